//! Properties: random expression trees printed, parsed and evaluated agree
//! with a reference evaluator written here; no input makes the parser or
//! the evaluator panic.

mod common;

use common::TestSystem;
use fiveaxis_gcode::Block;
use fiveaxis_macro::{
    MacroErrorKind as K, MacroSettings, Statement, Variables, evaluate_block, is_macro_line,
    loop_end, loop_start, parse_statement,
};
use proptest::prelude::*;

/// The variables every case starts with: #1 vacant, #2 = 0, #3 = 2.5,
/// #4 = -7 (and #0, always vacant).
const VARS: [Option<f64>; 5] = [None, None, Some(0.0), Some(2.5), Some(-7.0)];

#[derive(Clone, Copy, Debug)]
enum Op {
    Add,
    Sub,
    Mul,
    Div,
    Mod,
    And,
    Or,
    Xor,
}

#[derive(Clone, Copy, Debug)]
enum F {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sqrt,
    Abs,
    Round,
    Fix,
    Fup,
    Ln,
    Exp,
}

#[derive(Clone, Debug)]
enum T {
    Num(f64),
    Var(usize),
    Neg(Box<T>),
    Bin(Op, Box<T>, Box<T>),
    F1(F, Box<T>),
    Atan2(Box<T>, Box<T>),
    Pow(Box<T>, Box<T>),
}

fn prec(op: Op) -> u8 {
    match op {
        Op::Mul | Op::Div | Op::Mod | Op::And => 2,
        Op::Add | Op::Sub | Op::Or | Op::Xor => 1,
    }
}

fn op_text(op: Op) -> &'static str {
    match op {
        Op::Add => "+",
        Op::Sub => "-",
        Op::Mul => "*",
        Op::Div => "/",
        Op::Mod => " MOD ",
        Op::And => " AND ",
        Op::Or => " OR ",
        Op::Xor => " XOR ",
    }
}

fn f_name(f: F) -> &'static str {
    match f {
        F::Sin => "SIN",
        F::Cos => "COS",
        F::Tan => "TAN",
        F::Asin => "ASIN",
        F::Acos => "ACOS",
        F::Atan => "ATAN",
        F::Sqrt => "SQRT",
        F::Abs => "ABS",
        F::Round => "ROUND",
        F::Fix => "FIX",
        F::Fup => "FUP",
        F::Ln => "LN",
        F::Exp => "EXP",
    }
}

/// Prints a tree with as few brackets as the precedence needs.
fn print(t: &T) -> String {
    match t {
        T::Num(x) => format!("{x}"),
        T::Var(n) => format!("#{n}"),
        T::Neg(e) => match **e {
            T::Bin(..) | T::Neg(_) => format!("-[{}]", print(e)),
            _ => format!("-{}", print(e)),
        },
        T::Bin(op, l, r) => {
            let side = |e: &T, right: bool| match e {
                T::Bin(o, ..) if prec(*o) < prec(*op) || (right && prec(*o) == prec(*op)) => {
                    format!("[{}]", print(e))
                }
                // `ATAN[a]/[b]` would read as the two-argument form.
                _ if !right && matches!(op, Op::Div) && ends_with_atan(e) => {
                    format!("[{}]", print(e))
                }
                _ => print(e),
            };
            format!("{}{}{}", side(l, false), op_text(*op), side(r, true))
        }
        T::F1(f, a) => format!("{}[{}]", f_name(*f), print(a)),
        T::Atan2(a, b) => format!("ATAN[{}]/[{}]", print(a), print(b)),
        T::Pow(a, b) => format!("POW[{},{}]", print(a), print(b)),
    }
}

/// Whether the printed tree ends with a one-argument `ATAN[…]`.
fn ends_with_atan(t: &T) -> bool {
    match t {
        T::F1(F::Atan, _) => true,
        T::Neg(e) => !matches!(**e, T::Bin(..) | T::Neg(_)) && ends_with_atan(e),
        T::Bin(op, _, r) => {
            !matches!(**r, T::Bin(o, ..) if prec(o) <= prec(*op)) && ends_with_atan(r)
        }
        _ => false,
    }
}

