//! `fiveaxis post`: the output as a file (whole or not at all), the alarm
//! of the source program stops it with nothing written, and the output is
//! a program the kernel runs. (The tolerances themselves are judged by
//! forward kinematics in `fiveaxis-post`'s tests.)

mod common;

#[test]
fn the_example_converts_and_the_output_runs_on_the_machine() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let examples = common::root().join("examples");
    for name in ["tcpc-vector.nc", "offsets.toml"] {
        std::fs::copy(examples.join(name), dir.path().join(name)).expect("copied");
    }
    let out = common::run_in(
        dir.path(),
        &[
            "post",
            "tcpc-vector.nc",
            "--machine",
            "head-table-bc",
            "--offsets",
            "offsets.toml",
            "-o",
            "out.nc",
        ],
        b"",
    );
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    assert!(common::stdout(&out).is_empty());
    let text = std::fs::read_to_string(dir.path().join("out.nc")).expect("out.nc written");
    assert!(text.starts_with("%\n(FIVEAXIS POST"), "{text}");
    for needle in [
        "(SOURCE: TCPC-VECTOR.NC)",
        "(TOLERANCE: TIP 0.01 MM, DIRECTION 0.1 DEG)",
        "TOOL LENGTH 120.0000 MM",
        "G93",
        "M30\n%\n",
    ] {
        assert!(text.contains(needle), "{needle} missing:\n{text}");
    }
    // The blocks (not the comments that say what was removed).
    let blocks: String = text.lines().filter(|l| !l.starts_with('(')).collect();
    for gone in ["G43", "G68.2", " I", " J", " K"] {
        assert!(!blocks.contains(gone), "{gone} left in:\n{text}");
    }
    let run = common::run_in(
        dir.path(),
        &[
            "run",
            "out.nc",
            "--machine",
            "head-table-bc",
            "--offsets",
            "offsets.toml",
        ],
        b"",
    );
    assert_eq!(run.status.code(), Some(0), "{}", common::stderr(&run));
    // Standard output without -o, the same text.
    let again = common::run_in(
        dir.path(),
        &[
            "post",
            "tcpc-vector.nc",
            "--machine",
            "head-table-bc",
            "--offsets",
            "offsets.toml",
        ],
        b"",
    );
    assert_eq!(common::stdout(&again), text);
}

#[test]
fn an_alarm_in_the_source_writes_nothing() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("p.nc"),
        "G0 X10. Z50.\nG43.4 H1 X0 Y0 Z20.\nG1 Z10. F500.\nG1 X5. F0\nM30\n",
    )
    .expect("written");
    std::fs::write(dir.path().join("kept.nc"), "old\n").expect("written");
    let out = common::run_in(dir.path(), &["post", "p.nc", "-o", "kept.nc"], b"");
    assert_eq!(out.status.code(), Some(1), "{}", common::stderr(&out));
    assert!(
        common::stderr(&out).contains(" line 4"),
        "{}",
        common::stderr(&out)
    );
    let kept = std::fs::read_to_string(dir.path().join("kept.nc")).expect("still there");
    assert_eq!(kept, "old\n");
    let out = common::run_in(dir.path(), &["post", "p.nc", "-o", "new.nc"], b"");
    assert_eq!(out.status.code(), Some(1));
    assert!(!dir.path().join("new.nc").exists());
    assert!(common::stdout(&out).is_empty());
}

#[test]
fn a_tolerance_must_be_positive() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(dir.path().join("p.nc"), "G0 X10.\nM30\n").expect("written");
    for bad in ["0", "-1", "nan"] {
        let out = common::run_in(dir.path(), &["post", "p.nc", "--tolerance", bad], b"");
        assert_eq!(out.status.code(), Some(2), "{bad}");
    }
    // Below the floors (1e-6 mm, 1e-5 degrees: finer than any written
    // program holds) post would never end: refused at once.
    for (option, bad, says) in [
        ("--tolerance", "9.9e-7", "at least 1e-6 mm"),
        ("--tolerance", "1e-8", "at least 1e-6 mm"),
        ("--angle-tolerance", "9.9e-6", "at least 1e-5 degrees"),
        ("--angle-tolerance", "1e-6", "at least 1e-5 degrees"),
    ] {
        let out = common::run_in(
            dir.path(),
            &["post", "p.nc", "--tool-length", "100", option, bad],
            b"",
        );
        let err = common::stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{option} {bad}: {err}");
        assert!(err.contains(says), "{option} {bad}: {err}");
    }
}

