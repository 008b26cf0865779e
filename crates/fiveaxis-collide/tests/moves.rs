//! Hand-built moves with known answers: a block on a tilting table that
//! meets the spindle head half-way through a 90° turn and clears it at
//! both ends; moves that stay a known distance away; a holder that meets
//! a fixture while its cutting part cuts the stock.

use fiveaxis_collide::{PartKind, Scene};
use fiveaxis_machine::geometry::{Cutter, HolderStep, ToolShape};
use fiveaxis_machine::{Joints, MAX_AXES, Machine};
use nalgebra::{Point3, Vector3};
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::shape::SharedShape;

/// A box of half sizes `half` centred on `at`.
fn boxed(half: [f64; 3], at: [f64; 3]) -> SharedShape {
    SharedShape::compound(vec![(
        Pose::from_translation(Vector::new(at[0], at[1], at[2])),
        SharedShape::cuboid(half[0], half[1], half[2]),
    )])
}

/// A table tilting about +X through the origin, a 40 mm block on it 200
/// mm out along +Y, and a head Ø60 rising 300 mm from the gauge point.
const TILTING: &str = r#"
name = "tilting"
type = "table"
[[linear]]
name = "X"
min = -1000.0
max = 1000.0
[[linear]]
name = "Y"
min = -1000.0
max = 1000.0
[[linear]]
name = "Z"
min = -1000.0
max = 1000.0
[[rotary]]
name = "A"
on = "table"
axis = [1, 0, 0]
center = [0, 0, 0]
min = -120.0
max = 120.0
[[body]]
name = "block"
on = "A"
solids = [{ box = [40.0, 40.0, 40.0], at = [0.0, 200.0, 0.0] }]
[[body]]
name = "head"
on = "head"
solids = [{ cylinder = [30.0, 300.0] }]
"#;

fn machine() -> Machine {
    Machine::from_toml(TILTING).expect("the test machine")
}

fn joints(x: f64, y: f64, z: f64, a: f64) -> Joints {
    let mut j = [0.0; MAX_AXES];
    j[..4].copy_from_slice(&[x, y, z, a]);
    j
}

/// Whether a point of the block (sampled on a 2 mm grid through its
/// volume) lies inside the head's cylinder at `q`: an intersection found
/// without the collision library.
fn block_inside_head(m: &Machine, q: &Joints) -> bool {
    let block = m.link_pose(fiveaxis_machine::geometry::Link::Axis(3), q);
    let gauge = Vector3::new(q[0], q[1], q[2]);
    for i in 0..=20 {
        for j in 0..=20 {
            for k in 0..=20 {
                let local = Point3::new(
                    -20.0 + 2.0 * f64::from(i),
                    180.0 + 2.0 * f64::from(j),
                    -20.0 + 2.0 * f64::from(k),
                );
                let p = block.transform_point(&local).coords - gauge;
                if p.x.hypot(p.y) <= 30.0 && (0.0..=300.0).contains(&p.z) {
                    return true;
                }
            }
        }
    }
    false
}

#[test]
fn a_block_meets_the_head_half_way_through_a_tilt_and_clears_it_at_both_ends() {
    let m = machine();
    let scene = Scene::new(&m, 0.5);
    let (y, z) = (
        200.0 * 45f64.to_radians().cos(),
        200.0 * 45f64.to_radians().sin(),
    );
    let path = |s: f64| joints(0.0, y, z, 90.0 * s);
    // Clear at both ends, by the independent check.
    assert!(!block_inside_head(&m, &path(0.0)));
    assert!(!block_inside_head(&m, &path(1.0)));
    let contacts = contacts_of(scene.check_move(&m, path));
    assert_eq!(contacts.len(), 1, "{contacts:?}");
    let c = &contacts[0];
    assert!(c.collides(), "{c:?}");
    assert_eq!(c.bodies, ["head".to_string(), "block".to_string()]);
    assert!(c.s > 0.0 && c.s < 1.0, "{c:?}");
    assert!(c.depth > 10.0, "the block runs deep into the head: {c:?}");
    // At the reported instant the block is inside the head.
    let mid = path(0.5);
    assert!(block_inside_head(&m, &mid));
    // The first contact is reported within the clearance of the true
    // one: a little before it, the block is still outside the head.
    assert!(c.s <= 0.5);
}

