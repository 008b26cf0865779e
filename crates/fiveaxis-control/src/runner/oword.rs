//! LinuxCNC's RS274/NGC in the runner (`control = "linuxcnc"`): o-word
//! control flow, parameter assignments after the line is read, active
//! comments, and the parameters the controller answers.
//!
//! Lines with parameters, expressions or o-words are read by
//! `fiveaxis_macro::parse_ngc_line` (cached by position, so a loop parses
//! its lines once); plain lines keep the front end's fast path
//! (`Syntax::LINUXCNC`). Every word is then read as LinuxCNC does: a
//! number within 0.0001 of an integer is an integer (`T1.0`), any other
//! has a fraction, and none counts in least input increments.
//!
//! Flow (LinuxCNC 2.9 `o-code.adoc`, behaviour checked with `rs274`):
//!
//! * `sub` … `endsub`: a definition reached in the flow is recorded and
//!   skipped; a `call` finds it where it was recorded, or reads on through
//!   the file (a call before the definition works in `rs274`), or opens
//!   `name.ngc` from the program library (the machine's `subroutine_path`,
//!   then the program's folder). A call saves `#1`–`#30`, passes up to 30
//!   arguments, opens a level of named locals; `endsub`/`return [v]`
//!   restores them and sets `#<_value>` and `#<_value_returned>`. At most
//!   10 calls nest (`o-code.adoc`).
//! * `if`/`elseif`/`else`/`endif`, `while`/`endwhile`, `do`/`while`,
//!   `repeat`/`endrepeat`, `break`, `continue`: control-flow labels are
//!   local to their call level. A condition is true when not 0.
//! * Every line read counts against the block budget, so an endless loop
//!   is stopped.
//! * Skips are looked up, not read: the first skip in a file reads the
//!   file once and indexes the lines of the o-words skips end at
//!   (`endsub`, `elseif`, `else`, `endif`, `while`, `endwhile`,
//!   `endrepeat`) by label and kind ([`OIndex`]), so skipping a construct
//!   costs a binary search however long it is and however deep
//!   constructs nest. A file with more than [`MAX_INDEXED_OWORDS`] of them
//!   (or one that cannot be read to its end) is not indexed: its skips
//!   read the text, and every line read counts against the budget.

use std::collections::HashMap;
use std::sync::Arc;

use fiveaxis_gcode::{Block, Span, SyntaxErrorKind, parse_line_as};
use fiveaxis_macro::{
    Comment, MacroError, MacroSettings, NgcLine, OKind, OLabel, SystemVarError, SystemVariables,
    VarNumber, evaluate_block, label_key, oword_of, parse_ngc_line,
};

use super::{MacroFlow, Mark, RunError, Runner, Source};
use crate::alarm::{Alarm, Condition};
use crate::controller::{Controller, SystemVarFault};
use crate::modal::{Distance, FeedMode, LengthMode, MotionMode, Plane, Units, WorkSelect};

/// LinuxCNC's limit of nested subroutine calls (o-code.adoc).
pub(super) const NGC_MAX_CALLS: usize = 10;

/// Most parsed lines kept.
const CACHE_LINES: usize = 4096;

/// Most o-word lines indexed, over all files (16 bytes and a share of
/// their label each): far beyond real programs, a bound on the memory a
/// file of nothing but o-words can take.
const MAX_INDEXED_OWORDS: usize = 1 << 20;

/// The o-word kinds a skip ends at (the only ones indexed).
const SKIP_ENDS: [OKind; 7] = [
    OKind::EndSub,
    OKind::ElseIf,
    OKind::Else,
    OKind::EndIf,
    OKind::While,
    OKind::EndWhile,
    OKind::EndRepeat,
];

/// Where the o-words that skips end at lie in one file: label key → per
/// kind, the positions of their lines in file order (the line's mark and
/// the position after it).
type OIndex = HashMap<Box<str>, Vec<(OKind, Vec<(Mark, u64)>)>>;

/// A number this close to an integer is that integer (overview.adoc,
/// "Numbers": "within 0.0001 of an integer value").
const INTEGER_TOLERANCE: f64 = 1e-4;

/// LinuxCNC's version as `#<_vmajor>` and `#<_vminor>` give it (2.9.x).
const VERSION_MAJOR: f64 = 2.9;
const VERSION_MINOR: f64 = 0.0;

/// `#5599`: DEBUG comments shown when not 0.
const DEBUG_FLAG: u32 = 5599;

/// The axis letters of LinuxCNC's parameter layouts, in order.
const NGC_AXES: &[u8; 9] = b"XYZABCUVW";

/// The state of RS274/NGC flow.
#[derive(Debug, Default)]
pub(super) struct NgcState {
    /// Subroutine definitions: label key → the line after its `sub`.
    subs: HashMap<String, Mark>,
    /// Open calls, innermost last.
    calls: Vec<NgcCall>,
    /// Open control-flow blocks, innermost last.
    blocks: Vec<OBlock>,
    /// Parsed lines by position.
    cache: HashMap<u64, Arc<NgcLine>>,
    /// Values of a line's assignments, before they are made.
    pending: Vec<(Target, f64)>,
    /// The line being executed (`#<_line>`).
    line: u32,
    /// The o-word index of each file skipped in (by file number); `None`
    /// for a file not indexed (too many o-words, or unreadable).
    index: HashMap<usize, Option<OIndex>>,
    /// O-word lines indexed so far, over all files.
    indexed: usize,
    /// The line of the `if` / `while` / `do` / `repeat` each label opened
    /// first, by the subroutine it is in (its body's position; `u64::MAX`
    /// for the main program) and the label: rs274 stops on a label opened
    /// again on another line of the same subroutine.
    opened: HashMap<(u64, String), u32>,
}

