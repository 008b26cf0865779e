//! The parser: the tokens of one line into a [`Line`].
//!
//! Recursion happens only where the text nests (parentheses, function
//! arguments, indices, unary operators), each level counted against
//! [`MAX_DEPTH`]; binary operators are read by precedence climbing, whose
//! recursion is bounded by the eleven precedence levels, and a line holds at
//! most [`MAX_OPERATIONS`] of them. No line can build a tree deep enough
//! to overflow a small stack when it is read, walked or dropped.

use fiveaxis_gcode::Span;

use crate::error::{ParseError, ParseErrorKind};
use crate::lex::{Tok, Token, lex};
use crate::names::{call_kind, is_address, is_keyword};
use crate::tree::{
    Assign, BinOp, BlockNumber, Call, CallKind, Comment, Declarator, Def, Expr, ExprKind,
    IndirectCall, Init, Item, Jump, JumpKind, JumpTarget, Line, Name, Param, PositionMode, Proc,
    Skip, Statement, SyncAction, SyncWhen, Type, UnOp, Var, Word,
};

/// How deep parentheses, function arguments, indices and unary operators
/// may nest in one line. A bound of this reader (the control's own limit
/// was not found), far above what programs write.
pub const MAX_DEPTH: u8 = 32;

/// Most binary operations in one line. A bound of this reader: it bounds
/// the depth of a chain like `1+1+1+…`.
pub const MAX_OPERATIONS: usize = 256;

type Result<T> = std::result::Result<T, ParseError>;

/// Reads one line of a SINUMERIK part program (`text` without or with its
/// line end) into a [`Line`]; `line` is its number, kept in the result and
/// in errors.
///
/// # Errors
///
/// A [`ParseError`] with the columns of the first text that cannot be
/// read: [`ParseErrorKind::Syntax`] (alarm 12080) for text the language
/// does not allow, [`ParseErrorKind::TooDeep`] and
/// [`ParseErrorKind::TooManyOperations`] past the reader's bounds.
pub fn parse_line(text: &[u8], line: u32) -> Result<Line> {
    let mut text = text;
    while let [rest @ .., b'\r' | b'\n'] = text {
        text = rest;
    }
    let blank = text
        .iter()
        .take_while(|b| matches!(b, b' ' | b'\t'))
        .count();
    if text.get(blank) == Some(&b'%') {
        let name = String::from_utf8_lossy(&text[blank + 1..])
            .trim()
            .to_string();
        return Ok(Line {
            line,
            skip: None,
            number: None,
            label: None,
            statement: Statement::ProgramHeader(name),
            comment: None,
        });
    }
    let lexed = lex(text).map_err(|(span, message)| ParseError {
        kind: ParseErrorKind::Syntax,
        line,
        span,
        message,
    })?;
    let comment = lexed.comment.map(|(text, span)| Comment { text, span });
    let mut p = Parser {
        text,
        toks: &lexed.tokens,
        pos: 0,
        depth: 0,
        ops: 0,
        line,
    };
    if lexed.tokens.is_empty()
        && let Some(path) = comment
            .as_ref()
            .and_then(|c| c.text.trim().strip_prefix("$PATH="))
    {
        return Ok(Line {
            line,
            skip: None,
            number: None,
            label: None,
            statement: Statement::PathHeader(path.trim().to_string()),
            comment,
        });
    }
    let skip = p.skip()?;
    let number = p.block_number()?;
    let label = p.label();
    let statement = p.statement()?;
    Ok(Line {
        line,
        skip,
        number,
        label,
        statement,
        comment,
    })
}

struct Parser<'a> {
    text: &'a [u8],
    toks: &'a [Token],
    pos: usize,
    depth: u8,
    ops: usize,
    line: u32,
}

impl<'a> Parser<'a> {
    // ---- tokens ----

