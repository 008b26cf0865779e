//! The variable store, system variables, and the alarms of evaluation
//! with their numbers and spans.

mod common;

use common::{TestSystem, exec};
use fiveaxis_gcode::Span;
use fiveaxis_macro::{
    LOCAL_COUNT, MacroErrorKind as K, MacroSettings, NoSystemVariables, Statement, Variables,
    parse_statement,
};

fn setup() -> (Variables, TestSystem, MacroSettings) {
    (
        Variables::new(4),
        TestSystem::default(),
        MacroSettings::default(),
    )
}

#[test]
fn ranges_of_variables() {
    let (mut vars, mut sys, s) = setup();
    for n in [1, 33, 100, 199, 500, 999] {
        vars.set(n, Some(f64::from(n)), &mut sys, &s)
            .expect("exists");
        assert_eq!(vars.get(n, &sys, &s).expect("read"), Some(f64::from(n)));
    }
    for n in [34, 99, 200, 499] {
        assert_eq!(
            vars.set(n, Some(1.0), &mut sys, &s).map_err(|e| e.kind),
            Err(K::UndefinedVariable)
        );
        assert_eq!(
            vars.get(n, &sys, &s).map_err(|e| e.kind),
            Err(K::UndefinedVariable)
        );
    }
    let ext = MacroSettings {
        extended_common: true,
        ..s
    };
    vars.set(300, Some(3.0), &mut sys, &ext).expect("extended");
    assert_eq!(vars.get(300, &sys, &ext).expect("read"), Some(3.0));
    assert_eq!(vars.get(0, &sys, &s).expect("#0"), None);
}

#[test]
fn undefined_variable_alarm_names_the_number() {
    let (mut vars, mut sys, s) = setup();
    let e = exec(&mut vars, &mut sys, &s, "#1=#34+1").expect_err("alarm");
    assert_eq!(e.kind, K::UndefinedVariable);
    assert_eq!(e.fanuc_number(), 115);
    assert_eq!(e.message, "variable #34 does not exist");
    assert_eq!(e.span, Span::new(4, 7));
    let e = exec(&mut vars, &mut sys, &s, "#1=#[-3]").expect_err("alarm");
    assert_eq!(e.message, "variable #-3 does not exist");
    assert_eq!(e.span, Span::new(4, 9));
    let e = exec(&mut vars, &mut sys, &s, "#50=1").expect_err("alarm");
    assert_eq!(e.span, Span::new(1, 4));
    let e = exec(&mut vars, &mut sys, &s, "#1=#9000").expect_err("alarm");
    assert_eq!(e.kind, K::UndefinedVariable);
}

#[test]
fn write_protection() {
    let (mut vars, mut sys, s) = setup();
    let e = exec(&mut vars, &mut sys, &s, "#0=1").expect_err("alarm");
    assert_eq!(e.kind, K::WriteProtected);
    assert_eq!(e.fanuc_number(), 116);
    assert_eq!(e.span, Span::new(1, 3));
    let e = exec(&mut vars, &mut sys, &s, "#[#5]=1").expect_err("vacant number is #0");
    assert_eq!(e.kind, K::WriteProtected);
    let e = exec(&mut vars, &mut sys, &s, "#1001=1").expect_err("read-only");
    assert_eq!(e.kind, K::WriteProtected);
    assert_eq!(e.message, "variable #1001 can only be read");
}

#[test]
fn system_variables_go_to_the_controller() {
    let (mut vars, mut sys, s) = setup();
    sys.values.insert(1005, Some(1.0));
    exec(&mut vars, &mut sys, &s, "#5001=#1005*2+0.5").expect("write");
    assert_eq!(sys.values.get(&5001), Some(&Some(2.5)));
    exec(&mut vars, &mut sys, &s, "#1=#5001").expect("read");
    assert_eq!(vars.get(1, &sys, &s).expect("get"), Some(2.5));
    let e = vars
        .get(5001, &NoSystemVariables, &s)
        .expect_err("no system variables");
    assert_eq!(e.kind, K::UndefinedVariable);
    let e = vars
        .set(5001, None, &mut NoSystemVariables, &s)
        .expect_err("no system variables");
    assert_eq!(e.kind, K::UndefinedVariable);
}

