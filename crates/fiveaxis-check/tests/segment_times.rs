//! The timeline of a check (`Checker::keep_segment_times`): when each
//! segment ends in the report's estimated time.

use fiveaxis_check::{Checker, Ending, Report, SegmentTimes, TimeKind};
use fiveaxis_control::{RunOptions, Runner, SliceSource};
use fiveaxis_machine::{Offsets, builtin};

/// The report and, when `keep`, the segment times of a program on the
/// A/C trunnion, with the number of segments.
fn check(program: &str, keep: bool) -> (Report, Option<SegmentTimes>, usize) {
    let machine = builtin("trunnion-ac").expect("built in");
    let options = RunOptions {
        lift_soft_limits: true,
        ..RunOptions::default()
    };
    let mut runner = Runner::new(
        &machine,
        Offsets::default(),
        SliceSource::new(program.as_bytes()),
        options,
    );
    let mut checker = Checker::new(&machine);
    if keep {
        checker.keep_segment_times();
    }
    let mut segments = 0;
    while let Some(seg) = runner.next_segment().expect("runs") {
        checker.segment(&seg);
        segments += 1;
    }
    let (report, times) = checker.finish_with_times(Ending {
        ended: true,
        alarm: None,
        blocks: runner.blocks(),
    });
    (report, times, segments)
}

/// Seconds, estimated, of a program alone.
fn estimated(program: &str) -> f64 {
    check(program, false).0.time.estimated
}

#[test]
fn each_block_ends_when_the_planner_reaches_it_and_the_last_is_the_total() {
    // Rapids and exact stops (G61) end at a stop: a block's end is the
    // time of the program up to it, planned alone.
    let blocks = [
        "G21 G90 G94 G61\n",
        "G0 X100. Y50.\n",
        "G1 X200. F3000.\n",
        "G4 P500\n",
        "G1 Y-50. A-30. F2000.\n",
        "G1 C90. F3600.\n",
        "G0 Z50.\n",
    ];
    let program: String = blocks.concat() + "M30\n";
    let (report, times, segments) = check(&program, true);
    let times = times.expect("kept");
    assert_eq!(times.kind, TimeKind::Estimated);
    assert_eq!(times.ends.len(), segments);
    assert_eq!(times.ends.last().copied(), Some(report.time.estimated));
    assert!(
        times.ends.windows(2).all(|w| w[0] <= w[1]),
        "{:?}",
        times.ends
    );
    // The segments that move, one per motion block here.
    let moving: Vec<f64> = times
        .ends
        .iter()
        .copied()
        .enumerate()
        .filter(|(k, _)| *k == 0 || times.ends[k - 1] < times.ends[*k])
        .map(|(_, t)| t)
        .collect();
    let mut prefix = String::from(blocks[0]);
    let mut want = Vec::new();
    for block in &blocks[1..] {
        prefix.push_str(block);
        if !block.starts_with("G4") {
            want.push(estimated(&(prefix.clone() + "M30\n")));
        }
    }
    assert_eq!(moving.len(), want.len(), "{moving:?} {want:?}");
    for (got, want) in moving.iter().zip(&want) {
        assert!((got - want).abs() <= 1e-9 * want, "{got} s, alone {want} s");
    }
    // Keeping the times changes nothing in the report.
    assert_eq!(check(&program, false).0, report);
}

#[test]
fn the_programmed_time_when_the_estimate_is_the_programmed_time() {
    // A slow full circle: the planner's chords (one per 10°) are shorter
    // than the arc, and the accelerations at F100 take nothing, so the
    // estimate is the programmed time, and so is the timeline.
    let program = "G21 G90 G94 G17\nG0 X50. Y0\nG2 X50. Y0 I-50. J0 F100.\nM30\n";
    let (report, times, _) = check(program, true);
    let times = times.expect("kept");
    assert_eq!(report.time.estimated, report.time.programmed);
    assert_eq!(times.kind, TimeKind::Programmed);
    assert_eq!(times.ends.last().copied(), Some(report.time.programmed));
    // The circle alone: 2π·50 mm at 100 mm/min.
    let circle = times.ends[times.ends.len() - 1] - times.ends[times.ends.len() - 2];
    let want = 2.0 * std::f64::consts::PI * 50.0 / 100.0 * 60.0;
    assert!((circle - want).abs() < 1e-9, "{circle}");
}

#[test]
fn without_asking_there_are_no_times() {
    assert!(check("G0 X10.\nM30\n", false).1.is_none());
}
