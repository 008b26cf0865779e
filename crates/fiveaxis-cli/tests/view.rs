//! `fiveaxis view`: the page as a file (whole or not at all, exit status as
//! `run`), and the viewer's own tests in a real browser (`viewer/test/`,
//! run with node, playwright-core and Debian's Chromium) on this binary.

mod common;

use std::process::Command;

#[test]
fn the_page_is_one_file_with_the_data_and_the_viewer() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    std::fs::write(dir.path().join("p.nc"), "G0 X10. Y5.\nG1 Z-1. F100.\nM30\n").expect("written");
    let out = common::run_in(dir.path(), &["view", "p.nc"], b"");
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let page = std::fs::read_to_string(dir.path().join("p.html")).expect("p.html written beside");
    assert!(page.starts_with("<!DOCTYPE html>"));
    assert!(page.contains("\"blocks\":2"));
    assert!(page.contains("id=\"fiveaxis-program\">G0 X10. Y5.\nG1 Z-1. F100.\nM30\n</script>"));
    // Nothing loaded from elsewhere (the browser test also watches the
    // requests the page makes: none but the file itself).
    for tag in ["<link", "<script src", "<img", "<iframe"] {
        assert!(!page.contains(tag), "{tag}");
    }
}

#[test]
fn an_alarm_is_shown_and_exits_1_a_bad_input_leaves_the_target_alone() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    // An over-travel is a finding drawn on the path (as `check` reports
    // it), and the program goes on to its alarm: G1 without a feed.
    std::fs::write(
        dir.path().join("p.nc"),
        "G0 X10.\nG1 X600. F100.\nG0 X0\nG94 G1 F0 X5.\n",
    )
    .expect("written");
    let out = common::run_in(dir.path(), &["view", "p.nc", "-o", "v.html"], b"");
    assert_eq!(out.status.code(), Some(1), "{}", common::stderr(&out));
    assert!(
        common::stderr(&out).contains(" line 4"),
        "{}",
        common::stderr(&out)
    );
    let page = std::fs::read_to_string(dir.path().join("v.html")).expect("written");
    // The findings as columns: lines 2 and 4 (u32), kinds over-travel and
    // alarm (their indices in `Kind::ALL`), and the messages.
    assert_eq!(
        common::page_element(&page, "fiveaxis-array-finding_lines"),
        [2, 0, 0, 0, 4, 0, 0, 0],
        "the findings at lines 2 and 4"
    );
    assert_eq!(
        common::page_element(&page, "fiveaxis-array-finding_kinds"),
        [1, 0],
        "an over-travel and an alarm"
    );
    assert!(
        page.contains("\"finding_messages\":[\"X+ over-travel"),
        "the messages"
    );

    std::fs::write(dir.path().join("keep.html"), "old").expect("written");
    let out = common::run_in(
        dir.path(),
        &["view", "p.nc", "--machine", "nope", "-o", "keep.html"],
        b"",
    );
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        std::fs::read_to_string(dir.path().join("keep.html")).expect("kept"),
        "old"
    );
    let out = common::run_in(dir.path(), &["view", "p.nc", "-o", "p.nc"], b"");
    assert_eq!(
        out.status.code(),
        Some(2),
        "the page never replaces the program"
    );
}

