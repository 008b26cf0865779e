//! The reader of one Klartext block: [`parse_block`] turns the code of a
//! block (its lines joined, comments removed or not) into a [`Block`]
//! whose values are still unevaluated ([`Operand`], formula nodes).
//!
//! The reader is pure and never panics: any text gives a [`Block`] or a
//! [`ParseError`] with the columns at fault. A [`Block`] is meant to be
//! reused: [`parse_block`] clears it and refills its vectors, so a plain
//! `L` block allocates nothing once the vectors have grown.
//!
//! Columns are 1-based columns of the text given; for a block joined from
//! several lines they count in the joined text.

use fiveaxis_gcode::Span;

use crate::{Kind, LangErrorKind};

/// The kinds of numeric parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum QKind {
    /// `Q0`–`Q1999`: global, shared by all programs.
    Q,
    /// `QL0`–`QL499`: local to the program (each call has its own).
    Ql,
    /// `QR0`–`QR499`: kept (remanent) parameters.
    Qr,
}

/// A numeric parameter: `Q5`, `QL3`, `QR10`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct QRef {
    /// Which kind.
    pub kind: QKind,
    /// Its number.
    pub n: u32,
}

/// Highest `Q` number (`Q0`–`Q1999`).
pub const Q_MAX: u32 = 1999;
/// Highest `QL` / `QR` number (`QL0`–`QL499`).
pub const QL_MAX: u32 = 499;
/// Highest `QS` number (`QS0`–`QS1999`).
pub const QS_MAX: u32 = 1999;

/// A value as written in an address: a number or a (negated) parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Operand {
    /// A number (`+10`, `-5.5`).
    Num(f64),
    /// A parameter, negated when written `-Q1`.
    Param {
        /// The parameter.
        q: QRef,
        /// Written with `-`.
        neg: bool,
    },
}

/// A name of an item: a fixed keyword, or columns of the text (read
/// upper-cased), or a text of its own.
#[derive(Clone, Debug, PartialEq)]
pub enum Name {
    /// A keyword the reader knows (`FMAX`, `TABLE ROT`).
    Static(&'static str),
    /// Bytes `start..end` of the block text, upper-cased when read.
    Range(usize, usize),
    /// A text.
    Owned(String),
}

impl Name {
    /// Appends the name, upper-cased, to `out`.
    pub fn write_to(&self, text: &[u8], out: &mut String) {
        match self {
            Name::Static(s) => out.push_str(s),
            Name::Range(a, b) => {
                if let Some(bytes) = text.get(*a..*b) {
                    out.extend(bytes.iter().map(|b| char::from(b.to_ascii_uppercase())));
                }
            }
            Name::Owned(s) => out.push_str(s),
        }
    }

    /// The name as a string, upper-cased.
    pub fn to_upper(&self, text: &[u8]) -> String {
        let mut s = String::new();
        self.write_to(text, &mut s);
        s
    }
}

/// A word, keyword or M function of a block.
#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    /// An address with a value.
    Word {
        /// The address (without the `I` of an incremental value).
        address: Name,
        /// The value as written.
        value: Operand,
        /// Written with `I`.
        incremental: bool,
        /// Columns.
        span: Span,
    },
    /// A keyword without value.
    Key {
        /// The keyword.
        key: Name,
        /// Columns.
        span: Span,
    },
    /// An M function.
    M {
        /// Its number.
        n: u32,
        /// Columns.
        span: Span,
    },
}

/// The tool of `TOOL CALL` / `TOOL DEF` as written.
#[derive(Clone, Debug, PartialEq)]
pub enum ToolRef {
    /// A number or a numeric parameter (`5`, `Q10`).
    Number(Operand),
    /// A name in quotes.
    Name(String),
    /// A string parameter (`QS1`).
    Text(u32),
}

/// A label: `LBL 1`, `LBL "NAME"`.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Label {
    /// A number (`LBL 0` ends a subprogram).
    Number(u32),
    /// A name.
    Name(String),
}

/// The comparisons of `FN 9` – `FN 12`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compare {
    /// `FN 9: IF a EQU b`.
    Equal,
    /// `FN 10: IF a NE b`.
    NotEqual,
    /// `FN 11: IF a GT b`.
    Greater,
    /// `FN 12: IF a LT b`.
    Less,
}

/// The arithmetic `FN` functions: `FN 0` – `FN 8` and `FN 13`.
///
/// Numbering after the TNC 640 Conversational Programming manual
/// (10/2017, "Basic arithmetic" and "Angle functions"): `FN 0` assign,
/// `FN 1` add, `FN 2` subtract, `FN 3` multiply, `FN 4` divide (written
/// `DIV`), `FN 5` square root, `FN 6` sine, `FN 7` cosine, `FN 8` root of
/// the sum of squares (`+5 LEN +4`), `FN 13` angle (`+25 ANG -Q1`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FnOp {
    /// `FN 0`.
    Assign,
    /// `FN 1`.
    Add,
    /// `FN 2`.
    Sub,
    /// `FN 3`.
    Mul,
    /// `FN 4`.
    Div,
    /// `FN 5`.
    Sqrt,
    /// `FN 6`.
    Sin,
    /// `FN 7`.
    Cos,
    /// `FN 8`.
    Len,
    /// `FN 13`.
    Angle,
}

/// Functions of formulas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Func {
    /// `SIN` (degrees).
    Sin,
    /// `COS`.
    Cos,
    /// `TAN`.
    Tan,
    /// `ASIN` (gives degrees).
    Asin,
    /// `ACOS`.
    Acos,
    /// `ATAN`.
    Atan,
    /// `SQ` square.
    Sq,
    /// `SQRT`.
    Sqrt,
    /// `LN`.
    Ln,
    /// `LOG` (base 10).
    Log,
    /// `EXP`.
    Exp,
    /// `NEG`.
    Neg,
    /// `INT` (drops the decimals).
    Int,
    /// `ABS`.
    Abs,
    /// `FRAC`.
    Frac,
    /// `SGN` (1 for ≥ 0, −1 below: TNC 620 ISO manual 340 56x-03 p242).
    Sgn,
}

/// Binary operators of formulas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// `+`.
    Add,
    /// `-`.
    Sub,
    /// `*`.
    Mul,
    /// `/`.
    Div,
    /// `%` (remainder).
    Mod,
    /// `^`.
    Pow,
}

/// A node of a formula; nodes refer to others by index into
/// [`Block::nodes`].
#[derive(Clone, Debug, PartialEq)]
pub enum Node {
    /// A number.
    Num(f64),
    /// A numeric parameter.
    Param(QRef),
    /// `PI`.
    Pi,
    /// A unary minus.
    Minus(usize),
    /// A function of a value.
    Func(Func, usize),
    /// Two values.
    Bin(Op, usize, usize),
    /// `TONUMB ( SRC_QS1 )`: a string node read as a number.
    ToNumber(usize),
    /// `STRLEN ( SRC_QS1 )`: a string node's length.
    StrLen(usize),
    /// A string literal `"TEXT"` (string node).
    Text(String),
    /// `QS1` (string node).
    TextParam(u32),
    /// `a || b` (string node).
    Concat(usize, usize),
    /// `TOCHAR ( DAT+Q1 DECIMALS3 )` (string node): a number as text.
    ToChar(usize, Option<usize>),
    /// `SUBSTR ( SRC_QS1 BEG2 LEN4 )` (string node), positions from 0.
    SubStr(usize, usize, usize),
}

