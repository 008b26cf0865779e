//! APT / CL input: the corpus's SolidWorks CAM file converted to a TCPC
//! program and run by the kernel; every `GOTO` point and tool vector of the
//! file (read here by a separate minimal scan) is reached, in order, at the
//! end of a block (`Segment::row`, forward kinematics). Bad records give
//! their line.

#[path = "../../fiveaxis-cli/tests/common/corpus.rs"]
mod corpus;

use fiveaxis_control::{RunOptions, Runner, SliceSource};
use fiveaxis_machine::{Offsets, ToolOffset, Vec3, builtin};
use fiveaxis_post::apt::to_tcpc;

/// How close a block end must be to the GOTO point, mm (the program is
/// written with 6 decimals).
const POINT_EPS: f64 = 1e-5;
/// How close the tool direction must be, as a vector difference.
const DIR_EPS: f64 = 1e-6;

/// GOTO points and vectors of the APT text, the vector kept between them.
fn gotos(text: &str) -> Vec<(Vec3, Vec3)> {
    let mut dir = Vec3::z();
    let mut out = Vec::new();
    for line in text.lines() {
        let Some(args) = line.trim().strip_prefix("GOTO/") else {
            continue;
        };
        let v: Vec<f64> = args
            .split(',')
            .map(|a| a.trim().parse().expect("number"))
            .collect();
        if v.len() == 6 {
            dir = Vec3::new(v[3], v[4], v[5]).normalize();
        }
        out.push((Vec3::new(v[0], v[1], v[2]), dir));
    }
    out
}

#[test]
fn the_corpus_cl_file_converts_and_every_point_is_reached() {
    let Some(path) = corpus::corpus_path("cl_solidworks_boss.apt") else {
        return;
    };
    let text = std::fs::read_to_string(path).expect("the corpus CL file reads");
    let program = to_tcpc(&text, "cl_solidworks_boss.apt").expect("converts");
    let machine = builtin("head-table-bc").expect("built-in");
    let mut offsets = Offsets::default();
    for (n, length) in [(1, 76.0), (5, 90.0)] {
        offsets.tools.insert(
            n,
            ToolOffset {
                length,
                ..ToolOffset::default()
            },
        );
    }
    let options = RunOptions {
        lift_soft_limits: true,
        ..RunOptions::default()
    };
    let mut runner = Runner::new(
        &machine,
        offsets,
        SliceSource::new(program.as_bytes()),
        options,
    );
    let mut segments = Vec::new();
    loop {
        let want = segments.len() + 4096;
        if !runner.fill(&mut segments, want).expect("runs") {
            break;
        }
    }
    let targets = gotos(&text);
    assert_eq!(targets.len(), 9814);
    let mut next = 0;
    for seg in &segments {
        let row = seg.row(&machine, 1.0);
        if let Some((p, d)) = targets.get(next)
            && (row.tip - p).norm() <= POINT_EPS
            && (row.dir - d).norm() <= DIR_EPS
        {
            next += 1;
        }
    }
    assert_eq!(
        next,
        targets.len(),
        "GOTO {} not reached: {:?}",
        next + 1,
        targets.get(next)
    );
}

#[test]
fn records_continue_with_dollar_and_circles_turn_about_their_axis() {
    let text = "UNIT/MM\nLOAD/TOOL,2\nRAPID\nGOTO/10,0,5,$\n0,0,1\nFEDRAT/600,MMPM\nGOTO/10,0,0\n\
                CIRCLE/0,0,0,0,0,1\nGOTO/0,10,0\nCIRCLE/0,0,0,0,0,-1.\nGOTO/10,0,0\n\
                CIRCLE/0,0,0,0,0,1\nGOTO/0,-10,0\nFINI\n";
    let program = to_tcpc(text, "t").expect("converts");
    // A quarter counter-clockwise about +Z, a quarter back clockwise
    // (counter-clockwise about -Z), then three quarters counter-clockwise
    // (R negative: more than half a turn).
    assert!(
        program.contains("T2 M6\nG43.5 H2 G0 X10.000000 Y0.000000 Z5.000000\nG0 X10.000000 Y0.000000 Z5.000000 I0"),
        "{program}"
    );
    assert!(
        program.contains("G17 G3 X0.000000 Y10.000000 Z0.000000 R10.000000"),
        "{program}"
    );
    assert!(
        program.contains("G17 G2 X10.000000 Y0.000000 Z0.000000 R10.000000"),
        "{program}"
    );
    assert!(
        program.contains("G17 G3 X0.000000 Y-10.000000 Z0.000000 R-10.000000"),
        "{program}"
    );
    assert!(program.ends_with("G49\nM30\n%\n"));
}

