// Browser test of the deployment plan, the first section of the page.
//
//   node tests/browser/plan_page.mjs http://127.0.0.1:8080/
//
// Opens the page (it plans the defaults at once: thesis data to 1200 m at
// 40 m/s, 2 m/s², 5 % reserve), checks the go verdict, the duration against
// the SPEC §7 bound (50.0 s), the four plots and the operator's table; checks
// the print layout (print media: the plan alone, the inputs recorded, the
// thesis analyses hidden) and its page count; changes the target, checks that
// the URL carries the inputs, and reopens that URL in a fresh page: the same
// plan. A target beyond the lift limit gives a no-go naming it. Then the phone
// width (375 px). Screenshots: plan_page.png, plan_page_print.png,
// plan_page_print.pdf, plan_page_375*.png in tests/artifacts/.

import path from "node:path";
import { checker, launch, target, watchConsole } from "./harness.mjs";

const { url, artifacts } = target("plan_page.mjs");
const { failures, check } = checker();
const browser = await launch();
const consoleErrors = [];
let phase = "load";

async function waitPlan(page) {
  await page.waitForSelector('#plan-status[data-state="ready"], #plan-status[data-state="error"]', { timeout: 60_000 });
  return page.evaluate(() => window.tetherplan?.plan ?? null);
}

