//! Reading the assignments of a swivel data file: `$TC_CARR<i>[<n>]=<value>`
//! lines as a SINUMERIK set-up archive (or a hand-written part program)
//! holds them.
//!
//! What a line may hold, in order: an optional block number `N…`, then any
//! number of assignments, each `$TC_CARR<i>[<n>]` `=` a value, separated by
//! blanks; a `;` starts a comment that runs to the end of the line. Values:
//!
//! * numbers, with an optional sign, decimal point and exponent (`EX`, the
//!   SINUMERIK spelling, or `E`);
//! * `"strings"` (`$TC_CARR34`–`36`);
//! * characters and axis names, quoted (`'T'`, `"M"`) or bare (`T`, `B1`),
//!   for `$TC_CARR21`–`23`.
//!
//! So that a whole tool-data archive can be given, the reader also passes
//! over what such an archive puts around the records: lines starting with
//! `%` (the file's name line), `CHANDATA(<n>)`, M words (`M17`, `M30`) and
//! assignments to other system variables (`$TC_DP…`, `$TC_CARR_KIN_…`),
//! which it counts in a note. `$TC_CARR1[0]=0` clears every record read
//! so far, as the control does when it executes it. Anything else is an
//! error at its line and column.

use std::collections::BTreeMap;

use super::TcCarrError;

/// Highest field number of a swivel data record (`$TC_CARR65`).
pub(crate) const LAST_FIELD: u8 = 65;

/// A value as written.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Value {
    Number(f64),
    /// A quoted string or character (`"B"`, `'T'`).
    Text(String),
    /// A bare name (`T`, `B1`).
    Name(String),
}

/// One assignment to a field of a record.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Field {
    pub value: Value,
    /// Line of the assignment, 1-based.
    pub line: u32,
    /// Column of the value, 1-based, in characters.
    pub column: u32,
}

/// The fields assigned in one record, by field number.
pub(crate) type Record = BTreeMap<u8, Field>;

/// What a file holds: the records by number, and notes about what was
/// passed over.
#[derive(Debug, Default)]
pub(crate) struct Parsed {
    pub records: BTreeMap<u32, Record>,
    pub notes: Vec<String>,
}

/// Field numbers that no record has (SINUMERIK: fine offsets exist only
/// for the offset vectors and the axis offsets).
fn undefined(field: u8) -> bool {
    matches!(field, 47..=54 | 61..=63)
}

/// What kind of value a field takes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Number,
    /// `$TC_CARR21`, `22`: an axis name, or 0 for none.
    Axis,
    /// `$TC_CARR23`: T, P or M.
    KinematicType,
    /// `$TC_CARR34`–`36`.
    Text,
}

fn kind(field: u8) -> Kind {
    match field {
        21 | 22 => Kind::Axis,
        23 => Kind::KinematicType,
        34..=36 => Kind::Text,
        _ => Kind::Number,
    }
}

/// Reads the whole file.
pub(crate) fn parse(text: &str) -> Result<Parsed, TcCarrError> {
    let mut parsed = Parsed::default();
    let mut others = 0usize;
    let mut cleared: Vec<u32> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let number = u32::try_from(i + 1).unwrap_or(u32::MAX);
        let mut reader = Line {
            chars: line.chars().collect(),
            at: 0,
            line: number,
        };
        reader.read(&mut parsed, &mut others, &mut cleared)?;
    }
    if others > 0 {
        parsed.notes.push(format!(
            "{others} assignment(s) to other system variables ($TC_DP…, $TC_CARR_KIN_…) passed over"
        ));
    }
    for line in cleared {
        parsed.notes.push(format!(
            "$TC_CARR1[0]=0 on line {line} cleared the records read before it"
        ));
    }
    Ok(parsed)
}

/// A cursor over one line.
struct Line {
    chars: Vec<char>,
    at: usize,
    line: u32,
}

impl Line {
    fn error(&self, at: usize, message: impl Into<String>) -> TcCarrError {
        TcCarrError {
            line: self.line,
            column: u32::try_from(at + 1).unwrap_or(u32::MAX),
            message: message.into(),
        }
    }

