//! Seeded properties of tool centre point control (G43.4 / G43.5, FANUC
//! 30i), judged by forward kinematics only.
//!
//! The expectations never come from the kernel's own inverse kinematics:
//! tool vectors are made from random rotary angles through
//! `Machine::forward`, programmed points are compared with the forward
//! tip carried into the programming frame (`machine-model.md` §1: with T₀
//! the table map at start-up and W the work offset, a table-frame tip t is
//! the programmed point `T₀(t) − W`, a table-frame direction d the
//! programmed vector `R_T₀·d`), and the rotary choice is checked against
//! an independent brute-force search over the angle grid.
//!
//! Every property runs a fixed number of cases from a fixed seed with no
//! failure persistence, so a run is reproducible; a failure prints the
//! program that shows it.
//!
//! Properties (random FANUC 30i machines with two rotary axes of every
//! arrangement, axis-aligned, 45° or arbitrary axes, centres ±300 mm, no
//! rotary limits, random rollover, random work offset and H1 50 … 200):
//!
//! * type 2 (G43.5): tip at every block end and on the line inside,
//!   vector at every block end (P0), and on the great circle inside (P1);
//! * type 1 (G43.4): tip as above, rotary axes at the programmed angles and
//!   linear in s; the same with WKP = 1 in the frame that does not turn;
//! * the FANUC rotary choice against a brute-force search (trunnion-ac,
//!   head-table-bc);
//! * posture control: circles that leave the reachable set, opposite
//!   vectors, continuity of the rotary axes;
//! * random TCPC programs on random machines never panic.
//!
//! Tests named `..._minimal_example` are hand-made small cases; those whose
//! comment starts with BUG fail on the kernel as it stands.

mod common;
/// The machine crate's generators of directions and points.
#[path = "../../fiveaxis-machine/tests/common/mod.rs"]
mod machine_gen;

use std::cell::Cell;
use std::f64::consts::PI;
use std::sync::OnceLock;

use common::{Outcome, check, run};
use fiveaxis_control::{Condition, Path, RunError, RunOptions, Runner, Segment, SliceSource};
use fiveaxis_machine::{
    Control, Dynamics, Joints, LinearAxis, MAX_AXES, MCodes, Machine, Offsets, Parameters,
    ProgrammingFrame, RotaryAxis, RotaryChoice, Side, ToolOffset, Vec3, builtin, principal,
};
use machine_gen::{direction, point};
use nalgebra::{IsometryMatrix3, Unit};
use proptest::prelude::*;
use proptest::sample::subsequence;
use proptest::test_runner::{Config, RngSeed, TestCaseError};

// ----- tolerances -----------------------------------------------------------

/// Tip tolerance, mm (`machine-model.md` §3).
const TIP_EPS: f64 = 1e-6;
/// Direction tolerance, rad (`machine-model.md` §3).
const DIR_EPS: f64 = 1e-9;
/// Rotary angle tolerance at block ends and inside type 1 blocks, degrees.
const ANGLE_EPS: f64 = 1e-9;
/// Rotary choice tolerance against the brute force, degrees.
const CHOICE_EPS: f64 = 1e-6;
/// Samples inside a block: s = k / SAMPLES.
const SAMPLES: u32 = 8;

// ----- configuration and generators ---------------------------------------

/// A deterministic proptest configuration.
fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x7C9C_43A5),
        failure_persistence: None,
        max_shrink_iters: 2048,
        ..Config::default()
    }
}

/// The four arrangements of two rotary axes, bed outwards.
fn two_sides() -> impl Strategy<Value = [Side; 2]> {
    use Side::{Head, Table};
    prop_oneof![
        Just([Head, Head]),
        Just([Table, Table]),
        Just([Head, Table]),
        Just([Table, Head]),
    ]
}

fn linear_axes(limit: f64) -> Vec<LinearAxis> {
    ['X', 'Y', 'Z']
        .into_iter()
        .map(|name| LinearAxis {
            name,
            min: -limit,
            max: limit,
            dynamics: Dynamics::LINEAR_DEFAULT,
            along: fiveaxis_machine::Along::Parallel,
        })
        .collect()
}

/// A FANUC 30i five-axis machine with random rotary geometry, no rotary
/// limits (rollover random), linear limits ±1e6, tool along +Z.
fn tcpc_machine(frame: ProgrammingFrame) -> impl Strategy<Value = Machine> {
    let names = subsequence(vec!['A', 'B', 'C'], 2).prop_shuffle();
    let axis = || (direction(), point(300.0), any::<bool>());
    (two_sides(), names, axis(), axis()).prop_map(move |(sides, names, a0, a1)| {
        let rotary = [(a0, sides[0], names[0]), (a1, sides[1], names[1])]
            .into_iter()
            .map(|((axis, center, rollover), on, name)| RotaryAxis {
                name,
                on,
                axis,
                center,
                limits: None,
                rollover,
                dynamics: Dynamics::ROTARY_DEFAULT,
            })
            .collect();
        Machine {
            name: "random tcpc".into(),
            control: Control::Fanuc30i,
            tool_direction: Vec3::z_axis(),
            linear: linear_axes(1e6),
            rotary,
            params: Parameters {
                programming_frame: frame,
                decimal_point_input: false,
                ..Parameters::default()
            },
            m_codes: MCodes::default(),
            bodies: Vec::new(),
            meshes: Vec::new(),
        }
    })
}

/// One TCPC block as generated: programmed tip, rotary angles (type 1:
/// the programmed angles; type 2: the angles the tool vector is made
/// from) and a scale for the vector (I J K need not be a unit vector).
#[derive(Clone, Debug)]
struct BlockSpec {
    tip: Vec3,
    angles: [f64; 2],
    scale: f64,
    /// Type 2: write no I J K (the previous vector stays).
    keep: bool,
}

/// A random TCPC program before it is written out.
#[derive(Clone, Debug)]
struct Case {
    machine: Machine,
    work: Vec3,
    length: f64,
    /// G0 before start-up: X Y Z and the rotary angles.
    rapid_xyz: Vec3,
    rapid_angles: [f64; 2],
    /// Programmed point of the start-up block.
    startup_tip: Vec3,
    blocks: Vec<BlockSpec>,
}

/// Type 2 cases: block angles anywhere (they only make a reachable vector).
fn case_type2() -> impl Strategy<Value = Case> {
    let angle = || -180.0..180.0f64;
    let block = (
        point(200.0),
        (angle(), angle()),
        0.5..2.0f64,
        proptest::bool::weighted(0.15),
    )
        .prop_map(|(tip, (a, b), scale, keep)| BlockSpec {
            tip,
            angles: [a, b],
            scale,
            keep,
        });
    (
        tcpc_machine(ProgrammingFrame::Table),
        point(300.0),
        50.0..200.0f64,
        point(200.0),
        (angle(), angle()),
        point(200.0),
        proptest::collection::vec(block, 3..=8),
    )
        .prop_map(
            |(machine, work, length, rapid_xyz, (a, b), startup_tip, blocks)| Case {
                machine,
                work,
                length,
                rapid_xyz,
                rapid_angles: [a, b],
                startup_tip,
                blocks,
            },
        )
}

/// Type 1 cases: the block angles are steps of less than 170° from the
/// previous block (so the shorter way on a rollover axis is the step).
fn case_type1(frame: ProgrammingFrame) -> impl Strategy<Value = Case> {
    let step = || -169.0..169.0f64;
    let block = (point(200.0), (step(), step())).prop_map(|(tip, (a, b))| BlockSpec {
        tip,
        angles: [a, b],
        scale: 1.0,
        keep: false,
    });
    (
        tcpc_machine(frame),
        point(300.0),
        50.0..200.0f64,
        point(200.0),
        (-180.0..180.0f64, -180.0..180.0f64),
        point(200.0),
        proptest::collection::vec(block, 3..=8),
    )
        .prop_map(
            |(machine, work, length, rapid_xyz, (a, b), startup_tip, mut blocks)| {
                let mut q = [a, b];
                for block in &mut blocks {
                    q = [q[0] + block.angles[0], q[1] + block.angles[1]];
                    block.angles = q;
                }
                Case {
                    machine,
                    work,
                    length,
                    rapid_xyz,
                    rapid_angles: [a, b],
                    startup_tip,
                    blocks,
                }
            },
        )
}

