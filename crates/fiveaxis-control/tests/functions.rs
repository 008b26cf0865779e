//! Hand-computed cases for the controller functions, from the FANUC
//! operator's manual descriptions. Tool tips are checked through the rows,
//! which come from forward kinematics, never from the controller's own
//! arithmetic.

mod common;

use common::builtin_at_zero;
use fiveaxis_control::{Alarm, Row, RunError, RunOptions, Runner, SliceSource};
use fiveaxis_machine::{Control, Machine, Offsets, ToolOffset, Vec3};

const EPS: f64 = 1e-9;

fn machine(name: &str) -> Machine {
    builtin_at_zero(name).expect("built-in machine")
}

fn offsets() -> Offsets {
    let mut o = Offsets::default();
    o.tools.insert(
        1,
        ToolOffset {
            length: 100.0,
            radius: 5.0,
            ..ToolOffset::default()
        },
    );
    o.tools.insert(
        2,
        ToolOffset {
            length: 50.0,
            length_wear: -0.5,
            ..ToolOffset::default()
        },
    );
    o.work[1] = Vec3::new(100.0, 0.0, -50.0);
    o.extended_work[1] = Vec3::new(10.0, 20.0, 30.0);
    o
}

struct Run {
    rows: Vec<Row>,
    alarm: Option<Alarm>,
}

/// Runs `program`, sampling each segment at `samples` equal steps.
fn run_sampled(
    program: &str,
    machine: &Machine,
    offsets: Offsets,
    options: RunOptions,
    samples: u32,
) -> Run {
    let mut runner = Runner::new(
        machine,
        offsets,
        SliceSource::new(program.as_bytes()),
        options,
    );
    let mut rows = Vec::new();
    loop {
        match runner.next_segment() {
            Ok(Some(seg)) => {
                for i in 1..=samples {
                    rows.push(seg.row(machine, f64::from(i) / f64::from(samples)));
                }
            }
            Ok(None) => return Run { rows, alarm: None },
            Err(RunError::Alarm { alarm, .. }) => {
                return Run {
                    rows,
                    alarm: Some(alarm),
                };
            }
            Err(e) => panic!("io error {e}"),
        }
    }
}

fn run_on(program: &str, machine: &Machine) -> Run {
    run_sampled(program, machine, offsets(), RunOptions::default(), 1)
}

fn run(program: &str) -> Run {
    run_on(program, &machine("trunnion-ac"))
}

fn ends(run: &Run) -> Vec<[f64; 5]> {
    assert!(run.alarm.is_none(), "unexpected alarm {:?}", run.alarm);
    run.rows
        .iter()
        .map(|r| {
            [
                r.joints[0],
                r.joints[1],
                r.joints[2],
                r.joints[3],
                r.joints[4],
            ]
        })
        .collect()
}

fn assert_close(a: &[f64], b: &[f64]) {
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert!((x - y).abs() < EPS, "{a:?} != {b:?}");
    }
}

fn alarm_code(run: &Run) -> String {
    run.alarm
        .as_ref()
        .map(|a| a.code.to_string())
        .unwrap_or_else(|| "none".into())
}

#[test]
fn decimal_point_rule_counts_plain_integers_in_least_increments() {
    let r = run("G0 X10 Y10. Z-5\n");
    assert_close(&ends(&r)[0], &[0.01, 10.0, -0.005, 0.0, 0.0]);
    assert_eq!(r.rows[0].motion.name(), "rapid");
}

#[test]
fn calculator_input_parameter_takes_integers_as_millimetres() {
    let mut m = machine("trunnion-ac");
    m.params.decimal_point_input = true;
    let r = run_on("G0 X10 A-5\n", &m);
    assert_close(&ends(&r)[0], &[10.0, 0.0, 0.0, -5.0, 0.0]);
}

#[test]
fn inch_input_is_converted_to_millimetres() {
    let r = run("G20 G0 X1. Y10000\n");
    assert_close(&ends(&r)[0], &[25.4, 25.4, 0.0, 0.0, 0.0]);
}

#[test]
fn incremental_and_absolute_moves() {
    let r = run("G0 X10. Y10.\nG91 X5. Y-2.\nG90 X1.\n");
    let e = ends(&r);
    assert_close(&e[1], &[15.0, 8.0, 0.0, 0.0, 0.0]);
    assert_close(&e[2], &[1.0, 8.0, 0.0, 0.0, 0.0]);
}

