//! `--programs DIR`: the control's program memory. Programs that `M98` and
//! `G65` call by number and that the running file does not hold come from
//! the folder: a file named after the number, or the file whose first `O`
//! line has it.

mod common;

use common::run_in;

#[test]
fn calls_reach_programs_kept_in_other_files() {
    let dir = tempfile::tempdir().expect("dir");
    let lib = dir.path().join("memory");
    std::fs::create_dir(&lib).expect("mkdir");
    std::fs::write(
        lib.join("O9010.nc"),
        "%\nO9010 (DRILL)\nG0 X#24 Y#25\nG1 Z-#26 F100.\nG0 Z0\nM99\n%\n",
    )
    .expect("write");
    std::fs::write(
        lib.join("fixture-probe.txt"),
        "O0042 (BY ITS O LINE)\nG0 X99.\nM99\n",
    )
    .expect("write");
    let program = b"G65 P9010 X10. Y20. Z5.\nM98 P42\nG0 X0\nM30\n";
    let out = run_in(dir.path(), &["run", "-", "--programs", "memory"], program);
    let rows = String::from_utf8_lossy(&out.stdout).into_owned();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let xyz: Vec<String> = rows
        .lines()
        .skip(1)
        .map(|l| l.split(',').take(6).collect::<Vec<_>>().join(","))
        .collect();
    assert_eq!(
        xyz,
        vec![
            "3,1,rapid,10,20,500",
            "4,1,linear,10,20,-5",
            "5,1,rapid,10,20,0",
            "2,1,rapid,99,20,0",
            "3,1,rapid,0,20,0",
        ]
    );
    // Without the folder the call is the control's alarm.
    let out = run_in(dir.path(), &["run", "-"], program);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("PS0078"));
}

#[test]
fn an_alarm_in_a_library_program_names_its_file() {
    let dir = tempfile::tempdir().expect("dir");
    std::fs::write(dir.path().join("O7.nc"), "O7\nG0 X1. X2.\nM99\n").expect("write");
    let out = run_in(dir.path(), &["run", "-", "--programs", "."], b"M98 P7\n");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("O7.nc:2:"), "{err}");
}
