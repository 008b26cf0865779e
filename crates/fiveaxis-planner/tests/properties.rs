//! Properties of the planned motion over random programs (fixed seed):
//! no axis ever goes faster, accelerates harder or (where jerk is
//! modelled: along the path, outside the corner blends) jerks harder than
//! its limit; the path speed never exceeds the feed; exact stops and rapids
//! end at zero speed; the time is never below the programmed time.
//!
//! The checks do not use the planner's internals. The planned motion is
//! the traced pieces of constant jerk, s(t); the test maps s to machine
//! positions itself: the polyline of the samples, each joint rounded by the
//! parabolic blend the crate documents (axis velocities changing linearly
//! in s over `b = min(L_before, L_after, 8·δ/max|Δu|)`; none at a stop),
//! and differentiates the positions in time by finite differences. A
//! central difference of order k is a weighted mean of the k-th derivative
//! over its window, so it never exceeds a bound the derivative keeps:
//! only rounding needs a tolerance.

#![allow(clippy::needless_range_loop)] // axis i of several position vectors

use fiveaxis_planner::{AxisLimits, Block, Feed, Options, Piece, Planner, Point};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestCaseError, TestRunner};

/// Relative slack on every limit.
const REL: f64 = 1e-6;
/// Time samples per plan (fewer when the plan is shorter than
/// `SAMPLES · MIN_STEP`).
const SAMPLES: f64 = 4000.0;
/// Smallest time step of the finite differences, s (rounding grows as
/// step^-k).
const MIN_STEP: f64 = 2e-4;
/// Rounding of a position, relative to the largest coordinate.
const ROUNDING: f64 = 1e-12;

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x9A7E_11AB),
        failure_persistence: None,
        ..Config::default()
    }
}

#[derive(Clone, Debug)]
struct Case {
    axes: Vec<AxisLimits>,
    tolerance: f64,
    lookahead: usize,
    blocks: Vec<(Feed, bool, Vec<Vec<f64>>, f64)>,
}

fn limits(jerk: bool) -> impl Strategy<Value = AxisLimits> {
    (
        600.0..30_000.0f64,
        1.0..2.0f64,
        100.0..5000.0f64,
        1000.0..100_000.0f64,
    )
        .prop_map(move |(v, r, a, j)| AxisLimits {
            max_velocity: v,
            rapid: v * r,
            max_acceleration: a,
            max_jerk: jerk.then_some(j),
        })
}

fn feed() -> impl Strategy<Value = Feed> {
    prop_oneof![
        4 => (60.0..20_000.0f64).prop_map(Feed::PerMinute),
        1 => (0.5..100.0f64).prop_map(Feed::InverseTime),
        1 => Just(Feed::Rapid),
    ]
}

fn case() -> impl Strategy<Value = Case> {
    (2..=5usize, any::<bool>()).prop_flat_map(|(n, jerk)| {
        let step = prop::collection::vec(prop_oneof![3 => -20.0..20.0f64, 1 => -0.5..0.5f64], n);
        let block = (
            feed(),
            prop::bool::weighted(0.3),
            prop::collection::vec(step, 1..6),
            0.5..2.0f64,
        );
        (
            prop::collection::vec(limits(jerk), n),
            prop_oneof![Just(0.0), 0.001..0.2f64],
            prop_oneof![Just(2usize), 3..40usize, Just(1024usize)],
            prop::collection::vec(block, 1..8),
        )
            .prop_map(|(axes, tolerance, lookahead, blocks)| Case {
                axes,
                tolerance,
                lookahead,
                blocks,
            })
    })
}

/// One interval of the path as the test sees it.
#[derive(Clone, Debug)]
struct Interval {
    q0: Vec<f64>,
    u: Vec<f64>,
    s0: f64,
    len: f64,
    /// Path speed cap from the feed, mm/s (infinite for a rapid).
    feed: f64,
    rapid: bool,
    /// Blend lengths of the joints at the start and at the end (0: stop).
    front: f64,
    back: f64,
}

struct Path {
    iv: Vec<Interval>,
    /// Path parameters where the speed must be zero.
    stops: Vec<f64>,
    programmed: f64,
}

