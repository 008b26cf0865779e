//! The controller: the only place whose state changes block by block.
//!
//! [`Controller::execute`] takes one block and yields the segments it moves
//! through, or the alarm it stops with, and tells the runner what to do
//! next ([`Flow`]). Functions follow the FANUC Series 30i/16 operator's
//! manuals; where a control family differs, [`crate::dialect`] says how.

use fiveaxis_gcode::{Block, Span};
use fiveaxis_machine::{Control, Joints, MAX_AXES, Machine, Offsets, SetupError, Side, Vec3};

use crate::alarm::{Alarm, Condition};
use crate::command::CutterSide;
use crate::command::{DataSetting, OffsetMemory, ToolField};
use crate::dialect::Dialect;
use crate::fanuc::{
    AccuracyCode, AddedLength, Classify, FeatureCode, GCodes, LengthCode, OneShot, Rules, Words,
};
use crate::modal::{CuttingMode, Distance, LengthMode, Modal, MotionMode, TcpcType, Units};
use crate::reach;
use crate::segment::{Arc, Motion, Path, Segment, TipPath};
use linuxcnc::NgcMotion;

mod commands;
mod comp3d;
mod coordinates;
mod cutter_c;
mod cycles;
pub(crate) mod engrave;
mod haas;
mod linuxcnc;
mod m_codes;
mod motion;
mod operands;
mod plain;
mod splines;
mod system_vars;
mod tcpc;
mod threading;

pub(crate) use coordinates::{MIRROR, POLAR, ROTATION, SCALING};
pub(crate) use cycles::Cycle;
pub use cycles::{MAX_CYCLE_SEGMENTS, PECK_CLEARANCE, PECK_RETRACT};
pub use engrave::SERIAL_VARIABLE;
pub(crate) use linuxcnc::NgcMotion as NgcMotionMode;
pub use m_codes::ProgramStop;
use motion::arc_sweep;
pub use system_vars::SystemVarFault;
pub use tcpc::inclined;

/// Millimetres in an inch.
/// Distance under which two points count as the same (full circles, G27).
pub const POSITION_TOLERANCE: f64 = 1e-6;
/// Largest difference between the start and end radius of an arc (FANUC
/// No.3410), mm.
pub const ARC_RADIUS_TOLERANCE: f64 = 0.02;
/// How far from its reference position G27 accepts an axis (the in-position
/// width), mm or degrees.
pub const REFERENCE_CHECK_TOLERANCE: f64 = 0.001;

/// What the runner does after a block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flow {
    /// Go on with the next block.
    Next,
    /// The program ended (M02, M30).
    End,
    /// M98: call program `program` `repeats` times.
    Call {
        /// Program number (the `O` number).
        program: u32,
        /// How many times.
        repeats: u32,
    },
    /// Haas M97: call the blocks from sequence number `sequence` of the
    /// running program, `repeats` times, up to their M99.
    LocalCall {
        /// The sequence (N) number the subprogram starts at.
        sequence: u32,
        /// How many times.
        repeats: u32,
    },
    /// M99: return to the caller, at sequence number `sequence` if given.
    Return {
        /// `M99 P…`: the sequence number to return to.
        sequence: Option<u32>,
    },
}

/// Controller state besides the modal groups. Plain data (`Copy`): a
/// block saves it whole, to put it back on an alarm, in one copy.
#[derive(Clone, Copy, Debug)]
struct State {
    modal: Modal,
    /// LinuxCNC: the G28 and G30 positions (`#5161`…, `#5181`…), machine
    /// coordinates; they start as the machine file's reference positions
    /// 1 and 2 and change with G28.1 / G30.1 or the parameters.
    homes: [Joints; 2],
    /// LinuxCNC G43.1: the tool length offset given in the program (it
    /// replaces the tool's until G43 or G49).
    /// Deltas on the offset memory's length and radius the program gives
    /// with its tool call (HEIDENHAIN `TOOL CALL … DL DR`), mm.
    tool_delta: [f64; 2],
    dynamic_length: Option<f64>,
    /// The tilted working plane's feature frame (G68.2), if one is in force.
    feature: Option<coordinates::Feature>,
    /// A G68.2 P2 / P3 definition whose blocks are still coming.
    feature_pending: Option<coordinates::Pending>,
    /// LinuxCNC TWP remap: the plane G68.2 / G68.3 / G68.4 defined, in
    /// force (as `feature`) only from G53.x (`coordinates/twp.rs`).
    twp: Option<coordinates::Feature>,
    /// Current machine position (rollover axes unwrapped).
    joints: Joints,
    /// Active H number (0: none).
    h: u32,
    /// The last H number other than 0: the tool of a program that never
    /// changes tools, still in the spindle after G49.
    length_tool: u32,
    /// LinuxCNC: the TCP kinematics are switched on (`tcpc_on` M code,
    /// M428 in the sim configurations).
    kinematics_tcp: bool,
    /// LinuxCNC: G43 is in force (G49 not), whichever kinematics run.
    length_on: bool,
    /// LinuxCNC `tcpc_at_start`: the TCP kinematics are still to be
    /// switched on, with the first block.
    kinematics_pending: bool,
    /// LinuxCNC: the H number G49 set aside under the TCP kinematics (where
    /// G49 runs them with H0), given back by a G43 without H.
    h_before_g49: Option<u32>,
    /// Active D number.
    d: u32,
    /// Last F word, in internal units (mm/min, mm/rev or 1/min).
    feed: f64,
    /// Spindle speed, rev/min.
    spindle_speed: f64,
    /// Spindle turning (M03/M04).
    spindle_on: bool,
    /// Selected tool (T).
    tool: u32,
    /// The last M code given (`#4113`), as a number (`M98` is 98).
    last_m: Option<f64>,
    /// The last sequence number read (`N`, `#4114`).
    sequence: Option<u32>,
    /// The tool in the spindle (the selected tool at the last tool change).
    spindle_tool: u32,
    /// Coolant on.
    coolant: bool,
    /// Rigid tapping commanded (M29) for the next G84 / G74; cleared by G80.
    rigid_tap: bool,
    /// Clamped rotary axes, by rotary index.
    clamped: [Option<m_codes::Clamp>; 2],
    /// G92 shift of the linear axes.
    shift: Vec3,
    /// G92 shift of each axis beyond X, Y, Z (by joint index).
    axis_shift: Joints,
    /// LinuxCNC: the work offsets of the axes beyond X, Y, Z in each of its
    /// nine coordinate systems (G10 L2 / L20 with A, B, C words; by joint
    /// index). The offset memory holds X, Y, Z only.
    rotary_work: [Joints; 9],
    /// LinuxCNC: the XY rotation of each of its nine coordinate systems
    /// about Z, degrees (`G10 L2 R`, #5230…).
    xy_rotation: [f64; 9],
    /// LinuxCNC: its group-1 modes beyond G0–G3 (G5, G5.1, G33, G33.1,
    /// G76) in force.
    ngc_motion: Option<linuxcnc::NgcMotion>,
    /// LinuxCNC G5: the end tangent offset (P, Q) of the last cubic, which
    /// a following G5 without I, J continues.
    spline_tangent: Option<[f64; 2]>,
    /// LinuxCNC: the G92 shift kept in parameters #5211–#5219, which
    /// G92.2 leaves and G92.3 applies again.
    g92_kept: (Vec3, Joints),
    /// Tool centre point control data of the running mode.
    tcpc: tcpc::TcpcState,
    /// Three-dimensional tool compensation.
    comp3d: comp3d::Comp3d,
    /// Workpiece setup error correction in force (G54.4), identity when off.
    setup: SetupError,
    /// The data set selected by G54.4 (0: off).
    setup_set: u32,
    /// The side of the tilt axis at the G54.4 block (keep-tilt-sign rule).
    setup_tilt_sign: f64,
    /// Under G54.4 and TCPC type 1, the programmed rotary angles (the
    /// attitude on the ideal workpiece), which differ from the machine's.
    setup_angles: Option<[f64; 2]>,
    /// Canned cycle (groups 09, 10) and its drilling data.
    cycle: cycles::CycleState,
    /// G52, G16, G51.1, G51, G68 (`controller/coordinates/program_transforms.rs`).
    frames: coordinates::Frames,
    /// A command front end's choice of how TCPC turns the tool (great
    /// circle or rotary axes linear); `None`: the machine file's
    /// `tool_posture_control`.
    orientation_path: Option<bool>,
    /// Haas: the serial number G47 P1 engraves next (macro variable
    /// `#599`, which the runner keeps; `None`: vacant).
    serial: Option<f64>,
}

