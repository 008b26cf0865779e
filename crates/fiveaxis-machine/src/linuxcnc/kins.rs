//! The machine of each LinuxCNC kinematics module (`[KINS] KINEMATICS`).
//!
//! Sources (LinuxCNC documentation only):
//!
//! * `motion/5-axis-kinematics.adoc`, "Transformations for a xyzac-trt
//!   machine with rotary axis offsets" and "… xyzbc-trt machine …": the
//!   table-tilting machines. The tilt axis turns about its line through
//!   the pivot point (offsets D_y, D_z or D_x, D_z from the rotary table's
//!   centre line) and carries the rotary table C. The document's notes fix
//!   the senses: "the table rotations are positive relative to the
//!   workpiece coordinate axes" and "the rotational axes move in the
//!   opposite direction of what the convention is": for +θ the table turns
//!   right-handed about +X (+Y) and +Z, so the world point (the tool tip in
//!   the table frame) is the joint point turned by −θ. The sim
//!   configuration's own check program (`xyzac_switchkins_test_3.ngc`,
//!   "(debug, C expect: 0 -10 2)" at joints X10 Y0 Z2 C90) agrees. Tool
//!   length: "Tool-Length Compensation" adds `motion.tooloffset.z` to D_z.
//! * `motion/switchkins.adoc`: which kinematics type is which, and
//!   `sparm=identityfirst`.
//! * `man/man9/kins.9.adoc`: trivkins' `coordinates=` (a doubled letter is
//!   a gantry: two joints, one axis), 5axiskins, maxkins, scarakins.
//!
//! In the machine model's terms (`machine-model.md` §3) a table turning
//! right-handed about +X for +θ is `axis = [1, 0, 0]`; the table frame is
//! `T⁻¹(tip_machine)`. With the rotation points (`x/y/z-rot-point`) the rotary
//! table's centre line passes through the rotation point and the tilt axis
//! through the rotation point plus the offsets.

use nalgebra::Unit;

use std::path::Path;

use super::hal::{Drive, Hal};
use super::ini::Ini;
use super::{ImportError, Units};
use crate::{Dynamics, MAX_FILE_MAGNITUDE, RotaryAxis, Side, Vec3};

/// What a kinematics type (`motion.switchkins-type`) computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum KinsType {
    /// The module's own kinematics: X Y Z are the tool tip in the table
    /// frame (TCP).
    Tcp,
    /// Identity: every coordinate letter is its joint.
    Identity,
    /// `userk`, the user-provided type 2 (`switchkins.adoc`, "User
    /// kinematics provisions"); the template as shipped is identity.
    User,
    /// The trsrn modules' TOOL kinematics (type 2): X Y Z in the tool
    /// coordinate system the tilted-working-plane remaps set up (G53.1 /
    /// G53.3 / G53.6 after G68.2). The kernel's tilted working plane gives
    /// that frame; the M code itself is the TCP kinematics, tcpc_on.
    Tool,
}

/// The machine a kinematics module describes.
#[derive(Clone, Debug)]
pub(crate) struct Kinematics {
    /// Module name as the INI file gives it.
    pub module: String,
    /// Linear axis letters, X Y Z first.
    pub linear: Vec<char>,
    /// Rotary axes, bed outwards, geometry set; limits and dynamics are
    /// filled in from `[AXIS_L]` afterwards.
    pub rotary: Vec<RotaryAxis>,
    /// Kinematics types by `motion.switchkins-type` value; empty for a
    /// module without switching.
    pub types: Vec<KinsType>,
    /// The linear axis that moves the tool along its own axis (5axiskins'
    /// W), if any.
    pub quill: Option<char>,
    /// The coordinate letter of each LinuxCNC joint, by joint number (the
    /// coordinates in order, a doubled letter a second joint of its axis).
    pub joints: Vec<char>,
    /// Notes on the geometry's sources.
    pub notes: Vec<String>,
}

/// The kinematics modules the importer turns into machines, and the
/// letters they take.
const TRT_AC: &str = "xyzac-trt-kins";
const TRT_BC: &str = "xyzbc-trt-kins";
const TDR_AB: &str = "xyzab_tdr_kins";
const FIVE_AXIS: &str = "5axiskins";
const TRSRN_ACB: &str = "xyzacb_trsrn";
const TRSRN_BCA: &str = "xyzbca_trsrn";

