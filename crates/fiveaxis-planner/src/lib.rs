//! The machining time a control would take: a velocity planner over the
//! machine axes, with look-ahead across blocks.
//!
//! Pure and streaming: blocks go in one at a time as polylines of sampled
//! machine-axis positions, the time comes out; memory is bounded by the
//! look-ahead window, and nothing is allocated per block once the window
//! has filled (unless a trace of the profile is asked for).
//!
//! # What it models
//!
//! * **Feed along the path.** Each block is a polyline of samples; each
//!   sample gives the axis positions and the length of path since the
//!   previous sample, measured where the control measures the feed `F`
//!   (the tool tip under TCPC; for a plain move the composite axis distance
//!   FANUC uses). The path speed never exceeds `F` (mm/min), or, for an
//!   inverse-time block (`G93`), the block's length times `F` (1/min): the
//!   block lasts at least `1/F` minutes.
//! * **Axis limits.** At path speed `v` each axis moves at `v·dq_i/ds`,
//!   never above its `max_velocity`; the path acceleration keeps every
//!   axis within `max_acceleration`, and, with `max_jerk`, the path jerk
//!   within it: jerk-limited (S-curve, "bell-shaped") speed changes.
//! * **Corners and curves** (see [Corners](#corners)): a change of
//!   direction between samples is rounded within the junction tolerance
//!   ([`Options::junction_tolerance`]); its speed keeps each axis'
//!   acceleration from the change of direction within
//!   [`BLEND_SHARE`] of its limit, the rest left for the change of speed.
//!   On a finely sampled curve this is the curvature limit `v² ≤
//!   share·amax/|d²q/ds²|`.
//! * **Look-ahead** ([`Options::lookahead`]): the classic backward and
//!   forward passes over a window of stretches, assuming a stop at the
//!   window's end (FANUC AI contour control: "look-ahead linear
//!   acceleration/deceleration before interpolation", deceleration started
//!   blocks ahead).
//! * **Exact stop** (`G61` mode, `G09` block, [`Block::exact_stop`]): zero
//!   speed at the block's end. [`Planner::stop`] does the same between
//!   blocks (dwell, program stop, tool change).
//! * **Rapids** ([`Feed::Rapid`]): linear interpolation type positioning
//!   (FANUC AI contour control specification, "Rapid traverse": the move
//!   is a straight line in axis space, its speed the smallest of the axes'
//!   rapid rates scaled to the path, acceleration before interpolation),
//!   from a stop to a stop.
//!
//! # What it does not model
//!
//! Servo lag and acceleration after interpolation, feed override, the
//! spindle, dwell times, tool changes (add them outside), the jerk of a
//! change of direction (jerk is limited along the path only), and a
//! control's exact block-count look-ahead (the window counts stretches).
//! With a jerk limit, every stretch (a run of samples with alike limits,
//! see [`JERK_MERGE_RATIO`]) starts and ends with zero acceleration, and
//! takes the smallest limits of its samples: conservative, slower than a
//! jerk-optimal control on paths whose limits change often. The
//! acceleration budget of a blend is split at a fixed share instead of
//! optimally: also conservative.
//!
//! # Example
//!
//! ```
//! use fiveaxis_planner::{AxisLimits, Block, Feed, Options, Planner, Point};
//!
//! let axis = AxisLimits {
//!     max_velocity: 30_000.0,   // mm/min
//!     rapid: 48_000.0,          // mm/min
//!     max_acceleration: 3000.0, // mm/s²
//!     max_jerk: None,
//! };
//! let mut planner = Planner::new(&[axis; 3], Options::default(), &[0.0; 3])?;
//! // G01 X100 F6000: one sample at the end of the line.
//! let end = Point::new(&[100.0, 0.0, 0.0], 100.0);
//! planner.push(&Block { feed: Feed::PerMinute(6000.0), exact_stop: false, points: &[end] })?;
//! let time = planner.finish().time;
//! // 100 mm at 100 mm/s, plus the time lost accelerating and braking at
//! // 3000 mm/s²: 1 s + 100/3000 s.
//! assert!((time - (1.0 + 100.0 / 3000.0)).abs() < 1e-9);
//! # Ok::<(), fiveaxis_planner::PlanError>(())
//! ```
//!
//! # Corners
//!
//! Between two samples the axes move in proportion (a straight line in
//! axis space, `dq/ds = u`). Where `u` changes by `Δu`, the control rounds
//! the joint: the axis velocities change linearly along a blend of path
//! length `b = min(L_before, L_after, 8·δ / max_i |Δu_i|)` centred on the
//! joint (δ the junction tolerance; each axis then leaves the sharp path by
//! at most `|Δu_i|·b/8 ≤ δ`). In the blend axis `i` accelerates at
//! `v²·Δu_i/b` from the change of direction, plus `a·dq_i/ds` from the
//! change of speed. The blend's speed is capped so that the first takes at
//! most [`BLEND_SHARE`] of the axis' acceleration, and the path
//! acceleration there is limited to what is left: their sum never exceeds
//! the axis' limit. On a finely sampled curve `b` is the sample spacing,
//! so the cap is the curvature limit whatever the spacing (FANUC AI
//! contour control's "feedrate clamp based on acceleration"); at a sharp
//! corner it is the velocity jump the axis can make within the tolerance
//! (the per-axis rule of FANUC's automatic corner deceleration, No.1783,
//! with the allowed jump taken from the acceleration and the tolerance).

