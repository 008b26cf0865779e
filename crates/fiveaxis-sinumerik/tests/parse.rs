//! One test per construct, with the exact tree.

use fiveaxis_sinumerik::{
    Assign, BinOp, BlockNumber, Call, CallKind, Comment, Declarator, Def, Expr, ExprKind,
    IndirectCall, Init, Item, Jump, JumpKind, JumpTarget, Line, Name, Param, ParseError,
    ParseErrorKind, PositionMode, Proc, Skip, Span, Statement, SyncAction, SyncWhen, Type, UnOp,
    Var, Word, parse_line,
};

fn read(text: &str) -> Line {
    parse_line(text.as_bytes(), 7).unwrap_or_else(|e| panic!("`{text}`: {e}"))
}

fn fail(text: &str) -> ParseError {
    match parse_line(text.as_bytes(), 7) {
        Ok(line) => panic!("`{text}` read as {line:?}"),
        Err(e) => e,
    }
}

fn items(text: &str) -> Vec<Item> {
    match read(text).statement {
        Statement::Block(items) => items,
        other => panic!("`{text}`: {other:?}"),
    }
}

fn one(text: &str) -> Item {
    let mut list = items(text);
    assert_eq!(list.len(), 1, "`{text}`: {list:?}");
    list.remove(0)
}

fn statement(text: &str) -> Statement {
    read(text).statement
}

fn sp(start: u32, end: u32) -> Span {
    Span::new(start, end)
}

fn num(x: f64, start: u32, end: u32) -> Expr {
    Expr {
        kind: ExprKind::Number(x),
        span: sp(start, end),
    }
}

fn var(name: &str, start: u32, end: u32) -> Var {
    Var {
        name: name.into(),
        indices: Vec::new(),
        span: sp(start, end),
    }
}

fn var_expr(name: &str, start: u32, end: u32) -> Expr {
    Expr {
        kind: ExprKind::Var(var(name, start, end)),
        span: sp(start, end),
    }
}

fn bin(op: BinOp, left: Expr, right: Expr) -> Expr {
    let span = sp(left.span.start, right.span.end);
    Expr {
        kind: ExprKind::Binary(op, Box::new(left), Box::new(right)),
        span,
    }
}

fn name(text: &str, start: u32, end: u32) -> Name {
    Name {
        text: text.into(),
        span: sp(start, end),
    }
}

/// A literal word `A n` (no `=`), address at `start`.
fn lit(address: &str, value: f64, start: u32, end: u32) -> Item {
    let after = start + u32::try_from(address.len()).expect("short");
    Item::Word(Word {
        address: address.into(),
        value: num(value, after, end),
        mode: None,
        equals: false,
        span: sp(start, end),
    })
}

/// The words of a block as (address, number) pairs.
fn words(text: &str) -> Vec<(String, Option<f64>)> {
    items(text)
        .into_iter()
        .map(|item| match item {
            Item::Word(w) => (w.address.clone(), w.number()),
            other => panic!("`{text}`: {other:?}"),
        })
        .collect()
}

fn pairs(list: &[(&str, f64)]) -> Vec<(String, Option<f64>)> {
    list.iter().map(|(a, x)| ((*a).into(), Some(*x))).collect()
}

/// The value of `R1=…`.
fn value(text: &str) -> Expr {
    match items(text).as_slice() {
        [Item::Assign(a)] => a.value.clone(),
        other => panic!("`{text}`: {other:?}"),
    }
}

/// The shape of an expression, spans left out: `(1 + (2 * 3))`.
fn shape(e: &Expr) -> String {
    match &e.kind {
        ExprKind::Number(x) => format!("{x}"),
        ExprKind::String(s) => format!("{s:?}"),
        ExprKind::Bool(b) => format!("{b}"),
        ExprKind::Var(v) if v.indices.is_empty() => v.name.clone(),
        ExprKind::Var(v) => format!(
            "{}[{}]",
            v.name,
            v.indices.iter().map(shape).collect::<Vec<_>>().join(",")
        ),
        ExprKind::Unary(op, x) => format!("({op:?} {})", shape(x)),
        ExprKind::Binary(op, l, r) => format!("({} {} {})", shape(l), op.as_str(), shape(r)),
        ExprKind::Call(name, args) => format!(
            "{name}({})",
            args.iter()
                .map(|a| a.as_ref().map_or(String::new(), shape))
                .collect::<Vec<_>>()
                .join(",")
        ),
    }
}

