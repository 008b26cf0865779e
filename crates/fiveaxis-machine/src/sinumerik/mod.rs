//! Importing a SINUMERIK swivel data record (`fiveaxis machines import
//! FILE`, a file of `$TC_CARR<i>[<n>]=<value>` assignments): the record's
//! kinematics become a [`Machine`] with `control = "sinumerik"`.
//!
//! [`import_tc_carr`] reads the file ([`tc_carr`] gives its syntax), picks
//! one record (the one named, else the first), and turns it into one pair
//! (or one, or none) of rotary axes. Like the LinuxCNC importer it returns
//! an [`Imported`]: the machine, and a note of where every value came
//! from, which [`Imported::to_toml`] writes as comments above the file.
//!
//! # The fields read
//!
//! Field numbers and meanings are those of the SINUMERIK 828D Function
//! Manual 09/2011 (W1 "Toolholder with orientation capability", pp.
//! 1502–1503) and the SINUMERIK ONE programming manual 12/2019 p. 779:
//!
//! | fields | meaning | read as |
//! |---|---|---|
//! | 1–3, 4–6, 15–17, 18–20 | offset vectors l1, l2, l3, l4 (mm) | the axis lines (below) |
//! | 7–9, 10–12 | rotary axis vectors v1, v2 | `axis` of the two rotary axes |
//! | 21, 22 | axis identifiers of v1, v2 | names, after 35/36 |
//! | 23 | kinematic type T, P or M (case-insensitive; else alarm 14153); default T | which side each axis is on |
//! | 24, 25 | axis offsets: the axis position of the initial state | folded into the geometry (below) |
//! | 30/32, 31/33 | min / max of axis 1, axis 2; both 0: not checked | `min`, `max` (none when both 0) |
//! | 34 | record name | machine `name`, and what `record` picks |
//! | 35, 36 | axis names for the cycles | rotary axis names, first choice |
//! | 41–46, 55–60, 64, 65 | fine offsets of l1, l2, l3, l4 and of 24, 25 | added to their base field |
//!
//! Not read (noted when set): 13, 14 (the angles used when 21/22 name no
//! axis), 26–29 (Hirth tooth system), 37–40 (swivel identifier, retract
//! position). Fine offsets are added whenever they are in the file, as the
//! control does with setting data SD42974 `$SC_TOCARR_FINE_CORRECTION` = 1
//! (828D Function Manual, W1). An axis name must be A, B or C, or one of
//! them followed by digits (`B1`, read as B); otherwise the next source is
//! used, and last a name from the axis vector (the letter of its largest
//! component: X → A, Y → B, Z → C, ties to the earlier one, a letter in use
//! moving to the next free one). The record does not say whether an axis
//! is endless (that is machine data MD30310 `ROT_IS_MODULO`): an axis
//! without limits takes `rollover` from the base machine's axis of the
//! same name.
//!
//! # From the vector chain to the machine model
//!
//! The SINUMERIK describes each body of the machine by the vectors between
//! reference points (SINUMERIK 840D sl commissioning manual, swivel data,
//! 03/2013 p. 502; W1 08/2005 2-88: vectors in the head are positive from
//! the tool tip towards the toolholder reference point):
//!
//! * type T, both axes in the head: l3 from the tool adapter reference
//!   point (where the tool length starts, the model's spindle gauge point)
//!   to a point on axis 2; l2 from there to a point on axis 1; l1 from
//!   there to the toolholder reference point, which the machine axes X, Y,
//!   Z position. Normally l1 = −(l2 + l3) and the chain closes. l4 is not
//!   used (W1: ignored).
//! * type P, both axes in the table: l2 from the machine reference point
//!   (machine zero) to a point on axis 1; l3 from there to a point on
//!   axis 2; l4 from there to the table reference point, normally l4 =
//!   −(l2 + l3). l1 is not used.
//! * type M: axis 1 in the head, axis 2 in the table: l2 from the tool
//!   adapter to head axis 1 and l1 from there to the toolholder reference
//!   (l1 = −l2 normally); l3 from machine zero to table axis 2 and l4 from
//!   there to the table reference point (l4 = −l3 normally).
//!
//! Axis 2 is carried by axis 1. v1 and v2 are the axis directions in the
//! initial state, and a positive angle turns clockwise looking along the
//! vector (W1 08/2005 2-92), which is the right-hand rule about it; for an
//! axis that turns the workpiece the vector is entered reversed (the
//! commissioning manual's rule), i.e. it is the direction about which the
//! table itself turns by the right-hand rule. Both are exactly the meaning
//! of a rotary axis' `axis` in the machine model (`machine-model.md` §2),
//! so `axis` = v normalised, with no sign change on either side.
//!
//! **Head (T).** With R1, R2 the rotations by the angles about v1, v2 and
//! L the tool length along t0 = (0, 0, 1), the SINUMERIK's vector from the
//! tool tip to the toolholder reference point is l1 + R1·(l2 + R2·(l3 +
//! L·t0)) (each vector turned by the axes that carry it). Put the model's
//! gauge point G at the tool adapter reference with the angles at 0, G =
//! P_ref − (l1 + l2 + l3); then axis 1 passes through G + l2 + l3 and axis
//! 2 through G + l3. The model's head map about those lines
//! (`center1 = l2 + l3`, `center2 = l3`, relative to the gauge point, §3
//! `H = M1 ∘ M2`) gives `G + H(−L·t0) = P_ref − l1 − R1·l2 − R1·R2·l3 − R1·R2·L·t0`,
//! which is the SINUMERIK's tip. The model's X, Y, Z are therefore the
//! SINUMERIK's minus l1 + l2 + l3, nothing when the chain closes.
//!
//! **Head (M).** The same with one axis: `center1 = l2`; X, Y, Z shift by
//! l1 + l2.
//!
//! **Table (P).** A point q of the workpiece, measured from the table
//! reference point, stands in the machine at l2 + R1·(l3 + R2·(l4 + q)).
//! The model's table map with `center1 = l2`, `center2 = l2 + l3` (machine
//! frame) takes the table-frame point p to l2 + R1·(l3 + R2·(p − l2 −
//! l3)), the same point for p = q + (l2 + l3 + l4). The model's table frame
//! is so the SINUMERIK's moved by l2 + l3 + l4, nothing when the chain
//! closes.
//!
//! **Table (M).** `center2 = l3`; the table frame moves by l3 + l4.
//!
//! **Axis offsets (24, 25).** With offsets o1, o2 the vectors describe the
//! machine at the axis positions o1, o2, and a position θ turns by θ − o.
//! The model describes its machine at position 0. Rotations about one line
//! commute, so M1(θ1 − o1) ∘ M2(θ2 − o2) = M1(θ1) ∘ M2′(θ2) ∘ E, where M2′
//! turns about axis 2's line carried to position 0 of axis 1 (that line
//! taken through M1(−o1)) and E = M2′(−o2) ∘ M1(−o1) is fixed. For a head,
//! E moves the tool: the model's `tool_direction` is E's rotation of t0,
//! and its gauge point moves by E(0) (every `center` is taken less E(0),
//! X, Y, Z shift with it). For a table, E moves the workpiece frame only:
//! the model's table frame is the SINUMERIK's taken through E.
//!
//! Each of these shifts is written in the notes when it is not zero.
//!
//! # Everything else
//!
//! The linear axes (with their reference positions) and the parameters
//! come from the `base` machine, else from the built-in SINUMERIK machine
//! [`SINUMERIK_BUILTIN`]; so do the M codes (less any clamp of an axis the
//! imported machine does not have), and the rotary axes' dynamics, by axis
//! name. Rotary reference positions are 0, or the nearest limit.

