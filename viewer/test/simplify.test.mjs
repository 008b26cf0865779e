// The path to the pixel (viewer/src/simplify.js), judged on random
// polylines by an independent measure: every point of the whole line strip
// lies within the spacing of the simplified one and the other way round
// (distances of densely sampled points to the other strip), and every
// change of colour, the first and the last vertex stay.

import assert from 'node:assert/strict';
import { test } from 'node:test';
import { simplifyToSpacing } from '../src/simplify.js';

/** A seeded generator of numbers in [0, 1) (mulberry32). */
function random(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

/** Distance of point p to segment ab (arrays of 3). */
function toSegment(p, a, b) {
  const ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
  const len2 = ab[0] ** 2 + ab[1] ** 2 + ab[2] ** 2;
  const f = len2 > 0 ? Math.min(1, Math.max(0, ((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1] + (p[2] - a[2]) * ab[2]) / len2)) : 0;
  return Math.hypot(a[0] + f * ab[0] - p[0], a[1] + f * ab[1] - p[1], a[2] + f * ab[2] - p[2]);
}

/** Largest distance of the strip `from` (sampled) to the strip `to`. */
function farthest(pos, from, to) {
  const at = (i) => [pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]];
  let worst = 0;
  for (let j = 1; j < from.length; j++) {
    const a = at(from[j - 1]);
    const b = at(from[j]);
    for (let s = 0; s <= 8; s++) {
      const p = [0, 1, 2].map((k) => a[k] + ((b[k] - a[k]) * s) / 8);
      let best = Infinity;
      for (let m = 1; m < to.length; m++) best = Math.min(best, toSegment(p, at(to[m - 1]), at(to[m])));
      worst = Math.max(worst, best);
    }
  }
  return worst;
}

test('random strips: the simplified strip is within the spacing of the whole one, both ways', () => {
  const rnd = random(0x5eed);
  let dropped = 0;
  for (let c = 0; c < 200; c++) {
    const n = 2 + Math.floor(rnd() * 120);
    const step = rnd() < 0.5 ? 0.05 : 1;
    const pos = new Float32Array(3 * n);
    const col = new Float32Array(3 * n);
    const p = [0, 0, 0];
    let colour = 0;
    for (let i = 0; i < n; i++) {
      for (let k = 0; k < 3; k++) p[k] += (rnd() - 0.5) * step;
      if (rnd() < 0.05) colour = (colour + 1) % 3;
      pos.set(p, 3 * i);
      col.set([colour === 0 ? 1 : 0, colour === 1 ? 1 : 0, colour === 2 ? 1 : 0], 3 * i);
    }
    const all = Uint32Array.from({ length: n }, (_, i) => i);
    const tol = 0.01 + rnd() * 0.5;
    const kept = simplifyToSpacing(pos, col, all, tol);
    dropped += n - kept.length;
    assert.equal(kept[0], 0, 'first stays');
    assert.equal(kept.at(-1), n - 1, 'last stays');
    const keptSet = new Set(kept);
    for (let i = 1; i < n; i++) {
      const changes = [0, 1, 2].some((k) => col[3 * i + k] !== col[3 * (i - 1) + k]);
      if (changes) assert.ok(keptSet.has(i) && keptSet.has(i - 1), `colour change at ${i} stays`);
    }
    // Float32 positions: a little room for rounding.
    const room = tol * (1 + 1e-5) + 1e-6;
    assert.ok(farthest(pos, all, kept) <= room, `whole strip within ${tol} of the simplified one (case ${c})`);
    assert.ok(farthest(pos, kept, all) <= room, `simplified strip within ${tol} of the whole one (case ${c})`);
  }
  assert.ok(dropped > 1000, `too few vertices left out to judge: ${dropped}`);
});
