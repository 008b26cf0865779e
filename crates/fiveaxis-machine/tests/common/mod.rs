//! Random machines built in code, for the property tests.

#![allow(dead_code)]

use fiveaxis_machine::{
    Control, Dynamics, Joints, LinearAxis, MAX_AXES, MAX_M_CODE, MCodes, MFunction, Machine,
    Parameters, ProgrammingFrame, RESERVED_M_CODES, RotaryAxis, RotaryChoice, Side, Vec3,
};
use nalgebra::Unit;
use proptest::prelude::*;
use proptest::sample::subsequence;
use proptest::test_runner::{Config, RngSeed};

/// A deterministic proptest configuration.
pub fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x5A17_F1FE),
        failure_persistence: None,
        ..Config::default()
    }
}

/// A unit direction: axis-aligned, at 45° between two axes, or arbitrary.
pub fn direction() -> impl Strategy<Value = Unit<Vec3>> {
    let sign = || prop_oneof![Just(1.0), Just(-1.0)];
    let aligned = (0..3usize, sign()).prop_map(|(i, s)| {
        let mut v = Vec3::zeros();
        v[i] = s;
        v
    });
    let diagonal = (0..3usize, sign(), sign()).prop_map(|(i, s, t)| {
        let mut v = Vec3::zeros();
        v[i] = s;
        v[(i + 1) % 3] = t;
        v
    });
    let any = (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)
        .prop_map(|(x, y, z)| Vec3::new(x, y, z))
        .prop_filter("not too short", |v| v.norm() > 0.1);
    prop_oneof![aligned, diagonal, any].prop_map(Unit::new_normalize)
}

/// A point within a few hundred millimetres of the origin.
pub fn point(range: f64) -> impl Strategy<Value = Vec3> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// Limits `lo < hi` inside `[-range, range]`, holding 0 (where a machine's
/// reference position is unless its file says otherwise; a machine file
/// with the reference position outside the limits is refused).
fn limits(range: f64) -> impl Strategy<Value = (f64, f64)> {
    (0.0..range, 0.001..range).prop_map(|(down, up)| (-down, up))
}

/// Rotary limits: some, none (unlimited) or rollover.
fn rotary_limits() -> impl Strategy<Value = (Option<(f64, f64)>, bool)> {
    prop_oneof![
        limits(360.0).prop_map(|l| (Some(l), false)),
        Just((None, false)),
        Just((None, true)),
    ]
}

/// Axis dynamics: every key positive, jerk given or not.
pub fn dynamics() -> impl Strategy<Value = Dynamics> {
    (
        1.0..1e6f64,
        1.0..1e6f64,
        1.0..1e6f64,
        proptest::option::of(1.0..1e9f64),
    )
        .prop_map(
            |(max_velocity, rapid, max_acceleration, max_jerk)| Dynamics {
                max_velocity,
                rapid,
                max_acceleration,
                max_jerk,
            },
        )
}

fn rotary(name: char, on: Side) -> impl Strategy<Value = RotaryAxis> {
    (direction(), point(300.0), rotary_limits(), dynamics()).prop_map(
        move |(axis, center, (limits, rollover), dynamics)| RotaryAxis {
            name,
            on,
            axis,
            center,
            limits,
            rollover,
            dynamics,
        },
    )
}

/// X, Y, Z and then some of U, V, W in any order.
fn linear_axes() -> impl Strategy<Value = Vec<LinearAxis>> {
    let extra = subsequence(vec!['U', 'V', 'W'], 0..=3).prop_shuffle();
    extra.prop_flat_map(|extra| {
        let names: Vec<char> = ['X', 'Y', 'Z'].into_iter().chain(extra).collect();
        let n = names.len();
        proptest::collection::vec((limits(1000.0), dynamics()), n).prop_map(move |lims| {
            names
                .iter()
                .zip(lims)
                .map(|(&name, ((min, max), dynamics))| LinearAxis {
                    name,
                    min,
                    max,
                    dynamics,
                    along: fiveaxis_machine::Along::Parallel,
                })
                .collect()
        })
    })
}

