//! Haas G47 text engraving (group 00), expanded into plunges, feeds and
//! retracts like a canned cycle: every elementary move is an ordinary
//! segment on the G47 block's line, so that the work offset, tool length
//! compensation and the soft limits apply to each of them.
//!
//! `G47 P… (TEXT) X Y Z R I J E F` (Haas NGC mill operator's manual, 2017,
//! "G47 Text Engraving (Group 00)", with "Engraving Sequential Serial
//! Numbers" and "Initial Serial Number"):
//!
//! * P0 engraves the text of the block's comment, P1 the serial number kept
//!   in macro variable `#599` (the comment gives the number of digits as
//!   `#` signs, `(####)`, and the number is one more after each
//!   engraving; digits instead, `G47 P1 (0001)`, set the number and
//!   engrave nothing), P32–P126 the one ASCII character of that code (the
//!   only way to engrave `(` and `)`).
//! * X, Y: the start of the text, the bottom left corner of its first
//!   character (the position where the tool stands when left out); Z the
//!   depth of the cut; R the return plane (where the tool stands when left
//!   out); I the angle of the baseline, −360° … 360°, counterclockwise from
//!   +X (0 when left out); J the height of the text, at least 0.001 in
//!   (1.0 in when left out); E the plunge feed, units/min (F when left
//!   out); F the engraving feed.
//!
//! The moves: rapid to X Y at the level where the tool stands, rapid to R;
//! then for each stroke of each character a rapid at R to its first point,
//! a plunge at E to Z, feeds at F along the stroke, a rapid back to R. The
//! tool ends at R above the end of the last stroke. The text lies in the
//! selected plane (G17: X Y, depth along Z; the manual shows G17).
//!
//! Decisions, also in `docs/functions.md`:
//!
//! * The font is the kernel's own (`engrave/font.rs`): Haas's is not
//!   published. J is the height of capitals and digits; a capital is 2/3 J
//!   wide and characters follow every J.
//! * In G91, X Y are an increment from where the tool stands, R the
//!   distance from the tool's level and Z the distance from R, as in the
//!   canned cycles. The distance mode stays as it was (the manual's
//!   internal switch to G91 and back is not visible to the program with
//!   Settings 29 and 73 off, as G47 requires).
//! * Blanks at both ends of the comment are not engraved; at most
//!   [`MAX_CHARACTERS`] characters; the serial number has 1 to
//!   [`MAX_SERIAL_DIGITS`] digits, shorter numbers filled with leading
//!   zeros, longer ones cut to their last digits (as the manual says);
//!   `#599` vacant is 0.
//! * Z is required (FX0130): the manual marks it optional but does not
//!   say which depth is cut without it.
//! * Refused (FX0133): cutter compensation, 3-D tool compensation, TCPC,
//!   program transforms (G68, G51, G51.1, G16), inverse time feed, rotary
//!   axis words in the G47 block.

pub(crate) mod font;

use fiveaxis_gcode::Span;
use fiveaxis_machine::Joints;

use super::Controller;
use crate::alarm::{Alarm, Condition};
use crate::fanuc::MM_PER_INCH;
use crate::modal::{Distance, FeedMode};
use crate::segment::{Motion, Segment};

use font::{ADVANCE, CAP_HEIGHT};

/// J when left out: 1.0 inch (the manual's default), mm.
pub const DEFAULT_HEIGHT: f64 = MM_PER_INCH;
/// The smallest J: 0.001 inch (the manual's minimum), mm.
pub const MIN_HEIGHT: f64 = 0.001 * MM_PER_INCH;
/// A J equal to the minimum up to this, mm, is the minimum (0.0254 mm
/// written in mm and 0.001 in converted differ by a rounding).
const HEIGHT_TOLERANCE: f64 = 1e-9;
/// Most characters one G47 engraves (a bound of the kernel's).
pub const MAX_CHARACTERS: usize = 256;
/// Most digits of a serial number (a bound of the kernel's).
pub const MAX_SERIAL_DIGITS: usize = 9;
/// The macro variable holding the next serial number (Haas #599).
pub const SERIAL_VARIABLE: u32 = 599;

/// The text one G47 engraves, without allocating: the block's comment, a
/// serial number or one character.
enum Text {
    /// The comment's bytes `start..end` (blanks trimmed).
    Comment(usize, usize),
    /// The digits of a serial number.
    Digits([u8; MAX_SERIAL_DIGITS], usize),
    /// One character (P32–P126).
    Char(u8),
    /// Nothing: P1 with digits sets the serial number.
    SetSerial,
}

