//! Adaptive linearisation: the pieces of a block over which straight
//! motion of the machine axes stays within the tolerances.
//!
//! A piece [s0, s1] of a block is kept when, at every check point inside
//! it, the tool tip and direction of the axes interpolated linearly between
//! the piece's ends (forward kinematics, [`Machine::forward`]) lie within
//! [`ACCEPT_SHARE`] of the tolerances from the tip and direction of the
//! block's own law at the same fraction of the piece; otherwise it is cut
//! in two at its middle. Under inverse time feed all axes move linearly in
//! time, and the block's law moves the tip uniformly in `s`, so the same
//! fraction is the same instant: the comparison is by time, stricter than
//! the distance to the nearest point of the path.
//!
//! The check points are samples, not a proof: [`ACCEPT_SHARE`] leaves room
//! for what lies between them (the deviation of a short chord is smooth,
//! largest near its middle, where the check points are densest).

use fiveaxis_control::Segment;
use fiveaxis_machine::{Joints, Machine};

use crate::PostOptions;
use crate::program::Quantum;

/// Fractions of a piece where the deviation is checked.
pub const CHECK_POINTS: [f64; 9] = [0.0625, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875, 0.9375];

/// Share of the tolerances a piece may use at its check points.
pub const ACCEPT_SHARE: f64 = 0.8;

/// Most turn of a rotary axis in one output block, degrees: well under
/// half a turn, so that a rollover axis, which takes the shorter way to an
/// absolute target, turns the way the block does.
pub const MAX_PIECE_TURN: f64 = 90.0;

/// Shortest piece, as a share of the block: below it the piece is kept
/// even if it misses the tolerances (counted as unresolved).
pub const MIN_PIECE: f64 = 1e-7;

/// Largest deviation reached.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Deviation {
    /// Tool tip, mm.
    pub tip: f64,
    /// Tool direction, degrees.
    pub angle: f64,
}

impl Deviation {
    /// The larger of each.
    pub fn max(self, other: Self) -> Self {
        Self {
            tip: self.tip.max(other.tip),
            angle: self.angle.max(other.angle),
        }
    }
}

/// What the linearisation of one block reached.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Outcome {
    /// Largest deviation at the check points of the kept pieces.
    pub deviation: Deviation,
    /// Pieces kept at the shortest length without meeting the tolerances.
    pub unresolved: u64,
    /// Whether the block reached [`MAX_BLOCK_PIECES`] with pieces still
    /// outside the tolerances (the output is not made then).
    pub capped: bool,
}

/// Most pieces one block may be cut into: 65,536 pieces hold a 1 m move
/// to 15 µm steps, far finer than any tolerance a control's look-ahead
/// can use. A block that needs more asks for a tolerance finer than the
/// output's digits can hold; without a bound it never ends (the shortest
/// piece, [`MIN_PIECE`], allows ten million pieces a block).
pub const MAX_BLOCK_PIECES: u64 = 1 << 16;

/// Most pending pieces (depth of the bisection).
const STACK: usize = 64;

/// Cuts the block `seg` into pieces and hands each piece's end position
/// (quantized to the output's digits) and its share of the block to `emit`,
/// in order.
pub fn pieces(
    machine: &Machine,
    seg: &Segment,
    options: &PostOptions,
    quantum: &Quantum,
    emit: impl FnMut(Joints, f64),
) -> Outcome {
    let law = |s: f64| seg.eval(machine, s);
    pieces_of(
        machine,
        &law,
        &seg.start,
        seg.tool_length,
        options,
        quantum,
        emit,
    )
}

