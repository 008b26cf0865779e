// `fiveaxis view`: the viewer's entry point. Reads the data the page
// holds, builds the 3-D scene, the program text, the plots and the
// controls, links them by time and by line, and exposes `window.__viewer`
// (statistics and probes for tests and for people at the console).

import { findingAt, findingsTitle, readPage, readProgramLines, stockCorners, textLeftOutLine } from './data.js';
import { forward, toPart, toPartVector } from './kinematics.js';
import { AxisPlots } from './plots.js';
import { MachineScene } from './scene.js';
import { blockAt, blockStart, blocksByLine, frameOfBlock, jointsAt, lowerBound } from './timeline.js';
import { FindingsList, ProgramText, clock, layout } from './ui.js';

const SLIDER_STEPS = 1000000;

/** Milliseconds since navigation at each step of the opening (`window.__viewer.timings`). */
const timings = { scriptStart: performance.now() };
const mark = (name) => (timings[name] = performance.now());

async function start() {
  const data = await readPage(document, mark);
  mark('readPage');
  const ui = layout(document, data.meta);
  const scene = new MachineScene(ui.view3d, data);
  mark('scene');
  // Blocks by line, up to the last line that has one (the text comes later).
  const lineIndex = blocksByLine(data.lines, data.lines.reduce((m, l) => Math.max(m, l), 0));
  const joints = new Array(data.axes).fill(0);
  const state = { t: 0, playing: false, speed: 1, selectedLine: 0, block: -1 };
  const frameOf = (b) => data.meta.frames[frameOfBlock(data, Math.max(0, b))] || { tool_length: 0, tool_radius: 5, to_part: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0] };

  // Findings: markers where they happened (a contact point, a gouge)
  // or else at the end of their line's path, entries in a list, marks in
  // the text.
  const findings = data.findings;
  const vertexOfLine = (line) => {
    const { first, order } = lineIndex;
    if (line >= 0 && line < first.length - 1 && first[line + 1] > first[line]) {
      return lowerBound(data.times, data.ends[order[first[line]]]);
    }
    return data.times.length - 1; // not run (an alarm stops before its block): where the machine stopped
  };
  {
    const at = new Float32Array(3 * findings.count);
    const severities = new Uint8Array(findings.count);
    const severityCodes = { error: 0, warning: 1, info: 2 };
    let lastLine = -1;
    let i = 0;
    for (let k = 0; k < findings.count; k++) {
      const line = findings.lines[k];
      if (line !== lastLine) {
        i = Math.max(0, Math.min(vertexOfLine(line), data.times.length - 1));
        lastLine = line;
      }
      const placed = findings.points.length >= 3 * (k + 1) && Number.isFinite(findings.points[3 * k]);
      const from = placed ? findings.points : data.tips;
      const j = placed ? k : i;
      for (let c = 0; c < 3; c++) at[3 * k + c] = from[3 * j + c];
      const type = findings.table[findings.kinds[k]];
      severities[k] = severityCodes[type && type.severity] ?? 1;
    }
    // No path (an alarm before the first move): no place to mark.
    if (data.times.length) scene.setMarkers(at, severities);
  }
  mark('findings');
  ui.findingsTitle.textContent = findingsTitle(data.meta, findings.count);
  new FindingsList(ui.findings, findings, (k) => selectLine(findings.lines[k]));

  const text = new ProgramText(ui.text, ui.textInner, [], (line) => selectLine(line));
  const plots = new AxisPlots(ui.plots, data, (t) => seek(t));

  /** Moves everything to time `t`. */
  function seek(t, { scrollText = true, block = -1 } = {}) {
    state.t = Math.min(Math.max(0, t), data.duration);
    jointsAt(data, state.t, joints);
    // Blocks that take no time share their end with the one before: the
    // caller may say which one it means.
    const b = block >= 0 && data.ends[block] === state.t ? block : blockAt(data, state.t);
    state.block = b;
    scene.pose(joints, frameOf(b));
    scene.stockAt(state.t);
    ui.slider.value = String(data.duration > 0 ? Math.round((state.t / data.duration) * SLIDER_STEPS) : 0);
    ui.time.textContent = `${clock(state.t)} / ${clock(data.duration)}`;
    const line = b >= 0 ? data.lines[b] : 0;
    text.setCurrent(line, scrollText);
    plots.setCursor(state.t);
    const names = data.machine.axisNames;
    ui.status.textContent = `block ${b + 1} / ${data.ends.length}  line ${line}\n` + names.map((n, i) => `${n} ${joints[i].toFixed(3).padStart(10)}`).join('\n');
  }

  /** Selects a program line: its blocks drawn in the selection colour, time at its first block. */
  function selectLine(line) {
    state.selectedLine = line;
    text.setSelected(line);
    const { first, order } = lineIndex;
    const ranges = [];
    if (line >= 0 && line < first.length - 1) {
      for (let k = first[line]; k < first[line + 1]; k++) {
        const b = order[k];
        const from = Math.max(0, lowerBound(data.times, blockStart(data, b)));
        const to = Math.min(data.times.length - 1, lowerBound(data.times, data.ends[b]));
        ranges.push([from, to]);
      }
    }
    scene.select(ranges);
    if (ranges.length) seek(data.ends[order[first[line]]], { scrollText: false, block: order[first[line]] });
    window.__viewer.selectedLine = line;
  }

  // Playback.
  let last = 0;
  function tick(now) {
    if (!state.playing) return;
    const dt = last ? (now - last) / 1000 : 0;
    last = now;
    seek(state.t + dt * state.speed);
    if (state.t >= data.duration) {
      setPlaying(false);
      return;
    }
    requestAnimationFrame(tick);
  }
  function setPlaying(on) {
    state.playing = on && data.duration > 0;
    ui.toggle.textContent = state.playing ? '❚❚' : '▶';
    if (state.playing) {
      if (state.t >= data.duration) seek(0);
      last = 0;
      requestAnimationFrame(tick);
    }
  }
  const stepBlock = (d) => {
    const b = blockAt(data, state.t);
    const atEnd = b >= 0 && Math.abs(data.ends[b] - state.t) < 1e-9;
    const next = d > 0 ? (atEnd ? b + 1 : b) : atEnd ? b - 1 : b - 1;
    if (next < 0) seek(0);
    else if (next < data.ends.length) seek(data.ends[next], { block: next });
  };
  ui.toggle.addEventListener('click', () => setPlaying(!state.playing));
  ui.start.addEventListener('click', () => seek(0));
  ui.prev.addEventListener('click', () => stepBlock(-1));
  ui.next.addEventListener('click', () => stepBlock(1));
  ui.speed.addEventListener('change', () => (state.speed = Number(ui.speed.value)));
  ui.slider.addEventListener('input', () => seek((Number(ui.slider.value) / SLIDER_STEPS) * data.duration));
  ui.plotMode.addEventListener('change', () => plots.setMode(ui.plotMode.value));
  ui.tools.addEventListener('click', (e) => {
    const v = e.target.dataset && e.target.dataset.view;
    if (v) scene.view(v);
  });
  ui.fit.addEventListener('click', () => scene.fit());
  // The stock layer: on at first; the button only where there is a stock.
  const setStock = (on) => {
    if (!scene.setStockVisible(on)) return false;
    ui.stock.setAttribute('aria-pressed', String(on));
    return true;
  };
  ui.stock.hidden = !setStock(true);
  ui.stock.addEventListener('click', () => setStock(ui.stock.getAttribute('aria-pressed') !== 'true'));
  document.addEventListener('keydown', (e) => {
    if (e.target.tagName === 'INPUT' || e.target.tagName === 'SELECT') return;
    if (e.key === ' ') {
      setPlaying(!state.playing);
      e.preventDefault();
    } else if (e.key === 'ArrowRight') stepBlock(1);
    else if (e.key === 'ArrowLeft') stepBlock(-1);
  });
  // A click (not a drag) on the path selects its line.
  let down = null;
  scene.renderer.domElement.addEventListener('pointerdown', (e) => (down = [e.clientX, e.clientY]));
  scene.renderer.domElement.addEventListener('pointerup', (e) => {
    if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
    const i = scene.pick(e.clientX, e.clientY);
    if (i >= 0) {
      // The block the picked vertex ends (vertex 0: the first block).
      const b = data.vertexBlock[i];
      if (b < data.lines.length) selectLine(data.lines[b]);
    }
  });

  // Statistics and probes (tests, and people at the console).
  window.__viewer = {
    ready: false,
    stats: {
      segments: data.ends.length,
      vertices: data.times.length,
      rows: data.meta.rows,
      bbox: data.bbox,
      findings: findings.count,
      duration: data.duration,
      machineType: data.machine.type,
      programLines: data.programLines.length,
      softwareRenderer: scene.software,
    },
    selectedLine: 0,
    /** Findings `from` to `to` (all by default) as the check contract has them. */
    findings: (from = 0, to = findings.count) => {
      const out = [];
      for (let k = Math.max(0, from); k < Math.min(to, findings.count); k++) out.push(findingAt(findings, k));
      return out;
    },
    seek: (t) => seek(t),
    /** Where each finding's marker is, in the table frame. */
    markers: () => {
      const a = scene.markerPoints ? scene.markerPoints.geometry.getAttribute('position').array : [];
      const out = [];
      for (let k = 0; k + 2 < a.length; k += 3) out.push([a[k], a[k + 1], a[k + 2]]);
      return out;
    },
    /** The work drawn, by name, with its box as the bodies stand. */
    work: () => scene.workSummary(),
    seekBlock: (b) => seek(data.ends[b], { block: b }),
    selectLine: (line) => selectLine(line),
    /** The machine position, the tool tip by the bodies and by forward kinematics. */
    probe() {
      const b = state.block;
      const frame = frameOf(b);
      const fk = forward(data.machine, joints, frame.tool_length);
      const bodies = scene.probe();
      return {
        t: state.t,
        block: b,
        line: b >= 0 ? data.lines[b] : 0,
        joints: joints.slice(),
        bodies,
        bodiesTipPart: toPart(frame.to_part, bodies.table),
        fkTipPart: toPart(frame.to_part, fk.tip),
        fkDirPart: toPartVector(frame.to_part, fk.dir),
      };
    },
    screenOfVertex: (i) => scene.screenOf(i),
    blockEnds: () => Array.from(data.ends),
    vertexOfBlockEnd: (b) => lowerBound(data.times, data.ends[b]),
    /** The lines of the blocks whose path segments are drawn within `px` pixels of a point. */
    linesNear(x, y, px) {
      const lines = new Set();
      let a = scene.screenOf(0);
      for (let i = 1; i < data.times.length; i++) {
        const b = scene.screenOf(i);
        const dx = b.x - a.x;
        const dy = b.y - a.y;
        const len2 = dx * dx + dy * dy;
        const f = len2 > 0 ? Math.min(1, Math.max(0, ((x - a.x) * dx + (y - a.y) * dy) / len2)) : 0;
        if (Math.hypot(a.x + f * dx - x, a.y + f * dy - y) <= px) lines.add(data.lines[data.vertexBlock[i]]);
        a = b;
      }
      return [...lines];
    },
    view: (name) => scene.view(name),
    renderedFrames: () => scene.frames || 0,
    renderNow: () => scene.renderNow(),
    /** Draws the whole path (`true`) or the coarse one (drawn while the camera moves). */
    setDetail: (whole) => scene.setDetail(whole),
    timeFrame: (whole) => scene.timeFrame(whole),
    coarse: () => (scene.coarse ? scene.coarse.geometry.index.count : 0),
    /** Path vertices in the last frame drawn, and in the whole path. */
    drawn: () => ({ drawn: scene.drawnVertices, total: scene.path.geometry.getAttribute('position').count }),
    zoomBy: (f) => scene.zoomBy(f),
    /** The stock model's grid and its cells' tops as drawn now (null without one). */
    stockTops() {
      const t = scene.stockTimeline;
      if (!t) return null;
      const { nx, ny, cell, origin } = data.work.stockModel;
      return { nx, ny, cell, origin, snapshots: t.times.length, shown: t.shown, tops: Array.from(t.tops) };
    },
    /** Shows or hides the stock layer; whether there is a stock. */
    setStock: (on) => setStock(on),
    /** The stock as drawn: whether declared (BLK FORM), visible, and its table-frame corners (declared) or box. */
    stock() {
      const s = scene.stock;
      if (!s) return null;
      const declared = !!s.userData.declared;
      scene.scene.updateMatrixWorld(true);
      return { declared, visible: s.visible, corners: declared ? stockCorners(data.meta) : null, world: Array.from(s.matrixWorld.elements), carrier: s.parent.name };
    },
  };
  seek(0);
  mark('seek');
  scene.renderNow();
  mark('render');
  plots.draw();
  mark('plots');
  // The path and the machine are drawn and move: the text follows (the
  // page holds it last, so a long one is still being read).
  window.__viewer.interactiveMs = performance.now();
  // A big path opened coarse: the whole one follows when the page rests.
  scene.rest();
  data.programLines = await readProgramLines(document);
  mark('programLines');
  const leftOut = textLeftOutLine(data.meta);
  text.setLines(leftOut ? [...data.programLines, leftOut] : data.programLines);
  for (let k = 0; k < findings.count; k++) text.mark(findings.lines[k]);
  text.setCurrent(state.block >= 0 ? data.lines[state.block] : 0);
  window.__viewer.stats.programLines = data.programLines.length;
  mark('text');
  window.__viewer.timings = timings;
  window.__viewer.openMs = performance.now();
  window.__viewer.ready = true;
  document.documentElement.dataset.ready = 'true';
}

start().catch((error) => {
  document.body.insertAdjacentHTML('afterbegin', `<pre style="color:#f85149;white-space:pre-wrap">fiveaxis view: ${String(error && error.stack ? error.stack : error).replace(/</g, '&lt;')}</pre>`);
  window.__viewer = { ready: false, error: String(error) };
  throw error;
});
