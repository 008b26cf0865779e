//! Cutter compensation C through the controller: the tool centre path as
//! the rows show it (forward kinematics of the machine positions).

mod common;

use common::builtin_at_zero;
use fiveaxis_control::{Alarm, Row};
use fiveaxis_machine::{Control, Machine, Offsets, ToolOffset};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

const EPS: f64 = 1e-9;

fn mill() -> Machine {
    let mut m = builtin_at_zero("mill-3axis").expect("built-in");
    m.control = Control::Fanuc16;
    m
}

fn offsets() -> Offsets {
    let mut o = Offsets::default();
    o.tools.insert(
        1,
        ToolOffset {
            radius: 5.0,
            ..ToolOffset::default()
        },
    );
    o.tools.insert(
        2,
        ToolOffset {
            radius: 2.0,
            ..ToolOffset::default()
        },
    );
    o.tools.insert(
        3,
        ToolOffset {
            length: 100.0,
            radius: 5.0,
            ..ToolOffset::default()
        },
    );
    o
}

fn run_on(machine: &Machine, program: &str) -> (Vec<Row>, Option<Alarm>) {
    common::run_ends(machine, offsets(), program)
}

fn run(program: &str) -> (Vec<Row>, Option<Alarm>) {
    run_on(&mill(), program)
}

fn xy(rows: &[Row]) -> Vec<(u32, [f64; 2])> {
    rows.iter().map(|r| (r.line, [r.tip.x, r.tip.y])).collect()
}

fn assert_path(rows: &[Row], want: &[(u32, [f64; 2])]) {
    let got = xy(rows);
    assert_eq!(got.len(), want.len(), "{got:?}");
    for ((l, p), (wl, wp)) in got.iter().zip(want) {
        assert_eq!(l, wl, "{got:?}");
        assert!(
            (p[0] - wp[0]).abs() < EPS && (p[1] - wp[1]).abs() < EPS,
            "{got:?} vs {want:?}"
        );
    }
}

/// A 50 mm square, clockwise from (0, 0), in and out.
const SQUARE: &str =
    "G0 X-10. Y-10.\nG41 G1 X0 Y0 D1 F500.\nY50.\nX50.\nY0\nX0\nG40 G0 X-10. Y-10.\nM30\n";

#[test]
fn square_outside_with_g41_type_a() {
    let (rows, alarm) = run(SQUARE);
    assert!(alarm.is_none(), "{alarm:?}");
    // Start-up ends perpendicular to the next block; the outer corners
    // (90°, obtuse) are the intersections of the offset lines; the last
    // block ends perpendicular to itself before the cancel.
    assert_path(
        &rows,
        &[
            (1, [-10.0, -10.0]),
            (2, [-5.0, 0.0]),
            (3, [-5.0, 55.0]),
            (4, [55.0, 55.0]),
            (5, [55.0, -5.0]),
            (6, [0.0, -5.0]),
            (7, [-10.0, -10.0]),
        ],
    );
}

#[test]
fn square_inside_with_g42() {
    let (rows, alarm) = run(&SQUARE.replace("G41", "G42"));
    assert!(alarm.is_none(), "{alarm:?}");
    assert_path(
        &rows,
        &[
            (1, [-10.0, -10.0]),
            (2, [5.0, 0.0]),
            (3, [5.0, 45.0]),
            (4, [45.0, 45.0]),
            (5, [45.0, 5.0]),
            (6, [0.0, 5.0]),
            (7, [-10.0, -10.0]),
        ],
    );
}

