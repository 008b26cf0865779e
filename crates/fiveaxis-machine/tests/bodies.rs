//! The machine's bodies (`[[body]]`): read, refused with line and column,
//! written back, and placed by the same kinematics as the tool.

mod common;

use common::{config, posed, sides};
use fiveaxis_machine::geometry::{Link, Shape};
use fiveaxis_machine::{Machine, Side, builtin, builtin_names};
use nalgebra::{Point3, Vector3};
use proptest::prelude::*;

const TRUNNION: &str = r#"
name = "t"
type = "table"
[[linear]]
name = "X"
min = -500.0
max = 500.0
[[linear]]
name = "Y"
min = -400.0
max = 400.0
[[linear]]
name = "Z"
min = -300.0
max = 500.0
[[rotary]]
name = "A"
on = "table"
axis = [-1, 0, 0]
center = [0, 0, -100]
min = -120.0
max = 30.0
[[rotary]]
name = "C"
on = "table"
axis = [0, 0, -1]
center = [0, 0, 0]
rollover = true
"#;

fn with(bodies: &str) -> Result<Machine, fiveaxis_machine::FileError> {
    Machine::from_toml(&format!("{TRUNNION}{bodies}"))
}

#[test]
fn every_shape_and_link_is_read() {
    let m = with(
        r#"
[[body]]
name = "bed"
on = "base"
solids = [
    { box = [1200, 1000, 100], at = [0, 0, -560] },
    { cylinder = [50, 300], at = [400, 0, -500], axis = [0, 0, 1] },
    { cone = [60, 30, 100], at = [-400, 0, -500], axis = [1, 0, 0], turn = 15 },
    { sphere = 20, at = [0, 300, -500] },
    { capsule = [10, 200], at = [0, -300, -500] },
]
[[body]]
name = "cradle"
on = "A"
solids = [{ box = [700, 500, 40], at = [0, 0, -80] }]
[[body]]
name = "saddle"
on = "Y"
solids = [{ box = [300, 300, 100], at = [0, 0, 800] }]
[[body]]
name = "spindle"
on = "head"
solids = [{ cylinder = [90, 450] }]
"#,
    )
    .expect("a valid machine");
    assert_eq!(m.bodies.len(), 4);
    assert_eq!(m.bodies[0].on, Link::Base);
    assert_eq!(m.bodies[1].on, Link::Axis(3));
    assert_eq!(m.bodies[2].on, Link::Axis(1));
    assert_eq!(m.bodies[3].on, Link::Head);
    let bed = &m.bodies[0].solids;
    assert!(
        matches!(bed[0].shape, Shape::Box { size } if size == Vector3::new(1200.0, 1000.0, 100.0))
    );
    assert!(
        matches!(bed[2].shape, Shape::Cone { bottom, top, length } if (bottom, top, length) == (60.0, 30.0, 100.0))
    );
    assert_eq!(bed[2].place.turn, 15.0);
    assert_eq!(bed[2].place.axis.into_inner(), Vector3::x());
    assert!(matches!(bed[3].shape, Shape::Sphere { radius } if radius == 20.0));
    // A solid placed nowhere stands on the origin, upright.
    assert_eq!(m.bodies[3].solids[0].place.at, Vector3::zeros());
}

/// The error of a machine file with these bodies: (line, key, message).
fn refusal(bodies: &str) -> (u32, Option<String>, String) {
    let e = with(bodies).expect_err("refused");
    (e.line, e.key, e.message)
}

