// Browser test of the live-flight panel and the page's units (issues 32, 33):
//
//   node tests/browser/live_page.mjs http://127.0.0.1:8080/
//
// The page starts a flight from the plan's inputs (a breaking strength of
// 20 000 N typed into the card, so the tension is checked); this script then
// replays a log by POSTing 10 Hz telemetry batches itself (node fetch). The
// thresholds are the flight's own (`checks`: tension caution_at, stop_at).
// The stoplight (#live-light: its word and data-state) must read what the
// API says at each step: unavailable before any sample; normal at half the
// caution; caution between caution and stop for 2 s (> the 1 s dwell); stop
// above the stop for 2 s; the stop latched through 7 s back at half the
// caution (< 0.9 × the thresholds, > the 5 s clear dwell) until the page's
// Acknowledge is clicked, then what the API says (normal). Silence: the
// flight was started with "no data after" 2 s, so the light turns
// unavailable 2 to 3 s after the last batch, and normal when samples resume.
// The page holds each sample once (as many as the API stored, distinct
// arrival numbers), also after a batch sent twice. Re-plan from now shows
// GET /replan's mode and current length. Units: knots and feet in the header
// change the shown figures by exactly 1852/3600 and 0.3048, the URL keeps
// them (`speed=kn&length=ft`) across a reload; the plan's verdict follows
// them too. Phone (390×844): no
// horizontal scrolling, the stoplight inside the first screen of the panel.
// Print: the panel alone. Screenshots: tests/artifacts/live_page*.png.

import path from "node:path";
import { checker, launch, target, watchConsole } from "./harness.mjs";

const { url, artifacts } = target("live_page.mjs");
const { failures, check } = checker();
const browser = await launch();
const consoleErrors = [];
let phase = "load";
const KNOT = 1852 / 3600;
const FOOT = 0.3048;

async function api(method, p, body) {
  const res = await fetch(new URL(p, url), {
    method,
    headers: body === undefined ? {} : { "content-type": "application/json" },
    body: body === undefined ? undefined : JSON.stringify(body),
  });
  return { status: res.status, body: await res.json().catch(() => null) };
}

const light = (page) =>
  page.evaluate(() => {
    const l = document.querySelector("#live-light");
    return { state: l.dataset.state, word: l.querySelector(".word").textContent.trim(), why: l.querySelector(".why").textContent.trim() };
  });
// Waits until the stoplight reads `state` (attribute and word); returns what it reads then.
async function lightReads(page, state, timeout = 10_000) {
  try {
    await page.waitForFunction((s) => {
      const l = document.querySelector("#live-light");
      return l.dataset.state === s && l.querySelector(".word").textContent.trim() === s;
    }, state, { timeout });
  } catch {
    /* reported by the caller's check */
  }
  return light(page);
}

// Linear interpolation in the committed schedule (clamped at its ends).
function interp(xs, ys, x) {
  if (x <= xs[0]) return ys[0];
  for (let i = 1; i < xs.length; i++) if (x <= xs[i]) return ys[i - 1] + ((ys[i] - ys[i - 1]) * (x - xs[i - 1])) / (xs[i] - xs[i - 1]);
  return ys.at(-1);
}

