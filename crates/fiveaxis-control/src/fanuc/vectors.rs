//! The vector words I, J, K outside circles: the tool direction of TCPC
//! type 2 (G43.5), the normal of three-dimensional tool compensation
//! (G41 / G42 with I J K), and TCPC's mode words P and Q.

use fiveaxis_gcode::Span;

use super::{CENTER_LETTERS, Rules, Words};
use crate::alarm::{Alarm, Condition};

/// Each basic axis with the axis parallel to it.
const PARALLEL: [(u8, u8); 3] = [(b'X', b'U'), (b'Y', b'V'), (b'Z', b'W')];

impl Words {
    /// Whether the block gives every component of a vector.
    pub(crate) fn has_whole_vector(&self) -> bool {
        CENTER_LETTERS.iter().all(|&l| self.has(l))
    }

    /// Whether the block gives a component of a vector.
    pub(crate) fn has_vector(&self) -> bool {
        CENTER_LETTERS.iter().any(|&l| self.has(l))
    }

    /// Where the block's first vector component is written.
    pub(crate) fn vector_span(&self) -> Option<Span> {
        CENTER_LETTERS
            .into_iter()
            .find_map(|l| self.peek(l))
            .map(|w| w.span)
    }

    /// The block's vector (an omitted component is 0), mm, taken.
    pub(crate) fn vector(&mut self, rules: &Rules) -> [f64; 3] {
        CENTER_LETTERS.map(|l| self.take(l).map_or(0.0, |w| rules.length(&w)))
    }

    /// The vector words taken without a meaning (Mitsubishi's TCPC type 1
    /// ignores them).
    pub(crate) fn drop_vector(&mut self) {
        for letter in CENTER_LETTERS {
            self.take(letter);
        }
    }

    /// TCPC's `P`: tool posture control (P1) or not (P0).
    pub(crate) fn tool_posture(&mut self) -> Result<Option<bool>, Alarm> {
        match self.take(b'P') {
            Some(word) => Ok(Some(self.integer(&word, 1)? == 1)),
            None => Ok(None),
        }
    }

    /// TCPC type 2's `Q`: the inclination angle, degrees (0 when left
    /// out).
    pub(crate) fn inclination(&mut self, rules: &Rules) -> f64 {
        self.take(b'Q').map_or(0.0, |w| rules.angle(&w))
    }

    /// P/S 047 and 048 at the start-up of 3-D tool compensation: two axes
    /// in the same direction, or an omitted axis whose basic axis the
    /// machine does not have (`has_axis`).
    pub(crate) fn comp3d_startup_axes(&self, has_axis: impl Fn(char) -> bool) -> Result<(), Alarm> {
        for (basic, parallel) in PARALLEL {
            if let (Some(_), Some(word)) = (self.peek(basic), self.peek(parallel)) {
                return Err(self.alarm(
                    Condition::Comp3dParallelAxes,
                    Some(word.span),
                    format!(
                        "3-D tool compensation start-up names {} and {}, two axes in the same direction",
                        char::from(basic),
                        char::from(parallel)
                    ),
                ));
            }
            let named = self.has(basic) || self.has(parallel);
            if !named && !has_axis(char::from(basic)) {
                return Err(self.alarm(
                    Condition::Comp3dBasicAxisMissing,
                    None,
                    format!(
                        "3-D tool compensation start-up omits {0} but the machine has no basic axis {0}",
                        char::from(basic)
                    ),
                ));
            }
        }
        Ok(())
    }
}
