//! Forward kinematics: properties over random machines, and poses of the
//! built-in machines worked out by hand from `machine-model.md` §3.

mod common;

use approx::assert_relative_eq;
use common::{config, distance_to_line, posed};
use fiveaxis_machine::{Joints, MAX_AXES, Machine, Side, Vec3, builtin};
use proptest::prelude::*;

const EPS: f64 = 1e-9;

fn gauge(j: &Joints) -> Vec3 {
    Vec3::new(j[0], j[1], j[2])
}

proptest! {
    #![proptest_config(config(256))]

    /// (a) The direction is a unit vector.
    #[test]
    fn direction_is_unit((m, j, l) in posed(common::sides())) {
        let pose = m.forward(&j, l);
        prop_assert!((pose.dir.norm() - 1.0).abs() < EPS);
    }

    /// (b) With every rotary at 0 the tool hangs straight from the gauge
    /// point along the machine's tool direction.
    #[test]
    fn rotaries_at_zero((m, mut j, l) in posed(common::sides())) {
        for k in 0..m.rotary.len() {
            j[m.rotary_index(k)] = 0.0;
        }
        let pose = m.forward(&j, l);
        let t0 = m.tool_direction.into_inner();
        prop_assert!((pose.tip - (gauge(&j) - l * t0)).norm() < EPS * 1e3);
        prop_assert!((pose.dir - t0).norm() < EPS);
    }

    /// (c) A head-only machine moves the tool as a rigid body: tips for two
    /// tool lengths are |L1 − L2| apart.
    #[test]
    fn head_tool_is_rigid(
        (m, j, l1) in posed(prop_oneof![Just(vec![Side::Head]), Just(vec![Side::Head, Side::Head])]),
        l2 in 0.0..300.0f64,
    ) {
        let d = (m.forward(&j, l1).tip - m.forward(&j, l2).tip).norm();
        prop_assert!((d - (l1 - l2).abs()).abs() < 1e-8);
    }

    /// (c') On any machine, a longer tool puts the tip further back along
    /// the tool direction: tip(L1) − tip(L2) = (L2 − L1)·dir.
    #[test]
    fn tool_length_runs_along_direction((m, j, l1) in posed(common::sides()), l2 in 0.0..300.0f64) {
        let (p1, p2) = (m.forward(&j, l1), m.forward(&j, l2));
        prop_assert!((p1.tip - p2.tip - (l2 - l1) * p1.dir).norm() < 1e-8);
        prop_assert!((p1.dir - p2.dir).norm() < EPS);
    }

    /// (d) On a table-only machine, turning one table axis (the others at
    /// 0) keeps the tip at the machine point's distance from that axis'
    /// line and at its position along the line.
    #[test]
    fn table_axis_keeps_distance_to_its_line(
        (m, mut j, l) in posed(prop_oneof![Just(vec![Side::Table]), Just(vec![Side::Table, Side::Table])]),
        pick in 0..2usize,
        angle in -400.0..400.0f64,
    ) {
        let k = pick % m.rotary.len();
        for i in 0..m.rotary.len() {
            j[m.rotary_index(i)] = 0.0;
        }
        j[m.rotary_index(k)] = angle;
        let axis = &m.rotary[k];
        let (a, c) = (axis.axis.into_inner(), axis.center);
        let machine_point = gauge(&j) - l * m.tool_direction.into_inner();
        let tip = m.forward(&j, l).tip;
        let scale = 1e-9 * (1.0 + machine_point.norm() + c.norm());
        prop_assert!((distance_to_line(&tip, &c, &a) - distance_to_line(&machine_point, &c, &a)).abs() < scale);
        prop_assert!(((tip - c).dot(&a) - (machine_point - c).dot(&a)).abs() < scale);
    }

    /// (d') Turning the outermost table axis, whatever the inner one is at,
    /// keeps the tip's distance to the outermost axis' line.
    #[test]
    fn outer_table_axis_keeps_distance(
        (m, j, l) in posed(Just(vec![Side::Table, Side::Table])),
        other in -400.0..400.0f64,
    ) {
        let outer = &m.rotary[1];
        let (a, c) = (outer.axis.into_inner(), outer.center);
        let mut turned = j;
        turned[m.rotary_index(1)] = other;
        let d1 = distance_to_line(&m.forward(&j, l).tip, &c, &a);
        let d2 = distance_to_line(&m.forward(&turned, l).tip, &c, &a);
        prop_assert!((d1 - d2).abs() < 1e-8);
    }

    /// A full turn of any rotary axis changes nothing.
    #[test]
    fn full_turn_is_identity((m, j, l) in posed(common::sides()), pick in 0..2usize) {
        prop_assume!(!m.rotary.is_empty());
        let mut turned = j;
        turned[m.rotary_index(pick % m.rotary.len())] += 360.0;
        let (p, q) = (m.forward(&j, l), m.forward(&turned, l));
        prop_assert!((p.tip - q.tip).norm() < 1e-8);
        prop_assert!((p.dir - q.dir).norm() < EPS);
    }
}

