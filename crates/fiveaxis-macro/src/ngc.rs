//! LinuxCNC's RS274/NGC language: one line into an [`NgcLine`].
//!
//! The same expression tree ([`Expr`]) and evaluator as custom macro B
//! serve both languages; [`crate::MacroSettings::linuxcnc`] selects
//! LinuxCNC's evaluation rules. What differs here is the reading
//! (LinuxCNC 2.9 documentation, `gcode/overview.adoc` and
//! `gcode/o-code.adoc`; behaviour checked with the `rs274` binary):
//!
//! * blanks and tabs are dropped anywhere outside comments; letters are
//!   case-insensitive; a named parameter's name is lower-cased with its
//!   blanks removed (`#<P a R am>` is `#<param>`);
//! * `( … )` comments (the first `)` ends one) and `;` comments to the end
//!   of the line (a `;` inside parentheses is comment text). The last
//!   comment of the line is kept ([`NgcLine::comment`]): `MSG`, `DEBUG`,
//!   `PRINT`, `LOG…`, `ABORT` comments are reported by the runner;
//! * `/` as the first character is block delete; `%` alone is a tape mark;
//! * an `N` number at the start;
//! * numbers `[+|-] digits [. digits]` taken as written (no least input
//!   increment);
//! * parameters `#n`, `##n`, `#[expr]`, `#<name>`; assignments `#… = value`
//!   anywhere in the line (the runner applies them after the line is read);
//! * expressions in brackets: `**` (highest), `* / MOD`, `+ -`,
//!   `EQ NE GT GE LT LE`, `AND OR XOR` (lowest), each group left to right;
//!   a unary sign binds to its operand (`-2**2` is 4); functions `ABS ACOS
//!   ASIN COS EXP FIX FUP ROUND LN SIN SQRT TAN` of a bracketed argument,
//!   `ATAN[a]/[b]`, `EXISTS[#<name>]`;
//! * a word's value is a number, a parameter, a bracketed expression or a
//!   function (`X SIN[30]`), optionally signed;
//! * o-words: `o100`/`o<name>`/`o[expr]` followed by `sub`, `endsub`,
//!   `return`, `call`, `if`, `elseif`, `else`, `endif`, `while`,
//!   `endwhile`, `do`, `break`, `continue`, `repeat`, `endrepeat`, with
//!   their bracketed arguments; nothing else may share the line.
//!
//! Recursion happens only at brackets, at most [`MAX_NGC_DEPTH`] deep.
//! Signs and `#` in a row are read in a loop, at most [`MAX_NGC_SIGNS`]
//! and [`MAX_NGC_INDIRECTION`] of them, and a line holds at most
//! [`MAX_NGC_OPERATIONS`] binary operations: no line can make the tree
//! deep enough to overflow a small stack when it is read, evaluated or
//! dropped.

use fiveaxis_gcode::{Code, Span};

use crate::error::{MacroError, MacroErrorKind};
use crate::expr::{BinOp, Binary, Call, Expr, Func, NcBlock, NcWord, Var, VarNumber, WordValue};

/// How deep brackets may nest in one line (a bound of the kernel, so that
/// no line can overflow the stack; LinuxCNC's own limit is not documented).
pub const MAX_NGC_DEPTH: u8 = 32;

/// Most unary signs in a row before one operand (`--1` has two). A bound
/// of the kernel that real programs do not come near; LinuxCNC reads any
/// number of them.
pub const MAX_NGC_SIGNS: usize = 8;

/// Most `#` in a row before a parameter number, name or bracket: `##1`
/// (the parameter whose number is in `#1`) has two. A bound of the
/// kernel; each `#` is one more level of the tree.
pub const MAX_NGC_INDIRECTION: usize = 4;

/// Most binary operations in one line. Operators of one group chain
/// without brackets (`1+1+1+…`) into a tree as deep as the chain; this
/// bound keeps evaluating and dropping the tree within a small stack (the
/// same bound as custom macro B's `MAX_OPERATIONS`).
pub const MAX_NGC_OPERATIONS: usize = 256;

/// Longest named parameter or o-word name kept.
const MAX_NAME: usize = 127;

/// One line of an RS274/NGC program, parsed.
#[derive(Clone, Debug, PartialEq)]
pub struct NgcLine {
    /// 1-based line number.
    pub line: u32,
    /// The line starts with `/`.
    pub block_delete: bool,
    /// The `N` number, if any.
    pub sequence: Option<u32>,
    /// The o-word statement, if the line holds one.
    pub oword: Option<OWord>,
    /// Parameter assignments, in the order written.
    pub assignments: Vec<(Var, Expr)>,
    /// The NC words (none for an o-word line).
    pub nc: NcBlock,
    /// The last comment of the line.
    pub comment: Option<Comment>,
}

