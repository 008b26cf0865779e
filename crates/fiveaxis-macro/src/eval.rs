//! Evaluation of expressions: operators, functions and the vacant rules.
//!
//! A recursive walk over the tree (its depth is bounded by the parser); it
//! allocates nothing unless it fails, when the message is formatted.
//!
//! Vacant values follow the manual's tables (the Series 16i/30i custom
//! macro chapter, "vacant variables"; the same tables appear in the
//! Mitsubishi M700V user macro chapter found with the search tool):
//!
//! * a variable read alone keeps its vacancy (`#2 = #1` gives vacant), and
//!   so does a bracket around it and a sign in front (decision);
//! * every operator and function takes a vacant operand as 0, so
//!   `#1 * 5` and `#1 + #1` give 0;
//! * `EQ` and `NE` tell vacant from 0 (`#1 EQ #0` holds for a vacant `#1`,
//!   not for `#1 = 0`); `GT GE LT LE` take vacant as 0.
//!
//! No result is ever NaN or infinite: a non-finite result is alarm PS0111.

use fiveaxis_gcode::Span;

use crate::error::{MacroError, MacroErrorKind};
use crate::expr::{BinOp, Binary, Call, Expr, Func, Value, Var, VarNumber, needs_brackets};
use crate::settings::MacroSettings;
use crate::variables::{SystemVariables, Variables};

/// Evaluates `expr` (see [`Variables::eval`]).
pub(crate) fn eval(
    vars: &Variables,
    expr: &Expr,
    sys: &dyn SystemVariables,
    settings: &MacroSettings,
) -> Result<Value, MacroError> {
    match expr {
        Expr::Number(x) => Ok(Value::Number(*x)),
        Expr::Var(var) => {
            if let VarNumber::Named(name) = &var.number {
                return vars.read_named(name, var.span, sys).map(Value::Number);
            }
            let number = vars.resolve(var, sys, settings)?;
            vars.read(number, var.span, sys, settings).map(Value::from)
        }
        Expr::Neg(e) => Ok(match eval(vars, e, sys, settings)? {
            Value::Number(x) => Value::Number(-x),
            other => other,
        }),
        Expr::Binary(b) => binary(vars, b, sys, settings),
        Expr::Call(c) => call(vars, c, sys, settings),
    }
}

/// The number of an operand: vacant counts as 0.
fn num(value: Value, span: Span) -> Result<f64, MacroError> {
    match value {
        Value::Number(x) => Ok(x),
        Value::Vacant => Ok(0.0),
        Value::Bool(_) => Err(MacroError::new(
            MacroErrorKind::FormatError,
            span,
            "a comparison used as a number",
        )),
    }
}

/// `x` when finite, alarm PS0111 otherwise.
fn finite(x: f64, span: Span, what: &dyn std::fmt::Display) -> Result<f64, MacroError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(MacroError::new(
            MacroErrorKind::Overflow,
            span,
            format!("the value of `{what}` is too large"),
        ))
    }
}

fn binary(
    vars: &Variables,
    b: &Binary,
    sys: &dyn SystemVariables,
    settings: &MacroSettings,
) -> Result<Value, MacroError> {
    let lhs = eval(vars, &b.lhs, sys, settings)?;
    let rhs = eval(vars, &b.rhs, sys, settings)?;
    combine(b, lhs, rhs, settings)
}

/// `lhs op rhs`, both evaluated. Kept out of line so that the frames of
/// the recursion (`eval`, `binary`) stay small: a line's deepest tree
/// must evaluate on a small stack (the crate's `tests/depth.rs`).
#[inline(never)]
fn combine(
    b: &Binary,
    lhs: Value,
    rhs: Value,
    settings: &MacroSettings,
) -> Result<Value, MacroError> {
    if settings.linuxcnc {
        return ngc_binary(b, num(lhs, b.span)?, num(rhs, b.span)?);
    }
    if let (Value::Bool(l), Value::Bool(r)) = (lhs, rhs) {
        return match b.op {
            BinOp::And => Ok(Value::Bool(l && r)),
            BinOp::Or => Ok(Value::Bool(l || r)),
            BinOp::Xor => Ok(Value::Bool(l != r)),
            _ => Err(MacroError::new(
                MacroErrorKind::FormatError,
                b.span,
                format!("{} cannot combine two comparisons", b.op.as_str()),
            )),
        };
    }
    if matches!(b.op, BinOp::Eq | BinOp::Ne) {
        let equal = match (lhs, rhs) {
            (Value::Vacant, Value::Vacant) => true,
            (Value::Vacant, Value::Number(_)) | (Value::Number(_), Value::Vacant) => false,
            _ => num(lhs, b.span)? == num(rhs, b.span)?,
        };
        return Ok(Value::Bool(equal == (b.op == BinOp::Eq)));
    }
    let l = num(lhs, b.span)?;
    let r = num(rhs, b.span)?;
    let x = match b.op {
        BinOp::Gt => return Ok(Value::Bool(l > r)),
        BinOp::Ge => return Ok(Value::Bool(l >= r)),
        BinOp::Lt => return Ok(Value::Bool(l < r)),
        BinOp::Le => return Ok(Value::Bool(l <= r)),
        BinOp::Eq | BinOp::Ne => return Ok(Value::Bool(false)),
        BinOp::Add => l + r,
        BinOp::Sub => l - r,
        BinOp::Mul => l * r,
        BinOp::Div => {
            if r == 0.0 {
                return Err(division_by_zero(b));
            }
            l / r
        }
        BinOp::Mod => remainder(l, r, b)?,
        BinOp::And | BinOp::Or | BinOp::Xor => bitwise(b, l, r)?,
        // `**` is LinuxCNC's; the FANUC parser never builds it.
        BinOp::Pow => l.powf(r),
    };
    finite(x, b.span, &DisplayBinary(b)).map(Value::Number)
}

