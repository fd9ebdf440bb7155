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

  async function api(method, path, body) {
    let res;
    try {
      res = await fetch(path, {
        method,
        headers: body === undefined ? {} : { "content-type": "application/json" },
        body: body === undefined ? undefined : JSON.stringify(body),
      });
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
