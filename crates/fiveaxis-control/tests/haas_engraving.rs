//! Haas G47 text engraving on the built-in `haas-umc750` (B0 C0, so the
//! part frame is the machine's shifted by G54): every cut is judged by
//! forward kinematics of the reported axes (`Machine::forward` with tool
//! 1's length), against closed forms of the kernel's font cell (capitals
//! 4 units wide and 6 high, characters every 6 units, descenders to −2;
//! J is the capital height, so a unit is J / 6) and of the rotation by I.

use fiveaxis_control::{Alarm, Motion, Row, RunError, RunOptions, Runner, SliceSource};
use fiveaxis_machine::{Machine, Offsets, ToolOffset, Vec3, builtin};

/// Positions computed by hand and by the kernel agree to this, mm.
const EPS: f64 = 1e-9;
/// Tool 1's length, mm.
const L: f64 = 100.0;
/// G54: on the C axis, 30 mm above the B axis.
const G54: [f64; 3] = [-381.0, -254.0, -400.0];

fn umc() -> Machine {
    builtin("haas-umc750").expect("built-in")
}

fn offsets() -> Offsets {
    let mut o = Offsets::default();
    o.tools.insert(
        1,
        ToolOffset {
            length: L,
            ..ToolOffset::default()
        },
    );
    o.work[0] = Vec3::from(G54);
    o
}

/// A cut or move of the tip, in the part frame (G54 zero), with its kind.
#[derive(Clone, Copy, Debug)]
struct Tip {
    line: u32,
    motion: Motion,
    p: [f64; 3],
    feed: Option<f64>,
}

fn tips(machine: &Machine, rows: &[Row]) -> Vec<Tip> {
    rows.iter()
        .map(|row| {
            let t = machine.forward(&row.joints, L).tip;
            Tip {
                line: row.line,
                motion: row.motion,
                p: [t.x - G54[0], t.y - G54[1], t.z - G54[2]],
                feed: row.feed,
            }
        })
        .collect()
}

struct Run {
    rows: Vec<Row>,
    alarm: Option<Alarm>,
    kept: Vec<(u32, f64)>,
}

fn run_program(machine: &Machine, program: &str) -> Run {
    let mut runner = Runner::new(
        machine,
        offsets(),
        SliceSource::new(program.as_bytes()),
        RunOptions::default(),
    );
    let mut rows = Vec::new();
    let alarm = loop {
        match runner.next_segment() {
            Ok(Some(seg)) => rows.push(seg.row(machine, 1.0)),
            Ok(None) => break None,
            Err(RunError::Alarm { alarm, .. }) => break Some(alarm),
            Err(e) => panic!("a program in memory failed to read: {e}"),
        }
    };
    Run {
        rows,
        alarm,
        kept: runner.kept_variables(),
    }
}

/// The tips of the rows of line `line` of a program that must run.
#[track_caller]
fn engraving(program: &str, line: u32) -> Vec<Tip> {
    let machine = umc();
    let run = run_program(&machine, program);
    assert!(run.alarm.is_none(), "unexpected alarm {:?}", run.alarm);
    tips(&machine, &run.rows)
        .into_iter()
        .filter(|t| t.line == line)
        .collect()
}

#[track_caller]
fn alarm(program: &str) -> Alarm {
    let machine = umc();
    run_program(&machine, program)
        .alarm
        .unwrap_or_else(|| panic!("no alarm in {program}"))
}

/// A metric program: tool 1 above G54's zero, then `g47` on line 4.
fn program(g47: &str) -> String {
    format!("G21 G90 G54 G00 X0. Y0.\nT1 M06\nG43 H01 Z10.\n{g47}\nM30\n")
}

/// The cut points (ends of feed moves at the depth) of an engraving.
fn cuts(t: &[Tip], depth: f64) -> Vec<[f64; 3]> {
    t.iter()
        .filter(|t| t.motion == Motion::Linear && (t.p[2] - depth).abs() < EPS)
        .map(|t| t.p)
        .collect()
}

fn extent(points: &[[f64; 3]], axis: usize) -> (f64, f64) {
    points.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
        (lo.min(p[axis]), hi.max(p[axis]))
    })
}

#[track_caller]
fn close(a: f64, b: f64, what: &str) {
    assert!((a - b).abs() < EPS, "{what}: {a} against {b}");
}

