//! Inverse kinematics: the rotary angles that point the tool along a
//! direction, and the linear axes that put the tip on a point.
//!
//! Two rotary axes make the orientation equation `R_H·t0 = R_T·v` a
//! Paden–Kahan subproblem 2 (`R(ωa, θa)·R(ωb, θb)·p = q`), solved in closed
//! form for any axis directions, nutating heads and tables included:
//!
//! * head-head `[h0, h1]`: `R(ω0, θ0)·R(ω1, θ1)·t0 = v`;
//! * table-table `[t0, t1]`: `R(ω0, θ0)·R(ω1, θ1)·v = t0`;
//! * mixed: `R(ωt, −θt)·R(ωh, θh)·t0 = v`.
//!
//! It has at most two solutions. When the direction lies on the line of the
//! axis applied first (p ∥ ωb) or last (q ∥ ωa), that axis can take any
//! angle: it holds the angle it has, and the other axis alone meets the
//! direction (subproblem 1). The answer is exact: forward kinematics of it
//! gives the commanded direction to rounding.

use nalgebra::{Rotation3, Unit};

use crate::kinematics::{rotation, turn_about};

use crate::{Joints, Machine, Side, Vec3};

/// Below this sine of the angle between a direction and a rotation line,
/// the rotation line counts as through the direction and its angle is free
/// (the singular point).
pub const SINGULAR_TOLERANCE: f64 = 1e-12;

/// How far a direction may miss the reachable set and still be met, as a
/// squared length (rounding of the subproblem arithmetic).
const REACH_TOLERANCE: f64 = 1e-12;

/// Up to two pairs of rotary angles (degrees, in (−180, 180]) for the two
/// rotary axes in machine-file order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orientations {
    pairs: [[f64; 2]; 2],
    len: usize,
    /// Which axis (0 or 1, file order) was free at a singular direction and
    /// kept its held angle.
    pub free_axis: Option<usize>,
}

impl Orientations {
    fn none() -> Self {
        Self {
            pairs: [[0.0; 2]; 2],
            len: 0,
            free_axis: None,
        }
    }

    fn push(&mut self, pair: [f64; 2]) {
        if self.len < 2 && !self.pairs[..self.len].contains(&pair) {
            self.pairs[self.len] = pair;
            self.len += 1;
        }
    }

    /// The angle pairs found.
    pub fn pairs(&self) -> &[[f64; 2]] {
        &self.pairs[..self.len]
    }

    /// Whether the direction cannot be reached.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// The orientation equation `R(ωa, θa)·R(ωb, θb)·p = q` of a machine, with
/// the file index and angle sign of `a` and `b`.
struct Subproblem {
    file_index: [usize; 2],
    sign: [f64; 2],
    wa: Unit<Vec3>,
    wb: Unit<Vec3>,
    p: Vec3,
    q: Vec3,
}

/// Angle in degrees that turns `p` about `axis` onto `q` (subproblem 1),
/// both projected onto the plane normal to `axis`; `None` when `p` lies on
/// the axis (any angle does).
pub fn turn_angle(axis: &Unit<Vec3>, p: &Vec3, q: &Vec3) -> Option<f64> {
    let w = axis.into_inner();
    let pp = p - w * w.dot(p);
    let qp = q - w * w.dot(q);
    if pp.norm() <= SINGULAR_TOLERANCE * p.norm().max(1.0) {
        return None;
    }
    Some(w.dot(&pp.cross(&qp)).atan2(pp.dot(&qp)).to_degrees())
}

/// `degrees` reduced to (−180, 180].
pub fn principal(degrees: f64) -> f64 {
    // Most angles are within a turn of the range: no division for them.
    if degrees > -180.0 && degrees <= 180.0 {
        return degrees;
    }
    if degrees > 180.0 && degrees <= 540.0 {
        return degrees - 360.0;
    }
    if degrees <= -180.0 && degrees > -540.0 {
        return degrees + 360.0;
    }
    let r = degrees.rem_euclid(360.0);
    if r > 180.0 { r - 360.0 } else { r }
}

impl Machine {
    /// The rotary angle pairs that point the tool along `dir` (a unit
    /// vector in the table frame). `held` gives the angles a free axis
    /// keeps at a singular direction. Machines with other than two rotary
    /// axes have no pairs.
    pub fn orientations(&self, dir: &Vec3, held: [f64; 2]) -> Orientations {
        if self.rotary.len() != 2 {
            return Orientations::none();
        }
        let Subproblem {
            file_index,
            sign,
            wa,
            wb,
            p,
            q,
        } = self.subproblem(dir);
        let held_ab = [sign[0] * held[file_index[0]], sign[1] * held[file_index[1]]];
        let mut out = Orientations::none();
        let mut free = None;
        for [a, b] in subproblem_2(&wa, &wb, &p, &q, held_ab, &mut free) {
            let mut pair = [0.0; 2];
            pair[file_index[0]] = principal(sign[0] * a);
            pair[file_index[1]] = principal(sign[1] * b);
            out.push(pair);
        }
        out.free_axis = free.map(|k| file_index[k]);
        out
    }

