// The page's shared code as one module. Every panel starts with
// `import S from "./shared/index.js"`: the module graph loads every shared
// file, once, before any panel runs, whatever the order of index.html's
// script tags. S holds the helpers of api.js (HTTP, jobs), form.js (inputs,
// errors, the URL), system.js (the system card), plot.js and export.js, and the page's units (units.js).
import "./api.js";
import "./form.js";
import "./system.js";
import "./plot.js";
import "./export.js";
import "./units.js";
export { default } from "./core.js";
