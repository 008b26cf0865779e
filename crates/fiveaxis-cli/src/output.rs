//! Row writers for `fiveaxis run`: CSV and JSON Lines, exactly as the
//! `run` contract fixes them.

use fiveaxis_control::{Alarm, Row, displayed};
use fiveaxis_machine::Machine;

use crate::number::{write_computed_f64, write_f64, write_rounded, write_u64};
use crate::text::Text;

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
    /// `--digits`: every number rounded to at most this many decimals;
    /// `None`: the contract's shortest round-trip form.
    digits: Option<u8>,
}

impl<'m> RowWriter<'m> {
    /// A writer for rows of `machine`, numbers in full (the contract's
    /// form) or rounded to at most `digits` decimals.
    pub fn new(format: Format, machine: &'m Machine, digits: Option<u8>) -> Self {
        let axes = machine.axis_names().map(String::from).collect();
        Self {
            format,
            machine,
            axes,
            digits,
        }
    }

    /// Appends one number as the writer shows numbers.
    #[inline]
    fn number(&self, out: &mut Text, x: f64) {
        match self.digits {
            None => write_f64(out, x),
            Some(digits) => write_rounded(out, x, digits),
        }
    }

    /// Appends one computed number (tip, tool direction): the same text
    /// as [`RowWriter::number`].
    #[inline]
    fn computed(&self, out: &mut Text, x: f64) {
        match self.digits {
            None => write_computed_f64(out, x),
            Some(digits) => write_rounded(out, x, digits),
        }
    }

    /// The header (CSV only).
    pub fn header(&self, out: &mut Text) {
        if self.format == Format::Csv {
            out.put_slice(b"line,s,motion");
            for name in &self.axes {
                out.push(b',');
                out.put_slice(name.as_bytes());
            }
            out.put_slice(b",tip_x,tip_y,tip_z,tool_i,tool_j,tool_k,feed\n");
        }
    }

    /// Appends one row.
    pub fn row(&self, out: &mut Text, row: &Row) {
        out.make_room();
        let axis_count = self.machine.axis_count();
        let shown = displayed(self.machine, &row.joints);
        let values = shown[..axis_count].iter().copied();
        let pose = [
            row.tip.x, row.tip.y, row.tip.z, row.dir.x, row.dir.y, row.dir.z,
        ];
        const POSE_KEYS: [&str; 6] = ["tip_x", "tip_y", "tip_z", "tool_i", "tool_j", "tool_k"];
        match self.format {
            Format::Csv => {
                write_u64(out, u64::from(row.line));
                out.push(b',');
                self.number(out, row.s);
                out.push(b',');
                out.put_slice(row.motion.name().as_bytes());
                for x in values {
                    out.push(b',');
                    self.number(out, x);
                }
                for x in pose {
                    out.push(b',');
                    self.computed(out, x);
                }
                out.push(b',');
                if let Some(f) = row.feed {
                    self.number(out, f);
                }
                out.push(b'\n');
            }
            Format::Jsonl => {
                out.put_slice(b"{\"line\":");
                write_u64(out, u64::from(row.line));
                out.put_slice(b",\"s\":");
                self.number(out, row.s);
                out.put_slice(b",\"motion\":\"");
                out.put_slice(row.motion.name().as_bytes());
                out.push(b'"');
                for (key, x) in self.axes.iter().map(String::as_str).zip(values) {
                    out.put_slice(b",\"");
                    out.put_slice(key.as_bytes());
                    out.put_slice(b"\":");
                    self.number(out, x);
                }
                for (key, x) in POSE_KEYS.into_iter().zip(pose) {
                    out.put_slice(b",\"");
                    out.put_slice(key.as_bytes());
                    out.put_slice(b"\":");
                    self.computed(out, x);
                }
                out.put_slice(b",\"feed\":");
                match row.feed {
                    Some(f) => self.number(out, f),
                    None => out.put_slice(b"null"),
                }
                out.put_slice(b"}\n");
            }
        }
    }

    /// The closing alarm object (JSON Lines only).
    pub fn alarm(&self, out: &mut Text, alarm: &Alarm) {
        out.make_room();
        if self.format == Format::Jsonl {
            let object = serde_json::json!({
                "alarm": { "code": alarm.code.to_string(), "line": alarm.line, "message": alarm.message }
            });
            out.put_slice(object.to_string().as_bytes());
            out.push(b'\n');
        }
    }
}
