// The operating-envelope panel (issue 12): reads its form, asks
// POST /api/v1/envelope (or an `envelope` job with progress when the grid is
// large, or when the server asks for one), and draws a heat map over wind
// speed × tether length of the chosen quantity (altitude, tensions, safety
// factor, blow-down), the feasible region outlined and each region named by
// its binding limit (tension, stability, slack, ceiling), the highest
// altitude per wind marked, tables of the largest operating wind per length
// and the highest altitude per wind, and CSV/PNG export with every input
// recorded. Self-contained: it uses shared/ alone.
"use strict";

import S from "./shared/index.js";

(function () {
  // What this panel reads from the system card (shared/system.js): the tether,
  // the aerostat with its aerodynamics, gravity, the safety factor and today's
  // wind, whose profile the envelope scales to each grid speed.
  const CARD = S.declareCard("envelope", [
    "cable.preset", "cable.diameter_m", "cable.mass_per_length_kg_m", "cable.breaking_strength_n",
    "cable.normal_drag_coefficient_nondim", "cable.axial_stiffness_n",
    "aerostat.preset", "aerostat.net_buoyancy_n", "aerostat.mass_kg",
    "aerostat.drag_coefficient_nondim", "aerostat.reference_area_m2", "aerostat.lift_coefficient_nondim",
    "gravity_m_s2", "required_safety_factor_nondim",
    "wind.air_density_kg_m3", "wind.flow", "wind.gust",
  ]);
  const form = document.getElementById("envelope-form");
  if (!form) return;
  const $ = (id) => document.getElementById(id);
  const SOURCE = "envelope";
  // The server answers at most this many points directly
  // (contract::envelope::MAX_SYNC_ENVELOPE_POINTS); more run as a job.
  const SYNC_POINTS = 5000;

  // Shared with the browser test and the console.
  const state = { request: null, result: null, via: null, jobProgress: [], job: null, regions: [], outline: [], layout: null };
  window.tetherplanEnvelope = state;

  // ---------- reading the form ----------

  // The envelope's own inputs first, then the system card's (errors land there).
  const roots = [form, document.getElementById("plan-form")];
  const num = (name, errors, opts) => S.readNumber(form, name, errors, opts);

  function readRequest(errors) {
    const sys = S.readSystem(errors, CARD);
    return S.compact({
      cable: sys.cable,
      aerostat: sys.aerostat,
      // Today's wind: its profile scaled to each grid speed (the speed at the reference height).
      wind: sys.wind,
      wind_speeds_m_s: {
        min: num("wind_speeds_m_s.min", errors),
        max: num("wind_speeds_m_s.max", errors),
        count: num("wind_speeds_m_s.count", errors, { integer: true }),
      },
      tether_lengths_m: {
        min: num("tether_lengths_m.min", errors),
        max: num("tether_lengths_m.max", errors),
        count: num("tether_lengths_m.count", errors, { integer: true }),
      },
      gravity_m_s2: sys.gravity_m_s2,
      required_safety_factor_nondim: sys.required_safety_factor_nondim,
      ceiling_m: num("ceiling_m", errors, { optional: true }),
      payout_rate_m_s: num("payout_rate_m_s", errors, { optional: true }),
    });
  }

  const points = (req) => (req.wind_speeds_m_s.count || 0) * (req.tether_lengths_m.count || 0);
  const wantsJob = (req) => points(req) > SYNC_POINTS;

  // ---------- status and jobs ----------

  const setStatus = S.statusSetter($("env-status"), $("env-results"));
  const runJob = S.jobRunner("env-", { log: state.jobProgress, slot: state });
  const fmt = S.sig3;
  const { ticks, colour } = S;

  // ---------- the heat map ----------

  const QUANTITIES = {
    altitude: { key: "aerostat_altitude_m", label: "Aerostat altitude (m)", unit: "m" },
    winch_tension: { key: "winch_tension_n", label: "Winch tension (N)", unit: "N" },
    top_tension: { key: "top_tension_n", label: "Top (confluence) tension (N)", unit: "N" },
    safety_factor: { key: "safety_factor_nondim", label: "Safety factor (–)", unit: "–" },
    blowdown: { key: "blowdown_angle_deg", label: "Blow-down angle (°)", unit: "°" },
    downwind: { key: "aerostat_downwind_m", label: "Downwind distance (m)", unit: "m" },
  };

  // What a region is called on the map (binding_limit, or feasible).
  const REGION_NAMES = {
    feasible: "feasible",
    tension: "tension limit",
    stability: "stability limit",
    slack: "slack tether",
    ceiling: "above ceiling",
    min_altitude: "below the floor",
    not_converged: "not converged",
  };

  // The grid as [wind index][length index] cells.
  function grid(res) {
    const nw = res.wind_speeds_m_s.length;
    const nl = res.tether_lengths_m.length;
    const cell = (i, j) => res.points[i * nl + j];
    return { nw, nl, cell };
  }

  const regionKey = (p) => (p.feasible ? "feasible" : p.binding_limit || "infeasible");

  // Connected regions (4-neighbours) of cells with the same key; each with the
  // cell deepest inside it (largest distance to another key) for its label.
  function regions(res) {
    const { nw, nl, cell } = grid(res);
    const id = new Int32Array(nw * nl).fill(-1);
    const out = [];
    for (let i0 = 0; i0 < nw; i0++) {
      for (let j0 = 0; j0 < nl; j0++) {
        if (id[i0 * nl + j0] >= 0) continue;
        const key = regionKey(cell(i0, j0));
        const cells = [];
        const stack = [[i0, j0]];
        id[i0 * nl + j0] = out.length;
        while (stack.length) {
          const [i, j] = stack.pop();
          cells.push([i, j]);
          for (const [a, b] of [[i + 1, j], [i - 1, j], [i, j + 1], [i, j - 1]]) {
            if (a < 0 || b < 0 || a >= nw || b >= nl || id[a * nl + b] >= 0) continue;
            if (regionKey(cell(a, b)) !== key) continue;
            id[a * nl + b] = out.length;
            stack.push([a, b]);
          }
        }
        out.push({ key, name: REGION_NAMES[key] || key.replace(/_/g, " "), cells });
      }
    }
    // Distance (in cells, Chebyshev) to the nearest cell of another region or
    // the grid's edge, by a breadth-first sweep from the boundaries.
    const dist = new Int32Array(nw * nl).fill(-1);
    let frontier = [];
    for (let i = 0; i < nw; i++) {
      for (let j = 0; j < nl; j++) {
        // The grid's own edge counts as a boundary: names sit inside the map.
        let edge = false;
        for (let a = i - 1; a <= i + 1 && !edge; a++) {
          for (let b = j - 1; b <= j + 1; b++) {
            if (a < 0 || b < 0 || a >= nw || b >= nl || id[a * nl + b] !== id[i * nl + j]) edge = true;
          }
        }
        if (edge) {
          dist[i * nl + j] = 0;
          frontier.push([i, j]);
        }
      }
    }
    while (frontier.length) {
      const next = [];
      for (const [i, j] of frontier) {
        for (let a = i - 1; a <= i + 1; a++) {
          for (let b = j - 1; b <= j + 1; b++) {
            if (a < 0 || b < 0 || a >= nw || b >= nl || dist[a * nl + b] >= 0) continue;
            dist[a * nl + b] = dist[i * nl + j] + 1;
            next.push([a, b]);
          }
        }
      }
      frontier = next;
    }
    for (const r of out) {
      // Deepest cell; ties go to the one nearest the region's centroid.
      const ci = r.cells.reduce((s, [i]) => s + i, 0) / r.cells.length;
      const cj = r.cells.reduce((s, [, j]) => s + j, 0) / r.cells.length;
      let best = null;
      for (const [i, j] of r.cells) {
        const d = dist[i * nl + j];
        const off = (i - ci) ** 2 + (j - cj) ** 2;
        if (!best || d > best.d || (d === best.d && off < best.off)) best = { i, j, d, off };
      }
      r.anchor = [best.i, best.j];
      r.depth = best.d;
    }
    return out;
  }

  // Edges between a feasible cell and an infeasible one (or the grid's edge),
  // as [i0, j0, i1, j1] in cell-corner coordinates (corner (i, j) is the
  // lower-left corner of cell (i, j)).
  function outline(res) {
    const { nw, nl, cell } = grid(res);
    const ok = (i, j) => i >= 0 && j >= 0 && i < nw && j < nl && cell(i, j).feasible;
    const segs = [];
    for (let i = 0; i < nw; i++) {
      for (let j = 0; j < nl; j++) {
        if (!ok(i, j)) continue;
        if (!ok(i - 1, j)) segs.push([i, j, i, j + 1]);
        if (!ok(i + 1, j)) segs.push([i + 1, j, i + 1, j + 1]);
        if (!ok(i, j - 1)) segs.push([i, j, i + 1, j]);
        if (!ok(i, j + 1)) segs.push([i, j + 1, i + 1, j + 1]);
      }
    }
    return segs;
  }

  // Draws the map into `canvas` at `cssW` CSS pixels wide; returns its layout.
  function drawMap(canvas, cssW, { forExport = false } = {}) {
    const res = state.result;
    const cssH = forExport ? 520 : Math.round(Math.min(440, Math.max(280, cssW * 0.62)));
    const dpr = forExport ? 2 : window.devicePixelRatio || 1;
    canvas.width = Math.round(cssW * dpr);
    canvas.height = Math.round(cssH * dpr);
    if (!forExport) canvas.style.height = `${cssH}px`;
    const ctx = canvas.getContext("2d");
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.fillStyle = "#fff";
    ctx.fillRect(0, 0, cssW, cssH);
    if (!res) return null;
    const narrow = cssW < 480;
    const m = { left: 58, right: narrow ? 60 : 84, top: 8, bottom: 40 };
    const pw = cssW - m.left - m.right;
    const ph = cssH - m.top - m.bottom;
    const { nw, nl, cell } = grid(res);
    const q = QUANTITIES[$("env-quantity").value] || QUANTITIES.altitude;
    const logColour = $("env-log").checked;
    let lo = Infinity;
    let hi = -Infinity;
    for (const p of res.points) {
      const v = p[q.key];
      if (v == null || !Number.isFinite(v) || (logColour && !(v > 0))) continue;
      const s = logColour ? Math.log10(v) : v;
      lo = Math.min(lo, s);
      hi = Math.max(hi, s);
    }
    if (!Number.isFinite(lo)) {
      lo = 0;
      hi = 1;
    }
    if (!(hi > lo)) hi = lo + 1;
    const scaled = (v) => {
      if (v == null || !Number.isFinite(v) || (logColour && !(v > 0))) return null;
      return ((logColour ? Math.log10(v) : v) - lo) / (hi - lo);
    };
    // Cells: one pixel per (wind, length) in an offscreen image, scaled up;
    // infeasible cells washed out so the feasible region stands out.
    S.heatCells(ctx, { m, pw, ph, columns: nw, rows: nl }, (i, j) => {
      const p = cell(i, j);
      const s = scaled(p[q.key]);
      const rgb = s == null ? [190, 190, 190] : colour(s);
      return p.feasible ? rgb : rgb.map((c) => Math.round(c * 0.55 + 255 * 0.45));
    });

    // Axes: cell i spans [U_i − dU/2, U_i + dU/2] (likewise in length).
    const W = res.wind_speeds_m_s;
    const L = res.tether_lengths_m;
    const dW = nw > 1 ? (W[nw - 1] - W[0]) / (nw - 1) : 1;
    const dL = nl > 1 ? (L[nl - 1] - L[0]) / (nl - 1) : Math.max(1, L[0] * 0.1);
    const w0 = W[0] - dW / 2, w1 = W[nw - 1] + dW / 2;
    const l0 = L[0] - dL / 2, l1 = L[nl - 1] + dL / 2;
    const xOf = (v) => m.left + ((v - w0) / (w1 - w0)) * pw;
    const yOf = (v) => m.top + ph - ((v - l0) / (l1 - l0)) * ph;
    const cx = (i) => m.left + (i / nw) * pw; // corner i
    const cy = (j) => m.top + ph - (j / nl) * ph; // corner j

    // Hatch the infeasible cells lightly (visible in print and for colour-blind readers).
    ctx.save();
    ctx.beginPath();
    for (let i = 0; i < nw; i++) for (let j = 0; j < nl; j++) if (!cell(i, j).feasible) ctx.rect(cx(i), cy(j + 1), cx(i + 1) - cx(i), cy(j) - cy(j + 1));
    ctx.clip();
    ctx.strokeStyle = "rgba(0,0,0,0.18)";
    ctx.lineWidth = 1;
    ctx.beginPath();
    for (let d = -ph; d < pw; d += 8) {
      ctx.moveTo(m.left + d, m.top + ph);
      ctx.lineTo(m.left + d + ph, m.top);
    }
    ctx.stroke();
    ctx.restore();

    // The feasible region's outline: a white halo under a dark line.
    const segs = outline(res);
    state.outline = segs;
    for (const [style, width] of [["#fff", 4], ["#111", 2]]) {
      ctx.strokeStyle = style;
      ctx.lineWidth = width;
      ctx.lineCap = "round";
      ctx.beginPath();
      for (const [i0, j0, i1, j1] of segs) {
        ctx.moveTo(cx(i0), cy(j0));
        ctx.lineTo(cx(i1), cy(j1));
      }
      ctx.stroke();
    }

    // The highest altitude per wind: a marker at the length that reaches it.
    ctx.fillStyle = "#fff";
    ctx.strokeStyle = "#111";
    ctx.lineWidth = 1;
    for (const wl of res.max_altitude_per_wind) {
      if (wl.tether_length_m == null) continue;
      const x = xOf(wl.wind_speed_m_s);
      const y = yOf(wl.tether_length_m);
      ctx.beginPath();
      ctx.arc(x, y, Math.min(3.5, Math.max(2, pw / nw / 3)), 0, 2 * Math.PI);
      ctx.fill();
      ctx.stroke();
    }

    // Region names, at each region's deepest cell; small regions get none
    // when the text would not fit.
    const regs = regions(res);
    ctx.font = `${narrow ? 11 : 12}px system-ui, sans-serif`;
    ctx.textAlign = "center";
    ctx.textBaseline = "middle";
    const cellW = pw / nw;
    const cellH = ph / nl;
    const placed = [];
    const th = 16;
    const overlaps = (box) => placed.some((b) => box[0] < b[0] + b[2] && b[0] < box[0] + box[2] && box[1] < b[1] + b[3] && b[1] < box[1] + box[3]);
    const boxAt = (r, dy = 0) => {
      const [i, j] = r.anchor;
      const x = m.left + (i + 0.5) * cellW;
      const y = Math.min(Math.max(m.top + ph - (j + 0.5) * cellH + dy, m.top + th / 2 + 1), m.top + ph - th / 2 - 1);
      const tw = ctx.measureText(r.name).width + 8;
      return [Math.min(Math.max(x - tw / 2, m.left + 1), m.left + pw - tw - 1), y - th / 2, tw, th];
    };
    const sorted = regs.sort((a, b) => b.cells.length - a.cells.length);
    // First every region with room for its name; then, for a limit whose
    // regions all lack room, its largest region anyway (moved up or down
    // off other names), so each binding limit is named on the map.
    for (const r of sorted) {
      const box = boxAt(r);
      const room = (2 * r.depth + 1) * Math.min(cellW, cellH) >= th || r.cells.length * cellW * cellH >= box[2] * th;
      r.labelled = room && !overlaps(box);
      if (r.labelled) {
        r.box = box;
        placed.push(box);
      }
    }
    for (const r of sorted) {
      if (sorted.some((o) => o.key === r.key && o.labelled) || sorted.find((o) => o.key === r.key) !== r) continue;
      for (const dy of [0, -th, th, -2 * th, 2 * th, -3 * th, 3 * th]) {
        const box = boxAt(r, dy);
        if (overlaps(box)) continue;
        r.labelled = true;
        r.box = box;
        placed.push(box);
        break;
      }
    }
    for (const r of sorted) {
      if (!r.labelled) continue;
      const box = r.box;
      const tw = box[2];
      const y = box[1] + th / 2;
      r.label_x = box[0] + tw / 2;
      r.label_y = y;
      ctx.fillStyle = r.key === "feasible" ? "rgba(255,255,255,0.92)" : "rgba(255,240,242,0.92)";
      ctx.strokeStyle = r.key === "feasible" ? "#1a7f37" : "#b00020";
      ctx.lineWidth = 1;
      ctx.fillRect(...box);
      ctx.strokeRect(box[0] + 0.5, box[1] + 0.5, box[2] - 1, box[3] - 1);
      ctx.fillStyle = r.key === "feasible" ? "#0d4d21" : "#7a0016";
      ctx.fillText(r.name, box[0] + tw / 2, y + 0.5);
    }
    state.regions = regs.map((r) => ({ key: r.key, name: r.name, cells: r.cells.length, labelled: r.labelled, x: r.label_x, y: r.label_y, box: r.labelled ? r.box : null }));

    ctx.strokeStyle = "#333";
    ctx.lineWidth = 1;
    ctx.strokeRect(m.left + 0.5, m.top + 0.5, pw - 1, ph - 1);
    S.heatFrame(ctx, {
      m, pw, ph, xOf, yOf,
      xTicks: ticks(W[0], W[nw - 1], narrow ? 4 : 8), yTicks: ticks(L[0], L[nl - 1], 6),
      fmtX: (v) => fmt(v), fmtY: (v) => fmt(v, 4),
      xLabel: "Wind speed at the reference height (m/s)", yLabel: "Tether length (m)", xLabelDy: 22,
    });

    // Colour bar.
    const bx = m.left + pw + 10;
    const bw = 12;
    // Log colour: 1, 2 and 5 × 10^k when the range spans few decades.
    const barTicks = logColour
      ? (() => {
          const out = [];
          for (let d = Math.floor(lo); d <= Math.ceil(hi); d++) for (const f of hi - lo > 3 ? [1] : [1, 2, 5]) out.push(d + Math.log10(f));
          return out.filter((v) => v >= lo - 1e-9 && v <= hi + 1e-9);
        })()
      : ticks(lo, hi, 5);
    S.heatScale(ctx, { x: bx, top: m.top, w: bw, h: ph, lo, hi, ticks: barTicks, text: (v) => (logColour ? fmt(10 ** v, 2) : fmt(v, 3)) });
    ctx.textAlign = "center";
    ctx.textBaseline = "top";
    ctx.fillText(`(${q.unit})`, bx + bw / 2 + 10, m.top + ph + 22);
    return { m, pw, ph, nw, nl, w0, w1, l0, l1, cssW, cssH };
  }

  function draw() {
    const canvas = $("env-heatmap");
    const wrap = canvas.parentElement;
    state.layout = drawMap(canvas, Math.max(260, Math.floor(wrap.clientWidth)));
  }

  function readout(ev) {
    const L = state.layout;
    const out = $("env-readout");
    const res = state.result;
    if (!L || !res) return;
    const rect = ev.target.getBoundingClientRect();
    const x = ev.clientX - rect.left - L.m.left;
    const y = ev.clientY - rect.top - L.m.top;
    if (x < 0 || y < 0 || x > L.pw || y > L.ph) {
      out.innerHTML = "&nbsp;";
      return;
    }
    const i = Math.min(L.nw - 1, Math.floor((x / L.pw) * L.nw));
    const j = Math.min(L.nl - 1, Math.floor(((L.ph - y) / L.ph) * L.nl));
    const p = grid(res).cell(i, j);
    out.textContent =
      `U = ${fmt(p.wind_speed_m_s)} m/s, L = ${fmt(p.tether_length_m, 4)} m: altitude ${fmt(p.aerostat_altitude_m, 4)} m, ` +
      `downwind ${fmt(p.aerostat_downwind_m, 4)} m, winch ${fmt(p.winch_tension_n, 4)} N, top ${fmt(p.top_tension_n, 4)} N, ` +
      `safety factor ${fmt(p.safety_factor_nondim)}` +
      (p.gust ? `; in the gust (${fmt(p.gust.wind_speed_m_s)} m/s): altitude ${fmt(p.gust.aerostat_altitude_m, 4)} m, winch ${fmt(p.gust.winch_tension_n, 4)} N, ` +
        `safety factor ${fmt(p.gust.safety_factor_nondim)}` : "") +
      ` — ${p.feasible ? "feasible" : `${REGION_NAMES[p.binding_limit] || p.binding_limit}${p.gust?.binds ? " in the gust" : ""}`}`;
  }

  // ---------- tables ----------

  function fillTables(res) {
    const perLength = $("env-per-length").querySelector("tbody");
    perLength.textContent = "";
    for (const r of res.max_wind_per_length) {
      const tr = document.createElement("tr");
      for (const [text, cls] of [
        [fmt(r.tether_length_m, 4), "num"],
        [r.altitude_at_max_wind_m == null ? "–" : fmt(r.altitude_at_max_wind_m, 4), "num"],
        [r.max_wind_speed_m_s == null ? "none" : fmt(r.max_wind_speed_m_s), "num"],
        [r.binding_limit == null ? "whole grid inside" : REGION_NAMES[r.binding_limit] || r.binding_limit, ""],
      ]) {
        const td = document.createElement("td");
        td.textContent = text;
        if (cls) td.className = cls;
        tr.append(td);
      }
      perLength.append(tr);
    }
    const perWind = $("env-per-wind").querySelector("tbody");
    perWind.textContent = "";
    for (const r of res.max_altitude_per_wind) {
      const tr = document.createElement("tr");
      for (const text of [fmt(r.wind_speed_m_s), r.max_altitude_m == null ? "none inside" : fmt(r.max_altitude_m, 4), r.tether_length_m == null ? "–" : fmt(r.tether_length_m, 4)]) {
        const td = document.createElement("td");
        td.textContent = text;
        td.className = "num";
        tr.append(td);
      }
      perWind.append(tr);
    }
  }

  function summary(res) {
    const feasible = res.points.filter((p) => p.feasible).length;
    const best = res.max_altitude_per_wind.reduce((a, r) => (r.max_altitude_m != null && (!a || r.max_altitude_m > a.max_altitude_m) ? r : a), null);
    const windiest = res.max_altitude_per_wind.filter((r) => r.max_altitude_m != null).at(-1);
    const limits = [...new Set(res.points.filter((p) => !p.feasible).map((p) => REGION_NAMES[p.binding_limit] || p.binding_limit))];
    const parts = [`${feasible} of ${res.points.length} points feasible`];
    if (best) parts.push(`highest altitude ${fmt(best.max_altitude_m, 4)} m (L = ${fmt(best.tether_length_m, 4)} m at ${fmt(best.wind_speed_m_s)} m/s)`);
    if (windiest) parts.push(`operable up to ${fmt(windiest.wind_speed_m_s)} m/s (then at most ${fmt(windiest.max_altitude_m, 4)} m)`);
    if (limits.length) parts.push(`limits met: ${limits.join(", ")}`);
    return parts.join("; ");
  }

  function render(res, req, via) {
    state.result = res;
    state.request = req;
    state.via = via;
    const sfOption = $("env-quantity").querySelector('option[value="safety_factor"]');
    sfOption.disabled = res.cable.breaking_strength_n == null;
    if (sfOption.disabled && $("env-quantity").value === "safety_factor") $("env-quantity").value = "altitude";
    // Shown before drawing: a hidden box has no width to draw into.
    $("env-output").hidden = false;
    draw();
    fillTables(res);
    $("env-csv").disabled = false;
    $("env-png").disabled = false;
    $("env-criterion").textContent = res.payout_rate_m_s != null
      ? `Stability at ${fmt(res.payout_rate_m_s)} m/s payout: ${res.stability_criterion}.`
      : "Stability not judged (no payout rate).";
    setStatus("ready", `${summary(res)}${via && via !== "direct" ? ` (${via})` : ""}.`);
  }

  // ---------- submitting ----------

  let busy = false;
  async function run() {
    if (busy) return;
    S.clearErrors(SOURCE);
    S.showFormError($("env-error"), "");
    S.writeUrl();
    const errors = [];
    const req = readRequest(errors);
    if (errors.length) {
      S.showInputErrors(roots, errors, SOURCE);
      setStatus("error", "Fix the highlighted fields.");
      return;
    }
    busy = true;
    $("env-button").disabled = true;
    try {
      let outcome;
      const n = points(req);
      if (wantsJob(req)) {
        setStatus("busy", `Submitting a job for ${n} points…`);
        outcome = await runJob("envelope", req, `${n} points`, setStatus);
      } else {
        setStatus("busy", `Computing ${n} points…`);
        const r = await S.api("POST", "/api/v1/envelope", req);
        if (S.needsJob(r)) {
          setStatus("busy", "The server asked for a background job…");
          outcome = await runJob("envelope", req, `${n} points`, setStatus);
        } else {
          outcome = r.ok ? { result: r.body, via: "direct" } : { status: r.status, error: r.body };
        }
      }
      if (outcome.result) render(outcome.result, req, outcome.via);
      else if (outcome.error?.error?.code === "cancelled") setStatus("idle", "Job cancelled.");
      else {
        const text = S.renderApiError(roots, outcome.status, outcome.error, $("env-error"), SOURCE);
        setStatus("error", `Fix the highlighted field: ${text}`);
      }
    } finally {
      busy = false;
      $("env-button").disabled = false;
    }
  }

  form.addEventListener("submit", (ev) => {
    ev.preventDefault();
    run();
  });

  function updateHint() {
    const errors = [];
    const req = readRequest(errors);
    const n = errors.length ? null : points(req);
    $("env-hint").textContent = n == null ? "" : `${n} point${n === 1 ? "" : "s"}${wantsJob(req) ? " · runs as a background job" : ""}`;
  }

  // An answer for other inputs is no answer: dimmed and marked until computed again.
  function stale() {
    if (state.result && $("env-status").dataset.state === "ready") setStatus("stale", "Inputs changed: compute the envelope again.");
    $("env-csv").disabled = true;
    $("env-png").disabled = true;
  }
  form.addEventListener("input", (ev) => {
    if (ev.target.matches("input")) S.clearFieldError(ev.target);
    S.writeUrl();
    stale();
    updateHint();
  });
  document.addEventListener("tetherplan:system-input", () => {
    stale();
    updateHint();
  });

  $("env-quantity").addEventListener("change", () => {
    $("env-log").checked = $("env-quantity").value === "safety_factor";
    if (state.result) draw();
  });
  $("env-log").addEventListener("change", () => state.result && draw());
  $("env-heatmap").addEventListener("mousemove", readout);
  $("env-heatmap").addEventListener("mouseleave", () => ($("env-readout").innerHTML = "&nbsp;"));

  // ---------- downloads ----------

  const { download, flatten, sig, wrap } = S;

  const CSV_COLUMNS = ["wind_speed_m_s", "tether_length_m", "aerostat_altitude_m", "aerostat_downwind_m", "blowdown_angle_deg", "winch_tension_n",
    "top_tension_n", "max_tension_n", "min_tension_n", "safety_factor_nondim", "slack", "stability_margin_n", "stable", "feasible", "binding_limit"];
  const GUST_COLUMNS = ["wind_speed_m_s", "aerostat_altitude_m", "aerostat_downwind_m", "blowdown_angle_deg", "winch_tension_n", "max_tension_n",
    "safety_factor_nondim", "binding_limit", "binds"];

  // The inputs as sent (`# input`), the resolved tether and aerostat the server
  // used (`# resolved`, preset values filled in), then one row per grid point.
  function csv(res, req) {
    const lines = ["# tetherplan operating envelope"];
    for (const [k, v] of flatten(req)) lines.push(`# input ${k},${sig(v)}`);
    for (const [k, v] of flatten({ cable: res.cable, aerostat: res.aerostat })) lines.push(`# resolved ${k},${v == null ? "none" : sig(v)}`);
    lines.push(`# resolved integration_steps,${res.integration_steps}`);
    lines.push(`# stability_criterion,"${res.stability_criterion.replaceAll('"', "'")}"`);
    for (const r of res.max_wind_per_length) {
      lines.push(`# max_wind_per_length tether_length_m=${sig(r.tether_length_m)} max_wind_speed_m_s=${sig(r.max_wind_speed_m_s) || "none"} altitude_at_max_wind_m=${sig(r.altitude_at_max_wind_m) || "none"} binding_limit=${r.binding_limit ?? "none"}`);
    }
    for (const r of res.max_altitude_per_wind) {
      lines.push(`# max_altitude_per_wind wind_speed_m_s=${sig(r.wind_speed_m_s)} max_altitude_m=${sig(r.max_altitude_m) || "none"} tether_length_m=${sig(r.tether_length_m) || "none"}`);
    }
    // With gusts (SPEC §10) each row carries the cell's gust figures too.
    const gust = res.points.some((p) => p.gust) ? GUST_COLUMNS : [];
    lines.push([...CSV_COLUMNS, ...gust.map((c) => `gust_${c}`)].join(","));
    for (const p of res.points) lines.push([...CSV_COLUMNS.map((c) => sig(p[c])), ...gust.map((c) => sig(p.gust?.[c]))].join(","));
    return lines.join("\n") + "\n";
  }

  $("env-csv").addEventListener("click", () => {
    if (state.result) download(new Blob([csv(state.result, state.request)], { type: "text/csv" }), "tetherplan-envelope.csv");
  });

  // The map at a fixed size, its caption, the outline's legend and every input, on one white canvas.
  function png() {
    const W = 900;
    const map = document.createElement("canvas");
    const saved = { regions: state.regions, outline: state.outline };
    drawMap(map, W, { forExport: true });
    Object.assign(state, saved);
    const scale = map.width / W;
    const pad = 14;
    const line = 15;
    const q = QUANTITIES[$("env-quantity").value] || QUANTITIES.altitude;
    const canvas = document.createElement("canvas");
    const ctx = canvas.getContext("2d");
    const caption = `Operating envelope: ${q.label} over wind speed × tether length${$("env-log").checked ? " (log colour)" : ""}. ` +
      "Outlined: the feasible region; washed out and hatched: outside it, named by the binding limit; dots: the highest altitude per wind.";
    ctx.font = "12px sans-serif";
    const capRows = wrap(ctx, caption, W - 2 * pad);
    const inputs = [...flatten(state.request).map(([k, v]) => `${k} = ${sig(v)}`), ...flatten({ cable: state.result.cable, aerostat: state.result.aerostat }).map(([k, v]) => `resolved ${k} = ${v == null ? "none" : sig(v)}`)];
    const inputRows = wrap(ctx, `Inputs: ${inputs.join("; ")}.`, W - 2 * pad);
    const height = pad + capRows.length * line + 6 + 520 + 8 + inputRows.length * line + pad;
    canvas.width = W * scale;
    canvas.height = height * scale;
    ctx.scale(scale, scale);
    ctx.fillStyle = "#fff";
    ctx.fillRect(0, 0, W, height);
    ctx.fillStyle = "#111";
    ctx.font = "bold 12px sans-serif";
    ctx.textBaseline = "top";
    let y = pad;
    for (const r of capRows) {
      ctx.fillText(r, pad, y);
      y += line;
    }
    y += 6;
    ctx.drawImage(map, 0, y, W, 520);
    y += 528;
    ctx.font = "11px sans-serif";
    ctx.fillStyle = "#333";
    for (const r of inputRows) {
      ctx.fillText(r, pad, y);
      y += line;
    }
    return canvas;
  }

  $("env-png").addEventListener("click", () => {
    if (state.result) png().toBlob((blob) => download(blob, "tetherplan-envelope.png"), "image/png");
  });

  let resizeTimer = null;
  window.addEventListener("resize", () => {
    clearTimeout(resizeTimer);
    resizeTimer = setTimeout(() => state.result && draw(), 100);
  });

  updateHint();
  // A shared link with envelope inputs computes it at once.
  if (new URLSearchParams(window.location.search).toString().includes("envelope.")) run();
})();
