//! The post: a program run with tool centre point control (G43.4 / G43.5),
//! in a tilted working plane (G68.2), made from APT / CL data, or written
//! in the machine axes of another machine, turned into a program in
//! machine axes for a machine without those options.
//!
//! Pure computation, no I/O: segments in (from the controller, which knows
//! every machine axis at every `s` of a block), moves out ([`Post`]), and
//! the program text from [`program::write`].
//!
//! * Each cutting block becomes straight moves of the machine axes between
//!   points of a law, as many as needed: a piece is split in two while
//!   linear interpolation of the axes over it carries the tool tip further
//!   than the tip tolerance from the law's, or the tool direction further
//!   than the angle tolerance ([`linearize`]). The law is the block's own
//!   ([`fiveaxis_control::Segment::eval`], [`Axes::Source`]) or the
//!   post's own rotary solution for the block's tool path ([`follow`],
//!   [`Axes::Post`]: continuous, singular passages inside the cone, flips
//!   with a retract where the soft limits demand one), on the same
//!   machine or another ([`retarget`]).
//! * Each piece lasts its share of the source block's time (tip length
//!   over the programmed tip feed), written as [`FeedStyle`] says.
//! * Rapid moves stay one positioning block (split only where a rollover
//!   axis would otherwise take the other way round).

pub mod apt;
pub mod feed;
pub mod follow;
pub mod linearize;
pub mod program;
pub mod retarget;

use fiveaxis_control::{Motion, Path, RunError, Runner, Segment, Source};
use fiveaxis_machine::{Joints, MAX_AXES, Machine, Vec3};

pub use feed::FeedStyle;
pub use linearize::Deviation;

/// Default tip tolerance, mm (issue 13).
pub const DEFAULT_TOLERANCE: f64 = 0.01;
/// Default tool direction tolerance, degrees (issue 13).
pub const DEFAULT_ANGLE_TOLERANCE: f64 = 0.1;
/// Finest tip tolerance a post takes, mm: a tenth of the finest least
/// input increment of a control (0.0001 mm, FANUC IS-C) the output is
/// written in, and a thousand times the spacing of doubles at the
/// largest travel a machine file may give (10^6 mm: 1.2e-10 mm). A finer
/// tolerance cannot be met by any written program; the post would cut
/// every block into its shortest pieces.
pub const MIN_TOLERANCE: f64 = 1e-6;
/// Finest tool direction tolerance a post takes, degrees: a tenth of the
/// finest least input increment of a rotary axis (0.0001 degree, IS-C).
pub const MIN_ANGLE_TOLERANCE: f64 = 1e-5;
/// Why a tip tolerance (mm) or a direction tolerance (degrees) cannot be
/// used, if one cannot: not a positive number, or finer than
/// [`MIN_TOLERANCE`] / [`MIN_ANGLE_TOLERANCE`].
///
/// # Errors
///
/// The message, naming the value and the floor.
pub fn check_tolerances(tolerance: f64, angle_tolerance: f64) -> Result<(), String> {
    for (value, floor, what, unit) in [
        (tolerance, MIN_TOLERANCE, "tolerance", "mm"),
        (
            angle_tolerance,
            MIN_ANGLE_TOLERANCE,
            "angle tolerance",
            "degrees",
        ),
    ] {
        if !(value > 0.0 && value.is_finite()) {
            return Err(format!(
                "the {what} must be a positive number of {unit}, not {value}"
            ));
        }
        if value < floor {
            return Err(format!(
                "the {what} {value:e} {unit} is finer than a program can hold: at least {floor:e} {unit}"
            ));
        }
    }
    Ok(())
}

/// The message of a post that stopped at a block needing more than
/// [`linearize::MAX_BLOCK_PIECES`] pieces (`Post::capped_line`), the line
/// given as the caller names it.
pub fn capped_message(line: u32, tolerance: f64, angle_tolerance: f64) -> String {
    format!(
        "line {line}: the block needs more than {} pieces to hold a tolerance of {tolerance} mm and {angle_tolerance} degrees: give larger tolerances",
        linearize::MAX_BLOCK_PIECES
    )
}