// ----- writing programs ------------------------------------------------------

/// `x` written with a decimal point and as many decimals (at most 12) as
/// the 15-digit limit of a number allows, and the value the control reads
/// back from it.
fn num(x: f64) -> (String, f64) {
    let mut decimals = 12usize;
    loop {
        let text = format!("{x:.decimals$}");
        let digits = text
            .trim_start_matches('-')
            .trim_start_matches('0')
            .chars()
            .filter(char::is_ascii_digit)
            .count();
        if digits <= 15 || decimals == 1 {
            let value = text.parse().expect("formatted number");
            return (text, value);
        }
        decimals -= 1;
    }
}

/// A program being written, with the values the control reads.
#[derive(Default)]
struct Writer {
    text: String,
    lines: u32,
}

impl Writer {
    /// Appends `letter` with value `x`; returns the value as read.
    fn word(&mut self, letter: char, x: f64) -> f64 {
        let (text, value) = num(x);
        self.text.push(' ');
        self.text.push(letter);
        self.text.push_str(&text);
        value
    }

    fn xyz(&mut self, p: &Vec3) -> Vec3 {
        Vec3::new(
            self.word('X', p.x),
            self.word('Y', p.y),
            self.word('Z', p.z),
        )
    }

    fn start(&mut self, code: &str) {
        self.text.push_str(code);
    }

    /// Ends the line; returns its 1-based number.
    fn end(&mut self) -> u32 {
        self.text.push('\n');
        self.lines += 1;
        self.lines
    }
}

fn joints_with_angles(machine: &Machine, angles: [f64; 2]) -> Joints {
    let mut j = [0.0; MAX_AXES];
    j[machine.rotary_index(0)] = angles[0];
    j[machine.rotary_index(1)] = angles[1];
    j
}

fn offsets(work: Vec3, length: f64) -> Offsets {
    let mut o = Offsets::default();
    o.tools.insert(
        1,
        ToolOffset {
            length,
            ..ToolOffset::default()
        },
    );
    o.work[0] = work;
    o
}

/// A written TCPC program and what it programs, as read by the control.
#[derive(Debug)]
struct Program {
    text: String,
    /// Rotary angles of the G0 before start-up (the start-up frame).
    rapid_angles: [f64; 2],
    startup_line: u32,
    startup_tip: Vec3,
    /// Per TCPC block after start-up: line, tip, angles (type 1) and
    /// programmed vector (type 2, as read, not normalized).
    blocks: Vec<(u32, Vec3, [f64; 2], Vec3)>,
}

/// The `G0 X Y Z <rotary>` before start-up; the angles as written.
fn write_rapid(w: &mut Writer, case: &Case) -> [f64; 2] {
    let names = [case.machine.rotary[0].name, case.machine.rotary[1].name];
    w.start("G0");
    w.xyz(&case.rapid_xyz);
    let angles = [
        w.word(names[0], case.rapid_angles[0]),
        w.word(names[1], case.rapid_angles[1]),
    ];
    w.end();
    angles
}

/// Type 2: `G0`, `G43.5 H1 X Y Z [P1]`, then `G1 X Y Z I J K` with each
/// vector made by forward kinematics from random angles and turned into
/// the programming frame; now and then a block without I J K, which keeps
/// the vector in force.
fn write_type2(case: &Case, posture: bool) -> Program {
    let m = &case.machine;
    let mut w = Writer::default();
    let rapid_angles = write_rapid(&mut w, case);
    let frame = m.chain(Side::Table, &joints_with_angles(m, rapid_angles));
    w.start(if posture { "G43.5 H1 P1" } else { "G43.5 H1" });
    let startup_tip = w.xyz(&case.startup_tip);
    let startup_line = w.end();
    let mut blocks = Vec::new();
    // The vector in force: at start-up, the tool's own direction.
    let mut v = frame.rotation * m.forward(&joints_with_angles(m, rapid_angles), 0.0).dir;
    for b in &case.blocks {
        w.start("G1");
        let tip = w.xyz(&b.tip);
        if !b.keep {
            let d = m.forward(&joints_with_angles(m, b.angles), 0.0).dir;
            let u = frame.rotation * d * b.scale;
            v = Vec3::new(w.word('I', u.x), w.word('J', u.y), w.word('K', u.z));
        }
        w.text.push_str(" F1000.");
        let line = w.end();
        blocks.push((line, tip, b.angles, v));
    }
    Program {
        text: w.text,
        rapid_angles,
        startup_line,
        startup_tip,
        blocks,
    }
}

/// Type 1: `G0`, `G43.4 H1 X Y Z`, then `G1 X Y Z <rotary> F1000.`.
fn write_type1(case: &Case) -> Program {
    let m = &case.machine;
    let names = [m.rotary[0].name, m.rotary[1].name];
    let mut w = Writer::default();
    let rapid_angles = write_rapid(&mut w, case);
    w.start("G43.4 H1");
    let startup_tip = w.xyz(&case.startup_tip);
    let startup_line = w.end();
    let mut blocks = Vec::new();
    for b in &case.blocks {
        w.start("G1");
        let tip = w.xyz(&b.tip);
        let q = [w.word(names[0], b.angles[0]), w.word(names[1], b.angles[1])];
        w.text.push_str(" F1000.");
        let line = w.end();
        blocks.push((line, tip, q, Vec3::zeros()));
    }
    Program {
        text: w.text,
        rapid_angles,
        startup_line,
        startup_tip,
        blocks,
    }
}

// ----- running ------------------------------------------------------------

/// The one segment of `line`.
fn segment_of(out: &Outcome, line: u32) -> Result<&Segment, TestCaseError> {
    let mut found = out.segments.iter().filter(|s| s.line == line);
    let seg = found
        .next()
        .ok_or_else(|| TestCaseError::fail(format!("no segment for line {line}")))?;
    prop_assert!(found.next().is_none(), "several segments for line {line}");
    Ok(seg)
}

// ----- geometry -------------------------------------------------------------

/// Angle between two vectors, rad (robust for small angles).
fn angle_between(a: &Vec3, b: &Vec3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// Spherical interpolation between unit `a` and `b`, computed here.
fn slerp(a: &Vec3, b: &Vec3, s: f64) -> Vec3 {
    let omega = angle_between(a, b);
    if omega < 1e-15 {
        return *a;
    }
    (a * ((1.0 - s) * omega).sin() + b * (s * omega).sin()) / omega.sin()
}

fn lerp3(a: &Vec3, b: &Vec3, s: f64) -> Vec3 {
    a + (b - a) * s
}

/// Difference of two angles in degrees, modulo 360 when `modulo`.
fn angle_diff(a: f64, b: f64, modulo: bool) -> f64 {
    if modulo {
        principal(a - b).abs()
    } else {
        (a - b).abs()
    }
}

/// How far inside the set of reachable tool directions (table frame) the
/// unit vector `v` lies, rad: negative outside.
///
/// Forward kinematics turns t0 first about one rotary line ("inner": the
/// innermost head axis, or the bed table axis when there is no head
/// axis), then about the other ("outer"), both fixed vectors. The inner
/// turn sweeps a cone of half-angle α = ∠(inner, t0) about the inner
/// line; the outer turn then reaches exactly the directions whose angle
/// to the outer line lies in [|β − α|, min(β + α, 2π − β − α)],
/// β = ∠(outer, inner).
fn reach_margin(machine: &Machine, v: &Vec3) -> f64 {
    let t0 = machine.tool_direction.into_inner();
    let heads = machine.rotary.iter().rev().filter(|a| a.on == Side::Head);
    let tables = machine.rotary.iter().filter(|a| a.on == Side::Table);
    let order: Vec<Vec3> = heads.chain(tables).map(|a| a.axis.into_inner()).collect();
    let (inner, outer) = (order[0], order[1]);
    let alpha = angle_between(&inner, &t0);
    let beta = angle_between(&outer, &inner);
    let lo = (beta - alpha).abs();
    let hi = (beta + alpha).min(2.0 * PI - beta - alpha);
    let g = angle_between(v, &outer);
    (g - lo).min(hi - g)
}

// ----- property 2: type 2 -----------------------------------------------

fn bump(c: &Cell<u32>) {
    c.set(c.get() + 1);
}

/// Where each block's great circle (start vector to end vector, as
/// programmed) lies against the reachable set of tool directions.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Circle {
    /// Every sample clearly inside (margin > 1e-7 rad).
    Inside,
    /// Some sample clearly outside (margin < −1e-7 rad).
    Outside,
    /// Touching the boundary, or start and end nearly opposite (no
    /// unique great circle): interior not judged.
    Unjudged,
}