/// LinuxCNC's equality tolerance (overview, "Equality and floating-point
/// values": values within 1e-6 are equal).
const NGC_EQUAL_TOLERANCE: f64 = 1e-6;

/// A binary operation by LinuxCNC's rules: every result is a number
/// (a comparison or a logical operation gives 1 or 0; zero is false,
/// anything else true).
fn ngc_binary(b: &Binary, l: f64, r: f64) -> Result<Value, MacroError> {
    let truth = |t: bool| if t { 1.0 } else { 0.0 };
    let x = match b.op {
        BinOp::Add => l + r,
        BinOp::Sub => l - r,
        BinOp::Mul => l * r,
        BinOp::Div => {
            if r == 0.0 {
                return Err(ngc_division_by_zero(b));
            }
            l / r
        }
        BinOp::Mod => {
            if r == 0.0 {
                return Err(ngc_division_by_zero(b));
            }
            // rs274 2.9: -7 MOD 3 = 2, 7.5 MOD -2 = 1.5: the remainder of
            // truncated division, moved up by |r| when negative.
            let m = l % r;
            if m < 0.0 { m + r.abs() } else { m }
        }
        BinOp::Pow => {
            if l < 0.0 && r.fract() != 0.0 {
                return Err(MacroError::new(
                    MacroErrorKind::ArgumentOutOfRange,
                    b.span,
                    format!(
                        "attempt to raise a negative number to a non-integer power in `{}`",
                        DisplayBinary(b)
                    ),
                ));
            }
            if l == 0.0 && r < 0.0 {
                return Err(ngc_division_by_zero(b));
            }
            l.powf(r)
        }
        BinOp::Eq => truth((l - r).abs() < NGC_EQUAL_TOLERANCE),
        BinOp::Ne => truth((l - r).abs() >= NGC_EQUAL_TOLERANCE),
        BinOp::Gt => truth(l > r),
        BinOp::Ge => truth(l >= r),
        BinOp::Lt => truth(l < r),
        BinOp::Le => truth(l <= r),
        BinOp::And => truth(l != 0.0 && r != 0.0),
        BinOp::Or => truth(l != 0.0 || r != 0.0),
        BinOp::Xor => truth((l != 0.0) != (r != 0.0)),
    };
    finite(x, b.span, &DisplayBinary(b)).map(Value::Number)
}

fn ngc_division_by_zero(b: &Binary) -> MacroError {
    MacroError::new(
        MacroErrorKind::DivisionByZero,
        b.span,
        format!("attempt to divide by zero in `{}`", DisplayBinary(b)),
    )
}

/// Prints a [`Binary`] without cloning it into an [`Expr`].
struct DisplayBinary<'a>(&'a Binary);

impl std::fmt::Display for DisplayBinary<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let b = self.0;
        let lhs = bracketed(&b.lhs, b.op, false);
        let rhs = bracketed(&b.rhs, b.op, true);
        let op = b.op.as_str();
        let sep = if op.len() > 1 { " " } else { "" };
        write!(f, "{lhs}{sep}{op}{sep}{rhs}")
    }
}

/// An operand printed with brackets where they are needed.
fn bracketed(e: &Expr, parent: BinOp, right: bool) -> String {
    if needs_brackets(e, parent, right) {
        format!("[{e}]")
    } else {
        e.to_string()
    }
}

fn division_by_zero(b: &Binary) -> MacroError {
    MacroError::new(
        MacroErrorKind::DivisionByZero,
        b.span,
        format!("division by zero in `{}`", DisplayBinary(b)),
    )
}

