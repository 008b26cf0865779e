//! The control's program memory from Python: programs by number
//! (`programs={9010: "..."}`), which `M98` and `G65` call when the running
//! file does not hold them. In memory: Python reads any files.

use std::io::{self, Cursor};

use fiveaxis_control::{ProgramLibrary, ReaderSource, Runner, Source};

/// Program texts by number.
pub type Programs = Vec<(u32, Vec<u8>)>;

/// A program memory held in memory.
#[derive(Debug, Clone, Default)]
pub struct MemoryLibrary {
    programs: Programs,
}

impl ProgramLibrary for MemoryLibrary {
    fn open(&mut self, number: u32) -> io::Result<Option<(Box<dyn Source>, String)>> {
        Ok(self
            .programs
            .iter()
            .find(|(n, _)| *n == number)
            .map(|(n, text)| {
                let source: Box<dyn Source> =
                    Box::new(ReaderSource::new(Cursor::new(text.clone())));
                (source, format!("O{n:04}"))
            }))
    }
}

/// `runner` with the program memory `programs` (unchanged when empty).
pub fn with_programs<'m, S: Source>(runner: Runner<'m, S>, programs: &Programs) -> Runner<'m, S> {
    if programs.is_empty() {
        runner
    } else {
        runner.with_library(Box::new(MemoryLibrary {
            programs: programs.clone(),
        }))
    }
}
