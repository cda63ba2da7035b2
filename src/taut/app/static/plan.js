// Planner viewer: load a planning scenario, run the planner (the server runs the SE(2)
// bypass baseline, the same search with crossing disabled, then the planner with obstacle
// crossing, and reports progress), animate and scrub the plan, plot object height over
// obstacles and the least sheet slack (the library's plan_profile), and compare with the
// baseline.
"use strict";

const PlanView = {
  sc: null, world: null, result: null, k: 0, playing: false, job: null,

  init(names) {
    this.top = document.getElementById("plan-top");
    const sel = document.getElementById("plan-example");
    fillSelect(sel, ["(choose)"].concat(names), "(choose)");
    sel.addEventListener("change", () => { if (sel.value !== "(choose)") this.load({example: sel.value}); });
    onUpload(document.getElementById("plan-upload"), body => this.load(body));
    document.getElementById("plan-run").addEventListener("click", () => this.run());
    document.getElementById("plan-play").addEventListener("click", () => this.toggle());
    const slider = document.getElementById("plan-time");
    slider.addEventListener("input", () => { this.k = Number(slider.value); this.drawFrame(); });
  },

  async load(body, {run = false, k = 0} = {}) {
    const r = await api("/api/plan/load", body);
    if (!r.ok) return false;
    this.sc = r.data.scenario; this.world = r.data.world; this.result = null; this.k = 0;
    const w = this.world;
    this.frame = new Frame(this.top, ...grow(bbox(w.free_space), 0.02), 12);
    document.getElementById("plan-time").max = 0;
    document.getElementById("plan-compare").innerHTML = "";
    clear(document.getElementById("plan-height")); clear(document.getElementById("plan-margin"));
    document.getElementById("plan-clock").textContent = "";
    showMessage(`loaded: ${this.sc.name || "planning scenario"}`, "info");
    this.drawFrame();
    this.saveUrl();
    if (run) await this.run(k);
    return true;
  },

  saveUrl() { if (this.sc) saveUrl({v: "plan", s: this.sc, k: this.result ? this.k : null}); },

  async run(k = 0) {
    if (!this.sc) { showMessage("planner: load a scenario first", "error"); return; }
    const r = await api("/api/plan/run", {scenario: this.sc});
    if (!r.ok) return;
    const id = r.data.job, bar = document.getElementById("plan-progress");
    const stage = document.getElementById("plan-stage");
    document.getElementById("plan-run").disabled = true;
    this.job = id;
    for (;;) {
      const s = await api(`/api/plan/job/${id}`);
      if (!s.ok) break;
      bar.max = s.data.steps; bar.value = s.data.state === "running" ? s.data.step - 0.5 : s.data.steps;
      stage.textContent = s.data.state === "running" ?
        `step ${s.data.step}/${s.data.steps}: ${s.data.stage}, ${s.data.elapsed.toFixed(1)} s` :
        `done in ${s.data.elapsed.toFixed(1)} s`;
      if (s.data.state === "error") { showMessage(s.data.error, "error"); break; }
      if (s.data.state === "done") { this.show(s.data, k); break; }
      await new Promise(res => setTimeout(res, 250));
    }
    document.getElementById("plan-run").disabled = false;
  },

  show(data, k) {
    this.result = data;
    const p = data.plan, n = p.times.length;
    const slider = document.getElementById("plan-time");
    slider.max = Math.max(0, n - 1);
    this.k = Math.min(k || 0, Math.max(0, n - 1)); slider.value = this.k;
    showMessage(p.success ? `plan: ${p.duration.toFixed(2)} s, path ${p.path_length.toFixed(3)} m, crossed [${p.crossed}]`
                          : `no plan: ${p.message}`, p.success ? "info" : "error");
    this.drawCompare();
    this.drawFrame();
    this.saveUrl();
  },

  toggle() {
    if (!this.result || !this.result.plan.times.length) return;
    this.playing = !this.playing;
    document.getElementById("plan-play").textContent = this.playing ? "Pause" : "Play";
    if (!this.playing) return;
    const p = this.result.plan, T = p.times;
    if (this.k >= T.length - 1) this.k = 0;
    let t0 = performance.now(), tStart = T[this.k];
    const step = () => {
      if (!this.playing) return;
      const speed = Number(document.getElementById("plan-speed").value);
      const t = tStart + (performance.now() - t0) / 1000 * speed;
      while (this.k < T.length - 1 && T[this.k + 1] <= t) this.k++;
      document.getElementById("plan-time").value = this.k;
      this.drawFrame();
      if (this.k >= T.length - 1) { this.playing = false; document.getElementById("plan-play").textContent = "Play"; this.saveUrl(); return; }
      requestAnimationFrame(step);
    };
    requestAnimationFrame(step);
  },

  drawFrame() {
    if (!this.world) return;
    const svg = this.top, fr = this.frame, w = this.world;
    clear(svg);
    el("polygon", {points: fr.poly(w.free_space), fill: "#fff", stroke: "#333", "stroke-width": 2}, svg);
    for (const o of w.obstacles) {
      el("polygon", {points: fr.poly(o.polygon), fill: "#bbb", stroke: "#666"}, svg);
      const c = centroid(o.polygon);
      el("text", {x: fr.x(c[0]) - 14, y: fr.y(c[1]) + 4, "font-size": 10}, svg).textContent = `${o.id}: ${o.height} m`;
    }
    for (const [p, label] of [[w.start, "start"], [w.goal, "goal"]]) {
      el("circle", {cx: fr.x(p[0]), cy: fr.y(p[1]), r: 4, fill: "#24344d"}, svg);
      el("text", {x: fr.x(p[0]) + 5, y: fr.y(p[1]) - 5, "font-size": 11}, svg).textContent = label;
    }
    if (!this.result) return;
    const b = this.result.baseline, p = this.result.plan;
    if (b.success) this.path(b.object, "#999", "6 3");
    if (!p.success || !p.times.length) return;
    this.path(p.object, "#e07010", "4 3");
    const k = this.k, R = p.robots[k], o = p.object[k], taut = new Set(p.taut[k]);
    el("polygon", {points: fr.poly(R), fill: "rgba(70,120,200,0.25)", stroke: "#46c"}, svg);
    R.forEach((r, i) => {
      const t = taut.has(i);
      el("line", {x1: fr.x(r[0]), y1: fr.y(r[1]), x2: fr.x(o[0]), y2: fr.y(o[1]), stroke: t ? "#1f5fbf" : "#888",
                  "stroke-dasharray": t ? "" : "3 3"}, svg);
      el("circle", {cx: fr.x(r[0]), cy: fr.y(r[1]), r: w.robot_radius * fr.s, fill: "rgba(36,52,77,0.55)"}, svg);
    });
    el("circle", {cx: fr.x(o[0]), cy: fr.y(o[1]), r: 5, fill: "#e07010", class: "plan-object"}, svg);
    const end = k === p.times.length - 1;
    const clock = document.getElementById("plan-clock");
    clock.textContent = `t = ${p.times[k].toFixed(2)} s / ${p.duration.toFixed(2)} s, object height ${o[2].toFixed(3)} m` + (end ? " (end)" : "");
    clock.dataset.end = end ? "1" : "0";
    this.drawPlots(p, p.times[k]);
  },

  path(obj, color, dash) {
    const fr = this.frame;
    const d = obj.map((o, i) => (i ? "L" : "M") + fr.x(o[0]).toFixed(1) + "," + fr.y(o[1]).toFixed(1)).join("");
    el("path", {d, fill: "none", stroke: color, "stroke-width": 1.5, "stroke-dasharray": dash}, this.top);
  },

  drawPlots(p, tc) {
    const t = p.times, hs = this.world.height_safety;
    linePlot(document.getElementById("plan-height"), [
      {t, y: p.object.map(o => o[2]), color: "#e07010", label: "object height"},
      {t, y: p.beneath_height_m.map(v => v > 0 ? v : null), color: "#666", label: "obstacle beneath"},
      {t, y: p.height_over_obstacle_m, color: "#1a8a2a", label: "height over obstacle"},
      {t, y: t.map(() => hs), color: "#c00", dash: "3 3", label: "height safety"},
    ], {tc, zero: true});
    linePlot(document.getElementById("plan-margin"), [
      {t, y: p.sheet_slack_m, color: "#46c", label: "least sheet slack"},
    ], {tc, zero: true});
  },

  drawCompare() {
    const tb = document.getElementById("plan-compare"), d = this.result;
    tb.innerHTML = "";
    const head = tb.insertRow();
    for (const h of ["", "success", "duration [s]", "path [m]", "crossed", "bypassed", "object height [m]", "message"]) {
      const th = document.createElement("th"); th.textContent = h; head.appendChild(th);
    }
    for (const [name, r] of [["planner (crossing)", d.plan], ["baseline (SE(2) bypass, no crossing)", d.baseline]]) {
      const row = tb.insertRow();
      row.dataset.planner = r.planner;
      [name, r.success ? "yes" : "no", fmt(r.duration), fmt(r.path_length, 3), r.crossed.join(", ") || "-",
       r.bypassed.join(", ") || "-", fmt(r.object_height, 3), r.message].forEach(c => { row.insertCell().textContent = c; });
    }
  },
};