#[test]
fn bad_records_name_their_line() {
    for (text, line, needle) in [
        ("GOTO/1,2,3\n", 1, "before any FEDRAT"),
        ("FEDRAT/100\nGOTO/1,2\n", 2, "3 to 6 numbers"),
        ("FEDRAT/100\nROTABL/90,CLW\n", 2, "not carried out"),
        ("FEDRAT/100\nORIGIN/10,0,0\n", 2, "ORIGIN"),
        ("CYCLE/TAP,DEPTH,10,MMPM,100,CLEAR,2\n", 1, "CYCLE/TAP"),
        (
            "CYCLE/DRILL,DEPTH,10,MMPM,100,CLEAR,2,RETURN,0\n",
            1,
            "RETURN",
        ),
        ("CYCLE/DRILL,DEPTH,10,CLEAR,2\n", 1, "feed"),
        ("FEDRAT/0.1,MMPR\nGOTO/1,2,3\n", 2, "no spindle speed"),
        ("FEDRAT/100,FURLONGS\n", 1, "unit"),
        ("UNITS/CUBITS\n", 1, "MM or INCHES"),
        ("0.0,1.0,0.0\n", 1, "not a record"),
        ("GODLTA/0,0,5\n", 1, "before any position"),
        (
            "FEDRAT/100\nGOTO/0,0,0\nCIRCLE/0,0,0,0,0,1\nGOTO/1,1,1,1,2\n",
            4,
            "3 or 6",
        ),
        (
            "FEDRAT/100\nGOTO/5,0,0\nCIRCLE/0,0,0,5\nGOTO/0,5,0\n",
            3,
            "no direction",
        ),
        (
            "FEDRAT/100\nGOTO/5,0,0\nFEDRAT/200\n0,5,0\n",
            4,
            "not a record",
        ),
        (
            "FEDRAT/100\nGOTO/1,2,3\nFINI\nGOTO/1,2,4\n",
            4,
            "after the end",
        ),
        (
            "FEDRAT/100\nGOTO/10,0,0\nCIRCLE/0,0,0,0.6,0,0.8\nGOTO/0,10,0\n",
            3,
            "not along",
        ),
        ("FEDRAT/100\nGOTO/10,0,0,$\n", 2, "continued on no line"),
        ("MSYS/0,0,0,1,0,0,1,1,0\n", 1, "right angles"),
        ("MULTAX/SOMETIMES\n", 1, "ON or OFF"),
        ("SPINDL/RPM,CLW\n", 1, "no speed"),
        ("SPINDL/SFM,200\n", 1, "RPM"),
    ] {
        let e = to_tcpc(text, "t").expect_err(text);
        assert_eq!(e.line, line, "{text}: {e}");
        assert!(e.message.contains(needle), "{text}: {e}");
    }
}

