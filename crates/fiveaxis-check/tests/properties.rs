//! Property tests judged by forward kinematics and dense independent
//! sampling of each block's law (`Segment::eval`, `Machine::forward`):
//! every reported singular passage, over-travel and chord error is real
//! (its value is reached), and none is missed: on the built-in machines,
//! and for chord errors on random two-rotary machines (the machine
//! crate's generator: random axis lines, centres, limits, parameters).

use fiveaxis_check::{Checker, Ending, Kind, Report};
use fiveaxis_control::{Motion, RunError, RunOptions, Runner, Segment, SliceSource};
use fiveaxis_machine::{Machine, Offsets, Vec3, builtin};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestRunner};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The machine crate's generators of random machines.
#[path = "../../fiveaxis-machine/tests/common/mod.rs"]
mod machine_gen;

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x0C4E_C411),
        failure_persistence: None,
        ..Config::default()
    }
}

fn check<S: Strategy>(
    cases: u32,
    strategy: S,
    test: impl Fn(S::Value) -> Result<(), TestCaseError>,
) {
    let mut runner = TestRunner::new(config(cases));
    if let Err(e) = runner.run(&strategy, test) {
        panic!("{e}");
    }
}

/// Tool 1 is 120 mm long.
fn offsets() -> Offsets {
    Offsets::from_toml("[tools]\n1 = { length = 120.0 }\n").expect("offsets")
}

/// How many findings of `kind` a report holds.
fn count(report: &Report, kind: Kind) -> usize {
    report.findings.iter().filter(|f| f.kind == kind).count()
}

/// Runs a program with the soft limits lifted: its segments and the
/// check's report. A second checker drains its settled findings after
/// every segment: what it hands over, then what its `finish` gives, must
/// be the report's findings in the report's order.
fn run(machine: &Machine, program: &str) -> (Vec<Segment>, Report) {
    let options = RunOptions {
        lift_soft_limits: true,
        ..RunOptions::default()
    };
    let mut runner = Runner::new(
        machine,
        offsets(),
        SliceSource::new(program.as_bytes()),
        options,
    );
    let mut checker = Checker::new(machine);
    let mut draining = Checker::new(machine);
    let mut drained = Vec::new();
    let mut segments = Vec::new();
    let alarm = loop {
        match runner.next_segment() {
            Ok(Some(seg)) => {
                checker.segment(&seg);
                draining.segment(&seg);
                draining.drain_settled(|f| drained.push(f));
                segments.push(seg);
            }
            Ok(None) => break None,
            Err(RunError::Alarm { alarm, .. }) => break Some(alarm),
            Err(e) => panic!("{e}"),
        }
    };
    let ending = Ending {
        ended: alarm.is_none(),
        alarm: None,
        blocks: runner.blocks(),
    };
    let report = checker.finish(ending.clone());
    drained.extend(draining.finish(ending.clone()).findings);
    assert_eq!(drained, report.findings, "drained findings\n{program}");
    // The same segments in one batch: the chord proofs, the time plan's
    // samples and the feeds the axes allow worked out ahead (the proofs on every core when there
    // are enough) give the same report, times to the last bit.
    let mut batched = Checker::new(machine);
    batched.segments(&segments);
    let batched = batched.finish(ending);
    assert_eq!(batched.findings, report.findings, "batched\n{program}");
    assert_eq!(batched.time, report.time, "batched\n{program}");
    assert_eq!(batched.axes, report.axes, "batched\n{program}");
    assert_eq!(
        batched.feed_limited_seconds.to_bits(),
        report.feed_limited_seconds.to_bits(),
        "batched\n{program}"
    );
    (segments, report)
}

