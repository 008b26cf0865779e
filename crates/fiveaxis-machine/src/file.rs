//! Machine and offsets files (TOML): reading with exact error positions,
//! and writing a machine back as a file a user can edit.
//!
//! Reading goes in two steps. Serde fills "raw" structs that mirror the
//! file (unknown keys rejected, values wrapped in [`Spanned`] where a later
//! check may need to point at them); then the raw structs are checked and
//! turned into the public types. Every error carries the 1-based line and
//! column of the offending text and, when there is one, the key at fault.

mod bodies;
mod machine;
pub use bodies::{MAX_BODIES, MAX_SOLIDS, RESERVED_BODY_NAMES};
pub use machine::{MAX_JERK, MIN_ACCELERATION, MIN_JERK, MIN_VELOCITY};
mod offsets;
mod write;

use std::collections::BTreeMap;
use std::ops::Range;

use serde::de::DeserializeOwned;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

use crate::Vec3;

/// A machine or offsets file that cannot be used: where and why.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("line {line}, column {column}: {message}")]
pub struct FileError {
    /// 1-based line of the offending text.
    pub line: u32,
    /// 1-based column, counted in characters.
    pub column: u32,
    /// The key at fault, when there is one.
    pub key: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl FileError {
    /// The bytes of a machine or offsets file as text: UTF-8, or the error
    /// at the first byte that is not (its line, and its column counted in
    /// characters).
    pub fn utf8(bytes: &[u8]) -> Result<&str, FileError> {
        std::str::from_utf8(bytes).map_err(|e| {
            let at = e.valid_up_to();
            let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
            let start = bytes[..at]
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |i| i + 1);
            let column = String::from_utf8_lossy(&bytes[start..at]).chars().count() + 1;
            FileError {
                line: u32::try_from(line).unwrap_or(u32::MAX),
                column: u32::try_from(column).unwrap_or(u32::MAX),
                key: None,
                message: "not UTF-8 text: the file must be saved as UTF-8".into(),
            }
        })
    }
}

#[cfg(test)]
mod utf8_tests {
    use super::FileError;

    #[test]
    fn the_first_bad_byte_is_named() {
        assert_eq!(FileError::utf8(b"a = 1\n").ok(), Some("a = 1\n"));
        let e = FileError::utf8(b"a = 1\nb = \"\xc3\xa9\xff\"\n").err();
        let e = e.expect("not UTF-8");
        assert_eq!((e.line, e.column, e.key), (2, 7, None));
        assert!(e.message.contains("UTF-8"));
    }
}

/// The text of a file being read, to turn byte offsets into positions.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Source<'a> {
    text: &'a str,
}

impl<'a> Source<'a> {
    pub(crate) fn new(text: &'a str) -> Self {
        Self { text }
    }

    /// 1-based line and column (in characters) of a byte offset.
    fn position(&self, offset: usize) -> (u32, u32) {
        let mut end = offset.min(self.text.len());
        while !self.text.is_char_boundary(end) {
            end -= 1;
        }
        let before = &self.text[..end];
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let line = before.matches('\n').count() + 1;
        let column = before[line_start..].chars().count() + 1;
        (saturate(line), saturate(column))
    }

    /// An error about the text at `span`.
    pub(crate) fn error(
        &self,
        span: Range<usize>,
        key: Option<&str>,
        message: impl Into<String>,
    ) -> FileError {
        let (line, column) = self.position(span.start);
        FileError {
            line,
            column,
            key: key.map(str::to_owned),
            message: message.into(),
        }
    }

    /// An error about the value of `key`.
    pub(crate) fn at<T>(
        &self,
        value: &Spanned<T>,
        key: &str,
        message: impl Into<String>,
    ) -> FileError {
        self.error(value.span(), Some(key), message)
    }

    /// Deserialises the whole file into `T`, turning toml's errors (syntax,
    /// unknown keys, missing keys, wrong types) into [`FileError`]s.
    pub(crate) fn deserialize<T: DeserializeOwned>(&self) -> Result<T, FileError> {
        toml::from_str(self.text).map_err(|e| self.toml_error(&e))
    }

    fn toml_error(&self, error: &toml::de::Error) -> FileError {
        let span = error.span().unwrap_or(0..0);
        let message = error.message().trim().to_owned();
        let key = self.key_of_error(&message, &span);
        self.error(span, key.as_deref(), message)
    }

    /// The key an error of toml's is about: named in the message for a
    /// missing or unknown key, otherwise the key nearest the error in the
    /// document tree.
    fn key_of_error(&self, message: &str, span: &Range<usize>) -> Option<String> {
        if let Some(name) = quoted_after(message, "missing field `") {
            return Some(name);
        }
        if message.starts_with("duplicate key") {
            return self
                .text
                .get(span.clone())
                .map(|k| k.trim_matches(['"', '\'']).to_owned());
        }
        let tree = DeTable::parse(self.text).ok()?;
        let mut best = None;
        find_key(tree.get_ref(), span, &mut best);
        best.map(|(_, key)| key)
    }

    /// A finite number within what a machine can have
    /// ([`MAX_FILE_MAGNITUDE`]).
    pub(crate) fn finite(&self, value: &Spanned<f64>, key: &str) -> Result<f64, FileError> {
        let v = *value.get_ref();
        if !v.is_finite() {
            Err(self.at(value, key, format!("`{key}` must be a finite number")))
        } else if v.abs() > MAX_FILE_MAGNITUDE {
            Err(self.at(value, key, magnitude_message(key)))
        } else {
            Ok(v)
        }
    }

