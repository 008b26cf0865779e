//! `fiveaxis machines import`, and the LinuxCNC programs of the shared
//! corpus run on the machine imported from their own configuration
//! (`../shared/corpus/MANIFEST.tsv` gives each program's path in the
//! LinuxCNC repository; its configuration is the INI file of that folder).
//! The configurations and programs are read in place; the imported machine
//! is written to a temporary file at test time.
//!
//! Each program's ending today is asserted as it is: many still stop in
//! the RS274/NGC language, which is being built; when a program runs
//! further, its expectation here is updated.

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;

use fiveaxis_machine::{MFunction, Machine};

fn configs() -> PathBuf {
    common::corpus_dir().join("linuxcnc-configs")
}

fn fiveaxis(args: &[&str]) -> Output {
    let dir = tempfile::tempdir().expect("a temporary directory");
    common::run_in(dir.path(), args, b"")
}

fn path_str(path: &Path) -> &str {
    path.to_str().expect("UTF-8 paths")
}

/// `machines import CONFIG` into `dir/machine.toml`.
fn import_to(config: &str, dir: &Path) -> PathBuf {
    let ini = configs().join(config);
    let output = fiveaxis(&["machines", "import", path_str(&ini)]);
    assert_eq!(
        output.status.code(),
        Some(0),
        "{config}: {}",
        common::stderr(&output)
    );
    let file = dir.join("machine.toml");
    std::fs::write(&file, &output.stdout).expect("machine file written");
    file
}

// ----- the command -----------------------------------------------------------

