//! Custom macro B in the runner: where the program text is, the control
//! flow of macro statements (`GOTO`, `IF`, `WHILE … DO … END`, `G65`
//! calls) is carried out; expressions, variables and their alarms are
//! `fiveaxis-macro`'s.
//!
//! A line goes through the macro layer only when it holds macro syntax
//! (`#`, `[ ]` or a macro keyword, [`fiveaxis_macro::is_macro_line`]);
//! plain lines keep the front end's fast path. An NC block with
//! expressions is evaluated into an ordinary [`fiveaxis_gcode::Block`]
//! and executed like any other.

use fiveaxis_gcode::{Code, Span};
use std::collections::HashMap;
use std::sync::Arc;

use fiveaxis_macro::{
    LOCAL_COUNT, Line, MacroError, MacroErrorKind, MacroSettings, Statement, SystemVarError,
    SystemVariables, Variables, evaluate_block, parse_statement,
};

use super::{Mark, RunError, Runner, Source};
use crate::alarm::{Alarm, AlarmCode, Condition};
use crate::controller::{Controller, SystemVarFault};

/// Macro state of a run: the variables and the open loops.
#[derive(Debug)]
pub(super) struct MacroState {
    pub(super) vars: Variables,
    pub(super) settings: MacroSettings,
    /// Open `WHILE … DO m` / `DO m` loops, innermost last.
    pub(super) loops: Vec<Loop>,
    /// Macro lines parsed before, by their offset in the program: a loop
    /// parses its lines once. Bounded: cleared when full.
    cache: HashMap<u64, Arc<Line>>,
    /// Interface signal inputs `#1000`–`#1035` (the variables file may set
    /// them; otherwise 0).
    pub(super) inputs: [f64; INPUTS],
    /// The `G66` modal call in force.
    modal_call: Option<MacroCall>,
    /// The control has structured IF (`Dialect::structured_if`).
    structured_if: bool,
}

/// Addresses whose values are lengths or angles: as macro arguments
/// without a decimal point they count in least input increments.
const DIMENSION_ADDRESSES: &[u8] = b"ABCIJKQRUVWXYZ";

/// A macro call: program, repetitions and the local variables it starts
/// with.
#[derive(Clone, Copy, Debug)]
struct MacroCall {
    program: u32,
    repeats: u32,
    args: [Option<f64>; LOCAL_COUNT],
}

/// Interface signal inputs `#1000`–`#1035`.
const INPUTS: usize = 36;

/// Most parsed macro lines kept.
const CACHE_LINES: usize = 4096;

/// An open loop: its number, its `WHILE` (or `DO`) line and the call
/// level it belongs to.
#[derive(Clone, Copy, Debug)]
pub(super) struct Loop {
    id: u8,
    start: Mark,
    pub(super) level: usize,
}

impl MacroState {
    /// LinuxCNC's parameters and evaluation rules.
    pub(super) fn linuxcnc(max_calls: usize) -> Self {
        Self {
            vars: Variables::linuxcnc(max_calls),
            settings: MacroSettings::LINUXCNC,
            ..Self::new(max_calls, 0, false)
        }
    }

    pub(super) fn new(max_nesting: usize, additional_common: u32, structured_if: bool) -> Self {
        Self {
            structured_if,
            vars: Variables::new(max_nesting),
            settings: MacroSettings {
                additional_common,
                ..MacroSettings::default()
            },
            loops: Vec::new(),
            cache: HashMap::new(),
            inputs: [0.0; INPUTS],
            modal_call: None,
        }
    }
}

/// What a macro line left for the runner.
pub(super) enum MacroFlow {
    /// Nothing more to do for this line.
    Done,
    /// The line was an NC block, now in `Runner::block`: execute it.
    Block,
}

/// The system variables the kernel answers (`#1000` and up): the
/// controller's (tool and work offsets, modal information, positions:
/// `controller/system_vars.rs`), and here the ones nothing outside the
/// program sets: interface signal inputs `#1000`–`#1035`, clocks
/// `#3001`/`#3002` and part counts `#3901`/`#3902` read 0 (writes are
/// taken); `#3000 = n` stops with the program's alarm 3000 + n. Any other
/// number is the undefined-variable alarm naming it.
pub(super) struct System<'c, 'm> {
    controller: &'c mut Controller<'m>,
    inputs: &'c [f64; INPUTS],
    /// `#4012` / `#4212`: 66 while a `G66` modal call is in force.
    modal_call: bool,
    /// `#4115` / `#4315`: the number of the program running, if it has one.
    program: Option<u32>,
}

