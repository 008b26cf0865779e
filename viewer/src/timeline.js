// Time along the program: which vertex and which block stand at a time,
// and the machine position there. Every axis moves linearly in time
// between two vertices (that is how `fiveaxis view` packs the path).

/** Index of the first entry of the sorted `values` that is ≥ `x` (n if none). */
export function lowerBound(values, x) {
  let lo = 0;
  let hi = values.length;
  while (lo < hi) {
    const mid = (lo + hi) >>> 1;
    if (values[mid] < x) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

/** Index of the first entry of the sorted `values` that is > `x`. */
export function upperBound(values, x) {
  let lo = 0;
  let hi = values.length;
  while (lo < hi) {
    const mid = (lo + hi) >>> 1;
    if (values[mid] <= x) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

/**
 * The machine position at time `t`, written into `out` (length
 * `axes`): linear between the vertices around `t`.
 */
export function jointsAt(data, t, out) {
  const { times, joints, axes } = data;
  const n = times.length;
  if (n === 0) return out;
  let i = upperBound(times, t); // first vertex after t
  if (i <= 0) i = 1;
  if (i >= n) {
    for (let a = 0; a < axes; a++) out[a] = joints[(n - 1) * axes + a];
    return out;
  }
  const t0 = times[i - 1];
  const t1 = times[i];
  const f = t1 > t0 ? Math.min(1, Math.max(0, (t - t0) / (t1 - t0))) : 1;
  for (let a = 0; a < axes; a++) {
    const x0 = joints[(i - 1) * axes + a];
    const x1 = joints[i * axes + a];
    out[a] = x0 + (x1 - x0) * f;
  }
  return out;
}

/** The block running at time `t` (the first whose end is ≥ t), or -1. */
export function blockAt(data, t) {
  if (data.ends.length === 0) return -1;
  return Math.min(lowerBound(data.ends, t), data.ends.length - 1);
}

/** Start time of block `b`. */
export function blockStart(data, b) {
  return b > 0 ? data.ends[b - 1] : 0;
}

/** The frame index of block `b` (frame runs are `[first block, frame]`). */
export function frameOfBlock(data, b) {
  const runs = data.meta.frame_runs;
  let lo = 0;
  let hi = runs.length - 1;
  while (lo < hi) {
    const mid = (lo + hi + 1) >>> 1;
    if (runs[mid][0] <= b) lo = mid;
    else hi = mid - 1;
  }
  return runs.length ? runs[lo][1] : 0;
}

/**
 * For each program line, the blocks that ran it, in order: `first[line]`
 * to `first[line + 1]` in `order` (a counting sort, linear in the blocks).
 */
export function blocksByLine(lines, lineCount) {
  const first = new Uint32Array(lineCount + 2);
  for (let b = 0; b < lines.length; b++) first[Math.min(lines[b], lineCount) + 1]++;
  for (let l = 1; l < first.length; l++) first[l] += first[l - 1];
  const fill = first.slice();
  const order = new Uint32Array(lines.length);
  for (let b = 0; b < lines.length; b++) order[fill[Math.min(lines[b], lineCount)]++] = b;
  return { first, order };
}
