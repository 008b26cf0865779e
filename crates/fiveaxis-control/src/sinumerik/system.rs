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
//! * `$P_UIFR[n]`: the settable frames (K2; brief §3). A frame the
//!   program writes is kept for the run and takes the place of the
//!   offsets file's work offset n when n is next selected (G500 = 0,
//!   G54…G57 = 1…4, G505…G599 = 5…99: `$P_IFRAME = $P_UIFR[$P_IFRNUM]`,
//!   a write "becomes active only with the next G500/G54…", brief §3).
//!   Read, it is the frame written or the offsets file's work offset (its
//!   translation). Scale and mirror in a settable frame are refused.
//! * `$P_PFRAME`: the programmable frame, read and written (a write holds
//!   from the next block on).
//! * Components of both (K2 p2-45): `$P_UIFR[n, X, TR]`,
//!   `$P_PFRAME[Z, RT]`, with TR, FI, RT, SC, MI.
//!
//! Other writes are refused: the offsets are the offsets file's.

use fiveaxis_machine::{MAX_AXES, Machine, Offsets, Vec3};
use fiveaxis_sinumerik::{FrameAxis, FrameValue, System, Value};
use nalgebra::Rotation3;

use crate::command::Frame;
use crate::controller::Controller;

/// Settable frames the program wrote, by number 0…99.
const SETTABLE_FRAMES: usize = 100;

/// The frames a program reads and writes through system variables, kept
/// by the front end for the run.
#[derive(Debug)]
pub(crate) struct FrameStore {
    /// `$P_UIFR[n]` written in this run.
    pub(crate) settable: Box<[Option<Frame>; SETTABLE_FRAMES]>,
    /// The programmable frame in force (`$P_PFRAME`), as the front end
    /// keeps it.
    pub(crate) programmable: Frame,
    /// `$P_PFRAME` was written: the next block puts it in force.
    pub(crate) programmable_written: bool,
}

impl Default for FrameStore {
    fn default() -> Self {
        Self {
            settable: Box::new([None; SETTABLE_FRAMES]),
            programmable: Frame::IDENTITY,
            programmable_written: false,
        }
    }
}

/// The controller's state as the language reads it.
pub(crate) struct SystemView<'a, 'm> {
    pub(crate) controller: &'a Controller<'m>,
    /// The selected tool and edge of the front end.
    pub(crate) tool: u32,
    pub(crate) edge: u32,
    /// The frames of the front end.
    pub(crate) frames: &'a mut FrameStore,
    /// The front end's G group 13 (G70 1, G71 2, G700 3, G710 4).
    pub(crate) units: u8,
}

/// A frame value of the language as the kernel's frame: translations
/// (plus fine translations) of X, Y, Z and shifts of the other axes;
/// rotations RPY about Z, the new Y, the newest X (K2; as `ROT`); scale
/// and mirror of X, Y, Z.
pub(crate) fn frame_of_value(machine: &Machine, value: &FrameValue) -> Result<Frame, String> {
    let mut frame = Frame::IDENTITY;
    let mut angles = [0.0; 3];
    for a in &value.axes {
        let index = (a.axis.len() == 1)
            .then(|| machine.axis_index(char::from(a.axis.as_bytes()[0])))
            .flatten()
            .ok_or_else(|| format!("{} is not an axis of this machine", a.axis))?;
        let shift = a.tr + a.fi;
        if index < 3 {
            frame.translation[index] = shift;
            angles[index] = a.rt;
            frame.scale[index] = a.sc;
            frame.mirror[index] = a.mi;
        } else {
            if a.rt != 0.0 || a.sc != 1.0 || a.mi {
                return Err(format!(
                    "{}: a frame turns, scales and mirrors X, Y, Z only",
                    a.axis
                ));
            }
            frame.axis_shift[index] = shift;
        }
    }
    frame.rotation = Rotation3::from_euler_angles(
        angles[0].to_radians(),
        angles[1].to_radians(),
        angles[2].to_radians(),
    );
    if ![
        frame.translation.x,
        frame.translation.y,
        frame.translation.z,
    ]
    .iter()
    .chain(frame.scale.iter())
    .chain(frame.axis_shift.iter())
    .all(|v| v.is_finite())
        || frame.scale.contains(&0.0)
    {
        return Err("a frame with a scale of 0 or a value that is not finite".into());
    }
    Ok(frame)
}

