// A generic OPC UA browser's tree of a part of the address space, as node-opcua browses it
// (required by opcua_client.js, option "browseTree": {"expand": [PATH, ...]}).
//
// From the joining system down, each node's hierarchical children (HasChild, Organizes...)
// in the server's order; a node is expanded when its path (browse names without their
// namespaces, from the joining system: "ResultManagement/Results"; "*" stands for any one
// name) is one of "expand", and shown collapsed otherwise. Each node: {depth, path, name,
// nodeClass ("Object", "Variable", "Method"...), type (its type definition's browse name),
// dataType, value (a scalar as it is, a structure by its type's name, an array by its
// length), children (how many)}.
"use strict";
const { AttributeIds, BrowseDirection, NodeClass } = require("node-opcua-client");

const HIERARCHICAL = "HierarchicalReferences";

async function browseTree(session, rootId, rootName, expand) {
    const patterns = expand.map((pattern) => pattern.split("/"));
    const wanted = (path) => {
        const names = path.split("/");
        return patterns.some(
            (pattern) =>
                pattern.length === names.length &&
                pattern.every((name, i) => name === "*" || name === names[i]),
        );
    };
    const names = new Map(); // node id -> browse name, for types and data types
    const nameOf = async (nodeId) => {
        if (!nodeId || nodeId.isEmpty()) return null;
        const key = nodeId.toString();
        if (!names.has(key)) {
            const read = await session.read({ nodeId, attributeId: AttributeIds.BrowseName });
            names.set(key, read.value.value ? read.value.value.name : key);
        }
        return names.get(key);
    };
    const children = async (nodeIds) => {
        if (nodeIds.length === 0) return [];
        const browsed = await session.browse(
            nodeIds.map((nodeId) => ({
                nodeId,
                referenceTypeId: HIERARCHICAL,
                includeSubtypes: true,
                browseDirection: BrowseDirection.Forward,
                resultMask: 0x3f,
            })),
        );
        return browsed.map((result) => result.references || []);
    };
    const nodes = [];
    const visit = async (nodeId, name, nodeClass, typeId, depth, path) => {
        const [references] = await children([nodeId]);
        const node = {
            depth,
            path,
            name,
            nodeClass: NodeClass[nodeClass],
            type: await nameOf(typeId),
            dataType: null,
            value: null,
            children: references.length,
        };
        if (nodeClass === NodeClass.Variable) {
            const [value, dataType] = await session.read([
                { nodeId, attributeId: AttributeIds.Value },
                { nodeId, attributeId: AttributeIds.DataType },
            ]);
            node.dataType = await nameOf(dataType.value.value);
            node.value = shown(value.value);
        }
        nodes.push(node);
        if (depth > 0 && !wanted(path)) return;
        for (const ref of references) {
            const child = ref.browseName.name;
            await visit(
                ref.nodeId,
                child,
                ref.nodeClass,
                ref.typeDefinition,
                depth + 1,
                depth === 0 ? child : `${path}/${child}`,
            );
        }
    };
    const typed = await session.browse({
        nodeId: rootId,
        referenceTypeId: "HasTypeDefinition",
        browseDirection: BrowseDirection.Forward,
    });
    const found = typed.references || [];
    const rootType = found.length ? found[0].nodeId : null;
    await visit(rootId, rootName, NodeClass.Object, rootType, 0, "");
    return nodes;
}

function shown(variant) {
    const value = variant ? variant.value : null;
    if (value === null || value === undefined) return null;
    if (Array.isArray(value) || ArrayBuffer.isView(value)) return `[${value.length}]`;
    if (typeof value === "bigint") return value.toString();
    if (value instanceof Date) return value.toISOString();
    if (typeof value === "object") {
        if ("text" in value) return value.text; // a LocalizedText
        if ("name" in value && "namespaceIndex" in value) return value.name; // a QualifiedName
        return `{${value.constructor ? value.constructor.name : "structure"}}`;
    }
    return value;
}

module.exports = { browseTree };
