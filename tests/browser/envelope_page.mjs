// Browser test of the operating-envelope panel (and the page at desktop and
// phone sizes).
//
//   node tests/browser/envelope_page.mjs http://127.0.0.1:8080/
//
// Loads the page at 1280×800, checks the verdict and the plan are still the
// opening view, enters the OpenAPI example's system once in the system card
// (Dyneema 6 mm, 2000 N, 100 kg, C_D 0.3 on 20 m², today's wind a log law)
// and runs the envelope panel's default grid (40 winds × 50 lengths, ceiling
// 2500 m, payout 5 m/s) with it, checks the heat map
// against the API's altitudes, the feasible region's outline (every outline
// edge separates a feasible cell from an infeasible one or the grid's edge),
// the region labels (feasible and each binding limit present), the tables,
// the CSV export (every input recorded, at most six significant digits) and
// the PNG export; switches the quantity to the safety factor; runs a grid
// above the synchronous limit as a job with progress; puts an invalid input
// and checks the API's error beside its field; then takes screenshots of the
// whole page at 1280×800 and 390×844 (no horizontal scrolling on the phone).
// Screenshots: tests/artifacts/envelope_page*.png, page_1280.png, page_390.png.

import { readFileSync } from "node:fs";
import path from "node:path";
import { checker, launch, target, watchConsole } from "./harness.mjs";

const { url, artifacts } = target("envelope_page.mjs");
const { failures, check } = checker();
const browser = await launch();
const consoleErrors = [];
let phase = "load";
const watch = (page) => watchConsole(page, consoleErrors, () => phase);

async function runEnvelope(page) {
  await page.click("#env-button");
  await page.waitForFunction(() => !document.querySelector("#env-button").disabled && document.querySelector("#env-status").dataset.state !== "busy", null, { timeout: 60_000 });
  const st = await page.getAttribute("#env-status", "data-state");
  check(st === "ready", `envelope computed (status: ${await page.textContent("#env-status")})`);
  return st === "ready";
}

