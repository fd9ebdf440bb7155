// The transient-run panel of the page (SPEC §2): reads its form (with the
// tether, aerostat and gravity of the system card), asks POST /api/v1/simulate
// (directly, or as a background job with progress when long), and plots the
// tip deflection with its envelope, the energy and the first natural
// frequency against time (uPlot). API errors are shown next to the field they
// name. Its readers, plots and solve helpers are in shared/run.js, which the
// frequency-response panel (frequency.js) uses too. No build step.
"use strict";

import S from "./shared/index.js";
import {
  COLORS, state, num, readSystem, readProfile, readInitial, readBody, clearErrors, showInputErrors,
  fmt, peakEnvelope, log10, pow10, plotSize, makePlot, solve, finish,
} from "./shared/run.js";

(function () {
  // What this panel reads from the system card (shared/system.js): the tether,
  // the aerostat and gravity in calm air, and the card's starting length
  // (replaced by this panel's L₀).
  const CARD = S.declareCard("transient", [
    "cable.preset", "cable.diameter_m if preset", "cable.mass_per_length_kg_m", "cable.breaking_strength_n",
    "aerostat.preset", "aerostat.net_buoyancy_n", "aerostat.mass_kg",
    "gravity_m_s2", "initial_length_m",
  ]);
  // Runs with more work than this (simulated seconds × elements; 600 s at 50
  // elements) go through a job. So does any run the server refuses directly
  // (422 `too_large`, 503 busy, 504 timeout).
  const JOB_WORK = 30_000;

  const $ = (sel) => document.querySelector(sel);
  const form = $("#transient-form");
  if (!form || typeof uPlot === "undefined") return;

  // ---------- inputs ----------

  function readFlow(errors) {
    const kind = $("#tr-wind").value;
    if (kind === "sinusoidal") {
      return { kind, amplitude_m_s: num("aero.flow.amplitude_m_s", errors), angular_frequency_rad_s: num("aero.flow.angular_frequency_rad_s", errors) };
    }
    if (kind === "power_law") {
      return { kind, coefficient_m_s: num("aero.flow.coefficient_m_s", errors), exponent_nondim: num("aero.flow.exponent_nondim", errors) };
    }
    return null;
  }

  // Eigenvalue solves along the run (dense QEP of size 2n): enough to place the
  // resonance, few enough to stay cheap; none above 400 elements, where each
  // solve takes seconds.
  const EIGEN_MAX_ELEMENTS = 400;
  function eigenTracking(req) {
    const n = req.model.elements || 50;
    if (n > EIGEN_MAX_ELEMENTS) return undefined;
    return { interval_s: req.duration_s / (n > 200 ? 40 : 150), count: 1 };
  }

  function readSimulateRequest(errors) {
    const req = readSystem(errors, CARD);
    req.profile = readProfile(errors);
    req.duration_s = num("duration_s", errors);
    req.samples = num("samples", errors, { integer: true });
    req.initial = readInitial(errors);
    const flow = readFlow(errors);
    const body = readBody(errors);
    if (flow) req.aero = { flow, ...body };
    if (req.duration_s > 0) {
      const track = eigenTracking(req);
      if (track) req.eigenvalues = track;
    }
    return req;
  }

  const work = (req) => (req.duration_s || 0) * (req.model.elements || 50);
  const runWantsJob = (req) => work(req) > JOB_WORK;

  // ---------- status and jobs ----------

  const setRunStatus = S.statusSetter($("#tr-status"), $("#tr-results"));
  const runJob = S.jobRunner("tr-", { log: state.jobProgress, slot: state.jobs.run });

  // ---------- numbers ----------

  // The first time ω₁(t) crosses ω, interpolated in the eigenvalue track.
  function resonance(track, omega) {
    const pts = track
      .map((e) => ({ t: e.time_s, L: e.length_m, w: e.eigenvalues[0]?.im_1_s }))
      .filter((p) => Number.isFinite(p.w));
    for (let k = 1; k < pts.length; k++) {
      const a = pts[k - 1].w - omega;
      const b = pts[k].w - omega;
      if (a === 0 || a * b < 0) {
        const s = a === 0 ? 0 : a / (a - b);
        return {
          time_s: pts[k - 1].t + s * (pts[k].t - pts[k - 1].t),
          length_m: pts[k - 1].L + s * (pts[k].L - pts[k - 1].L),
          omega_rad_s: omega,
        };
      }
    }
    return null;
  }

  // ---------- plots ----------

  // A hatch pattern (device pixels) for the region past the onset of instability.
  let hatch = null;
  function hatchPattern(ctx, dpr) {
    if (hatch && hatch.dpr === dpr) return hatch.pattern;
    const size = Math.round(8 * dpr);
    const tile = document.createElement("canvas");
    tile.width = size;
    tile.height = size;
    const t = tile.getContext("2d");
    t.fillStyle = "rgba(110,110,110,0.22)";
    t.fillRect(0, 0, size, size);
    t.strokeStyle = "rgba(60,60,60,0.35)";
    t.lineWidth = dpr;
    t.beginPath();
    t.moveTo(0, size);
    t.lineTo(size, 0);
    t.moveTo(-size / 2, size / 2);
    t.lineTo(size / 2, -size / 2);
    t.moveTo(size / 2, size * 1.5);
    t.lineTo(size * 1.5, size / 2);
    t.stroke();
    hatch = { dpr, pattern: ctx.createPattern(tile, "repeat") };
    return hatch.pattern;
  }

  // Past the onset (the API's first_unstable_time_s) the linear model's
  // growth is not a prediction: that part of each time plot is greyed and
  // hatched over the curves, and labelled. Also vertical dashed lines,
  // labelled: where ω₁ passes the wind frequency, and the onset itself.
  const resonanceMarker = {
    hooks: {
      draw: [
        (u) => {
          const marks = [];
          if (state.resonance) marks.push([state.resonance.time_s, "ω₁ = ω", "#777"]);
          if (state.firstUnstable) marks.push([state.firstUnstable.time_s, `onset t* = ${fmt(state.firstUnstable.time_s)} s: unstable past it`, "#b00020"]);
          const dpr = devicePixelRatio;
          const { top, height, left: bl, width: bw } = u.bbox;
          const ctx = u.ctx;
          if (state.firstUnstable) {
            const x0 = Math.max(bl, Math.round(u.valToPos(state.firstUnstable.time_s, "x", true)));
            if (x0 < bl + bw) {
              ctx.save();
              ctx.fillStyle = hatchPattern(ctx, dpr);
              ctx.fillRect(x0, top, bl + bw - x0, height);
              ctx.restore();
            }
          }
          for (const [time, label, colour] of marks) {
            const x = Math.round(u.valToPos(time, "x", true));
            if (x < bl || x > bl + bw) continue;
            ctx.save();
            ctx.strokeStyle = colour;
            ctx.setLineDash([4, 4]);
            ctx.lineWidth = dpr;
            ctx.beginPath();
            ctx.moveTo(x, top);
            ctx.lineTo(x, top + height);
            ctx.stroke();
            ctx.setLineDash([]);
            ctx.font = `${11 * dpr}px sans-serif`;
            ctx.textBaseline = "top";
            ctx.textAlign = "left";
            const w = ctx.measureText(label).width;
            const left = x + 4 * dpr + w > bl + bw ? Math.max(bl + 2 * dpr, x - 4 * dpr - w) : x + 4 * dpr;
            ctx.fillStyle = "rgba(255,255,255,0.85)";
            ctx.fillRect(left - 2 * dpr, top + 2 * dpr, w + 4 * dpr, 15 * dpr);
            ctx.fillStyle = colour;
            ctx.fillText(label, left, top + 4 * dpr);
            ctx.restore();
          }
        },
      ],
    },
  };

  // Why the run ended, in words (the API's stopped_reason).
  function stopReason(res) {
    const at = res.outcome_time_s != null ? ` at t = ${fmt(res.outcome_time_s, 4)} s` : "";
    switch (res.stopped_reason) {
      case "completed":
        return `Stopped: the run completed its ${fmt(res.time_s[res.time_s.length - 1], 4)} s.`;
      case "magnitude_cap":
        return `Stopped${at}: magnitude cap, a deflection passed ${fmt(res.magnitude_cap_lengths_nondim)} × the cable length (${fmt(res.magnitude_cap_m)} m).`;
      case "step_failed":
        return `Stopped${at}: a time step failed (non-finite or singular).`;
      case "length_collapsed":
        return `Stopped${at}: the cable was shortened to almost zero length.`;
      default:
        return `Stopped${at}: ${String(res.stopped_reason).replace(/_/g, " ")}.`;
    }
  }

  function renderRun(res, req, via, keepScale = false) {
    state.result = res;
    state.request = req;
    state.via = via;
    const t = res.time_s;
    // Envelope: straight lines through the peaks of the API's max |y| per sample.
    // Peaks of |y| come every half period π/ω of the fastest oscillation that
    // matters (forcing, or the first mode at its highest): ripples closer than
    // half of that are not peaks.
    const dtSample = t.length > 1 ? (t[t.length - 1] - t[0]) / (t.length - 1) : 1;
    const omegaWind = req.aero?.flow?.kind === "sinusoidal" ? req.aero.flow.angular_frequency_rad_s : null;
    const w1 = res.eigenvalues.map((e) => e.eigenvalues[0]?.im_1_s).filter((w) => w > 0);
    const omegaMax = Math.max(omegaWind > 0 ? omegaWind : 0, ...w1, 0);
    const spacingS = omegaMax > 0 ? Math.PI / omegaMax / 2 : 2 * dtSample;
    const env = peakEnvelope(res.tip_envelope_m, Math.max(1, Math.round(spacingS / dtSample)));
    state.envelope = { peak_spacing_s: spacingS, values: env };
    state.resonance = omegaWind > 0 ? resonance(res.eigenvalues, omegaWind) : null;
    // The onset of instability as the API states it (t* of the profile, or the
    // first unstable eigenvalue sample); the samples after it are growth past onset.
    const unstable = res.eigenvalues.find((e) => !e.stable);
    state.firstUnstable = res.first_unstable_time_s != null
      ? { time_s: res.first_unstable_time_s, length_m: res.first_unstable_length_m, max_real_1_s: unstable?.max_real_1_s ?? null }
      : null;
    // What the plots shade: from the onset to the end of the run.
    state.shade = state.firstUnstable && t.length && state.firstUnstable.time_s < t[t.length - 1]
      ? { from_s: state.firstUnstable.time_s, to_s: t[t.length - 1] }
      : null;
    state.stoppedReason = res.stopped_reason;

    // A run that diverged spans hundreds of decades: switch to the log scale.
    if (!keepScale) $("#tr-log").checked = res.outcome === "diverged";
    const log = $("#tr-log").checked;
    for (const p of Object.values(state.plots)) p?.destroy();
    const envLabel = "envelope ±|y|max (m)";
    // Log scale: |y| itself cannot go on it; plot the API's max |y| per output
    // interval instead (zeros left out).
    state.plots.tip = makePlot(
      $("#tr-plot-tip"),
      log
        ? [
            { label: "t (s)", value: (u, v) => fmt(v, 4) },
            { label: "max |y| per output interval (m)", stroke: COLORS.tip, width: 1.5, value: pow10 },
          ]
        : [
            { label: "t (s)", value: (u, v) => fmt(v, 4) },
            { label: "tip deflection y (m)", stroke: COLORS.tip, width: 1, value: (u, v) => fmt(v) },
            { label: envLabel, stroke: COLORS.envelope, width: 1.5, dash: [5, 3], value: (u, v) => fmt(v) },
            { label: "−envelope (m)", stroke: COLORS.envelope, width: 1.5, dash: [5, 3], value: (u, v) => fmt(v) },
          ],
      log ? [t, log10(res.tip_envelope_m)] : [t, res.tip_deflection_m, env, env.map((v) => -v)],
      "Time t (s)",
      log ? "max |y| (m), log scale" : "Tip deflection y (m)",
      { plugins: [resonanceMarker], log },
    );
    state.plots.energy = makePlot(
      $("#tr-plot-energy"),
      [
        { label: "t (s)", value: (u, v) => fmt(v, 4) },
        { label: "total energy E (J)", stroke: COLORS.energy, width: 2, value: log ? pow10 : (u, v) => fmt(v) },
        { label: "without axial kinetic energy (J)", stroke: COLORS.vibration, width: 1.5, dash: [6, 4], value: log ? pow10 : (u, v) => fmt(v) },
      ],
      log ? [t, log10(res.energy_j), log10(res.vibration_energy_j)] : [t, res.energy_j, res.vibration_energy_j],
      "Time t (s)",
      log ? "Energy E (J), log scale" : "Energy E (J)",
      { plugins: [resonanceMarker], log },
    );
    const tEig = res.eigenvalues.map((e) => e.time_s);
    const freqSeries = [
      { label: "t (s)", value: (u, v) => fmt(v, 4) },
      { label: "first natural frequency ω₁ (rad/s)", stroke: COLORS.freq, width: 2, value: (u, v) => fmt(v) },
    ];
    const freqData = [tEig, res.eigenvalues.map((e) => e.eigenvalues[0]?.im_1_s ?? null)];
    if (omegaWind > 0) {
      freqSeries.push({ label: "wind frequency ω (rad/s)", stroke: COLORS.wind, width: 1.5, dash: [6, 4], value: (u, v) => fmt(v) });
      freqData.push(tEig.map(() => omegaWind));
    }
    state.plots.freq = makePlot($("#tr-plot-freq"), freqSeries, freqData, "Time t (s)", "ω (rad/s)", { plugins: [resonanceMarker] });

    // Outcome, explanation, and the resonance when there is one.
    const out = $("#tr-outcome");
    out.dataset.outcome = res.outcome;
    const parts = [];
    const b = document.createElement("b");
    b.textContent = res.outcome.replace(/_/g, " ");
    parts.push(b, `: ${res.explanation}.`);
    const peakAt = (from, to) => {
      let m = 0;
      for (let i = 0; i < t.length; i++) if (t[i] >= from && t[i] <= to) m = Math.max(m, res.tip_envelope_m[i]);
      return m;
    };
    if (state.resonance) {
      const r = state.resonance;
      const before = peakAt(-Infinity, r.time_s);
      const after = peakAt(r.time_s, Infinity);
      state.resonance.peak_before_m = before;
      state.resonance.peak_after_m = after;
      parts.push(
        ` The first natural frequency passes the wind frequency ω = ${fmt(r.omega_rad_s)} rad/s at t ≈ ${fmt(r.time_s)} s (L ≈ ${fmt(r.length_m)} m):` +
          ` peak |y| ${fmt(before)} m before, ${fmt(after)} m after.`,
      );
    } else {
      parts.push(` Peak |y| ${fmt(peakAt(-Infinity, Infinity))} m.`);
    }
    const onset = state.firstUnstable;
    if (onset) {
      parts.push(
        ` Unstable from t* ≈ ${fmt(onset.time_s)} s (L ≈ ${fmt(onset.length_m)} m${onset.max_real_1_s != null ? `, max Re λ = ${fmt(onset.max_real_1_s)} 1/s at the first unstable sample` : ""}):` +
          " the greyed, hatched part of the plots is growth past onset, not a prediction of the linear model.",
      );
    }
    const stop = document.createElement("span");
    stop.className = "tr-stop";
    stop.dataset.stoppedReason = res.stopped_reason;
    stop.textContent = ` ${stopReason(res)}`;
    parts.push(stop);
    out.replaceChildren(...parts);
    out.dataset.stoppedReason = res.stopped_reason;
    out.hidden = false;
    $("#tr-csv").disabled = false;
    const noTrack = req.eigenvalues ? "" : ` (natural frequencies not tracked above ${EIGEN_MAX_ELEMENTS} elements)`;
    setRunStatus("ready", `${t.length} samples, ${res.steps} steps of ${fmt(res.time_step_s)} s, ${res.elements} elements${noTrack}${via && via !== "direct" ? ` (${via})` : ""}.`);
  }

  // ---------- submitting ----------

  let runBusy = false;
  form.addEventListener("submit", async (ev) => {
    ev.preventDefault();
    if (runBusy) return;
    clearErrors();
    S.showFormError($("#tr-form-error"), "");
    S.writeUrl();
    const errors = [];
    const req = readSimulateRequest(errors);
    if (errors.length) return showInputErrors(errors, setRunStatus);
    runBusy = true;
    $("#tr-run").disabled = true;
    try {
      const outcome = await solve("/api/v1/simulate", "simulate", req, runWantsJob(req), setRunStatus, runJob, `${req.duration_s} s`);
      finish(outcome, (res) => renderRun(res, req, outcome.via), setRunStatus, $("#tr-form-error"));
    } finally {
      runBusy = false;
      $("#tr-run").disabled = false;
    }
  });


  // ---------- form behaviour ----------

  function toggle(attr, value) {
    for (const el of document.querySelectorAll(`#transient [data-${attr}]`)) el.hidden = el.dataset[attr] !== value;
  }
  const switches = [
    ["#tr-profile", "profile"],
    ["#tr-initial", "initial"],
    ["#tr-wind", "wind"],
    ["#tr-force-model", "model"],
  ];
  for (const [sel, attr] of switches) {
    $(sel).addEventListener("change", (ev) => {
      toggle(attr, ev.target.value);
      updateHints();
    });
    toggle(attr, $(sel).value);
  }

  function updateHints() {
    const errors = [];
    const req = readSimulateRequest(errors);
    $("#tr-hint").textContent = errors.length ? "" : runWantsJob(req) ? "long run · runs as a background job" : "";
  }

  const stale = () => {
    if (state.result && $("#tr-status").dataset.state === "ready") setRunStatus("stale", "Inputs changed: run again.");
  };
  form.addEventListener("input", (ev) => {
    if (ev.target.matches("input")) S.clearFieldError(ev.target);
    S.writeUrl();
    stale();
    updateHints();
  });
  $("#chart-form")?.addEventListener("input", updateHints);
  document.addEventListener("tetherplan:system-input", () => {
    stale();
    updateHints();
  });

  // ---------- downloads ----------

  const { inputLines, sig } = S;
  const download = (text, name) => S.download(text, name, "text/csv");

  const RUN_COLUMNS = ["time_s", "length_m", "rate_m_s", "tip_deflection_m", "tip_velocity_m_s", "tip_envelope_m", "energy_j", "vibration_energy_j", "tip_force_n"];

  $("#tr-csv").addEventListener("click", () => {
    const r = state.result;
    if (!r) return;
    const lines = ["# tetherplan transient run", ...inputLines(state.request), `# elements,${r.elements}`, `# time_step_s,${sig(r.time_step_s)}`,
      `# outcome,${r.outcome}`, `# stopped_reason,${r.stopped_reason}`, `# first_unstable_time_s,${sig(r.first_unstable_time_s) || "none"}`, RUN_COLUMNS.join(",")];
    for (let i = 0; i < r.time_s.length; i++) lines.push(RUN_COLUMNS.map((c) => sig(r[c][i])).join(","));
    download(lines.join("\n") + "\n", "transient-run.csv");
  });


  // ---------- resizing ----------

  let resizeTimer = null;
  window.addEventListener("resize", () => {
    clearTimeout(resizeTimer);
    resizeTimer = setTimeout(() => {
      for (const [key, sel] of [["tip", "#tr-plot-tip"], ["energy", "#tr-plot-energy"], ["freq", "#tr-plot-freq"]]) {
        state.plots[key]?.setSize(plotSize($(sel)));
      }
    }, 100);
  });

  updateHints();
})();