#[test]
fn moves_a_known_distance_away_report_no_collision() {
    let m = machine();
    let scene = Scene::new(&m, 0.5);
    // The head passes 100 mm above the block's top face (z 20).
    let high = |s: f64| joints(-500.0 + 1000.0 * s, 200.0, 120.0, 0.0);
    assert!(contacts_of(scene.check_move(&m, high)).is_empty());
    // It stops 0.3 mm above it: a near miss, not a collision.
    let near = |s: f64| joints(0.0, 200.0, 120.0 - 99.7 * s, 0.0);
    let contacts = contacts_of(scene.check_move(&m, near));
    assert_eq!(contacts.len(), 1, "{contacts:?}");
    assert!(!contacts[0].collides());
    assert!(
        (contacts[0].distance - 0.3).abs() < 1e-6,
        "{:?}",
        contacts[0]
    );
    assert_eq!(contacts[0].depth, 0.0);
}

#[test]
fn the_holder_hits_a_fixture_while_the_cutter_cuts_the_stock() {
    let m = machine();
    let mut scene = Scene::new(&m, 0.5);
    let tool = ToolShape {
        cutter: Cutter::Flat,
        flute: 30.0,
        shank: 10.0,
        holder: vec![HolderStep {
            diameter: 40.0,
            tip_diameter: 40.0,
            length: 50.0,
        }],
    };
    scene.set_tool(&m, &tool, 100.0, 5.0);
    // Stock: a slab at the origin, its top at z 0; a fixture wall 60 mm
    // high beside it at x 30..40.
    scene.add_work(
        &m,
        "stock",
        PartKind::Stock,
        boxed([100.0, 100.0, 20.0], [0.0, 0.0, -20.0]),
    );
    scene.add_work(
        &m,
        "fixture",
        PartKind::Fixture,
        boxed([5.0, 50.0, 30.0], [35.0, -100.0, 30.0]),
    );
    // The tool plunges 10 mm into the stock at x 0, y −100: its tip at z
    // −10, the gauge point at 90; the holder (Ø40, from 90 down to 40)
    // reaches x 20, short of the wall at 30.
    let plunge = |s: f64| joints(0.0, -100.0, 100.0 - 10.0 * s, 0.0);
    let contacts = contacts_of(scene.check_move(&m, plunge));
    // Cutting is not a collision, and nothing else comes near.
    assert!(contacts.is_empty(), "{contacts:?}");
    // Moving over to x 15 the holder (radius 20) runs 5 mm into the wall.
    let over = |s: f64| joints(15.0 * s, -100.0, 90.0, 0.0);
    let contacts = contacts_of(scene.check_move(&m, over));
    let hit: Vec<_> = contacts.iter().filter(|c| c.collides()).collect();
    assert_eq!(hit.len(), 1, "{contacts:?}");
    assert_eq!(hit[0].bodies, ["holder".to_string(), "fixture".to_string()]);
    assert!((hit[0].depth - 5.0).abs() < 0.5, "{:?}", hit[0]);
    // The shank and the cutting part stay clear of the wall.
    assert!(
        contacts
            .iter()
            .all(|c| !c.bodies.contains(&"shank".to_string()))
    );
}

