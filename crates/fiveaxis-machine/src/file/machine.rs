//! Reading a machine file (`machine-model.md` §4).

use std::collections::BTreeMap;

use nalgebra::Unit;
use serde::Deserialize;
use toml::Spanned;

use super::{FileError, MAX_FILE_MAGNITUDE, Source, in_file_order};
use crate::{
    Along, Control, Dynamics, InputUnit, Joints, LinearAxis, MAX_AXES, MAX_M_CODE, MAX_ROTARY,
    MCodes, MFunction, Machine, MachineType, Parameters, ProgrammingFrame, RESERVED_M_CODES,
    RotaryAxis, RotaryChoice, Side, Vec3,
};

/// The linear axes that must come first, in this order.
const PRINCIPAL: [char; 3] = ['X', 'Y', 'Z'];
/// Optional linear axes parallel to X, Y, Z.
const PARALLEL: [char; 3] = ['U', 'V', 'W'];
/// Rotary axis names.
const ROTARY_NAMES: [char; 3] = ['A', 'B', 'C'];

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMachine {
    name: String,
    #[serde(rename = "type")]
    kind: Spanned<RawType>,
    #[serde(default)]
    control: RawControl,
    tool_direction: Option<Spanned<Vec<f64>>>,
    linear: Spanned<Vec<Spanned<RawLinear>>>,
    #[serde(default)]
    rotary: Vec<Spanned<RawRotary>>,
    #[serde(default)]
    parameters: RawParameters,
    #[serde(default)]
    m_codes: RawMCodes,
    #[serde(default)]
    body: Vec<Spanned<super::bodies::RawBody>>,
}

/// M number → function word, as written in `[m_codes]`.
type RawMCodes = BTreeMap<Spanned<String>, Spanned<String>>;

#[derive(Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum RawType {
    Head,
    Table,
    Mixed,
    None,
}

#[derive(Clone, Copy, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
enum RawControl {
    #[default]
    Fanuc30i,
    Fanuc16,
    Mitsubishi,
    Mazak,
    Haas,
    #[serde(rename = "linuxcnc")]
    LinuxCnc,
    Sinumerik,
    Heidenhain,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "lowercase")]
enum RawSide {
    Head,
    Table,
}

#[derive(Clone, Copy, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
enum RawFrame {
    #[default]
    Table,
    Workpiece,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "snake_case")]
enum RawChoice {
    Shortest,
    RotatingAxis,
    KeepTiltSign,
}

impl From<RawChoice> for RotaryChoice {
    fn from(raw: RawChoice) -> Self {
        match raw {
            RawChoice::Shortest => RotaryChoice::Shortest,
            RawChoice::RotatingAxis => RotaryChoice::RotatingAxis,
            RawChoice::KeepTiltSign => RotaryChoice::KeepTiltSign,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLinear {
    name: Spanned<String>,
    min: Spanned<f64>,
    max: Spanned<f64>,
    max_velocity: Option<Spanned<f64>>,
    rapid: Option<Spanned<f64>>,
    max_acceleration: Option<Spanned<f64>>,
    max_jerk: Option<Spanned<f64>>,
    along: Option<Spanned<RawAlong>>,
}

#[derive(Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum RawAlong {
    Parallel,
    Tool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRotary {
    name: Spanned<String>,
    on: RawSide,
    axis: Spanned<Vec<f64>>,
    center: Spanned<Vec<f64>>,
    min: Option<Spanned<f64>>,
    max: Option<Spanned<f64>>,
    #[serde(default)]
    rollover: bool,
    max_velocity: Option<Spanned<f64>>,
    rapid: Option<Spanned<f64>>,
    max_acceleration: Option<Spanned<f64>>,
    max_jerk: Option<Spanned<f64>>,
}

/// Axis name → position, as written in a reference position table.
type RawPositions = BTreeMap<Spanned<String>, Spanned<f64>>;

#[derive(Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawParameters {
    #[serde(default)]
    programming_frame: RawFrame,
    tcpc_option: Option<bool>,
    #[serde(default)]
    reference_1: RawPositions,
    #[serde(default)]
    reference_2: RawPositions,
    decimal_point_input: Option<bool>,
    least_input_increment: Option<Spanned<f64>>,
    input_unit: Option<RawInputUnit>,
    tool_posture_control: Option<bool>,
    rotary_choice: Option<RawChoice>,
    singular_zone: Option<Spanned<f64>>,
    tool_comp_3d_denominator: Option<Spanned<f64>>,
    cutter_startup: Option<RawStartup>,
    setup_error_choice: Option<RawSetupChoice>,
    singular_cone: Option<Spanned<f64>>,
    flip_angle: Option<Spanned<f64>>,
    chord_tolerance: Option<Spanned<f64>>,
    #[serde(default)]
    subroutine_path: Vec<String>,
    tool_table: Option<String>,
    tcpc_at_start: Option<Spanned<bool>>,
    twp_remap: Option<Spanned<bool>>,
    twp_priority: Option<Spanned<i64>>,
    additional_common_variables: Option<Spanned<i64>>,
    hal_pins: Option<Spanned<BTreeMap<String, f64>>>,
    ini: Option<Spanned<BTreeMap<String, BTreeMap<String, f64>>>>,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "lowercase")]
enum RawInputUnit {
    Mm,
    Inch,
}

impl From<RawInputUnit> for InputUnit {
    fn from(raw: RawInputUnit) -> Self {
        match raw {
            RawInputUnit::Mm => InputUnit::Millimetre,
            RawInputUnit::Inch => InputUnit::Inch,
        }
    }
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "snake_case")]
enum RawSetupChoice {
    KeepTiltSign,
    TableMotion,
}

