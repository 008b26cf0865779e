//! The output program: FANUC-style text (G93 inverse time feed, absolute
//! machine positions in G54 with length compensation and TCPC off), or,
//! for a machine whose control is a SINUMERIK, the same in the Siemens
//! form: a `%_N_NAME_MPF` header, `;` comments, `D0` instead of `G49` and
//! `TRAFOOF` instead of the cancels of TCPC and the tilted plane (ONE
//! p43–45; brief §1, §4), and for a HEIDENHAIN TNC the same as Klartext
//! (TNC 640 conventions): `BEGIN PGM` / `END PGM`, every block numbered
//! from 0, `;` comments, `FUNCTION RESET TCPM` and `PLANE RESET STAY`
//! instead of the cancels, `L X+… R0 FMAX` / `L … R0 F…` with signed
//! values, `TOOL CALL` for the carried T and S words, and no inverse time
//! feed (the TNC has none: the composite style, its reading of F without
//! `M116`).
//!
//! Word formats: lengths in mm and angles in degrees with at least four
//! decimals (the FANUC least input increment of IS-C is 0.0001 mm / deg;
//! IS-B would be 0.001), more when the tolerance is finer; F of inverse
//! time with at least six significant digits.

use std::fmt::Write;

use fiveaxis_machine::{Control, Joints, Machine, Vec3};

use crate::feed::{composite_travel, tip_feed_error};
use crate::{Axes, FeedStyle, Move, Note, Post, PostOptions};

/// Fewest decimals written for lengths and angles.
pub const MIN_DECIMALS: u32 = 4;
/// Most decimals written.
pub const MAX_DECIMALS: u32 = 8;
/// Share of the tip tolerance the rounding of the written words may use.
pub const ROUNDING_SHARE: f64 = 0.05;
/// Arm of the tool tip about the rotary axes assumed for the rounding of
/// angles, mm (a turn of one quantum moves the tip by this times it).
pub const ROUNDING_ARM: f64 = 1000.0;
/// Significant digits of the inverse-time F.
pub const FEED_DIGITS: i32 = 6;

/// The last digit of the written words.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quantum {
    /// Decimals of lengths.
    pub length_decimals: u32,
    /// Decimals of angles.
    pub angle_decimals: u32,
}

impl Quantum {
    /// Digits that keep the rounding of every word within
    /// [`ROUNDING_SHARE`] of the tip tolerance.
    pub fn for_tolerance(tolerance: f64) -> Self {
        let decimals = |step: f64| {
            // Half a unit of the last digit must be at most `step`.
            let d = (0.5 / step).log10().ceil();
            if d.is_finite() {
                (d.max(0.0) as u32).clamp(MIN_DECIMALS, MAX_DECIMALS)
            } else {
                MAX_DECIMALS
            }
        };
        let share = tolerance * ROUNDING_SHARE;
        Self {
            length_decimals: decimals(share),
            angle_decimals: decimals((share / ROUNDING_ARM).to_degrees()),
        }
    }

    /// A machine position rounded as it will be written: linear axes
    /// relative to `origin`, rotary axes as they are.
    pub fn snap(&self, machine: &Machine, j: &Joints, origin: &Vec3) -> Joints {
        let mut out = *j;
        let round = |v: f64, d: u32| {
            let scale = 10f64.powi(d as i32);
            (v * scale).round() / scale
        };
        for (i, v) in out.iter_mut().enumerate().take(machine.axis_count()) {
            *v = if i < machine.linear.len() {
                let o = work_offset(origin, i);
                round(*v - o, self.length_decimals) + o
            } else {
                round(*v, self.angle_decimals)
            };
        }
        out
    }
}

/// The work offset of linear axis `i`: X, Y, Z have one; additional
/// linear axes (U, V, W) are written as machine positions.
fn work_offset(origin: &Vec3, i: usize) -> f64 {
    if i < 3 { origin[i] } else { 0.0 }
}

/// What the header says besides the post's own figures.
#[derive(Clone, Copy, Debug, Default)]
pub struct Header<'a> {
    /// The source program, as named by the user.
    pub source: &'a str,
    /// Program number of the output (`O` word), if any.
    pub number: Option<u32>,
    /// The machine the source was written for, when it is not the
    /// output's (retargeting).
    pub source_machine: Option<&'a str>,
    /// Words of the source carried into the output, by source line
    /// ([`carried_words`]).
    pub carried: &'a [(u32, String)],
}

