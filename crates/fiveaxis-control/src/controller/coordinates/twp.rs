//! LinuxCNC's tilted working plane (TWP): the G codes that the nutating-head
//! demo configurations of LinuxCNC add by REMAP (`[parameters] twp_remap =
//! true` on a `control = "linuxcnc"` machine). The source is the remap
//! author's documentation (the `5axis-twp/README` of Sigma1912's
//! LinuxCNC_Demo_Configs and the configurations' READMEs); the FANUC
//! tilted working plane fills in what it leaves open. Decisions are
//! written in docs/functions.md ("LinuxCNC tilted working plane").
//!
//! Two steps, unlike FANUC's G68.2, which works in the plane at once:
//!
//! 1. **Definition**, no motion, the program stays in the untilted work
//!    coordinate system ("None of these commands cause machine movement"):
//!    * `G68.2 [P0] [Q313] X Y Z I J K R`: true Euler angles, the turns
//!      about moving axes in the order Q names (121, 131, 212, 232, 313,
//!      323; 1 = X, 2 = Y, 3 = Z), I the first, J the second, K the third:
//!      `R = R_q1(I)·R_q2(J)·R_q3(K)` (FANUC G68.2 P0 is Q313).
//!    * `G68.2 P1 [Q123] …`: non-true Euler angles (roll-pitch-yaw), the
//!      turns about the fixed axes of the work coordinate system in the
//!      order Q names (123, 132, 213, 231, 312, 321): `R =
//!      R_q3(K)·R_q2(J)·R_q1(I)` (FANUC G68.2 P1 is Q123).
//!    * `G68.2 P2 Q0 X Y Z R`, `Q1 I J K`, `Q2 I J K`, `Q3 I J K`: three
//!      points (I J K their coordinates in the work coordinate system),
//!      blocks following each other; Q0 (optional, first) shifts the
//!      origin from the first point by X Y Z in the work coordinate
//!      system's axes.
//!    * `G68.2 P3 Q1 X Y Z I J K R`, `Q2 I J K`: the origin, the +X
//!      direction, the +Z direction, 85° to 95° apart; +X made normal.
//!    * `G68.3 X Y Z R`: +Z the tool axis as it stands, +X by FANUC's rule
//!      (`tool_axis_frame`); the origin X Y Z, 0 when left out.
//!    * `G68.4 …`: G68.2's forms given in the plane defined before.
//!
//!    R turns each frame about its own +Z; X Y Z are absolute, 0 when left
//!    out. A plane is defined only in G54 ("TWP can only be defined when
//!    in G54"); G68.4 also in the G59 of an oriented plane.
//! 2. **Orientation**: `G53.1 [P]` turns the two rotary axes of the pair
//!    (the head axes, the table axis held, on a machine with three; both
//!    on a machine with two) so the tool stands along the plane's +Z, the
//!    linear axes standing; `G53.3 [P] X Y Z` turns them and moves to the
//!    plane's point X Y Z in the same rapid move; `G53.6 [P]` turns them
//!    with the tool tip held (TCP). P0 / P1 / P2: the prioritized axis
//!    (`twp_priority`) turns the shortest way, positive only, negative
//!    only; the other the shortest way; the soft limits hold. Then G54's
//!    offset is copied to G59, G59 is selected (#5220 = 6) and the
//!    plane's frame is in force ("TOOL kinematics"): programmed X Y Z
//!    are coordinates of the plane, through `feature_frame.rs`'s machinery
//!    (lines straight in the plane, arcs in it, the tool length along the
//!    tool). G0 stays the motion mode.
//!
//! `G69` ends both: no motion, the plane forgotten, G54 selected.

use fiveaxis_gcode::{Code, Span};
use fiveaxis_machine::{Side, Vec3, principal};

