//! The control's program memory beyond the running file: programs that
//! `M98` / `G65` call and that are kept in files of their own.
//!
//! The runner reads every line through [`Sources`]: the main program's
//! source and the library programs opened so far. A position is one `u64`
//! for all of them: the file's index in the top [`FILE_BITS`] bits (0 for
//! the main program), the byte offset in the rest, so that marks, jumps
//! and the macro cache work across files unchanged.

use std::io;

use fiveaxis_gcode::{Block, Syntax};

use super::Source;

/// Programs kept outside the running file (`--programs DIR`).
pub trait ProgramLibrary: Send {
    /// Program number `number`: a source at its start and a name for
    /// messages (its path), or `None` when the library has no such program.
    ///
    /// # Errors
    ///
    /// The program exists but cannot be read.
    fn open(&mut self, number: u32) -> io::Result<Option<(Box<dyn Source>, String)>>;

    /// The file of LinuxCNC subroutine `name` (`o<name> call`, `o123
    /// call`: `name.ngc` in the subroutine path), or `None`. Default:
    /// none.
    ///
    /// # Errors
    ///
    /// The file exists but cannot be read.
    fn open_named(&mut self, _name: &str) -> io::Result<Option<(Box<dyn Source>, String)>> {
        Ok(None)
    }

    /// The SINUMERIK program `name` (a subprogram or user cycle called
    /// by name: `NAME.SPF`, `NAME.MPF`, `_N_NAME_SPF`, `_N_NAME_MPF`,
    /// found case-insensitively), or `None`. Default: none.
    ///
    /// # Errors
    ///
    /// The file exists but cannot be read.
    fn open_sinumerik(&mut self, _name: &str) -> io::Result<Option<(Box<dyn Source>, String)>> {
        Ok(None)
    }

    /// The HEIDENHAIN program `name` as `CALL PGM` writes it (`SUB1`,
    /// `SUB1.H`, `TNC:\\PARTS\\SUB1.H`): the file of that name (its last
    /// path component) with or without `.h`, found case-insensitively,
    /// or `None`. Default: none.
    ///
    /// # Errors
    ///
    /// The file exists but cannot be read.
    fn open_heidenhain(&mut self, _name: &str) -> io::Result<Option<(Box<dyn Source>, String)>> {
        Ok(None)
    }

    /// The SINUMERIK definition files (`*.DEF`: global user data and
    /// macros), each with its name. Default: none.
    ///
    /// # Errors
    ///
    /// A file cannot be read.
    fn sinumerik_definitions(&mut self) -> io::Result<Vec<(Box<dyn Source>, String)>> {
        Ok(Vec::new())
    }
}

/// A source as the language interpreters (SINUMERIK, HEIDENHAIN) read a
/// program: the main program handed over by [`Sources::take_main`], or a
/// program of the library.
pub(super) struct SourceText<S>(pub(super) S);

impl<S: Source> fiveaxis_gcode::ProgramText for SourceText<S> {
    fn read_line(&mut self, buf: &mut Vec<u8>) -> io::Result<bool> {
        self.0.read_line(buf)
    }

    fn position(&self) -> u64 {
        self.0.position()
    }

    fn seek(&mut self, offset: u64) -> io::Result<()> {
        self.0.seek(offset)
    }
}

/// Bits of a position that hold the file index.
pub(super) const FILE_BITS: u32 = 12;
/// Bits of a position that hold the byte offset.
const OFFSET_BITS: u32 = 64 - FILE_BITS;
const OFFSET_MASK: u64 = (1 << OFFSET_BITS) - 1;
/// Most library programs one run opens.
pub(super) const MAX_OPEN: usize = (1 << FILE_BITS) - 2;

/// The file index of a position.
pub(super) fn file_of(position: u64) -> usize {
    (position >> OFFSET_BITS) as usize
}

/// The position of the start of file `file`.
pub(super) fn file_start(file: usize) -> u64 {
    (file as u64) << OFFSET_BITS
}

/// The main program and the library programs opened so far.
pub(super) struct Sources<S> {
    /// The main program; `None` once handed over whole
    /// ([`Sources::take_main`]).
    main: Option<S>,
    /// What reads in its place then: nothing.
    drained: super::SliceSource<'static>,
    library: Option<Box<dyn ProgramLibrary>>,
    open: Vec<(u32, String, Box<dyn Source>)>,
    /// Files opened by name (LinuxCNC subroutines): name, file index.
    named: Vec<(String, usize)>,
    current: usize,
}

