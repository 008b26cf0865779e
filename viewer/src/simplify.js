// The path simplified to the pixel (pure: no three.js, no DOM), for the
// levels the scene draws at rest (viewer/src/scene.js).

/**
 * Indices of the drawn vertices that stay when points closer than `tol` to
 * the last one kept are left out (from the vertices `from`, in order): a
 * vertex where the colour changes (a change of motion), the first and the
 * last always stay. On a line strip that moves the drawing by at most
 * `tol`: nothing closer than a pixel is visible, nothing farther is lost.
 */
export function simplifyToSpacing(pos, col, from, tol) {
  const out = new Uint32Array(from.length);
  const tol2 = tol * tol;
  const sameColour = (a, b) => col[3 * a] === col[3 * b] && col[3 * a + 1] === col[3 * b + 1] && col[3 * a + 2] === col[3 * b + 2];
  let m = 0;
  let last = from[0];
  out[m++] = last;
  for (let j = 1; j < from.length; j++) {
    const i = from[j];
    const dx = pos[3 * i] - pos[3 * last];
    const dy = pos[3 * i + 1] - pos[3 * last + 1];
    const dz = pos[3 * i + 2] - pos[3 * last + 2];
    const edge = j === from.length - 1 || !sameColour(i, from[j + 1]) || !sameColour(i, from[j - 1]);
    if (edge || dx * dx + dy * dy + dz * dz >= tol2) {
      out[m++] = i;
      last = i;
    }
  }
  return out.subarray(0, m);
}