use super::feature_frame::{DEFINITION_TOLERANCE, Feature, about, frame_of, tool_axis_frame};
use crate::alarm::{Alarm, Condition};
use crate::controller::Controller;
use crate::fanuc::{FeatureCode, TwpOrient};
use crate::modal::{MotionMode, Units, WorkSelect};
use crate::segment::{Motion, Path, Segment, TcpcPath, TipPath};

/// G54, where a plane is defined.
const G54: WorkSelect = WorkSelect::Standard(0);
/// G59, the plane's coordinate system once it is oriented.
const G59: WorkSelect = WorkSelect::Standard(5);

/// The orders of G68.2 P0 (true Euler angles, moving axes).
const EULER_ORDERS: [u32; 6] = [121, 131, 212, 232, 313, 323];
/// The orders of G68.2 P1 (non-true Euler angles, fixed axes).
const FIXED_ORDERS: [u32; 6] = [123, 132, 213, 231, 312, 321];

/// G68.2 P2: the least distance between the line through two of the
/// points and the third (README: "less than 10mm or 0.5inch").
const POINT_DISTANCE_MM: f64 = 10.0;
/// The same in G20.
const POINT_DISTANCE_INCH: f64 = 0.5;

/// G68.2 P3: the enclosed angle of the two vectors, degrees (README:
/// "<85° or >95°" is an error).
const SQUARE_RANGE: (f64, f64) = (85.0, 95.0);

/// A turn counts as none below this, degrees (positive / negative only).
const TURN_TOLERANCE: f64 = 1e-9;

/// How the prioritized rotary axis turns to the plane (G53.x P).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Strategy {
    Shortest,
    Positive,
    Negative,
}

