//! Byte-level preparation of a line, and the cheap scans the runner uses.
//!
//! [`prepare`] cuts the line at `;`, removes the line terminators, reads the
//! `%` tape mark and the `/` block delete, drops blanks and comments, and
//! keeps every other byte (letters upper-cased) with its column. FANUC reads
//! blanks nowhere, so `G O T O 1 0` is `GOTO10` and `#1 = 1 0` is `#1=10`.
//! A comment is dropped like a blank (decision: the G-code front end ends a
//! word at a comment; here the comment simply vanishes).

use fiveaxis_gcode::Span;

use crate::error::{MacroError, MacroErrorKind};

/// A byte kept by [`prepare`] and its 0-based index in the line.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Char {
    pub byte: u8,
    pub index: u32,
}

/// A line after [`prepare`].
#[derive(Debug, Default)]
pub(crate) struct Prepared {
    pub chars: Vec<Char>,
    pub block_delete: bool,
    pub tape_mark: bool,
    pub comment: Option<String>,
    /// Length of the line (up to `;`) in bytes.
    pub len: usize,
}

const BLANKS: [u8; 2] = [b' ', b'\t'];

/// The line up to its first `;`, without trailing `\r`/`\n`.
pub(crate) fn block_text(text: &[u8]) -> &[u8] {
    let mut block = text.split(|&b| b == b';').next().unwrap_or(text);
    while let [rest @ .., b'\r' | b'\n'] = block {
        block = rest;
    }
    block
}

/// 1-based span of the 0-based byte range `start..end`.
pub(crate) fn span(start: usize, end: usize) -> Span {
    let col = |i: usize| u32::try_from(i).unwrap_or(u32::MAX).saturating_add(1);
    Span::new(col(start), col(end))
}

/// The index of the first non-blank byte at or after `pos`.
fn skip_blanks(text: &[u8], mut pos: usize) -> usize {
    while text.get(pos).is_some_and(|b| BLANKS.contains(b)) {
        pos += 1;
    }
    pos
}

/// The position after the `)` closing the comment opened at `pos`.
fn comment_end(text: &[u8], pos: usize) -> Option<usize> {
    let body = pos + 1;
    let close = text.get(body..)?.iter().position(|&b| b == b')')?;
    Some(body + close + 1)
}

/// Prepares the line for parsing (see the module documentation).
pub(crate) fn prepare(text: &[u8]) -> Result<Prepared, MacroError> {
    let text = block_text(text);
    let mut out = Prepared {
        len: text.len(),
        ..Prepared::default()
    };
    let mut pos = skip_blanks(text, 0);
    match text.get(pos) {
        Some(b'%') => {
            out.tape_mark = true;
            return Ok(out);
        }
        Some(b'/') => {
            out.block_delete = true;
            pos += 1;
            let next = skip_blanks(text, pos);
            if text.get(next).is_some_and(|b| (b'1'..=b'9').contains(b)) {
                pos = next + 1;
            }
        }
        _ => {}
    }
    while let Some(&byte) = text.get(pos) {
        if BLANKS.contains(&byte) {
            pos += 1;
        } else if byte == b'(' {
            let end = comment_end(text, pos).ok_or_else(|| {
                MacroError::new(
                    MacroErrorKind::FormatError,
                    span(pos, text.len()),
                    "comment is not closed",
                )
            })?;
            if out.comment.is_none() {
                let body = text.get(pos + 1..end - 1).unwrap_or_default();
                out.comment = Some(String::from_utf8_lossy(body).trim().to_owned());
            }
            pos = end;
        } else {
            out.chars.push(Char {
                byte: byte.to_ascii_uppercase(),
                index: u32::try_from(pos).unwrap_or(u32::MAX),
            });
            pos += 1;
        }
    }
    Ok(out)
}

/// Macro keywords that start a statement, for [`is_macro_line`].
const STATEMENT_KEYWORDS: [&[u8]; 7] = [b"IF", b"GOTO", b"WHILE", b"DO", b"END", b"ELSE", b"ENDIF"];