/// The contacts without their pair indices.
fn contacts_of(found: Vec<(usize, fiveaxis_collide::Contact)>) -> Vec<fiveaxis_collide::Contact> {
    found.into_iter().map(|(_, c)| c).collect()
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

        /// No contact between samples is missed: where the independent
        /// check finds the block inside the head at any of 100 instants of
        /// a random move, the scene reports a collision.
        #[test]
        fn a_contact_anywhere_along_a_move_is_found(
            from in (-60.0..60.0f64, 100.0..260.0f64, -60.0..200.0f64, -30.0..120.0f64),
            to in (-60.0..60.0f64, 100.0..260.0f64, -60.0..200.0f64, -30.0..120.0f64),
        ) {
            let m = machine();
            let scene = Scene::new(&m, 0.5);
            let path = |s: f64| {
                joints(
                    from.0 + (to.0 - from.0) * s,
                    from.1 + (to.1 - from.1) * s,
                    from.2 + (to.2 - from.2) * s,
                    from.3 + (to.3 - from.3) * s,
                )
            };
            let inside = (0..=100).any(|k| block_inside_head(&m, &path(f64::from(k) / 100.0)));
            let contacts = contacts_of(scene.check_move(&m, path));
            if inside {
                prop_assert!(contacts.iter().any(|c| c.collides()), "{contacts:?}");
            }
        }
    }
}

#[test]
fn bodies_assembled_together_are_not_a_collision_but_the_rest_of_the_chain_is() {
    // A trunnion on A carrying a round table on C: the table sits on the
    // cradle (touching with every axis at 0), the cradle's shafts in the
    // bed's supports. Tilted 90°, the table's edge swings into the bed's
    // floor: that pair (not adjacent) is checked.
    let text = r#"
name = "trunnion"
type = "table"
[[linear]]
name = "X"
min = -1000.0
max = 1000.0
[[linear]]
name = "Y"
min = -1000.0
max = 1000.0
[[linear]]
name = "Z"
min = -1000.0
max = 1000.0
[[rotary]]
name = "A"
on = "table"
axis = [1, 0, 0]
center = [0, 0, 0]
[[rotary]]
name = "C"
on = "table"
axis = [0, 0, 1]
center = [0, 0, 0]
[[body]]
name = "bed"
on = "base"
solids = [
    { box = [100.0, 400.0, 20.0], at = [0.0, 0.0, -150.0] },
    { box = [60.0, 40.0, 60.0], at = [-230.0, 0.0, 0.0] },
]
[[body]]
name = "cradle"
on = "A"
solids = [
    { box = [400.0, 300.0, 20.0], at = [0.0, 0.0, -30.0] },
    { cylinder = [20.0, 60.0], at = [-260.0, 0.0, 0.0], axis = [1, 0, 0] },
]
[[body]]
name = "table"
on = "C"
solids = [{ cylinder = [150.0, 20.0], at = [0.0, 0.0, -20.0] }]
"#;
    let m = Machine::from_toml(text).expect("the test machine");
    let scene = Scene::new(&m, 0.5);
    let names = |pair: &(usize, usize)| {
        let parts = scene.parts();
        let mut n = [parts[pair.0].name.clone(), parts[pair.1].name.clone()];
        n.sort();
        n
    };
    let pairs: Vec<[String; 2]> = scene.pairs().iter().map(names).collect();
    assert_eq!(
        pairs,
        [["bed".to_string(), "table".to_string()]],
        "{pairs:?}"
    );
    // Tilting A to 90°: the table (radius 150, z −20..0) reaches down to
    // −(150·sin A + 20·cos A), the floor's top (−140) at A = 60.1°: the
    // contact is first found there, less the clearance's worth.
    let found = scene.check_move(&m, |s| joints(0.0, 0.0, 0.0, 90.0 * s));
    assert_eq!(found.len(), 1, "{found:?}");
    let contact = &found[0].1;
    let mut bodies = contact.bodies.clone();
    bodies.sort();
    assert_eq!(bodies, ["bed".to_string(), "table".to_string()]);
    let first = 90.0 * contact.s;
    assert!((59.0..=60.1).contains(&first), "first contact at A{first}");
}
