//! The machine model's solids and a tool's shape as parry shapes, in
//! their link's frame.

use fiveaxis_machine::Vec3;
use fiveaxis_machine::geometry::{Cutter, Placement, Shape, Solid, ToolShape};
use nalgebra::{IsometryMatrix3, UnitQuaternion};
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::shape::SharedShape;

/// Segments of the circle of a cone or a cutter's profile made convex.
const CIRCLE_SEGMENTS: usize = 32;

/// A nalgebra isometry as parry's pose.
pub fn pose(iso: &IsometryMatrix3<f64>) -> Pose {
    let q = UnitQuaternion::from_rotation_matrix(&iso.rotation);
    let t = iso.translation.vector;
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

/// A point as parry's vector.
pub fn vector(v: &Vec3) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

/// A solid of revolution about the local Z axis from z = 0 to `length`:
/// the convex hull of circles of radius `r0` at 0 and `r1` at `length`.
fn frustum(r0: f64, r1: f64, length: f64) -> Option<SharedShape> {
    let mut points = Vec::with_capacity(2 * CIRCLE_SEGMENTS);
    for k in 0..CIRCLE_SEGMENTS {
        let a = std::f64::consts::TAU * k as f64 / CIRCLE_SEGMENTS as f64;
        // The polygon circumscribes the circle: no point of the solid is
        // left outside.
        let grow = 1.0 / (std::f64::consts::PI / CIRCLE_SEGMENTS as f64).cos();
        let (s, c) = a.sin_cos();
        points.push(Vector::new(r0 * grow * c, r0 * grow * s, 0.0));
        points.push(Vector::new(r1 * grow * c, r1 * grow * s, length));
    }
    SharedShape::convex_hull(&points)
}

/// A cylinder along the local Z axis from z = 0 to `length`.
fn cylinder_z(radius: f64, length: f64) -> (Pose, SharedShape) {
    // parry's cylinder stands along its Y axis, centred on its origin.
    let turn = Rotation::from_rotation_x(std::f64::consts::FRAC_PI_2);
    (
        Pose::from_parts(Vector::new(0.0, 0.0, length / 2.0), turn),
        SharedShape::cylinder(length / 2.0, radius),
    )
}

/// One solid as a shape in its link's frame, with the pose it is drawn
/// at; `None` for a solid without volume.
pub fn solid(solid: &Solid) -> Option<(Pose, SharedShape)> {
    let place = pose(&solid.place.isometry());
    let (local, shape) = match solid.shape {
        Shape::Box { size } => (
            Pose::IDENTITY,
            SharedShape::cuboid(size.x / 2.0, size.y / 2.0, size.z / 2.0),
        ),
        Shape::Cylinder { radius, length } => cylinder_z(radius, length),
        Shape::Cone {
            bottom,
            top,
            length,
        } => (Pose::IDENTITY, frustum(bottom, top, length)?),
        Shape::Sphere { radius } => (Pose::IDENTITY, SharedShape::ball(radius)),
        Shape::Capsule { radius, length } => (
            Pose::IDENTITY,
            SharedShape::capsule(Vector::ZERO, Vector::new(0.0, 0.0, length), radius),
        ),
        // A mesh is a part of its own (`mesh_solid`): parry's compounds
        // hold convex shapes.
        Shape::Mesh { .. } => return None,
    };
    Some((place * local, shape))
}

/// The solids of a body as one compound shape.
pub fn body(solids: &[Solid]) -> Option<SharedShape> {
    let parts: Vec<_> = solids.iter().filter_map(solid).collect();
    (!parts.is_empty()).then(|| SharedShape::compound(parts))
}

/// A tool's parts in the head's frame (the gauge point at the origin, the
/// tool along −`t0`): the cutting part, the shank and the holder, each
/// `None` when it has no length. `length`: the tool's gauge length;
/// `radius`: its radius.
pub fn tool(shape: &ToolShape, length: f64, radius: f64, t0: &Vec3) -> [Option<SharedShape>; 3] {
    // The tool's own frame: +Z from the tip towards the spindle, the tip
    // at z = 0 and the gauge point at z = length.
    let place = Placement {
        at: -length * t0,
        axis: nalgebra::Unit::new_normalize(*t0),
        turn: 0.0,
    };
    let frame = pose(&place.isometry());
    let holder_length = shape.holder_length();
    let flute = shape.flute.min((length - holder_length).max(0.0));
    let cutting = cutter(shape.cutter, radius, flute);
    let shank_length = (length - holder_length - flute).max(0.0);
    let shank = (shank_length > 0.0).then(|| {
        let (p, s) = cylinder_z(shape.shank / 2.0, shank_length);
        SharedShape::compound(vec![(
            frame * Pose::from_translation(Vector::new(0.0, 0.0, flute)) * p,
            s,
        )])
    });
    let mut steps = Vec::new();
    let mut top = length;
    for step in &shape.holder {
        // Each step hangs from the previous one, towards the tip.
        let bottom = top - step.length;
        if let Some(s) = frustum(step.tip_diameter / 2.0, step.diameter / 2.0, step.length) {
            steps.push((
                frame * Pose::from_translation(Vector::new(0.0, 0.0, bottom)),
                s,
            ));
        }
        top = bottom;
    }
    let holder = (!steps.is_empty()).then(|| SharedShape::compound(steps));
    let cutting = cutting.map(|(p, s)| SharedShape::compound(vec![(frame * p, s)]));
    [cutting, shank, holder]
}

/// The cutting part, from the tip (z = 0) up `flute`.
fn cutter(kind: Cutter, radius: f64, flute: f64) -> Option<(Pose, SharedShape)> {
    if flute <= 0.0 || radius <= 0.0 {
        return None;
    }
    match kind {
        Cutter::Flat => Some(cylinder_z(radius, flute)),
        Cutter::Ball => {
            let core = (flute - radius).max(0.0);
            Some((
                Pose::IDENTITY,
                SharedShape::capsule(
                    Vector::new(0.0, 0.0, radius),
                    Vector::new(0.0, 0.0, radius + core),
                    radius,
                ),
            ))
        }
        Cutter::BullNose { corner } => {
            // The torus' convex hull: a cylinder rounded by the corner.
            let inner = (radius - corner).max(0.0);
            let mut points = Vec::new();
            for k in 0..=8 {
                let a = std::f64::consts::FRAC_PI_2 * k as f64 / 8.0;
                let (s, c) = a.sin_cos();
                let r = inner + corner * c;
                let z = corner - corner * s;
                for j in 0..CIRCLE_SEGMENTS {
                    let b = std::f64::consts::TAU * j as f64 / CIRCLE_SEGMENTS as f64;
                    let grow = 1.0 / (std::f64::consts::PI / CIRCLE_SEGMENTS as f64).cos();
                    let (sb, cb) = b.sin_cos();
                    points.push(Vector::new(r * grow * cb, r * grow * sb, z));
                }
            }
            for j in 0..CIRCLE_SEGMENTS {
                let b = std::f64::consts::TAU * j as f64 / CIRCLE_SEGMENTS as f64;
                let grow = 1.0 / (std::f64::consts::PI / CIRCLE_SEGMENTS as f64).cos();
                let (sb, cb) = b.sin_cos();
                points.push(Vector::new(radius * grow * cb, radius * grow * sb, flute));
            }
            Some((Pose::IDENTITY, SharedShape::convex_hull(&points)?))
        }
        Cutter::Drill { point_angle } => {
            let point = radius / (point_angle / 2.0).to_radians().tan();
            let point = point.min(flute);
            let mut points = vec![Vector::ZERO];
            for j in 0..CIRCLE_SEGMENTS {
                let b = std::f64::consts::TAU * j as f64 / CIRCLE_SEGMENTS as f64;
                let grow = 1.0 / (std::f64::consts::PI / CIRCLE_SEGMENTS as f64).cos();
                let (sb, cb) = b.sin_cos();
                points.push(Vector::new(radius * grow * cb, radius * grow * sb, point));
                points.push(Vector::new(radius * grow * cb, radius * grow * sb, flute));
            }
            Some((Pose::IDENTITY, SharedShape::convex_hull(&points)?))
        }
        Cutter::Taper { half_angle } => {
            let top = radius + flute * half_angle.to_radians().tan();
            Some((Pose::IDENTITY, frustum(radius, top, flute)?))
        }
    }
}

/// A closed triangle mesh (a fixture or stock read from STL), its
/// vertices already where it stands; `None` without triangles or when
/// parry refuses the mesh.
pub fn mesh(triangles: &[[Vec3; 3]]) -> Option<SharedShape> {
    if triangles.is_empty() {
        return None;
    }
    let mut vertices = Vec::with_capacity(triangles.len() * 3);
    let mut indices = Vec::with_capacity(triangles.len());
    for (k, t) in triangles.iter().enumerate() {
        vertices.extend(t.iter().map(vector));
        let k = u32::try_from(3 * k).ok()?;
        indices.push([k, k + 1, k + 2]);
    }
    use parry3d_f64::shape::TriMeshFlags;
    let flags = TriMeshFlags::MERGE_DUPLICATE_VERTICES
        | TriMeshFlags::DELETE_DEGENERATE_TRIANGLES
        | TriMeshFlags::DELETE_DUPLICATE_TRIANGLES
        | TriMeshFlags::ORIENTED;
    SharedShape::trimesh_with_flags(vertices.clone(), indices.clone(), flags)
        .or_else(|_| SharedShape::trimesh(vertices, indices))
        .ok()
}

/// The box between corners `min` and `max`.
pub fn cuboid(min: &Vec3, max: &Vec3) -> SharedShape {
    let half = (max - min) / 2.0;
    let centre = (min + max) / 2.0;
    SharedShape::compound(vec![(
        Pose::from_translation(vector(&centre)),
        SharedShape::cuboid(half.x, half.y, half.z),
    )])
}

/// A body's mesh solid as a shape in its link's frame: the triangles of
/// `meshes` it names, moved by its placement; `None` when they were not
/// read or parry refuses them.
pub fn mesh_solid(
    solid: &Solid,
    meshes: &[fiveaxis_machine::geometry::BodyMesh],
) -> Option<SharedShape> {
    let Shape::Mesh { mesh } = solid.shape else {
        return None;
    };
    let iso = solid.place.isometry();
    let moved: Vec<[Vec3; 3]> = meshes
        .get(mesh)?
        .triangles
        .iter()
        .map(|t| t.map(|p| (iso * nalgebra::Point3::from(p)).coords))
        .collect();
    self::mesh(&moved)
}
