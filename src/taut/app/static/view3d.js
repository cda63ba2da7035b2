// The sheet explorer's 3D view (Plotly.js scatter3d/mesh3d, turned with the mouse): robot
// posts, holding points, the sheet sketched as a fan from the holding points to the
// object, cables (taut solid, slack dotted) and the object. Lengths in the scenario's unit.
// The view follows once the input pauses for QUIET_MS: a WebGL redraw on every drag step
// (software-rendered in headless Chromium) would slow the top view's drag-to-redraw
// several-fold (measured with bench/bench_app_latency.py; see examples/app/README.md).
"use strict";

const QUIET_MS = 250;

class View3D {
  constructor(div) {
    this.div = div; this.scene = null; this.timer = null;
  }

  // scene: {formation [[x,y]], hold, object [x,y,z] | null, taut [i], note, units}
  set(scene) {
    this.scene = scene;
    if (this.timer !== null) clearTimeout(this.timer);
    this.timer = setTimeout(() => { this.timer = null; this.draw(); }, QUIET_MS);
  }

  draw() {
    const s = this.scene;
    if (!s) return;
    const R = s.formation, n = R.length, z = s.hold, u = s.units || "sheet units";
    const hold = R.map(p => [p[0], p[1], z]);
    const traces = [segments3(R.map((p, i) => [[p[0], p[1], 0], hold[i]]), "robots (posts)", "#777", {line: {color: "#777", width: 5}}),
                    {type: "scatter3d", mode: "markers+text", name: "holding points", x: hold.map(p => p[0]),
                     y: hold.map(p => p[1]), z: hold.map(p => p[2]), text: hold.map((p, i) => String(i + 1)),
                     marker: {size: 3, color: "#24344d"}, textposition: "top center"}];
    const notes = [];
    if (s.object) {
      const o = s.object, taut = new Set(s.taut), V = hold.concat([o]);
      traces.push({type: "mesh3d", name: "sheet (sketch)", showlegend: true, opacity: 0.25, color: "#4678c8",
                   x: V.map(p => p[0]), y: V.map(p => p[1]), z: V.map(p => p[2]), hoverinfo: "skip",
                   i: R.map((p, a) => a), j: R.map((p, a) => (a + 1) % n), k: R.map(() => n)});
      traces.push(segments3(hold.map((h, i) => [h, o]).filter((c, i) => taut.has(i)), "taut cable", "#1f5fbf"));
      const slack = hold.map((h, i) => [h, o]).filter((c, i) => !taut.has(i));
      if (slack.length) traces.push(segments3(slack, "slack cable", "#888", {line: {color: "#888", width: 2, dash: "dot"}}));
      traces.push({type: "scatter3d", mode: "markers", name: `object (height ${o[2].toFixed(2)} ${u})`,
                   x: [o[0]], y: [o[1]], z: [o[2]], marker: {size: 6, color: "#e07010"}});
    } else {
      notes.push({text: s.note || "no stable state", x: 0.02, y: 0.98, xref: "paper", yref: "paper",
                  showarrow: false, font: {color: "#8a1010"}});
    }
    chart3d(this.div, traces, [`x [${u}]`, `y [${u}]`, `z [${u}]`], {annotations: notes, zoom: 0.7});
  }
}
