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
