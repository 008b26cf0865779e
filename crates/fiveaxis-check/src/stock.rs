//! The stock along the run: each move's cutting part removes material
//! (`fiveaxis-stock`), and the check reports what should not happen to
//! it: a rapid move into the stock, the shank or holder running into
//! what is left, a cut into the designed part (gouge) and material left
//! on it (excess); with the volume each tool removed and the time spent
//! cutting air.

use std::collections::BTreeMap;

use fiveaxis_control::{Motion, Segment};
use fiveaxis_machine::geometry::Link;
use fiveaxis_machine::{Joints, Machine, Offsets, Vec3};
use fiveaxis_stock::Stock;
use fiveaxis_stock::solid::{Posed, ToolPieces};

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

/// The stock check of one run.
pub struct StockCheck {
    stock: Stock,
    tools: BTreeMap<u32, (ToolPieces, f64)>,
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
        let tools = offsets
            .tools
            .keys()
            .chain(offsets.tool_shapes.keys())
            .map(|&n| {
                let solid = offsets.tool_solid(n);
                (
                    n,
                    (
                        ToolPieces::of(&solid.shape, solid.length, solid.radius),
                        solid.length,
                    ),
                )
            })
            .collect();
        let table = machine.work_link();
        let start_volume = stock.dexels.volume();
        Self {
            stock,
            tools,
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

    /// The stock model as the run has cut it so far.
    pub fn model_mut(&mut self) -> &mut Stock {
        &mut self.stock
    }

    /// The first segment order of a finding still open, if any.
    pub(crate) fn open_order(&self) -> Option<u64> {
        self.runs.iter().flatten().map(|r| r.order).min()
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
        let Some((pieces, length)) = self.tools.get(&seg.tool) else {
            if !rapid {
                self.air_minutes += block_minutes(machine, seg);
            }
            return;
        };
        let (pieces, length) = (pieces.clone(), *length);
        let step = self.stock.dexels.cell;
        let reach = pieces
            .cutting
            .iter()
            .chain(&pieces.shank)
            .chain(&pieces.holder)
            .map(|p| match *p {
                fiveaxis_stock::solid::Piece::Sphere { at, radius } => at + radius,
                fiveaxis_stock::solid::Piece::Frustum { a1, r0, r1, .. } => a1 + r0.max(r1),
            })
            .fold(0.0, f64::max);
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
        let mut removed = 0.0;
        let mut worst: [Option<(f64, [Vec3; 2], Joints)>; 4] = [None; 4];
        let mut note = |which: usize, depth: f64, at: [Vec3; 2], q: Joints| {
            if worst[which].is_none_or(|w| depth > w.0) {
                worst[which] = Some((depth, at, q));
            }
        };
        // A rapid move's path through the stock: the tip's travel while
        // the tool removes material.
        let mut through = 0.0;
        let mut previous: Option<Vec3> = None;
        // Places in the workpiece coordinates of the segment.
        let work = |p: &Vec3| seg.setup.inverse_point(&(p - seg.work));
        for k in first..=n {
            let s = f64::from(k) / f64::from(n);
            let q = if k == n { q1 } else { seg.eval(machine, s) };
            let (tip, axis) = self.tool_pose(machine, &q, length);
            let cutter = Posed::new(&pieces.cutting, &tip, &axis);
            let cut = self.stock.cut(&cutter, seg.line, rapid);
            removed += cut.removed;
            if rapid && cut.depth > CONTACT_DEPTH {
                through += previous.map_or(cut.depth, |p| (tip - p).norm());
                note(RAPID, through, [tip, work(&tip)], q);
            }
            previous = Some(tip);
            if cut.gouge > 0.0 {
                note(GOUGE, cut.gouge, [cut.gouge_at, work(&cut.gouge_at)], q);
            }
            for (which, part) in [(SHANK, &pieces.shank), (HOLDER, &pieces.holder)] {
                if part.is_empty() {
                    continue;
                }
                let solid = Posed::new(part, &tip, &axis);
                let depth = self.stock.interference(&solid);
                if depth > CONTACT_DEPTH {
                    note(which, depth, [tip, work(&tip)], q);
                }
            }
        }
        self.last = Some(q1);
        *self.removed.entry(seg.tool).or_insert(0.0) += removed;
        if !rapid && removed < AIR_CUT_VOLUME {
            self.air_minutes += block_minutes(machine, seg);
        }
        for (which, worst) in worst.into_iter().enumerate() {
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
                        order,
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
            message,
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
                message,
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
