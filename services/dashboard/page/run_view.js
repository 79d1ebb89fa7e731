// The line's page: a run's curve, one click from any result row (the stations' last results,
// the part search, the NOK list: a row with data-station and data-run), or #run=ST/RUN in
// the address. Read from the run's recording on the line server (GET /api/runs/ST/RUN);
// beside it the part's runs, a multi-spindle run's cycle and the program's band (run_specs.js),
// drawn by run_chart.js.
// Uses el, none, table and fixed of dashboard.js. What a reply holds goes in as text only.
"use strict";
// one scope of its own: nothing here meets a name of dashboard.js or part_search.js
(() => {

const runPanel = document.getElementById("run");
const RETRY_MS = 500; // a run whose result is on its way to the store: asked again
const RETRY_FOR_MS = 8000;
const BAND_RUNS = 20;
let runOpens = 0; // the latest open: a reply to an older one is dropped
window.boltwatchRun = null; // what is shown, for a test or a benchmark to read

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
const runUrl = (station, run) => `/api/runs/${encodeURIComponent(station)}/${run}`;

function figureRow(name, figure, unit, scale = 1, digits = 1) {
  if (!figure) return el("tr", {}, el("th", {}, name), el("td", {}, "-"));
  const value = figure.value === null ? "-" : `${(figure.value / scale).toFixed(digits)} ${unit}`;
  const bound = (v) => (v === null ? "…" : (v / scale).toFixed(digits));
  const window = figure.min === null && figure.max === null ? "no window"
    : `window ${bound(figure.min)} to ${bound(figure.max)} ${unit}`;
  return el("tr", { "data-figure": name }, el("th", {}, name), el("td", { class: "num value" }, value),
    el("td", {}, window), el("td", { class: `status ${figure.status}` }, figure.status.replace("_", " ")));
}

function stopText(view) {
  const acted = view.decisions.filter((d) => !d.advisory);
  if (!acted.length) {
    const reason = view.result && view.result.stop_reason;
    return reason ? `${reason} (the result's; no decision recorded)` : "the tool stopped by itself (no stop decision)";
  }
  const d = acted[0];
  const predicted = d.predicted_force_n !== null ? `, predicted to land on ${fixed(d.predicted_force_n / 1000, 2, " kN")}`
    : d.predicted_torque_nm !== null ? `, predicted to land on ${fixed(d.predicted_torque_nm, 1, " Nm")}` : "";
  return `${d.reason}${d.detail ? `: ${d.detail}` : ""} at ${fixed(d.time_s, 3, " s")}, ` +
    `${fixed(d.angle_deg, 1, "°")}, on ${fixed(d.torque_nm, 1, " Nm")}` +
    (d.force_n === null ? "" : ` / ${fixed(d.force_n / 1000, 2, " kN")}`) + predicted;
}

function stageText(view) {
  if (!view.stages.length) return null;
  return view.stages.map((s) => `${s.command}${s.pulse ? ` ${s.pulse}` : ""} at ${fixed(s.time_s, 3, " s")} ` +
    `(${s.reason}${s.detail ? `: ${s.detail}` : ""})`).join("; ");
}

function figures(view) {
  const r = view.result;
  const rows = [
    figureRow("torque", r && r.final_torque_nm, "Nm"),
    figureRow("angle", r && r.final_angle_deg, "°"),
    figureRow("preload", r && r.final_force_n, "kN", 1000, 2),
    el("tr", { "data-figure": "stop" }, el("th", {}, "stop"), el("td", { colspan: "3" }, stopText(view))),
    el("tr", {}, el("th", {}, "stick-slip"), el("td", { colspan: "3" },
      `${view.events.length} events` + (r && r.process_intensity !== null ? `, intensity ${r.process_intensity.toPrecision(3)}` : ""))),
  ];
  const stages = stageText(view);
  if (stages) rows.push(el("tr", {}, el("th", {}, "final stage"), el("td", { colspan: "3" }, stages)));
  return el("table", { class: "figures-table" }, ...rows);
}

function steps(view) {
  const list = view.result ? view.result.steps : [];
  if (!list.length) return "";
  return el("div", {}, el("h3", {}, "The controller's steps"), table(["step", "function", "nominal", "actual", "status"],
    list.map((s) => el("tr", { class: "step" }, el("td", {}, s.name), el("td", {}, s.function || "-"),
      el("td", { class: "num" }, s.nominal === null ? "-" : String(s.nominal)),
      el("td", { class: "num" }, s.actual === null ? "-" : String(s.actual)), el("td", {}, s.status)))));
}

function events(view) {
  if (!view.events.length) return "";
  return el("details", {}, el("summary", {}, `The ${view.events.length} stick-slip events`),
    table(["j", "time", "angle", "T_max", "ΔT", "F_j", "ΔF", "f_ss"], view.events.map((e) => el("tr", {},
      el("td", { class: "num" }, e.index), el("td", { class: "num" }, fixed(e.time_s, 3, " s")),
      el("td", { class: "num" }, fixed(e.angle_deg, 1, "°")), el("td", { class: "num" }, fixed(e.peak_torque_nm, 1, " Nm")),
      el("td", { class: "num" }, fixed(e.torque_drop_nm, 1, " Nm")),
      el("td", { class: "num" }, e.plateau_force_n === null ? "-" : fixed(e.plateau_force_n / 1000, 2, " kN")),
      el("td", { class: "num" }, e.force_step_n === null ? "-" : fixed(e.force_step_n / 1000, 2, " kN")),
      el("td", { class: "num" }, fixed(e.f_ss_hz, 1, " Hz"))))));
}

function fileUrl(view, name) {
  return `${runUrl(view.station, view.run_id)}/files/${encodeURIComponent(name)}`;
}

function handOffs(view) {
  const links = view.downloads.map((d) => el("a", { href: fileUrl(view, d.name), download: d.name, class: `download ${d.kind}` },
    `${d.kind === "rrd" ? "Rerun .rrd" : "MCAP"} (${d.bytes === null ? "?" : `${(d.bytes / 1024).toFixed(0)} kB`})`));
  const outside = (template, kind, words) => {
    const file = view.downloads.find((d) => d.kind === kind);
    if (!template || !file) return null;
    const address = new URL(fileUrl(view, file.name), location.href).href;
    return el("a", { href: template.replace("{url}", encodeURIComponent(address)), target: "_blank",
      rel: "noopener noreferrer", class: "viewer" }, words);
  };
  const viewers = view.viewers || {};
  for (const link of [outside(viewers.rerun, "rrd", "open in Rerun"), outside(viewers.foxglove, "mcap", "open in Foxglove")]) {
    if (link) links.push(link);
  }
  return el("p", { class: "hand-offs" }, "Download: ", ...links.flatMap((l, n) => (n ? [" · ", l] : [l])));
}

function stateLine(view) {
  const lines = [];
  if (!view.complete) lines.push(el("p", { class: "store-error" }, `DAMAGED recording: its readable part only (${view.state})`));
  if (view.found.writing) lines.push(el("p", { class: "figures" }, "its file is still being written by the recorder"));
  if (view.found.note) lines.push(el("p", { class: "figures" }, view.found.note));
  const where = view.found.recording || view.files.join(", ");
  lines.push(el("p", { class: "figures recording" }, `${view.samples} samples from `, el("code", {}, where),
    view.found.recording_host ? ` on ${view.found.recording_host}` : ""));
  return lines;
}

function heading(station, run, view) {
  const close = el("button", { type: "button", class: "close" }, "close");
  close.addEventListener("click", closeRun);
  const title = el("h2", {}, `Run ${run} at ${station}`);
  if (view && view.result) {
    title.append(" ", el("span", { class: `verdict ${view.result.result}` }, view.result.result));
    if (view.result.nok_reasons) title.append(el("div", { class: "reasons" }, view.result.nok_reasons));
  }
  return el("div", { class: "found-head" }, title, close);
}

function subtitle(view) {
  const r = view.result, stored = view.stored, parts = [];
  if (r) parts.push(`program ${r.program_id}${r.program_name ? ` ${r.program_name}` : ""}`, `tool ${r.tool_id}`);
  if (r && r.spindle !== null && r.spindle !== undefined) parts.push(`spindle ${r.spindle} of cycle ${r.sync_id}`);
  if (r && r.part_id) parts.push(`part ${r.part_id}`);
  if (stored) parts.push(`ended ${stored.ended_utc} UTC`);
  const line = el("p", { class: "figures" }, parts.join(" · "));
  const cycle = stored && stored.cycle;
  if (!cycle) return line;
  // a multi-spindle cycle's run: the cycle's common result (OK only when every spindle is)
  return el("div", {}, line, el("p", { class: "figures cycle-result" }, `cycle ${cycle.sync_id} of ${cycle.spindles} spindles: `,
    el("span", { class: `verdict ${cycle.result}` }, cycle.result),
    cycle.nok_reasons ? el("span", { class: "reasons" }, ` ${cycle.nok_reasons}`) : ""));
}

// a multi-spindle station's run: its cycle's spindles can be put beside it
const inCycle = (view) => Boolean(view.result && view.result.sync_id !== null && view.result.sync_id !== undefined);

function closeRun() {
  runOpens += 1;
  runPanel.hidden = true;
  runPanel.dataset.key = "";
  runPanel.replaceChildren();
  window.boltwatchRun = null;
  history.replaceState(null, "", location.pathname + location.search);
}

function makeCharts(box, withForce) {
  const charts = {
    torque_angle: new RunChart(box, "torque over angle", "angle (°)", "torque (Nm)"),
    torque_time: new RunChart(box, "torque over time", "time (s)", "torque (Nm)"),
  };
  if (withForce) {
    charts.force_angle = new RunChart(box, "preload over angle", "angle (°)", "preload (kN)");
    charts.force_time = new RunChart(box, "preload over time", "time (s)", "preload (kN)");
  }
  return charts;
}

function drawAll(charts, specOf) {
  for (const [name, chart] of Object.entries(charts)) chart.draw(specOf(name));
}

// the buttons that put the run beside others: its part's runs, its program's band
function sideBySide(view, charts, note) {
  const state = { mode: "run", align: "start" };
  const buttons = {
    run: el("button", { type: "button", class: "mode on", "data-mode": "run" }, "this run"),
    part: el("button", { type: "button", class: "mode", "data-mode": "part" }, "the part's runs"),
    program: el("button", { type: "button", class: "mode", "data-mode": "program" },
      `against its program's last ${BAND_RUNS} OK runs`),
  };
  if (inCycle(view)) {
    buttons.cycle = el("button", { type: "button", class: "mode", "data-mode": "cycle" }, "its cycle's spindles");
  }
  const align = el("select", { class: "align", "aria-label": "align the runs at" },
    el("option", { value: "start" }, "aligned at their start"),
    el("option", { value: "first-slip" }, "aligned at their first slip"));
  const show = async () => {
    const open = runOpens;
    Object.values(buttons).forEach((b) => b.classList.toggle("on", b.dataset.mode === state.mode));
    runPanel.dataset.mode = state.mode;
    note.replaceChildren();
    if (state.mode === "run") {
      drawAll(charts, (name) => runSpec(view, name));
      runPanel.dataset.modeReady = state.mode;
      return;
    }
    runPanel.dataset.modeReady = "";
    note.append(none("reading the runs…"));
    const path = state.mode === "program" ? `program?runs=${BAND_RUNS}&align=${state.align}`
      : `${state.mode}?align=${state.align}`;
    let reply, ok;
    try {
      const response = await fetch(`${runUrl(view.station, view.run_id)}/${path}`);
      ok = response.ok;
      reply = await response.json();
    } catch (err) {
      ok = false; reply = { errors: ["the page's server does not answer"] };
    }
    if (open !== runOpens) return;
    note.replaceChildren();
    if (!ok) { note.append(el("p", { class: "store-error" }, (reply.errors || []).join("; "))); return; }
    if (state.mode === "part") {
      drawAll(charts, (name) => partSpec(reply, name));
      note.append(el("p", { class: "figures part-summary" }, `${reply.runs.length} runs of part ${reply.part_id}` +
        `, aligned at the ${reply.alignment}`));
    } else if (state.mode === "cycle") {
      drawAll(charts, (name) => partSpec(reply, name));
      const c = reply.cycle;
      note.append(el("p", { class: "figures cycle-summary" },
        `${reply.runs.length} spindles of cycle ${view.result.sync_id}, aligned at the ${reply.alignment}; the cycle: `,
        c ? el("span", { class: `verdict ${c.result}` }, c.result) : "its common result not stored yet",
        c && c.nok_reasons ? el("span", { class: "reasons" }, ` ${c.nok_reasons}`) : ""));
    } else {
      drawAll(charts, (name) => bandSpec(view, reply, name));
      note.append(el("p", { class: "figures band-summary" }, `the band of ${reply.runs.length} OK runs of program ` +
        `${reply.program.id} before this one, aligned at the ${reply.alignment}`));
    }
    for (const line of reply.left_out || []) note.append(el("p", { class: "figures" }, `left out: ${line}`));
    window.boltwatchRun.side = reply;
    runPanel.dataset.modeReady = state.mode;
  };
  for (const button of Object.values(buttons)) {
    button.addEventListener("click", () => { state.mode = button.dataset.mode; show(); });
  }
  align.addEventListener("change", () => { state.align = align.value; show(); });
  if (!(view.result && view.result.part_id) && !(view.stored && view.stored.part_id)) buttons.part.disabled = true;
  return el("div", { class: "modes" }, ...Object.values(buttons), align);
}

function drawRun(view, started, fetched) {
  const chartBox = el("div", { class: "charts" });
  const note = el("div", { class: "side-note" });
  runPanel.replaceChildren(heading(view.station, view.run_id, view), subtitle(view), ...stateLine(view),
    figures(view), handOffs(view));
  const charts = makeCharts(chartBox, view.series.force_n !== null);
  runPanel.append(sideBySide(view, charts, note), note, chartBox, steps(view), events(view));
  drawAll(charts, (name) => runSpec(view, name));
  runPanel.dataset.mode = runPanel.dataset.modeReady = "run";
  window.boltwatchRun = { key: view.key, samples: view.samples, drawn: view.drawn, view, charts,
    fetchMs: fetched - started, readyMs: null };
  // ready: drawn, and the frame that shows it begun (what the benchmark times from the click)
  const open = runOpens;
  requestAnimationFrame(() => {
    if (open !== runOpens) return;
    window.boltwatchRun.readyMs = performance.now() - started;
    runPanel.dataset.ready = "1";
  });
}

async function showRun(station, run) {
  const open = ++runOpens;
  const started = performance.now();
  history.replaceState(null, "", `#run=${encodeURIComponent(station)}/${run}`);
  runPanel.hidden = false;
  runPanel.dataset.ready = "";
  runPanel.dataset.key = `${station}/${run}`;
  runPanel.replaceChildren(heading(station, run, null), none("reading its recording…"));
  window.scrollTo({ top: 0 });
  for (;;) {
    let response, body;
    try {
      response = await fetch(runUrl(station, run));
      body = await response.json();
    } catch (err) {
      body = { errors: [err instanceof TypeError ? "the page's server does not answer" : err.message] };
    }
    if (open !== runOpens) return;
    if (response && response.ok) { drawRun(body, started, performance.now()); return; }
    const waiting = body.pending || (response && response.status === 503);
    if (waiting && performance.now() - started < RETRY_FOR_MS) {
      runPanel.replaceChildren(heading(station, run, null), none(`${body.errors.join("; ")}: asking again…`));
      await sleep(RETRY_MS);
      if (open !== runOpens) return;
      continue;
    }
    runPanel.replaceChildren(heading(station, run, null),
      el("p", { class: "store-error run-error" }, (body.errors || []).join("; ") || `HTTP ${response.status}`));
    runPanel.dataset.ready = "error";
    return;
  }
}

document.addEventListener("click", (event) => {
  const row = event.target.closest("tr[data-station][data-run]");
  if (!row || event.target.closest("a, button, input, select")) return;
  showRun(row.dataset.station, row.dataset.run);
});

// a run named in the address: at load, and when the address changes (back, forward, a link)
function fromAddress() {
  const asked = /^#run=([A-Za-z0-9_-]{1,64})\/([0-9]{1,19})$/.exec(location.hash);
  if (asked && runPanel.dataset.key !== `${asked[1]}/${asked[2]}`) showRun(asked[1], asked[2]);
}
window.addEventListener("hashchange", fromAddress);
fromAddress();
})();
