//! The HEIDENHAIN TNC (Klartext) drilling and boring cycles the front end
//! carries out itself: `CYCL DEF 200` … `209`, `240` and `241`, and the
//! point patterns of `PATTERN DEF`.
//!
//! A pure module: a cycle call becomes a list of elementary [`Step`]s
//! (rapid and feed moves in programmed coordinates, helices, dwells,
//! spindle functions), a `PATTERN DEF` a list of points; the controller
//! carries them out. Nothing here reads or changes the controller.
//!
//! # Sources
//!
//! * [T640C]: HEIDENHAIN TNC 640 / TNC 620 user's manual "Programming of
//!   Machining Cycles" (cycle run, parameter descriptions), as far as it
//!   was reachable; the older TNC 320 / TNC 426 / TNC 430 user's manuals
//!   (chapter 8, "Cycles for Drilling, Tapping and Thread Milling") where
//!   their text is the same.
//! * [BRIEF §9]: the design brief
//!   (`/work/shared/design/sinumerik-heidenhain-brief.md`, §9: `CYCL DEF`
//!   form, parameter lists of 200, 203, 207).
//! * [POST]: the parameter lists a Fusion HEIDENHAIN post and hyperMILL
//!   write (which parameters real programs carry, `Q208=MAX`,
//!   `Q253=MAX`).
//!
//! Everything else is the kernel's reading, marked *kernel*; facts not
//! confirmed in a retrieved source are marked *UNVERIFIED*.
//!
//! # Parameters
//!
//! `params` are the `Q` parameters of the `CYCL DEF` as written
//! (`Q200=2` is `(200, 2.0)`). Every cycle has a list of the parameters
//! it reads: a missing required one, one not in the list, one written
//! twice, or a value that is not finite is refused naming the Q number
//! (*kernel*: a parameter the kernel does not read may change what the
//! TNC does). Parameters that later software versions added (Q395, Q336
//! of 202/207, Q403, Q379/Q253/Q208 of 205, Q351, Q342, Q429/Q430, Q435,
//! Q401, Q202/Q212/Q205 of 241) are optional with the value that leaves
//! them without effect.
//!
//! * Feeds are mm/min. A feed of [`FMAX`] (99999.999, what a `MAX` /
//!   `FMAX` entry is passed as) or more is rapid traverse; [`FAUTO`] (−1)
//!   is the feed in force ([`Context::feed`], the TNC's FAUTO takes the
//!   feed of the `TOOL CALL`); any other feed must be above 0.
//! * Dwells are seconds, not negative.
//!
//! # Levels (every cycle)
//!
//! The hole is machined along the applicate of the working plane at the
//! position where the tool stands in the plane when the cycle is called
//! [T640C]. Q203 is the workpiece surface (absolute); Q200 the set-up
//! clearance above it (incremental; taken without its sign, *kernel*);
//! Q204 the 2nd set-up clearance above the surface (incremental, not
//! negative). Q201 the depth below the surface, incremental; its sign
//! gives the working direction [T640C]:
//!
//! * Q201 = 0: the cycle is not carried out (no steps) [T640C].
//! * Q201 > 0: refused (*kernel*: the TNC refuses a positive depth only
//!   when its machine parameter asks for "enter depth with a negative
//!   sign"; the kernel always does, as a positive depth would bore
//!   upwards into the clearance).
//!
//! Every cycle starts with a rapid move on the applicate straight to the
//! set-up clearance Q203 + Q200 [T640C], from above or below (*kernel*:
//! no detour to the 2nd set-up clearance first), and ends with one rapid
//! move to the set-up clearance or, when Q204 is greater, to the 2nd
//! set-up clearance: Q203 + max(Q200, Q204) [T640C: "returns to set-up
//! clearance or, if programmed, to the 2nd set-up clearance"].
//!
//! Q395 (200, 203, 205; depth reference): 0 the depth is that of the tool
//! tip; 1 that of the cylindrical part, so the tip goes deeper by
//! R / tan(T-ANGLE / 2) [T640C]. The kernel does that with
//! [`Context::point_angle`] and [`Context::tool_radius`], and refuses
//! Q395 = 1 without them.
//!
//! # Cycles
//!
//! * **200 DRILLING** (Q200 Q201 Q206 Q202 Q210 Q203 Q204 [Q211 Q395]):
//!   feed Q206 to the first plunging depth Q202, rapid back to the set-up
//!   clearance, dwell Q210, rapid to Q200 above the depth reached, feed
//!   on; at the depth dwell Q211, rapid out [T640C]. A plunging depth at
//!   or above the depth goes to depth in one move [T640C]. Q202 must be
//!   above 0 (*kernel*).
//! * **201 REAMING** (Q200 Q201 Q206 Q211 Q208 Q203 Q204): feed Q206 to
//!   depth, dwell Q211, retract at Q208 to the set-up clearance (Q208 = 0:
//!   at Q206) [T640C], rapid out.
//! * **202 BORING** (Q200 Q201 Q206 Q211 Q208 Q203 Q204 Q214 [Q336]):
//!   feed to depth, dwell Q211 with the spindle turning, oriented spindle
//!   stop at Q336 ([`Step::Orient`]; omitted: 0°), with Q214 ≠ 0 a move of
//!   0.2 mm off the wall in the plane (1: −first axis, 2: −second axis,
//!   3: +first axis, 4: +second axis) [T640C], retract at Q208 (0: Q206),
//!   rapid back over the hole centre (*kernel*: at the set-up clearance,
//!   *UNVERIFIED* order), rapid out, spindle on again in the direction in
//!   force [T640C: the spindle state at the cycle start is restored]. The
//!   0.2 mm move is rapid (*kernel*).
//! * **203 UNIVERSAL DRILLING** (Q200 Q201 Q206 Q202 Q210 Q203 Q204 Q212
//!   Q213 Q205 Q211 Q208 Q256 [Q395]): pecks of Q202, each the one before
//!   less the decrement Q212 but not less than Q205 [T640C]. After each
//!   peck but the last: while fewer than Q213 chip breaks were made since
//!   the tool last left the hole, a chip break (rapid retract by Q256,
//!   then feed on; *UNVERIFIED* that the break retract is rapid);
//!   otherwise retract at Q208 (0: Q206) to the set-up clearance, dwell
//!   Q210, rapid to Q200 above the depth reached [T640C]. Q213 = 0: every
//!   peck leaves the hole. At depth dwell Q211, retract at Q208, rapid
//!   out. A decrement with Q205 = 0 that would bring the peck to 0 is
//!   refused (*kernel*).
//! * **204 BACK BORING** (Q200 Q249 Q250 Q251 Q252 Q253 Q254 Q255 Q203
//!   Q204 Q214 [Q336]): Q250 material thickness, Q249 counterbore depth
//!   (up from the underside, > 0), Q251 off-centre distance, Q252 tool
//!   edge height (tool length to the underside of the bar, the edge Q252
//!   above it), Q253 pre-positioning feed, Q254 counterboring feed, Q255
//!   dwell, Q214 1…4 as in 202 [T640C]. Steps: rapid to the set-up
//!   clearance, oriented stop at Q336, rapid off-centre by Q251 in the Q214
//!   direction, at Q253 down until the edge is Q200 below the underside
//!   (tip at Q203 − Q250 − Q200 − Q252), at Q253 back to the centre,
//!   spindle on (direction in force), feed Q254 up until the edge is at
//!   the counterbore depth (tip at Q203 − Q250 + Q249 − Q252), dwell Q255,
//!   oriented stop, at Q253 off-centre again, at Q253 up to the set-up
//!   clearance, rapid out, rapid back to the centre, spindle on [T640C for
//!   the sequence; *kernel* for the speeds of the in-plane moves and the
//!   last two steps]. Coolant is not switched (no M8 step).
//! * **205 UNIVERSAL PECKING** (Q200 Q201 Q206 Q202 Q203 Q204 Q212 Q205
//!   Q258 Q259 Q257 Q256 Q211 [Q379 Q253 Q208 Q395]): with a deepened
//!   starting point Q379 > 0 the tool first moves at Q253 to Q200 above
//!   it [T640C] and the pecks count from there. Pecks as in 203 (Q202,
//!   Q212, Q205). Within a peck, every Q257 of depth a chip break: rapid
//!   retract by Q256, feed on (Q257 = 0: none) [T640C]. After each peck
//!   but the last, retract at Q208 to the set-up clearance, rapid back to
//!   the advanced stop distance above the depth reached: Q258 after the
//!   first peck, Q259 before the last, in between in equal steps [T640C:
//!   "changes … at the same rate"; the kernel's reading of the rate]. At
//!   depth dwell Q211, retract at Q208, rapid out. Q208 = 0: Q206
//!   [T640C]; Q208 omitted (the older cycle): rapid (*kernel*). The
//!   retraction with Q379 goes straight to the set-up clearance at Q208
//!   (*UNVERIFIED*).
//! * **207 RIGID TAPPING NEW** (Q200 Q201 Q239 Q203 Q204 [Q336]): Q239 the
//!   pitch, its sign the hand (+ right, − left) [T640C]. The feed is
//!   |Q239| × the speed in force. Oriented stop at Q336 if written, spindle
//!   on for the hand (M3 right, M4 left), tap to depth, reverse (M4 / M3),
//!   tap out to the set-up clearance, M5, rapid out [T640C: the spindle
//!   stops at the set-up clearance; *UNVERIFIED* in every version].
//! * **208 BORE MILLING** (Q200 Q201 Q206 Q334 Q203 Q204 Q335 [Q342 Q351]):
//!   Q335 the hole diameter, Q334 the infeed per helix turn, Q206 the feed
//!   on the helix [T640C]. Q335 equal to the tool diameter: a straight
//!   plunge at Q206 to depth [T640C]; smaller: refused; above twice the
//!   tool diameter refused unless the roughing (pre-drilled) diameter Q342
//!   is above 0, which only lifts that check [T640C]. Otherwise: at the
//!   set-up clearance a feed move from the centre to the helix start at
//!   Q335/2 − R along +first axis (*kernel*), helix turns about the centre
//!   from the set-up clearance down to the depth, each turn Q334 lower,
//!   the last one the part turn left, one full circle at depth, a feed back
//!   to the centre [T640C; *kernel*: the feed], rapid out. Q351 +1 climb,
//!   −1 up-cut, for M3 [T640C]; climb with M3 is counterclockwise in the
//!   plane, up-cut clockwise, and M4 turns both round (*kernel*). Q351
//!   omitted (the older cycle): climb (*UNVERIFIED*).
//! * **209 TAPPING W/ CHIP BRKG** (Q200 Q201 Q239 Q203 Q204 Q257 Q256 Q336
//!   [Q403]): as 207, oriented stop at Q336 at the set-up clearance, and
//!   every Q257 of depth the spindle reverses and the tool taps back by
//!   Q256 × |Q239| (Q256 = 0: out to the set-up clearance), then forward
//!   again [T640C]. Q257 = 0: no chip breaking. Retraction moves run at
//!   Q403 × the speed (omitted: 1) with their feed in proportion [T640C];
//!   the speed in force is set back after each. M5 at the set-up clearance
//!   as in 207 (*UNVERIFIED*).
//! * **240 CENTERING** (Q200 Q343 Q201 Q344 Q206 Q211 Q203 Q204): Q343 = 0
//!   to the depth Q201; Q343 = 1 to the countersink diameter Q344 (its
//!   sign the working direction, as Q201), depth (|Q344| / 2) /
//!   tan(T-ANGLE / 2) [T640C]; refused without a point angle. Feed Q206,
//!   dwell Q211, rapid out [T640C].
//! * **241 SINGLE-LIP DEEP-HOLE DRILLING** (Q200 Q201 Q206 Q211 Q203 Q204
//!   Q379 Q253 Q208 Q426 Q427 [Q428 Q429 Q430 Q435 Q401 Q202 Q212 Q205]):
//!   spindle Q426 (3, 4; 5 stationary) at Q427 for entering [T640C], with
//!   Q379 > 0 at Q253 to Q200 above the deepened starting point, drilling
//!   speed Q428 in the direction in force (*kernel*: the direction of
//!   drilling), coolant M Q429 (0: none), feed Q206 to depth, dwell Q211,
//!   coolant M Q430 (0: none), Q426 at Q427 again, retract at Q208 (0:
//!   Q206) to the set-up clearance, rapid out [T640C for the sequence]. The
//!   spindle is left as Q426 / Q427 set it (*UNVERIFIED*). A dwell depth
//!   Q435 ≠ 0 and pecking with Q202 (above 0, below the depth) are refused:
//!   how the TNC carries them out was not found. Q401, Q212, Q205 are then
//!   without effect.
//!
//! # Patterns (`PATTERN DEF`, [T640C])
//!
//! Items in the order written, each a kind (`POS`, `ROW`, `PAT`, `FRAME`,
//! `CIRC`, `PITCHCIRC`, the item number dropped) and its words. `X`, `Y`
//! are the first and second axis of the working plane, `Z` the surface
//! coordinate, which the TNC adds to Q203 of the cycle [T640C]. Points
//! come out as `[first, second, surface]`, not indexed by axis. Angles in
//! degrees, counterclockwise from the first axis. Counts are whole numbers
//! ≥ 1; at most [`MAX_POINTS`] points in all.
//!
//! * `POS (X Y [Z])`: one point.
//! * `ROW (X Y D NUM [ROT Z])`: NUM points from (X, Y), D apart, along
//!   ROT.
//! * `PAT (X Y DX DY NUMX NUMY [ROT ROTX ROTY Z])`: NUMY rows of NUMX
//!   points; columns DX apart along ROT + ROTX, rows DY apart along ROT +
//!   90° + ROTY (*UNVERIFIED* reading of ROTX / ROTY as separate turns of
//!   the two directions). Order a meander: the first row forward, the
//!   second backward … (*UNVERIFIED*: the order of cycle 221).
//! * `FRAME (…as PAT)`: only the points on the border of the PAT grid,
//!   round it: the first row forward, up the last column, the last row
//!   backward, down the first column (*kernel* order).
//! * `CIRC (X Y D [START] NUM [Z])`: NUM points on the full circle of
//!   diameter D about (X, Y), the first at START, 360° / NUM apart.
//! * `PITCHCIRC (X Y D [START] STEP NUM [Z])`: as CIRC, STEP apart (its
//!   sign the direction).
//!
//! # Errors
//!
//! [`CycleError`] with the Q number at fault (None for the context and
//! patterns) and a message. On an error `out` is left as it was. Nothing
//! panics; NaN or infinite inputs are refused.

