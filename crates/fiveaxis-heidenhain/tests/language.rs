//! Q parameters, formulas, FN functions, labels, calls and errors.

mod common;

use common::{FakeSystem, StrictText, options, run, run_err, run_q, run_with, w};
use fiveaxis_heidenhain::{
    Executed, Interpreter, Kind, LangErrorKind, MemoryStore, Options, Span, Step,
};

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

#[test]
fn formulas_and_precedence() {
    let i = run_q(
        "Q1 = 2 + 3 * 4\nQ2 = (2 + 3) * 4\nQ3 = -2 ^ 2\nQ4 = 2 ^ 3 ^ 2\nQ5 = SIN 30 * 2\nQ6 = SQ 3 + SQRT 16\nQ7 = 400 % 360\nQ8 = 10 / 4 - 1\nQ9 = ABS -3 + INT 2.7 + FRAC 2.5\nQ10 = SGN -4\nQ11 = SGN 0\nQ12 = NEG Q1\nQ13 = PI\nQ14 = LN EXP 2\nQ15 = LOG 1000\nQ16 = ATAN 1 + ASIN 1 + ACOS 1\nQ17 = COS 60 + TAN 45\nq18=q1-q2--1",
    );
    assert_eq!(i.q(1), 14.0);
    assert_eq!(i.q(2), 20.0);
    assert_eq!(i.q(3), -4.0);
    assert_eq!(i.q(4), 512.0);
    assert!(close(i.q(5), 1.0));
    assert_eq!(i.q(6), 13.0);
    assert_eq!(i.q(7), 40.0);
    assert_eq!(i.q(8), 1.5);
    assert_eq!(i.q(9), 5.5);
    assert_eq!(i.q(10), -1.0);
    assert_eq!(i.q(11), 1.0);
    assert_eq!(i.q(12), -14.0);
    assert!(close(i.q(13), std::f64::consts::PI));
    assert!(close(i.q(14), 2.0));
    assert!(close(i.q(15), 3.0));
    assert!(close(i.q(16), 135.0));
    assert!(close(i.q(17), 1.5));
    assert_eq!(i.q(18), -5.0);
}

#[test]
fn local_kept_and_string_parameters() {
    let i = run_q(
        "QL3 = 4\nQR2 = QL3 * 2\nQ1 = QL3 + QR2\nQS1 = \"AB\"\nQS2 = QS1 || \"CDE\"\nQ2 = STRLEN ( SRC_QS2 )\nQS3 = SUBSTR ( SRC_QS2 BEG1 LEN3 )\nQ3 = TONUMB ( SRC_\"12.5\" )\nQS4 = TOCHAR ( DAT+Q3 DECIMALS2 )\nDECLARE STRING QS5 = \"X\"\nQS6 = STRF QS5 || QS5",
    );
    assert_eq!(i.ql(3), 4.0);
    assert_eq!(i.qr(2), 8.0);
    assert_eq!(i.q(1), 12.0);
    assert_eq!(i.qs(2), "ABCDE");
    assert_eq!(i.q(2), 5.0);
    assert_eq!(i.qs(3), "BCD");
    assert_eq!(i.q(3), 12.5);
    assert_eq!(i.qs(4), "12.50");
    assert_eq!(i.qs(6), "XX");
}

#[test]
fn fn_arithmetic() {
    let i = run_q(
        "FN 0: Q1 = +5\nFN 0:Q2=3\nFN 1: Q3 = +Q1 + +Q2\nFN 2: Q4 = +Q1 - +Q2\nFN 3: Q5 = +Q1 * -Q2\nFN 4: Q6 = +Q1 DIV +2\nFN 5: Q7 = SQRT 9\nFN 6: Q8 = SIN-30\nFN 7: Q9 = COS+60\nFN 8: Q10 = +3 LEN +4\nFN 8: Q11 = LEN +6 LEN +8\nFN 13: Q12 = +10 ANG +10\nFN 13: Q13 = +0 ANG -5",
    );
    assert_eq!(i.q(1), 5.0);
    assert_eq!(i.q(3), 8.0);
    assert_eq!(i.q(4), 2.0);
    assert_eq!(i.q(5), -15.0);
    assert_eq!(i.q(6), 2.5);
    assert_eq!(i.q(7), 3.0);
    assert!(close(i.q(8), -0.5));
    assert!(close(i.q(9), 0.5));
    assert_eq!(i.q(10), 5.0);
    assert_eq!(i.q(11), 10.0);
    assert!(close(i.q(12), 45.0));
    assert!(close(i.q(13), 270.0));
}

