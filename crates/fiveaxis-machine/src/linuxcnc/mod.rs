//! Importing a LinuxCNC machine configuration (`fiveaxis machines import
//! CONFIG.ini`): the INI file, the static values of its HAL files, and the
//! kinematics module it names become a [`Machine`] with `control =
//! "linuxcnc"`.
//!
//! The importer is pure: every file is read through the caller's
//! [`Reader`], so the library does no I/O of its own. What each value is
//! taken from is kept as a note that [`Imported::to_toml`] writes as
//! comments above the machine file.
//!
//! * [`ini`]: the INI reader (sections, repeated keys, `#INCLUDE`).
//! * [`hal`]: `setp` / `sets` / `net` of the HAL files and commands.
//! * [`kins`]: each kinematics module's machine, with the source of its
//!   formulas.
//! * [`remap`]: the M codes of switchable kinematics (`REMAP = M428 …`).
//! * [`vismach`]: the machine's bodies from its vismach model (the
//!   `loadusr` Python script that draws it).

mod hal;
mod ini;
mod kins;
mod remap;
mod vismach;

use std::fmt;
use std::path::{Component, Path, PathBuf};

use crate::{
    Control, Dynamics, InputUnit, LinearAxis, MAX_FILE_MAGNITUDE, MAX_JERK, MCodes,
    MIN_ACCELERATION, MIN_JERK, MIN_VELOCITY, Machine, Parameters,
};

use ini::{Entry, Ini};

/// Reads a file of the configuration as text.
pub type Reader<'a> = dyn FnMut(&Path) -> std::io::Result<String> + 'a;

/// A configuration that cannot be imported: the file, the line when there
/// is one, and what is wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImportError {
    /// The file at fault (the INI file, an included file, a HAL file, a
    /// remap subroutine).
    pub file: PathBuf,
    /// 1-based line, when the error is about one line.
    pub line: Option<u32>,
    /// What is wrong.
    pub message: String,
}

impl ImportError {
    pub(crate) fn at(file: &Path, line: u32, message: impl Into<String>) -> Self {
        Self {
            file: file.to_path_buf(),
            line: Some(line),
            message: message.into(),
        }
    }

    pub(crate) fn file(file: &Path, message: impl Into<String>) -> Self {
        Self {
            file: file.to_path_buf(),
            line: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for ImportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{line}: {}", self.file.display(), self.message),
            None => write!(f, "{}: {}", self.file.display(), self.message),
        }
    }
}

impl std::error::Error for ImportError {}

/// An imported machine and what each of its values was taken from.
#[derive(Clone, Debug, PartialEq)]
pub struct Imported {
    /// The machine.
    pub machine: Machine,
    /// Where each value came from, and what was not read or differs from
    /// LinuxCNC, one line each.
    pub notes: Vec<String>,
    /// Lines written as comments under `[parameters]`: settings of the
    /// configuration that the machine file has no key for (yet).
    pub parameter_comments: Vec<String>,
}

impl Imported {
    /// The machine file, with the notes as comments at its top.
    /// [`Machine::from_toml`] reads it back to the same machine.
    pub fn to_toml(&self) -> String {
        let mut out = String::new();
        for note in &self.notes {
            for line in note.lines() {
                out.push_str("# ");
                out.push_str(line);
                out.push('\n');
            }
        }
        out.push_str("#\n");
        let file = self.machine.to_toml();
        match file.find("\n[parameters]") {
            Some(at) if !self.parameter_comments.is_empty() => {
                let end = file[at + 1..]
                    .find('\n')
                    .map_or(file.len(), |e| at + 1 + e + 1);
                out.push_str(&file[..end]);
                for line in &self.parameter_comments {
                    out.push_str("# ");
                    out.push_str(line);
                    out.push('\n');
                }
                out.push_str(&file[end..]);
            }
            _ => out.push_str(&file),
        }
        out
    }
}

/// Lengths and angles of the configuration's machine units in mm and
/// degrees.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Units {
    pub mm: f64,
    pub degrees: f64,
}

