// Browser test of the transient-run and frequency-response panels.
//
//   node tests/browser/transient_page.mjs http://127.0.0.1:8080/
//
// Drives Debian's Chromium (/usr/bin/chromium, or $CHROMIUM) with playwright-core
// (no browser download). Loads the page, runs the default transient (thesis Fig 4.5:
// L0 = 1 m, 1 m/s, u = 10 sin(2t), r = 0.5 m, thesis force model, 60 s), checks the
// plotted tip deflection, that the envelope after the resonance (first natural
// frequency = wind frequency) is larger than before it, the energy plot, the outcome
// and the CSV; runs a 4-frequency response directly and a 24-frequency one as a job
// (progress), cancels a large job, puts invalid inputs in each panel (and the chart
// form's cable) and checks the API's error beside the field, runs a long transient as
// a job and an unstable deployment (diverged, log scale), repeats at phone width
// (375 px), and fails on any console error. Screenshots: tests/artifacts/transient_page*.png.
// Exit status 0 on success, 1 on a failed check, 2 on bad usage.

import { readFileSync } from "node:fs";
import path from "node:path";
import { checker, launch, target, watchConsole } from "./harness.mjs";

const { url, artifacts } = target("transient_page.mjs");

const { failures, check } = checker();

const browser = await launch();

// Console errors with the phase they happened in; the invalid-input phase expects
// the browser's own "Failed to load resource: … status of 422" line.
const consoleErrors = [];
let phase = "load";
const watch = (page) => watchConsole(page, consoleErrors, () => phase);

async function runDefaultTransient(page) {
  await page.click("#tr-run");
  await page.waitForSelector('#tr-status[data-state="ready"], #tr-status[data-state="error"]', { timeout: 60_000 });
  const st = await page.getAttribute("#tr-status", "data-state");
  check(st === "ready", `transient run computed (status: ${await page.textContent("#tr-status")})`);
  return st === "ready";
}

// What the tip-deflection plot holds, the resonance the page found, and the energy plot.
async function transientData(page) {
  return page.evaluate(() => {
    const s = window.tetherplanTransient;
    const pick = (u) => ({ labels: u.series.map((x) => x.label), data: u.data.map((a) => Array.from(a)) });
    return {
      tip: pick(s.plots.tip),
      energy: pick(s.plots.energy),
      freq: pick(s.plots.freq),
      resonance: s.resonance,
      request: s.request,
      outcome: s.result.outcome,
      via: s.via,
    };
  });
}

async function runFrequency(page, count) {
  await page.fill("#fr-count", String(count));
  await page.click("#fr-run");
  await page.waitForSelector('#fr-status[data-state="ready"], #fr-status[data-state="error"], #fr-status[data-state="idle"]', { timeout: 120_000 });
  // idle is the start state too: wait until the button is usable again.
  await page.waitForFunction(() => !document.querySelector("#fr-run").disabled, null, { timeout: 120_000 });
  const st = await page.getAttribute("#fr-status", "data-state");
  check(st === "ready", `frequency response of ${count} computed (status: ${await page.textContent("#fr-status")})`);
  return st === "ready";
}

async function frData(page) {
  return page.evaluate(() => {
    const s = window.tetherplanTransient.fr;
    const u = s.plot;
    return {
      x: Array.from(u.data[0]),
      y: Array.from(u.data[1]),
      labels: u.series.map((x) => x.label),
      apiPeak: s.result.peak_amplitude_m,
      frequencies: s.result.frequencies_rad_s,
      times: s.result.time_s.length,
      via: s.via,
      progress: s.jobProgress.slice(),
    };
  });
}

// Fraction of the heat map's plot area that is not white (drawn cells).
async function heatCoverage(page) {
  return page.evaluate(() => {
    const c = document.querySelector("#fr-heatmap");
    const ctx = c.getContext("2d");
    const { data } = ctx.getImageData(0, 0, c.width, c.height);
    let coloured = 0;
    for (let k = 0; k < data.length; k += 4) if (!(data[k] > 245 && data[k + 1] > 245 && data[k + 2] > 245)) coloured++;
    return coloured / (c.width * c.height);
  });
}

