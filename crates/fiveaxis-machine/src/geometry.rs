//! The machine's bodies: solids attached to the links of its kinematic
//! chain (the bed, a linear axis' carriage, a rotary axis' part, the
//! spindle head), placed by the same forward kinematics as the tool
//! (`machine-model.md` §3), for collision checking and the view.
//!
//! Coordinates are the machine frame with every axis at 0 (the spindle
//! gauge point at the origin). A body moves with its link:
//!
//! * `base`: not at all (the bed, the enclosure);
//! * a table rotary axis: with the table chain from the bed out to that
//!   axis (a trunnion's cradle rides on its first axis, the round table
//!   on the second);
//! * a linear axis (X, Y, Z): by that axis' travel alone, as the tool
//!   moves relative to the workpiece (ISO 841): a carriage that carries
//!   the spindle side;
//! * a head rotary axis: with X, Y, Z and the head chain from the
//!   carriage out to that axis;
//! * `head`: with X, Y, Z and the whole head chain (the spindle housing).

use nalgebra::{IsometryMatrix3, Rotation3, Translation3, Unit};

use crate::kinematics::rotation_about;
use crate::{Joints, Machine, Side, Vec3};

/// What a body rides on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Link {
    /// The machine bed: it does not move.
    Base,
    /// The spindle head: X, Y, Z and every head rotary axis.
    Head,
    /// An axis of the machine, by joint index (linear axes first).
    Axis(usize),
}

/// A solid's position in its link's frame: its reference point and the
/// direction of its own Z axis, turned about that axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Where the solid's reference point is, mm.
    pub at: Vec3,
    /// The solid's own +Z.
    pub axis: Unit<Vec3>,
    /// A turn about `axis`, degrees (a box's X and Y).
    pub turn: f64,
}

impl Default for Placement {
    fn default() -> Self {
        Self {
            at: Vec3::zeros(),
            axis: Vec3::z_axis(),
            turn: 0.0,
        }
    }
}

impl Placement {
    /// The map from the solid's own frame to its link's frame.
    pub fn isometry(&self) -> IsometryMatrix3<f64> {
        let up = Rotation3::rotation_between(&Vec3::z(), &self.axis).unwrap_or_else(|| {
            // Straight down: half a turn about X.
            Rotation3::from_axis_angle(&Vec3::x_axis(), std::f64::consts::PI)
        });
        let spin = Rotation3::from_axis_angle(&Vec3::z_axis(), self.turn.to_radians());
        IsometryMatrix3::from_parts(Translation3::from(self.at), up * spin)
    }

    /// The placement whose [`Placement::isometry`] is `map`: `axis` the
    /// image of +Z, `turn` what is left about it once the solid's +Z is
    /// brought there the way `isometry` does (in (−180°, 180°]).
    pub fn from_isometry(map: &IsometryMatrix3<f64>) -> Self {
        let axis = Unit::new_normalize(map.rotation * Vec3::z());
        let up = Placement {
            axis,
            ..Placement::default()
        }
        .isometry()
        .rotation;
        // up⁻¹·R keeps +Z: a turn about it.
        let spin = up.inverse() * map.rotation;
        let m = spin.matrix();
        let turn = m[(1, 0)].atan2(m[(0, 0)]).to_degrees();
        Self {
            at: map.translation.vector,
            axis,
            turn,
        }
    }
}

