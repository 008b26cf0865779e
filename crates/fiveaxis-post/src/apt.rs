//! APT / CL data in, a TCPC program out (`G43.5` with the tool vector,
//! FANUC style), for a machine with the option; `fiveaxis post` then makes
//! it a machine-axis program for a machine without.
//!
//! The CL print of the CAM systems (Creo / Pro/E, CATIA, NX CLSF,
//! SOLIDWORKS CAM, Mastercam's APT output; the words of ANSI X3.37 /
//! ISO 4343 APT as docs/post.md lists them with their sources): a record
//! is `WORD/args` (`WORD / args`, `WORD` alone, and for the text words
//! `WORD text` without the slash); a `$` at the end of a line continues
//! the record on the next; `$$` starts a comment to the end of the line
//! (a line that starts with `$$` is a comment; ending in `$` it goes on
//! on the next line, as Creo's `$$->` lines do); a card's identification
//! field past column 72 (CATIA's `PT n`) is dropped.
//!
//! * `GOTO/x,y,z[,i,j,k]`: the tool end point and, if given, the tool axis
//!   vector (kept until the next one); a cutting move, or positioning after
//!   `RAPID`. Lines of numbers alone after it are more points of it (Creo
//!   writes an arc's points so: each an arc about the CIRCLE's centre). `FROM/...`: the start point, positioning. `GODLTA/dx,dy,dz`
//!   (or `GODLTA/d` along the tool axis): a move by that much.
//! * `RAPID`: the next `GOTO` is positioning.
//! * `FEDRAT/f[,unit]` or `FEDRAT/unit,f`: unit `MMPM`, `IPM`, `FPM`,
//!   `PERMIN` (the file's units) per minute, `MMPR`, `IPR`, `FPR`,
//!   `PERREV` per revolution: times the spindle speed in force at each
//!   move (`SPINDL/rpm`), written as a feed per minute.
//! * `UNITS/MM|INCHES` (`UNIT`): inch data is scaled to mm as it is read
//!   (points, circle centres, MSYS origins, cycle depths, feeds); the
//!   program is always written in mm.
//! * `MULTAX/ON|OFF`: with `OFF` (3-axis data) a `GOTO/x,y,z` has the tool
//!   along `TLAXIS` (+Z unless given) of the MSYS frame; with `ON`, and
//!   before any `MULTAX`, it keeps the last vector (initially +Z).
//!   `TLAXIS/i,j,k`: that tool axis from the next move on.
//! * `MSYS/x,y,z,xi,xj,xk,yi,yj,yk` (NX CLSF): the following points,
//!   vectors and circles are in the frame with that origin and those X
//!   and Y axes (Z = X × Y), turned into the absolute frame.
//! * `CIRCLE/xc,yc,zc,i,j,k[,r,...]`: the next `GOTO` ends an arc about
//!   that centre (and each further point of that GOTO another),
//!   counter-clockwise about the axis vector (right-hand rule, as the
//!   record's axis is the arc's normal); written `G2`/`G3` with `R` in the
//!   plane the axis is normal to (G17 / G18 / G19), the tool standing.
//! * `CYCLE/DRILL,...` (Creo's couplets `DEPTH, d, MMPM, f, CLEAR, c
//!   [, RAPTO, r]`, or APT's `DRILL, d, MMPM, f, c`): each following
//!   `GOTO` is a hole's top: rapid to `c` above it along the tool axis
//!   (`c − r` with RAPTO), feed to `d` below it, rapid back, as `G0`/`G1`
//!   moves; `CYCLE/OFF` ends it. Other cycles are refused with their line.
//! * `LOAD/TOOL,n` (`LOADTL/n`): `Tn M6`, then TCPC with `Hn`.
//! * `SPINDL/s,RPM,CLW|CCLW` (NX: `SPINDL/RPM,s,CLW`): `S s M3|M4`;
//!   `SPINDL/OFF`: `M5`; `COOLNT/ON|FLOOD`: `M8`, `COOLNT/MIST`: `M7`,
//!   `COOLNT/OFF`: `M9` (other coolants: a note); `STOP`: `M0`,
//!   `OPSTOP`: `M1`. The machine-axis
//!   output carries these words.
//! * `FINI`: the end (a record after it is an error). `END` (APT: a stop
//!   of the machine between sections) writes nothing, reading goes on.
//! * Kept as comments (no motion): `PARTNO`, `PPRINT`, `REMARK`,
//!   `TPRINT`, `INSERT`, `CUTTER`, `SELECT`, `MACHIN`, `TOOLNO`,
//!   `TRNTYP/WORLD` and `CSYS` (the points are in the world frame),
//!   `CUTCOM` (as a comment, never G41/G42: the CL points are the tool
//!   tip path the CAM has already offset; compensating again at the
//!   control would offset it twice), `TLDATA` (the tool's shape; its
//!   length is the cutter's, not the gauge length a TCPC program needs,
//!   which is the offsets file's), NX's `TOOL PATH`, `END-OF-PATH`,
//!   `PAINT` (display) and `$$` lines, and vendor records `CSI_...`.
//! * Read and not carried out, with a note ([`ClWarning::note`]):
//!   `PPWORD`, `OPSKIP`, `CLEARP`, `CLRSRF`, `DELAY`, `INTOL`, `OUTTOL`,
//!   `TOLER`, `LINTOL`, `CHANNEL`, `SWITCH`, `END`.
//!
//! A word that moves the tool or changes the frame and is not carried out
//! (`ORIGIN`, `TRANS`, `ROTABL`, `RETRCT`, `GOHOME`, `COPY`, `INDEX`,
//! `NURBS`, APT's `TLON,GOFWD/...` motion statements, ...) is an error
//! with its line and word: a record that might move the tool is never
//! dropped silently. Any other word is a warning naming it and its first
//! line ([`Converted::warnings`]), and is skipped.
//!
//! Every number must be finite and at most `MAX_FILE_MAGNITUDE` (10^6, the
//! bound of a machine file's numbers) in size, a point also after MSYS.

use std::fmt::Write;

use fiveaxis_control::RunError;
use fiveaxis_machine::{MAX_FILE_MAGNITUDE, Vec3};

