//! The operands of a block in a canned cycle (G73, G74, G76, G81–G89):
//! its drilling data, read as the control reads them.

use fiveaxis_gcode::Span;
use fiveaxis_machine::MAX_AXES;

use super::{Rules, Words};
use crate::alarm::{Alarm, Condition};

/// Largest K (repetitions), FANUC 1 to 9999.
const MAX_REPEATS: u32 = 9999;

/// The drilling data a cycle block gives; what it leaves out stays as
/// the cycle's modal data had it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CycleData {
    /// The R level, mm.
    pub r: Option<f64>,
    /// The depth of each peck (Q, taken positive), mm.
    pub q: Option<f64>,
    /// Where Q is written.
    pub q_span: Option<Span>,
    /// LinuxCNC's peck clearance of G73 / G83 (D), mm.
    pub d: Option<f64>,
    /// The dwell at the bottom (P), ms.
    pub p: Option<u32>,
    /// How many times (K or L; 1 when left out).
    pub repeats: u32,
    /// The axis values: the hole position, and the bottom on the drilling
    /// axis.
    pub targets: [Option<f64>; MAX_AXES],
}

/// How a dwell P is read (the dialect's rules).
#[derive(Clone, Copy, Debug)]
pub(crate) struct DwellRules {
    /// Haas: P with a decimal point is seconds.
    pub seconds_with_point: bool,
    /// LinuxCNC: P is seconds.
    pub seconds: bool,
}

impl Words {
    /// The drilling data of a cycle block; `peck_clearance`: D is the
    /// peck clearance (LinuxCNC G73 / G83).
    pub(crate) fn cycle_data(
        &mut self,
        rules: &Rules,
        dwell: DwellRules,
        peck_clearance: bool,
    ) -> Result<CycleData, Alarm> {
        let r = self.take(b'R').map(|word| rules.length(&word));
        let q_word = self.take(b'Q');
        let q = q_word.map(|word| rules.length(&word).abs());
        let d = match peck_clearance.then(|| self.take(b'D')).flatten() {
            Some(word) => {
                let d = rules.length(&word);
                if !(d >= 0.0 && d.is_finite()) {
                    return Err(self.alarm(
                        Condition::ValueOutOfRange,
                        Some(word.span),
                        format!(
                            "D{}: the peck clearance of G73 / G83 cannot be negative",
                            word.value
                        ),
                    ));
                }
                Some(d)
            }
            None => None,
        };
        let p = match self.take(b'P') {
            Some(word) => Some(self.dwell_ms(&word, dwell.seconds_with_point, dwell.seconds)?),
            None => None,
        };
        let repeats = match self.take(b'K').or_else(|| self.take(b'L')) {
            Some(word) => self.integer(&word, MAX_REPEATS)?,
            None => 1,
        };
        let targets = self.axes(rules);
        Ok(CycleData {
            r,
            q,
            q_span: q_word.map(|w| w.span),
            d,
            p,
            repeats,
            targets,
        })
    }
}