/// M codes carried from the source into the output: stops, spindle, tool
/// change, coolant.
pub const CARRIED_M: [u32; 9] = [0, 1, 3, 4, 5, 6, 7, 8, 9];

/// The `M`, `S` and `T` words of each line of a G-code text that the
/// output carries (M in [`CARRIED_M`], S and T with a number), joined per
/// line, with the line number (1-based). Comments are skipped; words
/// whose value is not a plain number (macro expressions) are not carried.
///
/// A HEIDENHAIN Klartext text (its first block `BEGIN PGM`) gives the
/// same words from its blocks ([`klartext_carried_words`]).
pub fn carried_words(text: &str) -> Vec<(u32, String)> {
    if is_klartext(text) {
        return klartext_carried_words(text);
    }
    let mut out = Vec::new();
    for (index, line) in text.lines().enumerate() {
        let mut words = Vec::new();
        let mut chars = line.char_indices().peekable();
        let bytes = line.as_bytes();
        while let Some((i, c)) = chars.next() {
            match c {
                '(' => {
                    // To the closing parenthesis.
                    for (_, d) in chars.by_ref() {
                        if d == ')' {
                            break;
                        }
                    }
                }
                ';' => break,
                'M' | 'm' | 'S' | 's' | 'T' | 't' => {
                    let letter = c.to_ascii_uppercase();
                    let mut end = i + 1;
                    while end < bytes.len() && (bytes[end].is_ascii_digit() || bytes[end] == b'.') {
                        end += 1;
                    }
                    let digits = &line[i + 1..end];
                    if let Ok(v) = digits.parse::<f64>()
                        && v >= 0.0
                        && v.fract() == 0.0
                        && (letter != 'M' || CARRIED_M.contains(&(v as u32)))
                    {
                        words.push(format!("{letter}{}", v as u64));
                    }
                }
                _ => {}
            }
        }
        if !words.is_empty() {
            out.push((
                u32::try_from(index + 1).unwrap_or(u32::MAX),
                words.join(" "),
            ));
        }
    }
    out
}

/// Whether `text` is a Klartext program: its first line that is not
/// blank is `BEGIN PGM` (with or without a block number).
fn is_klartext(text: &str) -> bool {
    text.lines()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .is_some_and(|l| {
            l.trim_start_matches(|c: char| c.is_ascii_digit())
                .trim_start()
                .to_ascii_uppercase()
                .starts_with("BEGIN PGM")
        })
}

/// The carried words of a Klartext program, as [`carried_words`] gives
/// G-code's: `TOOL CALL 5 Z S1000` is `T5 M6 S1000` (`TOOL CALL Z S1000`
/// `S1000`; a tool called by name or a Q parameter is not carried), and
/// the M words of [`CARRIED_M`] of any block. Comments (`;` to the end
/// of the line) are skipped.
pub fn klartext_carried_words(text: &str) -> Vec<(u32, String)> {
    let mut out = Vec::new();
    for (index, line) in text.lines().enumerate() {
        let code = line.split(';').next().unwrap_or("").to_ascii_uppercase();
        let mut tokens = code.split_whitespace().peekable();
        // The block number.
        tokens.next_if(|t| t.bytes().all(|b| b.is_ascii_digit()));
        let plain = |digits: &str| {
            digits
                .parse::<f64>()
                .ok()
                .filter(|v| *v >= 0.0 && v.fract() == 0.0)
                .map(|v| v as u64)
        };
        let mut words = Vec::new();
        let tool_call =
            tokens.next_if_eq(&"TOOL").is_some() && tokens.next_if_eq(&"CALL").is_some();
        if tool_call && let Some(n) = tokens.peek().and_then(|t| plain(t)) {
            tokens.next();
            words.push(format!("T{n} M6"));
        }
        for t in tokens {
            let (letter, value) = t.split_at(1);
            match letter {
                "S" if tool_call => {
                    if let Some(v) = plain(value) {
                        words.push(format!("S{v}"));
                    }
                }
                "M" => {
                    if let Some(v) = plain(value)
                        && CARRIED_M.contains(&(v as u32))
                        && value.bytes().all(|b| b.is_ascii_digit())
                    {
                        words.push(format!("M{v}"));
                    }
                }
                _ => {}
            }
        }
        if !words.is_empty() {
            out.push((
                u32::try_from(index + 1).unwrap_or(u32::MAX),
                words.join(" "),
            ));
        }
    }
    out
}

