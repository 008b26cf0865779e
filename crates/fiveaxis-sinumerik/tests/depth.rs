//! Every bound on the depth of the tree, at the bound, one past it and
//! far past it (30,000 nested brackets, signs, calls, indices, `NOT`s and
//! operations): the bound is read, one more is an error, 30,000 is the same
//! error and not a stack overflow. Everything runs on a thread with a
//! 256 KiB stack, and the deepest lines the bounds allow are read,
//! printed, cloned and dropped there.

mod common;

use common::on_small_stack;
use fiveaxis_sinumerik::{
    ExprKind, Item, Line, MAX_DEPTH, MAX_OPERATIONS, ParseErrorKind, Statement, parse_line,
};

/// How many of a repeated thing a hostile line holds.
const HOSTILE: usize = 30_000;

fn read(text: &str) -> Line {
    parse_line(text.as_bytes(), 1).unwrap_or_else(|e| panic!("{e}"))
}

fn kind_of(text: &str) -> ParseErrorKind {
    match parse_line(text.as_bytes(), 1) {
        Ok(_) => panic!("read a line of {} bytes", text.len()),
        Err(e) => {
            assert!(e.span.start >= 1 && e.span.end as usize <= text.len() + 1);
            e.kind
        }
    }
}

/// Each nesting `open … close` around `1`, `n` times, in `R1=…`.
fn nested(open: &str, close: &str, n: usize) -> String {
    format!("R1={}1{}", open.repeat(n), close.repeat(n))
}

#[test]
fn nesting_is_bounded_at_every_kind_of_level() {
    on_small_stack(|| {
        let depth = usize::from(MAX_DEPTH);
        for (open, close) in [
            ("(", ")"),
            ("-", ""),
            ("+", ""),
            ("NOT ", ""),
            ("B_NOT ", ""),
            ("SIN(", ")"),
            ("R[", "]"),
            ("ATAN2(1,", ")"),
        ] {
            let line = read(&nested(open, close, depth));
            assert!(matches!(line.statement, Statement::Block(_)));
            for n in [depth + 1, HOSTILE] {
                assert_eq!(
                    kind_of(&nested(open, close, n)),
                    ParseErrorKind::TooDeep,
                    "{open} × {n}"
                );
            }
        }
        // In a word's value, an index of a target, a condition.
        for n in [depth + 1, HOSTILE] {
            let e = format!("X={}1{}", "(".repeat(n), ")".repeat(n));
            assert_eq!(kind_of(&e), ParseErrorKind::TooDeep);
            let e = format!("$R[{}1{}]=1", "(".repeat(n), ")".repeat(n));
            assert_eq!(kind_of(&e), ParseErrorKind::TooDeep);
            let e = format!("IF {}1{} GOTOF L", "(".repeat(n), ")".repeat(n));
            assert_eq!(kind_of(&e), ParseErrorKind::TooDeep);
            let e = format!("CYCLE81({}1{})", "(".repeat(n), ")".repeat(n));
            assert_eq!(kind_of(&e), ParseErrorKind::TooDeep);
        }
        // Unclosed brackets far past the bound: the bound, not the end.
        assert_eq!(
            kind_of(&format!("R1={}", "(".repeat(HOSTILE))),
            ParseErrorKind::TooDeep
        );
        // Signs on a literal word: one is read, two are a syntax error.
        assert_eq!(
            kind_of(&format!("X{}1", "-".repeat(HOSTILE))),
            ParseErrorKind::Syntax
        );
    });
}

fn chain(op: &str, n: usize) -> String {
    let mut s = String::from("1");
    for _ in 0..n {
        s.push_str(op);
        s.push('1');
    }
    s
}

#[test]
fn operations_per_line_are_bounded() {
    on_small_stack(|| {
        for op in ["+", "*", "==", " AND ", "<<"] {
            let line = read(&format!("R1={}", chain(op, MAX_OPERATIONS)));
            drop(line);
            for n in [MAX_OPERATIONS + 1, HOSTILE] {
                assert_eq!(
                    kind_of(&format!("R1={}", chain(op, n))),
                    ParseErrorKind::TooManyOperations
                );
            }
        }
        // Counted over the whole line.
        let half = MAX_OPERATIONS / 2;
        let text = format!("X={} Y={}", chain("+", half), chain("-", half + 1));
        assert_eq!(kind_of(&text), ParseErrorKind::TooManyOperations);
    });
}

/// The deepest trees the bounds allow: each bracket level entered through
/// every precedence level (the most frames per level), then the rest of
/// the levels and operations.
#[test]
fn deepest_lines_read_print_clone_and_drop_on_a_small_stack() {
    on_small_stack(|| {
        let level = "1:1==1<<1 OR 1 XOR 1 AND 1 B_OR 1 B_XOR 1 B_AND 1+1*(";
        let per_level = 11;
        let levels = (MAX_OPERATIONS / per_level).min(usize::from(MAX_DEPTH));
        let rest = usize::from(MAX_DEPTH) - levels;
        let text = format!(
            "R1={}{}{}{}",
            level.repeat(levels),
            "-(".repeat(rest / 2),
            chain("+", MAX_OPERATIONS - levels * per_level),
            ")".repeat(levels + rest / 2)
        );
        let line = read(&text);
        let printed = format!("{line:?}");
        assert!(printed.len() > text.len());
        let copy = line.clone();
        assert_eq!(copy, line);
        drop(copy);
        let Statement::Block(items) = &line.statement else {
            panic!()
        };
        let Item::Assign(a) = &items[0] else { panic!() };
        assert!(matches!(a.value.kind, ExprKind::Binary(..)));
        drop(line);

        // A left-leaning chain of every operation.
        let line = read(&format!("R1={}", chain("-", MAX_OPERATIONS)));
        assert!(format!("{line:?}").len() > MAX_OPERATIONS);
        drop(line.clone());
    });
}
