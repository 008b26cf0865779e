//! The syntax tree of one line of a SINUMERIK part program.
//!
//! Every identifier is kept upper-cased (the language is not case
//! sensitive); strings are kept as written. Trees are built by
//! [`crate::parse_line`], which bounds their depth, so walking them
//! recursively is safe.

use fiveaxis_gcode::Span;

/// One line: the block's prefix (skip level, block number, label), what it
/// says, and its comment.
#[derive(Clone, Debug, PartialEq)]
pub struct Line {
    /// The line number given to [`crate::parse_line`].
    pub line: u32,
    /// `/` (level 0) or `/n`: the block is skipped when level `n` is on.
    pub skip: Option<Skip>,
    /// `N10` or the main block `:10`.
    pub number: Option<BlockNumber>,
    /// `NAME:` at the start of the block, a jump target.
    pub label: Option<Name>,
    /// What the block says.
    pub statement: Statement,
    /// The `;` comment to the end of the line, without the `;`.
    pub comment: Option<Comment>,
}

/// A skip level: `/` is level 0, `/3` level 3.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Skip {
    /// 0 … 9.
    pub level: u8,
    /// The columns of `/` and its digit.
    pub span: Span,
}

/// A block number: `N10` (a sub-block) or `:10` (a main block).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlockNumber {
    /// The number.
    pub value: u32,
    /// Written `:n`, a main block.
    pub main: bool,
    /// The columns of the number with its `N` or `:`.
    pub span: Span,
}

/// A name as written, upper-cased, with its columns.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Name {
    /// The name, upper-cased.
    pub text: String,
    /// Its columns.
    pub span: Span,
}

/// A `;` comment.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Comment {
    /// The text after `;`, as written (invalid UTF-8 replaced).
    pub text: String,
    /// The columns of the comment, `;` included.
    pub span: Span,
}

/// What a block says.
#[derive(Clone, Debug, PartialEq)]
pub enum Statement {
    /// Nothing (blanks, a comment, a block number or label alone).
    Empty,
    /// `%_N_NAME_MPF`: the first line of a transfer file, naming the
    /// program. The text after `%`.
    ProgramHeader(String),
    /// `;$PATH=/_N_MPF_DIR`: where the program belongs. The path.
    PathHeader(String),
    /// Words, assignments, calls and jumps, in the order written.
    Block(Vec<Item>),
    /// `DEF …`: a variable definition.
    Def(Def),
    /// `DEFINE NAME AS text`: a macro.
    Define {
        /// The macro's name.
        name: Name,
        /// The text it stands for, as written.
        text: String,
    },
    /// `PROC NAME(…)`: the first line of a subprogram.
    Proc(Proc),
    /// `IF condition` opening a structure.
    If(Expr),
    /// `IF condition GOTOF label`: a conditional jump.
    IfJump {
        /// The condition.
        condition: Expr,
        /// The jump.
        jump: Jump,
    },
    /// `ELSE`
    Else,
    /// `ENDIF`
    EndIf,
    /// `WHILE condition`
    While(Expr),
    /// `ENDWHILE`
    EndWhile,
    /// `FOR variable = from TO to`
    For {
        /// The counter.
        variable: Var,
        /// The first value.
        from: Expr,
        /// The last value.
        to: Expr,
    },
    /// `ENDFOR`
    EndFor,
    /// `REPEAT`
    Repeat,
    /// `UNTIL condition`
    Until(Expr),
    /// `LOOP`
    Loop,
    /// `ENDLOOP`
    EndLoop,
    /// `CASE (selector) OF c1 GOTOF l1 … DEFAULT GOTOF l`
    Case {
        /// The value compared with the constants.
        selector: Expr,
        /// Each constant with its jump.
        arms: Vec<(Expr, Jump)>,
        /// The jump when no constant matches.
        default: Option<Jump>,
    },
    /// A synchronized action: `ID=1 WHENEVER … DO …`.
    SyncAction(SyncAction),
}

