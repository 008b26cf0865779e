//! Program text in memory, and `DEFINE` macro substitution.

use std::collections::HashMap;

pub use fiveaxis_gcode::TextProgram;

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
}