/// An APT record that cannot be converted.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("line {line}: {message}")]
pub struct AptError {
    /// 1-based line where the record starts.
    pub line: u32,
    /// The record's major word (`GOTO`, `CYCLE`, ...); empty where the
    /// error is the file's, not a record's.
    pub word: String,
    /// What is wrong, beginning with the word where the record has one
    /// (`GOTO: expected 3 to 6 numbers, found ...`).
    pub message: String,
}

/// `WORD: message`, the message alone where it names the word already
/// or there is none.
fn with_word(word: &str, message: &str) -> String {
    if word.is_empty() || message.starts_with(word) || message.contains(&format!("`{word}")) {
        message.to_owned()
    } else {
        format!("{word}: {message}")
    }
}

/// A record read and skipped: a word not known (a warning), or one known
/// and deliberately not carried out (a note). One per word, at its first
/// line, with how many records had it.
#[derive(Clone, Debug, PartialEq)]
pub struct ClWarning {
    /// 1-based line of the first record with the word.
    pub line: u32,
    /// The major word.
    pub word: String,
    /// What was done.
    pub message: String,
    /// How many records had the word.
    pub count: u32,
    /// A known word not carried out (`note:`), not an unknown one
    /// (`warning:`).
    pub note: bool,
}

impl std::fmt::Display for ClWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}: {}: {}", self.line, self.word, self.message)?;
        if self.count > 1 {
            write!(f, " ({} records, the first here)", self.count)?;
        }
        Ok(())
    }
}

/// At most this many distinct words are listed as warnings; the rest are
/// counted in one last entry.
const MAX_WARNINGS: usize = 64;

/// A tool vector shorter than this is refused.
const MIN_VECTOR: f64 = 1e-6;
/// Distance below which an arc's end is its start (a full circle), mm.
const SAME_POINT: f64 = 1e-6;
/// Largest difference of the start and end radius of an arc, mm.
const RADIUS_MISMATCH: f64 = 1e-3;
/// Largest angle between an arc's axis and a coordinate axis, as a
/// component difference of unit vectors.
const AXIS_ALIGNMENT: f64 = 1e-6;
/// mm per inch.
const INCH: f64 = 25.4;
/// The last column of an APT card's statement field: past it, the
/// identification field.
const STATEMENT_COLUMNS: usize = 72;

/// Words whose arguments are text (a comment), written with or without
/// the slash.
const TEXT_WORDS: &[&str] = &["PARTNO", "PPRINT", "REMARK", "TPRINT", "INSERT"];
/// Words kept as comments.
const COMMENT_WORDS: &[&str] = &[
    "CUTTER",
    "SELECT",
    "TRNTYP",
    "CSYS",
    "CUTCOM",
    "TLDATA",
    "TOOL PATH",
    "END-OF-PATH",
    "PAINT",
    "MACHIN",
    "TOOLNO",
];
/// Words read and not carried out (no motion, no frame), with why.
const NOTED_WORDS: &[(&str, &str)] = &[
    ("PPWORD", "a post-processor word definition: not used"),
    (
        "OPSKIP",
        "optional block skip: not written (every block is run)",
    ),
    (
        "CLEARP",
        "a clearance plane for the post's retracts: not used (no RETRCT is carried out)",
    ),
    (
        "CLRSRF",
        "a clearance surface for the post's retracts: not used (no RETRCT is carried out)",
    ),
    ("DELAY", "a dwell: not written (the path is the same)"),
    ("INTOL", "the CAM's tolerance: not used"),
    ("OUTTOL", "the CAM's tolerance: not used"),
    ("TOLER", "the CAM's tolerance: not used"),
    ("LINTOL", "the CAM's tolerance: not used"),
    ("CHANNEL", "a channel of a multi-channel control: not used"),
    ("SWITCH", "a turret or spindle switch: not used"),
    (
        "END",
        "a stop between sections (APT END): nothing written, reading goes on",
    ),
];
/// Words that move the tool or change the frame of what follows and are
/// not carried out: an error, never skipped.
const PATH_WORDS: &[&str] = &[
    "ORIGIN", "TRANS", "REFSYS", "TRACUT", "ROTABL", "ROTATE", "ROTHED", "RETRCT", "GOHOME",
    "COPY", "INDEX", "NURBS", "SPLINE", "ARCMOV", "TLON", "TLLFT", "TLRGT", "TLONPS", "TLOFPS",
    "GOFWD", "GOLFT", "GORGT", "GOBACK", "GOUP", "GODOWN", "INDIRV", "INDIRP", "AUTOPS", "THREAD",
    "MOVE", "POSITN", "HEAD", "AXIS", "GOCLR", "PIVOTZ",
];

/// A feed as read: mm per minute, or mm per spindle revolution.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Feed {
    PerMinute(f64),
    PerRev(f64),
}

/// A drilling cycle in force (`CYCLE/DRILL`): lengths in mm along the
/// tool axis from the hole's top, the feed.
#[derive(Clone, Copy, Debug)]
struct Drill {
    depth: f64,
    clear: f64,
    rapto: f64,
    feed: Feed,
}

/// A `CIRCLE` in force: centre and axis (absolute frame), its line.
type Circle = (Vec3, Vec3, u32);

/// The state of the reader between records.
struct State {
    out: String,
    position: Option<Vec3>,
    vector: Vec3,
    rapid: bool,
    feed: Option<Feed>,
    feed_written: bool,
    /// Spindle speed in force, rpm (`SPINDL`), for feeds per revolution.
    spindle: Option<f64>,
    circle: Option<Circle>,
    /// After a GOTO: a line of numbers alone is another point of it,
    /// positioning or not as it was, on its arc if it ended one.
    more_points: Option<(bool, Option<Circle>)>,
    cycle: Option<Drill>,
    tool: Option<u32>,
    tcpc: bool,
    ended: bool,
    /// `MULTAX/OFF` in force: a GOTO without a vector has the tool along
    /// `axis3` (+Z unless `TLAXIS` gave another) of the MSYS frame.
    three_axis: bool,
    /// The tool axis of 3-axis data, in the MSYS frame.
    axis3: Vec3,
    /// mm per unit of the file (`UNITS`): 1, or 25.4 for inches.
    scale: f64,
    /// `MSYS` in force: origin and rotation (columns: the frame's X, Y,
    /// Z in the absolute frame).
    msys: Option<(Vec3, nalgebra::Matrix3<f64>)>,
    warnings: Vec<ClWarning>,
}

