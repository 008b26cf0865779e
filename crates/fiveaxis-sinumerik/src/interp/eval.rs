//! Expressions: values, conversions, operators, the predefined functions
//! and the frame functions.

use std::cmp::Ordering;

use fiveaxis_gcode::Span;

use super::frames;
use super::vars::{ALARM_CONVERSION, ALARM_INDEX_1, ALARM_UNDEFINED, Home, Place, Vars};
use crate::{BinOp, Expr, ExprKind, System, Type, UnOp, Value, Var};

/// Alarm for an arithmetic error: division by zero, a function outside
/// its domain (`SQRT(-1)`, `ASIN(2)`), a value too large. The number is
/// our choice from the 14xxx interpreter range (the brief lists no alarm
/// for it).
pub(crate) const ALARM_ARITHMETIC: u32 = 14051;
/// Alarm for a syntax error (design brief §8, UNVERIFIED): also used for
/// a call with the wrong number of arguments.
pub(crate) const ALARM_SYNTAX: u32 = 12080;

/// The relative tolerance of REAL comparisons (ONE p444 says REAL
/// comparisons are made with a relative tolerance without giving it;
/// ours is 1e-12 of the larger magnitude).
pub const REAL_TOLERANCE: f64 = 1e-12;

/// An error inside a line, before the interpreter adds program and line.
#[derive(Clone, Debug)]
pub(crate) struct Fault {
    pub alarm: Option<u32>,
    pub span: Span,
    pub message: String,
}

impl Fault {
    pub fn new(alarm: Option<u32>, span: Span, message: String) -> Self {
        Self {
            alarm,
            span,
            message,
        }
    }
}

fn conversion(span: Span, what: &str) -> Fault {
    Fault::new(
        Some(ALARM_CONVERSION),
        span,
        format!("illegal type conversion: {what}"),
    )
}

fn arithmetic(span: Span, what: &str) -> Fault {
    Fault::new(
        Some(ALARM_ARITHMETIC),
        span,
        format!("arithmetic error: {what}"),
    )
}

/// The name of a value's type, for messages.
pub(crate) fn type_name(v: &Value) -> &'static str {
    match v {
        Value::Int(_) => "INT",
        Value::Real(_) => "REAL",
        Value::Bool(_) => "BOOL",
        Value::Char(_) => "CHAR",
        Value::Str(_) => "STRING",
        Value::Axis(_) => "AXIS",
        Value::Frame(_) => "FRAME",
    }
}

/// The value a variable of `ty` has before anything is written to it.
pub(crate) fn default_of(ty: Type) -> Value {
    match ty {
        Type::Int => Value::Int(0),
        Type::Real => Value::Real(0.0),
        Type::Bool => Value::Bool(false),
        Type::Char => Value::Char(0),
        Type::String(_) => Value::Str(String::new()),
        Type::Axis => Value::Axis(String::new()),
        Type::Frame => Value::Frame(Box::default()),
    }
}

/// The INT range of the control, ±(2^31 − 1) (840Di p62–63).
const INT_MAX: f64 = 2_147_483_647.0;

/// A number rounded to an INT, half away from zero.
fn round_int(x: f64, span: Span) -> Result<i64, Fault> {
    let r = x.round();
    if !r.is_finite() || r.abs() > INT_MAX {
        return Err(arithmetic(span, &format!("{x} is outside the INT range")));
    }
    Ok(r as i64)
}

