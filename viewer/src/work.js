// The machine's bodies, the tool with its holder, the fixtures and the
// stock left, as three.js meshes: the same solids and placements as the
// kernel's (`fiveaxis-machine/src/geometry.rs`, `fiveaxis-stock`).

import {
  BoxGeometry,
  BufferAttribute,
  BufferGeometry,
  CapsuleGeometry,
  Group,
  LatheGeometry,
  Mesh,
  Quaternion,
  SphereGeometry,
  Vector2,
  Vector3,
} from 'three';

const Z = new Vector3(0, 0, 1);
/** Segments around a solid of revolution. */
const ROUND = 40;
/** Points on a quarter circle of a tool's profile. */
const ARC = 10;

/**
 * The map of a solid's placement: the frame's Z along `axis`, turned by
 * `turn` degrees about it, at `at` (`Placement::isometry`).
 */
function place(mesh, solid) {
  const axis = new Vector3(...solid.axis).normalize();
  const up = axis.z < -1 + 1e-12 ? new Quaternion().setFromAxisAngle(new Vector3(1, 0, 0), Math.PI) : new Quaternion().setFromUnitVectors(Z, axis);
  const spin = new Quaternion().setFromAxisAngle(Z, ((solid.turn || 0) * Math.PI) / 180);
  mesh.quaternion.copy(up.multiply(spin));
  mesh.position.set(...solid.at);
  return mesh;
}

/** A solid of revolution about Z from its (radius, height) profile. */
function lathe(profile) {
  const g = new LatheGeometry(
    profile.map(([r, h]) => new Vector2(Math.max(r, 0), h)),
    ROUND,
  );
  // Lathe turns about Y: its Y becomes Z.
  g.rotateX(Math.PI / 2);
  return g;
}

/** The geometry of one solid in its own frame (as `shapes.rs`). */
function solidGeometry(s) {
  switch (s.shape) {
    case 'box':
      return new BoxGeometry(...s.size);
    case 'cylinder':
      return lathe([[0, 0], [s.radius, 0], [s.radius, s.length], [0, s.length]]);
    case 'cone':
      return lathe([[0, 0], [s.bottom, 0], [s.top, s.length], [0, s.length]]);
    case 'sphere':
      return new SphereGeometry(s.radius, ROUND, ROUND / 2);
    case 'capsule': {
      const g = new CapsuleGeometry(s.radius, s.length, 8, ROUND);
      g.rotateX(Math.PI / 2);
      g.translate(0, 0, s.length / 2);
      return g;
    }
    case 'mesh': {
      if (!s.triangles || !s.triangles.length) return null;
      const g = new BufferGeometry();
      g.setAttribute('position', new BufferAttribute(new Float32Array(s.triangles), 3));
      g.computeVertexNormals();
      return g;
    }
    default:
      return null;
  }
}

/** A body of the machine file as a group in its link's frame. */
export function bodyGroup(body, material) {
  const g = new Group();
  g.name = `body-${body.name}`;
  for (const s of body.solids) {
    const geometry = solidGeometry(s);
    if (geometry) g.add(place(new Mesh(geometry, material), s));
  }
  return g;
}

/** The profile of a tool's cutting part, tip up to the flute's end. */
function cutterProfile(tool, flute) {
  const R = tool.radius;
  const arc = (cx, ch, r, from, to) => {
    const out = [];
    for (let k = 0; k <= ARC; k++) {
      const t = from + ((to - from) * k) / ARC;
      out.push([cx + r * Math.sin(t), ch - r * Math.cos(t)]);
    }
    return out;
  };
  switch (tool.cutter) {
    case 'ball':
      return [...arc(0, R, R, 0, Math.PI / 2), [R, Math.max(flute, R)]];
    case 'bull': {
      const c = Math.min(tool.cutter_value, R);
      return [[0, 0], ...arc(R - c, c, c, 0, Math.PI / 2), [R, Math.max(flute, c)]];
    }
    case 'drill': {
      const point = R / Math.tan(((tool.cutter_value / 2) * Math.PI) / 180);
      return [[0, 0], [R, Math.min(point, flute)], [R, flute]];
    }
    case 'taper':
      return [[0, 0], [R, 0], [R + flute * Math.tan((tool.cutter_value * Math.PI) / 180), flute]];
    default:
      return [[0, 0], [R, 0], [R, flute]];
  }
}

/**
 * A tool with its shank and holder (the offsets file's shape) as a group
 * in the head's frame: the tip `length` from the gauge point against the
 * tool direction `t0`, as `fiveaxis-collide` places it.
 */