/// Joints from named positions.
fn joints(m: &Machine, values: &[(char, f64)]) -> Joints {
    let mut j = [0.0; MAX_AXES];
    for &(name, v) in values {
        j[m.axis_index(name).expect("axis exists")] = v;
    }
    j
}

fn machine(name: &str) -> Machine {
    builtin(name).expect("built-in machine")
}

fn assert_pose(m: &Machine, j: &Joints, l: f64, tip: [f64; 3], dir: [f64; 3]) {
    let pose = m.forward(j, l);
    assert_relative_eq!(pose.tip, Vec3::from(tip), epsilon = 1e-9);
    assert_relative_eq!(pose.dir, Vec3::from(dir), epsilon = 1e-12);
}

/// trunnion-ac, A = −90: T⁻¹ turns by +90° about [−1, 0, 0] through
/// (0, 0, −100), i.e. by −90° about +X: (0, y, z) ↦ (0, z, −y) about the
/// centre. The gauge point (0, 0, 0) is (0, 0, 100) from the centre, which
/// goes to (0, 100, 0): tip (0, 100, −100). The tool direction (0, 0, 1)
/// goes to (0, 1, 0).
#[test]
fn trunnion_ac_tilted_table() {
    let m = machine("trunnion-ac");
    assert_pose(
        &m,
        &joints(&m, &[('A', -90.0)]),
        0.0,
        [0.0, 100.0, -100.0],
        [0.0, 1.0, 0.0],
    );
}

/// trunnion-ac, C = +90 turns the table clockwise seen from above, so the
/// table point (0, 100, 0) comes under a tool standing at X = 100.
#[test]
fn trunnion_ac_turned_table() {
    let m = machine("trunnion-ac");
    assert_pose(
        &m,
        &joints(&m, &[('X', 100.0), ('C', 90.0)]),
        0.0,
        [0.0, 100.0, 0.0],
        [0.0, 0.0, 1.0],
    );
}

/// head-head-ca, A = 90, C = 0, L = 100: the tip starts 250 mm below the
/// pivot (0, 0, 150); +90° about +X takes (0, 0, −250) to (0, 250, 0), so
/// the tip is at the pivot height 250 mm towards +Y and the tool points
/// back along −Y.
#[test]
fn head_head_ca_tilted() {
    let m = machine("head-head-ca");
    let j = joints(&m, &[('X', 10.0), ('Y', 20.0), ('Z', 30.0), ('A', 90.0)]);
    assert_pose(&m, &j, 100.0, [10.0, 270.0, 180.0], [0.0, -1.0, 0.0]);
}

