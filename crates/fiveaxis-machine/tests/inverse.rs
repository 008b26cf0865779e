//! Inverse kinematics judged by forward kinematics: every answer must give
//! back the commanded tip within 1e-6 mm and direction within 1e-9 rad.

mod common;

use common::{config, posed};
use fiveaxis_machine::{Joints, Machine, Side, Vec3, builtin, principal};
use proptest::prelude::*;

const TIP_TOLERANCE: f64 = 1e-6;
const DIRECTION_TOLERANCE: f64 = 1e-9;

fn two_rotary_sides() -> impl Strategy<Value = Vec<Side>> {
    use Side::{Head, Table};
    prop_oneof![
        Just(vec![Head, Head]),
        Just(vec![Table, Table]),
        Just(vec![Head, Table]),
        Just(vec![Table, Head]),
    ]
}

fn with_angles(joints: &Joints, machine: &Machine, pair: [f64; 2]) -> Joints {
    let mut j = *joints;
    j[machine.rotary_index(0)] = pair[0];
    j[machine.rotary_index(1)] = pair[1];
    j
}

fn angle_between(a: &Vec3, b: &Vec3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

fn same_angle(a: f64, b: f64) -> bool {
    principal(a - b).abs() < 1e-6
}

proptest! {
    #![proptest_config(config(2000))]

    /// Every pair returned points the tool along the asked direction, puts
    /// the tip on the asked point, and the pose it came from is among them
    /// (up to 360° repeats) unless an axis was free.
    #[test]
    fn answers_reproduce_the_pose_by_forward_kinematics(
        (machine, joints, length) in posed(two_rotary_sides()),
        held in (-180.0..180.0f64, -180.0..180.0f64),
    ) {
        let pose = machine.forward(&joints, length);
        let found = machine.orientations(&pose.dir, [held.0, held.1]);
        prop_assert!(!found.is_empty(), "reachable direction not found");
        let (i0, i1) = (machine.rotary_index(0), machine.rotary_index(1));
        let mut matched = false;
        for &pair in found.pairs() {
            let mut answer = with_angles(&joints, &machine, pair);
            let gauge = machine.gauge_for_tip(&answer, &pose.tip, length);
            answer[..3].copy_from_slice(gauge.as_slice());
            let back = machine.forward(&answer, length);
            prop_assert!(angle_between(&back.dir, &pose.dir) < DIRECTION_TOLERANCE,
                "direction off by {} rad for {pair:?}", angle_between(&back.dir, &pose.dir));
            prop_assert!((back.tip - pose.tip).norm() < TIP_TOLERANCE,
                "tip off by {} mm", (back.tip - pose.tip).norm());
            matched |= same_angle(pair[0], joints[i0]) && same_angle(pair[1], joints[i1]);
        }
        prop_assert!(matched || found.free_axis.is_some(),
            "original angles {:?} not among {:?}", (joints[i0], joints[i1]), found.pairs());
    }

    /// Directions no pose reaches get no answer, and those found are exact.
    #[test]
    fn unreachable_directions_have_no_answer(
        (machine, joints, _) in posed(two_rotary_sides()),
        dir in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
    ) {
        let v = Vec3::new(dir.0, dir.1, dir.2);
        prop_assume!(v.norm() > 0.1);
        let v = v.normalize();
        let found = machine.orientations(&v, [0.0, 0.0]);
        for &pair in found.pairs() {
            let answer = with_angles(&joints, &machine, pair);
            let back = machine.forward(&answer, 0.0);
            prop_assert!(angle_between(&back.dir, &v) < DIRECTION_TOLERANCE);
        }
    }
}

#[test]
fn trunnion_has_two_solutions_that_differ_by_tilt_sign_and_half_turn() {
    let m = builtin("trunnion-ac").expect("built-in");
    // Tool leaning 30° towards +Y of the part: A tilts, C turns.
    let v = Vec3::new(0.0, 30f64.to_radians().sin(), 30f64.to_radians().cos());
    let found = m.orientations(&v, [0.0, 0.0]);
    let mut pairs: Vec<[f64; 2]> = found.pairs().to_vec();
    pairs.sort_by(|a, b| a[0].total_cmp(&b[0]));
    assert_eq!(pairs.len(), 2);
    assert!(
        (pairs[0][0] + 30.0).abs() < 1e-9 && (pairs[1][0] - 30.0).abs() < 1e-9,
        "{pairs:?}"
    );
    assert!(same_angle(pairs[0][1] - pairs[1][1], 180.0), "{pairs:?}");
}

#[test]
fn singular_direction_holds_the_rotating_axis() {
    let m = builtin("trunnion-ac").expect("built-in");
    let found = m.orientations(&Vec3::z(), [0.0, 123.0]);
    assert_eq!(found.free_axis, Some(1));
    assert_eq!(found.pairs(), &[[0.0, 123.0]]);
    let m = builtin("head-head-ca").expect("built-in");
    let found = m.orientations(&Vec3::z(), [-45.0, 0.0]);
    assert_eq!(found.free_axis, Some(0));
    assert_eq!(found.pairs(), &[[-45.0, 0.0]]);
}

#[test]
fn head_table_solution_by_hand() {
    // B head about +Y, C table about -Z: a tool direction (sin 40°, 0,
    // cos 40°) in the part is B40 C0 or B-40 C180.
    let m = builtin("head-table-bc").expect("built-in");
    let v = Vec3::new(40f64.to_radians().sin(), 0.0, 40f64.to_radians().cos());
    let pairs = m.orientations(&v, [0.0, 0.0]);
    let has = |b: f64, c: f64| {
        pairs
            .pairs()
            .iter()
            .any(|p| same_angle(p[0], b) && same_angle(p[1], c))
    };
    assert!(has(40.0, 0.0) && has(-40.0, 180.0), "{:?}", pairs.pairs());
    // Turned 90° in the part, the table turns: C+90 with the table
    // turning clockwise from above brings part +Y to machine +X.
    let v = Vec3::new(0.0, 40f64.to_radians().sin(), 40f64.to_radians().cos());
    let pairs = m.orientations(&v, [0.0, 0.0]);
    let has = |b: f64, c: f64| {
        pairs
            .pairs()
            .iter()
            .any(|p| same_angle(p[0], b) && same_angle(p[1], c))
    };
    assert!(has(40.0, 90.0) || has(40.0, -90.0), "{:?}", pairs.pairs());
}
