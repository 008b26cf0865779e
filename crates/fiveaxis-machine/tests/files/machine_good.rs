//! Machine files that read, and what they read as.

use fiveaxis_machine::{Control, Machine, MachineType, Parameters, ProgrammingFrame, Side, Vec3};

/// X, Y, Z with limits that differ per axis, so that each text is unique.
pub const XYZ: &str = r#"
[[linear]]
name = "X"
min = -100.0
max = 100.0

[[linear]]
name = "Y"
min = -200.0
max = 200.0

[[linear]]
name = "Z"
min = -300.0
max = 300.0
"#;

/// A machine file: `top` keys after `name`, then X, Y, Z, then `rest`.
pub fn file(top: &str, rest: &str) -> String {
    format!("name = \"test\"\n{top}{XYZ}{rest}")
}

/// A table C axis, for files that need one rotary axis.
pub const TABLE_C: &str = r#"
[[rotary]]
name = "C"
on = "table"
axis = [0, 0, -1]
center = [0, 0, 0]
rollover = true
"#;

pub fn read(text: &str) -> Machine {
    Machine::from_toml(text).unwrap_or_else(|e| panic!("{e}\nin\n{text}"))
}

#[test]
fn minimal_three_axis_file_takes_defaults() {
    let m = read(&file("type = \"none\"\n", ""));
    assert_eq!(m.name, "test");
    assert_eq!(m.control, Control::Fanuc30i);
    assert_eq!(m.tool_direction.into_inner(), Vec3::z());
    assert_eq!(m.machine_type(), MachineType::None);
    assert_eq!(m.params, Parameters::default());
    let names: Vec<char> = m.axis_names().collect();
    assert_eq!(names, ['X', 'Y', 'Z']);
    assert_eq!((m.linear[1].min, m.linear[1].max), (-200.0, 200.0));
}

#[test]
fn integers_are_numbers() {
    let text = file(
        "type = \"table\"\ntool_direction = [0, 0, 1]\n",
        "[[rotary]]\nname = \"A\"\non = \"table\"\naxis = [-1, 0, 0]\ncenter = [0, 0, -100]\nmin = -120\nmax = 30\n",
    );
    let m = read(&text);
    let a = &m.rotary[0];
    assert_eq!(a.axis.into_inner(), Vec3::new(-1.0, 0.0, 0.0));
    assert_eq!(a.center, Vec3::new(0.0, 0.0, -100.0));
    assert_eq!(a.limits, Some((-120.0, 30.0)));
    assert!(!a.rollover);
}

#[test]
fn directions_are_normalised() {
    let text = file(
        "type = \"head\"\ntool_direction = [0, 0, 2.5]\n",
        "[[rotary]]\nname = \"B\"\non = \"head\"\naxis = [0, 3, 4]\ncenter = [0, 0, 150]\n",
    );
    let m = read(&text);
    assert_eq!(m.tool_direction.into_inner(), Vec3::z());
    assert!((m.rotary[0].axis.into_inner() - Vec3::new(0.0, 0.6, 0.8)).norm() < 1e-15);
}

#[test]
fn every_control_reads() {
    for (word, control) in [
        ("fanuc30i", Control::Fanuc30i),
        ("fanuc16", Control::Fanuc16),
        ("mitsubishi", Control::Mitsubishi),
        ("mazak", Control::Mazak),
    ] {
        let m = read(&file(
            &format!("type = \"none\"\ncontrol = \"{word}\"\n"),
            "",
        ));
        assert_eq!(m.control, control);
    }
}

#[test]
fn parallel_axes_follow_xyz() {
    let text = file(
        "type = \"none\"\n",
        "[[linear]]\nname = \"W\"\nmin = 0\nmax = 400\n\n[[linear]]\nname = \"U\"\nmin = -1\nmax = 1\n",
    );
    let m = read(&text);
    let names: Vec<(char, char)> = m.linear.iter().map(|a| (a.name, a.parallel_to())).collect();
    assert_eq!(
        names,
        [('X', 'X'), ('Y', 'Y'), ('Z', 'Z'), ('W', 'Z'), ('U', 'X')]
    );
}

#[test]
fn eight_axes_fit() {
    let uvw = ["U", "V", "W"]
        .map(|n| format!("[[linear]]\nname = \"{n}\"\nmin = -1\nmax = 1\n\n"))
        .concat();
    let rotary = "[[rotary]]\nname = \"A\"\non = \"table\"\naxis = [1, 0, 0]\ncenter = [0, 0, 0]\n";
    let m = read(&file(
        "type = \"table\"\n",
        &format!("{uvw}{rotary}{TABLE_C}"),
    ));
    assert_eq!(m.axis_count(), fiveaxis_machine::MAX_AXES);
}

