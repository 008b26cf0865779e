//! Material removal: the stock as vertical dexels ([`dexel::Dexels`]), cut
//! by the tool's cutting part at poses along each move so close that no
//! point of the tool moves more than a cell between them; the shank, the
//! holder and rapid moves tested against what is left; the designed part
//! as dexels of the same grid for gouges and material left on it.
//!
//! Everything here is in the stock's frame, the table frame of the
//! machine with the work zero placed; the caller places the tool.

pub mod dexel;
pub mod solid;

use dexel::{Dexels, Span};
use fiveaxis_machine::Vec3;
use solid::Posed;

/// The cell size of the stock model unless told, mm.
pub const DEFAULT_RESOLUTION: f64 = 0.2;

/// The designed part: its dexels on the stock's grid, and how deep a
/// point lies inside it (distance to its surface, negative outside).
pub struct Part {
    /// The part as dexels of the stock's grid.
    pub dexels: Dexels,
    /// Depth of a point inside the part, mm.
    pub depth: Box<dyn Fn(&Vec3) -> f64 + Send + Sync>,
}

impl std::fmt::Debug for Part {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Part")
            .field("dexels", &self.dexels)
            .finish_non_exhaustive()
    }
}

/// What one pose of the cutting part did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Cut {
    /// Material removed, mm³.
    pub removed: f64,
    /// The deepest cut into the part beyond the tolerance, mm (0: none).
    pub gouge: f64,
    /// Where that deepest point is.
    pub gouge_at: Vec3,
    /// The deepest point of the stock's material inside the tool
    /// before the cut, mm (0: none), for a rapid move into the stock.
    pub depth: f64,
}

/// The stock being cut.
#[derive(Debug)]
pub struct Stock {
    /// The material left.
    pub dexels: Dexels,
    /// The designed part, when given.
    pub part: Option<Part>,
    /// Gouges and material left count beyond this, mm.
    pub tolerance: f64,
    /// The highest material, mm above the grid's origin: no part of a
    /// tool above it can meet the stock.
    top: f32,
    /// The line that last cut each ray (with a part only, for material
    /// left on it).
    last_line: Vec<u32>,
    /// The rays cut since [`Stock::take_touched`] last asked.
    touched: Option<Touched>,
}

/// A rectangle of rays: columns `i.0..i.1`, rows `j.0..j.1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Touched {
    /// First column and the one past the last.
    pub i: (usize, usize),
    /// First row and the one past the last.
    pub j: (usize, usize),
}

impl Touched {
    fn add(this: &mut Option<Touched>, i: usize, j: usize) {
        match this {
            Some(t) => {
                t.i = (t.i.0.min(i), t.i.1.max(i + 1));
                t.j = (t.j.0.min(j), t.j.1.max(j + 1));
            }
            None => {
                *this = Some(Touched {
                    i: (i, i + 1),
                    j: (j, j + 1),
                });
            }
        }
    }
}

impl Stock {
    /// The stock `dexels`, cut towards `part` within `tolerance` mm.
    pub fn new(dexels: Dexels, part: Option<Part>, tolerance: f64) -> Self {
        let top = dexels.top();
        let last_line = if part.is_some() {
            vec![0; dexels.nx * dexels.ny]
        } else {
            Vec::new()
        };
        Self {
            dexels,
            part,
            tolerance,
            top,
            last_line,
            touched: None,
        }
    }

    /// The rays cut since the last call, as the rectangle around them
    /// (`None`: nothing was cut).
    pub fn take_touched(&mut self) -> Option<Touched> {
        self.touched.take()
    }

    /// Whether `posed` may reach the stock at all (its box against the
    /// grid and the top of the material).
    pub fn may_meet(&self, posed: &Posed) -> bool {
        let d = &self.dexels;
        let hi_x = d.origin.x + d.cell * d.nx as f64;
        let hi_y = d.origin.y + d.cell * d.ny as f64;
        !posed.pieces.is_empty()
            && posed.min.z - d.origin.z <= f64::from(self.top)
            && posed.max.x >= d.origin.x
            && posed.min.x <= hi_x
            && posed.max.y >= d.origin.y
            && posed.min.y <= hi_y
    }

    /// Cuts the material inside `cutter` (line `line` of the program).
    pub fn cut(&mut self, cutter: &Posed, line: u32, measure_depth: bool) -> Cut {
        let mut cut = Cut::default();
        if !self.may_meet(cutter) {
            return cut;
        }
        let d = &mut self.dexels;
        let oz = d.origin.z;
        let floor = (cutter.min.z - oz) as f32;
        let tolerance = self.tolerance;
        let mut removed = 0.0f64;
        for j in d.rows(cutter.min.y, cutter.max.y) {
            for i in d.columns(cutter.min.x, cutter.max.x) {
                let k = j * d.nx + i;
                match d.spans(k).last() {
                    Some(top) if top[1] > floor => {}
                    _ => continue,
                }
                let (x, y) = d.centre(i, j);
                let Some((lo, hi)) = cutter.ray(x, y) else {
                    continue;
                };
                let (lo, hi) = ((lo - oz) as f32, (hi - oz) as f32);
                let part = self.part.as_ref();
                let mut gouge = (0.0, Vec3::zeros());
                let mut depth = 0.0f64;
                let length = d.subtract(k, lo, hi, |piece: Span| {
                    if measure_depth {
                        for z in [piece[0], piece[1], (piece[0] + piece[1]) / 2.0] {
                            let p = Vec3::new(x, y, oz + f64::from(z));
                            depth = depth.max(cutter.depth(&p));
                        }
                    }
                    let Some(part) = part else { return };
                    part.dexels.overlap(k, piece[0], piece[1], |[c, e]| {
                        if f64::from(e - c) <= tolerance {
                            return;
                        }
                        for z in [c, e, (c + e) / 2.0] {
                            let p = Vec3::new(x, y, oz + f64::from(z));
                            let g = (part.depth)(&p);
                            if g > gouge.0 {
                                gouge = (g, p);
                            }
                        }
                    });
                });
                if length > 0.0 {
                    removed += f64::from(length);
                    Touched::add(&mut self.touched, i, j);
                    if !self.last_line.is_empty() {
                        self.last_line[k] = line;
                    }
                    if gouge.0 > tolerance && gouge.0 > cut.gouge {
                        cut.gouge = gouge.0;
                        cut.gouge_at = gouge.1;
                    }
                    cut.depth = cut.depth.max(depth);
                }
            }
        }
        cut.removed = removed * d.cell * d.cell;
        cut
    }

