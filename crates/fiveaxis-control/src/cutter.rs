//! Cutter compensation C (G40, G41, G42) in the selected plane, as FANUC
//! controls offset the tool centre path: a pure state machine with one
//! block of look-ahead, independent of the controller.
//!
//! The caller hands in each programmed block in the coordinates of the
//! offset plane (first and second axis of G17, G18 or G19) with the
//! compensation in force for it, and receives the pieces of the tool centre
//! path in order, each tagged with the block it belongs to. The controller
//! keeps everything else of a block (the third axis, feed, M codes) under
//! that tag.
//!
//! # Sources
//!
//! The rules follow the FANUC operator's manuals for the machining-centre
//! series 0i-MC, 16/18-MC, 16i/18i-MB and 30i/31i/32i-MA: the chapter
//! "Cutter compensation C (G40–G42)" and its detail sections "Overview"
//! (inner and outer side, the angle α), "Tool movement in start-up", "Tool
//! movement in offset mode", "Tool movement in offset mode cancel",
//! "Interference check", "Overcutting by cutter compensation", "Change in
//! the offset direction in the offset mode", "Change of the cutter
//! compensation value" and "Blocks without tool movement", with the alarm
//! list (PS0033, PS0034, PS0038, PS0041). The manuals give many rules as
//! figures only; where a figure had to be read, the decision taken is
//! marked *Decision* below. LinuxCNC's different scheme (arcs around outer
//! corners, no start-up types) is not followed.
//!
//! # Terms
//!
//! * `d`: the signed offset of a block: `+r` for G41, `−r` for G42, so a
//!   negative radius swaps the sides as on FANUC. The offset vector of a
//!   direction `t` is `d·n(t)`, `n(t)` the left normal.
//! * At a corner between block A (ending at P with direction t₁) and block
//!   B (starting at P with direction t₂; arcs use their tangents), the turn
//!   θ is the signed angle from t₁ to t₂ and α = 180° + sign(d)·θ is the
//!   angle on the workpiece side. **Inner side**: α ≥ 180°. **Outer side,
//!   obtuse**: 90° ≤ α < 180° (α = 90° exactly, as at a square's corner, is
//!   obtuse). **Outer side, acute**: α < 90°. A reversal (θ = ±180°) is
//!   outer acute; |θ| ≤ [`ANGLE_TOLERANCE`] is a tangent transition.
//! * Qa = P + d·n(t₁), Qb = P + d·n(t₂) (the perpendicular points);
//!   the two extra points of an acute corner are P1 = Qa + |d|·t₁ and
//!   P2 = Qb − |d|·t₂.
//! * The *offset carrier* of a line is the parallel line at `d`; of an arc,
//!   the concentric circle of radius R − d (counter-clockwise) or R + d
//!   (clockwise). Intersections of carriers are taken nearest to the middle
//!   of Qa and Qb; carriers that miss by less than
//!   [`INTERSECTION_TOLERANCE`] are taken as touching.
//!
//! # Rules
//!
//! **Offset mode** (both blocks compensated, same side):
//! * tangent transition: the single point Qa, no extra points;
//! * inner side: the intersection of the carriers of A and B; none is
//!   [`CompError::NoIntersection`] (PS0033);
//! * outer obtuse: the intersection of the carriers (lines always have
//!   one). *Decision*: where arcs' carriers have none, the acute
//!   construction is used (it never gouges);
//! * outer acute: A's offset runs on to P1 (a line's offset is extended;
//!   an arc's offset ends at Qa and a tangent line Qa→P1 follows), a line
//!   P1→P2, and B's offset starts at P2 (an arc is preceded by the tangent
//!   line P2→Qb).
//!
//! **Start-up** (cancel mode → offset mode; [`StartupType`], FANUC
//! parameter No.5003#0 SUP). The start-up block must be a line (G00/G01),
//! an arc is [`CompError::ArcInStartOrCancel`] (PS0034). It runs from the
//! programmed start point (tool centre on the program, no vector) to the
//! vector at its end, which is:
//! * type A, every corner: perpendicular to the next block at its start
//!   (Qb);
//! * type B: inner side Qb (*Decision*: the manual tells the two types
//!   apart on the outer side only, and draws the inner side with one
//!   vector perpendicular to the next block); outer obtuse the intersection of the start-up line's carrier
//!   with the next block's; outer acute P1, then the line P1→P2;
//! * a tangent transition: Qa (= Qb).
//!
//! A start-up command in a block without movement in the plane makes no
//! vector: the next moving block is the start-up.
//!
//! **Offset cancel** (G40 with a move): the cancel block must be a line
//! (else PS0034). The last compensated block ends with the vector
//! * type A: perpendicular to itself at its end (Qa);
//! * type B: inner side Qa; outer obtuse the intersection of its carrier
//!   with the cancel line's carrier; outer acute P1 then P1→P2;
//!
//! and the cancel move runs from there to the programmed end point. A
//! start-up block followed directly by a cancel block ends at Qa of the
//! start-up line.
//!
//! **Change of offset direction** (G41↔G42 between A and B in offset
//! mode): no inner/outer distinction; the corner is the intersection of
//! A's carrier (old side) with B's carrier (new side). Where there is none
//! (parallel lines, circles apart), or it lies behind the start of a line A
//! or beyond the end of a line B, A ends at Qa, a line Qa→Qb follows, and
//! B starts at Qb. *Decision*: a direction change right after a start-up
//! block ends the start-up at Qb of the new side.
//!
//! **Change of the offset value** (D) in offset mode: the vector at the
//! start of a block keeps the old value and the vector at its end uses the
//! block's value, so the offset of the block where D changes is not
//! parallel to the program (a line tapers; an arc becomes an [`Element::Arc`]
//! whose start and end radii differ, to be interpolated with a radius
//! linear in the angle). A corner is always computed with the value of the
//! block that ends at it.
//!
//! **Blocks without movement in the plane** (dwell, M codes, a Z move; a
//! zero-length line counts as one) in offset mode:
//! * one such block between two moves: the path is as if it were absent;
//!   the block runs at the corner, after the corner's extra pieces;
//! * two or more in a row: the block before them ends with the vector
//!   perpendicular to itself (Qa), and the next moving block runs from
//!   there to its own end vector (it is not parallel: overcutting is
//!   possible, as the manual warns);
//! * G40 in a block without movement: the block before ends at Qa; the
//!   vector is removed by the next move, which must then be a line.
//!
//! **Interference check** (PS0041, [`CompError::Interference`]), done for a
//! block before any piece of it is emitted: a compensated line whose
//! direction differs from the programmed one by more than 90° (it runs
//! backwards); a compensated arc that runs backwards, or whose angle
//! differs from the programmed one by 180° or more; an arc on the inner
//! side whose radius is smaller than the offset (R < r). Start-up and
//! cancel moves are not checked. With one block of look-ahead the check
//! sees a block once the corner after it is known: the block before the
//! offending one has been emitted by then (FANUC, reading more blocks, may
//! stop earlier). An arc whose centre is on its start or end
//! point in offset mode is [`CompError::ArcCentreOnEndpoint`] (PS0038).
//!
//! # Output
//!
//! Each pushed block yields its pieces once, in program order, so the tags
//! in the output never go back; a block without movement yields one
//! [`PieceKind::Still`] piece (no element), and a moving block whose
//! compensated path has no length yields none. For a continuous program
//! the pieces join: each starts exactly where the previous one ended (a
//! start-up starts at its programmed start point, cancel mode passes moves
//! on unchanged). *Decision*: the extra pieces at a corner (extensions,
//! connecting lines) belong to the block that **ends** at the corner, so a
//! block's own offset starts exactly at its first piece; they are marked
//! [`PieceKind::Corner`], so a caller that wants FANUC's single-block stop
//! point elsewhere can re-assign them. A compensated arc of a full turn or
//! more (a programmed full circle) is split into two to four arcs of at
//! most 180°, and an arc too short to define its direction is emitted as a
//! line, so no output arc is ambiguous. At the end of the program
//! ([`CutterComp::finish`]) the held block ends at Qa and the vector stays,
//! as a reset clears it without moving.
//!
//! On an error nothing of the offending block, nor of the block held
//! before it, is emitted, and the state is unchanged.
//!
//! Not modelled: G39 corner arcs, the I, J, K vector in the G41/G42 or
//! G40 block, the special start-up for α < 1°, G41/G42 re-commanded in
//! offset mode without a change of side, and look-ahead of more than one
//! block (FANUC may read up to five blocks for the interference check).

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use nalgebra::Vector2;