/// Writes the whole program.
pub fn write(machine: &Machine, post: &Post, options: &PostOptions, header: &Header<'_>) -> String {
    let quantum = Quantum::for_tolerance(options.tolerance);
    let siemens = machine.control == Control::Sinumerik;
    let klartext = machine.control == Control::Heidenhain;
    // The TNC has no inverse time: its F with rotary axes is the
    // composite reading ([`FeedStyle::for_control`] refuses inverse time
    // asked for; a library caller's is taken as that).
    let feed_style = if klartext && options.feed == FeedStyle::InverseTime {
        FeedStyle::DegreesPerMinute
    } else {
        options.feed
    };
    let mut out = String::with_capacity(64 * (post.moves.len() + 16));
    let comment = |out: &mut String, text: &str| {
        // Parentheses cannot nest in a FANUC comment; a Siemens comment
        // runs to the end of the line.
        let clean: String = text
            .chars()
            .map(|c| match c {
                '(' | ')' | ';' | '%' => ' ',
                c if c.is_ascii() && !c.is_ascii_control() => c.to_ascii_uppercase(),
                _ => '?',
            })
            .collect();
        if siemens || klartext {
            let _ = writeln!(out, ";{clean}");
        } else {
            let _ = writeln!(out, "({clean})");
        }
    };
    // The F words and what they do to the tip feed.
    // The F words, and what they do to the tip feed. Time-keeping styles
    // carry the rounding of each F into the next block's (the written
    // times add up to the intended ones within one rounding, however many
    // blocks a stretch has).
    let mut words: Vec<Option<String>> = Vec::with_capacity(post.moves.len());
    let mut feed_error = 0.0f64;
    let mut drift = 0.0f64;
    let mut at = post
        .start
        .or_else(|| post.moves.iter().find_map(Move::to).copied());
    for m in &post.moves {
        let mut word = None;
        if let Move::Feed {
            to, minutes, feed, ..
        } = m
        {
            let from = at.unwrap_or(*to);
            let keeps_time = feed_style != FeedStyle::Programmed;
            let wanted = if keeps_time && minutes + drift > 0.0 {
                minutes + drift
            } else {
                *minutes
            };
            if let Some(f) = feed_style.f_word(machine, &from, to, wanted, *feed) {
                let mut text = String::new();
                feed_text(&mut text, f);
                let written: f64 = text.parse().unwrap_or(f);
                let taken = match feed_style {
                    FeedStyle::InverseTime => 1.0 / written,
                    _ => composite_travel(machine, &from, to) / written,
                };
                if keeps_time {
                    drift = wanted - taken;
                } else {
                    feed_error =
                        feed_error.max(tip_feed_error(machine, &from, to, *minutes, written));
                }
                word = Some(text);
            }
        }
        if let Some(to) = m.to() {
            at = Some(*to);
        }
        words.push(word);
    }
    // The program's name (`%_N_NAME_MPF`, `BEGIN PGM NAME MM`).
    let name = header
        .number
        .map_or("FIVEAXIS".to_owned(), |n| format!("P{n:04}"));
    if klartext {
        // Block numbers are put in front of every line at the end.
        let _ = writeln!(out, "BEGIN PGM {name} MM");
    } else if siemens {
        // The transfer header names the program.
        let _ = writeln!(out, "%_N_{name}_MPF");
        out.push_str(";$PATH=/_N_MPF_DIR\n");
    } else {
        out.push_str("%\n");
        if let Some(n) = header.number {
            let _ = writeln!(out, "O{n:04}");
        }
    }
    comment(
        &mut out,
        "fiveaxis post: machine-axis program, TCPC removed",
    );
    comment(&mut out, &format!("source: {}", header.source));
    if let Some(from) = header.source_machine {
        comment(&mut out, &format!("written for: {from}, retargeted"));
    }
    comment(&mut out, &format!("machine: {}", machine.name));
    comment(
        &mut out,
        &format!(
            "tolerance: tip {} mm, direction {} deg",
            options.tolerance, options.angle_tolerance
        ),
    );
    // A block without length compensation (the move of a G49 cancel)
    // names no tool when others do.
    let any_tool = post.tool_lengths.iter().any(|l| *l != 0.0);
    let lengths: Vec<String> = post
        .tool_lengths
        .iter()
        .filter(|l| !any_tool || **l != 0.0)
        .map(|l| format!("{l:.4}"))
        .collect();
    comment(
        &mut out,
        &format!(
            "for tool length {} mm only: {}",
            if lengths.is_empty() {
                "-".to_owned()
            } else {
                lengths.join(", ")
            },
            if siemens {
                "TRAORI, CYCLE800 and the tool length removed, D0"
            } else if klartext {
                "M128, FUNCTION TCPM and PLANE removed"
            } else {
                "G43.4/G43.5, G68.2 and G43 removed, G49"
            }
        ),
    );
    comment(
        &mut out,
        &format!(
            "largest deviation reached: tip {:.5} mm, direction {:.5} deg",
            post.deviation.tip, post.deviation.angle
        ),
    );
    if let Axes::Post { .. } = options.axes {
        comment(
            &mut out,
            &format!(
                "rotary axes: the post's own, continuous, {} flips: retract {} mm along the tool axis, turn, re-engage",
                post.flips, options.retract
            ),
        );
        if post.singular_blocks > 0 {
            comment(
                &mut out,
                &format!(
                    "singular passages: {} blocks, rotating axis linear within the {} deg cone, direction within {:.4} deg of the programmed there",
                    post.singular_blocks, machine.params.singular_cone, post.singular_error
                ),
            );
        }
        if post.fixed_direction_error > options.angle_tolerance {
            comment(
                &mut out,
                &format!(
                    "warning: the machine cannot turn the tool, direction off by up to {:.4} deg",
                    post.fixed_direction_error
                ),
            );
        }
        if post.out_of_limits > 0 {
            comment(
                &mut out,
                &format!(
                    "warning: {} blocks leave the rotary soft limits on every solution",
                    post.out_of_limits
                ),
            );
        }
    }
    if post.unresolved > 0 {
        comment(
            &mut out,
            &format!(
                "warning: {} pieces miss the tolerances at the shortest piece",
                post.unresolved
            ),
        );
    }
    let feed_text = match feed_style {
        FeedStyle::InverseTime => "feed G93 inverse time, tip feed kept".to_owned(),
        FeedStyle::DegreesPerMinute if klartext => {
            "feed F per block from the combined travel of all axes, degrees as mm, the TNC's reading without M116, it has no inverse time, tip feed kept".to_owned()
        }
        FeedStyle::DegreesPerMinute => {
            "feed G94 per block from the composite travel, degrees as mm, tip feed kept".to_owned()
        }
        FeedStyle::Programmed if klartext => format!(
            "feed F as programmed: tip feed error up to {:.2} percent",
            100.0 * feed_error
        ),
        FeedStyle::Programmed => format!(
            "feed G94 as programmed: tip feed error up to {:.2} percent",
            100.0 * feed_error
        ),
    };
    comment(
        &mut out,
        &format!(
            "{} cutting blocks in, {} blocks out, {feed_text}",
            post.source_blocks,
            post.moves.len()
        ),
    );
    comment(
        &mut out,
        &format!(
            "positions: machine axes minus {} X{:.4} Y{:.4} Z{:.4}",
            if klartext { "the preset" } else { "G54" },
            options.origin[0],
            options.origin[1],
            options.origin[2]
        ),
    );
    let carried_words: Vec<(u32, Vec<String>)> = header
        .carried
        .iter()
        .map(|(line, w)| {
            let blocks = if klartext {
                klartext_blocks(w)
            } else {
                vec![w.clone()]
            };
            (*line, blocks)
        })
        .collect();
    // A TOOL CALL switches on the length of the tool called along the
    // tool axis (the TNC has no G49): the linear axes after it are
    // written less that length, the one the output is made for. With
    // several lengths the output does not say which tool has which: the
    // positions are left as they are, right with length 0 in the table.
    let calls_tool = klartext
        && carried_words
            .iter()
            .flat_map(|(_, b)| b)
            .any(|b| is_tool_change(b));
    let mut distinct: Vec<f64> = post
        .tool_lengths
        .iter()
        .copied()
        .filter(|l| *l != 0.0)
        .collect();
    distinct.dedup();
    let called_length = match distinct[..] {
        [l] if calls_tool => Some(l),
        _ => None,
    };
    if let Some(l) = called_length {
        comment(
            &mut out,
            &format!(
                "after TOOL CALL the tool's length is compensated: X Y Z there less {l:.4} mm along the tool axis, the tool table must hold that length"
            ),
        );
    } else if calls_tool {
        comment(
            &mut out,
            "warning: TOOL CALL switches on the tool table's length: the positions are right with length 0 there",
        );
    } else if klartext {
        comment(
            &mut out,
            "no TOOL CALL: positions without length compensation, right with no tool length in force",
        );
    }
    let length_vector = |l: f64| l * machine.tool_direction.into_inner();
    let mut shift = Vec3::zeros();
    // The feed mode stays on throughout: positioning does not read F.
    if klartext {
        out.push_str("FUNCTION RESET TCPM\nPLANE RESET STAY\n");
    } else if siemens {
        let _ = writeln!(
            out,
            "G71 G17 G90 G40 G54 D0 TRAFOOF {}",
            feed_style.g_code()
        );
    } else {
        let _ = writeln!(
            out,
            "G21 G17 G90 G40 G49 G69 G80 G54 {}",
            feed_style.g_code()
        );
    }
    let mut carried = carried_words.iter().peekable();
    for (m, word) in post.moves.iter().zip(&words) {
        let line = match m {
            Move::Rapid { line, .. } | Move::Feed { line, .. } => Some(*line),
            Move::Note(_) => None,
        };
        if let Some(line) = line {
            while let Some((_, blocks)) = carried.next_if(|(l, _)| *l <= line) {
                for w in blocks {
                    out.push_str(w);
                    out.push('\n');
                    if let Some(l) = called_length
                        && is_tool_change(w)
                    {
                        shift = length_vector(l);
                    }
                }
            }
        }
        match m {
            Move::Rapid { to, .. } if klartext => {
                out.push('L');
                axes(
                    &mut out,
                    machine,
                    to,
                    &(options.origin + shift),
                    &quantum,
                    true,
                );
                out.push_str(" R0 FMAX");
            }
            Move::Rapid { to, .. } => {
                out.push_str("G0");
                axes(&mut out, machine, to, &options.origin, &quantum, false);
            }
            Move::Feed { to, .. } => {
                let Some(f) = word else {
                    // No axis moves (G94 styles): nothing to write.
                    continue;
                };
                if klartext {
                    out.push('L');
                    axes(
                        &mut out,
                        machine,
                        to,
                        &(options.origin + shift),
                        &quantum,
                        true,
                    );
                    out.push_str(" R0 F");
                } else {
                    out.push_str("G1");
                    axes(&mut out, machine, to, &options.origin, &quantum, false);
                    out.push_str(" F");
                }
                out.push_str(f);
            }
            Move::Note(Note::FlipStart { line, retract }) => {
                comment(
                    &mut out,
                    &format!(
                        "flip before source line {line}: retract {retract} mm along the tool axis, turn the rotary axes, re-engage"
                    ),
                );
                continue;
            }
            Move::Note(Note::FlipEnd) => {
                comment(&mut out, "flip end: re-engaged at the same tip");
                continue;
            }
        }
        out.push('\n');
    }
    if feed_style == FeedStyle::InverseTime {
        out.push_str("G94\n");
    }
    for (_, blocks) in carried {
        for w in blocks {
            out.push_str(w);
            out.push('\n');
        }
    }
    if klartext {
        let _ = writeln!(out, "M30\nEND PGM {name} MM");
        // The TNC's block numbers, from 0.
        let mut numbered = String::with_capacity(out.len() + 8 * (post.moves.len() + 32));
        for (n, line) in out.lines().enumerate() {
            let _ = writeln!(numbered, "{n} {line}");
        }
        numbered
    } else if siemens {
        out.push_str("M30\n");
        out
    } else {
        out.push_str("M30\n%\n");
        out
    }
}