/// One element of a block.
#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    /// An address with its value: `X10`, `X=R1*2`, `CR=5`, `G642`, `T="DRILL"`.
    Word(Word),
    /// A value given to a variable: `R1=5`, `_X_HOME=-365`, `$TC_DP3[1,1]=10`.
    Assign(Assign),
    /// A named instruction or a call of a subprogram or cycle.
    Call(Call),
    /// `MCALL name(…)`: a modal call; bare `MCALL` ends one.
    ModalCall {
        /// The call, or none for the bare `MCALL`.
        call: Option<Call>,
        /// The columns from `MCALL` to the end of the call.
        span: Span,
    },
    /// `CALL "NAME"`, `CALL BLOCK A TO B`: an indirect call.
    IndirectCall(IndirectCall),
    /// `GOTOF label` and the other jumps.
    Jump(Jump),
}

/// An address and its value.
#[derive(Clone, Debug, PartialEq)]
pub struct Word {
    /// The address, upper-cased: `X`, `A3`, `CR`, `TURN`, `G`, `M`.
    pub address: String,
    /// The value: a number for a literal (`X-10`, `G642`), else the
    /// expression after `=`.
    pub value: Expr,
    /// `AC(…)`, `IC(…)`, `DC(…)` … around the value.
    pub mode: Option<PositionMode>,
    /// Written with `=`.
    pub equals: bool,
    /// The columns of the whole word.
    pub span: Span,
}

impl Word {
    /// The value when it is a plain number.
    pub fn number(&self) -> Option<f64> {
        match self.value.kind {
            ExprKind::Number(x) => Some(x),
            _ => None,
        }
    }
}

/// How one coordinate is taken, whatever G90/G91 say.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PositionMode {
    /// `AC`: absolute.
    Ac,
    /// `IC`: incremental.
    Ic,
    /// `DC`: rotary axis, absolute along the shorter way.
    Dc,
    /// `ACP`: rotary axis, absolute in the positive direction.
    Acp,
    /// `ACN`: rotary axis, absolute in the negative direction.
    Acn,
}

impl PositionMode {
    /// The mode of a name, upper-cased.
    pub fn from_name(name: &str) -> Option<Self> {
        Some(match name {
            "AC" => Self::Ac,
            "IC" => Self::Ic,
            "DC" => Self::Dc,
            "ACP" => Self::Acp,
            "ACN" => Self::Acn,
            _ => return None,
        })
    }
}

/// `target = value`.
#[derive(Clone, Debug, PartialEq)]
pub struct Assign {
    /// The variable written.
    pub target: Var,
    /// The value.
    pub value: Expr,
    /// The columns of the whole assignment.
    pub span: Span,
}

/// A variable: an R parameter (`R1`, `R[R2]`), a user variable, a system
/// variable (`$AA_IW[X]`), with its indices.
#[derive(Clone, Debug, PartialEq)]
pub struct Var {
    /// The name, upper-cased: `R1`, `R`, `_X_HOME`, `$TC_DP3`.
    pub name: String,
    /// The indices in `[…]`, none for a plain name.
    pub indices: Vec<Expr>,
    /// The columns of the name and its indices.
    pub span: Span,
}

/// A named instruction or a call of a subprogram or cycle: `TRAORI`,
/// `TRAORI(1)`, `MSG("…")`, `CYCLE81(10,,2,)`, `MYSUB`, `L100 P3`.
#[derive(Clone, Debug, PartialEq)]
pub struct Call {
    /// The name, upper-cased.
    pub name: String,
    /// What the name is to the control (a guess from the name alone).
    pub kind: CallKind,
    /// The arguments in parentheses, `None` for an omitted one
    /// (`CYCLE81(10,,2,)`); `None` when there are no parentheses.
    pub args: Option<Vec<Option<Expr>>>,
    /// `P n`: how many times a subprogram runs.
    pub passes: Option<Expr>,
    /// The columns of the name and its arguments.
    pub span: Span,
}

/// What a called name is, known from the name alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CallKind {
    /// A function of a G group written as a word: `SOFT`, `COMPOF`,
    /// `ORIWKS`, `CUT3DC`, `FNORM` … (G groups listed in ONE p1262–1263).
    GFunction,
    /// A programmable frame instruction: `TRANS`, `ATRANS`, `ROT`, `AROT`,
    /// `SCALE`, `MIRROR` … (group 3).
    Frame,
    /// A kinematic transformation switched on or off: `TRAORI`, `TRAFOOF` …
    Transformation,
    /// `SUPA`: frames and offsets suppressed for the block (group 9).
    Suppress,
    /// A predefined procedure: `STOPRE`, `MSG`, `SETAL`, `FGROUP`, `RET`,
    /// `EXTCALL` …
    Procedure,
    /// A Siemens cycle: a name beginning with `CYCLE`.
    Cycle,
    /// Any other name: a user subprogram or cycle.
    User,
}

