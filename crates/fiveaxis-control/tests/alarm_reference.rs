//! `docs/alarms.md` is the alarm table the code defines.

use fiveaxis_control::{Condition, alarm_reference};

#[test]
fn alarm_reference_matches_the_code() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/alarms.md");
    let expected = alarm_reference();
    if std::env::var_os("FIVEAXIS_BLESS").is_some() {
        std::fs::write(path, &expected).expect("write docs/alarms.md");
    }
    let actual = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        actual == expected,
        "docs/alarms.md is out of date: run FIVEAXIS_BLESS=1 cargo test -p fiveaxis-control alarm_reference"
    );
}

#[test]
fn kernel_codes_are_unique_per_control() {
    use fiveaxis_machine::Control;
    for control in [
        Control::Fanuc30i,
        Control::Fanuc16,
        Control::Mitsubishi,
        Control::Mazak,
    ] {
        let mut kernel: Vec<String> = Condition::ALL
            .iter()
            .map(|c| c.code(control).to_string())
            .filter(|code| code.starts_with("FX"))
            .collect();
        let n = kernel.len();
        kernel.sort();
        kernel.dedup();
        assert_eq!(
            n,
            kernel.len(),
            "two conditions share a kernel code on {control:?}"
        );
    }
}
