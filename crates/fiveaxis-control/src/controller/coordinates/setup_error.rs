//! Workpiece setup error correction, G54.4 (Mazak, seed 002; FANUC 30i
//! "workpiece setting error compensation").
//!
//! `G54.4 Pn` selects data set n of the offsets file (1 to 7), `G54.4 P0`
//! cancels. From then on programmed points map onto the real workpiece as
//! `p ↦ Δ + R·p` and tool vectors as `v ↦ R·v` before the work offset
//! (`SetupError`); rows still report the tip and tool in the frame of the
//! programmed (ideal) workpiece. FANUC adds the common set 00 to the
//! selected one. Under TCPC the G54.4 block turns the tool to keep its
//! programmed attitude on the real workpiece, taking of the two rotary
//! pairs the one with the smaller table-axis motion; later blocks follow
//! the machine's `setup_error_choice` (Mazak F162 bit 1).

use fiveaxis_gcode::Span;
use fiveaxis_machine::{Control, Joints, SetupError, SetupErrorSet, Vec3};

use crate::alarm::{Alarm, Condition};
use crate::controller::Controller;
use crate::controller::tcpc::Choice;
use crate::modal::{MotionMode, TcpcType};
use crate::segment::{Motion, Path, Segment, TcpcPath, TipPath};

/// Highest data set number.
const MAX_SET: u32 = 7;

impl Controller<'_> {
    /// The G54.4 block: alone in its block, P selects or cancels.
    pub(in crate::controller) fn select_setup_error(
        &mut self,
        span: Span,
        from: &Joints,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let (n, p_span) = self.fanuc.setup_error_set(span, MAX_SET)?;
        self.fanuc.take_setup_error_set();
        if n != 0 && self.machine.rotary.len() > 2 {
            // The correction turns the tool back onto its attitude on the
            // real workpiece, an inverse that needs two rotary axes.
            return Err(self.alarm(
                Condition::TcpcWithoutRotaryAxis,
                Some(p_span),
                format!(
                    "G54.4 P{n}: workpiece setup error correction needs a machine with at most two \
                     rotary axes (this one has {})",
                    self.machine.rotary.len()
                ),
            ));
        }
        let error = self.setup_error_of(n, p_span)?;
        let before = self.state.setup;
        // Type 1 keeps its programmed angles apart from the machine's while
        // a correction is in force.
        let programmed_angles = self.state.setup_angles.or_else(|| {
            (self.machine.rotary.len() == 2).then(|| {
                let (i0, i1) = (self.machine.rotary_index(0), self.machine.rotary_index(1));
                [self.state.joints[i0], self.state.joints[i1]]
            })
        });
        self.state.setup = error;
        self.state.setup_set = n;
        self.state.setup_angles = if n != 0 && self.tcpc_type() == Some(TcpcType::Angles) {
            programmed_angles
        } else {
            None
        };
        if let Some(kind) = self.tcpc_type() {
            self.setup_attitude_move(kind, &before, programmed_angles, from, out)?;
        }
        Ok(())
    }

    /// The correction of data set `n`, turned back to table position 0, with
    /// FANUC's common set 00 added.
    fn setup_error_of(&self, n: u32, span: Span) -> Result<SetupError, Alarm> {
        if n == 0 {
            return Ok(SetupError::IDENTITY);
        }
        let convert = |set: &SetupErrorSet| {
            SetupError::from_set(set, self.machine).map_err(|axis| {
                self.alarm(
                    Condition::SetupErrorAxis,
                    Some(span),
                    format!("setup error data set names axis {axis}, which is not a table axis of this machine"),
                )
            })
        };
        let selected = convert(
            &self
                .offsets
                .setup_error
                .get(&n)
                .cloned()
                .unwrap_or_default(),
        )?;
        let fanuc = matches!(self.machine.control, Control::Fanuc30i | Control::Fanuc16);
        match self.offsets.setup_error.get(&0) {
            Some(common) if fanuc => Ok(convert(common)?.after(&selected)),
            _ => Ok(selected),
        }
    }

    /// Under TCPC the G54.4 block turns the tool so that it keeps its
    /// programmed attitude on the real workpiece, the tip on the programmed
    /// point: of the two rotary pairs, the one with the smaller table-axis
    /// motion.
    fn setup_attitude_move(
        &mut self,
        kind: TcpcType,
        before: &SetupError,
        programmed_angles: Option<[f64; 2]>,
        from: &Joints,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let machine = self.machine;
        if machine.rotary.len() != 2 {
            return Ok(());
        }
        let start = self.state.joints;
        let (i0, i1) = (machine.rotary_index(0), machine.rotary_index(1));
        // The attitude on the ideal workpiece, table frame.
        let ideal = match kind {
            TcpcType::Vector => self.tcpc_vector_table(),
            TcpcType::Angles => match programmed_angles {
                Some([a, b]) => {
                    let mut ideal = start;
                    ideal[i0] = a;
                    ideal[i1] = b;
                    machine.forward(&ideal, 0.0).dir
                }
                None => before.inverse_vector(&machine.forward(&start, 0.0).dir),
            },
        };
        let real = self.state.setup.vector(&ideal);
        let angles = self.choose_rotaries_by(&real, [start[i0], start[i1]], Choice::TableMotion)?;
        let mut end = start;
        end[i0] = angles[0];
        end[i1] = angles[1];
        self.state.setup_tilt_sign = self.tilt_side(&end);
        let point = Vec3::new(from[0], from[1], from[2]);
        let gauge = self.tcpc_gauge(&end, &point);
        end[..3].copy_from_slice(gauge.as_slice());
        let length = self.tool_length();
        let tip = TipPath::Line([
            machine.forward(&start, length).tip,
            machine.forward(&end, length).tip,
        ]);
        let motion = if self.state.modal.motion == MotionMode::Rapid {
            Motion::Rapid
        } else {
            Motion::Linear
        };
        let path = Path::Tcpc(TcpcPath {
            tip,
            turning: false,
            posture: None,
        });
        let mut seg = self.segment(motion, start, end, path);
        if motion == Motion::Linear {
            seg.feed = Some(self.cutting_feed(|| tip.length())?);
        }
        if seg.moves() || start != end {
            out.push(seg);
        }
        Ok(())
    }
}