#[test]
fn work_offsets_shift_machine_positions_and_tip_stays_in_part_frame() {
    let r = run("G55 G0 X0 Y0 Z0\nG54.1 P2 X1. Y0 Z0\nG54 P2 Y1.\nG54 X0 Y0 Z0\n");
    let e = ends(&r);
    assert_close(&e[0], &[100.0, 0.0, -50.0, 0.0, 0.0]);
    assert_close(&e[1], &[11.0, 20.0, 30.0, 0.0, 0.0]);
    assert_close(&e[2], &[11.0, 21.0, 30.0, 0.0, 0.0]);
    assert_close(r.rows[0].tip.as_slice(), &[0.0, 0.0, 0.0]);
    assert_close(r.rows[1].tip.as_slice(), &[1.0, 0.0, 0.0]);
    // An axis the block does not name does not move when the work
    // coordinate system changes.
    let e = ends(&run("G55 G0 X0 Y0 Z0\nG54.1 P2 X1.\n"));
    assert_close(&e[1], &[11.0, 0.0, -50.0, 0.0, 0.0]);
}

#[test]
fn g10_sets_work_and_tool_offsets() {
    let r = run(
        "G10 L2 P1 X5. Y6. Z7.\nG0 X0 Y0 Z0\nG91 G10 L2 P1 X1.\nG90 G0 X0\nG10 L20 P3 X-1.\nG54.1 P3 G0 X0\n",
    );
    let e = ends(&r);
    assert_close(&e[0], &[5.0, 6.0, 7.0, 0.0, 0.0]);
    assert_close(&e[1], &[6.0, 6.0, 7.0, 0.0, 0.0]);
    // G54.1 P3 was all zero but X, set to -1.
    assert_close(&e[2], &[-1.0, 6.0, 7.0, 0.0, 0.0]);

    let r = run("G10 L10 P5 R20.\nG10 L11 P5 R-1.\nG43 H5 G0 Z0\n");
    assert_close(&ends(&r)[0], &[0.0, 0.0, 19.0, 0.0, 0.0]);
    assert_eq!(alarm_code(&run("G10 L2 P7 X1.\n")), "PS0031");
    assert_eq!(alarm_code(&run("G10 L20 P49 X1.\n")), "PS0031");
    assert_eq!(alarm_code(&run("G10 L3 P1 X1.\n")), "FX0042");
}

#[test]
fn tool_length_compensation_plus_minus_and_cancel_move_the_axis() {
    let r = run("G43 H1 G0 Z50.\nG49\nG44 H1 Z50.\nG43 H2\n");
    let e = ends(&r);
    assert_close(&e[0], &[0.0, 0.0, 150.0, 0.0, 0.0]);
    // G49 alone takes the offset away: the axis moves down by H.
    assert_close(&e[1], &[0.0, 0.0, 50.0, 0.0, 0.0]);
    assert_close(&e[2], &[0.0, 0.0, -50.0, 0.0, 0.0]);
    // H2 = 50 - 0.5 (geometry + wear).
    assert_close(&e[3], &[0.0, 0.0, 99.5, 0.0, 0.0]);
    // With G43 the reported tip is the programmed point.
    assert_close(r.rows[0].tip.as_slice(), &[0.0, 0.0, 50.0]);
    assert_close(r.rows[3].tip.as_slice(), &[0.0, 0.0, 50.0]);
}

#[test]
fn length_compensation_along_tool_axis_puts_the_tip_on_the_programmed_point() {
    // Head-head C/A with a pivot 150 above the gauge point: forward
    // kinematics of the machine position must give the programmed tip.
    let m = machine("head-head-ca");
    let r = run_on(
        "G0 A30. C45.\nG43.1 H1 X10. Y20. Z30.\nX-5. A-20. C10.\n",
        &m,
    );
    assert!(r.alarm.is_none(), "{:?}", r.alarm);
    assert_close(r.rows[1].tip.as_slice(), &[10.0, 20.0, 30.0]);
    assert_close(r.rows[2].tip.as_slice(), &[-5.0, 20.0, 30.0]);
    // The tool direction is the head's: A30 about +X from +Z, then C45.
    let a = 30f64.to_radians();
    let c = 45f64.to_radians();
    let dir = [a.sin() * c.sin(), -a.sin() * c.cos(), a.cos()];
    assert_close(r.rows[1].dir.as_slice(), &dir);
}

