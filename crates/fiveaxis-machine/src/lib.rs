//! The machine model: an immutable description of a 3-, 4- or 5-axis
//! machine (its axes, rotary geometry, soft limits and control parameters),
//! the operator's offset data, and forward kinematics.
//!
//! The conventions are those of the project's machine-model contract
//! (`machine-model.md`): millimetres and degrees, ISO 841 relative motion,
//! rotary axes listed from the bed outwards, tool direction from the tip
//! towards the spindle. Nothing here does I/O: files are parsed from
//! strings that the caller has read.
//!
//! Machines come from a machine file ([`Machine::from_toml`]), the
//! built-in library ([`builtin`]), or an importer that turns a control's
//! own description into a machine file with notes of where each value
//! came from ([`Imported`]): [`import_linuxcnc`] for a LinuxCNC
//! configuration, [`import_tc_carr`] for a SINUMERIK swivel data record
//! (`$TC_CARR1` … `$TC_CARR65`, kinematic types T, P and M; the module
//! `sinumerik` derives how the record's vector chain maps to the head and
//! table chains of the model).

mod builtin;
mod file;
pub mod geometry;
mod inverse;
mod kinematics;
mod linuxcnc;
mod m_codes;
mod offsets;
mod setup_error;
mod sinumerik;
mod tool_table;

pub use builtin::{DEFAULT_MACHINE, builtin, builtin_names, builtin_source};
pub use file::{FileError, MAX_BODIES, MAX_FILE_MAGNITUDE, MAX_SOLIDS, RESERVED_BODY_NAMES};
pub use file::{MAX_JERK, MIN_ACCELERATION, MIN_JERK, MIN_VELOCITY};
pub use inverse::{Orientations, SINGULAR_TOLERANCE, principal, turn_angle};
pub use kinematics::{Pose, TipChain, rotation, sin_cos_degrees, turn_about};
pub use linuxcnc::{ImportError, Imported, Reader, import_linuxcnc};
pub use m_codes::{MAX_M_CODE, MCodes, MFunction, RESERVED_M_CODES};
pub use offsets::{
    BeyondXyz, MAX_EXTENDED_WORK, MAX_HAAS_WORK, MAX_TOOL_OFFSET, Offsets, SetupErrorSet,
    ToolOffset,
};
pub use setup_error::SetupError;
pub use sinumerik::{SINUMERIK_BUILTIN, SINUMERIK_BUILTIN_TC_CARR, TcCarrError, import_tc_carr};

use std::collections::BTreeMap;

use nalgebra::{Unit, Vector3};

/// A 3-vector of `f64`: points in mm, directions unitless.
pub type Vec3 = Vector3<f64>;

/// Most axes a machine can have: X, Y, Z, further linear axes (U, V, W)
/// and up to three rotary axes, eight in all.
pub const MAX_AXES: usize = 8;

/// Most rotary axes a machine can have (a table axis and a two-axis head,
/// e.g. LinuxCNC's `xyzacb_trsrn`).
pub const MAX_ROTARY: usize = 3;

/// Positions of every machine axis, in the machine file's order (linear
/// axes first, then rotary axes bed outwards). Entries past
/// [`Machine::axis_count`] are 0.
pub type Joints = [f64; MAX_AXES];

/// Which part of the machine a rotary axis turns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// It turns the spindle.
    Head,
    /// It turns the workpiece.
    Table,
}

/// FANUC's machine type (parameter 19680), derived from the rotary axes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MachineType {
    /// No rotary axis (19680 = 0).
    None,
    /// Every rotary axis turns the spindle: tool rotation type (2).
    Head,
    /// Every rotary axis turns the table: table rotation type (12).
    Table,
    /// Head and table axes: mixed type (21); with three rotary axes, a
    /// table axis and a two-axis head (or the reverse).
    Mixed,
}

