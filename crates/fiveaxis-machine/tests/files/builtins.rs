//! The built-in machines, and writing machines back as files.

use fiveaxis_machine::{
    DEFAULT_MACHINE, Machine, MachineType, Side, Vec3, builtin, builtin_names, builtin_source,
};
use proptest::prelude::*;

use crate::common;

fn machine(name: &str) -> Machine {
    builtin(name).unwrap_or_else(|| panic!("no built-in machine {name}"))
}

#[test]
fn library_lists_every_machine_and_the_default() {
    let names = builtin_names();
    assert_eq!(
        names,
        [
            "trunnion-ac",
            "trunnion-bc",
            "head-table-bc",
            "head-head-ca",
            "mill-3axis",
            "haas-umc750",
            "haas-vf2-tr160",
            "sinumerik-dmu-bc",
            "heidenhain-dmu-ac"
        ]
    );
    assert!(names.contains(&DEFAULT_MACHINE));
    assert!(builtin("no-such-machine").is_none());
    assert!(builtin_source("no-such-machine").is_none());
}

/// The built-ins of the FANUC 30i (the Haas and SINUMERIK machines are
/// tested below).
fn fanuc_builtins() -> impl Iterator<Item = &'static str> {
    builtin_names()
        .iter()
        .copied()
        .filter(|n| machine(n).control == fiveaxis_machine::Control::Fanuc30i)
}

#[test]
fn every_builtin_reads_with_a_name_and_fanuc_30i() {
    for name in fanuc_builtins() {
        let m = machine(name);
        assert!(m.name.len() > 10, "{name}: {:?}", m.name);
        assert_eq!(m.control, fiveaxis_machine::Control::Fanuc30i);
        assert_eq!(m.tool_direction.into_inner(), Vec3::z());
        let limits: Vec<(char, f64, f64)> =
            m.linear.iter().map(|a| (a.name, a.min, a.max)).collect();
        assert_eq!(
            limits,
            [
                ('X', -500.0, 500.0),
                ('Y', -400.0, 400.0),
                ('Z', -300.0, 500.0)
            ]
        );
        // A program starts at the top of Z travel (the reference
        // positions), the spindle nose 500 mm above the table face (Z 0).
        let z = m.axis_index('Z').expect("Z");
        for reference in [m.params.reference_1, m.params.reference_2] {
            assert_eq!(reference[z], m.linear[z].max, "{name}");
            assert_eq!(reference[z], 500.0, "{name}");
        }
    }
}

#[test]
fn reference_position_1_is_inside_every_limit() {
    for name in builtin_names() {
        let m = machine(name);
        let r = &m.params.reference_1;
        for (i, a) in m.linear.iter().enumerate() {
            assert!(a.min <= r[i] && r[i] <= a.max, "{name} {}", a.name);
        }
        for (k, a) in m.rotary.iter().enumerate() {
            if let Some((lo, hi)) = a.limits {
                let v = r[m.rotary_index(k)];
                assert!(lo <= v && v <= hi, "{name} {}", a.name);
            }
        }
    }
}

/// (name, side, axis, center, limits) of each rotary axis.
type Rotary = (char, Side, [f64; 3], [f64; 3], Option<(f64, f64)>);

fn rotary(m: &Machine) -> Vec<Rotary> {
    m.rotary
        .iter()
        .map(|a| {
            (
                a.name,
                a.on,
                a.axis.into_inner().into(),
                a.center.into(),
                a.limits,
            )
        })
        .collect()
}