/// The controller of one run.
#[derive(Debug)]
pub struct Controller<'m> {
    machine: &'m Machine,
    offsets: Offsets,
    dialect: Dialect,
    state: State,
    /// The FANUC family's front end: the block's words, read on the
    /// controller's typed questions (`crate::fanuc`).
    fanuc: Words,
    /// The operands of a block of commands (`operands.rs`).
    operands: operands::Operands,
    /// Address letters of the machine's axes, in joint order.
    axis_letters: [u8; MAX_AXES],
    /// The tool posture law worked out for the block being executed (kept
    /// out of `state`, which is copied for every block).
    block_posture: Option<crate::segment::Posture>,
    /// G09 in the block being executed (its segments end in an exact stop).
    block_exact_stop: bool,
    /// A block of commands asks for an exact stop at its end.
    pending_exact_stop: bool,
    /// The settable, swivel, tool and programmable frames of the command
    /// front ends (`commands.rs`), composed into the state's feature
    /// frame. Kept out of `state`, which is copied for every block: a
    /// block of commands saves and restores them itself.
    neutral: commands::NeutralFrames,
    /// The whole turns a block of commands gives its circle.
    block_turns: Option<u32>,
    /// The block being executed chose rotary axes from a tool direction
    /// (set where the inverse kinematics is asked; `Segment::rotary_chosen`).
    block_chose_rotary: std::cell::Cell<bool>,
    /// Cutter compensation C: the engine and the blocks it holds.
    cutter: cutter_c::CutterC,
    /// The optional-stop switch: M01 stops like M00.
    optional_stop: bool,
    /// Whether the last block stops a real control.
    stop: Option<ProgramStop>,
    /// The highest tool offset number of the offsets file, when it has
    /// tools: T numbers beyond it are an alarm.
    tool_memory: Option<u32>,
    /// Soft limits lifted (`RunOptions::lift_soft_limits`): moves beyond
    /// them raise no alarm; `fiveaxis check` reports them instead.
    limits_lifted: bool,
    /// The first comment of the block being executed (Haas G47 engraves
    /// it), and its columns; the buffer is kept from block to block.
    comment: Vec<u8>,
    comment_span: Option<Span>,
    /// Axis words written without a decimal point where they count in
    /// least input increments, when asked for
    /// ([`Controller::count_words_without_point`]); `None`: not counted.
    without_point: Option<WordsWithoutPoint>,
    /// Plain blocks take the plain path (`plain.rs`); off only to test
    /// it against the general path.
    plain_path: bool,
    /// The addresses of a plain block: the axes' and F, by letter bit.
    plain_addresses: u32,
    /// The soft limits of each axis, by joint index; infinite for a
    /// rollover axis or one without limits (the machine's, laid out for
    /// the check of every segment).
    soft_limits: [(f64, f64); MAX_AXES],
}

/// Axis words a program writes without a decimal point on a control that
/// reads them in least input increments (FANUC with decimal point input
/// off: `X10` is 0.010 mm): the machine's axis addresses and I, J, K, R,
/// except those whose value is 0 (`X0` is 0 in any unit).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WordsWithoutPoint {
    /// How many (each time a block is executed).
    pub count: u64,
    /// The line of the first (0 while `count` is 0).
    pub first_line: u32,
}

/// Where the control point goes, for each axis: programmed value if the
/// block names the axis.
type Targets = [Option<f64>; MAX_AXES];

impl State {
    /// Whether this block started TCPC.
    fn tcpc_started(&self) -> bool {
        self.tcpc.startup
    }
}

impl<'m> Controller<'m> {
    /// A controller switched on: every axis at reference position 1, no
    /// compensation, power-on modal codes.
    pub fn new(machine: &'m Machine, offsets: Offsets) -> Self {
        let tool_memory = offsets.tools.keys().next_back().copied();
        Self {
            machine,
            offsets,
            tool_memory,
            limits_lifted: false,
            comment: Vec::new(),
            comment_span: None,
            without_point: None,
            plain_path: true,
            soft_limits: soft_limits(machine),
            plain_addresses: Words::letter_mask(
                machine.axis_names().map(|name| name as u8).chain([b'F']),
            ),
            optional_stop: false,
            stop: None,
            dialect: Dialect::of(machine.control),
            state: State {
                modal: Modal {
                    // A SINUMERIK starts in G500: no settable frame (its
                    // reset value of group 8, MD20150; a program selects
                    // G54… itself).
                    work: if machine.control == fiveaxis_machine::Control::Sinumerik {
                        crate::modal::WorkSelect::Null
                    } else {
                        crate::modal::WorkSelect::Standard(0)
                    },
                    ..Modal::power_on(machine.params.input_unit)
                },
                dynamic_length: None,
                tool_delta: [0.0; 2],
                homes: [machine.params.reference_1, machine.params.reference_2],
                feature: None,
                feature_pending: None,
                twp: None,
                joints: machine.params.reference_1,
                h: 0,
                length_tool: 0,
                kinematics_tcp: false,
                length_on: false,
                kinematics_pending: machine.params.tcpc_at_start,
                h_before_g49: None,
                d: 0,
                feed: 0.0,
                spindle_speed: 0.0,
                spindle_on: false,
                tool: 0,
                last_m: None,
                sequence: None,
                spindle_tool: 0,
                coolant: false,
                rigid_tap: false,
                clamped: [None; 2],
                shift: Vec3::zeros(),
                axis_shift: [0.0; MAX_AXES],
                rotary_work: [[0.0; MAX_AXES]; 9],
                xy_rotation: [0.0; 9],
                ngc_motion: None,
                spline_tangent: None,
                g92_kept: (Vec3::zeros(), [0.0; MAX_AXES]),
                tcpc: tcpc::TcpcState::default(),
                comp3d: comp3d::Comp3d::default(),
                setup: SetupError::IDENTITY,
                setup_set: 0,
                setup_tilt_sign: 1.0,
                setup_angles: None,
                cycle: cycles::CycleState::default(),
                frames: coordinates::Frames::default(),
                serial: None,
                orientation_path: None,
            },
            fanuc: Words::new(machine),
            operands: operands::Operands::default(),
            block_posture: None,
            block_exact_stop: false,
            pending_exact_stop: false,
            neutral: commands::NeutralFrames::default(),
            block_turns: None,
            block_chose_rotary: std::cell::Cell::new(false),
            cutter: cutter_c::CutterC::new(machine.params.cutter_startup_b),
            axis_letters: {
                let mut letters = [0u8; MAX_AXES];
                for (slot, name) in letters.iter_mut().zip(machine.axis_names()) {
                    *slot = name as u8;
                }
                letters
            },
        }
    }

