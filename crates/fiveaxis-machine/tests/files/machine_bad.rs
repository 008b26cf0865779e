//! Machine files that must not read, and where their errors point.

use fiveaxis_machine::{FileError, MIN_ACCELERATION, MIN_JERK, MIN_VELOCITY, Machine};

use super::machine_good::{TABLE_C, file};
use super::{assert_error, pos};

fn fail(text: &str) -> FileError {
    match Machine::from_toml(text) {
        Ok(m) => panic!("read as {m:?}:\n{text}"),
        Err(e) => e,
    }
}

/// A file with one rotary axis whose body (after `name` and `on`) is `body`.
fn one_rotary(kind: &str, on: &str, body: &str) -> String {
    file(
        &format!("type = \"{kind}\"\n"),
        &format!("[[rotary]]\nname = \"A\"\non = \"{on}\"\n{body}"),
    )
}

#[test]
fn syntax_error() {
    let text = "name = \"m\"\ntype = none\n";
    let e = fail(text);
    assert_eq!((e.line, e.key.as_deref()), (2, None));
    assert_eq!(e.column, 8);
}

#[test]
fn unclosed_array() {
    let text = file("type = \"none\"\ntool_direction = [0, 0, 1\n", "");
    let e = fail(&text);
    // An array may run over lines: the parser gives up at the next table.
    assert_eq!((e.line, e.column, e.key.as_deref()), (5, 1, None));
    assert!(
        e.message.contains("missing comma between array elements"),
        "{e:?}"
    );
}

#[test]
fn duplicate_key() {
    let text = "name = \"m\"\ntype = \"none\"\nname = \"n\"\n";
    let e = fail(text);
    assert_eq!((e.line, e.column, e.key.as_deref()), (3, 1, Some("name")));
}

#[test]
fn unknown_top_level_key() {
    let text = file("type = \"none\"\nspindle = 1\n", "");
    assert_error(
        &fail(&text),
        &text,
        "spindle",
        Some("spindle"),
        "unknown field",
    );
}

#[test]
fn unknown_table() {
    let text = file("type = \"none\"\n", "[spindle]\nspeed = 1\n");
    assert_error(
        &fail(&text),
        &text,
        "spindle",
        Some("spindle"),
        "unknown field",
    );
}

#[test]
fn unknown_key_in_linear() {
    let text = file(
        "type = \"none\"\n",
        "[[linear]]\nname = \"U\"\nmin = 0\nmax = 1\nhome = 0\n",
    );
    assert_error(
        &fail(&text),
        &text,
        "home",
        Some("home"),
        "unknown field `home`",
    );
}

#[test]
fn unknown_key_in_rotary() {
    let text = one_rotary(
        "table",
        "table",
        "axis = [1, 0, 0]\ncenter = [0, 0, 0]\nspeed = 10\n",
    );
    assert_error(
        &fail(&text),
        &text,
        "speed",
        Some("speed"),
        "unknown field `speed`",
    );
}

#[test]
fn unknown_key_in_parameters() {
    let text = file("type = \"none\"\n", "[parameters]\nwkp = 1\n");
    assert_error(
        &fail(&text),
        &text,
        "wkp",
        Some("wkp"),
        "unknown field `wkp`",
    );
}

#[test]
fn missing_name_points_at_the_file() {
    let text = "type = \"none\"\n";
    let e = fail(text);
    assert_eq!((e.line, e.column, e.key.as_deref()), (1, 1, Some("name")));
    assert!(e.message.contains("missing field `name`"));
}

#[test]
fn missing_type() {
    let e = fail(&file("", ""));
    assert_eq!((e.line, e.column, e.key.as_deref()), (1, 1, Some("type")));
}

#[test]
fn missing_linear_axes() {
    let e = fail("name = \"m\"\ntype = \"none\"\n");
    assert_eq!(e.key.as_deref(), Some("linear"));
    assert!(e.message.contains("missing field `linear`"));
}

