//! Canned cycles for drilling (FANUC Series 30i operator's manual, chapter
//! "Canned cycles for drilling"): G73, G74, G76, G81 to G89 (group 09),
//! cancelled by G80 or a group-01 code, with G98 / G99 (group 10: return
//! to the initial level or to the R point).
//!
//! Every elementary move of a cycle is a segment of its own (rapid or
//! linear at F, on the cycle block's line) and goes through the ordinary
//! segment path, so that tool length compensation applies and the soft
//! limits are checked on each of them. Dwells, spindle stops, orientations
//! and reversals move no axis and make no row.
//!
//! The hole is drilled along the normal of the selected plane (G17: Z,
//! G18: Y, G19: X). Levels are positions of that axis in the work
//! coordinate system: the initial level (where the drilling axis stood
//! when the cycle mode began), the R point and the hole bottom Z. In G90,
//! R and Z are absolute; in G91, R is the distance from the initial level
//! and Z the distance from the R point, and the plane position is an
//! increment repeated K times. The stored R and Z are read in the mode of
//! the block that drills.
//!
//! Decisions where the manual leaves room, also in `docs/functions.md`:
//!
//! * G73 retracts [`PECK_RETRACT`] (No.5114) and G83 stops
//!   [`PECK_CLEARANCE`] (No.5115) above the previous depth: constants, the
//!   machine file has no such parameters yet.
//! * G76 and G87 shift by Q (its sign ignored) in the direction that
//!   No.5101#4 RD1 = #5 RD2 = 0 gives: + the first axis of the plane
//!   (G17 +X, G18 +Z, G19 +Y).
//! * G87 always returns to the initial level (its R point is below the
//!   work); G88's manual retraction is taken as a rapid move to the R
//!   point (then to the initial level in G98). On Haas G87 is "bore in,
//!   manual retract" ([`crate::dialect::Dialect::g87_manual_retract`]): G88
//!   without the dwell.
//! * Z and R are needed by the first block that drills after the cycle mode
//!   begins (FX0130); G80 and group-01 codes clear Z, R, Q and P.
//! * A block drills when it has an axis word or R (a block with only F, Q,
//!   P, K, M codes stores data); K0 stores the data and drills nothing.
//! * Under TCPC (G43.4 / G43.5, Haas G234; not on LinuxCNC) a cycle
//!   drills along the tool in the programming frame (the NX posts for
//!   FANUC 5-axis machines write `G43.4 … G98 G73 …` for 3+2 holes, and
//!   the Mori Seiki NMV post `G98 G82 X Y Z B90. C2700. R …` with the
//!   rotary words in the cycle block). Rotary words turn the axes with
//!   the positioning, as a G00 block of TCPC (`tcpc.rs`, `tcpc_rapid`);
//!   then every move is a straight line of the tip along the tool, exact
//!   as a joint line because the rotary axes stand. In G90 the programmed
//!   X Y Z is the tip at the hole bottom and the levels (R, the initial
//!   level, where the tool stands) are measured along the tool through
//!   it ([`HoleAxis::Tool`]); in G91 the levels keep the initial level's
//!   origin. With the tool along the plane's normal the cycle is the
//!   plain one ([`HoleAxis::Normal`]), to the last bit. The manuals give
//!   no alarm for it: docs/functions.md, "Canned cycles", has the
//!   decision. A rotary word under G43.5 is type 2's alarm (FX0073); any
//!   cycle under cutter compensation C or 3-D tool compensation is refused
//!   (FX0133).

use fiveaxis_gcode::Span;
use fiveaxis_machine::{Joints, Vec3};

use super::Controller;
use crate::alarm::{Alarm, Condition};
use crate::fanuc::DwellRules;
use crate::fanuc::{GCodes, OneShot};
use crate::modal::{Distance, TcpcType};
use crate::segment::{Motion, Segment};