/// Default retract of a flip along the tool axis, mm: clear of the cut
/// for the usual stock allowances (tenths of a millimetre to a few
/// millimetres) and short enough not to leave the machine's travel.
pub const DEFAULT_RETRACT: f64 = 5.0;

/// Most rotary turn between the samples of a straight block's tip path,
/// degrees.
pub const LENGTH_STEP: f64 = 0.05;

/// Length of the tip path of a block by forward kinematics: the chord
/// when no rotary axis turns, else the sum of chords of samples at most
/// [`LENGTH_STEP`] of rotary turn apart (at most 65,536).
pub fn tip_path_length(machine: &Machine, seg: &Segment) -> f64 {
    let turn = linearize::max_turn(machine, &seg.start, &seg.end);
    let n = ((turn / LENGTH_STEP).ceil() as u32).clamp(1, 1 << 16);
    let mut last = seg.row(machine, 0.0).tip;
    let mut sum = 0.0;
    for k in 1..=n {
        let tip = seg.row(machine, f64::from(k) / f64::from(n)).tip;
        sum += (tip - last).norm();
        last = tip;
    }
    sum
}

/// Tip travel of a cutting block below which it is a rotary move alone,
/// mm.
pub const TIP_AT_REST: f64 = 1e-9;

/// Duration given to a cutting block that has no length to feed over,
/// minutes.
pub const MIN_BLOCK_MINUTES: f64 = 1e-6;

/// Whose rotary solution the output takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Axes {
    /// The source's own machine axes (what the control with TCPC would
    /// do with the program, its choice among the rotary solutions
    /// included), linearised. Same machine only.
    #[default]
    Source,
    /// The post's own ([`follow`]): the tool path (tip and direction) of
    /// the source followed continuously on the target machine, singular
    /// passages with the rotating axis moving linearly inside the cone,
    /// and a flip (retract, turn, re-engage) where the solution must jump
    /// to stay inside the soft limits.
    Post {
        /// TCPC blocks turn the tool on the great circle between their
        /// end directions (programmed tool vectors, APT / CL data).
        great_circle: bool,
    },
}

/// What the post must hold and where the output's coordinates start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PostOptions {
    /// Largest distance of the output's tool tip from the programmed tip
    /// path, mm.
    pub tolerance: f64,
    /// Largest angle between the output's tool direction and the
    /// programmed one, degrees.
    pub angle_tolerance: f64,
    /// Machine coordinates of the zero of the work coordinate system the
    /// output is written in (G54 plus the external offset): the output's
    /// X Y Z are machine positions minus this.
    pub origin: Vec3,
    /// Whose rotary solution.
    pub axes: Axes,
    /// Retract of a flip along the tool axis, mm.
    pub retract: f64,
    /// How the feed is written.
    pub feed: FeedStyle,
    /// The tool length a machine-axis source (no length compensation in
    /// force) was written for, mm: its tool tip is what the output
    /// follows. `None`: the gauge point (length 0).
    pub source_tool_length: Option<f64>,
}

impl Default for PostOptions {
    fn default() -> Self {
        Self {
            tolerance: DEFAULT_TOLERANCE,
            angle_tolerance: DEFAULT_ANGLE_TOLERANCE,
            origin: Vec3::zeros(),
            axes: Axes::Source,
            retract: DEFAULT_RETRACT,
            feed: FeedStyle::InverseTime,
            source_tool_length: None,
        }
    }
}

/// A comment the output carries between blocks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Note {
    /// A flip starts: retract along the tool axis, turn, re-engage.
    FlipStart {
        /// Source line of the block it precedes.
        line: u32,
        /// The retract, mm.
        retract: f64,
    },
    /// The flip has re-engaged the tool at the tip where it left.
    FlipEnd,
}

