//! `fiveaxis check`: what a program does on a machine, as a verdict.
//!
//! A [`Checker`] is fed the segments a run produces (the `Runner` of
//! `fiveaxis-control`, run with the soft limits lifted) and gives a
//! [`Report`]: the axis ranges against their soft limits, the programmed
//! machining time, and the findings of the `check` contract
//! (`overtravel`, `alarm`, `singular_passage`, `rotary_flip`,
//! `feed_limited`, `chord_error`), and the project's own
//! `no_decimal_point` ([`check_run`] only). Pure: no I/O, the report is
//! data.
//!
//! How each finding is found (exactly, not by coarse sampling):
//!
//! * positions over a block ([`extent`]): closed forms for joint moves,
//!   circles and reference returns; for TCPC blocks and anything whose
//!   law is not a circle, bound and refine ([`bound`]) on a proven bound
//!   of the second derivative. Tool posture control, whose rotary angles
//!   come from inverse kinematics, is sampled every
//!   [`POSTURE_SAMPLE_ANGLE`] of rotary motion and refined (not a proof);
//! * singular passages ([`singular`]): closed form;
//! * chord error: bound and refine on the tool tip's law;
//! * feed limits: closed forms for machine-axis moves; for TCPC blocks the
//!   derivative bound decides, and a block it cannot clear is sampled.

pub mod bound;
pub mod collision;
mod extent;
mod law;
pub mod message;
mod motion;
pub mod singular;
pub mod stock;
mod time;

use fiveaxis_control::{Motion, Path, RunError, Runner, Segment, Source};
use fiveaxis_machine::{Joints, MAX_AXES, Machine, Vec3};
use std::sync::atomic::{AtomicBool, Ordering::Relaxed};

pub use extent::axis_max;
pub use message::{Message, Word};
pub use motion::{block_minutes, tip_feed_allowed};

/// How serious a finding is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Severity {
    /// Worth knowing.
    Info,
    /// The program runs, but not as written (slower, marked, risky).
    Warning,
    /// The program does not run on this machine.
    Error,
}

impl Severity {
    /// The contract's name.
    pub fn name(self) -> &'static str {
        match self {
            Severity::Info => "info",
            Severity::Warning => "warning",
            Severity::Error => "error",
        }
    }
}

/// The kinds of findings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Kind {
    /// An axis beyond a soft limit.
    Overtravel,
    /// The program stopped with an alarm.
    Alarm,
    /// The tool direction passes near the singular direction.
    SingularPassage,
    /// A rotary axis turns more than `flip_angle` in one block.
    RotaryFlip,
    /// An axis cannot follow the programmed feed.
    FeedLimited,
    /// The tip leaves the straight line between block ends (outside TCPC).
    ChordError,
    /// Axis words without a decimal point read in least input increments
    /// (decimal point input off): one finding for the program, at the
    /// first such word, with their count.
    NoDecimalPoint,
    /// Two parts that must not touch overlap during a move (a machine
    /// body, the holder, shank or tool against the table's side or a
    /// fixture).
    Collision,
    /// Two such parts pass nearer than the clearance without touching.
    NearMiss,
    /// A rapid move takes the tool into the stock.
    RapidIntoStock,
    /// The tool cuts into the designed part beyond the tolerance.
    Gouge,
    /// Material is left on the designed part beyond the tolerance.
    Excess,
}

impl Kind {
    /// Every kind: the index of each ([`Kind::index`]) is its place here,
    /// kept as kinds are added (a page of `view` holds findings by it).
    /// Reports group them by severity, then in this order.
    pub const ALL: [Kind; 12] = [
        Kind::Alarm,
        Kind::Overtravel,
        Kind::SingularPassage,
        Kind::RotaryFlip,
        Kind::FeedLimited,
        Kind::ChordError,
        Kind::NoDecimalPoint,
        Kind::Collision,
        Kind::NearMiss,
        Kind::RapidIntoStock,
        Kind::Gouge,
        Kind::Excess,
    ];

    /// The position of this kind in [`Kind::ALL`] (and in
    /// [`Report::counts`]).
    pub fn index(self) -> usize {
        match self {
            Kind::Alarm => 0,
            Kind::Overtravel => 1,
            Kind::SingularPassage => 2,
            Kind::RotaryFlip => 3,
            Kind::FeedLimited => 4,
            Kind::ChordError => 5,
            Kind::NoDecimalPoint => 6,
            Kind::Collision => 7,
            Kind::NearMiss => 8,
            Kind::RapidIntoStock => 9,
            Kind::Gouge => 10,
            Kind::Excess => 11,
        }
    }

    /// The contract's name.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Overtravel => "overtravel",
            Kind::Alarm => "alarm",
            Kind::SingularPassage => "singular_passage",
            Kind::RotaryFlip => "rotary_flip",
            Kind::FeedLimited => "feed_limited",
            Kind::ChordError => "chord_error",
            Kind::NoDecimalPoint => "no_decimal_point",
            Kind::Collision => "collision",
            Kind::NearMiss => "near_miss",
            Kind::RapidIntoStock => "rapid_into_stock",
            Kind::Gouge => "gouge",
            Kind::Excess => "excess",
        }
    }

    /// The contract's severity of this kind.
    pub fn severity(self) -> Severity {
        match self {
            Kind::Overtravel
            | Kind::Alarm
            | Kind::Collision
            | Kind::RapidIntoStock
            | Kind::Gouge => Severity::Error,
            Kind::NoDecimalPoint => Severity::Info,
            _ => Severity::Warning,
        }
    }
}

/// One finding.
#[derive(Clone, Debug, PartialEq)]
pub struct Finding {
    /// What was found.
    pub kind: Kind,
    /// 1-based program line of the block (the first of a run of blocks).
    pub line: u32,
    /// In words.
    pub message: Message,
    /// The axis it is about, when there is one.
    pub axis: Option<char>,
    /// The measure of the finding (see the contract), when there is one.
    pub value: Option<f64>,
    /// The two parts of a collision or near miss.
    pub bodies: Option<Box<[String; 2]>>,
    /// Where it happened, in the table frame (the frame of the link the
    /// work rides on, every axis at 0: where the view draws the path),
    /// when the finding has a place apart from its block's path: a
    /// contact point, a gouge, material left on the part.
    pub point: Option<[f64; 3]>,
    /// Position in the run, for program order.
    order: u64,
}

impl Finding {
    /// The severity of its kind.
    pub fn severity(&self) -> Severity {
        self.kind.severity()
    }
}

/// The alarm that stopped a program.
#[derive(Clone, Debug, PartialEq)]
pub struct AlarmInfo {
    /// The number the control shows.
    pub code: String,
    /// 1-based line.
    pub line: u32,
    /// In words.
    pub message: String,
}

/// The range one axis covered, and its soft limits.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisRange {
    /// Address letter.
    pub name: char,
    /// Lowest position reached.
    pub min: f64,
    /// Highest position reached.
    pub max: f64,
    /// Soft limits; `None` for a rollover axis or an axis without limits.
    pub limits: Option<(f64, f64)>,
}

