// The 3-D scene, in the machine frame (Z up): a fixed bed; the table
// chain (one group per table rotary axis, nested bed outwards) carrying the
// table, the workpiece zero and the tool path; the head (translated by X,
// Y, Z, one group per head rotary axis) carrying the spindle and the tool.
// Every group turns about its axis' real line by the angle of its axis, so
// the bodies move as forward kinematics says (machine-model.md §3).

import {
  AmbientLight,
  AxesHelper,
  Box3,
  BoxGeometry,
  BufferAttribute,
  BufferGeometry,
  Color,
  CylinderGeometry,
  DirectionalLight,
  DoubleSide,
  Group,
  Line,
  LineBasicMaterial,
  LineSegments,
  Matrix4,
  Mesh,
  MeshLambertMaterial,
  Object3D,
  PerspectiveCamera,
  Points,
  PointsMaterial,
  Quaternion,
  Raycaster,
  Scene,
  SphereGeometry,
  Vector2,
  Vector3,
  WebGLRenderer,
} from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { MOTIONS, stockCorners } from './data.js';
import { simplifyToSpacing } from './simplify.js';
import { StockTimeline, bodyGroup, fixtureGroup, stockGeometry, stockMesh, toolGroup } from './work.js';

/** Colours of the path by motion: rapid, linear feed, arcs. */
export const MOTION_COLOURS = { rapid: '#e8554e', linear: '#3fb950', cw: '#58a6ff', ccw: '#58a6ff' };
const SELECTED_COLOUR = '#ffd33d';
/** Tool-axis ticks drawn along the path, at most. */
const TOOL_AXIS_TICKS = 400;
/**
 * Drawn path vertices above which a coarser path (every k-th vertex, at
 * most this many) is drawn while the camera moves and at the first frame;
 * the whole path is drawn once the camera has rested `REST_MS`.
 */
export const COARSE_VERTICES = 10000;
const REST_MS = 250;
/**
 * The path at rest is drawn simplified to the pixel: levels whose points
 * are at least `pathSize / PIXEL_LEVEL_FINEST · 2^k` apart (k = 0, 1, …,
 * `PIXEL_LEVELS − 1`, each made from the one before, so a level's drawing
 * is within twice its spacing of the whole path), and the one drawn is the
 * coarsest whose spacing is below half a pixel at the camera's target:
 * within a pixel of the whole path. A level is kept only where it leaves
 * out at least `PIXEL_LEVEL_GAIN` of the finer one's vertices.
 */
const PIXEL_LEVEL_FINEST = 8192;
const PIXEL_LEVELS = 6;
const PIXEL_LEVEL_GAIN = 0.2;

/** Finding markers drawn, at most, with the coarse path (every k-th). */
export const COARSE_MARKERS = 3000;
/** Path vertices the picking ray must come this close to, pixels. */
const PICK_PIXELS = 6;

const UP = new Vector3(0, 1, 0);

/** The declared stock: a light neutral box seen through, and its edges. */
const STOCK_FILL = { color: '#cfd4da', opacity: 0.12 };
const STOCK_EDGE = { color: '#e6e9ed', opacity: 0.55 };
/** The faces of a box by its corners (`stockCorners`: bit 0, 1, 2 = max in X, Y, Z), wound outwards. */
const BOX_FACES = [
  [0, 2, 3, 1], [4, 5, 7, 6], // −Z, +Z
  [0, 1, 5, 4], [2, 6, 7, 3], // −Y, +Y
  [0, 4, 6, 2], [1, 3, 7, 5], // −X, +X
];

/**
 * The stock box from its 8 table-frame corners: translucent faces and
 * their 12 edges, neither writing depth, so the path shows through.
 */
export function stockObject(corners) {
  const group = new Group();
  group.name = 'stock';
  group.userData.declared = true;
  const tri = [];
  for (const [a, b, c, d] of BOX_FACES) for (const k of [a, b, c, a, c, d]) tri.push(...corners[k]);
  const fg = new BufferGeometry();
  fg.setAttribute('position', new BufferAttribute(new Float32Array(tri), 3));
  fg.computeVertexNormals();
  const faces = new Mesh(fg, new MeshLambertMaterial({ ...STOCK_FILL, transparent: true, depthWrite: false, side: DoubleSide }));
  faces.name = 'stock-faces';
  const edges = [];
  for (let k = 0; k < 8; k++) for (const bit of [1, 2, 4]) if (!(k & bit)) edges.push(...corners[k], ...corners[k | bit]);
  const eg = new BufferGeometry();
  eg.setAttribute('position', new BufferAttribute(new Float32Array(edges), 3));
  const lines = new LineSegments(eg, new LineBasicMaterial({ ...STOCK_EDGE, transparent: true, depthWrite: false }));
  lines.name = 'stock-edges';
  group.add(faces, lines);
  return group;
}

