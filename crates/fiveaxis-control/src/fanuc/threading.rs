//! The operands of LinuxCNC's spindle-synchronized motion (G33, G33.1:
//! K, I) and threading cycle (G76: P Z I J K R Q H E L; g-code.adoc).

use fiveaxis_gcode::Span;

use super::{Rules, Words};
use crate::alarm::{Alarm, Condition};

/// G76's data, lengths in mm (I, J, K already halved in diameter mode).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ThreadData {
    /// P: the distance per revolution.
    pub pitch: f64,
    /// Z: the end of the thread as written (absolute or incremental).
    pub z: f64,
    /// I: the thread peak's offset from the drive line.
    pub peak_offset: f64,
    /// J: the first cut's depth.
    pub first: f64,
    /// Where J is written.
    pub first_span: Span,
    /// K: the full thread depth.
    pub full: f64,
    /// R: the depth degression (1 or more).
    pub degression: f64,
    /// Q: the compound slide angle, degrees.
    pub compound: f64,
    /// H: the spring passes.
    pub spring: u32,
    /// E: the taper length along the drive line, and where it is written.
    pub taper: Option<(f64, Span)>,
    /// L: which ends taper (1 entry, 2 exit, 3 both).
    pub ends: u32,
}

impl Words {
    /// The distance per revolution, mm: `letter` (K of G33 / G33.1, P of
    /// G76), positive.
    fn pitch(&mut self, name: &str, letter: u8, rules: &Rules) -> Result<f64, Alarm> {
        let Some(word) = self.take(letter) else {
            return Err(self.alarm(
                Condition::CycleDataMissing,
                None,
                format!(
                    "{name} needs {}, the distance per revolution",
                    char::from(letter)
                ),
            ));
        };
        let pitch = rules.length(&word);
        if !(pitch > 0.0 && pitch.is_finite()) {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(word.span),
                format!(
                    "{name}: {}{} must be positive",
                    char::from(letter),
                    word.value
                ),
            ));
        }
        Ok(pitch)
    }

    /// G33 / G33.1 (`name`): the distance per revolution K; F is refused
    /// (the feed is K per revolution).
    pub(crate) fn sync_pitch(&mut self, name: &str, rules: &Rules) -> Result<f64, Alarm> {
        if let Some(f) = self.peek(b'F') {
            return Err(self.alarm(
                Condition::WordNotUsed,
                Some(f.span),
                format!("{name} takes no F: the feed is K per revolution of the spindle"),
            ));
        }
        self.pitch(name, b'K', rules)
    }

    /// Whether G33 / G33.1's K is written.
    pub(crate) fn has_pitch(&self) -> bool {
        self.has(b'K')
    }

    /// G33.1's I: the retract's speed multiplier (1 or more).
    pub(crate) fn retract_multiplier(&mut self) -> f64 {
        self.take(b'I').map_or(1.0, |w| w.value.max(1.0))
    }

    /// G76's data; `diameter`: lathe diameter mode (G7), where I, J and K
    /// are diameters; `max_passes` bounds H.
    pub(crate) fn thread_data(
        &mut self,
        rules: &Rules,
        diameter: bool,
        max_passes: u32,
    ) -> Result<ThreadData, Alarm> {
        for letter in [b'X', b'Y', b'A', b'B', b'C', b'U', b'V', b'W'] {
            if let Some(word) = self.peek(letter) {
                return Err(self.alarm(
                    Condition::WordNotUsed,
                    Some(word.span),
                    format!(
                        "G76 takes Z only: {} is not a word of it",
                        char::from(letter)
                    ),
                ));
            }
        }
        let required = |w: &Self, letter: u8| {
            w.peek(letter).ok_or_else(|| {
                w.alarm(
                    Condition::CycleDataMissing,
                    None,
                    format!("G76 needs {}", char::from(letter)),
                )
            })
        };
        let pitch = self.pitch("G76", b'P', rules)?;
        let z_word = required(self, b'Z')?;
        let i_word = required(self, b'I')?;
        let j_word = required(self, b'J')?;
        let k_word = required(self, b'K')?;
        for letter in [b'Z', b'I', b'J', b'K'] {
            self.take(letter);
        }
        let scale = if diameter { 0.5 } else { 1.0 };
        let first = rules.length(&j_word) * scale;
        let full = rules.length(&k_word) * scale;
        if first <= 0.0 {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(j_word.span),
                "G76: J, the first cut's depth, must be greater than 0".into(),
            ));
        }
        if full < 0.0 {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(k_word.span),
                "G76: K, the full thread depth, cannot be negative".into(),
            ));
        }
        let degression = match self.take(b'R') {
            Some(w) if w.value < 1.0 => {
                return Err(self.alarm(
                    Condition::ValueOutOfRange,
                    Some(w.span),
                    format!("G76: the depth degression R{} is below 1", w.value),
                ));
            }
            Some(w) => w.value,
            None => 1.0,
        };
        let compound = self.take(b'Q').map_or(0.0, |w| w.value);
        let spring = match self.take(b'H') {
            Some(w) if w.value < 0.0 => {
                return Err(self.alarm(
                    Condition::ValueOutOfRange,
                    Some(w.span),
                    "G76: H, the spring passes, cannot be negative".into(),
                ));
            }
            Some(w) if w.value > f64::from(max_passes) => {
                return Err(self.alarm(
                    Condition::ValueOutOfRange,
                    Some(w.span),
                    format!(
                        "G76: H{} asks for more than {max_passes} spring passes",
                        w.value
                    ),
                ));
            }
            Some(w) => w.value.round() as u32,
            None => 0,
        };
        let taper = self.take(b'E').map(|w| (rules.length(&w), w.span));
        let ends = match self.take(b'L') {
            Some(w) => self.integer(&w, 3)?,
            None => 0,
        };
        Ok(ThreadData {
            pitch,
            z: rules.length(&z_word),
            peak_offset: rules.length(&i_word) * scale,
            first,
            first_span: j_word.span,
            full,
            degression,
            compound,
            spring,
            taper,
            ends,
        })
    }
}
