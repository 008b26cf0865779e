//! Retargeting, judged by forward kinematics (`common::judge`): random
//! G43.5 programs (fixed seed) converted to machine axes on machine A,
//! that machine-axis program retargeted to machine B, and B's program
//! back to A. Each stage is within the tolerances of its own source, and
//! the round trip A -> B -> A within three times them of the original
//! (each of the three conversions may use its tolerance once), when B's
//! program needed no flip (a flip's retract is part of B's program and
//! the way back keeps it). Where the
//! post's own axes pass the singular cone (leaving a vertical tool), the
//! direction may be off by its angle to the singular line.

mod common;

use common::{Rules, Side, Worst, judge, offsets, post, run, vector_program};
use fiveaxis_machine::{Machine, Vec3, builtin};
use fiveaxis_post::{Axes, PostOptions};
use proptest::test_runner::{TestCaseError, TestRunner};

const LENGTH: f64 = 100.0;

fn round_trip(a: &Machine, b: &Machine) -> Worst {
    let oa = offsets(LENGTH, Vec3::new(10.0, -5.0, 20.0));
    let ob = offsets(LENGTH, Vec3::new(-30.0, 40.0, 60.0));
    let mut runner = TestRunner::new(common::config(6));
    let worst = std::cell::Cell::new(Worst::default());
    // Round trips compared whole, and with a flip on B.
    let trips = std::cell::Cell::new(Trips(0, 0));
    runner
        .run(&common::points(), |points| {
            let p = vector_program(&points, 900.0);
            let fail = |stage: &str, e: String| {
                TestCaseError::fail(format!("{} -> {} {stage}:\n{p}\n{e}", a.name, b.name))
            };
            // Stage 0: TCPC to A's axes.
            let at_a = PostOptions {
                origin: oa.work[0],
                ..PostOptions::default()
            };
            let segs = run(a, &oa, &p, None, false).map_err(|e| fail("source", e.to_string()))?;
            let (pa, _) = post(a, a, &segs, at_a);
            let side = |machine, offsets, text| Side {
                machine,
                offsets,
                text,
            };
            let w0 = judge(side(a, &oa, &p), side(a, &oa, &pa), &Rules::of(&at_a))
                .map_err(|e| fail("A", e))?;
            // Stage 1: A's axes to B's.
            let to_b = PostOptions {
                origin: ob.work[0],
                axes: Axes::Post {
                    great_circle: false,
                },
                source_tool_length: Some(LENGTH),
                ..PostOptions::default()
            };
            let segs = run(a, &oa, &pa, None, false).map_err(|e| fail("A run", e.to_string()))?;
            let (pb, result) = post(a, b, &segs, to_b);
            prop_assert_eq!(result.out_of_limits, 0);
            // The post's own axes: in the singular cone the direction may
            // be off by its angle to the singular line.
            let cone = |options: &PostOptions| Rules {
                singular_margin: Some(fiveaxis_post::follow::KNOT_TURN),
                ..Rules::of(options)
            };
            let w1 = judge(side(a, &oa, &pa), side(b, &ob, &pb), &cone(&to_b))
                .map_err(|e| fail("A -> B", e))?;
            // Stage 2: B's axes back to A's.
            let back = PostOptions {
                origin: oa.work[0],
                ..to_b
            };
            let segs = run(b, &ob, &pb, None, false).map_err(|e| fail("B run", e.to_string()))?;
            let (pa2, _) = post(b, a, &segs, back);
            let w2 = judge(side(b, &ob, &pb), side(a, &oa, &pa2), &cone(&back))
                .map_err(|e| fail("B -> A", e))?;
            // The round trip against the original, unless B needed a flip
            // (its retract is then part of B's program, which the way
            // back keeps: another path than the original's in time).
            if w1.flips > 0 {
                trips.set(trips.get() + (0, 1));
                return Ok(());
            }
            let whole = Rules {
                tolerance: 3.0 * at_a.tolerance,
                angle_tolerance: 3.0 * at_a.angle_tolerance,
                ..cone(&at_a)
            };
            let w3 = judge(side(a, &oa, &p), side(a, &oa, &pa2), &whole)
                .map_err(|e| fail("A -> B -> A", e))?;
            trips.set(trips.get() + (1, 0));
            eprintln!(
                "{} -> {}: stages tip {:.5} {:.5} {:.5} mm, round trip {:.5} mm {:.5} deg",
                a.name, b.name, w0.tip, w1.tip, w2.tip, w3.tip, w3.angle
            );
            worst.set(worst.get().max(w0).max(w1).max(w2));
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{e}"));
    let Trips(whole, flipped) = trips.get();
    eprintln!("{whole} round trips compared whole, {flipped} with a flip on B");
    assert!(whole >= 3, "only {whole} round trips without a flip");
    worst.get()
}

#[derive(Clone, Copy)]
struct Trips(u32, u32);

impl std::ops::Add<(u32, u32)> for Trips {
    type Output = Trips;
    fn add(self, (a, b): (u32, u32)) -> Trips {
        Trips(self.0 + a, self.1 + b)
    }
}

use proptest::prop_assert_eq;

#[test]
fn head_table_to_trunnion_and_back() {
    let a = builtin("head-table-bc").expect("built-in");
    let b = builtin("trunnion-ac").expect("built-in");
    let w = round_trip(&a, &b);
    eprintln!("worst stage: {w:?}");
}

#[test]
fn trunnion_to_head_head_and_back() {
    let a = builtin("trunnion-bc").expect("built-in");
    let b = builtin("head-head-ca").expect("built-in");
    let w = round_trip(&a, &b);
    eprintln!("worst stage: {w:?}");
}
