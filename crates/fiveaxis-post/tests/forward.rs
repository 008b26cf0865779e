//! The post judged by forward kinematics: every output program is run by
//! the kernel on the same machine (TCPC off, rows every few hundredths of a
//! millimetre), and each row's tool tip and direction (`Machine::forward`
//! of the row's axes, with the source block's tool length) is compared
//! with the source program's path at the same instant: the source's law
//! (`Segment::eval`, forward kinematics again) at the share of its block's
//! time, the block's time being its tip path length (summed from densely
//! sampled forward tips) over its programmed feed. The output's time is
//! the kernel's reading of G93 (`length / feed` of each segment). Block
//! ends of the source must have a block end of the output within 1 % of
//! the block's time.
//!
//! Random TCPC programs (fixed seed) on every built-in machine type, and
//! hand examples (the README's, an arc, a tilted working plane).

mod common;

use common::{ROW_STEP, TIME_SHARE, offsets};
use fiveaxis_control::{Motion, Segment};
use fiveaxis_machine::{Machine, Offsets, Vec3, builtin};
use fiveaxis_post::PostOptions;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestCaseError, TestRunner};

/// Samples of a source block for its tip length.
const LENGTH_SAMPLES: u32 = 400;
/// Rounding of the comparison itself (time matching of rows), mm / deg.
const SLACK: f64 = 1e-6;

/// Tip path length of a segment by forward kinematics, mm.
fn tip_length(machine: &Machine, seg: &Segment) -> f64 {
    let mut last = machine
        .forward(&seg.eval(machine, 0.0), seg.tool_length)
        .tip;
    let mut sum = 0.0;
    for k in 1..=LENGTH_SAMPLES {
        let tip = machine
            .forward(
                &seg.eval(machine, f64::from(k) / f64::from(LENGTH_SAMPLES)),
                seg.tool_length,
            )
            .tip;
        sum += (tip - last).norm();
        last = tip;
    }
    sum
}

/// Worst deviations found: tip mm, direction degrees, block time share.
#[derive(Clone, Copy, Debug, Default)]
struct Worst {
    tip: f64,
    angle: f64,
    time: f64,
    rows: u64,
}

/// A run of consecutive cutting segments with their times.
struct Stretch<'a> {
    segs: Vec<(&'a Segment, f64)>,
}

fn stretches<'a>(
    segments: &'a [Segment],
    time: impl Fn(&Segment) -> f64,
) -> (Vec<Stretch<'a>>, Vec<&'a Segment>) {
    let mut out = Vec::new();
    let mut rapids = Vec::new();
    let mut current: Vec<(&Segment, f64)> = Vec::new();
    for seg in segments.iter().filter(|s| s.moves()) {
        if seg.motion == Motion::Rapid {
            if !current.is_empty() {
                out.push(Stretch {
                    segs: std::mem::take(&mut current),
                });
            }
            rapids.push(seg);
        } else {
            current.push((seg, time(seg)));
        }
    }
    if !current.is_empty() {
        out.push(Stretch { segs: current });
    }
    (out, rapids)
}

/// Converts the program and judges the output; the worst deviations.
fn judge(
    machine: &Machine,
    offsets: &Offsets,
    source: &str,
    options: PostOptions,
) -> Result<Worst, String> {
    let original =
        common::run(machine, offsets, source, None, false).map_err(|e| format!("source: {e}"))?;
    let (text, _) = common::post(machine, machine, &original, options);
    judge_text(machine, offsets, source, &text, options)
}

