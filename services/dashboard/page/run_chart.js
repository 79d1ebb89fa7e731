// The line's page: a small chart of its own on a canvas, for a run's curves (run_view.js).
// One chart draws what a spec holds, in data units:
//   lines    [{x, y, color, width, dash, label, main}] a curve (null breaks it); the one
//                                                      marked main (else the first) is read out
//   bands    [{x, low, high, color, label}]           a filled band between two curves
//   boxes    [{x: [a, b], y: [c, d], color, label}]   a window (a null side: the plot's edge)
//   hlines   [{y, color, dash, label}], vlines [{x, color, dash, label}]
//   segments [{x0, x1, y, color, label}]              a plateau over its stick phase
//   points   [{x, y, color, shape, label}]            a mark ("down": a peak, "dot")
// Drag across it to zoom in on x, double-click to see it all again; the pointer's nearest
// sample of the first line is read out below it. Everything stays on the page: no library.
"use strict";

const CHART_PAD = { left: 58, right: 12, top: 10, bottom: 34 };
const TICKS = 6;

function niceStep(span, count) {
  const raw = span / Math.max(1, count);
  const power = 10 ** Math.floor(Math.log10(raw));
  const unit = raw / power;
  return power * (unit < 1.5 ? 1 : unit < 3 ? 2 : unit < 7 ? 5 : 10);
}

function tickText(value, step) {
  const decimals = Math.max(0, -Math.floor(Math.log10(step) + 1e-9));
  return value.toFixed(Math.min(decimals, 6));
}

function finiteRange(values, range) {
  for (const v of values) {
    if (v === null || v === undefined || !Number.isFinite(v)) continue;
    if (v < range[0]) range[0] = v;
    if (v > range[1]) range[1] = v;
  }
  return range;
}

class RunChart {
  constructor(parent, title, xLabel, yLabel) {
    this.xLabel = xLabel;
    this.yLabel = yLabel;
    this.box = el("figure", { class: "chart" }, el("figcaption", {}, title));
    this.canvas = el("canvas", { role: "img", "aria-label": title });
    this.readout = el("div", { class: "readout" }, "\u00a0");
    this.legend = el("ul", { class: "legend" });
    this.box.append(this.canvas, this.readout, this.legend);
    parent.append(this.box);
    this.spec = null;
    this.zoom = null; // [x0, x1] or null: everything
    this.drag = null;
    this.canvas.addEventListener("mousedown", (e) => { this.drag = { from: e.offsetX, to: e.offsetX }; });
    this.canvas.addEventListener("mousemove", (e) => this.pointer(e));
    this.canvas.addEventListener("mouseup", () => this.zoomTo());
    this.canvas.addEventListener("mouseleave", () => { this.drag = null; this.render(); });
    this.canvas.addEventListener("dblclick", () => { this.zoom = null; this.render(); });
    new ResizeObserver(() => this.render()).observe(this.canvas);
  }

  draw(spec) {
    this.spec = { lines: [], bands: [], boxes: [], hlines: [], vlines: [], segments: [], points: [], ...spec };
    this.zoom = null;
    const main = this.main();
    this.canvas.dataset.points = main ? String(main.x.length) : "0";
    this.canvas.dataset.lines = String(this.spec.lines.length);
    this.drawLegend();
    this.render();
  }

  main() {
    return this.spec.lines.find((l) => l.main) || this.spec.lines[0];
  }

  ranges() {
    const s = this.spec;
    const x = [Infinity, -Infinity];
    for (const l of s.lines) finiteRange(l.x, x);
    for (const b of s.bands) finiteRange(b.x, x);
    if (this.zoom) [x[0], x[1]] = this.zoom;
    const y = [Infinity, -Infinity];
    const inside = (xv) => xv >= x[0] && xv <= x[1];
    for (const l of s.lines) l.y.forEach((v, n) => { if (inside(l.x[n])) finiteRange([v], y); });
    for (const b of s.bands) b.x.forEach((xv, n) => { if (inside(xv)) finiteRange([b.low[n], b.high[n]], y); });
    for (const p of s.points) if (inside(p.x)) finiteRange([p.y], y);
    for (const h of s.hlines) finiteRange([h.y], y);
    for (const b of s.boxes) finiteRange(b.y, y);
    for (const g of s.segments) finiteRange([g.y], y);
    for (const r of [x, y]) {
      if (!Number.isFinite(r[0])) { r[0] = 0; r[1] = 1; }
      if (r[1] - r[0] < 1e-9) { r[0] -= 0.5; r[1] += 0.5; }
    }
    const pad = 0.04 * (y[1] - y[0]);
    return { x, y: [y[0] - pad, y[1] + pad] };
  }

