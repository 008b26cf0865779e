//! Speed changes along one stretch of path, in one dimension (the path
//! parameter s, mm): how far a speed change takes, how long, how fast one
//! can get over a distance, and the fastest accelerate–cruise–decelerate
//! profile of a stretch.
//!
//! Every speed change starts and ends with zero acceleration. Without a
//! jerk limit (`jerk = f64::INFINITY`) it is a constant acceleration `acc`
//! (a trapezoid in time); with one it is the jerk-limited change of the
//! double-S profile: jerk `+jerk` until the acceleration reaches `acc`,
//! constant `acc`, jerk `-jerk` back to zero, or, when the change is too
//! small to reach `acc` (`dv < acc²/jerk`), two jerk phases meeting at the
//! peak acceleration `√(dv·jerk)` (L. Biagiotti, C. Melchiorri, *Trajectory
//! Planning for Automatic Machines and Robots*, Springer 2008, §3.4). The
//! velocity of such a change is point-symmetric about its middle, so its
//! distance is the mean speed `(v0 + v1)/2` times its duration.
//!
//! With `jerk = ∞`, `acc²/jerk = 0` and the jerk formulas reduce exactly to
//! the trapezoid ones, so one set of formulas serves both.

/// Iterations of the bracketed root search for the peak speed (each one at
/// least halves the bracket every second step).
const ROOT_ITERATIONS: usize = 200;

/// Acceleration and jerk limits of a stretch along the path (mm/s², mm/s³;
/// infinite when the stretch moves no axis, or no axis has a jerk limit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Dynamics {
    pub acc: f64,
    pub jerk: f64,
}

impl Dynamics {
    /// The speed change above which the acceleration reaches `acc`.
    fn full(self) -> f64 {
        self.acc * self.acc / self.jerk
    }
}

/// Distance (mm) a speed change between `v0` and `v1` (mm/s) takes.
pub(crate) fn change_distance(v0: f64, v1: f64, d: Dynamics) -> f64 {
    if d.acc.is_infinite() {
        return 0.0;
    }
    (v0 + v1) * 0.5 * change_time(v0, v1, d)
}

/// Duration (s) of a speed change between `v0` and `v1`.
pub(crate) fn change_time(v0: f64, v1: f64, d: Dynamics) -> f64 {
    if d.acc.is_infinite() {
        return 0.0;
    }
    let dv = (v1 - v0).abs();
    let full = d.full();
    if dv >= full {
        dv / d.acc + d.acc / d.jerk
    } else {
        2.0 * (dv / d.jerk).sqrt()
    }
}

/// The highest speed reachable from `v0` over `len` mm (also the highest
/// speed from which `v0` can be reached by braking over `len`).
pub(crate) fn reach(v0: f64, len: f64, d: Dynamics) -> f64 {
    if d.acc.is_infinite() {
        return f64::INFINITY;
    }
    let c = d.full();
    // Acceleration reaches `acc`: (v1² − v0²)/(2A) + (v0 + v1)·A/(2J) = len.
    let v1 = 0.5 * (-c + ((2.0 * v0 - c).powi(2) + 8.0 * d.acc * len).sqrt());
    if v1 - v0 >= c {
        return v1;
    }
    // It does not: (2·v0 + y²)·y = len·√J with y = √(v1 − v0).
    let y = cubic_root(2.0 * v0, len * d.jerk.sqrt());
    v0 + y * y
}

/// The real root y ≥ 0 of y³ + p·y − q = 0 for p ≥ 0, q ≥ 0 (one real
/// root: the left side increases). Closed form, then two Newton steps to
/// clean up rounding.
fn cubic_root(p: f64, q: f64) -> f64 {
    if q <= 0.0 {
        return 0.0;
    }
    let mut y = if p * p * p <= 1e-12 * q * q {
        q.cbrt()
    } else {
        // Hyperbolic form of Cardano's root for a positive linear term.
        let r = (p / 3.0).sqrt();
        2.0 * r * ((1.5 * q / (p * r)).asinh() / 3.0).sinh()
    };
    for _ in 0..2 {
        let f = y * y * y + p * y - q;
        let df = 3.0 * y * y + p;
        if df > 0.0 {
            y -= f / df;
        }
    }
    y.max(0.0)
}