fn r1(expression: &str) -> String {
    shape(&value(&format!("R1={expression}")))
}

// ---- block structure ----

#[test]
fn block_prefix_skip_number_label_comment() {
    let line = read("/3 N20 START: G0 ; go");
    assert_eq!(
        line,
        Line {
            line: 7,
            skip: Some(Skip {
                level: 3,
                span: sp(1, 3)
            }),
            number: Some(BlockNumber {
                value: 20,
                main: false,
                span: sp(4, 7)
            }),
            label: Some(name("START", 8, 13)),
            statement: Statement::Block(vec![lit("G", 0.0, 15, 17)]),
            comment: Some(Comment {
                text: " go".into(),
                span: sp(18, 22)
            }),
        }
    );
    let line = read("/N10 X1");
    assert_eq!(line.skip.map(|s| s.level), Some(0));
    assert_eq!(line.number.map(|n| n.value), Some(10));
    let line = read(":100 G1");
    assert_eq!(
        line.number,
        Some(BlockNumber {
            value: 100,
            main: true,
            span: sp(1, 5)
        })
    );
    let line = read("N26 PROG_4444411:");
    assert_eq!(line.label, Some(name("PROG_4444411", 5, 17)));
    assert_eq!(line.statement, Statement::Empty);
    // Run together.
    assert_eq!(read("N10G0").number.map(|n| n.value), Some(10));
}

#[test]
fn blank_and_comment_lines_are_empty() {
    for text in ["", "   ", "\r", "; only a comment", "N10", "N10 ;"] {
        assert_eq!(statement(text), Statement::Empty, "`{text}`");
    }
    let line = read(";-- ; twice");
    assert_eq!(line.comment.map(|c| c.text), Some("-- ; twice".into()));
    // A `;` inside a string is no comment.
    let line = read("MSG(\"A;B\")");
    assert!(line.comment.is_none());
}

#[test]
fn line_ends_and_case() {
    assert_eq!(read("g1 x10\r\n").statement, read("G1 X10").statement);
    assert_eq!(
        items("msg()"),
        vec![call("MSG", CallKind::Procedure, Some(vec![]), sp(1, 6))]
    );
    let Item::Assign(a) = one("r01=1") else {
        panic!()
    };
    assert_eq!(a.target.name, "R01");
}

#[test]
fn headers() {
    assert_eq!(
        statement("%_N_SHAFT123_MPF"),
        Statement::ProgramHeader("_N_SHAFT123_MPF".into())
    );
    assert_eq!(
        statement(";$PATH=/_N_MPF_DIR"),
        Statement::PathHeader("/_N_MPF_DIR".into())
    );
}

// ---- words ----

#[test]
fn literal_words() {
    assert_eq!(items("X10"), vec![lit("X", 10.0, 1, 4)]);
    assert_eq!(items("X-10.5"), vec![lit("X", -10.5, 1, 7)]);
    assert_eq!(items("Z-1."), vec![lit("Z", -1.0, 1, 5)]);
    assert_eq!(items("Y.5"), vec![lit("Y", 0.5, 1, 4)]);
    assert_eq!(
        words("G0 G642 G710 M30 D1 H2 S1000 F3820. T1"),
        pairs(&[
            ("G", 0.0),
            ("G", 642.0),
            ("G", 710.0),
            ("M", 30.0),
            ("D", 1.0),
            ("H", 2.0),
            ("S", 1000.0),
            ("F", 3820.0),
            ("T", 1.0)
        ])
    );
    // Run together, and case does not matter.
    assert_eq!(
        words("G53G0X0M5"),
        pairs(&[("G", 53.0), ("G", 0.0), ("X", 0.0), ("M", 5.0)])
    );
    assert_eq!(
        items("g1x9.285y-3"),
        vec![
            lit("G", 1.0, 1, 3),
            lit("X", 9.285, 3, 9),
            lit("Y", -3.0, 9, 12)
        ]
    );
}