/// `CALL …`: a call whose program is named by a value.
#[derive(Clone, Debug, PartialEq)]
pub struct IndirectCall {
    /// The program: `"NAME"` or a string variable; none for `CALL BLOCK`
    /// in the current program.
    pub program: Option<Expr>,
    /// `BLOCK start TO end`: run a section of the program.
    pub section: Option<(JumpTarget, Option<JumpTarget>)>,
    /// The columns from `CALL` to the end.
    pub span: Span,
}

/// A jump.
#[derive(Clone, Debug, PartialEq)]
pub struct Jump {
    /// Which jump.
    pub kind: JumpKind,
    /// Where to: none for `GOTOS`.
    pub target: Option<JumpTarget>,
    /// The columns of the keyword and target.
    pub span: Span,
}

/// The jump instructions (AV11 p107).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum JumpKind {
    /// `GOTOF`: search forward.
    Gotof,
    /// `GOTOB`: search backward.
    Gotob,
    /// `GOTO`: forward, then backward.
    Goto,
    /// `GOTOC`: as `GOTO`, no alarm when the target is missing.
    Gotoc,
    /// `GOTOS`: to the start of the program.
    Gotos,
}

/// Where a jump goes.
#[derive(Clone, Debug, PartialEq)]
pub enum JumpTarget {
    /// A label, upper-cased.
    Label(Name),
    /// A block number (`N100` or `100`).
    Block(u32, Span),
}

/// `DEF [scope] type name[dims][=init], …`.
#[derive(Clone, Debug, PartialEq)]
pub struct Def {
    /// `NCK` or `CHAN` (global user data), when written.
    pub scope: Option<Name>,
    /// The type.
    pub ty: Type,
    /// The variables defined.
    pub vars: Vec<Declarator>,
}

/// The data types of `DEF` and `PROC` parameters (840Di p62–63).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Type {
    /// `INT`
    Int,
    /// `REAL`
    Real,
    /// `BOOL`
    Bool,
    /// `CHAR`
    Char,
    /// `STRING[n]`: at most n characters.
    String(u32),
    /// `AXIS`
    Axis,
    /// `FRAME`
    Frame,
}

/// One variable of a `DEF`.
#[derive(Clone, Debug, PartialEq)]
pub struct Declarator {
    /// The name.
    pub name: Name,
    /// The array dimensions (`A[3,4]`), none for a scalar.
    pub dims: Vec<Expr>,
    /// The initial value.
    pub init: Option<Init>,
}

/// The initial value of a `DEF`.
#[derive(Clone, Debug, PartialEq)]
pub enum Init {
    /// `= value`
    Value(Expr),
    /// `= SET(a, b, …)`: the first elements, in order.
    Set(Vec<Expr>),
    /// `= REP(value)`: every element.
    Rep(Expr),
}

/// `PROC NAME(params) attributes`.
#[derive(Clone, Debug, PartialEq)]
pub struct Proc {
    /// The subprogram's name.
    pub name: Name,
    /// Its formal parameters.
    pub params: Vec<Param>,
    /// `SAVE`, `DISPLOF`, `SBLOF` … as written after the parameters.
    pub attributes: Vec<Name>,
}

/// A formal parameter of `PROC`.
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    /// `VAR`: passed by reference.
    pub by_reference: bool,
    /// The type.
    pub ty: Type,
    /// The name.
    pub name: Name,
    /// Array dimensions, when an array.
    pub dims: Vec<Option<Expr>>,
}

/// A synchronized action: `[ID=n|IDS=n] [WHEN|WHENEVER|FROM|EVERY cond] DO actions`.
/// Read, not executed.
#[derive(Clone, Debug, PartialEq)]
pub struct SyncAction {
    /// `ID=n` (modal, false) or `IDS=n` (static, true) with n.
    pub id: Option<(bool, Expr)>,
    /// The condition and when it is tested.
    pub condition: Option<(SyncWhen, Expr)>,
    /// The actions after `DO`.
    pub actions: Vec<Item>,
}

