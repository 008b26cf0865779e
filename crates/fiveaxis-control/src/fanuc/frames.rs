//! The operands of the coordinate functions: the work offset a G54–G59 /
//! G54.1 block selects, G52 / G92 values, and the program transforms'
//! centres, factors and angle (G50.1 / G51.1 mirror, G51 scaling, G68
//! rotation in the plane).

use fiveaxis_gcode::{Code, Span};
use fiveaxis_machine::MAX_EXTENDED_WORK;

use super::{Rules, Words};
use crate::alarm::{Alarm, Condition};
use crate::modal::WorkSelect;

/// The addresses of the linear axes X, Y, Z.
const LINEAR: [u8; 3] = [b'X', b'Y', b'Z'];

/// G51's factors: one for every axis (P) or one per axis (I, J, K).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum ScaleFactors {
    /// None given.
    None,
    /// P: every axis.
    Uniform(f64),
    /// I, J, K (an omitted one is 1).
    PerAxis([f64; 3]),
}

impl Words {
    /// The work coordinate system a G54–G59 / G54.1 block selects
    /// (`code`; LinuxCNC's G59.1–G59.3 with `ngc`; Haas's G154 / G110–
    /// G129 with `haas`).
    pub(crate) fn work(&mut self, code: Code, span: Span, ngc: bool) -> Result<WorkSelect, Alarm> {
        if code.major >= 110 {
            return self.haas_work(code, span);
        }
        if ngc && code.major == 59 && code.minor > 0 {
            // LinuxCNC G59.1 / G59.2 / G59.3: systems 7–9, kept in the
            // offset memory of G54.1 P1–P3.
            return Ok(WorkSelect::Extended(code.minor));
        }
        let extended = code.minor == 1 || (code.major == 54 && self.has(b'P'));
        if !extended {
            return Ok(WorkSelect::Standard((code.major - 54) as u8));
        }
        let p = match self.take(b'P') {
            Some(word) => self.integer(&word, MAX_EXTENDED_WORK)?,
            // G54.1 without P selects P1 (as Mitsubishi documents).
            None => 1,
        };
        if p == 0 {
            return Err(self.alarm(
                Condition::IllegalOffsetNumber,
                Some(span),
                "G54.1 P0 does not exist".into(),
            ));
        }
        Ok(WorkSelect::Extended(p as u8))
    }

    /// The values of X, Y, Z, mm, taken.
    pub(crate) fn linear_values(&mut self, rules: &Rules) -> [Option<f64>; 3] {
        LINEAR.map(|l| self.take(l).map(|w| rules.length(&w)))
    }

    /// The value of linear axis `axis` (X 0, Y 1, Z 2), mm, taken.
    pub(crate) fn linear_value(&mut self, axis: usize, rules: &Rules) -> Option<f64> {
        self.take(LINEAR[axis]).map(|w| rules.length(&w))
    }

    /// A factor word of G51: without a decimal point in units of 0.001
    /// (P1000 = 1.0), with one as written.
    fn scale_factor(&self, letter: u8) -> Result<Option<f64>, Alarm> {
        let Some(word) = self.peek(letter) else {
            return Ok(None);
        };
        let value = if word.decimal_point {
            word.value
        } else {
            word.value * 0.001
        };
        if value == 0.0 || !value.is_finite() || value.abs() > 1.0e4 {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(word.span),
                format!(
                    "scaling factor {}{} is out of range: not 0, at most 10000 (P1000 = 1.0)",
                    char::from(letter),
                    word.value
                ),
            ));
        }
        Ok(Some(value))
    }

    /// G51's factors (`code` for the alarm: P and I, J, K together).
    pub(crate) fn scale_factors(&mut self, code: Code, span: Span) -> Result<ScaleFactors, Alarm> {
        let p = self.scale_factor(b'P')?;
        let ijk = [
            self.scale_factor(b'I')?,
            self.scale_factor(b'J')?,
            self.scale_factor(b'K')?,
        ];
        if p.is_some() && ijk.iter().any(Option::is_some) {
            return Err(self.alarm(
                Condition::GCodeConflict,
                Some(span),
                format!("G{code} takes either P or I, J, K, not both"),
            ));
        }
        for letter in [b'P', b'I', b'J', b'K'] {
            self.take(letter);
        }
        Ok(match p {
            Some(p) => ScaleFactors::Uniform(p),
            None if ijk.iter().any(Option::is_some) => {
                ScaleFactors::PerAxis(ijk.map(|k| k.unwrap_or(1.0)))
            }
            None => ScaleFactors::None,
        })
    }

    /// G68 `R`: the rotation angle, degrees.
    pub(crate) fn rotation_angle(&mut self, rules: &Rules) -> Option<f64> {
        self.take(b'R').map(|w| rules.angle(&w))
    }
}

