//! The SINUMERIK cycles the front end carries out itself: the drilling,
//! tapping and boring cycles CYCLE81 … CYCLE89 and CYCLE840, the hole
//! patterns HOLES1, HOLES2 and CYCLE801, and the engraving cycle CYCLE60.
//!
//! A pure module: each cycle call becomes a list of elementary steps
//! ([`CycleStep`]: rapid and feed moves in programmed coordinates, dwells,
//! M functions) or of hole positions; the controller carries them out.
//! Nothing here reads or changes the controller.
//!
//! Sources are cited by the keys of the design brief
//! (`/work/shared/design/sinumerik-heidenhain-brief.md`, §0), mostly its
//! §7 "Canned cycles" (parameter orders, [ONE p494] for omitted arguments,
//! [840D PGZ 11.02 p2-86] for CYCLE840) and §8 "Alarms". Everything else
//! is the kernel's reading, listed below and marked *kernel* or
//! *UNVERIFIED*.
//!
//! # Levels (every drilling cycle and CYCLE60)
//!
//! The hole is drilled along the applicate of the selected plane (G17: Z,
//! G18: Y, G19: X) at the position where the tool stands in the plane.
//! RTP (retract plane), RFP (reference plane) and DP (final depth) are
//! absolute positions on the applicate; SDIS is the safety clearance above
//! RFP, taken without its sign (brief §7: "unsigned"); DPR is the final
//! depth relative to RFP, taken as an amount below RFP whatever its sign.
//!
//! * DP wins when both DP and DPR are given (brief §7: DPR is "used when
//!   DP empty"). *UNVERIFIED*: an older cycles manual may prefer DPR; not
//!   checked.
//! * An omitted RFP is 0: the brief (§1, [ONE p494]) says omitted
//!   arguments arrive as 0, and its real-program example
//!   `CYCLE81(5,,3,-15,0)` leaves RFP out. RTP and the depth (DP or DPR)
//!   have no such default here: a missing one is refused (*kernel*: a
//!   retract plane of 0 is most likely the work surface).
//! * Every cycle begins with a rapid move on the applicate straight to
//!   RFP+SDIS, from above or below (brief §7: "G0 to RFP+SDIS"; nothing in
//!   the brief makes it go to RTP first), and ends with a rapid move to
//!   RTP.
//! * 61101 "reference plane incorrectly defined" (brief §8) when RFP+SDIS
//!   is not above the final depth; also (*kernel*) when RTP is below RFP.
//!
//! # Arguments
//!
//! `args[i]` is the i-th argument in the manual's order, `None` when
//! omitted. A parameter with a default below (SDIS, DTB, FRF, _MDEP,
//! _VRT, _DTD, _DIS1, SDAC, SDIR, SDR, SST, SST1, FFR, RFF, INDA) takes
//! it when omitted or 0, as the control passes an omitted argument as 0
//! (brief §1, [ONE p494]); levels, depths, positions and angles are taken
//! as written, 0 included, and only their omission counts. Arguments past
//! the ones the kernel reads (the later Operate additions GMODE, DMODE,
//! AMODE, CYCLE84's `_AXN, _PTAB, _TECHNO, _VARI, …`) must be omitted or
//! 0; any other value is refused (61098) rather than guessed.
//! Under G70/G700 (`CycleContext::inch`) every length argument (levels,
//! depths, pecks, pitch, lift-off, pattern positions and spacings,
//! character sizes) is in inches and multiplied by 25.4. Feed arguments
//! (CYCLE85's FFR, RFF) are taken as mm/min, speeds as rev/min (*kernel*:
//! the context does not say whether G700 made the feed inches too).
//! Dwells are seconds; a negative dwell (revolutions in some manuals,
//! *UNVERIFIED*) is refused.
//!
//! # Cycles (brief §7; details marked *kernel* are the kernel's reading)
//!
//! * CYCLE81(RTP,RFP,SDIS,DP,DPR) (brief §7, from helmancnc and ADSK):
//!   rapid RFP+SDIS, feed to depth at the feed in force, rapid RTP.
//!   CYCLE82(…,DTB): + dwell DTB at depth.
//! * CYCLE83(RTP,RFP,SDIS,DP,DPR,FDEP,FDPR,DAM,DTB,DTS,FRF,VARI,_AXN,
//!   _MDEP,_VRT,_DTD,_DIS1): deep-hole drilling. The first depth is FDEP
//!   (absolute) or FDPR (below RFP), FDEP winning, at the feed × FRF
//!   (default 1; *kernel*: a factor, any positive value). The first peck
//!   is RFP − first depth; each later peck is the one before less DAM, but
//!   not less than _MDEP (omitted or 0: DAM; with DAM 0 every peck is the
//!   first). A first depth below the final depth is cut to it. DTB dwells
//!   at each intermediate depth, _DTD (omitted or 0: DTB) at the final
//!   depth. VARI = 0 (chip breaking): after each peck a rapid retract by
//!   _VRT (omitted or 0: 1 mm; *kernel*: rapid, as the kernel's G73), then
//!   feed on. VARI = 1 (chip removal): rapid to RFP+SDIS, dwell DTS, rapid
//!   back to _DIS1 above the depth reached, feed on; _DIS1 omitted or 0
//!   ("automatic") is [`PECK_CLEARANCE`] (0.1 mm, *kernel*: the kernel's
//!   FANUC G83 clearance). Negative DAM, _MDEP, _VRT, _DIS1 (percentage
//!   or other forms not in the brief) and a non-zero _AXN are refused
//!   (61098). Other VARI values: 61002.
//! * CYCLE84(RTP,RFP,SDIS,DP,DPR,DTB,SDAC,MPIT,PIT,POSS,SST,SST1): rigid
//!   tapping. Pitch from PIT (a length, converted under G70) or, when PIT
//!   is omitted or 0, from the metric size MPIT (ISO 261 coarse pitch, see
//!   [`coarse_pitch`]); the sign of the one used is the hand (negative:
//!   left hand). Neither, or an MPIT not in the table: 61001. Spindle on in
//!   the thread's direction (right hand M3, left hand M4), feed to depth at
//!   |pitch| × SST (SST omitted or 0: the speed in force), dwell DTB, the
//!   other direction (M4 / M3), feed back to RFP+SDIS at |pitch| × SST1
//!   (omitted or 0: SST), the speed in force again, SDAC (3/4/5 → M3, M4,
//!   M5; omitted or 0: the direction before the cycle; others 61002),
//!   rapid RTP. A speed different from the one in force is set with
//!   [`CycleStep::Speed`] (*kernel*: the step list must carry it for the
//!   feed to match the pitch). POSS (orientation before tapping) is read
//!   and ignored: the steps have no oriented stop at an angle.
//! * CYCLE840(RTP,RFP,SDIS,DP,DPR,DTB,SDR,SDAC,ENC,MPIT,PIT): tapping
//!   with a compensating chuck in the spindle direction in force: feed to
//!   depth at |pitch| × the speed in force (no MPIT/PIT: the feed in
//!   force, the form without lead of [840D PGZ 11.02 p2-86]), dwell DTB,
//!   SDR (3/4; omitted or 0: the reverse of the direction in force, as
//!   the manual's automatic reversal), feed out to RFP+SDIS, SDAC, rapid
//!   RTP. ENC is ignored (the moves are the same with or without encoder).
//! * CYCLE85(RTP,RFP,SDIS,DP,DPR,DTB,FFR,RFF): feed in at FFR (omitted or
//!   0: the feed in force), dwell, feed out to RFP+SDIS at RFF (omitted or
//!   0: as in), rapid RTP (brief §7, from ADSK).
//! * CYCLE86(RTP,RFP,SDIS,DP,DPR,DTB,SDIR,RPA,RPO,RPAP,POSS) (brief:
//!   list UNVERIFIED): feed to depth, dwell, M5, M19 (oriented stop), one
//!   rapid lift-off by RPA, RPO (first, second axis of the plane) and RPAP
//!   (applicate), all relative (*UNVERIFIED* that RPAP moves with the
//!   other two), rapid to RFP+SDIS, rapid back to the hole in the plane,
//!   rapid RTP, spindle on SDIR. A non-zero POSS is refused (61098): M19
//!   carries no angle, and the lift-off direction depends on it.
//! * CYCLE87(RTP,RFP,SDIS,DP,DPR,SDIR) (brief §7, from ADSK): feed to
//!   depth, M5, M0, rapid RTP, spindle on SDIR. CYCLE88(…,DTB,SDIR)
//!   (UNVERIFIED list): the same with a dwell at depth. CYCLE89(…,DTB)
//!   (UNVERIFIED list): feed to depth, dwell, feed out to RFP+SDIS, rapid
//!   RTP.
//! * SDIR omitted or 0: the direction before the cycle (*kernel*); other
//!   values than 3, 4: 61002.
//!
//! # Patterns (brief §7: the orders are UNVERIFIED)
//!
//! Positions in the plane (first, second axis); angles in degrees,
//! counterclockwise from the first axis towards the second. Omitted
//! positions and angles are 0; the counts are required whole numbers ≥ 1
//! (61097 otherwise), a spacing is required when its count is above 1.
//!
//! * HOLES1(SPCA,SPCO,STA1,FDIS,DBH,NUM): NUM holes on a line from
//!   (SPCA,SPCO) at STA1, the first FDIS from it, then every DBH.
//! * HOLES2(CPA,CPO,RAD,STA1,INDA,NUM): NUM holes on the circle about
//!   (CPA,CPO) of radius RAD (required), the first at STA1, then every
//!   INDA (0 or omitted: 360°/NUM).
//! * CYCLE801(SPCA,SPCO,STA,DIS1,DIS2,NUM1,NUM2): a grid of NUM2 rows of
//!   NUM1 holes; the first hole at (SPCA,SPCO), columns DIS1 apart along
//!   STA, rows DIS2 apart along STA + 90°. Order (*kernel*): a meander,
//!   the first row forward, the second backward, and so on.
//!
//! # CYCLE60 (not in the brief: the kernel's reading, UNVERIFIED)
//!
//! The brief has no parameter list for the engraving cycle, so the kernel
//! reads `CYCLE60(TEXT, RTP, RFP, SDIS, DP, DPR, PA, PO, CW, CH, ANG)`:
//! the text (a string, ASCII 32–126, at most 200 characters, the
//! SINUMERIK STRING length of brief §1), the levels as for drilling, the
//! reference point (PA, PO) in the plane (omitted: where the tool
//! stands), the width CW of a capital (omitted: in proportion to CH), the
//! height CH of capitals (required), and the angle ANG of the baseline.
//! The strokes are the kernel's single-stroke font (`controller/engrave/
//! font.rs`), scaled by CH / CAP_HEIGHT upwards and CW / GLYPH_WIDTH
//! along the baseline (the advance too), the first character's baseline
//! start at (PA, PO), turned by ANG about it. Steps: rapid to RFP+SDIS;
//! per stroke a rapid in the plane above its first point, a feed down to
//! the depth, feeds through its points, a rapid up to RFP+SDIS; at the
//! end a rapid to RTP. Every feed is at the feed in force. The real
//! CYCLE60 of SINUMERIK Operate has another, longer list; programs written
//! for it are not read correctly by this one.
//!
//! # Alarms
//!
//! 61101 is from the brief (§8, secondary source); the other numbers are
//! the kernel's choice in the cycle range 61xxx (brief §8), not checked
//! against a Siemens alarm list: [`ALARM_PITCH`] 61001,
//! [`ALARM_MACHINING_TYPE`] 61002, [`ALARM_OUT_OF_RANGE`] 61097,
//! [`ALARM_NOT_CARRIED_OUT`] 61098, [`ALARM_MISSING`] 61099.

