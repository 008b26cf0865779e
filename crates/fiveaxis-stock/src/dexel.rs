//! The dexel grid: a solid as vertical rays through the centres of square
//! cells, each ray holding the spans of z where it is inside the solid.
//! Exact along z, sampled at the cell size across; a ray may hold several
//! spans, so undercuts are kept.

use std::ops::Range;

use fiveaxis_machine::Vec3;
use smallvec::SmallVec;

/// A span of material along a ray, `[bottom, top]` in mm from the grid's
/// base height (f32: a micrometre on a 10 m ray).
pub type Span = [f32; 2];

/// Spans of one ray, lowest first, disjoint.
pub type Spans = SmallVec<[Span; 1]>;

/// Rays at most in one grid (a 1 m square at 0.2 mm is 25 M rays).
pub const MAX_RAYS: usize = 64_000_000;

/// A solid as dexels.
#[derive(Clone, Debug)]
pub struct Dexels {
    /// Corner of the grid (lowest x, y) and the height spans start from.
    pub origin: Vec3,
    /// Cell size, mm.
    pub cell: f64,
    /// Cells along x and y.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    rays: Vec<Spans>,
}

/// Why a grid cannot be made.
#[derive(Clone, Debug, PartialEq)]
pub enum GridError {
    /// More rays than [`MAX_RAYS`].
    TooFine {
        /// The rays it would take.
        rays: f64,
    },
    /// A size that is not a positive finite number.
    Empty,
}

impl std::fmt::Display for GridError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GridError::TooFine { rays } => write!(
                f,
                "{rays:.0} rays, more than the {MAX_RAYS} a stock model may have: choose a coarser resolution"
            ),
            GridError::Empty => write!(f, "the solid has no extent"),
        }
    }
}

impl std::error::Error for GridError {}

impl Dexels {
    /// An empty grid covering `min`..`max` in x and y with cells of
    /// `cell` mm, heights from `min.z`.
    ///
    /// # Errors
    ///
    /// [`GridError`] when the grid would be empty or too fine.
    pub fn empty(min: &Vec3, max: &Vec3, cell: f64) -> Result<Self, GridError> {
        let size = max - min;
        if !(cell > 0.0 && size.x > 0.0 && size.y > 0.0 && size.iter().all(|v| v.is_finite())) {
            return Err(GridError::Empty);
        }
        let (fx, fy) = ((size.x / cell).ceil(), (size.y / cell).ceil());
        if fx * fy > MAX_RAYS as f64 {
            return Err(GridError::TooFine { rays: fx * fy });
        }
        let (nx, ny) = (fx as usize, fy as usize);
        Ok(Self {
            origin: *min,
            cell,
            nx,
            ny,
            rays: vec![Spans::new(); nx * ny],
        })
    }

    /// A grid of the same cells, empty.
    pub fn like(&self) -> Self {
        Self {
            rays: vec![Spans::new(); self.rays.len()],
            ..*self
        }
    }

    /// Fills the box `min`..`max`.
    pub fn fill_box(&mut self, min: &Vec3, max: &Vec3) {
        let span = [
            (min.z - self.origin.z) as f32,
            (max.z - self.origin.z) as f32,
        ];
        let (xs, ys) = (self.columns(min.x, max.x), self.rows(min.y, max.y));
        for j in ys {
            for i in xs.clone() {
                let (x, y) = self.centre(i, j);
                if x >= min.x && x <= max.x && y >= min.y && y <= max.y {
                    self.rays[j * self.nx + i] = Spans::from_slice(&[span]);
                }
            }
        }
    }

    /// Fills the inside of a closed triangle mesh (nonzero winding along
    /// each ray, so either orientation of the triangles is taken).
    pub fn fill_mesh(&mut self, triangles: &[[Vec3; 3]]) {
        // Rays through an edge or a vertex would count it twice or not at
        // all: the rays are nudged off by a fraction of a cell that no
        // mesh of the work lines up with.
        let nudge = (self.cell * 1.234_567e-6, self.cell * 2.345_678e-6);
        let mut crossings: Vec<(u32, f32, i8)> = Vec::new();
        for t in triangles {
            let [a, b, c] = *t;
            let area = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
            if area == 0.0 {
                continue;
            }
            let (lo, hi) = (a.inf(&b).inf(&c), a.sup(&b).sup(&c));
            for j in self.rows(lo.y, hi.y) {
                for i in self.columns(lo.x, hi.x) {
                    let (x, y) = self.centre(i, j);
                    let (x, y) = (x + nudge.0, y + nudge.1);
                    // Barycentric coordinates in the xy projection.
                    let w1 = ((b.x - x) * (c.y - y) - (c.x - x) * (b.y - y)) / area;
                    let w2 = ((c.x - x) * (a.y - y) - (a.x - x) * (c.y - y)) / area;
                    let w3 = 1.0 - w1 - w2;
                    if w1 < 0.0 || w2 < 0.0 || w3 < 0.0 {
                        continue;
                    }
                    let z = w1 * a.z + w2 * b.z + w3 * c.z - self.origin.z;
                    // Facing down (area < 0 seen from above): the ray
                    // enters the solid going up.
                    let sign = if area < 0.0 { 1 } else { -1 };
                    crossings.push(((j * self.nx + i) as u32, z as f32, sign));
                }
            }
        }
        crossings.sort_unstable_by(|p, q| p.0.cmp(&q.0).then(p.1.total_cmp(&q.1)));
        let mut k = 0;
        while k < crossings.len() {
            let ray = crossings[k].0 as usize;
            let mut spans = Spans::new();
            let mut winding = 0i32;
            let mut start = 0.0f32;
            while k < crossings.len() && crossings[k].0 as usize == ray {
                let (_, z, sign) = crossings[k];
                let before = winding;
                winding += i32::from(sign);
                if before == 0 && winding != 0 {
                    start = z;
                } else if before != 0 && winding == 0 && z > start {
                    push_span(&mut spans, [start, z]);
                }
                k += 1;
            }
            for s in spans {
                add_span(&mut self.rays[ray], s);
            }
        }
    }

