//! The estimated machining time: the segments of the run fed to the
//! velocity planner (`fiveaxis-planner`) as polylines of machine-axis
//! positions, with the path length the feed is measured along.

use fiveaxis_control::{Motion, Path, Segment, TipPath};
use fiveaxis_machine::{Joints, MAX_AXES, Machine, Vec3};
use fiveaxis_planner::{AxisLimits, Block, Feed, Options, Planner, Point};

/// Largest turn, degrees, of a rotary axis or of a circle between two
/// samples of a curved block: fine enough that the straight intervals
/// carry the curve's direction changes to the planner.
const SAMPLE_ANGLE: f64 = 10.0;

/// Most samples of one block.
const MAX_SAMPLES: usize = 36;

/// A tip path shorter than this, mm, counts as none: the block turns
/// rotary axes only, and its feed is in degrees per minute.
const NO_TIP_MOTION: f64 = 1e-9;

/// The planner of one run, with a buffer of samples reused block by block.
#[derive(Debug)]
pub struct TimePlan {
    /// `None` when the machine's dynamics cannot be planned (the planner
    /// refused them): the estimate is then the programmed time.
    planner: Option<Planner>,
    points: Vec<Point>,
    /// Samples worked out here, not ahead, so far.
    sampled: usize,
}

impl TimePlan {
    /// A plan starting where the run starts.
    pub fn new(machine: &Machine) -> Self {
        let limits: Vec<AxisLimits> = (0..machine.axis_count())
            .map(|i| {
                let d = machine.dynamics(i);
                AxisLimits {
                    max_velocity: d.max_velocity,
                    rapid: d.rapid,
                    max_acceleration: d.max_acceleration,
                    max_jerk: d.max_jerk,
                }
            })
            .collect();
        let start = machine.params.reference_1;
        let planner =
            Planner::new(&limits, Options::default(), &start[..machine.axis_count()]).ok();
        Self {
            planner,
            points: Vec::with_capacity(MAX_SAMPLES),
            sampled: 0,
        }
    }

    /// Adds a segment that moves; `inside` are its samples between the
    /// ends when worked out already ([`SamplesAhead`]).
    pub fn segment(
        &mut self,
        machine: &Machine,
        seg: &Segment,
        tips: &[Vec3; 2],
        inside: Option<&[(Joints, Vec3)]>,
    ) {
        let Some(planner) = self.planner.as_mut() else {
            return;
        };
        let feed = match (seg.motion, seg.feed) {
            (Motion::Rapid, _) | (_, None) => Feed::Rapid,
            (_, Some(f)) if f > 0.0 && f.is_finite() => Feed::PerMinute(f),
            _ => Feed::Rapid,
        };
        // Worked out ahead: as many as `samples` gives.
        let n = inside.map_or_else(|| samples(machine, seg), |s| s.len() + 1);
        let count = machine.axis_count().min(MAX_AXES);
        self.points.clear();
        // Tips first, then the lengths: a block whose tip stands (rotary
        // axes alone) gives lengths of 0, so that the planner measures the
        // composite axis distance (F in degrees per minute).
        let mut previous = tips[0];
        let mut tip_length = 0.0;
        for k in 1..=n {
            let (joints, tip) = if k == n {
                (seg.end, tips[1])
            } else if let Some(inside) = inside {
                inside[k - 1]
            } else {
                self.sampled += 1;
                sample(machine, seg, k, n)
            };
            let length = (tip - previous).norm();
            tip_length += length;
            previous = tip;
            self.points.push(Point::new(&joints[..count], length));
        }
        let tip_moves = tip_length > NO_TIP_MOTION
            || matches!(&seg.path, Path::Tcpc(t) if t.tip.length() > NO_TIP_MOTION);
        if !tip_moves {
            for point in &mut self.points {
                point.length = 0.0;
            }
        }
        let block = Block {
            feed,
            exact_stop: seg.exact_stop,
            points: &self.points,
        };
        if planner.push(&block).is_err() {
            // Input the planner cannot take (it says what): the estimate
            // falls back to the programmed time rather than a wrong one.
            self.planner = None;
        }
    }