try {
  // ---------- desktop width ----------
  const context = await browser.newContext({ viewport: { width: 1100, height: 1400 }, acceptDownloads: true });
  const page = await context.newPage();
  watch(page);
  const response = await page.goto(url, { waitUntil: "load" });
  check(response && response.ok(), `GET ${url} → ${response?.status()}`);
  check(await page.isVisible("#transient-run"), "transient-run panel present");
  check(await page.isVisible("#frequency-response"), "frequency-response panel present");
  // Every visible label names a unit (or is a choice).
  const unitless = await page.evaluate(() =>
    [...document.querySelectorAll("#transient .field")]
      .filter((f) => !f.hidden && f.querySelector("input"))
      .map((f) => f.querySelector("label").textContent)
      .filter((t) => !/\((m|s|m\/s|N|kg\/m³|rad\/s|count|–|m, blank: never)\)/.test(t)),
  );
  check(unitless.length === 0, `units on every label (${unitless.join("; ") || "all"})`);

  phase = "transient";
  if (await runDefaultTransient(page)) {
    const d = await transientData(page);
    check(d.request.aero?.flow?.kind === "sinusoidal" && d.request.aero.flow.amplitude_m_s === 10 && d.request.aero.flow.angular_frequency_rad_s === 2, "defaults: u = 10 sin(2t)");
    check(d.request.initial_length_m === 1 && d.request.profile.rate_m_s === 1 && d.request.duration_s === 60, "defaults: L0 = 1 m, 1 m/s, 60 s");
    const cardAir = Number(await page.inputValue('#system-card [name="wind.air_density_kg_m3"], #plan-form [name="wind.air_density_kg_m3"]'));
    check(d.request.aero.radius_m === 0.5 && d.request.aero.air_density_kg_m3 === cardAir && d.request.aero.model.kind === "thesis",
      `defaults: r = 0.5 m, air density ${d.request.aero.air_density_kg_m3} kg/m³ = the system card's ${cardAir}, thesis force model`);
    check((await page.locator('#transient [name="aero.air_density_kg_m3"], #transient [name="aero.model.drag_coefficient_nondim"]').count()) === 0,
      "the transient panel has no air density or drag coefficient of its own");
    const [t, y, env] = d.tip.data;
    check(t.length === 1000 && y.length === 1000, `tip-deflection plot has ${y.length} points`);
    const maxAbs = Math.max(...y.map(Math.abs));
    check(maxAbs > 0.1 && Number.isFinite(maxAbs), `tip deflection is nonzero (max |y| = ${maxAbs.toFixed(3)} m)`);
    check(d.tip.labels.some((l) => /\(m\)$/.test(l)) && /\(s\)/.test(d.tip.labels[0]), `tip plot labels carry units (${d.tip.labels.join(" | ")})`);
    check(env.every((v, i) => v >= Math.abs(y[i]) - 1e-12), "envelope bounds |y| everywhere");
    const r = d.resonance;
    check(r && r.time_s > 1 && r.time_s < 59, `resonance found: ω₁ = 2 rad/s at t ≈ ${r?.time_s?.toFixed(2)} s (L ≈ ${r?.length_m?.toFixed(2)} m)`);
    if (r) {
      const before = Math.max(...env.filter((_, i) => t[i] < r.time_s));
      const after = Math.max(...env.filter((_, i) => t[i] > r.time_s));
      check(after > 1.5 * before, `peak envelope after the resonance ${after.toFixed(3)} m > before it ${before.toFixed(3)} m`);
    }
    const e = d.energy.data[1];
    check(e.length === 1000 && e.every(Number.isFinite) && Math.max(...e) > e[0], `energy plot: ${e.length} points, ${e[0].toFixed(2)} J → max ${Math.max(...e).toFixed(1)} J`);
    check(d.freq.data[1].length > 10, `ω₁ tracked at ${d.freq.data[1].length} times`);
    check(d.outcome === "completed" && (await page.getAttribute("#tr-outcome", "data-outcome")) === "completed", "outcome completed, shown");
    check(/ran \d+ steps/.test(await page.textContent("#tr-outcome")), `explanation shown: “${(await page.textContent("#tr-outcome")).slice(0, 90)}…”`);
    const canvases = await page.locator("#transient-run .plot-area canvas").count();
    check(canvases === 3, `three transient plots drawn (${canvases})`);

    const [download] = await Promise.all([page.waitForEvent("download"), page.click("#tr-csv")]);
    const csvPath = path.join(artifacts, "transient_page.csv");
    await download.saveAs(csvPath);
    const lines = readFileSync(csvPath, "utf8").trim().split("\n");
    const csv = lines.filter((l) => !l.startsWith("#"));
    check(csv[0] === "time_s,length_m,rate_m_s,tip_deflection_m,tip_velocity_m_s,tip_envelope_m,energy_j,vibration_energy_j,tip_force_n", "CSV header");
    check(csv.length === 1001, `CSV has ${csv.length - 1} rows`);
    check(["# input profile.rate_m_s,1", "# input aero.flow.amplitude_m_s,10", "# input duration_s,60", "# input cable.mass_per_length_kg_m,0.078"].every((l) => lines.includes(l)), "CSV records the inputs");
    const significant = (t) => t.replace(/^[-+]/, "").replace(/e.*$/i, "").replace(".", "").replace(/^0+/, "").length;
    const tooLong = csv.slice(1).flatMap((l) => l.split(",")).filter((t) => significant(t) > 6);
    check(tooLong.length === 0, `CSV numbers have at most six significant digits (${tooLong.slice(0, 3).join(" ")})`);
    check(!(await page.evaluate(() => window.tetherplanTransient.shade)), "a stable run shades nothing");
    check(/Stopped: the run completed/.test(await page.textContent("#tr-outcome")), "stop reason stated: completed");
    check(!/–/.test(await page.textContent("#tr-plot-tip .u-legend")), "legend blank until hovered (no “–”)");
  }

  // ---------- a small frequency response, direct ----------
  phase = "frequency";
  if (await runFrequency(page, 4)) {
    const f = await frData(page);
    check(f.via === "direct", `4 frequencies answered directly (${f.via})`);
    check(f.x.length === 4 && f.x[0] === 0.25 && Math.abs(f.x[3] - 4) < 1e-12, `4 points plotted at ω = ${f.x.map((v) => v.toFixed(2)).join(", ")} rad/s`);
    check(f.y.every((v, i) => v > 0 && Math.abs(v - f.apiPeak[i]) <= 1e-9 * Math.max(1, v)), `peak amplitudes (${f.y.map((v) => v.toFixed(3)).join(", ")} m) equal the API's peak_amplitude_m`);
    check(/\(m\)/.test(f.labels[1]) && /rad\/s/.test(f.labels[0]), "frequency plot labels carry units");
    const cov = await heatCoverage(page);
    check(cov > 0.4, `heat map drawn (${(cov * 100).toFixed(0)} % of the canvas coloured)`);
  }
  await page.screenshot({ path: path.join(artifacts, "transient_page.png"), fullPage: true });
  await page.locator("#transient").screenshot({ path: path.join(artifacts, "transient_page_panels.png") });

  // ---------- more than 16 frequencies: a job with progress ----------
  phase = "frequency-job";
  if (await runFrequency(page, 24)) {
    const f = await frData(page);
    check(/^job /.test(f.via ?? ""), `24 frequencies came from a ${f.via}`);
    check(f.x.length === 24 && f.y.every((v) => v > 0), `24 points plotted`);
    const last = f.progress.at(-1);
    check(f.progress.length > 0 && last[0] === "done" && last[1] === 1, `job progress reported (${f.progress.map(([s, p]) => `${s} ${p.toFixed(2)}`).join(", ")})`);
    check(await page.isHidden("#fr-job"), "progress bar hidden once the job is done");
  }

  // ---------- a large job, cancelled ----------
  phase = "cancel";
  await page.fill("#fr-count", "1024");
  await page.fill("#tr-duration", "600");
  await page.click("#fr-run");
  await page.waitForSelector("#fr-job:not([hidden])", { timeout: 10_000 });
  await page.waitForFunction(() => window.tetherplanTransient.fr.jobProgress.some(([s]) => s === "running"), null, { timeout: 30_000 });
  await page.click("#fr-job-cancel");
  await page.waitForFunction(() => !document.querySelector("#fr-run").disabled, null, { timeout: 30_000 });
  check((await page.textContent("#fr-status")) === "Job cancelled.", `large job cancelled (status: ${await page.textContent("#fr-status")})`);
  await page.fill("#tr-duration", "60");
  await page.fill("#fr-count", "4");

  // ---------- invalid inputs: the API's error beside the field ----------
  phase = "invalid";
  await page.fill("#tr-radius", "-0.5");
  await page.click("#tr-run");
  const radiusError = page.locator(".field:has(#tr-radius) .field-error");
  await radiusError.waitFor({ timeout: 30_000 });
  check((await radiusError.getAttribute("data-error-for")) === "aero.radius_m" && /greater than zero|positive|must be between/.test(await radiusError.textContent()), `error next to the radius: “${await radiusError.textContent()}”`);
  check((await page.getAttribute("#tr-radius", "aria-invalid")) === "true", "radius input marked invalid");
  check((await page.getAttribute("#tr-status", "data-state")) === "error", "transient status shows the error");
  await page.locator("#transient-run").screenshot({ path: path.join(artifacts, "transient_page_error.png") });
  await page.fill("#tr-radius", "0.5");
  check((await radiusError.count()) === 0, "error clears when the field is edited");

  // A job submission's `request.`-prefixed field lands on its input too.
  await page.fill("#fr-count", "20");
  await page.fill("#fr-max", "-1");
  await page.click("#fr-run");
  const maxError = page.locator(".field:has(#fr-max) .field-error");
  await maxError.waitFor({ timeout: 30_000 });
  check(/^frequencies_rad_s\.max$/.test(await maxError.getAttribute("data-error-for")), `job error next to the highest ω: “${await maxError.textContent()}” (${await maxError.getAttribute("data-error-for")})`);
  await page.fill("#fr-max", "4");
  await page.fill("#fr-count", "4");

  // Not a number: caught on the page, beside the field.
  await page.fill("#tr-duration", "sixty");
  await page.click("#tr-run");
  const durError = page.locator(".field:has(#tr-duration) .field-error");
  await durError.waitFor({ timeout: 5_000 });
  check(/not a number/.test(await durError.textContent()), `page-side error next to the duration: “${await durError.textContent()}”`);
  await page.fill("#tr-duration", "60");

  // A system field (the tether, in the system card above) refused by the transient route.
  await page.fill("#mass-per-length", "0");
  await page.click("#tr-run");
  const cableError = page.locator('.field:has(#mass-per-length) .field-error[data-source="transient"]');
  await cableError.waitFor({ timeout: 30_000 });
  check((await cableError.getAttribute("data-error-for")) === "cable.mass_per_length_kg_m", `transient error on the system card's mass per length: “${await cableError.textContent()}”`);
  check(/system card above/.test(await page.textContent("#tr-status")), `status points at the system card: “${await page.textContent("#tr-status")}”`);
  await page.fill("#mass-per-length", "0.078");
  check((await cableError.count()) === 0, "ρA error clears when edited");

  // ---------- a long transient run goes through a job ----------
  phase = "transient-job";
  await page.fill("#tr-duration", "700");
  check(/background job/.test(await page.textContent("#tr-hint")), `hint announces a job: “${await page.textContent("#tr-hint")}”`);
  if (await runDefaultTransient(page)) {
    const j = await page.evaluate(() => ({ via: window.tetherplanTransient.via, progress: window.tetherplanTransient.jobProgress.slice(), n: window.tetherplanTransient.result.time_s.length }));
    const last = j.progress.at(-1);
    check(/^job /.test(j.via ?? "") && j.n === 1000, `700 s run came from a ${j.via} (${j.n} samples)`);
    check(last && last[0] === "done" && last[1] === 1, `transient job progress reported (${j.progress.map(([s, p]) => `${s} ${p.toFixed(2)}`).join(", ")})`);
    check(await page.isHidden("#tr-job"), "transient progress bar hidden once done");
  }
  await page.fill("#tr-duration", "60");

  // ---------- an unstable deployment: diverged, shown on a log scale ----------
  phase = "diverged";
  await page.selectOption("#tr-profile", "trapezoidal");
  await page.fill("#tr-cruise", "10");
  await page.fill("#tr-target", "2000");
  await page.selectOption("#tr-wind", "power_law");
  await page.fill("#tr-duration", "250");
  if (await runDefaultTransient(page)) {
    const d = await page.evaluate(() => {
      const s = window.tetherplanTransient;
      return { outcome: s.result.outcome, unstable: s.firstUnstable, log: document.querySelector("#tr-log").checked, ys: Array.from(s.plots.tip.data[1]).filter((v) => v != null) };
    });
    check(d.outcome === "diverged" && (await page.getAttribute("#tr-outcome", "data-outcome")) === "diverged", "10 m/s to 2 km under 0.1 z^(1/3) diverges");
    check(d.unstable && d.unstable.length_m > 1100 && d.unstable.length_m < 1500, `first unstable at L ≈ ${d.unstable?.length_m?.toFixed(0)} m (critical length for 10 m/s ≈ 1.3 km)`);
    // The run stops at its magnitude cap (1000 × the length, reached near the
    // roller where the onset is), so the tip need not grow large first.
    check(d.log, `log scale switched on for the diverged run (log₁₀ max |y| = ${Math.max(...d.ys).toFixed(1)})`);
    // Past the onset the plots are greyed and hatched, from first_unstable_time_s on.
    const sh = await page.evaluate(() => {
      const s = window.tetherplanTransient;
      const u = s.plots.tip;
      const { left, top, width, height } = u.bbox;
      const x0 = u.valToPos(s.result.first_unstable_time_s, "x", true);
      // Mean brightness of a strip just before and just after the onset, above the curves' lower half.
      const mean = (a, b) => {
        const w = Math.max(1, Math.round(b - a));
        const img = u.ctx.getImageData(Math.round(a), Math.round(top), w, Math.round(height / 2)).data;
        let sum = 0;
        // The plot canvas is transparent over the white page: composite over white.
        for (let k = 0; k < img.length; k += 4) {
          const a = img[k + 3] / 255;
          sum += (a * (img[k] + img[k + 1] + img[k + 2])) / 3 + 255 * (1 - a);
        }
        return sum / (img.length / 4);
      };
      const strip = Math.min(40 * devicePixelRatio, (left + width - x0) * 0.8, (x0 - left) * 0.8);
      return {
        shade: s.shade,
        onset: s.result.first_unstable_time_s,
        stopped: s.result.stopped_reason,
        end: s.result.time_s.at(-1),
        before: mean(x0 - strip - 2, x0 - 2),
        after: mean(x0 + 2, x0 + 2 + strip),
      };
    });
    check(sh.shade && sh.onset != null && sh.shade.from_s === sh.onset && sh.shade.to_s === sh.end, `shaded from first_unstable_time_s = ${sh.onset?.toFixed(2)} s to the end ${sh.end?.toFixed(2)} s`);
    check(sh.after < sh.before - 15, `the region past onset is greyed (mean brightness ${sh.after.toFixed(0)} after, ${sh.before.toFixed(0)} before)`);
    const outcomeText = await page.textContent("#tr-outcome");
    check(/past onset|greyed/.test(outcomeText) && /Unstable from t\*/.test(outcomeText), "the outcome explains the greyed region");
    check(sh.stopped === "magnitude_cap" && (await page.getAttribute("#tr-outcome", "data-stopped-reason")) === "magnitude_cap" && /magnitude cap/.test(outcomeText),
      `stop reason stated: “${(await page.textContent("#tr-outcome .tr-stop")).trim()}”`);
    await page.locator("#transient-run").screenshot({ path: path.join(artifacts, "transient_page_diverged.png") });
  }
  await page.fill("#tr-duration", "60");
  await page.fill("#tr-cruise", "1");
  await page.fill("#tr-target", "40");

  // The other panel options produce valid requests.
  phase = "options";
  await page.selectOption("#tr-profile", "trapezoidal");
  await page.selectOption("#tr-initial", "tip_force");
  await page.selectOption("#tr-wind", "power_law");
  await page.selectOption("#tr-force-model", "drag");
  // The drag model's numbers come from the system card, entered once.
  await page.fill('[name="aerostat.drag_coefficient_nondim"]', "0.45");
  await page.fill('[name="aerostat.reference_area_m2"]', "3.5");
  await page.fill('[name="wind.air_density_kg_m3"]', "1.1");
  if (await runDefaultTransient(page)) {
    const d = await transientData(page);
    check(d.request.profile.kind === "trapezoidal" && d.request.initial.kind === "tip_force" && d.request.aero.flow.kind === "power_law" && d.request.aero.model.kind === "drag", "trapezoidal profile, tip force, power-law wind, drag model accepted");
    check(d.request.aero.model.drag_coefficient_nondim === 0.45 && d.request.aero.model.reference_area_m2 === 3.5 && d.request.aero.air_density_kg_m3 === 1.1,
      `the transient run uses the system card's C_D ${d.request.aero.model.drag_coefficient_nondim}, area ${d.request.aero.model.reference_area_m2} m², air ${d.request.aero.air_density_kg_m3} kg/m³`);
    const query = new URL(page.url()).searchParams;
    check(query.get("transient.aero.model.kind") === "drag" && query.get("transient.profile.kind") === "trapezoidal" && query.get("transient.aero.flow.kind") === "power_law",
      `the panel's choices are kept in the URL by their request paths (${[...query.keys()].filter((k) => k.startsWith("transient.")).join(", ")})`);
  }
  // A refused card number is shown on the card, not on a panel input.
  phase = "invalid";
  await page.fill('[name="wind.air_density_kg_m3"]', "500");
  await page.click("#tr-run");
  await page.waitForSelector('#tr-status[data-state="ready"], #tr-status[data-state="error"]', { timeout: 60_000 });
  const airError = page.locator('.field-error[data-error-for="wind.air_density_kg_m3"]');
  check((await airError.count()) === 1, `a refused air density is shown beside the card's input (${await page.textContent("#tr-status")})`);
  await page.fill('[name="wind.air_density_kg_m3"]', "1.225");
  await context.close();

  // ---------- phone width ----------
  phase = "phone";
  const phone = await browser.newContext({ viewport: { width: 375, height: 800 }, deviceScaleFactor: 2, isMobile: true, hasTouch: true });
  const small = await phone.newPage();
  watch(small);
  await small.goto(url, { waitUntil: "load" });
  if (await runDefaultTransient(small)) {
    await runFrequency(small, 4);
    const overflow = await small.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
    check(overflow <= 0, `no horizontal scrolling at 375 px (overflow ${overflow} px)`);
    const widths = await small.evaluate(() => [...document.querySelectorAll("#transient .plot-area .uplot, #fr-heatmap")].map((e) => e.getBoundingClientRect().width));
    check(widths.length === 5 && widths.every((w) => w <= 375 && w >= 250), `plots fit the phone width (${widths.map((w) => w.toFixed(0)).join(", ")} px)`);
  }
  await small.locator("#transient").screenshot({ path: path.join(artifacts, "transient_page_375.png") });
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
console.log(`screenshots: ${path.join(artifacts, "transient_page.png")}, transient_page_panels.png, transient_page_error.png, transient_page_diverged.png, transient_page_375.png`);
process.exit(failures.length ? 1 : 0);