/// Machining time, seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Time {
    /// Path length over feed for cutting moves, rapids at the rapid rates.
    pub programmed: f64,
    /// What the control would take: the velocity planner over the machine
    /// axes (`fiveaxis-planner`, fed in `time.rs`), at least `programmed`.
    pub estimated: f64,
}

/// Which of the report's times the [`SegmentTimes`] follow.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimeKind {
    /// The velocity planner's: `time.estimated` is its total.
    Estimated,
    /// The programmed time: the planner fell back to it or gave less, so
    /// that `time.estimated` is `time.programmed`.
    Programmed,
}

/// When each segment of the run ends in the report's estimated time, for
/// a timeline ([`Checker::keep_segment_times`]).
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentTimes {
    /// Whether the times are the planner's or the programmed ones.
    pub kind: TimeKind,
    /// Seconds from the start at which each segment given to
    /// [`Checker::segment`] ends, in order (a segment that moves nothing
    /// ends where the one before it does); the last is `time.estimated`
    /// (to rounding).
    pub ends: Vec<f64>,
}

/// Segment end times being gathered.
#[derive(Debug, Default)]
struct Timeline {
    /// Each segment's programmed end (not kept when streamed).
    programmed: Vec<f64>,
    /// The estimated ends the plan has committed past (not yet taken,
    /// when streamed).
    estimated: Vec<f64>,
    /// Handed over as they come ([`Checker::stream_segment_times`]).
    streamed: bool,
}

/// How a run ended, as the caller saw it.
#[derive(Clone, Debug, PartialEq)]
pub struct Ending {
    /// The program reached its end.
    pub ended: bool,
    /// The alarm that stopped it.
    pub alarm: Option<AlarmInfo>,
    /// Blocks executed.
    pub blocks: u64,
}

/// The result of checking one program.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// The machine's name.
    pub machine: String,
    /// The program ran to its end.
    pub ended: bool,
    /// The alarm that stopped it.
    pub alarm: Option<AlarmInfo>,
    /// Blocks executed.
    pub blocks: u64,
    /// Machining time.
    pub time: Time,
    /// Every axis, in machine order.
    pub axes: Vec<AxisRange>,
    /// Findings in program order: every one from [`check_run`], none from
    /// [`check_run_into`] (which hands them over as they settle).
    pub findings: Vec<Finding>,
    /// How many findings of each kind the run had, by [`Kind::index`]
    /// (whether the report holds them or they were handed over).
    pub counts: [usize; Kind::ALL.len()],
    /// The time the feed-limited blocks lose, seconds: their cutting time
    /// at the tip feed the axes allow less that at the programmed feed (not
    /// part of `time.programmed`, which is the program's own figure).
    pub feed_limited_seconds: f64,
    /// What the stock model saw, when there was one.
    pub stock: Option<stock::StockSummary>,
}

impl Report {
    /// Whether any finding is at or above `severity`.
    pub fn fails(&self, severity: Severity) -> bool {
        Kind::ALL
            .iter()
            .any(|k| k.severity() >= severity && self.count(*k) > 0)
    }

    /// How many findings of a kind.
    pub fn count(&self, kind: Kind) -> usize {
        self.counts[kind.index()]
    }

    /// How many findings of a severity.
    pub fn count_severity(&self, severity: Severity) -> usize {
        Kind::ALL
            .iter()
            .filter(|k| k.severity() == severity)
            .map(|k| self.count(*k))
            .sum()
    }

    /// How many findings in all.
    pub fn total(&self) -> usize {
        self.counts.iter().sum()
    }
}

/// Rotary motion between two samples of a posture-controlled block,
/// degrees (as the controller's soft-limit check samples them).
pub const POSTURE_SAMPLE_ANGLE: f64 = 0.5;

/// How far past a soft limit rounding may carry a position before it
/// counts as an over-travel, mm or degrees (the controller's tolerance).
pub const LIMIT_TOLERANCE: f64 = 1e-9;

/// An over-travel run in progress: consecutive segments beyond one limit.
#[derive(Clone, Copy, Debug)]
struct Run {
    line: u32,
    order: u64,
    farthest: f64,
}

/// Checks the segments of one run.
#[derive(Debug)]
pub struct Checker<'m> {
    machine: &'m Machine,
    singular: Option<singular::Singular>,
    /// Lowest and highest position of each axis so far.
    range: [(f64, f64); MAX_AXES],
    /// Soft limits by joint index.
    limits: [Option<(f64, f64)>; MAX_AXES],
    /// Over-travel runs in progress, below and above the limits.
    runs: [[Option<Run>; 2]; MAX_AXES],
    findings: Vec<Finding>,
    /// Findings of each kind so far, by [`Kind::index`].
    counts: [usize; Kind::ALL.len()],
    /// Segments seen.
    order: u64,
    /// Programmed time so far, minutes.
    minutes: f64,
    /// Time lost to feed limits, minutes.
    limited_minutes: f64,
    /// The velocity planner's estimate of the time, fed block by block.
    plan: time::TimePlan,
    /// Each segment's end time, when asked for.
    timeline: Option<Timeline>,
    /// The collision check, when asked for.
    collisions: Option<collision::Collisions>,
    /// The stock model, when given.
    stock: Option<stock::StockCheck>,
    /// The chord proof of the segment being checked, when worked out
    /// ahead ([`Checker::segments_ahead`]).
    chord_known: Option<Option<f64>>,
    /// The tip feed the axes allow in the segment being checked, its end
    /// tips and its law, when worked out ahead
    /// ([`Checker::segments_ahead`]).
    tcpc_known: Option<TcpcAhead>,
    /// Chord proofs worked out in order, not ahead, so far.
    proofs_in_order: usize,
    /// The tool tips at the segments' ends, in order.
    end_tips: TipsInOrder,
}

impl<'m> Checker<'m> {
    /// A check of a run on `machine` that starts at the controller's
    /// power-on position (reference position 1).
    pub fn new(machine: &'m Machine) -> Self {
        let start = machine.params.reference_1;
        let mut limits = [None; MAX_AXES];
        for (i, axis) in machine.linear.iter().enumerate() {
            limits[i] = Some((axis.min, axis.max));
        }
        for (k, axis) in machine.rotary.iter().enumerate() {
            if !axis.rollover {
                limits[machine.rotary_index(k)] = axis.limits;
            }
        }
        Self {
            machine,
            singular: singular::Singular::of(machine),
            range: std::array::from_fn(|i| (start[i], start[i])),
            limits,
            runs: [[None; 2]; MAX_AXES],
            findings: Vec::new(),
            counts: [0; Kind::ALL.len()],
            order: 0,
            minutes: 0.0,
            limited_minutes: 0.0,
            plan: time::TimePlan::new(machine),
            timeline: None,
            collisions: None,
            stock: None,
            chord_known: None,
            tcpc_known: None,
            proofs_in_order: 0,
            end_tips: TipsInOrder::default(),
        }
    }

    /// Cuts a stock model too ([`stock::StockCheck`]).
    pub fn check_stock(&mut self, stock: stock::StockCheck) {
        self.stock = Some(stock);
    }