#[derive(Clone, Copy, Deserialize)]
enum RawStartup {
    #[serde(rename = "A")]
    A,
    #[serde(rename = "B")]
    B,
}

impl Machine {
    /// Reads a machine file (`machine-model.md` §4).
    ///
    /// # Errors
    ///
    /// A [`FileError`] with the line, column and key of the first problem:
    /// bad TOML, an unknown or missing key, a value of the wrong type, or
    /// a value that breaks a rule of the format (axis names and order,
    /// limits, directions, `type` against the rotary axes…).
    pub fn from_toml(text: &str) -> Result<Machine, FileError> {
        let src = Source::new(text);
        let raw: RawMachine = src.deserialize()?;
        let linear = linear_axes(&src, &raw.linear)?;
        let rotary = rotary_axes(&src, &raw.rotary, linear.len())?;
        let tool_direction = match &raw.tool_direction {
            Some(t) => unit_vector(&src, t, "tool_direction")?,
            None => Vec3::z_axis(),
        };
        let mut machine = Machine {
            name: raw.name,
            control: raw.control.into(),
            tool_direction,
            linear,
            rotary,
            params: Parameters::default(),
            m_codes: MCodes::default(),
            bodies: Vec::new(),
            meshes: Vec::new(),
        };
        check_type(&src, &raw.kind, machine.machine_type())?;
        machine.params = parameters(&src, &raw.parameters, &machine)?;
        machine.m_codes = m_codes(&src, &raw.m_codes, &machine)?;
        let (bodies, meshes) = super::bodies::bodies(&src, &raw.body, &machine)?;
        machine.bodies = bodies;
        machine.meshes = meshes;
        Ok(machine)
    }
}

impl From<RawControl> for Control {
    fn from(raw: RawControl) -> Self {
        match raw {
            RawControl::Fanuc30i => Control::Fanuc30i,
            RawControl::Fanuc16 => Control::Fanuc16,
            RawControl::Mitsubishi => Control::Mitsubishi,
            RawControl::Mazak => Control::Mazak,
            RawControl::Haas => Control::Haas,
            RawControl::LinuxCnc => Control::LinuxCnc,
            RawControl::Sinumerik => Control::Sinumerik,
            RawControl::Heidenhain => Control::Heidenhain,
        }
    }
}

impl From<RawSide> for Side {
    fn from(raw: RawSide) -> Self {
        match raw {
            RawSide::Head => Side::Head,
            RawSide::Table => Side::Table,
        }
    }
}

impl From<RawFrame> for ProgrammingFrame {
    fn from(raw: RawFrame) -> Self {
        match raw {
            RawFrame::Table => ProgrammingFrame::Table,
            RawFrame::Workpiece => ProgrammingFrame::Workpiece,
        }
    }
}