/// Imports the LinuxCNC configuration whose INI file is `ini_path`.
/// Relative paths inside the configuration are taken from the INI file's
/// folder; the paths written into the machine file (`tool_table`,
/// `subroutine_path`) are that folder joined with them, so an absolute
/// `ini_path` gives absolute paths.
pub fn import_linuxcnc(ini_path: &Path, read: &mut Reader<'_>) -> Result<Imported, ImportError> {
    let ini = Ini::read(ini_path, read)?;
    let folder = ini_path.parent().unwrap_or(Path::new("")).to_path_buf();
    let mut notes = vec![format!(
        "Imported from the LinuxCNC configuration {} by `fiveaxis machines import`.",
        ini_path.display()
    )];
    let units = units(&ini, ini_path, &mut notes)?;
    let hal = hal::Hal::read(&ini, &folder, read)?;
    let kins = kins::Kinematics::read(&ini, ini_path, &hal, units, &mut notes)?;

    let mut linear = Vec::new();
    for &letter in &kins.linear {
        let mut axis = linear_axis(&ini, letter, units, &mut notes)?;
        if kins.quill == Some(letter) {
            axis.along = crate::Along::Tool;
            notes.push(format!(
                "{letter}: along = \"tool\": {} moves the tool along its own axis",
                kins.module
            ));
        }
        linear.push(axis);
    }
    let mut rotary = kins.rotary.clone();
    for axis in &mut rotary {
        kins::rotary_limits(&ini, axis, units, &mut notes)?;
    }
    // RS274/NGC reads `X10` as 10 units: calculator-type input.
    let mut params = Parameters {
        input_unit: input_unit(&ini, units, &mut notes),
        decimal_point_input: true,
        ..Parameters::default()
    };
    if let Some(entry) = ini.get("EMCIO", "TOOL_TABLE") {
        let path = normalize(&folder.join(entry.value.trim()));
        notes.push(format!(
            "tool_table: [EMCIO]TOOL_TABLE = {} (line {})",
            entry.value, entry.line
        ));
        params.tool_table = Some(path.display().to_string());
    }
    params.subroutine_path = subroutine_path(&ini, &folder, &mut notes);
    let (m_codes, tcpc_at_start) = remap::m_codes(&ini, &folder, &hal, &kins, read, &mut notes)?;
    params.tcpc_at_start = tcpc_at_start;
    params.hal_pins = hal.pin_values();
    // The TWP remaps run on a machine with a pair of rotary axes.
    params.twp_remap = rotary.len() >= 2 && twp_remapped(&ini, &mut notes);
    params.ini_values = ini.numbers();
    notes.extend(hal.notes.iter().cloned());
    notes.extend(kins.notes.iter().cloned());
    // G28 / G30 positions are LinuxCNC parameters (5161…, 5181…) of the
    // parameter file, not read: 0, or the nearest limit when 0 is outside
    // an axis' limits (a machine file needs them inside).
    let limits = linear.iter().map(|a| Some((a.name, a.min, a.max))).chain(
        rotary
            .iter()
            .map(|r| r.limits.map(|(lo, hi)| (r.name, lo, hi))),
    );
    for (i, limit) in limits.enumerate() {
        if let Some((name, lo, hi)) = limit
            && !(lo..=hi).contains(&0.0)
        {
            let at = 0.0f64.clamp(lo, hi);
            params.reference_1[i] = at;
            params.reference_2[i] = at;
            notes.push(format!(
                "{name}: 0 is outside the limits: reference_1 and reference_2 (G28, G30) written at {at}"
            ));
        }
    }
    let name = ini
        .value("EMC", "MACHINE")
        .map_or_else(|| file_stem(ini_path), str::to_owned);
    let mut machine = Machine {
        name,
        control: Control::LinuxCnc,
        tool_direction: nalgebra::Unit::new_normalize(crate::Vec3::z()),
        linear,
        rotary,
        params,
        m_codes: MCodes::new(m_codes),
        bodies: Vec::new(),
        meshes: Vec::new(),
    };
    // The bodies, from the configuration's vismach model where it has one.
    let mapped = vismach::map_model(&folder, &hal, &kins.joints, &machine, units, read);
    machine.bodies = mapped.bodies;
    notes.extend(mapped.notes);
    // The machine file must read back: a value out of the file's bounds
    // is reported here, against the INI file, rather than later.
    Machine::from_toml(&machine.to_toml()).map_err(|e| {
        ImportError::file(
            ini_path,
            format!(
                "the imported machine is not a valid machine file: {}",
                e.message
            ),
        )
    })?;
    let parameter_comments = twp_axes(&ini);
    Ok(Imported {
        machine,
        notes,
        parameter_comments,
    })
}

