//! M codes (the control's and the machine file's `[m_codes]`), accuracy
//! modes, and the words real programs hold around them: hand-computed.

mod common;

use common::builtin_at_zero;
use fiveaxis_control::{
    Alarm, ContourControl, Controller, CuttingMode, Flow, LengthMode, ProgramStop, Segment,
    TcpcType,
};
use fiveaxis_gcode::{Block, parse_line};
use fiveaxis_machine::{MCodes, MFunction, Machine, Offsets, ToolOffset};

const EPS: f64 = 1e-9;

fn machine(name: &str) -> Machine {
    builtin_at_zero(name).expect("built-in machine")
}

/// Tools 1 (H 100) and 2 (H 50) in the offset memory.
fn offsets() -> Offsets {
    let mut o = Offsets::default();
    for (n, length) in [(1, 100.0), (2, 50.0)] {
        o.tools.insert(
            n,
            ToolOffset {
                length,
                ..ToolOffset::default()
            },
        );
    }
    o
}

/// A program run block by block through a controller.
struct Run<'m> {
    controller: Controller<'m>,
    segments: Vec<Segment>,
    alarm: Option<Alarm>,
    /// The flow and program stop of each block executed.
    blocks: Vec<(Flow, Option<ProgramStop>)>,
}

fn run_with<'m>(
    machine: &'m Machine,
    offsets: Offsets,
    optional_stop: bool,
    program: &str,
) -> Run<'m> {
    let mut controller = Controller::new(machine, offsets);
    controller.set_optional_stop(optional_stop);
    let mut segments = Vec::new();
    let mut blocks = Vec::new();
    let mut block = Block::default();
    for (i, line) in program.lines().enumerate() {
        let n = u32::try_from(i + 1).expect("short program");
        parse_line(line.as_bytes(), n, &mut block).expect("program parses");
        match controller.execute(&block, &mut segments) {
            Ok(flow) => {
                blocks.push((flow, controller.program_stop()));
                if flow == Flow::End {
                    break;
                }
            }
            Err(alarm) => {
                return Run {
                    controller,
                    segments,
                    alarm: Some(alarm),
                    blocks,
                };
            }
        }
    }
    Run {
        controller,
        segments,
        alarm: None,
        blocks,
    }
}

fn run<'m>(machine: &'m Machine, program: &str) -> Run<'m> {
    run_with(machine, offsets(), false, program)
}

fn code(r: &Run<'_>) -> String {
    r.alarm
        .as_ref()
        .map_or("none".into(), |a| a.code.to_string())
}

/// Position of axis `letter` after the run.
fn at(r: &Run<'_>, letter: char) -> f64 {
    let m = r.controller.machine();
    r.controller.joints()[m.axis_index(letter).expect("axis")]
}

/// `name` with `extra` added to its `[m_codes]`.
fn with_codes(name: &str, extra: &[(u16, MFunction)]) -> Machine {
    let mut m = machine(name);
    m.m_codes = MCodes::new(m.m_codes.iter().chain(extra.iter().copied()));
    m
}

#[test]
fn an_undeclared_m_code_says_how_to_declare_it() {
    let m = machine("mill-3axis");
    let r = run(&m, "G0 X1.\nM50\n");
    assert_eq!(code(&r), "FX0011");
    let alarm = r.alarm.expect("alarm");
    assert_eq!(alarm.line, 2);
    assert!(alarm.message.contains("[m_codes]"), "{}", alarm.message);
    assert!(
        alarm.message.contains("50 = \"signal\""),
        "{}",
        alarm.message
    );
    // Declared, it moves nothing.
    let m = with_codes("mill-3axis", &[(50, MFunction::Signal)]);
    let r = run(&m, "G0 X1.\nM50\nG0 X2.\n");
    assert_eq!(code(&r), "none");
    assert_eq!(r.segments.len(), 2);
}

#[test]
fn a_declared_code_replaces_the_standard_meaning() {
    // M03 declared as a signal: the spindle does not turn, G95 stops.
    let m = with_codes("mill-3axis", &[(3, MFunction::Signal)]);
    assert_eq!(code(&run(&m, "S1000 M3\nG95 G1 X1. F0.1\n")), "FX0021");
    // A builder's spindle start on M13 (M03 + coolant on some machines).
    let m = with_codes("mill-3axis", &[(13, MFunction::SpindleCw)]);
    let r = run(&m, "S1000 M13\nG95 G1 X1. F0.1\n");
    assert_eq!(code(&r), "none");
    assert!((r.segments[0].feed.expect("feed") - 100.0).abs() < EPS);
    // A builder's end of program: nothing after it runs.
    let m = with_codes("mill-3axis", &[(60, MFunction::End)]);
    let r = run(&m, "G0 X1.\nM60\nG0 X2.\n");
    assert_eq!(r.blocks.last().map(|b| b.0), Some(Flow::End));
    assert_eq!(r.segments.len(), 1);
}

