// The viewer's forward kinematics against the kernel's: for every row
// `fiveaxis run` prints, the tip and tool direction that viewer/src/
// kinematics.js computes from the row's machine position, the machine
// description and the block's frame that the page embeds, equal the row's
// own (computed in Rust by Machine::forward). Plus hand-computed poses.

import assert from 'node:assert/strict';
import { test } from 'node:test';
import { forward, prepareMachine, toPart, toPartVector } from '../src/kinematics.js';
import { CASES, blockRows, makePage, runRows } from './cases.mjs';

const close = (a, b, tol, what) => {
  for (let k = 0; k < 3; k++) assert.ok(Math.abs(a[k] - b[k]) <= tol, `${what}: ${a} vs ${b}`);
};

test('hand-computed: A/C trunnion, A = -90 turns the tip about the A line', () => {
  // Table A about -X through (0,0,-100); tool length 0 at X0 Y0 Z0. T⁻¹
  // turns the gauge point by +90 deg about -X about the centre:
  // (0,0,0) - c = (0,0,100); about -X by 90: (0,0,100) → (0,100,0);
  // + c = (0,100,-100). The direction (0,0,1) → (0,1,0).
  const m = prepareMachine({
    tool_direction: [0, 0, 1],
    linear: [{ name: 'X' }, { name: 'Y' }, { name: 'Z' }],
    rotary: [
      { name: 'A', on: 'table', axis: [-1, 0, 0], center: [0, 0, -100] },
      { name: 'C', on: 'table', axis: [0, 0, -1], center: [0, 0, 0] },
    ],
  });
  const { tip, dir } = forward(m, [0, 0, 0, -90, 0], 0);
  close(tip, [0, 100, -100], 1e-12, 'tip');
  close(dir, [0, 1, 0], 1e-12, 'dir');
});

test('hand-computed: head B = 90 about +Y through the pivot 150 above the gauge point', () => {
  const m = prepareMachine({
    tool_direction: [0, 0, 1],
    linear: [{ name: 'X' }, { name: 'Y' }, { name: 'Z' }],
    rotary: [{ name: 'B', on: 'head', axis: [0, 1, 0], center: [0, 0, 150] }],
  });
  // Tip at -100 on the tool axis: (0,0,-100) - (0,0,150) = (0,0,-250),
  // turned +90 about Y: (-250, 0, 0), + pivot = (-250, 0, 150), + XYZ.
  const { tip, dir } = forward(m, [10, 20, 30, 90], 100);
  close(tip, [-240, 20, 180], 1e-12, 'tip');
  close(dir, [1, 0, 0], 1e-12, 'dir');
});

for (const c of CASES) {
  test(`forward kinematics equals the kernel's rows: ${c.program} on ${c.machine}`, () => {
    const { meta } = makePage(c);
    const machine = prepareMachine(meta.machine);
    const all = runRows(c).rows;
    assert.equal(all.length, meta.segments, 'one row per segment without --step');
    const rows = blockRows(all);
    assert.equal(rows.length, meta.blocks, 'a block per run of segments of one line and motion');
    const runs = meta.frame_runs;
    let r = 0;
    rows.forEach((row, b) => {
      while (r + 1 < runs.length && runs[r + 1][0] <= b) r++;
      const frame = meta.frames[runs[r][1]];
      const joints = machine.axisNames.map((n) => row[n]);
      const fk = forward(machine, joints, frame.tool_length);
      close(toPart(frame.to_part, fk.tip), [row.tip_x, row.tip_y, row.tip_z], 1e-9, `line ${row.line} tip`);
      close(toPartVector(frame.to_part, fk.dir), [row.tool_i, row.tool_j, row.tool_k], 1e-12, `line ${row.line} dir`);
    });
  });
}