// The front end does not call the module yet.
#![allow(dead_code)]

/// A feed of this value or more is rapid traverse (FMAX); the value a
/// `Q208=MAX` / `FMAX` entry is passed as.
pub(crate) const FMAX: f64 = 99_999.999;
/// Feeds from this value on are read as FMAX.
const FMAX_FROM: f64 = 99_999.0;
/// The value a feed entered as `FAUTO` is passed as: the feed in force.
pub(crate) const FAUTO: f64 = -1.0;
/// Most pecks, helix turns or chip breaks of one cycle call.
pub(crate) const MAX_PIECES: usize = 10_000;
/// Most points of one `PATTERN DEF`.
pub(crate) const MAX_POINTS: usize = 10_000;
/// The distance cycle 202 moves the tool off the wall, mm [T640C].
const BORING_LIFT: f64 = 0.2;
/// Lengths closer than this are equal (a peck reaching the depth, a hole
/// of the tool's diameter).
const EPS: f64 = 1e-9;

/// The elementary steps of a cycle, in programmed coordinates, absolute,
/// mm; coordinates indexed by axis (0 X, 1 Y, 2 Z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Step {
    /// Rapid traverse to the given coordinates (None: the axis stays).
    Rapid([Option<f64>; 3]),
    /// Straight feed move at `feed` mm/min (this step only).
    Feed {
        /// End point (None: the axis stays).
        to: [Option<f64>; 3],
        /// Feed, mm/min.
        feed: f64,
    },
    /// A helix (or, with `end` at the start's applicate, a circle) from
    /// where the tool stands about `center` in the working plane: the
    /// radius is the tool's distance from the centre; `sweep` degrees,
    /// positive counterclockwise (from the plane's first axis towards its
    /// second), down or up to the applicate coordinate `end` in
    /// proportion to the angle.
    Helix {
        /// Centre (first, second axis of the plane).
        center: [f64; 2],
        /// Angle swept, degrees; + counterclockwise.
        sweep: f64,
        /// Applicate coordinate at the end.
        end: f64,
        /// Feed, mm/min.
        feed: f64,
    },
    /// Dwell, seconds.
    Dwell(f64),
    /// An M function: M3 / M4 spindle on, M5 stop, coolant (241's Q429 /
    /// Q430).
    M(u16),
    /// Oriented spindle stop (M19) at the angle, degrees.
    Orient(f64),
    /// Spindle speed, rev/min.
    Speed(f64),
}

