//! The controller of the fiveaxis kernel: modal state, offsets, the
//! functions of the G and M codes, alarms, and the segments a program moves
//! through.
//!
//! Data flows one way: a [`Runner`] reads lines from a [`Source`], the
//! front end (`fiveaxis-gcode`) turns each into a block, the [`Controller`]
//! turns blocks into [`Segment`]s or an [`Alarm`], and the caller samples
//! segments into [`Row`]s. Nothing here does I/O of its own: sources are
//! handed in by the caller.

mod alarm;
pub mod command;
mod controller;
pub mod cutter;
mod dialect;
mod fanuc;
mod heidenhain;
mod language;
mod modal;
mod reach;
mod runner;
pub mod search;
mod segment;
mod sinumerik;

pub use alarm::{Alarm, AlarmCode, Condition, Num, alarm_reference};
pub use controller::{
    ARC_RADIUS_TOLERANCE, Controller, Flow, POSITION_TOLERANCE, ProgramStop,
    REFERENCE_CHECK_TOLERANCE, WordsWithoutPoint, inclined, normalize_360, shortest_turn,
};
pub use controller::{MAX_CYCLE_SEGMENTS, PECK_CLEARANCE, PECK_RETRACT};
pub use dialect::Dialect;
pub use heidenhain::Stock;
pub use language::{HEAD_BYTES, machine_for_language, program_language};
pub use modal::{
    Accuracy, ContourControl, CuttingMode, Distance, FeedMode, LengthMode, Modal, MotionMode,
    Plane, TcpcType, Units, WorkSelect,
};
pub use runner::{
    AheadSource, DEFAULT_MAX_BLOCKS, Interpolation, MAX_LINE_BYTES, ProgramLibrary, ReaderSource,
    RunError, RunOptions, Runner, SliceSource, Source,
};
pub use segment::{
    Arc, MAX_STEPS, Motion, POSTURE_KNOTS, Path, Posture, Row, Segment, TcpcPath, TipPath,
    displayed, posture_angles, slerp,
};
