//! LinuxCNC's switchable kinematics on a `control = "linuxcnc"` machine
//! (`motion/switchkins.adoc`, `motion/5-axis-kinematics.adoc`): the M codes
//! declared `tcpc_on` / `tcpc_off` (M428 / M429 in the sim configurations)
//! switch between identity kinematics and the TCP kinematics, and G43 /
//! G49 keep their own meaning in both. Checked with forward kinematics:
//! the tip of the tool on the table where the program puts it.

mod common;

use fiveaxis_machine::{Joints, Machine, Offsets, ToolOffset};

const EPS: f64 = 1e-9;

/// The xyzbc-trt sim machine as `machines import` writes it: B tilting
/// table about a line x-offset −20, z-offset −15 from the C table's centre
/// line, C rotary table on it, both turning right-handed for +θ.
fn machine() -> Machine {
    Machine::from_toml(&machine_text()).expect("the machine file reads")
}

fn machine_text() -> String {
    r#"
name = "xyzbc-trt"
type = "table"
control = "linuxcnc"
[[linear]]
name = "X"
min = -200.0
max = 200.0
[[linear]]
name = "Y"
min = -200.0
max = 200.0
[[linear]]
name = "Z"
min = -300.0
max = 300.0
[[rotary]]
name = "B"
on = "table"
axis = [0.0, 1.0, 0.0]
center = [-20.0, 0.0, -15.0]
min = -120.0
max = 120.0
[[rotary]]
name = "C"
on = "table"
axis = [0.0, 0.0, 1.0]
center = [0.0, 0.0, 0.0]
min = -36000.0
max = 36000.0
[parameters]
decimal_point_input = true
[m_codes]
428 = "tcpc_on"
429 = "tcpc_off"
"#
    .to_owned()
}

/// Tool 1: 100 mm.
fn offsets() -> Offsets {
    let mut o = Offsets::default();
    o.tools.insert(
        1,
        ToolOffset {
            length: 100.0,
            ..ToolOffset::default()
        },
    );
    o
}

/// The machine position at the end of each line, and the alarm if any.
fn run_program(program: &str) -> (Vec<(u32, Joints)>, Option<String>) {
    let m = machine();
    let out = common::run(&m, offsets(), program);
    let ends = out.segments.iter().map(|s| (s.line, s.end)).collect();
    (ends, out.alarm.map(|a| a.to_string()))
}

fn end_of(ends: &[(u32, Joints)], line: u32) -> Joints {
    ends.iter()
        .rev()
        .find(|(l, _)| *l == line)
        .unwrap_or_else(|| panic!("no segment of line {line}"))
        .1
}

fn assert_tip(joints: &Joints, length: f64, want: [f64; 3]) {
    let tip = machine().forward(joints, length).tip;
    for i in 0..3 {
        assert!((tip[i] - want[i]).abs() < EPS, "tip {tip:?}, want {want:?}");
    }
}

#[test]
fn g43_under_the_tcp_kinematics_changes_the_length_and_stays_tcp() {
    // boat-xyzbc.ngc's order: M428 first, then G43 H1 with a Z move. The
    // length changes with the table level, as LinuxCNC wants it (its TCP
    // kinematics jump when the tool offset changes on a tilted table).
    let (ends, alarm) = run_program(
        "G90 G0 X0 Y0 Z50 B0 C0\nM428\nG43 H1 Z5.\nG0 X10. Y5. B-30. C45.\nG1 X12. F100\nG0 B0 C0\nG49 Z20.\nM429\nM30\n",
    );
    assert_eq!(alarm, None);
    // Lines 3 to 6: TCP with the 100 mm tool, its tip where programmed on
    // the table.
    assert_tip(&end_of(&ends, 3), 100.0, [0.0, 0.0, 5.0]);
    let j = end_of(&ends, 4);
    assert_tip(&j, 100.0, [10.0, 5.0, 5.0]);
    assert_eq!((j[3], j[4]), (-30.0, 45.0));
    assert_tip(&end_of(&ends, 5), 100.0, [12.0, 5.0, 5.0]);
    assert_tip(&end_of(&ends, 6), 100.0, [12.0, 5.0, 5.0]);
    // Line 7: G49 under TCP: length 0, still TCP.
    assert_tip(&end_of(&ends, 7), 0.0, [12.0, 5.0, 20.0]);
}