impl<S> std::fmt::Debug for Sources<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Sources")
            .field("open", &self.open.len())
            .field("current", &self.current)
            .finish()
    }
}

impl<S: Source> Sources<S> {
    pub(super) fn new(main: S) -> Self {
        Self {
            main: Some(main),
            drained: super::SliceSource::new(b""),
            library: None,
            open: Vec::new(),
            named: Vec::new(),
            current: 0,
        }
    }

    pub(super) fn set_library(&mut self, library: Box<dyn ProgramLibrary>) {
        self.library = Some(library);
    }

    /// The program memory, handed over whole (a SINUMERIK run reads it
    /// through its own interpreter).
    pub(super) fn take_library(&mut self) -> Option<Box<dyn ProgramLibrary>> {
        self.library.take()
    }

    /// The main program, handed over whole (a SINUMERIK run reads it
    /// through its own interpreter); `None` once taken.
    pub(super) fn take_main(&mut self) -> Option<S> {
        self.main.take()
    }

    /// The start of program `number` in the library, opening it; `None`
    /// when there is no library or it lacks the program.
    pub(super) fn library_program(&mut self, number: u32) -> io::Result<Option<u64>> {
        if let Some(k) = self.open.iter().position(|(n, _, _)| *n == number) {
            return Ok(Some(file_start(k + 1)));
        }
        let Some(library) = self.library.as_mut() else {
            return Ok(None);
        };
        if self.open.len() >= MAX_OPEN {
            return Err(io::Error::other(format!(
                "more than {MAX_OPEN} programs called from the program library"
            )));
        }
        match library.open(number)? {
            Some((source, name)) => {
                self.open.push((number, name, source));
                Ok(Some(file_start(self.open.len())))
            }
            None => Ok(None),
        }
    }

    /// The start of the file of subroutine `name` in the library,
    /// opening it; `None` when there is no library or it lacks the file.
    pub(super) fn library_named(&mut self, name: &str) -> io::Result<Option<u64>> {
        if let Some((_, k)) = self.named.iter().find(|(n, _)| n == name) {
            return Ok(Some(file_start(*k)));
        }
        let Some(library) = self.library.as_mut() else {
            return Ok(None);
        };
        if self.open.len() >= MAX_OPEN {
            return Err(io::Error::other(format!(
                "more than {MAX_OPEN} files opened from the program library"
            )));
        }
        match library.open_named(name)? {
            Some((source, path)) => {
                // Number u32::MAX: not a numbered program.
                self.open.push((u32::MAX, path, source));
                self.named.push((name.to_owned(), self.open.len()));
                Ok(Some(file_start(self.open.len())))
            }
            None => Ok(None),
        }
    }

    /// The name of the file being read, `None` for the main program.
    pub(super) fn current_name(&self) -> Option<&str> {
        self.current
            .checked_sub(1)
            .and_then(|k| self.open.get(k))
            .map(|(_, name, _)| name.as_str())
    }

    fn inner(&mut self) -> &mut dyn Source {
        match self
            .current
            .checked_sub(1)
            .and_then(|k| self.open.get_mut(k))
        {
            Some((_, _, source)) => source.as_mut(),
            None => match self.main.as_mut() {
                Some(main) => main,
                None => &mut self.drained,
            },
        }
    }
}

impl<S: Source> Source for Sources<S> {
    fn read_line(&mut self, buf: &mut Vec<u8>) -> io::Result<bool> {
        self.inner().read_line(buf)
    }

    fn position(&self) -> u64 {
        let inner = match self.current.checked_sub(1).and_then(|k| self.open.get(k)) {
            Some((_, _, source)) => source.position(),
            None => self.main.as_ref().map_or(0, |main| main.position()),
        };
        file_start(self.current) | (inner & OFFSET_MASK)
    }

    fn seek(&mut self, offset: u64) -> io::Result<()> {
        let file = file_of(offset);
        if file > self.open.len() {
            return Err(io::Error::other(
                "a jump into a program file that is not open",
            ));
        }
        self.current = file;
        self.inner().seek(offset & OFFSET_MASK)
    }

    fn read_blocks_as(&mut self, syntax: Syntax) {
        if let Some(main) = self.main.as_mut() {
            main.read_blocks_as(syntax);
        }
    }

    fn take_block(&mut self, line: u32, block: &mut Block) -> bool {
        self.inner().take_block(line, block)
    }
}
