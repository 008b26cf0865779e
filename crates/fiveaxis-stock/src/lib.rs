//! Material removal: the stock as vertical dexels ([`dexel::Dexels`]), cut
//! by the tool's cutting part at poses along each move so close that no
//! point of the tool moves more than a cell between them; the shank, the
//! holder and rapid moves tested against what is left; the designed part
//! as dexels of the same grid for gouges and material left on it.
//!
//! Everything here is in the stock's frame, the table frame of the
//! machine with the work zero placed; the caller places the tool.

pub mod dexel;
pub mod lanes;
pub mod solid;

use dexel::{Dexels, Span};
use fiveaxis_machine::Vec3;
pub use lanes::{Outcome, Pose};
use solid::{Posed, ToolPieces};

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
    /// Adds the rectangle `other` to `this`.
    pub(crate) fn merge(this: &mut Option<Touched>, other: Option<Touched>) {
        if let Some(t) = other {
            Touched::add(this, t.i.0, t.j.0);
            Touched::add(this, t.i.1 - 1, t.j.1 - 1);
        }
    }

    /// Adds ray (`i`, `j`) to `this`.
    pub(crate) fn add(this: &mut Option<Touched>, i: usize, j: usize) {
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

    /// What the lanes read: the grid, the part, the tolerance, the top.
    fn shared(&self) -> lanes::Shared<'_> {
        lanes::Shared {
            grid: &self.dexels,
            part: self.part.as_ref(),
            tolerance: self.tolerance,
            top: self.top,
        }
    }

    /// Whether `posed` may reach the stock at all (its box against the
    /// grid and the top of the material).
    pub fn may_meet(&self, posed: &Posed) -> bool {
        self.shared().may_meet(posed)
    }

    /// Cuts the material inside `cutter` (line `line` of the program).
    pub fn cut(&mut self, cutter: &Posed, line: u32, measure_depth: bool) -> Cut {
        let mut cut = Cut::default();
        self.with_lanes(1, |shared, lanes| {
            cut = shared.cut(&mut lanes[0], cutter, line, measure_depth);
            lanes[0].touched
        });
        cut
    }

    /// Cuts with each of `poses` in order (their tools: indices into
    /// `tools`), one [`lanes::Outcome`] each into `out`: on up to `lanes`
    /// threads, each cutting its own rows ([`lanes`]); the stock left
    /// is the same whatever their number.
    pub fn run(
        &mut self,
        tools: &[ToolPieces],
        poses: &[Pose],
        out: &mut Vec<Outcome>,
        lanes: usize,
    ) {
        let lanes = lanes.clamp(1, (poses.len() / lanes::POSES_PER_LANE).max(1));
        self.with_lanes(lanes, |shared, lanes| {
            lanes::run_lanes(shared, std::mem::take(lanes), tools, poses, out)
        });
    }

    /// Runs `work` on the rays dealt out to `count` lanes, and notes the
    /// rays it says it touched.
    fn with_lanes(
        &mut self,
        count: usize,
        work: impl FnOnce(&lanes::Shared<'_>, &mut Vec<lanes::Lane<'_>>) -> Option<Touched>,
    ) {
        let mut rays = self.dexels.take_rays();
        let mut lines = std::mem::take(&mut self.last_line);
        let nx = self.dexels.nx;
        let touched = {
            let mut dealt = lanes::deal(&mut rays, &mut lines, nx, count);
            work(&self.shared(), &mut dealt)
        };
        self.dexels.put_rays(rays);
        self.last_line = lines;
        Touched::merge(&mut self.touched, touched);
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
