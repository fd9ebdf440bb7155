// The page's export helpers, shared by every panel: downloads, every input of
// a request flattened (`# input <path>,<value>` lines), six significant
// digits, text wrapped to a canvas width, and plots composed onto one PNG
// with their captions, a drawn legend and the inputs.
"use strict";

import shared from "./core.js";

(function (shared) {
  function download(content, name, type = "text/plain") {
    const blob = content instanceof Blob ? content : new Blob([content], { type });
    const url = URL.createObjectURL(blob);
    const a = document.createElement("a");
    a.href = url;
    a.download = name;
    document.body.append(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(url), 1000);
  }

  // Every value of `obj` as [path, value]; lists of numbers joined by spaces,
  // lists of objects indexed (`forecast[0].time_s`).
  function flatten(obj, prefix = "", out = []) {
    for (const [k, v] of Object.entries(obj ?? {})) {
      const key = prefix ? `${prefix}.${k}` : k;
      if (Array.isArray(v)) {
        if (v.some((x) => x && typeof x === "object")) v.forEach((x, i) => flatten(x, `${key}[${i}]`, out));
        else out.push([key, v.join(" ")]);
      } else if (v && typeof v === "object") flatten(v, key, out);
      else out.push([key, v]);
    }
    return out;
  }

  // Six significant digits: what the model resolves, not 16-digit floats.
  const sig = (v) => (typeof v === "number" && Number.isFinite(v) ? String(Number(v.toPrecision(6))) : v == null ? "" : String(v));

  const inputLines = (obj, tag = "input") => flatten(obj).map(([k, v]) => `# ${tag} ${k},${sig(v)}`);

  // Splits `text` into lines no wider than `max` pixels in the context's font.
  function wrap(ctx, text, max) {
    const rows = [];
    let row = "";
    for (const word of text.split(" ")) {
      const next = row ? `${row} ${word}` : word;
      if (row && ctx.measureText(next).width > max) {
        rows.push(row);
        row = word;
      } else row = next;
    }
    if (row) rows.push(row);
    return rows;
  }

  // uPlot plots on one white canvas, each with its caption and a drawn legend,
  // then `footer` (the inputs) wrapped below. blocks: [[uplot, caption], …].
  function plotsPng(blocks, footer) {
    const ratio = window.devicePixelRatio || 1;
    const pad = 12 * ratio;
    const line = 18 * ratio;
    const width = Math.max(...blocks.map(([u]) => u.ctx.canvas.width)) + 2 * pad;
    const legendRows = (u) => u.series.length - 1;
    const canvas = document.createElement("canvas");
    const ctx = canvas.getContext("2d");
    ctx.font = `${11 * ratio}px sans-serif`;
    const footerRows = footer ? wrap(ctx, footer, width - 2 * pad) : [];
    ctx.font = `bold ${13 * ratio}px sans-serif`;
    const captionRows = (c) => wrap(ctx, c, width - 2 * pad).length;
    const height = blocks.reduce((h, [u, c]) => h + line * (captionRows(c) + 0.5) + u.ctx.canvas.height + legendRows(u) * line + pad, pad) +
      footerRows.length * 15 * ratio + pad;
    canvas.width = width;
    canvas.height = height;
    ctx.fillStyle = "#fff";
    ctx.fillRect(0, 0, width, height);
    let y = pad;
    for (const [u, caption] of blocks) {
      ctx.fillStyle = "#111";
      ctx.font = `bold ${13 * ratio}px sans-serif`;
      ctx.textBaseline = "top";
      for (const row of wrap(ctx, caption, width - 2 * pad)) {
        ctx.fillText(row, pad, y);
        y += line;
      }
      y += line * 0.5;
      ctx.drawImage(u.ctx.canvas, pad, y);
      y += u.ctx.canvas.height;
      ctx.font = `${12 * ratio}px sans-serif`;
      ctx.textBaseline = "middle";
      for (const s of u.series.slice(1)) {
        ctx.strokeStyle = s.color || s._stroke || "#000";
        ctx.lineWidth = 2 * ratio;
        ctx.setLineDash(s.dash ? s.dash.map((d) => d * ratio) : []);
        ctx.beginPath();
        ctx.moveTo(pad, y + line / 2);
        ctx.lineTo(pad + 28 * ratio, y + line / 2);
        ctx.stroke();
        ctx.setLineDash([]);
        ctx.fillStyle = "#111";
        ctx.fillText(s.label, pad + 36 * ratio, y + line / 2);
        y += line;
      }
      y += pad;
    }
    ctx.fillStyle = "#333";
    ctx.font = `${11 * ratio}px sans-serif`;
    ctx.textBaseline = "top";
    for (const row of footerRows) {
      ctx.fillText(row, pad, y);
      y += 15 * ratio;
    }
    return canvas;
  }

  Object.assign(shared, { download, flatten, sig, inputLines, wrap, plotsPng });
})(shared);