#[test]
fn full_circle_with_center_words_turns_clockwise() {
    let m = machine("trunnion-ac");
    let r = run_sampled(
        "G0 X10. Y0\nG2 I-10. F100.\n",
        &m,
        offsets(),
        RunOptions::default(),
        4,
    );
    assert!(r.alarm.is_none());
    let arc = &r.rows[4..];
    // Quarter steps clockwise from (10, 0): (0,-10), (-10,0), (0,10), (10,0).
    let expected = [[0.0, -10.0], [-10.0, 0.0], [0.0, 10.0], [10.0, 0.0]];
    for (row, xy) in arc.iter().zip(expected) {
        assert!(
            (row.tip.x - xy[0]).abs() < 1e-9 && (row.tip.y - xy[1]).abs() < 1e-9,
            "{:?}",
            row.tip
        );
        assert_eq!(row.motion.name(), "cw");
        assert_eq!(row.feed, Some(100.0));
    }
}

#[test]
fn radius_arcs_take_the_minor_or_major_arc_by_sign() {
    let m = machine("trunnion-ac");
    let half = 1.0 - std::f64::consts::FRAC_1_SQRT_2;
    let r = run_sampled(
        "G0 X0 Y0\nG2 X10. Y10. R10. F100.\n",
        &m,
        offsets(),
        RunOptions::default(),
        2,
    );
    // Centre (10, 0); half way at 135 degrees.
    assert_close(
        &[r.rows[0].tip.x, r.rows[0].tip.y],
        &[10.0 - 10.0 * (1.0 - half), 10.0 * (1.0 - half)],
    );
    let r = run_sampled(
        "G0 X0 Y0\nG2 X10. Y10. R-10. F100.\n",
        &m,
        offsets(),
        RunOptions::default(),
        2,
    );
    // Centre (0, 10); 270 degrees clockwise from -90: half way at 135.
    let (x, y) = (
        10.0 * (135f64).to_radians().cos(),
        10.0 + 10.0 * (135f64).to_radians().sin(),
    );
    assert_close(&[r.rows[0].tip.x, r.rows[0].tip.y], &[x, y]);
}

#[test]
fn helical_arc_and_zx_plane_direction() {
    let m = machine("trunnion-ac");
    let r = run_sampled(
        "G0 X10. Y0 Z0\nG3 X-10. Z-4. I-10. F100.\n",
        &m,
        offsets(),
        RunOptions::default(),
        2,
    );
    assert_close(r.rows[2].tip.as_slice(), &[0.0, 10.0, -2.0]);
    // G18: from X10 to Z10 about the origin, clockwise seen from +Y.
    let r = run_sampled(
        "G18 G0 X10. Z0\nG2 X0 Z10. I-10. F100.\n",
        &m,
        offsets(),
        RunOptions::default(),
        2,
    );
    let h = 10.0 * std::f64::consts::FRAC_1_SQRT_2;
    assert_close(r.rows[2].tip.as_slice(), &[h, 0.0, h]);
}

#[test]
fn arc_alarms() {
    assert_eq!(
        alarm_code(&run("G0 X0 Y0\nG2 X10. Y0 I4. F100.\n")),
        "PS0020"
    );
    assert_eq!(alarm_code(&run("G0 X0 Y0\nG2 X10. Y0 F100.\n")), "PS0022");
    assert_eq!(
        alarm_code(&run("G0 X0 Y0\nG2 X10. Y0 R2. F100.\n")),
        "PS0020"
    );
}

