//! `import_linuxcnc` and the configuration's vismach model: hand-written
//! scripts with answers worked out by hand, damaged scripts, and the
//! corpus's xyzac-trt model with a few of its solids derived by hand from
//! its script (`xyzac-trt-gui.py`).

mod common;
#[path = "../../fiveaxis-cli/tests/common/corpus.rs"]
mod corpus;

use std::path::Path;
use std::time::{Duration, Instant};

use common::import_in_memory;
use fiveaxis_machine::geometry::{Body, Link, Shape, Solid};
use fiveaxis_machine::{Imported, Machine, Vec3, import_linuxcnc};

/// A table-tilting A/C machine (xyzac-trt-kins: A about X through
/// (0, 20, 10), C about Z through the origin) whose model is `gui.py`,
/// loaded with `settings`.
fn ini(settings: &str) -> String {
    format!(
        "[EMC]\nMACHINE = hand\n[KINS]\nKINEMATICS = xyzac-trt-kins\n[TRAJ]\nCOORDINATES = XYZAC\n\
         LINEAR_UNITS = mm\nANGULAR_UNITS = deg\n[HAL]\n\
         HALCMD = loadusr -W ./gui.py {settings}\n\
         HALCMD = net :x joint.0.pos-fb g.x\nHALCMD = net :y joint.1.pos-fb g.y\n\
         HALCMD = net :z joint.2.pos-fb g.z\nHALCMD = net :a joint.3.pos-fb g.a\n\
         HALCMD = net :c joint.4.pos-fb g.c\n\
         HALCMD = net :tl motion.tooloffset.z g.tool-len xyzac-trt-kins.tool-offset\n\
         HALCMD = net :yo xyzac-trt-kins.y-offset\nHALCMD = net :zo xyzac-trt-kins.z-offset\n\
         HALCMD = sets :yo 20\nHALCMD = sets :zo 10\n\
         [AXIS_X]\nMIN_LIMIT = -300\nMAX_LIMIT = 300\n[AXIS_Y]\nMIN_LIMIT = -300\nMAX_LIMIT = 300\n\
         [AXIS_Z]\nMIN_LIMIT = -300\nMAX_LIMIT = 300\n[AXIS_A]\nMIN_LIMIT = -90\nMAX_LIMIT = 90\n"
    )
}

/// The model: the table moves in X, Y, Z (vismach draws the table
/// moving), the cradle tilts about X through (0, 20, 10) from the work
/// capture, the round table turns on it; the head column stands still; a
/// knee moves with Z alone; an STL part and a custom class.
const GUI: &str = r#"from vismach import *
import hal
import sys
c = hal.component("g")
c.newpin("x", hal.HAL_FLOAT, hal.HAL_IN)
column_len = 100
for setting in sys.argv[1:]: exec(setting)

tooltip = Capture()
tool = Collection([tooltip, CylinderZ(0, 3, 40, 3)])
tool = HalTranslate([tool], c, "tool-len", 0, 0, -1)
column = Collection([tool, Box(-40, -40, 0, 40, 40, column_len)])
column = Translate([column], 0, 0, 300)

work = Capture()
plate = Collection([work, CylinderZ(-10, 60, 0, 60), CylinderZ(-10, 20, -30, 10)])
plate = HalRotate([plate], c, "c", 1, 0, 0, 1)
cradle = Collection([plate, Box(-80, -50, -40, 80, 50, -30)])
cradle = Translate([cradle], 0, -20, -10)
cradle = HalRotate([cradle], c, "a", 1, 1, 0, 0)
cradle = Translate([cradle], 0, 20, 10)
bed = Translate([Color([1, 0, 0, 0], [BoxCentered(400, 200, 20)])], 0, 0, -70)
table = Collection([cradle, bed])
table = HalTranslate([table], c, "x", -1, 0, 0)
table = HalTranslate([table], c, "y", 0, -1, 0)
table = HalTranslate([table], c, "z", 0, 0, -1)
table = Translate([table], 0, 0, 300)
knee = Box(-100, -100, -200, 100, 100, -150)
knee = HalTranslate([knee], c, "z", 0, 0, -1)
clamp = AsciiSTL(filename="clamp.stl")
odd = MyPart(c, 3)
model = Collection([table, column, knee, clamp, odd])
main(model, tooltip, work, size=500)
"#;

fn hand(settings: &str, gui: &str) -> Imported {
    let ini = ini(settings);
    import_in_memory(&[("/m/m.ini", &ini), ("/m/gui.py", gui)]).expect("imports")
}

fn body<'a>(machine: &'a Machine, name: &str) -> &'a Body {
    machine
        .bodies
        .iter()
        .find(|b| b.name == name)
        .unwrap_or_else(|| panic!("no body {name}: {:#?}", machine.bodies))
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).norm() < 1e-9
}

