// The page around the 3-D view: the layout, the program text (a virtual
// list: only the lines in sight are in the page, so two million lines
// scroll as fast as twenty), the findings list and the playback controls.

import { findingAt, thinnedNotes } from './data.js';

export const STYLE = `
*{box-sizing:border-box}
html,body{margin:0;height:100%;background:#0d1117;color:#c9d1d9;font:13px/1.4 system-ui,sans-serif}
#fa{display:grid;grid-template-columns:minmax(260px,28%) 1fr;grid-template-rows:100%;height:100vh}
#fa-left{display:flex;flex-direction:column;border-right:1px solid #30363d;min-height:0}
#fa-head{padding:6px 8px;border-bottom:1px solid #30363d}
#fa-head b{color:#fff}
#fa-head small{color:#8b949e;display:block}
#fa-head #fa-notes{color:#d29922}
#fa-text{flex:1;overflow:auto;position:relative;font:12px/18px ui-monospace,monospace;min-height:0}
#fa-text .ln{position:absolute;left:0;right:0;height:18px;white-space:pre;padding-left:4px;cursor:pointer}
#fa-text .ln i{display:inline-block;width:6ch;color:#6e7681;font-style:normal;text-align:right;margin-right:1ch}
#fa-text .ln.cur{background:#1f6feb55}
#fa-text .ln.sel{outline:1px solid #ffd33d;outline-offset:-1px}
#fa-text .ln.find{border-left:3px solid #f85149}
#fa-findings{max-height:30%;display:flex;flex-direction:column;border-top:1px solid #30363d;min-height:0}
#fa-findings h3{margin:4px 8px;font-size:12px;color:#8b949e}
#fa-findings-list{overflow:auto;min-height:0;position:relative}
#fa-findings .fd{position:absolute;left:0;right:0;height:18px;padding:0 8px;white-space:nowrap;overflow:hidden;text-overflow:ellipsis;cursor:pointer}
#fa-findings .fd:hover{background:#161b22}
#fa-findings .error{color:#f85149}#fa-findings .warning{color:#d29922}#fa-findings .info{color:#58a6ff}
#fa-right{display:grid;grid-template-rows:1fr auto auto;min-height:0;min-width:0}
#fa-3d{position:relative;min-height:0;overflow:hidden}
#fa-3d canvas{display:block}
#fa-tools{position:absolute;top:6px;left:6px;display:flex;gap:3px;flex-wrap:wrap}
#fa-legend{position:absolute;bottom:6px;left:8px;font-size:12px;color:#8b949e}
#fa-legend span{margin-right:10px}
#fa-status{position:absolute;top:6px;right:8px;text-align:right;font:12px ui-monospace,monospace;color:#c9d1d9;white-space:pre}
button,select{background:#21262d;color:#c9d1d9;border:1px solid #30363d;border-radius:4px;padding:2px 7px;font:12px system-ui,sans-serif;cursor:pointer}
button:hover{background:#30363d}
button[aria-pressed=true]{border-color:#8b949e;color:#fff}
button[hidden]{display:none}
#fa-play{display:flex;align-items:center;gap:6px;padding:6px 8px;border-top:1px solid #30363d}
#fa-play input[type=range]{flex:1}
#fa-time{font:12px ui-monospace,monospace;min-width:15ch;text-align:right}
#fa-timekind{font-size:11px;color:#8b949e;max-width:40ch}
#fa-plots{max-height:38vh;overflow:auto;padding:2px 8px 6px}
.plot{display:flex;align-items:center;gap:6px}
.plot span{width:2ch;color:#8b949e;font:12px ui-monospace,monospace}
.plot canvas{flex:1;height:58px;min-width:0;border-bottom:1px solid #21262d}
`;

