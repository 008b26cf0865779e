//! CL data of each major CAM system (`tests/cl/`, small files written by
//! hand in each system's format, the source named at the top of each),
//! converted to a TCPC program and run by the kernel: every point the
//! file programs (hand-computed here: inch data scaled, MSYS applied,
//! drilling cycles carried out) is reached, in order, at the end of a
//! block (`Segment::row`, forward kinematics); then posted to machine axes
//! for the built-in swivel-head machine and judged against the TCPC run
//! (`common::judge`), and the same points reached by the machine-axis
//! program. Words skipped are warned with their first line.

mod common;

use common::{Rules, Side, judge, run};
use fiveaxis_control::Segment;
use fiveaxis_machine::{Machine, Offsets, ToolOffset, Vec3, builtin};
use fiveaxis_post::apt::{Converted, to_tcpc_mapped};
use fiveaxis_post::{Axes, PostOptions};

/// How close a block end of the TCPC run must be to the point, mm (the
/// program is written with 6 decimals).
const POINT_EPS: f64 = 1e-5;
/// How close the tool direction must be, as a vector difference.
const DIR_EPS: f64 = 1e-6;
/// The same for the machine-axis program (4 decimals, 5 for degrees).
const POST_POINT_EPS: f64 = 1e-3;
const POST_DIR_EPS: f64 = 1e-5;

/// G54 of the runs: the part zero 50 mm above the table.
const WORK: Vec3 = Vec3::new(0.0, 0.0, 50.0);
/// The length of every tool, mm.
const TOOL_LENGTH: f64 = 100.0;

/// Offsets with tools 1 to 9 of [`TOOL_LENGTH`] and G54 at [`WORK`].
fn offsets() -> Offsets {
    let mut o = Offsets::default();
    for n in 1..=9 {
        o.tools.insert(
            n,
            ToolOffset {
                length: TOOL_LENGTH,
                ..ToolOffset::default()
            },
        );
    }
    o.work[0] = WORK;
    o
}

/// The 1-based line of the first line of `text` starting with `prefix`.
fn line_of(text: &str, prefix: &str) -> u32 {
    let index = text
        .lines()
        .position(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no line starts with {prefix}"));
    u32::try_from(index + 1).expect("small")
}

/// How many of `targets` (tip in the part frame, G54, and direction)
/// the block ends of `segments` reach in order. `gauge`: a machine-axis
/// run in G49, its tip that of the tools' 100 mm (the table frame's,
/// less G54), as the judge takes it.
fn reached(
    machine: &Machine,
    segments: &[Segment],
    targets: &[(Vec3, Vec3)],
    (point_eps, dir_eps): (f64, f64),
    gauge: bool,
) -> usize {
    let mut next = 0;
    for seg in segments {
        let (tip, dir) = if gauge {
            let pose = machine.forward(&seg.end, TOOL_LENGTH);
            (pose.tip - WORK, pose.dir)
        } else {
            let row = seg.row(machine, 1.0);
            (row.tip, row.dir)
        };
        if let Some((p, d)) = targets.get(next)
            && (tip - p).norm() <= point_eps
            && (dir - d).norm() <= dir_eps
        {
            next += 1;
        }
    }
    next
}

/// Converts `text`, checks the points on the TCPC run and on the
/// machine-axis program posted from it, and gives the conversion.
fn check(name: &str, text: &str, targets: &[(Vec3, Vec3)]) -> Converted {
    let converted = to_tcpc_mapped(text, name).unwrap_or_else(|e| panic!("{name}: {e}"));
    let program = &converted.program;
    let machine = builtin("head-table-bc").expect("built-in");
    let offsets = offsets();
    let segments =
        run(&machine, &offsets, program, None, true).unwrap_or_else(|e| panic!("{name}: {e:?}"));
    let next = reached(&machine, &segments, targets, (POINT_EPS, DIR_EPS), false);
    assert_eq!(
        next,
        targets.len(),
        "{name}: point {} not reached: {:?}\n{program}",
        next + 1,
        targets.get(next)
    );
    let options = PostOptions {
        origin: WORK,
        axes: Axes::Post { great_circle: true },
        ..PostOptions::default()
    };
    let (text, result) = common::post(&machine, &machine, &segments, options);
    assert_eq!(result.unresolved, 0, "{name}");
    assert_eq!(result.out_of_limits, 0, "{name}");
    let rules = Rules::great_circle_of(&options);
    let side = |text| Side {
        machine: &machine,
        offsets: &offsets,
        text,
    };
    let worst = judge(side(program), side(&text), &rules)
        .unwrap_or_else(|e| panic!("{name}: {}", e.chars().take(3000).collect::<String>()));
    eprintln!("{name}: {worst:?}");
    let axes = run(&machine, &offsets, &text, None, true)
        .unwrap_or_else(|e| panic!("{name} machine axes: {e:?}"));
    let next = reached(
        &machine,
        &axes,
        targets,
        (POST_POINT_EPS, POST_DIR_EPS),
        true,
    );
    assert_eq!(
        next,
        targets.len(),
        "{name} machine axes: point {} not reached: {:?}\n{text}",
        next + 1,
        targets.get(next)
    );
    converted
}

fn v(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x, y, z)
}