#[test]
fn acute_outer_corner_gets_two_extra_points() {
    // Up the Y axis, then back down at 30°: the outer corner at (0, 50).
    let t = 30f64.to_radians();
    let (dx, dy) = (50.0 * t.sin(), -50.0 * t.cos());
    let program = format!(
        "G0 X0 Y-10.\nG41 G1 X0 Y0 D1 F500.\nY50.\nX{:.12} Y{:.12}\nG40 X{:.12} Y-10.\n",
        dx,
        50.0 + dy,
        dx
    );
    let (rows, alarm) = run(&program);
    assert!(alarm.is_none(), "{alarm:?}");
    // Block 3 runs past the corner by r along its own direction (to
    // P1 = Qa + r·t1), then across to P2 = Qb − r·t2: the two extra points.
    let block3: Vec<_> = rows.iter().filter(|r| r.line == 3).collect();
    assert_eq!(block3.len(), 2, "{:?}", xy(&rows));
    assert!((block3[0].tip.x + 5.0).abs() < EPS && (block3[0].tip.y - 55.0).abs() < EPS);
    let (t2x, t2y) = (t.sin(), -t.cos());
    let qb = (5.0 * -t2y, 50.0 + 5.0 * t2x);
    let p2 = (qb.0 - 5.0 * t2x, qb.1 - 5.0 * t2y);
    assert!(
        (block3[1].tip.x - p2.0).abs() < EPS && (block3[1].tip.y - p2.1).abs() < EPS,
        "{:?}",
        xy(&rows)
    );
}

#[test]
fn arcs_are_offset_concentric() {
    // A half circle of radius 20 around (20, 0), outside with G41 on a
    // clockwise arc: radius 25.
    let (rows, alarm) =
        run("G0 X0 Y-10.\nG41 G1 X0 Y0 D1 F500.\nG2 X40. Y0 R20.\nG40 G1 X40. Y-10.\n");
    assert!(alarm.is_none(), "{alarm:?}");
    let arc = rows.iter().find(|r| r.line == 3).expect("arc row");
    assert!(
        ((arc.tip.x - 20.0).hypot(arc.tip.y) - 25.0).abs() < EPS,
        "{:?}",
        arc.tip
    );
    assert_eq!(arc.motion.name(), "cw");
}

#[test]
fn helical_arc_keeps_its_third_axis() {
    let (rows, alarm) =
        run("G0 X0 Y-10. Z0\nG41 G1 X0 Y0 D1 F500.\nG2 X40. Y0 Z-4. R20.\nG40 G1 X40. Y-10.\n");
    assert!(alarm.is_none(), "{alarm:?}");
    let arc = rows.iter().rfind(|r| r.line == 3).expect("arc row");
    assert!((arc.tip.z + 4.0).abs() < EPS);
}

#[test]
fn interference_stops_before_the_gouging_block() {
    // Up, across 6 mm, down: with G42 the 10 mm cutter would have to fit
    // between the two sides.
    let program = "G0 X0 Y-10.\nG42 G1 X0 Y0 D1 F500.\nY30.\nX6.\nY0\nX20.\nG40 Y-10.\n";
    let (rows, alarm) = run(program);
    let alarm = alarm.expect("interference");
    assert_eq!(alarm.code.to_string(), "PS041");
    // Nothing of the gouging block (and what follows) was output.
    assert!(
        rows.iter().all(|r| r.line < alarm.line),
        "{:?} {alarm:?}",
        xy(&rows)
    );
}

#[test]
fn arc_in_start_up_is_an_alarm() {
    let (_, alarm) = run("G0 X0 Y-10.\nG41 G2 X20. Y-10. R10. D1 F500.\n");
    assert_eq!(alarm.map(|a| a.code.to_string()), Some("PS034".into()));
}

#[test]
fn plane_change_in_the_mode_is_an_alarm() {
    let (_, alarm) = run("G0 X0 Y-10.\nG41 G1 X0 Y0 D1 F500.\nG18 X10.\n");
    assert_eq!(alarm.map(|a| a.code.to_string()), Some("PS037".into()));
}

#[test]
fn blocks_without_movement_and_z_moves_run_in_order() {
    let program =
        "G0 X-10. Y-10. Z10.\nG41 G1 X0 Y0 D1 F500.\nZ0\nY50.\nM8\nX50.\nG40 G0 X60. Y60.\nM30\n";
    let (rows, alarm) = run(program);
    assert!(alarm.is_none(), "{alarm:?}");
    let lines: Vec<u32> = rows.iter().map(|r| r.line).collect();
    let mut sorted = lines.clone();
    sorted.sort_unstable();
    assert_eq!(lines, sorted, "rows in program order");
    // The Z move runs at the start-up point, the compensated corner
    // afterwards is unchanged (one block without movement in the plane).
    let z = rows.iter().find(|r| r.line == 3).expect("Z row");
    assert!((z.tip.z).abs() < EPS && (z.tip.x + 5.0).abs() < EPS);
    let corner = rows.iter().find(|r| r.line == 4).expect("Y row");
    assert!(
        (corner.tip.x + 5.0).abs() < EPS && (corner.tip.y - 55.0).abs() < EPS,
        "{:?}",
        corner.tip
    );
}