/// Whether a Klartext block calls a tool (`TOOL CALL 5 Z`, not the
/// speed alone `TOOL CALL Z S…`).
fn is_tool_change(block: &str) -> bool {
    block.starts_with("TOOL CALL ") && !block.starts_with("TOOL CALL Z")
}

/// The Klartext blocks of a line's carried words ([`carried_words`]):
/// a T word (with or without M6) is `TOOL CALL n Z`, with the line's S
/// (`TOOL CALL 5 Z S1200`); an S alone is `TOOL CALL Z S1200`; each M a
/// block of its own; M6 is left out (`TOOL CALL` changes the tool).
fn klartext_blocks(words: &str) -> Vec<String> {
    let mut tool = None;
    let mut speed = None;
    let mut m = Vec::new();
    for w in words.split_whitespace() {
        let (letter, value) = w.split_at(1);
        match letter {
            "T" => tool = Some(value),
            "S" => speed = Some(value),
            "M" if value != "6" => m.push(format!("M{value}")),
            _ => {}
        }
    }
    let mut out = Vec::new();
    match (tool, speed) {
        (Some(t), Some(s)) => out.push(format!("TOOL CALL {t} Z S{s}")),
        (Some(t), None) => out.push(format!("TOOL CALL {t} Z")),
        (None, Some(s)) => out.push(format!("TOOL CALL Z S{s}")),
        (None, None) => {}
    }
    out.extend(m);
    out
}

