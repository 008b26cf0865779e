//! The M codes of a switchable-kinematics configuration
//! (`motion/switchkins.adoc`, "G-/M-code commands"; `remap/remap.adoc`).
//!
//! A line `REMAP = M428 modalgroup=10 ngc=428remap` makes M428 call the
//! subroutine `428remap.ngc` (found in `[RS274NGC] SUBROUTINE_PATH`). The
//! sim configurations' subroutines select a kinematics type with
//! `M68 E<n> Q<type>` on the analog output that is netted to
//! `motion.switchkins-type` (`net :kinstype-select <= motion.analog-out-03
//! => motion.switchkins-type`), then synchronise with `M66 E0 L0`. The
//! importer reads which type each subroutine selects (numbers given
//! directly or through `#<name> = value` assignments in the subroutine) and
//! writes what that type is in the machine model's words: the module's
//! TCP kinematics → `tcpc_on`; identity → `tcpc_off`; `userk` (type 2,
//! the user's kinematics, identity as shipped) → `tcpc_off`, with a note.

use std::path::Path;

use super::hal::{Drive, Hal};
use super::ini::{Ini, parse_real};
use super::kins::{Kinematics, KinsType};
use super::{ImportError, Reader, normalize};
use crate::{MAX_M_CODE, MFunction, RESERVED_M_CODES};

/// The builder M codes of the configuration, and whether the machine runs
/// its TCP kinematics from power-on (a switchable module whose switch is
/// not connected, with the TCP kinematics as type 0).
pub(crate) fn m_codes(
    ini: &Ini,
    folder: &Path,
    hal: &Hal,
    kins: &Kinematics,
    read: &mut Reader<'_>,
    notes: &mut Vec<String>,
) -> Result<(Vec<(u16, MFunction)>, bool), ImportError> {
    let switch = switch_output(hal);
    // switchkins.adoc: "Switchable kinematics initialize with
    // motion.switchkins-type==0", connected or not.
    let tcp_at_start = kins.types.first() == Some(&KinsType::Tcp);
    if !kins.types.is_empty() {
        match (switch, kins.types.first()) {
            (None, Some(KinsType::Tcp)) => notes.push(format!(
                "{}: motion.switchkins-type is not connected, so LinuxCNC runs every program \
                 with the TCP kinematics (X Y Z = tool tip on the table): tcpc_at_start = true",
                kins.module
            )),
            (None, _) => notes.push(format!(
                "{}: motion.switchkins-type is not connected: the kinematics stay identity",
                kins.module
            )),
            (Some(n), first) => notes.push(format!(
                "kinematics switch: motion.switchkins-type is driven by motion.analog-out-{n:02} (M68 E{n}){}",
                if first == Some(&KinsType::Tcp) {
                    "; type 0, the power-on type, is the TCP kinematics: tcpc_at_start = true"
                } else {
                    ""
                }
            )),
        }
    }
    let folders: Vec<String> = ini
        .get("RS274NGC", "SUBROUTINE_PATH")
        .map(|e| e.value.split(':').map(|f| f.trim().to_owned()).collect())
        .unwrap_or_default();
    let mut codes = Vec::new();
    for entry in ini.all("RS274NGC", "REMAP") {
        let mut words = entry.value.split_whitespace();
        let code = words.next().unwrap_or("");
        let ngc = words.find_map(|w| w.strip_prefix("ngc="));
        let number = code
            .strip_prefix(['M', 'm'])
            .and_then(|n| n.parse::<u16>().ok())
            .filter(|n| *n <= MAX_M_CODE && !RESERVED_M_CODES.contains(n));
        let skip = |why: &str, notes: &mut Vec<String>| {
            notes.push(format!(
                "[RS274NGC]REMAP = {} (line {}): not imported: {why}",
                entry.value, entry.line
            ));
        };
        let (Some(number), Some(ngc), Some(pin)) = (number, ngc, switch) else {
            skip("not an M code that switches the kinematics", notes);
            continue;
        };
        let Some((path, text)) = folders.iter().find_map(|f| {
            let path = normalize(&folder.join(f).join(format!("{ngc}.ngc")));
            read(&path).ok().map(|t| (path, t))
        }) else {
            return Err(entry.error(format!(
                "the subroutine {ngc}.ngc is in none of the SUBROUTINE_PATH folders"
            )));
        };
        let selects: Vec<(f64, u32)> = analog_outputs(&text)
            .into_iter()
            .filter(|(e, _, _)| *e == f64::from(pin))
            .map(|(_, q, line)| (q, line))
            .collect();
        let Some(&(kinstype, line)) = selects.first() else {
            skip(&format!("{ngc}.ngc sets no M68 E{pin}"), notes);
            continue;
        };
        if selects.iter().any(|(q, _)| *q != kinstype) {
            skip(
                &format!("{ngc}.ngc selects more than one kinematics type"),
                notes,
            );
            continue;
        }
        let kind = (kinstype >= 0.0)
            .then(|| kins.types.get(kinstype.trunc() as usize))
            .flatten()
            .ok_or_else(|| {
                ImportError::at(
                    &path,
                    line,
                    format!(
                        "M68 E{pin} Q{kinstype}: {} has no kinematics type {kinstype}",
                        kins.module
                    ),
                )
            })?;
        let (function, what) = match kind {
            KinsType::Tcp => (MFunction::TcpcOn, "the TCP kinematics: tcpc_on"),
            KinsType::Identity => (MFunction::TcpcOff, "identity kinematics: tcpc_off"),
            KinsType::Tool => (
                MFunction::TcpcOn,
                "the TOOL kinematics (X Y Z in the tool frame the TWP remaps set; fiveaxis's \
                 tilted working plane gives that frame): tcpc_on",
            ),
            KinsType::User => (
                MFunction::TcpcOff,
                "userk (type 2), the user's kinematics, identity as LinuxCNC ships it: tcpc_off",
            ),
        };
        notes.push(format!(
            "M{number}: REMAP (line {}) calls {ngc}.ngc, whose M68 E{pin} Q{kinstype} (line {line}) selects {what}",
            entry.line
        ));
        codes.push((number, function));
    }
    Ok((codes, tcp_at_start))
}

