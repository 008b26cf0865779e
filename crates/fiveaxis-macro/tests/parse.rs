//! Statement shapes, sequence numbers, block delete, comments, fast scans.

use fiveaxis_gcode::Span;
use fiveaxis_macro::{
    BinOp, Expr, Line, MacroErrorKind as K, Statement, VarNumber, WordValue, is_macro_line,
    loop_end, loop_start, parse_statement,
};

fn parse(text: &str) -> Line {
    parse_statement(text.as_bytes(), 7).unwrap_or_else(|e| panic!("{text}: {e:?}"))
}

fn err(text: &str) -> fiveaxis_macro::MacroError {
    match parse_statement(text.as_bytes(), 7) {
        Err(e) => e,
        Ok(l) => panic!("{text}: parsed as {l:?}"),
    }
}

#[test]
fn assignments() {
    let line = parse("#1=5");
    assert_eq!(line.line, 7);
    let Statement::Assign { target, value } = line.statement else {
        panic!()
    };
    assert_eq!(target.number, VarNumber::Direct(1));
    assert_eq!(target.span, Span::new(1, 3));
    assert_eq!(value, Expr::Number(5.0));

    let line = parse("#[#2+100]=#3*2");
    let Statement::Assign { target, value } = line.statement else {
        panic!()
    };
    assert!(matches!(target.number, VarNumber::Indirect(_)));
    assert_eq!(target.span, Span::new(1, 10));
    let Expr::Binary(b) = value else { panic!() };
    assert_eq!(b.op, BinOp::Mul);
    assert_eq!(b.span, Span::new(11, 15));

    let line = parse("  #500 = SIN [ 30. ]  ");
    let Statement::Assign {
        value: Expr::Call(c),
        ..
    } = line.statement
    else {
        panic!()
    };
    assert_eq!(c.span, Span::new(10, 21));
}

#[test]
fn control_statements() {
    assert!(matches!(
        parse("GOTO 10").statement,
        Statement::Goto(Expr::Number(10.0))
    ));
    assert!(matches!(
        parse("GOTO #5").statement,
        Statement::Goto(Expr::Var(_))
    ));
    assert!(matches!(
        parse("goto [#1+1]").statement,
        Statement::Goto(Expr::Binary(_))
    ));
    assert!(matches!(
        parse("IF [#1 GT 10] GOTO 20").statement,
        Statement::IfGoto { .. }
    ));
    assert!(matches!(
        parse("IF[#1EQ#2]THEN#3=0").statement,
        Statement::IfThen { .. }
    ));
    assert!(matches!(
        parse("WHILE [#1 LE 10] DO 1").statement,
        Statement::While { id: 1, .. }
    ));
    assert!(matches!(
        parse("while[#1le10]do3").statement,
        Statement::While { id: 3, .. }
    ));
    assert!(matches!(parse("DO 2").statement, Statement::Do { id: 2 }));
    assert!(matches!(parse("END 1").statement, Statement::End { id: 1 }));
    assert!(matches!(parse("G O T O 1 0").statement, Statement::Goto(_)));
}

#[test]
fn sequence_numbers_block_delete_comments() {
    let line = parse("N10 #1=0");
    assert_eq!(line.sequence, Some(10));
    assert!(matches!(line.statement, Statement::Assign { .. }));
    let line = parse("/N20 WHILE[#1 LT 3]DO1 (LOOP)");
    assert!(line.block_delete);
    assert_eq!(line.sequence, Some(20));
    assert_eq!(line.comment.as_deref(), Some("LOOP"));
    let line = parse("#3000=1(TOOL BROKEN)");
    assert_eq!(line.comment.as_deref(), Some("TOOL BROKEN"));
    let line = parse("#1=1(A)+(B)2 ; #2=3");
    let Statement::Assign { value, .. } = line.statement else {
        panic!()
    };
    assert!(matches!(value, Expr::Binary(_)));
    assert_eq!(line.comment.as_deref(), Some("A"));
    let line = parse("/3 G01 X1");
    assert!(line.block_delete);
    let line = parse("");
    assert!(matches!(line.statement, Statement::Nc(ref nc) if nc.words.is_empty()));
    let line = parse("(ONLY A COMMENT)");
    assert!(matches!(line.statement, Statement::Nc(ref nc) if nc.words.is_empty()));
    let line = parse("%");
    assert!(matches!(line.statement, Statement::Nc(ref nc) if nc.tape_mark));
    let line = parse("#1=2\r\n");
    assert!(matches!(line.statement, Statement::Assign { .. }));
}

