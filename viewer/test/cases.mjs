// The example programs on each built-in machine type, made into pages by
// `fiveaxis view`, with what `fiveaxis run` reports for the same program.

import { execFileSync, spawnSync } from 'node:child_process';
import { mkdirSync, readFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

export const ROOT = resolve(dirname(fileURLToPath(import.meta.url)), '../..');
/** The binary: $FIVEAXIS (the cargo test sets it), else the debug build. */
export const FIVEAXIS = process.env.FIVEAXIS || join(process.env.CARGO_TARGET_DIR || join(ROOT, 'target'), 'debug/fiveaxis');
/** Where pages and screenshots go. */
export const OUT = process.env.VIEW_TEST_OUT || join(process.env.CARGO_TARGET_DIR || join(ROOT, 'target'), 'view-test');

/** Program × machine: every built-in type (table, mixed, head, none), and a program an alarm stops. */
export const CASES = [
  { program: 'bracket.nc', machine: 'trunnion-ac' },
  { program: 'tilted-holes.nc', machine: 'trunnion-bc' },
  { program: 'tcpc-vector.nc', machine: 'head-table-bc' },
  { program: 'bracket.nc', machine: 'head-head-ca' },
  { program: 'subprogram.nc', machine: 'mill-3axis' },
  { program: 'tcpc-vector.nc', machine: 'trunnion-ac', alarm: true },
];

function args(c) {
  return [join(ROOT, 'examples', c.program), '--machine', c.machine, '--offsets', join(ROOT, 'examples/offsets.toml'), '--programs', join(ROOT, 'examples')];
}

/** JSON Lines of `fiveaxis run` (with extra options): rows and the closing alarm. */
export function runRows(c, extra = []) {
  const r = spawnSync(FIVEAXIS, ['run', ...args(c), '--format', 'jsonl', ...extra], { encoding: 'utf8', maxBuffer: 1 << 30 });
  if (r.status !== 0 && r.status !== 1) throw new Error(`fiveaxis run failed: ${r.stderr}`);
  const objects = r.stdout.split('\n').filter(Boolean).map((l) => JSON.parse(l));
  return { rows: objects.filter((o) => !o.alarm), alarm: (objects.find((o) => o.alarm) || {}).alarm || null, status: r.status };
}

/**
 * The rows of the page's blocks: the last row of each run of rows of one
 * line and motion (the page holds such a run, the chords of a spline or
 * the feeds of a cycle, as one block).
 */
export function blockRows(rows) {
  return rows.filter((r, i) => i + 1 === rows.length || rows[i + 1].line !== r.line || rows[i + 1].motion !== r.motion);
}

/** The report of `fiveaxis check` on a case (the contract's JSON). */
export function checkReport(c) {
  const r = spawnSync(FIVEAXIS, ['check', ...args(c), '--format', 'json', '--fail-on', 'never'], { encoding: 'utf8', maxBuffer: 1 << 30 });
  if (r.status !== 0) throw new Error(`fiveaxis check failed: ${r.stderr}`);
  return JSON.parse(r.stdout.split('\n').filter(Boolean)[0]);
}

/** Writes the page of a case; returns its path, exit status and meta. */
export function makePage(c) {
  mkdirSync(OUT, { recursive: true });
  const file = join(OUT, `${c.program.replace(/\.nc$/, '')}-${c.machine}.html`);
  const r = spawnSync(FIVEAXIS, ['view', ...args(c), '-o', file], { encoding: 'utf8' });
  if (r.status !== 0 && r.status !== 1) throw new Error(`fiveaxis view failed: ${r.stderr}`);
  const html = readFileSync(file, 'utf8');
  const json = html.match(/<script type="application\/json" id="fiveaxis-meta">(.*?)<\/script>/s)[1];
  return { file, status: r.status, meta: JSON.parse(json), size: html.length };
}

/** The machine description as the page embeds it. */
export function fiveaxisVersion() {
  return execFileSync(FIVEAXIS, ['--version'], { encoding: 'utf8' }).trim();
}