#[test]
fn a_capital_fills_two_thirds_of_j_by_j() {
    // H: strokes at x = 0 and 4 units, from y = 0 to 6; J9. is 1.5 mm a unit.
    let t = engraving(&program("G47 P72 X20. Y5. Z-0.2 R1. J9. F300."), 4);
    let c = cuts(&t, -0.2);
    let (x0, x1) = extent(&c, 0);
    let (y0, y1) = extent(&c, 1);
    close(x0, 20.0, "left");
    close(x1, 20.0 + 4.0 * 1.5, "right: 2/3 J");
    close(y0, 5.0, "baseline");
    close(y1, 5.0 + 9.0, "top: J");
}

#[test]
fn characters_follow_every_j_and_descenders_reach_a_third_of_j_below() {
    // "HgH": the third character starts 2 J after the first; g's tail is
    // 2 units (J / 3) below the baseline; J 6 mm is 1 mm a unit.
    let t = engraving(&program("G47 P0 (HgH) X0. Y0. Z-0.1 R2. J6. F300."), 4);
    let c = cuts(&t, -0.1);
    let (x0, x1) = extent(&c, 0);
    let (y0, y1) = extent(&c, 1);
    close(x0, 0.0, "left");
    close(x1, 2.0 * 6.0 + 4.0, "right of the third character");
    close(y0, -2.0, "descender");
    close(y1, 6.0, "capital height");
    // Blanks at the ends of the comment are not engraved; inner blanks are
    // a character's advance.
    let spaced = engraving(&program("G47 P0 (  H H ) X0. Y0. Z-0.1 R2. J6. F300."), 4);
    let (_, right) = extent(&cuts(&spaced, -0.1), 0);
    close(right, 2.0 * 6.0 + 4.0, "H, a space, H");
}

#[test]
fn rotation_by_i_turns_every_cut_about_the_start() {
    // The same text at I0 and I30: each point of the turned run is the
    // plain run's point turned by 30° about the start (closed form).
    let plain = engraving(&program("G47 P0 (A1) X10. Y-5. Z-0.3 R1. J4. F200."), 4);
    let turned = engraving(
        &program("G47 P0 (A1) X10. Y-5. Z-0.3 R1. J4. F200. I30."),
        4,
    );
    assert_eq!(plain.len(), turned.len());
    let (s, c) = 30_f64.to_radians().sin_cos();
    for (a, b) in plain.iter().zip(&turned).skip(1) {
        let (u, v) = (a.p[0] - 10.0, a.p[1] + 5.0);
        close(b.p[0], 10.0 + u * c - v * s, "x");
        close(b.p[1], -5.0 + u * s + v * c, "y");
        close(b.p[2], a.p[2], "z");
        assert_eq!(a.motion, b.motion);
    }
    // I-90: the baseline runs along −Y, the letters' up along +X.
    let down = engraving(&program("G47 P45 X0. Y0. Z-0.3 R1. J6. F200. I-90."), 4);
    let c = cuts(&down, -0.3);
    close(c[0][0], 3.0, "the minus sign's height turns to +X");
    close(c[0][1], 0.0, "its start");
    close(c[1][0], 3.0, "its end's height");
    close(c[1][1], -4.0, "its end, 4 units along -Y");
}

#[test]
fn retracts_go_to_r_plunges_to_z_and_the_tool_ends_at_r() {
    let t = engraving(&program("G47 P0 (T.) X5. Y0. Z-0.2 R1.5 J6. F300. E50."), 4);
    // First the positioning at the level where the tool stood, then R.
    assert_eq!(t[0].motion, Motion::Rapid);
    close(t[0].p[2], 10.0, "positioning at the initial level");
    close(t[0].p[0], 5.0, "X start");
    close(t[1].p[2], 1.5, "down to R");
    for tip in &t[1..] {
        match tip.motion {
            Motion::Rapid => close(tip.p[2], 1.5, "every rapid at R"),
            _ => close(tip.p[2], -0.2, "every feed at Z"),
        }
    }
    // Plunges at E, cuts along the strokes at F (mm/min).
    let plunges: Vec<&Tip> = t
        .windows(2)
        .filter(|w| w[0].motion == Motion::Rapid && w[1].motion == Motion::Linear)
        .map(|w| &w[1])
        .collect();
    // T has two strokes, the full stop one dot.
    assert_eq!(plunges.len(), 3);
    assert!(plunges.iter().all(|p| p.feed == Some(50.0)));
    assert!(
        t.iter()
            .filter(|x| x.motion == Motion::Linear && !plunges.iter().any(|p| std::ptr::eq(*p, *x)))
            .all(|x| x.feed == Some(300.0))
    );
    let last = t.last().expect("the engraving moves");
    assert_eq!(last.motion, Motion::Rapid);
    close(last.p[2], 1.5, "ends at R");
    // The dot of the full stop: plunged and retracted in place at
    // (5 + 6 + 2, 0).
    close(last.p[0], 13.0, "the dot's x");
    close(last.p[1], 0.0, "the dot's y");
}