  render() {
    if (!this.spec) return;
    const ratio = window.devicePixelRatio || 1;
    const width = this.canvas.clientWidth, height = this.canvas.clientHeight;
    if (width === 0 || height === 0) return;
    this.canvas.width = Math.round(width * ratio);
    this.canvas.height = Math.round(height * ratio);
    const ctx = this.canvas.getContext("2d");
    ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    ctx.clearRect(0, 0, width, height);
    const { x, y } = this.ranges();
    const plot = { left: CHART_PAD.left, top: CHART_PAD.top,
      width: width - CHART_PAD.left - CHART_PAD.right, height: height - CHART_PAD.top - CHART_PAD.bottom };
    const px = (v) => plot.left + ((v - x[0]) / (x[1] - x[0])) * plot.width;
    const py = (v) => plot.top + (1 - (v - y[0]) / (y[1] - y[0])) * plot.height;
    this.frame = { x, y, plot, px, py };
    this.axes(ctx, plot, x, y, px, py);
    ctx.save();
    ctx.beginPath();
    ctx.rect(plot.left, plot.top, plot.width, plot.height);
    ctx.clip();
    const s = this.spec;
    for (const b of s.boxes) {
      const [x0, x1] = [b.x[0] ?? x[0], b.x[1] ?? x[1]], [y0, y1] = [b.y[0] ?? y[0], b.y[1] ?? y[1]];
      ctx.fillStyle = b.color; ctx.globalAlpha = 0.12;
      ctx.fillRect(px(x0), py(y1), px(x1) - px(x0), py(y0) - py(y1));
      ctx.globalAlpha = 1; ctx.strokeStyle = b.color; ctx.lineWidth = 1.5;
      ctx.setLineDash(b.x[0] === null && b.x[1] === null ? [6, 3, 2, 3] : []);
      ctx.strokeRect(px(x0), py(y1), px(x1) - px(x0), py(y0) - py(y1));
    }
    for (const b of s.bands) this.band(ctx, b, px, py);
    for (const h of s.hlines) this.rule(ctx, h, px(x[0]), py(h.y), px(x[1]), py(h.y));
    for (const v of s.vlines) this.rule(ctx, v, px(v.x), py(y[0]), px(v.x), py(y[1]));
    for (const l of s.lines) this.line(ctx, l, px, py);
    for (const g of s.segments) {
      ctx.setLineDash([]); ctx.strokeStyle = g.color; ctx.lineWidth = 3;
      ctx.beginPath(); ctx.moveTo(px(g.x0), py(g.y)); ctx.lineTo(px(g.x1), py(g.y)); ctx.stroke();
    }
    for (const p of s.points) this.point(ctx, p, px(p.x), py(p.y));
    if (this.drag && Math.abs(this.drag.to - this.drag.from) > 2) {
      ctx.fillStyle = "rgba(38, 50, 56, 0.12)";
      ctx.fillRect(Math.min(this.drag.from, this.drag.to), plot.top, Math.abs(this.drag.to - this.drag.from), plot.height);
    }
    ctx.restore();
  }

  axes(ctx, plot, x, y, px, py) {
    ctx.strokeStyle = "#b0bec5"; ctx.fillStyle = "#455a64"; ctx.lineWidth = 1; ctx.setLineDash([]);
    ctx.font = "11px system-ui, sans-serif";
    ctx.strokeRect(plot.left, plot.top, plot.width, plot.height);
    const xStep = niceStep(x[1] - x[0], TICKS), yStep = niceStep(y[1] - y[0], TICKS);
    ctx.textAlign = "center"; ctx.textBaseline = "top";
    for (let v = Math.ceil(x[0] / xStep) * xStep; v <= x[1]; v += xStep) {
      ctx.fillText(tickText(v, xStep), px(v), plot.top + plot.height + 4);
      this.grid(ctx, px(v), plot.top, px(v), plot.top + plot.height);
    }
    ctx.textAlign = "right"; ctx.textBaseline = "middle";
    for (let v = Math.ceil(y[0] / yStep) * yStep; v <= y[1]; v += yStep) {
      ctx.fillText(tickText(v, yStep), plot.left - 5, py(v));
      this.grid(ctx, plot.left, py(v), plot.left + plot.width, py(v));
    }
    ctx.textAlign = "center"; ctx.textBaseline = "bottom";
    ctx.fillText(this.xLabel, plot.left + plot.width / 2, plot.top + plot.height + 32);
    ctx.save(); ctx.translate(12, plot.top + plot.height / 2); ctx.rotate(-Math.PI / 2);
    ctx.textBaseline = "middle"; ctx.fillText(this.yLabel, 0, 0); ctx.restore();
  }

