//! The control-neutral commands (`crate::command`) carried out on the
//! kernel's functions: modal settings straight into the state, frames as
//! the feature frame of `coordinates/feature_frame.rs`, tool centre point
//! control through `tcpc.rs`, and the block's move through the same
//! motion, compensation and limit checks a FANUC block goes through.
//!
//! A block of commands is one unit: on an alarm the state is as before
//! it and nothing of it is released.

use fiveaxis_gcode::Span;
use fiveaxis_machine::{Joints, MAX_AXES, Side, Vec3};
use nalgebra::Rotation3;

use super::coordinates::Feature;
use super::{Controller, Flow, MAX_DWELL_SECONDS, normalize_360, shortest_turn};
use crate::alarm::{Alarm, Condition};
use crate::command::{
    Command, CommandBlock, CutterSide, Frame, Move, SpaceCircle, Suppress, TargetMode, WorkOffset,
};
use crate::modal::{Distance, LengthMode, TcpcType, WorkSelect};
use crate::segment::{Motion, Path, Segment, TipPath};

/// The frames a front end keeps in force beside the work offset, from
/// the outside in: a settable frame in place of the work offset, the
/// swivel frame (a tilted working plane), the tool frame and the
/// programmable frame; and whether the workpiece coordinates turn with
/// the table (`part`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct NeutralFrames {
    pub(super) programmable: Frame,
    pub(super) swivel: Option<Frame>,
    pub(super) settable: Option<Frame>,
    pub(super) tool: Option<Frame>,
    pub(super) part: bool,
}