use crate::controller::engrave::font::{self, ADVANCE, CAP_HEIGHT, GLYPH_WIDTH};
use crate::controller::{MAX_CYCLE_SEGMENTS, PECK_CLEARANCE};

/// Millimetres per inch (G70 / G700 arguments).
const MM_PER_INCH: f64 = 25.4;

/// Thread pitch wrongly defined (neither MPIT nor PIT, MPIT not a size of
/// the table). Kernel's choice of number.
pub(crate) const ALARM_PITCH: u32 = 61001;
/// Type of machining wrongly defined (VARI, SDIR, SDR, SDAC out of their
/// sets). Kernel's choice of number.
pub(crate) const ALARM_MACHINING_TYPE: u32 = 61002;
/// A value out of its range (counts, speeds, feeds, a CYCLE83 first depth
/// not below RFP, the text or its type, non-finite numbers, too many
/// steps). Kernel's choice of number.
pub(crate) const ALARM_OUT_OF_RANGE: u32 = 61097;
/// A parameter form the kernel does not carry out (negative DAM, later
/// Operate parameters, non-zero _AXN or CYCLE86 POSS, negative dwell).
/// Kernel's choice of number.
pub(crate) const ALARM_NOT_CARRIED_OUT: u32 = 61098;
/// A required parameter is missing. Kernel's choice of number.
pub(crate) const ALARM_MISSING: u32 = 61099;
/// Reference plane incorrectly defined (brief §8, from cnc.wiki).
pub(crate) const ALARM_REFERENCE_PLANE: u32 = 61101;

/// Most characters of a CYCLE60 text: the SINUMERIK STRING length (brief
/// §1, [840Di p62–63]).
pub(crate) const MAX_TEXT: usize = 200;

/// The elementary steps of a cycle, in programmed (workpiece) coordinates,
/// absolute, mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum CycleStep {
    /// Rapid to the given coordinates (X, Y, Z by index 0..3; None = stays).
    Rapid([Option<f64>; 3]),
    /// Feed move at `feed` mm/min for this step only (None: the feed in
    /// force, [`CycleContext::feed`]); the feed in force is not changed.
    Feed {
        /// End point (X, Y, Z; None = stays).
        to: [Option<f64>; 3],
        /// Feed of this step, mm/min.
        feed: Option<f64>,
    },
    /// Dwell, seconds.
    Dwell(f64),
    /// An M function (M5 spindle stop, M0 stop, M3/M4 spindle on, M19
    /// orient).
    M(u16),
    /// Spindle speed, rev/min (the tapping cycle's SST / SST1, and back to
    /// the speed in force).
    Speed(f64),
}

/// What the cycle needs to know of the controller's state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CycleContext {
    /// Indices of the plane's first axis, second axis and applicate (G17:
    /// `[0, 1, 2]`, G18: `[2, 0, 1]`, G19: `[1, 2, 0]`); a permutation of
    /// 0, 1, 2.
    pub plane: [usize; 3],
    /// Programmed X Y Z now, mm.
    pub position: [f64; 3],
    /// The feed in force, mm/min.
    pub feed: f64,
    /// The spindle speed in force, rev/min.
    pub spindle: f64,
    /// The spindle turns counterclockwise (M4).
    pub spindle_ccw: bool,
    /// G70 / G700: lengths in the arguments are inches.
    pub inch: bool,
}

/// A cycle call refused.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct CycleError {
    /// SINUMERIK cycle alarm number 61xxx.
    pub alarm: u32,
    /// 0-based index of the faulty argument.
    pub argument: Option<usize>,
    /// What is wrong, in words.
    pub message: String,
}

impl CycleError {
    fn new(alarm: u32, argument: Option<usize>, message: String) -> Self {
        CycleError {
            alarm,
            argument,
            message,
        }
    }
}

/// One argument of CYCLE60 (its first one is a string).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum CycleArg {
    /// A number.
    Number(f64),
    /// A string.
    Text(String),
    /// Left out (`,,`).
    Omitted,
}

/// Parameters of each cycle, in the manual's order (brief §7), as far as
/// the kernel reads them.
fn parameters(name: &str) -> Option<&'static [&'static str]> {
    const LEVELS: [&str; 5] = ["RTP", "RFP", "SDIS", "DP", "DPR"];
    Some(match name {
        "CYCLE81" => &LEVELS,
        "CYCLE82" => &["RTP", "RFP", "SDIS", "DP", "DPR", "DTB"],
        "CYCLE83" => &[
            "RTP", "RFP", "SDIS", "DP", "DPR", "FDEP", "FDPR", "DAM", "DTB", "DTS", "FRF", "VARI",
            "_AXN", "_MDEP", "_VRT", "_DTD", "_DIS1",
        ],
        "CYCLE84" => &[
            "RTP", "RFP", "SDIS", "DP", "DPR", "DTB", "SDAC", "MPIT", "PIT", "POSS", "SST", "SST1",
        ],
        "CYCLE840" => &[
            "RTP", "RFP", "SDIS", "DP", "DPR", "DTB", "SDR", "SDAC", "ENC", "MPIT", "PIT",
        ],
        "CYCLE85" => &["RTP", "RFP", "SDIS", "DP", "DPR", "DTB", "FFR", "RFF"],
        "CYCLE86" => &[
            "RTP", "RFP", "SDIS", "DP", "DPR", "DTB", "SDIR", "RPA", "RPO", "RPAP", "POSS",
        ],
        "CYCLE87" => &["RTP", "RFP", "SDIS", "DP", "DPR", "SDIR"],
        "CYCLE88" => &["RTP", "RFP", "SDIS", "DP", "DPR", "DTB", "SDIR"],
        "CYCLE89" => &["RTP", "RFP", "SDIS", "DP", "DPR", "DTB"],
        "HOLES1" => &["SPCA", "SPCO", "STA1", "FDIS", "DBH", "NUM"],
        "HOLES2" => &["CPA", "CPO", "RAD", "STA1", "INDA", "NUM"],
        "CYCLE801" => &["SPCA", "SPCO", "STA", "DIS1", "DIS2", "NUM1", "NUM2"],
        "CYCLE60" => &[
            "TEXT", "RTP", "RFP", "SDIS", "DP", "DPR", "PA", "PO", "CW", "CH", "ANG",
        ],
        _ => return None,
    })
}

/// Whether `name` (upper-cased) is a cycle this module carries out.
pub(crate) fn is_cycle(name: &str) -> bool {
    parameters(&name.to_ascii_uppercase()).is_some()
}

/// The ISO 261 coarse pitch of metric thread size `size` (M3 … M48, first
/// and second choice sizes), mm.
pub(crate) fn coarse_pitch(size: f64) -> Option<f64> {
    const TABLE: [(f64, f64); 21] = [
        (3.0, 0.5),
        (4.0, 0.7),
        (5.0, 0.8),
        (6.0, 1.0),
        (8.0, 1.25),
        (10.0, 1.5),
        (12.0, 1.75),
        (14.0, 2.0),
        (16.0, 2.0),
        (18.0, 2.5),
        (20.0, 2.5),
        (22.0, 2.5),
        (24.0, 3.0),
        (27.0, 3.0),
        (30.0, 3.5),
        (33.0, 3.5),
        (36.0, 4.0),
        (39.0, 4.0),
        (42.0, 4.5),
        (45.0, 4.5),
        (48.0, 5.0),
    ];
    TABLE.iter().find(|(s, _)| *s == size).map(|(_, p)| *p)
}