/// The kernel's frame as a frame value of the language.
pub(crate) fn value_of_frame(machine: &Machine, frame: &Frame) -> FrameValue {
    let (rx, ry, rz) = frame.rotation.euler_angles();
    let rt = [rx, ry, rz].map(f64::to_degrees);
    let mut axes = Vec::new();
    for (i, name) in machine.axis_names().enumerate().take(MAX_AXES) {
        let axis = if i < 3 {
            FrameAxis {
                axis: name.to_string(),
                tr: frame.translation[i],
                fi: 0.0,
                rt: rt[i],
                sc: frame.scale[i],
                mi: frame.mirror[i],
            }
        } else {
            FrameAxis {
                axis: name.to_string(),
                tr: frame.axis_shift[i],
                fi: 0.0,
                rt: 0.0,
                sc: 1.0,
                mi: false,
            }
        };
        if axis.tr != 0.0 || axis.rt != 0.0 || axis.sc != 1.0 || axis.mi {
            axes.push(axis);
        }
    }
    FrameValue { axes }
}

/// The offsets file's work offset of settable frame `n` as a frame.
fn offsets_frame(offsets: &Offsets, n: usize) -> Frame {
    let (t, beyond) = match n {
        1..=4 => (offsets.work[n - 1], Some(offsets.work_beyond[n - 1])),
        5.. if n - 5 < offsets.extended_work.len() => (
            offsets.extended_work[n - 5],
            Some(offsets.extended_work_beyond[n - 5]),
        ),
        _ => (Vec3::zeros(), None),
    };
    let mut frame = Frame::rigid(t, Rotation3::identity());
    if let Some(beyond) = beyond {
        for (k, v) in beyond.iter().enumerate() {
            if 3 + k < MAX_AXES {
                frame.axis_shift[3 + k] = *v;
            }
        }
    }
    frame
}

/// A component of a frame: `[X, TR]` (K2 p2-45: TR translation, FI
/// fine translation, RT rotation, SC scale, MI mirror).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Component {
    Tr,
    Fi,
    Rt,
    Sc,
    Mi,
}

/// The axis and component of indices `[X, TR]`.
fn component(indices: &[Value]) -> Result<(String, Component), String> {
    match indices {
        [Value::Axis(axis), Value::Axis(c)] => {
            let c = match c.as_str() {
                "TR" => Component::Tr,
                "FI" => Component::Fi,
                "RT" => Component::Rt,
                "SC" => Component::Sc,
                "MI" => Component::Mi,
                _ => return Err(format!("{c} is not a frame component (TR, FI, RT, SC, MI)")),
            };
            Ok((axis.clone(), c))
        }
        _ => Err("a frame component takes [axis, TR | FI | RT | SC | MI]".into()),
    }
}

/// The value of one component of `frame`.
fn read_component(value: &FrameValue, axis: &str, c: Component) -> Value {
    let a = value.axes.iter().find(|a| a.axis == axis);
    match c {
        Component::Tr => Value::Real(a.map_or(0.0, |a| a.tr)),
        Component::Fi => Value::Real(a.map_or(0.0, |a| a.fi)),
        Component::Rt => Value::Real(a.map_or(0.0, |a| a.rt)),
        Component::Sc => Value::Real(a.map_or(1.0, |a| a.sc)),
        Component::Mi => Value::Int(i64::from(a.is_some_and(|a| a.mi))),
    }
}

