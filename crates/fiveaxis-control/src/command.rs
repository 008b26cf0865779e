//! The control-neutral commands: what a front end tells the controller,
//! whatever language the program is written in.
//!
//! A front end reads its language (the SINUMERIK front end its variables,
//! frames and cycles) and hands the controller one [`CommandBlock`] per
//! block: typed values in the kernel's units (mm, degrees, mm/min,
//! seconds), every language rule already applied (a Siemens `G70` inch
//! value is mm here, a `CR=` radius is a radius, a cycle is its moves).
//! No control-specific text reaches the controller: no letters, no G or M
//! numbers of a language, only functions. The controller carries a block
//! out as one unit, as it does a FANUC block: on an alarm nothing of it
//! happened.
//!
//! The FANUC family's words reach the same functions through
//! [`crate::Controller::execute`]; see ARCHITECTURE.md, "Front ends".

use fiveaxis_gcode::Span;
use fiveaxis_machine::{MAX_AXES, Vec3};
use nalgebra::Rotation3;

use crate::modal::{CuttingMode, Distance, FeedMode, MotionMode, Plane, TcpcType};

/// One block of commands, reused from block to block (its buffer is kept:
/// no allocation per block once it has grown).
#[derive(Clone, Debug, Default)]
pub struct CommandBlock {
    /// The line of the block in its program, for segments and alarms.
    pub line: u32,
    /// The block number, when written.
    pub number: Option<u32>,
    /// The commands, in the order the control carries them out.
    pub commands: Vec<Command>,
}

impl CommandBlock {
    /// Empties the block for the next line, keeping its buffer.
    pub fn clear(&mut self, line: u32) {
        self.line = line;
        self.number = None;
        self.commands.clear();
    }
}

/// How one target coordinate is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetMode {
    /// As the block's distance mode says.
    Modal,
    /// Absolute, whatever the distance mode.
    Absolute,
    /// Incremental, whatever the distance mode.
    Incremental,
    /// A rotary axis, absolute, the shorter way round.
    Shortest,
    /// A rotary axis, absolute, turning in the positive direction.
    Positive,
    /// A rotary axis, absolute, turning in the negative direction.
    Negative,
}

/// A target coordinate of one axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    /// mm for a linear axis, degrees for a rotary one.
    pub value: f64,
    /// How it is read.
    pub mode: TargetMode,
    /// Where it is written.
    pub span: Span,
}

/// Which frames a move leaves out (for this block only).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Suppress {
    /// None: the move is in the workpiece coordinates.
    #[default]
    Nothing,
    /// Every frame and work offset: the targets are machine coordinates
    /// of the tool tip, the tool length in force still applied (SINUMERIK
    /// `G53`, `G153`, `SUPA` with machine data G53_TOOLCORR = 0, its
    /// default: 840D ISO milling manual 04.07 §3.1.1).
    Frames,
    /// Frames, offsets and the tool length: the targets are the machine
    /// axes' own positions (a cycle's retract and swivel moves).
    Axes,
}

/// A move: where each named axis goes, and how the path gets there (the
/// interpolation in force, [`Command::Interpolation`]).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Move {
    /// Targets by joint index (machine-file axis order).
    pub targets: [Option<Target>; MAX_AXES],
    /// A circle's centre, from its start point (per axis of the machine's
    /// X, Y, Z), mm; `None` where not given (0).
    pub center: [Option<f64>; 3],
    /// The centre is given in absolute workpiece coordinates instead.
    pub center_absolute: bool,
    /// A circle's radius (negative: the sweep exceeds 180°), mm.
    pub radius: Option<f64>,
    /// Whole turns a helix makes beyond the last part turn.
    pub turns: Option<u32>,
    /// The tool direction at the end point in the workpiece frame (under
    /// tool centre point control by vector), not necessarily unit.
    pub tool_vector: Option<[f64; 3]>,
    /// A circle in space through the start and the end point (SINUMERIK
    /// `CIP` whose three points do not lie in a plane parallel to the
    /// working plane); the targets are then absolute.
    pub circle: Option<SpaceCircle>,
    /// Frames left out for this move.
    pub suppress: Suppress,
    /// Where the block's words are, for alarms about the move as a whole.
    pub span: Span,
}

