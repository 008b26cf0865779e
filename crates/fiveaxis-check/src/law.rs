//! The motion laws of a segment as [`Moving`] points: the linear axes of
//! a TCPC block, and the tool tip of a machine-axis block, with bounds on
//! their derivatives in `s` for [`crate::bound::maximize`] and
//! [`crate::bound::maximize_norm`].

use fiveaxis_control::{Path, Segment, TcpcPath};
use fiveaxis_machine::{Machine, Side, Vec3};

use crate::bound::Moving;

/// Start angle and turn over the block of rotary axis `k`.
fn turn(machine: &Machine, seg: &Segment, k: usize) -> (f64, f64) {
    let i = machine.rotary_index(k);
    (seg.start[i], seg.end[i] - seg.start[i])
}

/// The tool end (tip relative to the spindle gauge point) turned by the
/// head axes, innermost first; with `quill`, moved along the tool by the
/// quill ([`fiveaxis_machine::Along::Tool`]), linear in `s`.
fn tool_end(machine: &Machine, seg: &Segment, quill: bool) -> Moving {
    let t0 = machine.tool_direction.into_inner();
    let mut end = match machine.quill_index() {
        Some(i) if quill => Moving::line(
            (seg.start[i] - seg.tool_length) * t0,
            (seg.end[i] - seg.tool_length) * t0,
        ),
        _ => Moving::fixed(-seg.tool_length * t0),
    };
    for (k, axis) in machine.rotary.iter().enumerate().rev() {
        if axis.on == Side::Head {
            let (a0, d) = turn(machine, seg, k);
            end = end.turned(&axis.axis, &axis.center, a0, d);
        }
    }
    end
}

/// X, Y, Z of a TCPC block whose rotary axes move linearly in `s`
/// (no tool posture control): the tip carried into the machine frame by
/// the table axes, less the tool end (as
/// `Machine::gauge_for_programmed_tip`).
pub fn tcpc_gauge(machine: &Machine, seg: &Segment, tcpc: &TcpcPath) -> Moving {
    let mut tip = Moving::tip_path(&tcpc.tip);
    if tcpc.turning {
        // The ideal tip given in the machine frame: back into the table
        // frame, onto the real workpiece (as `Segment::eval`).
        for (k, axis) in machine.rotary.iter().enumerate() {
            if axis.on == Side::Table {
                let (a0, d) = turn(machine, seg, k);
                tip = tip.turned(&axis.axis, &axis.center, -a0, -d);
            }
        }
        tip = tip.mapped(|p| seg.work + seg.setup.point(&(p - seg.work)));
    }
    for (k, axis) in machine.rotary.iter().enumerate().rev() {
        if axis.on == Side::Table {
            let (a0, d) = turn(machine, seg, k);
            tip = tip.turned(&axis.axis, &axis.center, a0, d);
        }
    }
    // The programmed tip is the tip with the quill at 0
    // (`Machine::gauge_for_programmed_tip`).
    tip.minus(tool_end(machine, seg, false))
}

/// [`tcpc_gauge`] of a TCPC block without tool posture control, the law
/// its extremes and axis speeds are bounded by: worked out once a block.
pub fn tcpc_law(machine: &Machine, seg: &Segment) -> Option<Moving> {
    match &seg.path {
        Path::Tcpc(tcpc) if tcpc.posture.is_none() => Some(tcpc_gauge(machine, seg, tcpc)),
        _ => None,
    }
}