/// One block of the output program.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Move {
    /// Positioning (G00) to a machine position.
    Rapid {
        /// Machine position at the end of the block.
        to: Joints,
        /// Source line.
        line: u32,
    },
    /// Linear interpolation of every axis (G01) to a machine position in
    /// `minutes`.
    Feed {
        /// Machine position at the end of the block.
        to: Joints,
        /// Duration of the block, minutes (its G93 F is the inverse).
        minutes: f64,
        /// Programmed tip feed of the source block, mm/min.
        feed: f64,
        /// Source line.
        line: u32,
    },
    /// A comment.
    Note(Note),
}

impl Move {
    /// The machine position at the end of the block, if it moves.
    pub fn to(&self) -> Option<&Joints> {
        match self {
            Move::Rapid { to, .. } | Move::Feed { to, .. } => Some(to),
            Move::Note(_) => None,
        }
    }
}

/// The machine-axis program: its moves and what was reached.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Post {
    /// The blocks, in order.
    pub moves: Vec<Move>,
    /// Machine position before the first block.
    pub start: Option<Joints>,
    /// Largest deviation of the output from the programmed path (cutting
    /// moves), measured by forward kinematics of the output's axes.
    pub deviation: Deviation,
    /// The tool lengths the output was computed for, in order of first
    /// use, without repeats.
    pub tool_lengths: Vec<f64>,
    /// Cutting blocks of the source.
    pub source_blocks: u64,
    /// Pieces where even the shortest allowed piece did not meet the
    /// tolerances (the axes move too fast for them there).
    pub unresolved: u64,
    /// Flips made (retract, turn, re-engage).
    pub flips: u64,
    /// Source blocks that pass within the singular cone.
    pub singular_blocks: u64,
    /// Largest angle between the tool direction of the post's law and the
    /// programmed one, degrees (inside singular passages), before
    /// linearisation.
    pub singular_error: f64,
    /// Source blocks where no rotary solution stays inside the soft
    /// limits (kept as tracked).
    pub out_of_limits: u64,
    /// On a target without two rotary axes (the tip followed, the rotary
    /// axes standing): the largest angle between its tool direction and
    /// the programmed one, degrees.
    pub fixed_direction_error: f64,
    /// Whether the source ran blocks under a function whose machine
    /// positions depend on the kinematics and the tool (TCPC, G43.1, a
    /// tilted working plane, G54.4:
    /// `fiveaxis_control::Controller::kinematic_mode`), as [`convert`]
    /// saw it. Without any, on the same machine, there is nothing to
    /// convert: the source is a machine-axis program already.
    pub kinematic: bool,
    /// The source line of the first block that needed more than
    /// [`linearize::MAX_BLOCK_PIECES`] pieces to hold the tolerances: the
    /// output is not fit to write (tolerances too fine for the block).
    pub capped_line: Option<u32>,
}

impl Post {
    /// Whether the output was made for a tool length (one of the cutting
    /// blocks had a length other than 0). A machine-axis program is right
    /// for that length only; without one it holds the gauge point's path.
    pub fn has_tool_length(&self) -> bool {
        self.tool_lengths.iter().any(|l| *l != 0.0)
    }
}

/// The offsets with `length` as the length of every tool they do not
/// give one (absent, or length and wear 0): the tool length a post is
/// made for when the offsets file has none for the program's H (`fiveaxis
/// post --tool-length`). Tools 1 to the highest the offsets hold, or to
/// [`fiveaxis_machine::MAX_TOOL_OFFSET`] when they hold none; radii stay.
pub fn with_tool_length(
    offsets: &fiveaxis_machine::Offsets,
    length: f64,
) -> fiveaxis_machine::Offsets {
    let mut offsets = offsets.clone();
    offsets.any_name = true;
    let last = offsets
        .tools
        .keys()
        .next_back()
        .copied()
        .unwrap_or(fiveaxis_machine::MAX_TOOL_OFFSET);
    for n in 1..=last {
        let tool = offsets.tools.entry(n).or_default();
        if tool.length == 0.0 && tool.length_wear == 0.0 {
            tool.length = length;
        }
    }
    offsets
}