#[test]
fn missing_limit_points_at_its_table() {
    let text = file(
        "type = \"none\"\n",
        "[[linear]] # U\nname = \"U\"\nmin = 0\n",
    );
    assert_error(
        &fail(&text),
        &text,
        "[[linear]] # U",
        Some("max"),
        "missing field `max`",
    );
}

#[test]
fn missing_rotary_axis_and_side() {
    let text = one_rotary("table", "table", "center = [0, 0, 0]\n");
    assert_error(
        &fail(&text),
        &text,
        "[[rotary]]",
        Some("axis"),
        "missing field `axis`",
    );
    let text = file(
        "type = \"table\"\n",
        "[[rotary]]\nname = \"A\"\naxis = [1, 0, 0]\ncenter = [0, 0, 0]\n",
    );
    assert_error(
        &fail(&text),
        &text,
        "[[rotary]]",
        Some("on"),
        "missing field `on`",
    );
}

#[test]
fn wrong_types_point_at_the_value() {
    let text = file(
        "type = \"none\"\n",
        "[[linear]]\nname = \"U\"\nmin = \"low\"\nmax = 1\n",
    );
    assert_error(&fail(&text), &text, "\"low\"", Some("min"), "invalid type");
    let text = file("type = \"none\"\ntool_direction = 1\n", "");
    assert_error(
        &fail(&text),
        &text,
        "tool_direction = ^1",
        Some("tool_direction"),
        "invalid type",
    );
    let text = file("type = \"none\"\ntool_direction = [0, \"z\", 1]\n", "");
    assert_error(
        &fail(&text),
        &text,
        "\"z\"",
        Some("tool_direction"),
        "invalid type",
    );
    let text = file("type = \"none\"\n", "[parameters]\ntcpc_option = 1\n");
    assert_error(
        &fail(&text),
        &text,
        "tcpc_option = ^1",
        Some("tcpc_option"),
        "invalid type",
    );
    let text = file(
        "type = \"none\"\n",
        "[parameters]\nreference_1 = { X = true }\n",
    );
    assert_error(&fail(&text), &text, "true", Some("X"), "invalid type");
    let text = file("name = 7\n", "");
    let e = fail(&text);
    // `name` is given twice here: the duplicate is found first.
    assert_eq!((e.line, e.key.as_deref()), (2, Some("name")));
}

#[test]
fn unknown_words() {
    let text = file("type = \"diagonal\"\n", "");
    assert_error(
        &fail(&text),
        &text,
        "\"diagonal\"",
        Some("type"),
        "unknown variant `diagonal`",
    );
    let text = file("type = \"none\"\ncontrol = \"fagor\"\n", "");
    assert_error(
        &fail(&text),
        &text,
        "\"fagor\"",
        Some("control"),
        "unknown variant",
    );
    let text = one_rotary("table", "bed", "axis = [1, 0, 0]\ncenter = [0, 0, 0]\n");
    assert_error(
        &fail(&text),
        &text,
        "\"bed\"",
        Some("on"),
        "unknown variant",
    );
    let text = file(
        "type = \"none\"\n",
        "[parameters]\nprogramming_frame = \"part\"\n",
    );
    assert_error(
        &fail(&text),
        &text,
        "\"part\"",
        Some("programming_frame"),
        "unknown variant",
    );
}

#[test]
fn type_must_match_the_rotary_axes() {
    let head = "[[rotary]]\nname = \"B\"\non = \"head\"\naxis = [0, 1, 0]\ncenter = [0, 0, 0]\n";
    let cases = [
        ("head", String::new()),
        ("none", TABLE_C.to_owned()),
        ("head", TABLE_C.to_owned()),
        ("table", head.to_owned()),
        ("mixed", TABLE_C.to_owned()),
        ("mixed", head.to_owned()),
        ("table", format!("{head}{TABLE_C}")),
        ("head", format!("{head}{TABLE_C}")),
    ];
    for (word, rotary) in cases {
        let text = file(&format!("type = \"{word}\"\n"), &rotary);
        let needle = format!("type = ^\"{word}\"");
        assert_error(
            &fail(&text),
            &text,
            &needle,
            Some("type"),
            "does not match the rotary axes",
        );
    }
}

