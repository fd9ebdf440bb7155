// Browser test of /docs (Swagger UI): every POST operation's "Try it out"
// with its example from the document, executed as is, answers 2xx; the page
// runs under the server's Content-Security-Policy with no console error.
//
//   node tests/browser/docs_page.mjs http://127.0.0.1:8080/
//
// Exit status 0 on success, 1 on a failed check, 2 on bad usage.

import path from "node:path";
import { checker, launch, target, watchConsole } from "./harness.mjs";

const { url, artifacts } = target("docs_page.mjs");
const { failures, check } = checker();
const browser = await launch();
const errors = [];
let phase = "load";
const page = await browser.newPage();
watchConsole(page, errors, () => phase);
const base = url.endsWith("/") ? url : `${url}/`;
const resp = await page.goto(`${base}docs/`);
check(resp.ok(), `/docs/ loads (${resp.status()})`);
const csp = resp.headers()["content-security-policy"] || "";
check(csp.includes("default-src 'self'"), "/docs/ carries the CSP");
await page.waitForSelector(".opblock-post", { timeout: 20000 });
const ops = await page.$$eval(".opblock-post", (els) => els.map((e) => e.id));
check(ops.length >= 7, `${ops.length} POST operations listed`);
// The actions on one flight (`/flights/{id}/…`) need a flight's id in the
// path, which the document cannot give as an example: tests/api_flights.rs
// and tests/api_examples.rs post them on a flight they create.
const needsFlightId = (id) => id.startsWith("operations-flights-") && id !== "operations-flights-create_flight";
for (const id of ops) {
  if (needsFlightId(id)) continue;
  phase = id;
  const block = page.locator(`#${id}`);
  await block.locator(".opblock-summary").first().click();
  await block.locator(".try-out__btn").click();
  await block.locator(".execute").click();
  const status = block.locator(".live-responses-table tbody .response-col_status").first();
  await status.waitFor({ timeout: 60000 });
  const code = (await status.innerText()).trim();
  check(/^2\d\d$/.test(code), `${id}: Try it out → ${code}`);
  // Clear the answer (large ones slow Swagger UI down) and fold the operation.
  const clear = block.locator(".btn-clear");
  if (await clear.count()) await clear.first().click();
  await block.locator(".opblock-summary").first().click();
}
await page.screenshot({ path: path.join(artifacts, "docs_page.png"), fullPage: false });
check(errors.length === 0, `no console errors (${JSON.stringify(errors).slice(0, 400)})`);
await browser.close();
process.exit(failures.length ? 1 : 0);
