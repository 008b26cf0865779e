//! Time and speed of a block: the programmed time, the axis speeds the
//! programmed feed needs, and how far each rotary axis turns.

use fiveaxis_control::{Motion, Path, Segment};
use fiveaxis_machine::{Joints, Machine, Vec3};

use crate::{bound, law};

/// A tip path shorter than this, mm, counts as no tip motion (a block
/// that turns rotary axes about the tip).
const NO_TIP_MOTION: f64 = 1e-9;

/// The tool tip at the two ends of a segment ([`Machine::forward_tip`]): what
/// the checks that measure the straight line between them share, computed
/// once a segment.
pub fn end_tips(machine: &Machine, seg: &Segment) -> [Vec3; 2] {
    [
        machine.forward_tip(&seg.start, seg.tool_length),
        machine.forward_tip(&seg.end, seg.tool_length),
    ]
}

/// [`end_tips`] where the feed length needs them (machine-axis lines),
/// else zeros.
fn straight_tips(machine: &Machine, seg: &Segment) -> [Vec3; 2] {
    match &seg.path {
        Path::Joint | Path::Via(_) => end_tips(machine, seg),
        _ => [Vec3::zeros(); 2],
    }
}

/// The path length the feed of a cutting segment applies to, as the
/// controller measures it for inverse-time feed: the tip path of TCPC and
/// of circles, the straight line between the tip's ends for machine-axis
/// lines.
/// `tips`: the segment's [`end_tips`].
pub fn feed_length_at(seg: &Segment, tips: &[Vec3; 2]) -> f64 {
    match &seg.path {
        Path::Tcpc(t) => t.tip.length(),
        Path::Helix { circle, .. } => circle.length(),
        Path::Arc(arc) => {
            let normal: f64 = (0..3)
                .filter(|i| !arc.axes.contains(i))
                .map(|i| (seg.end[i] - seg.start[i]).powi(2))
                .sum();
            arc.length().hypot(normal.sqrt())
        }
        Path::Joint | Path::Via(_) => (tips[1] - tips[0]).norm(),
    }
}

/// How far rotary axis `k` turns in the segment, degrees (both legs of a
/// reference return; under tool posture control, along its knots).
pub fn rotary_travel(machine: &Machine, seg: &Segment, k: usize) -> f64 {
    let i = machine.rotary_index(k);
    match &seg.path {
        Path::Via(mid) => (mid[i] - seg.start[i]).abs() + (seg.end[i] - mid[i]).abs(),
        Path::Tcpc(t) if t.posture.is_some() => t.posture.as_deref().map_or(0.0, |p| {
            let mut total = 0.0;
            let mut previous = p.start[k];
            for (_, angles) in &p.knots[1..] {
                let a = f64::from(angles[k]);
                total += (a - previous).abs();
                previous = a;
            }
            total + (seg.end[i] - previous).abs()
        }),
        _ => (seg.end[i] - seg.start[i]).abs(),
    }
}

/// The programmed time of a segment, minutes: a cutting move takes its
/// feed length over its feed (inverse-time feed G93 comes as a tip feed
/// that makes this 1/F); one that moves only rotary axes about the tip
/// takes its largest rotary turn over F, F in degrees per minute (FANUC:
/// the feed of a block of rotary axes alone is in deg/min). A rapid move
/// takes the longest of each axis' travel over its rapid rate (linear
/// interpolation of positioning, FANUC No.1401#1 LRP = 1).
pub fn block_minutes(machine: &Machine, seg: &Segment) -> f64 {
    let tips = match (seg.motion, seg.feed) {
        (Motion::Rapid, _) | (_, None) => [Vec3::zeros(); 2],
        _ => straight_tips(machine, seg),
    };
    block_minutes_at(machine, seg, &tips)
}

