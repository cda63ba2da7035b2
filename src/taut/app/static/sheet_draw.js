// Drawing of the sheet explorer (top view, sheet frame, 3D, table, status line).
"use strict";

Object.assign(SheetView, {
  draw() {
    if (!this.sc) return;
    const fk = this.fk, F = this.fkFormation || this.formation;
    this.drawBase(F, fk);
    if (fk && fk.feasible) this.drawEquilibria(F, fk);
    this.drawRobots();
    this.drawSheetFrame(fk);
    this.drawTable(fk);
    this.draw3D(F, fk);
    this.status();
  },

  // Robot polygon, the recorded path, an infeasible pair.
  drawBase(F, fk) {
    clear(this.top);
    const fr = this.frame;
    svgAxes(fr, `x [${this.units()}]`, `y [${this.units()}]`);
    el("polygon", {points: fr.poly(F), fill: "rgba(70,120,200,0.06)", stroke: "#9ab",
                   "stroke-dasharray": "2 3"}, this.top);
    if (this.path.length > 1) {
      for (let i = 0; i < F.length; i++) {
        const d = this.path.map((f, k) => (k ? "L" : "M") + fr.x(f[i][0]).toFixed(1) + "," + fr.y(f[i][1]).toFixed(1)).join("");
        el("path", {d, fill: "none", stroke: "#b9c", "stroke-width": 1}, this.top);
      }
    }
    if (fk && !fk.feasible) {
      const [i, j] = fk.pair, [x1, y1] = fr.pt(F[i]), [x2, y2] = fr.pt(F[j]);
      el("line", {x1, y1, x2, y2, stroke: "#c00", "stroke-width": 3, "stroke-dasharray": "6 4",
                  class: "infeasible-pair"}, this.top);
    }
    this.robotLayer = el("g", {}, this.top);
  },

  drawEquilibria(F, fk) {
    const fr = this.frame, g = el("g", {}, this.top);
    this.top.insertBefore(g, this.robotLayer);
    fk.equilibria.forEach((e, k) => {
      const sel = k === this.sel, col = KIND_COLOR[e.kind], taut = new Set(e.taut);
      const [ox, oy] = fr.pt(e.object);
      for (let i = 0; i < F.length; i++) {
        const [x, y] = fr.pt(F[i]), t = taut.has(i);
        if (!t && !sel) continue;              // slack cables: of the selected state only
        el("line", {x1: x, y1: y, x2: ox, y2: oy, stroke: t ? col : "#aaa",
                    "stroke-width": sel ? (t ? 2.2 : 1.2) : 0.8, opacity: sel ? 1 : 0.35,
                    "stroke-dasharray": t ? "" : "3 4"}, g);
      }
      el("circle", {cx: ox, cy: oy, r: sel ? 7 : 4.5, fill: e.kind === "not_equilibrium" ? "none" : col,
                    stroke: col, "stroke-width": 2, class: "equilibrium"}, g);
    });
  },

  drawRobots() {
    if (!this.robotLayer) return;
    clear(this.robotLayer);
    this.formation.forEach((p, i) => {
      const [x, y] = this.frame.pt(p);
      const g = el("g", {class: "robot", "data-i": i, transform: `translate(${x.toFixed(1)},${y.toFixed(1)})`}, this.robotLayer);
      el("circle", {r: 9, fill: "#24344d"}, g);
      el("text", {x: -4, y: 4, fill: "#fff", "font-size": 11}, g).textContent = String(i + 1);
    });
  },

  drawSheetFrame(fk) {
    const svg = this.frameSvg, fr = this.sframe, V = this.sc.sheet;
    clear(svg);
    svgAxes(fr, `x, sheet frame [${this.units()}]`, `y, sheet frame [${this.units()}]`);
    el("polygon", {points: fr.poly(V), fill: "rgba(70,120,200,0.12)", stroke: "#46c"}, svg);
    V.forEach((v, i) => {
      el("text", {x: fr.x(v[0]) + 3, y: fr.y(v[1]) - 3, "font-size": 11}, svg).textContent = String(i + 1);
    });
    if (!fk || !fk.feasible) return;
    fk.equilibria.forEach((e, k) => {
      const sel = k === this.sel, col = KIND_COLOR[e.kind], taut = new Set(e.taut);
      const [cx, cy] = fr.pt(e.contact);
      if (sel) V.forEach((v, i) => {
        const t = taut.has(i), [x, y] = fr.pt(v);
        el("line", {x1: x, y1: y, x2: cx, y2: cy, stroke: t ? col : "#aaa", "stroke-width": t ? 2 : 1,
                    "stroke-dasharray": t ? "" : "3 4"}, svg);
      });
      el("circle", {cx, cy, r: sel ? 5 : 3, fill: col}, svg);
    });
  },

  drawTable(fk) {
    const tb = document.getElementById("sheet-table");
    clear(tb);
    if (!fk || !fk.feasible) return;
    const head = tb.insertRow();
    for (const h of ["#", "taut", "x_o", "y_o", "z_o", "kind", "tensions [N]"]) {
      const th = document.createElement("th"); th.textContent = h; head.appendChild(th);
    }
    fk.equilibria.forEach((e, k) => {
      const row = tb.insertRow();
      row.className = "equilibrium-row" + (k === this.sel ? " selected" : "");
      row.dataset.k = k;
      const cells = [k + 1, "{" + e.taut.map(i => i + 1).join(",") + "}", fmt(e.object[0]), fmt(e.object[1]),
                     fmt(e.object[2]), e.kind, e.tensions ? e.tensions.map(t => t.toFixed(3)).join(", ") : "-"];
      cells.forEach(c => { row.insertCell().textContent = c; });
      row.addEventListener("click", () => { this.sel = k; this.draw(); });
    });
  },

  draw3D(F, fk) {
    const low = fk && fk.feasible && fk.lowest !== null ? fk.equilibria[fk.lowest] : null;
    document.getElementById("sheet-3d-caption").textContent = "3D: lowest stable state (drag to turn)";
    this.view3d.set({formation: F, hold: this.sc.hold_height, units: this.sc.units,
                     object: low ? low.object : null, taut: low ? low.taut : [],
                     note: fk && !fk.feasible ? "infeasible formation" : "no stable state"});
  },

  status() {
    const s = document.getElementById("sheet-status"), fk = this.fk;
    if (!this.sc || !fk) { s.textContent = ""; return; }
    const u = this.sc.units ? " " + this.sc.units : "";
    let text;
    if (!fk.feasible) {
      text = `INFEASIBLE formation: robots ${fk.pair[0] + 1} and ${fk.pair[1] + 1} are too far apart (${fk.message.replace(/^formation: /, "")})`;
    } else {
      const low = fk.lowest !== null ? fk.equilibria[fk.lowest] : null;
      text = `${fk.equilibria.length} equilibria, ${fk.stable_count} stable` +
        (low ? `; lowest stable: object height ${low.height.toFixed(2)}${u}, taut {${low.taut.map(i => i + 1)}}` : "; no stable state");
    }
    if (this.mode === "simulate") text += ` | recorded path: ${this.path.length} formations`;
    s.textContent = text;
    s.dataset.feasible = fk.feasible ? "1" : "0";
  },
});