/// G73's retraction d after each peck, mm (FANUC No.5114; the kernel uses
/// this value, the machine file has no such parameter).
pub const PECK_RETRACT: f64 = 0.1;
/// G83's clearance d: the rapid move back into the hole stops this far
/// short of the previous depth, mm (FANUC No.5115).
pub const PECK_CLEARANCE: f64 = 0.1;
/// LinuxCNC's G73 retract and G83 clearance: 0.010 in, 0.254 mm
/// (g-code.adoc, G73 and G83: "the default of .010\" / 0.254 mm"; `rs274`
/// prints 0.254 mm under G21 too).
pub const LINUXCNC_PECK_CLEARANCE: f64 = 0.254;
/// Most segments one cycle block may make (K repeats times pecks): a bound
/// that holds whatever the magnitudes of Z, R, Q and K.
pub const MAX_CYCLE_SEGMENTS: usize = 1 << 16;

/// The canned cycle of group 09.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cycle {
    /// High-speed peck drilling.
    G73,
    /// Left-hand tapping.
    G74,
    /// Fine boring.
    G76,
    /// Drilling, spot drilling.
    G81,
    /// Drilling, counter boring (dwell).
    G82,
    /// Peck drilling.
    G83,
    /// Tapping.
    G84,
    /// Boring (feed out).
    G85,
    /// Boring (spindle stop, rapid out).
    G86,
    /// Back boring.
    G87,
    /// Boring (dwell, manual retract).
    G88,
    /// Boring (dwell, feed out).
    G89,
}

impl Cycle {
    /// The G code number (`#4009`).
    pub(super) fn g_number(self) -> f64 {
        match self {
            Cycle::G73 => 73.0,
            Cycle::G74 => 74.0,
            Cycle::G76 => 76.0,
            Cycle::G81 => 81.0,
            Cycle::G82 => 82.0,
            Cycle::G83 => 83.0,
            Cycle::G84 => 84.0,
            Cycle::G85 => 85.0,
            Cycle::G86 => 86.0,
            Cycle::G87 => 87.0,
            Cycle::G88 => 88.0,
            Cycle::G89 => 89.0,
        }
    }
}

/// Canned cycle modal state and its stored drilling data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct CycleState {
    /// The cycle in force (None: G80).
    pub(super) cycle: Option<Cycle>,
    /// G98 (true, power-on) or G99.
    pub(super) return_initial: bool,
    /// The cycle mode began in this block: the initial level is taken.
    pending_initial: bool,
    /// Programmed X, Y, Z when the cycle mode began.
    initial: [f64; 3],
    /// R as programmed (mm): absolute, or from the initial level in G91.
    r: Option<f64>,
    /// Z as programmed (mm): absolute, or from the R point in G91.
    z: Option<f64>,
    /// Q, mm, sign dropped (0: not given).
    q: f64,
    /// P, ms.
    p: u32,
    /// LinuxCNC's D of G73 / G83, the peck clearance, mm (None: the
    /// configuration's or the default).
    d: Option<f64>,
    /// Under TCPC with the tool off the plane's normal: the last hole's
    /// position (its bottom in G90, the positioned point in G91) and the
    /// tip where the cycle left the tool, so that the next block's
    /// omitted plane words and G91 increments start from the hole and not
    /// from the tip on the tilted hole axis.
    last_hole: Option<([f64; 3], [f64; 3])>,
}

impl Default for CycleState {
    fn default() -> Self {
        Self {
            cycle: None,
            return_initial: true,
            pending_initial: false,
            initial: [0.0; 3],
            r: None,
            z: None,
            q: 0.0,
            p: 0,
            d: None,
            last_hole: None,
        }
    }
}

impl CycleState {
    /// G80 or a group-01 code: the mode and its drilling data end.
    pub(super) fn cancel(&mut self) {
        *self = Self {
            return_initial: self.return_initial,
            ..Self::default()
        };
    }
}

/// The levels of one hole along the drilling axis, in programmed
/// coordinates.
#[derive(Clone, Copy, Debug)]
struct Levels {
    initial: f64,
    r: f64,
    bottom: f64,
    /// Where the tool goes after the hole (G98: initial, G99: R).
    back: f64,
}