#[test]
fn rotary_limits_rollover_and_unlimited() {
    let unlimited = "[[rotary]]\nname = \"A\"\non = \"table\"\naxis = [1, 0, 0]\ncenter = [0, 0, 0]\nrollover = false\n";
    let m = read(&file(
        "type = \"table\"\n",
        &format!("{unlimited}{TABLE_C}"),
    ));
    assert_eq!((m.rotary[0].limits, m.rotary[0].rollover), (None, false));
    assert_eq!((m.rotary[1].limits, m.rotary[1].rollover), (None, true));
}

#[test]
fn machine_types_follow_the_sides() {
    let head_b =
        "[[rotary]]\nname = \"B\"\non = \"head\"\naxis = [0, 1, 0]\ncenter = [0, 0, 150]\n";
    let table_a =
        "[[rotary]]\nname = \"A\"\non = \"table\"\naxis = [1, 0, 0]\ncenter = [0, 0, 0]\n";
    let cases = [
        ("head", head_b.to_owned(), MachineType::Head),
        ("table", table_a.to_owned(), MachineType::Table),
        ("mixed", format!("{head_b}{TABLE_C}"), MachineType::Mixed),
        ("mixed", format!("{TABLE_C}{head_b}"), MachineType::Mixed),
        ("table", format!("{table_a}{TABLE_C}"), MachineType::Table),
    ];
    for (word, rotary, kind) in cases {
        let m = read(&file(&format!("type = \"{word}\"\n"), &rotary));
        assert_eq!(m.machine_type(), kind);
    }
}

#[test]
fn parameters_read() {
    let params = r#"
[parameters]
programming_frame = "workpiece"
tcpc_option = false
reference_1 = { Z = 250, C = 90.5 }
reference_2 = { X = -10.0, Y = 20.0, Z = 30.0, C = 0 }
decimal_point_input = true
least_input_increment = 0.0001
"#;
    let m = read(&file("type = \"table\"\n", &format!("{TABLE_C}{params}")));
    let p = &m.params;
    assert_eq!(p.programming_frame, ProgrammingFrame::Workpiece);
    assert!(!p.tcpc_option);
    assert!(p.decimal_point_input);
    assert_eq!(p.least_input_increment, 0.0001);
    assert_eq!(p.reference_1[..4], [0.0, 0.0, 250.0, 90.5]);
    assert_eq!(p.reference_2[..4], [-10.0, 20.0, 30.0, 0.0]);
    assert!(p.reference_1[4..].iter().all(|&v| v == 0.0));
}

#[test]
fn parameters_table_may_be_empty() {
    let m = read(&file(
        "type = \"table\"\n",
        &format!("{TABLE_C}\n[parameters]\n"),
    ));
    assert_eq!(m.params, Parameters::default());
    assert_eq!(m.rotary[0].on, Side::Table);
}

#[test]
fn comments_and_key_order_do_not_matter() {
    let text = "# a comment\ntype = \"none\" # trailing\nname = \"m\"\n\n[[linear]]\nmax = 1\nmin = 0\nname = \"X\"\n\
                [[linear]]\nname = \"Y\"\nmin = 0\nmax = 1\n[[linear]]\nname = \"Z\"\nmin = 0\nmax = 1\n";
    let m = read(text);
    assert_eq!(
        (m.linear[0].name, m.linear[0].min, m.linear[0].max),
        ('X', 0.0, 1.0)
    );
}

#[test]
fn spec_example_reads() {
    let text = r#"
name = "Generic A/C trunnion"
type = "table"
control = "fanuc30i"
tool_direction = [0, 0, 1]

[[linear]]
name = "X"
min = -400.0
max = 400.0

[[linear]]
name = "Y"
min = -400.0
max = 400.0

[[linear]]
name = "Z"
min = -400.0
max = 400.0

[[rotary]]
name = "A"
on = "table"
axis = [-1, 0, 0]
center = [0, 0, -100]
min = -120.0
max = 30.0

[[rotary]]
name = "C"
on = "table"
axis = [0, 0, -1]
center = [0, 0, 0]
rollover = true

[parameters]
programming_frame = "table"
tcpc_option = true
reference_1 = { X = 0.0, Y = 0.0, Z = 0.0, A = 0.0, C = 0.0 }
reference_2 = { X = 0.0, Y = 0.0, Z = 0.0, A = 0.0, C = 0.0 }
"#;
    let m = read(text);
    assert_eq!(m.name, "Generic A/C trunnion");
    assert_eq!(m.axis_names().collect::<String>(), "XYZAC");
}