#[test]
fn builtin_geometry() {
    use Side::{Head, Table};
    let cases: [(&str, MachineType, Vec<Rotary>); 5] = [
        (
            "trunnion-ac",
            MachineType::Table,
            vec![
                (
                    'A',
                    Table,
                    [-1.0, 0.0, 0.0],
                    [0.0, 0.0, -100.0],
                    Some((-120.0, 30.0)),
                ),
                ('C', Table, [0.0, 0.0, -1.0], [0.0; 3], None),
            ],
        ),
        (
            "trunnion-bc",
            MachineType::Table,
            vec![
                (
                    'B',
                    Table,
                    [0.0, -1.0, 0.0],
                    [0.0, 0.0, -100.0],
                    Some((-120.0, 120.0)),
                ),
                ('C', Table, [0.0, 0.0, -1.0], [0.0; 3], None),
            ],
        ),
        (
            "head-table-bc",
            MachineType::Mixed,
            vec![
                (
                    'B',
                    Head,
                    [0.0, 1.0, 0.0],
                    [0.0, 0.0, 150.0],
                    Some((-110.0, 110.0)),
                ),
                ('C', Table, [0.0, 0.0, -1.0], [0.0; 3], None),
            ],
        ),
        (
            "head-head-ca",
            MachineType::Head,
            vec![
                (
                    'C',
                    Head,
                    [0.0, 0.0, 1.0],
                    [0.0, 0.0, 150.0],
                    Some((-360.0, 360.0)),
                ),
                (
                    'A',
                    Head,
                    [1.0, 0.0, 0.0],
                    [0.0, 0.0, 150.0],
                    Some((-110.0, 110.0)),
                ),
            ],
        ),
        ("mill-3axis", MachineType::None, vec![]),
    ];
    for (name, kind, axes) in cases {
        let m = machine(name);
        assert_eq!(m.machine_type(), kind, "{name}");
        assert_eq!(rotary(&m), axes, "{name}");
        let rollover: Vec<bool> = m.rotary.iter().map(|a| a.rollover).collect();
        let expected: Vec<bool> = axes.iter().map(|a| a.4.is_none()).collect();
        assert_eq!(rollover, expected, "{name}");
    }
}

#[test]
fn every_builtin_round_trips() {
    for name in builtin_names() {
        let m = machine(name);
        let text = m.to_toml();
        let back = Machine::from_toml(&text).unwrap_or_else(|e| panic!("{name}: {e}\n{text}"));
        assert_eq!(back, m, "{name}");
    }
}

#[test]
fn written_file_explains_its_keys() {
    let text = machine(DEFAULT_MACHINE).to_toml();
    for key in [
        "name",
        "type",
        "control",
        "tool_direction",
        "min",
        "max",
        "on",
        "axis",
        "center",
        "rollover",
    ] {
        let line = text
            .lines()
            .find(|l| l.starts_with(&format!("{key} = ")))
            .unwrap_or_else(|| panic!("no `{key}` in\n{text}"));
        assert!(line.contains(" # "), "`{key}` has no comment: {line}");
    }
    assert!(text.contains("[parameters]"));
    assert!(text.contains("reference_1 = { X = 0.0, Y = 0.0, Z = 500.0, A = 0.0, C = 0.0 }"));
}

#[test]
fn decimal_point_input_is_explained_the_right_way_round() {
    let mut m = machine(DEFAULT_MACHINE);
    let line = |m: &Machine| {
        m.to_toml()
            .lines()
            .find(|l| l.starts_with("decimal_point_input = "))
            .map(str::to_owned)
            .unwrap_or_default()
    };
    assert!(!m.params.decimal_point_input);
    assert!(
        line(&m).ends_with(
            "# off: a number without a point is in least input increments (X10 = 0.010 mm)"
        ),
        "{}",
        line(&m)
    );
    m.params.least_input_increment = 0.0001;
    assert!(line(&m).contains("(X10 = 0.0010 mm)"), "{}", line(&m));
    m.params.decimal_point_input = true;
    assert!(
        line(&m).ends_with("# on: a number without a point is mm/degrees (X10 = 10 mm)"),
        "{}",
        line(&m)
    );
}

#[test]
fn unlimited_axis_round_trips() {
    let mut m = machine("head-table-bc");
    m.rotary[0].limits = None;
    m.params.reference_2[4] = 12.5;
    m.name = "quote \" backslash \\ tab\t new line\n 'single' é".to_owned();
    let back = Machine::from_toml(&m.to_toml()).expect("reads back");
    assert_eq!(back, m);
}

proptest! {
    #![proptest_config(common::config(256))]

    /// Any machine reads back from its own file unchanged.
    #[test]
    fn random_machines_round_trip(m in common::machine()) {
        let text = m.to_toml();
        let back = Machine::from_toml(&text);
        prop_assert_eq!(back, Ok(m), "{}", text);
    }
}

