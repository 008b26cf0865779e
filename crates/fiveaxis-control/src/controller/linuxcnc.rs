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

use fiveaxis_machine::{Joints, MAX_AXES, SetupError, Vec3};
use nalgebra::Rotation3;

use super::Controller;
use crate::alarm::{Alarm, Condition};
use crate::command::ToolLength;
use crate::fanuc::KERNEL_WORK_SYSTEMS;
use crate::modal::LengthMode;

/// LinuxCNC's motion modes of group 1 beyond G0–G3.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum NgcMotion {
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

impl NgcMotion {}

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
        if self.fanuc.first_axis(&self.rules(), 0).is_none() {
            if matches!(mode, NgcMotion::Thread | NgcMotion::RigidTap) && self.fanuc.has_pitch() {
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

    /// LinuxCNC's G10 L2 / L20: coordinate system `slot`'s origin on the
    /// named axes (`at_position`: put so that the current position reads
    /// the values) and its rotation; `from` is where the program stands.
    pub(super) fn set_coordinate_system_data(
        &mut self,
        slot: usize,
        values: &[Option<f64>; MAX_AXES],
        rotation: Option<f64>,
        at_position: bool,
        from: &Joints,
    ) {
        let kernel = KERNEL_WORK_SYSTEMS as usize;
        let mut value = if slot < kernel {
            self.offsets.work[slot]
        } else {
            self.offsets.extended_work[slot - kernel]
        };
        // Where the program stands, and the point as system P is to read
        // it: the values, the current position on the axes not named.
        let here = Vec3::new(from[0], from[1], from[2]);
        let mut q = here;
        for axis in 0..3 {
            if let Some(v) = values[axis] {
                q[axis] = v;
            }
        }
        // L2: the values are the origin. L20: the origin is where the
        // tool stands less P's turned G92 shift and q (coordinates.adoc:
        // G92 applies inside the rotation). An axis not named keeps its
        // offset.
        let origin = if at_position {
            let turn = rotation_z(self.state.xy_rotation[slot]);
            self.to_real(&here) - self.offsets.external - turn * (q + self.state.shift)
        } else {
            q
        };
        for axis in (0..3).filter(|&a| values[a].is_some()) {
            value[axis] = origin[axis];
        }
        // The axes beyond X, Y, Z (A, B, C…): their offsets are kept per
        // system beside the offset memory (LinuxCNC's G5x offsets hold
        // every axis).
        let active = self.linuxcnc_system().unwrap_or(slot);
        for (i, here) in from
            .iter()
            .enumerate()
            .take(self.machine.axis_count())
            .skip(3)
        {
            let Some(v) = values[i] else { continue };
            let now = self.state.rotary_work[active][i];
            self.state.rotary_work[slot][i] = if at_position { now + here - v } else { v };
        }
        if let Some(r) = rotation {
            self.state.xy_rotation[slot] = r;
        }
        if slot < kernel {
            self.offsets.work[slot] = value;
        } else {
            self.offsets.extended_work[slot - kernel] = value;
        }
        self.refresh_xy_rotation();
    }

    /// LinuxCNC's G10 L1 / L10 / L11: tool `number`'s length and radius,
    /// their wear cleared; `from` is where the program stands.
    pub(super) fn set_tool_table(
        &mut self,
        number: u32,
        length: Option<ToolLength>,
        radius: Option<f64>,
        from: &Joints,
    ) {
        let applied = match self.state.modal.length {
            LengthMode::Plus => {
                let t = self.offsets.tool(self.state.h);
                t.length + t.length_wear
            }
            _ => 0.0,
        };
        let z = self.machine.axis_index('Z');
        let length = length.map(|l| match (l, z) {
            (ToolLength::Value(v), _) => v,
            (ToolLength::Reads(v), Some(i)) => from[i] + applied - v,
            (ToolLength::ReadsMachine(v), Some(i)) => self.state.joints[i] - v,
            (ToolLength::Reads(v) | ToolLength::ReadsMachine(v), None) => v,
        });
        let tool = self.offsets.tools.entry(number).or_default();
        if let Some(length) = length {
            tool.length = length;
            tool.length_wear = 0.0;
        }
        if let Some(radius) = radius {
            tool.radius = radius;
            tool.radius_wear = 0.0;
        }
    }
}