#[test]
fn words_with_equals() {
    assert_eq!(
        items("X=10"),
        vec![Item::Word(Word {
            address: "X".into(),
            value: num(10.0, 3, 5),
            mode: None,
            equals: true,
            span: sp(1, 5),
        })]
    );
    let Item::Word(w) = one("X=R1*2+5") else {
        panic!()
    };
    assert_eq!(
        w.value,
        bin(
            BinOp::Add,
            bin(BinOp::Mul, var_expr("R1", 3, 5), num(2.0, 6, 7)),
            num(5.0, 8, 9)
        )
    );
    assert_eq!(w.span, sp(1, 9));
    let Item::Word(w) = one("Z=1589+100") else {
        panic!()
    };
    assert_eq!(shape(&w.value), "(1589 + 100)");
    assert_eq!(
        words("CR=-5 AR=90 A3=0 B3=1 C3=0.5 A2=1 TURN=2 I1=5 LEAD=1 TILT=2 F=100 S1=1000 RPL=30"),
        pairs(&[
            ("CR", -5.0),
            ("AR", 90.0),
            ("A3", 0.0),
            ("B3", 1.0),
            ("C3", 0.5),
            ("A2", 1.0),
            ("TURN", 2.0),
            ("I1", 5.0),
            ("LEAD", 1.0),
            ("TILT", 2.0),
            ("F", 100.0),
            ("S1", 1000.0),
            ("RPL", 30.0)
        ])
    );
    let Item::Word(t) = one("T=\"PLAN_D50\"") else {
        panic!()
    };
    assert_eq!(t.address, "T");
    assert_eq!(t.value.kind, ExprKind::String("PLAN_D50".into()));
    // The exponent of 840Di p62.
    let Item::Word(x) = one("X=-.1EX-3") else {
        panic!()
    };
    assert_eq!(x.number(), Some(-0.0001));
    assert_eq!(words("Y='HFF'"), pairs(&[("Y", 255.0)]));
}

#[test]
fn position_modes() {
    let cases = [
        ("X=AC(10)", PositionMode::Ac, 10.0),
        ("X=IC(-5)", PositionMode::Ic, -5.0),
        ("C=DC(90)", PositionMode::Dc, 90.0),
        ("A=ACP(45)", PositionMode::Acp, 45.0),
        ("B=ACN(45)", PositionMode::Acn, 45.0),
    ];
    for (text, mode, x) in cases {
        let Item::Word(w) = one(text) else { panic!() };
        assert_eq!((w.mode, w.number()), (Some(mode), Some(x)), "{text}");
    }
    let Item::Word(w) = one("I=AC(37)") else {
        panic!()
    };
    assert_eq!(w.value, num(37.0, 6, 8));
    assert_eq!(w.span, sp(1, 9));
}

#[test]
fn an_address_needs_a_value() {
    let e = fail("G1 X Y10");
    assert_eq!(e.kind, ParseErrorKind::Syntax);
    assert_eq!(e.alarm(), Some(12080));
    assert_eq!(e.span, sp(4, 5));
    assert_eq!(e.line, 7);
    let e = fail("X=");
    assert_eq!(e.span, sp(2, 3));
    assert!(e.message.contains("expected a value"), "{}", e.message);
}

// ---- variables ----

#[test]
fn assignments_to_variables() {
    assert_eq!(
        items("R1=5"),
        vec![Item::Assign(Assign {
            target: var("R1", 1, 3),
            value: num(5.0, 4, 5),
            span: sp(1, 5),
        })]
    );
    assert_eq!(
        items("R[R2]=1"),
        vec![Item::Assign(Assign {
            target: Var {
                name: "R".into(),
                indices: vec![var_expr("R2", 3, 5)],
                span: sp(1, 6),
            },
            value: num(1.0, 7, 8),
            span: sp(1, 8),
        })]
    );
    let Item::Assign(a) = one("$TC_DP3[1,1]=10") else {
        panic!()
    };
    assert_eq!(a.target.name, "$TC_DP3");
    assert_eq!(a.target.indices, vec![num(1.0, 9, 10), num(1.0, 11, 12)]);
    assert_eq!(r1("$AA_IW[X]+$P_TOOLNO"), "($AA_IW[X] + $P_TOOLNO)");
    assert_eq!(r1("$TC_CARR1[1]"), "$TC_CARR1[1]");
    // Two assignments and words in one block.
    let list = items("_X_HOME=-365. _Y_HOME=224. X=_X_HOME");
    assert_eq!(list.len(), 3);
    let Item::Assign(a) = &list[0] else { panic!() };
    assert_eq!(
        (a.target.name.as_str(), shape(&a.value)),
        ("_X_HOME", "-365".into())
    );
    let Item::Word(w) = &list[2] else { panic!() };
    assert_eq!(shape(&w.value), "_X_HOME");
}

