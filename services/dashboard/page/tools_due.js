// The line's page: "Tools due soonest", from the board's tools_due (services/dashboard/tools_due.py).
// Each tool: when it is due and how sure, the runs left, what wears it most, and a chart of its
// intensity since service against its threshold with the forecast line to the date.
"use strict";

(() => {
  const section = document.getElementById("due");
  const SVG = "http://www.w3.org/2000/svg";
  const WIDTH = 360;
  const HEIGHT = 120;
  const PAD = { left: 8, right: 8, top: 10, bottom: 16 };

  function node(tag, attrs = {}, ...children) {
    const made = tag.startsWith("svg:") ? document.createElementNS(SVG, tag.slice(4))
      : document.createElement(tag);
    for (const [name, value] of Object.entries(attrs)) made.setAttribute(name, value);
    for (const child of children) {
      made.append(child instanceof Node ? child : document.createTextNode(String(child)));
    }
    return made;
  }

  function utc(ns) {
    if (ns === null || ns === undefined) return "later";
    return new Date(ns / 1e6).toISOString().slice(0, 16).replace("T", " ");
  }

  function day(ns) {
    if (ns === null || ns === undefined) return "later";
    return new Date(ns / 1e6).toISOString().slice(5, 16).replace("T", " ");
  }

  function number(value, digits = 1) {
    return value === null || value === undefined ? "-" : value.toFixed(digits);
  }

  // The chart: x from the service to the late end (or the date), y from 0 to the threshold.
  function chart(tool) {
    const data = tool.chart;
    const points = data.points;
    const threshold = data.threshold;
    const svg = node("svg:svg", {
      class: "due-chart", width: WIDTH, height: HEIGHT, viewBox: `0 0 ${WIDTH} ${HEIGHT}`,
      role: "img", "data-tool": tool.tool_id, "data-chart": JSON.stringify(data),
      "aria-label": `tool ${tool.tool_id}: intensity since service against its threshold`,
    });
    if (points.length === 0) return svg;
    const start = points[0][0];
    const ends = [points[points.length - 1][0]];
    if (data.forecast) ends.push(data.forecast[1][0]);
    if (data.late_ns) ends.push(data.late_ns);
    const end = Math.max(...ends);
    const top = Math.max(threshold || 0, ...points.map((p) => p[1])) * 1.08 || 1;
    const x = (ns) => PAD.left + (WIDTH - PAD.left - PAD.right) * ((ns - start) / Math.max(end - start, 1));
    const y = (value) => HEIGHT - PAD.bottom - (HEIGHT - PAD.top - PAD.bottom) * (value / top);
    if (threshold !== null) {
      if (data.early_ns) {
        const left = x(data.early_ns);
        const right = data.late_ns ? x(data.late_ns) : WIDTH - PAD.right;
        svg.append(node("svg:rect", { class: "interval", x: left, y: y(threshold) - 5,
          width: Math.max(right - left, 1), height: 10 }));
      }
      svg.append(node("svg:line", { class: "threshold", x1: PAD.left, x2: WIDTH - PAD.right,
        y1: y(threshold), y2: y(threshold) }));
    }
    svg.append(node("svg:polyline", { class: "since",
      points: points.map((p) => `${x(p[0]).toFixed(2)},${y(p[1]).toFixed(2)}`).join(" ") }));
    if (data.forecast) {
      const [from, to] = data.forecast;
      svg.append(node("svg:line", { class: "forecast", x1: x(from[0]), y1: y(from[1]),
        x2: x(to[0]), y2: y(to[1]) }));
    }
    svg.append(node("svg:text", { x: PAD.left, y: HEIGHT - 3, class: "axis" }, day(start)));
    svg.append(node("svg:text", { x: WIDTH - PAD.right, y: HEIGHT - 3, class: "axis end" }, day(end)));
    return svg;
  }

  function when(tool) {
    const told = tool.forecast;
    if (told.state === "due") return node("span", { class: "due" }, "due now");
    if (told.state !== "forecast") return node("span", { class: "none" }, told.reason || "no date");
    return node("span", {}, `due ${utc(told.due_ns)} UTC`,
      node("div", { class: "interval-text" },
        `80 %: ${day(told.early_ns)} – ${day(told.late_ns)}; ` +
        `${number(told.production_days)} production days`),
      told.service_by_ns ? node("div", { class: "plan" }, `plan by the shift change ${utc(told.service_by_ns)}`) : "");
  }

  function most(tool) {
    const top = tool.wears_it_most;
    const parts = [];
    if (top) {
      const joint = top.joint ? `, ${top.joint}` : "";
      parts.push(node("div", {}, `program ${top.program_id} at ${top.station}${joint}: ${(100 * top.share).toFixed(0)} %`));
    }
    for (const line of tool.unusual) parts.push(node("div", { class: "unusual" }, line));
    return parts.length ? node("div", {}, ...parts) : "-";
  }

  function draw(board) {
    const tools = board.tools_due || [];
    const rows = tools.map((tool) => {
      const told = tool.forecast;
      const runs = told.runs_left === null ? "-" : told.runs_left +
        (told.runs_left_low !== null && told.runs_left_high !== null
          ? ` (${told.runs_left_low}–${told.runs_left_high})` : "");
      return node("tr", { class: "due-tool", "data-tool": tool.tool_id, "data-state": told.state },
        node("td", { class: "num" }, `tool ${tool.tool_id}`, node("div", { class: "stations" }, tool.stations.join(", "))),
        node("td", {}, when(tool)),
        node("td", { class: "num" }, runs),
        node("td", {}, most(tool)),
        node("td", {}, chart(tool)));
    });
    const parts = [node("h2", {}, "Tools due soonest")];
    if (rows.length) {
      parts.push(node("table", {}, node("tr", {}, ...["tool", "service", "runs left", "wears it most", "intensity since service"]
        .map((h) => node("th", {}, h))), ...rows));
    } else {
      parts.push(node("p", { class: "none" }, "no tool in the wear ledger yet"));
    }
    section.replaceChildren(...parts);
  }

  fetch("/board.json").then((r) => r.json()).then(draw).catch(() => {});
  // the board dashboard.js receives (its EventSource, /events): one stream for the page
  const stream = typeof events !== "undefined" ? events : new EventSource("/events");
  stream.addEventListener("message", (message) => draw(JSON.parse(message.data)));
})();
