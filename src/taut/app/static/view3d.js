// A small hand-written 3D view on a canvas: orthographic projection with azimuth and
// elevation turned by dragging. Draws one sheet equilibrium: robot posts, holding points,
// cables (taut solid, slack dotted), the sheet sketched as a fan from the holding points
// to the object, and the object.
"use strict";

class View3D {
  constructor(canvas) {
    this.canvas = canvas;
    this.az = -0.6; this.el = 0.45;
    this.scene = null;
    let last = null;
    canvas.addEventListener("pointerdown", e => { last = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
    canvas.addEventListener("pointermove", e => {
      if (!last) return;
      this.az += (e.clientX - last[0]) * 0.01;
      this.el = Math.max(-0.1, Math.min(1.5, this.el + (e.clientY - last[1]) * 0.01));
      last = [e.clientX, e.clientY];
      this.draw();
    });
    canvas.addEventListener("pointerup", () => { last = null; });
  }

  // scene: {formation [[x,y]], hold, object [x,y,z] | null, taut [i], scale}
  set(scene) { this.scene = scene; this.draw(); }

  project(p) {
    const s = this.scene, c = s.center;
    const x = p[0] - c[0], y = p[1] - c[1], z = p[2] - s.hold / 2;
    const ca = Math.cos(this.az), sa = Math.sin(this.az);
    const xr = ca * x - sa * y, yr = sa * x + ca * y;
    const ce = Math.cos(this.el), se = Math.sin(this.el);
    const u = xr, v = ce * z - se * yr, depth = ce * yr + se * z;
    const k = Math.min(this.canvas.width, this.canvas.height) * 0.42 / s.scale;
    return [this.canvas.width / 2 + k * u, this.canvas.height / 2 - k * v, depth];
  }

  line(ctx, a, b, color, dash = [], width = 1.2) {
    const p = this.project(a), q = this.project(b);
    ctx.setLineDash(dash); ctx.strokeStyle = color; ctx.lineWidth = width;
    ctx.beginPath(); ctx.moveTo(p[0], p[1]); ctx.lineTo(q[0], q[1]); ctx.stroke();
    ctx.setLineDash([]);
  }

  draw() {
    const ctx = this.canvas.getContext("2d"), s = this.scene;
    ctx.clearRect(0, 0, this.canvas.width, this.canvas.height);
    if (!s) return;
    const R = s.formation, n = R.length, z = s.hold;
    // ground grid
    const g = s.scale, c = s.center;
    for (let k = -2; k <= 2; k++) {
      const t = k * g / 2;
      this.line(ctx, [c[0] - g, c[1] + t, 0], [c[0] + g, c[1] + t, 0], "#e2e2e2");
      this.line(ctx, [c[0] + t, c[1] - g, 0], [c[0] + t, c[1] + g, 0], "#e2e2e2");
    }
    for (let i = 0; i < n; i++) {
      this.line(ctx, [R[i][0], R[i][1], 0], [R[i][0], R[i][1], z], "#777", [], 2);
    }
    if (!s.object) {
      ctx.fillStyle = "#8a1010"; ctx.font = "12px sans-serif";
      ctx.fillText(s.note || "no stable state", 8, 16);
      return;
    }
    const o = s.object;
    ctx.fillStyle = "rgba(70, 120, 200, 0.18)";
    for (let i = 0; i < n; i++) {
      const a = this.project([R[i][0], R[i][1], z]);
      const b = this.project([R[(i + 1) % n][0], R[(i + 1) % n][1], z]);
      const p = this.project(o);
      ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(b[0], b[1]); ctx.lineTo(p[0], p[1]);
      ctx.closePath(); ctx.fill();
    }
    const taut = new Set(s.taut);
    for (let i = 0; i < n; i++) {
      const h = [R[i][0], R[i][1], z];
      if (taut.has(i)) this.line(ctx, h, o, "#1f5fbf", [], 2);
      else this.line(ctx, h, o, "#888", [3, 4], 1);
    }
    this.line(ctx, o, [o[0], o[1], 0], "#d08020", [2, 3], 1);
    const p = this.project(o);
    ctx.fillStyle = "#e07010";
    ctx.beginPath(); ctx.arc(p[0], p[1], 6, 0, 2 * Math.PI); ctx.fill();
    ctx.fillStyle = "#333"; ctx.font = "11px sans-serif";
    for (let i = 0; i < n; i++) {
      const q = this.project([R[i][0], R[i][1], z]);
      ctx.fillText(String(i + 1), q[0] + 3, q[1] - 3);
    }
    ctx.fillText(`object height ${o[2].toFixed(2)}`, 8, this.canvas.height - 8);
  }
}