/** A group turning about the line through `center` along `axis`. */
function rotaryGroup(axis, center) {
  const g = new Group();
  g.matrixAutoUpdate = false;
  g.userData = { axis: new Vector3(...axis).normalize(), center: new Vector3(...center) };
  return g;
}

/** Sets a rotary group to `deg`: T(c)·R(a, deg)·T(−c). */
function setRotary(g, deg) {
  const { axis, center } = g.userData;
  const r = new Matrix4().makeRotationAxis(axis, (deg * Math.PI) / 180);
  const m = new Matrix4().makeTranslation(center.x, center.y, center.z);
  m.multiply(r);
  m.multiply(new Matrix4().makeTranslation(-center.x, -center.y, -center.z));
  g.matrix.copy(m);
  g.matrixWorldNeedsUpdate = true;
}

/** A cylinder from `from` along `dir` for `length`, radius `r`. */
function cylinder(from, dir, length, r, material) {
  const geometry = new CylinderGeometry(r, r, Math.max(length, 1e-3), 32);
  const mesh = new Mesh(geometry, material);
  const d = new Vector3(...dir).normalize();
  mesh.quaternion.copy(new Quaternion().setFromUnitVectors(UP, d));
  mesh.position.copy(new Vector3(...from).addScaledVector(d, length / 2));
  return mesh;
}

/** A box of size `size` whose centre is `at`. */
function box(size, at, material) {
  const mesh = new Mesh(new BoxGeometry(...size), material);
  mesh.position.set(...at);
  return mesh;
}

/**
 * Whether the browser draws WebGL in software (SwiftShader, llvmpipe: no
 * GPU, as in a virtual machine or a headless test): there antialiasing
 * multiplies the cost of every frame, so the scene goes without it.
 */
export function softwareRenderer() {
  const gl = document.createElement('canvas').getContext('webgl');
  if (!gl) return false;
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
  const lose = gl.getExtension('WEBGL_lose_context');
  if (lose) lose.loseContext();
  return /swiftshader|llvmpipe|softpipe|software/i.test(name);
}

