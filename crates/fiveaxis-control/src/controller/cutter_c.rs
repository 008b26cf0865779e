//! Cutter compensation C in the controller: blocks go through the
//! [`crate::cutter`] engine, which holds one block of look-ahead, and
//! come back as pieces of the tool centre path in the plane; each piece
//! becomes a segment with the rest of its block (third axis, rotary axes,
//! feed) and the offsets that were in force when the block was read.

use std::collections::VecDeque;

use fiveaxis_machine::{Joints, SetupError, Vec3};

use super::{Controller, LengthMode};
use crate::alarm::{Alarm, Condition};
use crate::cutter::{CompError, Compensated, Element, Move, P2, PieceKind, Side};
use crate::modal::MotionMode;
use crate::segment::{Arc, Motion, Path, Segment, TipPath};

/// Blocks waiting for their compensated path (the held block and those
/// without movement behind it); more raise an alarm (FANUC reads a bounded
/// number of blocks ahead).
const MAX_DEFERRED: usize = 8;

/// What a block needs to become segments once its path is known: taken
/// when the block was read. (G92 shifts and G54.4 selections end the
/// compensated path before they act, so they are the same when the block
/// is emitted.)
#[derive(Clone, Copy, Debug)]
pub(super) struct Deferred {
    tag: u32,
    line: u32,
    motion: Motion,
    feed: Option<f64>,
    /// Programmed start and end of every axis.
    from: Joints,
    end: Joints,
    /// Plane axes (first, second, normal).
    plane: [usize; 3],
    /// The 3-D compensation vector (zero: the two compensations exclude
    /// each other, kept for the mapping).
    vector: Vec3,
    length_mode: LengthMode,
    tool_length: f64,
    work: Vec3,
}

/// The controller's side of cutter compensation C.
#[derive(Debug, Default)]
pub(super) struct CutterC {
    pub(super) engine: crate::cutter::CutterComp,
    queue: VecDeque<Deferred>,
    pieces: Vec<Compensated>,
    next_tag: u32,
    /// Programmed position at the end of the last block read.
    pub(super) point: Joints,
    /// The mode in force: `Some(side)` for G41 / G42.
    pub(super) side: Option<Side>,
    /// The I, J type vector direction of this block (a G41 / G42 block
    /// with the plane's centre words but not all of I, J, K).
    pub(super) vector: Option<crate::cutter::P2>,
}

impl CutterC {
    /// The engine with the machine's start-up type.
    pub(super) fn new(startup_b: bool) -> Self {
        let startup = if startup_b {
            crate::cutter::StartupType::B
        } else {
            crate::cutter::StartupType::A
        };
        Self {
            engine: crate::cutter::CutterComp::new(startup),
            ..Self::default()
        }
    }

    /// Whether blocks go through the engine: the mode is on, or it still
    /// holds a block.
    pub(super) fn routing(&self) -> bool {
        self.side.is_some() || self.engine.is_active() || !self.queue.is_empty()
    }
}

