//! A fake control ([`FakeSystem`]) and program store ([`FakeStore`]) for
//! the interpreter's tests, and a runner that collects the blocks.

use std::collections::{HashMap, HashSet};

use fiveaxis_sinumerik::{
    Action, Executed, Interpreter, LangError, Options, ProgramStore, ProgramText, Step, System,
    TextProgram, Value,
};

/// A program in memory that holds the interpreter to the contract of
/// [`ProgramText::seek`]: a seek must go to a line start seen before (a
/// position reported by [`ProgramText::position`]) or 0, else it panics.
#[derive(Debug)]
pub struct StrictText {
    inner: TextProgram,
    seen: HashSet<u64>,
}

impl StrictText {
    /// A strict program of `text`.
    pub fn new(text: &str) -> Self {
        Self {
            inner: TextProgram::new(text),
            seen: HashSet::from([0]),
        }
    }
}

impl ProgramText for StrictText {
    fn read_line(&mut self, buf: &mut Vec<u8>) -> std::io::Result<bool> {
        let more = self.inner.read_line(buf)?;
        self.seen.insert(self.inner.position());
        Ok(more)
    }

    fn position(&self) -> u64 {
        let p = self.inner.position();
        assert!(self.seen.contains(&p), "position {p} never reported");
        p
    }

    fn seek(&mut self, offset: u64) -> std::io::Result<()> {
        assert!(
            self.seen.contains(&offset),
            "seek to {offset}, not a line start seen before"
        );
        self.inner.seek(offset)
    }
}

/// The channel's axes.
pub const AXES: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];

/// Cycles and instructions the fake control carries out.
pub const BUILTINS: [&str; 8] = [
    "CYCLE81", "CYCLE800", "CYCLE832", "TRAORI", "TRANS", "MSG", "TOL", "GETT",
];

/// A control with the axes [`AXES`], the builtins [`BUILTINS`] (or every
/// name), and system variables in a map keyed `NAME[i,j]`.
#[derive(Debug, Default)]
pub struct FakeSystem {
    /// The variables written or preset.
    pub vars: HashMap<String, Value>,
    /// Unknown variables read as 0 instead of an error.
    pub zero_reads: bool,
    /// Every name is a builtin.
    pub all_builtin: bool,
}

/// The key of a system variable with its indices.
pub fn key(name: &str, indices: &[Value]) -> String {
    if indices.is_empty() {
        return name.to_string();
    }
    let parts: Vec<String> = indices
        .iter()
        .map(|v| match v {
            Value::Int(i) => i.to_string(),
            Value::Real(x) => x.to_string(),
            Value::Axis(a) | Value::Str(a) => a.clone(),
            other => format!("{other:?}"),
        })
        .collect();
    format!("{name}[{}]", parts.join(","))
}

impl System for FakeSystem {
    fn read(&mut self, name: &str, indices: &[Value]) -> Result<Value, String> {
        match self.vars.get(&key(name, indices)) {
            Some(v) => Ok(v.clone()),
            None if self.zero_reads => Ok(Value::Int(0)),
            None => Err(format!("no variable {}", key(name, indices))),
        }
    }

    fn write(&mut self, name: &str, indices: &[Value], value: Value) -> Result<(), String> {
        self.vars.insert(key(name, indices), value);
        Ok(())
    }

    fn is_axis(&self, name: &str) -> bool {
        AXES.contains(&name)
    }

    fn is_builtin(&self, name: &str) -> bool {
        self.all_builtin || BUILTINS.contains(&name)
    }
}

/// Programs by name and definition files.
#[derive(Debug, Default, Clone)]
pub struct FakeStore {
    /// Program texts by upper-case name.
    pub programs: HashMap<String, String>,
    /// Definition files: name and text.
    pub definitions: Vec<(String, String)>,
}

impl FakeStore {
    /// A store with `programs`.
    pub fn with(programs: &[(&str, &str)]) -> Self {
        Self {
            programs: programs
                .iter()
                .map(|(n, t)| (n.to_ascii_uppercase(), t.to_string()))
                .collect(),
            definitions: Vec::new(),
        }
    }

    /// Adds a definition file.
    pub fn define(mut self, name: &str, text: &str) -> Self {
        self.definitions.push((name.to_string(), text.to_string()));
        self
    }
}

impl ProgramStore for FakeStore {
    fn open(&mut self, name: &str) -> std::io::Result<Option<Box<dyn ProgramText>>> {
        Ok(self
            .programs
            .get(&name.to_ascii_uppercase())
            .map(|t| Box::new(StrictText::new(t)) as Box<dyn ProgramText>))
    }