    /// The machine this controller drives.
    pub fn machine(&self) -> &'m Machine {
        self.machine
    }

    /// Current machine position.
    pub fn joints(&self) -> Joints {
        self.state.joints
    }

    /// Current modal state.
    pub fn modal(&self) -> Modal {
        self.state.modal
    }

    /// Offset memory as it stands (G10 changes it).
    pub fn offsets(&self) -> &Offsets {
        &self.offsets
    }

    /// The control family.
    pub fn control(&self) -> Control {
        self.machine.control
    }

    /// Turns the optional-stop switch on or off (off at power-on). With it
    /// on, M01 (or a code declared `"optional_stop"`) is a program stop
    /// like M00: [`Controller::program_stop`] reports it; the run goes on.
    pub fn set_optional_stop(&mut self, on: bool) {
        self.optional_stop = on;
    }

    /// Lifts the soft limits: no move raises an over-travel alarm (a
    /// verifier goes on and measures the excursions from the segments).
    pub fn lift_soft_limits(&mut self, lifted: bool) {
        self.limits_lifted = lifted;
    }

    /// Whether a function is in force that makes the machine positions
    /// of a block depend on the machine's kinematics and the tool: TCPC
    /// (G43.4 / G43.5, Haas G234, LinuxCNC's TCP kinematics), length
    /// compensation along the tool axis (G43.1), a feature frame (the
    /// tilted working plane G68.2 / G68.3 / G68.4, the 3-D coordinate
    /// conversion, Haas G254) or the workpiece setup error (G54.4). A
    /// program that never has one is already a machine-axis program
    /// (what `fiveaxis post` leaves unchanged).
    pub fn kinematic_mode(&self) -> bool {
        matches!(
            self.state.modal.length,
            LengthMode::Tcpc(_) | LengthMode::ToolAxis
        ) || self.state.kinematics_tcp
            || self.state.feature.is_some()
            || self.state.setup_set != 0
    }

    /// From now on, counts the axis words written without a decimal point
    /// while such words are read in least input increments (decimal point
    /// input off, No.3401#0 DPI = 0): what `fiveaxis check` reports.
    /// Nothing is counted on a control that reads them as whole units.
    pub fn count_words_without_point(&mut self) {
        self.without_point = Some(WordsWithoutPoint::default());
    }

    /// The count of [`Controller::count_words_without_point`], if asked for.
    pub fn words_without_point(&self) -> Option<WordsWithoutPoint> {
        self.without_point
    }

    /// Counts the block's axis words without a decimal point (only when
    /// asked for and read in increments).
    fn count_without_point(&mut self, block: &Block) {
        if self.without_point.is_none() || self.rules().calculator {
            return;
        }
        let found = crate::fanuc::words_without_point(
            block,
            &self.axis_letters[..self.machine.axis_count()],
        );
        if let Some(counted) = &mut self.without_point
            && found > 0
        {
            if counted.count == 0 {
                counted.first_line = block.line;
            }
            counted.count += found;
        }
    }

    /// Whether the last block executed would stop a real control (M00, M01
    /// with the optional-stop switch on). A verification run goes on.
    pub fn program_stop(&self) -> Option<ProgramStop> {
        self.stop
    }

    /// The selected tool (last T number).
    pub fn tool(&self) -> u32 {
        self.state.tool
    }

    /// The tool in the spindle: the selected tool at the last tool change.
    pub fn spindle_tool(&self) -> u32 {
        self.state.spindle_tool
    }

    /// The tool length offset applied now (0 under G49).
    pub fn applied_tool_length(&self) -> f64 {
        self.tool_length()
    }

    /// LinuxCNC's G28 (`n` = 0) or G30 (1) position of machine axis `i`.
    pub fn home(&self, n: usize, i: usize) -> Option<f64> {
        self.state.homes.get(n).and_then(|h| h.get(i)).copied()
    }

    /// Sets LinuxCNC's G28 (`n` = 0) or G30 (1) position of axis `i`.
    pub fn set_home(&mut self, n: usize, i: usize, value: f64) {
        if let Some(slot) = self.state.homes.get_mut(n).and_then(|h| h.get_mut(i)) {
            *slot = value;
        }
    }

    /// Haas: the serial number G47 P1 engraves next (`#599`; `None` when
    /// vacant).
    pub fn serial_number(&self) -> Option<f64> {
        self.state.serial
    }

    /// Haas: sets the serial number G47 P1 engraves next (the runner
    /// passes `#599` before a G47 block).
    pub fn set_serial_number(&mut self, value: Option<f64>) {
        self.state.serial = value;
    }

    /// Whether `block` engraves (Haas G47), so that the runner passes it
    /// the serial number `#599`.
    pub fn engraves(&self, block: &Block) -> bool {
        self.dialect.haas_codes && crate::fanuc::engraves(block)
    }

    /// Whether the spindle turns (M03 / M04 and not stopped since).
    pub fn spindle_on(&self) -> bool {
        self.state.spindle_on
    }

    /// The programmed position of every axis now: the tool tip (or the
    /// gauge point without a length offset) in the frames in force.
    pub fn programmed_position(&self) -> Joints {
        if self.cutter.routing() {
            return self.cutter.point;
        }
        self.programmed(&self.state.joints)
    }

    /// The feed in force (mm/min, mm/rev or 1/min as the feed mode says).
    pub fn feed(&self) -> f64 {
        self.state.feed
    }

    /// Spindle speed, rev/min (last S).
    pub fn spindle_speed(&self) -> f64 {
        self.state.spindle_speed
    }

    /// Whether coolant is on.
    pub fn coolant(&self) -> bool {
        self.state.coolant
    }

    /// Whether rigid tapping is commanded for the next G84 / G74.
    pub fn rigid_tap(&self) -> bool {
        self.state.rigid_tap
    }

    /// The rotary axes clamped by M code, by name.
    pub fn clamped_axes(&self) -> impl Iterator<Item = char> + '_ {
        self.machine
            .rotary
            .iter()
            .zip(self.state.clamped)
            .filter(|(_, c)| c.is_some())
            .map(|(r, _)| r.name)
    }

    /// An alarm for the current block.
    fn alarm(&self, condition: Condition, span: Option<Span>, message: String) -> Alarm {
        self.fanuc.alarm(condition, span, message)
    }

    /// Executes one block: appends its segments to `out` and says what
    /// comes next. On an alarm nothing is appended and the state is as
    /// before the block, except for offset data written by G10 before the
    /// failing part.
    pub fn execute(&mut self, block: &Block, out: &mut Vec<Segment>) -> Result<Flow, Alarm> {
        let base = out.len();
        self.stop = None;
        if self.without_point.is_some() {
            self.count_without_point(block);
        }
        self.operands.active = false;
        self.fanuc.load(block)?;
        if self.dialect.haas_codes {
            // Haas G47 engraves the block's comment.
            self.comment.clear();
            self.comment.extend_from_slice(&block.comment);
            self.comment_span = block.comment_span;
        }
        if let Some(mode) = self.plain_block() {
            return self.execute_plain(mode, block.sequence, base, out);
        }
        let saved = self.state;
        if let Some(n) = block.sequence {
            self.state.sequence = Some(n);
        }
        let result = self.execute_loaded(base, out);
        if result.is_err() {
            self.state = saved;
            out.truncate(base);
        }
        result
    }

    fn execute_loaded(&mut self, base: usize, out: &mut Vec<Segment>) -> Result<Flow, Alarm> {
        // A program-number line is a label (Haas: O00001 to O99999).
        self.fanuc.program_number(self.dialect.haas_codes)?;
        let mut codes = self.classify_g_codes()?;
        self.block_exact_stop = codes.exact_stop || self.pending_exact_stop;
        self.block_chose_rotary.set(false);
        self.feature_restrictions(&codes)?;
        self.m_code_length(&mut codes)?;
        self.apply_modal(&codes)?;
        // LinuxCNC: the coordinate system chosen brings its rotation.
        self.refresh_xy_rotation();
        self.apply_cycle_codes(&codes)?;
        // LinuxCNC: in a G73 / G83 block without G41 / G42, D is the
        // cycle's peck clearance, not a tool number (controller/cycles.rs).
        let d_for_cycle = self.dialect.rs274ngc
            && codes.cutter.is_none()
            && matches!(
                self.state.cycle.cycle,
                Some(cycles::Cycle::G73 | cycles::Cycle::G83)
            );
        self.apply_values(d_for_cycle)?;
        // G69 (Haas G269) ends the tilted working plane before the block's
        // move, which is then in the workpiece frame; Haas G254 / G255
        // switch the dynamic work offset the same way.
        if let Some((FeatureCode::Cancel, _, _)) = codes.feature
            && self.feature().is_some_and(|f| !f.is_dwo())
        {
            self.state.feature = None;
        }
        if self.twp_remap() && matches!(codes.feature, Some((FeatureCode::Cancel, _, _))) {
            self.twp_cancel();
        }
        if let Some((on, span)) = codes.dwo {
            self.dwo_command(on, span)?;
        }
        self.smoothness(codes.smoothness)?;
        // Where the program stands, in the (possibly new) work coordinate
        // system, under the length offset in force before this block.
        let from = if self.cutter.routing() {
            // Cutter compensation C holds blocks back: the program stands
            // at the end of the last block read, not where the tool is.
            self.cutter.point
        } else {
            self.programmed(&self.state.joints)
        };
        // The same point as the tip in the work coordinate system that
        // does not turn: where a block leaving TCPC starts from.
        let mut from = from;
        if let Some(angles) = self.state.setup_angles {
            // G54.4 under TCPC type 1: the program stands at its own angles.
            for (k, angle) in angles
                .into_iter()
                .enumerate()
                .take(self.machine.rotary.len())
            {
                let i = self.machine.rotary_index(k);
                from[i] = angle - self.rotary_shift(i);
            }
        }
        let was_tcpc = self.tcpc_type().is_some();
        let plain_from =
            (was_tcpc && codes.length.is_some()).then(|| self.plain_programmed(&self.state.joints));
        let flow = self.m_codes()?;
        let change = self.apply_length(&codes)?;
        let from = if change == LengthChange::InPlace {
            // A cancel or start-up without movement (Mitsubishi G44,
            // G43.4/G43.5): the axes stay, the programmed position takes
            // the offset's place.
            self.programmed(&self.state.joints)
        } else if let Some(plain_from) = plain_from.filter(|_| self.tcpc_type().is_none()) {
            // Leaving TCPC: axes the block does not name move only by the
            // removal of the offset vector along the tool.
            plain_from
        } else {
            from
        };
        if self.tcpc_type() != Some(TcpcType::Angles) || self.state.tcpc_started() {
            self.state.setup_angles = None;
        }
        let comp_changed = self.apply_cutter(&codes)?;
        // A transform block's axis words are its centre or mirror axes.
        let framed = self.apply_frames(&codes, &from)?;
        let length_changed = change == LengthChange::Moves || comp_changed;
        self.dwo_rotary_words()?;
        if let Some((what, span, code)) = codes
            .feature
            .filter(|&(what, _, _)| what != FeatureCode::Cancel)
        {
            // G68.2 / G68.4 define the frame and move nothing: the program
            // stands where it was, in the new frame.
            if self.twp_remap() {
                self.twp_define(what, code, span)?;
            } else {
                self.feature_command(what, code, span)?;
            }
        } else if let Some(span) = codes.setup {
            if self.cutter.routing() {
                // The held block is emitted with the correction it was
                // read with.
                self.cutter_c_finish(out)?;
                self.cutter.engine.reset();
            }
            self.select_setup_error(span, &from, out)?;
        } else if !framed {
            self.block_motion(&codes, &from, length_changed, out)?;
        }
        self.end_block(base, out)?;
        Ok(flow)
    }

    /// The end of every block, on either path: every word used, no
    /// clamped axis moved, every segment from `base` on within the soft
    /// limits; then the machine stands where the last one ends.
    fn end_block(&mut self, base: usize, out: &[Segment]) -> Result<(), Alarm> {
        self.fanuc.check_all_used()?;
        self.check_clamps(&out[base..])?;
        for seg in &out[base..] {
            self.check_limits(seg).map_err(|a| at_line(a, seg.line))?;
        }
        if let Some(last) = out[base..].last() {
            self.state.joints = last.end;
        }
        Ok(())
    }

    /// The movement of a block: its group-00 function or its motion.
    fn block_motion(
        &mut self,
        codes: &GCodes,
        from: &Joints,
        length_changed: bool,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let from = *from;
        if codes.one_shot.is_none()
            && let Some(mode) = self.state.ngc_motion
        {
            return self.ngc_motion(mode, &from, out);
        }
        match codes.one_shot {
            Some((what @ (OneShot::Dwell | OneShot::DataSetting), span, _))
                if self.cutter.routing() =>
            {
                // A dwell or data setting in cutter compensation C is a
                // block without movement.
                self.one_shot(what, span, &from, out)?;
                self.cutter_c_motion(&from, false, out)?;
            }
            Some((what, span, _)) => {
                // Other group-00 functions end the compensated path here;
                // the next move starts the offset again.
                let routing = self.cutter.routing();
                let from = if routing {
                    self.cutter_c_finish(out)?;
                    self.cutter.engine.reset();
                    self.programmed(&self.state.joints)
                } else {
                    from
                };
                let before = out.len();
                self.one_shot(what, span, &from, out)?;
                if routing {
                    // The next block starts where this one left the
                    // program (a G53 / G28 move changes it).
                    let end = out[before..].last().map_or(self.state.joints, |s| s.end);
                    self.cutter.point = self.programmed(&end);
                }
            }
            None if self.cycle_active() => self.cycle_motion(codes, &from, length_changed, out)?,
            None => self.motion(&from, length_changed, out)?,
        }
        Ok(())
    }

    // ----- G codes --------------------------------------------------------

    fn classify_g_codes(&mut self) -> Result<GCodes, Alarm> {
        self.fanuc.g_codes(&Classify {
            haas: self.dialect.haas_codes,
            ngc: self.dialect.rs274ngc,
            twp: self.twp_remap(),
            comp3d: self.state.comp3d.active,
            inch_input: self.machine.params.input_unit == fiveaxis_machine::InputUnit::Inch,
            g44_cancels: self.dialect.g44_cancels,
        })
    }

    fn apply_modal(&mut self, codes: &GCodes) -> Result<(), Alarm> {
        let modal = &mut self.state.modal;
        if let Some((mode, ngc, _)) = codes.motion {
            self.state.ngc_motion = ngc;
            if ngc != Some(NgcMotion::CubicSpline) {
                self.state.spline_tangent = None;
            }
            modal.motion = mode;
        }
        if codes.cycle.is_some() {
            self.state.ngc_motion = None;
            self.state.spline_tangent = None;
        }
        if let Some(plane) = codes.plane
            && plane != self.state.modal.plane
            && self.cutter.routing()
        {
            return Err(self.alarm(
                Condition::CrcPlaneChange,
                None,
                "the plane cannot change in cutter compensation C".into(),
            ));
        }
        let modal = &mut self.state.modal;
        if let Some(plane) = codes.plane {
            modal.plane = plane;
        }
        if let Some(distance) = codes.distance {
            modal.distance = distance;
        }
        if let Some(absolute) = codes.arc_distance {
            modal.ijk_absolute = absolute;
        }
        if let Some(diameter) = codes.diameter {
            modal.diameter_mode = diameter;
        }
        if let Some(feed) = codes.feed {
            modal.feed_mode = feed;
        }
        if let Some(units) = codes.units {
            modal.units = units;
        }
        if let Some((work, _, _)) = codes.work {
            self.state.modal.work = work;
        }
        if let Some(cutting) = codes.cutting {
            if self.dialect.rs274ngc {
                self.state.modal.blend = None;
                if cutting == CuttingMode::Cutting {
                    self.blend_tolerance()?;
                }
            }
            self.state.modal.cutting = cutting;
        }
        if let Some((what, _)) = codes.accuracy {
            let accuracy = &mut self.state.modal.accuracy;
            match what {
                AccuracyCode::Contour(c) => accuracy.contour = c,
                AccuracyCode::HighPrecision(on) => accuracy.high_precision = on,
                AccuracyCode::LookAhead(on) => accuracy.look_ahead = on,
            }
        }
        if codes.canned_cancel {
            self.state.rigid_tap = false;
        }
        Ok(())
    }

    /// LinuxCNC `G43.1 axes` (g-code.adoc, G43.1): the word of the axis
    /// along the tool (Z on a mill) is the tool length offset from now
    /// on; nothing moves in this block (the next move carries it). A
    /// motion in the block, or an offset on another axis (the kernel's
    /// length offset lies along the tool), is an alarm.
    fn dynamic_length_offset(&mut self, span: Span, name: &str) -> Result<(), Alarm> {
        let rules = self.rules();
        self.state.dynamic_length = Some(self.fanuc.tool_axis_offset(span, name, &rules)?);
        Ok(())
    }

    /// LinuxCNC `G43.2 H-` or `G43.2 axes` (g-code.adoc, G43.2): the
    /// length of tool H, or the value of the word of the axis along the
    /// tool (Z on a mill), to add to the length offset in force; the
    /// caller makes the sum the offset until G43 or G49. An H the tool
    /// table lacks is the manual's error.
    fn additional_length_offset(&mut self, span: Span) -> Result<f64, Alarm> {
        let rules = self.rules();
        match self.fanuc.added_length(span, &rules)? {
            AddedLength::Value(v) => Ok(v),
            AddedLength::Tool(n, span) => match self.offsets.tools.get(&n) {
                Some(tool) => Ok(tool.length + tool.length_wear),
                None => Err(self.alarm(
                    Condition::IllegalOffsetNumber,
                    Some(span),
                    format!("G43.2 H{n}: tool {n} is not in the tool table"),
                )),
            },
        }
    }

    /// LinuxCNC `G64 P- <Q->`: the path blending tolerance P and the
    /// naive CAM tolerance Q (Q defaults to P), kept in the modal state
    /// (g-code.adoc, G64); they change speed, not the programmed path.
    fn blend_tolerance(&mut self) -> Result<(), Alarm> {
        let rules = self.rules();
        self.state.modal.blend = self.fanuc.blend_tolerance(&rules)?;
        Ok(())
    }

    /// F, S, T, D words: modal values.
    fn apply_values(&mut self, d_for_cycle: bool) -> Result<(), Alarm> {
        if !self.operands.active && !self.fanuc.has_values() {
            return Ok(());
        }
        self.op_feed()?;
        if let Some(s) = self.fanuc.spindle_speed(self.dialect.rs274ngc)? {
            self.state.spindle_speed = s;
        }
        self.op_tool()?;
        if !d_for_cycle && let Some(d) = self.fanuc.radius_offset()? {
            self.state.d = d;
        }
        Ok(())
    }

    /// Group 08 and H: returns whether the length offset vector may have
    /// changed in this block.
    fn apply_length(&mut self, codes: &GCodes) -> Result<LengthChange, Alarm> {
        let before = (self.state.modal.length, self.state.h);
        let mut in_place = false;
        self.state.tcpc.startup = false;
        let dynamic_before = self.state.dynamic_length;
        if let Some((what, span, _)) = codes.length {
            let length_before = self.tool_length();
            self.state.dynamic_length = None;
            self.state.modal.length = match what {
                LengthCode::Added => {
                    let added = self.additional_length_offset(span)?;
                    self.state.dynamic_length = Some(length_before + added);
                    LengthMode::Plus
                }
                LengthCode::HaasTcpc => {
                    self.start_haas_tcpc(span)?;
                    LengthMode::Tcpc(TcpcType::Angles)
                }
                LengthCode::Given => {
                    self.dynamic_length_offset(span, "G43.1")?;
                    LengthMode::Plus
                }
                LengthCode::ToolAxis => LengthMode::ToolAxis,
                LengthCode::Tcpc(kind) => {
                    in_place = self.start_tcpc(kind, span)? == LengthChange::InPlace;
                    LengthMode::Tcpc(kind)
                }
                LengthCode::Plus => LengthMode::Plus,
                LengthCode::OffInPlace => {
                    in_place = true;
                    LengthMode::Off
                }
                LengthCode::Minus => LengthMode::Minus,
                LengthCode::Off => LengthMode::Off,
            };
            in_place |= codes.length_in_place;
            // The H number stays modal through G49 (FANUC: #4111 keeps it;
            // a later G43 without H takes it again).
        }
        if self.fanuc.has_length_offset()
            && (self.state.modal.length != LengthMode::Off || codes.length.is_some())
            && (codes.length.is_some()
                || self.state.ngc_motion != Some(linuxcnc::NgcMotion::ThreadingCycle))
        {
            self.state.h = self.fanuc.length_offset()?.unwrap_or(0);
            self.note_length_tool();
        } else if self.dialect.rs274ngc
            && !codes.length_synthesized
            && (codes.length_from_spindle
                || codes
                    .length
                    .is_some_and(|(what, _, _)| what == LengthCode::Plus))
        {
            // LinuxCNC: G43 without H takes the tool in the spindle
            // (g-code.adoc, G43: "If H is not given, the current tool").
            self.state.h = self.state.spindle_tool;
            self.note_length_tool();
        }
        if self.dialect.rs274ngc
            && (before != (self.state.modal.length, self.state.h)
                || dynamic_before != self.state.dynamic_length)
        {
            // LinuxCNC: a new length offset moves nothing; the axes stay
            // and the program position takes the change (rs274: after
            // `G43 H1` the canonical Z differs by the offset, the machine
            // stands; g-code.adoc, G43.1: "does not cause any motion").
            in_place = true;
        }
        Ok(if in_place {
            LengthChange::InPlace
        } else if before == (self.state.modal.length, self.state.h)
            && dynamic_before == self.state.dynamic_length
            && !self.state.tcpc.startup
        {
            LengthChange::None
        } else {
            LengthChange::Moves
        })
    }

    /// Group 07: 3-D tool compensation (G41/G42 with I, J, K) or cutter
    /// compensation C. Returns whether the offset vector changed.
    fn apply_cutter(&mut self, codes: &GCodes) -> Result<bool, Alarm> {
        self.cutter.vector = None;
        if let Some((side, span)) = codes.cutter {
            let side = match side {
                CutterSide::Left if !self.starts_comp3d(codes) => Some(crate::cutter::Side::Left),
                CutterSide::Right if !self.starts_comp3d(codes) => Some(crate::cutter::Side::Right),
                _ => None,
            };
            self.select_cutter_side(side);
            if self.cutter.side.is_some() {
                self.cutter_ij_vector(span)?;
            }
        }
        self.apply_comp3d(codes)
    }

    /// Seed 001: a G41 / G42 block that omits one of I, J, K starts (or
    /// stays in) cutter compensation C; the centre words of the plane it
    /// gives (I, J in G17; I, K in G18; J, K in G19) are the I, J type
    /// vector: the offset vector at the block's end is perpendicular to
    /// that direction, on the compensation side, and no intersection with
    /// the next block is taken.
    fn cutter_ij_vector(&mut self, span: Span) -> Result<(), Alarm> {
        let arc = matches!(self.state.modal.motion, MotionMode::Cw | MotionMode::Ccw);
        if arc {
            return Ok(());
        }
        let [p, q, _] = self.state.modal.plane.axes();
        let rules = self.rules();
        if let Some([i, j]) = self.fanuc.plane_vector(p, q, span, &rules)? {
            self.cutter.vector = Some(crate::cutter::P2::new(i, j));
        }
        Ok(())
    }

    /// Whether cutter compensation C holds a block back (its look-ahead):
    /// an alarm then drops the held block.
    pub fn holds_blocks(&self) -> bool {
        self.cutter.routing()
    }

    /// The end of the program: blocks held by cutter compensation C are
    /// emitted.
    pub fn finish(&mut self, out: &mut Vec<Segment>) -> Result<(), Alarm> {
        let base = out.len();
        self.cutter_c_finish(out)?;
        for seg in &out[base..] {
            self.check_limits(seg).map_err(|a| at_line(a, seg.line))?;
        }
        Ok(())
    }

    // ----- M codes --------------------------------------------------------

    /// M98 P… L…: FANUC also reads P as four digits of repetitions then
    /// four digits of program number when it has more than four digits.
    fn call(&mut self) -> Result<Flow, Alarm> {
        let (program, repeats) = self.fanuc.program_call()?;
        Ok(Flow::Call { program, repeats })
    }

    // ----- values ---------------------------------------------------------

    /// The reading rules of the block being executed (`fanuc/values.rs`).
    fn rules(&self) -> Rules {
        Rules {
            inch: self.state.modal.units == Units::Inch,
            increment: self.machine.params.least_input_increment,
            calculator: self.machine.params.decimal_point_input || self.dialect.calculator_input,
            letters: self.axis_letters,
            axes: self.machine.axis_count(),
            linear: self.machine.linear.len(),
            polar_axis: self
                .state
                .frames
                .polar
                .then(|| self.state.modal.plane.axes()[1]),
            diameter: self.state.modal.diameter_mode,
        }
    }

    /// Axis words of the block, by joint index, marked used.
    fn axis_words(&mut self) -> Targets {
        self.op_axes()
    }

    /// The active H value (geometry + wear), mm.
    fn tool_length(&self) -> f64 {
        if let Some(length) = self.state.dynamic_length
            && self.state.modal.length == LengthMode::Plus
        {
            return length;
        }
        if self.state.modal.length == LengthMode::Off || self.state.h == 0 {
            return 0.0;
        }
        let tool = self.offsets.tool(self.state.h);
        tool.length + tool.length_wear + self.state.tool_delta[0]
    }

    /// The length offset vector at machine position `joints`: what is added
    /// to W + P to get the machine position of X, Y, Z.
    fn length_vector(&self, joints: &Joints) -> Vec3 {
        self.length_vector_for(self.state.modal.length, self.tool_length(), joints)
    }

    /// The length offset vector of mode `mode` with tool length `l`.
    fn length_vector_for(&self, mode: LengthMode, l: f64, joints: &Joints) -> Vec3 {
        let t0 = self.machine.tool_direction.into_inner();
        match mode {
            LengthMode::Off => Vec3::zeros(),
            LengthMode::Plus => l * t0,
            LengthMode::Minus => -l * t0,
            LengthMode::ToolAxis | LengthMode::Tcpc(_) => {
                let head = self.machine.chain(Side::Head, joints);
                -head.transform_point(&(-l * t0).into()).coords
            }
        }
    }

    /// Programmed position outside TCPC semantics: machine position less
    /// the work offset and the length offset vector in force.
    fn plain_programmed(&self, joints: &Joints) -> Joints {
        let mut p = self.programmed(joints);
        let lin = self.programmed_of_real(
            &(Vec3::new(joints[0], joints[1], joints[2]) - self.length_vector(joints)),
        );
        p[..3].copy_from_slice(lin.as_slice());
        p
    }

    /// The shift between the programmed and the machine position of axis
    /// `i` beyond X, Y, Z: G92's and the work offset's of that axis (on
    /// LinuxCNC the coordinate system in use; on the other controls the
    /// work offset selected, plus the external one).
    pub(super) fn rotary_shift(&self, i: usize) -> f64 {
        let work = match self.linuxcnc_system() {
            Some(k) => self.state.rotary_work[k][i],
            None if self.dialect.rs274ngc => 0.0,
            None => self.work_beyond(i),
        };
        self.state.axis_shift[i] + work
    }

    /// LinuxCNC's coordinate system in use, 0–8 (G54–G59.3), when the
    /// program reads as LinuxCNC's.
    pub(super) fn linuxcnc_system(&self) -> Option<usize> {
        if !self.dialect.rs274ngc {
            return None;
        }
        match self.state.modal.work {
            crate::WorkSelect::Standard(i) => Some(usize::from(i)),
            crate::WorkSelect::Extended(k) if (1..=3).contains(&k) => Some(5 + usize::from(k)),
            _ => None,
        }
    }

    /// LinuxCNC: the work offset of axis `letter` (A, B, C…) in coordinate
    /// system `system` (1–9), as parameters #5224… read it.
    pub fn rotary_work_offset(&self, system: usize, letter: char) -> Option<f64> {
        let i = self.machine.axis_index(letter)?;
        (i >= 3 && (1..=9).contains(&system)).then(|| self.state.rotary_work[system - 1][i])
    }

    /// Programmed position of every axis at machine position `joints`.
    fn programmed(&self, joints: &Joints) -> Joints {
        let mut p = *joints;
        let lin = if self.tcpc_type().is_some() {
            self.tcpc_programmed(joints)
        } else if self.feature().is_some() {
            self.feature_programmed(joints)
        } else {
            self.programmed_of_real(
                &(Vec3::new(joints[0], joints[1], joints[2]) - self.length_vector(joints)),
            )
        };
        p[..3].copy_from_slice(lin.as_slice());
        for (i, value) in p
            .iter_mut()
            .enumerate()
            .skip(3)
            .take(self.machine.axis_count() - 3)
        {
            *value -= self.rotary_shift(i);
        }
        p
    }

    /// Machine position for programmed position `p` (rotary axes already
    /// machine angles in `p` beyond the shift).
    fn machine_position(&self, p: &Joints) -> Joints {
        let mut joints = *p;
        for (i, value) in joints
            .iter_mut()
            .enumerate()
            .skip(3)
            .take(self.machine.axis_count() - 3)
        {
            *value += self.rotary_shift(i);
        }
        let lin = if self.tcpc_type().is_some() {
            self.tcpc_gauge(&joints, &Vec3::new(p[0], p[1], p[2]))
        } else if self.feature().is_some() {
            self.feature_gauge(&joints, &Vec3::new(p[0], p[1], p[2]))
        } else {
            self.to_real(&Vec3::new(p[0], p[1], p[2])) + self.length_vector(&joints)
        };
        joints[..3].copy_from_slice(lin.as_slice());
        joints
    }

    /// The programmed end point of a block from its axis words, absolute or
    /// incremental, and each axis's signed travel. Rollover axes end on
    /// their target reduced to [0, 360) (so that positions stay exactly as
    /// programmed) and travel the shorter way on absolute commands, the
    /// increment itself on incremental ones.
    fn end_point(&self, from: &Joints, targets: &Targets) -> (Joints, Joints) {
        if self.state.frames.active() {
            return self.framed_end_point(from, targets);
        }
        self.plain_end_point(from, targets)
    }

    /// [`Controller::end_point`] without program transforms.
    fn plain_end_point(&self, from: &Joints, targets: &Targets) -> (Joints, Joints) {
        let mut end = *from;
        let mut travel = [0.0; MAX_AXES];
        let incremental = self.state.modal.distance == Distance::Incremental;
        for (i, target) in targets.iter().enumerate().take(self.machine.axis_count()) {
            let Some(value) = *target else { continue };
            if self.is_rollover(i) {
                end[i] = normalize_360(if incremental { from[i] + value } else { value });
                travel[i] = if incremental {
                    value
                } else {
                    shortest_turn(from[i], end[i])
                };
            } else {
                end[i] = if incremental { from[i] + value } else { value };
                travel[i] = end[i] - from[i];
            }
        }
        (end, travel)
    }

    /// The start of a segment that ends at `end`: the current position,
    /// with each rollover axis unwrapped so that it reaches `end` by its
    /// `travel`.
    fn rollover_start(&self, end: &Joints, travel: &Joints) -> Joints {
        let mut start = self.state.joints;
        for i in self.machine.linear.len()..self.machine.axis_count() {
            if self.is_rollover(i) {
                start[i] = end[i] - travel[i];
            }
        }
        start
    }

    fn is_rollover(&self, index: usize) -> bool {
        index >= self.machine.linear.len()
            && self.machine.rotary[index - self.machine.linear.len()].rollover
    }

    // ----- group 00 -------------------------------------------------------

    fn one_shot(
        &mut self,
        what: OneShot,
        span: Span,
        from: &Joints,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        match what {
            OneShot::Dwell => self.dwell(span),
            OneShot::DataSetting => self.data_setting(span, from),
            OneShot::ReferenceCheck => self.reference_check(from, out),
            OneShot::SetHome(n) => {
                // LinuxCNC G28.1 / G30.1: the machine position becomes the
                // G28 / G30 position.
                self.state.homes[n] = self.state.joints;
                Ok(())
            }
            OneShot::ReferenceReturn { numbered: false } => self.reference_return(from, 1, out),
            OneShot::ReferenceReturn { numbered: true } => {
                let n = self.fanuc.reference_number()?;
                self.reference_return(from, n, out)
            }
            OneShot::TwpOrient(how) => self.twp_orient(how, span, out),
            // G53.1, G53.6; Haas G253: the spindle normal to the feature
            // coordinate system (G268), as G53.1.
            OneShot::ToolAxis { keep_tip } => self.tool_axis_control(span, keep_tip, out),
            // Haas G47: text engraving.
            OneShot::Engrave => self.engrave(span, from, out),
            OneShot::LocalShift => {
                self.local_coordinate_system()?;
                self.refresh_xy_rotation();
                Ok(())
            }
            OneShot::MachineMove => self.machine_coordinates(out),
            OneShot::ShiftReset(minor) => {
                self.g92_reset(minor);
                Ok(())
            }
            OneShot::SetPosition => {
                self.set_coordinate_system(from)?;
                self.state.g92_kept = (self.state.shift, self.state.axis_shift);
                // LinuxCNC: the G92 shift turns with the rotation in force.
                self.refresh_xy_rotation();
                Ok(())
            }
        }
    }

    /// LinuxCNC (g-code.adoc, G92.1, G92.2, G92.3): G92.1 clears the G92
    /// offsets and their parameters, G92.2 clears the offsets and keeps
    /// the parameters, G92.3 applies the kept parameters again. None
    /// moves.
    fn g92_reset(&mut self, minor: u8) {
        let zero = (Vec3::zeros(), [0.0; MAX_AXES]);
        let (shift, axis_shift) = match minor {
            1 => {
                self.state.g92_kept = zero;
                zero
            }
            2 => zero,
            _ => self.state.g92_kept,
        };
        self.state.shift = shift;
        self.state.axis_shift = axis_shift;
        self.refresh_xy_rotation();
    }

    /// G04: dwell, P in ms (Haas: seconds with a decimal point) or X in
    /// s. No axis moves.
    fn dwell(&mut self, span: Span) -> Result<(), Alarm> {
        let rules = self.rules();
        self.fanuc.dwell(
            span,
            &rules,
            self.dialect.dwell_p_seconds_with_point,
            self.dialect.dwell_p_seconds,
            MAX_DWELL_SECONDS,
        )?;
        Ok(())
    }

    /// G10: the FANUC family's programmable data input, read by the front
    /// end (`fanuc/data_setting.rs`) and written into the offset memory.
    fn data_setting(&mut self, span: Span, from: &Joints) -> Result<(), Alarm> {
        let rules = self.rules();
        let data = if self.dialect.rs274ngc {
            let work = self.state.modal.work;
            self.fanuc.data_setting_linuxcnc(span, &rules, work)?
        } else {
            let incremental = self.state.modal.distance == Distance::Incremental;
            let haas = self.dialect.haas_codes;
            self.fanuc.data_setting(span, &rules, haas, incremental)?
        };
        self.set_data(&data, from)
    }

    /// Writes `data` into the offset memory; `from` is where the program
    /// stands.
    fn set_data(&mut self, data: &DataSetting, from: &Joints) -> Result<(), Alarm> {
        match *data {
            DataSetting::WorkOffset {
                memory,
                values,
                incremental,
            } => {
                let (value, beyond) = match memory {
                    OffsetMemory::External => (
                        &mut self.offsets.external,
                        &mut self.offsets.external_beyond,
                    ),
                    OffsetMemory::Standard(i) => (
                        &mut self.offsets.work[usize::from(i)],
                        &mut self.offsets.work_beyond[usize::from(i)],
                    ),
                    OffsetMemory::Extended(n) => (
                        &mut self.offsets.extended_work[usize::from(n) - 1],
                        &mut self.offsets.extended_work_beyond[usize::from(n) - 1],
                    ),
                };
                for (i, v) in values.iter().enumerate() {
                    let Some(v) = *v else { continue };
                    let slot = if i < 3 {
                        &mut value[i]
                    } else {
                        &mut beyond[i - 3]
                    };
                    *slot = if incremental { *slot + v } else { v };
                }
            }
            DataSetting::ToolOffset {
                number,
                field,
                value,
                incremental,
            } => {
                let tool = self.offsets.tools.entry(number).or_default();
                let slot = match field {
                    ToolField::Length => &mut tool.length,
                    ToolField::LengthWear => &mut tool.length_wear,
                    ToolField::Radius => &mut tool.radius,
                    ToolField::RadiusWear => &mut tool.radius_wear,
                };
                *slot = if incremental { *slot + value } else { value };
            }
            DataSetting::CoordinateSystem {
                system,
                values,
                rotation,
                at_position,
            } => self.set_coordinate_system_data(system, &values, rotation, at_position, from),
            DataSetting::ToolTable {
                number,
                length,
                radius,
            } => self.set_tool_table(number, length, radius, from),
        }
        Ok(())
    }

    /// G27: positions the named axes, then checks that they stand at
    /// reference position 1.
    fn reference_check(&mut self, from: &Joints, out: &mut Vec<Segment>) -> Result<(), Alarm> {
        let targets = self.axis_words();
        let (end_p, travel) = self.end_point(from, &targets);
        let end = self.machine_position(&end_p);
        let reference = self.machine.params.reference_1;
        for (i, name) in self.machine.axis_names().enumerate() {
            if targets[i].is_some() && (end[i] - reference[i]).abs() > REFERENCE_CHECK_TOLERANCE {
                let span = self.op_axis_span(i);
                return Err(self.alarm(
                    Condition::ReferenceReturnCheck,
                    span,
                    format!(
                        "G27: axis {name} reaches {} but reference position 1 is at {}",
                        end[i], reference[i]
                    ),
                ));
            }
        }
        self.push_line(Motion::Rapid, self.rollover_start(&end, &travel), end, out)
    }

    /// G28 / G30: through the intermediate point to reference position `n`,
    /// named axes only. One segment: the intermediate point at s = 0.5.
    fn reference_return(
        &mut self,
        from: &Joints,
        n: u32,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let reference = match n {
            1 | 2 if self.dialect.rs274ngc => self.state.homes[n as usize - 1],
            1 => self.machine.params.reference_1,
            2 => self.machine.params.reference_2,
            _ => {
                let span = self.fanuc.reference_span();
                return Err(self.alarm(
                    Condition::ReferencePositionUndefined,
                    span,
                    format!("reference position {n} is not defined for this machine"),
                ));
            }
        };
        let targets = self.axis_words();
        // LinuxCNC: G28 / G30 without axis words takes every axis home
        // straight from where it stands (g-code.adoc, G28, G30).
        let every_axis = self.dialect.rs274ngc && targets.iter().all(Option::is_none);
        let (mid_p, travel) = self.end_point(from, &targets);
        // 3-D tool compensation: the vector is cleared at the intermediate
        // point.
        self.state.comp3d.vector = Vec3::zeros();
        let mid = self.machine_position(&mid_p);
        let mut start = self.rollover_start(&mid, &travel);
        let mut mid_joints = start;
        let mut end = start;
        for (i, target) in targets.iter().enumerate().take(self.machine.axis_count()) {
            if target.is_some() || every_axis {
                mid_joints[i] = mid[i];
                end[i] = reference[i];
                if self.is_rollover(i) {
                    // Unwrap backwards from the reference: the last leg
                    // takes the shorter way.
                    end[i] = normalize_360(reference[i]);
                    let last_leg = shortest_turn(mid[i], end[i]);
                    mid_joints[i] = end[i] - last_leg;
                    start[i] = mid_joints[i] - travel[i];
                }
            }
        }
        let seg = self.segment(Motion::Rapid, start, end, Path::Via(mid_joints));
        if seg.moves() {
            // The leg to the intermediate point is checked like any move.
            self.check_limits(&self.segment(Motion::Rapid, start, mid_joints, Path::Joint))?;
            out.push(seg);
        }
        Ok(())
    }

    /// G53: positioning in machine coordinates, offsets not applied.
    fn machine_coordinates(&mut self, out: &mut Vec<Segment>) -> Result<(), Alarm> {
        let mut end = self.state.joints;
        let mut travel = [0.0; MAX_AXES];
        let rules = self.rules();
        let values = self.fanuc.axis_values(&rules);
        for (i, value) in values.into_iter().enumerate() {
            if let Some(value) = value {
                end[i] = if self.is_rollover(i) {
                    normalize_360(value)
                } else {
                    value
                };
                travel[i] = if self.is_rollover(i) {
                    shortest_turn(self.state.joints[i], end[i])
                } else {
                    end[i] - self.state.joints[i]
                };
            }
        }
        self.push_line(Motion::Rapid, self.rollover_start(&end, &travel), end, out)
    }

    // ----- soft limits ----------------------------------------------------

    /// Alarms before a move that would leave the soft limits anywhere along
    /// it (end points, and the extremes of an arc).
    fn check_limits(&self, seg: &Segment) -> Result<(), Alarm> {
        if self.limits_lifted {
            return Ok(());
        }
        let machine = self.machine;
        // A move in joint space stays between its ends: most blocks are
        // settled by comparing those (the alarm, if any, below).
        if matches!(seg.path, Path::Joint) {
            let within = |x: f64, (min, max): (f64, f64)| {
                x <= max + LIMIT_TOLERANCE && x >= min - LIMIT_TOLERANCE
            };
            let inside = self.soft_limits[..machine.axis_count()]
                .iter()
                .zip(seg.start.iter().zip(&seg.end))
                .all(|(&limits, (&a, &b))| within(a, limits) && within(b, limits));
            if inside {
                return Ok(());
            }
        }
        let mut lo = seg.end;
        let mut hi = seg.end;
        for i in 0..machine.axis_count() {
            lo[i] = lo[i].min(seg.start[i]);
            hi[i] = hi[i].max(seg.start[i]);
        }
        match &seg.path {
            Path::Arc(arc) => {
                for (k, &axis) in arc.axes.iter().enumerate() {
                    let (a, b) = arc_extent(arc, k);
                    lo[axis] = lo[axis].min(a);
                    hi[axis] = hi[axis].max(b);
                }
            }
            Path::Via(mid) => {
                for i in 0..machine.axis_count() {
                    lo[i] = lo[i].min(mid[i]);
                    hi[i] = hi[i].max(mid[i]);
                }
            }
            // The linear axes of a TCPC block swing with the rotary axes:
            // checked on the way, below.
            Path::Tcpc(_) => {}
            Path::Helix { circle, drift } => {
                for i in 0..3 {
                    let (a, b) = circle.extent(i);
                    lo[i] = lo[i].min(a + drift[i].min(0.0));
                    hi[i] = hi[i].max(b + drift[i].max(0.0));
                }
            }
            Path::Joint => {}
        }
        for (i, &(min, max)) in self.soft_limits[..machine.axis_count()].iter().enumerate() {
            let (condition, side, reach, bound) = if hi[i] > max + LIMIT_TOLERANCE {
                (Condition::OvertravelPlus, '+', hi[i], max)
            } else if lo[i] < min - LIMIT_TOLERANCE {
                (Condition::OvertravelMinus, '-', lo[i], min)
            } else {
                continue;
            };
            let span = self.op_axis_span(i);
            let name = char::from(self.axis_letters[i]);
            return Err(self.alarm(
                condition,
                span,
                format!("{name}{side} over-travel: {name} would reach {reach} beyond the soft limit {bound}"),
            ));
        }
        if let Path::Tcpc(_) = seg.path
            && let Some((i, value)) = tcpc_overtravel(seg, machine)
        {
            let name = self.axis_letters[i];
            let (min, max) = (machine.linear[i].min, machine.linear[i].max);
            let (condition, side, bound) = if value > max {
                (Condition::OvertravelPlus, '+', max)
            } else {
                (Condition::OvertravelMinus, '-', min)
            };
            let name = char::from(name);
            return Err(self.alarm(
                condition,
                self.op_axis_span(i),
                format!("{name}{side} over-travel: {name} would reach {value} beyond the soft limit {bound} on the way"),
            ));
        }
        Ok(())
    }
}

