//! Segments: one move of every machine axis, described completely, and the
//! rows sampled from it.
//!
//! A segment knows how every axis moves as a function of the block's shared
//! interpolation parameter `s` in [0, 1] ([`Segment::eval`]); every consumer
//! (the `run` writer, later verification, conversion and the backplot)
//! samples that one truth. The reported tool tip and direction of a row come
//! from forward kinematics of the sampled machine position, never from the
//! programmed values.

use fiveaxis_machine::{Joints, Machine, SetupError, Side, Vec3};

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
#[derive(Clone, Debug, PartialEq)]
// Segments live in reused buffers; boxing the large TCPC variant would
// allocate once per TCPC block instead.
#[allow(clippy::large_enum_variant)]
pub enum Path {
    /// Every axis linear in `s`.
    Joint,
    /// The two plane axes on a circle (or a spiral, when the radii differ
    /// within tolerance), every other axis linear in `s`.
    Arc(Arc),
    /// Straight through an intermediate machine position reached at
    /// s = 0.5 (G28 / G30 reference returns).
    Via(Joints),
    /// X, Y, Z on a circle (or helix) in space, plus `drift · s`; every
    /// other axis linear in `s` (arcs on a workpiece turned by a setup
    /// error).
    Helix {
        /// The circle of X, Y, Z.
        circle: TipPath,
        /// Change of the length offset over the block.
        drift: Vec3,
    },
    /// Tool centre point control: the tip follows `tip` relative to the
    /// workpiece while the rotary axes turn; the linear axes are whatever
    /// puts the tip there.
    Tcpc(TcpcPath),
}

/// The law of a TCPC block.
#[derive(Clone, Debug, PartialEq)]
pub struct TcpcPath {
    /// Where the tip goes, as a function of s.
    pub tip: TipPath,
    /// The tip path is given in the machine frame and the table turns
    /// under it (FANUC WKP = 1), on the ideal workpiece (the segment's
    /// setup error maps it onto the real one in the table frame);
    /// otherwise it is in the table frame, on the real workpiece.
    pub turning: bool,
    /// Tool posture control: the tool turns on the great circle between
    /// two directions. `None`: the rotary axes move linearly in s.
    /// Boxed: it is large, and only posture-controlled blocks have one.
    pub posture: Option<Box<Posture>>,
}

/// Knots of a posture-controlled block.
pub const POSTURE_KNOTS: usize = 16;

/// The law of a block under tool posture control.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Posture {
    /// Tool directions (table frame) at s = 0 and s = 1.
    pub ends: [Vec3; 2],
    /// The rotary angles, followed continuously along the circle, at
    /// increasing s from 0 to 1, spaced by equal shares of the rotary
    /// motion: they say which of the solutions of each direction the axes
    /// are on, and how they turn.
    /// Single precision is plenty for that and keeps segments small; the
    /// angles themselves come from the inverse kinematics.
    pub knots: [(f32, [f32; 2]); POSTURE_KNOTS + 1],
    /// Share of the block (from s = 0) in which the tool leaves the
    /// singular direction: the tool stays on `ends[0]` while the free
    /// rotary axis turns to the angle of the way out (the first two knots),
    /// so that every axis moves continuously. 0 when the block does not
    /// start at the singular direction.
    pub lead: f64,
    /// The rotary angles at s = 0 exactly (the first knot holds them in
    /// single precision): the block starts where the axes stand.
    pub start: [f64; 2],
}

impl Posture {
    /// The tool direction at `s`.
    pub fn direction(&self, s: f64) -> Vec3 {
        if s <= self.lead {
            return self.ends[0];
        }
        let t = ((s - self.lead) / (1.0 - self.lead)).clamp(0.0, 1.0);
        slerp(&self.ends[0], &self.ends[1], t)
    }