/// Sine and cosine of degrees, exact at multiples of 90°.
fn sin_cos(deg: f64) -> (f64, f64) {
    let mut r = deg % 360.0;
    if r < 0.0 {
        r += 360.0;
    }
    match r {
        0.0 => (0.0, 1.0),
        90.0 => (1.0, 0.0),
        180.0 => (0.0, -1.0),
        270.0 => (-1.0, 0.0),
        _ => (r.to_radians().sin(), r.to_radians().cos()),
    }
}

fn checked(x: f64) -> Result<Option<f64>, K> {
    if x.is_finite() {
        Ok(Some(x))
    } else {
        Err(K::Overflow)
    }
}

fn int32(x: f64) -> Result<i64, K> {
    let x = x.round();
    if (-2_147_483_648.0..=2_147_483_647.0).contains(&x) {
        Ok(x as i64)
    } else {
        Err(K::ArgumentOutOfRange)
    }
}

/// The reference evaluator (default settings: NAT = 0).
fn reference(t: &T) -> Result<Option<f64>, K> {
    match t {
        T::Num(x) => Ok(Some(*x)),
        T::Var(n) => Ok(VARS[*n]),
        T::Neg(e) => Ok(reference(e)?.map(|x| -x)),
        T::Bin(op, l, r) => {
            let a = reference(l)?.unwrap_or(0.0);
            let b = reference(r)?.unwrap_or(0.0);
            let x = match op {
                Op::Add => a + b,
                Op::Sub => a - b,
                Op::Mul => a * b,
                Op::Div => {
                    if b == 0.0 {
                        return Err(K::DivisionByZero);
                    }
                    a / b
                }
                Op::Mod => {
                    let (a, b) = (a.round(), b.round());
                    if b == 0.0 {
                        return Err(K::DivisionByZero);
                    }
                    a % b
                }
                Op::And | Op::Or | Op::Xor => {
                    let (a, b) = (int32(a)?, int32(b)?);
                    (match op {
                        Op::And => a & b,
                        Op::Or => a | b,
                        _ => a ^ b,
                    }) as f64
                }
            };
            checked(x)
        }
        T::F1(f, e) => {
            let a = reference(e)?.unwrap_or(0.0);
            let pos = |d: f64| if d < 0.0 { d + 360.0 } else { d };
            let x = match f {
                F::Sin => sin_cos(a).0,
                F::Cos => sin_cos(a).1,
                F::Tan => {
                    let (s, c) = sin_cos(a);
                    if c == 0.0 {
                        return Err(K::ArgumentOutOfRange);
                    }
                    s / c
                }
                F::Asin | F::Acos if a.abs() > 1.0 => return Err(K::ArgumentOutOfRange),
                F::Asin => pos(a.asin().to_degrees()),
                F::Acos => a.acos().to_degrees(),
                F::Atan => pos(a.atan().to_degrees()),
                F::Sqrt if a < 0.0 => return Err(K::ArgumentOutOfRange),
                F::Sqrt => a.sqrt(),
                F::Abs => a.abs(),
                F::Round => a.round(),
                F::Fix => a.trunc(),
                F::Fup => {
                    if a.fract() == 0.0 {
                        a
                    } else {
                        a.trunc() + a.signum()
                    }
                }
                F::Ln if a <= 0.0 => return Err(K::ArgumentOutOfRange),
                F::Ln => a.ln(),
                F::Exp => a.exp(),
            };
            checked(x)
        }
        T::Atan2(a, b) => {
            let (y, x) = (reference(a)?.unwrap_or(0.0), reference(b)?.unwrap_or(0.0));
            if y == 0.0 && x == 0.0 {
                return Err(K::ArgumentOutOfRange);
            }
            let d = y.atan2(x).to_degrees();
            checked(if d < 0.0 { d + 360.0 } else { d })
        }
        T::Pow(a, b) => {
            let (a, b) = (reference(a)?.unwrap_or(0.0), reference(b)?.unwrap_or(0.0));
            if a < 0.0 && b.fract() != 0.0 {
                return Err(K::ArgumentOutOfRange);
            }
            if a == 0.0 && b < 0.0 {
                return Err(K::DivisionByZero);
            }
            checked(a.powf(b))
        }
    }
}