/// A circle in space, in the program's coordinates (those of the frames
/// in force, before them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpaceCircle {
    /// The centre, absolute, mm.
    pub center: Vec3,
    /// The unit normal the circle turns about, counter-clockwise seen
    /// from its tip.
    pub normal: Vec3,
    /// The angle swept from the start to the end point, radians, 0 to 2π.
    pub sweep: f64,
}

/// Which side of the contour the tool runs on under radius compensation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CutterSide {
    /// No radius compensation.
    Off,
    /// Left of the contour.
    Left,
    /// Right of the contour.
    Right,
}

/// A programmable frame: applied to programmed points as
/// `translation + rotation · (scale ⊙ mirror ⊙ p)` before the work
/// offset (the SINUMERIK order of a frame's components, ONE p309, p316:
/// mirror, scale, rotation, translation from the program outwards).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// The origin of the frame in the work coordinate system, mm.
    pub translation: Vec3,
    /// The frame's axes in the work coordinate system.
    pub rotation: Rotation3<f64>,
    /// Shifts of the axes beyond X, Y, Z (by joint index), degrees or mm.
    pub axis_shift: [f64; MAX_AXES],
    /// Scale factors of X, Y, Z (1: none).
    pub scale: [f64; 3],
    /// X, Y, Z mirrored (the coordinate's sign reversed).
    pub mirror: [bool; 3],
}

impl Frame {
    /// The neutral frame.
    pub const IDENTITY: Frame = Frame {
        translation: Vec3::new(0.0, 0.0, 0.0),
        rotation: Rotation3::from_matrix_unchecked(nalgebra::Matrix3::new(
            1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0,
        )),
        axis_shift: [0.0; MAX_AXES],
        scale: [1.0; 3],
        mirror: [false; 3],
    };

    /// A frame of a translation and a rotation only.
    pub fn rigid(translation: Vec3, rotation: Rotation3<f64>) -> Frame {
        Frame {
            translation,
            rotation,
            ..Frame::IDENTITY
        }
    }

    /// Whether the frame changes nothing.
    pub fn is_identity(&self) -> bool {
        self.is_rigid_identity()
            && self.axis_shift.iter().all(|&s| s == 0.0)
            && self.scale == [1.0; 3]
            && self.mirror == [false; 3]
    }

    /// Whether its translation and rotation change nothing.
    pub fn is_rigid_identity(&self) -> bool {
        self.translation == Vec3::zeros() && self.rotation == Rotation3::identity()
    }

    /// Whether it scales or mirrors.
    pub fn scales(&self) -> bool {
        self.scale != [1.0; 3] || self.mirror != [false; 3]
    }

    /// `self : inner` (the SINUMERIK chain operator): `inner` acts inside
    /// `self`. Scale and mirror of `self` carry `inner`'s translation;
    /// `inner`'s own scale and mirror multiply in (exact for a uniform
    /// scale and an inner frame without rotation, as the control keeps
    /// a frame's components apart: K2).
    pub fn then(&self, inner: &Frame) -> Frame {
        let mut t = inner.translation;
        for k in 0..3 {
            t[k] *= self.scale[k] * if self.mirror[k] { -1.0 } else { 1.0 };
        }
        let mut axis_shift = self.axis_shift;
        for (a, s) in axis_shift.iter_mut().zip(inner.axis_shift) {
            *a += s;
        }
        Frame {
            translation: self.translation + self.rotation * t,
            rotation: self.rotation * inner.rotation,
            axis_shift,
            scale: [0, 1, 2].map(|k| self.scale[k] * inner.scale[k]),
            mirror: [0, 1, 2].map(|k| self.mirror[k] != inner.mirror[k]),
        }
    }
}

impl Default for Frame {
    fn default() -> Self {
        Self::IDENTITY
    }
}

