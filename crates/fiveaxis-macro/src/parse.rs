//! The parser: one prepared line into a [`Line`].
//!
//! A recursive-descent parser over the bytes [`crate::scan::prepare`] kept.
//! Recursion only happens at brackets, and brackets nest at most
//! [`MAX_BRACKET_DEPTH`] levels (deeper is alarm PS0118, raised as soon as
//! the sixth `[` is read) and a line holds at most [`MAX_OPERATIONS`]
//! binary operations, so no input can overflow the stack. A unary sign
//! may stand once before an operand (`--1` is a format error), which keeps
//! the remaining recursion bounded too.
//!
//! Expressions are typed while they are read: comparisons give truth
//! values, which only `IF`, `WHILE` and `AND`/`OR`/`XOR` between two truth
//! values accept; every other operator, function and statement wants
//! numbers. A mismatch is a format error (PS0114) at the operand.

use fiveaxis_gcode::{Code, MAX_DIGITS, Span};

use crate::error::{MacroError, MacroErrorKind};
use crate::expr::{
    BinOp, Binary, Call, Expr, Func, Line, NcBlock, NcWord, Statement, Var, VarNumber, WordValue,
};
use crate::scan::{Char, prepare, span};

/// How deep brackets may nest, function brackets and the brackets of `IF`,
/// `WHILE` and `#[…]` included (FANUC: five levels, alarm PS0118).
pub const MAX_BRACKET_DEPTH: u8 = 5;

/// The most binary operations one line may hold. Operators of one level
/// chain without brackets (`1+1+1+…`) into a tree as deep as the chain;
/// this bound keeps evaluating, printing and dropping the tree within a
/// small stack (decision: FANUC bounds a block's length instead).
pub const MAX_OPERATIONS: usize = 256;

/// The highest direct variable number accepted by the parser; larger
/// numbers are alarm PS0115 at once.
const MAX_VARIABLE_NUMBER: u64 = 99_999_999;

/// The powers of ten that `f64` holds exactly.
const POWERS_OF_TEN: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Parses one program line (without line end) of custom macro B or plain
/// NC syntax into a [`Line`]; `line` is its 1-based number.
///
/// # Errors
///
/// The first alarm of the line: format errors (PS0114, PS0125), too many
/// digits (PS0003), brackets nested too deep (PS0118), an illegal loop
/// number (PS0126), an NC and a macro statement together (PS0127), a
/// variable number too large (PS0115).
pub fn parse_statement(text: &[u8], line: u32) -> Result<Line, MacroError> {
    let prepared = prepare(text)?;
    let mut parser = Parser {
        chars: &prepared.chars,
        pos: 0,
        depth: 0,
        operations: 0,
        len: prepared.len,
    };
    let mut nc = NcBlock {
        line,
        block_delete: prepared.block_delete,
        tape_mark: prepared.tape_mark,
        ..NcBlock::default()
    };
    let sequence = if parser.at_sequence() {
        parser.pos += 1;
        Some(parser.sequence_number()?)
    } else {
        None
    };
    nc.sequence = sequence;
    let statement = parser.statement(nc)?;
    let sequence = match &statement {
        Statement::Nc(nc) => nc.sequence,
        _ => sequence,
    };
    Ok(Line {
        line,
        sequence,
        block_delete: prepared.block_delete,
        comment: prepared.comment,
        statement,
    })
}

/// Whether an expression gives a number or a truth value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ty {
    Number,
    Bool,
}

/// A parsed expression with its type and its range of kept bytes.
struct Typed {
    expr: Expr,
    ty: Ty,
    start: usize,
    end: usize,
}

struct Parser<'a> {
    chars: &'a [Char],
    pos: usize,
    depth: u8,
    /// Binary operations read so far in the line.
    operations: usize,
    /// Length of the line in bytes, for spans at its end.
    len: usize,
}