impl Words {
    /// I, J, K as angles (the decimal-point rule, no unit change), taken.
    pub(crate) fn angle_vector(&mut self, rules: &Rules) -> [Option<f64>; 3] {
        super::CENTER_LETTERS.map(|l| self.take(l).map(|w| rules.angle(&w)))
    }

    /// The form `P` of a feature-frame definition (0 when left out).
    pub(crate) fn definition_form(&mut self) -> Result<u32, Alarm> {
        match self.take(b'P') {
            Some(word) => self.integer(&word, 9),
            None => Ok(0),
        }
    }

    /// The `Q` of a definition given block by block: required, 0 to
    /// `last` (`name`: the code, for the alarm).
    pub(crate) fn definition_step(
        &mut self,
        name: &str,
        span: Span,
        last: u32,
    ) -> Result<u32, Alarm> {
        match self.take(b'Q') {
            Some(word) => self.integer(&word, last),
            None => Err(self.alarm(
                Condition::FeatureDefinition,
                Some(span),
                format!("{name}: the block-by-block forms P2 and P3 number their blocks with Q"),
            )),
        }
    }

    /// Haas G268 `Q`: the order of the three turns as axis indices (X 0,
    /// Y 1, Z 2); `Q123` when left out.
    pub(crate) fn rotation_order(&mut self) -> Result<[usize; 3], Alarm> {
        let Some(word) = self.take(b'Q') else {
            return Ok([0, 1, 2]);
        };
        let q = self.integer(&word, 999)?;
        let digits = [q / 100, q / 10 % 10, q % 10];
        let mut seen = [false; 3];
        for d in digits {
            if (1..=3).contains(&d) {
                seen[d as usize - 1] = true;
            }
        }
        if !seen.iter().all(|s| *s) || (word.decimal_point && !word.computed) {
            return Err(self.alarm(
                Condition::FeatureDefinition,
                Some(word.span),
                format!(
                    "G268 Q{}: the order of rotation names each of 1 (X), 2 (Y) and 3 (Z) once, e.g. Q123",
                    word.value
                ),
            ));
        }
        Ok(digits.map(|d| d as usize - 1))
    }
}

impl Words {
    /// The G54.4 block: alone in its block with P, the data set number (0
    /// cancels, up to `max`); the number and where it is written.
    pub(crate) fn setup_error_set(&self, span: Span, max: u32) -> Result<(u32, Span), Alarm> {
        if let Some(word) = self.first_other_than(b'P') {
            return Err(self.alarm(
                Condition::SetupErrorNotAlone,
                Some(word.span),
                "G54.4 must be alone in its block (with P only)".into(),
            ));
        }
        if self.g_len > 1 || self.m_len > 0 {
            return Err(self.alarm(
                Condition::SetupErrorNotAlone,
                Some(span),
                "G54.4 must be alone in its block (with P only)".into(),
            ));
        }
        let Some(p) = self.peek(b'P') else {
            return Err(self.alarm(
                Condition::SetupErrorNumberMissing,
                Some(span),
                "G54.4 needs P, the data set number".into(),
            ));
        };
        let value = if p.computed { p.value.round() } else { p.value };
        if (p.decimal_point && !p.computed)
            || !(0.0..=f64::from(max)).contains(&value)
            || value.fract() != 0.0
        {
            return Err(self.alarm(
                Condition::SetupErrorNumberRange,
                Some(p.span),
                format!("G54.4 P{}: data sets are 0 (cancel) to {max}", p.value),
            ));
        }
        Ok((value as u32, p.span))
    }

    /// Marks G54.4's P used.
    pub(crate) fn take_setup_error_set(&mut self) {
        self.take(b'P');
    }

    /// The rotation order `Q` of LinuxCNC's TWP P0 / P1: one of `orders`,
    /// `default` when left out (`name` and `form` for the alarm).
    pub(crate) fn twp_order(
        &mut self,
        name: &str,
        form: u32,
        orders: &[u32],
        default: u32,
    ) -> Result<u32, Alarm> {
        let Some(word) = self.take(b'Q') else {
            return Ok(default);
        };
        let q = self.integer(&word, 999)?;
        if !orders.contains(&q) {
            let list: Vec<String> = orders.iter().map(|o| format!("Q{o}")).collect();
            return Err(self.alarm(
                Condition::FeatureDefinition,
                Some(word.span),
                format!(
                    "{name} P{form} Q{q}: the orders of rotation are {}",
                    list.join(", ")
                ),
            ));
        }
        Ok(q)
    }

    /// LinuxCNC's G53.x `P`: how the rotary axes turn (0 the shorter
    /// way, 1 positive, 2 negative; 0 when left out).
    pub(crate) fn twp_direction(&mut self) -> Result<u32, Alarm> {
        match self.take(b'P') {
            Some(word) => self.integer(&word, 2),
            None => Ok(0),
        }
    }
}