#[test]
fn d_change_takes_effect_at_the_end_of_its_block() {
    let (rows, alarm) =
        run("G0 X-10. Y-10.\nG41 G1 X0 Y0 D1 F500.\nY50. D2\nX50.\nG40 G0 X60. Y60.\n");
    assert!(alarm.is_none(), "{alarm:?}");
    let end = rows.iter().rfind(|r| r.line == 3).expect("row");
    assert!(
        (end.tip.x + 2.0).abs() < EPS && (end.tip.y - 52.0).abs() < EPS,
        "{:?}",
        end.tip
    );
}

#[test]
fn program_end_emits_the_held_block() {
    let (rows, alarm) = run("G0 X-10. Y-10.\nG41 G1 X0 Y0 D1 F500.\nY50.\nM30\n");
    assert!(alarm.is_none());
    assert!(rows.iter().any(|r| r.line == 3), "{:?}", xy(&rows));
}

#[test]
fn length_compensation_and_work_offsets_apply_to_the_compensated_path() {
    let (rows, alarm) = run("G43 H3 G0 X-10. Y-10. Z0\nG41 G1 X0 Y0 D3 F500.\nY50.\nG40 X-10.\n");
    assert!(alarm.is_none(), "{alarm:?}");
    let row = rows.iter().find(|r| r.line == 3).expect("row");
    assert!((row.joints[2] - 100.0).abs() < EPS);
    assert!((row.tip.x + 5.0).abs() < EPS);
}

#[test]
fn tcpc_with_cutter_compensation_c_is_refused() {
    let m = builtin_at_zero("trunnion-ac").expect("built-in");
    let (_, alarm) = run_on(&m, "G43.4 H1 X0 Y0 Z0\nG41 G1 X10. D1 F500.\n");
    assert_eq!(alarm.map(|a| a.code.to_string()), Some("FX0092".into()));
}

proptest! {
    #![proptest_config(Config { cases: 128, rng_seed: RngSeed::Fixed(0xC0FFEE), failure_persistence: None, ..Config::default() })]

    /// Around a convex polygon (clockwise, outside with G41), every row
    /// that ends an offset line lies at exactly the radius from the
    /// programmed line of its block.
    #[test]
    fn offset_lines_lie_at_the_radius(n in 3usize..9, radius in 20.0..80.0f64, phase in 0.0..1.0f64) {
        let points: Vec<[f64; 2]> = (0..n)
            .map(|k| {
                let a = -std::f64::consts::TAU * (k as f64 + phase) / n as f64;
                [radius * a.cos(), radius * a.sin()]
            })
            .collect();
        let mut program = format!("G0 X{:.12} Y{:.12}\n", points[0][0] * 2.0, points[0][1] * 2.0);
        program.push_str(&format!("G41 G1 X{:.12} Y{:.12} D2 F500.\n", points[0][0], points[0][1]));
        for p in points.iter().skip(1).chain(std::iter::once(&points[0])) {
            program.push_str(&format!("X{:.12} Y{:.12}\n", p[0], p[1]));
        }
        program.push_str(&format!("G40 X{:.12} Y{:.12}\n", points[0][0] * 2.0, points[0][1] * 2.0));
        let (rows, alarm) = run(&program);
        prop_assert!(alarm.is_none(), "{alarm:?}");
        // Block k + 3 runs from points[k] to points[k + 1].
        for k in 0..n - 1 {
            let line = (k + 3) as u32;
            let (a, b) = (points[k], points[k + 1]);
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let len = dx.hypot(dy);
            for row in rows.iter().filter(|r| r.line == line).take(1) {
                let d = ((row.tip.x - a[0]) * dy - (row.tip.y - a[1]) * dx).abs() / len;
                prop_assert!((d - 2.0).abs() < 1e-9, "line {line}: distance {d}");
            }
        }
    }
}