/// What a cycle needs to know of the controller's state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Context {
    /// Indices of the working plane's first axis, second axis and
    /// applicate (tool axis Z: `[0, 1, 2]`, Y: `[2, 0, 1]`, X:
    /// `[1, 2, 0]`); a permutation of 0, 1, 2.
    pub plane: [usize; 3],
    /// Programmed X Y Z now, mm.
    pub position: [f64; 3],
    /// The feed in force, mm/min (for [`FAUTO`]).
    pub feed: f64,
    /// The spindle speed in force, rev/min.
    pub spindle: f64,
    /// The spindle turns counterclockwise (M4).
    pub spindle_ccw: bool,
    /// The tool radius, mm (208, Q395).
    pub tool_radius: f64,
    /// The tool's point angle (T-ANGLE), degrees, if known (240 with
    /// Q343 = 1, Q395 = 1).
    pub point_angle: Option<f64>,
}

/// A cycle call or pattern refused.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct CycleError {
    /// The Q parameter at fault, if one is.
    pub param: Option<u32>,
    /// What is wrong, in words.
    pub message: String,
}

/// One item of `PATTERN DEF`: its kind (`POS`, `ROW`, `PAT`, `FRAME`,
/// `CIRC`, `PITCHCIRC`) and its words (`X`, `NUMX`, `START` … with their
/// values, absolute).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct PatternItem {
    /// The kind, without the item's number.
    pub kind: String,
    /// (address, value) in the order written.
    pub words: Vec<(String, f64)>,
}

/// The machining cycles this module carries out.
pub(crate) fn is_machining_cycle(number: u32) -> bool {
    cycle_name(number).is_some()
}

/// The cycle's name as the TNC writes it.
fn cycle_name(number: u32) -> Option<&'static str> {
    Some(match number {
        200 => "DRILLING",
        201 => "REAMING",
        202 => "BORING",
        203 => "UNIVERSAL DRILLING",
        204 => "BACK BORING",
        205 => "UNIVERSAL PECKING",
        207 => "RIGID TAPPING NEW",
        208 => "BORE MILLING",
        209 => "TAPPING W/ CHIP BRKG",
        240 => "CENTERING",
        241 => "SINGLE-LIP D.H.DRLNG",
        _ => return None,
    })
}

/// What a Q parameter is, for messages.
fn q_name(q: u32) -> &'static str {
    match q {
        200 => "set-up clearance",
        201 => "depth",
        202 => "plunging depth",
        203 => "surface coordinate",
        204 => "2nd set-up clearance",
        205 => "minimum plunging depth",
        206 => "feed rate for plunging",
        208 => "retraction feed rate",
        210 => "dwell time at top",
        211 => "dwell time at depth",
        212 => "decrement",
        213 => "number of breaks",
        214 => "disengaging direction",
        239 => "thread pitch",
        249 => "depth of counterbore",
        250 => "material thickness",
        251 => "off-center distance",
        252 => "tool edge height",
        253 => "feed rate for pre-positioning",
        254 => "feed rate for counterboring",
        255 => "dwell time",
        256 => "distance for chip breaking",
        257 => "depth for chip breaking",
        258 => "upper advanced stop distance",
        259 => "lower advanced stop distance",
        334 => "infeed per helix",
        335 => "nominal diameter",
        336 => "angle for spindle orientation",
        342 => "roughing diameter",
        343 => "select diameter/depth",
        344 => "countersink diameter",
        351 => "climb or up-cut",
        379 => "starting point",
        395 => "depth reference",
        401 => "feed rate factor",
        403 => "RPM factor",
        426 => "direction of spindle rotation",
        427 => "entry/exit speed",
        428 => "drilling speed",
        429 => "coolant on",
        430 => "coolant off",
        435 => "dwell depth",
        _ => "parameter",
    }
}

/// Required (`R`) and optional (`O`) parameters of each cycle.
#[derive(Clone, Copy)]
enum Need {
    R(u32),
    O(u32),
}
use Need::{O, R};

fn parameters(number: u32) -> &'static [Need] {
    match number {
        200 => &[
            R(200),
            R(201),
            R(206),
            R(202),
            R(210),
            R(203),
            R(204),
            O(211),
            O(395),
        ],
        201 => &[R(200), R(201), R(206), R(211), R(208), R(203), R(204)],
        202 => &[
            R(200),
            R(201),
            R(206),
            R(211),
            R(208),
            R(203),
            R(204),
            R(214),
            O(336),
        ],
        203 => &[
            R(200),
            R(201),
            R(206),
            R(202),
            R(210),
            R(203),
            R(204),
            R(212),
            R(213),
            R(205),
            R(211),
            R(208),
            R(256),
            O(395),
        ],
        204 => &[
            R(200),
            R(249),
            R(250),
            R(251),
            R(252),
            R(253),
            R(254),
            R(255),
            R(203),
            R(204),
            R(214),
            O(336),
        ],
        205 => &[
            R(200),
            R(201),
            R(206),
            R(202),
            R(203),
            R(204),
            R(212),
            R(205),
            R(258),
            R(259),
            R(257),
            R(256),
            R(211),
            O(379),
            O(253),
            O(208),
            O(395),
        ],
        207 => &[R(200), R(201), R(239), R(203), R(204), O(336)],
        208 => &[
            R(200),
            R(201),
            R(206),
            R(334),
            R(203),
            R(204),
            R(335),
            O(342),
            O(351),
        ],
        209 => &[
            R(200),
            R(201),
            R(239),
            R(203),
            R(204),
            R(257),
            R(256),
            R(336),
            O(403),
        ],
        // Q201 / Q344 are required by Q343's choice.
        240 => &[
            R(200),
            R(343),
            O(201),
            O(344),
            R(206),
            R(211),
            R(203),
            R(204),
        ],
        241 => &[
            R(200),
            R(201),
            R(206),
            R(211),
            R(203),
            R(204),
            R(379),
            R(253),
            R(208),
            R(426),
            R(427),
            R(428),
            O(429),
            O(430),
            O(435),
            O(401),
            O(202),
            O(212),
            O(205),
        ],
        _ => &[],
    }
}

