//! Bound and refine: the largest value of a function of the block
//! parameter `s` found to within a proven tolerance, from bounds on its
//! derivatives.
//!
//! Every motion law of a block is built from points that move linearly or
//! on circles in `s` and are turned about rotation lines by angles linear
//! in `s`. [`Moving`] carries, through those steps, where a point is at
//! `s = 0` and bounds on the size of its first, second and third
//! derivatives in `s` (`|p'| ≤ speed`, `|p''| ≤ curvature`,
//! `|p'''| ≤ jerk`). A function with `|f''| ≤ M` stays within `M·h²/8` of
//! the chord of its values over a piece of length `h` (the error of linear
//! interpolation), so over that piece it is at most the larger end value
//! plus `M·h²/8`. [`maximize`] halves pieces until that bound is below the
//! best value found (plus [`EXTREMUM_TOLERANCE`]): the value it returns is
//! reached, and nothing in the block exceeds it by more than the
//! tolerance. The third derivative gives a second bound: the parabola
//! through a piece's ends and the far end of the piece it was halved from
//! stays within `J·h³·2/(3·√3)/3!` of a function with `|f'''| ≤ J` on the
//! piece (the error of quadratic interpolation), a bound that shrinks
//! with the cube of the piece and settles a peak in fewer halvings.
//! [`maximize_norm`] does the same for the length of a moving vector.

use arrayvec::ArrayVec;
use fiveaxis_control::TipPath;
use fiveaxis_machine::{Vec3, turn_about};
use nalgebra::Unit;

/// How far the true maximum may lie above the value [`maximize`] returns
/// (mm, or whatever `f` measures).
pub const EXTREMUM_TOLERANCE: f64 = 1e-9;

/// Most evaluations one maximisation spends; beyond them the best value
/// found is returned (only a pathological bound reaches it).
pub const MAX_EVALUATIONS: u32 = 4096;

/// Smallest piece of `s` that is still halved.
const MIN_PIECE: f64 = 1e-13;

/// Depth of the piece stack (a depth-first search keeps at most one piece
/// per level).
const STACK: usize = 64;

/// A point moving with `s` in [0, 1]: where it is at `s = 0`, and bounds
/// on the size of its first and second derivatives in `s`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Moving {
    /// The point at `s = 0`.
    pub at0: Vec3,
    /// `|dp/ds| ≤ speed` over the block.
    pub speed: f64,
    /// `|d²p/ds²| ≤ curvature` over the block.
    pub curvature: f64,
    /// `|d³p/ds³| ≤ jerk` over the block.
    pub jerk: f64,
}

impl Moving {
    /// A point that stays.
    pub fn fixed(p: Vec3) -> Self {
        Self {
            at0: p,
            speed: 0.0,
            curvature: 0.0,
            jerk: 0.0,
        }
    }

    /// From `a` to `b` linearly.
    pub fn line(a: Vec3, b: Vec3) -> Self {
        Self {
            at0: a,
            speed: (b - a).norm(),
            curvature: 0.0,
            jerk: 0.0,
        }
    }

    /// Along a tip path: `r(s)·(cos θ·u + sin θ·v) + rise·s·n` with `r`
    /// and `θ` linear in `s` has `|p'| ≤ |Δr| + r·|sweep| + |rise|`,
    /// `|p''| ≤ 2·|Δr|·|sweep| + r·sweep²` and
    /// `|p'''| ≤ 3·|Δr|·sweep² + r·|sweep|³`.
    pub fn tip_path(path: &TipPath) -> Self {
        match *path {
            TipPath::Line([a, b]) => Self::line(a, b),
            TipPath::Arc {
                radius,
                sweep,
                rise,
                ..
            } => {
                let r = radius[0].abs().max(radius[1].abs());
                let dr = (radius[1] - radius[0]).abs();
                let w = sweep.abs();
                Self {
                    at0: path.at(0.0),
                    speed: dr + r * w + rise.abs(),
                    curvature: 2.0 * dr * w + r * w * w,
                    jerk: 3.0 * dr * w * w + r * w * w * w,
                }
            }
        }
    }

    /// The point turned about the line through `center` along `axis` by
    /// `angle0 + delta·s` degrees. With `q` the point and `R` the turn,
    /// `p = c + R(q − c)`, and each derivative of `R` keeping only the
    /// part across the line of what it turns, times `ω` (Leibniz):
    /// `|p'| ≤ ω·ρ + |q'|`, `|p''| ≤ ω²·ρ + 2ω·|q'| + |q''|` and
    /// `|p'''| ≤ ω³·ρ + 3ω²·|q'| + 3ω·|q''| + |q'''|`, where `ω` is the
    /// turn rate in radians per unit `s` and `ρ` bounds the distance of
    /// `q` from the line (its distance at `s = 0` plus how far it can
    /// move).
    #[must_use]
    pub fn turned(self, axis: &Unit<Vec3>, center: &Vec3, angle0: f64, delta: f64) -> Self {
        let w = delta.to_radians().abs();
        let rel = self.at0 - center;
        let k = axis.as_ref();
        let rho = (rel - k * k.dot(&rel)).norm() + self.speed;
        Self {
            at0: turn_about(axis, center, angle0, &self.at0),
            speed: w * rho + self.speed,
            curvature: w * w * rho + 2.0 * w * self.speed + self.curvature,
            jerk: w * w * w * rho + 3.0 * w * w * self.speed + 3.0 * w * self.curvature + self.jerk,
        }
    }