    /// Samples between segment ends worked out by the plan itself (not
    /// ahead) so far.
    pub fn samples_in_order(&self) -> usize {
        self.sampled
    }

    /// Marks the end of the segments planned so far; the times of the
    /// marks the plan has committed past are appended to `times`. Nothing
    /// when the plan has fallen back to the programmed time.
    pub fn mark(&mut self, times: &mut Vec<f64>) {
        if let Some(planner) = self.planner.as_mut() {
            planner.mark();
            planner.take_mark_times(|t| times.push(t));
        }
    }

    /// The estimated time, seconds, never below the programmed time, and
    /// whether it is the planner's (not the programmed time it fell back
    /// to). The times of the marks not yet taken are appended to `times`.
    pub fn finish(self, programmed: f64, times: &mut Vec<f64>) -> (f64, bool) {
        match self.planner {
            Some(p) => {
                let planned = p.finish_marked(|t| times.push(t)).time;
                if planned >= programmed {
                    (planned, true)
                } else {
                    (programmed, false)
                }
            }
            None => (programmed, false),
        }
    }
}

/// Sample `k` of `n` of a segment: its machine position and tool tip at
/// `s = k/n`.
fn sample(machine: &Machine, seg: &Segment, k: usize, n: usize) -> (Joints, Vec3) {
    let joints = seg.eval(machine, k as f64 / n as f64);
    (joints, machine.forward(&joints, seg.tool_length).tip)
}

/// The samples between the ends of each segment of a batch, worked out
/// on the runner's thread ahead of the plan that takes the segments in
/// order: the TCPC interpolation and the forward kinematics of every
/// sample of a curved block are most of the plan's time there. The same
/// samples, to the last bit, as the plan works out itself.
#[derive(Debug, Default)]
pub struct SamplesAhead {
    /// Where each segment's samples start in `points`, and one past the
    /// last segment's.
    starts: Vec<usize>,
    points: Vec<(Joints, Vec3)>,
}

impl SamplesAhead {
    /// Works out the samples of the segments of `batch` that move.
    pub fn work_out(&mut self, machine: &Machine, batch: &[Segment]) {
        self.starts.clear();
        self.points.clear();
        for seg in batch {
            self.starts.push(self.points.len());
            if seg.moves() {
                let n = samples(machine, seg);
                self.points
                    .extend((1..n).map(|k| sample(machine, seg, k, n)));
            }
        }
        self.starts.push(self.points.len());
    }

    /// Nothing worked out (the plan samples the segments itself).
    pub fn clear(&mut self) {
        self.starts.clear();
        self.points.clear();
    }

    /// Whether no segment of the batch had samples between its ends.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The samples between the ends of segment `i` of the batch, when
    /// worked out.
    pub fn get(&self, i: usize) -> Option<&[(Joints, Vec3)]> {
        let (&from, &to) = (self.starts.get(i)?, self.starts.get(i + 1)?);
        self.points.get(from..to)
    }
}

/// How many samples a segment needs: one for a straight move in axis
/// space (a joint line), more for circles and for TCPC blocks whose axes
/// move on curves.
fn samples(machine: &Machine, seg: &Segment) -> usize {
    let rotary_span = || {
        (machine.linear.len()..machine.axis_count())
            .map(|i| (seg.end[i] - seg.start[i]).abs())
            .fold(0.0, f64::max)
    };
    let turns = |span_degrees: f64| (span_degrees / SAMPLE_ANGLE).ceil() as usize;
    let n = match &seg.path {
        Path::Joint => 1,
        Path::Via(_) => 2,
        Path::Arc(arc) => turns(arc.sweep.abs().to_degrees()),
        Path::Helix { circle, .. } => turns(sweep_degrees(circle)),
        Path::Tcpc(t) => turns(rotary_span()).max(turns(sweep_degrees(&t.tip))),
    };
    n.clamp(1, MAX_SAMPLES)
}

fn sweep_degrees(tip: &TipPath) -> f64 {
    match tip {
        TipPath::Line(_) => 0.0,
        TipPath::Arc { sweep, .. } => sweep.abs().to_degrees(),
    }
}
