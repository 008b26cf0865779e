//! Program transforms of the FANUC 30i (G52, G16/G15, G51.1/G50.1,
//! G51/G50, G68/G69): hand-computed end points (rotation matrices in
//! closed form), arcs, incremental moves and the restriction alarms. Tool
//! tips come from the rows (forward kinematics).

use fiveaxis_control::{Alarm, Motion, Row, RunError, RunOptions, Runner, SliceSource};
use fiveaxis_machine::{Machine, Offsets, ToolOffset, builtin};

const EPS: f64 = 1e-9;

fn machine(name: &str) -> Machine {
    builtin(name).expect("built-in machine")
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
    o
}

/// Rows of every segment sampled at `samples`, and the alarm.
fn run_on(program: &str, machine: &Machine, samples: &[f64]) -> (Vec<Row>, Option<Alarm>) {
    let mut runner = Runner::new(
        machine,
        offsets(),
        SliceSource::new(program.as_bytes()),
        RunOptions::default(),
    );
    let mut rows = Vec::new();
    loop {
        match runner.next_segment() {
            Ok(Some(seg)) => rows.extend(samples.iter().map(|&s| seg.row(machine, s))),
            Ok(None) => return (rows, None),
            Err(RunError::Alarm { alarm, .. }) => return (rows, Some(alarm)),
            Err(e) => panic!("io error {e}"),
        }
    }
}

/// End rows on the three-axis mill; no alarm expected.
fn run(program: &str) -> Vec<Row> {
    let (rows, alarm) = run_on(program, &machine("mill-3axis"), &[1.0]);
    assert!(alarm.is_none(), "unexpected alarm {alarm:?}");
    rows
}

/// The alarm code and line of a program on `name`.
fn alarm(program: &str, name: &str) -> (String, u32) {
    let (_, alarm) = run_on(program, &machine(name), &[1.0]);
    let alarm = alarm.expect("an alarm");
    (alarm.code.to_string(), alarm.line)
}

/// The tip of the last row of line `line`.
fn tip(rows: &[Row], line: u32) -> [f64; 3] {
    let row = rows
        .iter()
        .rfind(|r| r.line == line)
        .unwrap_or_else(|| panic!("no row of line {line}"));
    [row.tip.x, row.tip.y, row.tip.z]
}

fn near(a: [f64; 3], b: [f64; 3]) {
    assert!(
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < EPS),
        "{a:?} is not {b:?}"
    );
}

const START: &str = "G90 G17 G00 X0 Y0 Z0\n";

fn program(body: &str) -> String {
    format!("{START}{body}")
}

// ----- coordinate system rotation ------------------------------------------

#[test]
fn g68_rotates_about_the_given_centre() {
    // (20, 0) about (10, 0) by 90°: (10 + 0, 0 + 10).
    let rows = run(&program("G68 X10. Y0 R90.\nG01 X20. Y0 F100.\nG69 X0 Y0\n"));
    near(tip(&rows, 3), [10.0, 10.0, 0.0]);
    // The G68 block does not move.
    assert!(rows.iter().all(|r| r.line != 2));
    // G69 in a block with a move: the move is not rotated.
    near(tip(&rows, 4), [0.0, 0.0, 0.0]);
}

#[test]
fn g68_by_an_arbitrary_angle_is_the_rotation_matrix() {
    let a = 30.0f64.to_radians();
    let rows = run(&program("G68 X0 Y0 R30.\nG01 X10. Y5. Z-1. F100.\n"));
    near(
        tip(&rows, 3),
        [
            10.0 * a.cos() - 5.0 * a.sin(),
            10.0 * a.sin() + 5.0 * a.cos(),
            -1.0,
        ],
    );
}

#[test]
fn g68_without_centre_turns_about_the_tool_position() {
    let rows = run(&program("G00 X5. Y5.\nG68 R90.\nG01 X15. Y5. F100.\n"));
    near(tip(&rows, 4), [5.0, 15.0, 0.0]);
}