    /// The angle pairs of two chosen rotary axes `pair` (rotary numbers,
    /// bed outwards, `pair[0]` before `pair[1]`) that point the tool along
    /// `dir` (a unit vector in the table frame) with every other rotary
    /// axis held at its angle in `joints` (a three-rotary machine turning
    /// its two head axes with the table standing). Each pair gives the
    /// angles of `pair[0]` then `pair[1]`; a free axis at a singular
    /// direction keeps its angle in `joints`.
    ///
    /// The tool direction in the table frame is a product of turns applied
    /// to `t0`: the head axes bed outwards, then the table axes undone
    /// from the outermost: `v = T_m(−θ)…T_1(−θ)·H_1(θ)…H_n(θ)·t0`. With the
    /// others held, `v = P·F_a(θa)·M·F_b(θb)·S·t0`, and `F_a·M·F_b =
    /// R(ωa, ±θa)·R(M·ωb, ±θb)·M`, subproblem 2 with `p = M·S·t0` and
    /// `q = P⁻¹·v`.
    pub fn orientations_held(&self, dir: &Vec3, pair: [usize; 2], joints: &Joints) -> Orientations {
        let n = self.rotary.len();
        if pair[0] >= n || pair[1] >= n || pair[0] == pair[1] {
            return Orientations::none();
        }
        let first = self.linear.len();
        // The turns in the order they multiply (leftmost first): the table
        // axes from the outermost in, angle negated; the head axes bed
        // outwards.
        let mut order = [(0usize, 0.0f64); crate::MAX_AXES];
        let mut len = 0;
        for k in (0..n).rev().filter(|&k| self.rotary[k].on == Side::Table) {
            order[len] = (k, -1.0);
            len += 1;
        }
        for k in (0..n).filter(|&k| self.rotary[k].on == Side::Head) {
            order[len] = (k, 1.0);
            len += 1;
        }
        let order = &order[..len];
        let Some(ia) = order
            .iter()
            .position(|&(k, _)| k == pair[0] || k == pair[1])
        else {
            return Orientations::none();
        };
        let Some(ib) = order
            .iter()
            .rposition(|&(k, _)| k == pair[0] || k == pair[1])
        else {
            return Orientations::none();
        };
        let held = |range: &[(usize, f64)]| {
            range.iter().fold(Rotation3::identity(), |acc, &(k, sign)| {
                acc * rotation(&self.rotary[k].axis, sign * joints[first + k])
            })
        };
        let p_map = held(&order[..ia]);
        let m_map = held(&order[ia + 1..ib]);
        let s_map = held(&order[ib + 1..]);
        let (ka, sa) = order[ia];
        let (kb, sb) = order[ib];
        let wa = self.rotary[ka].axis;
        let wb = Unit::new_normalize(m_map * self.rotary[kb].axis.into_inner());
        let p = m_map * (s_map * self.tool_direction.into_inner());
        let q = p_map.inverse() * dir;
        let held_ab = [sa * joints[first + ka], sb * joints[first + kb]];
        let mut free = None;
        let mut out = Orientations::none();
        // Which slot of the answer each of a and b fills.
        let slot_a = usize::from(ka != pair[0]);
        for [a, b] in subproblem_2(&wa, &wb, &p, &q, held_ab, &mut free) {
            let mut angles = [0.0; 2];
            angles[slot_a] = principal(sa * a);
            angles[1 - slot_a] = principal(sb * b);
            out.push(angles);
        }
        out.free_axis = free.map(|k| if k == 0 { slot_a } else { 1 - slot_a });
        out
    }

