//! How far each axis goes inside a segment: the exact extremes.

use std::f64::consts::{PI, TAU};

use fiveaxis_control::{Path, Segment};
use fiveaxis_machine::Machine;

use crate::bound::{self, Moving};
use crate::{POSTURE_SAMPLE_ANGLE, law};

/// The largest value of `sign · position` of axis `i` (`sign` ±1) over the
/// segment, if it is above `floor`; `None` proves that it is not (to
/// within [`bound::EXTREMUM_TOLERANCE`]).
///
/// Joint moves and reference returns: the ends (and the intermediate
/// point). Circles of constant radius without drift: the closed form of
/// the circle's extremes. TCPC blocks without tool posture control and
/// every other circle: bound and refine on the axis' second derivative
/// ([`law::tcpc_gauge`]). Tool posture control: sampled every
/// [`POSTURE_SAMPLE_ANGLE`] of rotary motion and refined. `law` is the
/// block's [`law::tcpc_law`].
pub fn axis_max(
    machine: &Machine,
    seg: &Segment,
    i: usize,
    sign: f64,
    floor: f64,
    law: Option<&Moving>,
) -> Option<f64> {
    let ends = [sign * seg.start[i], sign * seg.end[i]];
    let mut best = ends[0].max(ends[1]);
    let linear = i < machine.linear.len();
    match &seg.path {
        Path::Joint => {}
        Path::Via(mid) => best = best.max(sign * mid[i]),
        Path::Arc(arc) if arc.axes.contains(&i) => {
            let k = usize::from(arc.axes[1] == i);
            if arc.drift == [0.0, 0.0] && arc.r0 == arc.r1 {
                let centre = seg.start[i] - arc.r0 * trig(k, arc.theta0);
                let peak = circle_peak(arc.theta0, arc.sweep, k, sign);
                if let Some(p) = peak {
                    best = best.max(sign * centre + arc.r0.abs() * p);
                }
            } else {
                // A coordinate of r(s)·(cos θ, sin θ) with r and θ linear
                // in s: the derivative bounds of `Moving::tip_path`.
                let r = arc.r0.abs().max(arc.r1.abs());
                let dr = (arc.r1 - arc.r0).abs();
                let w = arc.sweep.abs();
                let curvature = 2.0 * dr * w + r * w * w;
                let jerk = 3.0 * dr * w * w + r * w * w * w;
                return refine(machine, seg, i, sign, floor, [curvature, jerk]);
            }
        }
        Path::Arc(_) => {}
        Path::Helix { circle, drift } if i < 3 => {
            if let fiveaxis_control::TipPath::Arc { radius, .. } = circle
                && radius[0] == radius[1]
                && drift[i] == 0.0
            {
                let (lo, hi) = circle.extent(i);
                best = best.max(if sign > 0.0 { hi } else { -lo });
            } else {
                let m = Moving::tip_path(circle);
                return refine(machine, seg, i, sign, floor, [m.curvature, m.jerk]);
            }
        }
        Path::Helix { .. } => {}
        Path::Tcpc(tcpc) if tcpc.posture.is_some() => {
            let turn = (machine.linear.len()..machine.axis_count())
                .map(|k| (seg.end[k] - seg.start[k]).abs())
                .fold(0.0, f64::max);
            let n = (turn / POSTURE_SAMPLE_ANGLE).ceil().clamp(16.0, 4096.0) as u32;
            let (_, v) = bound::sampled_max(|s| sign * seg.eval(machine, s)[i], n);
            best = best.max(v);
        }
        Path::Tcpc(tcpc) if linear && i < 3 => {
            let law = law
                .copied()
                .unwrap_or_else(|| law::tcpc_gauge(machine, seg, tcpc));
            return refine(machine, seg, i, sign, floor, [law.curvature, law.jerk]);
        }
        Path::Tcpc(_) => {}
    }
    (best > floor).then_some(best)
}

/// Bound and refine on `sign · position` of axis `i`, with `|f''|` and
/// `|f'''|` at most `curvature` and `jerk`.
fn refine(
    machine: &Machine,
    seg: &Segment,
    i: usize,
    sign: f64,
    floor: f64,
    [curvature, jerk]: [f64; 2],
) -> Option<f64> {
    let ends = [sign * seg.start[i], sign * seg.end[i]];
    bound::maximize(
        |s| sign * seg.eval(machine, s)[i],
        curvature,
        jerk,
        floor,
        ends,
    )
    .map(|(_, v)| v)
}

/// cos (k = 0) or sin (k = 1) of `theta`.
fn trig(k: usize, theta: f64) -> f64 {
    if k == 0 { theta.cos() } else { theta.sin() }
}

/// The largest value of `sign · cos θ` (k = 0) or `sign · sin θ` (k = 1)
/// for θ on the sweep from `theta0`, if it is reached inside the sweep at
/// a peak (1); the ends are the caller's.
fn circle_peak(theta0: f64, sweep: f64, k: usize, sign: f64) -> Option<f64> {
    // Where sign·cos or sign·sin is 1.
    let peak = match (k, sign > 0.0) {
        (0, true) => 0.0,
        (0, false) => PI,
        (_, true) => 0.5 * PI,
        (_, false) => 1.5 * PI,
    };
    let (from, to) = if sweep >= 0.0 {
        (theta0, theta0 + sweep)
    } else {
        (theta0 + sweep, theta0)
    };
    let t = peak + ((from - peak) / TAU).ceil() * TAU;
    (t <= to).then_some(1.0)
}
