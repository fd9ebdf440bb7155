// The live-flight panel's small plots (live.js): lines of [x, y] points and
// horizontal threshold lines drawn as SVG at the element's width, with the
// y range's ends and middle and the x range's ends labelled. SVG rather than
// canvas: it prints sharp and redraws cheaply at a few hertz.
"use strict";

const NS = "http://www.w3.org/2000/svg";

function node(name, attrs, text) {
  const el = document.createElementNS(NS, name);
  for (const [k, v] of Object.entries(attrs)) el.setAttribute(k, String(v));
  if (text != null) el.textContent = text;
  return el;
}

const round = (v) => (Math.abs(v) >= 100 ? v.toFixed(0) : Math.abs(v) >= 10 ? v.toFixed(1) : v.toFixed(2));

// `lines`: [{points: [[x, y], …], cls}]; `levels`: [{y, cls, label}];
// `label`: what the plot shows (its aria-label); `unit`: of y; `width`: the
// drawing's width (default the element's); `xMax`: points past it left out.
export function linePlot(el, { lines, levels = [], label, unit, height = 150, width, xMax = Infinity }) {
  const w = Math.max(220, Math.floor(width || el.clientWidth || 320));
  const m = { l: 52, r: 8, t: 8, b: 20 };
  const xs = [];
  const ys = [];
  const shown = (x, y) => Number.isFinite(x) && Number.isFinite(y) && x <= xMax;
  for (const l of lines) for (const [x, y] of l.points) if (shown(x, y)) (xs.push(x), ys.push(y));
  for (const l of levels) if (Number.isFinite(l.y)) ys.push(l.y);
  const svg = node("svg", { viewBox: `0 0 ${w} ${height}`, width: w, height, role: "img", "aria-label": label, class: "live-svg" });
  el.replaceChildren(svg);
  if (!xs.length) {
    svg.append(node("text", { x: w / 2, y: height / 2, "text-anchor": "middle", class: "empty" }, "no data yet"));
    return;
  }
  let [x0, x1] = [Math.min(...xs), Math.max(...xs)];
  let [y0, y1] = [Math.min(...ys), Math.max(...ys)];
  if (x1 - x0 < 1e-9) x1 = x0 + 1;
  if (y1 - y0 < 1e-9) (y0 -= 1, y1 += 1);
  const pad = 0.05 * (y1 - y0);
  (y0 -= pad), (y1 += pad);
  const X = (x) => m.l + ((x - x0) / (x1 - x0)) * (w - m.l - m.r);
  const Y = (y) => m.t + (1 - (y - y0) / (y1 - y0)) * (height - m.t - m.b);
  svg.append(node("rect", { x: m.l, y: m.t, width: w - m.l - m.r, height: height - m.t - m.b, class: "frame" }));
  for (const v of [y0 + pad, (y0 + y1) / 2, y1 - pad]) {
    svg.append(node("text", { x: m.l - 4, y: Y(v) + 4, "text-anchor": "end", class: "tick" }, `${round(v)}`));
  }
  svg.append(node("text", { x: 2, y: m.t + 10, class: "tick unit" }, unit));
  svg.append(node("text", { x: m.l, y: height - 4, class: "tick" }, `${round(x0)} s`));
  svg.append(node("text", { x: w - m.r, y: height - 4, "text-anchor": "end", class: "tick" }, `${round(x1)} s`));
  for (const l of levels) {
    if (!Number.isFinite(l.y)) continue;
    svg.append(node("line", { x1: m.l, x2: w - m.r, y1: Y(l.y), y2: Y(l.y), class: `level ${l.cls}` }));
    svg.append(node("text", { x: w - m.r - 2, y: Y(l.y) - 3, "text-anchor": "end", class: `tick ${l.cls}` }, l.label));
  }
  for (const l of lines) {
    const pts = l.points.filter(([x, y]) => shown(x, y));
    if (!pts.length) continue;
    const d = pts.map(([x, y], i) => `${i ? "L" : "M"}${X(x).toFixed(1)},${Y(y).toFixed(1)}`).join("");
    svg.append(node("path", { d, class: `line ${l.cls}`, "data-points": pts.length }));
  }
}
