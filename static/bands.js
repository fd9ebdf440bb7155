// Uncertainty bands panel (issue 14): a self-contained <section> that posts
// POST /api/v1/bands and shades the 5–95 % band of h* and t* around the
// median and the nominal chart, with CSV export of the percentiles, their
// sampling errors and the uncertainty inputs. Needs uPlot and common.js.
"use strict";

(function () {
  const { api, showFormError } = window.tetherplanCommon;
  const fields = [
    ["bands-lift", "Net buoyancy F (N)", "1000"],
    ["bands-lift-sd", "σ of F (N)", "50"],
    ["bands-rhoa", "Mass per length ρA (kg/m)", "0.078"],
    ["bands-rhoa-sd", "σ of ρA (kg/m)", "0.002"],
    ["bands-mass", "Aerostat mass m (kg)", "10"],
    ["bands-min", "Smallest rate (m/s)", "5"],
    ["bands-max", "Largest rate (m/s)", "60"],
    ["bands-count", "Rates", "24"],
    ["bands-samples", "Samples", "500"],
    ["bands-seed", "Seed", "1"],
    ["bands-target", "Target elevation (m)", "1200"],
  ];
  const section = document.createElement("section");
  section.id = "bands";
  section.innerHTML = `
    <h2>Uncertainty bands</h2>
    <p class="hint">Monte Carlo over a normal net buoyancy and mass per length: 5–95 % band of h* and t*
      (converged chart points), median and nominal curves, and the probability that the target is unsafe.</p>
    <form id="bands-form" novalidate>
      ${fields.map(([id, label, value]) => `<div class="field"><label for="${id}">${label}</label>
        <input id="${id}" inputmode="decimal" value="${value}"></div>`).join("")}
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

  function request() {
    return {
      cable: { mass_per_length_kg_m: num("bands-rhoa") },
      aerostat: { net_buoyancy_n: num("bands-lift"), mass_kg: num("bands-mass") },
      rates_m_s: { min: num("bands-min"), max: num("bands-max"), count: num("bands-count") },
      target_elevation_m: num("bands-target"),
      uncertainty: {
        samples: num("bands-samples"),
        seed: num("bands-seed"),
        inputs: [
          { field: "aerostat.net_buoyancy_n", distribution: "normal", mean: num("bands-lift"), std_dev: num("bands-lift-sd") },
          { field: "cable.mass_per_length_kg_m", distribution: "normal", mean: num("bands-rhoa"), std_dev: num("bands-rhoa-sd") },
        ],
      },
    };
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
    showFormError($("bands-error"), "");
    $("bands-button").disabled = true;
    const res = await api("POST", "/api/v1/bands", request());
    $("bands-button").disabled = false;
    if (!res.ok) {
      const e = res.body?.error;
      showFormError($("bands-error"), e ? e.message : `HTTP ${res.status}`);
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