// ---- expressions ----

#[test]
fn precedence_of_one_p444() {
    assert_eq!(r1("1+2*3"), "(1 + (2 * 3))");
    assert_eq!(r1("(1+2)*3"), "((1 + 2) * 3)");
    assert_eq!(r1("8/4/2"), "((8 / 4) / 2)");
    assert_eq!(r1("7 DIV 2 MOD 3"), "((7 DIV 2) MOD 3)");
    assert_eq!(r1("1+2 B_AND 3"), "((1 + 2) B_AND 3)");
    assert_eq!(
        r1("1 B_OR 2 B_XOR 3 B_AND 4"),
        "(1 B_OR (2 B_XOR (3 B_AND 4)))"
    );
    assert_eq!(r1("A OR B XOR C AND D"), "(A OR (B XOR (C AND D)))");
    assert_eq!(r1("1 B_OR 2 AND 3"), "((1 B_OR 2) AND 3)");
    assert_eq!(r1("\"A\"<<R2 OR R3"), "(\"A\" << (R2 OR R3))");
    // The comparisons bind weakest: write brackets around them.
    assert_eq!(r1("R2==1 AND R3"), "(R2 == (1 AND R3))");
    assert_eq!(r1("(R2==1) AND (R3<>2)"), "((R2 == 1) AND (R3 <> 2))");
    assert_eq!(r1("R2<=R3+1"), "(R2 <= (R3 + 1))");
    assert_eq!(r1("R2>=1"), "(R2 >= 1)");
    assert_eq!(r1("R2<1"), "(R2 < 1)");
    assert_eq!(r1("R2>1"), "(R2 > 1)");
    // Unary operators bind tightest.
    assert_eq!(r1("NOT R2 AND R3"), "((Not R2) AND R3)");
    assert_eq!(r1("B_NOT R2"), "(BitNot R2)");
    assert_eq!(r1("-R2*3"), "((Neg R2) * 3)");
    assert_eq!(r1("-2*3"), "(-2 * 3)");
    assert_eq!(r1("2--3"), "(2 - -3)");
    assert_eq!(r1("TRUE"), "true");
    // Frames chained (a frame variable's value).
    assert_eq!(
        shape(&value("$P_UIFR[1]=CTRANS(X,10,Y,20):CROT(Z,45)")),
        "(CTRANS(X,10,Y,20) : CROT(Z,45))"
    );
}

#[test]
fn functions() {
    assert_eq!(
        r1("SIN(30)+COS(R2)*TAN(1)"),
        "(SIN(30) + (COS(R2) * TAN(1)))"
    );
    assert_eq!(r1("ATAN2(1,2)"), "ATAN2(1,2)");
    assert_eq!(
        r1("SQRT(POT(3)+ABS(-4))-TRUNC(1.5)+ROUND(2.5)"),
        "((SQRT((POT(3) + ABS(-4))) - TRUNC(1.5)) + ROUND(2.5))"
    );
    assert_eq!(r1("LN(EXP(1))"), "LN(EXP(1))");
    assert_eq!(
        r1("MINVAL(R2,R3)+MAXVAL(1,2)"),
        "(MINVAL(R2,R3) + MAXVAL(1,2))"
    );
    assert_eq!(
        r1("STRLEN(\"AB\"<<TOUPPER(\"c\"))"),
        "STRLEN((\"AB\" << TOUPPER(\"c\")))"
    );
    assert_eq!(r1("ASIN(1)+ACOS(0)"), "(ASIN(1) + ACOS(0))");
    let e = value("R1=SIN(30)");
    assert_eq!(e.span, sp(4, 11));
}

// ---- statements ----

