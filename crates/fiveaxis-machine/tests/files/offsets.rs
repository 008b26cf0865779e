//! The offsets file.

use fiveaxis_machine::{FileError, Offsets, ToolOffset, Vec3};

use super::assert_error;

fn read(text: &str) -> Offsets {
    Offsets::from_toml(text).unwrap_or_else(|e| panic!("{e}\nin\n{text}"))
}

fn fail(text: &str) -> FileError {
    match Offsets::from_toml(text) {
        Ok(o) => panic!("read as {o:?}:\n{text}"),
        Err(e) => e,
    }
}

#[test]
fn empty_file_is_all_zero() {
    assert_eq!(read(""), Offsets::default());
    assert_eq!(read("[tools]\n[work]\n"), Offsets::default());
}

#[test]
fn spec_example_reads() {
    let text = r#"
[tools]
1 = { length = 100.0, radius = 5.0 }

[work]
G54 = [0.0, 0.0, 0.0]
G55 = [100.0, 0.0, -50.0]
"G54.1 P1" = [10.0, 20.0, 30.0]

[setup_error.1]
x = 0.0
y = 0.0
z = 0.0
a = 0.0
b = -30.0
c = 0.0
table = { C = 0.0 }
"#;
    let o = read(text);
    assert_eq!(
        o.tool(1),
        ToolOffset {
            length: 100.0,
            radius: 5.0,
            ..ToolOffset::default()
        }
    );
    assert_eq!(o.work[1], Vec3::new(100.0, 0.0, -50.0));
    assert_eq!(o.extended_work[0], Vec3::new(10.0, 20.0, 30.0));
    let set = &o.setup_error[&1];
    assert_eq!(set.rotation, Vec3::new(0.0, -30.0, 0.0));
    assert_eq!(set.table, [('C', 0.0)]);
}

#[test]
fn tools_default_to_zero() {
    let text = "[tools]\n7 = { length = 50 }\n999 = { radius = 3 }\n12 = {}\n";
    let o = read(text);
    assert_eq!(
        o.tool(7),
        ToolOffset {
            length: 50.0,
            ..ToolOffset::default()
        }
    );
    assert_eq!(
        o.tool(999),
        ToolOffset {
            radius: 3.0,
            ..ToolOffset::default()
        }
    );
    assert_eq!(o.tool(12), ToolOffset::default());
    assert_eq!(o.tool(8), ToolOffset::default());
    assert_eq!(o.tools.len(), 3);
}

#[test]
fn tool_wear_values_read() {
    let text = "[tools.4]\nlength = 120.5\nlength_wear = -0.02\nradius = 4\nradius_wear = 0.01\n";
    let t = read(text).tool(4);
    assert_eq!(
        (t.length, t.length_wear, t.radius, t.radius_wear),
        (120.5, -0.02, 4.0, 0.01)
    );
}

#[test]
fn every_work_offset_slot() {
    let names = ["G54", "G55", "G56", "G57", "G58", "G59"];
    let mut text = String::from("[work]\n");
    for (i, name) in names.iter().enumerate() {
        text.push_str(&format!("{name} = [{i}, 1, 2]\n"));
    }
    text.push_str("\"G54.1 P1\" = [1, 0, 0]\n\"G54.1 P48\" = [48, 0, 0]\nEXT = [0, 0, -5]\n");
    let o = read(&text);
    for (i, w) in o.work.iter().enumerate() {
        assert_eq!(*w, Vec3::new(i as f64, 1.0, 2.0));
    }
    assert_eq!(o.extended_work[0].x, 1.0);
    assert_eq!(o.extended_work[47].x, 48.0);
    assert!(o.extended_work[1..47].iter().all(|w| *w == Vec3::zeros()));
    assert_eq!(o.external, Vec3::new(0.0, 0.0, -5.0));
}

#[test]
fn setup_error_sets_zero_to_seven() {
    let text =
        "[setup_error.0]\nx = 1\n\n[setup_error.7]\nc = 2.5\ntable = { A = 10, B = 20, C = 30 }\n";
    let o = read(text);
    assert_eq!(o.setup_error[&0].origin, Vec3::new(1.0, 0.0, 0.0));
    assert_eq!(o.setup_error[&0].table, []);
    assert_eq!(o.setup_error[&7].rotation, Vec3::new(0.0, 0.0, 2.5));
    assert_eq!(
        o.setup_error[&7].table,
        [('A', 10.0), ('B', 20.0), ('C', 30.0)]
    );
}

#[test]
fn unknown_keys() {
    let text = "[tool]\n1 = { length = 1 }\n";
    assert_error(
        &fail(text),
        text,
        "tool",
        Some("tool"),
        "unknown field `tool`",
    );
    let text = "[tools]\n1 = { lenght = 1 }\n";
    assert_error(
        &fail(text),
        text,
        "lenght",
        Some("lenght"),
        "unknown field `lenght`",
    );
    let text = "[setup_error.1]\nd = 1\n";
    assert_error(&fail(text), text, "d = 1", Some("d"), "unknown field `d`");
}

#[test]
fn tool_numbers_are_1_to_999() {
    for bad in ["0", "1000", "-1", "\"1 \"", "007"] {
        let text = format!("[tools]\n{bad} = {{ length = 1 }}\n");
        let key = bad.trim_matches('"');
        let e = fail(&text);
        assert_eq!(
            (e.line, e.column, e.key.as_deref()),
            (2, 1, Some(key)),
            "{bad}"
        );
        assert!(e.message.contains("not a tool offset number"), "{e:?}");
    }
}