/// Converts APT CL text into a TCPC program; `name` goes into the header.
pub fn to_tcpc(text: &str, name: &str) -> Result<String, AptError> {
    to_tcpc_mapped(text, name).map(|c| c.program)
}

/// A TCPC program converted from CL data, with where each of its lines
/// came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Converted {
    /// The TCPC program.
    pub program: String,
    /// For each line of `program` (index 0: line 1), the 1-based line of
    /// the CL file where the record it was written for starts; `None` for
    /// the header and the end the converter adds.
    pub source_lines: Vec<Option<u32>>,
    /// Records skipped: unknown words (warnings) and known words not
    /// carried out (notes), one per word, in the order first met.
    pub warnings: Vec<ClWarning>,
}

/// A file name of CL data: `.apt`, `.cl`, `.cls` (NX), `.ncl` (Creo, also
/// with its version number, `.ncl.3`), `.aptsource` (CATIA).
pub fn is_cl_file_name(name: &str) -> bool {
    let path = std::path::Path::new(name);
    let extension = |p: &std::path::Path| {
        p.extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
    };
    let ext = match extension(path) {
        // Creo's versions: `seq00005.ncl.1`.
        Some(e) if !e.is_empty() && e.bytes().all(|b| b.is_ascii_digit()) => path
            .file_stem()
            .map(std::path::Path::new)
            .and_then(extension),
        e => e,
    };
    ext.is_some_and(|e| ["apt", "cl", "cls", "ncl", "aptsource"].contains(&e.as_str()))
}

impl Converted {
    /// The CL line the program's 1-based `line` was written for.
    pub fn source_line(&self, line: u32) -> Option<u32> {
        let index = usize::try_from(line).ok()?.checked_sub(1)?;
        self.source_lines.get(index).copied().flatten()
    }

    /// An error raised running the converted program, told at the CL
    /// record the failing line was written for: its line and text (`text`
    /// is the CL data; the column of a word of the generated line means
    /// nothing there). A line the conversion adds (the header, the end) is
    /// named as a line of the program `name` converted to TCPC.
    pub fn on_cl_lines(&self, error: RunError, text: &str, name: &str) -> RunError {
        match error {
            RunError::Alarm {
                mut alarm,
                text: generated,
                program: None,
            } => match self.source_line(alarm.line) {
                Some(line) => {
                    alarm.line = line;
                    alarm.span = None;
                    let index = usize::try_from(line).map_or(usize::MAX, |l| l.saturating_sub(1));
                    let record = text.lines().nth(index).unwrap_or("");
                    RunError::Alarm {
                        alarm,
                        text: record.as_bytes().to_vec(),
                        program: None,
                    }
                }
                None => RunError::Alarm {
                    alarm,
                    text: generated,
                    program: Some(format!("{name} converted to TCPC")),
                },
            },
            RunError::LineTooLong { line } => RunError::LineTooLong {
                line: self.source_line(line).unwrap_or(line),
            },
            other => other,
        }
    }
}

/// Converts APT CL text into a TCPC program, keeping for each of its
/// lines the CL record's line (so that an alarm raised while running it
/// names the file's own line).
pub fn to_tcpc_mapped(text: &str, name: &str) -> Result<Converted, AptError> {
    let mut st = State {
        out: String::with_capacity(text.len()),
        position: None,
        vector: Vec3::z(),
        rapid: false,
        feed: None,
        feed_written: false,
        spindle: None,
        circle: None,
        more_points: None,
        cycle: None,
        tool: None,
        tcpc: false,
        ended: false,
        three_axis: false,
        axis3: Vec3::z(),
        scale: 1.0,
        msys: None,
        warnings: Vec::new(),
    };
    st.out.push_str("%\n");
    let _ = writeln!(
        st.out,
        "({})",
        comment_text(&format!("from APT/CL {name} by fiveaxis post"))
    );
    st.out.push_str("G21 G17 G90 G94 G40 G49 G80 G54\n");
    // Every record's output ends its lines: the header's are counted
    // here, each record's as it is written.
    let mut source_lines = Vec::new();
    mark(&mut source_lines, &st.out);
    let mut record = String::new();
    let mut start = 0u32;
    for (index, raw) in text.lines().enumerate() {
        let line = u32::try_from(index + 1).unwrap_or(u32::MAX);
        if record.is_empty() {
            start = line;
        }
        let (part, continues) = physical_line(raw, record.starts_with("$$"));
        record.push_str(part);
        if continues {
            continue;
        }
        let r = std::mem::take(&mut record);
        if st.ended {
            if r.is_empty() || r.starts_with("$$") {
                continue;
            }
            return Err(AptError {
                line: start,
                word: major_word(&r).0,
                message: format!("`{}` after the end of the tool path (FINI)", clip(&r)),
            });
        }
        let before = st.out.len();
        st.record(&r, start).map_err(|mut e| {
            if e.word.is_empty() {
                e.word = major_word(&r).0;
            }
            e.message = with_word(&e.word, &e.message);
            e
        })?;
        let written = st.out[before..].matches('\n').count();
        source_lines.extend(std::iter::repeat_n(Some(start), written));
    }
    if !record.is_empty() {
        return Err(AptError {
            line: start,
            word: major_word(&record).0,
            message: "the last record ends in `$` (continued on no line)".into(),
        });
    }
    if let Some((_, _, line)) = st.circle {
        return Err(AptError {
            line,
            word: "CIRCLE".into(),
            message: "CIRCLE with no GOTO after it".into(),
        });
    }
    if st.tcpc {
        st.out.push_str("G49\n");
    }
    st.out.push_str("M30\n%\n");
    mark(&mut source_lines, &st.out);
    Ok(Converted {
        program: st.out,
        source_lines,
        warnings: st.warnings,
    })
}

/// One line of the file: its part of a record, and whether a `$` at its
/// end continues the record on the next line. `comment`: the record so
/// far is a `$$` comment. The identification field past column 72 (the
/// letters and number CATIA writes there, `PT 5`) is dropped; a `$$`
/// after a record's text starts a comment to the end of the line.
fn physical_line(raw: &str, comment: bool) -> (&str, bool) {
    let t = strip_identification(raw).trim();
    if comment || t.starts_with("$$") {
        // A comment line: to its end; a `$` after its text continues it
        // (Creo's `$$->` lines with several lines of numbers).
        return match t.strip_suffix('$') {
            Some(body) if t.len() > 2 => (body.trim_end(), true),
            _ => (t, false),
        };
    }
    let t = t.find("$$").map_or(t, |i| t[..i].trim_end());
    match t.strip_suffix('$') {
        Some(body) => (body.trim(), true),
        None => (t, false),
    }
}

