// Browser test of the tether-dynamics panel (issue 23).
//
//   node tests/browser/dynamics_page.mjs http://127.0.0.1:8080/
//
// Opens a shared URL that carries the system card (Dyneema 6 mm, 2000 N,
// 100 kg, C_D 0.3 on 20 m², a uniform 8 m/s wind) and the panel's inputs
// (800 m, 40 s, a 1 − cos gust of +6 m/s over 8 s from t = 10 s): the panel
// runs at once. Checks what the operator sees: the peak winch tension shown
// is the API's for the same request and exceeds the start tension, the
// static tension at the largest wind is shown, the tension and altitude
// plots are drawn (uPlot canvases with ink on them), the animation frame
// advances (and pauses), the inputs are in the URL; then runs the peak
// distribution of 6 seeds and checks its figure and summary; then puts an
// invalid gust duration and checks the API's error beside its field.
// Screenshot: tests/artifacts/dynamics_page.png.

import path from "node:path";
import { checker, launch, target, watchConsole } from "./harness.mjs";

const { url, artifacts } = target("dynamics_page.mjs");
const { failures, check } = checker();
const browser = await launch();
const consoleErrors = [];
let phase = "load";

const card = {
  "cable.preset": "dyneema",
  "cable.diameter_m": "0.006",
  "aerostat.net_buoyancy_n": "2000",
  "aerostat.mass_kg": "100",
  "aerostat.drag_coefficient_nondim": "0.3",
  "aerostat.reference_area_m2": "20",
  "wind.flow.kind": "uniform",
  "wind.flow.speed_m_s": "8",
};
const panel = {
  "dynamics.tether_length_m": "800",
  "dynamics.duration_s": "40",
  "dynamics.wind.time_history.kind": "one_minus_cosine",
  "dynamics.wind.time_history.start_time_s": "10",
  "dynamics.wind.time_history.duration_s": "8",
  "dynamics.wind.time_history.amplitude_m_s": "6",
  "dynamics.numerics.segments": "30",
  "dynamics.numerics.time_step_s": "0.05",
  "dynamics.exposure_s": "60",
  "dynamics.samples": "6",
};

// Pixels of a canvas that are not blank (alpha > 0 and not white).
const ink = (page, selector) =>
  page.evaluate((sel) => {
    const c = document.querySelector(sel);
    if (!c || !c.width || !c.height) return 0;
    const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 0; i < d.length; i += 4) if (d[i + 3] > 0 && (d[i] < 240 || d[i + 1] < 240 || d[i + 2] < 240)) n++;
    return n;
  }, selector);

const settled = (page) =>
  page.waitForFunction(() => !document.querySelector("#dyn-button").disabled && document.querySelector("#dyn-status").dataset.state !== "busy", null, { timeout: 120_000 });