#[test]
fn g68_incremental_moves_turn_and_g91_r_adds_to_the_angle() {
    let rows = run(&program(
        "G68 X0 Y0 R30.\nG91 G01 X10. F100.\nG90 G69 G00 X0 Y0\nG68 R30.\nG91 G68 R15.\nG90 G01 X10. Y0\n",
    ));
    let a = 30.0f64.to_radians();
    near(tip(&rows, 3), [10.0 * a.cos(), 10.0 * a.sin(), 0.0]);
    let b = 45.0f64.to_radians();
    near(tip(&rows, 7), [10.0 * b.cos(), 10.0 * b.sin(), 0.0]);
}

#[test]
fn g68_in_g18_turns_the_z_x_plane() {
    // G18: first axis Z, second X; +90° takes +Z to +X.
    let rows = run(&program("G18\nG68 X0 Z0 R90.\nG01 Z10. X0 F100.\n"));
    near(tip(&rows, 4), [10.0, 0.0, 0.0]);
}

#[test]
fn an_arc_turns_with_the_rotation() {
    // Unrotated: CW half circle (0,0) → (10,0) about (5,0), through (5,5).
    // Turned by 90° about the zero: ends at (0,10), through (-5,5).
    let (rows, alarm) = run_on(
        &program("G68 X0 Y0 R90.\nG02 X10. Y0 I5. J0 F100.\n"),
        &machine("mill-3axis"),
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let arc: Vec<&Row> = rows.iter().filter(|r| r.line == 3).collect();
    near([arc[0].tip.x, arc[0].tip.y, arc[0].tip.z], [-5.0, 5.0, 0.0]);
    near([arc[1].tip.x, arc[1].tip.y, arc[1].tip.z], [0.0, 10.0, 0.0]);
    assert_eq!(arc[1].motion, Motion::Cw);
}

// ----- programmable mirror image --------------------------------------------

#[test]
fn g51_1_mirrors_about_the_given_position() {
    let rows = run(&program(
        "G51.1 X10.\nG01 X15. Y3. F100.\nG91 X2.\nG90 G50.1 X0\nX15. Y3.\n",
    ));
    near(tip(&rows, 3), [5.0, 3.0, 0.0]);
    near(tip(&rows, 4), [3.0, 3.0, 0.0]);
    assert!(rows.iter().all(|r| r.line != 2 && r.line != 5));
    near(tip(&rows, 6), [15.0, 3.0, 0.0]);
}

#[test]
fn a_mirrored_arc_changes_direction() {
    let (rows, alarm) = run_on(
        &program("G51.1 X0\nG02 X10. Y0 I5. F100.\n"),
        &machine("mill-3axis"),
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let arc: Vec<&Row> = rows.iter().filter(|r| r.line == 3).collect();
    near([arc[0].tip.x, arc[0].tip.y, arc[0].tip.z], [-5.0, 5.0, 0.0]);
    near(
        [arc[1].tip.x, arc[1].tip.y, arc[1].tip.z],
        [-10.0, 0.0, 0.0],
    );
    assert_eq!(arc[1].motion, Motion::Ccw);
}

#[test]
fn mirroring_both_axes_keeps_the_arc_direction() {
    let (rows, _) = run_on(
        &program("G51.1 X0 Y0\nG02 X10. Y0 R5. F100.\n"),
        &machine("mill-3axis"),
        &[0.5, 1.0],
    );
    let arc: Vec<&Row> = rows.iter().filter(|r| r.line == 3).collect();
    near(
        [arc[0].tip.x, arc[0].tip.y, arc[0].tip.z],
        [-5.0, -5.0, 0.0],
    );
    assert_eq!(arc[1].motion, Motion::Cw);
}

#[test]
fn cutter_compensation_under_a_mirror_image_is_the_mirror_of_the_path() {
    let body = "G01 G41 D1 X20. Y10. F100.\nX40.\nG03 X50. Y20. R10.\nG01 Y30.\nG02 X40. Y40. I-10.\nG01 G40 X0 Y0\n";
    let m = machine("mill-3axis");
    let (plain, a1) = run_on(&format!("{START}G00 X0 Y0\n{body}"), &m, &[0.5, 1.0]);
    let (mirrored, a2) = run_on(&format!("{START}G51.1 X0\n{body}"), &m, &[0.5, 1.0]);
    assert!(a1.is_none() && a2.is_none(), "{a1:?} {a2:?}");
    assert_eq!(plain.len(), mirrored.len());
    for (a, b) in plain.iter().zip(&mirrored).skip(2) {
        near([-a.tip.x, a.tip.y, a.tip.z], [b.tip.x, b.tip.y, b.tip.z]);
        let flipped = match a.motion {
            Motion::Cw => Motion::Ccw,
            Motion::Ccw => Motion::Cw,
            m => m,
        };
        assert_eq!(b.motion, flipped);
    }
}

// ----- scaling ----------------------------------------------------------------

#[test]
fn g51_p_scales_all_axes_about_the_centre() {
    // P2000 = 2.0; P0.5 with a decimal point = 0.5.
    let rows = run(&program(
        "G51 X0 Y0 Z0 P2000\nG01 X5. Y3. Z-1. F100.\nG50\nG51 X10. Y10. Z0 P0.5\nX20. Y0 Z0\nG50\n",
    ));
    near(tip(&rows, 3), [10.0, 6.0, -2.0]);
    assert!(rows.iter().all(|r| r.line != 2 && r.line != 5));
    near(tip(&rows, 6), [15.0, 5.0, 0.0]);
}

#[test]
fn g51_i_j_k_scale_each_axis_and_a_negative_factor_mirrors() {
    let rows = run(&program(
        "G51 X10. Y0 Z0 I-1000 J2000\nG01 X15. Y3. F100.\nG91 X1. Y1.\n",
    ));
    near(tip(&rows, 3), [5.0, 6.0, 0.0]);
    near(tip(&rows, 4), [4.0, 8.0, 0.0]);
}

#[test]
fn an_r_arc_scales_with_p() {
    let (rows, alarm) = run_on(
        &program("G51 X0 Y0 P2000\nG02 X10. Y0 R5. F100.\n"),
        &machine("mill-3axis"),
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let arc: Vec<&Row> = rows.iter().filter(|r| r.line == 3).collect();
    near(
        [arc[0].tip.x, arc[0].tip.y, arc[0].tip.z],
        [10.0, 10.0, 0.0],
    );
    near([arc[1].tip.x, arc[1].tip.y, arc[1].tip.z], [20.0, 0.0, 0.0]);
}

#[test]
fn an_arc_under_unequal_scaling_is_refused() {
    let (code, line) = alarm(
        &program("G51 X0 Y0 I1000 J2000\nG02 X10. Y0 R5. F100.\n"),
        "mill-3axis",
    );
    assert_eq!((code.as_str(), line), ("FX0144", 3));
}

// ----- combined -------------------------------------------------------------

#[test]
fn mirror_then_scaling_then_rotation() {
    // (1, 2) → mirror X0: (-1, 2) → ×2: (-2, 4) → +90°: (-4, -2).
    let rows = run(&program(
        "G51.1 X0\nG51 X0 Y0 P2000\nG68 X0 Y0 R90.\nG01 X1. Y2. F100.\nG69\nG50\nG50.1 X0\nX1. Y2.\n",
    ));
    near(tip(&rows, 5), [-4.0, -2.0, 0.0]);
    near(tip(&rows, 9), [1.0, 2.0, 0.0]);
}

#[test]
fn the_rotation_centre_is_scaled() {
    // Centre (5, 0) scaled: (10, 0); the point (5, 1) scaled: (10, 2);
    // turned by 90° about (10, 0): (8, 0).
    let rows = run(&program(
        "G51 X0 Y0 P2000\nG68 X5. Y0 R90.\nG01 X5. Y1. F100.\n",
    ));
    near(tip(&rows, 4), [8.0, 0.0, 0.0]);
}

#[test]
fn canned_cycle_holes_turn_with_the_rotation() {
    let rows = run(&program(
        "Z10.\nG68 X0 Y0 R90.\nG81 X10. Y0 Z-5. R2. F100.\nG80\n",
    ));
    let holes: Vec<&Row> = rows.iter().filter(|r| r.line == 4).collect();
    near(
        [holes[0].tip.x, holes[0].tip.y, holes[0].tip.z],
        [0.0, 10.0, 10.0],
    );
    assert!(holes.iter().any(|r| (r.tip.z + 5.0).abs() < EPS));
}

// ----- polar coordinates ----------------------------------------------------

#[test]
fn g16_radius_and_angle_about_the_work_zero() {
    let a = 30.0f64.to_radians();
    let rows = run(&program(
        "G16\nG01 X10. Y30. F100.\nG91 Y60.\nG90 Y-90.\nG15 X1. Y1.\n",
    ));
    near(tip(&rows, 3), [10.0 * a.cos(), 10.0 * a.sin(), 0.0]);
    // G91 angle: 30° + 60° at the same radius.
    near(tip(&rows, 4), [0.0, 10.0, 0.0]);
    near(tip(&rows, 5), [0.0, -10.0, 0.0]);
    near(tip(&rows, 6), [1.0, 1.0, 0.0]);
}

#[test]
fn g16_incremental_radius_puts_the_pole_at_the_current_position() {
    // From (10, 0): angle 0 + 90°, 5 long from the current position.
    let rows = run(&program("G01 X10. Y0 F100.\nG16 G91 X5. Y90.\n"));
    near(tip(&rows, 3), [10.0, 5.0, 0.0]);
}

#[test]
fn g16_bolt_circle_with_a_canned_cycle() {
    let rows = run(&program(
        "Z10.\nG16\nG81 X50. Y0 Z-5. R2. F100.\nG91 Y120.\nY120.\nG80 G90 G15\n",
    ));
    for (line, deg) in [(4u32, 0.0f64), (5, 120.0), (6, 240.0)] {
        let first = rows.iter().find(|r| r.line == line).expect("hole");
        let a = deg.to_radians();
        near(
            [first.tip.x, first.tip.y, first.tip.z],
            [50.0 * a.cos(), 50.0 * a.sin(), 10.0],
        );
    }
}

// ----- local coordinate system ----------------------------------------------

#[test]
fn g52_shifts_the_program_zero() {
    let rows = run(&program(
        "G52 X10. Y20.\nG00 X1. Y1.\nG55\nX1. Y1.\nG54 G52 X0 Y0\nX1. Y1.\n",
    ));
    near(tip(&rows, 3), [11.0, 21.0, 0.0]);
    near(tip(&rows, 7), [1.0, 1.0, 0.0]);
}

#[test]
fn g52_holds_across_work_systems() {
    let mut o = offsets();
    o.work[1] = fiveaxis_machine::Vec3::new(100.0, 0.0, 0.0);
    let m = machine("mill-3axis");
    let text = program("G52 X10.\nG55 X1. Y0\n");
    let mut runner = Runner::new(
        &m,
        o,
        SliceSource::new(text.as_bytes()),
        RunOptions::default(),
    );
    let mut last = None;
    while let Ok(Some(seg)) = runner.next_segment() {
        last = Some(seg.end);
    }
    let end = last.expect("a move");
    assert!((end[0] - 111.0).abs() < EPS, "{end:?}");
}

// ----- restrictions ---------------------------------------------------------

#[test]
fn the_plane_cannot_change_in_g68() {
    assert_eq!(
        alarm(&program("G68 X0 Y0 R10.\nG18\n"), "mill-3axis"),
        ("PS0144".into(), 3)
    );
}

#[test]
fn reference_returns_and_coordinate_changes_are_refused_in_the_transforms() {
    for (mode, code) in [
        ("G68 X0 Y0 R10.", "G28 Z0"),
        ("G51 X0 Y0 P2000", "G30 Z0"),
        ("G51.1 X0", "G92 X0"),
        ("G68 X0 Y0 R10.", "G55"),
        ("G68 X0 Y0 R10.", "G52 X1."),
    ] {
        let (c, line) = alarm(&program(&format!("{mode}\n{code}\n")), "mill-3axis");
        assert_eq!((c.as_str(), line), ("FX0141", 3), "{mode} / {code}");
    }
}

#[test]
fn the_transforms_nest() {
    for text in [
        "G68 X0 Y0 R10.\nG51 X0 Y0 P2000\n",
        "G51 X0 Y0 P2000\nG51.1 X0\n",
        "G51 X0 Y0 P2000\nG68 X0 Y0 R10.\nG50\n",
        "G51.1 X0\nG68 X0 Y0 R10.\nG50.1 X0\n",
    ] {
        let (code, _) = alarm(&program(text), "mill-3axis");
        assert_eq!(code, "FX0142", "{text}");
    }
}

#[test]
fn two_transforms_with_centres_in_one_block_conflict() {
    let (code, _) = alarm(&program("G51 G68 X0 Y0 R10. P2000\n"), "mill-3axis");
    assert_eq!(code, "PS0010");
}

#[test]
fn transforms_are_refused_under_tcpc() {
    let (code, line) = alarm(
        "G90 G00 X0 Y0 Z100.\nG43.4 H1\nG68 X0 Y0 R10.\n",
        "trunnion-bc",
    );
    assert_eq!((code.as_str(), line), ("FX0143", 3));
    let (code, line) = alarm(
        "G90 G00 X0 Y0 Z100.\nG68 X0 Y0 R10.\nG43.4 H1\n",
        "trunnion-bc",
    );
    assert_eq!((code.as_str(), line), ("FX0143", 3));
}

#[test]
fn a_scaling_factor_of_zero_is_refused() {
    let (code, _) = alarm(&program("G51 X0 Y0 P0\n"), "mill-3axis");
    assert_eq!(code, "FX0014");
}

#[test]
fn the_transform_groups_read_as_system_variables() {
    let rows = run(&program(
        "G68 X0 Y0 R10.\n#1 = #4016\nG69\n#2 = #4016\nG51.1 X0\n#3 = #4022\nG50.1\nG01 X[#1 / 1000 + #2 / 1000000 + #3 / 100] F100.\n",
    ));
    // 0.068 + 0.000069 + 0.511.
    near(tip(&rows, 9), [0.579069, 0.0, 0.0]);
}

#[test]
fn a_transform_block_moves_nothing_and_uses_no_other_axis_word() {
    let (code, line) = alarm(&program("G68 X0 Y0 R10. Z5.\n"), "mill-3axis");
    assert_eq!((code.as_str(), line), ("FX0012", 2));
}

#[test]
fn g92_cancels_the_local_shift_of_its_axes() {
    // At X11 (program X1 in G52 X10.), G92 X0 makes this point X0 with
    // the local shift gone: X5. then lies 5 further.
    let rows = run(&program("G52 X10.\nG00 X1. Y0\nG92 X0\nX5.\n"));
    let last = rows.last().expect("rows");
    assert!((last.joints[0] - 16.0).abs() < EPS, "{:?}", last.joints);
}

#[test]
fn g68_with_i_j_k_about_z_is_the_plane_rotation() {
    // Three-dimensional conversion about +Z through (10, 0, 0) by 90°
    // turns (20, 0, 5) as the 2-D G68 does, and keeps Z.
    let rows = run(&program(
        "G68 X10. Y0 Z0 I0 J0 K1. R90.\nG01 X20. Y0 Z5. F100.\n",
    ));
    near(tip(&rows, 3), [10.0, 10.0, 5.0]);
    assert!(rows.iter().all(|r| r.line != 2));
}
