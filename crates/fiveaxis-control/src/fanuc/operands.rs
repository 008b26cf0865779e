//! The operands of the functions every FANUC-family block can call: the
//! axis values, F, S, T, D, H, the dwell, the subprogram call, the
//! reference position number, the modes that take a number (G05.1 Q,
//! G64 P Q), the length offsets given in the block (LinuxCNC G43.1 /
//! G43.2) and the I, J type vector of cutter compensation C.

use fiveaxis_gcode::{Block, Code, Span, Word};
use fiveaxis_machine::{MAX_AXES, MAX_TOOL_OFFSET};

use super::{Rules, Words};
use crate::alarm::{Alarm, Condition};

/// The addresses of a circle's centre (and of vectors) along X, Y, Z.
pub(crate) const CENTER_LETTERS: [u8; 3] = [b'I', b'J', b'K'];

/// The highest Haas program number (O99999: five digits).
pub const MAX_HAAS_PROGRAM: u32 = 99_999;

/// An additional tool length offset (LinuxCNC G43.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum AddedLength {
    /// The length of this tool of the tool table (`G43.2 H`).
    Tool(u32, Span),
    /// This length, mm (`G43.2 Z`).
    Value(f64),
}

/// The addresses counted in [`words_without_point`] besides the machine's
/// axes: arc centres and radius, the R level of canned cycles (lengths).
const LENGTH_ADDRESSES: [u8; 4] = [b'I', b'J', b'K', b'R'];

/// How many of `block`'s axis words (`axes`: the machine's axis letters)
/// and I, J, K, R are written without a decimal point and are not 0 (zero
/// is zero in any unit): the words a control with decimal point input off
/// reads in least input increments.
pub(crate) fn words_without_point(block: &Block, axes: &[u8]) -> u64 {
    block
        .words
        .iter()
        .filter(|w| {
            !w.decimal_point
                && w.value != 0.0
                && (axes.contains(&w.letter) || LENGTH_ADDRESSES.contains(&w.letter))
        })
        .count() as u64
}

/// Whether `block` is a Haas G47 engraving block (the runner passes it the
/// serial number `#599`).
pub(crate) fn engraves(block: &Block) -> bool {
    block
        .words
        .iter()
        .any(|w| w.letter == b'G' && w.value == 47.0)
}