try {
  const context = await browser.newContext({ viewport: { width: 1280, height: 900 } });
  const page = await context.newPage();
  watchConsole(page, consoleErrors, () => phase);
  const query = new URLSearchParams({ ...card, ...panel }).toString();
  const response = await page.goto(`${url}?${query}`, { waitUntil: "load" });
  check(response && response.ok(), `GET the shared URL → ${response?.status()}`);

  phase = "gust";
  // The shared URL runs the panel at once.
  await page.waitForFunction(() => document.querySelector("#dyn-status").dataset.state === "ready" || document.querySelector("#dyn-status").dataset.state === "error", null, { timeout: 120_000 });
  check((await page.getAttribute("#dyn-status", "data-state")) === "ready", `the gust run is shown (status: ${await page.textContent("#dyn-status")})`);
  const state = await page.evaluate(() => ({ req: window.tetherplanDynamics.request, res: window.tetherplanDynamics.result }));
  check(state.req?.wind?.time_history?.kind === "one_minus_cosine" && state.req.wind.time_history.amplitude_m_s === 6, "the request carries the gust from the URL");
  check(state.req?.cable?.preset === "dyneema" && state.req?.aerostat?.net_buoyancy_n === 2000, "the request carries the system card");
  // The figure the operator reads is the API's answer for the same request.
  const api = await page.evaluate(async (req) => {
    const r = await fetch("/api/v1/dynamics", { method: "POST", headers: { "content-type": "application/json" }, body: JSON.stringify(req) });
    return r.json();
  }, state.req);
  const shown = await page.textContent("#dyn-peak");
  const shownN = Number(/([\d.]+) N/.exec(shown)?.[1]);
  check(Math.abs(shownN - api.peak_winch_tension_n) < 0.051, `peak winch tension shown ${shown} = API ${api.peak_winch_tension_n.toFixed(2)} N`);
  check(api.peak_winch_tension_n > api.quasi_static.start_winch_tension_n, `the gust raises the tension above the start (${api.quasi_static.start_winch_tension_n.toFixed(1)} N)`);
  const qs = await page.textContent("#dyn-qs");
  check(new RegExp(api.quasi_static.winch_tension_at_max_wind_n.toFixed(1)).test(qs), `static tension at the largest wind shown: ${qs}`);
  check(/\d/.test(await page.textContent("#dyn-factor")), `dynamic factor shown: ${await page.textContent("#dyn-factor")}`);

  // The plots are drawn.
  for (const id of ["dyn-tension-plot", "dyn-altitude-plot"]) {
    const info = await page.evaluate((i) => {
      const canvas = document.querySelector(`#${i} canvas`);
      return canvas ? { w: canvas.width, h: canvas.height } : null;
    }, id);
    check(info && info.w > 200 && info.h > 100, `${id} drawn (${info?.w}×${info?.h})`);
    check((await ink(page, `#${id} canvas`)) > 500, `${id} has curves on it`);
  }
  const series = await page.evaluate(() => document.querySelectorAll("#dyn-tension-plot .u-legend .u-series").length);
  check(series >= 4, `tension plot legend: winch, top and the static line (${series} entries)`);
  check((await ink(page, "#dyn-shape")) > 200, "the tether's shape is drawn");

  // The animation advances, and pauses.
  const f0 = await page.evaluate(() => window.tetherplanDynamics.framesShown);
  const t0 = await page.textContent("#dyn-frame-time");
  await page.waitForTimeout(1000);
  const f1 = await page.evaluate(() => window.tetherplanDynamics.framesShown);
  const t1 = await page.textContent("#dyn-frame-time");
  check(f1 > f0 + 3, `the animation advanced ${f1 - f0} frames in a second`);
  check(t1 !== t0 && /t = [\d.]+ s/.test(t1), `its time readout moved: “${t0}” → “${t1}”`);
  await page.click("#dyn-play");
  const p0 = await page.evaluate(() => window.tetherplanDynamics.framesShown);
  await page.waitForTimeout(500);
  const p1 = await page.evaluate(() => window.tetherplanDynamics.framesShown);
  check(p1 === p0, "Pause stops it");
  await page.click("#dyn-play");

  // The inputs are in the URL by their request paths (those that differ from the page's defaults).
  const href = await page.evaluate(() => window.location.search);
  check(/dynamics\.tether_length_m=800/.test(href) && /dynamics\.duration_s=40/.test(href) && /dynamics\.numerics\.segments=30/.test(href), `the panel's inputs are in the URL (${href.length} characters)`);
  await page.locator("#dynamics").screenshot({ path: path.join(artifacts, "dynamics_page.png") });

  phase = "peaks";
  await page.click("#dyn-peaks-button");
  await settled(page);
  check((await page.getAttribute("#dyn-status", "data-state")) === "ready", `peak distribution shown (status: ${await page.textContent("#dyn-status")})`);
  const peaks = await page.evaluate(() => window.tetherplanDynamics.peaks);
  check(peaks?.samples?.length === 6, `6 seeds sampled (${peaks?.samples?.length})`);
  check((await ink(page, "#dyn-peaks-plot")) > 300, "the peak distribution is drawn");
  const summary = await page.textContent("#dyn-peaks-summary");
  check(/50 %: [\d.]+ N/.test(summary) && /gust check/.test(summary), `percentiles and the gust check in words: ${summary.slice(0, 160)}…`);
  await page.locator("#dynamics").screenshot({ path: path.join(artifacts, "dynamics_page_peaks.png") });

  phase = "invalid";
  await page.fill("#dyn-gust-duration", "0");
  await page.click("#dyn-button");
  const err = page.locator(".field:has(#dyn-gust-duration) .field-error");
  await err.waitFor({ timeout: 30_000 });
  check((await err.getAttribute("data-error-for")) === "wind.time_history.duration_s", `error beside the gust duration: “${await err.textContent()}”`);
  check((await page.getAttribute("#dyn-status", "data-state")) === "error", "status says error");
  await context.close();

  const unexpected = consoleErrors.filter((e) => !(e.phase === "invalid" && /status of 4\d\d/.test(e.text)));
  for (const e of unexpected) console.log(`  console error (${e.phase}): ${e.text}`);
  check(unexpected.length === 0, `no console errors (${unexpected.length})`);
} catch (e) {
  console.error(`FAIL ${e.stack || e}`);
  failures.push(String(e));
} finally {
  await browser.close();
}

console.log(failures.length ? `${failures.length} check(s) failed` : "all browser checks passed");
console.log(`screenshot: ${path.join(artifacts, "dynamics_page.png")}`);
process.exit(failures.length ? 1 : 0);
