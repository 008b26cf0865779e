//! How the output states its feed, and what each style costs the tip feed.
//!
//! Every cutting block of the output has a duration (its share of the
//! source block's time: tip length over programmed feed). The styles:
//!
//! * [`FeedStyle::InverseTime`] (default): `G93`, `F` = 1 / minutes: the
//!   control takes exactly that time whatever the axes do.
//! * [`FeedStyle::DegreesPerMinute`]: `G94`, `F` chosen per block so that
//!   the control's own reading of a feed with rotary axes gives the block
//!   its time. A FANUC control in `G94` moving linear and rotary axes
//!   together feeds the composite vector of the axes' travels, degrees
//!   counted as millimetres (FANUC Series 30i-B operator's manual,
//!   B-64484EN, "Feed functions", feedrate of simultaneous linear and
//!   rotary axis control, No.1408#0 RFD = 0): the block takes
//!   `sqrt(ΔX² + ΔY² + ΔZ² + ΔA² + ΔC²) / F` minutes, so
//!   `F = sqrt(ΣΔ²) / minutes`. This is what "degrees per minute" posts
//!   for controls without inverse time write.
//! * [`FeedStyle::Programmed`]: `G94` with the source block's `F` kept:
//!   the same composite reading makes each block last
//!   `sqrt(ΣΔ²) / F`, so the tip feed is off by the ratio of that to the
//!   block's time; the header states the largest error.

use fiveaxis_machine::{Control, Joints, Machine, principal};

/// How the feed is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FeedStyle {
    /// `G93` inverse time.
    #[default]
    InverseTime,
    /// `G94`, F per block from the composite travel of all axes.
    DegreesPerMinute,
    /// `G94`, the programmed F kept.
    Programmed,
}

impl FeedStyle {
    /// The name used on the command line and in the header.
    pub fn name(self) -> &'static str {
        match self {
            FeedStyle::InverseTime => "inverse-time",
            FeedStyle::DegreesPerMinute => "dpm",
            FeedStyle::Programmed => "programmed",
        }
    }

    /// The style of a name ([`FeedStyle::name`]).
    pub fn parse(name: &str) -> Option<Self> {
        [
            FeedStyle::InverseTime,
            FeedStyle::DegreesPerMinute,
            FeedStyle::Programmed,
        ]
        .into_iter()
        .find(|s| s.name() == name)
    }

    /// The style of a post for a machine with `control`: the one
    /// `requested`, or the default: [`FeedStyle::InverseTime`], on a
    /// HEIDENHAIN [`FeedStyle::DegreesPerMinute`]. The TNC has no inverse
    /// time feed (without `M116` its F applies to the combined travel of
    /// all axes, degrees as mm: the composite style): inverse time
    /// requested for it is refused.
    pub fn for_control(requested: Option<Self>, control: Control) -> Result<Self, String> {
        match (requested, control) {
            (Some(FeedStyle::InverseTime), Control::Heidenhain) => Err(
                "feed inverse-time: a HEIDENHAIN TNC has no inverse time feed; give dpm (F per block from the combined travel of all axes, the TNC's own reading without M116, the default there) or programmed".into(),
            ),
            (Some(style), _) => Ok(style),
            (None, Control::Heidenhain) => Ok(FeedStyle::DegreesPerMinute),
            (None, _) => Ok(FeedStyle::InverseTime),
        }
    }

    /// The G code of the feed mode.
    pub fn g_code(self) -> &'static str {
        match self {
            FeedStyle::InverseTime => "G93",
            _ => "G94",
        }
    }

    /// The F word of a cutting block from `from` to `to` that must last
    /// `minutes`, the source block programmed at `programmed` mm/min;
    /// `None` for a block whose axes do not move (it is left out: in
    /// `G94` its F would be 0, and a block of no motion takes no time on
    /// the control).
    pub fn f_word(
        self,
        machine: &Machine,
        from: &Joints,
        to: &Joints,
        minutes: f64,
        programmed: f64,
    ) -> Option<f64> {
        let travel = composite_travel(machine, from, to);
        match self {
            _ if travel <= 0.0 => None,
            FeedStyle::InverseTime => Some(1.0 / minutes),
            FeedStyle::DegreesPerMinute => Some(travel / minutes),
            FeedStyle::Programmed => Some(programmed),
        }
    }
}

/// The composite travel of a move as a FANUC control feeds it in `G94`:
/// the length of the vector of every axis' travel, degrees as mm.
/// A rollover axis travels the shorter way to its absolute target.
pub fn composite_travel(machine: &Machine, from: &Joints, to: &Joints) -> f64 {
    let first_rotary = machine.linear.len();
    (0..machine.axis_count())
        .map(|i| {
            let d = to[i] - from[i];
            let rollover = i >= first_rotary && machine.rotary[i - first_rotary].rollover;
            if rollover { principal(d) } else { d }.powi(2)
        })
        .sum::<f64>()
        .sqrt()
}

/// Relative error of the tip feed of a block written with F `f` in `G94`
/// that should last `minutes`: the control takes `travel / f`, the tip
/// feed is scaled by `minutes / (travel / f)`.
pub fn tip_feed_error(machine: &Machine, from: &Joints, to: &Joints, minutes: f64, f: f64) -> f64 {
    let taken = composite_travel(machine, from, to) / f;
    if taken > 0.0 {
        (minutes / taken - 1.0).abs()
    } else {
        0.0
    }
}