/// The smallest `reach_margin` along the shorter great-circle arc from
/// unit `a` to unit `b` (table frame): exact, from the arc's extreme
/// angles to the outer rotary line, plus 257 samples for good measure.
///
/// On the arc `v(ψ) = cos ψ·a + sin ψ·u` (u ⊥ a in the plane of a and b,
/// 0 ≤ ψ ≤ Ω) the cosine of the angle to a fixed line w is
/// `cos ψ (w·a) + sin ψ (w·u)`, extreme at ψ = atan2(w·u, w·a) and that
/// plus π: the margin (the smaller of two monotone functions of that
/// angle) is smallest at one of those or at an end.
fn arc_margin(m: &Machine, a: &Vec3, b: &Vec3) -> f64 {
    let omega = angle_between(a, b);
    let sampled = (0..=256)
        .map(|k| reach_margin(m, &slerp(a, b, f64::from(k) / 256.0)))
        .fold(f64::INFINITY, f64::min);
    let perp = b - a * a.dot(b);
    if perp.norm() < 1e-12 {
        return sampled;
    }
    let u = perp.normalize();
    let heads = m.rotary.iter().rev().filter(|r| r.on == Side::Head);
    let tables = m.rotary.iter().filter(|r| r.on == Side::Table);
    let outer = heads
        .chain(tables)
        .last()
        .map_or(Vec3::z(), |r| r.axis.into_inner());
    let phi = outer.dot(&u).atan2(outer.dot(a));
    [phi - 2.0 * PI, phi - PI, phi, phi + PI, phi + 2.0 * PI]
        .into_iter()
        .filter(|psi| (0.0..=omega).contains(psi))
        .map(|psi| reach_margin(m, &(a * psi.cos() + u * psi.sin())))
        .fold(sampled, f64::min)
}

/// The programmed vectors of a type 2 program as unit vectors in the
/// programming frame, preceded by the start-up vector, and how each
/// block's great circle lies.
fn circles(m: &Machine, p: &Program) -> (Vec<Vec3>, Vec<Circle>) {
    let frame = m.chain(Side::Table, &joints_with_angles(m, p.rapid_angles));
    let start = frame.rotation * m.forward(&joints_with_angles(m, p.rapid_angles), 0.0).dir;
    let mut vectors = vec![start];
    vectors.extend(p.blocks.iter().map(|b| b.3.normalize()));
    let kinds = vectors
        .windows(2)
        .map(|ab| {
            let to_table = |v: &Vec3| frame.rotation.inverse_transform_vector(v);
            let min = arc_margin(m, &to_table(&ab[0]), &to_table(&ab[1]));
            if min < -1e-7 {
                Circle::Outside
            } else if min > 1e-7 && angle_between(&ab[0], &ab[1]) < 179f64.to_radians() {
                Circle::Inside
            } else {
                Circle::Unjudged
            }
        })
        .collect();
    (vectors, kinds)
}

/// Checks a type 2 run: the start-up tip, then each block's tip on the
/// line and its vector at the end; with `posture` also the tool vector
/// inside each block on the great circle (blocks whose circle is
/// `Inside`).
///
/// With posture control, a block whose great circle leaves the reachable
/// set cannot be followed: the run may stop there with an alarm, and the
/// blocks from there on are not checked here (see
/// `type2_posture_circle_outside_reach_alarms_or_is_followed`). Returns
/// how many blocks had their interior directions checked.
fn check_type2(case: &Case, posture: bool) -> Result<u32, TestCaseError> {
    let m = &case.machine;
    let p = write_type2(case, posture);
    let out = run(m, offsets(case.work, case.length), &p.text);
    let w = case.work;
    let frame = m.chain(Side::Table, &joints_with_angles(m, p.rapid_angles));
    let tip_prog = |tip_part: &Vec3| frame.transform_point(&(tip_part + w).into()).coords - w;
    let dir_prog = |dir: &Vec3| frame.rotation * dir;
    let (vectors, kinds) = circles(m, &p);
    let first_outside = kinds.iter().position(|&k| k == Circle::Outside);
    let last = if posture {
        first_outside.unwrap_or(p.blocks.len())
    } else {
        p.blocks.len()
    };
    let allowed_alarm = posture
        .then(|| first_outside.map(|k| p.blocks[k].0))
        .flatten();
    if let Some(alarm) = &out.alarm {
        prop_assert!(
            Some(alarm.line) == allowed_alarm,
            "unexpected alarm {alarm:?}\nprogram:\n{}",
            p.text
        );
    }
    let ctx = |line: u32| format!("line {line}, program:\n{}", p.text);

    // Start-up block: the tip lands on the programmed point.
    let seg = segment_of(&out, p.startup_line)?;
    let row = seg.row(m, 1.0);
    let e = (tip_prog(&row.tip) - p.startup_tip).norm();
    prop_assert!(
        e < TIP_EPS,
        "start-up tip off by {e} mm; {}",
        ctx(p.startup_line)
    );

    let mut prev_tip = p.startup_tip;
    let mut interiors = 0;
    for (k, (line, tip, _, _)) in p.blocks.iter().enumerate().take(last) {
        let (v0, v) = (vectors[k], vectors[k + 1]);
        // A block that changes neither the tip nor the tool direction moves
        // no axis (under posture control the axes follow the tool, so they
        // stand still too) and has no segment.
        if posture && *tip == prev_tip && angle_between(&v0, &v) < DIR_EPS {
            prop_assert!(
                out.segments.iter().all(|s| s.line != *line),
                "a block that moves nothing has a segment; {}",
                ctx(*line)
            );
            continue;
        }
        let seg = segment_of(&out, *line)?;
        let judge = posture && kinds[k] == Circle::Inside;
        for i in 1..=SAMPLES {
            let s = f64::from(i) / f64::from(SAMPLES);
            let row = seg.row(m, s);
            let want = lerp3(&prev_tip, tip, s);
            let e = (tip_prog(&row.tip) - want).norm();
            prop_assert!(
                e < TIP_EPS,
                "tip off the line by {e} mm at s = {s}; {}",
                ctx(*line)
            );
            if i == SAMPLES {
                let a = angle_between(&dir_prog(&row.dir), &v);
                prop_assert!(
                    a < DIR_EPS,
                    "tool vector off by {a} rad at the end; {}",
                    ctx(*line)
                );
            } else if judge {
                let want = slerp(&v0, &v, s);
                let a = angle_between(&dir_prog(&row.dir), &want);
                prop_assert!(
                    a < DIR_EPS,
                    "tool vector off the great circle by {a} rad at s = {s}; {}",
                    ctx(*line)
                );
            }
        }
        interiors += u32::from(judge);
        prev_tip = *tip;
    }
    Ok(interiors)
}

/// Type 2, rotary axes linear in s (P0): tips at block ends and on the
/// line inside, tool vectors at block ends.
#[test]
fn type2_tip_on_line_and_vector_at_block_ends() {
    check(config(256), case_type2(), |case| {
        check_type2(&case, false).map(|_| ())
    });
}

/// Type 2 with tool posture control (G43.5 P1): as above, and the tool
/// vector inside each block on the great circle between the block's start
/// and end vectors (where that circle stays inside the reachable set).
#[test]
fn type2_posture_control_turns_on_the_great_circle() {
    let blocks = Cell::new(0);
    check(config(256), case_type2(), |case| {
        blocks.set(blocks.get() + check_type2(&case, true)?);
        Ok(())
    });
    eprintln!(
        "posture: great circle checked inside {} blocks",
        blocks.get()
    );
    assert!(blocks.get() >= 200, "too few blocks checked");
}