/// A comment the run may act upon.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Comment {
    /// An ordinary comment.
    Plain(String),
    /// `(MSG, text)`.
    Msg(String),
    /// `(DEBUG, text)`, parameters substituted when shown.
    Debug(String),
    /// `(PRINT, text)`, parameters substituted when shown.
    Print(String),
    /// `(ABORT, text)`: the program stops with this message.
    Abort(String),
    /// `(LOGOPEN,…)`, `(LOGAPPEND,…)`, `(LOGCLOSE)`, `(LOG,…)`: the
    /// interpreter's log file, which the kernel does not write.
    Log(String),
}

/// An o-word statement.
#[derive(Clone, Debug, PartialEq)]
pub struct OWord {
    /// The label: `o100`, `o<name>`, or computed `o[expr]`.
    pub label: OLabel,
    /// Columns of the `o…` label.
    pub span: Span,
    /// What it does.
    pub kind: OKind,
    /// Bracketed arguments (`call`'s arguments; the condition of
    /// `if`/`elseif`/`while`; `repeat`'s count; `return`/`endsub`'s value).
    pub args: Vec<Expr>,
}

/// An o-word label.
#[derive(Clone, Debug, PartialEq)]
pub enum OLabel {
    /// `o100`.
    Number(u32),
    /// `o<name>` (lower case, no blanks).
    Name(Box<str>),
    /// `o[expr]`.
    Computed(Expr),
}

/// The keyword of an o-word.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OKind {
    /// `sub`
    Sub,
    /// `endsub [value]`
    EndSub,
    /// `return [value]`
    Return,
    /// `call [a] [b] …`
    Call,
    /// `if [cond]`
    If,
    /// `elseif [cond]`
    ElseIf,
    /// `else`
    Else,
    /// `endif`
    EndIf,
    /// `while [cond]` (the head of a while loop or the tail of a do loop)
    While,
    /// `endwhile`
    EndWhile,
    /// `do`
    Do,
    /// `break`
    Break,
    /// `continue`
    Continue,
    /// `repeat [n]`
    Repeat,
    /// `endrepeat`
    EndRepeat,
    /// A bare `o100` (a numbered program for `M98`).
    Program,
}

const OKINDS: [(&[u8], OKind); 15] = [
    (b"ENDSUB", OKind::EndSub),
    (b"ENDWHILE", OKind::EndWhile),
    (b"ENDREPEAT", OKind::EndRepeat),
    (b"ENDIF", OKind::EndIf),
    (b"ELSEIF", OKind::ElseIf),
    (b"ELSE", OKind::Else),
    (b"SUB", OKind::Sub),
    (b"RETURN", OKind::Return),
    (b"CALL", OKind::Call),
    (b"IF", OKind::If),
    (b"WHILE", OKind::While),
    (b"DO", OKind::Do),
    (b"BREAK", OKind::Break),
    (b"CONTINUE", OKind::Continue),
    (b"REPEAT", OKind::Repeat),
];

const FUNCTIONS: [(&[u8], Func); 14] = [
    (b"EXISTS", Func::Exists),
    (b"ROUND", Func::Round),
    (b"ACOS", Func::Acos),
    (b"ASIN", Func::Asin),
    (b"ATAN", Func::Atan),
    (b"SQRT", Func::Sqrt),
    (b"ABS", Func::Abs),
    (b"COS", Func::Cos),
    (b"EXP", Func::Exp),
    (b"FIX", Func::Fix),
    (b"FUP", Func::Fup),
    (b"SIN", Func::Sin),
    (b"TAN", Func::Tan),
    (b"LN", Func::Ln),
];

/// Operator words and symbols by precedence group, lowest first.
const GROUPS: [&[(&[u8], BinOp)]; 5] = [
    &[
        (b"AND", BinOp::And),
        (b"XOR", BinOp::Xor),
        (b"OR", BinOp::Or),
    ],
    &[
        (b"EQ", BinOp::Eq),
        (b"NE", BinOp::Ne),
        (b"GT", BinOp::Gt),
        (b"GE", BinOp::Ge),
        (b"LT", BinOp::Lt),
        (b"LE", BinOp::Le),
    ],
    &[(b"+", BinOp::Add), (b"-", BinOp::Sub)],
    &[(b"*", BinOp::Mul), (b"/", BinOp::Div), (b"MOD", BinOp::Mod)],
    &[(b"**", BinOp::Pow)],
];

