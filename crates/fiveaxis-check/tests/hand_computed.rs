//! Programs whose findings are computed by hand.

use fiveaxis_check::{Checker, Ending, Kind, Report};
use fiveaxis_control::{RunError, RunOptions, Runner, SliceSource};
use fiveaxis_machine::{Machine, Offsets, builtin};

fn check(machine: &Machine, offsets: &str, program: &str) -> Report {
    let options = RunOptions {
        lift_soft_limits: true,
        ..RunOptions::default()
    };
    let offsets = Offsets::from_toml(offsets).expect("offsets");
    let mut runner = Runner::new(
        machine,
        offsets,
        SliceSource::new(program.as_bytes()),
        options,
    );
    let mut checker = Checker::new(machine);
    loop {
        match runner.next_segment() {
            Ok(Some(seg)) => checker.segment(&seg),
            Ok(None) => break,
            Err(RunError::Alarm { alarm, .. }) => panic!("{alarm}"),
            Err(e) => panic!("{e}"),
        }
    }
    checker.finish(Ending {
        ended: true,
        alarm: None,
        blocks: runner.blocks(),
    })
}

fn only(report: &Report, kind: Kind) -> (u32, f64, Option<char>) {
    let found: Vec<_> = report.findings.iter().filter(|f| f.kind == kind).collect();
    assert_eq!(found.len(), 1, "{:#?}", report.findings);
    (found[0].line, found[0].value.expect("value"), found[0].axis)
}

#[test]
fn a_tilted_table_passes_the_y_limit_inside_a_tcpc_arc() {
    // TCPC starts with the table tilted (A -90): the programming frame is
    // the table's frame frozen at the start (WKP = 0), its X, Y, Z along
    // the machine's. The start-up block goes to X50 Y0 with the tool
    // length on Z; the arc from (50, 0) counter-clockwise to (-50, 0)
    // passes Y = 50 half way, both ends at Y = 0: beyond the limit 40
    // inside the block only.
    let mut machine = builtin("trunnion-ac").expect("built in");
    machine.linear[1].max = 40.0;
    let report = check(
        &machine,
        "[tools]\n1 = { length = 120.0 }\n",
        "G21 G90 G94 G17\nG0 A-90. C0\nG43.4 H1 X50. Y0 Z0\nG3 X-50. Y0 R50. F1000.\nG49\nM30\n",
    );
    let (line, value, axis) = only(&report, Kind::Overtravel);
    assert_eq!((line, axis), (4, Some('Y')));
    assert!((value - 50.0).abs() < 1e-9, "{value}");
    assert!((report.axes[1].max - 50.0).abs() < 1e-9);
}

