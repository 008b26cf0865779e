// The data `fiveaxis view` embeds in the page (crates/fiveaxis-cli/src/
// view/html.rs): a JSON description, typed arrays in base64, and the
// program text.

import { forward, prepareMachine, toPart } from './kinematics.js';
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

function array(doc, name, Type) {
  const element = doc.getElementById(ARRAY_PREFIX + name);
  if (!element) throw new Error(`the page has no array ${name}: written by another fiveaxis version?`);
  const bytes = decodeBase64(element.textContent.trim());
  element.textContent = '';
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
export function readPage(doc, mark = () => {}) {
  const meta = JSON.parse(doc.getElementById(META_ID).textContent);
  const machine = prepareMachine(meta.machine);
  const program = doc.getElementById(PROGRAM_ID);
  const text = unescapeProgram(program.textContent);
  program.textContent = '';
  mark('programText');
  const data = {
    meta,
    machine,
    axes: machine.axisCount,
    joints: array(doc, 'joints', Float32Array),
    times: array(doc, 'times', Float64Array),
    lines: array(doc, 'lines', Uint32Array),
    ends: array(doc, 'ends', Float64Array),
    motions: array(doc, 'motions', Uint8Array),
    findings: {
      lines: array(doc, 'finding_lines', Uint32Array),
      kinds: array(doc, 'finding_kinds', Uint8Array),
      axes: array(doc, 'finding_axes', Uint8Array),
      values: array(doc, 'finding_values', Float64Array),
      table: meta.finding_kinds || [],
      messages: meta.finding_messages || [],
    },
  };
  data.findings.count = data.findings.lines.length;
  mark('arrays');
  data.programLines = splitLines(text);
  mark('programLines');
  derive(data);
  mark('derive');
  return data;
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
  const q = new Array(axes).fill(0);
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
    const { tip, dir } = forward(machine, q, frame.tool_length);
    tips.set(tip, 3 * i);
    dirs.set(dir, 3 * i);
    // The bounding box of the rows: the start position (vertex 0) is not one.
    if (i === 0 && n > 1) continue;
    const p = toPart(frame.to_part, tip);
    for (let k = 0; k < 3; k++) {
      if (p[k] < lo[k]) lo[k] = p[k];
      if (p[k] > hi[k]) hi[k] = p[k];
    }
  }
  data.tips = tips;
  data.dirs = dirs;
  data.vertexBlock = blocks;
  data.bbox = n ? { min: lo, max: hi } : null;
  data.duration = ends.length ? ends[ends.length - 1] : 0;
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
