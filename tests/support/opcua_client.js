// An OPC UA client of another implementation than the server's (node-opcua), for the tests.
//
//   node opcua_client.js '{"endpoint": "opc.tcp://127.0.0.1:4840", "certificate": "c.pem",
//                          "privateKey": "c.key", "applicationUri": "urn:...",
//                          "security": "SignAndEncrypt" | "None", "stations": ["st1"],
//                          "results": 5, "timeoutMs": 60000, "userName": "u", "password": "p"}'
//
// The session's user: "userName" and "password" (a UserName token), anonymous without them.
// Prints JSON lines on stdout: {"type": "connected"} or {"type": "refused", "reason"};
// per station {"type": "system", "station", "nodeId"} once it browsed to its joining
// system (Objects/Machines/<station>); {"type": "subscribed"} once it subscribed to the
// events of the Server object (i=2253), as SCADA systems do, with no where clause; one
// {"type": "result", "station", "eventType", "message", "resultIdField",
// "evaluationField", "classificationField", "countersField", "result"} per result-ready
// event (the Result field as JSON, and its sub-fields Result/ResultMetaData/ResultId,
// .../ResultEvaluation, .../Classification and .../ResultCounters selected on their own), {"type": "event", "station", "eventType", "message", "conditionId",
// "conditionName", "retain", "acked", "code", "severity"} per other event (a condition's);
// it waits for "results" result events. With "acknowledge": {"conditionName", "comment"},
// a SCADA's handling of that condition (opcua_alarms.js: acknowledged, then confirmed) and
// at the end {"type": "retained", "conditions"}: what ConditionRefresh returns.
// At the end, per station, {"type": "results_folder", "station", "names"} (the browse names in
// ResultManagement/Results); with "askById": true, the first result received asked by
// its id (ResultManagement's GetResultById, again while the results store does not have
// it yet: Error -1) as {"type": "by_id", "station", "resultId", "error", "result"}
// (typed arrays as JSON arrays, NaN as null); with "askLatest": true, ResultManagement's
// GetLatestResult (again until the store has the last result received) as {"type":
// "latest", "station", "resultId", "error", "tracePoints"}, and the same method through
// MachineryBuildingBlocks/ResultManagement as {"type": "latest_blocks", "station",
// "resultId", "error", "objectId", "systemObjectId"}; with "toolRuns": N, each tool of
// AssetManagement/Assets/Tools once its OperationCycleCounter reached N (read again until
// then) as {"type": "tool", "station", "name", "serialNumber", "tightenings",
// "sinceService", "intensitySinceService", "limitValue", "warningValues", "unitId",
// "serviceDue", "tighteningsToService"}; with "browseTree":
// {"expand": [PATH, ...]}, per station {"type": "tree", "station", "nodes"}: the joining
// system's address space as a generic browser shows it (opcua_browse_tree.js); with
// "crawl": true, {"type": "crawl", ...} (opcua_crawl.js: the whole address space walked);
// then {"type": "done"}. Exit status 0, or 1 on an error
// (its line: {"type": "error", "message"}).
"use strict";
const {
    AttributeIds,
    TimestampsToReturn,
    makeBrowsePath,
    constructEventFilter,
    DataType,
    StatusCodes,
} = require("node-opcua-client");
const { acknowledgeWhenRaised, retainedConditions } = require("./opcua_alarms.js");
const { browseTree } = require("./opcua_browse_tree.js");
const { crawlAddressSpace } = require("./opcua_crawl.js");
const { createClient, openSession } = require("./opcua_connect.js");

const options = JSON.parse(process.argv[2]);
const say = (object) => process.stdout.write(JSON.stringify(object) + "\n");

function plain(value) {
    return JSON.parse(
        JSON.stringify(value, (_key, item) => {
            if (typeof item === "bigint") return item.toString();
            if (ArrayBuffer.isView(item)) return Array.from(item);
            return item;
        }),
    );
}

