//! Program flow: control structures, jumps and program sections.

use fiveaxis_gcode::Span;

use super::eval::{ALARM_SYNTAX, binary};
use super::{Interpreter, LinePos, Section};
use crate::{
    BinOp, JumpKind, JumpTarget, LangError, Statement, System, Value, Var, interp::eval::literal,
};

/// Alarm for a jump whose destination is not found (AV11 p107).
pub(crate) const ALARM_NO_TARGET: u32 = 14080;

/// An open control structure of a program level.
#[derive(Debug)]
pub(crate) enum Structure {
    If {
        open: u64,
    },
    /// The `WHILE` line, read again at `ENDWHILE`.
    While {
        open: LinePos,
    },
    For {
        open: u64,
        var: Var,
        to: f64,
        body: LinePos,
    },
    Repeat {
        open: u64,
        body: LinePos,
    },
    Loop {
        open: u64,
        body: LinePos,
    },
}

impl Structure {
    fn open(&self) -> u64 {
        match self {
            Self::If { open }
            | Self::For { open, .. }
            | Self::Repeat { open, .. }
            | Self::Loop { open, .. } => *open,
            Self::While { open } => open.pos,
        }
    }
}

/// The kinds of structure, for matching and searching.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    If,
    While,
    For,
    Repeat,
    Loop,
}

impl Kind {
    fn of(s: &Structure) -> Self {
        match s {
            Structure::If { .. } => Self::If,
            Structure::While { .. } => Self::While,
            Structure::For { .. } => Self::For,
            Structure::Repeat { .. } => Self::Repeat,
            Structure::Loop { .. } => Self::Loop,
        }
    }

    fn opener(self) -> &'static str {
        match self {
            Self::If => "IF",
            Self::While => "WHILE",
            Self::For => "FOR",
            Self::Repeat => "REPEAT",
            Self::Loop => "LOOP",
        }
    }
}

/// What a forward search of a structure's end stopped at.
#[derive(PartialEq, Eq)]
enum Stop {
    Else,
    End,
}

fn target_text(t: &JumpTarget) -> String {
    match t {
        JumpTarget::Label(n) => n.text.clone(),
        JumpTarget::Block(n, _) => format!("N{n}"),
    }
}

fn target_span(t: &JumpTarget) -> Span {
    match t {
        JumpTarget::Label(n) => n.span,
        JumpTarget::Block(_, s) => *s,
    }
}

