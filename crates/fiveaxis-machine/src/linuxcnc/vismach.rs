//! The machine's bodies from the configuration's vismach model: the
//! Python script a LinuxCNC configuration loads to draw its machine
//! (`loadusr -W ./NAME-gui.py [var=value …]`), read as far as it is a
//! scene description, and its parts put on the links of the imported
//! machine.
//!
//! Sources (LinuxCNC documentation only): `gui/vismach.adoc` gives the
//! constructors and their arguments: `Collection([parts])`;
//! `Translate([parts], x, y, z)`; `Rotate([parts], th, x, y, z)` (degrees
//! about the vector); `HalTranslate([parts], comp, "pin", x, y, z)` (the
//! pin's value times the vector); `HalRotate([parts], comp, "pin", scale,
//! x, y, z)` (the pin's value times scale, degrees); `HalVectorTranslate`
//! (each component a number or a pin, times an optional scale);
//! `Color(colour, [parts])`; `HalShow`; `Capture()`, the tool tip and the
//! work the scene is seen from (`main(model, tooltip, work, …)`);
//! `Box(x1, y1, z1, x2, y2, z2)` between two opposite corners,
//! `BoxCentered(xw, yw, zw)` about the origin, `BoxCenteredXY(xw, yw, zw)`
//! centred in X and Y from Z = 0 to zw; `CylinderX/Y/Z(c1, r1, c2, r2)`
//! a cylinder or cone between two positions along the axis with those
//! radii; `Sphere(x, y, z, r)`. A transform applies to the parts in its
//! list; the list's own transforms are inside it.
//!
//! It is not a Python interpreter. It reads top-level `NAME = EXPR`
//! statements whose expression is numbers, arithmetic, names of earlier
//! values, lists and the calls above; the `for setting in sys.argv[1:]:
//! exec(setting)` loop takes the loadusr line's `var=value` words there.
//! Everything else (imports, pins, classes, blocks, the HUD) is passed
//! over, and a part built from what it cannot read (a custom class, an
//! STL file, a size from a pin, an unknown function) is left out with a
//! note naming its line. Sizes are bounded: statements, nodes, nesting and
//! the parts of the flattened scene, so no input hangs or panics it.
//!
//! The mapping ([`map_model`]): the scene is a function of its pins; a pin
//! netted to a joint's position follows that machine axis, a pin with a
//! static value (setp, sets, a panel's start value) keeps it, a pin on
//! `motion.tooloffset.*` is 0 (the gauge point), any other is 0. The parts
//! that move with the tool length, or sit beside the tool tip capture in
//! its collection, are the tool: left out. Our machine frame puts the
//! gauge point (the tool tip capture at tool length 0, every joint at 0)
//! at the origin, axes as vismach's world, and moves with the linear
//! translations on the way to the work capture (vismach moves the table
//! where ISO 841 moves the tool): a part's pose at joints q is B(q)⁻¹·V(q)
//! with B(q) the translation to the gauge point plus the work's linear
//! displacement. A part belongs to the link whose motion reproduces that
//! pose at a handful of seeded random joint positions; one that matches
//! none (a knee that moves with Z while the table moves in X and Y) is
//! left out with a note.

use std::collections::{BTreeMap, HashMap};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use nalgebra::{IsometryMatrix3, Point3, Rotation3, Translation3, Unit};

use super::hal::{Drive, Hal};
use super::{Reader, Units, normalize};
use crate::geometry::{Body, Link, Placement, Shape, Solid};
use crate::{
    Joints, MAX_BODIES, MAX_FILE_MAGNITUDE, MAX_SOLIDS, Machine, RESERVED_BODY_NAMES, Vec3,
};

type Iso = IsometryMatrix3<f64>;

/// Most top-level statements read from a script.
const MAX_STATEMENTS: usize = 100_000;
/// Most scene nodes a script may build.
const MAX_NODES: usize = 100_000;
/// Deepest nesting of an expression or of the scene.
const MAX_DEPTH: usize = 64;
/// Most parts (primitives reached from the model) mapped.
const MAX_PARTS: usize = 20_000;
/// Most nodes visited when the scene is flattened (shared sub-scenes are
/// visited once per use).
const MAX_VISITS: usize = 200_000;
/// Most elements of one list.
const MAX_LIST: usize = 10_000;
/// Joint positions a part's motion is compared at.
const SAMPLES: usize = 6;
/// Agreement asked of a part's points, mm.
const TOLERANCE: f64 = 1e-6;

// ----- the scene ---------------------------------------------------------

/// A vismach primitive, in the script's units and its parent's frame.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Prim {
    /// Between two opposite corners.
    Box { lo: Vec3, hi: Vec3 },
    /// Along axis `axis` (0 X, 1 Y, 2 Z) from `c1` (radius `r1`) to `c2`
    /// (radius `r2`).
    Cylinder {
        axis: usize,
        c1: f64,
        r1: f64,
        c2: f64,
        r2: f64,
    },
    /// About a centre.
    Sphere { center: Vec3, radius: f64 },
}

/// A component of a `HalVectorTranslate`.
#[derive(Clone, Debug, PartialEq)]
enum Part {
    Number(f64),
    Pin(String),
}

/// What a group node does to its parts.
#[derive(Clone, Debug, PartialEq)]
enum Xf {
    /// Nothing (`Collection`, `Color`, `HalShow`).
    Identity,
    /// A fixed map (`Translate`, `Rotate`).
    Fixed(Iso),
    /// The pin's value times a vector.
    Translate { pin: String, by: Vec3 },
    /// The pin's value times `scale`, degrees about `axis`.
    Rotate {
        pin: String,
        scale: f64,
        axis: Unit<Vec3>,
    },
    /// Each component a number or a pin, times `scale`.
    Vector { parts: [Part; 3], scale: f64 },
}

impl Xf {
    fn pins(&self) -> Vec<&str> {
        match self {
            Xf::Translate { pin, .. } | Xf::Rotate { pin, .. } => vec![pin.as_str()],
            Xf::Vector { parts, .. } => parts
                .iter()
                .filter_map(|p| match p {
                    Part::Pin(pin) => Some(pin.as_str()),
                    Part::Number(_) => None,
                })
                .collect(),
            Xf::Identity | Xf::Fixed(_) => Vec::new(),
        }
    }
}

#[derive(Clone, Debug)]
enum Child {
    Node(usize),
    /// Something the reader could not build: its entry in
    /// [`Script::unread`].
    Unread(usize),
}

#[derive(Clone, Debug)]
enum Node {
    Group {
        xf: Xf,
        children: Vec<Child>,
        /// The variable it was first assigned to.
        name: Option<String>,
    },
    Prim {
        prim: Prim,
        line: u32,
    },
    Capture,
}

/// A vismach script as far as it was read: its scene graph and the model,
/// tool tip and work `main(…)` names.
#[derive(Clone, Debug, Default)]
pub(crate) struct Script {
    nodes: Vec<Node>,
    /// What could not be read: line, and what it is.
    unread: Vec<(u32, String)>,
    root: Option<Value>,
    tooltip: Option<Value>,
    work: Option<Value>,
    /// `hal.component("NAME")`.
    component: Option<String>,
    /// Whether the `sys.argv` settings loop was met.
    takes_settings: bool,
    /// What stopped the reading early, or was wrong with it.
    notes: Vec<String>,
}

/// A value of the script.
#[derive(Clone, Debug)]
enum Value {
    Number(f64),
    Text(String),
    Node(usize),
    List(Rc<Vec<Value>>),
    Component(String),
    /// Cannot be read: its entry in [`Script::unread`].
    Unread(usize),
}

// ----- reading the script ------------------------------------------------

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Number(f64),
    Name(String),
    Text(String),
    Op(&'static str),
}

#[derive(Clone, Debug)]
struct Token {
    tok: Tok,
    line: u32,
}

const KEYWORDS: [&str; 22] = [
    "import", "from", "class", "def", "if", "elif", "else", "for", "while", "with", "try",
    "except", "finally", "return", "pass", "global", "assert", "del", "raise", "lambda", "async",
    "nonlocal",
];

/// Splits `text` into top-level logical statements (first line, and the
/// code of each physical line with its number). Indented lines (block
/// bodies) and triple-quoted strings are passed over.
/// Physical lines of a statement: number and code.
type Segments = Vec<(u32, String)>;