/// A feed: rapid traverse or mm/min.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Rate {
    Rapid,
    At(f64),
}

/// The parameters of one call, checked.
struct Params<'a> {
    number: u32,
    name: &'static str,
    values: &'a [(u32, f64)],
}

impl<'a> Params<'a> {
    fn new(number: u32, values: &'a [(u32, f64)]) -> Result<Self, CycleError> {
        let Some(name) = cycle_name(number) else {
            return Err(CycleError {
                param: None,
                message: format!("cycle {number} is not a machining cycle the kernel carries out"),
            });
        };
        let p = Params {
            number,
            name,
            values,
        };
        let list = parameters(number);
        for (i, &(q, v)) in values.iter().enumerate() {
            if !list.iter().any(|n| matches!(n, R(x) | O(x) if *x == q)) {
                return Err(p.error(q, "is not a parameter of this cycle"));
            }
            if values[..i].iter().any(|(x, _)| *x == q) {
                return Err(p.error(q, "is written twice"));
            }
            if !v.is_finite() {
                return Err(p.error(q, "is not a finite number"));
            }
        }
        for n in list {
            if let R(q) = *n {
                if p.get(q).is_none() {
                    return Err(p.error(q, "is missing"));
                }
            }
        }
        Ok(p)
    }

    fn error(&self, q: u32, what: &str) -> CycleError {
        CycleError {
            param: Some(q),
            message: format!(
                "cycle {} {}: Q{q} ({}) {what}",
                self.number,
                self.name,
                q_name(q)
            ),
        }
    }

    fn get(&self, q: u32) -> Option<f64> {
        self.values.iter().find(|(x, _)| *x == q).map(|(_, v)| *v)
    }

    fn req(&self, q: u32) -> Result<f64, CycleError> {
        self.get(q).ok_or_else(|| self.error(q, "is missing"))
    }

    fn or(&self, q: u32, default: f64) -> f64 {
        self.get(q).unwrap_or(default)
    }

    /// A value ≥ 0 (0 when omitted and optional).
    fn not_negative(&self, q: u32) -> Result<f64, CycleError> {
        let v = self.or(q, 0.0);
        if v < 0.0 {
            return Err(self.error(q, "must not be negative"));
        }
        Ok(v)
    }

    /// A value > 0.
    fn positive(&self, q: u32) -> Result<f64, CycleError> {
        let v = self.req(q)?;
        if v <= 0.0 {
            return Err(self.error(q, "must be greater than 0"));
        }
        Ok(v)
    }

    /// A dwell, seconds (0 when omitted).
    fn dwell(&self, q: u32) -> Result<f64, CycleError> {
        let t = self.or(q, 0.0);
        if t < 0.0 {
            return Err(self.error(q, "(a dwell) must not be negative"));
        }
        Ok(t)
    }

    /// A whole number.
    fn whole(&self, q: u32, default: f64) -> Result<f64, CycleError> {
        let v = self.or(q, default);
        if v.fract() != 0.0 {
            return Err(self.error(q, "must be a whole number"));
        }
        Ok(v)
    }

    /// A feed (FMAX, FAUTO or above 0).
    fn feed(&self, q: u32, ctx: &Context) -> Result<Rate, CycleError> {
        let f = self.req(q)?;
        self.rate(q, f, ctx)
    }

    fn rate(&self, q: u32, f: f64, ctx: &Context) -> Result<Rate, CycleError> {
        if f >= FMAX_FROM {
            Ok(Rate::Rapid)
        } else if f == FAUTO {
            if ctx.feed > 0.0 && ctx.feed.is_finite() {
                Ok(Rate::At(ctx.feed))
            } else {
                Err(self.error(q, "is FAUTO but no feed is in force"))
            }
        } else if f > 0.0 {
            Ok(Rate::At(f))
        } else {
            Err(self.error(q, "(a feed) must be greater than 0, FMAX or FAUTO"))
        }
    }

    /// A feed that must not be rapid (cutting).
    fn cutting(&self, q: u32, ctx: &Context) -> Result<f64, CycleError> {
        match self.feed(q, ctx)? {
            Rate::At(f) => Ok(f),
            Rate::Rapid => Err(self.error(q, "must be a feed, not FMAX")),
        }
    }

    /// A retraction feed: 0 is `plunge`; omitted is `omitted`.
    fn retract(
        &self,
        q: u32,
        plunge: f64,
        omitted: Rate,
        ctx: &Context,
    ) -> Result<Rate, CycleError> {
        match self.get(q) {
            None => Ok(omitted),
            Some(f) if f == 0.0 => Ok(Rate::At(plunge)),
            Some(f) => self.rate(q, f, ctx),
        }
    }

    /// An M function number (0: none).
    fn m(&self, q: u32) -> Result<Option<u16>, CycleError> {
        let v = self.whole(q, 0.0)?;
        if !(0.0..=999.0).contains(&v) {
            return Err(self.error(q, "must be an M function number 0 … 999"));
        }
        Ok((v > 0.0).then_some(v as u16))
    }
}

/// The levels on the applicate.
#[derive(Clone, Copy, Debug)]
struct Levels {
    surface: f64,
    /// Q200, unsigned.
    clearance: f64,
    /// Q203 + Q200.
    safe: f64,
    /// Q203 + max(Q200, Q204).
    top: f64,
    /// The depth the tool tip goes to.
    bottom: f64,
}

/// Reads Q203, Q200, Q204 and the (negative) `depth` read from `depth_q`;
/// None when the depth is 0 (the cycle is not run).
fn levels(p: &Params<'_>, depth_q: u32, depth: f64) -> Result<Option<Levels>, CycleError> {
    if depth > 0.0 {
        return Err(p.error(
            depth_q,
            "must be negative: its sign gives the working direction, and a positive depth is refused",
        ));
    }
    let surface = p.req(203)?;
    let clearance = p.req(200)?.abs();
    let second = p.req(204)?;
    if second < 0.0 {
        return Err(p.error(204, "must not be negative"));
    }
    if depth == 0.0 {
        return Ok(None);
    }
    Ok(Some(Levels {
        surface,
        clearance,
        safe: surface + clearance,
        top: surface + clearance.max(second),
        bottom: surface + depth,
    }))
}

/// How much deeper the tip goes for Q395 = 1.
fn depth_reference(p: &Params<'_>, ctx: &Context) -> Result<f64, CycleError> {
    match p.whole(395, 0.0)? {
        0.0 => Ok(0.0),
        1.0 => {
            let Some(angle) = ctx.point_angle.filter(|a| *a > 0.0 && *a < 180.0) else {
                return Err(p.error(
                    395,
                    "= 1 (depth of the cylindrical part) needs the tool's point angle, which is not known",
                ));
            };
            if ctx.tool_radius <= 0.0 {
                return Err(p.error(395, "= 1 needs a tool radius above 0"));
            }
            Ok(ctx.tool_radius / (angle / 2.0).to_radians().tan())
        }
        _ => Err(p.error(395, "must be 0 (tool tip) or 1 (cylindrical part)")),
    }
}

