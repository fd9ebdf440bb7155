// What the transient-run panel (transient.js) and the frequency-response
// panel (frequency.js) share, as an explicit interface: the readers of the
// transient form (deployment, initial state, aerostat body, and the system of
// the string model from the card by the panel's declaration), errors beside
// their fields, the number formats, the peak envelope, the plots with their
// log scale, solving directly or as a job, and the two panels' state (for the
// browser test and the console: window.tetherplanTransient, the frequency
// response under `.fr`). Neither panel imports the other: either works alone,
// loaded in any order.
"use strict";

import S from "./index.js";

const $ = (sel) => document.querySelector(sel);
// Both panels' errors carry this source (each clears the other's too, as one form).
const SOURCE = "transient";
export const COLORS = { tip: "#0072b2", envelope: "#d55e00", energy: "#009e73", vibration: "#cc79a7", freq: "#0072b2", wind: "#d55e00" };

// Shared with the browser test and the console: requests, answers, what is plotted.
export const state = {
  request: null,
  result: null,
  via: null,
  envelope: null,
  resonance: null,
  firstUnstable: null,
  jobProgress: [],
  plots: { tip: null, energy: null, freq: null },
  fr: { request: null, result: null, via: null, peak: null, jobProgress: [], plot: null },
  jobs: { run: {}, fr: {} },
};
window.tetherplanTransient = state;

// ---------- inputs ----------

// This section's inputs first, then the chart form's (elements) and the system card's.
export const roots = [$("#transient"), $("#chart-form"), $("#plan-form")];
export const num = (field, errors, opts) => S.readNumber(roots, field, errors, opts);
const inputFor = (field) => S.inputFor(roots, field);

// What the panel's declaration `card` names from the system card; L0 from the
// transient form; the chart's element count (blank there: the default mesh).
export function readSystem(errors, card) {
  const sys = S.readSystem(errors, card);
  sys.initial_length_m = num("initial_length_m", errors);
  const elements = num("model.elements", errors, { integer: true, optional: true, fallback: 50 });
  sys.model = elements === undefined ? { kind: "linear_string" } : { kind: "linear_string", elements };
  return sys;
}

export function readProfile(errors) {
  const kind = $("#tr-profile").value;
  if (kind === "trapezoidal") {
    return {
      kind,
      cruise_rate_m_s: num("profile.cruise_rate_m_s", errors),
      ramp_up_s: num("profile.ramp_up_s", errors),
      ramp_down_s: num("profile.ramp_down_s", errors),
      target_length_m: num("profile.target_length_m", errors),
    };
  }
  const rate = num("profile.rate_m_s", errors);
  const profile = { kind: "constant_rate", rate_m_s: kind === "shortening" && rate != null ? -Math.abs(rate) : rate };
  const stop = num("profile.target_length_m", errors, { optional: kind !== "shortening" });
  if (stop !== undefined) profile.target_length_m = stop;
  return profile;
}

export function readInitial(errors) {
  const kind = $("#tr-initial").value;
  if (kind === "shape") return { kind, tip_deflection_m: num("initial.tip_deflection_m", errors) };
  if (kind === "tip_force") return { kind, force_n: num("initial.force_n", errors), duration_s: num("initial.duration_s", errors) };
  return { kind: "rest" };
}

// The aerostat as an aerodynamic body (AeroBodyInput): the sphere radius
// from this panel; the drag coefficient, reference area and air density
// from the system card (the numbers the plan and the envelope use).
const cardRoots = () => [$("#system-card"), $("#plan-form")];
// Where the API's `aero` fields are entered on the page.
const CARD_FIELDS = {
  "aero.model.drag_coefficient_nondim": "aerostat.drag_coefficient_nondim",
  "aero.model.reference_area_m2": "aerostat.reference_area_m2",
  "aero.air_density_kg_m3": "wind.air_density_kg_m3",
};
export function readBody(errors) {
  const fromCard = (name, opts) => S.readNumber(cardRoots(), name, errors, opts);
  const model = $("#tr-force-model").value === "drag"
    ? S.compact({
        kind: "drag",
        drag_coefficient_nondim: fromCard("aerostat.drag_coefficient_nondim"),
        reference_area_m2: fromCard("aerostat.reference_area_m2", { optional: true }),
      })
    : { kind: "thesis" };
  return { model, radius_m: num("aero.radius_m", errors), air_density_kg_m3: fromCard("wind.air_density_kg_m3") };
}

// ---------- errors next to fields ----------

export const clearErrors = () => S.clearErrors(SOURCE);
// Renders an API error body next to its field (or in `fallback`); returns a summary.
export function renderApiError(status, body, fallback) {
  const field = body?.error?.field;
  const onCard = field && Object.keys(CARD_FIELDS).find((k) => field === k || field.startsWith(`${k}.`));
  if (onCard) {
    body = { ...body, error: { ...body.error, field: CARD_FIELDS[onCard] } };
    const text = S.renderApiError(cardRoots(), status, body, fallback, SOURCE);
    return `Fix the highlighted field (in the system card above): ${text}`;
  }
  const input = inputFor(field);
  const text = S.renderApiError(roots, status, body, fallback, SOURCE);
  if (!input) return text;
  const where = input.closest("#transient") ? "" : input.closest("#chart-form") ? " (in the chart form above)" : " (in the system card above)";
  return `Fix the highlighted field${where}: ${text}`;
}
export function showInputErrors(errors, statusFn) {
  S.showInputErrors(roots, errors, SOURCE);
  statusFn("error", "Fix the highlighted fields.");
}

