//! Operators, functions, precedence, vacant rules: hand-computed cases.

mod common;

use common::{alarm, close, eval, eval_with, num};
use fiveaxis_macro::{MacroErrorKind as K, MacroSettings};

#[test]
fn arithmetic_operators() {
    assert_eq!(num("1+2"), 3.0);
    assert_eq!(num("5-7"), -2.0);
    assert_eq!(num("6*7"), 42.0);
    assert_eq!(num("7/2"), 3.5);
    assert_eq!(num("1.5+.25"), 1.75);
    assert_eq!(num("10."), 10.0);
}

#[test]
fn precedence_and_brackets() {
    assert_eq!(num("1+2*3"), 7.0);
    assert_eq!(num("[1+2]*3"), 9.0);
    assert_eq!(num("10-4-3"), 3.0);
    assert_eq!(num("24/4/2"), 3.0);
    assert_eq!(num("2*3 MOD 4"), 2.0); // (2*3) MOD 4
    assert_eq!(num("1 + 7 MOD 4"), 4.0); // MOD binds like *
    assert_eq!(num("1 OR 2 AND 3"), 3.0); // 1 OR (2 AND 3) = 1 OR 2
    assert_eq!(num("6 AND 3 + 8"), 10.0); // (6 AND 3) + 8
    assert_eq!(num("-2*3"), -6.0);
    assert_eq!(num("2*-3"), -6.0);
    assert_eq!(num("-[1+2]"), -3.0);
    assert!(close(num("SIN[30]*2"), 1.0));
    assert_eq!(num("90-ACOS[0]"), 0.0);
}

#[test]
fn remainder() {
    assert_eq!(num("10 MOD 3"), 1.0);
    assert_eq!(num("-10 MOD 3"), -1.0);
    assert_eq!(num("10 MOD -3"), 1.0);
    assert_eq!(num("10.4 MOD 3"), 1.0); // 10 MOD 3
    assert_eq!(num("10.5 MOD 3"), 2.0); // 11 MOD 3
    assert_eq!(alarm("5 MOD 0"), K::DivisionByZero);
    assert_eq!(alarm("5 MOD 0.4"), K::DivisionByZero);
}

#[test]
fn bitwise_operators() {
    assert_eq!(num("12 AND 10"), 8.0);
    assert_eq!(num("12 OR 10"), 14.0);
    assert_eq!(num("12 XOR 10"), 6.0);
    assert_eq!(num("1.4 OR 2"), 3.0);
    assert_eq!(num("-1 AND 255"), 255.0);
    assert_eq!(alarm("1 AND 1E10"), K::NcAndMacro); // no exponents: `E10` is a word
    assert_eq!(alarm("1 AND 9999999999"), K::ArgumentOutOfRange);
}

#[test]
fn trigonometry_in_degrees() {
    assert!(close(num("SIN[30]"), 0.5));
    assert!(close(num("COS[60]"), 0.5));
    assert!(close(num("TAN[45]"), 1.0));
    assert_eq!(num("SIN[180]"), 0.0);
    assert_eq!(num("COS[90]"), 0.0);
    assert_eq!(num("COS[-180]"), -1.0);
    assert_eq!(num("SIN[450]"), 1.0);
    assert!(close(num("ASIN[0.5]"), 30.0));
    assert!(close(num("ACOS[0.5]"), 60.0));
    assert!(close(num("ACOS[-1]"), 180.0));
    assert_eq!(alarm("TAN[90]"), K::ArgumentOutOfRange);
    assert_eq!(alarm("TAN[-270]"), K::ArgumentOutOfRange);
    assert_eq!(alarm("ASIN[1.5]"), K::ArgumentOutOfRange);
    assert_eq!(alarm("ACOS[-1.01]"), K::ArgumentOutOfRange);
}