impl Post {
    /// Takes in how one linearised law came out: the largest deviation
    /// reached and the pieces that could not be brought within tolerance.
    fn record(&mut self, outcome: &linearize::Outcome) {
        self.deviation = self.deviation.max(outcome.deviation);
        self.unresolved += outcome.unresolved;
        self.note_capped(outcome);
    }

    /// Keeps the line of the block (the last move's) if `outcome` reached
    /// the bound of pieces, and no block did before.
    fn note_capped(&mut self, outcome: &linearize::Outcome) {
        if outcome.capped && self.capped_line.is_none() {
            self.capped_line = self.moves.iter().rev().find_map(|m| match m {
                Move::Feed { line, .. } => Some(*line),
                _ => None,
            });
        }
    }
}

/// Turns segments into moves, one segment at a time.
#[derive(Debug)]
pub struct Converter<'m> {
    source: &'m Machine,
    machine: &'m Machine,
    options: PostOptions,
    post: Post,
    /// Output quantum of lengths and angles (the last digit written).
    quantum: program::Quantum,
    /// With [`Axes::Post`]: the exact rotary angles where the axes stand.
    angles: Option<[f64; 2]>,
}

impl<'m> Converter<'m> {
    /// A converter for `machine` with `options` (the source run on the
    /// same machine).
    pub fn new(machine: &'m Machine, options: PostOptions) -> Self {
        Self::retarget(machine, machine, options)
    }

    /// A converter of segments run on `source` into moves of `machine`
    /// (the source's tool path by forward kinematics, the post's own axes
    /// on `machine`: `options.axes` is taken as [`Axes::Post`] unless the
    /// machines are the same).
    pub fn retarget(source: &'m Machine, machine: &'m Machine, options: PostOptions) -> Self {
        let mut options = options;
        if !std::ptr::eq(source, machine) && options.axes == Axes::Source {
            options.axes = Axes::Post {
                great_circle: false,
            };
        }
        Self {
            source,
            machine,
            options,
            post: Post::default(),
            quantum: program::Quantum::for_tolerance(options.tolerance),
            angles: None,
        }
    }

    fn snap(&self, j: &Joints) -> Joints {
        self.quantum.snap(self.machine, j, &self.options.origin)
    }

    /// Where the output stands: the last block's end, or `fallback`.
    fn at(&self, fallback: &Joints) -> Joints {
        self.post
            .moves
            .iter()
            .rev()
            .find_map(Move::to)
            .copied()
            .unwrap_or(*fallback)
    }

    /// Adds the moves of one segment.
    pub fn push(&mut self, seg: &Segment) {
        if !seg.moves() {
            return;
        }
        match self.options.axes {
            Axes::Source => self.push_source(seg),
            Axes::Post { great_circle } => self.push_post(seg, great_circle),
        }
    }

    fn push_source(&mut self, seg: &Segment) {
        if self.post.start.is_none() {
            self.post.start = Some(seg.start);
        }
        let q = |j: &Joints| self.snap(j);
        match (seg.motion, &seg.path) {
            (Motion::Rapid, Path::Via(mid)) => {
                let (m, e) = (q(mid), q(&seg.end));
                self.rapid(&seg.start, &m, seg.line);
                self.rapid(&m, &e, seg.line);
            }
            (Motion::Rapid, _) => {
                let e = q(&seg.end);
                self.rapid(&seg.start, &e, seg.line);
            }
            _ => {
                self.cutting_bookkeeping(seg.tool_length);
                let minutes = block_minutes(self.source, seg);
                let feed = seg.feed.unwrap_or(0.0);
                let machine = self.machine;
                let (options, quantum) = (self.options, self.quantum);
                let moves = &mut self.post.moves;
                let outcome = linearize::pieces(machine, seg, &options, &quantum, |to, share| {
                    moves.push(Move::Feed {
                        to,
                        minutes: minutes * share,
                        feed,
                        line: seg.line,
                    });
                });
                self.post.record(&outcome);
            }
        }
    }