#[test]
fn incremental_g47_reads_r_from_the_tool_and_z_from_r() {
    // G91: X Y from where the tool stands (0, 0), R −8.5 from Z10 is 1.5,
    // Z −1.7 from R is −0.2: the same moves as the absolute block.
    let abs = engraving(&program("G47 P0 (T) X3. Y4. Z-0.2 R1.5 J6. F300."), 4);
    let inc = engraving(&program("G91 G47 P0 (T) X3. Y4. Z-1.7 R-8.5 J6. F300."), 4);
    assert_eq!(abs.len(), inc.len());
    for (a, b) in abs.iter().zip(&inc) {
        for k in 0..3 {
            close(a.p[k], b.p[k], "G90 and G91");
        }
    }
}

#[test]
fn inch_words_and_the_default_height_of_one_inch() {
    // G20: X1. is 25.4 mm; without J the text is 1 inch high.
    let t = engraving(
        "G20 G90 G54 G00 X0. Y0.\nT1 M06\nG43 H01 Z1.\nG47 P72 X1. Y0. Z-0.01 R0.05 F10. E5.\nM30\n",
        4,
    );
    let c = cuts(&t, -0.254);
    let (x0, x1) = extent(&c, 0);
    let (_, y1) = extent(&c, 1);
    close(x0, 25.4, "X1.");
    close(x1, 25.4 + 25.4 * 4.0 / 6.0, "2/3 inch wide");
    close(y1, 25.4, "1 inch high");
    assert!(
        t.iter().any(|x| x.feed == Some(5.0 * 25.4)),
        "E in inch/min"
    );
}

#[test]
fn the_serial_number_grows_by_one_with_each_engraving() {
    // (1234) only sets the number (the manual: "nothing is engraved");
    // (####) then engraves 1234 and (####) again 1235, which must cut
    // exactly where P0 (1234) and P0 (1235) cut; #599 is left at 1236.
    let serial = "G21 G90 G54 G00 X0. Y0.\nT1 M06\nG43 H01 Z10.\n\
                  G47 P1 (1234)\n\
                  G47 P1 (####) X0. Y0. Z-0.1 R1. J6. F300.\n\
                  G47 P1 (####) X0. Y20. Z-0.1 R1. J6. F300.\nM30\n";
    let literal = "G21 G90 G54 G00 X0. Y0.\nT1 M06\nG43 H01 Z10.\n\n\
                   G47 P0 (1234) X0. Y0. Z-0.1 R1. J6. F300.\n\
                   G47 P0 (1235) X0. Y20. Z-0.1 R1. J6. F300.\nM30\n";
    let machine = umc();
    let a = run_program(&machine, serial);
    let b = run_program(&machine, literal);
    assert!(a.alarm.is_none() && b.alarm.is_none(), "{:?}", a.alarm);
    let (ta, tb) = (tips(&machine, &a.rows), tips(&machine, &b.rows));
    assert!(
        ta.iter().all(|t| t.line != 4),
        "the setting block moves nothing"
    );
    assert_eq!(ta.len(), tb.len());
    for (x, y) in ta.iter().zip(&tb) {
        assert_eq!(x.line, y.line);
        for k in 0..3 {
            close(x.p[k], y.p[k], "serial against literal");
        }
    }
    assert!(a.kept.contains(&(599, 1236.0)), "{:?}", a.kept);
}