mod path;
mod profile;
mod window;

pub use path::BLEND_SHARE;
pub use profile::Piece;

use window::{Stretch, Window};

/// Most axes a planner takes (as `fiveaxis_machine::MAX_AXES`).
pub const MAX_AXES: usize = 8;

/// Default junction tolerance, mm (degrees for rotary axes): grbl's default
/// junction deviation (`$11 = 0.010`).
pub const JUNCTION_TOLERANCE: f64 = 0.01;

/// Default look-ahead, in stretches.
pub const LOOKAHEAD: usize = 1024;

/// With a jerk limit, consecutive samples whose limits are within this
/// ratio of each other form one stretch (taking the smallest). Without one,
/// only equal limits (to rounding, [`EQUAL_RATIO`]) are merged, which
/// changes nothing.
pub const JERK_MERGE_RATIO: f64 = 0.8;

/// Limits equal to this ratio are the same limit.
pub const EQUAL_RATIO: f64 = 1.0 - 1e-12;

/// A sample length at or below this (mm) is no length: the interval is
/// measured by its composite axis distance instead (FANUC's feed of a move
/// of rotary axes alone, in degrees per minute).
pub const ZERO_LENGTH: f64 = 1e-9;

/// The dynamics of one machine axis, in the machine file's units (the
/// machine-model contract, "Axis dynamics").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisLimits {
    /// Fastest cutting feed of the axis, mm/min (deg/min) (FANUC No.1430).
    pub max_velocity: f64,
    /// Rapid traverse rate, mm/min (deg/min) (FANUC No.1420).
    pub rapid: f64,
    /// mm/s² (deg/s²) (FANUC No.1660).
    pub max_acceleration: f64,
    /// mm/s³ (deg/s³), if the axis' jerk is limited.
    pub max_jerk: Option<f64>,
}

/// The planner's own parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// How far a rounded corner may leave the programmed path, mm (degrees
    /// for a rotary axis), per axis. 0 stops at every corner.
    pub junction_tolerance: f64,
    /// Stretches of path the look-ahead window holds (at least 2).
    pub lookahead: usize,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            junction_tolerance: JUNCTION_TOLERANCE,
            lookahead: LOOKAHEAD,
        }
    }
}

/// How a block's speed is programmed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Feed {
    /// `G94`: the path speed, mm/min.
    PerMinute(f64),
    /// `G93`: the block takes `1/F` minutes at its programmed speed (F in
    /// 1/min).
    InverseTime(f64),
    /// `G00`: every axis at up to its rapid rate, from a stop to a stop.
    Rapid,
}