#[test]
fn linear_axes_start_x_y_z() {
    let text = "name = \"m\"\ntype = \"none\"\n[[linear]]\nname = \"Y\"\nmin = 0\nmax = 1\n";
    assert_error(&fail(text), text, "\"Y\"", Some("name"), "must be X");
    let text = "name = \"m\"\ntype = \"none\"\n[[linear]]\nname = \"X\"\nmin = 0\nmax = 1\n[[linear]]\nname = \"Z\"\nmin = 0\nmax = 1\n";
    assert_error(&fail(text), text, "\"Z\"", Some("name"), "must be Y");
    let text = "name = \"m\"\ntype = \"none\"\n[[linear]]\nname = \"x\"\nmin = 0\nmax = 1\n";
    assert_error(&fail(text), text, "\"x\"", Some("name"), "must be X");
}

#[test]
fn linear_axes_need_z() {
    let text = "name = \"m\"\ntype = \"none\"\n[[linear]]\nname = \"X\"\nmin = 0\nmax = 1\n[[linear]] # Y\nname = \"Y\"\nmin = 0\nmax = 1\n";
    assert_error(
        &fail(text),
        text,
        "[[linear]] # Y",
        Some("linear"),
        "Z is missing",
    );
    let text = "name = \"m\"\ntype = \"none\"\nlinear = []\n";
    assert_error(&fail(text), text, "[]", Some("linear"), "X is missing");
}

#[test]
fn parallel_axes_are_u_v_w_once() {
    let text = file(
        "type = \"none\"\n",
        "[[linear]]\nname = \"Q\"\nmin = 0\nmax = 1\n",
    );
    assert_error(&fail(&text), &text, "\"Q\"", Some("name"), "U, V or W");
    let text = file(
        "type = \"none\"\n",
        "[[linear]]\nname = \"X\"\nmin = 0\nmax = 1\n",
    );
    assert_error(
        &fail(&text),
        &text,
        "^\"X\"\nmin = 0",
        Some("name"),
        "U, V or W",
    );
    let text = file(
        "type = \"none\"\n",
        "[[linear]]\nname = \"V\"\nmin = 0\nmax = 1\n[[linear]]\nname = \"V\"\nmin = 0\nmax = 2\n",
    );
    assert_error(
        &fail(&text),
        &text,
        "^\"V\"\nmin = 0\nmax = 2",
        Some("name"),
        "given twice",
    );
}

#[test]
fn linear_min_below_max() {
    let text = file(
        "type = \"none\"\n",
        "[[linear]]\nname = \"U\"\nmin = 5\nmax = 5\n",
    );
    assert_error(
        &fail(&text),
        &text,
        "max = ^5",
        Some("max"),
        "greater than `min`",
    );
    let text = file(
        "type = \"none\"\n",
        "[[linear]]\nname = \"U\"\nmin = 5\nmax = -5\n",
    );
    assert_error(
        &fail(&text),
        &text,
        "max = ^-5",
        Some("max"),
        "greater than `min`",
    );
}

#[test]
fn numbers_are_finite() {
    let text = file(
        "type = \"none\"\n",
        "[[linear]]\nname = \"U\"\nmin = nan\nmax = 5\n",
    );
    assert_error(&fail(&text), &text, "nan", Some("min"), "finite");
    let text = file("type = \"none\"\ntool_direction = [0, 0, inf]\n", "");
    assert_error(
        &fail(&text),
        &text,
        "[0, 0, inf]",
        Some("tool_direction"),
        "finite",
    );
}

#[test]
fn rotary_names() {
    let text = file(
        "type = \"table\"\n",
        "[[rotary]]\nname = \"D\"\non = \"table\"\naxis = [1, 0, 0]\ncenter = [0, 0, 0]\n",
    );
    assert_error(&fail(&text), &text, "\"D\"", Some("name"), "A, B or C");
    let text = file(
        "type = \"table\"\n",
        &format!(
            "{TABLE_C}[[rotary]]\nname = \"C\"\non = \"table\"\naxis = [1, 0, 0]\ncenter = [0, 0, 0]\n"
        ),
    );
    assert_error(
        &fail(&text),
        &text,
        "^\"C\"\non = \"table\"\naxis = [1",
        Some("name"),
        "given twice",
    );
}

