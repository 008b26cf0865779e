//! The Haas control (`control = "haas"`), first part: how it reads
//! comments, dwell P words, G87 and the O line, and the power-on input
//! unit (`[parameters] input_unit`, usable by every control). Each rule
//! against the FANUC behaviour it differs from. Expected positions are
//! worked out by hand; tips come from the rows (forward kinematics).

mod common;

use common::builtin_at_zero;
use fiveaxis_control::{Alarm, Condition, Motion, Row, RunError, RunOptions, Runner, SliceSource};
use fiveaxis_gcode::{Block, Syntax, SyntaxErrorKind, parse_line, parse_line_as};
use fiveaxis_machine::{Control, InputUnit, Machine, Offsets};

const EPS: f64 = 1e-9;
const MM_PER_INCH: f64 = 25.4;

/// The three-axis mill of the built-ins with `control`.
fn mill(control: Control) -> Machine {
    let mut m = builtin_at_zero("mill-3axis").expect("built-in machine");
    m.control = control;
    m
}

/// The mill with the power-on input unit `unit`.
fn mill_in(control: Control, unit: InputUnit) -> Machine {
    let mut m = mill(control);
    m.params.input_unit = unit;
    m
}

/// Rows (one per segment, at its end) and the alarm, if any.
fn run_on(machine: &Machine, program: &str) -> (Vec<Row>, Option<Alarm>) {
    let mut runner = Runner::new(
        machine,
        Offsets::default(),
        SliceSource::new(program.as_bytes()),
        RunOptions::default(),
    );
    let mut rows = Vec::new();
    loop {
        match runner.next_segment() {
            Ok(Some(seg)) => rows.push(seg.row(machine, 1.0)),
            Ok(None) => return (rows, None),
            Err(RunError::Alarm { alarm, .. }) => return (rows, Some(alarm)),
            Err(e) => panic!("a program in memory failed to read: {e}"),
        }
    }
}

/// Runs on `machine` and expects no alarm.
#[track_caller]
fn run(machine: &Machine, program: &str) -> Vec<Row> {
    let (rows, alarm) = run_on(machine, program);
    assert!(alarm.is_none(), "unexpected alarm {alarm:?}");
    rows
}

/// The alarm a program stops with.
#[track_caller]
fn alarm(machine: &Machine, program: &str) -> Alarm {
    run_on(machine, program).1.expect("an alarm")
}

/// The tips of the rows, as (line, motion, x, y, z).
fn tips(rows: &[Row]) -> Vec<(u32, Motion, [f64; 3])> {
    rows.iter()
        .map(|r| (r.line, r.motion, [r.tip.x, r.tip.y, r.tip.z]))
        .collect()
}

#[track_caller]
fn assert_tips(actual: &[(u32, Motion, [f64; 3])], expected: &[(u32, Motion, [f64; 3])]) {
    assert_eq!(
        actual.len(),
        expected.len(),
        "got {actual:#?}\nexpected {expected:#?}"
    );
    for (a, e) in actual.iter().zip(expected) {
        let close = (0..3).all(|i| (a.2[i] - e.2[i]).abs() < EPS);
        assert!(
            a.0 == e.0 && a.1 == e.1 && close,
            "got {a:?}, expected {e:?}\nall {actual:#?}"
        );
    }
}

// ----- comments ---------------------------------------------------------

#[test]
fn haas_reads_a_comment_with_parentheses_inside_as_one_comment() {
    // The NX post's tool list line (corpus haas_nx_vf2tr_5T.nc, line 3).
    let line = b"(#508= (MILL_.25_PROFILE         ))";
    let mut block = Block::default();
    parse_line_as(Syntax::HAAS, line, 3, &mut block).expect("one comment");
    assert!(block.is_empty());
    // FANUC: the first `)` ends the comment, the second is a stray.
    let error = parse_line(line, 3, &mut block).expect_err("stray `)`");
    assert_eq!(error.kind, SyntaxErrorKind::UnexpectedChar(')'));
    assert_eq!((error.span.start, error.span.end), (35, 36));
}

#[test]
fn haas_nested_comment_ends_at_its_balancing_parenthesis() {
    let mut block = Block::default();
    parse_line_as(Syntax::HAAS, b"G1 X1. (A (B) (C (D)) E) Y2.", 1, &mut block)
        .expect("words around a nested comment");
    let words: Vec<(u8, f64)> = block.words.iter().map(|w| (w.letter, w.value)).collect();
    assert_eq!(words, vec![(b'G', 1.0), (b'X', 1.0), (b'Y', 2.0)]);
    // The Y column is after the comment, counted in bytes from 1.
    assert_eq!(block.word(b'Y').map(|w| w.span.start), Some(26));
}