fn statements(text: &str) -> (Vec<(u32, Segments, bool)>, bool) {
    let mut out = Vec::new();
    let mut triple: Option<&'static str> = None;
    let mut current: Option<(u32, Segments, i64)> = None;
    let mut truncated = false;
    for (index, raw) in text.lines().enumerate() {
        let line = u32::try_from(index + 1).unwrap_or(u32::MAX);
        if out.len() >= MAX_STATEMENTS {
            truncated = true;
            break;
        }
        if let Some(delim) = triple {
            if raw.contains(delim) {
                triple = None;
            }
            continue;
        }
        let starts_block = raw.starts_with([' ', '\t']);
        if current.is_none() {
            let trimmed = raw.trim_start();
            if trimmed.is_empty() || trimmed.starts_with('#') {
                continue;
            }
            if starts_block {
                triple = opens_triple(raw);
                continue;
            }
            current = Some((line, Vec::new(), 0));
        }
        let Some((_, segments, depth)) = current.as_mut() else {
            continue;
        };
        let (code, change, opens) = scan(raw);
        *depth += change;
        let continued = code.trim_end().ends_with('\\');
        let code = code.trim_end().trim_end_matches('\\').to_owned();
        segments.push((line, code));
        if let Some(delim) = opens {
            // A string over several lines: the statement is not read.
            triple = Some(delim);
            if let Some((start, segments, _)) = current.take() {
                out.push((start, segments, false));
            }
            continue;
        }
        if *depth <= 0
            && !continued
            && let Some((start, segments, depth)) = current.take()
        {
            out.push((start, segments, depth == 0));
        }
    }
    if let Some((start, segments, _)) = current.take() {
        // Brackets left open at the end of the script.
        out.push((start, segments, false));
    }
    (out, truncated)
}

/// A line's code before its comment, its bracket balance, and the
/// delimiter of a triple-quoted string it leaves open.
fn scan(raw: &str) -> (String, i64, Option<&'static str>) {
    let mut quote: Option<char> = None;
    let mut depth = 0i64;
    let mut chars = raw.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        match quote {
            Some(q) => {
                if c == '\\' {
                    chars.next();
                } else if c == q {
                    quote = None;
                }
            }
            None => match c {
                '#' => return (raw[..i].to_owned(), depth, None),
                '\'' | '"' => {
                    let delim = if c == '"' { "\"\"\"" } else { "'''" };
                    if raw[i..].starts_with(delim) {
                        let rest = &raw[i + 3..];
                        match rest.find(delim) {
                            Some(end) => {
                                // Closed on the line: skip over it.
                                let skip = rest[..end + 3].chars().count() + 2;
                                for _ in 0..skip {
                                    chars.next();
                                }
                            }
                            None => return (raw[..i].to_owned(), depth, Some(delim)),
                        }
                    } else {
                        quote = Some(c);
                    }
                }
                '(' | '[' | '{' => depth += 1,
                ')' | ']' | '}' => depth -= 1,
                _ => {}
            },
        }
    }
    (raw.to_owned(), depth, None)
}

/// The delimiter of a triple-quoted string an indented line leaves open.
fn opens_triple(raw: &str) -> Option<&'static str> {
    scan(raw).2
}

fn tokenize(segments: &[(u32, String)]) -> Result<Vec<Token>, (u32, String)> {
    let mut out = Vec::new();
    for (line, code) in segments {
        let line = *line;
        let bytes: Vec<char> = code.chars().collect();
        let mut i = 0;
        while i < bytes.len() {
            let c = bytes[i];
            if c.is_whitespace() {
                i += 1;
                continue;
            }
            let start = i;
            let tok = if c.is_ascii_digit()
                || (c == '.' && bytes.get(i + 1).is_some_and(char::is_ascii_digit))
            {
                while i < bytes.len()
                    && (bytes[i].is_ascii_alphanumeric()
                        || bytes[i] == '.'
                        || bytes[i] == '_'
                        || ((bytes[i] == '+' || bytes[i] == '-')
                            && matches!(bytes[i - 1], 'e' | 'E')))
                {
                    i += 1;
                }
                let text: String = bytes[start..i].iter().filter(|c| **c != '_').collect();
                match text.parse::<f64>() {
                    Ok(v) => Tok::Number(v),
                    Err(_) => return Err((line, format!("`{text}` is not a number"))),
                }
            } else if c.is_alphabetic() || c == '_' {
                while i < bytes.len()
                    && (bytes[i].is_alphanumeric() || bytes[i] == '_' || bytes[i] == '.')
                {
                    i += 1;
                }
                Tok::Name(bytes[start..i].iter().collect())
            } else if c == '"' || c == '\'' {
                i += 1;
                let mut text = String::new();
                loop {
                    match bytes.get(i) {
                        None => return Err((line, "a string is not closed".into())),
                        Some('\\') => {
                            if let Some(&next) = bytes.get(i + 1) {
                                text.push(next);
                            }
                            i += 2;
                        }
                        Some(&q) if q == c => {
                            i += 1;
                            break;
                        }
                        Some(&other) => {
                            text.push(other);
                            i += 1;
                        }
                    }
                }
                Tok::Text(text)
            } else {
                const OPS: [&str; 14] = [
                    "**", "//", "==", "(", ")", "[", "]", ",", "=", "+", "-", "*", "/", ":",
                ];
                let rest: String = bytes[i..bytes.len().min(i + 2)].iter().collect();
                match OPS.iter().find(|op| rest.starts_with(**op)) {
                    Some(op) => {
                        i += op.len();
                        Tok::Op(op)
                    }
                    None => return Err((line, format!("`{c}` is not read"))),
                }
            };
            out.push(Token { tok, line });
        }
    }
    Ok(out)
}

/// Reads a vismach script. `settings` are the loadusr line's `var=value`
/// words, taken where the script runs its `sys.argv` loop.
pub(crate) fn read_script(text: &str, settings: &[String]) -> Script {
    let mut s = Reading {
        script: Script::default(),
        vars: HashMap::new(),
    };
    let (statements, truncated) = statements(text);
    for (line, segments, balanced) in statements {
        let first = segments
            .first()
            .map_or("", |(_, c)| c.as_str())
            .trim_start();
        let word = first
            .split(|c: char| !(c.is_alphanumeric() || c == '_'))
            .next()
            .unwrap_or("");
        if KEYWORDS.contains(&word) || first.starts_with('@') {
            if word == "for" && first.contains("sys.argv") {
                s.script.takes_settings = true;
                for (k, setting) in settings.iter().enumerate() {
                    let k = u32::try_from(k + 1).unwrap_or(u32::MAX);
                    s.statement(0, &[(0, setting.clone())], true, Some(k));
                }
            }
            continue;
        }
        s.statement(line, &segments, balanced, None);
    }
    if truncated {
        s.script.notes.push(format!(
            "the script has more than {MAX_STATEMENTS} statements: the rest is not read"
        ));
    }
    s.script
}

struct Reading {
    script: Script,
    vars: HashMap<String, Value>,
}

impl Reading {
    fn unread(&mut self, line: u32, what: impl Into<String>) -> Value {
        self.script.unread.push((line, what.into()));
        Value::Unread(self.script.unread.len() - 1)
    }

    /// One statement; `setting` numbers a loadusr setting.
    fn statement(
        &mut self,
        line: u32,
        segments: &[(u32, String)],
        balanced: bool,
        setting: Option<u32>,
    ) {
        let target = segments.first().and_then(|(_, code)| {
            let (name, rest) = code.split_once('=')?;
            let name = name.trim();
            let ok = !rest.starts_with('=')
                && !name.is_empty()
                && name.chars().all(|c| c.is_alphanumeric() || c == '_')
                && !name.starts_with(|c: char| c.is_ascii_digit());
            ok.then(|| name.to_owned())
        });
        let is_main = segments
            .first()
            .is_some_and(|(_, c)| c.trim_start().starts_with("main("));
        if target.is_none() && !is_main {
            return;
        }
        let where_ = match setting {
            Some(k) => format!("the loadusr setting {k}"),
            None => format!("line {line}"),
        };
        if !balanced {
            if let Some(name) = target {
                let v = self.unread(line, format!("{where_}: its brackets do not balance"));
                self.vars.insert(name, v);
            } else {
                self.script.notes.push(format!(
                    "{where_}: main(…) is not read: its brackets do not balance"
                ));
            }
            return;
        }
        let tokens = match tokenize(segments) {
            Ok(t) => t,
            Err((l, why)) => {
                if let Some(name) = target {
                    let v = self.unread(l, why);
                    self.vars.insert(name, v);
                }
                return;
            }
        };
        if is_main {
            self.main(&tokens);
            return;
        }
        let Some(name) = target else { return };
        // `NAME = EXPR`: the name, `=`, the expression.
        let mut p = Parser {
            tokens: &tokens[2..],
            pos: 0,
            depth: 0,
            line,
        };
        let value = match p.expr(self) {
            Ok(v) if p.pos == p.tokens.len() => v,
            Ok(_) => self.unread(
                line,
                format!("{where_}: `{name} = …` is not read to its end"),
            ),
            Err(why) => self.unread(p.line, why),
        };
        if let Value::Node(i) = value
            && let Some(Node::Group { name: n @ None, .. }) = self.script.nodes.get_mut(i)
        {
            *n = Some(name.clone());
        }
        if let (Value::Component(c), None) = (&value, &self.script.component) {
            self.script.component = Some(c.clone());
        }
        self.vars.insert(name, value);
    }

