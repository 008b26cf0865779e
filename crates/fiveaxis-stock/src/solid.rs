//! The tool as solids of revolution about its axis, and where a vertical
//! ray meets them: spheres and cone frustums (a cylinder is a frustum of
//! equal radii), each met along a ray in one span found in closed form.
//! The cutters of the offsets file are convex, so a ray meets a whole
//! cutting part in one span too: the hull of its pieces' spans.

use fiveaxis_machine::Vec3;
use fiveaxis_machine::geometry::{Cutter, ToolShape};
use smallvec::SmallVec;

/// Frustums that stand for a bull nose's corner (the chord of each
/// 11.25° of the quarter circle: 0.5 % of the corner radius inside it).
const CORNER_STEPS: usize = 8;

/// A piece of a tool, along its axis from the tip (`a` upwards).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Piece {
    /// A ball centred on the axis `at` mm from the tip.
    Sphere {
        /// Its centre's height above the tip, mm.
        at: f64,
        /// Its radius, mm.
        radius: f64,
    },
    /// A cone frustum between heights `a0` and `a1` with radii `r0` and
    /// `r1` there.
    Frustum {
        /// Lower height, mm.
        a0: f64,
        /// Upper height, mm.
        a1: f64,
        /// Radius at `a0`, mm.
        r0: f64,
        /// Radius at `a1`, mm.
        r1: f64,
    },
}

/// The pieces of a tool: its cutting part, and what does not cut (shank
/// and holder).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ToolPieces {
    /// The cutting part.
    pub cutting: Vec<Piece>,
    /// The shank.
    pub shank: Vec<Piece>,
    /// The holder.
    pub holder: Vec<Piece>,
}

impl ToolPieces {
    /// The pieces of a tool of `shape`, `length` mm from gauge line to
    /// tip and `radius` mm, the way `fiveaxis-collide` places them: the
    /// holder's steps down from the gauge line, the cutting part `flute`
    /// long at the tip, the shank in between.
    pub fn of(shape: &ToolShape, length: f64, radius: f64) -> Self {
        let holder_length = shape.holder_length();
        let flute = shape.flute.min((length - holder_length).max(0.0));
        let mut pieces = Self::default();
        if flute > 0.0 && radius > 0.0 {
            pieces.cutting = cutting(shape.cutter, radius, flute);
        }
        let shank_length = (length - holder_length - flute).max(0.0);
        if shank_length > 0.0 && shape.shank > 0.0 {
            let r = shape.shank / 2.0;
            pieces.shank.push(Piece::Frustum {
                a0: flute,
                a1: flute + shank_length,
                r0: r,
                r1: r,
            });
        }
        let mut top = length;
        for step in &shape.holder {
            let bottom = top - step.length;
            pieces.holder.push(Piece::Frustum {
                a0: bottom,
                a1: top,
                r0: step.tip_diameter / 2.0,
                r1: step.diameter / 2.0,
            });
            top = bottom;
        }
        pieces
    }
}

/// The cutting part's pieces.
fn cutting(cutter: Cutter, radius: f64, flute: f64) -> Vec<Piece> {
    let cylinder = |a0: f64, r: f64| Piece::Frustum {
        a0,
        a1: flute,
        r0: r,
        r1: r,
    };
    match cutter {
        Cutter::Flat => vec![cylinder(0.0, radius)],
        Cutter::Ball => {
            let mut p = vec![Piece::Sphere { at: radius, radius }];
            if flute > radius {
                p.push(cylinder(radius, radius));
            }
            p
        }
        Cutter::BullNose { corner } => {
            let corner = corner.min(radius);
            let inner = radius - corner;
            let mut p = Vec::with_capacity(CORNER_STEPS + 2);
            if inner > 0.0 {
                p.push(Piece::Frustum {
                    a0: 0.0,
                    a1: corner.min(flute),
                    r0: inner,
                    r1: inner,
                });
            }
            let point = |k: usize| {
                let t = std::f64::consts::FRAC_PI_2 * k as f64 / CORNER_STEPS as f64;
                (inner + corner * t.sin(), corner - corner * t.cos())
            };
            for k in 0..CORNER_STEPS {
                let ((r0, a0), (r1, a1)) = (point(k), point(k + 1));
                if a0 < flute {
                    p.push(Piece::Frustum {
                        a0,
                        a1: a1.min(flute),
                        r0,
                        r1,
                    });
                }
            }
            if flute > corner {
                p.push(cylinder(corner, radius));
            }
            p
        }
        Cutter::Drill { point_angle } => {
            let point = (radius / (point_angle / 2.0).to_radians().tan()).min(flute);
            let mut p = vec![Piece::Frustum {
                a0: 0.0,
                a1: point,
                r0: 0.0,
                r1: radius * point / (radius / (point_angle / 2.0).to_radians().tan()),
            }];
            if flute > point {
                p.push(cylinder(point, radius));
            }
            p
        }
        Cutter::Taper { half_angle } => vec![Piece::Frustum {
            a0: 0.0,
            a1: flute,
            r0: radius,
            r1: radius + flute * half_angle.to_radians().tan(),
        }],
    }
}

