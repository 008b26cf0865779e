//! The variable store: R parameters, global user data (GUD), local user
//! data (LUD) per program level, and references (`VAR` parameters).

use std::collections::HashMap;

use fiveaxis_gcode::Span;

use super::eval::{Fault, convert, default_of};
use crate::{Type, Value};

/// Alarm for an array index out of range (first index). The control
/// raises 17020 "illegal array index 1" and 17030 for the second index
/// (alarm texts from a secondary source, a Siemens support note; not
/// confirmed in a Siemens diagnostics manual).
pub(crate) const ALARM_INDEX_1: u32 = 17020;
/// Alarm for an array's second index out of range.
pub(crate) const ALARM_INDEX_2: u32 = 17030;
/// Alarm for a name that is not defined (design brief §8, UNVERIFIED).
pub(crate) const ALARM_UNDEFINED: u32 = 12550;
/// Alarm for an illegal type conversion (design brief §8).
pub(crate) const ALARM_CONVERSION: u32 = 14096;

/// The most elements one array may hold: a bound of this interpreter
/// against a `DEF` that would exhaust memory, not the control's limit.
pub(crate) const MAX_ELEMENTS: usize = 1 << 20;

/// A defined variable: its type, its dimensions (none for a scalar) and
/// its elements in row-major order.
#[derive(Clone, Debug)]
pub(crate) struct Variable {
    pub ty: Type,
    pub dims: Vec<usize>,
    pub data: Vec<Value>,
}

impl Variable {
    /// A variable of `ty` with `dims`, every element the type's default.
    pub fn new(ty: Type, dims: Vec<usize>) -> Self {
        let count = dims.iter().product::<usize>().max(1);
        Self {
            ty,
            data: vec![default_of(ty); count],
            dims,
        }
    }
}

/// A local name: a variable of its own, or a reference to another
/// (a `VAR` parameter).
#[derive(Clone, Debug)]
pub(crate) enum Slot {
    Own(Variable),
    Alias(Place),
}

/// Where a variable lives.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Home {
    /// A local of the program level (index into the call stack).
    Level(usize, String),
    /// A global user variable.
    Global(String),
    /// An R parameter.
    R(usize),
    /// A system variable with its evaluated indices.
    System(String, Vec<Value>),
}

/// A variable or one element of it: the target of an assignment or of a
/// `VAR` parameter.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Place {
    pub home: Home,
    /// Indices into the variable, applied after any of an alias.
    pub index: Vec<usize>,
}

/// Every variable of the language the interpreter holds.
#[derive(Debug)]
pub(crate) struct Vars {
    pub globals: HashMap<String, Variable>,
    pub levels: Vec<HashMap<String, Slot>>,
    pub r: Vec<f64>,
}

impl Vars {
    pub fn new(r_parameters: usize) -> Self {
        Self {
            globals: HashMap::new(),
            levels: vec![HashMap::new()],
            r: vec![0.0; r_parameters],
        }
    }

    /// The home of a user variable by name, following aliases, from the
    /// program level `level` (locals first, then globals). The alias's
    /// own indices come back with it.
    pub fn resolve_user(&self, level: usize, name: &str) -> Option<Place> {
        if let Some(slot) = self.levels.get(level).and_then(|l| l.get(name)) {
            return Some(match slot {
                Slot::Own(_) => Place {
                    home: Home::Level(level, name.to_string()),
                    index: Vec::new(),
                },
                Slot::Alias(place) => place.clone(),
            });
        }
        self.globals.contains_key(name).then(|| Place {
            home: Home::Global(name.to_string()),
            index: Vec::new(),
        })
    }

    /// The variable at a home (not a system or R home).
    fn variable(&self, home: &Home) -> Option<&Variable> {
        match home {
            Home::Level(l, n) => match self.levels.get(*l)?.get(n)? {
                Slot::Own(v) => Some(v),
                Slot::Alias(_) => None,
            },
            Home::Global(n) => self.globals.get(n),
            Home::R(_) | Home::System(..) => None,
        }
    }

    fn variable_mut(&mut self, home: &Home) -> Option<&mut Variable> {
        match home {
            Home::Level(l, n) => match self.levels.get_mut(*l)?.get_mut(n)? {
                Slot::Own(v) => Some(v),
                Slot::Alias(_) => None,
            },
            Home::Global(n) => self.globals.get_mut(n),
            Home::R(_) | Home::System(..) => None,
        }
    }