    fn definitions(&mut self) -> std::io::Result<Vec<(String, Box<dyn ProgramText>)>> {
        Ok(self
            .definitions
            .iter()
            .map(|(n, t)| {
                (
                    n.clone(),
                    Box::new(TextProgram::new(t.clone())) as Box<dyn ProgramText>,
                )
            })
            .collect())
    }
}

/// What a run gave: the blocks, then the end or an error.
#[derive(Debug)]
pub struct Run {
    /// The blocks yielded.
    pub blocks: Vec<Executed>,
    /// The error that stopped the run, if any.
    pub error: Option<LangError>,
    /// The interpreter's notes.
    pub notes: Vec<String>,
    /// The names of the programs of the blocks.
    pub names: Vec<String>,
    /// Lines read.
    pub lines: u64,
}

impl Run {
    /// The blocks, or a panic with the error.
    pub fn ok(&self) -> &[Executed] {
        if let Some(e) = &self.error {
            panic!("the run stopped: {e:?}");
        }
        &self.blocks
    }

    /// The error, or a panic.
    pub fn err(&self) -> &LangError {
        self.error.as_ref().expect("the run should fail")
    }

    /// Every word as `address=value` in order, values written short.
    pub fn words(&self) -> Vec<String> {
        let mut out = Vec::new();
        for b in self.ok() {
            for a in &b.actions {
                out.push(action_text(a));
            }
        }
        out
    }

    /// The values of every word of `address`.
    pub fn values(&self, address: &str) -> Vec<Value> {
        let mut out = Vec::new();
        for b in self.ok() {
            for a in &b.actions {
                if let Action::Word {
                    address: x, value, ..
                } = a
                    && x == address
                {
                    out.push(value.clone());
                }
            }
        }
        out
    }
}

/// A value written short: `3`, `1.5`, `"S"`, `TRUE`, `X`.
pub fn value_text(v: &Value) -> String {
    match v {
        Value::Int(i) => i.to_string(),
        Value::Real(x) => {
            let s = format!("{x:.6}");
            let s = s.trim_end_matches('0').trim_end_matches('.').to_string();
            if s == "-0" { "0".to_string() } else { s }
        }
        Value::Bool(b) => if *b { "TRUE" } else { "FALSE" }.to_string(),
        Value::Char(c) => format!("'{}'", char::from(*c)),
        Value::Str(s) => format!("\"{s}\""),
        Value::Axis(a) => a.clone(),
        Value::Frame(f) => format!("{f:?}"),
    }
}

/// An action written short: `X=10`, `TRAORI`, `CYCLE81(5,,3)`, `MCALL …`.
pub fn action_text(a: &Action) -> String {
    let args = |args: &[Option<Value>]| {
        args.iter()
            .map(|a| a.as_ref().map(value_text).unwrap_or_default())
            .collect::<Vec<_>>()
            .join(",")
    };
    match a {
        Action::Word { address, value, .. } => format!("{address}={}", value_text(value)),
        Action::Instruction {
            name, args: None, ..
        } => name.clone(),
        Action::Instruction {
            name,
            args: Some(a),
            ..
        } => format!("{name}({})", args(a)),
        Action::ModalCall { call: None, .. } => "MCALL".to_string(),
        Action::ModalCall {
            call: Some((name, a)),
            ..
        } => format!("MCALL {name}({})", args(a)),
        Action::SyncAction { .. } => "SYNC".to_string(),
    }
}

/// Runs `main` with `store`, `sys` and `options` to the end or an error
/// (at most 100 000 blocks).
pub fn run_with(main: &str, store: FakeStore, sys: &mut FakeSystem, options: Options) -> Run {
    let mut interp =
        match Interpreter::new(Box::new(StrictText::new(main)), Box::new(store), options) {
            Ok(i) => i,
            Err(e) => {
                return Run {
                    blocks: Vec::new(),
                    error: Some(e),
                    notes: Vec::new(),
                    names: Vec::new(),
                    lines: 0,
                };
            }
        };
    let mut blocks = Vec::new();
    let mut names = Vec::new();
    let mut error = None;
    let mut out = Executed::default();
    for _ in 0..100_000 {
        match interp.next_block(sys, &mut out) {
            Ok(Step::Block) => {
                names.push(interp.program_name(out.program).to_string());
                blocks.push(out.clone());
            }
            Ok(Step::End) => break,
            Err(e) => {
                error = Some(e);
                break;
            }
        }
    }
    Run {
        blocks,
        error,
        notes: interp.notes().to_vec(),
        names,
        lines: interp.blocks(),
    }
}

/// Runs `main` with `store` on a fresh [`FakeSystem`].
pub fn run_store(main: &str, store: FakeStore) -> Run {
    run_with(main, store, &mut FakeSystem::default(), Options::default())
}

/// Runs `main` alone.
pub fn run(main: &str) -> Run {
    run_store(main, FakeStore::default())
}