// ---------- numbers ----------

export function fmt(v, digits = 3) {
  if (v == null || !Number.isFinite(v)) return "–";
  const a = Math.abs(v);
  return a !== 0 && (a >= 1e5 || a < 1e-3) ? v.toExponential(digits - 1) : S.sig3(v, digits);
}

// Centered sliding maximum of `values` over `half` samples either side.
function slidingMax(values, half) {
  const n = values.length;
  const out = new Array(n);
  // Monotone deque: O(n).
  const dq = [];
  let head = 0;
  let next = 0;
  for (let i = 0; i < n; i++) {
    const hi = Math.min(n - 1, i + half);
    while (next <= hi) {
      while (dq.length > head && values[dq[dq.length - 1]] <= values[next]) dq.pop();
      dq.push(next++);
    }
    while (dq[head] < i - half) head++;
    out[i] = values[dq[head]];
  }
  return out;
}

// An upper envelope of |y|: straight lines through its dominant peaks (the
// samples that are the largest within `half` samples either side), never
// below |y| itself.
export function peakEnvelope(abs, half) {
  const n = abs.length;
  if (n < 3) return abs.slice();
  const local = slidingMax(abs, half);
  const peaks = [0];
  for (let i = 1; i < n - 1; i++) if (abs[i] > 0 && abs[i] === local[i] && i - peaks[peaks.length - 1] > half) peaks.push(i);
  const out = new Array(n);
  for (let k = 1; k < peaks.length; k++) {
    const a = peaks[k - 1];
    const b = peaks[k];
    for (let i = a; i <= b; i++) {
      const line = abs[a] + ((abs[b] - abs[a]) * (i - a)) / (b - a || 1);
      out[i] = Math.max(line, abs[i]);
    }
  }
  // After the last peak: hold it (the run ends mid-swing).
  const last = peaks[peaks.length - 1];
  for (let i = last; i < n; i++) out[i] = Math.max(abs[last], abs[i]);
  return out;
}

// ---------- plots ----------

const axis = { stroke: "#333", grid: { stroke: "#e5e5e5" }, ticks: { stroke: "#ccc" } };

// Log scale: uPlot's log axes find no ticks across the 60 decades of a
// diverged run, so the data are plotted as log₁₀ on a linear axis whose
// labels and legend values are shown as powers of ten.
export const log10 = (a) => a.map((v) => (v > 0 ? Math.log10(v) : null));
// 10^k as a short label: 0.01 … 10000 plainly, else 1e60 or 3.2e59.
function powLabel(k, digits = 2) {
  if (k >= -2 && k <= 4) return String(Number((10 ** k).toPrecision(digits)));
  const e = Math.floor(k + 1e-9);
  const m = Number((10 ** (k - e)).toPrecision(digits));
  return m === 1 ? `1e${e}` : m >= 10 ? `1e${e + 1}` : `${m}e${e}`;
}
export const pow10 = (u, v) => (v == null ? "–" : powLabel(v, 3));
const logAxis = { ...axis, values: (u, splits) => splits.map((v) => powLabel(v)) };

export const plotSize = (el, aspect = 0.6) => S.plotSize(el, { aspect, max: 340 });

export function makePlot(el, series, data, xLabel, yLabel, extra = {}) {
  el.textContent = "";
  // Legend values: blank until the cursor is on the plot (not a row of "–").
  const blankIdle = series.map((s) => (s.value ? { ...s, value: (u, v, ...rest) => (v == null ? "" : s.value(u, v, ...rest)) } : s));
  return new uPlot(
    {
      ...plotSize(el),
      series: blankIdle,
      scales: { x: { time: false } },
      axes: [
        { ...axis, label: xLabel },
        extra.log ? { ...logAxis, label: yLabel, size: 62 } : { ...axis, label: yLabel, size: 62 },
      ],
      legend: { live: true, markers: { dash: (u, i) => (u.series[i].dash ? "dashed" : "solid"), fill: () => "transparent" } },
      cursor: { drag: { x: true, y: false } },
      plugins: extra.plugins || [],
    },
    data,
    el,
  );
}

// ---------- solving ----------

// Runs `req` directly or as a job; resolves to {result, via} or {status, error}.
export async function solve(path, kind, req, useJob, setStatus, job, what) {
  if (useJob) {
    setStatus("busy", `Submitting a job (${what})…`);
    return job(kind, req, what, setStatus);
  }
  setStatus("busy", `Computing (${what})…`);
  const r = await S.api("POST", path, req);
  if (S.needsJob(r)) {
    setStatus("busy", "The server asked for a background job…");
    return job(kind, req, what, setStatus);
  }
  return r.ok ? { result: r.body, via: "direct" } : { status: r.status, error: r.body };
}

export function finish(outcome, render, setStatus, errorEl) {
  if (outcome.result) render(outcome.result);
  else if (outcome.error?.error?.code === "cancelled") setStatus("idle", "Job cancelled.");
  else setStatus("error", renderApiError(outcome.status, outcome.error, errorEl));
}