#[test]
fn spindle_state_follows_m_and_s() {
    let m = machine("mill-3axis");
    let r = run(&m, "S1200 M3\n");
    assert!(r.controller.spindle_on());
    assert!((r.controller.spindle_speed() - 1200.0).abs() < EPS);
    // S alone keeps the spindle as it is; S0 with G95 has no feed.
    assert!(!run(&m, "S1200\n").controller.spindle_on());
    assert_eq!(code(&run(&m, "S0 M3\nG95 G1 X1. F0.1\n")), "FX0021");
    // M05, M19 (orientation) and M06 (tool change) leave it stopped.
    for stop in ["M5", "M19", "T1 M6"] {
        let r = run(&m, &format!("S1000 M3\n{stop}\nG95 G1 X1. F0.1\n"));
        assert_eq!(code(&r), "FX0021", "{stop}");
    }
    let r = run(&m, "S1000 M4\nM8\n");
    assert!(r.controller.spindle_on() && r.controller.coolant());
    assert!(!run(&m, "M8\nM9\n").controller.coolant());
}

#[test]
fn t_selects_and_m06_loads_the_tool() {
    let m = machine("mill-3axis");
    let r = run(&m, "T2 M6\nT1\n");
    assert_eq!((r.controller.spindle_tool(), r.controller.tool()), (2, 1));
    let r = run(&m, "T2\nM6\n");
    assert_eq!(r.controller.spindle_tool(), 2);
    // The offsets file holds tools up to 2: T3 is beyond the memory.
    let r = run(&m, "T3 M6\n");
    assert_eq!(code(&r), "PS0030");
    assert!(r.alarm.expect("alarm").message.contains("up to 2"));
    assert_eq!(code(&run(&m, "T0\n")), "none");
    // Without tools in the offsets file any T number goes.
    let r = run_with(&m, Offsets::default(), false, "T1234 M6\n");
    assert_eq!(
        (code(&r), r.controller.spindle_tool()),
        ("none".into(), 1234)
    );
    assert_eq!(code(&run(&m, "T1.\n")), "PS0007");
}

#[test]
fn stops_are_reported_and_the_run_goes_on() {
    let m = machine("mill-3axis");
    let r = run(&m, "M0\nG0 X1.\nM1\nG0 X2.\nM30\n");
    let stops: Vec<Option<ProgramStop>> = r.blocks.iter().map(|b| b.1).collect();
    assert_eq!(stops, [Some(ProgramStop::Stop), None, None, None, None]);
    assert_eq!(r.segments.len(), 2);
    // With the optional-stop switch on, M01 stops too.
    let r = run_with(&m, offsets(), true, "M1\nG0 X1.\n");
    let stops: Vec<Option<ProgramStop>> = r.blocks.iter().map(|b| b.1).collect();
    assert_eq!(stops, [Some(ProgramStop::OptionalStop), None]);
    // A builder's code declared `"optional_stop"` does the same.
    let m = with_codes("mill-3axis", &[(101, MFunction::OptionalStop)]);
    let r = run_with(&m, offsets(), true, "M101\n");
    assert_eq!(r.blocks[0].1, Some(ProgramStop::OptionalStop));
}

