//! The stock along the run: each move's cutting part removes material
//! (`fiveaxis-stock`), and the check reports what should not happen to
//! it: a rapid move into the stock, the shank or holder running into
//! what is left, a cut into the designed part (gouge) and material left
//! on it (excess); with the volume each tool removed and the time spent
//! cutting air.

use std::collections::BTreeMap;

use fiveaxis_control::{Motion, Segment};
use fiveaxis_machine::geometry::Link;
use fiveaxis_machine::{Joints, Machine, Offsets, SetupError, Vec3};
use fiveaxis_stock::solid::{Piece, ToolPieces};
use fiveaxis_stock::{Outcome, Pose, Stock};

use crate::{Finding, Kind, block_minutes, round3};

/// A feed move that removes less than this cuts air, mm³ (a micrometre
/// along one ray of a 1 mm cell).
pub const AIR_CUT_VOLUME: f64 = 1e-3;

/// Material reaching deeper than this into a tool in a rapid move, or
/// into its shank or holder, is a finding, mm.
pub const CONTACT_DEPTH: f64 = 1e-3;

/// Poses at most in one move.
const MAX_POSES: f64 = 100_000.0;

/// What the stock saw over the run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StockSummary {
    /// The stock's volume at the start, mm³.
    pub start_volume: f64,
    /// Its volume at the end, mm³.
    pub end_volume: f64,
    /// Volume removed by each tool, mm³.
    pub removed: BTreeMap<u32, f64>,
    /// Programmed time of feed moves that removed nothing, seconds.
    pub air_cut_seconds: f64,
    /// The model's cell size, mm.
    pub resolution: f64,
}

/// Findings in progress: consecutive segments with the same trouble.
#[derive(Clone, Copy, Debug)]
struct Run {
    line: u32,
    order: u64,
    depth: f64,
    /// Where: in the table frame, and in the workpiece coordinates of
    /// its segment.
    at: [Vec3; 2],
    joints: Joints,
}

/// The troubles a run is kept for.
const RAPID: usize = 0;
const SHANK: usize = 1;
const HOLDER: usize = 2;
const GOUGE: usize = 3;

/// Poses cut at once: enough to share out over the cores (a pose of a
/// finishing tool at 0.2 mm is some 50 µs of cutting), few enough that
/// the poses held stay small.
const BATCH: usize = 512;

/// A segment whose poses are queued or being cut.
#[derive(Clone, Copy, Debug)]
struct Queued {
    line: u32,
    order: u64,
    rapid: bool,
    tool: u32,
    /// Its programmed time, for the time cutting air.
    minutes: f64,
    /// Its work offset and setup error, for places in findings.
    work: Vec3,
    setup: SetupError,
    /// Its poses not yet cut.
    remaining: usize,
}

/// What the poses of the segment being cut did so far.
#[derive(Clone, Copy, Debug, Default)]
struct Tally {
    removed: f64,
    worst: [Option<(f64, [Vec3; 2], Joints)>; 4],
    /// A rapid move's path through the stock so far, and its last tip.
    through: f64,
    previous: Option<Vec3>,
}

impl Tally {
    fn note(&mut self, which: usize, depth: f64, at: [Vec3; 2], q: Joints) {
        if self.worst[which].is_none_or(|w| depth > w.0) {
            self.worst[which] = Some((depth, at, q));
        }
    }
}

/// The stock check of one run.
pub struct StockCheck {
    stock: Stock,
    /// Each tool's pieces, by index (the poses name them so).
    pieces: Vec<ToolPieces>,
    /// Per tool number: its index in `pieces`, its length, and how far
    /// any of its points lies from its tip, mm.
    tools: BTreeMap<u32, (usize, f64, f64)>,
    /// Threads to cut on.
    lanes: usize,
    /// Segments queued, oldest first, and their poses with the machine
    /// position of each.
    queue: std::collections::VecDeque<Queued>,
    poses: Vec<Pose>,
    joints: Vec<Joints>,
    outcomes: Vec<Outcome>,
    tally: Tally,
    table: Link,
    start_volume: f64,
    tool: Option<u32>,
    /// The machine position the last pose was cut at.
    last: Option<Joints>,
    removed: BTreeMap<u32, f64>,
    air_minutes: f64,
    runs: [Option<Run>; 4],
    /// The work zero in the stock's frame, for the places of material
    /// left on the part (a move's findings use its own block's frame).
    zero: Vec3,
    /// Where the stock goes at the end, when the caller keeps it.
    keep: Option<std::sync::Arc<std::sync::Mutex<Option<Stock>>>>,
}

