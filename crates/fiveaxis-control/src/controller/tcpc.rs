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
use crate::segment::{Motion, POSTURE_KNOTS, Path, Posture, Segment, TcpcPath, TipPath};

/// Shortest tip travel that counts as a direction of travel for the
/// inclination angle Q, mm.
const TRAVEL_EPSILON: f64 = 1e-9;
/// How close to a half turn two tool vectors count as opposite for tool
/// posture control, radians.
const POSTURE_OPPOSITE: f64 = 1e-9;
/// Turn of the tool between two steps of following the rotary axes under
/// tool posture control, degrees.
const POSTURE_TRACK_ANGLE: f64 = 0.25;
/// Most the rotary axes may turn in one step of following them before the
/// step is halved, degrees.
const POSTURE_STEP_TURN: f64 = 45.0;
/// Most halvings of one step: a turn still above [`POSTURE_STEP_TURN`]
/// after them is the passage through the singular direction.
const POSTURE_REFINE_DEPTH: u32 = 24;
/// Most the rotary angles may stray from the straight line between two
/// knots, degrees (well inside the half turn that separates solutions).
const POSTURE_GUIDE_TURN: f64 = 60.0;
/// How far outside the reach a posture-controlled direction may lie
/// (rounding), in reach-margin units.
const POSTURE_REACH_TOLERANCE: f64 = 1e-12;
/// Reach margin under which a dip between samples is searched.
const POSTURE_REFINE_BELOW: f64 = 1e-2;
/// How close the followed end angles must come to the programmed ones,
/// degrees.
const POSTURE_END_TOLERANCE: f64 = 1e-6;
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
    last: Option<LastPoint>,
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

impl TcpcState {
    /// Tool posture control on (the tool turns on the great circle) or
    /// off (the rotary axes linear) for the running TCPC.
    pub(super) fn set_posture(&mut self, on: bool) {
        self.posture = on;
    }
}

/// What the programmed point depends on besides the machine position: the
/// work offset, the 3-D compensation vector and the setup error.
type FramesKey = (Vec3, Vec3, fiveaxis_machine::SetupError);