fn unit(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x, y, z).normalize()
}

/// (word, line, note) of each warning.
fn warnings(c: &Converted) -> Vec<(String, u32, bool)> {
    c.warnings
        .iter()
        .map(|w| (w.word.clone(), w.line, w.note))
        .collect()
}

#[test]
fn creo_cl_file() {
    let text = include_str!("cl/creo.ncl");
    let z = Vec3::z();
    let tilt = unit(0.0, 0.258_819_045_1, 0.965_925_826_3);
    let targets = [
        (v(10.0, 0.0, 20.0), z),
        (v(10.0, 0.0, 0.0), z),
        // CIRCLE/x,y,z,r about the tool axis: a quarter counter-clockwise.
        (v(0.0, 10.0, 0.0), z),
        (v(-10.0, 10.0, 0.0), tilt),
        (v(-20.0, 10.0, 5.0), z),
        (v(20.0, 20.0, 20.0), z),
        // CYCLE/DRILL, DEPTH 8, CLEAR 2: clear, bottom, clear per hole.
        (v(20.0, 20.0, 2.0), z),
        (v(20.0, 20.0, -8.0), z),
        (v(20.0, 20.0, 2.0), z),
        (v(30.0, 20.0, 2.0), z),
        (v(30.0, 20.0, -8.0), z),
        (v(30.0, 20.0, 2.0), z),
    ];
    let c = check("creo.ncl", text, &targets);
    let p = &c.program;
    // REMARK without a slash, a $$-> line continued over three lines.
    assert!(
        p.contains("(REMARK FIVEAXIS TEST PART - CREO FORMAT)"),
        "{p}"
    );
    assert!(
        p.contains("0.0000000000, 0.0000000000, 1.0000000000, 0.0000000000)"),
        "{p}"
    );
    // 0.05 mm per revolution at 2000 rpm: 100 mm/min; the cycle's feed.
    assert!(
        p.contains("Y0.000000 Z0.000000 I0.0000000 J0.0000000 K1.0000000 F100\n"),
        "{p}"
    );
    assert!(
        p.contains("G17 G3 X0.000000 Y10.000000 Z0.000000 R10.000000"),
        "{p}"
    );
    assert!(
        p.contains("Z-8.000000 I0.0000000 J0.0000000 K1.0000000 F120\n"),
        "{p}"
    );
    assert!(
        p.contains("T1 M6") && p.contains("S2000 M3") && p.contains("M8\n"),
        "{p}"
    );
    assert_eq!(warnings(&c), []);
}

#[test]
fn catia_apt_file() {
    let text = include_str!("cl/catia.aptsource");
    let z = Vec3::z();
    let d1 = unit(0.0, -0.258_819, 0.965_926);
    let d2 = unit(0.0, -0.5, 0.866_025);
    let targets = [
        // FROM (its point number in columns 73-80 dropped).
        (v(0.0, 0.0, 50.0), z),
        (v(20.0, 0.0, 10.0), z),
        (v(20.0, 0.0, 0.0), z),
        (v(30.0, 0.0, 0.0), d1),
        (v(30.0, 15.0, 0.0), d1),
        // MULTAX/OFF: the tool along TLAXIS.
        (v(20.0, 15.0, 5.0), d2),
        (v(20.0, 15.0, 0.0), z),
        // About -Z: a quarter clockwise.
        (v(10.0, 25.0, 0.0), z),
        (v(10.0, 25.0, 30.0), z),
    ];
    let c = check("catia.aptsource", text, &targets);
    let p = &c.program;
    assert!(p.contains("(PARTNO PART OPERATION.1)"), "{p}");
    assert!(
        p.contains("(PPRINT OPERATION NAME = MULTI-AXIS SWEEPING.1)"),
        "{p}"
    );
    assert!(
        p.contains("G17 G2 X10.000000 Y25.000000 Z0.000000 R10.000000"),
        "{p}"
    );
    assert!(p.contains("T2 M6") && p.contains("G43.5 H2 G0 X0.000000 Y0.000000 Z50.000000"));
    assert_eq!(
        warnings(&c),
        [
            ("INTOL".into(), line_of(text, "INTOL/"), true),
            ("OUTTOL".into(), line_of(text, "OUTTOL/"), true),
            ("END".into(), line_of(text, "END"), true),
        ]
    );
}