#[test]
fn m_codes_table_reads_every_function() {
    use fiveaxis_machine::MFunction as F;
    let text = file(
        "type = \"table\"\n",
        &format!(
            "{TABLE_C}\n[m_codes]\n12 = \"clamp C\"\n13 = \"unclamp C\"\n29 = \"rigid_tap\"\n50 = \"signal\"\n\
             128 = \"tcpc_on\"\n129 = \"tcpc_off\"\n0 = \"stop\"\n1 = \"optional_stop\"\n2 = \"end\"\n\
             3 = \"spindle_cw\"\n4 = \"spindle_ccw\"\n5 = \"spindle_stop\"\n19 = \"spindle_orient\"\n\
             6 = \"tool_change\"\n8 = \"coolant_on\"\n9 = \"coolant_off\"\n9999 = \"signal\"\n"
        ),
    );
    let m = read(&text);
    let got: Vec<(u16, F)> = m.m_codes.iter().collect();
    assert_eq!(
        got,
        [
            (0, F::Stop),
            (1, F::OptionalStop),
            (2, F::End),
            (3, F::SpindleCw),
            (4, F::SpindleCcw),
            (5, F::SpindleStop),
            (6, F::ToolChange),
            (8, F::CoolantOn),
            (9, F::CoolantOff),
            (12, F::Clamp('C')),
            (13, F::Unclamp('C')),
            (19, F::SpindleOrient),
            (29, F::RigidTap),
            (50, F::Signal),
            (128, F::TcpcOn),
            (129, F::TcpcOff),
            (9999, F::Signal),
        ]
    );
    // Written back, the table reads the same.
    assert_eq!(read(&m.to_toml()), m);
}

#[test]
fn no_m_codes_table_is_an_empty_table() {
    let m = read(&file("type = \"none\"\n", ""));
    assert!(m.m_codes.is_empty());
    assert!(m.to_toml().contains("[m_codes]"));
    assert_eq!(read(&m.to_toml()), m);
}

#[test]
fn dynamics_default_when_absent_and_rapid_follows_max_velocity() {
    use fiveaxis_machine::Dynamics;
    let m = read(&file("type = \"table\"\n", TABLE_C));
    assert_eq!(m.linear[0].dynamics, Dynamics::LINEAR_DEFAULT);
    assert_eq!(m.rotary[0].dynamics, Dynamics::ROTARY_DEFAULT);
    let text = file(
        "type = \"table\"\n",
        &format!("{TABLE_C}max_velocity = 7200.0\nmax_acceleration = 900\nmax_jerk = 20000.0\n"),
    );
    let c = read(&text).rotary[0].dynamics;
    assert_eq!(
        c,
        Dynamics {
            max_velocity: 7200.0,
            rapid: 7200.0,
            max_acceleration: 900.0,
            max_jerk: Some(20000.0),
        }
    );
}

#[test]
fn check_parameters_read_and_default() {
    let m = read(&file("type = \"none\"\n", ""));
    assert_eq!(
        (
            m.params.singular_cone,
            m.params.flip_angle,
            m.params.chord_tolerance
        ),
        (2.0, 90.0, 0.01)
    );
    let m = read(&file(
        "type = \"none\"\n",
        "[parameters]\nsingular_cone = 5.0\nflip_angle = 170.0\nchord_tolerance = 0.002\n",
    ));
    assert_eq!(
        (
            m.params.singular_cone,
            m.params.flip_angle,
            m.params.chord_tolerance
        ),
        (5.0, 170.0, 0.002)
    );
}

#[test]
fn builtin_machines_have_their_own_dynamics_and_write_them_back() {
    use fiveaxis_machine::{Dynamics, builtin, builtin_names};
    for name in builtin_names() {
        let m = builtin(name).expect("built in");
        for axis in &m.linear {
            assert_ne!(
                axis.dynamics,
                Dynamics::LINEAR_DEFAULT,
                "{name} {}",
                axis.name
            );
            assert!(axis.dynamics.rapid >= axis.dynamics.max_velocity);
        }
        for axis in &m.rotary {
            assert_ne!(
                axis.dynamics,
                Dynamics::ROTARY_DEFAULT,
                "{name} {}",
                axis.name
            );
        }
        assert_eq!(read(&m.to_toml()), m, "{name}");
    }
}
