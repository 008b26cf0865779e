//! Control structures, jumps, skip levels, the block budget: programs and
//! the words they must give.

mod common;

use common::fake::{FakeStore, FakeSystem, run, run_with};
use fiveaxis_sinumerik::Options;

/// A program and its words in order (the `M=30` of the end left out).
const PROGRAMS: &[(&str, &str, &[&str])] = &[
    (
        "nested IF / ELSE",
        "R1=1\nIF R1==1\nIF R2==1\nX1\nELSE\nX2\nENDIF\nELSE\nX3\nENDIF\nX4",
        &["X=2", "X=4"],
    ),
    (
        "false IF skips nested IFs to its ELSE",
        "IF R1==1\nIF 1\nX1\nELSE\nX2\nENDIF\nX3\nELSE\nX4\nIF 1\nX5\nENDIF\nENDIF\nX6",
        &["X=4", "X=5", "X=6"],
    ),
    (
        "false IF without ELSE",
        "IF 0\nX1\nIF 1\nX2\nENDIF\nENDIF\nX3",
        &["X=3"],
    ),
    (
        "WHILE",
        "R1=0\nWHILE R1<3\nR1=R1+1\nX=R1\nENDWHILE\nY=R1",
        &["X=1", "X=2", "X=3", "Y=3"],
    ),
    (
        "false WHILE skips nested WHILEs",
        "WHILE 0\nWHILE 1\nX1\nENDWHILE\nENDWHILE\nX2",
        &["X=2"],
    ),
    (
        "FOR with an INT counter, one past the end after",
        "DEF INT I\nFOR I=1 TO 3\nX=I\nENDFOR\nY=I",
        &["X=1", "X=2", "X=3", "Y=4"],
    ),
    (
        "FOR with a REAL counter",
        "FOR R1=0.5 TO 2.5\nX=R1\nENDFOR",
        &["X=0.5", "X=1.5", "X=2.5"],
    ),
    (
        "FOR that does not run",
        "FOR R1=5 TO 1\nX1\nENDFOR\nX2",
        &["X=2"],
    ),
    (
        "nested FOR",
        "DEF INT I, J\nFOR I=1 TO 2\nFOR J=1 TO 2\nX=I*10+J\nENDFOR\nENDFOR",
        &["X=11", "X=12", "X=21", "X=22"],
    ),
    (
        "REPEAT / UNTIL",
        "REPEAT\nR1=R1+1\nX=R1\nUNTIL R1>=3",
        &["X=1", "X=2", "X=3"],
    ),
    (
        "LOOP left by a jump",
        "LOOP\nR1=R1+1\nIF R1>2 GOTOF OUT\nX=R1\nENDLOOP\nOUT: Y=R1",
        &["X=1", "X=2", "Y=3"],
    ),
    (
        "WHILE inside FOR inside IF",
        "DEF INT I\nIF 1\nFOR I=1 TO 2\nR1=0\nWHILE R1<I\nR1=R1+1\nX=R1\nENDWHILE\nENDFOR\nENDIF",
        &["X=1", "X=1", "X=2"],
    ),
    (
        "CASE to the matching constant",
        "R1=2\nCASE(R1) OF 1 GOTOF L1 2 GOTOF L2 DEFAULT GOTOF LD\nL1: X1\nL2: X2\nLD: X3",
        &["X=2", "X=3"],
    ),
    (
        "CASE to DEFAULT",
        "R1=7\nCASE(R1) OF 1 GOTOF L1 2 GOTOF L2 DEFAULT GOTOF LD\nL1: X1\nL2: X2\nLD: X3",
        &["X=3"],
    ),
    (
        "CASE without a match or DEFAULT goes on",
        "CASE(R1+5) OF 1 GOTOF L1\nX9\nL1: X1",
        &["X=9", "X=1"],
    ),
    (
        "nearest label in the direction of search",
        "AA: X1\nGOTOF AA\nX2\nAA: X3\nR1=R1+1\nIF R1<2 GOTOB AA\nX4",
        &["X=1", "X=3", "X=3", "X=4"],
    ),
    (
        "GOTO searches forward, then backward",
        "BB: X1\nR1=R1+1\nIF R1<2 GOTO BB\nGOTO CC\nX2\nCC: X3",
        &["X=1", "X=1", "X=3"],
    ),
    (
        "jumps to block numbers",
        "N10 X1\nN20 R1=R1+1\nIF R1<3 GOTOB N10\nGOTOF N50\nN40 X40\nN50 X50",
        &["X=1", "X=1", "X=1", "X=50"],
    ),
    (
        "a block number jump to the nearest of two",
        "N10 X1\nN10 X2\nR1=R1+1\nIF R1<2 GOTOB N10\nX3",
        &["X=1", "X=2", "X=2", "X=3"],
    ),
    (
        "a forward label far ahead, then found in the index",
        "R1=0\nTOP: R1=R1+1\nIF R1<3 GOTOF FAR\nGOTOF DONE\nX0\nX0\nFAR: X=R1\nGOTOB TOP\nDONE: Y=R1",
        &["X=1", "X=2", "Y=3"],
    ),
    (
        "a missing target is no error while not executed",
        "IF R1==1 GOTOF NOWHERE\nX1",
        &["X=1"],
    ),
    (
        "GOTOC to a missing target goes on",
        "GOTOC NOWHERE\nX1",
        &["X=1"],
    ),
    (
        "GOTOS back to the start",
        "R1=R1+1\nX=R1\nIF R1<2 GOTOS",
        &["X=1", "X=2"],
    ),
    (
        "a jump in a block with words yields the block first",
        "X1 GOTOF L\nX2\nL: X3",
        &["X=1", "X=3"],
    ),
    (
        "a thousand passes of a loop",
        "DEF INT I\nFOR I=1 TO 1000\nR2=R2+I\nENDFOR\nX=R2",
        &["X=500500"],
    ),
    (
        "a jump back out of nested loops again and again",
        "START: R1=R1+1\nWHILE 1\nLOOP\nIF R1<50 GOTOB START\nGOTOF END\nENDLOOP\nENDWHILE\nEND: X=R1",
        &["X=50"],
    ),
];

