//! The operands of Haas's own codes: G187 smoothness, M97 local calls,
//! G154 / G110–G129 work offsets.

use fiveaxis_gcode::{Code, Span};
use fiveaxis_machine::MAX_HAAS_WORK;

use super::{Rules, Words};
use crate::alarm::{Alarm, Condition};
use crate::modal::WorkSelect;

impl Words {
    /// G187 `P1`–`P3 E`: the smoothness level (0 without P: the control's
    /// setting) and the corner rounding, mm (none without E).
    pub(crate) fn smoothness(&mut self, rules: &Rules) -> Result<(u8, Option<f64>), Alarm> {
        let level = match self.take(b'P') {
            Some(word) => {
                let p = self.integer(&word, 99)?;
                if !(1..=3).contains(&p) {
                    return Err(self.alarm(
                        Condition::ValueOutOfRange,
                        Some(word.span),
                        format!(
                            "G187 P{p}: the smoothness is P1 (rough), P2 (medium) or P3 (finish)"
                        ),
                    ));
                }
                p as u8
            }
            None => 0,
        };
        let rounding = match self.take(b'E') {
            Some(word) => {
                let e = rules.length(&word);
                if !(e.is_finite() && e > 0.0) {
                    return Err(self.alarm(
                        Condition::ValueOutOfRange,
                        Some(word.span),
                        format!(
                            "G187 E{}: the corner rounding must be more than 0",
                            word.value
                        ),
                    ));
                }
                Some(e)
            }
            None => None,
        };
        Ok((level, rounding))
    }

    /// M97 `P… L…`: the sequence number of the local subprogram and how
    /// many times (1 when L is left out).
    pub(crate) fn local_call(&mut self, span: Span) -> Result<(u32, u32), Alarm> {
        let Some(p) = self.take(b'P') else {
            return Err(self.alarm(
                Condition::SubprogramNumberMissing,
                Some(span),
                "M97 needs P, the sequence number (N) of the local subprogram".into(),
            ));
        };
        let sequence = self.integer(&p, 99_999)?;
        let repeats = match self.take(b'L') {
            Some(l) => self.integer(&l, 9999)?,
            None => 1,
        };
        Ok((sequence, repeats))
    }

    /// G154 P1–P99, G110–G129 (G154 P1–P20).
    pub(crate) fn haas_work(&mut self, code: Code, span: Span) -> Result<WorkSelect, Alarm> {
        if code.major != 154 {
            return Ok(WorkSelect::Haas((code.major - 109) as u8));
        }
        let Some(word) = self.take(b'P') else {
            return Err(self.alarm(
                Condition::NoDataAfterAddress,
                Some(span),
                format!("G154 needs P, the work offset P1 to P{MAX_HAAS_WORK}"),
            ));
        };
        let p = self.integer(&word, 99_999)?;
        if !(1..=MAX_HAAS_WORK).contains(&p) {
            return Err(self.alarm(
                Condition::IllegalOffsetNumber,
                Some(word.span),
                format!("G154 P{p}: the work offsets are P1 to P{MAX_HAAS_WORK}"),
            ));
        }
        Ok(WorkSelect::Haas(p as u8))
    }
}
