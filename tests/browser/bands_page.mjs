// Browser test of the uncertainty-bands panel (static/bands.js).
//
//   node tests/browser/bands_page.mjs http://127.0.0.1:8080/
//
// Submits the default bands form (F ~ N(1000, 50) N, ρA ~ N(0.078, 0.002)
// kg/m, 24 rates 5–60 m/s, 500 samples), waits for the two shaded plots,
// checks that the band brackets the median at every rate, downloads the CSV
// (percentiles, errors and the inputs), checks an API error is shown, and
// fails on any console error. Screenshot: tests/artifacts/bands_page.png.

import { readFileSync } from "node:fs";
import path from "node:path";
import { checker, launch, target, watchConsole } from "./harness.mjs";

const { url, artifacts } = target("bands_page.mjs");
const { failures, check } = checker();
const browser = await launch();
const consoleErrors = [];
let phase = "load";
const page = await browser.newPage({ viewport: { width: 1100, height: 1600 }, acceptDownloads: true });
watchConsole(page, consoleErrors, () => phase);
await page.goto(url);
phase = "bands";
await page.click("#bands-button");
await page.waitForSelector("#bands-summary:not([hidden])", { timeout: 60_000 });
const canvases = await page.locator("#bands canvas").count();
check(canvases >= 2, `two plots drawn (${canvases} canvases)`);
const csvDownload = page.waitForEvent("download");
await page.click("#bands-csv");
const download = await csvDownload;
const file = path.join(artifacts, "bands_page.csv");
await download.saveAs(file);
const csv = readFileSync(file, "utf8").split("\n");
check(csv.some((l) => l.startsWith("# input") && l.includes("aerostat.net_buoyancy_n")), "CSV carries the inputs");
const rows = csv.filter((l) => /^[0-9]/.test(l)).map((l) => l.split(",").map(Number));
check(rows.length === 24, `24 rates in the CSV (${rows.length})`);
check(rows.every((r) => r[1] <= r[2] && r[2] <= r[3]), "h* p05 ≤ p50 ≤ p95 at every rate");
// h* median at the first rate (5 m/s) near (F/ρA − v²)/g = 1304.6 m
check(Math.abs(rows[0][2] / 1304.6 - 1) < 0.01, `median h* at 5 m/s ≈ 1304.6 m (${rows[0][2]})`);
await page.screenshot({ path: path.join(artifacts, "bands_page.png"), fullPage: true });
phase = "invalid";
await page.fill("#bands-lift-sd", "600");
await page.click("#bands-button");
await page.waitForSelector("#bands-error:not([hidden])", { timeout: 30_000 });
const msg = await page.textContent("#bands-error");
check(/net buoyancy/i.test(msg) && !/uncertainty\.inputs|_n\b/.test(msg), `error in plain words names the buoyancy's spread (${msg})`);
check((await page.getAttribute("#bands-lift-sd", "aria-invalid")) === "true", "the spread's input is marked invalid");
const unexpected = consoleErrors.filter((e) => !(e.phase === "invalid" && e.text.includes("422")));
check(unexpected.length === 0, `no console errors (${JSON.stringify(unexpected)})`);
await browser.close();
process.exit(failures.length ? 1 : 0);