async function main() {
    const secure = options.security === "SignAndEncrypt";
    const client = createClient(options, "boltwatch test client", options.connectRetries ?? 40, 60000);
    let session;
    try {
        session = await openSession(client, options);
    } catch (err) {
        say({ type: "refused", reason: String(err && err.message ? err.message : err) });
        await client.disconnect().catch(() => {});
        return;
    }
    say({ type: "connected", securityMode: secure ? "SignAndEncrypt" : "None" });

    const namespaces = await session.readNamespaceArray();
    const index = (uri) => namespaces.indexOf(uri);
    const machinery = index("http://opcfoundation.org/UA/Machinery/");
    const result = index("http://opcfoundation.org/UA/Machinery/Result/");
    const ours = index("urn:boltwatch:opcua");

    const subscription = await session.createSubscription2({
        requestedPublishingInterval: 100,
        requestedMaxKeepAliveCount: 20,
        requestedLifetimeCount: 600,
        publishingEnabled: true,
    });
    const ijt = index("http://opcfoundation.org/UA/IJT/Base/");
    const resultReady = `ns=${ijt};i=1007`;
    const filter = constructEventFilter([
        "EventType",
        "SourceName",
        "Message",
        `${result}:Result`,
        `${result}:Result.${result}:ResultMetaData.${result}:ResultId`,
        `${result}:Result.${result}:ResultMetaData.${result}:ResultEvaluation`,
        "ConditionId",
        "ConditionName",
        "Retain",
        "AckedState.Id",
        `${ijt}:JoiningSystemEventContent.${ijt}:EventCode`,
        "Severity",
        `${result}:Result.${result}:ResultMetaData.${ijt}:Classification`,
        `${result}:Result.${result}:ResultMetaData.${ijt}:ResultCounters`,
    ]);
    const systems = {};
    const firstResultId = {};
    const lastResultId = {};
    let received = 0;
    let finish;
    const finished = new Promise((resolve) => (finish = resolve));
    for (const station of options.stations) {
        const path = makeBrowsePath("ObjectsFolder", `/${machinery}:Machines/${ours}:${station}`);
        const found = await session.translateBrowsePath(path);
        if (!found.targets || found.targets.length === 0) {
            throw new Error(`no joining system ${station}: ${found.statusCode.toString()}`);
        }
        systems[station] = found.targets[0].targetId;
        say({ type: "system", station, nodeId: systems[station].toString() });
    }
    const item = await subscription.monitor(
        { nodeId: "i=2253", attributeId: AttributeIds.EventNotifier },
        { samplingInterval: 0, queueSize: 1000, filter, discardOldest: false },
        TimestampsToReturn.Both,
    );
    item.on("changed", (fields) => {
        const [eventType, sourceName, message, value, resultIdField, evaluationField] = fields;
        const [conditionId, conditionName, retain, acked, code, severity] = fields.slice(6);
        const [classificationField, countersField] = fields.slice(12);
        const station = sourceName.value;
        const typeId = eventType.value ? eventType.value.toString() : null;
        if (typeId !== resultReady) {
            say({
                type: "event",
                station,
                eventType: typeId,
                message: message.value ? message.value.text : null,
                conditionId: conditionId.value ? conditionId.value.toString() : null,
                conditionName: conditionName.value,
                retain: retain.value,
                acked: acked.value,
                code: Array.isArray(code.value) ? code.value[0] * 2 ** 32 + code.value[1] : code.value,
                severity: severity.value,
            });
            return;
        }
        if (!(station in firstResultId)) firstResultId[station] = value.value.resultMetaData.resultId;
        lastResultId[station] = value.value.resultMetaData.resultId;
        say({
            type: "result",
            station,
            eventType: typeId,
            message: message.value ? message.value.text : null,
            resultIdField: resultIdField.value,
            evaluationField: evaluationField.value,
            classificationField: classificationField.value,
            countersField: plain(countersField.value),
            result: plain(value.value),
        });
        received += 1;
        if (received >= options.results) finish();
    });
    const handled = options.acknowledge
        ? acknowledgeWhenRaised(session, options.acknowledge.conditionName, options.acknowledge.comment, say)
        : Promise.resolve();
    say({ type: "subscribed" });
    const timer = setTimeout(finish, options.timeoutMs ?? 60000);
    await finished;
    await handled;
    clearTimeout(timer);
    for (const [station, nodeId] of Object.entries(systems)) {
        const path = makeBrowsePath(nodeId, `/${result}:ResultManagement/${result}:Results`);
        const folder = await session.translateBrowsePath(path);
        const browsed = await session.browse(folder.targets[0].targetId);
        say({
            type: "results_folder",
            station,
            names: browsed.references.map((ref) => ref.browseName.name),
        });
    }
    if (options.toolRuns) {
        for (const [station, nodeId] of Object.entries(systems)) {
            await readTools(session, nodeId, namespaces, station, options.toolRuns);
        }
    }
    if (options.askById) {
        for (const [station, nodeId] of Object.entries(systems)) {
            await askById(session, nodeId, result, station, firstResultId[station]);
        }
    }
    if (options.browseTree) {
        for (const [station, nodeId] of Object.entries(systems)) {
            const nodes = await browseTree(session, nodeId, station, options.browseTree.expand);
            say({ type: "tree", station, nodes });
        }
    }
    if (options.askLatest) {
        for (const [station, nodeId] of Object.entries(systems)) {
            await askLatest(session, nodeId, result, station, lastResultId[station]);
            await askLatestThroughBlocks(session, nodeId, machinery, result, station);
        }
    }
    if (options.acknowledge) {
        say({ type: "retained", conditions: await retainedConditions(session) });
    }
    if (options.crawl) {
        say({ type: "crawl", ...(await crawlAddressSpace(session)) });
    }
    await subscription.terminate();
    await session.close();
    await client.disconnect();
    say({ type: "done" });
}

