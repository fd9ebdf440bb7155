// The live-flight panel (SPEC §13, issue 33): starts a flight from the plan's
// inputs (POST /api/v1/flights with a name and the "no data after" limit) or
// opens one of the token's flights, then follows GET …/events: the stoplight
// first (#live-light, data-state normal | caution | stop | unavailable, the
// word always written beside the colour), the checks against their caution
// and stop thresholds, the alarms with Acknowledge, the committed plan's
// length against time with the flight's trace, small traces of rate, tension
// (its caution and stop lines) and wind, and "Re-plan from now".
//
// Samples are kept by arrival number (`seq`): a replay after a reconnect
// (EventSource sends Last-Event-ID by itself) never adds one twice. A
// `state` event comes every second: none for 2 s shows `unavailable` here
// whatever the last one said. A server with API tokens needs the
// Authorization header, which EventSource cannot send: with a token the
// same stream is read with fetch, sending Last-Event-ID as a browser would.
// Figures are shown in the page's units (shared/units.js). The committed
// plan is the answer to the POST, kept in this browser (localStorage); a
// flight opened in another browser reads it from GET …/plan.
"use strict";

import S from "./shared/index.js";
import { linePlot } from "./live_plot.js";

(function () {
  const CARD = S.declareCard("live", [
    "cable.preset", "cable.diameter_m", "cable.mass_per_length_kg_m", "cable.breaking_strength_n",
    "cable.normal_drag_coefficient_nondim", "cable.axial_stiffness_n",
    "aerostat.preset", "aerostat.net_buoyancy_n", "aerostat.mass_kg",
    "aerostat.drag_coefficient_nondim", "aerostat.reference_area_m2", "aerostat.lift_coefficient_nondim",
    "gravity_m_s2", "required_safety_factor_nondim",
    "wind.air_density_kg_m3", "wind.flow", "wind.gust",
    "winch.max_rate_m_s", "winch.max_acceleration_m_s2", "winch.max_jerk_m_s3",
    "lift_reserve_nondim", "initial_length_m",
  ]);
  const section = document.getElementById("live");
  const planForm = document.getElementById("plan-form");
  if (!section || !planForm) return;
  const $ = (id) => document.getElementById(id);
  const SOURCE = "live";
  const QUIET_MS = 2000;
  const roots = [planForm, section];
  const st = { id: null, flight: null, plan: null, samples: [], lastSeq: 0, stream: null, lastStateAt: 0, local: false, replan: null };
  window.tetherplanLive = st;

  const NAMES = { tension: "Winch tension", slack: "Slack", wind: "Wind (10-min mean)", gust: "Gust (3 s)", payout_rate: "Payout rate", plan: "Ahead of the plan", data: "Since the last sample" };
  function checkText(c, v) {
    if (v == null) return "–";
    if (c.unit === "N") return `${Math.round(v)} N`;
    if (c.unit === "m/s") return c.name === "payout_rate" ? S.rateText(v) : S.speedText(v);
    if (c.unit === "nondim") return `${(100 * v).toFixed(1)} %`;
    if (c.unit === "s") return `${v.toFixed(1)} s`;
    return `${v} ${c.unit}`;
  }
  const showError = (text) => S.showFormError($("live-error"), text);

  // ---------- starting and opening ----------

  function readRequest(errors) {
    const body = S.readSystem(errors, CARD);
    body.target_elevation_m = S.readNumber([planForm], "target_elevation_m", errors);
    const floor = S.readNumber([planForm], "min_altitude_m", errors, { optional: true, fallback: undefined });
    if (floor != null) body.min_altitude_m = floor;
    // The plan's forecast and wind limits, as the plan panel read them.
    const hd = window.tetherplanPlan?.request?.haul_down;
    if (hd) body.haul_down = hd;
    return body;
  }

  const planKey = (id) => `tetherplan.flight.${id}.plan`;
  function keepPlan(id, plan) {
    const corridor = { t: plan.schedule.map((s) => s.time_s), length: plan.schedule.map((s) => s.length_m) };
    try {
      localStorage.setItem(planKey(id), JSON.stringify(corridor));
    } catch {
      /* private mode: the corridor is shown while the page stays open */
    }
    return corridor;
  }
  function storedPlan(id) {
    try {
      return JSON.parse(localStorage.getItem(planKey(id)) || "null");
    } catch {
      return null;
    }
  }

  async function start(ev) {
    ev.preventDefault();
    S.clearErrors(SOURCE);
    showError("");
    const errors = [];
    const body = readRequest(errors);
    const stale = Number($("live-stale").value);
    if (!(stale > 0)) errors.push({ field: "limits.stale_after_s", message: "enter a number of seconds above 0" });
    if (errors.length) {
      S.showInputErrors(roots, errors, SOURCE);
      showError(errors.map((e) => S.plainMessage(e.field, e.message)).join("; "));
      return;
    }
    body.name = $("live-flight-name").value.trim() || "flight";
    body.limits = { stale_after_s: stale };
    $("live-start").disabled = true;
    const r = await S.api("POST", "api/v1/flights", body);
    $("live-start").disabled = false;
    if (!r.ok) {
      S.renderApiError(roots, r.status, r.body, $("live-error"), SOURCE);
      return;
    }
    const plan = keepPlan(r.body.id, r.body.plan);
    await listFlights(r.body.id);
    await open(r.body.id, plan);
  }

  async function listFlights(selected) {
    const r = await S.api("GET", "api/v1/flights");
    if (!r.ok) return;
    const options = r.body.flights.map((f) => new Option(`${f.name} · #${f.id} · ${f.created_at}${f.ended_at ? " · ended" : ""}`, String(f.id)));
    $("live-flights").replaceChildren(new Option("–", ""), ...options);
    if (selected != null) $("live-flights").value = String(selected);
  }

  async function open(id, plan) {
    st.stream?.close();
    Object.assign(st, { id, flight: null, samples: [], lastSeq: 0, stream: null, replan: null, local: false });
    st.plan = plan || storedPlan(id);
    showError("");
    if (!st.plan) {
      // opened in another browser: the committed plan from the server
      const p = await S.api("GET", `api/v1/flights/${encodeURIComponent(id)}/plan`);
      if (p.ok && st.id === id) st.plan = keepPlan(id, p.body);
    }
    const r = await S.api("GET", `api/v1/flights/${encodeURIComponent(id)}`);
    if (!r.ok || st.id !== id) {
      if (!r.ok) S.renderApiError(roots, r.status, r.body, $("live-error"), SOURCE);
      return;
    }
    $("live-body").hidden = false;
    $("live-replan-out").hidden = true;
    for (const b of ["live-ack", "live-replan", "live-print"]) $(b).disabled = false;
    onState(r.body);
    connect();
  }

  // ---------- the stream ----------

  function connect() {
    const path = `api/v1/flights/${encodeURIComponent(st.id)}/events`;
    st.lastStateAt = performance.now();
    const token = S.apiToken();
    if (token) {
      st.stream = fetchStream(path, token);
      return;
    }
    const es = new EventSource(path);
    es.addEventListener("samples", (e) => onSamples(JSON.parse(e.data)));
    es.addEventListener("state", (e) => onState(JSON.parse(e.data)));
    st.stream = { close: () => es.close(), kind: "EventSource" };
  }

  // The stream read with fetch (a server with tokens): reconnects after 1 s
  // from the last samples event's id, as EventSource does. `drop()` ends
  // the current connection (as a network drop would); the loop reconnects.
  function fetchStream(path, token) {
    let stopped = false;
    let abort = null;
    (async () => {
      while (!stopped) {
        abort = new AbortController();
        try {
          const headers = { accept: "text/event-stream", authorization: `Bearer ${token}` };
          if (st.lastSeq > 0) headers["last-event-id"] = String(st.lastSeq);
          const res = await fetch(path, { headers, signal: abort.signal });
          if (!res.ok) break;
          const reader = res.body.pipeThrough(new TextDecoderStream()).getReader();
          let buf = "";
          for (;;) {
            const { value, done } = await reader.read();
            if (done) break;
            buf += value.replace(/\r\n?/g, "\n");
            let i;
            while ((i = buf.indexOf("\n\n")) >= 0) {
              dispatch(buf.slice(0, i));
              buf = buf.slice(i + 2);
            }
          }
        } catch {
          if (stopped) return;
        }
        st.reconnects = (st.reconnects || 0) + 1;
        await S.sleep(1000);
      }
    })();
    return { close: () => ((stopped = true), abort?.abort()), drop: () => abort?.abort(), kind: "fetch" };
  }
  function dispatch(block) {
    let event = "message";
    const data = [];
    for (const line of block.split("\n")) {
      const m = /^([^:]+):? ?(.*)$/.exec(line);
      if (!m) continue;
      if (m[1] === "event") event = m[2];
      else if (m[1] === "data") data.push(m[2]);
    }
    if (!data.length) return;
    const body = JSON.parse(data.join("\n"));
    if (event === "samples") onSamples(body);
    else if (event === "state") onState(body);
  }

  function onSamples(body) {
    let added = false;
    for (const s of body.samples) {
      if (s.seq <= st.lastSeq) continue;
      st.lastSeq = s.seq;
      st.samples.push(s);
      added = true;
    }
    if (added) {
      st.sorted = null;
      redraw();
    }
  }

  function onState(f) {
    if (st.id == null || f.id !== st.id) return;
    st.lastStateAt = performance.now();
    st.flight = f;
    st.local = false;
    render();
  }

  // No state event for 2 s: unavailable here, whatever the last one said.
  setInterval(() => {
    if (st.id == null) return;
    const quiet = performance.now() - st.lastStateAt > QUIET_MS;
    if (quiet !== st.local) {
      st.local = quiet;
      render();
    }
  }, 250);

  // ---------- what is shown ----------

  const bySampleTime = () => (st.sorted ||= [...st.samples].sort((a, b) => a.time_s - b.time_s));

  function render() {
    const f = st.flight;
    if (!f) return;
    const state = st.local ? "unavailable" : f.state;
    const light = $("live-light");
    light.dataset.state = state;
    light.dataset.source = st.local ? "page" : "server";
    section.dataset.state = state;
    light.querySelector(".word").textContent = state;
    light.querySelector(".why").textContent = why(f, state);
    $("live-name").textContent = `${f.name} · #${f.id}${f.ended_at ? " · ended" : ""}`;

    const tbody = $("live-checks").tBodies[0];
    tbody.replaceChildren(...f.checks.map((c) => {
      const tr = document.createElement("tr");
      tr.dataset.check = c.name;
      tr.dataset.state = c.state;
      for (const text of [NAMES[c.name] || c.name, c.state, checkText(c, c.value), checkText(c, c.caution_at), checkText(c, c.stop_at)]) {
        tr.insertCell().textContent = text;
      }
      tr.cells[2].dataset.si = c.value ?? "";
      return tr;
    }));

    const open = f.alarms.filter((a) => a.cleared_at_s == null || (a.level === "stop" && a.acknowledged_at_s == null));
    const list = $("live-alarms");
    list.replaceChildren(...(f.alarms.length ? f.alarms.slice().reverse() : [null]).map((a) => {
      const li = document.createElement("li");
      if (!a) return (li.textContent = "none", li);
      li.dataset.level = a.level;
      li.textContent = `${a.level.toUpperCase()} ${NAMES[a.check] || a.check} at ${a.raised_at_s.toFixed(1)} s` +
        (a.cleared_at_s != null ? `, back at ${a.cleared_at_s.toFixed(1)} s` : ", raised") +
        (a.acknowledged_at_s != null ? `, acknowledged at ${a.acknowledged_at_s.toFixed(1)} s` : a.level === "stop" ? ", not acknowledged" : "");
      return li;
    }));
    $("live-ack").disabled = !open.some((a) => a.acknowledged_at_s == null);
    latest();
    redraw();
  }

  function why(f, state) {
    if (st.local) return `no word from the server for ${((performance.now() - st.lastStateAt) / 1000).toFixed(0)} s`;
    if (state === "unavailable") {
      const since = f.seconds_since_last_sample_s;
      return since == null ? "no samples yet" : `no sample for ${since.toFixed(0)} s`;
    }
    const bad = f.checks.filter((c) => c.state === state && state !== "normal");
    const latched = f.alarms.some((a) => a.level === "stop" && a.acknowledged_at_s == null && a.cleared_at_s == null) && state === "stop" && !bad.length;
    if (latched) return "stop latched: acknowledge it";
    if (!bad.length) return `${f.samples_received} samples, the last at ${f.last_sample_time_s?.toFixed(1) ?? "–"} s`;
    return bad.map((c) => `${(NAMES[c.name] || c.name).toLowerCase()} ${checkText(c, c.value)} (${state} at ${checkText(c, state === "stop" ? c.stop_at : c.caution_at)})`).join("; ");
  }

  // The latest sample's figures, each with its SI value (data-si).
  function latest() {
    const s = bySampleTime().at(-1);
    const rows = s ? [
      ["Time", `${s.time_s.toFixed(1)} s`, s.time_s],
      ["Tether", S.lengthText(s.tether_length_m, 1), s.tether_length_m],
      ["Rate", S.rateText(s.winch_rate_m_s), s.winch_rate_m_s],
      ["Tension", s.winch_tension_n == null ? "–" : `${Math.round(s.winch_tension_n)} N`, s.winch_tension_n],
      ["Wind", S.speedText(s.wind_speed_m_s), s.wind_speed_m_s],
      ["Altitude", S.lengthText(s.aerostat_altitude_m, 1), s.aerostat_altitude_m],
    ] : [];
    $("live-latest").replaceChildren(...rows.map(([k, text, si]) => {
      const pair = document.createElement("div");
      const dt = document.createElement("dt");
      dt.textContent = k;
      const dd = document.createElement("dd");
      dd.textContent = text;
      dd.dataset.figure = k.toLowerCase();
      dd.dataset.si = si ?? "";
      pair.append(dt, dd);
      return pair;
    }));
  }

  let pending = false;
  function redraw() {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => {
      pending = false;
      draw();
    });
  }

  function draw(width) {
    if (st.id == null || $("live-body").hidden) return;
    const s = bySampleTime();
    const check = (n) => st.flight?.checks.find((c) => c.name === n) || {};
    const L = S.toLength;
    const lines = [];
    if (st.plan) lines.push({ cls: "plan", points: st.plan.t.map((t, i) => [t, L(st.plan.length[i])]) });
    if (st.replan) {
      const t0 = st.replan.from_s;
      lines.push({ cls: "replan", points: st.replan.plan.schedule.map((p) => [t0 + p.time_s, L(p.length_m)]) });
    }
    lines.push({ cls: "flight", points: s.map((p) => [p.time_s, L(p.tether_length_m)]) });
    // The plan around now: up to half as long again as flown (at least 60 s).
    const last = s.at(-1)?.time_s ?? 0;
    const xMax = Math.max(60, 1.5 * last, st.replan ? st.replan.from_s + 30 : 0);
    $("live-plan-note").hidden = !!st.plan;
    linePlot($("live-corridor"), { lines, label: "Tether length against time: plan and flight", unit: S.units.length, height: 200, width, xMax });
    const small = (id, pick, conv, unit, levels, label) =>
      linePlot($(id), { lines: [{ cls: "flight", points: s.map((p) => [p.time_s, conv(p[pick])]) }], levels, label, unit, width });
    small("live-rate", "winch_rate_m_s", L, `${S.units.length}/s`, [], "Winch rate against time");
    const t = check("tension");
    small("live-tension", "winch_tension_n", (v) => v, "N",
      [{ y: t.caution_at, cls: "caution", label: "caution" }, { y: t.stop_at, cls: "stop", label: "stop" }], "Winch tension against time");
    const w = check("wind");
    small("live-wind", "wind_speed_m_s", S.toSpeed, S.units.speed,
      [{ y: S.toSpeed(w.caution_at), cls: "caution", label: "caution" }, { y: S.toSpeed(w.stop_at), cls: "stop", label: "stop" }], "Wind against time");
  }

  // ---------- actions ----------

  async function acknowledge() {
    const r = await S.api("POST", `api/v1/flights/${encodeURIComponent(st.id)}/alarms/acknowledge`);
    if (!r.ok) return S.renderApiError(roots, r.status, r.body, $("live-error"), SOURCE);
    const g = await S.api("GET", `api/v1/flights/${encodeURIComponent(st.id)}`);
    if (g.ok) onState(g.body);
  }

  async function replan() {
    const out = $("live-replan-out");
    const from = st.flight?.last_sample_time_s ?? 0;
    const r = await S.api("GET", `api/v1/flights/${encodeURIComponent(st.id)}/replan`);
    out.hidden = false;
    if (!r.ok) {
      out.dataset.state = "error";
      out.textContent = `Re-plan: ${S.plainMessage(r.body?.error?.field, r.body?.error?.message ?? `the server answered ${r.status}`)}`;
      return;
    }
    st.replan = { from_s: from, ...r.body };
    showReplan();
    redraw();
  }
  function showReplan() {
    const r = st.replan;
    if (!r) return;
    const out = $("live-replan-out");
    out.dataset.state = r.plan.go ? "go" : "no-go";
    const head = document.createElement("p");
    head.innerHTML = "<strong></strong> ";
    head.firstChild.textContent = `Re-plan from ${r.from_s.toFixed(1)} s: ${r.mode === "haul_down" ? "HAUL DOWN" : "CONTINUE"}.`;
    head.append(r.reason);
    const figures = document.createElement("p");
    figures.textContent = `From ${S.lengthText(r.current_length_m, 1)}; measured wind ${S.speedText(r.measured_mean_wind_m_s)}, gust ${S.speedText(r.measured_gust_m_s)}; ` +
      `${r.plan.duration_s != null ? `${r.plan.duration_s.toFixed(0)} s` : "no schedule"}: ${r.plan.reason} (dashed on the length plot).`;
    out.replaceChildren(head, figures);
  }

  $("live-form").addEventListener("submit", start);
  $("live-open").addEventListener("click", () => {
    const id = Number($("live-flights").value);
    if (id) open(id);
  });
  $("live-ack").addEventListener("click", acknowledge);
  $("live-replan").addEventListener("click", replan);
  $("live-print").addEventListener("click", () => {
    document.body.dataset.print = "live";
    draw(680);
    window.print();
  });
  window.addEventListener("afterprint", () => {
    delete document.body.dataset.print;
    redraw();
  });
  window.addEventListener("resize", redraw);
  document.addEventListener("tetherplan:units", () => {
    render();
    showReplan();
  });
  listFlights();
  Object.assign(st, { open, acknowledge, replanNow: replan, listFlights });
})();
