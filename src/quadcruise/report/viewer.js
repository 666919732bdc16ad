/* quadcruise report: interactive 3-D view of logged flights, plain JavaScript on a canvas.
 *
 * Each div.qc-view holds a canvas and a JSON script element of class qc-data:
 * {flights: [{label, color, t, x, y, z, ref, ok, status}], refs: [{t, x, y, z}]}; null
 * marks an instant after a vehicle stopped. Drag to orbit, shift-drag (or right-drag) to
 * pan, wheel to zoom, double-click to reset. After each drawing the canvas gets
 * data-rendered="1" and, in data-labels, the axis labels drawn with their boxes in CSS
 * pixels (read by the tests through the DOM): no two labels overlap, and an axis seen
 * end-on (the depth axis of a side view) has none.
 */
(function () {
  "use strict";

  const DEG = Math.PI / 180;
  const TICK_PX = 12.5, NAME_PX = 13.5, LABEL_GAP = 8;
  const TICK_FONT = TICK_PX + "px system-ui, sans-serif", NAME_FONT = "bold " + NAME_PX + "px system-ui, sans-serif";
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
    this.placed = [[6, 4, 150, 30]];          // the time readout drawn in the top left corner
    this.labels = [];
    // z axis just outside the floor corner farthest from the viewer, ticks ~30 px apart;
    // none when it is seen end-on (from above)
    let back = corners[0], far = Infinity;
    for (const q of corners) { const d = P(q[0], q[1], z0)[2]; if (d < far) { far = d; back = q; } }
    back = [back[0] + (back[0] < this.center[0] ? -1.5 : 1.5) * pad, back[1] + (back[1] < this.center[1] ? -1.5 : 1.5) * pad];
    const a = P(back[0], back[1], z0), c = P(back[0], back[1], b.hi[2]);
    const zLength = Math.hypot(c[0] - a[0], c[1] - a[1]);
    ctx.strokeStyle = "#8a94a3";
    ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(c[0], c[1]); ctx.stroke();
    if (zLength >= 30) {
      const zStep = niceStep(b.hi[2] - z0, Math.max(1, Math.min(6, Math.floor(zLength / 30))));
      const left = a[0] <= P(this.center[0], this.center[1], z0)[0];
      for (const z of ticks(z0, b.hi[2], zStep)) {
        const q = P(back[0], back[1], z);
        ctx.beginPath(); ctx.moveTo(q[0] - 3, q[1]); ctx.lineTo(q[0] + 3, q[1]); ctx.stroke();
        this.place(tickText(z, zStep), q[0] + (left ? -7 : 7), q[1], left ? "right" : "left", TICK_FONT, "z");
      }
      this.place("z [m]", c[0], c[1] - 14, "center", NAME_FONT, "z name");
    }
    // x ticks along the y edge nearer the viewer, y ticks along the nearer x edge
    const yEdge = P(this.center[0], b.lo[1], z0)[2] > P(this.center[0], b.hi[1], z0)[2] ? -1 : 1;
    const xEdge = P(b.lo[0], this.center[1], z0)[2] > P(b.hi[0], this.center[1], z0)[2] ? -1 : 1;
    const yAt = yEdge < 0 ? b.lo[1] - pad : b.hi[1] + pad, xAt = xEdge < 0 ? b.lo[0] - pad : b.hi[0] + pad;
    const centre = P(this.center[0], this.center[1], z0);
    this.tickRow(xs.map(x => [x, P(x, yAt, z0)]), step, centre, "x");
    this.tickRow(ys.map(y => [y, P(xAt, y, z0)]), step, centre, "y");
    this.canvas.setAttribute("data-labels", JSON.stringify(this.labels));
  };

  /* Tick labels of one floor axis, thinned (every k-th tick, 0 kept) so that no two meet on
   * the screen, then its name beyond them, away from the floor's centre (below when the
   * floor is seen edge-on). An axis seen end-on, where fewer than two labels would fit, gets
   * neither: in a side view the depth axis has no readable ticks. */
  Viewer.prototype.tickRow = function (row, step, centre, axis) {
    const ctx = this.ctx;
    if (row.length < 2) return;
    ctx.font = TICK_FONT;
    const texts = row.map(([v]) => tickText(v, step));
    const w = Math.max(...texts.map(t => ctx.measureText(t).width)) + LABEL_GAP, h = TICK_PX + LABEL_GAP;
    let k = 1;
    for (let i = 1; i < row.length; i++) {
      const dx = Math.abs(row[i][1][0] - row[i - 1][1][0]), dy = Math.abs(row[i][1][1] - row[i - 1][1][1]);
      k = Math.max(k, Math.min(Math.ceil(w / Math.max(dx, 1e-9)), Math.ceil(h / Math.max(dy, 1e-9))));
    }
    const kept = row.filter(([v]) => Math.round(v / step) % k === 0);
    if (kept.length < 2) return;
    for (const [v, p] of kept) this.place(tickText(v, step), p[0], p[1], "center", TICK_FONT, axis);
    const first = row[0][1], last = row[row.length - 1][1];
    const mid = [(first[0] + last[0]) / 2, (first[1] + last[1]) / 2];
    const len = Math.hypot(last[0] - first[0], last[1] - first[1]);
    let n = [-(last[1] - first[1]) / len, (last[0] - first[0]) / len];   // normal to the row on screen
    const side = (mid[0] - centre[0]) * n[0] + (mid[1] - centre[1]) * n[1];
    if (Math.abs(side) < 2) { if (n[1] < 0) n = [-n[0], -n[1]]; } else if (side < 0) n = [-n[0], -n[1]];
    const name = axis + " [m]";
    ctx.font = NAME_FONT;
    const W = ctx.measureText(name).width, H = NAME_PX;
    let d = Math.abs(n[0]) * (w + W) / 2 + Math.abs(n[1]) * (h + H) / 2 + 4;
    for (let tries = 0; tries < 5; tries++, d += 8) {
      if (this.place(name, mid[0] + n[0] * d, mid[1] + n[1] * d, "center", NAME_FONT, axis + " name")) break;
    }
  };

  /* Draw text at (x, y) unless its box leaves the canvas or meets a label already drawn;
   * keep the box (and report it in data-labels, for the tests). */
  Viewer.prototype.place = function (text, x, y, align, font, kind) {
    const ctx = this.ctx;
    ctx.font = font;
    const w = ctx.measureText(text).width, h = font === NAME_FONT ? NAME_PX : TICK_PX;
    const x0 = align === "left" ? x : align === "right" ? x - w : x - w / 2;
    const box = [x0 - 1, y - h / 2 - 1, x0 + w + 1, y + h / 2 + 1];
    if (box[0] < 0 || box[1] < 0 || box[2] > this.W || box[3] > this.H) return false;
    for (const o of this.placed) if (box[0] < o[2] && o[0] < box[2] && box[1] < o[3] && o[1] < box[3]) return false;
    ctx.textAlign = align;
    ctx.textBaseline = "middle";
    ctx.fillText(text, x, y);
    this.placed.push(box);
    this.labels.push({ text: text, kind: kind, px: h, box: box.map(v => Math.round(v * 10) / 10) });
    return true;
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