#[test]
fn nx_clsf_file() {
    let text = include_str!("cl/nx.cls");
    // MSYS: origin (10, -5, 2), X along +Y, Y along -X: a frame point
    // (x, y, z) is (10 - y, -5 + x, 2 + z), a direction (-j, i, k).
    let z = Vec3::z();
    let tilt = unit(-0.5, 0.0, 0.866_025_4);
    let targets = [
        (v(10.0, -5.0, 32.0), z),
        (v(10.0, -5.0, 2.0), z),
        (v(10.0, 15.0, 2.0), tilt),
        (v(0.0, 15.0, 2.0), tilt),
        // The circle about frame (10, 10, 0) = (0, 5, 2), counter-clockwise
        // about Z, to frame (10, 20, 0).
        (v(-10.0, 5.0, 2.0), tilt),
        (v(-10.0, 5.0, 27.0), z),
    ];
    let c = check("nx.cls", text, &targets);
    let p = &c.program;
    assert!(
        p.contains("G17 G3 X-10.000000 Y5.000000 Z2.000000 R10.000000"),
        "{p}"
    );
    assert!(
        p.contains("T3 M6") && p.contains("S8000 M3") && p.contains(" F250\n"),
        "{p}"
    );
    assert_eq!(warnings(&c), []);
}

#[test]
fn solidworks_cam_file() {
    let text = include_str!("cl/solidworks.apt");
    let z = Vec3::z();
    let tilt = unit(0.0, -0.5, 0.866_025);
    let targets = [
        (v(40.0, 0.0, 25.0), z),
        (v(40.0, 0.0, 2.5), z),
        (v(40.0, 0.0, -3.0), z),
        (v(40.0, 20.0, -3.0), z),
        // About -Z from (40, 20) to (30, 30) round (30, 20): three quarters.
        (v(30.0, 30.0, -3.0), z),
        (v(20.0, 30.0, -3.0), z),
        // About +Y in the ZX plane (Z turning to X) from +Z round to -X
        // of the centre: three quarters.
        (v(10.0, 30.0, -13.0), z),
        (v(10.0, 30.0, 20.0), z),
        (v(0.0, -20.0, 20.0), tilt),
        (v(0.0, -20.0, 5.0), tilt),
        (v(0.0, -40.0, 5.0), tilt),
        (v(0.0, -40.0, 30.0), z),
    ];
    let c = check("solidworks.apt", text, &targets);
    let p = &c.program;
    assert!(
        p.contains("G17 G2 X30.000000 Y30.000000 Z-3.000000 R-10.000000"),
        "{p}"
    );
    assert!(
        p.contains("G18 G3 X10.000000 Y30.000000 Z-13.000000 R-10.000000"),
        "{p}"
    );
    assert!(p.contains("(CUTCOM/ON,LEFT)") && !p.contains("G41"), "{p}");
    assert!(p.contains("T5 M6") && p.contains("G43.5 H5"), "{p}");
    assert_eq!(warnings(&c), []);
}

#[test]
fn mastercam_inch_file() {
    let text = include_str!("cl/mastercam.apt");
    let z = Vec3::z();
    let tilt = unit(0.0, 0.5, 0.866_025_4);
    // Inches: 25.4 mm each.
    let targets = [
        (v(25.4, 12.7, 25.4), z),
        (v(25.4, 12.7, 0.0), z),
        (v(50.8, 12.7, 0.0), z),
        (v(50.8, 38.1, 0.0), tilt),
        (v(50.8, 38.1, 25.4), z),
        // CYCLE/DRILL depth 0.5 in = 12.7 mm, clearance 0.1 in = 2.54 mm.
        (v(12.7, 25.4, 2.54), z),
        (v(12.7, 25.4, -12.7), z),
        (v(12.7, 25.4, 2.54), z),
        (v(12.7, 50.8, 2.54), z),
        (v(12.7, 50.8, -12.7), z),
        (v(12.7, 50.8, 2.54), z),
    ];
    let c = check("mastercam.apt", text, &targets);
    let p = &c.program;
    // FEDRAT/IPM,20: 508 mm/min; 0.004 in per revolution at 2500 rpm:
    // 254 mm/min; the cycle's 8 in/min: 203.2 mm/min.
    assert!(
        p.contains("Z0.000000 I0.0000000 J0.0000000 K1.0000000 F508\n"),
        "{p}"
    );
    assert!(
        p.contains("X50.800000 Y12.700000 Z0.000000 I0.0000000 J0.0000000 K1.0000000 F254\n"),
        "{p}"
    );
    assert!(p.contains(" F203.2\n"), "{p}");
    assert!(p.contains("(PPRINT TOOL 4 - 1/4 FLAT ENDMILL)"), "{p}");
    assert!(
        p.contains("M1\n") && p.contains("T4 M6") && p.contains("S2500 M3"),
        "{p}"
    );
    assert!(!p.contains("G20"), "{p}");
    assert_eq!(warnings(&c), [("END".into(), line_of(text, "END"), true)]);
}

