//! Bound and refine: the largest value of a function of the block
//! parameter `s` found to within a proven tolerance, from a bound on its
//! second derivative.
//!
//! Every motion law of a block is built from points that move linearly or
//! on circles in `s` and are turned about rotation lines by angles linear
//! in `s`. [`Moving`] carries, through those steps, where a point is at
//! `s = 0` and bounds on the size of its first and second derivatives in
//! `s` (`|p'| ≤ speed`, `|p''| ≤ curvature`). A function with
//! `|f''| ≤ M` stays within `M·h²/8` of the chord of its values over a
//! piece of length `h` (the error of linear interpolation), so over that
//! piece it is at most the larger end value plus `M·h²/8`. [`maximize`]
//! halves pieces until that bound is below the best value found (plus
//! [`EXTREMUM_TOLERANCE`]): the value it returns is reached, and nothing in
//! the block exceeds it by more than the tolerance. The bound shrinks with
//! the square of the piece, so a few dozen evaluations settle a block.

use fiveaxis_control::TipPath;
use fiveaxis_machine::{Vec3, rotation};
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
}

impl Moving {
    /// A point that stays.
    pub fn fixed(p: Vec3) -> Self {
        Self {
            at0: p,
            speed: 0.0,
            curvature: 0.0,
        }
    }

    /// From `a` to `b` linearly.
    pub fn line(a: Vec3, b: Vec3) -> Self {
        Self {
            at0: a,
            speed: (b - a).norm(),
            curvature: 0.0,
        }
    }

    /// Along a tip path: `r(s)·(cos θ·u + sin θ·v) + rise·s·n` with `r`
    /// and `θ` linear in `s` has `|p'| ≤ |Δr| + r·|sweep| + |rise|` and
    /// `|p''| ≤ 2·|Δr|·|sweep| + r·sweep²`.
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
                }
            }
        }
    }

    /// The point turned about the line through `center` along `axis` by
    /// `angle0 + delta·s` degrees. With `q` the point and `R` the turn,
    /// `p = c + R(q − c)`: `|p'| ≤ ω·ρ + |q'|` and
    /// `|p''| ≤ ω²·ρ + 2ω·|q'| + |q''|`, where `ω` is the turn rate in
    /// radians per unit `s` and `ρ` bounds the distance of `q` from the
    /// line (its distance at `s = 0` plus how far it can move).
    #[must_use]
    pub fn turned(self, axis: &Unit<Vec3>, center: &Vec3, angle0: f64, delta: f64) -> Self {
        let w = delta.to_radians().abs();
        let rel = self.at0 - center;
        let k = axis.as_ref();
        let rho = (rel - k * k.dot(&rel)).norm() + self.speed;
        Self {
            at0: center + rotation(axis, angle0) * rel,
            speed: w * rho + self.speed,
            curvature: w * w * rho + 2.0 * w * self.speed + self.curvature,
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
        }
    }

    /// The difference of two moving points.
    #[must_use]
    pub fn minus(self, other: Self) -> Self {
        Self {
            at0: self.at0 - other.at0,
            speed: self.speed + other.speed,
            curvature: self.curvature + other.curvature,
        }
    }
}

/// The largest size of `f(s)` over `s` in [0, 1], if it is above `floor`:
/// `(s, size)` where it is reached. `f` gives a value whose `size` is
/// measured (a coordinate, or the length of a vector); `curvature` bounds
/// the second derivative of that value (of each coordinate, or of the
/// vector's length of change), so that the size over a piece is at most
/// the larger end size plus `curvature·h²/8`. `ends` are `f(0)`, `f(1)`.
///
/// `None` proves that no value exceeds `floor + EXTREMUM_TOLERANCE`.
pub fn maximize<V: Copy>(
    f: impl Fn(f64) -> V,
    size: impl Fn(&V) -> f64,
    curvature: f64,
    floor: f64,
    ends: [V; 2],
) -> Option<(f64, f64)> {
    maximize_within(f, size, curvature, floor, ends, EXTREMUM_TOLERANCE)
}

/// [`maximize`] to a tolerance of the caller's: the true maximum lies at
/// most `tolerance` above the value returned.
pub fn maximize_within<V: Copy>(
    f: impl Fn(f64) -> V,
    size: impl Fn(&V) -> f64,
    curvature: f64,
    floor: f64,
    ends: [V; 2],
    tolerance: f64,
) -> Option<(f64, f64)> {
    let mut level = floor;
    let mut best = None;
    for (s, v) in [(0.0, &ends[0]), (1.0, &ends[1])] {
        let x = size(v);
        if x > level {
            level = x;
            best = Some((s, x));
        }
    }
    let mut stack = [(0.0, 0.0, 1.0, 0.0); STACK];
    stack[0] = (0.0, size(&ends[0]), 1.0, size(&ends[1]));
    let mut depth = 1;
    // Values at piece ends are kept as sizes; the vectors themselves are
    // not needed once measured.
    let mut evaluations = 0;
    while depth > 0 {
        depth -= 1;
        let (s0, x0, s1, x1) = stack[depth];
        let h = s1 - s0;
        let bound = x0.max(x1) + curvature * h * h / 8.0;
        if bound <= level + tolerance
            || h < MIN_PIECE
            || evaluations >= MAX_EVALUATIONS
            || depth + 2 > STACK
        {
            continue;
        }
        let mid = 0.5 * (s0 + s1);
        let xm = size(&f(mid));
        evaluations += 1;
        if xm > level {
            level = xm;
            best = Some((mid, xm));
        }
        // The half with the larger end is searched first: it raises the
        // level soonest, which prunes the other.
        let (first, second) = if x1 >= x0 {
            ((s0, x0, mid, xm), (mid, xm, s1, x1))
        } else {
            ((mid, xm, s1, x1), (s0, x0, mid, xm))
        };
        stack[depth] = first;
        stack[depth + 1] = second;
        depth += 2;
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
    let mut best = (0.0, f(0.0));
    for k in 1..=n {
        let s = f64::from(k) / f64::from(n);
        let v = f(s);
        if v > best.1 {
            best = (s, v);
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

    #[test]
    fn maximize_finds_the_peak_of_a_sine_within_the_tolerance() {
        // sin(3s + 0.2) peaks at s = (π/2 − 0.2)/3 with value 1; |f''| ≤ 9.
        let f = |s: f64| (3.0 * s + 0.2).sin();
        let (s, v) = maximize(f, |x| *x, 9.0, 0.0, [f(0.0), f(1.0)]).expect("above 0");
        assert!((v - 1.0).abs() <= EXTREMUM_TOLERANCE, "{v}");
        assert!((s - (std::f64::consts::FRAC_PI_2 - 0.2) / 3.0).abs() < 1e-4);
        assert_eq!(maximize(f, |x| *x, 9.0, 1.0, [f(0.0), f(1.0)]), None);
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
    fn sampled_max_refines_between_samples() {
        let f = |s: f64| -(s - 0.3137).powi(2);
        let (s, v) = sampled_max(f, 4);
        assert!((s - 0.3137).abs() < 1e-6 && v > -1e-12);
    }
}
