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