/// How far (as a difference of unit vectors) the tool may be from the
/// plane's normal and the cycle still drill along the normal itself.
const NORMAL_SNAP: f64 = 1e-12;

/// The line a hole is drilled along, in programmed coordinates.
#[derive(Clone, Copy, Debug)]
enum HoleAxis {
    /// Along the plane's normal: a level is that axis's coordinate and
    /// the plane position is the hole's.
    Normal,
    /// Along the tool under TCPC: the point at level `l` is `anchor + (l -
    /// anchor_level) dir`; G76 / G87 shift along `shift`.
    Tool {
        anchor: Vec3,
        anchor_level: f64,
        dir: Vec3,
        shift: Vec3,
    },
}

impl HoleAxis {
    /// The programmed point at `level` (with Q's shift when `shifted`);
    /// the rotary words and other axes as in `hole`.
    fn at(&self, hole: &Joints, axes: [usize; 3], level: f64, shift: f64, shifted: bool) -> Joints {
        let [first, _, n] = axes;
        let mut p = *hole;
        match *self {
            HoleAxis::Normal => {
                p[n] = level;
                if shifted {
                    p[first] += shift;
                }
            }
            HoleAxis::Tool {
                anchor,
                anchor_level,
                dir,
                shift: along,
            } => {
                let mut q = anchor + (level - anchor_level) * dir;
                if shifted {
                    q += shift * along;
                }
                p[..3].copy_from_slice(q.as_slice());
            }
        }
        p
    }
}

