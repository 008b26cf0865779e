//! Feed styles, judged by the kernel's run of the output: random G43.5
//! programs (fixed seed) on every built-in machine type written with
//! `G94` F per block (`dpm`) keep every source block's time within 1 %
//! and every row within the tolerances at its instant, the block time
//! read as FANUC reads a G94 feed with rotary axes (the composite travel
//! of all axes, degrees as mm, over F; `common::block_time`). With the
//! programmed F kept, the header states the largest tip feed error, which
//! must be what the same reading of the output gives against the
//! inverse-time output's block times.

mod common;

use common::{Rules, Side, Worst, composite, judge, line_f, offsets, post, run, vector_program};
use fiveaxis_machine::{Vec3, builtin};
use fiveaxis_post::{FeedStyle, PostOptions};
use proptest::test_runner::{TestCaseError, TestRunner};

const MACHINES: [&str; 4] = [
    "trunnion-ac",
    "trunnion-bc",
    "head-table-bc",
    "head-head-ca",
];

#[test]
fn degrees_per_minute_keeps_every_block_time() {
    let mut all = Worst::default();
    for name in MACHINES {
        let machine = builtin(name).expect("built-in");
        let o = offsets(120.0, Vec3::new(5.0, 10.0, 30.0));
        let options = PostOptions {
            origin: o.work[0],
            feed: FeedStyle::DegreesPerMinute,
            ..PostOptions::default()
        };
        let mut runner = TestRunner::new(common::config(6));
        let worst = std::cell::Cell::new(Worst::default());
        runner
            .run(&common::points(), |points| {
                let p = vector_program(&points, 700.0);
                let segs = run(&machine, &o, &p, None, false)
                    .map_err(|e| TestCaseError::fail(format!("{p}\n{e}")))?;
                let (text, _) = post(&machine, &machine, &segs, options);
                assert!(
                    text.contains("G54 G94\n") && !text.contains("G93"),
                    "{text}"
                );
                let side = |text| Side {
                    machine: &machine,
                    offsets: &o,
                    text,
                };
                let w = judge(side(&p), side(&text), &Rules::of(&options))
                    .map_err(|e| TestCaseError::fail(format!("{name}\n{p}\n{e}")))?;
                worst.set(worst.get().max(w));
                Ok(())
            })
            .unwrap_or_else(|e| panic!("{e}"));
        eprintln!("{name} dpm: {:?}", worst.get());
        all = all.max(worst.get());
    }
    assert!(all.time <= common::TIME_SHARE);
    eprintln!("dpm, all machines: {all:?}");
}

/// The header's figure of `--feed programmed`.
fn stated_error(text: &str) -> f64 {
    let at = text.find("TIP FEED ERROR UP TO ").expect("stated") + "TIP FEED ERROR UP TO ".len();
    text[at..]
        .split_whitespace()
        .next()
        .and_then(|w| w.parse::<f64>().ok())
        .expect("a number")
        / 100.0
}

#[test]
fn programmed_feed_states_its_tip_feed_error() {
    for name in MACHINES {
        let machine = builtin(name).expect("built-in");
        let o = offsets(120.0, Vec3::new(5.0, 10.0, 30.0));
        let mut runner = TestRunner::new(common::config(4));
        runner
            .run(&common::points(), |points| {
                let p = vector_program(&points, 700.0);
                let segs = run(&machine, &o, &p, None, false)
                    .map_err(|e| TestCaseError::fail(format!("{p}\n{e}")))?;
                let base = PostOptions {
                    origin: o.work[0],
                    ..PostOptions::default()
                };
                let kept = PostOptions {
                    feed: FeedStyle::Programmed,
                    ..base
                };
                let (timed, _) = post(&machine, &machine, &segs, base);
                let (text, _) = post(&machine, &machine, &segs, kept);
                // The same blocks: each G1's intended time from the
                // inverse-time output, its time on the control from the
                // programmed one.
                let cut = |t: &str| -> Vec<fiveaxis_control::Segment> {
                    run(&machine, &o, t, None, true)
                        .expect("runs")
                        .into_iter()
                        .filter(|s| s.motion == fiveaxis_control::Motion::Linear && s.moves())
                        .collect()
                };
                let (a, b) = (cut(&timed), cut(&text));
                assert_eq!(a.len(), b.len(), "{timed}\n{text}");
                let mut largest = 0.0f64;
                for (x, y) in a.iter().zip(&b) {
                    let intended = 1.0 / line_f(&timed, x.line).expect("F");
                    let taken = composite(&machine, y) / line_f(&text, y.line).expect("F");
                    largest = largest.max((intended / taken - 1.0).abs());
                }
                let stated = stated_error(&text);
                if (stated - largest).abs() > 1e-4 + 1e-3 * largest {
                    return Err(TestCaseError::fail(format!(
                        "{name}: stated {stated}, measured {largest}\n{text}"
                    )));
                }
                Ok(())
            })
            .unwrap_or_else(|e| panic!("{e}"));
    }
}