#[test]
fn definitions() {
    assert_eq!(
        statement("DEF REAL _X_HOME, _Y=2"),
        Statement::Def(Def {
            scope: None,
            ty: Type::Real,
            vars: vec![
                Declarator {
                    name: name("_X_HOME", 10, 17),
                    dims: vec![],
                    init: None,
                },
                Declarator {
                    name: name("_Y", 19, 21),
                    dims: vec![],
                    init: Some(Init::Value(num(2.0, 22, 23))),
                },
            ],
        })
    );
    let Statement::Def(d) = statement("DEF INT A[3,4]=SET(1,2,3)") else {
        panic!()
    };
    assert_eq!(d.ty, Type::Int);
    assert_eq!(d.vars[0].dims, vec![num(3.0, 11, 12), num(4.0, 13, 14)]);
    assert_eq!(
        d.vars[0].init,
        Some(Init::Set(vec![
            num(1.0, 20, 21),
            num(2.0, 22, 23),
            num(3.0, 24, 25)
        ]))
    );
    let Statement::Def(d) = statement("DEF REAL B[5]=REP(0.1)") else {
        panic!()
    };
    assert_eq!(d.vars[0].init, Some(Init::Rep(num(0.1, 19, 22))));
    let Statement::Def(d) = statement("DEF STRING[20] S=\"ABC\"") else {
        panic!()
    };
    assert_eq!(d.ty, Type::String(20));
    let Statement::Def(d) = statement("DEF NCK BOOL FLAG=TRUE") else {
        panic!()
    };
    assert_eq!(d.scope, Some(name("NCK", 5, 8)));
    assert_eq!(d.ty, Type::Bool);
    let Statement::Def(d) = statement("def axis AX1=(X)") else {
        panic!()
    };
    assert_eq!(d.ty, Type::Axis);
    assert_eq!(d.vars[0].name.text, "AX1");
    let Some(Init::Value(axis)) = &d.vars[0].init else {
        panic!()
    };
    assert_eq!(shape(axis), "X");
    for (text, ty) in [("DEF FRAME F1", Type::Frame), ("DEF CHAR C", Type::Char)] {
        let Statement::Def(d) = statement(text) else {
            panic!()
        };
        assert_eq!(d.ty, ty);
    }
    let e = fail("DEF LONG X");
    assert_eq!(e.span, sp(5, 9));
    assert!(e.message.contains("a type"), "{}", e.message);
}

#[test]
fn define_macro() {
    assert_eq!(
        statement("DEFINE LINE AS G1 F100 ; macro"),
        Statement::Define {
            name: name("LINE", 8, 12),
            text: "G1 F100".into(),
        }
    );
}

#[test]
fn structured_control() {
    let Statement::If(c) = statement("IF (R1>1) AND (R2<2)") else {
        panic!()
    };
    assert_eq!(shape(&c), "((R1 > 1) AND (R2 < 2))");
    assert_eq!(statement("ELSE"), Statement::Else);
    assert_eq!(statement("ENDIF"), Statement::EndIf);
    let Statement::While(c) = statement("WHILE R1<5") else {
        panic!()
    };
    assert_eq!(shape(&c), "(R1 < 5)");
    assert_eq!(statement("ENDWHILE"), Statement::EndWhile);
    assert_eq!(
        statement("FOR R1=1 TO 10"),
        Statement::For {
            variable: var("R1", 5, 7),
            from: num(1.0, 8, 9),
            to: num(10.0, 13, 15),
        }
    );
    assert_eq!(statement("ENDFOR"), Statement::EndFor);
    assert_eq!(statement("REPEAT"), Statement::Repeat);
    let Statement::Until(c) = statement("UNTIL R1>=3") else {
        panic!()
    };
    assert_eq!(shape(&c), "(R1 >= 3)");
    assert_eq!(statement("LOOP"), Statement::Loop);
    assert_eq!(statement("N90 ENDLOOP"), Statement::EndLoop);
    let e = fail("ENDIF X1");
    assert_eq!(e.span, sp(7, 8));
    let e = fail("G1 IF R1>1");
    assert!(e.message.contains("must begin its block"), "{}", e.message);
}

#[test]
fn conditional_jump() {
    assert_eq!(
        statement("IF R1>5 GOTOF END1"),
        Statement::IfJump {
            condition: bin(BinOp::Gt, var_expr("R1", 4, 6), num(5.0, 7, 8)),
            jump: Jump {
                kind: JumpKind::Gotof,
                target: Some(JumpTarget::Label(name("END1", 15, 19))),
                span: sp(9, 19),
            },
        }
    );
}

