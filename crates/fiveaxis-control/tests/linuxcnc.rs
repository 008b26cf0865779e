//! The LinuxCNC language (`control = "linuxcnc"`): RS274/NGC parameters,
//! expressions and o-word flow, judged against LinuxCNC's own interpreter.
//!
//! Each program's expected end points were printed by `rs274 -g` (the
//! LinuxCNC 2.9 stand-alone interpreter) and are written here; where
//! `rs274` is on PATH the test also runs it live on the same text and
//! compares the end points to 4 decimals (the digits it prints). The
//! machine is the built-in three-axis mill with zero offsets, so the
//! joints X, Y, Z are the canonical positions `rs274` prints.

mod common;

use std::io;
use std::process::Command;

use common::builtin_at_zero;
use fiveaxis_control::{
    Alarm, Condition, ProgramLibrary, Row, RunError, RunOptions, Runner, SliceSource, Source,
};
use fiveaxis_machine::{Control, Machine, Offsets};

/// The digits `rs274` prints.
const RS274_DIGITS: f64 = 1e-4;

fn mill() -> Machine {
    let mut m = builtin_at_zero("mill-3axis").expect("built-in machine");
    m.control = Control::LinuxCnc;
    m
}

/// A library of in-memory files by subroutine name.
struct Files(Vec<(&'static str, &'static str)>);

impl ProgramLibrary for Files {
    fn open(&mut self, _number: u32) -> io::Result<Option<(Box<dyn Source>, String)>> {
        Ok(None)
    }

    fn open_named(&mut self, name: &str) -> io::Result<Option<(Box<dyn Source>, String)>> {
        Ok(self.0.iter().find(|(n, _)| *n == name).map(|(n, text)| {
            (
                Box::new(SliceSource::new(text.as_bytes())) as Box<dyn Source>,
                format!("{n}.ngc"),
            )
        }))
    }
}

fn run_with(
    program: &str,
    files: Files,
    options: RunOptions,
) -> (Vec<Row>, Option<Alarm>, Vec<String>) {
    let machine = mill();
    let mut runner = Runner::new(
        &machine,
        Offsets::default(),
        SliceSource::new(program.as_bytes()),
        options,
    )
    .with_library(Box::new(files));
    let mut rows = Vec::new();
    let alarm = loop {
        match runner.next_segment() {
            Ok(Some(seg)) => rows.push(seg.row(&machine, 1.0)),
            Ok(None) => break None,
            Err(RunError::Alarm { alarm, .. }) => break Some(alarm),
            Err(e) => panic!("a program in memory failed to read: {e}"),
        }
    };
    (rows, alarm, runner.notes().to_vec())
}

fn run_on(program: &str) -> (Vec<Row>, Option<Alarm>) {
    let (rows, alarm, _) = run_with(program, Files(Vec::new()), RunOptions::default());
    (rows, alarm)
}

#[track_caller]
fn alarm(program: &str) -> Alarm {
    run_on(program).1.expect("an alarm")
}

/// The end points of the straight moves and G17 arcs `rs274 -g` prints
/// for `program`,
/// or `None` when `rs274` is not installed.
fn rs274_points(program: &str) -> Option<Vec<[f64; 3]>> {
    // rs274 runs one at a time: concurrent runs were seen to print
    // nothing (it keeps state in files of its own).
    static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _turn = ONE_AT_A_TIME
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let dir = std::env::temp_dir().join(format!("fiveaxis-ngc-{}", std::process::id()));
    std::fs::create_dir_all(&dir).ok()?;
    let file = dir.join(format!("p{:x}.ngc", fxhash(program)));
    std::fs::write(&file, program).ok()?;
    let output = Command::new("rs274").arg("-g").arg(&file).output().ok()?;
    let _ = std::fs::remove_file(&file);
    let text = String::from_utf8_lossy(&output.stdout);
    let mut points = Vec::new();
    for line in text.lines() {
        let parse = |args: &str| -> Vec<f64> {
            args.trim_end_matches(')')
                .split(',')
                .filter_map(|x| x.trim().parse().ok())
                .collect()
        };
        if let Some((_, args)) = line.split_once("ARC_FEED(") {
            // G17 arcs: first end (X), second end (Y), centre, turn,
            // axis end (Z), …
            let v = parse(args);
            points.push([v[0], v[1], v[5]]);
            continue;
        }
        let Some(args) = ["STRAIGHT_FEED(", "STRAIGHT_TRAVERSE("]
            .iter()
            .find_map(|k| line.split_once(k).map(|(_, rest)| rest))
        else {
            continue;
        };
        let v = parse(args);
        points.push([v[0], v[1], v[2]]);
    }
    Some(points)
}

/// A small stable hash for temporary file names.
fn fxhash(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
    })
}

/// Runs `program`, expects no alarm and the end points `expected` (from
/// `rs274`), and, where `rs274` is installed, its live output too.
#[track_caller]
fn same_as_rs274(program: &str, expected: &[[f64; 3]]) {
    let (rows, alarm) = run_on(program);
    assert!(alarm.is_none(), "unexpected alarm {alarm:?}");
    let got: Vec<[f64; 3]> = rows
        .iter()
        .map(|r| [r.joints[0], r.joints[1], r.joints[2]])
        .collect();
    let close = |a: &[[f64; 3]], b: &[[f64; 3]]| {
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(p, q)| p.iter().zip(q).all(|(x, y)| (x - y).abs() <= RS274_DIGITS))
    };
    assert!(
        close(&got, expected),
        "kernel {got:?}\nexpected {expected:?}"
    );
    if let Some(live) = rs274_points(program) {
        assert!(close(&got, &live), "kernel {got:?}\nrs274 {live:?}");
    }
}