/// Numbers beyond `MAX_FILE_MAGNITUDE` (the bound of every number of a
/// machine) or not finite are refused with the record's line; the bound
/// itself converts.
#[test]
fn numbers_are_bounded_like_the_machine_files() {
    let max = fiveaxis_machine::MAX_FILE_MAGNITUDE;
    let over = format!("{:e}", max * 1.000_001);
    for (text, line, needle) in [
        (
            "FEDRAT/100\n$$ x\nGOTO/1e300,0,0,0,0,1\n".to_owned(),
            3,
            "`1e300` is beyond what a machine can have",
        ),
        (
            format!("FEDRAT/100\nGOTO/0,{over},0\n"),
            2,
            "beyond what a machine can have",
        ),
        (
            format!("FEDRAT/100\nGOTO/0,0,-{over}\n"),
            2,
            "beyond what a machine can have",
        ),
        (
            "FEDRAT/100\nGOTO/inf,0,0\n".to_owned(),
            2,
            "not a finite number",
        ),
        (
            "FEDRAT/100\nGOTO/0,0,0,NaN,0,1\n".to_owned(),
            2,
            "not a finite number",
        ),
        (
            "FEDRAT/100\nGOTO/0,0,0\nCIRCLE/1e7,0,0,0,0,1\n".to_owned(),
            3,
            "beyond",
        ),
        (
            "FEDRAT/1e300\n".to_owned(),
            1,
            "beyond what a machine can have",
        ),
        (
            "SPINDL/1e300,RPM,CLW\n".to_owned(),
            1,
            "beyond what a machine can have",
        ),
        (
            "MSYS/900000,0,0,1,0,0,0,1,0\nFEDRAT/100\nGOTO/900000,0,0\n".to_owned(),
            3,
            "after MSYS",
        ),
    ] {
        let e = to_tcpc(&text, "t").expect_err(&text);
        assert_eq!(e.line, line, "{text}: {e}");
        assert!(e.message.contains(needle), "{text}: {e}");
    }
    let text = format!("FEDRAT/100\nGOTO/{max:e},-{max:e},0,0,0,1\n");
    if let Err(e) = to_tcpc(&text, "t") {
        panic!("{text}: {e}");
    }
}

