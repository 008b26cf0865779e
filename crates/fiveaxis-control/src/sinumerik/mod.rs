//! The SINUMERIK front end: the blocks the Siemens language executes
//! (`fiveaxis-sinumerik`'s interpreter) turned into the kernel's commands
//! (`crate::command`).
//!
//! The interpreter runs the language (variables, expressions, program
//! flow, subprograms) and hands on each block with its values evaluated;
//! this module knows what the words and instructions mean on a SINUMERIK
//! 840D sl and keeps the Siemens modal state that has no place in the
//! controller (inch input G70 / G700, the programmable frame TRANS / ROT,
//! the swivel frame of CYCLE800, the modal cycle of MCALL). Sources are
//! the keys of the design brief (`sinumerik-heidenhain-brief.md` §0).
//!
//! * `system.rs`: the system variables a part program reads (`$AA_IW`,
//!   `$P_TOOLNO`, `$TC_DP…`) and the frames it reads and writes
//!   (`$P_UIFR[n]`, `$P_PFRAME`).
//! * `swivel.rs`: CYCLE800's rotation from its mode and angles.
//! * `cycles.rs`: the drilling, tapping, boring, pattern and engraving
//!   cycles as their elementary moves.
//!
//! Functions worked out here before the controller sees them:
//!
//! * The programmable frame (brief §3, ONE p309, p316): TRANS, ROT,
//!   SCALE, MIRROR replace it, ATRANS, AROT, ASCALE, AMIRROR add to it;
//!   it maps `T + R·S·M·p` (`command::Frame`), the controller carries
//!   `T`, `R` as its feature frame and `S`, `M` as the program transforms
//!   (G2 / G3 and G41 / G42 swap under an odd mirror; a circle under
//!   unequal factors is refused).
//! * Circles (FUND11 p216, brief §2): CIP through I1 J1 K1 (which follow
//!   G90 / G91 unless AC / IC, incremental from the start), CT tangential
//!   to the path before, AR= with the end point or the centre; each ends
//!   as G2 / G3 about an absolute centre, or, for a CIP out of the
//!   working plane, as a circle in space (`command::SpaceCircle`).
//! * Radius compensation G41 / G42 / G40 with the D in force: the
//!   controller's cutter compensation C (NORM start-up and cancel; KONT,
//!   KONTC, KONTT are taken as NORM; outside corners as the engine makes
//!   them, an intersection up to 90°, not G450's circle).
//! * CYCLE800 (brief §5): the swivel frame `T(X0)·R·T(X1)` (additive
//!   with `_ST` 1), `_MODE` 192 direct rotary angles, `_FR` 1, 2, 4, 5,
//!   `_DIR` ±1 the solution with the higher / lower first rotary axis,
//!   0 the frame only.
//! * TOFRAME / TOROT, PAROT (brief §3), settable frames written by the
//!   program (taking effect at the next G500 / G54…), ORIRESET, ORIWKS /
//!   ORIMKS, A2 B2 C2, LEAD= / TILT= (brief §4).

pub(crate) mod cycles;
mod swivel;
pub(crate) mod system;

use fiveaxis_gcode::Span;
use fiveaxis_machine::{MAX_AXES, Machine, Offsets, Vec3};
use fiveaxis_sinumerik::{Action, Executed, PositionMode, Value};
use nalgebra::Rotation3;

use crate::alarm::{Alarm, AlarmCode, Condition};
use crate::command::{
    Command, CommandBlock, CutterSide, Frame, Move, SpaceCircle, Suppress, Target, TargetMode,
    WorkOffset,
};
use crate::controller::{Controller, Flow};
use crate::modal::{CuttingMode, Distance, FeedMode, MotionMode, Plane, TcpcType};
use crate::segment::Segment;

/// Millimetres in an inch.
const MM_PER_INCH: f64 = 25.4;

/// The instructions and cycles the front end carries out (what
/// [`fiveaxis_sinumerik::System::is_builtin`] answers), and the control's
/// own instructions it knows and refuses by name rather than look for
/// them as programs (the couplings and the other transformations).
pub(crate) fn is_builtin(name: &str) -> bool {
    matches!(
        name,
        "TRAILON" | "TRAILOF" | "TRANSMIT" | "TRACYL" | "TRAANG" | "TRACON"
    ) || cycles::is_cycle(name)
        || matches!(
            name,
            "CYCLE800"
                | "CYCLE832"
                | "MSG"
                | "SETAL"
                | "TRAORI"
                | "TRAFOOF"
                | "FGROUP"
                | "STOPRE"
                | "ORIRESET"
        )
}

/// G functions written as names (groups of ONE p1262–1263) that set a
/// mode of speed or smoothing, not of the path: recorded, nothing moves
/// differently.
const PATH_NEUTRAL_NAMES: &[&str] = &[
    "SOFT",
    "BRISK",
    "DRIVE",
    "FNORM",
    "FLIN",
    "FCUB",
    "FPO",
    "COMPOF",
    "COMPON",
    "COMPCURV",
    "COMPCAD",
    "COMPSURF",
    "FFWON",
    "FFWOF",
    "UPATH",
    "SPATH",
    "DYNNORM",
    "DYNPOS",
    "DYNROUGH",
    "DYNSEMIFIN",
    "DYNFINISH",
    "DYNPREC",
    "CFC",
    "CFTCP",
    "CFIN",
    "ORISOF",
    "ORISON",
    "KONT",
    "KONTT",
    "KONTC",
    "CUT2D",
    "CUT2DF",
    "G450",
    "G451",
    "BNAT",
    "ENAT",
    "BTAN",
    "ETAN",
    "BAUTO",
    "EAUTO",
    "WALIMON",
    "WALIMOF",
    "DIAMOF",
    "SPOF",
    "SPIF1",
    "SPIF2",
];

/// The pattern cycles, which call the modal drilling cycle at each of
/// their positions.
fn is_pattern(name: &str) -> bool {
    matches!(name, "HOLES1" | "HOLES2" | "CYCLE801")
}

/// A circle of group 1 beyond G2 / G3 (FUND11 p216; brief §2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum CircleMode {
    /// `CIP`: through an intermediate point.
    Through,
    /// `CT`: tangential to the path before.
    Tangential,
}

/// What the front end keeps between blocks.
#[derive(Debug)]
pub(crate) struct Front {
    /// G70 / G700: lengths are inches.
    inch: bool,
    /// G700: feeds are inches per minute too.
    inch_feed: bool,
    /// G710 (metric, feeds too) rather than G71, for `$P_GG[13]`.
    units_with_feed: bool,
    plane: Plane,
    motion: MotionMode,
    distance: Distance,
    /// TRAORI in force, and how the last block gave the orientation.
    tcp: Option<TcpcType>,
    /// The programmable frame (TRANS, ROT, ATRANS, AROT).
    programmable: Frame,
    /// The swivel frame of CYCLE800.
    swivel: Option<Frame>,
    /// The settable frame a program wrote for the work offset in force.
    settable: Option<Frame>,
    /// The tool frame of TOFRAME / TOROT.
    tool_frame: Option<Frame>,
    /// CIP or CT in force (the controller then interpolates circles the
    /// front end works out), with `motion` G1.
    circle: Option<CircleMode>,
    /// The direction of the path at the end of the last move, in program
    /// coordinates (for CT).
    tangent: Option<Vec3>,
    /// ORIMKS: orientation vectors are in the machine frame.
    orimks: bool,
    /// The frames the program reads and writes ($P_UIFR, $P_PFRAME).
    pub(crate) frames: system::FrameStore,
    /// ORIEULER (true) or ORIRPY (false) for A2 / B2 / C2.
    euler: bool,
    /// The selected tool and the edge in force.
    tool: u32,
    edge: u32,
    /// Named tools (`T="NAME"`) met so far, with the number each stands for.
    tool_names: Vec<(String, u32)>,
    /// MCALL of a built-in cycle: its name and arguments.
    modal_call: Option<(String, Vec<Option<Value>>)>,
    /// The block being built, and the steps of a cycle.
    block: CommandBlock,
    steps: Vec<cycles::CycleStep>,
    holes: Vec<[f64; 2]>,
    /// Messages (MSG) and notes for the run's notes.
    pub(crate) notes: Vec<String>,
}

/// A word of an executed block.
#[derive(Clone, Copy)]
struct Word<'a> {
    address: &'a str,
    value: &'a Value,
    mode: Option<PositionMode>,
    span: Span,
}

/// A frame instruction of the block and its words.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FrameOp {
    Trans,
    Atrans,
    Rot,
    Arot,
    Scale,
    Ascale,
    Mirror,
    Amirror,
}

