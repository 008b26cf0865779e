//! `fiveaxis check` through the binary: the contract's JSON keys, exit
//! statuses, program order, and golden reports of the examples.

mod common;

use std::path::Path;
use std::process::Output;

use serde_json::Value;

use common::scratch;

fn run(dir: &Path, args: &[&str]) -> Output {
    common::run_in(dir, args, b"")
}

fn json_lines(output: &Output) -> Vec<Value> {
    String::from_utf8_lossy(&output.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("one JSON object per line"))
        .collect()
}

/// Clean: a short 3-axis move inside the limits.
const CLEAN: &str = "G21 G90 G94\nG0 X10. Y5.\nG1 Z-1. F600.\nM30\n";
/// X beyond +500 from line 2 to line 4 (which starts beyond it), inside
/// on line 5, beyond again on line 6.
const OVER: &str = "G21 G90\nG0 X510.\nG1 X520. F1000.\nG0 X0\nG0 X100.\nG0 X505.\nM30\n";
/// A feed C cannot follow (warning only).
const FEED: &str = "G21 G90 G94\nG0 X100. Y0 Z0 A0 C0\nG1 C20. F20000.\nM30\n";
/// An alarm: an address the machine lacks.
const ALARM: &str = "G21\nG0 X1.\nG1 Q5.\nM30\n";

#[test]
fn json_has_the_contract_keys_in_program_order() {
    let dir = scratch(&[("clean.nc", CLEAN), ("over.nc", OVER), ("alarm.nc", ALARM)]);
    let out = run(
        dir.path(),
        &[
            "check", "over.nc", "clean.nc", "alarm.nc", "--format", "json",
        ],
    );
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let objects = json_lines(&out);
    let programs: Vec<&str> = objects
        .iter()
        .map(|o| o["program"].as_str().unwrap_or(""))
        .collect();
    assert_eq!(programs, ["over.nc", "clean.nc", "alarm.nc"]);
    for o in &objects {
        for key in [
            "program", "machine", "ended", "alarm", "blocks", "time", "axes", "findings",
        ] {
            assert!(o.get(key).is_some(), "{key} missing in {o}");
        }
        assert!(o["time"]["programmed"].is_number() && o["time"]["estimated"].is_number());
        assert!(o["time"]["estimated"].as_f64() >= o["time"]["programmed"].as_f64());
        for axis in ["X", "Y", "Z", "A", "C"] {
            let a = &o["axes"][axis];
            for key in ["min", "max", "limit_min", "limit_max"] {
                assert!(a.get(key).is_some(), "{axis}.{key} missing in {o}");
            }
        }
        // C of the default machine rolls over: no limits.
        assert!(o["axes"]["C"]["limit_min"].is_null());
        for f in o["findings"].as_array().expect("list") {
            for key in ["severity", "kind", "line", "message"] {
                assert!(f.get(key).is_some(), "{key} missing in {f}");
            }
        }
    }
    // Two runs beyond X+500: lines 2-4 (farthest 520) and line 6 (505).
    let over: Vec<(u64, f64)> = objects[0]["findings"]
        .as_array()
        .expect("list")
        .iter()
        .map(|f| {
            assert_eq!(f["kind"], "overtravel");
            assert_eq!(f["severity"], "error");
            assert_eq!(f["axis"], "X");
            (
                f["line"].as_u64().unwrap_or(0),
                f["value"].as_f64().unwrap_or(0.0),
            )
        })
        .collect();
    assert_eq!(over, [(2, 520.0), (6, 505.0)]);
    assert_eq!(objects[0]["ended"], true);
    assert_eq!(objects[0]["axes"]["X"]["max"], 520.0);
    assert_eq!(objects[1]["findings"].as_array().map(Vec::len), Some(0));
    assert_eq!(objects[1]["alarm"], Value::Null);
    assert_eq!(objects[1]["blocks"], 4);
    assert_eq!(objects[2]["ended"], false);
    assert_eq!(objects[2]["alarm"]["line"], 3);
    assert_eq!(objects[2]["findings"][0]["kind"], "alarm");
}