export function toolGroup(tool, t0, materials) {
  const g = new Group();
  g.name = 'tool-shape';
  const L = tool.length;
  const holderLength = tool.holder.reduce((s, h) => s + h.length, 0);
  const flute = Math.min(tool.flute, Math.max(L - holderLength, 0));
  const parts = [];
  if (flute > 0 && tool.radius > 0) {
    const p = cutterProfile(tool, flute);
    parts.push([[[0, 0], ...p.slice(p[0][0] === 0 ? 1 : 0), [0, p[p.length - 1][1]]], materials.cutter, 'cutter']);
  }
  const shankLength = L - holderLength - flute;
  if (shankLength > 0 && tool.shank > 0) {
    const r = tool.shank / 2;
    parts.push([[[0, flute], [r, flute], [r, flute + shankLength], [0, flute + shankLength]], materials.shank, 'shank']);
  }
  let top = L;
  for (const h of tool.holder) {
    const bottom = top - h.length;
    parts.push([[[0, bottom], [h.tip_diameter / 2, bottom], [h.diameter / 2, top], [0, top]], materials.holder, 'holder']);
    top = bottom;
  }
  const axis = new Vector3(...t0).normalize();
  for (const [profile, material, name] of parts) {
    const mesh = new Mesh(lathe(profile), material);
    mesh.name = name;
    mesh.quaternion.copy(new Quaternion().setFromUnitVectors(Z, axis));
    mesh.position.copy(axis.clone().multiplyScalar(-L));
    g.add(mesh);
  }
  return g;
}

/**
 * The fixtures in the table frame: boxes by their corners, meshes by
 * their range in the flat array of triangle vertices.
 */
export function fixtureGroup(fixtures, triangles, material) {
  const g = new Group();
  g.name = 'fixtures';
  for (const f of fixtures) {
    let mesh;
    if (f.min) {
      const size = [0, 1, 2].map((k) => f.max[k] - f.min[k]);
      mesh = new Mesh(new BoxGeometry(...size), material);
      mesh.position.set(...[0, 1, 2].map((k) => (f.max[k] + f.min[k]) / 2));
    } else {
      const geometry = new BufferGeometry();
      geometry.setAttribute('position', new BufferAttribute(triangles.slice(9 * f.first, 9 * (f.first + f.count)), 3));
      geometry.computeVertexNormals();
      mesh = new Mesh(geometry, material);
    }
    mesh.name = `fixture-${f.name}`;
    g.add(mesh);
  }
  return g;
}

/**
 * The stock along the run (`view --stock`): the cells' tops at the start
 * and, per snapshot (`model.snapshots`: the last block it includes and
 * the end of its changes), the cells that changed. `at(t)` gives the
 * tops at time `t` when they differ from the ones it gave last.
 */
export class StockTimeline {
  constructor(model, start, cells, values, ends) {
    this.start = start;
    this.cells = cells;
    this.values = values;
    const snapshots = model.snapshots || [];
    this.times = snapshots.map(([block]) => ends[Math.min(block, ends.length - 1)] ?? 0);
    this.ends = snapshots.map(([, end]) => end);
    this.tops = Float32Array.from(start);
    // Snapshots applied to `tops`.
    this.applied = 0;
    this.shown = -1;
  }

  /** How many snapshots were taken by time `t`. */
  countAt(t) {
    let lo = 0;
    let hi = this.times.length;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (this.times[mid] <= t) lo = mid + 1;
      else hi = mid;
    }
    return lo;
  }

  /** The tops at time `t`, or null when they are the ones last given. */
  at(t) {
    const n = this.countAt(t);
    if (n === this.shown) return null;
    if (n < this.applied) {
      this.tops.set(this.start);
      this.applied = 0;
    }
    const from = this.applied ? this.ends[this.applied - 1] : 0;
    const to = n ? this.ends[n - 1] : 0;
    for (let e = from; e < to; e++) this.tops[this.cells[e]] = this.values[e];
    this.applied = n;
    this.shown = n;
    return this.tops;
  }
}

/**
 * The stock, from its cells' highest material (`tops`, NaN where none is
 * left) down to its base: each cell's top, and walls where a neighbour
 * stands lower.
 */
export function stockMesh(model, tops, material) {
  const mesh = new Mesh(stockGeometry(model, tops), material);
  mesh.name = 'stock-left';
  return mesh;
}

/** The geometry of `stockMesh`. */
export function stockGeometry(model, tops) {
  const { nx, ny, cell, base } = model;
  const [ox, oy] = model.origin;
  const positions = [];
  const quad = (a, b, c, d) => positions.push(...a, ...b, ...c, ...a, ...c, ...d);
  const top = (i, j) => (i < 0 || j < 0 || i >= nx || j >= ny ? NaN : tops[j * nx + i]);
  for (let j = 0; j < ny; j++) {
    for (let i = 0; i < nx; i++) {
      const z = top(i, j);
      if (Number.isNaN(z)) continue;
      const x0 = ox + i * cell;
      const y0 = oy + j * cell;
      const x1 = x0 + cell;
      const y1 = y0 + cell;
      quad([x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]);
      // Walls down to the neighbour (or the base), facing out.
      const low = (n) => (Number.isNaN(n) ? base : n);
      const w = low(top(i - 1, j));
      if (w < z) quad([x0, y1, w], [x0, y0, w], [x0, y0, z], [x0, y1, z]);
      const e = low(top(i + 1, j));
      if (e < z) quad([x1, y0, e], [x1, y1, e], [x1, y1, z], [x1, y0, z]);
      const s = low(top(i, j - 1));
      if (s < z) quad([x0, y0, s], [x1, y0, s], [x1, y0, z], [x0, y0, z]);
      const n = low(top(i, j + 1));
      if (n < z) quad([x1, y1, n], [x0, y1, n], [x0, y1, z], [x1, y1, z]);
    }
  }
  const geometry = new BufferGeometry();
  geometry.setAttribute('position', new BufferAttribute(new Float32Array(positions), 3));
  geometry.computeVertexNormals();
  return geometry;
}
