//! LinuxCNC's tool table (`.tbl`, the file `[EMCIO] TOOL_TABLE` names),
//! read into offset memory.
//!
//! Format (LinuxCNC 2.9 documentation, `gcode/tool-compensation.adoc`,
//! "Tool Table Format"): one tool per line, entries separated by blanks,
//! each a letter and a number: `T` tool number (unsigned integer,
//! required, unique), `P` pocket (integer 0 … 1000, required, unique), `X`
//! … `W` offsets per axis, `D` diameter, `I`/`J` front and back angle,
//! `Q` orientation (integer 0 … 9); `;` starts a remark to the end of the
//! line; a line that is blank or starts with `;` is skipped.
//!
//! What the kernel takes from it: tool `T n` becomes offset number `n`
//! (LinuxCNC's `G43` without `H` uses the loaded tool's entry, `G43 Hn`
//! tool `n`'s): length = the `Z` entry, radius = half the `D` entry, no
//! wear. The other entries are read and checked, and not used (lathe
//! data, offsets on other axes).

use crate::file::FileError;
use crate::offsets::{MAX_TOOL_OFFSET, Offsets, ToolOffset};

/// The highest pocket number (tool-compensation.adoc: "1-1000", 0 the
/// spindle).
const MAX_POCKET: f64 = 1000.0;
/// The highest lathe tool orientation.
const MAX_ORIENTATION: f64 = 9.0;
/// The letters of a tool table entry.
const LETTERS: &[u8] = b"TPXYZABCUVWDIJQ";

impl Offsets {
    /// Offset memory from a LinuxCNC tool table (see the module
    /// documentation); everything else zero.
    ///
    /// # Errors
    ///
    /// A [`FileError`] with the line and column of the first entry that
    /// cannot be read: an unknown letter, a malformed number, a missing
    /// `T` or `P`, a tool number beyond the offset memory, a repeated tool,
    /// pocket or letter.
    pub fn from_tool_table(text: &str) -> Result<Self, FileError> {
        let mut offsets = Self::default();
        let mut pockets: Vec<u32> = Vec::new();
        for (index, line) in text.lines().enumerate() {
            let line_no = u32::try_from(index + 1).unwrap_or(u32::MAX);
            let body = line.split(';').next().unwrap_or("");
            if body.trim().is_empty() {
                continue;
            }
            let (tool, pocket, length, diameter) = read_line(body, line_no)?;
            let at = |what: &str, message: String| FileError {
                line: line_no,
                column: column_of(body, what),
                key: Some(what.to_owned()),
                message,
            };
            if offsets.tools.contains_key(&tool) {
                return Err(at("T", format!("tool T{tool} is listed twice")));
            }
            if pocket != 0 && pockets.contains(&pocket) {
                return Err(at("P", format!("pocket P{pocket} is listed twice")));
            }
            pockets.push(pocket);
            offsets.tools.insert(
                tool,
                ToolOffset {
                    length,
                    length_wear: 0.0,
                    radius: diameter / 2.0,
                    radius_wear: 0.0,
                },
            );
        }
        Ok(offsets)
    }
}

/// The 1-based character column of the entry starting with `letter`.
fn column_of(body: &str, letter: &str) -> u32 {
    let upper = body.to_ascii_uppercase();
    let byte = upper
        .split_whitespace()
        .find(|e| e.starts_with(letter))
        .and_then(|e| upper.find(e))
        .unwrap_or(0);
    u32::try_from(body[..byte].chars().count() + 1).unwrap_or(u32::MAX)
}

