//! The HEIDENHAIN TNC front end: what the blocks of a Klartext program
//! (`fiveaxis-heidenhain` runs their language) mean on the control, as
//! the kernel's control-neutral commands (`crate::command`).
//!
//! Sources are the TNC 640 / TNC 620 / iTNC 530 user's manuals as the
//! design brief (`sinumerik-heidenhain-brief.md` §9) cites them; what the
//! brief marks unverified, and the kernel's own readings, are named where
//! they are used and listed in `docs/heidenhain.md`.
//!
//! What the front end keeps between blocks:
//!
//! * the working plane (from `TOOL CALL`'s spindle axis), the pole `CC`,
//!   the radius compensation `RL` / `RR` / `R0`, the feed `F` (modal;
//!   `FMAX` holds for its block only), `M126` shortest rotary paths;
//! * the transformations: the datum shift (cycle 7), the tilted working
//!   plane (`PLANE`, cycle 19) and, inside it, mirror (8), rotation (10)
//!   and scaling (11, 26). A datum shift defined with no tilted plane in
//!   force is the origin the plane turns about; one defined in a tilted
//!   plane shifts in it (iTNC 530 manual, "Working plane": "the TNC tilts
//!   about the active datum");
//! * tool centre point control (`M128`, `FUNCTION TCPM`);
//! * the machining cycle last defined (`CYCL DEF 200` …), called by
//!   `CYCL CALL`, `M99` (one block) and `M89` (modal);
//! * the stock (`BLK FORM`), for `view`.

pub(crate) mod cycles;

use fiveaxis_gcode::Span;
use fiveaxis_heidenhain::{Executed, Kind, Tool};
use fiveaxis_machine::{Control, Joints, MAX_AXES, Vec3};
use nalgebra::Rotation3;

use crate::alarm::{Alarm, Condition};
use crate::command::{
    Command, CommandBlock, CutterSide, Frame, Move, Suppress, Target, TargetMode,
};
use crate::controller::{Controller, Flow};
use crate::modal::{MotionMode, Plane, TcpcType};
use crate::segment::Segment;

/// 25.4 mm to the inch.
const MM_PER_INCH: f64 = 25.4;

/// Two angles or lengths closer than this are the same (a circle's end
/// on its radius, a vector's length).
const GEOMETRY_TOLERANCE: f64 = 1e-9;

/// A circle's end point may lie off the circle about the pole by this much
/// before the block is refused (the TNC's own check is a machine
/// parameter; 0.016 mm is FANUC's default arc tolerance in the kernel).
const CIRCLE_TOLERANCE: f64 = 0.016;

/// `PLANE … MOVE DIST`: the largest turn of a rotary axis in one step
/// of the turn about the point above the tip, degrees (a 50 mm distance
/// leaves the tip 0.002 mm inside its circle between steps).
const DIST_STEP: f64 = 1.0;

/// Most steps of one such turn.
const MAX_DIST_STEPS: usize = 3600;

/// The stock of `BLK FORM 0.1 / 0.2`: its minimum and maximum corner in
/// workpiece coordinates, mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stock {
    /// `BLK FORM 0.1`.
    pub min: [f64; 3],
    /// `BLK FORM 0.2`.
    pub max: [f64; 3],
}

/// The shape of a path in the working plane, for roundings and chamfers.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Shape {
    /// A straight line.
    Line,
    /// A circular arc about `centre`.
    Arc { centre: [f64; 2], ccw: bool },
    /// A move that is no contour element (rotary axes alone, machine
    /// coordinates): no rounding or chamfer joins it.
    Other,
}

/// A path block held back, in program coordinates.
#[derive(Clone, Copy, Debug)]
struct Held {
    line: u32,
    start: Joints,
    end: Joints,
    shape: Shape,
    /// The block calls the machining cycle (`M99`, `M89`).
    call: bool,
}

/// `RND R…` or `CHF …` waiting for the path after it.
#[derive(Clone, Copy, Debug)]
struct Corner {
    line: u32,
    /// The rounding radius, or the chamfer's length.
    size: f64,
    chamfer: bool,
    /// The feed of the rounding or chamfer (`F` in its block).
    feed: Option<f64>,
}

/// What the front end keeps between blocks.
#[derive(Debug)]
pub(crate) struct Front {
    /// `BEGIN PGM … INCH`: lengths are inches.
    inch: bool,
    /// The working plane (from the spindle axis of `TOOL CALL`).
    plane: Plane,
    /// The pole `CC` in the plane's two axes, program coordinates.
    pole: Option<[f64; 2]>,
    /// The radius compensation in force.
    comp: CutterSide,
    /// The feed in force, mm/min (0 before any).
    feed: f64,
    /// The feed of the last `TOOL CALL` (`F AUTO`).
    tool_feed: f64,
    /// `M126`: rotary axes take the shorter way.
    shortest: bool,
    /// Tool centre point control in force (`M128`, `FUNCTION TCPM`), and
    /// how the orientation was last given.
    tcp: Option<TcpcType>,
    /// Datum shift outside the tilted plane (X, Y, Z, then rotary axes by
    /// joint index).
    shift: [f64; MAX_AXES],
    /// Datum shift inside the tilted plane.
    inner_shift: [f64; 3],
    /// Cycle 8 mirror, per axis.
    mirror: [bool; 3],
    /// Cycle 10 rotation about the tool axis, degrees.
    rotation: f64,
    /// Cycle 11 / 26 scale factors.
    scale: [f64; 3],
    /// The tilted working plane's rotation, if one is in force.
    tilt: Option<Rotation3<f64>>,
    /// The tolerance of cycle 32, mm (none: off).
    tolerance: Option<f64>,
    /// The machining cycle last defined: its number and Q parameters.
    cycle: Option<(u32, Vec<(u32, f64)>)>,
    /// `M89`: the cycle is called after every positioning block.
    modal_call: bool,
    /// The `PATTERN DEF` in force.
    pattern: Vec<cycles::PatternItem>,
    /// The stock, once both `BLK FORM` blocks are read.
    pub(crate) stock: Option<Stock>,
    stock_min: Option<[f64; 3]>,
    /// Named tools met so far with the number each stands for.
    tool_names: Vec<(String, u32)>,
    /// The tool of the last `TOOL CALL` and its `DR`.
    tool: u32,
    delta_length: f64,
    delta_radius: f64,
    /// The direction of the path at the end of the last move, in the
    /// plane (for `CT`).
    tangent: Option<[f64; 2]>,
    /// Axis positions `PLANE … STAY` computed, for Q120 (A), Q121 (B),
    /// Q122 (C): the runner writes them into the program's parameters.
    pub(crate) stay: Option<[Option<f64>; 3]>,
    /// A path block held back until the next block is known (a rounding
    /// or a chamfer after it shortens it), with its commands.
    held: Option<Held>,
    held_block: CommandBlock,
    /// `RND` / `CHF` read after the held path, for the next path.
    corner: Option<Corner>,
    /// The block being built, and the steps of a cycle.
    block: CommandBlock,
    steps: Vec<cycles::Step>,
    points: Vec<[f64; 3]>,
    /// Notes for the run's notes.
    pub(crate) notes: Vec<String>,
}

/// A HEIDENHAIN alarm: the kernel's condition under its FX code (the TNC
/// shows texts, not numbers).
fn alarm(line: u32, condition: Condition, span: Option<Span>, message: String) -> Alarm {
    Alarm {
        condition,
        code: condition.code(Control::Heidenhain),
        line,
        span,
        message,
    }
}

fn about(axis: usize, degrees: f64) -> Rotation3<f64> {
    let v = match axis {
        0 => Vec3::x_axis(),
        1 => Vec3::y_axis(),
        _ => Vec3::z_axis(),
    };
    Rotation3::from_axis_angle(&v, degrees.to_radians())
}

/// The rotation whose columns are the tilted plane's X and Z (Y their
/// cross product); `None` when they are zero or parallel.
fn from_x_and_z(x: Vec3, z: Vec3) -> Option<Rotation3<f64>> {
    let z = z.try_normalize(GEOMETRY_TOLERANCE)?;
    let x = (x - z * x.dot(&z)).try_normalize(GEOMETRY_TOLERANCE)?;
    let y = z.cross(&x);
    Some(Rotation3::from_matrix_unchecked(
        nalgebra::Matrix3::from_columns(&[x, y, z]),
    ))
}

/// The angle of `v` in the plane, degrees in (−180, 180].
fn angle_of(v: [f64; 2]) -> f64 {
    v[1].atan2(v[0]).to_degrees()
}