/// The largest size of the additional common variables option: every one
/// of `#500000` … `#999999`.
const MAX_ADDITIONAL_COMMON: u32 = 500_000;

/// The one-letter axis name written in `name`, if it is one of `allowed`.
fn axis_letter(name: &Spanned<String>, allowed: &[char]) -> Option<char> {
    let mut chars = name.get_ref().chars();
    match (chars.next(), chars.next()) {
        (Some(c), None) if allowed.contains(&c) => Some(c),
        _ => None,
    }
}

fn linear_axes(
    src: &Source<'_>,
    raw: &Spanned<Vec<Spanned<RawLinear>>>,
) -> Result<Vec<LinearAxis>, FileError> {
    let mut axes: Vec<LinearAxis> = Vec::with_capacity(raw.get_ref().len());
    for item in raw.get_ref() {
        let name = linear_name(src, &item.get_ref().name, &axes)?;
        let (min, max) = limits(src, &item.get_ref().min, &item.get_ref().max)?;
        let raw = item.get_ref();
        let dynamics = dynamics(
            src,
            [
                &raw.max_velocity,
                &raw.rapid,
                &raw.max_acceleration,
                &raw.max_jerk,
            ],
            Dynamics::LINEAR_DEFAULT,
        )?;
        let along = match &raw.along {
            None => Along::Parallel,
            Some(a) if *a.get_ref() == RawAlong::Parallel => Along::Parallel,
            Some(a) => {
                if PRINCIPAL.contains(&name) {
                    return Err(src.at(
                        a,
                        "along",
                        format!("{name} moves along its own machine direction: only U, V or W may move `along = \"tool\"`"),
                    ));
                }
                if let Some(other) = axes.iter().find(|x| x.along == Along::Tool) {
                    return Err(src.at(
                        a,
                        "along",
                        format!(
                            "linear axis {} already moves along the tool: one quill at most",
                            other.name
                        ),
                    ));
                }
                Along::Tool
            }
        };
        axes.push(LinearAxis {
            name,
            min,
            max,
            dynamics,
            along,
        });
    }
    if axes.len() < PRINCIPAL.len() {
        let at = raw.get_ref().last().map_or(raw.span(), Spanned::span);
        let missing = PRINCIPAL[axes.len()];
        return Err(src.error(
            at,
            Some("linear"),
            format!("linear axis {missing} is missing: X, Y and Z are required"),
        ));
    }
    Ok(axes)
}

/// Checks the name of the next linear axis after `before`.
fn linear_name(
    src: &Source<'_>,
    name: &Spanned<String>,
    before: &[LinearAxis],
) -> Result<char, FileError> {
    let index = before.len();
    if let Some(&expected) = PRINCIPAL.get(index) {
        return match axis_letter(name, &[expected]) {
            Some(c) => Ok(c),
            None => Err(src.at(
                name,
                "name",
                format!(
                    "linear axis {} must be {expected}: X, Y, Z come first, in that order",
                    index + 1
                ),
            )),
        };
    }
    let Some(c) = axis_letter(name, &PARALLEL) else {
        return Err(src.at(
            name,
            "name",
            "a linear axis after X, Y, Z must be U, V or W",
        ));
    };
    if before.iter().any(|a| a.name == c) {
        return Err(src.at(name, "name", format!("linear axis {c} is given twice")));
    }
    Ok(c)
}

/// Finite `min` < `max`.
fn limits(
    src: &Source<'_>,
    min: &Spanned<f64>,
    max: &Spanned<f64>,
) -> Result<(f64, f64), FileError> {
    let lo = src.finite(min, "min")?;
    let hi = src.finite(max, "max")?;
    if lo < hi {
        Ok((lo, hi))
    } else {
        Err(src.at(
            max,
            "max",
            format!("`max` ({hi:?}) must be greater than `min` ({lo:?})"),
        ))
    }
}

