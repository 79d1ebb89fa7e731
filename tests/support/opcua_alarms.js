// Alarms and conditions as a SCADA handles them, with node-opcua's own client tools
// (required by opcua_client.js, option "acknowledge").
//
// acknowledgeWhenRaised(session, conditionName, comment, say): node-opcua's
// installAlarmMonitoring (a subscription on the Server object, the fields of
// AlarmConditionType, where OfType(AcknowledgeableConditionType), then ConditionRefresh);
// the first time the condition named `conditionName` is unacknowledged, it is acknowledged
// (ClientAlarm.acknowledge: node-opcua finds the Acknowledge method from the ConditionId),
// then, once it says it is acknowledged and not confirmed, confirmed. Says
// {"type": "acknowledged" | "confirmed", "station", "conditionName", "status"}; resolves
// once confirmed.
//
// retainedConditions(session): node-opcua's findActiveConditions (the conditions a
// ConditionRefresh returns between its RefreshStartEvent and RefreshEndEvent) as
// [{conditionName, station, retain, acked, confirmed, conditionId}].
"use strict";
const { findActiveConditions, installAlarmMonitoring } = require("node-opcua-client");

const value = (field) => (field && field.value !== undefined ? field.value : null);

function acknowledgeWhenRaised(session, conditionName, comment, say) {
    let acknowledging = false;
    let confirming = false;
    return new Promise((resolve, reject) => {
        installAlarmMonitoring(session).then((alarms) => {
            const changed = (alarm) => {
                const fields = alarm.fields;
                if (value(fields.conditionName) !== conditionName) return;
                const station = value(fields.sourceName);
                const acked = value(fields.ackedState && fields.ackedState.id);
                const confirmed = value(fields.confirmedState && fields.confirmedState.id);
                if (!acked && !acknowledging) {
                    acknowledging = true;
                    alarm.acknowledge(session, comment).then((status) => {
                        say({ type: "acknowledged", station, conditionName, status: status.name });
                    }, reject);
                } else if (acked && confirmed === false && !confirming) {
                    confirming = true;
                    alarm.confirm(session, comment).then((status) => {
                        say({ type: "confirmed", station, conditionName, status: status.name });
                        resolve();
                    }, reject);
                }
            };
            alarms.on("newAlarm", changed);
            alarms.on("alarmChanged", changed);
        }, reject);
    });
}

async function retainedConditions(session) {
    const found = await findActiveConditions(session);
    return found.map((fields) => ({
        conditionName: value(fields.conditionName),
        station: value(fields.sourceName),
        retain: value(fields.retain),
        acked: value(fields.ackedState && fields.ackedState.id),
        confirmed: value(fields.confirmedState && fields.confirmedState.id),
        conditionId: fields.conditionId && fields.conditionId.value ? fields.conditionId.value.toString() : null,
    }));
}

module.exports = { acknowledgeWhenRaised, retainedConditions };