/// `raw` without an APT card's identification field: past column 72,
/// letters then digits (`PT    5`, `CIR 1`), nothing else.
fn strip_identification(raw: &str) -> &str {
    if raw.len() <= STATEMENT_COLUMNS || !raw.is_char_boundary(STATEMENT_COLUMNS) {
        return raw;
    }
    let (statement, tail) = raw.split_at(STATEMENT_COLUMNS);
    let tail = tail.trim();
    let letters = tail.bytes().take_while(u8::is_ascii_alphabetic).count();
    let rest = tail[letters..].trim_start();
    if letters > 0 && !rest.is_empty() && rest.bytes().all(|b| b.is_ascii_digit()) {
        statement
    } else {
        raw
    }
}

/// The record's major word, upper case (NX's `TOOL PATH` is two words),
/// and the text after it.
fn major_word(r: &str) -> (String, &str) {
    let r = r.trim_start();
    let end = r
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '-'))
        .unwrap_or(r.len());
    let word = r[..end].to_ascii_uppercase();
    let rest = r[end..].trim_start();
    if word == "TOOL"
        && let Some(path) = rest.get(..4)
        && path.eq_ignore_ascii_case("PATH")
    {
        return ("TOOL PATH".into(), rest[4..].trim_start());
    }
    (word, rest)
}

/// At most 60 characters of `text`, for a message.
fn clip(text: &str) -> String {
    let mut s: String = text.chars().take(60).collect();
    if s.len() < text.len() {
        s.push_str("...");
    }
    s
}

/// Extends `lines` with `None` up to the number of lines `out` has ended.
fn mark(lines: &mut Vec<Option<u32>>, out: &str) {
    let ended = out.matches('\n').count();
    if lines.len() < ended {
        lines.resize(ended, None);
    }
}

/// The arguments of a record, as numbers where they are numbers: each
/// finite and within [`MAX_FILE_MAGNITUDE`].
fn numbers(
    args: &str,
    line: u32,
    count: std::ops::RangeInclusive<usize>,
) -> Result<Vec<f64>, AptError> {
    let values: Result<Vec<f64>, _> = args.split(',').map(|a| a.trim().parse::<f64>()).collect();
    match values {
        Ok(v) if count.contains(&v.len()) => {
            for (x, text) in v.iter().zip(args.split(',')) {
                bounded(*x, text.trim(), line)?;
            }
            Ok(v)
        }
        _ => Err(AptError {
            line,
            word: String::new(),
            message: format!(
                "expected {} to {} numbers, found `{}`",
                count.start(),
                count.end(),
                clip(args)
            ),
        }),
    }
}

/// `x` (written `text` in the record) if it is finite and within
/// [`MAX_FILE_MAGNITUDE`], the bound of every number of a machine: a
/// larger coordinate, feed or speed is no machine's, and would be written
/// as a word of hundreds of digits.
fn bounded(x: f64, text: &str, line: u32) -> Result<f64, AptError> {
    if !x.is_finite() {
        return Err(AptError {
            line,
            word: String::new(),
            message: format!("`{text}` is not a finite number"),
        });
    }
    if x.abs() > MAX_FILE_MAGNITUDE {
        return Err(AptError {
            line,
            word: String::new(),
            message: format!(
                "`{text}` is beyond what a machine can have: at most {MAX_FILE_MAGNITUDE:e} in size"
            ),
        });
    }
    Ok(x)
}

/// A feed unit: mm per unit of length, per revolution (not per minute).
/// `scale` is the file's length unit (`PERMIN`, `PERREV`).
fn feed_unit(word: &str, scale: f64) -> Option<(f64, bool)> {
    Some(match word {
        "MMPM" => (1.0, false),
        "IPM" => (INCH, false),
        "FPM" => (12.0 * INCH, false),
        "PERMIN" => (scale, false),
        "MMPR" => (1.0, true),
        "IPR" => (INCH, true),
        "FPR" => (12.0 * INCH, true),
        "PERREV" => (scale, true),
        _ => return None,
    })
}

/// A feed of `value` in `unit` (from [`feed_unit`]).
fn make_feed(value: f64, (mm, per_rev): (f64, bool)) -> Feed {
    let f = round_feed(value * mm);
    if per_rev {
        Feed::PerRev(f)
    } else {
        Feed::PerMinute(f)
    }
}

/// A feed rounded to 10⁻⁶ (scaled values written without a tail of
/// binary noise; a feed read in mm per minute is unchanged).
fn round_feed(f: f64) -> f64 {
    (f * 1e6).round() / 1e6
}

/// Text fit for a FANUC comment.
fn comment_text(text: &str) -> String {
    text.chars()
        .map(|c| match c {
            '(' | ')' | ';' | '%' => ' ',
            c if c.is_ascii() && !c.is_ascii_control() => c.to_ascii_uppercase(),
            _ => '?',
        })
        .collect()
}

