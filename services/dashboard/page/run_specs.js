// The line's page: what each chart of a run's view draws (RunChart specs, run_chart.js), from
// the server's documents: one run (/api/runs/ST/RUN), a part's runs (.../part), a program's
// band (.../program). Four charts: torque and preload, each over angle and over time.
"use strict";

const COLOURS = {
  run: "#1565c0", reference: "#111", window: "#2e7d32", target: "#6a1b9a", peak: "#c62828",
  plateau: "#263238", decision: "#111", stage: "#00838f", band: "#78909c",
};
const WINDOW_COLOURS = ["#2e7d32", "#6a1b9a", "#8d6e63", "#00838f"];
const NOK_COLOURS = ["#c62828", "#ef6c00", "#ad1457", "#d84315", "#f9a825"];
const OK_COLOURS = ["#1565c0", "#00897b", "#5e35b1", "#0277bd", "#2e7d32", "#6d4c41"];

const kN = (v) => (v === null || v === undefined ? null : v / 1000);
const kNs = (values) => (values ? values.map(kN) : null);

// which axis each chart has: its x key in series and marks, its unit
const CHART_AXES = {
  torque_angle: { x: "angle_deg", mark: "angle_deg", figure: "torque" },
  torque_time: { x: "time_s", mark: "time_s", figure: "torque" },
  force_angle: { x: "angle_deg", mark: "angle_deg", figure: "force" },
  force_time: { x: "time_s", mark: "time_s", figure: "force" },
};

function windowsOf(result) {
  if (!result) return null;
  const pair = (f) => [f.min, f.max];
  return { torque: pair(result.final_torque_nm), angle: pair(result.final_angle_deg),
    force: pair(result.final_force_n).map(kN) };
}

function windowBox(windows, axes, colour, label) {
  if (!windows) return [];
  const y = axes.figure === "torque" ? windows.torque : windows.force;
  const x = axes.x === "angle_deg" ? windows.angle : [null, null];
  const open = (pair) => pair[0] === null && pair[1] === null;
  if (open(y) && open(x)) return [];
  return [{ x, y, color: colour, label }];
}

const STAGE_LINES = {
  final: { dash: [2, 3], words: "final stage from here" },
  rundown: { dash: [2, 3], words: "back to the rundown speed" },
  pulse: { dash: [7, 3, 2, 3], words: "pulse back to the target" },
};

// the stop decisions and a final stage's commands, as vertical lines at their samples
function commandLines(view, axes) {
  const lines = view.decisions.map((d) => ({ x: d[axes.mark], color: COLOURS.decision, dash: [6, 4], width: 1.4,
    label: d.advisory ? `replayed stop decision (${d.reason}, not acted on)` : `stop decision: ${d.reason}` }));
  for (const s of view.stages) {
    const style = STAGE_LINES[s.command];
    if (style) lines.push({ x: s[axes.mark], color: COLOURS.stage, dash: style.dash, label: style.words });
  }
  return lines.filter((l) => l.x !== null);
}

function targetLines(view, axes) {
  const lines = [];
  const target = view.target, marks = view.controller;
  const torque = target ? target.torque_nm : marks ? marks.torque_target_nm : null;
  if (axes.figure === "torque" && torque !== null && torque !== undefined) {
    lines.push({ y: torque, color: COLOURS.target, dash: [2, 3], label: `target ${torque} Nm` });
  }
  if (axes.figure === "force" && target && target.force_n !== null) {
    lines.push({ y: kN(target.force_n), color: COLOURS.target, dash: [2, 3], label: `target ${kN(target.force_n)} kN` });
  }
  return lines;
}