#[test]
fn the_page_goes_into_the_current_directory_and_says_where() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let (src, out) = (dir.path().join("src"), dir.path().join("out"));
    std::fs::create_dir(&src).expect("src");
    std::fs::create_dir(&out).expect("out");
    let program = "G0 X10. Y5.\nG1 Z-1. F100.\nM30\n";
    std::fs::write(src.join("bracket.nc"), program).expect("written");

    // Without -o: the program's name with .html, where the command runs,
    // not beside the program.
    let run = common::run_in(&out, &["view", "../src/bracket.nc"], b"");
    assert_eq!(run.status.code(), Some(0), "{}", common::stderr(&run));
    let page = std::fs::read(out.join("bracket.html")).expect("written where it ran");
    assert!(
        !src.join("bracket.html").exists(),
        "nothing beside the program"
    );
    let said = common::stderr(&run);
    let size = page.len();
    assert!(size > 1000, "{size} bytes");
    assert_eq!(
        said,
        format!(
            "wrote bracket.html ({:.1} kB): open it in a browser\n",
            size as f64 / 1e3
        ),
    );
    assert!(common::stdout(&run).is_empty());

    // With -o, there, and said so.
    let run = common::run_in(
        &out,
        &["view", "../src/bracket.nc", "-o", "../src/b.html"],
        b"",
    );
    assert_eq!(run.status.code(), Some(0), "{}", common::stderr(&run));
    assert!(src.join("b.html").exists());
    assert!(
        common::stderr(&run).starts_with("wrote ../src/b.html ("),
        "{}",
        common::stderr(&run)
    );

    // Standard input: stdin.html.
    let run = common::run_in(&out, &["view", "-"], program.as_bytes());
    assert_eq!(run.status.code(), Some(0), "{}", common::stderr(&run));
    assert!(out.join("stdin.html").exists());
    assert!(
        common::stderr(&run).starts_with("wrote stdin.html ("),
        "{}",
        common::stderr(&run)
    );

    // A program named .html run where it is would be replaced by its own
    // page: refused before the run, the program kept.
    std::fs::write(out.join("prog.html"), program).expect("written");
    let run = common::run_in(&out, &["view", "prog.html"], b"");
    assert_eq!(run.status.code(), Some(2));
    assert!(
        common::stderr(&run).contains("would replace the program"),
        "{}",
        common::stderr(&run)
    );
    assert_eq!(
        std::fs::read_to_string(out.join("prog.html")).expect("kept"),
        program
    );
    // Also through another path to the same file.
    let run = common::run_in(&out, &["view", "prog.html", "-o", "../out/prog.html"], b"");
    assert_eq!(run.status.code(), Some(2), "{}", common::stderr(&run));

    // An alarm: the page is written and said so, after the alarm.
    std::fs::write(src.join("alarm.nc"), "G0 X10.\nG94 G1 F0 X5.\n").expect("written");
    let run = common::run_in(&out, &["view", "../src/alarm.nc"], b"");
    assert_eq!(run.status.code(), Some(1));
    let said = common::stderr(&run);
    assert!(said.starts_with("ALARM "), "{said}");
    assert!(said.contains("\nwrote alarm.html ("), "{said}");
    assert!(out.join("alarm.html").exists());
}

/// The browser tests. They need node, `npm ci` in `viewer/` and Chromium
/// (`.ci/run` installs all three); set `FIVEAXIS_NO_BROWSER=1` to leave
/// them out on a machine without them.
#[test]
fn viewer_in_a_real_browser() {
    if std::env::var_os("FIVEAXIS_NO_BROWSER").is_some() {
        eprintln!("FIVEAXIS_NO_BROWSER is set: the browser tests are left out");
        return;
    }
    let viewer = common::root().join("viewer");
    assert!(
        viewer.join("node_modules/playwright-core").exists(),
        "run `npm ci` in viewer/ first (and install Chromium: apt-get install chromium), or set FIVEAXIS_NO_BROWSER=1"
    );
    let out = Command::new("node")
        .args([
            "--test",
            "test/data.test.mjs",
            "test/kinematics.test.mjs",
            "test/simplify.test.mjs",
            "test/view.test.mjs",
        ])
        .current_dir(&viewer)
        .env("FIVEAXIS", env!("CARGO_BIN_EXE_fiveaxis"))
        .output()
        .expect("node runs (install Node.js, or set FIVEAXIS_NO_BROWSER=1)");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "viewer tests failed:\n{text}");
    assert!(text.contains("# fail 0"), "{text}");
}

