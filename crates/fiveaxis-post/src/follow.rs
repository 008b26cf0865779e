//! The post's own rotary solution: the machine axes of a target machine
//! that follow a source block's tool path (tip and direction in the part
//! frame), chosen by the post rather than taken from the source's axes.
//!
//! * **Continuity**: the rotary angles are tracked along the block at
//!   knots no more than [`KNOT_TURN`] of tool turn apart, each knot taking
//!   the solution nearest the previous one (each axis unwrapped to within
//!   half a turn of it), so the axes never change branch inside a block.
//! * **Singular passages**: where the programmed direction comes within
//!   the machine's `singular_cone` of the singular line (the line of the
//!   rotating axis, where its angle is free), the rotating axis moves
//!   linearly in `s` from its angle where the tool entered the cone to the
//!   angle of the exit solution nearest it (held, when the block ends in
//!   the cone), and the tilt axis takes the angle that brings the tool
//!   nearest the programmed direction. What is guaranteed there: the tool
//!   tip exactly on the path (the linear axes follow), and the direction
//!   within the angle between the programmed direction and the singular
//!   line, so within the cone (the directions reachable with the rotating
//!   axis held form a circle through the singular line); on the knot
//!   interval where the tool crosses into or out of the cone the bound is
//!   the cone widened by one knot ([`KNOT_TURN`]).
//! * **Limits**: [`Law::within_limits`] says whether the tracked angles
//!   stay inside the soft limits of every limited axis;
//!   [`start_candidates`] lists the other solutions of the block's start
//!   direction (the other branch, 360° repeats) from which the block can
//!   be tracked instead: the converter turns to one of them with the tool
//!   clear (a flip).

use fiveaxis_control::{Path, Segment, posture_angles, slerp};
use fiveaxis_machine::{Joints, MAX_AXES, Machine, Side, Vec3, principal};

/// Largest turn of the programmed tool direction between knots, degrees.
pub const KNOT_TURN: f64 = 0.5;
/// Fewest knots of one block.
pub const MIN_KNOTS: usize = 2;
/// Most knots of one block.
pub const MAX_KNOTS: usize = 8192;
/// Samples of a block's direction path that estimate its turn.
const TURN_SAMPLES: u32 = 16;
/// Slack on the soft limits, degrees (rounding).
pub const LIMIT_SLACK: f64 = 1e-6;

/// The rotating axis of a two-rotary machine (rotary file order): the one
/// whose angle is free when the tool lies on its line (the outer head axis
/// of a head-head machine, the inner table axis of a table-table one, the
/// table axis of a mixed one; the rule of `fiveaxis-check`'s singular
/// passage).
pub fn rotating_axis(machine: &Machine) -> usize {
    match (machine.rotary[0].on, machine.rotary[1].on) {
        (Side::Head, Side::Head) | (Side::Table, Side::Head) => 0,
        (Side::Table, Side::Table) | (Side::Head, Side::Table) => 1,
    }
}

/// Angle in degrees between a direction (table frame) and the singular
/// line of a two-rotary machine.
pub fn singular_angle(machine: &Machine, dir: &Vec3) -> f64 {
    let line = machine.rotary[rotating_axis(machine)].axis.into_inner();
    line.cross(dir)
        .norm()
        .atan2(line.dot(dir).abs())
        .to_degrees()
}

/// Where the tool path of a source block comes from.
#[derive(Clone, Copy, Debug)]
pub struct Source<'a> {
    /// The machine the source block was run on.
    pub machine: &'a Machine,
    /// The block.
    pub seg: &'a Segment,
    /// Between the block's end directions the tool turns on the great
    /// circle (programmed tool vectors: APT / CL data), not as the source's
    /// axes turn. Only for TCPC blocks.
    pub great_circle: bool,
    /// The tool length of the tip (the block's own, or the one a
    /// machine-axis source was written for).
    pub tool_length: f64,
}