    /// The stock model as cut so far, when there is one.
    /// (The poses queued are cut first.)
    pub fn stock_model(&mut self) -> Option<&mut fiveaxis_stock::Stock> {
        let stock = self.stock.as_mut()?;
        let (counts, findings) = (&mut self.counts, &mut self.findings);
        Some(stock.model_mut(self.machine, &mut |f| {
            counts[f.kind.index()] += 1;
            findings.push(f);
        }))
    }

    /// Checks collisions too ([`collision::Collisions`]).
    pub fn check_collisions(&mut self, collisions: collision::Collisions) {
        self.collisions = Some(collisions);
    }

    /// Keeps the time at which each segment ends, for
    /// [`Checker::finish_with_times`]: a timeline whose total is the
    /// report's. Costs a mark in the planner and two numbers per segment.
    pub fn keep_segment_times(&mut self) {
        self.timeline = Some(Timeline::default());
    }

    /// Marks each segment's end in the plan, for a caller that keeps its
    /// own timeline of any length: [`Checker::take_segment_times`] hands
    /// over the estimated ends as the plan commits past them and
    /// [`Checker::finish_streamed`] the rest. Nothing is held but the
    /// ends not yet taken (the planner's look-ahead).
    pub fn stream_segment_times(&mut self) {
        self.timeline = Some(Timeline {
            streamed: true,
            ..Timeline::default()
        });
    }

    /// Hands over, in segment order, the estimated end times (seconds from
    /// the start) known since the last call (after
    /// [`Checker::stream_segment_times`]).
    pub fn take_segment_times(&mut self, mut take: impl FnMut(f64)) {
        if let Some(timeline) = &mut self.timeline {
            for t in timeline.estimated.drain(..) {
                take(t);
            }
        }
    }

    /// The report, once the run is over, handing over the estimated end
    /// times not yet taken (after [`Checker::stream_segment_times`]), and
    /// which time the ends follow: [`TimeKind::Estimated`] when the plan's
    /// total is the report's estimate (the last end is then that total, to
    /// rounding), else [`TimeKind::Programmed`] and the caller times the
    /// segments by their programmed ends.
    pub fn finish_streamed(
        mut self,
        ending: Ending,
        mut take: impl FnMut(f64),
    ) -> (Report, TimeKind) {
        let timeline = self.timeline.get_or_insert_with(|| Timeline {
            streamed: true,
            ..Timeline::default()
        });
        timeline.streamed = true;
        let (report, times) = self.finish_with_times(ending);
        let kind = times.map_or(TimeKind::Programmed, |t| {
            for end in t.ends {
                take(end);
            }
            t.kind
        });
        (report, kind)
    }

    fn push(
        &mut self,
        kind: Kind,
        line: u32,
        axis: Option<char>,
        value: Option<f64>,
        message: Message,
    ) {
        self.add(Finding {
            kind,
            line,
            message,
            axis,
            value,
            bodies: None,
            point: None,
            order: self.order,
        });
    }

    fn add(&mut self, finding: Finding) {
        self.counts[finding.kind.index()] += 1;
        self.findings.push(finding);
    }

    /// An alarm finding, in its place after the segments so far: the alarm
    /// that stopped the run (from [`Ending::alarm`]), or one the run went
    /// on after (`check --keep-going`).
    pub fn alarm(&mut self, alarm: &AlarmInfo) {
        self.order += 1;
        let message = format!("{} {}", alarm.code, alarm.message);
        self.push(Kind::Alarm, alarm.line, None, None, message.into());
    }

    /// Checks one segment.
    pub fn segment(&mut self, seg: &Segment) {
        self.segment_inside(seg, None);
    }

    /// [`Checker::segment`] with the plan's samples of the segment
    /// between its ends worked out ahead, when they are.
    fn segment_inside(&mut self, seg: &Segment, inside: Option<&[(Joints, Vec3)]>) {
        self.check_segment(seg, inside);
        if let Some(timeline) = &mut self.timeline {
            if !timeline.streamed {
                timeline.programmed.push(self.minutes * 60.0);
            }
            self.plan.mark(&mut timeline.estimated);
        }
    }

    fn check_segment(&mut self, seg: &Segment, inside: Option<&[(Joints, Vec3)]>) {
        self.order += 1;
        let known = self.tcpc_known.take();
        let law = match &known {
            Some(known) => known.law,
            None => law::tcpc_law(self.machine, seg),
        };
        self.positions(seg, law.as_ref());
        if !seg.moves() {
            return;
        }
        let tips = match &known {
            Some(known) => self.end_tips.follow(seg, known.tips),
            None => self.end_tips.tips(self.machine, seg),
        };
        self.time(seg, &tips, law.as_ref(), known.map(|k| k.allowed));
        self.plan.segment(self.machine, seg, &tips, inside);
        if let Some(collisions) = &mut self.collisions {
            let (counts, findings) = (&mut self.counts, &mut self.findings);
            collisions.segment(self.machine, seg, self.order, &mut |f| {
                counts[f.kind.index()] += 1;
                findings.push(f);
            });
        }
        if let Some(stock) = &mut self.stock {
            let (counts, findings) = (&mut self.counts, &mut self.findings);
            stock.segment(self.machine, seg, self.order, &mut |f| {
                counts[f.kind.index()] += 1;
                findings.push(f);
            });
        }
        // Positioning moves cut nothing: they are where a program turns
        // its rotary axes, and how the tool passes the singular direction
        // or leaves the chord there does not matter.
        if turns_cutting(self.machine, seg) {
            self.rotary_flip(seg);
            // Only where the control chose the rotary axes: a program that
            // writes them passes where it says.
            if seg.rotary_chosen {
                self.singular_passage(seg);
            }
            if !matches!(seg.path, Path::Tcpc(_)) {
                self.chord_error(seg, &tips);
            }
        }
    }

    /// Checks a batch of segments in order, as [`Checker::segment`] each,
    /// with the work that is pure per segment done first ([`Ahead`]: the
    /// chord proofs on every core).
    pub fn segments(&mut self, batch: &[Segment]) {
        let mut ahead = Ahead::default();
        let all = Wanted {
            chords: true,
            time: true,
        };
        ahead.work_out(self.machine, batch, all);
        self.segments_ahead(batch, &ahead);
    }

    /// [`Checker::segments`] with the batch's work ahead done already (by
    /// [`Ahead::work_out`], on another thread).
    pub fn segments_ahead(&mut self, batch: &[Segment], ahead: &Ahead) {
        for (i, seg) in batch.iter().enumerate() {
            self.chord_known = ahead.chords.get(i);
            self.tcpc_known = ahead.tcpc.get(i).copied().flatten();
            self.segment_inside(seg, ahead.samples.get(i));
            self.chord_known = None;
            self.tcpc_known = None;
        }
    }

