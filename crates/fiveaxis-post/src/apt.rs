//! APT / CL data in, a TCPC program out (`G43.5` with the tool vector,
//! FANUC style), for a machine with the option; `fiveaxis post` then makes
//! it a machine-axis program for a machine without.
//!
//! Records read (APT CL print as CAM systems write it: `WORD/args`, a `$`
//! at the end of a line continues the record on the next):
//!
//! * `GOTO/x,y,z[,i,j,k]`: the tool end point and, if given, the tool axis
//!   vector (kept until the next one); a cutting move, or positioning after
//!   `RAPID`.
//! * `RAPID`: the next `GOTO` is positioning.
//! * `FEDRAT/f[,MMPM]` (NX: `FEDRAT/MMPM,f`): feed, mm/min (`IPM` in
//!   inch units).
//! * `MULTAX/ON|OFF`: with `OFF` (3-axis data) a `GOTO/x,y,z` has the tool
//!   along +Z (of the MSYS frame); with `ON`, and before any `MULTAX`, it
//!   keeps the last vector (initially +Z).
//! * `MSYS/x,y,z,xi,xj,xk,yi,yj,yk` (NX CLSF): the following points,
//!   vectors and circles are in the frame with that origin and those X
//!   and Y axes (Z = X × Y), turned into the absolute frame.
//! * `CIRCLE/xc,yc,zc,i,j,k[,...]`: the next `GOTO` ends an arc about that
//!   centre, counter-clockwise about the axis vector (right-hand rule, as
//!   the record's axis is the arc's normal); written `G2`/`G3` with `R` in
//!   the plane the axis is normal to (G17 / G18 / G19), the tool standing.
//! * `LOAD/TOOL,n` (`LOADTL/n`): `Tn M6`, then TCPC with `Hn`.
//! * `SPINDL/s,RPM,CLW|CCLW` (NX: `SPINDL/RPM,s,CLW`): `S s M3|M4`;
//!   `SPINDL/OFF`: `M5`; `COOLNT/ON|FLOOD`: `M8`, `COOLNT/MIST`: `M7`,
//!   `COOLNT/OFF`: `M9`. The machine-axis output carries these words.
//! * `UNIT/MM|INCH`; `END`, `FINI`: the end.
//! * Kept as comments (no motion): `PARTNO`, `INSERT`, `CUTTER`, `SELECT`,
//!   `TRNTYP/WORLD` and `CSYS` (the points are in the world frame),
//!   `CUTCOM` (as a comment, never G41/G42: the CL points are the tool
//!   tip path the CAM has already offset; compensating again at the
//!   control would offset it twice), `TLDATA` (the tool's shape; its
//!   length is the offsets file's), NX's `TOOL PATH`, `END-OF-PATH`,
//!   `PAINT` (display) and `$$` lines, and vendor records `CSI_...`.
//!
//! Anything else is an error with its line: a record that might move the
//! tool is never dropped silently.
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
    /// What is wrong.
    pub message: String,
}

/// A tool vector shorter than this is refused.
const MIN_VECTOR: f64 = 1e-6;
/// Distance below which an arc's end is its start (a full circle), mm.
const SAME_POINT: f64 = 1e-6;
/// Largest difference of the start and end radius of an arc, mm.
const RADIUS_MISMATCH: f64 = 1e-3;
/// Largest angle between an arc's axis and a coordinate axis, as a
/// component difference of unit vectors.
const AXIS_ALIGNMENT: f64 = 1e-6;