/// With tool posture control, a block whose great circle between two
/// reachable tool vectors leaves the set of directions the two rotary axes
/// can reach (common on nutating or non-orthogonal machines) must stop
/// with an alarm at that block (or, were it possible, keep the tool on the
/// great circle): never leave the circle silently. (Before b00d67d
/// `posture_angles` found no solution inside and kept the rotary angles
/// linear in s without an alarm.) Judged at 256 points of each such block.
#[test]
fn type2_posture_circle_outside_reach_alarms_or_is_followed() {
    let seen = Cell::new(0);
    check(config(256), case_type2(), |case| {
        let m = &case.machine;
        let p = write_type2(&case, true);
        let (vectors, kinds) = circles(m, &p);
        let Some(k) = kinds.iter().position(|&k| k == Circle::Outside) else {
            return Ok(());
        };
        seen.set(seen.get() + 1);
        let out = run(m, offsets(case.work, case.length), &p.text);
        let line = p.blocks[k].0;
        if out.alarm.as_ref().is_some_and(|a| a.line == line) {
            return Ok(());
        }
        let frame = m.chain(Side::Table, &joints_with_angles(m, p.rapid_angles));
        let seg = segment_of(&out, line)?;
        for i in 1..256 {
            let s = f64::from(i) / 256.0;
            let got = frame.rotation * seg.row(m, s).dir;
            let a = angle_between(&got, &slerp(&vectors[k], &vectors[k + 1], s));
            prop_assert!(
                a < DIR_EPS,
                "no alarm, and the tool is {a} rad off the great circle at s = {s} \
                 (line {line}, whose circle leaves the reachable set); program:\n{}",
                p.text
            );
        }
        Ok(())
    });
    assert!(
        seen.get() >= 16,
        "too few cases with a circle outside the reachable set"
    );
}

/// Head-head: outer head axis A about X, inner head axis B tilted 20°
/// from Z in the XZ plane, centres 150 mm above the gauge point, tool +Z,
/// no limits. It reaches exactly the directions 50° … 90° from +X.
fn nutating_head() -> Machine {
    let tilt = 20f64.to_radians();
    let axis = |name, axis| RotaryAxis {
        name,
        on: Side::Head,
        axis,
        center: Vec3::new(0.0, 0.0, 150.0),
        limits: None,
        rollover: false,
        dynamics: Dynamics::ROTARY_DEFAULT,
    };
    Machine {
        name: "nutating head".into(),
        control: Control::Fanuc30i,
        tool_direction: Vec3::z_axis(),
        linear: linear_axes(1e6),
        rotary: vec![
            axis('A', Vec3::x_axis()),
            axis(
                'B',
                Unit::new_normalize(Vec3::new(tilt.sin(), 0.0, tilt.cos())),
            ),
        ],
        params: Parameters::default(),
        m_codes: MCodes::default(),
        bodies: Vec::new(),
        meshes: Vec::new(),
    }
}

/// The same by hand, on a head-head machine (no table
/// axes, so the programming frame is the machine frame): outer head axis A
/// about X, inner head axis B tilted 20° from Z in the XZ plane, tool +Z.
/// The reachable directions are those 50° … 90° from +X. The start vector
/// (A90 B90) and the end vector (A−90 B90) are both reachable, but the
/// great circle between them passes through +X (0° from X) at s = 0.5.
///
/// Before b00d67d: no alarm; at s = 0.5 the rotary axes sat at the linear
/// midpoint and the tool pointed 71° away from the circle.
#[test]
fn posture_outside_reach_minimal_example() {
    let m = nutating_head();
    let v0 = fk_dir(&m, [90.0, 90.0]);
    let v1 = fk_dir(&m, [-90.0, 90.0]);
    let mut w = Writer::default();
    w.start("G0 X0. Y0. Z0. A90. B90.");
    w.end();
    w.start("G43.5 H1 P1 X0. Y0. Z0.");
    w.end();
    w.start("G1 X0. Y0. Z0.");
    let v1 = Vec3::new(w.word('I', v1.x), w.word('J', v1.y), w.word('K', v1.z)).normalize();
    w.text.push_str(" F1000.");
    let line = w.end();
    // The oracle agrees: both ends reachable, the midpoint not.
    assert!(reach_margin(&m, &v0) > 0.1 && reach_margin(&m, &v1) > 0.1);
    assert!(reach_margin(&m, &slerp(&v0, &v1, 0.5)) < -0.5);
    let out = run(&m, offsets(Vec3::zeros(), 100.0), &w.text);
    if out.alarm.as_ref().is_some_and(|a| a.line == line) {
        return;
    }
    assert!(out.alarm.is_none(), "alarm {:?}", out.alarm);
    let seg = out
        .segments
        .iter()
        .find(|s| s.line == line)
        .expect("segment");
    let end = angle_between(&seg.row(&m, 1.0).dir, &v1);
    assert!(end < DIR_EPS, "end vector off by {end}");
    let mid = seg.row(&m, 0.5);
    let a = angle_between(&mid.dir, &slerp(&v0, &v1, 0.5));
    assert!(
        a < DIR_EPS,
        "program:\n{}no alarm, and at s = 0.5 the tool is {:.3} rad ({:.1}°) off the great circle \
         (joints A{:.6} B{:.6}, dir {:?})",
        w.text,
        a,
        a.to_degrees(),
        mid.joints[3],
        mid.joints[4],
        mid.dir
    );
}

/// With tool posture control, a tool vector exactly opposite to the
/// previous one has no unique great circle: the block must stop with an
/// alarm, or at least turn the tool uniformly (s·180° from the start
/// vector at every s). (Before b00d67d `slerp` fell back to the chord: the
/// tool stayed on the start vector for s < 0.5 and jumped to the end
/// vector after it, the B axis 0° → 180° at s = 0.5, with no alarm.)
#[test]
fn posture_opposite_vector_alarms_or_turns_uniformly() {
    let mut m = builtin("trunnion-bc").expect("built-in machine");
    m.rotary[0].limits = None; // B may tilt 180°.
    m.linear = linear_axes(1e6);
    let program =
        "G0 X0. Y0. Z0. B0. C0.\nG43.5 H1 P1 X0. Y0. Z0.\nG1 X10. Y0. Z0. I0. J0. K-1. F1000.\n";
    let out = run(&m, offsets(Vec3::zeros(), 100.0), program);
    if out.alarm.as_ref().is_some_and(|a| a.line == 3) {
        return;
    }
    assert!(out.alarm.is_none(), "alarm {:?}", out.alarm);
    let seg = out.segments.iter().find(|s| s.line == 3).expect("segment");
    let mut report = String::new();
    let mut worst: f64 = 0.0;
    for i in 1..=SAMPLES {
        let s = f64::from(i) / f64::from(SAMPLES);
        let row = seg.row(&m, s);
        let from_start = angle_between(&row.dir, &Vec3::z()).to_degrees();
        worst = worst.max((from_start - 180.0 * s).abs());
        report += &format!(
            "s = {s}: B{:.3} C{:.3}, {from_start:.3}° from the start vector (want {:.3}°)\n",
            row.joints[3],
            row.joints[4],
            180.0 * s
        );
    }
    assert!(
        worst < DIR_EPS.to_degrees(),
        "program:\n{program}no alarm, and the tool does not turn uniformly:\n{report}"
    );
}

// ----- property 3 and 4: type 1 -----------------------------------------

