//! `fiveaxis check` with the work: `--fixture`, `--stock`, `--part`,
//! `--stock-out`, `--collisions` through the binary, their JSON keys and
//! their errors.

mod common;

use std::path::Path;
use std::process::Output;

use serde_json::Value;

use common::scratch;

fn run(dir: &Path, args: &[&str]) -> Output {
    common::run_in(dir, args, b"")
}

fn json(output: &Output) -> Value {
    let text = String::from_utf8_lossy(&output.stdout);
    serde_json::from_str(text.lines().next().expect("a line")).expect("JSON")
}

/// T1, a 10 mm end mill 60 mm long in a Ø40 holder; G54 on the table.
const OFFSETS: &str = r#"
[tools]
1 = { length = 60.0, radius = 5.0, cutter = "flat", flute_length = 15.0, shank_diameter = 10.0, holder = [{ diameter = 40.0, length = 30.0 }] }
"#;

/// A slot 10 × 5 × 50 across a 50 mm block, then a rapid into its side.
const SLOT: &str = "G21 G90 G54 T1 M6\nG0 G43 H1 X-10. Y25. Z30.\nZ-5.\nG1 X60. F500.\nG0 Z30.\nX25. Y-4.\nZ-3.\nG0 Z30.\nM30\n";

/// An ASCII STL of the box 0..50 × 0..50 × −20..0 (12 triangles).
fn box_stl() -> String {
    box_stl_between([0.0, 0.0, -20.0], [50.0, 50.0, 0.0])
}

/// An ASCII STL of the box from `lo` to `hi` (12 triangles, outwards).
fn box_stl_between(lo: [f64; 3], hi: [f64; 3]) -> String {
    let p = |i: usize| {
        [
            if i & 1 == 0 { lo[0] } else { hi[0] },
            if i & 2 == 0 { lo[1] } else { hi[1] },
            if i & 4 == 0 { lo[2] } else { hi[2] },
        ]
    };
    let faces = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut s = String::from("solid block\n");
    for f in faces {
        for t in [[f[0], f[1], f[2]], [f[0], f[2], f[3]]] {
            s.push_str("facet normal 0 0 0\nouter loop\n");
            for i in t {
                let v = p(i);
                s.push_str(&format!("vertex {} {} {}\n", v[0], v[1], v[2]));
            }
            s.push_str("endloop\nendfacet\n");
        }
    }
    s.push_str("endsolid block\n");
    s
}