async function readTools(session, systemId, namespaces, station, runs) {
    const [di, machinery, ijt, ours] = [
        "http://opcfoundation.org/UA/DI/",
        "http://opcfoundation.org/UA/Machinery/",
        "http://opcfoundation.org/UA/IJT/Base/",
        "urn:boltwatch:opcua",
    ].map((uri) => namespaces.indexOf(uri));
    const target = async (start, path) => {
        const found = await session.translateBrowsePath(makeBrowsePath(start, path));
        if (!found.targets || found.targets.length === 0) throw new Error(`no ${path}`);
        return found.targets[0].targetId;
    };
    const folder = await target(systemId, `/${ijt}:AssetManagement/${ijt}:Assets/${ijt}:Tools`);
    const browsed = await session.browse(folder);
    const intensity = `/${machinery}:LifetimeCounters/${ours}:StickSlipIntensitySinceService`;
    const paths = {
        serialNumber: `/${di}:Identification/${di}:SerialNumber`,
        tightenings: `/${di}:OperationCounters/${di}:OperationCycleCounter`,
        sinceService: `/${di}:Maintenance/${ijt}:Service/${ijt}:ServiceCycleCount`,
        intensitySinceService: intensity,
        limitValue: `${intensity}/${di}:LimitValue`,
        warningValues: `${intensity}/${di}:WarningValues`,
        unit: `${intensity}/EngineeringUnits`,
        serviceDue: `/${machinery}:LifetimeCounters/${ours}:StickSlipServiceDue`,
        tighteningsToService: `/${machinery}:LifetimeCounters/${ours}:StickSlipTighteningsToService`,
    };
    for (const ref of browsed.references) {
        if (!ref.browseName.name.startsWith("Tool_")) continue;
        const ids = {};
        for (const [key, path] of Object.entries(paths)) ids[key] = await target(ref.nodeId, path);
        for (;;) {
            const keys = Object.keys(ids);
            const read = await session.read(keys.map((key) => ({ nodeId: ids[key], attributeId: AttributeIds.Value })));
            const values = {};
            keys.forEach((key, i) => (values[key] = read[i].value.value));
            if (values.tightenings < runs) {
                await new Promise((resolve) => setTimeout(resolve, 500)); // the ledger lags
                continue;
            }
            say({
                type: "tool",
                station,
                name: ref.browseName.name,
                serialNumber: values.serialNumber,
                tightenings: values.tightenings,
                sinceService: values.sinceService,
                intensitySinceService: values.intensitySinceService,
                limitValue: values.limitValue,
                warningValues: values.warningValues ? Array.from(values.warningValues) : null,
                unitId: values.unit ? values.unit.unitId : null,
                serviceDue: values.serviceDue ? values.serviceDue.toISOString() : null,
                tighteningsToService: values.tighteningsToService,
            });
            break;
        }
    }
}

