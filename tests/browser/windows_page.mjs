// Browser test of the launch-windows panel (issue 32):
//
//   node tests/browser/windows_page.mjs http://127.0.0.1:8080/
//
// The page opens at the default plan (900 m); the Open-Meteo file of
// tests/forecasts/ is dropped on the panel (a DataTransfer drop event): the
// day's timeline shows its 24 hours, coloured by verdict, with GO and NO-GO
// hours; choosing a NO-GO hour sets the plan's wind to that hour's (the
// fitted power law) and the plan's verdict turns NO-GO; choosing a GO hour
// turns it GO. Each cell is labelled by its hour, and the launch window's
// band lies under its hours, also at 390 px with the day scrolled. The
// page's units (the header's) reach the timeline and the URL. Screenshots:
// tests/artifacts/windows_page.png, windows_page_390.png. Dropped as an
// ensemble (the file as control and three members, one stormy), each hour
// shows its share of members that go: windows_page_ensemble.png. A TAF
// pasted: one cell per change group, each window under the groups it
// overlaps: windows_page_taf.png. A limit typed as "12 kn" and a TAF the
// server refuses are each named, and the day shown before is cleared.

import { readFileSync } from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";
import { checker, launch, target, watchConsole } from "./harness.mjs";

const { url, artifacts } = target("windows_page.mjs");
const { failures, check } = checker();
const browser = await launch();
const consoleErrors = [];
let phase = "load";
const here = path.dirname(fileURLToPath(import.meta.url));
const forecast = readFileSync(path.resolve(here, "..", "forecasts", "open_meteo_hourly.json"), "utf8");

const verdictState = (page) =>
  page.waitForFunction(() => ["go", "no-go", "error"].includes(document.querySelector("#verdict")?.dataset.state), null, { timeout: 120_000 })
    .then(() => page.getAttribute("#verdict", "data-state"));