#[test]
fn a_batch_with_its_chord_proofs_on_every_core_checks_as_block_by_block() {
    // 200 moves turning A and C far outside TCPC: every one a chord proof,
    // enough for the batch to spread them over the cores.
    let machine = builtin("trunnion-ac").expect("built in");
    let mut program = String::from("G90 G0 X0 Y0 Z0 A0 C0\nG1 F1000.\n");
    let mut state = 12_345_u64;
    let mut next = |lo: f64, hi: f64| {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        lo + (hi - lo) * ((state >> 11) as f64 / (1u64 << 53) as f64)
    };
    for _ in 0..200 {
        let (x, y, z) = (next(-100.0, 100.0), next(-100.0, 100.0), next(-50.0, 50.0));
        let (a, c) = (next(-90.0, 0.0), next(0.0, 359.0));
        program.push_str(&format!("X{x:.3} Y{y:.3} Z{z:.3} A{a:.3} C{c:.3}\n"));
    }
    program.push_str("M30\n");
    let (_, report) = run(&machine, &program);
    let chords = count(&report, Kind::ChordError);
    assert!(chords >= 100, "{chords} chord errors");
}

/// Dense sampling of `f` over [0, 1], then golden-section refinement around
/// the best sample: the test's own estimate of the maximum.
fn densest_max(f: impl Fn(f64) -> f64) -> f64 {
    const N: u32 = 2000;
    let mut best = (0.0, f(0.0));
    for k in 1..=N {
        let s = f64::from(k) / f64::from(N);
        let v = f(s);
        if v > best.1 {
            best = (s, v);
        }
    }
    let h = 1.0 / f64::from(N);
    let (mut a, mut b) = ((best.0 - h).max(0.0), (best.0 + h).min(1.0));
    for _ in 0..80 {
        let (c, d) = (a + (b - a) / 3.0, b - (b - a) / 3.0);
        if f(c) > f(d) {
            b = d;
        } else {
            a = c;
        }
    }
    best.1.max(f(0.5 * (a + b)))
}

/// The rotating axis' line of a built-in two-rotary machine, table frame.
fn singular_line(machine: &Machine) -> Vec3 {
    use fiveaxis_machine::Side::{Head, Table};
    let k = match (machine.rotary[0].on, machine.rotary[1].on) {
        (Head, Head) | (Table, Head) => 0,
        _ => 1,
    };
    machine.rotary[k].axis.into_inner()
}

/// Angle between the tool and the singular line at `s`, degrees.
fn singular_angle(machine: &Machine, seg: &Segment, s: f64) -> f64 {
    let dir = machine.forward(&seg.eval(machine, s), seg.tool_length).dir;
    let line = singular_line(machine);
    line.cross(&dir)
        .norm()
        .atan2(line.dot(&dir).abs())
        .to_degrees()
}

const FIVE_AXIS: [&str; 4] = [
    "trunnion-ac",
    "trunnion-bc",
    "head-table-bc",
    "head-head-ca",
];

/// Random TCPC type 1 blocks (`G43.4`, rotary words) swinging the tilt
/// axis across the singular direction, or type 2 (`G43.5`, tool vectors)
/// with tool posture control on or off.
fn tcpc_program() -> impl Strategy<Value = (usize, bool, bool, String)> {
    let block = (
        -80.0..80.0f64,
        -80.0..80.0f64,
        -20.0..40.0f64,
        -30.0..30.0f64,
        -170.0..170.0f64,
    );
    (
        0..FIVE_AXIS.len(),
        any::<bool>(),
        any::<bool>(),
        proptest::collection::vec(block, 2..6),
    )
        .prop_map(|(m, vectors, posture, blocks)| {
            let machine = builtin(FIVE_AXIS[m]).expect("built in");
            let names: Vec<char> = machine.rotary.iter().map(|r| r.name).collect();
            let mut text = String::from("G21 G90 G94\n");
            if vectors {
                text.push_str("G43.5 H1 X0 Y0 Z50.\n");
            } else {
                text.push_str("G43.4 H1 X0 Y0 Z50.\n");
            }
            for (x, y, z, tilt, turn) in blocks {
                if vectors {
                    // Within 30° of the spindle axis, any way round.
                    let (t, c) = (tilt.to_radians(), turn.to_radians());
                    let (i, j, k) = (t.sin() * c.cos(), t.sin() * c.sin(), t.cos());
                    text.push_str(&format!(
                        "G1 X{x:.3} Y{y:.3} Z{z:.3} I{i:.6} J{j:.6} K{k:.6} F2000.\n"
                    ));
                } else {
                    let (tilt_name, turn_name) = match machine.machine_type() {
                        fiveaxis_machine::MachineType::Head if names[0] == 'C' => (names[1], names[0]),
                        _ => (names[0], names[1]),
                    };
                    text.push_str(&format!(
                        "G1 X{x:.3} Y{y:.3} Z{z:.3} {tilt_name}{tilt:.3} {turn_name}{turn:.3} F2000.\n"
                    ));
                }
            }
            text.push_str("G49\nM30\n");
            (m, vectors, posture, text)
        })
}