fn has(body: &Body, shape: Shape, at: Vec3) -> bool {
    body.solids
        .iter()
        .any(|s: &Solid| s.shape == shape && close(s.place.at, at))
}

#[test]
fn a_hand_written_model_maps_to_known_links_and_placements() {
    let imported = hand("column_len=150", GUI);
    let m = &imported.machine;
    let notes = imported.notes.join("\n");
    // The gauge point: the column's Translate 300; the work capture at
    // the plate's origin, (0, 0, 300) too. Our frame is vismach's less
    // (0, 0, 300).
    let cradle = body(m, "cradle");
    assert_eq!(cradle.on, Link::Axis(3), "{notes}");
    // Box(-80, -50, -40, 80, 50, -30): centre (0, 0, -35), shifted by
    // (0, -20, -10) and back by (0, 20, 10).
    assert!(has(
        cradle,
        Shape::Box {
            size: Vec3::new(160.0, 100.0, 10.0)
        },
        Vec3::new(0.0, 0.0, -35.0)
    ));
    let plate = body(m, "plate");
    assert_eq!(plate.on, Link::Axis(4));
    assert!(has(
        plate,
        Shape::Cylinder {
            radius: 60.0,
            length: 10.0
        },
        Vec3::new(0.0, 0.0, -10.0)
    ));
    // CylinderZ(-10, 20, -30, 10): from its lower end, radius 10 at z -30
    // up to radius 20 at z -10.
    assert!(has(
        plate,
        Shape::Cone {
            bottom: 10.0,
            top: 20.0,
            length: 20.0
        },
        Vec3::new(0.0, 0.0, -30.0)
    ));
    // The table moves with X, Y, Z in vismach: the bed, fixed here.
    let table = body(m, "table");
    assert_eq!(table.on, Link::Base);
    assert!(has(
        table,
        Shape::Box {
            size: Vec3::new(400.0, 200.0, 20.0)
        },
        Vec3::new(0.0, 0.0, -70.0)
    ));
    // The column stands still in vismach: it moves with X, Y, Z here;
    // column_len = 150 from the loadusr line.
    let head = body(m, "head");
    assert_eq!(head.on, Link::Head);
    assert_eq!(head.solids.len(), 1, "the tool is not in the head");
    assert!(has(
        head,
        Shape::Box {
            size: Vec3::new(80.0, 80.0, 150.0)
        },
        Vec3::new(0.0, 0.0, 75.0)
    ));
    assert_eq!(m.bodies.len(), 4, "{:#?}", m.bodies);
    // What was left out, with lines.
    for wanted in [
        "the tool (the tool comes from the offsets file): 1 part(s), gui.py lines 10",
        "no link of the machine does",
        "lines 28",
        "gui.py:30: `AsciiSTL(…)`: not a vismach constructor",
        "gui.py:31: `MyPart(…)`",
        "settings column_len=150",
        "on A: 1 solids in cradle (1)",
    ] {
        assert!(notes.contains(wanted), "`{wanted}` missing:\n{notes}");
    }
    // The file reads back with its bodies.
    let back = Machine::from_toml(&imported.to_toml()).expect("reads back");
    assert_eq!(back.bodies.len(), 4);
}

#[test]
fn without_the_setting_the_script_value_holds() {
    let imported = hand("", GUI);
    assert!(has(
        body(&imported.machine, "head"),
        Shape::Box {
            size: Vec3::new(80.0, 80.0, 100.0)
        },
        Vec3::new(0.0, 0.0, 50.0)
    ));
}

#[test]
fn a_missing_or_broken_script_leaves_the_bodies_to_the_user() {
    let ini = ini("");
    let imported = import_in_memory(&[("/m/m.ini", &ini)]).expect("imports without it");
    assert!(imported.machine.bodies.is_empty());
    assert!(
        imported.notes.iter().any(|n| n.contains("cannot be read")),
        "{:?}",
        imported.notes
    );
    let deep = format!(
        "from vismach import *\nc = hal.component(\"g\")\nx = {}1{}\n",
        "[".repeat(50_000),
        "]".repeat(50_000)
    );
    let many = format!(
        "from vismach import *\nc = hal.component(\"g\")\n{}",
        "b = Box(0, 0, 0, 1, 1, 1)\n".repeat(1_000_000)
    );
    let huge = GUI.replace(
        "Box(-40, -40, 0, 40, 40, column_len)",
        "Box(-4e300, 0, 0, 4e300, 1e999, 1)",
    );
    let garbage: Vec<String> = vec![
        GUI.replace("main(model", "main((model"),
        GUI.replace(
            "tool = Collection([tooltip,",
            "tool = Collection([[tooltip,",
        ),
        GUI.replace(
            "column = Translate([column], 0, 0, 300)",
            "column = Translate([column], 0, 0, 1e308 * 10)",
        ),
        GUI.replace(
            "table = Translate([table], 0, 0, 300)",
            "table = Translate([table], 0, 0, 1e300)",
        ),
        huge,
        deep,
        many,
        "vismach\0\u{7f}((([[[\"'''".into(),
        String::new(),
    ];
    for gui in &garbage {
        let started = Instant::now();
        let imported = import_in_memory(&[("/m/m.ini", &ini), ("/m/gui.py", gui)]);
        assert!(started.elapsed() < Duration::from_secs(60));
        let imported = imported.expect("a damaged model is a note, not an error");
        assert!(imported.notes.iter().any(|n| n.starts_with("vismach")));
        Machine::from_toml(&imported.to_toml()).expect("reads back");
    }
}