    /// `main(model, tooltip, work, …)`.
    fn main(&mut self, tokens: &[Token]) {
        let names: Vec<Option<&str>> = tokens[2..]
            .split(|t| t.tok == Tok::Op(","))
            .take(3)
            .map(|arg| match arg {
                [
                    Token {
                        tok: Tok::Name(n), ..
                    },
                ]
                | [
                    Token {
                        tok: Tok::Name(n), ..
                    },
                    Token {
                        tok: Tok::Op(")"), ..
                    },
                ] => Some(n.as_str()),
                _ => None,
            })
            .collect();
        let get = |k: usize| {
            names
                .get(k)
                .copied()
                .flatten()
                .and_then(|n| self.vars.get(n).cloned())
        };
        self.script.root = get(0);
        self.script.tooltip = get(1);
        self.script.work = get(2);
    }

    fn node(&mut self, line: u32, node: Node) -> Value {
        if self.script.nodes.len() >= MAX_NODES {
            return self.unread(line, format!("more than {MAX_NODES} parts in the script"));
        }
        self.script.nodes.push(node);
        Value::Node(self.script.nodes.len() - 1)
    }

    /// A call of `name` with these arguments.
    fn call(&mut self, name: &str, line: u32, args: Vec<Value>, keywords: usize) -> Value {
        let number = |v: &Value| match v {
            Value::Number(x) if x.is_finite() => Some(*x),
            _ => None,
        };
        let numbers = |from: usize, n: usize| -> Option<Vec<f64>> {
            let got: Vec<f64> = args.iter().skip(from).filter_map(number).collect();
            (args.len() == from + n && got.len() == n).then_some(got)
        };
        const KNOWN: [&str; 28] = [
            "hal.component",
            "Capture",
            "Box",
            "BoxCentered",
            "BoxCenteredXY",
            "CylinderX",
            "CylinderY",
            "CylinderZ",
            "Sphere",
            "Collection",
            "Translate",
            "Rotate",
            "Scale",
            "HalTranslate",
            "HalRotate",
            "HalVectorTranslate",
            "HalShow",
            "Color",
            "math.sqrt",
            "sqrt",
            "math.sin",
            "sin",
            "math.cos",
            "cos",
            "math.radians",
            "radians",
            "abs",
            "float",
        ];
        let known = KNOWN.contains(&name) || matches!(name, "int" | "math.degrees" | "degrees");
        if keywords > 0 && known && name != "hal.component" {
            return self.unread(line, format!("`{name}(…)` with keyword arguments"));
        }
        match name {
            "hal.component" => match args.first() {
                Some(Value::Text(t)) => Value::Component(t.clone()),
                _ => self.unread(line, "hal.component without a name"),
            },
            "Capture" if args.is_empty() => self.node(line, Node::Capture),
            "Box" | "BoxCentered" | "BoxCenteredXY" => {
                let Some(v) = numbers(0, if name == "Box" { 6 } else { 3 }) else {
                    return self.unread(line, format!("`{name}` with sizes that are not numbers"));
                };
                let (lo, hi) = match name {
                    "Box" => (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5])),
                    "BoxCentered" => (
                        Vec3::new(-v[0] / 2.0, -v[1] / 2.0, -v[2] / 2.0),
                        Vec3::new(v[0] / 2.0, v[1] / 2.0, v[2] / 2.0),
                    ),
                    _ => (
                        Vec3::new(-v[0] / 2.0, -v[1] / 2.0, 0.0),
                        Vec3::new(v[0] / 2.0, v[1] / 2.0, v[2]),
                    ),
                };
                self.node(
                    line,
                    Node::Prim {
                        prim: Prim::Box { lo, hi },
                        line,
                    },
                )
            }
            "CylinderX" | "CylinderY" | "CylinderZ" => {
                let Some(v) = numbers(0, 4) else {
                    return self.unread(
                        line,
                        format!(
                            "`{name}` with sizes that are not numbers (a custom class or pins)"
                        ),
                    );
                };
                let axis = match name {
                    "CylinderX" => 0,
                    "CylinderY" => 1,
                    _ => 2,
                };
                let prim = Prim::Cylinder {
                    axis,
                    c1: v[0],
                    r1: v[1],
                    c2: v[2],
                    r2: v[3],
                };
                self.node(line, Node::Prim { prim, line })
            }
            "Sphere" => {
                let Some(v) = numbers(0, 4) else {
                    return self.unread(line, "`Sphere` with sizes that are not numbers");
                };
                let prim = Prim::Sphere {
                    center: Vec3::new(v[0], v[1], v[2]),
                    radius: v[3],
                };
                self.node(line, Node::Prim { prim, line })
            }
            "Collection" | "Translate" | "Rotate" | "Scale" | "HalTranslate" | "HalRotate"
            | "HalVectorTranslate" | "HalShow" | "Color" => self.group(name, line, &args),
            "math.sqrt" | "sqrt" | "math.sin" | "sin" | "math.cos" | "cos" | "math.radians"
            | "radians" | "math.degrees" | "degrees" | "abs" | "float" | "int" => {
                let Some(v) = numbers(0, 1) else {
                    return self.unread(line, format!("`{name}` of what is not a number"));
                };
                let x = v[0];
                let r = match name.trim_start_matches("math.") {
                    "sqrt" => x.sqrt(),
                    "sin" => x.sin(),
                    "cos" => x.cos(),
                    "radians" => x.to_radians(),
                    "degrees" => x.to_degrees(),
                    "abs" => x.abs(),
                    "int" => x.trunc(),
                    _ => x,
                };
                Value::Number(r)
            }
            _ => self.unread(
                line,
                format!("`{name}(…)`: not a vismach constructor the importer reads"),
            ),
        }
    }

    /// A transform or collection node.
    fn group(&mut self, name: &str, line: u32, args: &[Value]) -> Value {
        // Color(colour, [parts]); the others ([parts], …).
        let (list, rest) = match (name, args) {
            ("Color", [_, list, ..]) => (list, &args[2..]),
            (_, [list, rest @ ..]) => (list, rest),
            _ => return self.unread(line, format!("`{name}` without parts")),
        };
        let mut children = Vec::new();
        if !self.children(list, &mut children, 0) {
            return self.unread(line, format!("`{name}`: its parts are not a list of parts"));
        }
        let number = |v: &Value| match v {
            Value::Number(x) if x.is_finite() => Some(*x),
            _ => None,
        };
        let pin = |v: &Value| match v {
            Value::Text(t) => Some(t.clone()),
            _ => None,
        };
        let vector = |vs: &[Value]| -> Option<Vec3> {
            match vs {
                [x, y, z] => Some(Vec3::new(number(x)?, number(y)?, number(z)?)),
                _ => None,
            }
        };
        let xf = match name {
            "Collection" | "Color" | "HalShow" => Some(Xf::Identity),
            "Translate" => vector(rest).map(|v| {
                Xf::Fixed(Iso::from_parts(
                    Translation3::from(v),
                    Rotation3::identity(),
                ))
            }),
            "Rotate" => match rest {
                [th, axis @ ..] => number(th).zip(vector(axis)).and_then(|(th, axis)| {
                    let axis = Unit::try_new(axis, 1e-12)?;
                    Some(Xf::Fixed(Iso::from_parts(
                        Translation3::identity(),
                        Rotation3::from_axis_angle(&axis, th.to_radians()),
                    )))
                }),
                _ => None,
            },
            "Scale" => (vector(rest) == Some(Vec3::new(1.0, 1.0, 1.0))).then_some(Xf::Identity),
            "HalTranslate" => match rest {
                [_, p, by @ ..] => pin(p)
                    .zip(vector(by))
                    .map(|(pin, by)| Xf::Translate { pin, by }),
                _ => None,
            },
            "HalRotate" => match rest {
                [_, p, scale, axis @ ..] => (|| {
                    let axis = Unit::try_new(vector(axis)?, 1e-12)?;
                    Some(Xf::Rotate {
                        pin: pin(p)?,
                        scale: number(scale)?,
                        axis,
                    })
                })(),
                _ => None,
            },
            "HalVectorTranslate" => {
                let part = |v: &Value| match v {
                    Value::Text(t) => Some(Part::Pin(t.clone())),
                    other => number(other).map(Part::Number),
                };
                match rest {
                    [_, x, y, z, more @ ..] if more.len() <= 1 => (|| {
                        let scale = match more.first() {
                            Some(s) => number(s)?,
                            None => 1.0,
                        };
                        Some(Xf::Vector {
                            parts: [part(x)?, part(y)?, part(z)?],
                            scale,
                        })
                    })(),
                    _ => None,
                }
            }
            _ => None,
        };
        let Some(xf) = xf else {
            return self.unread(
                line,
                format!("`{name}(…)` with arguments that are not read (numbers, pin names)"),
            );
        };
        self.node(
            line,
            Node::Group {
                xf,
                children,
                name: None,
            },
        )
    }

    /// The parts of a list (nested lists flattened); false when it is not
    /// a list of parts.
    fn children(&self, list: &Value, out: &mut Vec<Child>, depth: usize) -> bool {
        let Value::List(items) = list else {
            return false;
        };
        if depth > MAX_DEPTH {
            return false;
        }
        for item in items.iter() {
            if out.len() >= MAX_LIST {
                return false;
            }
            match item {
                Value::Node(i) => out.push(Child::Node(*i)),
                Value::Unread(k) => out.push(Child::Unread(*k)),
                Value::List(_) => {
                    if !self.children(item, out, depth + 1) {
                        return false;
                    }
                }
                _ => return false,
            }
        }
        true
    }
}