/// Records continued with `$` and a `$$` after a record's text are read
/// as one record; unknown words are warned once per word at their first
/// line; a word that would move the tool is an error with its line and
/// word.
#[test]
fn continuations_comments_and_unknown_words() {
    let text = "FEDRAT/ 600 , MMPM $$ the feed\nGOTO/ 1, 2,$\n 3, 0, 0,$ $$ half way\n 1\n\
                FOO/1\nBAR\nFOO/2\nGOTO/4,5,6\nFINI\n";
    let c = to_tcpc_mapped(text, "t").expect("converts");
    assert!(
        c.program
            .contains("G1 X1.000000 Y2.000000 Z3.000000 I0.0000000 J0.0000000 K1.0000000 F600\n"),
        "{}",
        c.program
    );
    assert_eq!(
        warnings(&c),
        [("FOO".into(), 5, false), ("BAR".into(), 6, false)]
    );
    assert_eq!(c.warnings[0].count, 2);
    assert_eq!(
        c.warnings[0].to_string(),
        "line 5: FOO: not a word this reader knows (no motion assumed): skipped (2 records, the first here)"
    );
    let e = to_tcpc_mapped("FEDRAT/100\nGOTO/1,2,3\n\nTRANS/0,0,10\n", "t").expect_err("refused");
    assert_eq!((e.line, e.word.as_str()), (4, "TRANS"));
    assert!(e.to_string().starts_with("line 4: `TRANS`"), "{e}");
    let e = to_tcpc_mapped("FEDRAT/100\nGOTO/1,2\n", "t").expect_err("refused");
    assert_eq!(
        e.to_string(),
        "line 2: GOTO: expected 3 to 6 numbers, found `1,2`"
    );
    // The message names the word (the Python binding reports it alone).
    assert_eq!(e.message, "GOTO: expected 3 to 6 numbers, found `1,2`");
    // Coolants without a standard M code: a note, no M code.
    let c = to_tcpc_mapped("COOLNT/THRU,HIGH\nCOOLNT/ON,LOW\n", "t").expect("converts");
    assert_eq!(warnings(&c), [("COOLNT".into(), 1, true)]);
    assert!(
        c.program.contains("M8\n") && !c.program.contains("M7"),
        "{}",
        c.program
    );
}

proptest::proptest! {
    #![proptest_config(common::config(256))]

    /// Any text made of CL words, numbers, separators, continuations and
    /// comments converts or is refused with a line inside the file and
    /// never panics; the program converted runs or alarms, never panics.
    #[test]
    fn hostile_cl_text_never_panics(
        lines in proptest::collection::vec(
            proptest::collection::vec(
                proptest::sample::select(vec![
                    "GOTO/", "FROM/", "GODLTA/", "CIRCLE/", "CYCLE/", "DRILL", "DEPTH", "CLEAR",
                    "RAPTO", "OFF", "RAPID", "FEDRAT/", "MMPR", "IPR", "IPM", "MMPM", "SPINDL/",
                    "RPM", "UNITS/", "INCHES", "MM", "MSYS/", "TLAXIS/", "MULTAX/", "LOADTL/",
                    "REMARK ", "PPRINT ", "FINI", "END", "TRANS/", "FOO/", ",", ",", ",", "/",
                    "$", "$$", " ", "0", "1", "-1", "10", "0.5", "25.4", "1e6", "1e7", "NaN",
                    "inf", "-0", "é", "\t",
                ]),
                0..14,
            ),
            0..12,
        )
    ) {
        let text: String = lines.iter().map(|l| l.concat() + "\n").collect();
        let count = u32::try_from(lines.len()).expect("small");
        match to_tcpc_mapped(&text, "p") {
            Ok(c) => {
                for w in &c.warnings {
                    proptest::prop_assert!(w.line >= 1 && w.line <= count);
                }
                let machine = builtin("head-table-bc").expect("built-in");
                let _ = run(&machine, &offsets(), &c.program, None, false);
            }
            Err(e) => proptest::prop_assert!(e.line >= 1 && e.line <= count.max(1), "{e}"),
        }
    }
}