/// [`block_minutes`] with the segment's [`end_tips`] known.
pub fn block_minutes_at(machine: &Machine, seg: &Segment, tips: &[Vec3; 2]) -> f64 {
    let rapid_minutes = |seg: &Segment| {
        (0..machine.axis_count())
            .map(|i| {
                let travel = match &seg.path {
                    Path::Via(mid) => (mid[i] - seg.start[i]).abs() + (seg.end[i] - mid[i]).abs(),
                    _ => (seg.end[i] - seg.start[i]).abs(),
                };
                travel / machine.dynamics(i).rapid
            })
            .fold(0.0, f64::max)
    };
    match (seg.motion, seg.feed) {
        (Motion::Rapid, _) | (_, None) => rapid_minutes(seg),
        (_, Some(feed)) => {
            let length = feed_length_at(seg, tips);
            if length > NO_TIP_MOTION && feed > 0.0 {
                length / feed
            } else {
                let turn = (0..machine.rotary.len())
                    .map(|k| rotary_travel(machine, seg, k))
                    .fold(0.0, f64::max);
                if feed > 0.0 {
                    turn / feed
                } else {
                    rapid_minutes(seg)
                }
            }
        }
    }
}

/// The largest speed of axis `i` per unit `s` over the segment: exact for
/// lines and circles; for TCPC blocks the derivative bound when it clears
/// the axis (`budget`: the most the axis may move per unit `s`), else the
/// largest mean speed over 1/N of the block, sampled and refined.
fn axis_rate(
    machine: &Machine,
    seg: &Segment,
    i: usize,
    budget: f64,
    law: Option<&crate::bound::Moving>,
    grid: &mut Option<RateGrid>,
) -> f64 {
    let travel = (seg.end[i] - seg.start[i]).abs();
    match &seg.path {
        Path::Joint | Path::Via(_) => travel,
        Path::Arc(arc) => {
            let Some(k) = arc.axes.iter().position(|&a| a == i) else {
                return travel;
            };
            let r = arc.r0.abs().max(arc.r1.abs());
            // d/ds of r·cos θ (or sin θ): r·sweep·(−sin θ or cos θ), plus
            // the change of radius and the drift.
            let peak = peak_abs_trig(1 - k, arc.theta0, arc.sweep);
            r * arc.sweep.abs() * peak + (arc.r1 - arc.r0).abs() + arc.drift[k].abs()
        }
        Path::Helix { circle, drift } if i < 3 => match *circle {
            // Along coordinate i: r·sweep·(−sin θ·u_i + cos θ·v_i) + rise·n_i
            // (+ the change of radius), at most r·|sweep|·|(u_i, v_i)|.
            fiveaxis_control::TipPath::Arc {
                axes,
                radius,
                sweep,
                rise,
                ..
            } => {
                let r = radius[0].abs().max(radius[1].abs());
                r * sweep.abs() * axes[0][i].hypot(axes[1][i])
                    + (rise * axes[2][i]).abs()
                    + (radius[1] - radius[0]).abs()
                    + drift[i].abs()
            }
            fiveaxis_control::TipPath::Line([a, b]) => (b[i] - a[i]).abs() + drift[i].abs(),
        },
        Path::Helix { .. } => travel,
        Path::Tcpc(tcpc) if i < 3 && tcpc.posture.is_none() => {
            let speed = law.map_or_else(|| law::tcpc_gauge(machine, seg, tcpc).speed, |l| l.speed);
            if speed <= budget {
                speed
            } else {
                sampled_rate(machine, seg, i, grid)
            }
        }
        Path::Tcpc(tcpc) if tcpc.posture.is_none() => travel,
        Path::Tcpc(_) => sampled_rate(machine, seg, i, grid),
    }
}

/// Samples per TCPC block for its axis speeds, at least.
const RATE_SAMPLES: u32 = 64;

/// The machine positions of a block at `s = 0`, at the middles
/// `(2k − 1)/(2N)` between the [`RATE_SAMPLES`] `N` steps, and at
/// `s = 1`: the mean speed over the step around sample `k/N` is the
/// difference of entries `k + 1` and `k`, for every axis at once.
pub(crate) struct RateGrid([Joints; RATE_SAMPLES as usize + 2]);

impl RateGrid {
    fn new(machine: &Machine, seg: &Segment) -> Self {
        let h = 1.0 / f64::from(RATE_SAMPLES);
        let mut grid = [seg.start; RATE_SAMPLES as usize + 2];
        for (k, joints) in (0..=RATE_SAMPLES + 1).zip(grid.iter_mut()) {
            let s = match k {
                0 => 0.0,
                k if k > RATE_SAMPLES => 1.0,
                k => (f64::from(k) - 0.5) * h,
            };
            *joints = seg.eval(machine, s);
        }
        Self(grid)
    }
}