    fn cutting_bookkeeping(&mut self, length: f64) {
        // Positions are exact for any tool; the tool length matters where
        // the tip must follow the path.
        if !self.post.tool_lengths.contains(&length) {
            self.post.tool_lengths.push(length);
        }
        self.post.source_blocks += 1;
    }

    /// The target's axes with rotary angles `q` and the tip of
    /// `tool_length` on `tip` (target table frame).
    fn pose_joints(&self, q: [f64; 2], tip: &Vec3, tool_length: f64) -> Joints {
        let m = self.machine;
        let mut j = [0.0; MAX_AXES];
        j[m.rotary_index(0)] = q[0];
        j[m.rotary_index(1)] = q[1];
        let gauge = m.gauge_for_tip(&j, tip, tool_length);
        j[..3].copy_from_slice(gauge.as_slice());
        j
    }

    /// The angles the target takes for `dir` when nothing else decides:
    /// the solution nearest where the axes stand (or the source's angles
    /// on the same machine), inside the soft limits when one is.
    fn nearest_angles(&self, dir: &Vec3, seg: &Segment) -> [f64; 2] {
        let near = self.angles.unwrap_or_else(|| {
            if std::ptr::eq(self.source, self.machine) {
                let m = self.machine;
                [seg.start[m.rotary_index(0)], seg.start[m.rotary_index(1)]]
            } else {
                [0.0, 0.0]
            }
        });
        follow::start_candidates(self.machine, dir, near)
            .into_iter()
            .next()
            .unwrap_or(near)
    }

