// The frequency-response panel (SPEC §2): one transient run per wind
// frequency ω of u = U₀ sin(ωt), with the deployment, initial state and
// aerostat body of the transient-run form (read by shared/run.js, with its
// plot and solve helpers; this panel does not need transient.js).
// Posts /api/v1/frequency-response (or a job when there are many
// frequencies), plots the peak tip amplitude against ω and a heat map of the
// envelope over (time, ω), and exports CSV. No build step.
"use strict";

import S from "./shared/index.js";
import {
  COLORS, state, num, readSystem, readProfile, readInitial, readBody, clearErrors, showInputErrors,
  fmt, peakEnvelope, log10, pow10, plotSize, makePlot, solve, finish,
} from "./shared/run.js";

(function () {
  // What this panel reads from the system card (shared/system.js): as the
  // transient run, the tether, the aerostat and gravity in calm air, and the
  // card's starting length (replaced by the transient form's L₀).
  const CARD = S.declareCard("frequency", [
    "cable.preset", "cable.diameter_m if preset", "cable.mass_per_length_kg_m", "cable.breaking_strength_n",
    "aerostat.preset", "aerostat.net_buoyancy_n", "aerostat.mass_kg",
    "gravity_m_s2", "initial_length_m",
  ]);
  const frForm = document.getElementById("fr-form");
  if (!frForm || typeof uPlot === "undefined") return;
  const { colour, ticks, inputLines, sig } = S;
  const download = (text, name) => S.download(text, name, "text/csv");
  const $ = (sel) => document.querySelector(sel);
  // The server answers at most this many frequencies directly (api/solve.rs,
  // MAX_SYNC_FREQUENCIES); more run as a job.
  const SYNC_FREQUENCIES = 16;

  function readFrequencyRequest(errors) {
    const req = readSystem(errors, CARD);
    req.profile = readProfile(errors);
    req.duration_s = num("duration_s", errors);
    req.initial = readInitial(errors);
    req.aero = readBody(errors);
    req.wind_amplitude_m_s = num("wind_amplitude_m_s", errors);
    req.frequencies_rad_s = {
      min: num("frequencies_rad_s.min", errors),
      max: num("frequencies_rad_s.max", errors),
      count: num("frequencies_rad_s.count", errors, { integer: true }),
    };
    return req;
  }

  const frWantsJob = (req) => (req.frequencies_rad_s.count || 0) > SYNC_FREQUENCIES;
  const setFrStatus = S.statusSetter($("#fr-status"), $("#fr-results"));
  const frJob = S.jobRunner("fr-", { log: state.fr.jobProgress, slot: state.jobs.fr });

  // ---------- the heat map of the envelope over (time, ω) ----------


  const heat = { layout: null, cache: null };

  // The envelope drawn: the API's (max |y| over each output interval), or by
  // default straight lines through its peaks, at most two per forcing period.
  function heatValues(res) {
    const smooth = $("#fr-smooth").checked;
    if (!smooth) return res.envelope_m;
    if (heat.cache?.res === res) return heat.cache.values;
    const t = res.time_s;
    const dt = t.length > 1 ? (t[t.length - 1] - t[0]) / (t.length - 1) : 1;
    const values = res.envelope_m.map((row, i) => {
      const w = res.frequencies_rad_s[i];
      const spacing = w > 0 ? Math.PI / w / 2 : 2 * dt;
      return peakEnvelope(row.map((v) => (Number.isFinite(v) ? v : 0)), Math.max(1, Math.round(spacing / dt)));
    });
    heat.cache = { res, values };
    return values;
  }

  function drawHeatmap() {
    const canvas = $("#fr-heatmap");
    const res = state.fr.result;
    const wrap = canvas.parentElement;
    const cssW = Math.max(260, Math.floor(wrap.clientWidth));
    const cssH = Math.round(Math.min(320, Math.max(220, cssW * 0.5)));
    const dpr = window.devicePixelRatio || 1;
    canvas.width = Math.round(cssW * dpr);
    canvas.height = Math.round(cssH * dpr);
    canvas.style.height = `${cssH}px`;
    const ctx = canvas.getContext("2d");
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.fillStyle = "#fff";
    ctx.fillRect(0, 0, cssW, cssH);
    if (!res) return;
    const narrow = cssW < 480;
    const m = { left: 52, right: narrow ? 58 : 74, top: 8, bottom: 38 };
    const pw = cssW - m.left - m.right;
    const ph = cssH - m.top - m.bottom;
    const w = res.frequencies_rad_s;
    const t = res.time_s;
    const E = heatValues(res);
    // Colour: linear in |y| from 0, or log₁₀|y| over the decades present
    // (automatic when a run diverged).
    const logColour = $("#fr-log").checked;
    let max = 0;
    let minPos = Infinity;
    for (const row of E) {
      for (const v of row) {
        if (!Number.isFinite(v)) continue;
        max = Math.max(max, v);
        if (v > 0) minPos = Math.min(minPos, v);
      }
    }
    if (!(max > 0)) max = 1;
    const lo = logColour ? Math.log10(Math.max(minPos, max * 1e-300)) : 0;
    const hi = logColour ? Math.log10(max) : max;
    const scaleOf = (v) => (logColour ? (v > 0 ? (Math.log10(v) - lo) / (hi - lo || 1) : 0) : v / max);
    // Cells: one pixel per (time, frequency) in an offscreen image, scaled up.
    S.heatCells(ctx, { m, pw, ph, columns: t.length, rows: w.length }, (j, i) => {
      const v = E[i][j];
      return Number.isFinite(v) ? colour(scaleOf(v)) : [200, 200, 200];
    });
    ctx.strokeStyle = "#333";
    ctx.lineWidth = 1;
    ctx.strokeRect(m.left + 0.5, m.top + 0.5, pw - 1, ph - 1);

    // Axes. Cell i spans [ω_i − dω/2, ω_i + dω/2] (likewise in time).
    const dw = w.length > 1 ? (w[w.length - 1] - w[0]) / (w.length - 1) : Math.max(1e-3, Math.abs(w[0]) * 0.1 || 1);
    const dt = t.length > 1 ? (t[t.length - 1] - t[0]) / (t.length - 1) : 1;
    const w0 = w[0] - dw / 2, w1 = w[w.length - 1] + dw / 2;
    const t0 = t[0] - dt / 2, t1 = t[t.length - 1] + dt / 2;
    const xOf = (v) => m.left + ((v - t0) / (t1 - t0)) * pw;
    const yOf = (v) => m.top + ph - ((v - w0) / (w1 - w0)) * ph;
    heat.layout = { m, pw, ph, w, t, E, t0, t1, w0, w1, max };
    S.heatFrame(ctx, {
      m, pw, ph, xOf, yOf,
      xTicks: ticks(Math.max(0, t[0]), t[t.length - 1], narrow ? 4 : 8), yTicks: ticks(w[0], w[w.length - 1], 5),
      fmtX: (v) => fmt(v), fmtY: (v) => fmt(v),
      xLabel: "Time t (s)", yLabel: "ω (rad/s)", xLabelDy: 21,
    });

    // Colour bar.
    const bx = m.left + pw + 10;
    const bw = 12;
    S.heatScale(ctx, {
      x: bx, top: m.top, w: bw, h: ph, lo, hi: hi === lo ? lo + 1 : hi,
      ticks: ticks(lo, hi, 5).filter((v) => !logColour || Number.isInteger(v)),
      text: (v) => (logColour ? (v >= -2 && v <= 3 ? fmt(10 ** v, 2) : `1e${v}`) : fmt(v, 2)),
    });
    ctx.textAlign = "center";
    ctx.textBaseline = "top";
    ctx.fillText("|y| (m)", bx + bw / 2 + (narrow ? 14 : 18), m.top + ph + 21);
  }

  function heatReadout(ev) {
    const L = heat.layout;
    const out = $("#fr-heat-readout");
    if (!L) return;
    const rect = ev.target.getBoundingClientRect();
    const x = ev.clientX - rect.left - L.m.left;
    const y = ev.clientY - rect.top - L.m.top;
    if (x < 0 || y < 0 || x > L.pw || y > L.ph) {
      out.innerHTML = "&nbsp;";
      return;
    }
    const j = Math.min(L.t.length - 1, Math.floor((x / L.pw) * L.t.length));
    const i = Math.min(L.w.length - 1, Math.floor(((L.ph - y) / L.ph) * L.w.length));
    out.textContent = `t = ${fmt(L.t[j])} s, ω = ${fmt(L.w[i])} rad/s: envelope ${fmt(L.E[i][j])} m`;
  }
  $("#fr-smooth").addEventListener("change", drawHeatmap);
  $("#fr-log").addEventListener("change", drawHeatmap);
  $("#fr-heatmap").addEventListener("mousemove", heatReadout);
  $("#fr-heatmap").addEventListener("mouseleave", () => ($("#fr-heat-readout").innerHTML = "&nbsp;"));

  function renderFrequency(res, req, via) {
    state.fr.result = res;
    state.fr.request = req;
    state.fr.via = via;
    const peak = res.envelope_m.map((row) => row.reduce((a, v) => (Number.isFinite(v) ? Math.max(a, v) : a), 0));
    state.fr.peak = { frequencies_rad_s: res.frequencies_rad_s.slice(), peak_m: peak };
    $("#fr-log").checked = res.outcomes.includes("diverged");
    state.fr.plot?.destroy();
    // Diverged runs peak at up to 1e100 m: then the peaks go on a log scale.
    const log = res.outcomes.includes("diverged");
    state.fr.plot = makePlot(
      $("#fr-plot-peak"),
      [
        { label: "ω (rad/s)", value: (u, v) => fmt(v, 4) },
        { label: "peak tip amplitude (m)", stroke: COLORS.tip, width: 2, points: { show: true, size: 7, fill: COLORS.tip }, value: log ? pow10 : (u, v) => fmt(v) },
      ],
      [res.frequencies_rad_s, log ? log10(peak) : peak],
      "Wind frequency ω (rad/s)",
      log ? "Peak amplitude (m), log scale" : "Peak amplitude (m)",
      { log },
    );
    drawHeatmap();
    $("#fr-csv").disabled = false;
    const best = peak.indexOf(Math.max(...peak));
    const bad = res.outcomes.filter((o) => o !== "completed").length;
    setFrStatus(
      "ready",
      `${res.frequencies_rad_s.length} frequencies × ${res.time_s.length} times; largest peak ${fmt(peak[best])} m at ω = ${fmt(res.frequencies_rad_s[best])} rad/s` +
        `${bad ? `; ${bad} run(s) did not complete (${[...new Set(res.outcomes.filter((o) => o !== "completed"))].join(", ")})` : ""}` +
        `${via && via !== "direct" ? ` (${via})` : ""}.`,
    );
  }

  // ---------- submitting ----------

  let frBusy = false;
  frForm.addEventListener("submit", async (ev) => {
    ev.preventDefault();
    if (frBusy) return;
    clearErrors();
    S.showFormError($("#fr-form-error"), "");
    S.writeUrl();
    const errors = [];
    const req = readFrequencyRequest(errors);
    if (errors.length) return showInputErrors(errors, setFrStatus);
    frBusy = true;
    $("#fr-run").disabled = true;
    try {
      const n = req.frequencies_rad_s.count;
      const outcome = await solve("/api/v1/frequency-response", "frequency_response", req, frWantsJob(req), setFrStatus, frJob, `${n} frequencies`);
      finish(outcome, (res) => renderFrequency(res, req, outcome.via), setFrStatus, $("#fr-form-error"));
    } finally {
      frBusy = false;
      $("#fr-run").disabled = false;
    }
  });

  function updateFrequencyHint() {
    const fe = [];
    const fr = readFrequencyRequest(fe);
    const n = fr.frequencies_rad_s.count;
    $("#fr-hint").textContent = fe.length ? "" : `${n} run${n === 1 ? "" : "s"}${frWantsJob(fr) ? " · runs as a background job" : ""}`;
  }
  frForm.addEventListener("input", (ev) => {
    if (ev.target.matches("input")) S.clearFieldError(ev.target);
    S.writeUrl();
    if (state.fr.result && $("#fr-status").dataset.state === "ready") setFrStatus("stale", "Inputs changed: sweep again.");
    updateFrequencyHint();
  });
  // The transient form's inputs (deployment, initial state, body) and the
  // chart form's elements are this panel's too; so is the system card.
  const transientForm = $("#transient-form");
  transientForm?.addEventListener("input", updateFrequencyHint);
  transientForm?.addEventListener("change", updateFrequencyHint);
  $("#chart-form")?.addEventListener("input", updateFrequencyHint);
  document.addEventListener("tetherplan:system-input", updateFrequencyHint);

  let resizeTimer = null;
  window.addEventListener("resize", () => {
    clearTimeout(resizeTimer);
    resizeTimer = setTimeout(() => {
      state.fr.plot?.setSize(plotSize($("#fr-plot-peak")));
      drawHeatmap();
    }, 100);
  });

  // ---------- downloads ----------

  $("#fr-csv").addEventListener("click", () => {
    const r = state.fr.result;
    if (!r) return;
    const lines = ["# tetherplan frequency response", ...inputLines(state.fr.request), "angular_frequency_rad_s,time_s,envelope_m"];
    r.frequencies_rad_s.forEach((w, i) => r.time_s.forEach((t, j) => lines.push(`${sig(w)},${sig(t)},${sig(r.envelope_m[i][j])}`)));
    download(lines.join("\n") + "\n", "frequency-response.csv");
  });

  drawHeatmap();
  updateFrequencyHint();
})();