/// A kept byte and its 0-based index in the line.
#[derive(Clone, Copy, Debug)]
struct Kept {
    byte: u8,
    index: u32,
}

/// Parses one line of RS274/NGC (without its line end).
///
/// # Errors
///
/// The first error of the line, with its columns: a format error
/// ([`MacroErrorKind::FormatError`]) for text that cannot be read,
/// [`MacroErrorKind::BracketNesting`] past [`MAX_NGC_DEPTH`], a format
/// error past [`MAX_NGC_SIGNS`], [`MAX_NGC_INDIRECTION`] or
/// [`MAX_NGC_OPERATIONS`].
pub fn parse_ngc_line(text: &[u8], line: u32) -> Result<NgcLine, MacroError> {
    let mut kept = Vec::with_capacity(text.len());
    let mut out = NgcLine {
        line,
        block_delete: false,
        sequence: None,
        oword: None,
        assignments: Vec::new(),
        nc: NcBlock {
            line,
            ..NcBlock::default()
        },
        comment: None,
    };
    prepare(text, &mut kept, &mut out)?;
    let mut p = Parser {
        kept: &kept,
        pos: 0,
        depth: 0,
        operations: 0,
        len: text.len(),
    };
    if p.peek() == Some(b'%') && kept.len() == 1 {
        out.nc.tape_mark = true;
        return Ok(out);
    }
    if p.peek() == Some(b'N') && p.peek_at(1).is_some_and(|b| b.is_ascii_digit()) {
        p.pos += 1;
        let start = p.pos;
        let n = p.unsigned()?;
        out.sequence = Some(
            u32::try_from(n).map_err(|_| p.error(start, p.pos, "the line number is too large"))?,
        );
        out.nc.sequence = out.sequence;
    }
    if p.peek() == Some(b'O') {
        out.oword = Some(p.oword()?);
        if !p.at_end() {
            return Err(p.error(
                p.pos,
                kept.len(),
                "an o-word takes no other words on its line",
            ));
        }
        return Ok(out);
    }
    while let Some(byte) = p.peek() {
        let start = p.pos;
        if byte == b'#' {
            let var = p.parameter()?;
            if p.peek() != Some(b'=') {
                return Err(p.error(
                    start,
                    p.pos,
                    "a parameter standing alone must be assigned: `#n = value`",
                ));
            }
            p.pos += 1;
            let value = p.real_value()?;
            out.assignments.push((var, value));
            continue;
        }
        if !byte.is_ascii_uppercase() {
            return Err(p.unexpected());
        }
        p.pos += 1;
        if p.peek().is_some_and(|b| b.is_ascii_uppercase()) && p.function_at().is_none() {
            let end = p.letters_end(start);
            return Err(p.error(start, end, format!("unknown word `{}`", p.text(start, end))));
        }
        let value = p.word_value(start, byte)?;
        out.nc.words.push(NcWord {
            letter: byte,
            value,
            span: p.span(start, p.pos),
        });
    }
    Ok(out)
}

/// Drops blanks, upper-cases letters (lower-cases names in `< >`), takes
/// comments out, notes block delete.
fn prepare(text: &[u8], kept: &mut Vec<Kept>, out: &mut NgcLine) -> Result<(), MacroError> {
    let mut i = 0;
    let mut first = true;
    let mut in_name = false;
    while let Some(&byte) = text.get(i) {
        let index = u32::try_from(i).unwrap_or(u32::MAX);
        match byte {
            b' ' | b'\t' | b'\r' | b'\n' => {}
            b'(' if !in_name => {
                let body = text.get(i + 1..).unwrap_or_default();
                let Some(close) = body.iter().position(|&b| b == b')') else {
                    return Err(MacroError::new(
                        MacroErrorKind::FormatError,
                        crate::scan::span(i, text.len()),
                        "comment is not closed",
                    ));
                };
                let inner = body.get(..close).unwrap_or_default();
                if inner.contains(&b'(') {
                    return Err(MacroError::new(
                        MacroErrorKind::FormatError,
                        crate::scan::span(i, i + close + 2),
                        "nested comment found",
                    ));
                }
                out.comment = Some(comment(inner));
                i += close + 2;
                first = false;
                continue;
            }
            b';' if !in_name => {
                out.comment = Some(comment(text.get(i + 1..).unwrap_or_default()));
                break;
            }
            b'/' if first => out.block_delete = true,
            _ => {
                if byte == b'<' {
                    in_name = true;
                } else if byte == b'>' {
                    in_name = false;
                }
                let byte = if in_name {
                    byte.to_ascii_lowercase()
                } else {
                    byte.to_ascii_uppercase()
                };
                if !byte.is_ascii() {
                    return Err(MacroError::new(
                        MacroErrorKind::FormatError,
                        crate::scan::span(i, i + 1),
                        format!("byte 0x{byte:02x} is not G-code"),
                    ));
                }
                kept.push(Kept { byte, index });
            }
        }
        if !matches!(byte, b' ' | b'\t') {
            first = false;
        }
        i += 1;
    }
    Ok(())
}

