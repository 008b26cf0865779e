//! The syntax tree of one line: expressions, variables and statements.
//!
//! Trees are built by [`crate::parse_statement`], which bounds their depth
//! (brackets nest at most [`crate::MAX_BRACKET_DEPTH`] levels), so walking
//! them recursively is safe. `Display` prints an expression back as macro
//! text that reads back to the same tree.

use std::fmt;

use fiveaxis_gcode::{Code, Span};

/// A value: vacant (`#0`, a variable never set), a number, or the truth
/// value of a comparison (only `IF` and `WHILE` take those).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    /// No value ("null"): `#0` and unset variables.
    Vacant,
    /// A finite number.
    Number(f64),
    /// The result of a comparison, or of `AND`/`OR`/`XOR` between two.
    Bool(bool),
}

impl Value {
    /// The value as a variable holds it: `None` when vacant (a truth value
    /// is not a variable value and also gives `None`).
    pub fn number(self) -> Option<f64> {
        match self {
            Self::Number(x) => Some(x),
            Self::Vacant | Self::Bool(_) => None,
        }
    }
}

impl From<Option<f64>> for Value {
    fn from(value: Option<f64>) -> Self {
        value.map_or(Self::Vacant, Self::Number)
    }
}

/// A binary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BinOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
    /// `MOD`: remainder.
    Mod,
    /// `AND`: bitwise on numbers, logical between comparisons.
    And,
    /// `OR`: bitwise on numbers, logical between comparisons.
    Or,
    /// `XOR`: bitwise on numbers, logical between comparisons.
    Xor,
    /// `EQ`
    Eq,
    /// `NE`
    Ne,
    /// `GT`
    Gt,
    /// `GE`
    Ge,
    /// `LT`
    Lt,
    /// `LE`
    Le,
    /// `**`: power (LinuxCNC only; it binds tightest).
    Pow,
}

impl BinOp {
    /// How tightly the operator binds: 2 for `* / AND MOD`, 1 for
    /// `+ - OR XOR`, 0 for comparisons (functions bind tightest).
    pub fn precedence(self) -> u8 {
        match self {
            Self::Pow => 3,
            Self::Mul | Self::Div | Self::And | Self::Mod => 2,
            Self::Add | Self::Sub | Self::Or | Self::Xor => 1,
            Self::Eq | Self::Ne | Self::Gt | Self::Ge | Self::Lt | Self::Le => 0,
        }
    }

    /// Whether the operator compares (its result is a truth value).
    pub fn is_comparison(self) -> bool {
        self.precedence() == 0
    }

    /// The operator as written.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Add => "+",
            Self::Sub => "-",
            Self::Mul => "*",
            Self::Div => "/",
            Self::Mod => "MOD",
            Self::And => "AND",
            Self::Or => "OR",
            Self::Xor => "XOR",
            Self::Eq => "EQ",
            Self::Ne => "NE",
            Self::Gt => "GT",
            Self::Ge => "GE",
            Self::Lt => "LT",
            Self::Le => "LE",
            Self::Pow => "**",
        }
    }

    /// Whether the operator is written as a keyword (needs blanks around
    /// it when printed).
    fn is_word(self) -> bool {
        !matches!(
            self,
            Self::Add | Self::Sub | Self::Mul | Self::Div | Self::Pow
        )
    }
}

/// A function of custom macro B.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Func {
    /// Sine of degrees.
    Sin,
    /// Cosine of degrees.
    Cos,
    /// Tangent of degrees.
    Tan,
    /// Arc sine in degrees.
    Asin,
    /// Arc cosine in degrees.
    Acos,
    /// Arc tangent in degrees: `ATAN[a]`, `ATAN[a]/[b]`, `ATAN[a,b]`.
    Atan,
    /// Square root.
    Sqrt,
    /// Absolute value.
    Abs,
    /// Rounding half away from zero.
    Round,
    /// Rounding toward zero.
    Fix,
    /// Rounding away from zero.
    Fup,
    /// Natural logarithm.
    Ln,
    /// Exponential.
    Exp,
    /// `POW[a,b]`: a to the power b.
    Pow,
    /// Addition of the decimal point (undoes least-input-increment scaling).
    Adp,
    /// BCD to binary.
    Bin,
    /// Binary to BCD.
    Bcd,
    /// `EXISTS[#<name>]`: 1 when the named parameter exists (LinuxCNC).
    Exists,
}

