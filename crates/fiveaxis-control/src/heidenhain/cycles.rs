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
//!   Machining Cycles" (cycle run, parameter descriptions). Its pages on
//!   these cycles could not be retrieved while this module was written:
//!   the items cited [T640C] are the author's reading of that manual, not
//!   checked against a copy, so take every one as *UNVERIFIED* until it
//!   is. Checked against retrieved pages (TNC 320 / TNC 426 / TNC 430 /
//!   TNC 410 user's manuals, chapter 8): the meanings of Q200, Q201
//!   (incremental, its sign the working direction, 0: the cycle is not
//!   run), Q203, Q204; Q202 going to depth in one move when it is at
//!   least the depth; Q239's sign (+ right, − left hand); Q351 (+1 climb,
//!   −1 up-cut, "with M03"); Q257 (0: no chip breaking), Q256, Q258 (the
//!   advanced stop distance when the tool goes back down to the depth
//!   reached).
//! * [BRIEF §9]: the design brief
//!   (`/work/shared/design/sinumerik-heidenhain-brief.md`, §9: `CYCL DEF`
//!   form, parameter lists of 200, 203, 207).
//! * [POST]: the parameter lists a Fusion HEIDENHAIN post
//!   (`mwinterm/fusion_post`, iTNC 530) and hyperMILL programs write for
//!   200, 201, 202, 203, 204, 205, 207, 208, 209, 241 (which parameters
//!   real programs carry; `Q208=MAX`, `Q253=MAX`; Q249 the counterbore
//!   distance and Q250 the material thickness of 204; Q435 "not fully
//!   specified" by the manual, says the post).
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
//!   but not above the set-up clearance, then feed on; *UNVERIFIED* that
//!   the break retract is rapid);
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
//!   the advanced stop distance above the depth reached (at most to the
//!   set-up clearance; so are the chip-break retracts): Q258 after the
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
//!   Q256 × |Q239| (Q256 = 0, or more than the way out: out to the set-up
//!   clearance), then forward
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
//!   Q379 Q253 Q208 Q426 Q427 Q428 [Q429 Q430 Q435 Q401 Q202 Q212 Q205]):
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
//! * `POS (X Y [Z])`: one point. `IX`, `IY`, `IZ` (the front end passes an
//!   incremental word with its `I`) are relative to the point before in the
//!   same `PATTERN DEF` (*UNVERIFIED* reference; the TNC manual's example
//!   writes `POS2 (X+15 IY+6.5 Z+0)`); refused on the first point.
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
            if let R(q) = *n
                && p.get(q).is_none()
            {
                return Err(p.error(q, "is missing"));
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
            Some(0.0) => Ok(Rate::At(plunge)),
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
            o.rapid((d + lift).min(lv.safe));
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
                o.rapid((at + lift).min(lv.safe));
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
        o.rapid((d + stop).min(lv.safe));
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
            retract(
                o,
                if lift > 0.0 {
                    (at + lift).min(lv.safe)
                } else {
                    lv.safe
                },
            );
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
            let w = Words::new(item, &["X", "Y", "Z", "IX", "IY", "IZ"], &[])?;
            let mut p = [0.0; 3];
            for (k, (abs, inc)) in [("X", "IX"), ("Y", "IY"), ("Z", "IZ")]
                .into_iter()
                .enumerate()
            {
                p[k] = match (w.get(abs), w.get(inc)) {
                    (Some(_), Some(_)) => {
                        return Err(w.error(inc, &format!("and {abs} are both written")));
                    }
                    (Some(v), None) => v,
                    (None, Some(v)) => match out.last() {
                        Some(last) => last[k] + v,
                        None => return Err(w.error(inc, "(incremental) has no point before it")),
                    },
                    (None, None) if k < 2 => return Err(w.error(abs, "is missing")),
                    (None, None) => 0.0,
                };
            }
            out.push(p);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Tool axis Z.
    const ZP: [usize; 3] = [0, 1, 2];
    /// Tool axis X (plane Y Z).
    const XP: [usize; 3] = [1, 2, 0];

    /// At X10 Y20 Z50, F100, S1000 M3, a 6 mm tool without a point angle.
    fn ctx() -> Context {
        Context {
            plane: ZP,
            position: [10.0, 20.0, 50.0],
            feed: 100.0,
            spindle: 1000.0,
            spindle_ccw: false,
            tool_radius: 3.0,
            point_angle: None,
        }
    }

    /// Parameters as in the `CYCL DEF` block: `"Q200=2 ~ Q201=-20"`.
    fn q(text: &str) -> Vec<(u32, f64)> {
        text.split(|c: char| c.is_whitespace() || c == '~')
            .filter(|w| !w.is_empty())
            .map(|w| {
                let (n, v) = w
                    .strip_prefix('Q')
                    .and_then(|w| w.split_once('='))
                    .expect("Qn=v");
                (n.parse().expect("a Q number"), v.parse().expect("a value"))
            })
            .collect()
    }

    fn run_in(number: u32, text: &str, c: &Context) -> Vec<Step> {
        let mut out = Vec::new();
        cycle(number, &q(text), c, &mut out).expect("the cycle runs");
        out
    }

    fn run(number: u32, text: &str) -> Vec<Step> {
        run_in(number, text, &ctx())
    }

    /// The error; `out` must be left as it was.
    fn fail_in(number: u32, text: &str, c: &Context) -> CycleError {
        let mut out = vec![Step::Dwell(9.0)];
        let e = cycle(number, &q(text), c, &mut out).expect_err("the cycle is refused");
        assert_eq!(out, vec![Step::Dwell(9.0)], "out changed on an error");
        e
    }

    fn fail(number: u32, text: &str) -> CycleError {
        fail_in(number, text, &ctx())
    }

    fn z(v: f64) -> Step {
        Step::Rapid([None, None, Some(v)])
    }
    fn fz(v: f64, feed: f64) -> Step {
        Step::Feed {
            to: [None, None, Some(v)],
            feed,
        }
    }
    fn xy(x: f64, y: f64) -> Step {
        Step::Rapid([Some(x), Some(y), None])
    }
    fn fxy(x: f64, y: f64, feed: f64) -> Step {
        Step::Feed {
            to: [Some(x), Some(y), None],
            feed,
        }
    }
    fn helix(sweep: f64, end: f64, feed: f64) -> Step {
        Step::Helix {
            center: [10.0, 20.0],
            sweep,
            end,
            feed,
        }
    }

    fn near(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }
    fn near_opt(a: [Option<f64>; 3], b: [Option<f64>; 3]) -> bool {
        a.iter().zip(b).all(|(a, b)| match (a, b) {
            (Some(a), Some(b)) => near(*a, b),
            (None, None) => true,
            _ => false,
        })
    }
    fn same(a: &Step, b: &Step) -> bool {
        match (a, b) {
            (Step::Rapid(a), Step::Rapid(b)) => near_opt(*a, *b),
            (Step::Feed { to: a, feed: f }, Step::Feed { to: b, feed: g }) => {
                near_opt(*a, *b) && near(*f, *g)
            }
            (
                Step::Helix {
                    center: c,
                    sweep: s,
                    end: e,
                    feed: f,
                },
                Step::Helix {
                    center: d,
                    sweep: t,
                    end: g,
                    feed: h,
                },
            ) => {
                near(c[0], d[0]) && near(c[1], d[1]) && near(*s, *t) && near(*e, *g) && near(*f, *h)
            }
            (Step::Dwell(a), Step::Dwell(b))
            | (Step::Orient(a), Step::Orient(b))
            | (Step::Speed(a), Step::Speed(b)) => near(*a, *b),
            (Step::M(a), Step::M(b)) => a == b,
            _ => false,
        }
    }

    #[track_caller]
    fn check(got: &[Step], want: &[Step]) {
        let ok = got.len() == want.len() && got.iter().zip(want).all(|(a, b)| same(a, b));
        assert!(ok, "\n got: {got:?}\nwant: {want:?}");
    }

    // ----- 200 DRILLING

    const C200: &str =
        "Q200=2 ~ Q201=-15 ~ Q206=150 ~ Q202=6 ~ Q210=1 ~ Q203=+0 ~ Q204=50 ~ Q211=0.5";

    #[test]
    fn drilling_pecks_back_to_clearance_and_down_to_clearance_above_the_depth() {
        // Pecks to -6, -12, then the rest to -15.
        check(
            &run(200, C200),
            &[
                z(2.0),
                fz(-6.0, 150.0),
                z(2.0),
                Step::Dwell(1.0),
                z(-4.0),
                fz(-12.0, 150.0),
                z(2.0),
                Step::Dwell(1.0),
                z(-10.0),
                fz(-15.0, 150.0),
                Step::Dwell(0.5),
                z(50.0),
            ],
        );
    }

    #[test]
    fn drilling_in_one_move_when_the_plunging_depth_reaches_the_depth() {
        let text = "Q200=2 Q201=-20 Q206=150 Q202=20 Q210=0 Q203=10 Q204=50";
        check(&run(200, text), &[z(12.0), fz(-10.0, 150.0), z(60.0)]);
        let text = "Q200=2 Q201=-20 Q206=150 Q202=25 Q210=3 Q203=10 Q204=50 Q211=0";
        check(&run(200, text), &[z(12.0), fz(-10.0, 150.0), z(60.0)]);
    }

    #[test]
    fn the_end_is_the_set_up_clearance_when_the_second_is_lower() {
        let text = "Q200=5 Q201=-10 Q206=150 Q202=10 Q210=0 Q203=0 Q204=2";
        check(&run(200, text), &[z(5.0), fz(-10.0, 150.0), z(5.0)]);
    }

    #[test]
    fn the_set_up_clearance_is_taken_without_its_sign() {
        let text = "Q200=-2 Q201=-10 Q206=150 Q202=10 Q210=0 Q203=0 Q204=0";
        check(&run(200, text), &[z(2.0), fz(-10.0, 150.0), z(2.0)]);
    }

    #[test]
    fn a_depth_of_zero_runs_nothing_and_a_positive_depth_is_refused() {
        let text = "Q200=2 Q201=0 Q206=150 Q202=5 Q210=0 Q203=0 Q204=50";
        assert!(run(200, text).is_empty());
        let e = fail(200, "Q200=2 Q201=+5 Q206=150 Q202=5 Q210=0 Q203=0 Q204=50");
        assert_eq!(e.param, Some(201));
        assert!(e.message.contains("negative"), "{}", e.message);
    }

    #[test]
    fn depth_reference_one_adds_the_point_length() {
        let text = "Q200=2 Q201=-10 Q206=150 Q202=20 Q210=0 Q203=0 Q204=50 Q395=1";
        let mut c = ctx();
        c.point_angle = Some(90.0);
        // R / tan(45°) = 3.
        check(&run_in(200, text, &c), &[z(2.0), fz(-13.0, 150.0), z(50.0)]);
        assert_eq!(fail(200, text).param, Some(395));
        let text = "Q200=2 Q201=-10 Q206=150 Q202=20 Q210=0 Q203=0 Q204=50 Q395=2";
        assert_eq!(fail_in(200, text, &c).param, Some(395));
    }

    #[test]
    fn feeds_fauto_fmax_and_zero() {
        // FAUTO: the feed in force.
        let text = "Q200=2 Q201=-10 Q206=-1 Q202=20 Q210=0 Q203=0 Q204=50";
        check(&run(200, text), &[z(2.0), fz(-10.0, 100.0), z(50.0)]);
        let text = "Q200=2 Q201=-10 Q206=0 Q202=20 Q210=0 Q203=0 Q204=50";
        assert_eq!(fail(200, text).param, Some(206));
        let text = "Q200=2 Q201=-10 Q206=99999.999 Q202=20 Q210=0 Q203=0 Q204=50";
        assert_eq!(fail(200, text).param, Some(206));
        let mut c = ctx();
        c.feed = 0.0;
        let text = "Q200=2 Q201=-10 Q206=-1 Q202=20 Q210=0 Q203=0 Q204=50";
        assert_eq!(fail_in(200, text, &c).param, Some(206));
    }

    #[test]
    fn drilling_refusals() {
        let base = "Q200=2 Q201=-10 Q206=150 Q203=0 Q204=50";
        assert_eq!(fail(200, &format!("{base} Q202=0 Q210=0")).param, Some(202));
        assert_eq!(
            fail(200, &format!("{base} Q202=5 Q210=-1")).param,
            Some(210)
        );
        assert_eq!(
            fail(200, &format!("{base} Q202=5 Q210=0 Q211=-1")).param,
            Some(211)
        );
        assert_eq!(fail(200, &format!("{base} Q210=0")).param, Some(202));
        assert_eq!(
            fail(200, &format!("{base} Q202=5 Q210=0 Q999=1")).param,
            Some(999)
        );
        assert_eq!(
            fail(200, &format!("{base} Q202=5 Q210=0 Q202=6")).param,
            Some(202)
        );
        assert_eq!(
            fail(200, &format!("{base} Q202=5 Q210=0 Q204=-1")).param,
            Some(204)
        );
        let e = fail(200, "Q200=2 Q201=-10 Q206=150 Q202=5 Q210=0 Q204=50");
        assert_eq!(e.param, Some(203));
        assert!(
            e.message.contains("Q203") && e.message.contains("missing"),
            "{}",
            e.message
        );
        let mut p = q(&format!("{base} Q202=5 Q210=0"));
        p[1].1 = f64::NAN;
        let mut out = Vec::new();
        assert_eq!(
            cycle(200, &p, &ctx(), &mut out).expect_err("refused").param,
            Some(201)
        );
        p[1].1 = f64::INFINITY;
        assert_eq!(
            cycle(200, &p, &ctx(), &mut out).expect_err("refused").param,
            Some(201)
        );
        let text = "Q200=2 Q201=-10 Q206=150 Q202=0.0001 Q210=0 Q203=0 Q204=50";
        assert_eq!(fail(200, text).param, Some(202));
        assert!(out.is_empty());
    }

    #[test]
    fn context_refusals() {
        let text = "Q200=2 Q201=-10 Q206=150 Q202=5 Q210=0 Q203=0 Q204=50";
        let mut c = ctx();
        c.position[0] = f64::NAN;
        assert_eq!(fail_in(200, text, &c).param, None);
        let mut c = ctx();
        c.plane = [0, 0, 2];
        assert_eq!(fail_in(200, text, &c).param, None);
        let mut c = ctx();
        c.tool_radius = -1.0;
        assert_eq!(fail_in(200, text, &c).param, None);
        let mut c = ctx();
        c.point_angle = Some(f64::INFINITY);
        assert_eq!(fail_in(200, text, &c).param, None);
        let e = fail(206, text);
        assert_eq!(e.param, None);
        assert!(e.message.contains("206"), "{}", e.message);
    }

    #[test]
    fn is_machining_cycle_lists_the_drilling_cycles() {
        for n in [200, 201, 202, 203, 204, 205, 207, 208, 209, 240, 241] {
            assert!(is_machining_cycle(n), "{n}");
        }
        for n in [0, 7, 19, 206, 210, 220, 247, 262] {
            assert!(!is_machining_cycle(n), "{n}");
        }
    }

    #[test]
    fn another_working_plane_drills_along_its_applicate() {
        let mut c = ctx();
        c.plane = XP;
        let text = "Q200=2 Q201=-15 Q206=100 Q211=0 Q208=0 Q203=5 Q204=20";
        check(
            &run_in(201, text, &c),
            &[
                Step::Rapid([Some(7.0), None, None]),
                Step::Feed {
                    to: [Some(-10.0), None, None],
                    feed: 100.0,
                },
                Step::Feed {
                    to: [Some(7.0), None, None],
                    feed: 100.0,
                },
                Step::Rapid([Some(25.0), None, None]),
            ],
        );
        // 202's lift in that plane: Q214 = 4 is +second axis, Z here.
        let text = "Q200=2 Q201=-15 Q206=100 Q211=0 Q208=0 Q203=5 Q204=20 Q214=4";
        let got = run_in(202, text, &c);
        check(
            &got[2..4],
            &[
                Step::Orient(0.0),
                Step::Rapid([None, Some(20.0), Some(50.2)]),
            ],
        );
    }

    // ----- 201 REAMING

    #[test]
    fn reaming_retracts_at_q208_or_q206() {
        let text = "Q200=2 Q201=-15 Q206=100 Q211=0.5 Q208=250 Q203=+0 Q204=50";
        check(
            &run(201, text),
            &[
                z(2.0),
                fz(-15.0, 100.0),
                Step::Dwell(0.5),
                fz(2.0, 250.0),
                z(50.0),
            ],
        );
        let text = "Q200=2 Q201=-15 Q206=100 Q211=0 Q208=0 Q203=+0 Q204=50";
        check(
            &run(201, text),
            &[z(2.0), fz(-15.0, 100.0), fz(2.0, 100.0), z(50.0)],
        );
        let text = "Q200=2 Q201=-15 Q206=100 Q211=0 Q208=99999.999 Q203=+0 Q204=50";
        check(
            &run(201, text),
            &[z(2.0), fz(-15.0, 100.0), z(2.0), z(50.0)],
        );
        let text = "Q200=2 Q201=-15 Q206=100 Q211=0 Q208=-5 Q203=+0 Q204=50";
        assert_eq!(fail(201, text).param, Some(208));
        let text = "Q200=2 Q201=-15 Q206=100 Q211=0 Q203=+0 Q204=50";
        assert_eq!(fail(201, text).param, Some(208));
    }

    // ----- 202 BORING

    const C202: &str = "Q200=2 Q201=-15 Q206=100 Q211=0.5 Q208=250 Q203=0 Q204=50";

    #[test]
    fn boring_orients_lifts_off_the_wall_and_restores_the_spindle() {
        check(
            &run(202, &format!("{C202} Q214=1 Q336=90")),
            &[
                z(2.0),
                fz(-15.0, 100.0),
                Step::Dwell(0.5),
                Step::Orient(90.0),
                xy(9.8, 20.0),
                fz(2.0, 250.0),
                xy(10.0, 20.0),
                z(50.0),
                Step::M(3),
            ],
        );
        // Q214 = 3: +X; the spindle was M4.
        let mut c = ctx();
        c.spindle_ccw = true;
        let got = run_in(202, &format!("{C202} Q214=3"), &c);
        assert!(same(&got[4], &xy(10.2, 20.0)), "{got:?}");
        assert_eq!(got.last(), Some(&Step::M(4)));
    }

    #[test]
    fn boring_without_disengaging_stays_on_the_axis() {
        check(
            &run(202, &format!("{C202} Q214=0")),
            &[
                z(2.0),
                fz(-15.0, 100.0),
                Step::Dwell(0.5),
                Step::Orient(0.0),
                fz(2.0, 250.0),
                z(50.0),
                Step::M(3),
            ],
        );
        assert_eq!(fail(202, &format!("{C202} Q214=5")).param, Some(214));
        assert_eq!(fail(202, &format!("{C202} Q214=1.5")).param, Some(214));
        assert_eq!(fail(202, C202).param, Some(214));
    }

    // ----- 203 UNIVERSAL DRILLING

    const C203: &str = "Q200=2 ~ Q201=-20 ~ Q206=150 ~ Q202=6 ~ Q210=0 ~ Q203=+0 ~ Q204=50 ~ \
                        Q212=1 ~ Q213=2 ~ Q205=3 ~ Q211=0 ~ Q208=500 ~ Q256=0.2";

    #[test]
    fn universal_drilling_with_decrement_and_breaks() {
        // Pecks 6, 5, 4, 3 (Q205), 3 → -6, -11, -15, -18, -20. Two chip
        // breaks, then out of the hole, then breaks again.
        check(
            &run(203, C203),
            &[
                z(2.0),
                fz(-6.0, 150.0),
                z(-5.8),
                fz(-11.0, 150.0),
                z(-10.8),
                fz(-15.0, 150.0),
                fz(2.0, 500.0),
                z(-13.0),
                fz(-18.0, 150.0),
                z(-17.8),
                fz(-20.0, 150.0),
                fz(2.0, 500.0),
                z(50.0),
            ],
        );
    }

    #[test]
    fn universal_drilling_as_hypermill_writes_it() {
        // CYCL DEF 203 with Q213=2 breaks: 1 mm pecks to -9.041, out of
        // the hole after every third peck.
        let text = "Q200=3 ~ Q201=-9.041 ~ Q206=68 ~ Q202=1 ~ Q210=0 ~ Q203=0 ~ Q204=50 ~ \
                    Q212=0 ~ Q213=2 ~ Q205=1 ~ Q211=0 ~ Q208=25000 ~ Q256=0.2";
        let mut want = vec![z(3.0)];
        for k in 1..=9 {
            let d = -f64::from(k);
            want.push(fz(d, 68.0));
            if k % 3 == 0 {
                want.push(fz(3.0, 25000.0));
                want.push(z(d + 3.0));
            } else {
                want.push(z(d + 0.2));
            }
        }
        want.extend([fz(-9.041, 68.0), fz(3.0, 25000.0), z(50.0)]);
        check(&run(203, text), &want);
    }

    #[test]
    fn universal_drilling_without_breaks_leaves_the_hole_each_peck() {
        let text = "Q200=2 Q201=-12 Q206=150 Q202=5 Q210=1.5 Q203=0 Q204=50 Q212=0 Q213=0 \
                    Q205=0 Q211=0.25 Q208=0 Q256=0.2";
        check(
            &run(203, text),
            &[
                z(2.0),
                fz(-5.0, 150.0),
                fz(2.0, 150.0),
                Step::Dwell(1.5),
                z(-3.0),
                fz(-10.0, 150.0),
                fz(2.0, 150.0),
                Step::Dwell(1.5),
                z(-8.0),
                fz(-12.0, 150.0),
                Step::Dwell(0.25),
                fz(2.0, 150.0),
                z(50.0),
            ],
        );
    }

    #[test]
    fn universal_drilling_refusals() {
        let text = "Q200=2 Q201=-20 Q206=150 Q202=2 Q210=0 Q203=0 Q204=50 Q212=1 Q213=0 \
                    Q205=0 Q211=0 Q208=500 Q256=0.2";
        assert_eq!(fail(203, text).param, Some(205));
        let text = "Q200=2 Q201=-20 Q206=150 Q202=5 Q210=0 Q203=0 Q204=50 Q212=0 Q213=2 \
                    Q205=0 Q211=0 Q208=500 Q256=0";
        assert_eq!(fail(203, text).param, Some(256));
        let text = "Q200=2 Q201=-20 Q206=150 Q202=5 Q210=0 Q203=0 Q204=50 Q212=0 Q213=1.5 \
                    Q205=0 Q211=0 Q208=500 Q256=0.2";
        assert_eq!(fail(203, text).param, Some(213));
        let text = "Q200=2 Q201=-20 Q206=150 Q202=5 Q210=0 Q203=0 Q204=50 Q212=0 Q213=-1 \
                    Q205=0 Q211=0 Q208=500 Q256=0.2";
        assert_eq!(fail(203, text).param, Some(213));
        let text = "Q200=2 Q201=-20 Q206=150 Q202=5 Q210=0 Q203=0 Q204=50 Q212=-1 Q213=0 \
                    Q205=0 Q211=0 Q208=500 Q256=0.2";
        assert_eq!(fail(203, text).param, Some(212));
        let e = fail(203, "Q200=2 Q201=-20 Q206=150 Q202=5 Q210=0 Q203=0 Q204=50");
        assert_eq!(e.param, Some(212));
    }

    // ----- 204 BACK BORING

    const C204: &str = "Q200=2 Q249=+5 Q250=20 Q251=3.5 Q252=15 Q253=750 Q254=200 Q255=0.5 \
                        Q203=+0 Q204=50";

    #[test]
    fn back_boring_goes_through_off_centre_and_cuts_upwards() {
        // Underside -20; tip -20-2-15 = -37 below, -20+5-15 = -30 at the
        // counterbore depth; off-centre X 10-3.5 = 6.5 (Q214 = 1).
        check(
            &run(204, &format!("{C204} Q214=1 Q336=0")),
            &[
                z(2.0),
                Step::Orient(0.0),
                xy(6.5, 20.0),
                fz(-37.0, 750.0),
                fxy(10.0, 20.0, 750.0),
                Step::M(3),
                fz(-30.0, 200.0),
                Step::Dwell(0.5),
                Step::Orient(0.0),
                fxy(6.5, 20.0, 750.0),
                fz(2.0, 750.0),
                z(50.0),
                xy(10.0, 20.0),
                Step::M(3),
            ],
        );
        // Q253 = MAX: the pre-positioning moves are rapid.
        let text = C204.replace("Q253=750", "Q253=99999.999");
        let got = run(204, &format!("{text} Q214=2 Q336=45"));
        check(
            &got[1..5],
            &[Step::Orient(45.0), xy(10.0, 16.5), z(-37.0), xy(10.0, 20.0)],
        );
    }

    #[test]
    fn back_boring_refusals() {
        assert_eq!(fail(204, &format!("{C204} Q214=0")).param, Some(214));
        let text = C204.replace("Q249=+5", "Q249=25");
        assert_eq!(fail(204, &format!("{text} Q214=1")).param, Some(249));
        let text = C204.replace("Q249=+5", "Q249=-5");
        assert_eq!(fail(204, &format!("{text} Q214=1")).param, Some(249));
        let text = C204.replace("Q251=3.5", "Q251=0");
        assert_eq!(fail(204, &format!("{text} Q214=1")).param, Some(251));
        let text = C204.replace("Q254=200", "Q254=99999.999");
        assert_eq!(fail(204, &format!("{text} Q214=1")).param, Some(254));
        let text = C204.replace("Q249=+5", "Q249=0");
        assert!(run(204, &format!("{text} Q214=1")).is_empty());
    }

    // ----- 205 UNIVERSAL PECKING

    #[test]
    fn universal_pecking_with_chip_breaking_and_advanced_stops() {
        let text = "Q200=2 Q201=-20 Q206=150 Q202=8 Q203=0 Q204=50 Q212=0 Q205=0 Q258=0.5 \
                    Q259=1.5 Q257=3 Q256=0.2 Q211=0.5 Q379=0 Q253=750 Q208=1000";
        // Pecks to -8, -16, -20; breaks every 3 mm within each peck; the
        // stops 0.5 after the first peck and 1.5 before the last.
        check(
            &run(205, text),
            &[
                z(2.0),
                fz(-3.0, 150.0),
                z(-2.8),
                fz(-6.0, 150.0),
                z(-5.8),
                fz(-8.0, 150.0),
                fz(2.0, 1000.0),
                z(-7.5),
                fz(-11.0, 150.0),
                z(-10.8),
                fz(-14.0, 150.0),
                z(-13.8),
                fz(-16.0, 150.0),
                fz(2.0, 1000.0),
                z(-14.5),
                fz(-19.0, 150.0),
                z(-18.8),
                fz(-20.0, 150.0),
                Step::Dwell(0.5),
                fz(2.0, 1000.0),
                z(50.0),
            ],
        );
    }

    #[test]
    fn universal_pecking_stops_in_equal_steps() {
        let text = "Q200=2 Q201=-20 Q206=150 Q202=5 Q203=0 Q204=50 Q212=0 Q205=0 Q258=1 \
                    Q259=2 Q257=0 Q256=0 Q211=0";
        // Pecks -5, -10, -15, -20; stops 1, 1.5, 2; Q208 omitted: rapid.
        check(
            &run(205, text),
            &[
                z(2.0),
                fz(-5.0, 150.0),
                z(2.0),
                z(-4.0),
                fz(-10.0, 150.0),
                z(2.0),
                z(-8.5),
                fz(-15.0, 150.0),
                z(2.0),
                z(-13.0),
                fz(-20.0, 150.0),
                z(2.0),
                z(50.0),
            ],
        );
    }

    #[test]
    fn universal_pecking_from_a_deepened_starting_point() {
        let text = "Q200=2 Q201=-20 Q206=150 Q202=8 Q203=0 Q204=50 Q212=0 Q205=0 Q258=0.5 \
                    Q259=1.5 Q257=0 Q256=0.2 Q211=0 Q379=5 Q253=750 Q208=0";
        check(
            &run(205, text),
            &[
                z(2.0),
                fz(-3.0, 750.0),
                fz(-13.0, 150.0),
                fz(2.0, 150.0),
                z(-12.5),
                fz(-20.0, 150.0),
                fz(2.0, 150.0),
                z(50.0),
            ],
        );
        let no_feed = text.replace("Q253=750 ", "");
        assert_eq!(fail(205, &no_feed).param, Some(253));
        let deep = text.replace("Q379=5", "Q379=25");
        assert_eq!(fail(205, &deep).param, Some(379));
        let no_lift = text
            .replace("Q257=0", "Q257=2")
            .replace("Q256=0.2", "Q256=0");
        assert_eq!(fail(205, &no_lift).param, Some(256));
    }

    // ----- 207 RIGID TAPPING NEW

    #[test]
    fn rigid_tapping_at_pitch_times_speed() {
        let mut c = ctx();
        c.position = [159.0, 7.0, 100.0];
        c.spindle = 566.0;
        let text =
            "CYCL DEF 207 RIGID TAPPING NEW ~ Q200=3 ~ Q201=-12.0296 ~ Q239=+1 ~ Q203=0 ~ Q204=70";
        let text = text.trim_start_matches("CYCL DEF 207 RIGID TAPPING NEW ~");
        check(
            &run_in(207, text, &c),
            &[
                z(3.0),
                Step::M(3),
                fz(-12.0296, 566.0),
                Step::M(4),
                fz(3.0, 566.0),
                Step::M(5),
                z(70.0),
            ],
        );
    }

    #[test]
    fn left_hand_tapping_turns_m4_in_and_m3_out() {
        let text = "Q200=2 Q201=-10 Q239=-1.5 Q203=0 Q204=20 Q336=30";
        check(
            &run(207, text),
            &[
                z(2.0),
                Step::Orient(30.0),
                Step::M(4),
                fz(-10.0, 1500.0),
                Step::M(3),
                fz(2.0, 1500.0),
                Step::M(5),
                z(20.0),
            ],
        );
    }

    #[test]
    fn tapping_refusals() {
        let text = "Q200=2 Q201=-10 Q239=0 Q203=0 Q204=20";
        assert_eq!(fail(207, text).param, Some(239));
        let mut c = ctx();
        c.spindle = 0.0;
        let text = "Q200=2 Q201=-10 Q239=1 Q203=0 Q204=20";
        let e = fail_in(207, text, &c);
        assert_eq!(e.param, None);
        assert!(e.message.contains("spindle"), "{}", e.message);
        assert_eq!(fail(207, "Q200=2 Q201=-10 Q203=0 Q204=20").param, Some(239));
    }

    // ----- 209 TAPPING W/ CHIP BRKG

    const C209: &str = "Q200=2 Q201=-10 Q239=+1.5 Q203=+0 Q204=50 Q257=4 Q256=1 Q336=30";

    #[test]
    fn tapping_with_chip_breaking_backs_off_by_pitch_times_q256() {
        // Feed 1.5 × 1000; chip breaks at -4 and -8, back 1.5 each.
        check(
            &run(209, C209),
            &[
                z(2.0),
                Step::Orient(30.0),
                Step::M(3),
                fz(-4.0, 1500.0),
                Step::M(4),
                fz(-2.5, 1500.0),
                Step::M(3),
                fz(-8.0, 1500.0),
                Step::M(4),
                fz(-6.5, 1500.0),
                Step::M(3),
                fz(-10.0, 1500.0),
                Step::M(4),
                fz(2.0, 1500.0),
                Step::M(5),
                z(50.0),
            ],
        );
    }

    #[test]
    fn tapping_with_chip_removal_and_a_faster_retraction() {
        let text = "Q200=2 Q201=-6 Q239=1 Q203=0 Q204=0 Q257=4 Q256=0 Q336=0 Q403=2";
        check(
            &run(209, text),
            &[
                z(2.0),
                Step::Orient(0.0),
                Step::M(3),
                fz(-4.0, 1000.0),
                Step::M(4),
                Step::Speed(2000.0),
                fz(2.0, 2000.0),
                Step::Speed(1000.0),
                Step::M(3),
                fz(-6.0, 1000.0),
                Step::M(4),
                Step::Speed(2000.0),
                fz(2.0, 2000.0),
                Step::Speed(1000.0),
                Step::M(5),
                z(2.0),
            ],
        );
        let text = "Q200=2 Q201=-6 Q239=1 Q203=0 Q204=0 Q257=0 Q256=0 Q336=0 Q403=0";
        assert_eq!(fail(209, text).param, Some(403));
        let text = "Q200=2 Q201=-6 Q239=1 Q203=0 Q204=0 Q257=-1 Q256=0 Q336=0";
        assert_eq!(fail(209, text).param, Some(257));
        let text = "Q200=2 Q201=-6 Q239=1 Q203=0 Q204=0 Q257=0 Q256=0";
        assert_eq!(fail(209, text).param, Some(336));
    }

    #[test]
    fn retracts_inside_the_hole_stop_at_the_set_up_clearance() {
        // 209: 3 × 1.5 = 4.5 back from -2 would be above Z2.
        let text = "Q200=2 Q201=-4 Q239=1.5 Q203=0 Q204=0 Q257=2 Q256=3 Q336=0";
        check(
            &run(209, text)[3..6],
            &[fz(-2.0, 1500.0), Step::M(4), fz(2.0, 1500.0)],
        );
        // 203: a chip-break distance of 5 after a 1 mm peck.
        let text = "Q200=2 Q201=-3 Q206=150 Q202=1 Q210=0 Q203=0 Q204=0 Q212=0 Q213=5 \
                    Q205=0 Q211=0 Q208=0 Q256=5";
        check(&run(203, text)[1..3], &[fz(-1.0, 150.0), z(2.0)]);
        // 205: an advanced stop distance of 10.
        let text = "Q200=2 Q201=-6 Q206=150 Q202=3 Q203=0 Q204=0 Q212=0 Q205=0 Q258=10 \
                    Q259=10 Q257=0 Q256=0 Q211=0";
        check(&run(205, text)[1..4], &[fz(-3.0, 150.0), z(2.0), z(2.0)]);
    }

    // ----- 208 BORE MILLING

    const C208: &str = "CYCL DEF 208 BORE MILLING ~ Q200=1 ~ Q201=-15 ~ Q206=840 ~ Q334=0.7 ~ \
                        Q203=0 ~ Q204=57 ~ Q335=12.5 ~ Q342=12.4 ~ Q351=1";

    fn c208() -> String {
        C208.trim_start_matches("CYCL DEF 208 BORE MILLING ~")
            .to_string()
    }

    #[test]
    fn bore_milling_helix_turns_then_a_full_circle_at_depth() {
        // 6 mm tool: helix radius 6.25 - 3 = 3.25. From Z1 to Z-15 is
        // 16 mm, 16 / 0.7 = 22 full turns to Z-14.4 and 6/7 of a turn
        // (308.571428…°) to Z-15; climb with M3: counterclockwise.
        let mut want = vec![z(1.0), fxy(13.25, 20.0, 840.0)];
        for k in 1..=22 {
            want.push(helix(360.0, 1.0 - 0.7 * f64::from(k), 840.0));
        }
        want.push(helix(360.0 * 6.0 / 7.0, -15.0, 840.0));
        want.push(helix(360.0, -15.0, 840.0));
        want.push(fxy(10.0, 20.0, 840.0));
        want.push(z(57.0));
        check(&run(208, &c208()), &want);
    }

    #[test]
    fn bore_milling_direction_from_q351_and_the_spindle() {
        let up_cut = c208().replace("Q351=1", "Q351=-1");
        assert!(same(&run(208, &up_cut)[2], &helix(-360.0, 0.3, 840.0)));
        let mut c = ctx();
        c.spindle_ccw = true;
        assert!(same(
            &run_in(208, &c208(), &c)[2],
            &helix(-360.0, 0.3, 840.0)
        ));
        assert!(same(
            &run_in(208, &up_cut, &c)[2],
            &helix(360.0, 0.3, 840.0)
        ));
        // Q351 omitted: climb.
        let old = c208().replace("~ Q351=1", "");
        assert!(same(&run(208, &old)[2], &helix(360.0, 0.3, 840.0)));
        assert_eq!(
            fail(208, &c208().replace("Q351=1", "Q351=0")).param,
            Some(351)
        );
    }

    #[test]
    fn bore_milling_a_hole_of_the_tool_diameter_plunges_straight() {
        let text = c208().replace("Q335=12.5", "Q335=6");
        check(&run(208, &text), &[z(1.0), fz(-15.0, 840.0), z(57.0)]);
        let text = c208().replace("Q335=12.5", "Q335=5");
        assert_eq!(fail(208, &text).param, Some(335));
    }

    #[test]
    fn bore_milling_checks_the_diameter_ratio_without_a_roughing_diameter() {
        let text = c208().replace("Q342=12.4", "Q342=0");
        let e = fail(208, &text);
        assert_eq!(e.param, Some(335));
        assert!(e.message.contains("twice"), "{}", e.message);
        // 12 = twice the tool diameter is allowed.
        let text = text.replace("Q335=12.5", "Q335=12");
        assert_eq!(run(208, &text)[1], fxy(13.0, 20.0, 840.0));
        assert_eq!(
            fail(208, &c208().replace("Q334=0.7", "Q334=0")).param,
            Some(334)
        );
        assert_eq!(
            fail(208, &c208().replace("Q334=0.7", "Q334=0.000001")).param,
            Some(334)
        );
        let mut c = ctx();
        c.tool_radius = 0.0;
        assert_eq!(fail_in(208, &c208(), &c).param, Some(335));
    }

    #[test]
    fn bore_milling_whole_turns_end_on_the_depth() {
        // 1 + 15 = 16 = 8 turns of 2 mm: no part turn.
        let text = c208().replace("Q334=0.7", "Q334=2");
        let got = run(208, &text);
        assert_eq!(got.len(), 2 + 8 + 1 + 2);
        assert!(same(&got[9], &helix(360.0, -15.0, 840.0)));
        assert!(same(&got[10], &helix(360.0, -15.0, 840.0)));
    }

    // ----- 240 CENTERING

    const C240: &str = "Q200=2 Q201=-3 Q344=-9 Q206=250 Q211=0.1 Q203=+0 Q204=50";

    #[test]
    fn centering_to_a_depth_or_a_diameter() {
        check(
            &run(240, &format!("{C240} Q343=0")),
            &[z(2.0), fz(-3.0, 250.0), Step::Dwell(0.1), z(50.0)],
        );
        let mut c = ctx();
        c.point_angle = Some(90.0);
        // 9 / 2 / tan(45°) = 4.5.
        check(
            &run_in(240, &format!("{C240} Q343=1"), &c),
            &[z(2.0), fz(-4.5, 250.0), Step::Dwell(0.1), z(50.0)],
        );
        // 60°: 4.5 / tan(30°) = 7.794228634…
        c.point_angle = Some(60.0);
        let got = run_in(240, &format!("{C240} Q343=1"), &c);
        assert!(same(&got[1], &fz(-7.794_228_634_059_948, 250.0)), "{got:?}");
    }

    #[test]
    fn centering_refusals() {
        assert_eq!(fail(240, &format!("{C240} Q343=1")).param, Some(343));
        assert_eq!(fail(240, &format!("{C240} Q343=2")).param, Some(343));
        let mut c = ctx();
        c.point_angle = Some(90.0);
        let text = C240.replace("Q344=-9", "Q344=9");
        assert_eq!(fail_in(240, &format!("{text} Q343=1"), &c).param, Some(344));
        let text = C240.replace("Q344=-9", "Q344=0");
        assert!(run_in(240, &format!("{text} Q343=1"), &c).is_empty());
        let text = C240.replace("Q201=-3 ", "");
        assert_eq!(fail(240, &format!("{text} Q343=0")).param, Some(201));
    }

    // ----- 241 SINGLE-LIP DEEP-HOLE DRILLING

    const C241: &str = "Q200=2 Q201=-80 Q206=150 Q211=0.25 Q203=+0 Q204=50 Q379=7.5 Q253=750 \
                        Q208=1000 Q427=25 Q428=500 Q429=8 Q430=9 Q435=0";

    #[test]
    fn single_lip_drilling_enters_slowly_drills_and_leaves() {
        check(
            &run(241, &format!("{C241} Q426=3")),
            &[
                z(2.0),
                Step::Speed(25.0),
                Step::M(3),
                fz(-5.5, 750.0),
                Step::Speed(500.0),
                Step::M(3),
                Step::M(8),
                fz(-80.0, 150.0),
                Step::Dwell(0.25),
                Step::M(9),
                Step::Speed(25.0),
                Step::M(3),
                fz(2.0, 1000.0),
                z(50.0),
            ],
        );
        // A stationary spindle for entering and leaving, no coolant, no
        // deepened start.
        let text = C241
            .replace("Q379=7.5", "Q379=0")
            .replace("Q429=8 Q430=9 ", "");
        check(
            &run(241, &format!("{text} Q426=5")),
            &[
                z(2.0),
                Step::M(5),
                Step::Speed(500.0),
                Step::M(3),
                fz(-80.0, 150.0),
                Step::Dwell(0.25),
                Step::M(5),
                fz(2.0, 1000.0),
                z(50.0),
            ],
        );
    }

    #[test]
    fn single_lip_refusals() {
        assert_eq!(fail(241, &format!("{C241} Q426=6")).param, Some(426));
        let text = C241.replace("Q435=0", "Q435=10");
        assert_eq!(fail(241, &format!("{text} Q426=3")).param, Some(435));
        assert_eq!(
            fail(241, &format!("{C241} Q426=3 Q202=10")).param,
            Some(202)
        );
        // A plunging depth past the depth is one plunge.
        assert_eq!(run(241, &format!("{C241} Q426=3 Q202=100")).len(), 14);
        let text = C241.replace("Q427=25", "Q427=0");
        assert_eq!(fail(241, &format!("{text} Q426=3")).param, Some(427));
        let text = C241.replace("Q429=8", "Q429=8.5");
        assert_eq!(fail(241, &format!("{text} Q426=3")).param, Some(429));
        let text = C241.replace("Q379=7.5", "Q379=80");
        assert_eq!(fail(241, &format!("{text} Q426=3")).param, Some(379));
        assert_eq!(fail(241, C241).param, Some(426));
    }

    // ----- PATTERN DEF

    fn item(kind: &str, words: &str) -> PatternItem {
        PatternItem {
            kind: kind.to_string(),
            words: words
                .split_whitespace()
                .map(|w| {
                    let at = w
                        .find(|c: char| c == '+' || c == '-' || c.is_ascii_digit())
                        .expect("a value");
                    (w[..at].to_string(), w[at..].parse().expect("a number"))
                })
                .collect(),
        }
    }

    fn points(items: &[PatternItem]) -> Vec<[f64; 3]> {
        let mut out = Vec::new();
        pattern(items, &mut out).expect("the pattern is read");
        out
    }

    #[track_caller]
    fn check_points(got: &[[f64; 3]], want: &[[f64; 3]]) {
        let ok = got.len() == want.len()
            && got
                .iter()
                .zip(want)
                .all(|(a, b)| a.iter().zip(b).all(|(a, b)| near(*a, *b)));
        assert!(ok, "\n got: {got:?}\nwant: {want:?}");
    }

    fn pattern_fail(items: &[PatternItem]) -> CycleError {
        let mut out = vec![[9.0; 3]];
        let e = pattern(items, &mut out).expect_err("the pattern is refused");
        assert_eq!(out, vec![[9.0; 3]]);
        e
    }

    #[test]
    fn pattern_points_and_rows() {
        check_points(
            &points(&[
                item("POS", "X+25 Y+33.5 Z+0"),
                item("POS", "X+15 Y+6.5"),
                item("ROW", "X+10 Y+20 D+5 NUM3 ROT+90 Z-2"),
                item("ROW", "X+0 Y+0 D-4 NUM2 ROT+0 Z+0"),
            ]),
            &[
                [25.0, 33.5, 0.0],
                [15.0, 6.5, 0.0],
                [10.0, 20.0, -2.0],
                [10.0, 25.0, -2.0],
                [10.0, 30.0, -2.0],
                [0.0, 0.0, 0.0],
                [-4.0, 0.0, 0.0],
            ],
        );
    }

    #[test]
    fn pattern_positions_may_be_incremental() {
        check_points(
            &points(&[
                item("POS", "X+25 Y+33.5 Z+0"),
                item("POS", "X+15 IY+6.5 Z+0"),
                item("POS", "IX+1 IY-1 IZ-2"),
            ]),
            &[[25.0, 33.5, 0.0], [15.0, 40.0, 0.0], [16.0, 39.0, -2.0]],
        );
        let e = pattern_fail(&[item("POS", "IX+1 Y+0")]);
        assert!(e.message.contains("no point before"), "{}", e.message);
        let e = pattern_fail(&[item("POS", "X+1 Y+0"), item("POS", "X+1 IX+1 Y+0")]);
        assert!(e.message.contains("both"), "{}", e.message);
        let e = pattern_fail(&[item("ROW", "IX+1 Y+0 D+1 NUM1")]);
        assert!(e.message.contains("not a word"), "{}", e.message);
    }

    #[test]
    fn pattern_grid_is_a_meander_and_a_frame_goes_round() {
        check_points(
            &points(&[item(
                "PAT",
                "X+0 Y+0 DX+10 DY+5 NUMX3 NUMY2 ROT+0 ROTX+0 ROTY+0 Z+1",
            )]),
            &[
                [0.0, 0.0, 1.0],
                [10.0, 0.0, 1.0],
                [20.0, 0.0, 1.0],
                [20.0, 5.0, 1.0],
                [10.0, 5.0, 1.0],
                [0.0, 5.0, 1.0],
            ],
        );
        // Turned by 90°: columns along +Y, rows along -X.
        check_points(
            &points(&[item("PAT", "X+0 Y+0 DX+10 DY+5 NUMX2 NUMY2 ROT+90")]),
            &[
                [0.0, 0.0, 0.0],
                [0.0, 10.0, 0.0],
                [-5.0, 10.0, 0.0],
                [-5.0, 0.0, 0.0],
            ],
        );
        check_points(
            &points(&[item("FRAME", "X+0 Y+0 DX+10 DY+10 NUMX3 NUMY3 ROT+0")]),
            &[
                [0.0, 0.0, 0.0],
                [10.0, 0.0, 0.0],
                [20.0, 0.0, 0.0],
                [20.0, 10.0, 0.0],
                [20.0, 20.0, 0.0],
                [10.0, 20.0, 0.0],
                [0.0, 20.0, 0.0],
                [0.0, 10.0, 0.0],
            ],
        );
        check_points(
            &points(&[item("FRAME", "X+0 Y+0 DX+10 DY+10 NUMX1 NUMY3")]),
            &[[0.0, 0.0, 0.0], [0.0, 10.0, 0.0], [0.0, 20.0, 0.0]],
        );
        check_points(
            &points(&[item("FRAME", "X+0 Y+0 DX+10 DY+10 NUMX2 NUMY1")]),
            &[[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]],
        );
    }

    #[test]
    fn pattern_circles() {
        check_points(
            &points(&[item("CIRC", "X+0 Y+0 D20 START+0 NUM4 Z+0")]),
            &[
                [10.0, 0.0, 0.0],
                [0.0, 10.0, 0.0],
                [-10.0, 0.0, 0.0],
                [0.0, -10.0, 0.0],
            ],
        );
        let h = 10.0 * 60f64.to_radians().sin();
        check_points(
            &points(&[item("PITCHCIRC", "X+1 Y+2 D20 START+90 STEP-30 NUM3 Z+0")]),
            &[[1.0, 12.0, 0.0], [6.0, 2.0 + h, 0.0], [1.0 + h, 7.0, 0.0]],
        );
    }

    #[test]
    fn pattern_refusals() {
        for (kind, words, what) in [
            ("LINE", "X+0 Y+0", "not a pattern"),
            ("POS", "X+0", "Y is missing"),
            ("POS", "X+0 Y+0 A+1", "A is not a word"),
            ("POS", "X+0 Y+0 X+1", "written twice"),
            ("ROW", "X+0 Y+0 D+5", "NUM is missing"),
            ("ROW", "X+0 Y+0 D+5 NUM0", "NUM must be"),
            ("ROW", "X+0 Y+0 D+5 NUM2.5", "NUM must be"),
            ("PAT", "X+0 Y+0 DX+1 DY+1 NUMX200 NUMY200", "more than"),
            ("CIRC", "X+0 Y+0 D0 NUM4", "diameter"),
            ("PITCHCIRC", "X+0 Y+0 D10 NUM4", "STEP is missing"),
        ] {
            let e = pattern_fail(&[item("POS", "X+1 Y+1"), item(kind, words)]);
            assert!(e.message.contains(what), "{kind} {words}: {}", e.message);
            assert_eq!(e.param, None);
        }
        let mut bad = item("POS", "X+0 Y+0");
        bad.words[0].1 = f64::NAN;
        assert!(pattern_fail(&[bad]).message.contains("finite"));
        let many: Vec<_> = (0..3)
            .map(|_| item("PAT", "X+0 Y+0 DX+1 DY+1 NUMX100 NUMY40"))
            .collect();
        assert!(pattern_fail(&many).message.contains("more than"));
    }
}
