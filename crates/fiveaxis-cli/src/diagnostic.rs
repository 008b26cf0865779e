//! Rendering of alarms and file errors for people: the source line with a
//! caret under the offending text.

use annotate_snippets::{AnnotationKind, Level, Renderer, Snippet};

/// Renders `message` about `text`, line `line` of `path`, with the columns
/// `span` (1-based, end exclusive) marked.
pub fn render(
    path: &str,
    line: u32,
    text: &str,
    span: Option<(u32, u32)>,
    title: &str,
    label: &str,
) -> String {
    let len = text.len();
    let (start, end) = match span {
        Some((s, e)) => {
            let s = (s.saturating_sub(1) as usize).min(len);
            let e = (e.saturating_sub(1) as usize).clamp(s, len);
            (s, if e == s { (s + 1).min(len.max(s)) } else { e })
        }
        None => (0, len),
    };
    let snippet = Snippet::source(text)
        .line_start(line as usize)
        .path(path)
        .annotation(AnnotationKind::Primary.span(start..end).label(label));
    let report = &[Level::ERROR.primary_title(title).element(snippet)];
    Renderer::plain().render(report).to_string()
}