fn check_type1(case: &Case) -> Result<(), TestCaseError> {
    let m = &case.machine;
    let p = write_type1(case);
    let out = run(m, offsets(case.work, case.length), &p.text);
    prop_assert!(
        out.alarm.is_none(),
        "unexpected alarm {:?}\nprogram:\n{}",
        out.alarm,
        p.text
    );
    let w = case.work;
    let turning = m.params.programming_frame == ProgrammingFrame::Workpiece;
    let frame0 = m.chain(Side::Table, &joints_with_angles(m, p.rapid_angles));
    // Programmed point of a row: T(tip) − W with T the start-up table map
    // (WKP = 0) or the table map at the row's own joints (WKP = 1).
    let tip_prog = |row: &fiveaxis_control::Row| {
        let frame: IsometryMatrix3<f64> = if turning {
            m.chain(Side::Table, &row.joints)
        } else {
            frame0
        };
        frame.transform_point(&(row.tip + w).into()).coords - w
    };
    let ctx = |line: u32| format!("line {line}, program:\n{}", p.text);
    let (i0, i1) = (m.rotary_index(0), m.rotary_index(1));
    let roll = [m.rotary[0].rollover, m.rotary[1].rollover];

    let seg = segment_of(&out, p.startup_line)?;
    let row = seg.row(m, 1.0);
    let e = (tip_prog(&row) - p.startup_tip).norm();
    prop_assert!(
        e < TIP_EPS,
        "start-up tip off by {e} mm; {}",
        ctx(p.startup_line)
    );

    let mut prev_tip = p.startup_tip;
    let mut prev_q = p.rapid_angles;
    for (line, tip, q, _) in &p.blocks {
        let seg = segment_of(&out, *line)?;
        for i in 1..=SAMPLES {
            let s = f64::from(i) / f64::from(SAMPLES);
            let row = seg.row(m, s);
            let want = lerp3(&prev_tip, tip, s);
            let e = (tip_prog(&row) - want).norm();
            prop_assert!(
                e < TIP_EPS,
                "tip off the line by {e} mm at s = {s}; {}",
                ctx(*line)
            );
            for (k, i) in [i0, i1].into_iter().enumerate() {
                let want = prev_q[k] + (q[k] - prev_q[k]) * s;
                let d = angle_diff(row.joints[i], want, roll[k]);
                prop_assert!(
                    d < ANGLE_EPS,
                    "rotary axis {} at {} instead of {want} (s = {s}); {}",
                    m.rotary[k].name,
                    row.joints[i],
                    ctx(*line)
                );
            }
        }
        prev_tip = *tip;
        prev_q = *q;
    }
    Ok(())
}

/// Type 1 (G43.4), WKP = 0: tips at block ends and on the line inside,
/// rotary axes at the programmed angles (mod 360 on rollover axes) and
/// linear in s.
#[test]
fn type1_tip_on_line_and_rotaries_as_programmed() {
    check(config(256), case_type1(ProgrammingFrame::Table), |case| {
        check_type1(&case)
    });
}

/// Type 1, WKP = 1: the programmed point is the tip seen in the work
/// coordinate system that does not turn with the table (table map at the
/// row's own joints).
#[test]
fn type1_workpiece_frame_tip_on_line_in_non_turning_frame() {
    check(
        config(256),
        case_type1(ProgrammingFrame::Workpiece),
        |case| check_type1(&case),
    );
}

// ----- property 5: rotary choice against a brute force ----------------------

/// Forward directions on the 1° grid of both rotary angles, −180 … 179.
struct Grid {
    dirs: Vec<Vec3>,
}

const GRID: usize = 360;

fn grid_angle(i: usize) -> f64 {
    i as f64 - 180.0
}

impl Grid {
    fn new(m: &Machine) -> Self {
        let mut dirs = Vec::with_capacity(GRID * GRID);
        for i in 0..GRID {
            for j in 0..GRID {
                let q = [grid_angle(i), grid_angle(j)];
                dirs.push(m.forward(&joints_with_angles(m, q), 0.0).dir);
            }
        }
        Self { dirs }
    }
}

fn fk_dir(m: &Machine, q: [f64; 2]) -> Vec3 {
    m.forward(&joints_with_angles(m, q), 0.0).dir
}

/// Gauss–Newton on the forward direction error from `q` (degrees).
fn refine(m: &Machine, d: &Vec3, mut q: [f64; 2]) -> Option<[f64; 2]> {
    const H: f64 = 1e-4;
    for _ in 0..50 {
        let r = fk_dir(m, q) - d;
        if r.norm() < 1e-14 {
            break;
        }
        let col = |k: usize| {
            let (mut a, mut b) = (q, q);
            a[k] += H;
            b[k] -= H;
            (fk_dir(m, a) - fk_dir(m, b)) / (2.0 * H)
        };
        let (j0, j1) = (col(0), col(1));
        let (a, b, c) = (j0.dot(&j0), j0.dot(&j1), j1.dot(&j1));
        let (g0, g1) = (j0.dot(&r), j1.dot(&r));
        let det = a * c - b * b;
        if det.abs() < 1e-300 {
            return None;
        }
        let dq = [-(c * g0 - b * g1) / det, -(a * g1 - b * g0) / det];
        q = [q[0] + dq[0], q[1] + dq[1]];
        if dq[0].abs().max(dq[1].abs()) < 1e-13 {
            break;
        }
    }
    let err = (fk_dir(m, q) - d).norm();
    (err < 1e-11).then_some([principal(q[0]), principal(q[1])])
}

/// Every rotary pair (principal angles) pointing the tool along `d`:
/// local minima of the grid error, refined, deduplicated.
fn brute_solutions(m: &Machine, grid: &Grid, d: &Vec3) -> Vec<[f64; 2]> {
    let err: Vec<f64> = grid.dirs.iter().map(|g| (g - d).norm_squared()).collect();
    let at = |i: usize, j: usize| err[(i % GRID) * GRID + (j % GRID)];
    let mut out: Vec<[f64; 2]> = Vec::new();
    for i in 0..GRID {
        for j in 0..GRID {
            let e = at(i, j);
            if e > 0.05 * 0.05 {
                continue;
            }
            let minimum = (0..3).all(|di| {
                (0..3)
                    .all(|dj| (di == 1 && dj == 1) || e <= at(i + GRID - 1 + di, j + GRID - 1 + dj))
            });
            if !minimum {
                continue;
            }
            if let Some(q) = refine(m, d, [grid_angle(i), grid_angle(j)])
                && !out.iter().any(|o| {
                    principal(o[0] - q[0]).abs() < 1e-6 && principal(o[1] - q[1]).abs() < 1e-6
                })
            {
                out.push(q);
            }
        }
    }
    out
}

/// The positions of axis `k` equivalent to `angle`: the shorter way from
/// `current` on a rollover axis; every 360° repeat inside the limits on a
/// limited one. `None` when some repeat lies within `CHOICE_EPS` of a
/// limit (ambiguous).
fn positions(m: &Machine, k: usize, angle: f64, current: f64) -> Option<Vec<f64>> {
    let axis = &m.rotary[k];
    match axis.limits {
        Some((min, max)) if !axis.rollover => {
            let mut out = Vec::new();
            for n in -3..=3 {
                let a = angle + 360.0 * f64::from(n);
                if (a - min).abs() < CHOICE_EPS || (a - max).abs() < CHOICE_EPS {
                    return None;
                }
                if a > min && a < max {
                    out.push(a);
                }
            }
            Some(out)
        }
        _ => Some(vec![current + principal(angle - current)]),
    }
}

#[derive(Clone, Debug)]
struct ChoiceCase {
    machine: usize,
    current: [f64; 2],
    /// Angles the direction is made from (reachable), or a free direction.
    target: Result<[f64; 2], Vec3>,
}

fn choice_machines() -> &'static [(Machine, Grid)] {
    static MACHINES: OnceLock<Vec<(Machine, Grid)>> = OnceLock::new();
    MACHINES.get_or_init(|| {
        ["trunnion-ac", "head-table-bc"]
            .into_iter()
            .map(|name| {
                let mut m = builtin(name).expect("built-in machine");
                // Keep the linear axes out of the way: only the rotary
                // limits matter here.
                m.linear = linear_axes(1e6);
                let grid = Grid::new(&m);
                (m, grid)
            })
            .collect()
    })
}

/// Angles within `limits` (or any on a rollover axis).
fn angle_in(axis: &RotaryAxis) -> BoxedStrategy<f64> {
    match axis.limits {
        Some((min, max)) if !axis.rollover => (min..max).boxed(),
        _ => (-180.0..540.0f64).boxed(),
    }
}

fn choice_case() -> impl Strategy<Value = ChoiceCase> {
    (0..2usize).prop_flat_map(|mi| {
        let m = &choice_machines()[mi].0;
        let q = || (angle_in(&m.rotary[0]), angle_in(&m.rotary[1]));
        let target = prop_oneof![
            3 => q().prop_map(|(a, b)| Ok([a, b])),
            1 => direction().prop_map(|d| Err(d.into_inner())),
        ];
        (Just(mi), q(), target).prop_map(|(machine, (a, b), target)| ChoiceCase {
            machine,
            current: [a, b],
            target,
        })
    })
}