#[test]
fn haas_unbalanced_nested_comment_is_unclosed_where_fanuc_closes_it() {
    let mut block = Block::default();
    let error = parse_line_as(Syntax::HAAS, b"G0 X1. (A (B)", 1, &mut block)
        .expect_err("the outer comment is never closed");
    assert_eq!(error.kind, SyntaxErrorKind::UnclosedComment);
    assert_eq!((error.span.start, error.span.end), (8, 14));
    // FANUC: `(A (B)` is a whole comment.
    parse_line(b"G0 X1. (A (B)", 1, &mut block).expect("FANUC comment");
    assert_eq!(block.words.len(), 2);
    // In a run: the kernel's code for an unclosed comment on Haas.
    let a = alarm(&mill(Control::Haas), "G0 X1. (A (B)\n");
    assert_eq!(a.condition, Condition::UnclosedComment);
    assert_eq!(a.code.to_string(), "FX0005");
}

#[test]
fn haas_nested_comment_hides_macro_characters_and_the_program_runs() {
    let program =
        "(#508= (MILL_.25_PROFILE ))\n(#509= (UGTI0201_011 ))\nG0 X1. (A (#1) [2])\nM30\n";
    let rows = run(&mill(Control::Haas), program);
    assert_tips(&tips(&rows), &[(3, Motion::Rapid, [1.0, 0.0, 0.0])]);
    // FANUC stops at the first of these lines.
    let a = alarm(&mill(Control::Fanuc30i), program);
    assert_eq!((a.line, a.code.to_string()), (1, "PS0009".to_owned()));
}

// ----- dwell P ----------------------------------------------------------

#[test]
fn haas_g04_p_is_seconds_with_a_decimal_point_and_milliseconds_without() {
    let haas = mill(Control::Haas);
    for program in [
        "G04 P.5\n",
        "G04 P10.\n",
        "G04 P10\n",
        "G04 P0\n",
        "G4 P99999.999\n",
    ] {
        run(&haas, program);
    }
    // P100000 is 100 s in milliseconds; P100000. is 100 000 s, beyond the
    // longest dwell (99 999.999 s): the two readings differ here.
    run(&haas, "G04 P100000\n");
    let a = alarm(&haas, "G04 P100000.\n");
    assert_eq!(a.condition, Condition::ValueOutOfRange);
    assert_eq!(a.code.to_string(), "FX0014");
    // Half a millisecond past the longest dwell.
    let a = alarm(&haas, "G04 P99999.9995\n");
    assert_eq!(a.condition, Condition::ValueOutOfRange);
    let a = alarm(&haas, "G04 P-1.\n");
    assert_eq!(a.condition, Condition::ValueOutOfRange);
    let a = alarm(&haas, "G04 P-1\n");
    assert_eq!(a.condition, Condition::ValueOutOfRange);
}

#[test]
fn fanuc_g04_p_with_a_decimal_point_is_still_an_alarm() {
    let fanuc = mill(Control::Fanuc30i);
    run(&fanuc, "G04 P500\n");
    let a = alarm(&fanuc, "G04 P.5\n");
    assert_eq!(a.condition, Condition::DecimalPointNotAllowed);
    assert_eq!(a.code.to_string(), "PS0007");
}

#[test]
fn haas_dwell_cycles_take_p_in_seconds() {
    let start = "G90 G17 G0 X0. Y0. Z50.\n";
    let haas = mill(Control::Haas);
    // G82: rapid to R, feed to Z, (dwell 0.05 s), rapid back to the
    // initial level (G98).
    let rows = run(
        &haas,
        &format!("{start}G98 G82 X10. Y5. Z-5. R2. P.05 F100.\nG80\n"),
    );
    assert_tips(
        &tips(&rows[1..]),
        &[
            (2, Motion::Rapid, [10.0, 5.0, 50.0]),
            (2, Motion::Rapid, [10.0, 5.0, 2.0]),
            (2, Motion::Linear, [10.0, 5.0, -5.0]),
            (2, Motion::Rapid, [10.0, 5.0, 50.0]),
        ],
    );
    // G88 and G89 read P the same way.
    run(&haas, &format!("{start}G88 X10. Z-5. R2. P.5 F100.\nG80\n"));
    run(&haas, &format!("{start}G89 X10. Z-5. R2. P.6 F100.\nG80\n"));
    run(
        &haas,
        &format!("{start}G89 X10. Z-5. R2. P600 F100.\nG80\n"),
    );
    let a = alarm(&haas, &format!("{start}G82 X10. Z-5. R2. P-.05 F100.\n"));
    assert_eq!(a.condition, Condition::ValueOutOfRange);
    // FANUC: integer milliseconds only.
    let a = alarm(
        &mill(Control::Fanuc30i),
        &format!("{start}G82 X10. Z-5. R2. P.05 F100.\n"),
    );
    assert_eq!(a.code.to_string(), "PS0007");
}