/// The fastest profile of a stretch of `len` mm entered at `v0` and left at
/// `v1`, no faster than `cap`: its peak speed (reached with zero
/// acceleration, then held) and its duration.
///
/// `v0` and `v1` must be joinable over `len` (the look-ahead passes make
/// them so); rounding beyond that is absorbed.
pub(crate) fn stretch(v0: f64, v1: f64, len: f64, cap: f64, d: Dynamics) -> Shape {
    let low = v0.max(v1);
    let excess = |vp: f64| change_distance(v0, vp, d) + change_distance(vp, v1, d) - len;
    let peak = if d.acc.is_infinite() || excess(cap) <= 0.0 {
        cap
    } else {
        let c = d.full();
        // Both changes reach `acc`: a quadratic in the peak speed.
        let k = (v0 + v1) * c - v0 * v0 - v1 * v1 - 2.0 * d.acc * len;
        let vp = 0.5 * (-c + (c * c - 2.0 * k).max(0.0).sqrt());
        if vp - low >= c && vp <= cap {
            vp
        } else {
            root(excess, low, cap)
        }
    };
    let peak = peak.max(low);
    let up = change_distance(v0, peak, d);
    let down = change_distance(peak, v1, d);
    let cruise = (len - up - down).max(0.0);
    let cruise_time = if cruise > 0.0 { cruise / peak } else { 0.0 };
    Shape {
        peak,
        cruise,
        time: change_time(v0, peak, d) + cruise_time + change_time(peak, v1, d),
    }
}

/// The peak speed, cruise length (mm) and duration (s) of a stretch.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Shape {
    pub peak: f64,
    pub cruise: f64,
    pub time: f64,
}

/// The root of the increasing function `f` in `[lo, hi]` with `f(lo) ≤ 0 <
/// f(hi)`: regula falsi with the Illinois correction, bounded by
/// [`ROOT_ITERATIONS`], ending when the bracket no longer shrinks.
fn root(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let mut f_lo = f(lo);
    if f_lo >= 0.0 {
        return lo;
    }
    let mut f_hi = f(hi);
    let mut side = 0i8;
    for _ in 0..ROOT_ITERATIONS {
        let x = if f_hi.is_finite() && f_hi > f_lo {
            (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        } else {
            0.5 * (lo + hi)
        };
        let x = if x > lo && x < hi { x } else { 0.5 * (lo + hi) };
        if x <= lo || x >= hi {
            break;
        }
        let fx = f(x);
        if fx == 0.0 {
            return x;
        }
        if fx < 0.0 {
            lo = x;
            f_lo = fx;
            if side == -1 {
                f_hi *= 0.5;
            }
            side = -1;
        } else {
            hi = x;
            f_hi = fx;
            if side == 1 {
                f_lo *= 0.5;
            }
            side = 1;
        }
    }
    lo
}

/// One piece of constant jerk of the planned motion along the path: from
/// time `t` for `duration` seconds, the path parameter is
/// `s(τ) = s + v·τ + a·τ²/2 + j·τ³/6`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    /// Start time, s.
    pub t: f64,
    /// Duration, s.
    pub duration: f64,
    /// Path parameter at the start, mm.
    pub s: f64,
    /// Speed at the start, mm/s.
    pub v: f64,
    /// Acceleration at the start, mm/s².
    pub a: f64,
    /// Jerk, constant over the piece, mm/s³.
    pub j: f64,
}

/// Appends the pieces of a speed change from `v0` to `v1` starting at time
/// `t` and parameter `s`; returns the time and parameter at its end.
pub(crate) fn change_pieces(
    v0: f64,
    v1: f64,
    d: Dynamics,
    t: f64,
    s: f64,
    out: &mut Vec<Piece>,
) -> (f64, f64) {
    let (pieces, count) = change_phases(v0, v1, d, t, s);
    out.extend_from_slice(&pieces[..count]);
    let end = match pieces[..count].last() {
        Some(last) => advance(*last),
        None => piece(t, 0.0, s, v0, 0.0, 0.0),
    };
    (end.t, end.s)
}