    /// Axis ranges and over-travel runs.
    fn positions(&mut self, seg: &Segment, law: Option<&bound::Moving>) {
        let machine = self.machine;
        let axes = machine.axis_count();
        // A joint move lies between its ends: with both inside the limits
        // and no excursion open, the ranges take in the ends and nothing
        // else changes (what the search below finds for such a block).
        if matches!(seg.path, Path::Joint) {
            let inside = |i: usize| {
                self.runs[i].iter().all(Option::is_none)
                    && self.limits[i].is_none_or(|(lo, hi)| {
                        let (a, b) = (seg.start[i], seg.end[i]);
                        a.min(b) >= lo - LIMIT_TOLERANCE && a.max(b) <= hi + LIMIT_TOLERANCE
                    })
            };
            if (0..axes).all(inside) {
                for (range, (a, b)) in self.range[..axes]
                    .iter_mut()
                    .zip(seg.start.iter().zip(&seg.end))
                {
                    range.0 = range.0.min(a.min(*b));
                    range.1 = range.1.max(a.max(*b));
                }
                return;
            }
        }
        for i in 0..axes {
            let limits = self.limits[i];
            for (side, sign) in [(0, -1.0), (1, 1.0)] {
                // Signed: the highest of `sign · position`.
                let reached = sign
                    * if side == 1 {
                        self.range[i].1
                    } else {
                        self.range[i].0
                    };
                let limit = limits.map(|(lo, hi)| sign * if side == 1 { hi } else { lo });
                let floor = limit.map_or(reached, |l| reached.min(l + LIMIT_TOLERANCE));
                let found = axis_max(machine, seg, i, sign, floor, law);
                if let Some(v) = found {
                    let position = sign * v;
                    if side == 1 {
                        self.range[i].1 = self.range[i].1.max(position);
                    } else {
                        self.range[i].0 = self.range[i].0.min(position);
                    }
                }
                let beyond = match (found, limit) {
                    (Some(v), Some(l)) if v > l + LIMIT_TOLERANCE => Some(sign * v),
                    _ => None,
                };
                match (beyond, &mut self.runs[i][side]) {
                    (Some(p), Some(run)) => {
                        if sign * p > sign * run.farthest {
                            run.farthest = p;
                        }
                    }
                    (Some(p), slot @ None) => {
                        *slot = Some(Run {
                            line: seg.line,
                            order: self.order,
                            farthest: p,
                        });
                    }
                    (None, slot @ Some(_)) => {
                        let run = slot.take();
                        if let Some(run) = run {
                            self.close_run(i, side, run);
                        }
                    }
                    (None, None) => {}
                }
                // Back inside at the block's end: the excursion ends here
                // (a later departure is a new one, even in the next block).
                let back_inside = limit.is_some_and(|l| sign * seg.end[i] <= l + LIMIT_TOLERANCE);
                if back_inside && let Some(run) = self.runs[i][side].take() {
                    self.close_run(i, side, run);
                }
            }
        }
    }

    fn close_run(&mut self, i: usize, side: usize, run: Run) {
        let Some((lo, hi)) = self.limits[i] else {
            return;
        };
        let name = self.machine.axis_names().nth(i).unwrap_or('?');
        let (sign, limit) = if side == 1 { ('+', hi) } else { ('-', lo) };
        let unit = if i < self.machine.linear.len() {
            " mm"
        } else {
            " deg"
        };
        let message = Message::of(&[
            Word::Letter(name),
            Word::Letter(sign),
            Word::Text(" over-travel: "),
            Word::Letter(name),
            Word::Text(" reaches "),
            Word::Number(round6(run.farthest)),
            Word::Text(" beyond the soft limit "),
            Word::Number(limit),
            Word::Text(" ("),
            Word::Number(round6((run.farthest - limit).abs())),
            Word::Text(unit),
            Word::Text(" too far)"),
        ]);
        self.add(Finding {
            kind: Kind::Overtravel,
            line: run.line,
            message,
            axis: Some(name),
            value: Some(run.farthest),
            bodies: None,
            point: None,
            order: run.order,
        });
    }

    /// Programmed time and feed limits; `known` is the tip feed the axes
    /// allow when worked out ahead.
    fn time(
        &mut self,
        seg: &Segment,
        tips: &[fiveaxis_machine::Vec3; 2],
        law: Option<&bound::Moving>,
        known: Option<Option<(f64, usize)>>,
    ) {
        let machine = self.machine;
        let minutes = motion::block_minutes_at(machine, seg, tips);
        self.minutes += minutes;
        let Some(feed) = seg.feed else { return };
        let allowed = match known {
            Some(known) => known,
            None => motion::tip_feed_allowed_by(machine, seg, minutes, law),
        };
        if let Some((allowed, axis)) = allowed
            && allowed < feed
        {
            self.limited_minutes += minutes * (feed / allowed - 1.0);
            let name = machine.axis_names().nth(axis).unwrap_or('?');
            let vmax = if axis < machine.linear.len() {
                machine.linear[axis].dynamics.max_velocity
            } else {
                machine.rotary[axis - machine.linear.len()]
                    .dynamics
                    .max_velocity
            };
            let unit = if axis < machine.linear.len() {
                " mm/min: the tip moves at "
            } else {
                " deg/min: the tip moves at "
            };
            let needs = [
                Word::Letter(name),
                Word::Text(" faster than its "),
                Word::Number(round3(vmax)),
                Word::Text(unit),
                Word::Number(round3(allowed)),
                Word::Text(" mm/min at most"),
            ];
            // In inverse time F is 1/minutes, not the tip feed the axes
            // must keep: both are named.
            let mut words: arrayvec::ArrayVec<Word<'static>, { message::MAX_WORDS }> =
                arrayvec::ArrayVec::new();
            if seg.inverse_time && minutes > 0.0 {
                words.extend([
                    Word::Text("the inverse-time F"),
                    Word::Number(round6(1.0 / minutes)),
                    Word::Text(" works out to a tip feed of "),
                    Word::Number(round3(feed)),
                    Word::Text(" mm/min, which needs "),
                ]);
            } else {
                words.extend([
                    Word::Text("F"),
                    Word::Number(round3(feed)),
                    Word::Text(" needs "),
                ]);
            }
            words.extend(needs);
            let message = Message::of(&words);
            self.push(
                Kind::FeedLimited,
                seg.line,
                Some(name),
                Some(allowed),
                message,
            );
        }
    }

    fn singular_passage(&mut self, seg: &Segment) {
        let Some(singular) = self.singular else {
            return;
        };
        let machine = self.machine;
        let angle = match &seg.path {
            Path::Tcpc(t) if t.posture.is_some() => t
                .posture
                .as_deref()
                .map_or(90.0, |p| singular.smallest_on_posture(p)),
            Path::Via(mid) => {
                let tilt = singular.tilt();
                let first = singular.smallest_on_tilt(machine, &seg.start, mid[tilt]).0;
                let second = singular.smallest_on_tilt(machine, mid, seg.end[tilt]).0;
                first.min(second)
            }
            _ => {
                singular
                    .smallest_on_tilt(machine, &seg.start, seg.end[singular.tilt()])
                    .0
            }
        };
        let cone = machine.params.singular_cone;
        if angle <= cone {
            let message = Message::of(&[
                Word::Text("the tool passes "),
                Word::Number(round6(angle)),
                Word::Text("° from the singular direction (within "),
                Word::Number(cone),
                Word::Text("°): the rotating axis may swing fast"),
            ]);
            self.push(Kind::SingularPassage, seg.line, None, Some(angle), message);
        }
    }