// ----- G87 --------------------------------------------------------------

#[test]
fn haas_g87_bores_in_and_is_retracted_like_g88() {
    // Haas G87: feed to Z, spindle stop, the operator jogs out; the kernel
    // takes the manual retraction as a rapid move to R, then the initial
    // level in G98 (as for G88). The shift Q of FANUC's back boring does
    // not apply.
    let program = "G90 G17 G0 X0. Y0. Z50.\nG98 G87 X10. Y5. Z-5. R2. F100.\nG80\n";
    let rows = run(&mill(Control::Haas), program);
    assert_tips(
        &tips(&rows[1..]),
        &[
            (2, Motion::Rapid, [10.0, 5.0, 50.0]),
            (2, Motion::Rapid, [10.0, 5.0, 2.0]),
            (2, Motion::Linear, [10.0, 5.0, -5.0]),
            (2, Motion::Rapid, [10.0, 5.0, 2.0]),
            (2, Motion::Rapid, [10.0, 5.0, 50.0]),
        ],
    );
}

// ----- input unit -------------------------------------------------------

#[test]
fn inch_input_unit_reads_lengths_in_inches_until_g21() {
    // Haas refuses the G21 against an inch Setting 9 (below).
    for control in [Control::Fanuc30i, Control::Mitsubishi] {
        let inch = mill_in(control, InputUnit::Inch);
        let rows = run(
            &inch,
            "G0 X1. Y-2.5\nG1 Z-.5 F10.\nG21 G0 X1.\nG20 G0 X2.\nM30\n",
        );
        let ends: Vec<(u32, [f64; 3], Option<f64>)> = rows
            .iter()
            .map(|r| (r.line, [r.joints[0], r.joints[1], r.joints[2]], r.feed))
            .collect();
        let expected = [
            (1, [25.4, -63.5, 0.0], None),
            (2, [25.4, -63.5, -12.7], Some(254.0)),
            (3, [1.0, -63.5, -12.7], None),
            (4, [50.8, -63.5, -12.7], None),
        ];
        assert_eq!(ends.len(), expected.len(), "{control:?}: {ends:?}");
        for (a, e) in ends.iter().zip(&expected) {
            let close = (0..3).all(|i| (a.1[i] - e.1[i]).abs() < EPS);
            let feed = match (a.2, e.2) {
                (Some(x), Some(y)) => (x - y).abs() < EPS,
                (x, y) => x == y,
            };
            assert!(a.0 == e.0 && close && feed, "{control:?}: {a:?} vs {e:?}");
        }
    }
}

/// Haas NGC mill operator's manual, G20 / G21: "G20 in a program causes
/// an alarm if Setting 9 is not set to inch" (and G21 when it is).
#[test]
fn haas_unit_codes_must_agree_with_setting_9() {
    let inch = mill_in(Control::Haas, InputUnit::Inch);
    let rows = run(&inch, "G20 G0 X1.\nM30\n");
    assert!((rows[0].joints[0] - 25.4).abs() < EPS);
    let a = alarm(&inch, "G0 X1.\nG21 G0 X1.\nM30\n");
    assert_eq!((a.condition, a.line), (Condition::UnitsMismatch, 2));
    let mm = mill(Control::Haas);
    let a = alarm(&mm, "G20\n");
    assert_eq!(a.condition, Condition::UnitsMismatch);
    assert!(a.message.contains("Setting 9"), "{}", a.message);
    let rows = run(&mm, "G21 G0 X1.\nM30\n");
    assert!((rows[0].joints[0] - 1.0).abs() < EPS);
}

#[test]
fn inch_input_without_a_decimal_point_counts_tenths_of_increments() {
    // IS-B in inches: 0.0001 in per unit, so X10000 is one inch.
    let rows = run(&mill_in(Control::Haas, InputUnit::Inch), "G0 X10000\n");
    assert!((rows[0].joints[0] - MM_PER_INCH).abs() < EPS);
}