/// Judges the output `text` of `source` at `options`' tolerances.
fn judge_text(
    machine: &Machine,
    offsets: &Offsets,
    source: &str,
    text: &str,
    options: PostOptions,
) -> Result<Worst, String> {
    let original =
        common::run(machine, offsets, source, None, false).map_err(|e| format!("source: {e}"))?;
    let output = common::run(machine, offsets, text, Some(ROW_STEP), false)
        .map_err(|e| format!("output: {e}\n{text}"))?;
    let (src, src_rapids) = stretches(&original, |s| {
        tip_length(machine, s) / s.feed.unwrap_or(f64::NAN)
    });
    let (out, out_rapids) = stretches(&output, |s| {
        let chord = (s.row(machine, 1.0).tip - s.row(machine, 0.0).tip).norm();
        chord / s.feed.unwrap_or(f64::NAN)
    });
    if src.len() != out.len() {
        return Err(format!(
            "{} cutting stretches in, {} out\n{text}",
            src.len(),
            out.len()
        ));
    }
    let mut worst = Worst::default();
    // Rapids end where the source's end.
    let last_rapid_tips = |rapids: &[&Segment]| -> Vec<Vec3> {
        rapids
            .iter()
            .map(|s| machine.forward(&s.end, 0.0).tip)
            .collect()
    };
    let (a, b) = (last_rapid_tips(&src_rapids), last_rapid_tips(&out_rapids));
    for tip in &a {
        if !b.iter().any(|t| (t - tip).norm() <= options.tolerance) {
            return Err(format!("rapid end {tip:?} missing\n{text}"));
        }
    }
    for (s, o) in src.iter().zip(&out) {
        // Source block ends in time.
        let mut ends = Vec::new();
        let mut t = 0.0;
        for (_, d) in &s.segs {
            t += d;
            ends.push((t, *d));
        }
        let mut out_ends = Vec::new();
        let mut t = 0.0;
        for (_, d) in &o.segs {
            t += d;
            out_ends.push(t);
        }
        for (end, d) in &ends {
            let nearest = out_ends
                .iter()
                .map(|e| (e - end).abs())
                .fold(f64::INFINITY, f64::min);
            let share = nearest / d;
            worst.time = worst.time.max(share);
            if share > TIME_SHARE {
                return Err(format!(
                    "source block end at {end} min kept only within {share}\n{text}"
                ));
            }
        }
        // Every row at its instant.
        let mut t0 = 0.0;
        for (seg, d) in &o.segs {
            for k in 0..=seg.rows {
                let u = f64::from(k) / f64::from(seg.rows);
                let time = t0 + u * d;
                let at = ends.partition_point(|(e, _)| *e < time).min(ends.len() - 1);
                let (src_seg, dur) = s.segs[at];
                let start = ends[at].0 - dur;
                let sv = ((time - start) / dur).clamp(0.0, 1.0);
                let law = machine.forward(&src_seg.eval(machine, sv), src_seg.tool_length);
                let got = machine.forward(&seg.eval(machine, u), src_seg.tool_length);
                let tip = (got.tip - law.tip).norm();
                let angle = got
                    .dir
                    .cross(&law.dir)
                    .norm()
                    .atan2(got.dir.dot(&law.dir))
                    .to_degrees();
                worst.tip = worst.tip.max(tip);
                worst.angle = worst.angle.max(angle);
                worst.rows += 1;
                if tip > options.tolerance + SLACK || angle > options.angle_tolerance + SLACK {
                    return Err(format!(
                        "row at {time} min (source line {}, s {sv}): tip off by {tip} mm, direction by {angle} deg\n{text}",
                        src_seg.line
                    ));
                }
            }
            t0 += d;
        }
    }
    Ok(worst)
}

