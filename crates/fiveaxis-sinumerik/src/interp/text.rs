//! Program text in memory, and `DEFINE` macro substitution.

use std::collections::HashMap;

use crate::ProgramText;

/// A program held in memory, read line by line: for tests and for
/// callers that have the text already.
///
/// ```
/// use fiveaxis_sinumerik::{ProgramText, TextProgram};
///
/// let mut p = TextProgram::new("G1 X10\r\nM30\n");
/// let mut line = Vec::new();
/// assert!(p.read_line(&mut line)?);
/// assert_eq!(line, b"G1 X10");
/// assert_eq!(p.position(), 8);
/// # Ok::<(), std::io::Error>(())
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct TextProgram {
    data: Vec<u8>,
    pos: usize,
}

impl TextProgram {
    /// A program of `text`.
    pub fn new(text: impl Into<Vec<u8>>) -> Self {
        Self {
            data: text.into(),
            pos: 0,
        }
    }
}

impl ProgramText for TextProgram {
    fn read_line(&mut self, buf: &mut Vec<u8>) -> std::io::Result<bool> {
        buf.clear();
        let Some(rest) = self.data.get(self.pos..) else {
            return Ok(false);
        };
        if rest.is_empty() {
            return Ok(false);
        }
        let (line, used) = match rest.iter().position(|&b| b == b'\n') {
            Some(n) => (&rest[..n], n + 1),
            None => (rest, rest.len()),
        };
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        buf.extend_from_slice(line);
        self.pos += used;
        Ok(true)
    }

    fn position(&self) -> u64 {
        self.pos as u64
    }

    fn seek(&mut self, offset: u64) -> std::io::Result<()> {
        match usize::try_from(offset) {
            Ok(p) if p <= self.data.len() => {
                self.pos = p;
                Ok(())
            }
            _ => Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("offset {offset} is past the end of the program"),
            )),
        }
    }
}

fn ident_start(b: u8) -> bool {
    b.is_ascii_alphabetic() || b == b'_' || b == b'$'
}

fn ident_rest(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_' || b == b'$'
}

/// The line with every macro name (a whole identifier outside strings
/// and the comment) replaced by its text, once; `None` when nothing is
/// replaced. A line that holds `DEFINE` is left alone (a macro is not
/// replaced in its own definition).
pub(crate) fn substitute(line: &[u8], macros: &HashMap<String, String>) -> Option<Vec<u8>> {
    if macros.is_empty() {
        return None;
    }
    let mut out = Vec::with_capacity(line.len());
    let mut changed = false;
    let mut i = 0;
    while i < line.len() {
        let b = line[i];
        if b == b'"' || b == b'\'' {
            let end = line[i + 1..]
                .iter()
                .position(|&c| c == b)
                .map_or(line.len(), |n| i + 1 + n + 1);
            out.extend_from_slice(&line[i..end]);
            i = end;
        } else if b == b';' {
            out.extend_from_slice(&line[i..]);
            break;
        } else if ident_start(b) {
            let start = i;
            while i < line.len() && ident_rest(line[i]) {
                i += 1;
            }
            let word = String::from_utf8_lossy(&line[start..i]).to_ascii_uppercase();
            if word == "DEFINE" {
                return None;
            }
            match macros.get(&word) {
                Some(text) => {
                    out.extend_from_slice(text.as_bytes());
                    changed = true;
                }
                None => out.extend_from_slice(&line[start..i]),
            }
        } else if b.is_ascii_digit() || b == b'.' {
            // A number with its exponent (`1.5EX3`) is not a name.
            let start = i;
            while i < line.len() && (line[i].is_ascii_alphanumeric() || line[i] == b'.') {
                i += 1;
            }
            out.extend_from_slice(&line[start..i]);
        } else {
            out.push(b);
            i += 1;
        }
    }
    changed.then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn macros_replace_whole_names_outside_strings() {
        let mut m = HashMap::new();
        m.insert("LIFT".to_string(), "G0 Z100".to_string());
        let out = substitute(b"N10 lift ; LIFT", &m).expect("changed");
        assert_eq!(out, b"N10 G0 Z100 ; LIFT");
        assert!(substitute(b"MSG(\"LIFT\") LIFTER", &m).is_none());
        assert!(substitute(b"DEFINE LIFT AS G1", &m).is_none());
        assert!(substitute(b"X1.5EX3", &m).is_none());
    }

    #[test]
    fn lines_and_positions() {
        let mut p = TextProgram::new("A\r\nB\nC");
        let mut buf = Vec::new();
        let mut lines = Vec::new();
        while p.read_line(&mut buf).expect("read") {
            lines.push((String::from_utf8_lossy(&buf).into_owned(), p.position()));
        }
        assert_eq!(
            lines,
            [
                ("A".to_string(), 3),
                ("B".to_string(), 5),
                ("C".to_string(), 6)
            ]
        );
        p.seek(3).expect("seek");
        assert!(p.read_line(&mut buf).expect("read"));
        assert_eq!(buf, b"B");
        assert!(p.seek(99).is_err());
    }
}
