//! The control-neutral commands (`crate::command`) carried out on the
//! kernel's functions: modal settings straight into the state, frames as
//! the feature frame of `coordinates/feature_frame.rs`, tool centre point
//! control through `tcpc.rs`, and the block's move through the same
//! motion, compensation and limit checks a FANUC block goes through.
//!
//! A block of commands is one unit: on an alarm the state is as before
//! it and nothing of it is released.

use fiveaxis_gcode::Span;
use fiveaxis_machine::{Joints, MAX_AXES};

use super::coordinates::Feature;
use super::{Controller, Flow, MAX_DWELL_SECONDS, normalize_360, shortest_turn};
use crate::alarm::{Alarm, Condition};
use crate::command::{
    Command, CommandBlock, CutterSide, Frame, Move, Suppress, TargetMode, WorkOffset,
};
use crate::modal::{Distance, LengthMode, TcpcType, WorkSelect};
use crate::segment::Segment;

/// The frames a front end keeps in force beside the work offset: the
/// swivel frame (a tilted working plane) and, inside it, the
/// programmable frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct NeutralFrames {
    pub(super) programmable: Frame,
    pub(super) swivel: Option<Frame>,
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
        self.words.clear(block.line);
        let saved = self.state.clone();
        if let Some(n) = block.number {
            self.state.sequence = Some(n);
        }
        let result = self.run_commands(block, base, out);
        if result.is_err() {
            self.state = saved;
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
        let mut align: Option<(bool, Span)> = None;
        for command in &block.commands {
            match *command {
                Command::Interpolation(mode) => self.state.modal.motion = mode,
                Command::Plane(plane) => self.state.modal.plane = plane,
                Command::Distance(d) => self.state.modal.distance = d,
                Command::FeedMode(mode) => self.state.modal.feed_mode = mode,
                Command::PathMode(mode) => self.state.modal.cutting = mode,
                Command::ExactStop => self.pending_exact_stop = true,
                Command::Feed { value, span } => self.words.set(b'F', value, span),
                Command::SpindleSpeed(s) => self.state.spindle_speed = s,
                Command::MFunction { number, span } => self.words.push_m(number, span)?,
                Command::ToolSelect { tool, span } => self.words.set(b'T', f64::from(tool), span),
                Command::ToolOffset { number, span } => self.tool_offset(number, span)?,
                Command::Radius { side, span } => self.radius_side(side, span)?,
                Command::WorkOffset(w) => {
                    self.state.modal.work = match w {
                        WorkOffset::Null => WorkSelect::Null,
                        WorkOffset::Standard(i) => WorkSelect::Standard(i),
                        WorkOffset::Extended(p) => WorkSelect::Extended(p),
                    }
                }
                Command::ProgrammableFrame(frame) => {
                    self.state.neutral.programmable = frame;
                    self.refresh_neutral_frames();
                }
                Command::SwivelFrame(frame) => {
                    self.state.neutral.swivel = frame;
                    self.refresh_neutral_frames();
                }
                Command::AlignTool { higher, span } => align = Some((higher, span)),
                Command::Tcp { mode, span } => self.tcp(mode, span)?,
                Command::Dwell { seconds, span } => {
                    if !(0.0..=MAX_DWELL_SECONDS).contains(&seconds) {
                        return Err(self.alarm(
                            Condition::ValueOutOfRange,
                            Some(span),
                            format!("dwell time {seconds} s is outside 0 to {MAX_DWELL_SECONDS} s"),
                        ));
                    }
                }
                Command::Move(m) => motion = Some(m),
            }
        }
        if let Some((higher, span)) = align {
            return self.align_tool(higher, span, base, out);
        }
        match motion {
            Some(m) if m.suppress == Suppress::Frames => self.machine_move(&m, base, out),
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

    /// Radius compensation: off is always possible; on a side it needs
    /// cutter compensation C's look-ahead, which the command path does
    /// not hold blocks for yet.
    fn radius_side(&mut self, side: CutterSide, span: Span) -> Result<(), Alarm> {
        match side {
            CutterSide::Off if !self.cutter.routing() => Ok(()),
            _ => Err(self.alarm(
                Condition::ImproperGCode,
                Some(span),
                "tool radius compensation on the contour (G41 / G42) is not carried out for \
                 this control yet"
                    .into(),
            )),
        }
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

    /// The feature frame from the swivel and programmable frames.
    fn refresh_neutral_frames(&mut self) {
        let NeutralFrames {
            programmable: p,
            swivel,
        } = self.state.neutral;
        let s = swivel.unwrap_or_default();
        let origin = s.translation + s.rotation * p.translation;
        let rotation = s.rotation * p.rotation;
        self.state.feature =
            (swivel.is_some() || !p.is_identity()).then(|| Feature::plane(origin, rotation));
        for i in 3..MAX_AXES {
            self.state.axis_shift[i] = s.axis_shift[i] + p.axis_shift[i];
        }
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
        let from = if mixed {
            Some(if self.cutter.routing() {
                self.cutter.point
            } else {
                self.programmed(&self.state.joints)
            })
        } else {
            None
        };
        let incremental = self.state.modal.distance == Distance::Incremental;
        for (i, target) in m.targets.iter().enumerate().take(self.machine.axis_count()) {
            let Some(t) = target else { continue };
            // With a target read otherwise than the distance mode says,
            // the block's targets are all written as increments.
            let value = match from {
                Some(from) => {
                    let mode = match t.mode {
                        TargetMode::Modal if incremental => TargetMode::Incremental,
                        TargetMode::Modal => TargetMode::Absolute,
                        mode => mode,
                    };
                    self.increment(i, from[i], t.value, mode)
                }
                None => t.value,
            };
            self.words.set(self.axis_letters[i], value, t.span);
        }
        for (k, c) in m.center.iter().enumerate() {
            if let Some(c) = *c {
                let value = if m.center_absolute {
                    c - from.map_or(0.0, |f| f[k])
                } else {
                    c
                };
                self.words.set(super::CENTER_LETTERS[k], value, m.span);
            }
        }
        if let Some(r) = m.radius {
            self.words.set(b'R', r, m.span);
        }
        self.block_turns = m.turns.filter(|&t| t > 0);
        if let Some(v) = m.tool_vector {
            if m.center.iter().any(Option::is_some) {
                return Err(self.alarm(
                    Condition::ImproperGCode,
                    Some(m.span),
                    "a circle and a tool vector in one block".into(),
                ));
            }
            for (k, letter) in [b'I', b'J', b'K'].into_iter().enumerate() {
                self.words.set(letter, v[k], m.span);
            }
        }
        let saved_distance = self.state.modal.distance;
        if mixed {
            self.state.modal.distance = Distance::Incremental;
        }
        let result = self.execute_loaded(base, out);
        self.state.modal.distance = saved_distance;
        result
    }

    /// The increment that takes axis `i` from `from` to `value` read in
    /// `mode`.
    fn increment(&self, i: usize, from: f64, value: f64, mode: TargetMode) -> f64 {
        let rotary = i >= self.machine.linear.len();
        match mode {
            TargetMode::Incremental => value,
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
            let delta = match t.mode {
                TargetMode::Modal if self.state.modal.distance == Distance::Incremental => t.value,
                TargetMode::Modal | TargetMode::Absolute => {
                    if self.is_rollover(i) {
                        shortest_turn(current[i], normalize_360(t.value))
                    } else {
                        t.value - current[i]
                    }
                }
                mode => self.increment(i, current[i], t.value, mode),
            };
            end[i] = current[i] + delta;
            if self.is_rollover(i) {
                end[i] = normalize_360(end[i]);
            }
            travel[i] = delta;
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
        higher: bool,
        span: Span,
        base: usize,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let flow = self.m_codes_and_values()?;
        let _ = higher;
        self.tool_axis_control(span, false, out)?;
        self.finish_block(base, out)?;
        Ok(flow)
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
        self.words.check_all_used()?;
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