/// What one block asks for besides its commands.
#[derive(Default)]
struct Parts {
    mv: Move,
    /// Axis words as written (a frame instruction's angles and shifts).
    raw: [Option<f64>; MAX_AXES],
    moves: bool,
    frame: Option<(FrameOp, Span)>,
    rpl: Option<f64>,
    euler: [Option<f64>; 3],
    vector: [Option<f64>; 3],
    swivel: Option<(Vec<Option<Value>>, Span)>,
    /// TOFRAME / TOROT (with the frame axis along the tool) or TOROTOF.
    tool_frame: Option<Option<usize>>,
    cycle: Option<(String, Vec<Option<Value>>, Span)>,
    dwell: bool,
    dwell_value: Option<(f64, bool, Span)>,
    /// CIP's intermediate point I1 J1 K1 and how each is read.
    via: [Option<(f64, Option<PositionMode>)>; 3],
    /// AR=: the opening angle of a circle.
    ar: Option<(f64, Span)>,
    /// A circle's centre words, as written (with AC or not).
    center_written: [Option<(f64, Option<PositionMode>)>; 3],
    /// ORIRESET's angles.
    orireset: Option<(Vec<Option<f64>>, Span)>,
    /// LEAD= and TILT=, degrees.
    lead_tilt: [Option<f64>; 2],
    /// A5 B5 C5: the surface normal at the block's end.
    normal: [Option<f64>; 3],
}

