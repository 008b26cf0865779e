//! The words of one block, sorted by address, with a record of which ones
//! the block's functions used: a word that no function uses stops the
//! program instead of being silently ignored.

use fiveaxis_gcode::{Block, Code, Span, Word};
use fiveaxis_machine::{Control, Machine};

use crate::alarm::{Alarm, Condition};

/// Most G codes in one block.
pub const MAX_G_CODES: usize = 16;
/// Most M codes in one block the kernel reads (the control's own limit is
/// checked separately).
pub const MAX_M_CODES: usize = 8;

/// A block's words, by address letter.
#[derive(Debug)]
pub struct Words {
    /// Words by letter; only those whose bit is set in `present` belong to
    /// the current block (the rest are left over, never read).
    by_letter: [Option<Word>; 26],
    present: u32,
    used: u32,
    /// The addresses a block may have on this machine and control, by
    /// letter bit.
    addresses: u32,
    /// G codes in the order written.
    pub(super) g: [(Code, Span); MAX_G_CODES],
    /// How many of `g` are set.
    pub(super) g_len: usize,
    /// M codes in the order written.
    pub(super) m: [(Code, Span); MAX_M_CODES],
    /// How many of `m` are set.
    pub(super) m_len: usize,
    /// 1-based line of the block.
    pub line: u32,
    control: Control,
}

fn index(letter: u8) -> usize {
    usize::from(letter.wrapping_sub(b'A')).min(25)
}

impl Words {
    /// An empty set for `machine` (its control and axes decide which
    /// addresses a block may have).
    pub fn new(machine: &Machine) -> Self {
        let blank = (Code::new(0, 0), Span::default());
        let control = machine.control;
        let addresses = (b'A'..=b'Z')
            .filter(|&l| {
                is_address(l, machine) || (control == Control::LinuxCnc && l == LINUXCNC_E)
            })
            .fold(0u32, |mask, l| mask | 1 << index(l));
        Self {
            addresses,
            by_letter: [None; 26],
            present: 0,
            used: 0,
            g: [blank; MAX_G_CODES],
            g_len: 0,
            m: [blank; MAX_M_CODES],
            m_len: 0,
            line: 0,
            control,
        }
    }

    /// An alarm for this block.
    pub fn alarm(&self, condition: Condition, span: Option<Span>, message: String) -> Alarm {
        Alarm {
            condition,
            code: condition.code(self.control),
            line: self.line,
            span,
            message,
        }
    }

    /// Sorts `block`'s words. Alarms on an address the machine does not
    /// have, a repeated address, and a G or M code that is not a code.
    pub fn load(&mut self, block: &Block) -> Result<(), Alarm> {
        self.present = 0;
        self.used = 0;
        self.g_len = 0;
        self.m_len = 0;
        self.line = block.line;
        for word in &block.words {
            let letter = word.letter;
            match letter {
                b'G' | b'M' => self.push_code(word)?,
                _ => {
                    let bit = 1 << index(letter);
                    if !letter.is_ascii_uppercase() || self.addresses & bit == 0 {
                        return Err(self.alarm(
                            Condition::ImproperAddress,
                            Some(word.span),
                            format!(
                                "address {} is not used by this control or machine",
                                char::from(letter)
                            ),
                        ));
                    }
                    if self.present & bit != 0 {
                        return Err(self.alarm(
                            Condition::DuplicateAddress,
                            Some(word.span),
                            format!("address {} appears twice in the block", char::from(letter)),
                        ));
                    }
                    self.present |= bit;
                    self.by_letter[index(letter)] = Some(*word);
                }
            }
        }
        Ok(())
    }

    /// The bits of `letters` in the masks of addresses.
    pub fn letter_mask(letters: impl IntoIterator<Item = u8>) -> u32 {
        letters.into_iter().fold(0, |mask, l| mask | 1 << index(l))
    }

    /// The block's G code when it has only addresses of `allowed` (by
    /// [`Words::letter_mask`]), no M code and at most one G code:
    /// `Some(None)` when it has no G code, `None` when it has more.
    pub(crate) fn plain_motion_code(&self, allowed: u32) -> Option<Option<Code>> {
        if self.present & !allowed != 0 || self.m_len != 0 || self.g_len > 1 {
            return None;
        }
        Some((self.g_len == 1).then(|| self.g[0].0))
    }

    fn push_code(&mut self, word: &Word) -> Result<(), Alarm> {
        let letter = char::from(word.letter);
        // M codes are whole numbers: a computed value (`M#1`) is rounded to
        // one, as FANUC rounds a variable's value to the address's least
        // increment (`M#1` with #1 = 2.6 is M3).
        let rounded = (letter == 'M' && word.computed)
            .then(|| word.value.round())
            .filter(|v| (0.0..=f64::from(u16::MAX)).contains(v))
            .map(|v| fiveaxis_gcode::Code::new(v as u16, 0));
        let Some(code) = rounded.or(word.code) else {
            let condition = if letter == 'G' {
                Condition::ImproperGCode
            } else {
                Condition::UnsupportedMCode
            };
            return Err(self.alarm(
                condition,
                Some(word.span),
                format!("{letter}{} is not a valid code", word.value),
            ));
        };
        let (list, len, max) = if letter == 'G' {
            (&mut self.g[..], &mut self.g_len, MAX_G_CODES)
        } else {
            (&mut self.m[..], &mut self.m_len, MAX_M_CODES)
        };
        if *len >= max {
            return Err(self.alarm(
                Condition::GCodeConflict,
                Some(word.span),
                format!("too many {letter} codes in one block"),
            ));
        }
        list[*len] = (code, word.span);
        *len += 1;
        Ok(())
    }