#[test]
fn the_stock_is_cut_and_reported_in_json() {
    let stl = box_stl();
    let dir = scratch(&[("slot.nc", SLOT), ("o.toml", OFFSETS), ("block.stl", &stl)]);
    for stock in ["box:0,0,-20,50,50,0", "block.stl"] {
        let out = run(
            dir.path(),
            &[
                "check",
                "slot.nc",
                "--machine",
                "mill-3axis",
                "--offsets",
                "o.toml",
                "--stock",
                stock,
                "--resolution",
                "0.25",
                "--format",
                "json",
                "--stock-out",
                "left.stl",
            ],
        );
        assert_eq!(
            out.status.code(),
            Some(1),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v = json(&out);
        let stock = &v["stock"];
        assert_eq!(stock["start_volume"].as_f64(), Some(50_000.0));
        let removed = stock["removed"]["1"].as_f64().expect("T1's volume");
        // The slot 2500 mm³ and the rapid's 2 mm into the side wall.
        assert!(removed > 2500.0 && removed < 2700.0, "{stock}");
        assert_eq!(stock["resolution"].as_f64(), Some(0.25));
        let kinds: Vec<&str> = v["findings"]
            .as_array()
            .expect("findings")
            .iter()
            .map(|f| f["kind"].as_str().expect("kind"))
            .collect();
        assert_eq!(kinds, ["rapid_into_stock"], "{v}");
        assert_eq!(v["findings"][0]["line"].as_u64(), Some(7));
        // The stock left, whole, as binary STL: 84 bytes of header and
        // count, 50 bytes a triangle.
        let bytes = std::fs::read(dir.path().join("left.stl")).expect("left.stl");
        let count = u32::from_le_bytes(bytes[80..84].try_into().expect("count"));
        assert_eq!(bytes.len(), 84 + 50 * count as usize);
        assert!(count > 1000);
    }
}

#[test]
fn view_writes_the_stock_left_as_check_does() {
    let dir = scratch(&[("slot.nc", SLOT), ("o.toml", OFFSETS)]);
    let mut stls = Vec::new();
    for command in ["check", "view"] {
        let out_file = format!("{command}.stl");
        let out = run(
            dir.path(),
            &[
                command,
                "slot.nc",
                "--machine",
                "mill-3axis",
                "--offsets",
                "o.toml",
                "--stock",
                "box:0,0,-20,50,50,0",
                "--resolution",
                "0.5",
                "--stock-out",
                &out_file,
                "-o",
                "slot.html",
            ][..if command == "check" { 12 } else { 14 }],
        );
        assert!(
            out.status.code().is_some_and(|c| c <= 1),
            "{command}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        stls.push(std::fs::read(dir.path().join(&out_file)).expect("the stock left"));
    }
    // The same stock, cut by the same moves.
    assert!(stls[0].len() > 84);
    assert_eq!(stls[0][80..], stls[1][80..]);
    // Without a stock, --stock-out is refused by view as by check.
    let out = run(
        dir.path(),
        &[
            "view",
            "slot.nc",
            "--machine",
            "mill-3axis",
            "--offsets",
            "o.toml",
            "--stock-out",
            "none.stl",
            "-o",
            "none.html",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("--stock-out needs a stock"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!dir.path().join("none.stl").exists());
}

#[test]
fn a_fixture_the_holder_meets_is_a_collision_with_its_bodies() {
    // G54 50 mm above the table. A clamp 20..30 in x rising to z −15;
    // the holder's face 30 mm above the tip, radius 20 about x 10: with
    // the tip at z −47 it is 2 mm below the clamp's top, while the cutter
    // and the shank (x 5..15) stay 5 mm from it and the tip 3 mm above
    // the table.
    let program = "G21 G90 G54 T1 M6\nG0 G43 H1 X10. Y25. Z30.\nG1 Z-47. F300.\nG0 Z30.\nM30\n";
    let offsets = format!("{OFFSETS}\n[work]\nG54 = [0.0, 0.0, 50.0]\n");
    let dir = scratch(&[("p.nc", program), ("o.toml", &offsets)]);
    let out = run(
        dir.path(),
        &[
            "check",
            "p.nc",
            "--machine",
            "mill-3axis",
            "--offsets",
            "o.toml",
            "--fixture",
            "box:20,0,-50,30,50,-15",
            "--format",
            "json",
        ],
    );
    let v = json(&out);
    let f = &v["findings"][0];
    assert_eq!(f["kind"], "collision", "{v}");
    assert_eq!(f["severity"], "error");
    assert_eq!(f["line"].as_u64(), Some(3));
    assert_eq!(f["bodies"], serde_json::json!(["holder", "box"]));
    let depth = f["value"].as_f64().expect("depth");
    assert!((depth - 2.0).abs() < 0.05, "{f}");
    assert_eq!(v["findings"].as_array().map(Vec::len), Some(1), "{v}");
}

#[test]
fn bad_work_inputs_are_refused_with_their_option() {
    let dir = scratch(&[
        ("p.nc", "G0 X1.\nM30\n"),
        ("o.toml", OFFSETS),
        ("bad.stl", "not a mesh"),
    ]);
    let cases: [(&[&str], &str); 5] = [
        (
            &["--stock", "box:0,0,0,1,1"],
            "--stock box:0,0,0,1,1: expected 6 numbers",
        ),
        (&["--fixture", "box:0,0,0,1,1,0"], "the box has no volume"),
        (&["--fixture", "missing.stl"], "missing.stl"),
        (&["--stock", "bad.stl"], "--stock bad.stl: not an STL file"),
        (
            &["--stock", "box:0,0,0,1,1,1", "--resolution", "0"],
            "not a length above 0 mm",
        ),
    ];
    for (extra, want) in cases {
        let mut args = vec![
            "check",
            "p.nc",
            "--machine",
            "mill-3axis",
            "--offsets",
            "o.toml",
        ];
        args.extend_from_slice(extra);
        let out = run(dir.path(), &args);
        assert_eq!(out.status.code(), Some(2), "{extra:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(want), "{extra:?}: {err}");
    }
    // --part needs a stock; --stock-out one program.
    let out = run(dir.path(), &["check", "p.nc", "--part", "box:0,0,0,1,1,1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("need a stock"));
    let out = run(
        dir.path(),
        &[
            "check",
            "p.nc",
            "p.nc",
            "--stock",
            "box:0,0,0,1,1,1",
            "--stock-out",
            "x.stl",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("one program"));
    assert!(!dir.path().join("x.stl").exists());
}

#[test]
fn a_body_of_the_machine_file_can_be_a_mesh() {
    // mill-3axis with a clamp as a mesh body on the base: the box
    // 0..10 × 0..50 × 0..35 of clamp.stl placed at x 20. G54 50 mm up: the
    // holder's face comes 2 mm into its top, as the fixture of the test
    // above.
    let dir = scratch(&[]);
    let shown = run(dir.path(), &["machines", "show", "mill-3axis"]);
    assert_eq!(shown.status.code(), Some(0));
    let mut machine = String::from_utf8_lossy(&shown.stdout).into_owned();
    machine.push_str(
        "\n[[body]]\nname = \"clamp\"\non = \"base\"\nsolids = [{ mesh = \"meshes/clamp.stl\", at = [20.0, 0.0, 0.0] }]\n",
    );
    std::fs::create_dir_all(dir.path().join("setup/meshes")).expect("folder");
    std::fs::write(dir.path().join("setup/m.toml"), &machine).expect("machine");
    std::fs::write(
        dir.path().join("setup/meshes/clamp.stl"),
        box_stl_between([0.0, 0.0, 0.0], [10.0, 50.0, 35.0]),
    )
    .expect("mesh");
    let program = "G21 G90 G54 T1 M6\nG0 G43 H1 X10. Y25. Z30.\nG1 Z-47. F300.\nG0 Z30.\nM30\n";
    let offsets = format!("{OFFSETS}\n[work]\nG54 = [0.0, 0.0, 50.0]\n");
    std::fs::write(dir.path().join("p.nc"), program).expect("program");
    std::fs::write(dir.path().join("o.toml"), offsets).expect("offsets");
    let out = run(
        dir.path(),
        &[
            "check",
            "p.nc",
            "--machine",
            "setup/m.toml",
            "--offsets",
            "o.toml",
            "--collisions",
            "--format",
            "json",
        ],
    );
    let v = json(&out);
    let hits: Vec<&Value> = v["findings"]
        .as_array()
        .expect("findings")
        .iter()
        .filter(|f| f["kind"] == "collision")
        .collect();
    assert_eq!(hits.len(), 1, "{v}");
    assert_eq!(hits[0]["bodies"], serde_json::json!(["holder", "clamp"]));
    let depth = hits[0]["value"].as_f64().expect("depth");
    assert!((depth - 2.0).abs() < 0.05, "{v}");
    // A mesh file that is not there is refused with its name.
    std::fs::remove_file(dir.path().join("setup/meshes/clamp.stl")).expect("removed");
    let out = run(dir.path(), &["check", "p.nc", "--machine", "setup/m.toml"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("mesh meshes/clamp.stl"));
}
