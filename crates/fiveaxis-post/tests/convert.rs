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
    // `convert` also says whether the source used TCPC or a tilted plane.
    assert!(converted.kinematic);
    let unmarked = fiveaxis_post::Post {
        kinematic: false,
        ..converted.clone()
    };
    assert_eq!(unmarked, by_hand);
    assert!(converted.source_blocks > 0 && !converted.moves.is_empty());
    assert!(converted.has_tool_length());
}

#[test]
fn convert_tells_a_program_without_tcpc_or_tilted_plane_apart() {
    let machine = builtin("trunnion-ac").expect("built-in");
    let post = |text: &'static str, offsets: &Offsets| {
        let mut runner = Runner::new(
            &machine,
            offsets.clone(),
            SliceSource::new(text.as_bytes()),
            RunOptions::default(),
        );
        convert(&mut runner, &machine, PostOptions::default()).expect("runs")
    };
    let none = Offsets::default();
    // Arcs, G43 and rotary moves: a machine-axis program already.
    let plain = post(
        "G0 X0 Y0 Z50. A0 C0\nG43 H1 Z10.\nG2 X20. Y0 R10. F300.\nG1 A-20. C45.\nG49\nM30\n",
        &none,
    );
    assert!(!plain.kinematic);
    // TCPC for two blocks only, the tilted working plane, G54.4.
    for text in [
        "G0 X0 Y0 Z50. A0 C0\nG43.4 H1 X0 Y0 Z20.\nG1 X10. A-10. F500.\nG49\nG0 Z100.\nM30\n",
        "G68.2 X0 Y0 Z0 I0 J-30. K0\nG53.1\nG0 X10. Y0 Z30.\nG69\nM30\n",
    ] {
        assert!(post(text, &none).kinematic, "{text}");
    }
    // The tool length: none without the offsets' tool, the given one with
    // `with_tool_length` (and the file's own where it has one).
    let tcpc = "G0 X0 Y0 Z50. A0 C0\nG43.4 H1 X0 Y0 Z20.\nG1 X10. A-10. F500.\nG49\nM30\n";
    assert!(!post(tcpc, &none).has_tool_length());
    let filled = fiveaxis_post::with_tool_length(&none, 95.5);
    assert_eq!(post(tcpc, &filled).tool_lengths[0], 95.5);
    let mut own = Offsets::default();
    own.tools.insert(
        1,
        ToolOffset {
            length: 120.0,
            radius: 5.0,
            ..ToolOffset::default()
        },
    );
    own.tools.insert(
        3,
        ToolOffset {
            radius: 2.0,
            ..ToolOffset::default()
        },
    );
    let filled = fiveaxis_post::with_tool_length(&own, 95.5);
    assert_eq!(filled.tool(1).length, 120.0);
    assert_eq!((filled.tool(2).length, filled.tool(3).length), (95.5, 95.5));
    assert_eq!(filled.tool(3).radius, 2.0);
    // Only up to the highest tool the offsets hold (the tool memory).
    assert!(!filled.tools.contains_key(&4));
    assert_eq!(post(tcpc, &filled).tool_lengths[0], 120.0);
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

/// A law no tolerance near the floor can follow in few pieces (X swinging
/// 100 mm five times in one block) is cut into at most
/// `MAX_BLOCK_PIECES` pieces and says it was capped; at the default
/// tolerance it is not.
#[test]
fn one_block_is_cut_into_a_bounded_number_of_pieces() {
    use fiveaxis_post::linearize::{MAX_BLOCK_PIECES, pieces_of};
    use fiveaxis_post::program::Quantum;
    let machine = builtin("head-table-bc").expect("built-in");
    let law = |s: f64| {
        let mut j = [0.0; fiveaxis_machine::MAX_AXES];
        j[0] = 100.0 * (std::f64::consts::TAU * 5.0 * s).sin();
        j[2] = 100.0;
        j
    };
    let start = law(0.0);
    for (tolerance, capped) in [
        (fiveaxis_post::MIN_TOLERANCE, true),
        (fiveaxis_post::DEFAULT_TOLERANCE, false),
    ] {
        let options = PostOptions {
            tolerance,
            ..PostOptions::default()
        };
        let quantum = Quantum::for_tolerance(tolerance);
        let mut count = 0u64;
        let outcome = pieces_of(&machine, &law, &start, 100.0, &options, &quantum, |_, _| {
            count += 1;
        });
        assert_eq!(outcome.capped, capped, "{tolerance}: {count} pieces");
        assert!(count <= MAX_BLOCK_PIECES, "{tolerance}: {count} pieces");
        if capped {
            assert!(count > MAX_BLOCK_PIECES / 2, "{count} pieces");
        }
    }
}
