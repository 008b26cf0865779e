//! Reading a machine file's bodies (`[[body]]`, `geometry.rs`).

use serde::Deserialize;
use toml::Spanned;

use super::{FileError, Source};
use crate::geometry::{Body, BodyMesh, Link, Placement, Shape, Solid};
use crate::{Machine, Vec3};

/// Names a body cannot take: the tool assembly's parts and the work's
/// (collision findings name them).
pub const RESERVED_BODY_NAMES: [&str; 5] = ["tool", "shank", "holder", "fixture", "stock"];

/// What a solid is.
const ONE_SHAPE: &str = "a solid is one of box = [x, y, z], cylinder = [radius, length], cone = [bottom radius, top radius, length], sphere = radius, capsule = [radius, length] or mesh = \"FILE.stl\"";

/// Most mesh solids in a machine file.
pub const MAX_MESHES: usize = 64;

/// Most bodies in a machine file.
pub const MAX_BODIES: usize = 64;
/// Most solids in one body.
pub const MAX_SOLIDS: usize = 256;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawBody {
    name: Spanned<String>,
    on: Spanned<String>,
    solids: Spanned<Vec<Spanned<RawSolid>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSolid {
    #[serde(rename = "box")]
    cuboid: Option<Spanned<Vec<f64>>>,
    cylinder: Option<Spanned<Vec<f64>>>,
    cone: Option<Spanned<Vec<f64>>>,
    sphere: Option<Spanned<f64>>,
    capsule: Option<Spanned<Vec<f64>>>,
    mesh: Option<Spanned<String>>,
    at: Option<Spanned<Vec<f64>>>,
    axis: Option<Spanned<Vec<f64>>>,
    turn: Option<Spanned<f64>>,
}

/// The bodies of `raw`, checked against `machine`'s axes, and the mesh
/// files their `mesh` solids name (not read).
pub(super) fn bodies(
    src: &Source<'_>,
    raw: &[Spanned<RawBody>],
    machine: &Machine,
) -> Result<(Vec<Body>, Vec<BodyMesh>), FileError> {
    let mut meshes = Vec::new();
    if let Some(extra) = raw.get(MAX_BODIES) {
        return Err(src.at(
            extra,
            "body",
            format!("a machine has at most {MAX_BODIES} bodies"),
        ));
    }
    let mut out: Vec<Body> = Vec::with_capacity(raw.len());
    for body in raw {
        let body = body.get_ref();
        let name = body.name.get_ref().trim();
        if name.is_empty() {
            return Err(src.at(&body.name, "name", "a body needs a name"));
        }
        if RESERVED_BODY_NAMES.contains(&name) {
            return Err(src.at(
                &body.name,
                "name",
                format!(
                    "`{name}` names a part of the tool or the work: give the body another name"
                ),
            ));
        }
        if out.iter().any(|b| b.name == name) {
            return Err(src.at(&body.name, "name", format!("two bodies are named `{name}`")));
        }
        let on = link(src, &body.on, machine)?;
        let solids = body.solids.get_ref();
        if solids.is_empty() {
            return Err(src.at(&body.solids, "solids", "a body needs at least one solid"));
        }
        if let Some(extra) = solids.get(MAX_SOLIDS) {
            return Err(src.at(
                extra,
                "solids",
                format!("a body has at most {MAX_SOLIDS} solids"),
            ));
        }
        let solids = solids
            .iter()
            .map(|s| solid(src, s, &mut meshes))
            .collect::<Result<Vec<_>, _>>()?;
        out.push(Body {
            name: name.to_owned(),
            on,
            solids,
        });
    }
    Ok((out, meshes))
}

/// `on`: `base`, `head`, X / Y / Z or a rotary axis of the machine.
fn link(src: &Source<'_>, on: &Spanned<String>, machine: &Machine) -> Result<Link, FileError> {
    let text = on.get_ref().trim();
    match text {
        "base" => return Ok(Link::Base),
        "head" => return Ok(Link::Head),
        _ => {}
    }
    let mut chars = text.chars();
    let axis = match (chars.next(), chars.next()) {
        (Some(c), None) => machine.axis_index(c),
        _ => None,
    };
    match axis {
        Some(i) if i >= machine.linear.len() || matches!(text, "X" | "Y" | "Z") => {
            Ok(Link::Axis(i))
        }
        _ => Err(src.at(
            on,
            "on",
            format!(
                "`{text}`: a body rides on \"base\", \"head\", X, Y, Z or a rotary axis of the machine"
            ),
        )),
    }
}

/// A positive size.
fn size(
    src: &Source<'_>,
    value: &Spanned<Vec<f64>>,
    key: &str,
    count: usize,
) -> Result<Vec<f64>, FileError> {
    let v = value.get_ref();
    if v.len() != count {
        return Err(src.at(
            value,
            key,
            format!("`{key}` takes {count} numbers, found {}", v.len()),
        ));
    }
    if v.iter()
        .any(|x| !(x.is_finite() && *x >= 0.0 && *x <= super::MAX_FILE_MAGNITUDE))
    {
        return Err(src.at(
            value,
            key,
            format!(
                "`{key}` takes sizes from 0 to {}",
                super::MAX_FILE_MAGNITUDE
            ),
        ));
    }
    Ok(v.clone())
}

fn solid(
    src: &Source<'_>,
    raw: &Spanned<RawSolid>,
    meshes: &mut Vec<BodyMesh>,
) -> Result<Solid, FileError> {
    let s = raw.get_ref();
    let given = [
        s.cuboid.is_some(),
        s.cylinder.is_some(),
        s.cone.is_some(),
        s.sphere.is_some(),
        s.capsule.is_some(),
        s.mesh.is_some(),
    ]
    .into_iter()
    .filter(|&g| g)
    .count();
    if given != 1 {
        return Err(src.at(raw, "solids", ONE_SHAPE));
    }
    let shape = if let Some(file) = &s.mesh {
        let name = file.get_ref().trim();
        if name.is_empty() {
            return Err(src.at(file, "mesh", "`mesh` names an STL file"));
        }
        if meshes.len() >= MAX_MESHES {
            return Err(src.at(
                file,
                "mesh",
                format!("a machine has at most {MAX_MESHES} mesh solids"),
            ));
        }
        meshes.push(BodyMesh {
            file: name.to_owned(),
            triangles: Vec::new(),
        });
        Shape::Mesh {
            mesh: meshes.len() - 1,
        }
    } else {
        primitive(src, raw)?
    };
    let mut place = Placement::default();
    if let Some(at) = &s.at {
        place.at = src.vec3(at, "at")?;
    }
    if let Some(axis) = &s.axis {
        place.axis = super::machine::unit_vector(src, axis, "axis")?;
    }
    if let Some(turn) = &s.turn {
        place.turn = src.finite(turn, "turn")?;
    }
    Ok(Solid { shape, place })
}

/// A box, cylinder, cone, sphere or capsule.
fn primitive(src: &Source<'_>, raw: &Spanned<RawSolid>) -> Result<Shape, FileError> {
    let s = raw.get_ref();
    let shape = match (&s.cuboid, &s.cylinder, &s.cone, &s.sphere, &s.capsule) {
        (Some(v), ..) => {
            let v = size(src, v, "box", 3)?;
            Shape::Box {
                size: Vec3::new(v[0], v[1], v[2]),
            }
        }
        (_, Some(v), ..) => {
            let v = size(src, v, "cylinder", 2)?;
            Shape::Cylinder {
                radius: v[0],
                length: v[1],
            }
        }
        (_, _, Some(v), ..) => {
            let v = size(src, v, "cone", 3)?;
            Shape::Cone {
                bottom: v[0],
                top: v[1],
                length: v[2],
            }
        }
        (_, _, _, Some(r), _) => {
            let radius = src.finite(r, "sphere")?;
            if radius < 0.0 {
                return Err(src.at(r, "sphere", "`sphere` is a radius: not negative"));
            }
            Shape::Sphere { radius }
        }
        (_, _, _, _, Some(v)) => {
            let v = size(src, v, "capsule", 2)?;
            Shape::Capsule {
                radius: v[0],
                length: v[1],
            }
        }
        (None, None, None, None, None) => return Err(src.at(raw, "solids", ONE_SHAPE)),
    };
    Ok(shape)
}
