// Sheet explorer: drag robots in a top view; every drag asks the server for forward
// kinematics and draws every equilibrium (taut cables solid; the selected state also its
// slack cables, dotted), the sheet in its own frame, a 3D view of the lowest stable
// state and a table. IK mode: click a target. Simulate mode: record a drag path and
// play it through the quasi-static model, with charts of the object's height and of the
// taut set along the path (Plotly.js, charts.js). Lengths in the scenario's unit.
"use strict";

const KIND_COLOR = {stable: "#1a8a2a", saddle: "#d08020", not_equilibrium: "#999"};

const SheetView = {
  sc: null, formation: null, fk: null, fkFormation: null, sel: null, mode: "drag",
  path: [], playing: false, inflight: false, pendingT0: null, latency: [],

  init(names) {
    this.top = document.getElementById("sheet-top");
    this.frameSvg = document.getElementById("sheet-frame");
    this.view3d = new View3D(document.getElementById("sheet-3d"));
    const sel = document.getElementById("sheet-example");
    const regular = [4, 8, 20].map(n => `regular ${n}-gon team`);
    fillSelect(sel, ["(choose)"].concat(names, regular), "(choose)");
    sel.addEventListener("change", () => {
      const m = /^regular (\d+)-gon team$/.exec(sel.value);
      if (m) this.load({regular: Number(m[1])});
      else if (sel.value !== "(choose)") this.load({example: sel.value});
    });
    onUpload(document.getElementById("sheet-upload"), body => this.load(body));
    document.getElementById("sheet-mass").addEventListener("change", () => this.requestFK(performance.now()));
    for (const r of document.querySelectorAll("input[name=sheet-mode]")) {
      r.addEventListener("change", () => { this.mode = r.value; this.status(); });
    }
    document.getElementById("sim-play").addEventListener("click", () => this.play());
    document.getElementById("sim-clear").addEventListener("click", () => { this.path = []; this.status(); this.draw(); });
    this.top.addEventListener("pointerdown", e => this.onDown(e));
    this.top.addEventListener("pointermove", e => this.onMove(e));
    this.top.addEventListener("pointerup", e => this.onUp(e));
    window.tautLatency = this.latency;
  },

  // Load a scenario: {example}, {text, filename}, {regular} or {scenario}. On failure the
  // message bar shows the loader's line and the current scenario stays.
  async load(body) {
    const r = await api("/api/sheet/load", body);
    if (!r.ok) return false;
    this.setScenario(r.data.scenario);
    showMessage(`loaded: ${this.sc.name || "sheet scenario"}`, "info");
    return true;
  },

  setScenario(sc) {
    this.sc = sc;
    this.formation = sc.formation.map(p => p.slice());
    this.path = []; this.fk = null;
    if (sc.mass) document.getElementById("sheet-mass").value = sc.mass;
    document.getElementById("ik-height").value = (sc.hold_height / 2).toPrecision(4);
    document.getElementById("ik-height-box").firstChild.textContent = `IK height [${this.units()}] `;
    const V = sc.sheet, cv = centroid(V);
    this.size = Math.max(...V.map(v => Math.hypot(v[0] - cv[0], v[1] - cv[1])));
    this.frame = new Frame(this.top, ...grow(bbox(this.formation), 0.3), 40);
    this.sframe = new Frame(this.frameSvg, ...grow(bbox(V), 0.08), 36);
    this.requestFK(performance.now());
    this.saveUrl();
  },

  mass() {
    const m = Number(document.getElementById("sheet-mass").value);
    return m > 0 ? m : null;
  },

  scenario() {
    return Object.assign({}, this.sc, {formation: this.formation, mass: this.mass() || undefined});
  },

  saveUrl() { if (this.sc) saveUrl({v: "sheet", s: this.scenario()}); },

  body(extra) {
    return Object.assign({sheet: this.sc.sheet, hold_height: this.sc.hold_height,
                          mass: this.mass()}, extra);
  },

  // --- forward kinematics, one request in flight; later drags coalesce ------------
  requestFK(t0) {
    if (!this.sc) return;
    if (this.inflight) { if (this.pendingT0 === null) this.pendingT0 = t0; return; }
    this.sendFK(t0);
  },

  async sendFK(t0) {
    this.inflight = true;
    const f = this.formation.map(p => p.slice()), tSend = performance.now();
    const r = await api("/api/sheet/fk", this.body({formation: f}));
    const tResp = performance.now();
    this.inflight = false;
    if (r.ok) {
      this.fk = r.data; this.fkFormation = f;
      this.sel = r.data.feasible ? (r.data.lowest !== null ? r.data.lowest : 0) : null;
      this.draw();
      const tDom = performance.now(), n = f.length, server = r.data.server_ms, feasible = r.data.feasible;
      requestAnimationFrame(() => {
        this.latency.push({n, feasible, ms: performance.now() - t0, dom: tDom - t0, server,
                           wait: tSend - t0, net: tResp - tSend, draw: tDom - tResp});
        if (this.latency.length > 5000) this.latency.shift();
      });
    }
    if (this.pendingT0 !== null) { const t = this.pendingT0; this.pendingT0 = null; this.sendFK(t); }
  },

  // --- pointer input ----------------------------------------------------------------
  robotAt(evt) {
    const t = evt.target.closest && evt.target.closest(".robot");
    return t ? Number(t.dataset.i) : null;
  },

  onDown(evt) {
    if (!this.sc || this.playing) return;
    const i = this.robotAt(evt);
    if (this.mode === "ik" && i === null) { this.ik(this.frame.world(evt)); return; }
    if (i === null) return;
    this.drag = i;
    this.top.setPointerCapture(evt.pointerId);
    if (this.mode === "simulate" && !this.path.length) this.path.push(this.formation.map(p => p.slice()));
  },

  onMove(evt) {
    if (this.drag === undefined || this.drag === null) return;
    this.formation[this.drag] = this.frame.world(evt);
    if (this.mode === "simulate") this.path.push(this.formation.map(p => p.slice()));
    this.drawRobots();
    this.requestFK(evt.timeStamp);
  },

  onUp() {
    if (this.drag === null || this.drag === undefined) return;
    this.drag = null;
    this.saveUrl();
    this.status();
  },

  async ik(p) {
    const h = Number(document.getElementById("ik-height").value);
    const r = await api("/api/sheet/ik", this.body({target: [p[0], p[1], h], reference: this.formation}));
    if (!r.ok) return;
    this.lastTarget = [p[0], p[1], h];
    this.formation = r.data.ik.formation;
    showMessage(`IK: every cable taut, object at (${p[0].toFixed(1)}, ${p[1].toFixed(1)}, ${h})`, "info");
    this.requestFK(performance.now());
    this.saveUrl();
  },

  // --- simulate a recorded drag path ----------------------------------------------
  densePath() {
    const out = [this.path[0]], step = this.size / 200;
    for (let k = 1; k < this.path.length; k++) {
      const a = this.path[k - 1], b = this.path[k];
      const d = Math.max(...a.map((p, i) => Math.hypot(b[i][0] - p[0], b[i][1] - p[1])));
      const m = Math.max(1, Math.ceil(d / step));
      for (let j = 1; j <= m; j++) out.push(a.map((p, i) => [p[0] + (b[i][0] - p[0]) * j / m, p[1] + (b[i][1] - p[1]) * j / m]));
    }
    return out;
  },

  async play() {
    if (this.path.length < 2) { showMessage("simulate: record a drag path first (simulate mode, drag a robot)", "error"); return; }
    const F = this.densePath();
    const r = await api("/api/sheet/simulate", this.body({formations: F}));
    if (!r.ok) return;
    const sim = r.data.simulation, jumps = sim.events.filter(e => e.kind === "jump"), u = this.units();
    this.sim = sim;
    document.getElementById("sim-events").textContent = jumps.length ?
      jumps.map(e => `jump at step ${e.step}/${F.length - 1}: taut {${e.taut_before.map(i => i + 1)}} -> {${e.taut_after.map(i => i + 1)}}, drop ${fmt(e.drop)} ${u}`).join("; ")
      : `no jump along ${F.length} steps`;
    this.drawSimCharts(F, sim, 0);
    this.playing = true;
    const T = F.length, per = Math.max(1, Math.ceil(T / 120));
    let k = 0;
    const frame = () => {
      this.formation = F[k];
      this.drawSimulation(F, sim, k);
      this.moveSimCursor(k);
      if (k < T - 1) { k = Math.min(T - 1, k + per); requestAnimationFrame(frame); return; }
      this.playing = false;
      document.getElementById("sheet-status").textContent += " (played)";
      this.requestFK(performance.now());
      this.saveUrl();
    };
    frame();
  },

  drawSimulation(F, sim, k) {
    this.drawBase(F[k], null);
    const g = el("g", {}, this.top), fr = this.frame;
    let d = "";
    for (let j = 0; j <= k; j++) {
      const o = sim.object[j];
      if (o[0] !== null) d += (d ? "L" : "M") + fr.x(o[0]).toFixed(1) + "," + fr.y(o[1]).toFixed(1);
    }
    el("path", {d, fill: "none", stroke: "#e07010", "stroke-width": 1.5}, g);
    for (const e of sim.events.filter(e => e.kind === "jump" && e.step <= k)) {
      const [x, y] = fr.pt(e.object_before);
      el("path", {d: `M${x - 6},${y - 6}L${x + 6},${y + 6}M${x - 6},${y + 6}L${x + 6},${y - 6}`,
                  stroke: "#c00", "stroke-width": 2.5, class: "jump"}, g);
    }
    const o = sim.object[k];
    if (o[0] !== null) {
      for (let i = 0; i < F[k].length; i++) {
        const taut = sim.taut[k].includes(i);
        const [x1, y1] = fr.pt(F[k][i]), [x2, y2] = fr.pt(o);
        el("line", {x1, y1, x2, y2, stroke: taut ? "#1f5fbf" : "#888", "stroke-width": taut ? 2 : 1,
                    "stroke-dasharray": taut ? "" : "3 4"}, g);
      }
      el("circle", {cx: fr.x(o[0]), cy: fr.y(o[1]), r: 6, fill: "#e07010"}, g);
    }
    this.drawRobots();
    document.getElementById("sheet-status").textContent =
      `simulate: step ${k}/${F.length - 1}, object height ${o[2] === null ? "lost" : o[2].toFixed(2) + " " + this.units()}`;
    document.getElementById("sheet-3d-caption").textContent =
      `3D: simulated state at step ${k}/${F.length - 1} (drag to turn)`;
    this.view3d.set({formation: F[k], hold: this.sc.hold_height, units: this.sc.units,
                     object: o[0] === null ? null : o, taut: sim.taut[k], note: "object lost"});
  },

  units() { return this.sc && this.sc.units ? this.sc.units : "sheet units"; },

  // Charts of a simulation: the object's height per step (jumps marked) and which
  // robots' cables are taut per step; a cursor follows the playback.
  drawSimCharts(F, sim, k) {
    document.getElementById("sim-charts").hidden = false;
    const steps = sim.object.map((o, j) => j), u = this.units(), jumps = sim.events.filter(e => e.kind === "jump");
    const jumpTrace = {type: "scatter", mode: "markers", name: "jump", x: jumps.map(e => e.step),
                       y: jumps.map(e => e.object_before[2]), marker: {symbol: "x", size: 10, color: "#c00"}};
    chart2d(document.getElementById("sim-height"), [
      line(steps, sim.object.map(o => o[2]), "object height", "#e07010"),
      jumpTrace,
    ], "step along the path [index]", `object height [${u}]`, {shapes: [cursor(k)]});
    const x = [], y = [];
    for (let i = 0; i < F[0].length; i++) {
      sim.taut.forEach((t, j) => { x.push(j); y.push(t.includes(i) ? i + 1 : null); });
      x.push(null); y.push(null);
    }
    chart2d(document.getElementById("sim-taut"), [line(x, y, "cable taut", "#1f5fbf", {line: {color: "#1f5fbf", width: 6}})],
            "step along the path [index]", "robot [1-based]", {shapes: [cursor(k)], y: {dtick: 1}});
  },

  moveSimCursor(k) {
    for (const id of ["sim-height", "sim-taut"]) Plotly.relayout(document.getElementById(id), {shapes: [cursor(k)]});
  },
};

function centroid(P) {
  return [P.reduce((s, p) => s + p[0], 0) / P.length, P.reduce((s, p) => s + p[1], 0) / P.length];
}
