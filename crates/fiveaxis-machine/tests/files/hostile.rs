//! Machine and offsets files from anywhere: whatever the text, reading it
//! never panics, and a file that loads holds only numbers a machine can
//! have (finite, within `MAX_FILE_MAGNITUDE`), reference positions inside
//! the soft limits and two rotary axes that are not parallel.

use fiveaxis_machine::{
    MAX_FILE_MAGNITUDE, Machine, Offsets, builtin, builtin_names, builtin_source,
};
use proptest::prelude::*;

use crate::assert_error;

/// Numbers a hostile or careless file may hold in place of a real one.
const ODD_NUMBERS: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "1e308",
    "-1.7e308",
    "1e155",
    "1e7",
    "-1e18",
    "1e-300",
    "0.0",
    "-0.0",
    "5e-324",
    "999999999",
    "1000000.0",
    "1000000.1",
];

/// The text of a built-in machine with the `n`-th number replaced.
fn with_number_replaced(text: &str, n: usize, by: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut count = 0;
    let bytes = text.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        let starts_number = (bytes[i].is_ascii_digit() || bytes[i] == b'-')
            && (i == 0 || matches!(bytes[i - 1], b' ' | b'[' | b'='));
        if starts_number {
            let end = text[i..]
                .find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '-' | 'e' | '+')))
                .map_or(text.len(), |k| i + k);
            if count == n {
                out.push_str(by);
            } else {
                out.push_str(&text[i..end]);
            }
            count += 1;
            i = end.max(i + 1);
        } else {
            let c = text[i..].chars().next().unwrap_or(' ');
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

fn check_machine(machine: &Machine) -> Result<(), TestCaseError> {
    let sane = |x: f64| x.is_finite() && x.abs() <= MAX_FILE_MAGNITUDE;
    for axis in &machine.linear {
        prop_assert!(sane(axis.min) && sane(axis.max));
    }
    for (k, axis) in machine.rotary.iter().enumerate() {
        prop_assert!(axis.center.iter().all(|&x| sane(x)));
        if let Some((lo, hi)) = axis.limits {
            prop_assert!(sane(lo) && sane(hi));
        }
        for other in &machine.rotary[..k] {
            prop_assert!(
                other.axis.cross(&axis.axis).norm() > 1e-9,
                "parallel rotary axes loaded"
            );
        }
    }
    for reference in [&machine.params.reference_1, &machine.params.reference_2] {
        for (i, a) in machine.linear.iter().enumerate() {
            prop_assert!(
                (a.min..=a.max).contains(&reference[i]),
                "reference outside limits"
            );
        }
    }
    prop_assert!(sane(machine.params.least_input_increment));
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 400,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0xF11E_0008),
        ..ProptestConfig::default()
    })]

    #[test]
    fn machine_files_with_odd_numbers_are_refused_or_sane(
        machine in prop::sample::select(builtin_names()),
        n in 0usize..80,
        by in prop::sample::select(ODD_NUMBERS),
    ) {
        let Some(text) = builtin_source(machine) else { return Ok(()) };
        let text = with_number_replaced(text, n, by);
        match Machine::from_toml(&text) {
            Ok(m) => check_machine(&m)?,
            Err(e) => prop_assert!(e.line >= 1 && !e.message.is_empty()),
        }
    }

    #[test]
    fn arbitrary_text_never_panics_as_a_machine_or_offsets_file(text in "\\PC{0,400}") {
        if let Ok(m) = Machine::from_toml(&text) {
            check_machine(&m)?;
        }
        let _ = Offsets::from_toml(&text);
    }

    #[test]
    fn offsets_with_odd_numbers_are_refused_or_sane(
        by in prop::sample::select(ODD_NUMBERS),
        key in prop::sample::select(&["length", "length_wear", "radius", "radius_wear"][..]),
        work in any::<bool>(),
    ) {
        let text = if work {
            format!("[work]\nG54 = [{by}, 0.0, 0.0]\nEXT = [{by}, 0.0, 0.0]\n")
        } else {
            format!("[tools]\n1 = {{ {key} = {by} }}\n")
        };
        match Offsets::from_toml(&text) {
            Ok(o) => {
                let sane = |x: f64| x.is_finite() && x.abs() <= MAX_FILE_MAGNITUDE;
                prop_assert!(o.work.iter().all(|w| w.iter().all(|&x| sane(x))));
                prop_assert!(o.tools.values().all(|t| sane(t.length) && sane(t.length_wear) && sane(t.radius) && sane(t.radius_wear)));
            }
            Err(e) => prop_assert!(e.key.is_some(), "{e:?}"),
        }
    }
}

#[test]
fn reference_position_outside_the_limits_names_the_key() {
    let text = builtin("trunnion-ac")
        .map(|m| m.to_toml())
        .unwrap_or_default()
        .replace(
            "reference_1 = { X = 0.0, Y = 0.0, Z = 500.0, A = 0.0, C = 0.0 }",
            "reference_1 = { X = 0.0, Y = 0.0, Z = 500.0, A = 100.0, C = 0.0 }",
        );
    let Err(e) = Machine::from_toml(&text) else {
        panic!("a reference position beyond the soft limits loaded");
    };
    assert_error(
        &e,
        &text,
        "A = ^100.0",
        Some("reference_1"),
        "outside its soft limits",
    );
}

#[test]
fn parallel_rotary_axes_are_refused_at_load() {
    let machine = builtin("trunnion-ac")
        .map(|m| m.to_toml())
        .unwrap_or_default();
    let text = machine.replacen("axis = [0.0, 0.0, -1.0]", "axis = [-1.0, 0.0, 0.0]", 1);
    assert_ne!(text, machine, "the C axis line was not found");
    let Err(e) = Machine::from_toml(&text) else {
        panic!("parallel rotary axes loaded");
    };
    assert_eq!(e.key.as_deref(), Some("axis"));
    assert!(e.message.contains("parallel"), "{e:?}");
}

#[test]
fn huge_limits_are_refused_naming_the_key() {
    let text = builtin("trunnion-ac")
        .map(|m| m.to_toml())
        .unwrap_or_default();
    let text = text.replacen("min = -120.0", "min = -1e18", 1);
    let Err(e) = Machine::from_toml(&text) else {
        panic!("a stroke of 1e18 degrees loaded");
    };
    assert_eq!(e.key.as_deref(), Some("min"));
    assert!(
        e.message.contains("beyond what a machine can have"),
        "{e:?}"
    );
}