/// Whether the configuration remaps the tilted-working-plane codes
/// (`REMAP = G68.2 …`, G68.3, G68.4, G53.1, G53.3, G53.6, G69): the
/// `twp_remap` parameter.
fn twp_remapped(ini: &Ini, notes: &mut Vec<String>) -> bool {
    const CODES: [&str; 7] = ["G68.2", "G68.3", "G68.4", "G53.1", "G53.3", "G53.6", "G69"];
    let remapped: Vec<(String, u32)> = ini
        .all("RS274NGC", "REMAP")
        .filter_map(|e| {
            let code = e.value.split_whitespace().next()?.to_ascii_uppercase();
            CODES.contains(&code.as_str()).then_some((code, e.line))
        })
        .collect();
    if remapped.is_empty() {
        return false;
    }
    let list: Vec<String> = remapped
        .iter()
        .map(|(c, l)| format!("{c} (line {l})"))
        .collect();
    notes.push(format!(
        "twp_remap = true: [RS274NGC]REMAP of {} (LinuxCNC's TWP remaps)",
        list.join(", ")
    ));
    true
}

/// `[TWP] PRIMARY / SECONDARY` as comment lines under `[parameters]`:
/// the kernel takes the head axes' roles from their order.
fn twp_axes(ini: &Ini) -> Vec<String> {
    let mut lines = Vec::new();
    for key in ["PRIMARY", "SECONDARY"] {
        if let Some(e) = ini.get("TWP", key) {
            lines.push(format!(
                "[TWP]{key} = {} (line {}): the {} spindle axis; the kernel takes the axes' \
                 roles from their order (bed outwards), so this is for information",
                e.value,
                e.line,
                key.to_ascii_lowercase()
            ));
        }
    }
    lines
}

fn file_stem(path: &Path) -> String {
    path.file_stem().map_or_else(
        || "LinuxCNC machine".into(),
        |s| s.to_string_lossy().into_owned(),
    )
}

/// `[TRAJ] LINEAR_UNITS` and `ANGULAR_UNITS` (`config/ini-config.adoc`,
/// [TRAJ] section): mm or inch; degrees, radians or grads.
fn units(ini: &Ini, ini_path: &Path, notes: &mut Vec<String>) -> Result<Units, ImportError> {
    let mm = match ini.get("TRAJ", "LINEAR_UNITS") {
        None => {
            return Err(ImportError::file(
                ini_path,
                "[TRAJ]LINEAR_UNITS is missing: the machine units (mm or inch) are not known",
            ));
        }
        Some(e) => match e.value.to_ascii_lowercase().as_str() {
            "mm" | "metric" => 1.0,
            "inch" | "in" | "imperial" => {
                notes.push(format!(
                    "[TRAJ]LINEAR_UNITS = {} (line {}): lengths converted from inches to mm (x 25.4)",
                    e.value, e.line
                ));
                25.4
            }
            _ => return Err(e.error("machine units are `mm` or `inch`")),
        },
    };
    let degrees = match ini.get("TRAJ", "ANGULAR_UNITS") {
        None => 1.0,
        Some(e) => match e.value.to_ascii_lowercase().as_str() {
            "deg" | "degree" | "degrees" => 1.0,
            "rad" | "radian" | "radians" => 180.0 / std::f64::consts::PI,
            "grad" | "gon" => 0.9,
            _ => return Err(e.error("angular units are deg, degree, rad, radian, grad or gon")),
        },
    };
    Ok(Units { mm, degrees })
}

