// The transient-run panel of the page (SPEC §2): reads its form (with the
// tether, aerostat and gravity of the system card), asks POST /api/v1/simulate
// (directly, or as a background job with progress when long), and plots the
// tip deflection with its envelope, the energy and the first natural
// frequency against time (uPlot). API errors are shown next to the field they
// name. The frequency-response panel (frequency.js) reuses its readers and
// plots through window.tetherplanTransient.lib. No build step.
"use strict";

(function () {
  const S = window.tetherplanShared;
  // What this panel reads from the system card (shared/system.js): the tether,
  // the aerostat and gravity in calm air, and the card's starting length
  // (replaced by this panel's L₀).
  const CARD = S.declareCard("transient", [
    "cable.preset", "cable.diameter_m if preset", "cable.mass_per_length_kg_m", "cable.breaking_strength_n",
    "aerostat.preset", "aerostat.net_buoyancy_n", "aerostat.mass_kg",
    "gravity_m_s2", "initial_length_m",
  ]);
  const SOURCE = "transient";
  // Runs with more work than this (simulated seconds × elements; 600 s at 50
  // elements) go through a job. So does any run the server refuses directly
  // (422 `too_large`, 503 busy, 504 timeout).
  const JOB_WORK = 30_000;
  const COLORS = { tip: "#0072b2", envelope: "#d55e00", energy: "#009e73", vibration: "#cc79a7", freq: "#0072b2", wind: "#d55e00" };

  const $ = (sel) => document.querySelector(sel);
  const form = $("#transient-form");
  if (!form || typeof uPlot === "undefined") return;

  // Shared with the browser test and the console: requests, answers, what is plotted.
  const state = {
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
  state.lib = {};
  window.tetherplanTransient = state;

  // ---------- inputs ----------

  // This section's inputs first, then the chart form's (elements) and the system card's.
  const roots = [$("#transient"), $("#chart-form"), $("#plan-form")];
  const num = (field, errors, opts) => S.readNumber(roots, field, errors, opts);
  const inputFor = (field) => S.inputFor(roots, field);

  // The tether, aerostat and gravity of the card; L0 from this panel; the
  // chart's element count (blank there: the default mesh).
  function readSystem(errors) {
    const sys = S.readSystem(errors, CARD);
    sys.initial_length_m = num("initial_length_m", errors);
    const elements = num("model.elements", errors, { integer: true, optional: true, fallback: 50 });
    sys.model = elements === undefined ? { kind: "linear_string" } : { kind: "linear_string", elements };
    return sys;
  }

  function readProfile(errors) {
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

  function readInitial(errors) {
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
  function readBody(errors) {
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
    const req = readSystem(errors);
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

  // ---------- errors next to fields, status and jobs ----------

  const clearErrors = () => S.clearErrors(SOURCE);
  // Renders an API error body next to its field (or in `fallback`); returns a summary.
  function renderApiError(status, body, fallback) {
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
  function showInputErrors(errors, statusFn) {
    S.showInputErrors(roots, errors, SOURCE);
    statusFn("error", "Fix the highlighted fields.");
  }

  const setRunStatus = S.statusSetter($("#tr-status"), $("#tr-results"));
  const runJob = S.jobRunner("tr-", { log: state.jobProgress, slot: state.jobs.run });

  // ---------- numbers ----------

  function fmt(v, digits = 3) {
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
  function peakEnvelope(abs, half) {
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

  const axis = { stroke: "#333", grid: { stroke: "#e5e5e5" }, ticks: { stroke: "#ccc" } };

  // Log scale: uPlot's log axes find no ticks across the 60 decades of a
  // diverged run, so the data are plotted as log₁₀ on a linear axis whose
  // labels and legend values are shown as powers of ten.
  const log10 = (a) => a.map((v) => (v > 0 ? Math.log10(v) : null));
  // 10^k as a short label: 0.01 … 10000 plainly, else 1e60 or 3.2e59.
  function powLabel(k, digits = 2) {
    if (k >= -2 && k <= 4) return String(Number((10 ** k).toPrecision(digits)));
    const e = Math.floor(k + 1e-9);
    const m = Number((10 ** (k - e)).toPrecision(digits));
    return m === 1 ? `1e${e}` : m >= 10 ? `1e${e + 1}` : `${m}e${e}`;
  }
  const pow10 = (u, v) => (v == null ? "–" : powLabel(v, 3));
  const logAxis = { ...axis, values: (u, splits) => splits.map((v) => powLabel(v)) };

  const plotSize = (el, aspect = 0.6) => S.plotSize(el, { aspect, max: 340 });

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

  function makePlot(el, series, data, xLabel, yLabel, extra = {}) {
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

  // Runs `req` directly or as a job; resolves to {result, via} or {status, error}.
  async function solve(path, kind, req, useJob, setStatus, job, what) {
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

  function finish(outcome, render, setStatus, errorEl) {
    if (outcome.result) render(outcome.result);
    else if (outcome.error?.error?.code === "cancelled") setStatus("idle", "Job cancelled.");
    else setStatus("error", renderApiError(outcome.status, outcome.error, errorEl));
  }

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
    state.lib.updateFrequencyHint?.();
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
      state.lib.resizeFrequency?.();
    }, 100);
  });

  // What frequency.js reuses: the readers, the plot and the solve helpers.
  Object.assign(state.lib, { S, roots, num, readSystem, readProfile, readInitial, readBody, makePlot, plotSize, fmt, log10, pow10, peakEnvelope, COLORS, solve, finish, clearErrors, showInputErrors, renderApiError });
  updateHints();
})();
