// Cable-robot explorer: pick a preset or model file, move the platform with sliders or
// by dragging it in the side (x-z) or top (x-y) view; the server returns tensions (drawn
// as bars against their limits), tipping margins of the mobile bases and whether the pose
// is wrench-feasible; the side view shades the wrench-feasible slice of the workspace.
"use strict";

const AXES = [["x", "m"], ["y", "m"], ["z", "m"], ["roll", "rad"], ["pitch", "rad"], ["yaw", "rad"]];

const CdprView = {
  model: null, geo: null, pose: [0, 0, 0.8, 0, 0, 0], st: null, ws: null,
  inflight: false, pending: false, source: null,

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
      span.innerHTML = `${name} <input type="range" id="cdpr-${name}" step="0.01"> <output></output> ${unit}`;
      box.appendChild(span);
      const input = span.querySelector("input");
      input.addEventListener("input", () => { this.pose[k] = Number(input.value); this.request(); });
      input.addEventListener("change", () => { if (k !== 0 && k !== 2) this.slice(); this.saveUrl(); });
      return input;
    });
    for (const id of ["cdpr-side", "cdpr-top"]) this.dragging(document.getElementById(id), id === "cdpr-side" ? 2 : 1);
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
    this.side = new Frame(document.getElementById("cdpr-side"), [lo[0], lo[2]], [hi[0], hi[2]], 20);
    this.topf = new Frame(document.getElementById("cdpr-top"), [lo[0] - 0.8, lo[1] - 0.8], [hi[0] + 0.8, hi[1] + 0.8], 12);
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

  // Drag the platform in a view; `vert` is the pose index of the view's vertical axis.
  dragging(svg, vert) {
    let on = false;
    svg.addEventListener("pointerdown", e => {
      if (!this.st || !e.target.closest(".platform")) return;
      on = true; svg.setPointerCapture(e.pointerId);
    });
    svg.addEventListener("pointermove", e => {
      if (!on) return;
      const w = (vert === 2 ? this.side : this.topf).world(e);
      this.pose[0] = w[0]; this.pose[vert] = w[1];
      this.sliders[0].value = w[0]; this.sliders[vert].value = w[1];
      this.request();
    });
    svg.addEventListener("pointerup", () => { if (on) { on = false; if (vert === 1) this.slice(); this.saveUrl(); } });
  },

  draw() {
    if (!this.geo || !this.st) return;
    this.sliders.forEach((s, k) => { s.nextElementSibling.textContent = this.pose[k].toFixed(2); });
    const st = this.st, flag = document.getElementById("cdpr-flag");
    flag.textContent = st.message;
    flag.className = "flag " + (st.feasible ? "ok" : "bad");
    flag.dataset.feasible = st.feasible ? "1" : "0";
    this.drawView(document.getElementById("cdpr-side"), this.side, 0, 2);
    this.drawView(document.getElementById("cdpr-top"), this.topf, 0, 1);
    this.drawBars(); this.drawMargins();
  },

  drawView(svg, fr, a, b) {
    clear(svg);
    const g = this.geo, st = this.st, [lo, hi] = g.bounds;
    const rect = (l, h, attrs) => el("rect", Object.assign({x: fr.x(l[a]), y: fr.y(h[b]), width: (h[a] - l[a]) * fr.s,
                                                              height: (h[b] - l[b]) * fr.s}, attrs), svg);
    if (b === 2 && this.ws) {
      const ws = this.ws, dx = ws.a[1] - ws.a[0], dz = ws.b[1] - ws.b[0];
      ws.b.forEach((z, i) => ws.a.forEach((x, j) => {
        const lim = ws.feasible[i][j], tip = ws.feasible_tipping ? ws.feasible_tipping[i][j] : lim;
        if (!lim) return;
        el("rect", {x: fr.x(x - dx / 2), y: fr.y(z + dz / 2), width: dx * fr.s + 0.5, height: dz * fr.s + 0.5,
                    fill: tip ? "rgba(40,160,60,0.28)" : "rgba(230,180,30,0.3)"}, svg);
      }));
    }
    rect(lo, hi, {fill: "none", stroke: "#999", "stroke-dasharray": "4 3"});
    if (g.desired_workspace) rect(...g.desired_workspace, {fill: "none", stroke: "#46c"});
    if (b === 1) for (const base of g.bases) {
      if (base.support) el("polygon", {points: fr.poly(base.support), fill: "rgba(120,120,120,0.2)", stroke: "#666"}, svg);
    }
    const A = st.attachments, T = st.tensions;
    g.exits.forEach((e, i) => {
      const t = T ? T[i] : null, bad = t === null || t < g.t_min[i] - 1e-6 || t > g.t_max[i] + 1e-6;
      el("line", {x1: fr.x(e[a]), y1: fr.y(e[b]), x2: fr.x(A[i][a]), y2: fr.y(A[i][b]),
                  stroke: bad ? "#c00" : "#1f5fbf", "stroke-width": 1.2}, svg);
      el("circle", {cx: fr.x(e[a]), cy: fr.y(e[b]), r: 3, fill: "#333"}, svg);
    });
    const hull = A.map(p => [p[a], p[b]]);
    el("polygon", {points: fr.poly(convexHull(hull)), fill: st.feasible ? "#3a7" : "#d33", stroke: "#222",
                   class: "platform", cursor: "move"}, svg);
  },

  drawBars() {
    const svg = document.getElementById("cdpr-bars"), g = this.geo, T = this.st.tensions;
    clear(svg);
    const W = svg.width.baseVal.value, top = Math.max(...g.t_max) * 1.15, m = g.cables.length;
    const h = Math.min(20, (svg.height.baseVal.value - 20) / m), L = 60, X = v => L + v / top * (W - L - 70);
    g.cables.forEach((name, i) => {
      const y = 4 + i * h, t = T ? T[i] : null;
      el("text", {x: 4, y: y + h * 0.7, "font-size": 11}, svg).textContent = name;
      el("rect", {x: X(g.t_min[i]), y, width: X(g.t_max[i]) - X(g.t_min[i]), height: h - 4, fill: "#eef", stroke: "#99b"}, svg);
      if (t !== null) {
        const bad = t < g.t_min[i] - 1e-6 || t > g.t_max[i] + 1e-6;
        const tc = Math.min(Math.max(t, 0), top);                 // bar clipped to the axis
        el("rect", {x: X(0), y: y + 3, width: X(tc) - X(0), height: h - 10, fill: bad ? "#d33" : "#3a7", class: "tension-bar"}, svg);
        el("text", {x: X(tc) + 4, y: y + h * 0.7, "font-size": 10}, svg).textContent = t.toFixed(1);
      }
    });
    el("text", {x: L, y: 4 + m * h + 12, "font-size": 10}, svg).textContent =
      T ? `tensions: ${this.st.shown}; band: limits [t_min, t_max]` : "no tensions: " + this.st.message;
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

function convexHull(P) {
  const pts = P.slice().sort((p, q) => p[0] - q[0] || p[1] - q[1]);
  const cross = (o, a, b) => (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  const half = list => {
    const h = [];
    for (const p of list) { while (h.length >= 2 && cross(h[h.length - 2], h[h.length - 1], p) <= 0) h.pop(); h.push(p); }
    return h;
  };
  const lower = half(pts), upper = half(pts.slice().reverse());
  return lower.slice(0, -1).concat(upper.slice(0, -1));
}
