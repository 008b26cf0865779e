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
    /// Notes on the geometry's sources.
    pub notes: Vec<String>,
}

/// The kinematics modules the importer turns into machines, and the
/// letters they take.
const TRT_AC: &str = "xyzac-trt-kins";
const TRT_BC: &str = "xyzbc-trt-kins";
const TDR_AB: &str = "xyzab_tdr_kins";

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
        for c in letters.chars().filter(|c| !c.is_whitespace()) {
            let c = c.to_ascii_uppercase();
            if !"XYZABCUVW".contains(c) {
                return Err(entry.error(format!("`{c}` is not a coordinate letter (XYZABCUVW)")));
            }
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
            notes: Vec::new(),
        };
        match module.as_str() {
            "trivkins" => {
                if axes.is_empty() {
                    axes = "XYZABCUVW".chars().collect();
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
            "5axiskins" => {
                return Err(unsupported(
                    "the bridge mill's W coordinate moves the tool along its own (tilted) axis, \
                     while a machine model's W moves parallel to Z; and its pivot length comes \
                     from the GUI model (5axisgui pivot_len) plus the tool length, so the HAL \
                     files do not give it. The B/C head itself is a head-head machine: write a \
                     machine file with type = \"head\", C then B, center = [0, 0, pivot length]",
                ));
            }
            "xyzacb_trsrn" | "xyzbca_trsrn" => {
                return Err(unsupported(
                    "three rotary axes (a rotary table and a nutating spindle head with two axes, \
                     A B C); the machine model holds at most two rotary axes",
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
                     xyzac-trt-kins, xyzbc-trt-kins, xyzab_tdr_kins, corexykins, rotatekins, \
                     matrixkins)"
                )));
            }
        }
        Ok(k)
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
            "rotary axes {extra} besides the module's own: the machine model holds two rotary axes"
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
        let bounded = |v: Option<f64>| v.filter(|v| v.abs() <= MAX_FILE_MAGNITUDE);
        match (bounded(lo), bounded(hi)) {
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