/// The operands of `MOD` and of the bitwise operators are first rounded to
/// integers (half away from zero), as FANUC does wherever a real number
/// stands for an integer.
fn integer(x: f64) -> f64 {
    x.round()
}

/// `MOD`: the remainder of the rounded operands, with the sign of the
/// dividend (decision: the manual's "remainder" with FANUC's rounding of
/// real numbers used as integers; e.g. `-10 MOD 3` is -1, `10.4 MOD 3` is 1).
fn remainder(l: f64, r: f64, b: &Binary) -> Result<f64, MacroError> {
    let (l, r) = (integer(l), integer(r));
    if r == 0.0 {
        return Err(division_by_zero(b));
    }
    Ok(l % r)
}

/// `AND OR XOR` on numbers: bitwise, on the rounded operands taken as
/// 32-bit two's complement integers (decision: FANUC does logical
/// operations on 32-bit binary values; operands outside the 32-bit signed
/// range are alarm PS0119).
fn bitwise(b: &Binary, l: f64, r: f64) -> Result<f64, MacroError> {
    let to_i32 = |x: f64| {
        let x = integer(x);
        if x >= f64::from(i32::MIN) && x <= f64::from(i32::MAX) {
            // In range and integral: the cast is exact.
            Some(x as i32)
        } else {
            None
        }
    };
    let (Some(l), Some(r)) = (to_i32(l), to_i32(r)) else {
        return Err(MacroError::new(
            MacroErrorKind::ArgumentOutOfRange,
            b.span,
            format!(
                "the operands of {} in `{}` must be 32-bit integers",
                b.op.as_str(),
                DisplayBinary(b)
            ),
        ));
    };
    Ok(f64::from(match b.op {
        BinOp::And => l & r,
        BinOp::Or => l | r,
        _ => l ^ r,
    }))
}

fn call(
    vars: &Variables,
    c: &Call,
    sys: &dyn SystemVariables,
    settings: &MacroSettings,
) -> Result<Value, MacroError> {
    if c.func == Func::Exists {
        return match &c.arg {
            Expr::Var(Var {
                number: VarNumber::Named(name),
                ..
            }) => Ok(Value::Number(if vars.named_exists(name, sys) {
                1.0
            } else {
                0.0
            })),
            _ => Err(MacroError::new(
                MacroErrorKind::FormatError,
                c.span,
                "EXISTS takes one named parameter, `EXISTS[#<name>]`",
            )),
        };
    }
    let a = num(eval(vars, &c.arg, sys, settings)?, c.span)?;
    let b = match &c.arg2 {
        Some(arg2) => Some(num(eval(vars, arg2, sys, settings)?, c.span)?),
        None => None,
    };
    let x = apply(c, a, b, settings)?;
    let x = finite(x, c.span, &DisplayCall(c))?;
    // No negative zero out of a function.
    Ok(Value::Number(x + 0.0))
}

struct DisplayCall<'a>(&'a Call);

impl std::fmt::Display for DisplayCall<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let c = self.0;
        write!(f, "{}[{}", c.func.name(), c.arg)?;
        if let Some(arg2) = &c.arg2 {
            write!(f, ",{arg2}")?;
        }
        f.write_str("]")
    }
}

fn out_of_range(c: &Call, why: &str) -> MacroError {
    MacroError::new(
        MacroErrorKind::ArgumentOutOfRange,
        c.span,
        format!("`{}`: {why}", DisplayCall(c)),
    )
}

/// The sine and cosine of `degrees`, exact at multiples of 90°.
pub(crate) fn sin_cos_degrees(degrees: f64) -> (f64, f64) {
    let r = degrees % 360.0;
    let r = if r < 0.0 { r + 360.0 } else { r };
    if r == 0.0 {
        (0.0, 1.0)
    } else if r == 90.0 {
        (1.0, 0.0)
    } else if r == 180.0 {
        (0.0, -1.0)
    } else if r == 270.0 {
        (-1.0, 0.0)
    } else {
        r.to_radians().sin_cos()
    }
}

/// An angle in degrees into the manual's ranges: with NAT = 0 a negative
/// angle is given as its positive equivalent (`ASIN` 270°…90°, `ATAN`
/// 0°…360°); with NAT = 1 it is left as it is (-90°…90°, -180°…180°).
fn nat_range(degrees: f64, settings: &MacroSettings) -> f64 {
    if !settings.nat && degrees < 0.0 {
        degrees + 360.0
    } else {
        degrees
    }
}

/// The largest BCD value of 8 digits (32 bits).
const MAX_BCD_DIGITS: u32 = 8;