/// A soft limit `value` (mm or degrees) read from `[section]key` as the
/// machine file holds it: beyond +/-[`MAX_FILE_MAGNITUDE`] (LinuxCNC
/// configurations write "unlimited" as a huge limit) it is written at that
/// bound, and the notes say so.
pub(crate) fn file_limit(
    value: f64,
    axis: char,
    section: &str,
    key: &str,
    unit: &str,
    notes: &mut Vec<String>,
) -> f64 {
    let bounded = value.clamp(-MAX_FILE_MAGNITUDE, MAX_FILE_MAGNITUDE);
    if bounded != value {
        notes.push(format!(
            "{axis}: [{section}]{key} {value} {unit} is beyond what a machine file holds (+/-{MAX_FILE_MAGNITUDE}): written as {bounded}"
        ));
    }
    bounded
}

/// A linear axis from `[AXIS_L]`: soft limits and dynamics.
fn linear_axis(
    ini: &Ini,
    letter: char,
    units: Units,
    notes: &mut Vec<String>,
) -> Result<LinearAxis, ImportError> {
    let section = format!("AXIS_{letter}");
    let min = ini.get(&section, "MIN_LIMIT");
    let max = ini.get(&section, "MAX_LIMIT");
    let mut limit = |e: Option<&Entry>, key: &str, side: f64| -> Result<f64, ImportError> {
        match e {
            Some(e) => Ok(file_limit(
                e.number()? * units.mm,
                letter,
                &section,
                key,
                "mm",
                notes,
            )),
            None => Ok(side * MAX_FILE_MAGNITUDE),
        }
    };
    let (lo, hi) = (
        limit(min, "MIN_LIMIT", -1.0)?,
        limit(max, "MAX_LIMIT", 1.0)?,
    );
    if let (Some(a), Some(b)) = (min, max) {
        if lo >= hi {
            return Err(b.error(format!(
                "MAX_LIMIT {} is not above MIN_LIMIT {}",
                b.value, a.value
            )));
        }
        notes.push(format!(
            "{letter}: limits [{section}]MIN_LIMIT/MAX_LIMIT (lines {}, {})",
            a.line, b.line
        ));
    } else {
        notes.push(format!(
            "{letter}: [{section}] gives no MIN_LIMIT or MAX_LIMIT (LinuxCNC: unlimited): +/-{MAX_FILE_MAGNITUDE} mm written"
        ));
    }
    let dynamics = dynamics(ini, &section, units.mm, Dynamics::LINEAR_DEFAULT, notes)?;
    Ok(LinearAxis {
        name: letter,
        min: lo,
        max: hi,
        dynamics,
        along: crate::Along::Parallel,
    })
}

/// `[AXIS_L] MAX_VELOCITY` (machine units per second: times 60 for the
/// machine file's per minute; LinuxCNC rapids at it too),
/// `MAX_ACCELERATION` and `MAX_JERK` (0: not limited).
pub(crate) fn dynamics(
    ini: &Ini,
    section: &str,
    scale: f64,
    default: Dynamics,
    notes: &mut Vec<String>,
) -> Result<Dynamics, ImportError> {
    let mut d = default;
    // In the machine file's units, within its bounds (a machine file
    // with the figure would not read).
    let bounded = |e: &Entry, factor: f64, [floor, ceiling]: [f64; 2], unit: &str| {
        let v = e.number()?;
        if v <= 0.0 {
            return Err(e.error("must be above 0"));
        }
        let v = v * factor;
        if !(floor..=ceiling).contains(&v) {
            return Err(e.error(format!(
                "is {v:e} {unit}: a machine has from {floor:e} to {ceiling:e}"
            )));
        }
        Ok(v)
    };
    match ini.get(section, "MAX_VELOCITY") {
        Some(e) => {
            d.max_velocity = bounded(
                e,
                scale * 60.0,
                [MIN_VELOCITY, MAX_FILE_MAGNITUDE],
                "mm/min (deg/min)",
            )?;
            d.rapid = d.max_velocity;
        }
        None => notes.push(format!(
            "[{section}] gives no MAX_VELOCITY: the machine file's default written"
        )),
    }
    match ini.get(section, "MAX_ACCELERATION") {
        Some(e) => {
            d.max_acceleration = bounded(
                e,
                scale,
                [MIN_ACCELERATION, MAX_FILE_MAGNITUDE],
                "mm/s² (deg/s²)",
            )?;
        }
        None => notes.push(format!(
            "[{section}] gives no MAX_ACCELERATION: the machine file's default written"
        )),
    }
    if let Some(e) = ini.get(section, "MAX_JERK") {
        let v = e.number()?;
        if v < 0.0 {
            return Err(e.error("must not be below 0"));
        }
        d.max_jerk = if v > 0.0 {
            Some(bounded(e, scale, [MIN_JERK, MAX_JERK], "mm/s³ (deg/s³)")?)
        } else {
            None
        };
    }
    Ok(d)
}