impl Source<'_> {
    /// Tool tip and direction in the part frame at `s`.
    pub fn pose(&self, s: f64) -> (Vec3, Vec3) {
        let (tip, dir) = self.row(s);
        match self.ends() {
            Some([a, b]) => (tip, slerp(&a, &b, s)),
            None => (tip, dir),
        }
    }

    /// Tip (of [`Source::tool_length`]) and direction of the source's
    /// axes at `s`, part frame (as `Segment::row`).
    fn row(&self, s: f64) -> (Vec3, Vec3) {
        let seg = self.seg;
        let pose = self
            .machine
            .forward(&seg.eval(self.machine, s), self.tool_length);
        (
            seg.setup.inverse_point(&(pose.tip - seg.work)),
            seg.setup.inverse_vector(&pose.dir),
        )
    }

    /// The end directions when the tool turns on the great circle.
    fn ends(&self) -> Option<[Vec3; 2]> {
        match (&self.seg.path, self.great_circle) {
            (Path::Tcpc(_), true) => Some([self.row(0.0).1, self.row(1.0).1]),
            _ => None,
        }
    }
}

/// A stretch of a block where the rotating axis moves linearly in `s`
/// (a singular passage).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Passage {
    s: [f64; 2],
    rotating: [f64; 2],
}

/// The target machine's axes along one source block.
#[derive(Clone, Debug)]
pub struct Law<'a> {
    source: Source<'a>,
    target: &'a Machine,
    /// Table-frame coordinates of the part zero on the target.
    origin: Vec3,
    tool_length: f64,
    rotating: usize,
    knots: Vec<(f64, [f64; 2])>,
    passages: Vec<Passage>,
    /// The end directions of a great-circle block.
    ends: Option<[Vec3; 2]>,
}

impl<'a> Law<'a> {
    /// The law of `source` on `target`, the rotary axes starting at
    /// `start` (where they stand; its direction must be the block's start
    /// direction) and tracked from there.
    pub fn new(source: Source<'a>, target: &'a Machine, origin: Vec3, start: [f64; 2]) -> Self {
        Self::with_exit(source, target, origin, start, 0)
    }

    /// [`Law::new`], leaving each singular passage by the exit solution
    /// of rank `exit` (0: the one whose rotating axis is nearest its
    /// entry angle; 1: the other branch, for a block whose first choice
    /// leaves the soft limits).
    pub fn with_exit(
        source: Source<'a>,
        target: &'a Machine,
        origin: Vec3,
        start: [f64; 2],
        exit: usize,
    ) -> Self {
        let mut law = Self {
            source,
            target,
            origin,
            tool_length: source.tool_length,
            rotating: rotating_axis(target),
            knots: Vec::new(),
            passages: Vec::new(),
            ends: source.ends(),
        };
        law.track(start, exit);
        law
    }

    /// Programmed tip (target table frame) and direction at `s`.
    pub fn reference(&self, s: f64) -> (Vec3, Vec3) {
        let (tip, dir) = self.source.row(s);
        let dir = match &self.ends {
            Some([a, b]) => slerp(a, b, s),
            None => dir,
        };
        (tip + self.origin, dir)
    }

    /// The programmed direction at `s` (for a great-circle block without
    /// running the source's law).
    fn direction(&self, s: f64) -> Vec3 {
        match &self.ends {
            Some([a, b]) => slerp(a, b, s),
            None => self.source.row(s).1,
        }
    }

    fn track(&mut self, start: [f64; 2], exit_rank: usize) {
        let machine = self.target;
        let cone = machine.params.singular_cone;
        let turn = match &self.ends {
            // On the great circle: the angle between the ends.
            Some([a, b]) => angle(a, b),
            None => {
                let mut turn = 0.0;
                let mut last = self.direction(0.0);
                for k in 1..=TURN_SAMPLES {
                    let d = self.direction(f64::from(k) / f64::from(TURN_SAMPLES));
                    turn += angle(&last, &d);
                    last = d;
                }
                turn
            }
        };
        let n = ((turn / KNOT_TURN).ceil() as usize).clamp(MIN_KNOTS, MAX_KNOTS);
        let (rot, tilt) = (self.rotating, 1 - self.rotating);
        self.knots.push((0.0, start));
        // Knot index where the current singular passage was entered.
        let mut entered = (singular_angle(machine, &self.direction(0.0)) < cone).then_some(0);
        for k in 1..=n {
            let s = k as f64 / n as f64;
            let d = self.direction(s);
            let previous = self.knots[k - 1].1;
            if singular_angle(machine, &d) < cone {
                entered.get_or_insert(k - 1);
                self.knots.push((s, previous));
                continue;
            }
            let q = match entered.take() {
                Some(a) => {
                    let held = self.knots[a].1;
                    let exit = exit_solution(machine, &d, held, rot, exit_rank);
                    let passage = Passage {
                        s: [self.knots[a].0, s],
                        rotating: [held[rot], exit[rot]],
                    };
                    self.fill(a, k, &passage, tilt);
                    self.passages.push(passage);
                    exit
                }
                None => posture_angles(machine, &d, previous),
            };
            self.knots.push((s, q));
        }
        if let Some(a) = entered {
            let held = self.knots[a].1[rot];
            let passage = Passage {
                s: [self.knots[a].0, 1.0],
                rotating: [held, held],
            };
            self.fill(a, n + 1, &passage, tilt);
            self.passages.push(passage);
        }
    }