fn apply(c: &Call, a: f64, b: Option<f64>, settings: &MacroSettings) -> Result<f64, MacroError> {
    Ok(match c.func {
        Func::Sin => sin_cos_degrees(a).0,
        Func::Cos => sin_cos_degrees(a).1,
        Func::Tan => {
            let (s, co) = sin_cos_degrees(a);
            if co == 0.0 {
                return Err(out_of_range(c, "the tangent of 90° is infinite"));
            }
            s / co
        }
        Func::Asin => {
            if !(-1.0..=1.0).contains(&a) {
                return Err(out_of_range(c, "the argument must lie between -1 and 1"));
            }
            nat_range(a.asin().to_degrees(), settings)
        }
        Func::Acos => {
            if !(-1.0..=1.0).contains(&a) {
                return Err(out_of_range(c, "the argument must lie between -1 and 1"));
            }
            a.acos().to_degrees()
        }
        Func::Atan => match b {
            Some(b) => {
                if a == 0.0 && b == 0.0 {
                    return Err(out_of_range(c, "the angle of 0/0 is undefined"));
                }
                nat_range(a.atan2(b).to_degrees(), settings)
            }
            None => nat_range(a.atan().to_degrees(), settings),
        },
        Func::Sqrt => {
            if a < 0.0 {
                return Err(out_of_range(c, "the square root of a negative number"));
            }
            a.sqrt()
        }
        Func::Abs => a.abs(),
        Func::Round => a.round(),
        // LinuxCNC: FIX rounds down, FUP up (FIX[-2.8] = -3, FUP[-2.8] = -2).
        Func::Fix if settings.linuxcnc => a.floor(),
        Func::Fup if settings.linuxcnc => a.ceil(),
        Func::Fix => a.trunc(),
        Func::Fup => {
            let t = a.trunc();
            if t == a { t } else { t + a.signum() }
        }
        Func::Ln => {
            if a <= 0.0 {
                return Err(out_of_range(
                    c,
                    "the logarithm of a number that is not positive",
                ));
            }
            a.ln()
        }
        Func::Exp => a.exp(),
        Func::Exists => return Err(out_of_range(c, "EXISTS takes a named parameter")),
        Func::Pow => {
            let b = b.unwrap_or(1.0);
            if a < 0.0 && b.fract() != 0.0 {
                return Err(out_of_range(c, "a negative number to a fractional power"));
            }
            if a == 0.0 && b < 0.0 {
                return Err(MacroError::new(
                    MacroErrorKind::DivisionByZero,
                    c.span,
                    format!("division by zero in `{}`", DisplayCall(c)),
                ));
            }
            a.powf(b)
        }
        Func::Adp => a * 10f64.powi(i32::from(settings.adp_digits)),
        Func::Bcd => {
            let n = integer(a);
            let limit = 10f64.powi(MAX_BCD_DIGITS as i32);
            if n < 0.0 || n >= limit {
                return Err(out_of_range(c, "BCD takes 0 to 99999999"));
            }
            // 0 <= n < 10^8: the cast is exact.
            let mut n = n as u32;
            let mut bcd: u32 = 0;
            for shift in 0..MAX_BCD_DIGITS {
                bcd |= (n % 10) << (4 * shift);
                n /= 10;
            }
            f64::from(bcd)
        }
        Func::Bin => {
            let n = integer(a);
            if n < 0.0 || n > f64::from(u32::MAX) {
                return Err(out_of_range(c, "BIN takes a BCD value of at most 8 digits"));
            }
            // 0 <= n <= u32::MAX: the cast is exact.
            let n = n as u32;
            let mut bin: u32 = 0;
            for shift in (0..MAX_BCD_DIGITS).rev() {
                let digit = (n >> (4 * shift)) & 0xF;
                if digit > 9 {
                    return Err(out_of_range(c, "the value is not BCD (a digit above 9)"));
                }
                bin = bin * 10 + digit;
            }
            f64::from(bin)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_quadrants() {
        assert_eq!(sin_cos_degrees(0.0), (0.0, 1.0));
        assert_eq!(sin_cos_degrees(90.0), (1.0, 0.0));
        assert_eq!(sin_cos_degrees(-90.0), (-1.0, 0.0));
        assert_eq!(sin_cos_degrees(540.0), (0.0, -1.0));
        assert_eq!(sin_cos_degrees(-720.0), (0.0, 1.0));
        let (s, c) = sin_cos_degrees(30.0);
        assert!((s - 0.5).abs() < 1e-15 && (c - 0.75_f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn nat_ranges() {
        let nat0 = MacroSettings::default();
        let nat1 = MacroSettings { nat: true, ..nat0 };
        assert_eq!(nat_range(-30.0, &nat0), 330.0);
        assert_eq!(nat_range(-30.0, &nat1), -30.0);
        assert_eq!(nat_range(30.0, &nat0), 30.0);
    }
}