    fn rotary_flip(&mut self, seg: &Segment) {
        let machine = self.machine;
        let limit = machine.params.flip_angle;
        for (k, axis) in machine.rotary.iter().enumerate() {
            let turn = motion::rotary_travel(machine, seg, k);
            if turn > limit {
                let message = Message::of(&[
                    Word::Letter(axis.name),
                    Word::Text(" turns "),
                    Word::Number(round6(turn)),
                    Word::Text("° in one block (more than "),
                    Word::Number(limit),
                    Word::Text("°)"),
                ]);
                self.push(
                    Kind::RotaryFlip,
                    seg.line,
                    Some(axis.name),
                    Some(turn),
                    message,
                );
            }
        }
    }

    fn chord_error(&mut self, seg: &Segment, tips: &[fiveaxis_machine::Vec3; 2]) {
        let machine = self.machine;
        let tolerance = machine.params.chord_tolerance;
        let found = match self.chord_known.take() {
            Some(known) => known,
            None => {
                chord_deviation_counted(machine, seg, tolerance, tips, &mut self.proofs_in_order)
            }
        };
        if let Some(deviation) = found {
            let message = Message::of(&[
                Word::Text("the tip leaves the straight line between the block ends by "),
                Word::Number(round6(deviation)),
                Word::Text(" mm (tolerance "),
                Word::Number(tolerance),
                Word::Text(" mm): the rotary axes move outside TCPC"),
            ]);
            self.push(Kind::ChordError, seg.line, None, Some(deviation), message);
        }
    }

    /// Hands over, in report order, the findings no later segment can
    /// precede: all of them but those after the start of an over-travel
    /// run still open (its finding is written when the run ends, in the
    /// place of its first block). A caller that drains as it goes holds
    /// only those instead of every finding of the program; the findings
    /// drained and then those of [`Checker::finish`] are the report's, in
    /// its order.
    pub fn drain_settled(&mut self, mut take: impl FnMut(Finding)) {
        let open = self
            .runs
            .iter()
            .flatten()
            .flatten()
            .map(|run| run.order)
            .chain(self.collisions.as_ref().and_then(|c| c.open_order()))
            .chain(self.stock.as_ref().and_then(|c| c.open_order()))
            .min()
            .unwrap_or(u64::MAX);
        // Findings are pushed in segment order but for closed runs, which
        // arrive late: a stable sort puts them in place.
        self.findings.sort_by_key(|f| f.order);
        let settled = self.findings.partition_point(|f| f.order < open);
        for finding in self.findings.drain(..settled) {
            take(finding);
        }
    }

    /// The report, once the run is over.
    pub fn finish(self, ending: Ending) -> Report {
        self.finish_with_times(ending).0
    }

    /// The report, and when each segment ends in its estimated time if
    /// [`Checker::keep_segment_times`] asked for it.
    pub fn finish_with_times(mut self, ending: Ending) -> (Report, Option<SegmentTimes>) {
        for i in 0..MAX_AXES {
            for side in 0..2 {
                if let Some(run) = self.runs[i][side].take() {
                    self.close_run(i, side, run);
                }
            }
        }
        if let Some(mut collisions) = self.collisions.take() {
            let (counts, findings) = (&mut self.counts, &mut self.findings);
            collisions.close_all(self.machine, &mut |f| {
                counts[f.kind.index()] += 1;
                findings.push(f);
            });
        }
        let stock_summary = self.stock.take().map(|mut stock| {
            let (counts, findings) = (&mut self.counts, &mut self.findings);
            let mut add = |f: Finding| {
                counts[f.kind.index()] += 1;
                findings.push(f);
            };
            stock.close_all(self.machine, &mut add);
            stock.finish(&mut add)
        });
        if let Some(alarm) = &ending.alarm {
            self.alarm(alarm);
        }
        self.findings.sort_by_key(|f| f.order);
        let machine = self.machine;
        let axes = machine
            .axis_names()
            .enumerate()
            .map(|(i, name)| AxisRange {
                name,
                min: self.range[i].0,
                max: self.range[i].1,
                limits: self.limits[i],
            })
            .collect();
        let programmed = self.minutes * 60.0;
        let mut timeline = self.timeline.take();
        let mut marks = Vec::new();
        let (estimated, planned) = self.plan.finish(
            programmed,
            timeline.as_mut().map_or(&mut marks, |t| &mut t.estimated),
        );
        let times = timeline.map(|t| {
            if planned && (t.streamed || t.estimated.len() == t.programmed.len()) {
                let mut ends = t.estimated;
                // The last mark is the plan's end, to the rounding of the
                // summed lengths: made exactly the total.
                for end in ends.iter_mut().rev() {
                    if (*end - estimated).abs() > 1e-9 * estimated {
                        break;
                    }
                    *end = estimated;
                }
                SegmentTimes {
                    kind: TimeKind::Estimated,
                    ends,
                }
            } else {
                SegmentTimes {
                    kind: TimeKind::Programmed,
                    // Streamed: the caller has the programmed ends.
                    ends: if t.streamed { Vec::new() } else { t.programmed },
                }
            }
        });
        let report = Report {
            machine: machine.name.clone(),
            ended: ending.ended,
            alarm: ending.alarm,
            blocks: ending.blocks,
            time: Time {
                programmed,
                estimated,
            },
            axes,
            findings: self.findings,
            counts: self.counts,
            feed_limited_seconds: self.limited_minutes * 60.0,
            stock: stock_summary,
        };
        (report, times)
    }
}

/// What is worked out for a batch of segments ahead of the checks that
/// take them in order, pure per segment: the chord proofs (on every core,
/// when the batch has enough), and the time check's work: the samples the
/// time plan takes between the ends of curved blocks and the tip feed the
/// axes allow in TCPC blocks (sampled too where their law does not clear
/// an axis).
#[derive(Debug, Default)]
pub struct Ahead {
    chords: ChordsAhead,
    samples: time::SamplesAhead,
    /// By segment: a TCPC block's feed the axes allow, end tips and law,
    /// where worked out.
    tcpc: Vec<Option<TcpcAhead>>,
}

impl Ahead {
    /// Works out, as `wanted` says, the chord proofs of `batch`
    /// ([`ChordsAhead::work_out`]) and the time check's work; what is not
    /// wanted is left to the checks.
    pub fn work_out(&mut self, machine: &Machine, batch: &[Segment], wanted: Wanted) {
        if wanted.chords {
            self.chords.work_out(machine, batch);
        } else {
            self.chords.clear();
        }
        self.tcpc.clear();
        if wanted.time {
            self.samples.work_out(machine, batch);
            let mut tips = TipsInOrder::default();
            self.tcpc
                .extend(batch.iter().map(|seg| tcpc_ahead(machine, seg, &mut tips)));
        } else {
            self.samples.clear();
        }
    }

    /// What was worth working out for the batch: chord proofs when it
    /// had enough, the time check's work when it had any samples or TCPC
    /// feeds.
    fn found(&self) -> Wanted {
        Wanted {
            chords: !self.chords.found.is_empty(),
            time: !self.samples.is_empty() || self.tcpc.iter().any(Option::is_some),
        }
    }
}