/// Every axis word of a machine position, X Y Z less `origin`;
/// `signed`: with an explicit `+` (Klartext).
fn axes(
    out: &mut String,
    machine: &Machine,
    to: &Joints,
    origin: &Vec3,
    q: &Quantum,
    signed: bool,
) {
    for (i, name) in machine.axis_names().enumerate() {
        let linear = machine.linear.len();
        let (value, decimals) = if i < linear {
            (to[i] - work_offset(origin, i), q.length_decimals)
        } else {
            let axis = &machine.rotary[i - linear];
            let v = if axis.rollover {
                to[i].rem_euclid(360.0)
            } else {
                to[i]
            };
            (v, q.angle_decimals)
        };
        let _ = write!(out, " {name}");
        number(out, value, decimals as usize, signed);
    }
}

/// A number with `decimals` decimals, no `-0`; `signed`: `+` before
/// one that is not negative.
fn number(out: &mut String, value: f64, decimals: usize, signed: bool) {
    let at = out.len();
    let _ = write!(out, "{value:.decimals$}");
    let text = &out[at..];
    if text.starts_with('-') && text[1..].bytes().all(|b| b == b'0' || b == b'.') {
        out.remove(at);
    }
    if signed && !out[at..].starts_with('-') {
        out.insert(at, '+');
    }
}

