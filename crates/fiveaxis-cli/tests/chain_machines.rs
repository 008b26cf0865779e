//! Machines with three rotary axes (a table axis and a nutating two-axis
//! head, or three on one side) and with a quill along the tool: random
//! programs, drawn from a seeded generator, go through `run`, `check`,
//! `view` and `post`; each command ends with a result or an alarm (exit 0
//! or 1, or 2 for a refused input), never a panic. Functions that need
//! exactly two rotary axes refuse with an alarm that says so.

use std::fmt::Write as _;
use std::path::Path;

mod common;

use common::{run_in, stderr, stdout};

/// A small seeded generator (xorshift64*), so that every run draws the
/// same programs.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    /// A number with a decimal point (read in mm / degrees by every
    /// control).
    fn value(&mut self, lo: f64, hi: f64) -> String {
        let unit = (self.next() >> 11) as f64 / (1u64 << 53) as f64;
        format!("{:.3}", lo + (hi - lo) * unit)
    }
}

fn linear(name: &str, along: &str) -> String {
    format!("[[linear]]\nname = \"{name}\"\nmin = -2000\nmax = 2000\n{along}")
}

fn rotary(name: &str, on: &str, axis: &str, center: &str) -> String {
    format!(
        "[[rotary]]\nname = \"{name}\"\non = \"{on}\"\naxis = {axis}\ncenter = {center}\nmin = -400\nmax = 400\n"
    )
}

/// The machines: name, file text, the rotary letters, the quill letter.
fn machines() -> Vec<(&'static str, String, &'static str, Option<&'static str>)> {
    let xyz = format!("{}{}{}", linear("X", ""), linear("Y", ""), linear("Z", ""));
    let nutating = "[0, 0.8191520442889918, 0.5735764363510462]";
    let mixed = format!(
        "name = \"trsrn\"\ntype = \"mixed\"\n{xyz}{}{}{}",
        rotary("A", "table", "[-1, 0, 0]", "[0, -100, -200]"),
        rotary("C", "head", "[0, 0, 1]", "[0, 50, 120]"),
        rotary("B", "head", nutating, "[0, 50, 120]"),
    );
    let head = format!(
        "name = \"three heads\"\ntype = \"head\"\ncontrol = \"haas\"\n{xyz}{}{}{}",
        rotary("C", "head", "[0, 0, 1]", "[0, 0, 150]"),
        rotary("B", "head", "[0, 1, 0]", "[0, 0, 150]"),
        rotary("A", "head", "[1, 0, 0]", "[0, 0, 100]"),
    );
    let table = format!(
        "name = \"three tables\"\ntype = \"table\"\ncontrol = \"mitsubishi\"\n{xyz}{}{}{}",
        rotary("A", "table", "[1, 0, 0]", "[0, 0, -50]"),
        rotary("C", "table", "[0, 0, 1]", "[0, 0, 0]"),
        rotary("B", "table", "[0, 1, 1]", "[10, 0, 0]"),
    );
    let quill = format!(
        "name = \"bridge mill\"\ntype = \"head\"\n{xyz}{}{}{}",
        linear("W", "along = \"tool\"\n"),
        rotary("C", "head", "[0, 0, 1]", "[0, 0, 200]"),
        rotary("B", "head", "[0, -1, 0]", "[0, 0, 200]"),
    );
    let quill3 = format!(
        "name = \"quill and three\"\ntype = \"mixed\"\ncontrol = \"mazak\"\n{xyz}{}{}{}{}",
        linear("W", "along = \"tool\"\n"),
        rotary("A", "table", "[-1, 0, 0]", "[0, -100, -200]"),
        rotary("C", "head", "[0, 0, 1]", "[0, 50, 120]"),
        rotary("B", "head", nutating, "[0, 50, 120]"),
    );
    vec![
        ("trsrn", mixed, "ACB", None),
        ("head3", head, "CBA", None),
        ("table3", table, "ACB", None),
        ("bridge", quill, "CB", Some("W")),
        ("quill3", quill3, "ACB", Some("W")),
    ]
}