/// The control family whose behaviour and alarm numbers the kernel follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Control {
    /// FANUC Series 30i (the default).
    #[default]
    Fanuc30i,
    /// FANUC Series 16/18 (P/S alarms).
    Fanuc16,
    /// Mitsubishi M700/M800.
    Mitsubishi,
    /// Mazak (Matrix / Smooth, EIA/ISO programs).
    Mazak,
    /// Haas (classic and Next Generation control): FANUC-style G code with
    /// Haas's reading rules (nested comments, dwell P in seconds with a
    /// decimal point).
    Haas,
    /// LinuxCNC 2.9 / 2.10: the RS274/NGC language (O-word control flow,
    /// named parameters) and its kinematics modules' machines.
    LinuxCnc,
    /// SINUMERIK 840D sl / 828D: the Siemens language (R parameters, `DEF`
    /// variables, frames, `TRAORI`, `CYCLE800`), read by its own front end.
    Sinumerik,
    /// HEIDENHAIN TNC 640 / 620 / iTNC 530 / TNC7: conversational
    /// programs (Klartext: `L`, `CC`/`C`, `TOOL CALL`, `CYCL DEF`, `PLANE`,
    /// `M128`, `LN`, Q parameters), read by its own front end.
    Heidenhain,
}

/// The unit a program's lengths are read in until it gives G20 or G21
/// (FANUC No.0000#2 INI; Haas Setting 9 "Dimensioning").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum InputUnit {
    /// Millimetres: power-on G21 (INI = 0, Setting 9 = MM).
    #[default]
    Millimetre,
    /// Inches: power-on G20 (INI = 1, Setting 9 = INCH).
    Inch,
}

/// A linear axis: a name and its soft limits in machine coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearAxis {
    /// Address letter, `X`, `Y`, `Z` (or `U`, `V`, `W`).
    pub name: char,
    /// Lower soft limit, mm.
    pub min: f64,
    /// Upper soft limit, mm.
    pub max: f64,
    /// How fast the axis moves.
    pub dynamics: Dynamics,
    /// The direction the axis moves the tool in.
    pub along: Along,
}

/// The direction a linear axis after X, Y, Z moves the tool in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Along {
    /// Parallel to X, Y or Z (U, V, W as ISO 841 names them): the axis
    /// moves the tool in the machine frame and the kinematics leave it out.
    #[default]
    Parallel,
    /// Along the tool: a quill carried by the head. It moves the tool tip
    /// along the tool direction before the head rotaries turn it, positive
    /// away from the work (`tip = (X, Y, Z) + H((W − L)·t0)`; LinuxCNC's
    /// `5axiskins` W).
    Tool,
}

impl LinearAxis {
    /// The principal axis this one moves along: `X` for `U`, `Y` for `V`,
    /// `Z` for `W`, and the axis itself for `X`, `Y`, `Z`.
    pub fn parallel_to(&self) -> char {
        match self.name {
            'U' => 'X',
            'V' => 'Y',
            'W' => 'Z',
            other => other,
        }
    }
}

/// A rotary axis at the all-zero machine position.
#[derive(Clone, Debug, PartialEq)]
pub struct RotaryAxis {
    /// Address letter, `A`, `B` or `C`.
    pub name: char,
    /// What the axis turns.
    pub on: Side,
    /// Direction of the rotation line: a positive angle turns the carried
    /// part by the right-hand rule about it.
    pub axis: Unit<Vec3>,
    /// A point on the rotation line: machine frame for table axes, relative
    /// to the spindle gauge point for head axes.
    pub center: Vec3,
    /// Soft limits in degrees; `None` on a rollover axis or an axis
    /// without limits.
    pub limits: Option<(f64, f64)>,
    /// Endless axis: positions shown modulo 360, absolute commands take the
    /// shorter way (FANUC 1008#0 ROA with 1260 = 360).
    pub rollover: bool,
    /// How fast the axis turns.
    pub dynamics: Dynamics,
}