#[test]
fn import_prints_a_machine_file_that_reads_back() {
    let Some(_) = common::corpus::corpus_path("linuxcnc-configs") else {
        return;
    };
    let ini = configs().join("axis/vismach/5axis/table-rotary-tilting/xyzac-trt.ini");
    let output = fiveaxis(&["machines", "import", path_str(&ini)]);
    assert_eq!(output.status.code(), Some(0), "{}", common::stderr(&output));
    assert!(output.stderr.is_empty(), "{}", common::stderr(&output));
    let text = common::stdout(&output);
    for wanted in [
        "control = \"linuxcnc\"",
        "type = \"table\"",
        "428 = \"tcpc_on\"",
        "429 = \"tcpc_off\"",
        "# xyzac-trt-kins.y-offset = 20: sets :y-offset 20 (xyzac-trt.ini:65)",
    ] {
        assert!(text.contains(wanted), "`{wanted}` missing:\n{text}");
    }
    let machine = Machine::from_toml(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(machine.m_codes.get(428), Some(MFunction::TcpcOn));
    assert!(machine.params.decimal_point_input);
    // Relative paths of the INI file are written absolute.
    let table = machine.params.tool_table.expect("a tool table");
    assert!(
        Path::new(&table).is_absolute() && Path::new(&table).exists(),
        "{table}"
    );
}

#[test]
fn a_relative_ini_path_gives_absolute_paths_in_the_file() {
    let Some(_) = common::corpus::corpus_path("linuxcnc-configs") else {
        return;
    };
    let folder = configs().join("axis/vismach/5axis/table-rotary-tilting");
    let output = common::run_in(&folder, &["machines", "import", "xyzbc-trt.ini"], b"");
    assert_eq!(output.status.code(), Some(0), "{}", common::stderr(&output));
    let machine = Machine::from_toml(&common::stdout(&output)).expect("reads back");
    let folders = machine.params.subroutine_path;
    assert!(
        folders.iter().all(|f| Path::new(f).is_absolute()),
        "{folders:?}"
    );
    assert!(
        folders
            .iter()
            .any(|f| Path::new(f) == folder.join("remap_subs")),
        "{folders:?}"
    );
}

#[test]
fn a_missing_configuration_exits_2_naming_it() {
    let output = fiveaxis(&["machines", "import", "/nonexistent/folder/machine.ini"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(output.stdout.is_empty());
    let err = common::stderr(&output);
    assert!(err.contains("/nonexistent/folder/machine.ini"), "{err}");
}

#[test]
fn a_bad_ini_line_exits_2_with_file_and_line() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let ini = dir.path().join("bad.ini");
    std::fs::write(&ini, "[EMC]\nMACHINE = x\n[TRAJ\n").expect("written");
    let output = fiveaxis(&["machines", "import", path_str(&ini)]);
    assert_eq!(output.status.code(), Some(2));
    assert!(output.stdout.is_empty());
    let err = common::stderr(&output);
    assert!(err.contains(&format!("{}:3:", ini.display())), "{err}");
    assert!(err.contains("[TRAJ"), "{err}");
    // Text that is not UTF-8 is refused the same way, not a panic.
    std::fs::write(&ini, b"[EMC]\nMACHINE = \xff\n").expect("written");
    let output = fiveaxis(&["machines", "import", path_str(&ini)]);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        common::stderr(&output).contains("UTF-8"),
        "{}",
        common::stderr(&output)
    );
}

#[test]
fn a_configuration_the_model_cannot_hold_exits_2_saying_why() {
    let Some(_) = common::corpus::corpus_path("linuxcnc-configs") else {
        return;
    };
    let ini = configs().join("axis/vismach/5axis/max5/max5kins.ini");
    let output = fiveaxis(&["machines", "import", path_str(&ini)]);
    assert_eq!(output.status.code(), Some(2));
    let err = common::stderr(&output);
    assert!(
        err.contains("max5kins.ini:4:") && err.contains("maxkins"),
        "{err}"
    );
}

#[test]
fn nutating_and_bridge_mill_configurations_import() {
    let Some(_) = common::corpus::corpus_path("linuxcnc-configs") else {
        return;
    };
    for (config, axes, words) in [
        (
            ACB,
            "XYZACB",
            &[
                "type = \"mixed\"",
                "\ntwp_remap = true",
                "430 = \"tcpc_on\"",
            ][..],
        ),
        (
            BCA,
            "XYZBCA",
            &["type = \"mixed\"", "# [TWP]SECONDARY = A"][..],
        ),
        (
            BRIDGE,
            "XYZWCB",
            &["along = \"tool\"", "tcpc_at_start = true"][..],
        ),
    ] {
        let output = fiveaxis(&["machines", "import", path_str(&configs().join(config))]);
        assert_eq!(output.status.code(), Some(0), "{}", common::stderr(&output));
        let text = common::stdout(&output);
        for word in words {
            assert!(text.contains(word), "{config}: `{word}` missing:\n{text}");
        }
        let machine = Machine::from_toml(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(machine.axis_names().collect::<String>(), axes);
    }
}

// ----- the corpus programs on their own machines ---------------------------

/// How a run ends.
#[derive(Debug, PartialEq)]
enum Ending {
    /// Exit 0: the program ran to its end.
    End,
    /// Exit 1: this alarm at this line.
    Alarm(&'static str, usize),
}

const AC: &str = "axis/vismach/5axis/table-rotary-tilting/xyzac-trt.ini";
const BC: &str = "axis/vismach/5axis/table-rotary-tilting/xyzbc-trt.ini";
const TDR: &str = "axis/vismach/5axis/table-dual-rotary/xyzab-tdr.ini";
const GMOCCAPY_AC: &str = "gmoccapy/non_trivial_kinematics/table-rotary-tilting/xyzac-trt.ini";
const BRIDGE: &str = "axis/vismach/5axis/bridgemill/5axis.ini";
const ACB: &str =
    "axis/vismach/5axis/table-rotary_spindle-rotary-nutating/xyzacb-trsrn_twp/xyzacb-trsrn.ini";
const BCA: &str =
    "axis/vismach/5axis/table-rotary_spindle-rotary-nutating/xyzbca-trsrn_twp/xyzbca-trsrn.ini";

/// Corpus program → the configuration of its folder in the LinuxCNC
/// repository, and how the run ends today.
/// The nutating-head demos (xyzacb/xyzbca
/// trsrn, one demos folder for both) program LinuxCNC's tilted-working-
/// plane remaps.
const PROGRAMS: &[(&str, &str, Ending)] = &[
    ("lcnc_impeller-7bl-xyzac.ngc", AC, Ending::End),
    ("lcnc_boat-xyzac.ngc", AC, Ending::End),
    ("lcnc_boat-xyzbc.ngc", BC, Ending::End),
    ("lcnc_xyzac_switchkins_test_1.ngc", AC, Ending::End),
    ("lcnc_xyzac_switchkins_test_2.ngc", AC, Ending::End),
    ("lcnc_xyzac_switchkins_test_3.ngc", AC, Ending::End),
    ("lcnc_xyzac_switchkins_sub.ngc", AC, Ending::End),
    ("lcnc_xyzbc_switchkins_sub.ngc", BC, Ending::End),
    ("lcnc_helix_ac.ngc", AC, Ending::End),
    ("lcnc_helix_bc.ngc", BC, Ending::End),
    ("lcnc_centering.ngc", AC, Ending::End),
    ("lcnc_gmoccapy_test-xyzac.ngc", GMOCCAPY_AC, Ending::End),
    // The corpus holds gmoccapy's A/C configuration only: the B/C program
    // runs on the axis B/C one (the same kinematics module).
    ("lcnc_gmoccapy_test-xyzbc.ngc", BC, Ending::End),
    // `#<_hal[xyzab_tdr_kins.x-rot-point]>` reads the pin value the
    // importer wrote from the HAL files and panel (rs274, without HAL,
    // stops there).
    ("lcnc_xyzab-tdr-demo.ngc", TDR, Ending::End),
    // The bridge mill: B/C head, W along the tool (drilling with W under
    // the TCP kinematics it starts in).
    ("lcnc_bridgemill_5axisgui.ngc", BRIDGE, Ending::End),
    // The nutating heads with LinuxCNC's tilted-working-plane remap
    // (`twp_remap = true`, imported from their REMAP lines).
    ("lcnc_trsrn_simple_example.ngc", ACB, Ending::End),
    ("lcnc_trsrn_simple_example.ngc", BCA, Ending::End),
    ("lcnc_trsrn_incremental_repetition.ngc", ACB, Ending::End),
    ("lcnc_trsrn_incremental_repetition.ngc", BCA, Ending::End),
    // Each repetition's pair `G68.4 X50 … / G68.4 X-50 …` turns the plane
    // 45° and back but leaves its origin (17.7, 0, 33.9) mm further: the
    // X of an incremental G68.4 is along the plane in force (FANUC's
    // G68.4; the remap's README: "incremental definition from an active
    // TWP plane"). After about 180 of its 1000 repetitions Z passes the
    // configuration's +5000 limit: a real over-travel of the program.
    (
        "lcnc_trsrn_incremental_repetition_back_and_forth.ngc",
        ACB,
        Ending::Alarm("FX0500", 18),
    ),
    (
        "lcnc_trsrn_incremental_repetition_g533.ngc",
        BCA,
        Ending::End,
    ),
    ("lcnc_trsrn_circular_pocket.ngc", ACB, Ending::End),
    ("lcnc_trsrn_square.ngc", BCA, Ending::End),
    // lcnc-suite's copy of the nutating demo's simple_example with its own
    // offsets; its configuration (xyzabc6) is not in the corpus, so it
    // runs on the nutating sim configuration it was written from.
    ("lcnc_suite_twp_simple_example.ngc", BCA, Ending::End),
];

/// Files that hold one subroutine `o<NAME> sub … endsub` for NGCGUI: they
/// run as NGCGUI runs them, called with the defaults their comments give.
const SUBFILES: &[(&str, &str)] = &[
    ("lcnc_xyzac_switchkins_sub.ngc", "xyzac_switchkins_sub"),
    ("lcnc_xyzbc_switchkins_sub.ngc", "xyzbc_switchkins_sub"),
    ("lcnc_helix_ac.ngc", "helix_ac"),
    ("lcnc_helix_bc.ngc", "helix_bc"),
    ("lcnc_centering.ngc", "centering"),
    ("lcnc_gmoccapy_test-xyzac.ngc", "test-xyzac"),
    ("lcnc_gmoccapy_test-xyzbc.ngc", "test-xyzbc"),
    ("lcnc_trsrn_circular_pocket.ngc", "circular_pocket"),
    ("lcnc_trsrn_square.ngc", "square"),
];

/// Runs `program` on the machine imported from `config`: `None` when it
/// ends (exit 0), else the alarm code and line (exit 1); the rows and
/// standard error.
fn run_on(program: &str, config: &str) -> (Option<(String, usize)>, String, String) {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let machine = import_to(config, dir.path());
    let mut program_path = common::corpus_dir().join(program);
    if let Some((_, name)) = SUBFILES.iter().find(|(file, _)| *file == program) {
        // `o<NAME> call [defaults]`, M2, then the file: the call finds the
        // subroutine further on. The wrapper's lines come first, so the
        // file's line n is line n + 2.
        let text = std::fs::read_to_string(&program_path).expect("corpus file");
        let wrapper = format!("{}\nM2\n{text}", common::ngcgui_call(name, &text));
        program_path = dir.path().join(program);
        std::fs::write(&program_path, wrapper).expect("wrapper written");
    }
    let output = common::run_in(
        dir.path(),
        &[
            "run",
            path_str(&program_path),
            "--machine",
            path_str(&machine),
        ],
        b"",
    );
    let err = common::stderr(&output);
    let ending = match output.status.code() {
        Some(0) => None,
        Some(1) => {
            // `ALARM <code> line <n>: <message>`
            let first = err.lines().next().unwrap_or("");
            let mut words = first.split_whitespace();
            let code = words.nth(1).unwrap_or("").to_owned();
            let line = words
                .nth(1)
                .and_then(|w| w.trim_end_matches(':').parse::<usize>().ok())
                .unwrap_or(0);
            Some((code, line))
        }
        other => panic!("{program} on {config}: exit {other:?}\n{err}"),
    };
    (ending, common::stdout(&output), err)
}

fn matches(ending: &Option<(String, usize)>, expected: &Ending) -> bool {
    match (ending, expected) {
        (None, Ending::End) => true,
        (Some((code, line)), Ending::Alarm(want, want_line)) => code == want && line == want_line,
        _ => false,
    }
}

#[test]
fn linuxcnc_programs_on_their_imported_machines() {
    let Some(_) = common::corpus::corpus_path("linuxcnc-configs") else {
        return;
    };
    let listed =
        std::fs::read_to_string(common::corpus_dir().join("MANIFEST.tsv")).expect("manifest");
    for (program, config, expected) in PROGRAMS {
        assert!(listed.contains(program), "{program} is in the manifest");
        let (ending, rows, err) = run_on(program, config);
        assert!(
            matches(&ending, expected),
            "{program} on {config}: expected {expected:?}, got {ending:?}:\n{err}"
        );
        if *expected == Ending::End {
            assert!(rows.lines().count() > 1, "{program}: rows");
        }
        println!("{program} on {config}: {ending:?}");
    }
}

/// `xyzac_switchkins_test_3.ngc` carries LinuxCNC's own expected
/// positions as `(debug, X expect: x y z)` comments: the joints in
/// identity mode (M429), the tool tip on the table in TCP mode (M428).
#[test]
fn switchkins_test_3_reaches_the_positions_its_comments_expect() {
    let Some(_) = common::corpus::corpus_path("linuxcnc-configs") else {
        return;
    };
    let (ending, rows, err) = run_on("lcnc_xyzac_switchkins_test_3.ngc", AC);
    assert!(ending.is_none(), "{err}");
    let mut lines = rows.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).expect(name);
    let by_line: Vec<Vec<f64>> = lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse::<f64>().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let row = |line: f64| {
        by_line
            .iter()
            .rev()
            .find(|r| r[0] == line)
            .unwrap_or_else(|| panic!("a row of line {line}:\n{rows}"))
    };
    let close = |got: f64, want: f64| (got - want).abs() < 1e-9;
    // Line 5 `G1 F1000 Z2`: "A expect: 10 0 2" (joints, identity);
    // after M428 "C expect: 0 -10 2" (tip on the table).
    let r = row(5.0);
    let (x, y, z) = (column("X"), column("Y"), column("Z"));
    let (tx, ty, tz) = (column("tip_x"), column("tip_y"), column("tip_z"));
    assert!(
        close(r[x], 10.0) && close(r[y], 0.0) && close(r[z], 2.0),
        "{r:?}"
    );
    assert!(
        close(r[tx], 0.0) && close(r[ty], -10.0) && close(r[tz], 2.0),
        "{r:?}"
    );
    // Line 10 `g1f1000 z0` in TCP mode: "D expect: 0 -10 0"; after M429
    // the joints "F expect: 10 0 0".
    let r = row(10.0);
    assert!(
        close(r[tx], 0.0) && close(r[ty], -10.0) && close(r[tz], 0.0),
        "{r:?}"
    );
    assert!(
        close(r[x], 10.0) && close(r[y], 0.0) && close(r[z], 0.0),
        "{r:?}"
    );
}

/// The bridge mill's drilling: `g1 w[-10]` under the TCP kinematics moves
/// the tip 10 mm along the tool into the work ("g0w-10 ; simulate drill",
/// the configuration's README), and `g0 w0` takes it back; X Y Z of the
/// tip seen by forward kinematics of the rows' axes (tool T100, 100 mm).
#[test]
fn bridgemill_w_drills_along_the_tool() {
    let Some(_) = common::corpus::corpus_path("linuxcnc-configs") else {
        return;
    };
    let dir = tempfile::tempdir().expect("a temporary directory");
    let machine_file = import_to(BRIDGE, dir.path());
    let machine = Machine::from_toml(&std::fs::read_to_string(&machine_file).expect("machine"))
        .expect("reads back");
    let (ending, rows, err) = run_on("lcnc_bridgemill_5axisgui.ngc", BRIDGE);
    assert!(ending.is_none(), "{err}");
    let mut lines = rows.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).expect(n);
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let tip = |r: &[f64]| [r[col("tip_x")], r[col("tip_y")], r[col("tip_z")]];
    let mut drills = 0;
    for pair in rows.windows(2) {
        let (before, drill) = (&pair[0], &pair[1]);
        if drill[0] != 43.0 {
            continue;
        }
        drills += 1;
        let dir = [
            drill[col("tool_i")],
            drill[col("tool_j")],
            drill[col("tool_k")],
        ];
        let (a, b) = (tip(before), tip(drill));
        for k in 0..3 {
            assert!(
                (b[k] - (a[k] - 10.0 * dir[k])).abs() < 1e-9,
                "{before:?} -> {drill:?}"
            );
        }
        assert_eq!(drill[col("W")], -10.0);
        // The rows' tip is forward kinematics of their axes (the part
        // frame is the table frame shifted by the work offset).
        let mut joints = [0.0; fiveaxis_machine::MAX_AXES];
        for (i, name) in machine.axis_names().enumerate() {
            joints[i] = drill[col(&name.to_string())];
        }
        let f = machine.forward(&joints, 100.0).tip;
        let g = machine
            .forward(
                &{
                    let mut j = joints;
                    for (i, name) in machine.axis_names().enumerate() {
                        j[i] = before[col(&name.to_string())];
                    }
                    j
                },
                100.0,
            )
            .tip;
        for k in 0..3 {
            assert!(((f[k] - g[k]) - (b[k] - a[k])).abs() < 1e-9);
        }
    }
    assert_eq!(drills, 8 * 16, "every hole is drilled");
}

/// The machine the vismach model of a configuration gives can be
/// checked for collisions: its parts assembled together (the table on
/// its saddle, the trunnion in its brackets) are not collisions, and
/// tilts of ±10° with turns of the round table clear the rest (the
/// model's round table meets the brackets' mounting plate past about
/// 20°); a move of the head down into the round table is one.
#[test]
fn an_imported_vismach_model_checks_collisions() {
    let Some(_) = common::corpus::corpus_path("linuxcnc-configs") else {
        return;
    };
    let dir = tempfile::tempdir().expect("a temporary directory");
    let machine = import_to(AC, dir.path());
    let text = std::fs::read_to_string(&machine).expect("machine file");
    assert!(text.contains("[[body]]"), "bodies from the vismach model");
    let clear = dir.path().join("clear.ngc");
    std::fs::write(&clear, "G0 Z60\nG0 A-10 C90\nG0 A10 C-90\nG0 A0 C0\nM30\n").expect("program");
    let into = dir.path().join("into.ngc");
    std::fs::write(&into, "G0 Z60\nG0 Z-20\nG0 Z60\nM30\n").expect("program");
    let collisions = |program: &Path| {
        let out = common::run_in(
            dir.path(),
            &[
                "check",
                path_str(program),
                "--machine",
                path_str(&machine),
                "--collisions",
                "--format",
                "json",
            ],
            b"",
        );
        let v: serde_json::Value =
            serde_json::from_str(common::stdout(&out).lines().next().unwrap_or_default())
                .expect("a JSON report");
        v["findings"]
            .as_array()
            .expect("findings")
            .iter()
            .filter(|f| f["kind"] == "collision")
            .map(|f| f["line"].as_u64().unwrap_or_default())
            .collect::<Vec<_>>()
    };
    assert_eq!(collisions(&clear), Vec::<u64>::new());
    // The head's spindle nose (radius 10 about the gauge point) goes
    // 20 mm below the round table's top on line 2.
    assert_eq!(collisions(&into), [2]);
}
