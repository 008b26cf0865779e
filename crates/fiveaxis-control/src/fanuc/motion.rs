//! The operands of a circle (G02 / G03): its radius or its centre words,
//! and LinuxCNC's number of turns.

use fiveaxis_gcode::Span;

use super::{CENTER_LETTERS, Rules, Words};
use crate::alarm::{Alarm, Condition};

/// Most turns a LinuxCNC arc's P may ask for (each turn is a circle in
/// the segment's sweep).
const MAX_ARC_TURNS: u32 = 10_000;

/// How a circle block gives its centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum ArcCenter {
    /// By its radius, mm (negative: the arc spans more than 180°).
    Radius(f64, Span),
    /// By the centre's coordinates along the plane's two axes, mm: from
    /// the start point, or (`absolute` reading, LinuxCNC G90.1) in
    /// program coordinates.
    Center {
        /// Along the plane's first axis.
        i: f64,
        /// Along its second.
        j: f64,
        /// Where the first of them is written.
        span: Option<Span>,
    },
}

impl Words {
    /// Whether the block gives a circle's radius or a centre word of the
    /// plane of axes `p`, `q`.
    pub(crate) fn has_arc_words(&self, p: usize, q: usize) -> bool {
        self.has(b'R') || self.has_plane_vector(p, q)
    }

    /// The circle's radius or centre in the plane of axes `p`, `q`;
    /// `absolute`: the centre words are the centre itself (both needed).
    pub(crate) fn arc_center(
        &mut self,
        p: usize,
        q: usize,
        rules: &Rules,
        absolute: bool,
    ) -> Result<ArcCenter, Alarm> {
        if let Some(r) = self.take(b'R') {
            for letter in CENTER_LETTERS {
                if let Some(word) = self.peek(letter) {
                    return Err(self.alarm(
                        Condition::GCodeConflict,
                        Some(word.span),
                        "an arc takes either R or I, J, K, not both".into(),
                    ));
                }
            }
            return Ok(ArcCenter::Radius(rules.length(&r), r.span));
        }
        let i_word = self.take(CENTER_LETTERS[p]);
        let j_word = self.take(CENTER_LETTERS[q]);
        let span = i_word.or(j_word).map(|w| w.span);
        if absolute {
            // LinuxCNC G90.1: both are needed (rs274: "J word missing in
            // absolute center arc").
            let (Some(iw), Some(jw)) = (i_word, j_word) else {
                let missing = if i_word.is_none() {
                    CENTER_LETTERS[p]
                } else {
                    CENTER_LETTERS[q]
                };
                return Err(self.alarm(
                    Condition::ArcCenterMissing,
                    span,
                    format!(
                        "{} word missing in an absolute centre arc (G90.1 takes both centre \
                         words of the plane)",
                        char::from(missing)
                    ),
                ));
            };
            return Ok(ArcCenter::Center {
                i: rules.length(&iw),
                j: rules.length(&jw),
                span,
            });
        }
        let i = i_word.map_or(0.0, |w| rules.length(&w));
        let j = j_word.map_or(0.0, |w| rules.length(&w));
        if i == 0.0 && j == 0.0 {
            let message = if span.is_some() {
                format!(
                    "the arc's centre words {}0 {}0 put the centre on the start point: the radius is 0",
                    char::from(CENTER_LETTERS[p]),
                    char::from(CENTER_LETTERS[q])
                )
            } else {
                "arc needs R or the centre words of the selected plane".into()
            };
            return Err(self.alarm(Condition::ArcCenterMissing, span, message));
        }
        Ok(ArcCenter::Center { i, j, span })
    }

    /// Where a circle's radius is written.
    pub(crate) fn radius_span(&self) -> Option<Span> {
        self.peek(b'R').map(|w| w.span)
    }

    /// LinuxCNC `P` of a circle (g-code.adoc, G2/G3: "P - number of
    /// turns"): at least 1.
    pub(crate) fn arc_turns(&mut self) -> Result<Option<u32>, Alarm> {
        let Some(word) = self.take(b'P') else {
            return Ok(None);
        };
        let turns = self.integer(&word, MAX_ARC_TURNS)?;
        if turns == 0 {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                Some(word.span),
                "P of an arc counts its turns: at least 1".into(),
            ));
        }
        Ok(Some(turns))
    }
}