    fn push_post(&mut self, seg: &Segment, great_circle: bool) {
        let length = match (seg.tool_length, self.options.source_tool_length) {
            (0.0, Some(given)) => given,
            (l, _) => l,
        };
        let source = follow::Source {
            machine: self.source,
            seg,
            great_circle,
            tool_length: length,
        };
        if self.machine.rotary.len() != 2 {
            self.push_tip_only(seg, &source, length);
            return;
        }
        let origin = self.options.origin;
        if seg.motion == Motion::Rapid {
            let targets: &[f64] = if matches!(seg.path, Path::Via(_)) {
                &[0.5, 1.0]
            } else {
                &[1.0]
            };
            for &s in targets {
                let (tip, dir) = source.pose(s);
                let q = self.nearest_angles(&dir, seg);
                let to = self.pose_joints(q, &(tip + origin), length);
                if self.post.start.is_none() {
                    self.post.start = Some(to);
                }
                let from = self.at(&to);
                let to = self.snap(&to);
                self.rapid(&from, &to, seg.line);
                self.angles = Some(q);
            }
            return;
        }
        self.cutting_bookkeeping(length);
        let (tip0, dir0) = source.pose(0.0);
        // The axes go on from where they stand if they point the tool
        // along the block's start direction, or, inside the singular cone
        // (a passage goes on), within its angle to the singular line.
        let cone = self.machine.params.singular_cone;
        let standing = self.angles.filter(|q| {
            let j = self.pose_joints(*q, &(tip0 + origin), length);
            let d = self.machine.forward(&j, length).dir;
            let off = follow::singular_angle(self.machine, &dir0);
            let allowed = if off < cone { off + 1e-9 } else { 1e-6 };
            follow::angle(&d, &dir0) <= allowed
        });
        let start = standing.unwrap_or_else(|| self.nearest_angles(&dir0, seg));
        let mut law = follow::Law::new(source, self.machine, origin, start);
        if !law.within_limits() && law.has_passage() {
            // Leaving the singular cone on the other branch may keep the
            // limits without a flip.
            let other = follow::Law::with_exit(source, self.machine, origin, start, 1);
            if other.within_limits() {
                law = other;
            }
        }
        if !law.within_limits() {
            let other = follow::start_candidates(self.machine, &dir0, start)
                .into_iter()
                .filter(|q| (q[0] - start[0]).abs() + (q[1] - start[1]).abs() > 1e-6)
                .map(|q| follow::Law::new(source, self.machine, origin, q))
                .find(follow::Law::within_limits);
            match other {
                Some(other) => {
                    law = other;
                }
                None => self.post.out_of_limits += 1,
            }
        }
        let begin = self.pose_joints(start, &(tip0 + origin), length);
        if self.post.start.is_none() {
            self.post.start = Some(begin);
        }
        let feed = seg.feed.unwrap_or(0.0);
        let law_start = law.angles(0.0);
        if law_start != start {
            self.flip(
                seg.line,
                length,
                start,
                law_start,
                &(tip0 + origin),
                &dir0,
                feed,
            );
        } else if standing.is_none() {
            // The axes stood elsewhere (the first block, a tool change):
            // move to the block's start at its feed.
            let from = self.at(&begin);
            let to = self.snap(&begin);
            if from != to {
                let length = (self.machine.forward(&from, length).tip - tip0 - origin)
                    .norm()
                    .max(linearize::max_turn(self.machine, &from, &to));
                self.post.moves.push(Move::Feed {
                    to,
                    minutes: if feed > 0.0 {
                        (length / feed).max(MIN_BLOCK_MINUTES)
                    } else {
                        MIN_BLOCK_MINUTES
                    },
                    feed,
                    line: seg.line,
                });
            }
        }
        if law.has_passage() {
            self.post.singular_blocks += 1;
            self.post.singular_error = self.post.singular_error.max(law.direction_error());
        }
        let minutes = block_minutes(self.source, seg);
        let at = self.at(&begin);
        let (machine, options, quantum) = (self.machine, self.options, self.quantum);
        let moves = &mut self.post.moves;
        let joints = |s: f64| law.joints(s);
        let outcome = linearize::pieces_of(
            machine,
            &joints,
            &at,
            law.tool_length(),
            &options,
            &quantum,
            |to, share| {
                moves.push(Move::Feed {
                    to,
                    minutes: minutes * share,
                    feed,
                    line: seg.line,
                });
            },
        );
        self.post.record(&outcome);
        self.angles = Some(law.end_angles());
    }

    /// A target without two rotary axes: its rotary axes (if any) stand
    /// where they are, the linear axes put the tip on the path; the
    /// direction error is recorded.
    fn push_tip_only(&mut self, seg: &Segment, source: &follow::Source<'_>, length: f64) {
        let m = self.machine;
        let origin = self.options.origin;
        let held = self.at(&[0.0; MAX_AXES]);
        let joints = |s: f64| {
            let (tip, _) = source.pose(s);
            let mut j = held;
            let gauge = m.gauge_for_tip(&j, &(tip + origin), length);
            j[..3].copy_from_slice(gauge.as_slice());
            j
        };
        if self.post.start.is_none() {
            self.post.start = Some(joints(0.0));
        }
        if seg.motion == Motion::Rapid {
            let targets: &[f64] = if matches!(seg.path, Path::Via(_)) {
                &[0.5, 1.0]
            } else {
                &[1.0]
            };
            for &s in targets {
                let from = self.at(&joints(0.0));
                let to = self.snap(&joints(s));
                self.rapid(&from, &to, seg.line);
            }
            return;
        }
        self.cutting_bookkeeping(length);
        for k in 0..=8 {
            let s = f64::from(k) / 8.0;
            let got = m.forward(&joints(s), length).dir;
            let error = follow::angle(&got, &source.pose(s).1);
            self.post.fixed_direction_error = self.post.fixed_direction_error.max(error);
        }
        let minutes = block_minutes(self.source, seg);
        let feed = seg.feed.unwrap_or(0.0);
        let at = self.at(&joints(0.0));
        let (options, quantum) = (self.options, self.quantum);
        let moves = &mut self.post.moves;
        let outcome =
            linearize::pieces_of(m, &joints, &at, length, &options, &quantum, |to, share| {
                moves.push(Move::Feed {
                    to,
                    minutes: minutes * share,
                    feed,
                    line: seg.line,
                });
            });
        self.post.record(&outcome);
    }