/// Largest arc radius, mm: the magnitude bound of every machine-file
/// number (`MAX_FILE_MAGNITUDE`).
pub const MAX_ARC_RADIUS: f64 = fiveaxis_machine::MAX_FILE_MAGNITUDE;

/// Longest dwell, seconds (FANUC: G04 X or P up to 99999.999 s).
pub const MAX_DWELL_SECONDS: f64 = 99_999.999;

/// Finest subdivision of a TCPC block when its path is checked against
/// the soft limits (a fraction of s).
pub const LIMIT_CHECK_RESOLUTION: f64 = 1.0 / 4096.0;

/// A linear axis of a TCPC block beyond its soft limit somewhere inside
/// the block: the axis and the position found.
///
/// A box that holds every position of the block (`reach::gauge_box`, by
/// interval arithmetic over the tip's box and the rotary ranges) proves
/// most blocks inside their limits at once. Where it does not, the block is
/// halved, and each half boxed again, until every piece is proven inside or
/// a position beyond a limit is found, down to [`LIMIT_CHECK_RESOLUTION`].
/// With tool posture control the rotary axes do not move monotonically
/// inside the block, so it is sampled instead, every
/// [`LIMIT_SAMPLE_ANGLE`] of rotary motion.
fn tcpc_overtravel(seg: &Segment, machine: &Machine) -> Option<(usize, f64)> {
    let Path::Tcpc(tcpc) = &seg.path else {
        return None;
    };
    let linear = machine.linear.len().min(3);
    let outside = |j: &Joints| {
        (0..linear).find_map(|i| {
            let a = &machine.linear[i];
            (j[i] > a.max + LIMIT_TOLERANCE || j[i] < a.min - LIMIT_TOLERANCE).then_some((i, j[i]))
        })
    };
    // Sampled, not boxed: posture control (the rotary axes need not move
    // monotonically) and a setup error on a turning frame (the tip in the
    // machine frame then depends on the table's turn).
    if tcpc.posture.is_some() || (tcpc.turning && !seg.setup.is_identity()) {
        let turn = (machine.linear.len()..machine.axis_count())
            .map(|i| (seg.end[i] - seg.start[i]).abs())
            .fold(0.0, f64::max);
        let n = (turn / LIMIT_SAMPLE_ANGLE)
            .ceil()
            .clamp(8.0, 1.0 / LIMIT_CHECK_RESOLUTION) as u32;
        return (1..n).find_map(|k| outside(&seg.eval(machine, f64::from(k) / f64::from(n))));
    }
    let inside = |b: &reach::Box3| {
        (0..linear).all(|i| b[i].hi <= machine.linear[i].max && b[i].lo >= machine.linear[i].min)
    };
    let piece = Piece {
        seg,
        machine,
        tcpc,
        outside: &outside,
        inside: &inside,
    };
    piece.search((0.0, &seg.start), (1.0, &seg.end))
}

