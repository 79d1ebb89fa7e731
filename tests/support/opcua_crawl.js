// The whole address space as a generic client walks it, with node-opcua (required by
// opcua_client.js, option "crawl": true).
//
// From the Root folder, every forward reference of every node is followed (hierarchical and
// not: HasTypeDefinition, HasEncoding, HasModellingRule, HasCondition... lead somewhere too),
// each node browsed once (node-opcua's browseAll, which follows the server's limits and
// continuation points); of each node its NodeClass, BrowseName and DisplayName are read, of
// each variable also its Value, DataType and ValueRank; each type definition a reference
// names (HasTypeDefinition, and the typeDefinition of each reference's description) is read
// and must be an ObjectType or VariableType. What failed: {what, nodeId, path, status}, the
// path the browse names from Root to the node (the first way found).
//
// crawlAddressSpace(session) -> {nodes, byNamespace: {uri: {nodeClass: count}}, variables,
// typeDefinitions, references, failures, elapsedMs}
"use strict";
const {
    AttributeIds,
    BrowseDirection,
    NodeClass,
    StatusCodes,
    browseAll,
} = require("node-opcua-client");

const READS_PER_REQUEST = 500;
const ROOT = "i=84";

async function crawlAddressSpace(session) {
    const started = Date.now();
    const namespaces = await session.readNamespaceArray();
    const known = new Map(); // node id -> {nodeClass, path}
    known.set(ROOT, { nodeClass: NodeClass.Object, path: "Root" });
    const typeDefinitions = new Map(); // node id -> path of a node that names it
    const failures = [];
    let references = 0;
    let frontier = [ROOT];
    while (frontier.length > 0) {
        const browsed = await browseAll(
            session,
            frontier.map((nodeId) => ({
                nodeId,
                referenceTypeId: "References",
                includeSubtypes: true,
                browseDirection: BrowseDirection.Forward,
                nodeClassMask: 0,
                resultMask: 0x3f,
            })),
        );
        const next = [];
        browsed.forEach((result, i) => {
            const from = frontier[i];
            if (!result.statusCode.isGood()) {
                failures.push(failed("browse", from, known, result.statusCode));
                return;
            }
            for (const ref of result.references || []) {
                references += 1;
                const target = ref.nodeId.toString();
                if (ref.typeDefinition && !ref.typeDefinition.isEmpty()) {
                    const typeId = ref.typeDefinition.toString();
                    if (!typeDefinitions.has(typeId)) typeDefinitions.set(typeId, target);
                }
                if (ref.nodeId.serverIndex) continue; // another server's node: not ours to walk
                if (!known.has(target)) {
                    known.set(target, {
                        nodeClass: ref.nodeClass,
                        path: `${known.get(from).path}/${ref.browseName.name}`,
                    });
                    next.push(target);
                }
            }
        });
        frontier = next;
    }
    const ids = [...known.keys()];
    let variables = 0;
    const byNamespace = {};
    for (let start = 0; start < ids.length; start += READS_PER_REQUEST) {
        const chunk = ids.slice(start, start + READS_PER_REQUEST);
        const asked = []; // [node id, attribute id] (node-opcua turns a request's ids into objects)
        for (const nodeId of chunk) {
            const attributes = [AttributeIds.NodeClass, AttributeIds.BrowseName, AttributeIds.DisplayName];
            if (known.get(nodeId).nodeClass === NodeClass.Variable) {
                attributes.push(AttributeIds.Value, AttributeIds.DataType, AttributeIds.ValueRank);
                variables += 1;
            }
            for (const attributeId of attributes) asked.push([nodeId, attributeId]);
        }
        const read = await session.read(asked.map(([nodeId, attributeId]) => ({ nodeId, attributeId })));
        read.forEach((dataValue, j) => {
            const [nodeId, attributeId] = asked[j];
            if (!dataValue.statusCode.isGood()) {
                failures.push(failed(`read ${AttributeIds[attributeId]}`, nodeId, known, dataValue.statusCode));
            } else if (attributeId === AttributeIds.NodeClass) {
                const ns = namespaces[Number(nodeId.startsWith("ns=") ? nodeId.slice(3).split(";")[0] : 0)];
                const counts = (byNamespace[ns] = byNamespace[ns] || {});
                const name = NodeClass[dataValue.value.value];
                counts[name] = (counts[name] || 0) + 1;
            }
        });
    }
    const typeIds = [...typeDefinitions.keys()];
    for (let start = 0; start < typeIds.length; start += READS_PER_REQUEST) {
        const chunk = typeIds.slice(start, start + READS_PER_REQUEST);
        const read = await session.read(chunk.map((nodeId) => ({ nodeId, attributeId: AttributeIds.NodeClass })));
        read.forEach((dataValue, j) => {
            const typeClass = dataValue.value ? dataValue.value.value : null;
            if (!dataValue.statusCode.isGood()) {
                failures.push({ what: "type definition", nodeId: chunk[j], path: known.get(typeDefinitions.get(chunk[j]))?.path ?? null, status: dataValue.statusCode.name });
            } else if (typeClass !== NodeClass.ObjectType && typeClass !== NodeClass.VariableType) {
                failures.push({ what: "type definition", nodeId: chunk[j], path: null, status: `a ${NodeClass[typeClass]}` });
            }
        });
    }
    return {
        nodes: known.size,
        byNamespace,
        variables,
        typeDefinitions: typeDefinitions.size,
        references,
        failures,
        elapsedMs: Date.now() - started,
    };
}

function failed(what, nodeId, known, statusCode) {
    const entry = known.get(nodeId);
    return { what, nodeId, path: entry ? entry.path : null, status: statusCode.name || String(statusCode) };
}

module.exports = { crawlAddressSpace };