impl State {
    fn record(&mut self, r: &str, line: u32) -> Result<(), AptError> {
        let r = r.trim();
        if r.is_empty() {
            return Ok(());
        }
        if let Some(text) = r.strip_prefix("$$") {
            let _ = writeln!(self.out, "({})", comment_text(text.trim()));
            return Ok(());
        }
        let (word, rest) = major_word(r);
        let err = |message: String| AptError {
            line,
            word: word.clone(),
            message,
        };
        let more = self.more_points.take();
        if word.is_empty() || word.starts_with(|c: char| c.is_ascii_digit() || c == '-') {
            if let Some((rapid, arc)) = more {
                // Another point of the GOTO before, on a line of its own
                // (Creo writes an arc's points so, the last its end).
                self.rapid = rapid;
                self.circle = arc;
                return self.goto(&numbers(r, line, 3..=6)?, line);
            }
            return Err(err(format!(
                "`{}` is not a record: a major word (GOTO, FEDRAT, ...) comes first",
                clip(r)
            )));
        }
        if TEXT_WORDS.contains(&word.as_str())
            || COMMENT_WORDS.contains(&word.as_str())
            || word.starts_with("CSI_")
        {
            if word == "TRNTYP"
                && !rest
                    .trim_start_matches('/')
                    .trim()
                    .to_ascii_uppercase()
                    .starts_with("WORLD")
            {
                return Err(err(format!(
                    "`{}`: only TRNTYP/WORLD (points in the world frame) is read",
                    clip(r)
                )));
            }
            let _ = writeln!(self.out, "({})", comment_text(r));
            return Ok(());
        }
        // `WORD/args`; `WORD args` and `WORD,args` read the same.
        let args = rest
            .strip_prefix('/')
            .unwrap_or(rest)
            .trim_start_matches(',')
            .trim();
        let upper = args.to_ascii_uppercase();
        match word.as_str() {
            "GOTO" => self.goto(&numbers(args, line, 3..=6)?, line),
            "FROM" => {
                // The start point: positioning.
                self.rapid = true;
                self.goto(&numbers(args, line, 3..=6)?, line)
            }
            "GODLTA" => self.godlta(&numbers(args, line, 1..=6)?, line),
            "RAPID" => {
                self.rapid = true;
                Ok(())
            }
            "FEDRAT" => {
                // `FEDRAT/f[,unit]` or `FEDRAT/unit,f`.
                let mut value = None;
                let mut unit = None;
                let mut ok = true;
                for part in upper.split(',').map(str::trim) {
                    if let Some(u) = feed_unit(part, self.scale) {
                        ok &= unit.replace(u).is_none();
                    } else if let (Ok(f), None) = (part.parse::<f64>(), value) {
                        value = Some(bounded(f, part, line)?);
                    } else {
                        ok = false;
                    }
                }
                match value {
                    Some(f) if ok && f > 0.0 => {
                        let feed = make_feed(f, unit.unwrap_or((self.scale, false)));
                        let (Feed::PerMinute(mm) | Feed::PerRev(mm)) = feed;
                        bounded(mm, &format!("{mm} mm"), line)?;
                        self.feed = Some(feed);
                        self.feed_written = false;
                        Ok(())
                    }
                    _ => Err(err(format!(
                        "FEDRAT/{}: only a positive feed with its unit is read (MMPM, IPM, FPM, PERMIN per minute; MMPR, IPR, FPR, PERREV per revolution)",
                        clip(args)
                    ))),
                }
            }
            "MULTAX" => match upper.as_str() {
                "ON" | "" => {
                    self.three_axis = false;
                    Ok(())
                }
                "OFF" => {
                    self.three_axis = true;
                    Ok(())
                }
                _ => Err(err(format!("MULTAX/{}: ON or OFF", clip(args)))),
            },
            "TLAXIS" => {
                let v = numbers(args, line, 3..=3)?;
                let d = Vec3::new(v[0], v[1], v[2]);
                if d.norm() < MIN_VECTOR {
                    return Err(err("TLAXIS with a zero vector".into()));
                }
                self.axis3 = d.normalize();
                self.vector = self.direction(&self.axis3);
                Ok(())
            }
            "MSYS" => {
                let v = numbers(args, line, 9..=9)?;
                let x = Vec3::new(v[3], v[4], v[5]);
                let y = Vec3::new(v[6], v[7], v[8]);
                if x.norm() < MIN_VECTOR
                    || y.norm() < MIN_VECTOR
                    || x.normalize().dot(&y.normalize()).abs() > 1e-4
                {
                    return Err(err(
                        "MSYS: the X and Y vectors must be non-zero and at right angles".into(),
                    ));
                }
                let (x, y) = (x.normalize(), y.normalize());
                let z = x.cross(&y);
                let _ = writeln!(self.out, "({})", comment_text(r));
                let origin = Vec3::new(v[0], v[1], v[2]) * self.scale;
                let identity = (x - Vec3::x()).norm() < 1e-12
                    && (y - Vec3::y()).norm() < 1e-12
                    && origin.norm() == 0.0;
                self.msys =
                    (!identity).then(|| (origin, nalgebra::Matrix3::from_columns(&[x, y, z])));
                Ok(())
            }
            "CIRCLE" => {
                let v = numbers(args, line, 4..=11)?;
                if v.len() < 6 {
                    // APT's `CIRCLE/x,y,z,r` is a surface for GOFWD, with
                    // no direction of travel.
                    return Err(err(
                        "CIRCLE/x,y,z,r names no direction of travel: x,y,z,i,j,k[,r,...] is read"
                            .into(),
                    ));
                }
                let axis = Vec3::new(v[3], v[4], v[5]);
                if axis.norm() < MIN_VECTOR {
                    return Err(err("CIRCLE with a zero axis vector".into()));
                }
                let axis = self.direction(&axis.normalize());
                let center = self.point(&(Vec3::new(v[0], v[1], v[2]) * self.scale));
                check_point(&center, line)?;
                self.circle = Some((center, axis, line));
                Ok(())
            }
            "CYCLE" => self.cycle(args, line),
            "LOAD" | "LOADTL" => {
                let n = args
                    .split(',')
                    .map(str::trim)
                    .find_map(|a| a.parse::<f64>().ok())
                    .filter(|n| n.fract() == 0.0 && *n >= 1.0 && *n <= 9999.0)
                    .ok_or_else(|| err(format!("{word}/{}: no tool number", clip(args))))?;
                if self.tcpc {
                    self.out.push_str("G49\n");
                    self.tcpc = false;
                }
                let n = n as u32;
                let _ = writeln!(self.out, "T{n} M6");
                self.tool = Some(n);
                Ok(())
            }
            "SPINDL" => {
                if upper.trim() == "OFF" {
                    self.out.push_str("M5\n");
                    self.spindle = None;
                    return Ok(());
                }
                // `SPINDL/s,RPM,CLW` or NX's `SPINDL/RPM,s,CLW`.
                let mut speed = None;
                let mut m = 3;
                for part in upper.split(',').map(str::trim) {
                    match part {
                        "RPM" | "CLW" | "ON" => {}
                        "CCLW" => m = 4,
                        p if speed.is_none() && p.parse::<f64>().is_ok() => {
                            speed = Some(bounded(p.parse::<f64>().unwrap_or(f64::NAN), p, line)?);
                        }
                        _ => {
                            return Err(err(format!(
                                "SPINDL/{}: only a speed in RPM, CLW, CCLW are read",
                                clip(args)
                            )));
                        }
                    }
                }
                let s = speed
                    .filter(|s| *s >= 0.0)
                    .ok_or_else(|| err(format!("SPINDL/{}: no speed", clip(args))))?;
                let _ = writeln!(self.out, "S{} M{m}", s.round());
                self.spindle = Some(s);
                if matches!(self.feed, Some(Feed::PerRev(_))) {
                    self.feed_written = false;
                }
                Ok(())
            }
            "COOLNT" => {
                let m = match upper.split(',').next().unwrap_or("").trim() {
                    "ON" | "FLOOD" => 8,
                    "MIST" => 7,
                    "OFF" => 9,
                    _ => {
                        // THRU, TAP, AIR, ...: the machine builder's M
                        // code, no path.
                        self.warn(
                            line,
                            "COOLNT",
                            "a coolant other than ON, FLOOD, MIST, OFF has no standard M code: not written",
                            true,
                        );
                        return Ok(());
                    }
                };
                let _ = writeln!(self.out, "M{m}");
                Ok(())
            }
            "UNIT" | "UNITS" => {
                self.scale = match upper.as_str() {
                    "MM" | "MILLIMETER" | "MILLIMETERS" | "METRIC" => 1.0,
                    "INCH" | "INCHES" | "IN" => INCH,
                    _ => {
                        return Err(err(format!("{word}/{}: MM or INCHES", clip(args))));
                    }
                };
                Ok(())
            }
            "STOP" => {
                self.out.push_str("M0\n");
                Ok(())
            }
            "OPSTOP" => {
                self.out.push_str("M1\n");
                Ok(())
            }
            "FINI" => {
                self.ended = true;
                Ok(())
            }
            w if PATH_WORDS.contains(&w) => Err(err(format!(
                "`{w}` moves the tool or changes the frame of what follows and is not carried out: not converted"
            ))),
            w => {
                match NOTED_WORDS.iter().find(|(n, _)| *n == w) {
                    Some((_, why)) => self.warn(line, w, why, true),
                    None => self.warn(
                        line,
                        w,
                        "not a word this reader knows (no motion assumed): skipped",
                        false,
                    ),
                }
                Ok(())
            }
        }
    }