/// What a block does.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Body {
    /// Nothing: an empty or comment-only line.
    #[default]
    Nothing,
    /// A `*` section heading.
    Heading,
    /// `BEGIN PGM name MM|INCH`.
    Begin {
        /// The name as written.
        name: String,
        /// `INCH`.
        inch: bool,
    },
    /// `END PGM name`.
    End,
    /// A block for the control: kind, name, number and tool; the words
    /// in [`Block::items`].
    Control {
        /// The kind.
        kind: Kind,
        /// The name (upper-cased).
        name: Option<String>,
        /// The number (`CYCL DEF 7.1`, `BLK FORM 0.1`).
        number: Option<f64>,
        /// The tool.
        tool: Option<ToolRef>,
    },
    /// `Q5 = formula` (also `FN 0`-less forms of `QL`, `QR`): the root
    /// node.
    Assign(QRef, usize),
    /// `QS1 = string formula`: the root node.
    AssignText(u32, usize),
    /// `FN 0` – `FN 8`, `FN 13`.
    Arith {
        /// The function.
        op: FnOp,
        /// The target.
        target: QRef,
        /// First operand.
        a: Operand,
        /// Second operand (functions of two values).
        b: Option<Operand>,
    },
    /// `FN 9` – `FN 12`: `IF a cmp b GOTO LBL l`.
    If {
        /// The comparison.
        cmp: Compare,
        /// Left value.
        a: Operand,
        /// Right value.
        b: Operand,
        /// The target.
        label: Label,
    },
    /// `FN 14: ERROR = n`.
    Error(Operand),
    /// `FN 15: PRINT …` with its values (the text in `text`).
    Print {
        /// The values to print.
        values: Vec<Operand>,
        /// The text after `PRINT`.
        text: String,
    },
    /// `FN 16: F-PRINT …`: the text after `F-PRINT`.
    FPrint(String),
    /// `FN 18: SYSREAD Q = ID NR IDX`.
    SysRead {
        /// The target.
        target: QRef,
        /// `ID`.
        group: u32,
        /// `NR`.
        number: u32,
        /// `IDX`.
        index: Option<u32>,
    },
    /// `LBL n` / `LBL "name"`.
    Label(Label),
    /// `CALL LBL l [REP n]`.
    CallLabel {
        /// The label.
        label: Label,
        /// `REP n`.
        rep: Option<u32>,
    },
    /// `CALL PGM name`.
    CallProgram(String),
}

/// A cycle parameter `Q200=2` of `CYCL DEF`.
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    /// Its number.
    pub n: u32,
    /// Its value as written (`MAX` / `FMAX` read as +∞, `FAUTO` / `FU` /
    /// `FZ` as NaN: our choice, the control's own form is a key).
    pub value: Operand,
}

/// One item of `PATTERN DEF`.
#[derive(Clone, Debug, PartialEq)]
pub struct PatternDefItem {
    /// `POS`, `ROW`, … upper-cased.
    pub kind: String,
    /// Its words.
    pub items: Vec<Item>,
}

/// One block as read.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Block {
    /// The block number at the start, if written.
    pub number: Option<u32>,
    /// Written with `/` (block skip).
    pub skip: bool,
    /// What it does.
    pub body: Body,
    /// Words, keys and M functions of a control block, in order.
    pub items: Vec<Item>,
    /// Cycle parameters.
    pub params: Vec<Param>,
    /// `PATTERN DEF` items.
    pub pattern: Vec<PatternDefItem>,
    /// Formula nodes.
    pub nodes: Vec<Node>,
}

impl Block {
    fn clear(&mut self) {
        self.number = None;
        self.skip = false;
        self.body = Body::Nothing;
        self.items.clear();
        self.params.clear();
        self.pattern.clear();
        self.nodes.clear();
    }
}

/// A block the reader cannot read.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct ParseError {
    /// [`LangErrorKind::Syntax`], or [`LangErrorKind::Parameter`] for a
    /// parameter number out of range.
    pub kind: LangErrorKind,
    /// Columns at fault.
    pub span: Span,
    /// What is wrong.
    pub message: String,
}

/// Splits a line at its `;` comment (outside quotes): the code and the
/// comment without `;`.
pub fn split_comment(line: &[u8]) -> (&[u8], Option<&[u8]>) {
    let mut quoted = false;
    for (i, &b) in line.iter().enumerate() {
        match b {
            b'"' => quoted = !quoted,
            b';' if !quoted => return (&line[..i], Some(&line[i + 1..])),
            _ => {}
        }
    }
    (line, None)
}

/// Reads one block (`text` without its line end; a `;` comment is
/// ignored, `~` counts as a space) into `out`.
///
/// # Errors
///
/// The block is not one the reader knows, with the columns at fault.
///
/// ```
/// use fiveaxis_heidenhain::{Block, Body, Kind, parse_block};
///
/// let mut b = Block::default();
/// parse_block(b"12 L X+10 IY-5 R0 FMAX M3", &mut b)?;
/// assert_eq!(b.number, Some(12));
/// assert!(matches!(b.body, Body::Control { kind: Kind::Line, .. }));
/// assert_eq!(b.items.len(), 5);
/// # Ok::<(), fiveaxis_heidenhain::ParseError>(())
/// ```
pub fn parse_block(text: &[u8], out: &mut Block) -> Result<(), ParseError> {
    out.clear();
    let (code, _) = split_comment(text);
    let mut c = Cur { s: code, i: 0 };
    c.ws();
    if c.eat_byte(b'/') {
        out.skip = true;
        c.ws();
    }
    if c.peek().is_ascii_digit() {
        let start = c.i;
        while c.peek().is_ascii_digit() {
            c.i += 1;
        }
        let n = std::str::from_utf8(&code[start..c.i])
            .ok()
            .and_then(|s| s.parse().ok());
        if n.is_none() {
            return Err(c.err(start, "block number out of range"));
        }
        out.number = n;
        c.ws();
        if c.eat_byte(b'/') {
            out.skip = true;
            c.ws();
        }
    }
    if c.at_end() {
        return Ok(());
    }
    if c.peek() == b'*' {
        out.body = Body::Heading;
        return Ok(());
    }
    let start = c.i;
    let (ws, we) = c.letters();
    // The keyword upper-cased on the stack: a plain block allocates nothing.
    let mut buf = [0u8; 12];
    let len = (we - ws).min(buf.len());
    for (d, s) in buf.iter_mut().zip(&code[ws..ws + len]) {
        *d = s.to_ascii_uppercase();
    }
    let upper = if we - ws > buf.len() {
        "?"
    } else {
        std::str::from_utf8(&buf[..len]).unwrap_or("?")
    };
    // Parameter assignment: Q5 = …, QL3 = …, QS1 = …
    if c.peek().is_ascii_digit() && matches!(upper, "Q" | "QL" | "QR" | "QS") {
        c.i = start;
        return assign(&mut c, out);
    }
    match upper {
        "BEGIN" => {
            c.expect_kw("PGM")?;
            let name = c.token_string();
            if name.is_empty() {
                return Err(c.err(c.i, "BEGIN PGM needs a program name"));
            }
            c.ws();
            let inch = c.eat_kw("INCH");
            if !inch {
                c.eat_kw("MM");
            }
            c.end()?;
            out.body = Body::Begin { name, inch };
        }
        "END" => {
            c.expect_kw("PGM")?;
            out.body = Body::End;
        }
        "FN" => fn_block(&mut c, out)?,
        "LBL" => {
            let label = label(&mut c)?;
            c.end()?;
            out.body = Body::Label(label);
        }
        "CALL" => {
            if c.eat_kw_glued("LBL") {
                let label = label(&mut c)?;
                let rep = if c.eat_kw_glued("REP") {
                    c.ws();
                    let at = c.i;
                    let v = c.number().ok_or_else(|| c.err(at, "REP needs a count"))?;
                    if !(0.0..=65535.0).contains(&v) || v.fract() != 0.0 {
                        return Err(c.err(at, "REP count out of range"));
                    }
                    Some(v as u32)
                } else {
                    None
                };
                // A REP written as "REP 2/2" (the TNC's counter display).
                c.ws();
                if c.eat_byte(b'/') {
                    c.number();
                }
                c.end()?;
                out.body = Body::CallLabel { label, rep };
            } else if c.eat_kw("PGM") {
                let name = c.token_string();
                if name.is_empty() {
                    return Err(c.err(c.i, "CALL PGM needs a program name"));
                }
                out.body = Body::CallProgram(name);
            } else {
                return Err(c.err(c.i, "CALL must be followed by LBL or PGM"));
            }
        }
        "DECLARE" => {
            c.expect_kw("STRING")?;
            c.ws();
            return assign(&mut c, out);
        }
        _ => control(&mut c, out, upper, start)?,
    }
    Ok(())
}