#[test]
fn a_clamped_rotary_axis_does_not_move() {
    // trunnion-ac: M10 / M11 clamp / unclamp A, M12 / M13 C.
    let m = machine("trunnion-ac");
    let r = run(&m, "G0 A-10.\nM10\nG0 X5. C90.\nG0 A-20.\n");
    assert_eq!(code(&r), "FX0017");
    let alarm = r.alarm.clone().expect("alarm");
    assert_eq!(alarm.line, 4);
    assert!(
        alarm.message.contains("axis A is clamped (M10 at line 2)")
            && alarm.message.contains("(M11)"),
        "{}",
        alarm.message
    );
    // C was not clamped and moved; A stayed.
    assert!((at(&r, 'C') - 90.0).abs() < EPS && (at(&r, 'A') + 10.0).abs() < EPS);
    // M codes act before the motion of their block.
    assert_eq!(code(&run(&m, "M10 G0 A-10.\n")), "FX0017");
    let r = run(&m, "M10\nM11 G0 A-10.\n");
    assert_eq!(code(&r), "none");
    assert!((at(&r, 'A') + 10.0).abs() < EPS);
    // A reference return that would turn the clamped axis stops too; one
    // that leaves it where it is does not.
    assert_eq!(code(&run(&m, "G0 A-10.\nM10\nG28 A0.\n")), "FX0017");
    assert_eq!(code(&run(&m, "M10\nG91 G28 A0.\n")), "none");
    assert_eq!(r.controller.clamped_axes().count(), 0);
    let r = run(&m, "M12\nM10\n");
    assert_eq!(r.controller.clamped_axes().collect::<Vec<_>>(), ['A', 'C']);
    // Under TCPC a block whose tool direction turns the clamped axis.
    let r = run(
        &m,
        "G0 X0 Y0 Z100. A0 C0\nG43.4 H1 Z100.\nM12\nG1 X10. A-30. F1000.\nG1 X10. C30.\n",
    );
    assert_eq!(
        (code(&r), r.alarm.map(|a| a.line)),
        ("FX0017".into(), Some(5))
    );
}

#[test]
fn tcpc_by_m_code_is_g43_4_with_the_active_h_and_g49() {
    let m = with_codes(
        "trunnion-ac",
        &[(128, MFunction::TcpcOn), (129, MFunction::TcpcOff)],
    );
    let by_m = run(
        &m,
        "G0 X0 Y0 Z100. A0 C0\nG43 H1 Z100.\nM128\nG1 X10. A-30. F1000.\nM129\nG0 X20.\n",
    );
    let by_g = run(
        &m,
        "G0 X0 Y0 Z100. A0 C0\nG43 H1 Z100.\nG43.4\nG1 X10. A-30. F1000.\nG49\nG0 X20.\n",
    );
    assert_eq!(code(&by_m), "none");
    assert_eq!(by_m.segments.len(), by_g.segments.len());
    for (a, b) in by_m.segments.iter().zip(&by_g.segments) {
        assert_eq!((a.start, a.end), (b.start, b.end));
    }
    let on = run(&m, "G43 H2 Z100.\nM128\n");
    assert_eq!(
        on.controller.modal().length,
        LengthMode::Tcpc(TcpcType::Angles)
    );
    // H in the M128 block is taken as G43.4's.
    assert_eq!(code(&run(&m, "M128 H2\n")), "none");
    assert_eq!(code(&run(&m, "G43 H1 M128\n")), "PS0010");
}

#[test]
fn rigid_tapping_is_kept_until_g80() {
    let m = machine("mill-3axis");
    assert!(run(&m, "M29 S500\n").controller.rigid_tap());
    assert!(run(&m, "M29 S500\nG0 X1.\n").controller.rigid_tap());
    assert!(!run(&m, "M29 S500\nG80\n").controller.rigid_tap());
}

#[test]
fn accuracy_modes_are_kept_and_move_nothing() {
    let m = machine("mill-3axis");
    let modal = |p: &str| {
        let r = run(&m, p);
        assert_eq!(code(&r), "none", "{p}");
        assert!(r.segments.is_empty(), "{p}");
        r.controller.modal()
    };
    assert_eq!(modal("").accuracy.contour, ContourControl::Off);
    assert_eq!(
        modal("G05.1 Q1").accuracy.contour,
        ContourControl::AiContour
    );
    assert_eq!(
        modal("G5.1 Q3").accuracy.contour,
        ContourControl::NanoSmoothing
    );
    assert_eq!(
        modal("G05.1 Q1\nG05.1 Q0").accuracy.contour,
        ContourControl::Off
    );
    assert!(modal("G05 P10000").accuracy.high_precision);
    assert!(!modal("G05 P10000\nG05 P0").accuracy.high_precision);
    assert!(modal("G08 P1").accuracy.look_ahead);
    assert!(!modal("G08 P1\nG8 P0").accuracy.look_ahead);
    assert_eq!(modal("").cutting, CuttingMode::Cutting);
    assert_eq!(modal("G61").cutting, CuttingMode::ExactStop);
    assert_eq!(modal("G62").cutting, CuttingMode::CornerOverride);
    assert_eq!(modal("G63").cutting, CuttingMode::Tapping);
    assert_eq!(modal("G61\nG64").cutting, CuttingMode::Cutting);
    // G09 changes no mode; its block moves as programmed.
    let r = run(&m, "G09 G01 X10. F100.\n");
    assert_eq!((code(&r), r.segments.len()), ("none".into(), 1));
    assert_eq!(r.controller.modal().cutting, CuttingMode::Cutting);
    // Out of range, missing, or two mode codes in one block.
    for (p, want) in [
        ("G05.1 Q2", "FX0014"),
        ("G05.1", "PS0005"),
        ("G05 P1", "FX0014"),
        ("G05", "PS0005"),
        ("G08 P2", "FX0014"),
        ("G05.1 Q1.", "PS0007"),
        ("G05.1 Q1 G08 P1", "PS0010"),
        ("G05.1 Q1 X1.", "none"),
    ] {
        assert_eq!(code(&run(&m, p)), want, "{p}");
    }
}

