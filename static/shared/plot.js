// The page's plotting helpers, shared by every panel: number formats, legend
// values, uPlot with the page's axes, decade ticks on log axes, round tick
// values and the viridis colour map of the heat maps.
"use strict";

window.tetherplanShared = window.tetherplanShared || {};

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

  Object.assign(shared, { fixed, sig3, legendValue, plotSize, decadesOnly, makePlot, ticks, colour, colourBar });
})(window.tetherplanShared);