/// `value` converted for a variable of `ty` (840Di p62–63; 828JP p23):
/// REAL to INT rounds; BOOL is 0 / 1 as a number, non-zero is TRUE; a
/// number becomes a string as `<<` writes it; a string is never a number
/// (alarm 14096). A string longer than `STRING[n]` is cut to n characters
/// (UNVERIFIED: the control may raise an alarm instead).
pub(crate) fn convert(value: Value, ty: Type, span: Span) -> Result<Value, Fault> {
    let from = type_name(&value);
    let fail = |to: &str| conversion(span, &format!("{from} to {to}"));
    Ok(match ty {
        Type::Int => match value {
            Value::Int(i) => Value::Int(round_int(i as f64, span)?),
            Value::Real(x) => Value::Int(round_int(x, span)?),
            Value::Bool(b) => Value::Int(i64::from(b)),
            Value::Char(c) => Value::Int(i64::from(c)),
            _ => return Err(fail("INT")),
        },
        Type::Real => match value.as_f64() {
            Some(x) => Value::Real(x),
            None => return Err(fail("REAL")),
        },
        Type::Bool => match value.as_f64() {
            Some(x) => Value::Bool(x != 0.0),
            None => return Err(fail("BOOL")),
        },
        Type::Char => match value {
            Value::Char(c) => Value::Char(c),
            Value::Str(s) if s.len() == 1 => Value::Char(s.as_bytes()[0]),
            Value::Int(_) | Value::Real(_) | Value::Bool(_) => {
                let x = value.as_f64().unwrap_or(0.0);
                let i = round_int(x, span)?;
                match u8::try_from(i) {
                    Ok(c) => Value::Char(c),
                    Err(_) => return Err(arithmetic(span, &format!("{i} is not a CHAR 0 … 255"))),
                }
            }
            _ => return Err(fail("CHAR")),
        },
        Type::String(n) => {
            let mut s = match value {
                Value::Frame(_) => return Err(fail("STRING")),
                other => text_of(&other),
            };
            let n = n as usize;
            if n > 0 && s.len() > n {
                let mut cut = n;
                while !s.is_char_boundary(cut) {
                    cut -= 1;
                }
                s.truncate(cut);
            }
            Value::Str(s)
        }
        Type::Axis => match value {
            Value::Axis(a) => Value::Axis(a),
            _ => return Err(fail("AXIS")),
        },
        Type::Frame => match value {
            Value::Frame(f) => Value::Frame(f),
            _ => return Err(fail("FRAME")),
        },
    })
}

/// A REAL as `<<` and string conversion write it: rounded to 10 decimal
/// places, trailing zeros and a trailing point dropped (`1.5`, `3` for
/// 3.0, `0.3` for 0.1+0.2). Our rule: the manuals found do not give the
/// control's format.
pub fn format_real(x: f64) -> String {
    if !x.is_finite() {
        return "0".to_string();
    }
    let mut s = format!("{x:.10}");
    if s.contains('.') {
        while s.ends_with('0') {
            s.pop();
        }
        if s.ends_with('.') {
            s.pop();
        }
    }
    if s == "-0" {
        s = "0".to_string();
    }
    s
}

/// A value written as text: numbers as [`format_real`] and decimal
/// INTs, BOOL as `1` / `0` (UNVERIFIED), CHAR as its character, an axis
/// by its name. A frame has no text (empty).
pub(crate) fn text_of(v: &Value) -> String {
    match v {
        Value::Int(i) => i.to_string(),
        Value::Real(x) => format_real(*x),
        Value::Bool(b) => if *b { "1" } else { "0" }.to_string(),
        Value::Char(c) => char::from(*c).to_string(),
        Value::Str(s) => s.clone(),
        Value::Axis(a) => a.clone(),
        Value::Frame(_) => String::new(),
    }
}

fn number(v: &Value, span: Span) -> Result<f64, Fault> {
    v.as_f64()
        .ok_or_else(|| conversion(span, &format!("{} used as a number", type_name(v))))
}

/// An INT-like value (INT, BOOL, CHAR) as an integer.
fn exact_int(v: &Value) -> Option<i64> {
    match v {
        Value::Int(i) => Some(*i),
        Value::Bool(b) => Some(i64::from(*b)),
        Value::Char(c) => Some(i64::from(*c)),
        _ => None,
    }
}

/// A value as a condition: a number is TRUE when not zero.
pub(crate) fn truth(v: &Value, span: Span) -> Result<bool, Fault> {
    match v {
        Value::Bool(b) => Ok(*b),
        other => Ok(number(other, span)? != 0.0),
    }
}

/// Two REALs equal within [`REAL_TOLERANCE`].
fn close(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= REAL_TOLERANCE * a.abs().max(b.abs())
}