/// Plane coordinates: the first and second axis of G17, G18 or G19, mm.
pub type P2 = Vector2<f64>;

/// Lengths at or below this are zero: moves without movement, coincident
/// points, an arc centre on an end point, backward runs, mm.
pub const LENGTH_TOLERANCE: f64 = 1e-7;

/// Turns at or below this are tangent transitions; also the margin of the
/// 90° boundary between obtuse and acute corners, radians.
pub const ANGLE_TOLERANCE: f64 = 1e-9;

/// Offset carriers (lines, circles) that miss each other by no more than
/// this are taken as touching, so that rounding of programmed coordinates
/// never turns a tangent corner into "no intersection", mm.
pub const INTERSECTION_TOLERANCE: f64 = 1e-4;

/// A compensated arc whose chord is at most this (and which turns less
/// than half a circle) is emitted as a line: its direction could not be
/// told from its end points, mm.
pub const MIN_ARC_CHORD: f64 = 1e-5;

/// A compensated arc turning more than a full circle less this is split
/// into arcs of at most 180°, radians.
pub const FULL_TURN_MARGIN: f64 = 1e-3;

/// A path element in the offset plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Element {
    /// A straight move.
    Line {
        /// Start point.
        from: P2,
        /// End point.
        to: P2,
    },
    /// A circular move; `from == to` is a full circle. Start and end
    /// radius may differ (spiral), as after a change of the offset value.
    Arc {
        /// Start point.
        from: P2,
        /// End point.
        to: P2,
        /// Centre.
        center: P2,
        /// Counter-clockwise (G03) seen from the plane's normal.
        ccw: bool,
    },
}

