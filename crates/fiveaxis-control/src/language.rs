//! Which language a program file is written in, when it is not the
//! machine control's: SINUMERIK and HEIDENHAIN programs are read by their
//! own front ends on any machine, as the file's name or first line says.

use std::borrow::Cow;
use std::path::Path;

use fiveaxis_machine::{Control, Machine};

/// Bytes of a program's start that [`program_language`] looks at.
pub const HEAD_BYTES: usize = 64;

/// The control whose own language the program is in: SINUMERIK for a
/// `.mpf` / `.spf` file or a text starting with a transfer header `%_N_`;
/// HEIDENHAIN for a `.h` file or a text whose first block is `BEGIN PGM`
/// (after a block number, if any); `None` for anything else (the machine's
/// control reads it). `head` is the program's first bytes (at least
/// [`HEAD_BYTES`] of them, or all), after a UTF-8 byte-order mark if any.
pub fn program_language(name: Option<&Path>, head: &[u8]) -> Option<Control> {
    let extension = name
        .and_then(Path::extension)
        .and_then(|e| e.to_str())
        .unwrap_or("");
    let head = head.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(head);
    if extension.eq_ignore_ascii_case("mpf")
        || extension.eq_ignore_ascii_case("spf")
        || head.starts_with(b"%_N_")
    {
        return Some(Control::Sinumerik);
    }
    if extension.eq_ignore_ascii_case("h") || is_heidenhain_head(head) {
        return Some(Control::Heidenhain);
    }
    None
}

/// A first line `0 BEGIN PGM …` (the block number optional, any case).
fn is_heidenhain_head(head: &[u8]) -> bool {
    let text = head
        .iter()
        .position(|&b| b == b'\n')
        .map_or(head, |end| &head[..end]);
    let rest = text.trim_ascii_start();
    let digits = rest.iter().take_while(|b| b.is_ascii_digit()).count();
    let rest = rest[digits..].trim_ascii_start();
    rest.len() >= 9 && rest[..9].eq_ignore_ascii_case(b"BEGIN PGM")
}

/// The machine a program runs on: `machine` itself, or a clone with the
/// control whose language the program is in (`language`), when that is
/// another.
pub fn machine_for_language(machine: &Machine, language: Option<Control>) -> Cow<'_, Machine> {
    match language {
        Some(control) if control != machine.control => Cow::Owned(Machine {
            control,
            ..machine.clone()
        }),
        _ => Cow::Borrowed(machine),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_first_lines() {
        let none = |head: &[u8]| program_language(None, head);
        assert_eq!(none(b"%_N_PART_MPF\n"), Some(Control::Sinumerik));
        assert_eq!(none(b"\xEF\xBB\xBF%_N_X_SPF"), Some(Control::Sinumerik));
        assert_eq!(
            none(b"0 BEGIN PGM PART MM\n1 L X+0"),
            Some(Control::Heidenhain)
        );
        assert_eq!(none(b"begin pgm part mm"), Some(Control::Heidenhain));
        assert_eq!(none(b"%\nO1000\nG0 X0"), None);
        assert_eq!(none(b"BEGIN"), None);
        let named = |n: &str| program_language(Some(Path::new(n)), b"");
        assert_eq!(named("part.H"), Some(Control::Heidenhain));
        assert_eq!(named("part.MPF"), Some(Control::Sinumerik));
        assert_eq!(named("part.nc"), None);
    }
}
