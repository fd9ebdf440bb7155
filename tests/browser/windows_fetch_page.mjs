// Browser test of the configured forecast source (issue 32, item 3):
//
//   TETHERPLAN_FORECAST_URL=http://… node tests/browser/windows_fetch_page.mjs http://127.0.0.1:8080/
//
// The server was started with --forecast-url pointing at the recorded
// Open-Meteo file (served by the Rust test). The windows panel offers
// "Fetch today's forecast" (shown only when /healthz says the server has a
// source); clicking it fills the forecast with the file's JSON, says where
// and when it came from, and shows the day's timeline. Screenshot:
// tests/artifacts/windows_fetch_page.png.

import { readFileSync } from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";
import { checker, launch, target, watchConsole } from "./harness.mjs";

const { url, artifacts } = target("windows_fetch_page.mjs");
const { failures, check } = checker();
const browser = await launch();
const consoleErrors = [];
let phase = "load";
const here = path.dirname(fileURLToPath(import.meta.url));
const file = JSON.parse(readFileSync(path.resolve(here, "..", "forecasts", "open_meteo_hourly.json"), "utf8"));

try {
  const context = await browser.newContext({ viewport: { width: 1280, height: 900 } });
  const page = await context.newPage();
  watchConsole(page, consoleErrors, () => phase);
  const response = await page.goto(url, { waitUntil: "load" });
  check(response && response.ok(), `GET / → ${response?.status()}`);
  await page.waitForSelector("#windows-fetch:not([hidden])", { timeout: 30_000 });

  phase = "fetch";
  await page.click("#windows-fetch");
  await page.waitForFunction(() => document.querySelectorAll("#windows-timeline button").length > 0, null, { timeout: 180_000 });
  const data = JSON.parse(await page.inputValue("#windows-data"));
  // the same JSON value (the server's JSON objects keep their keys sorted)
  const canon = (v) => Array.isArray(v) ? v.map(canon)
    : v && typeof v === "object" ? Object.fromEntries(Object.keys(v).sort().map((k) => [k, canon(v[k])])) : v;
  check(JSON.stringify(canon(data)) === JSON.stringify(canon(file)), "the fetched forecast is the source's file");
  const hours = file.hourly.time.length;
  const source = await page.textContent("#windows-source");
  check(source.includes(`${hours} periods`) && source.includes(process.env.TETHERPLAN_FORECAST_URL),
    `where and when it came from (“${source}”)`);
  const cells = await page.$$eval("#windows-timeline button", (bs) => bs.map((b) => b.dataset.verdict));
  check(cells.length === hours, `the timeline shows its ${hours} hours (${cells.length})`);
  check(cells.includes("go") && cells.includes("no-go"), `GO and NO-GO hours (${cells.join(" ")})`);
  await page.locator("#windows").screenshot({ path: path.join(artifacts, "windows_fetch_page.png") });
  await context.close();

  // a day of distinct winds is priced past a direct answer: its 422 sends
  // the panel to a job, the one 4xx expected
  const unexpected = consoleErrors.filter((e) => !(e.phase === "fetch" && /status of 422/.test(e.text)));
  for (const e of unexpected) console.log(`  console error (${e.phase}): ${e.text}`);
  check(unexpected.length === 0, `no console errors (${unexpected.length})`);
} catch (e) {
  console.error(`FAIL ${e.stack || e}`);
  failures.push(String(e));
} finally {
  await browser.close();
}

console.log(failures.length ? `${failures.length} check(s) failed` : "all browser checks passed");
process.exit(failures.length ? 1 : 0);