/// The arguments of one call, read by index.
struct Args<'a> {
    name: &'a str,
    params: &'static [&'static str],
    values: &'a [Option<f64>],
    inch: bool,
}

impl<'a> Args<'a> {
    /// Checks that every given value is finite and that arguments past
    /// `params` are omitted or 0.
    fn new(
        name: &'a str,
        params: &'static [&'static str],
        values: &'a [Option<f64>],
        inch: bool,
    ) -> Result<Self, CycleError> {
        for (i, v) in values.iter().enumerate() {
            let Some(v) = *v else { continue };
            if !v.is_finite() {
                return Err(CycleError::new(
                    ALARM_OUT_OF_RANGE,
                    Some(i),
                    format!("{name}: argument {} is not a finite number", i + 1),
                ));
            }
            if i >= params.len() && v != 0.0 {
                return Err(CycleError::new(
                    ALARM_NOT_CARRIED_OUT,
                    Some(i),
                    format!(
                        "{name}: argument {} (after {}) is not carried out; leave it out or 0",
                        i + 1,
                        params[params.len() - 1]
                    ),
                ));
            }
        }
        Ok(Args {
            name,
            params,
            values,
            inch,
        })
    }

    fn param(&self, i: usize) -> &'static str {
        self.params.get(i).copied().unwrap_or("?")
    }

    fn error(&self, alarm: u32, i: usize, what: &str) -> CycleError {
        CycleError::new(
            alarm,
            Some(i),
            format!("{}: {} {what}", self.name, self.param(i)),
        )
    }

    /// The value as written.
    fn value(&self, i: usize) -> Option<f64> {
        self.values.get(i).copied().flatten()
    }

    /// The value, 0 read as omitted.
    fn nonzero(&self, i: usize) -> Option<f64> {
        self.value(i).filter(|v| *v != 0.0)
    }

    /// A length, mm.
    fn length(&self, i: usize) -> Option<f64> {
        self.value(i)
            .map(|v| if self.inch { v * MM_PER_INCH } else { v })
    }

    /// A length, 0 read as omitted; negative refused.
    fn positive_length(&self, i: usize) -> Result<Option<f64>, CycleError> {
        match self.length(i) {
            Some(v) if v < 0.0 => Err(self.error(
                ALARM_NOT_CARRIED_OUT,
                i,
                "negative: this form is not carried out",
            )),
            Some(v) if v > 0.0 => Ok(Some(v)),
            _ => Ok(None),
        }
    }

    fn required_length(&self, i: usize) -> Result<f64, CycleError> {
        self.length(i)
            .ok_or_else(|| self.error(ALARM_MISSING, i, "is missing"))
    }

    /// A dwell, seconds (0 when omitted).
    fn dwell(&self, i: usize) -> Result<f64, CycleError> {
        match self.value(i) {
            Some(t) if t < 0.0 => Err(self.error(
                ALARM_NOT_CARRIED_OUT,
                i,
                "negative dwell is not carried out",
            )),
            t => Ok(t.unwrap_or(0.0)),
        }
    }

    /// A spindle direction 3 / 4 (and 5 when `stop`); omitted or 0: the
    /// direction in force.
    fn spindle(&self, i: usize, ctx: &CycleContext, stop: bool) -> Result<u16, CycleError> {
        match self.nonzero(i) {
            None => Ok(in_force(ctx)),
            Some(3.0) => Ok(3),
            Some(4.0) => Ok(4),
            Some(5.0) if stop => Ok(5),
            Some(_) => Err(self.error(
                ALARM_MACHINING_TYPE,
                i,
                if stop {
                    "must be 3, 4 or 5"
                } else {
                    "must be 3 or 4"
                },
            )),
        }
    }

    /// A feed, mm/min; omitted or 0: None.
    fn feed(&self, i: usize) -> Result<Option<f64>, CycleError> {
        match self.nonzero(i) {
            Some(f) if f < 0.0 => Err(self.error(ALARM_OUT_OF_RANGE, i, "must not be negative")),
            f => Ok(f),
        }
    }

    /// A count of holes: a whole number ≥ 1.
    fn count(&self, i: usize) -> Result<usize, CycleError> {
        let n = self
            .value(i)
            .ok_or_else(|| self.error(ALARM_MISSING, i, "is missing"))?;
        if n < 1.0 || n.fract() != 0.0 || n > MAX_CYCLE_SEGMENTS as f64 {
            return Err(self.error(
                ALARM_OUT_OF_RANGE,
                i,
                &format!("must be a whole number from 1 to {MAX_CYCLE_SEGMENTS}"),
            ));
        }
        Ok(n as usize)
    }

    /// The signed pitch, mm (negative: left hand), from PIT or MPIT.
    fn pitch(&self, mpit: usize, pit: usize) -> Result<Option<f64>, CycleError> {
        if let Some(p) = self.length(pit).filter(|p| *p != 0.0) {
            return Ok(Some(p));
        }
        match self.nonzero(mpit) {
            None => Ok(None),
            Some(m) => coarse_pitch(m.abs())
                .map(|p| Some(p.copysign(m)))
                .ok_or_else(|| {
                    self.error(
                        ALARM_PITCH,
                        mpit,
                        "is not a metric coarse thread size (3 … 48, ISO 261)",
                    )
                }),
        }
    }
}

/// M3 or M4, the spindle direction in force.
fn in_force(ctx: &CycleContext) -> u16 {
    if ctx.spindle_ccw { 4 } else { 3 }
}

/// The levels of a drilling cycle (or CYCLE60) on the applicate, mm.
#[derive(Clone, Copy, Debug)]
struct Levels {
    rtp: f64,
    rfp: f64,
    /// RFP + SDIS.
    safe: f64,
    /// Final depth.
    depth: f64,
}

/// Reads RTP, RFP, SDIS, DP, DPR from `base` on.
fn levels(a: &Args<'_>, base: usize) -> Result<Levels, CycleError> {
    let rtp = a.required_length(base)?;
    let rfp = a.length(base + 1).unwrap_or(0.0);
    let safe = rfp + a.length(base + 2).unwrap_or(0.0).abs();
    let depth = match (a.length(base + 3), a.length(base + 4)) {
        (Some(dp), _) => dp,
        (None, Some(dpr)) => rfp - dpr.abs(),
        (None, None) => {
            return Err(CycleError::new(
                ALARM_MISSING,
                Some(base + 3),
                format!("{}: no final depth (DP or DPR)", a.name),
            ));
        }
    };
    if depth >= safe {
        return Err(a.error(
            ALARM_REFERENCE_PLANE,
            base + 1,
            "incorrectly defined: RFP + SDIS is not above the final depth",
        ));
    }
    if rtp < rfp {
        return Err(a.error(
            ALARM_REFERENCE_PLANE,
            base,
            "is below the reference plane RFP",
        ));
    }
    Ok(Levels {
        rtp,
        rfp,
        safe,
        depth,
    })
}

/// Coordinates with only axis `i` set.
fn on(i: usize, v: f64) -> [Option<f64>; 3] {
    let mut to = [None; 3];
    to[i] = Some(v);
    to
}

/// Coordinates with the plane's two axes set.
fn in_plane(ctx: &CycleContext, p: [f64; 2]) -> [Option<f64>; 3] {
    let mut to = [None; 3];
    to[ctx.plane[0]] = Some(p[0]);
    to[ctx.plane[1]] = Some(p[1]);
    to
}

/// Pushes the steps of one cycle; the applicate is `ax`.
struct Steps<'o> {
    out: &'o mut Vec<CycleStep>,
    ax: usize,
}

impl Steps<'_> {
    fn rapid(&mut self, v: f64) {
        self.out.push(CycleStep::Rapid(on(self.ax, v)));
    }
    fn feed(&mut self, v: f64, feed: Option<f64>) {
        self.out.push(CycleStep::Feed {
            to: on(self.ax, v),
            feed,
        });
    }
    fn dwell(&mut self, t: f64) {
        if t > 0.0 {
            self.out.push(CycleStep::Dwell(t));
        }
    }
    fn m(&mut self, m: u16) {
        self.out.push(CycleStep::M(m));
    }
}

/// The steps of drilling cycle `name` (CYCLE81…CYCLE89, CYCLE840) at the
/// current position. `args[i]` is the i-th argument, None when omitted.
/// On an error `out` is left as it was.
pub(crate) fn drilling(
    name: &str,
    args: &[Option<f64>],
    ctx: &CycleContext,
    out: &mut Vec<CycleStep>,
) -> Result<(), CycleError> {
    let start = out.len();
    let result = drill(&name.to_ascii_uppercase(), args, ctx, out);
    if result.is_err() {
        out.truncate(start);
    }
    result
}

