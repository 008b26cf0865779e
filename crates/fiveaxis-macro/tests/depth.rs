//! Every bound on the depth of what the readers build, at the bound and
//! one past it, and far past it (30,000, a line of about 30 KB, under the
//! runner's 64 KiB line limit): the bound is read, one more is an alarm,
//! and 30,000 is the same alarm, not a stack overflow. Everything runs on
//! a thread with a small stack (the Python package's worker threads, and
//! threads in programs that embed the kernel, have far less than the main
//! thread's 8 MiB), and the deepest line the bounds allow is read,
//! evaluated and dropped there.

use fiveaxis_macro::{
    MAX_BRACKET_DEPTH, MAX_NGC_DEPTH, MAX_NGC_INDIRECTION, MAX_NGC_OPERATIONS, MAX_NGC_SIGNS,
    MAX_OPERATIONS, MacroError, MacroErrorKind, MacroSettings, NoSystemVariables, Statement, Value,
    Variables, parse_ngc_line, parse_statement,
};

/// The stack of the thread the tests run on.
const SMALL_STACK: usize = 256 * 1024;

/// How many of a repeated thing a hostile line holds.
const HOSTILE: usize = 30_000;

fn on_small_stack(f: impl FnOnce() + Send + 'static) {
    std::thread::Builder::new()
        .stack_size(SMALL_STACK)
        .spawn(f)
        .expect("thread")
        .join()
        .expect("the test ends on a 256 KiB stack");
}

/// The value of an RS274/NGC `#1 = …` line with every numbered
/// parameter from 1 to 9 set to 1.
fn ngc_value(text: &str) -> Result<f64, MacroError> {
    let line = parse_ngc_line(text.as_bytes(), 1)?;
    let settings = MacroSettings::LINUXCNC;
    let mut vars = Variables::linuxcnc(10);
    for n in 1..=9 {
        vars.set(n, Some(1.0), &mut NoSystemVariables, &settings)?;
    }
    let (_, e) = &line.assignments[0];
    match vars.eval(e, &NoSystemVariables, &settings)? {
        Value::Number(x) => Ok(x),
        other => panic!("{other:?}"),
    }
}

fn ngc_error(text: &str) -> MacroError {
    parse_ngc_line(text.as_bytes(), 1).expect_err("refused")
}

/// `1 op 1 op …` with `n` operations.
fn chain(op: &str, n: usize) -> String {
    let mut s = String::from("1");
    for _ in 0..n {
        s.push_str(op);
        s.push('1');
    }
    s
}

#[test]
fn ngc_signs_in_a_row_are_bounded() {
    on_small_stack(|| {
        let even = format!("#1 = {}1", "-".repeat(MAX_NGC_SIGNS));
        assert_eq!(ngc_value(&even).expect("read"), 1.0);
        let odd = format!("#1 = +{}#1", "-".repeat(MAX_NGC_SIGNS - 1));
        assert_eq!(ngc_value(&odd).expect("read"), -1.0);
        for n in [MAX_NGC_SIGNS + 1, HOSTILE] {
            let e = ngc_error(&format!("#1 = {}1", "-".repeat(n)));
            assert_eq!(e.kind, MacroErrorKind::FormatError);
            assert!(e.message.contains("signs in a row"), "{}", e.message);
            // The columns of the signs up to the first one too many.
            assert_eq!(
                (e.span.start as usize, e.span.end as usize),
                (6, 6 + MAX_NGC_SIGNS + 1)
            );
        }
        // In a word's value too.
        let e = ngc_error(&format!("G1 X{}1", "-".repeat(HOSTILE)));
        assert!(e.message.contains("signs in a row"), "{}", e.message);
    });
}

#[test]
fn ngc_parameter_indirection_is_bounded() {
    on_small_stack(|| {
        let text = format!("#1 = {}1", "#".repeat(MAX_NGC_INDIRECTION));
        assert_eq!(ngc_value(&text).expect("read"), 1.0);
        let text = format!("#1 = {}[1]", "#".repeat(MAX_NGC_INDIRECTION));
        assert_eq!(ngc_value(&text).expect("read"), 1.0);
        for n in [MAX_NGC_INDIRECTION + 1, HOSTILE] {
            for target in [
                format!("#1 = {}1", "#".repeat(n)),
                format!("{}1 = 2", "#".repeat(n)),
            ] {
                let e = ngc_error(&target);
                assert_eq!(e.kind, MacroErrorKind::FormatError);
                assert!(e.message.contains("`#` in a row"), "{}", e.message);
            }
        }
    });
}

#[test]
fn ngc_operations_per_line_are_bounded() {
    on_small_stack(|| {
        let text = format!("#1 = [{}]", chain("+", MAX_NGC_OPERATIONS));
        assert_eq!(
            ngc_value(&text).expect("read"),
            (MAX_NGC_OPERATIONS + 1) as f64
        );
        for n in [MAX_NGC_OPERATIONS + 1, HOSTILE] {
            let e = ngc_error(&format!("#1 = [{}]", chain("+", n)));
            assert_eq!(e.kind, MacroErrorKind::FormatError);
            assert!(
                e.message.contains("operations in one line"),
                "{}",
                e.message
            );
        }
        // Counted over the whole line, not per expression.
        let half = MAX_NGC_OPERATIONS / 2;
        let text = format!("G1 X[{}] Y[{}]", chain("*", half), chain("*", half + 1));
        assert!(ngc_error(&text).message.contains("operations"));
    });
}