// ----- the corpus's xyzac-trt ---------------------------------------------

#[test]
fn xyzac_trt_solids_derived_by_hand_from_its_script() {
    let Some(ini) = corpus::corpus_path(
        "linuxcnc-configs/axis/vismach/5axis/table-rotary-tilting/xyzac-trt.ini",
    ) else {
        return;
    };
    let imported =
        import_linuxcnc(&ini, &mut |p: &Path| std::fs::read_to_string(p)).expect("imports");
    let m = &imported.machine;
    // The script: tooltip at z 200 (head 200, spindle 20, tool -20); the
    // work capture on the round table at the zslide's 200, the y/z
    // offsets (20, 10) there and back: at the gauge point. So our frame
    // is vismach's less (0, 0, 200).
    //
    // ctable: CylinderZ(-18, 50, 0, 50) on C: radius 50, top face at 0.
    let ctable = body(m, "ctable");
    assert_eq!(ctable.on, m.axis_index('C').map(Link::Axis).expect("C"));
    assert!(has(
        ctable,
        Shape::Cylinder {
            radius: 50.0,
            length: 18.0
        },
        Vec3::new(0.0, 0.0, -18.0)
    ));
    // The lump Box(42, -4, -20, 51, 4, 5): 9 x 8 x 25 about (46.5, 0, -7.5).
    assert!(has(
        ctable,
        Shape::Box {
            size: Vec3::new(9.0, 8.0, 25.0)
        },
        Vec3::new(46.5, 0.0, -7.5)
    ));
    // arotary: the trunnion plate Box(-65, -40, -35, 65, 40, -25) about
    // (0, 0, -30), shifted by the offsets (0, 20, 10); the rotary base
    // Box(-50, -50, -30, 50, 50, -18) shifted there and back: (0, 0, -24).
    let arotary = body(m, "arotary");
    assert_eq!(arotary.on, m.axis_index('A').map(Link::Axis).expect("A"));
    assert!(has(
        arotary,
        Shape::Box {
            size: Vec3::new(130.0, 80.0, 10.0)
        },
        Vec3::new(0.0, 20.0, -20.0)
    ));
    assert!(has(
        arotary,
        Shape::Box {
            size: Vec3::new(100.0, 100.0, 12.0)
        },
        Vec3::new(0.0, 0.0, -24.0)
    ));
    // The drive side trunnion CylinderX(-78, 20, -55, 20): along +X from
    // x -78, 23 long, through (0, 20, 10).
    let drive = arotary
        .solids
        .iter()
        .find(|s| {
            s.shape
                == Shape::Cylinder {
                    radius: 20.0,
                    length: 23.0,
                }
        })
        .expect("the drive trunnion");
    assert!(close(drive.place.at, Vec3::new(-78.0, 20.0, 10.0)));
    assert!(close(drive.place.axis.into_inner(), Vec3::x()));
    // The main table Box(-150, -50, -69, 150, 50, -52) moves with X in
    // vismach, as the bed does: on the base, at (0, 0, -60.5) + 200 - 200.
    let table = body(m, "table");
    assert_eq!(table.on, Link::Base);
    assert!(has(
        table,
        Shape::Box {
            size: Vec3::new(300.0, 100.0, 17.0)
        },
        Vec3::new(0.0, 0.0, -60.5)
    ));
    // The column Box(-50, 100, -250, 50, 200, 260) stands still in
    // vismach: on the head here, about (0, 150, 5 - 200).
    assert!(has(
        body(m, "head"),
        Shape::Box {
            size: Vec3::new(100.0, 100.0, 510.0)
        },
        Vec3::new(0.0, 150.0, -195.0)
    ));
    // Trunnion sides symmetric about the C axis.
    let side = |x: f64| {
        has(
            arotary,
            Shape::Box {
                size: Vec3::new(10.0, 80.0, 35.0),
            },
            Vec3::new(x, 20.0, -7.5),
        )
    };
    assert!(side(-60.0) && side(60.0));
    let notes = imported.notes.join("\n");
    assert!(notes.contains("left out, the tool"), "{notes}");
    // The knee (zslide) moves with Z alone while the table moves in X, Y
    // and Z: no link.
    assert!(notes.contains("no link of the machine does"), "{notes}");
}