/// What the checks need of a TCPC block that cuts, worked out ahead.
#[derive(Clone, Copy, Debug)]
struct TcpcAhead {
    /// The tip feed the axes allow, and the axis that sets it.
    allowed: Option<(f64, usize)>,
    /// The tool tip at the block's ends.
    tips: [Vec3; 2],
    /// The block's law ([`law::tcpc_law`]).
    law: Option<bound::Moving>,
}

/// The tip feed the axes allow in a TCPC block that cuts, as
/// [`Checker`]'s time check works it out (its tips, its minutes), with the
/// tips and the law it rests on, for the checks to take as they are.
fn tcpc_ahead(machine: &Machine, seg: &Segment, tips: &mut TipsInOrder) -> Option<TcpcAhead> {
    if !matches!(seg.path, Path::Tcpc(_)) || seg.feed.is_none() || !seg.moves() {
        return None;
    }
    let tips = tips.tips(machine, seg);
    let minutes = motion::block_minutes_at(machine, seg, &tips);
    let law = law::tcpc_law(machine, seg);
    Some(TcpcAhead {
        allowed: motion::tip_feed_allowed_by(machine, seg, minutes, law.as_ref()),
        tips,
        law,
    })
}

/// The tool tips at the ends of segments taken in order: a segment that
/// starts where the last one ended, with the same tool length, takes that
/// end's tip as its start's (one forward kinematics a segment).
#[derive(Clone, Copy, Debug, Default)]
struct TipsInOrder {
    /// The last segment's end: joints, tool length and tool tip.
    last: Option<(Joints, f64, Vec3)>,
}

impl TipsInOrder {
    /// The tips at `seg`'s ends.
    fn tips(&mut self, machine: &Machine, seg: &Segment) -> [Vec3; 2] {
        let start = match &self.last {
            Some((joints, length, tip)) if *joints == seg.start && *length == seg.tool_length => {
                *tip
            }
            _ => machine.forward_tip(&seg.start, seg.tool_length),
        };
        let end = machine.forward_tip(&seg.end, seg.tool_length);
        self.follow(seg, [start, end])
    }

    /// Takes `seg`'s tips as worked out elsewhere (the same forward
    /// kinematics), and gives them back.
    fn follow(&mut self, seg: &Segment, tips: [Vec3; 2]) -> [Vec3; 2] {
        self.last = Some((seg.end, seg.tool_length, tips[1]));
        tips
    }
}

/// Which of [`Ahead`]'s work to do.
#[derive(Clone, Copy, Debug)]
pub struct Wanted {
    /// The chord proofs.
    pub chords: bool,
    /// The time check's samples and TCPC feeds.
    pub time: bool,
}

/// [`Wanted`] shared by the two stages of [`check_run_with`]: the
/// runner's thread does the work from the start while batches have it,
/// and stops; the checks turn it back on when they meet enough of it in
/// order.
#[derive(Debug)]
struct WantedAhead {
    chords: AtomicBool,
    time: AtomicBool,
}

impl WantedAhead {
    fn new() -> Self {
        Self {
            chords: AtomicBool::new(true),
            time: AtomicBool::new(true),
        }
    }

    fn get(&self) -> Wanted {
        Wanted {
            chords: self.chords.load(Relaxed),
            time: self.time.load(Relaxed),
        }
    }

    /// Off what was wanted and not found (the runner's thread).
    fn found(&self, wanted: Wanted, found: Wanted) {
        if wanted.chords && !found.chords {
            self.chords.store(false, Relaxed);
        }
        if wanted.time && !found.time {
            self.time.store(false, Relaxed);
        }
    }

    /// On what the checks met in order (the checks' thread).
    fn met(&self, met: Wanted) {
        if met.chords {
            self.chords.store(true, Relaxed);
        }
        if met.time {
            self.time.store(true, Relaxed);
        }
    }
}

/// The chord proofs of a batch of segments, worked out ahead of the
/// checks that take the segments in order: they depend on nothing but
/// their segment and take most of the time where the rotary axes turn far
/// outside TCPC, so they are spread over every core.
#[derive(Debug, Default)]
pub struct ChordsAhead {
    /// Indices in the batch of the segments that need a proof.
    wanted: Vec<usize>,
    /// Their deviations beyond the tolerance, in the same order (empty
    /// when the batch had too few to be worth spreading: they are then
    /// proved in order).
    found: Vec<Option<f64>>,
}

impl ChordsAhead {
    /// Works out the chord proofs of `batch` on every core, when it has
    /// at least [`PARALLEL_CHORDS`] of them.
    pub fn work_out(&mut self, machine: &Machine, batch: &[Segment]) {
        let tolerance = machine.params.chord_tolerance;
        self.wanted.clear();
        self.found.clear();
        self.wanted.extend(
            batch
                .iter()
                .enumerate()
                .filter(|(_, seg)| needs_chord_proof(machine, seg, tolerance))
                .map(|(i, _)| i),
        );
        if self.wanted.len() >= PARALLEL_CHORDS {
            use rayon::prelude::*;
            self.wanted
                .par_iter()
                .with_min_len(CHORDS_PER_TASK)
                .map(|&i| chord_deviation(machine, &batch[i], tolerance))
                .collect_into_vec(&mut self.found);
        }
    }

    /// Nothing worked out (the proofs are made in order).
    pub fn clear(&mut self) {
        self.wanted.clear();
        self.found.clear();
    }

    /// The chord proof of segment `i` of the batch, when worked out: its
    /// deviation beyond the tolerance, if any.
    pub fn get(&self, i: usize) -> Option<Option<f64>> {
        if self.found.is_empty() {
            return None;
        }
        let k = self.wanted.binary_search(&i).ok()?;
        self.found.get(k).copied()
    }
}

/// Fewest chord proofs in a batch worth spreading over the cores.
const PARALLEL_CHORDS: usize = 32;

/// Chord proofs one task takes at least (each is some tens of forward
/// kinematics).
const CHORDS_PER_TASK: usize = 8;

/// Whether a segment turns rotary axes in a cutting move: where flips,
/// singular passages and the chord are checked.
fn turns_cutting(machine: &Machine, seg: &Segment) -> bool {
    if seg.motion == Motion::Rapid {
        return false;
    }
    let rotary = machine.linear.len()..machine.axis_count();
    rotary.clone().any(|i| seg.start[i] != seg.end[i])
        || matches!(&seg.path, Path::Via(mid) if rotary.clone().any(|i| mid[i] != seg.start[i]))
        || matches!(&seg.path, Path::Tcpc(t) if t.posture.is_some())
}

/// Whether the chord check of a segment needs a proof: a cutting move
/// outside TCPC that turns rotary axes, whose curvature bound does not
/// keep it within the tolerance by itself ([`chord_deviation_at`]).
fn needs_chord_proof(machine: &Machine, seg: &Segment, tolerance: f64) -> bool {
    seg.moves()
        && !matches!(seg.path, Path::Tcpc(_))
        && turns_cutting(machine, seg)
        && !law::joint_tip_curvature(machine, seg)
            .is_some_and(|c| c / 8.0 <= tolerance + CHORD_PRECISION)
        && law::machine_tip(machine, seg)
            .is_some_and(|law| law.curvature / 8.0 > tolerance + CHORD_PRECISION)
}