fn drill(
    name: &str,
    args: &[Option<f64>],
    ctx: &CycleContext,
    out: &mut Vec<CycleStep>,
) -> Result<(), CycleError> {
    let params = match name {
        "CYCLE81" | "CYCLE82" | "CYCLE83" | "CYCLE84" | "CYCLE840" | "CYCLE85" | "CYCLE86"
        | "CYCLE87" | "CYCLE88" | "CYCLE89" => parameters(name).unwrap_or(&[]),
        _ => {
            return Err(CycleError::new(
                ALARM_NOT_CARRIED_OUT,
                None,
                format!("{name} is not a drilling cycle"),
            ));
        }
    };
    let a = Args::new(name, params, args, ctx.inch)?;
    let lv = levels(&a, 0)?;
    let mut s = Steps {
        out,
        ax: ctx.plane[2],
    };
    match name {
        "CYCLE81" | "CYCLE82" => {
            let dtb = a.dwell(5)?;
            s.rapid(lv.safe);
            s.feed(lv.depth, None);
            s.dwell(dtb);
            s.rapid(lv.rtp);
        }
        "CYCLE83" => cycle83(&a, &lv, ctx, &mut s)?,
        "CYCLE84" => cycle84(&a, &lv, ctx, &mut s)?,
        "CYCLE840" => {
            let dtb = a.dwell(5)?;
            let sdr = match a.nonzero(6) {
                None => 7 - in_force(ctx),
                Some(_) => a.spindle(6, ctx, false)?,
            };
            let sdac = a.spindle(7, ctx, true)?;
            let feed = match a.pitch(9, 10)? {
                None => None,
                Some(p) => Some(p.abs() * speed(&a, ctx.spindle, None)?),
            };
            s.rapid(lv.safe);
            s.feed(lv.depth, feed);
            s.dwell(dtb);
            s.m(sdr);
            s.feed(lv.safe, feed);
            s.m(sdac);
            s.rapid(lv.rtp);
        }
        "CYCLE85" => {
            let dtb = a.dwell(5)?;
            let ffr = a.feed(6)?;
            let rff = a.feed(7)?.or(ffr);
            s.rapid(lv.safe);
            s.feed(lv.depth, ffr);
            s.dwell(dtb);
            s.feed(lv.safe, rff);
            s.rapid(lv.rtp);
        }
        "CYCLE86" => {
            let dtb = a.dwell(5)?;
            let sdir = a.spindle(6, ctx, false)?;
            let rpa = a.length(7).unwrap_or(0.0);
            let rpo = a.length(8).unwrap_or(0.0);
            let rpap = a.length(9).unwrap_or(0.0);
            if a.nonzero(10).is_some() {
                return Err(a.error(
                    ALARM_NOT_CARRIED_OUT,
                    10,
                    "(orientation angle) is not carried out; leave it out or 0",
                ));
            }
            let [first, second, _] = ctx.plane;
            let hole = [ctx.position[first], ctx.position[second]];
            s.rapid(lv.safe);
            s.feed(lv.depth, None);
            s.dwell(dtb);
            s.m(5);
            s.m(19);
            let mut lift = [None; 3];
            if rpa != 0.0 {
                lift[first] = Some(hole[0] + rpa);
            }
            if rpo != 0.0 {
                lift[second] = Some(hole[1] + rpo);
            }
            if rpap != 0.0 {
                lift[s.ax] = Some(lv.depth + rpap);
            }
            if lift != [None; 3] {
                s.out.push(CycleStep::Rapid(lift));
            }
            s.rapid(lv.safe);
            if rpa != 0.0 || rpo != 0.0 {
                s.out.push(CycleStep::Rapid(in_plane(ctx, hole)));
            }
            s.rapid(lv.rtp);
            s.m(sdir);
        }
        "CYCLE87" | "CYCLE88" => {
            let (dtb, sdir) = if name == "CYCLE87" {
                (0.0, a.spindle(5, ctx, false)?)
            } else {
                (a.dwell(5)?, a.spindle(6, ctx, false)?)
            };
            s.rapid(lv.safe);
            s.feed(lv.depth, None);
            s.dwell(dtb);
            s.m(5);
            s.m(0);
            s.rapid(lv.rtp);
            s.m(sdir);
        }
        _ => {
            // CYCLE89
            let dtb = a.dwell(5)?;
            s.rapid(lv.safe);
            s.feed(lv.depth, None);
            s.dwell(dtb);
            s.feed(lv.safe, None);
            s.rapid(lv.rtp);
        }
    }
    Ok(())
}

/// A spindle speed: argument `i` (omitted or 0: `default`), which must be
/// positive.
fn speed(a: &Args<'_>, default: f64, i: Option<usize>) -> Result<f64, CycleError> {
    let v = i.and_then(|i| a.nonzero(i)).unwrap_or(default);
    if v > 0.0 {
        Ok(v)
    } else {
        Err(CycleError::new(
            ALARM_OUT_OF_RANGE,
            i,
            format!("{}: no spindle speed for tapping", a.name),
        ))
    }
}

/// CYCLE83, deep-hole drilling.
fn cycle83(
    a: &Args<'_>,
    lv: &Levels,
    ctx: &CycleContext,
    s: &mut Steps<'_>,
) -> Result<(), CycleError> {
    let (first, first_i) = match (a.length(5), a.length(6)) {
        (Some(f), _) => (f, 5),
        (None, Some(r)) => (lv.rfp - r.abs(), 6),
        (None, None) => {
            return Err(CycleError::new(
                ALARM_MISSING,
                Some(5),
                "CYCLE83: no first drilling depth (FDEP or FDPR)".into(),
            ));
        }
    };
    if first >= lv.rfp {
        return Err(a.error(
            ALARM_OUT_OF_RANGE,
            first_i,
            "does not lie below the reference plane RFP",
        ));
    }
    let first = first.max(lv.depth);
    let dam = a.positive_length(7)?.unwrap_or(0.0);
    let dtb = a.dwell(8)?;
    let dts = a.dwell(9)?;
    let frf = match a.nonzero(10) {
        None => 1.0,
        Some(f) if f > 0.0 => f,
        Some(_) => return Err(a.error(ALARM_OUT_OF_RANGE, 10, "must be positive")),
    };
    let chip_removal = match a.value(11).unwrap_or(0.0) {
        0.0 => false,
        1.0 => true,
        _ => return Err(a.error(ALARM_MACHINING_TYPE, 11, "must be 0 or 1")),
    };
    if a.nonzero(12).is_some() {
        return Err(a.error(
            ALARM_NOT_CARRIED_OUT,
            12,
            "(another drilling axis) is not carried out; leave it out or 0",
        ));
    }
    let mdep = a.positive_length(13)?.unwrap_or(dam);
    let vrt = a.positive_length(14)?.unwrap_or(1.0);
    let dtd = match a.dwell(15)? {
        0.0 => dtb,
        t => t,
    };
    let dis1 = a.positive_length(16)?.unwrap_or(PECK_CLEARANCE);

    let start = s.out.len();
    s.rapid(lv.safe);
    s.feed(first, (frf != 1.0).then_some(ctx.feed * frf));
    let mut reached = first;
    let mut peck = lv.rfp - first;
    while reached > lv.depth {
        if s.out.len() - start > MAX_CYCLE_SEGMENTS {
            return Err(CycleError::new(
                ALARM_OUT_OF_RANGE,
                Some(7),
                format!("CYCLE83: more than {MAX_CYCLE_SEGMENTS} steps (pecks too small)"),
            ));
        }
        s.dwell(dtb);
        peck = (peck - dam).max(mdep);
        let next = (reached - peck).max(lv.depth);
        if chip_removal {
            s.rapid(lv.safe);
            s.dwell(dts);
            let back = reached + dis1;
            if back < lv.safe {
                s.rapid(back);
            }
        } else {
            s.rapid((reached + vrt).min(lv.safe));
        }
        s.feed(next, None);
        reached = next;
    }
    s.dwell(dtd);
    s.rapid(lv.rtp);
    Ok(())
}

/// CYCLE84, rigid tapping.
fn cycle84(
    a: &Args<'_>,
    lv: &Levels,
    ctx: &CycleContext,
    s: &mut Steps<'_>,
) -> Result<(), CycleError> {
    let dtb = a.dwell(5)?;
    let sdac = a.spindle(6, ctx, true)?;
    let pitch = a.pitch(7, 8)?.ok_or_else(|| {
        CycleError::new(
            ALARM_PITCH,
            Some(7),
            "CYCLE84: no thread pitch (MPIT or PIT)".into(),
        )
    })?;
    // POSS (9) is read and ignored.
    let sst = speed(a, ctx.spindle, Some(10))?;
    let sst1 = speed(a, sst, Some(11))?;
    let (into, out_of) = if pitch > 0.0 { (3, 4) } else { (4, 3) };
    s.rapid(lv.safe);
    if sst != ctx.spindle {
        s.out.push(CycleStep::Speed(sst));
    }
    s.m(into);
    s.feed(lv.depth, Some(pitch.abs() * sst));
    s.dwell(dtb);
    if sst1 != sst {
        s.out.push(CycleStep::Speed(sst1));
    }
    s.m(out_of);
    s.feed(lv.safe, Some(pitch.abs() * sst1));
    if sst1 != ctx.spindle {
        s.out.push(CycleStep::Speed(ctx.spindle));
    }
    s.m(sdac);
    s.rapid(lv.rtp);
    Ok(())
}

/// A point `d` from `p` at `angle` degrees (from the first axis towards
/// the second).
fn polar(p: [f64; 2], d: f64, angle: f64) -> [f64; 2] {
    let (sin, cos) = sin_cos(angle);
    [p[0] + d * cos, p[1] + d * sin]
}

