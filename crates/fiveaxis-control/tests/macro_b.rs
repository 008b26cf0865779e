//! Custom macro B run by the runner: control flow where the program text
//! is (GOTO, IF, WHILE … DO … END, G65 calls with arguments), system
//! variables read from and written to the controller, and the alarms.
//! Positions are checked against closed forms.

mod common;

use common::builtin_at_zero;
use fiveaxis_control::{Alarm, Row};
use fiveaxis_machine::{DEFAULT_MACHINE, Machine, Offsets, ToolOffset};

fn machine() -> Machine {
    builtin_at_zero(DEFAULT_MACHINE).expect("built in")
}

fn run(program: &str) -> (Vec<Row>, Option<Alarm>) {
    let mut offsets = Offsets::default();
    offsets.tools.insert(
        1,
        ToolOffset {
            length: 100.0,
            length_wear: -0.5,
            radius: 5.0,
            ..ToolOffset::default()
        },
    );
    common::run_ends(&machine(), offsets, program)
}

fn xy(rows: &[Row]) -> Vec<(u32, f64, f64)> {
    rows.iter().map(|r| (r.line, r.tip.x, r.tip.y)).collect()
}

/// Line and tool tip of every row.
fn tips(rows: &[Row]) -> Vec<(u32, f64, f64, f64)> {
    rows.iter()
        .map(|r| (r.line, r.tip.x, r.tip.y, r.tip.z))
        .collect()
}

fn code(alarm: &Option<Alarm>) -> String {
    alarm
        .as_ref()
        .map_or_else(|| "none".into(), |a| a.code.to_string())
}

