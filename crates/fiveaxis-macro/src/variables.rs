//! The variable store: local variables per call level, common variables,
//! and the bridge to the controller's system variables.
//!
//! | numbers | kind | kept by |
//! | --- | --- | --- |
//! | `#0` | always vacant, cannot be written (PS0116) | — |
//! | `#1` … `#33` | local, one set per call level | [`Variables`] |
//! | `#100` … `#199` | common, cleared by [`Variables::reset`] | [`Variables`] |
//! | `#200` … `#499` | common, only with [`MacroSettings::extended_common`] | [`Variables`] |
//! | `#500` … `#999` | common, kept (a variables file) | [`Variables`] |
//! | `#1000` and up | system | the controller, through [`SystemVariables`] |
//!
//! Any other number (`#34` … `#99`, negative numbers, the extended range
//! when not enabled) is alarm PS0115. A computed number (`#[#1+1]`) is first
//! rounded to the nearest integer, half away from zero (FANUC rounds real
//! numbers that stand for integers, variable numbers included); a vacant
//! computed number is `#0`.

use std::collections::HashMap;

use fiveaxis_gcode::Span;

use crate::error::{MacroError, MacroErrorKind};
use crate::eval;
use crate::expr::{Expr, Value, Var, VarNumber};
use crate::settings::MacroSettings;

/// Number of local variables per call level (`#1` … `#33`).
pub const LOCAL_COUNT: usize = 33;
/// The first and last common variables kept in the store.
const COMMON: std::ops::RangeInclusive<u32> = 100..=499;
/// The common variables that exist without the extended option.
const COMMON_STANDARD: std::ops::RangeInclusive<u32> = 100..=199;
/// The common variables kept across resets (and power off).
const PERSISTENT: std::ops::RangeInclusive<u32> = 500..=999;
/// The first system variable.
const FIRST_SYSTEM: u32 = 1000;
/// The 30i's additional common variables (option "addition of custom
/// macro common variables"): cleared at reset like `#100`…, and kept like
/// `#500`… The option's size (`MacroSettings::additional_common`) says
/// how many of each range exist, from its first number.
pub const ADDITIONAL_VOLATILE: std::ops::RangeInclusive<u32> = 100_000..=199_999;
/// The kept range of the additional common variables.
pub const ADDITIONAL_KEPT: std::ops::RangeInclusive<u32> = 500_000..=999_999;
/// The highest `GOTO` target (five-digit sequence numbers).
const MAX_SEQUENCE: f64 = 99_999.0;

/// Why the controller refused a system variable access.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SystemVarError {
    /// No such system variable (alarm PS0115).
    #[error("not a variable number")]
    NotAVariable,
    /// The variable can only be read (alarm PS0116).
    #[error("read only")]
    ReadOnly,
    /// The write raised an alarm of its own: `#3000 = n` gives
    /// `Alarm(n)`, and the alarm text is the comment of the line.
    #[error("alarm {0}")]
    Alarm(u32),
}

/// The controller's system variables (`#1000` and up: interface signals,
/// `#3000` alarm, clocks, `#4001`… modal information, `#5001`… positions,
/// offsets …). The macro layer stores none of them.
pub trait SystemVariables {
    /// The value of system variable `number` (vacant is `None`).
    ///
    /// # Errors
    ///
    /// [`SystemVarError::NotAVariable`] when there is no such variable.
    fn read(&self, number: u32) -> Result<Option<f64>, SystemVarError>;

    /// Writes system variable `number`.
    ///
    /// # Errors
    ///
    /// [`SystemVarError::NotAVariable`], [`SystemVarError::ReadOnly`], or
    /// [`SystemVarError::Alarm`] for a write that raises an alarm (`#3000`).
    fn write(&mut self, number: u32, value: Option<f64>) -> Result<(), SystemVarError>;

    /// The value of a predefined named parameter of LinuxCNC (`_x`,
    /// `_motion_mode`, `_ini[section]name` …; `name` lower case without
    /// the `#<` `>`). Default: none exist.
    ///
    /// # Errors
    ///
    /// [`SystemVarError::NotAVariable`] when the controller has no such
    /// parameter (the program's own globals are then looked up).
    fn read_named(&self, _name: &str) -> Result<f64, SystemVarError> {
        Err(SystemVarError::NotAVariable)
    }
}