#[test]
fn singular_passages_are_real_and_none_is_missed() {
    check(48, tcpc_program(), |(m, vectors, posture, program)| {
        let mut machine = builtin(FIVE_AXIS[m]).expect("built in");
        machine.params.tool_posture_control = posture;
        machine.params.singular_cone = 5.0;
        let (segments, report) = run(&machine, &program);
        for seg in segments.iter().filter(|s| s.motion != Motion::Rapid) {
            let rotary_moves = (3..machine.axis_count()).any(|i| seg.start[i] != seg.end[i]);
            let sampled = -densest_max(|s| -singular_angle(&machine, seg, s));
            let found = report
                .findings
                .iter()
                .find(|f| f.kind == Kind::SingularPassage && f.line == seg.line);
            // Only where the control chooses the rotary axes: from the
            // tool vectors of G43.5, or along the great circle of tool
            // posture control; not the rotary words of G43.4 alone.
            let posture_law =
                matches!(&seg.path, fiveaxis_control::Path::Tcpc(t) if t.posture.is_some());
            if !vectors && !posture_law {
                prop_assert!(
                    found.is_none(),
                    "line {}: programmed axes reported\n{program}",
                    seg.line
                );
                continue;
            }
            if let Some(f) = found {
                SINGULAR_SEEN.fetch_add(1, Ordering::Relaxed);
                let v = f.value.expect("value");
                // Reached: the sampled minimum is the same angle.
                prop_assert!(
                    (sampled - v).abs() <= 1e-6,
                    "line {}: reported {v}, sampled {sampled}\n{program}",
                    seg.line
                );
            } else if rotary_moves
                || matches!(&seg.path, fiveaxis_control::Path::Tcpc(t) if t.posture.is_some())
            {
                prop_assert!(
                    sampled > machine.params.singular_cone - 1e-6,
                    "line {}: missed a passage at {sampled}°\n{program}",
                    seg.line
                );
            }
        }
        Ok(())
    });
    assert!(
        SINGULAR_SEEN.load(Ordering::Relaxed) >= 10,
        "too few passages to judge"
    );
}

static SINGULAR_SEEN: AtomicUsize = AtomicUsize::new(0);
static OVERTRAVEL_SEEN: AtomicUsize = AtomicUsize::new(0);
static CHORD_SEEN: AtomicUsize = AtomicUsize::new(0);

