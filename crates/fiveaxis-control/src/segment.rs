//! Segments: one move of every machine axis, described completely, and the
//! rows sampled from it.
//!
//! A segment knows how every axis moves as a function of the block's shared
//! interpolation parameter `s` in [0, 1] ([`Segment::eval`]); every consumer
//! (the `run` writer, later verification, conversion and the backplot)
//! samples that one truth. The reported tool tip and direction of a row come
//! from forward kinematics of the sampled machine position, never from the
//! programmed values.

use fiveaxis_machine::{Joints, Machine, Vec3};

/// Interpolation kind of a move, as the `motion` column shows it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Motion {
    /// Positioning (G00 and the reference-return moves).
    Rapid,
    /// Linear interpolation (G01).
    Linear,
    /// Clockwise arc (G02).
    Cw,
    /// Counter-clockwise arc (G03).
    Ccw,
}

impl Motion {
    /// The name written in the `motion` column.
    pub fn name(self) -> &'static str {
        match self {
            Motion::Rapid => "rapid",
            Motion::Linear => "linear",
            Motion::Cw => "cw",
            Motion::Ccw => "ccw",
        }
    }
}

/// How the axes get from `start` to `end`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Path {
    /// Every axis linear in `s`.
    Joint,
    /// The two plane axes on a circle (or a spiral, when the radii differ
    /// within tolerance), every other axis linear in `s`.
    Arc(Arc),
    /// Straight through an intermediate machine position reached at
    /// s = 0.5 (G28 / G30 reference returns).
    Via(Joints),
}

/// A circle in the plane of two machine axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arc {
    /// Indices in [`Joints`] of the plane's first and second axis.
    pub axes: [usize; 2],
    /// Centre in those two axes' machine coordinates (at s = 0).
    pub center: [f64; 2],
    /// Radius at the start.
    pub r0: f64,
    /// Radius at the end.
    pub r1: f64,
    /// Angle of the start point, radians, from the first axis towards the
    /// second.
    pub theta0: f64,
    /// Signed sweep, radians: positive counter-clockwise seen from the
    /// plane's normal.
    pub sweep: f64,
    /// Change of the centre over the block (a length offset vector that
    /// changes between the block ends), in the two plane axes.
    pub drift: [f64; 2],
}

impl Arc {
    /// Length of the arc in its plane.
    pub fn length(&self) -> f64 {
        0.5 * (self.r0 + self.r1) * self.sweep.abs()
    }
}

/// One move of every machine axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// 1-based line of the block in the program.
    pub line: u32,
    /// Interpolation kind.
    pub motion: Motion,
    /// Programmed feed at the tool tip, mm/min; `None` for rapid moves.
    pub feed: Option<f64>,
    /// Machine position at s = 0.
    pub start: Joints,
    /// Machine position at s = 1.
    pub end: Joints,
    /// How the axes move in between.
    pub path: Path,
    /// Tool length used for the reported tip (the active H value).
    pub tool_length: f64,
    /// Work offset: table-frame coordinates of the part frame's origin.
    pub work: Vec3,
}

fn lerp(a: f64, b: f64, s: f64) -> f64 {
    a + (b - a) * s
}

impl Segment {
    /// Machine position at `s` (0 ≤ s ≤ 1); exactly `end` at s = 1.
    pub fn eval(&self, s: f64) -> Joints {
        if s >= 1.0 {
            return self.end;
        }
        let (from, to, t) = match &self.path {
            Path::Via(mid) if s < 0.5 => (&self.start, mid, 2.0 * s),
            Path::Via(mid) => (mid, &self.end, 2.0 * s - 1.0),
            _ => (&self.start, &self.end, s),
        };
        let mut joints = self.start;
        for (j, (a, b)) in joints.iter_mut().zip(from.iter().zip(to)) {
            *j = lerp(*a, *b, t);
        }
        if let Path::Arc(arc) = &self.path {
            let theta = arc.theta0 + arc.sweep * s;
            let r = lerp(arc.r0, arc.r1, s);
            let [p, q] = arc.axes;
            joints[p] = arc.center[0] + arc.drift[0] * s + r * theta.cos();
            joints[q] = arc.center[1] + arc.drift[1] * s + r * theta.sin();
        }
        joints
    }

