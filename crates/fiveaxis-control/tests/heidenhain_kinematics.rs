//! Seeded properties of the HEIDENHAIN front end's kinematics on random
//! machines, judged by forward kinematics only (`Machine::forward`).
//!
//! Every expectation is computed here from the programmed words: plane
//! rotations are products of rotation matrices written out below
//! (`PLANE SPATIAL` = Rz(SPC)·Ry(SPB)·Rx(SPA), turns about the fixed X,
//! then Y, then Z), tool vectors and plane normals are made from random
//! rotary angles through `Machine::forward` (so that they are reachable),
//! never from the kernel's inverse kinematics or frame code.
//!
//! Frames: every program starts with the machine at machine zero, every
//! rotary at 0, so the workpiece frame is the table frame and a
//! programmed point P is the tip at `W + P` (W the preset, table frame),
//! which `Machine::forward` reports.
//!
//! Machines: random machines with `control = Heidenhain`, two rotary axes
//! in each arrangement (table/table, head/table, table/head, head/head),
//! rotary lines in random directions through points within ±300 mm, no
//! rotary limits, random rollover; linear travel ±1e6 mm; random preset
//! (±300 mm) and tool 1 length 50 … 200 mm. Each property runs 64 cases
//! from a fixed seed with no persistence; a failure prints the program.
//!
//! A test marked `//! the reason says what was expected and what happens.

mod common;
/// The machine crate's generators of directions and points.
#[path = "../../fiveaxis-machine/tests/common/mod.rs"]
mod machine_gen;
#[path = "common/random_machines.rs"]
mod random_machines;

use common::{Outcome, check, run};
use fiveaxis_machine::{
    Control, Joints, MAX_AXES, Machine, Offsets, Side, ToolOffset, Vec3, principal,
};
use machine_gen::point;
use nalgebra::Matrix3;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestCaseError};

/// Tip tolerance, mm.
const TIP_EPS: f64 = 1e-6;
/// Direction tolerance, rad.
const DIR_EPS: f64 = 1e-9;
/// Cases per property.
const CASES: u32 = 64;

fn config() -> Config {
    Config {
        cases: CASES,
        rng_seed: RngSeed::Fixed(0x4E1D_E0A1),
        failure_persistence: None,
        max_shrink_iters: 512,
        ..Config::default()
    }
}

// ----- machines -------------------------------------------------------------------

