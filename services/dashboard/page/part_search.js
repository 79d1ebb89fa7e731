// The line's page, its part search: every tightening of a part (GET /api/results), newest
// first, above the stations; and the line's NOK list (GET /api/noks). A row opens its run's
// curve (run_view.js). Uses el, none and table of dashboard.js (loaded before it).
// What the reply holds goes in as text only (el makes text nodes): a part id is never markup.
"use strict";

const SEARCH_LIMIT = 500;
const searchForm = document.getElementById("part-search");
const partInput = document.getElementById("part");
const found = document.getElementById("found");
const nokButton = document.getElementById("nok-list");
let searches = 0; // the number of the latest search: a reply to an older one is dropped

function judged(figure, digits, unit, scale = 1) {
  if (!figure || figure.value === null) return "-";
  const mark = figure.status === "ok" || figure.status === "not_judged" ? "" : ` (${figure.status})`;
  return `${(figure.value / scale).toFixed(digits)}${unit}${mark}`;
}

function recording(r) {
  if (!r.recording) return "-";
  const where = el("code", { title: `boltwatch inspect ${r.recording} --run ${r.run_id}` },
    r.recording);
  return r.recording_host ? el("span", {}, where, el("span", { class: "host" }, ` on ${r.recording_host}`))
    : where;
}

// a multi-spindle station's rows: each run's spindle after it, each cycle's common result in a
// row above its spindles (byCycle of dashboard.js)
function tightenings(rows) {
  const spindles = spindled(rows);
  const headers = ["ended (UTC)", "station", "plant", "line", "run", ...(spindles ? ["spindle"] : []),
    "program", "tool", "result", "torque", "angle", "preload", "stopped on", "events", "recording"];
  return table(headers, byCycle(rows, headers.length, (r) => el("tr", { class: "found",
    "data-station": r.station, "data-run": r.run_id, title: "show its curve",
    ...(spindles ? { "data-spindle": r.spindle === null || r.spindle === undefined ? "" : r.spindle } : {}) },
    el("td", {}, r.ended_utc),
    el("td", {}, r.station, r.station_name ? el("div", { class: "name" }, r.station_name) : ""),
    el("td", {}, r.plant || "-"),
    el("td", {}, r.line || "-"),
    el("td", { class: "num" }, r.run_id),
    spindles ? el("td", { class: "num spindle" }, r.spindle === null || r.spindle === undefined ? "-" : r.spindle) : "",
    el("td", { class: "program" }, `${r.program_id} ${r.program_name}`.trim()),
    el("td", { class: "num" }, r.tool_id),
    el("td", {}, el("span", { class: `verdict ${r.result}` }, r.result),
      r.nok_reasons ? el("div", { class: "reasons" }, r.nok_reasons) : ""),
    el("td", { class: "num" }, judged(r.final_torque_nm, 1, " Nm")),
    el("td", { class: "num" }, judged(r.final_angle_deg, 0, "°")),
    el("td", { class: "num" }, judged(r.final_force_n, 2, " kN", 1000)),
    el("td", {}, r.stop_reason || "-"),
    el("td", { class: "num" }, r.events === null ? "-" : r.events),
    el("td", { class: "recording" }, recording(r)))));
}

function showFound(title, ...children) {
  const close = el("button", { type: "button", class: "close" }, "close");
  close.addEventListener("click", () => { searches += 1; found.hidden = true; found.replaceChildren(); });
  found.replaceChildren(el("div", { class: "found-head" }, el("h2", {}, title), close), ...children);
  found.hidden = false;
}

function show(part, ...children) {
  showFound(`Tightenings of part ${part}`, ...children);
}

function answer(part, reply, title = `Tightenings of part ${part}`, nothing = `no tightening of part ${part}`) {
  const errors = (reply.errors || []).map((text) => el("p", { class: "store-error" }, text));
  const rows = reply.results || [];
  if (rows.length === 0) {
    const stores = reply.stores ? ` in ${reply.stores.join(", ")}` : "";
    showFound(title, ...errors, reply.answered ? none(`${nothing}${stores}`) : "");
    return;
  }
  const more = reply.total > rows.length ? `, the newest ${rows.length} of ${reply.total}` : "";
  showFound(title, ...errors,
    el("p", { class: "figures found-summary" },
      `${rows.length} tightening${rows.length === 1 ? "" : "s"}, newest first${more}`),
    el("div", { class: "wide" }, tightenings(rows)));
}

searchForm.addEventListener("submit", (event) => {
  event.preventDefault();
  const part = partInput.value.trim();
  if (!part) return;
  const search = ++searches;
  show(part, none("searching…"));
  fetch(`/api/results?${new URLSearchParams({ part, limit: SEARCH_LIMIT })}`)
    .then((response) => response.json().catch(() => {
      throw new Error(`the server answered HTTP ${response.status}`);
    }))
    .then((reply) => { if (search === searches) answer(part, reply); })
    .catch((err) => {
      const why = err instanceof TypeError ? "the page's server does not answer" : err.message;
      if (search === searches) show(part, el("p", { class: "store-error" }, `search failed: ${why}`));
    });
});

// the line's NOK list: the newest NOK tightenings of the page's stations
nokButton.addEventListener("click", () => {
  const search = ++searches;
  const title = "NOK tightenings of the line";
  showFound(title, none("searching…"));
  fetch(`/api/noks?${new URLSearchParams({ limit: SEARCH_LIMIT })}`)
    .then((response) => response.json().catch(() => {
      throw new Error(`the server answered HTTP ${response.status}`);
    }))
    .then((reply) => { if (search === searches) answer("", reply, title, "no NOK tightening"); })
    .catch((err) => {
      const why = err instanceof TypeError ? "the page's server does not answer" : err.message;
      if (search === searches) showFound(title, el("p", { class: "store-error" }, `search failed: ${why}`));
    });
});