#[test]
fn reference_returns_pass_the_intermediate_point() {
    let mut m = machine("trunnion-ac");
    m.params.reference_2 = [1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let r = run_sampled(
        "G0 X50. Y40. Z30.\nG28 X10. Y10.\nG30 Z5.\n",
        &m,
        offsets(),
        RunOptions::default(),
        2,
    );
    assert!(r.alarm.is_none(), "{:?}", r.alarm);
    // s = 0.5 is the intermediate point, s = 1 the reference position;
    // Z, not named, stays.
    assert_close(&r.rows[2].joints[..3], &[10.0, 10.0, 30.0]);
    assert_close(&r.rows[3].joints[..3], &[0.0, 0.0, 30.0]);
    assert_close(&r.rows[4].joints[..3], &[0.0, 0.0, 5.0]);
    assert_close(&r.rows[5].joints[..3], &[0.0, 0.0, 3.0]);
    assert_eq!(alarm_code(&run("G30 P3 Z0\n")), "FX0061");
}

#[test]
fn reference_position_return_check() {
    let r = run("G0 X10.\nG27 X0\n");
    assert!(r.alarm.is_none());
    let r = run("G0 X10.\nG27 X5.\n");
    assert_eq!(alarm_code(&r), "PS0092");
    assert_eq!(r.rows.len(), 1, "no row from the failing block");
    // With a length offset active the tool lands off the reference.
    assert_eq!(alarm_code(&run("G43 H1\nG27 Z0\n")), "PS0092");
}

#[test]
fn machine_coordinates_and_coordinate_system_setting() {
    let r = run("G55 G0 X0 Z0\nG53 X1. Y2.\nG0 X0\nG92 X0\nG0 X5.\n");
    let e = ends(&r);
    assert_close(&e[1], &[1.0, 2.0, -50.0, 0.0, 0.0]);
    assert_close(&e[2], &[100.0, 2.0, -50.0, 0.0, 0.0]);
    assert_close(&e[3], &[105.0, 2.0, -50.0, 0.0, 0.0]);
}

#[test]
fn rollover_axis_takes_the_short_way() {
    let m = machine("trunnion-ac");
    let program = "G0 C350.\nC10.\nG91 C-30.\nG90 C180.\nG91 C720.\n";
    let r = run_sampled(program, &m, offsets(), RunOptions::default(), 2);
    assert!(r.alarm.is_none());
    let c: Vec<f64> = r.rows.iter().map(|row| row.joints[4]).collect();
    // Block ends stay exactly as programmed, in [0, 360); half way shows
    // the way taken: -10, +20, -30, then +160 (shorter than -200), then
    // two whole turns (an increment is travelled as given).
    assert_eq!(c[1], 350.0);
    assert_eq!(c[3], 10.0);
    assert_eq!(c[5], 340.0);
    assert_eq!(c[7], 180.0);
    assert_eq!(c[9], 180.0);
    assert_close(
        &[c[0], c[2], c[4], c[6], c[8]],
        &[355.0, 0.0, 355.0, 260.0, -180.0],
    );
}

#[test]
fn subprograms_with_repeats_and_returns() {
    let program =
        "O0001\nG0 X0\nM98 P1000 L3\nM98 P21000\nG0 Y1.\nM30\nO1000\nG91 X1.\nG90\nM99\n%\n";
    let r = run(program);
    let e = ends(&r);
    // G0 X0 does not move; three calls, then two, each X+1.
    assert_eq!(e.len(), 6);
    assert_close(&e[4], &[5.0, 0.0, 0.0, 0.0, 0.0]);
    assert_close(&e[5], &[5.0, 1.0, 0.0, 0.0, 0.0]);
    assert_eq!(r.rows[5].line, 5);
    assert_eq!(r.rows[0].line, 8);
}

#[test]
fn subprogram_alarms() {
    assert_eq!(alarm_code(&run("M98 P42\nM30\n")), "PS0078");
    assert_eq!(alarm_code(&run("M98\n")), "PS0076");
    assert_eq!(alarm_code(&run("M98 P1\nM30\nO1\nM98 P1\nM99\n")), "PS0077");
    let mut m = machine("trunnion-ac");
    m.control = Control::Fanuc16;
    assert_eq!(
        alarm_code(&run_on("M98 P1\nM30\nO1\nM98 P1\nM99\n", &m)),
        "PS077"
    );
}

#[test]
fn return_to_a_sequence_number() {
    let r = run("M98 P7\nG0 X1.\nN20 G0 Y2.\nM30\nO7\nM99 P20\n");
    let e = ends(&r);
    assert_eq!(e.len(), 1);
    assert_close(&e[0], &[0.0, 2.0, 0.0, 0.0, 0.0]);
}

#[test]
fn block_delete_switch() {
    let m = machine("trunnion-ac");
    let program = "G0 X1.\n/G0 X2.\n";
    let off = run_sampled(
        program,
        &m,
        offsets(),
        RunOptions {
            block_delete: false,
            ..RunOptions::default()
        },
        1,
    );
    let on = run_sampled(
        program,
        &m,
        offsets(),
        RunOptions {
            block_delete: true,
            ..RunOptions::default()
        },
        1,
    );
    assert_eq!(off.rows.len(), 2);
    assert_eq!(on.rows.len(), 1);
}

#[test]
fn soft_limits_stop_before_the_move() {
    let r = run("G0 X10.\nG1 X600. F100.\n");
    assert_eq!(alarm_code(&r), "OT0500");
    assert_eq!(r.rows.len(), 1);
    assert_eq!(r.alarm.as_ref().map(|a| a.line), Some(2));
    assert_eq!(alarm_code(&run("G0 Z-301.\n")), "OT0501");
    assert_eq!(alarm_code(&run("G0 A31.\n")), "OT0500");
    // Both end points inside, the arc bulges out past X 500.
    assert_eq!(
        alarm_code(&run("G0 X490. Y-10.\nG3 Y10. R-15. F100.\n")),
        "OT0500"
    );
    // The intermediate point of G28 is checked too.
    assert_eq!(alarm_code(&run("G28 X700.\n")), "OT0500");
}

#[test]
fn codes_and_words_the_kernel_does_not_have_stop_with_an_alarm() {
    assert_eq!(alarm_code(&run("G12.1\n")), "PS0010");
    assert_eq!(alarm_code(&run("G0 B10.\n")), "PS0009");
    assert_eq!(alarm_code(&run("M428\n")), "FX0011");
    assert_eq!(alarm_code(&run("G1 X1. F100. P5\n")), "FX0012");
    assert_eq!(alarm_code(&run("G0 X1. X2.\n")), "PS0009");
    assert_eq!(alarm_code(&run("#34=5\n")), "PS0115");
    let mut m = machine("trunnion-ac");
    m.control = Control::Mitsubishi;
    assert_eq!(alarm_code(&run_on("G12.1\n", &m)), "P34");
}

#[test]
fn feed_modes() {
    assert_eq!(alarm_code(&run("G1 X1.\n")), "PS0011");
    assert_eq!(alarm_code(&run("G93 G1 X1. F2.\nX2.\n")), "PS0011");
    let r = run("G93 G1 X10. F2.\n");
    assert_eq!(r.rows[0].feed, Some(20.0));
    assert_eq!(alarm_code(&run("G95 G1 X1. F0.1\n")), "FX0021");
    let r = run("S1000 M3\nG95 G1 X1. F0.1\n");
    assert!((r.rows[0].feed.unwrap_or(0.0) - 100.0).abs() < 1e-9);
    let r = run("G20 G1 X1. F10.\n");
    assert!((r.rows[0].feed.unwrap_or(0.0) - 254.0).abs() < 1e-9);
}

#[test]
fn dwell_and_program_end() {
    let r = run("G4 P500\nG4 X1.5\nG0 X1.\nM30\nG0 X2.\n");
    assert_eq!(ends(&r).len(), 1);
    assert_eq!(alarm_code(&run("G4\n")), "PS0005");
}

#[test]
fn tape_marks_and_a_following_program_end_the_main_program() {
    let r = run("%\nO100\nG0 X1.\n%\nG0 X2.\n");
    assert_eq!(ends(&r).len(), 1);
    let r = run("O100\nG0 X1.\nO200\nG0 X2.\n");
    assert_eq!(ends(&r).len(), 1);
}

/// The message of the alarm that stopped `run`.
fn alarm_message(run: &Run) -> String {
    run.alarm
        .as_ref()
        .map(|a| a.message.clone())
        .unwrap_or_default()
}

#[test]
fn messages_say_what_is_wrong() {
    // The range of an offset number is the offset memory's, not u32's.
    let r = run("G43 H-1\n");
    assert_eq!(alarm_code(&r), "PS0030");
    assert!(
        alarm_message(&r).contains("0 to 999"),
        "{}",
        alarm_message(&r)
    );
    // Centre words given as zero are not "missing".
    let r = run("G2 X10. I0 J0 F100.\n");
    assert_eq!(alarm_code(&r), "PS0022");
    assert!(
        alarm_message(&r).contains("radius is 0"),
        "{}",
        alarm_message(&r)
    );
    let r = run("G2 X10. F100.\n");
    assert!(alarm_message(&r).contains("needs R or the centre words"));
    // G04 X is range-checked like G04 P (FANUC: at most 99999.999 s).
    assert_eq!(alarm_code(&run("G4 X99999999999999.\n")), "FX0014");
    assert_eq!(alarm_code(&run("G4 X-1.\n")), "FX0014");
    assert_eq!(alarm_code(&run("G4 X99999.999\n")), "none");
    // Without a decimal point X counts least input increments: 1.5 s.
    assert_eq!(alarm_code(&run("G4 X1500\n")), "none");
}
