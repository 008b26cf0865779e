//! Cutting on several cores: the grid's rows dealt out to lanes (row `j`
//! to lane `j mod lanes`), each lane cutting every pose of a batch in
//! order on its own rows. A ray is only ever cut by its own lane, in
//! program order, so the stock left is the one a single thread leaves;
//! what a pose did is the sum (volume) or the largest (gouge, depth, the
//! shank's and holder's contact) of what it did in each lane. Rows
//! interleave so that the lanes share the work wherever the tool is.

use fiveaxis_machine::Vec3;

use crate::dexel::{self, Dexels, Span, Spans};
use crate::solid::{Posed, ToolPieces};
use crate::{Cut, Part, Touched};

/// One pose of a tool to cut with ([`crate::Stock::run`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// The tool: an index into the tools handed over with the poses.
    pub tool: usize,
    /// Its tip, in the stock's frame.
    pub tip: Vec3,
    /// Its axis, from the tip towards the holder.
    pub axis: Vec3,
    /// The program line, kept with each ray it cuts.
    pub line: u32,
    /// Whether to measure how deep the material reached into the cutter
    /// before the cut (a rapid move).
    pub measure_depth: bool,
}

/// What one pose did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Outcome {
    /// Its cut.
    pub cut: Cut,
    /// How deep the material left after the cut reaches into the shank,
    /// mm (0: it does not meet it).
    pub shank: f64,
    /// The same for the holder.
    pub holder: f64,
}

impl Outcome {
    /// The pose's outcome from those of two lanes (the earlier lane's
    /// gouge on a tie).
    fn merge(&mut self, other: &Outcome) {
        self.cut.removed += other.cut.removed;
        if other.cut.gouge > self.cut.gouge {
            self.cut.gouge = other.cut.gouge;
            self.cut.gouge_at = other.cut.gouge_at;
        }
        self.cut.depth = self.cut.depth.max(other.cut.depth);
        self.shank = self.shank.max(other.shank);
        self.holder = self.holder.max(other.holder);
    }
}

/// What every lane reads: the grid (its rays taken out), the part, the
/// tolerance and the highest material.
pub(crate) struct Shared<'a> {
    pub grid: &'a Dexels,
    pub part: Option<&'a Part>,
    pub tolerance: f64,
    pub top: f32,
}

/// The rows of one lane: row `first + stride · n` is `rays[n]`.
pub(crate) struct Lane<'a> {
    first: usize,
    stride: usize,
    rays: Vec<&'a mut [Spans]>,
    /// The line that last cut each ray, when there is a part.
    lines: Vec<&'a mut [u32]>,
    /// The rays this lane cut.
    pub touched: Option<Touched>,
}

/// Deals the rows of `rays` (and of `lines`, empty without a part) out to
/// `lanes` lanes.
pub(crate) fn deal<'a>(
    rays: &'a mut [Spans],
    lines: &'a mut [u32],
    nx: usize,
    lanes: usize,
) -> Vec<Lane<'a>> {
    let lanes = lanes.max(1);
    let mut out: Vec<Lane<'a>> = (0..lanes)
        .map(|first| Lane {
            first,
            stride: lanes,
            rays: Vec::new(),
            lines: Vec::new(),
            touched: None,
        })
        .collect();
    for (j, row) in rays.chunks_mut(nx.max(1)).enumerate() {
        out[j % lanes].rays.push(row);
    }
    for (j, row) in lines.chunks_mut(nx.max(1)).enumerate() {
        out[j % lanes].lines.push(row);
    }
    out
}