#[derive(Default)]
struct ChoiceCounts {
    compared: Cell<u32>,
    unreachable: Cell<u32>,
    singular: Cell<u32>,
    ties: Cell<u32>,
}

/// FANUC rotary choice (smallest |Δθ0| + |Δθ1|, rollover the shorter way,
/// inside the soft limits) against an independent search for every
/// solution, on the built-in trunnion-ac and head-table-bc.
#[test]
fn type2_rotary_choice_matches_brute_force() {
    let counts = ChoiceCounts::default();
    check(config(256), choice_case(), |case| {
        let (m, grid) = &choice_machines()[case.machine];
        let names = [m.rotary[0].name, m.rotary[1].name];
        let d = match case.target {
            Ok(q) => fk_dir(m, q),
            Err(d) => d,
        };
        // The rotating axis is C (file index 1) on both machines.
        let c_axis = m.rotary[1].axis.into_inner();
        if angle_between(&d, &c_axis).min(angle_between(&d, &-c_axis)) < 1f64.to_radians() {
            bump(&counts.singular);
            return Ok(());
        }
        let mut w = Writer::default();
        w.start("G0 X0. Y0. Z0.");
        let current = [
            w.word(names[0], case.current[0]),
            w.word(names[1], case.current[1]),
        ];
        w.end();
        w.start("G43.5 H1 X0. Y0. Z0.");
        w.end();
        let frame = m.chain(Side::Table, &joints_with_angles(m, current));
        let v = frame.rotation * d;
        w.start("G1 X0. Y0. Z0.");
        let v = Vec3::new(w.word('I', v.x), w.word('J', v.y), w.word('K', v.z));
        w.text.push_str(" F1000.");
        let line = w.end();
        let d = frame.rotation.inverse_transform_vector(&v.normalize());

        // The kernel's current position: rollover axes shown mod 360.
        let current: Vec<f64> = (0..2)
            .map(|k| {
                if m.rotary[k].rollover {
                    current[k].rem_euclid(360.0)
                } else {
                    current[k]
                }
            })
            .collect();
        let mut candidates = Vec::new();
        for q in brute_solutions(m, grid, &d) {
            let (Some(a), Some(b)) = (
                positions(m, 0, q[0], current[0]),
                positions(m, 1, q[1], current[1]),
            ) else {
                bump(&counts.ties);
                return Ok(());
            };
            for &a in &a {
                for &b in &b {
                    let cost = (a - current[0]).abs() + (b - current[1]).abs();
                    candidates.push((cost, [a, b]));
                }
            }
        }
        candidates.sort_by(|x, y| x.0.total_cmp(&y.0));
        let out = run(m, offsets(Vec3::zeros(), 100.0), &w.text);
        let Some(&(best_cost, best)) = candidates.first() else {
            bump(&counts.unreachable);
            let alarm = out.alarm.as_ref().map(|a| a.condition);
            prop_assert_eq!(
                alarm,
                Some(Condition::ToolDirectionUnreachable),
                "no rotary position inside the limits points along {:?}; program:\n{}",
                d,
                w.text
            );
            return Ok(());
        };
        if candidates.get(1).is_some_and(|c| c.0 - best_cost < 1e-6) {
            bump(&counts.ties);
            return Ok(());
        }
        prop_assert!(
            out.alarm.is_none(),
            "unexpected alarm {:?}; program:\n{}",
            out.alarm,
            w.text
        );
        let end = match out.segments.iter().find(|s| s.line == line) {
            Some(seg) => seg.end,
            // No motion: the rotaries stay where they are.
            None => out.segments.last().map_or([0.0; MAX_AXES], |s| s.end),
        };
        let got = [end[m.rotary_index(0)], end[m.rotary_index(1)]];
        for k in 0..2 {
            let diff = angle_diff(got[k], best[k], m.rotary[k].rollover);
            prop_assert!(
                diff < CHOICE_EPS,
                "{}: kernel chose {:?}, brute force {:?} (cost {}; all candidates {:?}); program:\n{}",
                m.name,
                got,
                best,
                best_cost,
                candidates,
                w.text
            );
        }
        bump(&counts.compared);
        Ok(())
    });
    eprintln!(
        "rotary choice: {} compared, {} unreachable (alarm checked), {} near singular, {} ties or at a limit (skipped)",
        counts.compared.get(),
        counts.unreachable.get(),
        counts.singular.get(),
        counts.ties.get()
    );
    assert!(counts.compared.get() >= 64, "too few cases compared");
}

// ----- property 6: never panics ------------------------------------------

fn any_rotary(name: char, on: Side) -> impl Strategy<Value = RotaryAxis> {
    let limits = prop_oneof![
        (-360.0..0.0f64, 0.001..720.0f64).prop_map(|(lo, span)| (Some((lo, lo + span)), false)),
        Just((None, false)),
        Just((None, true)),
    ];
    (direction(), point(300.0), limits).prop_map(move |(axis, center, (limits, rollover))| {
        RotaryAxis {
            name,
            on,
            axis,
            center,
            limits,
            rollover,
            dynamics: Dynamics::ROTARY_DEFAULT,
        }
    })
}

/// Any machine with 0, 1 or 2 rotary axes, any control and parameters.
fn any_machine() -> impl Strategy<Value = Machine> {
    use Side::{Head, Table};
    let sides = prop_oneof![
        1 => Just(vec![]),
        1 => Just(vec![Head]),
        1 => Just(vec![Table]),
        3 => Just(vec![Head, Head]),
        3 => Just(vec![Table, Table]),
        3 => Just(vec![Head, Table]),
        3 => Just(vec![Table, Head]),
    ];
    let control = prop_oneof![
        Just(Control::Fanuc30i),
        Just(Control::Fanuc16),
        Just(Control::Mitsubishi),
        Just(Control::Mazak)
    ];
    let frame = prop_oneof![
        4 => Just(ProgrammingFrame::Table),
        1 => Just(ProgrammingFrame::Workpiece)
    ];
    let choice = prop_oneof![
        Just(RotaryChoice::Shortest),
        Just(RotaryChoice::RotatingAxis),
        Just(RotaryChoice::KeepTiltSign)
    ];
    let option = prop_oneof![7 => Just(true), 1 => Just(false)];
    let params = (frame, option, any::<bool>(), choice, 0.0..10.0f64).prop_map(
        |(programming_frame, tcpc_option, tool_posture_control, rotary_choice, singular_zone)| {
            Parameters {
                programming_frame,
                tcpc_option,
                tool_posture_control,
                rotary_choice,
                singular_zone,
                ..Parameters::default()
            }
        },
    );
    let limit = prop_oneof![3 => Just(1e6), 1 => 200.0..2000.0f64];
    sides
        .prop_flat_map(|sides| {
            let n = sides.len();
            let names = subsequence(vec!['A', 'B', 'C'], n).prop_shuffle();
            (Just(sides), names)
        })
        .prop_flat_map(move |(sides, names)| {
            let axes: Vec<_> = names
                .iter()
                .zip(&sides)
                .map(|(&name, &on)| any_rotary(name, on))
                .collect();
            (
                axes,
                control.clone(),
                params.clone(),
                limit.clone(),
                prop_oneof![3 => Just(Vec3::z_axis()), 1 => direction()],
            )
        })
        .prop_map(|(rotary, control, params, limit, tool_direction)| Machine {
            name: "any".into(),
            control,
            tool_direction,
            linear: linear_axes(limit),
            rotary,
            params,
            m_codes: MCodes::default(),
            bodies: Vec::new(),
            meshes: Vec::new(),
        })
}

/// A number for a word: ordinary, tiny, zero, or an integer without a
/// decimal point (least input increments).
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => (-300.0..300.0f64).prop_map(|x| num(x).0),
        1 => (-1e-6..1e-6f64).prop_map(|x| format!("{x:.9}")),
        1 => Just("0.".to_string()),
        1 => Just("0".to_string()),
        1 => (-999i32..999).prop_map(|x| x.to_string()),
        1 => (-200.0..200.0f64).prop_map(|x| format!("{x:.3}")),
    ]
}

