//! G10, programmable data input, read into a [`DataSetting`]: FANUC's
//! (and Haas's) formats L2 / L20 (work offsets) and L10–L13 (tool
//! offsets), and LinuxCNC's L1 / L10 / L11 (tool table) and L2 / L20
//! (coordinate systems; g-code.adoc, G10).

use fiveaxis_gcode::Span;
use fiveaxis_machine::{MAX_EXTENDED_WORK, MAX_HAAS_WORK, MAX_TOOL_OFFSET};

use super::{Rules, Words};
use crate::alarm::{Alarm, Condition};
use crate::command::{DataSetting, OffsetMemory, ToolField, ToolLength};
use crate::modal::WorkSelect;

/// LinuxCNC's coordinate systems (G54 … G59.3).
const NGC_WORK_SYSTEMS: u32 = 9;
/// G54 … G59, the standard work offsets of the kernel's offset memory.
pub(crate) const KERNEL_WORK_SYSTEMS: u32 = 6;
/// G59.1 … G59.3, kept as G54.1 P1 … P3.
const NGC_EXTRA_SYSTEMS: u32 = 3;

impl Words {
    /// G10 by FANUC's formats (Haas's with `haas`); `incremental`: G91 is
    /// in force.
    pub(crate) fn data_setting(
        &mut self,
        span: Span,
        rules: &Rules,
        haas: bool,
        incremental: bool,
    ) -> Result<DataSetting, Alarm> {
        let l = self.take(b'L');
        let l_value = match l {
            // Haas: L1 is L11, the length wear.
            Some(l) if haas && self.integer(&l, 99)? == 1 => 11,
            Some(l) => self.integer(&l, 99)?,
            // Tool offset memory A format, `G10 P R`: the offset value of
            // number P, which is what H reads: the length geometry.
            None if self.has(b'P') && self.has(b'R') => 10,
            None => {
                return Err(self.alarm(
                    Condition::IllegalG10L,
                    Some(span),
                    "G10 needs L (or P and R: tool offset value)".into(),
                ));
            }
        };
        let Some(p) = self.take(b'P') else {
            return Err(self.alarm(Condition::IllegalG10P, Some(span), "G10 needs P".into()));
        };
        match l_value {
            2 | 20 => {
                let n = self.integer(&p, 9999)?;
                let max = if l_value == 2 {
                    6
                } else if haas {
                    // Haas: G154 P1-P99 (G110-G129 are P1-P20).
                    MAX_HAAS_WORK
                } else {
                    MAX_EXTENDED_WORK
                };
                if (l_value == 20 && n == 0) || n > max {
                    return Err(self.alarm(
                        Condition::IllegalG10P,
                        Some(p.span),
                        format!("G10 L{l_value} P{n}: no such work offset"),
                    ));
                }
                let memory = match (l_value, n) {
                    (2, 0) => OffsetMemory::External,
                    (2, n) => OffsetMemory::Standard(n as u8 - 1),
                    (_, n) => OffsetMemory::Extended(n as u8),
                };
                // One value per controlled axis, rotary axes included.
                let values = self.axis_values(rules);
                Ok(DataSetting::WorkOffset {
                    memory,
                    values,
                    incremental,
                })
            }
            10..=13 => {
                let n = self.integer(&p, 9999)?;
                if n == 0 || n > MAX_TOOL_OFFSET {
                    return Err(self.alarm(
                        Condition::IllegalG10P,
                        Some(p.span),
                        format!("G10 L{l_value} P{n}: no such tool offset"),
                    ));
                }
                let Some(r) = self.take(b'R') else {
                    return Err(self.alarm(
                        Condition::NoDataAfterAddress,
                        Some(span),
                        "G10 L10-L13 needs R".into(),
                    ));
                };
                Ok(DataSetting::ToolOffset {
                    number: n,
                    field: match l_value {
                        10 => ToolField::Length,
                        11 => ToolField::LengthWear,
                        12 => ToolField::Radius,
                        _ => ToolField::RadiusWear,
                    },
                    value: rules.length(&r),
                    incremental,
                })
            }
            _ => Err(self.alarm(
                Condition::IllegalG10L,
                l.map(|l| l.span),
                format!("G10 L{l_value} is not a data-setting format of this control"),
            )),
        }
    }

    /// G10 by LinuxCNC's formats; `work`: the coordinate system in use
    /// (P0's).
    pub(crate) fn data_setting_linuxcnc(
        &mut self,
        span: Span,
        rules: &Rules,
        work: WorkSelect,
    ) -> Result<DataSetting, Alarm> {
        let Some(l) = self.take(b'L') else {
            return Err(self.alarm(Condition::IllegalG10L, Some(span), "G10 needs L".into()));
        };
        let l_value = self.integer(&l, 99)?;
        let Some(p) = self.take(b'P') else {
            return Err(self.alarm(Condition::IllegalG10P, Some(span), "G10 needs P".into()));
        };
        match l_value {
            2 | 20 => {
                let n = self.integer(&p, NGC_WORK_SYSTEMS)?;
                let n = match (n, work) {
                    (0, WorkSelect::Standard(i)) => u32::from(i) + 1,
                    (0, WorkSelect::Extended(k)) if u32::from(k) <= NGC_EXTRA_SYSTEMS => {
                        KERNEL_WORK_SYSTEMS + u32::from(k)
                    }
                    (0, WorkSelect::Extended(k)) => {
                        return Err(self.alarm(
                            Condition::IllegalG10P,
                            Some(p.span),
                            format!(
                                "G10 P0: the system in use is G54.1 P{k}, not one of LinuxCNC's"
                            ),
                        ));
                    }
                    (n, _) => n,
                };
                let rotation = self.take(b'R');
                if let Some(r) = &rotation
                    && l_value == 20
                {
                    // rs274: "R not allowed in G10 L20".
                    return Err(self.alarm(
                        Condition::WordNotUsed,
                        Some(r.span),
                        "G10 L20 takes no R: the rotation is set by G10 L2".into(),
                    ));
                }
                // X, Y, Z and the axes beyond them (A, B, C…).
                let values = self.axis_values(rules);
                Ok(DataSetting::CoordinateSystem {
                    system: n as usize - 1,
                    values,
                    rotation: rotation.map(|r| rules.angle(&r)),
                    at_position: l_value == 20,
                })
            }
            1 | 10 | 11 => {
                let number = self.integer(&p, MAX_TOOL_OFFSET)?;
                let length = self.take(b'Z').map(|word| {
                    let v = rules.length(&word);
                    match l_value {
                        1 => ToolLength::Value(v),
                        10 => ToolLength::Reads(v),
                        _ => ToolLength::ReadsMachine(v),
                    }
                });
                let radius = self.take(b'R').map(|word| rules.length(&word));
                Ok(DataSetting::ToolTable {
                    number,
                    length,
                    radius,
                })
            }
            _ => Err(self.alarm(
                Condition::IllegalG10L,
                Some(l.span),
                format!("G10 L{l_value}: LinuxCNC's forms are L1, L10, L11, L2 and L20"),
            )),
        }
    }
}
