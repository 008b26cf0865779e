//! The swivel cycle `CYCLE800`'s frame: the rotation its `_MODE` and
//! angles describe, and the frame `T(X0) · R · T(X1)` it puts in force.
//!
//! `_MODE` (brief §5, HiNC "NcArgCycle800"): bits 7–6 the kind (00 axis
//! by axis, 01 solid angle, 10 projection angle, 11 direct rotary
//! angles); for axis by axis, bits 1–0, 3–2, 5–4 the first, second and
//! third axis turned about (01 X, 10 Y, 11 Z): 57 = 0b00_11_10_01 turns
//! about X, then Y, then Z. Each turn is about the axis of the frame the
//! turns before it made (the manual's "rotated axes").

use fiveaxis_machine::Vec3;
use nalgebra::{Rotation3, Unit};

/// The kind of angles `_MODE` gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SwivelKind {
    /// Turns about the frame's axes, in the order the mode gives.
    AxisByAxis([usize; 3]),
    /// Solid angle: a turn about Z by the first angle, then a tilt about
    /// the new Y by the second (brief §5: "rotation about Z then tilt").
    SolidAngle,
    /// Projection angles: the first two angles are the plane's angles as
    /// seen along X and Y, the third a turn about the new Z.
    Projection,
    /// The angles are the rotary axes' positions.
    Direct,
}

/// The kind and axis order of `_MODE`, or `None` for a mode that names
/// no axis where one is needed.
pub(crate) fn kind(mode: u32) -> Option<SwivelKind> {
    match (mode >> 6) & 0b11 {
        0 => {
            let axis = |shift: u32| match (mode >> shift) & 0b11 {
                1 => Some(0),
                2 => Some(1),
                3 => Some(2),
                _ => None,
            };
            Some(SwivelKind::AxisByAxis([axis(0)?, axis(2)?, axis(4)?]))
        }
        1 => Some(SwivelKind::SolidAngle),
        2 => Some(SwivelKind::Projection),
        _ => Some(SwivelKind::Direct),
    }
}

fn about(axis: usize, degrees: f64) -> Rotation3<f64> {
    let v = match axis {
        0 => Vec3::x_axis(),
        1 => Vec3::y_axis(),
        _ => Vec3::z_axis(),
    };
    Rotation3::from_axis_angle(&v, degrees.to_radians())
}

/// The rotation of a swivel of kind `kind` with angles `a` (degrees): the
/// new frame's axes in the old frame. `Direct` has none here (the
/// machine's axes make it).
pub(crate) fn rotation(kind: SwivelKind, a: [f64; 3]) -> Option<Rotation3<f64>> {
    Some(match kind {
        SwivelKind::AxisByAxis(order) => {
            about(order[0], a[0]) * about(order[1], a[1]) * about(order[2], a[2])
        }
        SwivelKind::SolidAngle => about(2, a[0]) * about(1, a[1]) * about(2, a[2]),
        SwivelKind::Projection => {
            // The new Z seen along X makes angle a0 with Z in the YZ
            // plane, seen along Y angle a1 in the ZX plane; the third
            // angle turns about the new Z.
            let z = Vec3::new(a[1].to_radians().tan(), -a[0].to_radians().tan(), 1.0);
            let z = Unit::new_normalize(z);
            // New X in the old ZX plane (OM800: "new X lies in old ZX
            // plane").
            let x = Vec3::y().cross(&z).normalize();
            let y = z.cross(&x);
            let m = nalgebra::Matrix3::from_columns(&[x, y, z.into_inner()]);
            Rotation3::from_matrix_unchecked(m) * about(2, a[2])
        }
        SwivelKind::Direct => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mode_57_turns_about_x_then_y_then_z() {
        assert_eq!(kind(57), Some(SwivelKind::AxisByAxis([0, 1, 2])));
        assert_eq!(kind(27), Some(SwivelKind::AxisByAxis([2, 1, 0])));
        assert_eq!(kind(192), Some(SwivelKind::Direct));
        assert_eq!(kind(64), Some(SwivelKind::SolidAngle));
        assert_eq!(kind(128), Some(SwivelKind::Projection));
        assert_eq!(kind(0), None);
    }

    #[test]
    fn axis_by_axis_turns_about_the_turned_axes() {
        // About X by 90°: the new Y is the old Z; then about the new Y
        // (the old Z) by 90°: the new X becomes the old Y, the new Z the
        // old X.
        let r = rotation(SwivelKind::AxisByAxis([0, 1, 2]), [90.0, 90.0, 0.0]).expect("a rotation");
        let z = r * Vec3::z();
        let x = r * Vec3::x();
        assert!((x - Vec3::new(0.0, 1.0, 0.0)).norm() < 1e-12, "{x}");
        assert!((z - Vec3::new(1.0, 0.0, 0.0)).norm() < 1e-12, "{z}");
    }

    #[test]
    fn projection_angles_are_the_planes_seen_along_x_and_y() {
        // Seen along Y the plane is tilted 30° about Y: the new Z leans
        // towards +X by 30°; seen along X not at all.
        let r = rotation(SwivelKind::Projection, [0.0, 30.0, 0.0]).expect("a rotation");
        let z = r * Vec3::z();
        assert!(
            (z - Vec3::new(0.5, 0.0, 3f64.sqrt() / 2.0)).norm() < 1e-12,
            "{z}"
        );
        assert!((r * Vec3::x()).y.abs() < 1e-12);
    }
}
