//! Workpiece setup error correction G54.4 (seed 002, Mazak; FANUC common
//! set): judged by forward kinematics of the machine positions.

mod common;

use fiveaxis_control::{Alarm, Row};
use fiveaxis_machine::{
    Control, Machine, Offsets, SetupError, SetupErrorSet, Side, ToolOffset, Vec3, builtin,
};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

const EPS: f64 = 1e-9;

fn machine(name: &str, control: Control) -> Machine {
    let mut m = builtin(name).expect("built-in");
    m.control = control;
    m
}

fn offsets(sets: &[(u32, SetupErrorSet)]) -> Offsets {
    let mut o = Offsets::default();
    o.tools.insert(
        1,
        ToolOffset {
            length: 100.0,
            ..ToolOffset::default()
        },
    );
    for (n, set) in sets {
        o.setup_error.insert(*n, set.clone());
    }
    o
}

fn run(m: &Machine, o: Offsets, program: &str) -> (Vec<Row>, Option<Alarm>) {
    common::run_sampled(m, o, program, &[0.5, 1.0])
}

fn ends(rows: &[Row]) -> Vec<&Row> {
    rows.iter().filter(|r| r.s == 1.0).collect()
}

fn close(a: &Vec3, b: &Vec3, eps: f64) -> bool {
    (a - b).norm() < eps
}

fn set_b(b: f64) -> SetupErrorSet {
    SetupErrorSet {
        rotation: Vec3::new(0.0, b, 0.0),
        ..Default::default()
    }
}