#[test]
fn fn_divide_by_zero_is_arithmetic() {
    let e = run_err("L X+1\nFN 4: Q1 = +1 DIV +0");
    assert_eq!(e.kind, LangErrorKind::Arithmetic);
    assert_eq!(e.line, 2);
    assert_eq!(run_err("Q1 = 1 / (2 - 2)").kind, LangErrorKind::Arithmetic);
    assert_eq!(run_err("Q1 = SQRT -1").kind, LangErrorKind::Arithmetic);
    assert_eq!(
        run_err("FN 5: Q1 = SQRT -4").kind,
        LangErrorKind::Arithmetic
    );
    assert_eq!(run_err("Q1 = LN 0").kind, LangErrorKind::Arithmetic);
}

#[test]
fn fn_conditional_jumps() {
    let v = run(
        "Q1 = 1\nFN 9: IF +Q1 EQU +1 GOTO LBL 5\nL X+1\nLBL 5\nFN 10: IF +Q1 NE +1 GOTO LBL 6\nL X+2\nLBL 6\nFN 11: IF +Q1 GT +0 GOTO LBL \"A\"\nL X+3\nLBL \"A\"\nFN 12: IF +Q1 LT +0 GOTO LBL 7\nL X+4\nLBL 7",
    );
    let xs: Vec<f64> = v.iter().map(|b| w(b, "X")).collect();
    assert_eq!(xs, [2.0, 4.0]);
}

#[test]
fn backward_jump_loop_counts() {
    let v = run("Q1 = 0\nLBL 1\nQ1 = Q1 + 1\nL X+Q1\nFN 12: IF +Q1 LT +4 GOTO LBL 1\nL Z+0");
    let xs: Vec<f64> = v
        .iter()
        .filter_map(|b| b.word("X").map(|w| w.value))
        .collect();
    assert_eq!(xs, [1.0, 2.0, 3.0, 4.0]);
    assert_eq!(v.last().map(|b| w(b, "Z")), Some(0.0));
    // Lines after a jump back keep their numbers.
    assert_eq!(v[3].line, 4);
    assert_eq!(v[4].line, 6);
}

#[test]
fn fn_error_print_and_sysread() {
    let e = run_err("L X+1\nFN 14: ERROR = 1000");
    assert_eq!(e.kind, LangErrorKind::ProgramError(1000));
    assert_eq!(e.line, 2);
    let mut i = Interpreter::new(
        Box::new(StrictText::new(
            "Q1 = 3\nFN 15: PRINT Q1\nFN 15: PRINT \"HELLO\"\nFN 16: F-PRINT TNC:\\MASK.A/TNC:\\OUT.TXT\nFN 18: SYSREAD Q25 = ID210 NR1 IDX3\nFN 18: SYSREAD Q26 = ID1 NR2\nL X+Q25",
        )),
        Box::new(MemoryStore::new()),
        options(),
    )
    .expect("new");
    let mut sys = FakeSystem::default();
    sys.data.insert((210, 1, Some(3)), 7.5);
    sys.data.insert((1, 2, None), 2.0);
    let mut b = Executed::default();
    assert_eq!(i.next_block(&mut sys, &mut b), Ok(Step::Block));
    assert_eq!(w(&b, "X"), 7.5);
    assert_eq!(i.q(26), 2.0);
    assert_eq!(i.notes().len(), 3);
    assert!(i.notes()[0].contains('3'));
    assert!(i.notes()[1].contains("HELLO"));
    assert!(i.notes()[2].contains("OUT.TXT"));
    let e = run_err("FN 18: SYSREAD Q25 = ID999 NR1");
    assert_eq!(e.kind, LangErrorKind::Parameter);
    assert!(e.message.contains("ID999"));
}