/// Judges the over-travel findings of axis `i` on one side (`sign`
/// +1 above, −1 below; `limit` the limit times `sign`) by samples: an
/// excursion runs from the segment that leaves the limit to the one that
/// ends back inside it, and its value is the farthest sampled position.
/// The number of excursions judged.
fn judge_excursions(
    machine: &Machine,
    segments: &[Segment],
    report: &Report,
    program: &str,
    i: usize,
    sign: f64,
    limit: f64,
) -> Result<usize, TestCaseError> {
    let name = machine.axis_names().nth(i).expect("an axis");
    let mut runs: Vec<(u32, f64)> = Vec::new();
    let mut open = false;
    for seg in segments {
        let top = densest_max(|s| sign * seg.eval(machine, s)[i]);
        if top > limit + 1e-9 {
            prop_assume!(top > limit + 1e-6);
            if open {
                let last = runs.last_mut().expect("open");
                last.1 = last.1.max(top);
            } else {
                runs.push((seg.line, top));
            }
            let end = sign * seg.end[i];
            prop_assume!((end - limit).abs() > 1e-6);
            open = end > limit;
        } else {
            prop_assume!(top < limit - 1e-6 || top == limit);
            open = false;
        }
    }
    let reported: Vec<(u32, f64)> = report
        .findings
        .iter()
        .filter(|f| {
            f.kind == Kind::Overtravel
                && f.axis == Some(name)
                && f.value.is_some_and(|v| sign * v > limit)
        })
        .map(|f| (f.line, sign * f.value.unwrap_or(0.0)))
        .collect();
    prop_assert_eq!(
        reported.len(),
        runs.len(),
        "{}{} runs {:?} vs {:?}\n{}",
        name,
        sign,
        reported,
        runs,
        program
    );
    for ((line, value), (l, top)) in reported.iter().zip(&runs) {
        prop_assert_eq!(line, l);
        prop_assert!(
            (value - top).abs() <= 1e-6,
            "{name} line {line}: reported {value}, sampled {top}\n{program}"
        );
    }
    Ok(runs.len())
}

#[test]
fn overtravel_runs_are_real_and_none_is_missed() {
    check(48, tcpc_program(), |(m, _, posture, program)| {
        let mut machine = builtin(FIVE_AXIS[m]).expect("built in");
        machine.params.tool_posture_control = posture;
        // Tight limits, so that TCPC swings leave them.
        for axis in &mut machine.linear {
            axis.min = -60.0;
            axis.max = 60.0;
        }
        let (segments, report) = run(&machine, &program);
        for i in 0..3 {
            let seen = judge_excursions(&machine, &segments, &report, &program, i, 1.0, 60.0)?;
            OVERTRAVEL_SEEN.fetch_add(seen, Ordering::Relaxed);
        }
        Ok(())
    });
    assert!(
        OVERTRAVEL_SEEN.load(Ordering::Relaxed) >= 10,
        "too few over-travels to judge"
    );
}

static JOINT_OVERTRAVEL_SEEN: AtomicUsize = AtomicUsize::new(0);

/// Machine-axis moves near one place, each block sending at most one axis
/// far off: on one machine, with what limits a test sets.
fn near_and_far_program() -> impl Strategy<Value = (usize, String)> {
    let near = -10.0..10.0f64;
    let block = (
        [near.clone(), near.clone(), near.clone(), near.clone(), near],
        proptest::option::weighted(0.3, (0..5usize, 15.0..40.0f64, any::<bool>())),
    );
    (0..FIVE_AXIS.len(), proptest::collection::vec(block, 2..8)).prop_map(|(m, blocks)| {
        let machine = builtin(FIVE_AXIS[m]).expect("built in");
        let names: Vec<char> = ['X', 'Y', 'Z']
            .into_iter()
            .chain(machine.rotary.iter().map(|r| r.name))
            .collect();
        let mut text = String::from("G21 G90 G94 G43 H1\n");
        for (mut at, far) in blocks {
            if let Some((k, off, below)) = far {
                at[k] = if below { -off } else { off };
            }
            text.push_str("G1");
            for (name, v) in names.iter().zip(at) {
                text.push_str(&format!(" {name}{v:.3}"));
            }
            text.push_str(" F1000.\n");
        }
        text.push_str("M30\n");
        (m, text)
    })
}

