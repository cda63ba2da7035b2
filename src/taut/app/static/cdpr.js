// Cable-robot explorer: pick a preset or model file, move the platform with sliders or by
// dragging it in the side (x-z) or top (x-y) view; the server returns tensions (charted
// against their limits), tipping margins of the mobile bases and whether the pose is
// wrench-feasible; the side view shades the wrench-feasible slice of the workspace and a
// 3D view (turned with the mouse) shows the frame, bases, cables, platform and the slice.
// SI units: m, rad, N, N m.
"use strict";

const AXES = [["x", "m"], ["y", "m"], ["z", "m"], ["roll", "rad"], ["pitch", "rad"], ["yaw", "rad"]];
//: How near the platform (pixels) a press must be to start dragging it.
const GRAB_PX = 40;

const CdprView = {
  model: null, geo: null, pose: [0, 0, 0.8, 0, 0, 0], st: null, ws: null,
  inflight: false, pending: false, source: null, timer3d: null,

  init(names) {
    const sel = document.getElementById("cdpr-example");
    fillSelect(sel, ["(choose)"].concat(names), "(choose)");
    sel.addEventListener("change", () => { if (sel.value !== "(choose)") this.load({example: sel.value}); });
    onUpload(document.getElementById("cdpr-upload"), body => this.load(body));
    document.getElementById("cdpr-stabilisers").addEventListener("change", () => { this.request(); this.slice(); });
    document.getElementById("cdpr-method").addEventListener("change", () => this.request());
    const box = document.getElementById("cdpr-sliders");
    this.sliders = AXES.map(([name, unit], k) => {
      const span = document.createElement("span"); span.className = "slider";
      span.innerHTML = `${name} [${unit}] <input type="range" id="cdpr-${name}" step="0.01"> <output></output>`;
      box.appendChild(span);
      const input = span.querySelector("input");
      input.addEventListener("input", () => { this.pose[k] = Number(input.value); this.request(); });
      input.addEventListener("change", () => { if (k !== 0 && k !== 2) this.slice(); this.saveUrl(); });
      return input;
    });
    for (const [id, vert] of [["cdpr-side", 2], ["cdpr-top", 1]]) this.dragging(document.getElementById(id), vert);
  },

  async load(body, {pose = null, stabilisers = null, method = null} = {}) {
    const r = await api("/api/cdpr/load", body);
    if (!r.ok) return false;
    this.model = r.data.model; this.geo = r.data.geometry;
    this.source = body.example ? {example: body.example} : {model: this.model};
    const g = this.geo, [lo, hi] = g.bounds;
    fillSelect(document.getElementById("cdpr-method"), g.methods, method || "qp_min_norm");
    if (stabilisers !== null) document.getElementById("cdpr-stabilisers").checked = stabilisers;
    const mid = [0, 1, 2].map(k => (lo[k] + hi[k]) / 2);
    this.pose = pose || [mid[0], mid[1], lo[2] + 0.35 * (hi[2] - lo[2]), 0, 0, 0];
    this.sliders.forEach((s, k) => {
      s.min = k < 3 ? lo[k] : -0.6; s.max = k < 3 ? hi[k] : 0.6; s.value = this.pose[k];
    });
    this.ws = null;
    showMessage(`loaded: ${g.name}`, "info");
    this.request(); this.slice(); this.saveUrl();
    return true;
  },

  body(extra) {
    return Object.assign({model: this.model, stabilisers: document.getElementById("cdpr-stabilisers").checked}, extra);
  },

  saveUrl() {
    if (!this.model) return;
    saveUrl({v: "cdpr", src: this.source, pose: this.pose, stab: this.body().stabilisers,
             method: document.getElementById("cdpr-method").value});
  },

  request() {
    if (!this.model) return;
    if (this.inflight) { this.pending = true; return; }
    this.send();
  },

  async send() {
    this.inflight = true;
    const r = await api("/api/cdpr/state", this.body({pose: this.pose.slice(), method: document.getElementById("cdpr-method").value}));
    this.inflight = false;
    if (r.ok) { this.st = r.data; this.draw(); }
    if (this.pending) { this.pending = false; this.send(); }
  },

  async slice() {
    if (!this.model) return;
    const r = await api("/api/cdpr/workspace", this.body({plane: "xz", offset: this.pose[1], n: [41, 21], rpy: this.pose.slice(3)}));
    if (r.ok) { this.ws = r.data; this.draw(); }
  },

  // Screen position (client pixels) of the platform's centre in a 2D view.
  platformScreen(id) {
    return chartScreen(document.getElementById(id), this.pose[0], this.pose[id === "cdpr-side" ? 2 : 1]);
  },

  // Drag the platform in a view; `vert` is the pose index of the view's vertical axis.
  dragging(div, vert) {
    chartDrag(div, (xy, e) => {
      if (!this.st) return false;
      const [px, py] = this.platformScreen(div.id);
      return Math.hypot(e.clientX - px, e.clientY - py) <= GRAB_PX;
    }, xy => {
      this.pose[0] = xy[0]; this.pose[vert] = xy[1];
      this.sliders[0].value = xy[0]; this.sliders[vert].value = xy[1];
      this.request();
    }, () => { if (vert === 1) this.slice(); this.saveUrl(); });
  },

  draw() {
    if (!this.geo || !this.st) return;
    this.sliders.forEach((s, k) => { s.nextElementSibling.textContent = this.pose[k].toFixed(2); });
    const st = this.st, flag = document.getElementById("cdpr-flag");
    flag.textContent = st.message;
    flag.className = "flag " + (st.feasible ? "ok" : "bad");
    flag.dataset.feasible = st.feasible ? "1" : "0";
    this.drawView("cdpr-side", 0, 2);
    this.drawView("cdpr-top", 0, 1);
    // The 3D view follows once the input pauses (QUIET_MS, view3d.js): a WebGL redraw per
    // drag step would slow the 2D views' drags.
    if (this.timer3d !== null) clearTimeout(this.timer3d);
    this.timer3d = setTimeout(() => { this.timer3d = null; this.draw3D(); }, QUIET_MS);
    this.drawBars(); this.drawMargins();
  },

  cableBad(i) {
    const t = this.st.tensions ? this.st.tensions[i] : null, g = this.geo;
    return t === null || t < g.t_min[i] - 1e-6 || t > g.t_max[i] + 1e-6;
  },

  // A 2D view: axes a (horizontal) and b (vertical) of x, y, z.
  drawView(id, a, b) {
    const div = document.getElementById(id), g = this.geo, st = this.st, [lo, hi] = g.bounds;
    const rect = (l, h) => [[l[a], l[b]], [h[a], l[b]], [h[a], h[b]], [l[a], h[b]]];
    const traces = [];
    if (b === 2 && this.ws) traces.push(...this.sliceTraces(div));
    traces.push(polygon(rect(lo, hi), "frame box", "rgba(0,0,0,0)", "#999", {line: {color: "#999", dash: "dash", width: 1}}));
    if (g.desired_workspace) traces.push(polygon(rect(...g.desired_workspace), "desired workspace", "rgba(0,0,0,0)", "#46c"));
    if (b === 1) g.bases.filter(s => s.support).forEach((s, k) => traces.push(
      polygon(s.support, "base support polygons", "rgba(120,120,120,0.2)", "#666", {legendgroup: "bases", showlegend: k === 0})));
    const A = st.attachments;
    for (const bad of [false, true]) {
      const x = [], y = [];
      g.exits.forEach((e, i) => { if (this.cableBad(i) === bad) x.push(e[a], A[i][a], null), y.push(e[b], A[i][b], null); });
      if (x.length) traces.push(line(x, y, bad ? "cable off its limits" : "cable within limits", bad ? "#c00" : "#1f5fbf"));
    }
    traces.push({type: "scatter", mode: "markers", x: g.exits.map(e => e[a]), y: g.exits.map(e => e[b]),
                 name: "cable exits", marker: {color: "#333", size: 6}});
    // The platform's outline is the library's hull of the attachment points (cdpr_api.outline).
    traces.push(polygon(st.outline_m[b === 2 ? "xz" : "xy"], "platform (drag it)", st.feasible ? "#3a7" : "#d33", "#222", {hoverinfo: "name"}));
    const names = ["x [m]", "y [m]", "z [m]"], pad = b === 1 ? 0.8 : 0.15;
    // Fixed ranges: the map does not rescale while the platform is dragged.
    chart2d(div, traces, names[a], names[b], {equal: true, drag: false,
            x: {range: [lo[a] - pad, hi[a] + pad]}, y: {range: [lo[b] - pad, hi[b] + pad]}});
  },

  // The wrench-feasible slice as square cells (green: limits and tipping; yellow: the
  // tension limits only, the bases would tip).
  sliceTraces(div) {
    const ws = this.ws, dx = ws.a[1] - ws.a[0], fl = div._fullLayout;
    const px = fl && fl.xaxis && fl.xaxis._m ? Math.abs(fl.xaxis._m) * dx : 8;
    const cells = [[], []];
    ws.b.forEach((z, i) => ws.a.forEach((x, j) => {
      const lim = ws.feasible[i][j], tip = ws.feasible_tipping ? ws.feasible_tipping[i][j] : lim;
      if (lim) cells[tip ? 0 : 1].push([x, z]);
    }));
    return cells.map((c, k) => ({
      type: "scatter", mode: "markers", x: c.map(p => p[0]), y: c.map(p => p[1]), hoverinfo: "skip",
      name: k ? "feasible by limits, bases tip" : `wrench-feasible slice (y = ${ws.offset.toFixed(2)} m)`,
      marker: {symbol: "square", size: Math.max(2, px), color: k ? "rgba(230,180,30,0.35)" : "rgba(40,160,60,0.3)"},
    })).filter(t => t.x.length);
  },

  draw3D() {
    const g = this.geo, st = this.st, [lo, hi] = g.bounds, A = st.attachments, traces = [];
    const c = [0, 1, 2].map(k => [lo[k], hi[k]]), edges = [];
    for (const [i, j] of [[0, 1], [1, 2], [0, 2]]) for (const u of c[i]) for (const v of c[j]) {
      const k = 3 - i - j, p = [0, 0, 0], q = [0, 0, 0];
      p[i] = q[i] = u; p[j] = q[j] = v; p[k] = c[k][0]; q[k] = c[k][1];
      edges.push([p, q]);
    }
    traces.push(segments3(edges, "frame box", "#aaa", {line: {color: "#aaa", width: 2, dash: "dash"}}));
    g.bases.filter(s => s.support).forEach((s, k) => traces.push(
      line3(s.support.concat([s.support[0]]).map(p => [p[0], p[1], 0]), "base support polygons", "#666",
            {legendgroup: "bases", showlegend: k === 0})));
    for (const bad of [false, true]) {
      const pairs = g.exits.map((e, i) => [e, A[i], i]).filter(p => this.cableBad(p[2]) === bad);
      if (pairs.length) traces.push(segments3(pairs, bad ? "cable off its limits" : "cable within limits", bad ? "#c00" : "#1f5fbf"));
    }
    traces.push({type: "scatter3d", mode: "markers", name: "cable exits", x: g.exits.map(e => e[0]),
                 y: g.exits.map(e => e[1]), z: g.exits.map(e => e[2]), marker: {size: 3, color: "#333"}});
    const hullEdges = [];
    A.forEach((p, i) => A.forEach((q, j) => { if (j > i) hullEdges.push([p, q]); }));
    traces.push(segments3(hullEdges, "platform", st.feasible ? "#2a8a4a" : "#d33", {line: {width: 3, color: st.feasible ? "#2a8a4a" : "#d33"}}));
    if (this.ws) {
      const pts = [];
      this.ws.b.forEach((z, i) => this.ws.a.forEach((x, j) => { if (this.ws.feasible[i][j]) pts.push([x, this.ws.offset, z]); }));
      traces.push({type: "scatter3d", mode: "markers", name: `wrench-feasible slice (y = ${this.ws.offset.toFixed(2)} m)`,
                   x: pts.map(p => p[0]), y: pts.map(p => p[1]), z: pts.map(p => p[2]), hoverinfo: "skip",
                   marker: {size: 2, color: "rgba(40,160,60,0.35)"}});
    }
    chart3d(document.getElementById("cdpr-3d"), traces, ["x [m]", "y [m]", "z [m]"], {zoom: 1.5});
  },

  // Tensions against their limits: per cable the band [t_min, t_max] and the tension.
  drawBars() {
    const g = this.geo, T = this.st.tensions, names = g.cables, traces = [];
    const seg = (from, to, which) => {
      const x = [], y = [];
      names.forEach((n, i) => { if (which(i)) x.push(from(i), to(i), null), y.push(n, n, null); });
      return [x, y];
    };
    traces.push(line(...seg(i => g.t_min[i], i => g.t_max[i], () => true), "limits [t_min, t_max]", "#c8cce8",
                     {line: {color: "#c8cce8", width: 14}}));
    if (T) {
      for (const bad of [false, true]) {
        const [x, y] = seg(() => 0, i => T[i], i => this.cableBad(i) === bad);
        if (x.length) traces.push(line(x, y, bad ? "tension off its limits" : "tension within limits", bad ? "#d33" : "#3a7",
                                       {line: {color: bad ? "#d33" : "#3a7", width: 6}}));
      }
      traces.push({type: "scatter", mode: "text", x: T, y: names, text: T.map(t => t === null ? "" : t.toFixed(1)),
                   textposition: T.map(t => t < 0 ? "middle left" : "middle right"), showlegend: false, hoverinfo: "skip", textfont: {size: 10}});
    }
    const vals = (T || []).filter(t => t !== null).concat(g.t_max, [0]);
    const lo = Math.min(...vals), hi = Math.max(...vals), room = 0.16 * (hi - lo || 1);  // value labels
    chart2d(document.getElementById("cdpr-bars"), traces, "tension [N]", "cable",
            {y: {type: "category", autorange: "reversed"}, x: {range: [lo - (lo < 0 ? room : 0), hi + room]}});
    document.getElementById("cdpr-bars-note").textContent =
      T ? `tensions: ${this.st.shown}` : "no tensions: " + this.st.message;
  },

  drawMargins() {
    const tb = document.getElementById("cdpr-margins");
    tb.innerHTML = "<tr><th>base</th><th>margin [N m]</th><th></th></tr>";
    if (!this.st.margins.length && this.geo.has_tipping) {
      tb.insertRow().insertCell().textContent = "no valid tensions: margins undefined";
    }
    for (const m of this.st.margins) {
      const row = tb.insertRow();
      [m.base, m.margin.toFixed(2), m.stable ? "stable" : "TIPS"].forEach(c => { row.insertCell().textContent = c; });
    }
  },
};