#[test]
fn g05_stays_refused_in_3d_tool_compensation() {
    let m = machine("mill-3axis");
    let r = run(&m, "G41 X0 Y0 Z0 I0 J0 K1 D1\nG05 P10000\n");
    assert_eq!(code(&r), "PS0178");
    // G05.1 is not G05.
    let r = run(&m, "G41 X0 Y0 Z0 I0 J0 K1 D1\nG05.1 Q1\n");
    assert_eq!(code(&r), "none");
}

#[test]
fn reference_returns_with_rotary_words_and_g91() {
    // trunnion-bc: reference position 1 is machine zero.
    let m = machine("trunnion-bc");
    let r = run(&m, "G0 X10. Z100. B30. C90.\nG91 G28 Z0.\n");
    assert_eq!(code(&r), "none");
    let last = r.segments.last().expect("segment");
    // G91: the intermediate point is where Z stands; only Z moves.
    assert!((at(&r, 'Z')).abs() < EPS && (at(&r, 'X') - 10.0).abs() < EPS);
    assert!((last.start[2] - 100.0).abs() < EPS);
    let r = run(&m, "G0 B30. C90.\nG91 G28 B0. C0.\n");
    assert_eq!(code(&r), "none");
    assert!(at(&r, 'B').abs() < EPS && at(&r, 'C').abs() < EPS);
    // G90 with rotary words: through B0 C0 of the program.
    let r = run(&m, "G0 B30. C90.\nG28 X0. Y0. B0.\n");
    assert!(at(&r, 'B').abs() < EPS && (at(&r, 'C') - 90.0).abs() < EPS);
    // G30 likewise (reference position 2 is all zero too).
    let r = run(&m, "G0 Z50. B20.\nG91 G30 Z0. B0.\n");
    assert!(at(&r, 'Z').abs() < EPS && at(&r, 'B').abs() < EPS);
}

#[test]
fn a_bare_g53_is_a_no_op() {
    let m = machine("trunnion-bc");
    let r = run(&m, "G0 X10.\nG53\nG90 G53 G0 Z0.\n");
    assert_eq!(code(&r), "none");
    assert_eq!(r.segments.len(), 1);
}

#[test]
fn g10_without_l_sets_the_length_of_offset_p() {
    let m = machine("mill-3axis");
    let r = run(&m, "G10 P1 R80.\nG43 H1 Z0.\n");
    assert_eq!(code(&r), "none");
    assert!((at(&r, 'Z') - 80.0).abs() < EPS);
    assert!((r.controller.offsets().tool(1).radius).abs() < EPS);
    assert_eq!(code(&run(&m, "G10 P1\n")), "FX0042");
    assert_eq!(code(&run(&m, "G10 P1000 R1.\n")), "PS0031");
}

#[test]
fn inch_programs_take_offsets_in_millimetres_and_g10_in_inches() {
    let m = machine("mill-3axis");
    // The offsets file is in mm: H1 = 100 mm in a G20 program too.
    let r = run(&m, "G20\nG43 H1 Z0.\n");
    assert!((at(&r, 'Z') - 100.0).abs() < EPS);
    // G10 in a G20 program writes inches.
    let r = run(&m, "G20\nG10 L10 P3 R4.\nG43 H3 Z1.\n");
    assert!((r.controller.offsets().tool(3).length - 101.6).abs() < EPS);
    assert!((at(&r, 'Z') - 127.0).abs() < EPS);
    let r = run(&m, "G20\nG10 P3 R4.\n");
    assert!((r.controller.offsets().tool(3).length - 101.6).abs() < EPS);
}