/// Calls `f` with every run of letters outside comments (blanks between
/// letters do not end a run; letters are upper-cased, at most 8 kept) and
/// the bytes that follow it, and with `None` for every `#`, `[` or `]`.
/// Stops when `f` returns `Some`.
fn scan<T>(text: &[u8], mut f: impl FnMut(Option<&[u8]>, &[u8]) -> Option<T>) -> Option<T> {
    let text = block_text(text);
    let mut pos = 0;
    while let Some(&byte) = text.get(pos) {
        if byte == b'(' {
            pos = comment_end(text, pos)?;
        } else if matches!(byte, b'#' | b'[' | b']') {
            if let Some(found) = f(None, text.get(pos..).unwrap_or_default()) {
                return Some(found);
            }
            pos += 1;
        } else if byte.is_ascii_alphabetic() {
            let mut word = [0u8; 8];
            let mut len = 0;
            while let Some(&b) = text.get(pos) {
                if b.is_ascii_alphabetic() {
                    if let Some(slot) = word.get_mut(len) {
                        *slot = b.to_ascii_uppercase();
                    }
                    len += 1;
                    pos += 1;
                } else if BLANKS.contains(&b)
                    && text
                        .get(skip_blanks(text, pos))
                        .is_some_and(u8::is_ascii_alphabetic)
                {
                    pos = skip_blanks(text, pos);
                } else {
                    break;
                }
            }
            let letters = if len <= word.len() {
                word.get(..len).unwrap_or_default()
            } else {
                &[]
            };
            if let Some(found) = f(Some(letters), text.get(pos..).unwrap_or_default()) {
                return Some(found);
            }
        } else {
            pos += 1;
        }
    }
    None
}

/// Whether the line holds custom macro syntax: `#`, `[` or `]` outside
/// comments, or one of the keywords `GOTO`, `IF`, `WHILE`, `DO`, `END`
/// written as a word of its own. A line for which this is `false` can go
/// to the plain G-code front end.
pub fn is_macro_line(text: &[u8]) -> bool {
    scan(text, |word, _| match word {
        None => Some(()),
        Some(letters) => STATEMENT_KEYWORDS.contains(&letters).then_some(()),
    })
    .is_some()
}

/// The number written after the keyword `keyword` in the line, if the line
/// holds it (blanks allowed); numbers that do not fit `u8` give `None`.
fn loop_number(text: &[u8], keyword: &[u8]) -> Option<u8> {
    scan(text, |word, rest| {
        if word != Some(keyword) {
            return None;
        }
        let rest = rest.get(skip_blanks(rest, 0)..).unwrap_or_default();
        let digits = rest.iter().take_while(|b| b.is_ascii_digit()).count();
        let digits = rest.get(..digits).filter(|d| !d.is_empty())?;
        std::str::from_utf8(digits).ok()?.parse().ok()
    })
}

/// `Some(m)` when the line holds `DO m` (alone or after `WHILE […]`), for
/// the runner matching loops. The number is returned as written; checking
/// it is 1 … 3 is [`crate::parse_statement`]'s job.
pub fn loop_start(text: &[u8]) -> Option<u8> {
    loop_number(text, b"DO")
}

/// `Some(m)` when the line holds `END m`.
pub fn loop_end(text: &[u8]) -> Option<u8> {
    loop_number(text, b"END")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kept(text: &[u8]) -> (Vec<u8>, Vec<u32>) {
        let p = prepare(text).expect("prepared");
        (
            p.chars.iter().map(|c| c.byte).collect(),
            p.chars.iter().map(|c| c.index).collect(),
        )
    }

    #[test]
    fn blanks_and_comments_are_dropped() {
        assert_eq!(
            kept(b"g 0 1 (c) x1"),
            (b"G01X1".to_vec(), vec![0, 2, 4, 10, 11])
        );
        assert_eq!(kept(b"#1=2;#3=4").0, b"#1=2");
        assert_eq!(kept(b"#1=2\r\n").0, b"#1=2");
        let p = prepare(b" / 2 N1 (A)(B)").expect("prepared");
        assert!(p.block_delete);
        assert_eq!(p.comment.as_deref(), Some("A"));
        assert!(prepare(b"  % anything").expect("tape").tape_mark);
        let e = prepare(b"X1 (open").expect_err("unclosed");
        assert_eq!(e.span, Span::new(4, 9));
    }
}
