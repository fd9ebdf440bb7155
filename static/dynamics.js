// The tether-dynamics panel (issue 23): reads its form and the system card,
// asks POST /api/v1/dynamics (or a `dynamics` job when the server asks for
// one) and shows the tether's shape animated through the gust, the winch and
// top tension and the aerostat's altitude against time beside the static
// tension at the largest wind; "Peak distribution" asks
// POST /api/v1/dynamics/peaks (or a `dynamics_peaks` job: many seeds) and
// draws the largest winch tension over the exposure against the static
// tensions of the mean wind and of the gust check.
"use strict";

import S from "./shared/index.js";

(function () {
  // What this panel reads from the system card (shared/system.js): the tether,
  // the aerostat with its aerodynamics, gravity, the safety factor and today's wind.
  const CARD = S.declareCard("dynamics", [
    "cable.preset", "cable.diameter_m", "cable.mass_per_length_kg_m", "cable.breaking_strength_n",
    "cable.normal_drag_coefficient_nondim", "cable.axial_stiffness_n",
    "aerostat.preset", "aerostat.net_buoyancy_n", "aerostat.mass_kg",
    "aerostat.drag_coefficient_nondim", "aerostat.reference_area_m2", "aerostat.lift_coefficient_nondim",
    "gravity_m_s2", "required_safety_factor_nondim",
    "wind.air_density_kg_m3", "wind.flow", "wind.gust",
  ]);
  const form = document.getElementById("dynamics-form");
  if (!form) return;
  const $ = (id) => document.getElementById(id);
  const SOURCE = "dynamics";
  const roots = [form, document.getElementById("plan-form")];

  // Shared with the browser test and the console.
  const state = { request: null, result: null, via: null, frame: 0, framesShown: 0, playing: true, peaks: null, peaksRequest: null, jobProgress: [], id: null };
  window.tetherplanDynamics = state;

  const setStatus = S.statusSetter($("dyn-status"), $("dyn-results"));
  const runJob = S.jobRunner("dyn-", { log: state.jobProgress, slot: state });
  const num = (name, errors, opts) => S.readNumber(form, name, errors, opts);
  const fmt = S.fixed;

  // ---------- the form ----------

  function showKind() {
    const kind = $("dyn-kind").value;
    for (const el of form.querySelectorAll("[data-kinds]")) {
      const kinds = el.dataset.kinds.split(" ");
      el.hidden = !kinds.includes(kind) && !kinds.includes("peaks");
    }
  }

  function turbulence(errors) {
    return {
      kind: "turbulence",
      model: $("dyn-model").value,
      turbulence_intensity_nondim: num("wind.time_history.turbulence_intensity_nondim", errors),
      length_scale_m: num("wind.time_history.length_scale_m", errors),
      seed: num("wind.time_history.seed", errors, { integer: true }),
    };
  }

  function timeHistory(errors) {
    const kind = $("dyn-kind").value;
    const n = (name) => num(`wind.time_history.${name}`, errors);
    switch (kind) {
      case "step":
        return { kind, time_s: n("time_s"), speed_m_s: n("speed_m_s") };
      case "ramp":
        return { kind, start_time_s: n("start_time_s"), duration_s: n("duration_s"), speed_m_s: n("speed_m_s") };
      case "one_minus_cosine":
        return { kind, start_time_s: n("start_time_s"), duration_s: n("duration_s"), amplitude_m_s: n("amplitude_m_s") };
      case "sinusoid":
        return { kind, amplitude_m_s: n("amplitude_m_s"), period_s: n("period_s") };
      case "turbulence":
        return turbulence(errors);
      default:
        return undefined;
    }
  }

  // The system (card + today's wind) with this panel's inputs.
  function base(errors, history) {
    const sys = S.readSystem(errors, CARD);
    return {
      cable: sys.cable,
      aerostat: sys.aerostat,
      wind: S.compact({ ...sys.wind, time_history: history }),
      gravity_m_s2: sys.gravity_m_s2,
      required_safety_factor_nondim: sys.required_safety_factor_nondim,
      tether_length_m: num("tether_length_m", errors),
      numerics: { segments: num("numerics.segments", errors, { integer: true }), time_step_s: num("numerics.time_step_s", errors) },
    };
  }

  function readRequest(errors) {
    const req = base(errors, timeHistory(errors));
    req.duration_s = num("duration_s", errors);
    req.sample_count = 601;
    req.shape_count = 61;
    return req;
  }

  function readPeaksRequest(errors) {
    const req = base(errors, turbulence(errors));
    req.exposure_s = num("exposure_s", errors);
    req.samples = num("samples", errors, { integer: true });
    req.percentiles_nondim = [0.5, 0.9, 0.99];
    return req;
  }

  // ---------- the run's figures ----------

  function figures(res) {
    const qs = res.quasi_static;
    $("dyn-peak").textContent = `${fmt(res.peak_winch_tension_n, 1)} N at ${fmt(res.peak_winch_tension_time_s, 2)} s`;
    $("dyn-qs").textContent = qs.winch_tension_at_max_wind_n == null ? "none found" : `${fmt(qs.winch_tension_at_max_wind_n, 1)} N (wind ${qs.max_wind_change_m_s >= 0 ? "+" : ""}${fmt(qs.max_wind_change_m_s, 2)} m/s)`;
    $("dyn-factor").textContent = res.dynamic_factor_nondim == null ? "–" : fmt(res.dynamic_factor_nondim, 3);
    $("dyn-low").textContent = `${fmt(res.min_aerostat_altitude_m, 1)} m`;
    $("dyn-slack").textContent = res.slack_events.length ? `${res.slack_events.length} time(s), from ${fmt(res.slack_events[0].start_time_s, 2)} s` : "never";
    $("dyn-explanation").textContent = res.explanation;
  }

  function plots(res) {
    const t = res.samples.map((s) => s.time_s);
    const qs = res.quasi_static.winch_tension_at_max_wind_n;
    S.makePlot($("dyn-tension-plot"), {
      xLabel: "time (s)",
      yLabel: "tension (N)",
      series: [
        { label: "t (s)", value: S.legendValue(2) },
        { label: "winch", stroke: "#0b5cad", width: 2, value: S.legendValue(1) },
        { label: "top", stroke: "#c0392b", width: 1, value: S.legendValue(1) },
        { label: "static at largest wind", stroke: "#555", dash: [6, 4], width: 1, value: S.legendValue(1) },
      ],
      data: [t, res.samples.map((s) => s.winch_tension_n), res.samples.map((s) => s.top_tension_n), t.map(() => qs ?? null)],
    });
    S.makePlot($("dyn-altitude-plot"), {
      xLabel: "time (s)",
      yLabel: "altitude (m)",
      series: [
        { label: "t (s)", value: S.legendValue(2) },
        { label: "aerostat altitude", stroke: "#27ae60", width: 2, value: S.legendValue(1) },
      ],
      data: [t, res.samples.map((s) => s.aerostat_altitude_m)],
    });
  }

  // ---------- the animation ----------

  let timer = null;
  function drawShape() {
    const res = state.result;
    const canvas = $("dyn-shape");
    if (!res || !res.shapes.length) return;
    const width = Math.max(260, Math.floor(canvas.parentElement.clientWidth || 300));
    const height = Math.round(Math.min(420, Math.max(240, width * 0.55)));
    const dpr = window.devicePixelRatio || 1;
    canvas.width = width * dpr;
    canvas.height = height * dpr;
    canvas.style.width = `${width}px`;
    canvas.style.height = `${height}px`;
    const ctx = canvas.getContext("2d");
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, width, height);
    let xmin = 0, xmax = 1, zmax = 1;
    for (const sh of res.shapes) {
      for (const n of sh.nodes) {
        xmin = Math.min(xmin, n.x_m);
        xmax = Math.max(xmax, n.x_m);
        zmax = Math.max(zmax, n.z_m);
      }
    }
    const pad = 36;
    const scale = Math.min((width - 2 * pad) / (xmax - xmin || 1), (height - 2 * pad) / zmax);
    const X = (x) => pad + (x - xmin) * scale;
    const Z = (z) => height - pad - z * scale;
    ctx.strokeStyle = "#999";
    ctx.beginPath();
    ctx.moveTo(pad / 2, Z(0));
    ctx.lineTo(width - pad / 2, Z(0));
    ctx.stroke();
    ctx.fillStyle = "#333";
    ctx.font = "12px system-ui, sans-serif";
    ctx.fillText(`${fmt(zmax, 0)} m`, 2, Z(zmax) + 4);
    ctx.fillText(`downwind ${fmt(xmax, 0)} m →`, width - 150, Z(0) + 16);
    // The first shape, faint: where the run started.
    const line = (nodes, stroke, w) => {
      ctx.strokeStyle = stroke;
      ctx.lineWidth = w;
      ctx.beginPath();
      nodes.forEach((n, i) => (i ? ctx.lineTo(X(n.x_m), Z(n.z_m)) : ctx.moveTo(X(n.x_m), Z(n.z_m))));
      ctx.stroke();
    };
    line(res.shapes[0].nodes, "#ccc", 1);
    const shape = res.shapes[state.frame % res.shapes.length];
    line(shape.nodes, "#0b5cad", 2);
    const top = shape.nodes[shape.nodes.length - 1];
    ctx.fillStyle = "#c0392b";
    ctx.beginPath();
    ctx.arc(X(top.x_m), Z(top.z_m), 6, 0, 2 * Math.PI);
    ctx.fill();
    const winch = shape.nodes[0];
    $("dyn-frame-time").textContent = `t = ${fmt(shape.time_s, 1)} s · winch ${fmt(winch.tension_n, 1)} N · altitude ${fmt(top.z_m, 1)} m`;
  }

  function animate() {
    clearInterval(timer);
    timer = setInterval(() => {
      if (!state.playing || !state.result?.shapes.length) return;
      state.frame = (state.frame + 1) % state.result.shapes.length;
      state.framesShown += 1;
      drawShape();
    }, 120);
  }

  $("dyn-play").addEventListener("click", () => {
    state.playing = !state.playing;
    $("dyn-play").textContent = state.playing ? "Pause" : "Play";
  });

  function render(res, req, via) {
    state.result = res;
    state.request = req;
    state.via = via;
    state.frame = 0;
    $("dyn-output").hidden = false;
    figures(res);
    plots(res);
    drawShape();
    animate();
    $("dyn-csv").disabled = false;
    const stop = res.outcome === "completed" ? "" : ` — stopped at ${fmt(res.stopped_at_s, 2)} s (${res.outcome.replace(/_/g, " ")})`;
    setStatus("ready", `Peak winch tension ${fmt(res.peak_winch_tension_n, 1)} N${stop}${via && via !== "direct" ? ` (${via})` : ""}.`);
  }

  // ---------- the peak distribution ----------

  function drawPeaks() {
    const res = state.peaks;
    const canvas = $("dyn-peaks-plot");
    if (!res) return;
    const width = Math.max(260, Math.floor(canvas.parentElement.clientWidth || 300));
    const height = 260;
    const dpr = window.devicePixelRatio || 1;
    canvas.width = width * dpr;
    canvas.height = height * dpr;
    canvas.style.width = `${width}px`;
    canvas.style.height = `${height}px`;
    const ctx = canvas.getContext("2d");
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, width, height);
    const values = res.samples.filter((s) => s.completed).map((s) => s.max_winch_tension_n);
    const qs = res.quasi_static;
    const marks = [
      [qs.mean_wind_winch_tension_n, "static, mean wind", "#555"],
      [qs.gust_check_winch_tension_n, `gust check (×${fmt(qs.gust_factor_nondim, 2)} wind)`, "#c0392b"],
    ].filter(([v]) => v != null);
    const all = values.concat(marks.map((m) => m[0]));
    let lo = Math.min(...all), hi = Math.max(...all);
    if (!(hi > lo)) hi = lo + 1;
    const span = hi - lo;
    lo -= 0.05 * span;
    hi += 0.05 * span;
    const bins = Math.max(5, Math.min(40, Math.round(Math.sqrt(values.length) * 2)));
    const counts = new Array(bins).fill(0);
    for (const v of values) counts[Math.min(bins - 1, Math.floor(((v - lo) / (hi - lo)) * bins))] += 1;
    const cmax = Math.max(...counts, 1);
    const pad = { l: 40, r: 10, t: 30, b: 36 };
    const X = (v) => pad.l + ((v - lo) / (hi - lo)) * (width - pad.l - pad.r);
    const Y = (c) => height - pad.b - (c / cmax) * (height - pad.t - pad.b);
    ctx.fillStyle = "#0b5cad";
    for (let i = 0; i < bins; i++) {
      const x0 = X(lo + (i / bins) * (hi - lo));
      const x1 = X(lo + ((i + 1) / bins) * (hi - lo));
      ctx.fillRect(x0 + 1, Y(counts[i]), Math.max(1, x1 - x0 - 2), Y(0) - Y(counts[i]));
    }
    ctx.strokeStyle = "#333";
    ctx.beginPath();
    ctx.moveTo(pad.l, Y(0));
    ctx.lineTo(width - pad.r, Y(0));
    ctx.stroke();
    ctx.fillStyle = "#333";
    ctx.font = "12px system-ui, sans-serif";
    for (const v of S.ticks(lo, hi, 5)) {
      if (v < lo || v > hi) continue;
      ctx.fillText(S.sig3(v), X(v) - 14, height - pad.b + 14);
    }
    ctx.fillText("largest winch tension over the exposure (N)", pad.l, height - 6);
    ctx.fillText(`${cmax}`, 4, Y(cmax) + 4);
    marks.forEach(([v, label, colour], k) => {
      ctx.strokeStyle = colour;
      ctx.setLineDash([6, 4]);
      ctx.beginPath();
      ctx.moveTo(X(v), pad.t - 6);
      ctx.lineTo(X(v), Y(0));
      ctx.stroke();
      ctx.setLineDash([]);
      ctx.fillStyle = colour;
      ctx.fillText(label, Math.min(width - 170, X(v) + 4), pad.t - 10 + 12 * k);
    });
  }

  function renderPeaks(res, req, via) {
    state.peaks = res;
    state.peaksRequest = req;
    $("dyn-peaks-output").hidden = false;
    drawPeaks();
    const p = res.max_winch_tension.percentiles.map((q) => {
      const ci = q.low_n != null && q.high_n != null ? ` [${fmt(q.low_n, 1)}, ${fmt(q.high_n, 1)}]` : " (too few seeds for its interval)";
      return `${fmt(100 * q.level_nondim, 0)} %: ${fmt(q.value_n, 1)} N${ci}`;
    });
    $("dyn-peaks-summary").textContent = `${res.explanation} Percentiles of the largest winch tension (${fmt(100 * res.confidence_nondim, 0)} % intervals): ${p.join("; ")}.`;
    setStatus("ready", `Peak distribution of ${res.completed_samples} seeds${via && via !== "direct" ? ` (${via})` : ""}.`);
  }

  // ---------- submitting ----------

  let busy = false;
  async function submit(path, kind, read, show, what) {
    if (busy) return;
    S.clearErrors(SOURCE);
    S.showFormError($("dyn-error"), "");
    S.writeUrl();
    const errors = [];
    const req = read(errors);
    if (errors.length) {
      S.showInputErrors(roots, errors, SOURCE);
      setStatus("error", "Fix the highlighted fields.");
      return;
    }
    busy = true;
    $("dyn-button").disabled = true;
    $("dyn-peaks-button").disabled = true;
    try {
      setStatus("busy", `Computing ${what}…`);
      let outcome;
      const r = await S.api("POST", path, req);
      if (S.needsJob(r)) {
        setStatus("busy", "The server asked for a background job…");
        outcome = await runJob(kind, req, what, setStatus);
      } else {
        outcome = r.ok ? { result: r.body, via: "direct" } : { status: r.status, error: r.body };
      }
      if (outcome.result) show(outcome.result, req, outcome.via);
      else if (outcome.error?.error?.code === "cancelled") setStatus("idle", "Job cancelled.");
      else {
        // The tether's stiffness is in the card's "More" section: open it.
        if (outcome.error?.error?.field === "cable.axial_stiffness_n") document.querySelector("#system-card details.more")?.setAttribute("open", "");
        const text = S.renderApiError(roots, outcome.status, outcome.error, $("dyn-error"), SOURCE);
        setStatus("error", `Fix the highlighted field: ${text}`);
      }
    } finally {
      busy = false;
      $("dyn-button").disabled = false;
      $("dyn-peaks-button").disabled = false;
    }
  }

  const run = () => submit("/api/v1/dynamics", "dynamics", readRequest, render, "the run");
  const runPeaks = () => submit("/api/v1/dynamics/peaks", "dynamics_peaks", readPeaksRequest, renderPeaks, "the peak distribution");

  form.addEventListener("submit", (ev) => {
    ev.preventDefault();
    run();
  });
  $("dyn-peaks-button").addEventListener("click", runPeaks);

  function csv() {
    const res = state.result;
    if (!res) return;
    const lines = ["time_s,winch_tension_n,top_tension_n,aerostat_altitude_m,aerostat_downwind_m,tether_length_m,aerostat_wind_m_s"];
    for (const s of res.samples) lines.push([s.time_s, s.winch_tension_n, s.top_tension_n, s.aerostat_altitude_m, s.aerostat_downwind_m, s.tether_length_m, s.aerostat_wind_m_s].join(","));
    const blob = new Blob([`# tetherplan dynamics; request: ${JSON.stringify(state.request)}\n${lines.join("\n")}\n`], { type: "text/csv" });
    const a = document.createElement("a");
    a.href = URL.createObjectURL(blob);
    a.download = "tetherplan-dynamics.csv";
    a.click();
    setTimeout(() => URL.revokeObjectURL(a.href), 1000);
  }
  $("dyn-csv").addEventListener("click", csv);

  function stale() {
    if (state.result && $("dyn-status").dataset.state === "ready") setStatus("stale", "Inputs changed: run again.");
    $("dyn-csv").disabled = true;
  }
  form.addEventListener("input", (ev) => {
    if (ev.target.matches("input")) S.clearFieldError(ev.target);
    S.writeUrl();
    stale();
  });
  $("dyn-kind").addEventListener("change", () => {
    showKind();
    S.writeUrl();
    stale();
  });
  document.addEventListener("tetherplan:system-input", stale);
  window.addEventListener("resize", () => {
    drawShape();
    drawPeaks();
  });

  // The plan panel has applied the URL already; a shared URL with this
  // panel's inputs runs it at once.
  showKind();
  state.run = run;
  state.runPeaks = runPeaks;
  if ([...new URLSearchParams(window.location.search).keys()].some((k) => k.startsWith("dynamics."))) run();
})();