impl Func {
    /// All functions with their names, for the parser.
    pub(crate) const ALL: [(&'static [u8], Func); 17] = [
        (b"SIN", Func::Sin),
        (b"COS", Func::Cos),
        (b"TAN", Func::Tan),
        (b"ASIN", Func::Asin),
        (b"ACOS", Func::Acos),
        (b"ATAN", Func::Atan),
        (b"SQRT", Func::Sqrt),
        (b"ABS", Func::Abs),
        (b"ROUND", Func::Round),
        (b"FIX", Func::Fix),
        (b"FUP", Func::Fup),
        (b"LN", Func::Ln),
        (b"EXP", Func::Exp),
        (b"POW", Func::Pow),
        (b"ADP", Func::Adp),
        (b"BIN", Func::Bin),
        (b"BCD", Func::Bcd),
    ];

    /// The function's name as written.
    pub fn name(self) -> &'static str {
        if self == Self::Exists {
            return "EXISTS";
        }
        Self::ALL
            .iter()
            .find(|(_, f)| *f == self)
            .and_then(|(name, _)| std::str::from_utf8(name).ok())
            .unwrap_or("?")
    }
}

/// An expression.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// A constant.
    Number(f64),
    /// The value of a variable.
    Var(Var),
    /// Unary minus. The negation of a vacant value stays vacant.
    Neg(Box<Expr>),
    /// A binary operation.
    Binary(Box<Binary>),
    /// A function call.
    Call(Box<Call>),
}

/// A binary operation with the columns of its whole text.
#[derive(Clone, Debug, PartialEq)]
pub struct Binary {
    /// The operator.
    pub op: BinOp,
    /// Left operand.
    pub lhs: Expr,
    /// Right operand.
    pub rhs: Expr,
    /// The columns of `lhs op rhs`.
    pub span: Span,
}

/// A function call with the columns of its whole text.
#[derive(Clone, Debug, PartialEq)]
pub struct Call {
    /// The function.
    pub func: Func,
    /// The (first) argument.
    pub arg: Expr,
    /// The second argument of `POW` and of the two-argument `ATAN`.
    pub arg2: Option<Expr>,
    /// The columns of the call, brackets included.
    pub span: Span,
}

/// A variable reference: `#n` or `#[expr]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Var {
    /// Which variable.
    pub number: VarNumber,
    /// The columns of the reference.
    pub span: Span,
}

/// How a variable is named.
#[derive(Clone, Debug, PartialEq)]
pub enum VarNumber {
    /// `#n`.
    Direct(u32),
    /// `#[expr]`: the number is computed (and rounded to an integer).
    Indirect(Box<Expr>),
    /// `#<name>`: a LinuxCNC named parameter, its name lower case without
    /// blanks; a name starting with `_` is global, any other local to its
    /// call level.
    Named(Box<str>),
}

/// One line of a program, parsed.
#[derive(Clone, Debug, PartialEq)]
pub struct Line {
    /// 1-based line number in the program.
    pub line: u32,
    /// The `N` sequence number written in front, if any.
    pub sequence: Option<u32>,
    /// The line starts with `/` (block delete); the runner decides.
    pub block_delete: bool,
    /// The text of the first `( … )` comment, without the parentheses
    /// (the message of `#3000 = n (MESSAGE)`).
    pub comment: Option<String>,
    /// What the line does.
    pub statement: Statement,
}

/// What one line does.
#[derive(Clone, Debug, PartialEq)]
pub enum Statement {
    /// `#n = expr`.
    Assign {
        /// The variable written.
        target: Var,
        /// The value.
        value: Expr,
    },
    /// `GOTO n`.
    Goto(Expr),
    /// `IF [cond] GOTO n`.
    IfGoto {
        /// The condition (a truth value).
        cond: Expr,
        /// The sequence number jumped to.
        target: Expr,
    },
    /// `IF [cond] THEN #n = expr`.
    IfThen {
        /// The condition (a truth value).
        cond: Expr,
        /// The variable written when the condition holds.
        target: Var,
        /// The value.
        value: Expr,
    },
    /// `IF [cond] THEN` alone on its line: the lines up to the matching
    /// `ELSE` or `ENDIF` run when the condition holds (structured IF of
    /// the controls that have it: Mitsubishi, Mazak).
    IfBlock {
        /// The condition (a truth value).
        cond: Expr,
    },
    /// `ELSE` of a structured IF.
    Else,
    /// `ENDIF` of a structured IF.
    EndIf,
    /// `WHILE [cond] DO m`.
    While {
        /// The condition (a truth value).
        cond: Expr,
        /// The loop number, 1 … 3.
        id: u8,
    },
    /// `DO m` without `WHILE`: an endless loop.
    Do {
        /// The loop number, 1 … 3.
        id: u8,
    },
    /// `END m`.
    End {
        /// The loop number, 1 … 3.
        id: u8,
    },
    /// An ordinary NC block (possibly empty) whose values may be macro
    /// expressions.
    Nc(NcBlock),
}

