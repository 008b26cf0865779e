//! Three-dimensional tool compensation (seed 001, FANUC 16/18-C): every
//! rule and alarm of the seed, hand-computed, judged through the rows
//! (forward kinematics of the machine position).

mod common;

use common::builtin_at_zero;
use fiveaxis_control::{Alarm, Row, RunOptions, Runner, SliceSource};
use fiveaxis_machine::{Control, LinearAxis, Machine, Offsets, ToolOffset, Vec3};

const EPS: f64 = 1e-9;

fn mill(control: Control) -> Machine {
    let mut m = builtin_at_zero("mill-3axis").expect("built-in");
    m.control = control;
    m
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
            radius: 3.0,
            radius_wear: -0.5,
            ..ToolOffset::default()
        },
    );
    o
}

/// Rows at the end of every block, and the alarm.
fn run_on(machine: &Machine, program: &str) -> (Vec<Row>, Option<Alarm>) {
    common::run_ends(machine, offsets(), program)
}

fn run(program: &str) -> (Vec<Row>, Option<Alarm>) {
    run_on(&mill(Control::Fanuc16), program)
}

fn tip(row: &Row) -> [f64; 3] {
    [row.tip.x, row.tip.y, row.tip.z]
}

fn assert_close(a: [f64; 3], b: [f64; 3]) {
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() < EPS, "{a:?} != {b:?}");
    }
}

fn code(alarm: &Option<Alarm>) -> String {
    alarm
        .as_ref()
        .map_or_else(|| "none".into(), |a| a.code.to_string())
}

#[test]
fn g41_offsets_by_radius_along_the_normalized_vector() {
    // D1 = 5; (i, j, k) = (3, 0, 4), p = 5: V = (3, 0, 4).
    let (rows, alarm) = run("G41 G1 X10. Y0 Z0 I3. J0 K4. D1 F500.\n");
    assert!(alarm.is_none());
    assert_close(tip(&rows[0]), [13.0, 0.0, 4.0]);
}

#[test]
fn g42_offsets_the_other_way() {
    let (rows, _) = run("G42 G1 X10. Y0 Z0 I3. J0 K4. D1 F500.\n");
    assert_close(tip(&rows[0]), [7.0, 0.0, -4.0]);
}

#[test]
fn parameter_5011_fixes_p_so_the_program_scales_the_vector() {
    // No.5011 = 10: V = 5·(3, 0, 4)/10 = (1.5, 0, 2).
    let mut m = mill(Control::Fanuc16);
    m.params.tool_comp_3d_denominator = 10.0;
    let (rows, _) = run_on(&m, "G41 G1 X10. I3. J0 K4. D1 F500.\n");
    assert_close(tip(&rows[0]), [11.5, 0.0, 2.0]);
}

#[test]
fn blocks_without_ijk_and_arcs_keep_the_vector() {
    let program = "G41 G1 X10. Y0 Z0 I0 J1. K0 D1 F500.\nX20.\nG3 X30. R5.\nG1 X40. I0 J0 K1.\n";
    let (rows, alarm) = run(program);
    assert!(alarm.is_none(), "{alarm:?}");
    assert_close(tip(&rows[0]), [10.0, 5.0, 0.0]);
    assert_close(tip(&rows[1]), [20.0, 5.0, 0.0]);
    // The arc is the programmed one shifted by the kept vector.
    assert_close(tip(&rows[2]), [30.0, 5.0, 0.0]);
    assert_close(tip(&rows[3]), [40.0, 0.0, 5.0]);
}

#[test]
fn omitted_addresses_in_the_mode_count_zero() {
    let (rows, _) = run("G41 G1 X10. I1. J1. K1. D1 F500.\nX20. K2.\n");
    assert_close(tip(&rows[1]), [20.0, 0.0, 5.0]);
}

#[test]
fn g40_cancels_at_the_end_of_its_block() {
    let (rows, _) = run("G41 G1 X10. I0 J0 K1. D1 F500.\nG40 X20.\n");
    assert_close(tip(&rows[1]), [20.0, 0.0, 0.0]);
}

#[test]
fn a_vector_change_alone_moves_the_tool() {
    let (rows, _) = run("G41 G1 X10. I0 J0 K1. D1 F500.\nI1. J0 K0\n");
    assert_eq!(rows.len(), 2);
    assert_close(tip(&rows[1]), [15.0, 0.0, 0.0]);
}

#[test]
fn d_changes_the_radius_from_its_block_on() {
    // D2 = 3 - 0.5.
    let (rows, _) = run("G41 G1 X10. I0 J0 K1. D1 F500.\nX20. D2\n");
    assert_close(tip(&rows[1]), [20.0, 0.0, 2.5]);
}

#[test]
fn length_compensation_applies_after_the_shift() {
    // Machine Z = P + V + H: 0 + 5 + 100.
    let (rows, _) = run("G43 H1 G41 G1 X10. Z0 I0 J0 K1. D1 F500.\n");
    assert!((rows[0].joints[2] - 105.0).abs() < EPS);
    assert_close(tip(&rows[0]), [10.0, 0.0, 5.0]);
}