#[test]
fn bad_bodies_are_refused_where_they_are_written() {
    let first_body_line = TRUNNION.lines().count() as u32 + 1;
    let cases: [(&str, u32, &str, &str); 8] = [
        (
            "[[body]]\nname = \"x\"\non = \"B\"\nsolids = [{ sphere = 1 }]\n",
            3,
            "on",
            "rides on",
        ),
        (
            "[[body]]\nname = \"x\"\non = \"W\"\nsolids = [{ sphere = 1 }]\n",
            3,
            "on",
            "rides on",
        ),
        (
            "[[body]]\nname = \"holder\"\non = \"head\"\nsolids = [{ sphere = 1 }]\n",
            2,
            "name",
            "tool or the work",
        ),
        (
            "[[body]]\nname = \"x\"\non = \"head\"\nsolids = []\n",
            4,
            "solids",
            "at least one solid",
        ),
        (
            "[[body]]\nname = \"x\"\non = \"head\"\nsolids = [{ sphere = 1, box = [1, 1, 1] }]\n",
            4,
            "solids",
            "a solid is one of",
        ),
        (
            "[[body]]\nname = \"x\"\non = \"head\"\nsolids = [{ box = [1, -1, 1] }]\n",
            4,
            "box",
            "sizes from 0",
        ),
        (
            "[[body]]\nname = \"x\"\non = \"head\"\nsolids = [{ cylinder = [1] }]\n",
            4,
            "cylinder",
            "takes 2 numbers",
        ),
        (
            "[[body]]\nname = \"x\"\non = \"head\"\nsolids = [{ sphere = 1, axis = [0, 0, 0] }]\n",
            4,
            "axis",
            "non-zero direction",
        ),
    ];
    for (text, line, key, words) in cases {
        let (l, k, m) = refusal(text);
        assert_eq!(
            (l, k.as_deref()),
            (first_body_line + line - 1, Some(key)),
            "{text}: {m}"
        );
        assert!(m.contains(words), "{text}: {m}");
    }
    let (l, _, m) = refusal(
        "[[body]]\nname = \"x\"\non = \"head\"\nsolids = [{ sphere = 1 }]\n[[body]]\nname = \"x\"\non = \"base\"\nsolids = [{ sphere = 1 }]\n",
    );
    assert_eq!(l, first_body_line + 5);
    assert!(m.contains("two bodies are named"), "{m}");
}

#[test]
fn the_built_in_machines_write_their_bodies_back() {
    for name in builtin_names() {
        let machine = builtin(name).expect("a built-in");
        let again = Machine::from_toml(&machine.to_toml()).expect("reads back");
        assert_eq!(again.bodies, machine.bodies, "{name}");
    }
    for name in builtin_names() {
        let machine = builtin(name).expect("a built-in");
        assert!(
            machine.bodies.len() >= 2,
            "{name} has a plausible set of bodies"
        );
        assert!(
            machine.bodies.iter().any(|b| b.on == Link::Head),
            "{name}: a head"
        );
    }
}

proptest! {
    #![proptest_config(config(500))]

    /// A head body's gauge point and axis, and a table body's frame, are
    /// where forward kinematics puts the tool and the workpiece: the tip
    /// of a tool of length L in the table frame, carried by the table's
    /// pose, is the point −L·t0 of the head's frame.
    #[test]
    fn bodies_move_as_forward_kinematics((machine, joints, length) in posed(sides())) {
        let t0 = machine.tool_direction.into_inner();
        let head = machine.link_pose(Link::Head, &joints);
        let last_table = machine
            .rotary
            .iter()
            .rposition(|r| r.on == Side::Table)
            .map(|k| Link::Axis(machine.linear.len() + k));
        let table = last_table.map_or_else(nalgebra::IsometryMatrix3::identity, |l| {
            machine.link_pose(l, &joints)
        });
        let pose = machine.forward(&joints, length);
        let tip_from_table = table.transform_point(&Point3::from(pose.tip));
        let tip_from_head = head.transform_point(&Point3::from(-length * t0));
        prop_assert!((tip_from_table - tip_from_head).norm() < 1e-9);
        let dir_from_table = table.rotation * pose.dir;
        prop_assert!((dir_from_table - head.rotation * t0).norm() < 1e-12);
        // A carriage moves by its axis alone.
        let y = machine.link_pose(Link::Axis(1), &joints);
        prop_assert_eq!(y.translation.vector, Vector3::new(0.0, joints[1], 0.0));
    }
}

// ----- tools and holders (the offsets file) -------------------------------

use fiveaxis_machine::Offsets;
use fiveaxis_machine::geometry::{Cutter, HolderStep};

