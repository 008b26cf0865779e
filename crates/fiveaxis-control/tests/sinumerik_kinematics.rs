//! Seeded properties of the SINUMERIK front end's kinematics, judged by
//! forward kinematics only (`Machine::forward`, `machine-model.md` §3).
//!
//! Every expectation is computed here from the programmed words: tool
//! vectors are made from random rotary angles through `Machine::forward`
//! (so they are reachable), frames are composed from explicit rotation
//! matrices written out below, never from the kernel's own frame or
//! inverse kinematics code.
//!
//! Frames: every program starts with the machine at its reference
//! position (machine zero, every rotary at 0), so the table frame is the
//! machine frame when `TRAORI` starts and a programmed point P is the tip
//! at `W + P` in the table frame (what `Machine::forward` reports).
//!
//! Machines: random SINUMERIK machines with two rotary axes in each
//! arrangement (table/table, head/table, table/head, head/head), rotary
//! lines axis-aligned, at 45° or arbitrary, through points within
//! ±300 mm, no rotary limits, random rollover; linear travel ±1e6 mm;
//! random G54 (±300 mm) and T1 length 50 … 200 mm. Each property runs
//! 64 cases from a fixed seed with no persistence; a failure prints the
//! program.
//!
//! A test marked `#[ignore = "bug: …"]` would show a fault of the kernel as it
//! stands; the reason says what was expected and what happens.

mod common;
/// The machine crate's generators of directions and points.
#[path = "../../fiveaxis-machine/tests/common/mod.rs"]
mod machine_gen;
#[path = "common/random_machines.rs"]
mod random_machines;

use common::{Outcome, check, run};
use fiveaxis_control::Segment;
use fiveaxis_machine::{
    Control, Dynamics, Joints, MAX_AXES, MCodes, Machine, Offsets, Parameters, RotaryAxis, Side,
    ToolOffset, Vec3, principal,
};
use machine_gen::point;
use nalgebra::Matrix3;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestCaseError};
use random_machines::linear_axes;

// ----- tolerances and configuration ------------------------------------------------

/// Tip tolerance, mm (`machine-model.md` §3).
const TIP_EPS: f64 = 1e-6;
/// Direction tolerance, rad (`machine-model.md` §3).
const DIR_EPS: f64 = 1e-9;
/// Joint tolerance of positions programmed directly, mm or degrees.
const JOINT_EPS: f64 = 1e-9;
/// Cases per property.
const CASES: u32 = 64;

fn config() -> Config {
    Config {
        cases: CASES,
        rng_seed: RngSeed::Fixed(0x5109_8400),
        failure_persistence: None,
        max_shrink_iters: 512,
        ..Config::default()
    }
}

// ----- machines -------------------------------------------------------------------

fn five_axis() -> impl Strategy<Value = Machine> {
    random_machines::five_axis(Control::Sinumerik, "random sinumerik")
}

/// A SINUMERIK three-axis machine.
fn three_axis() -> Machine {
    Machine {
        name: "sinumerik 3-axis".into(),
        control: Control::Sinumerik,
        tool_direction: Vec3::z_axis(),
        linear: linear_axes(1e6),
        rotary: Vec::new(),
        params: Parameters::default(),
        m_codes: MCodes::default(),
        bodies: Vec::new(),
        meshes: Vec::new(),
    }
}