/// A controller without system variables: every access is PS0115.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoSystemVariables;

impl SystemVariables for NoSystemVariables {
    fn read(&self, _number: u32) -> Result<Option<f64>, SystemVarError> {
        Err(SystemVarError::NotAVariable)
    }

    fn write(&mut self, _number: u32, _value: Option<f64>) -> Result<(), SystemVarError> {
        Err(SystemVarError::NotAVariable)
    }
}

/// The macro variables of one path: local variables per call level and
/// common variables.
#[derive(Clone, Debug)]
pub struct Variables {
    /// Local variables; `frames[0]` is the main program's level.
    frames: Vec<[Option<f64>; LOCAL_COUNT]>,
    /// How many calls may be nested.
    max_depth: usize,
    /// `#100` … `#499`.
    common: Vec<Option<f64>>,
    /// `#500` … `#999`.
    persistent: Vec<Option<f64>>,
    /// The additional common variables that are set (`#100000`… and
    /// `#500000`…): few of a range of up to 600,000 are used.
    additional: HashMap<u32, f64>,
    /// LinuxCNC's parameters (empty unless made by [`Variables::linuxcnc`]).
    ngc: NgcParams,
}

/// LinuxCNC's parameters: numbered `#1` … `#5602` (0 until set), named
/// globals `#<_name>`, named locals per call level, and the caller's
/// `#1` … `#30` saved per call.
#[derive(Clone, Debug, Default)]
struct NgcParams {
    numbered: Vec<f64>,
    globals: HashMap<Box<str>, f64>,
    /// Named locals; `locals[0]` is the main program's level.
    locals: Vec<HashMap<Box<str>, f64>>,
    /// `#1` … `#30` of each caller, innermost last.
    saved: Vec<[f64; NGC_CALL_ARGS]>,
}

/// LinuxCNC's highest numbered parameter (overview: "currently 5602").
pub const NGC_MAX_PARAMETER: u32 = 5602;
/// LinuxCNC's `#5599`: whether `(DEBUG, …)` comments are shown.
const NGC_DEBUG_FLAG: usize = 5599;
/// Parameters a LinuxCNC `call` passes: `#1` … `#30`.
pub const NGC_CALL_ARGS: usize = 30;
/// LinuxCNC's numbered parameters from this one on are the controller's
/// (positions, offsets, tool data); those it does not answer are stored.
const NGC_FIRST_SYSTEM: u32 = 5001;

/// Whether `n` is one of the additional common variables the option has:
/// the first `additional_common` of `#100000`… (at most 100,000) and of
/// `#500000`… (at most 500,000).
fn additional_exists(n: u32, settings: &MacroSettings) -> bool {
    let size = settings.additional_common;
    (ADDITIONAL_VOLATILE.contains(&n) && n - ADDITIONAL_VOLATILE.start() < size)
        || (ADDITIONAL_KEPT.contains(&n) && n - ADDITIONAL_KEPT.start() < size)
}

/// The message for a variable that does not exist.
fn undefined(number: impl std::fmt::Display, span: Span) -> MacroError {
    MacroError::new(
        MacroErrorKind::UndefinedVariable,
        span,
        format!("variable #{number} does not exist"),
    )
}

fn range_len(range: &std::ops::RangeInclusive<u32>) -> usize {
    (range.end() - range.start() + 1) as usize
}

impl Variables {
    /// An empty store: every variable vacant, at the main program's level.
    /// `max_call_depth` is how many macro calls may be nested (FANUC: 4
    /// for G65/G66 on the 16i, 5 on the 30i).
    pub fn new(max_call_depth: usize) -> Self {
        let mut frames = Vec::with_capacity(max_call_depth.saturating_add(1).min(64));
        frames.push([None; LOCAL_COUNT]);
        Self {
            frames,
            max_depth: max_call_depth,
            common: vec![None; range_len(&COMMON)],
            persistent: vec![None; range_len(&PERSISTENT)],
            additional: HashMap::new(),
            ngc: NgcParams::default(),
        }
    }

