//! Collision checking for the kernel: the machine's bodies (`[[body]]`),
//! the tool, its shank and holder, fixtures and stock, placed by forward
//! kinematics (`Machine::link_pose`) all along a move, not only at its
//! ends.
//!
//! A move is sampled so densely that between two samples no point of any
//! part moves by more than half the clearance relative to any other: a
//! contact anywhere between samples leaves the two parts nearer than the
//! clearance at a sample, so it is found, as a collision or as a near
//! miss. The bound is each joint's change times the part's reach from
//! that joint's axis line (`Part::reach`), summed over the joints.
//! Distances and penetration depths are parry's (`parry3d-f64`).

pub mod shapes;
pub mod work;

use fiveaxis_machine::geometry::{Link, ToolShape};
use fiveaxis_machine::{Joints, MAX_AXES, Machine, Side, Vec3};
use parry3d_f64::query::{self, ClosestPoints};
use parry3d_f64::shape::SharedShape;

/// Most halvings of a move when its samples are refined.
const MAX_DEPTH: u32 = 24;

/// What a part is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PartKind {
    /// A body of the machine file.
    Machine,
    /// The tool's cutting part.
    Tool,
    /// The tool's shank (not cutting).
    Shank,
    /// The tool holder.
    Holder,
    /// A fixture or clamp.
    Fixture,
    /// The raw stock.
    Stock,
}

/// A solid the check places and tests.
#[derive(Clone)]
pub struct Part {
    /// Its name in findings.
    pub name: String,
    /// What it is.
    pub kind: PartKind,
    /// What it moves with.
    pub on: Link,
    /// Its shape in its link's frame.
    pub shape: SharedShape,
    /// How far any of its points lies from each joint's motion: 1 for a
    /// linear joint that moves it, for a rotary joint that turns it a
    /// bound on its distance from the axis line (mm per radian), 0 for a
    /// joint that does not move it.
    pub reach: [f64; MAX_AXES],
    /// Its bounding sphere in its link's frame: centre and radius.
    pub sphere: (Vec3, f64),
}

impl std::fmt::Debug for Part {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Part")
            .field("name", &self.name)
            .field("kind", &self.kind)
            .field("on", &self.on)
            .finish_non_exhaustive()
    }
}

/// Two parts closer than the clearance during a move.
#[derive(Clone, Debug, PartialEq)]
pub struct Contact {
    /// The two parts' names.
    pub bodies: [String; 2],
    /// Where along the move it was found first (0 at its start, 1 at its
    /// end).
    pub s: f64,
    /// The machine positions there.
    pub joints: Joints,
    /// The smallest distance found, mm (0: they touch or overlap).
    pub distance: f64,
    /// The largest penetration depth found, mm (0 for a near miss).
    pub depth: f64,
}

impl Contact {
    /// Whether the two parts touch (a collision, not a near miss).
    pub fn collides(&self) -> bool {
        self.distance <= 0.0
    }
}

/// The parts of a machine and its work, and which pairs must not touch.
#[derive(Debug)]
pub struct Scene {
    parts: Vec<Part>,
    pairs: Vec<(usize, usize)>,
    /// Distance under which two parts count as a near miss, mm.
    pub clearance: f64,
}

/// Which side of the machine a link is on: the tool's (it moves with X,
/// Y, Z) or the work's.
fn tool_side(machine: &Machine, link: Link) -> bool {
    match link {
        Link::Base => false,
        Link::Head => true,
        Link::Axis(i) if i < machine.linear.len() => true,
        Link::Axis(i) => machine
            .rotary
            .get(i - machine.linear.len())
            .is_some_and(|r| r.on == Side::Head),
    }
}