struct Parser<'a> {
    tokens: &'a [Token],
    pos: usize,
    depth: usize,
    line: u32,
}

type Parsed = Result<Value, String>;

impl Parser<'_> {
    fn peek(&self) -> Option<&Tok> {
        self.tokens.get(self.pos).map(|t| &t.tok)
    }

    fn next(&mut self) -> Option<Tok> {
        let t = self.tokens.get(self.pos)?;
        self.line = t.line;
        self.pos += 1;
        Some(t.tok.clone())
    }

    fn eat(&mut self, op: &'static str) -> bool {
        if self.peek() == Some(&Tok::Op(op)) {
            self.pos += 1;
            true
        } else {
            false
        }
    }

    fn deeper(&mut self) -> Result<(), String> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            Err(format!("nested more than {MAX_DEPTH} deep"))
        } else {
            Ok(())
        }
    }

    fn expr(&mut self, r: &mut Reading) -> Parsed {
        self.deeper()?;
        let mut left = self.term(r)?;
        loop {
            let op = if self.eat("+") {
                '+'
            } else if self.eat("-") {
                '-'
            } else {
                break;
            };
            let right = self.term(r)?;
            left = arithmetic(r, self.line, op, &left, &right);
        }
        self.depth -= 1;
        Ok(left)
    }

    fn term(&mut self, r: &mut Reading) -> Parsed {
        let mut left = self.unary(r)?;
        loop {
            // `//` before `/`, which would take its first character.
            let op = if self.eat("*") {
                '*'
            } else if self.eat("//") {
                'f'
            } else if self.eat("/") {
                '/'
            } else {
                break;
            };
            let right = self.unary(r)?;
            left = arithmetic(r, self.line, op, &left, &right);
        }
        Ok(left)
    }

    fn unary(&mut self, r: &mut Reading) -> Parsed {
        if self.eat("-") {
            self.deeper()?;
            let v = self.unary(r)?;
            self.depth -= 1;
            return Ok(arithmetic(r, self.line, '-', &Value::Number(0.0), &v));
        }
        if self.eat("+") {
            self.deeper()?;
            let v = self.unary(r)?;
            self.depth -= 1;
            return Ok(v);
        }
        let base = self.atom(r)?;
        if self.eat("**") {
            self.deeper()?;
            let exponent = self.unary(r)?;
            self.depth -= 1;
            return Ok(arithmetic(r, self.line, '^', &base, &exponent));
        }
        Ok(base)
    }

    fn atom(&mut self, r: &mut Reading) -> Parsed {
        let Some(tok) = self.next() else {
            return Err("an expression ends early".into());
        };
        let line = self.line;
        match tok {
            Tok::Number(v) => Ok(Value::Number(v)),
            Tok::Text(t) => Ok(Value::Text(t)),
            Tok::Op("(") => {
                let items = self.items(r, ")")?;
                Ok(match <[Value; 1]>::try_from(items) {
                    Ok([one]) => one,
                    Err(items) => Value::List(Rc::new(items)),
                })
            }
            Tok::Op("[") => Ok(Value::List(Rc::new(self.items(r, "]")?))),
            Tok::Name(name) => {
                if self.eat("(") {
                    self.deeper()?;
                    let mut args = Vec::new();
                    let mut keywords = 0;
                    while !self.eat(")") {
                        if matches!(self.peek(), Some(Tok::Name(_)))
                            && self.tokens.get(self.pos + 1).map(|t| &t.tok) == Some(&Tok::Op("="))
                        {
                            self.pos += 2;
                            keywords += 1;
                            self.expr(r)?;
                        } else {
                            args.push(self.expr(r)?);
                        }
                        if args.len() + keywords > MAX_LIST {
                            return Err("a call with too many arguments".into());
                        }
                        if !self.eat(",") && self.peek() != Some(&Tok::Op(")")) {
                            return Err(format!("`{name}(…)`: its arguments are not read"));
                        }
                    }
                    self.depth -= 1;
                    return Ok(r.call(&name, line, args, keywords));
                }
                if self.peek() == Some(&Tok::Op("[")) {
                    return Err(format!("`{name}[…]`: indexing is not read"));
                }
                Ok(match name.as_str() {
                    "math.pi" | "pi" => Value::Number(std::f64::consts::PI),
                    "True" => Value::Number(1.0),
                    "False" => Value::Number(0.0),
                    _ => match r.vars.get(&name) {
                        Some(v) => v.clone(),
                        None => {
                            r.unread(line, format!("`{name}` is not a value the importer knows"))
                        }
                    },
                })
            }
            Tok::Op(op) => Err(format!("`{op}` where a value was expected")),
        }
    }

    /// Comma-separated values up to `close`.
    fn items(&mut self, r: &mut Reading, close: &'static str) -> Result<Vec<Value>, String> {
        self.deeper()?;
        let mut items = Vec::new();
        while !self.eat(close) {
            items.push(self.expr(r)?);
            if items.len() > MAX_LIST {
                return Err(format!("a list of more than {MAX_LIST} elements"));
            }
            if !self.eat(",") && self.peek() != Some(&Tok::Op(close)) {
                return Err(format!("a list is not closed by `{close}`"));
            }
        }
        self.depth -= 1;
        Ok(items)
    }
}

fn arithmetic(r: &mut Reading, line: u32, op: char, a: &Value, b: &Value) -> Value {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => Value::Number(match op {
            '+' => x + y,
            '-' => x - y,
            '*' => x * y,
            '/' => x / y,
            'f' => (x / y).floor(),
            _ => x.powf(*y),
        }),
        (Value::Unread(k), _) | (_, Value::Unread(k)) => Value::Unread(*k),
        _ => r.unread(line, "arithmetic on what is not a number"),
    }
}

// ----- the scene as a function of the joints -----------------------------

/// What a pin of the model follows.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Source {
    /// A machine axis: its index, and the machine's mm or degrees per
    /// configuration unit.
    Joint { index: usize, per: f64 },
    /// A static value.
    Static(f64),
    /// The tool length: 0 here.
    Tool,
}

/// A primitive reached from the model, with the group nodes on its way.
#[derive(Clone, Debug)]
pub(crate) struct Instance {
    pub prim: Prim,
    path: Vec<usize>,
    line: u32,
    tool: bool,
    /// The nearest group on the way that moves with a joint.
    motion: Option<usize>,
}

/// The flattened scene with its pins resolved: poses at any joints.
#[derive(Clone, Debug)]
pub(crate) struct Frame {
    script: Script,
    sources: HashMap<String, Source>,
    pub instances: Vec<Instance>,
    tooltip: Option<Vec<usize>>,
    work: Option<Vec<usize>>,
    /// Joint indices of the linear axes.
    linear: usize,
    /// mm per script unit.
    mm: f64,
    /// The gauge point in vismach's world at zero, script units.
    gauge: Vec3,
}

impl Frame {
    fn value(&self, pin: &str, q: &Joints) -> f64 {
        match self.sources.get(pin) {
            Some(Source::Joint { index, per }) => q.get(*index).copied().unwrap_or(0.0) / per,
            Some(Source::Static(v)) => *v,
            Some(Source::Tool) | None => 0.0,
        }
    }

    fn xf(&self, xf: &Xf, q: &Joints) -> Iso {
        let shift = |v: Vec3| Iso::from_parts(Translation3::from(v), Rotation3::identity());
        match xf {
            Xf::Identity => Iso::identity(),
            Xf::Fixed(m) => *m,
            Xf::Translate { pin, by } => shift(by * self.value(pin, q)),
            Xf::Rotate { pin, scale, axis } => Iso::from_parts(
                Translation3::identity(),
                Rotation3::from_axis_angle(axis, (self.value(pin, q) * scale).to_radians()),
            ),
            Xf::Vector { parts, scale } => {
                let c = |p: &Part| match p {
                    Part::Number(v) => *v,
                    Part::Pin(pin) => self.value(pin, q),
                };
                shift(Vec3::new(c(&parts[0]), c(&parts[1]), c(&parts[2])) * *scale)
            }
        }
    }

    /// The map of a path of groups in vismach's world, script units.
    fn path_pose(&self, path: &[usize], q: &Joints) -> Iso {
        let mut m = Iso::identity();
        for &i in path {
            if let Some(Node::Group { xf, .. }) = self.script.nodes.get(i) {
                m *= self.xf(xf, q);
            }
        }
        m
    }

