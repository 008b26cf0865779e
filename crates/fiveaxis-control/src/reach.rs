//! Boxes that hold every machine position of a piece of a TCPC block, by
//! interval arithmetic: the tip's box turned by the table axes over their
//! ranges of angles, less the tool end turned by the head axes. A box
//! inside the soft limits proves the piece cannot over-travel without
//! sampling it.

use fiveaxis_machine::{Joints, Machine, Side, Vec3};

/// A closed interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
}

impl Interval {
    fn point(x: f64) -> Self {
        Self { lo: x, hi: x }
    }

    fn hull(a: f64, b: f64) -> Self {
        Self {
            lo: a.min(b),
            hi: a.max(b),
        }
    }

    fn add(self, o: Self) -> Self {
        Self {
            lo: self.lo + o.lo,
            hi: self.hi + o.hi,
        }
    }

    fn sub(self, o: Self) -> Self {
        Self {
            lo: self.lo - o.hi,
            hi: self.hi - o.lo,
        }
    }

    fn mul(self, o: Self) -> Self {
        let p = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        Self {
            lo: p.into_iter().fold(f64::INFINITY, f64::min),
            hi: p.into_iter().fold(f64::NEG_INFINITY, f64::max),
        }
    }

    fn scale(self, k: f64) -> Self {
        Self::hull(self.lo * k, self.hi * k)
    }

    fn grow(self, margin: f64) -> Self {
        Self {
            lo: self.lo - margin,
            hi: self.hi + margin,
        }
    }
}

/// An axis-aligned box.
pub type Box3 = [Interval; 3];

fn box_of(a: &Vec3, b: &Vec3) -> Box3 {
    [
        Interval::hull(a.x, b.x),
        Interval::hull(a.y, b.y),
        Interval::hull(a.z, b.z),
    ]
}

/// The ranges of cos θ and sin θ for θ from `a` to `b` degrees.
fn trig_ranges(a: f64, b: f64) -> (Interval, Interval) {
    let (lo, hi) = (a.min(b), a.max(b));
    let (sa, ca) = fiveaxis_machine::sin_cos_degrees(lo);
    let (sb, cb) = fiveaxis_machine::sin_cos_degrees(hi);
    let mut cos = Interval::hull(ca, cb);
    let mut sin = Interval::hull(sa, sb);
    if hi - lo >= 360.0 {
        return (
            Interval { lo: -1.0, hi: 1.0 },
            Interval { lo: -1.0, hi: 1.0 },
        );
    }
    // Quarter turns inside the range are where cos and sin peak.
    // Fewer than 360 degrees: at most four quarter turns, whatever the
    // magnitudes.
    let first = (lo / 90.0).ceil();
    for quarter in (0..5).map(|k| first + f64::from(k)) {
        if quarter * 90.0 > hi {
            break;
        }
        match (quarter as i64).rem_euclid(4) {
            0 => cos.hi = 1.0,
            1 => sin.hi = 1.0,
            2 => cos.lo = -1.0,
            _ => sin.lo = -1.0,
        }
    }
    (cos, sin)
}

/// The box of `c + R(k, θ)(v − c)` for `v` in `b` and θ from `a0` to `a1`
/// degrees (Rodrigues: u·cos θ + (k × u)·sin θ + k (k·u)(1 − cos θ)).
fn turn_box(b: &Box3, k: &Vec3, c: &Vec3, a0: f64, a1: f64) -> Box3 {
    if a0 == a1 && a0 == 0.0 {
        return *b;
    }
    let (cos, sin) = trig_ranges(a0, a1);
    if let Some(j) = (0..3).find(|&j| k[j].abs() == 1.0) {
        return turn_box_about_axis(b, j, k[j], c, cos, sin);
    }
    let u = [
        b[0].sub(Interval::point(c.x)),
        b[1].sub(Interval::point(c.y)),
        b[2].sub(Interval::point(c.z)),
    ];
    let cross = [
        u[2].scale(k.y).sub(u[1].scale(k.z)),
        u[0].scale(k.z).sub(u[2].scale(k.x)),
        u[1].scale(k.x).sub(u[0].scale(k.y)),
    ];
    let along = u[0].scale(k.x).add(u[1].scale(k.y)).add(u[2].scale(k.z));
    let versine = Interval::point(1.0).sub(cos);
    let mut out = *b;
    for i in 0..3 {
        out[i] = u[i]
            .mul(cos)
            .add(cross[i].mul(sin))
            .add(along.scale(k[i]).mul(versine))
            .add(Interval::point(c[i]));
    }
    out
}