/// Reads a block from a string (a fresh [`Block`]).
///
/// # Errors
///
/// As [`parse_block`].
pub fn parse(text: &str) -> Result<Block, ParseError> {
    let mut b = Block::default();
    parse_block(text.as_bytes(), &mut b)?;
    Ok(b)
}

fn upper_of(bytes: &[u8]) -> String {
    bytes
        .iter()
        .map(|b| char::from(b.to_ascii_uppercase()))
        .collect()
}

fn ascii_eq(bytes: &[u8], kw: &str) -> bool {
    bytes.eq_ignore_ascii_case(kw.as_bytes())
}

struct Cur<'t> {
    s: &'t [u8],
    i: usize,
}

impl Cur<'_> {
    fn peek(&self) -> u8 {
        self.s.get(self.i).copied().unwrap_or(0)
    }

    fn peek_at(&self, k: usize) -> u8 {
        self.s.get(self.i + k).copied().unwrap_or(0)
    }

    fn ws(&mut self) {
        while matches!(self.peek(), b' ' | b'\t' | b'~' | b'\r') {
            self.i += 1;
        }
    }

    fn at_end(&mut self) -> bool {
        self.ws();
        self.i >= self.s.len()
    }

    fn eat_byte(&mut self, b: u8) -> bool {
        if self.peek() == b {
            self.i += 1;
            true
        } else {
            false
        }
    }

    fn span(&self, start: usize, end: usize) -> Span {
        let end = end.max(start + 1);
        Span::new(
            u32::try_from(start + 1).unwrap_or(u32::MAX),
            u32::try_from(end + 1).unwrap_or(u32::MAX),
        )
    }

    fn err(&self, at: usize, msg: &str) -> ParseError {
        let mut end = at;
        while end < self.s.len() && !self.s[end].is_ascii_whitespace() {
            end += 1;
        }
        ParseError {
            kind: LangErrorKind::Syntax,
            span: self.span(at, end),
            message: msg.to_string(),
        }
    }

    fn end(&mut self) -> Result<(), ParseError> {
        if self.at_end() {
            Ok(())
        } else {
            Err(self.err(self.i, "unexpected text at the end of the block"))
        }
    }

    /// A run of ASCII letters (and `_`), as a byte range.
    fn letters(&mut self) -> (usize, usize) {
        let start = self.i;
        while self.peek().is_ascii_alphabetic() || self.peek() == b'_' {
            self.i += 1;
        }
        (start, self.i)
    }

    /// Eats keyword `kw` (case-insensitive, whole word) after spaces.
    fn eat_kw(&mut self, kw: &str) -> bool {
        let save = self.i;
        self.ws();
        let end = self.i + kw.len();
        if end <= self.s.len()
            && ascii_eq(&self.s[self.i..end], kw)
            && !self
                .s
                .get(end)
                .is_some_and(|b| b.is_ascii_alphanumeric() || *b == b'_')
        {
            self.i = end;
            true
        } else {
            self.i = save;
            false
        }
    }

    fn expect_kw(&mut self, kw: &str) -> Result<(), ParseError> {
        if self.eat_kw(kw) {
            Ok(())
        } else {
            self.ws();
            Err(self.err(self.i, &format!("expected {kw}")))
        }
    }

    /// A token up to the next space (a program name, a path), or a
    /// quoted text without its quotes.
    fn token_string(&mut self) -> String {
        self.ws();
        if self.peek() == b'"'
            && let Some(s) = self.quoted()
        {
            return s;
        }
        let start = self.i;
        while self.i < self.s.len() && !matches!(self.peek(), b' ' | b'\t' | b'~') {
            self.i += 1;
        }
        String::from_utf8_lossy(&self.s[start..self.i]).into_owned()
    }

    fn quoted(&mut self) -> Option<String> {
        let save = self.i;
        if !self.eat_byte(b'"') {
            return None;
        }
        let start = self.i;
        while self.i < self.s.len() && self.peek() != b'"' {
            self.i += 1;
        }
        if self.i >= self.s.len() {
            self.i = save;
            return None;
        }
        let s = String::from_utf8_lossy(&self.s[start..self.i]).into_owned();
        self.i += 1;
        Some(s)
    }

    /// An unsigned decimal number (`10`, `5.`, `.5`, `12.0296`).
    fn unsigned(&mut self) -> Option<f64> {
        let start = self.i;
        while self.peek().is_ascii_digit() {
            self.i += 1;
        }
        if self.peek() == b'.' {
            self.i += 1;
            while self.peek().is_ascii_digit() {
                self.i += 1;
            }
        }
        let t = &self.s[start..self.i];
        if t.is_empty() || t == b"." {
            self.i = start;
            return None;
        }
        let v = std::str::from_utf8(t).ok()?.parse::<f64>().ok();
        if v.is_none() {
            self.i = start;
        }
        v
    }

    /// A signed number after spaces.
    fn number(&mut self) -> Option<f64> {
        self.ws();
        let save = self.i;
        let neg = if self.eat_byte(b'-') {
            true
        } else {
            self.eat_byte(b'+');
            false
        };
        match self.unsigned() {
            Some(v) => Some(if neg { -v } else { v }),
            None => {
                self.i = save;
                None
            }
        }
    }

    /// A parameter reference `Q5`, `QL3`, `QR1` at the cursor.
    fn qref(&mut self) -> Result<Option<QRef>, ParseError> {
        let save = self.i;
        if !self.peek().eq_ignore_ascii_case(&b'Q') {
            return Ok(None);
        }
        self.i += 1;
        let kind = match self.peek().to_ascii_uppercase() {
            b'L' => {
                self.i += 1;
                QKind::Ql
            }
            b'R' => {
                self.i += 1;
                QKind::Qr
            }
            _ => QKind::Q,
        };
        if !self.peek().is_ascii_digit() {
            self.i = save;
            return Ok(None);
        }
        let n = self.index(save)?;
        let max = if kind == QKind::Q { Q_MAX } else { QL_MAX };
        if n > max {
            return Err(ParseError {
                kind: LangErrorKind::Parameter,
                span: self.span(save, self.i),
                message: format!("parameter number {n} is out of range (at most {max})"),
            });
        }
        Ok(Some(QRef { kind, n }))
    }

    /// Digits as a `u32`.
    fn index(&mut self, from: usize) -> Result<u32, ParseError> {
        let start = self.i;
        while self.peek().is_ascii_digit() {
            self.i += 1;
        }
        std::str::from_utf8(&self.s[start..self.i])
            .ok()
            .and_then(|s| s.parse().ok())
            .ok_or_else(|| self.err(from, "a number was expected"))
    }

    /// `+5`, `-Q1`, `Q3`, `+QL2` after spaces.
    fn operand(&mut self) -> Result<Option<Operand>, ParseError> {
        self.ws();
        let save = self.i;
        let neg = if self.eat_byte(b'-') {
            true
        } else {
            self.eat_byte(b'+');
            false
        };
        self.ws();
        if let Some(q) = self.qref()? {
            return Ok(Some(Operand::Param { q, neg }));
        }
        match self.unsigned() {
            Some(v) => Ok(Some(Operand::Num(if neg { -v } else { v }))),
            None => {
                self.i = save;
                Ok(None)
            }
        }
    }

    fn need_operand(&mut self) -> Result<Operand, ParseError> {
        self.ws();
        let at = self.i;
        self.operand()?
            .ok_or_else(|| self.err(at, "a number or Q parameter was expected"))
    }
}

