//! The control parameters the macro layer depends on.

/// Parameters of the control that change how macros evaluate.
///
/// `Default` gives the manual's defaults.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MacroSettings {
    /// Parameter NAT (No. 6004#0). `false` (the default): `ASIN` and the
    /// one-argument `ATAN` give 270° … 90° (a negative angle is given as
    /// its positive equivalent, `ASIN[-0.5]` = 330), the two-argument
    /// `ATAN` gives 0° … 360° (`ATAN[-1,-1]` = 225). `true`: -90° … 90°
    /// and -180° … 180° (`ATAN[-1,-1]` = -135). `ACOS` always gives
    /// 0° … 180°.
    pub nat: bool,
    /// Whether the common variables `#200` … `#499` exist (the control's
    /// extended common variables option). Default `false`: they are
    /// undefined (PS0115).
    pub extended_common: bool,
    /// The size of the 30i's additional common variables option (FANUC
    /// 30i-B, "addition of custom macro common variables"): how many of
    /// `#100000`… (cleared at reset, at most 100,000) and of `#500000`…
    /// (kept, at most 500,000) exist. Default 0: the option is absent and
    /// they are undefined (PS0115).
    pub additional_common: u32,
    /// `ADP[x]` multiplies by `10^adp_digits`: it gives back the number
    /// as written for an argument passed without decimal point and scaled
    /// by the least input increment (3 for IS-B in mm: `A10` → 0.010 →
    /// `ADP` → 10). Default 3.
    pub adp_digits: u8,
    /// LinuxCNC's RS274/NGC rules instead of FANUC's (see `crate::ngc`):
    /// no vacant values (an unset numbered parameter is 0), comparisons
    /// and `AND OR XOR` give 1 or 0, `EQ`/`NE` within 1e-6, `MOD` with a
    /// non-negative result for a positive divisor, `FIX`/`FUP` as floor and
    /// ceiling, `ATAN[a]/[b]` in -180° … 180°, numbered parameters
    /// `#1` … `#5602` and named ones `#<name>`. Default `false`.
    pub linuxcnc: bool,
}

impl MacroSettings {
    /// LinuxCNC's settings.
    pub const LINUXCNC: Self = Self {
        nat: true,
        extended_common: false,
        additional_common: 0,
        adp_digits: 3,
        linuxcnc: true,
    };
}

impl Default for MacroSettings {
    fn default() -> Self {
        Self {
            nat: false,
            extended_common: false,
            additional_common: 0,
            adp_digits: 3,
            linuxcnc: false,
        }
    }
}