/// The depths the pecks reach, from `start` down to `bottom`: the first
/// peck `first`, each next one less `decrement` but not less than
/// `minimum`.
fn pecks(
    p: &Params<'_>,
    start: f64,
    bottom: f64,
    first: f64,
    decrement: f64,
    minimum: f64,
) -> Result<Vec<f64>, CycleError> {
    let mut out = Vec::new();
    let mut reached = start;
    let mut peck = first;
    loop {
        let mut next = reached - peck;
        if next <= bottom + EPS {
            next = bottom;
        }
        out.push(next);
        if next == bottom {
            return Ok(out);
        }
        if out.len() >= MAX_PIECES {
            return Err(p.error(202, &format!("gives more than {MAX_PIECES} pecks")));
        }
        reached = next;
        if decrement > 0.0 {
            peck = (peck - decrement).max(minimum);
            if peck <= EPS {
                return Err(p.error(
                    205,
                    "is 0 while the decrement Q212 brings the plunging depth to 0",
                ));
            }
        }
    }
}

/// Writes steps for one cycle.
struct Out<'o> {
    out: &'o mut Vec<Step>,
    plane: [usize; 3],
}

impl Out<'_> {
    fn axis(&self, v: f64) -> [Option<f64>; 3] {
        let mut to = [None; 3];
        to[self.plane[2]] = Some(v);
        to
    }
    fn flat(&self, p: [f64; 2]) -> [Option<f64>; 3] {
        let mut to = [None; 3];
        to[self.plane[0]] = Some(p[0]);
        to[self.plane[1]] = Some(p[1]);
        to
    }
    fn rapid(&mut self, v: f64) {
        let to = self.axis(v);
        self.out.push(Step::Rapid(to));
    }
    fn feed(&mut self, v: f64, feed: f64) {
        let to = self.axis(v);
        self.out.push(Step::Feed { to, feed });
    }
    fn go(&mut self, v: f64, rate: Rate) {
        match rate {
            Rate::Rapid => self.rapid(v),
            Rate::At(f) => self.feed(v, f),
        }
    }
    fn go_flat(&mut self, p: [f64; 2], rate: Rate) {
        let to = self.flat(p);
        self.out.push(match rate {
            Rate::Rapid => Step::Rapid(to),
            Rate::At(feed) => Step::Feed { to, feed },
        });
    }
    fn dwell(&mut self, t: f64) {
        if t > 0.0 {
            self.out.push(Step::Dwell(t));
        }
    }
    fn m(&mut self, m: u16) {
        self.out.push(Step::M(m));
    }
    fn push(&mut self, s: Step) {
        self.out.push(s);
    }
}

/// M3 / M4 as in force.
fn in_force(ctx: &Context) -> u16 {
    if ctx.spindle_ccw { 4 } else { 3 }
}

/// The steps of machining cycle `number` with `params` at the tool's
/// position in the working plane, appended to `out`. On an error `out` is
/// left as it was.
pub(crate) fn cycle(
    number: u32,
    params: &[(u32, f64)],
    ctx: &Context,
    out: &mut Vec<Step>,
) -> Result<(), CycleError> {
    let start = out.len();
    let result = run(number, params, ctx, out);
    if result.is_err() {
        out.truncate(start);
    }
    result
}

fn context_error(what: &str) -> CycleError {
    CycleError {
        param: None,
        message: format!("cycle context: {what}"),
    }
}

fn check_context(ctx: &Context) -> Result<(), CycleError> {
    let mut seen = [false; 3];
    for &i in &ctx.plane {
        if i > 2 || seen[i] {
            return Err(context_error(
                "the plane's axes are not a permutation of 0, 1, 2",
            ));
        }
        seen[i] = true;
    }
    let finite = ctx.position.iter().all(|v| v.is_finite())
        && ctx.feed.is_finite()
        && ctx.spindle.is_finite()
        && ctx.tool_radius.is_finite()
        && ctx.point_angle.is_none_or(f64::is_finite);
    if !finite {
        return Err(context_error("a value is not a finite number"));
    }
    if ctx.tool_radius < 0.0 {
        return Err(context_error("the tool radius is negative"));
    }
    Ok(())
}

fn run(
    number: u32,
    params: &[(u32, f64)],
    ctx: &Context,
    out: &mut Vec<Step>,
) -> Result<(), CycleError> {
    let p = Params::new(number, params)?;
    check_context(ctx)?;
    let mut o = Out {
        out,
        plane: ctx.plane,
    };
    match number {
        200 => drilling(&p, ctx, &mut o),
        201 => reaming(&p, ctx, &mut o),
        202 => boring(&p, ctx, &mut o),
        203 => universal_drilling(&p, ctx, &mut o),
        204 => back_boring(&p, ctx, &mut o),
        205 => universal_pecking(&p, ctx, &mut o),
        207 | 209 => tapping(&p, ctx, &mut o),
        208 => bore_milling(&p, ctx, &mut o),
        240 => centering(&p, ctx, &mut o),
        _ => single_lip(&p, ctx, &mut o),
    }
}

/// Levels with Q201 as the depth, Q395 applied when `reference`.
fn depth_levels(
    p: &Params<'_>,
    ctx: &Context,
    reference: bool,
) -> Result<Option<Levels>, CycleError> {
    let depth = p.req(201)?;
    let Some(mut lv) = levels(p, 201, depth)? else {
        return Ok(None);
    };
    if reference {
        lv.bottom -= depth_reference(p, ctx)?;
    }
    Ok(Some(lv))
}

/// 200 DRILLING.
fn drilling(p: &Params<'_>, ctx: &Context, o: &mut Out<'_>) -> Result<(), CycleError> {
    let Some(lv) = depth_levels(p, ctx, true)? else {
        return Ok(());
    };
    let feed = p.cutting(206, ctx)?;
    let peck = p.positive(202)?;
    let top_dwell = p.dwell(210)?;
    let bottom_dwell = p.dwell(211)?;
    let depths = pecks(p, lv.surface, lv.bottom, peck, 0.0, 0.0)?;
    o.rapid(lv.safe);
    for (i, &d) in depths.iter().enumerate() {
        o.feed(d, feed);
        if i + 1 < depths.len() {
            o.rapid(lv.safe);
            o.dwell(top_dwell);
            o.rapid(d + lv.clearance);
        }
    }
    o.dwell(bottom_dwell);
    o.rapid(lv.top);
    Ok(())
}

/// 201 REAMING.
fn reaming(p: &Params<'_>, ctx: &Context, o: &mut Out<'_>) -> Result<(), CycleError> {
    let Some(lv) = depth_levels(p, ctx, false)? else {
        return Ok(());
    };
    let feed = p.cutting(206, ctx)?;
    let dwell = p.dwell(211)?;
    let back = p.retract(208, feed, Rate::At(feed), ctx)?;
    o.rapid(lv.safe);
    o.feed(lv.bottom, feed);
    o.dwell(dwell);
    o.go(lv.safe, back);
    o.rapid(lv.top);
    Ok(())
}

/// The unit vector of disengaging direction Q214 (1 … 4) in the plane.
fn disengage(p: &Params<'_>, allow_none: bool) -> Result<Option<[f64; 2]>, CycleError> {
    match p.whole(214, 0.0)? {
        0.0 if allow_none => Ok(None),
        1.0 => Ok(Some([-1.0, 0.0])),
        2.0 => Ok(Some([0.0, -1.0])),
        3.0 => Ok(Some([1.0, 0.0])),
        4.0 => Ok(Some([0.0, 1.0])),
        _ => Err(p.error(
            214,
            if allow_none {
                "must be 0 … 4"
            } else {
                "must be 1 … 4 (the tool must leave the wall)"
            },
        )),
    }
}