    /// A record skipped, told once per word.
    fn warn(&mut self, line: u32, word: &str, message: &str, note: bool) {
        if let Some(w) = self.warnings.iter_mut().find(|w| w.word == word) {
            w.count = w.count.saturating_add(1);
        } else if self.warnings.len() < MAX_WARNINGS {
            self.warnings.push(ClWarning {
                line,
                word: word.to_owned(),
                message: message.to_owned(),
                count: 1,
                note,
            });
        } else if self.warnings.len() == MAX_WARNINGS {
            self.warnings.push(ClWarning {
                line,
                word: "...".into(),
                message: format!(
                    "records of more words, not listed (only {MAX_WARNINGS} are): skipped"
                ),
                count: 1,
                note: false,
            });
        } else if let Some(last) = self.warnings.last_mut() {
            last.count = last.count.saturating_add(1);
        }
    }

    /// `CYCLE/DRILL,...` or `CYCLE/OFF`.
    fn cycle(&mut self, args: &str, line: u32) -> Result<(), AptError> {
        let err = |message: String| AptError {
            line,
            word: "CYCLE".into(),
            message,
        };
        let parts: Vec<String> = args
            .split(',')
            .map(|p| p.trim().to_ascii_uppercase())
            .collect();
        match parts[0].as_str() {
            "OFF" => {
                self.cycle = None;
                return Ok(());
            }
            "DRILL" => {}
            kind => {
                return Err(err(format!(
                    "CYCLE/{kind}: only DRILL cycles (and CYCLE/OFF) are carried out: not converted"
                )));
            }
        }
        let number = |i: usize| -> Result<f64, AptError> {
            let text = parts.get(i).map_or("", String::as_str);
            let x = text.parse::<f64>().map_err(|_| {
                err(format!(
                    "CYCLE/{}: a number expected after `{}`",
                    clip(args),
                    parts.get(i - 1).map_or("", String::as_str)
                ))
            })?;
            bounded(x, text, line)
        };
        let (mut depth, mut clear, mut rapto, mut feed) = (None, None, 0.0, None);
        if parts.get(1).is_some_and(|p| p.parse::<f64>().is_err()) {
            // Creo's couplets: `DEPTH, d, MMPM, f, CLEAR, c, RAPTO, r`.
            let mut i = 1;
            while i < parts.len() {
                let value = number(i + 1)?;
                match parts[i].as_str() {
                    "DEPTH" => depth = Some(value * self.scale),
                    "CLEAR" => clear = Some(value * self.scale),
                    "RAPTO" => rapto = value * self.scale,
                    key => match feed_unit(key, self.scale) {
                        Some(unit) => feed = Some(make_feed(value, unit)),
                        None => {
                            return Err(err(format!(
                                "CYCLE/DRILL: `{key}` is not carried out (DEPTH, a feed unit, CLEAR, RAPTO are): not converted"
                            )));
                        }
                    },
                }
                i += 2;
            }
        } else if parts.len() == 5 {
            // APT's `DRILL, depth, unit, feed, clearance`.
            depth = Some(number(1)? * self.scale);
            let unit = feed_unit(&parts[2], self.scale).ok_or_else(|| {
                err(format!(
                    "CYCLE/{}: `{}` is not a feed unit",
                    clip(args),
                    parts[2]
                ))
            })?;
            feed = Some(make_feed(number(3)?, unit));
            clear = Some(number(4)? * self.scale);
        } else {
            return Err(err(format!(
                "CYCLE/{}: read are DRILL with DEPTH, a feed unit and feed, CLEAR (and RAPTO), or DRILL,depth,unit,feed,clearance",
                clip(args)
            )));
        }
        let (Some(depth), Some(clear), Some(feed)) = (depth, clear, feed) else {
            return Err(err(format!(
                "CYCLE/{}: a depth, a feed and a clearance are needed",
                clip(args)
            )));
        };
        let (Feed::PerMinute(rate) | Feed::PerRev(rate)) = feed;
        bounded(rate, &format!("{rate} mm"), line)?;
        if depth < 0.0 || clear < 0.0 || rate <= 0.0 || clear - rapto <= -depth {
            return Err(err(format!(
                "CYCLE/{}: the depth and clearance must not be negative, the feed positive, and the rapid must stop above the bottom",
                clip(args)
            )));
        }
        self.cycle = Some(Drill {
            depth,
            clear,
            rapto,
            feed,
        });
        Ok(())
    }