fn five_axis() -> impl Strategy<Value = Machine> {
    random_machines::five_axis(Control::Heidenhain, "random heidenhain")
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

/// `x` written with a sign and 9 decimals, and the value the control
/// reads.
fn num(x: f64) -> (String, f64) {
    let text = format!("{x:+.9}");
    let value = text.parse().expect("formatted number");
    (text, value)
}

/// A Klartext program being written (from `BEGIN PGM`, line 1).
struct Writer {
    text: String,
    lines: u32,
}

impl Writer {
    fn new() -> Self {
        let mut w = Writer {
            text: String::new(),
            lines: 0,
        };
        w.line("BEGIN PGM K MM");
        w.line("TOOL CALL 1 Z S1000");
        w
    }

    fn line(&mut self, s: &str) -> u32 {
        self.text.push_str(s);
        self.end()
    }

    fn start(&mut self, s: &str) {
        self.text.push_str(s);
    }

    /// ` <address><signed value>`; returns the value as read.
    fn word(&mut self, address: &str, x: f64) -> f64 {
        let (t, v) = num(x);
        self.text.push(' ');
        self.text.push_str(address);
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

    fn finish(mut self) -> String {
        self.line("END PGM K MM");
        self.text
    }
}

// ----- judging -------------------------------------------------------------------------

/// Where the machine stands after `line`: the end of the last segment up
/// to it (a block that moves nothing gives no segment), or machine zero
/// where the run started.
fn end_after(out: &Outcome, line: u32) -> Joints {
    out.segments
        .iter()
        .rev()
        .find(|s| s.line <= line)
        .map_or([0.0; MAX_AXES], |s| s.end)
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

/// `PLANE SPATIAL SPA SPB SPC`: about the fixed X, then Y, then Z.
fn spatial(a: f64, b: f64, c: f64) -> Matrix3<f64> {
    rz(c) * ry(b) * rx(a)
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

/// Spatial angles (SPA, SPB, SPC) whose plane Z, Rz(c)·Ry(b)·Rx(a)·ez, is
/// `d`: Rx(a)·ez = (0, −sin a, cos a) and Ry(b) of it is
/// (sin b cos a, −sin a, cos b cos a), whose z must be d.z; the turn about
/// Z then brings its xy direction onto d's. `a` is used when
/// |d.z| ≤ |cos a| (else 0).
fn spatial_for(d: &Vec3, a: f64) -> [f64; 3] {
    let ca = a.to_radians().cos();
    let a = if d.z.abs() <= ca.abs() - 1e-6 { a } else { 0.0 };
    let (sa, ca) = a.to_radians().sin_cos();
    let b = (d.z / ca).clamp(-1.0, 1.0).acos();
    let u = [b.sin() * ca, -sa];
    let c = d.y.atan2(d.x) - u[1].atan2(u[0]);
    [a, b.to_degrees(), c.to_degrees()]
}

/// The Q parameter `PLANE … STAY` writes for rotary axis `name`.
fn stay_q(name: char) -> u32 {
    match name.to_ascii_uppercase() {
        'A' => 120,
        'B' => 121,
        _ => 122,
    }
}

/// A random reachable direction: the tool of random rotary angles.
fn angles() -> impl Strategy<Value = [f64; 2]> {
    (-170.0..170.0f64, -170.0..170.0f64).prop_map(|(a, b)| [a, b])
}

/// Writes `PLANE SPATIAL` for direction `d` with a twist `twist`, then
/// `ending`; returns the line and the rotation as read.
fn write_plane(w: &mut Writer, d: &Vec3, twist: f64, ending: &str) -> (u32, Matrix3<f64>) {
    let [a, b, c] = spatial_for(d, twist);
    w.start("PLANE SPATIAL");
    let a = w.word("SPA", a);
    let b = w.word("SPB", b);
    let c = w.word("SPC", c);
    w.start(" ");
    w.start(ending);
    (w.end(), spatial(a, b, c))
}

// ----- (a) PLANE SPATIAL … TURN / STAY ------------------------------------------------

/// Property (a): `PLANE SPATIAL … TURN`, or `… STAY` and an `L` to the
/// positions STAY wrote into Q120 … Q122, leaves the tool along the
/// plane's Z = Rz(SPC)·Ry(SPB)·Rx(SPA)·ez.
#[test]
fn plane_spatial_turn_or_stay_aligns_the_tool() {
    let strategy = (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        angles(),
        -60.0..60.0f64,
        any::<bool>(),
    );
    check(config(), strategy, |(m, work, length, q, twist, stay)| {
        let d = m.forward(&joints_with(&m, q), 0.0).dir;
        let mut w = Writer::new();
        let (mut line, r) = write_plane(&mut w, &d, twist, if stay { "STAY" } else { "TURN FMAX" });
        if stay {
            let names: Vec<String> = m
                .rotary
                .iter()
                .map(|a| format!("{}+Q{}", a.name, stay_q(a.name)))
                .collect();
            line = w.line(&format!("L {} R0 FMAX", names.join(" ")));
        }
        let program = w.finish();
        let out = run(&m, offsets(work, length), &program);
        no_alarm(&out, &program)?;
        let dir = m.forward(&end_after(&out, line), length).dir;
        check_dir(&dir, &(r * Vec3::z()), "after PLANE", &program)
    });
}

// ----- (b) PLANE … MOVE keeps the tip ---------------------------------------------------

/// `L P` then `PLANE SPATIAL … MOVE` for a plane along `d`; returns the
/// program, the PLANE's line, P and the rotation as read.
fn write_move(d: &Vec3, twist: f64, p: &Vec3) -> (String, u32, Vec3, Matrix3<f64>) {
    let mut w = Writer::new();
    w.start("L");
    let p = w.xyz(p);
    w.line(" R0 FMAX");
    let (line, r) = write_plane(&mut w, d, twist, "MOVE F1000");
    (w.finish(), line, p, r)
}

fn move_case() -> impl Strategy<Value = (Machine, Vec3, f64, [f64; 2], f64, Vec3)> {
    (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        angles(),
        -60.0..60.0f64,
        point(150.0),
    )
}

/// Property (b): `PLANE SPATIAL … MOVE` turns the tool along the plane's
/// Z and ends with the tip where the `L` before put it (W + P).
#[test]
fn plane_move_keeps_the_tool_tip() {
    check(config(), move_case(), |(m, work, length, q, twist, p)| {
        let d = m.forward(&joints_with(&m, q), 0.0).dir;
        let (program, line, p, r) = write_move(&d, twist, &p);
        let out = run(&m, offsets(work, length), &program);
        no_alarm(&out, &program)?;
        let pose = m.forward(&end_after(&out, line), length);
        check_tip(&pose.tip, &(work + p), "after MOVE", &program)?;
        check_dir(&pose.dir, &(r * Vec3::z()), "after MOVE", &program)
    });
}

/// Property (b'): the tip stays at W + P during the MOVE too (a quarter,
/// half and three quarters of the way), as the compensating moves of the
/// TNC keep it.
#[test]
fn plane_move_keeps_the_tool_tip_on_the_way() {
    check(config(), move_case(), |(m, work, length, q, twist, p)| {
        let d = m.forward(&joints_with(&m, q), 0.0).dir;
        let (program, line, p, _) = write_move(&d, twist, &p);
        let out = run(&m, offsets(work, length), &program);
        no_alarm(&out, &program)?;
        for seg in out.segments.iter().filter(|s| s.line == line) {
            for s in [0.25, 0.5, 0.75] {
                let tip = m.forward(&seg.eval(&m, s), length).tip;
                check_tip(&tip, &(work + p), &format!("MOVE at s = {s}"), &program)?;
            }
        }
        Ok(())
    });
}

// ----- (c) points in the tilted plane -------------------------------------------------

/// Property (c): with a datum shift S (cycle 7, defined before the plane:
/// the point the plane turns about) and `PLANE SPATIAL … TURN`, `L X Y Z`
/// puts the tip at W + S + R·(X, Y, Z) with the tool along R·ez.
#[test]
fn points_in_the_tilted_plane() {
    let strategy = (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        angles(),
        -60.0..60.0f64,
        point(100.0),
        proptest::collection::vec(point(150.0), 1..=3),
    );
    check(
        config(),
        strategy,
        |(m, work, length, q, twist, shift, points)| {
            let d = m.forward(&joints_with(&m, q), 0.0).dir;
            let mut w = Writer::new();
            w.line("CYCL DEF 7.0 DATUM SHIFT");
            w.start("CYCL DEF 7.1");
            let sx = w.word("X", shift.x);
            w.end();
            w.start("CYCL DEF 7.2");
            let sy = w.word("Y", shift.y);
            w.end();
            w.start("CYCL DEF 7.3");
            let sz = w.word("Z", shift.z);
            w.end();
            let s = Vec3::new(sx, sy, sz);
            let (_, r) = write_plane(&mut w, &d, twist, "TURN FMAX");
            let mut ends = Vec::new();
            for p in &points {
                w.start("L");
                let p = w.xyz(p);
                ends.push((w.line(" R0 F1000"), s + r * p));
            }
            let program = w.finish();
            let out = run(&m, offsets(work, length), &program);
            no_alarm(&out, &program)?;
            for (line, want) in ends {
                let pose = m.forward(&end_after(&out, line), length);
                let what = format!("line {line}");
                check_tip(&pose.tip, &(work + want), &what, &program)?;
                check_dir(&pose.dir, &(r * Vec3::z()), &what, &program)?;
            }
            Ok(())
        },
    );
}

// ----- (d) M128 with rotary positions ------------------------------------------------------

/// Property (d): under `M128`, `L X Y Z` with both rotary axes at random
/// positions puts the tip at W + P and the tool where forward kinematics
/// of those positions points it.
#[test]
fn m128_rotary_positions_keep_the_tip_on_the_point() {
    let block = (point(200.0), angles());
    let strategy = (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        proptest::collection::vec(block, 1..=4),
    );
    check(config(), strategy, |(m, work, length, blocks)| {
        let mut w = Writer::new();
        w.line("M128");
        let mut ends = Vec::new();
        for (p, q) in &blocks {
            w.start("L");
            let p = w.xyz(p);
            let q = [
                w.word(&m.rotary[0].name.to_string(), q[0]),
                w.word(&m.rotary[1].name.to_string(), q[1]),
            ];
            let line = w.line(" R0 F1000");
            ends.push((line, p, m.forward(&joints_with(&m, q), 0.0).dir));
        }
        let program = w.finish();
        let out = run(&m, offsets(work, length), &program);
        no_alarm(&out, &program)?;
        for (line, p, d) in ends {
            let pose = m.forward(&end_after(&out, line), length);
            let what = format!("line {line}");
            check_tip(&pose.tip, &(work + p), &what, &program)?;
            check_dir(&pose.dir, &d, &what, &program)?;
        }
        Ok(())
    });
}

// ----- (e) M128 with LN tool vectors --------------------------------------------------------

/// Property (e): under `M128`, `LN X Y Z TX TY TZ` puts the tip at W + P
/// and the tool along (TX, TY, TZ) normalized; the vectors are the tool
/// directions of random rotary angles, scaled.
#[test]
fn m128_ln_tool_vectors() {
    let block = (point(200.0), angles(), 0.5..2.0f64);
    let strategy = (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        proptest::collection::vec(block, 1..=4),
    );
    check(config(), strategy, |(m, work, length, blocks)| {
        let mut w = Writer::new();
        w.line("M128");
        let mut ends = Vec::new();
        for (p, q, scale) in &blocks {
            w.start("LN");
            let p = w.xyz(p);
            let d = m.forward(&joints_with(&m, *q), 0.0).dir * *scale;
            let t = Vec3::new(w.word("TX", d.x), w.word("TY", d.y), w.word("TZ", d.z));
            let line = w.line(" R0 F1000");
            ends.push((line, p, t.normalize()));
        }
        let program = w.finish();
        let out = run(&m, offsets(work, length), &program);
        no_alarm(&out, &program)?;
        for (line, p, t) in ends {
            let pose = m.forward(&end_after(&out, line), length);
            let what = format!("line {line}");
            check_tip(&pose.tip, &(work + p), &what, &program)?;
            check_dir(&pose.dir, &t, &what, &program)?;
        }
        Ok(())
    });
}

// ----- (f) SEQ+ / SEQ- ---------------------------------------------------------------------

/// Property (f): `PLANE … TURN SEQ+` and `SEQ-` both turn the tool along
/// the plane's Z; where the two solutions differ, SEQ+ gives the first
/// rotary axis the higher value and SEQ- the lower (values compared in
/// (−180°, 180°] on a rollover axis).
#[test]
fn seq_plus_and_minus_choose_the_first_axis_sign() {
    let strategy = (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        angles(),
        -60.0..60.0f64,
    );
    check(config(), strategy, |(m, work, length, q, twist)| {
        let d = m.forward(&joints_with(&m, q), 0.0).dir;
        let mut first = Vec::new();
        let mut all = String::new();
        for seq in ["SEQ+", "SEQ-"] {
            let mut w = Writer::new();
            let (line, r) = write_plane(&mut w, &d, twist, &format!("TURN FMAX {seq}"));
            let program = w.finish();
            let out = run(&m, offsets(work, length), &program);
            no_alarm(&out, &program)?;
            let end = end_after(&out, line);
            let dir = m.forward(&end, length).dir;
            check_dir(&dir, &(r * Vec3::z()), seq, &program)?;
            let v = end[m.rotary_index(0)];
            first.push(if m.rotary[0].rollover {
                principal(v)
            } else {
                v
            });
            all.push_str(&program);
        }
        if (first[0] - first[1]).abs() > 1e-6 {
            prop_assert!(
                first[0] > first[1],
                "first rotary {}: SEQ+ {} SEQ- {}\n{all}",
                m.rotary[0].name,
                first[0],
                first[1]
            );
        }
        Ok(())
    });
}

// ----- (g) the other forms of PLANE ---------------------------------------------------

/// A form of PLANE for a rotation R (R·ez reachable).
#[derive(Clone, Copy, Debug)]
enum Form {
    Spatial,
    Euler,
    Vector,
    Points,
}

fn form() -> impl Strategy<Value = Form> {
    prop_oneof![
        Just(Form::Spatial),
        Just(Form::Euler),
        Just(Form::Vector),
        Just(Form::Points),
    ]
}

/// Writes `PLANE <form> … TURN FMAX` giving rotation `r`; returns the
/// rotation as the words read give it, by the form's closed form:
/// SPATIAL Rz(c)·Ry(b)·Rx(a) (b = −asin r31, a = atan2(r32, r33),
/// c = atan2(r21, r11)); EULER Rz(PR)·Rx(NU)·Rz(ROT) (NU = acos r33,
/// PR = atan2(r13, −r23), ROT = atan2(r31, r32)); VECTOR: Z along N, X
/// along B less its part along N (B written with a part along N and N
/// scaled); POINTS: X along P2 − P1, Z along (P2 − P1) × (P3 − P1).
fn write_form(w: &mut Writer, f: Form, r: &Matrix3<f64>, extra: [f64; 3]) -> Matrix3<f64> {
    match f {
        Form::Spatial => {
            let b = (-r[(2, 0)]).clamp(-1.0, 1.0).asin().to_degrees();
            let a = r[(2, 1)].atan2(r[(2, 2)]).to_degrees();
            let c = r[(1, 0)].atan2(r[(0, 0)]).to_degrees();
            w.start("PLANE SPATIAL");
            let (a, b, c) = (w.word("SPA", a), w.word("SPB", b), w.word("SPC", c));
            w.line(" TURN FMAX");
            spatial(a, b, c)
        }
        Form::Euler => {
            let nu = r[(2, 2)].clamp(-1.0, 1.0).acos().to_degrees();
            let pr = r[(0, 2)].atan2(-r[(1, 2)]).to_degrees();
            let rot = r[(2, 0)].atan2(r[(2, 1)]).to_degrees();
            w.start("PLANE EULER");
            let pr = w.word("EULPR", pr);
            let nu = w.word("EULNU", nu);
            let rot = w.word("EULROT", rot);
            w.line(" TURN FMAX");
            rz(pr) * rx(nu) * rz(rot)
        }
        Form::Vector => {
            let scale = 0.5 + extra[0].abs();
            let b = r.column(0) * 2.0 + r.column(2) * extra[1];
            let n = r.column(2) * scale;
            w.start("PLANE VECTOR");
            let b = Vec3::new(w.word("BX", b.x), w.word("BY", b.y), w.word("BZ", b.z));
            let n = Vec3::new(w.word("NX", n.x), w.word("NY", n.y), w.word("NZ", n.z));
            w.line(" TURN FMAX");
            frame_of(b, n)
        }
        Form::Points => {
            let p1 = Vec3::new(extra[0], extra[1], extra[2]) * 20.0;
            let p2 = p1 + r.column(0) * 30.0;
            let p3 = p1 + r.column(0) * 5.0 + r.column(1) * 25.0;
            w.start("PLANE POINTS");
            let mut read = Vec::new();
            for (k, p) in [p1, p2, p3].iter().enumerate() {
                let n = k + 1;
                read.push(Vec3::new(
                    w.word(&format!("P{n}X"), p.x),
                    w.word(&format!("P{n}Y"), p.y),
                    w.word(&format!("P{n}Z"), p.z),
                ));
            }
            w.line(" TURN FMAX");
            let x = read[1] - read[0];
            frame_of(x, x.cross(&(read[2] - read[0])))
        }
    }
}

/// The rotation with Z along `z` and X along `x` less its part along Z.
fn frame_of(x: Vec3, z: Vec3) -> Matrix3<f64> {
    let z = z.normalize();
    let x = (x - z * x.dot(&z)).normalize();
    Matrix3::from_columns(&[x, z.cross(&x), z])
}

/// Property (g): `PLANE SPATIAL | EULER | VECTOR | POINTS … TURN` for a
/// rotation R with a reachable Z: the tool along R·ez, and `L X Y Z`
/// puts the tip at W + R·P.
#[test]
fn plane_forms_align_the_tool_and_map_points() {
    let strategy = (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        angles(),
        -180.0..180.0f64,
        form(),
        (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
        proptest::collection::vec(point(150.0), 1..=2),
    );
    check(
        config(),
        strategy,
        |(m, work, length, q, twist, f, extra, points)| {
            let d = m.forward(&joints_with(&m, q), 0.0).dir;
            let [a, b, c] = spatial_for(&d, 0.0);
            let r = spatial(a, b, c) * rz(twist);
            let mut w = Writer::new();
            let r = write_form(&mut w, f, &r, [extra.0, extra.1, extra.2]);
            let mut ends = Vec::new();
            for p in &points {
                w.start("L");
                let p = w.xyz(p);
                ends.push((w.line(" R0 F1000"), r * p));
            }
            let program = w.finish();
            let out = run(&m, offsets(work, length), &program);
            no_alarm(&out, &program)?;
            for (line, want) in ends {
                let pose = m.forward(&end_after(&out, line), length);
                let what = format!("{f:?} line {line}");
                check_tip(&pose.tip, &(work + want), &what, &program)?;
                check_dir(&pose.dir, &(r * Vec3::z()), &what, &program)?;
            }
            Ok(())
        },
    );
}

/// Property (h): `PLANE PROJECTED PROPR PROMIN ROT … TURN`: the plane
/// holds x = (cos PROPR, 0, −sin PROPR) (in the ZX plane) and
/// y = (0, cos PROMIN, sin PROMIN) (in the YZ plane), so the tool lies
/// along x × y. For a reachable normal n with n.z > 0: PROPR =
/// atan2(n.x, n.z), PROMIN = atan2(−n.y, n.z); ROT random.
#[test]
fn plane_projected_aligns_the_tool() {
    let strategy = (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        angles(),
        -180.0..180.0f64,
    );
    check(config(), strategy, |(m, work, length, q, rot)| {
        let n = m.forward(&joints_with(&m, q), 0.0).dir;
        prop_assume!(n.z > 0.05);
        let mut w = Writer::new();
        w.start("PLANE PROJECTED");
        let p = w.word("PROPR", n.x.atan2(n.z).to_degrees()).to_radians();
        let mn = w
            .word("PROMIN", (-n.y).atan2(n.z).to_degrees())
            .to_radians();
        w.word("ROT", rot);
        let line = w.line(" TURN FMAX");
        let program = w.finish();
        let x = Vec3::new(p.cos(), 0.0, -p.sin());
        let y = Vec3::new(0.0, mn.cos(), mn.sin());
        let want = x.cross(&y).normalize();
        let out = run(&m, offsets(work, length), &program);
        no_alarm(&out, &program)?;
        let dir = m.forward(&end_after(&out, line), length).dir;
        check_dir(&dir, &want, "PROJECTED", &program)
    });
}

/// Property (i): `PLANE AXIAL` with both rotary axes turns them to the
/// positions written (modulo 360 on a rollover axis), and after it the
/// tool lies where forward kinematics of those positions points it. On a
/// machine with both axes in the table, `L X Y Z` puts the tip at
/// W + R·P, R the table's turn as the workpiece sees it: its columns are
/// how far the tip moves, by forward kinematics, when the machine's X or
/// Y moves by 1 with the rotaries there (with a head axis the plane's X
/// and Y turn with the head, which moving the linear axes cannot
/// measure; only the direction is checked there).
#[test]
fn plane_axial_positions_the_axes() {
    let strategy = (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        angles(),
        point(150.0),
    );
    check(config(), strategy, |(m, work, length, q, p)| {
        let mut w = Writer::new();
        w.start("PLANE AXIAL");
        let q = [
            w.word(&m.rotary[0].name.to_string(), q[0]),
            w.word(&m.rotary[1].name.to_string(), q[1]),
        ];
        let plane = w.line(" TURN FMAX");
        w.start("L");
        let p = w.xyz(&p);
        let line = w.line(" R0 F1000");
        let program = w.finish();
        let out = run(&m, offsets(work, length), &program);
        no_alarm(&out, &program)?;
        let end = end_after(&out, plane);
        for (k, want) in q.iter().enumerate() {
            let i = m.rotary_index(k);
            let dq = if m.rotary[k].rollover {
                principal(end[i] - want)
            } else {
                end[i] - want
            };
            prop_assert!(
                dq.abs() < 1e-9,
                "{} at {} ≠ {want}\n{program}",
                m.rotary[k].name,
                end[i]
            );
        }
        // The tilted frame by forward kinematics: the tool's direction
        // at the positions, and the tip moved along the machine's X and
        // Y with the rotaries there.
        let j = joints_with(&m, q);
        let o = m.forward(&j, length).tip;
        let mut jx = j;
        jx[0] += 1.0;
        let mut jy = j;
        jy[1] += 1.0;
        let r = Matrix3::from_columns(&[
            m.forward(&jx, length).tip - o,
            m.forward(&jy, length).tip - o,
            m.forward(&j, 0.0).dir,
        ]);
        let pose = m.forward(&end_after(&out, line), length);
        if m.rotary.iter().all(|a| a.on == Side::Table) {
            check_tip(&pose.tip, &(work + r * p), "after L", &program)?;
        }
        check_dir(&pose.dir, &r.column(2).into_owned(), "after L", &program)
    });
}

// ----- (j) transformations inside the tilted plane ------------------------------------

/// Property (j): a datum shift S2 and a rotation θ (cycles 7 and 10)
/// defined in the tilted plane act in it: `L X Y Z` puts the tip at
/// W + S + R·(S2 + Rz(θ)·P), S the shift defined before the plane.
#[test]
fn shift_and_rotation_inside_the_tilted_plane() {
    let strategy = (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        angles(),
        -60.0..60.0f64,
        (point(100.0), point(100.0)),
        -180.0..180.0f64,
        point(150.0),
    );
    check(
        config(),
        strategy,
        |(m, work, length, q, twist, (s1, s2), theta, p)| {
            let d = m.forward(&joints_with(&m, q), 0.0).dir;
            let mut w = Writer::new();
            let shift = |w: &mut Writer, s: &Vec3| {
                w.line("CYCL DEF 7.0 DATUM SHIFT");
                let mut v = [0.0; 3];
                for (k, a) in ["X", "Y", "Z"].into_iter().enumerate() {
                    w.start(&format!("CYCL DEF 7.{}", k + 1));
                    v[k] = w.word(a, s[k]);
                    w.end();
                }
                Vec3::new(v[0], v[1], v[2])
            };
            let s1 = shift(&mut w, &s1);
            let (_, r) = write_plane(&mut w, &d, twist, "TURN FMAX");
            let s2 = shift(&mut w, &s2);
            w.line("CYCL DEF 10.0 ROTATION");
            w.start("CYCL DEF 10.1");
            let theta = w.word("ROT", theta);
            w.end();
            w.start("L");
            let p = w.xyz(&p);
            let line = w.line(" R0 F1000");
            let program = w.finish();
            let out = run(&m, offsets(work, length), &program);
            no_alarm(&out, &program)?;
            let pose = m.forward(&end_after(&out, line), length);
            let want = work + s1 + r * (s2 + rz(theta) * p);
            check_tip(&pose.tip, &want, "after L", &program)?;
            check_dir(&pose.dir, &(r * Vec3::z()), "after L", &program)
        },
    );
}

// ----- (k) FUNCTION TCPM ----------------------------------------------------------------

/// Property (k): `FUNCTION TCPM F TCP AXIS POS` is `M128`: the same
/// blocks give the same machine positions, the tip at W + P.
#[test]
fn function_tcpm_is_m128() {
    let block = (point(200.0), angles());
    let strategy = (
        five_axis(),
        point(300.0),
        50.0..200.0f64,
        proptest::collection::vec(block, 1..=3),
    );
    check(config(), strategy, |(m, work, length, blocks)| {
        let mut programs = Vec::new();
        for on in ["M128", "FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS"] {
            let mut w = Writer::new();
            w.line(on);
            let mut ends = Vec::new();
            for (p, q) in &blocks {
                w.start("L");
                let p = w.xyz(p);
                w.word(&m.rotary[0].name.to_string(), q[0]);
                w.word(&m.rotary[1].name.to_string(), q[1]);
                ends.push((w.line(" R0 F1000"), p));
            }
            programs.push((w.finish(), ends));
        }
        let mut joints = Vec::new();
        for (program, ends) in &programs {
            let out = run(&m, offsets(work, length), program);
            no_alarm(&out, program)?;
            let mut js = Vec::new();
            for (line, p) in ends {
                let j = end_after(&out, *line);
                check_tip(&m.forward(&j, length).tip, &(work + p), "TCPM", program)?;
                js.push(j);
            }
            joints.push(js);
        }
        for (a, b) in joints[0].iter().zip(&joints[1]) {
            for k in 0..m.axis_count() {
                prop_assert!(
                    (a[k] - b[k]).abs() < 1e-9,
                    "M128 {a:?} ≠ FUNCTION TCPM {b:?}\n{}\n{}",
                    programs[0].0,
                    programs[1].0
                );
            }
        }
        Ok(())
    });
}
