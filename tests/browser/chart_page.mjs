// Browser test of the deployment-chart page.
//
//   node tests/browser/chart_page.mjs http://127.0.0.1:8080/
//
// Drives Debian's Chromium (/usr/bin/chromium, or $CHROMIUM) with playwright-core
// (no browser download). Loads the page, submits the default form, waits for the
// plotted curves, checks h* at 10 m/s for F = 1000 N against the thesis value
// (≈ 1310 m), downloads the CSV, submits one invalid input and checks that the
// API's error appears next to that field, runs the safe-rate calculator, repeats
// the chart at phone width (375 px), and fails on any console error. Screenshots
// go to tests/artifacts/ (chart_page.png, chart_page_375.png).
// Exit status 0 on success, 1 on a failed check, 2 on bad usage.

import { readFileSync } from "node:fs";
import path from "node:path";
import { checker, launch, target, watchConsole } from "./harness.mjs";

const { url, artifacts } = target("chart_page.mjs");

// F = 1000 N, ρA = 0.078 kg/m, m = 10 kg, L0 = 1 m, v = 10 m/s: the page asks
// for converged answers, so h* is the continuum (F/ρA − v²)/g = 1296.69 m
// (the 50-element mesh gave 1310, 1 % high).
const EXPECTED_H_M = 1296.69;
const TOLERANCE = 0.001;

const { failures, check } = checker();

const browser = await launch();

// Console errors and page errors, with the phase they happened in. The invalid-input
// phase expects the browser's own "Failed to load resource: … status of 422" line.
const consoleErrors = [];
let phase = "load";
const watch = (page) => watchConsole(page, consoleErrors, () => phase);

// Reads the plotted data back from the uPlot instances the page exposes.
async function plotted(page) {
  return page.evaluate(() => {
    const { time, elevation } = window.tetherplan.plots;
    const pick = (u) => ({ labels: u.series.map((s) => s.label), data: u.data.map((a) => Array.from(a)) });
    return { time: pick(time), elevation: pick(elevation), series: window.tetherplan.chart.series.length };
  });
}

async function submitDefaultChart(page) {
  await page.click("#plot-button");
  await page.waitForSelector('#status[data-state="ready"], #status[data-state="error"]', { timeout: 60_000 });
  const state = await page.getAttribute("#status", "data-state");
  check(state === "ready", `chart computed (status: ${await page.textContent("#status")})`);
  return state === "ready";
}

