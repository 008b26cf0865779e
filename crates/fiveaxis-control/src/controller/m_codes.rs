//! M codes: the control's standard set and the machine builder's table
//! (`[m_codes]` of the machine file), which replaces the standard meaning
//! of every number it declares.
//!
//! M codes act before the motion of their block: `M11 G00 A30.` moves A,
//! `M10 G00 A30.` stops with the clamp alarm.

use fiveaxis_gcode::{Code, Span};
use fiveaxis_machine::{Control, MFunction};

use super::{Controller, Flow, at_line};
use crate::alarm::{Alarm, Condition};
use crate::fanuc::{GCodes, LengthCode};
use crate::modal::TcpcType;
use crate::segment::{Path, Segment};

/// Why the last block would stop a real control (the run goes on).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProgramStop {
    /// A program stop (M00, or a code declared `"stop"`).
    Stop,
    /// An optional stop (M01) with the optional-stop switch on.
    OptionalStop,
}

/// A clamped rotary axis: the M code that clamped it and its line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Clamp {
    pub(super) code: u16,
    pub(super) line: u32,
}

/// How far a clamped axis may be found to move (rounding), degrees.
const CLAMP_TOLERANCE: f64 = 1e-9;

/// The control's standard meaning of an M code (FANUC machining centres:
/// the usual M00–M09, M19, M30).
pub(super) fn standard(code: Code) -> Option<MFunction> {
    if code.minor != 0 {
        return None;
    }
    Some(match code.major {
        0 => MFunction::Stop,
        1 => MFunction::OptionalStop,
        2 | 30 => MFunction::End,
        3 => MFunction::SpindleCw,
        4 => MFunction::SpindleCcw,
        5 => MFunction::SpindleStop,
        6 => MFunction::ToolChange,
        7 | 8 => MFunction::CoolantOn,
        9 => MFunction::CoolantOff,
        19 => MFunction::SpindleOrient,
        _ => return None,
    })
}

/// LinuxCNC's standard M codes beyond FANUC's (m-code.adoc): M60 pallet
/// change stop, M48–M53 override switches, M61 set the current tool, M62–
/// M68 digital and analog I/O, M70–M73 modal state save and restore, and
/// the user codes M100–M199 (an external program: no motion). The kernel
/// moves nothing for any of them.
fn standard_linuxcnc(code: Code) -> Option<MFunction> {
    if code.minor != 0 {
        return None;
    }
    match code.major {
        60 => Some(MFunction::Stop),
        48..=53 | 61..=68 | 70..=73 | 100..=199 => Some(MFunction::Signal),
        _ => standard(code),
    }
}

/// The highest tool number M61 takes (the offset memory's).
const MAX_TOOL_NUMBER: u32 = fiveaxis_machine::MAX_TOOL_OFFSET;

