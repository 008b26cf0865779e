//! A program's text as the language interpreters read it: line by line,
//! with jumps back to a line start seen before (`ProgramText`), and a
//! program held in memory (`TextProgram`). The SINUMERIK and HEIDENHAIN
//! interpreters read their programs through it; the runner hands them
//! its sources as such.

/// The lines of one program, read in order, with jumps back to a line
/// start seen before.
pub trait ProgramText: Send {
    /// Reads the next line, without its line end, into `buf` (cleared
    /// first). `Ok(false)` at the end.
    ///
    /// # Errors
    ///
    /// The program cannot be read.
    fn read_line(&mut self, buf: &mut Vec<u8>) -> std::io::Result<bool>;
    /// Byte offset of the next line.
    fn position(&self) -> u64;
    /// Goes on reading at `offset`, a line start seen before (or 0).
    ///
    /// # Errors
    ///
    /// The program cannot be read.
    fn seek(&mut self, offset: u64) -> std::io::Result<()>;
}

/// A program held in memory, read line by line: for tests and for
/// callers that have the text already.
///
/// ```
/// use fiveaxis_gcode::{ProgramText, TextProgram};
///
/// let mut p = TextProgram::new("G1 X10\r\nM30\n");
/// let mut line = Vec::new();
/// assert!(p.read_line(&mut line)?);
/// assert_eq!(line, b"G1 X10");
/// assert_eq!(p.position(), 8);
/// # Ok::<(), std::io::Error>(())
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct TextProgram {
    data: Vec<u8>,
    pos: usize,
}

impl TextProgram {
    /// A program of `text`.
    pub fn new(text: impl Into<Vec<u8>>) -> Self {
        Self {
            data: text.into(),
            pos: 0,
        }
    }
}

impl ProgramText for TextProgram {
    fn read_line(&mut self, buf: &mut Vec<u8>) -> std::io::Result<bool> {
        buf.clear();
        let Some(rest) = self.data.get(self.pos..) else {
            return Ok(false);
        };
        if rest.is_empty() {
            return Ok(false);
        }
        let (line, used) = match rest.iter().position(|&b| b == b'\n') {
            Some(n) => (&rest[..n], n + 1),
            None => (rest, rest.len()),
        };
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        buf.extend_from_slice(line);
        self.pos += used;
        Ok(true)
    }

    fn position(&self) -> u64 {
        self.pos as u64
    }

    fn seek(&mut self, offset: u64) -> std::io::Result<()> {
        match usize::try_from(offset) {
            Ok(p) if p <= self.data.len() => {
                self.pos = p;
                Ok(())
            }
            _ => Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("offset {offset} is past the end of the program"),
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_and_positions() {
        let mut p = TextProgram::new("A\r\nB\nC");
        let mut buf = Vec::new();
        let mut lines = Vec::new();
        while p.read_line(&mut buf).expect("read") {
            lines.push((String::from_utf8_lossy(&buf).into_owned(), p.position()));
        }
        assert_eq!(
            lines,
            [
                ("A".to_string(), 3),
                ("B".to_string(), 5),
                ("C".to_string(), 6)
            ]
        );
        p.seek(3).expect("seek");
        assert!(p.read_line(&mut buf).expect("read"));
        assert_eq!(buf, b"B");
        assert!(p.seek(99).is_err());
    }
}
