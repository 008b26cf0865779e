//! The tokens of one line.
//!
//! Names are upper-cased. A name made of one letter and digits in a
//! place where a word may begin (`G53G0X0M5`, `N10`, `X9.285`) is split
//! into the address letter and a number (after a label's `:` too); where an expression, a
//! declaration or a jump target goes (`X=R1*2`, `DEF REAL X1`, `GOTOF L1`),
//! and before `=`, `(`, `[` or `:` (`A3=0`, `M202(…)`, `L1:`), it is kept
//! whole. Blanks separate tokens and are otherwise dropped.

use fiveaxis_gcode::Span;

use crate::names::keeps_next_name_whole;

/// A token.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Tok {
    /// A name, upper-cased.
    Name(String),
    /// A number, with its text.
    Number(f64),
    /// A string between double quotes.
    Str(String),
    /// `=`
    Assign,
    /// `==`
    Eq,
    /// `<>`
    Ne,
    /// `<`
    Lt,
    /// `>`
    Gt,
    /// `<=`
    Le,
    /// `>=`
    Ge,
    /// `<<`
    Concat,
    /// `+`
    Plus,
    /// `-`
    Minus,
    /// `*`
    Star,
    /// `/`
    Slash,
    /// `(`
    LParen,
    /// `)`
    RParen,
    /// `[`
    LBracket,
    /// `]`
    RBracket,
    /// `,`
    Comma,
    /// `:`
    Colon,
}

/// A token and its columns.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Token {
    pub tok: Tok,
    pub span: Span,
}

/// The tokens of a line and its comment, or the columns and message of
/// the first text that is no token.
pub(crate) struct Lexed {
    pub tokens: Vec<Token>,
    pub comment: Option<(String, Span)>,
}

fn col(i: usize) -> u32 {
    u32::try_from(i + 1).unwrap_or(u32::MAX)
}

fn span(start: usize, end: usize) -> Span {
    Span::new(col(start), col(end))
}

fn is_name_start(b: u8) -> bool {
    b.is_ascii_alphabetic() || b == b'_' || b == b'$'
}

fn is_name_char(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

/// Splits `text` into tokens up to its `;` comment.
pub(crate) fn lex(text: &[u8]) -> Result<Lexed, (Span, String)> {
    let mut tokens: Vec<Token> = Vec::new();
    let mut comment = None;
    let mut i = 0;
    while i < text.len() {
        let b = text[i];
        let start = i;
        match b {
            b' ' | b'\t' | b'\r' | b'\n' | b'\x0c' => {
                i += 1;
                continue;
            }
            b';' => {
                let body = String::from_utf8_lossy(&text[i + 1..]);
                let body = body.trim_end_matches(['\r', '\n']).to_string();
                comment = Some((body, span(i, text.len())));
                break;
            }
            b'"' => {
                let Some(len) = text[i + 1..].iter().position(|&c| c == b'"') else {
                    return Err((
                        span(i, text.len()),
                        "a string without its closing `\"`".into(),
                    ));
                };
                let body = String::from_utf8_lossy(&text[i + 1..i + 1 + len]).into_owned();
                i += len + 2;
                tokens.push(Token {
                    tok: Tok::Str(body),
                    span: span(start, i),
                });
                continue;
            }
            b'\'' => {
                i = constant(text, i, &mut tokens)?;
                continue;
            }
            b'0'..=b'9' | b'.' => {
                i = number(text, i, &mut tokens)?;
                continue;
            }
            _ if is_name_start(b) => {
                i = name(text, i, &mut tokens);
                continue;
            }
            _ => {}
        }
        let next = text.get(i + 1).copied();
        let (tok, len) = match (b, next) {
            (b'=', Some(b'=')) => (Tok::Eq, 2),
            (b'<', Some(b'>')) => (Tok::Ne, 2),
            (b'<', Some(b'=')) => (Tok::Le, 2),
            (b'>', Some(b'=')) => (Tok::Ge, 2),
            (b'<', Some(b'<')) => (Tok::Concat, 2),
            (b'=', _) => (Tok::Assign, 1),
            (b'<', _) => (Tok::Lt, 1),
            (b'>', _) => (Tok::Gt, 1),
            (b'+', _) => (Tok::Plus, 1),
            (b'-', _) => (Tok::Minus, 1),
            (b'*', _) => (Tok::Star, 1),
            (b'/', _) => (Tok::Slash, 1),
            (b'(', _) => (Tok::LParen, 1),
            (b')', _) => (Tok::RParen, 1),
            (b'[', _) => (Tok::LBracket, 1),
            (b']', _) => (Tok::RBracket, 1),
            (b',', _) => (Tok::Comma, 1),
            (b':', _) => (Tok::Colon, 1),
            _ => {
                let end = char_end(text, i);
                let shown = String::from_utf8_lossy(&text[i..end]).into_owned();
                return Err((span(i, end), format!("`{shown}` cannot stand here")));
            }
        };
        i += len;
        tokens.push(Token {
            tok,
            span: span(start, i),
        });
    }
    Ok(Lexed { tokens, comment })
}

/// One past the end of the (UTF-8) character at `i`.
fn char_end(text: &[u8], i: usize) -> usize {
    let mut end = i + 1;
    while end < text.len() && (text[end] & 0xC0) == 0x80 && end - i < 4 {
        end += 1;
    }
    end
}

/// A number: digits, an optional decimal point and digits, an optional
/// exponent `EX` with a sign (840Di p62: `X=-.1EX-3`).
fn number(text: &[u8], start: usize, tokens: &mut Vec<Token>) -> Result<usize, (Span, String)> {
    let mut i = start;
    while i < text.len() && text[i].is_ascii_digit() {
        i += 1;
    }
    let mut digits = i > start;
    if i < text.len() && text[i] == b'.' {
        i += 1;
        let frac = i;
        while i < text.len() && text[i].is_ascii_digit() {
            i += 1;
        }
        digits |= i > frac;
    }
    if !digits {
        return Err((span(start, i), "a decimal point without digits".into()));
    }
    let mantissa_end = i;
    let mut exponent = String::new();
    if text.len() > i + 2
        && text[i].eq_ignore_ascii_case(&b'E')
        && text[i + 1].eq_ignore_ascii_case(&b'X')
    {
        let mut j = i + 2;
        if j < text.len() && (text[j] == b'+' || text[j] == b'-') {
            if text[j] == b'-' {
                exponent.push('-');
            }
            j += 1;
        }
        let exp_digits = j;
        while j < text.len() && text[j].is_ascii_digit() {
            j += 1;
        }
        if j > exp_digits {
            exponent.push_str(&String::from_utf8_lossy(&text[exp_digits..j]));
            i = j;
        } else {
            exponent.clear();
        }
    }
    let mut written = String::from_utf8_lossy(&text[start..mantissa_end]).into_owned();
    if !exponent.is_empty() {
        written.push('e');
        written.push_str(&exponent);
    }
    let value = written
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| {
            (
                span(start, i),
                format!("`{written}` is not a number the control reads"),
            )
        })?;
    tokens.push(Token {
        tok: Tok::Number(value),
        span: span(start, i),
    });
    Ok(i)
}