fn path(case: &Case) -> Path {
    let n = case.axes.len();
    let mut q = vec![0.0; n];
    let mut iv: Vec<Interval> = Vec::new();
    let mut stop_after: Vec<bool> = Vec::new();
    let mut s = 0.0;
    let mut programmed = 0.0;
    for (feed, exact, steps, factor) in &case.blocks {
        let lens: Vec<f64> = steps
            .iter()
            .map(|d| d.iter().map(|x| x * x).sum::<f64>().sqrt() * factor)
            .collect();
        let total: f64 = lens.iter().sum();
        let rapid = matches!(feed, Feed::Rapid);
        let cap = match *feed {
            Feed::PerMinute(f) => f / 60.0,
            Feed::InverseTime(f) => total * f / 60.0,
            Feed::Rapid => f64::INFINITY,
        };
        if let (true, Some(last)) = (rapid, stop_after.last_mut()) {
            *last = true;
        }
        for (d, &len) in steps.iter().zip(&lens) {
            let u: Vec<f64> = d.iter().map(|x| x / len).collect();
            programmed += if rapid {
                (0..n)
                    .map(|i| d[i].abs() / (case.axes[i].rapid / 60.0))
                    .fold(0.0, f64::max)
            } else {
                len / cap
            };
            iv.push(Interval {
                q0: q.clone(),
                u,
                s0: s,
                len,
                feed: cap,
                rapid,
                front: 0.0,
                back: 0.0,
            });
            stop_after.push(false);
            for i in 0..n {
                q[i] += d[i];
            }
            s += len;
        }
        if let (true, Some(last)) = (rapid || *exact, stop_after.last_mut()) {
            *last = true;
        }
    }
    let mut stops = vec![0.0, s];
    for k in 1..iv.len() {
        if stop_after[k - 1] {
            stops.push(iv[k].s0);
            continue;
        }
        let jump = (0..n)
            .map(|i| (iv[k].u[i] - iv[k - 1].u[i]).abs())
            .fold(0.0, f64::max);
        let b = iv[k - 1]
            .len
            .min(iv[k].len)
            .min(8.0 * case.tolerance / jump);
        if b <= 0.0 {
            stops.push(iv[k].s0);
        }
        iv[k - 1].back = b;
        iv[k].front = b;
    }
    Path {
        iv,
        stops,
        programmed,
    }
}

/// Machine positions at path parameter `s`: the polyline, rounded at each
/// joint by the parabolic blend.
fn position(path: &Path, s: f64, out: &mut [f64]) {
    let k = path.iv.partition_point(|iv| iv.s0 <= s).saturating_sub(1);
    let iv = &path.iv[k];
    let ds = s - iv.s0;
    for (i, o) in out.iter_mut().enumerate() {
        *o = iv.q0[i] + iv.u[i] * ds;
    }
    let mut blend = |b: f64, from_joint: f64, du: &dyn Fn(usize) -> f64| {
        if b > 0.0 && from_joint < b / 2.0 {
            let w = (b / 2.0 - from_joint).powi(2) / (2.0 * b);
            for (i, o) in out.iter_mut().enumerate() {
                *o += du(i) * w;
            }
        }
    };
    if k > 0 {
        let prev = &path.iv[k - 1];
        blend(iv.front, ds.max(0.0), &|i| iv.u[i] - prev.u[i]);
    }
    if k + 1 < path.iv.len() {
        let next = &path.iv[k + 1];
        blend(iv.back, (iv.len - ds).max(0.0), &|i| next.u[i] - iv.u[i]);
    }
}

/// Path parameter at time `t` from the traced pieces.
fn parameter(trace: &[Piece], t: f64) -> f64 {
    let k = trace.partition_point(|p| p.t <= t).saturating_sub(1);
    let p = &trace[k];
    let tau = (t - p.t).clamp(0.0, p.duration);
    p.s + p.v * tau + p.a * tau * tau / 2.0 + p.j * tau.powi(3) / 6.0
}

/// Intervals whose span (widened by one on each side, for blends) meets
/// `[lo, hi]`.
fn touched(path: &Path, lo: f64, hi: f64) -> std::ops::Range<usize> {
    let a = path.iv.partition_point(|iv| iv.s0 + iv.len < lo);
    let b = path.iv.partition_point(|iv| iv.s0 <= hi);
    a.saturating_sub(1)..(b + 1).min(path.iv.len())
}

