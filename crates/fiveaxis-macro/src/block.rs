//! Evaluation of an NC block whose values are macro expressions.

use fiveaxis_gcode::{Block, Code, Word};

use crate::error::{MacroError, MacroErrorKind};
use crate::expr::{NcBlock, Value, WordValue};
use crate::settings::MacroSettings;
use crate::variables::{SystemVariables, Variables};

/// Evaluates the words of `nc` into `out` (cleared first), ready for the
/// controller as if the block had been read by `fiveaxis_gcode::parse_line`.
///
/// * A literal word is copied as the G-code front end reads it.
/// * A word whose value is a variable or an expression gets the computed
///   value, and `decimal_point: true`: a computed value is a real number,
///   not a count of least input increments (`X#1` with `#1 = 10` is 10 mm,
///   as `X10.`). Its `code` is `Some` when the value, rounded to one
///   decimal place (half away from zero), is not negative and its integer
///   part fits `u16`: `G#10` with `#10 = 43.4` is `Code { 43, 4 }`. The
///   value itself is left unrounded.
/// * A word whose value is vacant is left out, as if not written.
///
/// The line number, sequence number, block delete and tape mark are
/// copied; each word keeps its span.
///
/// # Errors
///
/// The first alarm evaluating a value (see [`Variables::eval`]); `out` is
/// then left empty apart from its line number.
pub fn evaluate_block(
    nc: &NcBlock,
    vars: &Variables,
    sys: &dyn SystemVariables,
    settings: &MacroSettings,
    out: &mut Block,
) -> Result<(), MacroError> {
    out.clear();
    out.line = nc.line;
    let result = fill(nc, vars, sys, settings, out);
    if result.is_err() {
        out.clear();
        out.line = nc.line;
    }
    result
}

fn fill(
    nc: &NcBlock,
    vars: &Variables,
    sys: &dyn SystemVariables,
    settings: &MacroSettings,
    out: &mut Block,
) -> Result<(), MacroError> {
    out.block_delete = nc.block_delete;
    out.tape_mark = nc.tape_mark;
    out.sequence = nc.sequence;
    for word in &nc.words {
        let (value, decimal_point, code, computed) = match &word.value {
            WordValue::Literal {
                value,
                decimal_point,
                code,
            } => (*value, *decimal_point, *code, false),
            WordValue::Expr(expr) => match vars.eval(expr, sys, settings)? {
                Value::Vacant => continue,
                Value::Number(x) => (x, true, computed_code(x), true),
                Value::Bool(_) => {
                    return Err(MacroError::new(
                        MacroErrorKind::FormatError,
                        word.span,
                        "a comparison cannot be an address value",
                    ));
                }
            },
        };
        out.words.push(Word {
            letter: word.letter,
            value,
            decimal_point,
            code,
            computed,
            span: word.span,
        });
    }
    Ok(())
}

/// The code form of a computed value: rounded to one decimal place, not
/// negative, integer part within `u16`.
pub(crate) fn computed_code(x: f64) -> Option<Code> {
    let tenths = (x * 10.0).round();
    if !(0.0..=f64::from(u16::MAX) * 10.0 + 9.0).contains(&tenths) {
        return None;
    }
    // Integral and within 0 ..= 655359: the cast is exact.
    let tenths = tenths as u32;
    let major = u16::try_from(tenths / 10).ok()?;
    let minor = u8::try_from(tenths % 10).ok()?;
    Some(Code::new(major, minor))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn computed_codes() {
        assert_eq!(computed_code(43.4), Some(Code::new(43, 4)));
        assert_eq!(computed_code(43.44), Some(Code::new(43, 4)));
        assert_eq!(computed_code(43.45), Some(Code::new(43, 5)));
        assert_eq!(computed_code(0.0), Some(Code::new(0, 0)));
        assert_eq!(computed_code(-0.04), Some(Code::new(0, 0)));
        assert_eq!(computed_code(-0.05), None);
        assert_eq!(computed_code(65535.9), Some(Code::new(65535, 9)));
        assert_eq!(computed_code(65535.96), None);
        assert_eq!(computed_code(1e300), None);
    }
}