#[test]
fn subprogram_call_returns_after_call() {
    let v = run(
        "0 BEGIN PGM S MM\n1 CALL LBL 1\n2 L X+2\n3 CALL LBL \"SUB\"\n4 L X+4\n5 M30\n6 LBL 1\n7 L X+10\n8 LBL 0\n9 LBL \"SUB\"\n10 L X+20\n11 CALL LBL 1\n12 LBL 0\n13 END PGM S MM",
    );
    let xs: Vec<f64> = v
        .iter()
        .filter_map(|b| b.word("X").map(|w| w.value))
        .collect();
    assert_eq!(xs, [10.0, 2.0, 20.0, 10.0, 4.0]);
    assert_eq!(v[0].line, 8);
    assert_eq!(v.last().map(|b| b.m[0].0), Some(30));
}

#[test]
fn section_repeat_runs_rep_plus_one_times() {
    let v = run(
        "Q1 = 0\nLBL 1\nQ1 = Q1 + 1\nL X+Q1\nCALL LBL 1 REP 2\nL Y+1\nLBL 2\nL X+100\nCALL LBL 2 REP 1\nLBL 3\nQ2 = Q2 + 1\nFN 12: IF +Q2 LT +2 GOTO LBL 4\nL Z+Q2\nLBL 4\nCALL LBL 3 REP0/0\nLBL5\nL Z+9\nCALL LBL5 REP1",
    );
    let xs: Vec<f64> = v
        .iter()
        .filter_map(|b| b.word("X").map(|w| w.value))
        .collect();
    assert_eq!(xs, [1.0, 2.0, 3.0, 100.0, 100.0]);
    assert_eq!(v.iter().filter(|b| b.word("Y").is_some()).count(), 1);
    // LBL5 without a space, REP1 glued: read as LBL 5 and REP 1.
    assert_eq!(v.iter().filter(|b| b.word("Z").is_some()).count(), 2);
}

#[test]
fn repeat_counter_resets_for_the_next_pass() {
    // An outer loop runs the inner section repeat twice: 2 × 2 passes.
    let v = run(
        "LBL 9\nQ9 = Q9 + 1\nLBL 1\nL X+1\nCALL LBL 1 REP 1\nFN 12: IF +Q9 LT +2 GOTO LBL 9\nL Z+0",
    );
    assert_eq!(v.iter().filter(|b| b.word("X").is_some()).count(), 4);
}

#[test]
fn forward_label_search_remembers_and_comes_back() {
    let v = run("CALL LBL 7\nL X+1\nCALL LBL 7\nM30\nLBL 7\nL X+7\nLBL 0");
    let xs: Vec<f64> = v
        .iter()
        .filter_map(|b| b.word("X").map(|w| w.value))
        .collect();
    assert_eq!(xs, [7.0, 1.0, 7.0]);
}

#[test]
fn missing_label_is_reported_at_the_call() {
    let e = run_err("L X+1\n  CALL LBL 7 ; where?\nLBL 1");
    assert_eq!(e.kind, LangErrorKind::LabelMissing);
    assert_eq!(e.line, 2);
    assert_eq!(e.span, Span::new(3, 13));
    let e = run_err("FN 9: IF +0 EQU +0 GOTO LBL \"NOPE\"");
    assert_eq!(e.kind, LangErrorKind::LabelMissing);
    assert!(e.message.contains("NOPE"));
}

#[test]
fn call_pgm_through_the_store() {
    let store = MemoryStore::new()
        .with("SUB1.H", "0 BEGIN PGM SUB1 MM\n1 QL1 = 5\n2 Q7 = Q7 + QL1\n3 L X+Q7\n4 END PGM SUB1 MM\n5 L X+999")
        .with("DEEP", "CALL PGM SUB1");
    let text = "0 BEGIN PGM MAIN MM\nQL1 = 1\nCALL PGM TNC:\\PARTS\\SUB1.H\nCALL PGM sub1\nCALL PGM DEEP\nL Y+QL1\nEND PGM MAIN MM";
    let v = run_with(text, store.clone(), options())
        .map_err(|(e, _)| e)
        .expect("runs");
    let mut i =
        Interpreter::new(Box::new(StrictText::new(text)), Box::new(store), options()).expect("new");
    let mut b = Executed::default();
    while i.next_block(&mut FakeSystem::default(), &mut b) == Ok(Step::Block) {}
    assert_eq!(i.program_name(0), "MAIN");
    assert_eq!(i.program_name(1), "SUB1");
    assert_eq!(i.program_name(2), "DEEP");
    assert_eq!(i.program_name(3), "");
    let xs: Vec<f64> = v
        .iter()
        .filter_map(|b| b.word("X").map(|w| w.value))
        .collect();
    assert_eq!(xs, [5.0, 10.0, 15.0]);
    assert_eq!(v[0].program, 1);
    assert_eq!(v[0].line, 4);
    assert_eq!(v[1].program, 1);
    assert_eq!(v[2].program, 1);
    // QL is local: the main program's QL1 is still 1.
    assert_eq!(w(&v[3], "Y"), 1.0);
    assert_eq!(v[3].program, 0);
}