/// An inverse-time F with [`FEED_DIGITS`] significant digits.
fn feed_text(out: &mut String, f: f64) {
    let before = if f >= 1.0 {
        f.log10().floor() as i32 + 1
    } else {
        0
    };
    let decimals = (FEED_DIGITS - before).max(0) as usize;
    let decimals = if f < 1.0 && f > 0.0 {
        (FEED_DIGITS - f.log10().floor() as i32 - 1).max(0) as usize
    } else {
        decimals
    };
    let _ = write!(out, "{f:.decimals$}");
}

/// The tool length a `fiveaxis post` output was made for (its header's
/// `(FOR TOOL LENGTH L MM ONLY ...)`, on a SINUMERIK `;FOR TOOL LENGTH
/// …`, in Klartext `n ;FOR TOOL LENGTH …` after the block number; the
/// first length when it names several).
pub fn header_tool_length(text: &str) -> Option<f64> {
    let line = text.lines().take(32).find_map(|l| {
        l.strip_prefix("(FOR TOOL LENGTH ")
            .or_else(|| l.strip_prefix(";FOR TOOL LENGTH "))
            .or_else(|| {
                // A Klartext block: its number first.
                let rest = l.trim_start_matches(|c: char| c.is_ascii_digit());
                (rest.len() < l.len())
                    .then(|| rest.trim_start().strip_prefix(';'))
                    .flatten()
                    .and_then(|c| c.trim_start().strip_prefix("FOR TOOL LENGTH "))
            })
    })?;
    line.split([' ', ','])
        .next()?
        .parse()
        .ok()
        .filter(|l: &f64| l.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linearize::Deviation;

    /// A post of three blocks on the HEIDENHAIN A/C table: a rapid, a cut
    /// and a cut that does not move (left out).
    fn written(number: Option<u32>, carried: &[(u32, String)], feed: FeedStyle) -> String {
        written_for(number, carried, feed, &[100.0])
    }

    /// [`written`] for the tool lengths `lengths`.
    fn written_for(
        number: Option<u32>,
        carried: &[(u32, String)],
        feed: FeedStyle,
        lengths: &[f64],
    ) -> String {
        let machine = fiveaxis_machine::builtin("heidenhain-dmu-ac").expect("built in");
        let mut a = [0.0; fiveaxis_machine::MAX_AXES];
        a[..5].copy_from_slice(&[12.34564, -5.0, -400.0, -0.000001, 90.0]);
        let mut b = a;
        b[..5].copy_from_slice(&[12.5, -5.1, -401.0, 1.5, 90.2]);
        let post = Post {
            moves: vec![
                Move::Rapid { to: a, line: 3 },
                Move::Feed {
                    to: b,
                    minutes: 0.01,
                    feed: 500.0,
                    line: 5,
                },
                Move::Feed {
                    to: b,
                    minutes: 0.01,
                    feed: 500.0,
                    line: 6,
                },
            ],
            start: Some(a),
            deviation: Deviation::default(),
            tool_lengths: lengths.to_vec(),
            source_blocks: 2,
            ..Post::default()
        };
        let options = PostOptions {
            origin: Vec3::new(0.0, 0.0, -500.0),
            feed,
            ..PostOptions::default()
        };
        let header = Header {
            source: "p.nc",
            number,
            source_machine: None,
            carried,
        };
        write(&machine, &post, &options, &header)
    }

    #[test]
    fn klartext_numbers_every_block_and_signs_every_value() {
        let text = written(None, &[], FeedStyle::DegreesPerMinute);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "0 BEGIN PGM FIVEAXIS MM", "{text}");
        assert_eq!(
            lines[1], "1 ;FIVEAXIS POST: MACHINE-AXIS PROGRAM, TCPC REMOVED",
            "{text}"
        );
        for (n, line) in lines.iter().enumerate() {
            assert!(line.starts_with(&format!("{n} ")), "{text}");
        }
        let n = lines.len();
        assert_eq!(lines[n - 1], format!("{} END PGM FIVEAXIS MM", n - 1));
        assert_eq!(lines[n - 2], format!("{} M30", n - 2));
        assert!(text.contains(" FUNCTION RESET TCPM\n"), "{text}");
        assert!(text.contains(" PLANE RESET STAY\n"), "{text}");
        // Signs, no -0, the decimals of the quantum, FMAX.
        assert!(
            text.contains(" L X+12.3456 Y-5.0000 Z+100.0000 A+0.00000 C+90.00000 R0 FMAX\n"),
            "{text}"
        );
        let cut = lines
            .iter()
            .find(|l| l.contains(" L X+12.5000 Y-5.1000 Z+99.0000 A+1.50000 C+90.20000 R0 F"))
            .unwrap_or_else(|| panic!("the cut:\n{text}"));
        let f: f64 = cut
            .rsplit(" F")
            .next()
            .and_then(|f| f.parse().ok())
            .expect("an F");
        let travel = (0.15436f64.powi(2) + 0.01 + 1.0 + 1.500001f64.powi(2) + 0.04).sqrt();
        assert!((f - travel / 0.01).abs() < 0.01, "{f} {text}");
        // The block that does not move is left out; nothing of G-code.
        assert_eq!(text.matches(" L ").count(), 2, "{text}");
        for gone in ["G0", "G1 ", "G9", "%", "(", "-0.0000 "] {
            assert!(!text.contains(gone), "{gone}:\n{text}");
        }
        assert!(
            text.contains(";POSITIONS: MACHINE AXES MINUS THE PRESET X0.0000 Y0.0000 Z-500.0000")
        );
    }

    #[test]
    fn klartext_has_no_inverse_time_and_names_the_program() {
        // Inverse time asked of the writer itself: the composite style.
        let text = written(Some(12), &[], FeedStyle::InverseTime);
        assert_eq!(
            text,
            written(Some(12), &[], FeedStyle::DegreesPerMinute),
            "{text}"
        );
        assert!(text.starts_with("0 BEGIN PGM P0012 MM\n"), "{text}");
        assert!(text.ends_with(" END PGM P0012 MM\n"), "{text}");
        assert!(text.contains("THE TNC'S READING WITHOUT M116"), "{text}");
        assert!(!text.contains("G93") && !text.contains("G94"), "{text}");
        assert_eq!(
            FeedStyle::for_control(None, Control::Heidenhain),
            Ok(FeedStyle::DegreesPerMinute)
        );
        assert_eq!(
            FeedStyle::for_control(None, Control::Sinumerik),
            Ok(FeedStyle::InverseTime)
        );
        assert!(FeedStyle::for_control(Some(FeedStyle::InverseTime), Control::Heidenhain).is_err());
        assert_eq!(
            FeedStyle::for_control(Some(FeedStyle::Programmed), Control::Heidenhain),
            Ok(FeedStyle::Programmed)
        );
    }

    #[test]
    fn carried_words_become_tool_calls_and_m_blocks() {
        let carried = carried_words("T5 M6\nS1200 M3 M8\nG1 X0\nT7 S900\n");
        assert_eq!(
            carried,
            vec![
                (1, "T5 M6".to_owned()),
                (2, "S1200 M3 M8".to_owned()),
                (4, "T7 S900".to_owned())
            ]
        );
        assert_eq!(klartext_blocks("T5 M6"), ["TOOL CALL 5 Z"]);
        assert_eq!(klartext_blocks("T5 M6 S1200"), ["TOOL CALL 5 Z S1200"]);
        assert_eq!(
            klartext_blocks("S1200 M3 M8"),
            ["TOOL CALL Z S1200", "M3", "M8"]
        );
        assert_eq!(klartext_blocks("M9"), ["M9"]);
        let carried = [
            (1, "T5 M6 S1200".to_owned()),
            (4, "M3".to_owned()),
            (9, "M5".to_owned()),
        ];
        let text = written(None, &carried, FeedStyle::DegreesPerMinute);
        let order: Vec<&str> = text
            .lines()
            .filter_map(|l| l.split_once(' ').map(|(_, rest)| rest))
            .filter(|l| l.starts_with("TOOL") || l.starts_with('M') || l.starts_with("L "))
            .map(|l| l.split(" X").next().unwrap_or(l))
            .collect();
        assert_eq!(
            order,
            ["TOOL CALL 5 Z S1200", "L", "M3", "L", "M5", "M30"],
            "{text}"
        );
        assert!(!text.contains("M6"), "{text}");
        // After the TOOL CALL the TNC adds the tool's length along Z: the
        // positions are written less the one length the output is for.
        assert!(
            text.contains(
                ";AFTER TOOL CALL THE TOOL'S LENGTH IS COMPENSATED: X Y Z THERE LESS 100.0000 MM"
            ),
            "{text}"
        );
        assert!(
            text.contains(" L X+12.3456 Y-5.0000 Z+0.0000 A+0.00000 C+90.00000 R0 FMAX\n"),
            "{text}"
        );
        assert!(
            text.contains(" L X+12.5000 Y-5.1000 Z-1.0000 A+1.50000"),
            "{text}"
        );
        // A TOOL CALL after the first move: the moves before it as they are.
        let late = [(4, "T5 M6".to_owned())];
        let text = written(None, &late, FeedStyle::DegreesPerMinute);
        assert!(text.contains(" L X+12.3456 Y-5.0000 Z+100.0000 "), "{text}");
        assert!(text.contains(" L X+12.5000 Y-5.1000 Z-1.0000 "), "{text}");
        // Only S: no tool called, no length.
        let speed = [(1, "S800".to_owned())];
        let text = written(None, &speed, FeedStyle::DegreesPerMinute);
        assert!(text.contains(" TOOL CALL Z S800\n"), "{text}");
        assert!(
            text.contains(" Z+100.0000 ") && text.contains(";NO TOOL CALL"),
            "{text}"
        );
        // Two lengths: which tool has which is not known, nothing taken off.
        let text = written_for(None, &carried, FeedStyle::DegreesPerMinute, &[100.0, 80.0]);
        assert!(text.contains(";WARNING: TOOL CALL SWITCHES ON"), "{text}");
        assert!(text.contains(" Z+100.0000 "), "{text}");
    }

    #[test]
    fn a_klartext_source_gives_its_carried_words_and_tool_length() {
        let source = "0 BEGIN PGM P1 MM\n1 ;FOR TOOL LENGTH 95.5000 MM ONLY: …\n\
                      2 TOOL CALL 5 Z S1000 ; M8 in a comment\n3 TOOL CALL Z S2000 F AUTO\n\
                      4 TOOL CALL \"MILL\" Z S3000\n5 L X+0 R0 FMAX M3\n6 M128\n7 M30\n\
                      8 END PGM P1 MM\n";
        assert_eq!(
            carried_words(source),
            vec![
                (3, "T5 M6 S1000".to_owned()),
                (4, "S2000".to_owned()),
                (5, "S3000".to_owned()),
                (6, "M3".to_owned()),
            ]
        );
        assert_eq!(header_tool_length(source), Some(95.5));
        // The header of a written Klartext program reads back.
        let text = written(None, &[], FeedStyle::DegreesPerMinute);
        assert_eq!(header_tool_length(&text), Some(100.0));
        assert!(carried_words(&text).is_empty(), "{text}");
        // G-code and SINUMERIK headers as before.
        assert_eq!(
            header_tool_length("%\n(FOR TOOL LENGTH 120.0000 MM ONLY: X)\n"),
            Some(120.0)
        );
        assert_eq!(
            header_tool_length(";FOR TOOL LENGTH 80.0000 MM ONLY: X\n"),
            Some(80.0)
        );
    }
}
