//! The post's own axes on random machines (any two-rotary arrangement:
//! head-head, table-table, mixed; random axis lines, nutating included,
//! centres, limits, tool direction), judged by forward kinematics
//! (`common::judge`): a random machine-axis program (length compensation
//! on, feed moves turning both rotary axes) becomes the post's own
//! continuous axes for the same tool path; every row within the
//! tolerances of the source at the same instant, inside the singular cone
//! within the programmed direction's angle to the singular line.

mod common;

#[path = "../../fiveaxis-machine/tests/common/mod.rs"]
mod machine_gen;

use common::{Rules, Side, judge, run};
use fiveaxis_control::{RunOptions, Runner, SliceSource};
use fiveaxis_machine::{Machine, Offsets, Vec3};
use fiveaxis_post::{Axes, PostOptions};
use proptest::prelude::*;
use proptest::test_runner::{TestCaseError, TestRunner};

fn random_machine_program() -> impl Strategy<Value = (Machine, String)> {
    use fiveaxis_machine::Side::{Head, Table};
    let sides = prop_oneof![
        Just(vec![Head, Head]),
        Just(vec![Table, Table]),
        Just(vec![Table, Head]),
        Just(vec![Head, Table]),
    ];
    let block = (
        -50.0..50.0f64,
        -50.0..50.0f64,
        0.0..50.0f64,
        -40.0..40.0f64,
        -40.0..40.0f64,
    );
    (
        sides.prop_flat_map(machine_gen::machine_on),
        proptest::collection::vec(block, 1..4),
    )
        .prop_map(|(mut machine, blocks)| {
            // Rotary limits wide enough for the program (flips are
            // tested on the built-in machines); the default cone.
            for axis in &mut machine.rotary {
                axis.limits = None;
                axis.rollover = false;
            }
            machine.params.singular_cone = 2.0;
            let names: Vec<char> = machine.rotary.iter().map(|r| r.name).collect();
            let mut text = String::from("G21 G90 G94 G43 H1\n");
            for (x, y, z, a, b) in blocks {
                text.push_str(&format!(
                    "G1 X{x:.3} Y{y:.3} Z{z:.3} {}{a:.3} {}{b:.3} F1000.\n",
                    names[0], names[1]
                ));
            }
            text.push_str("M30\n");
            (machine, text)
        })
}

#[test]
fn own_axes_on_random_machines_within_tolerance() {
    let offsets = Offsets::from_toml("[tools]\n1 = { length = 120.0 }\n").expect("offsets");
    let mut runner = TestRunner::new(common::config(48));
    let judged = std::cell::Cell::new(0u32);
    let worst = std::cell::Cell::new(common::Worst::default());
    runner
        .run(&random_machine_program(), |(machine, program)| {
            // The program must run on this machine (a random control may
            // refuse a word): the property is about those that do.
            let options = RunOptions {
                lift_soft_limits: true,
                ..RunOptions::default()
            };
            let mut probe = Runner::new(
                &machine,
                offsets.clone(),
                SliceSource::new(program.as_bytes()),
                options,
            );
            let runs = loop {
                match probe.next_segment() {
                    Ok(Some(_)) => {}
                    Ok(None) => break true,
                    Err(_) => break false,
                }
            };
            prop_assume!(runs);
            let segments = run(&machine, &offsets, &program, None, false)
                .map_err(|e| TestCaseError::fail(e.to_string()))?;
            let options = PostOptions {
                axes: Axes::Post {
                    great_circle: false,
                },
                origin: Vec3::zeros(),
                ..PostOptions::default()
            };
            let (text, result) = common::post(&machine, &machine, &segments, options);
            prop_assert_eq!(result.unresolved, 0, "{}", text);
            let rules = Rules {
                singular_margin: Some(fiveaxis_post::follow::KNOT_TURN),
                output_limits: false,
                ..Rules::of(&options)
            };
            let side = |text| Side {
                machine: &machine,
                offsets: &offsets,
                text,
            };
            let w = judge(side(&program), side(&text), &rules)
                .map_err(|e| TestCaseError::fail(format!("{machine:?}\n{program}\n{e}")))?;
            worst.set(worst.get().max(w));
            judged.set(judged.get() + 1);
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{e}"));
    eprintln!("{} random machines judged: {:?}", judged.get(), worst.get());
    assert!(judged.get() >= 20, "only {} programs judged", judged.get());
}
