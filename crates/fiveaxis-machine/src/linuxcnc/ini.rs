//! LinuxCNC INI files as the LinuxCNC manual describes them
//! (`config/ini-config.adoc`, "Configuration File Format"): sections in
//! brackets, `NAME = value` variables, comment lines starting with `#` or
//! `;` (inside a value both are ordinary characters), a trailing backslash
//! continuing a value on the next line, escapes in values, and `#INCLUDE`
//! of further files (16 levels, recursion refused). A variable may repeat
//! (`HALCMD`, `REMAP`, `HALFILE`): every occurrence is kept in order, and a
//! single-valued variable takes the first one, as LinuxCNC does.

use std::path::{Path, PathBuf};

use super::{ImportError, Reader, normalize};

/// Deepest `#INCLUDE` nesting LinuxCNC accepts.
const MAX_INCLUDE_DEPTH: usize = 16;

/// One `NAME = value` line.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Entry {
    /// Section name, without brackets.
    pub section: String,
    /// Variable name.
    pub key: String,
    /// The value, leading and trailing white space removed, escapes decoded.
    pub value: String,
    /// The file the line is in (the INI or an included file).
    pub file: PathBuf,
    /// 1-based line of the variable's first line.
    pub line: u32,
}

impl Entry {
    /// An error about this entry's value.
    pub(crate) fn error(&self, message: impl Into<String>) -> ImportError {
        ImportError::at(
            &self.file,
            self.line,
            format!("[{}]{}: {}", self.section, self.key, message.into()),
        )
    }

    /// The value as a real number.
    pub(crate) fn number(&self) -> Result<f64, ImportError> {
        parse_real(&self.value)
            .ok_or_else(|| self.error(format!("`{}` is not a number", self.value)))
    }
}

/// A real number as LinuxCNC's INI reader takes it: decimal, with an
/// optional sign and exponent, finite.
pub(crate) fn parse_real(text: &str) -> Option<f64> {
    let t = text.trim();
    let ok = !t.is_empty()
        && t.bytes()
            .all(|b| b.is_ascii_digit() || matches!(b, b'+' | b'-' | b'.' | b'e' | b'E'));
    if !ok {
        return None;
    }
    t.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// An INI file with its includes, every variable in file order.
#[derive(Clone, Debug, Default)]
pub(crate) struct Ini {
    entries: Vec<Entry>,
}

impl Ini {
    /// Reads `path` and the files it includes.
    pub(crate) fn read(path: &Path, read: &mut Reader<'_>) -> Result<Ini, ImportError> {
        let mut ini = Ini::default();
        let mut stack = Vec::new();
        ini.read_file(path, None, None, read, &mut stack)?;
        Ok(ini)
    }

    fn read_file(
        &mut self,
        path: &Path,
        included_at: Option<(&Path, u32)>,
        section: Option<String>,
        read: &mut Reader<'_>,
        stack: &mut Vec<PathBuf>,
    ) -> Result<Option<String>, ImportError> {
        let text = read(path).map_err(|e| match included_at {
            Some((file, line)) => ImportError::at(
                file,
                line,
                format!("#INCLUDE {}: cannot be read: {e}", path.display()),
            ),
            None => ImportError::file(path, format!("cannot be read: {e}")),
        })?;
        stack.push(path.to_path_buf());
        let folder = path.parent().unwrap_or(Path::new(""));
        // An included file's variables belong to the section they are
        // included in until the file opens its own.
        let mut section = section;
        let mut lines = text.lines().enumerate();
        while let Some((index, raw)) = lines.next() {
            let line_no = line_number(index);
            if let Some(name) = raw.strip_prefix("#INCLUDE ") {
                let target = normalize(&folder.join(name.trim()));
                if stack.contains(&target) {
                    return Err(ImportError::at(
                        path,
                        line_no,
                        format!("#INCLUDE {}: includes itself", target.display()),
                    ));
                }
                if stack.len() >= MAX_INCLUDE_DEPTH {
                    return Err(ImportError::at(
                        path,
                        line_no,
                        format!("#INCLUDE nested deeper than {MAX_INCLUDE_DEPTH} files"),
                    ));
                }
                section = self.read_file(&target, Some((path, line_no)), section, read, stack)?;
                continue;
            }
            let trimmed = raw.trim();
            if trimmed.is_empty() || trimmed.starts_with('#') || trimmed.starts_with(';') {
                continue;
            }
            if let Some(rest) = trimmed.strip_prefix('[') {
                let Some(name) = rest.strip_suffix(']') else {
                    return Err(ImportError::at(
                        path,
                        line_no,
                        format!("`{trimmed}`: a section name must end with `]`"),
                    ));
                };
                section = Some(name.trim().to_owned());
                continue;
            }
            let Some((key, value)) = trimmed.split_once('=') else {
                return Err(ImportError::at(
                    path,
                    line_no,
                    format!(
                        "`{trimmed}` is neither a [SECTION], a comment nor a NAME = value variable"
                    ),
                ));
            };
            let key = key.trim();
            if !valid_key(key) {
                return Err(ImportError::at(
                    path,
                    line_no,
                    format!(
                        "`{key}` is not a variable name (letters, digits and `_`, not starting with a digit)"
                    ),
                ));
            }
            let Some(section) = section.clone() else {
                return Err(ImportError::at(
                    path,
                    line_no,
                    format!("variable {key} comes before any [SECTION]"),
                ));
            };
            let mut value = value.trim().to_owned();
            while value.ends_with('\\') {
                value.pop();
                match lines.next() {
                    Some((_, next)) => value.push_str(next.trim()),
                    None => break,
                }
            }
            let value = unescape(value.trim()).map_err(|message| {
                ImportError::at(path, line_no, format!("[{section}]{key}: {message}"))
            })?;
            self.entries.push(Entry {
                section,
                key: key.to_owned(),
                value,
                file: path.to_path_buf(),
                line: line_no,
            });
        }
        stack.pop();
        Ok(section)
    }

    /// The first occurrence of `[section]key`.
    pub(crate) fn get(&self, section: &str, key: &str) -> Option<&Entry> {
        self.entries
            .iter()
            .find(|e| e.section == section && e.key == key)
    }

    /// Every occurrence of `[section]key`, in file order.
    pub(crate) fn all<'a>(
        &'a self,
        section: &'a str,
        key: &'a str,
    ) -> impl Iterator<Item = &'a Entry> + 'a {
        self.entries
            .iter()
            .filter(move |e| e.section == section && e.key == key)
    }

    /// What a program can read as `#<_ini[section]name>`: the first
    /// occurrence of every variable whose value is a number, keyed
    /// `SECTION]NAME`. LinuxCNC upper-cases the name a program gives, so a
    /// section or name with a lower-case letter cannot be read and is left
    /// out (gcode/overview.adoc, "INI file values").
    pub(crate) fn numbers(&self) -> std::collections::BTreeMap<String, f64> {
        let mut out = std::collections::BTreeMap::new();
        for e in &self.entries {
            let readable = |s: &str| !s.chars().any(|c| c.is_ascii_lowercase());
            if !readable(&e.section) || !readable(&e.key) {
                continue;
            }
            if let Ok(v) = e.value.parse::<f64>()
                && v.is_finite()
            {
                out.entry(format!("{}]{}", e.section, e.key)).or_insert(v);
            }
        }
        out
    }

    /// The value of `[SECTION]KEY` for HAL's substitution, first
    /// occurrence.
    pub(crate) fn value(&self, section: &str, key: &str) -> Option<&str> {
        self.get(section, key).map(|e| e.value.as_str())
    }
}