    /// The orientation equation of a two-rotary machine as subproblem 2.
    fn subproblem(&self, dir: &Vec3) -> Subproblem {
        let t0 = self.tool_direction.into_inner();
        // R(ωa, θa)·R(ωb, θb)·p = q: which file axis is a and b, and the
        // sign of its angle (a table axis turns the part the other way
        // relative to the tool).
        let (file_index, sign, p, q) = match (self.rotary[0].on, self.rotary[1].on) {
            (Side::Head, Side::Head) => ([0, 1], [1.0, 1.0], t0, *dir),
            (Side::Table, Side::Table) => ([0, 1], [1.0, 1.0], *dir, t0),
            (Side::Head, Side::Table) => ([1, 0], [-1.0, 1.0], t0, *dir),
            (Side::Table, Side::Head) => ([0, 1], [-1.0, 1.0], t0, *dir),
        };
        let axes = [self.rotary[0].axis, self.rotary[1].axis];
        Subproblem {
            file_index,
            sign,
            wa: axes[file_index[0]],
            wb: axes[file_index[1]],
            p,
            q,
        }
    }

    /// How far inside the set of tool directions the machine can reach
    /// `dir` (a unit vector in the table frame) lies: positive inside,
    /// negative outside, 0 on its edge, where the two solutions meet. It
    /// is a quadratic form in `dir` (the squared third coordinate of the
    /// subproblem's intermediate vector, times the squared sine of the
    /// angle between the axes), so it changes smoothly along a path.
    /// Machines with other than two rotary axes, or two parallel ones,
    /// give 1 where `dir` is reachable and −1 where not.
    pub fn reach_margin(&self, dir: &Vec3) -> f64 {
        let fallback = || {
            if self.orientations(dir, [0.0, 0.0]).is_empty() {
                -1.0
            } else {
                1.0
            }
        };
        if self.rotary.len() != 2 {
            return fallback();
        }
        let Subproblem { wa, wb, p, q, .. } = self.subproblem(dir);
        let d = wa.dot(&wb);
        if 1.0 - d * d <= SINGULAR_TOLERANCE {
            return fallback();
        }
        let (aq, bp) = (wa.dot(&q), wb.dot(&p));
        let alpha = (aq - d * bp) / (1.0 - d * d);
        let beta = (bp - d * aq) / (1.0 - d * d);
        p.norm_squared() - alpha * alpha - beta * beta - 2.0 * alpha * beta * d
    }

    /// Machine position of the linear axes X, Y, Z that put the tool tip
    /// of length `tool_length` on `tip` (table frame) with the rotary axes
    /// (and a quill along the tool) at the positions in `joints`.
    pub fn gauge_for_tip(&self, joints: &Joints, tip: &Vec3, tool_length: f64) -> Vec3 {
        // The maps of `Machine::chain` applied to the two points directly,
        // each axis turning its side's point about its line, innermost
        // first (Rodrigues' formula; no matrices composed).
        let t0 = self.tool_direction.into_inner();
        let mut on = [*tip, (self.quill(joints) - tool_length) * t0];
        for (k, axis) in self.rotary.iter().enumerate().rev() {
            let p = &mut on[usize::from(axis.on == Side::Head)];
            *p = turn_about(&axis.axis, &axis.center, joints[self.rotary_index(k)], p);
        }
        on[0] - on[1]
    }

