//! Tool centre point control: G43.4 (type 1, rotary angles programmed) and
//! G43.5 (type 2, tool vector I J K programmed), as the FANUC 30i TCPC
//! manual and the Mitsubishi M700/M800 programming manual describe them.
//!
//! The programmed point is the tool tip in the programming frame: the work
//! coordinate system as it stood at start-up, frozen onto the table
//! (FANUC WKP = 0), or the work coordinate system that does not turn
//! (WKP = 1, type 1 only). Inside a block the tip moves on a straight line
//! (or an arc) in that frame; the rotary axes move linearly in s, or, with
//! tool posture control, the tool turns on the great circle.

use fiveaxis_gcode::Span;
use fiveaxis_machine::{
    Control, Joints, MachineType, ProgrammingFrame, RotaryChoice, Side, Vec3, principal,
};
use nalgebra::IsometryMatrix3;

use super::{Controller, LengthChange};
use crate::alarm::{Alarm, Condition};
use crate::modal::{LengthMode, MotionMode, TcpcType};
use crate::segment::{Motion, Path, Segment, TcpcPath, TipPath};

/// Shortest tip travel that counts as a direction of travel for the
/// inclination angle Q, mm.
const TRAVEL_EPSILON: f64 = 1e-9;
/// How close to a half turn two tool vectors count as opposite for tool
/// posture control, radians.
const POSTURE_OPPOSITE: f64 = 1e-9;
/// Turn of the tool between two checks that tool posture control stays
/// reachable, degrees.
const POSTURE_SAMPLE_ANGLE: f64 = 1.0;
/// Closest approach (radians) of a posture-controlled tool to the singular
/// direction under which the block is refused: passing nearer would turn
/// the rotating axis half a turn in an instant.
const SINGULAR_PASSAGE: f64 = 1e-6;
/// Rotary motion under which the rotary axes count as standing still
/// (arcs in TCPC), degrees.
const ROTARY_EPSILON: f64 = 1e-9;

/// TCPC data fixed when the mode starts.
#[derive(Clone, Copy, Debug)]
pub(super) struct TcpcState {
    /// The table map at start-up: programming frame → table frame is its
    /// inverse (WKP = 0).
    frame: IsometryMatrix3<f64>,
    /// WKP = 1: programmed points are in the work coordinate system that
    /// does not turn with the table.
    turning: bool,
    /// Tool posture control (P1).
    posture: bool,
    /// Inclination angle Q, degrees (type 2).
    inclination: f64,
    /// The last programmed tool vector, programming frame, unit (type 2).
    vector: Vec3,
    /// Side of the tilt axis to keep (+1 or −1) for `KeepTiltSign`.
    tilt_sign: f64,
    /// This block started the mode.
    pub(super) startup: bool,
    /// The programmed point a TCPC block ended on, with the machine
    /// position, tool length and work offset it was reached with: the
    /// programmed position stays exactly as programmed instead of being
    /// recomputed through forward kinematics.
    last: Option<(Joints, f64, Vec3, Vec3)>,
}

impl Default for TcpcState {
    fn default() -> Self {
        Self {
            frame: IsometryMatrix3::identity(),
            turning: false,
            posture: false,
            inclination: 0.0,
            vector: Vec3::z(),
            tilt_sign: 1.0,
            startup: false,
            last: None,
        }
    }
}

/// The tool vector inclined by `q` degrees from `n` towards the travel
/// direction `travel` (made perpendicular to `n`); `n` itself when the tip
/// does not travel or travels along `n`.
pub fn inclined(n: &Vec3, travel: &Vec3, q: f64) -> Vec3 {
    if q == 0.0 || travel.norm() <= TRAVEL_EPSILON {
        return *n;
    }
    let across = travel - n * n.dot(travel);
    if across.norm() <= TRAVEL_EPSILON * travel.norm().max(1.0) {
        return *n;
    }
    let (sin, cos) = q.to_radians().sin_cos();
    n * cos + across.normalize() * sin
}