fn rotary_axes(
    src: &Source<'_>,
    raw: &[Spanned<RawRotary>],
    linear: usize,
) -> Result<Vec<RotaryAxis>, FileError> {
    let mut axes: Vec<RotaryAxis> = Vec::with_capacity(raw.len());
    for item in raw {
        if axes.len() == MAX_ROTARY {
            return Err(src.error(
                item.span(),
                Some("rotary"),
                format!("at most {MAX_ROTARY} rotary axes"),
            ));
        }
        if linear + axes.len() == MAX_AXES {
            return Err(src.error(
                item.span(),
                Some("rotary"),
                format!("at most {MAX_AXES} axes in all"),
            ));
        }
        let axis = rotary_axis(src, item, &axes)?;
        if let Some(other) = axes
            .iter()
            .find(|a| a.axis.cross(&axis.axis).norm() <= PARALLEL_TOLERANCE)
        {
            return Err(src.at(
                &item.get_ref().axis,
                "axis",
                format!(
                    "rotary axes {} and {} turn about parallel lines: two rotary axes must point the tool in two different directions",
                    other.name, axis.name
                ),
            ));
        }
        axes.push(axis);
    }
    Ok(axes)
}

/// Sine of the smallest angle between two rotary axis directions.
const PARALLEL_TOLERANCE: f64 = 1e-9;

fn rotary_axis(
    src: &Source<'_>,
    item: &Spanned<RawRotary>,
    before: &[RotaryAxis],
) -> Result<RotaryAxis, FileError> {
    let raw = item.get_ref();
    let Some(name) = axis_letter(&raw.name, &ROTARY_NAMES) else {
        return Err(src.at(&raw.name, "name", "a rotary axis must be named A, B or C"));
    };
    if before.iter().any(|a| a.name == name) {
        return Err(src.at(
            &raw.name,
            "name",
            format!("rotary axis {name} is given twice"),
        ));
    }
    let rollover = raw.rollover;
    Ok(RotaryAxis {
        name,
        on: raw.on.into(),
        axis: unit_vector(src, &raw.axis, "axis")?,
        center: src.vec3(&raw.center, "center")?,
        limits: rotary_limits(src, item, rollover)?,
        rollover,
        dynamics: dynamics(
            src,
            [
                &raw.max_velocity,
                &raw.rapid,
                &raw.max_acceleration,
                &raw.max_jerk,
            ],
            Dynamics::ROTARY_DEFAULT,
        )?,
    })
}

/// Soft limits of a rotary axis: none on a rollover axis, both or neither
/// on any other.
fn rotary_limits(
    src: &Source<'_>,
    item: &Spanned<RawRotary>,
    rollover: bool,
) -> Result<Option<(f64, f64)>, FileError> {
    let raw = item.get_ref();
    match (&raw.min, &raw.max) {
        (None, None) => Ok(None),
        (Some(given), _) | (_, Some(given)) if rollover => {
            let key = if raw.min.is_some() { "min" } else { "max" };
            Err(src.at(given, key, "a rollover axis has no soft limits: remove `min` and `max` or set `rollover = false`"))
        }
        (Some(min), Some(max)) => limits(src, min, max).map(Some),
        (Some(_), None) => Err(src.error(
            item.span(),
            Some("max"),
            "missing field `max`: give both `min` and `max`, or neither for an unlimited axis",
        )),
        (None, Some(_)) => Err(src.error(
            item.span(),
            Some("min"),
            "missing field `min`: give both `min` and `max`, or neither for an unlimited axis",
        )),
    }
}

/// A non-zero 3-vector, normalised. A vector that is already of unit
/// length to within rounding is kept exactly as written, so that a file
/// written by [`Machine::to_toml`] reads back to the same bits.
pub(super) fn unit_vector(
    src: &Source<'_>,
    value: &Spanned<Vec<f64>>,
    key: &str,
) -> Result<Unit<Vec3>, FileError> {
    let v = src.vec3(value, key)?;
    let norm = v.norm();
    if !(norm.is_finite() && norm > 0.0) {
        return Err(src.at(value, key, format!("`{key}` must be a non-zero direction")));
    }
    if (norm - 1.0).abs() <= 4.0 * f64::EPSILON {
        Ok(Unit::new_unchecked(v))
    } else {
        Ok(Unit::new_unchecked(v / norm))
    }
}

