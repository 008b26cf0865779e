//! Reading an offsets file (`machine-model.md` §5).

use std::collections::BTreeMap;

use serde::Deserialize;
use toml::Spanned;

use super::machine::positive;
use super::{FileError, Source, in_file_order};
use crate::geometry::{Cutter, HolderStep, ToolShape};
use crate::offsets::{MAX_EXTENDED_WORK, MAX_HAAS_WORK, MAX_TOOL_OFFSET};
use crate::{Offsets, SetupErrorSet, ToolOffset, Vec3};

/// Highest workpiece setup error data set number (G54.4 P0 … P7).
const MAX_SETUP_ERROR: u32 = 7;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOffsets {
    #[serde(default)]
    tools: BTreeMap<Spanned<String>, RawTool>,
    #[serde(default)]
    work: BTreeMap<Spanned<String>, Spanned<Vec<f64>>>,
    #[serde(default)]
    setup_error: BTreeMap<Spanned<String>, RawSetupError>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTool {
    length: Option<Spanned<f64>>,
    length_wear: Option<Spanned<f64>>,
    radius: Option<Spanned<f64>>,
    radius_wear: Option<Spanned<f64>>,
    cutter: Option<Spanned<String>>,
    corner_radius: Option<Spanned<f64>>,
    point_angle: Option<Spanned<f64>>,
    taper_angle: Option<Spanned<f64>>,
    flute_length: Option<Spanned<f64>>,
    shank_diameter: Option<Spanned<f64>>,
    holder: Option<Spanned<Vec<Spanned<RawHolderStep>>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHolderStep {
    diameter: Spanned<f64>,
    length: Spanned<f64>,
    tip_diameter: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSetupError {
    x: Option<Spanned<f64>>,
    y: Option<Spanned<f64>>,
    z: Option<Spanned<f64>>,
    a: Option<Spanned<f64>>,
    b: Option<Spanned<f64>>,
    c: Option<Spanned<f64>>,
    #[serde(default)]
    table: BTreeMap<Spanned<String>, Spanned<f64>>,
}

/// Which work offset a `[work]` key names.
enum WorkSlot {
    /// `G54` … `G59`: index 0 … 5.
    Standard(usize),
    /// `G54.1 P1` … `P48`, `G154 P1` … `P99`, `G110` … `G129` (Haas's
    /// G154 P1 … P20): index 0 … 98.
    Extended(usize),
    /// `EXT`.
    External,
}

impl Offsets {
    /// Reads an offsets file (`machine-model.md` §5): `[tools]` by offset
    /// number or by name (a key that starts with a letter or `_`: a
    /// SINUMERIK tool called by name, given the offset numbers after the
    /// numbered ones) (`length`, `radius`, and the wear values
    /// `length_wear`, `radius_wear`, each 0 when left out), `[work]` (`G54` … `G59`,
    /// `"G54.1 P1"` … `"G54.1 P48"`, Haas's `"G154 P1"` … `"G154 P99"` and
    /// `G110` … `G129`, `EXT`) and `[setup_error.N]` data sets
    /// (N = 0 … 7). Anything not given is 0.
    ///
    /// # Errors
    ///
    /// A [`FileError`] with the line, column and key of the first problem:
    /// bad TOML, an unknown key, a value of the wrong type, an offset number
    /// out of range.
    pub fn from_toml(text: &str) -> Result<Offsets, FileError> {
        let src = Source::new(text);
        let raw: RawOffsets = src.deserialize()?;
        let mut offsets = Offsets::default();
        let is_name = |key: &Spanned<String>| {
            key.get_ref()
                .bytes()
                .next()
                .is_some_and(|b| b.is_ascii_alphabetic() || b == b'_')
        };
        for (key, tool) in in_file_order(&raw.tools) {
            if is_name(key) {
                continue;
            }
            let n = number(&src, key, 1, MAX_TOOL_OFFSET, "a tool offset number")?;
            if let Some(shape) = tool_shape(&src, tool)? {
                offsets.tool_shapes.insert(n, shape);
            }
            if offsets.tools.insert(n, tool_offset(&src, tool)?).is_some() {
                return Err(src.at(
                    key,
                    key.get_ref(),
                    format!("tool offset {n} is given twice"),
                ));
            }
        }
        // Named tools (`"FRA-D12" = {…}`, SINUMERIK `T="FRA-D12"`) take
        // the offset numbers after the highest numbered one, in file
        // order.
        for (key, tool) in in_file_order(&raw.tools) {
            if !is_name(key) {
                continue;
            }
            let n = offsets.tools.keys().next_back().map_or(1, |n| n + 1);
            if n > MAX_TOOL_OFFSET {
                return Err(src.at(
                    key,
                    key.get_ref(),
                    format!("no offset number is left for tool {:?}", key.get_ref()),
                ));
            }
            if let Some(shape) = tool_shape(&src, tool)? {
                offsets.tool_shapes.insert(n, shape);
            }
            offsets.tools.insert(n, tool_offset(&src, tool)?);
            offsets
                .tool_names
                .push((key.get_ref().to_ascii_uppercase(), n));
        }
        let mut extended_given = [false; MAX_HAAS_WORK as usize];
        for (key, value) in in_file_order(&raw.work) {
            let (v, beyond, count) = src.work_values(value, key.get_ref())?;
            if offsets.widest_work.as_ref().is_none_or(|(_, n)| count > *n) {
                offsets.widest_work = Some((key.get_ref().clone(), count));
            }
            match work_slot(&src, key)? {
                WorkSlot::Standard(i) => {
                    offsets.work[i] = v;
                    offsets.work_beyond[i] = beyond;
                }
                WorkSlot::Extended(i) => {
                    // `"G154 P7"` and `"G54.1 P7"` name one offset.
                    if std::mem::replace(&mut extended_given[i], true) {
                        return Err(src.at(
                            key,
                            key.get_ref(),
                            format!("extended work offset P{} is given twice", i + 1),
                        ));
                    }
                    offsets.extended_work[i] = v;
                    offsets.extended_work_beyond[i] = beyond;
                }
                WorkSlot::External => {
                    offsets.external = v;
                    offsets.external_beyond = beyond;
                }
            }
        }
        for (key, set) in in_file_order(&raw.setup_error) {
            let n = number(
                &src,
                key,
                0,
                MAX_SETUP_ERROR,
                "a setup error data set number",
            )?;
            if offsets
                .setup_error
                .insert(n, setup_error(&src, set)?)
                .is_some()
            {
                return Err(src.at(
                    key,
                    key.get_ref(),
                    format!("setup error data set {n} is given twice"),
                ));
            }
        }
        Ok(offsets)
    }
}

/// A key that must be a decimal number in `lo ..= hi`.
fn number(
    src: &Source<'_>,
    key: &Spanned<String>,
    lo: u32,
    hi: u32,
    what: &str,
) -> Result<u32, FileError> {
    let text = key.get_ref();
    let digits = !text.is_empty() && text.bytes().all(|b| b.is_ascii_digit());
    let parsed = if digits && (text == "0" || !text.starts_with('0')) {
        text.parse::<u32>().ok()
    } else {
        None
    };
    match parsed {
        Some(n) if (lo..=hi).contains(&n) => Ok(n),
        _ => Err(src.at(
            key,
            text,
            format!("`{text}` is not {what} ({lo} to {hi}, no leading zeros)"),
        )),
    }
}

fn tool_offset(src: &Source<'_>, raw: &RawTool) -> Result<ToolOffset, FileError> {
    Ok(ToolOffset {
        length: src.finite_or_zero(raw.length.as_ref(), "length")?,
        length_wear: src.finite_or_zero(raw.length_wear.as_ref(), "length_wear")?,
        radius: src.finite_or_zero(raw.radius.as_ref(), "radius")?,
        radius_wear: src.finite_or_zero(raw.radius_wear.as_ref(), "radius_wear")?,
    })
}

fn work_slot(src: &Source<'_>, key: &Spanned<String>) -> Result<WorkSlot, FileError> {
    let text = key.get_ref().as_str();
    let slot = match text {
        "EXT" => Some(WorkSlot::External),
        _ => standard_slot(text).or_else(|| extended_slot(text)),
    };
    slot.ok_or_else(|| {
        let msg = format!("`{text}` is not a work offset: use G54 … G59, \"G54.1 P1\" … \"G54.1 P{MAX_EXTENDED_WORK}\", \"G154 P1\" … \"G154 P{MAX_HAAS_WORK}\", G110 … G129 or EXT");
        src.at(key, text, msg)
    })
}

fn standard_slot(text: &str) -> Option<WorkSlot> {
    let digit = text.strip_prefix("G5")?;
    let i = ["4", "5", "6", "7", "8", "9"]
        .iter()
        .position(|d| *d == digit)?;
    Some(WorkSlot::Standard(i))
}

/// A decimal number without sign or leading zeros.
fn plain_number(text: &str) -> Option<u32> {
    if text.is_empty() || text.starts_with('0') || !text.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    text.parse().ok()
}

fn extended_slot(text: &str) -> Option<WorkSlot> {
    let (n, max) = if let Some(p) = text.strip_prefix("G54.1 P") {
        (plain_number(p)?, MAX_EXTENDED_WORK)
    } else if let Some(p) = text.strip_prefix("G154 P") {
        (plain_number(p)?, MAX_HAAS_WORK)
    } else {
        // Haas: G110 … G129 are G154 P1 … P20.
        let g = plain_number(text.strip_prefix('G')?)?;
        ((110..=129).contains(&g).then(|| g - 109)?, MAX_HAAS_WORK)
    };
    let index = usize::try_from(n).ok()?.checked_sub(1)?;
    (n <= max).then_some(WorkSlot::Extended(index))
}

fn setup_error(src: &Source<'_>, raw: &RawSetupError) -> Result<SetupErrorSet, FileError> {
    let f = |v: &Option<Spanned<f64>>, key| src.finite_or_zero(v.as_ref(), key);
    let origin = Vec3::new(f(&raw.x, "x")?, f(&raw.y, "y")?, f(&raw.z, "z")?);
    let rotation = Vec3::new(f(&raw.a, "a")?, f(&raw.b, "b")?, f(&raw.c, "c")?);
    let mut table = Vec::with_capacity(raw.table.len());
    for (name, value) in in_file_order(&raw.table) {
        let text = name.get_ref();
        let axis = match text.as_str() {
            "A" => 'A',
            "B" => 'B',
            "C" => 'C',
            _ => {
                return Err(src.at(
                    name,
                    text,
                    format!("`{text}` is not a rotary axis name (A, B or C)"),
                ));
            }
        };
        table.push((axis, src.finite(value, text)?));
    }
    Ok(SetupErrorSet {
        origin,
        rotation,
        table,
    })
}

/// Most steps of a tool holder.
const MAX_HOLDER_STEPS: usize = 16;

/// The tool's shape, when the file gives any of its keys: the cutter
/// (`cutter` flat, ball, bull, drill or taper, with its `corner_radius`,
/// `point_angle` or `taper_angle`), `flute_length`, `shank_diameter` and
/// the `holder` steps; checked against the tool's length and radius.
fn tool_shape(src: &Source<'_>, raw: &RawTool) -> Result<Option<ToolShape>, FileError> {
    let given = raw.cutter.is_some()
        || raw.corner_radius.is_some()
        || raw.point_angle.is_some()
        || raw.taper_angle.is_some()
        || raw.flute_length.is_some()
        || raw.shank_diameter.is_some()
        || raw.holder.is_some();
    if !given {
        return Ok(None);
    }
    let radius = match &raw.radius {
        Some(r) => src.finite(r, "radius")?,
        None => 0.0,
    };
    let length = match &raw.length {
        Some(l) => src.finite(l, "length")?,
        None => 0.0,
    };
    let only = |value: &Option<Spanned<f64>>, key: &str, cutter: &str| match value {
        Some(v) => Err(src.at(v, key, format!("`{key}` belongs to a {cutter} cutter"))),
        None => Ok(()),
    };
    let kind = raw.cutter.as_ref().map_or("flat", |c| c.get_ref().as_str());
    let at_cutter = |message: String| match &raw.cutter {
        Some(c) => src.at(c, "cutter", message),
        None => src.error(0..0, Some("cutter"), message),
    };
    let cutter = match kind {
        "flat" | "ball" => {
            only(&raw.corner_radius, "corner_radius", "bull")?;
            only(&raw.point_angle, "point_angle", "drill")?;
            only(&raw.taper_angle, "taper_angle", "taper")?;
            if kind == "flat" {
                Cutter::Flat
            } else {
                Cutter::Ball
            }
        }
        "bull" => {
            only(&raw.point_angle, "point_angle", "drill")?;
            only(&raw.taper_angle, "taper_angle", "taper")?;
            let Some(c) = &raw.corner_radius else {
                return Err(at_cutter("a bull cutter needs `corner_radius`".into()));
            };
            let corner = positive(src, c, "corner_radius")?;
            if corner > radius {
                return Err(src.at(
                    c,
                    "corner_radius",
                    format!("`corner_radius` {corner} is larger than the tool's radius {radius}"),
                ));
            }
            Cutter::BullNose { corner }
        }
        "drill" => {
            only(&raw.corner_radius, "corner_radius", "bull")?;
            only(&raw.taper_angle, "taper_angle", "taper")?;
            let angle = match &raw.point_angle {
                Some(a) => {
                    let v = src.finite(a, "point_angle")?;
                    if !(v > 0.0 && v < 180.0) {
                        return Err(src.at(
                            a,
                            "point_angle",
                            "`point_angle` is between 0 and 180 degrees",
                        ));
                    }
                    v
                }
                None => DEFAULT_POINT_ANGLE,
            };
            Cutter::Drill { point_angle: angle }
        }
        "taper" => {
            only(&raw.corner_radius, "corner_radius", "bull")?;
            only(&raw.point_angle, "point_angle", "drill")?;
            let Some(a) = &raw.taper_angle else {
                return Err(at_cutter(
                    "a taper cutter needs `taper_angle`, its half angle".into(),
                ));
            };
            let v = src.finite(a, "taper_angle")?;
            if !(v > 0.0 && v < 45.0) {
                return Err(src.at(
                    a,
                    "taper_angle",
                    "`taper_angle` (the half angle) is between 0 and 45 degrees",
                ));
            }
            Cutter::Taper { half_angle: v }
        }
        other => {
            return Err(at_cutter(format!(
                "`{other}`: a cutter is flat, ball, bull, drill or taper"
            )));
        }
    };
    let shank = match &raw.shank_diameter {
        Some(d) => positive(src, d, "shank_diameter")?,
        None => 2.0 * radius,
    };
    let mut holder = Vec::new();
    if let Some(steps) = &raw.holder {
        if let Some(extra) = steps.get_ref().get(MAX_HOLDER_STEPS) {
            return Err(src.at(
                extra,
                "holder",
                format!("a holder has at most {MAX_HOLDER_STEPS} steps"),
            ));
        }
        for step in steps.get_ref() {
            let s = step.get_ref();
            let diameter = positive(src, &s.diameter, "diameter")?;
            let tip_diameter = match &s.tip_diameter {
                Some(d) => positive(src, d, "tip_diameter")?,
                None => diameter,
            };
            holder.push(HolderStep {
                diameter,
                tip_diameter,
                length: positive(src, &s.length, "length")?,
            });
        }
    }
    let holder_length: f64 = holder.iter().map(|s| s.length).sum();
    let flute = match &raw.flute_length {
        Some(f) => positive(src, f, "flute_length")?,
        None => (length - holder_length).max(0.0),
    };
    if let Some(steps) = &raw.holder
        && holder_length + flute > length
    {
        return Err(src.at(steps, "holder", format!(
            "the holder ({holder_length} mm) and the cutting part ({flute} mm) are longer than the tool's length {length}: the gauge length is the holder, the shank and the cutting part"
        )));
    }
    Ok(Some(ToolShape {
        cutter,
        flute,
        shank,
        holder,
    }))
}

/// A twist drill's point angle, degrees.
const DEFAULT_POINT_ANGLE: f64 = 118.0;
