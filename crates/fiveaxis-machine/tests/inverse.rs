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

/// A machine with three rotary axes (a rotary table with a two-axis
/// head, as LinuxCNC's nutating-head demo, and the other arrangements),
/// built in code from a two-rotary one: a third axis along a random
/// direction added bed-most (a table axis) or outermost (a head axis).
fn three_rotary() -> impl Strategy<Value = (Machine, Joints)> {
    (
        posed(two_rotary_sides()).prop_filter("room for a third rotary axis", |(m, _, _)| {
            m.linear.len() + 3 <= fiveaxis_machine::MAX_AXES
        }),
        common::direction(),
        common::point(200.0),
        any::<bool>(),
        -400.0..400.0f64,
    )
        .prop_map(|((mut m, joints, _), axis, center, table, angle)| {
            let mut extra = m.rotary[0].clone();
            extra.axis = axis;
            extra.center = center;
            let first = m.linear.len();
            let mut j = joints;
            if table {
                extra.on = Side::Table;
                m.rotary.insert(0, extra);
                j[first + 2] = j[first + 1];
                j[first + 1] = j[first];
                j[first] = angle;
            } else {
                extra.on = Side::Head;
                m.rotary.push(extra);
                j[first + 2] = angle;
            }
            (m, j)
        })
}

proptest! {
    #![proptest_config(config(2000))]

    /// A chosen pair of axes with the others held: every answer points the
    /// tool along the asked direction by forward kinematics, the held
    /// axes stay, and the pose's own angles are among the answers (unless
    /// an axis was free).
    #[test]
    fn held_pair_answers_reproduce_the_direction(
        (machine, joints) in three_rotary(),
        pair_choice in 0..3usize,
    ) {
        let pair = [[0, 1], [0, 2], [1, 2]][pair_choice];
        let dir = machine.forward(&joints, 0.0).dir;
        let found = machine.orientations_held(&dir, pair, &joints);
        prop_assert!(!found.is_empty(), "reachable direction not found");
        let idx = [machine.rotary_index(pair[0]), machine.rotary_index(pair[1])];
        let mut matched = false;
        for &angles in found.pairs() {
            let mut answer = joints;
            answer[idx[0]] = angles[0];
            answer[idx[1]] = angles[1];
            let back = machine.forward(&answer, 0.0);
            prop_assert!(angle_between(&back.dir, &dir) < DIRECTION_TOLERANCE,
                "direction off by {} rad for {angles:?}", angle_between(&back.dir, &dir));
            matched |= same_angle(angles[0], joints[idx[0]]) && same_angle(angles[1], joints[idx[1]]);
        }
        prop_assert!(matched || found.free_axis.is_some(),
            "original angles {:?} not among {:?}", (joints[idx[0]], joints[idx[1]]), found.pairs());
    }

    /// On two rotary axes the held form is the ordinary one.
    #[test]
    fn held_pair_of_two_rotary_machine_is_orientations(
        (machine, joints, _) in posed(two_rotary_sides()),
    ) {
        let dir = machine.forward(&joints, 0.0).dir;
        let (i0, i1) = (machine.rotary_index(0), machine.rotary_index(1));
        let plain = machine.orientations(&dir, [joints[i0], joints[i1]]);
        let held = machine.orientations_held(&dir, [0, 1], &joints);
        prop_assert_eq!(plain.pairs().len(), held.pairs().len());
        for p in plain.pairs() {
            prop_assert!(held.pairs().iter().any(|h| same_angle(h[0], p[0]) && same_angle(h[1], p[1])),
                "{:?} not in {:?}", p, held.pairs());
        }
    }
}