try {
  const context = await browser.newContext({ viewport: { width: 1280, height: 900 } });
  const page = await context.newPage();
  watchConsole(page, consoleErrors, () => phase);
  const response = await page.goto(url, { waitUntil: "load" });
  check(response && response.ok(), `GET / → ${response?.status()}`);
  await verdictState(page);

  phase = "drop";
  await page.evaluate((text) => {
    const dt = new DataTransfer();
    dt.items.add(new File([text], "open_meteo_hourly.json", { type: "application/json" }));
    document.querySelector("#windows").dispatchEvent(new DragEvent("drop", { dataTransfer: dt, bubbles: true, cancelable: true }));
  }, forecast);
  await page.waitForFunction(() => document.querySelectorAll("#windows-timeline button").length > 0, null, { timeout: 180_000 });
  const cells = await page.$$eval("#windows-timeline button", (bs) => bs.map((b) => b.dataset.verdict));
  check(cells.length === 24, `the timeline shows the day's 24 hours (${cells.length})`);
  const via = await page.$eval("#windows", (s) => s.dataset.via);
  check(via === "job", `a day of distinct winds ran as a job, the server's price past its budget (${via})`);
  check(cells.includes("go") && cells.includes("no-go"), `GO and NO-GO hours (${cells.join(" ")})`);
  const colours = await page.$$eval("#windows-timeline button .bar", (bs) => [...new Set(bs.map((b) => getComputedStyle(b).backgroundColor))]);
  check(colours.length === 2, `hours coloured by verdict (${colours.join(", ")})`);
  const labels = await page.$$eval("#windows-timeline button .hour", (ls) => ls.map((l) => l.textContent));
  const hours = Array.from({ length: 24 }, (_, h) => String(h).padStart(2, "0"));
  check(labels.join(" ") === hours.join(" "), `each cell labelled by its hour (${labels.join(" ")})`);
  // The window band lies under its hours: from the left edge of its first
  // hour to the right edge of its last (the file's window is 00:00–10:00).
  const band = () => page.evaluate(() => {
    const cells = [...document.querySelectorAll("#windows-timeline button")].map((c) => c.getBoundingClientRect());
    const b = document.querySelector("#windows-bands span")?.getBoundingClientRect();
    return b && { text: document.querySelector("#windows-bands span").textContent, left: b.left - cells[0].left, right: b.right - cells[9].right };
  });
  const b = await band();
  check(b && b.text.startsWith("2026-12-03T00:00–2026-12-03T10:00"), `the launch window marked (${b?.text})`);
  check(b && Math.abs(b.left) <= 1 && Math.abs(b.right) <= 1, `the window's band spans its hours 00–09 (edges off by ${b?.left?.toFixed(1)} and ${b?.right?.toFixed(1)} px)`);
  await page.locator("#windows").screenshot({ path: path.join(artifacts, "windows_page.png") });

  phase = "choose";
  const noGo = cells.indexOf("no-go");
  await page.click(`#windows-timeline button[data-index="${noGo}"]`);
  check((await page.inputValue('[name="wind.flow.kind"]')) !== "uniform", "the plan's wind is the hour's fitted flow");
  check((await verdictState(page)) === "no-go", "choosing a NO-GO hour turns the plan NO-GO");
  const go = cells.indexOf("go");
  await page.click(`#windows-timeline button[data-index="${go}"]`);
  check((await verdictState(page)) === "go", "choosing a GO hour turns the plan GO");

  phase = "units";
  await page.selectOption("#units-speed", "kn");
  await page.selectOption("#units-length", "ft");
  const q = new URL(page.url()).searchParams;
  check(q.get("speed") === "kn" && q.get("length") === "ft", `the page's units kept in the URL (${page.url()})`);
  const title = await page.getAttribute(`#windows-timeline button[data-index="${go}"]`, "title");
  check(/ kn/.test(title) && / ft/.test(title), `the timeline speaks knots and feet (“${title.split("\n")[0]}”)`);
  // On a phone the day scrolls sideways, the band with its hours.
  await page.setViewportSize({ width: 390, height: 844 });
  await page.$eval(".windows-scroll", (s) => { s.scrollLeft = 120; });
  const scrolled = await page.$eval(".windows-scroll", (s) => s.scrollLeft);
  const p = await band();
  check(scrolled > 0 && p && Math.abs(p.left) <= 1 && Math.abs(p.right) <= 1,
    `at 390 px, scrolled ${scrolled} px, the band still spans its hours (edges off by ${p?.left?.toFixed(1)} and ${p?.right?.toFixed(1)} px)`);
  await page.locator("#windows").screenshot({ path: path.join(artifacts, "windows_page_390.png") });

  // An ensemble: the file's hours as the control and three members, the
  // third blowing three times as hard. Each hour shows its share of
  // members that go: 100 % or 75 % where the control goes (the stormy
  // member may not), 0 % or 25 % where it does not.
  phase = "ensemble";
  await page.setViewportSize({ width: 1280, height: 900 });
  await page.evaluate((text) => {
    const f = JSON.parse(text);
    for (const k of Object.keys(f.hourly).filter((k) => k.startsWith("wind_"))) {
      for (const m of [1, 2, 3]) {
        const key = `${k}_member0${m}`;
        f.hourly[key] = f.hourly[k].map((v) => (m === 3 ? 3 * v : v));
        f.hourly_units[key] = f.hourly_units[k];
      }
    }
    const dt = new DataTransfer();
    dt.items.add(new File([JSON.stringify(f)], "ensemble.json", { type: "application/json" }));
    document.querySelector("#windows").dispatchEvent(new DragEvent("drop", { dataTransfer: dt, bubbles: true, cancelable: true }));
  }, forecast);
  await page.waitForFunction(() => /4 ensemble members/.test(document.querySelector("#windows-summary")?.textContent ?? "") &&
    document.querySelectorAll("#windows-timeline .prob").length > 0, null, { timeout: 180_000 });
  const shares = await page.$$eval("#windows-timeline button", (bs) => bs.map((b) => [b.dataset.verdict, b.querySelector(".prob")?.textContent]));
  check(shares.length === 24 && shares.every(([, p]) => p != null), `each hour shows its share of members that go (${shares.map(([, p]) => p).join(" ")})`);
  check(shares.every(([v, p]) => (v === "go" ? ["100%", "75%"] : ["0%", "25%"]).includes(p)),
    `the shares agree with the control's verdicts (${shares.map(([v, p]) => `${v}:${p}`).join(" ")})`);
  check(shares.some(([, p]) => p === "75%"), "the stormy member turns some GO hours to 75 %");
  const ensTitle = await page.getAttribute('#windows-timeline button[data-index="0"]', "title");
  check(/P\(go\) \d+ % \(\d+–\d+ %\)/.test(ensTitle) && /10\/50\/90 %/.test(ensTitle), `an hour's title gives P(go) with its interval and the members' reach (“${ensTitle.split("\n")[0]}”)`);
  await page.locator("#windows").screenshot({ path: path.join(artifacts, "windows_page_ensemble.png") });

  // A TAF: one cell per change group, each lasting hours, a TEMPO inside
  // the BECMG. Each window's band lies under the groups it overlaps (the
  // overlap computed here from the cells' times), not from the first cell.
  phase = "taf";
  await page.fill("#windows-data", "TAF EGLL 051100Z 0512/0618 05005KT 9999 SCT030 BECMG 0515/0517 08004KT TEMPO 0520/0602 30040G55KT");
  await page.click("#windows-button");
  await page.waitForFunction(() => document.querySelectorAll("#windows-timeline button").length === 3 && document.querySelector("#windows")?.dataset.state === "done", null, { timeout: 120_000 });
  const taf = await page.evaluate(() => {
    const minutes = (t) => { const m = t.match(/^(\d\d)(\d\d)(\d\d)Z$/); return (Number(m[1]) * 24 + Number(m[2])) * 60 + Number(m[3]); };
    const cells = [...document.querySelectorAll("#windows-timeline button")].map((c) => ({
      from: minutes(c.dataset.time), to: minutes(c.dataset.end), verdict: c.dataset.verdict,
      label: c.querySelector(".hour").textContent, box: c.getBoundingClientRect() }));
    const bands = [...document.querySelectorAll("#windows-bands span")].map((b) => {
      const [start, end] = b.textContent.match(/^(\d{6}Z)–(\d{6}Z)/).slice(1).map(minutes);
      const over = cells.filter((c) => c.from < end && c.to > start);
      const r = b.getBoundingClientRect();
      return { text: b.textContent, over: over.length, top: r.top, bottom: r.bottom,
        left: over.length ? r.left - over[0].box.left : NaN, right: over.length ? r.right - over[over.length - 1].box.right : NaN };
    });
    return { labels: cells.map((c) => c.label), verdicts: cells.map((c) => c.verdict), bands, list: document.querySelector("#windows-list").textContent };
  });
  check(taf.labels.join(" ") === "12 15 20", `the TAF's groups labelled by their hours (${taf.labels.join(" ")})`);
  check(taf.verdicts.join(" ") === "go go no-go", `calm base and BECMG GO, the stormy TEMPO NO-GO (${taf.verdicts.join(" ")})`);
  check(taf.bands.length === 2 && taf.bands.every((b) => b.over > 0 && Math.abs(b.left) <= 1 && Math.abs(b.right) <= 1),
    `each TAF window under the groups it overlaps (${taf.bands.map((b) => `${b.text}: ${b.over} groups, edges ${b.left.toFixed(1)}/${b.right.toFixed(1)} px`).join("; ")})`);
  const [b1, b2] = taf.bands;
  check(b1 && b2 && (b1.bottom <= b2.top || b2.bottom <= b1.top), `two windows under the same groups take rows of their own (${b1?.top}–${b1?.bottom}, ${b2?.top}–${b2?.bottom})`);
  check(/^Launch windows: 051200Z–052000Z, launch by \d{6}Z; 060200Z–061800Z, launch by \d{6}Z\.$/.test(taf.list), `the windows listed in words (“${taf.list}”)`);
  await page.locator("#windows").screenshot({ path: path.join(artifacts, "windows_page_taf.png") });

  // Break one input, then the forecast: each time the panel names the
  // field and the day shown before is gone (not passed off as this one's).
  phase = "break";
  const dayShown = () => page.evaluate(() => ({
    cells: document.querySelectorAll("#windows-timeline button").length,
    timeline: !document.querySelector("#windows-timeline").hidden,
    list: !document.querySelector("#windows-list").hidden,
    error: document.querySelector("#windows-error").hidden ? null : document.querySelector("#windows-error").textContent,
    state: document.querySelector("#windows").dataset.state,
  }));
  await page.fill("#windows-limit", "12 kn");
  await page.click("#windows-button");
  let shown = await dayShown();
  check(shown.state === "error" && /^haul_down\.max_operating_wind_m_s: “12 kn” is not a number/.test(shown.error ?? "") && shown.cells === 0 && !shown.timeline && !shown.list,
    `a limit that is not a number is named, and the day before is gone (${JSON.stringify(shown)})`);
  await page.fill("#windows-limit", "");
  await page.fill("#windows-data", "TAF EGLL 051100Z 0512/0618 24010KT FM051500 99999KT");
  await page.click("#windows-button");
  await page.waitForFunction(() => document.querySelector("#windows").dataset.state === "error", null, { timeout: 60_000 });
  shown = await dayShown();
  check(/^forecast\.data: TAF group 2 \(fm, from 051500Z\)/.test(shown.error ?? "") && shown.cells === 0,
    `a TAF the server refuses: its reason shown, no day (${JSON.stringify(shown)})`);
  await page.fill("#windows-data", "TAF EGLL 051100Z 0512/0618 05005KT 9999 SCT030");
  await page.click("#windows-button");
  await page.waitForFunction(() => document.querySelector("#windows").dataset.state === "done", null, { timeout: 120_000 });
  shown = await dayShown();
  check(shown.cells === 1 && shown.error === null && shown.timeline, `mended, the day is back (${JSON.stringify(shown)})`);

  // Across midnight the new day is marked: its first hour labelled with its day.
  phase = "midnight";
  await page.fill("#windows-data", "time,height_m,speed_m_s,gust_m_s\n2026-12-03T23:00,10,3,\n2026-12-04T00:00,10,3,\n2026-12-04T01:00,10,3,\n");
  await page.click("#windows-button");
  await page.waitForFunction(() => document.querySelectorAll("#windows-timeline button").length === 3 && document.querySelector("#windows").dataset.state === "done", null, { timeout: 120_000 });
  const days = await page.$$eval("#windows-timeline button", (bs) => bs.map((b) => `${b.classList.contains("new-day") ? "|" : ""}${b.querySelector(".hour").textContent}`));
  check(days.join(" ") === "23 |04/00 01", `a new day marked and labelled (${days.join(" ")})`);
  await context.close();

  // A day of distinct winds costs more than a direct answer may (a plan
  // each, priced by the server): its 422 too_large sends the panel to a
  // job, the one 4xx expected.
  const unexpected = consoleErrors.filter((e) => !(["drop", "ensemble", "taf", "break", "midnight"].includes(e.phase) && /status of 422/.test(e.text)));
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
