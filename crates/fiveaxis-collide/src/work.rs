//! The work on the table: a fixture, the stock or the designed part, as a
//! box or a triangle mesh (STL) in the work frame, and where the work
//! frame stands in the table frame.

use fiveaxis_machine::Vec3;
use parry3d_f64::shape::SharedShape;

use crate::shapes;

/// A solid of the work, in the work frame.
#[derive(Clone, Debug, PartialEq)]
pub enum WorkShape {
    /// The box between two corners.
    Box {
        /// The lowest corner.
        min: Vec3,
        /// The highest corner.
        max: Vec3,
    },
    /// A closed triangle mesh.
    Mesh(Vec<[Vec3; 3]>),
}

impl WorkShape {
    /// The lowest and highest corner of its bounding box.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        match self {
            WorkShape::Box { min, max } => (*min, *max),
            WorkShape::Mesh(triangles) => {
                let mut lo = Vec3::repeat(f64::INFINITY);
                let mut hi = Vec3::repeat(f64::NEG_INFINITY);
                for p in triangles.iter().flatten() {
                    lo = lo.inf(p);
                    hi = hi.sup(p);
                }
                (lo, hi)
            }
        }
    }

    /// Its shape in the table frame, the work zero at `zero`; `None` for a
    /// mesh parry cannot use.
    pub fn placed(&self, zero: &Vec3) -> Option<SharedShape> {
        match self {
            WorkShape::Box { min, max } => Some(shapes::cuboid(&(min + zero), &(max + zero))),
            WorkShape::Mesh(triangles) => {
                let moved: Vec<[Vec3; 3]> = triangles
                    .iter()
                    .map(|t| [t[0] + zero, t[1] + zero, t[2] + zero])
                    .collect();
                shapes::mesh(&moved)
            }
        }
    }
}

/// How deep point `p` lies inside `shape` (its distance to the surface;
/// negative outside).
pub fn depth_inside(shape: &SharedShape, p: &Vec3) -> f64 {
    use parry3d_f64::math::Pose;
    let at = shapes::vector(p);
    let projection = shape.project_point(&Pose::IDENTITY, at, false);
    let d = (projection.point - at).length();
    if projection.is_inside { d } else { -d }
}