fn leaf() -> impl Strategy<Value = T> {
    prop_oneof![
        (0u32..2_000_000).prop_map(|k| T::Num(f64::from(k) / 1000.0)),
        (0u32..400).prop_map(|k| T::Num(f64::from(k))),
        prop_oneof![Just(0.0), Just(0.5), Just(1.0), Just(90.0), Just(180.0)].prop_map(T::Num),
        (0usize..5).prop_map(T::Var),
    ]
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        Just(Op::Add),
        Just(Op::Sub),
        Just(Op::Mul),
        Just(Op::Div),
        Just(Op::Mod),
        Just(Op::And),
        Just(Op::Or),
        Just(Op::Xor),
    ]
}

fn func() -> impl Strategy<Value = F> {
    prop_oneof![
        Just(F::Sin),
        Just(F::Cos),
        Just(F::Tan),
        Just(F::Asin),
        Just(F::Acos),
        Just(F::Atan),
        Just(F::Sqrt),
        Just(F::Abs),
        Just(F::Round),
        Just(F::Fix),
        Just(F::Fup),
        Just(F::Ln),
        Just(F::Exp),
    ]
}

/// Trees at most 4 levels deep: printed, they nest at most 4 brackets.
fn tree() -> impl Strategy<Value = T> {
    leaf().prop_recursive(4, 24, 2, |inner| {
        prop_oneof![
            inner.clone().prop_map(|e| T::Neg(Box::new(e))),
            (op(), inner.clone(), inner.clone()).prop_map(|(o, l, r)| T::Bin(
                o,
                Box::new(l),
                Box::new(r)
            )),
            (op(), inner.clone(), inner.clone()).prop_map(|(o, l, r)| T::Bin(
                o,
                Box::new(l),
                Box::new(r)
            )),
            (func(), inner.clone()).prop_map(|(f, e)| T::F1(f, Box::new(e))),
            (inner.clone(), inner.clone()).prop_map(|(a, b)| T::Atan2(Box::new(a), Box::new(b))),
            (inner.clone(), inner).prop_map(|(a, b)| T::Pow(Box::new(a), Box::new(b))),
        ]
    })
}

fn setup() -> (Variables, TestSystem, MacroSettings) {
    let s = MacroSettings::default();
    let mut sys = TestSystem::default();
    let mut vars = Variables::new(4);
    for (n, v) in VARS.iter().enumerate().skip(1) {
        vars.set(n as u32, *v, &mut sys, &s).expect("setup");
    }
    (vars, sys, s)
}

