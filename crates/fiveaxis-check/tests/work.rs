//! Collisions and the stock in whole runs, with answers known by hand: a
//! holder that comes down on a clamp, a near miss of a known gap, a rapid
//! move along the stock's side, a slot's volume and the time cutting air,
//! a ball mill below the part.

use fiveaxis_check::collision::{Collisions, WorkSolid};
use fiveaxis_check::stock::StockCheck;
use fiveaxis_check::{Checker, Ending, Finding, Kind, Report};
use fiveaxis_collide::work::WorkShape;
use fiveaxis_control::{RunError, RunOptions, Runner, SliceSource};
use fiveaxis_machine::{Machine, Offsets, Vec3, builtin};
use fiveaxis_stock::dexel::Dexels;
use fiveaxis_stock::{Part, Stock};

/// T1: a 10 mm flat end mill 50 mm long, 10 mm of flute, in a holder
/// Ø40 × 40 from the gauge line. T2: a ball mill of radius 5. G54 at the
/// origin of the table.
const OFFSETS: &str = r#"
[tools]
1 = { length = 50.0, radius = 5.0, cutter = "flat", flute_length = 10.0, shank_diameter = 10.0, holder = [{ diameter = 40.0, length = 40.0 }] }
2 = { length = 80.0, radius = 5.0, cutter = "ball", flute_length = 20.0 }
"#;