#[test]
fn the_power_on_unit_shows_in_4006_and_millimetres_stay_the_default() {
    // #4006: 20 in inch mode, 21 in mm (read before the G21 of the move).
    let program = "#1=#4006\nG21 G0 X#1\n";
    let rows = run(&mill_in(Control::Fanuc30i, InputUnit::Inch), program);
    assert!((rows[0].joints[0] - 20.0).abs() < EPS);
    let rows = run(
        &mill_in(Control::Haas, InputUnit::Inch),
        "#1=#4006\nG0 X[#1/100]\n",
    );
    assert!((rows[0].joints[0] - 0.2 * 25.4).abs() < EPS);
    let rows = run(&mill(Control::Haas), program);
    assert!((rows[0].joints[0] - 21.0).abs() < EPS);
    // The default is mm for every control.
    assert_eq!(mill(Control::Haas).params.input_unit, InputUnit::Millimetre);
    let rows = run(&mill(Control::Haas), "G0 X1.\n");
    assert!((rows[0].joints[0] - 1.0).abs() < EPS);
}

#[test]
fn machine_file_input_unit_reads_writes_and_refuses_other_words() {
    // A file as `to_toml` writes it (which has both keys), edited.
    let text = builtin_at_zero("mill-3axis").expect("built in").to_toml();
    assert!(text.contains("input_unit = \"mm\""), "{text}");
    let with = |unit: &str| {
        text.lines()
            .map(|l| {
                if l.starts_with("control =") {
                    "control = \"haas\"".to_owned()
                } else if l.starts_with("input_unit =") {
                    format!("input_unit = {unit}")
                } else {
                    l.to_owned()
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
    };
    let inch = Machine::from_toml(&with("\"inch\"")).expect("inch is a unit");
    assert_eq!(inch.params.input_unit, InputUnit::Inch);
    assert_eq!(inch.control, Control::Haas);
    let again = Machine::from_toml(&inch.to_toml()).expect("round trip");
    assert_eq!(again, inch);
    let mm = Machine::from_toml(&with("\"mm\"")).expect("mm is a unit");
    assert_eq!(mm.params.input_unit, InputUnit::Millimetre);
    let error = Machine::from_toml(&with("\"cm\"")).expect_err("not a unit");
    let message = error.to_string();
    let line = 1 + text
        .lines()
        .position(|l| l.starts_with("input_unit"))
        .expect("key");
    assert!(
        message.contains(&format!("line {line},")) && message.contains("`mm` or `inch`"),
        "{message}"
    );
}

// ----- the O line -------------------------------------------------------

#[test]
fn haas_refuses_the_posts_placeholder_o_line_and_runs_a_numbered_one() {
    let haas = mill(Control::Haas);
    let a = alarm(&haas, "%\nO ENTER OP AND LAST 3 DIGITS\nG0 X1.\nM30\n%\n");
    assert_eq!(a.line, 2);
    assert_eq!(a.condition, Condition::ImproperAddress);
    assert_eq!(a.code.to_string(), "FX0004");
    assert!(a.message.contains("program number"), "{}", a.message);
    for header in ["O1201", "O01201 (PART 1201)", "O1201 (#508= (NAME))"] {
        let rows = run(&haas, &format!("%\n{header}\nG0 X1.\nM30\n%\n"));
        assert_eq!(rows.len(), 1, "{header}");
        assert_eq!(rows[0].line, 3);
    }
}

#[test]
fn haas_numbers_programs_o00001_to_o99999_and_names_an_unnumbered_one_ononame() {
    let haas = mill(Control::Haas);
    for header in ["O00001", "O99999 (LAST)"] {
        let rows = run(&haas, &format!("%\n{header}\nG0 X1.\nM30\n%\n"));
        assert_eq!(rows.len(), 1, "{header}");
    }
    for header in ["O0", "O100000", "O1.5"] {
        let a = alarm(&haas, &format!("%\n{header}\nG0 X1.\nM30\n%\n"));
        assert_eq!(a.line, 2, "{header}");
        let code = a.code.to_string();
        assert!(code == "FX0014" || code == "FX0013", "{header}: {a}");
    }
    // ONONAME: a program start without a number, with or without a name
    // comment, in either case.
    for header in ["ONONAME", "ONONAME (BRACKET)", "  ononame  "] {
        let rows = run(&haas, &format!("%\n{header}\nG0 X1.\nM30\n%\n"));
        assert_eq!(rows.len(), 1, "{header}");
        assert_eq!(rows[0].line, 3, "{header}");
    }
    // As a program start it ends the program before it, as an O line does.
    let rows = run(&haas, "%\nO00010\nG0 X1.\nONONAME\nG0 X2.\nM30\n%\n");
    assert_eq!(rows.len(), 1);
    // Other words after it, and ONONAME on FANUC, are not a program name.
    let a = alarm(&haas, "%\nONONAME X1.\nM30\n%\n");
    assert_eq!(a.line, 2);
    let a = alarm(&mill(Control::Fanuc30i), "%\nONONAME\nG0 X1.\nM30\n%\n");
    assert_eq!(a.line, 2);
}

// ----- alarm numbers ----------------------------------------------------

/// The built-in UMC-750 (control = "haas"), metric words.
fn umc() -> Machine {
    builtin_at_zero("haas-umc750").expect("built-in")
}

#[test]
fn haas_stops_with_the_numbers_its_manual_gives() {
    let umc = umc();
    // A subprogram that is not in memory: "Alarm 314 Subprogram Not In
    // Memory", for M98 and for M97's sequence number alike.
    for call in ["M98 P9123", "M97 P77"] {
        let a = alarm(
            &umc,
            &format!("%\nO00001\nG20 G90 G00 X0. Y0.\n{call}\nM30\n%\n"),
        );
        assert_eq!(a.condition, Condition::ProgramNotFound, "{call}");
        assert_eq!(a.code.to_string(), "314", "{call}");
        assert_eq!(a.line, 4, "{call}");
    }
    // A subprogram ending without M99: "Alarm 312 - Program End", at its
    // M30, or where its file ends.
    let a = alarm(
        &umc,
        "%\nO00001\nG20 G90 G00 X-1. Y-1.\nM97 P100\nM30\nN100 G00 X-2.\nM30\n%\n",
    );
    assert_eq!(a.condition, Condition::SubprogramEndMissing);
    assert_eq!((a.code.to_string().as_str(), a.line), ("312", 7));
    let a = alarm(
        &umc,
        "%\nO00001\nG20 M98 P2\nM30\n%\nO00002\nG00 X-1. Y-1.\n",
    );
    assert_eq!((a.code.to_string().as_str(), a.line), ("312", 7));
    // FANUC returns from it.
    let fanuc = mill(Control::Fanuc30i);
    let r = run(&fanuc, "O0001\nM98 P2\nG0 X2.\nM30\nO0002\nG00 X1.\n");
    assert_eq!(r.len(), 2);
    // #3000 = 15: programmable alarm 1015.
    let a = alarm(&umc, "%\nO00001\n#3000=15 (CLAMP OPEN)\nM30\n%\n");
    assert_eq!(a.condition, Condition::MacroAlarm);
    assert_eq!(a.code.to_string(), "1015");
    // An arc under per-axis scaling: alarm 467.
    let a = alarm(
        &umc,
        "%\nO00001\nG20 G17 G90 G00 X0. Y0.\nG51 X0. Y0. I2000 J1000\nG02 X1. Y0. R.5 F10.\nM30\n%\n",
    );
    assert_eq!(a.condition, Condition::FrameArcScaling);
    assert_eq!(a.code.to_string(), "467");
    assert_eq!(a.line, 5);
    // A condition the manual numbers nowhere keeps the kernel's code.
    let a = alarm(&umc, "%\nO00001\nG20 G90 G01 X1.\nM30\n%\n");
    assert_eq!(a.condition, Condition::FeedZero);
    assert_eq!(a.code.to_string(), "FX0020");
}

#[test]
fn haas_macro_calls_nest_nine_deep() {
    // O2000 calls itself with G65 until #100 reaches the limit: nine
    // nested G65 calls run, a tenth is the macro nesting alarm (the manual:
    // "G65 calls can be nested up to 9 times"); FANUC 30i takes ten.
    let program = |limit: u32| {
        format!(
            "%\nO00001\n#100=0\nG65 P2000\nM30\nO2000\n#100=#100+1\nIF[#100GE{limit}]GOTO10\nG65 P2000\nN10 M99\n%\n"
        )
    };
    let umc = umc();
    let (_, a) = run_on(&umc, &program(9));
    assert!(a.is_none(), "{a:?}");
    let a = alarm(&umc, &program(10));
    assert_eq!(a.condition, Condition::MacroCallNesting);
    let (_, a) = run_on(&mill(Control::Fanuc30i), &program(10));
    assert!(a.is_none(), "{a:?}");
}