impl Controller<'_> {
    /// Carries out one block of commands; appends its segments to `out`.
    ///
    /// # Errors
    ///
    /// The alarm the control raises; the state is then as before the
    /// block and nothing is appended.
    pub fn run_block(
        &mut self,
        block: &CommandBlock,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let base = out.len();
        self.stop = None;
        self.fanuc.clear(block.line);
        self.operands.start();
        let saved = self.state;
        let saved_frames = self.neutral;
        if let Some(n) = block.number {
            self.state.sequence = Some(n);
        }
        let result = self.run_commands(block, base, out);
        if result.is_err() {
            self.state = saved;
            self.neutral = saved_frames;
            out.truncate(base);
        }
        self.pending_exact_stop = false;
        self.block_turns = None;
        result
    }

    fn run_commands(
        &mut self,
        block: &CommandBlock,
        base: usize,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let mut motion: Option<Move> = None;
        let mut align: Option<(Option<bool>, bool, Span)> = None;
        for command in &block.commands {
            match *command {
                Command::Interpolation(mode) => self.state.modal.motion = mode,
                Command::Plane(plane) => self.state.modal.plane = plane,
                Command::Distance(d) => self.state.modal.distance = d,
                Command::FeedMode(mode) => self.state.modal.feed_mode = mode,
                Command::PathMode(mode) => self.state.modal.cutting = mode,
                Command::ExactStop => self.pending_exact_stop = true,
                Command::Feed { value, span } => self.operands.feed = Some((value, span)),
                Command::SpindleSpeed(s) => self.state.spindle_speed = s,
                Command::MFunction { number, span } => self.push_m_function(number, span)?,
                Command::ToolSelect { tool, span } => self.operands.tool = Some((tool, span)),
                Command::ToolOffset { number, span } => self.tool_offset(number, span)?,
                Command::ToolDelta { length, radius } => self.state.tool_delta = [length, radius],
                Command::Radius { side, span } => self.radius_side(side, span)?,
                Command::WorkOffset(w) => {
                    self.state.modal.work = match w {
                        WorkOffset::Null => WorkSelect::Null,
                        WorkOffset::Standard(i) => WorkSelect::Standard(i),
                        WorkOffset::Extended(p) => WorkSelect::Extended(p),
                    }
                }
                Command::ProgrammableFrame(frame) => {
                    self.neutral.programmable = frame;
                    self.refresh_neutral_frames();
                }
                Command::SwivelFrame(frame) => {
                    self.neutral.swivel = frame;
                    self.refresh_neutral_frames();
                }
                Command::SettableFrame(frame) => {
                    self.neutral.settable = frame;
                    self.refresh_neutral_frames();
                }
                Command::ToolFrame(frame) => {
                    self.neutral.tool = frame;
                    self.refresh_neutral_frames();
                }
                Command::PartFrame(on) => {
                    self.neutral.part = on;
                    self.refresh_neutral_frames();
                }
                Command::AlignTool {
                    higher,
                    keep_tip,
                    span,
                } => align = Some((higher, keep_tip, span)),
                Command::Tcp { mode, span } => self.tcp(mode, span)?,
                Command::PathSmoothing { on, tolerance } => {
                    let accuracy = &mut self.state.modal.accuracy;
                    accuracy.contour = if on {
                        crate::modal::ContourControl::AiContour
                    } else {
                        crate::modal::ContourControl::Off
                    };
                    accuracy.corner_rounding = if on { tolerance } else { None };
                }
                Command::OrientationPath { great_circle } => {
                    self.state.orientation_path = Some(great_circle);
                    if matches!(self.state.modal.length, LengthMode::Tcpc(_)) {
                        self.state.tcpc.set_posture(great_circle);
                    }
                }
                Command::Dwell { seconds, span } => {
                    if !(0.0..=MAX_DWELL_SECONDS).contains(&seconds) {
                        return Err(self.alarm(
                            Condition::ValueOutOfRange,
                            Some(span),
                            format!("dwell time {seconds} s is outside 0 to {MAX_DWELL_SECONDS} s"),
                        ));
                    }
                }
                Command::DataSetting(data) => {
                    let from = self.programmed(&self.state.joints);
                    self.set_data(&data, &from)?;
                }
                Command::Move(m) => motion = Some(m),
                Command::Retract { distance, span } => {
                    motion = Some(self.retract_move(distance, span));
                }
            }
        }
        if let Some((higher, keep_tip, span)) = align {
            return self.align_tool(higher, keep_tip, span, base, out);
        }
        match motion {
            Some(m) if m.suppress != Suppress::Nothing => self.machine_move(&m, base, out),
            Some(m) if m.circle.is_some() => self.space_circle(&m, base, out),
            Some(m) => self.command_move(&m, base, out),
            None => self.execute_loaded(base, out),
        }
    }

    /// D: the offset memory in force (length along the tool, radius);
    /// the axes stay, the programmed position takes the change.
    fn tool_offset(&mut self, number: u32, span: Span) -> Result<(), Alarm> {
        if let Some(max) = self.tool_memory
            && number > max
        {
            return Err(self.alarm(
                Condition::IllegalOffsetNumber,
                Some(span),
                format!("tool offset {number} is beyond the offset memory (the offsets file holds up to {max})"),
            ));
        }
        self.state.h = number;
        self.note_length_tool();
        self.state.d = number;
        if !matches!(self.state.modal.length, LengthMode::Tcpc(_)) {
            self.state.modal.length = if number == 0 {
                LengthMode::Off
            } else {
                LengthMode::ToolAxis
            };
        }
        Ok(())
    }

    /// Radius compensation on a side of the contour or off, through cutter
    /// compensation C (`cutter_c.rs`), with the radius of the offset
    /// memory in force (`Command::ToolOffset`). The start-up and cancel
    /// are the engine's: the tool stands perpendicular to the contour at
    /// the end of the start-up block and at the start of the cancel block
    /// (SINUMERIK NORM, brief §6).
    fn radius_side(&mut self, side: CutterSide, _span: Span) -> Result<(), Alarm> {
        if !self.cutter.routing() {
            // The block starts where the program stands (FANUC reads it
            // before G41 / G42 take effect in the block).
            self.cutter.point = self.programmed(&self.state.joints);
        }
        self.select_cutter_side(match side {
            CutterSide::Off => None,
            CutterSide::Left => Some(crate::cutter::Side::Left),
            CutterSide::Right => Some(crate::cutter::Side::Right),
        });
        Ok(())
    }

    /// Tool centre point control on or off. Off leaves the tool length
    /// along the tool in force (the edge stays selected).
    fn tcp(&mut self, mode: Option<TcpcType>, span: Span) -> Result<(), Alarm> {
        match mode {
            Some(kind) => {
                if self.state.modal.length == LengthMode::Tcpc(kind) {
                    return Ok(());
                }
                self.start_tcpc(kind, span)?;
                if let Some(great_circle) = self.state.orientation_path {
                    self.state.tcpc.set_posture(great_circle);
                }
                self.state.modal.length = LengthMode::Tcpc(kind);
            }
            None => {
                if matches!(self.state.modal.length, LengthMode::Tcpc(_)) {
                    self.state.modal.length = if self.state.h == 0 {
                        LengthMode::Off
                    } else {
                        LengthMode::ToolAxis
                    };
                }
            }
        }
        Ok(())
    }

    /// The feature frame from the settable, swivel, tool and programmable
    /// frames (their translations and rotations); the programmable frame's
    /// scale and mirror as the program transforms inside it (mirror, then
    /// scale, then the feature frame: `T + R·S·M·p`).
    fn refresh_neutral_frames(&mut self) {
        let n = self.neutral;
        let p = n.programmable;
        let outer = n
            .settable
            .unwrap_or_default()
            .then(&n.swivel.unwrap_or_default())
            .then(&n.tool.unwrap_or_default());
        let origin = outer.translation + outer.rotation * p.translation;
        let rotation = outer.rotation * p.rotation;
        let on = n.settable.is_some()
            || n.swivel.is_some()
            || n.tool.is_some()
            || n.part
            || !p.is_rigid_identity();
        self.state.feature = on.then(|| Feature::plane(origin, rotation));
        self.state.frames.set_scale_mirror(p.scale, p.mirror);
        for i in 3..MAX_AXES {
            self.state.axis_shift[i] = outer.axis_shift[i] + p.axis_shift[i];
        }
    }

    /// The programmed position in the program's own coordinates (before
    /// the programmable frame's scale and mirror): where a front end's
    /// absolute coordinates are measured.
    pub(crate) fn program_position(&self) -> Joints {
        let mut p = self.programmed_position();
        if self.state.frames.maps() {
            let x = self.state.frames.invert(&Vec3::new(p[0], p[1], p[2]));
            p[..3].copy_from_slice(x.as_slice());
        }
        p
    }

    /// The tool direction in the workpiece (table) frame, by forward
    /// kinematics of the axes where they stand.
    pub(crate) fn tool_direction(&self) -> Vec3 {
        self.machine.forward(&self.state.joints, 0.0).dir
    }

    /// The tool direction in the machine frame (the head's rotary axes
    /// turn it, the table's do not).
    pub(crate) fn tool_direction_machine(&self) -> Vec3 {
        self.machine.chain(Side::Head, &self.state.joints).rotation
            * self.machine.tool_direction.into_inner()
    }

    /// The rotation of the tool's frame in the workpiece frame at the
    /// machine positions `joints`: the head's turns, the table's undone
    /// (its Z is the tool direction of [`fiveaxis_machine::Machine::forward`]).
    pub(crate) fn tool_rotation_at(&self, joints: &Joints) -> Rotation3<f64> {
        let head = self.machine.chain(Side::Head, joints).rotation;
        let table = self.machine.chain(Side::Table, joints).rotation;
        let base = Rotation3::rotation_between(&Vec3::z(), &self.machine.tool_direction)
            .unwrap_or_else(|| Rotation3::from_axis_angle(&Vec3::x_axis(), std::f64::consts::PI));
        table.inverse() * head * base
    }

    /// The radius of the offset memory in force (with its wear and the
    /// program's delta), mm.
    pub(crate) fn tool_radius_in_force(&self) -> f64 {
        self.tool_radius()
    }

    /// The machine positions now.
    pub(crate) fn joints_now(&self) -> Joints {
        self.state.joints
    }

    /// A circle in space through the functions an arc goes through: the
    /// circle in program coordinates, carried by the program transforms
    /// (a uniform scale and mirror only), the feature frame or the work
    /// offset and setup, and the length offset.
    fn space_circle(
        &mut self,
        m: &Move,
        base: usize,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let Some(SpaceCircle {
            center,
            normal,
            sweep,
        }) = m.circle
        else {
            return self.command_move(m, base, out);
        };
        if self.cutter.routing() || self.tcpc_type().is_some() {
            return Err(self.alarm(
                Condition::ImproperGCode,
                Some(m.span),
                "a circle in space (CIP out of the working plane) under radius compensation or \
                 an orientation transformation"
                    .into(),
            ));
        }
        let flow = self.m_codes_and_values()?;
        let from_p = self.program_position();
        let mut end_p = from_p;
        for (i, t) in m.targets.iter().enumerate().take(self.machine.axis_count()) {
            if let Some(t) = t {
                end_p[i] = t.value;
            }
        }
        let start = Vec3::new(from_p[0], from_p[1], from_p[2]);
        let radial = start - center;
        let r = radial.norm();
        let n = normal.normalize();
        if r <= 0.0 || !r.is_finite() || !n.iter().all(|c| c.is_finite()) {
            return Err(self.alarm(
                Condition::ArcRadiusTolerance,
                Some(m.span),
                "the circle through the intermediate point has no radius".into(),
            ));
        }
        let u = radial / r;
        let v = n.cross(&u);
        let program = TipPath::Arc {
            center,
            axes: [u, v, n],
            radius: [r, r],
            theta0: 0.0,
            sweep,
            rise: 0.0,
        };
        // The program transforms: a circle stays one under a uniform
        // scale and mirror only.
        let circle = if self.state.frames.maps() {
            let unit = [0, 1, 2].map(|k| {
                let mut e = Vec3::zeros();
                e[k] = 1.0;
                self.state.frames.vector(&e).norm()
            });
            if (unit[0] - unit[1]).abs() > 1e-12 || (unit[0] - unit[2]).abs() > 1e-12 {
                return Err(self.alarm(
                    Condition::FrameArcScaling,
                    Some(m.span),
                    "a circle in space under unequal scale factors would be an ellipse".into(),
                ));
            }
            let k = unit[0];
            let f = self.state.frames;
            program.mapped(|x| f.apply(x), |w| f.vector(w) / k)
        } else {
            program
        };
        // Where the circle ends in the controller's coordinates.
        let mut end_c = end_p;
        let e = self
            .state
            .frames
            .apply(&Vec3::new(end_p[0], end_p[1], end_p[2]));
        end_c[..3].copy_from_slice(e.as_slice());
        let end = self.machine_position(&end_c);
        let start_j = self.state.joints;
        let path = if self.feature().is_some() {
            Path::Helix {
                circle: self.feature_circle(&start_j, &circle),
                drift: Vec3::zeros(),
            }
        } else {
            let real = circle.mapped(|x| self.to_real(x), |w| self.state.setup.vector(w));
            let offset = self.length_vector(&start_j);
            Path::Helix {
                circle: real.shifted(&offset),
                drift: self.length_vector(&end) - offset,
            }
        };
        let motion = if sweep >= 0.0 {
            Motion::Ccw
        } else {
            Motion::Cw
        };
        let mut seg = self.segment(motion, start_j, end, path);
        let length = circle.length();
        seg.feed = Some(self.cutting_feed(|| length)?);
        out.push(seg);
        self.finish_block(base, out)?;
        Ok(flow)
    }

    /// The block's move through the functions a FANUC block's motion goes
    /// through: targets read as the command says, then motion, radius
    /// compensation, TCPC and the limit checks.
    fn command_move(
        &mut self,
        m: &Move,
        base: usize,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let mixed = m
            .targets
            .iter()
            .flatten()
            .any(|t| t.mode != TargetMode::Modal)
            || m.center_absolute;
        // Absolute values are measured in the program's coordinates.
        let from = mixed.then(|| self.program_position());
        for (i, target) in m.targets.iter().enumerate().take(self.machine.axis_count()) {
            let Some(t) = target else { continue };
            // With a target read otherwise than the distance mode says,
            // the block's targets are all written as increments.
            let value = match from {
                Some(from) => self.increment(i, from[i], t.value, t.mode),
                None => t.value,
            };
            self.operands.targets[i] = Some((value, t.span));
        }
        for (k, c) in m.center.iter().enumerate() {
            if let Some(c) = *c {
                let value = if m.center_absolute {
                    c - from.map_or(0.0, |f| f[k])
                } else {
                    c
                };
                self.operands.center[k] = Some(value);
            }
        }
        self.operands.radius = m.radius;
        self.operands.span = m.span;
        self.block_turns = m.turns.filter(|&t| t > 0);
        if let Some(v) = m.tool_vector {
            if m.center.iter().any(Option::is_some) {
                return Err(self.alarm(
                    Condition::ImproperGCode,
                    Some(m.span),
                    "a circle and a tool vector in one block".into(),
                ));
            }
            self.operands.vector = Some(v);
        }
        let saved_distance = self.state.modal.distance;
        if mixed {
            self.state.modal.distance = Distance::Incremental;
        }
        let result = self.execute_loaded(base, out);
        self.state.modal.distance = saved_distance;
        result
    }

    /// The move of [`Command::Retract`]: the linear axes along the tool
    /// direction (from the tip towards the spindle, `tool_direction_machine`)
    /// by `distance`, or as far as they go together, clamped to their
    /// travel so that rounding cannot pass a limit.
    fn retract_move(&self, distance: Option<f64>, span: Span) -> Move {
        let d = self.tool_direction_machine();
        let here = self.state.joints;
        let t = distance.unwrap_or_else(|| {
            let mut t = f64::INFINITY;
            for (i, axis) in self.machine.linear.iter().enumerate().take(3) {
                if d[i] > 1e-12 {
                    t = t.min((axis.max - here[i]) / d[i]);
                } else if d[i] < -1e-12 {
                    t = t.min((axis.min - here[i]) / d[i]);
                }
            }
            if t.is_finite() { t.max(0.0) } else { 0.0 }
        });
        let mut mv = Move {
            suppress: Suppress::Axes,
            span,
            ..Move::default()
        };
        for (i, axis) in self.machine.linear.iter().enumerate().take(3) {
            let mut v = here[i] + t * d[i];
            if distance.is_none() {
                v = v.clamp(axis.min, axis.max);
            }
            mv.targets[i] = Some(crate::command::Target {
                value: v,
                mode: TargetMode::Absolute,
                span,
            });
        }
        mv
    }

    /// The increment that takes axis `i` from `from` to `value` read in
    /// `mode` (`Modal`: as the distance mode in force says).
    fn increment(&self, i: usize, from: f64, value: f64, mode: TargetMode) -> f64 {
        let rotary = i >= self.machine.linear.len();
        let incremental = self.state.modal.distance == Distance::Incremental;
        match mode {
            TargetMode::Incremental => value,
            TargetMode::Modal if incremental => value,
            TargetMode::Modal | TargetMode::Absolute => {
                if rotary && self.is_rollover(i) {
                    shortest_turn(normalize_360(from), normalize_360(value))
                } else {
                    value - from
                }
            }
            TargetMode::Shortest => shortest_turn(normalize_360(from), normalize_360(value)),
            TargetMode::Positive => {
                let d = normalize_360(value) - normalize_360(from);
                if d < 0.0 { d + 360.0 } else { d }
            }
            TargetMode::Negative => {
                let d = normalize_360(value) - normalize_360(from);
                if d > 0.0 { d - 360.0 } else { d }
            }
        }
    }

    /// A move in machine coordinates: every frame and offset left out
    /// for the block (SINUMERIK `G53` / `G153` / `SUPA`).
    fn machine_move(
        &mut self,
        m: &Move,
        base: usize,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let current: Joints = self.state.joints;
        let mut end = current;
        let mut travel = [0.0; MAX_AXES];
        for (i, target) in m.targets.iter().enumerate().take(self.machine.axis_count()) {
            let Some(t) = target else { continue };
            let delta = self.increment(i, current[i], t.value, t.mode);
            end[i] = current[i] + delta;
            if self.is_rollover(i) {
                end[i] = normalize_360(end[i]);
            }
            travel[i] = delta;
        }
        if m.suppress == Suppress::Frames {
            // The tool length stays in force: an absolute X, Y, Z is where
            // the tool tip goes, the length vector at the end's rotary
            // positions added.
            let length = self.length_vector(&end);
            for (i, target) in m.targets.iter().enumerate().take(3) {
                if let Some(t) = target
                    && matches!(t.mode, TargetMode::Modal | TargetMode::Absolute)
                    && !(t.mode == TargetMode::Modal
                        && self.state.modal.distance == Distance::Incremental)
                {
                    end[i] = t.value + length[i];
                    travel[i] = end[i] - current[i];
                }
            }
        }
        let flow = self.m_codes_and_values()?;
        let motion = if self.state.modal.motion == crate::modal::MotionMode::Rapid {
            crate::segment::Motion::Rapid
        } else {
            crate::segment::Motion::Linear
        };
        let start = self.rollover_start(&end, &travel);
        self.push_line(motion, start, end, out)?;
        self.finish_block(base, out)?;
        Ok(flow)
    }

    /// The swivel cycle's positioning: the rotary axes turn so that the
    /// tool stands along the Z axis of the frames in force.
    fn align_tool(
        &mut self,
        higher: Option<bool>,
        keep_tip: bool,
        span: Span,
        base: usize,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let flow = self.m_codes_and_values()?;
        let choice = higher.map(super::tcpc::Choice::FirstAxis);
        self.tool_axis_control_by(span, keep_tip, choice, out)?;
        self.finish_block(base, out)?;
        Ok(flow)
    }

    /// The rotary positions (machine order) that put the tool along the Z
    /// axis of the swivel frame in force, by the solution whose first
    /// rotary axis is higher (`true`) or lower, without moving: what
    /// HEIDENHAIN `PLANE … STAY` computes for the program to move to.
    pub(crate) fn plane_axes(&self, higher: Option<bool>, span: Span) -> Result<[f64; 2], Alarm> {
        let choice = higher.map(super::tcpc::Choice::FirstAxis);
        self.plane_rotaries("PLANE", span, choice)
    }

    /// Adds M function `number` of a block of commands. Alarms past the
    /// kernel's bound of M functions per block.
    fn push_m_function(&mut self, number: u16, span: Span) -> Result<(), Alarm> {
        let o = &mut self.operands;
        if o.m_len >= o.m.len() {
            return Err(self.alarm(
                Condition::GCodeConflict,
                Some(span),
                "too many M functions in one block".into(),
            ));
        }
        o.m[o.m_len] = (fiveaxis_gcode::Code::new(number, 0), span);
        o.m_len += 1;
        Ok(())
    }

    /// The M functions and F, S, T values of a block whose move does not
    /// go through [`Controller::execute_loaded`].
    fn m_codes_and_values(&mut self) -> Result<Flow, Alarm> {
        let flow = self.m_codes()?;
        self.apply_values(false)?;
        Ok(flow)
    }

    /// The checks every block ends with: every value used, clamps, soft
    /// limits; the position taken on.
    fn finish_block(&mut self, base: usize, out: &mut [Segment]) -> Result<(), Alarm> {
        self.fanuc.check_all_used()?;
        self.check_clamps(&out[base..])?;
        for seg in &out[base..] {
            self.check_limits(seg)
                .map_err(|a| super::at_line(a, seg.line))?;
        }
        if let Some(last) = out[base..].last() {
            self.state.joints = last.end;
        }
        Ok(())
    }
}
