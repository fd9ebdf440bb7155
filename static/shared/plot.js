// The page's plotting helpers, shared by every panel: number formats, legend
// values, uPlot with the page's axes, decade ticks on log axes, round tick
// values, the viridis colour map, and the cells, frame and colour bar of the
// heat maps (envelope, frequency response).
"use strict";

import shared from "./core.js";

(function (shared) {
  // Fixed decimals (large values in exponent form).
  function fixed(v, digits = 1) {
    if (v == null || !Number.isFinite(v)) return "–";
    return Math.abs(v) >= 1e5 ? v.toExponential(3) : v.toFixed(digits);
  }

  // Significant digits (very large and very small values in exponent form).
  function sig3(v, digits = 3) {
    if (v == null || !Number.isFinite(v)) return "–";
    const a = Math.abs(v);
    if (a !== 0 && (a >= 1e6 || a < 1e-3)) return v.toExponential(digits - 1);
    return Number(v.toPrecision(digits)).toString();
  }

  // Legend values: blank until the cursor is on the plot (not a row of "–").
  const legendValue = (digits) => (u, v) => (v == null ? "" : fixed(v, digits));

  function plotSize(el, { aspect = 0.6, min = 240, max = 380, minWidth = 260 } = {}) {
    const width = Math.max(minWidth, Math.floor(el.clientWidth || 300));
    return { width, height: Math.round(Math.min(max, Math.max(min, width * aspect))) };
  }

  // On a log axis, grid lines and ticks at the decades only (uPlot draws 1..9 × 10^k).
  const decadesOnly = (u, splits) =>
    splits.map((v) => (v != null && Math.abs(Math.log10(v) - Math.round(Math.log10(v))) < 1e-9 ? v : null));

  const AXIS = { stroke: "#333", grid: { stroke: "#e5e5e5" }, ticks: { stroke: "#ccc" } };

  // A uPlot in `el` (emptied first): x against one y axis, legend live, drag-zoom on x.
  function makePlot(el, { series, data, xLabel, yLabel, log = false, size, bands, legendDash = true, extra = {} }) {
    el.textContent = "";
    const yAxis = log ? { ...AXIS, grid: { ...AXIS.grid, filter: decadesOnly }, ticks: { ...AXIS.ticks, filter: decadesOnly }, filter: decadesOnly } : AXIS;
    return new uPlot(
      {
        ...(size || plotSize(el)),
        series,
        scales: { x: { time: false }, y: log ? { distr: 3 } : {} },
        axes: [
          { ...AXIS, label: xLabel },
          { ...yAxis, label: yLabel, size: 60 },
        ],
        legend: legendDash ? { live: true, markers: { dash: (u, i) => (u.series[i].dash ? "dashed" : "solid"), fill: () => "transparent" } } : { live: true },
        cursor: { drag: { x: true, y: false } },
        ...(bands ? { bands } : {}),
        ...extra,
      },
      data,
      el,
    );
  }

  // About `n` round tick values covering [lo, hi].
  function ticks(lo, hi, n) {
    if (!(hi > lo)) return [lo];
    const raw = (hi - lo) / n;
    const mag = 10 ** Math.floor(Math.log10(raw));
    const step = [1, 2, 5, 10].map((m) => m * mag).find((s) => s >= raw) || 10 * mag;
    const out = [];
    for (let v = Math.ceil(lo / step - 1e-9) * step; v <= hi + step * 1e-9; v += step) out.push(Number(v.toPrecision(12)));
    return out;
  }

  // Viridis, sampled at 9 stops; s in [0, 1] → [r, g, b].
  const VIRIDIS = [
    [68, 1, 84], [71, 44, 122], [59, 81, 139], [44, 113, 142], [33, 144, 141],
    [39, 173, 129], [92, 200, 99], [170, 220, 50], [253, 231, 37],
  ];
  function colour(s) {
    const x = Math.min(1, Math.max(0, s)) * (VIRIDIS.length - 1);
    const i = Math.min(VIRIDIS.length - 2, Math.floor(x));
    const f = x - i;
    return VIRIDIS[i].map((c, k) => Math.round(c + f * (VIRIDIS[i + 1][k] - c)));
  }

  // A vertical colour bar at (x, top) of height h, with `labels` [[s, text]].
  function colourBar(ctx, x, top, w, h, labels) {
    for (let k = 0; k < h; k++) {
      const [r, g, b] = colour(1 - k / h);
      ctx.fillStyle = `rgb(${r},${g},${b})`;
      ctx.fillRect(x, top + k, w, 1);
    }
    ctx.strokeStyle = "#333";
    ctx.strokeRect(x + 0.5, top + 0.5, w - 1, h - 1);
    ctx.fillStyle = "#333";
    ctx.textAlign = "left";
    ctx.textBaseline = "middle";
    for (const [s, text] of labels) {
      const y = top + h - s * h;
      ctx.fillRect(x + w, y, 3, 1);
      ctx.fillText(text, x + w + 5, Math.min(top + h - 5, Math.max(top + 5, y)));
    }
  }

  // The frame of a heat map drawn on a canvas: ticks and values below and
  // left of the plot area (m: margins, pw × ph: its size; xOf/yOf: value →
  // pixel), the x label under them and the y label turned upright.
  function heatFrame(ctx, { m, pw, ph, xOf, yOf, xTicks, yTicks, fmtX, fmtY, xLabel, yLabel, xLabelDy = 22 }) {
    ctx.fillStyle = "#333";
    ctx.font = "11px system-ui, sans-serif";
    ctx.textAlign = "center";
    ctx.textBaseline = "top";
    for (const v of xTicks) {
      const x = xOf(v);
      if (x < m.left - 0.5 || x > m.left + pw + 0.5) continue;
      ctx.fillRect(x, m.top + ph, 1, 4);
      ctx.fillText(fmtX(v), x, m.top + ph + 6);
    }
    ctx.fillText(xLabel, m.left + pw / 2, m.top + ph + xLabelDy);
    ctx.textAlign = "right";
    ctx.textBaseline = "middle";
    for (const v of yTicks) {
      const y = yOf(v);
      if (y < m.top - 0.5 || y > m.top + ph + 0.5) continue;
      ctx.fillRect(m.left - 4, y, 4, 1);
      ctx.fillText(fmtY(v), m.left - 6, y);
    }
    ctx.save();
    ctx.translate(12, m.top + ph / 2);
    ctx.rotate(-Math.PI / 2);
    ctx.textAlign = "center";
    ctx.fillText(yLabel, 0, 0);
    ctx.restore();
  }

  // The cells of a heat map: one pixel per (column i, row j) in an
  // offscreen image (row 0 at the bottom), scaled up to the plot area
  // without smoothing; rgb(i, j) gives each cell's colour.
  function heatCells(ctx, { m, pw, ph, columns, rows }, rgb) {
    const img = document.createElement("canvas");
    img.width = columns;
    img.height = rows;
    const ictx = img.getContext("2d");
    const data = ictx.createImageData(columns, rows);
    for (let i = 0; i < columns; i++) {
      for (let j = 0; j < rows; j++) {
        const [r, g, b] = rgb(i, j);
        const k = 4 * ((rows - 1 - j) * columns + i);
        data.data[k] = r;
        data.data[k + 1] = g;
        data.data[k + 2] = b;
        data.data[k + 3] = 255;
      }
    }
    ictx.putImageData(data, 0, 0);
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(img, m.left, m.top, pw, ph);
  }

  // A colour bar for values lo…hi (bottom to top) with a tick and `text(v)`
  // at each of `ticks`.
  function heatScale(ctx, { x, top, w, h, lo, hi, ticks: at, text }) {
    colourBar(ctx, x, top, w, h, at.map((v) => [(v - lo) / (hi - lo || 1), text(v)]));
  }

  Object.assign(shared, { fixed, sig3, legendValue, plotSize, decadesOnly, makePlot, ticks, colour, colourBar, heatCells, heatFrame, heatScale });
})(shared);