    /// LinuxCNC's parameters: numbered `#1` … `#5602` all 0 (`#5599`, the
    /// DEBUG switch, 1), no named
    /// ones, at the main program's level; `max_call_depth` calls may nest
    /// (LinuxCNC: 10). Use with [`MacroSettings::LINUXCNC`].
    pub fn linuxcnc(max_call_depth: usize) -> Self {
        let mut vars = Self::new(max_call_depth);
        let mut numbered = vec![0.0; NGC_MAX_PARAMETER as usize + 1];
        // #5599: DEBUG comments shown (overview.adoc: "default=1").
        if let Some(debug) = numbered.get_mut(NGC_DEBUG_FLAG) {
            *debug = 1.0;
        }
        vars.ngc = NgcParams {
            numbered,
            globals: HashMap::new(),
            locals: vec![HashMap::new()],
            saved: Vec::new(),
        };
        vars
    }

    /// LinuxCNC `call`: the caller's `#1` … `#30` are saved, `args` go
    /// into `#1` … (the rest keep the caller's values), and a new level of
    /// named locals starts.
    ///
    /// # Errors
    ///
    /// [`MacroErrorKind::CallNesting`] past the depth given to
    /// [`Variables::linuxcnc`] (span empty), or more than 30 arguments.
    pub fn ngc_call(&mut self, args: &[f64]) -> Result<(), MacroError> {
        if self.ngc.saved.len() >= self.max_depth {
            return Err(MacroError::new(
                MacroErrorKind::CallNesting,
                Span::default(),
                format!(
                    "subroutine calls nested deeper than {} levels",
                    self.max_depth
                ),
            ));
        }
        if args.len() > NGC_CALL_ARGS {
            return Err(MacroError::new(
                MacroErrorKind::FormatError,
                Span::default(),
                format!(
                    "{} arguments in a call: at most {NGC_CALL_ARGS}",
                    args.len()
                ),
            ));
        }
        let mut saved = [0.0; NGC_CALL_ARGS];
        if let Some(own) = self.ngc.numbered.get(1..=NGC_CALL_ARGS) {
            saved.copy_from_slice(own);
        }
        self.ngc.saved.push(saved);
        for (slot, value) in self.ngc.numbered.iter_mut().skip(1).zip(args) {
            *slot = *value;
        }
        self.ngc.locals.push(HashMap::new());
        Ok(())
    }

    /// LinuxCNC `endsub`/`return`: the caller's `#1` … `#30` come back and
    /// the level's named locals vanish. `false` at the main level.
    pub fn ngc_return(&mut self) -> bool {
        let Some(saved) = self.ngc.saved.pop() else {
            return false;
        };
        if let Some(own) = self.ngc.numbered.get_mut(1..=NGC_CALL_ARGS) {
            own.copy_from_slice(&saved);
        }
        if self.ngc.locals.len() > 1 {
            self.ngc.locals.pop();
        }
        true
    }

    /// LinuxCNC: how many calls are open (`#<_call_level>`).
    pub fn ngc_depth(&self) -> usize {
        self.ngc.saved.len()
    }

    /// LinuxCNC: back to the main level (program end), keeping numbered
    /// parameters and globals, as LinuxCNC keeps them for the next run.
    pub fn ngc_reset(&mut self) {
        while self.ngc_return() {}
    }

    /// Reads named parameter `name` (lower case, no blanks): a predefined
    /// one from the controller, a global, or a local of this level.
    ///
    /// # Errors
    ///
    /// [`MacroErrorKind::UndefinedVariable`] when it was never set.
    pub fn read_named(
        &self,
        name: &str,
        span: Span,
        sys: &dyn SystemVariables,
    ) -> Result<f64, MacroError> {
        let value = if name.starts_with('_') {
            match sys.read_named(name) {
                Ok(v) => Some(v),
                Err(_) => self.ngc.globals.get(name).copied(),
            }
        } else {
            self.ngc.locals.last().and_then(|l| l.get(name)).copied()
        };
        value.ok_or_else(|| {
            MacroError::new(
                MacroErrorKind::UndefinedVariable,
                span,
                format!("named parameter #<{name}> is not defined"),
            )
        })
    }

    /// Whether named parameter `name` exists (`EXISTS[#<name>]`).
    pub fn named_exists(&self, name: &str, sys: &dyn SystemVariables) -> bool {
        self.read_named(name, Span::default(), sys).is_ok()
    }