    fn peek(&self) -> Option<char> {
        self.chars.get(self.at).copied()
    }

    fn skip_blanks(&mut self) {
        while self
            .peek()
            .is_some_and(|c| c == ' ' || c == '\t' || c == '\r')
        {
            self.at += 1;
        }
    }

    /// At the end of the line or of its statements (a comment follows).
    fn at_end(&self) -> bool {
        matches!(self.peek(), None | Some(';'))
    }

    /// A run of letters, digits and underscores from here.
    fn word(&mut self) -> String {
        let start = self.at;
        while self
            .peek()
            .is_some_and(|c| c.is_ascii_alphanumeric() || c == '_')
        {
            self.at += 1;
        }
        self.chars[start..self.at].iter().collect()
    }

    fn digits(&mut self) -> Option<u64> {
        let start = self.at;
        while self.peek().is_some_and(|c| c.is_ascii_digit()) {
            self.at += 1;
        }
        let s: String = self.chars[start..self.at].iter().collect();
        if s.is_empty() { None } else { s.parse().ok() }
    }

    fn read(
        &mut self,
        parsed: &mut Parsed,
        others: &mut usize,
        cleared: &mut Vec<u32>,
    ) -> Result<(), TcCarrError> {
        self.skip_blanks();
        if self.peek() == Some('%') {
            return Ok(());
        }
        // A block number.
        if self.peek().is_some_and(|c| c == 'N' || c == 'n')
            && self
                .chars
                .get(self.at + 1)
                .is_some_and(|c| c.is_ascii_digit())
        {
            self.at += 1;
            self.digits();
        }
        loop {
            self.skip_blanks();
            if self.at_end() {
                return Ok(());
            }
            let start = self.at;
            match self.peek() {
                Some('$') => {
                    self.at += 1;
                    self.assignment(start, parsed, others, cleared)?;
                }
                Some(c) if c.is_ascii_alphabetic() => {
                    let word = self.word().to_ascii_uppercase();
                    let m_word = word.len() > 1
                        && word.starts_with('M')
                        && word[1..].bytes().all(|b| b.is_ascii_digit());
                    if m_word {
                        continue;
                    }
                    if word == "CHANDATA" && self.peek() == Some('(') {
                        self.at += 1;
                        self.skip_blanks();
                        self.digits();
                        self.skip_blanks();
                        if self.peek() == Some(')') {
                            self.at += 1;
                            continue;
                        }
                        return Err(self.error(self.at, "CHANDATA(<channel>) is not closed"));
                    }
                    return Err(self.error(
                        start,
                        format!("`{word}` is not a swivel data assignment: expected `$TC_CARR<i>[<n>]=<value>`"),
                    ));
                }
                Some(c) => {
                    return Err(self.error(
                        start,
                        format!("unexpected `{c}`: expected `$TC_CARR<i>[<n>]=<value>`"),
                    ));
                }
                None => return Ok(()),
            }
        }
    }