#[test]
fn seed_example_b0_c0_with_error_b_minus_30_takes_b_minus_30_c0() {
    // Head B / table C, programmed B0 C0 (tool vertical) under TCPC; the
    // workpiece is turned by Δb = -30°. Both B-30 C0 and B30 C180 keep the
    // attitude; the G54.4 block takes the one with the smaller table (C)
    // motion: B-30 C0.
    let m = machine("head-table-bc", Control::Mazak);
    let (rows, alarm) = run(
        &m,
        offsets(&[(1, set_b(-30.0))]),
        "G0 X0 Y0 Z50. B0 C0\nG43.4 H1 X0 Y0 Z0\nG54.4 P1\n",
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let g544 = ends(&rows)
        .into_iter()
        .last()
        .expect("the G54.4 block moves");
    assert_eq!(g544.line, 3);
    let (b, c) = (g544.joints[3], g544.joints[4]);
    assert!((b + 30.0).abs() < EPS && c.abs() < EPS, "B{b} C{c}");
    // In the frame of the ideal workpiece the tool is still vertical and
    // the tip on the programmed point.
    assert!(
        close(&g544.dir, &Vec3::z(), EPS) && close(&g544.tip, &Vec3::zeros(), 1e-9),
        "{g544:?}"
    );
    // The other pair gives the same attitude (forward kinematics).
    let mut other = g544.joints;
    other[3] = 30.0;
    other[4] = 180.0;
    let e = SetupError::from_set(&set_b(-30.0), &m).expect("set");
    let pose = m.forward(&other, 100.0);
    assert!(close(&e.inverse_vector(&pose.dir), &Vec3::z(), EPS));
}

#[test]
fn later_blocks_keep_the_tilt_sign_or_take_the_smaller_table_motion() {
    // Programmed B20 C90 on the turned workpiece: its attitude has two
    // pairs; Mazak's default keeps B on its G54.4 side (negative), the
    // parameter takes the pair with the smaller C motion.
    let program = "G0 X0 Y0 Z50. B0 C0\nG43.4 H1 X0 Y0 Z0\nG54.4 P1\nG1 X10. B20. C90. F500.\n";
    let e_set = set_b(-30.0);
    for table_motion in [false, true] {
        let mut m = machine("head-table-bc", Control::Mazak);
        m.params.setup_error_table_motion = table_motion;
        let (rows, alarm) = run(&m, offsets(&[(1, e_set.clone())]), program);
        assert!(alarm.is_none(), "{alarm:?}");
        let last = *ends(&rows).last().expect("rows");
        // The attitude is the programmed one on the ideal workpiece.
        let mut ideal_joints = last.joints;
        ideal_joints[3] = 20.0;
        ideal_joints[4] = 90.0;
        let want = m.forward(&ideal_joints, 100.0).dir;
        assert!(close(&last.dir, &want, 1e-9), "{:?} vs {want:?}", last.dir);
        assert!(
            close(&last.tip, &Vec3::new(10.0, 0.0, 0.0), 1e-9),
            "{:?}",
            last.tip
        );
        let b = last.joints[3];
        if table_motion {
            // The smaller motion of C from 0.
            let c = last.joints[4];
            let alt = c + 180.0;
            assert!(
                fiveaxis_machine::principal(c).abs()
                    <= fiveaxis_machine::principal(alt).abs() + EPS,
                "C{c}"
            );
        } else {
            assert!(b <= 0.0, "B{b} left the negative side");
        }
    }
}

#[test]
fn without_tcpc_points_move_onto_the_real_workpiece() {
    // Δ = (10, 0, 0), Δc = 90°: programmed X10 is machine (10, 10, 0);
    // the row still reports the programmed point.
    let m = machine("mill-3axis", Control::Mazak);
    let set = SetupErrorSet {
        origin: Vec3::new(10.0, 0.0, 0.0),
        rotation: Vec3::new(0.0, 0.0, 90.0),
        ..Default::default()
    };
    let (rows, alarm) = run(&m, offsets(&[(1, set)]), "G54.4 P1\nG1 X10. Y0 Z0 F500.\n");
    assert!(alarm.is_none(), "{alarm:?}");
    let last = *ends(&rows).last().expect("row");
    assert!(close(
        &Vec3::new(last.joints[0], last.joints[1], last.joints[2]),
        &Vec3::new(10.0, 10.0, 0.0),
        1e-9
    ));
    assert!(
        close(&last.tip, &Vec3::new(10.0, 0.0, 0.0), 1e-9),
        "{:?}",
        last.tip
    );
}

#[test]
fn arcs_follow_the_turned_workpiece() {
    // Δa = 90°: the programmed X-Y circle stands in the X-Z plane of the
    // machine; half way round it is still on the programmed circle.
    let m = machine("mill-3axis", Control::Mazak);
    let set = SetupErrorSet {
        rotation: Vec3::new(90.0, 0.0, 0.0),
        ..Default::default()
    };
    let (rows, alarm) = run(
        &m,
        offsets(&[(1, set)]),
        "G54.4 P1\nG0 X10. Y0 Z0\nG3 X-10. Y0 R10. F500.\n",
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let half = rows
        .iter()
        .find(|r| r.line == 3 && r.s == 0.5)
        .expect("row");
    assert!(
        close(&half.tip, &Vec3::new(0.0, 10.0, 0.0), 1e-9),
        "{:?}",
        half.tip
    );
    // In the machine, programmed +Y is +Z.
    assert!((half.joints[2] - 10.0).abs() < 1e-9, "{:?}", half.joints);
}

#[test]
fn fanuc_adds_the_common_set() {
    // The FANUC example (functions-research.md §A.9): No.00 Δy = 10 at
    // C-90, No.01 Δx = 5, Δc = 2 at C90: at C0, Δ = (10, 5, 0), Δc = 2.
    let m = machine("trunnion-ac", Control::Fanuc30i);
    let common = SetupErrorSet {
        origin: Vec3::new(0.0, 10.0, 0.0),
        table: vec![('C', -90.0)],
        ..Default::default()
    };
    let first = SetupErrorSet {
        origin: Vec3::new(5.0, 0.0, 0.0),
        rotation: Vec3::new(0.0, 0.0, 2.0),
        table: vec![('C', 90.0)],
    };
    let (rows, alarm) = run(
        &m,
        offsets(&[(0, common), (1, first)]),
        "G54.4 P1\nG1 X0 Y0 Z0 F500.\n",
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let last = *ends(&rows).last().expect("row");
    assert!(
        close(
            &Vec3::new(last.joints[0], last.joints[1], last.joints[2]),
            &Vec3::new(10.0, 5.0, 0.0),
            1e-9
        ),
        "{:?}",
        last.joints
    );
    // Mazak has no common set: set 0 is the cancel.
    let m = machine("trunnion-ac", Control::Mazak);
    let common = SetupErrorSet {
        origin: Vec3::new(0.0, 10.0, 0.0),
        ..Default::default()
    };
    let (rows, _) = run(
        &m,
        offsets(&[(0, common), (1, SetupErrorSet::default())]),
        "G54.4 P1\nG1 X1. Y0 Z0 F500.\n",
    );
    let last = *ends(&rows).last().expect("row");
    assert!(last.joints[1].abs() < EPS);
}

#[test]
fn mazak_alarms_and_other_controls_codes() {
    let m = machine("head-table-bc", Control::Mazak);
    for (program, code) in [
        ("G54.4 P1 X1.\n", "1815"),
        ("G0 G54.4 P1\n", "1815"),
        ("G54.4\n", "807"),
        ("G54.4 P8\n", "809"),
    ] {
        let (_, alarm) = run(&m, offsets(&[]), program);
        assert_eq!(
            alarm.map(|a| a.code.to_string()),
            Some(code.into()),
            "{program}"
        );
    }
    let m = machine("head-table-bc", Control::Fanuc30i);
    let (_, alarm) = run(&m, offsets(&[]), "G54.4\n");
    assert_eq!(alarm.map(|a| a.code.to_string()), Some("FX0095".into()));
    // A data set that names a rotary axis the table does not have.
    let set = SetupErrorSet {
        table: vec![('A', 10.0)],
        ..Default::default()
    };
    let (_, alarm) = run(&m, offsets(&[(1, set)]), "G54.4 P1\n");
    assert_eq!(alarm.map(|a| a.code.to_string()), Some("FX0097".into()));
}

proptest! {
    #![proptest_config(Config { cases: 96, rng_seed: RngSeed::Fixed(0x5E7_0E44), failure_persistence: None, ..Config::default() })]

    /// Random setup errors on the built-in 5-axis machines under TCPC type 2:
    /// at every block end the real tip (forward kinematics, part frame) is
    /// the corrected programmed point, the real tool the corrected vector,
    /// and the rows report the programmed point and vector.
    #[test]
    fn corrected_tcpc_type2_meets_the_real_workpiece(
        name in prop_oneof![Just("trunnion-ac"), Just("trunnion-bc"), Just("head-table-bc"), Just("head-head-ca")],
        origin in (-5.0..5.0f64, -5.0..5.0f64, -5.0..5.0f64),
        rotation in (-10.0..10.0f64, -10.0..10.0f64, -10.0..10.0f64),
        points in proptest::collection::vec((-50.0..50.0f64, -50.0..50.0f64, 0.0..40.0f64, -0.4..0.4f64, -0.4..0.4f64), 1..5),
    ) {
        let m = machine(name, Control::Mazak);
        let set = SetupErrorSet { origin: Vec3::new(origin.0, origin.1, origin.2), rotation: Vec3::new(rotation.0, rotation.1, rotation.2), table: vec![] };
        let e = SetupError::from_set(&set, &m).expect("set");
        let mut program = String::from("G0 X0 Y0 Z100.\nG43.5 H1 X0 Y0 Z50.\nG54.4 P1\n");
        for (x, y, z, i, j) in &points {
            program.push_str(&format!("G1 X{x:.6} Y{y:.6} Z{z:.6} I{i:.6} J{j:.6} K1. F500.\n"));
        }
        let (rows, alarm) = run(&m, offsets(&[(1, set)]), &program);
        if let Some(alarm) = &alarm {
            // Over-travel or an unreachable attitude may stop a random case.
            prop_assert!(alarm.code.to_string().starts_with("FX") || alarm.code.to_string().starts_with("OT"), "{alarm:?}");
            return Ok(());
        }
        let frame = m.chain(Side::Table, &[0.0; 8]);
        let round = |x: f64| (x * 1e6).round() / 1e6;
        for (k, (x, y, z, i, j)) in points.iter().enumerate() {
            let (x, y, z, i, j) = (&round(*x), &round(*y), &round(*z), &round(*i), &round(*j));
            let line = (k + 4) as u32;
            let row = rows.iter().rev().find(|r| r.line == line && r.s == 1.0);
            let Some(row) = row else { continue };
            let p = Vec3::new(*x, *y, *z);
            let v = Vec3::new(*i, *j, 1.0).normalize();
            prop_assert!(close(&row.tip, &p, 1e-6), "line {line}: reported tip {:?} vs {p:?}", row.tip);
            prop_assert!(close(&row.dir, &v, 1e-9), "line {line}: reported dir {:?} vs {v:?}", row.dir);
            // The real tool, part frame, by forward kinematics.
            let pose = m.forward(&row.joints, 100.0);
            let real_tip = frame.inverse_transform_point(&pose.tip.into()).coords;
            prop_assert!(close(&real_tip, &e.point(&p), 1e-6), "line {line}: real tip {real_tip:?} vs {:?}", e.point(&p));
            prop_assert!(close(&pose.dir, &e.vector(&v), 1e-9), "line {line}: real dir");
        }
    }
}