try {
  const context = await browser.newContext({ viewport: { width: 1280, height: 800 }, acceptDownloads: true });
  const page = await context.newPage();
  watch(page);
  const response = await page.goto(url, { waitUntil: "load" });
  check(response && response.ok(), `GET ${url} → ${response?.status()}`);
  // The plan is the opening view: its heading is in the first screen, the envelope below it.
  const tops = await page.evaluate(() => ({
    plan: document.querySelector("#verdict").getBoundingClientRect().top,
    envelope: document.querySelector("#envelope-heading").getBoundingClientRect().top,
    thesis: document.querySelector("#thesis-heading").getBoundingClientRect().top,
  }));
  check(tops.plan < 200 && tops.envelope > tops.plan && tops.thesis > tops.envelope, `the verdict first (${tops.plan.toFixed(0)} px), then the envelope (${tops.envelope.toFixed(0)} px), then the thesis analyses`);
  await page.waitForSelector('#verdict[data-state="go"], #verdict[data-state="no-go"]', { timeout: 30_000 }).catch(() => {});
  await page.screenshot({ path: path.join(artifacts, "page_1280.png"), fullPage: false });
  await page.screenshot({ path: path.join(artifacts, "page_1280_full.png"), fullPage: true });

  phase = "envelope";
  // The system, entered once in the card.
  await page.selectOption('[name="cable.preset"]', "dyneema");
  for (const [name, value] of [["cable.diameter_m", "0.006"], ["aerostat.net_buoyancy_n", "2000"], ["aerostat.mass_kg", "100"],
    ["aerostat.drag_coefficient_nondim", "0.3"], ["aerostat.reference_area_m2", "20"]]) await page.fill(`[name="${name}"]`, value);
  await page.selectOption('[name="wind.flow.kind"]', "log_law");
  if (await runEnvelope(page)) {
    const d = await page.evaluate(() => {
      const s = window.tetherplanEnvelope;
      return { req: s.request, res: s.result, regions: s.regions, outline: s.outline, via: s.via };
    });
    check(d.via === "direct", `2000 points answered directly (${d.via})`);
    check(d.req.wind_speeds_m_s.count === 40 && d.req.tether_lengths_m.count === 50 && d.req.ceiling_m === 2500 && d.req.payout_rate_m_s === 5,
      "the panel's defaults: 40 winds × 50 lengths, ceiling 2500 m, payout 5 m/s");
    check(d.req.cable.preset === "dyneema" && d.req.cable.mass_per_length_kg_m === undefined && d.req.aerostat.net_buoyancy_n === 2000 && d.req.aerostat.mass_kg === 100 &&
      d.req.wind.flow?.kind === "log_law", `the card's system in the request (${JSON.stringify({ cable: d.req.cable, aerostat: d.req.aerostat })})`);
    check(d.res.points.length === 2000, `${d.res.points.length} points`);
    // Outline: every segment separates a feasible cell from an infeasible one (or the edge), and every such boundary is drawn.
    const nl = d.res.tether_lengths_m.length;
    const nw = d.res.wind_speeds_m_s.length;
    const ok = (i, j) => i >= 0 && j >= 0 && i < nw && j < nl && d.res.points[i * nl + j].feasible;
    let expected = 0;
    for (let i = 0; i < nw; i++) for (let j = 0; j < nl; j++) if (ok(i, j)) for (const [a, b] of [[i - 1, j], [i + 1, j], [i, j - 1], [i, j + 1]]) if (!ok(a, b)) expected++;
    const feasible = d.res.points.filter((p) => p.feasible).length;
    check(feasible > 0 && feasible < 2000, `the default has a feasible region (${feasible} of 2000 points) and limits around it`);
    check(d.outline.length === expected && expected > 0, `feasible region outlined: ${d.outline.length} edges (${expected} boundary edges in the API's answer)`);
    // Region labels: one per binding limit present, drawn.
    const limits = [...new Set(d.res.points.filter((p) => !p.feasible).map((p) => p.binding_limit))];
    const labelled = d.regions.filter((r) => r.labelled).map((r) => r.key);
    check(labelled.includes("feasible"), `the feasible region is labelled (${[...new Set(labelled)].join(", ")})`);
    check(limits.length > 0 && limits.every((l) => labelled.includes(l)), `every binding limit in the answer (${limits.join(", ")}) names a region on the map`);
    check(limits.includes("ceiling") && limits.includes("tension"), `the default meets the ceiling and the tension limit (${limits.join(", ")})`);
    // The region name is drawn: the pixel at a labelled feasible region's centre is the label box (near white).
    const px = await page.evaluate(() => {
      const s = window.tetherplanEnvelope;
      const r = s.regions.find((x) => x.key === "feasible" && x.labelled);
      const c = document.querySelector("#env-heatmap");
      const dpr = c.width / c.getBoundingClientRect().width;
      const box = c.getContext("2d").getImageData(Math.round((r.box[0] + 2.5) * dpr), Math.round(r.y * dpr), 1, 1).data;
      return Array.from(box);
    });
    check(px[0] > 200 && px[1] > 200 && px[2] > 200, `a label box is drawn on the feasible region (pixel rgb ${px.slice(0, 3).join(",")})`);
    // Tables: one row per length and per wind.
    const rows = await page.evaluate(() => [document.querySelectorAll("#env-per-length tbody tr").length, document.querySelectorAll("#env-per-wind tbody tr").length]);
    check(rows[0] === 50 && rows[1] === 40, `tables: ${rows[0]} lengths, ${rows[1]} winds`);
    check(/feasible/.test(await page.textContent("#env-status")) && /highest altitude/.test(await page.textContent("#env-status")), `summary: “${await page.textContent("#env-status")}”`);
    await page.locator("#envelope").screenshot({ path: path.join(artifacts, "envelope_page.png") });

    // CSV: the inputs, the resolved preset values, six significant digits at most.
    const [download] = await Promise.all([page.waitForEvent("download"), page.click("#env-csv")]);
    const csvPath = path.join(artifacts, "envelope_page.csv");
    await download.saveAs(csvPath);
    const all = readFileSync(csvPath, "utf8").trim().split("\n");
    const need = ["# input cable.preset,dyneema", "# input cable.diameter_m,0.006", "# input aerostat.net_buoyancy_n,2000", "# input wind.flow.kind,log_law",
      "# input wind.flow.roughness_length_m,0.03", "# input wind_speeds_m_s.count,40", "# input tether_lengths_m.max,3000", "# input ceiling_m,2500", "# input payout_rate_m_s,5",
      "# input required_safety_factor_nondim,5"];
    const missing = need.filter((l) => !all.includes(l));
    check(missing.length === 0, `CSV records every input (${missing.join("; ") || "all present"})`);
    check(all.some((l) => l.startsWith("# resolved cable.breaking_strength_n,")) && all.some((l) => l.startsWith("# resolved cable.mass_per_length_kg_m,")), "CSV records the preset's resolved values");
    const data = all.filter((l) => !l.startsWith("#"));
    check(data[0].startsWith("wind_speed_m_s,tether_length_m,aerostat_altitude_m") && data.length === 2001, `CSV header and ${data.length - 1} rows`);
    const significant = (t) => t.replace(/^[-+]/, "").replace(/e.*$/i, "").replace(".", "").replace(/^0+/, "").length;
    const tooLong = all.flatMap((l) => l.replace(/^# \w+ [^,]*,/, "").split(/[,= ]/)).filter((t) => /^[-+]?\d*\.?\d+(e[-+]?\d+)?$/i.test(t) && significant(t) > 6);
    check(tooLong.length === 0, `CSV numbers have at most six significant digits (${tooLong.slice(0, 3).join(" ")})`);
    const first = data[1].split(",");
    const p0 = d.res.points[0];
    check(Math.abs(Number(first[2]) - p0.aerostat_altitude_m) <= 1e-5 * Math.max(1, p0.aerostat_altitude_m), `CSV altitude ${first[2]} m = API ${p0.aerostat_altitude_m} m to 6 digits`);
    const [png] = await Promise.all([page.waitForEvent("download"), page.click("#env-png")]);
    const pngPath = path.join(artifacts, "envelope_page_download.png");
    await png.saveAs(pngPath);
    check(png.suggestedFilename().endsWith(".png") && readFileSync(pngPath).length > 10_000, `PNG download (${png.suggestedFilename()}, ${readFileSync(pngPath).length} bytes)`);

    // The safety factor as the heat-map quantity.
    await page.selectOption("#env-quantity", "safety_factor");
    check(await page.isChecked("#env-log"), "safety factor drawn with a log colour scale");
    await page.locator("#env-output figure").screenshot({ path: path.join(artifacts, "envelope_page_sf.png") });
    await page.selectOption("#env-quantity", "altitude");
  }

  // A grid above the synchronous limit: a job with progress.
  phase = "job";
  await page.fill("#env-wcount", "52");
  await page.fill("#env-lcount", "100");
  check(/background job/.test(await page.textContent("#env-hint")), `hint announces a job: “${await page.textContent("#env-hint")}”`);
  if (await runEnvelope(page)) {
    const j = await page.evaluate(() => ({ via: window.tetherplanEnvelope.via, progress: window.tetherplanEnvelope.jobProgress.slice(), n: window.tetherplanEnvelope.result.points.length }));
    const last = j.progress.at(-1);
    check(/^job /.test(j.via ?? "") && j.n === 5200, `5200 points came from a ${j.via}`);
    check(last && last[0] === "done" && last[1] === 1, `job progress reported (${j.progress.map(([s, p]) => `${s} ${p.toFixed(2)}`).join(", ")})`);
    check(await page.isHidden("#env-job"), "progress bar hidden once the job is done");
  }
  await page.fill("#env-wcount", "40");
  await page.fill("#env-lcount", "50");

  // The API's error beside its field.
  phase = "invalid";
  await page.fill("#cable-diameter", "-1");
  await page.click("#env-button");
  const err = page.locator(".field:has(#cable-diameter) .field-error");
  await err.waitFor({ timeout: 30_000 });
  check((await err.getAttribute("data-error-for")) === "cable.diameter_m", `error next to the card's diameter: “${await err.textContent()}”`);
  check(!/cable\.|_m\b/.test(await err.textContent()), "in plain words");
  await page.fill("#cable-diameter", "0.006");
  check((await err.count()) === 0, "error clears when the field is edited");
  await context.close();

  // ---------- phone ----------
  phase = "phone";
  const phone = await browser.newContext({ viewport: { width: 390, height: 844 }, deviceScaleFactor: 2, isMobile: true, hasTouch: true });
  const small = await phone.newPage();
  watch(small);
  await small.goto(url, { waitUntil: "load" });
  await small.waitForSelector('#verdict[data-state="go"], #verdict[data-state="no-go"]', { timeout: 30_000 }).catch(() => {});
  await small.screenshot({ path: path.join(artifacts, "page_390.png"), fullPage: false });
  if (await runEnvelope(small)) {
    const overflow = await small.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
    check(overflow <= 0, `no horizontal scrolling at 390 px (overflow ${overflow} px)`);
    const w = await small.evaluate(() => document.querySelector("#env-heatmap").getBoundingClientRect().width);
    check(w <= 390 && w >= 250, `heat map fits the phone width (${w.toFixed(0)} px)`);
    await small.locator("#envelope").screenshot({ path: path.join(artifacts, "envelope_page_390.png") });
  }
  await small.screenshot({ path: path.join(artifacts, "page_390_full.png"), fullPage: true });
  await phone.close();

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
console.log(`screenshots: ${path.join(artifacts, "envelope_page.png")}, page_1280.png, page_390.png`);
process.exit(failures.length ? 1 : 0);