    /// B(q): vismach's world to ours is its inverse; the gauge point plus
    /// the work's linear displacement (rotary joints held at 0).
    fn bed(&self, q: &Joints) -> Iso {
        let mut shift = self.gauge;
        if let Some(work) = &self.work {
            let mut linear = [0.0; crate::MAX_AXES];
            linear[..self.linear].copy_from_slice(&q[..self.linear]);
            let at = |j: &Joints| self.path_pose(work, j).translation.vector;
            shift += at(&linear) - at(&[0.0; crate::MAX_AXES]);
        }
        Iso::from_parts(Translation3::from(shift), Rotation3::identity())
    }

    /// A part's map from its primitive's frame to our machine frame at
    /// `q`, script units.
    pub fn pose(&self, instance: &Instance, q: &Joints) -> Iso {
        self.bed(q).inverse() * self.path_pose(&instance.path, q)
    }

    #[cfg_attr(not(test), allow(dead_code))]
    /// The tool tip (tool length 0) in the work link's frame at `q`, mm:
    /// the work capture's frame at zero (in ours) times the tip seen from
    /// the work capture at `q`.
    pub fn tip_in_work(&self, q: &Joints) -> Option<Vec3> {
        let (tip, work) = (self.tooltip.as_ref()?, self.work.as_ref()?);
        let zero = [0.0; crate::MAX_AXES];
        let w0 = self.bed(&zero).inverse() * self.path_pose(work, &zero);
        let seen = self.path_pose(work, q).inverse() * self.path_pose(tip, q);
        Some((w0 * seen).translation.vector * self.mm)
    }

    /// A primitive's own points: box corners, a cylinder's end centres
    /// and four rim points at each end, a sphere's centre and six poles.
    pub fn points(prim: &Prim) -> Vec<Vec3> {
        match *prim {
            Prim::Box { lo, hi } => (0..8)
                .map(|k| {
                    Vec3::new(
                        if k & 1 == 0 { lo.x } else { hi.x },
                        if k & 2 == 0 { lo.y } else { hi.y },
                        if k & 4 == 0 { lo.z } else { hi.z },
                    )
                })
                .collect(),
            Prim::Cylinder {
                axis,
                c1,
                r1,
                c2,
                r2,
            } => {
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let mut out = Vec::new();
                for (c, r) in [(c1, r1), (c2, r2)] {
                    let mut centre = Vec3::zeros();
                    centre[axis] = c;
                    out.push(centre);
                    for (k, s) in [(u, 1.0), (u, -1.0), (v, 1.0), (v, -1.0)] {
                        let mut p = centre;
                        p[k] = s * r;
                        out.push(p);
                    }
                }
                out
            }
            Prim::Sphere { center, radius } => {
                let mut out = vec![center];
                for k in 0..3 {
                    for s in [1.0, -1.0] {
                        let mut p = center;
                        p[k] += s * radius;
                        out.push(p);
                    }
                }
                out
            }
        }
    }

    /// A part's points in our frame at `q`, mm.
    pub fn part_points(&self, instance: &Instance, q: &Joints) -> Vec<Vec3> {
        let m = self.pose(instance, q);
        Self::points(&instance.prim)
            .iter()
            .map(|p| (m * Point3::from(*p)).coords * self.mm)
            .collect()
    }
}

/// The scene flattened from its root: every primitive with the groups on
/// its way, and the ways to the two captures.
struct Flat {
    instances: Vec<Instance>,
    tooltip: Option<Vec<usize>>,
    work: Option<Vec<usize>>,
    unread: Vec<usize>,
    visits: usize,
    cut: bool,
}

fn flatten(script: &Script, sources: &HashMap<String, Source>) -> Option<Flat> {
    let root = match &script.root {
        Some(Value::Node(i)) => *i,
        _ => return None,
    };
    let capture = |v: &Option<Value>| match v {
        Some(Value::Node(i)) if matches!(script.nodes.get(*i), Some(Node::Capture)) => Some(*i),
        _ => None,
    };
    let (tooltip, work) = (capture(&script.tooltip), capture(&script.work));
    let mut flat = Flat {
        instances: Vec::new(),
        tooltip: None,
        work: None,
        unread: Vec::new(),
        visits: 0,
        cut: false,
    };
    struct Way {
        path: Vec<usize>,
        tool: bool,
        motion: Option<usize>,
    }
    fn walk(
        script: &Script,
        sources: &HashMap<String, Source>,
        node: usize,
        way: &mut Way,
        captures: (Option<usize>, Option<usize>),
        flat: &mut Flat,
    ) {
        if flat.cut {
            return;
        }
        flat.visits += 1;
        if flat.visits > MAX_VISITS || way.path.len() > MAX_DEPTH {
            flat.cut = true;
            return;
        }
        match script.nodes.get(node) {
            Some(Node::Capture) => {
                if Some(node) == captures.0 && flat.tooltip.is_none() {
                    flat.tooltip = Some(way.path.clone());
                }
                if Some(node) == captures.1 && flat.work.is_none() {
                    flat.work = Some(way.path.clone());
                }
            }
            Some(Node::Prim { prim, line }) => {
                if flat.instances.len() >= MAX_PARTS {
                    flat.cut = true;
                    return;
                }
                flat.instances.push(Instance {
                    prim: prim.clone(),
                    path: way.path.clone(),
                    line: *line,
                    tool: way.tool,
                    motion: way.motion,
                });
            }
            Some(Node::Group { xf, children, .. }) => {
                let pins: Vec<Source> = xf
                    .pins()
                    .iter()
                    .map(|p| sources.get(*p).copied().unwrap_or(Source::Static(0.0)))
                    .collect();
                let holds_tip = children
                    .iter()
                    .any(|c| matches!(c, Child::Node(i) if Some(*i) == captures.0));
                let was = (way.tool, way.motion);
                way.tool |= holds_tip || pins.contains(&Source::Tool);
                if pins.iter().any(|s| matches!(s, Source::Joint { .. })) {
                    way.motion = Some(node);
                }
                way.path.push(node);
                for child in children {
                    match child {
                        Child::Node(i) => walk(script, sources, *i, way, captures, flat),
                        Child::Unread(k) => {
                            if !flat.unread.contains(k) {
                                flat.unread.push(*k);
                            }
                        }
                    }
                }
                way.path.pop();
                (way.tool, way.motion) = was;
            }
            None => {}
        }
    }
    let mut way = Way {
        path: Vec::new(),
        tool: false,
        motion: None,
    };
    walk(script, sources, root, &mut way, (tooltip, work), &mut flat);
    Some(flat)
}

// ----- mapping onto the machine ------------------------------------------

/// What [`map_model`] gives: the bodies, the notes, and (for the tests)
/// the scene and the part each solid came from.
#[derive(Debug, Default)]
pub(crate) struct Mapped {
    pub bodies: Vec<Body>,
    pub notes: Vec<String>,
    #[cfg_attr(not(test), allow(dead_code))]
    pub frame: Option<Frame>,
    /// `sources[b][s]`: the instance of body b's solid s.
    #[cfg_attr(not(test), allow(dead_code))]
    pub sources: Vec<Vec<usize>>,
}

/// A small seeded generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
        bits as f64 / (1u64 << 53) as f64
    }
}

/// Joint positions inside the machine's limits (within ±300 mm and ±180°
/// of 0 where the limits are wider).
pub(crate) fn samples(machine: &Machine, n: usize, seed: u64) -> Vec<Joints> {
    let mut rng = Rng(seed | 1);
    let mut out = Vec::new();
    for _ in 0..n {
        let mut q = [0.0; crate::MAX_AXES];
        for (i, a) in machine.linear.iter().enumerate() {
            let (lo, hi) = (a.min.max(-300.0), a.max.min(300.0));
            let (lo, hi) = if lo < hi { (lo, hi) } else { (a.min, a.max) };
            q[i] = lo + (hi - lo) * rng.unit();
        }
        for (k, r) in machine.rotary.iter().enumerate() {
            let (lo, hi) = r.limits.unwrap_or((-180.0, 180.0));
            let (lo, hi) = (lo.max(-180.0), hi.min(180.0));
            let (lo, hi) = if lo < hi {
                (lo, hi)
            } else {
                r.limits.unwrap_or((-180.0, 180.0))
            };
            q[machine.linear.len() + k] = lo + (hi - lo) * rng.unit();
        }
        out.push(q);
    }
    out
}

