// The one object the page's shared code fills (api.js, form.js, system.js,
// plot.js, export.js each add their helpers to it). Panels do not import it
// directly: they import index.js, which loads every shared file first.
export default {};