export class MachineScene {
  constructor(canvasParent, data) {
    this.data = data;
    const machine = data.machine;
    this.software = softwareRenderer();
    this.renderer = new WebGLRenderer({ antialias: !this.software, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.setClearColor(new Color('#161b22'));
    canvasParent.appendChild(this.renderer.domElement);
    this.parent = canvasParent;
    this.scene = new Scene();
    this.scene.add(new AmbientLight(0xffffff, 1.2));
    const sun = new DirectionalLight(0xffffff, 1.8);
    sun.position.set(1, -2, 3);
    this.scene.add(sun);

    const lin = machine.linear;
    const span = (i) => (lin[i] ? Math.abs(lin[i].max - lin[i].min) : 500);
    // The size of things: from the machine's strokes and the path.
    const bb = data.bbox;
    const pathSize = bb ? Math.max(bb.max[0] - bb.min[0], bb.max[1] - bb.min[1], bb.max[2] - bb.min[2], 1) : 100;
    this.pathSize = pathSize;
    // The declared stock (BLK FORM), in the table frame.
    const corners = stockCorners(data.meta);
    const stockSize = corners ? Math.max(...[0, 1].map((k) => Math.max(...corners.map((c) => c[k])) - Math.min(...corners.map((c) => c[k])))) : 0;
    const tableRadius = Math.min(Math.max(0.6 * pathSize, 0.6 * stockSize, 50), Math.max(0.3 * Math.min(span(0), span(1)), 50));
    this.sizes = { tableRadius, pathSize };

    const mat = (c) => new MeshLambertMaterial({ color: c });
    const bedMat = mat('#4a5361');
    const tableMat = mat('#7a8ca3');
    const cradleMat = mat('#6b7f99');
    const headMat = mat('#d08c3c');
    const spindleMat = mat('#b8bcc4');
    this.toolMat = mat('#f2f2f2');
    this.toolMats = { cutter: mat('#f2f2f2'), shank: mat('#9aa0a8'), holder: mat('#5b6270') };
    // The machine file's bodies, where it has them, instead of the
    // generic table, cradle, bed and head drawn from the strokes.
    const bodies = machine.bodies || [];
    const hasBodies = bodies.length > 0;

    // Table chain, bed outwards.
    this.tableGroups = [];
    let carrier = this.scene;
    const tables = machine.rotary.filter((r) => r.on === 'table');
    for (const r of machine.rotary.filter((x) => x.on === 'table')) {
      const g = rotaryGroup(r.axis, r.center);
      g.userData.index = r.index;
      g.name = `table-${r.name}`;
      carrier.add(g);
      carrier = g;
      this.tableGroups.push(g);
    }
    this.tableInner = carrier === this.scene ? new Group() : carrier;
    if (this.tableInner.parent == null) this.scene.add(this.tableInner);
    this.tableInner.name = this.tableInner.name || 'table';

    // The table top below the lowest point of the path.
    const low = bb ? Math.min(bb.min[2], 0) : 0;
    // The stock sits on the table: the table top below it too.
    const topZ = Math.min(this.pathLowZ(data, low), ...(corners ? corners.map((c) => c[2]) : [])) - 1;
    const thick = 0.15 * tableRadius;
    const table = cylinder([0, 0, topZ - thick], [0, 0, 1], thick, tableRadius, tableMat);
    const tableCenter = tables.length ? tables[tables.length - 1].center : [0, 0, 0];
    table.position.x += tableCenter[0];
    table.position.y += tableCenter[1];
    if (!hasBodies) this.tableInner.add(table);
    // The outer table axis of a trunnion: a cradle along its line.
    if (tables.length === 2 && !hasBodies) {
      const outer = tables[0];
      const g = this.tableGroups[0];
      const a = outer.axis;
      const c = outer.center;
      const half = tableRadius * 1.25;
      for (const s of [-1, 1]) {
        const end = [c[0] + s * half * a[0], c[1] + s * half * a[1], c[2] + s * half * a[2]];
        g.add(cylinder(end, [s * a[0], s * a[1], s * a[2]], 0.2 * tableRadius, 0.35 * tableRadius, cradleMat));
      }
      const floor = topZ - thick - 0.6 * thick;
      const along = new Vector3(...a).normalize();
      const size = [
        Math.abs(along.x) * 2 * half + (1 - Math.abs(along.x)) * 1.6 * tableRadius,
        Math.abs(along.y) * 2 * half + (1 - Math.abs(along.y)) * 1.6 * tableRadius,
        0.6 * thick,
      ];
      g.add(box(size, [c[0], c[1], floor], cradleMat));
    }
    // The workpiece zero of the first frame, and the path.
    this.buildPath(data);
    // The stock: the one the program declares (BLK FORM), else the box
    // the cutting moves span, seen through; carried by the table axes.
    this.stock = null;
    const cut = corners ? null : this.cutBox(data);
    if (corners) {
      this.stock = stockObject(corners);
      this.tableInner.add(this.stock);
    } else if (cut) {
      const size = [0, 1, 2].map((k) => Math.max(cut.max[k] - cut.min[k], 0.5));
      const stock = box(size, [0, 1, 2].map((k) => (cut.max[k] + cut.min[k]) / 2), new MeshLambertMaterial({ color: '#c9a86a', transparent: true, opacity: 0.18, depthWrite: false }));
      stock.name = 'stock';
      this.tableInner.add(stock);
      this.stock = stock;
    }
    // The bed: fixed, under everything.
    const bedZ = topZ - thick - 2 * thick - (tables.length === 2 ? tableRadius : 0);
    if (!hasBodies) this.scene.add(box([Math.max(span(0), 2.5 * tableRadius), Math.max(span(1), 2.5 * tableRadius), thick], [tableCenter[0], tableCenter[1], bedZ], bedMat));

    // Head: X, Y, Z move the gauge point; head axes turn about their lines.
    this.carriage = new Group();
    this.carriage.name = 'head';
    this.scene.add(this.carriage);
    this.headGroups = [];
    carrier = this.carriage;
    const t0 = machine.toolDirection;
    for (const r of machine.rotary.filter((x) => x.on === 'head')) {
      const g = rotaryGroup(r.axis, r.center);
      g.userData.index = r.index;
      g.name = `head-${r.name}`;
      // The housing of the axis around its centre.
      if (!hasBodies) g.add(box([0.5 * tableRadius, 0.5 * tableRadius, 0.5 * tableRadius], r.center, headMat));
      carrier.add(g);
      carrier = g;
      this.headGroups.push(g);
    }
    this.spindle = carrier;
    const spindleR = Math.max(0.12 * tableRadius, 15);
    if (!hasBodies) this.spindle.add(cylinder([0, 0, 0], t0, 2.5 * spindleR, spindleR, spindleMat));
    if (this.headGroups.length === 0 && !hasBodies) {
      this.spindle.add(box([3 * spindleR, 3 * spindleR, 3 * spindleR], [t0[0] * 4 * spindleR, t0[1] * 4 * spindleR, t0[2] * 4 * spindleR], headMat));
    }
    // Each body on its link: the bed, a carriage (moved by its own axis),
    // a rotary axis' group, the head.
    this.linearGroups = [];
    const nLinear = machine.linear.length;
    for (const body of bodies) {
      const on = body.on;
      let carrier2 = this.scene;
      let material = bedMat;
      if (on === 'head') {
        carrier2 = this.spindle;
        material = headMat;
      } else if (typeof on === 'number' && on < nLinear) {
        let g = this.linearGroups.find((x) => x.userData.linear === on);
        if (!g) {
          g = new Group();
          g.name = `carriage-${machine.linear[on].name}`;
          g.userData.linear = on;
          this.scene.add(g);
          this.linearGroups.push(g);
        }
        carrier2 = g;
        material = headMat;
      } else if (typeof on === 'number') {
        const g = [...this.tableGroups, ...this.headGroups].find((x) => x.userData.index === on);
        if (g) carrier2 = g;
        material = this.headGroups.includes(g) ? headMat : tableMat;
      }
      carrier2.add(bodyGroup(body, material));
    }
    // The fixtures and the stock left ride on the table.
    const work = data.work;
    if (work && work.fixtures.length) {
      this.tableInner.add(fixtureGroup(work.fixtures, work.triangles, mat('#8a6d5a')));
    }
    // The stock model: as cut by the time the slider is at (`stockAt`).
    this.stockTimeline = null;
    if (work && work.stockModel) {
      if (this.stock) this.tableInner.remove(this.stock);
      this.stockTimeline = new StockTimeline(work.stockModel, work.stockTops, work.stockCells, work.stockValues, data.ends);
      this.stock = stockMesh(work.stockModel, work.stockTops, mat('#c9a86a'));
      this.tableInner.add(this.stock);
    }
    this.tool = null;
    this.toolTip = new Object3D();
    this.toolTip.name = 'tool-tip';
    this.spindle.add(this.toolTip);
    this.tipMarker = new Mesh(new SphereGeometry(Math.max(0.008 * pathSize, 0.5), 16, 12), new MeshLambertMaterial({ color: '#ffffff' }));
    this.scene.add(this.tipMarker);

    this.camera = new PerspectiveCamera(40, 1, 0.1, 1e6);
    this.camera.up.set(0, 0, 1);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.requestRender());
    // Coarse while the camera moves, whole once it rests.
    this.controls.addEventListener('start', () => this.moving());
    this.controls.addEventListener('end', () => this.rest());
    this.raycaster = new Raycaster();
    this.resize();
    new ResizeObserver(() => this.resize()).observe(canvasParent);
    this.view('iso');
  }

  /**
   * The lowest table-frame Z of the cutting moves (the stock sits on the
   * table), or of the whole path when nothing cuts, or `fallback`.
   */
  pathLowZ(data, fallback) {
    const b = this.cutBox(data);
    return b ? b.min[2] : fallback;
  }

  /** Table-frame box of the cutting (non-rapid) vertices, or of all. */
  cutBox(data) {
    const { tips, vertexBlock, motions } = data;
    const n = tips.length / 3;
    const lo = [Infinity, Infinity, Infinity];
    const hi = [-Infinity, -Infinity, -Infinity];
    for (const cutOnly of [true, false]) {
      for (let i = 0; i < n; i++) {
        if (cutOnly && motions[vertexBlock[i]] === 0) continue;
        for (let k = 0; k < 3; k++) {
          const v = tips[3 * i + k];
          if (v < lo[k]) lo[k] = v;
          if (v > hi[k]) hi[k] = v;
        }
      }
      if (Number.isFinite(lo[0])) return { min: lo, max: hi };
    }
    return null;
  }

  /** The path in the table frame, coloured by motion, with tool-axis ticks. */
  buildPath(data) {
    const { tips, dirs, vertexBlock, motions } = data;
    const n = tips.length / 3;
    const colours = Object.fromEntries(MOTIONS.map((m) => [m, new Color(MOTION_COLOURS[m])]));
    // The segment from vertex i−1 to i has the motion of vertex i's block;
    // a vertex where the motion changes is drawn twice, once in each colour.
    let extra = 0;
    for (let i = 2; i < n; i++) if (motions[vertexBlock[i]] !== motions[vertexBlock[i - 1]]) extra++;
    const count = n + extra;
    const pos = new Float32Array(3 * count);
    const col = new Float32Array(3 * count);
    this.drawnToVertex = new Uint32Array(count);
    let k = 0;
    const put = (i, c) => {
      pos[3 * k] = tips[3 * i];
      pos[3 * k + 1] = tips[3 * i + 1];
      pos[3 * k + 2] = tips[3 * i + 2];
      col[3 * k] = c.r;
      col[3 * k + 1] = c.g;
      col[3 * k + 2] = c.b;
      this.drawnToVertex[k] = i;
      k++;
    };
    for (let i = 0; i < n; i++) {
      const m = MOTIONS[motions[vertexBlock[Math.min(i + 1, n - 1)]]] || 'linear';
      const here = MOTIONS[motions[vertexBlock[i]]] || 'linear';
      put(i, colours[i === 0 ? m : here]);
      if (i > 0 && i < n - 1 && m !== here) put(i, colours[m]);
    }
    const geometry = new BufferGeometry();
    geometry.setAttribute('position', new BufferAttribute(pos, 3));
    geometry.setAttribute('color', new BufferAttribute(col, 3));
    geometry.computeBoundingSphere();
    this.path = new Line(geometry, new LineBasicMaterial({ vertexColors: true }));
    this.path.name = 'path';
    this.tableInner.add(this.path);
    // The path to the pixel: levels over the same vertex buffers, by index.
    this.pixelLevels = [];
    if (count > 2) {
      let from = new Uint32Array(count);
      for (let i = 0; i < count; i++) from[i] = i;
      let kept = count;
      for (let k = 0; k < PIXEL_LEVELS; k++) {
        const spacing = (this.pathSize / PIXEL_LEVEL_FINEST) * 2 ** k;
        const index = simplifyToSpacing(pos, col, from, spacing);
        from = index;
        if (index.length > (1 - PIXEL_LEVEL_GAIN) * kept) continue;
        kept = index.length;
        const lg = new BufferGeometry();
        lg.setAttribute('position', geometry.getAttribute('position'));
        lg.setAttribute('color', geometry.getAttribute('color'));
        lg.setIndex(new BufferAttribute(index, 1));
        lg.boundingSphere = geometry.boundingSphere;
        const line = new Line(lg, this.path.material);
        line.name = `path-pixel-${k}`;
        line.visible = false;
        this.tableInner.add(line);
        this.pixelLevels.push({ spacing, line, vertices: index.length });
      }
    }
    // The coarse path: the same vertex buffers, every k-th vertex by index.
    this.coarse = null;
    if (count > COARSE_VERTICES) {
      const every = Math.ceil(count / COARSE_VERTICES);
      const index = new Uint32Array(Math.ceil(count / every) + 1);
      let m = 0;
      for (let i = 0; i < count; i += every) index[m++] = i;
      if (index[m - 1] !== count - 1) index[m++] = count - 1;
      const cg = new BufferGeometry();
      cg.setAttribute('position', geometry.getAttribute('position'));
      cg.setAttribute('color', geometry.getAttribute('color'));
      cg.setIndex(new BufferAttribute(index.subarray(0, m), 1));
      cg.boundingSphere = geometry.boundingSphere;
      this.coarse = new Line(cg, this.path.material);
      this.coarse.name = 'path-coarse';
      this.tableInner.add(this.coarse);
    }
    this.setDetail(!this.coarse);

    // Tool-axis ticks at intervals.
    const every = Math.max(1, Math.ceil(n / TOOL_AXIS_TICKS));
    const len = 0.04 * this.pathSize;
    const ticks = [];
    for (let i = 0; i < n; i += every) {
      const p = [tips[3 * i], tips[3 * i + 1], tips[3 * i + 2]];
      ticks.push(...p, p[0] + len * dirs[3 * i], p[1] + len * dirs[3 * i + 1], p[2] + len * dirs[3 * i + 2]);
    }
    const tg = new BufferGeometry();
    tg.setAttribute('position', new BufferAttribute(new Float32Array(ticks), 3));
    this.ticks = new LineSegments(tg, new LineBasicMaterial({ color: '#8b949e', transparent: true, opacity: 0.7 }));
    this.ticks.name = 'tool-axis';
    this.tableInner.add(this.ticks);

    // The selected line's blocks.
    const sg = new BufferGeometry();
    sg.setAttribute('position', new BufferAttribute(new Float32Array(0), 3));
    this.selected = new LineSegments(sg, new LineBasicMaterial({ color: SELECTED_COLOUR, depthTest: false }));
    this.selected.renderOrder = 2;
    this.tableInner.add(this.selected);

    // The workpiece zero of the first frame: the part frame's axes.
    const f = data.meta.frames[0];
    if (f) {
      const m = f.to_part;
      // Part origin in table coordinates: solve R·x + o = 0, R orthonormal.
      const o = [m[3], m[7], m[11]];
      const origin = [
        -(m[0] * o[0] + m[4] * o[1] + m[8] * o[2]),
        -(m[1] * o[0] + m[5] * o[1] + m[9] * o[2]),
        -(m[2] * o[0] + m[6] * o[1] + m[10] * o[2]),
      ];
      const axes = new AxesHelper(0.15 * this.pathSize);
      axes.position.set(...origin);
      this.tableInner.add(axes);
    }

    this.markers = new Group();
    this.markers.name = 'findings';
    this.tableInner.add(this.markers);
  }

  /** Shows or hides the stock; whether there is one. */
  setStockVisible(on) {
    if (!this.stock) return false;
    this.stock.visible = on;
    this.requestRender();
    return true;
  }

  /** The stock model as cut by time `t` (nothing to do without one, or when unchanged). */
  stockAt(t) {
    const tops = this.stockTimeline && this.stockTimeline.at(t);
    if (!tops) return;
    const old = this.stock.geometry;
    this.stock.geometry = stockGeometry(this.data.work.stockModel, tops);
    old.dispose();
    this.requestRender();
  }

  /** Draws the blocks (vertex ranges `[from, to]`) of the selected line. */
  select(ranges) {
    const tips = this.data.tips;
    const pts = [];
    for (const [from, to] of ranges) {
      for (let i = from + 1; i <= to; i++) {
        pts.push(tips[3 * i - 3], tips[3 * i - 2], tips[3 * i - 1], tips[3 * i], tips[3 * i + 1], tips[3 * i + 2]);
        if (pts.length > 6e6) break;
      }
    }
    this.selected.geometry.setAttribute('position', new BufferAttribute(new Float32Array(pts), 3));
    this.selected.geometry.computeBoundingSphere();
    this.requestRender();
  }

  /**
   * Finding markers: one point each (a few pixels, whatever the zoom) at
   * the table-frame points `at` (x, y, z each), coloured by severity
   * (0 error, 1 warning, 2 info). One draw call for any number.
   */
  setMarkers(at, severities) {
    this.markers.clear();
    if (!severities.length) return;
    const palette = [new Color('#f85149'), new Color('#d29922'), new Color('#58a6ff')];
    const col = new Float32Array(3 * severities.length);
    for (let k = 0; k < severities.length; k++) {
      const c = palette[severities[k]] || palette[1];
      col[3 * k] = c.r;
      col[3 * k + 1] = c.g;
      col[3 * k + 2] = c.b;
    }
    const g = new BufferGeometry();
    g.setAttribute('position', new BufferAttribute(at, 3));
    g.setAttribute('color', new BufferAttribute(col, 3));
    const material = new PointsMaterial({ size: 9, sizeAttenuation: false, vertexColors: true });
    this.markerPoints = new Points(g, material);
    this.markerPoints.renderOrder = 1;
    this.markers.add(this.markerPoints);
    this.coarseMarkers = null;
    const n = severities.length;
    if (n > COARSE_MARKERS) {
      const every = Math.ceil(n / COARSE_MARKERS);
      const index = new Uint32Array(Math.ceil(n / every));
      for (let k = 0, m = 0; k < n; k += every) index[m++] = k;
      const cg = new BufferGeometry();
      cg.setAttribute('position', g.getAttribute('position'));
      cg.setAttribute('color', g.getAttribute('color'));
      cg.setIndex(new BufferAttribute(index, 1));
      this.coarseMarkers = new Points(cg, material);
      this.coarseMarkers.renderOrder = 1;
      this.markers.add(this.coarseMarkers);
    }
    this.setDetail(!!this.detail && !this.coarseMarkers);
  }

  /** Puts every body where the machine position `joints` and tool say. */
  pose(joints, tool) {
    for (const g of this.tableGroups) setRotary(g, joints[g.userData.index]);
    this.carriage.position.set(joints[0], joints[1], joints[2]);
    for (const g of this.headGroups) setRotary(g, joints[g.userData.index]);
    for (const g of this.linearGroups) g.position.setComponent(g.userData.linear, joints[g.userData.linear]);
    const t0 = this.data.machine.toolDirection;
    const shape = this.data.work && this.data.work.tools[String(tool.tool)];
    const key = shape ? `T${tool.tool}` : `${tool.tool_length}/${tool.tool_radius}`;
    if (this.toolKey !== key) {
      if (this.tool) this.spindle.remove(this.tool);
      const L = tool.tool_length;
      // The tool's own shape and length where the offsets file gives it;
      // else a cylinder of the length offset in force.
      this.tool = shape ? toolGroup(shape, t0, this.toolMats) : cylinder([-L * t0[0], -L * t0[1], -L * t0[2]], t0, Math.max(L, 1e-3), tool.tool_radius, this.toolMat);
      this.tool.name = 'tool';
      this.spindle.add(this.tool);
      this.toolKey = key;
    }
    const L = tool.tool_length;
    this.toolTip.position.set(-L * t0[0], -L * t0[1], -L * t0[2]);
    this.scene.updateMatrixWorld(true);
    this.tipMarker.position.setFromMatrixPosition(this.toolTip.matrixWorld);
    this.requestRender();
  }

  /**
   * The work drawn (the machine's bodies, the tool's parts, the fixtures,
   * the stock left) by name, with each one's box in the machine frame as
   * the bodies stand.
   */
  workSummary() {
    this.scene.updateMatrixWorld(true);
    const out = {};
    this.scene.traverse((o) => {
      if (o.name && /^(body-|fixture-|stock-left$|cutter$|shank$|holder$)/.test(o.name)) {
        const b = new Box3().setFromObject(o);
        out[o.name] = { min: b.min.toArray(), max: b.max.toArray() };
      }
    });
    return out;
  }

  /** The tool tip as the bodies stand: in the machine frame and in the table frame. */
  probe() {
    this.scene.updateMatrixWorld(true);
    const world = new Vector3().setFromMatrixPosition(this.toolTip.matrixWorld);
    const table = world.clone().applyMatrix4(new Matrix4().copy(this.tableInner.matrixWorld).invert());
    const matrices = {};
    for (const g of [...this.tableGroups, ...this.headGroups, this.carriage]) matrices[g.name] = Array.from(g.matrixWorld.elements);
    return { world: world.toArray(), table: table.toArray(), matrices };
  }

  /** The path's world-frame bounding box as the table stands. */
  pathBox() {
    const g = this.path.geometry;
    g.computeBoundingBox();
    const b = g.boundingBox.clone().applyMatrix4(this.tableInner.matrixWorld);
    return b;
  }

  /** Views along the axes (`+x`, `-x`, `+y`, `-y`, `+z`, `-z`) or `iso`, then fit. */
  view(name) {
    const dirs = {
      '+x': [1, 0, 0], '-x': [-1, 0, 0], '+y': [0, 1, 0], '-y': [0, -1, 0],
      '+z': [0, 0, 1], '-z': [0, 0, -1], iso: [1, -1.2, 0.9],
    };
    this.viewDir = new Vector3(...(dirs[name] || dirs.iso)).normalize();
    this.camera.up.set(0, 0, 1);
    if (Math.abs(this.viewDir.z) > 0.99) this.camera.up.set(0, 1, 0);
    this.fit();
  }

  /** Fits the camera to the path, looking along the current view direction. */
  fit() {
    // A jump of the camera: coarse at once, whole after the rest.
    this.moving();
    this.rest();
    const b = this.pathBox();
    const centre = b.getCenter(new Vector3());
    const radius = Math.max(b.getSize(new Vector3()).length() / 2, 1);
    const dist = radius / Math.sin((this.camera.fov * Math.PI) / 360) * 1.1;
    this.camera.position.copy(centre).addScaledVector(this.viewDir, dist);
    this.camera.near = dist / 1000;
    this.camera.far = dist * 1000;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(centre);
    this.controls.update();
    this.requestRender();
  }

  /** The end vertex of the path segment under the pointer (client coordinates), or -1. */
  pick(clientX, clientY) {
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
    this.raycaster.setFromCamera(ndc, this.camera);
    const dist = this.camera.position.distanceTo(this.controls.target);
    const worldPerPixel = (2 * dist * Math.tan((this.camera.fov * Math.PI) / 360)) / rect.height;
    this.raycaster.params.Line.threshold = PICK_PIXELS * worldPerPixel;
    const hits = this.raycaster.intersectObject(this.path, false);
    if (!hits.length) return -1;
    // The segment hit is drawn by the block of its end vertex.
    const end = hits[0].index + 1;
    return this.drawnToVertex[Math.min(end, this.drawnToVertex.length - 1)];
  }

  /** Client coordinates of path vertex `i` as drawn now. */
  screenOf(i) {
    const p = new Vector3(this.data.tips[3 * i], this.data.tips[3 * i + 1], this.data.tips[3 * i + 2]);
    p.applyMatrix4(this.tableInner.matrixWorld).project(this.camera);
    const rect = this.renderer.domElement.getBoundingClientRect();
    return { x: rect.left + ((p.x + 1) / 2) * rect.width, y: rect.top + ((1 - p.y) / 2) * rect.height };
  }

  resize() {
    const w = Math.max(this.parent.clientWidth, 10);
    const h = Math.max(this.parent.clientHeight, 10);
    this.renderer.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  /** Draws the whole path (`true`) or the coarse one; no change without a coarse path. */
  setDetail(whole) {
    this.detail = whole;
    if (this.coarse) {
      this.path.visible = whole;
      this.coarse.visible = !whole;
    }
    if (this.coarseMarkers) {
      this.markerPoints.visible = whole;
      this.coarseMarkers.visible = !whole;
    }
  }

  /** Whether the scene has a coarse version to draw while the camera moves. */
  hasCoarse() {
    return !!(this.coarse || this.coarseMarkers);
  }

  /** The camera starts moving: the coarse path until it rests. */
  moving() {
    clearTimeout(this.restTimer);
    if (this.hasCoarse() && this.detail) {
      this.setDetail(false);
      this.requestRender();
    }
  }

  /** The camera stopped: the whole path once it has rested a moment. */
  rest() {
    clearTimeout(this.restTimer);
    if (!this.hasCoarse() || this.detail) return;
    this.restTimer = setTimeout(() => {
      this.setDetail(true);
      this.requestRender();
    }, REST_MS);
  }

  requestRender() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      this.renderNow();
    });
  }

  /** Milliseconds to draw one frame of the whole path (`true`) or the coarse one, to the last pixel. */
  timeFrame(whole) {
    const was = this.detail;
    this.setDetail(whole);
    const gl = this.renderer.getContext();
    const pixel = new Uint8Array(4);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    const t = performance.now();
    this.renderNow();
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    const ms = performance.now() - t;
    this.setDetail(was);
    return ms;
  }

  /** Moves the camera towards its target to `f` times its distance. */
  zoomBy(f) {
    const t = this.controls.target;
    this.camera.position.sub(t).multiplyScalar(f).add(t);
    this.controls.update();
    this.requestRender();
  }

  /** World length of a pixel at the camera's target. */
  worldPerPixel() {
    const height = Math.max(this.renderer.domElement.clientHeight, 1);
    const dist = this.camera.position.distanceTo(this.controls.target);
    return (2 * dist * Math.tan((this.camera.fov * Math.PI) / 360)) / height;
  }

  /**
   * The whole path as drawn: the coarsest pixel level whose spacing is
   * below half a pixel, else every vertex.
   */
  choosePixelLevel() {
    const half = 0.5 * this.worldPerPixel();
    let chosen = null;
    for (const level of this.pixelLevels) if (level.spacing <= half) chosen = level;
    const whole = !!this.detail || !this.coarse;
    this.path.visible = whole && !chosen;
    for (const level of this.pixelLevels) level.line.visible = whole && level === chosen;
    this.drawnVertices = whole ? (chosen ? chosen.vertices : this.path.geometry.getAttribute('position').count) : this.coarse.geometry.index.count;
  }

  renderNow() {
    this.choosePixelLevel();
    this.renderer.render(this.scene, this.camera);
    this.frames = (this.frames || 0) + 1;
  }
}