impl std::fmt::Debug for StockCheck {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StockCheck")
            .field("tool", &self.tool)
            .finish_non_exhaustive()
    }
}

impl StockCheck {
    /// The check of `stock` on `machine`'s table with the tools of
    /// `offsets`, the work zero at `zero` of the table frame.
    pub fn new(machine: &Machine, offsets: &Offsets, stock: Stock, zero: Vec3) -> Self {
        let numbers: std::collections::BTreeSet<u32> = offsets
            .tools
            .keys()
            .chain(offsets.tool_shapes.keys())
            .copied()
            .collect();
        let mut pieces = Vec::new();
        let mut tools = BTreeMap::new();
        for n in numbers {
            let solid = offsets.tool_solid(n);
            let tool = ToolPieces::of(&solid.shape, solid.length, solid.radius);
            let reach = tool
                .cutting
                .iter()
                .chain(&tool.shank)
                .chain(&tool.holder)
                .map(|p| match *p {
                    Piece::Sphere { at, radius } => at + radius,
                    Piece::Frustum { a1, r0, r1, .. } => a1 + r0.max(r1),
                })
                .fold(0.0, f64::max);
            tools.insert(n, (pieces.len(), solid.length, reach));
            pieces.push(tool);
        }
        let table = machine.work_link();
        let start_volume = stock.dexels.volume();
        let lanes = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
        Self {
            stock,
            pieces,
            tools,
            lanes,
            queue: std::collections::VecDeque::new(),
            poses: Vec::with_capacity(BATCH),
            joints: Vec::with_capacity(BATCH),
            outcomes: Vec::with_capacity(BATCH),
            tally: Tally::default(),
            table,
            start_volume,
            tool: None,
            last: None,
            removed: BTreeMap::new(),
            air_minutes: 0.0,
            runs: [None; 4],
            zero,
            keep: None,
        }
    }

    /// Hands the stock as the run leaves it to `slot` at the end.
    pub fn keep_final(&mut self, slot: std::sync::Arc<std::sync::Mutex<Option<Stock>>>) {
        self.keep = Some(slot);
    }

    /// Cuts on at most `lanes` threads (all the cores unless told).
    pub fn set_lanes(&mut self, lanes: usize) {
        self.lanes = lanes.max(1);
    }

    /// The stock model as the run has cut it so far, once the poses
    /// queued are cut (their findings to `add`).
    pub(crate) fn model_mut(
        &mut self,
        machine: &Machine,
        add: &mut impl FnMut(Finding),
    ) -> &mut Stock {
        self.flush(machine, add);
        &mut self.stock
    }

    /// The first segment order of a finding still open or of a segment
    /// still queued, if any.
    pub(crate) fn open_order(&self) -> Option<u64> {
        self.runs
            .iter()
            .flatten()
            .map(|r| r.order)
            .chain(self.queue.front().map(|q| q.order))
            .min()
    }

    /// The tool's tip and axis (tip towards the holder) in the stock's
    /// frame at machine position `q`, for a tool `length` long.
    fn tool_pose(&self, machine: &Machine, q: &Joints, length: f64) -> (Vec3, Vec3) {
        let head = machine.link_pose(Link::Head, q);
        let table = machine.link_pose(self.table, q);
        let rel = table.inverse() * head;
        let t0 = machine.tool_direction.into_inner();
        let tip = rel * nalgebra::Point3::from(-length * t0);
        (tip.coords, rel.rotation * t0)
    }