fn check_type(
    src: &Source<'_>,
    kind: &Spanned<RawType>,
    actual: MachineType,
) -> Result<(), FileError> {
    let expected = match kind.get_ref() {
        RawType::Head => MachineType::Head,
        RawType::Table => MachineType::Table,
        RawType::Mixed => MachineType::Mixed,
        RawType::None => MachineType::None,
    };
    if expected == actual {
        return Ok(());
    }
    let found = match actual {
        MachineType::None => "there are no rotary axes (type \"none\")",
        MachineType::Head => "every rotary axis is on the head (type \"head\")",
        MachineType::Table => "every rotary axis is on the table (type \"table\")",
        MachineType::Mixed => "rotary axes are on both the head and the table (type \"mixed\")",
    };
    Err(src.at(
        kind,
        "type",
        format!("`type` does not match the rotary axes: {found}"),
    ))
}

fn parameters(
    src: &Source<'_>,
    raw: &RawParameters,
    machine: &Machine,
) -> Result<Parameters, FileError> {
    let defaults = Parameters::default();
    Ok(Parameters {
        programming_frame: raw.programming_frame.into(),
        tcpc_option: raw.tcpc_option.unwrap_or(defaults.tcpc_option),
        reference_1: positions(src, &raw.reference_1, machine, "reference_1")?,
        reference_2: positions(src, &raw.reference_2, machine, "reference_2")?,
        decimal_point_input: raw
            .decimal_point_input
            .unwrap_or(defaults.decimal_point_input),
        least_input_increment: match &raw.least_input_increment {
            Some(v) => increment(src, v)?,
            None => defaults.least_input_increment,
        },
        input_unit: raw.input_unit.map_or(defaults.input_unit, InputUnit::from),
        tool_posture_control: raw
            .tool_posture_control
            .unwrap_or(defaults.tool_posture_control),
        rotary_choice: raw.rotary_choice.map_or(
            RotaryChoice::default_for(machine.control),
            RotaryChoice::from,
        ),
        singular_zone: match &raw.singular_zone {
            Some(v) => zone(src, v)?,
            None => defaults.singular_zone,
        },
        tool_comp_3d_denominator: match &raw.tool_comp_3d_denominator {
            Some(v) => non_negative(src, v, "tool_comp_3d_denominator")?,
            None => defaults.tool_comp_3d_denominator,
        },
        cutter_startup_b: matches!(raw.cutter_startup, Some(RawStartup::B)),
        setup_error_table_motion: matches!(
            raw.setup_error_choice,
            Some(RawSetupChoice::TableMotion)
        ),
        singular_cone: match &raw.singular_cone {
            Some(v) => cone(src, v)?,
            None => defaults.singular_cone,
        },
        flip_angle: match &raw.flip_angle {
            Some(v) => positive(src, v, "flip_angle")?,
            None => defaults.flip_angle,
        },
        chord_tolerance: match &raw.chord_tolerance {
            Some(v) => positive(src, v, "chord_tolerance")?,
            None => defaults.chord_tolerance,
        },
        subroutine_path: raw.subroutine_path.clone(),
        tool_table: raw.tool_table.clone(),
        tcpc_at_start: match &raw.tcpc_at_start {
            Some(v) if *v.get_ref() => {
                if machine.control != Control::LinuxCnc {
                    return Err(src.at(
                        v,
                        "tcpc_at_start",
                        "only a linuxcnc machine runs TCP kinematics from power-on",
                    ));
                }
                if machine.rotary.is_empty() {
                    return Err(src.at(
                        v,
                        "tcpc_at_start",
                        "a machine without rotary axes has no TCP kinematics",
                    ));
                }
                true
            }
            _ => false,
        },
        twp_remap: match &raw.twp_remap {
            Some(v) if *v.get_ref() => {
                if machine.control != Control::LinuxCnc {
                    return Err(src.at(
                        v,
                        "twp_remap",
                        "the tilted-working-plane remap is a LinuxCNC configuration's: set control = \"linuxcnc\"",
                    ));
                }
                if machine.rotary.len() < 2 {
                    return Err(src.at(
                        v,
                        "twp_remap",
                        "the tilted working plane turns two rotary axes: the machine has fewer",
                    ));
                }
                true
            }
            _ => false,
        },
        twp_priority: match &raw.twp_priority {
            Some(v) => match *v.get_ref() {
                1 => 1,
                2 => 2,
                _ => {
                    return Err(src.at(
                        v,
                        "twp_priority",
                        "`twp_priority` is 1 (the primary rotary axis) or 2 (the secondary)",
                    ));
                }
            },
            None => defaults.twp_priority,
        },
        additional_common_variables: match &raw.additional_common_variables {
            Some(v) => match u32::try_from(*v.get_ref()) {
                Ok(n) if n <= MAX_ADDITIONAL_COMMON => n,
                _ => {
                    return Err(src.at(
                        v,
                        "additional_common_variables",
                        format!(
                            "`additional_common_variables` is how many of #500000… the option has: 0 to {MAX_ADDITIONAL_COMMON}"
                        ),
                    ));
                }
            },
            None => defaults.additional_common_variables,
        },
        hal_pins: match &raw.hal_pins {
            Some(pins) => {
                linuxcnc_only(src, pins, machine, "hal_pins")?;
                pins.get_ref()
                    .iter()
                    .map(|(name, v)| (name.to_ascii_lowercase(), *v))
                    .collect()
            }
            None => BTreeMap::new(),
        },
        ini_values: match &raw.ini {
            Some(sections) => {
                linuxcnc_only(src, sections, machine, "ini")?;
                sections
                    .get_ref()
                    .iter()
                    .flat_map(|(section, keys)| {
                        keys.iter().map(move |(key, v)| {
                            (format!("{section}]{key}").to_ascii_uppercase(), *v)
                        })
                    })
                    .collect()
            }
            None => BTreeMap::new(),
        },
    })
}