impl Controller<'_> {
    /// Groups 09 and 10 of the block: G73 … G89, G80, G98, G99; a group-01
    /// code cancels the cycle. Called after the other modal groups.
    pub(super) fn apply_cycle_codes(&mut self, codes: &GCodes) -> Result<(), Alarm> {
        if let Some(initial) = codes.cycle_return {
            self.state.cycle.return_initial = initial;
        }
        if codes.motion.is_some() {
            self.state.cycle.cancel();
        }
        if let Some((cycle, _)) = codes.cycle {
            match cycle {
                None => self.state.cycle.cancel(),
                Some(cycle) => {
                    if self.state.cycle.cycle.is_none() {
                        self.state.cycle.pending_initial = true;
                    }
                    self.state.cycle.cycle = Some(cycle);
                }
            }
        }
        if self.state.cycle.cycle.is_some()
            && let Some((what, span, code)) = codes.one_shot
            && matches!(
                what,
                OneShot::ReferenceCheck | OneShot::ReferenceReturn { .. }
            )
        {
            return Err(self.alarm(
                Condition::CycleReferenceReturn,
                Some(span),
                format!("G{code} cannot be commanded in a canned cycle: cancel it with G80 first"),
            ));
        }
        Ok(())
    }

    /// Whether a canned cycle is in force.
    pub(super) fn cycle_active(&self) -> bool {
        self.state.cycle.cycle.is_some()
    }

    /// A block in the canned cycle mode: stores its drilling data and, when
    /// it has an axis word or R, drills K times.
    pub(super) fn cycle_motion(
        &mut self,
        codes: &GCodes,
        from: &Joints,
        length_changed: bool,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let code_span = codes.cycle.map(|(_, span)| span);
        self.cycle_allowed(code_span)?;
        // A block that cutter compensation C still holds (its cancel
        // block) is emitted first: the cycle starts where it ends.
        let base = out.len();
        if self.cutter.routing() {
            self.cutter_c_finish(out)?;
            self.cutter.engine.reset();
        }
        let start = out[base..].last().map_or(self.state.joints, |seg| seg.end);
        let from = &if out.len() > base {
            self.programmed(&start)
        } else {
            *from
        };
        let Some(cycle) = self.state.cycle.cycle else {
            return Ok(());
        };
        let [_, _, n] = self.state.modal.plane.axes();
        if std::mem::take(&mut self.state.cycle.pending_initial) {
            self.state.cycle.initial = [from[0], from[1], from[2]];
        }
        let rules = self.rules();
        let dwell = DwellRules {
            seconds_with_point: self.dialect.dwell_p_seconds_with_point,
            seconds: self.dialect.dwell_p_seconds,
        };
        let peck_clearance = self.dialect.rs274ngc && matches!(cycle, Cycle::G73 | Cycle::G83);
        let data = self.fanuc.cycle_data(&rules, dwell, peck_clearance)?;
        if let Some(r) = data.r {
            self.state.cycle.r = Some(r);
        }
        if let Some(q) = data.q {
            self.state.cycle.q = q;
        }
        if let Some(d) = data.d {
            self.state.cycle.d = Some(d);
        }
        if let Some(p) = data.p {
            self.state.cycle.p = p;
        }
        let repeats = data.repeats;
        let mut targets = data.targets;
        let drills = targets.iter().any(Option::is_some) || data.r.is_some();
        if let Some(z) = targets[n].take() {
            self.state.cycle.z = Some(z);
        }
        if !drills {
            if length_changed {
                // A change of the length offset alone moves as outside
                // the cycle.
                return self.motion(from, true, out);
            }
            return Ok(());
        }
        if repeats == 0 {
            return Ok(());
        }
        if self.dialect.rs274ngc && cycle == Cycle::G86 && data.p.is_none() {
            // LinuxCNC (g-code.adoc, G86: "uses a P number"; rs274: "Dwell
            // time p word missing with g86").
            return Err(self.alarm(
                Condition::CycleDataMissing,
                code_span,
                "G86 needs P, the dwell in seconds at the bottom (LinuxCNC)".into(),
            ));
        }
        if self.dialect.rs274ngc && cycle == Cycle::G86 && !self.state.spindle_on {
            // LinuxCNC (g-code.adoc, G86: "It is an error if the spindle is
            // not turning"; rs274: "Spindle not turning in g86").
            return Err(self.alarm(
                Condition::CycleNotAllowed,
                code_span,
                "G86 with the spindle stopped: LinuxCNC needs it turning (M3 or M4)".into(),
            ));
        }
        let levels = self.cycle_levels(cycle, code_span, self.state.cycle.initial[n])?;
        let pecks = if matches!(cycle, Cycle::G73 | Cycle::G83) {
            let q = self.state.cycle.q;
            if q <= 0.0 {
                return Err(self.alarm(
                    Condition::CycleDepthMissing,
                    data.q_span.or(code_span),
                    format!("{cycle:?} needs Q, the depth of each cut, greater than 0"),
                ));
            }
            let depth = (levels.bottom - levels.r).abs();
            let count = (depth / q - 1e-9).ceil().max(1.0);
            if count * 3.0 * f64::from(repeats) > MAX_CYCLE_SEGMENTS as f64 {
                return Err(self.alarm(
                    Condition::ValueOutOfRange,
                    data.q_span.or(code_span),
                    format!(
                        "Q{q} cuts {depth} mm in {count} pecks, {repeats} times: more than {MAX_CYCLE_SEGMENTS} moves"
                    ),
                ));
            }
            count as u32
        } else {
            0
        };
        // Under TCPC (FANUC, Mitsubishi, Mazak, Haas G234) the hole runs
        // along the tool; LinuxCNC's interpreter knows no tool direction.
        let tool_axis = self.tcpc_type().is_some() && !self.dialect.rs274ngc;
        let incremental = self.state.modal.distance == Distance::Incremental;
        let mut tip = Vec3::new(from[0], from[1], from[2]);
        let mut hole = *from;
        if let Some((anchor, left)) = self.state.cycle.last_hole.take()
            && (Vec3::from(left) - tip).norm() < 1e-9
        {
            hole[..3].copy_from_slice(&anchor);
        }
        let mut cur = start;
        if self.dialect.rs274ngc && (levels.r - hole[n]) * (levels.bottom - levels.r) < 0.0 {
            // LinuxCNC's preliminary motion: from below R the drilling
            // axis goes to R first, once whatever L is (g-code.adoc,
            // Preliminary and In-Between Motion).
            hole[n] = levels.r;
            tip[n] = levels.r;
            let end = self.machine_position(&hole);
            self.push_line(Motion::Rapid, cur, end, out)?;
            cur = end;
        }
        let axes = self.state.modal.plane.axes();
        for _ in 0..repeats {
            // Positioning in the plane (and any other named axis, the
            // rotary axes too) at the level where the tool stands.
            let (mut end_p, travel) = self.end_point(&hole, &targets);
            let mut lv = levels;
            let direction = if tool_axis {
                self.drilling_direction(&end_p)
            } else {
                None
            };
            let (axis, here) = match direction {
                None => {
                    end_p[n] = tip[n];
                    (HoleAxis::Normal, tip[n])
                }
                Some(dir) => {
                    // Levels along the tool: l(p) = p.dir + c, with c such
                    // that the programmed point X Y Z is the hole bottom
                    // (G90), or the initial level the tip's own (G91).
                    let mut anchor = Vec3::new(end_p[0], end_p[1], end_p[2]);
                    let p0 = Vec3::from(self.state.cycle.initial);
                    let c = if incremental {
                        p0[n] - p0.dot(&dir)
                    } else {
                        anchor[n] = levels.bottom;
                        levels.bottom - anchor.dot(&dir)
                    };
                    if !incremental {
                        lv = self.cycle_levels(cycle, code_span, p0.dot(&dir) + c)?;
                    }
                    let anchor_level = anchor.dot(&dir) + c;
                    let here = tip.dot(&dir) + c;
                    let axis = HoleAxis::Tool {
                        anchor,
                        anchor_level,
                        dir,
                        shift: self.shift_direction(&dir),
                    };
                    end_p = axis.at(&end_p, axes, here, 0.0, false);
                    (axis, here)
                }
            };
            let end = self.machine_position(&end_p);
            let mut start = cur;
            for i in 3..self.machine.axis_count() {
                if self.is_rollover(i) {
                    start[i] = end[i] - travel[i];
                }
            }
            let mut standing = hole;
            standing[..3].copy_from_slice(tip.as_slice());
            let turns = (3..self.machine.axis_count()).any(|i| travel[i] != 0.0);
            if self.tcpc_type().is_some() && turns {
                // The rotary axes turn with the positioning (operation 1),
                // the tip straight in the programming frame as in G00.
                self.tcpc_rapid(start, &end_p, end, &travel, out)?;
                cur = end;
            } else if end_p != standing {
                // No positioning when the hole is where the tool stands
                // (under TCPC the machine position computed again may
                // differ by a rounding, which is no move).
                self.push_line(Motion::Rapid, start, end, out)?;
                cur = end;
            }
            cur = self.hole(cycle, &lv, pecks, &end_p, here, &axis, cur, out)?;
            let left = if cycle == Cycle::G87 && !self.dialect.g87_manual_retract {
                lv.initial
            } else {
                lv.back
            };
            let after = axis.at(&end_p, axes, left, 0.0, false);
            tip = Vec3::new(after[0], after[1], after[2]);
            hole = end_p;
            match axis {
                HoleAxis::Normal => hole[n] = left,
                HoleAxis::Tool { anchor, .. } => hole[..3].copy_from_slice(anchor.as_slice()),
            }
        }
        if hole[..3] != *tip.as_slice() {
            self.state.cycle.last_hole = Some(([hole[0], hole[1], hole[2]], tip.into()));
        }
        Ok(())
    }

    /// The direction a hole is drilled along under TCPC with the rotary
    /// axes of `end_p`: the tool's, turned to the side of the plane's
    /// normal; `None` when that is the normal itself.
    fn drilling_direction(&self, end_p: &Joints) -> Option<Vec3> {
        let [_, _, n] = self.state.modal.plane.axes();
        let joints = self.machine_position(end_p);
        let tool = self.tcpc_tool_direction(&joints).normalize();
        let dir = if tool[n] < 0.0 { -tool } else { tool };
        let mut normal = Vec3::zeros();
        normal[n] = 1.0;
        ((dir - normal).norm() > NORMAL_SNAP).then_some(dir)
    }

    /// G76 / G87's shift under a tool off the normal: the plane's first
    /// axis made square to the tool (its second when the tool lies along
    /// the first).
    fn shift_direction(&self, dir: &Vec3) -> Vec3 {
        let [first, second, _] = self.state.modal.plane.axes();
        let square = |k: usize| {
            let mut e = Vec3::zeros();
            e[k] = 1.0;
            e - e.dot(dir) * dir
        };
        let v = square(first);
        if v.norm() > 1e-6 {
            v.normalize()
        } else {
            square(second).normalize()
        }
    }

    /// Cutter compensation C and 3-D tool compensation refuse canned
    /// cycles; under G43.5 a rotary word is type 2's alarm.
    fn cycle_allowed(&self, span: Option<Span>) -> Result<(), Alarm> {
        if self.tcpc_type() == Some(TcpcType::Vector)
            && let Some((i, span)) = self
                .fanuc
                .first_axis(&self.rules(), self.machine.linear.len())
        {
            // Type 2 gives the tool by I J K, never by rotary words: the
            // alarm of any G43.5 block with one.
            let name = self.axis_letters[i];
            return Err(self.alarm(
                Condition::TcpcRotaryWordInType2,
                Some(span),
                format!(
                    "rotary axis word {} in TCPC type 2: program the tool vector I, J, K",
                    char::from(name)
                ),
            ));
        }
        let mode = if self.state.comp3d.active {
            "3-D tool compensation"
        } else if self.cutter.side.is_some() {
            "cutter compensation C (G41/G42)"
        } else {
            return Ok(());
        };
        Err(self.alarm(
            Condition::CycleNotAllowed,
            span,
            format!("a canned cycle cannot be used in {mode}: cancel it first"),
        ))
    }

    /// The levels of the holes from the stored R and Z, the initial level
    /// being `initial`.
    fn cycle_levels(
        &self,
        cycle: Cycle,
        span: Option<Span>,
        initial: f64,
    ) -> Result<Levels, Alarm> {
        let [_, _, n] = self.state.modal.plane.axes();
        let letter = char::from(self.axis_letters[n]);
        let c = &self.state.cycle;
        let (Some(r), Some(z)) = (c.r, c.z) else {
            let missing = if c.z.is_none() {
                format!("{letter} (the hole bottom)")
            } else {
                "R (the R point)".into()
            };
            return Err(self.alarm(
                Condition::CycleDataMissing,
                span,
                format!("the canned cycle {cycle:?} has no {missing}"),
            ));
        };
        let (r, bottom) = if self.state.modal.distance == Distance::Incremental {
            (initial + r, initial + r + z)
        } else {
            (r, z)
        };
        // LinuxCNC's G98 goes back to the old Z only when it is above R
        // (g-code.adoc, Retract Mode); FANUC's to the initial level.
        let above_r = (initial - r) * (bottom - r) < 0.0;
        let back = if c.return_initial && (above_r || !self.dialect.rs274ngc) {
            initial
        } else {
            r
        };
        Ok(Levels {
            initial,
            r,
            bottom,
            back,
        })
    }

    /// LinuxCNC's peck clearance of G73 (the retract after each peck) and
    /// G83 (how far above the last depth the rapid return stops): the D
    /// word, else the configuration's `[RS274NGC] G73_PECK_CLEARANCE` /
    /// `G83_PECK_CLEARANCE` (machine file `[parameters.ini.RS274NGC]`, in
    /// the machine's unit), else 0.254 mm (g-code.adoc, G73 and G83).
    fn linuxcnc_peck_clearance(&self, cycle: Cycle) -> f64 {
        if let Some(d) = self.state.cycle.d {
            return d;
        }
        let key = if cycle == Cycle::G73 {
            "RS274NGC]G73_PECK_CLEARANCE"
        } else {
            "RS274NGC]G83_PECK_CLEARANCE"
        };
        let params = &self.machine.params;
        match params.ini_values.get(key) {
            Some(v) if params.input_unit == fiveaxis_machine::InputUnit::Inch => v * 25.4,
            Some(v) => *v,
            None => LINUXCNC_PECK_CLEARANCE,
        }
    }

    /// One hole along `axis` (the other axes as in `hole`), the tool at
    /// level `here`, from machine position `cur`. Returns where the
    /// machine ends.
    #[allow(clippy::too_many_arguments)]
    fn hole(
        &self,
        cycle: Cycle,
        lv: &Levels,
        pecks: u32,
        hole: &Joints,
        here: f64,
        axis: &HoleAxis,
        cur: Joints,
        out: &mut Vec<Segment>,
    ) -> Result<Joints, Alarm> {
        let axes = self.state.modal.plane.axes();
        let shift = self.state.cycle.q;
        let mut cur = cur;
        let mut go = |motion: Motion, level: f64, shifted: bool, out: &mut Vec<Segment>| {
            let p = axis.at(hole, axes, level, shift, shifted);
            let end = self.machine_position(&p);
            self.push_line(motion, cur, end, out)?;
            cur = end;
            Ok::<(), Alarm>(())
        };
        let (retract, clearance) = if self.dialect.rs274ngc {
            let d = self.linuxcnc_peck_clearance(cycle);
            (d, d)
        } else {
            (PECK_RETRACT, PECK_CLEARANCE)
        };
        let (rapid, feed) = (Motion::Rapid, Motion::Linear);
        let into = (lv.bottom - lv.r).signum();
        // A level short of `depth` by `d`, not above the R point.
        let short = |depth: f64, d: f64| {
            let level = depth - into * d;
            if (level - lv.r) * into < 0.0 {
                lv.r
            } else {
                level
            }
        };
        let back_boring = cycle == Cycle::G87 && !self.dialect.g87_manual_retract;
        if back_boring {
            go(rapid, here, true, out)?;
            go(rapid, lv.r, true, out)?;
            go(rapid, lv.r, false, out)?;
            go(feed, lv.bottom, false, out)?;
            go(rapid, lv.bottom, true, out)?;
            go(rapid, lv.initial, true, out)?;
            go(rapid, lv.initial, false, out)?;
            return Ok(cur);
        }
        go(rapid, lv.r, false, out)?;
        match cycle {
            Cycle::G73 | Cycle::G83 => {
                let q = self.state.cycle.q;
                for i in 1..=pecks {
                    let next = if i == pecks {
                        lv.bottom
                    } else {
                        lv.r + into * q * f64::from(i)
                    };
                    go(feed, next, false, out)?;
                    if i == pecks {
                        break;
                    }
                    if cycle == Cycle::G73 {
                        go(rapid, short(next, retract), false, out)?;
                    } else {
                        go(rapid, lv.r, false, out)?;
                        go(rapid, short(next, clearance), false, out)?;
                    }
                }
                go(rapid, lv.back, false, out)?;
            }
            Cycle::G81 | Cycle::G82 | Cycle::G86 => {
                go(feed, lv.bottom, false, out)?;
                go(rapid, lv.back, false, out)?;
            }
            // LinuxCNC G89 (g-code.adoc): after the dwell "retract the
            // Z-axis at the current feed rate to clear Z", one feed move.
            Cycle::G89 if self.dialect.rs274ngc => {
                go(feed, lv.bottom, false, out)?;
                go(feed, lv.back, false, out)?;
            }
            Cycle::G74 | Cycle::G84 | Cycle::G85 | Cycle::G89 => {
                go(feed, lv.bottom, false, out)?;
                go(feed, lv.r, false, out)?;
                go(rapid, lv.back, false, out)?;
            }
            // Haas's G87 is G88 without the dwell (bore in, manual retract).
            Cycle::G88 | Cycle::G87 => {
                go(feed, lv.bottom, false, out)?;
                go(rapid, lv.r, false, out)?;
                go(rapid, lv.back, false, out)?;
            }
            Cycle::G76 => {
                go(feed, lv.bottom, false, out)?;
                go(rapid, lv.bottom, true, out)?;
                go(rapid, lv.back, true, out)?;
                go(rapid, lv.back, false, out)?;
            }
        }
        Ok(cur)
    }
}