/// How two values compare: numbers (REAL with the tolerance), strings and
/// characters by their bytes, axes by name; frames only for equality.
fn compare(a: &Value, b: &Value, op: BinOp, span: Span) -> Result<bool, Fault> {
    let ordering = match (a, b) {
        (Value::Str(_) | Value::Char(_), Value::Str(_) | Value::Char(_))
            if matches!(a, Value::Str(_)) || matches!(b, Value::Str(_)) =>
        {
            text_of(a).as_bytes().cmp(text_of(b).as_bytes())
        }
        (Value::Axis(x), Value::Axis(y)) => x.cmp(y),
        (Value::Axis(x), Value::Str(y)) | (Value::Str(y), Value::Axis(x)) => {
            if !matches!(op, BinOp::Eq | BinOp::Ne) {
                return Err(conversion(span, "axes are only compared for equality"));
            }
            return Ok((x.eq_ignore_ascii_case(y)) == (op == BinOp::Eq));
        }
        (Value::Frame(x), Value::Frame(y)) => {
            return match op {
                BinOp::Eq => Ok(x == y),
                BinOp::Ne => Ok(x != y),
                _ => Err(conversion(span, "frames are only compared for equality")),
            };
        }
        _ => {
            let (x, y) = (number(a, span)?, number(b, span)?);
            if close(x, y) {
                Ordering::Equal
            } else {
                x.partial_cmp(&y).unwrap_or(Ordering::Equal)
            }
        }
    };
    Ok(match op {
        BinOp::Eq => ordering == Ordering::Equal,
        BinOp::Ne => ordering != Ordering::Equal,
        BinOp::Gt => ordering == Ordering::Greater,
        BinOp::Lt => ordering == Ordering::Less,
        BinOp::Ge => ordering != Ordering::Less,
        _ => ordering != Ordering::Greater,
    })
}

/// A REAL result, checked to be a number.
fn real(x: f64, span: Span) -> Result<Value, Fault> {
    if x.is_finite() {
        Ok(Value::Real(x))
    } else {
        Err(arithmetic(span, "the result is not a finite number"))
    }
}

/// A binary operation on two values.
pub(crate) fn binary(op: BinOp, a: Value, b: Value, span: Span) -> Result<Value, Fault> {
    use BinOp as B;
    match op {
        B::Add | B::Sub | B::Mul => {
            if let (Some(x), Some(y)) = (exact_int(&a), exact_int(&b)) {
                let r = match op {
                    B::Add => x.checked_add(y),
                    B::Sub => x.checked_sub(y),
                    _ => x.checked_mul(y),
                };
                if let Some(r) = r {
                    return Ok(Value::Int(r));
                }
            }
            let (x, y) = (number(&a, span)?, number(&b, span)?);
            real(
                match op {
                    B::Add => x + y,
                    B::Sub => x - y,
                    _ => x * y,
                },
                span,
            )
        }
        B::Div => {
            let (x, y) = (number(&a, span)?, number(&b, span)?);
            if y == 0.0 {
                return Err(arithmetic(span, "division by zero"));
            }
            real(x / y, span)
        }
        B::IntDiv => {
            let (x, y) = (number(&a, span)?, number(&b, span)?);
            if y == 0.0 {
                return Err(arithmetic(span, "division by zero (DIV)"));
            }
            if let (Some(i), Some(j)) = (exact_int(&a), exact_int(&b)) {
                return Ok(Value::Int(i.checked_div(j).unwrap_or(0)));
            }
            Ok(Value::Int(round_int((x / y).trunc(), span)?))
        }
        B::Mod => {
            let (x, y) = (number(&a, span)?, number(&b, span)?);
            if y == 0.0 {
                return Err(arithmetic(span, "division by zero (MOD)"));
            }
            if let (Some(i), Some(j)) = (exact_int(&a), exact_int(&b)) {
                return Ok(Value::Int(i.checked_rem(j).unwrap_or(0)));
            }
            real(x % y, span)
        }
        B::BitAnd | B::BitXor | B::BitOr => {
            let x = round_int(number(&a, span)?, span)?;
            let y = round_int(number(&b, span)?, span)?;
            Ok(Value::Int(match op {
                B::BitAnd => x & y,
                B::BitXor => x ^ y,
                _ => x | y,
            }))
        }
        B::And | B::Or | B::Xor => {
            let (x, y) = (truth(&a, span)?, truth(&b, span)?);
            Ok(Value::Bool(match op {
                B::And => x && y,
                B::Or => x || y,
                _ => x != y,
            }))
        }
        B::Concat => {
            if matches!(a, Value::Frame(_)) || matches!(b, Value::Frame(_)) {
                return Err(conversion(span, "a FRAME has no text for <<"));
            }
            Ok(Value::Str(text_of(&a) + &text_of(&b)))
        }
        B::Eq | B::Ne | B::Gt | B::Lt | B::Ge | B::Le => {
            Ok(Value::Bool(compare(&a, &b, op, span)?))
        }
        B::Chain => match (a, b) {
            (Value::Frame(x), Value::Frame(y)) => Ok(Value::Frame(Box::new(frames::chain(&x, &y)))),
            _ => Err(conversion(span, "the chain operator : joins two frames")),
        },
    }
}

