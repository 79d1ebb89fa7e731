// The line's page: draws /board.json and every board that /events sends.
"use strict";

const stations = document.getElementById("stations");
const link = document.getElementById("link");
const router = document.getElementById("router");

function el(tag, attrs = {}, ...children) {
  const node = document.createElement(tag);
  for (const [name, value] of Object.entries(attrs)) node.setAttribute(name, value);
  for (const child of children) {
    node.append(child instanceof Node ? child : document.createTextNode(String(child)));
  }
  return node;
}

function fixed(value, digits, unit = "") {
  return value === null || value === undefined ? "-" : `${value.toFixed(digits)}${unit}`;
}

function ago(seconds) {
  if (seconds === null || seconds === undefined) return "-";
  if (seconds < 60) return `${Math.max(0, seconds).toFixed(0)} s ago`;
  if (seconds < 3600) return `${(seconds / 60).toFixed(0)} min ago`;
  return `${(seconds / 3600).toFixed(1)} h ago`;
}

function none(text) {
  return el("p", { class: "none" }, text);
}

function table(headers, rows) {
  return el("table", {}, el("tr", {}, ...headers.map((h) => el("th", {}, h))), ...rows);
}

// A multi-spindle station's rows (each with its sync_id), a cycle row above each cycle's
// spindles: its sync id, its part, its common result with its reasons ("spindle 3 NOK
// (torque low)"; not come yet: "no common result yet"). A single-spindle station's rows as they are.
function cycleRow(columns, r) {
  const c = r.cycle;
  const verdict = c ? el("span", { class: `verdict ${c.result}` }, c.result)
    : el("span", { class: "verdict pending" }, "no common result yet");
  const part = r.part_id || (c && c.part_id);
  return el("tr", { class: "cycle", "data-sync": r.sync_id, "data-cycle-result": c ? c.result : "" },
    el("td", { colspan: String(columns) }, `cycle ${r.sync_id}${part ? ` · part ${part}` : ""} `,
      verdict, c && c.nok_reasons ? el("span", { class: "reasons" }, ` ${c.nok_reasons}`) : ""));
}

function byCycle(rows, columns, drawRow) {
  const drawn = [];
  let last = null;
  for (const r of rows) {
    const cycle = r.sync_id === null || r.sync_id === undefined ? null : `${r.station}/${r.sync_id}`;
    if (cycle !== null && cycle !== last) drawn.push(cycleRow(columns, r));
    last = cycle;
    drawn.push(drawRow(r));
  }
  return drawn;
}

const spindled = (rows) => rows.some((r) => r.spindle !== null && r.spindle !== undefined);

function services(station) {
  const names = Object.keys(station.services);
  if (names.length === 0) return none("services: first window not closed yet");
  return el("div", { class: "services" }, ...names.map((name) =>
    el("span", { class: station.services[name] ? "alive" : "dead",
                 "data-service": name }, `${name} ${station.services[name] ? "alive" : "down"}`)));
}

// Where the station is, as its station file says: "plant North, line B" (none named: nothing).
function place(station) {
  const named = [];
  if (station.plant) named.push(`plant ${station.plant}`);
  if (station.line) named.push(`line ${station.line}`);
  return named.length ? el("span", { class: "place" }, ` (${named.join(", ")})`) : "";
}

function figures(station) {
  const parts = [`samples: ${fixed(station.samples_per_s, 0, " /s")}`];
  if (station.bus_samples_per_s !== null) parts.push(`bus: ${fixed(station.bus_samples_per_s, 0, " /s")}`);
  if (station.last_run) parts.push(`last run ${station.last_run.run_id}: ${station.last_run.state}`);
  if (station.recorder) {
    parts.push(station.recorder.recording ? "recording" : "NOT recording");
    if (station.recorder.lag_p50_ms !== null) parts.push(`recorder lag ${fixed(station.recorder.lag_p50_ms, 1, " ms")}`);
  }
  if (station.bridge) parts.push(`controller ${station.bridge.controller} ${station.bridge.connected ? "connected" : "NOT connected"}`);
  for (const spool of station.spools) {
    const waiting = spool.messages === 0 ? "nothing waiting"
      : `${spool.runs} runs, ${spool.samples} samples waiting` +
        (spool.oldest_run_id === null ? "" : ` (oldest run ${spool.oldest_run_id})`);
    const resend = spool.resend_per_s ? `, sending again ${fixed(spool.resend_per_s, 0, " /s")}` : "";
    parts.push(`spool: ${waiting}, ${fixed(spool.full_pct, 1, " %")} full${resend}`);
  }
  return el("p", { class: "figures" }, parts.join(" · "));
}

