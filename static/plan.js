// The deployment plan (SPEC §7): the first section of the page. Reads the
// plan form, keeps its inputs in the URL (?plan.<field>=…, shareable), posts
// /api/v1/plan, and shows the go/no-go, the schedule plotted (length, rate,
// tension, margin against time), the operator's table, the margins, a print
// layout and CSV/JSON export with every input recorded. Self-contained: only
// window.tetherplanCommon and uPlot are shared with the other scripts.
"use strict";

(function () {
  const { api, clearFieldError, fieldMessage, showFormError } = window.tetherplanCommon;
  const form = document.getElementById("plan-form");
  if (!form) return;
  const $ = (id) => document.getElementById(id);
  const status = $("plan-status");
  const errorBox = $("plan-error");

  // Presets of tether + aerostat (+ winch, target, reserve).
  const PRESETS = {
    thesis: { "cable.mass_per_length_kg_m": "0.078", "aerostat.net_buoyancy_n": "1000", "aerostat.mass_kg": "10",
      initial_length_m: "1", target_elevation_m: "1200", "winch.max_rate_m_s": "40", "winch.max_acceleration_m_s2": "2",
      lift_reserve_nondim: "0.05" },
    heavy: { "cable.mass_per_length_kg_m": "0.25", "aerostat.net_buoyancy_n": "3000", "aerostat.mass_kg": "40",
      initial_length_m: "5", target_elevation_m: "1000", "winch.max_rate_m_s": "8", "winch.max_acceleration_m_s2": "0.3",
      lift_reserve_nondim: "0.1" },
    tight: { "cable.mass_per_length_kg_m": "0.078", "aerostat.net_buoyancy_n": "1000", "aerostat.mass_kg": "10",
      initial_length_m: "1", target_elevation_m: "1200", "winch.max_rate_m_s": "40", "winch.max_acceleration_m_s2": "2",
      lift_reserve_nondim: "0.075" },
  };

  // Uncertainty bands (issue 14): a fieldset added by this script. When
  // checked, the plan goes to /api/v1/plan/bands and the tension and margin
  // plots shade the 5–95 % band of the samples around the plan's traces.
  const bandsBox = document.createElement("fieldset");
  bandsBox.id = "plan-bands";
  bandsBox.innerHTML = `<legend>Uncertainty (5–95 % bands, optional)</legend>
    <div class="field"><label for="plan-bands-on"><input type="checkbox" id="plan-bands-on"> Shade the 5–95 % band</label></div>
    <div class="field"><label for="plan-bands-lift-sd">σ of F (N)</label><input id="plan-bands-lift-sd" inputmode="decimal" value="50"></div>
    <div class="field"><label for="plan-bands-rhoa-sd">σ of ρA (kg/m)</label><input id="plan-bands-rhoa-sd" inputmode="decimal" value="0.002"></div>
    <div class="field"><label for="plan-bands-samples">Samples</label><input id="plan-bands-samples" inputmode="numeric" value="500"></div>
    <div class="field"><label for="plan-bands-seed">Seed</label><input id="plan-bands-seed" inputmode="numeric" value="1"></div>
    <p id="plan-bands-summary" class="note" hidden></p>`;
  form.insertBefore(bandsBox, form.querySelector(".actions"));
  const bandsOn = () => $("plan-bands-on").checked;

  function uncertainty(body) {
    const inputs = [];
    const liftSd = Number($("plan-bands-lift-sd").value);
    const rhoSd = Number($("plan-bands-rhoa-sd").value);
    if (liftSd > 0) inputs.push({ field: "aerostat.net_buoyancy_n", distribution: "normal", mean: body.aerostat.net_buoyancy_n, std_dev: liftSd });
    if (rhoSd > 0) inputs.push({ field: "cable.mass_per_length_kg_m", distribution: "normal", mean: body.cable.mass_per_length_kg_m, std_dev: rhoSd });
    return { samples: Number($("plan-bands-samples").value), seed: Number($("plan-bands-seed").value), inputs };
  }

  const inputs = () => Array.from(form.querySelectorAll("[data-plan-field]"));
  const byField = (f) => form.querySelector(`[data-plan-field="${f}"]`);

  // Optional jerk limit, placed after the winch acceleration (empty: none).
  (function addJerkField() {
    const acc = byField("winch.max_acceleration_m_s2");
    if (!acc || byField("winch.max_jerk_m_s3")) return;
    const field = document.createElement("div");
    field.className = "field";
    const label = document.createElement("label");
    label.htmlFor = "plan-jerk";
    label.textContent = "Winch max jerk (m/s³, optional)";
    const input = document.createElement("input");
    input.id = "plan-jerk";
    input.dataset.planField = "winch.max_jerk_m_s3";
    input.inputMode = "decimal";
    input.placeholder = "none";
    input.value = "";
    field.append(label, input);
    acc.closest(".field").after(field);
  })();

  function num(field) {
    const el = byField(field);
    const text = el.value.trim();
    return text === "" ? null : Number(text);
  }

  // "0:5, 3600:15" → [{time_s, wind_speed_m_s}, …]
  function parseForecast(text) {
    return text
      .split(",")
      .map((s) => s.trim())
      .filter(Boolean)
      .map((pair) => {
        const [t, u] = pair.split(":").map((x) => Number(x.trim()));
        return { time_s: t, wind_speed_m_s: u };
      });
  }

  function request() {
    const body = {
      cable: { mass_per_length_kg_m: num("cable.mass_per_length_kg_m") },
      aerostat: { net_buoyancy_n: num("aerostat.net_buoyancy_n"), mass_kg: num("aerostat.mass_kg") },
      initial_length_m: num("initial_length_m"),
      gravity_m_s2: num("gravity_m_s2"),
      target_elevation_m: num("target_elevation_m"),
      winch: { max_rate_m_s: num("winch.max_rate_m_s"), max_acceleration_m_s2: num("winch.max_acceleration_m_s2") },
      lift_reserve_nondim: num("lift_reserve_nondim"),
      samples: 61,
    };
    const jerk = num("winch.max_jerk_m_s3");
    if (jerk !== null) body.winch.max_jerk_m_s3 = jerk;
    const breaking = num("tether.breaking_strength_n");
    if (breaking !== null) body.tether = { breaking_strength_n: breaking, safety_factor_nondim: num("tether.safety_factor_nondim") ?? 5 };
    const forecast = byField("haul_down.forecast").value.trim();
    const windLimit = num("haul_down.max_operating_wind_m_s");
    if (forecast && windLimit !== null) {
      body.haul_down = { forecast: parseForecast(forecast), max_operating_wind_m_s: windLimit };
    }
    return body;
  }

  // ---- URL state ----
  function writeUrl() {
    const params = new URLSearchParams(window.location.search);
    for (const el of inputs()) params.set(`plan.${el.dataset.planField}`, el.value.trim());
    params.set("plan.preset", $("plan-preset").value);
    history.replaceState(null, "", `${window.location.pathname}?${params.toString()}${window.location.hash}`);
  }

  function readUrl() {
    const params = new URLSearchParams(window.location.search);
    let any = false;
    if (params.has("plan.preset")) $("plan-preset").value = params.get("plan.preset");
    for (const el of inputs()) {
      const key = `plan.${el.dataset.planField}`;
      if (params.has(key)) {
        el.value = params.get(key);
        any = true;
      }
    }
    return any;
  }

  function applyPreset(name) {
    const p = PRESETS[name];
    if (!p) return;
    for (const [field, value] of Object.entries(p)) byField(field).value = value;
  }

  // ---- formatting ----
  const fmt = (v, d = 1) => (v === null || v === undefined || !Number.isFinite(v) ? "–" : v.toFixed(d));
  // Legend values: blank until the cursor is on the plot.
  const lv = (d) => (u, v) => (v == null ? "" : fmt(v, d));

  // ---- plots ----
  const plots = {};
  function plotSize(el) {
    const width = Math.max(240, Math.floor(el.clientWidth || 300));
    return { width, height: Math.round(Math.min(260, Math.max(180, width * 0.55))) };
  }

  function makePlot(el, yLabel, series, data, bands) {
    el.textContent = "";
    const axis = { stroke: "#333", grid: { stroke: "#e5e5e5" }, ticks: { stroke: "#ccc" } };
    return new uPlot(
      {
        ...plotSize(el),
        series: [{ label: "t (s)", value: lv(1) }, ...series],
        scales: { x: { time: false } },
        axes: [
          { ...axis, label: "Time t (s)" },
          { ...axis, label: yLabel, size: 60 },
        ],
        legend: { live: true },
        cursor: { drag: { x: true, y: false } },
        ...(bands ? { bands } : {}),
      },
      data,
      el,
    );
  }

  function drawPlots(r) {
    const s = r.schedule;
    const t = s.map((x) => x.time_s);
    const col = (k) => s.map((x) => x[k]);
    const absRate = s.map((x) => Math.abs(x.rate_m_s));
    plots.length = makePlot($("plan-plot-length"), "Length L (m)",
      [{ label: "L (m)", stroke: "#0b5cad", width: 2, value: lv(1) }], [t, col("length_m")]);
    plots.rate = makePlot($("plan-plot-rate"), "Rate (m/s)", [
      { label: "|L̇| (m/s)", stroke: "#0b5cad", width: 2, value: lv(2) },
      { label: "stability ceiling (m/s)", stroke: "#b00020", width: 1.5, dash: [6, 4], value: lv(2) },
    ], [t, absRate, col("rate_ceiling_m_s")]);
    const tension = [{ label: "winch (N)", stroke: "#0b5cad", width: 2, value: lv(1) },
      { label: "peak, at aerostat (N)", stroke: "#7a4a00", width: 1.5, value: lv(1) }];
    const tdata = [t, col("winch_tension_n"), col("max_tension_n")];
    if (r.limits.allowable_tension_n) {
      tension.push({ label: "allowable (N)", stroke: "#b00020", width: 1.5, dash: [6, 4], value: lv(1) });
      tdata.push(s.map(() => r.limits.allowable_tension_n));
    }
    const b = lastBands && lastBands.instants.length === s.length ? lastBands.instants : null;
    const shade = (series, data, key, color, d) => {
      if (!b) return null;
      const hi = series.length + 1;
      series.push({ label: "95 %", stroke: color, width: 0.5, value: lv(d) }, { label: "5 %", stroke: color, width: 0.5, value: lv(d) });
      data.push(b.map((x) => x[key].p95), b.map((x) => x[key].p05));
      return [{ series: [hi, hi + 1], fill: "rgba(11,92,173,0.15)" }];
    };
    const tBands = shade(tension, tdata, "winch_tension_n", "#6b9bd1", 1);
    plots.tension = makePlot($("plan-plot-tension"), "Tension (N)", tension, tdata, tBands);
    const mseries = [{ label: "stability margin (m/s)", stroke: "#1a7f37", width: 2, value: lv(2) }];
    const mdata = [t, col("stability_margin_m_s")];
    const mBands = shade(mseries, mdata, "stability_margin_m_s", "#6fbf86", 2);
    plots.margin = makePlot($("plan-plot-margin"), "Margin (m/s)", mseries, mdata, mBands);
  }

  // ---- tables ----
  function cell(tr, text, cls) {
    const td = document.createElement("td");
    td.textContent = text;
    if (cls) td.className = cls;
    tr.appendChild(td);
  }

  function fillPhases(r) {
    const body = $("plan-phases").querySelector("tbody");
    body.textContent = "";
    r.phases.forEach((p, i) => {
      const tr = document.createElement("tr");
      cell(tr, String(i + 1));
      cell(tr, `${fmt(p.start_time_s, 1)} – ${fmt(p.end_time_s, 1)}`, "num");
      cell(tr, `${fmt(p.start_length_m, 1)} → ${fmt(p.end_length_m, 1)}`, "num");
      cell(tr, `${fmt(Math.abs(p.start_rate_m_s), 2)} → ${fmt(Math.abs(p.end_rate_m_s), 2)}`, "num");
      cell(tr, fmt(p.mean_acceleration_m_s2, 3), "num");
      cell(tr, p.instruction);
      body.appendChild(tr);
    });
  }

  function fillSchedule(r) {
    const body = $("plan-table").querySelector("tbody");
    body.textContent = "";
    for (const s of r.schedule) {
      const tr = document.createElement("tr");
      cell(tr, fmt(s.time_s, 1), "num");
      cell(tr, fmt(s.length_m, 1), "num");
      cell(tr, fmt(Math.abs(s.rate_m_s), 2), "num");
      cell(tr, fmt(s.acceleration_m_s2, 3), "num");
      cell(tr, fmt(s.winch_tension_n, 0), "num");
      cell(tr, fmt(s.stability_margin_m_s, 2), "num");
      body.appendChild(tr);
    }
  }

  function dl(el, rows) {
    el.textContent = "";
    for (const [k, v] of rows) {
      if (v === null) continue;
      const dt = document.createElement("dt");
      dt.textContent = k;
      const dd = document.createElement("dd");
      dd.textContent = v;
      el.append(dt, dd);
    }
  }

  // Every input, flattened: [["cable.mass_per_length_kg_m", 0.078], …]
  function flatten(obj, prefix = "", out = []) {
    for (const [k, v] of Object.entries(obj ?? {})) {
      const key = prefix ? `${prefix}.${k}` : k;
      if (Array.isArray(v)) {
        v.forEach((item, i) => (typeof item === "object" ? flatten(item, `${key}[${i}]`, out) : out.push([`${key}[${i}]`, item])));
      } else if (v && typeof v === "object") flatten(v, key, out);
      else out.push([key, v]);
    }
    return out;
  }

  function fillInputs(r) {
    dl($("plan-inputs"), flatten(r.inputs).map(([k, v]) => [k, v === null ? "none" : String(v)]));
  }

  function showResult(r) {
    const verdict = $("plan-verdict");
    verdict.hidden = false;
    verdict.dataset.go = String(r.go);
    verdict.querySelector(".word").textContent = r.go ? "GO" : "NO-GO";
    verdict.querySelector(".why").textContent = r.reason;
    const c = r.constant_rate;
    const h = r.haul_down;
    const tc = r.transient_check;
    dl($("plan-figures"), [
      ["Direction", r.direction],
      ["Duration", r.duration_s === null ? "no schedule" : `${fmt(r.duration_s, 1)} s`],
      ["Binding limit", r.binding_limit ?? null],
      ["Best constant rate", c ? `${fmt(c.rate_m_s, 2)} m/s, ${fmt(c.duration_s, 1)} s` : null],
      ["Time saved", c ? `${fmt(c.time_saved_s, 1)} s (${fmt(100 * c.time_saved_fraction_nondim, 0)} %)` : null],
      ["Minimum-time bound", r.bound ? `${fmt(r.bound.duration_s, 1)} s: ${r.bound.explanation}` : null],
      ["Lift limit with reserve", `${fmt(r.limits.lift_limit_m, 1)} m`],
      ["Smallest stability margin", r.limits.min_stability_margin_m_s === null ? null : `${fmt(r.limits.min_stability_margin_m_s, 2)} m/s`],
      ["Peak tension", r.limits.peak_tension_n === null ? null : `${fmt(r.limits.peak_tension_n, 0)} N`],
      ["Allowable tension", r.limits.allowable_tension_n ? `${fmt(r.limits.allowable_tension_n, 0)} N` : null],
      ["Transient check", tc ? `${tc.outcome}; peak tip ${fmt(tc.peak_tip_deflection_m, 3)} m from ${fmt(tc.initial_tip_deflection_m, 3)} m, ×${fmt(tc.amplification_nondim, 3)} at the end` : null],
      ["WKB growth", r.oscillation?.wkb_amplification_nondim ? `×${fmt(r.oscillation.wkb_amplification_nondim, 3)}` : null],
      ["Tension rise hauling in", r.retrieval ? `${fmt(r.retrieval.tension_rise_n, 1)} N` : null],
      ["Haul-down", h ? h.reason : null],
    ]);
    fillInputs(r);
    const has = r.schedule.length > 0;
    $("plan-output").hidden = !has;
    if (has) {
      fillPhases(r);
      fillSchedule(r);
      drawPlots(r);
    }
    $("plan-csv").disabled = !has;
    $("plan-json").disabled = false;
    $("plan-print").disabled = false;
  }

  let last = null;
  let lastBands = null;

  async function runPlan() {
    for (const el of inputs()) clearFieldError(el);
    showFormError(errorBox, "");
    status.dataset.state = "busy";
    status.textContent = "Planning…";
    writeUrl();
    const body = request();
    const withBands = bandsOn();
    if (withBands) body.uncertainty = uncertainty(body);
    const res = await api("POST", withBands ? "api/v1/plan/bands" : "api/v1/plan", body);
    if (!res.ok) {
      const err = res.body?.error;
      status.dataset.state = "error";
      status.textContent = err?.message ?? `HTTP ${res.status}`;
      const el = err?.field ? byField(err.field) ?? byField(err.field.replace(/\[\d+\].*$/, "")) : null;
      if (el) {
        const box = el.closest(".field");
        const p = document.createElement("p");
        p.className = "field-error";
        p.id = `${el.id}-error`;
        p.textContent = fieldMessage(err.field, err.message);
        box.appendChild(p);
        el.setAttribute("aria-invalid", "true");
        el.setAttribute("aria-describedby", p.id);
      } else {
        showFormError(errorBox, err?.message ?? "the plan failed");
      }
      return;
    }
    lastBands = withBands ? res.body : null;
    last = withBands ? res.body.plan : res.body;
    const summary = $("plan-bands-summary");
    summary.hidden = !lastBands || !lastBands.probability_unstable;
    if (!summary.hidden) {
      const pc = (p) => (p ? `${fmt(100 * p.probability_nondim, 1)} % (95 %: ${fmt(100 * p.low_nondim, 1)}–${fmt(100 * p.high_nondim, 1)} %)` : "–");
      summary.textContent = `${lastBands.valid_samples} samples: P(unstable somewhere) ${pc(lastBands.probability_unstable)}; ` +
        `P(below the lift reserve) ${pc(lastBands.probability_below_reserve)}; P(over the rating) ${pc(lastBands.probability_over_rating)}.`;
    }
    window.tetherplan = window.tetherplan || {};
    window.tetherplan.planBands = lastBands;
    window.tetherplan.plan = last;
    window.tetherplan.planPlots = plots;
    showResult(last);
    status.dataset.state = "ready";
    status.textContent = last.feasible
      ? `Plan ready: ${fmt(last.duration_s, 1)} s (computed in ${fmt(1000 * last.compute_time_s, 0)} ms).`
      : `No schedule: ${last.binding_limit}.`;
  }

  // ---- export ----
  function download(name, type, text) {
    const a = document.createElement("a");
    a.href = URL.createObjectURL(new Blob([text], { type }));
    a.download = name;
    document.body.appendChild(a);
    a.click();
    setTimeout(() => {
      URL.revokeObjectURL(a.href);
      a.remove();
    }, 0);
  }

  const round = (v, d) => (Number.isFinite(v) ? Number(v.toFixed(d)) : v);

  function csv(r) {
    const lines = ["# tetherplan deployment plan", `# verdict,${r.go ? "go" : "no-go"}`, `# reason,"${r.reason.replaceAll('"', "'")}"`];
    for (const [k, v] of flatten(r.inputs)) lines.push(`# input ${k},${v}`);
    lines.push(`# duration_s,${round(r.duration_s, 3)}`);
    const b = lastBands && lastBands.instants.length === r.schedule.length ? lastBands : null;
    if (b) {
      lines.push(`# uncertainty samples,${b.samples}`, `# uncertainty valid_samples,${b.valid_samples}`, `# uncertainty seed,${b.seed}`);
      for (const [k, v] of flatten({ inputs: b.inputs })) lines.push(`# uncertainty ${k},${v}`);
      for (const k of ["probability_unstable", "probability_below_reserve", "probability_over_rating"]) {
        if (b[k]) lines.push(`# ${k},${b[k].probability_nondim},${b[k].low_nondim},${b[k].high_nondim}`);
      }
    }
    lines.push("time_s,length_m,rate_m_s,acceleration_m_s2,winch_tension_n,max_tension_n,rate_ceiling_m_s,stability_margin_m_s,effective_tension_margin_n" +
      (b ? ",winch_tension_p05_n,winch_tension_p50_n,winch_tension_p95_n,max_tension_p05_n,max_tension_p95_n,stability_margin_p05_m_s,stability_margin_p50_m_s,stability_margin_p95_m_s" : ""));
    r.schedule.forEach((s, i) => {
      const row = [round(s.time_s, 3), round(s.length_m, 3), round(s.rate_m_s, 4), round(s.acceleration_m_s2, 4),
        round(s.winch_tension_n, 2), round(s.max_tension_n, 2), round(s.rate_ceiling_m_s, 4), round(s.stability_margin_m_s, 4),
        round(s.effective_tension_margin_n, 2)];
      if (b) {
        const x = b.instants[i];
        row.push(round(x.winch_tension_n.p05, 2), round(x.winch_tension_n.p50, 2), round(x.winch_tension_n.p95, 2),
          round(x.max_tension_n.p05, 2), round(x.max_tension_n.p95, 2),
          round(x.stability_margin_m_s.p05, 4), round(x.stability_margin_m_s.p50, 4), round(x.stability_margin_m_s.p95, 4));
      }
      lines.push(row.join(","));
    });
    return `${lines.join("\n")}\n`;
  }

  $("plan-csv").addEventListener("click", () => last && download("tetherplan-plan.csv", "text/csv", csv(last)));
  $("plan-json").addEventListener("click", () => last && download("tetherplan-plan.json", "application/json", JSON.stringify(lastBands ?? last, null, 2)));
  $("plan-print").addEventListener("click", () => window.print());
  $("plan-preset").addEventListener("change", (e) => {
    applyPreset(e.target.value);
    runPlan();
  });
  form.addEventListener("submit", (e) => {
    e.preventDefault();
    runPlan();
  });
  for (const el of inputs()) el.addEventListener("change", () => ($("plan-preset").value = "custom"));

  let resizeTimer = null;
  window.addEventListener("resize", () => {
    clearTimeout(resizeTimer);
    resizeTimer = setTimeout(() => last && last.schedule.length && drawPlots(last), 150);
  });
  // Print at the page width of A4 portrait.
  window.addEventListener("beforeprint", () => {
    if (!last || !last.schedule.length) return;
    for (const p of Object.values(plots)) p.setSize({ width: 330, height: 170 });
  });
  window.addEventListener("afterprint", () => last && last.schedule.length && drawPlots(last));

  // The page opens on the plan: from the URL if it carries one, else the defaults.
  readUrl();
  runPlan();
})();