/// A random TCPC program on `machine`: G43.4 with the rotary angles, or
/// G43.5 with tool vectors made by forward kinematics of random angles.
fn random_program(
    machine: &Machine,
    vector: bool,
    points: &[(Vec3, [f64; 2])],
    feed: f64,
) -> String {
    let names: Vec<char> = machine.rotary.iter().map(|r| r.name).collect();
    let mut p = String::from("G21 G17 G90 G94 G54\n");
    p.push_str(&format!("G0 X0 Y0 Z200. {}0 {}0\n", names[0], names[1]));
    let words = |tip: &Vec3, angles: &[f64; 2]| {
        if vector {
            let mut j = [0.0; fiveaxis_machine::MAX_AXES];
            j[machine.rotary_index(0)] = angles[0];
            j[machine.rotary_index(1)] = angles[1];
            let d = machine.forward(&j, 100.0).dir;
            format!(
                "X{:.4} Y{:.4} Z{:.4} I{:.6} J{:.6} K{:.6}",
                tip[0], tip[1], tip[2], d[0], d[1], d[2]
            )
        } else {
            format!(
                "X{:.4} Y{:.4} Z{:.4} {}{:.4} {}{:.4}",
                tip[0], tip[1], tip[2], names[0], angles[0], names[1], angles[1]
            )
        }
    };
    // The start block names no vector (table and mixed machines refuse
    // one there, PS5421) and no angles: the tool stands vertical.
    let first = points[0].0;
    p.push_str(&format!(
        "{} H1 X{:.4} Y{:.4} Z{:.4}\n",
        if vector { "G43.5" } else { "G43.4" },
        first[0],
        first[1],
        first[2] + 20.0
    ));
    for (k, (tip, angles)) in points.iter().enumerate() {
        let f = if k == 0 {
            format!(" F{feed:.1}")
        } else {
            String::new()
        };
        p.push_str(&format!("G1 {}{f}\n", words(tip, angles)));
    }
    p.push_str("G0 Z200.\nG49\nM30\n");
    p
}

/// Rotary angles kept inside the machine's limits and away from the
/// singular direction (the tilting axis between 10 and 50 degrees off).
fn angles_for(machine: &Machine, tilt: f64, turn: f64) -> [f64; 2] {
    // The axis across Z tilts; the other turns.
    let tilting = usize::from(machine.rotary[0].axis.z.abs() > 0.5);
    let mut a = [0.0; 2];
    a[tilting] = tilt;
    a[1 - tilting] = turn;
    a
}

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x9057_0013),
        failure_persistence: None,
        max_shrink_iters: 256,
        ..Config::default()
    }
}

fn random_on(name: &str, vector: bool) -> Worst {
    let machine = builtin(name).expect("built-in");
    let mut runner = TestRunner::new(config(12));
    let worst = std::cell::Cell::new(Worst::default());
    let point = (
        -60.0..60.0f64,
        -60.0..60.0f64,
        -10.0..30.0f64,
        10.0..50.0f64,
        -120.0..120.0f64,
    );
    let strategy = (
        prop::collection::vec(point, 2..7),
        80.0..200.0f64,
        (-100.0..100.0f64, -100.0..100.0f64, -50.0..50.0f64),
        100.0..3000.0f64,
    );
    runner
        .run(&strategy, |(pts, length, (wx, wy, wz), feed)| {
            let points: Vec<(Vec3, [f64; 2])> = pts
                .iter()
                .map(|&(x, y, z, tilt, turn)| {
                    (Vec3::new(x, y, z), angles_for(&machine, tilt, turn))
                })
                .collect();
            let program = random_program(&machine, vector, &points, feed);
            let offsets = offsets(length, Vec3::new(wx, wy, wz));
            let options = PostOptions {
                origin: offsets.work[0],
                ..PostOptions::default()
            };
            match judge(&machine, &offsets, &program, options) {
                Ok(w) => {
                    let mut all = worst.get();
                    all.tip = all.tip.max(w.tip);
                    all.angle = all.angle.max(w.angle);
                    all.time = all.time.max(w.time);
                    all.rows += w.rows;
                    worst.set(all);
                    Ok(())
                }
                Err(e) => Err(TestCaseError::fail(format!("{name}:\n{program}\n{e}"))),
            }
        })
        .unwrap_or_else(|e| panic!("{e}"));
    let w = worst.get();
    eprintln!(
        "{name} ({}): worst tip {:.6} mm, direction {:.6} deg, block time {:.2e}, {} rows",
        if vector { "G43.5" } else { "G43.4" },
        w.tip,
        w.angle,
        w.time,
        w.rows
    );
    w
}