/// The end of the last TCPC block: machine position, tool length, frames,
/// programmed point.
type LastPoint = (Joints, f64, FramesKey, Vec3);

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

    /// The programmed tool vector of type 2 in the table frame (ideal
    /// workpiece).
    pub(super) fn tcpc_vector_table(&self) -> Vec3 {
        self.state
            .tcpc
            .frame
            .rotation
            .inverse_transform_vector(&self.state.tcpc.vector)
    }

    /// The table axis (0 or 1, file order) whose motion G54.4 keeps small:
    /// the machine's only table axis, or else the rotating axis.
    pub(super) fn table_axis(&self) -> usize {
        let mut tables =
            (0..self.machine.rotary.len()).filter(|&k| self.machine.rotary[k].on == Side::Table);
        match (tables.next(), tables.next()) {
            (Some(only), None) => only,
            _ => self.rotating_axis(),
        }
    }

    /// The tilt axis (rotary file order): the one that is not the
    /// rotating axis; the only one on a single-rotary machine.
    fn tilt_axis(&self) -> usize {
        if self.machine.rotary.len() == 2 {
            1 - self.rotating_axis()
        } else {
            0
        }
    }

    /// The side the tilt axis is on at `joints`: its sign, or from 0 the
    /// side with the wider stroke (minus when equal).
    pub(super) fn tilt_side(&self, joints: &Joints) -> f64 {
        let tilt = self.tilt_axis();
        let angle = joints[self.machine.rotary_index(tilt)];
        if angle > 0.0 {
            1.0
        } else if angle < 0.0 {
            -1.0
        } else {
            match self.machine.rotary.get(tilt).and_then(|a| a.limits) {
                Some((min, max)) if max > -min => 1.0,
                _ => -1.0,
            }
        }
    }

    /// G43.4 / G43.5 in a block: checks the start-up conditions and fixes
    /// the programming frame. Returns how the axes respond to the new
    /// offset.
    pub(super) fn start_tcpc(&mut self, kind: TcpcType, span: Span) -> Result<LengthChange, Alarm> {
        let code = if kind == TcpcType::Angles {
            "G43.4"
        } else {
            "G43.5"
        };
        self.start_tcpc_as(kind, code, false, span)
    }

    /// [`Controller::start_tcpc`] as `code` (`G43.4`, `G43.5`, Haas
    /// `G234`). With `table_zero` (Haas G234) the programming frame is the
    /// work coordinate system fixed to the table as it stands at rotary
    /// position 0, whatever the rotary axes stand at start-up (Haas: the
    /// coordinate system of the MRZP and the work offset stays fixed
    /// relative to the table), and the block takes no P.
    pub(super) fn start_tcpc_as(
        &mut self,
        kind: TcpcType,
        code: &str,
        table_zero: bool,
        span: Span,
    ) -> Result<LengthChange, Alarm> {
        let machine = self.machine;
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
        if kind == TcpcType::Vector && (workpiece_frame || machine.rotary.len() != 2) {
            let why = if workpiece_frame {
                "the programming frame is the workpiece coordinate system (WKP = 1)".to_owned()
            } else {
                format!(
                    "type 2 needs exactly two rotary axes to turn a tool vector into angles \
                     (this machine has {}); program the angles with G43.4",
                    machine.rotary.len()
                )
            };
            return Err(self.alarm(
                Condition::TcpcType2NotAvailable,
                Some(span),
                format!("G43.5: {why}"),
            ));
        }
        if kind == TcpcType::Vector
            && !self.dialect.tcpc_startup_controls_tip
            && machine.machine_type() != MachineType::Head
            && let Some(span) = self.op_vector_span()
        {
            return Err(self.alarm(
                Condition::TcpcIjkInStartBlock,
                Some(span),
                "I, J, K cannot be given in the G43.5 block on a table or mixed machine".into(),
            ));
        }
        // LinuxCNC switches its kinematics by M code, which takes no P: a
        // P in that block belongs to another function (G64 P…); Haas's
        // G234 takes none either (its alarm is raised before).
        let posture = if machine.control == Control::LinuxCnc || table_zero {
            None
        } else {
            self.fanuc.tool_posture()?
        };
        let posture = posture.unwrap_or(machine.params.tool_posture_control);
        let rules = self.rules();
        let inclination = match kind {
            TcpcType::Vector => self.fanuc.inclination(&rules),
            TcpcType::Angles => 0.0,
        };
        let joints = self.state.joints;
        // LinuxCNC's TCP kinematics program the tool tip in the table frame
        // as it stands with every rotary axis at 0, whatever the rotary
        // axes are when the kinematics are switched (5-axis-kinematics.adoc:
        // the world point is the tip on the workpiece table); so does
        // Haas's G234, and a SINUMERIK's TRAORI (X Y Z are the workpiece
        // coordinates, the work offset measured with the rotary axes at 0:
        // CAM output for TRAORI writes the part's coordinates whatever the
        // rotary axes stand at when TRAORI is switched on).
        let frame = if table_zero
            || machine.control == Control::LinuxCnc
            || machine.control == Control::Sinumerik
        {
            IsometryMatrix3::identity()
        } else {
            machine.chain(Side::Table, &joints)
        };
        let dir_table = machine.forward(&joints, 0.0).dir;
        let tilt_sign = self.tilt_side(&joints);
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
        if self.feature().is_some() {
            // Inside G68.2 the tool vector is read in the feature frame.
            self.state.tcpc.vector = self.programming_map(&joints).rotation * dir_table;
        }
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
        if let Some((at, length, frames, point)) = self.state.tcpc.last
            && at == *joints
            && length == self.tool_length()
            && frames == self.frames_key()
        {
            return point;
        }
        let tip_table = self.machine.programmed_pose(joints, self.tool_length()).tip;
        let ideal = self.ideal_from_real(&tip_table);
        let map = self.programming_map(joints);
        map.transform_point(&ideal.into()).coords - self.work() - self.state.comp3d.vector
    }

    /// The tool direction (tip towards spindle) in the programming frame
    /// with the rotary axes at `joints`: what a canned cycle under TCPC
    /// drills along (`cycles.rs`).
    pub(super) fn tcpc_tool_direction(&self, joints: &Joints) -> Vec3 {
        let dir = self.machine.programmed_pose(joints, self.tool_length()).dir;
        let ideal = self.state.setup.inverse_vector(&dir);
        self.programming_map(joints).transform_vector(&ideal)
    }

    /// A positioning under TCPC that turns the rotary axes (a canned
    /// cycle's move to its hole with rotary words): as a G00 block of
    /// type 1, the tip on the straight line in the programming frame from
    /// where it stands to `end_p` (machine position `end`), the rotary
    /// axes linear in s.
    pub(super) fn tcpc_rapid(
        &self,
        start: Joints,
        end_p: &Joints,
        end: Joints,
        travel: &Joints,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        self.check_singular_passage(&start, end_p, travel)?;
        let tip = self.tcpc_line(end_p, &start);
        if start == end && tip.length() == 0.0 {
            return Ok(());
        }
        let path = Path::Tcpc(TcpcPath {
            tip,
            turning: self.state.tcpc.turning,
            posture: None,
        });
        out.push(self.segment(Motion::Rapid, start, end, path));
        Ok(())
    }

    /// What the programmed point depends on besides the joints: the work
    /// offset, the 3-D compensation vector and the setup error.
    fn frames_key(&self) -> FramesKey {
        (self.work(), self.state.comp3d.vector, self.state.setup)
    }

    /// Machine position of X, Y, Z that puts the tip on programmed point
    /// `p` with the rotary axes at `joints`.
    pub(super) fn tcpc_gauge(&self, joints: &Joints, p: &Vec3) -> Vec3 {
        let map = self.programming_map(joints);
        let ideal = map
            .inverse_transform_point(&(p + self.work() + self.state.comp3d.vector).into())
            .coords;
        let tip_table = self.real_from_ideal(&ideal);
        self.machine
            .gauge_for_programmed_tip(joints, &tip_table, self.tool_length())
    }

    /// A point of the ideal workpiece in the table frame as the point of
    /// the real one (G54.4: the error acts about the work zero).
    fn real_from_ideal(&self, x: &Vec3) -> Vec3 {
        self.work() + self.state.setup.point(&(x - self.work()))
    }

    /// The inverse of [`Controller::real_from_ideal`].
    fn ideal_from_real(&self, x: &Vec3) -> Vec3 {
        self.work() + self.state.setup.inverse_point(&(x - self.work()))
    }

    /// Table frame → programming frame (plus the work offset) at `joints`.
    /// On a programming frame that does not turn with the table (WKP = 1)
    /// the table's turn comes first, then the feature frame in force (a
    /// tilted plane defined on the workpiece coordinate system that does
    /// not turn).
    fn programming_map(&self, joints: &Joints) -> IsometryMatrix3<f64> {
        if self.state.tcpc.turning {
            let turn = self.machine.chain(Side::Table, joints);
            match self.feature_isometry(self.work() + self.state.comp3d.vector) {
                Some(feature) => feature * turn,
                None => turn,
            }
        } else {
            self.tcpc_frame()
        }
    }

    /// The programming frame of TCPC: the one fixed at start-up, or the
    /// tilted working plane's feature frame when one is in force (G43.4 /
    /// G43.5 inside G68.2 program in the feature frame).
    fn tcpc_frame(&self) -> IsometryMatrix3<f64> {
        self.feature_isometry(self.work() + self.state.comp3d.vector)
            .unwrap_or(self.state.tcpc.frame)
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
            let span = self.op_axis_span(i);
            return Err(self.alarm(
                Condition::TcpcRotaryWordInType2,
                span,
                format!(
                    "rotary axis word {} in TCPC type 2: program the tool vector I, J, K",
                    char::from(name)
                ),
            ));
        }
        self.block_posture = None;
        let vector_given = self.tcpc_vector(kind)?;
        let mode = self.state.modal.motion;
        let is_arc = matches!(mode, MotionMode::Cw | MotionMode::Ccw);
        let arc_words = is_arc && self.arc_words_present();
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
            let tcpc = &self.state.tcpc;
            let t = inclined(&tcpc.vector, &(p1 - p0), tcpc.inclination);
            let v_table = self
                .state
                .setup
                .vector(&self.tcpc_frame().rotation.inverse_transform_vector(&t));
            let here = [current[i0], current[i1]];
            let chosen = if self.posture_controls_block() {
                // Tool posture control: the axes follow the tool along the
                // great circle, and end wherever that takes them.
                let d0 = machine.forward(&current, self.tool_length()).dir;
                let (posture, end) = self.track_posture([d0, v_table], here, None)?;
                self.block_posture = Some(posture);
                end
            } else {
                self.choose_rotaries(&v_table, here)?
            };
            for (k, i) in [i0, i1].into_iter().enumerate() {
                let shift = self.rotary_shift(i);
                travel[i] = chosen[k] - current[i];
                let angle = if self.is_rollover(i) {
                    super::normalize_360(chosen[k])
                } else {
                    chosen[k]
                };
                end_p[i] = angle - shift;
            }
        } else if self.state.setup_set != 0 && machine.rotary.len() == 2 {
            // G54.4: the programmed angles give the attitude on the ideal
            // workpiece; the axes turn to keep it on the real one.
            let (i0, i1) = (machine.rotary_index(0), machine.rotary_index(1));
            // The programmed angles: where the program stood (its own
            // angles, not the corrected machine's) moved by the block.
            let mut programmed = current;
            programmed[i0] = from[i0] + self.rotary_shift(i0) + travel[i0];
            programmed[i1] = from[i1] + self.rotary_shift(i1) + travel[i1];
            self.state.setup_angles = Some([programmed[i0], programmed[i1]]);
            let ideal = machine.forward(&programmed, 0.0).dir;
            let real = self.state.setup.vector(&ideal);
            let chosen = self.choose_rotaries(&real, [current[i0], current[i1]])?;
            for (k, i) in [i0, i1].into_iter().enumerate() {
                travel[i] = chosen[k] - current[i];
                let angle = if self.is_rollover(i) {
                    super::normalize_360(chosen[k])
                } else {
                    chosen[k]
                };
                end_p[i] = angle - self.rotary_shift(i);
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
                None => self.tcpc_line(&end_p, &start),
            }
        } else {
            self.tcpc_line(&end_p, &start)
        };
        let posture = match self.block_posture.take() {
            Some(mut posture) => {
                // The knots were followed from the axes as they stood; the
                // segment ends on the angles reduced for rollover axes.
                let (i0, i1) = (machine.rotary_index(0), machine.rotary_index(1));
                // Whole turns only: rounding the shift to them keeps the
                // single-precision knots on their solutions.
                let last = posture.knots[POSTURE_KNOTS].1;
                let turns = [end[i0] - f64::from(last[0]), end[i1] - f64::from(last[1])]
                    .map(|d| ((d / 360.0).round() * 360.0) as f32);
                for (_, knot) in &mut posture.knots {
                    knot[0] += turns[0];
                    knot[1] += turns[1];
                }
                posture.start[0] += f64::from(turns[0]);
                posture.start[1] += f64::from(turns[1]);
                posture.knots[POSTURE_KNOTS].1 = [end[i0] as f32, end[i1] as f32];
                Some(posture)
            }
            None if self.posture_controls_block() => {
                // Type 1: the tool turns on the great circle between the
                // directions of the programmed angles, which it must reach.
                let length = self.tool_length();
                let ends = [
                    machine.forward(&start, length).dir,
                    machine.forward(&end, length).dir,
                ];
                let (i0, i1) = (machine.rotary_index(0), machine.rotary_index(1));
                let (posture, _) =
                    self.track_posture(ends, [start[i0], start[i1]], Some([end[i0], end[i1]]))?;
                Some(posture)
            }
            None => None,
        };
        let path = Path::Tcpc(TcpcPath {
            tip,
            turning: self.state.tcpc.turning,
            posture: posture.map(Box::new),
        });
        if start == end && tip.length() == 0.0 {
            return Ok(());
        }
        let feed = if motion == Motion::Rapid {
            None
        } else {
            Some(self.cutting_feed(|| tip.length())?)
        };
        // The program stands exactly where it programmed the tip, not
        // where forward kinematics of the axes puts it back (the next
        // block's start, while the axes, the tool and the frames stay).
        self.state.tcpc.last = Some((
            end,
            self.tool_length(),
            self.frames_key(),
            Vec3::new(end_p[0], end_p[1], end_p[2]),
        ));
        // Built in place: segments are large.
        out.push(self.segment(motion, start, end, path));
        if let Some(seg) = out.last_mut() {
            seg.feed = feed;
        }
        Ok(())
    }

    /// Whether the block moves under tool posture control: the mode asks
    /// for it and the machine has the two rotary axes it needs.
    fn posture_controls_block(&self) -> bool {
        let joint_path = self.state.tcpc.startup && !self.dialect.tcpc_startup_controls_tip;
        self.state.tcpc.posture && self.machine.rotary.len() == 2 && !joint_path
    }

    /// Follows the rotary axes along the great circle of tool directions
    /// between `ends`, from the angles `from`, continuously: at each small
    /// turn of the tool the solution nearest the last one. Returns the law
    /// of the block and the angles it ends on, which must be `to` (mod 360)
    /// when the program gives them (type 1).
    ///
    /// Refuses opposite vectors (no single great circle), a circle that
    /// leaves the directions the machine reaches (the reach margin is
    /// followed, and its dips between samples searched), a passage through
    /// the singular direction, a turn too fast for the knots to follow, and
    /// rotary over-travel on the way.
    fn track_posture(
        &self,
        ends: [Vec3; 2],
        from: [f64; 2],
        to: Option<[f64; 2]>,
    ) -> Result<(Posture, [f64; 2]), Alarm> {
        let angle = ends[0].cross(&ends[1]).norm().atan2(ends[0].dot(&ends[1]));
        if std::f64::consts::PI - angle < POSTURE_OPPOSITE {
            return Err(self.alarm(
                Condition::PostureUndefined,
                None,
                "tool posture control between opposite tool vectors: no single great circle".into(),
            ));
        }
        // First pass: follow the axes, check the way, measure their motion
        // (and the turn of the free axis leaving a singular start).
        let mut travel = 0.0;
        let mut lead_turn = 0.0;
        let end = self.follow_circle(&ends, from, angle, |s, angles, step| {
            if s == 0.0 {
                lead_turn = (angles[0] - from[0]).abs() + (angles[1] - from[1]).abs();
            }
            travel += step;
            Ok(())
        })?;
        if travel / POSTURE_KNOTS as f64 > POSTURE_GUIDE_TURN {
            return Err(self.alarm(
                Condition::TcpcSingularPassage,
                None,
                format!(
                    "tool posture control turns the rotary axes {travel} degrees near the singular direction: too fast to follow"
                ),
            ));
        }
        // Leaving a singular start, the free axis turns first, in the
        // block's first `lead` share, while the tool stays put.
        let lead = if lead_turn > 0.0 {
            lead_turn / (lead_turn + travel)
        } else {
            0.0
        };
        let at = |s: f64| lead + (1.0 - lead) * s;
        // Second pass, the same way: knots at equal shares of the motion,
        // so that between two knots no axis strays far from their line.
        let knot = |s: f64, angles: [f64; 2]| (s as f32, angles.map(|a| a as f32));
        let mut knots = [knot(0.0, from); POSTURE_KNOTS + 1];
        let mut done = 0.0;
        let mut next_knot = 1;
        self.follow_circle(&ends, from, angle, |s, angles, step| {
            done += step;
            if s == 0.0 && lead > 0.0 {
                // The way out: a knot of its own, where the lead ends.
                knots[1] = knot(lead, angles);
                next_knot = 2;
                return Ok(());
            }
            while next_knot < POSTURE_KNOTS
                && done
                    >= travel * (next_knot - usize::from(lead > 0.0)) as f64 / POSTURE_KNOTS as f64
                && travel > 0.0
            {
                knots[next_knot] = knot(at(s), angles);
                next_knot += 1;
            }
            Ok(())
        })?;
        // Knots left over (no motion) sit on the end.
        for slot in &mut knots[next_knot..] {
            *slot = knot(1.0, end);
        }
        let mut last = end;
        if let Some(target) = to {
            if (0..2).any(|k| (principal(end[k] - target[k])).abs() > POSTURE_END_TOLERANCE) {
                return Err(self.alarm(
                    Condition::TcpcSingularPassage,
                    None,
                    format!(
                        "tool posture control reaches the rotary angles ({}, {}), not the programmed ({}, {})",
                        end[0], end[1], target[0], target[1]
                    ),
                ));
            }
            last = [0, 1].map(|k| end[k] + principal(target[k] - end[k]));
        }
        knots[POSTURE_KNOTS] = knot(1.0, last);
        Ok((
            Posture {
                ends,
                knots,
                lead,
                start: from,
            },
            last,
        ))
    }

    /// Follows the rotary axes from `from` along the great circle between
    /// `ends` (`angle` radians apart) in small turns of the tool, taking at
    /// each the solution nearest the last. Calls `visit(s, angles, turn)`
    /// at every step (first at s = 0 with the start, where the free axis of
    /// a singular start takes the angle of the way out). Returns the angles
    /// at the end.
    fn follow_circle(
        &self,
        ends: &[Vec3; 2],
        from: [f64; 2],
        angle: f64,
        mut visit: impl FnMut(f64, [f64; 2], f64) -> Result<(), Alarm>,
    ) -> Result<[f64; 2], Alarm> {
        let machine = self.machine;
        let steps = ((angle.to_degrees() / POSTURE_TRACK_ANGLE).ceil() as usize).max(1);
        let direction = |s: f64| crate::segment::slerp(&ends[0], &ends[1], s);
        let unreachable = |dir: &Vec3| {
            self.alarm(
                Condition::ToolDirectionUnreachable,
                None,
                format!(
                    "tool posture control passes a tool direction ({}, {}, {}) no rotary position gives",
                    dir.x, dir.y, dir.z
                ),
            )
        };
        // Leaving the singular direction the rotating axis is free: it
        // takes the angle of the way out at once (the tool does not move).
        let mut previous = from;
        if let Some(free) = machine.orientations(&ends[0], from).free_axis {
            let out = crate::segment::posture_angles(machine, &direction(1.0 / steps as f64), from);
            previous[free] = out[free];
        }
        visit(0.0, previous, 0.0)?;
        let mut margins = [machine.reach_margin(&ends[0]); 3];
        for i in 1..=steps {
            let s = i as f64 / steps as f64;
            let dir = direction(s);
            margins = [margins[1], margins[2], machine.reach_margin(&dir)];
            if margins[2] < -POSTURE_REACH_TOLERANCE {
                return Err(unreachable(&dir));
            }
            // A dip of the margin between samples: search it.
            if i >= 2
                && margins[1] <= margins[0]
                && margins[1] <= margins[2]
                && margins[1] < POSTURE_REFINE_BELOW
            {
                let step = 1.0 / steps as f64;
                let (dip, at) = crate::search::golden_minimum(
                    |t| machine.reach_margin(&direction(t)),
                    (s - 2.0 * step).max(0.0),
                    s.min(1.0),
                );
                if dip < -POSTURE_REACH_TOLERANCE {
                    return Err(unreachable(&direction(at)));
                }
            }
            if machine.orientations(&dir, previous).is_empty() {
                return Err(unreachable(&dir));
            }
            let next = self.posture_step(&direction, (s - 1.0 / steps as f64, previous), s, 0)?;
            let turn = (next[0] - previous[0]).abs() + (next[1] - previous[1]).abs();
            self.check_rotary_limits(&next)?;
            visit(s, next, turn)?;
            previous = next;
        }
        Ok(previous)
    }

    /// The rotary angles at `s`, followed from `(s0, angles)`: when the axes
    /// turn much in one step (near the singular direction) the step is
    /// halved until they turn little, so that the solution followed stays
    /// the continuous one. A turn that stays large however small the step
    /// is the passage through the singular direction itself.
    fn posture_step(
        &self,
        direction: &dyn Fn(f64) -> Vec3,
        (s0, angles): (f64, [f64; 2]),
        s: f64,
        depth: u32,
    ) -> Result<[f64; 2], Alarm> {
        let next = crate::segment::posture_angles(self.machine, &direction(s), angles);
        let turn = (next[0] - angles[0]).abs() + (next[1] - angles[1]).abs();
        if turn <= POSTURE_STEP_TURN {
            return Ok(next);
        }
        if depth >= POSTURE_REFINE_DEPTH {
            return Err(self.alarm(
                Condition::TcpcSingularPassage,
                None,
                "tool posture control passes the singular direction: the rotating axis would turn half a turn at once"
                    .into(),
            ));
        }
        let mid = 0.5 * (s0 + s);
        let halfway = self.posture_step(direction, (s0, angles), mid, depth + 1)?;
        self.posture_step(direction, (mid, halfway), s, depth + 1)
    }

    /// Over-travel of a rotary axis at `angles` (rotary file order).
    fn check_rotary_limits(&self, angles: &[f64; 2]) -> Result<(), Alarm> {
        for (k, axis) in self.machine.rotary.iter().enumerate() {
            let Some((min, max)) = axis.limits.filter(|_| !axis.rollover) else {
                continue;
            };
            let a = angles[k];
            if a > max + super::LIMIT_TOLERANCE || a < min - super::LIMIT_TOLERANCE {
                let (condition, side, bound) = if a > max {
                    (Condition::OvertravelPlus, '+', max)
                } else {
                    (Condition::OvertravelMinus, '-', min)
                };
                return Err(self.alarm(
                    condition,
                    None,
                    format!(
                        "{0}{side} over-travel: {0} would reach {a} beyond the soft limit {bound} under tool posture control",
                        axis.name
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
        let Some(span) = self.op_vector_span() else {
            return Ok(false);
        };
        if kind == TcpcType::Angles {
            if self.dialect.tcpc_startup_controls_tip {
                self.fanuc.drop_vector();
            }
            return Ok(false);
        }
        let v = Vec3::from(self.op_vector());
        if v.norm() <= TRAVEL_EPSILON {
            return Err(self.alarm(
                Condition::ToolVectorZero,
                Some(span),
                "the tool vector (I, J, K) gives no direction".into(),
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
        let (a, b) = (current[tilt], end_p[tilt] + self.rotary_shift(tilt));
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
    fn tcpc_line(&self, end_p: &Joints, start: &Joints) -> TipPath {
        let shift = self.work() + self.state.comp3d.vector;
        let programmed = Vec3::new(end_p[0], end_p[1], end_p[2]);
        let p1 = if self.state.tcpc.turning {
            // WKP = 1: a feature frame in force is defined on the work
            // coordinate system that does not turn.
            self.feature_to_work(&programmed) + shift
        } else {
            programmed + shift
        };
        // The line starts where the tip really is: on the programmed start
        // when nothing changed, and off it when the block itself changes
        // what the programmed point means (the start-up block, a 3-D
        // compensation vector, a tool length): the axes then move
        // continuously from where they stand.
        let here = self.machine.forward(start, self.tool_length()).tip;
        if self.state.tcpc.turning {
            // WKP = 1: the tip path is the programmed (ideal) line in the
            // work coordinate system that does not turn; the setup error
            // acts on the table, so the segment applies it point by point
            // after turning the tip into the table frame.
            let ideal = self.ideal_from_real(&here);
            let tip0 = self
                .machine
                .chain(Side::Table, start)
                .transform_point(&ideal.into())
                .coords;
            TipPath::Line([tip0, p1])
        } else {
            let frame = &self.tcpc_frame();
            let table = |p: &Vec3| {
                self.real_from_ideal(&frame.inverse_transform_point(&(*p).into()).coords)
            };
            TipPath::Line([here, table(&p1)])
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
        let [p, q] = geo.axes;
        let shift = self.work() + self.state.comp3d.vector;
        let mut center = Vec3::new(from[0], from[1], from[2]) + shift;
        center[p] = geo.center[0] + shift[p];
        center[q] = geo.center[1] + shift[q];
        let mut axes = [p, q, geo.normal].map(crate::segment::unit);
        if self.state.tcpc.turning && self.feature().is_some() {
            // WKP = 1: the circle of the feature plane in the work
            // coordinate system that does not turn.
            let origin = self.feature_to_work(&Vec3::zeros());
            center = self.feature_to_work(&(center - shift)) + shift;
            for axis in &mut axes {
                *axis = self.feature_to_work(axis) - origin;
            }
        }
        if !self.state.tcpc.turning {
            let frame = &self.tcpc_frame();
            center = frame.inverse_transform_point(&center.into()).coords;
            for axis in &mut axes {
                *axis = frame.rotation.inverse_transform_vector(axis);
            }
        }
        // On a turning frame the circle stays ideal in the machine frame
        // (the segment applies the setup error in the table frame).
        if !self.state.tcpc.turning {
            center = self.real_from_ideal(&center);
            axes = axes.map(|a| self.state.setup.vector(&a));
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

    /// The rotary angles TCPC would command to point the tool along `dir`
    /// (a unit vector in the table frame) from the rotary positions
    /// `current` (machine order, degrees), in the controller's present
    /// state: the machine's `rotary_choice` among the solutions and their
    /// 360° repeats inside the soft limits. An alarm when no position
    /// reaches `dir`, or when the machine has not two rotary axes.
    pub fn rotary_position_for(&self, dir: &Vec3, current: [f64; 2]) -> Result<[f64; 2], Alarm> {
        if self.machine.rotary.len() != 2 {
            return Err(self.alarm(
                Condition::ToolDirectionUnreachable,
                None,
                format!(
                    "the machine has {} rotary axes: only a machine with two chooses a tool direction",
                    self.machine.rotary.len()
                ),
            ));
        }
        self.choose_rotaries(dir, current)
    }

    /// The rotary angles (machine, unwrapped near `current`) that point the
    /// tool along `dir` (table frame), chosen by the control's rule among
    /// the solutions and their 360° repeats inside the soft limits.
    pub(super) fn choose_rotaries(&self, dir: &Vec3, current: [f64; 2]) -> Result<[f64; 2], Alarm> {
        let rule = if self.state.setup_set != 0 {
            // G54.4 in force: Mazak F162 bit 1.
            if self.machine.params.setup_error_table_motion {
                Choice::TableMotion
            } else {
                Choice::KeepTilt(self.state.setup_tilt_sign)
            }
        } else {
            Choice::Control
        };
        self.choose_rotaries_by(dir, current, rule)
    }

    /// [`Controller::choose_rotaries`] by an explicit rule.
    pub(super) fn choose_rotaries_by(
        &self,
        dir: &Vec3,
        current: [f64; 2],
        choice: Choice,
    ) -> Result<[f64; 2], Alarm> {
        let machine = self.machine;
        self.block_chose_rotary.set(true);
        let found = machine.orientations(dir, current);
        let rotating = self.rotating_axis();
        let (rule, tilt_sign, scored) = match choice {
            _ if self.in_singular_zone(dir, rotating) => {
                (RotaryChoice::RotatingAxis, 0.0, rotating)
            }
            Choice::Control => (
                machine.params.rotary_choice,
                self.state.tcpc.tilt_sign,
                rotating,
            ),
            Choice::TableMotion => (RotaryChoice::RotatingAxis, 0.0, self.table_axis()),
            Choice::KeepTilt(sign) => (RotaryChoice::KeepTiltSign, sign, rotating),
            Choice::FirstAxis(higher) => (
                RotaryChoice::Shortest,
                if higher { -1.0 } else { 1.0 },
                rotating,
            ),
        };
        let first_axis = matches!(choice, Choice::FirstAxis(_));
        let rotating = scored;
        let mut best: Option<(f64, f64, [f64; 2])> = None;
        for pair in found.pairs() {
            for a in self.repeats(0, pair[0], current[0]).into_iter().flatten() {
                for b in self.repeats(1, pair[1], current[1]).into_iter().flatten() {
                    let candidate = [a, b];
                    let key = if first_axis {
                        // tilt_sign −1 prefers the higher angle.
                        (
                            tilt_sign * candidate[0],
                            choice_key(rule, &candidate, &current, rotating, 0.0).0,
                        )
                    } else {
                        choice_key(rule, &candidate, &current, rotating, tilt_sign)
                    };
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
                // At most three repeats fit the limits the machine file
                // allows; the loop is bounded by that count, not by the
                // magnitudes (at 1e18 adding 360 changes nothing).
                let mut out = [None; 3];
                let mut n = 0;
                let first = angle - 360.0 * ((angle - min) / 360.0).floor();
                for turn in 0..4 {
                    let a = first + 360.0 * f64::from(turn);
                    if a > max + super::LIMIT_TOLERANCE || n == 3 {
                        break;
                    }
                    if a >= min - super::LIMIT_TOLERANCE {
                        out[n] = Some(a);
                        n += 1;
                    }
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

/// Which rule picks the rotary pair.
#[derive(Clone, Copy, Debug)]
pub(super) enum Choice {
    /// The machine's `rotary_choice`.
    Control,
    /// The smaller motion of the table axis (the G54.4 block).
    TableMotion,
    /// Keep the tilt axis on this side (+1 or −1).
    KeepTilt(f64),
    /// The solution whose first rotary axis has the higher (`true`) or
    /// lower angle (SINUMERIK CYCLE800 `_DIR`), then the smaller motion.
    FirstAxis(bool),
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