#[test]
fn missing_program_and_nesting() {
    let e = run_err("L X+1\nCALL PGM NOWHERE");
    assert_eq!(e.kind, LangErrorKind::ProgramMissing);
    assert_eq!(e.line, 2);
    let store = MemoryStore::new().with("SELF", "CALL PGM SELF");
    let e = run_with("CALL PGM SELF", store, options())
        .map(|_| ())
        .expect_err("nesting");
    assert_eq!(e.0.kind, LangErrorKind::Nesting);
    let e = run_err("LBL 1\nCALL LBL 1");
    assert_eq!(e.kind, LangErrorKind::Nesting);
}

#[test]
fn budget_stops_runaway_loops() {
    let opts = Options {
        block_skip: false,
        max_blocks: 50,
    };
    let e = run_with(
        "LBL 1\nL X+1\nFN 9: IF +0 EQU +0 GOTO LBL 1",
        MemoryStore::new(),
        opts,
    )
    .expect_err("runaway");
    assert_eq!(e.0.kind, LangErrorKind::Budget);
    assert!(e.1.len() > 10);
}

#[test]
fn m30_and_end_pgm_end_the_program() {
    let text = "0 BEGIN PGM E INCH\n1 L X+1 M30\n2 L X+2\n3 END PGM E INCH";
    let mut i = Interpreter::new(
        Box::new(StrictText::new(text)),
        Box::new(MemoryStore::new()),
        options(),
    )
    .expect("new");
    let mut sys = FakeSystem::default();
    let mut b = Executed::default();
    assert_eq!(i.next_block(&mut sys, &mut b), Ok(Step::Block));
    assert_eq!(b.m[0].0, 30);
    assert_eq!(i.next_block(&mut sys, &mut b), Ok(Step::End));
    assert_eq!(i.next_block(&mut sys, &mut b), Ok(Step::End));
    assert_eq!(i.program_name(0), "E");
    assert!(i.inch());
    assert_eq!(i.line_text(), b"1 L X+1 M30");
    assert_eq!(i.blocks(), 2);
    let v = run("0 BEGIN PGM E MM\nL X+1\nEND PGM E MM\nL X+2");
    assert_eq!(v.len(), 1);
    assert_eq!(v[0].kind, Kind::Line);
}

#[test]
fn syntax_errors_have_line_and_span() {
    let e = run_err("L X+1\n5 L X+1 $$");
    assert_eq!(e.kind, LangErrorKind::Syntax);
    assert_eq!(e.line, 2);
    assert_eq!(e.span, Span::new(9, 11));
    let e = run_err("FOO BAR");
    assert_eq!(e.kind, LangErrorKind::Syntax);
    assert_eq!(e.span, Span::new(1, 4));
    let e = run_err("Q2000 = 1");
    assert_eq!(e.kind, LangErrorKind::Parameter);
    let e = run_err("Q1 = (1 + 2");
    assert_eq!(e.kind, LangErrorKind::Syntax);
    let e = run_err("FN 99: Q1 = 1");
    assert_eq!(e.kind, LangErrorKind::Syntax);
}

#[test]
fn set_q_feeds_plane_stay_values() {
    let mut i = Interpreter::new(
        Box::new(StrictText::new(
            "PLANE SPATIAL SPA+90 SPB+0 SPC+0 STAY\nL A+Q120 C+Q122 R0 FMAX",
        )),
        Box::new(MemoryStore::new()),
        options(),
    )
    .expect("new");
    let mut sys = FakeSystem::default();
    let mut b = Executed::default();
    assert_eq!(i.next_block(&mut sys, &mut b), Ok(Step::Block));
    i.set_q(120, 90.0);
    i.set_q(122, -45.0);
    assert_eq!(i.next_block(&mut sys, &mut b), Ok(Step::Block));
    assert_eq!(w(&b, "A"), 90.0);
    assert_eq!(w(&b, "C"), -45.0);
}