    /// After the `$` of an assignment at `start`.
    fn assignment(
        &mut self,
        start: usize,
        parsed: &mut Parsed,
        others: &mut usize,
        cleared: &mut Vec<u32>,
    ) -> Result<(), TcCarrError> {
        let name_at = self.at;
        let name = self.word().to_ascii_uppercase();
        if name.is_empty() {
            return Err(self.error(name_at, "a system variable name must follow `$`"));
        }
        let field = name
            .strip_prefix("TC_CARR")
            .filter(|rest| !rest.is_empty() && rest.bytes().all(|b| b.is_ascii_digit()));
        let Some(field) = field else {
            // Another system variable: its indices and value are passed over.
            self.skip_blanks();
            if self.peek() == Some('[') {
                while let Some(c) = self.peek() {
                    self.at += 1;
                    if c == ']' {
                        break;
                    }
                }
            }
            self.equals(start)?;
            self.value()?;
            *others += 1;
            return Ok(());
        };
        let field_at = name_at + "TC_CARR".len();
        let field: u8 = match field.parse() {
            Ok(f) if (1..=LAST_FIELD).contains(&f) && !undefined(f) => f,
            _ => {
                return Err(self.error(
                    field_at,
                    format!(
                        "$TC_CARR{field} is not a field of a swivel data record (1–46, 55–60, 64, 65)"
                    ),
                ));
            }
        };
        self.skip_blanks();
        if self.peek() != Some('[') {
            return Err(self.error(self.at, format!("`[<record>]` must follow $TC_CARR{field}")));
        }
        self.at += 1;
        self.skip_blanks();
        let index_at = self.at;
        let index = self
            .digits()
            .and_then(|n| u32::try_from(n).ok())
            .ok_or_else(|| self.error(index_at, "the record number must be a whole number"))?;
        self.skip_blanks();
        if self.peek() != Some(']') {
            return Err(self.error(self.at, "`]` expected after the record number"));
        }
        self.at += 1;
        self.equals(start)?;
        let (value, value_at) = self.value()?;
        if index == 0 {
            if field == 1 && value == Value::Number(0.0) {
                parsed.records.clear();
                cleared.push(self.line);
                return Ok(());
            }
            return Err(self.error(
                index_at,
                "record numbers start at 1 (only `$TC_CARR1[0]=0`, clear every record, uses 0)",
            ));
        }
        let value = self.check(field, value, value_at)?;
        let column = u32::try_from(value_at + 1).unwrap_or(u32::MAX);
        parsed.records.entry(index).or_default().insert(
            field,
            Field {
                value,
                line: self.line,
                column,
            },
        );
        Ok(())
    }

    fn equals(&mut self, start: usize) -> Result<(), TcCarrError> {
        self.skip_blanks();
        if self.peek() != Some('=') {
            let what: String = self.chars[start..self.at].iter().collect();
            return Err(self.error(self.at, format!("`=` expected after `{what}`")));
        }
        self.at += 1;
        self.skip_blanks();
        Ok(())
    }

    /// A value and the index of its first character.
    fn value(&mut self) -> Result<(Value, usize), TcCarrError> {
        let start = self.at;
        match self.peek() {
            Some(q @ ('"' | '\'')) => {
                self.at += 1;
                let from = self.at;
                while self.peek().is_some_and(|c| c != q) {
                    self.at += 1;
                }
                if self.peek() != Some(q) {
                    return Err(self.error(start, format!("the text is not closed with {q}")));
                }
                let text: String = self.chars[from..self.at].iter().collect();
                self.at += 1;
                Ok((Value::Text(text), start))
            }
            Some(c) if c.is_ascii_alphabetic() || c == '_' => Ok((Value::Name(self.word()), start)),
            Some(c) if c.is_ascii_digit() || matches!(c, '+' | '-' | '.') => {
                self.number().map(|v| (Value::Number(v), start))
            }
            Some(c) => Err(self.error(
                start,
                format!(
                    "unexpected `{c}`: a value is a number, a \"string\", a 'character' or a name"
                ),
            )),
            None => Err(self.error(start, "a value must follow `=`")),
        }
    }