fn label(c: &mut Cur<'_>) -> Result<Label, ParseError> {
    c.ws();
    let at = c.i;
    if c.peek() == b'"' {
        return c
            .quoted()
            .map(Label::Name)
            .ok_or_else(|| c.err(at, "unclosed label name"));
    }
    if c.peek().is_ascii_digit() {
        let n = c.index(at)?;
        return Ok(Label::Number(n));
    }
    // A name without quotes (older controls accept LBL NAME).
    let (s, e) = c.letters();
    if s == e {
        return Err(c.err(at, "a label number or name was expected"));
    }
    while c.peek().is_ascii_alphanumeric() || c.peek() == b'_' {
        c.i += 1;
    }
    Ok(Label::Name(
        String::from_utf8_lossy(&c.s[s..c.i]).into_owned(),
    ))
}

fn assign(c: &mut Cur<'_>, out: &mut Block) -> Result<(), ParseError> {
    c.ws();
    let at = c.i;
    let is_text = c.peek().eq_ignore_ascii_case(&b'Q') && c.peek_at(1).eq_ignore_ascii_case(&b'S');
    if is_text {
        c.i += 2;
        let n = c.index(at)?;
        if n > QS_MAX {
            return Err(ParseError {
                kind: LangErrorKind::Parameter,
                span: c.span(at, c.i),
                message: format!("parameter number {n} is out of range (at most {QS_MAX})"),
            });
        }
        c.ws();
        if !c.eat_byte(b'=') {
            return Err(c.err(c.i, "expected = after the parameter"));
        }
        c.eat_kw("STRF");
        let root = Formula { c, out }.text()?;
        c.end()?;
        out.body = Body::AssignText(n, root);
        return Ok(());
    }
    let q = c
        .qref()?
        .ok_or_else(|| c.err(at, "a parameter was expected"))?;
    c.ws();
    if !c.eat_byte(b'=') {
        return Err(c.err(c.i, "expected = after the parameter"));
    }
    let root = Formula { c, out }.sum()?;
    c.end()?;
    out.body = Body::Assign(q, root);
    Ok(())
}

fn fn_block(c: &mut Cur<'_>, out: &mut Block) -> Result<(), ParseError> {
    c.ws();
    let at = c.i;
    let n = c.index(at)?;
    c.ws();
    c.eat_byte(b':');
    c.ws();
    match n {
        0..=8 | 13 => {
            let tat = c.i;
            let target = c
                .qref()?
                .ok_or_else(|| c.err(tat, "a Q parameter was expected"))?;
            c.ws();
            if !c.eat_byte(b'=') {
                return Err(c.err(c.i, "expected ="));
            }
            let op = match n {
                0 => FnOp::Assign,
                1 => FnOp::Add,
                2 => FnOp::Sub,
                3 => FnOp::Mul,
                4 => FnOp::Div,
                5 => FnOp::Sqrt,
                6 => FnOp::Sin,
                7 => FnOp::Cos,
                8 => FnOp::Len,
                _ => FnOp::Angle,
            };
            let prefix = match op {
                FnOp::Sqrt => Some("SQRT"),
                FnOp::Sin => Some("SIN"),
                FnOp::Cos => Some("COS"),
                _ => None,
            };
            if let Some(p) = prefix {
                c.expect_kw_glued(p)?;
            }
            if op == FnOp::Len {
                // Also accepted: "LEN +3 LEN +4".
                c.expect_kw_glued("LEN").ok();
            }
            let a = c.need_operand()?;
            let b = match op {
                FnOp::Add | FnOp::Sub | FnOp::Mul | FnOp::Div | FnOp::Len | FnOp::Angle => {
                    c.ws();
                    let ok = match op {
                        FnOp::Add => c.eat_byte(b'+'),
                        FnOp::Sub => c.eat_byte(b'-'),
                        FnOp::Mul => c.eat_byte(b'*'),
                        FnOp::Div => c.eat_byte(b'/') || c.eat_kw_glued("DIV"),
                        FnOp::Len => c.eat_kw_glued("LEN"),
                        _ => c.eat_kw_glued("ANG"),
                    };
                    if !ok {
                        return Err(c.err(c.i, "the operator of the FN function was expected"));
                    }
                    Some(c.need_operand()?)
                }
                _ => None,
            };
            c.end()?;
            out.body = Body::Arith { op, target, a, b };
        }
        9..=12 => {
            c.expect_kw("IF")?;
            let a = c.need_operand()?;
            let cmp = match n {
                9 => ("EQU", Compare::Equal),
                10 => ("NE", Compare::NotEqual),
                11 => ("GT", Compare::Greater),
                _ => ("LT", Compare::Less),
            };
            c.expect_kw_glued(cmp.0)?;
            let b = c.need_operand()?;
            c.expect_kw("GOTO")?;
            c.expect_kw_glued("LBL")?;
            let label = label(c)?;
            c.end()?;
            out.body = Body::If {
                cmp: cmp.1,
                a,
                b,
                label,
            };
        }
        14 => {
            c.expect_kw("ERROR")?;
            c.ws();
            c.eat_byte(b'=');
            let v = c.need_operand()?;
            c.end()?;
            out.body = Body::Error(v);
        }
        15 => {
            c.expect_kw("PRINT")?;
            c.ws();
            let text = String::from_utf8_lossy(&c.s[c.i..]).trim().to_string();
            // Values separated by spaces or `/`; any other text (a file
            // name, a quoted text) is printed as written.
            let mut values = Vec::new();
            loop {
                c.ws();
                c.eat_byte(b'/');
                if c.at_end() {
                    break;
                }
                match c.operand() {
                    Ok(Some(v)) => values.push(v),
                    _ => {
                        values.clear();
                        break;
                    }
                }
            }
            out.body = Body::Print { values, text };
        }
        16 => {
            c.expect_kw("F-PRINT")?;
            c.ws();
            let text = String::from_utf8_lossy(&c.s[c.i..]).trim().to_string();
            out.body = Body::FPrint(text);
        }
        18 => {
            c.expect_kw("SYSREAD")?;
            c.ws();
            let tat = c.i;
            let target = c
                .qref()?
                .ok_or_else(|| c.err(tat, "a Q parameter was expected"))?;
            c.ws();
            if !c.eat_byte(b'=') {
                return Err(c.err(c.i, "expected ="));
            }
            c.expect_kw_glued("ID")?;
            let gat = c.i;
            let group = c.index(gat)?;
            let mut number = 0;
            let mut index = None;
            if c.eat_kw_glued("NR") {
                let a = c.i;
                number = c.index(a)?;
            }
            if c.eat_kw_glued("IDX") {
                let a = c.i;
                index = Some(c.index(a)?);
            }
            c.end()?;
            out.body = Body::SysRead {
                target,
                group,
                number,
                index,
            };
        }
        _ => return Err(c.err(at, &format!("FN {n} is not supported"))),
    }
    Ok(())
}

