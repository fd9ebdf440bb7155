// The system card's reader (with the plan form's wind and starting length),
// generic over what a panel declares it needs. A panel lists the request
// paths it reads from the card (its declaration); `readSystem(errors, needs)`
// reads exactly those, in the card's order, into the nested request object:
//
//   const CARD = S.declareCard("bands", ["cable.preset", "cable.mass_per_length_kg_m", …, "gravity_m_s2"]);
//   const sys = S.readSystem(errors, CARD);   // { cable: {…}, gravity_m_s2: 9.81 }
//
// A path may end in " if preset": read only once its group's preset is
// chosen, and then optional (the calm-air analyses send a diameter only to
// pick a preset's row). Whether a field may be left blank is the card's: see
// FIELDS. The reader knows no panel.
"use strict";

import shared from "./core.js";

(function (shared) {
  const card = () => document.getElementById("system-card");
  const roots = () => [card(), document.getElementById("plan-form")];

  // Every path the card and the plan form hold, in request order, with how it
  // is read: "preset" (a select; blank: none), "required", "optional" (blank:
  // left out), "unless preset" (optional once the group's preset is chosen),
  // or a reader of its own (a group of inputs; null: left out).
  const FIELDS = [
    ["cable.preset", "preset"],
    ["cable.diameter_m", "required"],
    ["cable.mass_per_length_kg_m", "unless preset"],
    ["cable.breaking_strength_n", "optional"],
    ["cable.normal_drag_coefficient_nondim", "optional"],
    ["cable.axial_stiffness_n", "optional"],
    ["aerostat.preset", "preset"],
    ["aerostat.net_buoyancy_n", "unless preset"],
    ["aerostat.mass_kg", "unless preset"],
    ["aerostat.drag_coefficient_nondim", "unless preset"],
    ["aerostat.reference_area_m2", "unless preset"],
    ["aerostat.lift_coefficient_nondim", "unless preset"],
    ["gravity_m_s2", "required"],
    ["required_safety_factor_nondim", "required"],
    ["wind.air_density_kg_m3", "required"],
    ["wind.flow", readFlow],
    ["wind.gust", readGust],
    ["winch.max_rate_m_s", "required"],
    ["winch.max_acceleration_m_s2", "required"],
    ["winch.max_jerk_m_s3", "optional"],
    ["lift_reserve_nondim", "required"],
    ["initial_length_m", "required"],
  ];
  const PATHS = new Set(FIELDS.map(([path]) => path));

  // The declarations made so far (panel → paths), for the browser test and the console.
  const declared = {};

  // A panel's declaration, checked against the card: every path must be one
  // the card holds (an unknown one is a programming error, thrown at load).
  function declareCard(panel, needs) {
    for (const entry of needs) {
      const path = entry.replace(/ if preset$/, "");
      if (!PATHS.has(path)) throw new Error(`${panel}: the system card has no ${path}`);
    }
    declared[panel] = Object.freeze([...needs]);
    return declared[panel];
  }

  // The value of `path` in `obj` set, creating its groups; undefined leaves it out.
  function put(obj, path, value) {
    const keys = path.split(".");
    let at = obj;
    for (const k of keys.slice(0, -1)) at = at[k] ??= {};
    if (value !== undefined) at[keys[keys.length - 1]] = value;
  }

  // The card's values for the paths `needs` lists; errors collect {field, message}.
  function readSystem(errors, needs) {
    const r = roots();
    const wanted = new Map(needs.map((entry) => [entry.replace(/ if preset$/, ""), entry.endsWith(" if preset")]));
    const presetOf = (path) => (path.includes(".") ? shared.named(r, `${path.split(".")[0]}.preset`)?.value || "" : "");
    const sys = {};
    for (const [path, how] of FIELDS) {
      if (!wanted.has(path)) continue;
      const preset = presetOf(path);
      if (wanted.get(path) && !preset) {
        put(sys, path, undefined);
        continue;
      }
      let value;
      if (typeof how === "function") value = how(r, errors) ?? undefined;
      else if (how === "preset") value = shared.named(r, path)?.value || undefined;
      else {
        const optional = wanted.get(path) || how === "optional" || (how === "unless preset" && !!preset);
        value = shared.readNumber(r, path, errors, { optional });
      }
      put(sys, path, value);
    }
    return sys;
  }

  // Today's wind: uniform, or a log law through the speed at the reference height.
  function readFlow(roots, errors) {
    const n = (name, opts) => shared.readNumber(roots, name, errors, opts);
    const kind = shared.named(roots, "wind.flow.kind")?.value || "uniform";
    if (kind === "power_law") {
      return { kind, coefficient_m_s: n("wind.flow.speed_m_s"), exponent_nondim: n("wind.flow.exponent_nondim"),
        reference_height_m: n("wind.flow.power_reference_height_m") };
    }
    const flow = { kind, speed_m_s: n("wind.flow.speed_m_s") };
    if (kind === "log_law") {
      flow.reference_height_m = n("wind.flow.reference_height_m");
      flow.roughness_length_m = n("wind.flow.roughness_length_m");
    }
    return flow;
  }

  // The gusts (SPEC §10): a turbulence intensity (with its peak factor) or a
  // gust speed; both blank: none. Both given go to the API, which says which to drop.
  function readGust(roots, errors) {
    const n = (name) => shared.readNumber(roots, name, errors, { optional: true, fallback: undefined });
    const intensity = n("wind.gust.turbulence_intensity_nondim");
    const speed = n("wind.gust.gust_m_s");
    if (intensity == null && speed == null) return null;
    const peak = intensity == null ? undefined : n("wind.gust.peak_factor_nondim");
    return shared.compact({ turbulence_intensity_nondim: intensity ?? undefined, peak_factor_nondim: peak ?? undefined, gust_m_s: speed ?? undefined });
  }

  Object.assign(shared, { readSystem, declareCard, cardDeclarations: declared });
})(shared);