/// The tool tip (table frame) of a machine-axis block whose rotary axes
/// move linearly (`Joint`, `Arc`, `Helix` paths), as `Machine::forward`
/// computes it: the tool end turned by the head axes, plus X, Y, Z, then
/// the table axes undone bed outwards. `None` for other paths.
pub fn machine_tip(machine: &Machine, seg: &Segment) -> Option<Moving> {
    let xyz = |j: &[f64]| Vec3::new(j[0], j[1], j[2]);
    let gauge = match &seg.path {
        Path::Joint => Moving::line(xyz(&seg.start), xyz(&seg.end)),
        Path::Arc(arc) => {
            // The plane axes on a (spiral) circle with a drifting centre,
            // the other linear axes linear.
            let r = arc.r0.abs().max(arc.r1.abs());
            let dr = (arc.r1 - arc.r0).abs();
            let w = arc.sweep.abs();
            let mut linear = seg.end;
            for &a in &arc.axes {
                linear[a] = seg.start[a];
            }
            let rest = Moving::line(xyz(&seg.start), xyz(&linear));
            let drift = arc.drift[0].hypot(arc.drift[1]);
            Moving {
                at0: xyz(&seg.start),
                speed: rest.speed + dr + r * w + drift,
                curvature: 2.0 * dr * w + r * w * w,
                jerk: 3.0 * dr * w * w + r * w * w * w,
            }
        }
        Path::Helix { circle, drift } => {
            let c = Moving::tip_path(circle);
            Moving {
                at0: xyz(&seg.start),
                speed: c.speed + drift.norm(),
                curvature: c.curvature,
                jerk: c.jerk,
            }
        }
        Path::Via(_) | Path::Tcpc(_) => return None,
    };
    let mut tip = gauge.plus(tool_end(machine, seg, true));
    for (k, axis) in machine.rotary.iter().enumerate() {
        if axis.on == Side::Table {
            let (a0, d) = turn(machine, seg, k);
            tip = tip.turned(&axis.axis, &axis.center, -a0, -d);
        }
    }
    Some(tip)
}