pub(crate) mod tc_carr;

use std::collections::BTreeMap;
use std::fmt;

use nalgebra::{IsometryMatrix3, Translation3, Unit};

use crate::{
    Control, Dynamics, Imported, MAX_AXES, MCodes, Machine, RotaryAxis, Side, Vec3, builtin,
    rotation,
};

use tc_carr::{Field, Record, Value};

/// The built-in machine whose linear axes, parameters and M codes an
/// import takes when no base machine is given.
pub const SINUMERIK_BUILTIN: &str = "sinumerik-dmu-bc";

/// The built-in machine [`SINUMERIK_BUILTIN`] as a swivel data record
/// (kinematic type M, record 1 named `DMU_BC`): [`import_tc_carr`] makes
/// of it a machine with the built-in's kinematics.
pub const SINUMERIK_BUILTIN_TC_CARR: &str = include_str!("../../data/sinumerik-dmu-bc.spf");

/// A swivel data file that cannot be imported: where and what is wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TcCarrError {
    /// 1-based line; 0 when the error is about the file as a whole (no
    /// record, no record of the name asked for).
    pub line: u32,
    /// 1-based column, in characters; 0 with line 0.
    pub column: u32,
    /// What is wrong.
    pub message: String,
}

impl TcCarrError {
    fn whole(message: impl Into<String>) -> Self {
        Self {
            line: 0,
            column: 0,
            message: message.into(),
        }
    }