#[test]
fn at_most_three_rotary_axes() {
    let a = "[[rotary]]\nname = \"A\"\non = \"table\"\naxis = [1, 0, 0]\ncenter = [0, 0, 0]\n";
    let b = "[[rotary]]\nname = \"B\"\non = \"table\"\naxis = [0, 1, 0.5]\ncenter = [0, 0, 0]\n";
    let fourth =
        "[[rotary]] # fourth\nname = \"A\"\non = \"table\"\naxis = [0, 1, 0]\ncenter = [0, 0, 0]\n";
    // Three are a machine (a table axis and a nutating pair).
    let three = file("type = \"table\"\n", &format!("{a}{TABLE_C}{b}"));
    assert!(
        fiveaxis_machine::Machine::from_toml(&three).is_ok(),
        "{three}"
    );
    let text = file("type = \"table\"\n", &format!("{a}{TABLE_C}{b}{fourth}"));
    assert_error(
        &fail(&text),
        &text,
        "[[rotary]] # fourth",
        Some("rotary"),
        "at most 3 rotary axes",
    );
}

#[test]
fn only_one_u_v_or_w_moves_along_the_tool() {
    let x_along = "[[linear]]\nname = \"X\"\nmin = -1\nmax = 1\nalong = \"tool\"\n";
    let text = format!(
        "name = \"m\"\ntype = \"none\"\n{x_along}[[linear]]\nname = \"Y\"\nmin = -1\nmax = 1\n[[linear]]\nname = \"Z\"\nmin = -1\nmax = 1\n"
    );
    assert_error(
        &fail(&text),
        &text,
        "along = ^\"tool\"",
        Some("along"),
        "only U, V or W",
    );
    let xyz = "[[linear]]\nname = \"X\"\nmin = -1\nmax = 1\n[[linear]]\nname = \"Y\"\nmin = -1\nmax = 1\n[[linear]]\nname = \"Z\"\nmin = -1\nmax = 1\n";
    let w = "[[linear]]\nname = \"W\"\nmin = -1\nmax = 1\nalong = \"tool\"\n";
    let v = "[[linear]]\nname = \"V\"\nmin = -1\nmax = 1\nalong = \"tool\"\n";
    let text = format!("name = \"m\"\ntype = \"none\"\n{xyz}{w}{v}");
    assert_error(
        &fail(&text),
        &text,
        "name = \"V\"\nmin = -1\nmax = 1\nalong = ^\"tool\"",
        Some("along"),
        "one quill at most",
    );
    let text = format!("name = \"m\"\ntype = \"none\"\n{xyz}{w}");
    let m = fiveaxis_machine::Machine::from_toml(&text).expect("a quill W");
    assert_eq!(m.quill_index(), Some(3));
    assert_eq!(fiveaxis_machine::Machine::from_toml(&m.to_toml()), Ok(m));
}

#[test]
fn vectors_have_three_non_zero_numbers() {
    let text = one_rotary("table", "table", "axis = [0, 0, 0]\ncenter = [0, 0, 0]\n");
    assert_error(
        &fail(&text),
        &text,
        "axis = ^[0, 0, 0]",
        Some("axis"),
        "non-zero",
    );
    let text = one_rotary("table", "table", "axis = [1, 0]\ncenter = [0, 0, 0]\n");
    assert_error(
        &fail(&text),
        &text,
        "[1, 0]",
        Some("axis"),
        "3 numbers, found 2",
    );
    let text = one_rotary(
        "table",
        "table",
        "axis = [1, 0, 0]\ncenter = [0, 0, 0, 0]\n",
    );
    assert_error(
        &fail(&text),
        &text,
        "[0, 0, 0, 0]",
        Some("center"),
        "3 numbers, found 4",
    );
    let text = file("type = \"none\"\ntool_direction = [0.0, 0.0, 0.0]\n", "");
    assert_error(
        &fail(&text),
        &text,
        "[0.0, 0.0, 0.0]",
        Some("tool_direction"),
        "non-zero",
    );
}