/// The unit of program lengths at start: the machine units, or G20 / G21
/// in `[RS274NGC] RS274NGC_STARTUP_CODE`.
fn input_unit(ini: &Ini, units: Units, notes: &mut Vec<String>) -> InputUnit {
    let mut unit = if units.mm == 1.0 {
        InputUnit::Millimetre
    } else {
        InputUnit::Inch
    };
    if let Some(e) = ini.get("RS274NGC", "RS274NGC_STARTUP_CODE") {
        let code = e.value.to_ascii_uppercase().replace(' ', "");
        let mut rest = code.as_str();
        while let Some(i) = rest.find("G2") {
            let after = &rest[i + 2..];
            let next = after.chars().next();
            let digit_after = after.chars().nth(1).is_some_and(|c| c.is_ascii_digit());
            match next {
                Some('0') if !digit_after => unit = InputUnit::Inch,
                Some('1') if !digit_after => unit = InputUnit::Millimetre,
                _ => {}
            }
            rest = after;
        }
        notes.push(format!(
            "input_unit: [RS274NGC]RS274NGC_STARTUP_CODE = {} (line {})",
            e.value, e.line
        ));
    }
    unit
}

/// `[DISPLAY] PROGRAM_PREFIX` (searched first, `config/ini-config.adoc`)
/// and the `:`-separated `[RS274NGC] SUBROUTINE_PATH`, relative to the INI
/// file's folder.
fn subroutine_path(ini: &Ini, folder: &Path, notes: &mut Vec<String>) -> Vec<String> {
    let mut folders: Vec<String> = Vec::new();
    let mut add = |f: &str| {
        let f = f.trim();
        if f.is_empty() {
            return;
        }
        let path = normalize(&folder.join(f)).display().to_string();
        if !folders.contains(&path) {
            folders.push(path);
        }
    };
    if let Some(e) = ini.get("DISPLAY", "PROGRAM_PREFIX") {
        add(&e.value);
        notes.push(format!(
            "subroutine_path: [DISPLAY]PROGRAM_PREFIX = {} (line {}) first, as LinuxCNC searches it",
            e.value, e.line
        ));
    }
    if let Some(e) = ini.get("RS274NGC", "SUBROUTINE_PATH") {
        for f in e.value.split(':') {
            add(f);
        }
        notes.push(format!(
            "subroutine_path: [RS274NGC]SUBROUTINE_PATH = {} (line {})",
            e.value, e.line
        ));
    }
    folders
}

/// `path` with `.` and `a/..` removed, without touching the file system.
pub(crate) fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                let last_is_normal =
                    matches!(out.components().next_back(), Some(Component::Normal(_)));
                if last_is_normal {
                    out.pop();
                } else if !matches!(out.components().next_back(), Some(Component::RootDir)) {
                    out.push("..");
                }
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_are_normalized_lexically() {
        assert_eq!(
            normalize(Path::new("/a/b/./c/../d")),
            PathBuf::from("/a/b/d")
        );
        assert_eq!(normalize(Path::new("a/../../b")), PathBuf::from("../b"));
        assert_eq!(normalize(Path::new("/../a")), PathBuf::from("/a"));
    }
}