/// The bridge mill's pivot length (pivot to gauge point, mm) written when
/// the configuration computes `5axiskins.pivot-length` from its GUI model
/// (`5axisgui.py pivot_len` plus G43's length), which the files do not
/// give: the pivot at the gauge point. The user sets the real value as
/// the head axes' `center`.
pub(crate) const DEFAULT_PIVOT: f64 = 0.0;

impl Kinematics {
    /// The machine of `[KINS] KINEMATICS`.
    pub(crate) fn read(
        ini: &Ini,
        ini_path: &Path,
        hal: &Hal,
        units: Units,
        notes: &mut Vec<String>,
    ) -> Result<Kinematics, ImportError> {
        let Some(entry) = ini.get("KINS", "KINEMATICS") else {
            return Err(ImportError::file(
                ini_path,
                "[KINS]KINEMATICS is missing: the kinematics module is not known",
            ));
        };
        let mut words = entry.value.split_whitespace();
        let module = words.next().unwrap_or("").to_owned();
        let mut coordinates: Option<String> = None;
        let mut sparm: Option<String> = None;
        for word in words {
            match word.split_once('=') {
                Some(("coordinates", v)) => coordinates = Some(v.to_owned()),
                Some(("sparm", v)) => sparm = Some(v.to_owned()),
                Some(("kinstype", _)) => {}
                _ => {
                    return Err(entry.error(format!(
                        "`{word}` is not a module parameter (coordinates=, sparm=, kinstype=)"
                    )));
                }
            }
        }
        notes.push(format!(
            "kinematics: [KINS]KINEMATICS = {} (line {})",
            entry.value, entry.line
        ));
        // The coordinate letters: the module's coordinates=, else [TRAJ].
        let letters = match (&coordinates, ini.get("TRAJ", "COORDINATES")) {
            (Some(c), _) => c.clone(),
            (None, Some(e)) => e.value.clone(),
            (None, None) => String::new(),
        };
        let mut axes: Vec<char> = Vec::new();
        let mut joints: Vec<char> = Vec::new();
        for c in letters.chars().filter(|c| !c.is_whitespace()) {
            let c = c.to_ascii_uppercase();
            if !"XYZABCUVW".contains(c) {
                return Err(entry.error(format!("`{c}` is not a coordinate letter (XYZABCUVW)")));
            }
            joints.push(c);
            // A doubled letter is a second joint of the same axis (gantry).
            if !axes.contains(&c) {
                axes.push(c);
            }
        }
        let unsupported = |why: &str| entry.error(format!("kinematics {module}: {why}"));
        let mut k = Kinematics {
            module: module.clone(),
            linear: Vec::new(),
            rotary: Vec::new(),
            types: Vec::new(),
            quill: None,
            joints,
            notes: Vec::new(),
        };
        match module.as_str() {
            "trivkins" => {
                if axes.is_empty() {
                    axes = "XYZABCUVW".chars().collect();
                    k.joints.clone_from(&axes);
                }
                let rotary: String = axes.iter().filter(|c| "ABC".contains(**c)).collect();
                if !rotary.is_empty() {
                    return Err(unsupported(&format!(
                        "identity kinematics moves the rotary axes {rotary} as plain joints and \
                         the configuration says nothing of where their rotation lines are; \
                         the machine model needs each rotary axis' line and direction: import \
                         a configuration with 5-axis kinematics, or write the [[rotary]] \
                         entries of a machine file yourself"
                    )));
                }
                k.linear = linear_letters(&axes, &unsupported)?;
            }
            TRT_AC | TRT_BC => {
                let tilt = if module == TRT_AC { 'A' } else { 'B' };
                require(&axes, &['X', 'Y', 'Z', tilt, 'C'], &unsupported)?;
                k.linear = linear_letters(&axes, &unsupported)?;
                let prefix = module.as_str();
                let geometry = Pins::new(hal, prefix, units.mm, ini_path);
                let rot = [
                    geometry.value("x-rot-point", &mut k.notes)?,
                    geometry.value("y-rot-point", &mut k.notes)?,
                    geometry.value("z-rot-point", &mut k.notes)?,
                ];
                let rot = Vec3::new(rot[0], rot[1], rot[2]);
                let (offset_name, offset_axis) = if tilt == 'A' {
                    ("y-offset", Vec3::y())
                } else {
                    ("x-offset", Vec3::x())
                };
                let d = geometry.value(offset_name, &mut k.notes)?;
                let dz = geometry.value("z-offset", &mut k.notes)?;
                let conventional = Pins::new(hal, prefix, 1.0, ini_path)
                    .value("conventional-directions", &mut k.notes)?
                    != 0.0;
                tool_offset(hal, prefix, "tool-offset", &mut k.notes, &unsupported)?;
                // The table turns by +angle right-handed about +X (+Y)
                // and +Z ("table rotations positive relative to the
                // workpiece coordinate axes"; "the rotational axes move in
                // the opposite direction of what the convention is");
                // conventional-directions turns both the ISO way.
                let sense = if conventional { -1.0 } else { 1.0 };
                let tilt_dir = if tilt == 'A' { Vec3::x() } else { Vec3::y() };
                k.rotary = vec![
                    table_axis(
                        tilt,
                        tilt_dir * sense,
                        rot + offset_axis * d + Vec3::z() * dz,
                    ),
                    table_axis('C', Vec3::z() * sense, rot),
                ];
                // switchkins.adoc: type0 is the module's kinematics, type1
                // identity; sparm=identityfirst swaps them; type2 userk.
                k.types = if sparm.as_deref() == Some("identityfirst") {
                    vec![KinsType::Identity, KinsType::Tcp, KinsType::User]
                } else {
                    vec![KinsType::Tcp, KinsType::Identity, KinsType::User]
                };
                k.notes.push(format!(
                    "{module}: tilt {tilt} on the bed about a line through the rotation point + \
                     {offset_name} and z-offset, C on it about the table centre line through the \
                     rotation point (5-axis-kinematics.adoc, transformations with rotary axis offsets){}",
                    if conventional { "; conventional-directions: both senses reversed" } else { "" }
                ));
            }
            TDR_AB => {
                require(&axes, &['X', 'Y', 'Z', 'A', 'B'], &unsupported)?;
                k.linear = linear_letters(&axes, &unsupported)?;
                let geometry = Pins::new(hal, TDR_AB, units.mm, ini_path);
                let rot = Vec3::new(
                    geometry.value("x-rot-point", &mut k.notes)?,
                    geometry.value("y-rot-point", &mut k.notes)?,
                    geometry.value("z-rot-point", &mut k.notes)?,
                );
                let dx = geometry.value("x-offset", &mut k.notes)?;
                let dz = geometry.value("z-offset", &mut k.notes)?;
                tool_offset(hal, TDR_AB, "tool-offset-z", &mut k.notes, &unsupported)?;
                // The configuration's README: the B axis passes through
                // the rotation point; the A table's face centre is the
                // rotation point plus (x-offset, 0, z-offset); A is carried
                // by B. Senses as the trt modules' (table turns +θ).
                k.rotary = vec![
                    table_axis('B', Vec3::y(), rot),
                    table_axis('A', Vec3::x(), rot + Vec3::new(dx, 0.0, dz)),
                ];
                // The configuration's [KINS] note: type0 identity, type1
                // xyzab-tdr.
                k.types = vec![KinsType::Identity, KinsType::Tcp];
                k.notes.push(format!(
                    "{TDR_AB}: B on the bed about the Y line through the rotation point, A on it \
                     about the X line through the rotation point + (x-offset, 0, z-offset) (the \
                     configuration's README; the documentation gives no formulas for this module)"
                ));
            }
            FIVE_AXIS => {
                require(&axes, &['X', 'Y', 'Z', 'B', 'C'], &unsupported)?;
                k.linear = linear_letters(&axes, &unsupported)?;
                if axes.contains(&'W') {
                    k.quill = Some('W');
                }
                let pivot = pivot_length(hal, &mut k.notes, &unsupported)? * units.mm;
                // kins(9): "XYZBCW -- the W coordinate values (typically
                // used for tool motion) are incorporated into XYZ
                // positioning"; the README: `g0w10 ; retract w`, `g0b45 ;
                // tilt 45 deg wrt z`, `g0c30 ; rotate 30 deg in xy`,
                // `g0w-10 ; simulate drill`. So: C turns the head about
                // the vertical line through the pivot, B (carried by C)
                // tilts the tool away from Z, W moves the tool along its
                // own axis, + away from the work. The senses come from the
                // configuration's own program (5axisgui.ngc): at B = -90
                // it puts the tip at (r cos C, r sin C) and drills with W-
                // towards the C axis, which needs the tool (tip -> spindle)
                // along (cos C, sin C, 0) there: C right-handed about +Z,
                // B right-handed about -Y.
                let center = Vec3::new(0.0, 0.0, pivot);
                k.rotary = vec![
                    head_axis('C', Vec3::z(), center),
                    head_axis('B', -Vec3::y(), center),
                ];
                // switchkins.adoc: 5axiskins type0, identity type1; type2
                // userk.
                k.types = vec![KinsType::Tcp, KinsType::Identity, KinsType::User];
                k.notes.push(format!(
                    "{FIVE_AXIS}: head C on the carriage about +Z, B on it about -Y, both through \
                     the pivot {pivot} mm above the gauge point; W along the tool (kins(9) 5axiskins, \
                     the configuration's README and 5axisgui.ngc; docs/functions.md gives the reading)"
                ));
            }
            TRSRN_ACB | TRSRN_BCA => {
                // Sigma1912's kinematics notebooks for this machine family
                // (5axis-twp/spindle-nutating-rotary_table-rotary/*-docs):
                // Q = T(-r)·T(c)·R_w·T(P)·T(r)·R_p·T(d)·R_s·T(l)·T(t)·0.
                // The XYZBCA-SNRTR notebook is the machine LinuxCNC calls
                // xyzacb_trsrn (table A about X, primary C, secondary B
                // nutating in the YZ plane; y/z pivot, y/z rotation axis),
                // the XYZACB-SNRTR notebook the one it calls xyzbca_trsrn
                // (table B about Y, primary C, secondary A nutating in the
                // XZ plane; x/z pivot, x/z rotation axis).
                let acb = module == TRSRN_ACB;
                let (table, secondary) = if acb { ('A', 'B') } else { ('B', 'A') };
                require(&axes, &['X', 'Y', 'Z', 'A', 'B', 'C'], &unsupported)?;
                k.linear = linear_letters(&axes, &unsupported)?;
                let prefix = format!("{module}_kins");
                let geometry = Pins::new(hal, &prefix, units.mm, ini_path);
                let across = if acb { 'y' } else { 'x' };
                let nu = Pins::new(hal, &prefix, 1.0, ini_path).value("nut-angle", &mut k.notes)?;
                if !(0.0..=90.0).contains(&nu) {
                    return Err(unsupported(&format!(
                        "nut-angle {nu}: the notebooks' nutation is 0 to 90 degrees from the vertical"
                    )));
                }
                let pivot_across = geometry.value(&format!("{across}-pivot"), &mut k.notes)?;
                let pivot_z = geometry.value("z-pivot", &mut k.notes)?;
                let dx = geometry.value("x-offset", &mut k.notes)?;
                let dy = geometry.value("y-offset", &mut k.notes)?;
                let rot_across = geometry.value(&format!("{across}-rot-axis"), &mut k.notes)?;
                let rot_z = geometry.value("z-rot-axis", &mut k.notes)?;
                tool_offset(hal, &prefix, "tool-offset-z", &mut k.notes, &unsupported)?;
                let (s, c) = nu.to_radians().sin_cos();
                // Unit vectors: the one the table turns about, the one the
                // pivot and the nutation lean along.
                let lean = if acb { Vec3::y() } else { Vec3::x() };
                // R_w is R_x(θ) (R_y(θ)) applied to the joint point: the
                // table turns the part by -θ about +X (+Y).
                let table_dir = if acb { -Vec3::x() } else { -Vec3::y() };
                let table_center = lean * rot_across + Vec3::z() * rot_z;
                // The secondary turns about v = (0, sin ν, cos ν) (or
                // (sin ν, 0, cos ν)) through the point the pivot lengths
                // lead to from the spindle nose; the primary about +Z
                // through that point plus the offsets.
                let pivot = lean * pivot_across + Vec3::z() * pivot_z;
                k.rotary = vec![
                    table_axis(table, table_dir, table_center),
                    head_axis('C', Vec3::z(), pivot + Vec3::new(dx, dy, 0.0)),
                    head_axis(secondary, lean * s + Vec3::z() * c, pivot),
                ];
                // The configuration's [HALUI] note and remap_subs: M428
                // (type 0) identity, M429 (type 1) TCP, M430 (type 2) TOOL.
                k.types = vec![KinsType::Identity, KinsType::Tcp, KinsType::Tool];
                k.notes.push(format!(
                    "{module}: table {table} about {} through the rotation axis \
                     point, head C (primary) about +Z through the pivot point + (x-offset, \
                     y-offset, 0), {secondary} (secondary, nutation {nu} degrees) about \
                     {} through the pivot point (pivot point relative to the gauge point); \
                     Sigma1912's XYZ{}-SNRTR kinematics notebook",
                    show(&table_dir),
                    show(&(lean * s + Vec3::z() * c)),
                    if acb { "BCA" } else { "ACB" }
                ));
            }
            "maxkins" => {
                return Err(unsupported(
                    "kins(9) describes it only in words (tilting head B, table rotary C, UVW \
                     in the rotated frame) and gives no geometry parameters to read; write a \
                     machine file with the head B and table C of your machine",
                ));
            }
            "scarakins" | "genserkins" | "pumakins" | "genhexkins" | "pentakins"
            | "three21kins" | "tripodkins" | "rotarydeltakins" | "lineardeltakins" | "rosekins" => {
                return Err(unsupported(
                    "a robot arm, hexapod or delta machine whose joints are not linear axes X, Y, Z \
                     with rotary axes on the head or the table; the machine model cannot hold it",
                ));
            }
            "corexykins" | "rotatekins" | "matrixkins" => {
                // Cartesian machines: X Y Z are the axes, whatever the
                // motors do.
                if axes.is_empty() {
                    axes = vec!['X', 'Y', 'Z'];
                    k.joints.clone_from(&axes);
                }
                let rotary: String = axes.iter().filter(|c| "ABC".contains(**c)).collect();
                if !rotary.is_empty() {
                    return Err(unsupported(&format!(
                        "rotary axes {rotary} without geometry in the configuration"
                    )));
                }
                k.linear = linear_letters(&axes, &unsupported)?;
            }
            other => {
                return Err(unsupported(&format!(
                    "`{other}` is not a kinematics module the importer knows (trivkins, \
                     xyzac-trt-kins, xyzbc-trt-kins, xyzab_tdr_kins, 5axiskins, xyzacb_trsrn, \
                     xyzbca_trsrn, corexykins, rotatekins, matrixkins)"
                )));
            }
        }
        Ok(k)
    }
}