#[test]
fn bolt_hole_circle_by_a_g65_macro_with_a_while_loop() {
    // The manual's classic: holes on a circle, the macro called with
    // X Y (centre) R (radius) A (start angle) B (step) H (count).
    let program = "\
O1
G65 P9100 X100. Y50. R40. A15. B60. H6
M30
O9100
#30=0
WHILE [#30 LT #11] DO1
#31=#1+#30*#2
G0 X[#24+#18*COS[#31]] Y[#25+#18*SIN[#31]]
#30=#30+1
END1
M99
";
    let (rows, alarm) = run(program);
    assert_eq!(code(&alarm), "none", "{alarm:?}");
    assert_eq!(rows.len(), 6, "{:?}", xy(&rows));
    for (k, row) in rows.iter().enumerate() {
        let angle = (15.0 + 60.0 * k as f64).to_radians();
        assert!(
            (row.tip.x - (100.0 + 40.0 * angle.cos())).abs() < 1e-9,
            "{:?}",
            xy(&rows)
        );
        assert!(
            (row.tip.y - (50.0 + 40.0 * angle.sin())).abs() < 1e-9,
            "{:?}",
            xy(&rows)
        );
        assert_eq!(row.line, 8);
    }
}

#[test]
fn goto_if_and_nested_loops() {
    let program = "\
#1=0
N10 #1=#1+1
IF [#1 LT 3] GOTO 10
G0 X#1
#2=0
WHILE [#2 LT 2] DO1
#3=0
WHILE [#3 LT 2] DO2
G0 Y[#2*10+#3]
#3=#3+1
END2
#2=#2+1
END1
IF [#2 EQ 2] THEN #4=7.
G0 Z#4
GOTO 99
G0 X500.
N99 M30
";
    let (rows, alarm) = run(program);
    assert_eq!(code(&alarm), "none", "{alarm:?}");
    assert_eq!(
        tips(&rows),
        vec![
            (4, 3.0, 0.0, 0.0),
            (9, 3.0, 1.0, 0.0),
            (9, 3.0, 10.0, 0.0),
            (9, 3.0, 11.0, 0.0),
            (15, 3.0, 11.0, 7.0),
        ]
    );
}

#[test]
fn vacant_variables_leave_words_out() {
    // #1 is vacant: `Y#1` is as if not written, `#2 = #1 * 5` is 0.
    let (rows, alarm) = run("G0 X5. Y#1\n#2=#1*5\nG0 X#2\n");
    assert_eq!(code(&alarm), "none");
    assert_eq!(xy(&rows), vec![(1, 5.0, 0.0), (3, 0.0, 0.0)]);
}

#[test]
fn system_variables_read_and_write_the_controller() {
    let program = "\
G0 X10. Y20.
#1=#5001
#2=#5022
#3=#2201+#2001
#4=#4003
G91 G0 X[#1] Y#2
#5221=100.
G90 G0 X0
";
    let (rows, alarm) = run(program);
    assert_eq!(code(&alarm), "none", "{alarm:?}");
    // H1 geometry 100 + wear -0.5; G90 read as 90.
    assert_eq!(rows[1].joints[0], 20.0);
    assert_eq!(rows[1].joints[1], 40.0);
    // G54 X written: X0 is now machine X 100.
    assert_eq!(rows[2].joints[0], 100.0);
    let (rows, alarm) = run("#1=#2201+#2001\nG0 X#1\n");
    assert_eq!(code(&alarm), "none");
    assert_eq!(rows[0].joints[0], 99.5);
}

#[test]
fn macro_alarms_name_the_line_and_the_control_number() {
    for (program, want, line) in [
        ("#1=1/0\n", "PS0112", 1),
        ("G0 X1.\n#34=1\n", "PS0115", 2),
        ("#5021=0\n", "PS0116", 1),
        ("#1=SQRT[-1]\n", "PS0119", 1),
        ("WHILE [1 GT 2] DO1\nG0 X1.\n", "PS0124", 1),
        ("END1\n", "PS0126", 1),
        ("GOTO 77\n", "PS0128", 1),
        ("#1=[[[[[[1]]]]]]\n", "PS0118", 1),
        ("#3000=12(SPINDLE NOT READY)\n", "3012", 1),
    ] {
        let (_, alarm) = run(program);
        assert_eq!(code(&alarm), want, "{program}: {alarm:?}");
        assert_eq!(alarm.as_ref().map(|a| a.line), Some(line), "{program}");
    }
    let (_, alarm) = run("#3000=12(SPINDLE NOT READY)\n");
    assert!(alarm.is_some_and(|a| a.message.contains("SPINDLE NOT READY")));
}

#[test]
fn an_endless_macro_loop_is_stopped_by_the_block_budget() {
    let machine = machine();
    let options = fiveaxis_control::RunOptions {
        max_blocks: 10_000,
        ..fiveaxis_control::RunOptions::default()
    };
    let mut runner = fiveaxis_control::Runner::new(
        &machine,
        Offsets::default(),
        fiveaxis_control::SliceSource::new(b"#1=0\nWHILE [#1 GE 0] DO1\n#1=#1+1\nEND1\n"),
        options,
    );
    let alarm = loop {
        match runner.next_segment() {
            Ok(Some(_)) => {}
            Ok(None) => break None,
            Err(fiveaxis_control::RunError::Alarm { alarm, .. }) => break Some(alarm),
            Err(e) => panic!("{e}"),
        }
    };
    let alarm = alarm.expect("stopped");
    assert_eq!(alarm.code.to_string(), "FX0102");
    assert!(alarm.message.contains("lines 2 to 4"), "{}", alarm.message);
}

/// Lines a `GOTO` or a false `WHILE` reads past count against the
/// budget: a loop of two blocks that jumps over 10,000 lines each pass
/// stops after a few passes, not after `max_blocks / 2` passes of 10,000
/// lines read each.
#[test]
fn lines_skipped_by_goto_and_while_count_toward_the_block_budget() {
    const SKIPPED: usize = 10_000;
    const BUDGET: u64 = 100_000;
    let body = "G0 X1.\n".repeat(SKIPPED);
    let programs = [
        format!("N1 GOTO 2\n{body}N2 GOTO 1\n"),
        format!("N1 WHILE [1 EQ 0] DO1\n{body}END1\nGOTO 1\n"),
    ];
    for program in programs {
        let machine = machine();
        let options = fiveaxis_control::RunOptions {
            max_blocks: BUDGET,
            ..fiveaxis_control::RunOptions::default()
        };
        let mut runner = fiveaxis_control::Runner::new(
            &machine,
            Offsets::default(),
            fiveaxis_control::SliceSource::new(program.as_bytes()),
            options,
        );
        let alarm = loop {
            match runner.next_segment() {
                Ok(Some(_)) => {}
                Ok(None) => break None,
                Err(fiveaxis_control::RunError::Alarm { alarm, .. }) => break Some(alarm),
                Err(e) => panic!("{e}"),
            }
        };
        let alarm = alarm.expect("stopped");
        assert_eq!(alarm.code.to_string(), "FX0102");
        assert!(
            alarm.message.contains("lines skipped over"),
            "{}",
            alarm.message
        );
        // The budget ran out on lines read past, not on blocks run.
        assert!(runner.blocks() < BUDGET / 100, "{}", runner.blocks());
    }
}

#[test]
fn g66_calls_the_macro_after_every_move_until_g67() {
    // A drilling macro called modally: after each positioning block the
    // macro drills Z down by the argument Z and back.
    let program = "\
O1
G66 P9000 Z5. F100.
G0 X10. Y20.
X30.
G67
X50.
M30
O9000
G1 Z-#26 F#9
G0 Z0
M99
";
    let (rows, alarm) = run(program);
    assert_eq!(code(&alarm), "none", "{alarm:?}");
    assert_eq!(
        tips(&rows),
        vec![
            (3, 10.0, 20.0, 0.0),
            (9, 10.0, 20.0, -5.0),
            (10, 10.0, 20.0, 0.0),
            (4, 30.0, 20.0, 0.0),
            (9, 30.0, 20.0, -5.0),
            (10, 30.0, 20.0, 0.0),
            (6, 50.0, 20.0, 0.0),
        ]
    );
}

#[test]
fn arguments_without_a_decimal_point_count_in_least_input_increments() {
    // FANUC: `G65 P9000 X10` passes #24 = 0.010 mm (IS-B); with a decimal
    // point the value is as written. Other addresses (H, S, T, M, F, E)
    // pass their number as written.
    let program = "O1\nG65 P9000 X10 Y10. H3\nM30\nO9000\nG0 X[#24*1000] Y#25 Z#11\nM99\n";
    let (rows, alarm) = run(program);
    assert_eq!(code(&alarm), "none", "{alarm:?}");
    assert_eq!(
        rows.iter()
            .map(|r| (r.tip.x, r.tip.y, r.tip.z))
            .collect::<Vec<_>>(),
        vec![(10.0, 10.0, 3.0)]
    );
}

#[test]
fn a_3006_stop_is_noted_and_the_run_goes_on() {
    let machine = machine();
    let mut runner = fiveaxis_control::Runner::new(
        &machine,
        Offsets::default(),
        fiveaxis_control::SliceSource::new(b"#3006=1(CHECK THE CLAMPS)\nG0 X1.\n"),
        fiveaxis_control::RunOptions::default(),
    );
    let mut rows = 0;
    while let Ok(Some(_)) = runner.next_segment() {
        rows += 1;
    }
    assert_eq!(rows, 1);
    assert!(
        runner
            .notes()
            .iter()
            .any(|n| n.contains("#3006 stop: CHECK THE CLAMPS")),
        "{:?}",
        runner.notes()
    );
}

/// Issue 24, item 1: the value of a variable or expression in an address
/// that takes an integer is rounded to the integer (FANUC rounds a
/// variable's value to the address's least increment); the decimal point
/// rule is for what the tape says. `G10 L11 P#1 R-1.0` writes tool 1's
/// length wear; `H#2` with #2 = 0.6 is H1.
#[test]
fn variables_in_integer_addresses_are_rounded_values() {
    let z = |program: &str| {
        let (rows, alarm) = run(program);
        assert!(alarm.is_none(), "{alarm:?}\n{program}");
        rows.last().map(|r| r.joints[2]).expect("a row")
    };
    // Length 100, wear -0.5: the gauge point 99.5 above the tip.
    assert!((z("G21 G90 G0 X0 Y0\nG43 H1 Z0\nM30\n") - 99.5).abs() < 1e-9);
    assert!((z("G21 G90 G0 X0 Y0\n#1=1\nG43 H#1 Z0\nM30\n") - 99.5).abs() < 1e-9);
    assert!((z("G21 G90 G0 X0 Y0\n#2=0.6\nG43 H#2 Z0\nM30\n") - 99.5).abs() < 1e-9);
    assert!((z("G21 G90 G0 X0 Y0\n#1=1\nG43 H[#1+0.4] Z0\nM30\n") - 99.5).abs() < 1e-9);
    // G10 L11 P#1: tool 1's wear becomes -1.0.
    let program = "G21 G90 G0 X0 Y0\n#4=0.5\nG10 L11 P[#4*2] R-1.0\nG43 H1 Z0\nM30\n";
    assert!((z(program) - 99.0).abs() < 1e-9);
    // A decimal point written on the tape is still refused.
    let (_, alarm) = run("G21 G90\nG43 H1. Z0\nM30\n");
    assert_eq!(alarm.map(|a| a.code.to_string()), Some("PS0007".into()));
    // The rounded value must be in range.
    let (_, alarm) = run("G21 G90\n#1=-0.6\nG43 H#1 Z0\nM30\n");
    assert!(alarm.is_some());
    // M codes are whole numbers: M#1 with #1 = 7.6 is M8 (#4113 reads 8).
    let (rows, alarm) = run("G21 G90 G0 X0 Y0 Z100.\n#1=7.6\nM#1\nG0 X#4113\nM30\n");
    assert!(alarm.is_none(), "{alarm:?}");
    assert!((rows.last().map_or(0.0, |r| r.tip.x) - 8.0).abs() < 1e-9);
}

/// Issue 24, item 2: every modal information variable reads (FANUC 30i,
/// "System variables", modal information): the G code groups of the
/// preceding block (`#4001`–`#4030`) and of the block being executed
/// (`#4201`–`#4230`), the values B D E F H M N O S T P (`#4101`–`#4130`,
/// `#4301`–`#4330`); a group or address the kernel has no function of is
/// vacant, never an alarm; writing one is refused.
#[test]
fn every_modal_information_variable_reads() {
    let program = "O1234\nN10 G21 G90 G17 G0 X0 Y0 Z0\nM8\n\
        #100=#4003\n#101=#4113\n#102=#4114\nG0 X#100 Y#101 Z#102\n\
        #103=#4012\n#104=#4015\n#105=#4115/1000\nG0 X#103 Y#104 Z#105\n\
        G0 X[#4203] Y#4023 Z[#4130]\n\
        G66 P9000\n#110=#4012\n#111=#4212\nG67\n#112=#4012\nG0 X#110 Y#111 Z#112\n\
        M98 P9001\nG0 X[#120/1000]\n\
        M30\nO9000\nM99\nO9001\n#120=#4115\nM99\n";
    let (rows, alarm) = run(program);
    assert!(alarm.is_none(), "{alarm:?}");
    let ends: Vec<(u32, f64, f64, f64)> = tips(&rows);
    let at = |line: u32| {
        ends.iter()
            .rev()
            .find(|r| r.0 == line)
            .map(|r| [r.1, r.2, r.3])
            .expect("a row of the line")
    };
    let near = |got: [f64; 3], want: [f64; 3]| {
        assert!(
            got.iter().zip(want).all(|(g, w)| (g - w).abs() < 1e-9),
            "{got:?} vs {want:?}"
        );
    };
    // G90, the last M (M8), the last sequence number (N10).
    near(at(7), [90.0, 8.0, 10.0]);
    // No G66: G67; G64 (cutting mode); the program O1234.
    near(at(11), [67.0, 64.0, 1.234]);
    // The block being executed: G90; group 23 (none): vacant, Y stays;
    // P of G54.1: none, 0.
    near(at(12), [90.0, 64.0, 0.0]);
    // G66 in force, then G67.
    near(at(18), [66.0, 66.0, 67.0]);
    // Inside O9001, #4115 is 9001.
    near(at(20), [9.001, 66.0, 67.0]);
    // Every number of the four tables reads, vacant or not.
    for base in [4000, 4100, 4200, 4300] {
        for k in 1..=30 {
            let program = format!("G21\n#1=#{}\nM30\n", base + k);
            let (_, alarm) = run(&program);
            assert!(alarm.is_none(), "#{}: {alarm:?}", base + k);
        }
    }
    // They are read-only.
    let (_, alarm) = run("G21\n#4001=1\nM30\n");
    assert!(alarm.is_some());
}

/// Issue 24, item 4: a work offset holds one value per controlled axis,
/// rotary axes included (FANUC: `#5221`–`#5240` are G54's axes 1–20):
/// the offset of C shifts programmed C from machine C as X's does X; the
/// variables read and write it, and so does G10 L2 / L20 with the axis
/// word.
#[test]
fn work_offsets_hold_every_axis() {
    let machine = machine();
    assert_eq!(machine.axis_count(), 5, "X Y Z A C");
    let c_of = |offsets: Offsets, program: &str| {
        let (rows, alarm) = common::run_ends(&machine, offsets, program);
        assert!(alarm.is_none(), "{alarm:?}\n{program}");
        rows.iter()
            .map(|r| (r.line, r.joints[4]))
            .collect::<Vec<_>>()
    };
    let mut offsets = Offsets::default();
    offsets.work_beyond[0][1] = 10.0; // G54 C
    offsets.work_beyond[1][1] = -5.0; // G55 C
    offsets.external_beyond[1] = 1.0; // EXT C
    let c = c_of(
        offsets.clone(),
        "G21 G90 G54 G0 X0 Y0 Z100. C0\nG0 C20.\nG55 G0 C0\nM30\n",
    );
    assert_eq!(c, [(1, 11.0), (2, 31.0), (3, -4.0)]);
    // #5225 is G54's fifth axis (C), #5245 G55's, #5205 the external one.
    let c = c_of(
        offsets.clone(),
        "G21 G90 G54\n#1=#5225\n#2=#5245\n#3=#5205\nG0 X#1 Y#2 Z#3 C0\n#5225=3.\nG0 C0\nM30\n",
    );
    assert_eq!(c, [(5, 11.0), (7, 4.0)]);
    // G10 L2 P1 with the axis word: absolute, then incremental.
    let c = c_of(
        offsets,
        "G21 G90 G54\nG10 L2 P1 C15.\nG0 C0\nG91 G10 L2 P1 C-5.\nG90 G0 C0\nM30\n",
    );
    assert_eq!(c, [(3, 16.0), (5, 11.0)]);
    // A machine with five axes has no sixth: #5226 is not a variable.
    let (_, alarm) = run("G21\n#1=#5226\n#5226=1.\nM30\n");
    assert!(alarm.is_some());
}

/// Issue 24, item 5: structured IF (`IF […] THEN` alone on its line,
/// blocks, an optional `ELSE`, `ENDIF`) on the controls whose manuals have
/// it (Mitsubishi, Mazak), nested; FANUC's custom macro B refuses it.
#[test]
fn structured_if_runs_on_mitsubishi_and_mazak() {
    let program = "G21 G90 G0 X0 Y0 Z100.\n#1=2\nIF [#1 EQ 2] THEN\nG0 X10.\nIF [#1 GT 5] THEN\nG0 X99.\nELSE\nG0 Y20.\nENDIF\nELSE\nG0 X-10.\nENDIF\nIF [#1 EQ 3] THEN\nG0 Z50.\nENDIF\nG0 Z90.\nM30\n";
    for control in [
        fiveaxis_machine::Control::Mazak,
        fiveaxis_machine::Control::Mitsubishi,
    ] {
        let mut m = machine();
        m.control = control;
        let (rows, alarm) = common::run_ends(&m, Offsets::default(), program);
        assert!(alarm.is_none(), "{control:?}: {alarm:?}");
        assert_eq!(
            tips(&rows),
            [
                (1, 0.0, 0.0, 100.0),
                (4, 10.0, 0.0, 100.0),
                (8, 10.0, 20.0, 100.0),
                (16, 10.0, 20.0, 90.0)
            ],
            "{control:?}"
        );
        // An IF … THEN without its ENDIF.
        let (_, alarm) = common::run_ends(
            &m,
            Offsets::default(),
            "G21\n#1=0\nIF [#1 EQ 1] THEN\nG0 X1.\nM30\n",
        );
        let alarm = alarm.expect("no ENDIF");
        assert_eq!(alarm.line, 3);
        assert!(alarm.message.contains("no ENDIF"), "{}", alarm.message);
    }
    // FANUC: not a statement of the control.
    let (_, alarm) = run(program);
    let alarm = alarm.expect("refused");
    assert_eq!(alarm.line, 3);
    assert!(alarm.message.contains("structured IF"), "{}", alarm.message);
}