/// A piece placed in the stock's frame.
#[derive(Clone, Copy, Debug)]
pub enum Placed {
    /// A ball.
    Sphere {
        /// Centre.
        c: Vec3,
        /// Radius.
        r: f64,
    },
    /// A frustum: base centre `b`, unit axis `u`, length `len`, radius
    /// `r0 + k·a` at height `a` along the axis.
    Frustum {
        /// Base centre.
        b: Vec3,
        /// Unit axis.
        u: Vec3,
        /// Length.
        len: f64,
        /// Radius at the base.
        r0: f64,
        /// Radius change per mm along the axis.
        k: f64,
    },
}

/// Pieces placed at one pose, with their extent.
#[derive(Clone, Debug, Default)]
pub struct Posed {
    /// The pieces.
    pub pieces: SmallVec<[Placed; 12]>,
    /// Lowest corner of their bounding box.
    pub min: Vec3,
    /// Highest corner.
    pub max: Vec3,
}

impl Posed {
    /// `pieces` with the tip at `tip` and the axis (tip towards the
    /// holder) along the unit vector `axis`.
    pub fn new(pieces: &[Piece], tip: &Vec3, axis: &Vec3) -> Self {
        let mut posed = Posed {
            pieces: SmallVec::new(),
            min: Vec3::repeat(f64::INFINITY),
            max: Vec3::repeat(f64::NEG_INFINITY),
        };
        // How far a disc of unit radius square to `axis` reaches along
        // each coordinate.
        let disc = Vec3::new(
            (1.0 - axis.x * axis.x).max(0.0).sqrt(),
            (1.0 - axis.y * axis.y).max(0.0).sqrt(),
            (1.0 - axis.z * axis.z).max(0.0).sqrt(),
        );
        for piece in pieces {
            match *piece {
                Piece::Sphere { at, radius } => {
                    let c = tip + axis * at;
                    posed.min = posed.min.inf(&c.add_scalar(-radius));
                    posed.max = posed.max.sup(&c.add_scalar(radius));
                    posed.pieces.push(Placed::Sphere { c, r: radius });
                }
                Piece::Frustum { a0, a1, r0, r1 } => {
                    let len = a1 - a0;
                    if len <= 0.0 {
                        continue;
                    }
                    let b = tip + axis * a0;
                    let e = tip + axis * a1;
                    for (centre, r) in [(b, r0), (e, r1)] {
                        posed.min = posed.min.inf(&(centre - disc * r));
                        posed.max = posed.max.sup(&(centre + disc * r));
                    }
                    posed.pieces.push(Placed::Frustum {
                        b,
                        u: *axis,
                        len,
                        r0,
                        k: (r1 - r0) / len,
                    });
                }
            }
        }
        posed
    }