fn line_number(index: usize) -> u32 {
    u32::try_from(index + 1).unwrap_or(u32::MAX)
}

fn valid_key(key: &str) -> bool {
    let mut chars = key.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Decodes the escapes of an INI value: `\a \b \f \n \r \t \v \\`, octal
/// `\NNN` up to `\377` (one byte), `\xHH`, `\uHHHH` (with surrogate pairs) and `\UHHHHHHHH`.
fn unescape(value: &str) -> Result<String, String> {
    if !value.contains('\\') {
        return Ok(value.to_owned());
    }
    let mut bytes: Vec<u8> = Vec::with_capacity(value.len());
    let mut chars = value.chars().peekable();
    let mut pending_high: Option<u32> = None;
    while let Some(c) = chars.next() {
        if c != '\\' {
            push_char(&mut bytes, c);
            continue;
        }
        let Some(e) = chars.next() else {
            bytes.push(b'\\');
            break;
        };
        let simple = match e {
            'a' => Some(0x07),
            'b' => Some(0x08),
            'f' => Some(0x0c),
            'n' => Some(b'\n'),
            'r' => Some(b'\r'),
            't' => Some(b'\t'),
            'v' => Some(0x0b),
            '\\' => Some(b'\\'),
            _ => None,
        };
        if let Some(b) = simple {
            bytes.push(b);
            continue;
        }
        match e {
            '0'..='3' => {
                let mut n = e.to_digit(8).unwrap_or(0);
                for _ in 0..2 {
                    match chars.peek().and_then(|c| c.to_digit(8)) {
                        Some(d) if n * 8 + d <= 0xff => {
                            n = n * 8 + d;
                            chars.next();
                        }
                        _ => break,
                    }
                }
                bytes.push(u8::try_from(n).unwrap_or(0));
            }
            'x' => bytes.push(u8::try_from(hex(&mut chars, 2)?).unwrap_or(0)),
            'u' | 'U' => {
                let n = hex(&mut chars, if e == 'u' { 4 } else { 8 })?;
                let code = match pending_high.take() {
                    Some(high) if (0xdc00..0xe000).contains(&n) => {
                        0x10000 + ((high - 0xd800) << 10) + (n - 0xdc00)
                    }
                    Some(_) => return Err("a UTF-16 high surrogate without its low half".into()),
                    None if (0xd800..0xdc00).contains(&n) => {
                        pending_high = Some(n);
                        continue;
                    }
                    None => n,
                };
                let c = char::from_u32(code)
                    .ok_or_else(|| format!("\\{e}{code:x} is not a Unicode character"))?;
                push_char(&mut bytes, c);
            }
            other => {
                bytes.push(b'\\');
                push_char(&mut bytes, other);
            }
        }
    }
    if bytes.contains(&0) {
        return Err("a value may not hold a NUL character".into());
    }
    String::from_utf8(bytes).map_err(|_| "the escapes do not make UTF-8 text".into())
}

fn push_char(bytes: &mut Vec<u8>, c: char) {
    let mut buf = [0u8; 4];
    bytes.extend_from_slice(c.encode_utf8(&mut buf).as_bytes());
}

fn hex(chars: &mut std::iter::Peekable<std::str::Chars<'_>>, digits: usize) -> Result<u32, String> {
    let mut n = 0u32;
    for _ in 0..digits {
        let d = chars
            .next()
            .and_then(|c| c.to_digit(16))
            .ok_or_else(|| format!("an escape needs {digits} hexadecimal digits"))?;
        n = n * 16 + d;
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn files(list: &[(&str, &str)]) -> BTreeMap<PathBuf, String> {
        list.iter()
            .map(|(p, t)| (PathBuf::from(p), (*t).to_owned()))
            .collect()
    }

    fn read_ini(map: &BTreeMap<PathBuf, String>, path: &str) -> Result<Ini, ImportError> {
        let mut read = |p: &Path| {
            map.get(p)
                .cloned()
                .ok_or_else(|| std::io::Error::from(std::io::ErrorKind::NotFound))
        };
        Ini::read(Path::new(path), &mut read)
    }

    #[test]
    fn sections_repeats_comments_and_continuations() {
        let map = files(&[(
            "/c/m.ini",
            "; leading comment\n[HAL]\nHALCMD = net a b # not a comment\n  # comment\nHALCMD = sets a \\\n  20\n[EMC]\nMACHINE = first\nMACHINE = second\n",
        )]);
        let ini = read_ini(&map, "/c/m.ini").expect("reads");
        let cmds: Vec<&str> = ini.all("HAL", "HALCMD").map(|e| e.value.as_str()).collect();
        assert_eq!(cmds, ["net a b # not a comment", "sets a 20"]);
        assert_eq!(ini.value("EMC", "MACHINE"), Some("first"));
        assert_eq!(ini.get("EMC", "MACHINE").map(|e| e.line), Some(8));
    }

    #[test]
    fn includes_are_read_in_place_and_recursion_is_refused() {
        let map = files(&[
            ("/c/m.ini", "#INCLUDE base.inc\n[KINS]\nJOINTS = 5\n"),
            ("/c/base.inc", "[EMC]\nMACHINE = base\n"),
        ]);
        let ini = read_ini(&map, "/c/m.ini").expect("reads");
        assert_eq!(ini.value("EMC", "MACHINE"), Some("base"));
        assert_eq!(ini.value("KINS", "JOINTS"), Some("5"));
        let map = files(&[("/c/m.ini", "#INCLUDE m.ini\n")]);
        let e = read_ini(&map, "/c/m.ini").expect_err("recursion");
        assert_eq!(e.line, Some(1));
        assert!(e.message.contains("includes itself"), "{e}");
    }

    #[test]
    fn bad_lines_are_named() {
        let map = files(&[("/c/m.ini", "[EMC]\nMACHINE = x\nthis is not a variable\n")]);
        let e = read_ini(&map, "/c/m.ini").expect_err("bad line");
        assert_eq!((e.file.as_path(), e.line), (Path::new("/c/m.ini"), Some(3)));
        let map = files(&[("/c/m.ini", "KEY = 1\n")]);
        let e = read_ini(&map, "/c/m.ini").expect_err("outside");
        assert!(e.message.contains("before any [SECTION]"), "{e}");
        let map = files(&[("/c/m.ini", "[EMC\n")]);
        assert!(read_ini(&map, "/c/m.ini").is_err());
        let map = files(&[("/c/m.ini", "[EMC]\n1KEY = 2\n")]);
        assert!(read_ini(&map, "/c/m.ini").is_err());
    }

    #[test]
    fn escapes_are_decoded() {
        assert_eq!(unescape(r"a\x20b\tc").as_deref(), Ok("a b\tc"));
        assert_eq!(unescape(r"\360\237\230\200").as_deref(), Ok("😀"));
        assert_eq!(unescape(r"\ud83d\ude00").as_deref(), Ok("😀"));
        assert_eq!(unescape(r"\U0001f600").as_deref(), Ok("😀"));
        assert!(unescape(r"\x00").is_err());
        assert!(unescape(r"\xZZ").is_err());
    }

    #[test]
    fn reals() {
        assert_eq!(parse_real(" -36000 "), Some(-36000.0));
        assert_eq!(parse_real("1e3"), Some(1000.0));
        assert_eq!(parse_real("inf"), None);
        assert_eq!(parse_real("0x10"), None);
        assert_eq!(parse_real(""), None);
    }
}