/// A bound on the second derivative of the tool tip of a joint move
/// (`Path::Joint`), as [`machine_tip`]'s law gives but worked out without
/// turning its start point (no sine or cosine): where the law measures a
/// turned point's distance from the next rotation line, this takes its
/// distance from that line's centre, bounded by the triangle inequality
/// (`|R(q − c₁) + c₁ − c₂| ≤ |q − c₁| + |c₁ − c₂|`). Never below the law's
/// bound; it settles the chord of a block whose rotary axes turn little
/// before the law is built. `None` for other paths.
pub fn joint_tip_curvature(machine: &Machine, seg: &Segment) -> Option<f64> {
    if !matches!(seg.path, Path::Joint) {
        return None;
    }
    /// A moving point known by a bound on its distance from a place
    /// (`from`, or exactly there when `exact`), and its derivative bounds.
    #[derive(Clone, Copy)]
    struct Loose {
        at: Vec3,
        slack: f64,
        speed: f64,
        curvature: f64,
    }
    let turned = |p: Loose, axis: &nalgebra::Unit<Vec3>, center: &Vec3, delta: f64| {
        let w = delta.to_radians().abs();
        let rel = p.at - center;
        let k = axis.as_ref();
        let rho = (rel - k * k.dot(&rel)).norm() + p.slack + p.speed;
        Loose {
            // The turned point is within |q − c| of the centre.
            at: *center,
            slack: rel.norm() + p.slack,
            speed: w * rho + p.speed,
            curvature: w * w * rho + 2.0 * w * p.speed + p.curvature,
        }
    };
    let t0 = machine.tool_direction.into_inner();
    let mut end = match machine.quill_index() {
        Some(i) => Loose {
            at: (seg.start[i] - seg.tool_length) * t0,
            slack: 0.0,
            speed: (seg.end[i] - seg.start[i]).abs(),
            curvature: 0.0,
        },
        None => Loose {
            at: -seg.tool_length * t0,
            slack: 0.0,
            speed: 0.0,
            curvature: 0.0,
        },
    };
    for (k, axis) in machine.rotary.iter().enumerate().rev() {
        if axis.on == Side::Head {
            let (_, d) = turn(machine, seg, k);
            end = turned(end, &axis.axis, &axis.center, d);
        }
    }
    let a = Vec3::new(seg.start[0], seg.start[1], seg.start[2]);
    let b = Vec3::new(seg.end[0], seg.end[1], seg.end[2]);
    let mut tip = Loose {
        at: a + end.at,
        slack: end.slack,
        speed: (b - a).norm() + end.speed,
        curvature: end.curvature,
    };
    for (k, axis) in machine.rotary.iter().enumerate() {
        if axis.on == Side::Table {
            let (_, d) = turn(machine, seg, k);
            tip = turned(tip, &axis.axis, &axis.center, d);
        }
    }
    Some(tip.curvature)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fiveaxis_control::{RunOptions, Runner, SliceSource};
    use fiveaxis_machine::{Offsets, builtin};
    use proptest::prelude::*;
    use proptest::test_runner::{Config, RngSeed, TestRunner};

    /// Steps of the finite differences over a block.
    const FD_STEPS: f64 = 2000.0;

    /// The largest first, second and third finite differences of a
    /// moving point over the block, per unit `s`.
    fn measured(point: impl Fn(f64) -> Vec3) -> [f64; 3] {
        let n = FD_STEPS as u32;
        let h = 1.0 / FD_STEPS;
        let p: Vec<Vec3> = (0..=n).map(|k| point(f64::from(k) * h)).collect();
        let mut worst = [0.0_f64; 3];
        for k in 0..p.len() - 3 {
            let d1 = (p[k + 1] - p[k]).norm() / h;
            let d2 = (p[k + 2] - 2.0 * p[k + 1] + p[k]).norm() / (h * h);
            let d3 = (p[k + 3] - 3.0 * p[k + 2] + 3.0 * p[k + 1] - p[k]).norm() / (h * h * h);
            worst = [worst[0].max(d1), worst[1].max(d2), worst[2].max(d3)];
        }
        worst
    }

    /// Random feed moves turning both rotary axes, straight or on a
    /// circle in the XY plane, on each five-axis built-in machine, with
    /// TCPC (`G43.4`) or without: the speed, curvature and jerk of the
    /// tip (without TCPC) or of X, Y, Z (with it) stay within the law's
    /// bounds (the bounds the chord proofs and the axis extremes rest
    /// on).
    #[test]
    fn tip_laws_bound_the_first_three_derivatives_of_the_tip() {
        let machines = [
            "trunnion-ac",
            "trunnion-bc",
            "head-table-bc",
            "head-head-ca",
        ];
        let block = (
            -50.0..50.0f64,
            -50.0..50.0f64,
            -120.0..120.0f64,
            -120.0..120.0f64,
            any::<bool>(),
        );
        let strategy = (
            0..machines.len(),
            any::<bool>(),
            proptest::collection::vec(block, 1..4),
        );
        let config = Config {
            cases: 32,
            rng_seed: RngSeed::Fixed(0x1A3B_0DE5),
            failure_persistence: None,
            ..Config::default()
        };
        let offsets = Offsets::from_toml("[tools]\n1 = { length = 120.0 }\n").expect("offsets");
        let mut runner = TestRunner::new(config);
        let result = runner.run(&strategy, |(m, tcpc, blocks)| {
            let machine = builtin(machines[m]).expect("built in");
            let names: Vec<char> = machine.rotary.iter().map(|r| r.name).collect();
            let length = if tcpc { "G43.4" } else { "G43" };
            let mut text = format!("G21 G90 G94 G17 {length} H1\n");
            for (x, y, a, b, arc) in blocks {
                let motion = if arc { "G2 R80." } else { "G1" };
                text.push_str(&format!(
                    "{motion} X{x:.3} Y{y:.3} Z20. {}{a:.3} {}{b:.3} F1000.\n",
                    names[0], names[1]
                ));
            }
            text.push_str("M30\n");
            let options = RunOptions {
                lift_soft_limits: true,
                ..RunOptions::default()
            };
            let mut run = Runner::new(
                &machine,
                offsets.clone(),
                SliceSource::new(text.as_bytes()),
                options,
            );
            while let Ok(Some(seg)) = run.next_segment() {
                let (law, [speed, curvature, jerk]) = if let Some(law) = tcpc_law(&machine, &seg) {
                    let gauge = |s: f64| {
                        let j = seg.eval(&machine, s);
                        Vec3::new(j[0], j[1], j[2])
                    };
                    (law, measured(gauge))
                } else if let Some(law) = machine_tip(&machine, &seg) {
                    if let Some(loose) = joint_tip_curvature(&machine, &seg) {
                        prop_assert!(
                            loose >= law.curvature * (1.0 - 1e-12),
                            "loose {loose} < {}",
                            law.curvature
                        );
                    }
                    let tip = |s: f64| machine.forward(&seg.eval(&machine, s), seg.tool_length).tip;
                    (law, measured(tip))
                } else {
                    continue;
                };
                // Rounding of tips some hundred millimetres from the
                // origin, divided by the step to the power of the
                // difference's order.
                let rounding = |order: i32| 1e-12 * FD_STEPS.powi(order);
                prop_assert!(
                    speed <= law.speed + rounding(1),
                    "speed {speed} > {}",
                    law.speed
                );
                prop_assert!(
                    curvature <= law.curvature + rounding(2),
                    "curvature {curvature} > {}",
                    law.curvature
                );
                prop_assert!(jerk <= law.jerk + rounding(3), "jerk {jerk} > {}", law.jerk);
            }
            Ok(())
        });
        if let Err(e) = result {
            panic!("{e}");
        }
    }
}