#[test]
fn apt_input_gives_a_tcpc_program_or_machine_axes_and_bad_records_their_line() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("p.apt"),
        "LOAD/TOOL,1\nRAPID\nGOTO/0,0,10,0,0,1\nFEDRAT/500,MMPM\nGOTO/20,0,0,$\n0.5,0,0.866025\nFINI\n",
    )
    .expect("written");
    let out = common::run_in(dir.path(), &["post", "p.apt", "--tcpc"], b"");
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let tcpc = common::stdout(&out);
    assert!(tcpc.contains("G43.5 H1 G0 X0.000000"), "{tcpc}");
    let out = common::run_in(
        dir.path(),
        &[
            "post",
            "p.apt",
            "--machine",
            "head-table-bc",
            "--tool-length",
            "100",
            "-o",
            "axes.nc",
        ],
        b"",
    );
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let axes = std::fs::read_to_string(dir.path().join("axes.nc")).expect("written");
    assert!(
        axes.contains("(SOURCE: P.APT)") && axes.contains("\nG1 X"),
        "{axes}"
    );
    std::fs::write(dir.path().join("bad.apt"), "FEDRAT/100\nROTABL/90,CLW\n").expect("written");
    let out = common::run_in(dir.path(), &["post", "bad.apt", "-o", "no.nc"], b"");
    assert_eq!(out.status.code(), Some(2));
    // The file, the CL line and the word.
    assert!(
        common::stderr(&out).contains("bad.apt:line 2: `ROTABL`"),
        "{}",
        common::stderr(&out)
    );
    assert!(!dir.path().join("no.nc").exists());
}

/// An alarm raised running the program converted from CL data names the
/// CL record's own line and shows its text, not a line of the generated
/// G-code.
#[test]
fn an_alarm_in_apt_input_names_the_records_line() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let record = "GOTO/999,0,0,0,0,1";
    std::fs::write(
        dir.path().join("prog.apt"),
        format!(
            "$$ over-travel on line 6\nLOAD/TOOL,1\nRAPID\nGOTO/0,0,10,0,0,1\nFEDRAT/500,MMPM\n{record}\nFINI\n"
        ),
    )
    .expect("written");
    let out = common::run_in(
        dir.path(),
        &[
            "post",
            "prog.apt",
            "--machine",
            "head-table-bc",
            "--tool-length",
            "100",
        ],
        b"",
    );
    let err = common::stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains(" line 6:"), "{err}");
    assert!(err.contains("prog.apt:6"), "{err}");
    assert!(err.contains(record), "{err}");
    assert!(!err.contains("X999.000000"), "{err}");
    assert!(common::stdout(&out).is_empty());
}

/// `GOTO/1e300,...` wrote a 300-digit X word with `--tcpc` and, without,
/// said "too many digits" at a line the file does not have: refused at
/// the record's line either way.
#[test]
fn apt_numbers_beyond_a_machine_are_refused_at_their_line() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("big.apt"),
        "LOAD/TOOL,1\nFEDRAT/500,MMPM\n$$ the next is too far\nGOTO/1e300,0,0,0,0,1\nFINI\n",
    )
    .expect("written");
    for extra in [
        &["--tcpc"][..],
        &["--machine", "head-table-bc", "--tool-length", "100"],
    ] {
        let mut args = vec!["post", "big.apt"];
        args.extend_from_slice(extra);
        let out = common::run_in(dir.path(), &args, b"");
        let err = common::stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains("big.apt:line 4:"), "{extra:?}: {err}");
        assert!(
            err.contains("beyond what a machine can have"),
            "{extra:?}: {err}"
        );
        assert!(common::stdout(&out).is_empty(), "{extra:?}");
    }
}