/// A HEIDENHAIN program's stock (`BLK FORM 0.1 / 0.2`) is in the page's
/// description, its corners in workpiece coordinates, also when an alarm
/// stops the program after it; a program without one has `"stock": null`.
#[test]
fn the_page_has_the_stock_the_program_declares() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let view = |name: &str, program: &str, status: i32| {
        std::fs::write(dir.path().join(format!("{name}.h")), program).expect("written");
        let out = common::run_in(
            dir.path(),
            &[
                "view",
                &format!("{name}.h"),
                "--machine",
                "heidenhain-dmu-ac",
            ],
            b"",
        );
        assert_eq!(out.status.code(), Some(status), "{}", common::stderr(&out));
        let page =
            std::fs::read_to_string(dir.path().join(format!("{name}.html"))).expect("the page");
        page_meta(&page)
    };
    let stock = serde_json::json!({ "min": [-50.0, -30.5, -20.0], "max": [50.0, 30.5, 0.6] });

    let meta = view(
        "stock",
        "0 BEGIN PGM STOCK MM\n\
         1 BLK FORM 0.1 Z X-50 Y-30.5 Z-20\n\
         2 BLK FORM 0.2 X+50 Y+30.5 Z+0.6\n\
         3 TOOL CALL 1 Z S3000\n\
         4 L Z+50 R0 FMAX M3\n\
         5 L X-40 Y-20 R0 FMAX\n\
         6 L Z-2 R0 F200\n\
         7 L X+40 F500\n\
         8 L Y+20\n\
         9 L Z+50 R0 FMAX M30\n\
         10 END PGM STOCK MM\n",
        0,
    );
    assert_eq!(meta["stock"], stock);
    assert_eq!(meta["ended"], true);
    assert!(meta["blocks"].as_u64().expect("blocks") >= 5, "{meta}");

    // An alarm after the BLK FORM: the stock is still drawn.
    let meta = view(
        "alarm",
        "0 BEGIN PGM ALARM MM\n\
         1 BLK FORM 0.1 Z X-50 Y-30.5 Z-20\n\
         2 BLK FORM 0.2 X+50 Y+30.5 Z+0.6\n\
         3 TOOL CALL 1 Z S3000\n\
         4 L Z+50 R0 FMAX M3\n\
         5 L X+10 F0\n\
         6 END PGM ALARM MM\n",
        1,
    );
    assert_eq!(meta["stock"], stock);
    assert_eq!(meta["alarm"]["line"], 6);

    // No BLK FORM: no stock.
    let meta = view(
        "bare",
        "0 BEGIN PGM BARE MM\n\
         1 TOOL CALL 1 Z S3000\n\
         2 L Z+50 R0 FMAX M3\n\
         3 L X+10 F200\n\
         4 END PGM BARE MM\n",
        0,
    );
    assert!(
        meta.get("stock").is_some_and(serde_json::Value::is_null),
        "{meta}"
    );
}

/// The page's JSON description.
fn page_meta(page: &str) -> serde_json::Value {
    let start = page.find("id=\"fiveaxis-meta\">").expect("the description")
        + "id=\"fiveaxis-meta\">".len();
    let end = start + page[start..].find("</script>").expect("its end");
    serde_json::from_str(&page[start..end]).expect("JSON")
}