#[test]
fn nc_blocks() {
    let line = parse("G#10 X#24 Y-[#25+1.] F#9");
    let Statement::Nc(nc) = line.statement else {
        panic!()
    };
    let letters: Vec<u8> = nc.words.iter().map(|w| w.letter).collect();
    assert_eq!(letters, b"GXYF");
    let spans: Vec<Span> = nc.words.iter().map(|w| w.span).collect();
    assert_eq!(
        spans,
        [
            Span::new(1, 5),
            Span::new(6, 10),
            Span::new(11, 21),
            Span::new(22, 25)
        ]
    );
    assert!(matches!(&nc.words[2].value, WordValue::Expr(Expr::Neg(_))));

    let line = parse("N5 G65 P9010 A1. B#2");
    assert_eq!(line.sequence, Some(5));
    let Statement::Nc(nc) = line.statement else {
        panic!()
    };
    assert_eq!(nc.sequence, Some(5));
    assert_eq!(nc.line, 7);
    assert!(matches!(
        nc.words[2].value,
        WordValue::Literal {
            value: 1.0,
            decimal_point: true,
            ..
        }
    ));
    assert!(matches!(
        nc.words[0].value,
        WordValue::Literal { value: 65.0, decimal_point: false, code: Some(c) } if c == fiveaxis_gcode::Code::new(65, 0)
    ));
    let line = parse("G01 X-1.5 N30");
    assert_eq!(line.sequence, Some(30));
    let Statement::Nc(nc) = line.statement else {
        panic!()
    };
    assert!(matches!(
        nc.words[1].value,
        WordValue::Literal {
            value: -1.5,
            code: None,
            ..
        }
    ));
    let line = parse("X#[#1+1] Z-#3");
    let Statement::Nc(nc) = line.statement else {
        panic!()
    };
    assert_eq!(nc.words.len(), 2);
}

#[test]
fn format_errors() {
    for bad in [
        "#1=",
        "#1",
        "#=1",
        "#1=5+",
        "#1=[1+2",
        "#1=1+2]",
        "#1=SIN 30",
        "#1=FOO[1]",
        "#1=--1",
        "#1=POW[2]",
        "#1=1 GT 2",
        "#1=[1 LT 2]+1",
        "IF [#1] GOTO 5",
        "#1=ATAN[1,2,3]",
        "#1=5 #2=3",
        "X",
        "XY1",
        "G01 X1 Q",
        "#1=1(",
        "#1=1 $",
        "N1.5 G01",
        "N1 N2",
        "#1=1EQ1EQ1",
        "IF [[1 LT 2] + 1 GT 0] GOTO 1",
        "#1.5=1",
    ] {
        let e = err(bad);
        assert_eq!(e.kind, K::FormatError, "{bad}: {e:?}");
        assert_eq!(e.fanuc_number(), 114);
    }
}

#[test]
fn statement_format_errors() {
    for bad in [
        "IF [1 LT 2]",
        "IF [1 LT 2] #1=1",
        "IF 1 GOTO 2",
        "WHILE [1 LT 2]",
        "WHILE [1 LT 2] GOTO 1",
        "IF [1 LT 2] THEN G01",
    ] {
        let e = err(bad);
        assert_eq!(e.kind, K::StatementFormat, "{bad}: {e:?}");
        assert_eq!(e.fanuc_number(), 125);
    }
}

#[test]
fn loop_number_alarms() {
    for bad in [
        "DO 4",
        "DO 0",
        "END 5",
        "DO",
        "END",
        "WHILE [1 LT 2] DO 9",
        "DO #1",
        "END 300",
    ] {
        let e = err(bad);
        assert_eq!(e.kind, K::IllegalLoopNumber, "{bad}: {e:?}");
        assert_eq!(e.fanuc_number(), 126);
    }
    assert_eq!(err("DO 4").span, Span::new(1, 5));
    assert_eq!(err("WHILE [1 LT 2] DO 9").span, Span::new(16, 20));
}

#[test]
fn nc_and_macro_in_one_block() {
    let e = err("G01 X10 #1=5");
    assert_eq!(e.kind, K::NcAndMacro);
    assert_eq!(e.fanuc_number(), 127);
    assert_eq!(e.span, Span::new(9, 13));
    let e = err("#1=5 G01");
    assert_eq!(e.kind, K::NcAndMacro);
    assert_eq!(e.span, Span::new(6, 9));
    assert_eq!(err("G01 GOTO 5").kind, K::NcAndMacro);
    assert_eq!(err("X1 IF [1 LT 2] GOTO 5").kind, K::NcAndMacro);
    assert_eq!(err("GOTO 5 X1").kind, K::NcAndMacro);
}