fn run(
    machine: &Machine,
    program: &str,
    mut setup: impl FnMut(&mut Checker<'_>, &Offsets),
) -> Report {
    let options = RunOptions {
        lift_soft_limits: true,
        ..RunOptions::default()
    };
    let offsets = Offsets::from_toml(OFFSETS).expect("offsets");
    let mut checker = Checker::new(machine);
    setup(&mut checker, &offsets);
    let mut runner = Runner::new(
        machine,
        offsets,
        SliceSource::new(program.as_bytes()),
        options,
    );
    loop {
        match runner.next_segment() {
            Ok(Some(seg)) => checker.segment(&seg),
            Ok(None) => break,
            Err(RunError::Alarm { alarm, .. }) => panic!("{alarm}"),
            Err(e) => panic!("{e}"),
        }
    }
    checker.finish(Ending {
        ended: true,
        alarm: None,
        blocks: runner.blocks(),
    })
}

fn of_kind(report: &Report, kind: Kind) -> Vec<&Finding> {
    report.findings.iter().filter(|f| f.kind == kind).collect()
}

/// A clamp x 20..30, y 0..50, z 0..15 on the table.
fn clamp(machine: &Machine, offsets: &Offsets) -> Collisions {
    let shape = WorkShape::Box {
        min: Vec3::new(20.0, 0.0, 0.0),
        max: Vec3::new(30.0, 50.0, 15.0),
    };
    let solid = WorkSolid {
        name: "clamp".into(),
        shape: shape.placed(&Vec3::zeros()).expect("box"),
    };
    Collisions::new(machine, offsets, 0.5, vec![solid])
}

#[test]
fn the_holder_comes_down_on_a_clamp() {
    let m = builtin("mill-3axis").expect("machine");
    // With the tip at z 2 the holder's face (10 mm above the tip, radius
    // 20 about x 10) is 3 mm into the clamp's top; the cutter (x 5..15)
    // stays clear of it.
    let program = "G90 G54 T1 M6\nG0 X10. Y25. Z60.\nG43 H1 Z30.\nG1 Z2. F300.\nG0 Z60.\nM30\n";
    let report = run(&m, program, |c, o| c.check_collisions(clamp(&m, o)));
    let hits = of_kind(&report, Kind::Collision);
    assert_eq!(hits.len(), 1, "{:#?}", report.findings);
    let hit = hits[0];
    assert_eq!(hit.line, 4);
    assert_eq!(
        hit.bodies.as_deref(),
        Some(&["holder".to_string(), "clamp".to_string()])
    );
    let depth = hit.value.expect("depth");
    assert!((depth - 3.0).abs() < 0.05, "{hit:?}");
}

#[test]
fn a_gap_of_three_tenths_is_a_near_miss() {
    let m = builtin("mill-3axis").expect("machine");
    let program = "G90 G54 T1 M6\nG0 X10. Y25. Z60.\nG43 H1 Z30.\nG1 Z5.3 F300.\nG0 Z60.\nM30\n";
    let report = run(&m, program, |c, o| c.check_collisions(clamp(&m, o)));
    assert!(
        of_kind(&report, Kind::Collision).is_empty(),
        "{:#?}",
        report.findings
    );
    let near = of_kind(&report, Kind::NearMiss);
    assert_eq!(near.len(), 1, "{:#?}", report.findings);
    assert_eq!(near[0].line, 4);
    assert!(
        (near[0].value.expect("gap") - 0.3).abs() < 1e-6,
        "{:?}",
        near[0]
    );
}

/// A stock box 0..50 × 0..50 × −20..0, with the part `part` if given.
fn stock(machine: &Machine, offsets: &Offsets, part: Option<(Vec3, Vec3)>) -> StockCheck {
    let (min, max) = (Vec3::new(0.0, 0.0, -20.0), Vec3::new(50.0, 50.0, 0.0));
    let margin = Vec3::repeat(1.0);
    let mut dexels = Dexels::empty(&(min - margin), &(max + margin), 0.1).expect("grid");
    dexels.fill_box(&min, &max);
    let part = part.map(|(pmin, pmax)| {
        let mut design = dexels.like();
        design.fill_box(&pmin, &pmax);
        let shape = WorkShape::Box {
            min: pmin,
            max: pmax,
        }
        .placed(&Vec3::zeros())
        .expect("box");
        Part {
            dexels: design,
            depth: Box::new(move |p| fiveaxis_collide::work::depth_inside(&shape, p)),
        }
    });
    StockCheck::new(
        machine,
        offsets,
        Stock::new(dexels, part, 0.05),
        Vec3::zeros(),
    )
}

#[test]
fn a_rapid_along_the_side_of_the_stock() {
    let m = builtin("mill-3axis").expect("machine");
    // The tool's axis at x −3: it takes 2 mm off the side, 5 mm deep,
    // along the 50 mm of the stock, in a rapid move: 500 mm³. The tool
    // removes material from tip y −4 (where its edge, 3 mm from the axis,
    // meets the corner) to tip y 50 (where the last of its edge, 5 mm
    // from the axis, leaves the far side): 54 mm, less the grid's
    // 0.1 mm rays 4.95 mm from the axis.
    let program = "G90 G54 T1 M6\nG0 X-3. Y-10. Z60.\nG43 H1 Z30.\nZ-5.\nY60.\nG0 Z60.\nM30\n";
    let report = run(&m, program, |c, o| c.check_stock(stock(&m, o, None)));
    let rapid = of_kind(&report, Kind::RapidIntoStock);
    assert_eq!(rapid.len(), 1, "{:#?}", report.findings);
    assert_eq!(rapid[0].line, 5);
    let through = rapid[0].value.expect("length");
    assert!((53.0..=54.05).contains(&through), "{:?}", rapid[0]);
    let summary = report.stock.expect("stock");
    let removed = summary.removed[&1];
    assert!((removed - 500.0).abs() < 5.0, "{removed}");
    assert!((summary.start_volume - summary.end_volume - removed).abs() < 1e-6);
}

#[test]
fn a_slot_and_the_time_cutting_air() {
    let m = builtin("mill-3axis").expect("machine");
    // Line 5 cuts a slot 10 × 5 × 50 (2500 mm³) across the stock; line 6
    // feeds 60 mm over the top at F600: 6 s cutting air.
    let program = "G90 G54 T1 M6\nG0 X-10. Y25. Z60.\nG43 H1 Z30.\nG0 Z-5.\nG1 X60. F500.\nG1 Z5.\nX0. F600.\nG0 Z60.\nM30\n";
    let report = run(&m, program, |c, o| c.check_stock(stock(&m, o, None)));
    assert!(
        of_kind(&report, Kind::RapidIntoStock).is_empty(),
        "{:#?}",
        report.findings
    );
    let summary = report.stock.expect("stock");
    assert!((summary.removed[&1] - 2500.0).abs() < 12.5, "{summary:?}");
    // Line 6 (Z−5 to Z5 at F500) leaves the slot through air too: 1.2 s.
    assert!(
        (summary.air_cut_seconds - (6.0 + 1.2)).abs() < 1e-6,
        "{summary:?}"
    );
}

#[test]
fn a_ball_mill_below_the_part_gouges_it() {
    let m = builtin("mill-3axis").expect("machine");
    // The part is the stock below z −2. The ball's tip runs at z −2.3
    // from x 10 to x 40: a gouge of 0.3 mm from the plunge on line 3.
    let program = "G90 G54 T2 M6\nG0 G43 H2 X10. Y25. Z60.\nG1 Z-2.3 F300.\nX40.\nG0 Z60.\nM30\n";
    let part = (Vec3::new(0.0, 0.0, -20.0), Vec3::new(50.0, 50.0, -2.0));
    let report = run(&m, program, |c, o| c.check_stock(stock(&m, o, Some(part))));
    let gouges = of_kind(&report, Kind::Gouge);
    assert_eq!(gouges.len(), 1, "{:#?}", gouges);
    assert_eq!(gouges[0].line, 3);
    let depth = gouges[0].value.expect("depth");
    assert!((depth - 0.3).abs() < 2e-3, "{:?}", gouges[0]);
    // Material left on the part where the ball did not pass: 2 mm.
    let excess = of_kind(&report, Kind::Excess);
    assert!(
        excess
            .iter()
            .any(|e| (e.value.expect("most") - 2.0).abs() < 1e-3),
        "{excess:#?}"
    );
}