/// How fast an axis can move (`machine-model.md`, "Axis dynamics"), in mm
/// (linear axes) or degrees (rotary axes): used by the machining time and
/// the feed checks of `fiveaxis check`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dynamics {
    /// Fastest cutting feed of the axis, per minute (FANUC No.1430; a
    /// control that clamps every axis alike sets No.1422 instead).
    pub max_velocity: f64,
    /// Rapid traverse rate, per minute (FANUC No.1420).
    pub rapid: f64,
    /// Largest acceleration, per second squared (FANUC No.1660,
    /// acceleration/deceleration before interpolation).
    pub max_acceleration: f64,
    /// Largest jerk, per second cubed; `None`: not limited (no bell-shaped
    /// acceleration).
    pub max_jerk: Option<f64>,
}

impl Dynamics {
    /// A linear axis of a machine file that gives no dynamics: a small,
    /// slow machining centre (10 m/min, 0.1 g), so that times err long and
    /// feed warnings early rather than late.
    pub const LINEAR_DEFAULT: Dynamics = Dynamics {
        max_velocity: 10_000.0,
        rapid: 10_000.0,
        max_acceleration: 1_000.0,
        max_jerk: None,
    };

    /// A rotary axis of a machine file that gives no dynamics: 10 rpm,
    /// 360 deg/s² (a slow rotary table).
    pub const ROTARY_DEFAULT: Dynamics = Dynamics {
        max_velocity: 3_600.0,
        rapid: 3_600.0,
        max_acceleration: 360.0,
        max_jerk: None,
    };
}

/// Programming frame of TCPC (FANUC 19696#5 WKP).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ProgrammingFrame {
    /// WKP = 0: the workpiece frame frozen onto the table at TCPC start.
    #[default]
    Table,
    /// WKP = 1: the workpiece coordinate system that does not turn.
    Workpiece,
}

/// How TCPC picks among the rotary positions that give one tool direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum RotaryChoice {
    /// The smallest total rotary motion (FANUC).
    #[default]
    Shortest,
    /// The smallest motion of the rotating axis (Mitsubishi type 2; Mazak
    /// F162 bit 1 = 1).
    RotatingAxis,
    /// Keep the tilt axis on the side it had at TCPC start-up; from 0, the
    /// side with the wider stroke (Mitsubishi type 1; Mazak F162 bit 1 = 0).
    KeepTiltSign,
}

impl RotaryChoice {
    /// The choice a control family makes unless its parameters say
    /// otherwise.
    pub fn default_for(control: Control) -> Self {
        match control {
            Control::Fanuc30i
            | Control::Fanuc16
            | Control::Haas
            | Control::LinuxCnc
            | Control::Sinumerik
            | Control::Heidenhain => RotaryChoice::Shortest,
            Control::Mitsubishi => RotaryChoice::RotatingAxis,
            Control::Mazak => RotaryChoice::KeepTiltSign,
        }
    }
}

