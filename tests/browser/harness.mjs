// What the page's browser tests share: the command line (`node <script> <url>`),
// the artifacts folder, a check recorder, Chromium launched with the flags of
// NOTES.md (Debian's /usr/bin/chromium or $CHROMIUM; never a browser download),
// and a console watcher that records errors with the test phase they happened in.

import { chromium } from "playwright-core";
import { mkdirSync } from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";

/// The base URL from the command line (exit 2 without one) and tests/artifacts/.
export function target(script) {
  const url = process.argv[2];
  if (!url) {
    console.error(`usage: node ${script} <base url of a running tetherplan serve>`);
    process.exit(2);
  }
  const here = path.dirname(fileURLToPath(import.meta.url));
  const artifacts = path.resolve(here, "..", "artifacts");
  mkdirSync(artifacts, { recursive: true });
  return { url, artifacts };
}

/// A check recorder: `check(ok, what)` prints and collects the failures.
export function checker() {
  const failures = [];
  const check = (ok, what) => {
    console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
    if (!ok) failures.push(what);
  };
  return { failures, check };
}

/// Headless Chromium; playwright gives it a fresh temporary profile (the
/// equivalent of --user-data-dir=$(mktemp -d)).
export function launch() {
  return chromium.launch({
    executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
    headless: true,
    args: [
      "--no-sandbox",
      "--disable-gpu",
      "--disable-quic",
      "--disable-background-networking",
      "--disable-component-update",
      "--disable-sync",
      "--no-first-run",
    ],
  });
}

/// Records console errors, uncaught page errors and failed requests of `page`
/// into `errors`, each with the phase `phase()` names at that moment.
export function watchConsole(page, errors, phase) {
  page.on("console", (msg) => {
    if (msg.type() === "error") errors.push({ phase: phase(), text: msg.text() });
  });
  page.on("pageerror", (err) => errors.push({ phase: phase(), text: `uncaught: ${err.message}` }));
  page.on("requestfailed", (req) =>
    errors.push({ phase: phase(), text: `request failed: ${req.url()} ${req.failure()?.errorText}` }),
  );
}