/// `'H0FF'` (hexadecimal) or `'B0101'` (binary) constants.
fn constant(text: &[u8], start: usize, tokens: &mut Vec<Token>) -> Result<usize, (Span, String)> {
    let end = text[start + 1..]
        .iter()
        .position(|&c| c == b'\'')
        .map(|p| start + 1 + p);
    let Some(end) = end else {
        return Err((
            span(start, text.len()),
            "a constant without its closing `'`".into(),
        ));
    };
    let body = &text[start + 1..end];
    let radix = match body.first().map(u8::to_ascii_uppercase) {
        Some(b'H') => 16,
        Some(b'B') => 2,
        _ => 0,
    };
    let value = std::str::from_utf8(body.get(1..).unwrap_or_default())
        .ok()
        .filter(|digits| !digits.is_empty() && radix != 0)
        .and_then(|digits| u64::from_str_radix(digits, radix).ok())
        .filter(|&v| v <= u64::from(u32::MAX));
    let Some(value) = value else {
        return Err((
            span(start, end + 1),
            "not a hexadecimal 'H…' or binary 'B…' constant".into(),
        ));
    };
    tokens.push(Token {
        tok: Tok::Number(value as f64),
        span: span(start, end + 1),
    });
    Ok(end + 1)
}

/// Whether the token before lets a new word begin after it.
fn word_may_begin(tokens: &[Token]) -> bool {
    match tokens.last().map(|t| &t.tok) {
        None | Some(Tok::Number(_) | Tok::Str(_) | Tok::RParen | Tok::RBracket | Tok::Colon) => {
            true
        }
        Some(Tok::Name(n)) => !keeps_next_name_whole(n),
        // The skip slash at the start of the block.
        Some(Tok::Slash) => tokens.len() == 1,
        Some(_) => false,
    }
}

/// A name, or an address letter split off a run like `G53G0X0M5`.
fn name(text: &[u8], start: usize, tokens: &mut Vec<Token>) -> usize {
    let mut end = start;
    while end < text.len() && text[end] == b'$' {
        end += 1;
    }
    while end < text.len() && is_name_char(text[end]) {
        end += 1;
    }
    let first = text[start];
    let split = first.is_ascii_alphabetic()
        && text.get(start + 1).is_some_and(u8::is_ascii_digit)
        && word_may_begin(tokens)
        && !matches!(
            text[end..].iter().find(|c| !matches!(c, b' ' | b'\t')),
            Some(b'=' | b'(' | b'[' | b':')
        );
    let end = if split { start + 1 } else { end };
    let text = String::from_utf8_lossy(&text[start..end]).to_ascii_uppercase();
    tokens.push(Token {
        tok: Tok::Name(text),
        span: span(start, end),
    });
    end
}