/// The reach of a shape on `link` from every joint (`Part::reach`).
fn reach(machine: &Machine, link: Link, shape: &SharedShape) -> [f64; MAX_AXES] {
    let sphere = shape.compute_local_bounding_sphere();
    let c = sphere.center();
    let center = Vec3::new(c.x, c.y, c.z);
    let radius = sphere.radius();
    let mut reach = [0.0; MAX_AXES];
    let first = machine.linear.len();
    // The rotary axes that carry the link, bed (or carriage) outwards.
    let (side, last) = match link {
        Link::Base => return reach,
        Link::Head => (Side::Head, machine.rotary.len()),
        Link::Axis(i) if i < first => {
            reach[i] = 1.0;
            return reach;
        }
        Link::Axis(i) => {
            let k = i - first;
            (machine.rotary[k].on, k + 1)
        }
    };
    if side == Side::Head {
        for r in reach.iter_mut().take(first.min(3)) {
            *r = 1.0;
        }
    }
    let chain: Vec<usize> = (0..last)
        .filter(|&k| machine.rotary[k].on == side)
        .collect();
    // A point turns about axis k at most as far from its line as from a
    // point of it; the axes beyond k turn it about their own centres,
    // which stay at fixed distances from each other.
    for (n, &k) in chain.iter().enumerate() {
        let mut d = 0.0;
        let mut at = machine.rotary[k].center;
        for &j in &chain[n + 1..] {
            d += (machine.rotary[j].center - at).norm();
            at = machine.rotary[j].center;
        }
        d += (center - at).norm() + radius;
        reach[first + k] = d;
    }
    reach
}

impl Scene {
    /// The machine's bodies, none of the tool or the work yet.
    pub fn new(machine: &Machine, clearance: f64) -> Self {
        let mut scene = Self {
            parts: Vec::new(),
            pairs: Vec::new(),
            clearance,
        };
        for body in &machine.bodies {
            if let Some(shape) = shapes::body(&body.solids) {
                scene.push(
                    machine,
                    body.name.clone(),
                    PartKind::Machine,
                    body.on,
                    shape,
                );
            }
            // Its meshes, each a part of the same name.
            for solid in &body.solids {
                if let Some(shape) = shapes::mesh_solid(solid, &machine.meshes) {
                    scene.push(
                        machine,
                        body.name.clone(),
                        PartKind::Machine,
                        body.on,
                        shape,
                    );
                }
            }
        }
        scene
    }

    fn push(
        &mut self,
        machine: &Machine,
        name: String,
        kind: PartKind,
        on: Link,
        shape: SharedShape,
    ) {
        let reach = reach(machine, on, &shape);
        let bound = shape.compute_local_bounding_sphere();
        let c = bound.center();
        let sphere = (Vec3::new(c.x, c.y, c.z), bound.radius());
        self.parts.push(Part {
            name,
            kind,
            on,
            shape,
            reach,
            sphere,
        });
        self.refresh_pairs(machine);
    }

    /// The pairs that must not touch: a part that moves with the tool
    /// and one of the work's side; two machine bodies of different links
    /// on the work's side. Two machine bodies that touch with every axis
    /// at 0 are assembled, not colliding (a round table drawn on its
    /// cradle, a shaft in its bearing, a table on the saddle it slides
    /// on: as a robot's links in contact at rest are left out of its
    /// collision checks), unless one is the spindle head. The cutting
    /// part against the stock is cutting, not a collision.
    fn refresh_pairs(&mut self, machine: &Machine) {
        self.pairs.clear();
        for a in 0..self.parts.len() {
            for b in a + 1..self.parts.len() {
                let (pa, pb) = (&self.parts[a], &self.parts[b]);
                let (ta, tb) = (tool_side(machine, pa.on), tool_side(machine, pb.on));
                let cutting =
                    |p: &Part, q: &Part| p.kind == PartKind::Tool && q.kind == PartKind::Stock;
                if cutting(pa, pb) || cutting(pb, pa) {
                    continue;
                }
                let across = ta != tb;
                let work_bodies = !ta
                    && !tb
                    && pa.on != pb.on
                    && pa.kind == PartKind::Machine
                    && pb.kind == PartKind::Machine;
                if (across || work_bodies) && self.assembled(machine, a, b) {
                    continue;
                }
                // The part on the tool's side first: it is what hits.
                if across && tb {
                    self.pairs.push((b, a));
                } else if across || work_bodies {
                    self.pairs.push((a, b));
                }
            }
        }
    }

    /// Whether parts `a` and `b` are machine bodies assembled together:
    /// they touch with every axis at 0, and neither is the spindle head.
    fn assembled(&self, machine: &Machine, a: usize, b: usize) -> bool {
        let (pa, pb) = (&self.parts[a], &self.parts[b]);
        let bodies = pa.kind == PartKind::Machine && pb.kind == PartKind::Machine;
        if !bodies || pa.on == Link::Head || pb.on == Link::Head {
            return false;
        }
        let home = [0.0; MAX_AXES];
        let pose_a = shapes::pose(&machine.link_pose(pa.on, &home));
        let pose_b = shapes::pose(&machine.link_pose(pb.on, &home));
        // Touching counts: a micrometre apart.
        matches!(
            query::closest_points(&pose_a, &*pa.shape, &pose_b, &*pb.shape, 1e-3),
            Ok(ClosestPoints::Intersecting | ClosestPoints::WithinMargin(..))
        )
    }