fn plan(case: &Case) -> (f64, Vec<Piece>) {
    let n = case.axes.len();
    let options = Options {
        junction_tolerance: case.tolerance,
        lookahead: case.lookahead,
    };
    let mut planner = Planner::new(&case.axes, options, &vec![0.0; n]).expect("valid limits");
    let mut trace = Vec::new();
    let mut q = vec![0.0; n];
    for (feed, exact, steps, factor) in &case.blocks {
        let points: Vec<Point> = steps
            .iter()
            .map(|d| {
                for i in 0..n {
                    q[i] += d[i];
                }
                let len = d.iter().map(|x| x * x).sum::<f64>().sqrt() * factor;
                Point::new(&q, len)
            })
            .collect();
        let block = Block {
            feed: *feed,
            exact_stop: *exact,
            points: &points,
        };
        planner
            .push_traced(&block, &mut trace)
            .expect("valid block");
    }
    (planner.finish_traced(&mut trace).time, trace)
}

fn check_case(case: Case) -> Result<(), TestCaseError> {
    let n = case.axes.len();
    let path = path(&case);
    let (time, trace) = plan(&case);
    let length: f64 = path.iv.iter().map(|iv| iv.len).sum();

    // The pieces join: position, speed and acceleration are continuous.
    for w in trace.windows(2) {
        let (p, q) = (w[0], w[1]);
        let tau = p.duration;
        let s = p.s + p.v * tau + p.a * tau * tau / 2.0 + p.j * tau.powi(3) / 6.0;
        let v = p.v + p.a * tau + p.j * tau * tau / 2.0;
        let a = p.a + p.j * tau;
        prop_assert!((p.t + tau - q.t).abs() <= 1e-9 * (1.0 + q.t));
        prop_assert!(
            (s - q.s).abs() <= 1e-9 * (1.0 + length),
            "s {s} then {}",
            q.s
        );
        prop_assert!(
            (v - q.v).abs() <= 1e-6 * (1.0 + v.abs()),
            "v {v} then {}",
            q.v
        );
        if case.axes[0].max_jerk.is_some() {
            prop_assert!(
                (a - q.a).abs() <= 1e-6 * (1.0 + a.abs()),
                "a {a} then {}",
                q.a
            );
        }
    }
    let last = trace.last().expect("a plan of a moving program has pieces");
    prop_assert!((last.t + last.duration - time).abs() <= 1e-9 * time);

    // Never faster than programmed, nor than the axes allow.
    prop_assert!(
        time >= path.programmed * (1.0 - REL),
        "{time} < {}",
        path.programmed
    );

    // Zero speed at every stop.
    for &s in &path.stops {
        let v = trace
            .iter()
            .filter(|p| (p.s - s).abs() <= 1e-6 * (1.0 + s))
            .map(|p| p.v.abs())
            .fold(f64::INFINITY, f64::min);
        let end = s >= length - 1e-9 * length;
        prop_assert!(end || v <= 1e-9, "speed {v} at the stop at s = {s}");
    }

    // Finite differences of the motion.
    let h = (time / SAMPLES).max(MIN_STEP);
    let count = (time / h).floor() as usize;
    let mut s = Vec::with_capacity(count + 1);
    let mut q = vec![vec![0.0; n]; count + 1];
    for (k, qk) in q.iter_mut().enumerate() {
        let sk = parameter(&trace, k as f64 * h);
        position(&path, sk, qk);
        s.push(sk);
    }
    let scale = q.iter().flatten().fold(1.0f64, |m, x| m.max(x.abs())) + length;
    let err = ROUNDING * scale;
    for k in 1..count {
        let range = touched(&path, s[k - 1], s[k + 1]);
        let feed = path.iv[range.clone()]
            .iter()
            .map(|iv| iv.feed)
            .fold(0.0, f64::max);
        let speed = (s[k + 1] - s[k - 1]) / (2.0 * h);
        prop_assert!(
            speed <= feed * (1.0 + REL) + 2.0 * err / h,
            "path speed {speed} above the feed {feed} at t = {}",
            k as f64 * h
        );
        for i in 0..n {
            let axis = &case.axes[i];
            let rapid = path.iv[range.clone()].iter().any(|iv| iv.rapid);
            let vmax = if rapid { axis.rapid } else { axis.max_velocity } / 60.0;
            let v = (q[k + 1][i] - q[k - 1][i]) / (2.0 * h);
            prop_assert!(
                v.abs() <= vmax * (1.0 + REL) + 2.0 * err / h,
                "axis {i} at {v} above {vmax} at t = {}",
                k as f64 * h
            );
            let a = (q[k + 1][i] - 2.0 * q[k][i] + q[k - 1][i]) / (h * h);
            prop_assert!(
                a.abs() <= axis.max_acceleration * (1.0 + REL) + 4.0 * err / (h * h),
                "axis {i} accelerates at {a} above {} at t = {}",
                axis.max_acceleration,
                k as f64 * h
            );
        }
        // Jerk along the path: where the window lies on one straight part.
        if k + 2 <= count && case.axes[0].max_jerk.is_some() {
            let (lo, hi) = (s[k - 1], s[k + 2]);
            let straight = path
                .iv
                .iter()
                .any(|iv| lo >= iv.s0 + iv.front / 2.0 && hi <= iv.s0 + iv.len - iv.back / 2.0);
            if straight {
                for i in 0..n {
                    let limit = case.axes[i].max_jerk.unwrap_or(f64::INFINITY);
                    let j = (q[k + 2][i] - 3.0 * q[k + 1][i] + 3.0 * q[k][i] - q[k - 1][i])
                        / (h * h * h);
                    prop_assert!(
                        j.abs() <= limit * (1.0 + REL) + 8.0 * err / (h * h * h),
                        "axis {i} jerks at {j} above {limit} at t = {}",
                        k as f64 * h
                    );
                }
            }
        }
    }
    Ok(())
}