impl Element {
    /// Start point.
    pub fn start(&self) -> P2 {
        match *self {
            Element::Line { from, .. } | Element::Arc { from, .. } => from,
        }
    }

    /// End point.
    pub fn end(&self) -> P2 {
        match *self {
            Element::Line { to, .. } | Element::Arc { to, .. } => to,
        }
    }

    /// Unit direction of travel at the start.
    pub fn start_tangent(&self) -> P2 {
        match *self {
            Element::Line { from, to } => unit(to - from),
            Element::Arc {
                from, center, ccw, ..
            } => arc_tangent(from - center, ccw),
        }
    }

    /// Unit direction of travel at the end.
    pub fn end_tangent(&self) -> P2 {
        match *self {
            Element::Line { from, to } => unit(to - from),
            Element::Arc {
                to, center, ccw, ..
            } => arc_tangent(to - center, ccw),
        }
    }

    fn is_finite(&self) -> bool {
        let ok = |p: P2| p.x.is_finite() && p.y.is_finite();
        match *self {
            Element::Line { from, to } => ok(from) && ok(to),
            Element::Arc {
                from, to, center, ..
            } => ok(from) && ok(to) && ok(center),
        }
    }

    /// A line shorter than [`LENGTH_TOLERANCE`] does not move the tool.
    fn is_still(&self) -> bool {
        match *self {
            Element::Line { from, to } => (to - from).norm() <= LENGTH_TOLERANCE,
            Element::Arc { .. } => false,
        }
    }

    fn is_arc(&self) -> bool {
        matches!(self, Element::Arc { .. })
    }

    /// Line length; arcs are not measured (`None`).
    fn line_length(&self) -> Option<f64> {
        match *self {
            Element::Line { from, to } => Some((to - from).norm()),
            Element::Arc { .. } => None,
        }
    }
}

/// The side of the programmed path the tool centre keeps to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// G41: left of the direction of travel.
    Left,
    /// G42: right of the direction of travel.
    Right,
}

/// How compensation starts and ends at an outer corner (FANUC parameter
/// No.5003#0 SUP: 0 = type A, 1 = type B).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum StartupType {
    /// The vector at the end of the start-up block is perpendicular to the
    /// next block; the cancel starts perpendicular to the previous block.
    #[default]
    A,
    /// Start-up and cancel build outer corners as in offset mode
    /// (intersection, or the two extra points at an acute corner).
    B,
}

/// One programmed move in the offset plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Move {
    /// The programmed path.
    pub element: Element,
    /// Positioning (G00) rather than a cutting move.
    pub rapid: bool,
    /// The I, J type vector of a G41 / G42 block that gives only the
    /// plane's centre words (seed 001: not all of I, J, K): the direction
    /// (I, J) in the plane. The vector at the block's end is then
    /// perpendicular to it, `d` long, on the compensation side (G41: left
    /// of the direction), instead of the intersection with the next block.
    pub vector: Option<P2>,
}

/// What a piece of the tool centre path is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PieceKind {
    /// A block in cancel mode, passed on unchanged.
    Programmed,
    /// The start-up move, from the programmed start point to the first
    /// vector.
    StartUp,
    /// The offset of a programmed element: a parallel line or a concentric
    /// arc (not parallel where the offset value changes, or after blocks
    /// without movement).
    Offset,
    /// An extra piece at a corner (extension or connecting line); it
    /// belongs to the block that ends at the corner.
    Corner,
    /// The cancel move, from the last vector to the programmed end point.
    Cancel,
    /// A block without movement in the plane: it runs here, where the
    /// previous piece ended. Its element is `None`.
    Still,
}

/// One piece of the tool centre path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Compensated {
    /// The path; `None` exactly for [`PieceKind::Still`].
    pub element: Option<Element>,
    /// The tag of the block the piece belongs to.
    pub tag: u32,
    /// Positioning (G00), as the block it belongs to.
    pub rapid: bool,
    /// What the piece is.
    pub kind: PieceKind,
}

/// Why cutter compensation stopped the program. Each carries the tag of
/// the block the control stops before.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum CompError {
    /// The offset paths of two blocks meeting on the inner side do not
    /// intersect (FANUC PS0033). Tag: the later block.
    #[error("no intersection of the offset paths in cutter compensation (block {tag})")]
    NoIntersection {
        /// The block whose start corner has no intersection.
        tag: u32,
    },
    /// The compensated path would run against the program, or an inner arc
    /// is smaller than the offset: the tool would cut into the part (FANUC
    /// PS0041).
    #[error("interference in cutter compensation: the offset path runs backwards (block {tag})")]
    Interference {
        /// The block that would gouge.
        tag: u32,
    },
    /// An arc as the start-up or the cancel block (FANUC PS0034).
    #[error("an arc cannot start or cancel cutter compensation (block {tag})")]
    ArcInStartOrCancel {
        /// The arc block.
        tag: u32,
    },
    /// An arc whose centre is on its start or end point in offset mode
    /// (FANUC PS0038).
    #[error("arc centre on its start or end point in cutter compensation (block {tag})")]
    ArcCentreOnEndpoint {
        /// The arc block.
        tag: u32,
    },
    /// A coordinate or the offset is not finite, or the compensated path
    /// overflowed (no FANUC number: a control never reads such values).
    #[error("coordinates or offset not finite in cutter compensation (block {tag})")]
    NonFinite {
        /// The block.
        tag: u32,
    },
}