/// Some of `letters` (each at most once) with values.
fn words(letters: Vec<char>) -> impl Strategy<Value = String> {
    let n = letters.len();
    proptest::collection::vec((proptest::sample::select(letters), value()), 0..=n).prop_map(|ws| {
        let mut seen = Vec::new();
        let mut out = String::new();
        for (l, v) in ws {
            if !seen.contains(&l) {
                seen.push(l);
                out.push(' ');
                out.push(l);
                out.push_str(&v);
            }
        }
        out
    })
}

fn ijk(d: &Vec3) -> String {
    format!(" I{} J{} K{}", num(d.x).0, num(d.y).0, num(d.z).0)
}

/// One line of a TCPC program for machine `m`: start-ups of either type,
/// moves with the machine's own axis letters, tool vectors (unit, partial,
/// zero, a vector and its exact opposite in a row), arcs, cancels, G91,
/// and now and then a word the block cannot take.
fn tcpc_line(m: &Machine) -> impl Strategy<Value = String> + use<> {
    prop_oneof![1 => startup_line(m), 8 => mode_line(m)]
}

/// A TCPC start-up block (type 1 or 2, P, Q; now and then I J K).
fn startup_line(m: &Machine) -> impl Strategy<Value = String> + use<> {
    let rotary: Vec<char> = m.rotary.iter().map(|a| a.name).collect();
    let linear = vec!['X', 'Y', 'Z'];
    let all: Vec<char> = linear.iter().chain(&rotary).copied().collect();
    let posture = || prop_oneof![4 => Just(""), 1 => Just(" P1"), 1 => Just(" P0")];
    prop_oneof![
        3 => (posture(), words(all))
            .prop_map(|(p, w)| format!("G43.4 H1{p}{w}")),
        3 => (posture(), prop_oneof![3 => Just(""), 1 => Just(" Q5."), 1 => Just(" Q-30.")], words(linear.clone()))
            .prop_map(|(p, q, w)| format!("G43.5 H1{p}{q}{w}")),
        1 => (words(linear), direction()).prop_map(|(w, v)| format!("G43.5 H1{w}{}", ijk(&v))),
    ]
}

/// A block inside (or after) TCPC.
fn mode_line(m: &Machine) -> impl Strategy<Value = String> + use<> {
    let rotary: Vec<char> = m.rotary.iter().map(|a| a.name).collect();
    let linear = vec!['X', 'Y', 'Z'];
    let all: Vec<char> = linear.iter().chain(&rotary).copied().collect();
    let vector = vec!['I', 'J', 'K'];
    let unit = || direction().prop_map(|d| ijk(&d));
    prop_oneof![
        1 => words(all.clone()).prop_map(|w| format!("G0{w}")),
        6 => words(all.clone()).prop_map(|w| format!("G1{w} F1000.")),
        6 => (words(linear.clone()), unit()).prop_map(|(w, v)| format!("G1{w}{v} F1000.")),
        2 => (words(linear.clone()), words(vector)).prop_map(|(w, v)| format!("G1{w}{v} F1000.")),
        1 => (words(all), unit()).prop_map(|(w, v)| format!("G1{w}{v} F1000.")),
        // A vector and its exact opposite in a row.
        1 => direction().prop_map(|d| {
            let d = d.into_inner();
            format!("G1{} F1000.\nG1{} F1000.", ijk(&d), ijk(&-d))
        }),
        1 => (prop_oneof![Just("G2"), Just("G3")], words(linear.clone()), value())
            .prop_map(|(g, w, r)| format!("{g}{w} R{r} F1000.")),
        1 => Just("G1 I0 J0 K0 F1000.".to_string()),
        1 => Just("G49".to_string()),
        1 => Just("G91".to_string()),
        1 => Just("G90".to_string()),
        1 => words(vec!['A', 'B', 'C', 'U', 'Q', 'P', 'R']).prop_map(|w| format!("G1{w} F1000.")),
    ]
}

/// A random machine with a random TCPC program for it.
fn machine_and_program() -> impl Strategy<Value = (Machine, Vec<String>)> {
    any_machine().prop_flat_map(|m| {
        let rotary: Vec<char> = m.rotary.iter().map(|a| a.name).collect();
        let all: Vec<char> = ['X', 'Y', 'Z'].into_iter().chain(rotary).collect();
        let first = words(all).prop_map(|w| format!("G0{w}"));
        let rest = proptest::collection::vec(tcpc_line(&m), 1..10);
        let startup = startup_line(&m);
        (
            Just(m),
            (first, startup, rest).prop_map(|(a, b, rest)| {
                let mut lines = vec![a, b];
                lines.extend(rest);
                lines
            }),
        )
    })
}

fn finite_row(row: &fiveaxis_control::Row, m: &Machine) -> bool {
    row.joints[..m.axis_count()].iter().all(|x| x.is_finite())
        && row.tip.iter().all(|x| x.is_finite())
        && row.dir.iter().all(|x| x.is_finite())
}

/// Random TCPC type 1 / 2 programs on random machines (limits, unreachable
/// vectors, every control) end with Ok or an alarm, never a panic, and
/// every sampled row is finite.
#[test]
fn tcpc_programs_never_panic() {
    let strategy = (machine_and_program(), point(300.0), -50.0..200.0f64);
    let (runs, tcpc_runs, alarms) = (Cell::new(0), Cell::new(0), Cell::new(0));
    check(config(256), strategy, |((m, lines), work, length)| {
        bump(&runs);
        let program = lines.join("\n") + "\n";
        let lines_count = u32::try_from(program.lines().count()).unwrap_or(u32::MAX);
        let mut runner = Runner::new(
            &m,
            offsets(work, length),
            SliceSource::new(program.as_bytes()),
            RunOptions::default(),
        );
        for _ in 0..1000 {
            match runner.next_segment() {
                Ok(Some(seg)) => {
                    if matches!(seg.path, Path::Tcpc(_)) && tcpc_runs.get() < runs.get() {
                        bump(&tcpc_runs);
                    }
                    for s in [0.0, 0.25, 0.5, 0.75, 1.0] {
                        let row = seg.row(&m, s);
                        prop_assert!(
                            finite_row(&row, &m),
                            "row not finite at s = {s}: {row:?}\nprogram:\n{program}"
                        );
                    }
                }
                Ok(None) => return Ok(()),
                Err(RunError::Alarm { alarm, .. }) => {
                    prop_assert!(
                        !alarm.message.is_empty() && (1..=lines_count).contains(&alarm.line),
                        "alarm {alarm:?} outside the program's {lines_count} lines"
                    );
                    bump(&alarms);
                    return Ok(());
                }
                Err(e) => panic!("io error {e}"),
            }
        }
        Ok(())
    });
    eprintln!(
        "never panics: {} runs, {} with a TCPC segment, {} ended in an alarm",
        runs.get(),
        tcpc_runs.get(),
        alarms.get()
    );
}

// ----- self-checks of the oracle ------------------------------------------

/// The reachable-set test used to pick posture blocks contains every
/// forward direction.
#[test]
fn oracle_reach_margin_contains_forward_directions() {
    check(config(64), tcpc_machine(ProgrammingFrame::Table), |m| {
        for i in 0..36 {
            for j in 0..36 {
                let q = [f64::from(i) * 10.0 - 180.0, f64::from(j) * 10.0 - 180.0];
                let margin = reach_margin(&m, &fk_dir(&m, q));
                prop_assert!(margin > -1e-9, "{q:?} gives {margin}");
            }
        }
        Ok(())
    });
}

// ----- posture control: continuity of the rotary axes ---------------------

/// The largest rotary jump of `seg` at a single point of s: the worst of
/// `n` equal steps, narrowed by bisection to an interval of about 1e-12.
/// A continuous motion gives (almost) 0 there; a jump keeps its size
/// however small the interval. Returns (jump in degrees, s, joints just
/// before, just after).
fn rotary_jump(m: &Machine, seg: &Segment, n: u32) -> (f64, f64, Joints, Joints) {
    let (i0, i1) = (m.rotary_index(0), m.rotary_index(1));
    let jump = |a: f64, b: f64| {
        let (x, y) = (seg.eval(m, a), seg.eval(m, b));
        (x[i0] - y[i0]).abs().max((x[i1] - y[i1]).abs())
    };
    let step = 1.0 / f64::from(n);
    let k = (0..n)
        .max_by(|&a, &b| {
            let ja = jump(f64::from(a) * step, f64::from(a + 1) * step);
            let jb = jump(f64::from(b) * step, f64::from(b + 1) * step);
            ja.total_cmp(&jb)
        })
        .unwrap_or(0);
    let (mut a, mut b) = (f64::from(k) * step, f64::from(k + 1) * step);
    for _ in 0..32 {
        let mid = 0.5 * (a + b);
        if jump(a, mid) >= jump(mid, b) {
            b = mid;
        } else {
            a = mid;
        }
    }
    (jump(a, b), a, seg.eval(m, a), seg.eval(m, b))
}