#[test]
fn builtin_m_codes_clamp_the_rotary_axes_in_file_order() {
    use fiveaxis_machine::MFunction as F;
    for name in fanuc_builtins() {
        let m = machine(name);
        let t = &m.m_codes;
        assert_eq!(t.get(0), Some(F::Stop), "{name}");
        assert_eq!(t.get(1), Some(F::OptionalStop), "{name}");
        assert_eq!(t.get(6), Some(F::ToolChange), "{name}");
        assert_eq!(t.get(19), Some(F::SpindleOrient), "{name}");
        assert_eq!(t.get(29), Some(F::RigidTap), "{name}");
        assert_eq!(t.get(30), Some(F::End), "{name}");
        // The fourth axis (first rotary) on M10/M11, the fifth on M12/M13.
        for (k, axis) in m.rotary.iter().enumerate() {
            let n = 10 + 2 * u16::try_from(k).expect("small");
            assert_eq!(t.get(n), Some(F::Clamp(axis.name)), "{name}");
            assert_eq!(t.get(n + 1), Some(F::Unclamp(axis.name)), "{name}");
        }
        if m.rotary.is_empty() {
            assert_eq!(t.get(10), None, "{name}");
        }
    }
}

#[test]
fn haas_builtins_have_the_published_strokes_and_the_control_s_m_codes() {
    use fiveaxis_machine::{Control, InputUnit};
    let strokes = |m: &Machine| -> Vec<(char, f64, f64)> {
        m.linear.iter().map(|a| (a.name, a.min, a.max)).collect()
    };
    let umc = machine("haas-umc750");
    assert_eq!(umc.control, Control::Haas);
    assert_eq!(umc.params.input_unit, InputUnit::Inch);
    assert_eq!(umc.machine_type(), MachineType::Table);
    // X 30 in, Y 20 in, Z 20 in, all negative from home.
    assert_eq!(
        strokes(&umc),
        [('X', -762.0, 0.0), ('Y', -508.0, 0.0), ('Z', -508.0, 0.0)]
    );
    let names: Vec<char> = umc.rotary.iter().map(|r| r.name).collect();
    assert_eq!(names, ['B', 'C']);
    assert_eq!(umc.rotary[0].limits, Some((-35.0, 120.0)));
    assert!(umc.rotary[1].rollover && umc.rotary[1].limits.is_none());
    let vf = machine("haas-vf2-tr160");
    assert_eq!(vf.control, Control::Haas);
    assert_eq!(vf.params.input_unit, InputUnit::Inch);
    // X 30 in, Y 16 in, Z 20 in.
    assert_eq!(
        strokes(&vf),
        [('X', -762.0, 0.0), ('Y', -406.0, 0.0), ('Z', -508.0, 0.0)]
    );
    let names: Vec<char> = vf.rotary.iter().map(|r| r.name).collect();
    assert_eq!(names, ['A', 'B']);
    assert_eq!(vf.rotary[0].limits, Some((-120.0, 120.0)));
    assert!(vf.rotary[1].rollover);
    // No [m_codes] table: the control's standard set (M10-M13 brakes)
    // applies (crates/fiveaxis-control/tests/haas_functions.rs).
    for m in [&umc, &vf] {
        assert_eq!(m.m_codes.get(10), None);
        // Home is reference position 1 and inside every stroke.
        assert!(m.params.reference_1.iter().all(|v| *v == 0.0));
    }
}

#[test]
fn sinumerik_builtin_is_a_45_degree_head_with_a_table_and_the_control_s_m_codes() {
    use fiveaxis_machine::{Control, MFunction as F};
    let m = machine("sinumerik-dmu-bc");
    assert_eq!(m.control, Control::Sinumerik);
    assert_eq!(m.machine_type(), MachineType::Mixed);
    let b = &m.rotary[0];
    assert_eq!(
        (b.name, b.on, b.limits),
        ('B', Side::Head, Some((-5.0, 180.0)))
    );
    let half = std::f64::consts::FRAC_1_SQRT_2;
    assert!((b.axis.into_inner() - Vec3::new(0.0, half, half)).norm() < 1e-15);
    let c = &m.rotary[1];
    assert_eq!((c.name, c.on, c.rollover), ('C', Side::Table, true));
    // The linear axes and reference positions of the FANUC built-ins.
    assert_eq!(m.linear, machine("head-table-bc").linear);
    assert_eq!(m.params.reference_1[2], 500.0);
    let t = &m.m_codes;
    for (n, f) in [
        (0, F::Stop),
        (1, F::OptionalStop),
        (2, F::End),
        (3, F::SpindleCw),
        (4, F::SpindleCcw),
        (5, F::SpindleStop),
        (6, F::ToolChange),
        (8, F::CoolantOn),
        (9, F::CoolantOff),
        (30, F::End),
    ] {
        assert_eq!(t.get(n), Some(f), "M{n}");
    }
    // M17 ends a subprogram in the language; no clamps, no M19, no M29.
    assert_eq!(t.len(), 10);
}