/// N of the `motion.analog-out-NN` that drives `motion.switchkins-type`.
fn switch_output(hal: &Hal) -> Option<u8> {
    let Drive::Signal { pins, .. } = hal.drive("motion.switchkins-type") else {
        return None;
    };
    pins.iter().find_map(|p| {
        p.strip_prefix("motion.analog-out-")
            .and_then(|n| n.parse::<u8>().ok())
    })
}

/// Every `M68 E.. Q..` of a subroutine, with E and Q resolved through the
/// subroutine's `#<name> = number` assignments: (E, Q, line).
fn analog_outputs(text: &str) -> Vec<(f64, f64, u32)> {
    let mut names: Vec<(String, f64)> = Vec::new();
    let mut found = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line = u32::try_from(index + 1).unwrap_or(u32::MAX);
        let code = uncomment(raw);
        // `#<name> = value`
        if let Some(rest) = code.strip_prefix("#<")
            && let Some((name, value)) = rest.split_once(">=")
            && let Some(v) = parse_real(value)
        {
            names.retain(|(n, _)| n != name);
            names.push((name.to_owned(), v));
            continue;
        }
        let Some(at) = find_word(&code, "m68") else {
            continue;
        };
        let words = &code[at + 3..];
        let value_of = |letter: char| -> Option<f64> {
            let i = words.find(letter)?;
            let rest = &words[i + 1..];
            if let Some(named) = rest.strip_prefix("#<") {
                let name = &named[..named.find('>')?];
                names.iter().find(|(n, _)| n == name).map(|(_, v)| *v)
            } else {
                let end = rest
                    .find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '-' | '+')))
                    .unwrap_or(rest.len());
                parse_real(&rest[..end])
            }
        };
        if let (Some(e), Some(q)) = (value_of('e'), value_of('q')) {
            found.push((e, q, line));
        }
    }
    found
}

/// A line of RS274/NGC without comments and spaces, in lower case.
fn uncomment(raw: &str) -> String {
    let mut out = String::with_capacity(raw.len());
    let mut depth = 0usize;
    for c in raw.chars() {
        match c {
            ';' if depth == 0 => break,
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            c if depth == 0 && !c.is_whitespace() => out.push(c.to_ascii_lowercase()),
            _ => {}
        }
    }
    out
}

/// Where `word` (e.g. `m68`) stands as a word: not part of a longer
/// number or name.
fn find_word(code: &str, word: &str) -> Option<usize> {
    let mut from = 0;
    while let Some(i) = code[from..].find(word) {
        let at = from + i;
        let before = code[..at].chars().next_back();
        let after = code[at + word.len()..].chars().next();
        let inside_name = code[..at]
            .rfind('<')
            .is_some_and(|o| code[..at].rfind('>').is_none_or(|c| c < o));
        if !before.is_some_and(|c| c.is_ascii_alphanumeric())
            && !after.is_some_and(|c| c.is_ascii_digit())
            && !inside_name
        {
            return Some(at);
        }
        from = at + word.len();
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn m68_words_are_resolved_through_named_parameters() {
        let text = "o<x>sub\n  #<kinstype> = 1 ; comment\n  #<PIN> = 3\n  M68  E#<PIN> Q#<kinstype> (set)\n  M66 E0 L0\nM68 E2 Q5\no<x>endsub\n";
        assert_eq!(analog_outputs(text), vec![(3.0, 1.0, 4), (2.0, 5.0, 6)]);
        assert_eq!(
            analog_outputs("(M68 E3 Q1)\n; M68 E3 Q1\nM168 E3 Q1\n"),
            vec![]
        );
    }
}