/// Values of LinuxCNC's HAL and INI files belong to a `linuxcnc` machine.
fn linuxcnc_only<T>(
    src: &Source<'_>,
    value: &Spanned<T>,
    machine: &Machine,
    key: &str,
) -> Result<(), FileError> {
    if machine.control == Control::LinuxCnc {
        Ok(())
    } else {
        Err(src.at(
            value,
            key,
            "only a linuxcnc machine reads HAL pins and INI values (#<_hal[…]>, #<_ini[…]>)",
        ))
    }
}

/// A reference position: axes left out are 0; every axis inside its soft
/// limits (a machine cannot have its reference position beyond them).
fn positions(
    src: &Source<'_>,
    raw: &RawPositions,
    machine: &Machine,
    key: &str,
) -> Result<Joints, FileError> {
    let mut joints = [0.0; MAX_AXES];
    for (name, value) in in_file_order(raw) {
        let index = axis_letter(name, &['X', 'Y', 'Z', 'U', 'V', 'W', 'A', 'B', 'C'])
            .and_then(|c| machine.axis_index(c));
        let Some(index) = index else {
            return Err(src.at(
                name,
                name.get_ref(),
                format!("the machine has no axis named `{}`", name.get_ref()),
            ));
        };
        let v = src.finite(value, name.get_ref())?;
        let limits = match index.checked_sub(machine.linear.len()) {
            None => Some((machine.linear[index].min, machine.linear[index].max)),
            Some(k) => machine.rotary[k]
                .limits
                .filter(|_| !machine.rotary[k].rollover),
        };
        if let Some((min, max)) = limits
            && !(min..=max).contains(&v)
        {
            return Err(src.at(
                value,
                key,
                format!(
                    "`{key}` puts {} at {v}, outside its soft limits {min} to {max}",
                    name.get_ref()
                ),
            ));
        }
        joints[index] = v;
    }
    // Axes left out are at 0: that must be inside the limits too.
    for (index, name) in machine.axis_names().enumerate() {
        let given = in_file_order(raw)
            .iter()
            .any(|(n, _)| axis_letter(n, &[name]).is_some());
        let limits = match index.checked_sub(machine.linear.len()) {
            None => Some((machine.linear[index].min, machine.linear[index].max)),
            Some(k) => machine.rotary[k]
                .limits
                .filter(|_| !machine.rotary[k].rollover),
        };
        if !given
            && let Some((min, max)) = limits
            && !(min..=max).contains(&0.0)
        {
            let at = src.text.find(key).unwrap_or(0);
            return Err(src.error(
                at..at,
                Some(key),
                format!(
                    "`{key}` leaves {name} at 0, outside its soft limits {min} to {max}: give {name} in `{key}`"
                ),
            ));
        }
    }
    Ok(joints)
}