#[test]
fn random_type1_programs_on_every_machine_type() {
    for name in [
        "trunnion-ac",
        "trunnion-bc",
        "head-table-bc",
        "head-head-ca",
    ] {
        random_on(name, false);
    }
}

#[test]
fn random_type2_programs_on_every_machine_type() {
    for name in [
        "trunnion-ac",
        "trunnion-bc",
        "head-table-bc",
        "head-head-ca",
    ] {
        random_on(name, true);
    }
}

/// The post example of the README and docs/post.md (`examples/tcpc-vector.nc`, H1 = 120 mm).
#[test]
fn readme_example_within_tolerance() {
    let machine = builtin("head-table-bc").expect("built-in");
    let source = include_str!("../../../examples/tcpc-vector.nc");
    let offsets =
        fiveaxis_machine::Offsets::from_toml(include_str!("../../../examples/offsets.toml"))
            .expect("offsets");
    let options = PostOptions {
        origin: offsets.work[0] + offsets.external,
        ..PostOptions::default()
    };
    let w = judge(&machine, &offsets, source, options).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("tcpc-vector: {w:?}");
    // A finer tolerance holds too.
    let fine = PostOptions {
        tolerance: 0.001,
        angle_tolerance: 0.01,
        ..options
    };
    judge(&machine, &offsets, source, fine).unwrap_or_else(|e| panic!("{e}"));
}

/// The judge itself can fail: an output made for ten times the tolerance
/// is refused at the tolerance.
#[test]
fn judge_refuses_a_coarser_output() {
    let machine = builtin("head-table-bc").expect("built-in");
    let source = include_str!("../../../examples/tcpc-vector.nc");
    let offsets =
        fiveaxis_machine::Offsets::from_toml(include_str!("../../../examples/offsets.toml"))
            .expect("offsets");
    let origin = offsets.work[0] + offsets.external;
    let original = common::run(&machine, &offsets, source, None, false).expect("source runs");
    let coarse = PostOptions {
        tolerance: 0.1,
        angle_tolerance: 1.0,
        origin,
        ..PostOptions::default()
    };
    let (text, _) = common::post(&machine, &machine, &original, coarse);
    // Judged at 0.01 mm: run the coarse text through the same comparison.
    let strict = PostOptions {
        origin,
        ..PostOptions::default()
    };
    let verdict = judge_text(&machine, &offsets, source, &text, strict);
    assert!(verdict.is_err(), "a 0.1 mm output passed at 0.01 mm");
}

fn example_offsets() -> Offsets {
    Offsets::from_toml(include_str!("../../../examples/offsets.toml")).expect("offsets")
}

/// Circles under TCPC (the rotary axes standing, as FANUC requires) and
/// lines that turn the tool between them.
#[test]
fn tcpc_circles_within_tolerance() {
    let machine = builtin("head-table-bc").expect("built-in");
    let offsets = example_offsets();
    let options = PostOptions {
        origin: offsets.work[0],
        ..PostOptions::default()
    };
    let w = judge(&machine, &offsets, include_str!("tcpc-arcs.nc"), options)
        .unwrap_or_else(|e| panic!("{e}"));
    eprintln!("tcpc-arcs: {w:?}");
    assert!(w.rows > 1000, "the circles were sampled");
}

/// A tilted working plane (G68.2, G53.1) with length compensation and a
/// canned cycle called by a macro: the same holes in machine axes.
#[test]
fn tilted_working_plane_example_within_tolerance() {
    let machine = builtin("trunnion-ac").expect("built-in");
    let offsets = example_offsets();
    let options = PostOptions {
        origin: offsets.work[0],
        ..PostOptions::default()
    };
    let source = include_str!("../../../examples/tilted-holes.nc");
    let w = judge(&machine, &offsets, source, options).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("tilted-holes: {w:?}");
}
