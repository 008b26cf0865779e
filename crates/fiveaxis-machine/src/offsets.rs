//! Operator data kept in offset memory: tool offsets, work offsets and
//! workpiece setup error data sets (`machine-model.md` §5).

use std::collections::BTreeMap;

use crate::{MAX_AXES, Vec3};

/// The values of one work offset for the axes beyond X, Y, Z, in machine
/// axis order (the fourth axis first): a FANUC keeps one value per
/// controlled axis, rotary axes included.
pub type BeyondXyz = [f64; MAX_AXES - 3];

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
    /// The shapes of the tools and holders the file describes, by offset
    /// number (collision checking and the view).
    pub tool_shapes: BTreeMap<u32, crate::geometry::ToolShape>,
    /// Work offsets `G54` … `G59`, table-frame coordinates of the work zero.
    pub work: [Vec3; 6],
    /// Extended work offsets, index 0 is P1: `G54.1 P1` … `P48` on FANUC
    /// controls, `G154 P1` … `P99` on Haas.
    pub extended_work: [Vec3; MAX_HAAS_WORK as usize],
    /// External work zero offset, added to every work offset (FANUC "EXT",
    /// number 00).
    pub external: Vec3,
    /// The values of `work` for the axes beyond X, Y, Z.
    pub work_beyond: [BeyondXyz; 6],
    /// The values of `extended_work` for the axes beyond X, Y, Z.
    pub extended_work_beyond: [BeyondXyz; MAX_HAAS_WORK as usize],
    /// The value of `external` for the axes beyond X, Y, Z.
    pub external_beyond: BeyondXyz,
    /// The most values a work offset of the file gives (3: X, Y, Z only),
    /// and the key that gives them, for the check against the machine's
    /// axes ([`Offsets::check_axes`]).
    pub widest_work: Option<(String, usize)>,
    /// Setup error data sets by number (0 is FANUC's common set).
    pub setup_error: BTreeMap<u32, SetupErrorSet>,
    /// Tools by name (upper-cased) with the offset number each holds.
    pub tool_names: Vec<(String, u32)>,
    /// A tool a program names that `tool_names` lacks is known all the
    /// same (given a number in the order named), as when one length
    /// stands for every tool (`post --tool-length`).
    pub any_name: bool,
}

impl Default for Offsets {
    fn default() -> Self {
        Self {
            tools: BTreeMap::new(),
            tool_shapes: BTreeMap::new(),
            work: [Vec3::zeros(); 6],
            extended_work: [Vec3::zeros(); MAX_HAAS_WORK as usize],
            external: Vec3::zeros(),
            work_beyond: [[0.0; MAX_AXES - 3]; 6],
            extended_work_beyond: [[0.0; MAX_AXES - 3]; MAX_HAAS_WORK as usize],
            external_beyond: [0.0; MAX_AXES - 3],
            widest_work: None,
            setup_error: BTreeMap::new(),
            tool_names: Vec::new(),
            any_name: false,
        }
    }
}

impl Offsets {
    /// The offset number of the tool named `name` (any case), if the
    /// offsets file names it.
    pub fn tool_number(&self, name: &str) -> Option<u32> {
        self.tool_names
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, k)| *k)
    }

    /// The tool offset of number `n`, zero when it was never set.
    pub fn tool(&self, n: u32) -> ToolOffset {
        self.tools.get(&n).copied().unwrap_or_default()
    }

    /// Tool `n` as a solid, for collisions and the stock: its shape from
    /// `[tools.N]`, else a flat cylinder of its radius that cuts along its
    /// whole length; length and radius with their wear. A tool the offsets
    /// do not list has no length and cuts nothing.
    pub fn tool_solid(&self, n: u32) -> crate::geometry::ToolSolid {
        let offset = self.tool(n);
        let length = offset.length + offset.length_wear;
        let radius = offset.radius + offset.radius_wear;
        let shape = self
            .tool_shapes
            .get(&n)
            .cloned()
            .unwrap_or(crate::geometry::ToolShape {
                cutter: crate::geometry::Cutter::Flat,
                flute: length,
                shank: 2.0 * radius,
                holder: Vec::new(),
            });
        crate::geometry::ToolSolid {
            shape,
            length,
            radius,
        }
    }

    /// Whether the work offsets give no more values than a machine of
    /// `axes` axes has.
    ///
    /// # Errors
    ///
    /// The key that gives more, and how many.
    pub fn check_axes(&self, axes: usize) -> Result<(), String> {
        match &self.widest_work {
            Some((key, n)) if *n > axes => Err(format!(
                "work offset `{key}` gives {n} values: the machine has {axes} axes (one value per axis, in the machine file's order)"
            )),
            _ => Ok(()),
        }
    }
}