/// Segments taken from the runner at a time.
const BATCH: usize = 1024;

/// Batches the runner may be ahead of the checks.
const PIPELINE_DEPTH: usize = 4;

/// What the runner hands the checks: segments, and the run's state after
/// them.
struct Batch {
    segments: Vec<Segment>,
    /// Its work done ahead.
    ahead: Ahead,
    /// The stock the program has declared so far.
    stock: Option<fiveaxis_control::Stock>,
    /// Blocks run so far.
    blocks: u64,
    end: BatchEnd,
}

/// How the run stands after a batch.
enum BatchEnd {
    /// More segments follow.
    More,
    /// An alarm after which the run goes on (`keep_going`).
    Resumed(AlarmInfo),
    /// The program ended.
    Ended,
    /// The program stopped with an alarm.
    Alarm(AlarmInfo),
    /// The program could not be read.
    Failed(RunError),
}

/// The runner's side of [`check_run_with`]: fills batches until the
/// program ends, stops or the checks hang up.
fn produce<S: Source>(
    runner: &mut Runner<'_, S>,
    keep_going: bool,
    full: &std::sync::mpsc::SyncSender<Batch>,
    empty: &std::sync::mpsc::Receiver<(Vec<Segment>, Ahead)>,
    wanted: &WantedAhead,
) {
    let machine = runner.controller().machine();
    loop {
        let (mut segments, mut ahead) = empty
            .try_recv()
            .unwrap_or_else(|_| (Vec::with_capacity(BATCH), Ahead::default()));
        segments.clear();
        let filled = runner.fill(&mut segments, BATCH);
        // Looking for proofs costs a law a segment, for samples a look
        // at each: only while the last batches had them (a smooth path
        // has neither).
        let now = wanted.get();
        ahead.work_out(machine, &segments, now);
        wanted.found(now, ahead.found());
        let end = match filled {
            Ok(true) => BatchEnd::More,
            Ok(false) => BatchEnd::Ended,
            Err(RunError::Alarm { alarm, .. }) => {
                let info = AlarmInfo {
                    code: alarm.code.to_string(),
                    line: alarm.line,
                    message: alarm.message,
                };
                if keep_going && runner.resume() {
                    BatchEnd::Resumed(info)
                } else {
                    BatchEnd::Alarm(info)
                }
            }
            Err(other) => BatchEnd::Failed(other),
        };
        let last = !matches!(end, BatchEnd::More | BatchEnd::Resumed(_));
        let batch = Batch {
            segments,
            ahead,
            stock: runner.stock(),
            blocks: runner.blocks(),
            end,
        };
        if full.send(batch).is_err() || last {
            return;
        }
    }
}

/// Runs a program to its end or its alarm and checks every segment.
/// The runner should lift the soft limits (`RunOptions::lift_soft_limits`)
/// so that an over-travel is measured and the run goes on. `keep_going`:
/// as [`check_run_into`]'s. `progress` is called after each batch of
/// segments with the blocks run so far.
///
/// # Errors
///
/// The program cannot be read (`RunError::Io`, `RunError::LineTooLong`);
/// an alarm is not an error here but part of the report.
pub fn check_run<S: Source>(
    runner: &mut Runner<'_, S>,
    keep_going: bool,
    progress: impl FnMut(u64),
) -> Result<Report, RunError> {
    let mut findings = Vec::new();
    let (mut report, whole_program) =
        check_run_into(runner, keep_going, progress, |f| findings.push(f))?;
    if let Some(finding) = whole_program {
        let at = findings
            .iter()
            .position(|f| f.line > finding.line)
            .unwrap_or(findings.len());
        findings.insert(at, finding);
    }
    report.findings = findings;
    Ok(report)
}

/// [`check_run`] for programs of any length: the findings are handed to
/// `take` in report order as they settle instead of being held, so memory
/// does not grow with them; the report holds their counts. The finding
/// about the whole program (`no_decimal_point`), known only at the end,
/// comes back beside the report: it goes before the first finding handed
/// over whose line is after its own.
///
/// `keep_going`: an alarm after which the control's state is defined
/// ([`Runner::resume`]) becomes an `alarm` finding and the run goes on
/// from the next line; the report's `alarm` is then the first alarm, and
/// `ended` whether the program reached its end.
///
/// # Errors
///
/// As [`check_run`].
pub fn check_run_into<S: Source>(
    runner: &mut Runner<'_, S>,
    keep_going: bool,
    progress: impl FnMut(u64),
    take: impl FnMut(Finding),
) -> Result<(Report, Option<Finding>), RunError> {
    check_run_with(runner, keep_going, WorkChecks::default(), progress, take)
}

/// The checks of the work a run may add: collisions, the stock.
#[derive(Default)]
pub struct WorkChecks<'a> {
    /// The collision check.
    pub collisions: Option<collision::Collisions>,
    /// The stock model.
    pub stock: Option<stock::StockCheck>,
    /// Without `stock`: the stock model of the stock the program
    /// declares (HEIDENHAIN `BLK FORM`), made once it has been read.
    pub declared: Option<DeclaredStock<'a>>,
}

impl<'a> WorkChecks<'a> {
    /// Hands the collision check and the stock model to `checker`; what
    /// is left is the stock the program may still declare.
    pub fn install(self, checker: &mut Checker<'_>) -> Declared<'a> {
        if let Some(collisions) = self.collisions {
            checker.check_collisions(collisions);
        }
        match self.stock {
            Some(stock) => {
                checker.check_stock(stock);
                Declared(None)
            }
            None => Declared(self.declared),
        }
    }
}

/// The stock model a program's declared stock will make, until it is
/// read.
pub struct Declared<'a>(Option<DeclaredStock<'a>>);

impl std::fmt::Debug for Declared<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("Declared").field(&self.0.is_some()).finish()
    }
}

impl Declared<'_> {
    /// Gives `checker` the stock model once the program has declared its
    /// stock (`Runner::stock`). A declared stock comes first in its
    /// program (BLK FORM after BEGIN PGM), before any move.
    pub fn offer(&mut self, declared: Option<fiveaxis_control::Stock>, checker: &mut Checker<'_>) {
        if self.0.is_some()
            && let Some(blk) = declared
            && let Some(make) = self.0.take()
            && let Some(stock) = make(&blk)
        {
            checker.check_stock(stock);
        }
    }
}

/// Makes the stock model of a stock the program declares.
pub type DeclaredStock<'a> =
    Box<dyn FnOnce(&fiveaxis_control::Stock) -> Option<stock::StockCheck> + 'a>;

impl std::fmt::Debug for WorkChecks<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WorkChecks")
            .field("collisions", &self.collisions)
            .field("stock", &self.stock)
            .field("declared", &self.declared.is_some())
            .finish()
    }
}

