// Today's launch windows from a forecast (SPEC §12, issue 32): a panel of its
// own after today's plan. Paste a forecast or drop a file on the panel
// (Open-Meteo JSON or its ensemble, a METAR, a TAF, or CSV
// `time,height_m,speed_m_s,gust_m_s`; the format is recognised), post
// /api/v1/windows with the system card and the plan's target, and draw the
// day's timeline: one cell per forecast period coloured by its verdict
// (data-verdict go | no-go), its bar as high as the reachable altitude, the
// launch windows marked beneath. Choosing a cell sets the plan's wind to that
// period's §9 wind (the fitted flow and gust) and plans again. Speeds and
// heights are shown in the page's units (shared/units.js: chosen in the
// header, kept in the URL as `speed` and `length`); the API stays SI.
"use strict";

import S from "./shared/index.js";

(function () {
  // What this panel reads from the system card (shared/system.js): what the
  // plan reads (each window is planned as today is).
  const CARD = S.declareCard("windows", [
    "cable.preset", "cable.diameter_m", "cable.mass_per_length_kg_m", "cable.breaking_strength_n",
    "cable.normal_drag_coefficient_nondim", "cable.axial_stiffness_n",
    "aerostat.preset", "aerostat.net_buoyancy_n", "aerostat.mass_kg",
    "aerostat.drag_coefficient_nondim", "aerostat.reference_area_m2", "aerostat.lift_coefficient_nondim",
    "gravity_m_s2", "required_safety_factor_nondim",
    "wind.air_density_kg_m3", "wind.flow", "wind.gust",
    "winch.max_rate_m_s", "winch.max_acceleration_m_s2", "winch.max_jerk_m_s3",
    "lift_reserve_nondim", "initial_length_m",
  ]);
  const plan = document.getElementById("plan");
  if (!S || !plan) return;
  // The page's units (shared/units.js, chosen in the header); the API stays SI.
  const sp = (v) => S.speedText(v, 1);
  const len = (v) => S.lengthText(v, 0);

  const section = document.createElement("section");
  section.id = "windows";
  section.setAttribute("aria-labelledby", "windows-heading");
  section.innerHTML = `
  <h2 id="windows-heading">Today's launch windows from a forecast</h2>
  <p class="hint">Paste a forecast or drop its file here: Open-Meteo JSON (or its ensemble), a METAR, a TAF, or CSV
    <code>time,height_m,speed_m_s,gust_m_s</code>. Each hour is judged as the plan above judges its wind; choose an hour to plan in it.</p>
  <form id="windows-form" novalidate>
    <fieldset><legend>Forecast and flight</legend>
    <div class="field wide"><label for="windows-data">Forecast</label>
      <textarea id="windows-data" rows="4" placeholder="drop a file here or paste"></textarea></div>
    <div class="field wide"><label for="windows-file">Forecast file</label><input id="windows-file" type="file" accept=".json,.csv,.txt"></div>
    <div class="field"><label for="windows-operation">Time aloft (h)</label><input id="windows-operation" inputmode="decimal" value="1"></div>
    <div class="field"><label for="windows-limit">Highest wind at the aerostat (m/s, blank: the plan's limits only)</label>
      <input id="windows-limit" inputmode="decimal" value=""></div>
    </fieldset>
    <div class="actions"><button type="submit" id="windows-button">Show the day</button>
      <button type="button" id="windows-fetch" class="secondary" hidden>Fetch today's forecast</button></div>
    <p id="windows-source" class="note" hidden></p>
    <p id="windows-error" class="error" role="alert" hidden></p>
  </form>
  <div id="windows-job" class="job" hidden>
    <progress id="windows-job-progress" max="1" value="0"></progress>
    <span id="windows-job-text"></span>
    <button type="button" id="windows-job-cancel" class="secondary">Cancel</button>
  </div>
  <p id="windows-summary" class="note" hidden></p>
  <div class="windows-scroll">
    <div id="windows-timeline" class="windows-timeline" role="list" aria-label="Forecast periods" hidden></div>
    <div id="windows-bands" class="windows-bands" aria-label="Launch windows"></div>
  </div>
  <p id="windows-list" class="note" hidden></p>`;
  plan.after(section);
  const $ = (id) => document.getElementById(id);
  // A forecast of many distinct winds costs more than a direct answer may
  // (a plan each): the server says so and the panel runs it as a job.
  const runJob = S.jobRunner("windows-");

  function detect(text) {
    const t = text.trim();
    if (t.startsWith("{")) return "open_meteo";
    if (/^(TAF)\b/.test(t)) return "taf";
    if (/^(METAR|SPECI)\b/.test(t) || /^[A-Z]{4} \d{6}Z/.test(t)) return "metar";
    return "csv";
  }

  document.addEventListener("tetherplan:units", () => last && draw(last));

  let last = null;
  // An answer that failed leaves no earlier day on show: the timeline of
  // another forecast (or other inputs) must not pass for this one's.
  function clearDay() {
    last = null;
    for (const id of ["windows-timeline", "windows-summary", "windows-list"]) $(id).hidden = true;
    $("windows-timeline").innerHTML = "";
    $("windows-bands").innerHTML = "";
  }

  // A number typed in a panel field, or an error naming the request field.
  function fieldNumber(id, field, unit, errors, { blank = null, min = 0 } = {}) {
    const raw = $(id).value.trim();
    if (!raw) return blank;
    const v = Number(raw);
    if (!Number.isFinite(v) || v < min) {
      errors.push({ field, message: `“${raw}” is not a number ≥ ${min} (${unit})` });
      return null;
    }
    return v;
  }

  async function run() {
    const err = $("windows-error");
    err.hidden = true;
    const text = $("windows-data").value;
    if (!text.trim()) return;
    const errors = [];
    const hoursAloft = fieldNumber("windows-operation", "operation_s", "hours aloft", errors, { blank: 0 });
    const limit = fieldNumber("windows-limit", "haul_down.max_operating_wind_m_s", "m/s", errors);
    const sys = S.readSystem(errors, CARD);
    const format = detect(text);
    let data = text;
    if (format === "open_meteo") {
      try { data = JSON.parse(text); } catch (e) { errors.push({ field: "forecast.data", message: `not JSON: ${e.message}` }); }
    }
    const target = S.readNumber([document.getElementById("plan-form")], "target_elevation_m", errors);
    if (errors.length) {
      clearDay();
      section.dataset.state = "error";
      err.textContent = errors.map((e) => `${e.field}: ${e.message}`).join("; ");
      err.hidden = false;
      return;
    }
    const body = {
      cable: sys.cable, aerostat: sys.aerostat, winch: sys.winch, gravity_m_s2: sys.gravity_m_s2,
      initial_length_m: sys.initial_length_m, lift_reserve_nondim: sys.lift_reserve_nondim,
      required_safety_factor_nondim: sys.required_safety_factor_nondim,
      wind: { air_density_kg_m3: sys.wind.air_density_kg_m3 },
      target_elevation_m: target,
      operation_s: 3600 * hoursAloft,
      forecast: { format, data },
    };
    if (limit != null) body.haul_down = { max_operating_wind_m_s: limit };
    $("windows-button").disabled = true;
    section.dataset.state = "pending";
    let res = await S.api("POST", "api/v1/windows", body);
    section.dataset.via = "direct";
    if (S.needsJob(res)) {
      section.dataset.via = "job";
      const out = await runJob("windows", body, "launch windows");
      res = out.result ? { ok: true, body: out.result } : { ok: false, status: out.status, body: out.error };
    }
    $("windows-button").disabled = false;
    if (!res.ok) {
      clearDay();
      section.dataset.state = "error";
      const e = res.body?.error;
      // The server's message may already begin with its field.
      err.textContent = e ? (e.message.startsWith(`${e.field}: `) ? e.message : `${e.field}: ${e.message}`) : `error ${res.status}`;
      err.hidden = false;
      return;
    }
    last = res.body;
    draw(last);
    section.dataset.state = "done";
  }

  // The day a period starts: the date of an ISO time, the DD of an
  // aviation time or TAF group; null otherwise.
  function dayOf(time) {
    const iso = time.match(/^(\d{4}-\d\d-\d\d)T/);
    if (iso) return iso[1];
    const av = time.match(/^(\d\d)\d\d(?:\d\dZ$|\/)/);
    return av ? av[1] : null;
  }

  // The hour a period starts, as its cell's label: "HH" of an ISO time
  // (YYYY-MM-DDTHH:MM, with "HH:MM" off the hour), of an aviation time
  // (DDHHMMZ) or of a TAF group (DDHH/DDHH); else the period's index.
  function hourLabel(time, i) {
    const iso = time.match(/T(\d\d):(\d\d)/);
    if (iso) return iso[2] === "00" ? iso[1] : `${iso[1]}:${iso[2]}`;
    const av = time.match(/^\d\d(\d\d)(\d\d)Z$/);
    if (av) return av[2] === "00" ? av[1] : `${av[1]}:${av[2]}`;
    const taf = time.match(/^\d\d(\d\d)\//);
    if (taf) return taf[1];
    return String(i + 1);
  }

  // Times as the forecast writes them, made comparable: ISO 8601 by
  // Date.parse, aviation DDHHMMZ in minutes from the first period's month
  // (a day before the first one's is in the next month).
  function timeKey(first) {
    const av = /^(\d\d)(\d\d)(\d\d)Z$/;
    const day0 = Number((first.match(av) || [])[1] ?? 0);
    return (t) => {
      const m = t.match(av);
      if (m) return ((Number(m[1]) < day0 ? Number(m[1]) + 31 : Number(m[1])) * 24 + Number(m[2])) * 60 + Number(m[3]);
      const ms = Date.parse(/[zZ]|[+-]\d\d:?\d\d$/.test(t) ? t : `${t}Z`);
      return Number.isFinite(ms) ? ms / 60000 : t;
    };
  }

  // A window in words: its span, the latest launch, and with an ensemble
  // the share of members that support it.
  const windowText = (w) => `${w.start}–${w.end}, launch by ${w.latest_launch}` +
    (w.probability != null ? ` (${(100 * w.probability).toFixed(0)} % of members)` : "");

  function draw(r) {
    const tl = $("windows-timeline");
    tl.innerHTML = "";
    tl.hidden = false;
    const top = Math.max(1, ...r.hours.map((h) => h.max_altitude_m || 0));
    r.hours.forEach((h, i) => {
      const b = document.createElement("button");
      b.type = "button";
      b.setAttribute("role", "listitem");
      b.dataset.verdict = h.verdict;
      b.dataset.index = String(i);
      b.dataset.time = h.time;
      b.dataset.end = h.end;
      b.setAttribute("aria-pressed", "false");
      const ens = h.probability_go != null;
      const p = ens
        ? `, P(go) ${(100 * h.probability_go).toFixed(0)} % (${(100 * h.probability_go_low).toFixed(0)}–${(100 * h.probability_go_high).toFixed(0)} %), ` +
          `reach of the members ${len(h.max_altitude_p10_m)} / ${len(h.max_altitude_p50_m)} / ${len(h.max_altitude_p90_m)} (10/50/90 %)`
        : "";
      b.title = `${h.time}${h.group && h.group !== "base" ? ` (${h.group.toUpperCase()})` : ""}: ${h.verdict.toUpperCase()}, reach ${len(h.max_altitude_m)}, wind at target ${sp(h.wind_at_target_m_s)}${p}\n${h.reason}`;
      b.setAttribute("aria-label", `${h.time} ${h.verdict}`);
      const bar = document.createElement("span");
      bar.className = "bar";
      bar.style.height = `${Math.max(4, (100 * (h.max_altitude_m || 0)) / top)}%`;
      const lab = document.createElement("span");
      lab.className = "hour";
      lab.textContent = hourLabel(h.time, i);
      // A new day (after the first cell) is marked, its day before its hour.
      const day = dayOf(h.time);
      if (i > 0 && day != null && day !== dayOf(r.hours[i - 1].time)) {
        b.classList.add("new-day");
        lab.textContent = `${day.slice(-2)}/${lab.textContent}`;
      }
      b.append(bar, lab);
      if (ens) {
        // The share of the ensemble's members that go, under the hour.
        const pr = document.createElement("span");
        pr.className = "prob";
        pr.textContent = `${(100 * h.probability_go).toFixed(0)}%`;
        b.append(pr);
      }
      b.addEventListener("click", () => choose(r, i));
      tl.append(b);
    });
    const bands = $("windows-bands");
    bands.innerHTML = "";
    // Cells and bands share the scrolling box (.windows-scroll, positioned),
    // so a cell's offsetLeft is the band's left at any scroll.
    bands.style.width = `${tl.scrollWidth}px`;
    const cells = [...tl.children];
    // A window lies under the periods it overlaps ([time, end) against
    // [start, end)): the hours inside it, or a TAF's change groups (which
    // last many hours and may overlap: a TEMPO inside a BECMG).
    const at = timeKey(r.hours[0]?.time ?? "");
    const rows = [];
    for (const w of r.windows) {
      const over = r.hours.flatMap((h, i) => (at(h.time) < at(w.end) && at(h.end) > at(w.start) ? [i] : []));
      if (!over.length) continue;
      const first = cells[over[0]];
      const lastCell = cells[over[over.length - 1]];
      const s = document.createElement("span");
      s.className = "window";
      const left = first.offsetLeft;
      const right = lastCell.offsetLeft + lastCell.offsetWidth;
      // Bands that would overlap (a TAF's windows under the same groups)
      // take rows of their own.
      let row = rows.findIndex((end) => end <= left);
      if (row < 0) row = rows.push(0) - 1;
      rows[row] = right + 2;
      s.style.left = `${left}px`;
      s.style.width = `${right - left}px`;
      s.style.top = `${row * 1.3}rem`;
      s.textContent = windowText(w);
      s.title = windowText(w);
      bands.append(s);
    }
    bands.style.height = `${Math.max(1, rows.length) * 1.3}rem`;
    const list = $("windows-list");
    list.textContent = r.windows.length ? `Launch windows: ${r.windows.map(windowText).join("; ")}.` : "No launch window in this forecast.";
    list.hidden = false;
    const go = r.hours.filter((h) => h.verdict === "go").length;
    const sum = $("windows-summary");
    sum.textContent = `${go} of ${r.hours.length} periods GO; ${r.windows.length} launch window(s)` +
      (r.members > 1 ? `; ${r.members} ensemble members` : "") +
      `; limits × α from 1 down by ${r.lead_time_factor.per_hour_nondim} per hour of lead time. ` +
      `Green GO, red NO-GO; a bar's height is the hour's reachable altitude (full height ${len(top)})` +
      (r.members > 1 ? "; under each hour, the share of members that go." : ".");
    sum.hidden = false;
  }

  // The plan's wind becomes the period's §9 wind; then the plan runs.
  function choose(r, i) {
    const h = r.hours[i];
    for (const b of $("windows-timeline").children) b.setAttribute("aria-pressed", String(b.dataset.index === String(i)));
    const form = document.getElementById("plan-form");
    const set = (name, v) => {
      const el = form.elements[name];
      if (!el) return;
      el.value = v == null ? "" : String(v);
      el.dispatchEvent(new Event("input", { bubbles: true }));
    };
    const f = h.wind.flow;
    set("wind.flow.kind", f.kind);
    form.elements["wind.flow.kind"].dispatchEvent(new Event("change", { bubbles: true }));
    if (f.kind === "power_law") {
      set("wind.flow.speed_m_s", f.coefficient_m_s);
      set("wind.flow.exponent_nondim", f.exponent_nondim);
      set("wind.flow.power_reference_height_m", f.reference_height_m);
    } else {
      set("wind.flow.speed_m_s", f.speed_m_s);
      if (f.kind === "log_law") {
        set("wind.flow.reference_height_m", f.reference_height_m);
        set("wind.flow.roughness_length_m", f.roughness_length_m);
      }
    }
    set("wind.gust.turbulence_intensity_nondim", "");
    set("wind.gust.peak_factor_nondim", "");
    set("wind.gust.gust_m_s", h.wind.gust?.gust_m_s ?? "");
    set("wind.air_density_kg_m3", h.wind.air_density_kg_m3);
    document.dispatchEvent(new CustomEvent("tetherplan:plan-request"));
  }

  async function readFile(file) {
    $("windows-data").value = await file.text();
    run();
  }
  $("windows-file").addEventListener("change", (e) => e.target.files[0] && readFile(e.target.files[0]));
  section.addEventListener("dragover", (e) => e.preventDefault());
  section.addEventListener("drop", (e) => {
    e.preventDefault();
    const f = e.dataTransfer?.files?.[0];
    if (f) readFile(f);
  });
  // A server given a forecast source (--forecast-url) fetches it on request.
  async function fetchForecast() {
    const err = $("windows-error");
    err.hidden = true;
    $("windows-fetch").disabled = true;
    const res = await S.api("GET", "api/v1/forecast");
    $("windows-fetch").disabled = false;
    if (!res.ok) {
      err.textContent = res.body?.error ? res.body.error.message : `error ${res.status}`;
      err.hidden = false;
      return;
    }
    const f = res.body.forecast;
    $("windows-data").value = typeof f.data === "string" ? f.data : JSON.stringify(f.data, null, 1);
    const when = new Date(1000 * res.body.fetched_at_unix_s).toLocaleTimeString();
    $("windows-source").textContent = `Fetched at ${when} from ${res.body.source_url}: ${res.body.period_count} periods` +
      (res.body.member_count > 1 ? `, ${res.body.member_count} members` : "") + ".";
    $("windows-source").hidden = false;
    run();
  }
  $("windows-fetch").addEventListener("click", fetchForecast);
  S.api("GET", "healthz").then((res) => {
    if (res.ok && res.body.forecast_source) $("windows-fetch").hidden = false;
  });
  $("windows-form").addEventListener("submit", (e) => {
    e.preventDefault();
    run();
  });
  window.tetherplanWindows = { run, choose: (i) => last && choose(last, i) };
})();