#[test]
fn case_of() {
    let Statement::Case {
        selector,
        arms,
        default,
    } = statement("CASE (R1) OF 1 GOTOF L1 2 GOTOB N20 DEFAULT GOTOF L3")
    else {
        panic!()
    };
    assert_eq!(shape(&selector), "R1");
    assert_eq!(arms.len(), 2);
    assert_eq!(arms[0].0, num(1.0, 14, 15));
    assert_eq!(
        arms[0].1.target,
        Some(JumpTarget::Label(name("L1", 22, 24)))
    );
    assert_eq!(arms[1].1.kind, JumpKind::Gotob);
    assert_eq!(arms[1].1.target, Some(JumpTarget::Block(20, sp(33, 36))));
    assert_eq!(
        default.and_then(|j| j.target),
        Some(JumpTarget::Label(name("L3", 51, 53)))
    );
}

#[test]
fn jumps() {
    assert_eq!(
        items("GOTOB ASTART"),
        vec![Item::Jump(Jump {
            kind: JumpKind::Gotob,
            target: Some(JumpTarget::Label(name("ASTART", 7, 13))),
            span: sp(1, 13),
        })]
    );
    let cases = [
        (
            "GOTO 100",
            JumpKind::Goto,
            Some(JumpTarget::Block(100, sp(6, 9))),
        ),
        (
            "GOTOC N100",
            JumpKind::Gotoc,
            Some(JumpTarget::Block(100, sp(7, 11))),
        ),
        ("GOTOS", JumpKind::Gotos, None),
    ];
    for (text, kind, target) in cases {
        let Item::Jump(j) = one(text) else { panic!() };
        assert_eq!((j.kind, j.target), (kind, target), "{text}");
    }
    // After words.
    let list = items("G0 X10 GOTOF L1");
    assert!(matches!(list[2], Item::Jump(_)));
}

// ---- calls ----

fn call(name: &str, kind: CallKind, args: Option<Vec<Option<Expr>>>, span: Span) -> Item {
    Item::Call(Call {
        name: name.into(),
        kind,
        args,
        passes: None,
        span,
    })
}

#[test]
fn calls_by_name() {
    assert_eq!(
        items("MYSUB(1,2)"),
        vec![call(
            "MYSUB",
            CallKind::User,
            Some(vec![Some(num(1.0, 7, 8)), Some(num(2.0, 9, 10))]),
            sp(1, 11)
        )]
    );
    assert_eq!(
        items("RLIMIT"),
        vec![call("RLIMIT", CallKind::User, None, sp(1, 7))]
    );
    assert_eq!(
        items("CYCLE81(10,,2,)"),
        vec![call(
            "CYCLE81",
            CallKind::Cycle,
            Some(vec![
                Some(num(10.0, 9, 11)),
                None,
                Some(num(2.0, 13, 14)),
                None
            ]),
            sp(1, 16)
        )]
    );
    assert_eq!(
        items("CYCLE800()"),
        vec![call("CYCLE800", CallKind::Cycle, Some(vec![]), sp(1, 11))]
    );
    let Item::Call(c) = one("L100 P3") else {
        panic!()
    };
    assert_eq!((c.name.as_str(), c.kind), ("L100", CallKind::User));
    assert_eq!(c.passes, Some(num(3.0, 7, 8)));
    let Item::Call(c) = one("MYSUB P2") else {
        panic!()
    };
    assert_eq!(c.passes.map(|p| p.kind), Some(ExprKind::Number(2.0)));
    // An M function replaced by a subprogram, as an NX post writes it.
    let Item::Call(c) = one("M202(0.0059)") else {
        panic!()
    };
    assert_eq!(c.name, "M202");
    let Item::Call(c) = one("EXTCALL(\"4444411\")") else {
        panic!()
    };
    assert_eq!(c.kind, CallKind::Procedure);
    assert_eq!(
        c.args,
        Some(vec![Some(Expr {
            kind: ExprKind::String("4444411".into()),
            span: sp(9, 18)
        })])
    );
}