/// A comment's kind from its text (LinuxCNC: the keyword before the comma,
/// any case, blanks before it allowed).
fn comment(inner: &[u8]) -> Comment {
    let text = String::from_utf8_lossy(inner).into_owned();
    let trimmed = text.trim_start();
    let upper: String = trimmed
        .chars()
        .take(10)
        .collect::<String>()
        .to_ascii_uppercase();
    let after = |n: usize| trimmed.get(n..).unwrap_or("").to_owned();
    if upper.starts_with("MSG,") {
        Comment::Msg(after(4))
    } else if upper.starts_with("DEBUG,") {
        Comment::Debug(after(6))
    } else if upper.starts_with("PRINT,") {
        Comment::Print(after(6))
    } else if upper.starts_with("ABORT,") {
        Comment::Abort(after(6))
    } else if upper.starts_with("LOG") {
        Comment::Log(text)
    } else {
        Comment::Plain(text)
    }
}

struct Parser<'a> {
    kept: &'a [Kept],
    pos: usize,
    depth: u8,
    operations: usize,
    len: usize,
}

impl Parser<'_> {
    fn peek(&self) -> Option<u8> {
        self.peek_at(0)
    }

    fn peek_at(&self, ahead: usize) -> Option<u8> {
        self.kept.get(self.pos + ahead).map(|k| k.byte)
    }

    fn at_end(&self) -> bool {
        self.pos >= self.kept.len()
    }

    fn span(&self, start: usize, end: usize) -> Span {
        let first = self.kept.get(start).map(|k| k.index as usize);
        let last = end
            .checked_sub(1)
            .and_then(|i| self.kept.get(i))
            .map(|k| k.index as usize + 1);
        match (first, last) {
            (Some(first), Some(last)) if last > first => crate::scan::span(first, last),
            (Some(first), _) => crate::scan::span(first, first + 1),
            _ => crate::scan::span(self.len, self.len + 1),
        }
    }

    fn text(&self, start: usize, end: usize) -> String {
        self.kept
            .get(start..end.min(self.kept.len()))
            .unwrap_or_default()
            .iter()
            .map(|k| char::from(k.byte))
            .collect()
    }

    fn error(&self, start: usize, end: usize, msg: impl Into<String>) -> MacroError {
        MacroError::new(MacroErrorKind::FormatError, self.span(start, end), msg)
    }

    fn unexpected(&self) -> MacroError {
        match self.peek() {
            None => self.error(self.pos, self.pos, "unexpected end of line"),
            Some(b) => self.error(
                self.pos,
                self.pos + 1,
                format!("bad character `{}` used", char::from(b)),
            ),
        }
    }

    fn letters_end(&self, from: usize) -> usize {
        let mut end = from;
        while self
            .kept
            .get(end)
            .is_some_and(|k| k.byte.is_ascii_uppercase())
        {
            end += 1;
        }
        end
    }

    fn at_word(&self, word: &[u8]) -> bool {
        self.kept
            .get(self.pos..self.pos + word.len())
            .is_some_and(|ks| ks.iter().zip(word).all(|(k, w)| k.byte == *w))
    }

    fn expect(&mut self, byte: u8, what: &str) -> Result<(), MacroError> {
        if self.peek() == Some(byte) {
            self.pos += 1;
            Ok(())
        } else {
            let mut e = self.unexpected();
            e.message = format!("{}: {what}", e.message);
            Err(e)
        }
    }

    /// Digits at the cursor as an integer.
    fn unsigned(&mut self) -> Result<u64, MacroError> {
        let start = self.pos;
        let mut n: u64 = 0;
        while let Some(d) = self.peek().filter(u8::is_ascii_digit) {
            n = n
                .checked_mul(10)
                .and_then(|n| n.checked_add(u64::from(d - b'0')))
                .ok_or_else(|| self.error(start, self.pos + 1, "number too large"))?;
            self.pos += 1;
        }
        if self.pos == start {
            return Err(self.unexpected());
        }
        Ok(n)
    }

    /// An unsigned number `digits [. digits]` (at least one digit): its
    /// value, whether a point was written.
    fn number(&mut self) -> Result<(f64, bool), MacroError> {
        let start = self.pos;
        let mut digits = String::new();
        let mut point = false;
        while let Some(b) = self.peek() {
            if b.is_ascii_digit() {
                digits.push(char::from(b));
            } else if b == b'.' && !point {
                point = true;
                digits.push('.');
            } else {
                break;
            }
            self.pos += 1;
        }
        if !digits.bytes().any(|b| b.is_ascii_digit()) {
            return Err(self.error(start, self.pos.max(start + 1), "bad number format"));
        }
        let text = if digits.ends_with('.') {
            &digits[..digits.len() - 1]
        } else {
            &digits
        };
        let text = if text.starts_with('.') {
            format!("0{text}")
        } else {
            text.to_owned()
        };
        text.parse::<f64>()
            .map(|v| (v, point))
            .map_err(|_| self.error(start, self.pos, "bad number format"))
    }

    /// The name between `<` and `>`; the cursor is at `<`.
    fn name(&mut self) -> Result<Box<str>, MacroError> {
        let start = self.pos;
        self.pos += 1;
        let mut name = String::new();
        loop {
            match self.peek() {
                Some(b'>') => {
                    self.pos += 1;
                    break;
                }
                Some(b) if b.is_ascii_graphic() && b != b'<' => {
                    if name.len() >= MAX_NAME {
                        return Err(self.error(start, self.pos, "name too long"));
                    }
                    name.push(char::from(b));
                    self.pos += 1;
                }
                _ => {
                    return Err(self.error(
                        start,
                        self.pos.max(start + 1),
                        "name not closed by `>`",
                    ));
                }
            }
        }
        if name.is_empty() {
            return Err(self.error(start, self.pos, "empty name `<>`"));
        }
        Ok(name.into_boxed_str())
    }

    /// `#n`, `##n`, `#[e]`, `#<name>`; the cursor is at `#`. The `#` in
    /// a row are counted in a loop (at most [`MAX_NGC_INDIRECTION`]), each
    /// one a level of indirection around the innermost parameter.
    fn parameter(&mut self) -> Result<Var, MacroError> {
        let start = self.pos;
        while self.peek() == Some(b'#') {
            if self.pos - start == MAX_NGC_INDIRECTION {
                return Err(self.error(
                    start,
                    self.pos + 1,
                    format!("more than {MAX_NGC_INDIRECTION} `#` in a row"),
                ));
            }
            self.pos += 1;
        }
        let hashes = self.pos - start;
        let innermost = start + hashes - 1;
        let number = match self.peek() {
            Some(b'<') => VarNumber::Named(self.name()?),
            Some(b'[') => VarNumber::Indirect(Box::new(self.bracketed()?)),
            Some(b'0'..=b'9') => {
                let at = self.pos;
                let (value, point) = self.number()?;
                if point && value.fract() != 0.0 {
                    return Err(self.error(at, self.pos, "parameter number must be an integer"));
                }
                VarNumber::Direct(value.min(f64::from(u32::MAX)) as u32)
            }
            _ => {
                return Err(self.error(
                    innermost,
                    self.pos,
                    "`#` without a parameter number or name",
                ));
            }
        };
        let mut var = Var {
            number,
            span: self.span(innermost, self.pos),
        };
        for at in (start..innermost).rev() {
            var = Var {
                number: VarNumber::Indirect(Box::new(Expr::Var(var))),
                span: self.span(at, self.pos),
            };
        }
        Ok(var)
    }

    /// A bracketed expression; the cursor is at `[`.
    fn bracketed(&mut self) -> Result<Expr, MacroError> {
        let start = self.pos;
        if self.depth >= MAX_NGC_DEPTH {
            return Err(MacroError::new(
                MacroErrorKind::BracketNesting,
                self.span(start, start + 1),
                format!("brackets nested deeper than {MAX_NGC_DEPTH} levels"),
            ));
        }
        self.expect(b'[', "`[` expected")?;
        self.depth += 1;
        let e = self.binary(0)?;
        self.depth -= 1;
        if self.peek() != Some(b']') {
            return Err(match self.peek() {
                None => self.error(start, self.pos, "unclosed expression: `]` missing"),
                Some(_) => {
                    let mut e = self.unexpected();
                    e.message = format!("{}: an operator or `]` expected", e.message);
                    e
                }
            });
        }
        self.pos += 1;
        Ok(e)
    }

    /// Binary operations of precedence group `group` and above.
    fn binary(&mut self, group: usize) -> Result<Expr, MacroError> {
        let Some(ops) = GROUPS.get(group) else {
            return self.operand();
        };
        let start = self.pos;
        let mut lhs = self.binary(group + 1)?;
        loop {
            // `*` must not take the first half of `**`.
            let found = ops
                .iter()
                .find(|(w, _)| self.at_word(w) && !(*w == b"*" && self.at_word(b"**")));
            let Some(&(word, op)) = found else {
                return Ok(lhs);
            };
            self.operations += 1;
            if self.operations > MAX_NGC_OPERATIONS {
                return Err(self.error(
                    start,
                    self.pos + word.len(),
                    format!("more than {MAX_NGC_OPERATIONS} operations in one line"),
                ));
            }
            self.pos += word.len();
            let rhs = self.binary(group + 1)?;
            lhs = Expr::Binary(Box::new(Binary {
                op,
                lhs,
                rhs,
                span: self.span(start, self.pos),
            }));
        }
    }

    /// The function name at the cursor, if one is written there followed
    /// by `[`.
    fn function_at(&self) -> Option<(&'static [u8], Func)> {
        FUNCTIONS
            .iter()
            .find(|(w, _)| {
                self.at_word(w)
                    && self
                        .kept
                        .get(self.pos + w.len())
                        .is_some_and(|k| k.byte == b'[')
            })
            .copied()
    }

    /// A number, parameter, bracketed expression or function, optionally
    /// signed: the signs in a row are counted in a loop (at most
    /// [`MAX_NGC_SIGNS`]); an odd number of `-` negates the operand.
    fn operand(&mut self) -> Result<Expr, MacroError> {
        let signs_at = self.pos;
        let mut negative = false;
        while let Some(sign @ (b'-' | b'+')) = self.peek() {
            if self.pos - signs_at == MAX_NGC_SIGNS {
                return Err(self.error(
                    signs_at,
                    self.pos + 1,
                    format!("more than {MAX_NGC_SIGNS} signs in a row"),
                ));
            }
            negative ^= sign == b'-';
            self.pos += 1;
        }
        let operand = self.unsigned_operand()?;
        Ok(match operand {
            e if !negative => e,
            Expr::Number(x) => Expr::Number(-x),
            e => Expr::Neg(Box::new(e)),
        })
    }

    /// A number, parameter, bracketed expression or function.
    fn unsigned_operand(&mut self) -> Result<Expr, MacroError> {
        let start = self.pos;
        match self.peek() {
            Some(b'0'..=b'9' | b'.') => Ok(Expr::Number(self.number()?.0)),
            Some(b'#') => Ok(Expr::Var(self.parameter()?)),
            Some(b'[') => self.bracketed(),
            Some(b) if b.is_ascii_uppercase() => {
                let Some((word, func)) = self.function_at() else {
                    let end = self.letters_end(start);
                    return Err(self.error(
                        start,
                        end.max(start + 1),
                        format!("unknown operation `{}`", self.text(start, end)),
                    ));
                };
                self.pos += word.len();
                let arg = self.bracketed()?;
                let arg2 = if func == Func::Atan {
                    self.expect(b'/', "ATAN takes two arguments, `ATAN[a]/[b]`")?;
                    Some(self.bracketed()?)
                } else {
                    None
                };
                if func == Func::Exists
                    && !matches!(
                        arg,
                        Expr::Var(Var {
                            number: VarNumber::Named(_),
                            ..
                        })
                    )
                {
                    return Err(self.error(
                        start,
                        self.pos,
                        "EXISTS takes one named parameter, `EXISTS[#<name>]`",
                    ));
                }
                Ok(Expr::Call(Box::new(Call {
                    func,
                    arg,
                    arg2,
                    span: self.span(start, self.pos),
                })))
            }
            _ => Err(self.unexpected()),
        }
    }

    /// A value where a number stands: after a letter, after `=`.
    fn real_value(&mut self) -> Result<Expr, MacroError> {
        if self.at_end() {
            return Err(self.error(self.pos, self.pos, "a value is missing"));
        }
        self.operand()
    }

    /// The value of the word whose letter is at `start`.
    fn word_value(&mut self, start: usize, letter: u8) -> Result<WordValue, MacroError> {
        let (sign, at) = match self.peek() {
            Some(b'-') => (Some(true), self.pos + 1),
            Some(b'+') => (Some(false), self.pos + 1),
            _ => (None, self.pos),
        };
        match self.kept.get(at).map(|k| k.byte) {
            Some(b'0'..=b'9' | b'.') => {
                self.pos = at;
                let digits_at = self.pos;
                let (value, point) = self.number()?;
                let code = if sign.is_none() {
                    code_of(&self.text(digits_at, self.pos))
                } else {
                    None
                };
                Ok(WordValue::Literal {
                    value: if sign == Some(true) { -value } else { value },
                    decimal_point: point,
                    code,
                })
            }
            None => Err(self.error(
                start,
                self.pos,
                format!("address `{}` has no value", char::from(letter)),
            )),
            Some(_) => Ok(WordValue::Expr(self.operand()?)),
        }
    }

    /// `o100 kind [args]`, `o<name> kind …`, `o[e] kind …`; the cursor is
    /// at `O`.
    fn oword(&mut self) -> Result<OWord, MacroError> {
        let start = self.pos;
        self.pos += 1;
        let label = match self.peek() {
            Some(b'<') => OLabel::Name(self.name()?),
            Some(b'[') => OLabel::Computed(self.bracketed()?),
            Some(b'0'..=b'9') => {
                let n = self.unsigned()?;
                OLabel::Number(
                    u32::try_from(n)
                        .map_err(|_| self.error(start, self.pos, "o-number too large"))?,
                )
            }
            _ => return Err(self.error(start, self.pos, "`o` without a number or a name")),
        };
        let span = self.span(start, self.pos);
        if self.at_end() {
            return Ok(OWord {
                label,
                span,
                kind: OKind::Program,
                args: Vec::new(),
            });
        }
        let at = self.pos;
        let Some(&(word, kind)) = OKINDS.iter().find(|(w, _)| self.at_word(w)) else {
            let end = self.letters_end(at);
            return Err(self.error(
                at,
                end.max(at + 1),
                format!("unknown o-word command `{}`", self.text(at, end)),
            ));
        };
        self.pos += word.len();
        let mut args = Vec::new();
        while self.peek() == Some(b'[') {
            args.push(self.bracketed()?);
        }
        let (min, max) = match kind {
            OKind::Call => (0, crate::variables::NGC_CALL_ARGS),
            OKind::If | OKind::ElseIf | OKind::While | OKind::Repeat => (1, 1),
            OKind::Return | OKind::EndSub => (0, 1),
            _ => (0, 0),
        };
        if args.len() < min || args.len() > max {
            let what = match (min, max) {
                (1, 1) => "takes one bracketed expression",
                (0, 1) => "takes at most one bracketed value",
                (0, 0) => "takes no arguments",
                _ => "takes at most 30 arguments",
            };
            return Err(self.error(
                at,
                self.pos.max(at + word.len()),
                format!(
                    "`{}` {what}",
                    String::from_utf8_lossy(word).to_ascii_lowercase()
                ),
            ));
        }
        Ok(OWord {
            label,
            span,
            kind,
            args,
        })
    }
}