/// One line's tool number, pocket, Z offset and diameter.
fn read_line(body: &str, line: u32) -> Result<(u32, u32, f64, f64), FileError> {
    let mut values = [None::<f64>; LETTERS.len()];
    let mut pos = 0;
    for entry in body.split_whitespace() {
        let start = body[pos..].find(entry).map_or(pos, |k| pos + k);
        pos = start + entry.len();
        let column = u32::try_from(body[..start].chars().count() + 1).unwrap_or(u32::MAX);
        let error = |message: String| FileError {
            line,
            column,
            key: Some(entry.chars().take(1).collect()),
            message,
        };
        let mut chars = entry.chars();
        let letter = chars.next().map(|c| c.to_ascii_uppercase()).unwrap_or(' ');
        let Some(slot) = LETTERS.iter().position(|&l| char::from(l) == letter) else {
            return Err(error(format!(
                "`{entry}`: a tool table entry starts with one of T P X Y Z A B C U V W D I J Q"
            )));
        };
        let number = chars.as_str();
        let value: f64 = match number.parse() {
            Ok(v)
                if number
                    .bytes()
                    .all(|b| b.is_ascii_digit() || b"+-.".contains(&b)) =>
            {
                v
            }
            _ => return Err(error(format!("`{entry}`: `{number}` is not a number"))),
        };
        if !value.is_finite() {
            return Err(error(format!("`{entry}`: not a finite number")));
        }
        if values[slot].is_some() {
            return Err(error(format!("`{letter}` is given twice on the line")));
        }
        let integer = value.fract() == 0.0;
        let range_error = match letter {
            'T' if !integer || !(0.0..=f64::from(MAX_TOOL_OFFSET)).contains(&value) => {
                Some(format!(
                    "tool number T{number} must be an integer 0 to {MAX_TOOL_OFFSET} (the offset memory)"
                ))
            }
            'P' if !integer || !(0.0..=MAX_POCKET).contains(&value) => {
                Some(format!("pocket P{number} must be an integer 0 to 1000"))
            }
            'Q' if !integer || !(0.0..=MAX_ORIENTATION).contains(&value) => {
                Some(format!("orientation Q{number} must be an integer 0 to 9"))
            }
            _ => None,
        };
        if let Some(message) = range_error {
            return Err(error(message));
        }
        values[slot] = Some(value);
    }
    let missing = |letter: &str| FileError {
        line,
        column: 1,
        key: Some(letter.to_owned()),
        message: format!("the line has no {letter} entry (T and P are required)"),
    };
    // T and P are integers in range: the casts are exact.
    let tool = values[0].ok_or_else(|| missing("T"))? as u32;
    let pocket = values[1].ok_or_else(|| missing("P"))? as u32;
    let z = values[4].unwrap_or(0.0);
    let diameter = values[11].unwrap_or(0.0).abs();
    Ok((tool, pocket, z, diameter))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_documented_layout() {
        let text = "\
; no data after opening semicolon
T1 P17 X0 Y0 Z25.5 A0 B0 C0 U0 V0 W0 D6 I0 J0 Q0 ;rem
t2 p5 z-1.25 d10.0
\tT3\tP12  ; drill
";
        let offsets = Offsets::from_tool_table(text).expect("reads");
        assert_eq!(offsets.tools.len(), 3);
        let t1 = offsets.tool(1);
        assert_eq!((t1.length, t1.radius), (25.5, 3.0));
        let t2 = offsets.tool(2);
        assert_eq!((t2.length, t2.radius), (-1.25, 5.0));
        assert_eq!(offsets.tool(3).length, 0.0);
    }

    #[test]
    fn errors_name_line_and_column() {
        let cases = [
            ("T1 P1\nT2 P2 Z1 K4\n", 2, 10, "K4"),
            ("T1 P1 Zx\n", 1, 7, "not a number"),
            ("T1 P1\nT1 P2\n", 2, 1, "twice"),
            ("T1 P1\nT2 P1\n", 2, 4, "twice"),
            ("P1 Z3\n", 1, 1, "no T"),
            ("T1.5 P1\n", 1, 1, "integer"),
            ("T1000 P1\n", 1, 1, "offset memory"),
            ("T1 P1 Z1 Z2\n", 1, 10, "twice"),
            ("T1 P1 Q12\n", 1, 7, "orientation"),
        ];
        for (text, line, column, what) in cases {
            let e = Offsets::from_tool_table(text).expect_err(text);
            assert_eq!((e.line, e.column), (line, column), "{text:?}: {e:?}");
            assert!(e.message.contains(what), "{text:?}: {}", e.message);
        }
    }
}