/// A solid primitive, in its own frame ([`Placement`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A box of these sizes along its X, Y, Z, centred on its reference
    /// point.
    Box {
        /// Sizes, mm.
        size: Vec3,
    },
    /// A cylinder standing on its reference point, along its +Z.
    Cylinder {
        /// Radius, mm.
        radius: f64,
        /// Length, mm.
        length: f64,
    },
    /// A truncated cone standing on its reference point, along its +Z.
    Cone {
        /// Radius at the reference point, mm.
        bottom: f64,
        /// Radius at the far end, mm.
        top: f64,
        /// Length, mm.
        length: f64,
    },
    /// A sphere about its reference point.
    Sphere {
        /// Radius, mm.
        radius: f64,
    },
    /// A capsule: every point within `radius` of the segment from the
    /// reference point along +Z by `length`.
    Capsule {
        /// Radius, mm.
        radius: f64,
        /// Length of the core segment, mm.
        length: f64,
    },
    /// A closed triangle mesh (an STL file) in its own frame: the
    /// machine's [`BodyMesh`] of this index.
    Mesh {
        /// Index into [`crate::Machine::meshes`].
        mesh: usize,
    },
}

/// A body's triangle mesh: the file the machine file names, and its
/// triangles once read (the machine file is text; whoever reads it from
/// disk reads the mesh files too, relative to it).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BodyMesh {
    /// The file as the machine file writes it.
    pub file: String,
    /// Its triangles in the solid's own frame; empty until read.
    pub triangles: Vec<[Vec3; 3]>,
}

/// A placed solid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solid {
    /// Its shape.
    pub shape: Shape,
    /// Where it is on its link.
    pub place: Placement,
}

/// A body of the machine: a union of solids that move together.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// Its name (findings name it).
    pub name: String,
    /// What it rides on.
    pub on: Link,
    /// Its solids.
    pub solids: Vec<Solid>,
}

impl Machine {
    /// The link the work rides on: the outermost table axis (the one that
    /// carries the table top), else the base.
    pub fn work_link(&self) -> Link {
        self.rotary
            .iter()
            .rposition(|r| r.on == Side::Table)
            .map_or(Link::Base, |k| Link::Axis(self.linear.len() + k))
    }

    /// The map from a link's frame (the machine frame with every axis at
    /// 0) to the machine frame at `joints`.
    pub fn link_pose(&self, link: Link, joints: &Joints) -> IsometryMatrix3<f64> {
        let first = self.linear.len();
        // The head side: X, Y, Z, then the head chain out to `last`.
        let head = |last: usize| {
            let xyz = Vec3::new(joints[0], joints[1], joints[2]);
            let mut map =
                IsometryMatrix3::from_parts(Translation3::from(xyz), Rotation3::identity());
            for (k, axis) in self.rotary.iter().enumerate().take(last) {
                if axis.on == Side::Head {
                    map *= rotation_about(&axis.axis, &axis.center, joints[first + k]);
                }
            }
            map
        };
        match link {
            Link::Base => IsometryMatrix3::identity(),
            Link::Head => head(self.rotary.len()),
            Link::Axis(i) if i < first => {
                // X, Y, Z are joints 0, 1, 2 and move along their own
                // direction (the file puts no body on another linear axis).
                let mut shift = Vec3::zeros();
                if i < 3 {
                    shift[i] = joints[i];
                }
                IsometryMatrix3::from_parts(Translation3::from(shift), Rotation3::identity())
            }
            Link::Axis(i) => {
                let k = i - first;
                match self.rotary.get(k).map(|a| a.on) {
                    Some(Side::Head) => head(k + 1),
                    Some(Side::Table) => {
                        let mut map = IsometryMatrix3::identity();
                        for (j, axis) in self.rotary.iter().enumerate().take(k + 1) {
                            if axis.on == Side::Table {
                                map *= rotation_about(&axis.axis, &axis.center, joints[first + j]);
                            }
                        }
                        map
                    }
                    None => IsometryMatrix3::identity(),
                }
            }
        }
    }
}

/// The cutting end of a tool.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cutter {
    /// A flat end mill.
    Flat,
    /// A ball end mill (its corner radius is the tool radius).
    Ball,
    /// A bull nose (toroidal) end mill.
    BullNose {
        /// The corner radius, mm (0 to the tool radius).
        corner: f64,
    },
    /// A drill with a conical point.
    Drill {
        /// The point's included angle, degrees (118° on a twist drill).
        point_angle: f64,
    },
    /// A tapered end mill: the cutting part widens from the tip.
    Taper {
        /// The half angle of the taper, degrees.
        half_angle: f64,
    },
}

