//! The post: a program run with tool centre point control (G43.4 / G43.5)
//! or in a tilted working plane (G68.2), turned into a program in machine
//! axes for the same machine with those options off.
//!
//! Pure computation, no I/O: segments in (from the controller, which knows
//! every machine axis at every `s` of a block), moves out ([`Post`]), and
//! the program text from [`program::write`].
//!
//! * Each cutting block becomes straight moves of the machine axes between
//!   points of the block's own law ([`fiveaxis_control::Segment::eval`]),
//!   as many as needed: a piece is split in two while linear interpolation
//!   of the axes over it carries the tool tip further than the tip
//!   tolerance from the block's path, or the tool direction further than
//!   the angle tolerance ([`linearize`]).
//! * The feed is inverse time (G93): each piece lasts its share of the
//!   original block's time (tip length over the programmed tip feed), so
//!   the tip keeps the programmed feed.
//! * Rapid moves stay one positioning block (split only where a rollover
//!   axis would otherwise take the other way round).

pub mod apt;
pub mod linearize;
pub mod program;

use fiveaxis_control::{Motion, Path, RunError, Runner, Segment, Source};
use fiveaxis_machine::{Joints, Machine, Vec3};

pub use linearize::Deviation;

/// Default tip tolerance, mm (issue 13).
pub const DEFAULT_TOLERANCE: f64 = 0.01;
/// Default tool direction tolerance, degrees (issue 13).
pub const DEFAULT_ANGLE_TOLERANCE: f64 = 0.1;

/// Duration given to a cutting block that has no length to feed over,
/// minutes.
pub const MIN_BLOCK_MINUTES: f64 = 1e-6;

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
}

impl Default for PostOptions {
    fn default() -> Self {
        Self {
            tolerance: DEFAULT_TOLERANCE,
            angle_tolerance: DEFAULT_ANGLE_TOLERANCE,
            origin: Vec3::zeros(),
        }
    }
}

/// One block of the output program.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Move {
    /// Positioning (G00) to a machine position.
    Rapid(Joints),
    /// Linear interpolation of every axis (G01) to a machine position in
    /// `minutes`.
    Feed {
        /// Machine position at the end of the block.
        to: Joints,
        /// Duration of the block, minutes (its G93 F is the inverse).
        minutes: f64,
    },
}

/// The machine-axis program: its moves and what was reached.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Post {
    /// The blocks, in order.
    pub moves: Vec<Move>,
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
}

/// Turns segments into moves, one segment at a time.
#[derive(Debug)]
pub struct Converter<'m> {
    machine: &'m Machine,
    options: PostOptions,
    post: Post,
    /// Output quantum of lengths and angles (the last digit written).
    quantum: program::Quantum,
}

impl<'m> Converter<'m> {
    /// A converter for `machine` with `options`.
    pub fn new(machine: &'m Machine, options: PostOptions) -> Self {
        Self {
            machine,
            options,
            post: Post::default(),
            quantum: program::Quantum::for_tolerance(options.tolerance),
        }
    }

    /// Adds the moves of one segment.
    pub fn push(&mut self, seg: &Segment) {
        if !seg.moves() {
            return;
        }
        let (machine, quantum, origin) = (self.machine, self.quantum, self.options.origin);
        let q = |j: &Joints| quantum.snap(machine, j, &origin);
        match (seg.motion, &seg.path) {
            (Motion::Rapid, Path::Via(mid)) => {
                self.rapid(&seg.start, &q(mid));
                self.rapid(&q(mid), &q(&seg.end));
            }
            (Motion::Rapid, _) => self.rapid(&seg.start, &q(&seg.end)),
            _ => {
                // Positions are exact for any tool; the tool length
                // matters where the tip must follow the path.
                if !self.post.tool_lengths.contains(&seg.tool_length) {
                    self.post.tool_lengths.push(seg.tool_length);
                }
                self.post.source_blocks += 1;
                let minutes = block_minutes(self.machine, seg);
                let outcome = linearize::pieces(
                    self.machine,
                    seg,
                    &self.options,
                    &self.quantum,
                    |to, share| {
                        self.post.moves.push(Move::Feed {
                            to,
                            minutes: minutes * share,
                        });
                    },
                );
                self.post.deviation = self.post.deviation.max(outcome.deviation);
                self.post.unresolved += outcome.unresolved;
            }
        }
    }

    /// Positioning from `from` to `to`, split where a rotary axis turns
    /// more than [`linearize::MAX_PIECE_TURN`] (a rollover axis would
    /// otherwise take the shorter way).
    fn rapid(&mut self, from: &Joints, to: &Joints) {
        let last = match self.post.moves.last() {
            Some(Move::Rapid(p) | Move::Feed { to: p, .. }) => Some(*p),
            None => None,
        };
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
            let p = if k == turns {
                *to
            } else {
                self.quantum.snap(self.machine, &p, &self.options.origin)
            };
            self.post.moves.push(Move::Rapid(p));
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

/// Segments taken from the runner at once by [`convert`].
const BATCH: usize = 1024;

/// Runs a program to its end and converts every segment: the machine-axis
/// program of the run, or the error that stopped it (an alarm: then no
/// program, as the control would not have run it through).
pub fn convert<S: Source>(
    runner: &mut Runner<'_, S>,
    options: PostOptions,
) -> Result<Post, RunError> {
    let machine = runner.controller().machine();
    let mut converter = Converter::new(machine, options);
    let mut segments = Vec::with_capacity(BATCH);
    loop {
        segments.clear();
        let more = runner.fill(&mut segments, BATCH);
        for seg in &segments {
            converter.push(seg);
        }
        if !more? {
            return Ok(converter.finish());
        }
    }
}

/// The origin a post writes in for these offsets: G54 plus the external
/// work offset (machine coordinates).
pub fn g54_origin(offsets: &fiveaxis_machine::Offsets) -> Vec3 {
    offsets.work[0] + offsets.external
}

/// Time of a cutting block at its programmed tip feed, minutes: the length
/// of the tip path (the law's own length for TCPC blocks and circles, the
/// chord of the tips otherwise, as the control measures inverse time
/// blocks) over the feed.
pub fn block_minutes(machine: &Machine, seg: &Segment) -> f64 {
    let length = match &seg.path {
        Path::Tcpc(tcpc) => tcpc.tip.length(),
        Path::Helix { circle, .. } => circle.length(),
        Path::Arc(arc) => arc.length(),
        Path::Joint | Path::Via(_) => {
            (seg.row(machine, 1.0).tip - seg.row(machine, 0.0).tip).norm()
        }
    };
    // A block that only turns the tool about a standing tip: F is read as
    // degrees per minute of the largest rotary travel, as FANUC does for
    // rotary-only moves.
    let length = if length > 0.0 {
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
        Some(f) if f > 0.0 && length > 0.0 => length / f,
        // No time to keep: the shortest block the writer can state.
        _ => MIN_BLOCK_MINUTES,
    }
}