    /// The tool in the spindle: its cutting part, shank and holder from
    /// `shape`, `length` and `radius` (replacing a tool given before).
    pub fn set_tool(&mut self, machine: &Machine, shape: &ToolShape, length: f64, radius: f64) {
        self.parts
            .retain(|p| !matches!(p.kind, PartKind::Tool | PartKind::Shank | PartKind::Holder));
        let t0 = machine.tool_direction.into_inner();
        let [cutting, shank, holder] = shapes::tool(shape, length, radius, &t0);
        for (kind, name, part) in [
            (PartKind::Tool, "tool", cutting),
            (PartKind::Shank, "shank", shank),
            (PartKind::Holder, "holder", holder),
        ] {
            if let Some(part) = part {
                self.push(machine, name.into(), kind, Link::Head, part);
            }
        }
        self.refresh_pairs(machine);
    }

    /// A fixture or the stock, placed in the table frame (the machine
    /// frame with the table's axes at 0), turning with the table.
    pub fn add_work(&mut self, machine: &Machine, name: &str, kind: PartKind, shape: SharedShape) {
        self.push(machine, name.into(), kind, machine.work_link(), shape);
    }

    /// The parts.
    pub fn parts(&self) -> &[Part] {
        &self.parts
    }

    /// The pairs tested, by index into [`Scene::parts`].
    pub fn pairs(&self) -> &[(usize, usize)] {
        &self.pairs
    }

    /// The distance of pair `pair` at `joints` (0 when they touch), or
    /// `limit` when it is at least that: far pairs are settled by their
    /// bounding spheres, or by parry's search bounded by `limit`, without
    /// finding their closest points.
    fn distance(&self, machine: &Machine, pair: usize, joints: &Joints, limit: f64) -> f64 {
        let (a, b) = self.pairs[pair];
        let (pa, pb) = (&self.parts[a], &self.parts[b]);
        let ia = machine.link_pose(pa.on, joints);
        let ib = machine.link_pose(pb.on, joints);
        let ca = ia * nalgebra::Point3::from(pa.sphere.0);
        let cb = ib * nalgebra::Point3::from(pb.sphere.0);
        if (ca - cb).norm() - pa.sphere.1 - pb.sphere.1 >= limit {
            return limit;
        }
        let (pose_a, pose_b) = (shapes::pose(&ia), shapes::pose(&ib));
        match query::closest_points(&pose_a, &*pa.shape, &pose_b, &*pb.shape, limit) {
            Ok(ClosestPoints::Intersecting) => 0.0,
            Ok(ClosestPoints::WithinMargin(p, q)) => (p - q).length().min(limit),
            Ok(ClosestPoints::Disjoint) => limit,
            Err(_) => query::distance(&pose_a, &*pa.shape, &pose_b, &*pb.shape)
                .map_or(limit, |d| d.distance.min(limit)),
        }
    }

    /// The penetration depth of pair `pair` at `joints` (0 when apart).
    pub fn depth(&self, machine: &Machine, pair: usize, joints: &Joints) -> f64 {
        let (a, b) = self.pairs[pair];
        let pa = shapes::pose(&machine.link_pose(self.parts[a].on, joints));
        let pb = shapes::pose(&machine.link_pose(self.parts[b].on, joints));
        query::contact(&pa, &*self.parts[a].shape, &pb, &*self.parts[b].shape, 0.0)
            .ok()
            .flatten()
            .map_or(0.0, |c| (-c.dist).max(0.0))
    }

    /// Where pair `pair` meets at `joints`, in the machine frame: the
    /// middle of the two parts' nearest points (of their deepest points
    /// when they overlap); `None` when they are farther apart than twice
    /// the clearance.
    pub fn witness(&self, machine: &Machine, pair: usize, joints: &Joints) -> Option<Vec3> {
        let (a, b) = self.pairs[pair];
        let pa = shapes::pose(&machine.link_pose(self.parts[a].on, joints));
        let pb = shapes::pose(&machine.link_pose(self.parts[b].on, joints));
        let prediction = 2.0 * self.clearance;
        let c = query::contact(
            &pa,
            &*self.parts[a].shape,
            &pb,
            &*self.parts[b].shape,
            prediction,
        )
        .ok()
        .flatten()?;
        let m = (c.point1 + c.point2) / 2.0;
        Some(Vec3::new(m.x, m.y, m.z))
    }