#[test]
fn exit_status_follows_fail_on() {
    let dir = scratch(&[("clean.nc", CLEAN), ("feed.nc", FEED), ("over.nc", OVER)]);
    let status = |args: &[&str]| run(dir.path(), args).status.code();
    assert_eq!(status(&["check", "clean.nc"]), Some(0));
    assert_eq!(status(&["check", "feed.nc"]), Some(0));
    assert_eq!(
        status(&["check", "feed.nc", "--fail-on", "warning"]),
        Some(1)
    );
    assert_eq!(status(&["check", "over.nc"]), Some(1));
    assert_eq!(status(&["check", "over.nc", "--fail-on", "never"]), Some(0));
    assert_eq!(status(&["check", "clean.nc", "missing.nc"]), Some(2));
    assert_eq!(
        status(&["check", "clean.nc", "--machine", "no-such-machine"]),
        Some(2)
    );
}

#[test]
fn golden_text_and_json_reports_of_the_examples() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    for (program, machine) in [
        ("examples/bracket.nc", "trunnion-ac"),
        ("examples/tcpc-vector.nc", "head-table-bc"),
        ("examples/tilted-holes.nc", "trunnion-ac"),
    ] {
        let args = [
            "check",
            program,
            "--machine",
            machine,
            "--offsets",
            "examples/offsets.toml",
        ];
        let text = run(&root, &args);
        let mut json_args = args.to_vec();
        json_args.extend(["--format", "json"]);
        let json = run(&root, &json_args);
        let name = program.trim_start_matches("examples/").replace('.', "_");
        insta::assert_snapshot!(
            format!("check_{name}"),
            format!(
                "{}\n{}",
                String::from_utf8_lossy(&text.stdout),
                String::from_utf8_lossy(&json.stdout)
            )
        );
    }
}

/// A program that writes lengths without a decimal point: `X10` is
/// 0.010 mm on the FANUC built-ins (decimal point input off). Line 3
/// has two (X10, Z-5), line 4 one (Y25; X0 is 0 in any unit), line 5 the
/// arc's three (X20, Y25, R15; F and the G, M words are not counted).
const NO_POINT: &str =
    "G21 G90 G94 G17\nG0 X5. Y5. Z5.\nG1 X10 Z-5 F100\nG1 X0 Y25\nG2 X20 Y25 R15\nM30\n";

#[test]
fn axis_words_without_a_decimal_point_are_reported_once_as_info() {
    let dir = scratch(&[("p.nc", NO_POINT), ("clean.nc", CLEAN)]);
    let out = run(dir.path(), &["check", "p.nc", "--format", "json"]);
    // Info only: the status stays 0, also with --fail-on warning.
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let objects = json_lines(&out);
    let findings: Vec<&Value> = objects[0]["findings"]
        .as_array()
        .expect("list")
        .iter()
        .filter(|f| f["kind"] == "no_decimal_point")
        .collect();
    assert_eq!(findings.len(), 1, "{}", objects[0]);
    let f = findings[0];
    assert_eq!(f["severity"], "info");
    assert_eq!(f["line"], 3);
    assert_eq!(f["value"], 6.0);
    assert_eq!(
        f["message"],
        "6 axis words without a decimal point are read in least input increments (X10 = 0.010 mm): first on line 3"
    );
    let status = run(dir.path(), &["check", "p.nc", "--fail-on", "warning"]);
    assert_eq!(status.status.code(), Some(0));
    // The text report lists it with its line.
    let text = String::from_utf8_lossy(&status.stdout).into_owned();
    assert!(text.contains("no_decimal_point (info, 1)"), "{text}");
    assert!(text.contains("first on line 3"), "{text}");
    // A program with points everywhere has none.
    let out = run(dir.path(), &["check", "clean.nc", "--format", "json"]);
    assert_eq!(
        json_lines(&out)[0]["findings"].as_array().map(Vec::len),
        Some(0)
    );
}

#[test]
fn words_without_a_point_count_nothing_where_they_are_whole_units() {
    let dir = scratch(&[("p.nc", NO_POINT)]);
    let machine = run(dir.path(), &["machines", "show", "trunnion-ac"]);
    let text = String::from_utf8_lossy(&machine.stdout)
        .replace("decimal_point_input = false", "decimal_point_input = true");
    std::fs::write(dir.path().join("dpi.toml"), text).expect("written");
    let out = run(
        dir.path(),
        &["check", "p.nc", "--machine", "dpi.toml", "--format", "json"],
    );
    let objects = json_lines(&out);
    let kinds: Vec<&Value> = objects[0]["findings"]
        .as_array()
        .expect("list")
        .iter()
        .map(|f| &f["kind"])
        .collect();
    assert!(
        !kinds.contains(&&Value::from("no_decimal_point")),
        "{}",
        objects[0]
    );
}

