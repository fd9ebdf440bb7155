import path from "node:path";
import { launch, target } from "./harness.mjs";
const { url, artifacts } = target("zz_shots.mjs");
const browser = await launch();
for (const [w, h, tag] of [[1280, 800, "d"], [390, 844, "p"]]) {
  const ctx = await browser.newContext({ viewport: { width: w, height: h }, deviceScaleFactor: 1, isMobile: tag === "p", hasTouch: tag === "p" });
  const page = await ctx.newPage();
  page.on("console", (m) => m.type() === "error" && console.log("console:", m.text()));
  await page.goto(url, { waitUntil: "load" });
  await page.waitForSelector('#plan-status[data-state="ready"]', { timeout: 30000 });
  await page.click("#env-button");
  await page.waitForSelector('#env-status[data-state="ready"]', { timeout: 30000 });
  await page.click("#plot-button");
  await page.waitForSelector('#status[data-state="ready"]', { timeout: 30000 });
  await page.click("#tr-run");
  await page.waitForSelector('#tr-status[data-state="ready"]', { timeout: 60000 });
  await page.click("#fr-run");
  await page.waitForSelector('#fr-status[data-state="ready"]', { timeout: 60000 });
  const total = await page.evaluate(() => document.documentElement.scrollHeight);
  let k = 0;
  for (let y = 0; y < total; y += h) {
    await page.evaluate((y) => window.scrollTo(0, y), y);
    await page.waitForTimeout(100);
    await page.screenshot({ path: path.join(artifacts, `shot_${tag}_${String(k++).padStart(2, "0")}.png`) });
  }
  console.log(tag, "pages", k, "height", total);
  await ctx.close();
}
await browser.close();