#[test]
fn ngc_brackets_are_bounded() {
    on_small_stack(|| {
        let depth = usize::from(MAX_NGC_DEPTH);
        let text = format!("#1 = {}1{}", "[".repeat(depth), "]".repeat(depth));
        assert_eq!(ngc_value(&text).expect("read"), 1.0);
        for n in [depth + 1, HOSTILE] {
            let e = ngc_error(&format!("#1 = {}1{}", "[".repeat(n), "]".repeat(n)));
            assert_eq!(e.kind, MacroErrorKind::BracketNesting);
        }
    });
}

/// The deepest tree the bounds allow: every bracket level behind the
/// most signs and `#`, the most operations inside, through a function;
/// read, evaluated, printed in an alarm message and dropped.
#[test]
fn ngc_deepest_line_reads_evaluates_and_drops_on_a_small_stack() {
    on_small_stack(|| {
        let level = format!(
            "{}{}[",
            "-".repeat(MAX_NGC_SIGNS),
            "#".repeat(MAX_NGC_INDIRECTION)
        );
        // The outer bracket and ABS's take two levels.
        let levels = usize::from(MAX_NGC_DEPTH) - 2;
        let deep = |ops: usize| {
            format!(
                "{}ABS[{}]{}",
                level.repeat(levels),
                chain("**", ops),
                "]".repeat(levels)
            )
        };
        let text = format!("#1 = [{}]", deep(MAX_NGC_OPERATIONS));
        assert_eq!(ngc_value(&text).expect("read"), 1.0);
        // A division by zero's message prints the whole dividend.
        let text = format!("#1 = [{}/0]", deep(MAX_NGC_OPERATIONS - 1));
        let e = ngc_value(&text).expect_err("division by zero");
        assert_eq!(e.kind, MacroErrorKind::DivisionByZero);
        assert!(e.message.len() > text.len() / 2, "{}", e.message);
    });
}

fn fanuc_error(text: &str) -> MacroError {
    parse_statement(text.as_bytes(), 1).expect_err("refused")
}

fn fanuc_value(text: &str) -> f64 {
    let line = parse_statement(text.as_bytes(), 1).expect("read");
    let Statement::Assign { value, .. } = &line.statement else {
        panic!("{:?}", line.statement)
    };
    let mut vars = Variables::new(4);
    let settings = MacroSettings::default();
    vars.set(1, Some(1.0), &mut NoSystemVariables, &settings)
        .expect("set");
    match vars.eval(value, &NoSystemVariables, &settings) {
        Ok(Value::Number(x)) => x,
        other => panic!("{other:?}"),
    }
}

/// Custom macro B reads one sign per operand, no `##`, five bracket
/// levels and [`MAX_OPERATIONS`] operations: the hostile lines end in
/// alarms there too.
#[test]
fn fanuc_reader_is_bounded_too() {
    on_small_stack(|| {
        assert_eq!(fanuc_value("#2 = -1"), -1.0);
        assert_eq!(fanuc_error("#2 = --1").kind, MacroErrorKind::FormatError);
        let e = fanuc_error(&format!("#2 = {}1", "-".repeat(HOSTILE)));
        assert_eq!(e.kind, MacroErrorKind::FormatError);

        assert_eq!(fanuc_value("#2 = #[#1]"), 1.0);
        for n in [2, HOSTILE] {
            let e = fanuc_error(&format!("#2 = {}1", "#".repeat(n)));
            assert_eq!(e.kind, MacroErrorKind::FormatError);
        }

        let depth = usize::from(MAX_BRACKET_DEPTH);
        let text = format!("#2 = {}1{}", "[".repeat(depth), "]".repeat(depth));
        assert_eq!(fanuc_value(&text), 1.0);
        for n in [depth + 1, HOSTILE] {
            let e = fanuc_error(&format!("#2 = {}1{}", "[".repeat(n), "]".repeat(n)));
            assert_eq!(e.kind, MacroErrorKind::BracketNesting);
        }

        let text = format!("#2 = {}", chain("+", MAX_OPERATIONS));
        assert_eq!(fanuc_value(&text), (MAX_OPERATIONS + 1) as f64);
        for n in [MAX_OPERATIONS + 1, HOSTILE] {
            let e = fanuc_error(&format!("#2 = {}", chain("+", n)));
            assert_eq!(e.kind, MacroErrorKind::FormatError);
        }

        // The deepest: five levels of `#[`, the most operations inside,
        // printed whole in the message of a division by zero.
        let text = format!(
            "#2 = -{}{}{}/0",
            "#[".repeat(depth),
            chain("*", MAX_OPERATIONS - 1),
            "]".repeat(depth)
        );
        let line = parse_statement(text.as_bytes(), 1).expect("read");
        let Statement::Assign { value, .. } = &line.statement else {
            panic!("{:?}", line.statement)
        };
        let mut vars = Variables::new(4);
        let settings = MacroSettings::default();
        vars.set(1, Some(1.0), &mut NoSystemVariables, &settings)
            .expect("set");
        let e = vars
            .eval(value, &NoSystemVariables, &settings)
            .expect_err("division by zero");
        assert_eq!(e.kind, MacroErrorKind::DivisionByZero);
        assert!(e.message.len() > text.len() / 2, "{}", e.message);
    });
}