/// head-head-ca, A = 90, C = 90: the C head (first, on the carriage) then
/// turns that by +90° about +Z through the pivot: (0, 250, 0) ↦ (−250, 0, 0)
/// and the direction (0, −1, 0) ↦ (1, 0, 0).
#[test]
fn head_head_ca_tilted_and_turned() {
    let m = machine("head-head-ca");
    let j = joints(
        &m,
        &[
            ('X', 10.0),
            ('Y', 20.0),
            ('Z', 30.0),
            ('A', 90.0),
            ('C', 90.0),
        ],
    );
    assert_pose(&m, &j, 100.0, [-240.0, 20.0, 180.0], [1.0, 0.0, 0.0]);
}

/// head-table-bc, B = 90, L = 100: +90° about +Y through the pivot takes
/// (0, 0, −250) to (−250, 0, 0); the direction (0, 0, 1) to (1, 0, 0).
#[test]
fn head_table_bc_swivelled() {
    let m = machine("head-table-bc");
    assert_pose(
        &m,
        &joints(&m, &[('B', 90.0)]),
        100.0,
        [-250.0, 0.0, 150.0],
        [1.0, 0.0, 0.0],
    );
}

/// A three-axis machine: the tip is the gauge point less the tool length.
#[test]
fn mill_3axis_straight_down() {
    let m = machine("mill-3axis");
    let j = joints(&m, &[('X', 1.0), ('Y', 2.0), ('Z', 3.0)]);
    assert_pose(&m, &j, 50.0, [1.0, 2.0, -47.0], [0.0, 0.0, 1.0]);
}

/// A bridge mill with a quill W along the tool (C then B on the head,
/// pivot 200 above the gauge point), for the quill's forward kinematics.
const QUILL: &str = r#"
name = "quill"
type = "head"
[[linear]]
name = "X"
min = -1000
max = 1000
[[linear]]
name = "Y"
min = -1000
max = 1000
[[linear]]
name = "Z"
min = -1000
max = 1000
[[linear]]
name = "W"
min = -500
max = 500
along = "tool"
[[rotary]]
name = "C"
on = "head"
axis = [0, 0, 1]
center = [0, 0, 200]
[[rotary]]
name = "B"
on = "head"
axis = [0, -1, 0]
center = [0, 0, 200]
"#;

proptest! {
    #![proptest_config(ProptestConfig { rng_seed: proptest::test_runner::RngSeed::Fixed(7), ..ProptestConfig::default() })]

    /// The quill moves the tip along the tool by W: the tip is the one of
    /// W = 0 plus W times the tool direction (closed form: the tip on the
    /// sphere about the pivot, radius 200 + L − W); `gauge_for_tip` gives
    /// back X, Y, Z, and `gauge_for_programmed_tip` puts the W = 0 tip on
    /// the point.
    #[test]
    fn a_quill_moves_the_tip_along_the_tool(
        x in -500.0..500.0f64, y in -500.0..500.0f64, z in -500.0..500.0f64,
        w in -400.0..400.0f64, c in -360.0..360.0f64, b in -120.0..120.0f64,
        l in 0.0..200.0f64,
    ) {
        let m = Machine::from_toml(QUILL).expect("machine");
        let mut j: Joints = [0.0; MAX_AXES];
        j[..6].copy_from_slice(&[x, y, z, w, c, b]);
        let pose = m.forward(&j, l);
        let (br, cr) = (b.to_radians(), c.to_radians());
        let out = Vec3::new(br.sin() * cr.cos(), br.sin() * cr.sin(), -br.cos());
        let want = Vec3::new(x, y, z + 200.0) + (200.0 + l - w) * out;
        prop_assert!((pose.tip - want).norm() < 1e-9, "{:?} {:?}", pose.tip, want);
        prop_assert!((pose.dir + out).norm() < 1e-12);
        let back = m.gauge_for_tip(&j, &pose.tip, l);
        prop_assert!((back - Vec3::new(x, y, z)).norm() < 1e-9);
        let programmed = m.programmed_pose(&j, l).tip;
        prop_assert!((pose.tip - (programmed + w * pose.dir)).norm() < 1e-9);
        let gauge = m.gauge_for_programmed_tip(&j, &programmed, l);
        prop_assert!((gauge - Vec3::new(x, y, z)).norm() < 1e-9);
    }
}