    /// Retract along the tool axis by the retract distance, turn the
    /// rotary axes from `from` to `to` with the tip held there, and
    /// re-engage to `tip` (target table frame) along the same axis
    /// (`dir`: both solutions point the tool along it).
    #[allow(clippy::too_many_arguments)]
    fn flip(
        &mut self,
        line: u32,
        length: f64,
        from: [f64; 2],
        to: [f64; 2],
        tip: &Vec3,
        dir: &Vec3,
        feed: f64,
    ) {
        self.post.flips += 1;
        let retract = self.options.retract;
        self.post
            .moves
            .push(Move::Note(Note::FlipStart { line, retract }));
        let clear = tip + dir * retract;
        let minutes = |travel: f64| {
            if feed > 0.0 {
                (travel / feed).max(MIN_BLOCK_MINUTES)
            } else {
                MIN_BLOCK_MINUTES
            }
        };
        let up = self.snap(&self.pose_joints(from, &clear, length));
        self.post.moves.push(Move::Feed {
            to: up,
            minutes: minutes(retract),
            feed,
            line,
        });
        // The turn: the tip held at the clear point, the rotary axes
        // linear; F read as degrees per minute of the largest turn.
        let turn = (from[0] - to[0]).abs().max((from[1] - to[1]).abs());
        let total = minutes(turn);
        let lerp = |s: f64| {
            [
                from[0] + (to[0] - from[0]) * s,
                from[1] + (to[1] - from[1]) * s,
            ]
        };
        let law = |s: f64| self.pose_joints(lerp(s), &clear, length);
        let (machine, options, quantum) = (self.machine, self.options, self.quantum);
        let mut turned = Vec::new();
        let outcome = linearize::pieces_of(
            machine,
            &law,
            &up,
            length,
            &options,
            &quantum,
            |j, share| {
                turned.push(Move::Feed {
                    to: j,
                    minutes: total * share,
                    feed,
                    line,
                });
            },
        );
        self.post.moves.extend(turned);
        self.post.unresolved += outcome.unresolved;
        self.post.note_capped(&outcome);
        let down = self.snap(&self.pose_joints(to, tip, length));
        self.post.moves.push(Move::Feed {
            to: down,
            minutes: minutes(retract),
            feed,
            line,
        });
        self.post.moves.push(Move::Note(Note::FlipEnd));
    }

    /// Positioning from `from` to `to`, split where a rotary axis turns
    /// more than [`linearize::MAX_PIECE_TURN`] (a rollover axis would
    /// otherwise take the shorter way).
    fn rapid(&mut self, from: &Joints, to: &Joints, line: u32) {
        let last = self.post.moves.iter().rev().find_map(Move::to).copied();
        if last.as_ref() == Some(to) {
            // Already there (G28's intermediate point at the reference).
            return;
        }
        let turns = linearize::rollover_splits(self.machine, from, to);
        for k in 1..=turns {
            let t = f64::from(k) / f64::from(turns);
            let mut p = *to;
            for (i, v) in p.iter_mut().enumerate().take(self.machine.axis_count()) {
                *v = from[i] + (to[i] - from[i]) * t;
            }
            let p = if k == turns { *to } else { self.snap(&p) };
            self.post.moves.push(Move::Rapid { to: p, line });
        }
    }

