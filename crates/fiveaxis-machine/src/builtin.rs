//! The built-in machine library.

use crate::Machine;

/// Name of the machine used when none is given.
pub const DEFAULT_MACHINE: &str = "trunnion-ac";

/// Names of the built-in machines.
pub fn builtin_names() -> &'static [&'static str] {
    &[]
}

/// A built-in machine by name.
pub fn builtin(_name: &str) -> Option<Machine> {
    None
}