  grid(ctx, x0, y0, x1, y1) {
    ctx.save(); ctx.strokeStyle = "#eceff1"; ctx.beginPath(); ctx.moveTo(x0, y0); ctx.lineTo(x1, y1);
    ctx.stroke(); ctx.restore();
  }

  rule(ctx, r, x0, y0, x1, y1) {
    ctx.strokeStyle = r.color; ctx.lineWidth = r.width || 1.2; ctx.setLineDash(r.dash || []);
    ctx.beginPath(); ctx.moveTo(x0, y0); ctx.lineTo(x1, y1); ctx.stroke();
  }

  line(ctx, l, px, py) {
    ctx.strokeStyle = l.color; ctx.lineWidth = l.width || 1.2; ctx.setLineDash(l.dash || []);
    ctx.beginPath();
    let drawing = false;
    for (let n = 0; n < l.x.length; n++) {
      const xv = l.x[n], yv = l.y[n];
      if (xv === null || yv === null) { drawing = false; continue; }
      if (drawing) ctx.lineTo(px(xv), py(yv)); else { ctx.moveTo(px(xv), py(yv)); drawing = true; }
    }
    ctx.stroke();
  }

  band(ctx, b, px, py) {
    ctx.fillStyle = b.color; ctx.globalAlpha = 0.22;
    let run = [];
    const flush = () => {
      if (run.length > 1) {
        ctx.beginPath();
        run.forEach((n, k) => (k ? ctx.lineTo(px(b.x[n]), py(b.high[n])) : ctx.moveTo(px(b.x[n]), py(b.high[n]))));
        for (let k = run.length - 1; k >= 0; k--) ctx.lineTo(px(b.x[run[k]]), py(b.low[run[k]]));
        ctx.closePath(); ctx.fill();
      }
      run = [];
    };
    for (let n = 0; n < b.x.length; n++) {
      if (b.low[n] === null || b.high[n] === null) flush(); else run.push(n);
    }
    flush();
    ctx.globalAlpha = 1;
  }

  point(ctx, p, x, y) {
    ctx.fillStyle = p.color; ctx.setLineDash([]);
    ctx.beginPath();
    if (p.shape === "down") { ctx.moveTo(x - 5, y - 9); ctx.lineTo(x + 5, y - 9); ctx.lineTo(x, y - 1); }
    else ctx.arc(x, y, 3.5, 0, 2 * Math.PI);
    ctx.closePath(); ctx.fill();
  }

  drawLegend() {
    const seen = new Map();
    const s = this.spec;
    for (const item of [...s.lines, ...s.bands, ...s.boxes, ...s.hlines, ...s.vlines, ...s.segments, ...s.points]) {
      if (item.label && !seen.has(item.label)) seen.set(item.label, item);
    }
    this.legend.replaceChildren(...[...seen.entries()].map(([label, item]) =>
      el("li", {}, el("span", { class: "swatch", style: `background:${item.color}` }), label)));
  }

  pointer(e) {
    if (this.drag) { this.drag.to = e.offsetX; this.render(); return; }
    const f = this.frame, main = this.spec && this.main();
    if (!f || !main || !main.x.length) return;
    const xv = f.x[0] + ((e.offsetX - f.plot.left) / f.plot.width) * (f.x[1] - f.x[0]);
    let best = -1, distance = Infinity;
    for (let n = 0; n < main.x.length; n++) {
      if (main.x[n] === null || main.y[n] === null) continue;
      const d = Math.abs(main.x[n] - xv);
      if (d < distance) { distance = d; best = n; }
    }
    if (best >= 0) {
      const [xv2, yv2] = [main.x[best], main.y[best]];
      this.readout.textContent = `${this.xLabel} ${+xv2.toPrecision(6)} · ${this.yLabel} ${+yv2.toPrecision(6)}`;
    }
  }

  zoomTo() {
    const d = this.drag, f = this.frame;
    this.drag = null;
    if (!d || !f || Math.abs(d.to - d.from) < 6) { this.render(); return; }
    const at = (p) => f.x[0] + ((p - f.plot.left) / f.plot.width) * (f.x[1] - f.x[0]);
    this.zoom = [at(Math.min(d.from, d.to)), at(Math.max(d.from, d.to))];
    this.render();
  }
}