    /// The centre of cell (i, j).
    pub fn centre(&self, i: usize, j: usize) -> (f64, f64) {
        (
            self.origin.x + (i as f64 + 0.5) * self.cell,
            self.origin.y + (j as f64 + 0.5) * self.cell,
        )
    }

    /// The columns whose centres may lie in `lo..=hi` along x.
    pub fn columns(&self, lo: f64, hi: f64) -> Range<usize> {
        index_range(lo, hi, self.origin.x, self.cell, self.nx)
    }

    /// The rows whose centres may lie in `lo..=hi` along y.
    pub fn rows(&self, lo: f64, hi: f64) -> Range<usize> {
        index_range(lo, hi, self.origin.y, self.cell, self.ny)
    }

    /// The spans of ray `k` (`j · nx + i`).
    pub fn spans(&self, k: usize) -> &[Span] {
        &self.rays[k]
    }

    /// All rays, row by row.
    pub fn rays(&self) -> &[Spans] {
        &self.rays
    }

    /// Removes `[lo, hi]` (heights from the origin) from ray `k`, handing
    /// each piece of material removed to `removed`; returns the length
    /// removed, mm.
    pub fn subtract(&mut self, k: usize, lo: f32, hi: f32, removed: impl FnMut(Span)) -> f32 {
        subtract(&mut self.rays[k], lo, hi, removed)
    }

    /// The rays, taken out of the grid (which keeps its cells and is
    /// empty until [`Dexels::put_rays`] gives them back), so that they
    /// can be cut row by row on several threads while the grid's
    /// geometry is read.
    pub(crate) fn take_rays(&mut self) -> Vec<Spans> {
        std::mem::take(&mut self.rays)
    }

    /// Gives back the rays [`Dexels::take_rays`] took.
    pub(crate) fn put_rays(&mut self, rays: Vec<Spans>) {
        self.rays = rays;
    }

    /// The pieces of ray `k`'s material inside `[lo, hi]`.
    pub fn overlap(&self, k: usize, lo: f32, hi: f32, mut each: impl FnMut(Span)) {
        for &[a, b] in &self.rays[k] {
            if a >= hi {
                break;
            }
            if b > lo {
                each([a.max(lo), b.min(hi)]);
            }
        }
    }

    /// The volume of the solid, mm³.
    pub fn volume(&self) -> f64 {
        let length: f64 = self
            .rays
            .iter()
            .flatten()
            .map(|s| f64::from(s[1] - s[0]))
            .sum();
        length * self.cell * self.cell
    }

    /// The highest point of material, mm from the origin (the origin's
    /// height when empty).
    pub fn top(&self) -> f32 {
        self.rays
            .iter()
            .filter_map(|s| s.last())
            .map(|s| s[1])
            .fold(0.0, f32::max)
    }