fn non_negative(src: &Source<'_>, value: &Spanned<f64>, key: &str) -> Result<f64, FileError> {
    let v = src.finite(value, key)?;
    if v >= 0.0 {
        Ok(v)
    } else {
        Err(src.at(value, key, format!("`{key}` must not be negative")))
    }
}

/// A number above 0 (and within the file bound).
pub(super) fn positive(
    src: &Source<'_>,
    value: &Spanned<f64>,
    key: &str,
) -> Result<f64, FileError> {
    let v = src.finite(value, key)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(src.at(value, key, format!("`{key}` must be greater than 0")))
    }
}

fn cone(src: &Source<'_>, value: &Spanned<f64>) -> Result<f64, FileError> {
    let key = "singular_cone";
    let v = src.finite(value, key)?;
    if (0.0..90.0).contains(&v) {
        Ok(v)
    } else {
        Err(src.at(
            value,
            key,
            format!("`{key}` must be at least 0 and below 90 degrees"),
        ))
    }
}

/// Largest jerk a file may give, per second cubed: jerks are large
/// numbers (an acceleration reached in milliseconds), beyond the bound of
/// lengths and angles.
pub const MAX_JERK: f64 = 1e9;

/// Smallest `max_velocity` or `rapid` a file may give, mm/min (deg/min for
/// rotary axes): the finest feed a control can be programmed with (FANUC's
/// F at IS-B is 0.001 mm/min). No real axis is slower; a slower figure is
/// a typo or a unit mix-up, and makes times that no report can print
/// (1e-300 mm/min gives 10^303 s).
pub const MIN_VELOCITY: f64 = 1e-3;

/// Smallest `max_acceleration` a file may give, mm/s² (deg/s²): real axes
/// accelerate at 100 mm/s² or more, a hundred thousand times this floor.
pub const MIN_ACCELERATION: f64 = 1e-3;

/// Smallest `max_jerk` a file may give, mm/s³ (deg/s³): real axes reach
/// their acceleration within a second or less, thousands of mm/s³.
pub const MIN_JERK: f64 = 1e-3;

/// A dynamics figure: finite, at least `floor` and at most `ceiling`, in
/// `unit`.
fn dynamic(
    src: &Source<'_>,
    value: &Spanned<f64>,
    key: &str,
    [floor, ceiling]: [f64; 2],
    unit: &str,
) -> Result<f64, FileError> {
    let v = *value.get_ref();
    if !v.is_finite() {
        return Err(src.at(value, key, format!("`{key}` must be a finite number")));
    }
    if v <= 0.0 {
        return Err(src.at(
            value,
            key,
            format!("`{key}` must be greater than 0: at least {floor:e} {unit}"),
        ));
    }
    if v < floor {
        return Err(src.at(
            value,
            key,
            format!(
                "`{key}` is below what a machine can have: at least {floor:e} {unit} (found {v:e})"
            ),
        ));
    }
    if v > ceiling {
        return Err(src.at(
            value,
            key,
            format!(
                "`{key}` is beyond what a machine can have: at most {ceiling:e} {unit} (found {v:e})"
            ),
        ));
    }
    Ok(v)
}

