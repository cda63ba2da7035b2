// Planner viewer: load a planning scenario, choose the planner's settings (those of
// taut.plan.plan, offered by the server with the library's defaults), run the planner (the
// server runs the bypass baseline, then the planner with obstacle crossing, and reports
// progress), animate and scrub the plan, plot object height over obstacles and the least
// sheet slack (the library's plan_profile), compare with the baseline and download the
// plan as the JSON file `taut plan --out` writes or as a ROS 2 recording (MCAP). Every
// chart in metres and seconds.
"use strict";

const PlanView = {
  sc: null, world: null, result: null, k: 0, playing: false, job: null, built: false,

  init(names) {
    const sel = document.getElementById("plan-example");
    fillSelect(sel, ["(choose)"].concat(names), "(choose)");
    sel.addEventListener("change", () => { if (sel.value !== "(choose)") this.load({example: sel.value}); });
    onUpload(document.getElementById("plan-upload"), body => this.load(body));
    document.getElementById("plan-run").addEventListener("click", () => this.run());
    document.getElementById("plan-play").addEventListener("click", () => this.toggle());
    document.getElementById("plan-save-json").addEventListener("click", () => this.save());
    document.getElementById("plan-save-mcap").addEventListener("click", () => this.saveMcap());
    const slider = document.getElementById("plan-time");
    slider.addEventListener("input", () => { this.k = Number(slider.value); this.drawFrame(); });
  },

  // The settings row, once, from the library's signature (world.settings).
  buildSettings(settings) {
    if (this.built) return;
    this.built = true;
    const box = document.getElementById("plan-settings");
    const labels = {method: "method", search: "search", baseline: "compare with baseline",
                    sheet_margin: "sheet margin [m]", spacing: "lattice spacing [m]",
                    iterations: "iterations [samples]", seed: "seed"};
    for (const [name, s] of Object.entries(settings)) {
      const lab = document.createElement("label");
      lab.textContent = labels[name] + " ";
      let input;
      if (s.choices) {
        input = document.createElement("select");
        fillSelect(input, s.choices, s.default);
      } else {
        input = document.createElement("input");
        input.type = "number"; input.value = s.default;
        input.step = Number.isInteger(s.default) ? "1" : "0.005";
      }
      input.id = "plan-opt-" + name; input.dataset.setting = name;
      lab.appendChild(input); box.appendChild(lab);
    }
  },

  // The settings as given: numbers as numbers, choices as strings (the library checks them).
  options() {
    const out = {};
    for (const input of document.querySelectorAll("#plan-settings [data-setting]")) {
      out[input.dataset.setting] = input.tagName === "SELECT" ? input.value :
        (input.value.trim() === "" ? input.value : Number(input.value));
    }
    return out;
  },

  async load(body, {run = false, k = 0, options = null} = {}) {
    const r = await api("/api/plan/load", body);
    if (!r.ok) return false;
    this.sc = r.data.scenario; this.world = r.data.world; this.result = null; this.k = 0;
    this.buildSettings(this.world.settings);
    if (options) for (const [name, v] of Object.entries(options)) {
      const input = document.getElementById("plan-opt-" + name);
      if (input) input.value = v;
    }
    document.getElementById("plan-time").max = 0;
    document.getElementById("plan-compare").innerHTML = "";
    document.getElementById("plan-clock").textContent = "";
    document.getElementById("plan-save-json").disabled = true;
    document.getElementById("plan-save-mcap").disabled = true;
    for (const id of ["plan-height", "plan-margin"]) Plotly.purge(document.getElementById(id));
    showMessage(`loaded: ${this.sc.name || "planning scenario"}`, "info");
    this.drawFrame();
    this.saveUrl();
    if (run) await this.run(k);
    return true;
  },

  saveUrl() {
    if (this.sc) saveUrl({v: "plan", s: this.sc, k: this.result ? this.k : null, o: this.options()});
  },

  async run(k = 0) {
    if (!this.sc) { showMessage("planner: load a scenario first", "error"); return; }
    const r = await api("/api/plan/run", {scenario: this.sc, options: this.options()});
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
    document.getElementById("plan-save-json").disabled = false;
    const mcap = document.getElementById("plan-save-mcap");
    mcap.disabled = !data.plan_mcap;
    mcap.title = data.plan_mcap ? "ROS 2 recording (Foxglove, RViz, ros2 bag play)" : data.plan_mcap_note;
    this.drawCompare();
    this.drawFrame();
    this.saveUrl();
  },

  // The plan as `taut plan --out` writes it (serialized by the library in the worker).
  save() {
    if (!this.result) { showMessage("planner: run the planner first", "error"); return; }
    taut.lastPlanJson = this.result.plan_json;
    download(this.result.plan_json, "plan.json", "application/json");
  },

  // The plan as a ROS 2 recording (taut.io.write_mcap in the worker; base64 in the reply).
  saveMcap() {
    if (!this.result || !this.result.plan_mcap) { showMessage("planner: " + (this.result ? this.result.plan_mcap_note : "run the planner first"), "error"); return; }
    const bytes = Uint8Array.from(atob(this.result.plan_mcap), c => c.charCodeAt(0));
    taut.lastPlanMcap = bytes.length;
    download(bytes, "plan.mcap", "application/octet-stream");
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

  // The map: walls, obstacles with their heights, start and goal, both plans' object
  // paths, and the team at the current sample (taut cables solid, slack dotted).
  drawFrame() {
    if (!this.world) return;
    const w = this.world, traces = [polygon(w.free_space, "free space (walls)", "rgba(255,255,255,0)", "#333", {line: {color: "#333", width: 2}})];
    const notes = [];
    w.obstacles.forEach((o, i) => {
      traces.push(polygon(o.polygon, "obstacles (height [m])", "rgba(150,150,150,0.6)", "#666",
                          {legendgroup: "obstacles", showlegend: i === 0}));
      const c = centroid(o.polygon);
      notes.push({x: c[0], y: c[1], text: `${o.id}: ${o.height} m`, showarrow: false, font: {size: 10}});
    });
    traces.push({type: "scatter", mode: "markers+text", x: [w.start[0], w.goal[0]], y: [w.start[1], w.goal[1]],
                 text: ["start", "goal"], textposition: "top right", name: "start, goal",
                 marker: {color: "#24344d", size: 8}});
    if (this.result) this.teamTraces(traces);
    chart2d(document.getElementById("plan-top"), traces, "x [m]", "y [m]", {equal: true, annotations: notes});
    if (this.result && this.result.plan.success && this.result.plan.times.length) {
      const p = this.result.plan, k = this.k, o = p.object[k], end = k === p.times.length - 1;
      const clock = document.getElementById("plan-clock");
      clock.textContent = `t = ${p.times[k].toFixed(2)} s / ${p.duration.toFixed(2)} s, object height ${o[2].toFixed(3)} m` + (end ? " (end)" : "");
      clock.dataset.end = end ? "1" : "0";
      this.drawPlots(p, p.times[k]);
    }
  },

  teamTraces(traces) {
    const b = this.result.baseline, p = this.result.plan, w = this.world;
    const xy = obj => [obj.map(o => o[0]), obj.map(o => o[1])];
    if (b.success) traces.push(line(...xy(b.object), `baseline object path (${b.planner})`, "#999", {line: {color: "#999", dash: "dash", width: 1.5}}));
    if (!p.success || !p.times.length) return;
    traces.push(line(...xy(p.object), "planned object path", "#e07010", {line: {color: "#e07010", dash: "dot", width: 2}}));
    const k = this.k, R = p.robots[k], o = p.object[k], taut = new Set(p.taut[k]);
    traces.push(polygon(R, "team", "rgba(70,120,200,0.2)", "#46c"));
    const cab = t => { const x = [], y = []; R.forEach((r, i) => { if (taut.has(i) === t) x.push(r[0], o[0], null), y.push(r[1], o[1], null); }); return [x, y]; };
    traces.push(line(...cab(true), "taut cable", "#1f5fbf", {line: {color: "#1f5fbf", width: 2}}));
    traces.push(line(...cab(false), "slack cable", "#888", {line: {color: "#888", dash: "dot", width: 1}}));
    traces.push({type: "scatter", mode: "markers+text", x: R.map(r => r[0]), y: R.map(r => r[1]), name: "robots",
                 text: R.map((r, i) => String(i + 1)), textfont: {color: "#fff", size: 9},
                 marker: {color: "rgba(36,52,77,0.8)", size: Math.max(8, 2 * w.robot_radius * this.pxPerM())}});
    traces.push({type: "scatter", mode: "markers", x: [o[0]], y: [o[1]], name: "object",
                 marker: {color: "#e07010", size: 10}});
  },

  // Pixels per metre of the map (robot markers drawn at the robots' size).
  pxPerM() {
    const fl = document.getElementById("plan-top")._fullLayout;
    return fl && fl.xaxis && fl.xaxis._m ? Math.abs(fl.xaxis._m) : 30;
  },

  drawPlots(p, tc) {
    const t = p.times, hs = this.world.height_safety;
    chart2d(document.getElementById("plan-height"), [
      line(t, p.object.map(o => o[2]), "object height", "#e07010"),
      line(t, p.beneath_height_m.map(v => v > 0 ? v : null), "obstacle beneath", "#666"),
      line(t, p.height_over_obstacle_m, "height over obstacle", "#1a8a2a"),
      line(t, t.map(() => hs), "height safety", "#c00", {line: {color: "#c00", dash: "dash", width: 1}}),
    ], "time t [s]", "height [m]", {shapes: [cursor(tc)], y: {rangemode: "tozero"}});
    chart2d(document.getElementById("plan-margin"), [
      line(t, p.sheet_slack_m, "least sheet slack over robot pairs", "#46c"),
    ], "time t [s]", "slack [m]", {shapes: [cursor(tc)], y: {rangemode: "tozero"}});
  },

  drawCompare() {
    const tb = document.getElementById("plan-compare"), d = this.result;
    tb.innerHTML = "";
    const head = tb.insertRow();
    for (const h of ["", "success", "duration [s]", "path [m]", "crossed", "bypassed", "object height [m]", "message"]) {
      const th = document.createElement("th"); th.textContent = h; head.appendChild(th);
    }
    const base = d.baseline.planner === "disc" ? "disc-model bypass" : "SE(2) bypass";
    for (const [name, r] of [["planner (crossing)", d.plan], [`baseline (${base}, no crossing)`, d.baseline]]) {
      const row = tb.insertRow();
      row.dataset.planner = r.planner;
      [name, r.success ? "yes" : "no", fmt(r.duration), fmt(r.path_length, 3), r.crossed.join(", ") || "-",
       r.bypassed.join(", ") || "-", fmt(r.object_height, 3), r.message].forEach(c => { row.insertCell().textContent = c; });
    }
  },
};