/// The hole centre: where the tool stands in the plane.
fn centre(ctx: &Context) -> [f64; 2] {
    [ctx.position[ctx.plane[0]], ctx.position[ctx.plane[1]]]
}

/// 202 BORING.
fn boring(p: &Params<'_>, ctx: &Context, o: &mut Out<'_>) -> Result<(), CycleError> {
    let Some(lv) = depth_levels(p, ctx, false)? else {
        return Ok(());
    };
    let feed = p.cutting(206, ctx)?;
    let dwell = p.dwell(211)?;
    let back = p.retract(208, feed, Rate::At(feed), ctx)?;
    let lift = disengage(p, true)?;
    let angle = p.or(336, 0.0);
    let c = centre(ctx);
    o.rapid(lv.safe);
    o.feed(lv.bottom, feed);
    o.dwell(dwell);
    o.push(Step::Orient(angle));
    if let Some(d) = lift {
        o.go_flat(
            [c[0] + BORING_LIFT * d[0], c[1] + BORING_LIFT * d[1]],
            Rate::Rapid,
        );
    }
    o.go(lv.safe, back);
    if lift.is_some() {
        o.go_flat(c, Rate::Rapid);
    }
    o.rapid(lv.top);
    o.m(in_force(ctx));
    Ok(())
}

/// 203 UNIVERSAL DRILLING.
fn universal_drilling(p: &Params<'_>, ctx: &Context, o: &mut Out<'_>) -> Result<(), CycleError> {
    let Some(lv) = depth_levels(p, ctx, true)? else {
        return Ok(());
    };
    let feed = p.cutting(206, ctx)?;
    let peck = p.positive(202)?;
    let top_dwell = p.dwell(210)?;
    let decrement = p.not_negative(212)?;
    let breaks = p.whole(213, 0.0)?;
    if breaks < 0.0 {
        return Err(p.error(213, "must not be negative"));
    }
    let minimum = p.not_negative(205)?;
    let bottom_dwell = p.dwell(211)?;
    let back = p.retract(208, feed, Rate::At(feed), ctx)?;
    let lift = p.not_negative(256)?;
    if breaks > 0.0 && lift <= 0.0 {
        return Err(p.error(256, "must be greater than 0 when Q213 asks for chip breaks"));
    }
    let depths = pecks(p, lv.surface, lv.bottom, peck, decrement, minimum)?;
    o.rapid(lv.safe);
    let mut made = 0.0;
    for (i, &d) in depths.iter().enumerate() {
        o.feed(d, feed);
        if i + 1 == depths.len() {
            break;
        }
        if made < breaks {
            made += 1.0;
            o.rapid(d + lift);
        } else {
            made = 0.0;
            o.go(lv.safe, back);
            o.dwell(top_dwell);
            o.rapid(d + lv.clearance);
        }
    }
    o.dwell(bottom_dwell);
    o.go(lv.safe, back);
    o.rapid(lv.top);
    Ok(())
}

/// 204 BACK BORING.
fn back_boring(p: &Params<'_>, ctx: &Context, o: &mut Out<'_>) -> Result<(), CycleError> {
    let counterbore = p.req(249)?;
    let thickness = p.positive(250)?;
    let Some(lv) = levels(p, 249, if counterbore == 0.0 { 0.0 } else { -1.0 })? else {
        return Ok(());
    };
    if counterbore < 0.0 {
        return Err(p.error(
            249,
            "must be positive (the counterbore is cut upwards from the underside)",
        ));
    }
    if counterbore > thickness {
        return Err(p.error(249, "is greater than the material thickness Q250"));
    }
    let offset = p.positive(251)?;
    let edge = p.not_negative(252)?;
    let pre = p.feed(253, ctx)?;
    let cut = p.cutting(254, ctx)?;
    let dwell = p.dwell(255)?;
    let Some(dir) = disengage(p, false)? else {
        return Err(p.error(214, "must be 1 … 4"));
    };
    let angle = p.or(336, 0.0);
    let c = centre(ctx);
    let off = [c[0] + offset * dir[0], c[1] + offset * dir[1]];
    let underside = lv.surface - thickness;
    o.rapid(lv.safe);
    o.push(Step::Orient(angle));
    o.go_flat(off, Rate::Rapid);
    o.go(underside - lv.clearance - edge, pre);
    o.go_flat(c, pre);
    o.m(in_force(ctx));
    o.feed(underside + counterbore - edge, cut);
    o.dwell(dwell);
    o.push(Step::Orient(angle));
    o.go_flat(off, pre);
    o.go(lv.safe, pre);
    o.rapid(lv.top);
    o.go_flat(c, Rate::Rapid);
    o.m(in_force(ctx));
    Ok(())
}

/// 205 UNIVERSAL PECKING.
fn universal_pecking(p: &Params<'_>, ctx: &Context, o: &mut Out<'_>) -> Result<(), CycleError> {
    let Some(lv) = depth_levels(p, ctx, true)? else {
        return Ok(());
    };
    let feed = p.cutting(206, ctx)?;
    let peck = p.positive(202)?;
    let decrement = p.not_negative(212)?;
    let minimum = p.not_negative(205)?;
    let upper = p.not_negative(258)?;
    let lower = p.not_negative(259)?;
    let break_depth = p.not_negative(257)?;
    let lift = p.not_negative(256)?;
    if break_depth > 0.0 && lift <= 0.0 {
        return Err(p.error(
            256,
            "must be greater than 0 when Q257 asks for chip breaking",
        ));
    }
    let bottom_dwell = p.dwell(211)?;
    let deepened = p.not_negative(379)?;
    let back = p.retract(208, feed, Rate::Rapid, ctx)?;
    let start = lv.surface - deepened;
    if deepened > 0.0 && start <= lv.bottom + EPS {
        return Err(p.error(379, "is not above the depth"));
    }
    let depths = pecks(p, start, lv.bottom, peck, decrement, minimum)?;
    if break_depth > 0.0 && (start - lv.bottom) / break_depth > MAX_PIECES as f64 {
        return Err(p.error(257, &format!("gives more than {MAX_PIECES} chip breaks")));
    }
    o.rapid(lv.safe);
    if deepened > 0.0 {
        let pre = match p.get(253) {
            Some(f) => p.rate(253, f, ctx)?,
            None => {
                return Err(p.error(
                    253,
                    "is missing (needed with a deepened starting point Q379)",
                ));
            }
        };
        o.go(start + lv.clearance, pre);
    }
    let mut reached = start;
    let last = depths.len() - 1;
    for (i, &d) in depths.iter().enumerate() {
        if break_depth > 0.0 {
            let mut at = reached - break_depth;
            while at > d + EPS {
                o.feed(at, feed);
                o.rapid(at + lift);
                at -= break_depth;
            }
        }
        o.feed(d, feed);
        reached = d;
        if i == last {
            break;
        }
        // Re-approach i + 1 of `last`: Q258 first, Q259 last.
        let stop = if last > 1 {
            upper + (lower - upper) * i as f64 / (last - 1) as f64
        } else {
            upper
        };
        o.go(lv.safe, back);
        o.rapid(d + stop);
    }
    o.dwell(bottom_dwell);
    o.go(lv.safe, back);
    o.rapid(lv.top);
    Ok(())
}