/// A G43.5 program that turns the tool around the vertical twice (the
/// rotating axis winds through 720°), with spindle, coolant and a tool
/// change to carry.
fn winding_program() -> String {
    let mut p = String::from(
        "G21 G17 G90 G94 G54\nT1 M6\nS5000 M3\nM8\nG0 X0 Y0 Z150.\nG43.5 H1 X30. Y0 Z20.\n",
    );
    for k in 0..=48 {
        let az = (f64::from(k) * 15.0).to_radians();
        let t = 30f64.to_radians();
        p.push_str(&format!(
            "G1 X{:.4} Y{:.4} Z-5. I{:.6} J{:.6} K{:.6}{}\n",
            30.0 * az.cos(),
            30.0 * az.sin(),
            t.sin() * az.cos(),
            t.sin() * az.sin(),
            t.cos(),
            if k == 0 { " F800." } else { "" }
        ));
    }
    p.push_str("G0 Z150.\nG49\nM9\nM5\nM30\n");
    p
}

#[test]
fn retargeting_with_flips_feed_styles_and_carried_words() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(dir.path().join("wind.nc"), winding_program()).expect("written");
    std::fs::write(
        dir.path().join("o.toml"),
        "[tools]\n1 = { length = 100.0 }\n[work]\nG54 = [0.0, 0.0, 20.0]\n",
    )
    .expect("written");
    // The same machine with its C table limited to ±200°.
    let show = common::run_in(dir.path(), &["machines", "show", "head-table-bc"], b"");
    let machine = common::stdout(&show);
    let at = machine
        .rfind("rollover = true")
        .expect("the C axis rolls over");
    let limited = format!(
        "{}rollover = false\nmin = -200.0\nmax = 200.0{}",
        &machine[..at],
        &machine[at + "rollover = true".len()..]
    );
    std::fs::write(dir.path().join("limited.toml"), limited).expect("written");
    let out = common::run_in(
        dir.path(),
        &[
            "post",
            "wind.nc",
            "--from-machine",
            "head-table-bc",
            "--machine",
            "limited.toml",
            "--offsets",
            "o.toml",
            "--retract",
            "3",
            "-o",
            "wind-limited.nc",
        ],
        b"",
    );
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let text = std::fs::read_to_string(dir.path().join("wind-limited.nc")).expect("written");
    for needle in [
        "(WRITTEN FOR: SWIVEL HEAD B WITH ROTARY TABLE C, RETARGETED)",
        "RETRACT 3 MM ALONG THE TOOL AXIS",
        "(FLIP END: RE-ENGAGED AT THE SAME TIP)",
        "\nT1 M6\nS5000 M3\nM8\n",
        "\nM9\nM5\nM30\n",
    ] {
        assert!(text.contains(needle), "{needle} missing:\n{text}");
    }
    // The output keeps the limits: the kernel runs it with them.
    let run = common::run_in(
        dir.path(),
        &[
            "run",
            "wind-limited.nc",
            "--machine",
            "limited.toml",
            "--offsets",
            "o.toml",
        ],
        b"",
    );
    assert_eq!(run.status.code(), Some(0), "{}", common::stderr(&run));
    // Feed styles.
    for (feed, needle, gone) in [
        ("dpm", "G54 G94\n", "G93"),
        ("programmed", "TIP FEED ERROR UP TO ", "G93"),
        ("inverse-time", "G54 G93\n", "G54 G94"),
    ] {
        let out = common::run_in(
            dir.path(),
            &[
                "post",
                "wind.nc",
                "--machine",
                "head-table-bc",
                "--offsets",
                "o.toml",
                "--feed",
                feed,
            ],
            b"",
        );
        assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
        let text = common::stdout(&out);
        assert!(
            text.contains(needle) && !text.contains(gone),
            "{feed}:\n{text}"
        );
    }
    let out = common::run_in(dir.path(), &["post", "wind.nc", "--feed", "fast"], b"");
    assert_eq!(out.status.code(), Some(2));
    // A machine-axis program back to TCPC-free axes of another machine:
    // the tool length comes from the first output's header.
    let out = common::run_in(
        dir.path(),
        &[
            "post",
            "wind-limited.nc",
            "--from-machine",
            "limited.toml",
            "--machine",
            "head-head-ca",
            "--offsets",
            "o.toml",
        ],
        b"",
    );
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let text = common::stdout(&out);
    assert!(text.contains("TOOL LENGTH 100.0000 MM"), "{text}");
    let out = common::run_in(
        dir.path(),
        &[
            "post",
            "wind.nc",
            "--from-machine",
            "head-table-bc",
            "--axes",
            "source",
        ],
        b"",
    );
    assert_eq!(out.status.code(), Some(2));
}