    /// Writes named parameter `name`: a global when it starts with `_`,
    /// else a local of this call level; it springs into existence.
    ///
    /// # Errors
    ///
    /// [`MacroErrorKind::WriteProtected`] for a predefined (read-only)
    /// parameter, [`MacroErrorKind::Overflow`] for a value not finite.
    pub fn write_named(
        &mut self,
        name: &str,
        value: f64,
        span: Span,
        sys: &dyn SystemVariables,
    ) -> Result<(), MacroError> {
        if !value.is_finite() {
            return Err(MacroError::new(
                MacroErrorKind::Overflow,
                span,
                format!("#<{name}>: the value is too large"),
            ));
        }
        if name.starts_with('_') {
            if sys.read_named(name).is_ok() {
                return Err(MacroError::new(
                    MacroErrorKind::WriteProtected,
                    span,
                    format!("#<{name}> is a predefined parameter and can only be read"),
                ));
            }
            match self.ngc.globals.get_mut(name) {
                Some(slot) => *slot = value,
                None => {
                    self.ngc.globals.insert(name.into(), value);
                }
            }
        } else if let Some(level) = self.ngc.locals.last_mut() {
            match level.get_mut(name) {
                Some(slot) => *slot = value,
                None => {
                    level.insert(name.into(), value);
                }
            }
        }
        Ok(())
    }

    /// Sets a predefined-looking global the runner keeps itself
    /// (`_value`, `_value_returned`), bypassing the read-only check.
    pub fn set_global(&mut self, name: &str, value: f64) {
        match self.ngc.globals.get_mut(name) {
            Some(slot) => *slot = value,
            None => {
                self.ngc.globals.insert(name.into(), value);
            }
        }
    }

    /// The number of a numbered variable reference (`#n`, `#[e]`),
    /// computed and rounded; a named one is
    /// [`MacroErrorKind::FormatError`].
    ///
    /// # Errors
    ///
    /// As [`Variables::eval`].
    pub fn resolve_number(
        &self,
        var: &Var,
        sys: &dyn SystemVariables,
        settings: &MacroSettings,
    ) -> Result<u32, MacroError> {
        self.resolve(var, sys, settings)
    }

    /// How many calls are nested now (0 in the main program).
    pub fn depth(&self) -> usize {
        self.frames.len().saturating_sub(1)
    }

    /// Enters a macro call: a new set of local variables holding `args`
    /// (see [`crate::arguments`]).
    ///
    /// # Errors
    ///
    /// PS0122 when the call would nest deeper than the maximum given to
    /// [`Variables::new`]; its span is empty (the runner knows the call's).
    pub fn push_frame(&mut self, args: [Option<f64>; LOCAL_COUNT]) -> Result<(), MacroError> {
        if self.depth() >= self.max_depth {
            return Err(MacroError::new(
                MacroErrorKind::CallNesting,
                Span::default(),
                format!("macro calls nested deeper than {} levels", self.max_depth),
            ));
        }
        self.frames.push(args);
        Ok(())
    }

    /// Leaves a macro call: its local variables are dropped. Returns
    /// `false` (and changes nothing) at the main program's level.
    pub fn pop_frame(&mut self) -> bool {
        if self.frames.len() > 1 {
            self.frames.pop();
            true
        } else {
            false
        }
    }

    /// Reset: back to the main program's level with vacant local variables,
    /// and `#100` … `#499` vacant. `#500` … `#999` are kept.
    pub fn reset(&mut self) {
        self.frames.truncate(1);
        if let Some(main) = self.frames.first_mut() {
            *main = [None; LOCAL_COUNT];
        }
        self.common.fill(None);
        self.additional
            .retain(|n, _| !ADDITIONAL_VOLATILE.contains(n));
    }