/// 207 RIGID TAPPING NEW and 209 TAPPING W/ CHIP BRKG.
fn tapping(p: &Params<'_>, ctx: &Context, o: &mut Out<'_>) -> Result<(), CycleError> {
    let Some(lv) = depth_levels(p, ctx, false)? else {
        return Ok(());
    };
    let pitch = p.req(239)?;
    if pitch == 0.0 {
        return Err(p.error(239, "must not be 0"));
    }
    if ctx.spindle <= 0.0 {
        return Err(CycleError {
            param: None,
            message: format!(
                "cycle {} {}: no spindle speed in force for the tapping feed",
                p.number, p.name
            ),
        });
    }
    let (into, out_of) = if pitch > 0.0 { (3, 4) } else { (4, 3) };
    let feed = pitch.abs() * ctx.spindle;
    let (break_depth, lift, factor) = if p.number == 209 {
        let factor = p.or(403, 1.0);
        if factor <= 0.0 {
            return Err(p.error(403, "must be greater than 0"));
        }
        (
            p.not_negative(257)?,
            p.not_negative(256)? * pitch.abs(),
            factor,
        )
    } else {
        (0.0, 0.0, 1.0)
    };
    if break_depth > 0.0 && (lv.surface - lv.bottom) / break_depth > MAX_PIECES as f64 {
        return Err(p.error(257, &format!("gives more than {MAX_PIECES} chip breaks")));
    }
    let back_feed = feed * factor;
    // Out of the hole (to `to`) at Q403 × the speed.
    let retract = |o: &mut Out<'_>, to: f64| {
        o.m(out_of);
        if factor != 1.0 {
            o.push(Step::Speed(ctx.spindle * factor));
        }
        o.feed(to, back_feed);
        if factor != 1.0 {
            o.push(Step::Speed(ctx.spindle));
        }
    };
    o.rapid(lv.safe);
    if let Some(angle) = p.get(336) {
        o.push(Step::Orient(angle));
    }
    o.m(into);
    if break_depth > 0.0 {
        let mut at = lv.surface - break_depth;
        while at > lv.bottom + EPS {
            o.feed(at, feed);
            retract(o, if lift > 0.0 { at + lift } else { lv.safe });
            o.m(into);
            at -= break_depth;
        }
    }
    o.feed(lv.bottom, feed);
    retract(o, lv.safe);
    o.m(5);
    o.rapid(lv.top);
    Ok(())
}

/// 208 BORE MILLING.
fn bore_milling(p: &Params<'_>, ctx: &Context, o: &mut Out<'_>) -> Result<(), CycleError> {
    let Some(lv) = depth_levels(p, ctx, false)? else {
        return Ok(());
    };
    let feed = p.cutting(206, ctx)?;
    let infeed = p.positive(334)?;
    let diameter = p.positive(335)?;
    let roughing = p.not_negative(342)?;
    let climb = match p.whole(351, 1.0)? {
        1.0 => true,
        -1.0 => false,
        _ => return Err(p.error(351, "must be +1 (climb) or -1 (up-cut)")),
    };
    let tool = 2.0 * ctx.tool_radius;
    if tool <= 0.0 {
        return Err(p.error(335, "cannot be milled: the tool radius is 0"));
    }
    if diameter < tool - EPS {
        return Err(p.error(335, "is smaller than the tool diameter"));
    }
    o.rapid(lv.safe);
    if diameter <= tool + EPS {
        o.feed(lv.bottom, feed);
        o.rapid(lv.top);
        return Ok(());
    }
    if roughing == 0.0 && diameter > 2.0 * tool + EPS {
        return Err(p.error(
            335,
            "is more than twice the tool diameter (give the roughing diameter Q342 to mill it)",
        ));
    }
    let turns = (lv.safe - lv.bottom) / infeed;
    if turns > MAX_PIECES as f64 {
        return Err(p.error(334, &format!("gives more than {MAX_PIECES} helix turns")));
    }
    let ccw = climb != ctx.spindle_ccw;
    let full = if ccw { 360.0 } else { -360.0 };
    let c = centre(ctx);
    let radius = diameter / 2.0 - ctx.tool_radius;
    o.go_flat([c[0] + radius, c[1]], Rate::At(feed));
    let whole = turns.floor();
    let mut z = lv.safe;
    for _ in 0..whole as usize {
        z -= infeed;
        o.push(Step::Helix {
            center: c,
            sweep: full,
            end: if z <= lv.bottom + EPS { lv.bottom } else { z },
            feed,
        });
    }
    let rest = turns - whole;
    if rest * infeed > EPS {
        o.push(Step::Helix {
            center: c,
            sweep: full * rest,
            end: lv.bottom,
            feed,
        });
    }
    o.push(Step::Helix {
        center: c,
        sweep: full,
        end: lv.bottom,
        feed,
    });
    o.go_flat(c, Rate::At(feed));
    o.rapid(lv.top);
    Ok(())
}

/// 240 CENTERING.
fn centering(p: &Params<'_>, ctx: &Context, o: &mut Out<'_>) -> Result<(), CycleError> {
    let (q, depth) = match p.whole(343, 0.0)? {
        0.0 => (201, p.req(201)?),
        1.0 => {
            let d = p.req(344)?;
            let Some(angle) = ctx.point_angle.filter(|a| *a > 0.0 && *a < 180.0) else {
                return Err(p.error(
                    343,
                    "= 1 (countersink diameter) needs the tool's point angle, which is not known",
                ));
            };
            // A positive diameter stays positive, for `levels` to refuse.
            let depth = if d > 0.0 {
                d
            } else {
                -(d.abs() / 2.0) / (angle / 2.0).to_radians().tan()
            };
            (344, depth)
        }
        _ => return Err(p.error(343, "must be 0 (depth) or 1 (diameter)")),
    };
    let Some(lv) = levels(p, q, depth)? else {
        return Ok(());
    };
    let feed = p.cutting(206, ctx)?;
    let dwell = p.dwell(211)?;
    o.rapid(lv.safe);
    o.feed(lv.bottom, feed);
    o.dwell(dwell);
    o.rapid(lv.top);
    Ok(())
}

/// 241 SINGLE-LIP DEEP-HOLE DRILLING.
fn single_lip(p: &Params<'_>, ctx: &Context, o: &mut Out<'_>) -> Result<(), CycleError> {
    let Some(lv) = depth_levels(p, ctx, false)? else {
        return Ok(());
    };
    let feed = p.cutting(206, ctx)?;
    let dwell = p.dwell(211)?;
    let deepened = p.not_negative(379)?;
    if deepened > 0.0 && lv.surface - deepened <= lv.bottom + EPS {
        return Err(p.error(379, "is not above the depth"));
    }
    let pre = p.feed(253, ctx)?;
    let back = p.retract(208, feed, Rate::At(feed), ctx)?;
    let entry = match p.whole(426, 0.0)? {
        3.0 => 3,
        4.0 => 4,
        5.0 => 5,
        _ => return Err(p.error(426, "must be 3, 4 or 5")),
    };
    let entry_speed = p.not_negative(427)?;
    if entry != 5 && entry_speed == 0.0 {
        return Err(p.error(427, "must be greater than 0 with a turning spindle"));
    }
    let speed = p.positive(428)?;
    let coolant_on = p.m(429)?;
    let coolant_off = p.m(430)?;
    if p.or(435, 0.0) != 0.0 {
        return Err(p.error(435, "(a dwell depth) is not carried out: leave it 0"));
    }
    let peck = p.or(202, 0.0);
    if peck < 0.0 || (peck > 0.0 && peck < lv.surface - deepened - lv.bottom - EPS) {
        return Err(p.error(202, "(pecking) is not carried out: leave it 0"));
    }
    let spindle_entry = |o: &mut Out<'_>| {
        if entry == 5 {
            o.m(5);
        } else {
            o.push(Step::Speed(entry_speed));
            o.m(entry);
        }
    };
    o.rapid(lv.safe);
    spindle_entry(o);
    if deepened > 0.0 {
        o.go(lv.surface - deepened + lv.clearance, pre);
    }
    o.push(Step::Speed(speed));
    o.m(in_force(ctx));
    if let Some(m) = coolant_on {
        o.m(m);
    }
    o.feed(lv.bottom, feed);
    o.dwell(dwell);
    if let Some(m) = coolant_off {
        o.m(m);
    }
    spindle_entry(o);
    o.go(lv.safe, back);
    o.rapid(lv.top);
    Ok(())
}