/// A machine without two rotary axes cannot take the post's own rotary
/// solution: the tip is followed, the header says how far the direction
/// is off, and nothing panics.
#[test]
fn retargeting_to_a_three_axis_mill_keeps_the_tip() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("p.nc"),
        "G0 X0 Y0 Z50. B0 C0\nG1 X10. B20. F100.\nG1 X20. B0\nM30\n",
    )
    .expect("written");
    let machine = "mill-3axis";
    let out = common::run_in(
        dir.path(),
        &[
            "post",
            "p.nc",
            "--from-machine",
            "head-table-bc",
            "--machine",
            machine,
            "--tool-length",
            "100",
            "-o",
            "out.nc",
        ],
        b"",
    );
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let text = std::fs::read_to_string(dir.path().join("out.nc")).expect("written");
    assert!(
        text.contains(
            "(WARNING: THE MACHINE CANNOT TURN THE TOOL, DIRECTION OFF BY UP TO 20.0000 DEG)"
        ),
        "{text}"
    );
    let run = common::run_in(dir.path(), &["run", "out.nc", "--machine", machine], b"");
    assert_eq!(run.status.code(), Some(0), "{}", common::stderr(&run));
    let out = common::run_in(
        dir.path(),
        &["post", "p.nc", "--machine", "mill-3axis", "--axes", "post"],
        b"",
    );
    assert_eq!(out.status.code(), Some(1), "{}", common::stderr(&out));
}

/// The retargeting example of docs/post.md: three flips, and the output runs on
/// the limited machine.
#[test]
fn the_readme_winding_example_flips_three_times() {
    let root = common::root();
    let out = common::run_in(
        root,
        &[
            "post",
            "examples/tcpc-winding.nc",
            "--from-machine",
            "head-table-bc",
            "--machine",
            "examples/head-table-bc-limited.toml",
            "--offsets",
            "examples/offsets.toml",
        ],
        b"",
    );
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let text = common::stdout(&out);
    assert!(text.contains(", 3 FLIPS: RETRACT 5 MM"), "{text}");
    assert_eq!(text.matches("(FLIP END").count(), 3);
}

/// A G43.4 program whose H the offsets may not hold.
const TCPC: &str =
    "G21 G90 G94\nG0 X0 Y0 Z100. A0 C0\nG43.4 H1 X0 Y0 Z20.\nG1 X20. A10. F500.\nG49\nM30\n";

#[test]
fn a_post_without_a_tool_length_stops_and_says_how_to_give_one() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(dir.path().join("p.nc"), TCPC).expect("written");
    std::fs::write(
        dir.path().join("no-h1.toml"),
        "[tools]\n2 = { length = 80.0 }\n",
    )
    .expect("written");
    std::fs::write(
        dir.path().join("h1.toml"),
        "[tools]\n1 = { length = 120.0 }\n",
    )
    .expect("written");
    for extra in [&[][..], &["--offsets", "no-h1.toml"][..]] {
        let mut args = vec!["post", "p.nc", "-o", "out.nc"];
        args.extend(extra);
        let out = common::run_in(dir.path(), &args, b"");
        let err = common::stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{err}");
        for needle in [
            "p.nc",
            "no tool length",
            "--tool-length MM",
            "--offsets FILE",
        ] {
            assert!(err.contains(needle), "{needle} missing: {err}");
        }
        assert!(common::stdout(&out).is_empty());
        assert!(!dir.path().join("out.nc").exists());
    }
    // From the offsets file's tool the program selects, or given.
    for (extra, length) in [
        (&["--offsets", "h1.toml"][..], "120.0000"),
        (&["--tool-length", "95.5"][..], "95.5000"),
        (
            &["--offsets", "no-h1.toml", "--tool-length", "95.5"][..],
            "95.5000",
        ),
        // The file's own length wins over --tool-length.
        (
            &["--offsets", "h1.toml", "--tool-length", "95.5"][..],
            "120.0000",
        ),
    ] {
        let mut args = vec!["post", "p.nc"];
        args.extend(extra);
        let out = common::run_in(dir.path(), &args, b"");
        assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
        let text = common::stdout(&out);
        assert!(
            text.contains(&format!("(FOR TOOL LENGTH {length} MM ONLY")),
            "{extra:?}: {text}"
        );
    }
}

