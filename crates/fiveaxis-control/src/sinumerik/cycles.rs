//! The SINUMERIK cycles the control carries out itself (the cycles
//! module's interface; its body lands with the cycles).

/// The elementary steps of a cycle, in programmed (workpiece)
/// coordinates, absolute, mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum CycleStep {
    /// Rapid to the given coordinates (X, Y, Z; `None` stays).
    Rapid([Option<f64>; 3]),
    /// Feed move.
    Feed {
        /// Where to.
        to: [Option<f64>; 3],
        /// mm/min, `None` the feed in force.
        feed: Option<f64>,
    },
    /// Dwell, seconds.
    Dwell(f64),
    /// An M function.
    M(u16),
}

/// What a cycle needs to know of the control's state.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CycleContext {
    pub plane: [usize; 3],
    pub position: [f64; 3],
    pub feed: f64,
    pub spindle: f64,
    pub spindle_ccw: bool,
    pub inch: bool,
}

/// A cycle's alarm.
#[derive(Clone, Debug)]
pub(crate) struct CycleError {
    pub alarm: u32,
    pub argument: Option<usize>,
    pub message: String,
}

/// An argument of the engraving cycle.
#[derive(Clone, Debug)]
pub(crate) enum CycleArg {
    Number(f64),
    Text(String),
    Omitted,
}

pub(crate) fn is_cycle(name: &str) -> bool {
    is_pattern(name) || name.starts_with("CYCLE8") && name != "CYCLE800" && name != "CYCLE832"
}

pub(crate) fn is_pattern(name: &str) -> bool {
    matches!(name, "HOLES1" | "HOLES2" | "CYCLE801")
}

pub(crate) fn drilling(
    name: &str,
    args: &[Option<f64>],
    ctx: &CycleContext,
    out: &mut Vec<CycleStep>,
) -> Result<(), CycleError> {
    let _ = (name, args, ctx, out);
    Err(CycleError {
        alarm: 61000,
        argument: None,
        message: "cycles land with the cycles module".into(),
    })
}

pub(crate) fn pattern(
    name: &str,
    args: &[Option<f64>],
    ctx: &CycleContext,
    out: &mut Vec<[f64; 2]>,
) -> Result<(), CycleError> {
    let _ = (name, args, ctx, out);
    Err(CycleError {
        alarm: 61000,
        argument: None,
        message: "cycles land with the cycles module".into(),
    })
}

pub(crate) fn engrave(
    args: &[CycleArg],
    ctx: &CycleContext,
    out: &mut Vec<CycleStep>,
) -> Result<(), CycleError> {
    let _ = (args, ctx, out);
    Err(CycleError {
        alarm: 61000,
        argument: None,
        message: "cycles land with the cycles module".into(),
    })
}
