// Shared helpers of the taut app page: JSON requests, the one-line message bar, SVG
// drawing with a world-to-screen frame and axes (the sheet explorer's editable maps; the
// charts are Plotly.js, charts.js), shareable URL state and file download/upload.
"use strict";

const taut = {views: {}, current: null};
window.taut = taut;

// The per-launch secret `taut app` put in the page's URL (?token=...); every API request
// carries it, and the server refuses requests without it.
const TOKEN = new URLSearchParams(location.search).get("token") || "";

// POST a JSON body; resolves to {ok, data}. Errors from the server are one line
// ("<field>: <problem>") and are shown in the message bar; the caller keeps its state.
async function api(path, body, {quiet = false} = {}) {
  let resp, data;
  try {
    resp = await fetch(path, {
      method: body === undefined ? "GET" : "POST",
      headers: {"Content-Type": "application/json", "X-Taut-Token": TOKEN},
      body: body === undefined ? undefined : JSON.stringify(body),
    });
    data = await resp.json();
  } catch (e) {
    if (!quiet) showMessage("server: no answer (is `taut app` still running?)", "error");
    return {ok: false, data: {error: "no answer"}};
  }
  if (!resp.ok) {
    if (!quiet) showMessage(data.error || `HTTP ${resp.status}`, "error");
    return {ok: false, data};
  }
  return {ok: true, data};
}

function showMessage(text, kind = "info") {
  const bar = document.getElementById("message");
  bar.textContent = text;
  bar.className = text ? kind : "";
}

// --- SVG -------------------------------------------------------------------------
const SVGNS = "http://www.w3.org/2000/svg";