    /// Loads kept common variables from a variables file: `#500` …
    /// `#999`, and of the additional ones those of `#500000` … the option
    /// has (`settings.additional_common`).
    ///
    /// # Errors
    ///
    /// PS0115 for a number outside them, PS0111 for a value that is not
    /// finite; the values before it are loaded.
    pub fn load_persistent(
        &mut self,
        values: &[(u32, f64)],
        settings: &MacroSettings,
    ) -> Result<(), MacroError> {
        for &(number, value) in values {
            if !value.is_finite() {
                return Err(MacroError::new(
                    MacroErrorKind::Overflow,
                    Span::default(),
                    format!("#{number}: the value is not a finite number"),
                ));
            }
            if additional_exists(number, settings) && ADDITIONAL_KEPT.contains(&number) {
                self.additional.insert(number, value);
                continue;
            }
            let slot = number
                .checked_sub(*PERSISTENT.start())
                .filter(|_| PERSISTENT.contains(&number))
                .and_then(|i| self.persistent.get_mut(i as usize))
                .ok_or_else(|| undefined(number, Span::default()))?;
            *slot = Some(value);
        }
        Ok(())
    }

    /// The kept common variables that are set (`#500` … `#999`, then the
    /// additional `#500000` …), in order, for the CLI to save.
    pub fn persistent(&self) -> impl Iterator<Item = (u32, f64)> + '_ {
        let mut kept: Vec<(u32, f64)> = self
            .additional
            .iter()
            .filter(|(n, _)| ADDITIONAL_KEPT.contains(n))
            .map(|(&n, &v)| (n, v))
            .collect();
        kept.sort_by_key(|&(n, _)| n);
        (*PERSISTENT.start()..)
            .zip(&self.persistent)
            .filter_map(|(n, v)| Some((n, (*v)?)))
            .chain(kept)
    }

    /// Reads variable `number` (vacant is `None`).
    ///
    /// # Errors
    ///
    /// PS0115 for a number that does not exist.
    pub fn get(
        &self,
        number: u32,
        sys: &dyn SystemVariables,
        settings: &MacroSettings,
    ) -> Result<Option<f64>, MacroError> {
        self.read(number, Span::default(), sys, settings)
    }

    /// Writes variable `number`.
    ///
    /// # Errors
    ///
    /// PS0115 for a number that does not exist, PS0116 for `#0` and
    /// read-only system variables, PS0111 for a value that is not finite,
    /// the controller's alarm for a system variable.
    pub fn set(
        &mut self,
        number: u32,
        value: Option<f64>,
        sys: &mut dyn SystemVariables,
        settings: &MacroSettings,
    ) -> Result<(), MacroError> {
        self.write(number, value, Span::default(), None, sys, settings)
    }

    /// Evaluates an expression. Allocates nothing unless it fails.
    ///
    /// # Errors
    ///
    /// The alarm of the first operation that fails: undefined variable
    /// (PS0115), division by zero (PS0112), argument out of range (PS0119),
    /// overflow (PS0111), or the controller's refusal to read a system
    /// variable.
    pub fn eval(
        &self,
        expr: &Expr,
        sys: &dyn SystemVariables,
        settings: &MacroSettings,
    ) -> Result<Value, MacroError> {
        eval::eval(self, expr, sys, settings)
    }

    /// Evaluates an expression that must give a number or vacant.
    ///
    /// # Errors
    ///
    /// As [`Variables::eval`], and PS0114 for a truth value.
    pub fn eval_number(
        &self,
        expr: &Expr,
        sys: &dyn SystemVariables,
        settings: &MacroSettings,
    ) -> Result<Option<f64>, MacroError> {
        match self.eval(expr, sys, settings)? {
            Value::Bool(_) => Err(MacroError::new(
                MacroErrorKind::FormatError,
                expr_span(expr),
                "a comparison where a value is needed",
            )),
            value => Ok(value.number()),
        }
    }

    /// Evaluates the condition of `IF` or `WHILE`.
    ///
    /// # Errors
    ///
    /// As [`Variables::eval`], and PS0114 when the expression is not a
    /// comparison.
    pub fn eval_condition(
        &self,
        expr: &Expr,
        sys: &dyn SystemVariables,
        settings: &MacroSettings,
    ) -> Result<bool, MacroError> {
        match self.eval(expr, sys, settings)? {
            Value::Bool(b) => Ok(b),
            _ => Err(MacroError::new(
                MacroErrorKind::FormatError,
                expr_span(expr),
                "the condition is not a comparison",
            )),
        }
    }

    /// Evaluates the target of `GOTO`: a sequence number 1 … 99999 (the
    /// value rounded to an integer).
    ///
    /// # Errors
    ///
    /// As [`Variables::eval`], and PS0128 for a vacant value or a number
    /// outside 1 … 99999.
    pub fn eval_sequence(
        &self,
        expr: &Expr,
        sys: &dyn SystemVariables,
        settings: &MacroSettings,
    ) -> Result<u32, MacroError> {
        let value = self.eval_number(expr, sys, settings)?;
        match value.map(f64::round) {
            // In 1 ..= 99999 and integral: the cast is exact.
            Some(n) if (1.0..=MAX_SEQUENCE).contains(&n) => Ok(n as u32),
            _ => Err(MacroError::new(
                MacroErrorKind::IllegalSequenceNumber,
                expr_span(expr),
                format!(
                    "`{expr}` gives {}, not a sequence number (1 to 99999)",
                    value.map_or_else(|| "vacant".to_owned(), |v| v.to_string())
                ),
            )),
        }
    }

    /// Executes `target = value`; `comment` is the comment of the line,
    /// the message of a `#3000` alarm.
    ///
    /// # Errors
    ///
    /// The alarms of [`Variables::eval`] and [`Variables::set`]; a
    /// [`SystemVarError::Alarm`] becomes [`MacroErrorKind::CustomAlarm`]
    /// with the comment as its message.
    pub fn assign(
        &mut self,
        target: &Var,
        value: &Expr,
        comment: Option<&str>,
        sys: &mut dyn SystemVariables,
        settings: &MacroSettings,
    ) -> Result<(), MacroError> {
        let number = self.resolve(target, sys, settings)?;
        let value = self.eval_number(value, sys, settings)?;
        self.write(number, value, target.span, comment, sys, settings)
    }

    /// The number of a variable reference, computed and rounded.
    pub(crate) fn resolve(
        &self,
        var: &Var,
        sys: &dyn SystemVariables,
        settings: &MacroSettings,
    ) -> Result<u32, MacroError> {
        match &var.number {
            VarNumber::Direct(n) => Ok(*n),
            VarNumber::Named(name) => Err(MacroError::new(
                MacroErrorKind::FormatError,
                var.span,
                format!("#<{name}> is a named parameter, not a number"),
            )),
            VarNumber::Indirect(e) => {
                let number = self.eval_number(e, sys, settings)?.unwrap_or(0.0).round() + 0.0;
                if (0.0..=f64::from(u32::MAX)).contains(&number) {
                    // In range and integral: the cast is exact.
                    Ok(number as u32)
                } else {
                    Err(undefined(number, var.span))
                }
            }
        }
    }

    /// Reads variable `number`; `span` is the reference's.
    pub(crate) fn read(
        &self,
        number: u32,
        span: Span,
        sys: &dyn SystemVariables,
        settings: &MacroSettings,
    ) -> Result<Option<f64>, MacroError> {
        if settings.linuxcnc {
            return self.ngc_read(number, span, sys).map(Some);
        }
        match number {
            0 => Ok(None),
            1..=33 => Ok(self
                .frames
                .last()
                .and_then(|f| f.get(number as usize - 1))
                .copied()
                .flatten()),
            n if COMMON.contains(&n) => {
                if !settings.extended_common && !COMMON_STANDARD.contains(&n) {
                    return Err(undefined(n, span));
                }
                Ok(self
                    .common
                    .get((n - COMMON.start()) as usize)
                    .copied()
                    .flatten())
            }
            n if PERSISTENT.contains(&n) => Ok(self
                .persistent
                .get((n - PERSISTENT.start()) as usize)
                .copied()
                .flatten()),
            n if additional_exists(n, settings) => Ok(self.additional.get(&n).copied()),
            n if n >= FIRST_SYSTEM => sys.read(n).map_err(|e| system_error(e, n, span, None)),
            n => Err(undefined(n, span)),
        }
    }

    /// Writes variable `number`; `span` is the reference's.
    pub(crate) fn write(
        &mut self,
        number: u32,
        value: Option<f64>,
        span: Span,
        comment: Option<&str>,
        sys: &mut dyn SystemVariables,
        settings: &MacroSettings,
    ) -> Result<(), MacroError> {
        if value.is_some_and(|v| !v.is_finite()) {
            return Err(MacroError::new(
                MacroErrorKind::Overflow,
                span,
                format!("#{number}: the value is too large"),
            ));
        }
        if settings.linuxcnc {
            return self.ngc_write(number, value.unwrap_or(0.0), span, sys);
        }
        let slot = match number {
            0 => {
                return Err(MacroError::new(
                    MacroErrorKind::WriteProtected,
                    span,
                    "variable #0 is always vacant and cannot be written",
                ));
            }
            1..=33 => self
                .frames
                .last_mut()
                .and_then(|f| f.get_mut(number as usize - 1)),
            n if COMMON.contains(&n) => {
                if !settings.extended_common && !COMMON_STANDARD.contains(&n) {
                    return Err(undefined(n, span));
                }
                self.common.get_mut((n - COMMON.start()) as usize)
            }
            n if PERSISTENT.contains(&n) => {
                self.persistent.get_mut((n - PERSISTENT.start()) as usize)
            }
            n if additional_exists(n, settings) => {
                match value {
                    Some(v) => self.additional.insert(n, v),
                    None => self.additional.remove(&n),
                };
                return Ok(());
            }
            n if n >= FIRST_SYSTEM => {
                return sys
                    .write(n, value)
                    .map_err(|e| system_error(e, n, span, comment));
            }
            n => return Err(undefined(n, span)),
        };
        match slot {
            Some(slot) => {
                *slot = value;
                Ok(())
            }
            None => Err(undefined(number, span)),
        }
    }
}