try {
  const context = await browser.newContext({ viewport: { width: 1280, height: 900 } });
  const page = await context.newPage();
  watchConsole(page, consoleErrors, () => phase);
  const response = await page.goto(url, { waitUntil: "load" });
  check(response && response.ok(), `GET / → ${response?.status()}`);
  await page.fill('[name="cable.breaking_strength_n"]', "20000");
  await page.click("#plan-button");
  await page.waitForFunction(() => ["go", "no-go"].includes(document.querySelector("#verdict").dataset.state), null, { timeout: 60_000 });

  phase = "start";
  await page.fill("#live-flight-name", "browser replay");
  await page.click("#live-start");
  await page.waitForFunction(() => window.tetherplanLive?.flight != null, null, { timeout: 60_000 });
  const { id, plan } = await page.evaluate(() => ({ id: window.tetherplanLive.id, plan: window.tetherplanLive.plan }));
  const flight = (await api("GET", `api/v1/flights/${id}`)).body;
  check(flight.name === "browser replay" && flight.limits.stale_after_s === 2, `the flight is the page's (“${flight.name}”, no data after ${flight.limits.stale_after_s} s)`);
  let seen = await lightReads(page, "unavailable");
  check(seen.state === "unavailable" && flight.state === "unavailable", `before any sample: page “${seen.word}”, API ${flight.state}`);

  // The log: 10 Hz from t, the schedule flown at a quarter of its pace
  // (length L(t/4), rate L'(t/4)/4: behind the plan, well inside the payout
  // ceiling).
  const K = 0.25;
  let t = 0;
  let lastPost = 0;
  const sent = [];
  async function replay(seconds, tensionN) {
    const samples = [];
    for (let k = 0; k < Math.round(seconds * 10); k++, t = Math.round(t * 10 + 1) / 10) {
      const length = interp(plan.t, plan.length, K * t);
      const rate = (interp(plan.t, plan.length, K * (t + 0.1)) - length) / 0.1;
      samples.push({ time_s: t, tether_length_m: length, winch_rate_m_s: rate, winch_tension_n: tensionN, wind_speed_m_s: 4 + 0.5 * Math.sin(t), aerostat_altitude_m: 0.95 * length });
    }
    sent.push(samples);
    const r = await api("POST", `api/v1/flights/${id}/telemetry`, samples);
    lastPost = Date.now();
    if (r.status !== 200) throw new Error(`telemetry → ${r.status} ${JSON.stringify(r.body)}`);
    return r.body;
  }
  async function step(what, seconds, tensionN, expect) {
    phase = what;
    const answer = await replay(seconds, tensionN);
    seen = await lightReads(page, expect);
    check(seen.state === expect && answer.state === expect,
      `${what}: ${tensionN.toFixed(0)} N for ${seconds} s → page “${seen.word}” (${seen.why}), API ${answer.state}`);
  }
  // The first sample pulls the net buoyancy; the thresholds are then known.
  await replay(0.1, flight.limits.net_buoyancy_n);
  const judged = (await api("GET", `api/v1/flights/${id}`)).body;
  const tension = judged.checks.find((c) => c.name === "tension");
  let caution = tension?.caution_at;
  let stop = tension?.stop_at;
  check(Math.abs(stop - 20000 / 5) < 1e-9 && Math.abs(caution - 0.8 * stop) < 1e-9,
    `tension thresholds from the flight: caution ${caution} N = 0.8 × stop ${stop} N = 20 000 N / 5`);
  check(plan && plan.t.length > 1, `the committed schedule kept for the corridor (${plan?.t.length} samples)`);
  await step("normal", 3, 0.5 * caution, "normal");
  await step("caution", 2, 0.5 * (caution + stop), "caution");
  await page.locator("#live").screenshot({ path: path.join(artifacts, "live_page_caution.png") });
  await step("stop", 2, 1.05 * stop, "stop");
  await page.locator("#live").screenshot({ path: path.join(artifacts, "live_page.png") });
  await step("back below 0.9 × caution, still latched", 7, 0.5 * caution, "stop");
  const latched = (await api("GET", `api/v1/flights/${id}`)).body;
  const stopAlarm = latched.alarms.find((a) => a.level === "stop");
  check(stopAlarm && stopAlarm.acknowledged_at_s == null, `the stop alarm is not acknowledged (${JSON.stringify(stopAlarm)})`);
  const alarmsText = await page.textContent("#live-alarms");
  check(/STOP Winch tension/.test(alarmsText) && /not acknowledged/.test(alarmsText), `the page lists the stop (“${alarmsText.replace(/\s+/g, " ").slice(0, 120)}”)`);
  check(!(await page.isDisabled("#live-ack")), "Acknowledge is enabled");

  phase = "acknowledge";
  await page.click("#live-ack");
  await page.waitForFunction(() => document.querySelector("#live-light").dataset.state !== "stop", null, { timeout: 10_000 }).catch(() => {});
  const afterAck = (await api("GET", `api/v1/flights/${id}`)).body;
  seen = await light(page);
  check(afterAck.state === "normal" && seen.state === afterAck.state && seen.word === afterAck.state,
    `after Acknowledge: page “${seen.word}”, API ${afterAck.state}`);

  phase = "silence";
  seen = await lightReads(page, "unavailable", 8_000);
  const delay = (Date.now() - lastPost) / 1000;
  check(seen.state === "unavailable" && delay >= 1.9, `silence: “${seen.word}” ${delay.toFixed(1)} s after the last batch (${seen.why})`);
  const silent = (await api("GET", `api/v1/flights/${id}`)).body;
  check(silent.state === "unavailable", `the API says ${silent.state} too`);
  await step("samples resume", 2, 0.5 * caution, "normal");

  phase = "once each";
  const again = await api("POST", `api/v1/flights/${id}/telemetry`, sent.at(-1));
  await page.waitForTimeout(300);
  const stored = (await api("GET", `api/v1/flights/${id}`)).body.samples_received;
  const held = await page.evaluate(() => ({ n: window.tetherplanLive.samples.length, distinct: new Set(window.tetherplanLive.samples.map((s) => s.seq)).size }));
  const total = sent.reduce((n, b) => n + b.length, 0);
  check(again.body.duplicates === sent.at(-1).length && held.n === stored && held.distinct === held.n && stored === total,
    `each sample once: sent ${total} (+1 batch again: ${again.body.duplicates} duplicates), stored ${stored}, on the page ${held.n} (${held.distinct} distinct)`);
  const traced = await page.$eval("#live-corridor path.flight", (p) => Number(p.dataset.points));
  check(traced === stored && (await page.$$("#live-corridor path.plan")).length === 1 && (await page.$$("#live-tension line.level")).length === 2,
    `the corridor: the plan and ${traced} flight points; the tension with its caution and stop lines`);

  phase = "replan";
  await page.click("#live-replan");
  await page.waitForFunction(() => !document.querySelector("#live-replan-out").hidden, null, { timeout: 60_000 });
  const rp = (await api("GET", `api/v1/flights/${id}/replan`)).body;
  const rpText = await page.textContent("#live-replan-out");
  const mode = rp.mode === "haul_down" ? "HAUL DOWN" : "CONTINUE";
  check(rpText.includes(mode) && rpText.includes(`From ${rp.current_length_m.toFixed(1)} m`), `re-plan shown: ${mode} from ${rp.current_length_m.toFixed(1)} m (“${rpText.slice(0, 100)}”)`);

  phase = "units";
  const figures = () => page.$$eval("#live-latest dd", (dds) => Object.fromEntries(dds.map((d) => [d.dataset.figure, { text: d.textContent, si: Number(d.dataset.si) }])));
  let f = await figures();
  check(f.tether.text === `${f.tether.si.toFixed(1)} m` && f.wind.text === `${f.wind.si.toFixed(1)} m/s`, `in SI: tether ${f.tether.text}, wind ${f.wind.text}`);
  // The plan's verdict too: the tether needed and the wind in its headline.
  const verdict = () => page.evaluate(() => ({
    needed: document.querySelector('#verdict dd[data-figure="Tether needed"]').firstChild.textContent,
    why: document.querySelector("#verdict .why").textContent,
    lengthSi: window.tetherplanPlan.plan.wind.target_length_m,
    windSi: window.tetherplanPlan.request.wind.flow.speed_m_s,
  }));
  let v = await verdict();
  check(v.needed === `${v.lengthSi.toFixed(1)} m` && v.why.includes(`${v.windSi.toFixed(1)} m/s wind`), `the verdict in SI: tether needed ${v.needed}, “${v.why.slice(0, 70)}…”`);
  await page.selectOption("#units-speed", "kn");
  await page.selectOption("#units-length", "ft");
  v = await verdict();
  check(v.needed === `${(v.lengthSi / FOOT).toFixed(1)} ft` && v.why.includes(`${(v.windSi / KNOT).toFixed(1)} kn wind`),
    `the verdict in knots and feet: tether needed ${v.lengthSi.toFixed(3)} m shown “${v.needed}”, wind ${v.windSi} m/s shown “${(v.windSi / KNOT).toFixed(1)} kn” (“${v.why.slice(0, 70)}…”)`);
  const inKnotsFeet = async (when) => {
    f = await figures();
    const ft = (f.tether.si / FOOT).toFixed(1);
    const kn = (f.wind.si / KNOT).toFixed(1);
    check(f.tether.text === `${ft} ft` && f.wind.text === `${kn} kn` && f.rate.text === `${(f.rate.si / FOOT).toFixed(2)} ft/s`,
      `${when}: tether ${f.tether.si.toFixed(3)} m shown “${f.tether.text}” (÷ 0.3048), wind ${f.wind.si.toFixed(3)} m/s shown “${f.wind.text}” (÷ 1852/3600), rate “${f.rate.text}”`);
  };
  await inKnotsFeet("knots and feet");
  const q = new URL(page.url()).searchParams;
  check(q.get("speed") === "kn" && q.get("length") === "ft", `units in the URL (${page.url().split("?")[1]?.slice(0, 80)}…)`);
  await page.reload({ waitUntil: "load" });
  check((await page.inputValue("#units-speed")) === "kn" && (await page.inputValue("#units-length")) === "ft", "after a reload the header says knots and feet");
  await page.waitForFunction((id) => [...document.querySelectorAll("#live-flights option")].some((o) => o.value === String(id)), id, { timeout: 10_000 });
  await page.selectOption("#live-flights", String(id));
  await page.click("#live-open");
  await page.waitForFunction(() => document.querySelectorAll("#live-latest dd").length > 0, null, { timeout: 10_000 });
  await inKnotsFeet("after the reload");
  await page.screenshot({ path: path.join(artifacts, "live_page_1280.png"), fullPage: false });

  phase = "print";
  await page.evaluate(() => (document.body.dataset.print = "live"));
  await page.emulateMedia({ media: "print" });
  const shown = await page.evaluate(() => ["#live", "#plan", "#verdict-panel", "#live-form"].map((s) => getComputedStyle(document.querySelector(s)).display !== "none"));
  check(shown.join() === "true,false,false,false", `print: the panel alone, without its form (${shown.join(", ")})`);
  await page.emulateMedia({ media: "screen" });
  await context.close();

  phase = "phone";
  const phone = await browser.newContext({ viewport: { width: 390, height: 844 }, deviceScaleFactor: 2, isMobile: true, hasTouch: true });
  const small = await phone.newPage();
  watchConsole(small, consoleErrors, () => phase);
  await small.goto(`${url}?speed=kn&length=ft`, { waitUntil: "load" });
  await small.waitForFunction((id) => [...document.querySelectorAll("#live-flights option")].some((o) => o.value === String(id)), id, { timeout: 10_000 });
  await small.selectOption("#live-flights", String(id));
  await small.click("#live-open");
  await small.waitForFunction(() => document.querySelector("#live-light").dataset.state !== "none", null, { timeout: 10_000 });
  // a new browser holds no copy of the plan: it is read from GET …/plan
  const planLine = await small.evaluate(() => ({
    note: document.querySelector("#live-plan-note").hidden,
    points: Number(document.querySelector("#live-corridor path.line.plan")?.dataset.points || 0),
  }));
  check(planLine.note && planLine.points > 1, `a flight opened in another browser draws its committed plan (${planLine.points} points, from GET …/plan)`);
  await small.evaluate(() => document.querySelector("#live").scrollIntoView({ block: "start" }));
  const fit = await small.evaluate(() => ({ overflow: document.documentElement.scrollWidth - window.innerWidth, bottom: document.querySelector("#live-light").getBoundingClientRect().bottom, h: window.innerHeight }));
  check(fit.overflow <= 0, `no horizontal scrolling at 390 px (overflow ${fit.overflow} px)`);
  check(fit.bottom <= fit.h, `the stoplight inside the panel's first screen (bottom ${fit.bottom.toFixed(0)} of ${fit.h} px)`);
  await small.screenshot({ path: path.join(artifacts, "live_page_390.png"), fullPage: false });
  await small.locator("#live").screenshot({ path: path.join(artifacts, "live_page_390_panel.png") });
  await phone.close();

  for (const e of consoleErrors) console.log(`  console error (${e.phase}): ${e.text}`);
  check(consoleErrors.length === 0, `no console errors (${consoleErrors.length})`);
} catch (e) {
  console.error(`FAIL ${e.stack || e}`);
  failures.push(String(e));
} finally {
  await browser.close();
}

console.log(failures.length ? `${failures.length} check(s) failed` : "all browser checks passed");
process.exit(failures.length ? 1 : 0);