/// What a configuration's pin follows.
fn source(
    pin: &str,
    hal: &Hal,
    machine: &Machine,
    joints: &[char],
    units: Units,
) -> (Source, String) {
    let axis = |letter: char| {
        machine.axis_index(letter).map(|index| {
            let per = if index < machine.linear.len() {
                units.mm
            } else {
                units.degrees
            };
            (Source::Joint { index, per }, format!("{letter}"))
        })
    };
    // A joint's or an axis' position pin.
    let position = |p: &str| -> Option<(Source, String)> {
        let mut parts = p.split('.');
        let (kind, id, what) = (parts.next()?, parts.next()?, parts.next()?);
        if !what.contains("pos") {
            return None;
        }
        match (kind, id.parse::<usize>()) {
            ("joint", Ok(n)) | ("axis", Ok(n)) => axis(*joints.get(n)?),
            ("axis", Err(_)) => {
                let mut c = id.chars();
                match (c.next(), c.next()) {
                    (Some(l), None) => axis(l.to_ascii_uppercase()),
                    _ => None,
                }
            }
            _ => None,
        }
    };
    match hal.drive(pin) {
        Drive::Set(v, _) => (Source::Static(v), format!("{v}")),
        Drive::Signal { pins, value, .. } => {
            if pins.iter().any(|p| p.starts_with("motion.tooloffset.")) {
                return (Source::Tool, "tool length".into());
            }
            if let Some(found) = pins.iter().find_map(|p| position(p)) {
                return found;
            }
            match value {
                Some((v, _)) => (Source::Static(v), format!("{v}")),
                None => (Source::Static(0.0), "0 (no value)".into()),
            }
        }
        Drive::Unconnected => (Source::Static(0.0), "0 (unconnected)".into()),
    }
}

/// The vismach script of the configuration: the first `loadusr` of a
/// `.py` file that reads as one, its path, the loadusr line's settings,
/// and where that line is.
fn find_script(
    hal: &Hal,
    folder: &Path,
    read: &mut Reader<'_>,
    notes: &mut Vec<String>,
) -> Option<(PathBuf, String, Vec<String>, String)> {
    for load in &hal.loadusr {
        let mut words = load.words.iter().peekable();
        // Options: -W, -w, -i, -n NAME, -Wn NAME.
        while let Some(w) = words.peek() {
            if !w.starts_with('-') {
                break;
            }
            let takes_name = w.ends_with('n');
            words.next();
            if takes_name {
                words.next();
            }
        }
        let Some(program) = words.next() else {
            continue;
        };
        if !program.ends_with(".py") {
            continue;
        }
        let path = normalize(&folder.join(program));
        let at = format!(
            "{}:{}",
            load.file.file_name().map_or_else(
                || load.file.display().to_string(),
                |n| n.to_string_lossy().into_owned()
            ),
            load.line
        );
        match read(&path) {
            Ok(text) if text.contains("vismach") => {
                let settings = words.filter(|w| w.contains('=')).cloned().collect();
                return Some((path, text, settings, at));
            }
            Ok(_) => {}
            Err(e) => notes.push(format!(
                "vismach: {} (loadusr at {at}) cannot be read ({e}): no bodies from it",
                path.display()
            )),
        }
    }
    None
}

/// Lines as "12, 14, 20" (at most a dozen, then how many more).
fn lines(mut v: Vec<u32>) -> String {
    v.sort_unstable();
    v.dedup();
    let mut out: Vec<String> = v.iter().take(12).map(u32::to_string).collect();
    if v.len() > 12 {
        out.push(format!("and {} more", v.len() - 12));
    }
    out.join(", ")
}

fn link_name(machine: &Machine, link: Link) -> String {
    match link {
        Link::Base => "base".into(),
        Link::Head => "head".into(),
        Link::Axis(i) if i < machine.linear.len() => machine.linear[i].name.to_string(),
        Link::Axis(i) => machine
            .rotary
            .get(i - machine.linear.len())
            .map_or_else(|| "?".into(), |r| r.name.to_string()),
    }
}

/// The primitive as a solid: its shape (mm) and the map from the solid's
/// own frame to the primitive's (script units); `None` when it has no
/// size.
fn solid_of(prim: &Prim, mm: f64) -> Option<(Shape, Iso)> {
    let at = |v: Vec3| Iso::from_parts(Translation3::from(v), Rotation3::identity());
    match *prim {
        Prim::Box { lo, hi } => {
            let size = (hi - lo).abs();
            (size.min() > 0.0).then(|| (Shape::Box { size: size * mm }, at((lo + hi) / 2.0)))
        }
        Prim::Cylinder {
            axis,
            c1,
            r1,
            c2,
            r2,
        } => {
            let ((lo, r_lo), (hi, r_hi)) = if c1 <= c2 {
                ((c1, r1.abs()), (c2, r2.abs()))
            } else {
                ((c2, r2.abs()), (c1, r1.abs()))
            };
            let length = hi - lo;
            if length <= 0.0 || r_lo.max(r_hi) <= 0.0 {
                return None;
            }
            // The solid's X, Y, Z onto the next two axes and this one (a
            // cyclic permutation: a rotation).
            let e = |k: usize| Vec3::ith(k % 3, 1.0);
            let r = Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_columns(&[
                e(axis + 1),
                e(axis + 2),
                e(axis),
            ]));
            let mut base = Vec3::zeros();
            base[axis] = lo;
            let shape = if r_lo == r_hi {
                Shape::Cylinder {
                    radius: r_lo * mm,
                    length: length * mm,
                }
            } else {
                Shape::Cone {
                    bottom: r_lo * mm,
                    top: r_hi * mm,
                    length: length * mm,
                }
            };
            Some((shape, Iso::from_parts(Translation3::from(base), r)))
        }
        Prim::Sphere { center, radius } => (radius.abs() > 0.0).then(|| {
            (
                Shape::Sphere {
                    radius: radius.abs() * mm,
                },
                at(center),
            )
        }),
    }
}

/// A number written without float dust.
fn tidy(v: f64) -> f64 {
    let r = (v * 1e9).round() / 1e9;
    if r == 0.0 { 0.0 } else { r }
}

fn tidy_placement(p: Placement) -> Placement {
    let axis = p.axis.map(|c| if c.abs() < 1e-12 { 0.0 } else { c });
    let mut turn = tidy(p.turn);
    if turn <= -180.0 {
        turn += 360.0;
    }
    Placement {
        at: p.at.map(tidy),
        axis: Unit::new_normalize(axis),
        turn: if turn.abs() < 1e-9 { 0.0 } else { turn },
    }
}

/// Solids on one link moved by one node: the link, the node, each solid
/// with its instance.
type Group = (Link, Option<usize>, Vec<(Solid, usize)>);

