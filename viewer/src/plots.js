// Plots of every machine axis against time (or block number), on 2-D
// canvases, with the soft limits drawn: an over-travel or a rotary flip
// shows at a glance. Each column of pixels draws the smallest and largest
// value of the vertices it covers, so two million vertices cost one pass.

import { upperBound } from './timeline.js';

const PLOT_HEIGHT = 58;
const LIMIT_COLOUR = '#f85149';
const LINE_COLOUR = '#58a6ff';
const CURSOR_COLOUR = '#ffd33d';

/** A rollover axis is plotted as the control shows it, modulo 360. */
function shown(value, rollover) {
  if (!rollover) return value;
  const r = ((value % 360) + 360) % 360;
  return r >= 360 ? 0 : r;
}

export class AxisPlots {
  constructor(parent, data, onSeek) {
    this.data = data;
    this.parent = parent;
    this.onSeek = onSeek;
    this.mode = 'time';
    this.cursor = 0;
    const m = data.machine;
    this.axes = m.axisNames.map((name, i) => {
      const lin = m.linear[i];
      const rot = i >= m.linear.length ? m.rotary[i - m.linear.length] : null;
      const min = lin ? lin.min : rot.min;
      const max = lin ? lin.max : rot.max;
      const rollover = !!(rot && rot.rollover);
      const row = document.createElement('div');
      row.className = 'plot';
      const label = document.createElement('span');
      label.textContent = name;
      const canvas = document.createElement('canvas');
      canvas.height = PLOT_HEIGHT;
      canvas.dataset.axis = name;
      row.append(label, canvas);
      parent.appendChild(row);
      canvas.addEventListener('click', (e) => {
        const r = canvas.getBoundingClientRect();
        this.onSeek(this.timeAtX((e.clientX - r.left) / r.width));
      });
      return { name, index: i, min, max, rollover, canvas, columns: null, width: 0 };
    });
    new ResizeObserver(() => this.draw()).observe(parent);
  }

  /** The x of time `t`, 0..1. */
  xOf(t) {
    const d = this.data;
    if (this.mode === 'block') {
      const n = d.ends.length;
      return n ? upperBound(d.ends, t - 1e-12) / n : 0;
    }
    return d.duration > 0 ? t / d.duration : 0;
  }

  /** The time at x (0..1). */
  timeAtX(x) {
    const d = this.data;
    x = Math.min(1, Math.max(0, x));
    if (this.mode === 'block') {
      const b = Math.min(d.ends.length - 1, Math.floor(x * d.ends.length));
      return b >= 0 ? d.ends[b] : 0;
    }
    return x * d.duration;
  }

  setMode(mode) {
    this.mode = mode;
    for (const a of this.axes) a.columns = null;
    this.draw();
  }

  setCursor(t) {
    this.cursor = t;
    this.draw();
  }

  /** Smallest and largest value of each pixel column, and the range. */
  columns(axis, width) {
    const d = this.data;
    const n = d.times.length;
    const lo = new Float32Array(width).fill(Infinity);
    const hi = new Float32Array(width).fill(-Infinity);
    let vmin = Infinity;
    let vmax = -Infinity;
    for (let i = 0; i < n; i++) {
      const x = this.mode === 'block' ? (d.vertexBlock[i] + (i === 0 ? 0 : 1)) / Math.max(1, d.ends.length) : d.duration > 0 ? d.times[i] / d.duration : 0;
      const c = Math.min(width - 1, Math.max(0, Math.floor(x * width)));
      const v = shown(d.joints[i * d.axes + axis.index], axis.rollover);
      if (v < lo[c]) lo[c] = v;
      if (v > hi[c]) hi[c] = v;
      if (v < vmin) vmin = v;
      if (v > vmax) vmax = v;
    }
    return { lo, hi, vmin, vmax };
  }

  draw() {
    for (const a of this.axes) {
      const width = Math.max(50, a.canvas.clientWidth | 0);
      if (a.canvas.width !== width) a.canvas.width = width;
      if (!a.columns || a.width !== width) {
        a.columns = this.columns(a, width);
        a.width = width;
      }
      this.drawAxis(a);
    }
  }

  drawAxis(a) {
    const ctx = a.canvas.getContext('2d');
    const w = a.canvas.width;
    const h = a.canvas.height;
    const { lo, hi, vmin, vmax } = a.columns;
    const limits = [a.min, a.max].filter((v) => v !== null && v !== undefined);
    // The motion fills the plot; a soft limit is drawn where it is in
    // sight (or near: within a quarter of the motion's range), and an
    // over-travel shows as red marks along the top.
    let top = vmax;
    let bottom = vmin;
    if (a.rollover) {
      top = 360;
      bottom = 0;
    }
    if (!Number.isFinite(top) || !Number.isFinite(bottom)) {
      top = 1;
      bottom = -1;
    }
    if (top - bottom < 1e-6) {
      top += 1;
      bottom -= 1;
    }
    const near = 0.25 * (top - bottom);
    for (const v of limits) {
      if (v > top && v - top < near) top = v;
      if (v < bottom && bottom - v < near) bottom = v;
    }
    const pad = 0.08 * (top - bottom);
    top += pad;
    bottom -= pad;
    const y = (v) => h - ((v - bottom) / (top - bottom)) * h;
    ctx.clearRect(0, 0, w, h);
    ctx.fillStyle = '#0d1117';
    ctx.fillRect(0, 0, w, h);
    // Soft limits.
    ctx.strokeStyle = LIMIT_COLOUR;
    ctx.setLineDash([4, 3]);
    for (const v of limits) {
      ctx.beginPath();
      ctx.moveTo(0, y(v) + 0.5);
      ctx.lineTo(w, y(v) + 0.5);
      ctx.stroke();
    }
    ctx.setLineDash([]);
    // The axis, column by column.
    ctx.strokeStyle = LINE_COLOUR;
    ctx.beginPath();
    let prev = null;
    for (let c = 0; c < w; c++) {
      if (lo[c] > hi[c]) continue;
      const y0 = y(hi[c]);
      const y1 = y(lo[c]);
      if (prev === null) ctx.moveTo(c + 0.5, y0);
      else ctx.lineTo(c + 0.5, Math.min(prev, y0));
      ctx.lineTo(c + 0.5, Math.max(y1, y0 + 1));
      prev = y1;
    }
    ctx.stroke();
    // Past a limit: red.
    ctx.fillStyle = LIMIT_COLOUR;
    for (let c = 0; c < w; c++) {
      if ((a.max !== null && a.max !== undefined && hi[c] > a.max) || (a.min !== null && a.min !== undefined && lo[c] < a.min)) {
        ctx.fillRect(c, 0, 1, 4);
      }
    }
    // Range text and cursor.
    ctx.fillStyle = '#8b949e';
    ctx.font = '10px sans-serif';
    const lim = limits.length ? `   limits ${a.min} … ${a.max}` : a.rollover ? '   rollover (mod 360)' : '';
    ctx.fillText(`${vmin.toFixed(3)} … ${vmax.toFixed(3)}${lim}`, 4, 11);
    const cx = Math.round(this.xOf(this.cursor) * (w - 1)) + 0.5;
    ctx.strokeStyle = CURSOR_COLOUR;
    ctx.beginPath();
    ctx.moveTo(cx, 0);
    ctx.lineTo(cx, h);
    ctx.stroke();
  }
}