/// [`turn_box`] for a rotation line along coordinate axis `j` (direction
/// `sign`): that coordinate stays, the other two turn in their plane.
fn turn_box_about_axis(
    b: &Box3,
    j: usize,
    sign: f64,
    c: &Vec3,
    cos: Interval,
    sin: Interval,
) -> Box3 {
    // (p, q) follow j cyclically, so that +e_j turns p towards q.
    let (p, q) = ((j + 1) % 3, (j + 2) % 3);
    let sin = sin.scale(sign);
    let up = b[p].sub(Interval::point(c[p]));
    let uq = b[q].sub(Interval::point(c[q]));
    let mut out = *b;
    out[p] = up.mul(cos).sub(uq.mul(sin)).add(Interval::point(c[p]));
    out[q] = up.mul(sin).add(uq.mul(cos)).add(Interval::point(c[q]));
    out
}

/// The box of X, Y, Z over a piece of a TCPC block: the tip within
/// `tip_box` (table frame, or machine frame when `turning`), the rotary
/// axes moving from `j0` to `j1` (monotonically), tool length `length`.
pub fn gauge_box(
    machine: &Machine,
    tip_box: &Box3,
    turning: bool,
    j0: &Joints,
    j1: &Joints,
    length: f64,
) -> Box3 {
    let first = machine.linear.len();
    let angles = |k: usize| (j0[first + k], j1[first + k]);
    let mut tip = *tip_box;
    if !turning {
        for (k, axis) in machine.rotary.iter().enumerate().rev() {
            if axis.on == Side::Table {
                let (a, b) = angles(k);
                tip = turn_box(&tip, axis.axis.as_ref(), &axis.center, a, b);
            }
        }
    }
    let end = -length * machine.tool_direction.into_inner();
    let mut tool = box_of(&end, &end);
    for (k, axis) in machine.rotary.iter().enumerate().rev() {
        if axis.on == Side::Head {
            let (a, b) = angles(k);
            tool = turn_box(&tool, axis.axis.as_ref(), &axis.center, a, b);
        }
    }
    [
        tip[0].sub(tool[0]),
        tip[1].sub(tool[1]),
        tip[2].sub(tool[2]),
    ]
}

/// The box of a straight piece of tip path from `a` to `b`, grown by
/// `bulge` (for arcs: how far the curve can leave its chord).
pub fn tip_box(a: &Vec3, b: &Vec3, bulge: f64) -> Box3 {
    box_of(a, b).map(|i| i.grow(bulge))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turned_points_stay_in_the_box() {
        let k = Vec3::new(1.0, 2.0, -0.5).normalize();
        let c = Vec3::new(10.0, -20.0, 5.0);
        let b: Box3 = [
            Interval::hull(-3.0, 4.0),
            Interval::hull(1.0, 2.0),
            Interval::hull(-7.0, 0.5),
        ];
        let turned = turn_box(&b, &k, &c, -40.0, 130.0);
        let axis = nalgebra::Unit::new_normalize(k);
        for i in 0..=10 {
            for j in 0..=10 {
                let v = Vec3::new(
                    -3.0 + 0.7 * f64::from(i),
                    1.0 + 0.1 * f64::from(j),
                    -7.0 + 0.75 * f64::from(i),
                );
                for t in 0..=34 {
                    let angle = -40.0 + 5.0 * f64::from(t);
                    let p = c + fiveaxis_machine::rotation(&axis, angle) * (v - c);
                    for d in 0..3 {
                        assert!(
                            p[d] >= turned[d].lo - 1e-9 && p[d] <= turned[d].hi + 1e-9,
                            "{p:?} {turned:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn turned_points_stay_in_the_box_about_coordinate_axes() {
        let c = Vec3::new(10.0, -20.0, 5.0);
        let b: Box3 = [
            Interval::hull(-3.0, 4.0),
            Interval::hull(1.0, 2.0),
            Interval::hull(-7.0, 0.5),
        ];
        for k in [Vec3::x(), -Vec3::y(), Vec3::z(), -Vec3::z()] {
            let turned = turn_box(&b, &k, &c, -40.0, 130.0);
            let axis = nalgebra::Unit::new_normalize(k);
            for i in 0..=10 {
                let v = Vec3::new(
                    -3.0 + 0.7 * f64::from(i),
                    1.0 + 0.1 * f64::from(i),
                    -7.0 + 0.75 * f64::from(i),
                );
                for t in 0..=34 {
                    let p =
                        c + fiveaxis_machine::rotation(&axis, -40.0 + 5.0 * f64::from(t)) * (v - c);
                    for d in 0..3 {
                        assert!(
                            p[d] >= turned[d].lo - 1e-9 && p[d] <= turned[d].hi + 1e-9,
                            "{k:?} {p:?} {turned:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn trig_ranges_include_the_peaks() {
        let (cos, sin) = trig_ranges(-30.0, 100.0);
        assert_eq!(cos.hi, 1.0);
        assert_eq!(sin.hi, 1.0);
        assert!((sin.lo + 0.5).abs() < 1e-12);
        assert!((cos.lo - 100f64.to_radians().cos()).abs() < 1e-12);
    }
}