let exitCode = 0;
try {
  // ---------- desktop width ----------
  const context = await browser.newContext({ viewport: { width: 1100, height: 1400 }, acceptDownloads: true });
  const page = await context.newPage();
  watch(page);
  const response = await page.goto(url, { waitUntil: "load" });
  check(response && response.ok(), `GET ${url} → ${response?.status()}`);
  check((await page.title()).includes("go or no-go"), "page title names the launch decision");

  phase = "chart";
  if (await submitDefaultChart(page)) {
    const p = await plotted(page);
    const buoyancies = (await page.inputValue("#buoyancies")).split(",").length;
    check(p.series === buoyancies && buoyancies === 3, `one series per buoyancy (${p.series} of ${buoyancies})`);
    // x + (model, closed form) per buoyancy, in both plots.
    check(p.elevation.data.length === 1 + 2 * p.series, `h* plot has ${p.elevation.data.length - 1} curves`);
    check(p.time.data.length === 1 + 2 * p.series, `t* plot has ${p.time.data.length - 1} curves`);
    const canvases = await page.locator(".plot-area canvas").count();
    check(canvases === 2, `two plot canvases drawn (${canvases})`);

    const x = p.elevation.data[0];
    const i = x.findIndex((v) => Math.abs(v - 10) < 1e-9);
    const col = p.elevation.labels.findIndex((l) => /^h\*, 1000 N \(m\)$/.test(l));
    check(i >= 0 && col > 0, `10 m/s on the rate axis (index ${i}) and an h* curve for 1000 N (series ${col})`);
    if (i >= 0 && col > 0) {
      const h = p.elevation.data[col][i];
      const rel = Math.abs(h - EXPECTED_H_M) / EXPECTED_H_M;
      check(rel <= TOLERANCE, `h*(10 m/s, 1000 N) = ${h.toFixed(1)} m, thesis ≈ ${EXPECTED_H_M} m (off by ${(rel * 100).toFixed(2)} %)`);
      const cf = p.elevation.data[col + 1][i];
      check(Math.abs(cf - 1296.7) < 1, `closed-form h(10 m/s, 1000 N) = ${cf.toFixed(1)} m ≈ (F/ρA − v²)/g = 1296.7 m`);
      const dashed = await page.evaluate((c) => Array.isArray(window.tetherplan.plots.elevation.series[c + 1].dash), col);
      check(dashed, "closed-form curve is dashed");
    }
    const legend = await page.textContent("#plot-elevation .u-legend");
    check(/\(m\)/.test(legend) && /\(m\/s\)/.test(legend), "legend labels carry units");

    // CSV download: header and one row per point.
    const [download] = await Promise.all([page.waitForEvent("download"), page.click("#download-csv")]);
    const csvPath = path.join(artifacts, "chart_page.csv");
    await download.saveAs(csvPath);
    const all = readFileSync(csvPath, "utf8").trim().split("\n");
    const comments = all.filter((l) => l.startsWith("#"));
    check(comments.some((l) => l.startsWith("# input cable.mass_per_length_kg_m,0.078")) && comments.some((l) => l.startsWith("# input rates_m_s.count,100")),
      "CSV records the inputs");
    const csv = all.filter((l) => !l.startsWith("#"));
    const significant = (t) => t.replace(/^[-+]?/, "").replace(/e.*$/i, "").replace(".", "").replace(/^0+/, "").length;
    const tooLong = csv.filter((l) => !l.startsWith("#")).flatMap((l) => l.split(",")).filter((t) => /^[-+]?\d*\.?\d+(e[-+]?\d+)?$/i.test(t) && significant(t) > 6);
    check(tooLong.length === 0, `CSV numbers have at most six significant digits (${tooLong.slice(0, 3).join(" ")})`);
    check(csv[0] === "net_buoyancy_n,rate_m_s,critical_time_s,max_elevation_m,closed_form_elevation_m", "CSV header");
    check(csv.length === 1 + 300, `CSV has ${csv.length - 1} rows (3 × 100 points)`);
    const [png] = await Promise.all([page.waitForEvent("download"), page.click("#download-png")]);
    await png.saveAs(path.join(artifacts, "chart_page_download.png"));
    check(png.suggestedFilename().endsWith(".png"), `PNG download (${png.suggestedFilename()})`);
  }

  phase = "safe-rate";
  await page.click("#safe-button");
  await page.waitForSelector("#safe-result:not([hidden]), #safe-error:not([hidden])", { timeout: 30_000 });
  const maxRate = Number(await page.getAttribute("#safe-result", "data-max-rate"));
  check(maxRate > 0 && maxRate < 113.2, `safe rate to the plan's 900 m: ${maxRate.toFixed(2)} m/s (below the wave speed 113.2 m/s)`);

  await page.screenshot({ path: path.join(artifacts, "chart_page.png"), fullPage: true });

  // ---------- one invalid input: the API's error shows next to the field ----------
  phase = "invalid";
  await page.fill("#mass-per-length", "-0.078");
  await page.click("#plot-button");
  const fieldError = page.locator('#mass-per-length ~ .field-error, .field:has(#mass-per-length) .field-error');
  await fieldError.first().waitFor({ timeout: 30_000 });
  const msg = await fieldError.first().textContent();
  const errorFor = await fieldError.first().getAttribute("data-error-for");
  check(errorFor === "cable.mass_per_length_kg_m" && /greater than zero|positive|must be between/.test(msg), `error for ${errorFor} next to ρA: “${msg}”`);
  check((await page.getAttribute("#mass-per-length", "aria-invalid")) === "true", "ρA input marked invalid");
  check((await page.getAttribute("#status", "data-state")) === "error", "status shows the error");
  await page.screenshot({ path: path.join(artifacts, "chart_page_error.png"), fullPage: false });
  await page.fill("#mass-per-length", "0.078");
  check((await fieldError.count()) === 0, "error clears when the field is edited");

  // An error inside the buoyancy list (`net_buoyancies_n[1]`) lands on the list input.
  await page.fill("#buoyancies", "500, -1000");
  await page.click("#plot-button");
  const listError = page.locator(".field:has(#buoyancies) .field-error");
  await listError.waitFor({ timeout: 30_000 });
  check((await listError.getAttribute("data-error-for")) === "net_buoyancies_n[1]" && /^entry 2:/.test(await listError.textContent()), `error for net_buoyancies_n[1] next to the buoyancy list: “${await listError.textContent()}”`);
  await page.fill("#buoyancies", "500, 1000, 2000");

  // The safe rate goes to the plan's target altitude: its error lands there.
  await page.fill("#plan-target", "-5");
  await page.click("#safe-button");
  const targetError = page.locator(".field:has(#plan-target) .field-error");
  await targetError.waitFor({ timeout: 30_000 });
  check((await targetError.getAttribute("data-error-for")) === "target_elevation_m", `error next to the target elevation: “${await targetError.textContent()}”`);
  await context.close();

  // ---------- a large chart runs as a job, with progress ----------
  phase = "job";
  {
    const jobs = await browser.newContext({ viewport: { width: 900, height: 1000 } });
    const jp = await jobs.newPage();
    watch(jp);
    await jp.goto(url, { waitUntil: "load" });
    await jp.fill("#rate-count", "2000"); // 3 × 2000 points × 50 elements: above the page's job threshold
    check(/background job/.test(await jp.textContent("#points-hint")), `hint announces a job: “${await jp.textContent("#points-hint")}”`);
    // A submission the server refuses: its error (`request.cable.…`) lands on the ρA input.
    phase = "invalid";
    await jp.fill("#mass-per-length", "0");
    await jp.click("#plot-button");
    const jobError = jp.locator(".field:has(#mass-per-length) .field-error");
    await jobError.waitFor({ timeout: 30_000 });
    check((await jobError.getAttribute("data-error-for")) === "cable.mass_per_length_kg_m", `job submission error next to ρA: “${await jobError.textContent()}”`);
    await jp.fill("#mass-per-length", "0.078");
    phase = "job";
    await jp.click("#plot-button");
    await jp.waitForSelector("#job:not([hidden])", { timeout: 10_000 }).catch(() => {});
    await jp.waitForSelector('#status[data-state="ready"], #status[data-state="error"]', { timeout: 120_000 });
    const j = await jp.evaluate(() => ({ via: window.tetherplan.via, progress: window.tetherplan.jobProgress, n: window.tetherplan.chart?.series.reduce((a, s) => a + s.points.length, 0) }));
    check((await jp.getAttribute("#status", "data-state")) === "ready", `job chart computed (status: ${await jp.textContent("#status")})`);
    check(/^job /.test(j.via ?? "") && j.n === 6000, `chart came from a ${j.via} with ${j.n} points`);
    const last = j.progress.at(-1);
    check(j.progress.length > 0 && last[0] === "done" && last[1] === 1, `job progress reported (${j.progress.map(([s, p]) => `${s} ${p.toFixed(2)}`).join(", ")})`);
    check(await jp.isHidden("#job"), "progress bar hidden once the job is done");
    await jobs.close();
  }

  // ---------- GE cable beside the string ----------
  {
    phase = "ge";
    const geContext = await browser.newContext({ viewport: { width: 1100, height: 1400 } });
    const gp = await geContext.newPage();
    watch(gp);
    await gp.goto(url, { waitUntil: "load" });
    await gp.fill("#rate-min", "40");
    await gp.fill("#rate-count", "10");
    await gp.fill("#buoyancies", "1000");
    await gp.check("#ge-enabled");
    await gp.fill("#ge-count", "3");
    await gp.fill("#ge-ratios", "1e3, 1e5");
    await gp.click("#plot-button");
    // While the GE job runs, the finished string chart is the current answer: not dimmed.
    await gp.waitForSelector("#job:not([hidden])", { timeout: 60_000 }).catch(() => {});
    const dimmed = await gp.evaluate(() => ({ job: !document.querySelector("#job").hidden, stale: document.querySelector("#results").hasAttribute("data-stale"), string: !!window.tetherplan.chart }));
    check(dimmed.job && dimmed.string && !dimmed.stale, `the finished string chart is not dimmed while the GE job runs (job shown ${dimmed.job}, stale ${dimmed.stale})`);
    await gp.waitForSelector("#ge-time-figure:not([hidden])", { timeout: 120_000 }).catch(() => {});
    await gp.waitForSelector('#status[data-state="ready"], #status[data-state="error"]', { timeout: 120_000 });
    const g = await gp.evaluate(() => ({
      series: window.tetherplan.ge?.series.map((s) => [s.stiffness_ratio, s.points.map((p) => p.max_elevation_m)]),
      curves: window.tetherplan.plots.geElevation?.series.length,
      string: window.tetherplan.chart?.series[0].points.at(-1).max_elevation_m,
    }));
    check(g.series?.length === 2 && g.series.every(([, h]) => h.length === 3), `GE chart: one series per E* (${JSON.stringify(g.series?.map(([e]) => e))})`);
    check(g.curves === 4, `GE plot: the string curve and two GE curves (${g.curves ? g.curves - 1 : 0})`);
    const hGe = g.series?.[1][1][2];
    // near the wave speed the short stiff cable holds on longer (bending): above the string, within 50 %
    check(hGe > g.string && hGe < g.string * 1.5, `GE h*(100 m/s, E* = 1e5) = ${hGe?.toFixed(1)} m, above the string h* ${g.string?.toFixed(1)} m`);
    // E* = 1e3 and 1e5 do not hide each other: distinct widths, dashes and markers.
    const styles = await gp.evaluate(() => window.tetherplan.plots.geElevation.series.slice(1).map((s) => ({ label: s.label, width: s.width, dash: s.dash ?? null, marker: s.points?.show ? s.points.size : 0 })));
    const geStyles = styles.filter((s) => /^GE/.test(s.label));
    check(geStyles.length === 2 && geStyles[0].width > geStyles[1].width && geStyles[0].marker > geStyles[1].marker && JSON.stringify(geStyles[0].dash) !== JSON.stringify(geStyles[1].dash),
      `GE curves distinct: ${geStyles.map((s) => `${s.label} width ${s.width} marker ${s.marker} dash ${JSON.stringify(s.dash)}`).join("; ")}`);
    check(/string FE model/.test(styles.at(-1)?.label ?? "") && Array.isArray(styles.at(-1).dash), "the dashed curve is the string FE model, drawn last");
    check(/not a closed form/.test(await gp.textContent("#ge-time-figure figcaption")), "caption: the dashed line is the string model, not a closed form");
    check(!/–/.test(await gp.textContent("#plot-ge-time .u-legend")), "GE legend blank until hovered (no “–”)");
    // A log t* axis.
    await gp.check("#ge-log-time");
    check(await gp.evaluate(() => window.tetherplan.plots.geTime.scales.y.distr === 3), "GE t* on a log axis when asked");
    // GE CSV with the inputs, six significant digits at most; GE PNG.
    const [geCsv] = await Promise.all([gp.waitForEvent("download"), gp.click("#ge-csv")]);
    const geCsvPath = path.join(artifacts, "chart_page_ge.csv");
    await geCsv.saveAs(geCsvPath);
    const geLines = readFileSync(geCsvPath, "utf8").trim().split("\n");
    check(["# input ge.stiffness_ratios,1000 100000", "# input ge.model.elements,20", "# input ge.rates_m_s.count,3", "# input string.net_buoyancies_n,1000"].every((l) => geLines.includes(l)),
      "GE CSV records the GE and string inputs");
    const geRows = geLines.filter((l) => !l.startsWith("#"));
    check(geRows.length === 1 + 6 + 10 && geRows[0].startsWith("model,stiffness_ratio"), `GE CSV: header and ${geRows.length - 1} rows (2 × 3 GE points, 10 string points)`);
    const sigDigits = (t) => t.replace(/^[-+]/, "").replace(/e.*$/i, "").replace(".", "").replace(/^0+/, "").length;
    const geLong = geRows.slice(1).flatMap((l) => l.split(",")).filter((t) => /^[-+]?\d*\.?\d+(e[-+]?\d+)?$/i.test(t) && sigDigits(t) > 6);
    check(geLong.length === 0, `GE CSV numbers have at most six significant digits (${geLong.slice(0, 3).join(" ")})`);
    const [gePng] = await Promise.all([gp.waitForEvent("download"), gp.click("#ge-png")]);
    await gePng.saveAs(path.join(artifacts, "chart_page_ge_download.png"));
    check(gePng.suggestedFilename() === "ge-deployment-chart.png", `GE PNG download (${gePng.suggestedFilename()})`);
    await gp.screenshot({ path: path.join(artifacts, "chart_page_ge.png"), fullPage: true });
    await geContext.close();
  }

  // ---------- phone width ----------
  phase = "phone";
  const phone = await browser.newContext({ viewport: { width: 375, height: 800 }, deviceScaleFactor: 2, isMobile: true, hasTouch: true });
  const small = await phone.newPage();
  watch(small);
  await small.goto(url, { waitUntil: "load" });
  if (await submitDefaultChart(small)) {
    const overflow = await small.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
    check(overflow <= 0, `no horizontal scrolling at 375 px (overflow ${overflow} px)`);
    const widths = await small.evaluate(() => [...document.querySelectorAll(".plot-area .uplot")].map((e) => e.getBoundingClientRect().width));
    check(widths.length === 2 && widths.every((w) => w <= 375 && w >= 250), `plots fit the phone width (${widths.map((w) => w.toFixed(0)).join(", ")} px)`);
  }
  await small.screenshot({ path: path.join(artifacts, "chart_page_375.png"), fullPage: true });
  await phone.close();

  // ---------- console ----------
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
console.log(`screenshots: ${path.join(artifacts, "chart_page.png")}, chart_page_375.png`);
exitCode = failures.length ? 1 : 0;
process.exit(exitCode);