#[test]
fn the_serial_number_from_599_is_cut_or_filled_to_its_digits() {
    // #599 = 41 with (###) engraves 041; #599 = 12345 with (####) 2345.
    let machine = umc();
    let run = |set: &str, format: &str| {
        let p = format!(
            "G21 G90 G54 G00 X0. Y0.\nT1 M06\nG43 H01 Z10.\n#599={set}\nG47 P1 ({format}) X0. Y0. Z-0.1 R1. J6. F300.\nM30\n"
        );
        let r = run_program(&machine, &p);
        assert!(r.alarm.is_none(), "{:?}", r.alarm);
        (tips(&machine, &r.rows), r.kept)
    };
    let lit = |text: &str| {
        let p = format!(
            "G21 G90 G54 G00 X0. Y0.\nT1 M06\nG43 H01 Z10.\n\nG47 P0 ({text}) X0. Y0. Z-0.1 R1. J6. F300.\nM30\n"
        );
        tips(&machine, &run_program(&machine, &p).rows)
    };
    for (set, format, shown, next) in [
        ("41", "###", "041", 42.0),
        ("12345", "####", "2345", 12346.0),
    ] {
        let (t, kept) = run(set, format);
        let l = lit(shown);
        assert_eq!(t.len(), l.len(), "{shown}");
        for (x, y) in t.iter().zip(&l) {
            for k in 0..3 {
                close(x.p[k], y.p[k], shown);
            }
        }
        assert!(kept.contains(&(599, next)), "{kept:?}");
    }
}

#[test]
fn g47_refuses_bad_words_with_its_alarms() {
    let cases = [
        // No P, P out of its values, J below 0.001 in, I beyond 360.
        ("G47 (A) X0. Y0. Z-0.1 R1. F100.", "FX0001"),
        ("G47 P5 X0. Y0. Z-0.1 R1. F100.", "FX0014"),
        ("G47 P127 X0. Y0. Z-0.1 R1. F100.", "FX0014"),
        ("G47 P0. (A) X0. Y0. Z-0.1 R1. F100.", "FX0013"),
        ("G47 P65 J0.01 X0. Y0. Z-0.1 R1. F100.", "FX0014"),
        ("G47 P65 I400. X0. Y0. Z-0.1 R1. F100.", "FX0014"),
        ("G47 P65 E0 X0. Y0. Z-0.1 R1. F100.", "FX0014"),
        // No depth; the depth not below R.
        ("G47 P65 X0. Y0. R1. F100.", "FX0130"),
        ("G47 P65 X0. Y0. Z2. R1. F100.", "FX0014"),
        // P0 without a comment, with an empty one, with a character
        // outside the font or a parenthesis.
        ("G47 P0 X0. Y0. Z-0.1 R1. F100.", "FX0130"),
        ("G47 P0 (  ) X0. Y0. Z-0.1 R1. F100.", "FX0130"),
        ("G47 P0 (CAF\u{c9}) X0. Y0. Z-0.1 R1. F100.", "FX0014"),
        // P1 with a format that is neither # signs nor digits.
        ("G47 P1 (SN#) X0. Y0. Z-0.1 R1. F100.", "FX0014"),
        ("G47 P1 (##########) X0. Y0. Z-0.1 R1. F100.", "FX0014"),
        // No feed.
        ("G47 P65 X0. Y0. Z-0.1 R1.", "FX0020"),
        // Not with cutter compensation or a rotary word; not with a
        // motion code.
        ("D1 G41 G01 X1. F100.\nG47 P65 X0. Y0. Z-0.1 R1.", "FX0133"),
        ("G47 P65 X0. Y0. Z-0.1 R1. F100. C10.", "FX0133"),
        ("G01 G47 P65 X0. Y0. Z-0.1 R1. F100.", "FX0015"),
        // An unknown word.
        ("G47 P65 X0. Y0. Z-0.1 R1. F100. Q1.", "FX0012"),
    ];
    for (g47, code) in cases {
        let a = alarm(&program(g47));
        assert_eq!(a.code.to_string(), code, "{g47}: {a}");
    }
    // The nested Haas comment reading keeps inner parentheses: refused
    // (the manual engraves them with P40 / P41).
    let a = alarm(&program("G47 P0 (A(B)) X0. Y0. Z-0.1 R1. F100."));
    assert!(a.message.contains("P40"), "{a}");
}

#[test]
fn g47_is_not_a_code_of_the_fanuc_control() {
    let machine = builtin("trunnion-ac").expect("built-in");
    let run = run_program(
        &machine,
        "G21 G90 G54 G00 X0. Y0.\nG47 P65 X0. Y0. Z-0.1 R1. F100.\nM30\n",
    );
    assert_eq!(run.alarm.expect("alarm").code.to_string(), "PS0010");
}

