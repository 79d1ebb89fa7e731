// How the tests' and the benchmarks' node-opcua clients connect (opcua_client.js,
// tests/benchmarks/opcua_publish_client.js): the options' endpoint, security
// ("SignAndEncrypt" with Basic256Sha256, or "None"), client certificate and key, and
// application URI; a session as options.userName with options.password, or anonymous
// when no user name is given.
"use strict";
const {
    OPCUAClient,
    MessageSecurityMode,
    SecurityPolicy,
    UserTokenType,
} = require("node-opcua-client");

// a client of `applicationName`, trying `maxRetry` times to connect, asking sessions of
// `sessionTimeoutMs`
function createClient(options, applicationName, maxRetry, sessionTimeoutMs) {
    const secure = options.security === "SignAndEncrypt";
    const client = OPCUAClient.create({
        applicationName,
        applicationUri: options.applicationUri,
        securityMode: secure ? MessageSecurityMode.SignAndEncrypt : MessageSecurityMode.None,
        securityPolicy: secure ? SecurityPolicy.Basic256Sha256 : SecurityPolicy.None,
        certificateFile: options.certificate,
        privateKeyFile: options.privateKey,
        endpointMustExist: false,
        connectionStrategy: { maxRetry, initialDelay: 250, maxDelay: 500 },
        requestedSessionTimeout: sessionTimeoutMs,
    });
    client.on("backoff", () => {});
    return client;
}

// the client connected to options.endpoint, and its session
async function openSession(client, options) {
    await client.connect(options.endpoint);
    return client.createSession(
        options.userName === undefined || options.userName === null
            ? { type: UserTokenType.Anonymous }
            : { type: UserTokenType.UserName, userName: options.userName, password: options.password },
    );
}

module.exports = { createClient, openSession };