impl Cur<'_> {
    /// Eats `kw` after spaces, even when a value follows without a space
    /// (`SIN-Q5`, `NR1`), but not inside a longer word.
    fn eat_kw_glued(&mut self, kw: &str) -> bool {
        let save = self.i;
        self.ws();
        let end = self.i + kw.len();
        if end <= self.s.len()
            && ascii_eq(&self.s[self.i..end], kw)
            && !self.s.get(end).is_some_and(u8::is_ascii_alphabetic)
        {
            self.i = end;
            true
        } else {
            self.i = save;
            false
        }
    }

    fn expect_kw_glued(&mut self, kw: &str) -> Result<(), ParseError> {
        if self.eat_kw_glued(kw) {
            Ok(())
        } else {
            self.ws();
            Err(self.err(self.i, &format!("expected {kw}")))
        }
    }
}

/// Formula reader: precedence `+ -` < `* / %` < unary minus < `^` <
/// functions (a function takes the factor after it: `SIN Q1 * 2` is
/// `(SIN Q1) * 2`).
struct Formula<'c, 't, 'b> {
    c: &'c mut Cur<'t>,
    out: &'b mut Block,
}

/// Deepest nesting of parentheses and functions in a formula.
const MAX_DEPTH: usize = 64;

impl Formula<'_, '_, '_> {
    fn push(&mut self, n: Node) -> usize {
        self.out.nodes.push(n);
        self.out.nodes.len() - 1
    }

    fn sum(&mut self) -> Result<usize, ParseError> {
        self.sum_at(0)
    }

    fn sum_at(&mut self, depth: usize) -> Result<usize, ParseError> {
        if depth > MAX_DEPTH {
            return Err(self.c.err(self.c.i, "formula nested too deeply"));
        }
        let mut a = self.product(depth)?;
        loop {
            self.c.ws();
            let op = match self.c.peek() {
                b'+' => Op::Add,
                b'-' => Op::Sub,
                _ => return Ok(a),
            };
            self.c.i += 1;
            let b = self.product(depth)?;
            a = self.push(Node::Bin(op, a, b));
        }
    }

    fn product(&mut self, depth: usize) -> Result<usize, ParseError> {
        let mut a = self.unary(depth)?;
        loop {
            self.c.ws();
            let op = match self.c.peek() {
                b'*' => Op::Mul,
                b'/' => Op::Div,
                b'%' => Op::Mod,
                _ => return Ok(a),
            };
            self.c.i += 1;
            let b = self.unary(depth)?;
            a = self.push(Node::Bin(op, a, b));
        }
    }

    fn unary(&mut self, depth: usize) -> Result<usize, ParseError> {
        if depth > MAX_DEPTH {
            return Err(self.c.err(self.c.i, "formula nested too deeply"));
        }
        self.c.ws();
        if self.c.eat_byte(b'-') {
            let a = self.unary(depth + 1)?;
            return Ok(self.push(Node::Minus(a)));
        }
        if self.c.eat_byte(b'+') {
            return self.unary(depth + 1);
        }
        self.power(depth)
    }

    fn power(&mut self, depth: usize) -> Result<usize, ParseError> {
        let a = self.factor(depth)?;
        self.c.ws();
        if self.c.eat_byte(b'^') {
            let b = self.unary(depth + 1)?;
            return Ok(self.push(Node::Bin(Op::Pow, a, b)));
        }
        Ok(a)
    }

    fn factor(&mut self, depth: usize) -> Result<usize, ParseError> {
        self.c.ws();
        let at = self.c.i;
        if self.c.eat_byte(b'(') {
            let a = self.sum_at(depth + 1)?;
            self.c.ws();
            if !self.c.eat_byte(b')') {
                return Err(self.c.err(self.c.i, "expected )"));
            }
            return Ok(a);
        }
        if let Some(q) = self.c.qref()? {
            return Ok(self.push(Node::Param(q)));
        }
        if let Some(v) = self.c.unsigned() {
            return Ok(self.push(Node::Num(v)));
        }
        let (s, e) = self.c.letters();
        let word = upper_of(&self.c.s[s..e]);
        let func = match word.as_str() {
            "PI" => return Ok(self.push(Node::Pi)),
            "SIN" => Func::Sin,
            "COS" => Func::Cos,
            "TAN" => Func::Tan,
            "ASIN" => Func::Asin,
            "ACOS" => Func::Acos,
            "ATAN" => Func::Atan,
            "SQ" => Func::Sq,
            "SQRT" => Func::Sqrt,
            "LN" => Func::Ln,
            "LOG" => Func::Log,
            "EXP" => Func::Exp,
            "NEG" => Func::Neg,
            "INT" => Func::Int,
            "ABS" => Func::Abs,
            "FRAC" => Func::Frac,
            "SGN" => Func::Sgn,
            "TONUMB" | "STRLEN" => {
                let src = self.string_arg(depth, "SRC_")?;
                let n = if word == "TONUMB" {
                    Node::ToNumber(src)
                } else {
                    Node::StrLen(src)
                };
                return Ok(self.push(n));
            }
            _ => {
                self.c.i = at;
                return Err(self.c.err(at, "a value was expected in the formula"));
            }
        };
        let a = self.unary(depth + 1)?;
        Ok(self.push(Node::Func(func, a)))
    }

    /// `( SRC_QS1 )` / `( SRC_"TEXT" )`: a one-argument string function.
    fn string_arg(&mut self, depth: usize, tag: &str) -> Result<usize, ParseError> {
        self.c.ws();
        if !self.c.eat_byte(b'(') {
            return Err(self.c.err(self.c.i, "expected ("));
        }
        let a = self.tagged_text(depth, tag)?;
        self.c.ws();
        if !self.c.eat_byte(b')') {
            return Err(self.c.err(self.c.i, "expected )"));
        }
        Ok(a)
    }

    fn tagged_text(&mut self, depth: usize, tag: &str) -> Result<usize, ParseError> {
        self.c.ws();
        self.c.eat_kw_prefix(tag);
        self.text_term(depth + 1)
    }

    /// A string formula: terms joined by `||`.
    fn text(&mut self) -> Result<usize, ParseError> {
        let mut a = self.text_term(0)?;
        loop {
            self.c.ws();
            if self.c.peek() == b'|' && self.c.peek_at(1) == b'|' {
                self.c.i += 2;
                let b = self.text_term(0)?;
                a = self.push(Node::Concat(a, b));
            } else {
                return Ok(a);
            }
        }
    }

    fn text_term(&mut self, depth: usize) -> Result<usize, ParseError> {
        if depth > MAX_DEPTH {
            return Err(self.c.err(self.c.i, "formula nested too deeply"));
        }
        self.c.ws();
        let at = self.c.i;
        if self.c.peek() == b'"' {
            let s = self
                .c
                .quoted()
                .ok_or_else(|| self.c.err(at, "unclosed text"))?;
            return Ok(self.push(Node::Text(s)));
        }
        if self.c.peek().eq_ignore_ascii_case(&b'Q')
            && self.c.peek_at(1).eq_ignore_ascii_case(&b'S')
        {
            self.c.i += 2;
            let n = self.c.index(at)?;
            if n > QS_MAX {
                return Err(ParseError {
                    kind: LangErrorKind::Parameter,
                    span: self.c.span(at, self.c.i),
                    message: format!("parameter number {n} is out of range (at most {QS_MAX})"),
                });
            }
            return Ok(self.push(Node::TextParam(n)));
        }
        if self.c.eat_kw_glued("TOCHAR") {
            self.c.ws();
            if !self.c.eat_byte(b'(') {
                return Err(self.c.err(self.c.i, "expected ("));
            }
            self.c.ws();
            self.c.eat_kw_prefix("DAT");
            let v = self.sum_at(depth + 1)?;
            let dec = if self.c.eat_kw_glued("DECIMALS") {
                Some(self.sum_at(depth + 1)?)
            } else {
                None
            };
            self.c.ws();
            if !self.c.eat_byte(b')') {
                return Err(self.c.err(self.c.i, "expected )"));
            }
            return Ok(self.push(Node::ToChar(v, dec)));
        }
        if self.c.eat_kw_glued("SUBSTR") {
            self.c.ws();
            if !self.c.eat_byte(b'(') {
                return Err(self.c.err(self.c.i, "expected ("));
            }
            let src = self.tagged_text(depth, "SRC_")?;
            self.c.expect_kw_glued("BEG")?;
            let beg = self.sum_at(depth + 1)?;
            self.c.expect_kw_glued("LEN")?;
            let len = self.sum_at(depth + 1)?;
            self.c.ws();
            if !self.c.eat_byte(b')') {
                return Err(self.c.err(self.c.i, "expected )"));
            }
            return Ok(self.push(Node::SubStr(src, beg, len)));
        }
        Err(self
            .c
            .err(at, "a text, QS parameter or string function was expected"))
    }
}

