// The page's own account of its bounds (`meta.thinned`): what it says when
// the path was simplified coarser, blocks merged, findings or text left
// out, and nothing for a page that holds everything.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { findingsTitle, textLeftOutLine, thinnedNotes } from '../src/data.js';

const LIMITS = { vertices: 1000000, blocks: 1000000, findings: 100000, messages: 10000, text_bytes: 16 << 20 };
const whole = { tolerance: 0.001, thinned: { tolerance: 0.001, path: false, blocks: false, findings_total: 3, text_lines_left_out: 0, limits: LIMITS } };

test('a page that holds everything says nothing of bounds', () => {
  assert.deepEqual(thinnedNotes(whole), []);
  assert.equal(findingsTitle(whole, 3), 'Findings (3)');
  assert.equal(textLeftOutLine(whole), null);
  assert.equal(findingsTitle({ ...whole, thinned: { ...whole.thinned, findings_total: 0 } }, 0), 'No findings');
  // A page written before the bounds.
  assert.deepEqual(thinnedNotes({ tolerance: 0.001 }), []);
  assert.equal(findingsTitle({}, 2), 'Findings (2)');
});

test('a bounded page says what it simplified and left out', () => {
  const meta = { tolerance: 0.256, thinned: { ...whole.thinned, path: true, blocks: true, findings_total: 3100000, text_lines_left_out: 1500000 } };
  assert.deepEqual(thinnedNotes(meta), [
    'path drawn to 0.256 mm, not 0.001 mm: the page holds at most 1,000,000 vertices',
    'neighbouring blocks merged: the page holds at most 1,000,000 blocks',
  ]);
  assert.equal(findingsTitle(meta, 100000), 'Findings (the first 100,000 of 3,100,000; fiveaxis check lists every one)');
  assert.equal(textLeftOutLine(meta), '… 1,500,000 more lines: the page holds the first 16 MiB of the program');
});

// The stock a HEIDENHAIN program declares (BLK FORM): its corners in the
// table frame, where the scene draws it (under the table axes, as the path).
import { stockCorners } from '../src/data.js';
import { toPart } from '../src/kinematics.js';

const STOCK = { min: [-187, -55.5, -50.6], max: [187, 55.5, 0.6] };
const near3 = (a, b, what) => a.forEach((x, k) => assert.ok(Math.abs(x - b[k]) < 1e-9, `${what}: ${a} vs ${b}`));

test('the stock is placed by the work offset of the first frame', () => {
  // Work offset W = (10, −20, 30): tip_part = tip_table − W (view.rs, Frame::to_json).
  const frames = [
    { tool_length: 100, tool_radius: 5, to_part: [1, 0, 0, -10, 0, 1, 0, 20, 0, 0, 1, -30] },
    { tool_length: 100, tool_radius: 5, to_part: [1, 0, 0, -500, 0, 1, 0, 0, 0, 0, 1, 0] },
  ];
  const corners = stockCorners({ stock: STOCK, frames });
  assert.equal(corners.length, 8);
  // Corner k: bit 0, 1, 2 = max in X, Y, Z; each is the workpiece corner + W.
  near3(corners[0], [-177, -75.5, -20.6], 'min corner');
  near3(corners[7], [197, 35.5, 30.6], 'max corner');
  near3(corners[1], [197, -75.5, -20.6], 'max X');
  near3(corners[2], [-177, 35.5, -20.6], 'max Y');
  near3(corners[4], [-177, -75.5, 30.6], 'max Z');
  // Back in the part frame: the declared corners.
  near3(toPart(frames[0].to_part, corners[6]), [-187, 55.5, 0.6], 'corner 6 in the workpiece frame');
});

test('a turned setup turns the stock with it', () => {
  // Part frame turned 90° about Z from the table, origin at table (100, 0, 0):
  // tip_part = Rᵀ(tip_table − (100, 0, 0)), R = 90° about Z.
  const to_part = [0, 1, 0, 0, -1, 0, 0, 100, 0, 0, 1, 0];
  const corners = stockCorners({ stock: { min: [0, 0, -10], max: [20, 5, 0] }, frames: [{ to_part }] });
  near3(corners[0], [100, 0, -10], 'min corner at the part origin');
  near3(corners[1], [100, 20, -10], 'part +X is table +Y');
  near3(corners[2], [95, 0, -10], 'part +Y is table −X');
  near3(corners[7], [95, 20, 0], 'max corner');
  for (const c of corners) {
    const p = toPart(to_part, c);
    assert.ok(p[0] >= -1e-9 && p[0] <= 20 + 1e-9 && p[1] >= -1e-9 && p[1] <= 5 + 1e-9, `inside the stock: ${p}`);
  }
});

test('no stock: none drawn; no frame: the table frame; corners in any order', () => {
  assert.equal(stockCorners({ stock: null, frames: [] }), null);
  assert.equal(stockCorners({ frames: [] }), null, 'a page written before the stock');
  const corners = stockCorners({ stock: { min: [5, 5, 0], max: [-5, -5, -2] }, frames: [] });
  near3(corners[0], [-5, -5, -2], 'min, in the table frame');
  near3(corners[7], [5, 5, 0], 'max');
});