#[test]
fn arc_tangent_forms_and_nat() {
    let nat0 = MacroSettings::default();
    let nat1 = MacroSettings {
        nat: true,
        ..MacroSettings::default()
    };
    let at = |e: &str, s: &MacroSettings| eval_with(&[], e, s).expect("ok").expect("value");
    assert!(close(at("ATAN[1]/[1]", &nat0), 45.0));
    assert!(close(at("ATAN[1,1]", &nat0), 45.0));
    assert!(close(at("ATAN[-1]/[-1]", &nat0), 225.0));
    assert!(close(at("ATAN[-1,-1]", &nat1), -135.0));
    assert!(close(at("ATAN[-1,1]", &nat0), 315.0));
    assert!(close(at("ATAN[-1,1]", &nat1), -45.0));
    assert!(close(at("ATAN[1]", &nat0), 45.0));
    assert!(close(at("ATAN[-1]", &nat0), 315.0));
    assert!(close(at("ATAN[-1]", &nat1), -45.0));
    assert!(close(at("ASIN[-0.5]", &nat0), 330.0));
    assert!(close(at("ASIN[-0.5]", &nat1), -30.0));
    assert!(close(at("ACOS[-0.5]", &nat1), 120.0));
    assert_eq!(alarm("ATAN[0,0]"), K::ArgumentOutOfRange);
    // `ATAN[a]/b` without a bracket is the one-argument form divided.
    assert!(close(at("ATAN[1]/2", &nat0), 22.5));
}

#[test]
fn other_functions() {
    assert_eq!(num("SQRT[16]"), 4.0);
    assert_eq!(num("ABS[-3.5]"), 3.5);
    assert_eq!(num("ROUND[1.5]"), 2.0);
    assert_eq!(num("ROUND[-1.5]"), -2.0);
    assert_eq!(num("ROUND[1.49]"), 1.0);
    assert_eq!(num("FIX[1.2]"), 1.0);
    assert_eq!(num("FIX[-1.2]"), -1.0);
    assert_eq!(num("FUP[1.2]"), 2.0);
    assert_eq!(num("FUP[-1.2]"), -2.0);
    assert_eq!(num("FUP[3]"), 3.0);
    assert!(close(num("LN[EXP[2]]"), 2.0));
    assert!(close(num("EXP[1]"), std::f64::consts::E));
    assert_eq!(num("POW[2,10]"), 1024.0);
    assert_eq!(num("POW[-2,3]"), -8.0);
    assert_eq!(num("POW[4,0.5]"), 2.0);
    assert_eq!(num("ADP[0.01]"), 10.0);
    assert_eq!(num("BCD[123]"), f64::from(0x123));
    assert_eq!(num("BIN[291]"), 123.0);
    assert_eq!(num("BIN[BCD[99999999]]"), 99_999_999.0);
    assert_eq!(num("sqrt[9]"), 3.0); // case-insensitive
}

#[test]
fn function_alarms() {
    assert_eq!(alarm("SQRT[-1]"), K::ArgumentOutOfRange);
    assert_eq!(alarm("LN[0]"), K::ArgumentOutOfRange);
    assert_eq!(alarm("LN[-2]"), K::ArgumentOutOfRange);
    assert_eq!(alarm("POW[-2,0.5]"), K::ArgumentOutOfRange);
    assert_eq!(alarm("POW[0,-1]"), K::DivisionByZero);
    assert_eq!(alarm("BCD[-1]"), K::ArgumentOutOfRange);
    assert_eq!(alarm("BCD[100000000]"), K::ArgumentOutOfRange);
    assert_eq!(alarm("BIN[10]"), K::ArgumentOutOfRange); // 0xA is not BCD
    assert_eq!(alarm("EXP[1000]"), K::Overflow);
    assert_eq!(alarm("POW[10,400]"), K::Overflow);
    assert_eq!(
        alarm(
            "999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999*999999999999999"
        ),
        K::Overflow
    );
    assert_eq!(alarm("1/0"), K::DivisionByZero);
    assert_eq!(alarm("1/[2-2]"), K::DivisionByZero);
}