impl CompError {
    /// The FANUC alarm number (33, 41, 34, 38); `None` for
    /// [`CompError::NonFinite`], which no FANUC control numbers.
    pub fn code(&self) -> Option<u16> {
        match self {
            CompError::NoIntersection { .. } => Some(33),
            CompError::Interference { .. } => Some(41),
            CompError::ArcInStartOrCancel { .. } => Some(34),
            CompError::ArcCentreOnEndpoint { .. } => Some(38),
            CompError::NonFinite { .. } => None,
        }
    }

    /// The tag of the block the control stops before.
    pub fn tag(&self) -> u32 {
        match *self {
            CompError::NoIntersection { tag }
            | CompError::Interference { tag }
            | CompError::ArcInStartOrCancel { tag }
            | CompError::ArcCentreOnEndpoint { tag }
            | CompError::NonFinite { tag } => tag,
        }
    }

    /// A short description without the block.
    pub fn message(&self) -> &'static str {
        match self {
            CompError::NoIntersection { .. } => {
                "no intersection of the offset paths in cutter compensation"
            }
            CompError::Interference { .. } => {
                "interference in cutter compensation: the offset path runs backwards"
            }
            CompError::ArcInStartOrCancel { .. } => {
                "an arc cannot start or cancel cutter compensation"
            }
            CompError::ArcCentreOnEndpoint { .. } => {
                "arc centre on its start or end point in cutter compensation"
            }
            CompError::NonFinite { .. } => "coordinates or offset not finite",
        }
    }
}

/// A moving block held until the next one shows its end vector.
#[derive(Clone, Copy, Debug)]
struct Held {
    element: Element,
    tag: u32,
    rapid: bool,
    /// Signed offset of the block (+ left).
    d: f64,
    /// Where the tool centre is when the block starts.
    start: P2,
    /// The block is the start-up move.
    startup: bool,
    /// One block without movement read after it.
    still: Option<u32>,
    /// The block's I, J type vector direction ([`Move::vector`]).
    vector: Option<P2>,
}

#[derive(Clone, Copy, Debug)]
enum State {
    /// Cancel mode: no vector, nothing held.
    Off,
    /// Offset mode with one moving block held.
    Held(Held),
    /// A vector is in force but nothing is held (after two blocks without
    /// movement, or G40 without movement): the next move starts at `at`.
    Free { at: P2 },
}

/// Cutter compensation C: feed blocks with [`CutterComp::push`], end with
/// [`CutterComp::finish`].
///
/// ```
/// use fiveaxis_control::cutter::{CutterComp, Element, Move, P2, Side, StartupType};
///
/// let mv = |from: P2, to: P2| Some(Move { element: Element::Line { from, to }, rapid: false, vector: None });
/// let g41 = Some((Side::Left, 5.0));
/// let mut comp = CutterComp::new(StartupType::A);
/// let mut out = Vec::new();
/// // G41 G01 X0 Y0 D1 (start-up), X100, G40 Y30 (cancel).
/// comp.push(mv(P2::new(0.0, -30.0), P2::new(0.0, 0.0)), g41, 1, &mut out)?;
/// assert!(out.is_empty()); // held until the next move shows the corner
/// comp.push(mv(P2::new(0.0, 0.0), P2::new(100.0, 0.0)), g41, 2, &mut out)?;
/// comp.push(mv(P2::new(100.0, 0.0), P2::new(100.0, 30.0)), None, 3, &mut out)?;
/// comp.finish(&mut out)?;
/// let ends: Vec<P2> = out.iter().filter_map(|c| c.element).map(|e| e.end()).collect();
/// assert_eq!(ends, [P2::new(0.0, 5.0), P2::new(100.0, 5.0), P2::new(100.0, 30.0)]);
/// # Ok::<(), fiveaxis_control::cutter::CompError>(())
/// ```
#[derive(Clone, Debug)]
pub struct CutterComp {
    startup: StartupType,
    state: State,
}

