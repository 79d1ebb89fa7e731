// A loading client of the OPC UA server for bench_opcua_publish.py (node-opcua, as the tests').
//
//   node opcua_publish_client.js '{"endpoint": "opc.tcp://127.0.0.1:4840", "certificate": "c.pem",
//                                  "privateKey": "c.key", "applicationUri": "urn:...",
//                                  "security": "SignAndEncrypt" | "None", "stations": ["st01"],
//                                  "userName": "u", "password": "p", "publishingIntervalMs": 100}'
//
// Subscribes to the result-ready events of every station's joining system and asks the
// trace of each result received by its id (ResultManagement's GetResultById), one call at
// a time, oldest first. Times are process.hrtime (CLOCK_MONOTONIC, as Python's
// time.monotonic_ns), in ns. JSON lines on stdout:
//   {"t": "subscribed", "publishingIntervalMs"}  (the interval the server granted)
//   {"t": "e", "id", "ns"}  a result-ready event received
//   {"t": "r", "id", "sent", "ns", "error", "points"}  a GetResultById answered (points: its
//       trace's samples, 0 without a trace)
//   {"t": "skipped", "n"}  after "skip" on stdin: the results not yet asked, dropped
//   {"t": "done"}  after "stop" on stdin; {"t": "error", "message"} and exit status 1.
"use strict";
const readline = require("readline");
const {
    AttributeIds,
    TimestampsToReturn,
    makeBrowsePath,
    constructEventFilter,
    DataType,
    StatusCodes,
} = require("node-opcua-client");
const { createClient, openSession } = require("../support/opcua_connect.js");

const options = JSON.parse(process.argv[2]);
const say = (object) => process.stdout.write(JSON.stringify(object) + "\n");
const now = () => process.hrtime.bigint().toString();

async function connect() {
    const client = createClient(options, "boltwatch benchmark client", 240, 600000);
    const session = await openSession(client, options);
    return { client, session };
}

async function main() {
    const { client, session } = await connect();
    const namespaces = await session.readNamespaceArray();
    const machinery = namespaces.indexOf("http://opcfoundation.org/UA/Machinery/");
    const result = namespaces.indexOf("http://opcfoundation.org/UA/Machinery/Result/");
    const ours = namespaces.indexOf("urn:boltwatch:opcua");
    const subscription = await session.createSubscription2({
        requestedPublishingInterval: options.publishingIntervalMs ?? 100,
        requestedMaxKeepAliveCount: 20,
        requestedLifetimeCount: 6000,
        maxNotificationsPerPublish: 0,
        publishingEnabled: true,
    });
    const filter = constructEventFilter([`${result}:Result`]);
    const queue = [];
    const methods = {};
    let wake = null;
    for (const station of options.stations) {
        const system = makeBrowsePath("ObjectsFolder", `/${machinery}:Machines/${ours}:${station}`);
        const found = await session.translateBrowsePath(system);
        if (!found.targets || found.targets.length === 0) throw new Error(`no ${station}`);
        const nodeId = found.targets[0].targetId;
        const child = async (path) => {
            const target = await session.translateBrowsePath(makeBrowsePath(nodeId, path));
            return target.targets[0].targetId;
        };
        methods[station] = {
            objectId: await child(`/${result}:ResultManagement`),
            methodId: await child(`/${result}:ResultManagement/${result}:GetResultById`),
        };
        const item = await subscription.monitor(
            { nodeId, attributeId: AttributeIds.EventNotifier },
            { samplingInterval: 0, queueSize: 10000, filter, discardOldest: false },
            TimestampsToReturn.Neither,
        );
        item.on("changed", (fields) => {
            const value = fields[0].value;
            if (!value) return; // another event of the joining system
            const id = value.resultMetaData.resultId;
            say({ t: "e", id, ns: now() });
            queue.push([station, id]);
            if (wake) wake();
        });
    }
    say({ t: "subscribed", publishingIntervalMs: subscription.publishingInterval });

    let stopping = false;
    readline.createInterface({ input: process.stdin }).on("line", (line) => {
        if (line === "skip") say({ t: "skipped", n: queue.splice(0).length });
        if (line === "stop") stopping = true;
        if (wake) wake();
    });
    while (!stopping) {
        if (queue.length === 0) {
            await new Promise((resolve) => (wake = resolve));
            wake = null;
            continue;
        }
        const [station, id] = queue.shift();
        const sent = now();
        const called = await session.call({
            ...methods[station],
            inputArguments: [
                { dataType: DataType.String, value: id },
                { dataType: DataType.Int32, value: 0 },
            ],
        });
        const answered = now();
        if (called.statusCode !== StatusCodes.Good) {
            throw new Error(`GetResultById ${id}: ${called.statusCode.toString()}`);
        }
        const [, value, error] = called.outputArguments;
        const content = value.value ? value.value.resultContent[0].value : null;
        const trace = content && content.trace ? content.trace.stepTraces[0] : null;
        say({ t: "r", id, sent, ns: answered, error: error.value, points: trace ? trace.numberOfTracePoints : 0 });
    }
    await subscription.terminate();
    await session.close();
    await client.disconnect();
    say({ t: "done" });
}

// exit once stdout is written out (a pipe is written asynchronously)
const exit = (code) => process.stdout.write("", () => process.exit(code));

main().then(
    () => exit(0),
    (err) => {
        say({ t: "error", message: String(err && err.stack ? err.stack : err) });
        exit(1);
    },
);