    /// The surface of the solid as triangles (outward facing): each
    /// span's top and bottom squares and, on each side of its cell, the
    /// parts of it the neighbour's spans do not cover.
    pub fn triangles(&self, mut each: impl FnMut([Vec3; 3])) {
        let h = self.cell / 2.0;
        let z0 = self.origin.z;
        let mut open: Vec<Span> = Vec::new();
        for j in 0..self.ny {
            for i in 0..self.nx {
                let k = j * self.nx + i;
                let (x, y) = self.centre(i, j);
                for &[a, b] in &self.rays[k] {
                    let (za, zb) = (z0 + f64::from(a), z0 + f64::from(b));
                    quad(
                        &mut each,
                        [x - h, y - h, zb],
                        [h * 2.0, 0.0, 0.0],
                        [0.0, h * 2.0, 0.0],
                    );
                    quad(
                        &mut each,
                        [x - h, y - h, za],
                        [0.0, h * 2.0, 0.0],
                        [h * 2.0, 0.0, 0.0],
                    );
                    // Sides: −x, +x, −y, +y.
                    let sides: [(Option<usize>, [f64; 3], [f64; 3]); 4] = [
                        (
                            i.checked_sub(1).map(|i| j * self.nx + i),
                            [x - h, y + h, 0.0],
                            [0.0, -2.0 * h, 0.0],
                        ),
                        (
                            (i + 1 < self.nx).then(|| k + 1),
                            [x + h, y - h, 0.0],
                            [0.0, 2.0 * h, 0.0],
                        ),
                        (
                            j.checked_sub(1).map(|j| j * self.nx + i),
                            [x - h, y - h, 0.0],
                            [2.0 * h, 0.0, 0.0],
                        ),
                        (
                            (j + 1 < self.ny).then(|| k + self.nx),
                            [x + h, y + h, 0.0],
                            [-2.0 * h, 0.0, 0.0],
                        ),
                    ];
                    for (neighbour, corner, along) in sides {
                        open.clear();
                        open.push([a, b]);
                        if let Some(n) = neighbour {
                            for &[c, d] in &self.rays[n] {
                                let mut next = Vec::with_capacity(open.len() + 1);
                                for &[p, q] in &open {
                                    if d <= p || c >= q {
                                        next.push([p, q]);
                                        continue;
                                    }
                                    if c > p {
                                        next.push([p, c]);
                                    }
                                    if d < q {
                                        next.push([d, q]);
                                    }
                                }
                                open = next;
                            }
                        }
                        for &[p, q] in &open {
                            let (zp, zq) = (z0 + f64::from(p), z0 + f64::from(q));
                            quad(
                                &mut each,
                                [corner[0], corner[1], zp],
                                along,
                                [0.0, 0.0, zq - zp],
                            );
                        }
                    }
                }
            }
        }
    }
}

/// Two triangles of the parallelogram at `at` spanned by `u` then `v`
/// (facing `u × v`).
fn quad(each: &mut impl FnMut([Vec3; 3]), at: [f64; 3], u: [f64; 3], v: [f64; 3]) {
    let p = Vec3::from(at);
    let (u, v) = (Vec3::from(u), Vec3::from(v));
    each([p, p + u, p + u + v]);
    each([p, p + u + v, p + v]);
}

/// Indices of cells whose centres `origin + (i + ½)·cell` may lie in
/// `lo..=hi`, within `0..n`.
fn index_range(lo: f64, hi: f64, origin: f64, cell: f64, n: usize) -> Range<usize> {
    if lo
        .partial_cmp(&hi)
        .is_none_or(|o| o == std::cmp::Ordering::Greater)
    {
        return 0..0;
    }
    let first = ((lo - origin) / cell - 0.5).ceil().max(0.0);
    let last = ((hi - origin) / cell - 0.5).floor() + 1.0;
    let last = last.min(n as f64);
    if last <= first {
        return 0..0;
    }
    first as usize..last as usize
}

/// Adds a span above the others (spans come in order).
fn push_span(spans: &mut Spans, span: Span) {
    if let Some(last) = spans.last_mut()
        && last[1] >= span[0]
    {
        last[1] = last[1].max(span[1]);
        return;
    }
    spans.push(span);
}

/// Adds a span anywhere, merging with those it touches.
fn add_span(spans: &mut Spans, span: Span) {
    let [mut a, mut b] = span;
    let mut out = Spans::new();
    let mut placed = false;
    for &[c, d] in spans.iter() {
        if d < a {
            out.push([c, d]);
        } else if c > b {
            if !placed {
                out.push([a, b]);
                placed = true;
            }
            out.push([c, d]);
        } else {
            a = a.min(c);
            b = b.max(d);
        }
    }
    if !placed {
        out.push([a, b]);
    }
    *spans = out;
}

/// Removes `[lo, hi]` from the spans of one ray, handing each piece of
/// material removed to `removed`; returns the length removed.
pub(crate) fn subtract(spans: &mut Spans, lo: f32, hi: f32, mut removed: impl FnMut(Span)) -> f32 {
    let mut total = 0.0;
    let mut i = 0;
    while i < spans.len() {
        let [a, b] = spans[i];
        if b <= lo {
            i += 1;
            continue;
        }
        if a >= hi {
            break;
        }
        let cut = [a.max(lo), b.min(hi)];
        total += cut[1] - cut[0];
        removed(cut);
        match (a < lo, b > hi) {
            (true, true) => {
                spans[i] = [a, lo];
                spans.insert(i + 1, [hi, b]);
                break;
            }
            (true, false) => {
                spans[i] = [a, lo];
                i += 1;
            }
            (false, true) => {
                spans[i] = [hi, b];
                break;
            }
            (false, false) => {
                spans.remove(i);
            }
        }
    }
    total
}
