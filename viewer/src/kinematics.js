// Forward kinematics of the machine model (machine-model.md §1–3), the
// same maps the kernel applies (crates/fiveaxis-machine/src/kinematics.rs):
// a rotary axis turns what it carries by the right-hand rule about the line
// through `center` along `axis`; head axes act on coordinates relative to
// the spindle gauge point, table axes on machine coordinates; both chains
// are listed from the bed outwards.

/** `v` turned about the unit vector `k` by `deg` degrees (Rodrigues). */
export function turn(k, v, deg) {
  const a = (deg * Math.PI) / 180;
  const s = Math.sin(a);
  const c = Math.cos(a);
  const kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
  const x = k[1] * v[2] - k[2] * v[1];
  const y = k[2] * v[0] - k[0] * v[2];
  const z = k[0] * v[1] - k[1] * v[0];
  return [
    v[0] * c + x * s + k[0] * kv * (1 - c),
    v[1] * c + y * s + k[1] * kv * (1 - c),
    v[2] * c + z * s + k[2] * kv * (1 - c),
  ];
}

/** The point `p` turned about the line through `c` along `k`. */
export function turnAbout(k, c, p, deg) {
  const r = turn(k, [p[0] - c[0], p[1] - c[1], p[2] - c[2]], deg);
  return [c[0] + r[0], c[1] + r[1], c[2] + r[2]];
}

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
 * Tool tip and direction in the table frame for machine positions `joints`
 * (X, Y, Z first, then the rotary axes bed outwards) and tool length `L`:
 * tip_machine = XYZ + H(−L·t0), dir = R_H·t0, then T⁻¹ of both.
 */
export function forward(machine, joints, L) {
  const t0 = machine.toolDirection;
  let tip = [-L * t0[0], -L * t0[1], -L * t0[2]];
  let dir = t0;
  const rot = machine.rotary;
  for (let k = rot.length - 1; k >= 0; k--) {
    const r = rot[k];
    if (r.on === 'head') {
      const deg = joints[r.index];
      tip = turnAbout(r.axis, r.center, tip, deg);
      dir = turn(r.axis, dir, deg);
    }
  }
  tip = [tip[0] + joints[0], tip[1] + joints[1], tip[2] + joints[2]];
  for (let k = 0; k < rot.length; k++) {
    const r = rot[k];
    if (r.on === 'table') {
      const deg = -joints[r.index];
      tip = turnAbout(r.axis, r.center, tip, deg);
      dir = turn(r.axis, dir, deg);
    }
  }
  return { tip, dir };
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