#[test]
fn a_g43_5_path_passes_near_the_singular_direction_on_each_machine_type() {
    // Tool posture control: the tool turns on the great circle between
    // (sin 20° cos 85°, ∓sin 20° sin 85°, cos 20°). By symmetry it comes
    // closest to +Z (the rotating axis of every built-in machine) half
    // way, at normalize(sin 20° cos 85°, 0, cos 20°): atan(tan 20° cos 85°).
    let (t, p) = (20f64.to_radians(), 85f64.to_radians());
    let expected = (t.tan() * p.cos()).atan().to_degrees();
    let (i, j, k) = (t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
    let program = format!(
        "G21 G90 G94\nG43.5 H1 X0 Y0 Z50.\nG1 X0 I{i:.15} J{:.15} K{k:.15} F500.\nG1 X10. I{i:.15} J{j:.15} K{k:.15}\nG49\nM30\n",
        -j
    );
    for name in [
        "trunnion-ac",
        "trunnion-bc",
        "head-table-bc",
        "head-head-ca",
    ] {
        let mut machine = builtin(name).expect("built in");
        machine.params.tool_posture_control = true;
        let report = check(&machine, "[tools]\n1 = { length = 100.0 }\n", &program);
        // Line 3 leaves the vertical (0°); line 4 passes the direction.
        let found: Vec<_> = report
            .findings
            .iter()
            .filter(|f| f.kind == Kind::SingularPassage)
            .map(|f| (f.line, f.value.expect("value")))
            .collect();
        assert_eq!(found.len(), 2, "{name}: {found:?}");
        assert_eq!((found[0].0, found[1].0), (3, 4), "{name}");
        assert!(found[0].1 < 1e-9, "{name}");
        let value = found[1].1;
        assert!(
            (value - expected).abs() < 1e-7,
            "{name}: {value} vs {expected}"
        );
    }
}

#[test]
fn a_table_c_turn_moves_the_tip_off_the_chord_by_the_sagitta() {
    // No length offset, the tip at machine X100 on the C line's plane: C
    // turning 90° carries it along a quarter circle of radius 100 about
    // the C line in the table frame. Largest distance from the chord: the
    // sagitta 100·(1 − cos 45°).
    let machine = builtin("trunnion-ac").expect("built in");
    let report = check(
        &machine,
        "",
        "G21 G90 G94\nG0 X100. Y0 Z0 A0 C0\nG1 C90. F1000.\nM30\n",
    );
    let (line, value, _) = only(&report, Kind::ChordError);
    let sagitta = 100.0 * (1.0 - 45f64.to_radians().cos());
    assert_eq!(line, 3);
    assert!(
        (value - sagitta).abs() <= fiveaxis_check::CHORD_PRECISION,
        "{value} vs {sagitta}"
    );
}

#[test]
fn a_feed_the_c_axis_cannot_follow() {
    // The same quarter turn at F20000: the tip's chord is 100·√2 mm, so
    // the block takes 100·√2/20000 min and C needs 90/that deg/min, more
    // than its 7200. The tip feed C allows: 7200·100·√2/90 = 8000·√2.
    let machine = builtin("trunnion-ac").expect("built in");
    let report = check(
        &machine,
        "",
        "G21 G90 G94\nG0 X100. Y0 Z0 A0 C0\nG1 C90. F20000.\nM30\n",
    );
    let (line, value, axis) = only(&report, Kind::FeedLimited);
    assert_eq!((line, axis), (3, Some('C')));
    assert!((value - 8000.0 * 2f64.sqrt()).abs() < 1e-6, "{value}");
    // Programmed time: the rapid from the reference position (Z500) to
    // X100 Z0, as long as Z's 500 mm at 30000 mm/min (1 s), then the
    // chord at F20000.
    let expected = 1.0 + 100.0 * 2f64.sqrt() / 20000.0 * 60.0;
    assert!(
        (report.time.programmed - expected).abs() < 1e-9,
        "{}",
        report.time.programmed
    );
    // Estimated: C turns 90° at no more than its 7200 deg/min (0.75 s)
    // after the rapid (1 s at full speed), each with its accelerations:
    // at least 1.75 s, and not much more.
    let estimated = report.time.estimated;
    assert!((1.75..2.4).contains(&estimated), "{estimated}");
}

#[test]
fn an_inverse_time_feed_limit_names_the_f_word_and_the_tip_feed() {
    // The quarter turn of C in G93 at F200: 1/200 min for the tip's chord
    // of 100·√2 mm, a tip feed of 20000·√2 mm/min; C needs 90·200 =
    // 18000 deg/min, more than its 7200. The tip feed C allows:
    // 8000·√2 = 11313.708 mm/min.
    let machine = builtin("trunnion-ac").expect("built in");
    let report = check(
        &machine,
        "",
        "G21 G90 G94\nG0 X100. Y0 Z0 A0 C0\nG93 G1 C90. F200.\nM30\n",
    );
    let (line, value, axis) = only(&report, Kind::FeedLimited);
    assert_eq!((line, axis), (3, Some('C')));
    assert!((value - 8000.0 * 2f64.sqrt()).abs() < 1e-6, "{value}");
    let message = report.findings[0].message.to_string();
    assert_eq!(
        message,
        "the inverse-time F200 works out to a tip feed of 28284.271 mm/min, which needs C faster than its 7200 deg/min: the tip moves at 11313.708 mm/min at most"
    );
    // In G94 the F word is the tip feed.
    let report = check(
        &machine,
        "",
        "G21 G90 G94\nG0 X100. Y0 Z0 A0 C0\nG1 C90. F20000.\nM30\n",
    );
    assert!(
        report.findings[0]
            .message
            .to_string()
            .starts_with("F20000 needs C faster"),
        "{}",
        report.findings[0].message
    );
}

#[test]
fn inverse_time_feed_takes_one_over_f_minutes() {
    let machine = builtin("trunnion-ac").expect("built in");
    let report = check(&machine, "", "G21 G90 G93\nG1 X30. Y40. F2.\nM30\n");
    // 1/2 min, whatever the length.
    assert!(
        (report.time.programmed - 30.0).abs() < 1e-9,
        "{}",
        report.time.programmed
    );
}