/// Statement keywords, longest first where one is a prefix of another.
/// `ENDIF` before `END` and `ELSE` before neither: a keyword is found as
/// the start of a run of letters.
const STATEMENT_KEYWORDS: [&[u8]; 7] = [b"WHILE", b"GOTO", b"ENDIF", b"ELSE", b"END", b"IF", b"DO"];

impl Parser<'_> {
    fn peek(&self) -> Option<u8> {
        self.chars.get(self.pos).map(|c| c.byte)
    }

    fn peek_at(&self, pos: usize) -> Option<u8> {
        self.chars.get(pos).map(|c| c.byte)
    }

    /// The span of kept bytes `start..end`.
    fn span(&self, start: usize, end: usize) -> Span {
        let first = self.chars.get(start).map(|c| c.index as usize);
        let last = end
            .checked_sub(1)
            .and_then(|i| self.chars.get(i))
            .map(|c| c.index as usize + 1);
        match (first, last) {
            (Some(first), Some(last)) if last > first => span(first, last),
            (Some(first), _) => span(first, first + 1),
            _ => span(self.len, self.len + 1),
        }
    }

    fn error(
        &self,
        kind: MacroErrorKind,
        start: usize,
        end: usize,
        msg: impl Into<String>,
    ) -> MacroError {
        MacroError::new(kind, self.span(start, end), msg)
    }

    /// The text of kept bytes `start..end`, for messages.
    fn text(&self, start: usize, end: usize) -> String {
        self.chars
            .get(start..end)
            .unwrap_or_default()
            .iter()
            .map(|c| {
                if c.byte.is_ascii_graphic() {
                    char::from(c.byte)
                } else {
                    '?'
                }
            })
            .collect()
    }

    /// The run of letters at `pos`: its end.
    fn letters_end(&self, pos: usize) -> usize {
        let mut end = pos;
        while self.peek_at(end).is_some_and(|b| b.is_ascii_uppercase()) {
            end += 1;
        }
        end
    }

    /// Whether the run of letters at the cursor starts with `word`. Blanks
    /// are gone, so a keyword may run into the name after it
    /// (`#1 LE ABS[#2]` is `#1LEABS[#2]`): keywords are matched as prefixes
    /// wherever only a keyword can stand.
    fn at_word(&self, word: &[u8]) -> bool {
        let end = self.letters_end(self.pos);
        end - self.pos >= word.len()
            && self
                .chars
                .get(self.pos..end)
                .is_some_and(|cs| cs.iter().zip(word).all(|(c, w)| c.byte == *w))
    }

    fn word_at(&self, pos: usize) -> Vec<u8> {
        let end = self.letters_end(pos);
        self.chars
            .get(pos..end)
            .unwrap_or_default()
            .iter()
            .map(|c| c.byte)
            .collect()
    }

    /// `N` followed by a digit at the cursor.
    fn at_sequence(&self) -> bool {
        self.peek() == Some(b'N')
            && self.letters_end(self.pos) == self.pos + 1
            && self
                .peek_at(self.pos + 1)
                .is_some_and(|b| b.is_ascii_digit() || b == b'.')
    }

    /// The unsigned integer of an `N` word; the cursor is after the `N`.
    fn sequence_number(&mut self) -> Result<u32, MacroError> {
        let start = self.pos.saturating_sub(1);
        let number = self.number()?;
        if number.decimal_point || number.value > f64::from(u32::MAX) {
            return Err(self.error(
                MacroErrorKind::FormatError,
                start,
                self.pos,
                format!(
                    "sequence number `{}` is not an integer",
                    self.text(start, self.pos)
                ),
            ));
        }
        // The value is an integer that fits u32: the cast is exact.
        Ok(number.value as u32)
    }

    fn at_end(&self) -> bool {
        self.pos >= self.chars.len()
    }

    /// The statement after the optional sequence number.
    fn statement(&mut self, nc: NcBlock) -> Result<Statement, MacroError> {
        let Some(byte) = self.peek() else {
            return Ok(Statement::Nc(nc));
        };
        let statement = if byte == b'#' {
            let (target, value) = self.assignment()?;
            Statement::Assign { target, value }
        } else if byte.is_ascii_uppercase() {
            let start = self.pos;
            let end = self.letters_end(start);
            if end - start == 1 {
                return self.nc_block(nc).map(Statement::Nc);
            }
            let Some(keyword) = STATEMENT_KEYWORDS.iter().find(|k| self.at_word(k)) else {
                return Err(self.unknown_word(start, end));
            };
            self.pos = start + keyword.len();
            match *keyword {
                b"IF" => self.if_statement(start)?,
                b"GOTO" => Statement::Goto(self.numeric(start)?.expr),
                b"WHILE" => self.while_statement(start)?,
                b"DO" => Statement::Do {
                    id: self.loop_id(start)?,
                },
                b"ENDIF" => Statement::EndIf,
                b"ELSE" => Statement::Else,
                _ => Statement::End {
                    id: self.loop_id(start)?,
                },
            }
        } else {
            return Err(self.unexpected());
        };
        self.expect_end()?;
        Ok(statement)
    }

    fn unknown_word(&self, start: usize, end: usize) -> MacroError {
        self.error(
            MacroErrorKind::FormatError,
            start,
            end,
            format!("unknown word `{}`", self.text(start, end)),
        )
    }

    /// The error for the byte at the cursor, which cannot stand there.
    fn unexpected(&self) -> MacroError {
        match self.peek() {
            None => self.error(
                MacroErrorKind::FormatError,
                self.pos,
                self.pos,
                "unexpected end of line",
            ),
            Some(b) => self.error(
                MacroErrorKind::FormatError,
                self.pos,
                self.pos + 1,
                if b.is_ascii_graphic() {
                    format!("unexpected `{}`", char::from(b))
                } else {
                    format!("unexpected byte 0x{b:02X}")
                },
            ),
        }
    }

    /// After a complete statement: nothing may follow. An address word
    /// after a macro statement is PS0127.
    fn expect_end(&self) -> Result<(), MacroError> {
        if self.at_end() {
            return Ok(());
        }
        if self.peek().is_some_and(|b| b.is_ascii_uppercase())
            && self.letters_end(self.pos) == self.pos + 1
        {
            return Err(self.error(
                MacroErrorKind::NcAndMacro,
                self.pos,
                self.chars.len(),
                "an NC word and a macro statement in the same block",
            ));
        }
        Err(self.unexpected())
    }

    fn expect(&mut self, byte: u8) -> Result<(), MacroError> {
        if self.peek() == Some(byte) {
            self.pos += 1;
            Ok(())
        } else {
            Err(match self.peek() {
                None => self.error(
                    MacroErrorKind::FormatError,
                    self.pos,
                    self.pos,
                    format!("`{}` missing at the end of the line", char::from(byte)),
                ),
                Some(_) => {
                    let mut e = self.unexpected();
                    e.message = format!("{} where `{}` was expected", e.message, char::from(byte));
                    e
                }
            })
        }
    }

    /// `#n = expr` or `#[e] = expr`; the cursor is at `#`.
    fn assignment(&mut self) -> Result<(Var, Expr), MacroError> {
        let target = self.variable()?;
        self.expect(b'=')?;
        let value = self.numeric(self.pos)?;
        Ok((target, value.expr))
    }

    /// `IF [cond] GOTO n` or `IF [cond] THEN #n = e`; the cursor is after `IF`.
    fn if_statement(&mut self, start: usize) -> Result<Statement, MacroError> {
        let cond = self.condition(start, "IF")?;
        if self.at_word(b"GOTO") {
            let at = self.pos;
            self.pos += 4;
            let target = self.numeric(at)?.expr;
            Ok(Statement::IfGoto { cond, target })
        } else if self.at_word(b"THEN") {
            self.pos += 4;
            if self.at_end() {
                return Ok(Statement::IfBlock { cond });
            }
            if self.peek() != Some(b'#') {
                return Err(self.statement_error(start, "THEN must be followed by `#n = value`"));
            }
            let (target, value) = self.assignment()?;
            Ok(Statement::IfThen {
                cond,
                target,
                value,
            })
        } else {
            Err(self.statement_error(start, "IF […] must be followed by GOTO or THEN"))
        }
    }

    fn statement_error(&self, start: usize, msg: &str) -> MacroError {
        let end = self.chars.len().max(start + 1);
        self.error(MacroErrorKind::StatementFormat, start, end, msg)
    }

    /// `WHILE [cond] DO m`; the cursor is after `WHILE`.
    fn while_statement(&mut self, start: usize) -> Result<Statement, MacroError> {
        let cond = self.condition(start, "WHILE")?;
        if !self.at_word(b"DO") {
            return Err(self.statement_error(start, "WHILE […] must be followed by DO"));
        }
        let at = self.pos;
        self.pos += 2;
        let id = self.loop_id(at)?;
        Ok(Statement::While { cond, id })
    }

    /// The bracketed condition of `IF`/`WHILE`.
    fn condition(&mut self, start: usize, keyword: &str) -> Result<Expr, MacroError> {
        if self.peek() != Some(b'[') {
            return Err(self.statement_error(
                start,
                &format!("{keyword} must be followed by `[condition]`"),
            ));
        }
        let cond = self.primary()?;
        if cond.ty != Ty::Bool {
            return Err(self.error(
                MacroErrorKind::FormatError,
                cond.start,
                cond.end,
                format!("the condition of {keyword} must be a comparison"),
            ));
        }
        Ok(cond.expr)
    }

    /// The loop number after `DO`/`END`: a constant 1 … 3 (PS0126).
    fn loop_id(&mut self, keyword: usize) -> Result<u8, MacroError> {
        let start = self.pos;
        let digits = self.chars.get(start..).unwrap_or_default().iter();
        let count = digits.take_while(|c| c.byte.is_ascii_digit()).count();
        self.pos += count;
        let id = self
            .chars
            .get(start..self.pos)
            .unwrap_or_default()
            .iter()
            .try_fold(0u8, |acc, c| {
                acc.checked_mul(10)?.checked_add(c.byte - b'0')
            });
        match id {
            Some(id @ 1..=3) if count > 0 => Ok(id),
            _ => {
                let end = if count == 0 {
                    self.letters_end(keyword)
                } else {
                    self.pos
                };
                Err(self.error(
                    MacroErrorKind::IllegalLoopNumber,
                    keyword,
                    end,
                    format!(
                        "`{}`: the loop number must be 1, 2 or 3",
                        self.text(keyword, end)
                    ),
                ))
            }
        }
    }

    /// An NC block: address words up to the end of the line.
    fn nc_block(&mut self, mut nc: NcBlock) -> Result<NcBlock, MacroError> {
        while let Some(byte) = self.peek() {
            let start = self.pos;
            if byte == b'#' {
                return Err(self.error(
                    MacroErrorKind::NcAndMacro,
                    start,
                    self.chars.len(),
                    "an NC block and a macro assignment in the same block",
                ));
            }
            if !byte.is_ascii_uppercase() {
                return Err(self.unexpected());
            }
            let end = self.letters_end(start);
            if end - start > 1 {
                let keyword =
                    STATEMENT_KEYWORDS.iter().any(|k| self.at_word(k)) || self.at_word(b"THEN");
                return Err(if keyword {
                    self.error(
                        MacroErrorKind::NcAndMacro,
                        start,
                        self.chars.len(),
                        format!(
                            "an NC block and the macro statement `{}` in the same block",
                            self.text(start, end)
                        ),
                    )
                } else {
                    self.unknown_word(start, end)
                });
            }
            self.pos += 1;
            if byte == b'N' {
                let at_number = self.peek().is_some_and(|b| b.is_ascii_digit() || b == b'.');
                if !at_number {
                    return Err(self.error(
                        MacroErrorKind::FormatError,
                        start,
                        self.pos,
                        "the sequence number must be written as a number",
                    ));
                }
                let sequence = self.sequence_number()?;
                if nc.sequence.is_some() {
                    return Err(self.error(
                        MacroErrorKind::FormatError,
                        start,
                        self.pos,
                        "more than one sequence number in the block",
                    ));
                }
                nc.sequence = Some(sequence);
                continue;
            }
            let value = self.word_value(start, byte)?;
            nc.words.push(NcWord {
                letter: byte,
                value,
                span: self.span(start, self.pos),
            });
        }
        Ok(nc)
    }

    /// The value of the word whose letter is at `start`; the cursor is
    /// after the letter.
    fn word_value(&mut self, start: usize, letter: u8) -> Result<WordValue, MacroError> {
        let sign = match self.peek() {
            Some(b'-') => {
                self.pos += 1;
                Some(true)
            }
            Some(b'+') => {
                self.pos += 1;
                Some(false)
            }
            _ => None,
        };
        match self.peek() {
            Some(b'0'..=b'9' | b'.') => {
                let number = self.number()?;
                let negative = sign == Some(true);
                Ok(WordValue::Literal {
                    value: if negative {
                        -number.value
                    } else {
                        number.value
                    },
                    decimal_point: number.decimal_point,
                    code: if sign.is_some() { None } else { number.code() },
                })
            }
            Some(b'#' | b'[') => {
                let operand = if self.peek() == Some(b'#') {
                    let var = self.variable()?;
                    Expr::Var(var)
                } else {
                    let inner = self.primary()?;
                    if inner.ty != Ty::Number {
                        return Err(self.type_error(&inner, "an address value"));
                    }
                    inner.expr
                };
                Ok(WordValue::Expr(if sign == Some(true) {
                    Expr::Neg(Box::new(operand))
                } else {
                    operand
                }))
            }
            _ => Err(self.error(
                MacroErrorKind::FormatError,
                start,
                self.pos,
                format!("address `{}` has no value", char::from(letter)),
            )),
        }
    }

    fn type_error(&self, operand: &Typed, what: &str) -> MacroError {
        let (kind, msg) = match operand.ty {
            Ty::Bool => ("a comparison", "a number"),
            Ty::Number => ("a number", "a comparison"),
        };
        self.error(
            MacroErrorKind::FormatError,
            operand.start,
            operand.end,
            format!(
                "`{}` is {kind}, {what} must be {msg}",
                self.text(operand.start, operand.end)
            ),
        )
    }

    /// A whole expression that must be a number.
    fn numeric(&mut self, keyword: usize) -> Result<Typed, MacroError> {
        if self.at_end() {
            return Err(self.error(
                MacroErrorKind::FormatError,
                keyword,
                self.pos,
                format!("`{}` needs a value", self.text(keyword, self.pos)),
            ));
        }
        let e = self.comparison()?;
        if e.ty != Ty::Number {
            return Err(self.type_error(&e, "a value"));
        }
        Ok(e)
    }

    /// The comparison level: `a EQ b`, … (not associative).
    fn comparison(&mut self) -> Result<Typed, MacroError> {
        let lhs = self.additive()?;
        let op = match self.operator_word() {
            Some(op @ (BinOp::Eq | BinOp::Ne | BinOp::Gt | BinOp::Ge | BinOp::Lt | BinOp::Le)) => {
                op
            }
            _ => return Ok(lhs),
        };
        self.pos += 2;
        let rhs = self.additive()?;
        self.binary(op, lhs, rhs)
    }

    /// The operator keyword at the cursor, if any.
    fn operator_word(&self) -> Option<BinOp> {
        const WORDS: [(&[u8], BinOp); 10] = [
            (b"EQ", BinOp::Eq),
            (b"NE", BinOp::Ne),
            (b"GT", BinOp::Gt),
            (b"GE", BinOp::Ge),
            (b"LT", BinOp::Lt),
            (b"LE", BinOp::Le),
            (b"AND", BinOp::And),
            (b"OR", BinOp::Or),
            (b"XOR", BinOp::Xor),
            (b"MOD", BinOp::Mod),
        ];
        WORDS
            .iter()
            .find(|(w, _)| self.at_word(w))
            .map(|(_, op)| *op)
    }

    /// `+ - OR XOR`, left to right.
    fn additive(&mut self) -> Result<Typed, MacroError> {
        let mut lhs = self.multiplicative()?;
        loop {
            let (op, len) = match self.peek() {
                Some(b'+') => (BinOp::Add, 1),
                Some(b'-') => (BinOp::Sub, 1),
                _ => match self.operator_word() {
                    Some(BinOp::Or) => (BinOp::Or, 2),
                    Some(BinOp::Xor) => (BinOp::Xor, 3),
                    _ => return Ok(lhs),
                },
            };
            self.pos += len;
            let rhs = self.multiplicative()?;
            lhs = self.binary(op, lhs, rhs)?;
        }
    }

    /// `* / AND MOD`, left to right.
    fn multiplicative(&mut self) -> Result<Typed, MacroError> {
        let mut lhs = self.unary()?;
        loop {
            let (op, len) = match self.peek() {
                Some(b'*') => (BinOp::Mul, 1),
                Some(b'/') => (BinOp::Div, 1),
                _ => match self.operator_word() {
                    Some(BinOp::And) => (BinOp::And, 3),
                    Some(BinOp::Mod) => (BinOp::Mod, 3),
                    _ => return Ok(lhs),
                },
            };
            self.pos += len;
            let rhs = self.unary()?;
            lhs = self.binary(op, lhs, rhs)?;
        }
    }

    /// Builds `lhs op rhs`, checking the operand types.
    fn binary(&mut self, op: BinOp, lhs: Typed, rhs: Typed) -> Result<Typed, MacroError> {
        self.operations += 1;
        if self.operations > MAX_OPERATIONS {
            return Err(self.error(
                MacroErrorKind::FormatError,
                lhs.start,
                rhs.end,
                format!("more than {MAX_OPERATIONS} operations in one line"),
            ));
        }
        let logical = matches!(op, BinOp::And | BinOp::Or | BinOp::Xor);
        let ty = if logical && lhs.ty == Ty::Bool && rhs.ty == Ty::Bool {
            Ty::Bool
        } else {
            for operand in [&lhs, &rhs] {
                if operand.ty != Ty::Number {
                    return Err(self.type_error(operand, &format!("an operand of {}", op.as_str())));
                }
            }
            if op.is_comparison() {
                Ty::Bool
            } else {
                Ty::Number
            }
        };
        let (start, end) = (lhs.start, rhs.end);
        Ok(Typed {
            expr: Expr::Binary(Box::new(Binary {
                op,
                lhs: lhs.expr,
                rhs: rhs.expr,
                span: self.span(start, end),
            })),
            ty,
            start,
            end,
        })
    }

    /// An operand with at most one sign in front.
    fn unary(&mut self) -> Result<Typed, MacroError> {
        let start = self.pos;
        let negative = match self.peek() {
            Some(b'-') => true,
            Some(b'+') => false,
            _ => return self.primary(),
        };
        self.pos += 1;
        if matches!(self.peek(), Some(b'-' | b'+')) {
            return Err(self.unexpected());
        }
        let operand = self.primary()?;
        if operand.ty != Ty::Number {
            return Err(self.type_error(&operand, "the operand of a sign"));
        }
        Ok(Typed {
            expr: if negative {
                Expr::Neg(Box::new(operand.expr))
            } else {
                operand.expr
            },
            ty: Ty::Number,
            start,
            end: operand.end,
        })
    }

    /// A number, a variable, `[expr]` or a function call.
    fn primary(&mut self) -> Result<Typed, MacroError> {
        let start = self.pos;
        match self.peek() {
            Some(b'0'..=b'9' | b'.') => {
                let number = self.number()?;
                Ok(Typed {
                    expr: Expr::Number(number.value),
                    ty: Ty::Number,
                    start,
                    end: self.pos,
                })
            }
            Some(b'#') => {
                let var = self.variable()?;
                Ok(Typed {
                    expr: Expr::Var(var),
                    ty: Ty::Number,
                    start,
                    end: self.pos,
                })
            }
            Some(b'[') => {
                self.open_bracket()?;
                let inner = self.comparison()?;
                self.close_bracket()?;
                Ok(Typed {
                    start,
                    end: self.pos,
                    ..inner
                })
            }
            Some(b) if b.is_ascii_uppercase() => self.call(),
            _ => Err(self.unexpected()),
        }
    }

    fn open_bracket(&mut self) -> Result<(), MacroError> {
        if self.depth >= MAX_BRACKET_DEPTH {
            return Err(self.error(
                MacroErrorKind::BracketNesting,
                self.pos,
                self.pos + 1,
                format!("brackets nested deeper than {MAX_BRACKET_DEPTH} levels"),
            ));
        }
        self.depth += 1;
        self.pos += 1;
        Ok(())
    }

    fn close_bracket(&mut self) -> Result<(), MacroError> {
        self.expect(b']')?;
        self.depth = self.depth.saturating_sub(1);
        Ok(())
    }

    /// A function call; the cursor is at its name.
    fn call(&mut self) -> Result<Typed, MacroError> {
        let start = self.pos;
        let end = self.letters_end(start);
        let word = self.word_at(start);
        let Some(func) = Func::ALL
            .iter()
            .find(|(name, _)| *name == word.as_slice())
            .map(|(_, f)| *f)
        else {
            return Err(self.error(
                MacroErrorKind::FormatError,
                start,
                end,
                format!("`{}` is not a function", self.text(start, end)),
            ));
        };
        self.pos = end;
        if self.peek() != Some(b'[') {
            return Err(self.error(
                MacroErrorKind::FormatError,
                start,
                end,
                format!("{} must be followed by `[`", func.name()),
            ));
        }
        self.open_bracket()?;
        let arg = self.function_argument(func)?;
        let mut arg2 = None;
        if self.peek() == Some(b',') && matches!(func, Func::Atan | Func::Pow) {
            self.pos += 1;
            arg2 = Some(self.function_argument(func)?);
        }
        self.close_bracket()?;
        // `ATAN[a]/[b]` is the two-argument arc tangent.
        if func == Func::Atan
            && arg2.is_none()
            && self.peek() == Some(b'/')
            && self.peek_at(self.pos + 1) == Some(b'[')
        {
            self.pos += 1;
            self.open_bracket()?;
            arg2 = Some(self.function_argument(func)?);
            self.close_bracket()?;
        }
        if func == Func::Pow && arg2.is_none() {
            return Err(self.error(
                MacroErrorKind::FormatError,
                start,
                self.pos,
                "POW needs two arguments: POW[a,b]",
            ));
        }
        Ok(Typed {
            expr: Expr::Call(Box::new(Call {
                func,
                arg,
                arg2,
                span: self.span(start, self.pos),
            })),
            ty: Ty::Number,
            start,
            end: self.pos,
        })
    }

    fn function_argument(&mut self, func: Func) -> Result<Expr, MacroError> {
        let arg = self.comparison()?;
        if arg.ty != Ty::Number {
            return Err(self.type_error(&arg, &format!("the argument of {}", func.name())));
        }
        Ok(arg.expr)
    }

    /// `#n` or `#[expr]`; the cursor is at `#`.
    fn variable(&mut self) -> Result<Var, MacroError> {
        let start = self.pos;
        self.pos += 1;
        match self.peek() {
            Some(b'0'..=b'9') => {
                let mut number: u64 = 0;
                while let Some(d @ b'0'..=b'9') = self.peek() {
                    number = number
                        .saturating_mul(10)
                        .saturating_add(u64::from(d - b'0'));
                    self.pos += 1;
                }
                if number > MAX_VARIABLE_NUMBER {
                    return Err(self.error(
                        MacroErrorKind::UndefinedVariable,
                        start,
                        self.pos,
                        format!("variable `{}` does not exist", self.text(start, self.pos)),
                    ));
                }
                Ok(Var {
                    // At most MAX_VARIABLE_NUMBER: fits u32.
                    number: VarNumber::Direct(u32::try_from(number).unwrap_or(u32::MAX)),
                    span: self.span(start, self.pos),
                })
            }
            Some(b'[') => {
                self.open_bracket()?;
                let inner = self.comparison()?;
                if inner.ty != Ty::Number {
                    return Err(self.type_error(&inner, "a variable number"));
                }
                self.close_bracket()?;
                Ok(Var {
                    number: VarNumber::Indirect(Box::new(inner.expr)),
                    span: self.span(start, self.pos),
                })
            }
            _ => Err(self.error(
                MacroErrorKind::FormatError,
                start,
                start + 1,
                "`#` must be followed by a variable number or `[`",
            )),
        }
    }

    /// A number `digits [. digits]` at the cursor.
    fn number(&mut self) -> Result<Number, MacroError> {
        let start = self.pos;
        let mut n = Number::default();
        let mut digits = 0usize;
        let mut any_digit = false;
        let mut mantissa: u64 = 0;
        while let Some(b) = self.peek() {
            match b {
                b'0'..=b'9' => {
                    any_digit = true;
                    let d = b - b'0';
                    if n.decimal_point {
                        if n.fraction_digits == 0 {
                            n.first_fraction_digit = d;
                        }
                        n.fraction_digits += 1;
                    } else {
                        n.integer = n.integer.saturating_mul(10).saturating_add(u64::from(d));
                    }
                    if digits > 0 || d != 0 || n.decimal_point {
                        digits += 1;
                    }
                    if digits <= MAX_DIGITS {
                        mantissa = mantissa * 10 + u64::from(d);
                    }
                }
                b'.' if !n.decimal_point => n.decimal_point = true,
                b'.' => {
                    return Err(self.error(
                        MacroErrorKind::FormatError,
                        start,
                        self.pos + 1,
                        "a number with two decimal points",
                    ));
                }
                _ => break,
            }
            self.pos += 1;
        }
        if !any_digit {
            return Err(self.error(
                MacroErrorKind::FormatError,
                start,
                self.pos,
                "`.` is not a number",
            ));
        }
        if digits > MAX_DIGITS {
            return Err(self.error(
                MacroErrorKind::TooManyDigits,
                start,
                self.pos,
                format!(
                    "`{}` has more than {MAX_DIGITS} digits",
                    self.text(start, self.pos)
                ),
            ));
        }
        let power = POWERS_OF_TEN
            .get(n.fraction_digits)
            .copied()
            .unwrap_or(f64::INFINITY);
        // Exact: the mantissa has at most 15 digits (below 2^53) and the
        // power of ten is exact, so the quotient is correctly rounded.
        n.value = mantissa as f64 / power;
        Ok(n)
    }
}

/// A number as written.
#[derive(Debug, Default)]
struct Number {
    value: f64,
    decimal_point: bool,
    /// The integer part, saturated.
    integer: u64,
    fraction_digits: usize,
    first_fraction_digit: u8,
}

impl Number {
    /// The G/M code form, by the rule of the G-code front end: at most one
    /// digit after the point and an integer part that fits `u16` (the
    /// caller leaves signed numbers out).
    fn code(&self) -> Option<Code> {
        if self.fraction_digits > 1 {
            return None;
        }
        let major = u16::try_from(self.integer).ok()?;
        Some(Code::new(major, self.first_fraction_digit))
    }
}
