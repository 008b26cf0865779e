//! Properties of the RS274/NGC reader: flat chains of binary operations
//! evaluate as a reference written here from LinuxCNC's precedence table
//! (overview.adoc, "Operators Precedence": `**`; `* / MOD`; `+ -`;
//! comparisons; `AND OR XOR`; each group left to right); no bytes make the
//! reader or the evaluator panic.

use fiveaxis_macro::{
    MacroErrorKind, MacroSettings, NoSystemVariables, Value, Variables, parse_ngc_line,
};
use proptest::prelude::*;

#[derive(Clone, Copy, Debug)]
enum Op {
    Pow,
    Mul,
    Div,
    Mod,
    Add,
    Sub,
    Eq,
    Lt,
    Ge,
    And,
    Or,
    Xor,
}

impl Op {
    const ALL: [Op; 12] = [
        Op::Pow,
        Op::Mul,
        Op::Div,
        Op::Mod,
        Op::Add,
        Op::Sub,
        Op::Eq,
        Op::Lt,
        Op::Ge,
        Op::And,
        Op::Or,
        Op::Xor,
    ];

    fn text(self) -> &'static str {
        match self {
            Op::Pow => "**",
            Op::Mul => "*",
            Op::Div => "/",
            Op::Mod => "MOD",
            Op::Add => "+",
            Op::Sub => "-",
            Op::Eq => "EQ",
            Op::Lt => "LT",
            Op::Ge => "GE",
            Op::And => "AND",
            Op::Or => "OR",
            Op::Xor => "XOR",
        }
    }

    /// The precedence group, higher binds tighter.
    fn group(self) -> u8 {
        match self {
            Op::Pow => 4,
            Op::Mul | Op::Div | Op::Mod => 3,
            Op::Add | Op::Sub => 2,
            Op::Eq | Op::Lt | Op::Ge => 1,
            Op::And | Op::Or | Op::Xor => 0,
        }
    }

    /// The operation; `None` for division by zero.
    fn apply(self, a: f64, b: f64) -> Option<f64> {
        let t = |x: bool| if x { 1.0 } else { 0.0 };
        Some(match self {
            Op::Pow => {
                if (a < 0.0 && b.fract() != 0.0) || (a == 0.0 && b < 0.0) {
                    return None;
                }
                a.powf(b)
            }
            Op::Mul => a * b,
            Op::Div | Op::Mod if b == 0.0 => return None,
            Op::Div => a / b,
            Op::Mod => {
                let m = a % b;
                if m < 0.0 { m + b.abs() } else { m }
            }
            Op::Add => a + b,
            Op::Sub => a - b,
            Op::Eq => t((a - b).abs() < 1e-6),
            Op::Lt => t(a < b),
            Op::Ge => t(a >= b),
            Op::And => t(a != 0.0 && b != 0.0),
            Op::Or => t(a != 0.0 || b != 0.0),
            Op::Xor => t((a != 0.0) != (b != 0.0)),
        })
    }
}

/// Reference: repeatedly reduce the leftmost operator of the highest
/// group present (left associativity within a group).
fn reference(numbers: &[f64], ops: &[Op]) -> Option<f64> {
    let mut values = numbers.to_vec();
    let mut ops = ops.to_vec();
    while !ops.is_empty() {
        let top = ops.iter().map(|o| o.group()).max()?;
        let k = ops.iter().position(|o| o.group() == top)?;
        let v = ops[k].apply(values[k], values[k + 1])?;
        if !v.is_finite() {
            return None;
        }
        values[k] = v;
        values.remove(k + 1);
        ops.remove(k);
    }
    values.first().copied()
}

fn operand() -> impl Strategy<Value = f64> {
    // Small integers and halves: exact in binary, so the order of the
    // operations is all that can differ.
    (-6i32..=6, any::<bool>()).prop_map(|(n, half)| f64::from(n) + if half { 0.5 } else { 0.0 })
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 3000,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x4e47_4321),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn flat_chains_follow_linuxcnc_precedence(
        chain in prop::collection::vec((operand(), prop::sample::select(Op::ALL.to_vec())), 1..7),
        last in operand(),
    ) {
        let numbers: Vec<f64> = chain.iter().map(|(n, _)| *n).chain([last]).collect();
        let ops: Vec<Op> = chain.iter().map(|(_, o)| *o).collect();
        let mut text = String::from("#1 = [");
        for (n, op) in &chain {
            text.push_str(&format!("[{n}] {} ", op.text()));
        }
        text.push_str(&format!("[{last}]]"));
        let line = parse_ngc_line(text.as_bytes(), 1).expect("reads");
        let vars = Variables::linuxcnc(10);
        let got = vars.eval(&line.assignments[0].1, &NoSystemVariables, &MacroSettings::LINUXCNC);
        match (reference(&numbers, &ops), got) {
            (Some(want), Ok(Value::Number(x))) => {
                prop_assert!((want - x).abs() <= 1e-9 * want.abs().max(1.0), "{text}: {x} != {want}");
            }
            (None, Err(e)) => prop_assert!(matches!(
                e.kind,
                MacroErrorKind::DivisionByZero | MacroErrorKind::ArgumentOutOfRange | MacroErrorKind::Overflow
            ), "{text}: {e:?}"),
            (want, got) => prop_assert!(false, "{text}: reference {want:?}, kernel {got:?}"),
        }
    }

    #[test]
    fn any_bytes_are_read_or_refused_without_panic(bytes in prop::collection::vec(any::<u8>(), 0..200)) {
        if let Ok(line) = parse_ngc_line(&bytes, 1) {
            let vars = Variables::linuxcnc(10);
            for (_, e) in &line.assignments {
                let _ = vars.eval(e, &NoSystemVariables, &MacroSettings::LINUXCNC);
            }
        }
    }

    #[test]
    fn ngc_text_is_read_or_refused_without_panic(
        parts in prop::collection::vec(prop::sample::select(vec![
            "#", "<", ">", "[", "]", "o", "100", "sub", "call", "if", "**", "*", "-", "+", "/",
            "MOD", "EQ", "AND", "ATAN", "EXISTS", "SIN", "(", ")", ";", "x", "G1", "=", "1.5", " ",
            "_a", "#<_x>", "#5", ".", "N10", "%",
        ]), 0..40)
    ) {
        let text: String = parts.concat();
        if let Ok(line) = parse_ngc_line(text.as_bytes(), 1) {
            let vars = Variables::linuxcnc(10);
            for (_, e) in &line.assignments {
                let _ = vars.eval(e, &NoSystemVariables, &MacroSettings::LINUXCNC);
            }
        }
    }
}
