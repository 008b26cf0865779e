//! The tilted-working-plane demos of LinuxCNC's nutating-head sim
//! (`lcnc_trsrn_*.ngc`, `lcnc_suite_twp_simple_example.ngc`) run through
//! the binary to their M2 on a two-rotary head (C primary, A secondary at
//! nutation 90°) whose machine file has `twp_remap = true`, written here.
//! The configurations' own three-rotary machines, imported, run them in
//! `corpus_linuxcnc.rs`.
//! The corpus files are read in place: `o<square> call` finds `square.ngc`
//! as a symbolic link, made at test time, to `lcnc_trsrn_square.ngc`.

mod common;

use std::path::Path;

const MACHINE: &str = r#"
name = "head C + A, nutation 90, TWP remap"
type = "head"
control = "linuxcnc"
[[linear]]
name = "X"
min = -100000.0
max = 100000.0
[[linear]]
name = "Y"
min = -100000.0
max = 100000.0
[[linear]]
name = "Z"
min = -100000.0
max = 100000.0
[[rotary]]
name = "C"
on = "head"
axis = [0.0, 0.0, 1.0]
center = [0.0, 0.0, 0.0]
min = -36000.0
max = 36000.0
[[rotary]]
name = "A"
on = "head"
axis = [1.0, 0.0, 0.0]
center = [0.0, 0.0, 150.0]
min = -360.0
max = 360.0
[parameters]
twp_remap = true
subroutine_path = ["subs"]
"#;

const TOOL_TABLE: &str = "linuxcnc-configs/axis/vismach/5axis/table-rotary_spindle-rotary-nutating/xyzbca-trsrn_twp/xyzbca-trsrn.tbl";

#[test]
fn twp_demos_reach_their_end() {
    let Some(corpus) = common::corpus_or_skip() else {
        return;
    };
    let dir = tempfile::tempdir().expect("a temporary directory");
    let subs = dir.path().join("subs");
    std::fs::create_dir(&subs).expect("a folder");
    std::os::unix::fs::symlink(
        corpus.join("lcnc_trsrn_square.ngc"),
        subs.join("square.ngc"),
    )
    .expect("a link");
    let table = corpus.join(TOOL_TABLE);
    let text = format!(
        "{MACHINE}tool_table = {:?}\n",
        table.to_str().expect("UTF-8 paths")
    );
    let machine = dir.path().join("machine.toml");
    std::fs::write(&machine, text).expect("the machine file");
    let mut failures = Vec::new();
    for name in [
        "lcnc_trsrn_simple_example.ngc",
        "lcnc_suite_twp_simple_example.ngc",
        "lcnc_trsrn_incremental_repetition.ngc",
        "lcnc_trsrn_incremental_repetition_g533.ngc",
        "lcnc_trsrn_incremental_repetition_back_and_forth.ngc",
    ] {
        let program = corpus.join(name);
        let out = common::run_in(
            Path::new(dir.path()),
            &[
                "run",
                "--machine",
                machine.to_str().expect("UTF-8"),
                program.to_str().expect("UTF-8"),
            ],
            b"",
        );
        if out.status.code() != Some(0) {
            failures.push(format!("{name}: {}", common::stderr(&out)));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