    fn at(field: &Field, message: impl Into<String>) -> Self {
        Self {
            line: field.line,
            column: field.column,
            message: message.into(),
        }
    }
}

impl fmt::Display for TcCarrError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            write!(f, "{}", self.message)
        } else {
            write!(
                f,
                "line {}, column {}: {}",
                self.line, self.column, self.message
            )
        }
    }
}

impl std::error::Error for TcCarrError {}

/// Kinematic type (`$TC_CARR23`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// Both axes turn the tool.
    T,
    /// Both axes turn the part.
    P,
    /// Axis 1 turns the tool, axis 2 the part.
    M,
}

/// Imports one swivel data record of `text` as a machine. `record` picks
/// the record by its name (`$TC_CARR34`, compared without regard to case)
/// or number; without it the lowest-numbered record is taken and the
/// others are listed in the notes. `base` gives the linear axes,
/// parameters, M codes and rotary dynamics; without it they are those of
/// the built-in machine [`SINUMERIK_BUILTIN`].
pub fn import_tc_carr(
    text: &str,
    base: Option<&Machine>,
    record: Option<&str>,
) -> Result<Imported, TcCarrError> {
    let parsed = tc_carr::parse(text)?;
    let default_base;
    let base = match base {
        Some(b) => b,
        None => {
            default_base = builtin(SINUMERIK_BUILTIN)
                .ok_or_else(|| TcCarrError::whole("the built-in SINUMERIK machine is missing"))?;
            &default_base
        }
    };
    if parsed.records.is_empty() {
        return Err(TcCarrError::whole(
            "no swivel data record: the file assigns no $TC_CARR<i>[<n>] field",
        ));
    }
    let (index, rec) = pick(&parsed.records, record)?;
    let mut notes = vec![format!(
        "Imported from SINUMERIK swivel data record {index}{} by `fiveaxis machines import`.",
        text_field(rec, 34).map_or_else(String::new, |n| format!(" \"{n}\""))
    )];
    let others: Vec<String> = parsed
        .records
        .iter()
        .filter(|(n, _)| **n != index)
        .map(|(n, r)| {
            text_field(r, 34).map_or_else(|| format!("{n}"), |name| format!("{n} \"{name}\""))
        })
        .collect();
    if !others.is_empty() {
        notes.push(format!(
            "other records in the file, not imported (pick one with its name or number): {}",
            others.join(", ")
        ));
    }
    notes.extend(parsed.notes.iter().cloned());
    let mut b = Builder {
        rec,
        index,
        notes,
        base,
    };
    let machine = b.machine()?;
    // The machine file must read back: a value out of the file's bounds
    // (two parallel axes, a limit out of range) is reported against the
    // record here.
    if let Err(e) = Machine::from_toml(&machine.to_toml()) {
        let first = rec.values().next().expect("a record has a field");
        let at = rec.get(&23).unwrap_or(first);
        return Err(TcCarrError::at(
            at,
            format!(
                "record {index} does not make a valid machine: {}",
                e.message
            ),
        ));
    }
    Ok(Imported {
        machine,
        notes: b.notes,
        parameter_comments: Vec::new(),
    })
}

