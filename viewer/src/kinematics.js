// Forward kinematics of the machine model (machine-model.md §1–3), the
// same maps the kernel applies (crates/fiveaxis-machine/src/kinematics.rs):
// a rotary axis turns what it carries by the right-hand rule about the line
// through `center` along `axis`; head axes act on coordinates relative to
// the spindle gauge point, table axes on machine coordinates; both chains
// are listed from the bed outwards.

function unit(v) {
  const n = Math.hypot(v[0], v[1], v[2]);
  return [v[0] / n, v[1] / n, v[2] / n];
}

/**
 * The machine as the viewer uses it: the description `fiveaxis view`
 * embeds, with unit axis vectors and the index of each rotary axis in a
 * joints array.
 */
export function prepareMachine(description) {
  const linear = description.linear;
  const rotary = description.rotary.map((r, k) => ({
    ...r,
    axis: unit(r.axis),
    index: linear.length + k,
  }));
  return {
    ...description,
    toolDirection: unit(description.tool_direction),
    linear,
    rotary,
    axisCount: linear.length + rotary.length,
    axisNames: [...linear.map((a) => a.name), ...rotary.map((r) => r.name)],
  };
}

/**
 * Turns `s[o..o+3]` in place about the unit vector `k` by the angle of
 * sine `sn` and cosine `cs` (Rodrigues), about the point `c` when given.
 */
function turnInPlace(s, o, k, sn, cs, c) {
  const vx = c ? s[o] - c[0] : s[o];
  const vy = c ? s[o + 1] - c[1] : s[o + 1];
  const vz = c ? s[o + 2] - c[2] : s[o + 2];
  const kv = (k[0] * vx + k[1] * vy + k[2] * vz) * (1 - cs);
  const x = vx * cs + (k[1] * vz - k[2] * vy) * sn + k[0] * kv;
  const y = vy * cs + (k[2] * vx - k[0] * vz) * sn + k[1] * kv;
  const z = vz * cs + (k[0] * vy - k[1] * vx) * sn + k[2] * kv;
  s[o] = c ? x + c[0] : x;
  s[o + 1] = c ? y + c[1] : y;
  s[o + 2] = c ? z + c[2] : z;
}

/** Turns the tip `out[0..3]` and the direction `out[3..6]` by `deg` about rotary axis `r`. */
function turnBoth(out, r, deg) {
  const a = (deg * Math.PI) / 180;
  const sn = Math.sin(a);
  const cs = Math.cos(a);
  turnInPlace(out, 0, r.axis, sn, cs, r.center);
  turnInPlace(out, 3, r.axis, sn, cs, null);
}

/**
 * Tool tip and direction in the table frame for machine positions `joints`
 * (X, Y, Z first, then the rotary axes bed outwards) and tool length `L`,
 * written into `out` (tip x y z, then direction x y z) with no allocation:
 * tip_machine = XYZ + H(−L·t0), dir = R_H·t0, then T⁻¹ of both.
 */
export function forwardInto(machine, joints, L, out) {
  const t0 = machine.toolDirection;
  out[0] = -L * t0[0];
  out[1] = -L * t0[1];
  out[2] = -L * t0[2];
  out[3] = t0[0];
  out[4] = t0[1];
  out[5] = t0[2];
  const rot = machine.rotary;
  for (let k = rot.length - 1; k >= 0; k--) {
    const r = rot[k];
    if (r.on === 'head') {
      turnBoth(out, r, joints[r.index]);
    }
  }
  out[0] += joints[0];
  out[1] += joints[1];
  out[2] += joints[2];
  for (let k = 0; k < rot.length; k++) {
    const r = rot[k];
    if (r.on === 'table') {
      turnBoth(out, r, -joints[r.index]);
    }
  }
  return out;
}

/** Tool tip and direction as arrays ([`forwardInto`]). */
export function forward(machine, joints, L) {
  const out = forwardInto(machine, joints, L, new Float64Array(6));
  return { tip: [out[0], out[1], out[2]], dir: [out[3], out[4], out[5]] };
}

/** A table-frame point in the part frame: the frame's 3×4 matrix `m`. */
export function toPart(m, p) {
  return [
    m[0] * p[0] + m[1] * p[1] + m[2] * p[2] + m[3],
    m[4] * p[0] + m[5] * p[1] + m[6] * p[2] + m[7],
    m[8] * p[0] + m[9] * p[1] + m[10] * p[2] + m[11],
  ];
}

/** A table-frame vector in the part frame. */
export function toPartVector(m, v) {
  return [
    m[0] * v[0] + m[1] * v[1] + m[2] * v[2],
    m[4] * v[0] + m[5] * v[1] + m[6] * v[2],
    m[8] * v[0] + m[9] * v[1] + m[10] * v[2],
  ];
}

/**
 * A part-frame point in the table frame: the inverse of the frame's 3×4
 * matrix `m` ([`toPart`]), solved in full (the matrix of a setup error is
 * a rotation, but nothing here relies on it).
 */
export function fromPart(m, p) {
  const [a, b, c, d, e, f, g, h, i] = [m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]];
  const x = p[0] - m[3];
  const y = p[1] - m[7];
  const z = p[2] - m[11];
  const A = e * i - f * h;
  const B = f * g - d * i;
  const C = d * h - e * g;
  const det = a * A + b * B + c * C;
  return [
    (A * x + (c * h - b * i) * y + (b * f - c * e) * z) / det,
    (B * x + (a * i - c * g) * y + (c * d - a * f) * z) / det,
    (C * x + (b * g - a * h) * y + (a * e - b * d) * z) / det,
  ];
}
