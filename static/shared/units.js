// The page's units (issue 32): speeds in m/s, knots or km/h and lengths in
// metres or feet, chosen once in the header (#units: selects named `speed`
// and `length`) and kept in the URL (`?speed=kn&length=ft`, by form.js's
// writeUrl like every other input) so a shared link opens in the same units.
// The API stays SI: panels convert what they show with S.speedText,
// S.lengthText (or S.toSpeed, S.toLength) and redraw on the document's
// `tetherplan:units` event. 1 kn = 1852/3600 m/s, 1 ft = 0.3048 m, exactly.
"use strict";

import shared from "./core.js";

(function (shared) {
  // SI value ÷ factor = the value in the unit.
  const SPEED = { "m/s": 1, kn: 1852 / 3600, "km/h": 1 / 3.6 };
  const LENGTH = { m: 1, ft: 0.3048 };
  const units = { speed: "m/s", length: "m" };

  const pick = (table, v) => (v != null && Object.hasOwn(table, v) ? v : null);
  // The query's units (the older `units_speed`/`units_length` of the windows panel too).
  const params = new URLSearchParams(window.location.search);
  units.speed = pick(SPEED, params.get("speed")) ?? pick(SPEED, params.get("units_speed")) ?? "m/s";
  units.length = pick(LENGTH, params.get("length")) ?? pick(LENGTH, params.get("units_length")) ?? "m";

  const toSpeed = (v) => (v == null || !Number.isFinite(v) ? null : v / SPEED[units.speed]);
  const toLength = (v) => (v == null || !Number.isFinite(v) ? null : v / LENGTH[units.length]);
  const text = (v, digits, unit) => (v == null ? "–" : `${v.toFixed(digits)} ${unit}`);
  const speedText = (v, digits = 1) => text(toSpeed(v), digits, units.speed);
  const lengthText = (v, digits = 0) => text(toLength(v), digits, units.length);
  // A winch rate: the length unit per second.
  const rateText = (v, digits = 2) => text(toLength(v), digits, `${units.length}/s`);

  function bind() {
    const box = document.getElementById("units");
    if (!box) return;
    for (const name of ["speed", "length"]) {
      const select = box.querySelector(`[name="${name}"]`);
      if (!select) continue;
      select.value = units[name];
      select.addEventListener("change", () => {
        const table = name === "speed" ? SPEED : LENGTH;
        const v = pick(table, select.value);
        if (!v || v === units[name]) return;
        units[name] = v;
        if (!shared.restoring) shared.writeUrl?.();
        document.dispatchEvent(new CustomEvent("tetherplan:units", { detail: { ...units } }));
      });
    }
  }
  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", bind);
  else bind();

  Object.assign(shared, { units, SPEED_UNITS: SPEED, LENGTH_UNITS: LENGTH, toSpeed, toLength, speedText, lengthText, rateText });
})(shared);
