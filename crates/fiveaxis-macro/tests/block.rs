//! NC blocks with macro values into `fiveaxis_gcode::Block`s.

mod common;

use common::TestSystem;
use fiveaxis_gcode::{Block, Code, Span};
use fiveaxis_macro::{
    MacroErrorKind as K, MacroSettings, Statement, Variables, evaluate_block, parse_statement,
};

fn block(text: &str, setup: &[(u32, f64)]) -> Result<Block, fiveaxis_macro::MacroError> {
    let s = MacroSettings::default();
    let mut sys = TestSystem::default();
    let mut vars = Variables::new(4);
    for &(n, v) in setup {
        vars.set(n, Some(v), &mut sys, &s).expect("set");
    }
    let line = parse_statement(text.as_bytes(), 3)?;
    let Statement::Nc(nc) = line.statement else {
        panic!("not NC: {text}")
    };
    let mut out = Block::default();
    out.words.push(fiveaxis_gcode::Word {
        letter: b'Q',
        value: 9.0,
        decimal_point: false,
        code: None,
        computed: false,
        span: Span::default(),
    });
    evaluate_block(&nc, &vars, &sys, &s, &mut out).map(|()| out)
}

#[test]
fn words_from_variables_and_expressions() {
    let b = block(
        "N7 G#10 X#24 Y-[#25+1.] F#9 M3",
        &[(10, 43.4), (24, 10.0), (25, 2.0), (9, 100.0)],
    )
    .expect("ok");
    assert_eq!(b.line, 3);
    assert_eq!(b.sequence, Some(7));
    let w = &b.words;
    assert_eq!(w.len(), 5);
    assert_eq!(
        (w[0].letter, w[0].value, w[0].decimal_point, w[0].code),
        (b'G', 43.4, true, Some(Code::new(43, 4)))
    );
    assert_eq!(w[0].span, Span::new(4, 8));
    assert_eq!(
        (w[1].letter, w[1].value, w[1].decimal_point),
        (b'X', 10.0, true)
    );
    assert_eq!((w[2].letter, w[2].value, w[2].code), (b'Y', -3.0, None));
    assert_eq!(w[2].span, Span::new(14, 24));
    assert_eq!(w[3].value, 100.0);
    assert_eq!(
        (w[4].letter, w[4].value, w[4].decimal_point, w[4].code),
        (b'M', 3.0, false, Some(Code::new(3, 0)))
    );
}

#[test]
fn code_rounding() {
    let code = |v: f64| block("G#1", &[(1, v)]).expect("ok").words[0].code;
    assert_eq!(code(43.449), Some(Code::new(43, 4)));
    assert_eq!(code(43.45), Some(Code::new(43, 5)));
    assert_eq!(code(0.96), Some(Code::new(1, 0)));
    assert_eq!(code(1.0), Some(Code::new(1, 0)));
    assert_eq!(code(-1.0), None);
    assert_eq!(code(65536.0), None);
    assert_eq!(block("G[1+0.04]", &[]).expect("ok").words[0].value, 1.04);
}

#[test]
fn vacant_words_are_left_out() {
    let b = block("G00 X#1 Y-#2 Z[#3] A[#3+1] B#0", &[]).expect("ok");
    let letters: Vec<u8> = b.words.iter().map(|w| w.letter).collect();
    assert_eq!(letters, b"GA");
    assert_eq!(b.words[1].value, 1.0);
}

#[test]
fn literals_match_the_gcode_front_end() {
    let text = "/N12 G43.4 X-1.5 Y100 Z.5 M98 P1000";
    let ours = block(text, &[]).expect("ok");
    let mut theirs = Block::default();
    fiveaxis_gcode::parse_line(text.as_bytes(), 3, &mut theirs).expect("plain");
    assert_eq!(ours, theirs);
    let tape = block("%", &[]).expect("ok");
    assert!(tape.tape_mark);
}

#[test]
fn errors_leave_the_block_empty() {
    let e = block("G01 X[1/#1] Y2", &[]).expect_err("alarm");
    assert_eq!(e.kind, K::DivisionByZero);
    assert_eq!(e.span, Span::new(7, 11));
}