/// The pieces of a speed change from `v0` to `v1` (at most three, the
/// first `count` of the array) starting at time `t` and parameter `s`.
fn change_phases(v0: f64, v1: f64, d: Dynamics, t: f64, s: f64) -> ([Piece; 3], usize) {
    let mut pieces = [piece(t, 0.0, s, v0, 0.0, 0.0); 3];
    let dv = (v1 - v0).abs();
    if dv == 0.0 || d.acc.is_infinite() {
        return (pieces, 0);
    }
    let sign = if v1 > v0 { 1.0 } else { -1.0 };
    if d.jerk.is_infinite() {
        pieces[0] = piece(t, dv / d.acc, s, v0, sign * d.acc, 0.0);
        return (pieces, 1);
    }
    // (duration, jerk) of each phase, the acceleration starting at zero.
    let phases = if dv >= d.full() {
        let tj = d.acc / d.jerk;
        [
            (tj, sign * d.jerk),
            (dv / d.acc - tj, 0.0),
            (tj, -sign * d.jerk),
        ]
    } else {
        let tj = (dv / d.jerk).sqrt();
        [(tj, sign * d.jerk), (tj, -sign * d.jerk), (0.0, 0.0)]
    };
    let mut p = pieces[0];
    let mut count = 0;
    for (duration, j) in phases {
        if duration > 0.0 {
            p.duration = duration;
            p.j = j;
            pieces[count] = p;
            count += 1;
            p = advance(p);
        }
    }
    (pieces, count)
}

/// Bisection steps that place a time inside a piece: 2⁻⁶⁰ of its duration.
const TIME_AT_ITERATIONS: usize = 60;

/// How long after its start a speed change from `v0` to `v1` has covered
/// `x` mm (clamped to the change: its duration past its distance).
fn change_time_at(v0: f64, v1: f64, d: Dynamics, x: f64) -> f64 {
    let (pieces, count) = change_phases(v0, v1, d, 0.0, 0.0);
    let pieces = &pieces[..count];
    for p in pieces {
        let end = advance(*p);
        if x <= end.s {
            // s(τ) never decreases (the speed stays at least 0): bisection.
            let at =
                |tau: f64| p.s + p.v * tau + p.a * tau * tau / 2.0 + p.j * tau * tau * tau / 6.0;
            let (mut lo, mut hi) = (0.0, p.duration);
            for _ in 0..TIME_AT_ITERATIONS {
                let mid = 0.5 * (lo + hi);
                if at(mid) < x {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            return p.t + 0.5 * (lo + hi);
        }
    }
    pieces.last().map_or(0.0, |p| p.t + p.duration)
}

/// How long after its start a stretch of `shape` entered at `v0`, left at
/// `v1`, has covered `x` mm of its length (0 ≤ x ≤ its length; beyond it,
/// its duration).
pub(crate) fn time_at(v0: f64, v1: f64, shape: Shape, d: Dynamics, x: f64) -> f64 {
    let x = x.max(0.0);
    let up = change_distance(v0, shape.peak, d);
    if x <= up {
        return change_time_at(v0, shape.peak, d, x);
    }
    let up_time = change_time(v0, shape.peak, d);
    let x = x - up;
    if x <= shape.cruise {
        return up_time
            + if shape.peak > 0.0 {
                x / shape.peak
            } else {
                0.0
            };
    }
    let cruise_time = if shape.cruise > 0.0 {
        shape.cruise / shape.peak
    } else {
        0.0
    };
    let down = change_time_at(shape.peak, v1, d, x - shape.cruise);
    (up_time + cruise_time + down).min(shape.time)
}

fn piece(t: f64, duration: f64, s: f64, v: f64, a: f64, j: f64) -> Piece {
    Piece {
        t,
        duration,
        s,
        v,
        a,
        j,
    }
}

/// The state at the end of `p`, as the start of a piece of the same jerk
/// and duration.
pub(crate) fn advance(p: Piece) -> Piece {
    let tau = p.duration;
    Piece {
        t: p.t + tau,
        duration: p.duration,
        s: p.s + p.v * tau + p.a * tau * tau / 2.0 + p.j * tau * tau * tau / 6.0,
        v: p.v + p.a * tau + p.j * tau * tau / 2.0,
        a: p.a + p.j * tau,
        j: p.j,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reach_inverts_the_distance() {
        let d = Dynamics {
            acc: 3000.0,
            jerk: 50_000.0,
        };
        for &(v0, len) in &[(0.0, 0.01), (0.0, 100.0), (200.0, 0.001), (10.0, 5.0)] {
            let v1 = reach(v0, len, d);
            let back = change_distance(v0, v1, d);
            // A small change on top of a high speed loses digits to v1 − v0.
            assert!((back - len).abs() <= 1e-7 * len, "{v0} {len}: {back}");
        }
    }
}