impl Cur<'_> {
    /// Eats `tag` (`SRC_`, `DAT`) directly followed by anything.
    fn eat_kw_prefix(&mut self, tag: &str) -> bool {
        let end = self.i + tag.len();
        if end <= self.s.len() && ascii_eq(&self.s[self.i..end], tag) {
            self.i = end;
            true
        } else {
            false
        }
    }
}

/// Names of addresses and keywords the reader knows: these need no
/// upper-casing when written to an [`crate::Executed`] block.
const ADDRESSES: &[&str] = &[
    "PITCHCIRC",
    "HSC-MODE",
    "EULROT",
    "PROMIN",
    "PROROT",
    "EULPR",
    "EULNU",
    "PROPR",
    "START",
    "NUMX",
    "NUMY",
    "ROTX",
    "ROTY",
    "ROTZ",
    "DIST",
    "SPA",
    "SPB",
    "SPC",
    "ROT",
    "SCL",
    "LEN",
    "CCA",
    "DIA",
    "NUM",
    "DR2",
    "CHF",
    "DL",
    "DR",
    "PA",
    "PR",
    "BX",
    "BY",
    "BZ",
    "NX",
    "NY",
    "NZ",
    "TX",
    "TY",
    "TZ",
    "MB",
    "SEQ",
    "STAY",
    "MOVE",
    "TURN",
    "RL",
    "RR",
    "PAT",
    "POS",
];

fn is_axis(b: u8) -> bool {
    matches!(
        b.to_ascii_uppercase(),
        b'X' | b'Y' | b'Z' | b'A' | b'B' | b'C' | b'U' | b'V' | b'W'
    )
}