#[test]
fn rollover_axes_have_no_limits() {
    let body = "axis = [1, 0, 0]\ncenter = [0, 0, 0]\nrollover = true\nmin = -10\nmax = 10\n";
    let text = one_rotary("table", "table", body);
    assert_error(&fail(&text), &text, "min = ^-10\n", Some("min"), "rollover");
    let body = "axis = [1, 0, 0]\ncenter = [0, 0, 0]\nmax = 10\nrollover = true\n";
    let text = one_rotary("table", "table", body);
    assert_error(&fail(&text), &text, "max = ^10\n", Some("max"), "rollover");
}

#[test]
fn rotary_limits_come_in_pairs() {
    let text = one_rotary(
        "table",
        "table",
        "axis = [1, 0, 0]\ncenter = [0, 0, 0]\nmin = -10\n",
    );
    assert_error(
        &fail(&text),
        &text,
        "[[rotary]]",
        Some("max"),
        "missing field `max`",
    );
    let text = one_rotary(
        "table",
        "table",
        "axis = [1, 0, 0]\ncenter = [0, 0, 0]\nmax = 10\n",
    );
    assert_error(
        &fail(&text),
        &text,
        "[[rotary]]",
        Some("min"),
        "missing field `min`",
    );
    let text = one_rotary(
        "table",
        "table",
        "axis = [1, 0, 0]\ncenter = [0, 0, 0]\nmin = 10\nmax = -10\n",
    );
    assert_error(
        &fail(&text),
        &text,
        "max = ^-10",
        Some("max"),
        "greater than `min`",
    );
}

#[test]
fn reference_names_a_machine_axis() {
    let text = file(
        "type = \"table\"\n",
        &format!("{TABLE_C}[parameters]\nreference_1 = {{ X = 1, A = 2 }}\n"),
    );
    assert_error(
        &fail(&text),
        &text,
        "^A = 2",
        Some("A"),
        "no axis named `A`",
    );
    let text = file(
        "type = \"none\"\n",
        "[parameters]\nreference_2 = { Q = 2 }\n",
    );
    assert_error(&fail(&text), &text, "Q = 2", Some("Q"), "no axis named `Q`");
    let text = file(
        "type = \"none\"\n",
        "[parameters]\nreference_2 = { U = 2 }\n",
    );
    assert_error(&fail(&text), &text, "U = 2", Some("U"), "no axis named `U`");
}

#[test]
fn least_input_increment_is_positive_and_sane() {
    for bad in ["0", "-0.001", "0.0", "1e-300", "2.0"] {
        let text = file(
            "type = \"none\"\n",
            &format!("[parameters]\nleast_input_increment = {bad}\n"),
        );
        assert_error(
            &fail(&text),
            &text,
            &format!("increment = ^{bad}"),
            Some("least_input_increment"),
            "must be between",
        );
    }
}

#[test]
fn error_display_names_the_position() {
    let text = file("type = \"none\"\nspindle = 1\n", "");
    let shown = fail(&text).to_string();
    assert!(
        shown.starts_with("line 3, column 1: unknown field `spindle`"),
        "{shown}"
    );
}

/// A table-C machine with `[m_codes]` holding `table`.
fn with_m_codes(table: &str) -> String {
    file(
        "type = \"table\"\n",
        &format!("{TABLE_C}\n[m_codes]\n{table}"),
    )
}

#[test]
fn m_code_with_an_unknown_function() {
    let text = with_m_codes("10 = \"clamp C\"\n50 = \"coolant_flood\"\n");
    assert_error(
        &fail(&text),
        &text,
        "\"coolant_flood\"",
        Some("50"),
        "unknown M function `coolant_flood` for M50",
    );
}

#[test]
fn m_code_clamping_an_axis_the_machine_lacks() {
    let text = with_m_codes("10 = \"clamp A\"\n");
    assert_error(
        &fail(&text),
        &text,
        "\"clamp A\"",
        Some("10"),
        "no rotary axis named A",
    );
    // A linear axis is not a rotary axis either.
    let text = with_m_codes("10 = \"unclamp X\"\n");
    assert_error(&fail(&text), &text, "\"unclamp X\"", Some("10"), "named X");
}