/// The record asked for, or the first.
fn pick<'a>(
    records: &'a BTreeMap<u32, Record>,
    wanted: Option<&str>,
) -> Result<(u32, &'a Record), TcCarrError> {
    let Some(wanted) = wanted else {
        let (n, r) = records.iter().next().expect("not empty");
        return Ok((*n, r));
    };
    let by_name = records.iter().find(|(_, r)| {
        text_field(r, 34).is_some_and(|name| name.trim().eq_ignore_ascii_case(wanted.trim()))
    });
    let by_number = || {
        let n: u32 = wanted.trim().parse().ok()?;
        records.get_key_value(&n)
    };
    match by_name.or_else(by_number) {
        Some((n, r)) => Ok((*n, r)),
        None => {
            let list: Vec<String> = records
                .iter()
                .map(|(n, r)| {
                    text_field(r, 34)
                        .map_or_else(|| format!("{n}"), |name| format!("{n} \"{name}\""))
                })
                .collect();
            Err(TcCarrError::whole(format!(
                "no swivel data record named `{wanted}`; the file has {}",
                list.join(", ")
            )))
        }
    }
}

fn text_field(rec: &Record, field: u8) -> Option<&str> {
    match rec.get(&field).map(|f| &f.value) {
        Some(Value::Text(t) | Value::Name(t)) if !t.trim().is_empty() => Some(t.trim()),
        _ => None,
    }
}

/// A rotary axis of the record on its way to the model.
struct Axis {
    /// 1 or 2, as the record numbers them.
    number: u8,
    on: Side,
    dir: Unit<Vec3>,
    /// A point on the line: relative to the gauge point (head) or machine
    /// frame (table).
    center: Vec3,
    offset: f64,
}

struct Builder<'a> {
    rec: &'a Record,
    index: u32,
    notes: Vec<String>,
    base: &'a Machine,
}

/// Base fields of the offset vectors and axis offsets that have a fine
/// offset (the field number + 40).
fn fine_field(field: u8) -> Option<u8> {
    matches!(field, 1..=6 | 15..=20 | 24 | 25).then_some(field + 40)
}