impl std::fmt::Debug for System<'_, '_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("System")
    }
}

impl SystemVariables for System<'_, '_> {
    fn read(&self, number: u32) -> Result<Option<f64>, SystemVarError> {
        match number {
            1000..=1035 => Ok(self.inputs.get((number - 1000) as usize).copied()),
            3001 | 3002 | 3901 | 3902 => Ok(Some(0.0)),
            4012 | 4212 if self.modal_call => Ok(Some(66.0)),
            4115 | 4315 => Ok(self.program.map(f64::from)),
            _ => self.controller.read_system_variable(number).map_err(fault),
        }
    }

    fn write(&mut self, number: u32, value: Option<f64>) -> Result<(), SystemVarError> {
        match number {
            3000 => {
                let n = value.unwrap_or(0.0).round();
                Err(SystemVarError::Alarm(if (0.0..=999.0).contains(&n) {
                    n as u32
                } else {
                    0
                }))
            }
            3001 | 3002 | 3901 | 3902 | 1100..=1135 => Ok(()),
            1000..=1035 => Err(SystemVarError::ReadOnly),
            _ => self
                .controller
                .write_system_variable(number, value)
                .map_err(fault),
        }
    }
}

fn fault(fault: SystemVarFault) -> SystemVarError {
    match fault {
        SystemVarFault::Unknown => SystemVarError::NotAVariable,
        SystemVarFault::ReadOnly => SystemVarError::ReadOnly,
    }
}