/** Builds the page's elements; returns them by name. */
export function layout(doc, meta) {
  const style = doc.createElement('style');
  style.textContent = STYLE;
  doc.head.appendChild(style);
  const root = doc.createElement('div');
  root.id = 'fa';
  root.innerHTML = `
<div id="fa-left">
  <div id="fa-head"><b></b><small></small><small id="fa-notes"></small></div>
  <div id="fa-text"><div id="fa-text-inner"></div></div>
  <div id="fa-findings"><h3></h3><div id="fa-findings-list"></div></div>
</div>
<div id="fa-right">
  <div id="fa-3d">
    <div id="fa-tools">
      <button data-view="iso" title="Isometric view">Iso</button>
      <button data-view="+z" title="View along −Z (from above)">Top</button>
      <button data-view="-y" title="View along +Y (from the front)">Front</button>
      <button data-view="+x" title="View along −X (from the right)">Right</button>
      <button data-view="-x" title="View along +X (from the left)">Left</button>
      <button data-view="+y" title="View along −Y (from the back)">Back</button>
      <button data-view="-z" title="View along +Z (from below)">Bottom</button>
      <button id="fa-fit" title="Fit the view to the path">Fit</button>
      <button id="fa-stock" aria-pressed="true" hidden>Stock</button>
    </div>
    <div id="fa-status"></div>
    <div id="fa-legend"><span style="color:#e8554e">━ rapid</span><span style="color:#3fb950">━ feed</span><span style="color:#58a6ff">━ arc</span><span style="color:#ffd33d">━ selected line</span><span style="color:#8b949e">│ tool axis</span></div>
  </div>
  <div id="fa-play">
    <button id="fa-start" title="To the start">«</button>
    <button id="fa-prev" title="Previous block (←)">‹</button>
    <button id="fa-toggle" title="Play / pause (space)">▶</button>
    <button id="fa-next" title="Next block (→)">›</button>
    <select id="fa-speed" title="Playback speed">
      <option value="0.25">¼×</option><option value="1" selected>1×</option><option value="4">4×</option>
      <option value="16">16×</option><option value="64">64×</option><option value="256">256×</option><option value="1024">1024×</option>
    </select>
    <input id="fa-slider" type="range" min="0" max="1000000" step="1" value="0" title="Time">
    <span id="fa-time"></span>
    <span id="fa-timekind"></span>
    <select id="fa-plotmode" title="Plots against"><option value="time">by time</option><option value="block">by block</option></select>
  </div>
  <div id="fa-plots"></div>
</div>`;
  doc.body.appendChild(root);
  const $ = (id) => doc.getElementById(id);
  root.querySelector('#fa-head b').textContent = meta.program;
  root.querySelector('#fa-head small').textContent = meta.machine.name;
  $('fa-notes').textContent = thinnedNotes(meta).join('. ');
  // Which time the timeline is: `fiveaxis check`'s, as the page says
  // (pages before it had the programmed time).
  const timeLabel = meta.time ? meta.time.label : 'programmed machining time';
  $('fa-timekind').textContent = timeLabel;
  $('fa-slider').title = `Time: ${timeLabel}`;
  $('fa-stock').title = meta.stock ? 'Show / hide the stock (BLK FORM)' : 'Show / hide the stock (the box the cutting moves span)';
  return {
    root,
    text: $('fa-text'),
    textInner: $('fa-text-inner'),
    findingsTitle: root.querySelector('#fa-findings h3'),
    findings: $('fa-findings-list'),
    view3d: $('fa-3d'),
    tools: $('fa-tools'),
    fit: $('fa-fit'),
    stock: $('fa-stock'),
    status: $('fa-status'),
    start: $('fa-start'),
    prev: $('fa-prev'),
    toggle: $('fa-toggle'),
    next: $('fa-next'),
    speed: $('fa-speed'),
    slider: $('fa-slider'),
    time: $('fa-time'),
    plotMode: $('fa-plotmode'),
    plots: $('fa-plots'),
  };
}

const LINE_HEIGHT = 18;

/** The program text, one element per line in sight. */
export class ProgramText {
  constructor(scroller, inner, lines, onClick) {
    this.scroller = scroller;
    this.inner = inner;
    this.lines = lines;
    this.current = 0;
    this.selected = 0;
    /** Lines with a finding (1-based; 1 each). */
    this.marked = new Uint8Array(lines.length + 2);
    inner.style.height = `${lines.length * LINE_HEIGHT}px`;
    inner.style.position = 'relative';
    scroller.addEventListener('scroll', () => this.draw());
    inner.addEventListener('click', (e) => {
      const el = e.target.closest('.ln');
      if (el) onClick(Number(el.dataset.line));
    });
    new ResizeObserver(() => this.draw()).observe(scroller);
    this.draw();
  }