/// Rotary axes on these sides (bed outwards), with distinct names.
fn rotary_axes(sides: Vec<Side>) -> BoxedStrategy<Vec<RotaryAxis>> {
    let n = sides.len();
    subsequence(vec!['A', 'B', 'C'], n)
        .prop_shuffle()
        .prop_flat_map(move |names| {
            let axes: Vec<_> = names
                .iter()
                .zip(&sides)
                .map(|(&name, &on)| rotary(name, on))
                .collect();
            axes
        })
        // Two rotary axes about parallel lines are refused by the machine
        // file: they do not make a 5-axis machine.
        .prop_filter("rotary axes not parallel", |axes| {
            axes.iter().enumerate().all(|(k, a)| {
                axes[..k]
                    .iter()
                    .all(|b| a.axis.cross(&b.axis).norm() > 1e-6)
            })
        })
        .boxed()
}

fn control() -> impl Strategy<Value = Control> {
    prop_oneof![
        Just(Control::Fanuc30i),
        Just(Control::Fanuc16),
        Just(Control::Mitsubishi),
        Just(Control::Mazak)
    ]
}

fn reference(count: usize) -> impl Strategy<Value = Joints> {
    proptest::collection::vec(-1000.0..1000.0f64, count).prop_map(|v| {
        let mut j = [0.0; MAX_AXES];
        j[..v.len()].copy_from_slice(&v);
        j
    })
}

fn parameters(count: usize) -> impl Strategy<Value = Parameters> {
    let frame = prop_oneof![
        Just(ProgrammingFrame::Table),
        Just(ProgrammingFrame::Workpiece)
    ];
    let choice = prop_oneof![
        Just(RotaryChoice::Shortest),
        Just(RotaryChoice::RotatingAxis),
        Just(RotaryChoice::KeepTiltSign)
    ];
    (
        (frame, any::<bool>(), reference(count), reference(count)),
        (
            any::<bool>(),
            1e-6..1.0f64,
            any::<bool>(),
            choice,
            0.0..10.0f64,
            0.0..2.0f64,
        ),
    )
        .prop_map(
            |(
                (programming_frame, tcpc_option, reference_1, reference_2),
                (
                    decimal_point_input,
                    least_input_increment,
                    tool_posture_control,
                    rotary_choice,
                    singular_zone,
                    tool_comp_3d_denominator,
                ),
            )| Parameters {
                programming_frame,
                tcpc_option,
                reference_1,
                reference_2,
                decimal_point_input,
                least_input_increment,
                tool_posture_control,
                rotary_choice,
                singular_zone,
                tool_comp_3d_denominator,
                cutter_startup_b: tool_comp_3d_denominator > 1.0,
                setup_error_table_motion: singular_zone > 5.0,
                // Inch input would change how the property tests' programs
                // read; its file round trip has a test of its own.
                input_unit: fiveaxis_machine::InputUnit::Millimetre,
                singular_cone: singular_zone,
                flip_angle: 1.0 + 100.0 * least_input_increment,
                chord_tolerance: least_input_increment,
                subroutine_path: if singular_zone > 3.0 {
                    vec!["subs".into(), "/opt/shared subs".into()]
                } else {
                    Vec::new()
                },
                tool_table: (tool_comp_3d_denominator > 2.0).then(|| "tools \"a\".tbl".into()),
                tcpc_at_start: false,
                twp_remap: false,
                twp_priority: if singular_zone > 4.0 { 2 } else { 1 },
                additional_common_variables: 0,
                // HAL pins and INI values belong to linuxcnc machines; their
                // round trip has a test of its own.
                hal_pins: Default::default(),
                ini_values: Default::default(),
            },
        )
}

/// Every function an M code of a machine with rotary axes `names` can have.
fn m_functions(names: &[char]) -> Vec<MFunction> {
    let mut all: Vec<MFunction> = [
        "rigid_tap",
        "signal",
        "tcpc_on",
        "tcpc_off",
        "stop",
        "optional_stop",
        "end",
        "spindle_cw",
        "spindle_ccw",
        "spindle_stop",
        "spindle_orient",
        "tool_change",
        "coolant_on",
        "coolant_off",
    ]
    .iter()
    .map(|w| MFunction::parse(w).expect("a function word"))
    .collect();
    for &name in names {
        all.push(MFunction::Clamp(name));
        all.push(MFunction::Unclamp(name));
    }
    all
}