/// Control parameters. Every field has the control's default.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameters {
    /// TCPC programming frame (FANUC 19696#5 WKP).
    pub programming_frame: ProgrammingFrame,
    /// The control has the TCPC option (Mitsubishi: P940 without it).
    pub tcpc_option: bool,
    /// Machine position of reference position 1 (G28; FANUC No.1240).
    pub reference_1: Joints,
    /// Machine position of reference position 2 (G30; FANUC No.1241).
    pub reference_2: Joints,
    /// Calculator-type decimal-point input (FANUC 3401#0 DPI): a value
    /// without a decimal point is in mm / inch / degree rather than in
    /// least input increments.
    pub decimal_point_input: bool,
    /// Least input increment in mm (IS-B: 0.001); inch programs use a
    /// tenth of it in inches.
    pub least_input_increment: f64,
    /// The input unit at power-on and after reset, until the program gives
    /// G20 or G21 (FANUC No.0000#2 INI; Haas Setting 9).
    pub input_unit: InputUnit,
    /// Tool posture control (FANUC 19604#0 TPC): between block ends the
    /// tool vector turns on the great circle instead of the rotary axes
    /// moving linearly; G43.4 / G43.5 P1 turns it on for one mode.
    pub tool_posture_control: bool,
    /// How TCPC picks among the rotary positions of one tool direction.
    pub rotary_choice: RotaryChoice,
    /// Half-angle of the cone around the singular direction, degrees
    /// (Mitsubishi #7907 CHK_ANG): inside it the rotating axis moves as
    /// little as it can, whatever `rotary_choice` says.
    pub singular_zone: f64,
    /// Denominator p of the three-dimensional tool compensation vector
    /// `r·(i, j, k)/p` (FANUC No.5011); 0 takes p = √(i² + j² + k²).
    pub tool_comp_3d_denominator: f64,
    /// Cutter compensation C start-up and cancel type B (FANUC No.5003#0
    /// SUP = 1) instead of type A.
    pub cutter_startup_b: bool,
    /// Under G54.4 and TCPC, blocks after the G54.4 block take the rotary
    /// pair with the smaller table-axis motion instead of keeping the tilt
    /// axis on its side (Mazak F162 bit 1).
    pub setup_error_table_motion: bool,
    /// Half-angle of the cone around the singular direction, degrees,
    /// inside which `fiveaxis check` reports a singular passage.
    pub singular_cone: f64,
    /// Turn of one rotary axis inside one block, degrees, beyond which
    /// `fiveaxis check` reports a rotary flip.
    pub flip_angle: f64,
    /// Largest distance, mm, the tool tip of a cutting block that turns a
    /// rotary axis outside TCPC may leave the straight line between its
    /// ends before `fiveaxis check` reports a chord error.
    pub chord_tolerance: f64,
    /// Folders searched, in order, for the file `NAME.ngc` of a LinuxCNC
    /// `o<NAME> call` (LinuxCNC `[RS274NGC] SUBROUTINE_PATH`); a relative
    /// folder is relative to the machine file's folder.
    pub subroutine_path: Vec<String>,
    /// A LinuxCNC tool table (`.tbl`, LinuxCNC `[EMCIO] TOOL_TABLE`) read
    /// as the offsets when a run is given no offsets file; relative to the
    /// machine file's folder.
    pub tool_table: Option<String>,
    /// LinuxCNC: the machine runs its TCP kinematics from power-on (a
    /// configuration whose kinematics type 0 is the TCP one): programs are in
    /// tool-tip coordinates from their first block, as after `tcpc_on`.
    pub tcpc_at_start: bool,
    /// LinuxCNC: the configuration remaps the tilted-working-plane codes
    /// (G68.2, G68.3, G68.4, G69, G53.1, G53.3, G53.6) as the TWP remap of
    /// LinuxCNC's nutating-head demo configurations documents them
    /// (`controller/coordinates/twp.rs`); without it they are unknown codes.
    pub twp_remap: bool,
    /// LinuxCNC TWP `[TWP] PRIORITY`: the rotary axis (1 the primary, 2 the
    /// secondary of the pair G53.1 / G53.3 / G53.6 turn) whose direction of
    /// turn the P word of those codes chooses; the other takes the
    /// shortest way.
    pub twp_priority: u8,
    /// The size of FANUC 30i-B's additional custom macro common variables
    /// option: how many of `#100000`… (at most 100,000, cleared at reset)
    /// and of `#500000`… (at most 500,000, kept) exist; 0 (the default):
    /// none.
    pub additional_common_variables: u32,
    /// LinuxCNC: the values a program reads as `#<_hal[pin]>` (HAL pins
    /// as they stand when the program starts; names in lower case).
    pub hal_pins: BTreeMap<String, f64>,
    /// LinuxCNC: the values a program reads as `#<_ini[section]name>`,
    /// keyed `SECTION]NAME` in upper case (LinuxCNC upper-cases the name
    /// before it looks in the INI file).
    pub ini_values: BTreeMap<String, f64>,
}