#[test]
fn named_tools_take_the_numbers_after_the_numbered_ones_in_file_order() {
    let text = "[tools]\n\"FRA-D12\" = { length = 90, radius = 6 }\n3 = { length = 1 }\nT1 = { length = 2 }\n";
    let o = read(text);
    assert_eq!(o.tool_number("fra-d12"), Some(4));
    assert_eq!(o.tool_number("T1"), Some(5));
    assert_eq!(o.tool_number("T2"), None);
    assert_eq!(o.tool(4).length, 90.0);
    assert_eq!(o.tool(4).radius, 6.0);
    assert_eq!(o.tool(5).length, 2.0);
}

#[test]
fn tool_numbers_have_no_leading_zeros() {
    let text = "[tools]\n1 = { length = 1 }\n01 = { length = 2 }\n";
    assert_error(&fail(text), text, "01", Some("01"), "no leading zeros");
}

#[test]
fn first_bad_key_in_the_file_is_reported() {
    // Sorted as text, "1000" would come first.
    let text = "[tools]\n2000 = {}\n1000 = {}\n";
    assert_error(
        &fail(text),
        text,
        "2000",
        Some("2000"),
        "not a tool offset number",
    );
}

#[test]
fn tool_values_are_numbers() {
    let text = "[tools]\n3 = { length = \"long\" }\n";
    assert_error(
        &fail(text),
        text,
        "\"long\"",
        Some("length"),
        "invalid type",
    );
    let text = "[tools]\n3 = { radius = inf }\n";
    assert_error(&fail(text), text, "inf", Some("radius"), "finite");
}

#[test]
fn work_offset_names() {
    for bad in [
        "G53",
        "G60",
        "g54",
        "\"G54.1 P0\"",
        "\"G54.1 P49\"",
        "\"G54.1P1\"",
        "\"G54.1 P01\"",
        "\"G154 P0\"",
        "\"G154 P100\"",
        "\"G154 P07\"",
        "G109",
        "G130",
        "EXT1",
    ] {
        let text = format!("[work]\n{bad} = [0, 0, 0]\n");
        let e = fail(&text);
        let key = bad.trim_matches('"');
        assert_eq!(
            (e.line, e.column, e.key.as_deref()),
            (2, 1, Some(key)),
            "{bad}"
        );
        assert!(e.message.contains("not a work offset"), "{e:?}");
    }
}

#[test]
fn haas_work_offsets_g154_and_g110_share_the_extended_memory() {
    let text = "[work]\n\"G154 P7\" = [7, 0, 0]\nG110 = [1, 0, 0]\nG129 = [20, 0, 0]\n\"G154 P99\" = [99, 0, 0]\n\"G54.1 P48\" = [48, 0, 0]\n";
    let o = Offsets::from_toml(text).expect("Haas work offsets");
    assert_eq!(o.extended_work[6].x, 7.0);
    assert_eq!(o.extended_work[0].x, 1.0);
    assert_eq!(o.extended_work[19].x, 20.0);
    assert_eq!(o.extended_work[98].x, 99.0);
    assert_eq!(o.extended_work[47].x, 48.0);
    // G110 is G154 P1: one offset given twice.
    let e = fail("[work]\n\"G154 P1\" = [1, 0, 0]\nG110 = [2, 0, 0]\n");
    assert_eq!((e.line, e.key.as_deref()), (3, Some("G110")), "{e:?}");
    assert!(e.message.contains("given twice"), "{e:?}");
}

#[test]
fn work_offsets_are_three_numbers_or_one_per_axis() {
    let text = "[work]\nG54 = [1, 2]\n";
    assert_error(
        &fail(text),
        text,
        "[1, 2]",
        Some("G54"),
        "3 numbers (X, Y, Z) or one per machine axis (at most 8), found 2",
    );
    let text = "[work]\nG54 = [1, 2, 3, 4, 5, 6, 7, 8, 9]\n";
    assert_error(
        &fail(text),
        text,
        "[1, 2, 3, 4, 5, 6, 7, 8, 9]",
        Some("G54"),
        "found 9",
    );
    // X, Y, Z and then the axes beyond them in machine order.
    let o = Offsets::from_toml(
        "[work]\nG55 = [1, 2, 3, 4, 5]\nEXT = [0, 0, 0, 0, -1]\n\"G54.1 P2\" = [0, 0, 0, 7]\n",
    )
    .expect("read");
    assert_eq!(o.work[1], Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(o.work_beyond[1][..2], [4.0, 5.0]);
    assert_eq!(o.external_beyond[1], -1.0);
    assert_eq!(o.extended_work_beyond[1][0], 7.0);
    // The check against a machine's axes names the widest key.
    assert_eq!(o.check_axes(5), Ok(()));
    let e = o.check_axes(4).expect_err("five values on four axes");
    assert!(
        e.contains("`G55` gives 5 values: the machine has 4 axes"),
        "{e}"
    );
    let text = "[work]\nG55 = 5\n";
    assert_error(&fail(text), text, "= ^5", Some("G55"), "invalid type");
}

#[test]
fn setup_error_numbers_are_0_to_7() {
    let text = "[setup_error.8]\nx = 1\n";
    assert_error(
        &fail(text),
        text,
        "8",
        Some("8"),
        "not a setup error data set number (0 to 7",
    );
}

#[test]
fn setup_error_table_names_a_rotary_axis() {
    let text = "[setup_error.2]\ntable = { X = 1 }\n";
    assert_error(&fail(text), text, "X", Some("X"), "not a rotary axis name");
    let text = "[setup_error.2]\ntable = { B = \"x\" }\n";
    assert_error(&fail(text), text, "\"x\"", Some("B"), "invalid type");
}

#[test]
fn syntax_error_has_a_position() {
    let text = "[tools]\n1 = { length = 1 \n";
    let e = fail(text);
    assert_eq!((e.line, e.key.as_deref()), (2, None));
}
