// The transient-run and frequency-response panels of the page (SPEC §2):
// reads their forms (plus the cable and aerostat of the chart form), asks
// POST /api/v1/simulate and POST /api/v1/frequency-response (directly, or as
// a background job with progress when long), plots the tip deflection with
// its envelope, the energy and the first natural frequency against time
// (uPlot), the peak amplitude against wind frequency, and a heat map of the
// envelope over (time, frequency). API errors are shown next to the field
// they name. Kept apart from app.js; no build step.
"use strict";

(function () {
  const { clearFieldError, fieldMessage, showFormError, unwrapJobError, api } = window.tetherplanCommon;
  // The server answers at most this many frequencies directly (api/solve.rs,
  // MAX_SYNC_FREQUENCIES); more run as a job.
  const SYNC_FREQUENCIES = 16;
  // Runs with more work than this (simulated seconds × elements; 600 s at 50
  // elements) go through a job. So does any run the server refuses directly
  // (422 `too_large`, 503 busy, 504 timeout).
  const JOB_WORK = 30_000;
  const POLL_MS = 300;
  const COLORS = { tip: "#0072b2", envelope: "#d55e00", energy: "#009e73", vibration: "#cc79a7", freq: "#0072b2", wind: "#d55e00" };

  const $ = (sel) => document.querySelector(sel);
  const form = $("#transient-form");
  const frForm = $("#fr-form");
  if (!form || !frForm || typeof uPlot === "undefined") return;

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
    jobs: { run: null, fr: null },
  };
  window.tetherplanTransient = state;

  // ---------- inputs ----------

  const visible = (el) => el && !el.closest("[hidden]");

  // The visible input of this page section for an API field path (`data-api`),
  // else the chart form's (`data-field`: cable, aerostat, gravity, elements).
  function inputExact(path) {
    const mine = [...document.querySelectorAll(`#transient [data-api="${CSS.escape(path)}"]`)].find(visible);
    if (mine) return mine;
    return [...document.querySelectorAll(`[data-field="${CSS.escape(path)}"]`)].find(visible) || null;
  }

  // The input an API field path names: exact, else without a list index, else
  // the first visible input under the nearest named parent.
  function inputFor(field) {
    if (!field) return null;
    let path = field.replace(/^\./, "");
    while (path) {
      const exact = inputExact(path);
      if (exact) return exact;
      const unindexed = path.replace(/\[\d+\]$/, "");
      if (unindexed !== path) {
        path = unindexed;
        continue;
      }
      const dot = path.lastIndexOf(".");
      if (dot < 0) break;
      path = path.slice(0, dot);
      const prefix = CSS.escape(path + ".");
      const child = [...document.querySelectorAll(`#transient [data-api^="${prefix}"], [data-field^="${prefix}"]`)].find(visible);
      if (child) return child;
    }
    return null;
  }

  // A number from `input` (API path `field`); errors collect {field, message}.
  function numberOf(input, field, errors, { integer = false, optional = false, fallback } = {}) {
    if (!input) return fallback ?? null;
    const text = input.value.trim();
    if (text === "" && optional) return undefined;
    const value = Number(text);
    if (text === "" || !Number.isFinite(value)) {
      errors.push({ field, message: text === "" ? "enter a number" : `“${text}” is not a number` });
      return null;
    }
    if (integer && !Number.isInteger(value)) {
      errors.push({ field, message: `must be a whole number, got ${text}` });
      return null;
    }
    return value;
  }

  const num = (field, errors, opts) => numberOf(inputExact(field), field, errors, opts);

  // Cable, aerostat, gravity and elements from the chart form (its defaults if a
  // field is not on the page); L0 from this panel.
  function readSystem(errors) {
    const cable = {};
    if ($("#cable-mode")?.value === "density") {
      cable.density_kg_m3 = num("cable.density_kg_m3", errors, { fallback: 7800 });
      cable.area_m2 = num("cable.area_m2", errors, { fallback: 1e-5 });
    } else {
      cable.mass_per_length_kg_m = num("cable.mass_per_length_kg_m", errors, { fallback: 0.078 });
    }
    // An empty element count (the chart's "converged") runs the default mesh.
    const elements = num("model.elements", errors, { integer: true, optional: true, fallback: 50 });
    return {
      cable,
      aerostat: {
        net_buoyancy_n: num("aerostat.net_buoyancy_n", errors, { fallback: 1000 }),
        mass_kg: num("aerostat.mass_kg", errors, { fallback: 10 }),
      },
      initial_length_m: num("initial_length_m", errors),
      gravity_m_s2: num("gravity_m_s2", errors, { fallback: 9.81 }),
      model: elements === undefined ? { kind: "linear_string" } : { kind: "linear_string", elements },
    };
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

  // The aerostat as an aerodynamic body (AeroBodyInput).
  function readBody(errors) {
    const model = $("#tr-force-model").value === "drag"
      ? { kind: "drag", drag_coefficient_nondim: num("aero.model.drag_coefficient_nondim", errors) }
      : { kind: "thesis" };
    return { model, radius_m: num("aero.radius_m", errors), air_density_kg_m3: num("aero.air_density_kg_m3", errors) };
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

  function readFrequencyRequest(errors) {
    const req = readSystem(errors);
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

  const work = (req) => (req.duration_s || 0) * (req.model.elements || 50);
  const runWantsJob = (req) => work(req) > JOB_WORK;
  const frWantsJob = (req) => (req.frequencies_rad_s.count || 0) > SYNC_FREQUENCIES;

  // ---------- errors next to fields ----------

  // Errors this file placed carry data-source="transient" (also those in the chart form).
  function clearErrors() {
    for (const el of document.querySelectorAll('.field-error[data-source="transient"]')) {
      const input = document.getElementById(el.id.replace(/-error$/, ""));
      if (input) {
        input.removeAttribute("aria-invalid");
        input.removeAttribute("aria-describedby");
      }
      el.remove();
    }
    for (const el of document.querySelectorAll('#transient [aria-invalid]')) el.removeAttribute("aria-invalid");
  }

  function showFieldError(field, message) {
    const input = inputFor(field);
    if (!input) return null;
    clearFieldError(input);
    const p = document.createElement("p");
    p.className = "field-error";
    p.id = `${input.id}-error`;
    p.dataset.errorFor = field;
    p.dataset.source = "transient";
    p.textContent = fieldMessage(field, message);
    input.closest(".field").append(p);
    input.setAttribute("aria-invalid", "true");
    input.setAttribute("aria-describedby", p.id);
    return input;
  }

  // A job submission names fields inside its `request`: drop the prefix.

  // Renders an API error body next to its field (or in `fallback`); returns a summary.
  function renderApiError(status, body, fallback) {
    const err = body && body.error ? body.error : { code: `http_${status}`, field: null, message: `HTTP ${status}` };
    const input = showFieldError(err.field, err.message);
    if (input) {
      showFormError(fallback, "");
      input.focus({ preventScroll: false });
      const where = input.closest("#transient") ? "" : " (in the chart form above)";
      return `Fix the highlighted field${where}: ${err.message}`;
    }
    showFormError(fallback, err.message);
    return err.message;
  }

  function showInputErrors(errors, statusFn) {
    for (const e of errors) showFieldError(e.field, e.message);
    inputFor(errors[0].field)?.focus();
    statusFn("error", "Fix the highlighted fields.");
  }

  // ---------- HTTP and jobs ----------

  const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
  // The direct route cannot answer this one: run it as a job instead.
  const needsJob = (r) => !r.ok && (r.body?.error?.code === "too_large" || r.status === 503 || r.status === 504);

  // A progress bar with a cancel button, bound to one panel.
  function jobUi(prefix, slot, setStatus, log) {
    const box = $(`#${prefix}-job`);
    const bar = $(`#${prefix}-job-progress`);
    const text = $(`#${prefix}-job-text`);
    $(`#${prefix}-job-cancel`).addEventListener("click", async () => {
      const id = state.jobs[slot];
      if (id == null) return;
      text.textContent = "cancelling…";
      await api("DELETE", `/api/v1/jobs/${encodeURIComponent(id)}`);
    });
    // Resolves to {result, via} or {status, error}.
    return async function runJob(kind, request, what) {
      const submitted = await api("POST", "/api/v1/jobs", { kind, request });
      if (!submitted.ok) return { status: submitted.status, error: unwrapJobError(submitted.body) };
      const id = submitted.body.id;
      state.jobs[slot] = id;
      log.length = 0;
      box.hidden = false;
      bar.value = 0;
      text.textContent = "queued";
      try {
        for (;;) {
          const r = await api("GET", `/api/v1/jobs/${encodeURIComponent(id)}`);
          if (!r.ok) return { status: r.status, error: r.body };
          const job = r.body;
          const progress = Number(job.progress) || 0;
          bar.value = progress;
          log.push([job.status, progress]);
          if (text.textContent !== "cancelling…" || job.status !== "running") text.textContent = `${job.status} · ${(progress * 100).toFixed(0)} %`;
          setStatus("busy", `Job ${id} (${what}): ${job.status}, ${(progress * 100).toFixed(0)} %`);
          if (job.status === "done") return { result: job.result, via: `job ${id}` };
          if (job.status === "failed" || job.status === "cancelled") {
            const body = job.error?.error ? job.error : { error: { code: job.status, field: null, message: `the job was ${job.status}` } };
            return { status: 200, error: unwrapJobError(body) };
          }
          await sleep(POLL_MS);
        }
      } finally {
        state.jobs[slot] = null;
        box.hidden = true;
      }
    };
  }

  function statusSetter(statusEl, resultsEl) {
    return (kind, text) => {
      if (kind === "ready") delete resultsEl.dataset.stale;
      else resultsEl.dataset.stale = "";
      statusEl.dataset.state = kind;
      statusEl.textContent = text;
    };
  }

  const setRunStatus = statusSetter($("#tr-status"), $("#tr-results"));
  const setFrStatus = statusSetter($("#fr-status"), $("#fr-results"));
  const runJob = jobUi("tr", "run", setRunStatus, state.jobProgress);
  const frJob = jobUi("fr", "fr", setFrStatus, state.fr.jobProgress);

  // ---------- numbers ----------

  function fmt(v, digits = 3) {
    if (v == null || !Number.isFinite(v)) return "–";
    const a = Math.abs(v);
    if (a !== 0 && (a >= 1e5 || a < 1e-3)) return v.toExponential(digits - 1);
    return Number(v.toPrecision(digits)).toString();
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

  function plotSize(el, aspect = 0.6) {
    const width = Math.max(260, Math.floor(el.clientWidth));
    return { width, height: Math.round(Math.min(340, Math.max(240, width * aspect))) };
  }

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

  // ---------- heat map ----------

  // Viridis, sampled at 9 stops.
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

  // About `n` round tick values covering [lo, hi].
  function ticks(lo, hi, n) {
    if (!(hi > lo)) return [lo];
    const raw = (hi - lo) / n;
    const mag = 10 ** Math.floor(Math.log10(raw));
    const step = [1, 2, 5, 10].map((m) => m * mag).find((s) => s >= raw) || 10 * mag;
    const out = [];
    for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) out.push(Number(v.toPrecision(12)));
    return out;
  }

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
    const img = document.createElement("canvas");
    img.width = t.length;
    img.height = w.length;
    const ictx = img.getContext("2d");
    const data = ictx.createImageData(t.length, w.length);
    for (let i = 0; i < w.length; i++) {
      const row = w.length - 1 - i; // ω increases upwards
      for (let j = 0; j < t.length; j++) {
        const v = E[i][j];
        const [r, g, b] = Number.isFinite(v) ? colour(scaleOf(v)) : [200, 200, 200];
        const k = 4 * (row * t.length + j);
        data.data[k] = r;
        data.data[k + 1] = g;
        data.data[k + 2] = b;
        data.data[k + 3] = 255;
      }
    }
    ictx.putImageData(data, 0, 0);
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(img, m.left, m.top, pw, ph);
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
    ctx.fillStyle = "#333";
    ctx.font = "11px system-ui, sans-serif";
    ctx.textAlign = "center";
    ctx.textBaseline = "top";
    for (const v of ticks(Math.max(0, t[0]), t[t.length - 1], narrow ? 4 : 8)) {
      const x = xOf(v);
      if (x < m.left - 0.5 || x > m.left + pw + 0.5) continue;
      ctx.fillRect(x, m.top + ph, 1, 4);
      ctx.fillText(fmt(v), x, m.top + ph + 6);
    }
    ctx.fillText("Time t (s)", m.left + pw / 2, m.top + ph + 21);
    ctx.textAlign = "right";
    ctx.textBaseline = "middle";
    for (const v of ticks(w[0], w[w.length - 1], 5)) {
      const y = yOf(v);
      if (y < m.top - 0.5 || y > m.top + ph + 0.5) continue;
      ctx.fillRect(m.left - 4, y, 4, 1);
      ctx.fillText(fmt(v), m.left - 6, y);
    }
    ctx.save();
    ctx.translate(12, m.top + ph / 2);
    ctx.rotate(-Math.PI / 2);
    ctx.textAlign = "center";
    ctx.fillText("ω (rad/s)", 0, 0);
    ctx.restore();

    // Colour bar.
    const bx = m.left + pw + 10;
    const bw = 12;
    for (let k = 0; k < ph; k++) {
      const [r, g, b] = colour(1 - k / ph);
      ctx.fillStyle = `rgb(${r},${g},${b})`;
      ctx.fillRect(bx, m.top + k, bw, 1);
    }
    ctx.strokeStyle = "#333";
    ctx.strokeRect(bx + 0.5, m.top + 0.5, bw - 1, ph - 1);
    ctx.fillStyle = "#333";
    ctx.textAlign = "left";
    for (const v of ticks(lo, hi, 5)) {
      if (logColour && !Number.isInteger(v)) continue;
      const y = m.top + ph - ((v - lo) / (hi - lo || 1)) * ph;
      ctx.fillRect(bx + bw, y, 3, 1);
      const text = logColour ? (v >= -2 && v <= 3 ? fmt(10 ** v, 2) : `1e${v}`) : fmt(v, 2);
      ctx.fillText(text, bx + bw + 5, Math.min(m.top + ph - 5, Math.max(m.top + 5, y)));
    }
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
  $("#tr-log").addEventListener("change", () => {
    if (state.result) renderRun(state.result, state.request, state.via, true);
  });
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

  // Runs `req` directly or as a job; resolves to {result, via} or {status, error}.
  async function solve(path, kind, req, useJob, setStatus, job, what) {
    if (useJob) {
      setStatus("busy", `Submitting a job (${what})…`);
      return job(kind, req, what);
    }
    setStatus("busy", `Computing (${what})…`);
    const r = await api("POST", path, req);
    if (needsJob(r)) {
      setStatus("busy", "The server asked for a background job…");
      return job(kind, req, what);
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
    showFormError($("#tr-form-error"), "");
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

  let frBusy = false;
  frForm.addEventListener("submit", async (ev) => {
    ev.preventDefault();
    if (frBusy) return;
    clearErrors();
    showFormError($("#fr-form-error"), "");
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
    const fe = [];
    const fr = readFrequencyRequest(fe);
    const n = fr.frequencies_rad_s.count;
    $("#fr-hint").textContent = fe.length ? "" : `${n} run${n === 1 ? "" : "s"}${frWantsJob(fr) ? " · runs as a background job" : ""}`;
  }

  for (const f of [form, frForm]) {
    f.addEventListener("input", (ev) => {
      if (ev.target.matches("input")) clearFieldError(ev.target);
      updateHints();
    });
  }
  $("#chart-form")?.addEventListener("input", updateHints);

  // ---------- downloads ----------

  function download(text, name) {
    const url = URL.createObjectURL(new Blob([text], { type: "text/csv" }));
    const a = document.createElement("a");
    a.href = url;
    a.download = name;
    document.body.append(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(url), 1000);
  }

  const RUN_COLUMNS = ["time_s", "length_m", "rate_m_s", "tip_deflection_m", "tip_velocity_m_s", "tip_envelope_m", "energy_j", "vibration_energy_j", "tip_force_n"];

  // Every input of the request as `# input <path>,<value>` lines.
  function inputLines(obj, prefix = "", out = []) {
    for (const [k, v] of Object.entries(obj ?? {})) {
      const key = prefix ? `${prefix}.${k}` : k;
      if (v && typeof v === "object" && !Array.isArray(v)) inputLines(v, key, out);
      else out.push(`# input ${key},${Array.isArray(v) ? v.join(" ") : sig(v)}`);
    }
    return out;
  }

  // Six significant digits: what the model resolves, not 16-digit floats.
  const sig = (v) => (typeof v === "number" && Number.isFinite(v) ? String(Number(v.toPrecision(6))) : v == null ? "" : String(v));

  $("#tr-csv").addEventListener("click", () => {
    const r = state.result;
    if (!r) return;
    const lines = ["# tetherplan transient run", ...inputLines(state.request), `# elements,${r.elements}`, `# time_step_s,${sig(r.time_step_s)}`,
      `# outcome,${r.outcome}`, `# stopped_reason,${r.stopped_reason}`, `# first_unstable_time_s,${sig(r.first_unstable_time_s) || "none"}`, RUN_COLUMNS.join(",")];
    for (let i = 0; i < r.time_s.length; i++) lines.push(RUN_COLUMNS.map((c) => sig(r[c][i])).join(","));
    download(lines.join("\n") + "\n", "transient-run.csv");
  });

  $("#fr-csv").addEventListener("click", () => {
    const r = state.fr.result;
    if (!r) return;
    const lines = ["# tetherplan frequency response", ...inputLines(state.fr.request), "angular_frequency_rad_s,time_s,envelope_m"];
    r.frequencies_rad_s.forEach((w, i) => r.time_s.forEach((t, j) => lines.push(`${sig(w)},${sig(t)},${sig(r.envelope_m[i][j])}`)));
    download(lines.join("\n") + "\n", "frequency-response.csv");
  });

  // ---------- resizing ----------

  let resizeTimer = null;
  window.addEventListener("resize", () => {
    clearTimeout(resizeTimer);
    resizeTimer = setTimeout(() => {
      for (const [key, sel] of [["tip", "#tr-plot-tip"], ["energy", "#tr-plot-energy"], ["freq", "#tr-plot-freq"]]) {
        state.plots[key]?.setSize(plotSize($(sel)));
      }
      state.fr.plot?.setSize(plotSize($("#fr-plot-peak")));
      drawHeatmap();
    }, 100);
  });

  drawHeatmap();
  updateHints();
})();