    /// An optional finite number, 0 when left out.
    pub(crate) fn finite_or_zero(
        &self,
        value: Option<&Spanned<f64>>,
        key: &str,
    ) -> Result<f64, FileError> {
        value.map_or(Ok(0.0), |v| self.finite(v, key))
    }

    /// A 3-vector of finite numbers.
    /// A work offset: X, Y, Z and the values of the axes beyond them (3
    /// to [`crate::MAX_AXES`] numbers).
    pub(crate) fn work_values(
        &self,
        value: &Spanned<Vec<f64>>,
        key: &str,
    ) -> Result<(Vec3, crate::offsets::BeyondXyz, usize), FileError> {
        let v = value.get_ref();
        if !(3..=crate::MAX_AXES).contains(&v.len()) {
            let msg = format!(
                "`{key}` must have 3 numbers (X, Y, Z) or one per machine axis (at most {}), found {}",
                crate::MAX_AXES,
                v.len()
            );
            return Err(self.at(value, key, msg));
        }
        if v.iter().any(|x| !x.is_finite()) {
            return Err(self.at(value, key, format!("`{key}` must hold finite numbers")));
        }
        if v.iter().any(|x| x.abs() > MAX_FILE_MAGNITUDE) {
            return Err(self.at(value, key, magnitude_message(key)));
        }
        let mut beyond = [0.0; crate::MAX_AXES - 3];
        beyond[..v.len() - 3].copy_from_slice(&v[3..]);
        Ok((Vec3::new(v[0], v[1], v[2]), beyond, v.len()))
    }

    pub(crate) fn vec3(&self, value: &Spanned<Vec<f64>>, key: &str) -> Result<Vec3, FileError> {
        let v = value.get_ref();
        if v.len() != 3 {
            let msg = format!("`{key}` must have 3 numbers, found {}", v.len());
            return Err(self.at(value, key, msg));
        }
        if v.iter().any(|x| !x.is_finite()) {
            return Err(self.at(value, key, format!("`{key}` must hold finite numbers")));
        }
        if v.iter().any(|x| x.abs() > MAX_FILE_MAGNITUDE) {
            return Err(self.at(value, key, magnitude_message(key)));
        }
        Ok(Vec3::new(v[0], v[1], v[2]))
    }
}

/// The largest magnitude of any number in a machine or offsets file: a
/// length (mm), a position, a stroke or an angle (degrees). No machine
/// has a kilometre of travel or a thousand turns of soft limit; bounding
/// every input keeps every computed position finite.
pub const MAX_FILE_MAGNITUDE: f64 = 1e6;

fn magnitude_message(key: &str) -> String {
    format!(
        "`{key}` is beyond what a machine can have: at most {MAX_FILE_MAGNITUDE:e} (mm or degrees) in size"
    )
}

/// The entries of a map read from the file, in the order they were written
/// (so that the first error reported is the first in the file).
pub(crate) fn in_file_order<K, V>(map: &BTreeMap<Spanned<K>, V>) -> Vec<(&Spanned<K>, &V)> {
    let mut entries: Vec<_> = map.iter().collect();
    entries.sort_by_key(|(key, _)| key.span().start);
    entries
}

/// Clamps a count into `u32`.
fn saturate(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

/// The text between `prefix` and the next backtick in `message`.
fn quoted_after(message: &str, prefix: &str) -> Option<String> {
    let rest = message.strip_prefix(prefix)?;
    rest.split('`').next().map(str::to_owned)
}

/// Searches every keyed entry of `table` (recursively through tables and
/// arrays) for the one an error at `span` is about: a key whose own text
/// holds the error start wins outright; otherwise the entry with the
/// smallest value that holds the error. `best` keeps (size, key).
fn find_key(table: &DeTable<'_>, span: &Range<usize>, best: &mut Option<(usize, String)>) {
    for (key, value) in table {
        let name = key.get_ref().to_string();
        let (ks, vs) = (key.span(), value.span());
        if ks.start <= span.start && span.start < ks.end.max(ks.start + 1) {
            *best = Some((0, name.clone()));
        } else if vs.start <= span.start && span.end <= vs.end {
            let size = vs.end - vs.start;
            if best.as_ref().is_none_or(|(s, _)| size < *s) {
                *best = Some((size, name.clone()));
            }
        }
        find_key_in_value(value.get_ref(), span, best);
    }
}

fn find_key_in_value(value: &DeValue<'_>, span: &Range<usize>, best: &mut Option<(usize, String)>) {
    match value {
        DeValue::Table(t) => find_key(t, span, best),
        DeValue::Array(a) => {
            for item in a.iter() {
                find_key_in_value(item.get_ref(), span, best);
            }
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_are_one_based_and_count_characters() {
        let src = Source::new("ab\nc\u{e9}d\n");
        assert_eq!(src.position(0), (1, 1));
        assert_eq!(src.position(1), (1, 2));
        assert_eq!(src.position(3), (2, 1));
        // 'd' follows a two-byte character: byte 6, column 3.
        assert_eq!(src.position(6), (2, 3));
        assert_eq!(src.position(100), (3, 1));
    }
}
