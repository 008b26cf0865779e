//! Rendering of alarms and file errors for people: the source line with a
//! caret under the offending text.
//!
//! Program lines are bytes from anywhere (USB sticks, CAM systems with odd
//! encodings, half-written files), so the line is first made printable:
//! valid UTF-8 stays as it is, every control character, byte-order mark
//! and invalid byte is shown escaped (`\xff`, `\u{feff}`), tabs as one
//! blank. Spans arrive as 1-based byte columns of the raw line and are
//! carried over to the printable text, so the caret stands under the same
//! bytes whatever the line holds.

use annotate_snippets::{AnnotationKind, Level, Renderer, Snippet};

/// Renders `title` about `line_bytes`, line `line` of `path`, with the byte
/// columns `span` (1-based, end exclusive) marked.
pub fn render(
    path: &str,
    line: u32,
    line_bytes: &[u8],
    span: Option<(u32, u32)>,
    title: &str,
    label: &str,
) -> String {
    let (text, starts) = printable(line_bytes);
    // `starts[i]`: where raw byte `i` begins in `text`; one more entry for
    // the end of the line.
    let at = |column: u32| -> usize {
        let byte = (column.saturating_sub(1) as usize).min(line_bytes.len());
        starts[byte]
    };
    let len = text.len();
    let (start, end) = match span {
        Some((s, e)) => {
            let s = at(s);
            let e = at(e).max(s);
            if e == s {
                // An empty span marks the character at its place, or the
                // end of the line.
                let next = text[s..].chars().next().map_or(s, |c| s + c.len_utf8());
                (s, next)
            } else {
                (s, e)
            }
        }
        None => (0, len),
    };
    let snippet = Snippet::source(&text)
        .line_start(line as usize)
        .path(path)
        .annotation(AnnotationKind::Primary.span(start..end).label(label));
    let report = &[Level::ERROR.primary_title(title).element(snippet)];
    Renderer::plain().render(report).to_string()
}

/// The location of `span` in line `line` of `path` and the source line
/// with a caret under it, without a heading: what follows a message that
/// was already given in full (the contract's `ALARM` line), so that it is
/// not said twice.
pub fn render_location(
    path: &str,
    line: u32,
    line_bytes: &[u8],
    span: Option<(u32, u32)>,
    label: &str,
) -> String {
    let rendered = render(path, line, line_bytes, span, "", label);
    // The heading is the first line (`error: `); the title holds no line
    // break, so the location starts on the second.
    match rendered.split_once('\n') {
        Some((_, rest)) => rest.to_owned(),
        None => rendered,
    }
}

/// `bytes` as printable text, and where each byte starts in it (plus the
/// end): a byte inside a multi-byte character maps to its character's
/// start.
pub fn printable(bytes: &[u8]) -> (String, Vec<usize>) {
    let mut text = String::with_capacity(bytes.len());
    let mut starts = Vec::with_capacity(bytes.len() + 1);
    for chunk in bytes.utf8_chunks() {
        for c in chunk.valid().chars() {
            let here = text.len();
            starts.extend(std::iter::repeat_n(here, c.len_utf8()));
            push_char(&mut text, c);
        }
        for &b in chunk.invalid() {
            starts.push(text.len());
            text.push_str(&format!("\\x{b:02x}"));
        }
    }
    starts.push(text.len());
    (text, starts)
}

/// `text` with control characters, byte-order marks and other invisible
/// characters escaped, for messages that quote what a file holds.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        push_char(&mut out, c);
    }
    out
}

fn push_char(out: &mut String, c: char) {
    match c {
        '\t' => out.push(' '),
        c if c.is_control() || is_invisible(c) => {
            if (c as u32) < 0x100 {
                out.push_str(&format!("\\x{:02x}", c as u32));
            } else {
                out.push_str(&format!("\\u{{{:x}}}", c as u32));
            }
        }
        c => out.push(c),
    }
}

/// Format characters that print as nothing (byte-order mark, zero-width
/// and direction marks), which would make a message lie about its text.
fn is_invisible(c: char) -> bool {
    matches!(
        c,
        '\u{feff}' | '\u{200b}'..='\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2060}'..='\u{2064}'
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invalid_bytes_are_escaped_and_the_caret_follows_them() {
        let out = render("p.nc", 1, b"(\xe9\xe9) Q", Some((6, 7)), "t", "here");
        assert!(out.contains("(\\xe9\\xe9) Q"), "{out}");
        let lines: Vec<&str> = out.lines().collect();
        let source = lines.iter().position(|l| l.contains("Q")).unwrap_or(0);
        let caret = lines[source + 1];
        let q = lines[source].find('Q').unwrap_or(0);
        assert_eq!(caret.find('^'), Some(q), "{out}");
    }

    #[test]
    fn a_location_has_no_heading_and_keeps_its_caret() {
        let out = render_location("p.nc", 2, b"G1 X600.", Some((4, 9)), "here");
        let lines: Vec<&str> = out.trim_end().lines().collect();
        assert_eq!(lines[0], " --> p.nc:2:4", "{out}");
        assert!(!out.contains("error"), "{out}");
        let source = lines
            .iter()
            .position(|l| l.ends_with("G1 X600."))
            .unwrap_or(0);
        assert_eq!(lines[source + 1].trim_end(), "  |    ^^^^^ here", "{out}");
    }

    #[test]
    fn a_lone_invalid_byte_renders() {
        let out = render("p.nc", 3, b"\xff", Some((1, 2)), "t", "here");
        assert!(out.contains("\\xff"), "{out}");
    }

    #[test]
    fn multibyte_characters_keep_their_place() {
        let out = render("p.nc", 1, "(é) X".as_bytes(), Some((6, 7)), "t", "here");
        let lines: Vec<&str> = out.lines().collect();
        let source = lines.iter().position(|l| l.contains('X')).unwrap_or(0);
        let x = lines[source].chars().position(|c| c == 'X');
        let caret = lines[source + 1].chars().position(|c| c == '^');
        assert_eq!(caret, x, "{out}");
    }

    #[test]
    fn control_characters_and_bom_are_shown_escaped() {
        assert_eq!(escape("a\u{1b}[31mb\u{feff}"), "a\\x1b[31mb\\u{feff}");
        let (text, starts) = printable(b"\xef\xbb\xbfG1\r");
        assert_eq!(text, "\\u{feff}G1\\x0d");
        assert_eq!(starts.len(), 7);
        assert_eq!(starts[3], "\\u{feff}".len());
    }

    #[test]
    fn spans_past_the_end_do_not_panic() {
        for span in [Some((0, 0)), Some((50, 10)), Some((3, 99)), None] {
            let _ = render("p.nc", 1, b"G1 \xf0\x9f", span, "t", "here");
            let _ = render("p.nc", 1, b"", span, "t", "here");
        }
    }
}