    /// The point carried by a rigid map (`map` of the point at `s = 0`;
    /// derivatives keep their size).
    #[must_use]
    pub fn mapped(self, map: impl Fn(&Vec3) -> Vec3) -> Self {
        Self {
            at0: map(&self.at0),
            ..self
        }
    }

    /// The sum of two moving points.
    #[must_use]
    pub fn plus(self, other: Self) -> Self {
        Self {
            at0: self.at0 + other.at0,
            speed: self.speed + other.speed,
            curvature: self.curvature + other.curvature,
            jerk: self.jerk + other.jerk,
        }
    }

    /// The difference of two moving points.
    #[must_use]
    pub fn minus(self, other: Self) -> Self {
        Self {
            at0: self.at0 - other.at0,
            speed: self.speed + other.speed,
            curvature: self.curvature + other.curvature,
            jerk: self.jerk + other.jerk,
        }
    }
}

/// The largest value of `f(s)` over `s` in [0, 1], if it is above
/// `floor`: `(s, value)` where it is reached. `curvature` and `jerk`
/// bound the second and third derivatives of `f`; `ends` are `f(0)`,
/// `f(1)`.
///
/// `None` proves that no value exceeds `floor + EXTREMUM_TOLERANCE`.
pub fn maximize(
    f: impl Fn(f64) -> f64,
    curvature: f64,
    jerk: f64,
    floor: f64,
    ends: [f64; 2],
) -> Option<(f64, f64)> {
    search(
        |s| {
            let x = f(s);
            (x, x)
        },
        [(ends[0], ends[0]), (ends[1], ends[1])],
        curvature,
        |_, _, _| jerk,
        |target| target,
        floor,
        EXTREMUM_TOLERANCE,
    )
}

/// The largest length of the moving vector `f(s)` over `s` in [0, 1], if
/// it is above `floor`: `(s, length)` where it is reached, and nothing in
/// the block longer by more than `tolerance`. `law` bounds the
/// derivatives of `f` (its `at0` is not used); `ends` are `f(0)`, `f(1)`.
///
/// The parabola is fitted to `g = |f|²`, smooth where the length is not,
/// with `|g'''| = |6·f'·f'' + 2·f·f'''| ≤ 6·speed·curvature + 2·|f|·jerk`
/// and `|f|` over a piece at most the mean of its end lengths plus half
/// the piece's length times `speed`.
pub fn maximize_norm(
    f: impl Fn(f64) -> Vec3,
    law: &Moving,
    floor: f64,
    ends: [Vec3; 2],
    tolerance: f64,
) -> Option<(f64, f64)> {
    let (speed, curvature, jerk) = (law.speed, law.curvature, law.jerk);
    let measure = |v: Vec3| {
        let g = v.norm_squared();
        (g, g.sqrt())
    };
    search(
        |s| measure(f(s)),
        [measure(ends[0]), measure(ends[1])],
        curvature,
        |xa, xb, h| 6.0 * speed * curvature + (xa + xb + speed * h) * jerk,
        |target| target.max(0.0).powi(2),
        floor,
        tolerance,
    )
}

/// `2/(3·√3)/3!`: the parabola through `t = 0, 1, 2` misses a function
/// with `|g'''| ≤ G` on [0, 1] by at most this times `G·h³` (the node
/// polynomial `t·(t − 1)·(t − 2)` peaks there at `2/(3·√3)`, at
/// `t = 1 − 1/√3`).
const EXTRAPOLATION_ERROR: f64 = 0.064_150_029_909_958_36;

/// A piece of `s` seen from one end: the fitted value `g` at that end
/// (`t = 0`), at the other end (`t = 1`), and one piece length beyond it
/// (`t = 2`, the far end of the piece it was halved from); the sizes `x`
/// at its ends.
#[derive(Clone, Copy)]
struct Piece {
    s: [f64; 2],
    g: [f64; 3],
    x: [f64; 2],
}

