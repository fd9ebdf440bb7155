// Browser test of the live-flight panel on a server with API tokens:
//
//   TETHERPLAN_API_TOKENS=secret node tests/browser/live_token_page.mjs http://127.0.0.1:8080/
//
// (the server started with the same TETHERPLAN_API_TOKENS). The events route
// answers 401 without the token (EventSource could not send it); the page
// asks for the token once (window.prompt), starts a flight, and reads the
// events with fetch and the Authorization header. Telemetry posted by this
// script (with the token) turns the stoplight normal then caution (the
// flight's own thresholds); the stream is dropped, a batch is posted while
// it is down, and after the reconnect (Last-Event-ID) the page holds every
// stored sample exactly once and reads what the API says.

import { checker, launch, target, watchConsole } from "./harness.mjs";

const { url } = target("live_token_page.mjs");
const token = (process.env.TETHERPLAN_API_TOKENS || "").split(",")[0].trim();
const { failures, check } = checker();
const browser = await launch();
const consoleErrors = [];
let phase = "load";

async function api(method, p, body, auth = true) {
  const headers = body === undefined ? {} : { "content-type": "application/json" };
  if (auth) headers.authorization = `Bearer ${token}`;
  const res = await fetch(new URL(p, url), { method, headers, body: body === undefined ? undefined : JSON.stringify(body) });
  return { status: res.status, body: await res.json().catch(() => null) };
}
const lightIs = (page, state) =>
  page.waitForFunction((s) => {
    const l = document.querySelector("#live-light");
    return l.dataset.state === s && l.querySelector(".word").textContent.trim() === s;
  }, state, { timeout: 10_000 }).then(() => true, () => false);

try {
  check(token !== "", "a token in TETHERPLAN_API_TOKENS");
  const context = await browser.newContext({ viewport: { width: 1280, height: 900 } });
  const page = await context.newPage();
  watchConsole(page, consoleErrors, () => phase);
  let prompts = 0;
  page.on("dialog", (d) => {
    prompts++;
    d.accept(token);
  });
  await page.goto(url, { waitUntil: "load" });
  await page.fill('[name="cable.breaking_strength_n"]', "20000");
  await page.click("#plan-button");
  await page.waitForFunction(() => ["go", "no-go"].includes(document.querySelector("#verdict").dataset.state), null, { timeout: 60_000 });

  phase = "start";
  await page.click("#live-start");
  await page.waitForFunction(() => window.tetherplanLive?.flight != null, null, { timeout: 60_000 });
  const { id, kind } = await page.evaluate(() => ({ id: window.tetherplanLive.id, kind: window.tetherplanLive.stream?.kind }));
  check(prompts === 1, `the token asked for once (${prompts})`);
  check(kind === "fetch", `the events read with fetch and the token (${kind})`);
  const bare = await api("GET", `api/v1/flights/${id}/events`, undefined, false);
  check(bare.status === 401, `the events route without the token → ${bare.status}`);

  let t = 0;
  let sent = 0;
  async function replay(seconds, tension) {
    const samples = [];
    for (let k = 0; k < Math.round(seconds * 10); k++, t = Math.round(t * 10 + 1) / 10) {
      samples.push({ time_s: t, tether_length_m: 1 + 0.1 * t, winch_rate_m_s: 0.1, winch_tension_n: tension, wind_speed_m_s: 4 });
    }
    const r = await api("POST", `api/v1/flights/${id}/telemetry`, samples);
    if (r.status !== 200) throw new Error(`telemetry → ${r.status} ${JSON.stringify(r.body)}`);
    sent += samples.length;
    return r.body;
  }
  phase = "normal";
  const flight = (await api("GET", `api/v1/flights/${id}`)).body;
  await replay(0.1, flight.limits.net_buoyancy_n);
  const tc = (await api("GET", `api/v1/flights/${id}`)).body.checks.find((c) => c.name === "tension");
  let a = await replay(2, 0.5 * tc.caution_at);
  check((await lightIs(page, "normal")) && a.state === "normal", `at half the caution (${0.5 * tc.caution_at} N): page normal, API ${a.state}`);
  phase = "caution";
  a = await replay(2, 0.5 * (tc.caution_at + tc.stop_at));
  check((await lightIs(page, "caution")) && a.state === "caution", `between caution and stop: page caution, API ${a.state}`);

  phase = "drop";
  const before = await page.evaluate(() => window.tetherplanLive.reconnects || 0);
  await page.evaluate(() => window.tetherplanLive.stream.drop());
  a = await replay(1, 0.5 * (tc.caution_at + tc.stop_at));
  await page.waitForFunction((n) => (window.tetherplanLive.reconnects || 0) > n, before, { timeout: 10_000 });
  await page.waitForFunction((n) => window.tetherplanLive.samples.length >= n, sent, { timeout: 10_000 }).catch(() => {});
  await page.waitForTimeout(300);
  const stored = (await api("GET", `api/v1/flights/${id}`)).body;
  const held = await page.evaluate(() => ({ n: window.tetherplanLive.samples.length, distinct: new Set(window.tetherplanLive.samples.map((s) => s.seq)).size, state: document.querySelector("#live-light").dataset.state }));
  check(held.n === stored.samples_received && held.distinct === held.n && stored.samples_received === sent,
    `after a dropped stream: sent ${sent}, stored ${stored.samples_received}, on the page ${held.n} (${held.distinct} distinct)`);
  check(held.state === stored.state, `the page reads what the API says (${held.state}, ${stored.state})`);
  await context.close();

  for (const e of consoleErrors) console.log(`  console error (${e.phase}): ${e.text}`);
  // The page's first requests meet the 401 that asks for the token; the
  // dropped stream is the one this script aborted.
  const unexpected = consoleErrors.filter((e) => !(e.phase === "load" && /status of 401/.test(e.text)) && !(e.phase === "drop" && /events net::ERR_ABORTED/.test(e.text)));
  check(unexpected.length === 0, `no console errors but the first 401 (${unexpected.length})`);
} catch (e) {
  console.error(`FAIL ${e.stack || e}`);
  failures.push(String(e));
} finally {
  await browser.close();
}

console.log(failures.length ? `${failures.length} check(s) failed` : "all browser checks passed");
process.exit(failures.length ? 1 : 0);
