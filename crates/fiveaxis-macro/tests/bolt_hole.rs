//! A bolt-hole circle macro (after the manual's example) run line by line
//! through `parse_statement`, `Variables`, `arguments` and `evaluate_block`
//! by a minimal runner, checked against closed-form cos/sin.

mod common;

use common::TestSystem;
use fiveaxis_gcode::{Block, parse_line};
use fiveaxis_macro::{
    MacroSettings, Statement, Variables, arguments, evaluate_block, is_macro_line, loop_end,
    parse_statement,
};

/// O9100: drills #11 (H) holes on a circle of radius #18 (R) centred on
/// #24, #25 (X, Y), the first at #1 (A) degrees, #2 (B) degrees apart, to
/// depth #26 (Z) at feed #9 (F).
const BOLT_HOLE: [&str; 9] = [
    "N1 #30=1 (HOLE COUNTER)",
    "WHILE [#30 LE ABS[#11]] DO 1",
    "  #31 = #1 + [#30 - 1] * #2",
    "  #32 = #24 + #18 * COS[#31]",
    "  #33 = #25 + #18 * SIN[#31]",
    "  G81 X#32 Y#33 Z#26 R2. F#9",
    "  #30 = #30 + 1",
    "END 1",
    "M99",
];

/// Runs the macro; returns the NC blocks it produced.
fn run(
    program: &[&str],
    vars: &mut Variables,
    sys: &mut TestSystem,
    s: &MacroSettings,
) -> Vec<Block> {
    let mut out = Vec::new();
    let mut loops: Vec<(u8, usize)> = Vec::new();
    let mut pc = 0;
    let mut steps = 0;
    while let Some(text) = program.get(pc) {
        steps += 1;
        assert!(steps < 10_000, "runaway");
        let line = parse_statement(text.as_bytes(), pc as u32 + 1).expect("parse");
        pc += 1;
        match &line.statement {
            Statement::Assign { target, value } => {
                vars.assign(target, value, line.comment.as_deref(), sys, s)
                    .expect("assign");
            }
            Statement::While { cond, id } => {
                if vars.eval_condition(cond, sys, s).expect("cond") {
                    loops.push((*id, pc - 1));
                } else {
                    while program
                        .get(pc)
                        .is_some_and(|t| loop_end(t.as_bytes()) != Some(*id))
                    {
                        pc += 1;
                    }
                    pc += 1;
                }
            }
            Statement::End { id } => {
                let (open, start) = loops.pop().expect("END without WHILE");
                assert_eq!(open, *id);
                pc = start;
            }
            Statement::Nc(nc) => {
                let mut block = Block::default();
                evaluate_block(nc, vars, sys, s, &mut block).expect("block");
                if block.word(b'M').is_some_and(|m| m.value == 99.0) {
                    break;
                }
                out.push(block);
            }
            other => panic!("unexpected {other:?}"),
        }
    }
    out
}

#[test]
fn bolt_hole_circle() {
    let s = MacroSettings::default();
    let mut sys = TestSystem::default();
    let mut vars = Variables::new(4);
    let call = "G65 P9100 X100. Y50. Z-5. R40. A15. B45. H6 F100.";
    assert!(!is_macro_line(call.as_bytes()));
    let mut block = Block::default();
    parse_line(call.as_bytes(), 1, &mut block).expect("call");
    vars.push_frame(arguments(&block).expect("args"))
        .expect("push");
    let blocks = run(&BOLT_HOLE, &mut vars, &mut sys, &s);
    assert!(vars.pop_frame());

    assert_eq!(blocks.len(), 6);
    for (i, b) in blocks.iter().enumerate() {
        let angle = (15.0 + i as f64 * 45.0_f64).to_radians();
        let x = b.word(b'X').expect("X");
        let y = b.word(b'Y').expect("Y");
        assert!(
            (x.value - (100.0 + 40.0 * angle.cos())).abs() < 1e-9,
            "hole {i}: X {}",
            x.value
        );
        assert!(
            (y.value - (50.0 + 40.0 * angle.sin())).abs() < 1e-9,
            "hole {i}: Y {}",
            y.value
        );
        assert!(x.decimal_point && y.decimal_point);
        assert_eq!(b.word(b'Z').map(|w| w.value), Some(-5.0));
        assert_eq!(b.word(b'F').map(|w| w.value), Some(100.0));
        assert_eq!(
            b.word(b'G').and_then(|w| w.code),
            Some(fiveaxis_gcode::Code::new(81, 0))
        );
        assert_eq!(b.line, 6);
    }
    // The counter went one past the last hole; the caller's locals are back.
    assert_eq!(vars.depth(), 0);
    assert_eq!(vars.get(30, &sys, &s).expect("get"), None);
}

#[test]
fn no_holes_skips_the_loop() {
    let s = MacroSettings::default();
    let mut sys = TestSystem::default();
    let mut vars = Variables::new(4);
    let mut block = Block::default();
    parse_line(b"G65 P9100 X0 Y0 R10. H0", 1, &mut block).expect("call");
    vars.push_frame(arguments(&block).expect("args"))
        .expect("push");
    assert!(run(&BOLT_HOLE, &mut vars, &mut sys, &s).is_empty());
    assert_eq!(vars.get(30, &sys, &s).expect("get"), Some(1.0));
}
