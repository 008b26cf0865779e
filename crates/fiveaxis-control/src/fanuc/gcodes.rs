//! A block's G codes sorted by modal group ([`GCodes`]), with the
//! control's refusals: a code it does not have, two codes that cannot
//! share a block, a code 3-D tool compensation forbids in its mode.

use fiveaxis_gcode::{Code, Span};

use super::Words;
use crate::alarm::{Alarm, Condition};
use crate::command::CutterSide;
use crate::controller::{Cycle, NgcMotionMode as NgcMotion};
use crate::controller::{MIRROR, POLAR, ROTATION, SCALING};
use crate::modal::{
    ContourControl, CuttingMode, Distance, FeedMode, MotionMode, Plane, TcpcType, Units, WorkSelect,
};

/// What the classification depends on besides the block.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Classify {
    /// Haas's own codes.
    pub haas: bool,
    /// LinuxCNC's RS274/NGC codes.
    pub ngc: bool,
    /// LinuxCNC's tilted-working-plane remap.
    pub twp: bool,
    /// 3-D tool compensation is in force.
    pub comp3d: bool,
    /// The machine's input unit is the inch (Haas Setting 9).
    pub inch_input: bool,
    /// G44 cancels the length offset (Mitsubishi).
    pub g44_cancels: bool,
}

/// The transform slot of a program transform code: G15 / G16, G50.1 /
/// G51.1, G50 / G51, G68 / G69.
pub(crate) fn transform_slot(code: Code) -> usize {
    match (code.major, code.minor) {
        (15 | 16, _) => POLAR,
        (50 | 51, 1) => MIRROR,
        (50 | 51, _) => SCALING,
        _ => ROTATION,
    }
}

#[derive(Clone, Copy, Debug)]
enum GKind {
    Motion,
    Plane,
    Distance,
    Feed,
    Units,
    Length,
    Work,
    OneShot,
    Cutter,
    SetupError,
    Cutting,
    Accuracy,
    Cycle,
    CycleReturn,
    Feature,
    Frame,
    /// G09: exact stop for one block.
    ExactStop,
    /// Haas G254 / G255 (group 23).
    Dwo,
    /// Haas G187.
    Smoothness,
    /// LinuxCNC G90.1 / G91.1: arc centre distance mode.
    ArcDistance,
    Diameter,
}

/// A tool length function of group 08.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum LengthCode {
    /// The length offset along +Z (G43).
    Plus,
    /// Along −Z (G44).
    Minus,
    /// Off (G49).
    Off,
    /// Off, the axes staying where they are (Mitsubishi G44).
    OffInPlace,
    /// Along the tool axis (FANUC G43.1).
    ToolAxis,
    /// The length given in the block (LinuxCNC G43.1).
    Given,
    /// The length given in the block or of a tool, added to the one in
    /// force (LinuxCNC G43.2).
    Added,
    /// Tool centre point control (G43.4 type 1, G43.5 type 2).
    Tcpc(TcpcType),
    /// Haas's TCPC (G234).
    HaasTcpc,
}

impl LengthCode {
    /// The function of `code` on a control with these rules.
    pub(crate) fn of(code: Code, ngc: bool, g44_cancels: bool) -> LengthCode {
        match (code.major, code.minor) {
            (43, 2) => LengthCode::Added,
            (234, _) => LengthCode::HaasTcpc,
            (43, 1) if ngc => LengthCode::Given,
            (43, 1) => LengthCode::ToolAxis,
            (43, 4) => LengthCode::Tcpc(TcpcType::Angles),
            (43, 5) => LengthCode::Tcpc(TcpcType::Vector),
            (43, _) => LengthCode::Plus,
            (44, _) if g44_cancels => LengthCode::OffInPlace,
            (44, _) => LengthCode::Minus,
            _ => LengthCode::Off,
        }
    }
}