/// An `[m_codes]` table for a machine with rotary axes `names`: up to eight
/// numbers in 0 to 9999 (M98 and M99 left out), any function.
fn m_codes(names: Vec<char>) -> impl Strategy<Value = MCodes> {
    let functions = m_functions(&names);
    let count = functions.len();
    proptest::collection::vec((0..=MAX_M_CODE, 0..count), 0..8).prop_map(move |entries| {
        MCodes::new(
            entries
                .into_iter()
                .filter(|(n, _)| !RESERVED_M_CODES.contains(n))
                .map(|(n, k)| (n, functions[k])),
        )
    })
}

/// A machine whose rotary axes sit on `sides`, bed outwards.
pub fn machine_on(sides: Vec<Side>) -> impl Strategy<Value = Machine> {
    let name = prop_oneof!["[ -~]{0,24}", "\\PC{0,12}"];
    (
        name,
        control(),
        direction(),
        linear_axes(),
        rotary_axes(sides),
    )
        .prop_flat_map(|(name, control, tool_direction, linear, rotary)| {
            let count = linear.len() + rotary.len();
            let names: Vec<char> = rotary.iter().map(|r| r.name).collect();
            (parameters(count), m_codes(names)).prop_map(move |(mut params, m_codes)| {
                // Reference positions inside the soft limits, as a machine
                // file must have them.
                let limits: Vec<Option<(f64, f64)>> = linear
                    .iter()
                    .map(|a| Some((a.min, a.max)))
                    .chain(rotary.iter().map(|r| r.limits.filter(|_| !r.rollover)))
                    .collect();
                for reference in [&mut params.reference_1, &mut params.reference_2] {
                    for (value, limit) in reference.iter_mut().zip(&limits) {
                        if let Some((lo, hi)) = limit {
                            *value = value.clamp(*lo, *hi);
                        }
                    }
                }
                Machine {
                    name: name.clone(),
                    control,
                    tool_direction,
                    linear: linear.clone(),
                    rotary: rotary.clone(),
                    params,
                    m_codes,
                    bodies: Vec::new(),
                    meshes: Vec::new(),
                }
            })
        })
}

/// Every arrangement of 0, 1 or 2 rotary axes.
pub fn sides() -> impl Strategy<Value = Vec<Side>> {
    use Side::{Head, Table};
    prop_oneof![
        Just(vec![]),
        Just(vec![Head]),
        Just(vec![Table]),
        Just(vec![Head, Head]),
        Just(vec![Table, Table]),
        Just(vec![Head, Table]),
        Just(vec![Table, Head]),
    ]
}

/// Any machine.
pub fn machine() -> impl Strategy<Value = Machine> {
    sides().prop_flat_map(machine_on)
}

/// Joints for `machine`: linear positions within ±500 mm, rotary angles
/// within ±400°.
pub fn joints_for(machine: &Machine) -> impl Strategy<Value = Joints> + use<> {
    let linear = machine.linear.len();
    let rotary = machine.rotary.len();
    (
        proptest::collection::vec(-500.0..500.0f64, linear),
        proptest::collection::vec(-400.0..400.0f64, rotary),
    )
        .prop_map(|(l, r)| {
            let mut j = [0.0; MAX_AXES];
            for (slot, v) in j.iter_mut().zip(l.into_iter().chain(r)) {
                *slot = v;
            }
            j
        })
}

/// A machine with joints and a tool length.
pub fn posed(
    sides: impl Strategy<Value = Vec<Side>>,
) -> impl Strategy<Value = (Machine, Joints, f64)> {
    sides.prop_flat_map(machine_on).prop_flat_map(|m| {
        let joints = joints_for(&m);
        (Just(m), joints, 0.0..300.0f64)
    })
}

/// Distance from `p` to the line through `c` along unit `a`.
pub fn distance_to_line(p: &Vec3, c: &Vec3, a: &Vec3) -> f64 {
    (p - c).cross(a).norm()
}

/// Imports the LinuxCNC configuration held in memory: `files` as (path,
/// text), the INI file first.
pub fn import_in_memory(
    files: &[(&str, &str)],
) -> Result<fiveaxis_machine::Imported, fiveaxis_machine::ImportError> {
    use std::path::{Path, PathBuf};
    let map: std::collections::BTreeMap<PathBuf, String> = files
        .iter()
        .map(|(p, t)| (PathBuf::from(p), (*t).to_owned()))
        .collect();
    fiveaxis_machine::import_linuxcnc(Path::new(files[0].0), &mut |p: &Path| {
        map.get(p)
            .cloned()
            .ok_or_else(|| std::io::Error::from(std::io::ErrorKind::NotFound))
    })
}