/// One random block; a `tame` program keeps to positioning, feed and
/// TCPC type 1 (the programmed angles), which a three-rotary machine runs
/// to the end.
fn block(rng: &mut Rng, rotary: &str, quill: Option<&str>, tame: bool) -> String {
    let point = |rng: &mut Rng, b: &mut String| {
        for axis in ["X", "Y", "Z"] {
            if rng.below(3) > 0 {
                let _ = write!(b, " {axis}{}", rng.value(-200.0, 200.0));
            }
        }
        for axis in rotary.chars() {
            if rng.below(3) == 0 {
                let _ = write!(b, " {axis}{}", rng.value(-90.0, 90.0));
            }
        }
        if let Some(w) = quill
            && rng.below(3) == 0
        {
            let _ = write!(b, " {w}{}", rng.value(-50.0, 50.0));
        }
    };
    let mut b = String::new();
    let kinds = if tame { 10 } else { 17 };
    match rng.below(kinds) {
        0 => b.push_str("G0"),
        1..=6 => b.push_str("G1"),
        7 => return "G43.4 H1".to_owned(),
        8 => return "G49".to_owned(),
        9 => b.push_str("G1 F800."),
        10 => {
            let _ = write!(b, "G2 R{}", rng.value(500.0, 900.0));
        }
        11 => {
            return format!(
                "G43.5 H1 I{} J{} K{}",
                rng.value(-0.5, 0.5),
                rng.value(-0.5, 0.5),
                rng.value(0.5, 1.0)
            );
        }
        12 => return format!("G68.2 X0 Y0 Z0 I0 J{} K0", rng.value(-60.0, 60.0)),
        13 => return ["G53.1", "G53.6 H1", "G69"][rng.below(3)].to_owned(),
        14 => return ["G54.4 P1", "G54.4 P0", "G91", "G90"][rng.below(4)].to_owned(),
        15 => return "G91 G28 Z0\nG90".to_owned(),
        _ => return ["G81 Z-5. R5. F300.", "G80"][rng.below(2)].to_owned(),
    }
    point(rng, &mut b);
    b
}

fn program(rng: &mut Rng, rotary: &str, quill: Option<&str>, tame: bool) -> String {
    let mut text = String::from("G90 G54 G0 X0 Y0 Z100.\nG1 F1000.\n");
    for _ in 0..25 {
        text.push_str(&block(rng, rotary, quill, tame));
        text.push('\n');
    }
    text.push_str("M30\n");
    text
}

const OFFSETS: &str = "[tools]\n1 = { length = 100.0, radius = 5.0 }\n\n[setup_error.1]\nx = 1.0\ny = 0.0\nz = 0.0\na = 0.0\nb = 2.0\nc = 0.0\n";

/// Runs one command; panics when it panicked.
fn command(dir: &Path, args: &[&str], what: &str) -> Option<i32> {
    let out = run_in(dir, args, b"");
    let err = stderr(&out);
    assert!(
        !err.contains("panicked") && matches!(out.status.code(), Some(0..=2)),
        "{what}: {args:?} exit {:?}\n{err}",
        out.status.code()
    );
    out.status.code()
}