// ----- seed 001: G41 / G42 without all of I, J, K ------------------------

#[test]
fn g41_with_i_j_only_starts_cutter_compensation_c_with_the_ij_type_vector() {
    // Seed 001: "When even one of the three addresses is omitted,
    // two-dimensional cutter compensation C is activated." The I, J given
    // are the I, J type vector: the vector at the end of the block is r
    // long, perpendicular to (I, J), on the G41 side (left of it).
    let (rows, alarm) =
        run("G0 X-20. Y0\nG41 G1 X0. Y0. I0. J1. D1 F100.\nG1 Y50.\nX50.\nG40 G0 X80. Y80.\n");
    assert!(alarm.is_none(), "{alarm:?}");
    assert_path(
        &rows,
        &[
            (1, [-20.0, 0.0]),
            // Left of +Y is -X: the vector (-5, 0) at (0, 0).
            (2, [-5.0, 0.0]),
            // Offset mode goes on with intersections.
            (3, [-5.0, 55.0]),
            (4, [50.0, 55.0]),
            (5, [80.0, 80.0]),
        ],
    );
}

#[test]
fn the_ij_type_vector_replaces_the_intersection_in_offset_mode() {
    // Mitsubishi's example of the same function (M700V manual, tool radius
    // compensation, "I, J type vector"): G41 with I in offset mode; no
    // corner block is inserted, the vector is perpendicular to (I, J).
    let program =
        "G0 X0 Y0\nG41 G1 X50. D1 F100.\nG41 X100. I1. J1.\nG1 X150. Y-50.\nG40 G0 X200. Y-50.\n";
    let (rows, alarm) = run(program);
    assert!(alarm.is_none(), "{alarm:?}");
    let s = 5.0 / 2f64.sqrt();
    // Left of (1, 1)/√2 is (-1, 1)/√2.
    let at = |rows: &[Row], line: u32| {
        rows.iter()
            .find(|r| r.line == line)
            .map(|r| [r.tip.x, r.tip.y, r.tip.z])
            .unwrap_or_else(|| panic!("no row of line {line}: {:?}", xy(rows)))
    };
    let p = at(&rows, 3);
    assert!(
        (p[0] - (100.0 - s)).abs() < EPS && (p[1] - s).abs() < EPS,
        "{:?}",
        xy(&rows)
    );
    // G42 takes the other side; I, K in G18 and J, K in G19 likewise.
    let (rows, _) = run("G0 X0 Y0\nG42 G1 X50. I1. J0 D1 F100.\nX100.\nG40 X120.\n");
    let p = at(&rows, 2);
    assert!(
        (p[0] - 50.0).abs() < EPS && (p[1] + 5.0).abs() < EPS,
        "{:?}",
        xy(&rows)
    );
    let (rows, alarm) = run("G18 G0 X0 Z0\nG41 G1 X50. I0 K1. D1 F100.\nX100.\nG40 X120.\n");
    assert!(alarm.is_none(), "{alarm:?}");
    // G18: the plane is Z-X; left of +Z (seen from +Y) is +X.
    assert!((at(&rows, 2)[0] - 55.0).abs() < EPS, "{:?}", at(&rows, 2));
}

#[test]
fn an_ij_type_vector_of_zero_length_is_an_alarm() {
    let (_, alarm) = run("G0 X0 Y0\nG41 G1 X50. I0 J0 D1 F100.\nX100.\n");
    assert_eq!(alarm.map(|a| a.code.to_string()), Some("FX0076".into()));
    // With all of I, J, K it is 3-D tool compensation, not this.
    let (_, alarm) = run("G0 X0 Y0\nG41 G1 X50. I0 J0 K1. D1 F100.\nX100.\n");
    assert!(alarm.is_none(), "{alarm:?}");
}