/// The dynamics keys of an axis (`max_velocity`, `rapid`,
/// `max_acceleration`, `max_jerk`): each within its floor
/// ([`MIN_VELOCITY`], [`MIN_ACCELERATION`], [`MIN_JERK`]) and ceiling
/// ([`MAX_FILE_MAGNITUDE`], [`MAX_JERK`]); `rapid` defaults to
/// `max_velocity`, the others to `default`'s.
fn dynamics(
    src: &Source<'_>,
    [velocity, rapid, acceleration, jerk]: [&Option<Spanned<f64>>; 4],
    default: Dynamics,
) -> Result<Dynamics, FileError> {
    let velocity_bounds = [MIN_VELOCITY, MAX_FILE_MAGNITUDE];
    let per_min = "mm/min (deg/min)";
    let max_velocity = match velocity {
        Some(v) => dynamic(src, v, "max_velocity", velocity_bounds, per_min)?,
        None => default.max_velocity,
    };
    Ok(Dynamics {
        max_velocity,
        rapid: match rapid {
            Some(v) => dynamic(src, v, "rapid", velocity_bounds, per_min)?,
            None => max_velocity,
        },
        max_acceleration: match acceleration {
            Some(v) => dynamic(
                src,
                v,
                "max_acceleration",
                [MIN_ACCELERATION, MAX_FILE_MAGNITUDE],
                "mm/s² (deg/s²)",
            )?,
            None => default.max_acceleration,
        },
        max_jerk: match jerk {
            Some(v) => Some(dynamic(
                src,
                v,
                "max_jerk",
                [MIN_JERK, MAX_JERK],
                "mm/s³ (deg/s³)",
            )?),
            None => default.max_jerk,
        },
    })
}

fn zone(src: &Source<'_>, value: &Spanned<f64>) -> Result<f64, FileError> {
    let key = "singular_zone";
    let v = src.finite(value, key)?;
    if (0.0..90.0).contains(&v) {
        Ok(v)
    } else {
        Err(src.at(
            value,
            key,
            format!("`{key}` must be at least 0 and below 90 degrees"),
        ))
    }
}

/// Finest least input increment accepted, mm (FANUC's finest is IS-E,
/// 0.000001 mm; a thousandth of that is room enough).
const MIN_INCREMENT: f64 = 1e-9;
/// Coarsest least input increment accepted, mm.
const MAX_INCREMENT: f64 = 1.0;

fn increment(src: &Source<'_>, value: &Spanned<f64>) -> Result<f64, FileError> {
    let key = "least_input_increment";
    let v = src.finite(value, key)?;
    if (MIN_INCREMENT..=MAX_INCREMENT).contains(&v) {
        Ok(v)
    } else {
        Err(src.at(
            value,
            key,
            format!("`{key}` must be between {MIN_INCREMENT:e} and {MAX_INCREMENT} mm (FANUC IS-A is 0.01, IS-B 0.001, IS-C 0.0001)"),
        ))
    }
}

/// The `[m_codes]` table: keys are M numbers (0 to [`MAX_M_CODE`], not
/// M98 / M99), values the function words; a clamp names a rotary axis of
/// the machine.
fn m_codes(src: &Source<'_>, raw: &RawMCodes, machine: &Machine) -> Result<MCodes, FileError> {
    let mut entries: Vec<(u16, MFunction)> = Vec::with_capacity(raw.len());
    for (key, value) in in_file_order(raw) {
        let name = key.get_ref();
        let number = name
            .parse::<u16>()
            .ok()
            .filter(|n| *n <= MAX_M_CODE && name.bytes().all(|b| b.is_ascii_digit()));
        let Some(number) = number else {
            return Err(src.at(
                key,
                name,
                format!("`{name}` is not an M number: keys of [m_codes] are numbers 0 to {MAX_M_CODE}, e.g. 50 = \"signal\""),
            ));
        };
        if RESERVED_M_CODES.contains(&number) {
            return Err(src.at(
                key,
                name,
                format!(
                    "M{number} is the control's subprogram call or return and cannot be redeclared"
                ),
            ));
        }
        if entries.iter().any(|(n, _)| *n == number) {
            return Err(src.at(key, name, format!("M{number} is declared twice")));
        }
        let word = value.get_ref();
        let Some(function) = MFunction::parse(word) else {
            let known: Vec<String> = MFunction::words().map(|w| format!("\"{w}\"")).collect();
            return Err(src.at(
                value,
                name,
                format!(
                    "unknown M function `{word}` for M{number}: one of {}",
                    known.join(", ")
                ),
            ));
        };
        if let Some(axis) = function.axis()
            && !machine.rotary.iter().any(|r| r.name == axis)
        {
            return Err(src.at(
                value,
                name,
                format!("`{word}` for M{number}: the machine has no rotary axis named {axis}"),
            ));
        }
        entries.push((number, function));
    }
    Ok(MCodes::new(entries))
}
