//! The control's program memory from Python: programs by number
//! (`programs={9010: "..."}`), which `M98` and `G65` call when the running
//! file does not hold them, and SINUMERIK programs by name
//! (`programs={"RLIMIT": "...", "GUD.DEF": "..."}`): subprograms and user
//! cycles called by name, and the definition files read at the start of a
//! SINUMERIK run. In memory: Python reads any files.

use std::io::{self, Cursor};

use fiveaxis_control::{ProgramLibrary, ReaderSource, Runner, Source};
use pyo3::FromPyObject;

/// What a program of the memory is called by.
#[derive(Debug, Clone, FromPyObject)]
pub enum ProgramKey {
    /// A program number (`M98 P…`, `G65 P…`).
    Number(u32),
    /// A SINUMERIK program name (`RLIMIT`, `L100`, `RLIMIT.SPF`,
    /// `_N_RLIMIT_SPF`) or definition file (`GUD.DEF`, `_N_GUD_DEF`).
    Name(String),
}

/// Program texts by number or name.
pub type Programs = Vec<(ProgramKey, Vec<u8>)>;

/// What a SINUMERIK name stands for.
#[derive(Debug, PartialEq, Eq)]
enum Named {
    /// A program, by its name in upper case without extension.
    Program(String),
    /// A definition file (`*.DEF`).
    Definition,
}

/// A name of the program memory as the control reads it: `NAME.DEF` and
/// `_N_NAME_DEF` are definition files; `NAME.SPF`, `NAME.MPF`,
/// `_N_NAME_SPF`, `_N_NAME_MPF` and `NAME` are program `NAME`; case does
/// not matter.
fn classify(name: &str) -> Named {
    let upper = name.to_ascii_uppercase();
    if upper.ends_with(".DEF") || (upper.starts_with("_N_") && upper.ends_with("_DEF")) {
        return Named::Definition;
    }
    let internal = upper
        .strip_prefix("_N_")
        .and_then(|n| n.strip_suffix("_SPF").or_else(|| n.strip_suffix("_MPF")));
    let stem = internal
        .or_else(|| {
            upper
                .strip_suffix(".SPF")
                .or_else(|| upper.strip_suffix(".MPF"))
                .or_else(|| upper.strip_suffix(".H"))
        })
        .unwrap_or(&upper);
    Named::Program(stem.to_owned())
}

/// A program memory held in memory.
#[derive(Debug, Clone, Default)]
pub struct MemoryLibrary {
    /// Programs by number.
    numbered: Vec<(u32, Vec<u8>)>,
    /// SINUMERIK programs by name (upper case, no extension).
    named: Vec<(String, Vec<u8>)>,
    /// SINUMERIK definition files, with their names, in name order.
    definitions: Vec<(String, Vec<u8>)>,
}

impl MemoryLibrary {
    /// The memory of `programs` (the first of two with the same name is
    /// the one called).
    pub fn new(programs: &Programs) -> Self {
        let mut library = Self::default();
        for (key, text) in programs {
            match key {
                ProgramKey::Number(n) => library.numbered.push((*n, text.clone())),
                ProgramKey::Name(name) => match classify(name) {
                    Named::Definition => library.definitions.push((name.clone(), text.clone())),
                    Named::Program(stem) => library.named.push((stem, text.clone())),
                },
            }
        }
        // In name order, as the command line reads a folder's.
        library
            .definitions
            .sort_by_key(|(name, _)| name.to_ascii_uppercase());
        library
    }
}

/// A source reading `text`.
fn source(text: &[u8]) -> Box<dyn Source> {
    Box::new(ReaderSource::new(Cursor::new(text.to_vec())))
}

impl ProgramLibrary for MemoryLibrary {
    fn open(&mut self, number: u32) -> io::Result<Option<(Box<dyn Source>, String)>> {
        Ok(self
            .numbered
            .iter()
            .find(|(n, _)| *n == number)
            .map(|(n, text)| (source(text), format!("O{n:04}"))))
    }

    fn open_sinumerik(&mut self, name: &str) -> io::Result<Option<(Box<dyn Source>, String)>> {
        let Named::Program(wanted) = classify(name) else {
            return Ok(None);
        };
        if let Some((stem, text)) = self.named.iter().find(|(stem, _)| *stem == wanted) {
            return Ok(Some((source(text), stem.clone())));
        }
        // A name of digits alone (`4444411`) is also the program of that
        // number.
        let number = (!wanted.is_empty() && wanted.bytes().all(|b| b.is_ascii_digit()))
            .then(|| wanted.parse::<u32>().ok())
            .flatten()
            .filter(|n| n.to_string() == wanted);
        Ok(number.and_then(|number| {
            self.numbered
                .iter()
                .find(|(n, _)| *n == number)
                .map(|(_, text)| (source(text), wanted.clone()))
        }))
    }

    fn open_heidenhain(&mut self, name: &str) -> io::Result<Option<(Box<dyn Source>, String)>> {
        // `CALL PGM TNC:\PARTS\SUB1.H`: the last part of the path.
        let base = name.rsplit(['\\', '/', ':']).next().unwrap_or(name);
        let Named::Program(wanted) = classify(base) else {
            return Ok(None);
        };
        Ok(self
            .named
            .iter()
            .find(|(stem, _)| *stem == wanted)
            .map(|(stem, text)| (source(text), stem.clone())))
    }

    fn sinumerik_definitions(&mut self) -> io::Result<Vec<(Box<dyn Source>, String)>> {
        Ok(self
            .definitions
            .iter()
            .map(|(name, text)| (source(text), name.clone()))
            .collect())
    }
}

/// `runner` with the program memory `programs` (unchanged when empty).
pub fn with_programs<'m, S: Source>(runner: Runner<'m, S>, programs: &Programs) -> Runner<'m, S> {
    if programs.is_empty() {
        runner
    } else {
        runner.with_library(Box::new(MemoryLibrary::new(programs)))
    }
}