#[test]
fn a_g93_feed_limit_names_the_inverse_time_f_and_the_tip_feed() {
    let dir = scratch(&[(
        "g93.nc",
        "G21 G90 G94\nG0 X100. Y0 Z0 A0 C0\nG93 G1 C90. F200.\nG94\nM30\n",
    )]);
    let out = run(dir.path(), &["check", "g93.nc", "--format", "json"]);
    let objects = json_lines(&out);
    let f = &objects[0]["findings"][0];
    assert_eq!(f["kind"], "feed_limited", "{}", objects[0]);
    let message = f["message"].as_str().unwrap_or("");
    assert!(
        message.starts_with("the inverse-time F200 works out to a tip feed of 28284.271 mm/min, which needs C faster than its"),
        "{message}"
    );
}

/// A program with more findings than `check` holds in memory (their JSON
/// goes to a temporary file past 1 MiB): every one is in the report, in
/// program order, the whole-program finding in its place, and the text
/// report lists the first ones of each kind with their source lines and
/// counts the rest.
#[test]
fn findings_beyond_what_check_holds_are_all_reported_in_order() {
    // 12,000 flips of A (100° in one cutting block) on the default
    // trunnion: a rotary_flip warning each (with a chord error), about
    // 150 bytes of JSON each.
    let mut program = String::from("G21 G90 G94 F20000.\nG0 X0. Y0. Z100.\n");
    for k in 0..12_000 {
        program.push_str(if k % 2 == 0 {
            "G1 A-100.\n"
        } else {
            "G1 A0.\n"
        });
        if k == 6_000 {
            // An axis word without a decimal point: the whole-program
            // finding goes before the first finding of a later line.
            program.push_str("G0 X10\n");
        }
    }
    program.push_str("M30\n");
    let dir = scratch(&[("flips.nc", &program)]);
    let out = run(
        dir.path(),
        &[
            "check",
            "flips.nc",
            "--format",
            "json",
            "--fail-on",
            "never",
        ],
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stdout.len() > 1 << 21, "{} bytes", out.stdout.len());
    let objects = json_lines(&out);
    let findings = objects[0]["findings"].as_array().expect("list");
    let flips = findings
        .iter()
        .filter(|f| f["kind"] == "rotary_flip")
        .count();
    assert_eq!(flips, 12_000);
    let lines: Vec<u64> = findings
        .iter()
        .map(|f| f["line"].as_u64().unwrap_or(0))
        .collect();
    assert!(lines.windows(2).all(|w| w[0] <= w[1]), "program order");
    let at = findings
        .iter()
        .position(|f| f["kind"] == "no_decimal_point")
        .expect("the whole-program finding");
    assert_eq!(findings[at]["line"], 6_004);
    assert_eq!(findings[at + 1]["line"], 6_005);
    assert_eq!(findings[at - 1]["line"], 6_003);

    let out = run(dir.path(), &["check", "flips.nc", "--fail-on", "never"]);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(text.contains("rotary_flip (warning, 12000)"), "{text}");
    assert!(
        text.contains("… and 11992 more (the JSON report lists every one)"),
        "{text}"
    );
    assert!(text.contains("     3 | G1 A-100."), "{text}");
    assert!(text.contains("  6004 | G0 X10"), "{text}");
}

/// Issue 24, item 9: one over-travel finding per excursion. Against the
/// A limit of +30 of trunnion-ac, A leaves on line 4, is back inside at the
/// end of line 6 and leaves again on line 7: two excursions.
#[test]
fn every_excursion_is_a_finding() {
    let program =
        "G21 G90 G94\nG0 X0 Y0 Z100.\nG1 A0 F1000.\nG1 A45.\nG1 A50.\nG1 A0.\nG1 A40.\nM30\n";
    let dir = scratch(&[("p.nc", program)]);
    let out = run(dir.path(), &["check", "p.nc", "--format", "json"]);
    let objects = json_lines(&out);
    let over: Vec<(u64, f64)> = objects[0]["findings"]
        .as_array()
        .expect("list")
        .iter()
        .filter(|f| f["kind"] == "overtravel")
        .map(|f| {
            (
                f["line"].as_u64().unwrap_or(0),
                f["value"].as_f64().unwrap_or(0.0),
            )
        })
        .collect();
    assert_eq!(over, [(4, 50.0), (7, 40.0)], "{}", objects[0]);
}