    /// A point of the MSYS frame in the absolute frame.
    fn point(&self, p: &Vec3) -> Vec3 {
        match &self.msys {
            Some((origin, r)) => origin + r * p,
            None => *p,
        }
    }

    /// A direction of the MSYS frame in the absolute frame.
    fn direction(&self, d: &Vec3) -> Vec3 {
        match &self.msys {
            Some((_, r)) => r * d,
            None => *d,
        }
    }

    /// The feed per minute of `feed` at a move of `line`.
    fn per_minute(&self, feed: Option<Feed>, line: u32) -> Result<f64, AptError> {
        let err = |message: &str| AptError {
            line,
            word: String::new(),
            message: message.into(),
        };
        match feed {
            None => Err(err("a cutting move before any FEDRAT")),
            Some(Feed::PerMinute(f)) => Ok(f),
            Some(Feed::PerRev(f)) => match self.spindle {
                Some(s) if s > 0.0 => {
                    let f = round_feed(f * s);
                    bounded(f, &f.to_string(), line)
                }
                _ => Err(err(
                    "a feed per revolution (FEDRAT .. IPR / MMPR) with no spindle speed in force (SPINDL/rpm)",
                )),
            },
        }
    }

    /// `GODLTA/d` (along the tool axis) or `GODLTA/dx,dy,dz[,i,j,k]`.
    fn godlta(&mut self, v: &[f64], line: u32) -> Result<(), AptError> {
        let err = |message: &str| AptError {
            line,
            word: String::new(),
            message: message.into(),
        };
        let from = self
            .position
            .ok_or_else(|| err("GODLTA before any position"))?;
        let (to, dir) = match v.len() {
            1 => (from + self.vector * (v[0] * self.scale), None),
            3 | 6 => (
                from + self.direction(&(Vec3::new(v[0], v[1], v[2]) * self.scale)),
                (v.len() == 6).then(|| Vec3::new(v[3], v[4], v[5])),
            ),
            _ => return Err(err("GODLTA takes 1, 3 or 6 numbers")),
        };
        let dir = match dir {
            Some(d) if d.norm() < MIN_VECTOR => return Err(err("GODLTA with a zero tool vector")),
            Some(d) => Some(self.direction(&d.normalize())),
            None => None,
        };
        self.move_to(to, dir, line)
    }

    fn goto(&mut self, v: &[f64], line: u32) -> Result<(), AptError> {
        let p = self.point(&(Vec3::new(v[0], v[1], v[2]) * self.scale));
        let dir = match v.len() {
            3 => None,
            6 => {
                let d = Vec3::new(v[3], v[4], v[5]);
                if d.norm() < MIN_VECTOR {
                    return Err(AptError {
                        line,
                        word: String::new(),
                        message: "GOTO with a zero tool vector".into(),
                    });
                }
                Some(self.direction(&d.normalize()))
            }
            _ => {
                return Err(AptError {
                    line,
                    word: String::new(),
                    message: "GOTO takes 3 or 6 numbers".into(),
                });
            }
        };
        self.move_to(p, dir, line)
    }

    /// A move to the absolute point `p`, with the absolute tool direction
    /// `dir` if the record gives one.
    fn move_to(&mut self, p: Vec3, dir: Option<Vec3>, line: u32) -> Result<(), AptError> {
        let err = |message: String| AptError {
            line,
            word: String::new(),
            message,
        };
        check_point(&p, line)?;
        match dir {
            None if self.three_axis => {
                // MULTAX/OFF: the tool along the 3-axis tool axis of the
                // frame.
                self.vector = self.direction(&self.axis3);
            }
            None => {}
            Some(d) => {
                if self.circle.is_some() && (d - self.vector).norm() > AXIS_ALIGNMENT {
                    return Err(err(
                        "the tool vector changes along an arc: not converted (TCPC arcs keep the tool standing)"
                            .into(),
                    ));
                }
                self.vector = d;
            }
        }
        if let Some(drill) = self.cycle {
            if self.circle.is_some() {
                return Err(err("CIRCLE in a drilling cycle: not converted".into()));
            }
            self.drill(&p, &drill, line)?;
            self.more_points = Some((false, None));
            return Ok(());
        }
        self.start_tcpc(&p);
        let rapid = self.rapid;
        let arc = self.circle;
        if self.rapid {
            self.out.push_str("G0");
            xyz(&mut self.out, &p);
            ijk(&mut self.out, &self.vector);
            self.rapid = false;
        } else if let Some((center, axis, circle_line)) = self.circle.take() {
            let from = self
                .position
                .ok_or_else(|| err("an arc before any position".into()))?;
            self.arc(&from, &p, &center, &axis, circle_line, line)?;
        } else {
            let f = self.per_minute(self.feed, line)?;
            self.out.push_str("G1");
            xyz(&mut self.out, &p);
            ijk(&mut self.out, &self.vector);
            if !self.feed_written {
                let _ = write!(self.out, " F{f}");
                self.feed_written = true;
            }
        }
        self.out.push('\n');
        self.position = Some(p);
        self.more_points = Some((rapid, arc));
        Ok(())
    }

    /// TCPC starts up with a rapid to the first point in the tool
    /// direction standing: `G43.5 H1` alone would first lift Z by the
    /// tool length, over the top of travel from the reference position,
    /// and I J K are refused in the start-up block on a table or mixed
    /// machine (PS5421). The move with the vector follows.
    fn start_tcpc(&mut self, p: &Vec3) {
        if !self.tcpc {
            let h = self.tool.unwrap_or(1);
            let _ = write!(self.out, "G43.5 H{h} G0");
            xyz(&mut self.out, p);
            self.out.push('\n');
            self.tcpc = true;
        }
    }