let exitCode = 0;
try {
  const context = await browser.newContext({ viewport: { width: 1100, height: 1400 }, acceptDownloads: true });
  const page = await context.newPage();
  watchConsole(page, consoleErrors, () => phase);
  const response = await page.goto(url, { waitUntil: "load" });
  check(response && response.ok(), `GET ${url} → ${response?.status()}`);

  phase = "default plan";
  const firstSection = await page.evaluate(() => document.querySelector("main > section")?.id);
  check(firstSection === "plan", `the page opens on the plan (first section: ${firstSection})`);
  const plan = await waitPlan(page);
  check(plan && plan.feasible && plan.go, `default plan is a go (${plan?.reason})`);
  if (plan) {
    check(Math.abs(plan.duration_s - 50.0) < 0.05, `duration ${plan.duration_s?.toFixed(3)} s ≈ 50.0 s (SPEC §7 bound)`);
    const verdict = (await page.textContent("#plan-verdict .word"))?.trim();
    check(verdict === "GO", `verdict shows GO (${verdict})`);
    const canvases = await page.locator("#plan-output .plan-plot-area canvas").count();
    check(canvases === 4, `four plan plots drawn (${canvases})`);
    const phases = await page.locator("#plan-phases tbody tr").count();
    check(phases === plan.phases.length && phases === 3, `operator's table has one row per phase (${phases})`);
    const rows = await page.locator("#plan-table tbody tr").count();
    check(rows === plan.schedule.length, `schedule table has every sample (${rows})`);
    const saved = await page.textContent("#plan-figures");
    check(/Time saved/.test(saved) && /Haul-down/.test(saved), "figures list the time saved and the haul-down deadline");
    const csvDownload = page.waitForEvent("download");
    await page.click("#plan-csv");
    const csvPath = await (await csvDownload).path();
    const csv = csvPath ? (await import("node:fs")).readFileSync(csvPath, "utf8") : "";
    check(csv.includes("# input winch.max_rate_m_s,40") && csv.includes("# input lift_reserve_nondim,0.05"),
      "CSV records the inputs");
    check(!/\d\.\d{7,}/.test(csv), "CSV numbers are rounded");
  }
  await page.screenshot({ path: path.join(artifacts, "plan_page.png"), fullPage: false });

  phase = "print";
  await page.emulateMedia({ media: "print" });
  const print = await page.evaluate(() => {
    const vis = (sel) => {
      const el = document.querySelector(sel);
      return !!el && getComputedStyle(el).display !== "none" && el.offsetParent !== null;
    };
    return {
      form: vis("#plan-form"),
      chart: vis("#chart-form"),
      transient: vis("#transient"),
      inputs: vis("#plan-inputs"),
      table: vis("#plan-phases"),
      inputsText: document.querySelector("#plan-inputs")?.textContent ?? "",
    };
  });
  check(!print.form && !print.chart && !print.transient, "print hides the forms and the thesis analyses");
  check(print.inputs && print.table, "print shows the inputs and the operator's table");
  check(["target_elevation_m", "winch.max_acceleration_m_s2", "cable.mass_per_length_kg_m", "lift_reserve_nondim", "haul_down.max_operating_wind_m_s"]
    .every((k) => print.inputsText.includes(k)), "print records every input");
  await page.screenshot({ path: path.join(artifacts, "plan_page_print.png"), fullPage: true });
  await page.emulateMedia({ media: "screen" });
  const pdfPage = await context.newPage();
  await pdfPage.goto(page.url(), { waitUntil: "load" });
  await waitPlan(pdfPage);
  const pdf = await pdfPage.pdf({ path: path.join(artifacts, "plan_page_print.pdf"), format: "A4", printBackground: true });
  const pages = (pdf.toString("latin1").match(/\/Type\s*\/Page[^s]/g) || []).length;
  check(pages >= 1 && pages <= 2, `print layout fits one or two A4 pages (${pages})`);
  await pdfPage.close();

  phase = "shared URL";
  await page.fill("#plan-target", "1000");
  await page.fill("#plan-reserve", "0.08");
  await page.click("#plan-button");
  await page.waitForFunction(() => window.tetherplan?.plan?.inputs?.target_elevation_m === 1000, null, { timeout: 60_000 });
  const changed = await waitPlan(page);
  const shared = page.url();
  check(shared.includes("plan.target_elevation_m=1000") && shared.includes("plan.lift_reserve_nondim=0.08"),
    `URL carries the inputs (${shared.slice(0, 120)}…)`);
  const again = await context.newPage();
  watchConsole(again, consoleErrors, () => phase);
  await again.goto(shared, { waitUntil: "load" });
  const reopened = await waitPlan(again);
  check(reopened && changed && reopened.duration_s === changed.duration_s && reopened.schedule.length === changed.schedule.length,
    `the shared URL reopens the same plan (${reopened?.duration_s} s vs ${changed?.duration_s} s)`);
  check((await again.inputValue("#plan-target")) === "1000", "the shared URL restores the form");
  await again.close();

  phase = "bands";
  await page.check("#plan-bands-on");
  await page.fill("#plan-bands-samples", "300");
  await page.click("#plan-button");
  await page.waitForFunction(() => window.tetherplan?.planBands?.instants?.length > 0, null, { timeout: 60_000 });
  const withBands = await page.evaluate(() => {
    const b = window.tetherplan.planBands;
    const plan = window.tetherplan.plan;
    const plots = window.tetherplan.planPlots;
    return {
      aligned: b.instants.length === plan.schedule.length,
      ordered: b.instants.every((x) => x.winch_tension_n.p05 <= x.winch_tension_n.p50 && x.winch_tension_n.p50 <= x.winch_tension_n.p95),
      around: b.instants.every((x, i) => x.winch_tension_n.p05 <= plan.schedule[i].winch_tension_n + 1e-6 && plan.schedule[i].winch_tension_n <= x.winch_tension_n.p95 + 1e-6),
      tensionSeries: plots.tension.series.length,
      marginSeries: plots.margin.series.length,
      bandsOpt: (plots.tension.bands ?? []).length,
      summary: document.getElementById("plan-bands-summary").textContent,
      valid: b.valid_samples,
    };
  });
  check(withBands.aligned && withBands.ordered, "bands: one 5/50/95 % band per schedule instant, ordered");
  check(withBands.around, "bands: the 5–95 % band of the winch tension brackets the plan's trace");
  check(withBands.tensionSeries >= 5 && withBands.marginSeries === 4 && withBands.bandsOpt === 1,
    `bands: shaded 5–95 % series on the tension and margin plots (${withBands.tensionSeries}, ${withBands.marginSeries}, ${withBands.bandsOpt})`);
  check(/P\(unstable somewhere\)/.test(withBands.summary) && withBands.valid === 300, `bands: probabilities summarised (${withBands.summary})`);
  const bandsCsvDownload = page.waitForEvent("download");
  await page.click("#plan-csv");
  const bandsCsvPath = await (await bandsCsvDownload).path();
  const bandsCsv = bandsCsvPath ? (await import("node:fs")).readFileSync(bandsCsvPath, "utf8") : "";
  check(bandsCsv.includes("winch_tension_p05_n") && bandsCsv.includes("# uncertainty inputs[0].field,aerostat.net_buoyancy_n"),
    "bands: the CSV carries the percentiles and the uncertainty inputs");
  await page.screenshot({ path: path.join(artifacts, "plan_page_bands.png"), fullPage: false });
  await page.uncheck("#plan-bands-on");

  phase = "infeasible";
  await page.fill("#plan-target", "1290");
  await page.fill("#plan-reserve", "0.05");
  await page.click("#plan-button");
  await page.waitForFunction(() => window.tetherplan?.plan?.inputs?.target_elevation_m === 1290, null, { timeout: 60_000 });
  const nogo = await waitPlan(page);
  check(nogo && !nogo.feasible && nogo.binding_limit === "static_lift_limit", `1290 m with 5 % is a no-go (${nogo?.binding_limit})`);
  check((await page.textContent("#plan-verdict .word"))?.trim() === "NO-GO", "verdict shows NO-GO");

  phase = "phone";
  const phone = await browser.newContext({ viewport: { width: 375, height: 812 }, isMobile: true });
  const p2 = await phone.newPage();
  watchConsole(p2, consoleErrors, () => phase);
  await p2.goto(url, { waitUntil: "load" });
  const pp = await waitPlan(p2);
  check(pp && pp.go, "plan at phone width");
  const overflow = await p2.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
  check(overflow <= 1, `no horizontal overflow at 375 px (${overflow} px)`);
  await p2.screenshot({ path: path.join(artifacts, "plan_page_375.png"), fullPage: false });
  await p2.locator("#plan-verdict").scrollIntoViewIfNeeded();
  await p2.evaluate(() => document.getElementById("plan-verdict").scrollIntoView({ block: "start" }));
  await p2.screenshot({ path: path.join(artifacts, "plan_page_375_result.png"), fullPage: false });
  await p2.evaluate(() => document.getElementById("plan-phases").scrollIntoView({ block: "start" }));
  await p2.screenshot({ path: path.join(artifacts, "plan_page_375_table.png"), fullPage: false });
  await phone.close();

  const unexpected = consoleErrors.filter((e) => !(e.phase === "none"));
  check(unexpected.length === 0, `no console errors (${JSON.stringify(unexpected).slice(0, 300)})`);
} catch (e) {
  console.error(e);
  exitCode = 1;
} finally {
  await browser.close();
}
if (failures.length) {
  console.error(`${failures.length} check(s) failed`);
  exitCode = 1;
}
process.exit(exitCode);
