//! The SINUMERIK front end: executed blocks of the Siemens language
//! (`fiveaxis-sinumerik`) into the kernel's commands (`crate::command`).
//!
//! `cycles.rs`: the Siemens drilling, tapping, boring, pattern and
//! engraving cycles as their elementary moves.

pub(crate) mod cycles;