#[test]
fn the_planned_motion_keeps_every_limit() {
    let mut runner = TestRunner::new(config(256));
    if let Err(e) = runner.run(&case(), check_case) {
        panic!("{e}");
    }
}

/// Marks after every block: each mark's time is when the traced motion
/// reaches the block's end (the summed lengths of its samples), the times
/// do not depend on tracing, never decrease, and the last is the total.
fn check_marks(case: Case) -> Result<(), TestCaseError> {
    let n = case.axes.len();
    let (time, trace) = plan(&case);
    let options = Options {
        junction_tolerance: case.tolerance,
        lookahead: case.lookahead,
    };
    let mut planner = Planner::new(&case.axes, options, &vec![0.0; n]).expect("valid limits");
    let mut q = vec![0.0; n];
    let mut ends = Vec::new();
    let mut s = 0.0;
    let mut times = Vec::new();
    for (feed, exact, steps, factor) in &case.blocks {
        let points: Vec<Point> = steps
            .iter()
            .map(|d| {
                for i in 0..n {
                    q[i] += d[i];
                }
                let len = d.iter().map(|x| x * x).sum::<f64>().sqrt() * factor;
                s += len;
                Point::new(&q, len)
            })
            .collect();
        let block = Block {
            feed: *feed,
            exact_stop: *exact,
            points: &points,
        };
        planner.push(&block).expect("valid block");
        planner.mark();
        ends.push(s);
        // Taken as they come, as a streaming caller does.
        planner.take_mark_times(|t| times.push(t));
    }
    let summary = planner.finish_marked(|t| times.push(t));
    prop_assert_eq!(times.len(), ends.len());
    prop_assert!(
        (summary.time - time).abs() <= 1e-12 * time,
        "{} {time}",
        summary.time
    );
    prop_assert!(
        (times[times.len() - 1] - time).abs() <= 1e-9 * time,
        "last mark {} of {time}",
        times[times.len() - 1]
    );
    for (k, (&t, &end)) in times.iter().zip(&ends).enumerate() {
        prop_assert!(
            k == 0 || t >= times[k - 1],
            "mark {k} at {t} before the one before"
        );
        let reached = parameter(&trace, t);
        prop_assert!(
            (reached - end).abs() <= 1e-7 * (1.0 + s),
            "mark {k}: at {t} s the motion is at {reached}, the block ends at {end}"
        );
    }
    Ok(())
}

#[test]
fn marks_give_the_time_of_each_block_end() {
    let mut runner = TestRunner::new(config(256));
    if let Err(e) = runner.run(&case(), check_marks) {
        panic!("{e}");
    }
}
