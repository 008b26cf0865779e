// The data `fiveaxis view` embeds in the page (crates/fiveaxis-cli/src/
// view/html.rs): a JSON description, the typed arrays (their bytes
// regrouped by byte position, deflated (zlib) where that pays,
// `data-encoding`, and in base64) and the program text.

import { forwardInto, fromPart, prepareMachine } from './kinematics.js';
import { frameOfBlock, lowerBound } from './timeline.js';

const META_ID = 'fiveaxis-meta';
const ARRAY_PREFIX = 'fiveaxis-array-';
const PROGRAM_ID = 'fiveaxis-program';

/** Motion codes of the `motions` array. */
export const MOTIONS = ['rapid', 'linear', 'cw', 'ccw'];

/** Bytes of a base64 text (the browser's own decoder where it has one). */
export function decodeBase64(text) {
  if (typeof Uint8Array.fromBase64 === 'function') return Uint8Array.fromBase64(text);
  const binary = atob(text);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
  return bytes;
}

/** Bytes inflated by the browser's own zlib reader. */
async function inflate(bytes) {
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
  return new Uint8Array(await new Response(stream).arrayBuffer());
}

/** Undoes the page's regrouping of `width`-byte elements by byte position. */
export function unshuffle(bytes, width) {
  if (width <= 1) return bytes;
  const n = bytes.length / width;
  const out = new Uint8Array(bytes.length);
  for (let b = 0; b < width; b++) {
    const from = b * n;
    for (let i = 0, o = b; i < n; i++, o += width) out[o] = bytes[from + i];
  }
  return out;
}

/** The bytes of a packed element of the page (and its text let go). */
async function unpack(doc, id) {
  const element = doc.getElementById(id);
  if (!element) throw new Error(`the page has no element ${id}: written by another fiveaxis version?`);
  const width = Number(element.dataset.width || 1);
  const packed = decodeBase64(element.textContent.trim());
  element.textContent = '';
  return unshuffle(element.dataset.encoding === 'deflate' ? await inflate(packed) : packed, width);
}

async function array(doc, name, Type) {
  const bytes = await unpack(doc, ARRAY_PREFIX + name);
  return new Type(bytes.buffer, bytes.byteOffset, bytes.byteLength / Type.BYTES_PER_ELEMENT);
}

/** The program text as written (undoes the page's `&a;`, `&l;`, `&r;`). */
export function unescapeProgram(text) {
  if (!text.includes('&')) return text;
  return text.replace(/&[alr];/g, (m) => (m === '&a;' ? '&' : m === '&l;' ? '<' : '\r'));
}

/** Program lines as the control counts them: LF, CR LF or a lone CR. */
export function splitLines(text) {
  const lines = text.split(/\r\n|\r|\n/);
  if (lines.length > 1 && lines[lines.length - 1] === '') lines.pop();
  return lines;
}

/** Reads everything from the page. */
export async function readPage(doc, mark = () => {}) {
  const meta = JSON.parse(doc.getElementById(META_ID).textContent);
  const machine = prepareMachine(meta.machine);
  const names = ['joints', 'times', 'lines', 'ends', 'motions', 'finding_lines', 'finding_kinds', 'finding_axes', 'finding_values', 'finding_points', 'fixture_triangles', 'stock_tops', 'stock_cells', 'stock_values'];
  const types = [Float32Array, Float64Array, Uint32Array, Float64Array, Uint8Array, Uint32Array, Uint8Array, Uint8Array, Float64Array, Float32Array, Float32Array, Float32Array, Uint32Array, Float32Array];
  const arrays = await Promise.all(names.map((name, k) => array(doc, name, types[k])));
  mark('arrays');
  const [joints, times, lines, ends, motions, findingLines, findingKinds, findingAxes, findingValues, findingPoints, fixtureTriangles, stockTops, stockCells, stockValues] = arrays;
  const data = {
    meta,
    machine,
    axes: machine.axisCount,
    joints,
    times,
    lines,
    ends,
    motions,
    findings: {
      lines: findingLines,
      kinds: findingKinds,
      axes: findingAxes,
      values: findingValues,
      points: findingPoints,
      table: meta.finding_kinds || [],
      messages: meta.finding_messages || [],
    },
  };
  // The work on the table: fixtures, the stock along the run (`view
  // --fixture`, `--stock`), the tools' shapes.
  data.work = {
    fixtures: meta.fixtures || [],
    triangles: fixtureTriangles,
    stockModel: meta.stock_model || null,
    stockTops,
    stockCells,
    stockValues,
    tools: meta.tools || {},
  };
  data.findings.count = data.findings.lines.length;
  data.programLines = [];
  derive(data);
  mark('derive');
  return data;
}

/**
 * The program's lines. The page holds the text after the viewer script,
 * so that the viewer draws the path and the machine while the browser is
 * still reading a long text: this waits for the whole page.
 */
export async function readProgramLines(doc) {
  if (doc.readyState === 'loading') await new Promise((resolve) => doc.addEventListener('DOMContentLoaded', resolve, { once: true }));
  const program = doc.getElementById(PROGRAM_ID);
  if (!program) throw new Error('the page has no program text: written by another fiveaxis version?');
  const text = unescapeProgram(program.textContent);
  program.textContent = '';
  return splitLines(text);
}

/**
 * Per vertex: the block it ends in, the tip and direction in the table
 * frame (forward kinematics of its machine position with its block's
 * tool), and the bounding box of the tips in the part frame.
 */
