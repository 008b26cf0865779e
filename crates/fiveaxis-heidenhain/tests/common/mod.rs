//! Helpers of the interpreter's tests: a strict program text, a fake
//! control and a runner that collects the blocks.
#![allow(dead_code)]

use std::collections::{HashMap, HashSet};

use fiveaxis_heidenhain::{
    Executed, Interpreter, LangError, MemoryStore, Options, ProgramStore, ProgramText, Step,
    System, TextProgram,
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
        self.inner.position()
    }

    fn seek(&mut self, offset: u64) -> std::io::Result<()> {
        assert!(
            self.seen.contains(&offset),
            "seek to {offset}, not a line start seen before"
        );
        self.inner.seek(offset)
    }
}

/// A control whose `FN 18` data are a table.
#[derive(Debug, Default)]
pub struct FakeSystem {
    /// (group, number, index) → value.
    pub data: HashMap<(u32, u32, Option<u32>), f64>,
}

impl System for FakeSystem {
    fn sysread(&mut self, group: u32, number: u32, index: Option<u32>) -> Result<f64, String> {
        self.data
            .get(&(group, number, index))
            .copied()
            .ok_or_else(|| format!("ID{group} NR{number} unknown"))
    }
}

/// Options with a small budget.
pub fn options() -> Options {
    Options {
        block_skip: true,
        max_blocks: 100_000,
    }
}

/// Runs `text` with `store` to its end: the blocks, or the error and the
/// blocks before it.
pub fn run_with(
    text: &str,
    store: impl ProgramStore + 'static,
    opts: Options,
) -> Result<Vec<Executed>, (LangError, Vec<Executed>)> {
    let mut i = Interpreter::new(Box::new(StrictText::new(text)), Box::new(store), opts)
        .map_err(|e| (e, Vec::new()))?;
    let mut sys = FakeSystem::default();
    let mut out = Vec::new();
    let mut b = Executed::default();
    loop {
        match i.next_block(&mut sys, &mut b) {
            Ok(Step::Block) => out.push(b.clone()),
            Ok(Step::End) => return Ok(out),
            Err(e) => return Err((e, out)),
        }
    }
}

/// Runs `text` (no programs to call) to its end.
pub fn run(text: &str) -> Vec<Executed> {
    match run_with(text, MemoryStore::new(), options()) {
        Ok(v) => v,
        Err((e, _)) => panic!("line {}: {} ({:?})", e.line, e.message, e.kind),
    }
}

/// Runs `text` and gives the error.
pub fn run_err(text: &str) -> LangError {
    match run_with(text, MemoryStore::new(), options()) {
        Ok(v) => panic!("no error; {} blocks", v.len()),
        Err((e, _)) => e,
    }
}

/// Runs `text` and gives the interpreter at the end, for its Q values.
pub fn run_q(text: &str) -> Interpreter<'static> {
    let mut i = Interpreter::new(
        Box::new(StrictText::new(text)),
        Box::new(MemoryStore::new()),
        options(),
    )
    .expect("new");
    let mut sys = FakeSystem::default();
    let mut b = Executed::default();
    loop {
        match i.next_block(&mut sys, &mut b) {
            Ok(Step::Block) => {}
            Ok(Step::End) => return i,
            Err(e) => panic!("line {}: {} ({:?})", e.line, e.message, e.kind),
        }
    }
}

/// The value of word `a` of block `b`.
pub fn w(b: &Executed, a: &str) -> f64 {
    b.word(a)
        .unwrap_or_else(|| panic!("no word {a} in {b:?}"))
        .value
}

/// The keys of a block.
pub fn keys(b: &Executed) -> Vec<&str> {
    b.keys.iter().map(|k| k.key.as_str()).collect()
}