/// One sample of a block's path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Machine-axis positions (mm, degrees), the first
    /// [`Planner`]-axis-count of them used.
    pub axes: [f64; MAX_AXES],
    /// Path length from the previous sample (or the block's start), mm:
    /// the length the feed is measured along.
    pub length: f64,
}

impl Point {
    /// A sample from the positions of the axes (at most [`MAX_AXES`]; the
    /// rest are 0) and the path length since the previous sample.
    pub fn new(axes: &[f64], length: f64) -> Self {
        let mut p = [0.0; MAX_AXES];
        for (d, s) in p.iter_mut().zip(axes) {
            *d = *s;
        }
        Self { axes: p, length }
    }
}

/// One block of the program as the planner sees it.
#[derive(Clone, Copy, Debug)]
pub struct Block<'a> {
    pub feed: Feed,
    /// `G61` mode or `G09`: the speed is zero at the block's end.
    pub exact_stop: bool,
    /// The samples after the block's start (the previous block's end), in
    /// order; the last is the block's end.
    pub points: &'a [Point],
}

/// What went wrong with the planner's input.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PlanError {
    #[error("the planner takes 1 to {MAX_AXES} axes, not {count}")]
    AxisCount { count: usize },
    #[error("axis {axis}: {what} must be a finite number above 0, not {value}")]
    AxisLimit {
        axis: usize,
        what: &'static str,
        value: f64,
    },
    #[error("the junction tolerance must be a finite number of at least 0, not {value}")]
    JunctionTolerance { value: f64 },
    #[error("the look-ahead must hold at least 2 stretches, not {value}")]
    Lookahead { value: usize },
    #[error("the start position must give {expected} finite axis positions")]
    Start { expected: usize },
    #[error("point {index} of the block: {what}")]
    Point { index: usize, what: &'static str },
    #[error("the feed must be a finite number above 0, not {value}")]
    Feed { value: f64 },
}

/// One axis' limits in the planner's units (per second).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Axis {
    /// Cutting and rapid rates, per s.
    pub velocity: f64,
    pub rapid: f64,
    /// Per s², per s³ (infinite when not limited).
    pub acceleration: f64,
    pub jerk: f64,
}

/// What a finished plan gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    /// Machining time, s.
    pub time: f64,
    /// Path length planned, mm (the sum of the samples' lengths).
    pub length: f64,
}

/// The velocity planner: push blocks, then [`finish`](Planner::finish).
#[derive(Debug)]
pub struct Planner {
    axes: [Axis; MAX_AXES],
    count: usize,
    tolerance: f64,
    window: Window,
    /// Where the axes stand after the last sample pushed.
    position: [f64; MAX_AXES],
    /// The last interval, waiting for the joint after it.
    pending: Option<path::Interval>,
    /// The next joint is a stop.
    stop_next: bool,
    /// Path length pushed so far, mm (the marks' parameter).
    pushed: f64,
}

