//! The machine and offsets file formats (`machine-model.md` §4, §5), the
//! built-in machines and writing a machine back.

#[path = "../common/mod.rs"]
mod common;

mod builtins;
mod hostile;
mod machine_bad;
mod machine_good;
mod offsets;

use fiveaxis_machine::FileError;

/// 1-based line and column of the only occurrence of `needle` in `text`;
/// a `^` in `needle` marks the point within it (it is not part of the text).
pub fn pos(text: &str, needle: &str) -> (u32, u32) {
    let (lead, _) = needle.split_once('^').unwrap_or(("", needle));
    let needle = needle.replacen('^', "", 1);
    let at = text
        .find(&needle)
        .unwrap_or_else(|| panic!("`{needle}` not in the text"));
    assert_eq!(
        text.rfind(&needle),
        Some(at),
        "`{needle}` occurs more than once"
    );
    let before = &text[..at + lead.len()];
    let line = before.matches('\n').count() + 1;
    let column = before[before.rfind('\n').map_or(0, |i| i + 1)..]
        .chars()
        .count()
        + 1;
    (
        u32::try_from(line).expect("small"),
        u32::try_from(column).expect("small"),
    )
}

/// Asserts that `error` is at `needle` in `text`, names `key` and says
/// something containing `says`.
#[track_caller]
pub fn assert_error(error: &FileError, text: &str, needle: &str, key: Option<&str>, says: &str) {
    assert_eq!(
        (error.line, error.column),
        pos(text, needle),
        "position of {error:?} in\n{text}"
    );
    assert_eq!(error.key.as_deref(), key, "key of {error:?}");
    assert!(
        error.message.contains(says),
        "message of {error:?} should contain `{says}`"
    );
}