/// The machine's bodies from the configuration's vismach model, with the
/// notes of what was read, mapped and left out. `joints` gives the
/// coordinate letter of each LinuxCNC joint.
pub(crate) fn map_model(
    folder: &Path,
    hal: &Hal,
    joints: &[char],
    machine: &Machine,
    units: Units,
    read: &mut Reader<'_>,
) -> Mapped {
    let mut out = Mapped::default();
    let Some((path, text, settings, at)) = find_script(hal, folder, read, &mut out.notes) else {
        if out.notes.is_empty() {
            out.notes.push(
                "vismach: the HAL files load no vismach model (loadusr … .py): no bodies; \
                 write [[body]] tables for collision checking"
                    .into(),
            );
        }
        return out;
    };
    let file = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let script = read_script(&text, &settings);
    let mut head = format!("vismach: bodies from {} (loadusr at {at}", path.display());
    if !settings.is_empty() {
        let _ = write!(head, "; settings {}", settings.join(" "));
        if !script.takes_settings {
            head.push_str(", not taken: the script has no sys.argv loop");
        }
    }
    head.push(')');
    out.notes.push(head);
    for n in &script.notes {
        out.notes.push(format!("vismach: {file}: {n}"));
    }
    let Some(component) = script.component.clone() else {
        out.notes.push(format!(
            "vismach: {file}: no hal.component(\"NAME\"): its pins are not known, no bodies"
        ));
        return out;
    };
    // Every pin the scene names.
    let mut sources = HashMap::new();
    let mut pin_notes: BTreeMap<String, String> = BTreeMap::new();
    for node in &script.nodes {
        if let Node::Group { xf, .. } = node {
            for pin in xf.pins() {
                if sources.contains_key(pin) {
                    continue;
                }
                let (s, how) = source(&format!("{component}.{pin}"), hal, machine, joints, units);
                sources.insert(pin.to_owned(), s);
                pin_notes.insert(pin.to_owned(), how);
            }
        }
    }
    let Some(flat) = flatten(&script, &sources) else {
        let why = match &script.root {
            Some(Value::Unread(k)) => script
                .unread
                .get(*k)
                .map_or_else(String::new, |(l, w)| format!(" (line {l}: {w})")),
            _ => String::new(),
        };
        out.notes.push(format!(
            "vismach: {file}: no model read from main(model, tooltip, work){why}: no bodies"
        ));
        return out;
    };
    if !flat.unread.is_empty() {
        let list: Vec<String> = flat
            .unread
            .iter()
            .take(20)
            .filter_map(|k| script.unread.get(*k))
            .map(|(l, w)| format!("{file}:{l}: {w}"))
            .collect();
        let more = flat.unread.len().saturating_sub(20);
        out.notes.push(format!(
            "vismach: left out, not read: {}{}",
            list.join("; "),
            if more > 0 {
                format!("; and {more} more")
            } else {
                String::new()
            }
        ));
    }
    let Some(tip_path) = flat.tooltip.clone() else {
        out.notes.push(format!(
            "vismach: {file}: the tool tip capture (main's second argument) is not in the model: \
             the gauge point is not known, no bodies"
        ));
        return out;
    };
    if flat.work.is_none() {
        out.notes.push(format!(
            "vismach: {file}: the work capture (main's third argument) is not in the model: \
             the bed is taken as fixed in vismach's world"
        ));
    }
    if !pin_notes.is_empty() {
        let list: Vec<String> = pin_notes.iter().map(|(p, h)| format!("{p}: {h}")).collect();
        out.notes.push(format!("vismach: pins {}", list.join(", ")));
    }
    let mut frame = Frame {
        script,
        sources,
        instances: flat.instances,
        tooltip: Some(tip_path.clone()),
        work: flat.work,
        linear: machine.linear.len(),
        mm: units.mm,
        gauge: Vec3::zeros(),
    };
    frame.gauge = frame
        .path_pose(&tip_path, &[0.0; crate::MAX_AXES])
        .translation
        .vector;
    let qs = samples(machine, SAMPLES, 0x005e_ed0f_7a6e);
    let zero = [0.0; crate::MAX_AXES];
    // Candidate links, in order of preference.
    let mut links = vec![Link::Base];
    links.extend((0..machine.linear.len().min(3)).map(Link::Axis));
    links.push(Link::Head);
    links.extend((0..machine.rotary.len()).map(|k| Link::Axis(machine.linear.len() + k)));
    let poses: Vec<Vec<Iso>> = links
        .iter()
        .map(|l| qs.iter().map(|q| machine.link_pose(*l, q)).collect())
        .collect();

    let (mut tool, mut unmatched, mut empty, mut bounds) = (vec![], vec![], vec![], vec![]);
    // (link, motion node) → body index.
    let mut groups: Vec<Group> = Vec::new();
    for (index, inst) in frame.instances.iter().enumerate() {
        if inst.tool {
            tool.push(inst.line);
            continue;
        }
        let Some((shape, local)) = solid_of(&inst.prim, units.mm) else {
            empty.push(inst.line);
            continue;
        };
        let at_zero = frame.part_points(inst, &zero);
        let moved: Vec<Vec<Vec3>> = qs.iter().map(|q| frame.part_points(inst, q)).collect();
        let found = links.iter().zip(&poses).find(|(_, poses)| {
            poses.iter().zip(&moved).all(|(pose, points)| {
                at_zero.iter().zip(points).all(|(p0, p)| {
                    let q = pose * Point3::from(*p0);
                    (q.coords - p).norm() <= TOLERANCE
                })
            })
        });
        let Some((&link, _)) = found else {
            unmatched.push(inst.line);
            continue;
        };
        let mut m = frame.pose(inst, &zero) * local;
        m.translation.vector *= units.mm;
        let place = tidy_placement(Placement::from_isometry(&m));
        let size_ok = |v: f64| v.is_finite() && v.abs() <= MAX_FILE_MAGNITUDE;
        let sizes = match shape {
            Shape::Box { size } => size.iter().all(|v| size_ok(*v)),
            Shape::Cylinder { radius, length } => size_ok(radius) && size_ok(length),
            Shape::Cone {
                bottom,
                top,
                length,
            } => size_ok(bottom) && size_ok(top) && size_ok(length),
            Shape::Sphere { radius } => size_ok(radius),
            Shape::Capsule { .. } | Shape::Mesh { .. } => true,
        };
        if !(sizes && place.at.iter().all(|v| size_ok(*v)) && place.turn.is_finite()) {
            bounds.push(inst.line);
            continue;
        }
        let solid = Solid { shape, place };
        match groups
            .iter_mut()
            .find(|(l, m, _)| *l == link && *m == inst.motion)
        {
            Some((_, _, solids)) => solids.push((solid, index)),
            None => groups.push((link, inst.motion, vec![(solid, index)])),
        }
    }
    // Bodies, named after the variable of the node that moves them.
    let mut dropped_solids = 0usize;
    let mut dropped_bodies = Vec::new();
    for (link, motion, solids) in groups {
        let base = motion
            .and_then(|m| match frame.script.nodes.get(m) {
                Some(Node::Group { name: Some(n), .. }) => Some(n.clone()),
                _ => None,
            })
            .unwrap_or_else(|| match link {
                Link::Base => "frame".into(),
                Link::Head => "head".into(),
                l => link_name(machine, l).to_lowercase(),
            });
        let base = if RESERVED_BODY_NAMES.contains(&base.as_str()) {
            format!("{base}_body")
        } else {
            base
        };
        let mut name = base.clone();
        let mut k = 2;
        while out.bodies.iter().any(|b| b.name == name) {
            name = format!("{base}_{k}");
            k += 1;
        }
        if out.bodies.len() >= MAX_BODIES {
            dropped_bodies.push(name);
            continue;
        }
        if solids.len() > MAX_SOLIDS {
            dropped_solids += solids.len() - MAX_SOLIDS;
        }
        let solids: Vec<(Solid, usize)> = solids.into_iter().take(MAX_SOLIDS).collect();
        out.sources.push(solids.iter().map(|(_, i)| *i).collect());
        out.bodies.push(Body {
            name,
            on: link,
            solids: solids.into_iter().map(|(s, _)| s).collect(),
        });
    }
    // The notes: what is on each link, then what was left out.
    for link in &links {
        let on: Vec<&Body> = out.bodies.iter().filter(|b| b.on == *link).collect();
        if on.is_empty() {
            continue;
        }
        let names: Vec<String> = on
            .iter()
            .map(|b| format!("{} ({})", b.name, b.solids.len()))
            .collect();
        out.notes.push(format!(
            "vismach: on {}: {} solids in {}",
            link_name(machine, *link),
            on.iter().map(|b| b.solids.len()).sum::<usize>(),
            names.join(", ")
        ));
    }
    let mut left = |what: &str, v: Vec<u32>| {
        if !v.is_empty() {
            out.notes.push(format!(
                "vismach: left out, {what}: {} part(s), {file} lines {}",
                v.len(),
                lines(v)
            ));
        }
    };
    left("the tool (the tool comes from the offsets file)", tool);
    left(
        "moving with the joints as no link of the machine does (e.g. a knee that moves with \
         Z while the table moves in X and Y)",
        unmatched,
    );
    left("of no size", empty);
    left("beyond what a machine file holds", bounds);
    if flat.cut {
        out.notes.push(format!(
            "vismach: the model has more than {MAX_PARTS} parts, {MAX_VISITS} visits or \
             {MAX_DEPTH} levels: the rest is left out"
        ));
    }
    if dropped_solids > 0 {
        out.notes.push(format!(
            "vismach: {dropped_solids} solid(s) left out: a body holds at most {MAX_SOLIDS}"
        ));
    }
    if !dropped_bodies.is_empty() {
        out.notes.push(format!(
            "vismach: bodies left out, a machine holds at most {MAX_BODIES}: {}",
            dropped_bodies.join(", ")
        ));
    }
    if out.bodies.is_empty() {
        out.notes
            .push("vismach: no part of the model maps to the machine: no bodies".into());
    }
    out.frame = Some(frame);
    out
}

#[cfg(test)]
mod tests {
    use super::super::{hal::Hal, ini::Ini, kins::Kinematics};
    use super::*;