impl Planner {
    /// A planner for axes with `limits` (in machine-file order), standing
    /// still at `start`.
    pub fn new(limits: &[AxisLimits], options: Options, start: &[f64]) -> Result<Self, PlanError> {
        let count = limits.len();
        if count == 0 || count > MAX_AXES {
            return Err(PlanError::AxisCount { count });
        }
        let mut axes = [Axis::default(); MAX_AXES];
        let positive = |axis: usize, what: &'static str, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(value)
            } else {
                Err(PlanError::AxisLimit { axis, what, value })
            }
        };
        for (i, l) in limits.iter().enumerate() {
            axes[i] = Axis {
                velocity: positive(i, "max_velocity", l.max_velocity)? / 60.0,
                rapid: positive(i, "rapid", l.rapid)? / 60.0,
                acceleration: positive(i, "max_acceleration", l.max_acceleration)?,
                jerk: match l.max_jerk {
                    Some(j) => positive(i, "max_jerk", j)?,
                    None => f64::INFINITY,
                },
            };
        }
        let tolerance = options.junction_tolerance;
        if !(tolerance.is_finite() && tolerance >= 0.0) {
            return Err(PlanError::JunctionTolerance { value: tolerance });
        }
        if options.lookahead < 2 {
            return Err(PlanError::Lookahead {
                value: options.lookahead,
            });
        }
        if start.len() != count || start.iter().any(|x| !x.is_finite()) {
            return Err(PlanError::Start { expected: count });
        }
        let mut position = [0.0; MAX_AXES];
        position[..count].copy_from_slice(start);
        let jerk = limits.iter().any(|l| l.max_jerk.is_some());
        let merge = if jerk { JERK_MERGE_RATIO } else { EQUAL_RATIO };
        Ok(Self {
            axes,
            count,
            tolerance,
            window: Window::new(options.lookahead, merge),
            position,
            pending: None,
            stop_next: true,
            pushed: 0.0,
        })
    }

    /// Plans one block. A block that fails leaves the planner as it was.
    pub fn push(&mut self, block: &Block<'_>) -> Result<(), PlanError> {
        self.push_block(block, None)
    }

    /// [`push`](Planner::push), appending the pieces of the motion
    /// committed meanwhile to `trace` (for tests and plots).
    pub fn push_traced(
        &mut self,
        block: &Block<'_>,
        trace: &mut Vec<Piece>,
    ) -> Result<(), PlanError> {
        self.push_block(block, Some(trace))
    }

    /// The speed goes to zero here, between blocks (a dwell, a program
    /// stop, a tool change).
    pub fn stop(&mut self) {
        self.stop_next = true;
    }

    /// Marks the end of what has been pushed so far (a block's end): its
    /// time is known once the plan has committed past it, and is handed
    /// over by [`take_mark_times`](Planner::take_mark_times) (or
    /// [`finish_marked`](Planner::finish_marked)) in the order of the
    /// marks. A block's time is the difference of the marks around it;
    /// the last mark of a plan is its total time. Costs nothing unless
    /// called.
    pub fn mark(&mut self) {
        self.window.mark(self.pushed);
    }

    /// Hands over, in order, the times (s from the start) of the marks the
    /// plan has committed past since the last call.
    pub fn take_mark_times(&mut self, take: impl FnMut(f64)) {
        self.window.take_mark_times(take);
    }

    /// [`finish`](Planner::finish), handing over the times of every mark
    /// not yet taken.
    pub fn finish_marked(mut self, take: impl FnMut(f64)) -> Summary {
        if let Some(p) = self.pending.take() {
            self.emit(&p, path::Joint::Stop, None);
        }
        self.window.flush(None);
        self.window.take_mark_times(take);
        Summary {
            time: self.window.time(),
            length: self.window.length(),
        }
    }

    /// Time committed so far, s (the look-ahead window still holds the
    /// rest).
    pub fn time(&self) -> f64 {
        self.window.time()
    }

    /// Ends the plan with a stop and gives the total.
    pub fn finish(self) -> Summary {
        self.finish_inner(None)
    }

    /// [`finish`](Planner::finish), appending the remaining pieces to
    /// `trace`.
    pub fn finish_traced(self, trace: &mut Vec<Piece>) -> Summary {
        self.finish_inner(Some(trace))
    }

    fn finish_inner(mut self, mut trace: Option<&mut Vec<Piece>>) -> Summary {
        if let Some(p) = self.pending.take() {
            self.emit(&p, path::Joint::Stop, trace.as_deref_mut());
        }
        self.window.flush(trace);
        Summary {
            time: self.window.time(),
            length: self.window.length(),
        }
    }

    /// The length of the interval to `p` from `from`: the sample's own, or
    /// the composite axis distance when that is zero. `None` when nothing
    /// moves.
    fn interval_length(&self, from: &[f64; MAX_AXES], p: &Point) -> Option<f64> {
        if p.length > ZERO_LENGTH {
            return Some(p.length);
        }
        let d2: f64 = (0..self.count).map(|i| (p.axes[i] - from[i]).powi(2)).sum();
        (d2 > 0.0).then(|| d2.sqrt())
    }

    fn check(&self, block: &Block<'_>) -> Result<f64, PlanError> {
        let mut from = self.position;
        let mut total = 0.0;
        for (index, p) in block.points.iter().enumerate() {
            if p.axes[..self.count].iter().any(|x| !x.is_finite()) {
                return Err(PlanError::Point {
                    index,
                    what: "an axis position is not a finite number",
                });
            }
            if !(p.length.is_finite() && p.length >= 0.0) {
                return Err(PlanError::Point {
                    index,
                    what: "the length is not a finite number of at least 0",
                });
            }
            total += self.interval_length(&from, p).unwrap_or(0.0);
            from = p.axes;
        }
        Ok(total)
    }

    fn push_block(
        &mut self,
        block: &Block<'_>,
        mut trace: Option<&mut Vec<Piece>>,
    ) -> Result<(), PlanError> {
        let total = self.check(block)?;
        let (feed, rapid) = match block.feed {
            Feed::PerMinute(f) | Feed::InverseTime(f) if !(f.is_finite() && f > 0.0) => {
                return Err(PlanError::Feed { value: f });
            }
            Feed::PerMinute(f) => (f / 60.0, false),
            Feed::InverseTime(f) => (total * f / 60.0, false),
            Feed::Rapid => (f64::INFINITY, true),
        };
        let mut moved = false;
        for p in block.points {
            let from = self.position;
            let Some(len) = self.interval_length(&from, p) else {
                continue;
            };
            let mut dq = [0.0; MAX_AXES];
            for (i, d) in dq.iter_mut().enumerate().take(self.count) {
                *d = p.axes[i] - from[i];
            }
            self.position[..self.count].copy_from_slice(&p.axes[..self.count]);
            let mut next = path::interval(&self.axes[..self.count], &dq, len, feed, rapid);
            if rapid && !next.cap.is_finite() {
                // A rapid that moves no axis takes no time.
                continue;
            }
            self.pushed += len;
            if rapid && !moved {
                self.stop_next = true;
            }
            moved = true;
            let joint = match &self.pending {
                None => path::Joint::Stop,
                Some(_) if self.stop_next => path::Joint::Stop,
                Some(p) => path::joint(&self.axes[..self.count], self.tolerance, p, &next),
            };
            match joint {
                path::Joint::Stop => next.stop_before = true,
                path::Joint::Blend(b) => next.front = Some(b),
                path::Joint::Straight => {}
            }
            if let Some(p) = self.pending.take() {
                self.emit(&p, joint, trace.as_deref_mut());
            }
            self.stop_next = false;
            self.pending = Some(next);
        }
        if moved && (rapid || block.exact_stop) {
            self.stop_next = true;
        }
        Ok(())
    }

    /// Hands interval `p` to the window as stretches: the second half of
    /// the blend at its start, its middle, the first half of the blend at
    /// its end (`joint`).
    fn emit(&mut self, p: &path::Interval, joint: path::Joint, mut trace: Option<&mut Vec<Piece>>) {
        let front = p.front.map_or(0.0, |b| b.len / 2.0);
        let back = match joint {
            path::Joint::Blend(b) => b.len / 2.0,
            _ => 0.0,
        };
        let mut stop = p.stop_before;
        if let Some(b) = p.front {
            self.window.push(
                Stretch::new(front, b.cap, b.dynamics, stop),
                trace.as_deref_mut(),
            );
            stop = false;
        }
        let middle = p.len - front - back;
        if middle > 1e-12 * p.len {
            self.window.push(
                Stretch::new(middle, p.cap, p.dynamics, stop),
                trace.as_deref_mut(),
            );
            stop = false;
        }
        if let path::Joint::Blend(b) = joint {
            self.window
                .push(Stretch::new(back, b.cap, b.dynamics, stop), trace);
        }
    }
}