/// A packed `Float64Array` of the page.
fn page_f64(page: &str, name: &str) -> Vec<f64> {
    common::page_element(page, &format!("fiveaxis-array-{name}"))
        .chunks(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
        .collect()
}

/// `check`'s times and the page's time axis of one program (the page
/// written into `dir`).
fn check_and_view(dir: &std::path::Path, args: &[&str]) -> (serde_json::Value, String) {
    let root = common::root();
    let mut check = vec!["check"];
    check.extend(args);
    check.extend(["--format", "json", "--fail-on", "never"]);
    let out = common::run_in(root, &check, b"");
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let report: serde_json::Value =
        serde_json::from_str(common::stdout(&out).lines().next().expect("a report")).expect("JSON");
    let page = dir.join("page.html");
    let mut view = vec!["view"];
    view.extend(args);
    let page_arg = page.to_str().expect("a UTF-8 path");
    view.extend(["-o", page_arg]);
    let out = common::run_in(root, &view, b"");
    assert!(
        matches!(out.status.code(), Some(0 | 1)),
        "{}",
        common::stderr(&out)
    );
    (
        report["time"].clone(),
        std::fs::read_to_string(&page).expect("the page"),
    )
}

/// The view's timeline is `check`'s estimated time, block by block: its
/// total is the report's `time.estimated`, and it says so.
fn assert_same_time(what: &str, time: &serde_json::Value, page: &str) {
    let meta = page_meta(page);
    let estimated = time["estimated"].as_f64().expect("estimated");
    let duration = meta["duration"].as_f64().expect("duration");
    assert!(estimated > 0.0, "{what}: {time}");
    assert_eq!(duration, estimated, "{what}: the view's total is check's");
    assert_eq!(meta["time"]["estimated"], time["estimated"], "{what}");
    assert_eq!(meta["time"]["programmed"], time["programmed"], "{what}");
    let kind = meta["time"]["kind"].as_str().expect("kind");
    let label = meta["time"]["label"].as_str().expect("label");
    assert!(label.contains("as fiveaxis check"), "{what}: {label}");
    assert!(label.starts_with(kind), "{what}: {kind}, {label}");
    if time["estimated"] != time["programmed"] {
        assert_eq!(kind, "estimated", "{what}");
    }
    // Blocks and vertices on that time axis (serde_json reads a number
    // to within a unit in the last place: compared within that).
    let close = |x: Option<f64>| x.is_some_and(|x| (x - duration).abs() <= 1e-14 * duration);
    let ends = page_f64(page, "ends");
    assert!(close(ends.last().copied()), "{what}: {:?}", ends.last());
    assert!(ends.windows(2).all(|w| w[0] <= w[1]), "{what}: block ends");
    let times = page_f64(page, "times");
    assert!(
        times.windows(2).all(|w| w[0] <= w[1]),
        "{what}: vertex times"
    );
    assert!(close(times.last().copied()), "{what}: {:?}", times.last());
}

#[test]
fn the_view_and_check_give_the_same_time() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    for (program, machine) in [
        ("examples/bracket.nc", "trunnion-ac"),
        ("examples/tcpc-vector.nc", "head-table-bc"),
        ("examples/tilted-holes.nc", "trunnion-ac"),
        ("examples/subprogram.nc", "trunnion-ac"),
        ("examples/tcpc-winding.nc", "head-table-bc"),
    ] {
        let args = [
            program,
            "--machine",
            machine,
            "--offsets",
            "examples/offsets.toml",
        ];
        let (time, page) = check_and_view(dir.path(), &args);
        assert_same_time(program, &time, &page);
    }
}

/// The corpus program of the issue: the NX program for the NMV5000
/// (`../shared/corpus`; left out with a message where it is missing).
#[test]
fn the_view_and_check_give_the_same_time_on_the_nmv5000_program() {
    let program = common::corpus_dir().join("fanuc_nx_nmv5000_mm.nc");
    if !program.exists() {
        eprintln!(
            "skipped: {} is missing (the shared corpus)",
            program.display()
        );
        return;
    }
    let setups = common::root().join("crates/fiveaxis-cli/tests/corpus-setups");
    let (machine, offsets) = (
        setups.join("nmv5000.toml"),
        setups.join("nmv5000-offsets.toml"),
    );
    let dir = tempfile::tempdir().expect("a temporary directory");
    let args = [
        program.to_str().expect("UTF-8"),
        "--machine",
        machine.to_str().expect("UTF-8"),
        "--offsets",
        offsets.to_str().expect("UTF-8"),
    ];
    let (time, page) = check_and_view(dir.path(), &args);
    assert_same_time("the NMV5000 program", &time, &page);
}