#[test]
fn custom_alarm_from_3000_keeps_the_comment() {
    let (mut vars, mut sys, s) = setup();
    let e = exec(&mut vars, &mut sys, &s, "#3000=1(TOOL BROKEN)").expect_err("alarm");
    assert_eq!(e.kind, K::CustomAlarm(1));
    assert_eq!(e.fanuc_number(), 3001);
    assert_eq!(e.message, "TOOL BROKEN");
    assert_eq!(e.span, Span::new(1, 6));
    let e = exec(&mut vars, &mut sys, &s, "IF [1 LT 2] THEN #3000=12").expect_err("alarm");
    assert_eq!(e.kind, K::CustomAlarm(12));
    assert_eq!(e.message, "alarm 12 raised by #3000");
}

#[test]
fn evaluation_alarms_have_numbers_and_spans() {
    let (mut vars, mut sys, s) = setup();
    vars.set(2, Some(0.0), &mut sys, &s).expect("set");
    let e = exec(&mut vars, &mut sys, &s, "#3 = 5 + #1/#2").expect_err("alarm");
    assert_eq!(e.kind, K::DivisionByZero);
    assert_eq!(e.fanuc_number(), 112);
    assert_eq!(e.message, "division by zero in `#1/#2`");
    assert_eq!(e.span, Span::new(10, 15));
    let e = exec(&mut vars, &mut sys, &s, "#3=1+SQRT[-4]").expect_err("alarm");
    assert_eq!(e.kind, K::ArgumentOutOfRange);
    assert_eq!(e.fanuc_number(), 119);
    assert_eq!(e.span, Span::new(6, 14));
    assert!(e.message.contains("SQRT[-4]"), "{}", e.message);
    let e = exec(&mut vars, &mut sys, &s, "#3=EXP[800]").expect_err("alarm");
    assert_eq!(e.kind, K::Overflow);
    assert_eq!(e.fanuc_number(), 111);
    assert_eq!(e.span, Span::new(4, 12));
    let e = exec(&mut vars, &mut sys, &s, "#3=ASIN[2]").expect_err("alarm");
    assert_eq!(e.span, Span::new(4, 11));
}

#[test]
fn frames_and_nesting() {
    let (mut vars, mut sys, s) = setup();
    vars.set(1, Some(10.0), &mut sys, &s).expect("main #1");
    let mut args = [None; LOCAL_COUNT];
    args[0] = Some(1.0);
    for level in 1..=4 {
        vars.push_frame(args).expect("nest");
        assert_eq!(vars.depth(), level);
        assert_eq!(vars.get(1, &sys, &s).expect("get"), Some(1.0));
        assert_eq!(vars.get(2, &sys, &s).expect("get"), None);
    }
    let e = vars.push_frame(args).expect_err("too deep");
    assert_eq!(e.kind, K::CallNesting);
    assert_eq!(e.fanuc_number(), 122);
    for _ in 0..4 {
        assert!(vars.pop_frame());
    }
    assert!(!vars.pop_frame());
    assert_eq!(vars.get(1, &sys, &s).expect("get"), Some(10.0));
}

#[test]
fn reset_and_persistent_variables() {
    let (mut vars, mut sys, s) = setup();
    vars.load_persistent(&[(500, 1.5), (999, -2.0)], &s)
        .expect("load");
    vars.set(100, Some(1.0), &mut sys, &s).expect("set");
    vars.set(1, Some(1.0), &mut sys, &s).expect("set");
    vars.set(600, Some(6.0), &mut sys, &s).expect("set");
    vars.push_frame([None; LOCAL_COUNT]).expect("push");
    vars.reset();
    assert_eq!(vars.depth(), 0);
    assert_eq!(vars.get(100, &sys, &s).expect("get"), None);
    assert_eq!(vars.get(1, &sys, &s).expect("get"), None);
    let kept: Vec<(u32, f64)> = vars.persistent().collect();
    assert_eq!(kept, [(500, 1.5), (600, 6.0), (999, -2.0)]);
    assert_eq!(
        vars.load_persistent(&[(499, 1.0)], &s).map_err(|e| e.kind),
        Err(K::UndefinedVariable)
    );
    assert_eq!(
        vars.load_persistent(&[(501, f64::NAN)], &s)
            .map_err(|e| e.kind),
        Err(K::Overflow)
    );
}