#[test]
fn a_program_with_nothing_to_convert_is_written_unchanged() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    // Arcs and G43 on a five-axis machine, but no TCPC and no tilted plane.
    let program = "%\nO1000 (PLAIN)\nG21 G90 G94 G17\nG0 X0 Y0 Z50. A0 C0\nG43 H1 Z10.\nG2 X20. Y0 R10. F300.\nG1 A20. C45.\nG49\nM30\n%\n";
    std::fs::write(dir.path().join("p.nc"), program).expect("written");
    let out = common::run_in(dir.path(), &["post", "p.nc"], b"");
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    assert_eq!(common::stdout(&out), program);
    assert_eq!(
        common::stderr(&out).trim_end(),
        "note: p.nc: nothing to convert: the program uses no TCPC or tilted working plane; written unchanged"
    );
    let out = common::run_in(dir.path(), &["post", "p.nc", "-o", "out.nc"], b"");
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let written = std::fs::read(dir.path().join("out.nc")).expect("written");
    assert_eq!(written, program.as_bytes());
    // The same program with TCPC is converted (and needs its tool length).
    let tcpc = program.replace("G43 H1", "G43.4 H1");
    std::fs::write(dir.path().join("t.nc"), tcpc).expect("written");
    let out = common::run_in(dir.path(), &["post", "t.nc", "--tool-length", "100"], b"");
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    assert!(common::stdout(&out).contains("(FIVEAXIS POST"));
    assert!(!common::stderr(&out).contains("nothing to convert"));
}

/// CL words the reader does not know are skipped with a warning naming
/// the word and its first line, known words it does not carry out with a
/// note; the program is written all the same.
#[test]
fn unknown_cl_words_are_warned_with_their_line() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(
        dir.path().join("w.cl"),
        "REMARK Creo writes remarks without a slash\nMACHIN/UNCX01,1\nFROBNICATE/3\nPPWORD/MYWORD,1\n\
         RAPID\nGOTO/0,0,10\nFROBNICATE/4\nFEDRAT/500,MMPM\nGOTO/20,0,10\nFINI\n",
    )
    .expect("written");
    let out = common::run_in(dir.path(), &["post", "w.cl", "--tcpc"], b"");
    let err = common::stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains("warning: w.cl:line 3: FROBNICATE: ")
            && err.contains("(2 records, the first here)"),
        "{err}"
    );
    assert!(err.contains("note: w.cl:line 4: PPWORD: "), "{err}");
    assert_eq!(err.lines().count(), 2, "{err}");
    assert!(common::stdout(&out).contains("(REMARK CREO WRITES REMARKS WITHOUT A SLASH)"));
}

/// Creo's CL file, named as Creo names it (`.ncl` with a version), is
/// read as CL data and converted to machine axes; `STOP` and `OPSTOP`
/// become M0 and M1, carried into the output.
#[test]
fn a_creo_cl_file_with_its_version_converts() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let creo = include_str!("../../fiveaxis-post/tests/cl/creo.ncl")
        .replace("SPINDL / OFF", "STOP\nOPSTOP\nSPINDL / OFF");
    std::fs::write(dir.path().join("seq00005.ncl.1"), creo).expect("written");
    let out = common::run_in(
        dir.path(),
        &[
            "post",
            "seq00005.ncl.1",
            "--machine",
            "head-table-bc",
            "--tool-length",
            "100",
            "-o",
            "out.nc",
        ],
        b"",
    );
    let err = common::stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.is_empty(), "{err}");
    let text = std::fs::read_to_string(dir.path().join("out.nc")).expect("written");
    assert!(text.contains("(SOURCE: SEQ00005.NCL.1)"), "{text}");
    let m0 = text.find("M0\n").expect("M0");
    let m1 = text.find("M1\n").expect("M1");
    assert!(m0 < m1 && m1 < text.find("M5\n").expect("M5"), "{text}");
}