/// Which work offset (settable frame) is in force.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WorkOffset {
    /// None: work zero at machine zero (SINUMERIK `G500` with a null
    /// frame 0).
    Null,
    /// The n-th of the offsets file's work offsets G54… (0-based).
    Standard(u8),
    /// The n-th of the extended work offsets (1-based).
    Extended(u8),
}

/// Which work offset of the offset memory a data setting writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OffsetMemory {
    /// The external work offset, added to every work coordinate system.
    External,
    /// G54 … G59 (0 … 5).
    Standard(u8),
    /// The extended work offsets (1-based: G54.1 P1 …, Haas G154 P1 …).
    Extended(u8),
}

/// One value of a tool offset.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToolField {
    /// The length geometry.
    Length,
    /// The length wear.
    LengthWear,
    /// The radius geometry.
    Radius,
    /// The radius wear.
    RadiusWear,
}

/// A tool length a data setting gives, read as it says.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ToolLength {
    /// The length itself, mm.
    Value(f64),
    /// The length that makes the current Z, with the tool's length
    /// offset applied, read this value in the work coordinates, mm.
    Reads(f64),
    /// The length that makes the current machine Z read this value, mm.
    ReadsMachine(f64),
}

/// Data the program writes into the offset memory, in the kernel's units
/// (FANUC and Haas `G10`, LinuxCNC's `G10`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DataSetting {
    /// A work offset's values, one per named axis (by joint index); with
    /// `incremental`, added to the values held.
    WorkOffset {
        /// Which offset.
        memory: OffsetMemory,
        /// The values, mm or degrees.
        values: [Option<f64>; MAX_AXES],
        /// Added to the values held.
        incremental: bool,
    },
    /// One value of a tool offset; with `incremental`, added to it.
    ToolOffset {
        /// The offset number (1 …).
        number: u32,
        /// Which value.
        field: ToolField,
        /// The value, mm.
        value: f64,
        /// Added to the value held.
        incremental: bool,
    },
    /// A coordinate system of LinuxCNC's nine (0-based: G54 … G59.3): the
    /// named axes' origin (`at_position`: put where the current position
    /// reads the values) and the rotation about Z.
    CoordinateSystem {
        /// Which system, 0-based.
        system: usize,
        /// The values, mm or degrees, by joint index.
        values: [Option<f64>; MAX_AXES],
        /// The rotation of the system about Z, degrees.
        rotation: Option<f64>,
        /// The values are where the current position is, not the origin.
        at_position: bool,
    },
    /// A tool table entry: its length and radius (their wear cleared).
    ToolTable {
        /// The tool number.
        number: u32,
        /// The length.
        length: Option<ToolLength>,
        /// The radius, mm.
        radius: Option<f64>,
    },
}