    /// The element offset of `index` in `var`, or a fault.
    fn offset(var: &Variable, index: &[usize], span: Span) -> Result<usize, Fault> {
        if index.len() != var.dims.len() {
            // A string indexed once is one character of it.
            if var.dims.is_empty() && index.len() == 1 && matches!(var.ty, Type::String(_)) {
                return Ok(0);
            }
            return Err(Fault::new(
                Some(ALARM_INDEX_1),
                span,
                format!(
                    "the variable has {} dimension(s), {} index(es) given",
                    var.dims.len(),
                    index.len()
                ),
            ));
        }
        let mut offset = 0usize;
        for (k, (&i, &d)) in index.iter().zip(&var.dims).enumerate() {
            if i >= d {
                let alarm = if k == 0 { ALARM_INDEX_1 } else { ALARM_INDEX_2 };
                return Err(Fault::new(
                    Some(alarm),
                    span,
                    format!("index {i} out of range 0..{} (index {})", d - 1, k + 1),
                ));
            }
            offset = offset * d + i;
        }
        Ok(offset)
    }

    /// Reads a user or R variable at `place`.
    pub fn read(&self, place: &Place, span: Span) -> Result<Value, Fault> {
        match &place.home {
            Home::R(n) => self.r.get(*n).map(|x| Value::Real(*x)).ok_or_else(|| {
                Fault::new(
                    Some(ALARM_INDEX_1),
                    span,
                    format!("R parameter R{n} does not exist (R0 … R{})", self.last_r()),
                )
            }),
            Home::System(..) => Err(Fault::new(None, span, "system variable".into())),
            home => {
                let var = self.variable(home).ok_or_else(|| undefined(home, span))?;
                let at = Self::offset(var, &place.index, span)?;
                let value = var.data.get(at).cloned().unwrap_or(Value::Int(0));
                if var.dims.is_empty() && place.index.len() == 1 {
                    // One character of a string.
                    let Value::Str(s) = &value else {
                        return Ok(value);
                    };
                    let i = place.index[0];
                    return s.as_bytes().get(i).map(|c| Value::Char(*c)).ok_or_else(|| {
                        Fault::new(
                            Some(ALARM_INDEX_1),
                            span,
                            format!(
                                "index {i} past the end of a string of {} characters",
                                s.len()
                            ),
                        )
                    });
                }
                Ok(value)
            }
        }
    }

    fn last_r(&self) -> String {
        self.r
            .len()
            .checked_sub(1)
            .map_or("none".into(), |n| n.to_string())
    }

    /// Writes `value` (converted to the variable's type) at `place`.
    pub fn write(&mut self, place: &Place, value: Value, span: Span) -> Result<(), Fault> {
        match &place.home {
            Home::R(n) => {
                let x = convert(value, Type::Real, span)?;
                let last = self.last_r();
                let slot = self.r.get_mut(*n).ok_or_else(|| {
                    Fault::new(
                        Some(ALARM_INDEX_1),
                        span,
                        format!("R parameter R{n} does not exist (R0 … R{last})"),
                    )
                })?;
                *slot = x.as_f64().unwrap_or(0.0);
                Ok(())
            }
            Home::System(..) => Err(Fault::new(None, span, "system variable".into())),
            home => {
                let home = home.clone();
                let var = self
                    .variable_mut(&home)
                    .ok_or_else(|| undefined(&home, span))?;
                let at = Self::offset(var, &place.index, span)?;
                if var.dims.is_empty() && place.index.len() == 1 {
                    // One character of a string.
                    let c = match convert(value, Type::Char, span)? {
                        Value::Char(c) => c,
                        _ => 0,
                    };
                    let i = place.index[0];
                    if let Some(Value::Str(s)) = var.data.get_mut(0) {
                        let mut bytes = std::mem::take(s).into_bytes();
                        if i < bytes.len() {
                            bytes[i] = c;
                        } else {
                            return Err(Fault::new(
                                Some(ALARM_INDEX_1),
                                span,
                                format!(
                                    "index {i} past the end of a string of {} characters",
                                    bytes.len()
                                ),
                            ));
                        }
                        *s = String::from_utf8_lossy(&bytes).into_owned();
                    }
                    return Ok(());
                }
                let value = convert(value, var.ty, span)?;
                if let Some(slot) = var.data.get_mut(at) {
                    *slot = value;
                }
                Ok(())
            }
        }
    }

    /// Defines a local variable of the program level `level`.
    pub fn define_local(&mut self, level: usize, name: &str, slot: Slot) {
        if let Some(l) = self.levels.get_mut(level) {
            l.insert(name.to_string(), slot);
        }
    }
}

fn undefined(home: &Home, span: Span) -> Fault {
    let name = match home {
        Home::Level(_, n) | Home::Global(n) | Home::System(n, _) => n.clone(),
        Home::R(n) => format!("R{n}"),
    };
    Fault::new(
        Some(ALARM_UNDEFINED),
        span,
        format!("name {name} not defined"),
    )
}