    /// The knot angles interpolated at `s`: within a quarter turn of the
    /// rotary angles there (the controller refuses blocks where they would
    /// stray further).
    pub fn guide(&self, s: f64) -> [f64; 2] {
        let k = self.knots[1..]
            .iter()
            .position(|(at, _)| s <= f64::from(*at))
            .unwrap_or(POSTURE_KNOTS - 1);
        let ((s0, a), (s1, b)) = (self.knots[k], self.knots[k + 1]);
        let (s0, s1) = (f64::from(s0), f64::from(s1));
        let t = if s1 > s0 {
            ((s - s0) / (s1 - s0)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let a = if k == 0 { self.start } else { a.map(f64::from) };
        [
            lerp(a[0], f64::from(b[0]), t),
            lerp(a[1], f64::from(b[1]), t),
        ]
    }
}

/// A tip path: a line or a circle (helix) in space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TipPath {
    /// From `0` to `1` along a straight line.
    Line([Vec3; 2]),
    /// A circle in the plane of `axes[0]`, `axes[1]` about `center`,
    /// rising along `axes[2]` by `rise` over the block.
    Arc {
        /// Centre at s = 0.
        center: Vec3,
        /// Unit first and second plane axis and normal.
        axes: [Vec3; 3],
        /// Radius at s = 0 and s = 1.
        radius: [f64; 2],
        /// Angle of the start point from the first axis, radians.
        theta0: f64,
        /// Signed sweep, radians (positive counter-clockwise about the normal).
        sweep: f64,
        /// Travel along the normal over the block.
        rise: f64,
    },
}

impl TipPath {
    /// The tip at `s`.
    pub fn at(&self, s: f64) -> Vec3 {
        match self {
            TipPath::Line([a, b]) => a + (b - a) * s,
            TipPath::Arc {
                center,
                axes,
                radius,
                theta0,
                sweep,
                rise,
            } => {
                let theta = theta0 + sweep * s;
                let r = lerp(radius[0], radius[1], s);
                center
                    + axes[0] * (r * theta.cos())
                    + axes[1] * (r * theta.sin())
                    + axes[2] * (rise * s)
            }
        }
    }

    /// A circle in the plane of coordinate axes `plane` (first, second,
    /// normal) about `center`, rising along the normal by `rise`.
    pub fn plane_arc(
        plane: [usize; 3],
        center: Vec3,
        radius: [f64; 2],
        theta0: f64,
        sweep: f64,
        rise: f64,
    ) -> TipPath {
        TipPath::Arc {
            center,
            axes: plane.map(unit),
            radius,
            theta0,
            sweep,
            rise,
        }
    }

    /// The same path moved by `offset`.
    pub fn shifted(&self, offset: &Vec3) -> TipPath {
        self.mapped(|p| p + offset, |v| *v)
    }

    /// The path carried by a rigid map: `point` for its points, `vector`
    /// (the map's rotation) for its directions. A circle stays a circle.
    pub fn mapped(&self, point: impl Fn(&Vec3) -> Vec3, vector: impl Fn(&Vec3) -> Vec3) -> TipPath {
        match *self {
            TipPath::Line([a, b]) => TipPath::Line([point(&a), point(&b)]),
            TipPath::Arc {
                center,
                axes,
                radius,
                theta0,
                sweep,
                rise,
            } => TipPath::Arc {
                center: point(&center),
                axes: axes.map(|a| vector(&a)),
                radius,
                theta0,
                sweep,
                rise,
            },
        }
    }

    /// Whether every number of the path is finite.
    pub fn is_finite(&self) -> bool {
        let all = all_finite;
        match self {
            TipPath::Line([a, b]) => all(a.as_slice()) && all(b.as_slice()),
            TipPath::Arc {
                center,
                axes,
                radius,
                theta0,
                sweep,
                rise,
            } => {
                all(center.as_slice())
                    && axes.iter().all(|a| all(a.as_slice()))
                    && all(radius)
                    && all(&[*theta0, *sweep, *rise])
            }
        }
    }

    /// The range the path covers along coordinate `i`.
    pub fn extent(&self, i: usize) -> (f64, f64) {
        match *self {
            TipPath::Line([a, b]) => (a[i].min(b[i]), a[i].max(b[i])),
            TipPath::Arc {
                center,
                axes,
                radius,
                theta0,
                sweep,
                rise,
            } => {
                let (a, b) = (self.at(0.0)[i], self.at(1.0)[i]);
                let (mut lo, mut hi) = (a.min(b), a.max(b));
                // The circle peaks along i where its tangent is across i.
                let peak = axes[1][i].atan2(axes[0][i]);
                let r = radius[0].max(radius[1]);
                let reach = r * axes[0][i].hypot(axes[1][i]);
                for (k, value) in [(0.0, 1.0), (std::f64::consts::PI, -1.0)] {
                    let mut t = peak + k;
                    // Bring t into the sweep's turn, if it is inside.
                    let (from, to) = if sweep >= 0.0 {
                        (theta0, theta0 + sweep)
                    } else {
                        (theta0 + sweep, theta0)
                    };
                    while t < from {
                        t += std::f64::consts::TAU;
                    }
                    while t - std::f64::consts::TAU >= from {
                        t -= std::f64::consts::TAU;
                    }
                    if t <= to {
                        let s = ((t - theta0) / sweep).clamp(0.0, 1.0);
                        let v = center[i] + value * reach + axes[2][i] * rise * s;
                        lo = lo.min(v - (radius[1] - radius[0]).abs());
                        hi = hi.max(v + (radius[1] - radius[0]).abs());
                    }
                }
                (lo, hi)
            }
        }
    }