impl Controller<'_> {
    /// G47: engraves the text (module documentation).
    pub(super) fn engrave(
        &mut self,
        span: Span,
        from: &Joints,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        self.engrave_allowed(span)?;
        let rules = self.rules();
        let data = self.fanuc.engraving(
            span,
            &rules,
            u32::from(font::FIRST),
            MIN_HEIGHT,
            HEIGHT_TOLERANCE,
        )?;
        let (p, p_word_span) = (data.p, data.p_span);
        let height = data.height.unwrap_or(DEFAULT_HEIGHT);
        let (angle, plunge, r_word) = (data.angle, data.plunge, data.r);
        let [pa, qa, n] = self.state.modal.plane.axes();
        let mut targets = self.axis_words();
        let text = self.engraving_text(p, p_word_span)?;
        if let Text::SetSerial = text {
            // `G47 P1 (0001)` sets the first serial number and engraves
            // nothing.
            return Ok(());
        }
        let Some(z) = targets[n].take() else {
            return Err(self.alarm(
                Condition::CycleDataMissing,
                Some(span),
                format!(
                    "G47 needs {}, the depth of the engraving",
                    char::from(self.axis_letters[n])
                ),
            ));
        };
        // Levels along the plane's normal, in the work coordinate system.
        let initial = from[n];
        let incremental = self.state.modal.distance == Distance::Incremental;
        let r_level = match r_word {
            Some((r, _)) if incremental => initial + r,
            Some((r, _)) => r,
            None => initial,
        };
        let z_level = if incremental { r_level + z } else { z };
        if z_level >= r_level {
            let letter = char::from(self.axis_letters[n]);
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                r_word.map(|(_, span)| span).or(Some(span)),
                format!(
                    "G47: the depth {letter}{z_level:.4} is not below the return plane R{r_level:.4}"
                ),
            ));
        }
        let (mut start, _) = self.end_point(from, &targets);
        start[n] = initial;
        let scale = height / f64::from(CAP_HEIGHT);
        let (sin, cos) = angle.to_radians().sin_cos();
        let at = |k: usize, (gx, gy): (i8, i8), level: f64| {
            let u = (k as f64 * f64::from(ADVANCE) + f64::from(gx)) * scale;
            let v = f64::from(gy) * scale;
            let mut q = start;
            q[pa] += u * cos - v * sin;
            q[qa] += u * sin + v * cos;
            q[n] = level;
            q
        };
        let mut cur = self.state.joints;
        let mut go =
            |this: &Self, motion: Motion, feed: Option<f64>, q: &Joints, out: &mut Vec<Segment>| {
                let end = this.machine_position(q);
                let before = out.len();
                this.push_line(motion, cur, end, out)?;
                if let (Some(f), Some(seg)) = (feed, out.get_mut(before)) {
                    seg.feed = Some(f);
                }
                cur = end;
                Ok::<(), Alarm>(())
            };
        go(self, Motion::Rapid, None, &start, out)?;
        let mut above = start;
        above[n] = r_level;
        go(self, Motion::Rapid, None, &above, out)?;
        let bytes: &[u8] = match &text {
            Text::Comment(a, b) => &self.comment[*a..*b],
            Text::Digits(d, len) => &d[..*len],
            Text::Char(c) => std::slice::from_ref(c),
            Text::SetSerial => &[],
        };
        for (k, &c) in bytes.iter().enumerate() {
            let Some(strokes) = font::glyph(c) else {
                continue;
            };
            for stroke in strokes {
                let mut points = stroke.points();
                let Some(first) = points.next() else {
                    continue;
                };
                go(self, Motion::Rapid, None, &at(k, first, r_level), out)?;
                let mut last = first;
                go(self, Motion::Linear, plunge, &at(k, first, z_level), out)?;
                for point in points {
                    go(self, Motion::Linear, None, &at(k, point, z_level), out)?;
                    last = point;
                }
                go(self, Motion::Rapid, None, &at(k, last, r_level), out)?;
            }
        }
        if let Text::Digits(..) = text {
            // The next part gets the next number.
            let serial = self.state.serial.unwrap_or(0.0);
            self.state.serial = Some(serial + 1.0);
        }
        Ok(())
    }

    /// G47's refusals: modes it does not combine with.
    fn engrave_allowed(&self, span: Span) -> Result<(), Alarm> {
        let rotary_word = self
            .fanuc
            .first_axis(&self.rules(), self.machine.linear.len())
            .is_some();
        let mode = if self.cutter.side.is_some() {
            "cutter compensation C (G41/G42)"
        } else if self.state.comp3d.active {
            "3-D tool compensation"
        } else if self.tcpc_type().is_some() {
            "tool centre point control (G234)"
        } else if self.state.frames.active() {
            "a program transform (G68, G51, G51.1, G16)"
        } else if self.state.modal.feed_mode == FeedMode::InverseTime {
            "inverse time feed (G93)"
        } else if rotary_word {
            "a block with a rotary axis word (turn the rotary axes in a block of their own)"
        } else {
            return Ok(());
        };
        Err(self.alarm(
            Condition::CycleNotAllowed,
            Some(span),
            format!("G47 (text engraving) cannot be used in {mode}"),
        ))
    }

    /// What G47 P`p` engraves; P1 also sets the serial number a `(1234)`
    /// comment gives.
    fn engraving_text(&mut self, p: u32, p_span: Span) -> Result<Text, Alarm> {
        if p >= u32::from(font::FIRST) {
            return Ok(Text::Char(p as u8));
        }
        let Some(comment_span) = self.comment_span else {
            let what = if p == 0 {
                "the text to engrave, (TEXT)"
            } else {
                "the digits of the serial number, (####), or its first value, (1234)"
            };
            return Err(self.alarm(
                Condition::CycleDataMissing,
                Some(p_span),
                format!("G47 P{p} needs a comment in its block: {what}"),
            ));
        };
        let start = self
            .comment
            .iter()
            .position(|b| !b.is_ascii_whitespace())
            .unwrap_or(self.comment.len());
        let end = self
            .comment
            .iter()
            .rposition(|b| !b.is_ascii_whitespace())
            .map_or(start, |i| i + 1);
        let body = &self.comment[start..end];
        if body.is_empty() {
            return Err(self.alarm(
                Condition::CycleDataMissing,
                Some(comment_span),
                format!("G47 P{p}: the comment is empty"),
            ));
        }
        if p == 0 {
            if body.len() > MAX_CHARACTERS {
                return Err(self.alarm(
                    Condition::ValueOutOfRange,
                    Some(comment_span),
                    format!(
                        "G47 P0: {} characters, more than {MAX_CHARACTERS} in one G47",
                        body.len()
                    ),
                ));
            }
            if let Some(&bad) = body
                .iter()
                .find(|&&b| !(font::FIRST..=font::LAST).contains(&b) || b == b'(' || b == b')')
            {
                let shown = if bad.is_ascii_graphic() {
                    format!("{:?}", char::from(bad))
                } else {
                    format!("byte 0x{bad:02X}")
                };
                let hint = if bad == b'(' || bad == b')' {
                    ": engrave parentheses with G47 P40 and P41"
                } else {
                    ": the characters are ASCII 32 to 126"
                };
                return Err(self.alarm(
                    Condition::ValueOutOfRange,
                    Some(comment_span),
                    format!("G47 P0 cannot engrave {shown}{hint}"),
                ));
            }
            return Ok(Text::Comment(start, end));
        }
        // P1: (####) gives the digits, (1234) the number and its digits.
        let digits = body.len();
        let all_hash = body.iter().all(|&b| b == b'#');
        let all_digits = body.iter().all(u8::is_ascii_digit);
        if !(all_hash || all_digits) || digits > MAX_SERIAL_DIGITS {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(comment_span),
                format!(
                    "G47 P1: the comment gives the digits as 1 to {MAX_SERIAL_DIGITS} # signs, (####), or the first number, (1234)"
                ),
            ));
        }
        if all_digits {
            let value = body
                .iter()
                .fold(0.0, |v, &b| v * 10.0 + f64::from(b - b'0'));
            self.state.serial = Some(value);
            return Ok(Text::SetSerial);
        }
        let serial = self.state.serial.unwrap_or(0.0);
        if !(serial >= 0.0 && serial.fract() == 0.0 && serial < 1e15) {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(p_span),
                format!(
                    "G47 P1: the serial number #{SERIAL_VARIABLE} = {serial} is not a whole number from 0"
                ),
            ));
        }
        // The last `digits` digits, leading zeros kept.
        let mut n = serial as u64;
        let mut out = [b'0'; MAX_SERIAL_DIGITS];
        for slot in out[..digits].iter_mut().rev() {
            *slot = b'0' + (n % 10) as u8;
            n /= 10;
        }
        Ok(Text::Digits(out, digits))
    }
}
