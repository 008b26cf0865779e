//! The FANUC family's front end: FANUC, Mitsubishi, Mazak, Haas and
//! LinuxCNC's RS274/NGC, whose blocks are address words (`fiveaxis-gcode`
//! parses a line into a `Block`, `fiveaxis-macro` evaluates macro B and
//! O-words).
//!
//! The controller asks, the front end answers. A function of the kernel
//! that a FANUC block calls takes its operands from here as typed values
//! in the kernel's units (mm, degrees, seconds, numbers of the offset
//! memory), with the tape's rules applied: the decimal-point rule, inch
//! input, each address's format, the alarms of a word missing, malformed
//! or out of range. The operands are read when their function runs,
//! because a FANUC block's words mean what the modes set earlier in the
//! same block say (`G20 X1.`, `G16 X Y`, `G91 G10 …`): the control reads
//! them in that order too.
//!
//! * `gcodes.rs`: the block's G codes by modal group, and the codes a
//!   control refuses.
//! * `words.rs`: the block's words by address, and which ones a function
//!   used (a word no function uses is an alarm).
//! * `values.rs`: the decimal-point and inch rules ([`Rules`]).
//! * `operands.rs`: what every block may give: axis values, F S T D H,
//!   the dwell, the subprogram call, the numbers of mode codes.
//! * `motion.rs`: a circle's radius or centre, LinuxCNC's turns.
//! * `haas.rs`: Haas's own codes' operands (G187, M97, G154).
//! * `cycles.rs`: a canned-cycle block's drilling data.
//! * `vectors.rs`: I, J, K as a tool vector or a surface normal; TCPC's
//!   P and Q.
//! * `frames.rs`: work offset selection, G52 / G92 values, the program
//!   transforms' centres, factors and angle.
//! * `threading.rs`: LinuxCNC's G33 / G33.1 / G76 data.
//! * `engrave.rs`: Haas G47's words.
//! * `splines.rs`: LinuxCNC's G5 / G5.1 control offsets.
//! * `data_setting.rs`: G10, FANUC's and LinuxCNC's formats, into
//!   [`crate::command::DataSetting`].

mod cycles;
mod data_setting;
mod engrave;
mod frames;
mod gcodes;
mod haas;
mod motion;
mod operands;
mod splines;
mod threading;
mod values;
mod vectors;
pub(crate) mod words;

pub(crate) use cycles::DwellRules;
pub(crate) use data_setting::KERNEL_WORK_SYSTEMS;
pub(crate) use frames::ScaleFactors;
pub(crate) use gcodes::{
    AccuracyCode, Classify, FeatureCode, GCodes, LengthCode, OneShot, TwpOrient,
};
pub(crate) use motion::ArcCenter;
use operands::CENTER_LETTERS;
pub(crate) use operands::{AddedLength, engraves, words_without_point};
pub(crate) use splines::SplineData;
pub(crate) use threading::ThreadData;
pub(crate) use values::{MM_PER_INCH, Rules};
pub(crate) use words::Words;