    /// Cuts along one moving segment (`order`: its place in the run).
    pub(crate) fn segment(
        &mut self,
        machine: &Machine,
        seg: &Segment,
        order: u64,
        add: &mut impl FnMut(Finding),
    ) {
        if self.tool != Some(seg.tool) {
            self.close_all(machine, add);
            self.tool = Some(seg.tool);
            self.last = None;
        }
        let rapid = seg.motion == Motion::Rapid;
        let Some(&(tool, length, reach)) = self.tools.get(&seg.tool) else {
            if !rapid {
                self.air_minutes += block_minutes(machine, seg);
            }
            return;
        };
        let step = self.stock.dexels.cell;
        let q0 = seg.eval(machine, 0.0);
        let qm = seg.eval(machine, 0.5);
        let q1 = seg.eval(machine, 1.0);
        let (p0, u0) = self.tool_pose(machine, &q0, length);
        let (pm, um) = self.tool_pose(machine, &qm, length);
        let (p1, u1) = self.tool_pose(machine, &q1, length);
        let turn = u0.angle(&um) + um.angle(&u1);
        let travel = (pm - p0).norm() + (p1 - pm).norm() + turn * reach;
        let n = (travel / step).ceil().clamp(1.0, MAX_POSES) as u32;
        let first = if self.last == Some(q0) { 1 } else { 0 };
        self.queue.push_back(Queued {
            line: seg.line,
            order,
            rapid,
            tool: seg.tool,
            minutes: if rapid {
                0.0
            } else {
                block_minutes(machine, seg)
            },
            work: seg.work,
            setup: seg.setup,
            remaining: (n + 1 - first) as usize,
        });
        for k in first..=n {
            let s = f64::from(k) / f64::from(n);
            let q = if k == n { q1 } else { seg.eval(machine, s) };
            let (tip, axis) = self.tool_pose(machine, &q, length);
            self.poses.push(Pose {
                tool,
                tip,
                axis,
                line: seg.line,
                measure_depth: rapid,
            });
            self.joints.push(q);
            if self.poses.len() >= BATCH {
                self.flush(machine, add);
            }
        }
        self.last = Some(q1);
    }

    /// Cuts the poses queued, in order, and settles the segments they
    /// finish.
    fn flush(&mut self, machine: &Machine, add: &mut impl FnMut(Finding)) {
        let mut outcomes = std::mem::take(&mut self.outcomes);
        self.stock
            .run(&self.pieces, &self.poses, &mut outcomes, self.lanes);
        let mut next = 0;
        while let Some(&front) = self.queue.front() {
            let take = front.remaining.min(outcomes.len() - next);
            // Places in the workpiece coordinates of the segment.
            let work = |p: &Vec3| front.setup.inverse_point(&(p - front.work));
            let range = next..next + take;
            for ((o, pose), &q) in outcomes[range.clone()]
                .iter()
                .zip(&self.poses[range.clone()])
                .zip(&self.joints[range])
            {
                let tally = &mut self.tally;
                let tip = pose.tip;
                tally.removed += o.cut.removed;
                // A rapid move's path through the stock: the tip's
                // travel while the tool removes material.
                if front.rapid && o.cut.depth > CONTACT_DEPTH {
                    tally.through += tally.previous.map_or(o.cut.depth, |p| (tip - p).norm());
                    tally.note(RAPID, tally.through, [tip, work(&tip)], q);
                }
                tally.previous = Some(tip);
                if o.cut.gouge > 0.0 {
                    let at = o.cut.gouge_at;
                    tally.note(GOUGE, o.cut.gouge, [at, work(&at)], q);
                }
                for (which, depth) in [(SHANK, o.shank), (HOLDER, o.holder)] {
                    if depth > CONTACT_DEPTH {
                        tally.note(which, depth, [tip, work(&tip)], q);
                    }
                }
            }
            next += take;
            if take < front.remaining {
                if let Some(f) = self.queue.front_mut() {
                    f.remaining -= take;
                }
                break;
            }
            self.queue.pop_front();
            let tally = std::mem::take(&mut self.tally);
            self.settle(machine, &front, &tally, add);
        }
        self.poses.clear();
        self.joints.clear();
        self.outcomes = outcomes;
    }

