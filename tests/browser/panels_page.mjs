// Browser test of the page's panels as separate units.
//
//   node tests/browser/panels_page.mjs http://127.0.0.1:8080/
//
// 1. Each panel's system-card declaration (S.declareCard in static/<panel>.js)
//    lists what the card's reader gives it, exactly: with every optional field
//    of the card filled, S.readSystem(errors, declaration) yields one value per
//    declared path ("wind.flow" and "wind.gust" count as one each), and a
//    " if preset" path only once its group's preset is chosen.
// 2. The frequency-response panel works with transient.js absent (served as an
//    empty module): it reads the transient form through shared/run.js, not
//    through the transient panel, and sweeps 4 frequencies.
// 3. The panels' module script tags in reverse order: every panel starts, and the
//    default plan is GO (the module graph loads shared/ first).
// Fails on any console error. Exit status 0 on success, 1 on a failed check,
// 2 on bad usage.

import { checker, launch, target, watchConsole } from "./harness.mjs";

const { url } = target("panels_page.mjs");
const { failures, check } = checker();
const browser = await launch();
const consoleErrors = [];
let phase = "load";

// Every declaration and what the card's reader gives for it, as paths.
async function declarationsAndSupplied(page) {
  return page.evaluate(async () => {
    const S = (await import(new URL("shared/index.js", document.baseURI).href)).default;
    const leaves = (obj, prefix = "") =>
      Object.entries(obj).flatMap(([k, v]) => {
        const path = prefix + k;
        return v && typeof v === "object" && path !== "wind.flow" && path !== "wind.gust" ? leaves(v, `${path}.`) : [path];
      });
    const out = {};
    for (const [panel, needs] of Object.entries(S.cardDeclarations)) {
      const errors = [];
      out[panel] = { needs: [...needs], supplied: leaves(S.readSystem(errors, needs)), errors };
    }
    return out;
  });
}