/// [`pieces`] of any law of the machine axes in `s`, from `start` (where
/// the axes stand, `law(0)` to rounding): the output holds the tool tip of
/// `tool_length` and the direction of the law within the tolerances.
pub fn pieces_of(
    machine: &Machine,
    law: &dyn Fn(f64) -> Joints,
    start: &Joints,
    tool_length: f64,
    options: &PostOptions,
    quantum: &Quantum,
    mut emit: impl FnMut(Joints, f64),
) -> Outcome {
    let snap = |j: &Joints| quantum.snap(machine, j, &options.origin);
    let mut outcome = Outcome::default();
    // Pending pieces, the next one on top: (s0, start, s1, end).
    let mut stack = [(
        0.0,
        [0.0; fiveaxis_machine::MAX_AXES],
        0.0,
        [0.0; fiveaxis_machine::MAX_AXES],
    ); STACK];
    stack[0] = (0.0, *start, 1.0, snap(&law(1.0)));
    let mut depth = 1;
    let mut emitted = 0u64;
    while depth > 0 {
        depth -= 1;
        let (s0, a, s1, b) = stack[depth];
        let h = s1 - s0;
        let found = piece_deviation(machine, law, tool_length, s0, &a, s1, &b);
        let within = found.tip <= ACCEPT_SHARE * options.tolerance
            && found.angle <= ACCEPT_SHARE * options.angle_tolerance
            && max_turn(machine, &a, &b) <= MAX_PIECE_TURN;
        // Every pending piece gives at least one more: splitting this one
        // must leave room for them within the bound.
        let full = emitted + depth as u64 + 2 > MAX_BLOCK_PIECES;
        if within || h < MIN_PIECE || depth + 2 > STACK || full {
            if !within {
                outcome.unresolved += 1;
                outcome.capped |= full && h >= MIN_PIECE && depth + 2 <= STACK;
            }
            outcome.deviation = outcome.deviation.max(found);
            emitted += 1;
            emit(b, h);
            continue;
        }
        let mid = 0.5 * (s0 + s1);
        let m = snap(&law(mid));
        stack[depth] = (mid, m, s1, b);
        stack[depth + 1] = (s0, a, mid, m);
        depth += 2;
    }
    outcome
}

/// Deviation of the axes moving linearly from `a` (at `s0`) to `b` (at
/// `s1`) from the block's law, at the check points.
pub fn piece_deviation(
    machine: &Machine,
    law: &dyn Fn(f64) -> Joints,
    tool_length: f64,
    s0: f64,
    a: &Joints,
    s1: f64,
    b: &Joints,
) -> Deviation {
    let mut found = Deviation::default();
    let n = machine.axis_count();
    for t in CHECK_POINTS {
        let mut j = *a;
        for i in 0..n {
            j[i] = a[i] + (b[i] - a[i]) * t;
        }
        let out = machine.forward(&j, tool_length);
        let law = machine.forward(&law(s0 + (s1 - s0) * t), tool_length);
        found = found.max(Deviation {
            tip: (out.tip - law.tip).norm(),
            angle: angle_between(&out.dir, &law.dir),
        });
    }
    found
}

/// Angle between two unit vectors, degrees (accurate for small angles).
pub fn angle_between(u: &fiveaxis_machine::Vec3, v: &fiveaxis_machine::Vec3) -> f64 {
    u.cross(v).norm().atan2(u.dot(v)).to_degrees()
}

/// Largest turn of any rotary axis between two positions, degrees.
pub fn max_turn(machine: &Machine, a: &Joints, b: &Joints) -> f64 {
    (0..machine.rotary.len())
        .map(|k| {
            let i = machine.rotary_index(k);
            (b[i] - a[i]).abs()
        })
        .fold(0.0, f64::max)
}

/// Into how many equal moves a move from `a` to `b` must be cut so that no
/// rotary axis turns more than [`MAX_PIECE_TURN`] in one.
pub fn rollover_splits(machine: &Machine, a: &Joints, b: &Joints) -> u32 {
    let turn = max_turn(machine, a, b);
    // At most a few thousand turns in one block: the quotient fits.
    (turn / MAX_PIECE_TURN)
        .ceil()
        .clamp(1.0, f64::from(u32::MAX)) as u32
}