    /// How deep the material left reaches into `solid` (0: it does not
    /// meet it), without cutting.
    pub fn interference(&self, solid: &Posed) -> f64 {
        if !self.may_meet(solid) {
            return 0.0;
        }
        let d = &self.dexels;
        let oz = d.origin.z;
        let floor = (solid.min.z - oz) as f32;
        let mut depth = 0.0f64;
        for j in d.rows(solid.min.y, solid.max.y) {
            for i in d.columns(solid.min.x, solid.max.x) {
                let k = j * d.nx + i;
                match d.spans(k).last() {
                    Some(top) if top[1] > floor => {}
                    _ => continue,
                }
                let (x, y) = d.centre(i, j);
                let Some((lo, hi)) = solid.ray(x, y) else {
                    continue;
                };
                d.overlap(k, (lo - oz) as f32, (hi - oz) as f32, |piece| {
                    for z in [piece[0], piece[1], (piece[0] + piece[1]) / 2.0] {
                        let p = Vec3::new(x, y, oz + f64::from(z));
                        depth = depth.max(solid.depth(&p));
                    }
                });
            }
        }
        depth
    }

    /// The material left on the part beyond the tolerance, grouped by the
    /// line that last cut there (0: never cut): (line, most left mm,
    /// where, volume mm³), by line.
    ///
    /// The material left is what stands outside the part: above or below
    /// its spans on a ray, in the gaps between them, and on the rays the
    /// part does not reach (beside its walls). How much is left at a
    /// point is its distance from the part (the thickness standing on a
    /// floor, a top or a wall, along its normal), taken at the ends and
    /// the middle of each piece; a piece whose ends lie within the
    /// tolerance of the part along its own ray is not measured further.
    pub fn left_on_part(&self) -> Vec<(u32, f64, Vec3, f64)> {
        let Some(part) = &self.part else {
            return Vec::new();
        };
        let d = &self.dexels;
        let oz = d.origin.z;
        let mut by_line: std::collections::BTreeMap<u32, (f64, Vec3, f64)> =
            std::collections::BTreeMap::new();
        let mut pieces: smallvec::SmallVec<[(Span, f32); 4]> = smallvec::SmallVec::new();
        for j in 0..d.ny {
            for i in 0..d.nx {
                let k = j * d.nx + i;
                let spans = d.spans(k);
                if spans.is_empty() {
                    continue;
                }
                let design = part.dexels.spans(k);
                // Pieces of material outside the part, each with a bound
                // on how far its points lie from the part along the ray.
                pieces.clear();
                for &[a, b] in spans {
                    if design.is_empty() {
                        pieces.push(([a, b], f32::INFINITY));
                        continue;
                    }
                    let (lo, hi) = (design[0][0], design[design.len() - 1][1]);
                    if b > hi {
                        pieces.push(([a.max(hi), b], b - hi));
                    }
                    if a < lo {
                        pieces.push(([a, b.min(lo)], lo - a));
                    }
                    for w in design.windows(2) {
                        let (gap_lo, gap_hi) = (w[0][1], w[1][0]);
                        if b > gap_lo && a < gap_hi {
                            let piece = [a.max(gap_lo), b.min(gap_hi)];
                            pieces.push((piece, (gap_hi - gap_lo) / 2.0));
                        }
                    }
                }
                let (x, y) = d.centre(i, j);
                let mut excess = 0.0f64;
                let mut at = Vec3::zeros();
                let mut length = 0.0f64;
                for &([p, q], bound) in &pieces {
                    if f64::from(bound) <= self.tolerance || q <= p {
                        continue;
                    }
                    let mut most = 0.0f64;
                    for z in [p, q, (p + q) / 2.0] {
                        let point = Vec3::new(x, y, oz + f64::from(z));
                        let away = -(part.depth)(&point);
                        if away > most {
                            most = away;
                            if away > excess {
                                excess = away;
                                at = point;
                            }
                        }
                    }
                    if most > self.tolerance {
                        length += f64::from(q - p);
                    }
                }
                if excess > self.tolerance {
                    let line = self.last_line.get(k).copied().unwrap_or(0);
                    let entry = by_line.entry(line).or_insert((0.0, Vec3::zeros(), 0.0));
                    entry.2 += length * d.cell * d.cell;
                    if excess > entry.0 {
                        entry.0 = excess;
                        entry.1 = at;
                    }
                }
            }
        }
        by_line
            .into_iter()
            .map(|(line, (most, at, volume))| (line, most, at, volume))
            .collect()
    }
}
