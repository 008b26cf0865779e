//! The system variables a SINUMERIK part program reads, answered from
//! the controller's state (PGA00 p558–562; W1 for the tool data).
//!
//! * `$AA_IW[ax]`, `$P_EP[ax]`, `$AC_…`: the position in the workpiece
//!   coordinates (the block before has ended: every read is after
//!   preprocessing stops, as `STOPRE` makes it on the control).
//! * `$AA_IM[ax]`: the machine position.
//! * `$P_TOOLNO`, `$P_TOOL`: the selected tool and edge; `$TC_DP1…25[t,d]`
//!   the tool's data from the offsets file (3 length, 6 radius, 12 length
//!   wear, 15 radius wear; 1 type: a milling tool, 120).
//! * `$P_F`, `$P_S`: the feed and spindle speed in force.
//!
//! Writing is refused: the offsets and frames are the offsets file's.

use fiveaxis_sinumerik::{System, Value};

use crate::controller::Controller;

/// The controller's state as the language reads it.
pub(crate) struct SystemView<'a, 'm> {
    pub(crate) controller: &'a Controller<'m>,
    /// The selected tool and edge of the front end.
    pub(crate) tool: u32,
    pub(crate) edge: u32,
}

impl SystemView<'_, '_> {
    fn axis(&self, indices: &[Value]) -> Result<usize, String> {
        match indices {
            [Value::Axis(name)] if name.len() == 1 => self
                .controller
                .machine()
                .axis_index(char::from(name.as_bytes()[0]))
                .ok_or_else(|| format!("{name} is not an axis of this machine")),
            _ => Err("the variable takes one axis index, [X]".into()),
        }
    }
}

impl System for SystemView<'_, '_> {
    fn read(&mut self, name: &str, indices: &[Value]) -> Result<Value, String> {
        let c = self.controller;
        Ok(match name {
            "$AA_IW" | "$P_EP" | "$AA_IEN" => {
                Value::Real(c.programmed_position()[self.axis(indices)?])
            }
            "$AA_IM" | "$AA_IB" => Value::Real(c.joints()[self.axis(indices)?]),
            "$P_TOOLNO" | "$TC_MPP6" => Value::Int(i64::from(self.tool)),
            "$P_TOOL" => Value::Int(i64::from(self.edge)),
            "$P_F" => Value::Real(c.feed()),
            "$P_S" => Value::Real(c.spindle_speed()),
            _ if name.starts_with("$TC_DP") => {
                let k: u32 = name["$TC_DP".len()..]
                    .parse()
                    .map_err(|_| format!("{name} is not a system variable of this control"))?;
                let [t, _d] = match indices {
                    [t, d] => [t, d].map(|v| v.as_f64().unwrap_or(-1.0)),
                    _ => return Err(format!("{name} takes two indices, [tool, edge]")),
                };
                if t < 0.0 || t.fract() != 0.0 {
                    return Err(format!("{name}: {t} is not a tool number"));
                }
                let tool = c.offsets().tool(t as u32);
                Value::Real(match k {
                    1 => 120.0,
                    3 => tool.length,
                    6 => tool.radius,
                    12 => tool.length_wear,
                    15 => tool.radius_wear,
                    2 | 4 | 5 | 7..=11 | 13 | 14 | 16..=25 => 0.0,
                    _ => return Err(format!("{name} is not a tool parameter")),
                })
            }
            _ => return Err(format!("{name} is not a system variable of this control")),
        })
    }

    fn write(&mut self, name: &str, _indices: &[Value], _value: Value) -> Result<(), String> {
        Err(format!(
            "{name} cannot be written: offsets and frames come from the offsets file"
        ))
    }

    fn is_axis(&self, name: &str) -> bool {
        name.len() == 1
            && self
                .controller
                .machine()
                .axis_index(char::from(name.as_bytes()[0]))
                .is_some()
    }

    fn is_builtin(&self, name: &str) -> bool {
        super::is_builtin(name)
    }
}