impl Default for Parameters {
    fn default() -> Self {
        Self {
            programming_frame: ProgrammingFrame::Table,
            tcpc_option: true,
            reference_1: [0.0; MAX_AXES],
            reference_2: [0.0; MAX_AXES],
            decimal_point_input: false,
            least_input_increment: 0.001,
            input_unit: InputUnit::Millimetre,
            tool_posture_control: false,
            rotary_choice: RotaryChoice::Shortest,
            singular_zone: 0.0,
            tool_comp_3d_denominator: 0.0,
            cutter_startup_b: false,
            setup_error_table_motion: false,
            singular_cone: 2.0,
            flip_angle: 90.0,
            chord_tolerance: 0.01,
            subroutine_path: Vec::new(),
            tool_table: None,
            tcpc_at_start: false,
            twp_remap: false,
            twp_priority: 1,
            additional_common_variables: 0,
            hal_pins: BTreeMap::new(),
            ini_values: BTreeMap::new(),
        }
    }
}

/// An immutable machine description.
#[derive(Clone, Debug, PartialEq)]
pub struct Machine {
    /// Shown in reports.
    pub name: String,
    /// Control family.
    pub control: Control,
    /// Tool direction (tip → spindle) with every rotary axis at 0.
    pub tool_direction: Unit<Vec3>,
    /// Linear axes, X, Y, Z first.
    pub linear: Vec<LinearAxis>,
    /// Rotary axes, bed outwards (0 to [`MAX_ROTARY`]).
    pub rotary: Vec<RotaryAxis>,
    /// Control parameters.
    pub params: Parameters,
    /// The machine builder's M codes (`[m_codes]`): each replaces the
    /// control's standard meaning of its number.
    pub m_codes: MCodes,
    /// The machine's bodies (`[[body]]`), for collision checking and the
    /// view; none when the file gives none.
    pub bodies: Vec<geometry::Body>,
    /// The triangle meshes the bodies' `mesh` solids name, in order.
    pub meshes: Vec<geometry::BodyMesh>,
}

impl Machine {
    /// Number of axes (linear + rotary), the length of the meaningful part
    /// of a [`Joints`].
    pub fn axis_count(&self) -> usize {
        self.linear.len() + self.rotary.len()
    }

    /// Index in [`Joints`] of the axis with this address letter.
    pub fn axis_index(&self, name: char) -> Option<usize> {
        self.linear.iter().position(|a| a.name == name).or_else(|| {
            self.rotary
                .iter()
                .position(|a| a.name == name)
                .map(|i| i + self.linear.len())
        })
    }

    /// The dynamics of the axis at index `i` of [`Joints`] (linear axes
    /// first, then the rotary ones).
    pub fn dynamics(&self, i: usize) -> Dynamics {
        if i < self.linear.len() {
            self.linear[i].dynamics
        } else {
            self.rotary[i - self.linear.len()].dynamics
        }
    }

    /// Index in [`Joints`] of the linear axis that moves along the tool
    /// (a quill, [`Along::Tool`]), if the machine has one.
    pub fn quill_index(&self) -> Option<usize> {
        self.linear.iter().position(|a| a.along == Along::Tool)
    }

    /// Where the quill ([`Along::Tool`]) stands in `joints`: 0 on a
    /// machine without one.
    #[inline]
    pub fn quill(&self, joints: &Joints) -> f64 {
        self.quill_index().map_or(0.0, |i| joints[i])
    }

    /// Index in [`Joints`] of rotary axis `k` (0-based, bed outwards).
    pub fn rotary_index(&self, k: usize) -> usize {
        self.linear.len() + k
    }

    /// Axis names in [`Joints`] order.
    pub fn axis_names(&self) -> impl Iterator<Item = char> + '_ {
        self.linear
            .iter()
            .map(|a| a.name)
            .chain(self.rotary.iter().map(|a| a.name))
    }

    /// FANUC machine type, from the sides of the rotary axes.
    pub fn machine_type(&self) -> MachineType {
        let heads = self.rotary.iter().filter(|r| r.on == Side::Head).count();
        let tables = self.rotary.len() - heads;
        match (heads, tables) {
            (0, 0) => MachineType::None,
            (_, 0) => MachineType::Head,
            (0, _) => MachineType::Table,
            _ => MachineType::Mixed,
        }
    }
}