fn agree(got: &Result<Option<f64>, K>, want: &Result<Option<f64>, K>) -> bool {
    match (got, want) {
        (Ok(Some(a)), Ok(Some(b))) => {
            (a - b).abs() <= 1e-9 * a.abs().max(b.abs()) || (a - b).abs() <= 1e-12
        }
        _ => got == want,
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn printed_trees_evaluate_like_the_reference(t in tree()) {
        let text = format!("#100={}", print(&t));
        let line = parse_statement(text.as_bytes(), 1);
        let line = line.map_err(|e| TestCaseError::fail(format!("{text}: {e:?}")))?;
        let Statement::Assign { target, value } = line.statement else {
            return Err(TestCaseError::fail(format!("{text}: not an assignment")));
        };
        let (mut vars, mut sys, s) = setup();
        let got = vars
            .assign(&target, &value, None, &mut sys, &s)
            .and_then(|()| vars.get(100, &sys, &s))
            .map_err(|e| e.kind);
        let want = reference(&t);
        prop_assert!(agree(&got, &want), "{}: got {:?}, want {:?}", text, got, want);
        // The crate prints the tree back as text that reads back the same.
        let again = format!("#100={value}");
        let reparsed = parse_statement(again.as_bytes(), 1)
            .map_err(|e| TestCaseError::fail(format!("{again}: {e:?}")))?;
        let Statement::Assign { value: value2, .. } = reparsed.statement else {
            return Err(TestCaseError::fail(format!("{again}: not an assignment")));
        };
        prop_assert_eq!(value2.to_string(), value.to_string());
    }

    #[test]
    fn comparisons_follow_the_vacant_rules(a in tree(), b in tree(), cmp in 0usize..6) {
        let ops = ["EQ", "NE", "GT", "GE", "LT", "LE"];
        let text = format!("IF [{} {} {}] THEN #100=1", print(&a), ops[cmp], print(&b));
        let (mut vars, mut sys, s) = setup();
        let got = common::exec(&mut vars, &mut sys, &s, &text)
            .and_then(|()| vars.get(100, &sys, &s))
            .map(|v| v == Some(1.0))
            .map_err(|e| e.kind);
        let want = reference(&a).and_then(|x| reference(&b).map(|y| (x, y))).map(|(x, y)| {
            match cmp {
                0 | 1 => {
                    let eq = match (x, y) {
                        (None, None) => true,
                        (Some(p), Some(q)) => p == q,
                        _ => false,
                    };
                    eq == (cmp == 0)
                }
                _ => {
                    let (p, q) = (x.unwrap_or(0.0), y.unwrap_or(0.0));
                    [p > q, p >= q, p < q, p <= q][cmp - 2]
                }
            }
        });
        prop_assert_eq!(got, want, "{}", text);
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..200)) {
        exercise(&bytes);
    }

    #[test]
    fn macro_like_text_never_panics(
        parts in prop::collection::vec(
            prop_oneof![
                Just("#"), Just("["), Just("]"), Just("="), Just("+"), Just("-"), Just("*"),
                Just("/"), Just(","), Just("."), Just(" "), Just("("), Just(")"), Just(";"),
                Just("%"), Just("GOTO"), Just("IF"), Just("THEN"), Just("WHILE"), Just("DO"),
                Just("END"), Just("EQ"), Just("LT"), Just("AND"), Just("MOD"), Just("SIN"),
                Just("ATAN"), Just("POW"), Just("BCD"), Just("N"), Just("G"), Just("X"),
                Just("P"), Just("1"), Just("0"), Just("9"), Just("99999999999999999999"),
                Just("1.5"), Just("100"), Just("3000"), Just("1E308"), Just("\u{e9}"),
            ],
            0..40,
        )
    ) {
        exercise(parts.concat().as_bytes());
    }

    #[test]
    fn deep_brackets_never_overflow(depth in 0usize..20_000, kind in 0usize..4) {
        let (open, close) = ("[".repeat(depth), "]".repeat(depth));
        let text = match kind {
            0 => format!("#1={open}1{close}"),
            1 => format!("X{open}1{close}"),
            2 => format!("IF {open}1 LT 2{close} GOTO 1"),
            _ => format!("#1=#{open}1{close}"),
        };
        let result = parse_statement(text.as_bytes(), 1);
        if depth > usize::from(fiveaxis_macro::MAX_BRACKET_DEPTH) {
            prop_assert_eq!(result.map_err(|e| e.kind).err(), Some(K::BracketNesting));
        }
        exercise(text.as_bytes());
    }
}

/// Parses and evaluates whatever parses, with every entry point.
fn exercise(bytes: &[u8]) {
    let _ = is_macro_line(bytes);
    let _ = loop_start(bytes);
    let _ = loop_end(bytes);
    let Ok(line) = parse_statement(bytes, 1) else {
        return;
    };
    let (mut vars, mut sys, s) = setup();
    let _ = vars.set(3000, Some(1.0), &mut sys, &s);
    match &line.statement {
        Statement::Assign { target, value } | Statement::IfThen { target, value, .. } => {
            let _ = vars.assign(target, value, line.comment.as_deref(), &mut sys, &s);
        }
        Statement::Goto(e) | Statement::IfGoto { target: e, .. } => {
            let _ = vars.eval_sequence(e, &sys, &s);
        }
        Statement::While { cond, .. } | Statement::IfBlock { cond } => {
            let _ = vars.eval_condition(cond, &sys, &s);
        }
        Statement::Nc(nc) => {
            let mut block = Block::default();
            if evaluate_block(nc, &vars, &sys, &s, &mut block).is_ok() {
                let _ = fiveaxis_macro::arguments(&block);
            }
        }
        Statement::Do { .. } | Statement::End { .. } | Statement::Else | Statement::EndIf => {}
    }
    if let Statement::IfGoto { cond, .. } | Statement::IfThen { cond, .. } = &line.statement {
        let _ = vars.eval_condition(cond, &sys, &s);
    }
}
