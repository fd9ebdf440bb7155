// The page's form code, shared by every panel: numbers read from inputs named
// by their request path (`name="aerostat.net_buoyancy_n"`), the system card
// (entered once, read by every panel), API errors in plain words beside the
// input their `field` names, and the URL query (each panel's inputs under the
// same names, other panels' with their prefix: `envelope.tether_lengths_m.max`).
"use strict";

import shared from "./core.js";

(function (shared) {
  const visible = (el) => !!el && !el.closest("[hidden]");
  const card = () => document.getElementById("system-card");

  // ---------- inputs by name ----------

  // The visible input named `name` in the first of `roots` that has one.
  function named(roots, name) {
    for (const root of [].concat(roots)) {
      if (!root) continue;
      const all = [...root.querySelectorAll(`[name="${CSS.escape(name)}"]`)];
      const el = all.find(visible) || null;
      if (el) return el;
    }
    return null;
  }

  // A number from the input named `name`; errors collect {field, message}.
  // Blank optional inputs give `undefined`; an absent input gives `fallback`.
  function readNumber(roots, name, errors, { integer = false, optional = false, fallback = null } = {}) {
    const el = named(roots, name);
    if (!el) return fallback;
    const text = el.value.trim();
    if (text === "" && optional) return undefined;
    const value = Number(text);
    if (text === "" || !Number.isFinite(value)) {
      errors.push({ field: name, message: text === "" ? "enter a number" : `“${text}” is not a number` });
      return null;
    }
    if (integer && !Number.isInteger(value)) {
      errors.push({ field: name, message: `enter a whole number (not ${text})` });
      return null;
    }
    return value;
  }

  // Leaves out keys whose value is undefined (optional inputs left blank).
  const compact = (obj) => Object.fromEntries(Object.entries(obj).filter(([, v]) => v !== undefined));

  // ---------- errors beside their fields, in plain words ----------

  // The label of an input, without its unit in brackets: "Net buoyancy".
  function labelOf(el) {
    const label = el && document.querySelector(`label[for="${CSS.escape(el.id)}"]`);
    return label ? label.textContent.replace(/\s*\(.*$/, "").trim() : null;
  }

  // An API message in the operator's words: no request paths, no settings'
  // environment names, no "got null".
  function plainMessage(field, message) {
    let text = String(message ?? "");
    if (field && text.startsWith(`${field}: `)) text = text.slice(field.length + 2);
    text = text.replace(/^[a-z_][\w.[\]]*: /, "");
    text = text
      .replace(/must be a number, got null/g, "enter a number")
      .replace(/must be a number, got "([^"]*)"/g, "“$1” is not a number")
      .replace(/is required \(or density_kg_m3 with area_m2\)/g, "enter the mass per length")
      .replace(/is required/g, "enter a value")
      .replace(/\bTETHERPLAN_[A-Z_]+\b/g, "the server's limit")
      .replace(/\(set [^)]*\)/g, "");
    // Request paths the page has an input for read as that input's label.
    text = text.replace(/\b[a-z_]+(?:\.[a-z_]+)+\b|\b[a-z]+_[a-z_]*(?:_m|_n|_kg|_s|_nondim|_m_s|_m2|_kg_m)\b/g, (path) => {
      const el = document.querySelector(`[name="${CSS.escape(path)}"]`);
      const label = labelOf(el);
      if (label) return `“${label.toLowerCase()}”`;
      return path.split(".").pop().replace(/_(m|n|kg|s|nondim|m_s|m2|kg_m|m_s2|deg)$/, "").replace(/_/g, " ");
    });
    const index = field && /\[(\d+)\]/.exec(field);
    if (index) text = `entry ${Number(index[1]) + 1}: ${text}`;
    return text.replace(/\s+/g, " ").trim();
  }

  // The input an API field names, in `roots`: exact, else without list
  // indices, else the first visible input under the nearest named parent.
  function inputFor(roots, field) {
    if (!field) return null;
    let path = String(field).replace(/^\./, "");
    const unindexed = path.replace(/\[\d+\].*$/, "");
    const exact = named(roots, path) || named(roots, unindexed);
    if (exact) return exact;
    path = unindexed;
    while (path.includes(".")) {
      path = path.slice(0, path.lastIndexOf("."));
      for (const root of [].concat(roots)) {
        const child = root && [...root.querySelectorAll(`[name^="${CSS.escape(path + ".")}"]`)].find(visible);
        if (child) return child;
      }
    }
    return null;
  }

  function clearFieldError(input) {
    input.closest(".field")?.querySelector(".field-error")?.remove();
    input.removeAttribute("aria-invalid");
    input.removeAttribute("aria-describedby");
  }

  // Removes the errors `source` placed (anywhere: the card's inputs too).
  function clearErrors(source) {
    for (const p of document.querySelectorAll(`.field-error[data-source="${source}"]`)) {
      const input = document.getElementById(p.id.replace(/-error$/, ""));
      if (input) {
        input.removeAttribute("aria-invalid");
        input.removeAttribute("aria-describedby");
      }
      p.remove();
    }
  }

  // Shows `message` under the input `field` names; returns the input or null.
  function showFieldError(roots, field, message, source) {
    const input = inputFor(roots, field);
    if (!input) return null;
    clearFieldError(input);
    const p = document.createElement("p");
    p.className = "field-error";
    p.id = `${input.id}-error`;
    p.dataset.errorFor = field;
    p.dataset.source = source;
    p.textContent = plainMessage(field, message);
    input.closest(".field").append(p);
    input.setAttribute("aria-invalid", "true");
    input.setAttribute("aria-describedby", p.id);
    return input;
  }

  function showFormError(el, message) {
    if (!el) return;
    el.textContent = message;
    el.hidden = !message;
  }

  // An API error body ({error: {code, field, message}}) beside its field when
  // one is named and shown, else in `fallback`. Returns a one-line summary.
  function renderApiError(roots, status, body, fallback, source) {
    const err = body && body.error ? body.error : { code: `http_${status}`, field: null, message: `the server answered ${status}` };
    const input = showFieldError(roots, err.field, err.message, source);
    if (input) {
      showFormError(fallback, "");
      input.focus({ preventScroll: true });
      const label = labelOf(input);
      return `${label ? `${label}: ` : ""}${plainMessage(err.field, err.message)}`;
    }
    const text = plainMessage(err.field, err.message);
    showFormError(fallback, text);
    return text;
  }

  // Input errors found before sending, each beside its field.
  function showInputErrors(roots, errors, source) {
    for (const e of errors) showFieldError(roots, e.field, e.message, source);
    inputFor(roots, errors[0].field)?.focus({ preventScroll: true });
  }

  // ---------- the URL ----------

  // Every input inside an element with data-url-prefix is kept in the query
  // as prefix + name. Inside data-url-always (the card and the plan) always,
  // elsewhere only when it differs from the page's default.
  const urlInputs = () => [...document.querySelectorAll("[data-url-prefix] [name]")].filter((el) => el.matches("input, select, textarea"));
  const urlKey = (el) => `${el.closest("[data-url-prefix]").dataset.urlPrefix}${el.name}`;
  const valueOf = (el) => (el.type === "checkbox" ? (el.checked ? "1" : "0") : el.value.trim());
  function isDefault(el) {
    if (el.type === "checkbox") return el.checked === el.defaultChecked;
    if (el.tagName === "SELECT") return [...el.options].every((o) => o.selected === o.defaultSelected);
    return el.value.trim() === el.defaultValue.trim();
  }

  function writeUrl() {
    const params = new URLSearchParams();
    for (const el of urlInputs()) {
      if (!visible(el)) continue;
      if (el.closest("[data-url-always]") || !isDefault(el)) params.set(urlKey(el), valueOf(el));
    }
    history.replaceState(null, "", `${window.location.pathname}?${params.toString()}${window.location.hash}`);
  }

  // Sets the inputs the query names; returns the set of prefixes it carried.
  function readUrl() {
    const params = new URLSearchParams(window.location.search);
    const seen = new Set();
    shared.restoring = true;
    try {
    // Selects first: they show the fields that apply.
    const all = urlInputs().sort((a, b) => (b.tagName === "SELECT") - (a.tagName === "SELECT"));
    for (const el of all) {
      const key = urlKey(el);
      if (!params.has(key)) continue;
      const v = params.get(key);
      if (el.type === "checkbox") el.checked = v === "1" || v === "true";
      else el.value = v;
      el.dispatchEvent(new Event("change", { bubbles: true }));
      seen.add(el.closest("[data-url-prefix]").dataset.urlPrefix);
    }
    } finally {
      shared.restoring = false;
    }
    return seen;
  }

  Object.assign(shared, {
    visible, named, readNumber, compact, labelOf, plainMessage, inputFor, clearFieldError, clearErrors,
    showFieldError, showFormError, renderApiError, showInputErrors, writeUrl, readUrl,
  });
})(shared);