/// `value` with one component written.
fn write_component(
    value: &mut FrameValue,
    axis: &str,
    c: Component,
    v: &Value,
) -> Result<(), String> {
    let x = v
        .as_f64()
        .ok_or_else(|| format!("a frame component takes a number, not {v:?}"))?;
    let index = match value.axes.iter().position(|a| a.axis == axis) {
        Some(i) => i,
        None => {
            value.axes.push(FrameAxis {
                axis: axis.to_owned(),
                tr: 0.0,
                fi: 0.0,
                rt: 0.0,
                sc: 1.0,
                mi: false,
            });
            value.axes.len() - 1
        }
    };
    let a = &mut value.axes[index];
    match c {
        Component::Tr => a.tr = x,
        Component::Fi => a.fi = x,
        Component::Rt => a.rt = x,
        Component::Sc => a.sc = x,
        Component::Mi => a.mi = x != 0.0,
    }
    Ok(())
}

/// The number of a settable frame index `[n]` (and the component
/// indices after it).
fn settable_index(indices: &[Value]) -> Result<usize, String> {
    let n = match indices {
        [n] | [n, _, _] => n.as_f64(),
        _ => None,
    }
    .ok_or("$P_UIFR takes the frame number [n] (or [n, axis, component])")?;
    if !(0.0..SETTABLE_FRAMES as f64).contains(&n) || n.fract() != 0.0 {
        return Err(format!(
            "$P_UIFR[{n}]: the settable frames are 0 to {}",
            SETTABLE_FRAMES - 1
        ));
    }
    Ok(n as usize)
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

impl SystemView<'_, '_> {
    /// `$P_GG[n]`: the active G function of group `n` as its place in the
    /// group (1 the first), 0 for a group whose function is not active
    /// (PGA00 p558; the groups of ONE p1262–1263).
    fn g_group(&self, indices: &[Value]) -> Result<i64, String> {
        use crate::modal::{CuttingMode, Distance, FeedMode, MotionMode, Plane, WorkSelect};
        let [n] = indices else {
            return Err("$P_GG takes one index, the G group".into());
        };
        let n = n.as_f64().unwrap_or(-1.0);
        let m = self.controller.modal();
        Ok(match n as i64 {
            1 => match m.motion {
                MotionMode::Rapid => 1,
                MotionMode::Linear => 2,
                MotionMode::Cw => 3,
                MotionMode::Ccw => 4,
            },
            6 => match m.plane {
                Plane::Xy => 1,
                Plane::Zx => 2,
                Plane::Yz => 3,
            },
            8 => match m.work {
                WorkSelect::Null => 1,
                WorkSelect::Standard(i) => 2 + i64::from(i),
                WorkSelect::Extended(p) | WorkSelect::Haas(p) => 5 + i64::from(p),
            },
            10 => match m.cutting {
                CuttingMode::ExactStop => 1,
                _ => 2,
            },
            13 => i64::from(self.units),
            14 => match m.distance {
                Distance::Absolute => 1,
                Distance::Incremental => 2,
            },
            15 => match m.feed_mode {
                FeedMode::InverseTime => 1,
                FeedMode::PerMinute => 2,
                FeedMode::PerRevolution => 3,
            },
            k if (1..=70).contains(&k) && n.fract() == 0.0 => 0,
            _ => return Err(format!("$P_GG[{n}]: no such G group")),
        })
    }
}

impl System for SystemView<'_, '_> {
    fn read(&mut self, name: &str, indices: &[Value]) -> Result<Value, String> {
        let c = self.controller;
        Ok(match name {
            "$AA_IW" | "$P_EP" | "$AA_IEN" => {
                Value::Real(c.program_position()[self.axis(indices)?])
            }
            "$AA_IM" | "$AA_IB" => Value::Real(c.joints()[self.axis(indices)?]),
            "$P_TOOLNO" | "$TC_MPP6" => Value::Int(i64::from(self.tool)),
            "$P_GG" => Value::Int(self.g_group(indices)?),
            "$P_TOOL" => Value::Int(i64::from(self.edge)),
            "$P_F" => Value::Real(c.feed()),
            "$P_UIFR" => {
                let n = settable_index(indices)?;
                let frame =
                    self.frames.settable[n].unwrap_or_else(|| offsets_frame(c.offsets(), n));
                let value = value_of_frame(c.machine(), &frame);
                if indices.len() == 3 {
                    let (axis, k) = component(&indices[1..])?;
                    read_component(&value, &axis, k)
                } else {
                    Value::Frame(Box::new(value))
                }
            }
            "$P_PFRAME" => {
                let value = value_of_frame(c.machine(), &self.frames.programmable);
                if indices.is_empty() {
                    Value::Frame(Box::new(value))
                } else {
                    let (axis, k) = component(indices)?;
                    read_component(&value, &axis, k)
                }
            }
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

    fn write(&mut self, name: &str, indices: &[Value], value: Value) -> Result<(), String> {
        let machine = self.controller.machine();
        let frame = |value: &Value| match value {
            Value::Frame(f) => frame_of_value(machine, f),
            _ => Err(format!(
                "{name} takes a frame (CTRANS, CROT, … or a FRAME variable)"
            )),
        };
        match name {
            "$P_UIFR" => {
                let n = settable_index(indices)?;
                let f = if indices.len() == 3 {
                    let (axis, k) = component(&indices[1..])?;
                    let old = self.frames.settable[n]
                        .unwrap_or_else(|| offsets_frame(self.controller.offsets(), n));
                    let mut v = value_of_frame(machine, &old);
                    write_component(&mut v, &axis, k, &value)?;
                    frame_of_value(machine, &v)?
                } else {
                    frame(&value)?
                };
                if f.scales() {
                    return Err(format!(
                        "$P_UIFR[{n}]: scale and mirror in a settable frame are not carried out"
                    ));
                }
                self.frames.settable[n] = Some(f);
                Ok(())
            }
            "$P_PFRAME" => {
                self.frames.programmable = if indices.is_empty() {
                    frame(&value)?
                } else {
                    let (axis, k) = component(indices)?;
                    let mut v = value_of_frame(machine, &self.frames.programmable);
                    write_component(&mut v, &axis, k, &value)?;
                    frame_of_value(machine, &v)?
                };
                self.frames.programmable_written = true;
                Ok(())
            }
            _ => Err(format!(
                "{name} cannot be written: the offsets come from the offsets file"
            )),
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_values_round_trip() {
        let machine = fiveaxis_machine::builtin("sinumerik-dmu-bc").expect("built-in");
        let value = FrameValue {
            axes: vec![
                FrameAxis {
                    axis: "X".into(),
                    tr: 10.0,
                    fi: 0.5,
                    rt: 0.0,
                    sc: 1.0,
                    mi: false,
                },
                FrameAxis {
                    axis: "Z".into(),
                    tr: 0.0,
                    fi: 0.0,
                    rt: 30.0,
                    sc: 1.0,
                    mi: false,
                },
                FrameAxis {
                    axis: "C".into(),
                    tr: 15.0,
                    fi: 0.0,
                    rt: 0.0,
                    sc: 1.0,
                    mi: false,
                },
            ],
        };
        let frame = frame_of_value(&machine, &value).expect("a frame");
        assert_eq!(frame.translation, Vec3::new(10.5, 0.0, 0.0));
        let x = frame.rotation * Vec3::x();
        let (s, c) = 30f64.to_radians().sin_cos();
        assert!((x - Vec3::new(c, s, 0.0)).norm() < 1e-12);
        let c_index = machine.axis_index('C').expect("C");
        assert_eq!(frame.axis_shift[c_index], 15.0);
        let back = frame_of_value(&machine, &value_of_frame(&machine, &frame)).expect("a frame");
        assert!((back.translation - frame.translation).norm() < 1e-12);
        assert!(back.rotation.angle_to(&frame.rotation) < 1e-12);
        assert_eq!(back.axis_shift, frame.axis_shift);
        // An axis the machine does not have, a scale of 0.
        let bad = FrameValue {
            axes: vec![FrameAxis {
                axis: "Q".into(),
                tr: 1.0,
                fi: 0.0,
                rt: 0.0,
                sc: 1.0,
                mi: false,
            }],
        };
        assert!(frame_of_value(&machine, &bad).is_err());
    }
}
