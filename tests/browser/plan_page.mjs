// Browser test of the verdict, the system card and today's plan: the first
// screen of the page.
//
//   node tests/browser/plan_page.mjs http://127.0.0.1:8080/
//
// The issue-20 scenario, typed into the inputs named by their request paths:
// 0.078 kg/m, 6 mm tether, F = 1000 N, m = 10 kg, C_D 0.3 on 20 m², a uniform
// 6 m/s wind, to 1000 m altitude: NO-GO naming the wind (the API's
// wind_blowdown, checked against the answer's reachable altitude); to 900 m:
// GO with the tether length shown (the answer's wind.target_length_m).
// Editing an input turns #verdict to `stale` at once and disables Print and
// the downloads; a negative buoyancy turns it to `error` with the message in
// plain words beside aerostat.net_buoyancy_n. A shared URL (and one written
// by hand with the request paths) plans at once with the same verdict. The
// card's values reach the envelope panel's request. A turbulence intensity
// (wind.gust.turbulence_intensity_nondim) puts the gust's figures beside the
// mean's in the key figures, and a rating between the mean's and the gust's
// tension turns the verdict NO-GO naming the gust. A forecast gives the
// haul-down deadline on its own line (none by default). Print: the verdict,
// date and time, version, inputs with units, legends. The verdict's box is
// inside the first screen at 1440×900, 390×844 and in print; the phone's
// table says that it scrolls. Screenshots: tests/artifacts/plan_page*.png.

import { readFileSync } from "node:fs";
import path from "node:path";
import { checker, launch, target, watchConsole } from "./harness.mjs";

const { url, artifacts } = target("plan_page.mjs");
const { failures, check } = checker();
const browser = await launch();
const consoleErrors = [];
let phase = "load";

const SCENARIO = {
  "cable.preset": "",
  "cable.diameter_m": "0.006",
  "cable.mass_per_length_kg_m": "0.078",
  "cable.breaking_strength_n": "",
  "aerostat.net_buoyancy_n": "1000",
  "aerostat.mass_kg": "10",
  "aerostat.drag_coefficient_nondim": "0.3",
  "aerostat.reference_area_m2": "20",
  "wind.flow.kind": "uniform",
  "wind.flow.speed_m_s": "6",
  "target_elevation_m": "1000",
};
const field = (name) => `[name="${name}"]`;

// Waits until #verdict is current (go / no-go) or failed; returns its state, texts and the plan.
async function verdictOf(page) {
  await page.waitForFunction(() => ["go", "no-go", "error"].includes(document.querySelector("#verdict")?.dataset.state), null, { timeout: 60_000 });
  return page.evaluate(() => {
    const v = document.querySelector("#verdict");
    const r = v.getBoundingClientRect();
    return {
      state: v.dataset.state,
      word: v.querySelector(".word").textContent.trim(),
      why: v.querySelector(".why").textContent.trim(),
      tension: v.querySelector(".tension-check").hidden ? "" : v.querySelector(".tension-check").textContent.trim(),
      deadline: v.querySelector(".deadline").hidden ? "" : v.querySelector(".deadline").textContent.trim(),
      figures: Object.fromEntries([...v.querySelectorAll(".key-figures dd")].map((dd) => [dd.dataset.figure, dd.textContent.trim()])),
      box: { top: r.top, bottom: r.bottom, left: r.left, right: r.right },
      live: v.getAttribute("aria-live"),
      plan: window.tetherplanPlan?.plan ?? null,
      request: window.tetherplanPlan?.request ?? null,
    };
  });
}

async function fillScenario(page, values) {
  for (const [name, value] of Object.entries(values)) {
    const el = page.locator(field(name));
    if ((await el.evaluate((e) => e.tagName)) === "SELECT") await el.selectOption(value);
    else await el.fill(value);
  }
}

const inViewport = (box, vp) => box.top >= 0 && box.left >= 0 && box.bottom <= vp.height && box.right <= vp.width;
const disabled = (page) => page.evaluate(() => ["plan-print", "plan-csv", "plan-json"].map((id) => document.getElementById(id).disabled));