    /// Length of the path.
    pub fn length(&self) -> f64 {
        match self {
            TipPath::Line([a, b]) => (b - a).norm(),
            TipPath::Arc {
                radius,
                sweep,
                rise,
                ..
            } => (0.5 * (radius[0] + radius[1]) * sweep.abs()).hypot(*rise),
        }
    }
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
#[derive(Clone, Debug, PartialEq)]
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
    /// The tool in the spindle (0: none; a program that never changes
    /// tools has the tool of its length offset number), whose shape the
    /// collision check and the stock model take from the offsets.
    pub tool: u32,
    /// Work offset: table-frame coordinates of the part frame's origin.
    pub work: Vec3,
    /// Workpiece setup error in force (G54.4): rows report the tip and
    /// direction in the frame of the programmed (ideal) workpiece.
    pub setup: SetupError,
    /// The control stops at the end of this segment (G61 exact stop mode,
    /// or a G09 block): speed only, the path is the same.
    pub exact_stop: bool,
    /// The block was fed in inverse time (G93): it lasts 1/F, and `feed`
    /// is its tip chord over that time.
    pub inverse_time: bool,
    /// The control chose the rotary axes of this block from a tool
    /// direction (TCPC with a tool vector or with tool posture control,
    /// the tilted working plane's axis choice, a setup-error correction of
    /// the tool direction): only then is passing near the singular
    /// direction the control's doing rather than the program's.
    pub rotary_chosen: bool,
    /// Rows the block is sampled into: 1 (its end row only) unless the run
    /// interpolates (`--step`), when the runner sets it from
    /// [`Segment::steps`].
    pub rows: u32,
}

fn lerp(a: f64, b: f64, s: f64) -> f64 {
    a + (b - a) * s
}

/// Share of a step by which a span may exceed a whole number of steps
/// and still take that many ([`Segment::steps`]): rounding, not motion.
const STEP_ROUNDING: f64 = 1e-9;

impl Segment {
    /// Machine position at `s` (0 ≤ s ≤ 1); exactly `end` at s = 1.
    pub fn eval(&self, machine: &Machine, s: f64) -> Joints {
        if s >= 1.0 {
            return self.end;
        }
        if let Path::Tcpc(tcpc) = &self.path {
            return self.eval_tcpc(machine, tcpc, s);
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
        if let Path::Helix { circle, drift } = &self.path {
            let xyz = circle.at(s) + drift * s;
            joints[..3].copy_from_slice(xyz.as_slice());
        }
        if let Path::Arc(arc) = &self.path {
            // Relative to the start point: the turn of the start radius by
            // the swept angle, plus the change of radius. Exact at s = 0,
            // and precise for radii far larger than the arc (a centre
            // 1e12 mm away would lose the arc in rounding if added back).
            let d = arc.sweep * s;
            let theta = arc.theta0 + d;
            let grow = lerp(arc.r0, arc.r1, s) - arc.r0;
            let (sin_d, cos_d_1) = (d.sin(), -2.0 * (0.5 * d).sin().powi(2));
            let (ux, uy) = (arc.r0 * arc.theta0.cos(), arc.r0 * arc.theta0.sin());
            let [p, q] = arc.axes;
            joints[p] =
                self.start[p] + arc.drift[0] * s + (cos_d_1 * ux - sin_d * uy) + grow * theta.cos();
            joints[q] =
                self.start[q] + arc.drift[1] * s + (sin_d * ux + cos_d_1 * uy) + grow * theta.sin();
        }
        joints
    }

    fn eval_tcpc(&self, machine: &Machine, tcpc: &TcpcPath, s: f64) -> Joints {
        let mut joints = self.start;
        for (j, (a, b)) in joints.iter_mut().zip(self.start.iter().zip(&self.end)) {
            *j = lerp(*a, *b, s);
        }
        if let Some(posture) = &tcpc.posture {
            let angles = posture_angles(machine, &posture.direction(s), posture.guide(s));
            joints[machine.rotary_index(0)] = angles[0];
            joints[machine.rotary_index(1)] = angles[1];
        }
        let tip = tcpc.tip.at(s);
        let tip_table = if tcpc.turning {
            // The ideal tip turned into the table frame, then onto the
            // real workpiece (G54.4 acts about the work zero).
            let ideal = machine
                .chain(Side::Table, &joints)
                .inverse_transform_point(&tip.into())
                .coords;
            self.work + self.setup.point(&(ideal - self.work))
        } else {
            tip
        };
        let gauge = machine.gauge_for_programmed_tip(&joints, &tip_table, self.tool_length);
        joints[..3].copy_from_slice(gauge.as_slice());
        joints
    }

    /// Whether every number of the segment is finite (checked before a
    /// segment is released: no row may hold a non-finite number).
    pub fn is_finite(&self) -> bool {
        let all = all_finite;
        let vec = |v: &Vec3| all(v.as_slice());
        let path = match &self.path {
            Path::Joint => true,
            Path::Arc(arc) => {
                all(&arc.center) && all(&arc.drift) && all(&[arc.r0, arc.r1, arc.theta0, arc.sweep])
            }
            Path::Via(mid) => all(mid),
            Path::Helix { circle, drift } => circle.is_finite() && vec(drift),
            Path::Tcpc(tcpc) => {
                tcpc.tip.is_finite()
                    && tcpc.posture.as_ref().is_none_or(|p| {
                        p.ends.iter().all(vec)
                            && p.knots
                                .iter()
                                .all(|(s, a)| s.is_finite() && a.iter().all(|x| x.is_finite()))
                    })
            }
        };
        all(&self.start)
            && all(&self.end)
            && path
            && self.tool_length.is_finite()
            && vec(&self.work)
            && self.feed.is_none_or(f64::is_finite)
    }

    /// Whether any axis moves.
    pub fn moves(&self) -> bool {
        self.start != self.end
            || match &self.path {
                Path::Arc(a) => a.sweep != 0.0,
                Path::Via(mid) => *mid != self.start,
                Path::Tcpc(t) => t.tip.length() > 0.0,
                Path::Helix { circle, .. } => circle.length() > 0.0,
                Path::Joint => false,
            }
    }

    /// The row at `s`: machine position and, by forward kinematics, the tip
    /// and tool direction in the part frame.
    pub fn row(&self, machine: &Machine, s: f64) -> Row {
        let joints = self.eval(machine, s);
        let pose = machine.forward(&joints, self.tool_length);
        Row {
            line: self.line,
            s,
            motion: self.motion,
            joints,
            tip: self.setup.inverse_point(&(pose.tip - self.work)),
            dir: self.setup.inverse_vector(&pose.dir),
            feed: self.feed,
        }
    }

    /// The positions `s` of the block's rows, in order: with
    /// interpolation (`rows` > 1) the ones inside it, `i / rows`, then
    /// always its end, exactly 1.
    pub fn row_fractions(&self) -> impl Iterator<Item = f64> + use<> {
        let n = self.rows.max(1);
        (1..=n).map(move |i| {
            if i == n {
                1.0
            } else {
                f64::from(i) / f64::from(n)
            }
        })
    }

    /// How many equal steps in `s` keep consecutive tips at most `step` mm
    /// apart and every rotary axis within `step_angle` degrees per step.
    ///
    /// The tip path of a move with rotary axes is not straight, so the
    /// count from the straight-line estimate is doubled until every step
    /// obeys the bound. `None` when even [`MAX_STEPS`] steps do not: the
    /// axes move too fast for the bound somewhere in the block (a rotary
    /// axis swinging near the singular direction, or a bound far too fine
    /// for the block's length); the run then stops with an alarm rather
    /// than break the bound.
    pub fn steps(&self, machine: &Machine, step: f64, step_angle: f64) -> Option<u32> {
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
            Path::Tcpc(tcpc) => tcpc.tip.length(),
            Path::Helix { circle, .. } => circle.length(),
        };
        let count = |span: f64, limit: f64| {
            if limit > 0.0 && span.is_finite() {
                // A span of a whole number of steps, up to rounding, takes
                // that many (not one more for a last step of 1e-14 mm).
                (span / limit - STEP_ROUNDING).ceil()
            } else {
                1.0
            }
        };
        let estimate = count(chord, step)
            .max(count(rotary_span, step_angle))
            .max(1.0);
        if estimate > f64::from(MAX_STEPS) {
            return None;
        }
        let mut n = estimate as u32;
        while !self.steps_within(machine, n, step, step_angle) {
            if n >= MAX_STEPS {
                return None;
            }
            n = (n * 2).min(MAX_STEPS);
        }
        Some(n)
    }