#[test]
fn indirect_and_modal_calls() {
    assert_eq!(
        items("CALL \"PART2\""),
        vec![Item::IndirectCall(IndirectCall {
            program: Some(Expr {
                kind: ExprKind::String("PART2".into()),
                span: sp(6, 13)
            }),
            section: None,
            span: sp(1, 13),
        })]
    );
    assert_eq!(
        items("CALL BLOCK START TO N50"),
        vec![Item::IndirectCall(IndirectCall {
            program: None,
            section: Some((
                JumpTarget::Label(name("START", 12, 17)),
                Some(JumpTarget::Block(50, sp(21, 24)))
            )),
            span: sp(1, 24),
        })]
    );
    let Item::IndirectCall(c) = one("CALL PROGNAME BLOCK L1") else {
        panic!()
    };
    assert_eq!(c.program.as_ref().map(shape), Some("PROGNAME".into()));
    assert_eq!(c.section.map(|s| s.1), Some(None));
    let Item::ModalCall {
        call: Some(c),
        span,
    } = one("MCALL CYCLE81(10,0,2,-5)")
    else {
        panic!()
    };
    assert_eq!((c.name.as_str(), span), ("CYCLE81", sp(1, 25)));
    assert_eq!(
        items("MCALL"),
        vec![Item::ModalCall {
            call: None,
            span: sp(1, 6)
        }]
    );
    let Item::ModalCall { call: Some(c), .. } = one("MCALL L10") else {
        panic!()
    };
    assert_eq!(c.name, "L10");
}

#[test]
fn subprogram_definition_and_return() {
    assert_eq!(
        statement("PROC CONTOUR(REAL A, VAR REAL B[3], STRING[8] S) SAVE DISPLOF"),
        Statement::Proc(Proc {
            name: name("CONTOUR", 6, 13),
            params: vec![
                Param {
                    by_reference: false,
                    ty: Type::Real,
                    name: name("A", 19, 20),
                    dims: vec![],
                },
                Param {
                    by_reference: true,
                    ty: Type::Real,
                    name: name("B", 31, 32),
                    dims: vec![Some(num(3.0, 33, 34))],
                },
                Param {
                    by_reference: false,
                    ty: Type::String(8),
                    name: name("S", 47, 48),
                    dims: vec![],
                },
            ],
            attributes: vec![name("SAVE", 50, 54), name("DISPLOF", 55, 62)],
        })
    );
    let Statement::Proc(p) = statement("PROC PART2") else {
        panic!()
    };
    assert!(p.params.is_empty() && p.attributes.is_empty());
    assert_eq!(
        items("RET"),
        vec![call("RET", CallKind::Procedure, None, sp(1, 4))]
    );
    assert_eq!(words("M17"), pairs(&[("M", 17.0)]));
}

#[test]
fn named_instructions() {
    let list = items("MSG(\"ROUGH\") STOPRE");
    assert_eq!(list.len(), 2);
    let Item::Call(msg) = &list[0] else { panic!() };
    assert_eq!((msg.name.as_str(), msg.kind), ("MSG", CallKind::Procedure));
    let Item::Call(c) = one("MSG (\" --- END --- \")") else {
        panic!()
    };
    assert_eq!(c.name, "MSG");
    let Item::Call(c) = one("SETAL(65000)") else {
        panic!()
    };
    assert_eq!(c.args, Some(vec![Some(num(65000.0, 7, 12))]));
    // Frames with their addresses.
    assert_eq!(
        items("TRANS X10 Y-5"),
        vec![
            call("TRANS", CallKind::Frame, None, sp(1, 6)),
            lit("X", 10.0, 7, 10),
            lit("Y", -5.0, 11, 14)
        ]
    );
    for (text, first, rest) in [
        ("ATRANS Z2", "ATRANS", 1),
        ("ROT Z45", "ROT", 1),
        ("AROT RPL=30", "AROT", 1),
        ("AROT Y-90.", "AROT", 1),
        ("SCALE X2 Y2", "SCALE", 2),
        ("MIRROR X0", "MIRROR", 1),
        ("TRANS", "TRANS", 0),
    ] {
        let list = items(text);
        let Item::Call(c) = &list[0] else { panic!() };
        assert_eq!(
            (c.name.as_str(), c.kind),
            (first, CallKind::Frame),
            "{text}"
        );
        assert_eq!(list.len() - 1, rest, "{text}");
    }
    for (text, kind) in [
        ("TRAORI", CallKind::Transformation),
        ("TRAFOOF", CallKind::Transformation),
        ("ORIWKS", CallKind::GFunction),
        ("ORIAXES", CallKind::GFunction),
        ("SOFT", CallKind::GFunction),
        ("FGROUP()", CallKind::Procedure),
    ] {
        let Item::Call(c) = one(text) else { panic!() };
        assert_eq!(c.kind, kind, "{text}");
    }
    assert_eq!(
        items("TRAORI(1)"),
        vec![call(
            "TRAORI",
            CallKind::Transformation,
            Some(vec![Some(num(1.0, 8, 9))]),
            sp(1, 10)
        )]
    );
    let Item::Call(c) = one("CYCLE800(1,\"TC1\",0,57,0,0,0,45,35.26,0,0,0,0,1,)") else {
        panic!()
    };
    assert_eq!(c.args.map(|a| a.len()), Some(15));
    let list = items("SUPA G0 Z=_Z_HOME D0");
    assert_eq!(list[0], call("SUPA", CallKind::Suppress, None, sp(1, 5)));
    assert_eq!(list.len(), 4);
    assert_eq!(
        words("G153 G0 Z0"),
        pairs(&[("G", 153.0), ("G", 0.0), ("Z", 0.0)])
    );
}