impl Words {
    /// A program-number line (`O…`) is a label; Haas checks its number
    /// (O00001 to O99999, without a decimal point).
    pub(crate) fn program_number(&mut self, haas: bool) -> Result<(), Alarm> {
        let Some(word) = self.take(b'O') else {
            return Ok(());
        };
        if !haas {
            return Ok(());
        }
        let number = self.integer(&word, MAX_HAAS_PROGRAM)?;
        if number == 0 {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(word.span),
                format!("O0: Haas program numbers are O00001 to O{MAX_HAAS_PROGRAM}"),
            ));
        }
        Ok(())
    }

    /// The block's axis values by joint index, in mm or degrees, marked
    /// used: the angle of polar coordinates and the diameter of LinuxCNC
    /// G7 as the rules say.
    pub(crate) fn axes(&mut self, rules: &Rules) -> [Option<f64>; MAX_AXES] {
        let mut targets = [None; MAX_AXES];
        for (i, target) in targets.iter_mut().enumerate().take(rules.axes) {
            if let Some(word) = self.take(rules.letters[i]) {
                *target = Some(if rules.polar_axis == Some(i) {
                    rules.angle(&word)
                } else if i == 0 && rules.diameter {
                    // LinuxCNC G7: X is a diameter (g-code.adoc, G7).
                    rules.axis_value(i, &word) / 2.0
                } else {
                    rules.axis_value(i, &word)
                });
            }
        }
        targets
    }

    /// The block's axis values by joint index, in mm or degrees, as
    /// written (no polar or diameter reading), marked used.
    pub(crate) fn axis_values(&mut self, rules: &Rules) -> [Option<f64>; MAX_AXES] {
        let mut values = [None; MAX_AXES];
        for (i, value) in values.iter_mut().enumerate().take(rules.axes) {
            *value = self
                .take(rules.letters[i])
                .map(|word| rules.axis_value(i, &word));
        }
        values
    }

    /// Where the word of axis `i` is written, if the block has one.
    pub(crate) fn axis_span(&self, rules: &Rules, i: usize) -> Option<Span> {
        self.peek(rules.letters[i]).map(|w| w.span)
    }

    /// The first axis from joint `from` on that the block names, and
    /// where its word is.
    pub(crate) fn first_axis(&self, rules: &Rules, from: usize) -> Option<(usize, Span)> {
        (from..rules.axes).find_map(|i| self.axis_span(rules, i).map(|span| (i, span)))
    }

    /// LinuxCNC `G43.1 Z` (`name` is the code, for the alarms): the tool
    /// length offset, taken out of the block (the word is not a move).
    /// Another axis word is refused: the kernel's length offset lies
    /// along the tool.
    pub(crate) fn tool_axis_offset(
        &mut self,
        span: Span,
        name: &str,
        rules: &Rules,
    ) -> Result<f64, Alarm> {
        let letter = b'Z';
        for &other in &rules.letters[..rules.axes] {
            if other != letter
                && let Some(word) = self.peek(other)
            {
                return Err(self.alarm(
                    Condition::WordNotUsed,
                    Some(word.span),
                    format!(
                        "{name} {}: the kernel's tool length offset lies along the tool ({}) only",
                        char::from(other),
                        char::from(letter)
                    ),
                ));
            }
        }
        let Some(word) = self.remove(letter) else {
            return Err(self.alarm(
                Condition::NoDataAfterAddress,
                Some(span),
                format!(
                    "{name} needs {}, the tool length offset",
                    char::from(letter)
                ),
            ));
        };
        Ok(rules.length(&word))
    }

    /// LinuxCNC `G43.2 H-` or `G43.2 Z-`: H and an axis word together,
    /// or neither, are the manual's errors.
    pub(crate) fn added_length(&mut self, span: Span, rules: &Rules) -> Result<AddedLength, Alarm> {
        let h = self.take(b'H');
        if let (Some(h), true) = (&h, self.has(b'Z')) {
            return Err(self.alarm(
                Condition::WordNotUsed,
                Some(h.span),
                "G43.2: H and axis offsets together".into(),
            ));
        }
        match h {
            Some(h) => Ok(AddedLength::Tool(
                self.integer(&h, MAX_TOOL_OFFSET)?,
                h.span,
            )),
            None => self
                .tool_axis_offset(span, "G43.2", rules)
                .map(AddedLength::Value),
        }
    }

    /// LinuxCNC `G64 P- <Q->`: the blending tolerance P and the naive CAM
    /// tolerance Q (Q defaults to P), mm; none without P.
    pub(crate) fn blend_tolerance(&mut self, rules: &Rules) -> Result<Option<[f64; 2]>, Alarm> {
        let p = self.take(b'P').map(|word| rules.length(&word));
        let q = self.take(b'Q').map(|word| rules.length(&word));
        for (letter, value) in [('P', p), ('Q', q)] {
            if value.is_some_and(|v| v < 0.0) {
                return Err(self.alarm(
                    Condition::ValueOutOfRange,
                    None,
                    format!("G64 {letter} must not be negative"),
                ));
            }
        }
        Ok(p.map(|p| [p, q.unwrap_or(p)]))
    }

    /// The mode number of G05.1 (Q0 / Q1 / Q3), G05 (P0 / P10000) or G08
    /// (P0 / P1).
    pub(crate) fn accuracy_mode(&mut self, code: Code, span: Span) -> Result<u32, Alarm> {
        let (letter, allowed): (u8, &[u32]) = match (code.major, code.minor) {
            (5, 1) => (b'Q', &[0, 1, 3]),
            (5, _) => (b'P', &[0, 10_000]),
            _ => (b'P', &[0, 1]),
        };
        let written = allowed
            .iter()
            .map(|v| format!("{}{v}", char::from(letter)))
            .collect::<Vec<_>>()
            .join(", ");
        let Some(word) = self.take(letter) else {
            return Err(self.alarm(
                Condition::NoDataAfterAddress,
                Some(span),
                format!("G{code} needs {written}"),
            ));
        };
        let value = self.integer(&word, 99_999_999)?;
        if !allowed.contains(&value) {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(word.span),
                format!(
                    "G{code} {}{value} is not a mode of this control: {written}",
                    char::from(letter)
                ),
            ));
        }
        Ok(value)
    }

    /// Whether the block gives one of F, S, T, D.
    pub(crate) fn has_values(&self) -> bool {
        self.has_any(b"FSTD")
    }

    /// F: the feed, times `scale` (inch to mm), and where it is written.
    pub(crate) fn feed(&mut self, scale: f64) -> Option<(f64, Span)> {
        self.take(b'F').map(|word| (word.value * scale, word.span))
    }

    /// Whether the block gives a feed.
    pub(crate) fn has_feed(&self) -> bool {
        self.has(b'F')
    }

    /// Where F is written, if the block has it.
    pub(crate) fn feed_span(&self) -> Option<Span> {
        self.peek(b'F').map(|w| w.span)
    }

    /// S: the spindle speed, rev/min; `real`: a real number not negative
    /// (LinuxCNC, other-code.adoc: an error "if the S number is
    /// negative"), else an integer up to 999 999.
    pub(crate) fn spindle_speed(&mut self, real: bool) -> Result<Option<f64>, Alarm> {
        let Some(word) = self.take(b'S') else {
            return Ok(None);
        };
        if !real {
            return Ok(Some(f64::from(self.integer(&word, 999_999)?)));
        }
        if word.value < 0.0 {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(word.span),
                "the S number is negative".into(),
            ));
        }
        Ok(Some(word.value))
    }

    /// T: the tool number, and where it is written.
    pub(crate) fn tool_number(&mut self) -> Result<Option<(u32, Span)>, Alarm> {
        let Some(word) = self.take(b'T') else {
            return Ok(None);
        };
        Ok(Some((self.integer(&word, 99_999_999)?, word.span)))
    }

    /// An offset number (H, D): 0 to the offset memory's end.
    pub(crate) fn offset_number(&self, word: &Word) -> Result<u32, Alarm> {
        if word.decimal_point || (0.0..=f64::from(MAX_TOOL_OFFSET)).contains(&word.value) {
            return self.integer(word, MAX_TOOL_OFFSET);
        }
        Err(self.alarm(
            Condition::IllegalOffsetNumber,
            Some(word.span),
            format!(
                "offset number {}{} is outside the offset memory: numbers are 0 to {MAX_TOOL_OFFSET}",
                char::from(word.letter),
                word.value
            ),
        ))
    }

    /// D: the radius offset number.
    pub(crate) fn radius_offset(&mut self) -> Result<Option<u32>, Alarm> {
        let word = self.take(b'D');
        self.offset_of(word)
    }

    /// The offset number of `word`, if there is one.
    fn offset_of(&self, word: Option<Word>) -> Result<Option<u32>, Alarm> {
        word.map(|w| self.offset_number(&w)).transpose()
    }

    /// Whether the block gives a length offset number (H).
    pub(crate) fn has_length_offset(&self) -> bool {
        self.has(b'H')
    }

    /// H: the length offset number, checked but not marked used.
    pub(crate) fn peek_length_offset(&self) -> Result<Option<u32>, Alarm> {
        self.offset_of(self.peek(b'H'))
    }

    /// H: the length offset number.
    pub(crate) fn length_offset(&mut self) -> Result<Option<u32>, Alarm> {
        let word = self.take(b'H');
        self.offset_of(word)
    }

    /// Whether the block writes a centre word of plane axes `p` or `q`.
    pub(crate) fn has_plane_vector(&self, p: usize, q: usize) -> bool {
        self.has(CENTER_LETTERS[p]) || self.has(CENTER_LETTERS[q])
    }

    /// The centre words of plane axes `p` and `q` as a direction (cutter
    /// compensation C's I, J type vector), mm; none when neither is
    /// written, an alarm when both are 0.
    pub(crate) fn plane_vector(
        &mut self,
        p: usize,
        q: usize,
        span: Span,
        rules: &Rules,
    ) -> Result<Option<[f64; 2]>, Alarm> {
        if !self.has_plane_vector(p, q) {
            return Ok(None);
        }
        let i = self
            .take(CENTER_LETTERS[p])
            .map_or(0.0, |w| rules.length(&w));
        let j = self
            .take(CENTER_LETTERS[q])
            .map_or(0.0, |w| rules.length(&w));
        if i == 0.0 && j == 0.0 {
            return Err(self.alarm(
                Condition::ToolVectorZero,
                Some(span),
                format!(
                    "the I, J type vector {}0 {}0 gives no direction",
                    char::from(CENTER_LETTERS[p]),
                    char::from(CENTER_LETTERS[q])
                ),
            ));
        }
        Ok(Some([i, j]))
    }

    /// M98 `P… L…`: the program number and how many times. FANUC also
    /// reads a P of more than four digits as four digits of repetitions,
    /// then four of program number.
    pub(crate) fn program_call(&mut self) -> Result<(u32, u32), Alarm> {
        let Some(p) = self.take(b'P') else {
            return Err(self.alarm(
                Condition::SubprogramNumberMissing,
                None,
                "M98 needs P, the number of the program to call".into(),
            ));
        };
        let p = self.integer(&p, 99_999_999)?;
        let (mut repeats, program) = if p > 9999 {
            (p / 10_000, p % 10_000)
        } else {
            (1, p)
        };
        if let Some(l) = self.take(b'L') {
            repeats = self.integer(&l, 9999)?;
        }
        Ok((program, repeats))
    }

    /// G30 `P`: the reference position (2 to 4; 2 when not written).
    pub(crate) fn reference_number(&mut self) -> Result<u32, Alarm> {
        match self.take(b'P') {
            Some(word) => self.integer(&word, 4),
            None => Ok(2),
        }
    }

    /// Where G30's P is written.
    pub(crate) fn reference_span(&self) -> Option<Span> {
        self.peek(b'P').map(|w| w.span)
    }

    /// G04: the dwell, seconds: P in ms (Haas: seconds with a decimal
    /// point; LinuxCNC: seconds) or X in s.
    pub(crate) fn dwell(
        &mut self,
        span: Span,
        rules: &Rules,
        p_seconds_with_point: bool,
        p_seconds: bool,
        max_seconds: f64,
    ) -> Result<f64, Alarm> {
        if let Some(word) = self.take(b'P') {
            let ms = self.dwell_ms(&word, p_seconds_with_point, p_seconds)?;
            return Ok(f64::from(ms) / 1000.0);
        }
        let Some(word) = self.take(b'X') else {
            return Err(self.alarm(
                Condition::NoDataAfterAddress,
                Some(span),
                "G04 needs P (ms) or X (s)".into(),
            ));
        };
        let seconds = rules.seconds(&word);
        if !(0.0..=max_seconds).contains(&seconds) {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(word.span),
                format!("dwell time X{} is outside 0 to {max_seconds} s", word.value),
            ));
        }
        Ok(seconds)
    }
}

