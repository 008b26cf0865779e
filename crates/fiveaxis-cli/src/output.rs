//! Row writers for `fiveaxis run`: CSV and JSON Lines, exactly as the
//! `run` contract fixes them.

use std::io::{self, Write};

use fiveaxis_control::{Alarm, Row};
use fiveaxis_machine::Machine;

/// Output format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Comma-separated values with a header row.
    Csv,
    /// One JSON object per line.
    Jsonl,
}

/// Writes rows in one format.
#[derive(Debug)]
pub struct RowWriter<'m> {
    format: Format,
    machine: &'m Machine,
    /// Column names of the machine axes, in order.
    axes: Vec<String>,
    /// Which axes are shown modulo 360.
    rollover: Vec<bool>,
}

/// A number in its shortest round-trip form; negative zero is written 0.
fn number(out: &mut impl Write, x: f64) -> io::Result<()> {
    write!(out, "{}", x + 0.0)
}

/// A rollover axis position in [0, 360).
fn modulo_360(x: f64) -> f64 {
    let r = x.rem_euclid(360.0);
    if r >= 360.0 { 0.0 } else { r }
}

impl<'m> RowWriter<'m> {
    /// A writer for rows of `machine`.
    pub fn new(format: Format, machine: &'m Machine) -> Self {
        let axes = machine.axis_names().map(String::from).collect();
        let rollover = machine
            .linear
            .iter()
            .map(|_| false)
            .chain(machine.rotary.iter().map(|r| r.rollover))
            .collect();
        Self {
            format,
            machine,
            axes,
            rollover,
        }
    }

    /// The header (CSV only).
    pub fn header(&self, out: &mut impl Write) -> io::Result<()> {
        if self.format == Format::Csv {
            out.write_all(b"line,s,motion")?;
            for name in &self.axes {
                write!(out, ",{name}")?;
            }
            out.write_all(b",tip_x,tip_y,tip_z,tool_i,tool_j,tool_k,feed\n")?;
        }
        Ok(())
    }

    /// One row.
    pub fn row(&self, out: &mut impl Write, row: &Row) -> io::Result<()> {
        let axis_count = self.machine.axis_count();
        let values = row.joints[..axis_count]
            .iter()
            .zip(&self.rollover)
            .map(|(&x, &roll)| if roll { modulo_360(x) } else { x });
        let pose = [
            row.tip.x, row.tip.y, row.tip.z, row.dir.x, row.dir.y, row.dir.z,
        ];
        const POSE_KEYS: [&str; 6] = ["tip_x", "tip_y", "tip_z", "tool_i", "tool_j", "tool_k"];
        match self.format {
            Format::Csv => {
                write!(out, "{},", row.line)?;
                number(out, row.s)?;
                write!(out, ",{}", row.motion.name())?;
                for x in values.chain(pose) {
                    out.write_all(b",")?;
                    number(out, x)?;
                }
                out.write_all(b",")?;
                if let Some(f) = row.feed {
                    number(out, f)?;
                }
                out.write_all(b"\n")
            }
            Format::Jsonl => {
                write!(out, "{{\"line\":{},\"s\":", row.line)?;
                number(out, row.s)?;
                write!(out, ",\"motion\":\"{}\"", row.motion.name())?;
                let keys = self.axes.iter().map(String::as_str).chain(POSE_KEYS);
                for (key, x) in keys.zip(values.chain(pose)) {
                    write!(out, ",\"{key}\":")?;
                    number(out, x)?;
                }
                out.write_all(b",\"feed\":")?;
                match row.feed {
                    Some(f) => number(out, f)?,
                    None => out.write_all(b"null")?,
                }
                out.write_all(b"}\n")
            }
        }
    }

    /// The closing alarm object (JSON Lines only).
    pub fn alarm(&self, out: &mut impl Write, alarm: &Alarm) -> io::Result<()> {
        if self.format == Format::Jsonl {
            let object = serde_json::json!({
                "alarm": { "code": alarm.code.to_string(), "line": alarm.line, "message": alarm.message }
            });
            writeln!(out, "{object}")?;
        }
        Ok(())
    }
}