#[derive(Debug)]
struct NgcCall {
    return_to: Mark,
    /// Where the subroutine's body starts: the scope of its labels.
    body: u64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum BlockKind {
    If,
    While,
    Do,
    Repeat,
}

#[derive(Debug)]
struct OBlock {
    key: String,
    level: usize,
    kind: BlockKind,
    /// `while`: its line (evaluated again); `do`/`repeat`: the line after.
    start: Mark,
    /// `if`: a branch was taken. `repeat`: runs still to do.
    taken: bool,
    left: u64,
}

#[derive(Debug)]
enum Target {
    Number(u32),
    Named(Box<str>, Span),
}

/// The parameters the controller answers under LinuxCNC's numbers and
/// names (overview.adoc, "Numbered Parameters", "Predefined Named
/// Parameters").
pub(super) struct NgcSystem<'c, 'm> {
    controller: &'c mut Controller<'m>,
    line: u32,
    call_level: usize,
}

impl std::fmt::Debug for NgcSystem<'_, '_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("NgcSystem")
    }
}

impl NgcSystem<'_, '_> {
    /// The machine's index of LinuxCNC axis `a` (0 = X … 8 = W).
    fn axis(&self, a: u32) -> Option<usize> {
        let letter = *NGC_AXES.get(a as usize)?;
        self.controller.machine().axis_index(char::from(letter))
    }

    /// A FANUC-numbered variable of the controller.
    fn fanuc(&self, n: u32) -> Option<f64> {
        self.controller.read_system_variable(n).ok().flatten()
    }

    fn position(&self, base: u32, a: u32) -> Option<f64> {
        let i = self.axis(a)? as u32;
        self.fanuc(base + 1 + i)
    }

    fn flag(on: bool) -> f64 {
        if on { 1.0 } else { 0.0 }
    }
}

/// The G28 (0) or G30 (1) position and LinuxCNC axis of `#5161`–`#5169`,
/// `#5181`–`#5189`.
fn home_parameter(number: u32) -> (usize, u32) {
    if number >= 5181 {
        (1, number - 5181)
    } else {
        (0, number - 5161)
    }
}

/// The work-offset parameters #5221 … #5390 that are the controller's
/// (G54 … G59.3, X … W and R, 20 apart).
fn work_parameter(n: u32) -> bool {
    (5221..=5390).contains(&n) && (n - 5221) % 20 < 10
}

/// The controller's (FANUC) number of a LinuxCNC work-offset parameter:
/// G54 … G59 the same (`#5221` …), G59.1 … G59.3 those of G54.1 P1 … P3
/// (`#7001` …, 20 apart).
fn fanuc_work_number(n: u32) -> u32 {
    let (set, axis) = ((n - 5221) / 20, (n - 5221) % 20);
    if set < 6 {
        n
    } else {
        7001 + 20 * (set - 6) + axis
    }
}

impl SystemVariables for NgcSystem<'_, '_> {
    fn read(&self, number: u32) -> Result<Option<f64>, SystemVarError> {
        let value = match number {
            5161..=5169 | 5181..=5189 => {
                let (n, a) = home_parameter(number);
                self.axis(a).and_then(|i| self.controller.home(n, i))
            }
            5021..=5029 => self.position(5020, number - 5021),
            5220 => match self.controller.modal().work {
                WorkSelect::Standard(i) => Some(f64::from(i) + 1.0),
                WorkSelect::Extended(k) if k <= 3 => Some(6.0 + f64::from(k)),
                // Haas's G154 systems are not LinuxCNC's.
                WorkSelect::Extended(_) | WorkSelect::Haas(_) | WorkSelect::Null => None,
            },
            n if work_parameter(n) => {
                let k = (n - 5221) % 20;
                if k == 9 {
                    // R, the XY rotation of system (n − 5221) / 20 + 1.
                    let system = ((n - 5221) / 20 + 1) as usize;
                    self.controller.xy_rotation(system)
                } else if k >= 3 {
                    // A, B, C, U, V, W of system (n − 5221) / 20 + 1.
                    let letter = char::from(b"ABCUVW"[(k - 3) as usize]);
                    let system = ((n - 5221) / 20 + 1) as usize;
                    Some(
                        self.controller
                            .rotary_work_offset(system, letter)
                            .unwrap_or(0.0),
                    )
                } else {
                    self.fanuc(fanuc_work_number(n))
                }
            }
            5400 => Some(f64::from(self.controller.spindle_tool())),
            // The loaded tool's data: Z offset (length) and diameter; the
            // kernel's offset memory has no other axis offsets, angles or
            // orientation (0).
            5401..=5413 => {
                let tool = self
                    .controller
                    .offsets()
                    .tool(self.controller.spindle_tool());
                Some(match number {
                    5403 => tool.length,
                    5410 => 2.0 * tool.radius,
                    _ => 0.0,
                })
            }
            // The length offset applied now, along Z.
            5081..=5089 => Some(if number == 5083 {
                self.controller.applied_tool_length()
            } else {
                0.0
            }),
            5420..=5428 => self.position(5000, number - 5420),
            _ => None,
        };
        Ok(value)
    }

    fn write(&mut self, number: u32, value: Option<f64>) -> Result<(), SystemVarError> {
        match number {
            5161..=5169 | 5181..=5189 => {
                let (n, a) = home_parameter(number);
                if let Some(i) = self.axis(a) {
                    self.controller.set_home(n, i, value.unwrap_or(0.0));
                }
                // Axes the machine lacks are stored by the caller.
                Err(SystemVarError::NotAVariable)
            }
            n if work_parameter(n) && (n - 5221) % 20 < 3 => self
                .controller
                .write_system_variable(fanuc_work_number(n), value)
                .map_err(|f| match f {
                    SystemVarFault::Unknown => SystemVarError::NotAVariable,
                    SystemVarFault::ReadOnly => SystemVarError::ReadOnly,
                }),
            n if work_parameter(n) && (n - 5221) % 20 == 9 => {
                let system = ((n - 5221) / 20 + 1) as usize;
                self.controller
                    .set_xy_rotation(system, value.unwrap_or(0.0));
                Ok(())
            }
            5021..=5029 | 5081..=5089 | 5400..=5413 | 5420..=5428 => Err(SystemVarError::ReadOnly),
            _ => Err(SystemVarError::NotAVariable),
        }
    }