/// The context an expression is evaluated in.
pub(crate) struct Ctx<'a> {
    pub vars: &'a mut Vars,
    pub sys: &'a mut dyn System,
    /// The program level whose locals are visible.
    pub level: usize,
}

/// How an R parameter is named: `R` with an index, or `R<digits>`.
enum RForm {
    Indexed,
    Fixed(Option<usize>),
}

fn r_form(name: &str) -> Option<RForm> {
    let rest = name.strip_prefix('R')?;
    if rest.is_empty() {
        return Some(RForm::Indexed);
    }
    if rest.bytes().all(|b| b.is_ascii_digit()) {
        return Some(RForm::Fixed(rest.parse().ok()));
    }
    None
}

impl Ctx<'_> {
    /// Evaluates an expression.
    pub fn eval(&mut self, e: &Expr) -> Result<Value, Fault> {
        match &e.kind {
            ExprKind::Number(x) => Ok(literal(*x)),
            ExprKind::String(s) => Ok(Value::Str(s.clone())),
            ExprKind::Bool(b) => Ok(Value::Bool(*b)),
            ExprKind::Var(v) => self.read_var(v),
            ExprKind::Unary(op, inner) => {
                let v = self.eval(inner)?;
                match op {
                    UnOp::Plus => number(&v, e.span).map(|_| v),
                    UnOp::Neg => match v {
                        Value::Int(i) => Ok(Value::Int(-i)),
                        other => real(-number(&other, e.span)?, e.span),
                    },
                    UnOp::Not => Ok(Value::Bool(!truth(&v, e.span)?)),
                    UnOp::BitNot => Ok(Value::Int(!round_int(number(&v, e.span)?, e.span)?)),
                }
            }
            ExprKind::Binary(op, a, b) => {
                let a = self.eval(a)?;
                let b = self.eval(b)?;
                binary(*op, a, b, e.span)
            }
            ExprKind::Call(name, args) => self.function(name, args, e.span),
        }
    }

    /// An index of a system variable or an axis argument: a bare name
    /// that is no variable of the program is an axis (or another
    /// identifier such as `TR` the control knows), passed as
    /// [`Value::Axis`].
    pub fn loose(&mut self, e: &Expr) -> Result<Value, Fault> {
        if let ExprKind::Var(v) = &e.kind
            && v.indices.is_empty()
            && !v.name.starts_with('$')
            && r_form(&v.name).is_none()
            && self.vars.resolve_user(self.level, &v.name).is_none()
        {
            return Ok(Value::Axis(v.name.clone()));
        }
        self.eval(e)
    }

    fn index(&mut self, e: &Expr, k: usize) -> Result<usize, Fault> {
        let v = self.eval(e)?;
        let x = number(&v, e.span)?;
        let i = x.round();
        if !(0.0..=1e9).contains(&i) {
            let alarm = if k == 0 {
                ALARM_INDEX_1
            } else {
                super::vars::ALARM_INDEX_2
            };
            return Err(Fault::new(
                Some(alarm),
                e.span,
                format!("array index {} out of range", format_real(x)),
            ));
        }
        Ok(i as usize)
    }

    /// Where a variable lives: the target of an assignment or a `VAR`
    /// parameter. `None` when the name is no variable.
    pub fn place(&mut self, v: &Var) -> Result<Option<Place>, Fault> {
        if v.name.starts_with('$') {
            let mut idx = Vec::with_capacity(v.indices.len());
            for e in &v.indices {
                idx.push(self.loose(e)?);
            }
            return Ok(Some(Place {
                home: Home::System(v.name.clone(), idx),
                index: Vec::new(),
            }));
        }
        if let Some(place) = self.vars.resolve_user(self.level, &v.name) {
            let mut place = place;
            for (k, e) in v.indices.iter().enumerate() {
                let i = self.index(e, k)?;
                place.index.push(i);
            }
            return Ok(Some(place));
        }
        match r_form(&v.name) {
            Some(RForm::Indexed) if v.indices.len() == 1 => {
                let n = self.index(&v.indices[0], 0)?;
                Ok(Some(Place {
                    home: Home::R(n),
                    index: Vec::new(),
                }))
            }
            Some(RForm::Fixed(n)) if v.indices.is_empty() => {
                let n = n.unwrap_or(usize::MAX);
                Ok(Some(Place {
                    home: Home::R(n),
                    index: Vec::new(),
                }))
            }
            _ => Ok(None),
        }
    }

    fn undefined(v: &Var) -> Fault {
        Fault::new(
            Some(ALARM_UNDEFINED),
            v.span,
            format!("name {} not defined", v.name),
        )
    }

    /// Reads a variable at a place.
    pub fn read_place(&mut self, place: &Place, span: Span) -> Result<Value, Fault> {
        if let Home::System(name, idx) = &place.home {
            return self
                .sys
                .read(name, idx)
                .map_err(|m| Fault::new(Some(ALARM_UNDEFINED), span, format!("{name}: {m}")));
        }
        self.vars.read(place, span)
    }

    /// Writes a variable at a place.
    pub fn write_place(&mut self, place: &Place, value: Value, span: Span) -> Result<(), Fault> {
        if let Home::System(name, idx) = &place.home {
            return self
                .sys
                .write(name, idx, value)
                .map_err(|m| Fault::new(Some(ALARM_UNDEFINED), span, format!("{name}: {m}")));
        }
        self.vars.write(place, value, span)
    }

    /// The value of a variable, an R parameter, a system variable or an
    /// axis name.
    pub fn read_var(&mut self, v: &Var) -> Result<Value, Fault> {
        if let Some(place) = self.place(v)? {
            return self.read_place(&place, v.span);
        }
        if v.indices.is_empty() && self.sys.is_axis(&v.name) {
            return Ok(Value::Axis(v.name.clone()));
        }
        Err(Self::undefined(v))
    }

    /// `target = value`.
    pub fn assign(&mut self, v: &Var, value: Value) -> Result<(), Fault> {
        match self.place(v)? {
            Some(place) => self.write_place(&place, value, v.span),
            None => Err(Self::undefined(v)),
        }
    }

    fn args(&mut self, args: &[Option<Expr>], span: Span) -> Result<Vec<Value>, Fault> {
        let mut out = Vec::with_capacity(args.len());
        for (k, a) in args.iter().enumerate() {
            match a {
                Some(e) => out.push(self.eval(e)?),
                None => {
                    return Err(Fault::new(
                        Some(ALARM_SYNTAX),
                        span,
                        format!("argument {} missing", k + 1),
                    ));
                }
            }
        }
        Ok(out)
    }

    /// A predefined function (ONE p387; 828JP p70, p74).
    fn function(&mut self, name: &str, args: &[Option<Expr>], span: Span) -> Result<Value, Fault> {
        if matches!(name, "CTRANS" | "CROT" | "CSCALE" | "CMIRROR" | "CFINE") {
            return self.frame_function(name, args, span);
        }
        let known = matches!(
            name,
            "SIN"
                | "COS"
                | "TAN"
                | "ASIN"
                | "ACOS"
                | "ATAN2"
                | "SQRT"
                | "ABS"
                | "POT"
                | "TRUNC"
                | "ROUND"
                | "ROUNDUP"
                | "LN"
                | "EXP"
                | "MINVAL"
                | "MAXVAL"
                | "BOUND"
                | "STRLEN"
                | "INDEX"
                | "RINDEX"
                | "SUBSTR"
                | "TOUPPER"
                | "TOLOWER"
                | "NUMBER"
                | "ISNUMBER"
                | "AXNAME"
                | "AXSTRING"
        );
        if !known {
            return Err(Fault::new(
                Some(ALARM_UNDEFINED),
                span,
                format!("function {name} not defined"),
            ));
        }
        if name == "AXSTRING"
            && let [Some(e)] = args
        {
            let v = self.loose(e)?;
            return match v {
                Value::Axis(a) => Ok(Value::Str(a)),
                other => Err(conversion(
                    span,
                    &format!("AXSTRING takes an AXIS, not {}", type_name(&other)),
                )),
            };
        }
        let (min, max) = match name {
            "ATAN2" | "MINVAL" | "MAXVAL" | "INDEX" | "RINDEX" => (2, 2),
            "BOUND" => (3, 3),
            "SUBSTR" => (2, 3),
            _ => (1, 1),
        };
        // Trailing omitted arguments are absent.
        let mut given = args.len();
        while given > 0 && args[given - 1].is_none() {
            given -= 1;
        }
        if given < min || given > max {
            return Err(Fault::new(
                Some(ALARM_SYNTAX),
                span,
                format!(
                    "{name} takes {} argument(s), {given} given",
                    if min == max {
                        min.to_string()
                    } else {
                        format!("{min} or {max}")
                    }
                ),
            ));
        }
        let v = self.args(&args[..given], span)?;
        let num = |k: usize| number(&v[k], span);
        let text = |k: usize| -> Result<String, Fault> {
            match &v[k] {
                Value::Str(s) => Ok(s.clone()),
                Value::Char(c) => Ok(char::from(*c).to_string()),
                other => Err(conversion(
                    span,
                    &format!("{name} takes a STRING, not {}", type_name(other)),
                )),
            }
        };
        let domain = |what: &str| Err(arithmetic(span, &format!("{name}: {what}")));
        match name {
            "SIN" => real(num(0)?.to_radians().sin(), span),
            "COS" => real(num(0)?.to_radians().cos(), span),
            "TAN" => {
                let x = num(0)?.to_radians();
                if x.cos().abs() < 1e-12 {
                    return domain("the tangent of 90° is not defined");
                }
                real(x.tan(), span)
            }
            "ASIN" | "ACOS" => {
                let x = num(0)?;
                if !(-1.0..=1.0).contains(&x) {
                    return domain(&format!("{} is outside -1 … 1", format_real(x)));
                }
                let r = if name == "ASIN" { x.asin() } else { x.acos() };
                real(r.to_degrees(), span)
            }
            "ATAN2" => real(num(0)?.atan2(num(1)?).to_degrees(), span),
            "SQRT" => {
                let x = num(0)?;
                if x < 0.0 {
                    return domain(&format!("the root of {} is not real", format_real(x)));
                }
                real(x.sqrt(), span)
            }
            "ABS" => match v[0] {
                Value::Int(i) => Ok(Value::Int(i.abs())),
                _ => real(num(0)?.abs(), span),
            },
            "POT" => real(num(0)?.powi(2), span),
            "TRUNC" => real(num(0)?.trunc(), span),
            "ROUND" => real(num(0)?.round(), span),
            "ROUNDUP" => real(num(0)?.ceil(), span),
            "LN" => {
                let x = num(0)?;
                if x <= 0.0 {
                    return domain(&format!(
                        "the logarithm of {} is not defined",
                        format_real(x)
                    ));
                }
                real(x.ln(), span)
            }
            "EXP" => real(num(0)?.exp(), span),
            "MINVAL" | "MAXVAL" => {
                let (a, b) = (num(0)?, num(1)?);
                let pick_a = if name == "MINVAL" { a <= b } else { a >= b };
                Ok(if pick_a { v[0].clone() } else { v[1].clone() })
            }
            "BOUND" => {
                let (lo, hi, x) = (num(0)?, num(1)?, num(2)?);
                if lo > hi {
                    return domain("the minimum is above the maximum");
                }
                real(x.clamp(lo, hi), span)
            }
            "STRLEN" => Ok(Value::Int(text(0)?.len() as i64)),
            "INDEX" | "RINDEX" => {
                let s = text(0)?;
                let c = text(1)?;
                let Some(&c) = c.as_bytes().first() else {
                    return Ok(Value::Int(-1));
                };
                let found = if name == "INDEX" {
                    s.bytes().position(|b| b == c)
                } else {
                    s.bytes().rposition(|b| b == c)
                };
                Ok(Value::Int(found.map_or(-1, |i| i as i64)))
            }
            "SUBSTR" => {
                let s = text(0)?;
                let start = round_int(num(1)?, span)?;
                let len = if given == 3 {
                    round_int(num(2)?, span)?
                } else {
                    i64::MAX
                };
                if start < 0 || len < 0 {
                    return domain("start and length must not be negative");
                }
                let bytes = s.as_bytes();
                let from = (start as usize).min(bytes.len());
                let to = from
                    .saturating_add(len.min(bytes.len() as i64) as usize)
                    .min(bytes.len());
                Ok(Value::Str(
                    String::from_utf8_lossy(&bytes[from..to]).into_owned(),
                ))
            }
            "TOUPPER" => Ok(Value::Str(text(0)?.to_ascii_uppercase())),
            "TOLOWER" => Ok(Value::Str(text(0)?.to_ascii_lowercase())),
            "NUMBER" => {
                let s = text(0)?;
                match parse_number(&s) {
                    Some(x) => real(x, span),
                    None => Err(conversion(
                        span,
                        &format!("NUMBER: \"{s}\" is not a number"),
                    )),
                }
            }
            "ISNUMBER" => Ok(Value::Bool(parse_number(&text(0)?).is_some())),
            "AXNAME" => {
                let s = text(0)?;
                let s = s.trim().to_ascii_uppercase();
                if s.is_empty() {
                    return Err(conversion(span, "AXNAME of an empty string"));
                }
                Ok(Value::Axis(s))
            }
            _ => Err(Fault::new(
                Some(ALARM_UNDEFINED),
                span,
                format!("function {name} not defined"),
            )),
        }
    }

    /// `CTRANS(X,10,Y,5)`, `CROT(Z,30)`, `CSCALE(X,2)`, `CMIRROR(X,Y)`,
    /// `CFINE(X,0.1)`: a frame from axis and value pairs.
    fn frame_function(
        &mut self,
        name: &str,
        args: &[Option<Expr>],
        span: Span,
    ) -> Result<Value, Fault> {
        let mut items = Vec::new();
        let mut k = 0;
        let pairs = name != "CMIRROR";
        while k < args.len() {
            let Some(axis_expr) = &args[k] else {
                k += 1;
                continue;
            };
            let axis = match self.loose(axis_expr)? {
                Value::Axis(a) => a,
                other => {
                    return Err(conversion(
                        axis_expr.span,
                        &format!("{name} takes an axis, not {}", type_name(&other)),
                    ));
                }
            };
            let value = if pairs {
                let Some(Some(e)) = args.get(k + 1) else {
                    return Err(Fault::new(
                        Some(ALARM_SYNTAX),
                        span,
                        format!("{name}: no value after axis {axis}"),
                    ));
                };
                let v = self.eval(e)?;
                number(&v, e.span)?
            } else {
                0.0
            };
            items.push((axis, value));
            k += if pairs { 2 } else { 1 };
        }
        frames::build(name, &items)
            .map(|f| Value::Frame(Box::new(f)))
            .map_err(|m| Fault::new(Some(ALARM_CONVERSION), span, m))
    }
}

/// A literal number: an INT when whole and within the INT range, else a
/// REAL (the tree keeps no trace of a written decimal point).
pub(crate) fn literal(x: f64) -> Value {
    if x.fract() == 0.0 && x.abs() <= INT_MAX {
        Value::Int(x as i64)
    } else {
        Value::Real(x)
    }
}

/// A string as a number (`NUMBER`, `ISNUMBER`): blanks around, a sign,
/// digits with one optional point, an optional `EX` exponent.
fn parse_number(s: &str) -> Option<f64> {
    let t = s.trim().to_ascii_uppercase();
    if t.is_empty() {
        return None;
    }
    let t = t.replacen("EX", "E", 1);
    if !t
        .bytes()
        .all(|b| b.is_ascii_digit() || matches!(b, b'+' | b'-' | b'.' | b'E'))
    {
        return None;
    }
    t.parse::<f64>().ok().filter(|x| x.is_finite())
}
