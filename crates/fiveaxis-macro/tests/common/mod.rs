//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::collections::HashMap;

use fiveaxis_macro::{
    MacroError, MacroErrorKind, MacroSettings, Statement, SystemVarError, SystemVariables,
    Variables, parse_statement,
};

/// A controller with a few system variables: #1000–#1999 read-only
/// interface signals, #3000 raising alarms, #5001–#5999 writable.
#[derive(Debug, Default)]
pub struct TestSystem {
    pub values: HashMap<u32, Option<f64>>,
}

impl SystemVariables for TestSystem {
    fn read(&self, number: u32) -> Result<Option<f64>, SystemVarError> {
        match number {
            1000..=1999 | 5001..=5999 => Ok(self.values.get(&number).copied().flatten()),
            _ => Err(SystemVarError::NotAVariable),
        }
    }

    fn write(&mut self, number: u32, value: Option<f64>) -> Result<(), SystemVarError> {
        match number {
            1000..=1999 => Err(SystemVarError::ReadOnly),
            3000 => Err(SystemVarError::Alarm(value.unwrap_or(0.0) as u32)),
            5001..=5999 => {
                self.values.insert(number, value);
                Ok(())
            }
            _ => Err(SystemVarError::NotAVariable),
        }
    }
}

/// Executes one assignment line (`#n = e` or `IF […] THEN #n = e`).
pub fn exec(
    vars: &mut Variables,
    sys: &mut TestSystem,
    settings: &MacroSettings,
    text: &str,
) -> Result<(), MacroError> {
    let line = parse_statement(text.as_bytes(), 1)?;
    match &line.statement {
        Statement::Assign { target, value } => {
            vars.assign(target, value, line.comment.as_deref(), sys, settings)
        }
        Statement::IfThen {
            cond,
            target,
            value,
        } => {
            if vars.eval_condition(cond, sys, settings)? {
                vars.assign(target, value, line.comment.as_deref(), sys, settings)?;
            }
            Ok(())
        }
        other => panic!("not an assignment: {other:?}"),
    }
}

/// Evaluates `expr` with default settings and the given variables set
/// first, through `#100 = expr`.
pub fn eval_with(
    setup: &[(u32, Option<f64>)],
    expr: &str,
    settings: &MacroSettings,
) -> Result<Option<f64>, MacroError> {
    let mut vars = Variables::new(4);
    let mut sys = TestSystem::default();
    for &(n, v) in setup {
        vars.set(n, v, &mut sys, settings).expect("setup");
    }
    exec(&mut vars, &mut sys, settings, &format!("#100={expr}"))?;
    vars.get(100, &sys, settings)
}

/// `expr` evaluated with default settings.
pub fn eval(expr: &str) -> Result<Option<f64>, MacroError> {
    eval_with(&[], expr, &MacroSettings::default())
}

/// The number `expr` gives; panics on an alarm or vacant.
pub fn num(expr: &str) -> f64 {
    match eval(expr) {
        Ok(Some(x)) => x,
        other => panic!("{expr}: {other:?}"),
    }
}

/// The alarm kind `expr` gives.
pub fn alarm(expr: &str) -> MacroErrorKind {
    match eval(expr) {
        Err(e) => e.kind,
        Ok(v) => panic!("{expr}: no alarm, got {v:?}"),
    }
}

pub fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0)
}
