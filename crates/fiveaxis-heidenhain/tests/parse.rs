//! The block reader on its own: `parse_block` is pure and reports the
//! columns at fault.

use fiveaxis_heidenhain::{
    Block, Body, Compare, FnOp, Item, Kind, Label, LangErrorKind, Name, Node, Operand, QKind, QRef,
    Span, ToolRef, parse, parse_block, split_comment,
};

fn q(n: u32) -> QRef {
    QRef { kind: QKind::Q, n }
}

#[test]
fn block_number_skip_and_heading() {
    let b = parse("/105 M30").expect("parses");
    assert!(b.skip);
    assert_eq!(b.number, Some(105));
    let b = parse("105 /M30").expect("parses");
    assert!(b.skip);
    assert!(matches!(b.items[0], Item::M { n: 30, .. }));
    assert_eq!(
        parse("36 * - TOOL: T1").expect("parses").body,
        Body::Heading
    );
    assert_eq!(parse("   ").expect("parses").body, Body::Nothing);
    assert_eq!(
        parse("12 ; only a comment").expect("parses").body,
        Body::Nothing
    );
}

#[test]
fn split_comment_respects_quotes() {
    assert_eq!(
        split_comment(b"L X+1 ; go"),
        (&b"L X+1 "[..], Some(&b" go"[..]))
    );
    assert_eq!(split_comment(b"LBL \"A;B\""), (&b"LBL \"A;B\""[..], None));
}

#[test]
fn begin_end_and_labels() {
    assert_eq!(
        parse("0 BEGIN PGM W5270 INCH").expect("parses").body,
        Body::Begin {
            name: "W5270".into(),
            inch: true
        }
    );
    assert_eq!(parse("END PGM W5270 MM").expect("parses").body, Body::End);
    assert_eq!(
        parse("LBL \"CuttingEdges1\"").expect("parses").body,
        Body::Label(Label::Name("CuttingEdges1".into()))
    );
    assert_eq!(
        parse("CALL LBL 3 REP 5").expect("parses").body,
        Body::CallLabel {
            label: Label::Number(3),
            rep: Some(5)
        }
    );
    assert_eq!(
        parse("CALL PGM TNC:\\DIR\\SUB.H").expect("parses").body,
        Body::CallProgram("TNC:\\DIR\\SUB.H".into())
    );
}

#[test]
fn fn_functions_as_read() {
    assert_eq!(
        parse("FN 1: Q3 = +Q1 + -5").expect("parses").body,
        Body::Arith {
            op: FnOp::Add,
            target: q(3),
            a: Operand::Param {
                q: q(1),
                neg: false
            },
            b: Some(Operand::Num(-5.0)),
        }
    );
    assert_eq!(
        parse("FN 10: IF +Q1 NE -Q2 GOTO LBL 5")
            .expect("parses")
            .body,
        Body::If {
            cmp: Compare::NotEqual,
            a: Operand::Param {
                q: q(1),
                neg: false
            },
            b: Operand::Param { q: q(2), neg: true },
            label: Label::Number(5),
        }
    );
    assert_eq!(
        parse("FN 18: SYSREAD QL2 = ID210 NR1 IDX3")
            .expect("parses")
            .body,
        Body::SysRead {
            target: QRef {
                kind: QKind::Ql,
                n: 2
            },
            group: 210,
            number: 1,
            index: Some(3),
        }
    );
    assert_eq!(
        parse("FN 14: ERROR = 1000").expect("parses").body,
        Body::Error(Operand::Num(1000.0))
    );
}

#[test]
fn formula_nodes_are_children_first() {
    let b = parse("Q5 = SIN Q1 * 2 + Q2").expect("parses");
    let Body::Assign(target, root) = b.body else {
        panic!("{:?}", b.body)
    };
    assert_eq!(target, q(5));
    assert_eq!(root, b.nodes.len() - 1);
    for (i, n) in b.nodes.iter().enumerate() {
        if let Node::Bin(_, a, c) = n {
            assert!(*a < i && *c < i);
        }
    }
}

#[test]
fn words_keep_their_columns() {
    let mut b = Block::default();
    parse_block(b"L IX+5 FQ3 DR+", &mut b).expect("parses");
    assert!(matches!(
        b.body,
        Body::Control {
            kind: Kind::Line,
            ..
        }
    ));
    assert_eq!(
        b.items[0],
        Item::Word {
            address: Name::Static("X"),
            value: Operand::Num(5.0),
            incremental: true,
            span: Span::new(3, 7),
        }
    );
    assert_eq!(
        b.items[1],
        Item::Word {
            address: Name::Static("F"),
            value: Operand::Param {
                q: q(3),
                neg: false
            },
            incremental: false,
            span: Span::new(8, 11),
        }
    );
    assert_eq!(
        b.items[2],
        Item::Key {
            key: Name::Static("DR+"),
            span: Span::new(12, 15),
        }
    );
}

#[test]
fn tool_refs() {
    let b = parse("TOOL CALL QS3 Z").expect("parses");
    assert!(matches!(
        b.body,
        Body::Control {
            kind: Kind::ToolCall,
            tool: Some(ToolRef::Text(3)),
            ..
        }
    ));
}

#[test]
fn errors_name_the_columns() {
    let e = parse("L X+1 Y").map(|_| ()).err();
    assert_eq!(e, None, "a bare axis is a key");
    let e = parse("L X+1 #").expect_err("bad");
    assert_eq!(e.kind, LangErrorKind::Syntax);
    assert_eq!(e.span, Span::new(7, 8));
    let e = parse("Q5 = 1 +").expect_err("bad");
    assert_eq!(e.span.start, 9);
    let e = parse("QL500 = 1").expect_err("bad");
    assert_eq!(e.kind, LangErrorKind::Parameter);
    assert_eq!(e.span, Span::new(1, 6));
    let e = parse("FN 9: IF +Q1 EQU +1 GOTO 5").expect_err("bad");
    assert!(e.message.contains("LBL"));
    let e = parse("CALL LBL").expect_err("bad");
    assert_eq!(e.kind, LangErrorKind::Syntax);
    let e = parse("Q1 = ((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((1")
        .expect_err("deep");
    assert!(e.message.contains("deep"));
}