#[test]
fn bracket_nesting() {
    assert!(parse_statement(b"#1=[[[[[1]]]]]", 1).is_ok());
    let e = err("#1=[[[[[[1]]]]]]");
    assert_eq!(e.kind, K::BracketNesting);
    assert_eq!(e.fanuc_number(), 118);
    assert_eq!(e.span, Span::new(9, 10));
    // The manual's example: SIN[[[#2+#3]*#4+#5]*#6] is three levels.
    assert!(parse_statement(b"#1=SIN[[[#2+#3]*#4+#5]*#6]", 1).is_ok());
    assert_eq!(
        err("#1=SIN[COS[TAN[ABS[SQRT[[1]]]]]]").kind,
        K::BracketNesting
    );
    assert_eq!(err("IF [[[[[[1 LT 2]]]]]] GOTO 1").kind, K::BracketNesting);
    // Ten thousand deep: an alarm, not a stack overflow.
    let deep = format!("#1={}1{}", "[".repeat(10_000), "]".repeat(10_000));
    assert_eq!(err(&deep).kind, K::BracketNesting);
    let deep = format!("#1={}", "-".repeat(10_000));
    assert_eq!(err(&deep).kind, K::FormatError);
    let deep = format!("#1={}1", "#".repeat(10_000));
    assert_eq!(err(&deep).kind, K::FormatError);
    // A long chain without brackets: bounded too.
    let long = format!("#1={}1", "1+".repeat(100_000));
    assert_eq!(err(&long).kind, K::FormatError);
    let ok = format!("#1={}1", "1+".repeat(fiveaxis_macro::MAX_OPERATIONS));
    assert!(parse_statement(ok.as_bytes(), 1).is_ok());
}

#[test]
fn keywords_run_into_names_once_blanks_are_gone() {
    assert!(matches!(
        parse("WHILE [#30 LE ABS[#11]] DO 1").statement,
        Statement::While { id: 1, .. }
    ));
    assert!(matches!(
        parse("IF [#1 NE SQRT[4]] GOTO ROUND[#2]").statement,
        Statement::IfGoto { .. }
    ));
    assert!(matches!(
        parse("#1 = #2 AND FIX[3] MOD ROUND[2]").statement,
        Statement::Assign { .. }
    ));
    assert!(matches!(
        parse("GOTO ROUND[#1]").statement,
        Statement::Goto(Expr::Call(_))
    ));
}

#[test]
fn other_parse_alarms() {
    let e = err("#1=12345678901234567");
    assert_eq!(e.kind, K::TooManyDigits);
    assert_eq!(e.fanuc_number(), 3);
    assert_eq!(e.span, Span::new(4, 21));
    let e = err("#123456789=1");
    assert_eq!(e.kind, K::UndefinedVariable);
    assert_eq!(e.span, Span::new(1, 11));
    let e = err("#1=1 (NOT CLOSED");
    assert_eq!(e.span, Span::new(6, 17));
    let e = err("#1=5+\u{e9}");
    assert_eq!(e.kind, K::FormatError);
    assert_eq!(e.span, Span::new(6, 7));
}

#[test]
fn error_messages_name_the_thing() {
    assert_eq!(err("#1=FOO[1]").message, "`FOO` is not a function");
    assert_eq!(
        err("DO 4").message,
        "`DO4`: the loop number must be 1, 2 or 3"
    );
    assert!(err("#1=[1 LT 2]").message.contains("comparison"));
}

#[test]
fn fast_scans() {
    assert!(is_macro_line(b"#1=5"));
    assert!(is_macro_line(b"G01 X[1+2]"));
    assert!(is_macro_line(b"N10 GOTO 5"));
    assert!(is_macro_line(b"if [#1 gt 2] goto 5"));
    assert!(is_macro_line(b"WHILE[1LT2]DO1"));
    assert!(is_macro_line(b"DO 1"));
    assert!(is_macro_line(b"END1"));
    assert!(is_macro_line(b"G O T O 5"));
    assert!(!is_macro_line(b"G01 X10 Y20 (#1 in a comment)"));
    assert!(!is_macro_line(b"G01 X10 D01 E5 ; #1"));
    assert!(!is_macro_line(b"M30"));
    assert!(!is_macro_line(b"TRAORI"));
    assert!(!is_macro_line(b"(unclosed #"));
    assert!(!is_macro_line(b"\xff\xfe G1"));
    assert_eq!(loop_start(b"WHILE [#1 LE 10] DO 1"), Some(1));
    assert_eq!(loop_start(b"N5 DO2"), Some(2));
    assert_eq!(loop_start(b"END 1"), None);
    assert_eq!(loop_start(b"(DO 1) G01"), None);
    assert_eq!(loop_end(b"END 3"), Some(3));
    assert_eq!(loop_end(b"n9 end2 (x)"), Some(2));
    assert_eq!(loop_end(b"END"), None);
    assert_eq!(loop_end(b"END 999"), None);
    assert_eq!(loop_start(b"DO 7"), Some(7));
}