    /// Sets the knots strictly between `a` and `b` on a passage.
    fn fill(&mut self, a: usize, b: usize, passage: &Passage, tilt: usize) {
        for k in a + 1..b {
            let s = self.knots[k].0;
            let guide = self.knots[k - 1].1[tilt];
            let q = self.passage_angles(passage, s, guide);
            self.knots[k].1 = q;
        }
    }

    fn passage_angles(&self, passage: &Passage, s: f64, tilt_guide: f64) -> [f64; 2] {
        let t = (s - passage.s[0]) / (passage.s[1] - passage.s[0]);
        let rho = passage.rotating[0] + (passage.rotating[1] - passage.rotating[0]) * t;
        let dir = self.direction(s);
        let mut q = [0.0; 2];
        q[self.rotating] = rho;
        q[1 - self.rotating] = best_tilt(self.target, self.rotating, rho, &dir, tilt_guide);
        q
    }

    /// The rotary angles at `s`.
    pub fn angles(&self, s: f64) -> [f64; 2] {
        self.angles_for(s, &self.direction(s))
    }

    /// The rotary angles at `s`, where the programmed direction is `dir`.
    fn angles_for(&self, s: f64, dir: &Vec3) -> [f64; 2] {
        let n = self.knots.len() - 1;
        if s <= 0.0 {
            return self.knots[0].1;
        }
        if s >= 1.0 {
            return self.knots[n].1;
        }
        let k = ((s * n as f64).floor() as usize).min(n - 1);
        let ((s0, a), (s1, b)) = (self.knots[k], self.knots[k + 1]);
        let t = ((s - s0) / (s1 - s0)).clamp(0.0, 1.0);
        let guide = [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t];
        if let Some(p) = self.passages.iter().find(|p| s > p.s[0] && s < p.s[1]) {
            return self.passage_angles(p, s, guide[1 - self.rotating]);
        }
        posture_angles(self.target, dir, guide)
    }

    /// The target machine's axes at `s`: the rotary angles, and the linear
    /// axes that put the tip on the programmed point.
    pub fn joints(&self, s: f64) -> Joints {
        let (tip, dir) = self.reference(s);
        let q = self.angles_for(s, &dir);
        let mut j = [0.0; MAX_AXES];
        j[self.target.rotary_index(0)] = q[0];
        j[self.target.rotary_index(1)] = q[1];
        let gauge = self.target.gauge_for_tip(&j, &tip, self.tool_length);
        j[..3].copy_from_slice(gauge.as_slice());
        j
    }

    /// The angles at the block's end.
    pub fn end_angles(&self) -> [f64; 2] {
        self.knots[self.knots.len() - 1].1
    }

    /// The tool length the law is for.
    pub fn tool_length(&self) -> f64 {
        self.tool_length
    }

    /// Whether the tracked angles keep every limited rotary axis inside its
    /// soft limits (at the knots).
    pub fn within_limits(&self) -> bool {
        self.knots
            .iter()
            .all(|(_, q)| angles_within_limits(self.target, q))
    }

    /// Largest angle between the law's tool direction (forward kinematics)
    /// and the programmed one at the knots and between them, degrees: the
    /// price of the singular passages (and of unreachable directions).
    pub fn direction_error(&self) -> f64 {
        let n = self.knots.len() - 1;
        (0..=2 * n)
            .map(|k| {
                let s = k as f64 / (2 * n) as f64;
                let got = self.target.forward(&self.joints(s), self.tool_length).dir;
                angle(&got, &self.reference(s).1)
            })
            .fold(0.0, f64::max)
    }

