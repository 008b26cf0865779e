//! Operator data kept in offset memory: tool offsets, work offsets and
//! workpiece setup error data sets (`machine-model.md` §5).

use std::collections::BTreeMap;

use crate::Vec3;

/// Highest tool offset number (H, D) the offsets file and G10 accept.
pub const MAX_TOOL_OFFSET: u32 = 999;

/// Highest extended work offset number of FANUC (`G54.1 P1` … `G54.1 P48`).
pub const MAX_EXTENDED_WORK: u32 = 48;

/// Highest additional work offset number of Haas (`G154 P1` … `G154 P99`;
/// `G110` … `G129` are P1 … P20), and the size of the extended work
/// offset memory, which FANUC's `G54.1 P` and Haas's `G154 P` share.
pub const MAX_HAAS_WORK: u32 = 99;

/// One tool offset number: length (H) and radius (D) values, geometry and
/// wear (FANUC tool compensation memory C).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ToolOffset {
    /// Length geometry, mm (`G10 L10`).
    pub length: f64,
    /// Length wear, mm (`G10 L11`).
    pub length_wear: f64,
    /// Radius geometry, mm (`G10 L12`).
    pub radius: f64,
    /// Radius wear, mm (`G10 L13`).
    pub radius_wear: f64,
}

/// One workpiece setup error data set (G54.4 Pn).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SetupErrorSet {
    /// Origin errors Δx, Δy, Δz, mm.
    pub origin: Vec3,
    /// Rotation errors Δa, Δb, Δc about X, then Y, then Z, degrees.
    pub rotation: Vec3,
    /// Table rotary positions at which the errors were measured, by axis
    /// name; an axis left out was at 0.
    pub table: Vec<(char, f64)>,
}

/// Offset memory.
#[derive(Clone, Debug, PartialEq)]
pub struct Offsets {
    /// Tool offsets by number (1 ..= [`MAX_TOOL_OFFSET`]); a number not
    /// listed is all zero.
    pub tools: BTreeMap<u32, ToolOffset>,
    /// Work offsets `G54` … `G59`, table-frame coordinates of the work zero.
    pub work: [Vec3; 6],
    /// Extended work offsets, index 0 is P1: `G54.1 P1` … `P48` on FANUC
    /// controls, `G154 P1` … `P99` on Haas.
    pub extended_work: [Vec3; MAX_HAAS_WORK as usize],
    /// External work zero offset, added to every work offset (FANUC "EXT",
    /// number 00).
    pub external: Vec3,
    /// Setup error data sets by number (0 is FANUC's common set).
    pub setup_error: BTreeMap<u32, SetupErrorSet>,
}

impl Default for Offsets {
    fn default() -> Self {
        Self {
            tools: BTreeMap::new(),
            work: [Vec3::zeros(); 6],
            extended_work: [Vec3::zeros(); MAX_HAAS_WORK as usize],
            external: Vec3::zeros(),
            setup_error: BTreeMap::new(),
        }
    }
}

impl Offsets {
    /// The tool offset of number `n`, zero when it was never set.
    pub fn tool(&self, n: u32) -> ToolOffset {
        self.tools.get(&n).copied().unwrap_or_default()
    }
}