/// A five-axis machine or, one time in four, a three-axis one.
fn any_machine() -> impl Strategy<Value = Machine> {
    prop_oneof![3 => five_axis(), 1 => Just(three_axis())]
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

fn joints_with(machine: &Machine, angles: [f64; 2]) -> Joints {
    let mut j = [0.0; MAX_AXES];
    j[machine.rotary_index(0)] = angles[0];
    j[machine.rotary_index(1)] = angles[1];
    j
}

// ----- writing programs -------------------------------------------------------------

/// `x` written with 9 decimals, and the value the control reads.
fn num(x: f64) -> (String, f64) {
    let text = format!("{x:.9}");
    let value = text.parse().expect("formatted number");
    (text, value)
}

/// A program being written, with the values as read.
#[derive(Default)]
struct Writer {
    text: String,
    lines: u32,
}

impl Writer {
    fn line(&mut self, s: &str) -> u32 {
        self.text.push_str(s);
        self.end()
    }

    fn start(&mut self, s: &str) {
        self.text.push_str(s);
    }

    /// ` <address><value>` (`=` before the value when the address is
    /// longer than a letter); returns the value as read.
    fn word(&mut self, address: &str, x: f64) -> f64 {
        let (t, v) = num(x);
        self.text.push(' ');
        self.text.push_str(address);
        if address.len() > 1 {
            self.text.push('=');
        }
        self.text.push_str(&t);
        v
    }

    fn xyz(&mut self, p: &Vec3) -> Vec3 {
        Vec3::new(
            self.word("X", p.x),
            self.word("Y", p.y),
            self.word("Z", p.z),
        )
    }

    fn end(&mut self) -> u32 {
        self.text.push('\n');
        self.lines += 1;
        self.lines
    }
}

// ----- judging -------------------------------------------------------------------------

/// The segment the machine stands at the end of after `line`: the last
/// one of that line or, when the line moves nothing (a block to where the
/// tool already is gives no segment), of the lines before it (the
/// programs here run straight through, lines in order).
fn last_of(out: &Outcome, line: u32) -> Result<&Segment, TestCaseError> {
    out.segments
        .iter()
        .rev()
        .find(|s| s.line <= line)
        .ok_or_else(|| TestCaseError::fail(format!("no segment up to line {line}")))
}

fn no_alarm(out: &Outcome, program: &str) -> Result<(), TestCaseError> {
    if let Some(a) = &out.alarm {
        return Err(TestCaseError::fail(format!(
            "alarm {} on line {}: {}\n{program}",
            a.code, a.line, a.message
        )));
    }
    Ok(())
}

fn angle_between(a: &Vec3, b: &Vec3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// Rotations about X, Y, Z by `deg` degrees, written out.
fn rx(deg: f64) -> Matrix3<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

fn ry(deg: f64) -> Matrix3<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

fn rz(deg: f64) -> Matrix3<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// `ROT X a Y b Z c`: RPY, about Z, then the new Y, then the newest X.
fn rpy(a: f64, b: f64, c: f64) -> Matrix3<f64> {
    rz(c) * ry(b) * rx(a)
}

/// The tip and direction of `joints` with tool length `l`, table frame.
fn pose(m: &Machine, joints: &Joints, l: f64) -> (Vec3, Vec3) {
    let p = m.forward(joints, l);
    (p.tip, p.dir)
}

fn check_tip(got: &Vec3, want: &Vec3, what: &str, program: &str) -> Result<(), TestCaseError> {
    prop_assert!(
        (got - want).norm() <= TIP_EPS,
        "{what}: tip {got} ≠ {want} (off by {:e})\n{program}",
        (got - want).norm()
    );
    Ok(())
}

fn check_dir(got: &Vec3, want: &Vec3, what: &str, program: &str) -> Result<(), TestCaseError> {
    let a = angle_between(got, want);
    prop_assert!(
        a <= DIR_EPS,
        "{what}: direction {got} ≠ {want} ({a:e} rad)\n{program}"
    );
    Ok(())
}

/// Rotary positions equal, modulo 360 on a rollover axis.
fn check_rotary(
    m: &Machine,
    got: &Joints,
    want: [f64; 2],
    what: &str,
    program: &str,
) -> Result<(), TestCaseError> {
    for (k, w) in want.into_iter().enumerate() {
        let i = m.rotary_index(k);
        let d = if m.rotary[k].rollover {
            principal(got[i] - w)
        } else {
            got[i] - w
        };
        prop_assert!(
            d.abs() <= JOINT_EPS,
            "{what}: rotary {} at {} ≠ {w}\n{program}",
            m.rotary[k].name,
            got[i]
        );
    }
    Ok(())
}

// ----- 1. TRAORI with A3 B3 C3 -------------------------------------------------------------

#[derive(Clone, Debug)]
struct VectorBlock {
    tip: Vec3,
    angles: [f64; 2],
    scale: f64,
}

fn vector_blocks() -> impl Strategy<Value = Vec<VectorBlock>> {
    let block = (
        point(200.0),
        (-180.0..180.0f64, -180.0..180.0f64),
        0.5..2.0f64,
    )
        .prop_map(|(tip, (a, b), scale)| VectorBlock {
            tip,
            angles: [a, b],
            scale,
        });
    proptest::collection::vec(block, 2..=6)
}

/// `TRAORI` then `G1 X Y Z A3= B3= C3=` per block, each vector the tool
/// direction of random rotary angles (reachable), scaled. Returns the
/// program and per block its line, programmed point and vector as read.
fn write_vector_program(
    m: &Machine,
    blocks: &[VectorBlock],
    keep_last: Option<Vec3>,
) -> (String, Vec<(u32, Vec3, Vec3)>) {
    let mut w = Writer::default();
    w.line("T1 D1");
    w.line("G54 G17 G90");
    w.line("TRAORI");
    let mut out = Vec::new();
    for b in blocks {
        w.start("G1");
        let p = w.xyz(&b.tip);
        let d = m.forward(&joints_with(m, b.angles), 0.0).dir * b.scale;
        let v = Vec3::new(w.word("A3", d.x), w.word("B3", d.y), w.word("C3", d.z));
        w.start(" F1000");
        let line = w.end();
        out.push((line, p, v));
    }
    if let Some(tip) = keep_last {
        // A block without a vector: the orientation stays.
        w.start("G1");
        let p = w.xyz(&tip);
        let line = w.end();
        let v = out.last().map_or(Vec3::z(), |b| b.2);
        out.push((line, p, v));
    }
    (w.text, out)
}

/// Property 1: at the end of every TRAORI block with a tool vector, the
/// tip is at W + P and the tool along the programmed vector.
#[test]
fn traori_vector_tip_and_direction() {
    let strategy = (five_axis(), point(300.0), 50.0..200.0f64, vector_blocks());
    check(config(), strategy, |(m, work, length, blocks)| {
        let (program, ends) = write_vector_program(&m, &blocks, None);
        let out = run(&m, offsets(work, length), &program);
        no_alarm(&out, &program)?;
        for (line, p, v) in ends {
            let seg = last_of(&out, line)?;
            let (tip, dir) = pose(&m, &seg.end, length);
            let what = format!("line {line}");
            check_tip(&tip, &(work + p), &what, &program)?;
            check_dir(&dir, &v.normalize(), &what, &program)?;
            check_straight(&m, &out, line, length, &program)?;
        }
        Ok(())
    });
}

/// Inside a TRAORI block (G1) the tip runs on the straight line from
/// where it stood to the end, linearly in s (the table frame here is the
/// frame TRAORI started in). Checked when the line is one segment.
fn check_straight(
    m: &Machine,
    out: &Outcome,
    line: u32,
    length: f64,
    program: &str,
) -> Result<(), TestCaseError> {
    let mut of_line = out.segments.iter().filter(|s| s.line == line);
    let (Some(seg), None) = (of_line.next(), of_line.next()) else {
        return Ok(());
    };
    let a = m.forward(&seg.start, length).tip;
    let b = m.forward(&seg.end, length).tip;
    for s in [0.25, 0.5, 0.75] {
        let tip = m.forward(&seg.eval(m, s), length).tip;
        check_tip(
            &tip,
            &(a + (b - a) * s),
            &format!("line {line} at s = {s}"),
            program,
        )?;
    }
    Ok(())
}

/// Property 1b: a TRAORI block without A3 B3 C3 after vector blocks keeps
/// the orientation, and its X Y Z are still the tip in the frame TRAORI
/// started in (the table frame at rotary 0), however far the table has
/// turned since.
#[test]
fn traori_block_without_vector_keeps_frame() {
    let strategy = (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        vector_blocks(),
        point(200.0),
    );
    check(config(), strategy, |(m, work, length, blocks, last)| {
        let (program, ends) = write_vector_program(&m, &blocks, Some(last));
        let out = run(&m, offsets(work, length), &program);
        no_alarm(&out, &program)?;
        let n = ends.len();
        for (k, (line, p, v)) in ends.into_iter().enumerate() {
            let seg = last_of(&out, line)?;
            let (tip, dir) = pose(&m, &seg.end, length);
            let what = format!("line {line}");
            check_tip(&tip, &(work + p), &what, &program)?;
            check_dir(&dir, &v.normalize(), &what, &program)?;
            if k == n - 1 {
                // The rotaries stand still in the block without a vector.
                let i0 = m.rotary_index(0);
                let i1 = m.rotary_index(1);
                prop_assert!(
                    seg.line != line
                        || (seg.start[i0] == seg.end[i0] && seg.start[i1] == seg.end[i1]),
                    "rotaries turn in a block without orientation\n{program}"
                );
            }
        }
        Ok(())
    });
}

/// The smallest program that shows the fault of
/// `traori_block_without_vector_keeps_frame`, on a table/table machine
/// with both rotary lines through the origin.
#[test]
fn traori_block_without_vector_minimal_example() {
    let text = r#"
name = "table A over table C"
type = "table"
control = "sinumerik"

[[linear]]
name = "X"
min = -1000.0
max = 1000.0

[[linear]]
name = "Y"
min = -1000.0
max = 1000.0

[[linear]]
name = "Z"
min = -1000.0
max = 1000.0

[[rotary]]
name = "A"
on = "table"
axis = [1, 0, 0]
center = [0, 0, 0]
min = -120.0
max = 120.0

[[rotary]]
name = "C"
on = "table"
axis = [0, 0, 1]
center = [0, 0, 50]
rollover = true
"#;
    let m = Machine::from_toml(text).expect("machine");
    let program = "T1 D1\nG54\nTRAORI\nG1 X10 Y0 Z0 A3=0 B3=-1 C3=0 F1000\nG1 X20 Y5 Z3\n";
    let out = run(&m, offsets(Vec3::zeros(), 100.0), program);
    assert!(out.alarm.is_none(), "{:?}", out.alarm);
    let first = out.segments.iter().rfind(|s| s.line == 4).expect("line 4");
    let (tip, dir) = pose(&m, &first.end, 100.0);
    assert!((tip - Vec3::new(10.0, 0.0, 0.0)).norm() < TIP_EPS, "{tip}");
    assert!((dir - Vec3::new(0.0, -1.0, 0.0)).norm() < DIR_EPS, "{dir}");
    let last = out.segments.iter().rfind(|s| s.line == 5).expect("line 5");
    let (tip, dir) = pose(&m, &last.end, 100.0);
    assert!((dir - Vec3::new(0.0, -1.0, 0.0)).norm() < DIR_EPS, "{dir}");
    assert!(
        (tip - Vec3::new(20.0, 5.0, 3.0)).norm() < TIP_EPS,
        "tip {tip}, want (20, 5, 3)"
    );
}

// ----- 2. TRAORI with rotary words ------------------------------------------------------------

/// Property 2: `G1 X Y Z <rotary>=` under TRAORI: the rotary axes at the
/// programmed angles, the tip at W + P, the tool along the direction the
/// programmed angles give.
#[test]
fn traori_rotary_words_tip() {
    let step = || -169.0..169.0f64;
    let blocks = proptest::collection::vec((point(200.0), (step(), step())), 2..=6);
    let strategy = (five_axis(), point(300.0), 50.0..200.0f64, blocks);
    check(config(), strategy, |(m, work, length, blocks)| {
        let names = [m.rotary[0].name, m.rotary[1].name];
        let mut w = Writer::default();
        w.line("T1 D1");
        w.line("G54 G17 G90");
        w.line("TRAORI");
        let mut q = [0.0, 0.0];
        let mut ends = Vec::new();
        for (tip, (da, db)) in &blocks {
            w.start("G1");
            let p = w.xyz(tip);
            // Steps under 170°: the short way on an endless axis is the
            // step itself.
            let a = w.word(&names[0].to_string(), q[0] + da);
            let b = w.word(&names[1].to_string(), q[1] + db);
            q = [a, b];
            w.start(" F1000");
            let line = w.end();
            ends.push((line, p, q));
        }
        let program = w.text;
        let out = run(&m, offsets(work, length), &program);
        no_alarm(&out, &program)?;
        for (line, p, q) in ends {
            let seg = last_of(&out, line)?;
            let what = format!("line {line}");
            check_rotary(&m, &seg.end, q, &what, &program)?;
            let (tip, dir) = pose(&m, &seg.end, length);
            check_tip(&tip, &(work + p), &what, &program)?;
            check_straight(&m, &out, line, length, &program)?;
            let want_dir = m.forward(&joints_with(&m, q), 0.0).dir;
            check_dir(&dir, &want_dir, &what, &program)?;
        }
        Ok(())
    });
}

// ----- 3. TRANS / ROT / AROT -------------------------------------------------------------------

#[derive(Clone, Debug)]
struct FrameCase {
    variant: u8,
    t1: Vec3,
    angles: [f64; 3],
    t2: Vec3,
    rpl: f64,
    points: Vec<Vec3>,
}

fn frame_case() -> impl Strategy<Value = FrameCase> {
    let angle = || -180.0..180.0f64;
    (
        0u8..3,
        point(200.0),
        (angle(), angle(), angle()),
        point(200.0),
        angle(),
        proptest::collection::vec(point(200.0), 1..=4),
    )
        .prop_map(|(variant, t1, (a, b, c), t2, rpl, points)| FrameCase {
            variant,
            t1,
            angles: [a, b, c],
            t2,
            rpl,
            points,
        })
}

/// Property 3: programmable frames without TRAORI, rotaries at 0. Three
/// kinds of frame program, with the map each makes (R = Rz·Ry·Rx):
///
/// 0. `TRANS t1` / `AROT X a Y b Z c` / `ATRANS t2`: p ↦ t1 + R·(t2 + p);
/// 1. `TRANS t1` / `ROT X a Y b Z c` (replaces the frame, shift too):
///    p ↦ R·p;
/// 2. `TRANS t1` / `AROT RPL=d` (G17: about Z) / `AROT X a`:
///    p ↦ t1 + Rz(d)·Rx(a)·p.
///
/// The tip of each following `G1 X Y Z` is at W + map(P).
#[test]
fn programmable_frames_map_points() {
    let strategy = (any_machine(), point(300.0), 50.0..200.0f64, frame_case());
    check(config(), strategy, |(m, work, length, fc)| {
        let mut w = Writer::default();
        w.line("T1 D1");
        w.line("G54 G17 G90");
        w.start("TRANS");
        let t1 = w.xyz(&fc.t1);
        w.end();
        let map: Box<dyn Fn(&Vec3) -> Vec3> = match fc.variant {
            0 => {
                w.start("AROT");
                let a = w.word("X", fc.angles[0]);
                let b = w.word("Y", fc.angles[1]);
                let c = w.word("Z", fc.angles[2]);
                w.end();
                w.start("ATRANS");
                let t2 = w.xyz(&fc.t2);
                w.end();
                let r = rpy(a, b, c);
                Box::new(move |p| t1 + r * (t2 + p))
            }
            1 => {
                w.start("ROT");
                let a = w.word("X", fc.angles[0]);
                let b = w.word("Y", fc.angles[1]);
                let c = w.word("Z", fc.angles[2]);
                w.end();
                let r = rpy(a, b, c);
                Box::new(move |p| r * p)
            }
            _ => {
                w.start("AROT");
                let d = w.word("RPL", fc.rpl);
                w.end();
                w.start("AROT");
                let a = w.word("X", fc.angles[0]);
                w.end();
                let r = rz(d) * rx(a);
                Box::new(move |p| t1 + r * p)
            }
        };
        let mut ends = Vec::new();
        for p in &fc.points {
            w.start("G1");
            let p = w.xyz(p);
            w.start(" F1000");
            let line = w.end();
            ends.push((line, map(&p)));
        }
        let program = w.text;
        let out = run(&m, offsets(work, length), &program);
        no_alarm(&out, &program)?;
        for (line, want) in ends {
            let seg = last_of(&out, line)?;
            let (tip, dir) = pose(&m, &seg.end, length);
            let what = format!("line {line}");
            check_tip(&tip, &(work + want), &what, &program)?;
            check_dir(&dir, &Vec3::z(), &what, &program)?;
        }
        Ok(())
    });
}

// ----- 4. CYCLE800 mode 57 --------------------------------------------------------------------

/// Property 4: `CYCLE800(0,"TC1",0,57,X0,Y0,Z0,A,B,C,X1,Y1,Z1,1)` turns
/// the tool along the frame's Z, R·ez with R = Rx(A)·Ry(B)·Rz(C) (turns
/// about the turned axes), and a following `G1 X Y Z` puts the tip at
/// W + X0 + R·(X1 + P). The angles A, B are chosen so that R·ez is the
/// tool direction of random rotary angles (reachable): with
/// Rx(a)·Ry(b)·ez = (sin b, −sin a·cos b, cos a·cos b), b = asin(d.x),
/// a = atan2(−d.y, d.z).
#[test]
fn cycle800_mode57_aligns_tool_and_maps_points() {
    let angle = || -180.0..180.0f64;
    let strategy = (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        (angle(), angle(), angle()),
        (point(100.0), point(100.0)),
        proptest::collection::vec(point(150.0), 1..=3),
    );
    check(
        config(),
        strategy,
        |(m, work, length, (q0, q1, c), (x0, x1), points)| {
            let d = m.forward(&joints_with(&m, [q0, q1]), 0.0).dir;
            let b = d.x.clamp(-1.0, 1.0).asin().to_degrees();
            let a = (-d.y).atan2(d.z).to_degrees();
            let mut w = Writer::default();
            w.line("T1 D1");
            w.line("G54 G17 G90");
            let f = |x: f64| num(x);
            let args = [x0.x, x0.y, x0.z, a, b, c, x1.x, x1.y, x1.z].map(f);
            let text: Vec<&str> = args.iter().map(|(t, _)| t.as_str()).collect();
            let v: Vec<f64> = args.iter().map(|(_, v)| *v).collect();
            let swivel = w.line(&format!("CYCLE800(0,\"TC1\",0,57,{},1)", text.join(",")));
            let x0 = Vec3::new(v[0], v[1], v[2]);
            let r = rx(v[3]) * ry(v[4]) * rz(v[5]);
            let x1 = Vec3::new(v[6], v[7], v[8]);
            let mut ends = Vec::new();
            for p in &points {
                w.start("G1");
                let p = w.xyz(p);
                w.start(" F1000");
                let line = w.end();
                ends.push((line, x0 + r * (x1 + p)));
            }
            let program = w.text;
            let out = run(&m, offsets(work, length), &program);
            no_alarm(&out, &program)?;
            let z = r * Vec3::z();
            let seg = last_of(&out, swivel)?;
            let (_, dir) = pose(&m, &seg.end, length);
            check_dir(&dir, &z, "after CYCLE800", &program)?;
            for (line, want) in ends {
                let seg = last_of(&out, line)?;
                let (tip, dir) = pose(&m, &seg.end, length);
                let what = format!("line {line}");
                check_tip(&tip, &(work + want), &what, &program)?;
                check_dir(&dir, &z, &what, &program)?;
            }
            Ok(())
        },
    );
}

// ----- 5. G53 / SUPA ------------------------------------------------------------------------------

/// Property 5: `G0 G53 …` and `G1 SUPA …` with a work offset and a
/// programmable frame in force (no tool length active, D0): the machine
/// position at the block's end is the programmed machine coordinates,
/// rotary ones included (modulo 360 on an endless axis).
#[test]
fn g53_and_supa_program_machine_coordinates() {
    let angle = || -179.0..179.0f64;
    let target = (point(400.0), (angle(), angle()));
    let strategy = (
        any_machine(),
        point(300.0),
        (point(100.0), -90.0..90.0f64),
        proptest::collection::vec((target, any::<bool>()), 1..=4),
    );
    check(config(), strategy, |(m, work, (shift, turn), targets)| {
        let names: Vec<String> = m.rotary.iter().map(|r| r.name.to_string()).collect();
        let mut w = Writer::default();
        w.line("T1 D0");
        w.line("G54 G17 G90");
        w.start("TRANS");
        w.xyz(&shift);
        w.end();
        w.start("AROT");
        w.word("Z", turn);
        w.end();
        let mut ends = Vec::new();
        let mut rotary = [0.0, 0.0];
        for ((xyz, (a, b)), supa) in &targets {
            w.start(if *supa { "G1 SUPA" } else { "G0 G53" });
            let p = w.xyz(xyz);
            if names.len() == 2 {
                rotary = [w.word(&names[0], *a), w.word(&names[1], *b)];
            }
            if *supa {
                w.start(" F1000");
            }
            let line = w.end();
            ends.push((line, p, rotary));
        }
        let program = w.text;
        let out = run(&m, offsets(work, 100.0), &program);
        no_alarm(&out, &program)?;
        for (line, p, q) in ends {
            let seg = last_of(&out, line)?;
            let what = format!("line {line}");
            for i in 0..3 {
                prop_assert!(
                    (seg.end[i] - p[i]).abs() <= JOINT_EPS,
                    "{what}: axis {i} at {} ≠ {}\n{program}",
                    seg.end[i],
                    p[i]
                );
            }
            if m.rotary.len() == 2 {
                check_rotary(&m, &seg.end, q, &what, &program)?;
            }
        }
        Ok(())
    });
}

/// `G53` with a tool length active: on a SINUMERIK 840D with the default
/// MD10760 `$MN_G53_TOOLCORR = 0`, "G53/G153/SUPA is non-modal suppression
/// of zero offsets, tool length compensation and tool radius compensation,
/// however, remain active" (840D ISO milling programming manual 04.07,
/// §3.1.1; real programs write `G0 G53 D0 Z265` to move the spindle
/// itself). With T1 (100 mm) D1 and the tool vertical, `G0 G53 X50 Y60 Z70`
/// should stop the spindle at Z 170 (tip at machine Z 70).
#[test]
fn g53_keeps_tool_length_active() {
    let m = three_axis();
    let program = "T1 D1\nG54\nG0 G53 X50 Y60 Z70\n";
    let out = run(&m, offsets(Vec3::new(10.0, 20.0, 30.0), 100.0), program);
    assert!(out.alarm.is_none(), "{:?}", out.alarm);
    let seg = out.segments.last().expect("segment");
    assert_eq!(&seg.end[..3], &[50.0, 60.0, 170.0]);
}

// ----- 6. TRAFOOF ------------------------------------------------------------------------------------

/// Property 6: after `TRAFOOF` the next block's rotary axes keep the
/// angles the TRAORI block left, and its X Y Z place the tip at W + P in
/// the workpiece coordinates that do not turn with the table (machine
/// frame: the table map of the end position applied to the table-frame
/// tip): the tool length stays along the tool.
#[test]
fn trafoof_keeps_rotaries_and_length_along_tool() {
    let step = || -169.0..169.0f64;
    let strategy = (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        (point(200.0), (step(), step())),
        point(200.0),
    );
    check(config(), strategy, |(m, work, length, (p1, (a, b)), p2)| {
        let names = [m.rotary[0].name.to_string(), m.rotary[1].name.to_string()];
        let mut w = Writer::default();
        w.line("T1 D1");
        w.line("G54 G17 G90");
        w.line("TRAORI");
        w.start("G1");
        w.xyz(&p1);
        let q = [w.word(&names[0], a), w.word(&names[1], b)];
        w.start(" F1000");
        let traori_line = w.end();
        w.line("TRAFOOF");
        w.start("G1");
        let p = w.xyz(&p2);
        w.start(" F1000");
        let line = w.end();
        let program = w.text;
        let out = run(&m, offsets(work, length), &program);
        no_alarm(&out, &program)?;
        let before = last_of(&out, traori_line)?;
        check_rotary(&m, &before.end, q, "TRAORI block", &program)?;
        let seg = last_of(&out, line)?;
        for k in 0..2 {
            let i = m.rotary_index(k);
            prop_assert!(
                seg.start[i] == before.end[i] && seg.end[i] == before.end[i],
                "rotary {} moves after TRAFOOF: {} → {} (was {})\n{program}",
                m.rotary[k].name,
                seg.start[i],
                seg.end[i],
                before.end[i]
            );
        }
        let (tip_table, dir) = pose(&m, &seg.end, length);
        let (_, dir_before) = pose(&m, &before.end, length);
        check_dir(&dir, &dir_before, "after TRAFOOF", &program)?;
        let table = m.chain(Side::Table, &seg.end);
        let tip_machine = table.transform_point(&tip_table.into()).coords;
        check_tip(&tip_machine, &(work + p), "after TRAFOOF", &program)?;
        Ok(())
    });
}

// ----- 7. G70 inch --------------------------------------------------------------------------------

/// A value in inches with 6 decimals, and the same in mm written with 7
/// (exact: 25.4 × a 6-decimal number has at most 7 decimals).
fn inch_and_mm(x: f64) -> (String, String) {
    let inch = format!("{x:.6}");
    let v: f64 = inch.parse().expect("number");
    // Integer arithmetic in micro-inches, so the mm text is exact.
    let micro = (v * 1e6).round() as i64;
    let tenth_micro_mm = micro * 254; // 1e-7 mm units
    let sign = if tenth_micro_mm < 0 { "-" } else { "" };
    let a = tenth_micro_mm.unsigned_abs();
    let mm = format!("{sign}{}.{:07}", a / 10_000_000, a % 10_000_000);
    (inch, mm)
}

/// Property 7: a program in G70 with lengths in inches runs exactly as
/// the same program in G71 with every length ×25.4: positions, frames,
/// arc centres and radii, cycle planes, the swivel cycle's shifts.
#[test]
fn g70_inch_is_mm_times_25_4() {
    let p = || point(6.0);
    let strategy = (
        any_machine(),
        point(300.0),
        50.0..200.0f64,
        (p(), p(), p(), p()),
        (0.5..3.0f64, 0.5..3.0f64, -180.0..180.0f64),
    );
    check(
        config(),
        strategy,
        |(m, work, length, (shift, a, b, c), (radius, cr, turn))| {
            let write = |inch: bool| {
                let v = |x: f64| {
                    let (i, mm) = inch_and_mm(x);
                    if inch { i } else { mm }
                };
                let xyz = |q: &Vec3| format!("X{} Y{} Z{}", v(q.x), v(q.y), v(q.z));
                let mut t = String::new();
                t.push_str("T1 D1\nG54 G17 G90\n");
                t.push_str(if inch { "G70\n" } else { "G71\n" });
                t.push_str(&format!("TRANS {}\n", xyz(&shift)));
                t.push_str(&format!("AROT Z{turn:.6}\n"));
                t.push_str(&format!("G0 {}\n", xyz(&a)));
                t.push_str(&format!("G1 {} F100\n", xyz(&b)));
                // A full circle about a centre `radius` along X.
                t.push_str(&format!("G2 X{} Y{} I{} J0\n", v(b.x), v(b.y), v(radius)));
                // A quarter circle of radius cr and back the long way.
                t.push_str(&format!(
                    "G3 X{} Y{} CR={}\n",
                    v(b.x + cr),
                    v(b.y + cr),
                    v(cr)
                ));
                t.push_str(&format!("G3 X{} Y{} CR=-{}\n", v(b.x), v(b.y), v(cr)));
                t.push_str(&format!(
                    "MCALL CYCLE81({},{},{},{})\n",
                    v(c.z + 1.0),
                    v(c.z),
                    v(0.1),
                    v(c.z - 0.5)
                ));
                t.push_str(&format!("G0 X{} Y{}\n", v(c.x), v(c.y)));
                t.push_str("MCALL\n");
                t.push_str(&format!("G1 X=IC({}) Y=AC({})\n", v(0.25), v(c.y + 0.5)));
                t
            };
            let inch = write(true);
            let mm = write(false);
            let a_out = run(&m, offsets(work, length), &inch);
            let b_out = run(&m, offsets(work, length), &mm);
            let codes = |o: &Outcome| o.alarm.as_ref().map(|a| (a.code.to_string(), a.line));
            prop_assert_eq!(
                codes(&a_out),
                codes(&b_out),
                "alarms differ\n{}\n{}",
                inch,
                mm
            );
            no_alarm(&a_out, &inch)?;
            prop_assert_eq!(
                a_out.segments.len(),
                b_out.segments.len(),
                "segment counts differ\n{}\n{}",
                inch,
                mm
            );
            for (x, y) in a_out.segments.iter().zip(&b_out.segments) {
                for s in [0.25, 0.5, 1.0] {
                    let (jx, jy) = (x.eval(&m, s), y.eval(&m, s));
                    let d = jx
                        .iter()
                        .zip(&jy)
                        .map(|(p, q)| (p - q).abs())
                        .fold(0.0, f64::max);
                    prop_assert!(
                        d <= 1e-9,
                        "line {} at s = {s}: {jx:?} ≠ {jy:?}\n{}\n{}",
                        x.line,
                        inch,
                        mm
                    );
                }
            }
            Ok(())
        },
    );
}

/// CYCLE800's shifts X0 and X1 are lengths: in G70 they are inches.
#[test]
fn g70_cycle800_shifts_are_inches() {
    let strategy = (five_axis(), point(300.0), (point(4.0), point(4.0)));
    check(config(), strategy, |(m, work, (x0, x1))| {
        let write = |inch: bool| {
            let v = |x: f64| {
                let (i, mm) = inch_and_mm(x);
                if inch { i } else { mm }
            };
            format!(
                "T1 D1\nG54 G17 G90\n{}\nCYCLE800(0,\"TC1\",0,57,{},{},{},0,0,30,{},{},{},0)\n\
                 G1 X{} Y{} Z{} F100\n",
                if inch { "G70" } else { "G71" },
                v(x0.x),
                v(x0.y),
                v(x0.z),
                v(x1.x),
                v(x1.y),
                v(x1.z),
                v(1.0),
                v(-2.0),
                v(0.5)
            )
        };
        let (inch, mm) = (write(true), write(false));
        let a = run(&m, offsets(work, 100.0), &inch);
        let b = run(&m, offsets(work, 100.0), &mm);
        no_alarm(&a, &inch)?;
        no_alarm(&b, &mm)?;
        let ea = a.segments.last().map(|s| s.end);
        let eb = b.segments.last().map(|s| s.end);
        let (Some(ea), Some(eb)) = (ea, eb) else {
            return Err(TestCaseError::fail("no segment"));
        };
        let d = ea
            .iter()
            .zip(&eb)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max);
        prop_assert!(d <= 1e-9, "{ea:?} ≠ {eb:?}\n{inch}\n{mm}");
        Ok(())
    });
}

// ----- 8. CYCLE800 additive, with TRANS inside, and its reset ---------------------------------------

/// Property 8: two swivel frames, the second additive (`_ST` = 1), then a
/// programmable `TRANS` inside them, tool not turned (`_DIR` = 0). The
/// swivel frames chain as S = S1 ∘ S2 with Sk: p ↦ X0k + Rk·(X1k + p),
/// Rk = Rx(Ak)·Ry(Bk)·Rz(Ck); the programmable frame acts inside:
/// P ↦ S(t + P). After `CYCLE800()` only the programmable frame is left:
/// P ↦ t + P.
#[test]
fn cycle800_additive_frames_and_reset() {
    let angle = || -180.0..180.0f64;
    let swivel = || ((angle(), angle(), angle()), point(100.0), point(100.0));
    let strategy = (
        any_machine(),
        point(300.0),
        (swivel(), swivel()),
        point(50.0),
        (point(100.0), point(100.0)),
    );
    check(config(), strategy, |(m, work, (s1, s2), t, (p1, p2))| {
        let mut w = Writer::default();
        w.line("T1 D1");
        w.line("G54 G17 G90");
        let mut maps = Vec::new();
        for (k, ((a, b, c), x0, x1)) in [s1, s2].into_iter().enumerate() {
            let args = [x0.x, x0.y, x0.z, a, b, c, x1.x, x1.y, x1.z].map(num);
            let text: Vec<&str> = args.iter().map(|(t, _)| t.as_str()).collect();
            let v: Vec<f64> = args.iter().map(|(_, v)| *v).collect();
            w.line(&format!("CYCLE800(0,\"TC1\",{k},57,{},0)", text.join(",")));
            maps.push((
                Vec3::new(v[0], v[1], v[2]),
                rx(v[3]) * ry(v[4]) * rz(v[5]),
                Vec3::new(v[6], v[7], v[8]),
            ));
        }
        w.start("TRANS");
        let t = w.xyz(&t);
        w.end();
        w.start("G1");
        let p1 = w.xyz(&p1);
        w.start(" F1000");
        let line1 = w.end();
        w.line("CYCLE800()");
        w.start("G1");
        let p2 = w.xyz(&p2);
        let line2 = w.end();
        let program = w.text;
        let (x0a, ra, x1a) = maps[0];
        let (x0b, rb, x1b) = maps[1];
        let s = |p: Vec3| x0a + ra * (x1a + x0b + rb * (x1b + p));
        let out = run(&m, offsets(work, 120.0), &program);
        no_alarm(&out, &program)?;
        let seg = last_of(&out, line1)?;
        let (tip, _) = pose(&m, &seg.end, 120.0);
        check_tip(&tip, &(work + s(t + p1)), "in the swivel frames", &program)?;
        let seg = last_of(&out, line2)?;
        let (tip, _) = pose(&m, &seg.end, 120.0);
        check_tip(&tip, &(work + t + p2), "after CYCLE800()", &program)?;
        Ok(())
    });
}

// ----- 9. DC / ACP / ACN on an endless rotary axis ------------------------------------------------------

fn rotary_c_machine() -> Machine {
    let mut m = three_axis();
    m.rotary.push(RotaryAxis {
        name: 'C',
        on: Side::Table,
        axis: Vec3::z_axis(),
        center: Vec3::zeros(),
        limits: None,
        rollover: true,
        dynamics: Dynamics::ROTARY_DEFAULT,
    });
    m
}

/// Property 9: `C=DC(v)` turns the shorter way, `C=ACP(v)` in the
/// positive direction, `C=ACN(v)` in the negative one, each less than a
/// whole turn, to v modulo 360; `C=IC(d)` by d. The travel of each block
/// is computed here from the previous position modulo 360.
#[test]
fn endless_rotary_direction_words() {
    let step = (0u8..4, 0.0..360.0f64);
    let strategy = proptest::collection::vec(step, 1..=8);
    check(config(), strategy, |steps| {
        let m = rotary_c_machine();
        let mut w = Writer::default();
        w.line("G54 G17 G90");
        let mut c = 0.0f64;
        let mut ends = Vec::new();
        for (mode, v) in steps {
            let (text, v) = num(v);
            let from = c.rem_euclid(360.0);
            let (word, travel) = match mode {
                0 => {
                    let d = (v - from).rem_euclid(360.0);
                    ("DC", if d > 180.0 { d - 360.0 } else { d })
                }
                1 => ("ACP", (v - from).rem_euclid(360.0)),
                2 => ("ACN", -(from - v).rem_euclid(360.0)),
                _ => ("IC", v - 180.0),
            };
            let arg = if mode == 3 { num(v - 180.0).0 } else { text };
            // Skip the cases where the direction is a matter of rounding
            // (a half turn for DC, no travel at all).
            if travel.abs() < 1e-6 || (mode == 0 && (travel.abs() - 180.0).abs() < 1e-6) {
                continue;
            }
            let line = w.line(&format!("G0 C={word}({arg})"));
            c += travel;
            ends.push((line, travel, c));
        }
        let program = w.text;
        let out = run(&m, Offsets::default(), &program);
        no_alarm(&out, &program)?;
        for (line, travel, c) in ends {
            let seg = last_of(&out, line)?;
            prop_assert_eq!(seg.line, line, "line {} does not move\n{}", line, program);
            let d = seg.end[3] - seg.start[3];
            prop_assert!(
                (d - travel).abs() < 1e-6,
                "line {line}: travel {d} ≠ {travel}\n{program}"
            );
            prop_assert!(
                principal(seg.end[3] - c).abs() < 1e-6,
                "line {line}: C {} ≠ {c} (mod 360)\n{program}",
                seg.end[3]
            );
        }
        Ok(())
    });
}

// ----- 10. CYCLE800 _DIR: the lower or the higher solution -------------------------------------------------

const TABLE_AC: &str = r#"
name = "table A (limited) carrying endless table C"
type = "table"
control = "sinumerik"

[[linear]]
name = "X"
min = -1000.0
max = 1000.0

[[linear]]
name = "Y"
min = -1000.0
max = 1000.0

[[linear]]
name = "Z"
min = -1000.0
max = 1000.0

[[rotary]]
name = "A"
on = "table"
axis = [1, 0, 0]
center = [0, 0, 0]
min = -120.0
max = 120.0

[[rotary]]
name = "C"
on = "table"
axis = [0, 0, 1]
center = [0, 0, 0]
rollover = true
"#;

/// `CYCLE800(…,57,…,A −30,…,_DIR)` on a table A / C machine: the frame's
/// Z is Rx(−30°)·ez = (0, ½, √3/2), which the table reaches with A = +30°,
/// C = 0 and with A = −30°, C = 180° (both checked by forward kinematics
/// here). `_DIR` picks the solution with the lower (−1) or higher (+1)
/// value of the first rotary axis (brief §5; `Command::AlignTool`).
#[test]
fn cycle800_dir_picks_lower_or_higher_solution() {
    let m = Machine::from_toml(TABLE_AC).expect("machine");
    let want_dir = Vec3::new(0.0, 0.5, 3f64.sqrt() / 2.0);
    for (q, name) in [([30.0, 0.0], "A 30 C 0"), ([-30.0, 180.0], "A -30 C 180")] {
        let d = m.forward(&joints_with(&m, q), 0.0).dir;
        assert!((d - want_dir).norm() < 1e-12, "{name}: {d}");
    }
    let mut got = Vec::new();
    for (dir, want_a) in [(-1, -30.0), (1, 30.0)] {
        let program =
            format!("T1 D1\nG54 G17 G90\nCYCLE800(0,\"TC1\",0,57,0,0,0,-30,0,0,0,0,0,{dir})\n");
        let out = run(&m, offsets(Vec3::zeros(), 100.0), &program);
        assert!(out.alarm.is_none(), "{program}: {:?}", out.alarm);
        let seg = out.segments.last().expect("segment");
        let (_, d) = pose(&m, &seg.end, 100.0);
        assert!((d - want_dir).norm() < DIR_EPS, "{program}: direction {d}");
        got.push((dir, want_a, seg.end[3], seg.end[4]));
    }
    assert!(
        got.iter().all(|(_, want, a, _)| (a - want).abs() < 1e-6),
        "(_DIR, A wanted, A got, C got): {got:?}"
    );
}

// ----- 11. TRAORI with A2 B2 C2 ---------------------------------------------------------------------------

/// Property 11: under TRAORI the angles A2 B2 C2 give the tool direction
/// R·ez, with ORIEULER (the default) R = Rz(A2)·Rx(B2)·Rz(C2) (Euler
/// Z, X′, Z″, brief §4, assumed there) and with ORIRPY
/// R = Rz(C2)·Ry(B2)·Rx(A2) (about X, then Y, then Z of the fixed frame).
/// The angles are made from a reachable direction d: Euler
/// Rz(a)·Rx(b)·ez = (sin a sin b, −cos a sin b, cos b), so b = acos d.z,
/// a = atan2(d.x, −d.y), C2 random; RPY with C2 = c random, u = Rz(−c)·d,
/// Ry(b)·Rx(a)·ez = (sin b cos a, −sin a, cos b cos a), so a = asin(−u.y),
/// b = atan2(u.x, u.z).
#[test]
fn traori_euler_and_rpy_angles() {
    let angle = || -180.0..180.0f64;
    let block = (point(200.0), (angle(), angle()), angle());
    let strategy = (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        any::<bool>(),
        proptest::collection::vec(block, 1..=4),
    );
    check(config(), strategy, |(m, work, length, rpy_mode, blocks)| {
        let mut w = Writer::default();
        w.line("T1 D1");
        w.line("G54 G17 G90");
        w.line(if rpy_mode { "ORIRPY" } else { "ORIEULER" });
        w.line("TRAORI");
        let mut ends = Vec::new();
        for (tip, (q0, q1), third) in blocks {
            let d = m.forward(&joints_with(&m, [q0, q1]), 0.0).dir;
            let (a, b, c) = if rpy_mode {
                let u = rz(-third) * d;
                let a = (-u.y).clamp(-1.0, 1.0).asin().to_degrees();
                let b = u.x.atan2(u.z).to_degrees();
                (a, b, third)
            } else {
                let b = d.z.clamp(-1.0, 1.0).acos().to_degrees();
                let a = d.x.atan2(-d.y).to_degrees();
                (a, b, third)
            };
            w.start("G1");
            let p = w.xyz(&tip);
            let (a, b, c) = (w.word("A2", a), w.word("B2", b), w.word("C2", c));
            w.start(" F1000");
            let line = w.end();
            let r = if rpy_mode {
                rz(c) * ry(b) * rx(a)
            } else {
                rz(a) * rx(b) * rz(c)
            };
            ends.push((line, p, r * Vec3::z()));
        }
        let program = w.text;
        let out = run(&m, offsets(work, length), &program);
        no_alarm(&out, &program)?;
        for (line, p, v) in ends {
            let seg = last_of(&out, line)?;
            let (tip, dir) = pose(&m, &seg.end, length);
            let what = format!("line {line}");
            check_tip(&tip, &(work + p), &what, &program)?;
            // The angles are written with 9 decimals: the direction they
            // give is within ~1e-11 rad of the one they were made from.
            check_dir(&dir, &v, &what, &program)?;
        }
        Ok(())
    });
}

// ----- 12. Drilling in the swivelled plane -------------------------------------------------------------------

/// Property 12: after `CYCLE800(…,57,…,_DIR=1)` a modal `CYCLE81(RTP,
/// RFP, SDIS, DP)` drills along the swivelled Z: at each position P (X Y
/// in the swivelled plane) the tip goes, in the swivelled frame S, to
/// (P, z now), (P, RFP + SDIS), (P, DP), (P, RTP), that is to
/// W + S(those points) on the table, the tool along S's Z throughout.
#[test]
fn drilling_cycle_in_the_swivelled_plane() {
    let angle = || -180.0..180.0f64;
    let strategy = (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        (angle(), angle(), angle()),
        point(100.0),
        (0.0..20.0f64, 1.0..5.0f64, 1.0..30.0f64, 1.0..20.0f64),
        proptest::collection::vec((-100.0..100.0f64, -100.0..100.0f64), 1..=3),
    );
    check(
        config(),
        strategy,
        |(m, work, length, (q0, q1, c), x0, (rfp, sdis, depth, rise), holes)| {
            let d = m.forward(&joints_with(&m, [q0, q1]), 0.0).dir;
            let b = d.x.clamp(-1.0, 1.0).asin().to_degrees();
            let a = (-d.y).atan2(d.z).to_degrees();
            let mut w = Writer::default();
            w.line("T1 D1");
            w.line("G54 G17 G90");
            let args = [x0.x, x0.y, x0.z, a, b, c].map(num);
            let text: Vec<&str> = args.iter().map(|(t, _)| t.as_str()).collect();
            let v: Vec<f64> = args.iter().map(|(_, v)| *v).collect();
            let swivel = w.line(&format!(
                "CYCLE800(0,\"TC1\",0,57,{},0,0,0,1)",
                text.join(",")
            ));
            let origin = Vec3::new(v[0], v[1], v[2]);
            let r = rx(v[3]) * ry(v[4]) * rz(v[5]);
            let s = |p: Vec3| work + origin + r * p;
            let (rfp_t, rfp) = num(rfp);
            let (sdis_t, sdis) = num(sdis);
            let (dp_t, dp) = num(rfp - depth);
            let (rtp_t, rtp) = num(rfp + rise);
            w.start("G0 X0 Y0");
            let z0 = w.word("Z", rtp);
            w.end();
            w.line("F500");
            w.line(&format!("MCALL CYCLE81({rtp_t},{rfp_t},{sdis_t},{dp_t})"));
            let mut want = vec![s(Vec3::new(0.0, 0.0, z0))];
            let mut z = z0;
            for (x, y) in holes {
                w.start("G0");
                let (x, y) = (w.word("X", x), w.word("Y", y));
                w.end();
                for level in [z, rfp + sdis, dp, rtp] {
                    want.push(s(Vec3::new(x, y, level)));
                }
                z = rtp;
            }
            w.line("MCALL");
            let program = w.text;
            let out = run(&m, offsets(work, length), &program);
            no_alarm(&out, &program)?;
            // A move to where the tip already is gives no segment: leave
            // such points out of the expected list.
            let mut at = pose(&m, &last_of(&out, swivel)?.end, length).0;
            want.retain(|p| {
                let moves = (p - at).norm() > 1e-9;
                at = *p;
                moves
            });
            let z_axis = r * Vec3::z();
            let got: Vec<(Vec3, Vec3)> = out
                .segments
                .iter()
                .filter(|seg| seg.line > swivel && seg.moves())
                .map(|seg| pose(&m, &seg.end, length))
                .collect();
            prop_assert_eq!(
                got.len(),
                want.len(),
                "moves after the swivel: {:?}\n{}",
                got.iter().map(|g| g.0).collect::<Vec<_>>(),
                program
            );
            for (k, ((tip, dir), want)) in got.iter().zip(&want).enumerate() {
                let what = format!("move {k} after the swivel");
                check_tip(tip, want, &what, &program)?;
                check_dir(dir, &z_axis, &what, &program)?;
            }
            Ok(())
        },
    );
}