/// Rotary motion between two samples of a TCPC block with tool posture
/// control checked against the soft limits, degrees.
pub const LIMIT_SAMPLE_ANGLE: f64 = 0.5;

/// The halving search of [`tcpc_overtravel`].
struct Piece<'a> {
    seg: &'a Segment,
    machine: &'a Machine,
    tcpc: &'a crate::segment::TcpcPath,
    outside: &'a dyn Fn(&Joints) -> Option<(usize, f64)>,
    inside: &'a dyn Fn(&reach::Box3) -> bool,
}

impl Piece<'_> {
    fn search(&self, (s0, j0): (f64, &Joints), (s1, j1): (f64, &Joints)) -> Option<(usize, f64)> {
        let bulge = match self.tcpc.tip {
            TipPath::Arc { radius, sweep, .. } => {
                radius[0].max(radius[1]) * sweep.abs() * (s1 - s0)
            }
            TipPath::Line(_) => 0.0,
        };
        let tip = reach::tip_box(&self.tcpc.tip.at(s0), &self.tcpc.tip.at(s1), bulge);
        let gauge = reach::gauge_box(
            self.machine,
            &tip,
            self.tcpc.turning,
            j0,
            j1,
            self.seg.tool_length,
        );
        if (self.inside)(&gauge) {
            return None;
        }
        let mid = 0.5 * (s0 + s1);
        let jm = self.seg.eval(self.machine, mid);
        if let Some(found) = (self.outside)(&jm) {
            return Some(found);
        }
        if s1 - s0 <= LIMIT_CHECK_RESOLUTION {
            return None;
        }
        self.search((s0, j0), (mid, &jm))
            .or_else(|| self.search((mid, &jm), (s1, j1)))
    }
}