/// A vector as `[x, y, z]` for the notes.
fn show(v: &Vec3) -> String {
    format!("[{}, {}, {}]", v.x + 0.0, v.y + 0.0, v.z + 0.0)
}

fn head_axis(name: char, axis: Vec3, center: Vec3) -> RotaryAxis {
    RotaryAxis {
        on: Side::Head,
        ..table_axis(name, axis, center)
    }
}

/// `5axiskins.pivot-length`: the distance from the B/C pivot to the tool
/// tip along the tool. The sim configuration nets it to a `sum2` of the
/// GUI's `pivot_len` and `motion.tooloffset.z`: the pivot-to-gauge-point
/// part is then not in the files ([`DEFAULT_PIVOT`], noted), the tool
/// part is fiveaxis's active H. A `setp` value is the pivot length itself.
fn pivot_length(
    hal: &Hal,
    notes: &mut Vec<String>,
    unsupported: &dyn Fn(&str) -> ImportError,
) -> Result<f64, ImportError> {
    let pin = format!("{FIVE_AXIS}.pivot-length");
    match hal.drive(&pin) {
        Drive::Set(v, origin)
        | Drive::Signal {
            value: Some((v, origin)),
            ..
        } => {
            if !(v.is_finite() && v.abs() <= MAX_FILE_MAGNITUDE) {
                return Err(unsupported(&format!("{pin} = {v} is not a length")));
            }
            notes.push(format!(
                "{pin} = {v}: {origin}; a fixed pivot length: LinuxCNC's 5axiskins then \
                 leaves G43's length out, fiveaxis's TCPC adds the active H (use H0 to match)"
            ));
            Ok(v)
        }
        Drive::Signal { name, .. } => {
            notes.push(format!(
                "{pin} is computed at run time (signal {name}: the GUI's pivot_len plus \
                 motion.tooloffset.z): the tool part is fiveaxis's active H; the GUI part is \
                 not in the configuration files and is written as {DEFAULT_PIVOT} mm (pivot \
                 at the gauge point). Set the head axes' center to [0, 0, your pivot length]"
            ));
            Ok(DEFAULT_PIVOT)
        }
        Drive::Unconnected => {
            notes.push(format!(
                "{pin}: not set in the HAL files (module default 0): pivot at the gauge point"
            ));
            Ok(0.0)
        }
    }
}