    fn read_named(&self, name: &str) -> Result<f64, SystemVarError> {
        let m = self.controller.modal();
        let axis_of = |suffix: &str| {
            let [letter] = suffix.as_bytes() else {
                return None;
            };
            NGC_AXES
                .iter()
                .position(|a| a.to_ascii_lowercase() == *letter)
                .map(|a| a as u32)
        };
        let value = match name {
            "_vmajor" => VERSION_MAJOR,
            "_vminor" => VERSION_MINOR,
            "_line" => f64::from(self.line),
            "_task" => 1.0,
            "_call_level" => self.call_level as f64,
            "_remap_level" => 0.0,
            "_motion_mode" => match m.motion {
                MotionMode::Rapid => 0.0,
                MotionMode::Linear => 10.0,
                MotionMode::Cw => 20.0,
                MotionMode::Ccw => 30.0,
            },
            "_plane" => match m.plane {
                Plane::Xy => 170.0,
                Plane::Zx => 180.0,
                Plane::Yz => 190.0,
            },
            "_ccomp" => self.fanuc(4007).map_or(400.0, |g| g * 10.0),
            "_metric" => Self::flag(m.units == Units::Metric),
            "_imperial" => Self::flag(m.units == Units::Inch),
            "_absolute" => Self::flag(m.distance == Distance::Absolute),
            "_incremental" => Self::flag(m.distance == Distance::Incremental),
            "_inverse_time" => Self::flag(m.feed_mode == FeedMode::InverseTime),
            "_units_per_minute" => Self::flag(m.feed_mode == FeedMode::PerMinute),
            "_units_per_rev" => Self::flag(m.feed_mode == FeedMode::PerRevolution),
            "_coord_system" => match m.work {
                WorkSelect::Standard(i) if i < 6 => 540.0 + 10.0 * f64::from(i),
                WorkSelect::Standard(i) => 591.0 + f64::from(i - 6),
                WorkSelect::Extended(k) if k <= 3 => 590.0 + f64::from(k),
                WorkSelect::Extended(_) | WorkSelect::Haas(_) | WorkSelect::Null => {
                    return Err(SystemVarError::NotAVariable);
                }
            },
            "_tool_offset" => Self::flag(m.length != LengthMode::Off),
            "_ijk_absolute_mode" => Self::flag(m.ijk_absolute),
            "_retract_r_plane" => Self::flag(self.fanuc(4010) == Some(98.0)),
            "_retract_old_z" => Self::flag(self.fanuc(4010) == Some(99.0)),
            "_spindle_on" => Self::flag(self.controller.spindle_on()),
            "_flood" | "_mist" => Self::flag(self.controller.coolant()),
            "_feed" => self.fanuc(4109).unwrap_or(0.0),
            "_rpm" => self.controller.spindle_speed(),
            "_current_tool" => f64::from(self.controller.spindle_tool()),
            "_selected_tool" => f64::from(self.controller.tool()),
            n => {
                if let Some(a) = n.strip_prefix("_abs_").and_then(axis_of) {
                    self.position(5020, a).ok_or(SystemVarError::NotAVariable)?
                } else if let Some(a) = n.strip_prefix('_').and_then(axis_of) {
                    self.position(5000, a).ok_or(SystemVarError::NotAVariable)?
                } else if let Some(pin) = bracketed(n, "_hal[") {
                    let pins = &self.controller.machine().params.hal_pins;
                    *pins.get(pin).ok_or(SystemVarError::NotAVariable)?
                } else if let Some(key) = bracketed(n, "_ini[") {
                    let key = key.to_ascii_uppercase();
                    let values = &self.controller.machine().params.ini_values;
                    *values.get(&key).ok_or(SystemVarError::NotAVariable)?
                } else {
                    // The program's own globals.
                    return Err(SystemVarError::NotAVariable);
                }
            }
        };
        Ok(value)
    }
}

/// `_hal[pin]` → `pin`, `_ini[section]name` → `section]name`: what
/// follows `prefix` in a predefined name that reads a HAL pin or an INI
/// value (the machine file's `hal_pins` and `ini` tables).
fn bracketed<'n>(name: &'n str, prefix: &str) -> Option<&'n str> {
    let rest = name.strip_prefix(prefix)?;
    if prefix == "_hal[" {
        rest.strip_suffix(']')
    } else {
        rest.contains(']').then_some(rest)
    }
}

/// Whether a plain line can take the front end's fast path: no
/// parameter, expression, o-word or active comment.
fn is_plain(text: &[u8]) -> bool {
    let special = text.iter().any(|&b| matches!(b, b'#' | b'[' | b',' | b'<'));
    if special {
        return false;
    }
    let mut rest = text.trim_ascii_start();
    if let [b'/', tail @ ..] = rest {
        rest = tail.trim_ascii_start();
    }
    if let [b'N' | b'n', tail @ ..] = rest {
        let digits = tail
            .iter()
            .take_while(|b| b.is_ascii_digit() || matches!(b, b' ' | b'\t'))
            .count();
        rest = tail.get(digits..).unwrap_or_default();
    }
    !matches!(rest.first(), Some(b'O' | b'o'))
}

/// LinuxCNC reads a number within 0.0001 of an integer as that integer:
/// such a word is marked as written without decimal point (so the integer
/// addresses take it), any other as a real number; integer addresses are
/// rounded.
fn normalize_words(block: &mut Block) {
    for word in &mut block.words {
        // Written or computed, LinuxCNC reads every number by this rule.
        word.computed = false;
        let rounded = word.value.round();
        if (word.value - rounded).abs() < INTEGER_TOLERANCE {
            word.decimal_point = false;
            if matches!(word.letter, b'T' | b'H' | b'D' | b'L') {
                word.value = rounded;
            }
        } else {
            word.decimal_point = true;
        }
    }
}