impl Controller<'_> {
    /// Whether this machine has LinuxCNC's TWP remap.
    pub(in crate::controller) fn twp_remap(&self) -> bool {
        self.dialect.rs274ngc && self.machine.params.twp_remap
    }

    /// G68.2 / G68.3 / G68.4: define the plane (no motion, the program
    /// stays in its coordinate system until G53.x).
    pub(in crate::controller) fn twp_define(
        &mut self,
        what: FeatureCode,
        code: Code,
        span: Span,
    ) -> Result<(), Alarm> {
        let name = format!("G{code}");
        self.twp_not_with_tcp(span, &name)?;
        let work = self.state.modal.work;
        let oriented = self.state.feature.is_some();
        if what == FeatureCode::Relative {
            if self.state.twp.is_none() {
                return Err(self.alarm(
                    Condition::FeatureNotAllowed,
                    Some(span),
                    "G68.4 defines a plane relative to the active one: no tilted working plane is defined (G68.2, G68.3)".into(),
                ));
            }
            if work != G54 && !(oriented && work == G59) {
                return Err(self.alarm(
                    Condition::FeatureNotAllowed,
                    Some(span),
                    "G68.4: the tilted working plane is defined in G54 (or in the G59 of the oriented plane): select G54 first".into(),
                ));
            }
        } else if work != G54 {
            return Err(self.alarm(
                Condition::FeatureNotAllowed,
                Some(span),
                format!(
                    "{name}: a tilted working plane can only be defined in G54{}",
                    if oriented {
                        " (the oriented plane is G59: give G69 first, or G68.4)"
                    } else {
                        ": select G54 first"
                    }
                ),
            ));
        }
        let defined = if what == FeatureCode::ToolAxis {
            self.twp_from_tool_axis(span)?
        } else {
            let form = self.definition_form(code, span)?;
            let defined = match form {
                0 | 1 => Some(self.twp_by_angles(form, &name, span)?),
                2 => self.twp_by_points(code, &name, span)?,
                3 => self.twp_by_vectors(code, &name, span)?,
                _ => {
                    return Err(self.alarm(
                        Condition::FeatureDefinition,
                        Some(span),
                        format!(
                            "{name} P{form}: the forms are P0 (true Euler angles), P1 (non-true Euler angles), P2 (three points) and P3 (two vectors)"
                        ),
                    ));
                }
            };
            // A definition given block by block defines nothing yet.
            let Some(defined) = defined else {
                return Ok(());
            };
            defined
        };
        let plane = match self.state.twp {
            Some(outer) if what == FeatureCode::Relative => outer.within(&defined),
            _ => defined,
        };
        self.state.twp = Some(plane);
        Ok(())
    }

    /// G69: the plane ends, G54 again, no motion.
    pub(in crate::controller) fn twp_cancel(&mut self) {
        self.state.twp = None;
        self.state.feature = None;
        self.state.feature_pending = None;
        self.state.modal.work = G54;
    }

    /// The TWP codes are not combined with the TCP kinematics (M428) in
    /// this kernel.
    fn twp_not_with_tcp(&self, span: Span, name: &str) -> Result<(), Alarm> {
        if self.tcpc_type().is_none() {
            return Ok(());
        }
        Err(self.alarm(
            Condition::FeatureNotAllowed,
            Some(span),
            format!("{name} cannot be used with the TCP kinematics on in this kernel: switch them off first"),
        ))
    }

    /// R: the turn about the plane's +Z, degrees, 0 when left out.
    fn twp_turn(&mut self) -> f64 {
        let rules = self.rules();
        self.fanuc.rotation_angle(&rules).unwrap_or(0.0)
    }

    /// The rotation order Q of P0 / P1: one of `orders`, `default` when
    /// left out; the axes of the three turns.
    fn twp_order(&mut self, name: &str, form: u32) -> Result<[Vec3; 3], Alarm> {
        let (orders, default) = if form == 0 {
            (EULER_ORDERS, 313)
        } else {
            (FIXED_ORDERS, 123)
        };
        let q = self.fanuc.twp_order(name, form, &orders, default)?;
        let axis = |d: u32| match d {
            1 => Vec3::x(),
            2 => Vec3::y(),
            _ => Vec3::z(),
        };
        Ok([axis(q / 100), axis(q / 10 % 10), axis(q % 10)])
    }

    /// P0 (true Euler angles, moving axes) and P1 (fixed axes).
    fn twp_by_angles(&mut self, form: u32, name: &str, span: Span) -> Result<Feature, Alarm> {
        let axes = self.twp_order(name, form)?;
        let origin = self.definition_point();
        let angles = self.definition_ijk();
        let turn = self.twp_turn();
        self.definition_finite(
            &[
                origin.x, origin.y, origin.z, angles.x, angles.y, angles.z, turn,
            ],
            name,
            span,
        )?;
        let [r1, r2, r3] = [0, 1, 2].map(|k| about(axes[k], angles[k]));
        let rotation = if form == 0 {
            r1 * r2 * r3
        } else {
            r3 * r2 * r1
        };
        Ok(Feature::plane(origin, rotation * about(Vec3::z(), turn)))
    }

    /// I J K as a point (lengths, G20 inches to mm), 0 when left out.
    fn twp_point_ijk(&mut self) -> Vec3 {
        let rules = self.rules();
        Vec3::from(self.fanuc.vector(&rules))
    }

    /// P2: three points, one block each (see the module documentation).
    fn twp_by_points(
        &mut self,
        code: Code,
        name: &str,
        span: Span,
    ) -> Result<Option<Feature>, Alarm> {
        let (mut pending, q) = self.definition_block(code, 2, name, span)?;
        if q == 0 {
            pending.shift = self.definition_point();
            pending.turn = self.twp_turn();
            let (s, t) = (pending.shift, pending.turn);
            self.definition_finite(&[s.x, s.y, s.z, t], name, span)?;
        } else {
            let p = self.twp_point_ijk();
            self.definition_finite(&[p.x, p.y, p.z], name, span)?;
            pending.points[q as usize - 1] = p;
        }
        let Some(pending) = self.definition_hold(pending, q) else {
            return Ok(None);
        };
        let points = pending.points;
        for (a, b) in [(0, 1), (0, 2), (1, 2)] {
            if (points[a] - points[b]).norm() < DEFINITION_TOLERANCE {
                return Err(self.alarm(
                    Condition::FeatureDefinition,
                    Some(span),
                    format!(
                        "{name} P2: points Q{} and Q{} are the same point",
                        a + 1,
                        b + 1
                    ),
                ));
            }
        }
        let [p1, p2, p3] = points;
        let x = p2 - p1;
        let z = x.cross(&(p3 - p1));
        if z.norm() < DEFINITION_TOLERANCE * x.norm() * (p3 - p1).norm() {
            return Err(self.alarm(
                Condition::FeatureDefinition,
                Some(span),
                format!("{name} P2: the three points lie on one line"),
            ));
        }
        let (least, unit) = if self.state.modal.units == Units::Inch {
            (POINT_DISTANCE_INCH * 25.4, "0.5 inch")
        } else {
            (POINT_DISTANCE_MM, "10 mm")
        };
        // The distance of each point from the line through the other two.
        for (k, (a, b, c)) in [(p2, p3, p1), (p1, p3, p2), (p1, p2, p3)]
            .into_iter()
            .enumerate()
        {
            let d = (c - a).cross(&(b - a)).norm() / (b - a).norm();
            if d < least {
                return Err(self.alarm(
                    Condition::FeatureDefinition,
                    Some(span),
                    format!(
                        "{name} P2: point Q{} lies {d:.4} mm from the line through the other two; the least is {unit}",
                        k + 1
                    ),
                ));
            }
        }
        let frame = frame_of(x, z);
        Ok(Some(Feature::plane(
            p1 + pending.shift,
            frame * about(Vec3::z(), pending.turn),
        )))
    }

    /// P3: `Q1 X Y Z I J K R` the origin, +X and the turn, `Q2 I J K` +Z.
    fn twp_by_vectors(
        &mut self,
        code: Code,
        name: &str,
        span: Span,
    ) -> Result<Option<Feature>, Alarm> {
        let (mut pending, q) = self.definition_block(code, 3, name, span)?;
        if q == 1 {
            pending.points[0] = self.definition_point();
            pending.turn = self.twp_turn();
        }
        let vector = self.definition_ijk();
        pending.points[q as usize] = vector;
        let o = pending.points[0];
        self.definition_finite(
            &[o.x, o.y, o.z, vector.x, vector.y, vector.z, pending.turn],
            name,
            span,
        )?;
        if vector.norm() < DEFINITION_TOLERANCE {
            return Err(self.alarm(
                Condition::FeatureDefinition,
                Some(span),
                format!("{name} P3 Q{q}: the vector is the zero vector"),
            ));
        }
        let Some(pending) = self.definition_hold(pending, q) else {
            return Ok(None);
        };
        let [origin, x, z] = pending.points;
        let angle = x.angle(&z).to_degrees();
        if !(SQUARE_RANGE.0..=SQUARE_RANGE.1).contains(&angle) {
            return Err(self.alarm(
                Condition::FeatureDefinition,
                Some(span),
                format!(
                    "{name} P3: the vectors enclose {angle:.4} degrees; they must enclose 85 to 95 degrees"
                ),
            ));
        }
        Ok(Some(Feature::plane(
            origin,
            frame_of(x, z) * about(Vec3::z(), pending.turn),
        )))
    }

    /// G68.3 X Y Z R: +Z the tool axis as the axes stand (table frame).
    fn twp_from_tool_axis(&mut self, span: Span) -> Result<Feature, Alarm> {
        let origin = self.definition_point();
        let turn = self.twp_turn();
        self.definition_finite(&[origin.x, origin.y, origin.z, turn], "G68.3", span)?;
        let dir = self.machine.forward(&self.state.joints, 0.0).dir;
        let z = self.state.setup.inverse_vector(&dir).normalize();
        Ok(Feature::plane(
            origin,
            tool_axis_frame(z) * about(Vec3::z(), turn),
        ))
    }

    /// G53.1 / G53.3 / G53.6: orient the tool normal to the plane, then
    /// program in it (G59, TOOL kinematics).
    pub(in crate::controller) fn twp_orient(
        &mut self,
        how: TwpOrient,
        span: Span,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let name = match how {
            TwpOrient::Turn => "G53.1",
            TwpOrient::ToPoint => "G53.3",
            TwpOrient::KeepTip => "G53.6",
        };
        self.twp_not_with_tcp(span, name)?;
        let Some(plane) = self.state.twp else {
            return Err(self.alarm(
                Condition::FeatureNotAllowed,
                Some(span),
                format!("{name} needs a tilted working plane defined first (G68.2, G68.3, G68.4)"),
            ));
        };
        let strategy = match self.fanuc.twp_direction()? {
            0 => Strategy::Shortest,
            1 => Strategy::Positive,
            _ => Strategy::Negative,
        };
        // G53.3's point of the plane, absolute; axes left out keep the
        // tip's coordinate of the plane.
        let mut goal = [None; 3];
        if how == TwpOrient::ToPoint {
            let rules = self.rules();
            goal = self.fanuc.linear_values(&rules);
        }
        let pair = self.twp_pair(span, name)?;
        let dir = self.state.setup.vector(&(plane.rotation() * Vec3::z()));
        let current = self.state.joints;
        let chosen = self.twp_angles(&dir, pair, strategy, span, name)?;
        let mut start = current;
        let mut end = current;
        for (slot, k) in pair.into_iter().enumerate() {
            let i = self.machine.rotary_index(k);
            if self.is_rollover(i) {
                end[i] = crate::controller::normalize_360(chosen[slot]);
                start[i] = end[i] - (chosen[slot] - current[i]);
            } else {
                end[i] = chosen[slot];
            }
        }
        // The plane in force, defined in G54 (whose offset G59 takes).
        self.state.modal.work = G54;
        self.state.feature = Some(plane);
        let length = self.feature_tool_length();
        match how {
            TwpOrient::Turn => self.push_line(Motion::Rapid, start, end, out)?,
            TwpOrient::ToPoint => {
                let here = self.feature_programmed(&current);
                let p = Vec3::new(
                    goal[0].unwrap_or(here.x),
                    goal[1].unwrap_or(here.y),
                    goal[2].unwrap_or(here.z),
                );
                self.definition_finite(&[p.x, p.y, p.z], name, span)?;
                let gauge = self.feature_gauge(&end, &p);
                end[..3].copy_from_slice(gauge.as_slice());
                let mut seg = self.segment(Motion::Rapid, start, end, Path::Joint);
                seg.tool_length = length;
                if seg.moves() {
                    out.push(seg);
                }
            }
            TwpOrient::KeepTip => {
                // TCP: the tip stands while the axes turn.
                let tip = self.machine.forward(&current, length).tip;
                let gauge = self.machine.gauge_for_tip(&end, &tip, length);
                end[..3].copy_from_slice(gauge.as_slice());
                let path = Path::Tcpc(TcpcPath {
                    tip: TipPath::Line([tip, tip]),
                    turning: false,
                    posture: None,
                });
                let mut seg = self.segment(Motion::Rapid, start, end, path);
                seg.tool_length = length;
                if seg.moves() {
                    out.push(seg);
                }
            }
        }
        // G59 is the plane's coordinate system: G54's offset, the plane's
        // origin and turn in the feature frame.
        self.offsets.work[5] = self.offsets.work[0];
        self.state.rotary_work[5] = self.state.rotary_work[0];
        self.state.modal.work = G59;
        self.state.modal.motion = MotionMode::Rapid;
        Ok(())
    }

    /// The rotary numbers G53.x turns: the two head axes (a table axis
    /// holds), or the two rotary axes of a two-rotary machine; the first
    /// (bed outwards) is the primary.
    fn twp_pair(&self, span: Span, name: &str) -> Result<[usize; 2], Alarm> {
        let rotary = &self.machine.rotary;
        let mut heads = (0..rotary.len()).filter(|&k| rotary[k].on == Side::Head);
        if let (Some(a), Some(b), None) = (heads.next(), heads.next(), heads.next()) {
            return Ok([a, b]);
        }
        if rotary.len() == 2 {
            return Ok([0, 1]);
        }
        Err(self.alarm(
            Condition::TcpcWithoutRotaryAxis,
            Some(span),
            format!("{name} turns two rotary axes: two head axes, or two rotary axes in all"),
        ))
    }

    /// The angles (unwrapped from where the axes stand) of the pair that
    /// point the tool along `dir`: the prioritized axis by `strategy`,
    /// the other the shortest way, both inside their soft limits; among
    /// the solutions the least turn of the prioritized axis, then of the
    /// other.
    fn twp_angles(
        &self,
        dir: &Vec3,
        pair: [usize; 2],
        strategy: Strategy,
        span: Span,
        name: &str,
    ) -> Result<[f64; 2], Alarm> {
        let joints = &self.state.joints;
        self.block_chose_rotary.set(true);
        let found = self.machine.orientations_held(dir, pair, joints);
        let prio = usize::from(self.machine.params.twp_priority == 2);
        let current = pair.map(|k| joints[self.machine.rotary_index(k)]);
        let mut best: Option<((f64, f64), [f64; 2])> = None;
        for angles in found.pairs() {
            let mut chosen = [0.0; 2];
            let mut ok = true;
            for slot in 0..2 {
                let rule = if slot == prio {
                    strategy
                } else {
                    Strategy::Shortest
                };
                match self.twp_target(pair[slot], angles[slot], current[slot], rule) {
                    Some(a) => chosen[slot] = a,
                    None => ok = false,
                }
            }
            if !ok {
                continue;
            }
            let key = (
                (chosen[prio] - current[prio]).abs(),
                (chosen[1 - prio] - current[1 - prio]).abs(),
            );
            if best.is_none_or(|(k, _)| key < k) {
                best = Some((key, chosen));
            }
        }
        best.map(|(_, c)| c).ok_or_else(|| {
            let why = if found.is_empty() {
                "no position of the rotary axes"
            } else {
                "no position of the rotary axes inside their soft limits (and the P direction of turn)"
            };
            self.alarm(
                Condition::ToolDirectionUnreachable,
                Some(span),
                format!(
                    "{name}: {why} points the tool along the plane's +Z ({:.6}, {:.6}, {:.6})",
                    dir.x, dir.y, dir.z
                ),
            )
        })
    }

    /// Where rotary axis `k` standing at `current` goes for `angle` by
    /// `rule`, inside its limits; `None` when no position qualifies.
    fn twp_target(&self, k: usize, angle: f64, current: f64, rule: Strategy) -> Option<f64> {
        let axis = &self.machine.rotary[k];
        let ahead = (angle - current).rem_euclid(360.0);
        let ahead = if ahead > 360.0 - TURN_TOLERANCE {
            0.0
        } else {
            ahead
        };
        let behind = if ahead < TURN_TOLERANCE {
            0.0
        } else {
            360.0 - ahead
        };
        let nearest = current + principal(angle - current);
        // The positions the rule allows, nearest first.
        let candidates = match rule {
            Strategy::Shortest => [
                Some(nearest),
                Some(nearest - 360.0 * (nearest - current).signum()),
            ],
            Strategy::Positive => [Some(current + ahead), None],
            Strategy::Negative => [Some(current - behind), None],
        };
        let inside = |a: &f64| match axis.limits {
            Some((min, max)) if !axis.rollover => {
                *a >= min - crate::controller::LIMIT_TOLERANCE
                    && *a <= max + crate::controller::LIMIT_TOLERANCE
            }
            _ => true,
        };
        candidates.into_iter().flatten().find(inside)
    }
}