let exitCode = 0;
try {
  const desk = { width: 1440, height: 900 };
  const context = await browser.newContext({ viewport: desk, acceptDownloads: true });
  const page = await context.newPage();
  watchConsole(page, consoleErrors, () => phase);
  const response = await page.goto(url, { waitUntil: "load" });
  check(response && response.ok(), `GET ${url} → ${response?.status()}`);

  phase = "defaults";
  const first = await verdictOf(page);
  check(["go", "no-go"].includes(first.state), `the page plans its defaults at once (${first.state}: ${first.why})`);
  check(first.live === "polite" || first.live === "assertive", `the verdict is an aria-live region (${first.live})`);
  check((await page.inputValue(field("haul_down.forecast"))) === "", "no example forecast: the forecast entry is empty by default");
  check(/none set/.test(first.deadline), `the haul-down deadline on its own line says none is set (${first.deadline})`);
  const names = ["aerostat.net_buoyancy_n", "aerostat.mass_kg", "aerostat.drag_coefficient_nondim", "aerostat.reference_area_m2", "aerostat.lift_coefficient_nondim",
    "cable.diameter_m", "cable.mass_per_length_kg_m", "cable.breaking_strength_n", "cable.preset", "wind.flow.speed_m_s", "wind.flow.kind",
    "target_elevation_m", "winch.max_rate_m_s", "winch.max_acceleration_m_s2", "winch.max_jerk_m_s3", "required_safety_factor_nondim", "lift_reserve_nondim"];
  const counts = await page.evaluate((ns) => ns.map((n) => document.querySelectorAll(`[name="${n}"]`).length), names);
  check(counts.every((c) => c === 1), `every system and plan input exists once under its request path (${names.filter((n, i) => counts[i] !== 1).join(", ") || "all"})`);

  phase = "scenario 1000 m";
  await fillScenario(page, SCENARIO);
  check((await page.getAttribute("#verdict", "data-state")) === "stale", "typing into the inputs makes the verdict stale at once");
  await page.click("#plan-button");
  const nogo = await verdictOf(page);
  check(nogo.state === "no-go" && nogo.word === "NO-GO", `1000 m in a 6 m/s wind: NO-GO (${nogo.state}, “${nogo.word}”)`);
  check(/wind/i.test(nogo.why) && /6(\.0)? m\/s/.test(nogo.why), `the headline names the wind (“${nogo.why}”)`);
  const reach = nogo.plan?.wind?.reachable_altitude_m;
  check(nogo.plan?.binding_limit === "wind_blowdown" && reach > 900 && reach < 1000, `the API's limit is the blow-down: at most ${reach?.toFixed(1)} m reachable`);
  check(nogo.why.includes(`${Math.round(reach)} m`), `the headline gives the reachable altitude (${Math.round(reach)} m)`);
  check(!/binding|static lift|_|limit:/i.test(nogo.why), "no jargon in the headline");
  check(nogo.request?.wind?.flow?.speed_m_s === 6 && nogo.request?.cable?.diameter_m === 0.006 && nogo.request?.aerostat?.drag_coefficient_nondim === 0.3 &&
    nogo.request?.aerostat?.reference_area_m2 === 20 && nogo.request?.target_elevation_m === 1000, "the request carries the scenario under the §9 names");
  check(/Tension NOT checked/.test(nogo.tension), `without a breaking strength: “${nogo.tension}”`);
  const loud = await page.evaluate(() => {
    const t = getComputedStyle(document.querySelector("#verdict .tension-check"));
    const w = getComputedStyle(document.querySelector("#verdict .word"));
    return { tw: Number(t.fontWeight), ww: Number(w.fontWeight), tc: t.color, wc: w.color, ts: parseFloat(t.fontSize) };
  });
  check(loud.tw >= 700 && loud.tc === loud.wc && loud.ts >= 16, `“tension NOT checked” as loud as NO-GO (weight ${loud.tw}, ${loud.tc} vs ${loud.wc}, ${loud.ts} px)`);
  check(inViewport(nogo.box, desk), `verdict above the fold at 1440×900 (bottom ${nogo.box.bottom.toFixed(0)} px)`);
  await page.screenshot({ path: path.join(artifacts, "plan_page_nogo.png") });

  phase = "stale";
  await page.fill(field("target_elevation_m"), "900");
  const stale = await page.evaluate(() => ({ state: document.querySelector("#verdict").dataset.state, text: document.querySelector("#verdict").textContent, output: document.querySelector("#plan-output").hidden }));
  check(stale.state === "stale" && /inputs changed: plan again/i.test(stale.text.replace(/\s+/g, " ")), `editing the target turns the verdict to stale at once (“${stale.text.trim().replace(/\s+/g, " ").slice(0, 60)}”)`);
  check((await disabled(page)).every(Boolean), "stale: Print and the downloads are disabled");
  check(stale.output, "stale: the old figures, table and plots are gone");
  await page.screenshot({ path: path.join(artifacts, "plan_page_stale.png") });

  phase = "scenario 900 m";
  await page.click("#plan-button");
  const go = await verdictOf(page);
  const L = go.plan?.wind?.target_length_m;
  check(go.state === "go" && go.word === "GO", `900 m in a 6 m/s wind: GO (${go.state}: ${go.why})`);
  check(L > 900 && go.why.includes(`${Math.round(L)} m of tether`), `the headline gives the tether the altitude needs (${L?.toFixed(1)} m: “${go.why}”)`);
  check(go.figures["Tether needed"] === `${L?.toFixed(1)} m`, `the card shows the tether needed (${go.figures["Tether needed"]})`);
  const angle = go.plan?.wind?.blowdown_angle_deg;
  check(angle > 0 && go.figures["Blow-down angle"] === `${angle.toFixed(1)}°`, `the card shows the blow-down angle (${go.figures["Blow-down angle"]})`);
  check(go.figures["Peak tension"] === `${go.plan?.limits?.peak_tension_n?.toFixed(0)} N` && go.figures["Safety factor"] === "not checked",
    `peak tension and safety factor shown (${go.figures["Peak tension"]}, ${go.figures["Safety factor"]})`);
  check((await disabled(page)).every((d) => !d), "current again: Print and the downloads are enabled");
  check(inViewport(go.box, desk), `GO above the fold at 1440×900 (bottom ${go.box.bottom.toFixed(0)} px)`);
  await page.screenshot({ path: path.join(artifacts, "plan_page_go.png") });
  const csvDownload = page.waitForEvent("download");
  await page.click("#plan-csv");
  const csv = readFileSync(await (await csvDownload).path(), "utf8");
  check(csv.includes("# input wind.flow.speed_m_s,6") && csv.includes("# input cable.diameter_m,0.006") && csv.includes("# verdict,go"), "CSV records the verdict and the inputs");

  phase = "with a breaking strength";
  await page.fill(field("cable.breaking_strength_n"), "20000");
  await page.click("#plan-button");
  const rated = await verdictOf(page);
  const sf = rated.plan?.limits?.min_safety_factor_nondim;
  check(rated.state === "go" && /Tension checked/.test(rated.tension) && sf > 5 && rated.figures["Safety factor"] === sf.toFixed(1),
    `with 20 kN: tension checked, safety factor ${sf?.toFixed(2)} (${rated.tension})`);
  check(Math.abs(sf - 20000 / rated.plan.limits.peak_tension_n) < 1e-9 * sf, "safety factor = breaking strength / peak tension");

  phase = "gust";
  await page.fill(field("wind.gust.turbulence_intensity_nondim"), "0.15");
  await page.click("#plan-button");
  const gusty = await verdictOf(page);
  const gw = gusty.plan?.wind?.gust;
  check(gusty.request?.wind?.gust?.turbulence_intensity_nondim === 0.15, `the request carries wind.gust (${JSON.stringify(gusty.request?.wind?.gust)})`);
  check(gusty.state === "go" && gw && Math.abs(gw.reference_speed_m_s - 6 * 1.45) < 1e-9, `a 15 % turbulence: GO, the gust at 6 × 1.45 m/s (${gw?.reference_speed_m_s})`);
  const gustFigures = await page.evaluate(() => Object.fromEntries([...document.querySelectorAll("#verdict .key-figures .gust-figure")].map((s) => [s.closest("dd").dataset.figure, s.dataset.gust])));
  check(gustFigures["Peak tension"] === `${gusty.plan.limits.gust_peak_tension_n.toFixed(0)} N` && gustFigures["Blow-down angle"] === `${gw.blowdown_angle_deg.toFixed(1)}°` &&
    gustFigures["Safety factor"] === gusty.plan.limits.gust_min_safety_factor_nondim.toFixed(1),
    `the gust's figures beside the mean's: ${JSON.stringify(gustFigures)}`);
  check(gusty.figures["Altitude in the gust"] === `${gw.target_altitude_m.toFixed(0)} m` && gw.target_altitude_m < 900,
    `the altitude in the gust is shown (${gusty.figures["Altitude in the gust"]})`);
  check(gusty.figures["Peak tension"].startsWith(`${gusty.plan.limits.peak_tension_n.toFixed(0)} N`), `the mean's peak tension first (${gusty.figures["Peak tension"]})`);
  // A rating between the mean's and the gust's tension at rest: NO-GO naming the gust.
  const between = 5 * 0.5 * (gusty.plan.wind.target_max_tension_n + gw.target_max_tension_n);
  await page.fill(field("cable.breaking_strength_n"), between.toFixed(0));
  await page.click("#plan-button");
  const broken = await verdictOf(page);
  check(broken.state === "no-go" && broken.word === "NO-GO" && broken.plan?.binding_limit === "gust_tension_limit",
    `a gust that breaks the tension limit: NO-GO (${broken.state}, ${broken.plan?.binding_limit})`);
  check(/gust/i.test(broken.why) && !/_/.test(broken.why), `the headline names the gust (“${broken.why}”)`);
  // A turbulent gust's tension is judged at its dynamic value (docs/gust_check.md): the operator is told.
  check(broken.plan?.wind?.gust?.dynamic_tension_factor_nondim === 1.41 && broken.why.includes("× 1.41"),
    `the headline says the gust's tension is taken at the dynamic factor 1.41 (“${broken.why}”)`);
  await page.fill(field("wind.gust.turbulence_intensity_nondim"), "");
  await page.fill(field("cable.breaking_strength_n"), "");

  phase = "error";
  await page.fill(field("aerostat.net_buoyancy_n"), "-1000");
  await page.click("#plan-button");
  const failed = await verdictOf(page);
  check(failed.state === "error", `a negative buoyancy turns the verdict to error (${failed.state}: ${failed.word} ${failed.why})`);
  const err = await page.evaluate(() => {
    const input = document.querySelector('[name="aerostat.net_buoyancy_n"]');
    const p = input.closest(".field").querySelector(".field-error");
    return { text: p?.textContent ?? "", invalid: input.getAttribute("aria-invalid"), described: input.getAttribute("aria-describedby") === p?.id };
  });
  check(err.text.length > 0 && err.invalid === "true" && err.described, `the message sits beside aerostat.net_buoyancy_n (“${err.text}”)`);
  check(!/aerostat\.|_n\b|TETHERPLAN_|got null/.test(err.text + failed.why), `in plain words, no API paths (“${failed.why}”)`);
  check((await disabled(page)).every(Boolean), "error: Print and the downloads are disabled");
  await page.screenshot({ path: path.join(artifacts, "plan_page_error.png") });
  await page.fill(field("aerostat.net_buoyancy_n"), "1000");
  check((await page.locator('.field:has([name="aerostat.net_buoyancy_n"]) .field-error').count()) === 0, "the error clears when the field is edited");

  phase = "shared URL";
  await page.click("#plan-button");
  const again = await verdictOf(page);
  const shared = page.url();
  check(["aerostat.net_buoyancy_n=1000", "wind.flow.speed_m_s=6", "target_elevation_m=900", "cable.diameter_m=0.006", "winch.max_rate_m_s=40"].every((s) => shared.includes(s)),
    `the URL carries the inputs under their request paths (${shared.slice(0, 140)}…)`);
  const p2 = await context.newPage();
  watchConsole(p2, consoleErrors, () => phase);
  await p2.goto(shared, { waitUntil: "load" });
  const reopened = await verdictOf(p2);
  check(reopened.state === again.state && reopened.why === again.why, `the shared URL plans at once, same verdict (${reopened.state}: ${reopened.why})`);
  await p2.close();
  const handWritten = `${url}?${new URLSearchParams(SCENARIO).toString()}`;
  const p3 = await context.newPage();
  watchConsole(p3, consoleErrors, () => phase);
  await p3.goto(handWritten, { waitUntil: "load" });
  const hand = await verdictOf(p3);
  check(hand.state === "no-go" && hand.why === nogo.why, `a URL written with the request paths plans at once: ${hand.state} (${hand.why})`);
  await p3.close();

  phase = "envelope";
  await page.fill(field("aerostat.net_buoyancy_n"), "1500");
  await page.fill(field("aerostat.mass_kg"), "12");
  await page.fill("#env-wcount", "10");
  await page.fill("#env-lcount", "10");
  await page.click("#env-button");
  await page.waitForFunction(() => ["ready", "error"].includes(document.querySelector("#env-status").dataset.state), null, { timeout: 60_000 });
  const env = await page.evaluate(() => ({ req: window.tetherplanEnvelope.request, status: document.querySelector("#env-status").textContent }));
  check(env.req?.aerostat?.net_buoyancy_n === 1500 && env.req?.aerostat?.mass_kg === 12 && env.req?.aerostat?.drag_coefficient_nondim === 0.3 &&
    env.req?.aerostat?.reference_area_m2 === 20 && env.req?.cable?.diameter_m === 0.006 && env.req?.cable?.mass_per_length_kg_m === 0.078,
    `the system entered once reaches the envelope's request (${JSON.stringify(env.req?.aerostat)}; ${env.status.slice(0, 80)})`);
  check(page.url().includes("envelope.wind_speeds_m_s.count=10") && page.url().includes("envelope.tether_lengths_m.count=10"), "the envelope's inputs are in the URL with its prefix");
  await page.fill(field("aerostat.net_buoyancy_n"), "1000");
  await page.fill(field("aerostat.mass_kg"), "10");
  check((await page.getAttribute("#env-status", "data-state")) === "stale", "the card's edit marks the envelope stale");

  phase = "forecast";
  await page.fill(field("haul_down.forecast"), "0:5, 30:9, 60:15");
  await page.fill(field("haul_down.max_operating_wind_m_s"), "12");
  await page.click("#plan-button");
  const dl = await verdictOf(page);
  const h = dl.plan?.haul_down;
  check(h && h.wind_exceeds_limit_at_s > 1800 && h.wind_exceeds_limit_at_s < 3600 && /start hauling down by/.test(dl.deadline),
    `a forecast gives the haul-down deadline on its own line (${dl.deadline}; wind over the limit at ${h?.wind_exceeds_limit_at_s?.toFixed(0)} s)`);
  await page.fill(field("haul_down.forecast"), "");
  await page.click("#plan-button");
  await verdictOf(page);

  phase = "print";
  const version = await page.evaluate(async () => (await (await fetch("healthz")).json()).version);
  await page.emulateMedia({ media: "print" });
  await page.evaluate(() => window.dispatchEvent(new Event("beforeprint")));
  const print = await page.evaluate(() => {
    const vis = (sel) => {
      const el = document.querySelector(sel);
      return !!el && getComputedStyle(el).display !== "none" && el.getClientRects().length > 0;
    };
    const v = document.querySelector("#verdict").getBoundingClientRect();
    return {
      form: vis("#plan-form"),
      chart: vis("#chart-form"),
      envelope: vis("#envelope"),
      verdict: vis("#verdict"),
      table: vis("#plan-phases"),
      legend: vis("#plan-plot-tension .u-legend"),
      inputs: document.querySelector("#plan-inputs").textContent,
      stamp: document.querySelector(".print-stamp").textContent,
      stampShown: vis(".print-stamp"),
      box: { top: v.top, bottom: v.bottom, left: v.left, right: v.right },
    };
  });
  check(!print.form && !print.chart && !print.envelope, "print hides the forms and the other panels");
  check(print.verdict && print.table && print.legend, "print shows the verdict, the operator's table and the plots' legends");
  check(["Net buoyancy", "1000 N", "Wind speed", "6 m/s", "Target altitude", "900 m", "Diameter", "0.006 m", "Breaking strength", "not checked"].every((k) => print.inputs.includes(k)),
    "print lists the inputs with their units");
  check(print.stampShown && print.stamp.includes(version) && /\d{1,2}:\d{2}/.test(print.stamp), `print carries the date, time and version (“${print.stamp.trim()}”)`);
  check(inViewport(print.box, desk), `print: the verdict on the first screen (bottom ${print.box.bottom.toFixed(0)} px)`);
  await page.screenshot({ path: path.join(artifacts, "plan_page_print.png"), fullPage: true });
  const pdf = await page.pdf({ path: path.join(artifacts, "plan_page_print.pdf"), format: "A4", printBackground: true });
  const pages = (pdf.toString("latin1").match(/\/Type\s*\/Page[^s]/g) || []).length;
  check(pages >= 1 && pages <= 2, `print layout fits one or two A4 pages (${pages})`);
  await page.emulateMedia({ media: "screen" });

  phase = "phone";
  const phoneVp = { width: 390, height: 844 };
  const phone = await browser.newContext({ viewport: phoneVp, isMobile: true, hasTouch: true });
  const pp = await phone.newPage();
  watchConsole(pp, consoleErrors, () => phase);
  await pp.goto(shared, { waitUntil: "load" });
  const pv = await verdictOf(pp);
  check(pv.state === again.state, `phone: the shared URL's verdict (${pv.state})`);
  check(inViewport(pv.box, phoneVp), `phone: the verdict above the fold at 390×844 (bottom ${pv.box.bottom.toFixed(0)} px)`);
  const overflow = await pp.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
  check(overflow <= 1, `phone: no horizontal overflow of the page (${overflow} px)`);
  await pp.screenshot({ path: path.join(artifacts, "plan_page_390.png") });
  const table = await pp.evaluate(() => {
    const wrap = document.querySelector("#plan-phases").closest(".table-wrap");
    const hint = wrap.previousElementSibling;
    return { scrolls: wrap.scrollWidth > wrap.clientWidth + 1, marked: wrap.classList.contains("scrolls"), hint: hint.classList.contains("scroll-hint") && !hint.hidden };
  });
  check(!table.scrolls || (table.marked && table.hint), `phone: the operator's table says that it scrolls (scrolls ${table.scrolls}, hint ${table.hint})`);
  await pp.evaluate(() => document.getElementById("plan-phases").scrollIntoView({ block: "center" }));
  await pp.screenshot({ path: path.join(artifacts, "plan_page_390_table.png") });
  await pp.emulateMedia({ media: "print" });
  const pbox = await pp.evaluate(() => document.querySelector("#verdict").getBoundingClientRect().bottom);
  check(pbox <= phoneVp.height, `phone print: the verdict on the first screen (bottom ${pbox.toFixed(0)} px)`);
  await pp.screenshot({ path: path.join(artifacts, "plan_page_390_print.png") });
  await phone.close();

  const unexpected = consoleErrors.filter((e) => !(e.phase === "error" && /422|Unprocessable/.test(e.text)));
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