    fn steps_within(&self, machine: &Machine, n: u32, step: f64, step_angle: f64) -> bool {
        let bound = step * (1.0 + STEP_SLACK);
        let turn_bound = step_angle * (1.0 + STEP_SLACK);
        let rotary = machine.linear.len()..machine.axis_count();
        // From where the block's law starts (a posture-controlled block
        // leaving the singular direction turns its free axis at once).
        let first = self.eval(machine, 0.0);
        let mut previous = (first, machine.forward(&first, self.tool_length).tip);
        (1..=n).all(|i| {
            let joints = self.eval(machine, f64::from(i) / f64::from(n));
            let tip = machine.forward(&joints, self.tool_length).tip;
            let ok = (tip - previous.1).norm() <= bound
                && rotary
                    .clone()
                    .all(|k| (joints[k] - previous.0[k]).abs() <= turn_bound);
            previous = (joints, tip);
            ok
        })
    }
}

/// The unit vector a fraction `s` of the way from `a` to `b` along the
/// great circle through them (the shorter arc).
pub fn slerp(a: &Vec3, b: &Vec3, s: f64) -> Vec3 {
    let angle = a.cross(b).norm().atan2(a.dot(b));
    if angle < 1e-12 {
        return (a + (b - a) * s).normalize();
    }
    let sin = angle.sin();
    if sin < 1e-12 {
        // Opposite directions: no unique great circle; turn through the
        // lerp, which the caller never asks for (TCPC refuses it).
        return (a + (b - a) * s).normalize();
    }
    (a * ((1.0 - s) * angle).sin() + b * (s * angle).sin()) / sin
}

/// The rotary angles for tool direction `dir` nearest to `guide`, each
/// axis unwrapped to within half a turn of it; `guide` itself when `dir`
/// cannot be reached.
pub fn posture_angles(machine: &Machine, dir: &Vec3, guide: [f64; 2]) -> [f64; 2] {
    let found = machine.orientations(dir, guide);
    let near = |pair: &[f64; 2]| {
        let a = guide[0] + fiveaxis_machine::principal(pair[0] - guide[0]);
        let b = guide[1] + fiveaxis_machine::principal(pair[1] - guide[1]);
        ((a - guide[0]).abs() + (b - guide[1]).abs(), [a, b])
    };
    found
        .pairs()
        .iter()
        .map(near)
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .map_or(guide, |(_, angles)| angles)
}

/// Most interpolation steps one block is split into (rows per block).
pub const MAX_STEPS: u32 = 1 << 20;

/// Relative slack on the `--step` bound, for rounding.
const STEP_SLACK: f64 = 1e-9;

/// The unit vector along coordinate axis `i` (0 = X, 1 = Y, 2 = Z).
pub fn unit(i: usize) -> Vec3 {
    let mut v = Vec3::zeros();
    v[i] = 1.0;
    v
}

/// Whether every number of `v` is finite: x·0 is 0 for a finite x and
/// NaN otherwise, so one sum tells, without a branch per number (every
/// segment's numbers are looked at before it leaves the runner).
fn all_finite(v: &[f64]) -> bool {
    v.iter().fold(0.0, |sum, x| sum + x * 0.0) == 0.0
}

/// A machine position as the control displays it: rollover axes reduced
/// to [0, 360) (exactly when already in range), every other axis as it is.
/// Entries past [`Machine::axis_count`] are 0.
pub fn displayed(machine: &Machine, joints: &Joints) -> Joints {
    let mut shown = [0.0; fiveaxis_machine::MAX_AXES];
    let n = machine.axis_count();
    shown[..n].copy_from_slice(&joints[..n]);
    for (k, axis) in machine.rotary.iter().enumerate() {
        if axis.rollover {
            let i = machine.rotary_index(k);
            shown[i] = crate::normalize_360(shown[i]);
        }
    }
    shown
}

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
