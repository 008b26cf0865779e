//! The small public helpers that the command line and the Python package
//! both call: the row positions of a segment, the displayed machine
//! position, and the rotary choice of TCPC outside a program. Judged by
//! forward kinematics and by hand.

#[path = "../../fiveaxis-machine/tests/common/mod.rs"]
mod machines;

use fiveaxis_control::{Controller, RunOptions, Runner, SliceSource, displayed};
use fiveaxis_machine::{Machine, Offsets, Side, builtin};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

fn builtin_machine(name: &str) -> Machine {
    builtin(name).expect("a built-in machine")
}

#[test]
fn row_fractions_end_exactly_at_one() {
    let machine = builtin_machine("trunnion-ac");
    let program = "G0 X10.\nG1 X20. C100. F100.\n";
    let options = RunOptions {
        interpolation: Some(fiveaxis_control::Interpolation {
            step: 3.0,
            step_angle: 1.0,
        }),
        ..RunOptions::default()
    };
    let mut runner = Runner::new(
        &machine,
        Offsets::default(),
        SliceSource::new(program.as_bytes()),
        options,
    );
    let mut segments = Vec::new();
    runner.fill(&mut segments, 16).expect("the program runs");
    let feed = segments.last().expect("two segments");
    assert!(feed.rows > 1);
    let s: Vec<f64> = feed.row_fractions().collect();
    assert_eq!(s.len(), feed.rows as usize);
    assert_eq!(*s.last().expect("rows"), 1.0);
    for (i, v) in s.iter().enumerate().take(s.len() - 1) {
        assert_eq!(*v, (i + 1) as f64 / f64::from(feed.rows));
    }
    // Without interpolation a block has its end row only.
    let mut one = feed.clone();
    one.rows = 1;
    assert_eq!(one.row_fractions().collect::<Vec<_>>(), vec![1.0]);
}

#[test]
fn displayed_reduces_rollover_axes_only() {
    let machine = builtin_machine("trunnion-ac");
    let c = machine.axis_index('C').expect("C");
    let a = machine.axis_index('A').expect("A");
    assert!(machine.rotary[c - machine.linear.len()].rollover);
    let mut joints = [0.0; fiveaxis_machine::MAX_AXES];
    joints[0] = -725.5;
    joints[a] = -95.0;
    for (given, shown) in [(-90.0, 270.0), (720.0, 0.0), (359.5, 359.5), (-1e-20, 0.0)] {
        joints[c] = given;
        let d = displayed(&machine, &joints);
        assert_eq!(d[c], shown, "C {given}");
        assert_eq!(d[0], -725.5);
        assert_eq!(d[a], -95.0);
    }
}

#[test]
fn rotary_choice_points_the_tool_where_asked() {
    let mut runner = TestRunner::new_with_rng(
        Config {
            cases: 64,
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::from_seed(RngAlgorithm::ChaCha, &[14; 32]),
    );
    let sides = prop_oneof![
        Just(vec![Side::Head, Side::Head]),
        Just(vec![Side::Table, Side::Table]),
        Just(vec![Side::Head, Side::Table]),
        Just(vec![Side::Table, Side::Head]),
    ];
    let strategy = sides
        .prop_flat_map(machines::machine_on)
        .prop_flat_map(|m| {
            let joints = machines::joints_for(&m);
            (Just(m), joints)
        });
    runner
        .run(&strategy, |(mut machine, joints)| {
            // Unlimited rotaries: every direction forward kinematics
            // reaches is a direction the choice must reach.
            for axis in &mut machine.rotary {
                axis.limits = None;
            }
            let target = machine.forward(&joints, 0.0).dir;
            let controller = Controller::new(&machine, Offsets::default());
            let first = machine.linear.len();
            let current = [0.0, 0.0];
            let chosen = controller
                .rotary_position_for(&target, current)
                .map_err(|a| TestCaseError::fail(a.message))?;
            let mut at = joints;
            at[first] = chosen[0];
            at[first + 1] = chosen[1];
            let dir = machine.forward(&at, 0.0).dir;
            prop_assert!((dir - target).norm() < 1e-9, "{dir} against {target}");
            // Nearest repeat of each angle: never more than half a turn
            // from where the axis stands.
            prop_assert!(chosen[0].abs() <= 180.0 + 1e-9 && chosen[1].abs() <= 180.0 + 1e-9);
            Ok(())
        })
        .expect("the choice reaches the direction");
}

#[test]
fn rotary_choice_needs_two_rotary_axes() {
    let machine = builtin_machine("mill-3axis");
    let controller = Controller::new(&machine, Offsets::default());
    let error = controller
        .rotary_position_for(&fiveaxis_machine::Vec3::z(), [0.0, 0.0])
        .expect_err("no rotary axes");
    assert!(error.message.contains("two"), "{}", error.message);
}