try {
  const context = await browser.newContext({ viewport: { width: 1100, height: 1400 } });
  const page = await context.newPage();
  watchConsole(page, consoleErrors, () => phase);
  // transient.js served empty: the transient panel is absent.
  await page.route(/\/transient\.js(\?.*)?$/, (route) => route.fulfill({ status: 200, contentType: "text/javascript", body: "" }));
  const response = await page.goto(url, { waitUntil: "load" });
  check(response && response.ok(), `GET ${url} → ${response?.status()}`);

  // ---------- the declarations ----------
  phase = "declarations";
  // Every optional field of the card filled, no preset chosen.
  await page.click("#system-card details.more summary");
  for (const [sel, value] of [
    ["#cable-breaking", "20000"], ["#cable-cn", "1.2"], ["#cable-ea", "1e6"], ["#winch-jerk", "1"], ["#gust-speed", "9"],
  ]) {
    await page.fill(sel, value);
  }
  const expected = ["chart", "bands", "dynamics", "envelope", "frequency", "plan", "windows"];
  let got = await declarationsAndSupplied(page);
  const panels = Object.keys(got).sort();
  // transient.js is absent here, so no "transient" declaration.
  check(expected.every((p) => panels.includes(p)) && !panels.includes("transient"), `panels that declared their card needs: ${panels.join(", ")}`);
  // What a declaration should get: every path, but a group's preset and its
  // " if preset" paths only once that preset is chosen.
  const expectedOf = (needs, chosen) =>
    needs
      .filter((p) => {
        const group = p.split(".")[0];
        return !(p.endsWith(" if preset") || p.endsWith(".preset")) || chosen.includes(group);
      })
      .map((p) => p.replace(/ if preset$/, ""));
  const compare = (got, chosen, what) => {
    for (const [panel, { needs, supplied, errors }] of Object.entries(got)) {
      const want = expectedOf(needs, chosen);
      const same = want.length === supplied.length && want.every((p, i) => p === supplied[i]);
      check(same && errors.length === 0, `${panel}${what}: the card supplies exactly the ${want.length} paths it declares, in order` +
        `${same ? "" : ` (want ${want.join(", ")}; got ${supplied.join(", ")})`}${errors.length ? ` (errors: ${JSON.stringify(errors)})` : ""}`);
    }
  };
  compare(got, [], "");
  // A material chosen (it clears the mass and strength: typed again): the
  // preset and the " if preset" paths (the calm-air panels' diameter) too.
  await page.selectOption("#cable-preset", "dyneema");
  await page.fill("#mass-per-length", "0.078");
  await page.fill("#cable-breaking", "20000");
  compare(await declarationsAndSupplied(page), ["cable"], " with a material chosen");
  await context.close();

  // ---------- the frequency response without transient.js ----------
  phase = "frequency-alone";
  const context2 = await browser.newContext({ viewport: { width: 1100, height: 1400 } });
  const page2 = await context2.newPage();
  watchConsole(page2, consoleErrors, () => phase);
  await page2.route(/\/transient\.js(\?.*)?$/, (route) => route.fulfill({ status: 200, contentType: "text/javascript", body: "" }));
  await page2.goto(url, { waitUntil: "load" });
  check((await page2.getAttribute("#tr-status", "data-state")) === "idle" && (await page2.evaluate(() => window.tetherplanTransient.result)) === null,
    "transient panel absent (its status untouched, no run)");
  await page2.fill("#fr-count", "4");
  await page2.waitForFunction(() => document.querySelector("#fr-hint").textContent === "4 runs", null, { timeout: 5_000 }).catch(() => {});
  check((await page2.textContent("#fr-hint")) === "4 runs", `frequency hint follows its own form (${await page2.textContent("#fr-hint")})`);
  // A transient-form input the sweep reads: its hint follows it without transient.js.
  await page2.fill("#tr-duration", "x");
  check((await page2.textContent("#fr-hint")) === "", "frequency hint cleared by an invalid duration in the transient form");
  await page2.fill("#tr-duration", "60");
  await page2.click("#fr-run");
  await page2.waitForSelector('#fr-status[data-state="ready"], #fr-status[data-state="error"]', { timeout: 120_000 });
  const st = await page2.getAttribute("#fr-status", "data-state");
  check(st === "ready", `frequency response of 4 computed without transient.js (status: ${await page2.textContent("#fr-status")})`);
  if (st === "ready") {
    const fr = await page2.evaluate(() => {
      const s = window.tetherplanTransient.fr;
      return { x: Array.from(s.plot.data[0]), y: Array.from(s.plot.data[1]), req: s.request };
    });
    check(fr.x.length === 4 && fr.y.every((v) => Number.isFinite(v) && v > 0), `peak amplitudes plotted (${fr.y.map((v) => v.toPrecision(3)).join(", ")} m)`);
    check(fr.req.duration_s === 60 && fr.req.profile.kind === "constant_rate" && fr.req.aero.radius_m === 0.5 && fr.req.initial_length_m === 1,
      "the sweep's request read the transient form (60 s, constant rate, r = 0.5 m, L₀ = 1 m)");
  }
  await context2.close();

  // ---------- the panels' scripts in reverse order ----------
  phase = "reversed";
  const context3 = await browser.newContext({ viewport: { width: 1100, height: 1400 } });
  const page3 = await context3.newPage();
  watchConsole(page3, consoleErrors, () => phase);
  let reversed = [];
  await page3.route((u) => u.pathname === new URL(url).pathname, async (route) => {
    const html = await (await route.fetch()).text();
    const tags = html.match(/<script type="module" src="[^"]+"><\/script>\n/g) || [];
    reversed = tags.map((t) => /src="([^"]+)"/.exec(t)[1]).reverse();
    const body = html.replace(tags.join(""), [...tags].reverse().join(""));
    await route.fulfill({ status: 200, contentType: "text/html; charset=utf-8", body });
  });
  await page3.goto(url, { waitUntil: "load" });
  await page3.waitForSelector('#verdict[data-state="go"], #verdict[data-state="no-go"], #verdict[data-state="error"]', { timeout: 60_000 });
  const rev = await page3.evaluate(() => ({
    verdict: document.querySelector("#verdict").dataset.state,
    frHint: document.querySelector("#fr-hint").textContent,
    globals: ["tetherplan", "tetherplanPlan", "tetherplanEnvelope", "tetherplanDynamics", "tetherplanTransient", "tetherplanWindows"].filter((g) => !window[g]),
  }));
  check(reversed.length >= 7 && rev.verdict === "go" && rev.frHint === "16 runs" && rev.globals.length === 0,
    `panels loaded in reverse order (${reversed.join(", ")}): the default plan is ${rev.verdict}, frequency hint “${rev.frHint}”${rev.globals.length ? `, missing ${rev.globals.join(", ")}` : ""}`);
  await context3.close();

  // ---------- console ----------
  for (const e of consoleErrors) console.log(`  console error (${e.phase}): ${e.text}`);
  check(consoleErrors.length === 0, `no console errors (${consoleErrors.length})`);
} catch (e) {
  console.error(`FAIL ${e.stack || e}`);
  failures.push(String(e));
} finally {
  await browser.close();
}

console.log(failures.length ? `${failures.length} check(s) failed` : "all browser checks passed");
process.exit(failures.length ? 1 : 0);