function el(tag, attrs, parent) {
  const e = document.createElementNS(SVGNS, tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}

function clear(node) { while (node.firstChild) node.removeChild(node.firstChild); }

// Map world (x, y up) to screen pixels, fitted to a box with a margin.
class Frame {
  constructor(svg, lo, hi, pad = 24) {
    const w = svg.width.baseVal.value, h = svg.height.baseVal.value;
    const sx = (w - 2 * pad) / Math.max(hi[0] - lo[0], 1e-12);
    const sy = (h - 2 * pad) / Math.max(hi[1] - lo[1], 1e-12);
    this.s = Math.min(sx, sy);
    this.cx = (lo[0] + hi[0]) / 2; this.cy = (lo[1] + hi[1]) / 2;
    this.w = w; this.h = h; this.svg = svg;
  }
  x(wx) { return this.w / 2 + (wx - this.cx) * this.s; }
  y(wy) { return this.h / 2 - (wy - this.cy) * this.s; }
  pt(p) { return [this.x(p[0]), this.y(p[1])]; }
  // Screen event -> world coordinates.
  world(evt) {
    const r = this.svg.getBoundingClientRect();
    const px = evt.clientX - r.left, py = evt.clientY - r.top;
    return [this.cx + (px - this.w / 2) / this.s, this.cy - (py - this.h / 2) / this.s];
  }
  poly(points) { return points.map(p => this.pt(p).map(v => v.toFixed(1)).join(",")).join(" "); }
}

function bbox(points) {
  const lo = [Infinity, Infinity], hi = [-Infinity, -Infinity];
  for (const p of points) for (let k = 0; k < 2; k++) {
    lo[k] = Math.min(lo[k], p[k]); hi[k] = Math.max(hi[k], p[k]);
  }
  return [lo, hi];
}

function grow([lo, hi], f) {
  const d = Math.max(hi[0] - lo[0], hi[1] - lo[1]) * f;
  return [[lo[0] - d, lo[1] - d], [hi[0] + d, hi[1] + d]];
}

// A "nice" tick step: 1, 2 or 5 times a power of ten, about `n` ticks over `span`.
function niceStep(span, n) {
  const raw = span / n, p = 10 ** Math.floor(Math.log10(raw)), m = raw / p;
  return p * (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10);
}

// Axes of an editable SVG map (the sheet explorer's views, where pointer input moves the
// robots): light grid, tick labels along the bottom and left edges and axis titles with
// their units. Drawn first, under the content.
function svgAxes(fr, xTitle, yTitle) {
  const svg = fr.svg, W = fr.w, H = fr.h, L = 40, B = 30;
  const xs = [fr.cx - (W / 2 - L) / fr.s, fr.cx + (W / 2) / fr.s];
  const ys = [fr.cy - (H / 2 - B) / fr.s, fr.cy + (H / 2) / fr.s];
  const g = el("g", {class: "axes"}, svg);
  for (const [lo, hi, horiz] of [[...xs, true], [...ys, false]]) {
    const step = niceStep(hi - lo, 5), digits = Math.max(0, -Math.floor(Math.log10(step)));
    for (let v = Math.ceil(lo / step) * step; v <= hi; v += step) {
      const p = horiz ? fr.x(v) : fr.y(v);
      if (horiz ? p > W - 12 : p < 8) continue;               // no label cut by the edge
      el("line", horiz ? {x1: p, y1: 0, x2: p, y2: H - B} : {x1: L, y1: p, x2: W, y2: p},
         g).setAttribute("stroke", "#eee");
      el("text", horiz ? {x: p, y: H - B + 11, "text-anchor": "middle"} : {x: L - 3, y: p + 3, "text-anchor": "end"},
         g).textContent = v.toFixed(digits);
    }
  }
  el("line", {x1: L, y1: H - B, x2: W, y2: H - B, stroke: "#888"}, g);
  el("line", {x1: L, y1: 0, x2: L, y2: H - B, stroke: "#888"}, g);
  el("text", {x: (L + W) / 2, y: H - 4, "text-anchor": "middle", class: "axis-title"}, g).textContent = xTitle;
  el("text", {x: 11, y: (H - B) / 2, "text-anchor": "middle", class: "axis-title",
              transform: `rotate(-90 11 ${(H - B) / 2})`}, g).textContent = yTitle;
  for (const t of g.querySelectorAll("text")) t.setAttribute("font-size", t.classList.contains("axis-title") ? 11 : 9);
}

// --- shareable state in the URL hash (base64 of JSON) ------------------------------
function encodeState(obj) {
  const bytes = new TextEncoder().encode(JSON.stringify(obj));
  let s = "";
  bytes.forEach(b => { s += String.fromCharCode(b); });
  return btoa(s).replace(/\+/g, "-").replace(/\//g, "_").replace(/=+$/, "");
}

function decodeState(text) {
  const b = atob(text.replace(/-/g, "+").replace(/_/g, "/"));
  const bytes = Uint8Array.from(b, c => c.charCodeAt(0));
  return JSON.parse(new TextDecoder().decode(bytes));
}

function saveUrl(state) {
  history.replaceState(null, "", "#" + encodeState(state));
}

function download(data, filename, type = "application/x-yaml") {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([data], {type}));
  a.download = filename;
  document.body.appendChild(a);
  a.click();
  setTimeout(() => { URL.revokeObjectURL(a.href); a.remove(); }, 1000);
}

// Read a chosen file and hand {text, filename} to `load`; the input is reset so the
// same file can be chosen again.
function onUpload(input, load) {
  input.addEventListener("change", () => {
    const f = input.files[0];
    if (!f) return;
    const reader = new FileReader();
    reader.onload = () => { load({text: reader.result, filename: f.name}); input.value = ""; };
    reader.readAsText(f);
  });
}

function fillSelect(select, names, chosen) {
  clear(select);
  for (const n of names) {
    const o = document.createElement("option");
    o.value = n; o.textContent = n;
    if (n === chosen) o.selected = true;
    select.appendChild(o);
  }
}

function fmt(v, d = 2) { return v === null || v === undefined ? "-" : Number(v).toFixed(d); }