/// How far past a soft limit rounding may carry a position, mm or degrees.
const LIMIT_TOLERANCE: f64 = 1e-9;

/// The soft limits of `machine`'s axes by joint index: a rollover axis or
/// a rotary axis without limits has none (infinite bounds).
fn soft_limits(machine: &Machine) -> [(f64, f64); MAX_AXES] {
    let mut limits = [(f64::NEG_INFINITY, f64::INFINITY); MAX_AXES];
    let axes = machine.linear.iter().map(|a| Some((a.min, a.max))).chain(
        machine
            .rotary
            .iter()
            .map(|r| if r.rollover { None } else { r.limits }),
    );
    for (slot, limit) in limits.iter_mut().zip(axes) {
        if let Some(limit) = limit {
            *slot = limit;
        }
    }
    limits
}

/// An alarm about a segment of an earlier block (held back by cutter
/// compensation C) names that block's line.
fn at_line(mut alarm: Alarm, line: u32) -> Alarm {
    if alarm.line != line {
        alarm.line = line;
        alarm.span = None;
    }
    alarm
}

/// `x` reduced to [0, 360), exactly when it already is in range.
pub fn normalize_360(x: f64) -> f64 {
    let r = rem_360(x);
    if r >= 360.0 { 0.0 } else { r }
}