// one run: its curve, the windows of its result, its stick-slip peaks and plateaus, its stop
function runSpec(view, chart) {
  const axes = CHART_AXES[chart], s = view.series;
  const y = axes.figure === "torque" ? s.torque_nm : kNs(s.force_n);
  const spec = {
    lines: [{ x: s[axes.x], y, color: COLOURS.run, width: 1.3, label: axes.figure === "torque" ? "torque" : "preload" }],
    boxes: windowBox(windowsOf(view.result), axes, COLOURS.window, "the program's windows"),
    hlines: targetLines(view, axes),
    vlines: commandLines(view, axes),
  };
  if (axes.figure === "torque") {
    spec.points = view.events.filter((e) => e[axes.mark] !== null).map((e) => ({
      x: e[axes.mark], y: e.peak_torque_nm, shape: "down", color: COLOURS.peak, label: "stick-slip peak T_max,j" }));
  } else {
    const from = axes.x === "angle_deg" ? "from_angle_deg" : "from_time_s";
    const to = axes.x === "angle_deg" ? "to_angle_deg" : "to_time_s";
    spec.segments = view.plateaus.filter((p) => p.force_n !== null).map((p) => ({
      x0: p[from], x1: p[to], y: kN(p.force_n), color: COLOURS.plateau, label: "plateau F_j the predictor saw" }));
  }
  return spec;
}

function runColour(series, counts) {
  if (series.reference) return COLOURS.reference;
  const nok = series.verdict === "NOK";
  const palette = nok ? NOK_COLOURS : OK_COLOURS;
  const n = nok ? counts.nok++ : counts.ok++;
  return palette[n % palette.length];
}

// a part's runs (or a multi-spindle cycle's), the one shown black and on top, NOK runs in reds,
// each program's windows
function partSpec(part, chart) {
  const axes = CHART_AXES[chart];
  const counts = { nok: 0, ok: 0 };
  const ordered = [...part.runs.filter((r) => !r.reference), ...part.runs.filter((r) => r.reference)];
  const lines = [];
  for (const r of ordered) {
    const y = axes.figure === "torque" ? r.torque_nm : kNs(r.force_n);
    if (!y) continue;
    lines.push({ x: r[axes.x], y, color: runColour(r, counts), width: r.reference ? 2.2 : r.verdict === "NOK" ? 1.6 : 1.1,
      dash: r.aligned ? [] : [2, 3], label: `${r.key}${r.spindle ? ` spindle ${r.spindle}` : ""} ${r.verdict}${r.reference ? " (this run)" : ""}`,
      main: r.reference });
  }
  const boxes = part.windows.flatMap((w, n) => windowBox(
    { torque: w.torque_nm, angle: w.angle_deg, force: w.force_n.map(kN) }, axes,
    WINDOW_COLOURS[n % WINDOW_COLOURS.length], `program ${w.program_id} windows`));
  return { lines, boxes };
}

// the run against its program's band: lowest to highest of the runs, their median dashed
function bandSpec(view, band, chart) {
  const axes = CHART_AXES[chart], s = view.series;
  const over = axes.x === "angle_deg" ? band.over_angle : band.over_time;
  const own = axes.figure === "torque" ? s.torque_nm : kNs(s.force_n);
  const spec = {
    lines: [],
    boxes: windowBox(windowsOf(view.result), axes, COLOURS.window, "the program's windows"),
    bands: [],
  };
  const figures = over ? (axes.figure === "torque" ? over.torque_nm : over.force_n) : null;
  if (figures) {
    const scale = axes.figure === "torque" ? (v) => v : kN;
    spec.bands.push({ x: over.x, low: figures.low.map(scale), high: figures.high.map(scale), color: COLOURS.band,
      label: `lowest to highest of ${band.runs.length} OK runs` });
    spec.lines.push({ x: over.x, y: figures.median.map(scale), color: COLOURS.band, dash: [5, 3], width: 1.2,
      label: "their median" });
  }
  if (own) {
    spec.lines.push({ x: s[axes.x], y: own, color: COLOURS.reference, width: 1.6, label: `run ${view.run_id}`, main: true });
  }
  return spec;
}
