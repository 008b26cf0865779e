//! `--programs DIR`: a folder as the control's program memory. A program
//! called by number (`M98 P1234`, `G65 P9010`) is the file named after it
//! (`O1234`, `O1234.nc`, any extension, any case, with or without leading
//! zeros), or else the file whose first `O` line has that number.

use std::fs::File;
use std::io::{self, BufRead, BufReader};
use std::path::{Path, PathBuf};

use fiveaxis_control::{MAX_LINE_BYTES, ProgramLibrary, ReaderSource, Source};

/// Lines read from the top of a file to find its first `O` line.
const HEAD_LINES: usize = 64;

/// A folder of program files.
#[derive(Debug)]
pub struct DirLibrary {
    dir: PathBuf,
    /// Every file by its program number (from its name, else its first
    /// `O` line), found when first needed.
    index: Option<Vec<(u32, PathBuf)>>,
}

impl DirLibrary {
    /// The programs of `dir`, which must be a readable folder.
    pub fn new(dir: &Path) -> io::Result<Self> {
        std::fs::read_dir(dir)?;
        Ok(Self {
            dir: dir.to_path_buf(),
            index: None,
        })
    }

    fn build_index(&self) -> io::Result<Vec<(u32, PathBuf)>> {
        let mut by_name = Vec::new();
        let mut by_content = Vec::new();
        for entry in std::fs::read_dir(&self.dir)? {
            let path = entry?.path();
            if !path.is_file() {
                continue;
            }
            let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
            if let Some(n) = number_of_name(stem) {
                by_name.push((n, path));
            } else if let Some(n) = first_program_number(&path) {
                by_content.push((n, path));
            }
        }
        // Names first: a file named after a number is that program.
        by_name.sort();
        by_content.sort();
        by_name.extend(by_content);
        Ok(by_name)
    }
}

impl ProgramLibrary for DirLibrary {
    fn open(&mut self, number: u32) -> io::Result<Option<(Box<dyn Source>, String)>> {
        if self.index.is_none() {
            self.index = Some(self.build_index()?);
        }
        let found = self
            .index
            .as_ref()
            .and_then(|index| index.iter().find(|(n, _)| *n == number))
            .map(|(_, path)| path.clone());
        let Some(path) = found else {
            return Ok(None);
        };
        let file = File::open(&path)?;
        Ok(Some((
            Box::new(ReaderSource::new(file)),
            path.display().to_string(),
        )))
    }

    fn open_sinumerik(&mut self, name: &str) -> io::Result<Option<(Box<dyn Source>, String)>> {
        match sinumerik_program(&self.dir, name)? {
            Some(path) => {
                let file = File::open(&path)?;
                Ok(Some((
                    Box::new(ReaderSource::new(file)),
                    path.display().to_string(),
                )))
            }
            None => Ok(None),
        }
    }

    fn open_heidenhain(&mut self, name: &str) -> io::Result<Option<(Box<dyn Source>, String)>> {
        // `CALL PGM TNC:\PARTS\SUB1.H`: the file name is the last part of
        // the path; with or without `.h`, any case.
        let base = name.rsplit(['\\', '/', ':']).next().unwrap_or(name);
        let stem = base
            .strip_suffix(".h")
            .or_else(|| base.strip_suffix(".H"))
            .unwrap_or(base);
        if stem.is_empty() {
            return Ok(None);
        }
        for entry in std::fs::read_dir(&self.dir)? {
            let path = entry?.path();
            let file_name = path.file_name().and_then(|s| s.to_str()).unwrap_or("");
            let matches = file_name.eq_ignore_ascii_case(stem)
                || (file_name.len() == stem.len() + 2
                    && file_name[..stem.len()].eq_ignore_ascii_case(stem)
                    && file_name[stem.len()..].eq_ignore_ascii_case(".h"));
            if matches && path.is_file() {
                let file = File::open(&path)?;
                return Ok(Some((
                    Box::new(ReaderSource::new(file)),
                    path.display().to_string(),
                )));
            }
        }
        Ok(None)
    }

    fn sinumerik_definitions(&mut self) -> io::Result<Vec<(Box<dyn Source>, String)>> {
        let mut paths = Vec::new();
        for entry in std::fs::read_dir(&self.dir)? {
            let path = entry?.path();
            let name = path.file_name().and_then(|s| s.to_str()).unwrap_or("");
            let upper = name.to_ascii_uppercase();
            if path.is_file() && (upper.ends_with(".DEF") || upper.ends_with("_DEF")) {
                paths.push(path);
            }
        }
        // In name order, so that a run does not depend on the folder's.
        paths.sort();
        let mut files = Vec::with_capacity(paths.len());
        for path in paths {
            let file = File::open(&path)?;
            files.push((
                Box::new(ReaderSource::new(file)) as Box<dyn Source>,
                path.display().to_string(),
            ));
        }
        Ok(files)
    }
}

/// `O1234` / `o01234` as a file name: the number.
fn number_of_name(stem: &str) -> Option<u32> {
    let digits = stem.strip_prefix(['O', 'o'])?;
    (!digits.is_empty() && digits.len() <= 8 && digits.bytes().all(|b| b.is_ascii_digit()))
        .then(|| digits.parse().ok())
        .flatten()
}