/// The G/M code form of the digits of an unsigned number: at most one
/// digit after the point (LinuxCNC reads `G43.1`, `G59.3`, `M6`).
fn code_of(digits: &str) -> Option<Code> {
    let (int, frac) = digits.split_once('.').unwrap_or((digits, ""));
    let frac = frac.trim_end_matches('0');
    if frac.len() > 1 {
        return None;
    }
    let major = if int.is_empty() {
        0
    } else {
        int.parse::<u16>().ok()?
    };
    let minor = frac.bytes().next().map_or(0, |d| d - b'0');
    Some(Code::new(major, minor))
}

/// The key of an o-word label as LinuxCNC names subroutines: a number as
/// its decimal digits, a name as written (lower case).
pub fn label_key(label: &OLabel, computed: Option<f64>) -> String {
    match label {
        OLabel::Number(n) => n.to_string(),
        OLabel::Name(name) => name.to_string(),
        OLabel::Computed(_) => computed.map_or_else(String::new, |v| format!("{}", v.round())),
    }
}

/// The o-word of a line, cheaply, for skipping blocks: the label key of a
/// literal label and the kind, or `None` when the line has no o-word (or
/// a computed one, or cannot be read).
pub fn oword_of(text: &[u8]) -> Option<(String, OKind)> {
    let mut rest = text.trim_ascii_start();
    if let [b'/', tail @ ..] = rest {
        rest = tail.trim_ascii_start();
    }
    if let [b'N' | b'n', d, ..] = rest
        && d.is_ascii_digit()
    {
        let digits = rest
            .iter()
            .skip(1)
            .take_while(|b| b.is_ascii_digit() || **b == b' ')
            .count();
        rest = rest.get(1 + digits..)?.trim_ascii_start();
    }
    if !matches!(rest.first(), Some(b'O' | b'o')) {
        return None;
    }
    let line = parse_ngc_line(rest, 0).ok()?;
    let o = line.oword?;
    match o.label {
        OLabel::Computed(_) => None,
        ref label => Some((label_key(label, None), o.kind)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{MacroSettings, NoSystemVariables, Value, Variables};

    fn value_of(text: &str) -> f64 {
        let line = parse_ngc_line(format!("#1 = {text}").as_bytes(), 1).expect("parses");
        let vars = Variables::linuxcnc(10);
        let (_, e) = &line.assignments[0];
        match vars.eval(e, &NoSystemVariables, &MacroSettings::LINUXCNC) {
            Ok(Value::Number(x)) => x,
            other => panic!("{text}: {other:?}"),
        }
    }

    /// Values printed by `rs274 -g` (LinuxCNC 2.9) for the same
    /// expressions (`(print, …)`).
    #[test]
    fn expressions_as_rs274_evaluates_them() {
        let cases = [
            ("[-7 MOD 3]", 2.0),
            ("[7.5 MOD -2]", 1.5),
            ("[2 AND 0.5]", 1.0),
            ("[3 GT 2]", 1.0),
            ("[2 ** 3 ** 2]", 64.0),
            ("[ATAN[1]/[-1]]", 135.0),
            ("[FIX[-2.8]]", -3.0),
            ("[FUP[-2.8]]", -2.0),
            ("[ROUND[-2.5]]", -3.0),
            ("[1 + 2 EQ 3]", 1.0),
            ("[1.0000001 EQ 1]", 1.0),
            ("[- 2 ** 2]", 4.0),
            ("[1 OR 0 AND 0]", 0.0),
            ("[2.0 / 3 * 1.5 - 5.5 / 11.0]", 0.5),
            ("[1 + acos[0] - [3 ** [4.0/2]]]", 82.0),
            ("-[2]", -2.0),
            ("sqrt[16]", 4.0),
        ];
        for (text, want) in cases {
            let got = value_of(text);
            assert!((got - want).abs() < 1e-9, "{text}: {got} != {want}");
        }
    }

    #[test]
    fn comments_and_case() {
        let line = parse_ngc_line(b"g1 x 1 0 (a;b) f100 ; (MSG, not this)", 3).expect("reads");
        assert_eq!(line.nc.words.len(), 3);
        assert_eq!(
            line.comment,
            Some(Comment::Plain(" (MSG, not this)".into()))
        );
        let line = parse_ngc_line(b"(msg, Hello World)", 3).expect("reads");
        assert_eq!(line.comment, Some(Comment::Msg(" Hello World".into())));
        assert!(parse_ngc_line(b"G1 (a (b) c)", 1).is_err());
        let line = parse_ngc_line(b"/ G0 X1", 1).expect("reads");
        assert!(line.block_delete);
    }

    #[test]
    fn named_parameters_are_lower_case_without_blanks() {
        let line = parse_ngc_line(b"#<P a R am> = 2", 1).expect("reads");
        assert_eq!(
            line.assignments[0].0.number,
            VarNumber::Named("param".into())
        );
    }

    #[test]
    fn owords() {
        let line = parse_ngc_line(b"o<Foo> call [1] [2+#3]", 1).expect("reads");
        let o = line.oword.expect("reads");
        assert_eq!(o.label, OLabel::Name("foo".into()));
        assert_eq!(o.kind, OKind::Call);
        assert_eq!(o.args.len(), 2);
        assert_eq!(
            oword_of(b"  O100 EndWhile"),
            Some(("100".into(), OKind::EndWhile))
        );
        assert_eq!(
            oword_of(b"N10 o101 if [1]"),
            Some(("101".into(), OKind::If))
        );
        assert_eq!(oword_of(b"G1 X1"), None);
        assert!(parse_ngc_line(b"o100 if", 1).is_err());
        assert!(parse_ngc_line(b"o100 endif G1", 1).is_err());
        assert!(parse_ngc_line(b"o100 frobnicate", 1).is_err());
    }

    #[test]
    fn deep_brackets_are_refused_not_overflowed() {
        let text = format!("#1 = {}1{}", "[".repeat(5000), "]".repeat(5000));
        let e = parse_ngc_line(text.as_bytes(), 1).expect_err("fails");
        assert_eq!(e.kind, MacroErrorKind::BracketNesting);
    }

    #[test]
    fn undefined_named_parameter_is_an_error() {
        let line = parse_ngc_line(b"G1 X#<zz>", 1).expect("reads");
        let vars = Variables::linuxcnc(10);
        let WordValue::Expr(e) = &line.nc.words[1].value else {
            panic!()
        };
        let err = vars
            .eval(e, &NoSystemVariables, &MacroSettings::LINUXCNC)
            .expect_err("fails");
        assert_eq!(err.kind, MacroErrorKind::UndefinedVariable);
        assert!(err.message.contains("#<zz>"));
    }
}
