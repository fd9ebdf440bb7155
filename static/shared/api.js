// The page's HTTP: the JSON fetch wrapper (with the API token asked for once
// per browser session), background jobs with progress and cancel, and the
// unwrapping of a job's errors onto the request's own fields. Every panel
// uses S.{api, jobRunner, needsJob} (S: index.js).
"use strict";

import shared from "./core.js";

(function (shared) {
  // Servers with tokens configured answer 401 without one: asked for once,
  // kept for the browser session only (sessionStorage).
  const TOKEN_KEY = "tetherplan.apiToken";

  function storedToken() {
    try {
      return sessionStorage.getItem(TOKEN_KEY);
    } catch {
      return null;
    }
  }

  async function api(method, path, body, retried) {
    let res;
    try {
      const headers = body === undefined ? {} : { "content-type": "application/json" };
      const token = storedToken();
      if (token) headers.authorization = `Bearer ${token}`;
      res = await fetch(path, { method, headers, body: body === undefined ? undefined : JSON.stringify(body) });
      if (res.status === 401 && !retried) {
        // Another request was answered 401 too and its prompt got the token meanwhile.
        const meanwhile = storedToken();
        if (meanwhile && meanwhile !== token) return api(method, path, body, true);
        const entered = window.prompt(token ? "The API token was refused. API token:" : "This server needs an API token:");
        if (entered && entered.trim()) {
          try {
            sessionStorage.setItem(TOKEN_KEY, entered.trim());
          } catch {
            /* private mode: asked again next time */
          }
          return api(method, path, body, true);
        }
      }
    } catch (e) {
      return { ok: false, status: 0, body: { error: { code: "network", field: null, message: `cannot reach the server (${e.message})` } } };
    }
    let data = null;
    const text = await res.text();
    try {
      data = text ? JSON.parse(text) : null;
    } catch {
      data = { error: { code: "bad_response", field: null, message: `the server answered ${res.status} without a readable body` } };
    }
    return { ok: res.ok, status: res.status, body: data, headers: res.headers };
  }

  // A job submission names fields inside its `request` (`request.rates_m_s.count`):
  // drop that prefix so the error lands on the form's input.
  function unwrapJobError(body) {
    const err = body?.error;
    if (!err || typeof err.field !== "string" || !err.field.startsWith("request.")) return body;
    const field = err.field.slice("request.".length);
    const message = err.message.startsWith(`${err.field}: `) ? `${field}: ${err.message.slice(err.field.length + 2)}` : err.message;
    return { error: { ...err, field, message } };
  }

  // The direct route cannot answer this one (too large, busy, timed out): use a job.
  const needsJob = (r) => !r.ok && (r.body?.error?.code === "too_large" || r.status === 503 || r.status === 504);
  const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

  // A progress bar with a cancel button (#<prefix>job, <prefix>job-progress,
  // <prefix>job-text, <prefix>job-cancel; prefix "env-", "tr-", … or ""). Returns run(kind, request, what, setStatus) that
  // resolves to {result, via} or {status, error}; `log` collects
  // [status, progress] pairs, `slot.id` holds the running job's id.
  function jobRunner(prefix, { log = [], slot = {}, pollMs = 300 } = {}) {
    const el = (s) => document.getElementById(`${prefix}${s}`);
    const box = el("job");
    const bar = el("job-progress");
    const text = el("job-text");
    el("job-cancel")?.addEventListener("click", async () => {
      if (slot.id == null) return;
      text.textContent = "cancelling…";
      await api("DELETE", `/api/v1/jobs/${encodeURIComponent(slot.id)}`);
    });
    return async function run(kind, request, what, setStatus) {
      const submitted = await api("POST", "/api/v1/jobs", { kind, request });
      if (!submitted.ok) return { status: submitted.status, error: unwrapJobError(submitted.body) };
      const id = submitted.body.id;
      slot.id = id;
      log.length = 0;
      box.hidden = false;
      bar.value = 0;
      text.textContent = "queued";
      try {
        for (;;) {
          const r = await api("GET", `/api/v1/jobs/${encodeURIComponent(id)}`);
          if (!r.ok) return { status: r.status, error: r.body };
          const job = r.body;
          const progress = Number(job.progress) || 0;
          bar.value = progress;
          log.push([job.status, progress]);
          if (text.textContent !== "cancelling…" || job.status !== "running") text.textContent = `${job.status} · ${(progress * 100).toFixed(0)} %`;
          setStatus?.("busy", `Job ${id} (${what}): ${job.status}, ${(progress * 100).toFixed(0)} %`);
          if (job.status === "done") return { result: job.result, via: `job ${id}` };
          if (job.status === "failed" || job.status === "cancelled") {
            const body = job.error?.error ? job.error : { error: { code: job.status, field: null, message: `the job was ${job.status}` } };
            return { status: 200, error: unwrapJobError(body) };
          }
          await sleep(pollMs);
        }
      } finally {
        slot.id = null;
        box.hidden = true;
      }
    };
  }

  // A status line bound to its results box: anything but "ready" dims the box.
  function statusSetter(statusEl, resultsEl) {
    return (kind, text) => {
      if (resultsEl) {
        if (kind === "ready") delete resultsEl.dataset.stale;
        else resultsEl.dataset.stale = "";
      }
      statusEl.dataset.state = kind;
      statusEl.textContent = text;
    };
  }

  Object.assign(shared, { api, apiToken: storedToken, unwrapJobError, needsJob, sleep, jobRunner, statusSetter });
})(shared);