/// The state of the reader between records.
struct State {
    out: String,
    position: Option<Vec3>,
    vector: Vec3,
    rapid: bool,
    feed: Option<f64>,
    feed_written: bool,
    circle: Option<(Vec3, Vec3, u32)>,
    tool: Option<u32>,
    tcpc: bool,
    ended: bool,
    /// `MULTAX/OFF` in force: a GOTO without a vector has the tool along
    /// +Z (of the MSYS frame).
    three_axis: bool,
    /// `MSYS` in force: origin and rotation (columns: the frame's X, Y,
    /// Z in the absolute frame).
    msys: Option<(Vec3, nalgebra::Matrix3<f64>)>,
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
        circle: None,
        tool: None,
        tcpc: false,
        ended: false,
        three_axis: false,
        msys: None,
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
        let raw = raw.trim();
        if record.is_empty() {
            start = line;
        }
        if let Some(body) = raw.strip_suffix('$') {
            record.push_str(body.trim());
            continue;
        }
        record.push_str(raw);
        let r = std::mem::take(&mut record);
        if st.ended {
            if r.is_empty() {
                continue;
            }
            return Err(AptError {
                line: start,
                message: format!("`{r}` after the end of the tool path"),
            });
        }
        let before = st.out.len();
        st.record(&r, start)?;
        let written = st.out[before..].matches('\n').count();
        source_lines.extend(std::iter::repeat_n(Some(start), written));
    }
    if !record.is_empty() {
        return Err(AptError {
            line: start,
            message: "the last record ends in `$` (continued on no line)".into(),
        });
    }
    if let Some((_, _, line)) = st.circle {
        return Err(AptError {
            line,
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
    })
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
            message: format!(
                "expected {} to {} numbers, found `{args}`",
                count.start(),
                count.end()
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
            message: format!("`{text}` is not a finite number"),
        });
    }
    if x.abs() > MAX_FILE_MAGNITUDE {
        return Err(AptError {
            line,
            message: format!(
                "`{text}` is beyond what a machine can have: at most {MAX_FILE_MAGNITUDE:e} in size"
            ),
        });
    }
    Ok(x)
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
        if r.is_empty() {
            return Ok(());
        }
        if let Some(text) = r.strip_prefix("$$") {
            let _ = writeln!(self.out, "({})", comment_text(text.trim()));
            return Ok(());
        }
        let (word, args) = match r.split_once('/') {
            Some((w, a)) => (w.trim().to_ascii_uppercase(), a.trim()),
            None => (r.trim().to_ascii_uppercase(), ""),
        };
        let err = |message: String| AptError { line, message };
        match word.as_str() {
            "GOTO" => self.goto(&numbers(args, line, 3..=6)?, line),
            "RAPID" => {
                self.rapid = true;
                Ok(())
            }
            "FEDRAT" => {
                // `FEDRAT/f[,MMPM|IPM]` or NX's `FEDRAT/MMPM,f`.
                let mut value = None;
                let mut unit_ok = true;
                for part in args.split(',').map(str::trim) {
                    match part.to_ascii_uppercase().as_str() {
                        "MMPM" | "IPM" => {}
                        "" => unit_ok = false,
                        p if p.parse::<f64>().is_ok() && value.is_none() => {
                            value = Some(bounded(p.parse::<f64>().unwrap_or(f64::NAN), p, line)?);
                        }
                        _ => unit_ok = false,
                    }
                }
                match value {
                    Some(f) if unit_ok && f > 0.0 && f.is_finite() => {
                        self.feed = Some(f);
                        self.feed_written = false;
                        Ok(())
                    }
                    _ => Err(err(format!(
                        "FEDRAT/{args}: only a positive feed per minute (MMPM, IPM) is read"
                    ))),
                }
            }
            "MULTAX" => match args.trim().to_ascii_uppercase().as_str() {
                "ON" | "" => {
                    self.three_axis = false;
                    Ok(())
                }
                "OFF" => {
                    self.three_axis = true;
                    Ok(())
                }
                _ => Err(err(format!("MULTAX/{args}: ON or OFF"))),
            },
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
                let identity = (x - Vec3::x()).norm() < 1e-12
                    && (y - Vec3::y()).norm() < 1e-12
                    && Vec3::new(v[0], v[1], v[2]).norm() == 0.0;
                self.msys = (!identity).then(|| {
                    (
                        Vec3::new(v[0], v[1], v[2]),
                        nalgebra::Matrix3::from_columns(&[x, y, z]),
                    )
                });
                Ok(())
            }
            "CIRCLE" => {
                let v = numbers(args, line, 6..=11)?;
                let axis = Vec3::new(v[3], v[4], v[5]);
                if axis.norm() < MIN_VECTOR {
                    return Err(err("CIRCLE with a zero axis vector".into()));
                }
                let center = self.point(&Vec3::new(v[0], v[1], v[2]));
                self.circle = Some((center, self.direction(&axis.normalize()), line));
                Ok(())
            }
            "LOAD" | "LOADTL" => {
                let n = args
                    .split(',')
                    .map(str::trim)
                    .find_map(|a| a.parse::<f64>().ok())
                    .filter(|n| n.fract() == 0.0 && *n >= 1.0 && *n <= 9999.0)
                    .ok_or_else(|| err(format!("{word}/{args}: no tool number")))?;
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
                let upper = args.to_ascii_uppercase();
                if upper.trim() == "OFF" {
                    self.out.push_str("M5\n");
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
                                "SPINDL/{args}: only a speed in RPM, CLW, CCLW are read"
                            )));
                        }
                    }
                }
                let s = speed
                    .filter(|s| *s >= 0.0)
                    .ok_or_else(|| err(format!("SPINDL/{args}: no speed")))?;
                let _ = writeln!(self.out, "S{} M{m}", s.round());
                Ok(())
            }
            "COOLNT" => {
                let m = match args.trim().to_ascii_uppercase().as_str() {
                    "ON" | "FLOOD" => 8,
                    "MIST" => 7,
                    "OFF" => 9,
                    _ => return Err(err(format!("COOLNT/{args}: not read"))),
                };
                let _ = writeln!(self.out, "M{m}");
                Ok(())
            }
            "UNIT" => match args.trim().to_ascii_uppercase().as_str() {
                "MM" => Ok(()),
                "INCH" | "INCHES" => {
                    self.out.push_str("G20\n");
                    Ok(())
                }
                _ => Err(err(format!("UNIT/{args}: not read"))),
            },
            "END" | "FINI" => {
                self.ended = true;
                Ok(())
            }
            "TRNTYP" if !args.to_ascii_uppercase().starts_with("WORLD") => Err(err(format!(
                "TRNTYP/{args}: only WORLD (points in the world frame) is read"
            ))),
            "PARTNO" | "INSERT" | "CUTTER" | "SELECT" | "TRNTYP" | "CSYS" | "CUTCOM" | "TLDATA"
            | "TOOL PATH" | "END-OF-PATH" | "PAINT" => {
                let _ = writeln!(self.out, "({})", comment_text(r));
                Ok(())
            }
            w if w.starts_with("CSI_") => {
                let _ = writeln!(self.out, "({})", comment_text(r));
                Ok(())
            }
            _ => Err(err(format!("`{word}` records are not read"))),
        }
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

    fn goto(&mut self, v: &[f64], line: u32) -> Result<(), AptError> {
        let err = |message: String| AptError { line, message };
        let p = self.point(&Vec3::new(v[0], v[1], v[2]));
        if p.iter().any(|x| x.abs() > MAX_FILE_MAGNITUDE) {
            return Err(err(format!(
                "the point {:e},{:e},{:e} (after MSYS) is beyond what a machine can have: at most {MAX_FILE_MAGNITUDE:e} in size",
                p[0], p[1], p[2]
            )));
        }
        if v.len() == 3 && self.three_axis {
            // MULTAX/OFF: the tool along +Z of the frame.
            self.vector = self.direction(&Vec3::z());
        }
        if v.len() == 6 {
            let d = Vec3::new(v[3], v[4], v[5]);
            if d.norm() < MIN_VECTOR {
                return Err(err("GOTO with a zero tool vector".into()));
            }
            let d = self.direction(&d.normalize());
            if self.circle.is_some() && (d - self.vector).norm() > AXIS_ALIGNMENT {
                return Err(err(
                    "the tool vector changes along an arc: not converted (TCPC arcs keep the tool standing)"
                        .into(),
                ));
            }
            self.vector = d;
        } else if v.len() != 3 {
            return Err(err("GOTO takes 3 or 6 numbers".into()));
        }
        let xyz = |out: &mut String, p: &Vec3| {
            let _ = write!(out, " X{:.6} Y{:.6} Z{:.6}", p[0], p[1], p[2]);
        };
        if !self.tcpc {
            // TCPC starts up with a rapid to the first point in the tool
            // direction standing: `G43.5 H1` alone would first lift Z by
            // the tool length, over the top of travel from the reference
            // position, and I J K are refused in the start-up block on a
            // table or mixed machine (PS5421). The move with the vector
            // follows.
            let h = self.tool.unwrap_or(1);
            let _ = write!(self.out, "G43.5 H{h} G0");
            xyz(&mut self.out, &p);
            self.out.push('\n');
            self.tcpc = true;
        }
        let ijk = |out: &mut String, d: &Vec3| {
            let _ = write!(out, " I{:.7} J{:.7} K{:.7}", d[0], d[1], d[2]);
        };
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
            let f = self
                .feed
                .ok_or_else(|| err("a cutting move before any FEDRAT".into()))?;
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
            message,
        };
        let f = self.feed.ok_or_else(|| AptError {
            line,
            message: "a cutting move before any FEDRAT".into(),
        })?;
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