impl Builder<'_> {
    fn number(&self, field: u8) -> f64 {
        match self.rec.get(&field).map(|f| &f.value) {
            Some(Value::Number(v)) => *v,
            _ => 0.0,
        }
    }

    /// A field with its fine offset added.
    fn value(&self, field: u8) -> f64 {
        self.number(field) + fine_field(field).map_or(0.0, |f| self.number(f))
    }

    /// Where the fields `first`… `first + 2` (or one field) were read, for
    /// the notes.
    fn source(&self, fields: &[u8]) -> String {
        let mut lines: Vec<u32> = Vec::new();
        let mut fine = Vec::new();
        for &f in fields {
            if let Some(field) = self.rec.get(&f) {
                lines.push(field.line);
            }
            if let Some(ff) = fine_field(f)
                && let Some(field) = self.rec.get(&ff)
            {
                lines.push(field.line);
                fine.push(ff);
            }
        }
        let name = match fields {
            [one] => format!("$TC_CARR{one}[{}]", self.index),
            [first, .., last] => format!("$TC_CARR{first}–{last}[{}]", self.index),
            [] => String::new(),
        };
        lines.sort_unstable();
        lines.dedup();
        let mut s = name;
        if !fine.is_empty() {
            let list: Vec<String> = fine.iter().map(|f| format!("$TC_CARR{f}")).collect();
            s.push_str(&format!(" plus fine offsets {}", list.join(", ")));
        }
        if lines.is_empty() {
            s.push_str(" (not given: 0)");
        } else {
            let list: Vec<String> = lines.iter().map(u32::to_string).collect();
            s.push_str(&format!(
                " (line{} {})",
                if lines.len() > 1 { "s" } else { "" },
                list.join(", ")
            ));
        }
        s
    }

    fn vector(&self, first: u8) -> Vec3 {
        Vec3::new(
            self.value(first),
            self.value(first + 1),
            self.value(first + 2),
        )
    }

    fn kind(&mut self) -> Kind {
        match text_field(self.rec, 23) {
            Some("P") => Kind::P,
            Some("M") => Kind::M,
            Some(_) => Kind::T,
            None => {
                self.notes.push(format!(
                    "$TC_CARR23[{}] not given: kinematic type T, the control's default",
                    self.index
                ));
                Kind::T
            }
        }
    }

    fn machine(&mut self) -> Result<Machine, TcCarrError> {
        let kind = self.kind();
        let kind_name = match kind {
            Kind::T => "T (both rotary axes turn the tool)",
            Kind::P => "P (both rotary axes turn the part)",
            Kind::M => "M (axis 1 turns the tool, axis 2 the part)",
        };
        self.notes.push(format!("kinematic type {kind_name}"));
        let [l1, l2, l3, l4] = [1, 4, 15, 18].map(|f| self.vector(f));
        let v1 = self.vector(7);
        let v2 = self.vector(10);
        for (v, name, first) in [(l1, "l1", 1), (l2, "l2", 4), (l3, "l3", 15), (l4, "l4", 18)] {
            self.notes.push(format!(
                "{name} = {} from {}",
                show(&v),
                self.source(&[first, first + 1, first + 2])
            ));
        }
        let present1 = v1.norm() > 0.0;
        let present2 = v2.norm() > 0.0;
        if !present1 && present2 {
            let at = self.rec.get(&10).or_else(|| self.rec.get(&11));
            let at = at.or_else(|| self.rec.get(&12)).expect("v2 is set");
            return Err(TcCarrError::at(
                at,
                "v2 is set but v1 ($TC_CARR7–9) is zero: a single rotary axis must be axis 1",
            ));
        }
        let (o1, o2) = (self.value(24), self.value(25));
        let mut head: Vec<Axis> = Vec::new();
        let mut table: Vec<Axis> = Vec::new();
        let mut shift = Vec3::zeros();
        let mut table_shift = Vec3::zeros();
        let axis = |number, on, v: Vec3, center, offset| Axis {
            number,
            on,
            dir: Unit::new_normalize(v),
            center,
            offset,
        };
        match kind {
            Kind::T => {
                if present1 {
                    head.push(axis(1, Side::Head, v1, l2 + l3, o1));
                }
                if present2 {
                    head.push(axis(2, Side::Head, v2, l3, o2));
                }
                shift = l1 + l2 + l3;
                if l4 != Vec3::zeros() {
                    self.notes
                        .push("l4 is not used by kinematic type T (W1: ignored)".into());
                }
            }
            Kind::P => {
                if present1 {
                    table.push(axis(1, Side::Table, v1, l2, o1));
                }
                if present2 {
                    table.push(axis(2, Side::Table, v2, l2 + l3, o2));
                }
                table_shift = l2 + l3 + l4;
                if l1 != Vec3::zeros() {
                    self.notes
                        .push("l1 is not used by kinematic type P: left out".into());
                }
            }
            Kind::M => {
                if present1 {
                    head.push(axis(1, Side::Head, v1, l2, o1));
                }
                if present2 {
                    table.push(axis(2, Side::Table, v2, l3, o2));
                }
                shift = l1 + l2;
                table_shift = l3 + l4;
            }
        }
        // Axis offsets: carry the lines to position 0 (module docs).
        let head_e = fold_offsets(&mut head);
        let table_e = fold_offsets(&mut table);
        let t0 = Vec3::z();
        let tool_direction = Unit::new_normalize(head_e.rotation * t0);
        let gauge = head_e * nalgebra::Point3::origin();
        for a in &mut head {
            a.center -= gauge.coords;
        }
        let xyz_shift = shift - gauge.coords;
        if xyz_shift.norm() > 0.0 {
            self.notes.push(format!(
                "the head's vector chain does not close: the machine file's X, Y, Z are the SINUMERIK's minus {}",
                show(&xyz_shift)
            ));
        }
        if tool_direction.into_inner() != t0 {
            self.notes.push(format!(
                "the axis offsets turn the tool: tool_direction {} at the axis positions 0",
                show(&tool_direction)
            ));
        }
        if table_shift.norm() > 0.0 {
            self.notes.push(format!(
                "the table's vector chain does not close: the table frame's origin is the SINUMERIK table reference point moved by {}",
                show(&table_shift)
            ));
        }
        if table_e != IsometryMatrix3::identity() {
            self.notes.push(
                "the axis offsets turn the table: the table frame is the one at the axis positions 0"
                    .into(),
            );
        }
        for field in [13u8, 14, 26, 27, 28, 29, 37, 38, 39, 40] {
            if self.number(field) != 0.0 {
                self.notes.push(format!(
                    "{} = {} not used (angles without axes, Hirth teeth, swivel identifier, retract position)",
                    self.source(&[field]).split(" (").next().unwrap_or_default(),
                    self.number(field)
                ));
            }
        }
        let mut axes: Vec<Axis> = Vec::new();
        axes.extend(head);
        axes.extend(table);
        axes.sort_by_key(|a| a.number);
        let rotary = self.rotary(&axes)?;
        Ok(self.finish(rotary, tool_direction))
    }

    /// The model's rotary axes: names, limits, dynamics.
    fn rotary(&mut self, axes: &[Axis]) -> Result<Vec<RotaryAxis>, TcCarrError> {
        let mut names: Vec<char> = Vec::new();
        let mut out = Vec::new();
        for a in axes {
            let k = a.number;
            let name = self.axis_name(a, &names);
            names.push(name);
            let side = match a.on {
                Side::Head => "head",
                Side::Table => "table",
            };
            let (vf, offset_field) = if k == 1 { (7u8, 24u8) } else { (10, 25) };
            self.notes.push(format!(
                "{name}: axis {k} on the {side}, axis = v{k} from {}, center from the offset vectors",
                self.source(&[vf, vf + 1, vf + 2])
            ));
            if a.offset != 0.0 {
                self.notes.push(format!(
                    "{name}: axis offset {} from {}",
                    a.offset,
                    self.source(&[offset_field])
                ));
            }
            let (min_f, max_f) = (29 + k, 31 + k);
            let (lo, hi) = (self.number(min_f), self.number(max_f));
            let limits = if lo == 0.0 && hi == 0.0 {
                self.notes
                    .push(format!("{name}: $TC_CARR{min_f}/{max_f} both 0: no limits"));
                None
            } else if lo < hi {
                self.notes.push(format!(
                    "{name}: limits from {}, {}",
                    self.source(&[min_f]),
                    self.source(&[max_f])
                ));
                Some((lo, hi))
            } else {
                let at = self
                    .rec
                    .get(&max_f)
                    .or_else(|| self.rec.get(&min_f))
                    .expect("one limit is not 0");
                return Err(TcCarrError::at(
                    at,
                    format!(
                        "axis {k}: the maximum $TC_CARR{max_f} ({hi}) must be above the minimum $TC_CARR{min_f} ({lo})"
                    ),
                ));
            };
            let like = self.base.rotary.iter().find(|r| r.name == name);
            let dynamics = match like {
                Some(r) => {
                    self.notes.push(format!(
                        "{name}: dynamics from the base machine's {name} axis"
                    ));
                    r.dynamics
                }
                None => {
                    self.notes.push(format!(
                        "{name}: the base machine has no {name} axis: the machine file's default dynamics"
                    ));
                    Dynamics::ROTARY_DEFAULT
                }
            };
            let rollover = limits.is_none() && like.is_some_and(|r| r.rollover);
            if rollover {
                self.notes.push(format!(
                    "{name}: rollover = true as the base machine's {name} axis"
                ));
            }
            out.push(RotaryAxis {
                name,
                on: a.on,
                axis: a.dir,
                center: a.center,
                limits,
                rollover,
                dynamics,
            });
        }
        Ok(out)
    }

    /// The name of axis `a`: `$TC_CARR35`/`36`, else `21`/`22`, else from
    /// its direction.
    fn axis_name(&mut self, a: &Axis, taken: &[char]) -> char {
        let k = a.number;
        for field in [34 + k, 20 + k] {
            let Some(text) = text_field(self.rec, field) else {
                continue;
            };
            let upper = text.to_ascii_uppercase();
            let mut chars = upper.chars();
            let letter = chars.next().filter(|c| matches!(c, 'A' | 'B' | 'C'));
            let digits = chars.all(|c| c.is_ascii_digit());
            match letter {
                Some(c) if digits && !taken.contains(&c) => {
                    self.notes.push(format!(
                        "{c}: name from {} = \"{text}\"",
                        self.source(&[field])
                    ));
                    return c;
                }
                _ => self.notes.push(format!(
                    "axis {k}: {} = \"{text}\" is not a free rotary axis name A, B or C: not used",
                    self.source(&[field])
                )),
            }
        }
        let v = a.dir.into_inner().abs();
        let mut i = 0;
        for j in 1..3 {
            if v[j] > v[i] + 1e-12 {
                i = j;
            }
        }
        let letters = ['A', 'B', 'C'];
        let mut name = letters[i];
        let mut step = 0;
        while taken.contains(&name) && step < 3 {
            step += 1;
            name = letters[(i + step) % 3];
        }
        self.notes.push(format!(
            "{name}: axis {k} is named by its direction (no name in $TC_CARR{}/{})",
            34 + k,
            20 + k
        ));
        name
    }

    fn finish(&mut self, rotary: Vec<RotaryAxis>, tool_direction: Unit<Vec3>) -> Machine {
        let base = self.base;
        let linear = base.linear.clone();
        let mut params = base.params.clone();
        let first = linear.len();
        for refs in [&mut params.reference_1, &mut params.reference_2] {
            for (k, slot) in refs.iter_mut().enumerate().skip(first) {
                *slot = rotary
                    .get(k - first)
                    .and_then(|r| r.limits)
                    .map_or(0.0, |(lo, hi)| 0.0f64.clamp(lo, hi));
            }
        }
        debug_assert!(first + rotary.len() <= MAX_AXES);
        let names: Vec<char> = rotary.iter().map(|r| r.name).collect();
        let m_codes = MCodes::new(
            base.m_codes
                .iter()
                .filter(|(_, f)| f.axis().is_none_or(|axis| names.contains(&axis))),
        );
        self.notes.push(format!(
            "linear axes {}, their reference positions, the parameters and the M codes from the base machine \"{}\"",
            linear.iter().map(|a| a.name).collect::<String>(),
            base.name
        ));
        let name = text_field(self.rec, 34).map_or_else(
            || format!("SINUMERIK swivel data record {}", self.index),
            str::to_owned,
        );
        Machine {
            name,
            control: Control::Sinumerik,
            tool_direction,
            linear,
            rotary,
            params,
            m_codes,
            bodies: Vec::new(),
            meshes: Vec::new(),
        }
    }
}

/// Carries every axis line of one chain (outermost first) from the
/// initial state of the axis offsets to the positions 0, and returns the
/// fixed map E left over (module docs).
fn fold_offsets(chain: &mut [Axis]) -> IsometryMatrix3<f64> {
    let mut e = IsometryMatrix3::identity();
    for a in chain.iter_mut() {
        a.center = (e * nalgebra::Point3::from(a.center)).coords;
        a.dir = Unit::new_normalize(e.rotation * a.dir.into_inner());
        e = about(&a.dir, &a.center, -a.offset) * e;
    }
    e
}

/// Rotation by `degrees` about the line through `center` along `axis`.
fn about(axis: &Unit<Vec3>, center: &Vec3, degrees: f64) -> IsometryMatrix3<f64> {
    let r = rotation(axis, degrees);
    IsometryMatrix3::from_parts(Translation3::from(center - r * center), r)
}

fn show(v: &Vec3) -> String {
    format!("[{}, {}, {}]", v.x, v.y, v.z)
}