/// [`check_run_into`] with the checks of the work `work`.
///
/// # Errors
///
/// As [`check_run`].
pub fn check_run_with<S: Source + Send>(
    runner: &mut Runner<'_, S>,
    keep_going: bool,
    work: WorkChecks<'_>,
    mut progress: impl FnMut(u64),
    mut take: impl FnMut(Finding),
) -> Result<(Report, Option<Finding>), RunError> {
    let machine = runner.controller().machine();
    runner.count_words_without_point();
    let mut checker = Checker::new(machine);
    let mut declared = work.install(&mut checker);
    let mut first_alarm: Option<AlarmInfo> = None;
    // Two stages on two threads: the runner reads and interprets the
    // program into batches of segments while this thread checks the
    // batch before; batches go round between them (no allocation per
    // batch once both are in use).
    let (full_tx, full_rx) = std::sync::mpsc::sync_channel::<Batch>(PIPELINE_DEPTH);
    let (empty_tx, empty_rx) = std::sync::mpsc::channel::<(Vec<Segment>, Ahead)>();
    // What the runner's thread works out ahead.
    let ahead_wanted = WantedAhead::new();
    let alarm = std::thread::scope(|scope| {
        let producing = &mut *runner;
        let ahead = &ahead_wanted;
        let producer =
            scope.spawn(move || produce(producing, keep_going, &full_tx, &empty_rx, ahead));
        let mut alarm = None;
        while let Ok(batch) = full_rx.recv() {
            declared.offer(batch.stock, &mut checker);
            let before = checker.proofs_in_order;
            let sampled = checker.plan.samples_in_order();
            checker.segments_ahead(&batch.segments, &batch.ahead);
            // Proofs and samples worked out here in order are worth
            // working out ahead from the next batch on.
            ahead_wanted.met(Wanted {
                chords: checker.proofs_in_order - before >= PARALLEL_CHORDS,
                time: checker.plan.samples_in_order() > sampled,
            });
            checker.drain_settled(&mut take);
            progress(batch.blocks);
            // The producer may have ended: its batches are then dropped.
            let _ = empty_tx.send((batch.segments, batch.ahead));
            match batch.end {
                BatchEnd::More => {}
                BatchEnd::Resumed(info) => {
                    checker.alarm(&info);
                    first_alarm.get_or_insert(info);
                }
                BatchEnd::Ended => break,
                BatchEnd::Alarm(info) => {
                    alarm = Some(info);
                    break;
                }
                BatchEnd::Failed(e) => return Err(e),
            }
        }
        drop(full_rx);
        match producer.join() {
            Ok(()) => Ok(alarm),
            Err(panic) => std::panic::resume_unwind(panic),
        }
    })?;
    let mut report = checker.finish(Ending {
        ended: alarm.is_none(),
        alarm,
        blocks: runner.blocks(),
    });
    if let Some(first) = first_alarm {
        report.alarm = Some(first);
    }
    for finding in std::mem::take(&mut report.findings) {
        take(finding);
    }
    let whole_program = runner
        .controller()
        .words_without_point()
        .and_then(|words| words_without_point(machine, words));
    if let Some(f) = &whole_program {
        report.counts[f.kind.index()] += 1;
    }
    Ok((report, whole_program))
}

/// The `no_decimal_point` finding of a run that wrote axis words without
/// a decimal point where they count in least input increments (about the
/// whole program, from its first such word).
fn words_without_point(
    machine: &Machine,
    words: fiveaxis_control::WordsWithoutPoint,
) -> Option<Finding> {
    if words.count == 0 {
        return None;
    }
    let increment = machine.params.least_input_increment;
    // As many decimals as the increment has (0.001: 3, 0.0001: 4).
    let decimals = (-increment.log10()).ceil().clamp(0.0, 9.0) as usize;
    let (many, are) = if words.count == 1 {
        ("1 axis word", "is")
    } else {
        ("axis words", "are")
    };
    let count = if words.count == 1 {
        String::new()
    } else {
        format!("{} ", words.count)
    };
    let message = format!(
        "{count}{many} without a decimal point {are} read in least input increments (X10 = {:.decimals$} mm): first on line {}",
        10.0 * increment,
        words.first_line
    );
    Some(Finding {
        kind: Kind::NoDecimalPoint,
        line: words.first_line,
        message: message.into(),
        axis: None,
        value: Some(words.count as f64),
        bodies: None,
        point: None,
        order: 0,
    })
}

/// How far the true chord error may lie above the value reported, mm: a
/// tenth of a thousandth of a micrometre, far below any chord tolerance,
/// settles a block in fewer evaluations than a proof to 1e-9.
pub const CHORD_PRECISION: f64 = 1e-7;

/// The largest distance of the tool tip from the straight line between
/// its positions at the block ends (the end point, when they coincide),
/// if it exceeds `floor`: a machine-axis block whose rotary axes move
/// linearly, bound and refine on the tip's law ([`law::machine_tip`]).
pub fn chord_deviation(machine: &Machine, seg: &Segment, floor: f64) -> Option<f64> {
    chord_deviation_at(machine, seg, floor, &motion::end_tips(machine, seg))
}

/// [`chord_deviation`] with the segment's [`motion::end_tips`] known.
pub fn chord_deviation_at(
    machine: &Machine,
    seg: &Segment,
    floor: f64,
    tips: &[fiveaxis_machine::Vec3; 2],
) -> Option<f64> {
    chord_deviation_counted(machine, seg, floor, tips, &mut 0)
}

/// [`chord_deviation_at`], counting in `proofs` the segments that needed
/// more than their curvature bound.
fn chord_deviation_counted(
    machine: &Machine,
    seg: &Segment,
    floor: f64,
    tips: &[fiveaxis_machine::Vec3; 2],
    proofs: &mut usize,
) -> Option<f64> {
    // The deviation is 0 at both ends: a curvature bound that keeps the
    // whole block within the floor settles it without a sample (the
    // looser one first, without trigonometry).
    let settled = |curvature: f64| curvature / 8.0 <= floor + CHORD_PRECISION;
    if law::joint_tip_curvature(machine, seg).is_some_and(settled) {
        return None;
    }
    let law = law::machine_tip(machine, seg)?;
    if settled(law.curvature) {
        return None;
    }
    *proofs += 1;
    let chain = fiveaxis_machine::TipChain::new(machine);
    let tip = |s: f64| {
        // Every axis linear in s on a joint line: the interpolation alone.
        let joints = if matches!(seg.path, Path::Joint) && s < 1.0 {
            let mut joints = seg.start;
            for (j, (a, b)) in joints.iter_mut().zip(seg.start.iter().zip(&seg.end)) {
                *j = a + (b - a) * s;
            }
            joints
        } else {
            seg.eval(machine, s)
        };
        chain.tip(&joints, seg.tool_length)
    };
    let [a, b] = *tips;
    let chord = b - a;
    let length = chord.norm();
    let along = if length > 0.0 { chord / length } else { chord };
    let off = |s: f64| {
        let d = tip(s) - a;
        d - along * along.dot(&d)
    };
    let zero = fiveaxis_machine::Vec3::zeros();
    bound::maximize_norm(off, &law, floor, [zero, zero], CHORD_PRECISION).map(|(_, v)| v)
}

fn round6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

fn round3(x: f64) -> f64 {
    (x * 1e3).round() / 1e3
}