/// Machine-axis moves (every axis linear in the block) under limits on
/// every axis, both sides, that most blocks keep: each excursion is
/// reported once, from the block that leaves the limit to the one that
/// ends back inside, with the farthest position sampled, and the ranges
/// are the positions'.
#[test]
fn overtravel_runs_of_joint_moves_on_every_axis_and_side() {
    check(96, near_and_far_program(), |(m, program)| {
        let mut machine = builtin(FIVE_AXIS[m]).expect("built in");
        for axis in &mut machine.rotary {
            axis.rollover = false;
        }
        // Limits 12 either side of where the program's last block ends
        // (near the middle of where most of them are).
        let (free, _) = run(&machine, &program);
        let middle = free.last().expect("moves").end;
        let bounds: Vec<(f64, f64)> = (0..machine.axis_count())
            .map(|i| (middle[i] - 12.0, middle[i] + 12.0))
            .collect();
        for (axis, &(lo, hi)) in machine.linear.iter_mut().zip(&bounds) {
            (axis.min, axis.max) = (lo, hi);
        }
        for (axis, &limits) in machine
            .rotary
            .iter_mut()
            .zip(&bounds[machine.linear.len()..])
        {
            axis.limits = Some(limits);
        }
        let (segments, report) = run(&machine, &program);
        let names: Vec<char> = machine.axis_names().collect();
        for (i, &name) in names.iter().enumerate() {
            let (lo, hi) = bounds[i];
            let range = report.axes.iter().find(|a| a.name == name).expect("range");
            let mut seen = (f64::INFINITY, f64::NEG_INFINITY);
            for seg in &segments {
                seen.0 = seen.0.min(-densest_max(|s| -seg.eval(&machine, s)[i]));
                seen.1 = seen.1.max(densest_max(|s| seg.eval(&machine, s)[i]));
            }
            prop_assert!(
                (range.min - seen.0).abs() <= 1e-9 && (range.max - seen.1).abs() <= 1e-9,
                "{name} range {range:?} vs {seen:?}\n{program}"
            );
            for sign in [1.0, -1.0] {
                let limit = if sign > 0.0 { hi } else { -lo };
                let seen =
                    judge_excursions(&machine, &segments, &report, &program, i, sign, limit)?;
                JOINT_OVERTRAVEL_SEEN.fetch_add(seen, Ordering::Relaxed);
            }
        }
        Ok(())
    });
    assert!(
        JOINT_OVERTRAVEL_SEEN.load(Ordering::Relaxed) >= 20,
        "too few over-travels to judge"
    );
}

/// Straight moves of X, Y, Z alone at feeds up to past every axis' speed,
/// on machines whose linear axes have different speeds: where an axis
/// cannot keep the feed, the tip feed it allows is, in closed form, the
/// smallest `v_i · L / |Δ_i|` (`L` the move's length, `Δ_i` the axis'
/// travel), the finding names that axis, and no move within every axis'
/// speed has one.
#[test]
fn feed_limits_of_straight_moves_are_the_closed_form() {
    let block = (
        -200.0..200.0f64,
        -200.0..200.0f64,
        -100.0..100.0f64,
        1000.0..40000.0f64,
    );
    let strategy = (
        0..FIVE_AXIS.len(),
        [3000.0..20000.0f64, 3000.0..20000.0f64, 3000.0..20000.0f64],
        proptest::collection::vec(block, 1..6),
    );
    let limited = AtomicUsize::new(0);
    check(64, strategy, |(m, speeds, blocks)| {
        let mut machine = builtin(FIVE_AXIS[m]).expect("built in");
        for (axis, v) in machine.linear.iter_mut().zip(speeds) {
            axis.dynamics.max_velocity = v;
        }
        let mut program = String::from("G21 G90 G94 G49\nG0 X0 Y0 Z0\n");
        for (x, y, z, f) in &blocks {
            program.push_str(&format!("G1 X{x:.3} Y{y:.3} Z{z:.3} F{f:.0}\n"));
        }
        program.push_str("M30\n");
        let (segments, report) = run(&machine, &program);
        for seg in segments.iter().filter(|s| s.motion == Motion::Linear) {
            let feed = seg.feed.expect("a feed");
            let travel: Vec<f64> = (0..3).map(|i| (seg.end[i] - seg.start[i]).abs()).collect();
            let length = travel.iter().map(|t| t * t).sum::<f64>().sqrt();
            prop_assume!(length > 1e-3);
            let (allowed, axis) = (0..3)
                .filter(|&i| travel[i] > 0.0)
                .map(|i| (speeds[i] * length / travel[i], i))
                .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a });
            prop_assume!((allowed - feed).abs() > 1e-6 * feed);
            let found: Vec<_> = report
                .findings
                .iter()
                .filter(|f| f.kind == Kind::FeedLimited && f.line == seg.line)
                .collect();
            if allowed < feed {
                prop_assert_eq!(found.len(), 1, "line {}\n{}", seg.line, program);
                let value = found[0].value.expect("a value");
                prop_assert!(
                    (value - allowed).abs() <= 1e-9 * allowed,
                    "line {}: {value} vs {allowed}\n{program}",
                    seg.line
                );
                prop_assert_eq!(found[0].axis, Some(machine.linear[axis].name));
                limited.fetch_add(1, Ordering::Relaxed);
            } else {
                prop_assert!(
                    found.is_empty(),
                    "line {}: {:?}\n{}",
                    seg.line,
                    found,
                    program
                );
            }
        }
        Ok(())
    });
    assert!(
        limited.load(Ordering::Relaxed) >= 20,
        "too few limited feeds to judge"
    );
}