    /// Where the vertical ray through (x, y) meets the pieces: the hull of
    /// each piece's span (the whole when the pieces make a convex solid).
    pub fn ray(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        let mut span: Option<(f64, f64)> = None;
        for piece in &self.pieces {
            if let Some((lo, hi)) = piece.ray(x, y) {
                span = Some(span.map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi))));
            }
        }
        span
    }

    /// How deep point `p` lies inside the pieces (the most over them; 0
    /// or less outside).
    pub fn depth(&self, p: &Vec3) -> f64 {
        self.pieces
            .iter()
            .map(|piece| piece.depth(p))
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

impl Placed {
    /// Where the vertical ray through (x, y) meets this piece.
    pub fn ray(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        match *self {
            Placed::Sphere { c, r } => {
                let d2 = (x - c.x).powi(2) + (y - c.y).powi(2);
                let h2 = r * r - d2;
                (h2 >= 0.0).then(|| {
                    let h = h2.sqrt();
                    (c.z - h, c.z + h)
                })
            }
            Placed::Frustum { b, u, len, r0, k } => {
                // Along the ray z = b.z + t: w = (wx, wy, t) from b.
                let (wx, wy) = (x - b.x, y - b.y);
                let a0 = wx * u.x + wy * u.y;
                // The slab 0 ≤ a0 + t·u.z ≤ len.
                let (mut lo, mut hi) = if u.z.abs() < 1e-12 {
                    if a0 < 0.0 || a0 > len {
                        return None;
                    }
                    (f64::NEG_INFINITY, f64::INFINITY)
                } else {
                    let (t0, t1) = (-a0 / u.z, (len - a0) / u.z);
                    (t0.min(t1), t0.max(t1))
                };
                // Radial: |w|² − a² ≤ (r0 + k·a)², a = a0 + t·u.z.
                let rho2 = wx * wx + wy * wy;
                let ra = r0 + k * a0;
                let qa = 1.0 - u.z * u.z - k * k * u.z * u.z;
                let qb = -2.0 * a0 * u.z - 2.0 * k * u.z * ra;
                let qc = rho2 - a0 * a0 - ra * ra;
                let (s0, s1) = quadratic_nonpositive(qa, qb, qc)?;
                match (s0, s1) {
                    // One interval.
                    (Some(p), Some(q)) if p <= q => {
                        lo = lo.max(p);
                        hi = hi.min(q);
                    }
                    // Outside an interval (the far nappe beyond the
                    // slab): keep the part inside the slab.
                    (Some(p), Some(q)) => {
                        // (−∞, q] ∪ [p, ∞) with q < p.
                        let below = (lo, hi.min(q));
                        let above = (lo.max(p), hi);
                        let pick = if below.0 <= below.1 { below } else { above };
                        lo = pick.0;
                        hi = pick.1;
                    }
                    (None, None) => {}
                    _ => return None,
                }
                (lo <= hi).then(|| (b.z + lo, b.z + hi))
            }
        }
    }

    /// How deep point `p` lies inside this piece (negative outside): the
    /// least of its depth from the side and from the two ends.
    pub fn depth(&self, p: &Vec3) -> f64 {
        match *self {
            Placed::Sphere { c, r } => r - (p - c).norm(),
            Placed::Frustum { b, u, len, r0, k } => {
                let w = p - b;
                let a = w.dot(&u);
                let radial = (w - u * a).norm();
                let side = (r0 + k * a) - radial;
                side.min(a).min(len - a)
            }
        }
    }
}

/// The set where `a·t² + b·t + c ≤ 0`: `Some((Some(p), Some(q)))` for
/// `[p, q]` when p ≤ q, or for `(−∞, q] ∪ [p, ∞)` when q < p;
/// `Some((None, None))` for every t; `None` for no t.
#[allow(clippy::type_complexity)]
fn quadratic_nonpositive(a: f64, b: f64, c: f64) -> Option<(Option<f64>, Option<f64>)> {
    const FLAT: f64 = 1e-12;
    if a.abs() < FLAT {
        if b.abs() < FLAT {
            return (c <= 0.0).then_some((None, None));
        }
        let root = -c / b;
        // b·t + c ≤ 0.
        return Some(if b > 0.0 {
            (Some(f64::NEG_INFINITY), Some(root))
        } else {
            (Some(root), Some(f64::INFINITY))
        });
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return (a < 0.0).then_some((None, None));
    }
    let sq = disc.sqrt();
    // Roots without cancellation.
    let q = -0.5 * (b + b.signum() * sq);
    let (r0, r1) = if q == 0.0 {
        (0.0, 0.0)
    } else {
        let (x, y) = (q / a, c / q);
        (x.min(y), x.max(y))
    };
    Some(if a > 0.0 {
        (Some(r0), Some(r1))
    } else {
        (Some(r1), Some(r0))
    })
}