/// `x.rem_euclid(360.0)` to the last bit, without the library's `fmod`
/// (a call of some hundred instructions on baseline x86-64): the quotient
/// truncated by a conversion, `x − 360·q` exact (the two are within a
/// factor of two, or q is 0), and q corrected by one where the division
/// rounded across a whole number.
fn rem_360(x: f64) -> f64 {
    if !x.is_finite() || x.abs() >= EXACT_QUOTIENT_LIMIT {
        return x.rem_euclid(360.0);
    }
    let q = (x / 360.0) as i64 as f64;
    let mut r = x - 360.0 * q;
    // The exact remainder of `%` (sign of x, below 360 in size) ...
    if r >= 360.0 {
        r -= 360.0;
    } else if r <= -360.0 {
        r += 360.0;
    }
    if x > 0.0 && r < 0.0 {
        r += 360.0;
    } else if x < 0.0 && r > 0.0 {
        r -= 360.0;
    } else if r == 0.0 {
        r = r.copysign(x);
    }
    // ... then `rem_euclid`'s step for a negative one.
    if r < 0.0 { r + 360.0 } else { r }
}

/// Angles at or beyond this size go to the library's remainder (the
/// quotient by 360 stays far inside exact integers below it).
const EXACT_QUOTIENT_LIMIT: f64 = 1e15;