/// The last row's tool tip (`tip_x`, `tip_y`, `tip_z`) of `run` output.
fn last_tip(csv: &str) -> [f64; 3] {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let last: Vec<&str> = lines.last().expect("a row").split(',').collect();
    let column = |name: &str| {
        let i = header.iter().position(|c| *c == name).expect("tip column");
        last[i].parse::<f64>().expect("a number")
    };
    [column("tip_x"), column("tip_y"), column("tip_z")]
}

/// A FANUC TCPC program made a SINUMERIK machine-axis program for a machine
/// without the option (SINUMERIK text: transfer header, `;` comments, no
/// TRAORI), and a SINUMERIK TRAORI program made a FANUC one: each output
/// runs on its machine and ends with the tool tip where the source's ends
/// (the tips come from forward kinematics of the axes).
#[test]
fn fanuc_tcpc_retargets_to_a_sinumerik_machine_and_back() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let examples = common::root().join("examples");
    for name in ["tcpc-vector.nc", "swivel-drill.mpf", "offsets.toml"] {
        std::fs::copy(examples.join(name), dir.path().join(name)).expect("copied");
    }
    let cases = [
        (
            "tcpc-vector.nc",
            "head-table-bc",
            "sinumerik-dmu-bc",
            "out.mpf",
        ),
        (
            "swivel-drill.mpf",
            "sinumerik-dmu-bc",
            "head-table-bc",
            "out.nc",
        ),
    ];
    for (source, from, to, output) in cases {
        let out = common::run_in(
            dir.path(),
            &[
                "post",
                source,
                "--from-machine",
                from,
                "--machine",
                to,
                "--offsets",
                "offsets.toml",
                "-o",
                output,
            ],
            b"",
        );
        assert_eq!(
            out.status.code(),
            Some(0),
            "{source}: {}",
            common::stderr(&out)
        );
        let text = std::fs::read_to_string(dir.path().join(output)).expect("written");
        let blocks: String = text
            .lines()
            .filter(|l| !l.starts_with('(') && !l.starts_with(';'))
            .collect();
        if to == "sinumerik-dmu-bc" {
            assert!(text.starts_with("%_N_"), "{text}");
            assert!(
                text.contains("G71 G17 G90 G40 G54 D0 TRAFOOF G93"),
                "{text}"
            );
            for gone in ["TRAORI", "A3=", "G43", " I", " J", " K", "("] {
                assert!(!blocks.contains(gone), "{gone} left in:\n{text}");
            }
        } else {
            assert!(text.starts_with("%\n(FIVEAXIS POST"), "{text}");
            for gone in ["TRAORI", "A3=", "CYCLE", ";"] {
                assert!(!blocks.contains(gone), "{gone} left in:\n{text}");
            }
        }
        let run_on = |program: &str, machine: &str| {
            let run = common::run_in(
                dir.path(),
                &[
                    "run",
                    program,
                    "--machine",
                    machine,
                    "--offsets",
                    "offsets.toml",
                ],
                b"",
            );
            assert_eq!(
                run.status.code(),
                Some(0),
                "{program}: {}",
                common::stderr(&run)
            );
            last_tip(&common::stdout(&run))
        };
        let (want, got) = (run_on(source, from), run_on(output, to));
        let distance = (0..3)
            .map(|k| (want[k] - got[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(
            distance < 0.01,
            "{source} on {to}: the output ends at {got:?}, the source at {want:?}"
        );
    }
}

/// The machine axes (`X`, `Y`, `Z`, `A`, `C`) of every row of `run`
/// output.
fn machine_rows(csv: &str) -> Vec<[f64; 5]> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let columns: Vec<usize> = ["X", "Y", "Z", "A", "C"]
        .iter()
        .map(|name| {
            header
                .iter()
                .position(|c| c == name)
                .expect("an axis column")
        })
        .collect();
    lines
        .map(|line| {
            let row: Vec<&str> = line.split(',').collect();
            let mut axes = [0.0; 5];
            for (a, &i) in axes.iter_mut().zip(&columns) {
                *a = row[i].parse().expect("a number");
            }
            axes
        })
        .collect()
}

/// A FANUC TCPC program, on a FANUC machine with the kinematics of the
/// built-in HEIDENHAIN A/C table, made a Klartext machine-axis program for
/// `heidenhain-dmu-ac`: numbered blocks, `L … R0 FMAX` / `L … R0 F…`,
/// the carried S and M words as `TOOL CALL Z S…` and M blocks, the
/// composite feed (the TNC has no inverse time: asked for, refused).
/// `fiveaxis run` reads the output as Klartext and moves the axes to the
/// written positions plus the preset, ending where the source ends; and
/// the Klartext output posted back to the FANUC machine reads its tool
/// length and carried words.
#[test]
fn fanuc_tcpc_retargets_to_a_heidenhain_machine_and_back() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let show = common::run_in(dir.path(), &["machines", "show", "heidenhain-dmu-ac"], b"");
    assert_eq!(show.status.code(), Some(0), "{}", common::stderr(&show));
    let heidenhain = common::stdout(&show);
    assert!(
        heidenhain.contains("control = \"heidenhain\""),
        "{heidenhain}"
    );
    std::fs::write(
        dir.path().join("fanuc-ac.toml"),
        heidenhain.replace("control = \"heidenhain\"", "control = \"fanuc30i\""),
    )
    .expect("written");
    std::fs::write(
        dir.path().join("o.toml"),
        "[tools]\n1 = { length = 100.0 }\n[work]\nG54 = [0.0, 0.0, -500.0]\n",
    )
    .expect("written");
    std::fs::write(
        dir.path().join("p.nc"),
        "G21 G17 G90 G94 G54\nT1 M6\nS1200 M3\nM8\nG0 X0 Y0 Z-100. A0 C0\nG43.4 H1 X20. Y0 Z20.\n\
         G1 Z5. F500.\nG1 X30. Y10. A-20. C30.\nG1 X-10. Y25. A-35. C120.\nG0 Z80.\nG49\nM9\nM5\nM30\n",
    )
    .expect("written");
    let post = |extra: &[&str]| {
        let mut args = vec![
            "post",
            "p.nc",
            "--from-machine",
            "fanuc-ac.toml",
            "--machine",
            "heidenhain-dmu-ac",
            "--offsets",
            "o.toml",
        ];
        args.extend_from_slice(extra);
        common::run_in(dir.path(), &args, b"")
    };
    let out = post(&["-o", "out.h"]);
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let text = std::fs::read_to_string(dir.path().join("out.h")).expect("written");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "0 BEGIN PGM FIVEAXIS MM", "{text}");
    for (n, line) in lines.iter().enumerate() {
        assert!(line.starts_with(&format!("{n} ")), "block {n}:\n{text}");
    }
    let last = lines.len() - 1;
    assert_eq!(lines[last], format!("{last} END PGM FIVEAXIS MM"), "{text}");
    for needle in [
        " ;FOR TOOL LENGTH 100.0000 MM ONLY",
        "THE TNC'S READING WITHOUT M116",
        " FUNCTION RESET TCPM\n",
        " TOOL CALL 1 Z\n",
        " TOOL CALL Z S1200\n",
        " M3\n",
        " M8\n",
        // Less the tool length the TOOL CALL switches on.
        " L X+0.0000 Y+0.0000 Z-200.0000 A+0.00000 C+0.00000 R0 FMAX\n",
        " L X+20.0000 Y+0.0000 Z+20.0000 A+0.00000 C+0.00000 R0 FMAX\n",
        " M9\n",
        " M5\n",
        " M30\n",
    ] {
        assert!(text.contains(needle), "{needle} missing:\n{text}");
    }
    let blocks: Vec<&str> = lines
        .iter()
        .map(|l| l.split_once(' ').expect("a block number").1)
        .filter(|l| !l.starts_with(';'))
        .collect();
    for gone in [" G0", " G1", " G4", " G9", "M128", "(", "%", "-0.0000 "] {
        assert!(
            !blocks.iter().any(|b| format!(" {b}").contains(gone)),
            "{gone} left in:\n{text}"
        );
    }
    // The written positions of the L blocks, in the preset (Z -500),
    // with the length of tool 1 (100).
    let written: Vec<[f64; 5]> = blocks
        .iter()
        .filter(|b| b.starts_with("L "))
        .map(|b| {
            let mut axes = [0.0; 5];
            for (k, name) in ["X", "Y", "Z", "A", "C"].iter().enumerate() {
                let word = b
                    .split(' ')
                    .find(|w| w.starts_with(name))
                    .unwrap_or_else(|| panic!("{name} in {b}"));
                let value = &word[1..];
                assert!(value.starts_with(['+', '-']), "{word}: a sign");
                axes[k] = value.parse().expect("a number");
            }
            axes[2] += -500.0 + 100.0;
            axes
        })
        .collect();
    assert!(
        blocks
            .iter()
            .any(|b| b.starts_with("L ") && b.ends_with(" R0 FMAX"))
    );
    assert!(
        blocks
            .iter()
            .any(|b| b.starts_with("L ") && b.contains(" R0 F") && !b.contains("FMAX"))
    );
    let run = |program: &str, machine: &str| {
        let run = common::run_in(
            dir.path(),
            &["run", program, "--machine", machine, "--offsets", "o.toml"],
            b"",
        );
        assert_eq!(
            run.status.code(),
            Some(0),
            "{program}: {}",
            common::stderr(&run)
        );
        machine_rows(&common::stdout(&run))
    };
    let rows = run("out.h", "heidenhain-dmu-ac");
    assert_eq!(rows.len(), written.len(), "{text}");
    for (row, want) in rows.iter().zip(&written) {
        for k in 0..5 {
            assert!(
                (row[k] - want[k]).abs() < 1e-9,
                "the run moves to {row:?}, the program says {want:?}"
            );
        }
    }
    // Where the source ends, within the written decimals.
    let source = run("p.nc", "fanuc-ac.toml");
    let (end, want) = (rows.last().expect("a row"), source.last().expect("a row"));
    for k in 0..5 {
        assert!(
            (end[k] - want[k]).abs() < 1e-4,
            "the output ends at {end:?}, the source at {want:?}"
        );
    }
    // Inverse time asked for: refused, nothing written.
    let out = post(&["--feed", "inverse-time", "-o", "no.h"]);
    assert_eq!(out.status.code(), Some(2), "{}", common::stderr(&out));
    assert!(
        common::stderr(&out).contains("no inverse time"),
        "{}",
        common::stderr(&out)
    );
    assert!(!dir.path().join("no.h").exists());
    let out = post(&["--feed", "programmed"]);
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    assert!(common::stdout(&out).contains(";3 CUTTING BLOCKS IN, "));
    assert!(common::stdout(&out).contains("FEED F AS PROGRAMMED: TIP FEED ERROR UP TO "));
    // The Klartext output posted back to the FANUC machine: read as
    // Klartext, its tool length from its header, its words carried.
    let out = common::run_in(
        dir.path(),
        &[
            "post",
            "out.h",
            "--from-machine",
            "heidenhain-dmu-ac",
            "--machine",
            "fanuc-ac.toml",
            "--offsets",
            "o.toml",
            "-o",
            "back.nc",
        ],
        b"",
    );
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let back = std::fs::read_to_string(dir.path().join("back.nc")).expect("written");
    for needle in [
        "TOOL LENGTH 100.0000 MM",
        "\nT1 M6\nS1200\nM3\nM8\n",
        "\nM9\nM5\nM30\n%\n",
    ] {
        assert!(back.contains(needle), "{needle} missing:\n{back}");
    }
    let rows = run("back.nc", "fanuc-ac.toml");
    let end = rows.last().expect("a row");
    for k in 0..5 {
        assert!(
            (end[k] - want[k]).abs() < 1e-3,
            "back ends at {end:?}, the source at {want:?}"
        );
    }
}
