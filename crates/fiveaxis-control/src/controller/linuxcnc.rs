//! G10 as LinuxCNC writes it (`control = "linuxcnc"`; g-code.adoc, G10
//! L1, L10, L11, L2, L20):
//!
//! * `G10 L2 P- X Y Z`: work offset P (1–6 = G54–G59, 0 = the system in
//!   use) set to the values, absolute whatever G90/G91;
//! * `G10 L20 P- X Y Z`: work offset P set so that the current position
//!   reads the values;
//! * `G10 L1 P- Z R`: tool P's length and radius set to the values;
//! * `G10 L10 P- Z R`: tool P's length set so that, with it reloaded, the
//!   current Z reads the value (in the work system and G92 shift in use);
//! * `G10 L11 P- Z R`: as L10 with the machine coordinates (LinuxCNC:
//!   G59.3's, which the kernel does not have: machine coordinates here).
//!
//! The kernel's offset memory holds X, Y, Z work offsets and a tool length
//! and radius (other axis words are alarms); G59.1–G59.3 (P7–P9) are
//! kept as G54.1 P1–P3.

use fiveaxis_gcode::Span;
use fiveaxis_machine::{Joints, MAX_TOOL_OFFSET, SetupError, Vec3};
use nalgebra::Rotation3;

use super::Controller;
use crate::alarm::{Alarm, Condition};
use crate::modal::{LengthMode, WorkSelect};

/// LinuxCNC's coordinate systems (G54 … G59.3).
const NGC_WORK_SYSTEMS: u32 = 9;
/// G54 … G59, the standard work offsets of the kernel's offset memory.
const KERNEL_WORK_SYSTEMS: u32 = 6;
/// G59.1 … G59.3, kept as G54.1 P1 … P3.
const NGC_EXTRA_SYSTEMS: u32 = 3;

/// LinuxCNC's motion modes of group 1 beyond G0–G3.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum NgcMotion {
    /// G5 (`controller/splines.rs`).
    CubicSpline,
    /// G5.1.
    QuadraticSpline,
    /// G33 (`controller/threading.rs`).
    Thread,
    /// G33.1.
    RigidTap,
    /// G76.
    ThreadingCycle,
}

impl NgcMotion {
    /// The mode a group-1 code selects (`None` for G0–G3).
    pub(super) fn of(code: fiveaxis_gcode::Code) -> Option<Self> {
        Some(match (code.major, code.minor) {
            (5, 0) => Self::CubicSpline,
            (5, 1) => Self::QuadraticSpline,
            (33, 0) => Self::Thread,
            (33, 1) => Self::RigidTap,
            (76, 0) => Self::ThreadingCycle,
            _ => return None,
        })
    }
}

/// The rotation of LinuxCNC's XY plane about Z by `degrees`
/// (counter-clockwise seen from +Z).
fn rotation_z(degrees: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Vec3::z_axis(), degrees.to_radians())
}