/// A function of group 00 (one block only).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum OneShot {
    /// A dwell (G04).
    Dwell,
    /// Data written into the offset memory (G10).
    DataSetting,
    /// Positioning, then a check that the axes stand at reference
    /// position 1 (G27).
    ReferenceCheck,
    /// Through an intermediate point to reference position 1 (G28), or
    /// the one `P` names, 2 by default (G30).
    ReferenceReturn {
        /// G30: the reference position is read from P.
        numbered: bool,
    },
    /// LinuxCNC: the machine position becomes the G28 (0) or G30 (1)
    /// position (G28.1, G30.1).
    SetHome(usize),
    /// The local coordinate system (G52).
    LocalShift,
    /// Positioning in machine coordinates (G53).
    MachineMove,
    /// The tool along the feature frame's Z (G53.1; G53.6 keeping the
    /// tip; Haas G253).
    ToolAxis {
        /// The tool tip stays where it is.
        keep_tip: bool,
    },
    /// LinuxCNC's TWP remap: orient the tool to the plane defined (G53.1),
    /// and move to a point of it (G53.3) or keep the tip (G53.6).
    TwpOrient(TwpOrient),
    /// Haas text engraving (G47).
    Engrave,
    /// The current position gets the named coordinates (G92).
    SetPosition,
    /// LinuxCNC G92.1 (clear), G92.2 (suspend), G92.3 (restore).
    ShiftReset(u8),
}

/// How LinuxCNC's TWP remap orients the tool.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TwpOrient {
    /// The rotary axes turn (G53.1).
    Turn,
    /// And the tip goes to a point of the plane (G53.3).
    ToPoint,
    /// The tip stays (G53.6).
    KeepTip,
}

impl OneShot {
    /// The function of a group-00 code; `twp`: LinuxCNC's TWP remap.
    fn of(code: Code, twp: bool) -> OneShot {
        match (code.major, code.minor) {
            (4, _) => OneShot::Dwell,
            (10, _) => OneShot::DataSetting,
            (27, _) => OneShot::ReferenceCheck,
            (28 | 30, 1) => OneShot::SetHome(usize::from(code.major == 30)),
            (28, _) => OneShot::ReferenceReturn { numbered: false },
            (30, _) => OneShot::ReferenceReturn { numbered: true },
            (53, 1) if twp => OneShot::TwpOrient(TwpOrient::Turn),
            (53, 3) if twp => OneShot::TwpOrient(TwpOrient::ToPoint),
            (53, 6) if twp => OneShot::TwpOrient(TwpOrient::KeepTip),
            (53, 1) | (253, _) => OneShot::ToolAxis { keep_tip: false },
            (53, 6) => OneShot::ToolAxis { keep_tip: true },
            (47, _) => OneShot::Engrave,
            (52, _) => OneShot::LocalShift,
            (53, _) => OneShot::MachineMove,
            (92, minor @ 1..=3) => OneShot::ShiftReset(minor),
            _ => OneShot::SetPosition,
        }
    }
}

/// A function of the tilted working plane's group.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum FeatureCode {
    /// Define the plane (G68.2).
    Plane,
    /// Define it from the tool axis (G68.3).
    ToolAxis,
    /// Define it relative to the plane in force (G68.4).
    Relative,
    /// Haas's feature coordinate system (G268).
    HaasPlane,
    /// End it (G69, Haas G269).
    Cancel,
}

impl FeatureCode {
    fn of(code: Code) -> FeatureCode {
        match (code.major, code.minor) {
            (68, 3) => FeatureCode::ToolAxis,
            (68, 4) => FeatureCode::Relative,
            (68, _) => FeatureCode::Plane,
            (268, _) => FeatureCode::HaasPlane,
            _ => FeatureCode::Cancel,
        }
    }
}

/// An accuracy mode code and its number (G05.1 Q, G05 P, G08 P).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum AccuracyCode {
    /// AI contour control / nano smoothing (G05.1 Q1 / Q3), or off (Q0).
    Contour(ContourControl),
    /// High-precision contour control (G05 P10000), or off (P0).
    HighPrecision(bool),
    /// Advanced preview control (G08 P1), or off (P0).
    LookAhead(bool),
}

