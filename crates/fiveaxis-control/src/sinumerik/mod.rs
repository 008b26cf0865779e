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
//!   `$P_TOOLNO`, `$TC_DP…`).
//! * `swivel.rs`: CYCLE800's rotation from its mode and angles.
//! * `cycles.rs`: the drilling, tapping, boring, pattern and engraving
//!   cycles as their elementary moves.

pub(crate) mod cycles;
mod swivel;
pub(crate) mod system;

use fiveaxis_gcode::Span;
use fiveaxis_machine::{MAX_AXES, Machine, Offsets, Vec3};
use fiveaxis_sinumerik::{Action, Executed, PositionMode, Value};
use nalgebra::Rotation3;

use crate::alarm::{Alarm, AlarmCode, Condition};
use crate::command::{
    Command, CommandBlock, CutterSide, Frame, Move, Suppress, Target, TargetMode, WorkOffset,
};
use crate::controller::{Controller, Flow};
use crate::modal::{CuttingMode, Distance, FeedMode, MotionMode, Plane, TcpcType};
use crate::segment::Segment;

/// Millimetres in an inch.
const MM_PER_INCH: f64 = 25.4;

/// The instructions and cycles the front end carries out (what
/// [`fiveaxis_sinumerik::System::is_builtin`] answers).
pub(crate) fn is_builtin(name: &str) -> bool {
    cycles::is_cycle(name)
        || matches!(
            name,
            "CYCLE800" | "CYCLE832" | "MSG" | "SETAL" | "TRAORI" | "TRAFOOF" | "FGROUP" | "STOPRE"
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
    "ORIWKS",
    "ORIMKS",
    "ORIVECT",
    "ORIAXES",
    "ORIPLANE",
    "ORISOF",
    "ORISON",
    "NORM",
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
    "PAROTOF",
    "TOROTOF",
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

/// What the front end keeps between blocks.
#[derive(Debug)]
pub(crate) struct Front {
    /// G70 / G700: lengths are inches.
    inch: bool,
    /// G700: feeds are inches per minute too.
    inch_feed: bool,
    plane: Plane,
    motion: MotionMode,
    distance: Distance,
    /// TRAORI in force, and how the last block gave the orientation.
    tcp: Option<TcpcType>,
    /// The programmable frame (TRANS, ROT, ATRANS, AROT).
    programmable: Frame,
    /// The swivel frame of CYCLE800.
    swivel: Option<Frame>,
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
    cycle: Option<(String, Vec<Option<Value>>, Span)>,
    dwell: bool,
    dwell_value: Option<(f64, bool, Span)>,
}

impl Front {
    /// A front end at power-on (G71 G17 G0 G90, no frames).
    pub(crate) fn new() -> Self {
        Self {
            inch: false,
            inch_feed: false,
            plane: Plane::Xy,
            motion: MotionMode::Rapid,
            distance: Distance::Absolute,
            tcp: None,
            programmable: Frame::IDENTITY,
            swivel: None,
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
            self.frame_op(machine, op, &parts, span)?;
            self.push_frames();
            // The frame's words are not a move.
            parts.moves = false;
        }
        if let Some((args, span)) = parts.swivel.take() {
            return self.swivel(ctrl, line, &args, span, out);
        }
        if parts.moves {
            self.orientation(line, &mut parts)?;
            self.block.commands.push(Command::Move(parts.mv));
        }
        let flow = ctrl.run_block(&self.block, out)?;
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
                if mode == Some(PositionMode::Ac) {
                    parts.mv.center_absolute = true;
                }
                parts.mv.span = span;
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
            "A3" | "B3" | "C3" => {
                let k = usize::from(address.as_bytes()[0] - b'A');
                parts.vector[k] = Some(number(address)?);
                parts.moves = true;
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
            17 | 18 | 19 => {
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
            54..=57 => cmds.push(Command::WorkOffset(WorkOffset::Standard((n - 54) as u8))),
            500 => cmds.push(Command::WorkOffset(WorkOffset::Null)),
            505..=599 => cmds.push(Command::WorkOffset(WorkOffset::Extended((n - 504) as u8))),
            60 => cmds.push(Command::PathMode(CuttingMode::ExactStop)),
            64 | 641 | 642 | 643 | 644 | 645 => cmds.push(Command::PathMode(CuttingMode::Cutting)),
            // Exact stop windows, corner behaviour of radius compensation,
            // constant cutting rate off: no change of path.
            601 | 602 | 603 | 450 | 451 | 97 => {}
            70 | 700 => {
                self.inch = true;
                self.inch_feed = n == 700;
            }
            71 | 710 => {
                self.inch = false;
                self.inch_feed = false;
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
            "ORIEULER" => self.euler = true,
            "ORIRPY" => self.euler = false,
            "STOPRE" | "FGROUP" | "CYCLE832" => {}
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
                    format!("{name} is not an instruction this control carries out"),
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

    /// TRANS, ATRANS, ROT, AROT with the block's words (ONE p309, p316).
    fn frame_op(
        &mut self,
        machine: &Machine,
        op: FrameOp,
        parts: &Parts,
        span: Span,
    ) -> Result<(), Alarm> {
        let _ = span;
        let value = |i: usize| parts.raw[i];
        let length = |i: usize| parts.raw[i].map(|v| self.length(v));
        match op {
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
                if op == FrameOp::Trans {
                    self.programmable = Frame {
                        translation: v,
                        rotation: Rotation3::identity(),
                        axis_shift: shift,
                    };
                } else {
                    let p = &mut self.programmable;
                    p.translation += p.rotation * v;
                    for (a, s) in p.axis_shift.iter_mut().zip(shift) {
                        *a += s;
                    }
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
                if op == FrameOp::Rot {
                    self.programmable = Frame {
                        translation: Vec3::zeros(),
                        rotation: rot,
                        axis_shift: [0.0; MAX_AXES],
                    };
                } else {
                    self.programmable.rotation *= rot;
                }
            }
        }
        Ok(())
    }

    fn push_frames(&mut self) {
        self.block
            .commands
            .push(Command::ProgrammableFrame(self.programmable));
    }

    /// The tool orientation of a move under TRAORI: rotary axis words, a
    /// vector A3 B3 C3 or angles A2 B2 C2.
    fn orientation(&mut self, line: u32, parts: &mut Parts) -> Result<(), Alarm> {
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
            let Some(rotation) = swivel::rotation(kind, angles) else {
                return Err(Self::alarm(
                    line,
                    61184,
                    Some(span),
                    "CYCLE800: direct rotary angles (_MODE 192) are not carried out yet".into(),
                ));
            };
            let x0 = Vec3::new(l(4), l(5), l(6));
            let x1 = Vec3::new(l(10), l(11), l(12));
            let frame = Frame {
                translation: x0 + rotation * x1,
                rotation,
                axis_shift: [0.0; MAX_AXES],
            };
            let additive = num(2).is_some_and(|st| (st as i64) % 10 == 1);
            let frame = match (additive, self.swivel) {
                (true, Some(old)) => Frame {
                    translation: old.translation + old.rotation * frame.translation,
                    rotation: old.rotation * frame.rotation,
                    axis_shift: [0.0; MAX_AXES],
                },
                _ => frame,
            };
            // The retract before the swivel (_FR): 1 Z, 2 Z then X Y, to
            // the first reference position (the retract positions of the
            // swivel data record, $TC_CARR38–40, are the machine file's
            // reference position 1 here).
            let fr = num(0).unwrap_or(0.0) as i64;
            if fr == 1 || fr == 2 {
                self.retract(ctrl, line, fr == 2, span, out)?;
            } else if fr != 0 {
                return Err(Self::alarm(
                    line,
                    61186,
                    Some(span),
                    format!("CYCLE800: retract mode _FR={fr} is not carried out yet"),
                ));
            }
            self.swivel = Some(frame);
            self.block.clear(line);
            self.block.commands.push(Command::SwivelFrame(Some(frame)));
            let dir = num(13).unwrap_or(0.0);
            if dir != 0.0 {
                self.block.commands.push(Command::AlignTool {
                    higher: dir > 0.0,
                    span,
                });
            }
            ctrl.run_block(&self.block, out)?
        };
        Ok(flow)
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
            suppress: Suppress::Frames,
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
            for i in 0..2 {
                mv.targets[i] = Some(Target {
                    value: reference[i],
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
        let position = ctrl.programmed_position();
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
            Self::alarm(line, e.alarm, Some(span), format!("{name}: {}", e.message))
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
                let p = ctrl.programmed_position();
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