impl Controller<'_> {
    /// Cutter compensation C on one side of the contour, or off (`None`):
    /// the entry point of FANUC G41 / G42 / G40 and of the commands'
    /// `Command::Radius`. The radius is that of the offset memory in
    /// force when each block is read; the next move starts or ends the
    /// offset (the machine's start-up type).
    pub(super) fn select_cutter_side(&mut self, side: Option<Side>) {
        self.cutter.side = side;
    }

    /// A block under cutter compensation C (or its start-up or cancel):
    /// hands its movement in the plane to the engine and turns what comes
    /// out into segments.
    pub(super) fn cutter_c_motion(
        &mut self,
        from: &Joints,
        changed: bool,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        if self.tcpc_type().is_some() {
            return Err(self.alarm(
                Condition::CrcInTcpc,
                None,
                "cutter compensation C cannot run under tool centre point control".into(),
            ));
        }
        let targets = self.axis_words();
        let mode = self.state.modal.motion;
        let is_arc = matches!(mode, MotionMode::Cw | MotionMode::Ccw);
        let arc_words = is_arc && self.arc_words_present();
        let has_axes = targets.iter().any(Option::is_some) || arc_words;
        let (end_p, _) = if has_axes || changed {
            self.end_point(from, &targets)
        } else {
            (*from, *from)
        };
        let [p, q, n] = self.state.modal.plane.axes();
        let plane = |j: &Joints| P2::new(j[p], j[q]);
        let (start2, end2) = (plane(from), plane(&end_p));
        let (element, motion) = if is_arc && has_axes {
            match self.arc_geometry(mode, from, &end_p)? {
                Some(geo) => (
                    Some(Element::Arc {
                        from: start2,
                        to: end2,
                        center: P2::new(geo.center[0], geo.center[1]),
                        ccw: geo.motion == Motion::Ccw,
                    }),
                    geo.motion,
                ),
                None => (
                    Some(Element::Line {
                        from: start2,
                        to: end2,
                    }),
                    Motion::Linear,
                ),
            }
        } else if (end2 - start2).norm() > 0.0 {
            let motion = if mode == MotionMode::Rapid {
                Motion::Rapid
            } else {
                Motion::Linear
            };
            (
                Some(Element::Line {
                    from: start2,
                    to: end2,
                }),
                motion,
            )
        } else {
            let motion = if mode == MotionMode::Rapid {
                Motion::Rapid
            } else {
                Motion::Linear
            };
            (None, motion)
        };
        let moves = element.is_some() || end_p != *from;
        let feed = if motion == Motion::Rapid || !moves {
            None
        } else {
            let length = (end2 - start2).norm().hypot(end_p[n] - from[n]);
            Some(self.cutting_feed(|| length)?)
        };
        let tag = self.cutter.next_tag;
        self.cutter.next_tag = self.cutter.next_tag.wrapping_add(1);
        if self.cutter.queue.len() >= MAX_DEFERRED {
            return Err(self.alarm(
                Condition::CrcTooManyStill,
                None,
                format!(
                    "more than {MAX_DEFERRED} blocks without movement in cutter compensation C"
                ),
            ));
        }
        self.cutter.queue.push_back(Deferred {
            tag,
            line: self.fanuc.line,
            motion,
            feed,
            from: *from,
            end: end_p,
            plane: [p, q, n],
            vector: self.local_vector(),
            length_mode: self.state.modal.length,
            tool_length: self.tool_length(),
            work: self.work(),
        });
        self.cutter.point = end_p;
        let offset = self
            .cutter
            .side
            .map(|side| (self.framed_side(side, [p, q, n]), self.tool_radius()));
        let vector = self
            .cutter
            .vector
            .take()
            .map(|v| self.framed_direction(v, [p, q, n]));
        let block = element.map(|element| Move {
            element,
            rapid: motion == Motion::Rapid,
            vector,
        });
        let mut pieces = std::mem::take(&mut self.cutter.pieces);
        pieces.clear();
        let pushed = self.cutter.engine.push(block, offset, tag, &mut pieces);
        let result = pushed
            .map_err(|e| self.crc_alarm(&e))
            .and_then(|()| self.emit_pieces(&pieces, out));
        self.cutter.pieces = pieces;
        result
    }

    /// End of the program (or a reference return): the held block ends
    /// perpendicular to itself and is emitted.
    pub(super) fn cutter_c_finish(&mut self, out: &mut Vec<Segment>) -> Result<(), Alarm> {
        if !self.cutter.routing() {
            return Ok(());
        }
        let mut pieces = std::mem::take(&mut self.cutter.pieces);
        pieces.clear();
        let finished = self.cutter.engine.finish(&mut pieces);
        let result = finished
            .map_err(|e| self.crc_alarm(&e))
            .and_then(|()| self.emit_pieces(&pieces, out));
        self.cutter.pieces = pieces;
        self.cutter.queue.clear();
        result
    }

    /// The alarm of an engine error, at the line of the block it names.
    fn crc_alarm(&self, error: &CompError) -> Alarm {
        let condition = match error.code() {
            Some(33) => Condition::CrcNoIntersection,
            Some(34) => Condition::CrcArcInStartOrCancel,
            Some(38) => Condition::CrcArcCenter,
            Some(41) => Condition::CrcInterference,
            _ => Condition::CrcNonFinite,
        };
        let line = self
            .cutter
            .queue
            .iter()
            .find(|d| d.tag == error.tag())
            .map_or(self.fanuc.line, |d| d.line);
        let mut alarm = self.alarm(condition, None, error.message().into());
        alarm.line = line;
        alarm
    }

    /// Turns the engine's pieces into segments, block by block, and drops
    /// the blocks that are done.
    fn emit_pieces(&mut self, pieces: &[Compensated], out: &mut Vec<Segment>) -> Result<(), Alarm> {
        let mut i = 0;
        while i < pieces.len() {
            let tag = pieces[i].tag;
            let count = pieces[i..].iter().take_while(|p| p.tag == tag).count();
            let group = &pieces[i..i + count];
            // Blocks before this one that produced nothing are done.
            while self.cutter.queue.front().is_some_and(|d| d.tag != tag) {
                self.cutter.queue.pop_front();
            }
            let Some(block) = self.cutter.queue.pop_front() else {
                break;
            };
            self.emit_block(&block, group, out)?;
            i += count;
        }
        Ok(())
    }

    /// The segments of one block: its pieces in the plane, the other axes
    /// moving with the pieces that follow its path (in proportion to their
    /// length), standing still on the corner pieces.
    fn emit_block(
        &mut self,
        block: &Deferred,
        pieces: &[Compensated],
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let [p, q, _] = block.plane;
        let along =
            |piece: &Compensated| piece.kind != PieceKind::Corner && piece.kind != PieceKind::Still;
        let total: f64 = pieces
            .iter()
            .filter(|c| along(c))
            .map(|c| element_length(c.element.as_ref()))
            .sum();
        let moving = pieces.iter().filter(|c| along(c)).count();
        let mut done = 0.0;
        let mut done_count = 0;
        for piece in pieces {
            let before = self.state.joints;
            let mut end = block.end;
            let fraction = |d: f64, k: usize| {
                if total > 0.0 {
                    d / total
                } else {
                    k as f64 / moving.max(1) as f64
                }
            };
            if along(piece) {
                done += element_length(piece.element.as_ref());
                done_count += 1;
                let f1 = fraction(done, done_count);
                for (a, value) in end.iter_mut().enumerate() {
                    *value = block.from[a] + (block.end[a] - block.from[a]) * f1;
                }
            }
            let (s2, e2) = match piece.element {
                Some(element) => (element.start(), element.end()),
                None => {
                    // A block without movement in the plane runs where the
                    // tool is.
                    let here = self.programmed_at(block, &before);
                    (P2::new(here[p], here[q]), P2::new(here[p], here[q]))
                }
            };
            end[p] = e2.x;
            end[q] = e2.y;
            let end_joints = self.machine_at(block, &end);
            let path = match piece.element {
                Some(Element::Arc { center, ccw, .. })
                    if self.feature().is_some()
                        || self.state.setup.rotation != SetupError::IDENTITY.rotation =>
                {
                    // The tilted plane or a turned workpiece: the circle
                    // leaves the plane of the machine axes.
                    let mut c = Vec3::new(block.from[0], block.from[1], block.from[2]);
                    c[p] = center.x;
                    c[q] = center.y;
                    let r0 = (s2 - center).norm();
                    let theta0 = (s2.y - center.y).atan2(s2.x - center.x);
                    let theta1 = (e2.y - center.y).atan2(e2.x - center.x);
                    let programmed = TipPath::plane_arc(
                        block.plane,
                        c,
                        [r0, (e2 - center).norm()],
                        theta0,
                        super::arc_sweep(theta0, theta1, ccw, r0),
                        end[block.plane[2]] - start_normal(block, &before, self),
                    );
                    if self.feature().is_some() {
                        Path::Helix {
                            circle: self.feature_circle(&before, &programmed),
                            drift: Vec3::zeros(),
                        }
                    } else {
                        let offset = self.length_at(block, &before);
                        let circle = programmed.mapped(
                            |x| self.real_at(block, x) + offset,
                            |v| self.state.setup.vector(v),
                        );
                        let drift =
                            self.length_at(block, &end_joints) - self.length_at(block, &before);
                        Path::Helix { circle, drift }
                    }
                }
                Some(Element::Arc { center, ccw, .. }) => {
                    let offset =
                        self.length_at(block, &before) + self.real_at(block, &Vec3::zeros());
                    let r0 = (s2 - center).norm();
                    let r1 = (e2 - center).norm();
                    let theta0 = (s2.y - center.y).atan2(s2.x - center.x);
                    let theta1 = (e2.y - center.y).atan2(e2.x - center.x);
                    let sweep = super::arc_sweep(theta0, theta1, ccw, r0);
                    let offset1 =
                        self.length_at(block, &end_joints) + self.real_at(block, &Vec3::zeros());
                    Path::Arc(Arc {
                        axes: [p, q],
                        center: [center.x + offset[p], center.y + offset[q]],
                        r0,
                        r1,
                        theta0,
                        sweep,
                        drift: [offset1[p] - offset[p], offset1[q] - offset[q]],
                    })
                }
                _ => Path::Joint,
            };
            let motion = match piece.element {
                Some(Element::Arc { ccw: true, .. }) => Motion::Ccw,
                Some(Element::Arc { ccw: false, .. }) => Motion::Cw,
                _ if piece.rapid => Motion::Rapid,
                _ if block.motion == Motion::Rapid => Motion::Rapid,
                _ => Motion::Linear,
            };
            let seg = Segment {
                line: block.line,
                motion,
                feed: if motion == Motion::Rapid {
                    None
                } else {
                    block.feed
                },
                start: before,
                end: end_joints,
                path,
                tool_length: block.tool_length,
                tool: self.physical_tool(),
                work: block.work,
                setup: self.state.setup,
                exact_stop: self.state.modal.cutting == crate::modal::CuttingMode::ExactStop,
                inverse_time: self.state.modal.feed_mode == crate::modal::FeedMode::InverseTime,
                // Cutter compensation C: in plane, no tool direction.
                rotary_chosen: false,
                rows: 1,
            };
            if seg.moves() {
                out.push(seg);
                self.state.joints = end_joints;
            }
        }
        Ok(())
    }

    /// The programmed position of the machine position `joints` with the
    /// offsets of `block`.
    fn programmed_at(&self, block: &Deferred, joints: &Joints) -> Joints {
        let mut p = *joints;
        for (i, v) in p.iter_mut().enumerate().skip(3) {
            *v -= self.rotary_shift(i);
        }
        let lin = if self.feature().is_some() {
            // The tilted plane: the tip of the tool as it stands.
            let tip = self
                .machine
                .programmed_pose(joints, self.feature_length_at(block))
                .tip;
            self.work_to_feature(
                &(self.state.setup.inverse_point(&(tip - block.work)) - block.vector),
            )
        } else {
            let x = Vec3::new(joints[0], joints[1], joints[2]) - self.length_at(block, joints);
            self.state.setup.inverse_point(&(x - block.work)) - block.vector
        };
        p[..3].copy_from_slice(lin.as_slice());
        p
    }

    /// The tool length along the tool of `block` in the tilted plane.
    fn feature_length_at(&self, block: &Deferred) -> f64 {
        match block.length_mode {
            LengthMode::Plus | LengthMode::ToolAxis => block.tool_length,
            LengthMode::Minus => -block.tool_length,
            _ => 0.0,
        }
    }

    /// The machine position of programmed position `p` with the offsets of
    /// `block`.
    fn machine_at(&self, block: &Deferred, p: &Joints) -> Joints {
        let mut joints = *p;
        for (i, v) in joints.iter_mut().enumerate().skip(3) {
            *v += self.rotary_shift(i);
        }
        let real = self.real_at(block, &Vec3::new(p[0], p[1], p[2]));
        let lin = if self.feature().is_some() {
            self.machine
                .gauge_for_programmed_tip(&joints, &real, self.feature_length_at(block))
        } else {
            real + self.length_at(block, &joints)
        };
        joints[..3].copy_from_slice(lin.as_slice());
        joints
    }

    /// A programmed point of `block` on the real workpiece, work offset
    /// included.
    fn real_at(&self, block: &Deferred, p: &Vec3) -> Vec3 {
        block.work
            + self
                .state
                .setup
                .point(&(self.feature_to_work(p) + block.vector))
    }

    fn length_at(&self, block: &Deferred, joints: &Joints) -> Vec3 {
        self.length_vector_for(block.length_mode, block.tool_length, joints)
    }
}

/// The programmed normal-axis coordinate at machine position `joints`.
fn start_normal(block: &Deferred, joints: &Joints, controller: &Controller<'_>) -> f64 {
    controller.programmed_at(block, joints)[block.plane[2]]
}

/// Length of a piece's path in the plane (0 for none).
fn element_length(element: Option<&Element>) -> f64 {
    match element {
        Some(Element::Line { from, to }) => (to - from).norm(),
        Some(Element::Arc {
            from,
            to,
            center,
            ccw,
        }) => {
            let r = (from - center).norm();
            let theta0 = (from.y - center.y).atan2(from.x - center.x);
            let theta1 = (to.y - center.y).atan2(to.x - center.x);
            (super::arc_sweep(theta0, theta1, *ccw, r) * r).abs()
        }
        None => 0.0,
    }
}