  /** Shows `lines` (the program's, once the page has read them), no marks. */
  setLines(lines) {
    this.lines = lines;
    this.marked = new Uint8Array(lines.length + 2);
    this.inner.style.height = `${lines.length * LINE_HEIGHT}px`;
    this.draw();
  }

  /** Marks `line` (1-based) as having a finding; `draw` shows it. */
  mark(line) {
    if (line < this.marked.length) this.marked[line] = 1;
  }

  /** Highlights `line` (1-based) as the running one, scrolling to it. */
  setCurrent(line, scroll = true) {
    this.current = line;
    if (scroll) this.reveal(line);
    this.draw();
  }

  setSelected(line) {
    this.selected = line;
    this.reveal(line);
    this.draw();
  }

  reveal(line) {
    const y = (line - 1) * LINE_HEIGHT;
    const h = this.scroller.clientHeight;
    if (y < this.scroller.scrollTop || y > this.scroller.scrollTop + h - 2 * LINE_HEIGHT) {
      this.scroller.scrollTop = Math.max(0, y - h / 3);
    }
  }

  draw() {
    const top = this.scroller.scrollTop;
    const h = this.scroller.clientHeight || 400;
    const first = Math.max(0, Math.floor(top / LINE_HEIGHT) - 5);
    const last = Math.min(this.lines.length, Math.ceil((top + h) / LINE_HEIGHT) + 5);
    const parts = [];
    for (let i = first; i < last; i++) {
      const n = i + 1;
      const cls = ['ln'];
      if (n === this.current) cls.push('cur');
      if (n === this.selected) cls.push('sel');
      if (this.marked[n]) cls.push('find');
      parts.push(`<div class="${cls.join(' ')}" data-line="${n}" style="top:${i * LINE_HEIGHT}px"><i>${n}</i>${escapeHtml(this.lines[i])}</div>`);
    }
    this.inner.innerHTML = parts.join('');
  }
}

/** The findings, one element per finding in sight (a virtual list, as the text). */
export class FindingsList {
  constructor(scroller, findings, onClick) {
    this.scroller = scroller;
    this.findings = findings;
    this.inner = scroller.ownerDocument.createElement('div');
    this.inner.style.position = 'relative';
    this.inner.style.height = `${findings.count * LINE_HEIGHT}px`;
    scroller.appendChild(this.inner);
    scroller.addEventListener('scroll', () => this.draw());
    this.inner.addEventListener('click', (e) => {
      const el = e.target.closest('[data-k]');
      if (el) onClick(Number(el.dataset.k));
    });
    new ResizeObserver(() => this.draw()).observe(scroller);
    this.draw();
  }

  draw() {
    const top = this.scroller.scrollTop;
    const h = this.scroller.clientHeight || 200;
    const first = Math.max(0, Math.floor(top / LINE_HEIGHT) - 5);
    const last = Math.min(this.findings.count, Math.ceil((top + h) / LINE_HEIGHT) + 5);
    const parts = [];
    for (let k = first; k < last; k++) {
      const f = findingAt(this.findings, k);
      const said = f.message ? `: ${escapeHtml(f.message)}` : '';
      const measure = f.axis !== undefined || f.value !== undefined ? ` (${f.axis !== undefined ? escapeHtml(f.axis) : ''}${f.axis !== undefined && f.value !== undefined ? ' ' : ''}${f.value !== undefined ? f.value : ''})` : '';
      parts.push(`<div class="fd ${escapeHtml(f.severity)}" data-k="${k}" style="top:${k * LINE_HEIGHT}px" title="${escapeHtml(f.message)}">line ${f.line}: ${escapeHtml(f.kind)}${said}${measure}</div>`);
    }
    this.inner.innerHTML = parts.join('');
  }
}

export function escapeHtml(s) {
  return s.replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' })[c]);
}

/** Seconds as h:mm:ss.s. */
export function clock(seconds) {
  const s = Math.max(0, seconds);
  const h = Math.floor(s / 3600);
  const m = Math.floor((s % 3600) / 60);
  const r = (s % 60).toFixed(1).padStart(4, '0');
  return h ? `${h}:${String(m).padStart(2, '0')}:${r}` : `${m}:${r}`;
}