#[test]
fn structures_and_jumps() {
    let mut failures = Vec::new();
    for (what, text, want) in PROGRAMS {
        let r = run(&format!("{text}\nM30\n"));
        if let Some(e) = &r.error {
            failures.push(format!("{what}: error {e:?}"));
            continue;
        }
        let mut got = r.words();
        got.retain(|w| w != "M=30");
        if got != *want {
            got.truncate(20);
            failures.push(format!("{what}: got {got:?}…, want {want:?}"));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// Programs that stop with an alarm on a line.
const ALARMS: &[(&str, &str, u32, u32)] = &[
    ("a missing jump target", "X1\nGOTOF NOWHERE\nX2", 14080, 2),
    (
        "GOTOB finds no label after",
        "GOTOB LATER\nLATER: X1",
        14080,
        1,
    ),
    ("a missing block number", "GOTO N99\nN10 X1", 14080, 1),
    ("ENDIF without IF", "X1\nENDIF", 12080, 2),
    ("ELSE without IF", "ELSE", 12080, 1),
    ("ENDWHILE without WHILE", "ENDWHILE", 12080, 1),
    ("ENDFOR without FOR", "ENDFOR", 12080, 1),
    ("UNTIL without REPEAT", "UNTIL 1", 12080, 1),
    ("ENDLOOP without LOOP", "ENDLOOP", 12080, 1),
    ("a false IF never closed", "X1\nIF 0\nX2", 12080, 2),
    ("a syntax error", "X1\nG1 X=\n", 12080, 2),
];

#[test]
fn alarms_of_flow() {
    let mut failures = Vec::new();
    for (what, text, alarm, line) in ALARMS {
        let r = run(&format!("{text}\nM30\n"));
        match &r.error {
            Some(e) if e.alarm == Some(*alarm) && e.line == *line && !e.message.is_empty() => {}
            other => failures.push(format!("{what}: {other:?}, want {alarm} on line {line}")),
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn missing_target_is_reported_at_the_target() {
    let r = run("X1\nGOTOF NOWHERE\n");
    let e = r.err();
    assert_eq!(
        (e.alarm, e.line, e.span.start, e.span.end),
        (Some(14080), 2, 7, 14)
    );
    assert!(e.message.contains("NOWHERE"), "{}", e.message);
    assert_eq!(r.blocks.len(), 1);
}

#[test]
fn structure_errors_point_at_their_line() {
    let r = run("X1\n  ENDIF ; stray\n");
    let e = r.err();
    assert_eq!(
        (e.alarm, e.line, e.span.start, e.span.end),
        (Some(12080), 2, 3, 16)
    );
    assert!(e.message.contains("ENDIF without IF"), "{}", e.message);
    let r = run("X1\nWHILE R1>0\nX2\n");
    let e = r.err();
    assert_eq!(
        (e.alarm, e.line, e.span.start, e.span.end),
        (Some(12080), 2, 1, 11)
    );
    assert!(e.message.contains("WHILE"), "{}", e.message);
}

#[test]
fn skip_levels() {
    let text = "/X1\n/1 X2\n/2 X3\nX4\nM30\n";
    let words = |levels: u16| {
        let options = Options {
            skip_levels: levels,
            ..Options::default()
        };
        let r = run_with(
            text,
            FakeStore::default(),
            &mut FakeSystem::default(),
            options,
        );
        let mut w = r.words();
        w.retain(|w| w != "M=30");
        w
    };
    assert_eq!(words(0), ["X=1", "X=2", "X=3", "X=4"]);
    assert_eq!(words(0b1), ["X=2", "X=3", "X=4"]);
    assert_eq!(words(0b110), ["X=1", "X=4"]);
    // A skipped line is not even read for errors.
    let r = run_with(
        "/G1 X=\nX1\nM30\n",
        FakeStore::default(),
        &mut FakeSystem::default(),
        Options {
            skip_levels: 1,
            ..Options::default()
        },
    );
    assert_eq!(r.words(), ["X=1", "M=30"]);
}

#[test]
fn runaway_loops_stop_at_the_budget() {
    let options = Options {
        max_blocks: 1000,
        ..Options::default()
    };
    let r = run_with(
        "N5 X0\nLOOP\nR1=R1+1\nENDLOOP\n",
        FakeStore::default(),
        &mut FakeSystem::default(),
        options.clone(),
    );
    let e = r.err();
    assert_eq!(e.alarm, None);
    assert!(e.message.contains("budget"), "{}", e.message);
    assert!(e.message.contains("1000"), "{}", e.message);
    assert_eq!(r.lines, 1000);
    assert!(e.line >= 2 && e.line <= 4, "{e:?}");
    assert!(e.span.start < e.span.end);
    // GOTOB loops count too, searched lines included.
    let r = run_with(
        "TOP: X1\nGOTOB TOP\n",
        FakeStore::default(),
        &mut FakeSystem::default(),
        options.clone(),
    );
    assert!(r.err().message.contains("budget"));
    // A program within the budget runs.
    let r = run_with(
        "DEF INT I\nFOR I=1 TO 100\nX=I\nENDFOR\nM30\n",
        FakeStore::default(),
        &mut FakeSystem::default(),
        options,
    );
    assert_eq!(r.ok().len(), 101);
}

#[test]
fn lines_headers_comments_numbers() {
    let r = run(
        "%_N_TEST_MPF\n;$PATH=/_N_MPF_DIR\n; a comment alone\n\nN10 G1 X1 ; cut\nLBL:\nR1=1\nSTOPRE\nN20 M30\n",
    );
    let blocks = r.ok();
    assert_eq!(blocks.len(), 2);
    assert_eq!(blocks[0].line, 5);
    assert_eq!(blocks[0].number, Some(10));
    assert_eq!(blocks[0].comment.as_deref(), Some(" cut"));
    assert_eq!(blocks[0].program, 0);
    assert_eq!((blocks[1].line, blocks[1].number), (9, Some(20)));
}

#[test]
fn synchronized_actions_are_noted() {
    let r = run("ID=1 WHENEVER $AA_IW[X]>10 DO $AC_MARKER[1]=1\nX1\nM30\n");
    assert_eq!(r.words(), ["X=1", "M=30"]);
    assert_eq!(r.notes, ["line 1: synchronized action read, not simulated"]);
    // Notes are bounded.
    let many = "WHEN $AA_IW[X]>1 DO $AC_MARKER[1]=1\n".repeat(300);
    let r = run(&many);
    r.ok();
    assert_eq!(r.notes.len(), 101);
}

#[test]
fn the_end_comes_once_and_stays() {
    use fiveaxis_sinumerik::{Executed, Interpreter, Step, TextProgram};
    let mut interp = Interpreter::new(
        Box::new(TextProgram::new("X1\nM30\nX2\n")),
        Box::new(FakeStore::default()),
        Options::default(),
    )
    .expect("new");
    let mut sys = FakeSystem::default();
    let mut out = Executed::default();
    let mut steps = Vec::new();
    for _ in 0..5 {
        steps.push(interp.next_block(&mut sys, &mut out).expect("step"));
    }
    assert_eq!(
        steps,
        [Step::Block, Step::Block, Step::End, Step::End, Step::End]
    );
    assert!(out.actions.is_empty());
    assert_eq!(interp.program_name(0), "main");
    assert_eq!(interp.program_name(7), "?");
}

#[test]
fn labels_are_found_in_the_index_block_numbers_by_reading() {
    // A backward jump to a label seeks to the position remembered; one
    // to a block number reads the program again from its start to the
    // jump. Every line read counts.
    let label = run("AA: X1\nX2\nX3\nR1=R1+1\nIF R1<2 GOTOB AA\nM30\n");
    assert_eq!(label.ok().len(), 7);
    assert_eq!(label.lines, 5 + 6);
    let number = run("N10 X1\nX2\nX3\nR1=R1+1\nIF R1<2 GOTOB N10\nM30\n");
    assert_eq!(number.ok().len(), 7);
    assert_eq!(number.lines, 5 + 5 + 6);
    // A forward label not read yet is searched once, then known.
    // A forward label not read yet is searched by reading on: the jump
    // line, lines 2 to 4 searched, then 4 and 5 run.
    let ahead = run("GOTOF FAR\nX1\nX2\nFAR: X3\nM30\n");
    assert_eq!(ahead.words(), ["X=3", "M=30"]);
    assert_eq!(ahead.lines, 1 + 3 + 2);
}