impl Controller<'_> {
    /// Which rotary axis (0 or 1, file order) is the rotating axis: the one
    /// closest to parallel with the tool at the all-zero position (table C,
    /// head C); the other is the tilt axis.
    fn rotating_axis(&self) -> usize {
        let t0 = self.machine.tool_direction.into_inner();
        let along = |k: usize| self.machine.rotary[k].axis.dot(&t0).abs();
        if self.machine.rotary.len() == 2 && along(0) > along(1) {
            0
        } else {
            1
        }
    }

    /// G43.4 / G43.5 in a block: checks the start-up conditions and fixes
    /// the programming frame. Returns how the axes respond to the new
    /// offset.
    pub(super) fn start_tcpc(&mut self, kind: TcpcType, span: Span) -> Result<LengthChange, Alarm> {
        let machine = self.machine;
        let code = if kind == TcpcType::Angles {
            "G43.4"
        } else {
            "G43.5"
        };
        if !machine.params.tcpc_option {
            return Err(self.alarm(
                Condition::TcpcOptionMissing,
                Some(span),
                format!("{code}: this control has no tool centre point control option"),
            ));
        }
        if machine.rotary.is_empty() {
            return Err(self.alarm(
                Condition::TcpcWithoutRotaryAxis,
                Some(span),
                format!("{code}: the machine has no rotary axis"),
            ));
        }
        let workpiece_frame = machine.params.programming_frame == ProgrammingFrame::Workpiece;
        if kind == TcpcType::Vector && (workpiece_frame || machine.rotary.len() < 2) {
            let why = if workpiece_frame {
                "the programming frame is the workpiece coordinate system (WKP = 1)"
            } else {
                "type 2 needs two rotary axes"
            };
            return Err(self.alarm(
                Condition::TcpcType2NotAvailable,
                Some(span),
                format!("G43.5: {why}"),
            ));
        }
        let ijk = [b'I', b'J', b'K']
            .into_iter()
            .find_map(|l| self.words.peek(l));
        if kind == TcpcType::Vector
            && !self.dialect.tcpc_startup_controls_tip
            && machine.machine_type() != MachineType::Head
            && let Some(word) = ijk
        {
            return Err(self.alarm(
                Condition::TcpcIjkInStartBlock,
                Some(word.span),
                "I, J, K cannot be given in the G43.5 block on a table or mixed machine".into(),
            ));
        }
        let posture = match self.words.take(b'P') {
            Some(word) => self.words.integer(&word, 1)? == 1,
            None => machine.params.tool_posture_control,
        };
        let inclination = match kind {
            TcpcType::Vector => self.words.take(b'Q').map_or(0.0, |w| self.angle(&w)),
            TcpcType::Angles => 0.0,
        };
        let joints = self.state.joints;
        let frame = machine.chain(Side::Table, &joints);
        let dir_table = machine.forward(&joints, 0.0).dir;
        let tilt = if machine.rotary.len() == 2 {
            1 - self.rotating_axis()
        } else {
            0
        };
        let tilt_angle = joints[machine.rotary_index(tilt)];
        let tilt_sign = if tilt_angle > 0.0 {
            1.0
        } else if tilt_angle < 0.0 {
            -1.0
        } else {
            // From 0: the side with the wider stroke; equal strokes, minus.
            match machine.rotary.get(tilt).and_then(|a| a.limits) {
                Some((min, max)) if max > -min => 1.0,
                _ => -1.0,
            }
        };
        self.state.tcpc = TcpcState {
            frame,
            turning: workpiece_frame,
            posture,
            inclination,
            vector: frame.rotation * dir_table,
            tilt_sign,
            startup: true,
            last: None,
        };
        Ok(if self.dialect.tcpc_startup_controls_tip {
            // Mitsubishi: the start-up block moves under TCPC itself, and
            // without axis words does not move at all.
            LengthChange::InPlace
        } else {
            LengthChange::Moves
        })
    }

    /// Programmed position X, Y, Z under TCPC at machine position `joints`:
    /// the tool tip in the programming frame.
    pub(super) fn tcpc_programmed(&self, joints: &Joints) -> Vec3 {
        if let Some((at, length, work, point)) = self.state.tcpc.last
            && at == *joints
            && length == self.tool_length()
            && work == self.work()
        {
            return point;
        }
        let tip_table = self.machine.forward(joints, self.tool_length()).tip;
        let map = self.programming_map(joints);
        map.transform_point(&tip_table.into()).coords - self.work()
    }

    /// Machine position of X, Y, Z that puts the tip on programmed point
    /// `p` with the rotary axes at `joints`.
    pub(super) fn tcpc_gauge(&self, joints: &Joints, p: &Vec3) -> Vec3 {
        let map = self.programming_map(joints);
        let tip_table = map
            .inverse_transform_point(&(p + self.work()).into())
            .coords;
        self.machine
            .gauge_for_tip(joints, &tip_table, self.tool_length())
    }

    /// Table frame → programming frame (plus the work offset) at `joints`.
    fn programming_map(&self, joints: &Joints) -> IsometryMatrix3<f64> {
        if self.state.tcpc.turning {
            self.machine.chain(Side::Table, joints)
        } else {
            self.state.tcpc.frame
        }
    }

    /// A block in TCPC mode.
    pub(super) fn tcpc_motion(
        &mut self,
        kind: TcpcType,
        from: &Joints,
        length_changed: bool,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let machine = self.machine;
        let targets = self.axis_words();
        let first_rotary = machine.linear.len();
        if kind == TcpcType::Vector
            && let Some(i) = (first_rotary..machine.axis_count()).find(|&i| targets[i].is_some())
        {
            let name = self.axis_letters[i];
            let span = self.words.peek(name).map(|w| w.span);
            return Err(self.alarm(
                Condition::TcpcRotaryWordInType2,
                span,
                format!(
                    "rotary axis word {} in TCPC type 2: program the tool vector I, J, K",
                    char::from(name)
                ),
            ));
        }
        let vector_given = self.tcpc_vector(kind)?;
        let mode = self.state.modal.motion;
        let is_arc = matches!(mode, MotionMode::Cw | MotionMode::Ccw);
        let arc_words = is_arc && (self.words.has(b'R') || self.center_words_present());
        let has_axes = targets.iter().any(Option::is_some) || vector_given || arc_words;
        if !has_axes && !length_changed {
            return Ok(());
        }
        let (mut end_p, mut travel) = self.end_point(from, &targets);
        let current = self.state.joints;
        // The start-up block turns the rotary axes only for a vector it
        // gives itself (head-head machines); otherwise they stay.
        let solve_vector = kind == TcpcType::Vector && (vector_given || !self.state.tcpc.startup);
        if solve_vector {
            let (i0, i1) = (machine.rotary_index(0), machine.rotary_index(1));
            let p0 = Vec3::new(from[0], from[1], from[2]);
            let p1 = Vec3::new(end_p[0], end_p[1], end_p[2]);
            let tcpc = self.state.tcpc;
            let t = inclined(&tcpc.vector, &(p1 - p0), tcpc.inclination);
            let v_table = tcpc.frame.rotation.inverse_transform_vector(&t);
            let chosen = self.choose_rotaries(&v_table, [current[i0], current[i1]])?;
            for (k, i) in [i0, i1].into_iter().enumerate() {
                let shift = self.state.axis_shift[i];
                travel[i] = chosen[k] - current[i];
                let angle = if self.is_rollover(i) {
                    super::normalize_360(chosen[k])
                } else {
                    chosen[k]
                };
                end_p[i] = angle - shift;
            }
        } else {
            self.check_singular_passage(&current, &end_p, &travel)?;
        }
        let end = self.machine_position(&end_p);
        let start = self.rollover_start(&end, &travel);
        let motion = match mode {
            MotionMode::Rapid => Motion::Rapid,
            MotionMode::Linear => Motion::Linear,
            MotionMode::Cw => Motion::Cw,
            MotionMode::Ccw => Motion::Ccw,
        };
        if self.state.tcpc.startup && !self.dialect.tcpc_startup_controls_tip {
            // FANUC: the start-up block moves with tool length
            // compensation only, the tip not controlled on the way.
            let linear = if motion == Motion::Rapid {
                Motion::Rapid
            } else {
                Motion::Linear
            };
            return self.push_line(linear, start, end, out);
        }
        let tip = if is_arc && (arc_words || targets.iter().any(Option::is_some)) {
            let rotary_moves =
                (first_rotary..machine.axis_count()).any(|i| travel[i].abs() > ROTARY_EPSILON);
            if rotary_moves {
                let hint = if kind == TcpcType::Vector {
                    " (in G43.5, I J K give the tool vector: program the arc with R)"
                } else {
                    ""
                };
                return Err(self.alarm(
                    Condition::TcpcArcWithRotaryMotion,
                    None,
                    format!(
                        "circular interpolation in TCPC needs the rotary axes to stand still{hint}"
                    ),
                ));
            }
            match self.tcpc_arc(mode, from, &end_p)? {
                Some(tip) => tip,
                None => self.tcpc_line(from, &end_p, &start),
            }
        } else {
            self.tcpc_line(from, &end_p, &start)
        };
        let posture = if self.state.tcpc.posture {
            let length = self.tool_length();
            let ends = [
                machine.forward(&start, length).dir,
                machine.forward(&end, length).dir,
            ];
            self.check_posture_path(&ends, &start, &end)?;
            Some(ends)
        } else {
            None
        };
        let path = Path::Tcpc(TcpcPath {
            tip,
            turning: self.state.tcpc.turning,
            posture,
        });
        let mut seg = self.segment(motion, start, end, path);
        if !seg.moves() && start == end {
            return Ok(());
        }
        if motion != Motion::Rapid {
            seg.feed = Some(self.cutting_feed(|| tip.length())?);
        }
        out.push(seg);
        Ok(())
    }

    /// Tool posture control turns the tool on the great circle between
    /// `ends`: refuses opposite vectors (no single great circle) and a
    /// circle that passes directions no rotary position gives.
    fn check_posture_path(
        &self,
        ends: &[Vec3; 2],
        start: &Joints,
        end: &Joints,
    ) -> Result<(), Alarm> {
        let angle = ends[0].cross(&ends[1]).norm().atan2(ends[0].dot(&ends[1]));
        if std::f64::consts::PI - angle < POSTURE_OPPOSITE {
            return Err(self.alarm(
                Condition::PostureUndefined,
                None,
                "tool posture control between opposite tool vectors: no single great circle".into(),
            ));
        }
        let machine = self.machine;
        if machine.rotary.len() != 2 {
            return Ok(());
        }
        let axis = machine.rotary[self.rotating_axis()].axis.into_inner();
        if arc_distance(&ends[0], &ends[1], &axis).min(arc_distance(&ends[0], &ends[1], &-axis))
            < SINGULAR_PASSAGE
        {
            return Err(self.alarm(
                Condition::TcpcSingularPassage,
                None,
                "tool posture control passes the singular direction: the rotating axis would turn half a turn at once"
                    .into(),
            ));
        }
        let (i0, i1) = (machine.rotary_index(0), machine.rotary_index(1));
        let samples = (angle.to_degrees() / POSTURE_SAMPLE_ANGLE).ceil().max(1.0) as u32;
        for k in 1..samples {
            let s = f64::from(k) / f64::from(samples);
            let dir = crate::segment::slerp(&ends[0], &ends[1], s);
            let guide = [
                start[i0] + (end[i0] - start[i0]) * s,
                start[i1] + (end[i1] - start[i1]) * s,
            ];
            if machine.orientations(&dir, guide).is_empty() {
                return Err(self.alarm(
                    Condition::ToolDirectionUnreachable,
                    None,
                    format!(
                        "tool posture control passes a tool direction ({}, {}, {}) no rotary position gives",
                        dir.x, dir.y, dir.z
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Reads I, J, K of a type 2 block into the modal tool vector (omitted
    /// ones count 0; all omitted keep the vector). Type 1 ignores them on
    /// Mitsubishi; on FANUC they are left for the unused-word check.
    /// Returns whether a vector was given.
    fn tcpc_vector(&mut self, kind: TcpcType) -> Result<bool, Alarm> {
        let present = [b'I', b'J', b'K'].map(|l| self.words.peek(l));
        if present.iter().all(Option::is_none) {
            return Ok(false);
        }
        if kind == TcpcType::Angles {
            if self.dialect.tcpc_startup_controls_tip {
                for letter in [b'I', b'J', b'K'] {
                    self.words.take(letter);
                }
            }
            return Ok(false);
        }
        let [i, j, k] =
            [b'I', b'J', b'K'].map(|l| self.words.take(l).map_or(0.0, |w| self.length(&w)));
        let v = Vec3::new(i, j, k);
        if v.norm() <= TRAVEL_EPSILON {
            let span = present.iter().flatten().next().map(|w| w.span);
            return Err(self.alarm(
                Condition::ToolVectorZero,
                span,
                "I, J, K give no tool direction".into(),
            ));
        }
        self.state.tcpc.vector = v.normalize();
        Ok(true)
    }

    /// Mitsubishi P943: a G43.4 block whose tilt axis changes side (passes
    /// the singular point) while the rotating axis turns.
    fn check_singular_passage(
        &self,
        current: &Joints,
        end_p: &Joints,
        travel: &Joints,
    ) -> Result<(), Alarm> {
        if self.machine.control != Control::Mitsubishi || self.machine.rotary.len() != 2 {
            return Ok(());
        }
        let rotating = self.machine.rotary_index(self.rotating_axis());
        let tilt = self.machine.rotary_index(1 - self.rotating_axis());
        let (a, b) = (current[tilt], end_p[tilt] + self.state.axis_shift[tilt]);
        if a * b < 0.0 && travel[rotating].abs() > ROTARY_EPSILON {
            return Err(self.alarm(
                Condition::TcpcSingularPassage,
                None,
                format!(
                    "the tilt axis passes the singular point ({a} to {b}) while the rotating axis turns"
                ),
            ));
        }
        Ok(())
    }

    /// The tip path of a straight TCPC block.
    fn tcpc_line(&self, from: &Joints, end_p: &Joints, start: &Joints) -> TipPath {
        let work = self.work();
        let p0 = Vec3::new(from[0], from[1], from[2]) + work;
        let p1 = Vec3::new(end_p[0], end_p[1], end_p[2]) + work;
        if self.state.tcpc.turning {
            TipPath::Line([p0, p1])
        } else {
            let frame = &self.state.tcpc.frame;
            // A start-up block begins where the tip really is, off the
            // programmed path; later blocks on their programmed start.
            let tip0 = if self.state.tcpc.startup {
                self.machine.forward(start, self.tool_length()).tip
            } else {
                frame.inverse_transform_point(&p0.into()).coords
            };
            TipPath::Line([tip0, frame.inverse_transform_point(&p1.into()).coords])
        }
    }

    /// The tip path of a G02 / G03 block in TCPC: the circle in the
    /// programming frame, carried into the table frame.
    fn tcpc_arc(
        &mut self,
        mode: MotionMode,
        from: &Joints,
        end_p: &Joints,
    ) -> Result<Option<TipPath>, Alarm> {
        let Some(geo) = self.arc_geometry(mode, from, end_p)? else {
            return Ok(None);
        };
        let unit = |i: usize| {
            let mut v = Vec3::zeros();
            v[i] = 1.0;
            v
        };
        let [p, q] = geo.axes;
        let mut center = Vec3::new(from[0], from[1], from[2]) + self.work();
        center[p] = geo.center[0] + self.work()[p];
        center[q] = geo.center[1] + self.work()[q];
        let mut axes = [unit(p), unit(q), unit(geo.normal)];
        if !self.state.tcpc.turning {
            let frame = &self.state.tcpc.frame;
            center = frame.inverse_transform_point(&center.into()).coords;
            for axis in &mut axes {
                *axis = frame.rotation.inverse_transform_vector(axis);
            }
        }
        Ok(Some(TipPath::Arc {
            center,
            axes,
            radius: [geo.r0, geo.r1],
            theta0: geo.theta0,
            sweep: geo.sweep,
            rise: end_p[geo.normal] - from[geo.normal],
        }))
    }

    /// The rotary angles (machine, unwrapped near `current`) that point the
    /// tool along `dir` (table frame), chosen by the control's rule among
    /// the solutions and their 360° repeats inside the soft limits.
    pub(super) fn choose_rotaries(&self, dir: &Vec3, current: [f64; 2]) -> Result<[f64; 2], Alarm> {
        let machine = self.machine;
        let found = machine.orientations(dir, current);
        let rotating = self.rotating_axis();
        let rule = if self.in_singular_zone(dir, rotating) {
            RotaryChoice::RotatingAxis
        } else {
            machine.params.rotary_choice
        };
        let mut best: Option<(f64, f64, [f64; 2])> = None;
        for pair in found.pairs() {
            for a in self.repeats(0, pair[0], current[0]).into_iter().flatten() {
                for b in self.repeats(1, pair[1], current[1]).into_iter().flatten() {
                    let candidate = [a, b];
                    let key = choice_key(
                        rule,
                        &candidate,
                        &current,
                        rotating,
                        self.state.tcpc.tilt_sign,
                    );
                    if best.is_none_or(|(k0, k1, _)| key < (k0, k1)) {
                        best = Some((key.0, key.1, candidate));
                    }
                }
            }
        }
        best.map(|(_, _, c)| c).ok_or_else(|| {
            let why = if found.is_empty() {
                "no rotary position"
            } else {
                "no rotary position inside the soft limits"
            };
            self.alarm(
                Condition::ToolDirectionUnreachable,
                None,
                format!(
                    "{why} points the tool along ({}, {}, {})",
                    dir.x, dir.y, dir.z
                ),
            )
        })
    }

    /// Whether `dir` lies within the singular zone (#7907) around the
    /// rotating axis.
    fn in_singular_zone(&self, dir: &Vec3, rotating: usize) -> bool {
        let zone = self.machine.params.singular_zone;
        if zone <= 0.0 {
            return false;
        }
        let axis = self.machine.rotary[rotating].axis.into_inner();
        let angle = dir.cross(&axis).norm().atan2(dir.dot(&axis).abs());
        angle.to_degrees() < zone
    }

    /// The positions of rotary axis `k` equivalent to `angle`: on a
    /// rollover or unlimited axis the one nearest `current`; on a limited
    /// axis every 360° repeat inside its limits (at most three).
    fn repeats(&self, k: usize, angle: f64, current: f64) -> [Option<f64>; 3] {
        let axis = &self.machine.rotary[k];
        let nearest = current + principal(angle - current);
        match axis.limits {
            Some((min, max)) if !axis.rollover => {
                let mut out = [None; 3];
                let mut n = 0;
                let mut a = angle - 360.0 * ((angle - min) / 360.0).floor();
                while a <= max + super::LIMIT_TOLERANCE && n < 3 {
                    if a >= min - super::LIMIT_TOLERANCE {
                        out[n] = Some(a);
                        n += 1;
                    }
                    a += 360.0;
                }
                out
            }
            _ => [Some(nearest), None, None],
        }
    }

    /// Whether the block is in TCPC mode, and which type.
    pub(super) fn tcpc_type(&self) -> Option<TcpcType> {
        match self.state.modal.length {
            LengthMode::Tcpc(kind) => Some(kind),
            _ => None,
        }
    }
}

/// The smallest angle (radians) between direction `a` and the shorter
/// great-circle arc from `d0` to `d1`.
fn arc_distance(d0: &Vec3, d1: &Vec3, a: &Vec3) -> f64 {
    let angle = |u: &Vec3, v: &Vec3| u.cross(v).norm().atan2(u.dot(v));
    let ends = angle(d0, a).min(angle(d1, a));
    let normal = d0.cross(d1);
    if normal.norm() < 1e-15 {
        return ends;
    }
    let normal = normal.normalize();
    let foot = a - normal * normal.dot(a);
    if foot.norm() < 1e-15 {
        return ends;
    }
    let foot = foot.normalize();
    // The foot lies on the arc when it is between the ends.
    if d0.cross(&foot).dot(&normal) >= 0.0 && foot.cross(d1).dot(&normal) >= 0.0 {
        angle(&foot, a)
    } else {
        ends
    }
}

/// Sort key of a candidate under `rule` (smaller is better).
fn choice_key(
    rule: RotaryChoice,
    candidate: &[f64; 2],
    current: &[f64; 2],
    rotating: usize,
    tilt_sign: f64,
) -> (f64, f64) {
    let motion = [
        (candidate[0] - current[0]).abs(),
        (candidate[1] - current[1]).abs(),
    ];
    let total = motion[0] + motion[1];
    match rule {
        RotaryChoice::Shortest => (total, motion[rotating]),
        RotaryChoice::RotatingAxis => (motion[rotating], total),
        RotaryChoice::KeepTiltSign => {
            let tilt = candidate[1 - rotating];
            let wrong_side = if tilt * tilt_sign < 0.0 { 1.0 } else { 0.0 };
            (wrong_side, total)
        }
    }
}