#[test]
fn vacant_rules_of_the_manual() {
    let v = |e: &str| eval_with(&[(2, Some(0.0))], e, &MacroSettings::default()).expect("no alarm");
    // Assignment: vacant stays vacant; any operation makes 0 of it.
    assert_eq!(v("#1"), None);
    assert_eq!(v("[#1]"), None);
    assert_eq!(v("#0"), None);
    assert_eq!(v("#1*5"), Some(0.0));
    assert_eq!(v("#1+#1"), Some(0.0));
    assert_eq!(v("#0+1"), Some(1.0));
    assert_eq!(v("ABS[#1]"), Some(0.0));
    assert_eq!(
        eval_with(&[], "5/#1", &MacroSettings::default()).map_err(|e| e.kind),
        Err(K::DivisionByZero)
    );
}

#[test]
fn vacant_comparisons() {
    // #1 vacant, #2 = 0.
    let cond = |c: &str| {
        let mut vars = fiveaxis_macro::Variables::new(4);
        let mut sys = common::TestSystem::default();
        let s = MacroSettings::default();
        vars.set(2, Some(0.0), &mut sys, &s).expect("set");
        common::exec(&mut vars, &mut sys, &s, &format!("IF [{c}] THEN #100=1")).expect("exec");
        vars.get(100, &sys, &s).expect("get") == Some(1.0)
    };
    assert!(cond("#1 EQ #0"));
    assert!(!cond("#2 EQ #0"));
    assert!(cond("#1 NE 0"));
    assert!(!cond("#2 NE 0"));
    assert!(cond("#1 GE #0"));
    assert!(cond("#2 GE #0"));
    assert!(!cond("#1 GT 0"));
    assert!(!cond("#2 GT 0"));
    assert!(cond("#1 LE #0"));
    assert!(cond("#2 LE #0"));
    assert!(!cond("#1 LT 0"));
    assert!(!cond("#2 LT 0"));
    assert!(cond("#1 EQ #3"));
    // Logical operators between comparisons.
    assert!(cond("[1 LT 2] AND [2 LT 3]"));
    assert!(!cond("[1 LT 2] AND [2 GT 3]"));
    assert!(cond("[1 GT 2] OR [2 LT 3]"));
    assert!(cond("[1 GT 2] XOR [2 LT 3]"));
    assert!(!cond("[1 LT 2] XOR [2 LT 3]"));
    assert!(cond("1.5 EQ 1.5"));
    assert!(cond("2 GE 2"));
    assert!(cond("-1 LT 0"));
}

#[test]
fn indirect_variables() {
    let s = MacroSettings::default();
    let setup = [(1, Some(2.0)), (2, Some(7.0)), (102, Some(42.0))];
    assert_eq!(eval_with(&setup, "#[#1]", &s).expect("ok"), Some(7.0));
    assert_eq!(eval_with(&setup, "#[#1+100]", &s).expect("ok"), Some(42.0));
    assert_eq!(eval_with(&setup, "#[1.5]", &s).expect("ok"), Some(7.0)); // rounds to #2
    assert_eq!(eval_with(&setup, "#[#9]", &s).expect("ok"), None); // vacant number is #0
    assert_eq!(eval_with(&setup, "#[#[#1]-5]", &s).expect("ok"), Some(7.0));
}

#[test]
fn longest_chain_evaluates() {
    let chain = format!("{}1", "1+".repeat(fiveaxis_macro::MAX_OPERATIONS));
    assert_eq!(num(&chain), (fiveaxis_macro::MAX_OPERATIONS + 1) as f64);
    let nested = format!("{}1", "[1+".repeat(4)) + &"]".repeat(4);
    assert_eq!(num(&nested), 5.0);
}

#[test]
fn number_forms() {
    assert_eq!(num("000123"), 123.0);
    assert_eq!(num(".5"), 0.5);
    assert_eq!(num("0.001"), 0.001);
    assert_eq!(num("123456789012345"), 123_456_789_012_345.0);
    assert_eq!(alarm("1234567890123456"), K::TooManyDigits);
    assert_eq!(alarm("1..2"), K::FormatError);
    assert_eq!(alarm("."), K::FormatError);
    assert_eq!(eval("# 1 0 0 + 1 0").expect("ok"), Some(10.0));
}