impl<S: Source> Runner<'_, S> {
    /// Carries out the macro statement of the line just read (`here`).
    pub(super) fn macro_line(&mut self, here: Mark) -> Result<MacroFlow, RunError> {
        let line = match self.macros.cache.get(&here.offset) {
            Some(line) => Arc::clone(line),
            None => {
                let line = match parse_statement(&self.text, here.line) {
                    Ok(line) => Arc::new(line),
                    Err(error) => return Err(self.macro_alarm(here.line, error)),
                };
                if self.macros.cache.len() >= CACHE_LINES {
                    self.macros.cache.clear();
                }
                self.macros.cache.insert(here.offset, Arc::clone(&line));
                line
            }
        };
        self.macro_statement(here, &line)
    }

    /// Whether the line at `offset` is a macro line parsed before.
    pub(super) fn is_cached_macro_line(&self, offset: u64) -> bool {
        // Plain programs never fill the cache: no hashing per line.
        !self.macros.cache.is_empty() && self.macros.cache.contains_key(&offset)
    }

    fn macro_statement(&mut self, here: Mark, line: &Line) -> Result<MacroFlow, RunError> {
        if line.block_delete && self.options.block_delete {
            return Ok(MacroFlow::Done);
        }
        self.at_program_start = false;
        let program = self.program_number();
        let mut sys = System {
            controller: &mut self.controller,
            inputs: &self.macros.inputs,
            modal_call: self.macros.modal_call.is_some(),
            program,
        };
        let settings = self.macros.settings;
        let result: Result<MacroFlow, MacroError> = match &line.statement {
            Statement::Assign { target, .. }
                if matches!(target.number, fiveaxis_macro::VarNumber::Direct(3006)) =>
            {
                // #3006 = n (MESSAGE): the control stops and shows the
                // message until cycle start; a verification run goes on and
                // notes it.
                self.note(format!(
                    "line {}: #3006 stop: {}",
                    here.line,
                    line.comment.as_deref().unwrap_or("(no message)")
                ));
                Ok(MacroFlow::Done)
            }
            Statement::Assign { target, value } => self
                .macros
                .vars
                .assign(target, value, line.comment.as_deref(), &mut sys, &settings)
                .map(|()| MacroFlow::Done),
            Statement::IfThen {
                cond,
                target,
                value,
            } => match self.macros.vars.eval_condition(cond, &sys, &settings) {
                Ok(true) => self
                    .macros
                    .vars
                    .assign(target, value, line.comment.as_deref(), &mut sys, &settings)
                    .map(|()| MacroFlow::Done),
                Ok(false) => Ok(MacroFlow::Done),
                Err(e) => Err(e),
            },
            Statement::Goto(target) => {
                let n = match self.macros.vars.eval_sequence(target, &sys, &settings) {
                    Ok(n) => n,
                    Err(e) => return Err(self.macro_alarm(here.line, e)),
                };
                self.goto(n, here.line)?;
                return Ok(MacroFlow::Done);
            }
            Statement::IfGoto { cond, target } => {
                let jump = match self.macros.vars.eval_condition(cond, &sys, &settings) {
                    Ok(jump) => jump,
                    Err(e) => return Err(self.macro_alarm(here.line, e)),
                };
                if jump {
                    let n = match self.macros.vars.eval_sequence(target, &sys, &settings) {
                        Ok(n) => n,
                        Err(e) => return Err(self.macro_alarm(here.line, e)),
                    };
                    self.goto(n, here.line)?;
                }
                return Ok(MacroFlow::Done);
            }
            Statement::While { cond, id } => {
                let go_on = match self.macros.vars.eval_condition(cond, &sys, &settings) {
                    Ok(go_on) => go_on,
                    Err(e) => return Err(self.macro_alarm(here.line, e)),
                };
                if go_on {
                    self.open_loop(*id, here);
                } else {
                    self.close_loop(*id, here)?;
                }
                return Ok(MacroFlow::Done);
            }
            Statement::Do { id } => {
                self.open_loop(*id, here);
                return Ok(MacroFlow::Done);
            }
            Statement::IfBlock { .. } | Statement::Else | Statement::EndIf
                if !self.macros.structured_if =>
            {
                let word = match &line.statement {
                    Statement::IfBlock { .. } => "IF […] THEN without `#n = value` after it",
                    Statement::Else => "ELSE",
                    _ => "ENDIF",
                };
                return Err(self.macro_alarm(
                    here.line,
                    MacroError::new(
                        MacroErrorKind::FormatError,
                        Span::default(),
                        format!(
                            "{word}: structured IF (IF […] THEN, ELSE, ENDIF on lines of their own) is not a statement of this control"
                        ),
                    ),
                ));
            }
            Statement::IfBlock { cond } => {
                let holds = match self.macros.vars.eval_condition(cond, &sys, &settings) {
                    Ok(holds) => holds,
                    Err(e) => return Err(self.macro_alarm(here.line, e)),
                };
                if !holds {
                    self.skip_if_branch(here, true)?;
                }
                return Ok(MacroFlow::Done);
            }
            Statement::Else => {
                // The branch that ran ends here: on after its ENDIF.
                self.skip_if_branch(here, false)?;
                return Ok(MacroFlow::Done);
            }
            Statement::EndIf => return Ok(MacroFlow::Done),
            Statement::End { id } => {
                self.loop_back(*id, here.line)?;
                return Ok(MacroFlow::Done);
            }
            Statement::Nc(nc) => {
                evaluate_block(nc, &self.macros.vars, &sys, &settings, &mut self.block).map(|()| {
                    // The line's first comment (blanks trimmed) goes with
                    // the block, as the front end's does (Haas G47).
                    if let Some(comment) = &line.comment {
                        self.block.comment.extend_from_slice(comment.as_bytes());
                        let end = u32::try_from(self.text.len()).unwrap_or(u32::MAX);
                        self.block.comment_span = Some(Span::new(1, end.saturating_add(1)));
                    }
                    MacroFlow::Block
                })
            }
        };
        result.map_err(|e| self.macro_alarm(here.line, e))
    }

    /// The serial number Haas G47 P1 engraves next: kept common variable
    /// `#599` (`None` when vacant).
    pub(super) fn serial_number(&self) -> Option<f64> {
        self.macros
            .vars
            .persistent()
            .find(|&(number, _)| number == crate::controller::SERIAL_VARIABLE)
            .map(|(_, value)| value)
    }

    /// Writes `#599` after a G47 P1.
    pub(super) fn set_serial_number(&mut self, value: f64, line: u32) -> Result<(), RunError> {
        let number = crate::controller::SERIAL_VARIABLE;
        let settings = self.macros.settings;
        self.macros
            .vars
            .load_persistent(&[(number, value)], &settings)
            .map_err(|e| self.macro_alarm(line, e))
    }

    /// Sets variables before the run (a variables file): the kept common
    /// variables `#500`–`#999` (and the additional `#500000`… the machine's
    /// option has) and the interface signal inputs `#1000`–`#1035`. An
    /// error names the first number that is none of them.
    pub fn set_variables(&mut self, values: &[(u32, f64)]) -> Result<(), String> {
        let settings = self.macros.settings;
        let additional = settings.additional_common;
        for &(number, value) in values {
            if !value.is_finite() {
                return Err(format!("#{number}: {value} is not a finite number"));
            }
            match number {
                1000..=1035 => self.macros.inputs[(number - 1000) as usize] = value,
                500..=999 | 500_000..=999_999 => self
                    .macros
                    .vars
                    .load_persistent(&[(number, value)], &settings)
                    .map_err(|e| {
                        if additional == 0 && number >= 500_000 {
                            format!(
                                "{}: the machine has no additional common variables (parameter additional_common_variables)",
                                e.message
                            )
                        } else {
                            e.message
                        }
                    })?,
                _ => {
                    return Err(format!(
                        "#{number} cannot be set from a variables file: only #500-#999 and the machine's #500000-range (kept common variables) and #1000-#1035 (interface signals)"
                    ));
                }
            }
        }
        Ok(())
    }

    /// The kept common variables `#500`–`#999` that are not vacant, as
    /// the program left them (for writing the variables file back).
    pub fn kept_variables(&self) -> Vec<(u32, f64)> {
        self.macros.vars.persistent().collect()
    }

    /// `WHILE` true or `DO`: the loop is open (again, when `END` jumped
    /// back to it).
    fn open_loop(&mut self, id: u8, here: Mark) {
        let level = self.stack.len();
        let open = self
            .macros
            .loops
            .last()
            .is_some_and(|l| l.start == here && l.level == level);
        if !open {
            self.macros.loops.push(Loop {
                id,
                start: here,
                level,
            });
        }
    }

    /// `WHILE` false: the loop ends; the program goes on after its `END`.
    fn close_loop(&mut self, id: u8, here: Mark) -> Result<(), RunError> {
        let level = self.stack.len();
        if self
            .macros
            .loops
            .last()
            .is_some_and(|l| l.start == here && l.level == level)
        {
            self.macros.loops.pop();
        }
        let mut line = self.next_line;
        while let Some(_mark) = self.skip_line(&mut line, here.line)? {
            if fiveaxis_macro::loop_end(&self.scan_text) == Some(id) {
                self.next_line = line;
                return Ok(());
            }
            if super::program_number(&self.scan_text).is_some() {
                break;
            }
        }
        Err(self.macro_alarm(
            here.line,
            MacroError::new(
                MacroErrorKind::MissingEnd,
                Span::default(),
                format!("WHILE … DO{id} has no END{id} in its program"),
            ),
        ))
    }

    /// Structured IF: on after the `ELSE` (when `to_else`) or the `ENDIF`
    /// that matches the `IF […] THEN` or `ELSE` of line `here`, nested
    /// structured IFs skipped whole; every line read counts against the
    /// block budget.
    fn skip_if_branch(&mut self, here: Mark, to_else: bool) -> Result<(), RunError> {
        let mut depth = 0usize;
        let mut line = self.next_line;
        while let Some(mark) = self.skip_line(&mut line, here.line)? {
            if super::program_number(&self.scan_text).is_some() {
                break;
            }
            if !fiveaxis_macro::is_macro_line(&self.scan_text) {
                continue;
            }
            let Ok(parsed) = parse_statement(&self.scan_text, mark.line) else {
                continue;
            };
            match parsed.statement {
                Statement::IfBlock { .. } => depth += 1,
                Statement::EndIf if depth == 0 => {
                    self.next_line = line;
                    return Ok(());
                }
                Statement::EndIf => depth -= 1,
                Statement::Else if depth == 0 && to_else => {
                    self.next_line = line;
                    return Ok(());
                }
                _ => {}
            }
        }
        Err(self.macro_alarm(
            here.line,
            MacroError::new(
                MacroErrorKind::MissingEnd,
                Span::default(),
                "IF … THEN has no ENDIF in its program",
            ),
        ))
    }

    /// `END m`: back to the line that opened loop m.
    fn loop_back(&mut self, id: u8, line: u32) -> Result<(), RunError> {
        let level = self.stack.len();
        match self.macros.loops.last() {
            Some(open) if open.id == id && open.level == level => {
                let start = open.start;
                self.source.seek(start.offset)?;
                self.next_line = start.line;
                Ok(())
            }
            _ => Err(self.macro_alarm(
                line,
                MacroError::new(
                    MacroErrorKind::IllegalLoopNumber,
                    Span::default(),
                    format!("END{id} without an open DO{id}"),
                ),
            )),
        }
    }

    /// `GOTO n`: on at sequence number n of the program.
    fn goto(&mut self, n: u32, line: u32) -> Result<(), RunError> {
        let here = Mark {
            offset: self.source.position(),
            line: self.next_line,
        };
        match self.find_sequence(n, here, line)? {
            Some(mark) => {
                let at = self.at_program_start;
                self.source.seek(mark.offset)?;
                self.next_line = mark.line;
                self.at_program_start = at;
                // Loops opened after the target are left.
                let level = self.stack.len();
                self.macros
                    .loops
                    .retain(|l| l.level < level || l.start.offset < mark.offset);
                Ok(())
            }
            None => Err(self.macro_alarm(
                line,
                MacroError::new(
                    MacroErrorKind::IllegalSequenceNumber,
                    Span::default(),
                    format!("GOTO {n}: sequence number N{n} is not in the program"),
                ),
            )),
        }
    }

    /// A `G65 P… L…` block (a macro call with its arguments as local
    /// variables), a `G66 P… L…` block (the same call made modal: after
    /// every later block that moves an axis) or `G67` (the modal call
    /// cancelled). `None` when the block is none of these.
    pub(super) fn macro_call(&mut self, line: u32) -> Option<Result<(), RunError>> {
        // One pass for the plain block: no G65, G66 or G67 in it.
        if !self.block.words.iter().any(|w| {
            w.letter == b'G'
                && matches!(
                    w.code,
                    Some(Code {
                        major: 65..=67,
                        minor: 0
                    })
                )
        }) {
            return None;
        }
        let has = |block: &fiveaxis_gcode::Block, code: Code| {
            block
                .words
                .iter()
                .any(|w| w.letter == b'G' && w.code == Some(code))
        };
        if has(&self.block, Code::new(67, 0)) {
            self.macros.modal_call = None;
            self.block
                .words
                .retain(|w| !(w.letter == b'G' && w.code == Some(Code::new(67, 0))));
            if self.block.is_empty() {
                return Some(Ok(()));
            }
            return None;
        }
        let modal = has(&self.block, Code::new(66, 0));
        if !(modal || has(&self.block, Code::new(65, 0))) {
            return None;
        }
        let call = match self.read_call(line, if modal { "G66" } else { "G65" }) {
            Ok(call) => call,
            Err(e) => return Some(Err(e)),
        };
        if modal {
            // G66 only sets the call up; the block moves nothing.
            self.macros.modal_call = Some(call);
            return Some(Ok(()));
        }
        Some(self.invoke(call, line, false))
    }

    /// After a block that moved an axis: the `G66` modal call, if one is
    /// in force and this is not the called macro itself.
    pub(super) fn modal_call_after_move(&mut self, line: u32) -> Result<(), RunError> {
        let Some(call) = self.macros.modal_call else {
            return Ok(());
        };
        if self.stack.iter().any(|f| f.modal_call) {
            return Ok(());
        }
        let machine = self.controller.machine();
        let moved = self
            .block
            .words
            .iter()
            .any(|w| machine.axis_index(char::from(w.letter)).is_some());
        if moved {
            self.invoke(call, line, true)?;
        }
        Ok(())
    }

    /// P, L and the arguments of a `G65` / `G66` block.
    fn read_call(&mut self, line: u32, name: &str) -> Result<MacroCall, RunError> {
        // Arguments of dimension addresses written without a decimal point
        // count in least input increments, as the words themselves would
        // (FANUC: `G65 P9000 X10` gives #24 = 0.010 in mm, IS-B).
        if let Some(increment) = self.controller.input_increment() {
            for word in &mut self.block.words {
                if !word.decimal_point && DIMENSION_ADDRESSES.contains(&word.letter) {
                    word.value *= increment;
                    word.decimal_point = true;
                    word.code = None;
                }
            }
        }
        let args: [Option<f64>; LOCAL_COUNT] = match fiveaxis_macro::arguments(&self.block) {
            Ok(args) => args,
            Err(e) => return Err(self.macro_alarm(line, e)),
        };
        let word = |letter: u8| {
            self.block
                .words
                .iter()
                .find(|w| w.letter == letter)
                .copied()
        };
        let Some(p) = word(b'P') else {
            return Err(self.runner_alarm(
                Condition::SubprogramNumberMissing,
                line,
                format!("{name} needs P, the number of the macro program"),
            ));
        };
        let repeats = word(b'L').map_or(1.0, |l| l.value.round());
        if !(0.0..=9999.0).contains(&repeats) || !(0.0..=99_999_999.0).contains(&p.value) {
            return Err(self.runner_alarm(
                Condition::ValueOutOfRange,
                line,
                format!("{name}: P is a program number (0 to 99999999), L a count (0 to 9999)"),
            ));
        }
        Ok(MacroCall {
            program: p.value.round() as u32,
            repeats: repeats as u32,
            args,
        })
    }

    /// Calls the macro with a level of local variables of its own.
    fn invoke(&mut self, call: MacroCall, line: u32, modal: bool) -> Result<(), RunError> {
        if call.repeats == 0 {
            return Ok(());
        }
        if let Err(e) = self.macros.vars.push_frame(call.args) {
            return Err(self.macro_alarm(line, e));
        }
        let depth = self.stack.len();
        self.call(call.program, call.repeats, line)?;
        if self.stack.len() > depth
            && let Some(frame) = self.stack.last_mut()
        {
            frame.macro_call = true;
            frame.modal_call = modal;
        } else {
            self.macros.vars.pop_frame();
        }
        Ok(())
    }

    /// A macro alarm on `line`, under the control's number.
    pub(super) fn macro_alarm(&self, line: u32, error: MacroError) -> RunError {
        let control = self.controller.control();
        let (condition, code) = match error.kind {
            MacroErrorKind::CustomAlarm(n) => {
                (Condition::MacroAlarm, AlarmCode::program_alarm(control, n))
            }
            kind => {
                let condition = macro_condition(kind);
                (condition, condition.code(control))
            }
        };
        let span = (error.span != Span::default()).then_some(error.span);
        let alarm = Alarm {
            condition,
            code,
            line,
            span,
            message: error.message,
        };
        self.alarm_here(alarm)
    }
}

/// The kernel's condition for a macro alarm.
fn macro_condition(kind: MacroErrorKind) -> Condition {
    use MacroErrorKind as K;
    match kind {
        K::TooManyDigits => Condition::TooManyDigits,
        K::Overflow => Condition::MacroOverflow,
        K::DivisionByZero => Condition::MacroDivisionByZero,
        K::UndefinedVariable => Condition::MacroUndefinedVariable,
        K::WriteProtected => Condition::MacroWriteProtected,
        K::BracketNesting => Condition::MacroBracketNesting,
        K::ArgumentOutOfRange => Condition::MacroArgumentRange,
        K::CallNesting => Condition::MacroCallNesting,
        K::MissingEnd => Condition::MacroMissingEnd,
        K::StatementFormat => Condition::MacroStatementFormat,
        K::IllegalLoopNumber => Condition::MacroLoopNumber,
        K::NcAndMacro => Condition::MacroNcAndMacro,
        K::IllegalSequenceNumber => Condition::MacroSequenceNumber,
        K::IllegalArgumentAddress => Condition::MacroArgumentAddress,
        K::CustomAlarm(_) => Condition::MacroAlarm,
        _ => Condition::MacroFormat,
    }
}