    /// A segment's cuts done: its volume, its time cutting air, and the
    /// findings it starts, continues or ends.
    fn settle(
        &mut self,
        machine: &Machine,
        seg: &Queued,
        tally: &Tally,
        add: &mut impl FnMut(Finding),
    ) {
        *self.removed.entry(seg.tool).or_insert(0.0) += tally.removed;
        if !seg.rapid && tally.removed < AIR_CUT_VOLUME {
            self.air_minutes += seg.minutes;
        }
        for (which, worst) in tally.worst.into_iter().enumerate() {
            match (worst, &mut self.runs[which]) {
                (Some((depth, at, joints)), Some(run)) => {
                    if depth > run.depth {
                        run.depth = depth;
                        run.at = at;
                        run.joints = joints;
                    }
                }
                (Some((depth, at, joints)), slot @ None) => {
                    *slot = Some(Run {
                        line: seg.line,
                        order: seg.order,
                        depth,
                        at,
                        joints,
                    });
                }
                (None, slot @ Some(_)) => {
                    if let Some(run) = slot.take() {
                        add(self.finding(machine, which, run));
                    }
                }
                (None, None) => {}
            }
        }
    }

    /// Ends every finding in progress (a tool change, the run's end).
    pub(crate) fn close_all(&mut self, machine: &Machine, add: &mut impl FnMut(Finding)) {
        self.flush(machine, add);
        for which in 0..4 {
            if let Some(run) = self.runs[which].take() {
                add(self.finding(machine, which, run));
            }
        }
    }

    fn finding(&self, machine: &Machine, which: usize, run: Run) -> Finding {
        let tool = match self.tool {
            Some(t) if t > 0 => format!("T{t}"),
            _ => "the tool".into(),
        };
        let at = crate::collision::positions(machine, &run.joints);
        let depth = round3(run.depth);
        let (kind, message, bodies) = match which {
            RAPID => (
                Kind::RapidIntoStock,
                format!("a rapid move takes {tool} through {depth} mm of stock, to {at}"),
                None,
            ),
            SHANK | HOLDER => {
                let part = if which == SHANK { "shank" } else { "holder" };
                (
                    Kind::Collision,
                    format!("the {part} of {tool} runs {depth} mm into the stock at {at}"),
                    Some(Box::new([part.to_string(), "stock".to_string()])),
                )
            }
            _ => {
                let p = run.at[1];
                (
                    Kind::Gouge,
                    format!(
                        "{tool} cuts {depth} mm into the part (tolerance {} mm) at X{} Y{} Z{} of the work, machine at {at}",
                        self.stock.tolerance,
                        round3(p.x),
                        round3(p.y),
                        round3(p.z)
                    ),
                    None,
                )
            }
        };
        Finding {
            kind,
            line: run.line,
            message: message.into(),
            axis: None,
            value: Some(run.depth),
            bodies,
            point: Some(run.at[0].into()),
            order: run.order,
        }
    }

    /// The material left on the part, as findings at the lines that last
    /// cut there, and what the stock saw over the run.
    pub(crate) fn finish(self, add: &mut impl FnMut(Finding)) -> StockSummary {
        for (line, most, at, volume) in self.stock.left_on_part() {
            let point = Some(at.into());
            let at = at - self.zero;
            let message = if line == 0 {
                format!(
                    "{} mm of material left on the part where no move cut (tolerance {} mm), {} mm³ in all, the most at X{} Y{} Z{} of the work",
                    round3(most),
                    self.stock.tolerance,
                    round3(volume),
                    round3(at.x),
                    round3(at.y),
                    round3(at.z)
                )
            } else {
                format!(
                    "{} mm of material left on the part where this block cut last (tolerance {} mm), {} mm³ in all, the most at X{} Y{} Z{} of the work",
                    round3(most),
                    self.stock.tolerance,
                    round3(volume),
                    round3(at.x),
                    round3(at.y),
                    round3(at.z)
                )
            };
            add(Finding {
                kind: Kind::Excess,
                line: line.max(1),
                message: message.into(),
                axis: None,
                value: Some(most),
                bodies: None,
                point,
                order: u64::MAX,
            });
        }
        let summary = StockSummary {
            start_volume: self.start_volume,
            end_volume: self.stock.dexels.volume(),
            removed: self.removed,
            air_cut_seconds: self.air_minutes * 60.0,
            resolution: self.stock.dexels.cell,
        };
        if let Some(slot) = self.keep
            && let Ok(mut slot) = slot.lock()
        {
            *slot = Some(self.stock);
        }
        summary
    }
}