/// An NC block whose address values may be variables or expressions.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct NcBlock {
    /// 1-based line number in the program.
    pub line: u32,
    /// The `N` sequence number (the same as the line's).
    pub sequence: Option<u32>,
    /// Block delete (the same as the line's).
    pub block_delete: bool,
    /// The line is a `%` tape mark.
    pub tape_mark: bool,
    /// The words in the order written, `N` left out.
    pub words: Vec<NcWord>,
}

/// One address word of an NC block.
#[derive(Clone, Debug, PartialEq)]
pub struct NcWord {
    /// The address letter, upper case.
    pub letter: u8,
    /// The value as written.
    pub value: WordValue,
    /// The columns of the word, letter included.
    pub span: Span,
}

/// The value of an NC word.
#[derive(Clone, Debug, PartialEq)]
pub enum WordValue {
    /// A number written out (`X-1.5`, `G43.4`).
    Literal {
        /// The number, sign included.
        value: f64,
        /// Whether it was written with a decimal point.
        decimal_point: bool,
        /// Its G/M code form (as `fiveaxis_gcode` computes it).
        code: Option<Code>,
    },
    /// `#n`, `-#n`, `#[e]`, `[e]`, `-[e]` (a minus is an [`Expr::Neg`]).
    Expr(Expr),
}

/// Whether an operand of `parent` needs brackets when printed.
pub(crate) fn needs_brackets(child: &Expr, parent: BinOp, right: bool) -> bool {
    // `ATAN[a]/[b]` reads as the two-argument arc tangent.
    if !right && parent == BinOp::Div && ends_with_atan(child) {
        return true;
    }
    let parent_prec = parent.precedence();
    match child {
        Expr::Binary(b) => {
            let p = b.op.precedence();
            p < parent_prec || (right && p == parent_prec) || (p == 0 && parent_prec == 0)
        }
        _ => false,
    }
}

/// Whether the printed text of `e` ends with a one-argument `ATAN[…]`.
fn ends_with_atan(e: &Expr) -> bool {
    match e {
        Expr::Call(c) => c.func == Func::Atan && c.arg2.is_none(),
        Expr::Neg(inner) => {
            !matches!(**inner, Expr::Binary(_) | Expr::Neg(_)) && ends_with_atan(inner)
        }
        Expr::Binary(b) => !needs_brackets(&b.rhs, b.op, true) && ends_with_atan(&b.rhs),
        Expr::Number(_) | Expr::Var(_) => false,
    }
}

fn write_operand(f: &mut fmt::Formatter<'_>, e: &Expr, bracket: bool) -> fmt::Result {
    if bracket {
        write!(f, "[{e}]")
    } else {
        write!(f, "{e}")
    }
}

impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Number(x) => write!(f, "{x}"),
            Self::Var(v) => write!(f, "{v}"),
            Self::Neg(e) => {
                f.write_str("-")?;
                let bracket = matches!(**e, Self::Binary(_) | Self::Neg(_));
                write_operand(f, e, bracket)
            }
            Self::Binary(b) => {
                write_operand(f, &b.lhs, needs_brackets(&b.lhs, b.op, false))?;
                if b.op.is_word() {
                    write!(f, " {} ", b.op.as_str())?;
                } else {
                    f.write_str(b.op.as_str())?;
                }
                write_operand(f, &b.rhs, needs_brackets(&b.rhs, b.op, true))
            }
            Self::Call(c) => {
                write!(f, "{}[{}", c.func.name(), c.arg)?;
                if let Some(arg2) = &c.arg2 {
                    write!(f, ",{arg2}")?;
                }
                f.write_str("]")
            }
        }
    }
}

impl fmt::Display for Var {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.number {
            VarNumber::Direct(n) => write!(f, "#{n}"),
            VarNumber::Indirect(e) => write!(f, "#[{e}]"),
            VarNumber::Named(name) => write!(f, "#<{name}>"),
        }
    }
}