#[test]
fn flow_and_parameters_as_rs274_runs_them() {
    let program = "\
g21 g90 ; metric
#1 = 5
#1 = 6 G1 X#1 F100
#<_g> = 2
o<inner> sub
  #<loc> = [#1 * 2]
  #<_g> = [#<_g> + #<loc>]
  G1 Y#<_g>
o<inner> endsub
o<inner> call [1.5]
G1 X#1 Z[EXISTS[#<loc>]] (#1 restored)
o7 repeat [0]
  G1 X100
o7 endrepeat
#2 = 0
o8 while [1]
  #2 = [#2 + 1]
  o9 if [#2 GE 3]
    o8 break
  o9 endif
  G1 Z#2
o8 endwhile
o10 if [#2 EQ 1]
  G0 X1
o10 elseif [#2 EQ 3]
  G0 X3 Y[2 ** 3 MOD 5]
o10 elseif [#2 EQ 3]
  G0 X33
o10 else
  G0 X4
o10 endif
G0 x1 y sin[30] Z[-7 MOD 3]
M2
";
    same_as_rs274(
        program,
        &[
            [5.0, 0.0, 0.0],
            [5.0, 5.0, 0.0],
            [6.0, 5.0, 0.0],
            [6.0, 5.0, 1.0],
            [6.0, 5.0, 2.0],
            [3.0, 3.0, 2.0],
            [1.0, 0.5, 2.0],
        ],
    );
}

#[test]
fn loops_returns_and_calls_before_the_definition() {
    let program = "\
G21 G90 G17
#<r> = 10
o<circ> sub
  G1 X[#1] Y[#2] F500
  o<circ> return [#1+#2]
o<circ> endsub
#1 = 0
o10 while [#1 LT 3]
  o<circ> call [#1*#<r>] [5]
  #1 = [#1 + 1]
o10 endwhile
o20 repeat [2]
  G91 G1 X1
o20 endrepeat
G90
o30 if [#<_value> GT 100]
  G0 X99
o30 elseif [#<_value> EQ 25]
  G0 X25 (msg, value 25)
o30 else
  G0 X-1
o30 endif
#5 = 0
o40 do
  #5 = [#5+1]
  o41 if [#5 EQ 2]
    o40 continue
  o41 endif
  G1 Y#5
o40 while [#5 LT 4]
o<late> call [7]
M2
o<late> sub
  G0 Z#1
o<late> endsub
";
    same_as_rs274(
        program,
        &[
            [0.0, 5.0, 0.0],
            [10.0, 5.0, 0.0],
            [20.0, 5.0, 0.0],
            [21.0, 5.0, 0.0],
            [22.0, 5.0, 0.0],
            [25.0, 5.0, 0.0],
            [25.0, 1.0, 0.0],
            [25.0, 3.0, 0.0],
            [25.0, 4.0, 0.0],
            [25.0, 4.0, 7.0],
        ],
    );
}

#[test]
fn numbers_are_taken_as_written() {
    // LinuxCNC has no least-input-increment rule: X1 is 1 mm.
    same_as_rs274("G21 G90\nG1 X1 Y2.5 Z-3 F100\nM2\n", &[[1.0, 2.5, -3.0]]);
}

#[test]
fn messages_and_debug_are_noted_with_parameters() {
    let (_, alarm, notes) = run_with(
        "#<a> = 2\n(MSG, hello)\n(debug, a=#<a> n=#3 z=#<nope>)\n#5599 = 0\n(DEBUG, hidden)\nM2\n",
        Files(Vec::new()),
        RunOptions::default(),
    );
    assert!(alarm.is_none());
    assert!(notes.iter().any(|n| n.contains("MSG: hello")), "{notes:?}");
    assert!(
        notes
            .iter()
            .any(|n| n.contains("a=2.000000 n=0.000000 z=######")),
        "{notes:?}"
    );
    assert!(!notes.iter().any(|n| n.contains("hidden")), "{notes:?}");
}

#[test]
fn abort_comment_stops_the_program() {
    let a = alarm("G0 X1\n(ABORT, tool broken #<_x>)\nG0 X2\n");
    assert_eq!(a.line, 2);
    assert!(a.message.contains("tool broken"), "{}", a.message);
}

#[test]
fn subroutine_from_the_library_file() {
    let files = Files(vec![(
        "square",
        "(square.ngc)\no<square> sub\n  G1 X#1 Y0 F100\n  G1 Y#1\no<square> endsub\nM2\n",
    )]);
    let (rows, alarm, _) = run_with(
        "G90\no<SQUARE> call [4]\nG0 Z9\nM2\n",
        files,
        RunOptions::default(),
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let ends: Vec<_> = rows
        .iter()
        .map(|r| [r.joints[0], r.joints[1], r.joints[2]])
        .collect();
    assert_eq!(
        ends,
        vec![[4.0, 0.0, 0.0], [4.0, 4.0, 0.0], [4.0, 4.0, 9.0]]
    );
}

#[test]
fn a_missing_subroutine_is_an_alarm() {
    let a = alarm("o<nowhere> call\n");
    assert_eq!(a.condition, Condition::OWordFlow);
    assert!(a.message.contains("nowhere.ngc"), "{}", a.message);
    assert_eq!(a.code.to_string(), "FX0125");
}

#[test]
fn recursion_is_bounded_at_ten_calls() {
    let a = alarm("o1 sub\n  o1 call\no1 endsub\no1 call\nM2\n");
    assert_eq!(a.condition, Condition::MacroCallNesting);
    assert_eq!(a.line, 2);
}

#[test]
fn named_locals_vanish_when_the_sub_returns() {
    let a = alarm("o2 sub\n  #<t> = 1\no2 endsub\no2 call\nG0 X#<t>\n");
    assert_eq!(a.condition, Condition::MacroUndefinedVariable);
    assert_eq!(a.line, 5);
    assert!(a.message.contains("#<t>"), "{}", a.message);
    assert_eq!(a.code.to_string(), "FX0113");
}

#[test]
fn expression_errors_carry_kernel_codes() {
    let a = alarm("#1 = [1 / 0]\n");
    assert_eq!(a.condition, Condition::MacroDivisionByZero);
    assert!(a.message.contains("divide by zero"), "{}", a.message);
    let a = alarm("#1 = [SQRT[-1]]\n");
    assert_eq!(a.condition, Condition::MacroArgumentRange);
    let a = alarm("#<_x> = 1\n");
    assert_eq!(a.condition, Condition::MacroWriteProtected);
    let a = alarm("#5603 = 1\n");
    assert_eq!(a.condition, Condition::MacroUndefinedVariable);
}

#[test]
fn misplaced_owords_are_alarms() {
    for (program, line) in [
        ("o1 endif\n", 1),
        ("o1 endwhile\n", 1),
        ("o1 if [0]\nG0 X1\n", 1),
        ("o1 return\n", 1),
        ("o3 sub\nG0 X1\n", 1),
        ("o1 break\n", 1),
        ("o1 endrepeat\n", 1),
        // As rs274 2.9: `break` and `continue` leave `while` and `do` loops
        // only ("no matching while/do label … found 'repeat' in line 1").
        ("o1 repeat [3]\nG0 X1\no1 break\no1 endrepeat\nM2\n", 3),
        ("o1 repeat [3]\nG0 X1\no1 continue\no1 endrepeat\nM2\n", 3),
        // A label opened again on another line of the same subroutine
        // ("duplicate O-word label - already defined in line 1"); in
        // another subroutine it is another label.
        (
            "o1 if [1]\nG0 X1\no1 endif\no1 if [1]\nG0 X2\no1 endif\nM2\n",
            4,
        ),
        (
            "#1=0\no1 while [#1 LT 2]\n#1=[#1+1]\no1 endwhile\no1 if [1]\no1 endif\nM2\n",
            5,
        ),
    ] {
        let (_, a) = run_on(program);
        let a = a.unwrap_or_else(|| panic!("{program:?}: no alarm"));
        assert_eq!(a.condition, Condition::OWordFlow, "{program:?}");
        assert_eq!(a.line, line, "{program:?}");
    }
}

/// The same label in two subroutines, each called twice: no duplicate.
#[test]
fn labels_are_scoped_by_subroutine() {
    let program = "o<a> sub\no100 if [1]\nG1 X1 F100\no100 endif\no<a> endsub\n\
        o<b> sub\no100 if [1]\nG1 X2 F100\no100 endif\no<b> endsub\n\
        o<a> call\no<b> call\no<a> call\no<b> call\nM2\n";
    let (rows, alarm) = run_on(program);
    assert!(alarm.is_none(), "{alarm:?}");
    let xs: Vec<f64> = rows.iter().map(|r| r.tip.x).collect();
    assert_eq!(xs, [1.0, 2.0, 1.0, 2.0]);
}

#[test]
fn an_endless_loop_is_stopped_by_the_block_budget() {
    let options = RunOptions {
        max_blocks: 10_000,
        ..RunOptions::default()
    };
    let (_, alarm, _) = run_with(
        "o1 while [1]\n  #1 = [#1 + 1]\no1 endwhile\n",
        Files(Vec::new()),
        options,
    );
    assert_eq!(alarm.expect("stopped").condition, Condition::BlockBudget);
}

/// A loop whose body skips 10,000 lines each pass: the skip is looked
/// up in the file's index, so each pass costs its four blocks, and a
/// small budget stops the loop at once (it read the 10,000 lines on
/// every pass, unbounded by the budget).
#[test]
fn a_loop_over_skipped_lines_is_stopped_by_the_block_budget() {
    const SKIPPED: usize = 10_000;
    const BUDGET: u64 = 20_000;
    let program = format!(
        "o1 while [1]\no2 if [0]\n{}o2 endif\no1 endwhile\nM2\n",
        "G0 X1\n".repeat(SKIPPED)
    );
    let options = RunOptions {
        max_blocks: BUDGET,
        ..RunOptions::default()
    };
    let (rows, alarm, _) = run_with(&program, Files(Vec::new()), options);
    let alarm = alarm.expect("stopped");
    assert_eq!(alarm.condition, Condition::BlockBudget);
    assert_eq!(alarm.code.to_string(), "FX0102");
    assert!(rows.is_empty());
}

/// `NESTED` loops inside one another, each run once: every false
/// `while` skips to its `endwhile` by the index (reading on to it, each
/// skip was as long as the loops inside it: quadratic, 28 s for 10,000).
#[test]
fn deeply_nested_loops_end() {
    const NESTED: usize = 10_000;
    let mut program = String::new();
    for i in 0..NESTED {
        program.push_str(&format!(
            "#<_k{i}> = 0\no{i} while [#<_k{i}> EQ 0]\n#<_k{i}> = 1\n"
        ));
    }
    program.push_str("G0 X1\n");
    for i in (0..NESTED).rev() {
        program.push_str(&format!("o{i} endwhile\n"));
    }
    program.push_str("G0 X2\nM2\n");
    let (rows, alarm, _) = run_with(&program, Files(Vec::new()), RunOptions::default());
    assert!(alarm.is_none(), "{alarm:?}");
    let x: Vec<f64> = rows.iter().map(|r| r.joints[0]).collect();
    assert_eq!(x, [1.0, 2.0]);
}

/// Skips by the index land where reading on landed, and where rs274
/// lands: `elseif` chains, `break` in `while`, `continue` in `do`, a
/// definition skipped, in the main file and in a called file. (rs274
/// refuses a label used twice in one file and `break` inside `repeat`;
/// the kernel still reads both.)
#[test]
fn indexed_skips_land_where_reading_on_did() {
    let sub = "o<s> sub\no1 if [#1 EQ 1]\nG0 Y1\no1 elseif [#1 EQ 2]\nG0 Y2\no1 else\nG0 Y3\no1 endif\no<s> endsub\n";
    let program = "\
o9 sub
G0 Z9
o9 endsub
o1 if [0]
G0 X9
o1 endif
o7 if [0]
G0 X8
o7 elseif [0]
G0 X7
o7 elseif [1]
G0 X1
o7 else
G0 X6
o7 endif
#1 = 0
o2 do
#1 = [#1 + 1]
o3 if [#1 LT 3]
o2 continue
o3 endif
G0 X[10 + #1]
o2 while [#1 LT 4]
o4 while [1]
o5 if [1]
o4 break
o5 endif
G0 X99
o4 endwhile
o6 while [1]
o6 break
o6 endwhile
o<s> call [2]
o<s> call [3]
o9 call
M2
";
    let (rows, alarm, _) = run_with(program, Files(vec![("s", sub)]), RunOptions::default());
    assert!(alarm.is_none(), "{alarm:?}");
    let xyz: Vec<[f64; 3]> = rows
        .iter()
        .map(|r| [r.joints[0], r.joints[1], r.joints[2]])
        .collect();
    assert_eq!(
        xyz,
        [
            [1.0, 0.0, 0.0],
            [13.0, 0.0, 0.0],
            [14.0, 0.0, 0.0],
            [14.0, 2.0, 0.0],
            [14.0, 3.0, 0.0],
            [14.0, 3.0, 9.0],
        ]
    );
    same_as_rs274(
        program
            .replace("o<s> call [2]\no<s> call [3]\n", "")
            .as_str(),
        &[
            [1.0, 0.0, 0.0],
            [13.0, 0.0, 0.0],
            [14.0, 0.0, 0.0],
            [14.0, 0.0, 9.0],
        ],
    );
}

/// A subroutine name with a path in it is refused before the program
/// memory is asked for it.
#[test]
fn subroutine_names_with_a_path_are_refused() {
    for name in [
        "../outside/evil",
        "/abs/evil",
        "a/b",
        "..\\evil",
        "c:evil",
        "..",
    ] {
        let program = format!("o<{name}> call\nM2\n");
        // The memory holds the file: only the refusal keeps it out.
        let sub: &'static str = format!("o<{name}> sub\nG0 X99\no<{name}> endsub\n").leak();
        let (rows, alarm, _) = run_with(&program, Files(vec![(name, sub)]), RunOptions::default());
        let alarm = alarm.unwrap_or_else(|| panic!("{name}: no alarm"));
        assert_eq!(alarm.condition, Condition::OWordFlow, "{name}");
        assert_eq!(alarm.line, 1);
        assert!(
            alarm
                .message
                .starts_with(&format!("o<{name}> call: a subroutine name is a file name")),
            "{}",
            alarm.message
        );
        assert!(rows.is_empty(), "{name}");
    }
    // A name with a point in it is a file name.
    let (rows, alarm, _) = run_with(
        "o<a.b> call\nM2\n",
        Files(vec![("a.b", "o<a.b> sub\nG0 X1\no<a.b> endsub\n")]),
        RunOptions::default(),
    );
    assert!(alarm.is_none(), "{alarm:?}");
    assert_eq!(rows.len(), 1);
}

#[test]
fn predefined_parameters_answer_the_modal_state() {
    same_as_rs274(
        "G21 G90 G1 X3 F200\nG91\nG0 X[#<_incremental>] Y[#<_motion_mode>] Z[#<_feed>/100]\nG90\nG0 X[#<_x>] Y[#5420+#5421] Z[#<_metric>+#<_plane>/170]\nM2\n",
        &[[3.0, 0.0, 0.0], [4.0, 10.0, 2.0], [4.0, 14.0, 2.0]],
    );
}

/// Machine X, Y, Z at the end of each move.
fn ends(program: &str, offsets: Offsets) -> Vec<[f64; 3]> {
    let machine = mill();
    let mut runner = Runner::new(
        &machine,
        offsets,
        SliceSource::new(program.as_bytes()),
        RunOptions::default(),
    );
    let mut out = Vec::new();
    loop {
        match runner.next_segment() {
            Ok(Some(seg)) => out.push([seg.end[0], seg.end[1], seg.end[2]]),
            Ok(None) => return out,
            Err(e) => panic!("{program}: {e:?}"),
        }
    }
}

/// `rs274 -g` prints positions in the work system (G54 + G92 taken off):
/// its traverses (0,0) (2,1) (1,1) (1,1) (0,1) with offsets G54 X 5, then
/// 3 after L20, G92 X 2 then cleared, are these machine positions.
#[test]
fn g10_and_g92_as_linuxcnc_writes_them() {
    let program = "G10 L2 P0 X5\nG0 X0\nG10 L20 P1 X2\nG0 Y1\nG92 X0\nG0 X1\nG92.1\nG0 X1\n\
                   G92.3\nG0 X1\nG55\nG0 X0\nM2\n";
    assert_eq!(
        ends(program, Offsets::default()),
        vec![
            [5.0, 0.0, 0.0],
            [5.0, 1.0, 0.0],
            [6.0, 1.0, 0.0],
            [4.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ]
    );
    // G92.3 after G92.1: the parameters were cleared, nothing comes back
    // (X1 is still machine 4); after G92.2 they come back.
    let program = "G92 X-3\nG0 X1\nG92.2\nG0 X1\nG92.3\nG0 X1\nM2\n";
    assert_eq!(
        ends(program, Offsets::default()),
        vec![[4.0, 0.0, 0.0], [1.0, 0.0, 0.0], [4.0, 0.0, 0.0]]
    );
}

/// `rs274 -g` prints canonical positions without the tool length offset
/// (machine Z = canonical Z + offset): after `G43 H1` it prints Z smaller
/// by the change while the machine stands; `G10 L10 P3 Z40` at Z 50 gives
/// tool 3 the length 10 (`USE_TOOL_LENGTH_OFFSET(… 10)`, then Z 40).
#[test]
fn length_offset_changes_move_nothing() {
    let table = Offsets::from_tool_table("T1 P1 Z10 D6\nT2 P2 Z20 D10\n").expect("table");
    // G43 without H takes the spindle tool (T2); later changes (G43 H1,
    // G49, G43.1) leave the machine where it stands.
    let program = "T2 M6\nG43\nG0 X0 Y0 Z50\nG43 H1\nG1 X1 F100\nG49\nG1 Y1\n\
                   G43.1 Z5\nG0 X0\nG0 Z50\nM2\n";
    assert_eq!(
        ends(program, table),
        vec![
            [0.0, 0.0, 70.0],
            [1.0, 0.0, 70.0],
            [1.0, 1.0, 70.0],
            [0.0, 1.0, 70.0],
            [0.0, 1.0, 55.0],
        ]
    );
    let a = alarm("G43.1 X1\n");
    assert_eq!(a.condition, Condition::WordNotUsed);
}

/// G43.2 adds to the offset in force (g-code.adoc, G43.2): `G43 H1` then
/// `G43.2 H10` is tool 1's length plus tool 10's (rs274 2.9:
/// `USE_TOOL_LENGTH_OFFSET` 10 then 12.5 in the table's units); `G43.2 Z`
/// adds the value (the manual; rs274 2.9 still refuses the axis form);
/// G49 and G43 start over.
#[test]
fn g43_2_adds_length_offsets() {
    let table = Offsets::from_tool_table("T1 P1 Z10 D6\nT10 P10 Z2.5 D1\n").expect("table");
    let program = "T1 M6\nG43 H1\nG0 Z50\nG43.2 H10\nG0 Z50\nG43.2 Z0.5\nG0 Z50\n\
                   G49\nG0 Z50\nG43.2 Z1\nG0 Z50\nG43\nG0 Z50\nM2\n";
    let z: Vec<f64> = ends(program, table).iter().map(|p| p[2]).collect();
    assert_eq!(z, vec![60.0, 62.5, 63.0, 50.0, 51.0, 60.0]);
    for (program, condition, line) in [
        ("G43.2\n", Condition::NoDataAfterAddress, 1),
        ("G43.2 H1 Z1\n", Condition::WordNotUsed, 1),
        ("G43.2 X1\n", Condition::WordNotUsed, 1),
        ("G0 Z1\nG43.2 H7\n", Condition::IllegalOffsetNumber, 2),
    ] {
        let a = alarm(program);
        assert_eq!((a.condition, a.line), (condition, line), "{program}: {a:?}");
    }
}

#[test]
fn g10_l10_sets_the_tool_so_the_position_reads_the_value() {
    // rs274 prints Z 50, 40, 40, 30 with the offset 0, then 10: machine
    // Z 50, 50, 50, 40.
    assert_eq!(
        ends(
            "G21 G90\nG0 Z50\nG10 L10 P3 Z40\nG43 H3\nG0 X1\nG0 Z40\nG0 Z30\nM2\n",
            Offsets::default()
        ),
        vec![[0.0, 0.0, 50.0], [1.0, 0.0, 50.0], [1.0, 0.0, 40.0]]
    );
}

#[test]
fn io_user_codes_path_modes_and_dwell_move_nothing() {
    let program = "G64 P0.01 Q0.02\nG61\nG61.1\nG64\nM66 P0 L0\nM67 E1 Q2.5\nM101 P1 Q2\n\
                   M61 Q3\nG4 P0.5\nM60\nG0 X1\nM2\n";
    assert_eq!(ends(program, Offsets::default()), vec![[1.0, 0.0, 0.0]]);
    let a = alarm("G64 P-1\n");
    assert_eq!(a.condition, Condition::ValueOutOfRange);
    let a = alarm("G10 L2 P10 X1\n");
    assert_eq!(a.condition, Condition::ValueOutOfRange);
}

/// The arc radius tolerance as `rs274 -g` (2.9) applies it, found by
/// bisection on its output: radius 10 mm takes 0.028 and refuses 0.029;
/// 100 mm takes 0.1 (0.1 %) and refuses 0.101; 0.2 in takes 0.0027 in and
/// refuses 0.0029 in.
#[test]
fn arc_radius_tolerance_as_rs274_applies_it() {
    let arc = |units: &str, x: f64, r: f64| {
        format!("{units} G17 G90 F100\nG0 X0 Y0\nG2 X{x} Y{r} I0 J{r}\nM2\n")
    };
    for (units, x, r, ok) in [
        ("G21", 10.028, 10.0, true),
        ("G21", 10.029, 10.0, false),
        ("G21", 100.1, 100.0, true),
        ("G21", 100.101, 100.0, false),
        ("G20", 0.2027, 0.2, true),
        ("G20", 0.2029, 0.2, false),
    ] {
        let (_, alarm) = run_on(&arc(units, x, r));
        match (ok, alarm) {
            (true, None) => {}
            (false, Some(a)) => {
                assert_eq!(a.condition, Condition::ArcRadiusTolerance, "{x}");
                assert!(
                    a.message.contains("radius to end of arc differs"),
                    "{}",
                    a.message
                );
            }
            (ok, alarm) => panic!("{units} X{x} R{r}: expected ok={ok}, got {alarm:?}"),
        }
    }
}

#[test]
fn canned_cycles_as_rs274_runs_them() {
    let program = "\
G21 G17 G90 F100 M3 S1000
G0 X0 Y0 Z10
G98 G81 X5 Y5 Z-2 R2
X10
G99 G81 X15 Z-3 R1
G80
G0 Z20
G91 G98 G81 X5 Y0 Z-4 R-18 L3
G90 G80
G0 Z10
G83 X30 Y0 Z-5 R2 Q2 F100
G80
G73 X40 Z-5 R2 Q2.5
G82 X50 Z-1 R2 P0.5
G85 X60 Z-1 R2
G86 X70 Z-1 R2 P0.1
G89 X80 Z-1 R2 P0.2
G80
M2
";
    same_as_rs274(
        program,
        &[
            [0.0, 0.0, 10.0],
            [5.0, 5.0, 10.0],
            [5.0, 5.0, 2.0],
            [5.0, 5.0, -2.0],
            [5.0, 5.0, 10.0],
            [10.0, 5.0, 10.0],
            [10.0, 5.0, 2.0],
            [10.0, 5.0, -2.0],
            [10.0, 5.0, 10.0],
            [15.0, 5.0, 10.0],
            [15.0, 5.0, 1.0],
            [15.0, 5.0, -3.0],
            [15.0, 5.0, 1.0],
            [15.0, 5.0, 20.0],
            [20.0, 5.0, 20.0],
            [20.0, 5.0, 2.0],
            [20.0, 5.0, -2.0],
            [20.0, 5.0, 20.0],
            [25.0, 5.0, 20.0],
            [25.0, 5.0, 2.0],
            [25.0, 5.0, -2.0],
            [25.0, 5.0, 20.0],
            [30.0, 5.0, 20.0],
            [30.0, 5.0, 2.0],
            [30.0, 5.0, -2.0],
            [30.0, 5.0, 20.0],
            [30.0, 5.0, 10.0],
            [30.0, 0.0, 10.0],
            [30.0, 0.0, 2.0],
            [30.0, 0.0, 0.0],
            [30.0, 0.0, 2.0],
            [30.0, 0.0, 0.254],
            [30.0, 0.0, -2.0],
            [30.0, 0.0, 2.0],
            [30.0, 0.0, -1.746],
            [30.0, 0.0, -4.0],
            [30.0, 0.0, 2.0],
            [30.0, 0.0, -3.746],
            [30.0, 0.0, -5.0],
            [30.0, 0.0, 10.0],
            [40.0, 0.0, 10.0],
            [40.0, 0.0, 2.0],
            [40.0, 0.0, -0.5],
            [40.0, 0.0, -0.246],
            [40.0, 0.0, -3.0],
            [40.0, 0.0, -2.746],
            [40.0, 0.0, -5.0],
            [40.0, 0.0, 10.0],
            [50.0, 0.0, 10.0],
            [50.0, 0.0, 2.0],
            [50.0, 0.0, -1.0],
            [50.0, 0.0, 10.0],
            [60.0, 0.0, 10.0],
            [60.0, 0.0, 2.0],
            [60.0, 0.0, -1.0],
            [60.0, 0.0, 2.0],
            [60.0, 0.0, 10.0],
            [70.0, 0.0, 10.0],
            [70.0, 0.0, 2.0],
            [70.0, 0.0, -1.0],
            [70.0, 0.0, 10.0],
            [80.0, 0.0, 10.0],
            [80.0, 0.0, 2.0],
            [80.0, 0.0, -1.0],
            [80.0, 0.0, 10.0],
        ],
    );
}

#[test]
fn g86_needs_p_and_a_turning_spindle() {
    let a = alarm("G21 F100 M3 S100\nG0 Z10\nG86 X1 Z-1 R2\n");
    assert_eq!(a.condition, Condition::CycleDataMissing);
    let a = alarm("G21 F100\nG0 Z10\nG86 X1 Z-1 R2 P1\n");
    assert_eq!(a.condition, Condition::CycleNotAllowed);
}

#[test]
fn numbered_programs_with_m98_and_m99() {
    // o-code.adoc, "Fanuc-Style Numbered Programs": #1 is global there.
    same_as_rs274(
        "o1\n#1 = 0\nM98 P100 L3\nG0 X#1\nM30\no100\n#1 = [#1 + 1]\nG0 Y#1\nM99\n",
        &[
            [0.0, 1.0, 0.0],
            [0.0, 2.0, 0.0],
            [0.0, 3.0, 0.0],
            [3.0, 3.0, 0.0],
        ],
    );
}

/// rs274 prints (10,5,20) (0,0,0) (0,0,5) (0,0,20) (0,0,20) (10,5,20)
/// (4,5,20): G28.1 stores, `G28 Z5` goes through Z5 to the stored Z, `G28`
/// alone takes every axis home. (Its parameters are in inches, the
/// stand-alone interpreter's machine units; the kernel's in mm.)
#[test]
fn g28_g30_positions_are_parameters() {
    let program = "G21 G90\nG0 X10 Y5 Z20\nG28.1\nG0 X0 Y0 Z0\nG28 Z5\nG28\n\
                   #5181 = 1\n#5182 = 2\n#5183 = 3\nG0 X4\nG30\nG0 X[#5161] Y[#5182]\nM2\n";
    assert_eq!(
        ends(program, Offsets::default()),
        vec![
            [10.0, 5.0, 20.0],
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 20.0],
            [10.0, 5.0, 20.0],
            [4.0, 5.0, 20.0],
            [1.0, 2.0, 3.0],
            [10.0, 2.0, 3.0],
        ]
    );
}

/// rs274: `SET_G5X_OFFSET(7, 10, 20)`, then X 7 = `#5220`, Y 5.91 =
/// `#<_coord_system>`/100; G59.2 from `#5361`, `G10 L20 P0` on it.
#[test]
fn nine_coordinate_systems() {
    let program = "G21 G90\nG10 L2 P7 X10 Y20\nG59.1\nG0 X0 Y0\nG0 X[#5220] Y[#<_coord_system>/100]\n\
                   #5361 = 3\nG59.2\nG0 X0 Y0\nG10 L20 P0 X1\nG0 X0\nG54\nG0 X0 Y0\nM2\n";
    let got = ends(program, Offsets::default());
    let want = [
        [10.0, 20.0, 0.0],
        [17.0, 25.91, 0.0],
        [3.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 0.0, 0.0],
    ];
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, w) in got.iter().zip(want) {
        assert!(
            g.iter().zip(w).all(|(a, b)| (a - b).abs() < 1e-9),
            "{got:?}"
        );
    }
}

#[test]
fn tool_parameters_and_m61() {
    let table = Offsets::from_tool_table("T1 P1 Z10 D6\nT2 P2 Z20 D10\n").expect("table");
    // #5403 the loaded tool's Z offset, #5410 its diameter, #5083 the
    // offset applied; M61 Q1 makes tool 1 the loaded one (no change, the
    // applied offset stays until the next G43).
    let program = "T2 M6\nG43\nG0 X[#5403] Y[#5410] Z[#5083]\nM61 Q1\nG0 X[#5400] Y[#5403]\nM2\n";
    assert_eq!(
        ends(program, table),
        vec![[20.0, 10.0, 40.0], [1.0, 10.0, 40.0]]
    );
    assert_eq!(alarm("M61\n").condition, Condition::NoDataAfterAddress);
    // S is a real number (other-code.adoc), never negative.
    assert_eq!(
        ends("S1000.5 M3\nG0 X[#<_rpm> - 1000]\nM2\n", Offsets::default()),
        vec![[0.5, 0.0, 0.0]]
    );
    assert_eq!(alarm("S-1\n").condition, Condition::ValueOutOfRange);
    assert_eq!(
        alarm("#5400 = 3\n").condition,
        Condition::MacroWriteProtected
    );
}

/// R-format arcs: `rs274` takes R 0.00125 mm short of half the chord and
/// refuses 0.00128 mm ("radius too small to reach end point"), on chords
/// of 2, 20 and 200 mm alike.
#[test]
fn r_arc_shortfall_as_rs274_takes_it() {
    for (chord, r, ok) in [
        (20.0, 9.99875, true),
        (20.0, 9.99872, false),
        (2.0, 0.9989, true),
        (2.0, 0.9985, false),
        (200.0, 99.9989, true),
        (200.0, 99.9985, false),
    ] {
        let program = format!("G21 G17 G90 F100\nG0 X0 Y0\nG2 X{chord} Y0 R{r}\nM2\n");
        let (_, alarm) = run_on(&program);
        match (ok, alarm) {
            (true, None) => {}
            (false, Some(a)) => {
                assert_eq!(a.condition, Condition::ArcRadiusTolerance);
                assert!(
                    a.message.contains("too small to reach end point"),
                    "{}",
                    a.message
                );
            }
            (ok, alarm) => panic!("chord {chord} R{r}: expected ok={ok}, got {alarm:?}"),
        }
    }
}

#[test]
fn absolute_arc_centres() {
    // rs274: ARC_FEED(20, 5, centre 15, 5, -1) then (10, 5, centre 15, 5, 1).
    same_as_rs274(
        "G21 G17 G90 F100\nG0 X10 Y5\nG90.1\nG2 X20 Y5 I15 J5\nG91.1\nG3 X10 Y5 I-5 J0\n\
         G0 Z[#<_ijk_absolute_mode> + 1]\nM2\n",
        &[
            [10.0, 5.0, 0.0],
            [20.0, 5.0, 0.0],
            [10.0, 5.0, 0.0],
            [10.0, 5.0, 1.0],
        ],
    );
    let a = alarm("G21 G17 G90 F100\nG0 X10 Y5\nG90.1\nG2 X20 Y5 I15\n");
    assert_eq!(a.condition, Condition::ArcCenterMissing);
    assert!(a.message.contains("J word missing"), "{}", a.message);
}

#[test]
fn arc_turns_p_as_rs274_counts_them() {
    // G2 with P3 from (10, 0) about the origin back to (10, 0): three
    // turns, Z falling 3 mm over them (rs274: ARC_FEED rotation -3). Half
    // way along, after one and a half turns: (-10, 0), Z -1.5.
    let program = "G21 G90 G17 F100\nG0 X10 Y0 Z0\nG2 X10 Y0 I-10 J0 Z-3 P3\nM2\n";
    let machine = mill();
    let mut runner = Runner::new(
        &machine,
        Offsets::default(),
        SliceSource::new(program.as_bytes()),
        RunOptions::default(),
    );
    let mut last = None;
    while let Some(seg) = runner.next_segment().expect("no alarm") {
        last = Some(seg.clone());
    }
    let arc = last.expect("the arc");
    let mid = arc.row(&machine, 0.5).joints;
    assert!(
        (mid[0] + 10.0).abs() < 1e-9 && mid[1].abs() < 1e-9,
        "{mid:?}"
    );
    assert!((mid[2] + 1.5).abs() < 1e-9, "{mid:?}");
    let quarter = arc.row(&machine, 1.0 / 12.0).joints;
    assert!(
        quarter[0].abs() < 1e-9 && (quarter[1] + 10.0).abs() < 1e-9,
        "{quarter:?}"
    );
    // P counts turns: 0 is no arc.
    let a = alarm("G21 G90 G17 F100\nG0 X10 Y0\nG2 X10 Y0 I-10 P0\nM2\n");
    assert_eq!(a.line, 3, "{a:?}");
}

#[test]
fn hal_pins_and_ini_values_come_from_the_machine_file() {
    let mut machine = mill();
    machine
        .params
        .hal_pins
        .insert("kins.x-rot-point".into(), -50.0);
    machine.params.ini_values.insert("SETUP]XPOS".into(), 3.25);
    let program = "G0 X#<_hal[kins.x-rot-point]> Y#<_ini[setup]xpos>\n\
                   o1 if [EXISTS[#<_hal[kins.nothing]>] OR EXISTS[#<_ini[setup]ypos>]]\n\
                   G0 Z99\n\
                   o1 else\n\
                   G0 Z[EXISTS[#<_ini[SETUP]XPOS>] + 1]\n\
                   o1 endif\n\
                   G0 X#<_hal[kins.nothing]>\nM2\n";
    let mut runner = Runner::new(
        &machine,
        Offsets::default(),
        SliceSource::new(program.as_bytes()),
        RunOptions::default(),
    );
    let mut ends = Vec::new();
    let alarm = loop {
        match runner.next_segment() {
            Ok(Some(seg)) => {
                let r = seg.row(&machine, 1.0);
                ends.push([r.joints[0], r.joints[1], r.joints[2]]);
            }
            Ok(None) => break None,
            Err(RunError::Alarm { alarm, .. }) => break Some(alarm),
            Err(e) => panic!("{e}"),
        }
    };
    assert_eq!(ends, vec![[-50.0, 3.25, 0.0], [-50.0, 3.25, 2.0]]);
    // A pin the machine file does not list is an unknown parameter.
    let alarm = alarm.expect("unknown pin");
    assert_eq!((alarm.code.to_string().as_str(), alarm.line), ("FX0113", 7));
}

/// G73 / G83 peck clearance (g-code.adoc, G73, G83: "Rapid up either the
/// D value, the G73_PECK_CLEARANCE specified in the INI file or the
/// default of .010\" / 0.254 mm"). rs274 2.9 still refuses D there (a
/// LinuxCNC 2.10 word); the default is what rs274 prints.
#[test]
fn peck_clearance_from_d_the_ini_file_or_the_default() {
    let z_of = |machine: &Machine, program: &str| -> Vec<f64> {
        let mut runner = Runner::new(
            machine,
            Offsets::default(),
            SliceSource::new(program.as_bytes()),
            RunOptions::default(),
        );
        let mut z = Vec::new();
        while let Some(seg) = runner.next_segment().expect("runs") {
            z.push(seg.end[2]);
        }
        z
    };
    let g83 = "G0 Z10\nG83 X0 Y0 Z-2 R1 Q1.5 F100\nG80\nM2\n";
    let g83_d = "G0 Z10\nG83 X0 Y0 Z-2 R1 Q1.5 D0.5 F100\nG80\nM2\n";
    let g73 = "G0 Z10\nG73 X0 Y0 Z-2 R1 Q1.5 F100\nG80\nM2\n";
    let mut machine = mill();
    // Down to -0.5, out to R, back to 0.254 above -0.5, on to -2, out.
    assert_eq!(
        z_of(&machine, g83),
        vec![10.0, 1.0, -0.5, 1.0, -0.5 + 0.254, -2.0, 10.0]
    );
    assert_eq!(
        z_of(&machine, g83_d),
        vec![10.0, 1.0, -0.5, 1.0, 0.0, -2.0, 10.0]
    );
    machine
        .params
        .ini_values
        .insert("RS274NGC]G73_PECK_CLEARANCE".into(), 0.75);
    assert_eq!(z_of(&machine, g73), vec![10.0, 1.0, -0.5, 0.25, -2.0, 10.0]);
    // In inch configurations the INI value is inches: 0.75 in = 19.05 mm.
    machine.params.input_unit = fiveaxis_machine::InputUnit::Inch;
    let z = z_of(
        &machine,
        "G21 G0 Z10\nG73 X0 Y0 Z-40 R1 Q30 F100\nG80\nM2\n",
    );
    assert_eq!(z.len(), 6, "{z:?}");
    assert!((z[3] - (-29.0 + 19.05)).abs() < 1e-9, "{z:?}");
    // D in a G73 / G83 block is not a tool number; a negative D is refused.
    let a = alarm("G83 X0 Y0 Z-2 R1 Q1 D-1 F100\n");
    assert_eq!(a.condition, Condition::ValueOutOfRange);
}

/// `G10 L2 R`: the system turns counter-clockwise about its origin, with
/// the G92 / G52 offset inside the turn (coordinates.adoc; rs274 prints
/// `SET_XY_ROTATION` and the offsets, reckoned in turned coordinates).
/// Machine positions written out by hand: origin + Rz(θ)·(p + g92).
#[test]
fn rotated_coordinate_systems_turn_the_program_and_its_g92_offset() {
    let rz = |deg: f64, x: f64, y: f64| {
        let (s, c) = deg.to_radians().sin_cos();
        [c * x - s * y, s * x + c * y]
    };
    let close = |got: &[[f64; 3]], want: &[[f64; 3]]| {
        assert_eq!(got.len(), want.len(), "{got:?}");
        for (g, w) in got.iter().zip(want) {
            for k in 0..3 {
                assert!((g[k] - w[k]).abs() < 1e-9, "{got:?} != {want:?}");
            }
        }
    };
    // G92 at program (1, 1) with G52 (1, 2) in force: the offset becomes
    // (2, 3), as rs274 prints; G52 X0 Y0 then clears the shared register.
    let program = "G10 L2 P1 X10 R30\nG54\nG52 X1 Y2\nG0 X1 Y1\nG92 X0 Y0\nG0 X1 Y0\n\
                   G52 X0 Y0\nG0 X0 Y0\nM2\n";
    let [a, b] = rz(30.0, 2.0, 3.0);
    let [c, d] = rz(30.0, 3.0, 3.0);
    close(
        &ends(program, Offsets::default()),
        &[[10.0 + a, b, 0.0], [10.0 + c, d, 0.0], [10.0, 0.0, 0.0]],
    );
    // G10 L20 under a turn: the origin is where the current point reads the
    // values (rs274: SET_G5X_OFFSET(1, 14.3301, 2.5000, …)); G10 L20 R is
    // refused as by rs274; #5230 reads and writes the angle.
    let program = "G10 L2 P1 X10 R30\nG54 G0 X5 Y0\nG10 L20 P1 X0 Y0\nG0 X1 Y0\n\
                   #5230 = [#5230 + 60]\nG0 X1 Y0\nM2\n";
    let [e, f] = rz(30.0, 5.0, 0.0);
    let [g, h] = rz(30.0, 1.0, 0.0);
    close(
        &ends(program, Offsets::default()),
        &[
            [10.0 + e, f, 0.0],
            [10.0 + e + g, f + h, 0.0],
            [10.0 + e, f + 1.0, 0.0],
        ],
    );
    let a = alarm("G10 L20 P1 X1 R45\n");
    assert_eq!(a.condition, Condition::WordNotUsed);
    // A G18 arc in a turned system: its plane turns too (the end point
    // and the circle both, checked at the end).
    let program = "G10 L2 P1 R90\nG54 G0 X0 Y0 Z0\nG18 G2 X2 Z0 I1 K0 F100\nM2\n";
    close(&ends(program, Offsets::default()), &[[0.0, 2.0, 0.0]]);
}

/// G10 L20 for a system other than the one in use: the current position
/// reads the values in that system (rs274: G54 at X5, `G10 L20 P2 X0`
/// makes G55's X offset 5).
#[test]
fn g10_l20_for_another_system_measures_from_the_machine_position() {
    let program = "G10 L2 P2 X100\nG54 G0 X5\nG10 L20 P2 X0\nG55 G0 X1\nM2\n";
    assert_eq!(
        ends(program, Offsets::default()),
        vec![[5.0, 0.0, 0.0], [6.0, 0.0, 0.0]]
    );
}

/// G52 writes G92's register and its parameters: after `G52 X3`, G92.2
/// drops the offset and G92.3 brings it back (rs274: SET_G92_OFFSET 3,
/// 0, 3).
#[test]
fn g52_shares_g92s_register_and_parameters() {
    let program = "G52 X3\nG0 X0\nG92.2\nG0 X0\nG92.3\nG0 X0\nM2\n";
    assert_eq!(
        ends(program, Offsets::default()),
        vec![[3.0, 0.0, 0.0], [0.0, 0.0, 0.0], [3.0, 0.0, 0.0]]
    );
}

/// G33 / G33.1 / G76: feeds per spindle revolution (g-code.adoc); the
/// passes of G76 are checked against rs274 by the differential test, the
/// manual's errors here.
#[test]
fn spindle_synchronized_motion_feeds_and_errors() {
    let machine = mill();
    let program = "S500 M3\nG0 X0 Y0 Z0\nG33 Z-10 K1.5\nG0 X5\nG33.1 Z-8 K1 I2\nM2\n";
    let mut runner = Runner::new(
        &machine,
        Offsets::default(),
        SliceSource::new(program.as_bytes()),
        RunOptions::default(),
    );
    let mut moves = Vec::new();
    while let Some(seg) = runner.next_segment().expect("runs") {
        moves.push(([seg.end[0], seg.end[2]], seg.feed));
    }
    assert_eq!(
        moves,
        vec![
            ([0.0, -10.0], Some(750.0)),
            ([5.0, -10.0], None),
            ([5.0, -8.0], Some(500.0)),
            // Back at twice the speed (I2).
            ([5.0, -10.0], Some(1000.0)),
        ]
    );
    for (program, condition) in [
        ("G33 Z-1 K1\n", Condition::NoSpindleForFeedPerRev),
        ("S500 M3\nG33 Z-1\n", Condition::CycleDataMissing),
        ("S500 M3\nG33 Z-1 K1 F100\n", Condition::WordNotUsed),
        (
            "S500 M3\nG0 X1 Z0\nG76 P1 Z-5 I-1 J0.1 K0.5\n",
            Condition::CycleNotAllowed,
        ),
        (
            "S500 M3\nG18 G0 X1 Z0\nG76 P1 X2 Z-5 I-1 J0.1 K0.5\n",
            Condition::WordNotUsed,
        ),
        (
            "S500 M3\nG18 G0 X1 Z0\nG76 P1 Z-5 I-1 K0.5\n",
            Condition::CycleDataMissing,
        ),
        (
            "S500 M3\nG18 G0 X1 Z0\nG76 P1 Z-5 I-1 J0 K0.5\n",
            Condition::ValueOutOfRange,
        ),
        (
            "S500 M3\nG18 G0 X1 Z0\nG76 P1 Z-5 I-1 J0.1 K0.5 R0.5\n",
            Condition::ValueOutOfRange,
        ),
        (
            "S500 M3\nG18 G0 X1 Z0\nG76 P1 Z-5 I-1 J0.1 K0.5 E3 L1\n",
            Condition::ValueOutOfRange,
        ),
        (
            "S500 M3\nG18 G0 X1 Z0\nG76 P1 Z-5 I-1 J0.1 K0.5 H-1\n",
            Condition::ValueOutOfRange,
        ),
        // Beyond the bound on passes: an alarm, not a run without end.
        (
            "S500 M3\nG18 G0 X1 Z0\nG76 P1 Z-5 I-1 J0.1 K0.5 H99999999999\n",
            Condition::ValueOutOfRange,
        ),
    ] {
        let a = alarm(program);
        assert_eq!(a.condition, condition, "{program}: {a:?}");
    }
    // G76 is modal: a later Z word threads again, needing its words
    // (rs274: "P word missing with G76"); a block without axis words
    // does nothing.
    let a = alarm("S500 M3\nG18 G0 X1 Z0\nG76 P1 Z-5 I-1 J0.2 K0.5\nG17\nG18\nZ-8\n");
    assert_eq!((a.condition, a.line), (Condition::CycleDataMissing, 6));
}

/// G7 reads X words as diameters (rs274: `G7 G0 X10` prints X 5; the
/// arc's I stays a radius; readbacks stay radii); M19 takes R Q P.
#[test]
fn lathe_diameter_mode_and_spindle_orientation() {
    let program = "G18 G7\nG0 X10 Z1\nG91 X2\nG90\nG0 Z#5420\nG8\nX3\nM19 R45 Q2 P1\nM2\n";
    assert_eq!(
        ends(program, Offsets::default()),
        vec![
            [5.0, 0.0, 1.0],
            [6.0, 0.0, 1.0],
            [6.0, 0.0, 6.0],
            [3.0, 0.0, 6.0]
        ]
    );
    let a = alarm("M19 R400\n");
    assert_eq!(a.condition, Condition::ValueOutOfRange);
    let a = alarm("M19 P3\n");
    assert_eq!(a.condition, Condition::ValueOutOfRange);
}

/// G5 and G5.1 (g-code.adoc): every chord end lies on the curve written
/// out here with Bernstein polynomials, and every chord stays within
/// 0.001 mm of it (checked at the chords' middles).
#[test]
fn splines_follow_their_curves_within_the_tolerance() {
    let cubic = |c: [[f64; 2]; 4], t: f64| {
        let u = 1.0 - t;
        let b = [u * u * u, 3.0 * u * u * t, 3.0 * u * t * t, t * t * t];
        [0, 1].map(|a| (0..4).map(|k| b[k] * c[k][a]).sum::<f64>())
    };
    let quadratic = |c: [[f64; 2]; 3], t: f64| {
        let u = 1.0 - t;
        let b = [u * u, 2.0 * u * t, t * t];
        [0, 1].map(|a| (0..3).map(|k| b[k] * c[k][a]).sum::<f64>())
    };
    let check = |points: &[[f64; 3]], curve: &dyn Fn(f64) -> [f64; 2]| {
        let n = points.len();
        assert!(n > 4, "{n} chords");
        for (k, p) in points.iter().enumerate() {
            let t = (k + 1) as f64 / n as f64;
            let c = curve(t);
            assert!(
                (p[0] - c[0]).hypot(p[1] - c[1]) < 1e-9,
                "vertex {k}: {p:?} {c:?}"
            );
            let prev = if k == 0 {
                curve(0.0)
            } else {
                [points[k - 1][0], points[k - 1][1]]
            };
            let mid = [(prev[0] + p[0]) / 2.0, (prev[1] + p[1]) / 2.0];
            let c = curve((k as f64 + 0.5) / n as f64);
            assert!(
                (mid[0] - c[0]).hypot(mid[1] - c[1]) <= 0.001,
                "chord {k} strays"
            );
        }
    };
    // The manual's curvy N, then a second one continuing it (I, J = −P, −Q
    // of the first), then a G5.1 parabola.
    let program = "G17 G0 X0 Y0 Z2\nG1 F100\nG5 I0 J3 P0 Q-3 X1 Y1\nG5 P0 Q-3 X2 Y2\n\
                   G0 X-2 Y4\nG5.1 X2 I2 J-8\nM2\n";
    let points = ends(program, Offsets::default());
    let first: Vec<_> = points
        .iter()
        .skip(1)
        .take_while(|p| p[0] <= 1.0 + 1e-12 && p[1] <= 1.0 + 1e-12)
        .copied()
        .collect();
    let n1 = first.len();
    check(&first, &|t| {
        cubic([[0.0, 0.0], [0.0, 3.0], [1.0, -2.0], [1.0, 1.0]], t)
    });
    let second: Vec<_> = points[1 + n1..]
        .iter()
        .take_while(|p| p[0] >= 1.0 - 1e-12 && p[0] <= 2.0 + 1e-12 && p[1] >= 1.0 - 1e-9 - 3.0)
        .copied()
        .collect();
    let n2 = second
        .iter()
        .position(|p| *p == [2.0, 2.0, 2.0])
        .expect("ends at X2 Y2")
        + 1;
    check(&second[..n2], &|t| {
        cubic([[1.0, 1.0], [1.0, 4.0], [2.0, -1.0], [2.0, 2.0]], t)
    });
    let parabola = &points[1 + n1 + n2 + 1..];
    check(parabola, &|t| {
        quadratic([[-2.0, 4.0], [0.0, -4.0], [2.0, 4.0]], t)
    });
    assert!(points.iter().all(|p| p[2] == 2.0), "Z stays");
    for (program, condition) in [
        ("G5 X1 Y1 P0 Q1\n", Condition::CycleDataMissing),
        ("G5 I1 X1 Y1 P0 Q1\n", Condition::CycleDataMissing),
        ("G5 I1 J1 X1 Y1\n", Condition::CycleDataMissing),
        ("G5 I1 J1 P1 Q1 X1 Z1\n", Condition::WordNotUsed),
        ("G18 G5 I1 J1 P1 Q1 X1\n", Condition::WordNotUsed),
        ("G5.1 X1 Y1\n", Condition::CycleDataMissing),
        // A G1 between ends the series: the next G5 needs I and J again.
        (
            "G5 I0 J1 P0 Q-1 X1 Y1 F100\nG1 X2\nG5 P0 Q-1 X3 Y1\n",
            Condition::CycleDataMissing,
        ),
    ] {
        let a = alarm(program);
        assert_eq!(a.condition, condition, "{program}: {a:?}");
    }
}
