//! Forward kinematics (`machine-model.md` §3), the one source of the tool
//! tip and tool direction that the kernel reports.

use nalgebra::{IsometryMatrix3, Rotation3, Translation3, Unit};

use crate::{Joints, Machine, Side, Vec3};

/// Where the tool is: tip and direction (tip → spindle, unit) in one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Tool tip, mm.
    pub tip: Vec3,
    /// Unit tool direction, tip towards spindle.
    pub dir: Vec3,
}

/// Rotation by `degrees` about `axis`, right-hand rule.
pub fn rotation(axis: &Unit<Vec3>, degrees: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(axis, degrees.to_radians())
}

/// Sine and cosine of an angle in degrees.
#[inline]
pub fn sin_cos_degrees(degrees: f64) -> (f64, f64) {
    degrees.to_radians().sin_cos()
}

/// The rigid map of a rotation by `degrees` about the line through `center`
/// along `axis`: `p ↦ center + R·(p − center)`.
pub(crate) fn rotation_about(
    axis: &Unit<Vec3>,
    center: &Vec3,
    degrees: f64,
) -> IsometryMatrix3<f64> {
    let r = rotation(axis, degrees);
    let t = center - r * center;
    IsometryMatrix3::from_parts(Translation3::from(t), r)
}

impl Machine {
    /// The map of the outermost body of one side's chain, bed outwards
    /// `[k1, k2]` giving `M1 ∘ M2`. Head maps act on coordinates relative to
    /// the spindle gauge point; table maps on machine coordinates.
    pub fn chain(&self, side: Side, joints: &Joints) -> IsometryMatrix3<f64> {
        let mut map = IsometryMatrix3::identity();
        for (k, axis) in self.rotary.iter().enumerate() {
            if axis.on == side {
                let angle = joints[self.rotary_index(k)];
                map *= rotation_about(&axis.axis, &axis.center, angle);
            }
        }
        map
    }

    /// Forward kinematics: the tool tip and direction in the table frame
    /// for these machine positions and tool length `tool_length` (the
    /// active H value, 0 without length compensation).
    ///
    /// The same maps as [`Machine::chain`], applied to the two vectors
    /// directly (Rodrigues' formula) rather than composed as matrices: the
    /// head axes turn the tool from the innermost outwards, then the table
    /// axes are undone from the bed outwards. A quill ([`crate::Along::Tool`])
    /// at W puts the tip at `(X, Y, Z) + H((W − L)·t0)`, the contract's
    /// formula with `W − L` for `−L` (`machine-model.md` §3 extended as
    /// its §4 foresees, "more linear axes, e.g. W, allowed later").
    pub fn forward(&self, joints: &Joints, tool_length: f64) -> Pose {
        let t0 = self.tool_direction.into_inner();
        // A quill along the tool moves the tip before the head turns it.
        let mut tip = (self.quill(joints) - tool_length) * t0;
        let mut dir = t0;
        let first = self.linear.len();
        for (k, axis) in self.rotary.iter().enumerate().rev() {
            if axis.on == Side::Head {
                let (sin, cos) = joints[first + k].to_radians().sin_cos();
                tip = axis.center + turn(&axis.axis, &(tip - axis.center), sin, cos);
                dir = turn(&axis.axis, &dir, sin, cos);
            }
        }
        tip += Vec3::new(joints[0], joints[1], joints[2]);
        for (k, axis) in self.rotary.iter().enumerate() {
            if axis.on == Side::Table {
                let (sin, cos) = joints[first + k].to_radians().sin_cos();
                tip = axis.center + turn(&axis.axis, &(tip - axis.center), -sin, cos);
                dir = turn(&axis.axis, &dir, -sin, cos);
            }
        }
        Pose { tip, dir }
    }
}

impl Machine {
    /// [`Machine::forward`] with the quill ([`crate::Along::Tool`]) at 0:
    /// the point TCPC and the tilted working plane program (the inverse
    /// of [`Machine::gauge_for_programmed_tip`]). Without a quill it is
    /// `forward`.
    pub fn programmed_pose(&self, joints: &Joints, tool_length: f64) -> Pose {
        match self.quill_index() {
            Some(i) if joints[i] != 0.0 => {
                let mut j = *joints;
                j[i] = 0.0;
                self.forward(&j, tool_length)
            }
            _ => self.forward(joints, tool_length),
        }
    }
}

/// `v` turned about unit `axis` by the angle whose sine and cosine are
/// given (Rodrigues: v·cos + (k × v)·sin + k·(k·v)·(1 − cos)).
#[inline]
fn turn(axis: &Unit<Vec3>, v: &Vec3, sin: f64, cos: f64) -> Vec3 {
    let k = axis.as_ref();
    v * cos + k.cross(v) * sin + k * (k.dot(v) * (1.0 - cos))
}
