//! The output program: FANUC-style text (G93 inverse time feed, absolute
//! machine positions in G54 with length compensation and TCPC off), or,
//! for a machine whose control is a SINUMERIK, the same in the Siemens
//! form: a `%_N_NAME_MPF` header, `;` comments, `D0` instead of `G49` and
//! `TRAFOOF` instead of the cancels of TCPC and the tilted plane (ONE
//! p43–45; brief §1, §4).
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
pub fn carried_words(text: &str) -> Vec<(u32, String)> {
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

/// Writes the whole program.
pub fn write(machine: &Machine, post: &Post, options: &PostOptions, header: &Header<'_>) -> String {
    let quantum = Quantum::for_tolerance(options.tolerance);
    let siemens = machine.control == Control::Sinumerik;
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
        if siemens {
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
            let keeps_time = options.feed != FeedStyle::Programmed;
            let wanted = if keeps_time && minutes + drift > 0.0 {
                minutes + drift
            } else {
                *minutes
            };
            if let Some(f) = options.feed.f_word(machine, &from, to, wanted, *feed) {
                let mut text = String::new();
                feed_text(&mut text, f);
                let written: f64 = text.parse().unwrap_or(f);
                let taken = match options.feed {
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
    if siemens {
        // The transfer header names the program (`%_N_NAME_MPF`).
        let name = header
            .number
            .map_or("FIVEAXIS".to_owned(), |n| format!("P{n:04}"));
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
    let feed_text = match options.feed {
        FeedStyle::InverseTime => "feed G93 inverse time, tip feed kept".to_owned(),
        FeedStyle::DegreesPerMinute => {
            "feed G94 per block from the composite travel, degrees as mm, tip feed kept".to_owned()
        }
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
            "positions: machine axes minus G54 X{:.4} Y{:.4} Z{:.4}",
            options.origin[0], options.origin[1], options.origin[2]
        ),
    );
    // The feed mode stays on throughout: positioning does not read F.
    if siemens {
        let _ = writeln!(
            out,
            "G71 G17 G90 G40 G54 D0 TRAFOOF {}",
            options.feed.g_code()
        );
    } else {
        let _ = writeln!(
            out,
            "G21 G17 G90 G40 G49 G69 G80 G54 {}",
            options.feed.g_code()
        );
    }
    let mut carried = header.carried.iter().peekable();
    for (m, word) in post.moves.iter().zip(&words) {
        let line = match m {
            Move::Rapid { line, .. } | Move::Feed { line, .. } => Some(*line),
            Move::Note(_) => None,
        };
        if let Some(line) = line {
            while let Some((_, w)) = carried.next_if(|(l, _)| *l <= line) {
                out.push_str(w);
                out.push('\n');
            }
        }
        match m {
            Move::Rapid { to, .. } => {
                out.push_str("G0");
                axes(&mut out, machine, to, options, &quantum);
            }
            Move::Feed { to, .. } => {
                let Some(f) = word else {
                    // No axis moves (G94 styles): nothing to write.
                    continue;
                };
                out.push_str("G1");
                axes(&mut out, machine, to, options, &quantum);
                out.push_str(" F");
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
    if options.feed == FeedStyle::InverseTime {
        out.push_str("G94\n");
    }
    for (_, w) in carried {
        out.push_str(w);
        out.push('\n');
    }
    if siemens {
        out.push_str("M30\n");
    } else {
        out.push_str("M30\n%\n");
    }
    out
}

/// Every axis word of a machine position.
fn axes(out: &mut String, machine: &Machine, to: &Joints, options: &PostOptions, q: &Quantum) {
    for (i, name) in machine.axis_names().enumerate() {
        let linear = machine.linear.len();
        let (value, decimals) = if i < linear {
            (to[i] - work_offset(&options.origin, i), q.length_decimals)
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
        number(out, value, decimals as usize);
    }
}

/// A number with `decimals` decimals, no `-0`.
fn number(out: &mut String, value: f64, decimals: usize) {
    let at = out.len();
    let _ = write!(out, "{value:.decimals$}");
    let text = &out[at..];
    if text.starts_with('-') && text[1..].bytes().all(|b| b == b'0' || b == b'.') {
        out.remove(at);
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
/// …`, the first length when it names several).
pub fn header_tool_length(text: &str) -> Option<f64> {
    let line = text.lines().take(32).find_map(|l| {
        l.strip_prefix("(FOR TOOL LENGTH ")
            .or_else(|| l.strip_prefix(";FOR TOOL LENGTH "))
    })?;
    line.split([' ', ','])
        .next()?
        .parse()
        .ok()
        .filter(|l: &f64| l.is_finite())
}