/// The largest mean speed of axis `i` between neighbouring samples, the
/// samples taken once a block (`grid`, filled on first use) for all its
/// axes.
fn sampled_rate(machine: &Machine, seg: &Segment, i: usize, grid: &mut Option<RateGrid>) -> f64 {
    let n = RATE_SAMPLES;
    let h = 1.0 / f64::from(n);
    let grid = &grid.get_or_insert_with(|| RateGrid::new(machine, seg)).0;
    let (s, _) = bound::sampled_max_from(
        |k| (grid[k as usize + 1][i] - grid[k as usize][i]).abs(),
        |s| {
            let a = seg.eval(machine, (s - 0.5 * h).max(0.0))[i];
            let b = seg.eval(machine, (s + 0.5 * h).min(1.0))[i];
            (b - a).abs()
        },
        n,
    );
    let step = 1e-4;
    let a = seg.eval(machine, (s - 0.5 * step).max(0.0))[i];
    let b = seg.eval(machine, (s + 0.5 * step).min(1.0))[i];
    ((b - a) / step).abs()
}

/// The largest |sin θ| (k = 0) or |cos θ| (k = 1) for θ on the sweep.
fn peak_abs_trig(k: usize, theta0: f64, sweep: f64) -> f64 {
    let f = |t: f64| if k == 0 { t.sin().abs() } else { t.cos().abs() };
    let (from, to) = (theta0.min(theta0 + sweep), theta0.max(theta0 + sweep));
    // |sin| peaks at π/2 + nπ, |cos| at nπ.
    let offset = if k == 0 {
        0.5 * std::f64::consts::PI
    } else {
        0.0
    };
    let pi = std::f64::consts::PI;
    let first = offset + ((from - offset) / pi).ceil() * pi;
    if first <= to { 1.0 } else { f(from).max(f(to)) }
}

/// The tip feed the axes allow for a cutting segment that takes
/// `minutes` at its programmed feed, and the axis that limits it, when
/// some axis would need more than its `max_velocity`: the programmed feed
/// scaled by the smallest ratio of allowed to needed axis speed.
pub fn tip_feed_allowed(machine: &Machine, seg: &Segment, minutes: f64) -> Option<(f64, usize)> {
    tip_feed_allowed_by(machine, seg, minutes, law::tcpc_law(machine, seg).as_ref())
}

/// [`tip_feed_allowed`] with the block's [`law::tcpc_law`] worked out.
pub(crate) fn tip_feed_allowed_by(
    machine: &Machine,
    seg: &Segment,
    minutes: f64,
    law: Option<&crate::bound::Moving>,
) -> Option<(f64, usize)> {
    let feed = seg.feed?;
    if minutes <= 0.0 {
        return None;
    }
    let speeds = (machine.linear.iter().map(|a| a.dynamics.max_velocity))
        .chain(machine.rotary.iter().map(|a| a.dynamics.max_velocity));
    // Joint moves, most blocks, move every axis by its travel
    // (`axis_rate`'s first case), read here without the call.
    let worst = if matches!(seg.path, Path::Joint | Path::Via(_)) {
        slowest(
            speeds
                .enumerate()
                .map(|(i, vmax)| (i, vmax * minutes, (seg.end[i] - seg.start[i]).abs())),
        )
    } else {
        let mut grid = None;
        slowest(speeds.enumerate().map(|(i, vmax)| {
            let budget = vmax * minutes;
            (
                i,
                budget,
                axis_rate(machine, seg, i, budget, law, &mut grid),
            )
        }))
    };
    worst.map(|(ratio, i)| (feed * ratio, i))
}

/// The smallest ratio of allowed to needed speed among axes given as
/// `(axis, budget, rate)` (travel allowed and needed over the block), and
/// its axis: `None` when every axis keeps within its budget.
fn slowest(rates: impl Iterator<Item = (usize, f64, f64)>) -> Option<(f64, usize)> {
    let mut worst: Option<(f64, usize)> = None;
    for (i, budget, rate) in rates {
        if rate > budget * (1.0 + FEED_SLACK) {
            let ratio = budget / rate;
            if worst.is_none_or(|(r, _)| ratio < r) {
                worst = Some((ratio, i));
            }
        }
    }
    worst
}

/// Relative margin before a needed axis speed counts as above the axis'
/// maximum (rounding).
const FEED_SLACK: f64 = 1e-9;
