// The verdict, the system card and today's plan (SPEC §7, §9): the first
// screen of the page. Reads the card and the plan form (inputs named by their
// request path, kept in the URL: a shared link plans at once), posts
// /api/v1/plan in today's wind, and shows the verdict card (#verdict,
// data-state go | no-go | stale | pending | error; aria-live), the tether
// length the altitude needs, the blow-down angle, the peak tension and the
// safety factor (with gusts the gust's beside each, and the altitude in the
// gust), the haul-down deadline (the wind's or the gust's limit, whichever
// is passed first), the operator's table and the plots.
// Any input event clears the verdict to "inputs changed: plan again" and
// disables Print and the downloads until a plan is current again.
"use strict";

import S from "./shared/index.js";

(function () {
  // What this panel reads from the system card (shared/system.js): all of it,
  // the system, today's wind, the winch, the reserve and the start.
  const CARD = S.declareCard("plan", [
    "cable.preset", "cable.diameter_m", "cable.mass_per_length_kg_m", "cable.breaking_strength_n",
    "cable.normal_drag_coefficient_nondim", "cable.axial_stiffness_n",
    "aerostat.preset", "aerostat.net_buoyancy_n", "aerostat.mass_kg",
    "aerostat.drag_coefficient_nondim", "aerostat.reference_area_m2", "aerostat.lift_coefficient_nondim",
    "gravity_m_s2", "required_safety_factor_nondim",
    "wind.air_density_kg_m3", "wind.flow", "wind.gust",
    "winch.max_rate_m_s", "winch.max_acceleration_m_s2", "winch.max_jerk_m_s3",
    "lift_reserve_nondim", "initial_length_m",
  ]);
  const form = document.getElementById("plan-form");
  if (!form) return;
  const $ = (id) => document.getElementById(id);
  const verdict = $("verdict");
  const errorBox = $("plan-error");
  const SOURCE = "plan";
  const roots = [form];
  // The server's version (GET /healthz), printed and exported with the plan.
  let version = "unknown";

  const state = { request: null, plan: null, bands: null, plots: {}, seq: 0, current: false };
  window.tetherplanPlan = state;

  // ---------- the card's behaviour ----------

  // A material preset fills what is left blank from the diameter.
  function togglePreset() {
    const preset = form.elements["cable.preset"].value;
    const mass = form.elements["cable.mass_per_length_kg_m"];
    const breaking = form.elements["cable.breaking_strength_n"];
    mass.placeholder = preset ? "blank: from the material" : "";
    breaking.placeholder = preset ? "blank: from the material" : "blank: not checked";
  }
  form.elements["cable.preset"].addEventListener("change", (ev) => {
    // A chosen material: its mass and strength unless typed over.
    if (!S.restoring && ev.target.value) {
      form.elements["cable.mass_per_length_kg_m"].value = "";
      form.elements["cable.breaking_strength_n"].value = "";
    }
    togglePreset();
  });
  // A named aerostat: its lift, mass and aerodynamics unless typed over.
  const AEROSTAT = ["aerostat.net_buoyancy_n", "aerostat.mass_kg", "aerostat.drag_coefficient_nondim", "aerostat.reference_area_m2", "aerostat.lift_coefficient_nondim"];
  function toggleAerostat() {
    const preset = form.elements["aerostat.preset"].value;
    for (const name of AEROSTAT) form.elements[name].placeholder = preset ? "blank: from the aerostat" : "";
  }
  form.elements["aerostat.preset"].addEventListener("change", (ev) => {
    if (!S.restoring && ev.target.value) for (const name of AEROSTAT) form.elements[name].value = "";
    toggleAerostat();
  });
  function toggleWind() {
    const kind = form.elements["wind.flow.kind"].value;
    for (const el of form.querySelectorAll("[data-wind-kind]")) el.hidden = el.dataset.windKind !== kind;
  }
  form.elements["wind.flow.kind"].addEventListener("change", toggleWind);

  // Uncertainty bands of the plan (issue 14), folded away: /api/v1/plan/bands
  // shades the 5–95 % band of the tension and the margin.
  const bandsBox = document.createElement("details");
  bandsBox.id = "plan-bands";
  bandsBox.className = "more";
  bandsBox.innerHTML = `<summary>Uncertainty: 5–95 % bands of the tension and margin (optional)</summary>
    <fieldset>
    <div class="field"><label for="plan-bands-on"><input type="checkbox" id="plan-bands-on"> Shade the 5–95 % band</label></div>
    <div class="field"><label for="plan-bands-lift-sd">Spread of the lift (N)</label><input id="plan-bands-lift-sd" inputmode="decimal" value="50"></div>
    <div class="field"><label for="plan-bands-rhoa-sd">Spread of the mass per length (kg/m)</label><input id="plan-bands-rhoa-sd" inputmode="decimal" value="0.002"></div>
    <div class="field"><label for="plan-bands-samples">Samples</label><input id="plan-bands-samples" inputmode="numeric" value="500"></div>
    <div class="field"><label for="plan-bands-seed">Seed</label><input id="plan-bands-seed" inputmode="numeric" value="1"></div>
    </fieldset>
    <p id="plan-bands-summary" class="note" hidden></p>`;
  form.querySelector(".plan-inputs").append(bandsBox);
  const bandsOn = () => $("plan-bands-on").checked;

  function uncertainty(body) {
    const inputs = [];
    const liftSd = Number($("plan-bands-lift-sd").value);
    const rhoSd = Number($("plan-bands-rhoa-sd").value);
    if (liftSd > 0 && body.aerostat.net_buoyancy_n != null) inputs.push({ field: "aerostat.net_buoyancy_n", distribution: "normal", mean: body.aerostat.net_buoyancy_n, std_dev: liftSd });
    if (rhoSd > 0 && body.cable.mass_per_length_kg_m != null) {
      inputs.push({ field: "cable.mass_per_length_kg_m", distribution: "normal", mean: body.cable.mass_per_length_kg_m, std_dev: rhoSd });
    }
    return { samples: Number($("plan-bands-samples").value), seed: Number($("plan-bands-seed").value), inputs };
  }

  // ---------- the request ----------

  // "0:5, 60:14:20" (minutes from now : m/s [: gust m/s]) → [{time_s, wind_speed_m_s, gust_m_s?}, …].
  function parseForecast(text, errors) {
    const out = [];
    text.split(",").map((s) => s.trim()).filter(Boolean).forEach((pair, i) => {
      const parts = pair.split(":").map((x) => Number(x.trim()));
      const [t, u, g] = parts;
      if (!(parts.length === 2 || parts.length === 3) || !parts.every(Number.isFinite)) {
        errors.push({ field: `haul_down.forecast[${i}]`, message: `write minutes:m/s or minutes:m/s:gust, like 60:9 or 60:9:14 (not “${pair}”)` });
        return;
      }
      out.push(parts.length === 3 ? { time_s: 60 * t, wind_speed_m_s: u, gust_m_s: g } : { time_s: 60 * t, wind_speed_m_s: u });
    });
    return out;
  }

  function readRequest(errors) {
    const body = S.readSystem(errors, CARD);
    body.target_elevation_m = S.readNumber(roots, "target_elevation_m", errors);
    const floor = S.readNumber(roots, "min_altitude_m", errors, { optional: true, fallback: undefined });
    if (floor != null) body.min_altitude_m = floor;
    body.samples = 61;
    const forecast = form.elements["haul_down.forecast"].value.trim();
    if (forecast) {
      body.haul_down = S.compact({
        forecast: parseForecast(forecast, errors),
        max_operating_wind_m_s: S.readNumber(roots, "haul_down.max_operating_wind_m_s", errors),
        max_gust_m_s: S.readNumber(roots, "haul_down.max_gust_m_s", errors, { optional: true, fallback: undefined }) ?? undefined,
      });
    }
    return body;
  }

  // ---------- formatting ----------

  const fmt = S.fixed;
  const lv = S.legendValue;
  function duration(s) {
    if (s == null || !Number.isFinite(s)) return "–";
    if (s < 90) return `${s.toFixed(0)} s`;
    const m = Math.floor(s / 60);
    return m < 90 ? `${m} min ${Math.round(s - 60 * m)} s` : `${Math.floor(m / 60)} h ${m % 60} min`;
  }
  const clock = (s) => new Date(Date.now() + 1000 * s).toLocaleTimeString([], { hour: "2-digit", minute: "2-digit" });

  // ---------- the verdict card ----------

  function setVerdict(kind, word, why) {
    verdict.dataset.state = kind;
    verdict.querySelector(".word").textContent = word;
    verdict.querySelector(".why").textContent = why;
    const current = kind === "go" || kind === "no-go";
    state.current = current;
    if (!current) {
      for (const sel of [".tension-check", ".deadline", ".key-figures"]) verdict.querySelector(sel).hidden = true;
      $("plan-output").hidden = true;
    }
    $("plan-print").disabled = !current;
    $("plan-json").disabled = !current;
    $("plan-csv").disabled = !current || !(state.plan?.schedule?.length > 0);
  }

  // One plain line: why GO or NO-GO, naming what decides it. Jargon stays in the details.
  // The verdict, its tension and deadline lines and key figures, in the page's units.
  function showVerdict(r, req) {
    setVerdict(r.go ? "go" : "no-go", r.go ? "GO" : "NO-GO", headline(r, req));
    tensionLine(r, req);
    deadlineLine(r, req);
    keyFigures(r, req);
  }
  document.addEventListener("tetherplan:units", () => state.current && state.plan && state.request && showVerdict(state.plan, state.request));

  // With a turbulent gust the tensions are judged at their dynamic value
  // (docs/gust_check.md): say so wherever the gust's tension is shown.
  function dynamicNote(w) {
    const k = w?.gust?.dynamic_tension_factor_nondim;
    return k != null && k !== 1 ? ` (turbulence: the static tension's rise over calm air × ${fmt(k, 2)})` : "";
  }

  function headline(r, req) {
    const H = req.target_elevation_m;
    const U = req.wind?.flow?.speed_m_s;
    const w = r.wind;
    if (r.go) {
      const L = w?.target_length_m;
      const angle = w?.blowdown_angle_deg;
      const blown = angle != null && angle > 0.05 ? `, blown ${fmt(angle, 1)}° off vertical by the ${S.speedText(U, 1)} wind` : "";
      return `${r.direction === "retrieval" ? "Haul down" : "Deploy"} to ${S.lengthText(H, 0)}: pay out ${S.lengthText(L ?? H, 0)} of tether${blown}; ${duration(r.duration_s)} at the winch.`;
    }
    switch (r.binding_limit) {
      case "wind_blowdown":
        return `The ${S.speedText(U, 1)} wind blows the aerostat down: it reaches at most ${S.lengthText(w?.reachable_altitude_m, 0)}, short of ${S.lengthText(H, 0)}.`;
      case "static_lift_limit":
        return `Not enough lift: ${S.lengthText(H, 0)} is above the highest altitude the lift holds with its reserve (${S.lengthText(r.limits?.lift_limit_m, 0)}).`;
      case "tension_limit":
        return "The tether would be overloaded: its tension exceeds the breaking strength divided by the safety factor.";
      case "gust_tension_limit":
        return `The gust of ${S.speedText(w?.gust?.reference_speed_m_s, 1)} would overload the tether: ${fmt(r.limits?.gust_peak_tension_n, 0)} N in the gust, above the breaking strength divided by the safety factor (${fmt(r.limits?.allowable_tension_n, 0)} N)${dynamicNote(w)}.`;
      case "min_altitude":
        return `${w?.gust ? `The gust of ${S.speedText(w.gust.reference_speed_m_s, 1)} blows` : "The wind blows"} the aerostat down to ${S.lengthText(w?.gust?.target_altitude_m ?? req.target_elevation_m, 0)}, below the lowest altitude allowed (${S.lengthText(req.min_altitude_m, 0)}).`;
      case "amplification_limit":
        return "Hauling in lets a swing of the tether grow beyond the limit, even at the slowest rate.";
      case "jerk_limit":
        return "No winch schedule within the jerk limit keeps every margin.";
      case "quasi_static_ge_limit":
      case "quasi_static_ge_check":
        return "The stiff-tether check finds the tether unstable on the way up.";
      default:
        break;
    }
    if (r.feasible && r.haul_down && !r.haul_down.go) {
      return `The forecast wind passes ${S.speedText(req.haul_down.max_operating_wind_m_s, 1)} before the aerostat could be brought down.`;
    }
    return String(r.reason || "").replace(/^no-go:\s*/, "");
  }

  function tensionLine(r, req) {
    const el = verdict.querySelector(".tension-check");
    const checked = r.tension_checked ?? r.limits?.min_safety_factor_nondim != null;
    el.hidden = false;
    el.dataset.checked = String(!!checked);
    if (!checked) {
      el.textContent = "Tension NOT checked: no breaking strength entered.";
      return;
    }
    const sf = r.limits.min_safety_factor_nondim;
    const gsf = r.limits.gust_min_safety_factor_nondim;
    const gust = r.limits.gust_peak_tension_n == null ? "" : `; in the gust peak ${fmt(r.limits.gust_peak_tension_n, 0)} N, safety factor ${gsf == null ? "–" : fmt(gsf, 1)}`;
    el.textContent = `Tension checked: peak ${fmt(r.limits.peak_tension_n, 0)} N, safety factor ${sf == null ? "–" : fmt(sf, 1)}${gust} (required ${fmt(req.required_safety_factor_nondim, 1)}).`;
  }

  function deadlineLine(r, req) {
    const el = verdict.querySelector(".deadline");
    el.hidden = false;
    const h = r.haul_down;
    if (!req.haul_down) {
      el.textContent = "Haul-down deadline: none set (no forecast entered).";
    } else if (!h) {
      el.textContent = "Haul-down deadline: not worked out (no schedule).";
    } else if (h.wind_exceeds_limit_at_s == null) {
      el.textContent = `Haul-down deadline: none — the forecast stays below ${S.speedText(req.haul_down.max_operating_wind_m_s, 1)}.`;
    } else if (h.latest_start_s != null && h.latest_start_s >= 0) {
      const what = h.exceeded_by === "gust" ? `the gust passes ${S.speedText(req.haul_down.max_gust_m_s, 1)}` : `the wind passes ${S.speedText(req.haul_down.max_operating_wind_m_s, 1)}`;
      el.textContent = `Haul-down deadline: start hauling down by ${clock(h.latest_start_s)} (in ${duration(h.latest_start_s)}); ${what} at ${clock(h.wind_exceeds_limit_at_s)}.`;
    } else {
      el.textContent = `Haul-down deadline: already passed — ${h.reason}`;
    }
  }

  // The key figures; with gusts each figure of the mean wind has the gust's
  // beside it (a `.gust-figure` span), and the altitude in the gust its own row.
  function keyFigures(r, req) {
    const dl = verdict.querySelector(".key-figures");
    const w = r.wind;
    const g = w?.gust;
    const lim = r.limits ?? {};
    const sf = lim.min_safety_factor_nondim;
    const deg = (x) => (x == null ? "–" : `${fmt(x, 1)}°`);
    const rows = [
      ["Tether needed", w ? (w.target_length_m == null ? `out of reach (at most ${S.lengthText(w.reachable_altitude_m, 0)} up)` : `${S.lengthText(w.target_length_m, 1)}`) : `${S.lengthText(req.target_elevation_m, 1)}`],
      ["Altitude in the gust", g ? (g.target_altitude_m == null ? "–" : `${S.lengthText(g.target_altitude_m, 0)}`) : null],
      ["Blow-down angle", w?.blowdown_angle_deg == null ? "–" : deg(w.blowdown_angle_deg), g && deg(g.blowdown_angle_deg)],
      ["Downwind of the winch", w?.target_downwind_m == null ? null : `${S.lengthText(w.target_downwind_m, 0)}`, g?.target_downwind_m == null ? null : `${S.lengthText(g.target_downwind_m, 0)}`],
      ["Peak tension", lim.peak_tension_n == null ? "–" : `${fmt(lim.peak_tension_n, 0)} N`, g && lim.gust_peak_tension_n != null ? `${fmt(lim.gust_peak_tension_n, 0)} N` : null],
      ["Safety factor", sf == null ? "not checked" : fmt(sf, 1), g && lim.gust_min_safety_factor_nondim != null ? fmt(lim.gust_min_safety_factor_nondim, 1) : null],
      ["Time at the winch", duration(r.duration_s)],
    ];
    dl.replaceChildren(...rows.filter(([, v]) => v != null).map(([k, v, gust]) => {
      const div = document.createElement("div");
      const dt = document.createElement("dt");
      dt.textContent = k;
      const dd = document.createElement("dd");
      dd.textContent = v;
      dd.dataset.figure = k;
      if (gust != null) {
        const span = document.createElement("span");
        span.className = "gust-figure";
        span.dataset.gust = gust;
        span.textContent = ` · gust ${gust}`;
        dd.append(span);
      }
      div.append(dt, dd);
      return div;
    }));
    if (g) dl.dataset.gust = `${S.speedText(g.reference_speed_m_s, 1)}`;
    else delete dl.dataset.gust;
    dl.hidden = false;
  }

  // ---------- plots and tables ----------

  function plot(el, yLabel, series, data, bands) {
    return S.makePlot(el, {
      series: [{ label: "t (s)", value: lv(1) }, ...series],
      data,
      xLabel: "Time t (s)",
      yLabel,
      size: S.plotSize(el, { aspect: 0.55, min: 180, max: 260, minWidth: 240 }),
      bands,
    });
  }

  function drawPlots(r) {
    const s = r.schedule;
    const t = s.map((x) => x.time_s);
    const col = (k) => s.map((x) => x[k]);
    const p = state.plots;
    p.length = plot($("plan-plot-length"), "Length L (m)", [{ label: "tether L (m)", stroke: "#0b5cad", width: 2, value: lv(1) }], [t, col("length_m")]);
    p.rate = plot($("plan-plot-rate"), "Rate (m/s)", [
      { label: "winch |L̇| (m/s)", stroke: "#0b5cad", width: 2, value: lv(2) },
      { label: "stability ceiling (m/s)", stroke: "#b00020", width: 1.5, dash: [6, 4], value: lv(2) },
    ], [t, s.map((x) => Math.abs(x.rate_m_s)), col("rate_ceiling_m_s")]);
    const tension = [{ label: "winch (N)", stroke: "#0b5cad", width: 2, value: lv(1) }, { label: "peak, at the aerostat (N)", stroke: "#7a4a00", width: 1.5, value: lv(1) }];
    const tdata = [t, col("winch_tension_n"), col("max_tension_n")];
    if (s.length && s[0].gust_max_tension_n != null) {
      tension.push({ label: "peak in the gust (N)", stroke: "#8a2be2", width: 1.5, dash: [2, 3], value: lv(1) });
      tdata.push(col("gust_max_tension_n"));
    }
    if (r.limits.allowable_tension_n) {
      tension.push({ label: "allowable (N)", stroke: "#b00020", width: 1.5, dash: [6, 4], value: lv(1) });
      tdata.push(s.map(() => r.limits.allowable_tension_n));
    }
    const b = state.bands && state.bands.instants.length === s.length ? state.bands.instants : null;
    const shade = (series, data, key, color, d) => {
      if (!b) return null;
      const hi = series.length + 1;
      series.push({ label: "95 %", stroke: color, width: 0.5, value: lv(d) }, { label: "5 %", stroke: color, width: 0.5, value: lv(d) });
      data.push(b.map((x) => x[key].p95), b.map((x) => x[key].p05));
      return [{ series: [hi, hi + 1], fill: "rgba(11,92,173,0.15)" }];
    };
    const tBands = shade(tension, tdata, "winch_tension_n", "#6b9bd1", 1);
    p.tension = plot($("plan-plot-tension"), "Tension (N)", tension, tdata, tBands);
    const mseries = [{ label: "stability margin (m/s)", stroke: "#1a7f37", width: 2, value: lv(2) }];
    const mdata = [t, col("stability_margin_m_s")];
    const mBands = shade(mseries, mdata, "stability_margin_m_s", "#6fbf86", 2);
    p.margin = plot($("plan-plot-margin"), "Margin (m/s)", mseries, mdata, mBands);
  }

  function row(body, cells) {
    const tr = document.createElement("tr");
    for (const [text, cls] of cells) {
      const td = document.createElement("td");
      td.textContent = text;
      if (cls) td.className = cls;
      tr.append(td);
    }
    body.append(tr);
  }

  function fillTables(r) {
    const phases = $("plan-phases").querySelector("tbody");
    phases.textContent = "";
    r.phases.forEach((p, i) => row(phases, [
      [String(i + 1)],
      [p.instruction, "what"],
      [`${fmt(p.start_time_s, 1)} – ${fmt(p.end_time_s, 1)}`, "num"],
      [`${fmt(p.start_length_m, 1)} → ${fmt(p.end_length_m, 1)}`, "num"],
      [`${fmt(Math.abs(p.start_rate_m_s), 2)} → ${fmt(Math.abs(p.end_rate_m_s), 2)}`, "num"],
      [fmt(p.mean_acceleration_m_s2, 3), "num"],
    ]));
    const all = $("plan-table").querySelector("tbody");
    all.textContent = "";
    for (const s of r.schedule) {
      row(all, [[fmt(s.time_s, 1), "num"], [fmt(s.length_m, 1), "num"], [fmt(s.altitude_m, 1), "num"], [fmt(Math.abs(s.rate_m_s), 2), "num"],
        [fmt(s.acceleration_m_s2, 3), "num"], [fmt(s.winch_tension_n, 0), "num"], [fmt(s.stability_margin_m_s, 2), "num"]]);
    }
  }

  // A table wider than its box says so (phones): the hint above it shows.
  function scrollHints() {
    for (const wrap of document.querySelectorAll("#plan .table-wrap")) {
      const hint = wrap.previousElementSibling;
      const scrolls = wrap.scrollWidth > wrap.clientWidth + 1;
      wrap.classList.toggle("scrolls", scrolls);
      if (hint?.classList.contains("scroll-hint")) hint.hidden = !scrolls;
    }
  }

  function figures(r) {
    const c = r.constant_rate;
    const tc = r.transient_check;
    const rows = [
      ["What the planner says", r.reason],
      ["Direction", r.direction],
      ["Binding limit", r.binding_limit],
      ["Fastest constant rate", c ? `${fmt(c.rate_m_s, 2)} m/s, ${fmt(c.duration_s, 1)} s (the plan saves ${fmt(c.time_saved_s, 1)} s)` : null],
      ["Minimum-time bound", r.bound ? `${fmt(r.bound.duration_s, 1)} s: ${r.bound.explanation}` : null],
      ["Lift limit with the reserve (calm air)", r.limits ? `${fmt(r.limits.lift_limit_m, 1)} m` : null],
      ["Reachable altitude in this wind", r.wind ? `${fmt(r.wind.reachable_altitude_m, 1)} m` : null],
      ["Gust", r.wind?.gust ? `${fmt(r.wind.gust.reference_speed_m_s, 1)} m/s at ${fmt(r.wind.gust.reference_height_m, 0)} m (${fmt(r.wind.gust.gust_factor_nondim, 2)} × the mean); reachable altitude in the gust ${fmt(r.wind.gust.reachable_altitude_m, 1)} m${dynamicNote(r.wind)}` : null],
      ["Stability criterion", r.wind?.stability_criterion ?? null],
      ["Smallest stability margin", r.limits?.min_stability_margin_m_s == null ? null : `${fmt(r.limits.min_stability_margin_m_s, 2)} m/s`],
      ["Allowable tension", r.limits?.allowable_tension_n ? `${fmt(r.limits.allowable_tension_n, 0)} N` : null],
      ["Transient check", tc ? `${tc.outcome}; peak tip ${fmt(tc.peak_tip_deflection_m, 3)} m from ${fmt(tc.initial_tip_deflection_m, 3)} m` : null],
      ["Haul-down", r.haul_down?.reason ?? null],
      ["Method", r.method],
    ];
    $("plan-figures").replaceChildren(...rows.filter(([, v]) => v != null).flatMap(([k, v]) => {
      const dt = document.createElement("dt");
      dt.textContent = k;
      const dd = document.createElement("dd");
      dd.textContent = v;
      return [dt, dd];
    }));
  }

  // The inputs as the operator typed them, with their labels and units (print, CSV).
  function inputRows() {
    const out = [];
    for (const el of form.querySelectorAll("[name]")) {
      if (!S.visible(el) && !el.closest("details")) continue;
      if (el.closest("[hidden]")) continue;
      const label = S.labelOf(el) ?? el.name;
      let value = el.tagName === "SELECT" ? el.selectedOptions[0]?.textContent ?? el.value : el.value.trim();
      if (value === "") value = el.placeholder.startsWith("blank: ") ? el.placeholder.slice(7) : el.placeholder && !el.placeholder.startsWith("e.g.") ? el.placeholder : "none";
      else if (el.dataset.unit) value = `${value} ${el.dataset.unit}`;
      out.push([label, value, el.name]);
    }
    return out;
  }

  function fillInputs() {
    const body = $("plan-inputs").querySelector("tbody");
    body.textContent = "";
    for (const [label, value] of inputRows()) row(body, [[label], [value, "num"]]);
  }

  // ---------- planning ----------

  function stale() {
    if (verdict.dataset.state === "stale") return;
    state.seq++;
    setVerdict("stale", "Inputs changed:", "plan again.");
  }

  async function runPlan() {
    const seq = ++state.seq;
    S.clearErrors(SOURCE);
    S.showFormError(errorBox, "");
    S.writeUrl();
    const errors = [];
    const body = readRequest(errors);
    if (errors.length) {
      S.showInputErrors(roots, errors, SOURCE);
      const first = S.inputFor(roots, errors[0].field);
      setVerdict("error", "Cannot plan:", `${S.labelOf(first) ?? "an input"}: ${S.plainMessage(errors[0].field, errors[0].message)}.`);
      return;
    }
    setVerdict("pending", "Planning…", "");
    const withBands = bandsOn();
    if (withBands) body.uncertainty = uncertainty(body);
    state.request = body;
    const res = await S.api("POST", withBands ? "api/v1/plan/bands" : "api/v1/plan", body);
    if (seq !== state.seq) return; // an input changed meanwhile: that answer is not today's
    if (!res.ok) {
      state.plan = null;
      const text = S.renderApiError(roots, res.status, res.body, errorBox, SOURCE);
      setVerdict("error", "Cannot plan:", `${text.replace(/\.$/, "")}.`);
      return;
    }
    state.bands = withBands ? res.body : null;
    const r = withBands ? res.body.plan : res.body;
    state.plan = r;
    const summary = $("plan-bands-summary");
    summary.hidden = !state.bands?.probability_unstable;
    if (!summary.hidden) {
      const b = state.bands;
      const pc = (p) => (p ? `${fmt(100 * p.probability_nondim, 1)} % (95 %: ${fmt(100 * p.low_nondim, 1)}–${fmt(100 * p.high_nondim, 1)} %)` : "–");
      summary.textContent = `${b.valid_samples} samples: P(unstable somewhere) ${pc(b.probability_unstable)}; ` +
        `P(below the lift reserve) ${pc(b.probability_below_reserve)}; P(over the rating) ${pc(b.probability_over_rating)}.`;
    }
    showVerdict(r, body);
    figures(r);
    fillInputs();
    const has = r.schedule.length > 0;
    $("plan-output").hidden = false;
    for (const el of $("plan-output").querySelectorAll(".plan-plots, #plan-details, #plan-phases, h3")) el.hidden = !has;
    if (has) {
      fillTables(r);
      drawPlots(r);
    }
    scrollHints();
  }

  // ---------- export ----------

  function csv(r) {
    const v = verdict.dataset.state;
    const lines = ["# tetherplan deployment plan", `# planned,${new Date().toISOString()}`, `# version,${version}`, `# verdict,${v}`,
      `# why,"${verdict.querySelector(".why").textContent.replaceAll('"', "'")}"`,
      `# tension,"${verdict.querySelector(".tension-check").textContent.replaceAll('"', "'")}"`,
      `# haul-down,"${verdict.querySelector(".deadline").textContent.replaceAll('"', "'")}"`];
    lines.push(...S.inputLines(state.request));
    lines.push(`# duration_s,${S.sig(r.duration_s)}`);
    const b = state.bands && state.bands.instants.length === r.schedule.length ? state.bands : null;
    lines.push("time_s,length_m,altitude_m,rate_m_s,acceleration_m_s2,winch_tension_n,max_tension_n,rate_ceiling_m_s,stability_margin_m_s" +
      (b ? ",winch_tension_p05_n,winch_tension_p50_n,winch_tension_p95_n,stability_margin_p05_m_s,stability_margin_p95_m_s" : ""));
    r.schedule.forEach((s, i) => {
      const cells = [s.time_s, s.length_m, s.altitude_m, s.rate_m_s, s.acceleration_m_s2, s.winch_tension_n, s.max_tension_n, s.rate_ceiling_m_s, s.stability_margin_m_s];
      if (b) {
        const x = b.instants[i];
        cells.push(x.winch_tension_n.p05, x.winch_tension_n.p50, x.winch_tension_n.p95, x.stability_margin_m_s.p05, x.stability_margin_m_s.p95);
      }
      lines.push(cells.map(S.sig).join(","));
    });
    return `${lines.join("\n")}\n`;
  }

  $("plan-csv").addEventListener("click", () => state.current && state.plan && S.download(csv(state.plan), "tetherplan-plan.csv", "text/csv"));
  $("plan-json").addEventListener("click", () => state.current && state.plan &&
    S.download(JSON.stringify({ version, planned: new Date().toISOString(), request: state.request, answer: state.bands ?? state.plan }, null, 2), "tetherplan-plan.json", "application/json"));
  $("plan-print").addEventListener("click", () => state.current && window.print());

  form.addEventListener("submit", (e) => {
    e.preventDefault();
    runPlan();
  });
  // Any change clears the verdict at once; the card's changes also tell the other panels.
  const changed = (ev) => {
    if (!ev.target.matches("input, select, textarea")) return;
    S.clearFieldError(ev.target);
    stale();
    S.writeUrl();
    document.dispatchEvent(new CustomEvent("tetherplan:system-input", { detail: { name: ev.target.name } }));
  };
  form.addEventListener("input", changed);
  form.addEventListener("change", (ev) => !S.restoring && ev.target.tagName === "SELECT" && changed(ev));

  let resizeTimer = null;
  window.addEventListener("resize", () => {
    clearTimeout(resizeTimer);
    resizeTimer = setTimeout(() => {
      if (state.current && state.plan?.schedule.length) drawPlots(state.plan);
      scrollHints();
    }, 150);
  });
  // Print at the page width of A4 portrait, stamped with the date, time and version.
  window.addEventListener("beforeprint", () => {
    $("print-date").textContent = new Date().toLocaleString();
    $("print-version").textContent = version;
    fillInputs();
    if (!state.current || !state.plan?.schedule.length) return;
    for (const p of Object.values(state.plots)) p.setSize({ width: 330, height: 170 });
  });
  window.addEventListener("afterprint", () => state.current && state.plan?.schedule.length && drawPlots(state.plan));

  S.api("GET", "healthz").then((r) => {
    if (r.ok && r.body?.version) version = r.body.version;
    $("print-version").textContent = version;
  });
  $("print-date").textContent = new Date().toLocaleString();

  // The page opens planning: the shared URL's inputs if it carries any, else the defaults.
  S.readUrl();
  togglePreset();
  toggleAerostat();
  toggleWind();
  state.runPlan = runPlan;
  // Another panel that changes the plan's inputs (windows.js) asks for a plan with this event.
  document.addEventListener("tetherplan:plan-request", () => runPlan());
  runPlan();
})();