#[test]
fn m_code_key_that_is_not_a_number() {
    for key in ["M10", "\"10.5\"", "-1", "10000", "\"\""] {
        let text = with_m_codes(&format!("{key} = \"signal\"\n"));
        let e = fail(&text);
        assert_eq!(e.line, pos(&text, &format!("{key} =")).0, "{key}: {e:?}");
        assert!(
            e.message.contains("not an M number") || e.message.contains("keys of"),
            "{key}: {e:?}"
        );
    }
}

#[test]
fn m98_and_m99_stay_the_controls() {
    let text = with_m_codes("99 = \"end\"\n");
    assert_error(
        &fail(&text),
        &text,
        "99 =",
        Some("99"),
        "subprogram call or return",
    );
}

#[test]
fn m_code_declared_twice() {
    let text = with_m_codes("10 = \"signal\"\n010 = \"stop\"\n");
    assert_error(&fail(&text), &text, "010", Some("010"), "declared twice");
}

#[test]
fn m_code_value_of_the_wrong_type() {
    let text = with_m_codes("10 = 3\n");
    let e = fail(&text);
    assert_eq!(
        (e.line, e.key.as_deref()),
        (pos(&text, "10 = 3").0, Some("10"))
    );
}

#[test]
fn dynamics_must_be_positive_and_bounded() {
    for (key, value, says) in [
        ("max_velocity", "0.0", "greater than 0"),
        ("rapid", "-1.0", "greater than 0"),
        ("max_acceleration", "2e6", "beyond what a machine can have"),
        ("max_jerk", "0.0", "greater than 0"),
        ("max_jerk", "1e12", "at most"),
        ("max_velocity", "nan", "finite"),
    ] {
        let text = file("type = \"table\"\n", &format!("{TABLE_C}{key} = {value}\n"));
        assert_error(
            &fail(&text),
            &text,
            &format!("{key} = ^{value}"),
            Some(key),
            says,
        );
    }
}

/// Dynamics below the floors (`MIN_VELOCITY`, `MIN_ACCELERATION`,
/// `MIN_JERK`) are refused where they are written; the floors themselves
/// read.
#[test]
fn dynamics_have_a_floor() {
    for (key, floor) in [
        ("max_velocity", MIN_VELOCITY),
        ("rapid", MIN_VELOCITY),
        ("max_acceleration", MIN_ACCELERATION),
        ("max_jerk", MIN_JERK),
    ] {
        for value in ["1e-300".to_owned(), format!("{:e}", floor * 0.999)] {
            let text = file("type = \"table\"\n", &format!("{TABLE_C}{key} = {value}\n"));
            assert_error(
                &fail(&text),
                &text,
                &format!("{key} = ^{value}"),
                Some(key),
                "below what a machine can have",
            );
        }
        let text = file(
            "type = \"table\"\n",
            &format!("{TABLE_C}{key} = {floor:e}\n"),
        );
        if let Err(e) = Machine::from_toml(&text) {
            panic!("{key} = {floor:e} should read: {e:?}");
        }
    }
}

#[test]
fn dynamics_keys_are_known_by_name() {
    let text = file("type = \"table\"\n", &format!("{TABLE_C}max_speed = 1.0\n"));
    assert_error(
        &fail(&text),
        &text,
        "max_speed",
        Some("max_speed"),
        "unknown field",
    );
}

#[test]
fn check_parameters_are_bounded() {
    for (key, value, says) in [
        ("singular_cone", "90.0", "below 90"),
        ("singular_cone", "-1.0", "at least 0"),
        ("flip_angle", "0.0", "greater than 0"),
        ("chord_tolerance", "-0.01", "greater than 0"),
    ] {
        let text = file(
            "type = \"none\"\n",
            &format!("[parameters]\n{key} = {value}\n"),
        );
        assert_error(
            &fail(&text),
            &text,
            &format!("{key} = ^{value}"),
            Some(key),
            says,
        );
    }
}