/// The largest value over `t` in [0, 1] of the parabola through
/// `(0, g0)`, `(1, g1)`, `(2, g2)`.
fn parabola_max([g0, g1, g2]: [f64; 3]) -> f64 {
    let a = 0.5 * (g2 - 2.0 * g1 + g0);
    let b = g1 - g0 - a;
    let ends = g0.max(g1);
    if a < 0.0 {
        let t = -b / (2.0 * a);
        if t > 0.0 && t < 1.0 {
            return ends.max(g0 - b * b / (4.0 * a));
        }
    }
    ends
}

/// The halving search of [`maximize`] and [`maximize_norm`]. `measure`
/// gives at `s` the value `g` a parabola is fitted to and the size `x`
/// maximised (`g` increasing in `x`; `in_g` turns a size into `g`);
/// `curvature` bounds the second derivative of `x` (so that over a piece
/// it is at most its larger end plus `curvature·h²/8`, the error of
/// linear interpolation), `third(xa, xb, h)` the third of `g` over a
/// piece with end sizes `xa`, `xb`.
///
/// Pieces are halved, one evaluation each, and a piece is settled by the
/// smaller of two bounds: the linear one above, or the parabola through
/// its ends and the far end of its parent plus that parabola's error
/// (`third·h³·EXTRAPOLATION_ERROR`), which shrinks with `h³` and settles a
/// peak in fewer halvings.
fn search(
    measure: impl Fn(f64) -> (f64, f64),
    ends: [(f64, f64); 2],
    curvature: f64,
    third: impl Fn(f64, f64, f64) -> f64,
    in_g: impl Fn(f64) -> f64,
    floor: f64,
    tolerance: f64,
) -> Option<(f64, f64)> {
    let mut level = floor;
    let mut best = None;
    let [(g0, x0), (g1, x1)] = ends;
    for (s, x) in [(0.0, x0), (1.0, x1)] {
        if x > level {
            level = x;
            best = Some((s, x));
        }
    }
    // The whole block, with no third point for a parabola yet.
    if x0.max(x1) + curvature / 8.0 <= level + tolerance {
        return best;
    }
    let (gm, xm) = measure(0.5);
    if xm > level {
        level = xm;
        best = Some((0.5, xm));
    }
    // Filled as it grows: a block's search is often over in a few
    // pieces, and the whole stack is never written up front.
    let mut stack: ArrayVec<Piece, STACK> = ArrayVec::new();
    stack.push(Piece {
        s: [1.0, 0.5],
        g: [g1, gm, g0],
        x: [x1, xm],
    });
    stack.push(Piece {
        s: [0.0, 0.5],
        g: [g0, gm, g1],
        x: [x0, xm],
    });
    let mut evaluations = 1;
    while let Some(piece) = stack.pop() {
        let Piece {
            s: [sa, sb],
            g,
            x: [xa, xb],
        } = piece;
        let h = (sb - sa).abs();
        let target = level + tolerance;
        if xa.max(xb) + curvature * h * h / 8.0 <= target {
            continue;
        }
        let error = third(xa, xb, h) * EXTRAPOLATION_ERROR * h * h * h;
        if parabola_max(g) + error <= in_g(target)
            || h < MIN_PIECE
            || evaluations >= MAX_EVALUATIONS
            || stack.len() + 2 > STACK
        {
            continue;
        }
        let mid = 0.5 * (sa + sb);
        let (gm, xm) = measure(mid);
        evaluations += 1;
        if xm > level {
            level = xm;
            best = Some((mid, xm));
        }
        // The half with the larger end is searched first (pushed last):
        // it raises the level soonest, which prunes the other.
        let a_side = Piece {
            s: [sa, mid],
            g: [g[0], gm, g[1]],
            x: [xa, xm],
        };
        let b_side = Piece {
            s: [sb, mid],
            g: [g[1], gm, g[0]],
            x: [xb, xm],
        };
        let (first, later) = if g[0] >= g[1] {
            (a_side, b_side)
        } else {
            (b_side, a_side)
        };
        stack.push(later);
        stack.push(first);
    }
    best
}

/// The largest value of `f` over [0, 1] when no bound is known: `n + 1`
/// equally spaced samples, then a golden-section search on the two
/// intervals around the best sample. Not a proof: used only where the
/// law of a block has no derivative bound (tool posture control, whose
/// rotary angles come from the inverse kinematics of each direction).
pub fn sampled_max(f: impl Fn(f64) -> f64, n: u32) -> (f64, f64) {
    let n = n.max(2);
    sampled_max_from(|k| f(f64::from(k) / f64::from(n)), &f, n)
}