    /// Whether any axis moves.
    pub fn moves(&self) -> bool {
        self.start != self.end
            || match &self.path {
                Path::Arc(a) => a.sweep != 0.0,
                Path::Via(mid) => *mid != self.start,
                Path::Joint => false,
            }
    }

    /// The row at `s`: machine position and, by forward kinematics, the tip
    /// and tool direction in the part frame.
    pub fn row(&self, machine: &Machine, s: f64) -> Row {
        let joints = self.eval(s);
        let pose = machine.forward(&joints, self.tool_length);
        Row {
            line: self.line,
            s,
            motion: self.motion,
            joints,
            tip: pose.tip - self.work,
            dir: pose.dir,
            feed: self.feed,
        }
    }

    /// How many equal steps in `s` keep consecutive tips at most `step` mm
    /// apart and every rotary axis within `step_angle` degrees per step.
    ///
    /// The tip path of a move with rotary axes is not straight, so the
    /// count from the straight-line estimate is doubled until every step
    /// obeys the bound (at most [`MAX_STEPS`] steps).
    pub fn steps(&self, machine: &Machine, step: f64, step_angle: f64) -> u32 {
        let first_rotary = machine.linear.len();
        let rotary_span = (first_rotary..machine.axis_count())
            .map(|i| (self.end[i] - self.start[i]).abs())
            .fold(0.0, f64::max);
        let tip_start = machine.forward(&self.start, self.tool_length).tip;
        let tip_end = machine.forward(&self.end, self.tool_length).tip;
        let chord = match &self.path {
            Path::Arc(arc) => arc.length().max((tip_end - tip_start).norm()),
            Path::Via(mid) => {
                let tip_mid = machine.forward(mid, self.tool_length).tip;
                (tip_mid - tip_start).norm() + (tip_end - tip_mid).norm()
            }
            Path::Joint => (tip_end - tip_start).norm(),
        };
        let count = |span: f64, limit: f64| {
            if limit > 0.0 && span.is_finite() {
                (span / limit).ceil().min(f64::from(MAX_STEPS))
            } else {
                1.0
            }
        };
        let mut n = count(chord, step)
            .max(count(rotary_span, step_angle))
            .max(1.0) as u32;
        while n < MAX_STEPS && !self.steps_within(machine, n, step) {
            n = (n * 2).min(MAX_STEPS);
        }
        n
    }

    fn steps_within(&self, machine: &Machine, n: u32, step: f64) -> bool {
        let bound = step * (1.0 + STEP_SLACK);
        let mut previous = machine.forward(&self.start, self.tool_length).tip;
        (1..=n).all(|i| {
            let tip = machine
                .forward(&self.eval(f64::from(i) / f64::from(n)), self.tool_length)
                .tip;
            let ok = (tip - previous).norm() <= bound;
            previous = tip;
            ok
        })
    }
}

/// Most interpolation steps one block is split into.
pub const MAX_STEPS: u32 = 1 << 20;

/// Relative slack on the `--step` bound, for rounding.
const STEP_SLACK: f64 = 1e-9;

/// One output row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Row {
    /// 1-based line of the block.
    pub line: u32,
    /// Position inside the block, 0 < s ≤ 1.
    pub s: f64,
    /// Interpolation kind.
    pub motion: Motion,
    /// Machine position (rollover axes not yet reduced modulo 360).
    pub joints: Joints,
    /// Tool tip in the part frame.
    pub tip: Vec3,
    /// Unit tool direction in the part frame.
    pub dir: Vec3,
    /// Programmed feed at the tip, mm/min; `None` for rapid moves.
    pub feed: Option<f64>,
}