#[test]
fn tool_shapes_are_read_with_their_holders() {
    let o = Offsets::from_toml(
        r#"
[tools.1]
length = 120.0
radius = 5.0
cutter = "ball"
flute_length = 20.0
holder = [{ diameter = 40.0, length = 50.0 }, { diameter = 32.0, tip_diameter = 20.0, length = 30.0 }]
[tools.2]
length = 100.0
radius = 6.0
cutter = "bull"
corner_radius = 1.0
shank_diameter = 10.0
[tools.3]
length = 90.0
radius = 4.0
cutter = "drill"
[tools.4]
length = 80.0
radius = 3.0
cutter = "taper"
taper_angle = 3.0
[tools.5]
length = 50.0
radius = 2.0
"#,
    )
    .expect("valid");
    let one = &o.tool_shapes[&1];
    assert_eq!(one.cutter, Cutter::Ball);
    assert_eq!(one.flute, 20.0);
    assert_eq!(one.shank, 10.0);
    assert_eq!(
        one.holder[1],
        HolderStep {
            diameter: 32.0,
            tip_diameter: 20.0,
            length: 30.0
        }
    );
    assert_eq!(one.holder_length(), 80.0);
    assert_eq!(o.tool_shapes[&2].cutter, Cutter::BullNose { corner: 1.0 });
    assert_eq!(o.tool_shapes[&2].shank, 10.0);
    // Without a holder the cutting part is the whole gauge length.
    assert_eq!(o.tool_shapes[&2].flute, 100.0);
    assert_eq!(
        o.tool_shapes[&3].cutter,
        Cutter::Drill { point_angle: 118.0 }
    );
    assert_eq!(o.tool_shapes[&4].cutter, Cutter::Taper { half_angle: 3.0 });
    // A tool given by its length and radius alone has no shape.
    assert!(!o.tool_shapes.contains_key(&5));
    assert_eq!(o.tools[&1].length, 120.0);
}

#[test]
fn bad_tool_shapes_are_refused_where_they_are_written() {
    let cases = [
        ("cutter = \"bull\"", "cutter", "needs `corner_radius`"),
        (
            "cutter = \"bull\"\ncorner_radius = 7.0",
            "corner_radius",
            "larger than the tool's radius",
        ),
        ("point_angle = 118.0", "point_angle", "belongs to a drill"),
        (
            "cutter = \"drill\"\npoint_angle = 190.0",
            "point_angle",
            "between 0 and 180",
        ),
        ("cutter = \"taper\"", "cutter", "needs `taper_angle`"),
        (
            "cutter = \"chamfer\"",
            "cutter",
            "flat, ball, bull, drill or taper",
        ),
        (
            "holder = [{ diameter = 40.0, length = 90.0 }]\nflute_length = 20.0",
            "holder",
            "longer than the tool's length",
        ),
        (
            "holder = [{ diameter = -1.0, length = 10.0 }]",
            "diameter",
            "greater than 0",
        ),
    ];
    for (keys, key, words) in cases {
        let text = format!("[tools.1]\nlength = 100.0\nradius = 6.0\n{keys}\n");
        let e = Offsets::from_toml(&text).expect_err(keys);
        assert_eq!(e.key.as_deref(), Some(key), "{keys}: {}", e.message);
        assert!(e.message.contains(words), "{keys}: {}", e.message);
        assert!(e.line >= 4, "{keys}: line {}", e.line);
    }
}

#[test]
fn a_mesh_solid_names_its_file_and_is_written_back() {
    let m = with(
        "[[body]]\nname = \"jaw\"\non = \"A\"\nsolids = [{ mesh = \"meshes/jaw.stl\", at = [20.0, 0.0, 5.0] }, { box = [1.0, 1.0, 1.0] }]\n",
    )
    .expect("machine");
    assert_eq!(m.meshes.len(), 1);
    assert_eq!(m.meshes[0].file, "meshes/jaw.stl");
    assert!(
        m.meshes[0].triangles.is_empty(),
        "read by whoever reads files"
    );
    assert!(matches!(
        m.bodies[0].solids[0].shape,
        Shape::Mesh { mesh: 0 }
    ));
    let again = Machine::from_toml(&m.to_toml()).expect("written back");
    assert_eq!(again, m);
    // A mesh with another shape in one solid, or an empty name: refused.
    let (line, key, message) = refusal(
        "[[body]]\nname = \"j\"\non = \"A\"\nsolids = [{ mesh = \"a.stl\", sphere = 1.0 }]\n",
    );
    assert!(
        line > 0 && message.contains("mesh = \"FILE.stl\""),
        "{key:?} {message}"
    );
    let (_, key, _) = refusal("[[body]]\nname = \"j\"\non = \"A\"\nsolids = [{ mesh = \" \" }]\n");
    assert_eq!(key.as_deref(), Some("mesh"));
}