fn table_axis(name: char, axis: Vec3, center: Vec3) -> RotaryAxis {
    // `+ 0.0` writes a negative zero as 0.
    RotaryAxis {
        name,
        on: Side::Table,
        axis: Unit::new_normalize(axis.map(|v| v + 0.0)),
        center: center.map(|v| v + 0.0),
        limits: None,
        rollover: false,
        dynamics: Dynamics::ROTARY_DEFAULT,
    }
}

fn require(
    axes: &[char],
    needed: &[char],
    unsupported: &dyn Fn(&str) -> ImportError,
) -> Result<(), ImportError> {
    let missing: String = needed.iter().filter(|c| !axes.contains(c)).collect();
    let extra: String = axes
        .iter()
        .filter(|c| !needed.contains(c) && "ABC".contains(**c))
        .collect();
    if !missing.is_empty() {
        return Err(unsupported(&format!(
            "the coordinates lack {missing}: this module moves {}",
            needed.iter().collect::<String>()
        )));
    }
    if !extra.is_empty() {
        return Err(unsupported(&format!(
            "rotary axes {extra} besides the module's own, with no geometry in the configuration"
        )));
    }
    Ok(())
}

/// X, Y, Z then U, V, W among `axes`.
fn linear_letters(
    axes: &[char],
    unsupported: &dyn Fn(&str) -> ImportError,
) -> Result<Vec<char>, ImportError> {
    for needed in ['X', 'Y', 'Z'] {
        if !axes.contains(&needed) {
            return Err(unsupported(&format!(
                "no {needed} axis: the machine model needs X, Y and Z"
            )));
        }
    }
    Ok("XYZUVW".chars().filter(|c| axes.contains(c)).collect())
}

