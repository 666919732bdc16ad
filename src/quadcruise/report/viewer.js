/* quadcruise report: interactive 3-D view of logged flights, plain JavaScript on a canvas.
 *
 * Each div.qc-view holds a canvas and a JSON script element of class qc-data:
 * {flights: [{label, color, t, x, y, z, ref, ok, status}], refs: [{t, x, y, z}]}; null
 * marks an instant after a vehicle stopped. Drag to orbit, shift-drag (or right-drag) to
 * pan, wheel to zoom, double-click to reset. After each drawing the canvas gets
 * data-rendered="1" (read by the tests through the DOM).
 */
(function () {
  "use strict";

  const DEG = Math.PI / 180;
  const HOME = { az: -60 * DEG, el: 28 * DEG, zoom: 1, px: 0, py: 0 };

  function niceStep(span, n) {
    const raw = span / Math.max(n, 1);
    const p = Math.pow(10, Math.floor(Math.log10(raw)));
    const m = raw / p;
    return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
  }

  function tickText(v, step) {
    const d = Math.max(0, -Math.floor(Math.log10(step) + 1e-9));
    const s = v.toFixed(d);
    return s === "-0" || /^-0\.0*$/.test(s) ? s.slice(1) : s;
  }

  function ticks(lo, hi, step) {
    const out = [];
    for (let v = Math.ceil(lo / step - 1e-9) * step; v <= hi + 1e-9 * step; v += step) out.push(v);
    return out;
  }

  function num(v, d) { const s = v.toFixed(d); return /^-0\.?0*$/.test(s) ? s.slice(1) : s; }

  function finite(v) { return v !== null && Number.isFinite(v); }

  /* index i with t[i] <= v < t[i + 1], clamped to the ends */
  function bisect(t, v) {
    let lo = 0, hi = t.length - 1;
    if (v <= t[0]) return 0;
    if (v >= t[hi]) return hi;
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (t[mid] <= v) lo = mid; else hi = mid;
    }
    return lo;
  }

  /* position of a series at time v (linear between finite samples), or null */
  function sampleAt(s, v) {
    const i = bisect(s.t, v);
    if (!finite(s.x[i])) return null;
    const j = Math.min(i + 1, s.t.length - 1);
    if (j === i || !finite(s.x[j]) || v <= s.t[i]) return [s.x[i], s.y[i], s.z[i]];
    const a = Math.min(1, (v - s.t[i]) / (s.t[j] - s.t[i]));
    return [s.x[i] + a * (s.x[j] - s.x[i]), s.y[i] + a * (s.y[j] - s.y[i]), s.z[i] + a * (s.z[j] - s.z[i])];
  }

  function lastFinite(s) {
    for (let i = s.x.length - 1; i >= 0; i--) if (finite(s.x[i])) return i;
    return -1;
  }

  function el(tag, attrs, text) {
    const e = document.createElement(tag);
    for (const k in attrs || {}) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    return e;
  }

  function Viewer(root) {
    this.root = root;
    this.data = JSON.parse(root.querySelector("script.qc-data").textContent);
    this.canvas = root.querySelector("canvas");
    this.ctx = this.canvas.getContext("2d");
    this.flights = this.data.flights;
    this.refs = this.data.refs || [];
    this.visible = this.flights.map(() => true);
    this.showRef = true;
    this.view = Object.assign({}, HOME);
    this.bounds();
    this.t = this.t1;
    this.controls();
    this.bind();
    this.resize();
  }

  Viewer.prototype.bounds = function () {
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    let t0 = Infinity, t1 = -Infinity;
    for (const s of this.flights.concat(this.refs)) {
      for (let i = 0; i < s.t.length; i++) {
        const p = [s.x[i], s.y[i], s.z[i]];
        if (!p.every(finite)) continue;
        for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], p[k]); hi[k] = Math.max(hi[k], p[k]); }
      }
      if (s.t.length) { t0 = Math.min(t0, s.t[0]); t1 = Math.max(t1, s.t[s.t.length - 1]); }
    }
    if (!Number.isFinite(lo[0])) { lo.fill(0); hi.fill(1); }
    if (!Number.isFinite(t0)) { t0 = 0; t1 = 1; }
    const half = [0, 1].map(k => Math.max((hi[k] - lo[k]) / 2 * 1.06, 0.25));
    const big = Math.max(half[0], half[1]);
    // the floor is the ground (z = 0) when the flight is not far above it
    const floor = lo[2] >= 0 && lo[2] <= 2 * big ? 0 : lo[2];
    const top = Math.max(hi[2] + 0.03 * big, floor + 0.5);
    this.box = { lo: [(lo[0] + hi[0]) / 2 - half[0], (lo[1] + hi[1]) / 2 - half[1], floor],
                 hi: [(lo[0] + hi[0]) / 2 + half[0], (lo[1] + hi[1]) / 2 + half[1], top] };
    this.center = [0, 1, 2].map(k => (this.box.lo[k] + this.box.hi[k]) / 2);
    this.radius = Math.hypot(half[0], half[1], (top - floor) / 2);
    this.t0 = t0;
    this.t1 = t1;
  };

  Viewer.prototype.controls = function () {
    const side = this.root.querySelector(".qc-side");
    const list = el("div", { class: "qc-flights" });
    this.readouts = [];
    this.flights.forEach((f, i) => {
      const row = el("label", { class: "qc-flight" });
      const box = el("input", { type: "checkbox", "data-flight": String(i) });
      box.checked = true;
      box.addEventListener("change", () => { this.visible[i] = box.checked; this.draw(); });
      const sw = el("span", { class: "qc-swatch" });
      sw.style.background = f.color;
      row.append(box, sw, el("span", { class: "qc-name" }, f.label));
      if (!f.ok) row.append(el("span", { class: "qc-stopped" }, f.status));
      const out = el("div", { class: "qc-readout" });
      this.readouts.push(out);
      list.append(row, out);
    });
    if (this.refs.length) {
      const row = el("label", { class: "qc-flight" });
      const box = el("input", { type: "checkbox", "data-ref": "1" });
      box.checked = true;
      box.addEventListener("change", () => { this.showRef = box.checked; this.draw(); });
      row.append(box, el("span", { class: "qc-swatch qc-dashed" }), el("span", { class: "qc-name" }, "reference (dashed)"));
      list.append(row);
    }
    const time = el("div", { class: "qc-time" });
    this.slider = el("input", { type: "range", min: "0", max: "1000", step: "1", value: "1000",
                                "aria-label": "time" });
    this.tlabel = el("span", { class: "qc-tlabel" });
    this.play = el("button", { type: "button", class: "qc-play" }, "▶ play");
    this.slider.addEventListener("input", () => {
      this.t = this.t0 + (this.t1 - this.t0) * Number(this.slider.value) / 1000;
      this.draw();
    });
    this.play.addEventListener("click", () => this.toggle());
    time.append(el("div", { class: "qc-trow" }, ""), this.slider);
    time.firstChild.append(this.play, this.tlabel);
    const views = el("div", { class: "qc-buttons" });
    for (const [name, v] of [["reset", HOME], ["top", { az: -90 * DEG, el: 89.9 * DEG }],
                             ["side (x-z)", { az: -90 * DEG, el: 0 }], ["side (y-z)", { az: 0, el: 0 }]]) {
      const b = el("button", { type: "button" }, name);
      b.addEventListener("click", () => { Object.assign(this.view, HOME, v); this.draw(); });
      views.append(b);
    }
    side.append(list, time, views);
  };

  Viewer.prototype.toggle = function () {
    if (this.playing) { this.playing = false; this.play.textContent = "▶ play"; return; }
    if (this.t >= this.t1) this.t = this.t0;
    this.playing = true;
    this.play.textContent = "❚❚ pause";
    let last = null;
    const step = (now) => {
      if (!this.playing) return;
      if (last !== null) this.t = Math.min(this.t1, this.t + (now - last) / 1000 * Math.max(1, (this.t1 - this.t0) / 20));
      last = now;
      this.slider.value = String(Math.round(1000 * (this.t - this.t0) / ((this.t1 - this.t0) || 1)));
      this.draw();
      if (this.t >= this.t1) this.toggle(); else requestAnimationFrame(step);
    };
    requestAnimationFrame(step);
  };

  Viewer.prototype.bind = function () {
    const c = this.canvas;
    let drag = null;
    c.addEventListener("pointerdown", e => {
      drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
      c.setPointerCapture(e.pointerId);
      c.classList.add("qc-dragging");
    });
    c.addEventListener("pointermove", e => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.x = e.clientX;
      drag.y = e.clientY;
      if (drag.pan) { this.view.px += dx; this.view.py += dy; } else {
        this.view.az -= dx * 0.008;
        this.view.el = Math.max(-89.9 * DEG, Math.min(89.9 * DEG, this.view.el + dy * 0.008));
      }
      this.draw();
    });
    const end = () => { drag = null; c.classList.remove("qc-dragging"); };
    c.addEventListener("pointerup", end);
    c.addEventListener("pointercancel", end);
    c.addEventListener("contextmenu", e => e.preventDefault());
    c.addEventListener("dblclick", () => { Object.assign(this.view, HOME); this.draw(); });
    c.addEventListener("wheel", e => {
      e.preventDefault();
      this.view.zoom = Math.max(0.2, Math.min(40, this.view.zoom * Math.exp(-e.deltaY * 0.0015)));
      this.draw();
    }, { passive: false });
    window.addEventListener("resize", () => this.resize());
  };

  Viewer.prototype.resize = function () {
    const dpr = window.devicePixelRatio || 1;
    this.W = this.canvas.clientWidth || 800;
    this.H = this.canvas.clientHeight || 520;
    this.canvas.width = Math.round(this.W * dpr);
    this.canvas.height = Math.round(this.H * dpr);
    this.ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    this.fitView();
    this.draw();
  };

  /* screen position [X, Y] and depth towards the viewer of a point in metres; at zoom 1 the
   * box (with room for the axis labels) fills the canvas in the home view */
  Viewer.prototype.projector = function (fit) {
    const v = fit ? HOME : this.view, ca = Math.cos(v.az), sa = Math.sin(v.az), ce = Math.cos(v.el), se = Math.sin(v.el);
    const c = this.center, D = 4 * this.radius;
    const f = fit || this.fit, W2 = this.W / 2, H2 = this.H / 2;
    return (x, y, z) => {
      const dx = x - c[0], dy = y - c[1], dz = z - c[2];
      const sx = -sa * dx + ca * dy, sy = -se * ca * dx - se * sa * dy + ce * dz;
      const d = ce * ca * dx + ce * sa * dy + se * dz;
      const k = D / (D - d);
      return [W2 + v.px + v.zoom * (f.ox + f.s * sx * k - W2), H2 + v.py + v.zoom * (f.oy - f.s * sy * k - H2), d];
    };
  };

  Viewer.prototype.fitView = function () {
    const b = this.box, pad = 0.07 * Math.max(b.hi[0] - b.lo[0], b.hi[1] - b.lo[1]), c = this.center;
    const P = this.projector({ s: 1, ox: 0, oy: 0 }), pts = [];
    for (const x of [b.lo[0], b.hi[0]]) for (const y of [b.lo[1], b.hi[1]]) {
      pts.push([x, y, b.hi[2]], [x + (x < c[0] ? -1.5 : 1.5) * pad, y + (y < c[1] ? -1.5 : 1.5) * pad, b.lo[2]]);
    }
    for (const [x, y] of [[b.lo[0] - 3.6 * pad, c[1]], [b.hi[0] + 3.6 * pad, c[1]],
                          [c[0], b.lo[1] - 3.6 * pad], [c[0], b.hi[1] + 3.6 * pad]]) pts.push([x, y, b.lo[2]]);
    let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
    for (const p of pts) {
      const q = P(p[0], p[1], p[2]);
      x0 = Math.min(x0, q[0]); x1 = Math.max(x1, q[0]);
      y0 = Math.min(y0, q[1]); y1 = Math.max(y1, q[1]);
    }
    const s = Math.min((this.W - 70) / (x1 - x0), (this.H - 90) / (y1 - y0));
    this.fit = { s: s, ox: this.W / 2 - s * (x0 + x1) / 2, oy: this.H / 2 + 10 - s * (y0 + y1) / 2 };
  };

  Viewer.prototype.line = function (P, s, i0, i1, zFix) {
    const ctx = this.ctx;
    let pen = false;
    ctx.beginPath();
    for (let i = i0; i <= i1; i++) {
      if (!finite(s.x[i])) { pen = false; continue; }
      const q = P(s.x[i], s.y[i], zFix === undefined ? s.z[i] : zFix);
      if (pen) ctx.lineTo(q[0], q[1]); else ctx.moveTo(q[0], q[1]);
      pen = true;
    }
    ctx.stroke();
  };

  Viewer.prototype.axes = function (P) {
    const ctx = this.ctx, b = this.box, z0 = b.lo[2];
    const step = niceStep(Math.max(b.hi[0] - b.lo[0], b.hi[1] - b.lo[1]), 6);
    const xs = ticks(b.lo[0], b.hi[0], step), ys = ticks(b.lo[1], b.hi[1], step);
    ctx.lineWidth = 1;
    ctx.strokeStyle = "#e4e7ec";
    for (const x of xs) { ctx.beginPath(); const a = P(x, b.lo[1], z0), c = P(x, b.hi[1], z0); ctx.moveTo(a[0], a[1]); ctx.lineTo(c[0], c[1]); ctx.stroke(); }
    for (const y of ys) { ctx.beginPath(); const a = P(b.lo[0], y, z0), c = P(b.hi[0], y, z0); ctx.moveTo(a[0], a[1]); ctx.lineTo(c[0], c[1]); ctx.stroke(); }
    const corners = [[b.lo[0], b.lo[1]], [b.hi[0], b.lo[1]], [b.hi[0], b.hi[1]], [b.lo[0], b.hi[1]]];
    ctx.strokeStyle = "#aab2bd";
    ctx.beginPath();
    corners.forEach((q, i) => { const p = P(q[0], q[1], z0); if (i) ctx.lineTo(p[0], p[1]); else ctx.moveTo(p[0], p[1]); });
    ctx.closePath();
    ctx.stroke();
    const pad = 0.07 * Math.max(b.hi[0] - b.lo[0], b.hi[1] - b.lo[1]);
    ctx.fillStyle = "#4a5361";
    ctx.font = "12px system-ui, sans-serif";
    ctx.textAlign = "center";
    ctx.textBaseline = "middle";
    // x ticks along the y edge nearer the viewer, y ticks along the nearer x edge
    const yEdge = P(this.center[0], b.lo[1], z0)[2] > P(this.center[0], b.hi[1], z0)[2] ? -1 : 1;
    const xEdge = P(b.lo[0], this.center[1], z0)[2] > P(b.hi[0], this.center[1], z0)[2] ? -1 : 1;
    const yAt = yEdge < 0 ? b.lo[1] - pad : b.hi[1] + pad, xAt = xEdge < 0 ? b.lo[0] - pad : b.hi[0] + pad;
    for (const x of xs) { const p = P(x, yAt, z0); ctx.fillText(tickText(x, step), p[0], p[1]); }
    for (const y of ys) { const p = P(xAt, y, z0); ctx.fillText(tickText(y, step), p[0], p[1]); }
    ctx.font = "bold 13px system-ui, sans-serif";
    let p = P(this.center[0], yAt + yEdge * 2.6 * pad, z0);
    ctx.fillText("x [m]", p[0], p[1]);
    p = P(xAt + xEdge * 2.6 * pad, this.center[1], z0);
    ctx.fillText("y [m]", p[0], p[1]);
    // z axis just outside the floor corner farthest from the viewer, ticks ~30 px apart
    let back = corners[0], far = Infinity;
    for (const q of corners) { const d = P(q[0], q[1], z0)[2]; if (d < far) { far = d; back = q; } }
    back = [back[0] + (back[0] < this.center[0] ? -1.5 : 1.5) * pad, back[1] + (back[1] < this.center[1] ? -1.5 : 1.5) * pad];
    const a = P(back[0], back[1], z0), c = P(back[0], back[1], b.hi[2]);
    const zStep = niceStep(b.hi[2] - z0, Math.max(1, Math.min(6, Math.floor(Math.hypot(c[0] - a[0], c[1] - a[1]) / 30))));
    ctx.strokeStyle = "#8a94a3";
    ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(c[0], c[1]); ctx.stroke();
    const left = a[0] <= P(this.center[0], this.center[1], z0)[0];
    ctx.font = "12px system-ui, sans-serif";
    ctx.textAlign = left ? "right" : "left";
    for (const z of ticks(z0, b.hi[2], zStep)) {
      const q = P(back[0], back[1], z);
      ctx.beginPath(); ctx.moveTo(q[0] - 3, q[1]); ctx.lineTo(q[0] + 3, q[1]); ctx.stroke();
      ctx.fillText(tickText(z, zStep), q[0] + (left ? -7 : 7), q[1]);
    }
    ctx.font = "bold 13px system-ui, sans-serif";
    ctx.textAlign = "center";
    ctx.fillText("z [m]", c[0], c[1] - 14);
  };

  Viewer.prototype.draw = function () {
    const ctx = this.ctx, P = this.projector(), z0 = this.box.lo[2];
    ctx.clearRect(0, 0, this.W, this.H);
    ctx.fillStyle = "#ffffff";
    ctx.fillRect(0, 0, this.W, this.H);
    ctx.lineJoin = "round";
    ctx.lineCap = "round";
    this.axes(P);
    const shown = this.flights.filter((f, i) => this.visible[i]);
    ctx.globalAlpha = 0.16;
    ctx.lineWidth = 2;
    for (const f of shown) { ctx.strokeStyle = f.color; this.line(P, f, 0, f.t.length - 1, z0); }
    ctx.globalAlpha = 1;
    for (const f of shown) {
      const k = bisect(f.t, this.t);
      ctx.strokeStyle = f.color;
      ctx.lineWidth = 2.2;
      this.line(P, f, 0, Math.min(k + 1, f.t.length - 1));
      if (k + 1 < f.t.length - 1) { ctx.globalAlpha = 0.3; this.line(P, f, k + 1, f.t.length - 1); ctx.globalAlpha = 1; }
      const i0 = f.x.findIndex(finite);
      if (i0 >= 0) {
        const q = P(f.x[i0], f.y[i0], f.z[i0]);
        ctx.strokeStyle = "#2ca02c"; ctx.lineWidth = 2;
        ctx.beginPath(); ctx.arc(q[0], q[1], 6, 0, 2 * Math.PI); ctx.stroke();
      }
      if (!f.ok) {
        const j = lastFinite(f);
        if (j >= 0) {
          const q = P(f.x[j], f.y[j], f.z[j]);
          ctx.strokeStyle = "#d62728"; ctx.lineWidth = 3;
          ctx.beginPath(); ctx.moveTo(q[0] - 6, q[1] - 6); ctx.lineTo(q[0] + 6, q[1] + 6);
          ctx.moveTo(q[0] + 6, q[1] - 6); ctx.lineTo(q[0] - 6, q[1] + 6); ctx.stroke();
        }
      }
    }
    if (this.showRef) {
      ctx.setLineDash([7, 5]);
      ctx.lineWidth = 1.4;
      ctx.strokeStyle = "#222";
      for (const r of this.refs) this.line(P, r, 0, r.t.length - 1);
      ctx.setLineDash([]);
    }
    this.markers(P, z0);
    ctx.fillStyle = "#1d2430";
    ctx.font = "bold 14px system-ui, sans-serif";
    ctx.textAlign = "left";
    ctx.textBaseline = "top";
    ctx.fillText("t = " + this.t.toFixed(2) + " s", 12, 10);
    this.tlabel.textContent = "t = " + this.t.toFixed(2) + " s of " + this.t1.toFixed(2) + " s";
    this.canvas.setAttribute("data-rendered", "1");
  };

  Viewer.prototype.markers = function (P, z0) {
    const ctx = this.ctx;
    this.flights.forEach((f, i) => {
      const p = sampleAt(f, this.t);
      const r = f.ref !== null && f.ref !== undefined ? sampleAt(this.refs[f.ref], this.t) : null;
      let text = p ? "x " + num(p[0], 2) + "  y " + num(p[1], 2) + "  z " + num(p[2], 2) + " m" : "stopped";
      if (p && r) text += "  ·  error " + num(Math.hypot(p[0] - r[0], p[1] - r[1], p[2] - r[2]), 3) + " m";
      this.readouts[i].textContent = text;
      if (!this.visible[i]) return;
      if (r && this.showRef) {
        const q = P(r[0], r[1], r[2]);
        ctx.strokeStyle = "#222"; ctx.lineWidth = 1.5;
        ctx.beginPath(); ctx.arc(q[0], q[1], 5, 0, 2 * Math.PI); ctx.stroke();
      }
      if (!p) return;
      const q = P(p[0], p[1], p[2]), g = P(p[0], p[1], z0);
      ctx.strokeStyle = f.color; ctx.lineWidth = 1; ctx.setLineDash([2, 3]);
      ctx.beginPath(); ctx.moveTo(q[0], q[1]); ctx.lineTo(g[0], g[1]); ctx.stroke();
      ctx.setLineDash([]);
      ctx.fillStyle = f.color; ctx.strokeStyle = "#fff"; ctx.lineWidth = 2;
      ctx.beginPath(); ctx.arc(q[0], q[1], 6.5, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
    });
  };

  for (const root of document.querySelectorAll(".qc-view")) {
    try {
      new Viewer(root);
    } catch (err) {
      console.error("3-D view " + (root.id || "") + " failed: " + (err && err.stack || err));
    }
  }
})();
