//! `convert`, the run-and-convert loop `fiveaxis post` and the Python
//! package share: the same program as converting the segments one by one,
//! the source's alarm instead of a program, and the G54 origin.

use fiveaxis_control::{RunError, RunOptions, Runner, SliceSource};
use fiveaxis_machine::{Offsets, ToolOffset, Vec3, builtin};
use fiveaxis_post::{Converter, PostOptions, convert, g54_origin};

const PROGRAM: &str = include_str!("../../../examples/tcpc-vector.nc");

fn offsets() -> Offsets {
    let mut offsets = Offsets::default();
    offsets.tools.insert(
        1,
        ToolOffset {
            length: 120.0,
            ..ToolOffset::default()
        },
    );
    offsets.work[0] = Vec3::new(1.0, 2.0, 50.0);
    offsets.external = Vec3::new(0.5, 0.0, -1.0);
    offsets
}

#[test]
fn convert_is_the_segments_converted_one_by_one() {
    let machine = builtin("head-table-bc").expect("built-in");
    let offsets = offsets();
    let options = PostOptions {
        origin: g54_origin(&offsets),
        ..PostOptions::default()
    };
    assert_eq!(options.origin, Vec3::new(1.5, 2.0, 49.0));
    let runner = |text: &'static str| {
        Runner::new(
            &machine,
            offsets.clone(),
            SliceSource::new(text.as_bytes()),
            RunOptions::default(),
        )
    };
    let converted = convert(&mut runner(PROGRAM), &machine, options).expect("the example runs");

    let mut by_hand = Converter::new(&machine, options);
    let mut r = runner(PROGRAM);
    while let Some(seg) = r.next_segment().expect("the example runs") {
        by_hand.push(&seg);
    }
    let by_hand = by_hand.finish();
    assert_eq!(converted, by_hand);
    assert!(converted.source_blocks > 0 && !converted.moves.is_empty());
}

#[test]
fn convert_gives_the_source_alarm() {
    let machine = builtin("head-table-bc").expect("built-in");
    let mut runner = Runner::new(
        &machine,
        offsets(),
        SliceSource::new(b"G43.5 H1 Z100.\nG1 X10. I0 J0 K1. F100.\nG500\n"),
        RunOptions::default(),
    );
    match convert(&mut runner, &machine, PostOptions::default()) {
        Err(RunError::Alarm { alarm, .. }) => assert_eq!(alarm.line, 3),
        other => panic!("expected the alarm of line 3, got {other:?}"),
    }
}
