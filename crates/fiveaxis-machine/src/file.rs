//! Machine and offsets files (TOML): reading with exact error positions,
//! and writing a machine back as a file a user can edit.

/// A machine or offsets file that cannot be used: where and why.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("line {line}, column {column}: {message}")]
pub struct FileError {
    /// 1-based line of the offending text.
    pub line: u32,
    /// 1-based column.
    pub column: u32,
    /// The key at fault, when there is one.
    pub key: Option<String>,
    /// What is wrong.
    pub message: String,
}