/// One command to the controller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    /// The interpolation of the following moves (rapid, line, circle).
    Interpolation(MotionMode),
    /// The working plane (circles, radius compensation, cycles).
    Plane(Plane),
    /// Absolute or incremental targets.
    Distance(Distance),
    /// How feeds are read: per minute, per revolution, inverse time.
    FeedMode(FeedMode),
    /// Exact stop or continuous path (modal).
    PathMode(CuttingMode),
    /// This block ends in an exact stop.
    ExactStop,
    /// The path feed, mm/min (per revolution: mm/rev; inverse time: 1/min).
    Feed {
        /// The value.
        value: f64,
        /// Where it is written.
        span: Span,
    },
    /// The spindle speed, rev/min.
    SpindleSpeed(f64),
    /// A function of the machine's M-function table (spindle, coolant,
    /// tool change, stops, program end, builder functions), by number.
    MFunction {
        /// The number.
        number: u16,
        /// Where it is written.
        span: Span,
    },
    /// A tool is selected (the next tool change puts it in the spindle).
    ToolSelect {
        /// The tool number (a named tool: its number in the offsets file).
        tool: u32,
        /// Where it is written.
        span: Span,
    },
    /// The offset memory whose length (along the tool) and radius are in
    /// force; 0 ends them. The axes do not move for the change: the next
    /// programmed position takes it in.
    ToolOffset {
        /// The offset number.
        number: u32,
        /// Where it is written.
        span: Span,
    },
    /// A retract along the tool axis, away from the workpiece, at rapid
    /// and in machine coordinates: by `distance` mm, or (`None`) as far as
    /// the linear axes travel together (SINUMERIK CYCLE800 `_FR` 4 / 5,
    /// HEIDENHAIN `M140 MB`, `PLANE … MB`).
    Retract {
        /// How far, mm; `None`: to the end of the travel.
        distance: Option<f64>,
        /// Where it is written.
        span: Span,
    },
    /// Deltas on the length and radius of the offset memory in force, mm
    /// (HEIDENHAIN `TOOL CALL … DL DR`): they hold until the next tool
    /// call gives others.
    ToolDelta {
        /// Added to the tool length.
        length: f64,
        /// Added to the tool radius.
        radius: f64,
    },
    /// Radius compensation on one side, or off.
    Radius {
        /// The side.
        side: CutterSide,
        /// Where it is written.
        span: Span,
    },
    /// The work offset in force.
    WorkOffset(WorkOffset),
    /// The programmable frame, replaced whole.
    ProgrammableFrame(Frame),
    /// A settable frame written by the program (`$P_UIFR[n]`) in place of
    /// the work offset: the work zero and axes in machine coordinates, or
    /// none (the work offset of [`Command::WorkOffset`] holds).
    SettableFrame(Option<Frame>),
    /// The tool frame (SINUMERIK `TOFRAME` / `TOROT`): a rotation between
    /// the swivel frame and the programmable frame, or none.
    ToolFrame(Option<Frame>),
    /// The workpiece coordinates turn with the table's rotary axes
    /// (SINUMERIK `PAROT`), or stay with the machine (`PAROTOF`).
    PartFrame(bool),
    /// The swivel frame (a tilted working plane): its frame in the work
    /// coordinate system, or none.
    SwivelFrame(Option<Frame>),
    /// Turn the rotary axes so that the tool stands along the Z axis of
    /// the frames in force (the swivel cycle's positioning), choosing
    /// the solution whose first rotary axis is higher (`true`) or lower.
    /// The linear axes stay (`keep_tip` false: the tool tip moves with
    /// the turn) or follow so that the tool tip stays on the workpiece
    /// (`keep_tip` true: HEIDENHAIN `PLANE … MOVE`).
    AlignTool {
        /// Prefer the higher angle of the first rotary axis (`None`: the
        /// machine's rule for choosing a rotary solution).
        higher: Option<bool>,
        /// The tool tip stays where it is on the workpiece.
        keep_tip: bool,
        /// Where it is written.
        span: Span,
    },
    /// Tool centre point control on (with its orientation mode) or off.
    Tcp {
        /// On and how orientations are given, or off.
        mode: Option<TcpcType>,
        /// Where it is written.
        span: Span,
    },
    /// How tool centre point control turns the tool between block ends:
    /// on the great circle between the two directions (SINUMERIK
    /// `ORIVECT` / `ORIPLANE`; FANUC's tool posture control), or with the
    /// rotary axes linear (`ORIAXES`). Holds for the TCPC in force and
    /// the next one.
    OrientationPath {
        /// On the great circle.
        great_circle: bool,
    },
    /// The control's path smoothing and look-ahead for high-speed
    /// machining on or off, with its contour tolerance (SINUMERIK
    /// `CYCLE832`; FANUC's `G05.1 Q1`): speed, not path, kept in the modal
    /// state (`Modal::accuracy`).
    PathSmoothing {
        /// On.
        on: bool,
        /// The contour tolerance, mm, when given.
        tolerance: Option<f64>,
    },
    /// A dwell, seconds.
    Dwell {
        /// The time.
        seconds: f64,
        /// Where it is written.
        span: Span,
    },
    /// Data written into the offset memory.
    DataSetting(DataSetting),
    /// A move (at most one per block, the last command).
    Move(Move),
}