    /// Whether the block passes within the singular cone.
    pub fn has_passage(&self) -> bool {
        !self.passages.is_empty()
    }
}

/// Whether `q` (rotary file order) is inside the soft limits of every
/// limited, non-rollover rotary axis.
pub fn angles_within_limits(machine: &Machine, q: &[f64; 2]) -> bool {
    machine
        .rotary
        .iter()
        .zip(q)
        .all(|(axis, a)| match axis.limits {
            Some((min, max)) if !axis.rollover => {
                *a >= min - LIMIT_SLACK && *a <= max + LIMIT_SLACK
            }
            _ => true,
        })
}

/// The solutions of `dir` on `machine` (each pair with every 360° repeat
/// of a limited axis inside its limits, an unlimited axis unwrapped near
/// `near`), nearest `near` first (sum of the axes' motions).
pub fn start_candidates(machine: &Machine, dir: &Vec3, near: [f64; 2]) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::new();
    let repeats = |k: usize, a: f64| -> Vec<f64> {
        let axis = &machine.rotary[k];
        match axis.limits {
            Some((min, max)) if !axis.rollover => {
                let first = a - 360.0 * ((a - min) / 360.0).floor();
                (0..4)
                    .map(|t| first + 360.0 * f64::from(t))
                    .filter(|v| *v <= max + LIMIT_SLACK && *v >= min - LIMIT_SLACK)
                    .collect()
            }
            _ => vec![near[k] + principal(a - near[k])],
        }
    };
    for pair in machine.orientations(dir, near).pairs() {
        for a in repeats(0, pair[0]) {
            for b in repeats(1, pair[1]) {
                out.push([a, b]);
            }
        }
    }
    let cost = |q: &[f64; 2]| (q[0] - near[0]).abs() + (q[1] - near[1]).abs();
    out.sort_by(|x, y| cost(x).total_cmp(&cost(y)));
    out
}

/// The solutions of `dir`, each axis unwrapped near `held`, ranked by the
/// motion of the rotating axis from `held`'s (then the tilt axis'): the
/// one of rank `rank` (the last when there are fewer).
fn exit_solution(
    machine: &Machine,
    dir: &Vec3,
    held: [f64; 2],
    rot: usize,
    rank: usize,
) -> [f64; 2] {
    let found = machine.orientations(dir, held);
    let mut ranked: Vec<((f64, f64), [f64; 2])> = found
        .pairs()
        .iter()
        .map(|p| {
            let q = [
                held[0] + principal(p[0] - held[0]),
                held[1] + principal(p[1] - held[1]),
            ];
            let key = (
                (q[rot] - held[rot]).abs(),
                (q[1 - rot] - held[1 - rot]).abs(),
            );
            (key, q)
        })
        .collect();
    ranked.sort_by(|x, y| x.0.partial_cmp(&y.0).unwrap_or(std::cmp::Ordering::Equal));
    ranked
        .get(rank.min(ranked.len().saturating_sub(1)))
        .map_or(held, |(_, q)| *q)
}

/// The tilt angle (degrees, unwrapped near `guide`) that brings the tool
/// nearest `dir` with the rotating axis at `rho`: the tool's component
/// along `dir` is `a + b·cos θ + c·sin θ` in the tilt angle θ (Rodrigues),
/// largest at θ = atan2(c, b).
pub fn best_tilt(machine: &Machine, rotating: usize, rho: f64, dir: &Vec3, guide: f64) -> f64 {
    let mut j = [0.0; MAX_AXES];
    j[machine.rotary_index(rotating)] = rho;
    let tilt = machine.rotary_index(1 - rotating);
    let mut along = |theta: f64| {
        j[tilt] = theta;
        machine.forward(&j, 0.0).dir.dot(dir)
    };
    let (f0, f90, f180) = (along(0.0), along(90.0), along(180.0));
    let b = 0.5 * (f0 - f180);
    let c = f90 - 0.5 * (f0 + f180);
    let theta = c.atan2(b).to_degrees();
    guide + principal(theta - guide)
}

/// Angle between two unit vectors, degrees.
pub fn angle(u: &Vec3, v: &Vec3) -> f64 {
    u.cross(v).norm().atan2(u.dot(v)).to_degrees()
}