impl Interpreter<'_> {
    /// A control-structure statement or a conditional jump.
    pub(super) fn flow(
        &mut self,
        statement: Statement,
        at: LinePos,
        sys: &mut dyn System,
    ) -> Result<(), LangError> {
        match statement {
            Statement::If(cond) => {
                // True: run the branch; false: on after the ELSE (the
                // structure stays open to its ENDIF) or the ENDIF.
                let open = self.condition(&cond, sys)?
                    || self.skip_to_end(Kind::If, at, true)? == Stop::Else;
                if open {
                    self.top_mut()
                        .structures
                        .push(Structure::If { open: at.pos });
                }
            }
            Statement::Else => {
                self.close(Kind::If, "ELSE")?;
                self.skip_to_end(Kind::If, at, false)?;
            }
            Statement::EndIf => {
                self.close(Kind::If, "ENDIF")?;
            }
            Statement::While(cond) => {
                if self.condition(&cond, sys)? {
                    self.top_mut()
                        .structures
                        .push(Structure::While { open: at });
                } else {
                    self.skip_to_end(Kind::While, at, false)?;
                }
            }
            Statement::EndWhile => {
                if let Some(Structure::While { open }) = self.close(Kind::While, "ENDWHILE")? {
                    self.seek(open)?;
                }
            }
            Statement::For { variable, from, to } => {
                let from = self.eval(&from, sys)?;
                self.write_var(&variable, from, sys)?;
                let to_value = self.eval(&to, sys)?;
                let Some(to_number) = to_value.as_f64() else {
                    return Err(self.error(
                        Some(super::vars::ALARM_CONVERSION),
                        to.span,
                        "the end value of FOR is not a number".to_string(),
                    ));
                };
                if self.counter_within(&variable, to_number, sys)? {
                    let body = self.top().next;
                    self.top_mut().structures.push(Structure::For {
                        open: at.pos,
                        var: variable,
                        to: to_number,
                        body,
                    });
                } else {
                    self.skip_to_end(Kind::For, at, false)?;
                }
            }
            Statement::EndFor => {
                let n = self.find(Kind::For, "ENDFOR")?;
                let top = self.frames.len() - 1;
                self.frames[top].structures.truncate(n + 1);
                let Some(Structure::For { var, to, body, .. }) = self.frames[top].structures.last()
                else {
                    return Ok(());
                };
                let (var, to, body) = (var.clone(), *to, *body);
                let value = self.read_var(&var, sys)?;
                let next =
                    binary(BinOp::Add, value, literal(1.0), var.span).map_err(|f| self.fault(f))?;
                self.write_var(&var, next, sys)?;
                if self.counter_within(&var, to, sys)? {
                    self.seek(body)?;
                } else {
                    self.top_mut().structures.pop();
                }
            }
            Statement::Repeat => {
                let body = self.top().next;
                self.top_mut()
                    .structures
                    .push(Structure::Repeat { open: at.pos, body });
            }
            Statement::Until(cond) => {
                let n = self.find(Kind::Repeat, "UNTIL")?;
                let top = self.frames.len() - 1;
                self.frames[top].structures.truncate(n + 1);
                let body = match self.frames[top].structures.last() {
                    Some(Structure::Repeat { body, .. }) => *body,
                    _ => return Ok(()),
                };
                if self.condition(&cond, sys)? {
                    self.top_mut().structures.pop();
                } else {
                    self.seek(body)?;
                }
            }
            Statement::Loop => {
                let body = self.top().next;
                self.top_mut()
                    .structures
                    .push(Structure::Loop { open: at.pos, body });
            }
            Statement::EndLoop => {
                let n = self.find(Kind::Loop, "ENDLOOP")?;
                let top = self.frames.len() - 1;
                self.frames[top].structures.truncate(n + 1);
                if let Some(Structure::Loop { body, .. }) = self.frames[top].structures.last() {
                    let body = *body;
                    self.seek(body)?;
                }
            }
            Statement::IfJump { condition, jump } if self.condition(&condition, sys)? => {
                self.jump(&jump)?;
            }
            Statement::Case {
                selector,
                arms,
                default,
            } => {
                let value = self.eval(&selector, sys)?;
                for (constant, jump) in &arms {
                    let c = self.eval(constant, sys)?;
                    let equal = binary(BinOp::Eq, value.clone(), c, constant.span)
                        .map_err(|f| self.fault(f))?;
                    if equal == Value::Bool(true) {
                        return self.jump(jump);
                    }
                }
                if let Some(jump) = default {
                    self.jump(&jump)?;
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// Whether a `FOR` counter is still at most the end value.
    fn counter_within(
        &mut self,
        var: &Var,
        to: f64,
        sys: &mut dyn System,
    ) -> Result<bool, LangError> {
        let value = self.read_var(var, sys)?;
        let Some(x) = value.as_f64() else {
            return Err(self.error(
                Some(super::vars::ALARM_CONVERSION),
                var.span,
                "the FOR counter is not a number".to_string(),
            ));
        };
        Ok(x <= to + super::REAL_TOLERANCE * to.abs())
    }

    /// The index of the innermost open structure of `kind`; alarm 12080
    /// when there is none.
    fn find(&self, kind: Kind, keyword: &str) -> Result<usize, LangError> {
        self.top()
            .structures
            .iter()
            .rposition(|s| Kind::of(s) == kind)
            .ok_or_else(|| {
                self.error(
                    Some(ALARM_SYNTAX),
                    self.line_span(),
                    format!("{keyword} without {}", kind.opener()),
                )
            })
    }

    /// Closes the innermost open structure of `kind` (and any left open
    /// above it by a jump), giving it back.
    fn close(&mut self, kind: Kind, keyword: &str) -> Result<Option<Structure>, LangError> {
        let n = self.find(kind, keyword)?;
        let top = self.top_mut();
        top.structures.truncate(n + 1);
        Ok(top.structures.pop())
    }

    /// Reads forward from the structure opened at `at` to its `ELSE`
    /// (when `stop_at_else`) or its end, counting nested structures of
    /// the same kind. The next line read is the one after the stop.
    fn skip_to_end(
        &mut self,
        kind: Kind,
        at: LinePos,
        stop_at_else: bool,
    ) -> Result<Stop, LangError> {
        let mut depth = 0usize;
        let opener = self.line_span();
        loop {
            let Some(read) = self.read_line()? else {
                let top = self.top();
                return Err(LangError {
                    alarm: Some(ALARM_SYNTAX),
                    program: top.program,
                    line: at.line,
                    span: opener,
                    message: format!("{} without its end: the program ends first", kind.opener()),
                });
            };
            if read.skipped {
                continue;
            }
            let Ok(line) = read.parsed else { continue };
            let (opens, closes) = match (&line.statement, kind) {
                (Statement::If(_), Kind::If)
                | (Statement::While(_), Kind::While)
                | (Statement::For { .. }, Kind::For)
                | (Statement::Repeat, Kind::Repeat)
                | (Statement::Loop, Kind::Loop) => (true, false),
                (Statement::EndIf, Kind::If)
                | (Statement::EndWhile, Kind::While)
                | (Statement::EndFor, Kind::For)
                | (Statement::Until(_), Kind::Repeat)
                | (Statement::EndLoop, Kind::Loop) => (false, true),
                (Statement::Else, Kind::If) if depth == 0 && stop_at_else => return Ok(Stop::Else),
                _ => (false, false),
            };
            if opens {
                depth += 1;
            } else if closes {
                if depth == 0 {
                    return Ok(Stop::End);
                }
                depth -= 1;
            }
        }
    }

    /// Carries out a jump from the line being run.
    pub(super) fn jump(&mut self, jump: &crate::Jump) -> Result<(), LangError> {
        let at = self.top().cur;
        let after = self.top().next;
        let Some(target) = &jump.target else {
            // GOTOS
            self.top_mut().structures.clear();
            return self.seek(LinePos::START);
        };
        let found = match jump.kind {
            JumpKind::Gotof => self.search_forward(target, at, after)?,
            JumpKind::Gotob => self.search_backward(target, at)?,
            JumpKind::Goto | JumpKind::Gotoc => match self.search_forward(target, at, after)? {
                Some(t) => Some(t),
                None => self.search_backward(target, at)?,
            },
            JumpKind::Gotos => Some(LinePos::START),
        };
        match found {
            Some(t) => {
                if t.pos <= at.pos {
                    self.top_mut().structures.retain(|s| s.open() < t.pos);
                }
                self.seek(t)
            }
            None if jump.kind == JumpKind::Gotoc => self.seek(after),
            None => {
                self.seek(after)?;
                let top = self.top();
                Err(LangError {
                    alarm: Some(ALARM_NO_TARGET),
                    program: top.program,
                    line: at.line,
                    span: target_span(target),
                    message: format!("jump destination {} not found", target_text(target)),
                })
            }
        }
    }

    /// The nearest line after `at` that `target` names.
    fn search_forward(
        &mut self,
        target: &JumpTarget,
        at: LinePos,
        after: LinePos,
    ) -> Result<Option<LinePos>, LangError> {
        let from = match target {
            JumpTarget::Label(name) => {
                let info = self.top();
                if let Some(p) = info
                    .labels
                    .get(&name.text)
                    .and_then(|v| v.iter().find(|p| p.pos > at.pos))
                {
                    return Ok(Some(*p));
                }
                // Not in the text read so far: read on from its end.
                info.high_water
            }
            JumpTarget::Block(..) => after,
        };
        self.seek(from)?;
        while let Some(read) = self.read_line()? {
            let Ok(line) = read.parsed else { continue };
            let hit = match target {
                JumpTarget::Label(name) => line.label.is_some_and(|l| l.text == name.text),
                JumpTarget::Block(n, _) => line.number.is_some_and(|b| b.value == *n),
            };
            if hit {
                return Ok(Some(read.at));
            }
        }
        Ok(None)
    }

    /// The nearest line at or before `at` that `target` names.
    fn search_backward(
        &mut self,
        target: &JumpTarget,
        at: LinePos,
    ) -> Result<Option<LinePos>, LangError> {
        match target {
            JumpTarget::Label(name) => Ok(self
                .top()
                .labels
                .get(&name.text)
                .and_then(|v| v.iter().rev().find(|p| p.pos <= at.pos))
                .copied()),
            JumpTarget::Block(n, _) => {
                self.seek(LinePos::START)?;
                let mut last = None;
                while self.top().next.pos <= at.pos {
                    let Some(read) = self.read_line()? else { break };
                    if let Ok(line) = read.parsed
                        && line.number.is_some_and(|b| b.value == *n)
                    {
                        last = Some(read.at);
                    }
                }
                Ok(last)
            }
        }
    }

    /// `CALL BLOCK start TO end`: runs the section and comes back after
    /// the line of the call.
    pub(super) fn call_block(
        &mut self,
        start: &JumpTarget,
        end: Option<JumpTarget>,
        span: Span,
    ) -> Result<(), LangError> {
        let at = self.top().cur;
        let after = self.top().next;
        if self.top().sections.len() >= super::MAX_LEVELS {
            return Err(self.error(
                None,
                span,
                format!("CALL BLOCK nested more than {} deep", super::MAX_LEVELS),
            ));
        }
        let found = match self.search_forward(start, at, after)? {
            Some(t) => Some(t),
            None => self.search_backward(start, at)?,
        };
        let Some(t) = found else {
            self.seek(after)?;
            return Err(LangError {
                alarm: Some(ALARM_NO_TARGET),
                program: self.top().program,
                line: at.line,
                span: target_span(start),
                message: format!("CALL BLOCK: start {} not found", target_text(start)),
            });
        };
        let structures = self.top().structures.len();
        self.top_mut().sections.push(Section {
            back: after,
            end,
            structures,
        });
        self.seek(t)
    }
}
