//! The operands of LinuxCNC's splines (g-code.adoc, G5: `I J P Q`, the
//! start and end control offsets; G5.1: `I J`, the control point's
//! offset).

use super::{Rules, Words};
use crate::alarm::{Alarm, Condition};

/// A spline block's control offsets, mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SplineData {
    /// I, J: the first control offset from the start point.
    pub i: Option<f64>,
    /// Along Y.
    pub j: Option<f64>,
    /// P, Q: the end point's control offset (G5).
    pub end: Option<[f64; 2]>,
}

impl Words {
    /// A spline's words (`name` G5 or G5.1; `cubic`: G5, which needs P
    /// and Q). An axis word beyond X and Y is refused.
    pub(crate) fn spline(
        &mut self,
        name: &str,
        cubic: bool,
        rules: &Rules,
    ) -> Result<SplineData, Alarm> {
        for &letter in &rules.letters[2.min(rules.axes)..rules.axes] {
            if let Some(word) = self.peek(letter) {
                return Err(self.alarm(
                    Condition::WordNotUsed,
                    Some(word.span),
                    format!(
                        "{name} moves X and Y only: {} is not a word of it",
                        char::from(letter)
                    ),
                ));
            }
        }
        let i = self.take(b'I').map(|w| rules.length(&w));
        let j = self.take(b'J').map(|w| rules.length(&w));
        let end = if cubic {
            let (Some(p), Some(q)) = (self.take(b'P'), self.take(b'Q')) else {
                return Err(self.alarm(
                    Condition::CycleDataMissing,
                    None,
                    "G5 needs both P and Q, the end point's control offset".into(),
                ));
            };
            Some([rules.length(&p), rules.length(&q)])
        } else {
            None
        };
        Ok(SplineData { i, j, end })
    }
}