// ---- synchronized actions ----

#[test]
fn synchronized_actions() {
    let Statement::SyncAction(SyncAction {
        id,
        condition,
        actions,
    }) = statement("ID=1 WHENEVER $AA_IM[X]>10 DO $R1=1 M3")
    else {
        panic!()
    };
    assert_eq!(id, Some((false, num(1.0, 4, 5))));
    let (when, c) = condition.expect("condition");
    assert_eq!(
        (when, shape(&c)),
        (SyncWhen::Whenever, "($AA_IM[X] > 10)".into())
    );
    assert_eq!(actions.len(), 2);
    let Item::Assign(a) = &actions[0] else {
        panic!()
    };
    assert_eq!(a.target.name, "$R1");
    let Statement::SyncAction(s) = statement("WHEN $AA_IW[Z]<5 DO M5") else {
        panic!()
    };
    assert_eq!(s.condition.map(|c| c.0), Some(SyncWhen::When));
    let Statement::SyncAction(s) = statement("IDS=2 EVERY $A_IN[1]==1 DO $$SA_R1=0") else {
        panic!()
    };
    assert_eq!(s.id.map(|i| i.0), Some(true));
    let Statement::SyncAction(s) = statement("DO $R2=0") else {
        panic!()
    };
    assert!(s.id.is_none() && s.condition.is_none());
    let Statement::SyncAction(s) = statement("FROM $AC_TIME>1 DO $R3=1") else {
        panic!()
    };
    assert_eq!(s.condition.map(|c| c.0), Some(SyncWhen::From));
    assert!(fail("ID=1 WHEN R1>1").message.contains("`DO`"));
}

// ---- errors ----

#[test]
fn syntax_errors_have_columns() {
    let cases: [(&str, (u32, u32), &str); 10] = [
        ("G1 X10 )", (8, 9), "expected an address"),
        ("R1=(1+2", (7, 8), "`)`"),
        ("MSG(\"abc", (5, 9), "closing"),
        ("G1 #5", (4, 5), "`#`"),
        ("/12 G1", (2, 4), "skip level"),
        ("X=SIN(", (6, 7), "a value"),
        ("G1 X10.5.3", (9, 11), "expected an address"),
        ("R1=1 +", (6, 7), "a value"),
        ("IF R1>1 GOTOF", (9, 14), "label"),
        ("X=. ", (3, 4), "decimal point"),
    ];
    for (text, (start, end), part) in cases {
        let e = fail(text);
        assert_eq!(e.kind, ParseErrorKind::Syntax, "{text}");
        assert_eq!(e.alarm(), Some(12080), "{text}");
        assert_eq!(
            (e.span.start, e.span.end),
            (start, end),
            "{text}: {}",
            e.message
        );
        assert!(e.message.contains(part), "{text}: {}", e.message);
    }
}

#[test]
fn unary_operators_are_kept_on_names() {
    let e = value("R1=-R2");
    assert_eq!(
        e,
        Expr {
            kind: ExprKind::Unary(UnOp::Neg, Box::new(var_expr("R2", 5, 7))),
            span: sp(4, 7)
        }
    );
}
