//! Every front end's expression reader, fed random expressions that mix
//! nesting, runs of signs, indirection, functions and operators around
//! and past every bound: each line ends in a value (a number or vacant)
//! or an alarm, never a panic or a stack overflow, on a thread with a
//! small stack. FANUC custom macro B (`parse_statement`) and RS274/NGC
//! (`parse_ngc_line`) read the same generated text, each in its own
//! notation for what differs (functions `ABS[…]` / `ABS[…]`, brackets).

use fiveaxis_macro::{
    MacroSettings, NoSystemVariables, Statement, Value, Variables, parse_ngc_line, parse_statement,
};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestRunner};

/// The stack of the thread the property runs on.
const SMALL_STACK: usize = 256 * 1024;

/// A random expression as text: `depth` more levels may nest.
fn expression(depth: u32) -> BoxedStrategy<String> {
    let leaf = prop_oneof![
        (0u32..100).prop_map(|n| n.to_string()),
        (-1e7f64..1e7).prop_map(|x| format!("{x:.4}")),
        Just("1e300".to_string()),
        Just(".".to_string()),
        (1u32..12).prop_map(|n| format!("#{n}")),
        // Indirection, up to past every reader's bound.
        (1usize..8, 1u32..12).prop_map(|(k, n)| format!("{}{n}", "#".repeat(k))),
    ]
    .boxed();
    if depth == 0 {
        return leaf;
    }
    let inner = expression(depth - 1);
    prop_oneof![
        leaf,
        // Brackets, possibly many levels at once.
        (1usize..40, inner.clone()).prop_map(|(k, e)| format!(
            "{}{e}{}",
            "[".repeat(k),
            "]".repeat(k)
        )),
        // Runs of signs.
        (1usize..14, prop::bool::ANY, inner.clone())
            .prop_map(|(k, plus, e)| format!("{}{e}", if plus { "+" } else { "-" }.repeat(k))),
        // Indirection of a bracketed expression.
        (1usize..7, inner.clone()).prop_map(|(k, e)| format!("{}[{e}]", "#".repeat(k))),
        // Functions.
        (
            prop::sample::select(vec![
                "SIN", "COS", "TAN", "ATAN", "SQRT", "ABS", "ROUND", "FIX", "FUP", "LN", "EXP",
                "ASIN", "ACOS", "BIN", "BCD", "EXISTS", "NOPE",
            ]),
            inner.clone()
        )
            .prop_map(|(f, e)| format!("{f}[{e}]")),
        // Binary operators, in long chains.
        (
            inner.clone(),
            prop::collection::vec(
                (
                    prop::sample::select(vec![
                        "+", "-", "*", "/", "**", " MOD ", " AND ", " OR ", " XOR ", " EQ ",
                        " NE ", " LT ", " GE ", "&", "||",
                    ]),
                    inner
                ),
                1..6
            )
        )
            .prop_map(|(first, rest)| {
                let mut s = first;
                for (op, e) in rest {
                    s.push_str(op);
                    s.push_str(&e);
                }
                s
            }),
    ]
    .boxed()
}

/// A line, in both readers' syntax, that assigns the expression (and
/// sometimes uses it as an axis word or a target).
fn line() -> impl Strategy<Value = String> {
    (expression(4), 0u8..4).prop_map(|(e, form)| match form {
        0 => format!("#1 = {e}"),
        1 => format!("#1={e}"),
        2 => format!("#[{e}] = 1"),
        _ => format!("G1 X[{e}]"),
    })
}

/// FANUC: read, and the assignment evaluated; a value or an alarm.
/// Whether it gave a value.
fn fanuc(text: &str) -> bool {
    let Ok(line) = parse_statement(text.as_bytes(), 1) else {
        return false;
    };
    let settings = MacroSettings::default();
    let mut vars = Variables::new(4);
    for n in 1..=11 {
        let _ = vars.set(n, Some(f64::from(n)), &mut NoSystemVariables, &settings);
    }
    if let Statement::Assign { value, .. } = &line.statement {
        match vars.eval(value, &NoSystemVariables, &settings) {
            Ok(Value::Number(x)) => {
                assert!(x.is_finite(), "{text}: {x}");
                return true;
            }
            Ok(_) => return true,
            Err(_) => {}
        }
    }
    false
}

/// RS274/NGC: read, and every assignment evaluated; a value or an alarm.
/// Whether it gave values.
fn ngc(text: &str) -> bool {
    let Ok(line) = parse_ngc_line(text.as_bytes(), 1) else {
        return false;
    };
    let settings = MacroSettings::LINUXCNC;
    let mut vars = Variables::linuxcnc(12);
    for n in 1..=11 {
        let _ = vars.set(n, Some(f64::from(n)), &mut NoSystemVariables, &settings);
    }
    let mut valued = !line.assignments.is_empty();
    for (_, e) in &line.assignments {
        match vars.eval(e, &NoSystemVariables, &settings) {
            Ok(Value::Number(x)) => assert!(x.is_finite(), "{text}: {x}"),
            Ok(_) => {}
            Err(_) => valued = false,
        }
    }
    valued
}

#[test]
fn random_expressions_end_in_a_value_or_an_alarm_in_every_reader() {
    std::thread::Builder::new()
        .stack_size(SMALL_STACK)
        .spawn(|| {
            let mut runner = TestRunner::new(Config {
                cases: 1500,
                rng_seed: RngSeed::Fixed(23),
                failure_persistence: None,
                ..Config::default()
            });
            let valued = std::cell::Cell::new([0u32; 2]);
            runner
                .run(&line(), |text| {
                    let [f, n] = valued.get();
                    valued.set([f + u32::from(fanuc(&text)), n + u32::from(ngc(&text))]);
                    Ok(())
                })
                .expect("every line ends in a value or an alarm");
            // Not only alarms: a good share of the lines are read and give
            // a value in each reader.
            let [f, n] = valued.get();
            assert!(f > 100 && n > 100, "values: FANUC {f}, NGC {n} of 1500");
        })
        .expect("thread")
        .join()
        .expect("no panic and no stack overflow on a 256 KiB stack");
}
