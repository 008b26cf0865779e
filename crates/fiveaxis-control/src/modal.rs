//! One typed value per modal group (FANUC group numbers in the docs).

use fiveaxis_machine::InputUnit;

/// Group 01: interpolation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotionMode {
    /// G00 positioning.
    Rapid,
    /// G01 linear interpolation.
    Linear,
    /// G02 circular interpolation clockwise.
    Cw,
    /// G03 circular interpolation counter-clockwise.
    Ccw,
}

/// Group 02: plane selection, with its axes as indices of X, Y, Z.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plane {
    /// G17: X-Y, normal Z.
    Xy,
    /// G18: Z-X, normal Y.
    Zx,
    /// G19: Y-Z, normal X.
    Yz,
}

impl Plane {
    /// First axis, second axis and normal, as indices 0 = X, 1 = Y, 2 = Z,
    /// ordered so that first × second = normal.
    pub fn axes(self) -> [usize; 3] {
        match self {
            Plane::Xy => [0, 1, 2],
            Plane::Zx => [2, 0, 1],
            Plane::Yz => [1, 2, 0],
        }
    }
}

/// Group 03: absolute or incremental.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Distance {
    /// G90.
    Absolute,
    /// G91.
    Incremental,
}

/// Group 05: feed meaning.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FeedMode {
    /// G93: F is the inverse of the block time, 1/min.
    InverseTime,
    /// G94: F in mm/min (inch/min).
    PerMinute,
    /// G95: F in mm (inch) per spindle revolution.
    PerRevolution,
}

/// Group 06: input unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Units {
    /// G20: inch.
    Inch,
    /// G21: millimetre.
    Metric,
}

/// Group 08: tool length compensation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LengthMode {
    /// G49: off.
    Off,
    /// G43: +H along the reference tool direction.
    Plus,
    /// G44 (FANUC, Mazak): −H along the reference tool direction.
    Minus,
    /// G43.1: H along the actual tool axis, recomputed at block ends.
    ToolAxis,
    /// G43.4 / G43.5: tool centre point control, H along the tool axis
    /// everywhere on the path.
    Tcpc(TcpcType),
}

/// Which TCPC: how the tool direction is programmed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TcpcType {
    /// Type 1, G43.4: by the rotary axis angles.
    Angles,
    /// Type 2, G43.5: by the tool vector I, J, K.
    Vector,
}

/// Group 14: the selected work coordinate system.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WorkSelect {
    /// No work offset: work zero at machine zero (SINUMERIK `G500` with
    /// a null settable frame 0).
    Null,
    /// G54 … G59 (0 … 5).
    Standard(u8),
    /// G54.1 P1 … P48.
    Extended(u8),
    /// Haas G154 P1 … P99 (G110 … G129 are P1 … P20); the same memory as
    /// G54.1 P.
    Haas(u8),
}

impl std::fmt::Display for WorkSelect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            WorkSelect::Standard(i) => write!(f, "G{}", 54 + u32::from(*i)),
            WorkSelect::Extended(p) => write!(f, "G54.1 P{p}"),
            WorkSelect::Haas(p) => write!(f, "G154 P{p}"),
            WorkSelect::Null => write!(f, "G500"),
        }
    }
}

/// Group 15: how blocks join (speed at block ends, not the path).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CuttingMode {
    /// G61: exact stop mode, every block decelerates to a stop and is
    /// checked in position.
    ExactStop,
    /// G62: automatic corner override (inner corners of cutter
    /// compensation C at a reduced feed).
    CornerOverride,
    /// G63: tapping mode (feed override and feed hold without effect).
    Tapping,
    /// G64: cutting mode (the power-on state).
    Cutting,
}

/// Contour control of `G05.1` (group 00 codes that set a mode): they change
/// the feed along the path; the kernel reports the programmed path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContourControl {
    /// `G05.1 Q0`: off.
    Off,
    /// `G05.1 Q1`: AI contour control (AICC / AI APC).
    AiContour,
    /// `G05.1 Q3`: nano smoothing (the control smooths the programmed
    /// points into a curve; the kernel still reports the programmed path).
    NanoSmoothing,
}

/// Accuracy and look-ahead modes: speed, never path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Accuracy {
    /// `G05.1 Q1 / Q3 / Q0`.
    pub contour: ContourControl,
    /// `G05 P10000` (on) / `G05 P0` (off): high-precision contour control
    /// (HPCC), or AI high-precision on the 30i.
    pub high_precision: bool,
    /// `G08 P1` (on) / `G08 P0` (off): advanced preview (look-ahead) control.
    pub look_ahead: bool,
    /// Haas `G187 P1` / `P2` / `P3`: smoothness rough, medium, finish; 0
    /// after `G187` without P (the control's Setting 191 decides).
    pub smoothness: u8,
    /// Haas `G187 E`: the largest corner rounding, mm; `None` after
    /// `G187` without E (Setting 85 decides).
    pub corner_rounding: Option<f64>,
}

/// The modal state of the control.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Modal {
    /// Group 01.
    pub motion: MotionMode,
    /// Group 02.
    pub plane: Plane,
    /// Group 03.
    pub distance: Distance,
    /// Group 05.
    pub feed_mode: FeedMode,
    /// Group 06.
    pub units: Units,
    /// Group 08.
    pub length: LengthMode,
    /// Group 14.
    pub work: WorkSelect,
    /// Group 15.
    pub cutting: CuttingMode,
    /// G05.1, G05, G08 modes.
    pub accuracy: Accuracy,
    /// LinuxCNC `G64 P Q`: path blending tolerance and naive CAM
    /// tolerance, mm (`None`: G64 without P, blending as fast as
    /// possible, or G61 / G61.1).
    pub blend: Option<[f64; 2]>,
    /// LinuxCNC G90.1: arc centres I, J, K are absolute (program
    /// coordinates); G91.1 (the power-on state): relative to the start.
    pub ijk_absolute: bool,
    /// LinuxCNC G7 (true) / G8: X words are diameters (lathe diameter
    /// mode).
    pub diameter_mode: bool,
}

impl Modal {
    /// FANUC power-on state: G00 G17 G90 G94 G49 G54 G64 (G40 group
    /// 07), every accuracy mode off, and G21 or G20 as the machine's input
    /// unit says (FANUC No.0000#2 INI, Haas Setting 9).
    pub fn power_on(input_unit: InputUnit) -> Self {
        Self {
            motion: MotionMode::Rapid,
            plane: Plane::Xy,
            distance: Distance::Absolute,
            feed_mode: FeedMode::PerMinute,
            units: match input_unit {
                InputUnit::Millimetre => Units::Metric,
                InputUnit::Inch => Units::Inch,
            },
            length: LengthMode::Off,
            work: WorkSelect::Standard(0),
            cutting: CuttingMode::Cutting,
            accuracy: Accuracy {
                contour: ContourControl::Off,
                high_precision: false,
                look_ahead: false,
                smoothness: 0,
                corner_rounding: None,
            },
            blend: None,
            ijk_absolute: false,
            diameter_mode: false,
        }
    }
}