    fn number(&mut self) -> Result<f64, TcCarrError> {
        let start = self.at;
        let mut text = String::new();
        if let Some(sign @ ('+' | '-')) = self.peek() {
            text.push(sign);
            self.at += 1;
        }
        let mut mantissa = false;
        while let Some(c) = self.peek() {
            if c.is_ascii_digit() {
                mantissa = true;
            } else if c != '.' || text.contains('.') {
                break;
            }
            text.push(c);
            self.at += 1;
        }
        if !mantissa {
            return Err(self.error(start, "a number must have a digit"));
        }
        // Exponent: `EX` (SINUMERIK) or `E`, then a signed whole number.
        if self.peek().is_some_and(|c| c == 'E' || c == 'e') {
            let mut at = self.at + 1;
            if self.chars.get(at).is_some_and(|c| *c == 'X' || *c == 'x') {
                at += 1;
            }
            let mut exponent = String::from("e");
            if let Some(sign @ ('+' | '-')) = self.chars.get(at).copied() {
                exponent.push(sign);
                at += 1;
            }
            let digits_from = at;
            while self.chars.get(at).is_some_and(|c| c.is_ascii_digit()) {
                exponent.push(self.chars[at]);
                at += 1;
            }
            if at == digits_from {
                return Err(self.error(self.at, "the exponent must have a digit"));
            }
            text.push_str(&exponent);
            self.at = at;
        }
        if self
            .peek()
            .is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == '.')
        {
            return Err(self.error(self.at, "a number cannot go on like this"));
        }
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.error(start, format!("`{text}` is not a finite number"))),
        }
    }

    /// The value checked against the field's kind.
    fn check(&self, field: u8, value: Value, at: usize) -> Result<Value, TcCarrError> {
        match (kind(field), &value) {
            (Kind::Number, Value::Number(_)) | (Kind::Text, Value::Text(_)) => Ok(value),
            (Kind::Number, _) => Err(self.error(at, format!("$TC_CARR{field} takes a number"))),
            (Kind::Text, _) => Err(self.error(
                at,
                format!("$TC_CARR{field} takes a \"string\" in double quotes"),
            )),
            (Kind::Axis, Value::Number(v)) if *v == 0.0 => Ok(value),
            (Kind::Axis, Value::Text(_) | Value::Name(_)) => Ok(value),
            (Kind::Axis, Value::Number(_)) => Err(self.error(
                at,
                format!("$TC_CARR{field} takes an axis name (or 0 for none)"),
            )),
            (Kind::KinematicType, Value::Text(t) | Value::Name(t))
                if matches!(t.to_ascii_uppercase().as_str(), "T" | "P" | "M") =>
            {
                Ok(Value::Text(t.to_ascii_uppercase()))
            }
            (Kind::KinematicType, _) => {
                let shown = match &value {
                    Value::Number(v) => format!("{v}"),
                    Value::Text(t) | Value::Name(t) => format!("`{t}`"),
                };
                Err(self.error(
                    at,
                    format!(
                        "alarm 14153: invalid kinematic type {shown} in $TC_CARR23: T (tool), P (part) or M (mixed)"
                    ),
                ))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn records(text: &str) -> BTreeMap<u32, Record> {
        parse(text).expect("reads").records
    }

    #[test]
    fn assignments_numbers_strings_and_characters() {
        let r = records(
            "%_N_TO_TMA_INI\nCHANDATA(1)\nN10 $TC_CARR1[1]=-1.5 $TC_CARR2[1]=2EX2 ; l1\n\
             $TC_CARR23[1]='m' $TC_CARR34[1]=\"HEAD\"\n$tc_carr21[1]=B1 $TC_CARR22[1]=0\n\
             $TC_DP1[1,1]=120\nM17\n",
        );
        let rec = &r[&1];
        assert_eq!(rec[&1].value, Value::Number(-1.5));
        assert_eq!((rec[&1].line, rec[&1].column), (3, 18));
        assert_eq!(rec[&2].value, Value::Number(200.0));
        assert_eq!(rec[&23].value, Value::Text("M".into()));
        assert_eq!(rec[&34].value, Value::Text("HEAD".into()));
        assert_eq!(rec[&21].value, Value::Name("B1".into()));
        assert_eq!(rec[&22].value, Value::Number(0.0));
    }

    #[test]
    fn clear_all_forgets_earlier_records() {
        let r = records("$TC_CARR1[1]=5\n$TC_CARR1[0]=0\n$TC_CARR1[2]=5\n");
        assert_eq!(r.keys().copied().collect::<Vec<_>>(), [2]);
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = parse("$TC_CARR1[1]=0\n  $TC_CARR1[1]=1.2.3\n").expect_err("refused");
        assert_eq!((e.line, e.column), (2, 19));
        let e = parse("$TC_CARR50[1]=0").expect_err("refused");
        assert_eq!((e.line, e.column), (1, 9));
        let e = parse("$TC_CARR1[1]=\"x\"").expect_err("refused");
        assert_eq!((e.line, e.column), (1, 14));
        let e = parse("X10").expect_err("refused");
        assert_eq!((e.line, e.column), (1, 1));
        let e = parse("$TC_CARR23[3]=\"Q\"").expect_err("refused");
        assert!(e.message.contains("14153"), "{e}");
    }
}