    fn peek(&self) -> Option<&'a Tok> {
        self.toks.get(self.pos).map(|t| &t.tok)
    }

    fn peek_at(&self, k: usize) -> Option<&'a Tok> {
        self.toks.get(self.pos + k).map(|t| &t.tok)
    }

    fn peek_name(&self) -> Option<&'a str> {
        match self.peek() {
            Some(Tok::Name(n)) => Some(n),
            _ => None,
        }
    }

    fn next_is(&self, tok: &Tok) -> bool {
        self.peek() == Some(tok)
    }

    fn next_is_name(&self, name: &str) -> bool {
        self.peek_name() == Some(name)
    }

    /// The columns of the next token or, at the end of the block, of the
    /// last one (an error there is about what is missing after it).
    fn here(&self) -> Span {
        self.toks
            .get(self.pos)
            .or(self.toks.last())
            .map_or(Span::new(1, 2), |t| t.span)
    }

    /// The end column of the last token taken.
    fn last_end(&self) -> u32 {
        self.pos
            .checked_sub(1)
            .and_then(|i| self.toks.get(i))
            .map_or(1, |t| t.span.end)
    }

    fn bump(&mut self) -> Option<&'a Token> {
        let t = self.toks.get(self.pos);
        if t.is_some() {
            self.pos += 1;
        }
        t
    }

    fn at_end(&self) -> bool {
        self.pos >= self.toks.len()
    }

    fn error(&self, kind: ParseErrorKind, span: Span, message: impl Into<String>) -> ParseError {
        ParseError {
            kind,
            line: self.line,
            span,
            message: message.into(),
        }
    }

    fn syntax(&self, span: Span, message: impl Into<String>) -> ParseError {
        self.error(ParseErrorKind::Syntax, span, message)
    }

    /// The text of a span, as written.
    fn written(&self, span: Span) -> String {
        let start = (span.start as usize).saturating_sub(1);
        let end = (span.end as usize).saturating_sub(1).min(self.text.len());
        String::from_utf8_lossy(self.text.get(start..end).unwrap_or_default()).into_owned()
    }

    /// An error at the next token: "expected X, found `…`".
    fn expected(&self, what: &str) -> ParseError {
        let span = self.here();
        if self.at_end() {
            self.syntax(span, format!("expected {what} before the end of the block"))
        } else {
            self.syntax(
                span,
                format!("expected {what}, found `{}`", self.written(span)),
            )
        }
    }

    fn expect(&mut self, tok: &Tok, what: &str) -> Result<Span> {
        if self.next_is(tok) {
            Ok(self.bump().map_or_else(|| self.here(), |t| t.span))
        } else {
            Err(self.expected(what))
        }
    }

    fn expect_name(&mut self, name: &str) -> Result<Span> {
        if self.next_is_name(name) {
            Ok(self.bump().map_or_else(|| self.here(), |t| t.span))
        } else {
            Err(self.expected(&format!("`{name}`")))
        }
    }

    fn expect_end(&self) -> Result<()> {
        if self.at_end() {
            Ok(())
        } else {
            let span = self.here();
            Err(self.syntax(span, format!("`{}` cannot follow here", self.written(span))))
        }
    }

    fn enter(&mut self) -> Result<()> {
        if self.depth >= MAX_DEPTH {
            return Err(self.error(
                ParseErrorKind::TooDeep,
                self.here(),
                format!("nested deeper than {MAX_DEPTH} levels"),
            ));
        }
        self.depth += 1;
        Ok(())
    }

    fn leave(&mut self) {
        self.depth = self.depth.saturating_sub(1);
    }

    /// A name that may be defined: a variable, label or subprogram name.
    fn identifier(&mut self, what: &str) -> Result<Name> {
        match self.toks.get(self.pos) {
            Some(Token {
                tok: Tok::Name(n),
                span,
            }) if !is_keyword(n) => {
                self.pos += 1;
                Ok(Name {
                    text: n.clone(),
                    span: *span,
                })
            }
            _ => Err(self.expected(what)),
        }
    }

    // ---- block prefix ----

    fn skip(&mut self) -> Result<Option<Skip>> {
        let Some(slash) = self.toks.first().filter(|t| t.tok == Tok::Slash) else {
            return Ok(None);
        };
        self.pos = 1;
        let mut span = slash.span;
        let mut level = 0;
        if let Some(Token {
            tok: Tok::Number(n),
            span: s,
        }) = self.toks.get(1)
            && s.start == slash.span.end
        {
            if s.end != s.start + 1 || !(0.0..=9.0).contains(n) || n.fract() != 0.0 {
                return Err(self.syntax(*s, "a skip level is one digit, /0 … /9"));
            }
            level = *n as u8;
            span.end = s.end;
            self.pos = 2;
        }
        Ok(Some(Skip { level, span }))
    }

    fn block_number(&mut self) -> Result<Option<BlockNumber>> {
        let main = match self.peek() {
            Some(Tok::Name(n)) if n == "N" => false,
            Some(Tok::Colon) => true,
            _ => return Ok(None),
        };
        let Some(Token {
            tok: Tok::Number(n),
            span,
        }) = self.toks.get(self.pos + 1)
        else {
            if main {
                return Err(self.syntax(self.here(), "a main block `:` needs its number"));
            }
            return Ok(None);
        };
        let start = self.here().start;
        if n.fract() != 0.0 || *n < 0.0 || *n > f64::from(u32::MAX) {
            return Err(self.syntax(*span, "a block number is a whole number"));
        }
        self.pos += 2;
        Ok(Some(BlockNumber {
            value: *n as u32,
            main,
            span: Span::new(start, span.end),
        }))
    }

    fn label(&mut self) -> Option<Name> {
        let Some(Token {
            tok: Tok::Name(n),
            span,
        }) = self.toks.get(self.pos)
        else {
            return None;
        };
        if self.peek_at(1) != Some(&Tok::Colon) || is_keyword(n) || n.starts_with('$') {
            return None;
        }
        self.pos += 2;
        Some(Name {
            text: n.clone(),
            span: *span,
        })
    }

    // ---- statements ----

    fn statement(&mut self) -> Result<Statement> {
        let Some(first) = self.peek() else {
            return Ok(Statement::Empty);
        };
        let name = match first {
            Tok::Name(n) => n.as_str(),
            _ => "",
        };
        let simple = match name {
            "ELSE" => Some(Statement::Else),
            "ENDIF" => Some(Statement::EndIf),
            "ENDWHILE" => Some(Statement::EndWhile),
            "ENDFOR" => Some(Statement::EndFor),
            "REPEAT" => Some(Statement::Repeat),
            "LOOP" => Some(Statement::Loop),
            "ENDLOOP" => Some(Statement::EndLoop),
            _ => None,
        };
        if let Some(statement) = simple {
            self.bump();
            self.expect_end()?;
            return Ok(statement);
        }
        let statement = match name {
            "DEF" => Statement::Def(self.def()?),
            "DEFINE" => return self.define(),
            "PROC" => Statement::Proc(self.proc()?),
            "IF" => {
                self.bump();
                let condition = self.expr()?;
                if self.jump_kind().is_some() {
                    let jump = self.jump()?;
                    Statement::IfJump { condition, jump }
                } else {
                    Statement::If(condition)
                }
            }
            "WHILE" => {
                self.bump();
                Statement::While(self.expr()?)
            }
            "UNTIL" => {
                self.bump();
                Statement::Until(self.expr()?)
            }
            "FOR" => {
                self.bump();
                let variable = self.var()?;
                self.expect(&Tok::Assign, "`=` after the counter of FOR")?;
                let from = self.expr()?;
                self.expect_name("TO")?;
                let to = self.expr()?;
                Statement::For { variable, from, to }
            }
            "CASE" => self.case()?,
            "ID" | "IDS" if self.peek_at(1) == Some(&Tok::Assign) => self.sync_action()?,
            "WHEN" | "WHENEVER" | "FROM" | "EVERY" | "DO" => self.sync_action()?,
            _ => {
                let items = self.items()?;
                if items.is_empty() {
                    Statement::Empty
                } else {
                    Statement::Block(items)
                }
            }
        };
        self.expect_end()?;
        Ok(statement)
    }

    fn case(&mut self) -> Result<Statement> {
        self.bump();
        let selector = self.expr()?;
        self.expect_name("OF")?;
        let mut arms = Vec::new();
        let mut default = None;
        while !self.at_end() {
            if self.next_is_name("DEFAULT") {
                self.bump();
                default = Some(self.jump()?);
                break;
            }
            let constant = self.expr()?;
            let jump = self.jump()?;
            arms.push((constant, jump));
        }
        if arms.is_empty() && default.is_none() {
            return Err(self.expected("a constant and its jump after OF"));
        }
        Ok(Statement::Case {
            selector,
            arms,
            default,
        })
    }

    fn sync_action(&mut self) -> Result<Statement> {
        let mut id = None;
        if let Some(n @ ("ID" | "IDS")) = self.peek_name() {
            self.bump();
            self.bump();
            id = Some((n == "IDS", self.expr()?));
        }
        let when = match self.peek_name() {
            Some("WHEN") => Some(SyncWhen::When),
            Some("WHENEVER") => Some(SyncWhen::Whenever),
            Some("FROM") => Some(SyncWhen::From),
            Some("EVERY") => Some(SyncWhen::Every),
            _ => None,
        };
        let condition = match when {
            Some(when) => {
                self.bump();
                Some((when, self.expr()?))
            }
            None => None,
        };
        self.expect_name("DO")?;
        let actions = self.items()?;
        if actions.is_empty() {
            return Err(self.expected("an action after DO"));
        }
        Ok(Statement::SyncAction(SyncAction {
            id,
            condition,
            actions,
        }))
    }

    fn data_type(&mut self) -> Result<Type> {
        let ty = match self.peek_name() {
            Some("INT") => Type::Int,
            Some("REAL") => Type::Real,
            Some("BOOL") => Type::Bool,
            Some("CHAR") => Type::Char,
            Some("AXIS") => Type::Axis,
            Some("FRAME") => Type::Frame,
            Some("STRING") => {
                self.bump();
                self.expect(&Tok::LBracket, "`[` and the length after STRING")?;
                let span = self.here();
                let Some(Tok::Number(n)) = self.peek() else {
                    return Err(self.expected("the length of the string"));
                };
                if n.fract() != 0.0 || *n < 1.0 || *n > f64::from(u32::MAX) {
                    return Err(self.syntax(span, "a string length is a whole number"));
                }
                self.bump();
                self.expect(&Tok::RBracket, "`]`")?;
                return Ok(Type::String(*n as u32));
            }
            _ => {
                return Err(self.expected("a type (INT, REAL, BOOL, CHAR, STRING[n], AXIS, FRAME)"));
            }
        };
        self.bump();
        Ok(ty)
    }

    fn def(&mut self) -> Result<Def> {
        self.bump();
        let scope = match self.toks.get(self.pos) {
            Some(Token {
                tok: Tok::Name(n),
                span,
            }) if n == "NCK" || n == "CHAN" => {
                self.pos += 1;
                Some(Name {
                    text: n.clone(),
                    span: *span,
                })
            }
            _ => None,
        };
        let ty = self.data_type()?;
        let mut vars = Vec::new();
        loop {
            let name = self.identifier("the name of a variable")?;
            let mut dims = Vec::new();
            if self.next_is(&Tok::LBracket) {
                self.bump();
                loop {
                    dims.push(self.expr()?);
                    if self.next_is(&Tok::Comma) {
                        self.bump();
                    } else {
                        break;
                    }
                }
                self.expect(&Tok::RBracket, "`]` after the dimensions")?;
            }
            let init = if self.next_is(&Tok::Assign) {
                self.bump();
                Some(self.init()?)
            } else {
                None
            };
            vars.push(Declarator { name, dims, init });
            if self.next_is(&Tok::Comma) {
                self.bump();
            } else {
                break;
            }
        }
        Ok(Def { scope, ty, vars })
    }

    fn init(&mut self) -> Result<Init> {
        let set_or_rep = match self.peek_name() {
            Some(n @ ("SET" | "REP")) if self.peek_at(1) == Some(&Tok::LParen) => Some(n),
            _ => None,
        };
        let Some(which) = set_or_rep else {
            return Ok(Init::Value(self.expr()?));
        };
        self.bump();
        self.bump();
        let mut values = Vec::new();
        loop {
            values.push(self.expr()?);
            if self.next_is(&Tok::Comma) {
                self.bump();
            } else {
                break;
            }
        }
        self.expect(&Tok::RParen, "`)`")?;
        if which == "REP" {
            let mut values = values.into_iter();
            match (values.next(), values.next()) {
                (Some(v), None) => Ok(Init::Rep(v)),
                _ => Err(self.syntax(self.here(), "REP takes one value")),
            }
        } else {
            Ok(Init::Set(values))
        }
    }

    fn define(&mut self) -> Result<Statement> {
        self.bump();
        let name = self.identifier("the name of the macro")?;
        let as_span = self.expect_name("AS")?;
        let start = as_span.end as usize - 1;
        let end = self
            .text
            .iter()
            .position(|&b| b == b';')
            .unwrap_or(self.text.len());
        let text = String::from_utf8_lossy(self.text.get(start..end).unwrap_or_default())
            .trim()
            .to_string();
        if text.is_empty() {
            return Err(self.expected("the text of the macro after AS"));
        }
        Ok(Statement::Define { name, text })
    }

    fn proc(&mut self) -> Result<Proc> {
        self.bump();
        let name = self.identifier("the name of the subprogram")?;
        let mut params = Vec::new();
        if self.next_is(&Tok::LParen) {
            self.bump();
            if !self.next_is(&Tok::RParen) {
                loop {
                    let by_reference = self.next_is_name("VAR");
                    if by_reference {
                        self.bump();
                    }
                    let ty = self.data_type()?;
                    let name = self.identifier("the name of a parameter")?;
                    let mut dims = Vec::new();
                    if self.next_is(&Tok::LBracket) {
                        self.bump();
                        loop {
                            if matches!(self.peek(), Some(Tok::Comma | Tok::RBracket)) {
                                dims.push(None);
                            } else {
                                dims.push(Some(self.expr()?));
                            }
                            if self.next_is(&Tok::Comma) {
                                self.bump();
                            } else {
                                break;
                            }
                        }
                        self.expect(&Tok::RBracket, "`]` after the dimensions")?;
                    }
                    params.push(Param {
                        by_reference,
                        ty,
                        name,
                        dims,
                    });
                    if self.next_is(&Tok::Comma) {
                        self.bump();
                    } else {
                        break;
                    }
                }
            }
            self.expect(&Tok::RParen, "`)` after the parameters")?;
        }
        let mut attributes = Vec::new();
        while !self.at_end() {
            attributes.push(self.identifier("an attribute (SAVE, DISPLOF …)")?);
        }
        Ok(Proc {
            name,
            params,
            attributes,
        })
    }

    // ---- jumps ----

    fn jump_kind(&self) -> Option<JumpKind> {
        Some(match self.peek_name()? {
            "GOTOF" => JumpKind::Gotof,
            "GOTOB" => JumpKind::Gotob,
            "GOTO" => JumpKind::Goto,
            "GOTOC" => JumpKind::Gotoc,
            "GOTOS" => JumpKind::Gotos,
            _ => return None,
        })
    }

    fn jump(&mut self) -> Result<Jump> {
        let Some(kind) = self.jump_kind() else {
            return Err(self.expected("a jump (GOTOF, GOTOB, GOTO, GOTOC, GOTOS)"));
        };
        let start = self.here().start;
        self.bump();
        let target = if kind == JumpKind::Gotos {
            None
        } else {
            Some(self.jump_target()?)
        };
        Ok(Jump {
            kind,
            target,
            span: Span::new(start, self.last_end()),
        })
    }

    fn jump_target(&mut self) -> Result<JumpTarget> {
        let span = self.here();
        match self.peek() {
            Some(Tok::Number(n)) if n.fract() == 0.0 && *n >= 0.0 && *n <= f64::from(u32::MAX) => {
                self.bump();
                Ok(JumpTarget::Block(*n as u32, span))
            }
            Some(Tok::Name(n))
                if n.len() > 1
                    && n.starts_with('N')
                    && n[1..].bytes().all(|b| b.is_ascii_digit()) =>
            {
                let value = n[1..]
                    .parse::<u32>()
                    .map_err(|_| self.syntax(span, "a block number too large"))?;
                self.bump();
                Ok(JumpTarget::Block(value, span))
            }
            _ => Ok(JumpTarget::Label(
                self.identifier("a label or block number")?,
            )),
        }
    }

    // ---- blocks ----

    fn items(&mut self) -> Result<Vec<Item>> {
        let mut items: Vec<Item> = Vec::new();
        while let Some(tok) = self.peek() {
            let Tok::Name(name) = tok else {
                return Err(self.expected("an address, a name or a jump"));
            };
            let start = self.here();
            if self.jump_kind().is_some() {
                items.push(Item::Jump(self.jump()?));
                continue;
            }
            match name.as_str() {
                "CALL" => {
                    items.push(self.indirect_call()?);
                    continue;
                }
                "MCALL" => {
                    self.bump();
                    let call = match self.peek_name() {
                        Some(n) if !is_keyword(n) => Some(self.call()?),
                        _ => None,
                    };
                    items.push(Item::ModalCall {
                        call,
                        span: Span::new(start.start, self.last_end()),
                    });
                    continue;
                }
                _ => {}
            }
            if is_keyword(name) {
                return Err(self.syntax(start, format!("`{name}` must begin its block")));
            }
            match self.peek_at(1) {
                Some(Tok::Assign) => {
                    self.bump();
                    self.bump();
                    if is_address(name) {
                        let (value, mode) = self.word_value()?;
                        items.push(Item::Word(Word {
                            address: name.clone(),
                            value,
                            mode,
                            equals: true,
                            span: Span::new(start.start, self.last_end()),
                        }));
                    } else {
                        let target = Var {
                            name: name.clone(),
                            indices: Vec::new(),
                            span: start,
                        };
                        items.push(self.assign_value(target)?);
                    }
                }
                Some(Tok::LBracket) => {
                    let target = self.var()?;
                    self.expect(&Tok::Assign, "`=` after the indexed variable")?;
                    items.push(self.assign_value(target)?);
                }
                Some(Tok::LParen) => items.push(Item::Call(self.call()?)),
                _ if name.len() == 1 && name != "$" && name != "_" => {
                    let word = self.literal_word()?;
                    if word.address == "L" {
                        // `L100`: a subprogram named by L and digits.
                        items.push(Item::Call(Call {
                            name: self.written(word.span).to_ascii_uppercase(),
                            kind: CallKind::User,
                            args: None,
                            passes: None,
                            span: word.span,
                        }));
                    } else if let (
                        "P",
                        Some(Item::Call(Call {
                            passes: passes @ None,
                            ..
                        })),
                    ) = (word.address.as_str(), items.last_mut())
                    {
                        *passes = Some(word.value);
                    } else {
                        items.push(Item::Word(word));
                    }
                }
                _ => items.push(Item::Call(self.call()?)),
            }
        }
        Ok(items)
    }

    fn assign_value(&mut self, target: Var) -> Result<Item> {
        let value = self.expr()?;
        Ok(Item::Assign(Assign {
            span: Span::new(target.span.start, self.last_end()),
            target,
            value,
        }))
    }

    /// `X10`, `X-10`, `G642`: an address letter and a number.
    fn literal_word(&mut self) -> Result<Word> {
        let Some(Token {
            tok: Tok::Name(address),
            span: start,
        }) = self.bump()
        else {
            return Err(self.expected("an address"));
        };
        let negative = match self.peek() {
            Some(Tok::Minus) => true,
            Some(Tok::Plus) => false,
            Some(Tok::Number(_)) => false,
            _ => {
                return Err(self.syntax(
                    *start,
                    format!("the address {address} needs a value (`{address}10` or `{address}=…`)"),
                ));
            }
        };
        if matches!(self.peek(), Some(Tok::Minus | Tok::Plus)) {
            self.bump();
        }
        let value_span = self.here();
        let Some(Tok::Number(n)) = self.peek() else {
            return Err(self.expected(&format!("a number after {address}")));
        };
        self.bump();
        let value = if negative { -n } else { *n };
        Ok(Word {
            address: address.clone(),
            value: Expr {
                kind: ExprKind::Number(value),
                span: Span::new(start.end, value_span.end),
            },
            mode: None,
            equals: false,
            span: Span::new(start.start, value_span.end),
        })
    }

    /// The value after `X=`: an expression, or `AC(…)`, `IC(…)` … around one.
    fn word_value(&mut self) -> Result<(Expr, Option<PositionMode>)> {
        if let Some(mode) = self.peek_name().and_then(PositionMode::from_name)
            && self.peek_at(1) == Some(&Tok::LParen)
        {
            self.bump();
            self.bump();
            let value = self.expr()?;
            self.expect(&Tok::RParen, "`)`")?;
            return Ok((value, Some(mode)));
        }
        Ok((self.expr()?, None))
    }

    /// A name with its arguments in parentheses, if any.
    fn call(&mut self) -> Result<Call> {
        let name = self.identifier("the name of a subprogram or cycle")?;
        let args = if self.next_is(&Tok::LParen) {
            Some(self.args()?)
        } else {
            None
        };
        Ok(Call {
            kind: call_kind(&name.text),
            name: name.text,
            args,
            passes: None,
            span: Span::new(name.span.start, self.last_end()),
        })
    }

    fn indirect_call(&mut self) -> Result<Item> {
        let start = self.here().start;
        self.bump();
        let program = if self.at_end() || self.next_is_name("BLOCK") {
            None
        } else {
            Some(self.expr()?)
        };
        let section = if self.next_is_name("BLOCK") {
            self.bump();
            let from = self.jump_target()?;
            let to = if self.next_is_name("TO") {
                self.bump();
                Some(self.jump_target()?)
            } else {
                None
            };
            Some((from, to))
        } else {
            None
        };
        if program.is_none() && section.is_none() {
            return Err(self.expected("the program to call after CALL"));
        }
        Ok(Item::IndirectCall(IndirectCall {
            program,
            section,
            span: Span::new(start, self.last_end()),
        }))
    }

    // ---- expressions ----

    /// A variable: a name with indices, if any.
    fn var(&mut self) -> Result<Var> {
        let name = self.identifier("a variable")?;
        let mut indices = Vec::new();
        if self.next_is(&Tok::LBracket) {
            self.enter()?;
            self.bump();
            loop {
                indices.push(self.expr()?);
                if self.next_is(&Tok::Comma) {
                    self.bump();
                } else {
                    break;
                }
            }
            self.expect(&Tok::RBracket, "`]` after the indices")?;
            self.leave();
        }
        Ok(Var {
            name: name.text,
            indices,
            span: Span::new(name.span.start, self.last_end()),
        })
    }

    /// `( a, , b )`: arguments, `None` for those left out.
    fn args(&mut self) -> Result<Vec<Option<Expr>>> {
        self.enter()?;
        self.expect(&Tok::LParen, "`(`")?;
        let mut args = Vec::new();
        if self.next_is(&Tok::RParen) {
            self.bump();
            self.leave();
            return Ok(args);
        }
        loop {
            if matches!(self.peek(), Some(Tok::Comma | Tok::RParen)) {
                args.push(None);
            } else {
                args.push(Some(self.expr()?));
            }
            if self.next_is(&Tok::Comma) {
                self.bump();
            } else {
                break;
            }
        }
        self.expect(&Tok::RParen, "`,` or `)` after an argument")?;
        self.leave();
        Ok(args)
    }

    fn expr(&mut self) -> Result<Expr> {
        self.binary(0)
    }

    fn binary_op(&self) -> Option<BinOp> {
        Some(match self.peek()? {
            Tok::Star => BinOp::Mul,
            Tok::Slash => BinOp::Div,
            Tok::Plus => BinOp::Add,
            Tok::Minus => BinOp::Sub,
            Tok::Concat => BinOp::Concat,
            Tok::Eq => BinOp::Eq,
            Tok::Ne => BinOp::Ne,
            Tok::Gt => BinOp::Gt,
            Tok::Lt => BinOp::Lt,
            Tok::Ge => BinOp::Ge,
            Tok::Le => BinOp::Le,
            Tok::Colon => BinOp::Chain,
            Tok::Name(n) => BinOp::from_word(n)?,
            _ => return None,
        })
    }

    /// Precedence climbing: operators binding at least as tightly as
    /// `min`, left to right.
    fn binary(&mut self, min: u8) -> Result<Expr> {
        let mut left = self.unary()?;
        while let Some(op) = self.binary_op() {
            let precedence = op.precedence();
            if precedence < min {
                break;
            }
            let op_span = self.here();
            self.ops += 1;
            if self.ops > MAX_OPERATIONS {
                return Err(self.error(
                    ParseErrorKind::TooManyOperations,
                    op_span,
                    format!("more than {MAX_OPERATIONS} operations in one line"),
                ));
            }
            self.bump();
            let right = self.binary(precedence + 1)?;
            let span = Span::new(left.span.start, right.span.end);
            left = Expr {
                kind: ExprKind::Binary(op, Box::new(left), Box::new(right)),
                span,
            };
        }
        Ok(left)
    }

    fn unary(&mut self) -> Result<Expr> {
        let op = match self.peek() {
            Some(Tok::Minus) => UnOp::Neg,
            Some(Tok::Plus) => UnOp::Plus,
            Some(Tok::Name(n)) if n == "NOT" => UnOp::Not,
            Some(Tok::Name(n)) if n == "B_NOT" => UnOp::BitNot,
            _ => return self.primary(),
        };
        let start = self.here().start;
        self.enter()?;
        self.bump();
        let operand = self.unary()?;
        self.leave();
        let span = Span::new(start, operand.span.end);
        let kind = match (op, operand.kind) {
            (UnOp::Neg, ExprKind::Number(x)) => ExprKind::Number(-x),
            (UnOp::Plus, ExprKind::Number(x)) => ExprKind::Number(x),
            (op, kind) => ExprKind::Unary(
                op,
                Box::new(Expr {
                    kind,
                    span: operand.span,
                }),
            ),
        };
        Ok(Expr { kind, span })
    }

    fn primary(&mut self) -> Result<Expr> {
        let span = self.here();
        let kind = match self.peek() {
            Some(Tok::Number(n)) => ExprKind::Number(*n),
            Some(Tok::Str(s)) => ExprKind::String(s.clone()),
            Some(Tok::LParen) => {
                self.enter()?;
                self.bump();
                let inner = self.expr()?;
                let close = self.expect(&Tok::RParen, "`)`")?;
                self.leave();
                return Ok(Expr {
                    kind: inner.kind,
                    span: Span::new(span.start, close.end),
                });
            }
            Some(Tok::Name(n)) if n == "TRUE" || n == "FALSE" => ExprKind::Bool(n == "TRUE"),
            Some(Tok::Name(n)) if !is_keyword(n) => {
                if self.peek_at(1) == Some(&Tok::LParen) {
                    let name = n.clone();
                    self.bump();
                    let args = self.args()?;
                    return Ok(Expr {
                        kind: ExprKind::Call(name, args),
                        span: Span::new(span.start, self.last_end()),
                    });
                }
                let var = self.var()?;
                return Ok(Expr {
                    span: var.span,
                    kind: ExprKind::Var(var),
                });
            }
            _ => return Err(self.expected("a value")),
        };
        self.bump();
        Ok(Expr { kind, span })
    }
}