impl Controller<'_> {
    /// LinuxCNC's rotation of the coordinate system in use (`G10 L2 R`,
    /// #5230…) as the controller's workpiece transform: the program's X Y
    /// and its G92 / G52 shift turn together about the system's origin
    /// (coordinates.adoc: "the G92 offset is applied after rotation", G52
    /// "after the workpiece offset, including rotation"; rs274 reckons a
    /// G92 under rotation in the turned coordinates), so
    /// `real = origin + Rz·(p + shift)`. The controller's chain adds the
    /// shift unturned with the work offset and then the transform about
    /// the work zero, hence the transform's origin `(Rz − I)·shift`.
    /// LinuxCNC has no G54.4, whose transform this is on other controls.
    pub(super) fn refresh_xy_rotation(&mut self) {
        let Some(k) = self.linuxcnc_system() else {
            return;
        };
        let degrees = self.state.xy_rotation[k];
        self.state.setup = if degrees == 0.0 {
            SetupError::IDENTITY
        } else {
            let turn = rotation_z(degrees);
            SetupError {
                origin: turn * self.state.shift - self.state.shift,
                rotation: turn,
            }
        };
    }

    /// A block in one of LinuxCNC's own motion modes.
    pub(super) fn ngc_motion(
        &mut self,
        mode: NgcMotion,
        from: &Joints,
        out: &mut Vec<crate::segment::Segment>,
    ) -> Result<(), Alarm> {
        // A block of the mode without axis words moves nothing (rs274: a
        // lone `G17` after G76 is no threading cycle, `M2` after G5.1 no
        // spline).
        let count = self.machine.axis_count();
        if !self.axis_letters[..count]
            .iter()
            .any(|&l| self.words.has(l))
        {
            if matches!(mode, NgcMotion::Thread | NgcMotion::RigidTap) && self.words.has(b'K') {
                return Err(self.alarm(
                    Condition::CycleDataMissing,
                    None,
                    "G33 / G33.1 need an axis word".into(),
                ));
            }
            return Ok(());
        }
        match mode {
            NgcMotion::CubicSpline | NgcMotion::QuadraticSpline => {
                self.spline(mode == NgcMotion::CubicSpline, from, out)
            }
            NgcMotion::Thread | NgcMotion::RigidTap | NgcMotion::ThreadingCycle => {
                self.sync_motion(mode, from, out)
            }
        }
    }

    /// LinuxCNC: the rotation (degrees) of coordinate system `system`
    /// (1–9), as parameters #5230, #5250 … read it.
    pub fn xy_rotation(&self, system: usize) -> Option<f64> {
        (1..=9)
            .contains(&system)
            .then(|| self.state.xy_rotation[system - 1])
    }

    /// LinuxCNC: writing #5230, #5250 … sets the rotation of coordinate
    /// system `system` (1–9), as `G10 L2 P… R` does.
    pub fn set_xy_rotation(&mut self, system: usize, degrees: f64) {
        if (1..=9).contains(&system) {
            self.state.xy_rotation[system - 1] = degrees;
            self.refresh_xy_rotation();
        }
    }

    /// G10 by LinuxCNC's rules; `from` is where the program stands.
    pub(super) fn data_setting_linuxcnc(&mut self, span: Span, from: &Joints) -> Result<(), Alarm> {
        let Some(l) = self.words.take(b'L') else {
            return Err(self.alarm(Condition::IllegalG10L, Some(span), "G10 needs L".into()));
        };
        let l_value = self.words.integer(&l, 99)?;
        let Some(p) = self.words.take(b'P') else {
            return Err(self.alarm(Condition::IllegalG10P, Some(span), "G10 needs P".into()));
        };
        match l_value {
            2 | 20 => {
                let n = self.words.integer(&p, NGC_WORK_SYSTEMS)?;
                let n = match (n, self.state.modal.work) {
                    (0, WorkSelect::Standard(i)) => u32::from(i) + 1,
                    (0, WorkSelect::Extended(k)) if u32::from(k) <= NGC_EXTRA_SYSTEMS => {
                        KERNEL_WORK_SYSTEMS + u32::from(k)
                    }
                    (0, WorkSelect::Extended(k)) => {
                        return Err(self.alarm(
                            Condition::IllegalG10P,
                            Some(p.span),
                            format!(
                                "G10 P0: the system in use is G54.1 P{k}, not one of LinuxCNC's"
                            ),
                        ));
                    }
                    (n, _) => n,
                };
                let rotation = self.words.take(b'R');
                if let Some(r) = &rotation
                    && l_value == 20
                {
                    // rs274: "R not allowed in G10 L20".
                    return Err(self.alarm(
                        Condition::WordNotUsed,
                        Some(r.span),
                        "G10 L20 takes no R: the rotation is set by G10 L2".into(),
                    ));
                }
                let slot = n as usize - 1;
                let mut value = if slot < KERNEL_WORK_SYSTEMS as usize {
                    self.offsets.work[slot]
                } else {
                    self.offsets.extended_work[slot - KERNEL_WORK_SYSTEMS as usize]
                };
                // Where the program stands, and the point as system P is to
                // read it: the words' values, the current position on the
                // axes not named.
                let here = Vec3::new(from[0], from[1], from[2]);
                let mut named = [false; 3];
                let mut q = here;
                for (axis, letter) in [b'X', b'Y', b'Z'].into_iter().enumerate() {
                    if let Some(word) = self.words.take(letter) {
                        named[axis] = true;
                        q[axis] = self.length(&word);
                    }
                }
                // L2: the values are the origin. L20: the origin is where
                // the tool stands less P's turned G92 shift and q
                // (coordinates.adoc: G92 applies inside the rotation). An
                // axis not named keeps its offset.
                let origin = if l_value == 20 {
                    let turn = rotation_z(self.state.xy_rotation[slot]);
                    self.to_real(&here) - self.offsets.external - turn * (q + self.state.shift)
                } else {
                    q
                };
                for axis in (0..3).filter(|&a| named[a]) {
                    value[axis] = origin[axis];
                }
                // The axes beyond X, Y, Z (A, B, C…): their offsets are kept
                // per system beside the offset memory (LinuxCNC's G5x
                // offsets hold every axis).
                let active = self.linuxcnc_system().unwrap_or(slot);
                for (i, here) in from
                    .iter()
                    .enumerate()
                    .take(self.machine.axis_count())
                    .skip(3)
                {
                    let Some(word) = self.words.take(self.axis_letters[i]) else {
                        continue;
                    };
                    let v = self.axis_value(i, &word);
                    let now = self.state.rotary_work[active][i];
                    self.state.rotary_work[slot][i] = if l_value == 2 { v } else { now + here - v };
                }
                if let Some(r) = rotation {
                    self.state.xy_rotation[slot] = self.angle(&r);
                }
                if slot < KERNEL_WORK_SYSTEMS as usize {
                    self.offsets.work[slot] = value;
                } else {
                    self.offsets.extended_work[slot - KERNEL_WORK_SYSTEMS as usize] = value;
                }
                self.refresh_xy_rotation();
                Ok(())
            }
            1 | 10 | 11 => {
                let n = self.words.integer(&p, MAX_TOOL_OFFSET)?;
                let applied = match self.state.modal.length {
                    LengthMode::Plus => {
                        let t = self.offsets.tool(self.state.h);
                        t.length + t.length_wear
                    }
                    _ => 0.0,
                };
                let z = self.machine.axis_index('Z');
                let length = match self.words.take(b'Z') {
                    Some(word) => {
                        let v = self.length(&word);
                        Some(match (l_value, z) {
                            (1, _) => v,
                            (10, Some(i)) => from[i] + applied - v,
                            (_, Some(i)) => self.state.joints[i] - v,
                            (_, None) => v,
                        })
                    }
                    None => None,
                };
                let radius = self.words.take(b'R').map(|word| self.length(&word));
                let tool = self.offsets.tools.entry(n).or_default();
                if let Some(length) = length {
                    tool.length = length;
                    tool.length_wear = 0.0;
                }
                if let Some(radius) = radius {
                    tool.radius = radius;
                    tool.radius_wear = 0.0;
                }
                Ok(())
            }
            _ => Err(self.alarm(
                Condition::IllegalG10L,
                Some(l.span),
                format!("G10 L{l_value}: LinuxCNC's forms are L1, L10, L11, L2 and L20"),
            )),
        }
    }
}