/// The G codes of one block, by group; the last of a group wins.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct GCodes {
    /// Group 01: the interpolation, with LinuxCNC's modes beyond G0–G3
    /// (G5, G5.1, G33, G33.1, G76: linear interpolation with their own
    /// function).
    pub motion: Option<(MotionMode, Option<NgcMotion>, Span)>,
    /// LinuxCNC: the block's group 08 comes from a kinematics switch or a
    /// tool length change, which move nothing: the axes stay and the
    /// programmed position is read again under the new kinematics and
    /// length (as LinuxCNC's interpreter synchronises with motion).
    pub length_in_place: bool,
    /// LinuxCNC: the block's group 08 is the kinematics switch's own, not
    /// a programmed G43 (so not "G43 without H": the H in force stays).
    pub length_synthesized: bool,
    /// LinuxCNC: a programmed G43 without H, turned into the TCP
    /// kinematics' G43.4: it takes the tool in the spindle after the
    /// block's M6 (overview.adoc, order of execution: change tool before
    /// tool length offsets).
    pub length_from_spindle: bool,
    /// G17 / G18 / G19.
    pub plane: Option<Plane>,
    /// G90 / G91.
    pub distance: Option<Distance>,
    /// LinuxCNC G90.1 (true: arc centres absolute) / G91.1.
    pub arc_distance: Option<bool>,
    /// LinuxCNC G7 (true) / G8.
    pub diameter: Option<bool>,
    /// G93 / G94 / G95.
    pub feed: Option<FeedMode>,
    /// G20 / G21.
    pub units: Option<Units>,
    /// Group 08: the tool length function, where it is written, and the
    /// code as written (for messages).
    pub length: Option<(LengthCode, Span, Code)>,
    /// Group 14: the work coordinate system selected, where, the code.
    pub work: Option<(WorkSelect, Span, Code)>,
    /// Group 07: G40 / G41 / G42.
    pub cutter: Option<(CutterSide, Span)>,
    /// G54.4: workpiece setup error correction (its span).
    pub setup: Option<Span>,
    /// Group 00: the function, where it is written, the code as written.
    pub one_shot: Option<(OneShot, Span, Code)>,
    /// Group 15: G61 / G62 / G63 / G64 (LinuxCNC G61.1 as G61).
    pub cutting: Option<CuttingMode>,
    /// G05.1, G05 or G08 (one per block).
    pub accuracy: Option<(AccuracyCode, Span)>,
    /// G80: ends rigid tapping.
    pub canned_cancel: bool,
    /// G09: exact stop at the end of this block.
    pub exact_stop: bool,
    /// Group 09: a canned cycle, or its end (`None`: G80).
    pub cycle: Option<(Option<Cycle>, Span)>,
    /// G98 (true: back to the initial level) / G99.
    pub cycle_return: Option<bool>,
    /// G68.2 or G69 (tilted working plane).
    pub feature: Option<(FeatureCode, Span, Code)>,
    /// The program transforms by slot (polar coordinates G15 / G16,
    /// mirror image G50.1 / G51.1, scaling G50 / G51, rotation G69 /
    /// G68): on (true) or off, where, and the code as written.
    pub frames: [Option<(bool, Span, Code)>; 4],
    /// Haas G254 / G255: dynamic work offset on / off.
    pub dwo: Option<(bool, Span)>,
    /// Haas G187 (its span).
    pub smoothness: Option<Span>,
}

impl Words {
    /// G20 / G21: Haas checks them against Setting 9 (Haas NGC mill
    /// operator's manual, G20 / G21: "G20 in a program causes an alarm if
    /// Setting 9 is not set to inch"; G21 against an inch Setting 9
    /// likewise: the codes are there "to make sure that the inch/metric
    /// selection is set correctly").
    fn units(&self, code: Code, ctx: &Classify) -> Result<Units, Alarm> {
        let inch = code.major == 20;
        if ctx.haas && inch != ctx.inch_input {
            let (unit, setting) = if inch { ("inch", "MM") } else { ("mm", "INCH") };
            return Err(self.alarm(
                Condition::UnitsMismatch,
                None,
                format!(
                    "G{} asks for {unit} while Setting 9 (the machine's input_unit) is {setting}",
                    code.major
                ),
            ));
        }
        Ok(if inch { Units::Inch } else { Units::Metric })
    }