    /// The options in force.
    pub fn options(&self) -> &PostOptions {
        &self.options
    }

    /// The finished program.
    pub fn finish(self) -> Post {
        self.post
    }
}

/// Room for the segments of a block in [`convert`].
const BATCH: usize = 1024;

/// Runs a program to its end and converts every segment into moves of
/// `target` (the runner's own machine, or another: retargeting, see
/// [`Converter::retarget`]): the machine-axis program of the run, or the
/// error that stopped it (an alarm: then no program, as the control would
/// not have run it through).
pub fn convert<S: Source>(
    runner: &mut Runner<'_, S>,
    target: &Machine,
    options: PostOptions,
) -> Result<Post, RunError> {
    let source = runner.controller().machine();
    let mut converter = Converter::retarget(source, target, options);
    let mut segments = Vec::with_capacity(BATCH);
    let mut kinematic = false;
    loop {
        segments.clear();
        // A block at a time, so that the controller's state is seen after
        // every block that moves (TCPC may be on for a few blocks only).
        let more = runner.fill(&mut segments, 1);
        kinematic |= runner.controller().kinematic_mode();
        for seg in &segments {
            converter.push(seg);
        }
        // A block past the bound of pieces: the output will not be
        // written, the rest need not be made.
        if !more? || converter.post.capped_line.is_some() {
            let mut post = converter.finish();
            post.kinematic = kinematic;
            return Ok(post);
        }
    }
}

/// Whose rotary solution a conversion follows by default: the post's own
/// (continuous along the tool path, flipping where the limits force it)
/// for CL data, which has no machine axes, and across machines; the
/// source's own otherwise (on its machine the control's choice is the
/// programmer's). CL data's directions interpolate along great circles.
pub fn default_axes(cl_data: bool, retargeting: bool) -> Axes {
    if cl_data || retargeting {
        Axes::Post {
            great_circle: cl_data,
        }
    } else {
        Axes::Source
    }
}

/// The origin a post writes in for these offsets: G54 plus the external
/// work offset (machine coordinates).
pub fn g54_origin(offsets: &fiveaxis_machine::Offsets) -> Vec3 {
    offsets.work[0] + offsets.external
}

/// Time of a cutting block at its programmed tip feed, minutes: the length
/// of the tip path (the law's own length for TCPC blocks and circles; for
/// a block of straight axis motion, the tip path by forward kinematics,
/// or in inverse time the chord of the tips, as the kernel measures the
/// tip feed of a G93 block, which gives back 1/F) over the feed.
pub fn block_minutes(machine: &Machine, seg: &Segment) -> f64 {
    let length = match &seg.path {
        Path::Tcpc(tcpc) => tcpc.tip.length(),
        Path::Helix { circle, .. } => circle.length(),
        Path::Arc(arc) => arc.length(),
        Path::Joint | Path::Via(_) if seg.inverse_time => {
            (seg.row(machine, 1.0).tip - seg.row(machine, 0.0).tip).norm()
        }
        Path::Joint | Path::Via(_) => tip_path_length(machine, seg),
    };
    // A block that only turns the tool about a standing tip: F is read as
    // degrees per minute of the largest rotary travel, as FANUC does for
    // rotary-only moves.
    let length = if length > TIP_AT_REST {
        length
    } else {
        (0..machine.rotary.len())
            .map(|k| {
                let i = machine.rotary_index(k);
                (seg.end[i] - seg.start[i]).abs()
            })
            .fold(0.0, f64::max)
    };
    match seg.feed {
        Some(f) if f > 0.0 && length > 0.0 => (length / f).max(MIN_BLOCK_MINUTES),
        // No time to keep: the shortest block the writer can state.
        _ => MIN_BLOCK_MINUTES,
    }
}
