// Uncertainty bands panel (issue 14): a <section> that posts POST
// /api/v1/bands with the system card's tether and aerostat (in calm air) and
// the plan's target altitude, and shades the 5–95 % band of h* and t* around
// the median and the nominal chart, with CSV export of the percentiles, their
// sampling errors and the uncertainty inputs. Needs uPlot and shared/.
"use strict";

import S from "./shared/index.js";

(function () {
  // What this panel reads from the system card (shared/system.js): the tether
  // and the aerostat in calm air, gravity and the starting length.
  const CARD = S.declareCard("bands", [
    "cable.preset", "cable.diameter_m if preset", "cable.mass_per_length_kg_m", "cable.breaking_strength_n",
    "aerostat.preset", "aerostat.net_buoyancy_n", "aerostat.mass_kg",
    "gravity_m_s2", "initial_length_m",
  ]);
  const SOURCE = "bands";
  // [id, label, default, name (the request path; the σ are not one)]
  const fields = [
    ["bands-lift-sd", "Spread σ of the net buoyancy (N)", "50", "uncertainty.net_buoyancy_sd_n"],
    ["bands-rhoa-sd", "Spread σ of the mass per length (kg/m)", "0.002", "uncertainty.mass_per_length_sd_kg_m"],
    ["bands-min", "Smallest rate (m/s)", "5", "rates_m_s.min"],
    ["bands-max", "Largest rate (m/s)", "60", "rates_m_s.max"],
    ["bands-count", "Rates (count)", "24", "rates_m_s.count"],
    ["bands-samples", "Samples", "500", "uncertainty.samples"],
    ["bands-seed", "Seed", "1", "uncertainty.seed"],
  ];
  const section = document.createElement("section");
  section.id = "bands";
  section.innerHTML = `
    <h2>Uncertainty bands</h2>
    <p class="hint">Monte Carlo over a normal net buoyancy and mass per length about the system card's values, in calm air:
      5–95 % band of h* and t* (converged chart points), median and nominal curves, and the probability that the plan's
      target altitude is unsafe.</p>
    <form id="bands-form" novalidate data-url-prefix="bands.">
      ${fields.map(([id, label, value, name]) => `<div class="field"><label for="${id}">${label}</label>
        <input id="${id}" name="${name}" inputmode="decimal" value="${value}"></div>`).join("")}
      <div class="actions">
        <button type="submit" id="bands-button">Compute bands</button>
        <button type="button" id="bands-csv" class="secondary" disabled>Download CSV</button>
      </div>
      <p id="bands-error" class="error" role="alert" hidden></p>
    </form>
    <p id="bands-summary" hidden></p>
    <div id="bands-plot-elevation"></div>
    <div id="bands-plot-time"></div>`;
  const anchor = document.getElementById("safe-rate");
  if (anchor?.parentNode) anchor.parentNode.insertBefore(section, anchor.nextSibling);
  else document.body.appendChild(section);

  const $ = (id) => document.getElementById(id);
  const num = (id) => Number($(id).value);
  const plots = {};
  let last = null;

  const roots = () => [document.getElementById("bands-form"), document.getElementById("plan-form")];

  function request(errors) {
    const sys = S.readSystem(errors, CARD);
    const inputs = [{ field: "aerostat.net_buoyancy_n", distribution: "normal", mean: sys.aerostat.net_buoyancy_n, std_dev: num("bands-lift-sd") }];
    if (sys.cable.mass_per_length_kg_m != null) {
      inputs.push({ field: "cable.mass_per_length_kg_m", distribution: "normal", mean: sys.cable.mass_per_length_kg_m, std_dev: num("bands-rhoa-sd") });
    }
    return {
      ...sys,
      rates_m_s: { min: num("bands-min"), max: num("bands-max"), count: num("bands-count") },
      target_elevation_m: S.readNumber(roots(), "target_elevation_m", errors),
      uncertainty: { samples: num("bands-samples"), seed: num("bands-seed"), inputs },
    };
  }

  // The API names the distributions by index: uncertainty.inputs[0] is the
  // buoyancy's spread, inputs[1] the mass per length's.
  function fieldOf(err) {
    const m = /^uncertainty\.inputs\[(\d)\]/.exec(err?.field ?? "");
    if (m) return m[1] === "0" ? "uncertainty.net_buoyancy_sd_n" : "uncertainty.mass_per_length_sd_kg_m";
    return err?.field;
  }

  function plot(el, key, label, resp) {
    const pts = resp.points;
    const x = pts.map((p) => p.rate_m_s);
    const nominalKey = key === "max_elevation_m" ? "nominal_max_elevation_m" : "nominal_critical_time_s";
    const data = [x, pts.map((p) => p[key].p95), pts.map((p) => p[key].p50), pts.map((p) => p[key].p05), pts.map((p) => p[nominalKey])];
    el.textContent = "";
    const axis = { stroke: "#333", grid: { stroke: "#e5e5e5" }, ticks: { stroke: "#ccc" } };
    return new uPlot(
      {
        width: Math.max(280, Math.min(900, el.clientWidth || 600)),
        height: 260,
        scales: { x: { time: false } },
        series: [
          { label: "rate (m/s)" },
          { label: "95 %", stroke: "rgba(31,119,180,0.6)" },
          { label: "median", stroke: "#1f77b4", width: 2 },
          { label: "5 %", stroke: "rgba(31,119,180,0.6)" },
          { label: "nominal", stroke: "#d62728", dash: [6, 4] },
        ],
        bands: [{ series: [1, 3], fill: "rgba(31,119,180,0.18)" }],
        axes: [{ ...axis, label: "Deployment rate v (m/s)" }, { ...axis, label, size: 60 }],
      },
      data,
      el,
    );
  }

  function csv(resp) {
    const lines = [
      `# samples ${resp.samples}, valid ${resp.valid_samples}, seed ${resp.seed}, confidence ${resp.confidence_level_nondim}, converged ${resp.converged}`,
      ...resp.inputs.map((i) => `# input ${JSON.stringify(i)}`),
      "rate_m_s,h_p05_m,h_p50_m,h_p95_m,h_p05_error_m,h_p50_error_m,h_p95_error_m,t_p05_s,t_p50_s,t_p95_s,t_p05_error_s,t_p50_error_s,t_p95_error_s,nominal_h_m,nominal_t_s,probability_unsafe_nondim,probability_unsafe_error_nondim",
    ];
    for (const p of resp.points) {
      const h = p.max_elevation_m;
      const t = p.critical_time_s;
      const pu = p.probability_unsafe;
      lines.push([p.rate_m_s, h.p05, h.p50, h.p95, h.p05_error, h.p50_error, h.p95_error, t.p05, t.p50, t.p95,
        t.p05_error, t.p50_error, t.p95_error, p.nominal_max_elevation_m, p.nominal_critical_time_s,
        pu?.probability_nondim, pu?.standard_error_nondim].map((v) => (v == null ? "" : Number(v.toPrecision(6)))).join(","));
    }
    return lines.join("\n") + "\n";
  }

  $("bands-form").addEventListener("submit", async (ev) => {
    ev.preventDefault();
    S.clearErrors(SOURCE);
    S.showFormError($("bands-error"), "");
    S.writeUrl();
    const errors = [];
    const req = request(errors);
    if (errors.length) {
      S.showInputErrors(roots(), errors, SOURCE);
      S.showFormError($("bands-error"), "Fix the highlighted fields.");
      return;
    }
    $("bands-button").disabled = true;
    const res = await S.api("POST", "/api/v1/bands", req);
    $("bands-button").disabled = false;
    if (!res.ok) {
      const e = res.body?.error;
      const body = e ? { error: { ...e, field: fieldOf(e) } } : res.body;
      const text = S.renderApiError(roots(), res.status, body, null, SOURCE);
      S.showFormError($("bands-error"), text);
      return;
    }
    last = res.body;
    plots.elevation?.destroy();
    plots.time?.destroy();
    plots.elevation = plot($("bands-plot-elevation"), "max_elevation_m", "h* (m)", last);
    plots.time = plot($("bands-plot-time"), "critical_time_s", "t* (s)", last);
    const summary = $("bands-summary");
    summary.hidden = false;
    summary.textContent = `${last.valid_samples} of ${last.samples} samples (seed ${last.seed}); shaded: 5–95 % of h* and t*.`;
    $("bands-csv").disabled = false;
  });

  $("bands-csv").addEventListener("click", () => {
    if (!last) return;
    const a = document.createElement("a");
    a.href = URL.createObjectURL(new Blob([csv(last)], { type: "text/csv" }));
    a.download = "tetherplan-bands.csv";
    a.click();
    setTimeout(() => URL.revokeObjectURL(a.href), 1000);
  });
})();