#[test]
fn reference_return_clears_the_vector_at_the_intermediate_point() {
    let (rows, alarm) = run("G41 G1 X10. Z0 I0 J0 K1. D1 F500.\nG28 Z20.\nG1 X20. I0 J0 K1.\n");
    assert!(alarm.is_none(), "{alarm:?}");
    // The intermediate point is Z20 without the vector.
    let mill = mill(Control::Fanuc16);
    let mut runner = Runner::new(
        &mill,
        offsets(),
        SliceSource::new(b"G41 G1 X10. Z0 I0 J0 K1. D1 F500.\nG28 Z20.\n"),
        RunOptions::default(),
    );
    let _ = runner.next_segment();
    let g28 = runner.next_segment().ok().flatten().expect("G28 segment");
    assert!((g28.row(&mill, 0.5).joints[2] - 20.0).abs() < EPS);
    // After it the mode goes on with the next vector.
    assert_close(tip(&rows[2]), [20.0, 0.0, 5.0]);
}

#[test]
fn reference_check_in_the_mode_lands_offset_and_alarms() {
    // Reference position 1 is machine zero; the check lands at Z 0 + 5.
    let (_, alarm) = run("G41 G1 X0 Y0 Z0 I0 J0 K1. D1 F500.\nG27 Z0\n");
    assert_eq!(code(&alarm), "PS092");
}

#[test]
fn startup_alarms_047_and_048() {
    // Two axes in the same direction: X and a W? The mill has no U, so
    // build one that has it.
    let mut m = mill(Control::Fanuc16);
    m.linear.push(LinearAxis {
        name: 'U',
        min: -100.0,
        max: 100.0,
        dynamics: fiveaxis_machine::Dynamics::LINEAR_DEFAULT,
        along: fiveaxis_machine::Along::Parallel,
    });
    let (_, alarm) = run_on(&m, "G41 G1 X1. U1. I0 J0 K1. D1 F100.\n");
    assert_eq!(code(&alarm), "PS047");
    // A machine without a basic Z (its third axis is W): omitting Z at
    // start-up is P/S 048; naming W is fine.
    let mut m = mill(Control::Fanuc16);
    m.linear[2].name = 'W';
    let (_, alarm) = run_on(&m, "G41 G1 X1. Y1. I0 J0 K1. D1 F100.\n");
    assert_eq!(code(&alarm), "PS048");
    let (_, alarm) = run_on(&m, "G41 G1 X1. Y1. W0 I0 J0 K1. D1 F100.\n");
    assert_eq!(code(&alarm), "none");
}

#[test]
fn codes_forbidden_in_the_mode() {
    for (g, want) in [
        ("G05", "PS178"),
        ("G31 X1.", "PS036"),
        ("G51", "PS141"),
        ("G45 X1.", "PS042"),
        ("G48 X1.", "PS042"),
    ] {
        let (_, alarm) = run(&format!("G41 G1 X1. I0 J0 K1. D1 F100.\n{g}\n"));
        assert_eq!(code(&alarm), want, "{g}");
    }
    // FANUC 30i shows four digits; outside the mode these are unknown codes.
    let (_, alarm) = run_on(
        &mill(Control::Fanuc30i),
        "G41 G1 X1. I0 J0 K1. D1 F100.\nG31 X1.\n",
    );
    assert_eq!(code(&alarm), "PS0036");
    let (_, alarm) = run("G31 X1.\n");
    assert_eq!(code(&alarm), "PS010");
}

#[test]
fn on_a_five_axis_machine_the_vector_is_in_the_programming_frame() {
    // Under TCPC (type 1) on the A/C trunnion, with the table turned C90
    // before start-up: the programming frame is turned with it, and the
    // compensated tip is P + V in that frame, at block ends.
    let m = builtin_at_zero("trunnion-ac").expect("built-in");
    let program = "G0 C90.\nG43.4 H1 X0 Y0 Z0\nG41 G1 X10. Y0 Z0 I1. J0 K0 D1 F500.\n";
    let (rows, alarm) = run_on(&m, program);
    assert!(alarm.is_none(), "{alarm:?}");
    // The programming frame is the work coordinate system frozen onto the
    // table at C90: P + V = (15, 0, 0) there. The part frame (the table at
    // C0) sees it turned back by C90 (axis -Z): T0⁻¹ turns +X into +Y.
    let t0 = m.chain(fiveaxis_machine::Side::Table, &rows[0].joints);
    let want = t0
        .inverse_transform_point(&Vec3::new(15.0, 0.0, 0.0).into())
        .coords;
    assert_close(tip(rows.last().expect("rows")), [want.x, want.y, want.z]);
    assert_close([want.x, want.y, want.z], [0.0, 15.0, 0.0]);
}