#[test]
fn the_tcp_frame_is_the_table_at_rotary_zero() {
    // xyzac_switchkins_test_3.ngc on a B/C machine: joints X10 Y0 Z2 C90
    // are the tip at 0 -10 2 on the table (C turns the table +90°); after
    // M428, programming that point moves nothing.
    let (ends, alarm) =
        run_program("G90 G0 X10 Y0 Z2 B0 C90\nM428\nG1 X0 Y-10 Z2 F100\nZ0\nM429\nM30\n");
    assert_eq!(alarm, None);
    // The switch itself moves nothing (LinuxCNC synchronises with M66),
    // nor does line 3, which programs the point the tip is at.
    assert!(
        ends.iter().all(|(line, _)| *line != 2 && *line != 3),
        "{ends:?}"
    );
    let j = end_of(&ends, 1);
    for (got, want) in j.iter().zip([10.0, 0.0, 2.0, 0.0, 90.0]) {
        assert!((got - want).abs() < EPS, "{j:?}");
    }
    assert_tip(&end_of(&ends, 4), 0.0, [0.0, -10.0, 0.0]);
}

#[test]
fn identity_kinematics_keep_g43s_length_offset() {
    // G43 H1 under the TCP kinematics, then M429: the length offset stays
    // in force as LinuxCNC's interpreter keeps it (a Z shift of 100).
    let (ends, alarm) =
        run_program("G90 G0 X0 Y0 Z0 B0 C0\nG43 H1 Z10.\nM428\nM429\nG0 Z20.\nG49 Z30.\nM30\n");
    assert_eq!(alarm, None);
    assert_eq!(end_of(&ends, 2)[2], 110.0);
    assert_eq!(end_of(&ends, 5)[2], 120.0);
    assert_eq!(end_of(&ends, 6)[2], 30.0);
    // G43 without a move moves nothing; the next move takes the length.
    let (moves, alarm) = run_program("G90 G0 X0 Y0 Z0 B0 C0\nG43 H1\nG0 Z10.\nM30\n");
    assert_eq!(alarm, None);
    assert!(moves.iter().all(|(line, _)| *line != 2), "{moves:?}");
    assert_eq!(end_of(&moves, 3)[2], 110.0);
}

#[test]
fn other_length_codes_are_refused_under_the_tcp_kinematics() {
    let (_, alarm) = run_program("M428\nG44 H1\nM30\n");
    let alarm = alarm.expect("an alarm");
    assert!(alarm.contains("G44"), "{alarm}");
    let (_, alarm) = run_program("M428 M429\nM30\n");
    assert!(alarm.expect("an alarm").contains("both switch"));
}

#[test]
fn tcpc_at_start_runs_the_tcp_kinematics_from_the_first_block() {
    // A configuration without a kinematics switch (gmoccapy xyzac-trt):
    // LinuxCNC is in TCP mode from power-on.
    let text = machine_text().replace("[parameters]", "[parameters]\ntcpc_at_start = true");
    let m = Machine::from_toml(&text).expect("reads");
    assert!(m.params.tcpc_at_start);
    let out = common::run(
        &m,
        offsets(),
        "G90 G0 X10 Y5 Z20 B-30 C45\nG0 B0 C0\nG43 H1 Z5.\nG0 B-30 C45\nM30\n",
    );
    assert!(out.alarm.is_none(), "{:?}", out.alarm);
    let last = |line: u32| {
        out.segments
            .iter()
            .rev()
            .find(|s| s.line == line)
            .map(|s| s.end)
            .expect("a segment")
    };
    let tip = m.forward(&last(1), 0.0).tip;
    assert!(
        (tip - fiveaxis_machine::Vec3::new(10.0, 5.0, 20.0)).norm() < EPS,
        "{tip:?}"
    );
    let tip = m.forward(&last(4), 100.0).tip;
    assert!(
        (tip - fiveaxis_machine::Vec3::new(10.0, 5.0, 5.0)).norm() < EPS,
        "{tip:?}"
    );
    // Only a linuxcnc machine takes the key.
    let fanuc = text.replace("control = \"linuxcnc\"", "control = \"fanuc30i\"");
    let e = Machine::from_toml(&fanuc).expect_err("refused");
    assert_eq!(e.key.as_deref(), Some("tcpc_at_start"), "{e}");
}
