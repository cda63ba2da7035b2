// Shared helpers of the taut app page: JSON requests, the one-line message bar, SVG
// drawing with a world-to-screen frame, shareable URL state and file download/upload.
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

// A small line plot: series [{t, y, color, dash, label}], with a cursor at time tc.
function linePlot(svg, series, {tc = null, ylabel = "", zero = false} = {}) {
  clear(svg);
  const pts = [];
  for (const s of series) s.t.forEach((t, i) => { if (s.y[i] !== null) pts.push([t, s.y[i]]); });
  if (!pts.length) return;
  let [lo, hi] = bbox(pts);
  if (zero) lo[1] = Math.min(lo[1], 0);
  const dy = (hi[1] - lo[1]) || Math.abs(hi[1]) || 1;
  lo = [lo[0], lo[1] - 0.08 * dy]; hi = [hi[0], hi[1] + 0.08 * dy];
  const W = svg.width.baseVal.value, H = svg.height.baseVal.value, L = 48, B = 18;
  const X = t => L + (t - lo[0]) / ((hi[0] - lo[0]) || 1) * (W - L - 8);
  const Y = v => 6 + (hi[1] - v) / (hi[1] - lo[1]) * (H - B - 6);
  el("line", {x1: L, y1: H - B, x2: W - 8, y2: H - B, stroke: "#999"}, svg);
  el("line", {x1: L, y1: 6, x2: L, y2: H - B, stroke: "#999"}, svg);
  for (const v of [lo[1] + 0.08 * dy / 1.16, hi[1] - 0.08 * dy / 1.16]) {
    el("text", {x: 2, y: Y(v) + 4, "font-size": 10}, svg).textContent = v.toPrecision(3);
  }
  el("text", {x: W - 60, y: H - 4, "font-size": 10}, svg).textContent = `t [s] ${hi[0].toFixed(1)}`;
  let ly = 14;
  for (const s of series) {
    let d = "", pen = false;
    s.t.forEach((t, i) => {
      if (s.y[i] === null) { pen = false; return; }
      d += (pen ? "L" : "M") + X(t).toFixed(1) + "," + Y(s.y[i]).toFixed(1);
      pen = true;
    });
    el("path", {d, fill: "none", stroke: s.color, "stroke-width": 1.5,
                "stroke-dasharray": s.dash || ""}, svg);
    if (s.label) {
      el("text", {x: W - 200, y: ly, "font-size": 10, fill: s.color}, svg).textContent = s.label;
      ly += 12;
    }
  }
  if (tc !== null) el("line", {x1: X(tc), y1: 6, x2: X(tc), y2: H - B, stroke: "#c00",
                               "stroke-width": 1, class: "cursor"}, svg);
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

function download(text, filename) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([text], {type: "application/x-yaml"}));
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