/// FANUC 30i-B's additional common variables: without the option
/// undefined; with it (its size N) the first N of `#100000`… (cleared at
/// reset) and of `#500000`… (kept), vacant until set.
#[test]
fn additional_common_variables_exist_as_the_option_sizes_them() {
    let (mut vars, mut sys, s) = setup();
    for n in [100_000, 500_000, 900_000] {
        assert_eq!(
            vars.get(n, &sys, &s).map_err(|e| e.kind),
            Err(K::UndefinedVariable)
        );
        assert_eq!(
            vars.set(n, Some(1.0), &mut sys, &s).map_err(|e| e.kind),
            Err(K::UndefinedVariable)
        );
    }
    let s = MacroSettings {
        additional_common: 401_250,
        ..s
    };
    // #900000 … #901249 are the last 1,250 of 401,250.
    assert_eq!(vars.get(901_249, &sys, &s).expect("exists"), None);
    assert_eq!(
        vars.get(901_250, &sys, &s).map_err(|e| e.kind),
        Err(K::UndefinedVariable)
    );
    // The volatile range holds at most 100,000.
    assert_eq!(vars.get(199_999, &sys, &s).expect("exists"), None);
    assert_eq!(
        vars.get(200_000, &sys, &s).map_err(|e| e.kind),
        Err(K::UndefinedVariable)
    );
    vars.set(100_000, Some(1.0), &mut sys, &s).expect("set");
    vars.set(900_000, Some(2.5), &mut sys, &s).expect("set");
    vars.set(500_001, Some(-1.0), &mut sys, &s).expect("set");
    vars.set(500_001, None, &mut sys, &s).expect("vacant again");
    vars.load_persistent(&[(901_000, 7.0)], &s).expect("load");
    vars.reset();
    assert_eq!(vars.get(100_000, &sys, &s).expect("get"), None);
    assert_eq!(vars.get(900_000, &sys, &s).expect("get"), Some(2.5));
    let kept: Vec<(u32, f64)> = vars.persistent().collect();
    assert_eq!(kept, [(900_000, 2.5), (901_000, 7.0)]);
    assert_eq!(
        vars.load_persistent(&[(100_000, 1.0)], &s)
            .map_err(|e| e.kind),
        Err(K::UndefinedVariable)
    );
}

#[test]
fn goto_targets() {
    let (mut vars, mut sys, s) = setup();
    vars.set(5, Some(20.4), &mut sys, &s).expect("set");
    let target = |text: &str, vars: &Variables, sys: &TestSystem| {
        let line = parse_statement(text.as_bytes(), 1).expect("parse");
        let Statement::Goto(e) = line.statement else {
            panic!()
        };
        vars.eval_sequence(&e, sys, &s)
    };
    assert_eq!(target("GOTO #5", &vars, &sys).expect("ok"), 20);
    assert_eq!(target("GOTO [#5+1]", &vars, &sys).expect("ok"), 21);
    let e = target("GOTO #6", &vars, &sys).expect_err("vacant");
    assert_eq!(e.kind, K::IllegalSequenceNumber);
    assert_eq!(e.fanuc_number(), 128);
    assert_eq!(e.span, Span::new(6, 8));
    assert_eq!(
        target("GOTO 100000", &vars, &sys).map_err(|e| e.kind),
        Err(K::IllegalSequenceNumber)
    );
}

#[test]
fn remaining_alarm_numbers() {
    assert_eq!(K::MissingEnd.fanuc_number(), 124);
    assert_eq!(K::IllegalArgumentAddress.fanuc_number(), 129);
    assert_eq!(K::CustomAlarm(u32::MAX).fanuc_number(), u16::MAX);
}