    /// The block's G codes by group: an alarm for a code this control
    /// does not have, or two that cannot be in one block.
    pub(crate) fn g_codes(&mut self, ctx: &Classify) -> Result<GCodes, Alarm> {
        let mut codes = GCodes::default();
        let mut motion_code = None;
        let mut cycle_code = None;
        let mut accuracy_code: Option<Code> = None;
        let haas = ctx.haas;
        let twp = ctx.twp;
        for i in 0..self.g_len {
            let (code, span) = self.g[i];
            let kind = match (code.major, code.minor) {
                // LinuxCNC's tilted-working-plane remap (coordinates/twp.rs).
                (68, 2..=4) | (69, 0) if twp => GKind::Feature,
                (53, 1 | 3 | 6) if twp => GKind::OneShot,
                // Without the remap LinuxCNC has none of them.
                (68, 2..=4) | (53, 1 | 6) if ctx.ngc => {
                    return Err(self.alarm(
                        Condition::ImproperGCode,
                        Some(span),
                        format!("G{code} is not a G code of this control (LinuxCNC has it only through a tilted-working-plane remap: twp_remap in the machine file)"),
                    ));
                }
                // Haas's own codes (controller/haas.rs).
                (234, 0) if haas => GKind::Length,
                (254 | 255, 0) if haas => GKind::Dwo,
                (268 | 269, 0) if haas => GKind::Feature,
                (253, 0) if haas => GKind::OneShot,
                // G47 text engraving (controller/engrave.rs).
                (47, 0) if haas => GKind::OneShot,
                (187, 0) if haas => GKind::Smoothness,
                (154 | 110..=129, 0) if haas => GKind::Work,
                (0..=3, 0) => GKind::Motion,
                // LinuxCNC's spindle-synchronized motion and threading
                // cycle (controller/threading.rs): group 1.
                (33, 0 | 1) | (76, 0) | (5, 0 | 1) if ctx.ngc => GKind::Motion,
                (17..=19, 0) => GKind::Plane,
                (90 | 91, 0) => GKind::Distance,
                (90 | 91, 1) if ctx.ngc => GKind::ArcDistance,
                // LinuxCNC G7 / G8: lathe diameter / radius mode.
                (7 | 8, 0) if ctx.ngc => GKind::Diameter,
                (93..=95, 0) => GKind::Feed,
                (20 | 21, 0) => GKind::Units,
                (43 | 44 | 49, 0) | (43, 1 | 4 | 5) => GKind::Length,
                // LinuxCNC G43.2: an additional length offset.
                (43, 2) if ctx.ngc => GKind::Length,
                (54..=59, 0) | (54, 1) => GKind::Work,
                (54, 4) => GKind::SetupError,
                (4 | 10 | 27 | 28 | 30 | 52 | 53 | 92, 0) | (53, 1 | 6) => GKind::OneShot,
                // LinuxCNC G92.1 / G92.2 / G92.3.
                (92, 1..=3) | (28 | 30, 1) if ctx.ngc => GKind::OneShot,
                (59, 1..=3) if ctx.ngc => GKind::Work,
                (68, 2..=4) => GKind::Feature,
                (61..=64, 0) => GKind::Cutting,
                // LinuxCNC G61.1: exact path (speed only, as G61).
                (61, 1) if ctx.ngc => GKind::Cutting,
                // G05 is refused in 3-D tool compensation (below).
                (5, 0) if comp3d_forbidden(ctx.comp3d, code).is_none() => GKind::Accuracy,
                (5, 1) | (8, 0) => GKind::Accuracy,
                // Exact stop for one block: speed only.
                (9, 0) => GKind::ExactStop,
                (40..=42, 0) => GKind::Cutter,
                (73 | 74 | 76 | 80..=89, 0) => GKind::Cycle,
                (98 | 99, 0) => GKind::CycleReturn,
                // Program transforms (controller/coordinates); G51 is
                // refused in 3-D tool compensation (below).
                (51, 0) if comp3d_forbidden(ctx.comp3d, code).is_none() => GKind::Frame,
                (15 | 16 | 50 | 68 | 69, 0) | (50 | 51, 1) => GKind::Frame,
                _ => {
                    if let Some((condition, what)) = comp3d_forbidden(ctx.comp3d, code) {
                        return Err(self.alarm(
                            condition,
                            Some(span),
                            format!("G{code} ({what}) cannot be used in 3-D tool compensation"),
                        ));
                    }
                    return Err(self.alarm(
                        Condition::ImproperGCode,
                        Some(span),
                        format!("G{code} is not a G code of this control"),
                    ));
                }
            };
            match kind {
                GKind::OneShot => {
                    if let Some((_, _, other)) = codes.one_shot {
                        return Err(self.alarm(
                            Condition::GCodeConflict,
                            Some(span),
                            format!("G{code} and G{other} cannot be in the same block"),
                        ));
                    }
                    codes.one_shot = Some((OneShot::of(code, twp), span, code));
                }
                GKind::Motion => {
                    let mode = match code.major {
                        0 => MotionMode::Rapid,
                        2 => MotionMode::Cw,
                        3 => MotionMode::Ccw,
                        _ => MotionMode::Linear,
                    };
                    codes.motion = Some((mode, ngc_motion_of(code), span));
                    motion_code = Some(code);
                }
                GKind::Plane => {
                    codes.plane = Some(match code.major {
                        17 => Plane::Xy,
                        18 => Plane::Zx,
                        _ => Plane::Yz,
                    });
                }
                GKind::Distance => {
                    codes.distance = Some(if code.major == 90 {
                        Distance::Absolute
                    } else {
                        Distance::Incremental
                    });
                }
                GKind::ArcDistance => codes.arc_distance = Some(code.major == 90),
                GKind::Diameter => codes.diameter = Some(code.major == 7),
                GKind::Feed => {
                    codes.feed = Some(match code.major {
                        93 => FeedMode::InverseTime,
                        94 => FeedMode::PerMinute,
                        _ => FeedMode::PerRevolution,
                    });
                }
                GKind::Units => codes.units = Some(self.units(code, ctx)?),
                GKind::Length => {
                    let what = LengthCode::of(code, ctx.ngc, ctx.g44_cancels);
                    codes.length = Some((what, span, code));
                }
                GKind::Work => {
                    let work = self.work(code, span, ctx.ngc)?;
                    codes.work = Some((work, span, code));
                }
                GKind::Cutter => {
                    let side = match code.major {
                        41 => CutterSide::Left,
                        42 => CutterSide::Right,
                        _ => CutterSide::Off,
                    };
                    codes.cutter = Some((side, span));
                }
                GKind::SetupError => codes.setup = Some(span),
                GKind::Cutting => {
                    codes.cutting = Some(match code.major {
                        61 => CuttingMode::ExactStop,
                        62 => CuttingMode::CornerOverride,
                        63 => CuttingMode::Tapping,
                        _ => CuttingMode::Cutting,
                    });
                }
                GKind::Accuracy => {
                    if let Some(other) = accuracy_code {
                        return Err(self.alarm(
                            Condition::GCodeConflict,
                            Some(span),
                            format!("G{code} and G{other} cannot be in the same block"),
                        ));
                    }
                    let value = self.accuracy_mode(code, span)?;
                    let what = match (code.major, code.minor, value) {
                        (5, 1, 1) => AccuracyCode::Contour(ContourControl::AiContour),
                        (5, 1, 3) => AccuracyCode::Contour(ContourControl::NanoSmoothing),
                        (5, 1, _) => AccuracyCode::Contour(ContourControl::Off),
                        (5, _, v) => AccuracyCode::HighPrecision(v != 0),
                        (_, _, v) => AccuracyCode::LookAhead(v != 0),
                    };
                    codes.accuracy = Some((what, span));
                    accuracy_code = Some(code);
                }
                GKind::Cycle => {
                    // G80 also ends M29's rigid tapping.
                    codes.canned_cancel |= code.major == 80;
                    codes.cycle = Some((cycle_of(code), span));
                    cycle_code = Some(code);
                }
                GKind::CycleReturn => codes.cycle_return = Some(code.major == 98),
                GKind::Feature => codes.feature = Some((FeatureCode::of(code), span, code)),
                GKind::Frame => {
                    // G69 cancels the tilted working plane too.
                    if code == Code::new(69, 0) {
                        codes.feature = Some((FeatureCode::Cancel, span, code));
                    }
                    let on = matches!(code.major, 16 | 51 | 68);
                    codes.frames[transform_slot(code)] = Some((on, span, code));
                }
                GKind::ExactStop => codes.exact_stop = true,
                GKind::Dwo => codes.dwo = Some((code.major == 254, span)),
                GKind::Smoothness => codes.smoothness = Some(span),
            }
        }
        // G04, G10 and G92 do not move; G53 moves at rapid whatever the
        // motion code (posts write `G90 G53 G00 Z0.`), which stays modal.
        let motion = motion_code.zip(codes.motion.map(|(_, _, span)| span));
        // A canned cycle and a motion code of group 01 (G80 with one is
        // the cycle's end).
        if let (Some(cycle), Some((motion, _)), Some((Some(_), span))) =
            (cycle_code, motion, codes.cycle)
        {
            return Err(self.alarm(
                Condition::GCodeConflict,
                Some(span),
                format!("G{cycle} and G{motion} cannot be in the same block"),
            ));
        }
        if let (Some((motion, span)), Some((_, _, one))) = (motion, codes.one_shot)
            && !matches!(one.major, 4 | 10 | 92)
            && !(one.major == 53 && (one.minor == 0 || !twp) && motion.major <= 1)
        {
            return Err(self.alarm(
                Condition::GCodeConflict,
                Some(span),
                format!("G{motion} and G{one} cannot be in the same block"),
            ));
        }
        // The TWP remap's codes are of modal group 1 (REMAP … modalgroup=1):
        // one motion code per block.
        if twp && let (Some((motion, span)), Some((_, _, feature))) = (motion, codes.feature) {
            return Err(self.alarm(
                Condition::GCodeConflict,
                Some(span),
                format!("G{motion} and G{feature} are both of modal group 1 and cannot be in the same block"),
            ));
        }
        Ok(codes)
    }
}