/// Sine and cosine of `angle` degrees, exact at multiples of 90°.
fn sin_cos(angle: f64) -> (f64, f64) {
    match angle.rem_euclid(360.0) {
        0.0 => (0.0, 1.0),
        90.0 => (1.0, 0.0),
        180.0 => (0.0, -1.0),
        270.0 => (-1.0, 0.0),
        _ => angle.to_radians().sin_cos(),
    }
}

/// The hole positions of pattern cycle `name` (HOLES1, HOLES2, CYCLE801)
/// in the plane (first, second axis), in order. On an error `out` is left
/// as it was.
pub(crate) fn pattern(
    name: &str,
    args: &[Option<f64>],
    ctx: &CycleContext,
    out: &mut Vec<[f64; 2]>,
) -> Result<(), CycleError> {
    let name = name.to_ascii_uppercase();
    let params = match name.as_str() {
        "HOLES1" | "HOLES2" | "CYCLE801" => parameters(&name).unwrap_or(&[]),
        _ => {
            return Err(CycleError::new(
                ALARM_NOT_CARRIED_OUT,
                None,
                format!("{name} is not a pattern cycle"),
            ));
        }
    };
    let a = Args::new(&name, params, args, ctx.inch)?;
    let reference = [a.length(0).unwrap_or(0.0), a.length(1).unwrap_or(0.0)];
    let spacing = |i: usize, count: usize| -> Result<f64, CycleError> {
        match a.length(i) {
            Some(d) => Ok(d),
            None if count == 1 => Ok(0.0),
            None => Err(a.error(ALARM_MISSING, i, "is missing")),
        }
    };
    match name.as_str() {
        "HOLES1" => {
            let sta = a.value(2).unwrap_or(0.0);
            let fdis = a.length(3).unwrap_or(0.0);
            let num = a.count(5)?;
            let dbh = spacing(4, num)?;
            out.extend((0..num).map(|i| polar(reference, fdis + i as f64 * dbh, sta)));
        }
        "HOLES2" => {
            let rad = a.required_length(2)?;
            let sta = a.value(3).unwrap_or(0.0);
            let num = a.count(5)?;
            let inda = a.nonzero(4).unwrap_or(360.0 / num as f64);
            out.extend((0..num).map(|i| polar(reference, rad, sta + i as f64 * inda)));
        }
        _ => {
            // CYCLE801
            let sta = a.value(2).unwrap_or(0.0);
            let num1 = a.count(5)?;
            let num2 = a.count(6)?;
            if num1 * num2 > MAX_CYCLE_SEGMENTS {
                return Err(a.error(
                    ALARM_OUT_OF_RANGE,
                    6,
                    &format!("× NUM1: more than {MAX_CYCLE_SEGMENTS} holes"),
                ));
            }
            let dis1 = spacing(3, num1)?;
            let dis2 = spacing(4, num2)?;
            let (sin, cos) = sin_cos(sta);
            for row in 0..num2 {
                let v = row as f64 * dis2;
                for k in 0..num1 {
                    let column = if row % 2 == 0 { k } else { num1 - 1 - k };
                    let u = column as f64 * dis1;
                    out.push([
                        reference[0] + u * cos - v * sin,
                        reference[1] + u * sin + v * cos,
                    ]);
                }
            }
        }
    }
    Ok(())
}

