// Helpers shared by the page's scripts (app.js: the deployment chart;
// transient.js: transient runs and frequency response): the JSON fetch
// wrapper, job-error unwrapping and field-error text. No build step: loaded
// before them, exposed as `window.tetherplanCommon`.
"use strict";

window.tetherplanCommon = (function () {
  function clearFieldError(input) {
    const box = input.closest(".field");
    box?.querySelector(".field-error")?.remove();
    input.removeAttribute("aria-invalid");
    input.removeAttribute("aria-describedby");
  }

  function fieldMessage(field, message) {
    let text = message.startsWith(`${field}: `) ? message.slice(field.length + 2) : message;
    const index = /\[(\d+)\]$/.exec(field);
    if (index) text = `entry ${Number(index[1]) + 1}: ${text}`;
    return text;
  }

  function showFormError(el, message) {
    el.textContent = message;
    el.hidden = !message;
  }

  function unwrapJobError(body) {
    const err = body?.error;
    if (!err || typeof err.field !== "string" || !err.field.startsWith("request.")) return body;
    const field = err.field.slice("request.".length);
    const message = err.message.startsWith(`${err.field}: `) ? `${field}: ${err.message.slice(err.field.length + 2)}` : err.message;
    return { error: { ...err, field, message } };
  }

  // API token (servers with TETHERPLAN_API_TOKENS answer 401 without one):
  // asked for once, kept for the browser session only (sessionStorage).
  const TOKEN_KEY = "tetherplan.apiToken";

  function storedToken() {
    try { return sessionStorage.getItem(TOKEN_KEY); } catch { return null; }
  }

  async function api(method, path, body, retried) {
    let res;
    try {
      const headers = body === undefined ? {} : { "content-type": "application/json" };
      const token = storedToken();
      if (token) headers.authorization = `Bearer ${token}`;
      res = await fetch(path, {
        method,
        headers,
        body: body === undefined ? undefined : JSON.stringify(body),
      });
      if (res.status === 401 && !retried) {
        const entered = window.prompt(token ? "The API token was refused. API token:" : "This server needs an API token:");
        if (entered && entered.trim()) {
          try { sessionStorage.setItem(TOKEN_KEY, entered.trim()); } catch { /* private mode: ask again next time */ }
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
      data = { error: { code: "bad_response", field: null, message: `HTTP ${res.status}: ${text.slice(0, 200)}` } };
    }
    return { ok: res.ok, status: res.status, body: data, headers: res.headers };
  }

  return { clearFieldError, fieldMessage, showFormError, unwrapJobError, api };
})();