#[test]
fn random_programs_on_chain_machines_never_panic() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(dir.path().join("offsets.toml"), OFFSETS).expect("written");
    let mut rng = Rng(0x5eed_c4a1_2026);
    let mut ended = 0;
    for (name, text, rotary, quill) in machines() {
        let machine = dir.path().join(format!("{name}.toml"));
        std::fs::write(&machine, &text).expect("written");
        let m = fiveaxis_machine::Machine::from_toml(&text).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.rotary.len(), rotary.len());
        for n in 0..6 {
            let program = program(&mut rng, rotary, quill, n % 2 == 0);
            let file = dir.path().join(format!("{name}-{n}.nc"));
            std::fs::write(&file, &program).expect("written");
            let what = format!("{name}-{n}:\n{program}");
            let (m, p, o) = (
                machine.to_str().expect("UTF-8"),
                file.to_str().expect("UTF-8"),
                "offsets.toml",
            );
            let out = run_in(dir.path(), &["run", p, "--machine", m, "--offsets", o], b"");
            println!(
                "{name}-{n}: {}",
                stderr(&out).lines().next().unwrap_or("ended")
            );
            if command(
                dir.path(),
                &["run", p, "--machine", m, "--offsets", o],
                &what,
            ) == Some(0)
            {
                ended += 1;
            }
            command(
                dir.path(),
                &["check", p, "--machine", m, "--offsets", o],
                &what,
            );
            command(
                dir.path(),
                &["view", p, "--machine", m, "--offsets", o, "-o", "v.html"],
                &what,
            );
            command(
                dir.path(),
                &["post", p, "--machine", m, "--offsets", o],
                &what,
            );
        }
    }
    println!("{ended} of 30 random programs ran to their end");
    assert!(ended > 0, "some programs run to their end");
}

/// Positioning, limits and TCPC type 1 (the program gives the angles) work
/// on a three-rotary machine: the tip reported by forward kinematics stays
/// where the program puts it; vector-form TCPC and the tilted working plane
/// are refused with an alarm that names the two-axis need.
#[test]
fn three_rotary_tcpc_with_angles_holds_the_tip_and_vector_forms_alarm() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(dir.path().join("offsets.toml"), OFFSETS).expect("written");
    let (_, text, _, _) = machines().remove(0);
    std::fs::write(dir.path().join("m.toml"), &text).expect("written");
    let machine = fiveaxis_machine::Machine::from_toml(&text).expect("machine");
    let program = "G90 G0 X0 Y0 Z100. A0 B0 C0\nG43.4 H1\nG1 X10. Y20. Z30. A15. B40. C-30. F500.\nG1 X-5. A-20. B10. C60.\nG49\nM30\n";
    std::fs::write(dir.path().join("p.nc"), program).expect("written");
    let out = run_in(
        dir.path(),
        &[
            "run",
            "p.nc",
            "--machine",
            "m.toml",
            "--offsets",
            "offsets.toml",
        ],
        b"",
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let rows = stdout(&out);
    let mut lines = rows.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).expect(n);
    let mut seen = 0;
    for line in lines {
        let v: Vec<&str> = line.split(',').collect();
        let num = |n: &str| v[col(n)].parse::<f64>().expect(n);
        let row_line = num("line");
        if row_line != 3.0 && row_line != 4.0 {
            continue;
        }
        let s = num("s");
        if s != 1.0 {
            continue;
        }
        // Forward kinematics of the row's axes, independently of `run`'s
        // own tip columns.
        let mut joints = [0.0; fiveaxis_machine::MAX_AXES];
        for (i, name) in machine.axis_names().enumerate() {
            joints[i] = num(&name.to_string());
        }
        let tip = machine.forward(&joints, 100.0).tip;
        let want = if row_line == 3.0 {
            [10.0, 20.0, 30.0]
        } else {
            [-5.0, 20.0, 30.0]
        };
        for k in 0..3 {
            assert!((tip[k] - want[k]).abs() < 1e-6, "line {row_line}: {tip:?}");
        }
        seen += 1;
    }
    assert_eq!(seen, 2, "{rows}");
    for (code, says) in [
        ("G43.5 H1", "exactly two rotary axes"),
        ("G68.2 X0 Y0 Z0 I0 J30. K0\nG53.1", "two rotary axes"),
        ("G54.4 P1", "at most two rotary axes"),
    ] {
        let program = format!("G90 G0 X0 Y0 Z100.\n{code}\nM30\n");
        std::fs::write(dir.path().join("q.nc"), program).expect("written");
        let out = run_in(
            dir.path(),
            &[
                "run",
                "q.nc",
                "--machine",
                "m.toml",
                "--offsets",
                "offsets.toml",
            ],
            b"",
        );
        assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
        assert!(stderr(&out).contains(says), "{code}: {}", stderr(&out));
    }
}
