//! The operands of Haas G47 text engraving: P (what to engrave), J (the
//! height), I (the angle), E (the plunge feed), R (the return plane).

use fiveaxis_gcode::Span;

use super::{MM_PER_INCH, Rules, Words};
use crate::alarm::{Alarm, Condition};

/// What a G47 block gives besides its axis words.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct EngraveData {
    /// P: 0 the comment's text, 1 a serial number, 32–126 one character.
    pub p: u32,
    /// Where P is written.
    pub p_span: Span,
    /// J: the height of the text, mm.
    pub height: Option<f64>,
    /// I: the angle of the text's baseline, degrees (0 when left out).
    pub angle: f64,
    /// E: the plunge feed, mm/min.
    pub plunge: Option<f64>,
    /// R: the return plane, mm, and where it is written.
    pub r: Option<(f64, Span)>,
}

impl Words {
    /// G47's words; `first_char`: the lowest character code; `min_height`
    /// (mm) and `tolerance`: the smallest text.
    pub(crate) fn engraving(
        &mut self,
        span: Span,
        rules: &Rules,
        first_char: u32,
        min_height: f64,
        tolerance: f64,
    ) -> Result<EngraveData, Alarm> {
        let Some(p_word) = self.take(b'P') else {
            return Err(self.alarm(
                Condition::NoDataAfterAddress,
                Some(span),
                "G47 needs P: P0 the text of the block's comment, P1 a serial number, P32 to P126 one character".into(),
            ));
        };
        let p = self.integer(&p_word, 126)?;
        if p > 1 && p < first_char {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(p_word.span),
                format!(
                    "G47 P{p}: P is 0 (text), 1 (serial number) or an ASCII code from 32 to 126"
                ),
            ));
        }
        let height = match self.take(b'J') {
            Some(word) => {
                let j = rules.length(&word);
                if j.is_nan() || j < min_height - tolerance {
                    return Err(self.alarm(
                        Condition::ValueOutOfRange,
                        Some(word.span),
                        format!(
                            "G47 J{}: the height of the text is at least 0.001 inch ({min_height} mm)",
                            word.value
                        ),
                    ));
                }
                Some(j)
            }
            None => None,
        };
        let angle = match self.take(b'I') {
            Some(word) => {
                let a = rules.angle(&word);
                if !(-360.0..=360.0).contains(&a) {
                    return Err(self.alarm(
                        Condition::ValueOutOfRange,
                        Some(word.span),
                        format!("G47 I{}: the angle is -360 to 360 degrees", word.value),
                    ));
                }
                a
            }
            None => 0.0,
        };
        let plunge = match self.take(b'E') {
            Some(word) => {
                if word.value.is_nan() || word.value <= 0.0 {
                    return Err(self.alarm(
                        Condition::ValueOutOfRange,
                        Some(word.span),
                        format!("G47 E{}: the plunge feed must be more than 0", word.value),
                    ));
                }
                let scale = if rules.inch { MM_PER_INCH } else { 1.0 };
                Some(word.value * scale)
            }
            None => None,
        };
        let r = self.take(b'R').map(|w| (rules.length(&w), w.span));
        Ok(EngraveData {
            p,
            p_span: p_word.span,
            height,
            angle,
            plunge,
            r,
        })
    }
}