/// An NX CLSF: `MSYS` (a frame turned 30° about X, moved), 3-axis data
/// under `MULTAX/OFF` (the tool along the frame's Z), `FEDRAT/MMPM,f`,
/// `SPINDL/RPM,s,CLW`, `COOLNT/MIST`, `TLDATA`, `PAINT`, `$$` and then
/// 5-axis data under `MULTAX/ON`. Every GOTO, turned into the absolute
/// frame here by hand, is reached in order by the TCPC program; the
/// machine-axis program carries the tool change, spindle and coolant.
#[test]
fn nx_clsf_with_msys_and_multax() {
    let text = "TOOL PATH/VARIABLE_CONTOUR,TOOL,MILL\n\
                TLDATA/MILL,10.0000,0.0000,75.0000,0.0000,0.0000\n\
                MSYS/10.0000,20.0000,5.0000,1.0000000,0.0000000,0.0000000,$\n\
                0.0000000,0.8660254,0.5000000\n\
                $$ centerline data\n\
                PAINT/PATH\n\
                LOAD/TOOL,3\n\
                SPINDL/RPM,8000,CLW\n\
                COOLNT/MIST\n\
                MULTAX/OFF\n\
                RAPID\n\
                GOTO/0.0000,0.0000,20.0000\n\
                FEDRAT/MMPM,250.0000\n\
                GOTO/0.0000,0.0000,0.0000\n\
                GOTO/30.0000,0.0000,0.0000\n\
                GOTO/30.0000,15.0000,0.0000\n\
                MULTAX/ON\n\
                GOTO/20.0000,15.0000,0.0000,0.0000000,0.2588190,0.9659258\n\
                GOTO/20.0000,5.0000,0.0000\n\
                COOLNT/OFF\n\
                SPINDL/OFF\n\
                END-OF-PATH\n";
    let program = to_tcpc(text, "nx.cls").expect("converts");
    let origin = Vec3::new(10.0, 20.0, 5.0);
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let turn = |v: Vec3| Vec3::new(v.x, c * v.y - s * v.z, s * v.y + c * v.z);
    let z = turn(Vec3::z());
    let tilted = turn(Vec3::new(0.0, 0.258819, 0.9659258).normalize());
    let targets = [
        (Vec3::new(0.0, 0.0, 20.0), z),
        (Vec3::new(0.0, 0.0, 0.0), z),
        (Vec3::new(30.0, 0.0, 0.0), z),
        (Vec3::new(30.0, 15.0, 0.0), z),
        (Vec3::new(20.0, 15.0, 0.0), tilted),
        (Vec3::new(20.0, 5.0, 0.0), tilted),
    ]
    .map(|(p, d)| (origin + turn(p), d));
    let machine = builtin("head-table-bc").expect("built-in");
    let mut offsets = Offsets::default();
    offsets.tools.insert(
        3,
        ToolOffset {
            length: 75.0,
            ..ToolOffset::default()
        },
    );
    let mut runner = Runner::new(
        &machine,
        offsets.clone(),
        SliceSource::new(program.as_bytes()),
        RunOptions::default(),
    );
    let mut segments = Vec::new();
    while runner.fill(&mut segments, 1 << 20).expect("runs") {}
    let mut next = 0;
    for seg in &segments {
        let row = seg.row(&machine, 1.0);
        if let Some((p, d)) = targets.get(next)
            && (row.tip - p).norm() <= POINT_EPS
            && (row.dir - d).norm() <= DIR_EPS
        {
            next += 1;
        }
    }
    assert_eq!(
        next,
        targets.len(),
        "GOTO {} not reached\n{program}",
        next + 1
    );
    // Machine axes: the words carried, in their place.
    let options = fiveaxis_post::PostOptions {
        axes: fiveaxis_post::Axes::Post { great_circle: true },
        ..Default::default()
    };
    let mut converter = fiveaxis_post::Converter::new(&machine, options);
    for seg in &segments {
        converter.push(seg);
    }
    let carried = fiveaxis_post::program::carried_words(&program);
    let out = fiveaxis_post::program::write(
        &machine,
        &converter.finish(),
        &options,
        &fiveaxis_post::program::Header {
            source: "nx.cls",
            carried: &carried,
            ..Default::default()
        },
    );
    let at = |needle: &str| {
        out.find(needle)
            .unwrap_or_else(|| panic!("{needle}\n{out}"))
    };
    assert!(at("T3 M6") < at("S8000 M3"));
    assert!(at("S8000 M3") < at("M7\n"));
    assert!(at("M7\n") < at("\nG0 "));
    assert!(at("\nG1 ") < at("M9\n"));
    assert!(at("M9\n") < at("M5\n"));
    assert!(at("M5\n") < at("M30\n"));
}

/// Every line written for a record maps to the line the record starts
/// on (a continued GOTO, a full circle's four quarters and the G17 after
/// a G18 arc); the header and the end map to none.
#[test]
fn each_program_line_maps_to_its_record() {
    let text = "FEDRAT/100\nGOTO/10,0,0,$\n0,0,1\nCIRCLE/0,0,0,0,0,1\nGOTO/10,0,0\nCIRCLE/0,0,0,0,1,0\nGOTO/0,0,-10\nFINI\n";
    let c = fiveaxis_post::apt::to_tcpc_mapped(text, "t").expect("converts");
    let lines: Vec<&str> = c.program.lines().collect();
    assert_eq!(lines.len(), c.source_lines.len(), "{}", c.program);
    let from = |n: u32| -> Vec<&str> {
        lines
            .iter()
            .zip(&c.source_lines)
            .filter(|(_, l)| **l == Some(n))
            .map(|(t, _)| *t)
            .collect()
    };
    assert_eq!(from(2).len(), 2, "{}", c.program);
    assert!(from(2)[1].starts_with("G1 X10.000000"), "{}", c.program);
    assert_eq!(from(5).len(), 4, "{}", c.program);
    assert_eq!(from(7).len(), 2, "{}", c.program);
    assert_eq!(from(7)[1], "G17", "{}", c.program);
    assert_eq!(c.source_line(1), None);
    assert_eq!(
        c.source_line(u32::try_from(lines.len()).expect("few lines")),
        None
    );
    assert_eq!(c.source_line(0), None);
    assert_eq!(c.source_line(u32::MAX), None);
}
