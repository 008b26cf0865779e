//! Workpiece setup errors (G54.4): how the workpiece as clamped differs
//! from the workpiece of the drawing, as a rigid map.

use nalgebra::Rotation3;

use crate::{Joints, MAX_AXES, Machine, SetupErrorSet, Side, Vec3};

/// A rigid map from the programmed (ideal) workpiece to the real one:
/// `p ↦ origin + rotation·p`, in the work coordinate system at table
/// position 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SetupError {
    /// Origin error Δx, Δy, Δz, mm.
    pub origin: Vec3,
    /// Rotation error `Rz(Δc)·Ry(Δb)·Rx(Δa)`.
    pub rotation: Rotation3<f64>,
}

impl Default for SetupError {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl SetupError {
    /// No error.
    pub const IDENTITY: SetupError = SetupError {
        origin: Vec3::new(0.0, 0.0, 0.0),
        rotation: Rotation3::from_matrix_unchecked(nalgebra::Matrix3::new(
            1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0,
        )),
    };

    /// A data set as measured, turned back to table position 0: the errors
    /// were measured in the work coordinate system with the table at the
    /// set's rotary positions; turning the table back turns them with it
    /// (FANUC: Δy = 10 measured at C−90° on a table C turning about −Z is
    /// Δx = 10 at C0). Table axes the set does not name were at 0.
    ///
    /// # Errors
    ///
    /// The name of an axis in the set that is not a table axis of the
    /// machine.
    pub fn from_set(set: &SetupErrorSet, machine: &Machine) -> Result<SetupError, char> {
        let mut joints: Joints = [0.0; MAX_AXES];
        for &(name, angle) in &set.table {
            match machine
                .rotary
                .iter()
                .position(|r| r.name == name && r.on == Side::Table)
            {
                Some(k) => joints[machine.rotary_index(k)] = angle,
                None => return Err(name),
            }
        }
        let measured = machine.chain(Side::Table, &joints).rotation;
        let [a, b, c] = [set.rotation.x, set.rotation.y, set.rotation.z].map(f64::to_radians);
        let rotation = Rotation3::from_axis_angle(&Vec3::z_axis(), c)
            * Rotation3::from_axis_angle(&Vec3::y_axis(), b)
            * Rotation3::from_axis_angle(&Vec3::x_axis(), a);
        Ok(SetupError {
            origin: measured.inverse() * set.origin,
            rotation: measured.inverse() * rotation * measured,
        })
    }

    /// This error applied after `first` (FANUC adds the common set 00 to
    /// the selected one: the selected set, then the common one).
    pub fn after(&self, first: &SetupError) -> SetupError {
        SetupError {
            origin: self.origin + self.rotation * first.origin,
            rotation: self.rotation * first.rotation,
        }
    }

    /// A programmed point on the real workpiece.
    pub fn point(&self, p: &Vec3) -> Vec3 {
        self.origin + self.rotation * p
    }

    /// A programmed direction on the real workpiece.
    pub fn vector(&self, v: &Vec3) -> Vec3 {
        self.rotation * v
    }

    /// A point of the real workpiece back in programmed coordinates.
    pub fn inverse_point(&self, p: &Vec3) -> Vec3 {
        self.rotation.inverse() * (p - self.origin)
    }

    /// A direction of the real workpiece back in programmed coordinates.
    pub fn inverse_vector(&self, v: &Vec3) -> Vec3 {
        self.rotation.inverse() * v
    }

    /// Whether this is no error at all.
    pub fn is_identity(&self) -> bool {
        *self == Self::IDENTITY
    }
}