impl Front {
    /// A front end at power-on (G71 G17 G0 G90, no frames).
    pub(crate) fn new() -> Self {
        Self {
            inch: false,
            inch_feed: false,
            units_with_feed: false,
            plane: Plane::Xy,
            motion: MotionMode::Rapid,
            distance: Distance::Absolute,
            tcp: None,
            programmable: Frame::IDENTITY,
            swivel: None,
            settable: None,
            tool_frame: None,
            circle: None,
            tangent: None,
            orimks: false,
            frames: system::FrameStore::default(),
            euler: true,
            tool: 0,
            edge: 0,
            tool_names: Vec::new(),
            modal_call: None,
            block: CommandBlock::default(),
            steps: Vec::new(),
            holes: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// G group 13 as `$P_GG[13]` gives it: G70 1, G71 2, G700 3, G710 4.
    pub(crate) fn units_group(&self) -> u8 {
        match (self.inch, self.inch_feed, self.units_with_feed) {
            (true, true, _) => 3,
            (true, false, _) => 1,
            (false, _, true) => 4,
            (false, _, false) => 2,
        }
    }

    /// The selected tool.
    pub(crate) fn tool(&self) -> u32 {
        self.tool
    }

    /// The cutting edge in force.
    pub(crate) fn edge(&self) -> u32 {
        self.edge
    }

    fn length(&self, x: f64) -> f64 {
        if self.inch { x * MM_PER_INCH } else { x }
    }

    fn alarm(line: u32, number: u32, span: Option<Span>, message: String) -> Alarm {
        Alarm {
            condition: Condition::SinumerikAlarm,
            code: AlarmCode::sinumerik(number),
            line,
            span,
            message,
        }
    }

    /// An alarm of the kernel's conditions with the number SINUMERIK
    /// gives it (`Condition::code`), for faults the brief names no
    /// number for.
    fn plain_alarm(line: u32, condition: Condition, span: Option<Span>, message: String) -> Alarm {
        Alarm {
            condition,
            code: condition.code(fiveaxis_machine::Control::Sinumerik),
            line,
            span,
            message,
        }
    }

    /// Carries out one executed block on the controller; its segments
    /// are appended to `out`.
    pub(crate) fn run(
        &mut self,
        ex: &Executed,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let machine = ctrl.machine();
        let line = ex.line;
        self.block.clear(line);
        self.block.number = ex.number;
        let mut parts = Parts::default();
        if self.frames.programmable_written {
            // $P_PFRAME written by the block before (system.rs).
            self.frames.programmable_written = false;
            self.programmable = self.frames.programmable;
            self.push_frames();
        }
        let offsets = ctrl.offsets();
        for action in &ex.actions {
            match action {
                Action::Word {
                    address,
                    value,
                    mode,
                    span,
                } => {
                    let word = Word {
                        address,
                        value,
                        mode: *mode,
                        span: *span,
                    };
                    self.word(machine, offsets, line, &word, &mut parts)?;
                }
                Action::Instruction { name, args, span } => {
                    self.instruction(line, name, args.as_deref(), *span, &mut parts)?;
                }
                Action::ModalCall { call, .. } => self.modal_call = call.clone(),
                Action::SyncAction { .. } => {
                    self.notes.push(format!(
                        "line {line}: synchronized action read, not simulated"
                    ));
                }
            }
        }
        if let Some((seconds, revolutions, span)) = parts.dwell_value {
            let seconds = if revolutions {
                let s = ctrl.spindle_speed();
                if s <= 0.0 {
                    return Err(Self::alarm(
                        line,
                        14020,
                        Some(span),
                        "G4 S: a dwell in spindle revolutions with the spindle stopped".into(),
                    ));
                }
                seconds * 60.0 / s
            } else {
                seconds
            };
            self.block.commands.push(Command::Dwell { seconds, span });
        } else if parts.dwell {
            return Err(Self::alarm(
                line,
                12550,
                None,
                "G4 needs the time: F (seconds) or S (spindle revolutions)".into(),
            ));
        }
        if let Some((op, span)) = parts.frame {
            self.frame_op(machine, line, op, &parts, span)?;
            self.push_frames();
            // The frame's words are not a move.
            parts.moves = false;
        }
        if let Some(along) = parts.tool_frame.take() {
            self.tool_frame = along.map(|k| self.tool_frame_along(ctrl, k));
            self.block
                .commands
                .push(Command::ToolFrame(self.tool_frame));
        }
        if let Some((args, span)) = parts.swivel.take() {
            return self.swivel(ctrl, line, &args, span, out);
        }
        if let Some((angles, span)) = parts.orireset.take() {
            self.orireset(machine, line, &angles, span, &mut parts)?;
        }
        let start = ctrl.program_position();
        let mut center = None;
        if parts.moves {
            self.orientation(line, &start, &mut parts)?;
            center = self.circle(line, &start, &mut parts)?;
            let finite = |v: Option<f64>| v.is_none_or(f64::is_finite);
            let circle_finite = parts.mv.circle.is_none_or(|c| {
                c.center
                    .iter()
                    .chain(c.normal.iter())
                    .all(|v| v.is_finite())
                    && c.sweep.is_finite()
            });
            let worked_out = self.circle.is_some() || parts.ar.is_some();
            if worked_out
                && !(parts.mv.center.iter().all(|c| finite(*c))
                    && parts.mv.targets.iter().all(|t| finite(t.map(|t| t.value)))
                    && circle_finite)
            {
                return Err(Self::alarm(
                    line,
                    14040,
                    Some(parts.mv.span),
                    "the circle's centre or end point is out of range".into(),
                ));
            }
            self.block.commands.push(Command::Move(parts.mv));
        }
        let flow = ctrl.run_block(&self.block, out)?;
        if parts.moves && parts.mv.suppress == Suppress::Nothing {
            self.track_tangent(&start, &ctrl.program_position(), center, &parts);
        }
        self.frames.programmable = self.programmable;
        if let Some((name, args, span)) = parts.cycle.take() {
            self.cycle(ctrl, line, &name, &args, span, out)?;
        } else if parts.moves
            && parts.mv.suppress == Suppress::Nothing
            && parts.mv.targets[..3].iter().any(Option::is_some)
            && let Some((name, args)) = self.modal_call.clone()
        {
            self.cycle(ctrl, line, &name, &args, Span::default(), out)?;
        }
        Ok(flow)
    }

    fn word(
        &mut self,
        machine: &Machine,
        offsets: &Offsets,
        line: u32,
        word: &Word<'_>,
        parts: &mut Parts,
    ) -> Result<(), Alarm> {
        let Word {
            address,
            value,
            mode,
            span,
        } = *word;
        let number = |what: &str| {
            value.as_f64().ok_or_else(|| {
                Self::alarm(
                    line,
                    14096,
                    Some(span),
                    format!("{what} takes a number, not {value:?}"),
                )
            })
        };
        match address {
            "G" => {
                let g = number("G")?;
                self.g_function(machine, line, g, span, parts)?;
            }
            "M" => {
                let m = number("M")?;
                if !(0.0..=f64::from(u16::MAX)).contains(&m) || m.fract() != 0.0 {
                    return Err(Self::alarm(
                        line,
                        12470,
                        Some(span),
                        format!("M{m} is not an M function"),
                    ));
                }
                self.block.commands.push(Command::MFunction {
                    number: m as u16,
                    span,
                });
            }
            "F" => {
                let f = number("F")?;
                if parts.dwell {
                    parts.dwell_value = Some((f, false, span));
                } else {
                    let f = if self.inch_feed { f * MM_PER_INCH } else { f };
                    self.block.commands.push(Command::Feed { value: f, span });
                }
            }
            "S" => {
                let s = number("S")?;
                if parts.dwell {
                    parts.dwell_value = Some((s, true, span));
                } else {
                    self.block.commands.push(Command::SpindleSpeed(s));
                }
            }
            "T" => {
                let tool = match value {
                    Value::Str(name) => self.named_tool(offsets, line, name, span)?,
                    _ => {
                        let t = number("T")?;
                        if t < 0.0 || t.fract() != 0.0 || t > f64::from(u32::MAX) {
                            return Err(Self::alarm(
                                line,
                                17190,
                                Some(span),
                                format!("T{t} is not a tool number"),
                            ));
                        }
                        t as u32
                    }
                };
                self.tool = tool;
                self.block.commands.push(Command::ToolSelect { tool, span });
            }
            "D" => {
                let d = number("D")?;
                if d < 0.0 || d.fract() != 0.0 || d > 32_000.0 {
                    return Err(Self::alarm(
                        line,
                        17020,
                        Some(span),
                        format!("D{d} is not a cutting edge number"),
                    ));
                }
                self.edge = d as u32;
                // One edge per tool in the offsets file: D1… select the
                // tool's offsets, D0 none.
                let number = if self.edge == 0 { 0 } else { self.tool };
                self.block
                    .commands
                    .push(Command::ToolOffset { number, span });
            }
            // Auxiliary functions and path tolerances: nothing moves
            // otherwise.
            "H" | "ADIS" | "ADISPOS" | "CTOL" | "OTOL" | "ATOL" | "LIMS" | "SF" | "FL" => {
                number(address)?;
            }
            "I" | "J" | "K" => {
                let k = usize::from(address.as_bytes()[0] - b'I');
                let c = self.length(number(address)?);
                parts.mv.center[k] = Some(c);
                parts.center_written[k] = Some((c, mode));
                if mode == Some(PositionMode::Ac) {
                    parts.mv.center_absolute = true;
                }
                parts.mv.span = span;
                parts.moves = true;
            }
            "I1" | "J1" | "K1" => {
                let k = usize::from(address.as_bytes()[0] - b'I');
                parts.via[k] = Some((self.length(number(address)?), mode));
                parts.mv.span = span;
                parts.moves = true;
            }
            "AR" => {
                parts.ar = Some((number("AR")?, span));
                parts.moves = true;
            }
            "CR" => {
                parts.mv.radius = Some(self.length(number("CR")?));
                parts.moves = true;
            }
            "TURN" => {
                let t = number("TURN")?;
                if !(0.0..=999.0).contains(&t) || t.fract() != 0.0 {
                    return Err(Self::alarm(
                        line,
                        14048,
                        Some(span),
                        format!("TURN={t}: the turns of a helix are a whole number 0 to 999"),
                    ));
                }
                parts.mv.turns = Some(t as u32);
            }
            "RPL" => parts.rpl = Some(number("RPL")?),
            "A2" | "B2" | "C2" => {
                let k = usize::from(address.as_bytes()[0] - b'A');
                parts.euler[k] = Some(number(address)?);
                parts.moves = true;
            }
            "LEAD" | "TILT" => {
                parts.lead_tilt[usize::from(address == "TILT")] = Some(number(address)?);
                parts.moves = true;
            }
            "A5" | "B5" | "C5" => {
                let k = usize::from(address.as_bytes()[0] - b'A');
                parts.normal[k] = Some(number(address)?);
            }
            "A3" | "B3" | "C3" => {
                let k = usize::from(address.as_bytes()[0] - b'A');
                parts.vector[k] = Some(number(address)?);
                parts.moves = true;
            }
            // The reference radius of a rotary axis in FGROUP and an
            // axis's feed limit (ONE p105, p112): speed, not path.
            _ if address.starts_with("FGREF[") || address.starts_with("FL[") => {
                number(address)?;
            }
            _ => {
                let axis = (address.len() == 1)
                    .then(|| machine.axis_index(char::from(address.as_bytes()[0])))
                    .flatten();
                let Some(i) = axis else {
                    return Err(Self::alarm(
                        line,
                        12550,
                        Some(span),
                        format!("{address} is not an address or axis of this machine"),
                    ));
                };
                let v = number(address)?;
                parts.raw[i] = Some(v);
                let v = if i < machine.linear.len() {
                    self.length(v)
                } else {
                    v
                };
                let mode = match mode {
                    None => TargetMode::Modal,
                    Some(PositionMode::Ac) => TargetMode::Absolute,
                    Some(PositionMode::Ic) => TargetMode::Incremental,
                    Some(PositionMode::Dc) => TargetMode::Shortest,
                    Some(PositionMode::Acp) => TargetMode::Positive,
                    Some(PositionMode::Acn) => TargetMode::Negative,
                };
                if i < machine.linear.len()
                    && matches!(
                        mode,
                        TargetMode::Shortest | TargetMode::Positive | TargetMode::Negative
                    )
                {
                    return Err(Self::alarm(
                        line,
                        16830,
                        Some(span),
                        format!("{address}: DC, ACP and ACN are for rotary axes"),
                    ));
                }
                parts.mv.targets[i] = Some(Target {
                    value: v,
                    mode,
                    span,
                });
                parts.mv.span = span;
                parts.moves = true;
            }
        }
        Ok(())
    }

    /// The G functions by number (groups of ONE p1262–1263).
    fn g_function(
        &mut self,
        _machine: &Machine,
        line: u32,
        g: f64,
        span: Span,
        parts: &mut Parts,
    ) -> Result<(), Alarm> {
        let cmds = &mut self.block.commands;
        if g.fract() != 0.0 || !(0.0..=999.0).contains(&g) {
            return Err(Self::alarm(
                line,
                12470,
                Some(span),
                format!("G{g} is not a G function"),
            ));
        }
        let n = g as u32;
        match n {
            0..=3 => {
                self.circle = None;
                self.motion = match n {
                    0 => MotionMode::Rapid,
                    1 => MotionMode::Linear,
                    2 => MotionMode::Cw,
                    _ => MotionMode::Ccw,
                };
                cmds.push(Command::Interpolation(self.motion));
            }
            4 => parts.dwell = true,
            9 => cmds.push(Command::ExactStop),
            17..=19 => {
                self.plane = match n {
                    17 => Plane::Xy,
                    18 => Plane::Zx,
                    _ => Plane::Yz,
                };
                cmds.push(Command::Plane(self.plane));
            }
            40 => cmds.push(Command::Radius {
                side: CutterSide::Off,
                span,
            }),
            41 | 42 => cmds.push(Command::Radius {
                side: if n == 41 {
                    CutterSide::Left
                } else {
                    CutterSide::Right
                },
                span,
            }),
            53 | 153 => parts.mv.suppress = Suppress::Frames,
            54..=57 => self.select_work((n - 53) as usize),
            500 => self.select_work(0),
            505..=599 => self.select_work((n - 500) as usize),
            60 => cmds.push(Command::PathMode(CuttingMode::ExactStop)),
            64 | 641 | 642 | 643 | 644 | 645 => cmds.push(Command::PathMode(CuttingMode::Cutting)),
            // Exact stop windows, corner behaviour of radius compensation,
            // constant cutting rate off: no change of path.
            601 | 602 | 603 | 450 | 451 | 97 => {}
            70 | 700 => {
                self.inch = true;
                self.inch_feed = n == 700;
                self.units_with_feed = n == 700;
            }
            71 | 710 => {
                self.inch = false;
                self.inch_feed = false;
                self.units_with_feed = n == 710;
            }
            90 | 91 => {
                self.distance = if n == 90 {
                    Distance::Absolute
                } else {
                    Distance::Incremental
                };
                cmds.push(Command::Distance(self.distance));
            }
            93 => cmds.push(Command::FeedMode(FeedMode::InverseTime)),
            94 => cmds.push(Command::FeedMode(FeedMode::PerMinute)),
            95 => cmds.push(Command::FeedMode(FeedMode::PerRevolution)),
            _ => {
                return Err(Self::alarm(
                    line,
                    12470,
                    Some(span),
                    format!("G{n} is not a G function of this control"),
                ));
            }
        }
        Ok(())
    }

    fn instruction(
        &mut self,
        line: u32,
        name: &str,
        args: Option<&[Option<Value>]>,
        span: Span,
        parts: &mut Parts,
    ) -> Result<(), Alarm> {
        match name {
            "TRANS" => parts.frame = Some((FrameOp::Trans, span)),
            "ATRANS" => parts.frame = Some((FrameOp::Atrans, span)),
            "ROT" => parts.frame = Some((FrameOp::Rot, span)),
            "AROT" => parts.frame = Some((FrameOp::Arot, span)),
            "SCALE" => parts.frame = Some((FrameOp::Scale, span)),
            "ASCALE" => parts.frame = Some((FrameOp::Ascale, span)),
            "MIRROR" => parts.frame = Some((FrameOp::Mirror, span)),
            "AMIRROR" => parts.frame = Some((FrameOp::Amirror, span)),
            "CIP" | "CT" => {
                self.circle = Some(if name == "CIP" {
                    CircleMode::Through
                } else {
                    CircleMode::Tangential
                });
                self.motion = MotionMode::Linear;
                self.block
                    .commands
                    .push(Command::Interpolation(MotionMode::Linear));
            }
            // NORM: the tool perpendicular to the contour at the start and
            // end of radius compensation, the engine's start-up (brief §6).
            "NORM" => {}
            "ORIWKS" => self.orimks = false,
            // The orientation relative to the path: LEAD= / TILT= words.
            "ORIPATH" | "ORIPATHS" => {}
            "ORIMKS" => self.orimks = true,
            "ORIRESET" => {
                let angles = args
                    .unwrap_or_default()
                    .iter()
                    .map(|a| a.as_ref().and_then(Value::as_f64))
                    .collect();
                parts.orireset = Some((angles, span));
            }
            "TOFRAME" | "TOFRAMEZ" | "TOFRAMEX" | "TOFRAMEY" | "TOROT" | "TOROTZ" | "TOROTX"
            | "TOROTY" => {
                let along = match name.as_bytes().last() {
                    Some(b'X') => 0,
                    Some(b'Y') => 1,
                    _ => 2,
                };
                parts.tool_frame = Some(Some(along));
            }
            "TOROTOF" => parts.tool_frame = Some(None),
            "PAROT" => self.block.commands.push(Command::PartFrame(true)),
            "PAROTOF" => self.block.commands.push(Command::PartFrame(false)),
            "TRAORI" => {
                self.tcp = Some(TcpcType::Angles);
                self.block.commands.push(Command::Tcp {
                    mode: Some(TcpcType::Angles),
                    span,
                });
            }
            "TRAFOOF" => {
                self.tcp = None;
                self.block.commands.push(Command::Tcp { mode: None, span });
            }
            "SUPA" | "G153" => parts.mv.suppress = Suppress::Frames,
            // How the orientation is interpolated (group 51, ONE p672):
            // on the great circle between the block's end vectors, or
            // with the rotary axes linear; until one is given, the machine
            // file's `tool_posture_control`.
            "ORIVECT" | "ORIPLANE" | "ORIAXES" => {
                self.block.commands.push(Command::OrientationPath {
                    great_circle: name != "ORIAXES",
                });
            }
            "ORIEULER" => self.euler = true,
            "ORIRPY" => self.euler = false,
            "STOPRE" | "FGROUP" => {}
            // CYCLE832(_TOL, _TOLM, …) (ONE p1108): the high-speed
            // settings; the units digit of _TOLM 0 (or no arguments)
            // deselects them. Speed, not path: kept in the modal state.
            "CYCLE832" => {
                let arg = |k: usize| {
                    args.and_then(|a| a.get(k))
                        .and_then(|v| v.as_ref())
                        .and_then(Value::as_f64)
                };
                let mode = arg(1).unwrap_or(0.0);
                let on = args.is_some_and(|a| a.iter().any(Option::is_some))
                    && (mode.trunc() as i64).rem_euclid(10) != 0;
                let tolerance = arg(0).filter(|t| t.is_finite() && *t > 0.0);
                self.block.commands.push(Command::PathSmoothing {
                    on,
                    tolerance: tolerance.map(|t| self.length(t)),
                });
            }
            "MSG" => {
                if let Some(Some(Value::Str(text))) = args.and_then(|a| a.first()) {
                    self.notes.push(format!("line {line}: MSG \"{text}\""));
                }
            }
            "SETAL" => {
                let n = args
                    .and_then(|a| a.first())
                    .and_then(|v| v.as_ref())
                    .and_then(Value::as_f64)
                    .unwrap_or(0.0);
                let text = match args.and_then(|a| a.get(1)) {
                    Some(Some(Value::Str(t))) => format!(": {t}"),
                    _ => String::new(),
                };
                return Err(Self::alarm(
                    line,
                    n.clamp(0.0, f64::from(u32::MAX)) as u32,
                    Some(span),
                    format!("SETAL({n}): the program raises alarm {n}{text}"),
                ));
            }
            "CYCLE800" => parts.swivel = Some((args.unwrap_or_default().to_vec(), span)),
            _ if cycles::is_cycle(name) => {
                parts.cycle = Some((name.to_owned(), args.unwrap_or_default().to_vec(), span));
            }
            _ if PATH_NEUTRAL_NAMES.contains(&name) => {}
            _ => {
                return Err(Self::alarm(
                    line,
                    12550,
                    Some(span),
                    if is_builtin(name) {
                        format!(
                            "{name}: the kernel does not carry out this instruction of the control"
                        )
                    } else {
                        format!("{name} is not an instruction this control carries out")
                    },
                ));
            }
        }
        Ok(())
    }

    /// The tool number a named tool stands for: the offsets file's tool
    /// of that name; with no tools in the offsets file (a run without
    /// tool data), its place among the names met in this run, from 1 on.
    fn named_tool(
        &mut self,
        offsets: &Offsets,
        line: u32,
        name: &str,
        span: Span,
    ) -> Result<u32, Alarm> {
        if let Some(n) = offsets.tool_number(name) {
            return Ok(n);
        }
        if !offsets.tools.is_empty() && !offsets.any_name {
            return Err(Self::alarm(
                line,
                17190,
                Some(span),
                format!("tool \"{name}\" is not in the offsets file's [tools]"),
            ));
        }
        if let Some((_, n)) = self.tool_names.iter().find(|(t, _)| t == name) {
            return Ok(*n);
        }
        let n = self.tool_names.len() as u32 + 1;
        self.tool_names.push((name.to_owned(), n));
        Ok(n)
    }

    /// TRANS, ATRANS, ROT, AROT, SCALE, ASCALE, MIRROR, AMIRROR with the
    /// block's words (ONE p309, p316; brief §3). The absolute forms
    /// replace the whole programmable frame, the additive ones act in the
    /// frame in force: a frame maps `T + R·S·M·p`, so ATRANS shifts
    /// through the rotation, scale and mirror in force (SCALE scales later
    /// shifts), AROT turns after the rotation in force, ASCALE multiplies
    /// the factors, AMIRROR reverses the mirror of the axes it names
    /// (the value written is ignored).
    fn frame_op(
        &mut self,
        machine: &Machine,
        line: u32,
        op: FrameOp,
        parts: &Parts,
        span: Span,
    ) -> Result<(), Alarm> {
        let value = |i: usize| parts.raw[i];
        let length = |i: usize| parts.raw[i].map(|v| self.length(v));
        let inner = match op {
            FrameOp::Trans | FrameOp::Atrans => {
                let v = Vec3::new(
                    length(0).unwrap_or(0.0),
                    length(1).unwrap_or(0.0),
                    length(2).unwrap_or(0.0),
                );
                let mut shift = [0.0; MAX_AXES];
                for (i, s) in shift
                    .iter_mut()
                    .enumerate()
                    .take(machine.axis_count())
                    .skip(3)
                {
                    *s = value(i).unwrap_or(0.0);
                }
                Frame {
                    axis_shift: shift,
                    ..Frame::rigid(v, Rotation3::identity())
                }
            }
            FrameOp::Rot | FrameOp::Arot => {
                // ROT X Y Z: RPY, about Z, then the new Y, then the newest
                // X (K2); RPL= turns in the working plane, about its
                // applicate.
                let rot = if let Some(angle) = parts.rpl {
                    let axis = self.plane.axes()[2];
                    axis_rotation(axis, angle)
                } else {
                    // ROT names its angles with the geometry axes: the
                    // parser reads them as targets of the axes X, Y, Z.
                    axis_rotation(2, value(2).unwrap_or(0.0))
                        * axis_rotation(1, value(1).unwrap_or(0.0))
                        * axis_rotation(0, value(0).unwrap_or(0.0))
                };
                Frame::rigid(Vec3::zeros(), rot)
            }
            FrameOp::Scale | FrameOp::Ascale => {
                let mut f = Frame::IDENTITY;
                for k in 0..3 {
                    if let Some(v) = value(k) {
                        if v == 0.0 || !v.is_finite() {
                            return Err(Self::plain_alarm(
                                line,
                                Condition::ValueOutOfRange,
                                Some(span),
                                format!("SCALE: the factor {v} of an axis is not allowed"),
                            ));
                        }
                        f.scale[k] = v;
                    }
                }
                f
            }
            FrameOp::Mirror | FrameOp::Amirror => {
                let mut f = Frame::IDENTITY;
                for k in 0..3 {
                    f.mirror[k] = value(k).is_some();
                }
                f
            }
        };
        if (3..MAX_AXES).any(|i| value(i).is_some())
            && !matches!(op, FrameOp::Trans | FrameOp::Atrans)
        {
            return Err(Self::alarm(
                line,
                12550,
                Some(span),
                "ROT, SCALE and MIRROR name the geometry axes X, Y, Z only".into(),
            ));
        }
        self.programmable = match op {
            FrameOp::Trans | FrameOp::Rot | FrameOp::Scale | FrameOp::Mirror => inner,
            _ => self.programmable.then(&inner),
        };
        Ok(())
    }

    fn push_frames(&mut self) {
        self.block
            .commands
            .push(Command::ProgrammableFrame(self.programmable));
    }

    /// The tool orientation of a move under TRAORI: rotary axis words, a
    /// vector A3 B3 C3 or angles A2 B2 C2.
    fn orientation(&mut self, line: u32, start: &[f64], parts: &mut Parts) -> Result<(), Alarm> {
        let relative = parts.lead_tilt.iter().any(Option::is_some);
        if relative {
            if parts.vector.iter().any(Option::is_some) || parts.euler.iter().any(Option::is_some) {
                return Err(Self::plain_alarm(
                    line,
                    Condition::ImproperAddress,
                    Some(parts.mv.span),
                    "LEAD / TILT and A3 B3 C3 / A2 B2 C2 in one block: one orientation only".into(),
                ));
            }
            let v = self.lead_tilt(line, start, parts)?;
            parts.vector = v.map(Some);
        }
        let vector = parts.vector.iter().any(Option::is_some);
        let angles = parts.euler.iter().any(Option::is_some);
        if !vector && !angles {
            if self.tcp == Some(TcpcType::Vector) {
                self.tcp = Some(TcpcType::Angles);
                self.block.commands.push(Command::Tcp {
                    mode: Some(TcpcType::Angles),
                    span: parts.mv.span,
                });
            }
            return Ok(());
        }
        if self.tcp.is_none() {
            return Err(Self::alarm(
                line,
                14101,
                Some(parts.mv.span),
                "a tool orientation (A3 B3 C3 / A2 B2 C2) needs TRAORI".into(),
            ));
        }
        let v = if vector {
            parts.vector.map(|c| c.unwrap_or(0.0))
        } else {
            let [a, b, c] = parts.euler.map(|c| c.unwrap_or(0.0));
            let r = if self.euler {
                // Euler angles Z, X′, Z″ (brief §4, assumed).
                axis_rotation(2, a) * axis_rotation(0, b) * axis_rotation(2, c)
            } else {
                // RPY: about X, Y, Z of the fixed frame (ORIRPY = XYZ).
                axis_rotation(2, c) * axis_rotation(1, b) * axis_rotation(0, a)
            };
            let z = r * Vec3::z();
            [z.x, z.y, z.z]
        };
        // ORIMKS: the vector is in the machine frame; the controller reads
        // it in the frames' (ORIWKS, ONE p674).
        // (LEAD / TILT give it in the frames' coordinates already.)
        let v = if self.orimks && !relative {
            let w = self.all_rotation().inverse() * Vec3::new(v[0], v[1], v[2]);
            [w.x, w.y, w.z]
        } else {
            v
        };
        if v.iter().all(|&c| c == 0.0) {
            return Err(Self::alarm(
                line,
                14104,
                Some(parts.mv.span),
                "the tool vector A3 B3 C3 is zero".into(),
            ));
        }
        if self.tcp != Some(TcpcType::Vector) {
            self.tcp = Some(TcpcType::Vector);
            self.block.commands.push(Command::Tcp {
                mode: Some(TcpcType::Vector),
                span: parts.mv.span,
            });
        }
        parts.mv.tool_vector = Some(v);
        Ok(())
    }

    /// LEAD= / TILT= (JP06 p7-40/43, brief §4): the tool orientation
    /// relative to the path and the surface normal (A5 B5 C5 at the end of
    /// the block; without them Z of the frames in force), in the frames'
    /// coordinates. The kernel's reading (signs UNVERIFIED): the path
    /// direction is the block's, start to end; LEAD tilts the tool from
    /// the normal towards the direction of travel, TILT then turns it
    /// about the path direction, counter-clockwise seen along it.
    fn lead_tilt(&self, line: u32, start: &[f64], parts: &Parts) -> Result<[f64; 3], Alarm> {
        let n = if parts.normal.iter().any(Option::is_some) {
            let n = Vec3::from(parts.normal.map(|c| c.unwrap_or(0.0)));
            if self.orimks {
                self.all_rotation().inverse() * n
            } else {
                n
            }
        } else {
            Vec3::z()
        };
        let e = self.end_point(start, &parts.mv);
        let t = e - Vec3::new(start[0], start[1], start[2]);
        let nn = n.norm();
        let t = if nn > 0.0 {
            t - n * (t.dot(&n) / (nn * nn))
        } else {
            t
        };
        if nn <= 0.0 || !nn.is_finite() || t.norm() <= 1e-9 || !t.norm().is_finite() {
            return Err(Self::alarm(
                line,
                14104,
                Some(parts.mv.span),
                "LEAD / TILT need a path direction across the surface normal (A5 B5 C5 not \
                 zero, a move not along the normal)"
                    .into(),
            ));
        }
        let n = n / nn;
        let t = t.normalize();
        let [lead, tilt] = parts.lead_tilt.map(|a| a.unwrap_or(0.0).to_radians());
        let v = n * lead.cos() + t * lead.sin();
        let v = Rotation3::from_axis_angle(&nalgebra::Unit::new_unchecked(t), tilt) * v;
        Ok([v.x, v.y, v.z])
    }

    /// CYCLE800(_FR, _TC, _ST, _MODE, _X0, _Y0, _Z0, _A, _B, _C, _X1, _Y1,
    /// _Z1, _DIR, _FR_I, _DMODE) (brief §5).
    fn swivel(
        &mut self,
        ctrl: &mut Controller<'_>,
        line: u32,
        args: &[Option<Value>],
        span: Span,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let num = |k: usize| args.get(k).and_then(|v| v.as_ref()).and_then(Value::as_f64);
        let all_empty = args.iter().all(Option::is_none);
        let flow = if all_empty {
            // CYCLE800(): the swivel frame off.
            self.swivel = None;
            self.block.commands.push(Command::SwivelFrame(None));
            ctrl.run_block(&self.block, out)?
        } else {
            let mode = num(3).unwrap_or(0.0);
            let kind = (mode >= 0.0 && mode.fract() == 0.0)
                .then(|| swivel::kind(mode as u32))
                .flatten()
                .ok_or_else(|| {
                    Self::alarm(
                        line,
                        61183,
                        Some(span),
                        format!("CYCLE800: swivel mode _MODE={mode} names no rotation"),
                    )
                })?;
            let l = |k: usize| self.length(num(k).unwrap_or(0.0));
            let angles = [num(7), num(8), num(9)].map(|a| a.unwrap_or(0.0));
            let machine = ctrl.machine();
            // _MODE 192: the angles are the rotary axes' positions (_A the
            // first, _B the second); the frame is the tool's at those
            // positions (forward kinematics), brief §5.
            let direct = (kind == swivel::SwivelKind::Direct).then(|| {
                let mut joints = ctrl.joints_now();
                for (k, a) in angles.iter().enumerate().take(machine.rotary.len().min(2)) {
                    joints[machine.rotary_index(k)] = *a;
                }
                joints
            });
            let rotation = match (swivel::rotation(kind, angles), direct) {
                (Some(r), _) => r,
                (None, Some(joints)) => {
                    if machine.rotary.len() < 2 {
                        return Err(Self::alarm(
                            line,
                            61153,
                            Some(span),
                            "CYCLE800: direct rotary angles (_MODE 192) need two rotary axes"
                                .into(),
                        ));
                    }
                    for k in 0..2 {
                        let i = machine.rotary_index(k);
                        if let Some((min, max)) = machine.rotary[k].limits
                            && !machine.rotary[k].rollover
                            && !(min..=max).contains(&joints[i])
                        {
                            return Err(Self::alarm(
                                line,
                                61190,
                                Some(span),
                                format!(
                                    "CYCLE800: {} {} is outside the axis limits {min} to {max}",
                                    machine.rotary[k].name, joints[i]
                                ),
                            ));
                        }
                    }
                    ctrl.tool_rotation_at(&joints)
                }
                (None, None) => Rotation3::identity(),
            };
            let x0 = Vec3::new(l(4), l(5), l(6));
            let x1 = Vec3::new(l(10), l(11), l(12));
            let frame = Frame::rigid(x0 + rotation * x1, rotation);
            let additive = num(2).is_some_and(|st| (st as i64) % 10 == 1);
            let frame = match (additive, self.swivel) {
                (true, Some(old)) => old.then(&frame),
                _ => frame,
            };
            // The retract before the swivel (_FR): 1 Z, 2 Z then X Y, to
            // the first reference position (the retract positions of the
            // swivel data record, $TC_CARR38–40, are the machine file's
            // reference position 1 here).
            let fr = num(0).unwrap_or(0.0);
            match fr as i64 {
                _ if fr.fract() != 0.0 => {
                    return Err(Self::alarm(
                        line,
                        61186,
                        Some(span),
                        format!("CYCLE800: retract mode _FR={fr} does not exist"),
                    ));
                }
                0 => {}
                1 | 2 => self.retract(ctrl, line, fr == 2.0, span, out)?,
                4 => self.retract_along_tool(ctrl, line, None, span, out)?,
                5 => {
                    let d = self.length(num(14).unwrap_or(0.0));
                    self.retract_along_tool(ctrl, line, Some(d), span, out)?;
                }
                _ => {
                    return Err(Self::alarm(
                        line,
                        61186,
                        Some(span),
                        format!("CYCLE800: retract mode _FR={fr} does not exist (0, 1, 2, 4, 5)"),
                    ));
                }
            }
            self.swivel = Some(frame);
            self.block.clear(line);
            self.block.commands.push(Command::SwivelFrame(Some(frame)));
            // _DIR 0: the frame only, no axis moves (the kernel's reading,
            // brief §5 UNVERIFIED); −1 / +1 the solution with the lower /
            // higher angle of the first rotary axis; direct angles go
            // where they are written.
            let dir = num(13).unwrap_or(0.0);
            match direct {
                Some(joints) if dir != 0.0 => {
                    let mut mv = Move {
                        suppress: Suppress::Axes,
                        span,
                        ..Move::default()
                    };
                    for k in 0..2 {
                        let i = machine.rotary_index(k);
                        mv.targets[i] = Some(Target {
                            value: joints[i],
                            mode: TargetMode::Absolute,
                            span,
                        });
                    }
                    self.block
                        .commands
                        .push(Command::Interpolation(MotionMode::Rapid));
                    self.block.commands.push(Command::Move(mv));
                    self.block
                        .commands
                        .push(Command::Interpolation(self.motion));
                }
                None if dir != 0.0 => {
                    self.block.commands.push(Command::AlignTool {
                        higher: Some(dir > 0.0),
                        keep_tip: false,
                        span,
                    });
                }
                _ => {}
            }
            ctrl.run_block(&self.block, out)
                .map_err(|a| swivel_alarm(a, line))?
        };
        Ok(flow)
    }

    /// CYCLE800 `_FR` 4 / 5 (brief §5, HiNC, OM800): a retract along the
    /// tool (away from the workpiece), to the limit of the linear axes'
    /// travel (`distance` none) or by `distance`, in machine coordinates.
    fn retract_along_tool(
        &mut self,
        ctrl: &mut Controller<'_>,
        line: u32,
        distance: Option<f64>,
        span: Span,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let mut block = CommandBlock::default();
        block.clear(line);
        block
            .commands
            .push(Command::Interpolation(MotionMode::Rapid));
        block.commands.push(Command::Retract { distance, span });
        block.commands.push(Command::Interpolation(self.motion));
        ctrl.run_block(&block, out)?;
        Ok(())
    }

    /// A retract of Z (then X, Y) to the first reference position, in
    /// machine coordinates.
    fn retract(
        &mut self,
        ctrl: &mut Controller<'_>,
        line: u32,
        xy: bool,
        span: Span,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let machine = ctrl.machine();
        let reference = machine.params.reference_1;
        let mut block = CommandBlock::default();
        block.clear(line);
        let mut mv = Move {
            suppress: Suppress::Axes,
            span,
            ..Move::default()
        };
        mv.targets[2] = Some(Target {
            value: reference[2],
            mode: TargetMode::Absolute,
            span,
        });
        block
            .commands
            .push(Command::Interpolation(MotionMode::Rapid));
        block.commands.push(Command::Move(mv));
        ctrl.run_block(&block, out)?;
        if xy {
            let mut mv = mv;
            mv.targets[2] = None;
            for (target, value) in mv.targets.iter_mut().zip(reference).take(2) {
                *target = Some(Target {
                    value,
                    mode: TargetMode::Absolute,
                    span,
                });
            }
            block.clear(line);
            block.commands.push(Command::Move(mv));
            ctrl.run_block(&block, out)?;
        }
        // The interpolation in force before the retract.
        block.clear(line);
        block.commands.push(Command::Interpolation(self.motion));
        ctrl.run_block(&block, out)?;
        Ok(())
    }

    /// A built-in cycle at the current position, or a pattern cycle with
    /// the modal cycle at each of its positions.
    fn cycle(
        &mut self,
        ctrl: &mut Controller<'_>,
        line: u32,
        name: &str,
        args: &[Option<Value>],
        span: Span,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let position = ctrl.program_position();
        let ctx = cycles::CycleContext {
            plane: self.plane.axes(),
            position: [position[0], position[1], position[2]],
            feed: ctrl.feed(),
            spindle: ctrl.spindle_speed(),
            spindle_ccw: false,
            inch: self.inch,
        };
        let numbers: Vec<Option<f64>> = args
            .iter()
            .map(|a| a.as_ref().and_then(Value::as_f64))
            .collect();
        let error = |e: cycles::CycleError| {
            // The cycle's messages name the cycle.
            let message = if e.message.starts_with(name) {
                e.message
            } else {
                format!("{name}: {}", e.message)
            };
            Self::alarm(line, e.alarm, Some(span), message)
        };
        let mut steps = std::mem::take(&mut self.steps);
        steps.clear();
        if is_pattern(name) {
            let mut holes = std::mem::take(&mut self.holes);
            holes.clear();
            cycles::pattern(name, &numbers, &ctx, &mut holes).map_err(error)?;
            let Some((modal, margs)) = self.modal_call.clone() else {
                self.holes = holes;
                return Err(Self::alarm(
                    line,
                    61101,
                    Some(span),
                    format!("{name}: a hole pattern needs a modal drilling cycle (MCALL)"),
                ));
            };
            let [a, b, _] = self.plane.axes();
            for hole in &holes {
                let mut to = [None; 3];
                to[a] = Some(hole[0]);
                to[b] = Some(hole[1]);
                self.steps_to_blocks(ctrl, line, &[cycles::CycleStep::Rapid(to)], out)?;
                let mnumbers: Vec<Option<f64>> = margs
                    .iter()
                    .map(|a| a.as_ref().and_then(Value::as_f64))
                    .collect();
                let p = ctrl.program_position();
                let ctx = cycles::CycleContext {
                    position: [p[0], p[1], p[2]],
                    ..ctx
                };
                steps.clear();
                cycles::drilling(&modal, &mnumbers, &ctx, &mut steps).map_err(error)?;
                self.steps_to_blocks(ctrl, line, &steps, out)?;
            }
            self.holes = holes;
        } else if name == "CYCLE60" {
            let cargs: Vec<cycles::CycleArg> = args
                .iter()
                .map(|a| match a {
                    Some(Value::Str(s)) => cycles::CycleArg::Text(s.clone()),
                    Some(v) => v
                        .as_f64()
                        .map_or(cycles::CycleArg::Omitted, cycles::CycleArg::Number),
                    None => cycles::CycleArg::Omitted,
                })
                .collect();
            cycles::engrave(&cargs, &ctx, &mut steps).map_err(error)?;
            self.steps_to_blocks(ctrl, line, &steps, out)?;
        } else {
            cycles::drilling(name, &numbers, &ctx, &mut steps).map_err(error)?;
            self.steps_to_blocks(ctrl, line, &steps, out)?;
        }
        self.steps = steps;
        Ok(())
    }

    /// Runs a cycle's steps as blocks of commands, then gives back the
    /// interpolation in force before it.
    fn steps_to_blocks(
        &mut self,
        ctrl: &mut Controller<'_>,
        line: u32,
        steps: &[cycles::CycleStep],
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let mut block = CommandBlock::default();
        let feed = ctrl.feed();
        let target = |to: [Option<f64>; 3]| {
            let mut mv = Move::default();
            for (k, v) in to.iter().enumerate() {
                mv.targets[k] = v.map(|value| Target {
                    value,
                    mode: TargetMode::Absolute,
                    span: Span::default(),
                });
            }
            mv
        };
        for step in steps {
            block.clear(line);
            match *step {
                cycles::CycleStep::Rapid(to) => {
                    block
                        .commands
                        .push(Command::Interpolation(MotionMode::Rapid));
                    block.commands.push(Command::Move(target(to)));
                }
                cycles::CycleStep::Feed {
                    to,
                    feed: step_feed,
                } => {
                    // A step's own feed holds for that step only.
                    block
                        .commands
                        .push(Command::Interpolation(MotionMode::Linear));
                    block.commands.push(Command::Feed {
                        value: step_feed.unwrap_or(feed),
                        span: Span::default(),
                    });
                    block.commands.push(Command::Move(target(to)));
                }
                cycles::CycleStep::Speed(s) => block.commands.push(Command::SpindleSpeed(s)),
                cycles::CycleStep::Dwell(seconds) => block.commands.push(Command::Dwell {
                    seconds,
                    span: Span::default(),
                }),
                cycles::CycleStep::M(number) => block.commands.push(Command::MFunction {
                    number,
                    span: Span::default(),
                }),
            }
            ctrl.run_block(&block, out)?;
        }
        block.clear(line);
        block.commands.push(Command::Interpolation(self.motion));
        block.commands.push(Command::Feed {
            value: feed,
            span: Span::default(),
        });
        ctrl.run_block(&block, out)?;
        Ok(())
    }
}

fn axis_rotation(axis: usize, degrees: f64) -> Rotation3<f64> {
    let v = match axis {
        0 => Vec3::x_axis(),
        1 => Vec3::y_axis(),
        _ => Vec3::z_axis(),
    };
    Rotation3::from_axis_angle(&v, degrees.to_radians())
}

/// The unit vector of axis `k`.
fn unit(k: usize) -> Vec3 {
    let mut e = Vec3::zeros();
    e[k] = 1.0;
    e
}

/// How close to parallel two unit vectors must be for a circle to count
/// as lying in the working plane.
const PARALLEL: f64 = 1e-9;

impl Front {
    /// The rotation of the frames outside the tool frame (settable and
    /// swivel).
    fn outer_rotation(&self) -> Rotation3<f64> {
        self.settable.unwrap_or_default().rotation * self.swivel.unwrap_or_default().rotation
    }

    /// The rotation of every frame in force.
    fn all_rotation(&self) -> Rotation3<f64> {
        self.outer_rotation()
            * self.tool_frame.unwrap_or_default().rotation
            * self.programmable.rotation
    }

    /// TOFRAME / TOROT (W1 p2-82, K2 p2-104; brief §3): a frame at the
    /// work zero whose axis `along` (Z; X or Y for TOFRAMEX / Y) points
    /// along the tool as the rotary axes stand (forward kinematics), inside
    /// the settable and swivel frames. Its other axes are the shortest
    /// turn from the frame outside it (the kernel's reading: SD42980
    /// TOFRAME_MODE chooses them on the control). TOFRAME and TOROT give
    /// the same frame here: it has no translation of its own.
    fn tool_frame_along(&self, ctrl: &Controller<'_>, along: usize) -> Frame {
        let dir = self.outer_rotation().inverse() * ctrl.tool_direction();
        let turn = Rotation3::rotation_between(&Vec3::z(), &dir)
            .unwrap_or_else(|| axis_rotation(0, 180.0));
        // The named axis onto Z first.
        let onto_z = match along {
            0 => axis_rotation(1, -90.0),
            1 => axis_rotation(0, 90.0),
            _ => Rotation3::identity(),
        };
        Frame::rigid(Vec3::zeros(), turn * onto_z)
    }

    /// G500, G54…G57, G505…G599: settable frame `n`; one the program wrote
    /// ($P_UIFR, `system.rs`) takes the offsets file's place.
    fn select_work(&mut self, n: usize) {
        let written = self.frames.settable.get(n).copied().flatten();
        let work = match n {
            _ if written.is_some() => WorkOffset::Null,
            0 => WorkOffset::Null,
            1..=4 => WorkOffset::Standard((n - 1) as u8),
            _ => WorkOffset::Extended((n - 4) as u8),
        };
        self.settable = written;
        self.block.commands.push(Command::WorkOffset(work));
        self.block.commands.push(Command::SettableFrame(written));
    }

    /// The absolute end point of the block in program coordinates, from
    /// `start` and the targets of X, Y, Z.
    fn end_point(&self, start: &[f64], mv: &Move) -> Vec3 {
        let mut e = Vec3::new(start[0], start[1], start[2]);
        for k in 0..3 {
            if let Some(t) = mv.targets[k] {
                e[k] = match t.mode {
                    TargetMode::Incremental => start[k] + t.value,
                    TargetMode::Modal if self.distance == Distance::Incremental => {
                        start[k] + t.value
                    }
                    _ => t.value,
                };
            }
        }
        e
    }

    /// CIP, CT and AR= (FUND11 p216; brief §2): the circle worked out
    /// here, handed on as G2 / G3 with an absolute centre (in the working
    /// plane) or as a circle in space. Returns the centre of a circle
    /// (absolute, program coordinates) and whether it turns
    /// counter-clockwise about the plane's normal, for the tangent.
    fn circle(
        &mut self,
        line: u32,
        start: &Joints3,
        parts: &mut Parts,
    ) -> Result<Option<(Vec3, Vec3)>, Alarm> {
        let [p, q, k] = self.plane.axes();
        let s = Vec3::new(start[0], start[1], start[2]);
        let span = parts.mv.span;
        let circle_error = |message: String| Self::alarm(line, 14040, Some(span), message);
        let arc_motion = matches!(self.motion, MotionMode::Cw | MotionMode::Ccw);
        if parts.via.iter().any(Option::is_some) && self.circle != Some(CircleMode::Through) {
            return Err(Self::alarm(
                line,
                12550,
                Some(span),
                "I1 J1 K1 (an intermediate point) belong to CIP".into(),
            ));
        }
        if let Some((ar, ar_span)) = parts.ar {
            if !arc_motion {
                return Err(Self::alarm(
                    line,
                    14040,
                    Some(ar_span),
                    "AR= (an opening angle) belongs to G2 / G3".into(),
                ));
            }
            return self.opening_angle(line, s, ar, ar_span, parts).map(Some);
        }
        match self.circle {
            Some(CircleMode::Through) => {
                let e = self.end_point(start, &parts.mv);
                let mut m = s;
                for (c, v) in parts.via.iter().enumerate() {
                    if let Some((value, mode)) = *v {
                        // I1 J1 K1 follow G90 / G91 unless AC / IC (brief
                        // §2); incremental from the circle's start.
                        let incremental = match mode {
                            Some(PositionMode::Ic) => true,
                            Some(PositionMode::Ac) => false,
                            _ => self.distance == Distance::Incremental,
                        };
                        m[c] = if incremental { s[c] + value } else { value };
                    }
                }
                let a = m - s;
                let b = e - s;
                let axb = a.cross(&b);
                let n2 = axb.norm_squared();
                if n2 <= 1e-18 * a.norm_squared().max(1.0) * b.norm_squared().max(1.0) {
                    return Err(circle_error(
                        "CIP: the start, intermediate and end points lie on one line".into(),
                    ));
                }
                // The circumcentre of the three points.
                let c = s + (a.norm_squared() * b - b.norm_squared() * a).cross(&axb) / (2.0 * n2);
                let n = axb / n2.sqrt();
                self.set_absolute_end(parts, e);
                if n[k].abs() >= 1.0 - PARALLEL {
                    // In a plane parallel to the working plane: G2 / G3.
                    let ccw = n[k] > 0.0;
                    self.plane_circle(parts, c, ccw);
                    return Ok(Some((c, unit(k) * n[k].signum())));
                }
                let u = (s - c).normalize();
                let v = n.cross(&u);
                let w = e - c;
                let mut sweep = w.dot(&v).atan2(w.dot(&u));
                if sweep <= 0.0 {
                    sweep += std::f64::consts::TAU;
                }
                parts.mv.circle = Some(SpaceCircle {
                    center: c,
                    normal: n,
                    sweep,
                });
                parts.mv.center = [None; 3];
                Ok(Some((c, n)))
            }
            Some(CircleMode::Tangential) => {
                let e = self.end_point(start, &parts.mv);
                let Some(t) = self.tangent else {
                    return Err(circle_error(
                        "CT: no path before it to continue tangentially".into(),
                    ));
                };
                let t2 = [t[p], t[q]];
                let tn = t2[0].hypot(t2[1]);
                if tn <= 0.0 {
                    return Err(circle_error(
                        "CT: the path before runs along the plane's normal".into(),
                    ));
                }
                let t2 = [t2[0] / tn, t2[1] / tn];
                let left = [-t2[1], t2[0]];
                let w = [e[p] - s[p], e[q] - s[q]];
                let side = left[0] * w[0] + left[1] * w[1];
                let w2 = w[0] * w[0] + w[1] * w[1];
                self.set_absolute_end(parts, e);
                if side.abs() <= 1e-9 * w2.sqrt().max(1.0) {
                    // The end point on the tangent: a straight line.
                    parts.mv.center = [None; 3];
                    self.block
                        .commands
                        .push(Command::Interpolation(MotionMode::Linear));
                    return Ok(None);
                }
                // The centre on the normal to the tangent at the start,
                // as far from the end as from the start.
                let lambda = w2 / (2.0 * side);
                let mut c = s;
                c[p] += lambda * left[0];
                c[q] += lambda * left[1];
                let ccw = lambda > 0.0;
                self.plane_circle(parts, c, ccw);
                Ok(Some((c, unit(k) * if ccw { 1.0 } else { -1.0 })))
            }
            None => {
                // G2 / G3: the centre for the tangent afterwards.
                if !arc_motion {
                    return Ok(None);
                }
                let ccw = self.motion == MotionMode::Ccw;
                let e = self.end_point(start, &parts.mv);
                let normal = unit(k) * if ccw { 1.0 } else { -1.0 };
                if parts.center_written.iter().any(Option::is_some) {
                    let mut c = s;
                    for (i, w) in parts.center_written.iter().enumerate() {
                        if let Some((v, mode)) = *w {
                            c[i] = if mode == Some(PositionMode::Ac) {
                                v
                            } else {
                                s[i] + v
                            };
                        }
                    }
                    return Ok(Some((c, normal)));
                }
                Ok(parts.mv.radius.and_then(|r| {
                    radius_center([s[p], s[q]], [e[p], e[q]], r, ccw).map(|c2| {
                        let mut c = s;
                        c[p] = c2[0];
                        c[q] = c2[1];
                        (c, normal)
                    })
                }))
            }
        }
    }

    /// AR=: with the end point the centre follows, with the centre the
    /// end point (closed forms in the working plane).
    fn opening_angle(
        &mut self,
        line: u32,
        s: Vec3,
        ar: f64,
        span: Span,
        parts: &mut Parts,
    ) -> Result<(Vec3, Vec3), Alarm> {
        let [p, q, k] = self.plane.axes();
        let ccw = self.motion == MotionMode::Ccw;
        if !(ar > 0.0 && ar < 360.0) {
            return Err(Self::alarm(
                line,
                14040,
                Some(span),
                format!("AR={ar}: the opening angle of a circle lies between 0 and 360 degrees"),
            ));
        }
        let has_center = parts.center_written.iter().any(Option::is_some);
        let has_end = parts.mv.targets[p].is_some() || parts.mv.targets[q].is_some();
        let normal = unit(k) * if ccw { 1.0 } else { -1.0 };
        let start3 = [s[0], s[1], s[2]];
        if has_center == has_end {
            return Err(Self::alarm(
                line,
                14040,
                Some(span),
                "AR= takes either the centre (I, J, K) or the end point, one of them".into(),
            ));
        }
        let sign = if ccw { 1.0 } else { -1.0 };
        if has_center {
            let mut c = s;
            for (i, w) in parts.center_written.iter().enumerate() {
                if let Some((v, mode)) = *w {
                    c[i] = if mode == Some(PositionMode::Ac) {
                        v
                    } else {
                        s[i] + v
                    };
                }
            }
            let (sin, cos) = (sign * ar).to_radians().sin_cos();
            let (dx, dy) = (s[p] - c[p], s[q] - c[q]);
            let mut e = self.end_point(&start3, &parts.mv);
            e[p] = c[p] + cos * dx - sin * dy;
            e[q] = c[q] + sin * dx + cos * dy;
            self.set_absolute_end(parts, e);
            self.plane_circle(parts, c, ccw);
            return Ok((c, normal));
        }
        let e = self.end_point(&start3, &parts.mv);
        let w = [e[p] - s[p], e[q] - s[q]];
        let d = w[0].hypot(w[1]);
        if d <= 0.0 {
            return Err(Self::alarm(
                line,
                14040,
                Some(span),
                "AR= with the end point on the start point".into(),
            ));
        }
        // The centre on the chord's bisector, at (d/2)·cot(AR/2) from the
        // chord's middle: left of the chord for G3 (right for G2); an
        // angle beyond 180° puts it on the other side by itself.
        let half = (ar / 2.0).to_radians();
        let h = d / 2.0 * half.cos() / half.sin();
        let left = [-w[1] / d, w[0] / d];
        let mut c = s;
        c[p] = (s[p] + e[p]) / 2.0 + sign * h * left[0];
        c[q] = (s[q] + e[q]) / 2.0 + sign * h * left[1];
        self.set_absolute_end(parts, e);
        self.plane_circle(parts, c, ccw);
        Ok((c, normal))
    }

    /// The block's X, Y, Z targets as the absolute point `e`.
    fn set_absolute_end(&self, parts: &mut Parts, e: Vec3) {
        for k in 0..3 {
            parts.mv.targets[k] = Some(Target {
                value: e[k],
                mode: TargetMode::Absolute,
                span: parts.mv.targets[k].map_or(parts.mv.span, |t| t.span),
            });
        }
    }

    /// The block as G2 / G3 about the absolute centre `c` in the plane.
    fn plane_circle(&mut self, parts: &mut Parts, c: Vec3, ccw: bool) {
        let [p, q, _] = self.plane.axes();
        parts.mv.center = [None; 3];
        parts.mv.center[p] = Some(c[p]);
        parts.mv.center[q] = Some(c[q]);
        parts.mv.center_absolute = true;
        parts.mv.radius = None;
        self.block.commands.push(Command::Interpolation(if ccw {
            MotionMode::Ccw
        } else {
            MotionMode::Cw
        }));
        if self.circle.is_none() {
            // AR= under G2 / G3: the modal motion stays.
            self.motion = if ccw { MotionMode::Ccw } else { MotionMode::Cw };
        }
    }

    /// The path's direction at the end of the move just run (program
    /// coordinates), for a CT after it.
    fn track_tangent(
        &mut self,
        start: &Joints3,
        end: &Joints3,
        circle: Option<(Vec3, Vec3)>,
        parts: &Parts,
    ) {
        let s = Vec3::new(start[0], start[1], start[2]);
        let e = Vec3::new(end[0], end[1], end[2]);
        if (e - s).norm() <= 1e-12 && parts.mv.turns.is_none() {
            return;
        }
        let t = match circle {
            Some((c, n)) => n.cross(&(e - c)),
            None => e - s,
        };
        if t.norm() > 0.0 && t.iter().all(|v| v.is_finite()) {
            self.tangent = Some(t.normalize());
        }
    }

    /// ORIRESET(A, B, C) (JP09; brief §4): the rotary axes to the angles
    /// given (an angle left out: 0, the kernel's reading of the machine
    /// data's initial position), the tool tip staying where it is under
    /// TRAORI; without TRAORI alarm 14101.
    fn orireset(
        &mut self,
        machine: &Machine,
        line: u32,
        angles: &[Option<f64>],
        span: Span,
        parts: &mut Parts,
    ) -> Result<(), Alarm> {
        if self.tcp.is_none() {
            return Err(Self::alarm(
                line,
                14101,
                Some(span),
                "ORIRESET needs an orientation transformation (TRAORI) in force".into(),
            ));
        }
        if angles.len() > machine.rotary.len() {
            return Err(Self::alarm(
                line,
                14101,
                Some(span),
                format!(
                    "ORIRESET: {} angles for {} rotary axes",
                    angles.len(),
                    machine.rotary.len()
                ),
            ));
        }
        if parts.vector.iter().any(Option::is_some) || parts.euler.iter().any(Option::is_some) {
            return Err(Self::alarm(
                line,
                14101,
                Some(span),
                "ORIRESET and an orientation (A3 B3 C3 / A2 B2 C2) in one block".into(),
            ));
        }
        for k in 0..machine.rotary.len() {
            let i = machine.rotary_index(k);
            parts.mv.targets[i] = Some(Target {
                value: angles.get(k).copied().flatten().unwrap_or(0.0),
                mode: TargetMode::Absolute,
                span,
            });
        }
        parts.mv.span = span;
        parts.moves = true;
        Ok(())
    }
}

/// Program coordinates of X, Y, Z (and the other axes).
type Joints3 = fiveaxis_machine::Joints;

/// The centre of a circle of radius `r` (negative: more than 180°) from
/// `s` to `e` in the plane, turning counter-clockwise or not.
pub(crate) fn radius_center(s: [f64; 2], e: [f64; 2], r: f64, ccw: bool) -> Option<[f64; 2]> {
    let w = [e[0] - s[0], e[1] - s[1]];
    let d = w[0].hypot(w[1]);
    let half = d / 2.0;
    if d <= 0.0 || r.abs() < half {
        return None;
    }
    let h = (r * r - half * half).max(0.0).sqrt();
    let left = [-w[1] / d, w[0] / d];
    // Left of the chord: a short counter-clockwise or a long clockwise arc.
    let sign = if ccw == (r > 0.0) { 1.0 } else { -1.0 };
    Some([
        (s[0] + e[0]) / 2.0 + sign * h * left[0],
        (s[1] + e[1]) / 2.0 + sign * h * left[1],
    ])
}

/// An alarm of CYCLE800's positioning under the cycle's numbers (brief
/// §8, secondary sources): no rotary axes 61153, no solution inside the
/// axis limits 61190.
fn swivel_alarm(alarm: Alarm, line: u32) -> Alarm {
    let number = match alarm.condition {
        Condition::TcpcWithoutRotaryAxis => 61153,
        Condition::ToolDirectionUnreachable => 61190,
        _ => return alarm,
    };
    Front::alarm(
        line,
        number,
        alarm.span,
        format!("CYCLE800: {}", alarm.message),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radius_center_sides() {
        // A quarter from (10, 0) to (0, 10): counter-clockwise about the
        // origin with CR=10, clockwise about (10, 10).
        let c = radius_center([10.0, 0.0], [0.0, 10.0], 10.0, true).expect("a centre");
        assert!(c[0].abs() < 1e-12 && c[1].abs() < 1e-12, "{c:?}");
        let c = radius_center([10.0, 0.0], [0.0, 10.0], 10.0, false).expect("a centre");
        assert!(
            (c[0] - 10.0).abs() < 1e-12 && (c[1] - 10.0).abs() < 1e-12,
            "{c:?}"
        );
        // CR=-10: the long way, the centre on the other side.
        let c = radius_center([10.0, 0.0], [0.0, 10.0], -10.0, true).expect("a centre");
        assert!(
            (c[0] - 10.0).abs() < 1e-12 && (c[1] - 10.0).abs() < 1e-12,
            "{c:?}"
        );
        assert!(radius_center([0.0, 0.0], [30.0, 0.0], 10.0, true).is_none());
    }

    #[test]
    fn frame_then_scales_later_shifts() {
        let scale = Frame {
            scale: [2.0, 3.0, 1.0],
            ..Frame::IDENTITY
        };
        let shift = Frame::rigid(Vec3::new(1.0, 1.0, 1.0), Rotation3::identity());
        let f = scale.then(&shift);
        assert_eq!(f.translation, Vec3::new(2.0, 3.0, 1.0));
        let mirror = Frame {
            mirror: [true, false, false],
            ..Frame::IDENTITY
        };
        let f = mirror.then(&shift).then(&mirror);
        assert_eq!(f.translation, Vec3::new(-1.0, 1.0, 1.0));
        assert_eq!(f.mirror, [false; 3]);
    }
}