impl Default for CutterComp {
    fn default() -> Self {
        Self::new(StartupType::default())
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Role {
    StartUp,
    Offset,
    Cancel,
}

/// The points at a corner: `pts[0]` is where the earlier block's path ends,
/// `pts[n - 1]` where the later one's starts; consecutive points are joined
/// by corner lines.
#[derive(Clone, Copy, Debug)]
struct Corner {
    pts: [P2; 4],
    n: usize,
}

impl Corner {
    fn new() -> Self {
        Self {
            pts: [P2::zeros(); 4],
            n: 0,
        }
    }

    fn single(p: P2) -> Self {
        let mut c = Self::new();
        c.push(p);
        c
    }

    /// Appends a point unless it coincides with the last one.
    fn push(&mut self, p: P2) {
        if self.n > 0 && (p - self.pts[self.n - 1]).norm() <= LENGTH_TOLERANCE {
            return;
        }
        if self.n < self.pts.len() {
            self.pts[self.n] = p;
            self.n += 1;
        }
    }

    fn first(&self) -> P2 {
        self.pts[0]
    }

    fn last(&self) -> P2 {
        self.pts[self.n.saturating_sub(1)]
    }

    fn points(&self) -> &[P2] {
        &self.pts[..self.n]
    }

    fn is_finite(&self) -> bool {
        self.points().iter().all(|p| finite(*p))
    }
}

/// An offset carrier: the infinite line or full circle an offset element
/// lies on.
#[derive(Clone, Copy, Debug)]
enum Carrier {
    Line { p: P2, u: P2 },
    Circle { c: P2, rho: f64 },
}

impl CutterComp {
    /// A compensation in cancel mode with the given start-up type.
    pub fn new(startup: StartupType) -> Self {
        Self {
            startup,
            state: State::Off,
        }
    }

    /// An offset vector is in force or a block is held.
    pub fn is_active(&self) -> bool {
        !matches!(self.state, State::Off)
    }

    /// The tag of the moving block held for look-ahead, if any.
    pub fn held_tag(&self) -> Option<u32> {
        match self.state {
            State::Held(h) => Some(h.tag),
            _ => None,
        }
    }

    /// Clears the vector and drops whatever is held (a reset), without
    /// output.
    pub fn reset(&mut self) {
        self.state = State::Off;
    }

    /// One programmed block. `block` is its movement in the plane (`None`
    /// for a block without movement there); `mode` is the compensation in
    /// force for it: `None` for G40, `Some((side, radius))` for G41/G42 with
    /// the offset value. Pieces that are complete are appended to `out`.
    ///
    /// # Errors
    ///
    /// A [`CompError`] before anything of the offending block is emitted;
    /// the state is then unchanged.
    pub fn push(
        &mut self,
        block: Option<Move>,
        mode: Option<(Side, f64)>,
        tag: u32,
        out: &mut Vec<Compensated>,
    ) -> Result<(), CompError> {
        if let Some(m) = &block
            && !m.element.is_finite()
        {
            return Err(CompError::NonFinite { tag });
        }
        if let Some((_, r)) = mode
            && !r.is_finite()
        {
            return Err(CompError::NonFinite { tag });
        }
        let d = mode.map(|(side, r)| match side {
            Side::Left => r,
            Side::Right => -r,
        });
        let moving = block.filter(|m| !m.element.is_still());

        match (self.state, moving, d) {
            // Cancel mode passes every move on exactly as programmed (even
            // one below the length tolerance).
            (State::Off, _, None) => out.push(match block {
                Some(m) => Compensated {
                    element: Some(m.element),
                    tag,
                    rapid: m.rapid,
                    kind: PieceKind::Programmed,
                },
                None => still(tag),
            }),
            (State::Off, None, Some(_)) => out.push(still(tag)),
            (State::Off, Some(m), Some(d)) => {
                if m.element.is_arc() {
                    return Err(CompError::ArcInStartOrCancel { tag });
                }
                self.state = State::Held(Held {
                    element: m.element,
                    tag,
                    rapid: m.rapid,
                    d,
                    start: m.element.start(),
                    startup: true,
                    still: None,
                    vector: m.vector,
                });
            }
            (State::Held(mut h), None, Some(_)) => {
                if h.still.is_none() {
                    h.still = Some(tag);
                    self.state = State::Held(h);
                } else {
                    let end = Corner::single(perpendicular_end(&h));
                    check_held(&h, &end)?;
                    emit_held(&h, &end, out);
                    out.push(still(tag));
                    self.state = State::Free { at: end.last() };
                }
            }
            (State::Held(h), None, None) => {
                let end = Corner::single(perpendicular_end(&h));
                check_held(&h, &end)?;
                emit_held(&h, &end, out);
                out.push(still(tag));
                self.state = State::Free { at: end.last() };
            }
            (State::Held(h), Some(m), None) => {
                if m.element.is_arc() {
                    return Err(CompError::ArcInStartOrCancel { tag });
                }
                let corner = if h.startup || h.vector.is_some() {
                    Corner::single(perpendicular_end(&h))
                } else {
                    corner(&h.element, &m.element, h.d, h.d, Role::Cancel, self.startup)
                        .ok_or(CompError::NoIntersection { tag })?
                };
                check_held(&h, &corner)?;
                if !finite(m.element.end()) {
                    return Err(CompError::NonFinite { tag });
                }
                emit_held(&h, &corner, out);
                push_line(
                    out,
                    corner.last(),
                    m.element.end(),
                    tag,
                    m.rapid,
                    PieceKind::Cancel,
                );
                self.state = State::Off;
            }
            (State::Held(h), Some(m), Some(d)) => {
                check_offset_element(&m.element, d, tag)?;
                let role = if h.startup {
                    Role::StartUp
                } else {
                    Role::Offset
                };
                let corner = if h.vector.is_some() {
                    // The I, J type vector: no intersection, no extra
                    // points (no insertion block).
                    Corner::single(perpendicular_end(&h))
                } else {
                    corner(&h.element, &m.element, h.d, d, role, self.startup)
                        .ok_or(CompError::NoIntersection { tag })?
                };
                if !corner.is_finite() {
                    return Err(CompError::NonFinite { tag });
                }
                check_held(&h, &corner)?;
                emit_held(&h, &corner, out);
                self.state = State::Held(Held {
                    element: m.element,
                    tag,
                    rapid: m.rapid,
                    d,
                    start: corner.last(),
                    startup: false,
                    still: None,
                    vector: m.vector,
                });
            }
            (State::Free { .. }, None, _) => out.push(still(tag)),
            (State::Free { at }, Some(m), None) => {
                if m.element.is_arc() {
                    return Err(CompError::ArcInStartOrCancel { tag });
                }
                push_line(out, at, m.element.end(), tag, m.rapid, PieceKind::Cancel);
                self.state = State::Off;
            }
            (State::Free { at }, Some(m), Some(d)) => {
                check_offset_element(&m.element, d, tag)?;
                self.state = State::Held(Held {
                    element: m.element,
                    tag,
                    rapid: m.rapid,
                    d,
                    start: at,
                    startup: false,
                    still: None,
                    vector: m.vector,
                });
            }
        }
        Ok(())
    }

    /// End of the program: the held block is emitted ending with the
    /// vector perpendicular to it, which stays (a reset clears it without
    /// motion); the state returns to cancel mode.
    ///
    /// # Errors
    ///
    /// [`CompError::Interference`] if the held block's offset runs
    /// backwards; the state is then unchanged.
    pub fn finish(&mut self, out: &mut Vec<Compensated>) -> Result<(), CompError> {
        if let State::Held(h) = self.state {
            let end = Corner::single(perpendicular_end(&h));
            check_held(&h, &end)?;
            emit_held(&h, &end, out);
        }
        self.state = State::Off;
        Ok(())
    }
}

fn still(tag: u32) -> Compensated {
    Compensated {
        element: None,
        tag,
        rapid: false,
        kind: PieceKind::Still,
    }
}

fn finite(p: P2) -> bool {
    p.x.is_finite() && p.y.is_finite()
}

/// The left normal of a direction.
fn left(t: P2) -> P2 {
    P2::new(-t.y, t.x)
}

fn cross(a: P2, b: P2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// `v` scaled to unit length; `(1, 0)` for a vector too short to have a
/// direction (never reached for moving blocks, but no input may panic).
fn unit(v: P2) -> P2 {
    let n = v.norm();
    if n > 0.0 && n.is_finite() {
        v / n
    } else {
        P2::new(1.0, 0.0)
    }
}

/// Direction of travel on an arc at the radius vector `radial`.
fn arc_tangent(radial: P2, ccw: bool) -> P2 {
    let t = left(unit(radial));
    if ccw { t } else { -t }
}

fn sigma(ccw: bool) -> f64 {
    if ccw { 1.0 } else { -1.0 }
}

/// The end of the held block with the vector perpendicular to it, or to
/// its I, J type vector direction.
fn perpendicular_end(h: &Held) -> P2 {
    let direction = match h.vector {
        Some(v) if v.norm() > 0.0 => v / v.norm(),
        _ => h.element.end_tangent(),
    };
    h.element.end() + left(direction) * h.d
}

/// The PS0038 and inner-radius checks for a block entering offset mode.
fn check_offset_element(e: &Element, d: f64, tag: u32) -> Result<(), CompError> {
    if let Element::Arc {
        from,
        to,
        center,
        ccw,
    } = *e
    {
        let r0 = (from - center).norm();
        let r1 = (to - center).norm();
        if r0 <= LENGTH_TOLERANCE || r1 <= LENGTH_TOLERANCE {
            return Err(CompError::ArcCentreOnEndpoint { tag });
        }
        let s = sigma(ccw);
        if r0 - s * d < -LENGTH_TOLERANCE || r1 - s * d < -LENGTH_TOLERANCE {
            return Err(CompError::Interference { tag });
        }
    }
    Ok(())
}

/// The carrier of `e` offset by `d` through its point `at`, where its
/// tangent is `u`: the offset line, or the offset circle.
fn carrier(e: &Element, at: P2, u: P2, d: f64) -> Carrier {
    match *e {
        Element::Line { .. } => Carrier::Line {
            p: at + left(u) * d,
            u,
        },
        Element::Arc { center, ccw, .. } => Carrier::Circle {
            c: center,
            rho: ((at - center).norm() - sigma(ccw) * d).max(0.0),
        },
    }
}

fn carrier_end(e: &Element, d: f64) -> Carrier {
    carrier(e, e.end(), e.end_tangent(), d)
}

fn carrier_start(e: &Element, d: f64) -> Carrier {
    carrier(e, e.start(), e.start_tangent(), d)
}

fn nearest(a: P2, b: P2, reference: P2) -> P2 {
    if (a - reference).norm() <= (b - reference).norm() {
        a
    } else {
        b
    }
}

fn intersect_line_circle(p: P2, u: P2, c: P2, rho: f64, reference: P2) -> Option<P2> {
    let foot = p + u * (c - p).dot(&u);
    let h = (c - foot).norm();
    if h.is_nan() || h > rho + INTERSECTION_TOLERANCE {
        return None;
    }
    let half = (rho * rho - h * h).max(0.0).sqrt();
    Some(nearest(foot + u * half, foot - u * half, reference))
}

/// The intersection of two carriers nearest to `reference`.
fn intersect(a: Carrier, b: Carrier, reference: P2) -> Option<P2> {
    let x = match (a, b) {
        (Carrier::Line { p: p1, u: u1 }, Carrier::Line { p: p2, u: u2 }) => {
            let den = cross(u1, u2);
            if den.abs() <= 1e-12 {
                return None;
            }
            p1 + u1 * (cross(p2 - p1, u2) / den)
        }
        (Carrier::Line { p, u }, Carrier::Circle { c, rho })
        | (Carrier::Circle { c, rho }, Carrier::Line { p, u }) => {
            intersect_line_circle(p, u, c, rho, reference)?
        }
        (Carrier::Circle { c: c1, rho: r1 }, Carrier::Circle { c: c2, rho: r2 }) => {
            let dist = (c2 - c1).norm();
            if dist.is_nan()
                || dist <= LENGTH_TOLERANCE
                || dist > r1 + r2 + INTERSECTION_TOLERANCE
                || dist < (r1 - r2).abs() - INTERSECTION_TOLERANCE
            {
                return None;
            }
            let e = (c2 - c1) / dist;
            let along = (dist * dist + r1 * r1 - r2 * r2) / (2.0 * dist);
            let h = (r1 * r1 - along * along).max(0.0).sqrt();
            let base = c1 + e * along;
            nearest(base + left(e) * h, base - left(e) * h, reference)
        }
    };
    finite(x).then_some(x)
}

/// A side-change intersection is used only if it does not lie behind the
/// start of a line A or beyond the end of a line B.
fn side_change_usable(a: &Element, b: &Element, x: P2) -> bool {
    let behind_a =
        a.line_length().is_some() && (x - a.start()).dot(&a.end_tangent()) < -LENGTH_TOLERANCE;
    let beyond_b =
        b.line_length().is_some() && (b.end() - x).dot(&b.start_tangent()) < -LENGTH_TOLERANCE;
    !behind_a && !beyond_b
}

/// The corner between `a` (ending) and `b` (starting): `da` is A's signed
/// offset, `db` B's (only its sign counts: a corner uses A's value).
/// `None`: no intersection on the inner side (PS0033).
fn corner(
    a: &Element,
    b: &Element,
    da: f64,
    db: f64,
    role: Role,
    startup: StartupType,
) -> Option<Corner> {
    let pa = a.end();
    let pb = b.start();
    let t1 = a.end_tangent();
    let t2 = b.start_tangent();
    let side_change = da * db < 0.0;
    let db = if db == 0.0 {
        da
    } else {
        db.signum() * da.abs()
    };
    let qa = pa + left(t1) * da;
    let qb = pb + left(t2) * db;
    let reference = (qa + qb) * 0.5;
    let mut c = Corner::new();

    if side_change {
        if role == Role::StartUp {
            c.push(qb);
        } else {
            match intersect(carrier_end(a, da), carrier_start(b, db), reference) {
                Some(x) if side_change_usable(a, b, x) => c.push(x),
                _ => {
                    c.push(qa);
                    c.push(qb);
                }
            }
        }
        return Some(c);
    }

    let s = if da < 0.0 { -1.0 } else { 1.0 };
    let theta = cross(t1, t2).atan2(t1.dot(&t2));
    let st = s * theta;

    let acute = |c: &mut Corner| {
        let p1 = qa + t1 * da.abs();
        let p2 = qb - t2 * db.abs();
        if a.is_arc() {
            c.push(qa);
        }
        c.push(p1);
        c.push(p2);
        if b.is_arc() {
            c.push(qb);
        }
    };
    let type_a = startup == StartupType::A;

    if theta.abs() >= PI - ANGLE_TOLERANCE {
        // Reversal: outer side, acute.
        match role {
            Role::StartUp if type_a => c.push(qb),
            Role::Cancel if type_a => c.push(qa),
            _ => acute(&mut c),
        }
    } else if st.abs() <= ANGLE_TOLERANCE {
        // Tangent transition.
        c.push(qa);
        c.push(qb);
    } else if st > 0.0 {
        // Inner side.
        match role {
            Role::StartUp => c.push(qb),
            Role::Cancel => c.push(qa),
            Role::Offset => c.push(intersect(
                carrier_end(a, da),
                carrier_start(b, db),
                reference,
            )?),
        }
    } else if st >= -FRAC_PI_2 - ANGLE_TOLERANCE {
        // Outer side, obtuse (90° ≤ α < 180°).
        match role {
            Role::StartUp if type_a => c.push(qb),
            Role::Cancel if type_a => c.push(qa),
            _ => match intersect(carrier_end(a, da), carrier_start(b, db), reference) {
                Some(x) => c.push(x),
                None => acute(&mut c),
            },
        }
    } else {
        // Outer side, acute (α < 90°).
        match role {
            Role::StartUp if type_a => c.push(qb),
            Role::Cancel if type_a => c.push(qa),
            _ => acute(&mut c),
        }
    }
    Some(c)
}

/// The compensated sweep of an arc body from `a0` to `a1` and the
/// programmed sweep, both in the arc's sense of rotation.
fn arc_sweeps(from: P2, to: P2, center: P2, ccw: bool, a0: P2, a1: P2) -> (f64, f64) {
    let s = sigma(ccw);
    let u0 = from - center;
    let u1 = to - center;
    let programmed = if (to - from).norm() <= LENGTH_TOLERANCE {
        TAU
    } else {
        (s * (u1.y.atan2(u1.x) - u0.y.atan2(u0.x))).rem_euclid(TAU)
    };
    let shift = |prog: P2, comp: P2| {
        let v = comp - center;
        if v.norm() <= LENGTH_TOLERANCE {
            0.0
        } else {
            s * cross(prog, v).atan2(prog.dot(&v))
        }
    };
    (programmed + shift(u1, a1) - shift(u0, a0), programmed)
}

/// The interference check of the held block ending at `corner.first()`.
fn check_held(h: &Held, corner: &Corner) -> Result<(), CompError> {
    let end = corner.first();
    if !corner.is_finite() || !finite(h.start) {
        return Err(CompError::NonFinite { tag: h.tag });
    }
    if h.startup {
        return Ok(());
    }
    let reversed = match h.element {
        Element::Line { .. } => (end - h.start).dot(&h.element.end_tangent()) < -LENGTH_TOLERANCE,
        Element::Arc {
            from,
            to,
            center,
            ccw,
        } => {
            let (sweep, programmed) = arc_sweeps(from, to, center, ccw, h.start, end);
            let radius = (h.start - center).norm().max((end - center).norm());
            sweep * radius < -LENGTH_TOLERANCE || (sweep - programmed).abs() >= PI
        }
    };
    if reversed {
        return Err(CompError::Interference { tag: h.tag });
    }
    Ok(())
}

fn push_line(out: &mut Vec<Compensated>, from: P2, to: P2, tag: u32, rapid: bool, kind: PieceKind) {
    if from != to {
        out.push(Compensated {
            element: Some(Element::Line { from, to }),
            tag,
            rapid,
            kind,
        });
    }
}

/// The held block's own path from `h.start` to `corner.first()`, its
/// corner pieces, and the block without movement read after it.
fn emit_held(h: &Held, corner: &Corner, out: &mut Vec<Compensated>) {
    let end = corner.first();
    let kind = if h.startup {
        PieceKind::StartUp
    } else {
        PieceKind::Offset
    };
    match h.element {
        Element::Line { .. } => push_line(out, h.start, end, h.tag, h.rapid, kind),
        Element::Arc {
            from,
            to,
            center,
            ccw,
        } => push_arc(out, h, from, to, center, ccw, end),
    }
    for w in corner.points().windows(2) {
        push_line(out, w[0], w[1], h.tag, h.rapid, PieceKind::Corner);
    }
    if let Some(tag) = h.still {
        out.push(still(tag));
    }
}

fn push_arc(
    out: &mut Vec<Compensated>,
    h: &Held,
    from: P2,
    to: P2,
    center: P2,
    ccw: bool,
    end: P2,
) {
    let a0 = h.start;
    let (sweep, _) = arc_sweeps(from, to, center, ccw, a0, end);
    let r0 = (a0 - center).norm();
    let r1 = (end - center).norm();
    let chord = (end - a0).norm();
    let piece = |element| Compensated {
        element: Some(element),
        tag: h.tag,
        rapid: h.rapid,
        kind: PieceKind::Offset,
    };
    if sweep >= TAU - FULL_TURN_MARGIN && r0.min(r1) > LENGTH_TOLERANCE {
        // A full turn or more: two to four arcs of at most 180° each.
        let pieces: u32 = if sweep <= TAU {
            2
        } else if sweep <= 3.0 * PI {
            3
        } else {
            4
        };
        let n = f64::from(pieces);
        let angle0 = (a0 - center).y.atan2((a0 - center).x);
        let step = sigma(ccw) * sweep / n;
        let mut ends = [end; 4];
        for (i, q) in ends.iter_mut().enumerate().take(pieces as usize - 1) {
            let f = (i + 1) as f64;
            let angle = angle0 + step * f;
            *q = center + P2::new(angle.cos(), angle.sin()) * (r0 + (r1 - r0) * f / n);
        }
        if ends.iter().all(|q| finite(*q)) {
            let mut p = a0;
            for &q in &ends[..pieces as usize] {
                out.push(piece(Element::Arc {
                    from: p,
                    to: q,
                    center,
                    ccw,
                }));
                p = q;
            }
        } else if a0 != end {
            // Overflowed (absurd sizes): a straight move keeps the path finite.
            out.push(piece(Element::Line { from: a0, to: end }));
        }
    } else if sweep <= ANGLE_TOLERANCE
        || r0.min(r1) <= LENGTH_TOLERANCE
        || (chord <= MIN_ARC_CHORD && sweep < PI)
    {
        if a0 != end {
            out.push(piece(Element::Line { from: a0, to: end }));
        }
    } else {
        out.push(piece(Element::Arc {
            from: a0,
            to: end,
            center,
            ccw,
        }));
    }
}