impl Shared<'_> {
    /// Whether `posed` may reach the stock at all (its box against the
    /// grid and the top of the material).
    pub fn may_meet(&self, posed: &Posed) -> bool {
        let d = self.grid;
        let hi_x = d.origin.x + d.cell * d.nx as f64;
        let hi_y = d.origin.y + d.cell * d.ny as f64;
        !posed.pieces.is_empty()
            && posed.min.z - d.origin.z <= f64::from(self.top)
            && posed.max.x >= d.origin.x
            && posed.min.x <= hi_x
            && posed.max.y >= d.origin.y
            && posed.min.y <= hi_y
    }

    /// Cuts every pose of `poses` in order on `lane`'s rows, one outcome
    /// each into `out`.
    pub fn run(
        &self,
        lane: &mut Lane<'_>,
        tools: &[ToolPieces],
        poses: &[Pose],
        out: &mut Vec<Outcome>,
    ) {
        out.clear();
        for pose in poses {
            let Some(pieces) = tools.get(pose.tool) else {
                out.push(Outcome::default());
                continue;
            };
            let cutter = Posed::new(&pieces.cutting, &pose.tip, &pose.axis);
            let cut = self.cut(lane, &cutter, pose.line, pose.measure_depth);
            let mut contact = [0.0; 2];
            for (slot, part) in contact.iter_mut().zip([&pieces.shank, &pieces.holder]) {
                if !part.is_empty() {
                    *slot = self.interference(lane, &Posed::new(part, &pose.tip, &pose.axis));
                }
            }
            out.push(Outcome {
                cut,
                shank: contact[0],
                holder: contact[1],
            });
        }
    }

    /// Cuts the material of `lane`'s rows inside `cutter` (line `line`).
    pub fn cut(&self, lane: &mut Lane<'_>, cutter: &Posed, line: u32, measure_depth: bool) -> Cut {
        let mut cut = Cut::default();
        if !self.may_meet(cutter) {
            return cut;
        }
        let d = self.grid;
        let oz = d.origin.z;
        let floor = (cutter.min.z - oz) as f32;
        let tolerance = self.tolerance;
        let mut removed = 0.0f64;
        for j in lane.rows(d.rows(cutter.min.y, cutter.max.y)) {
            let n = (j - lane.first) / lane.stride;
            for i in d.columns(cutter.min.x, cutter.max.x) {
                let spans = &mut lane.rays[n][i];
                match spans.last() {
                    Some(top) if top[1] > floor => {}
                    _ => continue,
                }
                let (x, y) = d.centre(i, j);
                let Some((lo, hi)) = cutter.ray(x, y) else {
                    continue;
                };
                let (lo, hi) = ((lo - oz) as f32, (hi - oz) as f32);
                let k = j * d.nx + i;
                let mut gouge = (0.0, Vec3::zeros());
                let mut depth = 0.0f64;
                let length = dexel::subtract(spans, lo, hi, |piece: Span| {
                    if measure_depth {
                        for z in [piece[0], piece[1], (piece[0] + piece[1]) / 2.0] {
                            let p = Vec3::new(x, y, oz + f64::from(z));
                            depth = depth.max(cutter.depth(&p));
                        }
                    }
                    let Some(part) = self.part else { return };
                    part.dexels.overlap(k, piece[0], piece[1], |[c, e]| {
                        if f64::from(e - c) <= tolerance {
                            return;
                        }
                        for z in [c, e, (c + e) / 2.0] {
                            let p = Vec3::new(x, y, oz + f64::from(z));
                            let g = (part.depth)(&p);
                            if g > gouge.0 {
                                gouge = (g, p);
                            }
                        }
                    });
                });
                if length > 0.0 {
                    removed += f64::from(length);
                    Touched::add(&mut lane.touched, i, j);
                    if let Some(row) = lane.lines.get_mut(n) {
                        row[i] = line;
                    }
                    if gouge.0 > tolerance && gouge.0 > cut.gouge {
                        cut.gouge = gouge.0;
                        cut.gouge_at = gouge.1;
                    }
                    cut.depth = cut.depth.max(depth);
                }
            }
        }
        cut.removed = removed * d.cell * d.cell;
        cut
    }

    /// How deep the material of `lane`'s rows reaches into `solid` (0: it
    /// does not meet it), without cutting.
    pub fn interference(&self, lane: &Lane<'_>, solid: &Posed) -> f64 {
        if !self.may_meet(solid) {
            return 0.0;
        }
        let d = self.grid;
        let oz = d.origin.z;
        let floor = (solid.min.z - oz) as f32;
        let mut depth = 0.0f64;
        for j in lane.rows(d.rows(solid.min.y, solid.max.y)) {
            let n = (j - lane.first) / lane.stride;
            for i in d.columns(solid.min.x, solid.max.x) {
                let spans = &lane.rays[n][i];
                match spans.last() {
                    Some(top) if top[1] > floor => {}
                    _ => continue,
                }
                let (x, y) = d.centre(i, j);
                let Some((lo, hi)) = solid.ray(x, y) else {
                    continue;
                };
                let (lo, hi) = ((lo - oz) as f32, (hi - oz) as f32);
                for &[a, b] in spans.iter() {
                    if a >= hi {
                        break;
                    }
                    if b <= lo {
                        continue;
                    }
                    let piece = [a.max(lo), b.min(hi)];
                    for z in [piece[0], piece[1], (piece[0] + piece[1]) / 2.0] {
                        let p = Vec3::new(x, y, oz + f64::from(z));
                        depth = depth.max(solid.depth(&p));
                    }
                }
            }
        }
        depth
    }
}

impl Lane<'_> {
    /// The rows of `range` that are this lane's.
    fn rows(&self, range: std::ops::Range<usize>) -> impl Iterator<Item = usize> + use<> {
        let start =
            range.start + (self.first + self.stride - range.start % self.stride) % self.stride;
        (start..range.end).step_by(self.stride)
    }
}

/// Poses at least per lane for a batch to be shared out: fewer are cut
/// on the calling thread alone.
pub const POSES_PER_LANE: usize = 16;

/// Cuts `poses` on `lanes` lanes (the calling thread and `lanes − 1`
/// scoped threads), one outcome each into `out`.
pub(crate) fn run_lanes(
    shared: &Shared<'_>,
    mut lanes: Vec<Lane<'_>>,
    tools: &[ToolPieces],
    poses: &[Pose],
    out: &mut Vec<Outcome>,
) -> Option<Touched> {
    let mut touched = None;
    let Some((first, rest)) = lanes.split_first_mut() else {
        out.clear();
        return None;
    };
    let partial: Vec<Vec<Outcome>> = std::thread::scope(|scope| {
        let handles: Vec<_> = rest
            .iter_mut()
            .map(|lane| {
                scope.spawn(move || {
                    let mut mine = Vec::with_capacity(poses.len());
                    shared.run(lane, tools, poses, &mut mine);
                    mine
                })
            })
            .collect();
        shared.run(first, tools, poses, out);
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    for mine in &partial {
        for (o, m) in out.iter_mut().zip(mine) {
            o.merge(m);
        }
    }
    for lane in &lanes {
        Touched::merge(&mut touched, lane.touched);
    }
    touched
}