    /// Empties the set for a block of commands (`crate::command`) on
    /// `line`: it has no words.
    pub fn clear(&mut self, line: u32) {
        self.present = 0;
        self.used = 0;
        self.g_len = 0;
        self.m_len = 0;
        self.line = line;
    }

    /// The word with this letter, marking it used.
    pub(super) fn take(&mut self, letter: u8) -> Option<Word> {
        let word = self.peek(letter);
        if word.is_some() {
            self.used |= 1 << index(letter);
        }
        word
    }

    /// The word with this letter, marked used and taken out of the block,
    /// so that later functions do not see it (LinuxCNC's G43.1 axis
    /// words are offsets, not a move).
    pub(super) fn remove(&mut self, letter: u8) -> Option<Word> {
        let word = self.take(letter);
        self.present &= !(1 << index(letter));
        word
    }

    /// The word with this letter, without marking it used.
    pub(super) fn peek(&self, letter: u8) -> Option<Word> {
        if self.present & (1 << index(letter)) == 0 {
            return None;
        }
        self.by_letter[index(letter)]
    }

    /// The first word whose letter is not `letter`.
    pub(super) fn first_other_than(&self, letter: u8) -> Option<Word> {
        let others = self.present & !(1 << index(letter));
        (0..26)
            .find(|i| others & (1 << i) != 0)
            .and_then(|i| self.by_letter[i])
    }

    /// Whether a word with one of these letters is present.
    pub(super) fn has_any(&self, letters: &[u8]) -> bool {
        let mask = letters.iter().fold(0u32, |m, &l| m | 1 << index(l));
        self.present & mask != 0
    }

    /// Whether a word with this letter is present.
    pub(super) fn has(&self, letter: u8) -> bool {
        self.present & (1 << index(letter)) != 0
    }

    /// Alarms on the first word that no function of the block used.
    pub fn check_all_used(&self) -> Result<(), Alarm> {
        let unused = self.present & !self.used;
        if unused == 0 {
            return Ok(());
        }
        for (i, word) in self.by_letter.iter().enumerate() {
            if let Some(word) = word
                && unused & (1 << i) != 0
            {
                return Err(self.alarm(
                    Condition::WordNotUsed,
                    Some(word.span),
                    format!(
                        "address {} has no meaning in this block",
                        char::from(word.letter)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// A word's value as a non-negative integer (H, D, P, L, T, S numbers):
    /// alarms on a decimal point written on the tape, a sign or a value
    /// beyond `max`. A computed value (`P#1`, `H[#2+1]`) is rounded to the
    /// integer, half away from zero, as FANUC rounds a variable's value to
    /// the address's least increment.
    pub(super) fn integer(&self, word: &Word, max: u32) -> Result<u32, Alarm> {
        let letter = char::from(word.letter);
        if word.computed {
            let value = word.value.round();
            if !(0.0..=f64::from(max)).contains(&value) {
                return Err(self.alarm(
                    Condition::ValueOutOfRange,
                    Some(word.span),
                    format!(
                        "{letter}{} (the value of its variable or expression, rounded) is out of range 0 to {max}",
                        word.value
                    ),
                ));
            }
            return Ok(value as u32);
        }
        if word.decimal_point {
            return Err(self.alarm(
                Condition::DecimalPointNotAllowed,
                Some(word.span),
                format!("address {letter} takes an integer without a decimal point"),
            ));
        }
        if !(0.0..=f64::from(max)).contains(&word.value) {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(word.span),
                format!("{letter}{} is out of range 0 to {max}", word.value),
            ));
        }
        Ok(word.value as u32)
    }

    /// The dwell time of a P word (G04, G82, G88, G89), in milliseconds.
    /// With `seconds_with_point` (Haas) a P written with a decimal point is
    /// seconds, rounded to the millisecond (`P.05` is 50 ms), and one
    /// without is milliseconds; otherwise (FANUC) P is an integer of
    /// milliseconds and a decimal point is an alarm.
    /// With `always_seconds` (LinuxCNC) P is seconds however written.
    pub(super) fn dwell_ms(
        &self,
        word: &Word,
        seconds_with_point: bool,
        always_seconds: bool,
    ) -> Result<u32, Alarm> {
        if !(always_seconds || (seconds_with_point && word.decimal_point)) {
            return self.integer(word, MAX_DWELL_MS);
        }
        let ms = word.value * MS_PER_SECOND;
        if !(0.0..=f64::from(MAX_DWELL_MS)).contains(&ms) {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(word.span),
                format!(
                    "dwell P{} s is out of range 0 to {} s",
                    word.value,
                    f64::from(MAX_DWELL_MS) / MS_PER_SECOND
                ),
            ));
        }
        Ok(ms.round() as u32)
    }
}

/// Longest dwell, milliseconds (FANUC and Haas: 99 999.999 s).
pub const MAX_DWELL_MS: u32 = 99_999_999;
/// Milliseconds in a second.
const MS_PER_SECOND: f64 = 1000.0;

/// LinuxCNC's `E` word (the analog channel of M66–M68).
const LINUXCNC_E: u8 = b'E';

/// Whether `letter` is an address of the kernel on this machine.
fn is_address(letter: u8, machine: &Machine) -> bool {
    matches!(
        letter,
        b'F' | b'S' | b'T' | b'H' | b'D' | b'I' | b'J' | b'K' | b'R' | b'P' | b'L' | b'Q' | b'O'
    ) || machine.axis_index(char::from(letter)).is_some()
        // Haas: E of G187 (corner rounding).
        || (letter == b'E' && machine.control == fiveaxis_machine::Control::Haas)
}