fn control(c: &mut Cur<'_>, out: &mut Block, word: &str, start: usize) -> Result<(), ParseError> {
    let mut name = None;
    let mut number = None;
    let mut tool = None;
    let kind = match word {
        "L" => Kind::Line,
        "LN" => Kind::LineNormal,
        "CC" => Kind::Centre,
        "C" => Kind::Circle,
        "CR" => Kind::CircleRadius,
        "CT" => Kind::CircleTangent,
        "LP" => Kind::LinePolar,
        "CP" => Kind::CirclePolar,
        "CTP" => Kind::CircleTangentPolar,
        "RND" => Kind::Rounding,
        "CHF" => {
            let at = c.i;
            let v = c
                .operand()?
                .ok_or_else(|| c.err(at, "CHF needs a length"))?;
            out.items.push(Item::Word {
                address: Name::Static("CHF"),
                value: v,
                incremental: false,
                span: c.span(start, c.i),
            });
            Kind::Chamfer
        }
        "APPR" | "DEP" => {
            c.ws();
            let (s, e) = c.letters();
            if s == e {
                return Err(c.err(s, "the form of APPR / DEP was expected"));
            }
            name = Some(upper_of(&c.s[s..e]));
            if word == "APPR" {
                Kind::Approach
            } else {
                Kind::Depart
            }
        }
        "TOOL" => {
            let call = if c.eat_kw("CALL") {
                true
            } else if c.eat_kw("DEF") {
                false
            } else {
                return Err(c.err(c.i, "TOOL must be followed by CALL or DEF"));
            };
            c.ws();
            let at = c.i;
            if c.peek() == b'"' {
                tool = Some(ToolRef::Name(
                    c.quoted().ok_or_else(|| c.err(at, "unclosed tool name"))?,
                ));
            } else if c.peek().eq_ignore_ascii_case(&b'Q')
                && c.peek_at(1).eq_ignore_ascii_case(&b'S')
            {
                c.i += 2;
                let n = c.index(at)?;
                tool = Some(ToolRef::Text(n));
            } else if let Some(v) = c.operand()? {
                tool = Some(ToolRef::Number(v));
            }
            if call {
                name = lone_axis(c);
            }
            if call { Kind::ToolCall } else { Kind::ToolDef }
        }
        "BLK" => {
            c.expect_kw("FORM")?;
            let at = c.i;
            number = Some(
                c.number()
                    .ok_or_else(|| c.err(at, "BLK FORM needs 0.1 or 0.2"))?,
            );
            name = lone_axis(c);
            Kind::BlockForm
        }
        "CYCL" => {
            if c.eat_kw("DEF") {
                c.ws();
                let at = c.i;
                let n = c
                    .number()
                    .ok_or_else(|| c.err(at, "CYCL DEF needs a cycle number"))?;
                number = Some(n);
                if n.fract() == 0.0 {
                    name = cycle_name(c);
                }
                Kind::CycleDef
            } else if c.eat_kw("CALL") {
                Kind::CycleCall
            } else {
                return Err(c.err(c.i, "CYCL must be followed by DEF or CALL"));
            }
        }
        "PATTERN" => {
            c.expect_kw("DEF")?;
            pattern(c, out)?;
            out.body = Body::Control {
                kind: Kind::PatternDef,
                name,
                number,
                tool,
            };
            return Ok(());
        }
        "PLANE" => {
            c.ws();
            let (s, e) = c.letters();
            if s == e {
                return Err(c.err(s, "the form of PLANE was expected"));
            }
            name = Some(upper_of(&c.s[s..e]));
            Kind::Plane
        }
        "FUNCTION" => {
            if c.eat_kw("RESET") {
                c.expect_kw("TCPM")?;
                c.end()?;
                out.body = Body::Control {
                    kind: Kind::TcpmReset,
                    name,
                    number,
                    tool,
                };
                return Ok(());
            }
            c.expect_kw("TCPM")?;
            tcpm(c, out)?;
            out.body = Body::Control {
                kind: Kind::Tcpm,
                name,
                number,
                tool,
            };
            return Ok(());
        }
        "STOP" => Kind::Stop,
        "M" | "F" | "S" => {
            // A block of M functions and words without a path (M128 F1000).
            c.i = start;
            Kind::Empty
        }
        _ => {
            // FK free contours (`FL`, `FC`, `FPOL` …), `SEL PGM` and the
            // like are named, so that the program's author sees which.
            return Err(c.err(
                start,
                &format!("`{word}` blocks are not read by the kernel"),
            ));
        }
    };
    let params = kind == Kind::CycleDef;
    items(c, out, &kind, params)?;
    out.body = Body::Control {
        kind,
        name,
        number,
        tool,
    };
    Ok(())
}

/// A single axis letter standing alone (`TOOL CALL 5 Z`, `BLK FORM 0.1 Z`).
fn lone_axis(c: &mut Cur<'_>) -> Option<String> {
    c.ws();
    let b = c.peek();
    let next = c.peek_at(1);
    if is_axis(b) && (next == 0 || matches!(next, b' ' | b'\t' | b'~')) {
        c.i += 1;
        Some(char::from(b.to_ascii_uppercase()).to_string())
    } else {
        None
    }
}

/// The name of a cycle: the words after the number up to the first
/// parameter `Q200=` (collapsed to single spaces, upper-cased).
fn cycle_name(c: &mut Cur<'_>) -> Option<String> {
    let mut name = String::new();
    loop {
        c.ws();
        if c.i >= c.s.len() {
            break;
        }
        let b = c.peek();
        if b.eq_ignore_ascii_case(&b'Q') && c.peek_at(1).is_ascii_digit() {
            break;
        }
        let start = c.i;
        while c.i < c.s.len() && !matches!(c.peek(), b' ' | b'\t' | b'~') {
            c.i += 1;
        }
        if !name.is_empty() {
            name.push(' ');
        }
        name.push_str(&upper_of(&c.s[start..c.i]));
    }
    (!name.is_empty()).then_some(name)
}

fn pattern(c: &mut Cur<'_>, out: &mut Block) -> Result<(), ParseError> {
    loop {
        if c.at_end() {
            return Ok(());
        }
        let (s, e) = c.letters();
        if s == e {
            return Err(c.err(s, "a pattern item (POS1, ROW1, …) was expected"));
        }
        let kind = upper_of(&c.s[s..e]);
        while c.peek().is_ascii_digit() {
            c.i += 1;
        }
        c.ws();
        if !c.eat_byte(b'(') {
            return Err(c.err(c.i, "expected ( after the pattern item"));
        }
        let close = c.s[c.i..]
            .iter()
            .position(|&b| b == b')')
            .map(|p| c.i + p)
            .ok_or_else(|| c.err(s, "unclosed pattern item"))?;
        let mut tmp = Block::default();
        let mut inner = Cur {
            s: &c.s[..close],
            i: c.i,
        };
        items(&mut inner, &mut tmp, &Kind::PatternDef, false)?;
        c.i = close + 1;
        out.pattern.push(PatternDefItem {
            kind,
            items: tmp.items,
        });
    }
}

fn tcpm(c: &mut Cur<'_>, out: &mut Block) -> Result<(), ParseError> {
    loop {
        if c.at_end() {
            return Ok(());
        }
        let start = c.i;
        while c.i < c.s.len() && !matches!(c.peek(), b' ' | b'\t' | b'~') {
            c.i += 1;
        }
        let first = upper_of(&c.s[start..c.i]);
        let joins = matches!(first.as_str(), "F" | "AXIS" | "PATHCTRL" | "REFPNT");
        if joins && !c.at_end() {
            let s2 = c.i;
            while c.i < c.s.len() && !matches!(c.peek(), b' ' | b'\t' | b'~') {
                c.i += 1;
            }
            let second = upper_of(&c.s[s2..c.i]);
            out.items.push(Item::Key {
                key: Name::Owned(format!("{first} {second}")),
                span: c.span(start, c.i),
            });
        } else {
            out.items.push(Item::Key {
                key: Name::Owned(first),
                span: c.span(start, c.i),
            });
        }
    }
}

/// The name of an address or keyword at bytes `a..b` of `src`.
fn name_of(src: &[u8], a: usize, b: usize) -> Name {
    let t = &src[a..b];
    for known in ADDRESSES {
        if ascii_eq(t, known) {
            return Name::Static(known);
        }
    }
    if let [one] = t {
        for known in [
            "X", "Y", "Z", "A", "B", "C", "U", "V", "W", "F", "S", "R", "T",
        ] {
            if known.as_bytes()[0] == one.to_ascii_uppercase() {
                return Name::Static(known);
            }
        }
    }
    Name::Range(a, b)
}