/// The words LinuxCNC's I/O and user M codes take (m-code.adoc: M62–M65
/// P; M66 P E L Q; M67/M68 E Q; M61 Q; M100–M199 P Q; M50–M53 P).
const LINUXCNC_IO_WORDS: &[u8] = b"PELQ";

impl Words {
    /// The block's M codes, in the order written.
    pub(crate) fn m_codes(&self) -> &[(Code, Span)] {
        &self.m[..self.m_len]
    }

    /// M99 `P`: the sequence number to return to.
    pub(crate) fn return_sequence(&mut self) -> Result<Option<u32>, Alarm> {
        match self.take(b'P') {
            Some(word) => Ok(Some(self.integer(&word, 99_999)?)),
            None => Ok(None),
        }
    }

    /// LinuxCNC M61 `Q`: the tool now in the spindle.
    pub(crate) fn spindle_tool(&mut self, span: Span, max: u32) -> Result<u32, Alarm> {
        let Some(q) = self.take(b'Q') else {
            return Err(self.alarm(
                Condition::NoDataAfterAddress,
                Some(span),
                "M61 needs Q, the tool number now in the spindle".into(),
            ));
        };
        self.integer(&q, max)
    }

    /// LinuxCNC's I/O M codes: their words are read (I/O numbers and
    /// values, nothing the kernel simulates).
    pub(crate) fn io_words(&mut self) {
        for &letter in LINUXCNC_IO_WORDS {
            let _ = self.take(letter);
        }
    }

    /// LinuxCNC `M19 R- Q- P-` (m-code.adoc, M19): the angle R (0–360),
    /// the time Q allowed (not negative), the direction P (0, 1, 2),
    /// checked; the spindle stops at the angle and no axis moves.
    pub(crate) fn spindle_orientation(&mut self) -> Result<(), Alarm> {
        if let Some(r) = self.take(b'R')
            && !(0.0..=360.0).contains(&r.value)
        {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(r.span),
                format!(
                    "M19 R{}: the orientation angle is 0 to 360 degrees",
                    r.value
                ),
            ));
        }
        if let Some(q) = self.take(b'Q')
            && q.value < 0.0
        {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(q.span),
                format!("M19 Q{}: the time allowed cannot be negative", q.value),
            ));
        }
        if let Some(p) = self.take(b'P') {
            self.integer(&p, 2)?;
        }
        Ok(())
    }
}
