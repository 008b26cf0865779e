//! Haas's own functions (Haas Next Generation Control mill operator's
//! manual), each mapped onto the kernel function that is the same thing:
//!
//! * `G234 H…` tool centre point control is the kernel's TCPC of type 1
//!   (`tcpc.rs`, G43.4) with Haas's frame: the work coordinate system
//!   (MRZP and work offset) fixed to the table as it stands at rotary
//!   position 0, so that "when the rotary axes rotate, the linear
//!   coordinate system rotates with them". Group 08: `G49`, `G43`, `G44`
//!   end it, as do M02 / M30 (the end of the run). H is the block's or
//!   the one in force; with none the block is an alarm.
//! * `G254` dynamic work offset (DWO, group 23) is a feature frame
//!   (`coordinates/feature_frame.rs`, `Feature::dwo`): the work zero (the
//!   work offset, measured at rotary position 0) follows the table as the
//!   rotary axes stand at G254, the axes stay the machine's, so that a
//!   3+2 program posted for the part at the centre of rotation (tool
//!   along Z, X and Y the machine's) runs on the part where it is: the
//!   tip goes to the turned work zero + (X, Y, Z), the tool length along
//!   the tool; canned cycles drill along the tool. `G255` cancels. The
//!   manual's rules: rotary motion is complete before G254 and G254 is
//!   cancelled before any rotary motion (an axis word of a rotary axis in
//!   DWO is an alarm here); the work offset is applied before G254, and
//!   one selected in DWO (NX's UMC-750 post: `G254`, then `G54 G90 G00 X…
//!   Y…`) is accepted, the DWO frame taking its work zero from the offset
//!   in force at each block (as G234 does); G254 is
//!   not for simultaneous motion (G234 in DWO, and G254 in TCPC, are
//!   alarms).
//! * `G268 X Y Z I J K Q` feature coordinates is the tilted working plane
//!   (`feature_by_rotation_order`), `G269` cancels it, `G253` turns the
//!   rotary axes so that the spindle is normal to it (as G53.1).
//! * `G187 P1`–`P3` `E…` smoothness and corner rounding: speed, not path;
//!   kept in the modal state (`Modal::accuracy`) and reported.
//! * `G154 P1`–`P99` and `G110`–`G129` (P1–P20) select the additional
//!   work offsets, the memory FANUC's `G54.1 P` uses (`G10 L20 P1`–`P99`
//!   sets them, `#14001`+ reads them; Haas's tool variables `#2001`+ and
//!   `G10 L1` are in `system_vars.rs` and `controller.rs`).
//! * `M97 P… L…`: a local subprogram call, to the blocks from sequence
//!   number P of the running program up to their M99, L times
//!   (`Flow::LocalCall`, carried out by the runner as an M98 call).
//! * M codes: Haas's standard set (`standard_m_code`): M10 / M11 clamp /
//!   unclamp the fourth axis brake, M12 / M13 the fifth (the machine's
//!   first and second rotary axes), M88 / M89 through-spindle coolant and
//!   the other switching codes as signals.

use fiveaxis_gcode::{Code, Span};
use fiveaxis_machine::{MFunction, Machine, Side};

use super::coordinates::Feature;
use super::{Controller, Flow};
use crate::alarm::{Alarm, Condition};
use crate::modal::TcpcType;

/// Haas's standard meaning of an M code on `machine`, where it differs
/// from or adds to the common set.
pub(super) fn standard_m_code(machine: &Machine, code: Code) -> Option<MFunction> {
    if code.minor != 0 {
        return None;
    }
    let rotary = |k: usize| machine.rotary.get(k).map(|r| r.name);
    Some(match code.major {
        // M16 is a tool change as M06.
        16 => MFunction::ToolChange,
        // Brakes: the fourth axis on M10 / M11, the fifth on M12 / M13.
        10 => MFunction::Clamp(rotary(0)?),
        11 => MFunction::Unclamp(rotary(0)?),
        12 => MFunction::Clamp(rotary(1)?),
        13 => MFunction::Unclamp(rotary(1)?),
        // Chip conveyor (M31, M33), coolant spigot (M34, M35), air blast
        // (M83, M84), through-tool air blast (M73, M74), through-spindle
        // coolant (M88, M89): no axis moves; the kernel's coolant state is
        // the flood coolant of M08 / M09.
        31 | 33 | 34 | 35 | 73 | 74 | 83 | 84 | 88 | 89 => MFunction::Signal,
        // M00–M09 (M07 shower coolant, M08 flood), M19, M30 as FANUC's.
        _ => return super::m_codes::standard(code),
    })
}