/// Whether byte `k` after the cursor starts a number or a parameter.
fn number_at(c: &Cur<'_>, k: usize) -> bool {
    let n = c.peek_at(k);
    n.is_ascii_digit()
        || (n == b'.' && c.peek_at(k + 1).is_ascii_digit())
        || (n.eq_ignore_ascii_case(&b'Q')
            && (c.peek_at(k + 1).is_ascii_digit()
                || (matches!(c.peek_at(k + 1).to_ascii_uppercase(), b'L' | b'R')
                    && c.peek_at(k + 2).is_ascii_digit())))
}

/// Reads words, keys and M functions to the end (of the block or of a
/// pattern item).
fn items(c: &mut Cur<'_>, out: &mut Block, kind: &Kind, params: bool) -> Result<(), ParseError> {
    let src = c.s;
    loop {
        if c.at_end() {
            return Ok(());
        }
        let start = c.i;
        // Cycle parameter Q200=…
        if params && c.peek().eq_ignore_ascii_case(&b'Q') && c.peek_at(1).is_ascii_digit() {
            c.i += 1;
            let n = c.index(start)?;
            c.ws();
            if !c.eat_byte(b'=') {
                return Err(c.err(start, "expected = after the cycle parameter"));
            }
            c.ws();
            let value = if c.eat_kw_glued("FMAX") || c.eat_kw_glued("MAX") {
                Operand::Num(f64::INFINITY)
            } else if c.eat_kw_glued("FAUTO") || c.eat_kw_glued("FU") || c.eat_kw_glued("FZ") {
                Operand::Num(f64::NAN)
            } else {
                c.need_operand()?
            };
            out.params.push(Param { n, value });
            continue;
        }
        let (s, mut e) = c.letters();
        if s == e {
            return Err(c.err(start, "an address was expected"));
        }
        // Addresses with a digit inside (P1X, DR2) or a dash (HSC-MODE).
        if ascii_eq(&src[s..e], "P")
            && c.peek().is_ascii_digit()
            && c.peek_at(1).is_ascii_alphabetic()
        {
            c.i += 1;
            c.letters();
            e = c.i;
        } else if ascii_eq(&src[s..e], "DR")
            && c.peek() == b'2'
            && matches!(c.peek_at(1), b'+' | b'-')
        {
            c.i += 1;
            e = c.i;
        } else if c.peek() == b'-' && c.peek_at(1).is_ascii_alphabetic() && !number_at(c, 1) {
            c.i += 1;
            c.letters();
            e = c.i;
        }
        // FQ3: the address F and the parameter Q3.
        let mut addr_end = e;
        if c.peek().is_ascii_digit() {
            for suffix in ["QL", "QR", "Q"] {
                if e - s > suffix.len() && src[s..e].ends_with_ignore_case(suffix) {
                    addr_end = e - suffix.len();
                    c.i = addr_end;
                    break;
                }
            }
        }
        let letters = &src[s..addr_end];
        let is = |k: &str| ascii_eq(letters, k);
        // M functions.
        if is("M") && c.peek().is_ascii_digit() {
            let n = c.index(start)?;
            out.items.push(Item::M {
                n,
                span: c.span(start, c.i),
            });
            continue;
        }
        // Whole keywords.
        if is("FMAX") || is("FAUTO") {
            let k = if is("FMAX") { "FMAX" } else { "FAUTO" };
            out.items.push(key(k, c.span(start, c.i)));
            continue;
        }
        if is("TABLE") || is("COORD") {
            let save = c.i;
            if c.eat_kw("ROT") {
                let k = if is("TABLE") {
                    "TABLE ROT"
                } else {
                    "COORD ROT"
                };
                out.items.push(key(k, c.span(start, c.i)));
                continue;
            }
            c.i = save;
        }
        // Incremental: I before an axis or a polar / angle address.
        let rest = &letters[1.min(letters.len())..];
        let incremental = letters.len() >= 2
            && letters[0].eq_ignore_ascii_case(&b'I')
            && ((rest.len() == 1 && is_axis(rest[0]))
                || ["PA", "PR", "ROT", "CCA", "SPA", "SPB", "SPC"]
                    .iter()
                    .any(|k| ascii_eq(rest, k)));
        let addr_start = if incremental { s + 1 } else { s };
        c.eat_byte(b':');
        let after_addr = c.i;
        c.ws();
        // F MAX, F AUTO, MB MAX.
        if c.eat_kw("MAX") {
            let k = if is("F") {
                Name::Static("FMAX")
            } else {
                Name::Owned(format!("{} MAX", upper_of(letters)))
            };
            out.items.push(Item::Key {
                key: k,
                span: c.span(start, c.i),
            });
            continue;
        }
        if is("F") && c.eat_kw("AUTO") {
            out.items.push(key("FAUTO", c.span(start, c.i)));
            continue;
        }
        let sign = c.peek();
        let mut after_sign = 1;
        while matches!(c.peek_at(after_sign), b' ' | b'\t') {
            after_sign += 1;
        }
        if matches!(sign, b'+' | b'-') && !number_at(c, after_sign) {
            // A sign with no value: the keys DR+, DR-, SEQ+, SEQ-.
            c.i += 1;
            let k = match (upper_of(letters).as_str(), sign) {
                ("DR", b'+') => Name::Static("DR+"),
                ("DR", _) => Name::Static("DR-"),
                ("SEQ", b'+') => Name::Static("SEQ+"),
                ("SEQ", _) => Name::Static("SEQ-"),
                (l, _) => Name::Owned(format!("{l}{}", char::from(sign))),
            };
            out.items.push(Item::Key {
                key: k,
                span: c.span(start, c.i),
            });
            continue;
        }
        let value_at = c.i;
        if let Some(v) = c.operand()? {
            // R0 on a path is the key "no radius compensation".
            let plain_zero = matches!(v, Operand::Num(z) if z == 0.0)
                && src[value_at..c.i].iter().all(|b| *b == b'0');
            if is("R")
                && plain_zero
                && !matches!(kind, Kind::CircleRadius | Kind::Rounding | Kind::PatternDef)
            {
                out.items.push(key("R0", c.span(start, c.i)));
                continue;
            }
            out.items.push(Item::Word {
                address: name_of(src, addr_start, addr_end),
                value: v,
                incremental,
                span: c.span(start, c.i),
            });
            continue;
        }
        c.i = after_addr;
        // A keyword without value (RL, RR, STAY, MOVE, PAT, a bare axis).
        out.items.push(Item::Key {
            key: name_of(src, s, addr_end),
            span: c.span(start, addr_end),
        });
    }
}

fn key(k: &'static str, span: Span) -> Item {
    Item::Key {
        key: Name::Static(k),
        span,
    }
}

trait EndsWithIgnoreCase {
    fn ends_with_ignore_case(&self, suffix: &str) -> bool;
}

impl EndsWithIgnoreCase for [u8] {
    fn ends_with_ignore_case(&self, suffix: &str) -> bool {
        self.len() >= suffix.len() && ascii_eq(&self[self.len() - suffix.len()..], suffix)
    }
}