/// The signed rotation in (−180°, 180°] that takes angle `from` to the
/// same position as `to` modulo 360.
pub fn shortest_turn(from: f64, to: f64) -> f64 {
    let mut d = rem_360(to - from);
    if d > 180.0 {
        d -= 360.0;
    }
    d
}

/// The range an arc covers along its `k`-th plane axis (0 or 1).
fn arc_extent(arc: &Arc, k: usize) -> (f64, f64) {
    let point = |theta: f64, s: f64| {
        let r = arc.r0 + (arc.r1 - arc.r0) * s;
        let (c, d) = (arc.center[k], arc.drift[k] * s);
        c + d + r * if k == 0 { theta.cos() } else { theta.sin() }
    };
    let mut lo = point(arc.theta0, 0.0).min(point(arc.theta0 + arc.sweep, 1.0));
    let mut hi = point(arc.theta0, 0.0).max(point(arc.theta0 + arc.sweep, 1.0));
    // Quadrant angles inside the sweep are the extremes.
    let (a, b) = if arc.sweep >= 0.0 {
        (arc.theta0, arc.theta0 + arc.sweep)
    } else {
        (arc.theta0 + arc.sweep, arc.theta0)
    };
    let quarter = std::f64::consts::FRAC_PI_2;
    let first = (a / quarter).ceil();
    // A sweep is at most one turn: at most five quarter angles, a bound
    // that holds whatever the magnitudes.
    for k in 0..6 {
        let q = (first + f64::from(k)) * quarter;
        if q > b {
            break;
        }
        let s = ((q - arc.theta0) / arc.sweep).clamp(0.0, 1.0);
        let v = point(q, s);
        lo = lo.min(v);
        hi = hi.max(v);
    }
    (lo, hi)
}

/// What a block did to the length offset vector.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LengthChange {
    /// Nothing.
    None,
    /// Changed: axes the block does not name move by the change.
    Moves,
    /// Cancelled where it stands: no axis moves for it.
    InPlace,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `rem_360` is `rem_euclid(360)` to the bit: on whole turns and next
    /// to them (where the division rounds across a whole number), on
    /// both signs, and on a sweep of ordinary angles.
    #[test]
    fn rem_360_is_rem_euclid_to_the_bit() {
        let mut xs = vec![
            0.0,
            -0.0,
            1e-300,
            -1e-300,
            359.999_999_999_999_94,
            360.0,
            -360.0,
        ];
        for k in -2000_i32..=2000 {
            let whole = 360.0 * f64::from(k);
            xs.extend([whole, whole.next_up(), whole.next_down()]);
            xs.extend([whole + 1e-9, whole - 1e-9, whole + 180.0, whole - 0.5]);
        }
        let mut x = -1e7;
        while x < 1e7 {
            xs.push(x);
            x += 977.123_456_789;
        }
        xs.extend([1e14 + 0.3, -1e14 - 0.7, 1e15 + 4.0, f64::INFINITY, f64::NAN]);
        for x in xs {
            let (ours, theirs) = (rem_360(x), x.rem_euclid(360.0));
            assert!(
                ours.to_bits() == theirs.to_bits() || (ours.is_nan() && theirs.is_nan()),
                "{x:e}: {ours:e} vs {theirs:e}"
            );
        }
    }
}