    /// How far any point of pair `pair` can move relative to the other
    /// between machine positions `q0` and `q1` (joints linear between).
    fn travel(&self, machine: &Machine, pair: usize, q0: &Joints, q1: &Joints) -> f64 {
        let (a, b) = self.pairs[pair];
        let first = machine.linear.len();
        let mut sum = 0.0;
        for i in 0..machine.axis_count() {
            let mut dq = (q1[i] - q0[i]).abs();
            if i >= first {
                dq = dq.to_radians();
            }
            sum += dq * (self.parts[a].reach[i] + self.parts[b].reach[i]);
        }
        sum
    }

    /// The contacts of a move whose machine positions are `joints_at(s)`
    /// for s from 0 to 1: per pair, the first instant nearer than the
    /// clearance, the smallest distance and the largest depth.
    ///
    /// Each pair is refined on its own (conservative advancement): a span
    /// between two samples whose distances `d0` and `d1` exceed the
    /// relative travel `T` by the clearance (`d0 + d1 − T ≥ clearance`)
    /// keeps the pair at least half the clearance apart throughout, and a
    /// span with `T` at most half the clearance is fine enough; other
    /// spans are halved. A contact is never missed, nor a near miss under
    /// half the clearance. Each contact comes with its pair's index into
    /// [`Scene::pairs`].
    pub fn check_move(
        &self,
        machine: &Machine,
        joints_at: impl Fn(f64) -> Joints,
    ) -> Vec<(usize, Contact)> {
        let mut found = Vec::new();
        if self.pairs.is_empty() {
            return found;
        }
        let q0 = joints_at(0.0);
        let q1 = joints_at(1.0);
        // Spans still to refine: (s0, q0, d0, s1, q1, d1, depth).
        let mut stack: Vec<(f64, Joints, f64, f64, Joints, f64, u32)> = Vec::new();
        for pair in 0..self.pairs.len() {
            // Nearer than the clearance anywhere only if nearer than the
            // travel and the clearance at the start: distances beyond that
            // are not needed exactly.
            let limit = self.travel(machine, pair, &q0, &q1) + 2.0 * self.clearance;
            let d0 = self.distance(machine, pair, &q0, limit);
            if d0 >= limit {
                continue;
            }
            let d1 = self.distance(machine, pair, &q1, limit);
            let mut contact: Option<Contact> = None;
            let mut note = |s: f64, q: &Joints, d: f64| {
                if d >= self.clearance {
                    return;
                }
                let depth = if d <= 0.0 {
                    self.depth(machine, pair, q)
                } else {
                    0.0
                };
                let (a, b) = self.pairs[pair];
                let entry = contact.get_or_insert_with(|| Contact {
                    bodies: [self.parts[a].name.clone(), self.parts[b].name.clone()],
                    s,
                    joints: *q,
                    distance: d,
                    depth,
                });
                entry.distance = entry.distance.min(d);
                entry.depth = entry.depth.max(depth);
            };
            note(0.0, &q0, d0);
            stack.clear();
            stack.push((0.0, q0, d0, 1.0, q1, d1, 0));
            while let Some((s0, qa, da, s1, qb, db, depth)) = stack.pop() {
                let travel = self.travel(machine, pair, &qa, &qb);
                let apart = da + db - travel >= self.clearance;
                if apart || travel <= self.clearance / 2.0 || depth >= MAX_DEPTH {
                    // Spans are taken in order: the end is the next
                    // sample.
                    note(s1, &qb, db);
                    continue;
                }
                let sm = (s0 + s1) / 2.0;
                let qm = joints_at(sm);
                let dm = self.distance(machine, pair, &qm, limit);
                // The later half first on the stack: the earlier half is
                // taken first.
                stack.push((sm, qm, dm, s1, qb, db, depth + 1));
                stack.push((s0, qa, da, sm, qm, dm, depth + 1));
            }
            found.extend(contact.map(|c| (pair, c)));
        }
        found
    }
}