/// Random machine-axis feed moves turning the rotary axes.
fn machine_axis_program() -> impl Strategy<Value = (usize, String)> {
    let block = (
        -50.0..50.0f64,
        -50.0..50.0f64,
        0.0..50.0f64,
        -40.0..0.0f64,
        -60.0..60.0f64,
    );
    (0..FIVE_AXIS.len(), proptest::collection::vec(block, 1..5)).prop_map(|(m, blocks)| {
        let machine = builtin(FIVE_AXIS[m]).expect("built in");
        let names: Vec<char> = machine.rotary.iter().map(|r| r.name).collect();
        let mut text = String::from("G21 G90 G94 G43 H1\n");
        for (x, y, z, a, b) in blocks {
            text.push_str(&format!(
                "G1 X{x:.3} Y{y:.3} Z{z:.3} {}{a:.3} {}{b:.3} F1000.\n",
                names[0], names[1]
            ));
        }
        text.push_str("M30\n");
        (m, text)
    })
}

#[test]
fn chord_errors_are_real_and_none_is_missed() {
    check(48, machine_axis_program(), |(m, program)| {
        let machine = builtin(FIVE_AXIS[m]).expect("built in");
        let (segments, report) = run(&machine, &program);
        judge_chord_errors(&machine, &segments, &report, &program, &CHORD_SEEN)?;
        Ok(())
    });
    assert!(
        CHORD_SEEN.load(Ordering::Relaxed) >= 10,
        "too few chord errors to judge"
    );
}

static RANDOM_CHORD_SEEN: AtomicUsize = AtomicUsize::new(0);

/// A random machine with two rotary axes (any arrangement: head, table,
/// mixed; random axis lines, centres, limits and parameters) and random
/// machine-axis feed moves turning both rotary axes.
fn random_machine_program() -> impl Strategy<Value = (Machine, String)> {
    use fiveaxis_machine::Side::{Head, Table};
    let sides = prop_oneof![
        Just(vec![Head, Head]),
        Just(vec![Table, Table]),
        Just(vec![Table, Head]),
    ];
    let block = (
        -50.0..50.0f64,
        -50.0..50.0f64,
        0.0..50.0f64,
        -60.0..60.0f64,
        -60.0..60.0f64,
    );
    (
        sides.prop_flat_map(machine_gen::machine_on),
        proptest::collection::vec(block, 1..5),
    )
        .prop_map(|(machine, blocks)| {
            let names: Vec<char> = machine.rotary.iter().map(|r| r.name).collect();
            let mut text = String::from("G21 G90 G94 G43 H1\n");
            for (x, y, z, a, b) in blocks {
                text.push_str(&format!(
                    "G1 X{x:.3} Y{y:.3} Z{z:.3} {}{a:.3} {}{b:.3} F1000.\n",
                    names[0], names[1]
                ));
            }
            text.push_str("M30\n");
            (machine, text)
        })
}