/// The number of the first `O` line among the first lines of a file.
fn first_program_number(path: &Path) -> Option<u32> {
    let file = File::open(path).ok()?;
    let mut reader = BufReader::new(file);
    let mut line = Vec::new();
    for _ in 0..HEAD_LINES {
        line.clear();
        let n = reader
            .by_ref()
            .take(MAX_LINE_BYTES as u64)
            .read_until(b'\n', &mut line)
            .ok()?;
        if n == 0 {
            return None;
        }
        let text = line.trim_ascii();
        if let Some(rest) = text.strip_prefix(b"O").or_else(|| text.strip_prefix(b"o")) {
            let digits: Vec<u8> = rest
                .iter()
                .copied()
                .take_while(u8::is_ascii_digit)
                .collect();
            if digits.is_empty() || digits.len() > 8 {
                return None;
            }
            return std::str::from_utf8(&digits).ok()?.parse().ok();
        }
    }
    None
}

use std::io::Read as _;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_give_numbers() {
        assert_eq!(number_of_name("O1234"), Some(1234));
        assert_eq!(number_of_name("o0012"), Some(12));
        assert_eq!(number_of_name("O123456789"), None);
        assert_eq!(number_of_name("part"), None);
        assert_eq!(number_of_name("O"), None);
    }
}

/// The control's program memory as the runner sees it: the folder of
/// `--programs DIR` (programs by number) and LinuxCNC's subroutine folders
/// (`o<name> call` reads `name.ngc`: the machine file's `subroutine_path`
/// folders, relative to the machine file, then the program's own folder;
/// LinuxCNC `o-code.adoc`, "Calling Files", and `ini-config.adoc`,
/// `SUBROUTINE_PATH`).
#[derive(Debug, Default)]
pub struct Memory {
    programs: Option<DirLibrary>,
    ngc: Vec<PathBuf>,
}

impl Memory {
    /// The memory of `--programs` (if given) and the subroutine folders.
    pub fn new(programs: Option<DirLibrary>, ngc: Vec<PathBuf>) -> Self {
        Self { programs, ngc }
    }

    /// Whether there is anything to look in.
    pub fn is_empty(&self) -> bool {
        self.programs.is_none() && self.ngc.is_empty()
    }
}

impl ProgramLibrary for Memory {
    fn open(&mut self, number: u32) -> io::Result<Option<(Box<dyn Source>, String)>> {
        match self.programs.as_mut() {
            Some(dir) => dir.open(number),
            None => Ok(None),
        }
    }

    fn open_named(&mut self, name: &str) -> io::Result<Option<(Box<dyn Source>, String)>> {
        // Only a file in the folders (the runner refuses such names
        // first): no folders, no parent, no root.
        let mut parts = Path::new(name).components();
        if !matches!(
            (parts.next(), parts.next()),
            (Some(std::path::Component::Normal(_)), None)
        ) {
            return Ok(None);
        }
        let file_name = format!("{name}.ngc");
        let programs = self.programs.as_ref().map(|d| d.dir.clone());
        for dir in self.ngc.iter().chain(programs.iter()) {
            let path = dir.join(&file_name);
            if path.is_file() {
                let file = File::open(&path)?;
                return Ok(Some((
                    Box::new(ReaderSource::new(file)),
                    path.display().to_string(),
                )));
            }
        }
        Ok(None)
    }

    fn open_sinumerik(&mut self, name: &str) -> io::Result<Option<(Box<dyn Source>, String)>> {
        match self.programs.as_mut() {
            Some(dir) => dir.open_sinumerik(name),
            None => Ok(None),
        }
    }

    fn open_heidenhain(&mut self, name: &str) -> io::Result<Option<(Box<dyn Source>, String)>> {
        match self.programs.as_mut() {
            Some(dir) => dir.open_heidenhain(name),
            None => Ok(None),
        }
    }

    fn sinumerik_definitions(&mut self) -> io::Result<Vec<(Box<dyn Source>, String)>> {
        match self.programs.as_mut() {
            Some(dir) => dir.sinumerik_definitions(),
            None => Ok(Vec::new()),
        }
    }
}

/// The file of SINUMERIK program `name` in `dir`: `NAME.SPF`, `NAME.MPF`,
/// `_N_NAME_SPF`, `_N_NAME_MPF` (the control's internal names, ONE
/// p43–45), or `NAME` alone, in any case.
fn sinumerik_program(dir: &Path, name: &str) -> io::Result<Option<PathBuf>> {
    let name = name.to_ascii_uppercase();
    if name.is_empty() || name.contains(['/', '\\']) || name.starts_with('.') {
        return Ok(None);
    }
    let wanted = [
        format!("{name}.SPF"),
        format!("{name}.MPF"),
        format!("_N_{name}_SPF"),
        format!("_N_{name}_MPF"),
        name.clone(),
    ];
    let mut best: Option<(usize, PathBuf)> = None;
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        let file = path.file_name().and_then(|s| s.to_str()).unwrap_or("");
        let upper = file.to_ascii_uppercase();
        if let Some(rank) = wanted.iter().position(|w| *w == upper)
            && path.is_file()
            && best.as_ref().is_none_or(|(r, _)| rank < *r)
        {
            best = Some((rank, path));
        }
    }
    Ok(best.map(|(_, path)| path))
}

/// LinuxCNC's subroutine folders for a run: the machine file's
/// `subroutine_path` entries (relative to the machine file's folder; a
/// built-in machine has none), then the program's folder (not for
/// standard input).
pub fn ngc_folders(machine_spec: &str, subroutine_path: &[String], program: &str) -> Vec<PathBuf> {
    let mut folders = Vec::new();
    let machine_file = Path::new(machine_spec);
    if machine_file.is_file() {
        let base = machine_file.parent().unwrap_or(Path::new("."));
        folders.extend(subroutine_path.iter().map(|f| base.join(f)));
    }
    if program != "-" {
        let parent = Path::new(program).parent().unwrap_or(Path::new("."));
        folders.push(if parent.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            parent.to_path_buf()
        });
    }
    folders
}