// ---------------------------------------------------------------------
// PATTERN DEF

/// The words of one pattern item, checked.
struct Words<'a> {
    kind: &'a str,
    words: &'a [(String, f64)],
}

impl<'a> Words<'a> {
    fn new(item: &'a PatternItem, known: &[&str], required: &[&str]) -> Result<Self, CycleError> {
        let w = Words {
            kind: &item.kind,
            words: &item.words,
        };
        for (i, (a, v)) in item.words.iter().enumerate() {
            if !known.contains(&a.as_str()) {
                return Err(w.error(a, "is not a word of this pattern"));
            }
            if item.words[..i].iter().any(|(b, _)| b == a) {
                return Err(w.error(a, "is written twice"));
            }
            if !v.is_finite() {
                return Err(w.error(a, "is not a finite number"));
            }
        }
        for r in required {
            if w.get(r).is_none() {
                return Err(w.error(r, "is missing"));
            }
        }
        Ok(w)
    }

    fn error(&self, word: &str, what: &str) -> CycleError {
        CycleError {
            param: None,
            message: format!("PATTERN DEF {}: {word} {what}", self.kind),
        }
    }

    fn get(&self, a: &str) -> Option<f64> {
        self.words.iter().find(|(b, _)| b == a).map(|(_, v)| *v)
    }

    fn or0(&self, a: &str) -> f64 {
        self.get(a).unwrap_or(0.0)
    }

    fn count(&self, a: &str) -> Result<usize, CycleError> {
        let n = self.or0(a);
        if n < 1.0 || n.fract() != 0.0 || n > MAX_POINTS as f64 {
            return Err(self.error(a, &format!("must be a whole number from 1 to {MAX_POINTS}")));
        }
        Ok(n as usize)
    }

    fn diameter(&self) -> Result<f64, CycleError> {
        let d = self.or0("D");
        if d <= 0.0 {
            return Err(self.error("D", "(the diameter) must be greater than 0"));
        }
        Ok(d)
    }
}

/// The unit vector at `deg` degrees.
fn direction(deg: f64) -> [f64; 2] {
    let (s, c) = deg.to_radians().sin_cos();
    [c, s]
}

/// The points of `PATTERN DEF` `items`, as `[first axis, second axis,
/// surface]`, appended to `out`. On an error `out` is left as it was.
pub(crate) fn pattern(items: &[PatternItem], out: &mut Vec<[f64; 3]>) -> Result<(), CycleError> {
    let mut points = Vec::new();
    for item in items {
        pattern_item(item, &mut points)?;
        if points.len() > MAX_POINTS {
            return Err(CycleError {
                param: None,
                message: format!("PATTERN DEF: more than {MAX_POINTS} points"),
            });
        }
    }
    out.extend(points);
    Ok(())
}

const GRID: [&str; 10] = [
    "X", "Y", "DX", "DY", "NUMX", "NUMY", "ROT", "ROTX", "ROTY", "Z",
];

fn pattern_item(item: &PatternItem, out: &mut Vec<[f64; 3]>) -> Result<(), CycleError> {
    match item.kind.to_ascii_uppercase().as_str() {
        "POS" => {
            let w = Words::new(item, &["X", "Y", "Z"], &["X", "Y"])?;
            out.push([w.or0("X"), w.or0("Y"), w.or0("Z")]);
        }
        "ROW" => {
            let w = Words::new(
                item,
                &["X", "Y", "D", "NUM", "ROT", "Z"],
                &["X", "Y", "D", "NUM"],
            )?;
            let n = w.count("NUM")?;
            let u = direction(w.or0("ROT"));
            let (x, y, d, z) = (w.or0("X"), w.or0("Y"), w.or0("D"), w.or0("Z"));
            for i in 0..n {
                let s = d * i as f64;
                out.push([x + s * u[0], y + s * u[1], z]);
            }
        }
        "PAT" | "FRAME" => {
            let w = Words::new(item, &GRID, &GRID[..6])?;
            let nx = w.count("NUMX")?;
            let ny = w.count("NUMY")?;
            if nx.saturating_mul(ny) > MAX_POINTS {
                return Err(w.error("NUMX", &format!("× NUMY is more than {MAX_POINTS} points")));
            }
            let rot = w.or0("ROT");
            let u = direction(rot + w.or0("ROTX"));
            let v = direction(rot + 90.0 + w.or0("ROTY"));
            let (x, y, dx, dy, z) = (w.or0("X"), w.or0("Y"), w.or0("DX"), w.or0("DY"), w.or0("Z"));
            let at = |i: usize, j: usize| {
                let (a, b) = (dx * i as f64, dy * j as f64);
                [x + a * u[0] + b * v[0], y + a * u[1] + b * v[1], z]
            };
            if item.kind.eq_ignore_ascii_case("PAT") {
                for j in 0..ny {
                    for k in 0..nx {
                        let i = if j % 2 == 0 { k } else { nx - 1 - k };
                        out.push(at(i, j));
                    }
                }
            } else {
                for i in 0..nx {
                    out.push(at(i, 0));
                }
                for j in 1..ny {
                    out.push(at(nx - 1, j));
                }
                if ny > 1 && nx > 1 {
                    for i in (0..nx - 1).rev() {
                        out.push(at(i, ny - 1));
                    }
                    for j in (1..ny - 1).rev() {
                        out.push(at(0, j));
                    }
                }
            }
        }
        "CIRC" | "PITCHCIRC" => {
            let pitch = item.kind.eq_ignore_ascii_case("PITCHCIRC");
            let w = if pitch {
                Words::new(
                    item,
                    &["X", "Y", "D", "START", "STEP", "NUM", "Z"],
                    &["X", "Y", "D", "STEP", "NUM"],
                )?
            } else {
                Words::new(
                    item,
                    &["X", "Y", "D", "START", "NUM", "Z"],
                    &["X", "Y", "D", "NUM"],
                )?
            };
            let r = w.diameter()? / 2.0;
            let n = w.count("NUM")?;
            let step = if pitch {
                w.or0("STEP")
            } else {
                360.0 / n as f64
            };
            let (x, y, start, z) = (w.or0("X"), w.or0("Y"), w.or0("START"), w.or0("Z"));
            for k in 0..n {
                let u = direction(start + step * k as f64);
                out.push([x + r * u[0], y + r * u[1], z]);
            }
        }
        _ => {
            return Err(CycleError {
                param: None,
                message: format!(
                    "PATTERN DEF: {} is not a pattern (POS, ROW, PAT, FRAME, CIRC, PITCHCIRC)",
                    item.kind
                ),
            });
        }
    }
    Ok(())
}