/// A kinematics module's HAL pins.
struct Pins<'a> {
    hal: &'a Hal,
    prefix: &'a str,
    scale: f64,
    file: &'a Path,
}

impl<'a> Pins<'a> {
    fn new(hal: &'a Hal, prefix: &'a str, scale: f64, file: &'a Path) -> Self {
        Self {
            hal,
            prefix,
            scale,
            file,
        }
    }

    /// The pin's static value, times the scale; 0 (the modules' start
    /// value) when nothing drives it.
    fn value(&self, name: &str, notes: &mut Vec<String>) -> Result<f64, ImportError> {
        let pin = format!("{}.{name}", self.prefix);
        match self.hal.drive(&pin) {
            Drive::Unconnected => {
                notes.push(format!("{pin}: not set in the HAL files, 0"));
                Ok(0.0)
            }
            Drive::Set(v, origin)
            | Drive::Signal {
                value: Some((v, origin)),
                ..
            } => {
                notes.push(format!("{pin} = {v}: {origin}"));
                Ok(v * self.scale)
            }
            Drive::Signal {
                name,
                pins,
                value: None,
            } => {
                let others: Vec<&String> = pins.iter().filter(|p| **p != pin).collect();
                Err(ImportError::file(
                    self.file,
                    format!(
                        "{pin} is driven by the signal {name} ({}), whose value the \
                         configuration does not set (no sets, no PyVCP start value): the \
                         geometry is not known",
                        others
                            .iter()
                            .map(|p| p.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ))
            }
        }
    }
}

/// The module's tool length pin: LinuxCNC's TCP kinematics see G43's
/// length when it is netted to `motion.tooloffset.z` (5-axis-kinematics.adoc,
/// "Tool-Length Compensation"). fiveaxis's TCPC takes the active H as the
/// tool length along the tool, which is the same thing.
fn tool_offset(
    hal: &Hal,
    prefix: &str,
    name: &str,
    notes: &mut Vec<String>,
    unsupported: &dyn Fn(&str) -> ImportError,
) -> Result<(), ImportError> {
    let pin = format!("{prefix}.{name}");
    match hal.drive(&pin) {
        Drive::Signal { pins, .. } if pins.iter().any(|p| p == "motion.tooloffset.z") => {
            notes.push(format!(
                "{pin} follows motion.tooloffset.z (G43's length): TCP mode is fiveaxis's TCPC with the active H"
            ));
            Ok(())
        }
        Drive::Set(v, _)
        | Drive::Signal {
            value: Some((v, _)),
            ..
        } if v != 0.0 => Err(unsupported(&format!(
            "{pin} is held at {v} instead of following motion.tooloffset.z: LinuxCNC's \
                 TCP kinematics would then put the tip {v} from the gauge point whatever G43 \
                 says, which fiveaxis's TCPC (tool length = the active H) cannot reproduce"
        ))),
        _ => {
            notes.push(format!(
                "{pin} is not netted to motion.tooloffset.z: LinuxCNC's TCP kinematics would \
                 ignore the tool length; fiveaxis's TCPC uses the active H"
            ));
            Ok(())
        }
    }
}

/// Soft limits, rollover and dynamics of a rotary axis from `[AXIS_L]`.
///
/// `WRAPPED_ROTARY = 1` makes a rollover axis (LinuxCNC: "the axis will
/// move 0-359.999 degrees"; note that LinuxCNC turns it in the direction
/// of the programmed sign where fiveaxis takes the shorter way). Limits
/// left out are LinuxCNC's ±1e99, no limit; limits beyond the machine
/// file's ±10⁶ degrees are no limit too. Any other limits, ±36000 for a
/// rotary table included, are written as they are: LinuxCNC moves C720
/// two turns, and so does fiveaxis on an axis with limits.
pub(crate) fn rotary_limits(
    ini: &Ini,
    axis: &mut RotaryAxis,
    units: Units,
    notes: &mut Vec<String>,
) -> Result<(), ImportError> {
    let section = format!("AXIS_{}", axis.name);
    let wrapped = ini.get(&section, "WRAPPED_ROTARY").is_some_and(|e| {
        matches!(
            e.value.to_ascii_lowercase().as_str(),
            "1" | "true" | "yes" | "on"
        )
    });
    let min = ini.get(&section, "MIN_LIMIT");
    let max = ini.get(&section, "MAX_LIMIT");
    if wrapped {
        axis.rollover = true;
        axis.limits = None;
        notes.push(format!(
            "{}: [{section}]WRAPPED_ROTARY = 1: rollover (LinuxCNC turns it the programmed sign's way, fiveaxis the shorter way)",
            axis.name
        ));
    } else {
        let lo = min
            .map(|e| e.number())
            .transpose()?
            .map(|v| v * units.degrees);
        let hi = max
            .map(|e| e.number())
            .transpose()?
            .map(|v| v * units.degrees);
        let name = axis.name;
        let mut bounded = |v: Option<f64>, key: &str| {
            v.map(|v| super::file_limit(v, name, &section, key, "degrees", notes))
        };
        let (lo, hi) = (bounded(lo, "MIN_LIMIT"), bounded(hi, "MAX_LIMIT"));
        match (lo, hi) {
            (Some(a), Some(b)) => {
                if a >= b {
                    let message = format!("MAX_LIMIT {b} is not above MIN_LIMIT {a}");
                    return Err(match max.or(min) {
                        Some(e) => e.error(message),
                        None => ImportError::file(Path::new(&section), message),
                    });
                }
                axis.limits = Some((a, b));
                notes.push(format!(
                    "{}: limits [{section}]MIN_LIMIT/MAX_LIMIT {a} .. {b}",
                    axis.name
                ));
            }
            (None, None) => notes.push(format!(
                "{}: [{section}] gives no limits (LinuxCNC: +/-1e99): no soft limits, not rollover",
                axis.name
            )),
            (a, b) => {
                axis.limits = Some((
                    a.unwrap_or(-MAX_FILE_MAGNITUDE),
                    b.unwrap_or(MAX_FILE_MAGNITUDE),
                ));
                notes.push(format!(
                    "{}: [{section}] limits on one side only; the other written as +/-{MAX_FILE_MAGNITUDE}",
                    axis.name
                ));
            }
        }
    }
    axis.dynamics = super::dynamics(
        ini,
        &section,
        units.degrees,
        Dynamics::ROTARY_DEFAULT,
        notes,
    )?;
    Ok(())
}