/// [`sampled_max`] with the samples given: `sample(k)` is `f(k/n)`
/// (`n` at least 2), worked out already or more cheaply than `f`.
pub fn sampled_max_from(sample: impl Fn(u32) -> f64, f: impl Fn(f64) -> f64, n: u32) -> (f64, f64) {
    let mut best = (0.0, sample(0));
    for k in 1..=n {
        let v = sample(k);
        if v > best.1 {
            best = (f64::from(k) / f64::from(n), v);
        }
    }
    let h = 1.0 / f64::from(n);
    let (a, b) = ((best.0 - h).max(0.0), (best.0 + h).min(1.0));
    let (low, s) = fiveaxis_control::search::golden_minimum(|s| -f(s), a, b);
    if -low > best.1 {
        best = (s, -low);
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use fiveaxis_machine::rotation;

    #[test]
    fn maximize_finds_the_peak_of_a_sine_within_the_tolerance() {
        // sin(3s + 0.2) peaks at s = (π/2 − 0.2)/3 with value 1;
        // |f''| ≤ 9, |f'''| ≤ 27.
        let f = |s: f64| (3.0 * s + 0.2).sin();
        let ends = [f(0.0), f(1.0)];
        let (s, v) = maximize(f, 9.0, 27.0, 0.0, ends).expect("above 0");
        assert!((v - 1.0).abs() <= EXTREMUM_TOLERANCE, "{v}");
        assert!((s - (std::f64::consts::FRAC_PI_2 - 0.2) / 3.0).abs() < 1e-4);
        assert_eq!(maximize(f, 9.0, 27.0, 1.0, ends), None);
        // Below its ends: the larger end.
        let g = |s: f64| -(s - 2.0).powi(2);
        assert_eq!(
            maximize(g, 2.0, 0.0, -10.0, [g(0.0), g(1.0)]),
            Some((1.0, -1.0))
        );
    }

    #[test]
    fn turned_point_bounds_hold_on_a_circle() {
        // A point 10 from the Z axis turned by 90°: speed 10·π/2.
        let m = Moving::fixed(Vec3::new(10.0, 0.0, 0.0)).turned(
            &Vec3::z_axis(),
            &Vec3::zeros(),
            0.0,
            90.0,
        );
        let w = std::f64::consts::FRAC_PI_2;
        assert!((m.speed - 10.0 * w).abs() < 1e-12);
        assert!((m.curvature - 10.0 * w * w).abs() < 1e-12);
    }

    #[test]
    fn the_third_derivative_bound_holds_on_a_turned_moving_point() {
        // A point on a line turned about a tilted line: finite third
        // differences stay within the jerk bound.
        let axis = Unit::new_normalize(Vec3::new(0.3, -0.4, 0.85));
        let center = Vec3::new(1.0, 2.0, -3.0);
        let (a0, b0) = (Vec3::new(4.0, 1.0, 2.0), Vec3::new(-2.0, 5.0, 7.0));
        let m = Moving::line(a0, b0).turned(&axis, &center, 20.0, 130.0);
        let p = |s: f64| center + rotation(&axis, 20.0 + 130.0 * s) * (a0 + (b0 - a0) * s - center);
        let h = 1e-3;
        let mut worst: f64 = 0.0;
        for k in 0..997 {
            let s = f64::from(k) * h;
            let d3 = p(s + 3.0 * h) - 3.0 * p(s + 2.0 * h) + 3.0 * p(s + h) - p(s);
            worst = worst.max(d3.norm() / (h * h * h));
        }
        assert!(worst <= m.jerk, "{worst} > {}", m.jerk);
        assert!(worst > 0.2 * m.jerk, "bound {} far above {worst}", m.jerk);
    }

    #[test]
    fn maximize_norm_finds_the_farthest_point_of_a_helix() {
        // (10·cos 5s, 10·sin 5s + 3, 4s): |f'| ≤ 54, |f''| = 250 and
        // |f'''| = 1250.
        let f = |s: f64| {
            Vec3::new(
                10.0 * (5.0 * s).cos(),
                10.0 * (5.0 * s).sin() + 3.0,
                4.0 * s,
            )
        };
        let law = Moving {
            at0: f(0.0),
            speed: 54.0,
            curvature: 250.0,
            jerk: 1250.0,
        };
        let ends = [f(0.0), f(1.0)];
        let tolerance = 1e-9;
        let (s, v) = maximize_norm(f, &law, 0.0, ends, tolerance).expect("above 0");
        let (_, sampled) = sampled_max(|s| f(s).norm(), 20_000);
        assert!((f(s).norm() - v).abs() < 1e-12, "reached where it says");
        assert!(sampled <= v + tolerance, "{sampled} above {v}");
        assert!(v <= sampled + 1e-9, "{v} above the sampled {sampled}");
        assert_eq!(maximize_norm(f, &law, v, ends, tolerance), None);
    }

    #[test]
    fn sampled_max_refines_between_samples() {
        let f = |s: f64| -(s - 0.3137).powi(2);
        let (s, v) = sampled_max(f, 4);
        assert!((s - 0.3137).abs() < 1e-6 && v > -1e-12);
    }
}