/// BUG (kernel, `segment.rs` `posture_angles`, used by `Segment::eval`):
/// with tool posture control the rotary axes jump inside a block.
/// `posture_angles` takes, at each s, the solution nearest to the linear
/// interpolation of the block's end angles, each axis unwrapped to within
/// 180° of that guide. As s moves, the nearer solution changes from one
/// branch to the other (a jump of about 180° on both axes, or between the
/// two branches of a non-orthogonal machine), or the unwrap passes 180° (a
/// jump of 360° on one axis), while the tool direction stays continuous
/// (to 1e-15). The machine axes would have to move that far in no time,
/// and `Segment::steps` can never meet the step angle there.
///
/// Expected: the rotary axes (so the linear axes too) continuous in s
/// inside every block. Judged where the great circle stays clear (1e-3 rad)
/// of the edge of the reachable set, so away from singular directions,
/// where the rotating axis may turn fast but still continuously: after
/// narrowing to an interval of ~1e-12 in s, a continuous motion moves
/// far less than 1e-3°.
#[test]
fn type2_posture_rotary_axes_continuous_inside_block() {
    let blocks = Cell::new(0);
    check(config(256), case_type2(), |case| {
        let m = &case.machine;
        let p = write_type2(&case, true);
        let (vectors, _) = circles(m, &p);
        let frame = m.chain(Side::Table, &joints_with_angles(m, p.rapid_angles));
        let out = run(m, offsets(case.work, case.length), &p.text);
        for (k, (line, ..)) in p.blocks.iter().enumerate() {
            let to_table = |v: &Vec3| frame.rotation.inverse_transform_vector(v);
            let clear = angle_between(&vectors[k], &vectors[k + 1]) < 179f64.to_radians()
                && arc_margin(m, &to_table(&vectors[k]), &to_table(&vectors[k + 1])) > 1e-3;
            if !clear {
                // The blocks after this one start from wherever it ended
                // (or the run stopped): judge no further.
                break;
            }
            let Some(seg) = out.segments.iter().find(|s| s.line == *line) else {
                break;
            };
            bump(&blocks);
            let (jump, s, before, after) = rotary_jump(m, seg, 256);
            prop_assert!(
                jump < 1e-3,
                "line {line}: the rotary axes jump by {jump}° at s = {s} \
                 ({:?} -> {:?}); program:\n{}",
                &before[3..5],
                &after[3..5],
                p.text
            );
        }
        Ok(())
    });
    assert!(blocks.get() >= 100, "too few blocks judged");
}

/// The bug above on the built-in trunnion-ac (A tilt −120 … 30, C
/// rollover), small and by hand: from A−10 C0, posture control to the
/// vector of A−10 C170. The great circle passes about 0.9° from the C
/// axis, so a continuous motion turns C quickly near the pole but
/// continuously.
#[test]
fn posture_rotary_jump_minimal_example() {
    let mut m = builtin("trunnion-ac").expect("built-in machine");
    m.linear = linear_axes(1e6);
    let frame = m.chain(Side::Table, &joints_with_angles(&m, [-10.0, 0.0]));
    let v = frame.rotation * fk_dir(&m, [-10.0, 170.0]);
    let mut w = Writer::default();
    w.start("G0 X0. Y0. Z0. A-10. C0.");
    w.end();
    w.start("G43.5 H1 P1 X0. Y0. Z0.");
    w.end();
    w.start("G1 X0. Y0. Z0.");
    w.word('I', v.x);
    w.word('J', v.y);
    w.word('K', v.z);
    w.text.push_str(" F1000.");
    let line = w.end();
    let out = run(&m, offsets(Vec3::zeros(), 100.0), &w.text);
    assert!(out.alarm.is_none(), "alarm {:?}", out.alarm);
    let seg = out
        .segments
        .iter()
        .find(|s| s.line == line)
        .expect("segment");
    let (jump, s, before, after) = rotary_jump(&m, seg, 256);
    assert!(
        jump < 1e-3,
        "program:\n{}the rotary axes jump by {jump:.3}° at s = {s:.12}: \
         A{:.6} C{:.6} -> A{:.6} C{:.6} (block from A{:.3} C{:.3} to A{:.3} C{:.3})",
        w.text,
        before[3],
        before[4],
        after[3],
        after[4],
        seg.start[3],
        seg.start[4],
        seg.end[3],
        seg.end[4]
    );
}

/// BUG (kernel, `controller/tcpc.rs` `check_posture_path`): the check
/// that a tool posture control circle stays reachable samples it every
/// `POSTURE_SAMPLE_ANGLE` = 1°, so a circle that leaves the reachable set
/// over less than about 1° of arc passes; inside that gap
/// `segment.rs` `posture_angles` finds no rotary position and silently
/// keeps the rotary angles linear in s, so the tool leaves the great
/// circle with no alarm.
///
/// Machine as in `posture_outside_reach_minimal_example` (reachable: 50° …
/// 90° from +X). Start and end vectors both 50.01° from +X (inside), the
/// azimuth between them chosen so that the great circle comes to 49.999°
/// from +X at its middle: outside over about 0.7° of arc.
///
/// Got: no alarm, the tool 1.9e-4 rad off the circle at s = 0.5.
/// Expected: an alarm at line 3 (as for a circle that leaves the set over
/// more than 1°), or the tool on the circle (impossible here). An exact
/// check is cheap: the angle between the circle and the outer rotary line
/// has a closed-form extreme (see `reach_margin`).
#[test]
fn posture_circle_grazing_outside_reach_minimal_example() {
    let m = nutating_head();
    let (t0, tm) = (50.01f64.to_radians(), 49.999f64.to_radians());
    let half = (tm.tan() / t0.tan()).acos();
    let v = |phi: f64| Vec3::new(t0.cos(), t0.sin() * phi.cos(), t0.sin() * phi.sin());
    let (v0, v1) = (v(-half), v(half));
    let mut w = Writer::default();
    w.start("G0 X0. Y0. Z0.");
    w.end();
    // Head-head: the start-up block may give the vector.
    w.start("G43.5 H1 P1 X0. Y0. Z0.");
    let v0 = Vec3::new(w.word('I', v0.x), w.word('J', v0.y), w.word('K', v0.z)).normalize();
    w.end();
    w.start("G1 X0. Y0. Z0.");
    let v1 = Vec3::new(w.word('I', v1.x), w.word('J', v1.y), w.word('K', v1.z)).normalize();
    w.text.push_str(" F1000.");
    let line = w.end();
    // The oracle: both ends inside, the middle outside.
    assert!(reach_margin(&m, &v0) > 1e-4 && reach_margin(&m, &v1) > 1e-4);
    assert!(reach_margin(&m, &slerp(&v0, &v1, 0.5)) < -1e-5);
    assert!((arc_margin(&m, &v0, &v1) - reach_margin(&m, &slerp(&v0, &v1, 0.5))).abs() < 1e-12);
    let out = run(&m, offsets(Vec3::zeros(), 100.0), &w.text);
    if out.alarm.as_ref().is_some_and(|a| a.line == line) {
        return;
    }
    assert!(out.alarm.is_none(), "alarm {:?}", out.alarm);
    let seg = out
        .segments
        .iter()
        .find(|s| s.line == line)
        .expect("segment");
    let (worst, at) = (0..=1000)
        .map(|i| {
            let s = f64::from(i) / 1000.0;
            (angle_between(&seg.row(&m, s).dir, &slerp(&v0, &v1, s)), s)
        })
        .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a });
    assert!(
        worst < DIR_EPS,
        "program:\n{}no alarm, and the tool is {worst:e} rad off the great circle at s = {at}",
        w.text
    );
}