function results(station) {
  if (station.results.length === 0) return none("no result yet");
  const spindles = spindled(station.results);
  const headers = ["run", ...(spindles ? ["spindle"] : []), "program", "result", "torque", "angle",
    "preload", "when"];
  const rows = station.results.map((r) => ({ ...r, station: station.station }));
  return table(headers, byCycle(rows, headers.length, (r) => el("tr", { class: "result",
      "data-station": station.station, "data-run": r.run_id, title: "show its curve",
      ...(spindles ? { "data-spindle": r.spindle } : {}) },
      el("td", { class: "num" }, r.run_id),
      spindles ? el("td", { class: "num spindle" }, r.spindle === null ? "-" : r.spindle) : "",
      el("td", {}, r.program),
      el("td", {}, el("span", { class: `verdict ${r.result}` }, r.result),
        r.nok_reasons ? el("div", { class: "reasons" }, r.nok_reasons) : ""),
      el("td", { class: "num" }, fixed(r.torque_nm, 1, " Nm")),
      el("td", { class: "num" }, fixed(r.angle_deg, 0, "°")),
      el("td", { class: "num" }, r.force_n === null ? "-" : fixed(r.force_n / 1000, 2, " kN")),
      el("td", {}, ago(r.age_s)))));
}

function stops(station) {
  if (station.stops.length === 0) return none("no run ended yet");
  return table(["run", "stop reason", "error", "events", "when"],
    station.stops.map((s) => el("tr", { class: "stop" },
      el("td", { class: "num" }, s.run_id, s.spindle ? ` (spindle ${s.spindle})` : ""),
      el("td", {}, s.stop_reason + (s.late_decision ? ` (late: ${s.late_decision})` : "") +
        stageText(s)),
      el("td", { class: "num" }, fixed(s.error_pct, 2, " %")),
      el("td", { class: "num" }, s.events),
      el("td", {}, ago(s.age_s)))));
}

// a final stage: where it began, and the pulses back to the target (a quality signal)
function stageText(s) {
  if (s.final_stage_s === null || s.final_stage_s === undefined) return "";
  const pulses = s.pulses === 0 ? "" : s.pulses === 1 ? ", 1 pulse" : `, ${s.pulses} pulses`;
  return ` (final stage at ${fixed(s.final_stage_s, 2, " s")}${pulses})`;
}

function wear(station) {
  const threshold = station.wear_threshold;
  const head = threshold === null ? "no service threshold set (recorder.wear_service_threshold)"
    : `service threshold ${threshold.toPrecision(3)}`;
  const rows = station.wear.map((t) => el("tr", { class: "wear" },
    el("td", { class: "num" }, `tool ${t.tool_id}`),
    el("td", {}, t.used === null ? "" : el("meter", { min: "0", max: "1", low: "0.8", high: "0.95",
      optimum: "0", value: String(Math.min(t.used, 1)) })),
    el("td", { class: t.due ? "num due" : "num" },
      t.used === null ? t.intensity_since_service.toPrecision(3) : `${(100 * t.used).toFixed(0)} %`),
    el("td", { class: "num" }, `${t.runs_since_service} runs since service`)));
  const parts = [el("p", { class: "figures" }, head)];
  if (rows.length) parts.push(table(["tool", "wear", "", ""], rows));
  if (station.wear_error) parts.push(none(`wear: ${station.wear_error}`));
  return el("div", {}, ...parts);
}

function alerts(station) {
  const items = station.alerts.map((a) => el("li", { class: "alert" }, `${a.topic}: ${a.text}`));
  const alarm = station.bridge && station.bridge.alarm;
  if (alarm) items.unshift(el("li", { class: "alert" }, `controller alarm ${alarm.error_code}: ${alarm.text}`));
  for (const spool of station.spools) {
    if (spool.alert) items.unshift(el("li", { class: "alert spool" }, `spool (${spool.source}): ${spool.alert}`));
  }
  return items.length ? el("ul", { class: "alerts" }, ...items) : none("no alert");
}

// what the page's server cannot reach: the line's router (then nothing below is live)
function drawRouter(state) {
  router.hidden = !state || state.reachable === true;
  if (router.hidden) return;
  router.textContent = state.reachable === null ? `reaching the line's router at ${state.endpoints}…`
    : `the line's router at ${state.endpoints} is unreachable (${ago(state.for_s).replace(" ago", "")}): ` +
      "what is shown is not live";
}

function draw(board) {
  drawRouter(board.router);
  stations.replaceChildren(...board.stations.map((station) => el("section",
    { class: "station", id: `station-${station.station}` },
    el("h2", {}, `Station ${station.station}`, station.name ? ` — ${station.name}` : "",
      place(station)), services(station), figures(station),
    el("h3", {}, "Last results"), results(station),
    el("h3", {}, "Last stop reasons"), stops(station),
    el("h3", {}, "Tool wear"), wear(station),
    el("h3", {}, "Alerts"), alerts(station))));
}

fetch("/board.json").then((r) => r.json()).then(draw).catch(() => {});
const events = new EventSource("/events");
events.onopen = () => { link.textContent = "live"; link.className = "link up"; };
events.onerror = () => { link.textContent = "server unreachable: retrying"; link.className = "link down"; };
events.onmessage = (message) => draw(JSON.parse(message.data));