/// G codes that 3-D tool compensation forbids in its mode, with their
/// alarms: `None` when `code` is not one of them or the mode is off.
fn comp3d_forbidden(active: bool, code: Code) -> Option<(Condition, &'static str)> {
    if !active {
        return None;
    }
    match code.major {
        5 => Some((
            Condition::Comp3dHighSpeedCycle,
            "high-speed cycle machining",
        )),
        31 => Some((Condition::Comp3dSkip, "the skip function")),
        51 => Some((Condition::Comp3dScaling, "scaling")),
        45..=48 => Some((Condition::Comp3dToolOffset, "tool offset")),
        _ => None,
    }
}

/// The canned cycle of a group-09 code (`None`: G80, the end of the
/// cycle).
fn cycle_of(code: Code) -> Option<Cycle> {
    Some(match code.major {
        73 => Cycle::G73,
        74 => Cycle::G74,
        76 => Cycle::G76,
        81 => Cycle::G81,
        82 => Cycle::G82,
        83 => Cycle::G83,
        84 => Cycle::G84,
        85 => Cycle::G85,
        86 => Cycle::G86,
        87 => Cycle::G87,
        88 => Cycle::G88,
        89 => Cycle::G89,
        _ => return None,
    })
}

/// LinuxCNC's motion mode of a group-1 code (`None` for G0–G3).
fn ngc_motion_of(code: Code) -> Option<NgcMotion> {
    Some(match (code.major, code.minor) {
        (5, 0) => NgcMotion::CubicSpline,
        (5, 1) => NgcMotion::QuadraticSpline,
        (33, 0) => NgcMotion::Thread,
        (33, 1) => NgcMotion::RigidTap,
        (76, 0) => NgcMotion::ThreadingCycle,
        _ => return None,
    })
}
