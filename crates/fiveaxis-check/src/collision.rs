//! Collisions along the moves: the machine's bodies, the tool in the
//! spindle (its cutting part, shank and holder from the offsets file) and
//! the fixtures, checked continuously over each segment by
//! `fiveaxis-collide`. A contact that lasts several segments is one
//! finding, at its first line, as an over-travel excursion is.

use fiveaxis_collide::{Contact, PartKind, Scene};
use fiveaxis_control::Segment;

use fiveaxis_machine::{Joints, Machine, Offsets};
use parry3d_f64::shape::SharedShape;

use crate::{Finding, Kind, round3};

/// The clearance `check` uses unless told (`--clearance`), mm.
pub const DEFAULT_CLEARANCE: f64 = 0.5;

/// A solid of the work: a fixture or clamp, placed in the table frame.
pub struct WorkSolid {
    /// Its name in findings (the file's stem).
    pub name: String,
    /// Its shape in the table frame.
    pub shape: SharedShape,
}

impl std::fmt::Debug for WorkSolid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WorkSolid")
            .field("name", &self.name)
            .finish_non_exhaustive()
    }
}

/// A contact in progress: consecutive segments in which one pair is
/// nearer than the clearance.
#[derive(Clone, Debug)]
struct ContactRun {
    line: u32,
    order: u64,
    first: Contact,
    distance: f64,
    depth: f64,
    /// Where `first` meets, in the table frame.
    point: Option<[f64; 3]>,
}

/// The collision check of one run.
pub struct Collisions {
    scene: Scene,
    /// The tools' lengths, radii and shapes.
    tools: Offsets,
    /// The tool the scene holds (`None` before the first segment).
    tool: Option<u32>,
    /// Runs in progress, by pair index of the scene.
    runs: Vec<Option<ContactRun>>,
    /// Whether a pair was in contact in the segment being checked.
    touched: Vec<bool>,
}

impl std::fmt::Debug for Collisions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Collisions")
            .field("scene", &self.scene)
            .field("tool", &self.tool)
            .finish_non_exhaustive()
    }
}

impl Collisions {
    /// The check of `machine`'s bodies, the tools of `offsets` and the
    /// fixtures `work`, reporting parts nearer than `clearance` (mm).
    pub fn new(machine: &Machine, offsets: &Offsets, clearance: f64, work: Vec<WorkSolid>) -> Self {
        let mut scene = Scene::new(machine, clearance);
        for solid in work {
            scene.add_work(machine, &solid.name, PartKind::Fixture, solid.shape);
        }
        let tools = offsets.clone();
        Self {
            scene,
            tools,
            tool: None,
            runs: Vec::new(),
            touched: Vec::new(),
        }
    }

    /// The first segment order of a contact still open, if any.
    pub(crate) fn open_order(&self) -> Option<u64> {
        self.runs.iter().flatten().map(|r| r.order).min()
    }

    /// Checks one moving segment (`order`: its place in the run); the
    /// contacts that end hand their finding to `add`.
    pub(crate) fn segment(
        &mut self,
        machine: &Machine,
        seg: &Segment,
        order: u64,
        add: &mut impl FnMut(Finding),
    ) {
        if self.tool != Some(seg.tool) {
            self.close_all(machine, add);
            let solid = self.tools.tool_solid(seg.tool);
            self.scene
                .set_tool(machine, &solid.shape, solid.length, solid.radius);
            self.tool = Some(seg.tool);
            self.runs = vec![None; self.scene.pairs().len()];
            self.touched = vec![false; self.scene.pairs().len()];
        }
        self.touched.iter_mut().for_each(|t| *t = false);
        let contacts = self.scene.check_move(machine, |s| seg.eval(machine, s));
        let table = machine.work_link();
        let point = |contact: &Contact, pair: usize| {
            let p = self.scene.witness(machine, pair, &contact.joints)?;
            let on_table =
                machine.link_pose(table, &contact.joints).inverse() * nalgebra::Point3::from(p);
            Some(on_table.coords.into())
        };
        for (pair, contact) in contacts {
            self.touched[pair] = true;
            match &mut self.runs[pair] {
                Some(run) => {
                    if contact.collides() && !run.first.collides() {
                        run.point = point(&contact, pair);
                        run.first = contact.clone();
                    }
                    run.distance = run.distance.min(contact.distance);
                    run.depth = run.depth.max(contact.depth);
                }
                slot @ None => {
                    *slot = Some(ContactRun {
                        line: seg.line,
                        order,
                        distance: contact.distance,
                        depth: contact.depth,
                        point: point(&contact, pair),
                        first: contact,
                    });
                }
            }
        }
        for pair in 0..self.runs.len() {
            if !self.touched[pair]
                && let Some(run) = self.runs[pair].take()
            {
                add(self.finding(machine, run));
            }
        }
    }

    /// Ends every contact in progress (a tool change, the run's end).
    pub(crate) fn close_all(&mut self, machine: &Machine, add: &mut impl FnMut(Finding)) {
        for pair in 0..self.runs.len() {
            if let Some(run) = self.runs[pair].take() {
                add(self.finding(machine, run));
            }
        }
    }

    fn finding(&self, machine: &Machine, run: ContactRun) -> Finding {
        let [a, b] = &run.first.bodies;
        let tool = self.tool.filter(|&t| t > 0);
        let name = |part: &str| match (part, tool) {
            ("tool", Some(t)) => format!("tool T{t}"),
            ("shank" | "holder", Some(t)) => format!("the {part} of T{t}"),
            ("tool" | "shank" | "holder", None) => format!("the {part}"),
            _ => format!("`{part}`"),
        };
        let at = positions(machine, &run.first.joints);
        let (kind, value, message) = if run.first.collides() || run.distance <= 0.0 {
            (
                Kind::Collision,
                run.depth,
                format!(
                    "{} hits {} ({} mm deep) at {at}",
                    name(a),
                    name(b),
                    round3(run.depth)
                ),
            )
        } else {
            (
                Kind::NearMiss,
                run.distance,
                format!(
                    "{} passes {} mm from {} (clearance {} mm) at {at}",
                    name(a),
                    round3(run.distance),
                    name(b),
                    self.scene.clearance
                ),
            )
        };
        Finding {
            kind,
            line: run.line,
            message: message.into(),
            axis: None,
            value: Some(value),
            bodies: Some(Box::new([a.clone(), b.clone()])),
            point: run.point,
            order: run.order,
        }
    }
}

/// Machine positions as the control shows them, `X12.5 Y0 …`.
pub(crate) fn positions(machine: &Machine, joints: &Joints) -> String {
    machine
        .axis_names()
        .zip(joints.iter())
        .map(|(name, v)| format!("{name}{}", round3(*v)))
        .collect::<Vec<_>>()
        .join(" ")
}