impl<S: Source> Runner<'_, S> {
    /// Reads and executes the line just read at `here` as RS274/NGC.
    pub(super) fn ngc_step(
        &mut self,
        here: Mark,
        sequential: bool,
        out: &mut Vec<crate::Segment>,
    ) -> Result<(), RunError> {
        self.ngc.line = here.line;
        let cached = !self.ngc.cache.is_empty() && self.ngc.cache.contains_key(&here.offset);
        if !cached && is_plain(&self.text) {
            match parse_line_as(self.syntax, &self.text, here.line, &mut self.block) {
                Ok(()) => {}
                Err(error) if error.kind != SyntaxErrorKind::Macro => {
                    return Err(self.syntax_alarm(here.line, error));
                }
                Err(_) => return self.ngc_parsed_line(here, sequential, out),
            }
            normalize_words(&mut self.block);
            return self.execute_block(here, sequential, out);
        }
        self.ngc_parsed_line(here, sequential, out)
    }

    fn ngc_parsed_line(
        &mut self,
        here: Mark,
        sequential: bool,
        out: &mut Vec<crate::Segment>,
    ) -> Result<(), RunError> {
        let line = match self.ngc.cache.get(&here.offset) {
            Some(line) => Arc::clone(line),
            None => {
                let line = match parse_ngc_line(&self.text, here.line) {
                    Ok(line) => Arc::new(line),
                    Err(e) => return Err(self.macro_alarm(here.line, e)),
                };
                if self.ngc.cache.len() >= CACHE_LINES {
                    self.ngc.cache.clear();
                }
                self.ngc.cache.insert(here.offset, Arc::clone(&line));
                line
            }
        };
        if line.block_delete && self.options.block_delete {
            return Ok(());
        }
        if line.nc.tape_mark {
            self.block.clear();
            self.block.line = here.line;
            self.block.tape_mark = true;
            return self.execute_block(here, false, out);
        }
        if let Some(comment) = &line.comment {
            self.ngc_comment(here.line, comment)?;
        }
        if let Some(oword) = &line.oword {
            return self.ngc_oword(here, sequential, oword, out);
        }
        match self.ngc_evaluate(&line) {
            Ok(MacroFlow::Block) => {}
            Ok(MacroFlow::Done) => return Ok(()),
            Err(e) => return Err(self.macro_alarm(here.line, e)),
        }
        normalize_words(&mut self.block);
        self.execute_block(here, false, out)
    }

    /// Evaluates the line's words and assignments with the values before
    /// the line, then makes the assignments: the block is in
    /// `self.block`.
    fn ngc_evaluate(&mut self, line: &NgcLine) -> Result<MacroFlow, MacroError> {
        let settings = MacroSettings::LINUXCNC;
        let mut pending = std::mem::take(&mut self.ngc.pending);
        pending.clear();
        let result = (|| {
            let sys = NgcSystem {
                controller: &mut self.controller,
                line: self.ngc.line,
                call_level: self.ngc.calls.len(),
            };
            let vars = &self.macros.vars;
            evaluate_block(&line.nc, vars, &sys, &settings, &mut self.block)?;
            for (target, value) in &line.assignments {
                let value = vars.eval_number(value, &sys, &settings)?.unwrap_or(0.0);
                let target = match &target.number {
                    VarNumber::Named(name) => Target::Named(name.clone(), target.span),
                    _ => Target::Number(vars.resolve_number(target, &sys, &settings)?),
                };
                pending.push((target, value));
            }
            Ok::<(), MacroError>(())
        })();
        let applied = result.and_then(|()| {
            let mut sys = NgcSystem {
                controller: &mut self.controller,
                line: self.ngc.line,
                call_level: self.ngc.calls.len(),
            };
            for (target, value) in &pending {
                match target {
                    Target::Named(name, span) => {
                        self.macros.vars.write_named(name, *value, *span, &sys)?;
                    }
                    Target::Number(n) => {
                        self.macros
                            .vars
                            .set(*n, Some(*value), &mut sys, &settings)?;
                    }
                }
            }
            Ok(())
        });
        self.ngc.pending = pending;
        applied?;
        Ok(if self.block.is_empty() {
            MacroFlow::Done
        } else {
            MacroFlow::Block
        })
    }

    /// An active comment: `MSG`, `DEBUG`, `PRINT` are noted for
    /// `--verbose` (parameters substituted), `ABORT` stops the program.
    fn ngc_comment(&mut self, line: u32, comment: &Comment) -> Result<(), RunError> {
        if matches!(comment, Comment::Debug(_)) {
            let sys = NgcSystem {
                controller: &mut self.controller,
                line: self.ngc.line,
                call_level: self.ngc.calls.len(),
            };
            let shown = self
                .macros
                .vars
                .get(DEBUG_FLAG, &sys, &MacroSettings::LINUXCNC)
                .ok()
                .flatten()
                .unwrap_or(1.0);
            if shown == 0.0 {
                // #5599 = 0: DEBUG comments are off (overview.adoc).
                return Ok(());
            }
        }
        let (what, text, substitute) = match comment {
            Comment::Plain(_) | Comment::Log(_) => return Ok(()),
            Comment::Msg(text) => ("MSG", text, false),
            Comment::Debug(text) => ("DEBUG", text, true),
            Comment::Print(text) => ("PRINT", text, true),
            Comment::Abort(text) => ("ABORT", text, true),
        };
        let text = if substitute {
            self.substitute(text)
        } else {
            text.trim().to_owned()
        };
        if matches!(comment, Comment::Abort(_)) {
            return Err(self.runner_alarm(
                Condition::MacroAlarm,
                line,
                format!("the program aborted: {text}"),
            ));
        }
        self.note(format!("line {line}: {what}: {text}"));
        Ok(())
    }

    /// `#n` and `#<name>` in a DEBUG/PRINT text replaced by their values
    /// (six decimals, as `rs274` prints them; `######` for an undefined
    /// named parameter).
    fn substitute(&mut self, text: &str) -> String {
        let settings = MacroSettings::LINUXCNC;
        let mut out = String::new();
        let mut rest = text.trim();
        while let Some(at) = rest.find('#') {
            out.push_str(&rest[..at]);
            let tail = &rest[at + 1..];
            let (name, len) = if let Some(inner) = tail.strip_prefix('<') {
                match inner.find('>') {
                    Some(end) => (Some(inner[..end].to_owned()), end + 2),
                    None => (None, 0),
                }
            } else {
                let digits = tail.bytes().take_while(u8::is_ascii_digit).count();
                ((digits > 0).then(|| tail[..digits].to_owned()), digits)
            };
            let sys = NgcSystem {
                controller: &mut self.controller,
                line: self.ngc.line,
                call_level: self.ngc.calls.len(),
            };
            match name {
                Some(name) if len > 0 && tail.starts_with('<') => {
                    let key: String = name
                        .chars()
                        .filter(|c| !c.is_whitespace())
                        .collect::<String>()
                        .to_ascii_lowercase();
                    match self.macros.vars.read_named(&key, Span::default(), &sys) {
                        Ok(v) => out.push_str(&format!("{v:.6}")),
                        Err(_) => out.push_str("######"),
                    }
                }
                Some(digits) => {
                    let n: u32 = digits.parse().unwrap_or(0);
                    match self.macros.vars.get(n, &sys, &settings) {
                        Ok(v) => out.push_str(&format!("{:.6}", v.unwrap_or(0.0))),
                        Err(_) => out.push_str("######"),
                    }
                }
                None => out.push('#'),
            }
            rest = &tail[len..];
        }
        out.push_str(rest);
        out
    }

    fn oword_error(&self, line: u32, span: Span, message: String) -> RunError {
        let control = self.controller.control();
        self.alarm_here(Alarm {
            condition: Condition::OWordFlow,
            code: Condition::OWordFlow.code(control),
            line,
            span: Some(span),
            message,
        })
    }

    /// A condition, count or value of an o-word.
    fn oword_value(&mut self, line: u32, expr: &fiveaxis_macro::Expr) -> Result<f64, RunError> {
        let settings = MacroSettings::LINUXCNC;
        let sys = NgcSystem {
            controller: &mut self.controller,
            line: self.ngc.line,
            call_level: self.ngc.calls.len(),
        };
        let value = self.macros.vars.eval_number(expr, &sys, &settings);
        match value {
            Ok(v) => Ok(v.unwrap_or(0.0)),
            Err(e) => Err(self.macro_alarm(line, e)),
        }
    }

    fn ngc_oword(
        &mut self,
        here: Mark,
        sequential: bool,
        oword: &fiveaxis_macro::OWord,
        out: &mut Vec<crate::Segment>,
    ) -> Result<(), RunError> {
        let at_start = self.at_program_start;
        self.at_program_start = false;
        let key = match &oword.label {
            OLabel::Computed(e) => {
                let v = self.oword_value(here.line, e)?;
                label_key(&oword.label, Some(v))
            }
            label => label_key(label, None),
        };
        let level = self.ngc.calls.len();
        let after = Mark {
            offset: self.source.position(),
            line: here.line + 1,
        };
        let span = oword.span;
        let opens = match oword.kind {
            OKind::If | OKind::Do | OKind::Repeat => true,
            // `while` opens a loop unless it is the tail of a `do`.
            OKind::While => self
                .open_block(&key, level, &[BlockKind::Do])
                .is_none_or(|k| self.ngc.blocks[k].kind != BlockKind::Do),
            _ => false,
        };
        if opens {
            let scope = self.ngc.calls.last().map_or(u64::MAX, |c| c.body);
            let first = *self
                .ngc
                .opened
                .entry((scope, key.clone()))
                .or_insert(here.line);
            if first != here.line {
                return Err(self.oword_error(
                    here.line,
                    span,
                    format!("duplicate O-word label: o{key} was already opened on line {first}"),
                ));
            }
        }
        match oword.kind {
            OKind::Program => {
                // A bare `o100`: a numbered program for M98 (o-code.adoc,
                // "Fanuc-Style Numbered Programs").
                self.block.clear();
                self.block.line = here.line;
                if let OLabel::Number(n) = oword.label {
                    self.block.words.push(fiveaxis_gcode::Word {
                        letter: b'O',
                        value: f64::from(n),
                        decimal_point: false,
                        code: None,
                        computed: false,
                        span,
                    });
                }
                self.at_program_start = at_start;
                return self.execute_block(here, sequential, out);
            }
            OKind::Sub => {
                if level > 0 && self.ngc.subs.get(&key) != Some(&after) {
                    return Err(self.oword_error(
                        here.line,
                        span,
                        format!("o{key} sub: a subroutine definition inside another subroutine"),
                    ));
                }
                self.ngc.subs.insert(key.clone(), after);
                if !self.skip_to(&key, &[OKind::EndSub])? {
                    return Err(self.oword_error(
                        here.line,
                        span,
                        format!("o{key} sub has no o{key} endsub"),
                    ));
                }
            }
            OKind::EndSub | OKind::Return => {
                if self.ngc.calls.is_empty() {
                    return Err(self.oword_error(
                        here.line,
                        span,
                        format!(
                            "o{key} {}: not in a called subroutine",
                            kind_name(oword.kind)
                        ),
                    ));
                }
                let value = match oword.args.first() {
                    Some(e) => Some(self.oword_value(here.line, e)?),
                    None => None,
                };
                self.ngc_return(value)?;
            }
            OKind::Call => {
                let mut args = [0.0; fiveaxis_macro::NGC_CALL_ARGS];
                for (slot, e) in args.iter_mut().zip(&oword.args) {
                    *slot = self.oword_value(here.line, e)?;
                }
                let args = &args[..oword.args.len()];
                self.ngc_call(&key, args, here, after, span)?;
            }
            OKind::If => {
                let cond = self.oword_value(here.line, &oword.args[0])? != 0.0;
                self.ngc.blocks.push(OBlock {
                    key: key.clone(),
                    level,
                    kind: BlockKind::If,
                    start: here,
                    taken: cond,
                    left: 0,
                });
                if !cond {
                    self.next_branch(&key, here, span)?;
                }
            }
            OKind::ElseIf | OKind::Else => {
                let Some(top) = self.open_block(&key, level, &[BlockKind::If]) else {
                    return Err(self.oword_error(
                        here.line,
                        span,
                        format!("o{key} {} without o{key} if", kind_name(oword.kind)),
                    ));
                };
                if self.ngc.blocks[top].taken {
                    self.ngc.blocks.truncate(top);
                    self.skip_or_fail(&key, &[OKind::EndIf], here, span)?;
                } else {
                    let cond = match oword.kind {
                        OKind::ElseIf => self.oword_value(here.line, &oword.args[0])? != 0.0,
                        _ => true,
                    };
                    if cond {
                        self.ngc.blocks[top].taken = true;
                    } else {
                        self.next_branch(&key, here, span)?;
                    }
                }
            }
            OKind::EndIf => {
                let Some(top) = self.open_block(&key, level, &[BlockKind::If]) else {
                    return Err(self.oword_error(
                        here.line,
                        span,
                        format!("o{key} endif without o{key} if"),
                    ));
                };
                self.ngc.blocks.truncate(top);
            }
            OKind::While => {
                let tail = self
                    .open_block(&key, level, &[BlockKind::Do])
                    .filter(|&k| self.ngc.blocks[k].kind == BlockKind::Do);
                let cond = self.oword_value(here.line, &oword.args[0])? != 0.0;
                if let Some(top) = tail {
                    // The tail of `do … while`.
                    if cond {
                        let start = self.ngc.blocks[top].start;
                        self.ngc.blocks.truncate(top + 1);
                        self.jump_on(start)?;
                    } else {
                        self.ngc.blocks.truncate(top);
                    }
                } else {
                    let open = self
                        .open_block(&key, level, &[BlockKind::While])
                        .filter(|&k| self.ngc.blocks[k].start == here);
                    match (open, cond) {
                        (Some(top), true) => self.ngc.blocks.truncate(top + 1),
                        (None, true) => self.ngc.blocks.push(OBlock {
                            key: key.clone(),
                            level,
                            kind: BlockKind::While,
                            start: here,
                            taken: false,
                            left: 0,
                        }),
                        (open, false) => {
                            if let Some(top) = open {
                                self.ngc.blocks.truncate(top);
                            }
                            self.skip_or_fail(&key, &[OKind::EndWhile], here, span)?;
                        }
                    }
                }
            }
            OKind::EndWhile => {
                let Some(top) = self.open_block(&key, level, &[BlockKind::While]) else {
                    return Err(self.oword_error(
                        here.line,
                        span,
                        format!("o{key} endwhile without o{key} while"),
                    ));
                };
                let start = self.ngc.blocks[top].start;
                self.ngc.blocks.truncate(top + 1);
                self.jump_on(start)?;
            }
            OKind::Do => {
                self.ngc.blocks.push(OBlock {
                    key: key.clone(),
                    level,
                    kind: BlockKind::Do,
                    start: after,
                    taken: false,
                    left: 0,
                });
            }
            OKind::Repeat => {
                let n = self.oword_value(here.line, &oword.args[0])?.round();
                if n >= 1.0 {
                    self.ngc.blocks.push(OBlock {
                        key: key.clone(),
                        level,
                        kind: BlockKind::Repeat,
                        start: after,
                        taken: false,
                        // Counts beyond u64 are stopped by the block budget.
                        left: (n - 1.0).min(u64::MAX as f64) as u64,
                    });
                } else {
                    self.skip_or_fail(&key, &[OKind::EndRepeat], here, span)?;
                }
            }
            OKind::EndRepeat => {
                let Some(top) = self.open_block(&key, level, &[BlockKind::Repeat]) else {
                    return Err(self.oword_error(
                        here.line,
                        span,
                        format!("o{key} endrepeat without o{key} repeat"),
                    ));
                };
                self.repeat_again(top)?;
            }
            OKind::Break | OKind::Continue => {
                // rs274 2.9 leaves `while` and `do` loops only: in a
                // `repeat` it stops ("no matching while/do label").
                if let Some(top) = self.open_block(&key, level, &[BlockKind::Repeat]) {
                    // A repeat's start is the line after it.
                    let line = self.ngc.blocks[top].start.line.saturating_sub(1);
                    return Err(self.oword_error(
                        here.line,
                        span,
                        format!(
                            "o{key} {} leaves a while or do loop only: o{key} is the repeat of line {line}",
                            kind_name(oword.kind)
                        ),
                    ));
                }
                let loops = [BlockKind::While, BlockKind::Do];
                let Some(top) = self.open_block(&key, level, &loops) else {
                    return Err(self.oword_error(
                        here.line,
                        span,
                        format!("o{key} {} outside a loop o{key}", kind_name(oword.kind)),
                    ));
                };
                let block = &self.ngc.blocks[top];
                let (kind, start) = (block.kind, block.start);
                self.ngc.blocks.truncate(top + 1);
                let end = match kind {
                    BlockKind::While => OKind::EndWhile,
                    BlockKind::Repeat => OKind::EndRepeat,
                    _ => OKind::While,
                };
                match (oword.kind, kind) {
                    (OKind::Break, _) => {
                        self.ngc.blocks.truncate(top);
                        self.skip_or_fail(&key, &[end], here, span)?;
                    }
                    (_, BlockKind::While) => self.jump_on(start)?,
                    (_, BlockKind::Repeat) => self.repeat_again(top)?,
                    // `continue` in `do`: to the `while` test.
                    _ => {
                        let found = self.find_ahead(&key, &[OKind::While])?;
                        match found {
                            Some(mark) => self.jump_on(mark)?,
                            None => {
                                return Err(self.oword_error(
                                    here.line,
                                    span,
                                    format!("o{key} do has no o{key} while"),
                                ));
                            }
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// The innermost open block with `key` at `level` of one of `kinds`;
    /// blocks above it are left open (the caller truncates).
    fn open_block(&self, key: &str, level: usize, kinds: &[BlockKind]) -> Option<usize> {
        self.ngc
            .blocks
            .iter()
            .rposition(|b| b.level == level && b.key == key && kinds.contains(&b.kind))
    }

    /// `endrepeat` or `continue` in a repeat: again from its first line,
    /// or on after `endrepeat` when the count is done.
    fn repeat_again(&mut self, top: usize) -> Result<(), RunError> {
        let block = &mut self.ngc.blocks[top];
        if block.left > 0 {
            block.left -= 1;
            let start = block.start;
            self.ngc.blocks.truncate(top + 1);
            self.jump_on(start)
        } else {
            let key = block.key.clone();
            self.ngc.blocks.truncate(top);
            // From `continue`: on after `endrepeat`; from `endrepeat`
            // itself the next line is already after it.
            if self.last_oword_kind() == Some(OKind::Continue) {
                self.skip_to(&key, &[OKind::EndRepeat])?;
            }
            Ok(())
        }
    }

    /// The kind of the o-word on the line just read.
    fn last_oword_kind(&self) -> Option<OKind> {
        oword_of(&self.text).map(|(_, k)| k)
    }

    /// A jump inside the running program (loops): not a program start.
    fn jump_on(&mut self, mark: Mark) -> Result<(), RunError> {
        self.jump(mark)?;
        self.at_program_start = false;
        Ok(())
    }

    /// Reads on to the next `elseif`, `else` or `endif` of `key` and
    /// stops before it (it is read next), or after `endif`.
    fn next_branch(&mut self, key: &str, here: Mark, span: Span) -> Result<(), RunError> {
        let found = self.find_ahead(key, &[OKind::ElseIf, OKind::Else, OKind::EndIf])?;
        match found {
            Some(mark) => self.jump_on(mark),
            None => {
                Err(self.oword_error(here.line, span, format!("o{key} if has no o{key} endif")))
            }
        }
    }

    /// The mark of the next line (from the current position) whose
    /// o-word is `key` with one of `kinds`; the position is left where it
    /// was.
    fn find_ahead(&mut self, key: &str, kinds: &[OKind]) -> Result<Option<Mark>, RunError> {
        if let Some(found) = self.indexed(key, kinds)? {
            return Ok(found.map(|(mark, _)| mark));
        }
        let resume = Mark {
            offset: self.source.position(),
            line: self.next_line,
        };
        let mut line = resume.line;
        let mut found = None;
        while let Some(mark) = self.skip_line(&mut line, self.ngc.line)? {
            if let Some((k, kind)) = oword_of(&self.scan_text)
                && k == key
                && kinds.contains(&kind)
            {
                found = Some(mark);
                break;
            }
        }
        self.source.seek(resume.offset)?;
        self.next_line = resume.line;
        Ok(found)
    }

    /// Reads on past the next line whose o-word is `key` with one of
    /// `kinds`; `false` (at the end of the file) when there is none.
    fn skip_to(&mut self, key: &str, kinds: &[OKind]) -> Result<bool, RunError> {
        if let Some(Some((mark, after))) = self.indexed(key, kinds)? {
            self.source.seek(after)?;
            self.next_line = mark.line + 1;
            return Ok(true);
        }
        // Not indexed, or not there: read on to the end as before.
        let mut line = self.next_line;
        while let Some(_mark) = self.skip_line(&mut line, self.ngc.line)? {
            if let Some((k, kind)) = oword_of(&self.scan_text)
                && k == key
                && kinds.contains(&kind)
            {
                self.next_line = line;
                return Ok(true);
            }
        }
        self.next_line = line;
        Ok(false)
    }

    /// The next line from the current position whose o-word is `key` with
    /// one of `kinds` (all of them in [`SKIP_ENDS`]), from the file's
    /// index: its mark and the position after it, or `Some(None)` when
    /// the file has none; `None` when the file is not indexed.
    fn indexed(
        &mut self,
        key: &str,
        kinds: &[OKind],
    ) -> Result<Option<Option<(Mark, u64)>>, RunError> {
        let from = self.source.position();
        let file = super::library::file_of(from);
        if !self.ngc.index.contains_key(&file) {
            let index = self.build_index(file)?;
            self.ngc.index.insert(file, index);
        }
        let Some(Some(index)) = self.ngc.index.get(&file) else {
            return Ok(None);
        };
        let Some(lists) = index.get(key) else {
            return Ok(Some(None));
        };
        let mut best: Option<(Mark, u64)> = None;
        for (_, list) in lists.iter().filter(|(kind, _)| kinds.contains(kind)) {
            let i = list.partition_point(|(mark, _)| mark.offset < from);
            if let Some(&next) = list.get(i)
                && best.is_none_or(|b| next.0.offset < b.0.offset)
            {
                best = Some(next);
            }
        }
        Ok(Some(best))
    }

    /// Reads file `file` once and indexes its o-words of [`SKIP_ENDS`];
    /// the position is left where it was. `None` when the file holds
    /// more than the bound allows or cannot be read to its end (its skips
    /// then read the text).
    fn build_index(&mut self, file: usize) -> Result<Option<OIndex>, RunError> {
        let resume = Mark {
            offset: self.source.position(),
            line: self.next_line,
        };
        self.source.seek(super::library::file_start(file))?;
        let mut index = OIndex::new();
        let mut line = 1;
        let complete = loop {
            let mark = match self.scan_line(&mut line) {
                Ok(Some(mark)) => mark,
                Ok(None) => break true,
                Err(_) => break false,
            };
            let Some((key, kind)) = oword_of(&self.scan_text) else {
                continue;
            };
            if !SKIP_ENDS.contains(&kind) {
                continue;
            }
            if self.ngc.indexed >= MAX_INDEXED_OWORDS {
                break false;
            }
            self.ngc.indexed += 1;
            let entry = (mark, self.source.position());
            let lists = index.entry(key.into_boxed_str()).or_default();
            match lists.iter_mut().find(|(k, _)| *k == kind) {
                Some((_, list)) => list.push(entry),
                None => lists.push((kind, vec![entry])),
            }
        };
        self.source.seek(resume.offset)?;
        self.next_line = resume.line;
        Ok(complete.then_some(index))
    }

    fn skip_or_fail(
        &mut self,
        key: &str,
        kinds: &[OKind],
        here: Mark,
        span: Span,
    ) -> Result<(), RunError> {
        if self.skip_to(key, kinds)? {
            return Ok(());
        }
        let name = kinds.first().map_or("end", |k| kind_name(*k));
        Err(self.oword_error(here.line, span, format!("o{key}: no o{key} {name} follows")))
    }

    /// `o… call`: the subroutine's body runs with the arguments.
    fn ngc_call(
        &mut self,
        key: &str,
        args: &[f64],
        here: Mark,
        after: Mark,
        span: Span,
    ) -> Result<(), RunError> {
        if !is_plain_name(key) {
            return Err(self.oword_error(
                here.line,
                span,
                format!(
                    "o<{key}> call: a subroutine name is a file name in the subroutine path, \
                     without `/`, `\\`, `:` or `..`"
                ),
            ));
        }
        let body = match self.ngc.subs.get(key) {
            Some(&body) => Some(body),
            None => self.find_sub(key)?,
        };
        let Some(body) = body else {
            return Err(self.oword_error(
                here.line,
                span,
                format!(
                    "o{key} call: no subroutine o{key} in the program, and no file {key}.ngc in \
                     the subroutine path or the program's folder"
                ),
            ));
        };
        if self.ngc.calls.len() >= NGC_MAX_CALLS {
            return Err(self.runner_alarm(
                Condition::MacroCallNesting,
                here.line,
                format!("o{key} call: subroutine calls nested deeper than {NGC_MAX_CALLS} levels"),
            ));
        }
        if let Err(e) = self.macros.vars.ngc_call(args) {
            return Err(self.macro_alarm(here.line, e));
        }
        self.macros.vars.set_global("_value_returned", 0.0);
        self.ngc.calls.push(NgcCall {
            return_to: after,
            body: body.offset,
        });
        self.jump_on(body)
    }

    /// `endsub`/`return`: back to the caller.
    fn ngc_return(&mut self, value: Option<f64>) -> Result<(), RunError> {
        let Some(call) = self.ngc.calls.pop() else {
            return Ok(());
        };
        self.macros.vars.ngc_return();
        let level = self.ngc.calls.len();
        self.ngc.blocks.retain(|b| b.level <= level);
        self.macros.vars.set_global("_value", value.unwrap_or(0.0));
        self.macros
            .vars
            .set_global("_value_returned", if value.is_some() { 1.0 } else { 0.0 });
        self.jump_on(call.return_to)
    }

    /// Looks for `o<key> sub` ahead in the main program (recording every
    /// definition passed), then in the library file `key.ngc`.
    fn find_sub(&mut self, key: &str) -> Result<Option<Mark>, RunError> {
        let resume = Mark {
            offset: self.source.position(),
            line: self.next_line,
        };
        let mut found = None;
        if super::library::file_of(self.scanned.offset) == 0 {
            self.source.seek(self.scanned.offset)?;
            let mut line = self.scanned.line;
            while let Some(mark) = self.scan_line(&mut line)? {
                if let Some((k, OKind::Sub)) = oword_of(&self.scan_text) {
                    let body = Mark {
                        offset: self.source.position(),
                        line: mark.line + 1,
                    };
                    self.ngc.subs.entry(k.clone()).or_insert(body);
                    if k == key {
                        found = Some(body);
                        break;
                    }
                }
            }
        }
        if found.is_none()
            && let Some(start) = self.source.library_named(key)?
        {
            self.source.seek(start)?;
            let mut line = 1;
            while let Some(mark) = self.scan_line(&mut line)? {
                if let Some((k, OKind::Sub)) = oword_of(&self.scan_text)
                    && k == key
                {
                    let body = Mark {
                        offset: self.source.position(),
                        line: mark.line + 1,
                    };
                    self.ngc.subs.insert(k, body);
                    found = Some(body);
                    break;
                }
            }
        }
        self.source.seek(resume.offset)?;
        self.next_line = resume.line;
        Ok(found)
    }
}

/// Whether a subroutine name can only name a file in the folders of the
/// program memory: no path separator, drive or parent folder, so a
/// program reaches the program memory it was given and nothing else
/// (`o<../x> call`, `o</etc/x> call` are refused).
fn is_plain_name(key: &str) -> bool {
    !key.contains(['/', '\\', ':']) && !key.contains("..")
}

fn kind_name(kind: OKind) -> &'static str {
    match kind {
        OKind::Sub => "sub",
        OKind::EndSub => "endsub",
        OKind::Return => "return",
        OKind::Call => "call",
        OKind::If => "if",
        OKind::ElseIf => "elseif",
        OKind::Else => "else",
        OKind::EndIf => "endif",
        OKind::While => "while",
        OKind::EndWhile => "endwhile",
        OKind::Do => "do",
        OKind::Break => "break",
        OKind::Continue => "continue",
        OKind::Repeat => "repeat",
        OKind::EndRepeat => "endrepeat",
        OKind::Program => "",
    }
}
