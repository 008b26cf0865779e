//! The page `fiveaxis view` writes: one self-contained HTML file holding
//! the data (a JSON description, typed arrays in base64, compressed where
//! that pays, and the program text) and the viewer script (`assets/viewer.js`,
//! bundled from `viewer/` and committed, so that building fiveaxis never
//! needs Node). Nothing in the page refers to the network.
//!
//! The browser's time to open a big page grows with its size (the HTML
//! parser reads every byte), so the arrays are packed small: each array's
//! bytes regrouped by byte position, then deflated (zlib format) where
//! that leaves a quarter of them, then base64 ([`pack::write_packed`]);
//! the viewer undoes it with the browser's own `DecompressionStream`. The
//! program text stays text: the browser inflates about as slowly per byte
//! as it parses, and base64 would add a third.

use std::io::{self, Write};

use super::pack;

/// The viewer: `viewer/src/*.js` with three.js, bundled by esbuild into one
/// IIFE (`npm run build` in `viewer/`).
pub const VIEWER_SCRIPT: &str = include_str!("../../assets/viewer.js");

/// Element ids the viewer reads its data from (`viewer/src/data.js`).
pub const META_ID: &str = "fiveaxis-meta";
/// Prefix of the ids of the base64 typed arrays.
pub const ARRAY_ID_PREFIX: &str = "fiveaxis-array-";
/// Id of the program text.
pub const PROGRAM_ID: &str = "fiveaxis-program";

/// One typed array for the page.
#[derive(Debug)]
pub struct Array<'a> {
    /// Name the viewer looks it up by.
    pub name: &'a str,
    /// Its values.
    pub column: pack::Column<'a>,
}

/// The element holding `column`, packed ([`pack::write_packed`]), with the
/// element width the viewer regroups the bytes by.
fn write_element(out: &mut dyn Write, id: &str, column: pack::Column<'_>) -> io::Result<()> {
    pack::write_packed(out, column, |out, encoding| {
        write!(
            out,
            "<script type=\"application/octet-stream\" id=\"{id}\" data-width=\"{}\" data-encoding=\"{}\">",
            column.width(),
            encoding.name()
        )
    })?;
    out.write_all(b"</script>\n")
}

/// Writes the page: `meta` (a JSON object), the arrays, the viewer script
/// and then the program text.
pub fn write_page(
    out: &mut dyn Write,
    title: &str,
    meta: &serde_json::Value,
    arrays: &[Array<'_>],
    program: &str,
) -> io::Result<()> {
    write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>fiveaxis view: {}</title>\n</head>\n<body>\n",
        escape_html(title)
    )?;
    writeln!(
        out,
        "<script type=\"application/json\" id=\"{META_ID}\">{}</script>",
        json_for_script(meta)
    )?;
    for array in arrays {
        write_element(
            out,
            &format!("{ARRAY_ID_PREFIX}{}", array.name),
            array.column,
        )?;
    }
    // The viewer before the program text: it draws the path and the
    // machine while the browser still reads a long text.
    out.write_all(b"<script>\n")?;
    out.write_all(script_safe(VIEWER_SCRIPT).as_bytes())?;
    out.write_all(b"\n</script>\n")?;
    write!(out, "<script type=\"text/plain\" id=\"{PROGRAM_ID}\">")?;
    write_program_text(out, program)?;
    out.write_all(b"</script>\n</body>\n</html>\n")
}

/// JSON text that can stand inside a `<script>` element: `<` written as
/// `\u003c` (the same string to a JSON reader; outside strings JSON has no
/// `<`), so no `</script>` can end the element early.
pub fn json_for_script(value: &serde_json::Value) -> String {
    value.to_string().replace('<', "\\u003c")
}

/// The program text inside a `<script type="text/plain">` element, which
/// the browser reads raw: `&` as `&a;`, `<` as `&l;` (so no `</script>`
/// ends it) and a carriage return as `&r;` (the HTML parser would turn a
/// lone one into a line feed). The viewer undoes this (`viewer/src/data.js`).
pub fn write_program_text(out: &mut dyn Write, text: &str) -> io::Result<()> {
    let mut from = 0;
    for (at, c) in text.char_indices() {
        let escape: &[u8] = match c {
            '&' => b"&a;",
            '<' => b"&l;",
            '\r' => b"&r;",
            _ => continue,
        };
        out.write_all(&text.as_bytes()[from..at])?;
        out.write_all(escape)?;
        from = at + 1;
    }
    out.write_all(&text.as_bytes()[from..])
}

/// Text for an HTML element's content.
pub fn escape_html(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The script with any `</script` written as `<\/script` (the same
/// JavaScript inside strings and regular expressions, where alone it can
/// occur in a minified bundle).
fn script_safe(script: &str) -> std::borrow::Cow<'_, str> {
    if script.contains("</script") {
        std::borrow::Cow::Owned(script.replace("</script", "<\\/script"))
    } else {
        std::borrow::Cow::Borrowed(script)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn program_text(text: &str) -> String {
        let mut out = Vec::new();
        write_program_text(&mut out, text).expect("writes to a Vec");
        String::from_utf8(out).expect("UTF-8 in, UTF-8 out")
    }

    #[test]
    fn program_text_cannot_end_its_element() {
        let text = "G1 X1.\r\n(</script><b>&amp;)\rM30\n";
        let escaped = program_text(text);
        assert!(!escaped.contains('<'));
        assert!(!escaped.contains('\r'));
        assert_eq!(escaped, "G1 X1.&r;\n(&l;/script>&l;b>&a;amp;)&r;M30\n");
        // Undone as the viewer does it.
        let back = escaped
            .replace("&l;", "<")
            .replace("&r;", "\r")
            .replace("&a;", "&");
        assert_eq!(back, text);
    }

    #[test]
    fn json_cannot_end_its_element() {
        let meta = serde_json::json!({ "message": "</script><script>alert(1)</script>" });
        let text = json_for_script(&meta);
        assert!(!text.contains('<'));
        let back: serde_json::Value = serde_json::from_str(&text).expect("still JSON");
        assert_eq!(back, meta);
    }

    #[test]
    fn page_holds_everything_and_no_network_address() {
        let meta = serde_json::json!({ "vertices": 2 });
        let times = [0.5f64, 1.25, 3.0];
        let program = "G0 X1.\r\n(</script><b>&amp;)\rM30\n";
        let mut out = Vec::new();
        write_page(
            &mut out,
            "a<b>.nc",
            &meta,
            &[Array {
                name: "time",
                column: crate::view::pack::Column::F64(&times),
            }],
            program,
        )
        .expect("writes to a Vec");
        let page = String::from_utf8(out).expect("UTF-8");
        assert!(page.contains("<title>fiveaxis view: a&lt;b&gt;.nc</title>"));
        // Packed (the CLI's tests read them back as the viewer does), and
        // the program text escaped.
        assert!(page.contains(&format!(
            "id=\"{ARRAY_ID_PREFIX}time\" data-width=\"8\" data-encoding=\""
        )));
        assert!(page.contains(&format!(
            "id=\"{PROGRAM_ID}\">G0 X1.&r;\n(&l;/script>&l;b>&a;amp;)&r;M30\n</script>"
        )));
        assert!(page.contains(VIEWER_SCRIPT.get(..200).unwrap_or_default()));
        // Each script element ends where it should: as many ends as starts.
        assert_eq!(
            page.matches("<script").count(),
            page.matches("</script>").count()
        );
        for tag in ["<link", "src=\"http", "<iframe", "@import"] {
            assert!(!page.contains(tag), "{tag}");
        }
    }
}