impl Controller<'_> {
    /// G234: TCPC with Haas's frame (module documentation).
    pub(super) fn start_haas_tcpc(&mut self, span: Span) -> Result<(), Alarm> {
        if self.feature().is_some_and(|f| f.is_dwo()) {
            return Err(self.alarm(
                Condition::FeatureNotAllowed,
                Some(span),
                "G234 (TCPC) cannot be given in the dynamic work offset (G254): give G255 first"
                    .into(),
            ));
        }
        let h = self.fanuc.peek_length_offset()?.unwrap_or(self.state.h);
        if h == 0 {
            return Err(self.alarm(
                Condition::NoDataAfterAddress,
                Some(span),
                "G234 needs a tool length offset: give H (the block's or one in force)".into(),
            ));
        }
        self.start_tcpc_as(TcpcType::Angles, "G234", true, span)?;
        Ok(())
    }

    /// G254 (on) / G255 (off), before the block's move.
    pub(super) fn dwo_command(&mut self, on: bool, span: Span) -> Result<(), Alarm> {
        if !on {
            if self.feature().is_some_and(|f| f.is_dwo()) {
                self.state.feature = None;
            }
            return Ok(());
        }
        if self.tcpc_type().is_some() {
            return Err(self.alarm(
                Condition::FeatureNotAllowed,
                Some(span),
                "G254 (dynamic work offset) is for positioning, not for simultaneous motion: cancel TCPC (G234) with G49 first".into(),
            ));
        }
        if self.feature().is_some_and(|f| !f.is_dwo()) {
            return Err(self.alarm(
                Condition::FeatureNotAllowed,
                Some(span),
                "G254 cannot be given in the feature coordinate system (G268 / G68.2) in this kernel: cancel it with G269 first".into(),
            ));
        }
        self.feature_allowed(span, "G254")?;
        let turn = self.machine.chain(Side::Table, &self.state.joints).rotation;
        self.state.feature = Some(Feature::dwo(turn));
        Ok(())
    }

    /// In DWO no rotary axis may move (the manual: cancel G254 before any
    /// rotary motion).
    pub(super) fn dwo_rotary_words(&self) -> Result<(), Alarm> {
        if !self.feature().is_some_and(|f| f.is_dwo()) {
            return Ok(());
        }
        let rules = self.rules();
        for (k, r) in self.machine.rotary.iter().enumerate() {
            if let Some(span) = self.fanuc.axis_span(&rules, self.machine.rotary_index(k)) {
                return Err(self.alarm(
                    Condition::FeatureNotAllowed,
                    Some(span),
                    format!(
                        "axis {} cannot move in the dynamic work offset (G254): give G255 before any rotary motion",
                        r.name
                    ),
                ));
            }
        }
        Ok(())
    }

    /// G187 P1–P3 E: smoothness and corner rounding (speed, not path).
    /// Without P the level is the control's setting again (0), without E
    /// the corner rounding.
    pub(super) fn smoothness(&mut self, span: Option<Span>) -> Result<(), Alarm> {
        if span.is_none() {
            return Ok(());
        }
        let rules = self.rules();
        let (level, rounding) = self.fanuc.smoothness(&rules)?;
        let accuracy = &mut self.state.modal.accuracy;
        accuracy.smoothness = level;
        accuracy.corner_rounding = rounding;
        Ok(())
    }

    /// M97 P… L…: a local subprogram call to sequence number P of the
    /// running program, L times (1 when left out).
    pub(super) fn local_call(&mut self, span: Span) -> Result<Flow, Alarm> {
        let (sequence, repeats) = self.fanuc.local_call(span)?;
        Ok(Flow::LocalCall { sequence, repeats })
    }
}