impl Variables {
    fn ngc_out_of_range(number: u32, span: Span) -> MacroError {
        MacroError::new(
            MacroErrorKind::UndefinedVariable,
            span,
            format!("parameter number #{number} is out of range 1 to {NGC_MAX_PARAMETER}"),
        )
    }

    /// LinuxCNC numbered parameter `number`: the controller's from #5001
    /// on when it answers, otherwise the stored value (0 until set).
    fn ngc_read(
        &self,
        number: u32,
        span: Span,
        sys: &dyn SystemVariables,
    ) -> Result<f64, MacroError> {
        if number == 0 || number > NGC_MAX_PARAMETER {
            return Err(Self::ngc_out_of_range(number, span));
        }
        if number >= NGC_FIRST_SYSTEM
            && let Ok(Some(v)) = sys.read(number)
        {
            return Ok(v);
        }
        Ok(self
            .ngc
            .numbered
            .get(number as usize)
            .copied()
            .unwrap_or(0.0))
    }

    /// Writes LinuxCNC numbered parameter `number` (the controller's
    /// first, from #5001 on: a work offset changes the offset memory).
    fn ngc_write(
        &mut self,
        number: u32,
        value: f64,
        span: Span,
        sys: &mut dyn SystemVariables,
    ) -> Result<(), MacroError> {
        if number == 0 || number > NGC_MAX_PARAMETER {
            return Err(Self::ngc_out_of_range(number, span));
        }
        if number >= NGC_FIRST_SYSTEM {
            match sys.write(number, Some(value)) {
                Ok(()) | Err(SystemVarError::NotAVariable) => {}
                Err(e) => return Err(system_error(e, number, span, None)),
            }
        }
        match self.ngc.numbered.get_mut(number as usize) {
            Some(slot) => {
                *slot = value;
                Ok(())
            }
            None => Err(Self::ngc_out_of_range(number, span)),
        }
    }
}

/// The alarm for a refused system variable access.
fn system_error(
    error: SystemVarError,
    number: u32,
    span: Span,
    comment: Option<&str>,
) -> MacroError {
    match error {
        SystemVarError::NotAVariable => undefined(number, span),
        SystemVarError::ReadOnly => MacroError::new(
            MacroErrorKind::WriteProtected,
            span,
            format!("variable #{number} can only be read"),
        ),
        SystemVarError::Alarm(n) => MacroError::new(
            MacroErrorKind::CustomAlarm(n),
            span,
            match comment {
                Some(text) if !text.is_empty() => text.to_owned(),
                _ => format!("alarm {n} raised by #{number}"),
            },
        ),
    }
}

/// The columns of an expression, where the tree keeps them.
pub(crate) fn expr_span(expr: &Expr) -> Span {
    match expr {
        Expr::Var(v) => v.span,
        Expr::Binary(b) => b.span,
        Expr::Call(c) => c.span,
        Expr::Neg(e) => expr_span(e),
        Expr::Number(_) => Span::default(),
    }
}