/// When the condition of a synchronized action is tested.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SyncWhen {
    /// `WHEN`: once, the first time it holds.
    When,
    /// `WHENEVER`: every interpolation cycle it holds.
    Whenever,
    /// `FROM`: from the first time it holds on.
    From,
    /// `EVERY`: each time it becomes true.
    Every,
}

/// An expression with its columns.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    /// What it is.
    pub kind: ExprKind,
    /// Its columns.
    pub span: Span,
}

/// The kinds of expression.
#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    /// A number (a sign written before it is part of it).
    Number(f64),
    /// `"text"`.
    String(String),
    /// `TRUE` or `FALSE`.
    Bool(bool),
    /// A variable or an axis name.
    Var(Var),
    /// A unary operator and its operand.
    Unary(UnOp, Box<Expr>),
    /// A binary operator and its operands.
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// A function (`SIN(30)`, `ATAN2(1,2)`, `CTRANS(X,10)`) and its
    /// arguments, `None` for an omitted one.
    Call(String, Vec<Option<Expr>>),
}

/// The unary operators.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum UnOp {
    /// `-`
    Neg,
    /// `+`
    Plus,
    /// `NOT`
    Not,
    /// `B_NOT`
    BitNot,
}

/// The binary operators, with their precedence (ONE p444; 828JP p72).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BinOp {
    /// `*`
    Mul,
    /// `/`
    Div,
    /// `DIV`: integer division.
    IntDiv,
    /// `MOD`
    Mod,
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `B_AND`
    BitAnd,
    /// `B_XOR`
    BitXor,
    /// `B_OR`
    BitOr,
    /// `AND`
    And,
    /// `XOR`
    Xor,
    /// `OR`
    Or,
    /// `<<`: string concatenation.
    Concat,
    /// `==`
    Eq,
    /// `<>`
    Ne,
    /// `>`
    Gt,
    /// `<`
    Lt,
    /// `>=`
    Ge,
    /// `<=`
    Le,
    /// `:`: frames chained (`CTRANS(X,10):CROT(Z,45)`); not mixed with
    /// the other operators (ONE p444), so it binds weakest of all here.
    Chain,
}

impl BinOp {
    /// How tightly the operator binds: 10 for `* / DIV MOD` down to 1 for
    /// the comparisons, which bind weakest (ONE p444); 0 for the frame
    /// chain `:`.
    pub fn precedence(self) -> u8 {
        match self {
            Self::Mul | Self::Div | Self::IntDiv | Self::Mod => 10,
            Self::Add | Self::Sub => 9,
            Self::BitAnd => 8,
            Self::BitXor => 7,
            Self::BitOr => 6,
            Self::And => 5,
            Self::Xor => 4,
            Self::Or => 3,
            Self::Concat => 2,
            Self::Eq | Self::Ne | Self::Gt | Self::Lt | Self::Ge | Self::Le => 1,
            Self::Chain => 0,
        }
    }

    /// The operator as written.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Mul => "*",
            Self::Div => "/",
            Self::IntDiv => "DIV",
            Self::Mod => "MOD",
            Self::Add => "+",
            Self::Sub => "-",
            Self::BitAnd => "B_AND",
            Self::BitXor => "B_XOR",
            Self::BitOr => "B_OR",
            Self::And => "AND",
            Self::Xor => "XOR",
            Self::Or => "OR",
            Self::Concat => "<<",
            Self::Eq => "==",
            Self::Ne => "<>",
            Self::Gt => ">",
            Self::Lt => "<",
            Self::Ge => ">=",
            Self::Le => "<=",
            Self::Chain => ":",
        }
    }

    /// The operator written as a word (`AND`, `DIV` …), upper-cased.
    pub(crate) fn from_word(word: &str) -> Option<Self> {
        Some(match word {
            "DIV" => Self::IntDiv,
            "MOD" => Self::Mod,
            "B_AND" => Self::BitAnd,
            "B_XOR" => Self::BitXor,
            "B_OR" => Self::BitOr,
            "AND" => Self::And,
            "XOR" => Self::Xor,
            "OR" => Self::Or,
            _ => return None,
        })
    }
}