export function derive(data) {
  const { axes, joints, times, ends, machine, meta } = data;
  const n = times.length;
  const tips = new Float32Array(3 * n);
  const dirs = new Float32Array(3 * n);
  const blocks = new Uint32Array(n);
  const q = new Float64Array(axes);
  const fk = new Float64Array(6);
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  const lastBlock = Math.max(0, ends.length - 1);
  let b = 0;
  let frameBlock = -1;
  let frame = null;
  for (let i = 0; i < n; i++) {
    // The block a vertex belongs to: the first that ends at or after it
    // (the times grow: a walk along the blocks, as a search would find).
    if (i === 0 || times[i] < times[i - 1]) b = Math.min(lowerBound(ends, times[i]), lastBlock);
    while (b < lastBlock && ends[b] < times[i]) b++;
    blocks[i] = b;
    if (b !== frameBlock) {
      frame = meta.frames[frameOfBlock(data, b)] || { tool_length: 0, to_part: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0] };
      frameBlock = b;
    }
    for (let a = 0; a < axes; a++) q[a] = joints[i * axes + a];
    forwardInto(machine, q, frame.tool_length, fk);
    for (let k = 0; k < 3; k++) {
      tips[3 * i + k] = fk[k];
      dirs[3 * i + k] = fk[3 + k];
    }
    // The bounding box of the rows: the start position (vertex 0) is not one.
    if (i === 0 && n > 1) continue;
    const m = frame.to_part;
    for (let k = 0; k < 3; k++) {
      const p = m[4 * k] * fk[0] + m[4 * k + 1] * fk[1] + m[4 * k + 2] * fk[2] + m[4 * k + 3];
      if (p < lo[k]) lo[k] = p;
      if (p > hi[k]) hi[k] = p;
    }
  }
  data.tips = tips;
  data.dirs = dirs;
  data.vertexBlock = blocks;
  data.bbox = n ? { min: lo, max: hi } : null;
  data.duration = ends.length ? ends[ends.length - 1] : 0;
}

/** The frame of no work offset: the part frame is the table frame. */
const IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0];

/**
 * The stock the program declares (`meta.stock`: HEIDENHAIN `BLK FORM`, its
 * min and max corner in workpiece coordinates) as the scene draws it: the
 * 8 corners in the table frame, placed by the work offset of the first
 * frame run (`meta.frames[0].to_part`, as the workpiece zero), so that the
 * table axes carry it with the path. Corner `k` is, by bit 0, 1, 2 of `k`,
 * the min or max in X, Y, Z. Null when the program declares none (or a
 * page written before the stock).
 */
export function stockCorners(meta) {
  const s = meta.stock;
  if (!s || !s.min || !s.max) return null;
  const lo = [0, 1, 2].map((k) => Math.min(s.min[k], s.max[k]));
  const hi = [0, 1, 2].map((k) => Math.max(s.min[k], s.max[k]));
  if (![...lo, ...hi].every(Number.isFinite)) return null;
  const frame = meta.frames && meta.frames[0];
  const m = frame ? frame.to_part : IDENTITY;
  const corners = [];
  for (let k = 0; k < 8; k++) {
    corners.push(fromPart(m, [k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]]));
  }
  return corners;
}

/**
 * Finding `k` as the `check` contract has it (`severity`, `kind`, `line`,
 * `message`, and `axis`, `value` where they apply). The page holds the
 * messages of the first findings only (`view.rs`, FINDING_MESSAGES):
 * `message` is empty beyond them.
 */
export function findingAt(findings, k) {
  const type = findings.table[findings.kinds[k]] || { kind: 'unknown', severity: 'warning' };
  const f = { severity: type.severity, kind: type.kind, line: findings.lines[k], message: k < findings.messages.length ? findings.messages[k] : '' };
  if (findings.axes[k]) f.axis = String.fromCharCode(findings.axes[k]);
  if (!Number.isNaN(findings.values[k])) f.value = findings.values[k];
  return f;
}

/** A count with thousands separators, as the page writes them. */
const count = (n) => Number(n).toLocaleString('en-US');

/**
 * What the page's bounds left out or made coarser (`meta.thinned`, written
 * by `fiveaxis view`), as sentences for people; none for a page that holds
 * everything (or one written before the bounds).
 */
export function thinnedNotes(meta) {
  const t = meta.thinned;
  if (!t) return [];
  const notes = [];
  if (t.path) notes.push(`path drawn to ${Number(meta.tolerance.toPrecision(3))} mm, not ${t.tolerance} mm: the page holds at most ${count(t.limits.vertices)} vertices`);
  if (t.blocks) notes.push(`neighbouring blocks merged: the page holds at most ${count(t.limits.blocks)} blocks`);
  return notes;
}

/** The findings list's title: how many, and how many the page holds. */
export function findingsTitle(meta, shown) {
  const total = meta.thinned ? meta.thinned.findings_total : shown;
  if (!total) return 'No findings';
  if (total > shown) return `Findings (the first ${count(shown)} of ${count(total)}; fiveaxis check lists every one)`;
  return `Findings (${count(total)})`;
}

/** The line shown after the program text when the page holds only its start. */
export function textLeftOutLine(meta) {
  const n = meta.thinned ? meta.thinned.text_lines_left_out : 0;
  if (!n) return null;
  return `… ${count(n)} more line${n === 1 ? '' : 's'}: the page holds the first ${Math.round(meta.thinned.limits.text_bytes / (1 << 20))} MiB of the program`;
}