/// Singular passages only where the control chooses the rotary axes: a
/// programmed `G1 A45.` through the singular direction (A0, C free) is
/// not one; the same turn under TCPC with tool vectors is.
#[test]
fn a_programmed_rotary_move_is_not_a_singular_passage() {
    let programmed = "G21 G90 G94\nG0 X0 Y0 Z100. A-45.\nG1 A45. F1000.\nM30\n";
    // From the vertical (the singular direction) out to 30°: the control
    // chooses A and C there; then to 30° the other way, which it does by
    // turning C half a turn at A -30°, far from the vertical.
    let chosen = "G21 G90 G94\nG43.5 H1 X0 Y0 Z50.\nG1 I0 J-0.5 K0.8660254 F1000.\nG1 I0 J0.5 K0.8660254\nG49\nM30\n";
    let offsets = "[tools]\n1 = { length = 100.0 }\n";
    let dir = scratch(&[("a.nc", programmed), ("b.nc", chosen), ("o.toml", offsets)]);
    let out = run(
        dir.path(),
        &[
            "check",
            "a.nc",
            "b.nc",
            "--offsets",
            "o.toml",
            "--format",
            "json",
            "--fail-on",
            "never",
        ],
    );
    let objects = json_lines(&out);
    let passages = |o: &Value| {
        o["findings"]
            .as_array()
            .expect("list")
            .iter()
            .filter(|f| f["kind"] == "singular_passage")
            .map(|f| f["line"].as_u64().unwrap_or(0))
            .collect::<Vec<_>>()
    };
    assert_eq!(passages(&objects[0]), Vec::<u64>::new(), "{}", objects[0]);
    assert_eq!(passages(&objects[1]), [3], "{}", objects[1]);
}

/// `--keep-going`: alarms after which the control's state is defined are
/// findings and the check goes on; an alarm of the program's flow ends it.
#[test]
fn keep_going_reports_every_alarm_it_can_go_on_after() {
    let program =
        "G21 G90 G94\nG0 X0 Y0 Z100.\nM123\nG1 X10.\nG1 X20. F500.\nG1 Q5.\nG0 A50.\nM30\n";
    let flow = "G21 G90\nG0 X1.\nM123\nGOTO 99\nG0 X2.\nM30\n";
    let dir = scratch(&[("p.nc", program), ("flow.nc", flow)]);
    // Without it the check stops at the first alarm.
    let out = run(dir.path(), &["check", "p.nc", "--format", "json"]);
    let o = &json_lines(&out)[0];
    assert_eq!(
        (o["alarm"]["line"].as_u64(), o["ended"].as_bool()),
        (Some(3), Some(false))
    );
    let out = run(
        dir.path(),
        &["check", "p.nc", "--keep-going", "--format", "json"],
    );
    assert_eq!(out.status.code(), Some(1));
    let o = &json_lines(&out)[0];
    let kinds: Vec<(u64, String)> = o["findings"]
        .as_array()
        .expect("list")
        .iter()
        .map(|f| {
            (
                f["line"].as_u64().unwrap_or(0),
                f["kind"].as_str().unwrap_or("").to_owned(),
            )
        })
        .collect();
    let alarm = |l: u64| (l, "alarm".to_owned());
    assert_eq!(
        kinds,
        [alarm(3), alarm(4), alarm(6), (7, "overtravel".to_owned())],
        "{o}"
    );
    assert!(
        o["findings"][0]["message"]
            .as_str()
            .unwrap_or("")
            .starts_with("FX0011 "),
        "{o}"
    );
    assert!(
        o["findings"][1]["message"]
            .as_str()
            .unwrap_or("")
            .starts_with("PS0011 "),
        "{o}"
    );
    // The first alarm, and the program ran to its end.
    assert_eq!(
        (o["alarm"]["line"].as_u64(), o["ended"].as_bool()),
        (Some(3), Some(true))
    );
    assert_eq!(o["blocks"], 8);
    // GOTO to a sequence number that is not there: the flow is lost.
    let out = run(
        dir.path(),
        &["check", "flow.nc", "--keep-going", "--format", "json"],
    );
    let o = &json_lines(&out)[0];
    let lines: Vec<u64> = o["findings"]
        .as_array()
        .expect("list")
        .iter()
        .map(|f| f["line"].as_u64().unwrap_or(0))
        .collect();
    assert_eq!(lines, [3, 4], "{o}");
    assert_eq!(
        (o["alarm"]["line"].as_u64(), o["ended"].as_bool()),
        (Some(3), Some(false))
    );
}
