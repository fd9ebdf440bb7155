// The deployment-chart page: reads the form, asks the API for a chart
// (directly, or as a background job when it is large), plots t* and h*
// against rate with uPlot, and renders API errors next to the field they
// name. No build step: plain browser JavaScript. index.html loads it as a
// classic script (`<script src="app.js">`, as before the panels became
// modules): it imports the shared code itself and starts once the page's
// modules have run (DOMContentLoaded), so its place among the tags does not matter.
"use strict";

(async function () {
  const ready = document.readyState === "loading" ? new Promise((r) => document.addEventListener("DOMContentLoaded", r, { once: true })) : null;
  const [{ default: S }] = await Promise.all([import("./shared/index.js"), ready]);
  // What this panel reads from the system card (shared/system.js): the tether,
  // the aerostat and gravity in calm air, and the starting length.
  const CARD = S.declareCard("chart", [
    "cable.preset", "cable.diameter_m if preset", "cable.mass_per_length_kg_m", "cable.breaking_strength_n",
    "aerostat.preset", "aerostat.net_buoyancy_n", "aerostat.mass_kg",
    "gravity_m_s2", "initial_length_m",
  ]);
  // Charts with more work than this (points × elements; 5000 points at 50 elements)
  // run as a background job with progress; so does any chart the direct route
  // refuses as too large (422 `too_large`) or while the server is busy (503).
  const JOB_WORK_THRESHOLD = 250_000;
  // The server's own limit for a direct chart (config.rs, max_sync_chart_points).
  const SYNC_POINT_LIMIT = 20_000;
  const COLORS = ["#0072b2", "#d55e00", "#009e73", "#cc79a7", "#e69f00", "#56b4e9", "#000000", "#999933"];
  const SOURCE = "chart";

  const $ = (sel) => document.querySelector(sel);
  const chartForm = $("#chart-form");
  const safeForm = $("#safe-form");
  const statusEl = $("#status");
  if (!chartForm) return;

  // Shared with the browser test and the console: the last request, answer and plots.
  const state = { request: null, chart: null, via: null, jobProgress: [], plots: { time: null, elevation: null, geTime: null, geElevation: null }, job: null, ge: null };
  window.tetherplan = state;

  // ---------- reading the form ----------

  // The chart's inputs, then the system card's (the tether, the aerostat, gravity).
  const roots = [chartForm, safeForm, document.getElementById("plan-form")];
  const readNumber = (field, errors, opts) => S.readNumber(roots, field, errors, opts);

  function readBuoyancies(errors) {
    const input = $("#buoyancies");
    const parts = input.value.split(/[,;\s]+/).filter((s) => s !== "");
    if (parts.length === 0) {
      errors.push({ field: "net_buoyancies_n", message: "list at least one net buoyancy (N)" });
      return null;
    }
    const values = [];
    for (const [i, p] of parts.entries()) {
      const v = Number(p);
      if (!Number.isFinite(v)) {
        errors.push({ field: `net_buoyancies_n[${i}]`, message: `“${p}” is not a number` });
        return null;
      }
      values.push(v);
    }
    return values;
  }

  // The system of the card, in calm air, and the chart's mesh.
  function readSystem(errors) {
    const sys = S.readSystem(errors, CARD);
    // No element count: the server converges every answer and gives the safe side of its error.
    sys.model = $("#elements").value.trim() === ""
      ? { kind: "linear_string" }
      : { kind: "linear_string", elements: readNumber("model.elements", errors, { integer: true }) };
    return sys;
  }

  function readChartRequest(errors) {
    const req = readSystem(errors);
    req.rates_m_s = {
      min: readNumber("rates_m_s.min", errors),
      max: readNumber("rates_m_s.max", errors),
      count: readNumber("rates_m_s.count", errors, { integer: true }),
    };
    req.net_buoyancies_n = readBuoyancies(errors);
    return req;
  }

  function chartPoints(req) {
    return (req.rates_m_s.count || 0) * Math.max(1, (req.net_buoyancies_n || []).length);
  }

  function wantsJob(req) {
    return chartPoints(req) > SYNC_POINT_LIMIT || chartPoints(req) * (req.model.elements || 50) > JOB_WORK_THRESHOLD;
  }

  // ---------- errors next to fields ----------

  const inputFor = (field) => S.inputFor(roots, field);
  const clearErrors = () => S.clearErrors(SOURCE);
  const showFieldError = (field, message) => !!S.showFieldError(roots, field, message, SOURCE);
  const renderApiError = (status, body, fallback) => {
    const placed = S.inputFor(roots, body?.error?.field);
    const text = S.renderApiError(roots, status, body, fallback, SOURCE);
    return placed ? `Fix the highlighted field: ${text}` : text;
  };

  // ---------- HTTP ----------

  // True while a GE job runs after a finished string chart: that chart is
  // the current answer and stays undimmed.
  let geAfterString = false;

  function setStatus(kind, text) {
    // Plots of an earlier request are dimmed until a new answer replaces them.
    if (kind === "ready" || geAfterString) delete $("#results").dataset.stale;
    else $("#results").dataset.stale = "";
    statusEl.dataset.state = kind;
    statusEl.textContent = text;
  }

  // ---------- jobs ----------

  // Runs a chart as a background job, showing its progress; resolves to the chart
  // answer, or to {error} when the job fails, is cancelled, or cannot be submitted.
  const jobRun = S.jobRunner("", { log: state.jobProgress, slot: state });
  const runChartJob = (req, points = chartPoints(req)) =>
    jobRun("chart", req, `${points} points`, setStatus).then((o) => (o.result ? { chart: o.result, via: o.via } : o));
  // ---------- plotting ----------

  function closedFormTime(p, initialLength) {
    const t = (p.closed_form_elevation_m - initialLength) / p.rate_m_s;
    return t > 0 ? t : 0;
  }

  const fmt = S.fixed;

  // Legend values: blank until the cursor is on the plot (not a row of "–").
  const legendValue = S.legendValue;
  const curves = (n) => `${n} curve${n === 1 ? "" : "s"}`;

  // uPlot data and series for one quantity: x = rates, then per buoyancy the model
  // curve (solid) and the closed-form estimate (dashed).
  function plotSpec(chart, quantity, initialLength, log = false) {
    const x = chart.series[0].points.map((p) => p.rate_m_s);
    const data = [x];
    const series = [{ label: "v (m/s)", value: legendValue(2) }];
    const unit = quantity === "time" ? "s" : "m";
    const sym = quantity === "time" ? "t*" : "h*";
    chart.series.forEach((s, i) => {
      const color = COLORS[i % COLORS.length];
      // On a log axis, t* = 0 (unstable at once) has no place: leave a gap.
      const shown = (v) => (log && !(v > 0) ? null : v);
      const model = s.points.map((p) => shown(quantity === "time" ? p.critical_time_s : p.max_elevation_m));
      const closed = s.points.map((p) => shown(quantity === "time" ? closedFormTime(p, initialLength) : p.closed_form_elevation_m));
      data.push(model, closed);
      series.push(
        { label: `${sym}, ${s.net_buoyancy_n} N (${unit})`, color, stroke: color, width: 2, value: legendValue(1) },
        { label: `closed form, ${s.net_buoyancy_n} N (${unit})`, color, stroke: color, width: 1.5, dash: [6, 4], value: legendValue(1) },
      );
    });
    return { data, series, unit, sym, log };
  }

  const plotSize = (el) => S.plotSize(el);
  const makePlot = (el, spec, yLabel) =>
    S.makePlot(el, { series: spec.series, data: spec.data, log: spec.log, xLabel: "Deployment rate v (m/s)", yLabel });

  function render(chart, req, via = state.via) {
    state.chart = chart;
    state.request = req;
    state.via = via;
    const L0 = req.initial_length_m;
    const timeSpec = plotSpec(chart, "time", L0, $("#log-time").checked);
    const elevSpec = plotSpec(chart, "elevation", L0);
    state.plots.time?.destroy();
    state.plots.elevation?.destroy();
    state.plots.time = makePlot($("#plot-time"), timeSpec, "t* (s)");
    state.plots.elevation = makePlot($("#plot-elevation"), elevSpec, "h* (m)");
    $("#download-csv").disabled = false;
    $("#download-png").disabled = false;
    const pts = chart.series.reduce((n, s) => n + s.points.length, 0);
    statusEl.dataset.series = String(chart.series.length);
    setStatus("ready", `${curves(chart.series.length)}, ${pts} points, ${chart.converged ? "converged, safe side of the error" : `${chart.elements} elements`}${via && via !== "direct" ? ` (${via})` : ""}.`);
  }

  $("#log-time").addEventListener("change", () => {
    if (state.chart) render(state.chart, state.request);
  });

  let resizeTimer = null;
  window.addEventListener("resize", () => {
    clearTimeout(resizeTimer);
    resizeTimer = setTimeout(() => {
      for (const [key, el] of [["time", "#plot-time"], ["elevation", "#plot-elevation"], ["geTime", "#plot-ge-time"], ["geElevation", "#plot-ge-elevation"]]) {
        state.plots[key]?.setSize(plotSize($(el)));
      }
    }, 100);
  });

  // ---------- GE chart beside the string's ----------

  // The GE request (GeChartRequest in the API): the form's cable, aerostat and
  // rate range, the aerostat's net buoyancy, one series per stiffness ratio.
  function readGeRequest(errors) {
    const sys = readSystem(errors);
    const ratios = [];
    for (const [i, p] of $("#ge-ratios").value.split(/[,;\s]+/).filter((t) => t !== "").entries()) {
      const v = Number(p);
      if (!Number.isFinite(v)) errors.push({ field: `ge.stiffness_ratios[${i}]`, message: `“${p}” is not a number` });
      ratios.push(v);
    }
    if (ratios.length === 0) errors.push({ field: "ge.stiffness_ratios", message: "list at least one stiffness ratio" });
    return {
      cable: sys.cable,
      aerostat: sys.aerostat,
      initial_length_m: sys.initial_length_m,
      gravity_m_s2: sys.gravity_m_s2,
      model: {
        kind: "geometrically_exact",
        elements: readNumber("ge.model.elements", errors, { integer: true }),
        bending_stiffness_n_m2: readNumber("ge.model.bending_stiffness_n_m2", errors),
        inertia_ratio: readNumber("ge.model.inertia_ratio", errors),
      },
      stiffness_ratios: ratios,
      rates_m_s: {
        min: readNumber("rates_m_s.min", errors),
        max: readNumber("rates_m_s.max", errors),
        count: readNumber("ge.rates_m_s.count", errors, { integer: true }),
      },
    };
  }

  // API fields of a GE request land on the GE inputs (`ge.` prefix), the
  // shared ones (cable, aerostat, rate range) on the chart form's.
  function geErrorBody(body) {
    const err = body?.error;
    if (!err || typeof err.field !== "string") return body;
    const prefixed = `ge.${err.field}`;
    return inputFor(prefixed)?.name.startsWith("ge.") ? { error: { ...err, field: prefixed } } : body;
  }

  // One x axis for curves on different rate grids: the union of the rates,
  // gaps where a curve has no point (drawn across).
  // A GE series' name: E* (and F0, buoyancy, A0 when the chart varies them).
  function geLabel(s) {
    let label = `GE, E* = ${s.stiffness_ratio.toExponential(0).replace("e+", "e")}`;
    if (s.perturbation_force_n) label += `, F0 = ${s.perturbation_force_n} N`;
    if (s.wind_amplitude_nondim != null) label += `, A0 = ${s.wind_amplitude_nondim}`;
    return label;
  }

  // GE curves that lie on top of each other (E* = 1e3 and 1e5 often agree to
  // a fraction of a percent): each drawn wider than the next and with its own
  // dash and marker, so the one underneath shows as a halo; the note says
  // which curves coincide and by how much.
  const GE_DASHES = [undefined, [2, 3], [10, 4], [12, 3, 2, 3]];
  const GE_MARKERS = [11, 6, 4, 3];
  // Colour with alpha, for a wide curve underneath another.
  const translucent = (hex, a) => `rgba(${parseInt(hex.slice(1, 3), 16)},${parseInt(hex.slice(3, 5), 16)},${parseInt(hex.slice(5, 7), 16)},${a})`;

  function coincidences(geChart) {
    const out = [];
    const ss = geChart.series;
    for (let a = 0; a < ss.length; a++) {
      for (let b = a + 1; b < ss.length; b++) {
        let worst = 0;
        let common = 0;
        const pb = new Map(ss[b].points.map((p) => [p.rate_m_s, p.max_elevation_m]));
        for (const p of ss[a].points) {
          const hb = pb.get(p.rate_m_s);
          if (p.max_elevation_m == null || hb == null) continue;
          common++;
          worst = Math.max(worst, Math.abs(p.max_elevation_m - hb) / Math.max(Math.abs(hb), 1e-9));
        }
        if (common > 0 && worst < 0.01) out.push({ a: geLabel(ss[a]), b: geLabel(ss[b]), worst });
      }
    }
    return out;
  }

  function mergedSpec(stringChart, geChart, quantity, log = false) {
    const pick = (p) => (quantity === "time" ? p.critical_time_s : p.max_elevation_m);
    const curves = [];
    const F = geChart.series[0]?.net_buoyancy_n;
    const str = stringChart?.series.find((s) => s.net_buoyancy_n === F);
    const n = geChart.series.length;
    geChart.series.forEach((s, k) => {
      curves.push({
        label: geLabel(s),
        points: s.points.map((p) => [p.rate_m_s, pick(p)]),
        // The first is the widest (drawn first, underneath, translucent), the last the thinnest.
        width: 2 + 2.5 * (n - 1 - k),
        alpha: k < n - 1 ? 0.5 : 1,
        dash: GE_DASHES[k % GE_DASHES.length],
        marker: GE_MARKERS[k % GE_MARKERS.length],
        color: COLORS[(k + 1) % COLORS.length],
      });
    });
    // The string FE model last, dashed, on top.
    if (str) curves.push({ label: `string FE model, ${F} N`, points: str.points.map((p) => [p.rate_m_s, pick(p)]), dash: [6, 4], width: 2, color: COLORS[0] });
    const x = [...new Set(curves.flatMap((c) => c.points.map(([v]) => v)))].sort((a, b) => a - b);
    const data = [x];
    const unit = quantity === "time" ? "s" : "m";
    const series = [{ label: "v (m/s)", value: legendValue(2) }];
    for (const c of curves) {
      const map = new Map(c.points);
      // On a log axis, t* = 0 (unstable at once) has no place: leave a gap.
      data.push(x.map((v) => {
        const y = map.has(v) ? map.get(v) : null;
        return y == null || (log && !(y > 0)) ? null : y;
      }));
      const points = c.marker ? { show: true, size: c.marker, width: 1.5, stroke: c.color, fill: "#fff" } : { show: false };
      const stroke = c.alpha && c.alpha < 1 ? translucent(c.color, c.alpha) : c.color;
      series.push({ label: `${c.label} (${unit})`, color: c.color, stroke, width: c.width, dash: c.dash, points, spanGaps: true, value: legendValue(1) });
    }
    return { data, series, log };
  }

  function renderGe(geChart, stringChart) {
    state.ge = geChart;
    state.geString = stringChart;
    for (const id of ["#ge-time-figure", "#ge-elevation-figure", "#ge-actions"]) $(id).hidden = false;
    state.plots.geTime?.destroy();
    state.plots.geElevation?.destroy();
    state.plots.geTime = makePlot($("#plot-ge-time"), mergedSpec(stringChart, geChart, "time", $("#ge-log-time").checked), "t* (s)");
    state.plots.geElevation = makePlot($("#plot-ge-elevation"), mergedSpec(stringChart, geChart, "elevation"), "h* (m)");
    const same = coincidences(geChart);
    state.geCoincide = same;
    const note = $("#ge-note");
    note.textContent = same.length
      ? same.map((c) => `${c.a} and ${c.b} coincide within ${(100 * c.worst).toFixed(2)} % at every rate`).join("; ") +
        ": the first is drawn wider and translucent, underneath, with larger markers, so both stay visible."
      : "";
    note.hidden = !same.length;
    $("#ge-csv").disabled = false;
    $("#ge-png").disabled = false;
  }

  $("#ge-log-time").addEventListener("change", () => {
    if (state.ge) renderGe(state.ge, state.geString);
  });

  // ---------- chart form ----------

  function updateHint() {
    const errors = [];
    const req = readChartRequest(errors);
    const hint = $("#points-hint");
    if (errors.length || !req.net_buoyancies_n) {
      hint.textContent = "";
      return;
    }
    const n = chartPoints(req);
    hint.textContent = `${n} points${wantsJob(req) ? " · runs as a background job" : ""}`;
  }

  let busy = false;
  chartForm.addEventListener("submit", async (ev) => {
    ev.preventDefault();
    if (busy) return;
    clearErrors();
    S.showFormError($("#form-error"), "");
    const errors = [];
    const req = readChartRequest(errors);
    if (errors.length) {
      for (const e of errors) showFieldError(e.field, e.message);
      inputFor(errors[0].field)?.focus();
      setStatus("error", "Fix the highlighted fields.");
      return;
    }
    busy = true;
    $("#plot-button").disabled = true;
    try {
      const n = chartPoints(req);
      let outcome;
      if (wantsJob(req)) {
        setStatus("busy", `Submitting a job for ${n} points…`);
        outcome = await runChartJob(req);
      } else {
        setStatus("busy", `Computing ${n} points…`);
        const r = await S.api("POST", "/api/v1/charts", req);
        // The direct route may refuse a chart as too large or the server as busy: use a job.
        if (!r.ok && (r.body?.error?.code === "too_large" || r.status === 503)) {
          setStatus("busy", "The server asked for a background job…");
          outcome = await runChartJob(req);
        } else {
          outcome = r.ok ? { chart: r.body, via: "direct" } : { status: r.status, error: r.body };
        }
      }
      if (outcome.chart) render(outcome.chart, req, outcome.via);
      else if (outcome.error?.error?.code === "cancelled") setStatus("idle", "Job cancelled.");
      else setStatus("error", renderApiError(outcome.status, outcome.error, $("#form-error")));
      if (outcome.chart && $("#ge-enabled").checked) {
        const geErrors = [];
        const geReq = readGeRequest(geErrors);
        if (geErrors.length) {
          for (const e of geErrors) showFieldError(e.field, e.message);
          setStatus("error", "Fix the highlighted GE fields.");
        } else {
          const points = geReq.rates_m_s.count * geReq.stiffness_ratios.length;
          geAfterString = true;
          setStatus("busy", `Submitting a GE job for ${points} points…`);
          state.geRequest = geReq;
          const ge = await runChartJob(geReq, points).finally(() => {
            geAfterString = false;
          });
          if (ge.chart) {
            renderGe(ge.chart, outcome.chart);
            setStatus("ready", `String: ${curves(outcome.chart.series.length)}; GE: ${curves(ge.chart.series.length)}, ${points} points (${ge.via}).`);
          } else if (ge.error?.error?.code === "cancelled") setStatus("idle", "GE job cancelled.");
          else setStatus("error", renderApiError(ge.status, geErrorBody(ge.error), $("#form-error")));
        }
      }
    } finally {
      busy = false;
      $("#plot-button").disabled = false;
    }
  });

  // Other inputs than the chart's: dimmed until plotted again.
  const stale = () => {
    if (state.chart && statusEl.dataset.state === "ready") setStatus("stale", "Inputs changed: plot the chart again.");
  };
  chartForm.addEventListener("input", (ev) => {
    if (ev.target.matches("input")) S.clearFieldError(ev.target);
    S.writeUrl();
    stale();
    updateHint();
  });
  document.addEventListener("tetherplan:system-input", () => {
    stale();
    updateHint();
  });

  // ---------- safe rate ----------

  safeForm.addEventListener("submit", async (ev) => {
    ev.preventDefault();
    clearErrors();
    S.showFormError($("#safe-error"), "");
    const out = $("#safe-result");
    out.hidden = true;
    const errors = [];
    const req = readSystem(errors);
    req.target_elevation_m = readNumber("target_elevation_m", errors);
    if (errors.length) {
      for (const e of errors) showFieldError(e.field, e.message);
      S.showFormError($("#safe-error"), "Fix the highlighted fields.");
      return;
    }
    $("#safe-button").disabled = true;
    try {
      const r = await S.api("POST", "/api/v1/safe-rate", req);
      if (!r.ok) {
        const msg = renderApiError(r.status, r.body, $("#safe-error"));
        if (!$("#safe-error").textContent) S.showFormError($("#safe-error"), msg);
        return;
      }
      const a = r.body;
      const rows = [];
      if (a.max_rate_m_s != null) {
        // Converged answers are already the safe side of the error bound.
        rows.push(["Largest safe rate", `${fmt(a.max_rate_m_s, 2)} m/s`]);
        if (a.max_rate_error_m_s != null) rows.push([a.converged ? "Discretisation error (already subtracted)" : "Discretisation error of this mesh", `± ${fmt(a.max_rate_error_m_s, 3)} m/s`]);
        rows.push(["Time to reach H", `${fmt(a.time_to_target_s, 1)} s`]);
      } else {
        rows.push(["Largest safe rate", "none"]);
        rows.push(["Why", a.reason || "no constant rate reaches the target safely"]);
      }
      rows.push(["Closed-form estimate √(F/ρA − gH)", a.closed_form_rate_m_s != null ? `${fmt(a.closed_form_rate_m_s, 2)} m/s` : "none (above the static limit)"]);
      if (a.groups) rows.push(["Static lift limit F/(ρA g)", `${fmt(a.groups.static_lift_limit_m, 1)} m`]);
      out.replaceChildren(
        ...rows.flatMap(([k, v]) => {
          const dt = document.createElement("dt");
          dt.textContent = k;
          const dd = document.createElement("dd");
          dd.textContent = v;
          return [dt, dd];
        }),
      );
      out.dataset.maxRate = a.max_rate_m_s ?? "";
      out.hidden = false;
    } finally {
      $("#safe-button").disabled = false;
    }
  });



  // ---------- downloads ----------

  const { download, inputLines, sig } = S;

  function chartCsv(chart, request) {
    const lines = ["# tetherplan deployment chart", ...inputLines(request), `# elements,${chart.elements}`,
      "net_buoyancy_n,rate_m_s,critical_time_s,max_elevation_m,closed_form_elevation_m"];
    for (const s of chart.series) {
      for (const p of s.points) {
        lines.push([s.net_buoyancy_n, p.rate_m_s, p.critical_time_s, p.max_elevation_m, p.closed_form_elevation_m].map(sig).join(","));
      }
    }
    return lines.join("\n") + "\n";
  }

  $("#download-csv").addEventListener("click", () => {
    if (state.chart) download(new Blob([chartCsv(state.chart, state.request)], { type: "text/csv" }), "deployment-chart.csv");
  });

  // Both plots on one white canvas, each with its caption and a drawn legend, the inputs below.
  function chartPng(
    blocks = [
      [state.plots.time, `Critical time t* (s) against deployment rate v (m/s)${$("#log-time").checked ? ", log scale" : ""}`],
      [state.plots.elevation, "Highest safe elevation h* (m) against deployment rate v (m/s)"],
    ],
    footer = `Inputs: ${inputLines(state.request).map((l) => l.replace("# input ", "").replace(",", " = ")).join("; ")}.`,
  ) {
    return S.plotsPng(blocks, footer);
  }

  $("#download-png").addEventListener("click", () => {
    if (!state.chart) return;
    chartPng().toBlob((blob) => download(blob, "deployment-chart.png"), "image/png");
  });

  // The GE chart: its request and the string chart's as inputs, one row per
  // point of every GE series and of the string curve drawn beside them.
  function geCsv() {
    const ge = state.ge;
    const lines = ["# tetherplan GE deployment chart beside the linear string", ...inputLines(state.geRequest).map((l) => l.replace("# input ", "# input ge.")),
      ...inputLines(state.request).map((l) => l.replace("# input ", "# input string.")),
      `# ge.elements,${ge.elements}`, `# ge.time_scale_s,${sig(ge.time_scale_s)}`, `# ge.wave_speed_m_s,${sig(ge.wave_speed_m_s)}`,
      ...inputLines({ integrator: ge.integrator }).map((l) => l.replace("# input ", "# ge.")),
      "model,stiffness_ratio,perturbation_force_n,net_buoyancy_n,wind_amplitude_nondim,rate_m_s,onset,critical_time_s,max_elevation_m,string_closed_form_elevation_m,extensible_closed_form_elevation_m,closed_form_applies"];
    const cell = (v) => (v == null ? "" : sig(v));
    for (const s of ge.series) {
      for (const p of s.points) {
        lines.push(["ge", s.stiffness_ratio, s.perturbation_force_n, s.net_buoyancy_n, s.wind_amplitude_nondim, p.rate_m_s, p.onset, p.critical_time_s,
          p.max_elevation_m, p.string_closed_form_elevation_m, p.extensible_closed_form_elevation_m, p.closed_form_applies].map(cell).join(","));
      }
    }
    const F = ge.series[0]?.net_buoyancy_n;
    const str = state.geString?.series.find((s) => s.net_buoyancy_n === F);
    for (const p of str?.points ?? []) {
      lines.push(["string", "", "", F, "", p.rate_m_s, p.critical_time_s > 0 ? "during" : "immediate", p.critical_time_s, p.max_elevation_m, p.closed_form_elevation_m, "", ""].map(cell).join(","));
    }
    return lines.join("\n") + "\n";
  }

  $("#ge-csv").addEventListener("click", () => {
    if (state.ge) download(new Blob([geCsv()], { type: "text/csv" }), "ge-deployment-chart.csv");
  });

  $("#ge-png").addEventListener("click", () => {
    if (!state.ge) return;
    const note = $("#ge-note").hidden ? "" : ` ${$("#ge-note").textContent}`;
    const inputs = [...inputLines(state.geRequest).map((l) => l.replace("# input ", "GE ")), `string elements ${state.geString?.converged ? "converged" : state.geString?.elements}`]
      .map((l) => l.replace(",", " = "));
    chartPng([
      [state.plots.geTime, `GE beam beside the string: critical time t* (s) against deployment rate v (m/s)${$("#ge-log-time").checked ? ", log scale" : ""}. Solid and dotted: the GE beam, one curve per E*; dashed: the linear-string FE model, not a closed form.${note}`],
      [state.plots.geElevation, "GE beam beside the string: highest safe elevation h* (m) against deployment rate v (m/s)"],
    ], `Inputs: ${inputs.join("; ")}.`).toBlob((blob) => download(blob, "ge-deployment-chart.png"), "image/png");
  });

  updateHint();
})();