impl Controller<'_> {
    /// The function of an M code on this machine: its `[m_codes]` entry,
    /// else the control's standard meaning.
    fn m_function(&self, code: Code) -> Option<MFunction> {
        let declared = if code.minor == 0 {
            self.machine.m_codes.get(code.major)
        } else {
            None
        };
        declared.or_else(|| {
            if self.dialect.haas_codes {
                super::haas::standard_m_code(self.machine, code)
            } else if self.dialect.rs274ngc {
                standard_linuxcnc(code)
            } else {
                standard(code)
            }
        })
    }

    /// TCPC switched by M code: the block's group 08 becomes G43.4
    /// (`tcpc_on`, with the block's H or the H in force) or G49
    /// (`tcpc_off`). Runs before the G codes are applied.
    ///
    /// On a LinuxCNC machine the M code switches the kinematics
    /// (`motion/switchkins.adoc`) and G43 / G49 keep their own meaning in
    /// either: G43 H… under the TCP kinematics changes the tool length the
    /// kinematics take (`motion.tooloffset.z`), G49 makes it 0, and
    /// switching back to identity kinematics leaves G43's length offset in
    /// force. See [`Controller::linuxcnc_kinematics`].
    pub(super) fn m_code_length(&mut self, codes: &mut GCodes) -> Result<(), Alarm> {
        if self.machine.control == Control::LinuxCnc {
            return self.linuxcnc_kinematics(codes);
        }
        for &(code, span) in self.op_m_codes() {
            let g = match self.m_function(code) {
                Some(MFunction::TcpcOn) => (LengthCode::Tcpc(TcpcType::Angles), Code::new(43, 4)),
                Some(MFunction::TcpcOff) => (LengthCode::Off, Code::new(49, 0)),
                _ => continue,
            };
            if let Some((_, _, other)) = codes.length {
                return Err(self.alarm(
                    Condition::GCodeConflict,
                    Some(span),
                    format!(
                        "M{code} switches tool centre point control and cannot be in a block with G{other}"
                    ),
                ));
            }
            codes.length = Some((g.0, span, g.1));
        }
        Ok(())
    }

    /// LinuxCNC's kinematics switch and tool length, as the group 08 of
    /// the block: under the TCP kinematics G43.4 with the H of G43 (H0,
    /// length 0, while G49 is in force); under identity kinematics G43 or
    /// G49 as programmed.
    fn linuxcnc_kinematics(&mut self, codes: &mut GCodes) -> Result<(), Alarm> {
        let mut switch = None;
        if self.state.kinematics_pending {
            // `tcpc_at_start`: the TCP kinematics from the first block.
            self.state.kinematics_pending = false;
            switch = Some((true, Span::default(), None));
        }
        for &(code, span) in self.op_m_codes() {
            let on = match self.m_function(code) {
                Some(MFunction::TcpcOn) => true,
                Some(MFunction::TcpcOff) => false,
                _ => continue,
            };
            if let Some((_, _, Some(first))) = switch
                && first != code
            {
                return Err(self.alarm(
                    Condition::GCodeConflict,
                    Some(span),
                    format!("M{first} and M{code} both switch the kinematics"),
                ));
            }
            switch = Some((on, span, Some(code)));
        }
        let given = match codes.length {
            None => None,
            Some((LengthCode::Plus, span, _)) => Some((true, span)),
            Some((LengthCode::Off, span, _)) => Some((false, span)),
            // Other group 08 codes (G43.1, G44…) act as programmed outside
            // the TCP kinematics.
            Some((_, span, code)) => {
                if self.state.kinematics_tcp || switch.is_some_and(|(on, _, _)| on) {
                    return Err(self.alarm(
                        Condition::GCodeConflict,
                        Some(span),
                        format!("G{code} cannot be given under the TCP kinematics (M428): only G43 and G49"),
                    ));
                }
                return Ok(());
            }
        };
        if switch.is_none() && given.is_none() {
            return Ok(());
        }
        let tcp = switch.map_or(self.state.kinematics_tcp, |(on, _, _)| on);
        let length_on = given.map_or(self.state.length_on, |(on, _)| on);
        let span = given
            .map(|(_, span)| span)
            .or(switch.map(|(_, span, _)| span))
            .unwrap_or_default();
        self.state.kinematics_tcp = tcp;
        self.state.length_on = length_on;
        codes.length_in_place = true;
        codes.length_synthesized = given.is_none();
        let (what, name) = match (tcp, length_on) {
            (true, _) => (LengthCode::Tcpc(TcpcType::Angles), Code::new(43, 4)),
            (false, true) => (LengthCode::Plus, Code::new(43, 0)),
            (false, false) => (LengthCode::Off, Code::new(49, 0)),
        };
        codes.length = Some((what, span, name));
        if tcp && !length_on && !self.fanuc.has_length_offset() {
            // The TCP kinematics with no tool length: H0. The H number of
            // the last G43 comes back with the next G43 without H.
            self.state.h_before_g49 = Some(self.state.h);
            self.state.h = 0;
        } else if given.is_some_and(|(on, _)| on) && !self.fanuc.has_length_offset() {
            // G43 without H: the tool in the spindle (g-code.adoc, G43),
            // under the TCP kinematics as under identity; taken when the
            // length is applied, after the block's M6.
            self.state.h_before_g49 = None;
            codes.length_from_spindle = true;
        } else if length_on
            && !self.fanuc.has_length_offset()
            && let Some(h) = self.state.h_before_g49.take()
        {
            self.state.h = h;
            self.note_length_tool();
        }
        Ok(())
    }

    pub(super) fn m_codes(&mut self) -> Result<Flow, Alarm> {
        let mut flow = Flow::Next;
        if let Some(&(_, span)) = self.op_m_codes().get(self.dialect.max_m_codes) {
            return Err(self.alarm(
                Condition::GCodeConflict,
                Some(span),
                format!(
                    "more than {} M codes in one block",
                    self.dialect.max_m_codes
                ),
            ));
        }
        for i in 0..self.op_m_codes().len() {
            let (code, span) = self.op_m_codes()[i];
            self.state.last_m = Some(f64::from(code.major) + f64::from(code.minor) / 10.0);
            match (code.major, code.minor) {
                (98, 0) => flow = self.call()?,
                (97, 0) if self.dialect.haas_codes => flow = self.local_call(span)?,
                (99, 0) => {
                    let sequence = self.fanuc.return_sequence()?;
                    flow = Flow::Return { sequence };
                }
                _ => match self.m_function(code) {
                    Some(function) => {
                        if self.m_function_run(function, code, span)? {
                            flow = Flow::End;
                        }
                    }
                    None => {
                        return Err(self.alarm(
                            Condition::UnsupportedMCode,
                            Some(span),
                            format!(
                                "M{code} is not a function of this kernel or machine: if the machine builder gives it one, declare it in the machine file's [m_codes] table, e.g. {code} = \"signal\""
                            ),
                        ));
                    }
                },
            }
        }
        Ok(flow)
    }

    /// Carries out one M function; true when it ends the program.
    fn m_function_run(
        &mut self,
        function: MFunction,
        code: Code,
        span: Span,
    ) -> Result<bool, Alarm> {
        match function {
            MFunction::End => return Ok(true),
            MFunction::Stop => self.stop = Some(ProgramStop::Stop),
            MFunction::OptionalStop => {
                if self.optional_stop {
                    self.stop = Some(ProgramStop::OptionalStop);
                }
            }
            MFunction::SpindleCw | MFunction::SpindleCcw => self.state.spindle_on = true,
            // Orientation stops the spindle at an angle; a tool change
            // leaves it stopped (the program turns it on again).
            MFunction::SpindleStop => self.state.spindle_on = false,
            MFunction::SpindleOrient => {
                self.state.spindle_on = false;
                if self.dialect.rs274ngc {
                    self.linuxcnc_orient()?;
                }
            }
            MFunction::ToolChange => {
                self.state.spindle_on = false;
                self.state.spindle_tool = self.state.tool;
            }
            MFunction::CoolantOn => self.state.coolant = true,
            MFunction::CoolantOff => self.state.coolant = false,
            MFunction::RigidTap => self.state.rigid_tap = true,
            MFunction::Signal
                if self.dialect.rs274ngc && matches!(code.major, 50..=53 | 61..=68 | 100..=199) =>
            {
                if code.major == 61 {
                    // M61 Q-: the tool in the spindle is now Q (no change).
                    self.state.spindle_tool = self.fanuc.spindle_tool(span, MAX_TOOL_NUMBER)?;
                }
                // Their P, E, L, Q words are I/O numbers and values.
                self.fanuc.io_words();
            }
            MFunction::Signal | MFunction::TcpcOn | MFunction::TcpcOff => {}
            MFunction::Clamp(axis) | MFunction::Unclamp(axis) => {
                let Some(k) = self.machine.rotary.iter().position(|r| r.name == axis) else {
                    // The machine file checks the axis; a machine built in
                    // code may not have.
                    return Err(self.alarm(
                        Condition::UnsupportedMCode,
                        Some(span),
                        format!("M{code} clamps axis {axis}, which this machine does not have"),
                    ));
                };
                self.state.clamped[k] = matches!(function, MFunction::Clamp(_)).then_some(Clamp {
                    code: code.major,
                    line: self.fanuc.line,
                });
            }
        }
        Ok(false)
    }

    /// LinuxCNC `M19 R- Q- P-` (m-code.adoc, M19): the angle R (0–360,
    /// from 0 when left out), the time Q allowed for it, the direction P
    /// (0 shortest, 1 clockwise, 2 counter-clockwise). The spindle stops
    /// at the angle; no axis moves.
    fn linuxcnc_orient(&mut self) -> Result<(), Alarm> {
        self.fanuc.spindle_orientation()
    }

    /// Alarms when a segment moves a clamped rotary axis.
    pub(super) fn check_clamps(&self, segments: &[Segment]) -> Result<(), Alarm> {
        for (k, clamp) in self.state.clamped.iter().enumerate() {
            let Some(clamp) = clamp else { continue };
            let i = self.machine.rotary_index(k);
            for seg in segments {
                let moved = |a: f64| (a - seg.start[i]).abs() > CLAMP_TOLERANCE;
                let via = match &seg.path {
                    Path::Via(mid) => moved(mid[i]),
                    _ => false,
                };
                if !(moved(seg.end[i]) || via) {
                    continue;
                }
                let axis = self.machine.rotary[k].name;
                let unclamp = self
                    .machine
                    .m_codes
                    .number_of(MFunction::Unclamp(axis))
                    .or_else(|| {
                        (0..100).find(|&n| {
                            self.m_function(Code::new(n, 0)) == Some(MFunction::Unclamp(axis))
                        })
                    })
                    .map_or(String::new(), |n| format!(" (M{n})"));
                let span = self.op_axis_span(i);
                let alarm = self.alarm(
                    Condition::ClampedAxisMoved,
                    span,
                    format!(
                        "axis {axis} is clamped (M{} at line {}) and cannot move: unclamp it first{unclamp}",
                        clamp.code, clamp.line
                    ),
                );
                return Err(at_line(alarm, seg.line));
            }
        }
        Ok(())
    }
}