/// The steps of engraving cycle CYCLE60 (the kernel's reading, see the
/// module's documentation): `CYCLE60(TEXT, RTP, RFP, SDIS, DP, DPR, PA,
/// PO, CW, CH, ANG)`. On an error `out` is left as it was.
pub(crate) fn engrave(
    args: &[CycleArg],
    ctx: &CycleContext,
    out: &mut Vec<CycleStep>,
) -> Result<(), CycleError> {
    const NAME: &str = "CYCLE60";
    let params = parameters(NAME).unwrap_or(&[]);
    let text = match args.first() {
        Some(CycleArg::Text(t)) => t.as_str(),
        Some(CycleArg::Number(_)) => {
            return Err(CycleError::new(
                ALARM_OUT_OF_RANGE,
                Some(0),
                "CYCLE60: TEXT must be a string".into(),
            ));
        }
        _ => {
            return Err(CycleError::new(
                ALARM_MISSING,
                Some(0),
                "CYCLE60: TEXT is missing".into(),
            ));
        }
    };
    let mut numbers = vec![None];
    for (i, arg) in args.iter().enumerate().skip(1) {
        numbers.push(match arg {
            CycleArg::Number(v) => Some(*v),
            CycleArg::Omitted => None,
            CycleArg::Text(_) => {
                return Err(CycleError::new(
                    ALARM_OUT_OF_RANGE,
                    Some(i),
                    format!(
                        "CYCLE60: {} must be a number",
                        params.get(i).copied().unwrap_or("argument")
                    ),
                ));
            }
        });
    }
    let a = Args::new(NAME, params, &numbers, ctx.inch)?;
    if text.is_empty() || text.chars().count() > MAX_TEXT {
        return Err(a.error(
            ALARM_OUT_OF_RANGE,
            0,
            &format!("must have 1 to {MAX_TEXT} characters"),
        ));
    }
    let lv = levels(&a, 1)?;
    let [first, second, ax] = ctx.plane;
    let pa = a.length(6).unwrap_or(ctx.position[first]);
    let po = a.length(7).unwrap_or(ctx.position[second]);
    let ch = a.required_length(9)?;
    if ch <= 0.0 {
        return Err(a.error(ALARM_OUT_OF_RANGE, 9, "must be positive"));
    }
    let sy = ch / f64::from(CAP_HEIGHT);
    let sx = match a.length(8) {
        None => sy,
        Some(cw) if cw > 0.0 => cw / f64::from(GLYPH_WIDTH),
        Some(_) => return Err(a.error(ALARM_OUT_OF_RANGE, 8, "must be positive")),
    };
    let (sin, cos) = sin_cos(a.value(10).unwrap_or(0.0));
    let place = |x: f64, y: f64| [pa + x * cos - y * sin, po + x * sin + y * cos];

    let mut steps = Vec::new();
    steps.push(CycleStep::Rapid(on(ax, lv.safe)));
    for (k, c) in text.chars().enumerate() {
        let glyph = u8::try_from(c).ok().and_then(font::glyph).ok_or_else(|| {
            a.error(
                ALARM_OUT_OF_RANGE,
                0,
                &format!("has {c:?}, which the font does not have (ASCII 32 … 126 only)"),
            )
        })?;
        let origin = k as f64 * f64::from(ADVANCE) * sx;
        for stroke in glyph {
            let mut points = stroke
                .points()
                .map(|(x, y)| place(origin + f64::from(x) * sx, f64::from(y) * sy));
            let Some(p0) = points.next() else { continue };
            steps.push(CycleStep::Rapid(in_plane(ctx, p0)));
            steps.push(CycleStep::Feed {
                to: on(ax, lv.depth),
                feed: None,
            });
            steps.extend(points.map(|p| CycleStep::Feed {
                to: in_plane(ctx, p),
                feed: None,
            }));
            steps.push(CycleStep::Rapid(on(ax, lv.safe)));
        }
    }
    steps.push(CycleStep::Rapid(on(ax, lv.rtp)));
    out.extend(steps);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const G17: [usize; 3] = [0, 1, 2];
    const G18: [usize; 3] = [2, 0, 1];
    const G19: [usize; 3] = [1, 2, 0];

    /// At X10 Y20 Z50, F100, S1000 M3, metric.
    fn ctx(plane: [usize; 3]) -> CycleContext {
        CycleContext {
            plane,
            position: [10.0, 20.0, 50.0],
            feed: 100.0,
            spindle: 1000.0,
            spindle_ccw: false,
            inch: false,
        }
    }

    /// Arguments as written between the parentheses: `"10,,2,-15"`.
    fn args(text: &str) -> Vec<Option<f64>> {
        text.split(',')
            .map(|a| {
                let a = a.trim();
                (!a.is_empty()).then(|| a.parse().expect("a number"))
            })
            .collect()
    }

    fn run_in(name: &str, text: &str, c: &CycleContext) -> Vec<CycleStep> {
        let mut out = Vec::new();
        drilling(name, &args(text), c, &mut out).expect("the cycle runs");
        out
    }

    fn run(name: &str, text: &str) -> Vec<CycleStep> {
        run_in(name, text, &ctx(G17))
    }

    fn fail(name: &str, text: &str) -> CycleError {
        let mut out = vec![CycleStep::M(8)];
        let e = drilling(name, &args(text), &ctx(G17), &mut out).expect_err("refused");
        assert_eq!(out, [CycleStep::M(8)], "out is left as it was");
        e
    }

    fn rz(v: f64) -> CycleStep {
        CycleStep::Rapid([None, None, Some(v)])
    }
    fn fz(v: f64) -> CycleStep {
        CycleStep::Feed {
            to: [None, None, Some(v)],
            feed: None,
        }
    }
    fn fzf(v: f64, f: f64) -> CycleStep {
        CycleStep::Feed {
            to: [None, None, Some(v)],
            feed: Some(f),
        }
    }
    use CycleStep::{Dwell, M, Speed};

    #[test]
    fn names() {
        for n in [
            "CYCLE81", "cycle82", "CYCLE83", "CYCLE84", "CYCLE840", "CYCLE85", "CYCLE86",
            "CYCLE87", "CYCLE88", "CYCLE89", "HOLES1", "HOLES2", "CYCLE801", "CYCLE60",
        ] {
            assert!(is_cycle(n), "{n}");
        }
        for n in ["CYCLE800", "CYCLE832", "POCKET1", "CYCLE8", "CYCLE95", ""] {
            assert!(!is_cycle(n), "{n}");
        }
    }

    #[test]
    fn cycle81_drills_at_the_feed_in_force() {
        assert_eq!(run("CYCLE81", "10,0,2,-15"), [rz(2.0), fz(-15.0), rz(10.0)]);
        // The brief's real-program call: RFP left out is 0, DPR 0 with DP.
        assert_eq!(run("CYCLE81", "5,,3,-15,0"), [rz(3.0), fz(-15.0), rz(5.0)]);
        // Lower-case name.
        assert_eq!(run("cycle81", "10,0,2,-15"), [rz(2.0), fz(-15.0), rz(10.0)]);
        // Later Operate parameters left out or 0 are fine.
        assert_eq!(
            run("CYCLE81", "10,0,2,-15,,0,,0"),
            [rz(2.0), fz(-15.0), rz(10.0)]
        );
    }

    #[test]
    fn dpr_is_below_rfp_and_dp_wins() {
        let want = [rz(7.0), fz(-10.0), rz(10.0)];
        assert_eq!(run("CYCLE81", "10,5,2,,15"), want);
        assert_eq!(run("CYCLE81", "10,5,2,,-15"), want, "DPR's sign ignored");
        assert_eq!(run("CYCLE81", "10,5,2,-10,3"), want, "DP wins over DPR");
        // SDIS without its sign.
        assert_eq!(run("CYCLE81", "10,5,-2,-10"), want);
    }

    #[test]
    fn the_applicate_follows_the_plane() {
        // G18: the applicate is Y.
        assert_eq!(
            run_in("CYCLE81", "10,0,2,-15", &ctx(G18)),
            [
                CycleStep::Rapid([None, Some(2.0), None]),
                CycleStep::Feed {
                    to: [None, Some(-15.0), None],
                    feed: None
                },
                CycleStep::Rapid([None, Some(10.0), None]),
            ]
        );
        // G19: the applicate is X.
        assert_eq!(
            run_in("CYCLE82", "10,0,2,-15,,1", &ctx(G19)),
            [
                CycleStep::Rapid([Some(2.0), None, None]),
                CycleStep::Feed {
                    to: [Some(-15.0), None, None],
                    feed: None
                },
                Dwell(1.0),
                CycleStep::Rapid([Some(10.0), None, None]),
            ]
        );
    }

    #[test]
    fn cycle82_dwells_at_depth() {
        assert_eq!(
            run("CYCLE82", "10,0,2,-15,,1.5"),
            [rz(2.0), fz(-15.0), Dwell(1.5), rz(10.0)]
        );
        assert_eq!(run("CYCLE82", "10,0,2,-15"), [rz(2.0), fz(-15.0), rz(10.0)]);
    }

    #[test]
    fn inch_arguments_are_converted() {
        let mut c = ctx(G17);
        c.inch = true;
        assert_eq!(
            run_in("CYCLE81", "1,0,0.25,-0.5", &c),
            [rz(6.35), fz(-12.7), rz(25.4)]
        );
        // The pitch too (1/16 in).
        let feed = 0.0625 * 25.4 * 1000.0;
        assert_eq!(
            run_in("CYCLE84", "1,0,0.25,-0.5,,,,,0.0625", &c),
            [
                rz(6.35),
                M(3),
                fzf(-12.7, feed),
                M(4),
                fzf(6.35, feed),
                M(3),
                rz(25.4)
            ]
        );
    }

    #[test]
    fn cycle83_chip_breaking_with_degression() {
        // First depth -5, DAM 1, _MDEP = DAM: pecks 5, 4, 3, 2, then 1
        // left; retract 1 mm (_VRT default) after each.
        assert_eq!(
            run("CYCLE83", "50,0,2,-15,,-5,,1,,,,0"),
            [
                rz(2.0),
                fz(-5.0),
                rz(-4.0),
                fz(-9.0),
                rz(-8.0),
                fz(-12.0),
                rz(-11.0),
                fz(-14.0),
                rz(-13.0),
                fz(-15.0),
                rz(50.0),
            ]
        );
        // _MDEP 2, _VRT 0.5, DTB 0.25: pecks 5 4 3 2 2 2 2 to -20.
        let s = run("CYCLE83", "50,0,2,-20,,-5,,1,0.25,,,0,,2,0.5");
        let mut want = vec![rz(2.0), fz(-5.0)];
        for (from, to) in [(-5.0, -9.0), (-9.0, -12.0), (-12.0, -14.0), (-14.0, -16.0)] {
            want.extend([Dwell(0.25), rz(from + 0.5), fz(to)]);
        }
        for (from, to) in [(-16.0, -18.0), (-18.0, -20.0)] {
            want.extend([Dwell(0.25), rz(from + 0.5), fz(to)]);
        }
        want.extend([Dwell(0.25), rz(50.0)]);
        assert_eq!(s, want);
    }

    #[test]
    fn cycle83_chip_removal() {
        // FDPR 5 at F100 × FRF 0.5; DAM 2 (_MDEP = 2): pecks 5, 3, 2, 2;
        // DTB 0.5, DTS 1, _DTD 2, _DIS1 0.3.
        assert_eq!(
            run("CYCLE83", "50,0,2,-12,,,5,2,0.5,1,0.5,1,,,,2,0.3"),
            [
                rz(2.0),
                fzf(-5.0, 50.0),
                Dwell(0.5),
                rz(2.0),
                Dwell(1.0),
                rz(-4.7),
                fz(-8.0),
                Dwell(0.5),
                rz(2.0),
                Dwell(1.0),
                rz(-7.7),
                fz(-10.0),
                Dwell(0.5),
                rz(2.0),
                Dwell(1.0),
                rz(-9.7),
                fz(-12.0),
                Dwell(2.0),
                rz(50.0),
            ]
        );
        // _DIS1 automatic: PECK_CLEARANCE; constant pecks without DAM.
        assert_eq!(
            run("CYCLE83", "50,0,2,-8,,-4,,,,,,1"),
            [
                rz(2.0),
                fz(-4.0),
                rz(2.0),
                rz(-4.0 + PECK_CLEARANCE),
                fz(-8.0),
                rz(50.0)
            ]
        );
        // A first depth past the final depth is one peck.
        assert_eq!(
            run("CYCLE83", "50,0,2,-8,,-20,,,,,,1"),
            [rz(2.0), fz(-8.0), rz(50.0)]
        );
    }

    #[test]
    fn cycle83_refusals() {
        let e = fail("CYCLE83", "50,0,2,-15,,,,1,,,,0");
        assert_eq!((e.alarm, e.argument), (ALARM_MISSING, Some(5)));
        let e = fail("CYCLE83", "50,0,2,-15,,-5,,-10,,,,0");
        assert_eq!((e.alarm, e.argument), (ALARM_NOT_CARRIED_OUT, Some(7)));
        assert!(e.message.contains("DAM"), "{}", e.message);
        let e = fail("CYCLE83", "50,0,2,-15,,-5,,1,,,,2");
        assert_eq!((e.alarm, e.argument), (ALARM_MACHINING_TYPE, Some(11)));
        let e = fail("CYCLE83", "50,0,2,-15,,-5,,1,,,,0,3");
        assert_eq!((e.alarm, e.argument), (ALARM_NOT_CARRIED_OUT, Some(12)));
        let e = fail("CYCLE83", "50,0,2,-15,,5,,1,,,,0");
        assert_eq!((e.alarm, e.argument), (ALARM_OUT_OF_RANGE, Some(5)));
        let e = fail("CYCLE83", "50,0,2,-15,,-5,,1,-1,,,0");
        assert_eq!((e.alarm, e.argument), (ALARM_NOT_CARRIED_OUT, Some(8)));
        // Pecks of a micrometre: too many steps.
        let e = fail("CYCLE83", "50,0,2,-100,,-0.000001,,,,,,0");
        assert_eq!(e.alarm, ALARM_OUT_OF_RANGE);
    }

    #[test]
    fn cycle84_rigid_tapping() {
        // MPIT 8: M8 coarse, 1.25 mm at S1000.
        assert_eq!(
            run("CYCLE84", "10,0,2,-15,,0.5,3,8"),
            [
                rz(2.0),
                M(3),
                fzf(-15.0, 1250.0),
                Dwell(0.5),
                M(4),
                fzf(2.0, 1250.0),
                M(3),
                rz(10.0)
            ]
        );
        // Left-hand M10 (1.5), SST 500 in, SST1 800 out, spindle off after.
        assert_eq!(
            run("CYCLE84", "10,0,2,-15,,,5,-10,,,500,800"),
            [
                rz(2.0),
                Speed(500.0),
                M(4),
                fzf(-15.0, 750.0),
                Speed(800.0),
                M(3),
                fzf(2.0, 1200.0),
                Speed(1000.0),
                M(5),
                rz(10.0)
            ]
        );
        // PIT 1.5 (wins over MPIT), SDAC left out: the direction in force;
        // POSS is ignored.
        let mut c = ctx(G17);
        c.spindle_ccw = true;
        assert_eq!(
            run_in("CYCLE84", "10,0,2,-15,,,,6,1.5,90", &c),
            [
                rz(2.0),
                M(3),
                fzf(-15.0, 1500.0),
                M(4),
                fzf(2.0, 1500.0),
                M(4),
                rz(10.0)
            ]
        );
    }

    #[test]
    fn cycle84_refusals() {
        let e = fail("CYCLE84", "10,0,2,-15,,,3");
        assert_eq!((e.alarm, e.argument), (ALARM_PITCH, Some(7)));
        let e = fail("CYCLE84", "10,0,2,-15,,,3,7");
        assert_eq!((e.alarm, e.argument), (ALARM_PITCH, Some(7)));
        let e = fail("CYCLE84", "10,0,2,-15,,,6,8");
        assert_eq!((e.alarm, e.argument), (ALARM_MACHINING_TYPE, Some(6)));
        let e = fail("CYCLE84", "10,0,2,-15,,,3,8,,,,,1");
        assert_eq!((e.alarm, e.argument), (ALARM_NOT_CARRIED_OUT, Some(12)));
        let mut c = ctx(G17);
        c.spindle = 0.0;
        let e = drilling("CYCLE84", &args("10,0,2,-15,,,3,8"), &c, &mut Vec::new())
            .expect_err("no speed");
        assert_eq!((e.alarm, e.argument), (ALARM_OUT_OF_RANGE, Some(10)));
    }

    #[test]
    fn coarse_pitches() {
        assert_eq!(coarse_pitch(3.0), Some(0.5));
        assert_eq!(coarse_pitch(12.0), Some(1.75));
        assert_eq!(coarse_pitch(48.0), Some(5.0));
        assert_eq!(coarse_pitch(7.0), None);
        assert_eq!(coarse_pitch(2.0), None);
    }

    #[test]
    fn cycle840_compensating_chuck() {
        // MPIT 6 (1 mm) at S1000; SDR left out: reverse of M3; SDAC: M3.
        assert_eq!(
            run("CYCLE840", "10,0,2,-15,,1,,,,6"),
            [
                rz(2.0),
                fzf(-15.0, 1000.0),
                Dwell(1.0),
                M(4),
                fzf(2.0, 1000.0),
                M(3),
                rz(10.0)
            ]
        );
        // No lead: the feed in force; SDR 4, SDAC 5, ENC 1.
        assert_eq!(
            run("CYCLE840", "10,0,2,-15,,,4,5,1"),
            [rz(2.0), fz(-15.0), M(4), fz(2.0), M(5), rz(10.0)]
        );
        let e = fail("CYCLE840", "10,0,2,-15,,,5");
        assert_eq!((e.alarm, e.argument), (ALARM_MACHINING_TYPE, Some(6)));
    }

    #[test]
    fn cycle85_reams_in_and_out() {
        assert_eq!(
            run("CYCLE85", "10,0,2,-15,,0.5,200,400"),
            [
                rz(2.0),
                fzf(-15.0, 200.0),
                Dwell(0.5),
                fzf(2.0, 400.0),
                rz(10.0)
            ]
        );
        assert_eq!(
            run("CYCLE85", "10,0,2,-15,,,200"),
            [rz(2.0), fzf(-15.0, 200.0), fzf(2.0, 200.0), rz(10.0)]
        );
        assert_eq!(
            run("CYCLE85", "10,0,2,-15"),
            [rz(2.0), fz(-15.0), fz(2.0), rz(10.0)]
        );
    }

    #[test]
    fn cycle86_boring_with_lift_off() {
        // At X10 Y20: lift by RPA -1, RPO 0.5, RPAP 0.2.
        assert_eq!(
            run("CYCLE86", "10,0,2,-15,,1,3,-1,0.5,0.2"),
            [
                rz(2.0),
                fz(-15.0),
                Dwell(1.0),
                M(5),
                M(19),
                CycleStep::Rapid([Some(9.0), Some(20.5), Some(-14.8)]),
                rz(2.0),
                CycleStep::Rapid([Some(10.0), Some(20.0), None]),
                rz(10.0),
                M(3)
            ]
        );
        // G18: first axis Z, second X, applicate Y; no lift-off given.
        let c = ctx(G18);
        assert_eq!(
            run_in("CYCLE86", "10,0,2,-15,,,4,1", &c),
            [
                CycleStep::Rapid([None, Some(2.0), None]),
                CycleStep::Feed {
                    to: [None, Some(-15.0), None],
                    feed: None
                },
                M(5),
                M(19),
                CycleStep::Rapid([None, None, Some(51.0)]),
                CycleStep::Rapid([None, Some(2.0), None]),
                CycleStep::Rapid([Some(10.0), None, Some(50.0)]),
                CycleStep::Rapid([None, Some(10.0), None]),
                M(4)
            ]
        );
        let e = fail("CYCLE86", "10,0,2,-15,,,3,,,,90");
        assert_eq!((e.alarm, e.argument), (ALARM_NOT_CARRIED_OUT, Some(10)));
    }

    #[test]
    fn cycles_87_88_89() {
        assert_eq!(
            run("CYCLE87", "10,0,2,-15,,4"),
            [rz(2.0), fz(-15.0), M(5), M(0), rz(10.0), M(4)]
        );
        assert_eq!(
            run("CYCLE88", "10,0,2,-15,,2,3"),
            [rz(2.0), fz(-15.0), Dwell(2.0), M(5), M(0), rz(10.0), M(3)]
        );
        // SDIR left out: the direction in force.
        assert_eq!(
            run("CYCLE87", "10,0,2,-15"),
            [rz(2.0), fz(-15.0), M(5), M(0), rz(10.0), M(3)]
        );
        assert_eq!(
            run("CYCLE89", "10,0,2,-15,,1"),
            [rz(2.0), fz(-15.0), Dwell(1.0), fz(2.0), rz(10.0)]
        );
        let e = fail("CYCLE87", "10,0,2,-15,,5");
        assert_eq!((e.alarm, e.argument), (ALARM_MACHINING_TYPE, Some(5)));
    }

    #[test]
    fn level_refusals() {
        let e = fail("CYCLE81", ",0,2,-15");
        assert_eq!((e.alarm, e.argument), (ALARM_MISSING, Some(0)));
        assert!(e.message.contains("RTP"), "{}", e.message);
        let e = fail("CYCLE81", "10,0,2");
        assert_eq!((e.alarm, e.argument), (ALARM_MISSING, Some(3)));
        let e = fail("CYCLE81", "10,0,2,2");
        assert_eq!((e.alarm, e.argument), (ALARM_REFERENCE_PLANE, Some(1)));
        let e = fail("CYCLE81", "10,0,0,,0");
        assert_eq!((e.alarm, e.argument), (ALARM_REFERENCE_PLANE, Some(1)));
        let e = fail("CYCLE81", "-5,0,2,-15");
        assert_eq!((e.alarm, e.argument), (ALARM_REFERENCE_PLANE, Some(0)));
        let e = fail("CYCLE81", "10,0,2,-15,,1");
        assert_eq!((e.alarm, e.argument), (ALARM_NOT_CARRIED_OUT, Some(5)));
        let e = fail("CYCLE82", "10,0,2,-15,,-1");
        assert_eq!((e.alarm, e.argument), (ALARM_NOT_CARRIED_OUT, Some(5)));
        let e = fail("CYCLE81", &format!("10,0,2,{}", f64::NAN));
        assert_eq!((e.alarm, e.argument), (ALARM_OUT_OF_RANGE, Some(3)));
        let e = fail("CYCLE800", "10,0,2,-15");
        assert_eq!((e.alarm, e.argument), (ALARM_NOT_CARRIED_OUT, None));
        let e = fail("HOLES1", "0,0,0,0,10,3");
        assert_eq!(e.alarm, ALARM_NOT_CARRIED_OUT);
    }

    fn holes(name: &str, text: &str) -> Vec<[f64; 2]> {
        let mut out = Vec::new();
        pattern(name, &args(text), &ctx(G17), &mut out).expect("the pattern");
        out
    }

    fn close(got: &[[f64; 2]], want: &[[f64; 2]]) {
        assert_eq!(got.len(), want.len(), "{got:?}");
        for (g, w) in got.iter().zip(want) {
            assert!(
                (g[0] - w[0]).abs() < 1e-9 && (g[1] - w[1]).abs() < 1e-9,
                "{got:?} != {want:?}"
            );
        }
    }

    #[test]
    fn holes1_row() {
        assert_eq!(
            holes("HOLES1", "10,20,0,5,10,3"),
            [[15.0, 20.0], [25.0, 20.0], [35.0, 20.0]]
        );
        // Multiples of 90° are exact.
        assert_eq!(
            holes("HOLES1", "10,20,90,5,10,2"),
            [[10.0, 25.0], [10.0, 35.0]]
        );
        assert_eq!(
            holes("HOLES1", "10,20,-90,5,10,2"),
            [[10.0, 15.0], [10.0, 5.0]]
        );
        close(
            &holes("HOLES1", "0,0,30,0,2,2"),
            &[[0.0, 0.0], [2.0 * 0.866_025_403_784_438_6, 1.0]],
        );
        // One hole needs no spacing.
        assert_eq!(holes("HOLES1", "0,0,0,4,,1"), [[4.0, 0.0]]);
        let mut c = ctx(G17);
        c.inch = true;
        let mut out = Vec::new();
        pattern("HOLES1", &args("0,0,0,0.5,0.25,2"), &c, &mut out).expect("inch");
        assert_eq!(out, [[12.7, 0.0], [12.7 + 6.35, 0.0]]);
    }

    #[test]
    fn holes2_circle() {
        // Four holes, radius 10, from 45°: 360/4 = 90° apart.
        let h = 10.0 * std::f64::consts::FRAC_1_SQRT_2; // 7.0710678…
        close(
            &holes("HOLES2", "0,0,10,45,,4"),
            &[[h, h], [-h, h], [-h, -h], [h, -h]],
        );
        // About (100, 50), 3 holes 30° apart from 0°.
        close(
            &holes("HOLES2", "100,50,20,0,30,3"),
            &[
                [120.0, 50.0],
                [100.0 + 20.0 * 0.866_025_403_784_438_6, 60.0],
                [100.0 + 10.0, 50.0 + 20.0 * 0.866_025_403_784_438_6],
            ],
        );
    }

    #[test]
    fn cycle801_grid_meander() {
        assert_eq!(
            holes("CYCLE801", "0,0,0,10,5,3,2"),
            [
                [0.0, 0.0],
                [10.0, 0.0],
                [20.0, 0.0],
                [20.0, 5.0],
                [10.0, 5.0],
                [0.0, 5.0]
            ]
        );
        // Turned by 90°: columns along +Y, rows along -X.
        close(
            &holes("CYCLE801", "1,2,90,10,5,2,3"),
            &[
                [1.0, 2.0],
                [1.0, 12.0],
                [-4.0, 12.0],
                [-4.0, 2.0],
                [-9.0, 2.0],
                [-9.0, 12.0],
            ],
        );
    }

    #[test]
    fn pattern_refusals() {
        let fail = |name: &str, text: &str| {
            let mut out = vec![[1.0, 1.0]];
            let e = pattern(name, &args(text), &ctx(G17), &mut out).expect_err("refused");
            assert_eq!(out, [[1.0, 1.0]]);
            (e.alarm, e.argument)
        };
        assert_eq!(
            fail("HOLES1", "0,0,0,0,10,0"),
            (ALARM_OUT_OF_RANGE, Some(5))
        );
        assert_eq!(
            fail("HOLES1", "0,0,0,0,10,2.5"),
            (ALARM_OUT_OF_RANGE, Some(5))
        );
        assert_eq!(fail("HOLES1", "0,0,0,0,10"), (ALARM_MISSING, Some(5)));
        assert_eq!(fail("HOLES1", "0,0,0,0,,3"), (ALARM_MISSING, Some(4)));
        assert_eq!(fail("HOLES2", "0,0,,0,,3"), (ALARM_MISSING, Some(2)));
        assert_eq!(fail("CYCLE801", "0,0,0,10,,3,2"), (ALARM_MISSING, Some(4)));
        assert_eq!(
            fail("CYCLE801", "0,0,0,1,1,1000,1000"),
            (ALARM_OUT_OF_RANGE, Some(6))
        );
        assert_eq!(fail("CYCLE81", "10,0,2,-15"), (ALARM_NOT_CARRIED_OUT, None));
    }

    fn text_args(text: &str, rest: &str) -> Vec<CycleArg> {
        let mut a = vec![CycleArg::Text(text.into())];
        a.extend(args(rest).into_iter().map(|v| match v {
            Some(v) => CycleArg::Number(v),
            None => CycleArg::Omitted,
        }));
        a
    }

    fn engraved(text: &str, rest: &str, c: &CycleContext) -> Vec<CycleStep> {
        let mut out = Vec::new();
        engrave(&text_args(text, rest), c, &mut out).expect("engraves");
        out
    }

    fn xy(x: f64, y: f64) -> [Option<f64>; 3] {
        [Some(x), Some(y), None]
    }

    #[test]
    fn cycle60_one_letter() {
        // L: "0,6 0,0 4,0"; CH 6 = CAP_HEIGHT: one grid unit per mm.
        assert_eq!(
            engraved("L", "10,0,2,-0.5,,10,20,,6", &ctx(G17)),
            [
                rz(2.0),
                CycleStep::Rapid(xy(10.0, 26.0)),
                fz(-0.5),
                CycleStep::Feed {
                    to: xy(10.0, 20.0),
                    feed: None
                },
                CycleStep::Feed {
                    to: xy(14.0, 20.0),
                    feed: None
                },
                rz(2.0),
                rz(10.0)
            ]
        );
        // CW 8 (capital 4 units wide: 2 mm per unit), CH 3 (0.5 mm per
        // unit); the second character starts ADVANCE × 2 = 12 mm on; a
        // space only advances. PA, PO left out: where the tool stands.
        let s = engraved(" L", "10,0,2,,0.5,,,8,3", &ctx(G17));
        assert_eq!(s[1], CycleStep::Rapid(xy(10.0 + 12.0, 20.0 + 3.0)));
        assert_eq!(s[2], fz(-0.5));
        assert_eq!(
            s[4],
            CycleStep::Feed {
                to: xy(22.0 + 8.0, 20.0),
                feed: None
            }
        );
    }

    #[test]
    fn cycle60_follows_the_font_turned() {
        // A at 90°, CH 3 (scale 0.5), about (10, 20): the font's first
        // stroke's first point and its last stroke's last point.
        let strokes: Vec<Vec<(i8, i8)>> = font::glyph(b'A')
            .expect("A")
            .map(|s| s.points().collect())
            .collect();
        let s = engraved("A", "10,0,2,-1,,10,20,,3,90", &ctx(G17));
        let turned = |(x, y): (i8, i8)| {
            let (x, y) = (f64::from(x) * 0.5, f64::from(y) * 0.5);
            [10.0 - y, 20.0 + x]
        };
        let point = |step: &CycleStep| match step {
            CycleStep::Rapid(p) | CycleStep::Feed { to: p, .. } => {
                [p[0].expect("X"), p[1].expect("Y")]
            }
            other => panic!("{other:?}"),
        };
        let first = turned(strokes[0][0]);
        let last = turned(*strokes.last().and_then(|s| s.last()).expect("a point"));
        close(&[point(&s[1])], &[first]);
        close(&[point(&s[s.len() - 3])], &[last]);
        // Per stroke: rapid, plunge, the points after the first, rapid up.
        let count: usize = strokes.iter().map(|s| s.len() + 2).sum();
        assert_eq!(s.len(), count + 2);
        assert_eq!(s[s.len() - 1], rz(10.0));
        // A dot: plunge and retract in place.
        assert_eq!(
            engraved(".", "10,0,2,-1,,0,0,,6", &ctx(G17)),
            [
                rz(2.0),
                CycleStep::Rapid(xy(2.0, 0.0)),
                fz(-1.0),
                rz(2.0),
                rz(10.0)
            ]
        );
    }

    #[test]
    fn cycle60_in_g18() {
        // G18: first axis Z, second X, applicate Y.
        let s = engraved("L", "10,0,2,-0.5,,0,0,,6", &ctx(G18));
        assert_eq!(s[0], CycleStep::Rapid([None, Some(2.0), None]));
        assert_eq!(s[1], CycleStep::Rapid([Some(6.0), None, Some(0.0)]));
        assert_eq!(
            s[2],
            CycleStep::Feed {
                to: [None, Some(-0.5), None],
                feed: None
            }
        );
    }

    #[test]
    fn cycle60_refusals() {
        let c = ctx(G17);
        let fail = |a: Vec<CycleArg>| {
            let mut out = vec![M(8)];
            let e = engrave(&a, &c, &mut out).expect_err("refused");
            assert_eq!(out, [M(8)]);
            (e.alarm, e.argument)
        };
        assert_eq!(fail(vec![]), (ALARM_MISSING, Some(0)));
        assert_eq!(
            fail(vec![CycleArg::Number(1.0), CycleArg::Number(10.0)]),
            (ALARM_OUT_OF_RANGE, Some(0))
        );
        assert_eq!(
            fail(text_args("", "10,0,2,-1,,0,0,,6")),
            (ALARM_OUT_OF_RANGE, Some(0))
        );
        assert_eq!(
            fail(text_args("Aé", "10,0,2,-1,,0,0,,6")),
            (ALARM_OUT_OF_RANGE, Some(0))
        );
        assert_eq!(
            fail(text_args("A", "10,0,2,-1,,0,0")),
            (ALARM_MISSING, Some(9))
        );
        assert_eq!(
            fail(text_args("A", "10,0,2,-1,,0,0,,0")),
            (ALARM_OUT_OF_RANGE, Some(9))
        );
        assert_eq!(
            fail(text_args("A", ",0,2,-1,,0,0,,6")),
            (ALARM_MISSING, Some(1))
        );
        assert_eq!(
            fail(text_args("A", "10,0,2,3,,0,0,,6")),
            (ALARM_REFERENCE_PLANE, Some(2))
        );
        let mut a = text_args("A", "10,0,2,-1");
        a.push(CycleArg::Text("X".into()));
        assert_eq!(fail(a), (ALARM_OUT_OF_RANGE, Some(5)));
        assert_eq!(
            fail(text_args(&"A".repeat(MAX_TEXT + 1), "10,0,2,-1,,0,0,,6")),
            (ALARM_OUT_OF_RANGE, Some(0))
        );
    }
}