    /// A hole of the drilling cycle at `top` (its top, the GOTO point):
    /// rapid to the clearance above it along the tool axis (and on by
    /// RAPTO), feed to the depth below it, rapid back to the clearance.
    fn drill(&mut self, top: &Vec3, drill: &Drill, line: u32) -> Result<(), AptError> {
        let axis = self.vector;
        let clear = top + axis * drill.clear;
        let approach = top + axis * (drill.clear - drill.rapto);
        let bottom = top - axis * drill.depth;
        for p in [&clear, &approach, &bottom] {
            check_point(p, line)?;
        }
        let f = self.per_minute(Some(drill.feed), line)?;
        self.start_tcpc(&clear);
        self.out.push_str("G0");
        xyz(&mut self.out, &clear);
        ijk(&mut self.out, &axis);
        self.out.push('\n');
        if drill.rapto != 0.0 {
            self.out.push_str("G0");
            xyz(&mut self.out, &approach);
            ijk(&mut self.out, &axis);
            self.out.push('\n');
        }
        self.out.push_str("G1");
        xyz(&mut self.out, &bottom);
        ijk(&mut self.out, &axis);
        let _ = writeln!(self.out, " F{f}");
        self.out.push_str("G0");
        xyz(&mut self.out, &clear);
        ijk(&mut self.out, &axis);
        self.out.push('\n');
        // The next cutting move writes its own feed.
        self.feed_written = false;
        self.rapid = false;
        self.position = Some(clear);
        Ok(())
    }

    /// An arc from `from` to `to` about `center`, counter-clockwise about
    /// `axis`, written with R (I J K are the tool vector in G43.5).
    fn arc(
        &mut self,
        from: &Vec3,
        to: &Vec3,
        center: &Vec3,
        axis: &Vec3,
        circle_line: u32,
        line: u32,
    ) -> Result<(), AptError> {
        let err = |message: String| AptError {
            line: circle_line,
            word: "CIRCLE".into(),
            message,
        };
        let f = self.per_minute(self.feed, line)?;
        // The plane the axis is normal to: (G code, normal index, the two
        // plane axes in the order whose cross product is the normal).
        let (g, n, (p, q)) = match (0..3).find(|&i| (axis[i].abs() - 1.0).abs() < AXIS_ALIGNMENT) {
            Some(2) => (17, 2, (0, 1)),
            Some(1) => (18, 1, (2, 0)),
            Some(0) => (19, 0, (1, 2)),
            _ => {
                return Err(err(format!(
                    "CIRCLE axis {:.6},{:.6},{:.6} is not along X, Y or Z: not converted",
                    axis[0], axis[1], axis[2]
                )));
            }
        };
        let r0 = (from[p] - center[p]).hypot(from[q] - center[q]);
        let r1 = (to[p] - center[p]).hypot(to[q] - center[q]);
        if (r0 - r1).abs() > RADIUS_MISMATCH || r0 < SAME_POINT {
            return Err(err(format!(
                "the arc's start and end are {r0:.6} and {r1:.6} mm from the centre"
            )));
        }
        // Counter-clockwise about the axis: G3 when the axis is the plane's
        // positive normal, G2 when it is the negative one.
        let ccw = axis[n] > 0.0;
        let a0 = (from[q] - center[q]).atan2(from[p] - center[p]);
        let a1 = (to[q] - center[q]).atan2(to[p] - center[p]);
        let mut sweep = a1 - a0;
        if ccw {
            while sweep <= 0.0 {
                sweep += std::f64::consts::TAU;
            }
        } else {
            while sweep >= 0.0 {
                sweep -= std::f64::consts::TAU;
            }
        }
        let same = (to[p] - from[p]).hypot(to[q] - from[q]) < SAME_POINT;
        let code = if ccw { 3 } else { 2 };
        let write_arc = |out: &mut String, end: &Vec3, sweep: f64, feed: Option<f64>| {
            // R: negative for more than half a turn (FANUC).
            let r = if sweep.abs() > std::f64::consts::PI {
                -r0
            } else {
                r0
            };
            let _ = write!(
                out,
                "G{g} G{code} X{:.6} Y{:.6} Z{:.6} R{r:.6}",
                end[0], end[1], end[2]
            );
            if let Some(f) = feed {
                let _ = write!(out, " F{f}");
            }
        };
        let feed = (!self.feed_written).then_some(f);
        self.feed_written = true;
        if same {
            // A full circle: four quarters (R cannot name a whole turn).
            let turn = if ccw {
                std::f64::consts::TAU
            } else {
                -std::f64::consts::TAU
            };
            for k in 1..=4 {
                let t = f64::from(k) / 4.0;
                let mut end = *to;
                if k < 4 {
                    let a = a0 + turn * t;
                    end[p] = center[p] + r0 * a.cos();
                    end[q] = center[q] + r0 * a.sin();
                    end[n] = from[n] + (to[n] - from[n]) * t;
                }
                write_arc(
                    &mut self.out,
                    &end,
                    turn / 4.0,
                    if k == 1 { feed } else { None },
                );
                if k < 4 {
                    self.out.push('\n');
                }
            }
        } else {
            write_arc(&mut self.out, to, sweep, feed);
        }
        // Back to the XY plane for what follows.
        if g != 17 {
            self.out.push_str("\nG17");
        }
        Ok(())
    }
}

/// Writes ` X.. Y.. Z..`.
fn xyz(out: &mut String, p: &Vec3) {
    let _ = write!(out, " X{:.6} Y{:.6} Z{:.6}", p[0], p[1], p[2]);
}

/// Writes ` I.. J.. K..` (the tool vector of G43.5).
fn ijk(out: &mut String, d: &Vec3) {
    let _ = write!(out, " I{:.7} J{:.7} K{:.7}", d[0], d[1], d[2]);
}

/// `p` if it is within what a machine can have (after MSYS, units and
/// cycle lengths).
fn check_point(p: &Vec3, line: u32) -> Result<(), AptError> {
    if p.iter().any(|x| x.abs() > MAX_FILE_MAGNITUDE) {
        return Err(AptError {
            line,
            word: String::new(),
            message: format!(
                "the point {:e},{:e},{:e} (after MSYS) is beyond what a machine can have: at most {MAX_FILE_MAGNITUDE:e} in size",
                p[0], p[1], p[2]
            ),
        });
    }
    Ok(())
}