    /// The corpus's LinuxCNC configurations, beside the repository.
    fn corpus() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus/linuxcnc-configs")
    }

    /// The imported machine of a corpus configuration and its vismach
    /// mapping; `None` (said on the terminal) without the corpus.
    fn load(relative: &str) -> Option<(Machine, Mapped)> {
        let ini_path = corpus().join(relative);
        if !ini_path.exists() {
            eprintln!(
                "skipped: this test needs {} (the shared corpus beside the repository)",
                ini_path.display()
            );
            return None;
        }
        let mut read = |p: &Path| std::fs::read_to_string(p);
        let imported = super::super::import_linuxcnc(&ini_path, &mut read).expect("imports");
        let ini = Ini::read(&ini_path, &mut read).expect("ini");
        let folder = ini_path.parent().expect("a folder").to_path_buf();
        let mut notes = Vec::new();
        let units = super::super::units(&ini, &ini_path, &mut notes).expect("units");
        let hal = Hal::read(&ini, &folder, &mut read).expect("hal");
        let kins = Kinematics::read(&ini, &ini_path, &hal, units, &mut notes).expect("kins");
        let machine = imported.machine;
        let mapped = map_model(&folder, &hal, &kins.joints, &machine, units, &mut read);
        assert_eq!(mapped.bodies, machine.bodies, "{relative}");
        Some((machine, mapped))
    }

    const CONFIGS: [&str; 7] = [
        "axis/vismach/5axis/table-rotary-tilting/xyzac-trt.ini",
        "axis/vismach/5axis/table-rotary-tilting/xyzbc-trt.ini",
        "axis/vismach/5axis/table-dual-rotary/xyzab-tdr.ini",
        "gmoccapy/non_trivial_kinematics/table-rotary-tilting/xyzac-trt.ini",
        "axis/vismach/5axis/bridgemill/5axis.ini",
        "axis/vismach/5axis/table-rotary_spindle-rotary-nutating/xyzacb-trsrn_twp/xyzacb-trsrn.ini",
        "axis/vismach/5axis/table-rotary_spindle-rotary-nutating/xyzbca-trsrn_twp/xyzbca-trsrn.ini",
    ];

    /// A solid's own points in its frame: the counterparts of
    /// [`Frame::points`] for the shape the importer wrote.
    fn shape_points(shape: &Shape) -> Vec<Vec3> {
        match *shape {
            Shape::Box { size } => (0..8)
                .map(|k| {
                    let s = |bit: usize, v: f64| if k & bit == 0 { -v / 2.0 } else { v / 2.0 };
                    Vec3::new(s(1, size.x), s(2, size.y), s(4, size.z))
                })
                .collect(),
            Shape::Cylinder { radius, length } => ends(radius, radius, length),
            Shape::Cone {
                bottom,
                top,
                length,
            } => ends(bottom, top, length),
            Shape::Sphere { radius } => {
                let mut out = vec![Vec3::zeros()];
                for k in 0..3 {
                    out.push(Vec3::ith(k, radius));
                    out.push(Vec3::ith(k, -radius));
                }
                out
            }
            Shape::Capsule { .. } | Shape::Mesh { .. } => Vec::new(),
        }
    }

    fn ends(bottom: f64, top: f64, length: f64) -> Vec<Vec3> {
        let mut out = Vec::new();
        for (z, r) in [(0.0, bottom), (length, top)] {
            out.push(Vec3::new(0.0, 0.0, z));
            for (x, y) in [(r, 0.0), (-r, 0.0), (0.0, r), (0.0, -r)] {
                out.push(Vec3::new(x, y, z));
            }
        }
        out
    }

    /// Every mapped solid, moved by its link at random joints, covers the
    /// points of its vismach primitive evaluated directly from the scene
    /// (as sets: a cylinder written from its other end is the same one).
    #[test]
    fn corpus_solids_move_as_their_vismach_parts() {
        for config in CONFIGS {
            let Some((machine, mapped)) = load(config) else {
                return;
            };
            let Some(frame) = &mapped.frame else { continue };
            for q in samples(&machine, 8, 0xfeed) {
                for (body, sources) in mapped.bodies.iter().zip(&mapped.sources) {
                    for (solid, &index) in body.solids.iter().zip(sources) {
                        let direct = frame.part_points(&frame.instances[index], &q);
                        let map = machine.link_pose(body.on, &q) * solid.place.isometry();
                        let written: Vec<Vec3> = shape_points(&solid.shape)
                            .iter()
                            .map(|p| (map * Point3::from(*p)).coords)
                            .collect();
                        assert_eq!(written.len(), direct.len(), "{config} {}", body.name);
                        for (a, b) in [(&written, &direct), (&direct, &written)] {
                            for p in a {
                                let near =
                                    b.iter().map(|d| (d - p).norm()).fold(f64::MAX, f64::min);
                                assert!(
                                    near < 1e-6,
                                    "{config}: body {} at {q:?}: {p:?} is {near} from the model",
                                    body.name
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    /// The kernel's forward kinematics of the tool tip, in the work
    /// link's frame, against the vismach tool tip seen from the vismach
    /// work capture: the frame alignment tied to the kinematics. Where the
    /// model and the imported kinematics disagree the test says how.
    #[test]
    fn corpus_tip_seen_from_the_work_is_the_forward_kinematics() {
        for config in CONFIGS {
            let Some((mut machine, mapped)) = load(config) else {
                return;
            };
            let Some(frame) = &mapped.frame else {
                // The nutating heads: the tool tip sits under a custom
                // class (HalRotateNutation), so the gauge point is not
                // known and there are no bodies.
                assert!(config.contains("trsrn"), "{config}");
                assert!(mapped.bodies.is_empty());
                assert!(
                    mapped.notes.iter().any(|n| n.contains("HalRotateNutation")),
                    "{:?}",
                    mapped.notes
                );
                continue;
            };
            if config.contains("tdr") {
                // xyzab-tdr-gui.py turns A about -X and B about -Y; the
                // importer (no formulas in the documentation) takes the
                // trt modules' senses: the model agrees with both reversed.
                for r in &mut machine.rotary {
                    r.axis = -r.axis;
                }
            }
            if config.contains("bridgemill") {
                // 5axisgui.py's pivot_len = 250; the importer writes the
                // pivot at the gauge point (the length is the GUI's).
                for r in &mut machine.rotary {
                    r.center = Vec3::new(0.0, 0.0, 250.0);
                }
            }
            for mut q in samples(&machine, 12, 0xbeef) {
                // The model does not draw a quill (W).
                let linear = machine.linear.len();
                q[3..linear].fill(0.0);
                let model = frame.tip_in_work(&q).expect("both captures");
                let kernel = machine.forward(&q, 0.0).tip;
                assert!(
                    (model - kernel).norm() < 1e-6,
                    "{config} at {q:?}: model {model:?}, forward kinematics {kernel:?}"
                );
            }
        }
    }

    #[test]
    fn arithmetic_names_and_settings() {
        let text = r#"import math
c = hal.component("g")
w = 2 * (3 + 4) - -1
len = 10
for s in sys.argv[1:]: exec(s)
b = BoxCentered(w, len / 2, math.pi)
m = Collection([b, Sphere(0, 0, 0, 2 ** 2)])
main(m, m, m)
"#;
        let script = read_script(text, &["len=20".into()]);
        assert!(script.takes_settings);
        assert_eq!(script.component.as_deref(), Some("g"));
        let Some(Node::Prim { prim, .. }) = script.nodes.first() else {
            panic!("{:?}", script.nodes)
        };
        let h = std::f64::consts::PI / 2.0;
        assert_eq!(
            *prim,
            Prim::Box {
                lo: Vec3::new(-7.5, -5.0, -h),
                hi: Vec3::new(7.5, 5.0, h)
            }
        );
        assert!(matches!(
            script.nodes.get(1),
            Some(Node::Prim { prim: Prim::Sphere { radius, .. }, .. }) if *radius == 4.0
        ));
        assert!(matches!(script.root, Some(Value::Node(2))));
    }

    #[test]
    fn floor_division_is_not_read_as_division() {
        let script = read_script("b = BoxCentered(7 // 2, 9 / 2, 1)\nmain(b, b, b)\n", &[]);
        let Some(Node::Prim { prim, .. }) = script.nodes.first() else {
            panic!("{:?}", script.nodes)
        };
        assert_eq!(
            *prim,
            Prim::Box {
                lo: Vec3::new(-1.5, -2.25, -0.5),
                hi: Vec3::new(1.5, 2.25, 0.5)
            }
        );
    }

    #[test]
    fn blocks_strings_and_comments_are_passed_over() {
        let text = r#"'''
b = Box(0, 0, 0, 1, 1, 1)
'''
class A(CylinderZ):
    def f(self):
        return Box(0, 0, 0, 1, 1, 1)
if x:
    b = Box(0, 0, 0, 1, 1, 1)
b = Box(0, 0, 0, # a comment (
  2, 2, 2)  # ]
t = "[("
"#;
        let script = read_script(text, &[]);
        assert_eq!(script.nodes.len(), 1, "{:?}", script.nodes);
        assert!(matches!(
            script.nodes[0],
            Node::Prim { prim: Prim::Box { hi, .. }, line: 9 } if hi == Vec3::new(2.0, 2.0, 2.0)
        ));
    }

    #[test]
    fn garbage_is_bounded() {
        let deep = format!("x = {}1{}\n", "[".repeat(100_000), "]".repeat(100_000));
        let many = "a = Box(0, 0, 0, 1, 1, 1)\n".repeat(200_000);
        let doubling = format!(
            "a = Box(0, 0, 0, 1, 1, 1)\n{}main(a, a, a)\n",
            "a = Collection([a, a])\n".repeat(80)
        );
        for text in [
            deep.as_str(),
            &many,
            &doubling,
            "x = ((((\n",
            "x = 1e999 * 0\n",
            "x = [\"\n",
            "main(\n",
        ] {
            let script = read_script(text, &[]);
            assert!(script.nodes.len() <= MAX_NODES);
            let sources = HashMap::new();
            if let Some(flat) = flatten(&script, &sources) {
                assert!(flat.instances.len() <= MAX_PARTS && flat.visits <= MAX_VISITS + 1);
                assert!(flat.cut || text != doubling);
            }
        }
        let script = read_script(&many, &[]);
        assert!(script.notes.iter().any(|n| n.contains("more than")));
    }
}