impl Front {
    /// A front end at power-on: plane XY, no transformations, no tool.
    pub(crate) fn new() -> Self {
        Self {
            inch: false,
            plane: Plane::Xy,
            pole: None,
            comp: CutterSide::Off,
            feed: 0.0,
            tool_feed: 0.0,
            shortest: false,
            tcp: None,
            shift: [0.0; MAX_AXES],
            inner_shift: [0.0; 3],
            mirror: [false; 3],
            rotation: 0.0,
            scale: [1.0; 3],
            tilt: None,
            tolerance: None,
            cycle: None,
            modal_call: false,
            pattern: Vec::new(),
            stock: None,
            stock_min: None,
            tool_names: Vec::new(),
            tool: 0,
            delta_length: 0.0,
            delta_radius: 0.0,
            tangent: None,
            stay: None,
            held: None,
            held_block: CommandBlock::default(),
            corner: None,
            block: CommandBlock::default(),
            steps: Vec::new(),
            points: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// The system data of the front end's own state for `FN 18: SYSREAD`
    /// (technical manual TNC 426 / 430, p. 7-30): ID20 NR3 the tool axis,
    /// ID210 the coordinate
    /// transformations (NR2 the rotation of cycle 10, NR3 the mirrored
    /// axes as bits 0–2 for X Y Z, NR4 the scale factor of axis IDX, NR6
    /// −1 with a tilted working plane in force, else 0), ID214 NR8 the
    /// tolerance of cycle 32, ID220 NR2 the datum shift of axis IDX, ID280
    /// NR1 −1 with M128 / TCPM in force, else 0. `None` for others.
    pub(crate) fn sysread(&self, group: u32, number: u32, index: Option<u32>) -> Option<f64> {
        let i = index.unwrap_or(1).checked_sub(1).map(|i| i as usize);
        let flag = |on: bool| if on { -1.0 } else { 0.0 };
        match (group, number) {
            // ID20 NR3: the tool axis of the last TOOL CALL, 0 X, 1 Y, 2 Z.
            (20, 3) => Some(self.axes()[2] as f64),
            (210, 2) => Some(self.rotation),
            (210, 3) => Some(
                self.mirror
                    .iter()
                    .enumerate()
                    .map(|(k, &m)| if m { f64::from(1u8 << k) } else { 0.0 })
                    .sum(),
            ),
            (210, 4) => i.filter(|&i| i < 3).map(|i| self.scale[i]),
            (210, 6) => Some(flag(self.tilt.is_some())),
            (214, 8) => Some(self.tolerance.unwrap_or(0.0)),
            (220, 2) => i
                .filter(|&i| i < MAX_AXES)
                .map(|i| self.shift[i] + if i < 3 { self.inner_shift[i] } else { 0.0 }),
            (280, 1) => Some(flag(self.tcp.is_some())),
            _ => None,
        }
    }

    /// `BEGIN PGM … INCH`: the program's lengths are inches.
    pub(crate) fn set_inch(&mut self, inch: bool) {
        self.inch = inch;
    }

    fn length(&self, x: f64) -> f64 {
        if self.inch { x * MM_PER_INCH } else { x }
    }

    /// Carries out one executed block on the controller; its segments are
    /// appended to `out`.
    pub(crate) fn run(
        &mut self,
        ex: &Executed,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let line = ex.line;
        self.block.clear(line);
        self.block.number = ex.block_number;
        self.stay = None;
        let path = matches!(
            ex.kind,
            Kind::Line
                | Kind::LineNormal
                | Kind::Circle
                | Kind::CircleRadius
                | Kind::CircleTangent
                | Kind::LinePolar
                | Kind::CirclePolar
                | Kind::CircleTangentPolar
                | Kind::Rounding
                | Kind::Chamfer
                | Kind::Centre
        );
        if !path {
            let flow = self.finish(ctrl, out)?;
            if flow == Flow::End {
                return Ok(flow);
            }
        }
        match ex.kind {
            Kind::Empty | Kind::Stop => self.plain(ex, ctrl, out),
            Kind::Line | Kind::LineNormal => self.line(ex, ctrl, out),
            Kind::Centre => {
                self.centre(ex, ctrl)?;
                self.m_only(ex, ctrl, out)
            }
            Kind::Circle | Kind::CircleRadius | Kind::CircleTangent => self.circle(ex, ctrl, out),
            Kind::LinePolar | Kind::CirclePolar | Kind::CircleTangentPolar => {
                self.polar(ex, ctrl, out)
            }
            Kind::Rounding | Kind::Chamfer => self.corner(ex),
            Kind::Approach | Kind::Depart => Err(alarm(
                line,
                Condition::ImproperAddress,
                None,
                format!(
                    "{} (approach and departure with radius compensation) is not read by the kernel: \
                     program the approach with L and CT blocks (docs/heidenhain.md)",
                    if ex.kind == Kind::Approach {
                        "APPR"
                    } else {
                        "DEP"
                    }
                ),
            )),
            Kind::ToolCall => self.tool_call(ex, ctrl, out),
            Kind::ToolDef => self.m_only(ex, ctrl, out),
            Kind::BlockForm => {
                self.block_form(ex)?;
                self.m_only(ex, ctrl, out)
            }
            Kind::CycleDef => self.cycle_def(ex, ctrl, out),
            Kind::CycleCall => {
                let flow = self.m_only(ex, ctrl, out)?;
                self.call_cycle(ex, ctrl, out, ex.has_key("PAT"))?;
                Ok(flow)
            }
            Kind::PatternDef => {
                self.pattern.clear();
                for item in &ex.pattern {
                    self.pattern.push(cycles::PatternItem {
                        kind: item.kind.clone(),
                        words: item
                            .words
                            .iter()
                            .map(|w| (w.address.clone(), w.value))
                            .collect(),
                    });
                }
                self.m_only(ex, ctrl, out)
            }
            Kind::Plane => self.plane_function(ex, ctrl, out),
            Kind::Tcpm => {
                if self.tcp.is_none() {
                    self.set_tcp(Some(TcpcType::Angles), Span::default());
                }
                let great_circle = ex.has_key("PATHCTRL VECTOR");
                self.block
                    .commands
                    .push(Command::OrientationPath { great_circle });
                if ex.has_key("F CONT") {
                    self.notes.push(format!(
                        "line {line}: FUNCTION TCPM F CONT (feed of the axes) read; the kernel's feed is the tip's"
                    ));
                }
                self.m_only(ex, ctrl, out)
            }
            Kind::TcpmReset => {
                self.set_tcp(None, Span::default());
                self.m_only(ex, ctrl, out)
            }
        }
    }

    /// Where the next path starts, in program coordinates: the end of the
    /// path held back, else where the controller stands.
    fn start(&self, ctrl: &Controller<'_>) -> Joints {
        self.held.map_or_else(|| ctrl.program_position(), |h| h.end)
    }

    /// `RND R…` / `CHF …`: joins the path held back and the next one.
    fn corner(&mut self, ex: &Executed) -> Result<Flow, Alarm> {
        let line = ex.line;
        let chamfer = ex.kind == Kind::Chamfer;
        let name = if chamfer { "CHF" } else { "RND" };
        let size = if chamfer {
            ex.word("CHF").or_else(|| ex.words.first())
        } else {
            ex.word("R")
        }
        .ok_or_else(|| {
            alarm(
                line,
                Condition::NoDataAfterAddress,
                None,
                format!("{name} needs its size"),
            )
        })?;
        let size = self.length(size.value);
        if !(size.is_finite() && size > 0.0) {
            return Err(alarm(
                line,
                Condition::ValueOutOfRange,
                None,
                format!("{name} {size}: the size must be greater than 0"),
            ));
        }
        if !self.held.is_some_and(|h| h.shape != Shape::Other) || self.corner.is_some() {
            return Err(alarm(
                line,
                Condition::CrcNoIntersection,
                None,
                format!("{name} needs a contour element (L, C, CR, CT, LP, CP) right before it"),
            ));
        }
        let feed = ex.word("F").map(|f| self.length(f.value));
        self.corner = Some(Corner {
            line,
            size,
            chamfer,
            feed,
        });
        Ok(Flow::Next)
    }

    /// Holds the path block just built back and carries out the one held
    /// before (with a rounding or chamfer between them if one was
    /// programmed). A move that is no contour element is carried out at
    /// once.
    fn hold(
        &mut self,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
        held: Held,
    ) -> Result<Flow, Alarm> {
        // The new block waits aside while the one before runs (its cycle
        // call builds blocks in `self.block`).
        let mut incoming = std::mem::take(&mut self.block);
        let result = self.release(ctrl, out, &held);
        std::mem::swap(&mut incoming, &mut self.held_block);
        // The buffers are reused from block to block.
        self.block = incoming;
        let mut flow = result?;
        self.held = Some(held);
        if held.shape == Shape::Other {
            let next = self.run_held(ctrl, out)?;
            if flow == Flow::Next {
                flow = next;
            }
        }
        Ok(flow)
    }

    /// Carries out the path held back before `next`, with the rounding or
    /// chamfer between them if one was programmed.
    fn release(
        &mut self,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
        next: &Held,
    ) -> Result<Flow, Alarm> {
        let Some(corner) = self.corner.take() else {
            return self.run_held(ctrl, out);
        };
        let Some(prev) = self.held.take() else {
            return Err(alarm(
                corner.line,
                Condition::CrcNoIntersection,
                None,
                "a rounding or chamfer needs a contour element before it".into(),
            ));
        };
        if next.shape == Shape::Other {
            return Err(alarm(
                next.line,
                Condition::CrcNoIntersection,
                None,
                "a rounding or chamfer needs a contour element (L, C, CR, CT, LP, CP) after it"
                    .into(),
            ));
        }
        let joint = self.join(&prev, next, &corner)?;
        self.trim_held(&prev, joint.t1);
        self.held = Some(prev);
        let flow = self.run_held(ctrl, out)?;
        // The rounding's arc or the chamfer's line.
        let [a, b, _] = self.axes();
        self.block.clear(corner.line);
        let mut mv = Move::default();
        for (k, i) in [a, b].into_iter().enumerate() {
            mv.targets[i] = Some(Target {
                value: joint.t2[k],
                mode: TargetMode::Absolute,
                span: Span::default(),
            });
        }
        let interpolation = match joint.centre {
            Some((c, ccw)) => {
                self.set_centre(&mut mv, [a, b], c);
                if ccw { MotionMode::Ccw } else { MotionMode::Cw }
            }
            None => MotionMode::Linear,
        };
        self.block
            .commands
            .push(Command::Interpolation(interpolation));
        self.block.commands.push(Command::Feed {
            value: corner.feed.unwrap_or(self.feed),
            span: Span::default(),
        });
        self.block.commands.push(Command::Move(mv));
        ctrl.run_block(&self.block, out)?;
        Ok(flow)
    }

    /// Carries out the path held back, then its cycle call.
    fn run_held(
        &mut self,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let Some(held) = self.held.take() else {
            return Ok(Flow::Next);
        };
        let flow = ctrl.run_block(&self.held_block, out)?;
        if held.call {
            let line = held.line;
            let ex = Executed {
                line,
                ..Executed::default()
            };
            self.call_cycle(&ex, ctrl, out, false)?;
        }
        Ok(flow)
    }

    /// Carries out what is held back: at every block that is no path, and
    /// at the end of the program. A rounding or chamfer with no path after
    /// it is an alarm.
    pub(crate) fn finish(
        &mut self,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        if let Some(corner) = self.corner.take() {
            self.held = None;
            return Err(alarm(
                corner.line,
                Condition::CrcNoIntersection,
                None,
                format!(
                    "{} needs a contour element (L, C, CR, CT, LP, CP) after it",
                    if corner.chamfer { "CHF" } else { "RND" }
                ),
            ));
        }
        self.run_held(ctrl, out)
    }

    /// The held path ends at `t1` (in the plane) instead of its corner:
    /// its plane targets become `t1`, the tool axis' in proportion.
    fn trim_held(&mut self, prev: &Held, t1: [f64; 2]) {
        let [a, b, n] = self.axes();
        let fraction = match prev.shape {
            Shape::Line => {
                let full = (prev.end[a] - prev.start[a]).hypot(prev.end[b] - prev.start[b]);
                (t1[0] - prev.start[a]).hypot(t1[1] - prev.start[b]) / full
            }
            Shape::Arc { centre, ccw } => {
                let sweep = |p: [f64; 2]| {
                    let a0 = angle_of([prev.start[a] - centre[0], prev.start[b] - centre[1]]);
                    let a1 = angle_of([p[0] - centre[0], p[1] - centre[1]]);
                    let d = if ccw { a1 - a0 } else { a0 - a1 };
                    d.rem_euclid(360.0)
                };
                let full = sweep([prev.end[a], prev.end[b]]);
                if full > 0.0 { sweep(t1) / full } else { 1.0 }
            }
            Shape::Other => 1.0,
        };
        let z = prev.start[n] + fraction * (prev.end[n] - prev.start[n]);
        for command in &mut self.held_block.commands {
            if let Command::Move(mv) = command {
                for (k, i) in [a, b].into_iter().enumerate() {
                    mv.targets[i] = Some(Target {
                        value: t1[k],
                        mode: TargetMode::Absolute,
                        span: mv.targets[i].map_or(Span::default(), |t| t.span),
                    });
                }
                if let Some(t) = mv.targets[n].as_mut() {
                    t.value = z;
                    t.mode = TargetMode::Absolute;
                }
            }
        }
    }

    /// Where a rounding or chamfer meets the path before (`t1`) and the
    /// path after (`t2`), and the rounding's centre and sense.
    fn join(&self, prev: &Held, next: &Held, corner: &Corner) -> Result<Joint, Alarm> {
        let [a, b, _] = self.axes();
        let c = [prev.end[a], prev.end[b]];
        let fail = |what: &str| {
            alarm(
                corner.line,
                Condition::CrcNoIntersection,
                None,
                format!(
                    "{} {}: {what}",
                    if corner.chamfer { "CHF" } else { "RND R" },
                    corner.size
                ),
            )
        };
        let t1 = direction_at(prev.shape, [prev.start[a], prev.start[b]], c, true);
        let t2 = direction_at(next.shape, c, [next.end[a], next.end[b]], false);
        let turn = t1[0] * t2[1] - t1[1] * t2[0];
        if turn.abs() < 1e-9 {
            return Err(fail("the paths meet without a corner"));
        }
        if corner.chamfer {
            if prev.shape != Shape::Line || next.shape != Shape::Line {
                return Err(fail("a chamfer joins two straight lines only"));
            }
            let len1 = (c[0] - prev.start[a]).hypot(c[1] - prev.start[b]);
            let len2 = (next.end[a] - c[0]).hypot(next.end[b] - c[1]);
            if corner.size > len1 + GEOMETRY_TOLERANCE || corner.size > len2 + GEOMETRY_TOLERANCE {
                return Err(fail("the chamfer is longer than a line it cuts"));
            }
            return Ok(Joint {
                t1: [c[0] - corner.size * t1[0], c[1] - corner.size * t1[1]],
                t2: [c[0] + corner.size * t2[0], c[1] + corner.size * t2[1]],
                centre: None,
            });
        }
        // The rounding's centre: on both paths' offsets by the radius to
        // the inside of the corner, the crossing nearest the corner.
        let side = if turn > 0.0 { 1.0 } else { -1.0 };
        let r = corner.size;
        let offset1 = offset_curve(prev.shape, [prev.start[a], prev.start[b]], c, side * r);
        let offset2 = offset_curve(next.shape, c, [next.end[a], next.end[b]], side * r);
        let f = crossing_nearest(offset1, offset2, c)
            .ok_or_else(|| fail("no circle of that radius touches both paths"))?;
        let p1 = foot(prev.shape, [prev.start[a], prev.start[b]], c, f);
        let p2 = foot(next.shape, c, [next.end[a], next.end[b]], f);
        if !within(prev.shape, [prev.start[a], prev.start[b]], c, p1)
            || !within(next.shape, c, [next.end[a], next.end[b]], p2)
        {
            return Err(fail("the rounding is larger than the paths it joins"));
        }
        Ok(Joint {
            t1: p1,
            t2: p2,
            centre: Some((f, turn > 0.0)),
        })
    }

    /// Tool centre point control on (how the orientation is given) or
    /// off, for the block being built.
    fn set_tcp(&mut self, mode: Option<TcpcType>, span: Span) {
        self.tcp = mode;
        self.block.commands.push(Command::Tcp { mode, span });
    }

    /// The plane's axes: first, second, tool axis.
    fn axes(&self) -> [usize; 3] {
        self.plane.axes()
    }

    /// A block of M functions (and the words M128's `F` gives).
    fn plain(
        &mut self,
        ex: &Executed,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        if let Some(w) = ex
            .words
            .iter()
            .find(|w| w.address != "F" && w.address != "MB")
        {
            return Err(alarm(
                ex.line,
                Condition::ImproperAddress,
                Some(w.span),
                format!("{} has no meaning in a block without a path", w.address),
            ));
        }
        let flow = self.m_only(ex, ctrl, out)?;
        if ex.kind == Kind::Stop {
            self.block.clear(ex.line);
            self.block.commands.push(Command::MFunction {
                number: 0,
                span: Span::default(),
            });
            ctrl.run_block(&self.block, out)?;
        }
        Ok(flow)
    }

    /// The block's commands so far, its M functions, then the cycle call
    /// of `M99` / `M89`.
    fn m_only(
        &mut self,
        ex: &Executed,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let call = self.m_functions(ex, ctrl)?;
        let flow = ctrl.run_block(&self.block, out)?;
        if call {
            self.call_cycle(ex, ctrl, out, false)?;
        }
        self.retract_after(ex, ctrl, out)?;
        Ok(flow)
    }

    /// `M140 MB d` / `M140 MB MAX`: after the block, the tool retracts
    /// along its axis by `d`, or to the end of the travel (TNC 640
    /// manual, "Retraction in the tool axis: M140").
    fn retract_after(
        &mut self,
        ex: &Executed,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        if !ex.m.iter().any(|&(m, _)| m == 140) {
            return Ok(());
        }
        let distance = if ex.has_key("MB MAX") {
            None
        } else {
            let mb = ex.word("MB").ok_or_else(|| {
                alarm(
                    ex.line,
                    Condition::NoDataAfterAddress,
                    None,
                    "M140 needs MB, the retract distance, or MB MAX".into(),
                )
            })?;
            Some(self.length(mb.value))
        };
        self.retract(ctrl, ex.line, distance, out)
    }

    /// The block's M functions: the TNC's own (M91/M92 machine
    /// coordinates, M126/M127, M128/M129, M89/M99 cycle calls, M116/M117,
    /// M110–M112 feed on arcs, M140 is refused) become the front end's
    /// state; the others (M0–M9, M13/M14, M30, builder functions) go to
    /// the controller as M functions, for the machine file to give them
    /// meaning. Returns whether the block calls the cycle.
    fn m_functions(&mut self, ex: &Executed, ctrl: &Controller<'_>) -> Result<bool, Alarm> {
        let mut call = self.modal_call;
        for &(m, span) in &ex.m {
            match m {
                // Machine-referenced coordinates: per block, read by the
                // path (`line`).
                91 | 92 => {}
                126 => self.shortest = true,
                127 => self.shortest = false,
                128 => {
                    if let Some(w) = ex.word("F") {
                        self.notes.push(format!(
                            "line {}: M128 F{} (the compensating moves' feed) read; the kernel moves them at the block's feed",
                            ex.line, w.value
                        ));
                    }
                    if self.tcp.is_none() {
                        self.set_tcp(Some(TcpcType::Angles), span);
                    }
                }
                129 => self.set_tcp(None, span),
                // M140 MB: a retract along the tool axis after the block
                // (`retract_after`).
                140 => {}
                99 => call = true,
                89 => {
                    self.modal_call = true;
                    call = true;
                }
                // Feed at arcs (M109 / M110 / M111), feed on rotary axes
                // (M116 / M117), look-ahead (M120), rotary display
                // (M94): the feed or the display, not the path.
                94 | 109..=111 | 116 | 117 | 120 => {}
                13 | 14 => {
                    // Spindle and coolant on together.
                    for number in [if m == 13 { 3 } else { 4 }, 8] {
                        self.block
                            .commands
                            .push(Command::MFunction { number, span });
                    }
                }
                _ => {
                    let number = u16::try_from(m).map_err(|_| {
                        alarm(
                            ex.line,
                            Condition::UnsupportedMCode,
                            Some(span),
                            format!("M{m} is not an M function"),
                        )
                    })?;
                    if matches!(m, 2 | 30) {
                        self.modal_call = false;
                    }
                    let _ = ctrl;
                    self.block
                        .commands
                        .push(Command::MFunction { number, span });
                }
            }
        }
        Ok(call)
    }

    /// `L` and `LN`: a straight line, with the tool orientation under TCPM.
    fn line(
        &mut self,
        ex: &Executed,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let machine = ctrl.machine();
        let line = ex.line;
        let start = self.start(ctrl);
        let mut mv = Move::default();
        let machine_coords = ex.m.iter().any(|&(m, _)| m == 91 || m == 92);
        let mut normal = [None; 3];
        let mut vector = [None; 3];
        for w in &ex.words {
            match w.address.as_str() {
                "F" | "R" | "MB" => {}
                "NX" | "NY" | "NZ" if ex.kind == Kind::LineNormal => {
                    normal[usize::from(w.address.as_bytes()[1] - b'X')] = Some(w.value);
                }
                "TX" | "TY" | "TZ" if ex.kind == Kind::LineNormal => {
                    vector[usize::from(w.address.as_bytes()[1] - b'X')] = Some(w.value);
                }
                address => {
                    let Some(i) = axis_index(machine, address) else {
                        return Err(alarm(
                            line,
                            Condition::ImproperAddress,
                            Some(w.span),
                            format!("{address} is not an axis of this machine"),
                        ));
                    };
                    let rotary = i >= machine.linear.len();
                    let value = if rotary {
                        w.value
                    } else {
                        self.length(w.value)
                    };
                    let mode = if w.incremental {
                        TargetMode::Incremental
                    } else if rotary && self.shortest && machine_coords_rollover(machine, i) {
                        TargetMode::Shortest
                    } else {
                        TargetMode::Absolute
                    };
                    mv.targets[i] = Some(Target {
                        value,
                        mode,
                        span: w.span,
                    });
                }
            }
        }
        if let Some(r) = ex.word("R") {
            return Err(alarm(
                line,
                Condition::ImproperAddress,
                Some(r.span),
                "R with a value belongs to CR (the radius) or RND; L takes R0, RL or RR".into(),
            ));
        }
        self.feed_and_comp(ex, ctrl)?;
        if machine_coords {
            if ex.has_key("RL") || ex.has_key("RR") {
                return Err(alarm(
                    line,
                    Condition::ImproperAddress,
                    None,
                    "M91 / M92: a move in machine coordinates takes no radius compensation".into(),
                ));
            }
            // M91: the coordinates are the machine's own (measured from
            // the machine datum); M92 measures them from the machine
            // builder's fixed position, the machine file's reference
            // position 1 here (the kernel's reading). Neither takes the
            // tool length: M91 Z0 is the spindle at the top of travel on
            // the usual layout (the kernel's reading, unverified).
            if ex.m.iter().any(|&(m, _)| m == 92) {
                let reference = machine.params.reference_1;
                for (t, r) in mv.targets.iter_mut().zip(reference) {
                    if let Some(t) = t.as_mut()
                        && t.mode != TargetMode::Incremental
                    {
                        t.value += r;
                    }
                }
            }
            mv.suppress = Suppress::Axes;
        }
        if ex.kind == Kind::LineNormal {
            self.line_normal(ex, ctrl, (&start, normal, vector), &mut mv)?;
        }
        let linear = machine.linear.len();
        if self.tcp.is_none()
            && !machine_coords
            && mv.targets[linear..].iter().any(Option::is_some)
            && mv.targets[..linear].iter().all(Option::is_none)
        {
            // Rotary axes alone without TCPM: only they move, the linear
            // axes stay where they stand (the tool tip moves with the
            // table or head, as on the TNC after PLANE … STAY).
            for (i, t) in mv.targets.iter_mut().enumerate().skip(linear) {
                if let Some(t) = t.as_mut()
                    && t.mode != TargetMode::Incremental
                {
                    t.value += self.shift[i];
                }
            }
            mv.suppress = Suppress::Axes;
        }
        mv.span = ex.words.first().map_or(Span::default(), |w| w.span);
        let moves = mv.targets.iter().any(Option::is_some);
        let call = self.m_functions(ex, ctrl)?;
        let mut shape = Shape::Other;
        let mut end = start;
        if moves && mv.suppress == Suppress::Nothing {
            // The contour element, in program coordinates: increments
            // written out from where the element starts (a rounding may
            // move that start).
            for (i, t) in mv.targets.iter_mut().enumerate().take(machine.linear.len()) {
                if let Some(t) = t.as_mut() {
                    if t.mode == TargetMode::Incremental {
                        t.value += start[i];
                        t.mode = TargetMode::Absolute;
                    }
                    end[i] = t.value;
                }
            }
            let [a, b, _] = self.axes();
            let d = [end[a] - start[a], end[b] - start[b]];
            if d[0].hypot(d[1]) > GEOMETRY_TOLERANCE {
                self.tangent = Some(d);
                shape = Shape::Line;
            }
        }
        if moves {
            self.block.commands.push(Command::Move(mv));
        }
        let flow = self.hold(
            ctrl,
            out,
            Held {
                line,
                start,
                end,
                shape,
                call,
            },
        )?;
        if ex.m.iter().any(|&(m, _)| m == 140) {
            let end = self.finish(ctrl, out)?;
            self.retract_after(ex, ctrl, out)?;
            if flow == Flow::Next {
                return Ok(end);
            }
        }
        Ok(flow)
    }

    /// `LN`'s vectors. Under TCPM the tool vector `TX TY TZ` is the tool's
    /// orientation (as FANUC's G43.5 I J K). The surface normal `NX NY NZ`
    /// gives 3-D radius compensation: the TNC moves the tool off the
    /// programmed point along the normal by the delta radius, the tool
    /// table's (the offsets file's `radius_wear`) plus `TOOL CALL … DR`
    /// (iTNC 530 manual, "Three-dimensional tool compensation"; the
    /// programmed point already holds the tool's nominal radius, as the
    /// CAM system computes it).
    fn line_normal(
        &mut self,
        ex: &Executed,
        ctrl: &Controller<'_>,
        (start, normal, vector): (&Joints, [Option<f64>; 3], [Option<f64>; 3]),
        mv: &mut Move,
    ) -> Result<(), Alarm> {
        let line = ex.line;
        if normal.iter().any(Option::is_some) {
            let n = Vec3::from(normal.map(|c| c.unwrap_or(0.0)));
            let Some(n) = n.try_normalize(GEOMETRY_TOLERANCE) else {
                return Err(alarm(
                    line,
                    Condition::ToolVectorZero,
                    None,
                    "the surface normal NX NY NZ is zero".into(),
                ));
            };
            let delta = ctrl.offsets().tool(self.tool).radius_wear + self.delta_radius;
            if delta != 0.0 {
                for k in 0..3 {
                    let t = mv.targets[k].get_or_insert(Target {
                        value: start[k],
                        mode: TargetMode::Absolute,
                        span: Span::default(),
                    });
                    t.value += delta * n[k];
                }
            }
        }
        if vector.iter().any(Option::is_some) {
            if self.tcp.is_none() {
                return Err(alarm(
                    line,
                    Condition::TcpcOptionMissing,
                    None,
                    "LN with a tool vector TX TY TZ needs M128 or FUNCTION TCPM".into(),
                ));
            }
            let v = vector.map(|c| c.unwrap_or(0.0));
            if v.iter().all(|c| *c == 0.0) {
                return Err(alarm(
                    line,
                    Condition::ToolVectorZero,
                    None,
                    "the tool vector TX TY TZ is zero".into(),
                ));
            }
            if self.tcp != Some(TcpcType::Vector) {
                self.set_tcp(Some(TcpcType::Vector), Span::default());
            }
            mv.tool_vector = Some(v);
        } else if self.tcp == Some(TcpcType::Vector) {
            self.set_tcp(Some(TcpcType::Angles), Span::default());
        }
        Ok(())
    }

    /// `F`, `FMAX`, `F AUTO` and `R0` / `RL` / `RR` of a path block.
    fn feed_and_comp(&mut self, ex: &Executed, ctrl: &Controller<'_>) -> Result<(), Alarm> {
        let rapid = ex.has_key("FMAX");
        if let Some(f) = ex.word("F") {
            if f.value < 0.0 || !f.value.is_finite() {
                return Err(alarm(
                    ex.line,
                    Condition::ValueOutOfRange,
                    Some(f.span),
                    format!("feed F{} must be a positive number", f.value),
                ));
            }
            self.feed = self.length(f.value);
        } else if ex.has_key("FAUTO") {
            self.feed = self.tool_feed;
        }
        let side = if ex.has_key("RL") {
            Some(CutterSide::Left)
        } else if ex.has_key("RR") {
            Some(CutterSide::Right)
        } else if ex.has_key("R0") {
            Some(CutterSide::Off)
        } else {
            None
        };
        if let Some(side) = side
            && side != self.comp
        {
            self.comp = side;
            self.block.commands.push(Command::Radius {
                side,
                span: Span::default(),
            });
        }
        let _ = ctrl;
        self.block.commands.push(Command::Interpolation(if rapid {
            MotionMode::Rapid
        } else {
            MotionMode::Linear
        }));
        if !rapid {
            self.block.commands.push(Command::Feed {
                value: self.feed,
                span: ex.word("F").map_or(Span::default(), |w| w.span),
            });
        }
        Ok(())
    }

    /// `CC`: the pole, absolute or incremental from the last programmed
    /// position; without coordinates the last programmed position.
    fn centre(&mut self, ex: &Executed, ctrl: &Controller<'_>) -> Result<(), Alarm> {
        let [a, b, _] = self.axes();
        let p = self.start(ctrl);
        let mut pole = [p[a], p[b]];
        for w in &ex.words {
            let k = plane_slot(ctrl, &w.address, a, b).ok_or_else(|| {
                alarm(
                    ex.line,
                    Condition::ImproperAddress,
                    Some(w.span),
                    format!("CC takes the working plane's two axes, not {}", w.address),
                )
            })?;
            let v = self.length(w.value);
            pole[k] = if w.incremental { pole[k] + v } else { v };
        }
        self.pole = Some(pole);
        Ok(())
    }

    /// `C` (about the pole), `CR` (by radius), `CT` (tangential).
    fn circle(
        &mut self,
        ex: &Executed,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let line = ex.line;
        let machine = ctrl.machine();
        let [a, b, n] = self.axes();
        let start = self.start(ctrl);
        let mut mv = Move::default();
        let mut end = [start[a], start[b]];
        for w in &ex.words {
            if matches!(w.address.as_str(), "F" | "R") {
                continue;
            }
            let Some(i) = axis_index(machine, &w.address) else {
                return Err(alarm(
                    line,
                    Condition::ImproperAddress,
                    Some(w.span),
                    format!("{} is not an axis of this machine", w.address),
                ));
            };
            let v = if i < machine.linear.len() {
                self.length(w.value)
            } else {
                w.value
            };
            let value = if w.incremental { start[i] + v } else { v };
            if i == a {
                end[0] = value;
            } else if i == b {
                end[1] = value;
            }
            mv.targets[i] = Some(Target {
                value,
                mode: TargetMode::Absolute,
                span: w.span,
            });
        }
        mv.span = ex.words.first().map_or(Span::default(), |w| w.span);
        self.feed_and_comp(ex, ctrl)?;
        // The circle's own interpolation replaces the line's.
        self.block
            .commands
            .retain(|c| !matches!(c, Command::Interpolation(_)));
        let s = [start[a], start[b]];
        let (ccw, centre) = match ex.kind {
            Kind::CircleTangent => {
                let Some(t) = self.tangent else {
                    return Err(alarm(
                        line,
                        Condition::ArcCenterMissing,
                        None,
                        "CT needs a path before it to be tangential to".into(),
                    ));
                };
                let c = tangent_centre(s, end, t).ok_or_else(|| {
                    alarm(
                        line,
                        Condition::ArcRadiusTolerance,
                        None,
                        "CT: the end point lies on the tangent, no circle joins it".into(),
                    )
                })?;
                let cross = t[0] * (c[1] - s[1]) - t[1] * (c[0] - s[0]);
                (cross > 0.0, c)
            }
            Kind::CircleRadius => {
                let r = ex.word("R").ok_or_else(|| {
                    alarm(
                        line,
                        Condition::NoDataAfterAddress,
                        None,
                        "CR needs the radius R".into(),
                    )
                })?;
                let ccw = self.direction(ex)?;
                let radius = self.length(r.value);
                // R > 0: the shorter arc, R < 0: the longer (more than
                // 180°).
                let c = crate::sinumerik::radius_center(s, end, radius, ccw).ok_or_else(|| {
                    alarm(
                        line,
                        Condition::ArcRadiusTolerance,
                        Some(r.span),
                        format!("CR: radius {radius} is too small for the chord to the end point"),
                    )
                })?;
                (ccw, c)
            }
            _ => {
                let Some(pole) = self.pole else {
                    return Err(alarm(
                        line,
                        Condition::ArcCenterMissing,
                        None,
                        "C needs the circle centre CC".into(),
                    ));
                };
                let r0 = (s[0] - pole[0]).hypot(s[1] - pole[1]);
                let r1 = (end[0] - pole[0]).hypot(end[1] - pole[1]);
                if (r0 - r1).abs() > CIRCLE_TOLERANCE {
                    return Err(alarm(
                        line,
                        Condition::ArcRadiusTolerance,
                        None,
                        format!(
                            "C: the end point lies {r1:.4} mm from the pole, the start {r0:.4} mm"
                        ),
                    ));
                }
                (self.direction(ex)?, pole)
            }
        };
        self.set_centre(&mut mv, [a, b], centre);
        let _ = n;
        self.block.commands.push(Command::Interpolation(if ccw {
            MotionMode::Ccw
        } else {
            MotionMode::Cw
        }));
        let call = self.m_functions(ex, ctrl)?;
        let mut end_joints = start;
        for (i, t) in mv.targets.iter().enumerate() {
            if let Some(t) = t {
                end_joints[i] = t.value;
            }
        }
        self.block.commands.push(Command::Move(mv));
        self.tangent_after_arc(&end_joints, centre, ccw);
        self.hold(
            ctrl,
            out,
            Held {
                line,
                start,
                end: end_joints,
                shape: Shape::Arc { centre, ccw },
                call,
            },
        )
    }

    /// The circle's centre as absolute program coordinates of the plane.
    fn set_centre(&self, mv: &mut Move, [a, b]: [usize; 2], c: [f64; 2]) {
        let slot = |i: usize| match (i, self.plane) {
            (0, _) => 0,
            (1, _) => 1,
            _ => 2,
        };
        mv.center[slot(a)] = Some(c[0]);
        mv.center[slot(b)] = Some(c[1]);
        mv.center_absolute = true;
    }

    /// `DR+` counter-clockwise, `DR-` clockwise.
    fn direction(&self, ex: &Executed) -> Result<bool, Alarm> {
        if ex.has_key("DR+") {
            Ok(true)
        } else if ex.has_key("DR-") {
            Ok(false)
        } else {
            Err(alarm(
                ex.line,
                Condition::NoDataAfterAddress,
                None,
                "a circle needs its direction DR+ or DR-".into(),
            ))
        }
    }

    /// The path's direction at the end of an arc about the pole or centre
    /// just carried out.
    fn tangent_after_arc(&mut self, e: &Joints, c: [f64; 2], ccw: bool) {
        let [a, b, _] = self.axes();
        let r = [e[a] - c[0], e[b] - c[1]];
        self.tangent = Some(if ccw { [-r[1], r[0]] } else { [r[1], -r[0]] });
    }

    /// `LP`, `CP`, `CTP`: paths in polar coordinates about the pole.
    fn polar(
        &mut self,
        ex: &Executed,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let line = ex.line;
        let machine = ctrl.machine();
        let [a, b, n] = self.axes();
        let Some(pole) = self.pole else {
            return Err(alarm(
                line,
                Condition::ArcCenterMissing,
                None,
                "polar coordinates need the pole CC".into(),
            ));
        };
        let start = self.start(ctrl);
        let s = [start[a] - pole[0], start[b] - pole[1]];
        let (mut pr, mut pa) = (s[0].hypot(s[1]), angle_of(s));
        let mut sweep = None;
        let mut mv = Move::default();
        for w in &ex.words {
            match w.address.as_str() {
                "F" => {}
                "PR" => {
                    let v = self.length(w.value);
                    pr = if w.incremental { pr + v } else { v };
                }
                "PA" => {
                    if w.incremental {
                        sweep = Some(w.value);
                        pa += w.value;
                    } else {
                        pa = w.value;
                    }
                }
                address => {
                    let i = axis_index(machine, address)
                        .filter(|&i| i != a && i != b)
                        .ok_or_else(|| {
                            alarm(
                                line,
                                Condition::ImproperAddress,
                                Some(w.span),
                                format!(
                                    "{address}: a polar path takes PR, PA and the axes off the working plane"
                                ),
                            )
                        })?;
                    let v = if i < machine.linear.len() {
                        self.length(w.value)
                    } else {
                        w.value
                    };
                    mv.targets[i] = Some(Target {
                        value: if w.incremental { start[i] + v } else { v },
                        mode: TargetMode::Absolute,
                        span: w.span,
                    });
                }
            }
        }
        let (sin, cos) = pa.to_radians().sin_cos();
        let e = [pole[0] + pr * cos, pole[1] + pr * sin];
        for (k, i) in [a, b].into_iter().enumerate() {
            mv.targets[i] = Some(Target {
                value: e[k],
                mode: TargetMode::Absolute,
                span: Span::default(),
            });
        }
        mv.span = ex.words.first().map_or(Span::default(), |w| w.span);
        self.feed_and_comp(ex, ctrl)?;
        let mut shape = Shape::Line;
        if ex.kind == Kind::CircleTangentPolar {
            // CTP: tangential to the path before, to the polar point.
            self.block
                .commands
                .retain(|c| !matches!(c, Command::Interpolation(_)));
            let Some(t) = self.tangent else {
                return Err(alarm(
                    line,
                    Condition::ArcCenterMissing,
                    None,
                    "CTP needs a path before it to be tangential to".into(),
                ));
            };
            let s0 = [start[a], start[b]];
            let c = tangent_centre(s0, e, t).ok_or_else(|| {
                alarm(
                    line,
                    Condition::ArcRadiusTolerance,
                    None,
                    "CTP: the end point lies on the tangent, no circle joins it".into(),
                )
            })?;
            let ccw = t[0] * (c[1] - s0[1]) - t[1] * (c[0] - s0[0]) > 0.0;
            self.set_centre(&mut mv, [a, b], c);
            self.block.commands.push(Command::Interpolation(if ccw {
                MotionMode::Ccw
            } else {
                MotionMode::Cw
            }));
            shape = Shape::Arc { centre: c, ccw };
        } else if ex.kind == Kind::CirclePolar {
            self.block
                .commands
                .retain(|c| !matches!(c, Command::Interpolation(_)));
            let ccw = self.direction(ex)?;
            if let Some(sweep) = sweep {
                if (sweep > 0.0) != ccw {
                    return Err(alarm(
                        line,
                        Condition::ArcRadiusTolerance,
                        None,
                        format!(
                            "CP: IPA{sweep} turns against the direction DR{}",
                            if ccw { "+" } else { "-" }
                        ),
                    ));
                }
                // A helix's full turns beyond the last part turn.
                let turns = (sweep.abs() / 360.0 - GEOMETRY_TOLERANCE).floor();
                if turns >= 1.0 {
                    mv.turns = Some(turns as u32);
                }
            }
            self.set_centre(&mut mv, [a, b], pole);
            self.block.commands.push(Command::Interpolation(if ccw {
                MotionMode::Ccw
            } else {
                MotionMode::Cw
            }));
            shape = Shape::Arc { centre: pole, ccw };
        }
        let _ = n;
        let call = self.m_functions(ex, ctrl)?;
        let mut end_joints = start;
        for (i, t) in mv.targets.iter().enumerate() {
            if let Some(t) = t {
                end_joints[i] = t.value;
            }
        }
        self.block.commands.push(Command::Move(mv));
        match shape {
            Shape::Arc { centre, ccw } => self.tangent_after_arc(&end_joints, centre, ccw),
            _ => {
                let d = [e[0] - start[a], e[1] - start[b]];
                if d[0].hypot(d[1]) > GEOMETRY_TOLERANCE {
                    self.tangent = Some(d);
                } else {
                    shape = Shape::Other;
                }
            }
        }
        self.hold(
            ctrl,
            out,
            Held {
                line,
                start,
                end: end_joints,
                shape,
                call,
            },
        )
    }

    /// `TOOL CALL n | "name" Z S F DL DR`: the tool's length in force from
    /// the call (the TNC has no separate offset selection), the spindle
    /// axis choosing the working plane, the speed, the `F AUTO` feed and
    /// the deltas.
    fn tool_call(
        &mut self,
        ex: &Executed,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let line = ex.line;
        let number = match &ex.tool {
            Some(Tool::Number(n)) => Some(*n),
            Some(Tool::Name(name)) => Some(self.named_tool(ctrl, line, name)?),
            None => None,
        };
        if let Some(axis) = ex.name.as_deref() {
            self.plane = match axis {
                "Z" => Plane::Xy,
                "Y" => Plane::Zx,
                "X" => Plane::Yz,
                other => {
                    return Err(alarm(
                        line,
                        Condition::ImproperAddress,
                        None,
                        format!("TOOL CALL: the spindle axis {other} is not X, Y or Z"),
                    ));
                }
            };
            self.block.commands.push(Command::Plane(self.plane));
        }
        if let Some(n) = number {
            let span = Span::default();
            self.block
                .commands
                .push(Command::ToolSelect { tool: n, span });
            // The tool goes into the spindle (the TNC's tool change).
            self.block
                .commands
                .push(Command::MFunction { number: 6, span });
            self.block
                .commands
                .push(Command::ToolOffset { number: n, span });
        }
        let mut delta = [0.0; 2];
        for w in &ex.words {
            match w.address.as_str() {
                "S" => {
                    if w.value < 0.0 || !w.value.is_finite() {
                        return Err(alarm(
                            line,
                            Condition::ValueOutOfRange,
                            Some(w.span),
                            format!("TOOL CALL: spindle speed S{} must not be negative", w.value),
                        ));
                    }
                    self.block.commands.push(Command::SpindleSpeed(w.value));
                }
                "F" => {
                    if w.value < 0.0 || !w.value.is_finite() {
                        return Err(alarm(
                            line,
                            Condition::ValueOutOfRange,
                            Some(w.span),
                            format!("TOOL CALL: feed F{} must not be negative", w.value),
                        ));
                    }
                    self.tool_feed = self.length(w.value);
                }
                "DL" => delta[0] = self.length(w.value),
                "DR" => delta[1] = self.length(w.value),
                "DR2" => {}
                other => {
                    return Err(alarm(
                        line,
                        Condition::ImproperAddress,
                        Some(w.span),
                        format!("TOOL CALL takes S, F, DL, DR and DR2, not {other}"),
                    ));
                }
            }
        }
        if let Some(n) = number {
            self.tool = n;
            self.delta_length = delta[0];
            self.delta_radius = delta[1];
            self.block.commands.push(Command::ToolDelta {
                length: delta[0],
                radius: delta[1],
            });
        }
        self.m_only(ex, ctrl, out)
    }

    /// A tool called by name: the offsets file's number for it, or (with
    /// no tools in the file) a number of its own.
    fn named_tool(&mut self, ctrl: &Controller<'_>, line: u32, name: &str) -> Result<u32, Alarm> {
        let offsets = ctrl.offsets();
        if let Some(n) = offsets.tool_number(name) {
            return Ok(n);
        }
        if !offsets.tools.is_empty() && !offsets.any_name {
            return Err(alarm(
                line,
                Condition::IllegalOffsetNumber,
                None,
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

    /// `BLK FORM 0.1 Z X Y Z` / `0.2 X Y Z`: the stock's corners.
    fn block_form(&mut self, ex: &Executed) -> Result<(), Alarm> {
        let mut p = [0.0; 3];
        for w in &ex.words {
            let k = match w.address.as_str() {
                "X" => 0,
                "Y" => 1,
                "Z" => 2,
                other => {
                    return Err(alarm(
                        ex.line,
                        Condition::ImproperAddress,
                        Some(w.span),
                        format!("BLK FORM takes X, Y and Z, not {other}"),
                    ));
                }
            };
            p[k] = self.length(w.value);
        }
        match ex.number {
            Some(x) if (x - 0.1).abs() < 1e-6 => self.stock_min = Some(p),
            Some(x) if (x - 0.2).abs() < 1e-6 => {
                let Some(min) = self.stock_min else {
                    return Err(alarm(
                        ex.line,
                        Condition::CycleDataMissing,
                        None,
                        "BLK FORM 0.2 needs BLK FORM 0.1 before it".into(),
                    ));
                };
                let mut max = p;
                for (k, w) in ex.words.iter().enumerate() {
                    if w.incremental {
                        max[k] = min[k] + p[k];
                    }
                }
                self.stock = Some(Stock { min, max });
            }
            _ => {
                return Err(alarm(
                    ex.line,
                    Condition::ImproperAddress,
                    None,
                    "BLK FORM is 0.1 (minimum point) or 0.2 (maximum point); the kernel reads the box"
                        .into(),
                ));
            }
        }
        Ok(())
    }

    /// `CYCL DEF n.m`: coordinate transformations take effect at once,
    /// machining cycles are remembered for their call.
    fn cycle_def(
        &mut self,
        ex: &Executed,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let line = ex.line;
        let number = ex.number.unwrap_or(0.0);
        let major = number.trunc() as u32;
        let minor = ((number - number.trunc()) * 10.0).round() as u32;
        match (major, minor) {
            (7, 0) | (8, 0) | (10, 0) | (11, 0) | (26, 0) | (19, 0) | (32, 0) => {}
            (7, _) => {
                let machine = ctrl.machine();
                for w in &ex.words {
                    let i = axis_index(machine, &w.address).ok_or_else(|| {
                        alarm(
                            line,
                            Condition::ImproperAddress,
                            Some(w.span),
                            format!("DATUM SHIFT: {} is not an axis of this machine", w.address),
                        )
                    })?;
                    let v = if i < 3 { self.length(w.value) } else { w.value };
                    if self.tilt.is_some() && i < 3 {
                        let s = &mut self.inner_shift[i];
                        *s = if w.incremental { *s + v } else { v };
                    } else {
                        let s = &mut self.shift[i];
                        *s = if w.incremental { *s + v } else { v };
                    }
                }
                self.push_frames();
            }
            (8, _) => {
                // The axes named are mirrored; none named: mirror off.
                let mut mirror = [false; 3];
                for k in ex
                    .keys
                    .iter()
                    .map(|k| k.key.as_str())
                    .chain(ex.words.iter().map(|w| w.address.as_str()))
                {
                    match k {
                        "X" => mirror[0] = true,
                        "Y" => mirror[1] = true,
                        "Z" => mirror[2] = true,
                        _ => {}
                    }
                }
                self.mirror = mirror;
                self.push_frames();
            }
            (10, _) => {
                let rot = ex.word("ROT").ok_or_else(|| {
                    alarm(
                        line,
                        Condition::NoDataAfterAddress,
                        None,
                        "ROTATION needs ROT".into(),
                    )
                })?;
                self.rotation = if rot.incremental {
                    self.rotation + rot.value
                } else {
                    rot.value
                };
                self.push_frames();
            }
            (11, _) => {
                let scl = ex.word("SCL").ok_or_else(|| {
                    alarm(
                        line,
                        Condition::NoDataAfterAddress,
                        None,
                        "SCALING needs SCL".into(),
                    )
                })?;
                if scl.value.is_nan() || scl.value <= 0.0 {
                    return Err(alarm(
                        line,
                        Condition::ValueOutOfRange,
                        Some(scl.span),
                        format!("SCALING: factor {} must be greater than 0", scl.value),
                    ));
                }
                self.scale = [scl.value; 3];
                self.push_frames();
            }
            (26, _) => {
                let mut scale = [1.0; 3];
                for w in &ex.words {
                    let k = match w.address.as_str() {
                        "X" => 0,
                        "Y" => 1,
                        "Z" => 2,
                        _ => continue,
                    };
                    if w.value.is_nan() || w.value <= 0.0 {
                        return Err(alarm(
                            line,
                            Condition::ValueOutOfRange,
                            Some(w.span),
                            format!(
                                "AXIS-SPECIFIC SCALING: factor {} must be greater than 0",
                                w.value
                            ),
                        ));
                    }
                    scale[k] = w.value;
                }
                self.scale = scale;
                self.push_frames();
            }
            (19, _) => {
                // Cycle 19: the plane by the rotary axes' angles (as PLANE
                // AXIAL), no axis moves (the machine's setting for
                // positioning is the program's next L block here).
                let machine = ctrl.machine();
                let mut joints = ctrl.joints_now();
                let mut any = false;
                for w in &ex.words {
                    if w.address == "F" {
                        continue;
                    }
                    let i = axis_index(machine, &w.address)
                        .filter(|&i| i >= machine.linear.len())
                        .ok_or_else(|| {
                            alarm(
                                line,
                                Condition::ImproperAddress,
                                Some(w.span),
                                format!(
                                    "WORKING PLANE: {} is not a rotary axis of this machine",
                                    w.address
                                ),
                            )
                        })?;
                    joints[i] = w.value;
                    any |= w.value != 0.0;
                }
                self.tilt = any.then(|| ctrl.tool_rotation_at(&joints));
                if self.tilt.is_none() {
                    self.inner_shift = [0.0; 3];
                }
                self.push_frames();
            }
            (32, _) => {
                if let Some(t) = ex.word("T") {
                    let tolerance = self.length(t.value);
                    self.tolerance = (tolerance > 0.0).then_some(tolerance);
                    self.block.commands.push(Command::PathSmoothing {
                        on: tolerance > 0.0,
                        tolerance: (tolerance > 0.0).then_some(tolerance),
                    });
                } else if minor == 1 {
                    self.tolerance = None;
                    self.block.commands.push(Command::PathSmoothing {
                        on: false,
                        tolerance: None,
                    });
                }
            }
            (247, _) => {
                let n = ex.param(339).ok_or_else(|| {
                    alarm(
                        line,
                        Condition::CycleDataMissing,
                        None,
                        "DATUM SETTING needs Q339, the preset number".into(),
                    )
                })?;
                if !(0.0..=48.0).contains(&n) || n.fract() != 0.0 {
                    return Err(alarm(
                        line,
                        Condition::ValueOutOfRange,
                        None,
                        format!(
                            "DATUM SETTING: preset Q339={n} is not a row 0 to 48 of the preset table"
                        ),
                    ));
                }
                // Preset 0 is the offsets file's G54, preset n its
                // "G54.1 Pn" (docs/heidenhain.md).
                self.block.commands.push(Command::WorkOffset(if n == 0.0 {
                    crate::command::WorkOffset::Standard(1)
                } else {
                    crate::command::WorkOffset::Extended(n as u8)
                }));
            }
            (392, _) => {
                self.notes.push(format!(
                    "line {line}: CYCL DEF 392 (the machine's dynamics setting) read, not simulated"
                ));
            }
            (n, 0) if cycles::is_machining_cycle(n) => {
                self.cycle = Some((n, ex.params.clone()));
                self.modal_call = false;
            }
            _ => {
                return Err(alarm(
                    line,
                    Condition::CycleNotAllowed,
                    None,
                    format!("CYCL DEF {number} is not a cycle the kernel carries out"),
                ));
            }
        }
        let flow = self.m_only(ex, ctrl, out)?;
        if (major, minor) == (32, 0) {
            self.block.commands.clear();
        }
        Ok(flow)
    }

    /// The frames the transformations make: the datum shift outside the
    /// tilt and the tilt as the swivel frame, the shift inside the tilt,
    /// mirror, rotation and scale as the programmable frame.
    fn push_frames(&mut self) {
        let mut outer = Frame::rigid(
            Vec3::new(self.shift[0], self.shift[1], self.shift[2]),
            self.tilt.unwrap_or_else(Rotation3::identity),
        );
        for i in 3..MAX_AXES {
            outer.axis_shift[i] = self.shift[i];
        }
        let swivel = (!outer.is_identity() || self.tilt.is_some()).then_some(outer);
        self.block.commands.push(Command::SwivelFrame(swivel));
        let [_, _, n] = self.axes();
        let programmable = Frame {
            translation: Vec3::new(
                self.inner_shift[0],
                self.inner_shift[1],
                self.inner_shift[2],
            ),
            rotation: about(n, self.rotation),
            scale: self.scale,
            mirror: self.mirror,
            ..Frame::IDENTITY
        };
        self.block
            .commands
            .push(Command::ProgrammableFrame(programmable));
    }

    /// `PLANE …`: the tilted working plane, then `MOVE` / `TURN` / `STAY`.
    fn plane_function(
        &mut self,
        ex: &Executed,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let line = ex.line;
        let form = ex.name.as_deref().unwrap_or("");
        let w = |name: &str| ex.word(name).map_or(0.0, |w| w.value);
        let machine = ctrl.machine();
        let mut axial = None;
        let tilt = match form {
            "RESET" => None,
            "SPATIAL" => Some(about(2, w("SPC")) * about(1, w("SPB")) * about(0, w("SPA"))),
            "PROJECTED" => {
                let (p, m) = (w("PROPR").to_radians(), w("PROMIN").to_radians());
                let x = Vec3::new(p.cos(), 0.0, -p.sin());
                let y = Vec3::new(0.0, m.cos(), m.sin());
                let r = from_x_and_z(x, x.cross(&y)).ok_or_else(|| {
                    alarm(
                        line,
                        Condition::FeatureDefinition,
                        None,
                        "PLANE PROJECTED: the angles give no plane".into(),
                    )
                })?;
                let rot = ex
                    .word("ROT")
                    .or_else(|| ex.word("PROROT"))
                    .map_or(0.0, |w| w.value);
                Some(r * about(2, rot))
            }
            "EULER" => Some(about(2, w("EULPR")) * about(0, w("EULNU")) * about(2, w("EULROT"))),
            "VECTOR" => {
                let b = Vec3::new(w("BX"), w("BY"), w("BZ"));
                let n = Vec3::new(w("NX"), w("NY"), w("NZ"));
                Some(from_x_and_z(b, n).ok_or_else(|| {
                    alarm(
                        line,
                        Condition::FeatureDefinition,
                        None,
                        "PLANE VECTOR: the base vector and the normal vector must be non-zero and not parallel".into(),
                    )
                })?)
            }
            "POINTS" => {
                let p = |k: u8| {
                    Vec3::new(
                        w(&format!("P{k}X")),
                        w(&format!("P{k}Y")),
                        w(&format!("P{k}Z")),
                    )
                };
                let (p1, p2, p3) = (p(1), p(2), p(3));
                let x = p2 - p1;
                Some(from_x_and_z(x, x.cross(&(p3 - p1))).ok_or_else(|| {
                    alarm(
                        line,
                        Condition::FeatureDefinition,
                        None,
                        "PLANE POINTS: the three points lie on a line".into(),
                    )
                })?)
            }
            "RELATIV" => {
                let base = self.tilt.unwrap_or_else(Rotation3::identity);
                let turn = if let Some(v) = ex.word("SPA") {
                    about(0, v.value)
                } else if let Some(v) = ex.word("SPB") {
                    about(1, v.value)
                } else if let Some(v) = ex.word("SPC") {
                    about(2, v.value)
                } else {
                    return Err(alarm(
                        line,
                        Condition::FeatureDefinition,
                        None,
                        "PLANE RELATIV needs one angle SPA, SPB or SPC".into(),
                    ));
                };
                Some(base * turn)
            }
            "AXIAL" => {
                let mut joints = ctrl.joints_now();
                let mut angles = [None; 2];
                for word in &ex.words {
                    let Some(i) =
                        axis_index(machine, &word.address).filter(|&i| i >= machine.linear.len())
                    else {
                        continue;
                    };
                    joints[i] = word.value;
                    if let Some(k) =
                        (0..machine.rotary.len().min(2)).find(|&k| machine.rotary_index(k) == i)
                    {
                        angles[k] = Some(word.value);
                    }
                }
                axial = Some(angles);
                Some(ctrl.tool_rotation_at(&joints))
            }
            other => {
                return Err(alarm(
                    line,
                    Condition::FeatureDefinition,
                    None,
                    format!("PLANE {other} is not a form of PLANE"),
                ));
            }
        };
        self.tilt = tilt;
        if tilt.is_none() {
            self.inner_shift = [0.0; 3];
        }
        self.push_frames();
        let flow = self.m_only(ex, ctrl, out)?;
        let seq = if ex.has_key("SEQ+") {
            Some(true)
        } else if ex.has_key("SEQ-") {
            Some(false)
        } else {
            None
        };
        let positioning = ["MOVE", "TURN"].into_iter().find(|k| ex.has_key(k));
        if tilt.is_none() && positioning.is_none() {
            return Ok(flow);
        }
        // The axis positions that put the tool along the plane's Z (PLANE
        // RESET: the rotary axes' zero).
        let angles = match axial {
            _ if tilt.is_none() => [0.0; 2],
            Some(angles) => {
                let now = ctrl.joints_now();
                [0, 1].map(|k| {
                    angles[k].unwrap_or_else(|| {
                        machine
                            .rotary
                            .get(k)
                            .map_or(0.0, |_| now[machine.rotary_index(k)])
                    })
                })
            }
            None => self.table_rot(ex, ctrl, seq)?,
        };
        if ex.has_key("STAY") {
            let mut stay = [None; 3];
            for (k, angle) in angles.iter().enumerate().take(machine.rotary.len().min(2)) {
                let slot = match machine.rotary[k].name.to_ascii_uppercase() {
                    'A' => 0,
                    'B' => 1,
                    _ => 2,
                };
                stay[slot] = Some(*angle);
            }
            self.stay = Some(stay);
            return Ok(flow);
        }
        let Some(mode) = positioning else {
            return Err(alarm(
                line,
                Condition::FeatureDefinition,
                None,
                "PLANE needs MOVE, TURN or STAY".into(),
            ));
        };
        // MB: a retract along the tool axis first.
        if let Some(mb) = ex.word("MB") {
            self.retract(ctrl, line, Some(self.length(mb.value)), out)?;
        } else if ex.has_key("MB MAX") {
            self.retract(ctrl, line, None, out)?;
        }
        self.block.clear(line);
        self.positioning_feed(ex);
        let mut mv = Move::default();
        for (k, angle) in angles.iter().enumerate().take(machine.rotary.len().min(2)) {
            mv.targets[machine.rotary_index(k)] = Some(Target {
                value: *angle,
                mode: TargetMode::Absolute,
                span: Span::default(),
            });
        }
        let tcp_for_move = mode == "MOVE" && self.tcp.is_none();
        // MOVE DIST d: the turn is about the point d above the tool tip
        // along the tool (the TNC's centre of rotation), not the tip.
        let dist = ex
            .word("DIST")
            .filter(|_| mode == "MOVE")
            .map(|d| self.length(d.value))
            .filter(|d| *d != 0.0);
        let mut aside = CommandBlock::default();
        if tcp_for_move {
            // The tool tip stays on the workpiece: the linear axes follow as
            // under TCPC, switched on for the turn alone (in blocks of
            // their own: a block's move comes after its other commands).
            aside.clear(line);
            aside.commands.push(Command::Tcp {
                mode: Some(TcpcType::Angles),
                span: Span::default(),
            });
            ctrl.run_block(&aside, out)?;
        }
        if mode == "TURN" {
            // The rotary axes alone turn; the linear axes stay where they
            // stand (machine positions).
            mv.suppress = Suppress::Axes;
            for (i, t) in mv.targets.iter_mut().enumerate() {
                if let Some(t) = t.as_mut() {
                    t.value += self.shift[i];
                }
            }
        }
        if let Some(d) = dist {
            self.turn_about(ctrl, line, d, &angles, out)?;
        } else {
            self.block.commands.push(Command::Move(mv));
            ctrl.run_block(&self.block, out)?;
        }
        if tcp_for_move {
            aside.clear(line);
            aside.commands.push(Command::Tcp {
                mode: None,
                span: Span::default(),
            });
            ctrl.run_block(&aside, out)?;
        }
        Ok(flow)
    }

    /// `PLANE … MOVE DIST d` under TCPC: the rotary axes turn to `angles`
    /// while the point `d` above the tool tip along the tool stays where
    /// it is, in steps of at most [`DIST_STEP`] degrees of either axis;
    /// the tip's points are on the circle about that point, the tool's
    /// directions by forward kinematics. `self.block` holds the
    /// positioning feed.
    fn turn_about(
        &mut self,
        ctrl: &mut Controller<'_>,
        line: u32,
        d: f64,
        angles: &[f64; 2],
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let machine = ctrl.machine();
        let [_, _, n] = self.axes();
        // Program vectors to workpiece vectors: the plane, then the
        // rotation of cycle 10 inside it.
        let r = self.tilt.unwrap_or_else(Rotation3::identity) * about(n, self.rotation);
        let direction = |joints: &Joints| r.inverse() * machine.forward(joints, 0.0).dir;
        let start = ctrl.joints_now();
        let tip = ctrl.program_position();
        let pivot = Vec3::new(tip[0], tip[1], tip[2]) + d * direction(&start);
        let rotary = machine.rotary.len().min(2);
        let mut travel = 0.0f64;
        for (k, angle) in angles.iter().enumerate().take(rotary) {
            travel = travel.max((angle - start[machine.rotary_index(k)]).abs());
        }
        let steps = ((travel / DIST_STEP).ceil() as usize).clamp(1, MAX_DIST_STEPS);
        let feed: Vec<Command> = self.block.commands.clone();
        for step in 1..=steps {
            let f = step as f64 / steps as f64;
            let mut joints = start;
            let mut mv = Move::default();
            for (k, angle) in angles.iter().enumerate().take(rotary) {
                let i = machine.rotary_index(k);
                joints[i] = start[i] + f * (angle - start[i]);
                mv.targets[i] = Some(Target {
                    value: joints[i],
                    mode: TargetMode::Absolute,
                    span: Span::default(),
                });
            }
            let p = pivot - d * direction(&joints);
            for k in 0..3 {
                mv.targets[k] = Some(Target {
                    value: p[k],
                    mode: TargetMode::Absolute,
                    span: Span::default(),
                });
            }
            self.block.clear(line);
            self.block.commands.extend_from_slice(&feed);
            self.block.commands.push(Command::Move(mv));
            ctrl.run_block(&self.block, out)?;
        }
        Ok(())
    }

    /// The positioning feed of `PLANE … MOVE / TURN`: `F` or `FMAX`.
    fn positioning_feed(&mut self, ex: &Executed) {
        if let Some(f) = ex.word("F") {
            self.block
                .commands
                .push(Command::Interpolation(MotionMode::Linear));
            self.block.commands.push(Command::Feed {
                value: self.length(f.value),
                span: f.span,
            });
        } else {
            self.block
                .commands
                .push(Command::Interpolation(MotionMode::Rapid));
        }
    }

    /// The rotary positions for the tilted plane in force by `SEQ`; with
    /// `TABLE ROT` and the tool already along the plane's Z (no tilt), the
    /// rotary table turns the plane's rotation about the tool axis (the
    /// TNC's "TABLE ROT"), else the table stays (`COORD ROT`).
    fn table_rot(
        &self,
        ex: &Executed,
        ctrl: &Controller<'_>,
        seq: Option<bool>,
    ) -> Result<[f64; 2], Alarm> {
        let mut angles = ctrl
            .plane_axes(seq, Span::default())
            .map_err(|a| Alarm { line: ex.line, ..a })?;
        let machine = ctrl.machine();
        let Some(tilt) = self.tilt else {
            return Ok(angles);
        };
        if !ex.has_key("TABLE ROT") || machine.rotary.len() < 2 {
            return Ok(angles);
        }
        let z = tilt * Vec3::z();
        if (z - Vec3::z()).norm() > GEOMETRY_TOLERANCE {
            return Ok(angles);
        }
        // The table axis turning about the tool axis, if there is one.
        let Some(k) = (0..2).find(|&k| {
            machine.rotary[k].on == fiveaxis_machine::Side::Table
                && machine.rotary[k].axis.into_inner().cross(&Vec3::z()).norm() < GEOMETRY_TOLERANCE
        }) else {
            return Ok(angles);
        };
        let i = machine.rotary_index(k);
        let mut joints = ctrl.joints_now();
        joints[machine.rotary_index(0)] = angles[0];
        joints[machine.rotary_index(1)] = angles[1];
        let have = ctrl.tool_rotation_at(&joints) * Vec3::x();
        let want = tilt * Vec3::x();
        // The turn of the table that brings the plane's X where the
        // tool's X is: measured, so that the axis' sense does not matter.
        let turn = have.y.atan2(have.x) - want.y.atan2(want.x);
        joints[i] += turn.to_degrees();
        let check = ctrl.tool_rotation_at(&joints) * Vec3::x();
        let sign = if (check - want).norm() < 1e-6 {
            1.0
        } else {
            -1.0
        };
        angles[k] += sign * turn.to_degrees();
        Ok(angles)
    }

    /// A retract along the tool axis (machine coordinates) by `distance`,
    /// or to the end of the travel.
    fn retract(
        &mut self,
        ctrl: &mut Controller<'_>,
        line: u32,
        distance: Option<f64>,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        self.block.clear(line);
        self.block
            .commands
            .push(Command::Interpolation(MotionMode::Rapid));
        self.block.commands.push(Command::Retract {
            distance,
            span: Span::default(),
        });
        ctrl.run_block(&self.block, out)?;
        Ok(())
    }

    /// The machining cycle defined last, at the position where the tool
    /// stands (`CYCL CALL`, `M99`, `M89`), or at every point of the
    /// pattern (`CYCL CALL PAT`).
    fn call_cycle(
        &mut self,
        ex: &Executed,
        ctrl: &mut Controller<'_>,
        out: &mut Vec<Segment>,
        pattern: bool,
    ) -> Result<(), Alarm> {
        let line = ex.line;
        let Some((number, params)) = self.cycle.clone() else {
            return Err(alarm(
                line,
                Condition::CycleDataMissing,
                None,
                "a cycle call needs a machining cycle defined before it (CYCL DEF 200 …)".into(),
            ));
        };
        let mut points = std::mem::take(&mut self.points);
        points.clear();
        if pattern {
            cycles::pattern(&self.pattern, &mut points).map_err(|e| {
                alarm(
                    line,
                    Condition::CycleDataMissing,
                    None,
                    format!("PATTERN DEF: {}", e.message),
                )
            })?;
        }
        let [a, b, n] = self.axes();
        let result = (|| {
            if !pattern {
                return self.cycle_at(ctrl, line, number, &params, out);
            }
            for p in &points {
                // To the point in the plane at rapid, then the cycle (its
                // surface Q203 as the point's third coordinate when the
                // pattern gives one is the cycle's own).
                self.block.clear(line);
                self.block
                    .commands
                    .push(Command::Interpolation(MotionMode::Rapid));
                let mut mv = Move::default();
                for (k, i) in [a, b].into_iter().enumerate() {
                    mv.targets[i] = Some(Target {
                        value: p[k],
                        mode: TargetMode::Absolute,
                        span: Span::default(),
                    });
                }
                let _ = n;
                self.block.commands.push(Command::Move(mv));
                ctrl.run_block(&self.block, out)?;
                // A point's Z is the surface in addition to Q203 (TNC 640
                // manual, PATTERN DEF: "effective in addition to the
                // workpiece surface Q203").
                let mut params = params.clone();
                if p[2] != 0.0 {
                    match params.iter_mut().find(|(q, _)| *q == 203) {
                        Some((_, v)) => *v += p[2],
                        None => params.push((203, p[2])),
                    }
                }
                self.cycle_at(ctrl, line, number, &params, out)?;
            }
            Ok(())
        })();
        self.points = points;
        result
    }

    /// One call of cycle `number` where the tool stands.
    fn cycle_at(
        &mut self,
        ctrl: &mut Controller<'_>,
        line: u32,
        number: u32,
        params: &[(u32, f64)],
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let position = ctrl.program_position();
        let tool_radius = ctrl.tool_radius_in_force();
        let ctx = cycles::Context {
            plane: self.axes(),
            position: [position[0], position[1], position[2]],
            feed: ctrl.feed(),
            spindle: ctrl.spindle_speed(),
            tool_radius,
            spindle_ccw: false,
            point_angle: None,
        };
        let inch = self.inch;
        let params: Vec<(u32, f64)> = params
            .iter()
            .map(|&(q, v)| {
                // The language gives `FMAX` as +∞ and `FAUTO` as NaN; the
                // cycles take their markers.
                let v = if v == f64::INFINITY {
                    cycles::FMAX
                } else if v.is_nan() {
                    cycles::FAUTO
                } else {
                    v
                };
                (
                    q,
                    if inch && inch_value(q, v) {
                        v * MM_PER_INCH
                    } else {
                        v
                    },
                )
            })
            .collect();
        let mut steps = std::mem::take(&mut self.steps);
        steps.clear();
        let result = cycles::cycle(number, &params, &ctx, &mut steps)
            .map_err(|e| {
                alarm(
                    line,
                    Condition::CycleDataMissing,
                    None,
                    format!("CYCL DEF {number}: {}", e.message),
                )
            })
            .and_then(|()| self.steps_to_blocks(ctrl, line, &steps, out));
        self.steps = steps;
        result
    }

    /// Runs a cycle's steps as blocks of commands, then gives back the
    /// feed in force before it.
    fn steps_to_blocks(
        &mut self,
        ctrl: &mut Controller<'_>,
        line: u32,
        steps: &[cycles::Step],
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let feed = ctrl.feed();
        let [a, b, _] = self.axes();
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
            self.block.clear(line);
            match *step {
                cycles::Step::Rapid(to) => {
                    self.block
                        .commands
                        .push(Command::Interpolation(MotionMode::Rapid));
                    self.block.commands.push(Command::Move(target(to)));
                }
                cycles::Step::Feed { to, feed } if feed >= cycles::FMAX => {
                    self.block
                        .commands
                        .push(Command::Interpolation(MotionMode::Rapid));
                    self.block.commands.push(Command::Move(target(to)));
                }
                cycles::Step::Feed { to, feed } => {
                    self.block
                        .commands
                        .push(Command::Interpolation(MotionMode::Linear));
                    self.block.commands.push(Command::Feed {
                        value: feed,
                        span: Span::default(),
                    });
                    self.block.commands.push(Command::Move(target(to)));
                }
                cycles::Step::Helix {
                    center,
                    sweep,
                    end,
                    feed,
                } => {
                    let p = ctrl.program_position();
                    let [_, _, n] = self.axes();
                    let r = [p[a] - center[0], p[b] - center[1]];
                    let (sin, cos) = sweep.to_radians().sin_cos();
                    let e = [
                        center[0] + r[0] * cos - r[1] * sin,
                        center[1] + r[0] * sin + r[1] * cos,
                    ];
                    let mut to = [None; 3];
                    to[a] = Some(e[0]);
                    to[b] = Some(e[1]);
                    to[n] = Some(end);
                    self.block
                        .commands
                        .push(Command::Interpolation(if sweep >= 0.0 {
                            MotionMode::Ccw
                        } else {
                            MotionMode::Cw
                        }));
                    self.block.commands.push(Command::Feed {
                        value: feed,
                        span: Span::default(),
                    });
                    let mut mv = target(to);
                    self.set_centre(&mut mv, [a, b], center);
                    // Full turns beyond the last part turn (a whole number
                    // of turns ends where it starts: 360° each).
                    let turns = (sweep.abs() / 360.0 - GEOMETRY_TOLERANCE).floor();
                    if turns >= 1.0 {
                        mv.turns = Some(turns as u32);
                    }
                    self.block.commands.push(Command::Move(mv));
                }
                cycles::Step::Orient(_) => self.block.commands.push(Command::MFunction {
                    number: 19,
                    span: Span::default(),
                }),
                cycles::Step::Speed(s) => self.block.commands.push(Command::SpindleSpeed(s)),
                cycles::Step::Dwell(seconds) => self.block.commands.push(Command::Dwell {
                    seconds,
                    span: Span::default(),
                }),
                cycles::Step::M(number) => self.block.commands.push(Command::MFunction {
                    number,
                    span: Span::default(),
                }),
            }
            ctrl.run_block(&self.block, out)?;
        }
        self.block.clear(line);
        self.block.commands.push(Command::Feed {
            value: feed,
            span: Span::default(),
        });
        ctrl.run_block(&self.block, out)?;
        Ok(())
    }
}

/// Whether cycle parameter `q`'s value `v` is a length or a feed, which
/// an inch program gives in inches (and inches per minute): every
/// parameter but the dwell times, counts, angles, modes and speeds, and
/// not the feed markers FMAX and FAUTO.
fn inch_value(q: u32, v: f64) -> bool {
    const UNITLESS: [u32; 13] = [
        210, 211, 213, 214, 255, 336, 343, 351, 395, 426, 427, 429, 430,
    ];
    !UNITLESS.contains(&q) && (0.0..cycles::FMAX).contains(&v)
}

/// The machine's axis named `address` (X, Y, Z, then the rotary axes by
/// their names), by joint index.
fn axis_index(machine: &fiveaxis_machine::Machine, address: &str) -> Option<usize> {
    let mut chars = address.chars();
    let (Some(c), None) = (chars.next(), chars.next()) else {
        return None;
    };
    match c {
        'X' => Some(0),
        'Y' => Some(1),
        'Z' => Some(2),
        _ => (0..machine.rotary.len())
            .find(|&k| machine.rotary[k].name.eq_ignore_ascii_case(&c))
            .map(|k| machine.rotary_index(k)),
    }
}

/// Whether rotary axis `i` rolls over (an endless axis, where M126's
/// shorter way applies).
fn machine_coords_rollover(machine: &fiveaxis_machine::Machine, i: usize) -> bool {
    (0..machine.rotary.len())
        .find(|&k| machine.rotary_index(k) == i)
        .is_some_and(|k| machine.rotary[k].rollover)
}

/// Which of the plane's two axes (0 or 1) `address` names.
fn plane_slot(ctrl: &Controller<'_>, address: &str, a: usize, b: usize) -> Option<usize> {
    let i = axis_index(ctrl.machine(), address)?;
    if i == a {
        Some(0)
    } else if i == b {
        Some(1)
    } else {
        None
    }
}

/// Where a rounding or chamfer leaves the path before and meets the one
/// after, and the rounding's centre and sense (none: a chamfer's line).
#[derive(Clone, Copy, Debug)]
struct Joint {
    t1: [f64; 2],
    t2: [f64; 2],
    centre: Option<([f64; 2], bool)>,
}

/// A path's offset to its left by `d` (right when negative): a line
/// (point and unit direction) or a circle (centre and radius).
#[derive(Clone, Copy, Debug)]
enum Offset {
    Line([f64; 2], [f64; 2]),
    Circle([f64; 2], f64),
}

fn unit2(v: [f64; 2]) -> [f64; 2] {
    let l = v[0].hypot(v[1]);
    if l > 0.0 {
        [v[0] / l, v[1] / l]
    } else {
        [0.0, 0.0]
    }
}

/// The unit direction of travel of a path from `s` to `e`, at its end
/// (`at_end`) or its start.
fn direction_at(shape: Shape, s: [f64; 2], e: [f64; 2], at_end: bool) -> [f64; 2] {
    match shape {
        Shape::Arc { centre, ccw } => {
            let p = if at_end { e } else { s };
            let r = [p[0] - centre[0], p[1] - centre[1]];
            unit2(if ccw { [-r[1], r[0]] } else { [r[1], -r[0]] })
        }
        _ => unit2([e[0] - s[0], e[1] - s[1]]),
    }
}

fn offset_curve(shape: Shape, s: [f64; 2], e: [f64; 2], d: f64) -> Offset {
    match shape {
        Shape::Arc { centre, ccw } => {
            let r = (s[0] - centre[0]).hypot(s[1] - centre[1]);
            // Left of a counter-clockwise arc is towards its centre.
            Offset::Circle(centre, if ccw { r - d } else { r + d })
        }
        _ => {
            let t = unit2([e[0] - s[0], e[1] - s[1]]);
            Offset::Line([s[0] - d * t[1], s[1] + d * t[0]], t)
        }
    }
}

/// The crossing of two offset paths nearest `near`.
fn crossing_nearest(o1: Offset, o2: Offset, near: [f64; 2]) -> Option<[f64; 2]> {
    let mut best: Option<([f64; 2], f64)> = None;
    let mut take = |p: [f64; 2]| {
        let d = (p[0] - near[0]).hypot(p[1] - near[1]);
        if p[0].is_finite() && p[1].is_finite() && best.is_none_or(|(_, b)| d < b) {
            best = Some((p, d));
        }
    };
    let line_circle =
        |p: [f64; 2], t: [f64; 2], c: [f64; 2], r: f64, take: &mut dyn FnMut([f64; 2])| {
            // |p + u·t − c| = r.
            let w = [p[0] - c[0], p[1] - c[1]];
            let b = w[0] * t[0] + w[1] * t[1];
            let q = b * b - (w[0] * w[0] + w[1] * w[1] - r * r);
            if q >= 0.0 && r > 0.0 {
                for u in [-b - q.sqrt(), -b + q.sqrt()] {
                    take([p[0] + u * t[0], p[1] + u * t[1]]);
                }
            }
        };
    match (o1, o2) {
        (Offset::Line(p, t), Offset::Line(q, u)) => {
            let den = t[0] * u[1] - t[1] * u[0];
            if den.abs() > 1e-12 {
                let w = [q[0] - p[0], q[1] - p[1]];
                let k = (w[0] * u[1] - w[1] * u[0]) / den;
                take([p[0] + k * t[0], p[1] + k * t[1]]);
            }
        }
        (Offset::Line(p, t), Offset::Circle(c, r)) | (Offset::Circle(c, r), Offset::Line(p, t)) => {
            line_circle(p, t, c, r, &mut take);
        }
        (Offset::Circle(c1, r1), Offset::Circle(c2, r2)) => {
            let d = (c2[0] - c1[0]).hypot(c2[1] - c1[1]);
            if d > 0.0 && r1 > 0.0 && r2 > 0.0 && d <= r1 + r2 && d >= (r1 - r2).abs() {
                let x = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);
                let h = (r1 * r1 - x * x).max(0.0).sqrt();
                let u = [(c2[0] - c1[0]) / d, (c2[1] - c1[1]) / d];
                let m = [c1[0] + x * u[0], c1[1] + x * u[1]];
                take([m[0] - h * u[1], m[1] + h * u[0]]);
                take([m[0] + h * u[1], m[1] - h * u[0]]);
            }
        }
    }
    best.map(|(p, _)| p)
}

/// The point of a path nearest `f` (where a circle about `f` touches it).
fn foot(shape: Shape, s: [f64; 2], e: [f64; 2], f: [f64; 2]) -> [f64; 2] {
    match shape {
        Shape::Arc { centre, .. } => {
            let r = (s[0] - centre[0]).hypot(s[1] - centre[1]);
            let u = unit2([f[0] - centre[0], f[1] - centre[1]]);
            [centre[0] + r * u[0], centre[1] + r * u[1]]
        }
        _ => {
            let t = unit2([e[0] - s[0], e[1] - s[1]]);
            let k = (f[0] - s[0]) * t[0] + (f[1] - s[1]) * t[1];
            [s[0] + k * t[0], s[1] + k * t[1]]
        }
    }
}

/// Whether `p` (on the path's line or circle) lies on the path from `s`
/// to `e`.
fn within(shape: Shape, s: [f64; 2], e: [f64; 2], p: [f64; 2]) -> bool {
    match shape {
        Shape::Arc { centre, ccw } => {
            let angle = |q: [f64; 2]| angle_of([q[0] - centre[0], q[1] - centre[1]]);
            let sweep = |q: [f64; 2]| {
                let d = if ccw {
                    angle(q) - angle(s)
                } else {
                    angle(s) - angle(q)
                };
                d.rem_euclid(360.0)
            };
            let full = sweep(e);
            let full = if full == 0.0 { 360.0 } else { full };
            sweep(p) <= full + 1e-9
        }
        _ => {
            let d = [e[0] - s[0], e[1] - s[1]];
            let len2 = d[0] * d[0] + d[1] * d[1];
            let k = ((p[0] - s[0]) * d[0] + (p[1] - s[1]) * d[1]) / len2;
            (-1e-9..=1.0 + 1e-9).contains(&k)
        }
    }
}

/// The centre of the circle that leaves `s` along direction `t` and ends
/// at `e`, in the plane; `None` when `e` lies on the tangent.
fn tangent_centre(s: [f64; 2], e: [f64; 2], t: [f64; 2]) -> Option<[f64; 2]> {
    let len = t[0].hypot(t[1]);
    if len <= GEOMETRY_TOLERANCE {
        return None;
    }
    let t = [t[0] / len, t[1] / len];
    // The left normal; the centre is s + r·n with |c − e| = r.
    let n = [-t[1], t[0]];
    let d = [e[0] - s[0], e[1] - s[1]];
    let dn = d[0] * n[0] + d[1] * n[1];
    if dn.abs() <= GEOMETRY_TOLERANCE {
        return None;
    }
    let r = (d[0] * d[0] + d[1] * d[1]) / (2.0 * dn);
    Some([s[0] + r * n[0], s[1] + r * n[1]])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tangent_circle_centres() {
        // Leaving (0,0) along +X to (1,1): the quarter circle about (0,1).
        let c = tangent_centre([0.0, 0.0], [1.0, 1.0], [1.0, 0.0]).expect("circle");
        assert!((c[0]).abs() < 1e-12 && (c[1] - 1.0).abs() < 1e-12);
        // To (1,−1): about (0,−1), clockwise.
        let c = tangent_centre([0.0, 0.0], [1.0, -1.0], [2.0, 0.0]).expect("circle");
        assert!((c[1] + 1.0).abs() < 1e-12);
        assert!(tangent_centre([0.0, 0.0], [3.0, 0.0], [1.0, 0.0]).is_none());
    }

    #[test]
    fn plane_from_x_and_z_is_right_handed() {
        let r = from_x_and_z(Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, -1.0, 1.0)).expect("plane");
        let y = r * Vec3::y();
        // Y = Z × X.
        let z = Vec3::new(0.0, -1.0, 1.0).normalize();
        assert!((y - z.cross(&Vec3::x())).norm() < 1e-12);
        assert!(from_x_and_z(Vec3::x(), Vec3::x()).is_none());
    }

    #[test]
    fn spatial_angles_turn_about_the_fixed_axes_x_first() {
        // SPA90 SPC180: the plane's Z is the workpiece's +Y.
        let r = about(2, 180.0) * about(1, 0.0) * about(0, 90.0);
        let z = r * Vec3::z();
        assert!((z - Vec3::y()).norm() < 1e-12, "{z}");
    }
}