    /// Machine position of X, Y, Z that puts the tip on `tip` (table
    /// frame) with the quill ([`crate::Along::Tool`]) at 0: the programmed
    /// point of TCPC and of the tilted working plane. A quill then moves
    /// the tip from there along the tool, as LinuxCNC's 5axiskins moves it
    /// with W in TCP mode ("g0w-10 ; simulate drill"). Without a quill it
    /// is [`Machine::gauge_for_tip`].
    pub fn gauge_for_programmed_tip(&self, joints: &Joints, tip: &Vec3, tool_length: f64) -> Vec3 {
        match self.quill_index() {
            Some(i) if joints[i] != 0.0 => {
                let mut j = *joints;
                j[i] = 0.0;
                self.gauge_for_tip(&j, tip, tool_length)
            }
            _ => self.gauge_for_tip(joints, tip, tool_length),
        }
    }
}

/// Solves `R(ωa, θa)·R(ωb, θb)·p = q` for unit `p`, `q`: up to two
/// `[θa, θb]` in degrees. A free angle (p on ωb, or q on ωa) keeps its
/// value from `held` and is reported in `free`.
fn subproblem_2(
    wa: &Unit<Vec3>,
    wb: &Unit<Vec3>,
    p: &Vec3,
    q: &Vec3,
    held: [f64; 2],
    free: &mut Option<usize>,
) -> Vec2Solutions {
    let mut out = Vec2Solutions::default();
    // q on ωa: θa is free; hold it and turn p about ωb onto R(ωa, −θa)·q.
    if wa.cross(q).norm() <= SINGULAR_TOLERANCE {
        *free = Some(0);
        match turn_angle(wb, p, q) {
            Some(b) if reaches(wb, p, q) => out.push([held[0], b]),
            Some(_) => {}
            // p on ωb as well: both free; reachable only if p is q.
            None if (p - q).norm() <= REACH_TOLERANCE.sqrt() => out.push(held),
            None => {}
        }
        return out;
    }
    // p on ωb: θb is free; hold it and turn p about ωa onto q.
    if wb.cross(p).norm() <= SINGULAR_TOLERANCE {
        *free = Some(1);
        if let Some(a) = turn_angle(wa, p, q).filter(|_| reaches(wa, p, q)) {
            out.push([a, held[1]]);
        }
        return out;
    }
    let (ua, ub) = (wa.into_inner(), wb.into_inner());
    let d = ua.dot(&ub);
    let cross = ua.cross(&ub);
    let cross2 = cross.norm_squared();
    if cross2 <= SINGULAR_TOLERANCE {
        // Parallel lines: only the sum of the two turns matters. θa holds,
        // θb makes up the rest.
        *free = Some(0);
        let s = d.signum();
        if let Some(total) = turn_angle(wa, p, q).filter(|_| reaches(wa, p, q)) {
            out.push([held[0], s * (total - held[0])]);
        }
        return out;
    }
    let (aq, bp) = (ua.dot(q), ub.dot(p));
    let alpha = (aq - d * bp) / (1.0 - d * d);
    let beta = (bp - d * aq) / (1.0 - d * d);
    let gamma2 = (p.norm_squared() - alpha * alpha - beta * beta - 2.0 * alpha * beta * d) / cross2;
    if gamma2 < -REACH_TOLERANCE {
        return out;
    }
    let gamma = gamma2.max(0.0).sqrt();
    for g in [gamma, -gamma] {
        let c = alpha * ua + beta * ub + g * cross;
        if let (Some(b), Some(a)) = (turn_angle(wb, p, &c), turn_angle(wa, &c, q)) {
            out.push([a, b]);
        }
    }
    out
}

/// Whether turning `p` about `axis` can reach `q` (same height along it).
fn reaches(axis: &Unit<Vec3>, p: &Vec3, q: &Vec3) -> bool {
    let w = axis.into_inner();
    (w.dot(p) - w.dot(q)).abs() <= REACH_TOLERANCE.sqrt()
        && (p.norm() - q.norm()).abs() <= REACH_TOLERANCE.sqrt()
}

/// At most two angle pairs, without allocation.
#[derive(Clone, Copy, Debug, Default)]
struct Vec2Solutions {
    pairs: [[f64; 2]; 2],
    len: usize,
}

impl Vec2Solutions {
    fn push(&mut self, pair: [f64; 2]) {
        if self.len < 2 {
            self.pairs[self.len] = pair;
            self.len += 1;
        }
    }
}

impl IntoIterator for Vec2Solutions {
    type Item = [f64; 2];
    type IntoIter = std::iter::Take<std::array::IntoIter<[f64; 2], 2>>;

    fn into_iter(self) -> Self::IntoIter {
        self.pairs.into_iter().take(self.len)
    }
}