#[test]
fn chord_errors_on_random_machines_are_real_and_none_is_missed() {
    check(64, random_machine_program(), |(machine, program)| {
        let options = RunOptions {
            lift_soft_limits: true,
            ..RunOptions::default()
        };
        // The program must run on this machine (a random control may
        // refuse a word): the property is about the blocks that do.
        let mut probe = Runner::new(
            &machine,
            offsets(),
            SliceSource::new(program.as_bytes()),
            options,
        );
        let runs = loop {
            match probe.next_segment() {
                Ok(Some(_)) => {}
                Ok(None) => break true,
                Err(_) => break false,
            }
        };
        prop_assume!(runs);
        let (segments, report) = run(&machine, &program);
        judge_chord_errors(&machine, &segments, &report, &program, &RANDOM_CHORD_SEEN)?;
        Ok(())
    });
    assert!(
        RANDOM_CHORD_SEEN.load(Ordering::Relaxed) >= 10,
        "too few chord errors to judge"
    );
}

/// Every chord error reported on a linear block that turns a rotary axis
/// is reached (the dense sampling finds the same largest deviation, to
/// 1e-6 relative) and none is missed (no sampled deviation above the
/// tolerance goes unreported); `seen` counts the findings judged.
fn judge_chord_errors(
    machine: &Machine,
    segments: &[Segment],
    report: &Report,
    program: &str,
    seen: &AtomicUsize,
) -> Result<(), TestCaseError> {
    for seg in segments.iter().filter(|s| s.motion == Motion::Linear) {
        let rotary_moves =
            (machine.linear.len()..machine.axis_count()).any(|i| seg.start[i] != seg.end[i]);
        if !rotary_moves {
            continue;
        }
        let tip = |s: f64| machine.forward(&seg.eval(machine, s), seg.tool_length).tip;
        let (a, b) = (tip(0.0), tip(1.0));
        let chord = b - a;
        let along = if chord.norm() > 0.0 {
            chord.normalize()
        } else {
            chord
        };
        let off = |s: f64| {
            let d = tip(s) - a;
            (d - along * along.dot(&d)).norm()
        };
        let sampled = densest_max(off);
        let found = report
            .findings
            .iter()
            .find(|f| f.kind == Kind::ChordError && f.line == seg.line);
        let tolerance = machine.params.chord_tolerance;
        match found {
            Some(f) => {
                seen.fetch_add(1, Ordering::Relaxed);
                let v = f.value.expect("value");
                prop_assert!(
                    (sampled - v).abs() <= 1e-6 * v.max(1.0),
                    "line {}: reported {v}, sampled {sampled}\n{program}",
                    seg.line
                );
            }
            None => prop_assert!(
                sampled <= tolerance + 1e-6,
                "line {}: missed {sampled} mm (tolerance {tolerance})\n{program}",
                seg.line
            ),
        }
    }
    Ok(())
}

/// TCPC blocks fast enough for their rotary axes to limit the feed: the
/// limits worked out ahead of a batch (`run` compares the batched report
/// with the block-by-block one) are found, on every five-axis machine.
#[test]
fn feed_limits_of_tcpc_blocks_worked_out_ahead_are_the_checks_own() {
    for name in FIVE_AXIS {
        let machine = builtin(name).expect("built in");
        let names: Vec<char> = machine.rotary.iter().map(|r| r.name).collect();
        let mut program = String::from("G21 G90 G94\nG43.4 H1 X0 Y0 Z50.\n");
        for k in 0..40 {
            let sign = if k % 2 == 0 { -1.0 } else { 1.0 };
            program.push_str(&format!(
                "G1 X{:.3} Y{:.3} Z50. {}{:.3} {}{:.3} F20000.\n",
                10.0 * sign,
                f64::from(k),
                names[0],
                sign * 25.0,
                names[1],
                f64::from(k) * 40.0
            ));
        }
        program.push_str("G49\nM30\n");
        let (_, report) = run(&machine, &program);
        let limited = count(&report, Kind::FeedLimited);
        assert!(limited >= 10, "{name}: {limited} feed limits\n{program}");
    }
}
