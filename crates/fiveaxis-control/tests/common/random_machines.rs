//! Random five-axis machines for the front ends' kinematic properties:
//! two rotary axes in each arrangement (table/table, head/table,
//! table/head, head/head), lines through points within ±300 mm in any
//! direction, no rotary limits, random rollover, linear travel ±1e6 mm,
//! the tool along +Z. A test includes it beside the machine crate's
//! generators (`mod machine_gen`), as `mod random_machines`.

use fiveaxis_machine::{
    Control, Dynamics, LinearAxis, MCodes, Machine, Parameters, RotaryAxis, Side, Vec3,
};
use proptest::prelude::*;
use proptest::sample::subsequence;

// The including test's `machine_gen`: the machine crate's generators.
use super::machine_gen::{direction, point};

/// X, Y, Z travelling ±`limit`.
pub fn linear_axes(limit: f64) -> Vec<LinearAxis> {
    ['X', 'Y', 'Z']
        .into_iter()
        .map(|name| LinearAxis {
            name,
            min: -limit,
            max: limit,
            dynamics: Dynamics::LINEAR_DEFAULT,
            along: fiveaxis_machine::Along::Parallel,
        })
        .collect()
}

/// The four arrangements of two rotary axes.
pub fn two_sides() -> impl Strategy<Value = [Side; 2]> {
    use Side::{Head, Table};
    prop_oneof![
        Just([Table, Table]),
        Just([Head, Table]),
        Just([Table, Head]),
        Just([Head, Head]),
    ]
}

/// A five-axis machine of `control` with random rotary geometry.
pub fn five_axis(control: Control, name: &'static str) -> impl Strategy<Value = Machine> {
    let names = subsequence(vec!['A', 'B', 'C'], 2).prop_shuffle();
    let axis = || (direction(), point(300.0), any::<bool>());
    (two_sides(), names, axis(), axis()).prop_map(move |(sides, names, a0, a1)| {
        let rotary = [(a0, sides[0], names[0]), (a1, sides[1], names[1])]
            .into_iter()
            .map(|((axis, center, rollover), on, name)| RotaryAxis {
                name,
                on,
                axis,
                center,
                limits: None,
                rollover,
                dynamics: Dynamics::ROTARY_DEFAULT,
            })
            .collect();
        Machine {
            name: name.into(),
            control,
            tool_direction: Vec3::z_axis(),
            linear: linear_axes(1e6),
            rotary,
            params: Parameters::default(),
            m_codes: MCodes::default(),
            bodies: Vec::new(),
            meshes: Vec::new(),
        }
    })
}