#[test]
fn a_g47_line_with_macro_expressions_engraves_its_comment() {
    let plain = engraving(&program("G47 P0 (AB) X2. Y3. Z-0.1 R1. J6. F300."), 4);
    let macro_line = engraving(
        "G21 G90 G54 G00 X0. Y0.\nT1 M06\n#1=2.\nG43 H01 Z10.\nG47 P0 ( AB ) X#1 Y[#1+1] Z-0.1 R1. J6. F300.\nM30\n",
        5,
    );
    assert_eq!(plain.len(), macro_line.len());
    for (a, b) in plain.iter().zip(&macro_line) {
        for k in 0..3 {
            close(a.p[k], b.p[k], "macro line");
        }
    }
}

/// A small seeded generator (xorshift64*), so that the property runs are
/// the same on every machine.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in [lo, hi), rounded to 1e-3 (a word with three decimals).
    fn value(&mut self, lo: f64, hi: f64) -> f64 {
        let u = (self.next() >> 11) as f64 / (1u64 << 53) as f64;
        ((lo + u * (hi - lo)) * 1000.0).round() / 1000.0
    }
}

#[test]
fn every_cut_of_random_texts_lies_in_the_turned_cells_and_every_rapid_at_r() {
    // For random texts, starts, angles and heights: turned back by I about
    // the start, every cut point lies in the text's cells (u from 0 to
    // (n − 1) J + 2/3 J, v from −J/3 to J), at the depth; every rapid
    // after the first two is at R.
    let mut rng = Rng(0x5EED_0047);
    for case in 0..60 {
        let n = 1 + (rng.next() % 8) as usize;
        let text: String = (0..n)
            .map(|_| {
                let c = 32 + (rng.next() % 95) as u8;
                if c == b'(' || c == b')' {
                    'Z'
                } else {
                    char::from(c)
                }
            })
            .collect();
        let (x, y) = (rng.value(-40.0, 40.0), rng.value(-40.0, 40.0));
        let angle = rng.value(-360.0, 360.0);
        let j = rng.value(0.5, 12.0);
        let (r, z) = (rng.value(0.5, 3.0), rng.value(-1.0, -0.05));
        let t = engraving(
            &program(&format!(
                "G47 P0 (X{text}X) X{x:.3} Y{y:.3} Z{z:.3} R{r:.3} I{angle:.3} J{j:.3} F400."
            )),
            4,
        );
        let chars = n + 2;
        let (s, c) = angle.to_radians().sin_cos();
        let cuts = t.iter().filter(|t| t.motion == Motion::Linear);
        let mut count = 0;
        for cut in cuts {
            let (dx, dy) = (cut.p[0] - x, cut.p[1] - y);
            let (u, v) = (dx * c + dy * s, -dx * s + dy * c);
            let what = format!("case {case}: {text:?} at {:?}", cut.p);
            assert!(
                u > -1e-9 && u < (chars as f64 - 1.0) * j + j * 4.0 / 6.0 + 1e-9,
                "{what}: u {u}"
            );
            assert!(v > -j / 3.0 - 1e-9 && v < j + 1e-9, "{what}: v {v}");
            close(cut.p[2], z, &what);
            count += 1;
        }
        // The X at both ends is cut: at least its two strokes' points.
        assert!(count >= 4, "case {case}");
        for rapid in t.iter().skip(2).filter(|t| t.motion == Motion::Rapid) {
            close(rapid.p[2], r, &format!("case {case}: rapid at R"));
        }
    }
}

#[test]
fn in_feature_coordinates_the_text_lies_in_the_frames_plane() {
    // G268 turned 90° about Z with its origin at (10, 0, 0): a frame point
    // (u, v, w) is the part point (10 − v, u, w). The same engraving in the
    // frame and plain must agree point by point under that map.
    let plain = engraving(&program("G47 P0 (F7) X2. Y3. Z-0.2 R1. J6. F300."), 4);
    let framed = engraving(
        "G21 G90 G54 G00 X0. Y0.\nT1 M06\nG43 H01 Z10.\nG268 X10. Y0. Z0. I0. J0. K90.\n\
         G00 X0. Y0. Z10.\nG47 P0 (F7) X2. Y3. Z-0.2 R1. J6. F300.\nG269\nM30\n",
        6,
    );
    assert_eq!(plain.len(), framed.len());
    for (a, b) in plain.iter().zip(&framed) {
        close(b.p[0], 10.0 - a.p[1], "x");
        close(b.p[1], a.p[0], "y");
        close(b.p[2], a.p[2], "z");
    }
}