// the request of a call of the joining system's ResultManagement method `name` (not made
// here); `through`: the path to the ResultManagement from the joining system
async function managementRequest(session, systemId, result, name, inputArguments, through) {
    const child = async (path) => {
        const found = await session.translateBrowsePath(makeBrowsePath(systemId, path));
        if (!found.targets || found.targets.length === 0) throw new Error(`no ${path}`);
        return found.targets[0].targetId;
    };
    const management = through || `/${result}:ResultManagement`;
    return {
        objectId: await child(management),
        methodId: await child(`${management}/${result}:${name}`),
        inputArguments,
    };
}

// GetLatestResult through MachineryBuildingBlocks/ResultManagement, as a client that
// navigates by Machinery's building blocks calls it
async function askLatestThroughBlocks(session, systemId, machinery, result, station) {
    const through = `/${machinery}:MachineryBuildingBlocks/${result}:ResultManagement`;
    const zero = [{ dataType: DataType.Int32, value: 0 }];
    const request = await managementRequest(session, systemId, result, "GetLatestResult", zero, through);
    const own = await managementRequest(session, systemId, result, "GetLatestResult", zero);
    const called = await session.call(request);
    const [, value, error] = called.outputArguments;
    say({
        type: "latest_blocks",
        station,
        status: called.statusCode.name,
        resultId: value && value.value ? value.value.resultMetaData.resultId : null,
        error: error ? error.value : null,
        objectId: request.objectId.toString(),
        systemObjectId: own.objectId.toString(),
    });
}

async function askById(session, systemId, result, station, resultId) {
    const request = await managementRequest(session, systemId, result, "GetResultById", [
        { dataType: DataType.String, value: resultId },
        { dataType: DataType.Int32, value: 0 },
    ]);
    for (;;) {
        const called = await session.call(request);
        if (called.statusCode !== StatusCodes.Good) {
            throw new Error(`GetResultById ${resultId}: ${called.statusCode.toString()}`);
        }
        const [, value, error] = called.outputArguments;
        if (error.value === -1) {
            await new Promise((resolve) => setTimeout(resolve, 200)); // not stored yet
            continue;
        }
        say({ type: "by_id", station, resultId, error: error.value, result: plain(value.value) });
        return;
    }
}

async function askLatest(session, systemId, result, station, resultId) {
    const request = await managementRequest(session, systemId, result, "GetLatestResult", [
        { dataType: DataType.Int32, value: 0 },
    ]);
    for (;;) {
        const called = await session.call(request);
        if (called.statusCode !== StatusCodes.Good) {
            throw new Error(`GetLatestResult: ${called.statusCode.toString()}`);
        }
        const [, value, error] = called.outputArguments;
        const latest = value.value ? value.value.resultMetaData.resultId : null;
        if (error.value === -1 || latest !== resultId) {
            await new Promise((resolve) => setTimeout(resolve, 200)); // not stored yet
            continue;
        }
        const [content] = value.value.resultContent;
        const [step] = content.value.trace.stepTraces;
        say({ type: "latest", station, resultId: latest, error: error.value, tracePoints: step.numberOfTracePoints });
        return;
    }
}

// exit once stdout is written out: a pipe is written asynchronously, and process.exit
// would cut a long line (a trace) short
const exit = (code) => process.stdout.write("", () => process.exit(code));

main().then(
    () => exit(0),
    (err) => {
        say({ type: "error", message: String(err && err.stack ? err.stack : err) });
        exit(1);
    },
);