/// One step of a tool holder, from the spindle's gauge line towards the
/// tool: a cylinder, or a cone when its two diameters differ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HolderStep {
    /// Diameter at the spindle's end of the step, mm.
    pub diameter: f64,
    /// Diameter at the tool's end, mm.
    pub tip_diameter: f64,
    /// Length along the tool, mm.
    pub length: f64,
}

/// The shape of a tool and its holder (an offsets file's `[tools.N]`), for
/// collision checking and the view. Along the tool from the gauge point:
/// the holder's steps, then the shank, then the cutting part (`flute`
/// long) down to the tip, `length` (the tool's length offset) away.
#[derive(Clone, Debug, PartialEq)]
pub struct ToolShape {
    /// The cutting end.
    pub cutter: Cutter,
    /// The length of the cutting part, mm.
    pub flute: f64,
    /// The shank's diameter, mm.
    pub shank: f64,
    /// The holder's steps, from the gauge line towards the tool.
    pub holder: Vec<HolderStep>,
}

/// A tool as a solid: its shape, its length from the gauge line to the
/// tip and its radius, mm ([`crate::Offsets::tool_solid`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ToolSolid {
    /// Cutting end, shank and holder.
    pub shape: ToolShape,
    /// Gauge line to tip, mm (length geometry plus wear).
    pub length: f64,
    /// Radius, mm (geometry plus wear).
    pub radius: f64,
}

impl ToolShape {
    /// How far the holder reaches from the gauge line, mm.
    pub fn holder_length(&self) -> f64 {
        self.holder.iter().map(|s| s.length).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn same(a: &IsometryMatrix3<f64>, b: &IsometryMatrix3<f64>) -> bool {
        (a.to_homogeneous() - b.to_homogeneous()).abs().max() < 1e-9
    }

    proptest! {
        #[test]
        fn a_placement_from_an_isometry_gives_it_back(
            ax in -1.0f64..1.0, ay in -1.0f64..1.0, az in -1.0f64..1.0,
            angle in -7.0f64..7.0,
            t in prop::array::uniform3(-1000.0f64..1000.0),
        ) {
            let axis = Vec3::new(ax, ay, az);
            prop_assume!(axis.norm() > 1e-3);
            let rotation = Rotation3::from_axis_angle(&Unit::new_normalize(axis), angle);
            let map = IsometryMatrix3::from_parts(Translation3::new(t[0], t[1], t[2]), rotation);
            let back = Placement::from_isometry(&map).isometry();
            prop_assert!(same(&map, &back), "{map:?} {back:?}");
        }
    }

    #[test]
    fn straight_down_and_nearly_down_round_trip() {
        let mut turns = vec![];
        for spin in [0.0, 30.0, -90.0, 180.0] {
            for tilt in [0.0, 1e-9, 1e-14, 1e-17] {
                // +Z taken to -Z (half a turn about X or Y), then a spin,
                // then a tilt of almost nothing.
                for half in [Vec3::x_axis(), Vec3::y_axis()] {
                    let r = Rotation3::from_axis_angle(&Vec3::x_axis(), tilt)
                        * Rotation3::from_axis_angle(&half, std::f64::consts::PI)
                        * Rotation3::from_axis_angle(&Vec3::z_axis(), f64::to_radians(spin));
                    let map = IsometryMatrix3::from_parts(Translation3::new(1.0, 2.0, 3.0), r);
                    let p = Placement::from_isometry(&map);
                    assert!(same(&map, &p.isometry()), "{spin} {tilt}: {p:?}");
                    turns.push(p.turn);
                }
            }
        }
        assert!(turns.iter().all(|t| (-180.0..=180.0).contains(t)));
    }
}
