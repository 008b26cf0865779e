//! The path as the planner sees it: intervals between samples (straight
//! lines in machine-axis space) with their limits, and the joints between
//! them (straight on, a stop, or a blend).
//!
//! **Intervals.** Between two samples the axes move in proportion,
//! `q(s) = q0 + u·(s − s0)` with `u = Δq / length`. At path speed `v` and
//! path acceleration `a`, axis `i` moves at `u_i·v` and accelerates at
//! `u_i·a`, so the interval's speed cap is `min(F, min_i vmax_i/|u_i|)`
//! and its path acceleration (jerk) limit `min_i amax_i/|u_i|`
//! (`jmax_i/|u_i|`).
//!
//! **Joints.** Where the direction `u` changes, each axis' velocity would
//! jump by `v·Δu_i`. The control rounds the joint instead: the axis
//! velocities change linearly in s over a blend of path length `b`
//! centred on the joint (a parabolic blend, the geometry LinuxCNC's
//! trajectory planner docs describe for `G64 P`, and the corner rounding of
//! FANUC's acceleration/deceleration before interpolation). Inside the blend
//! `d²q_i/ds² = Δu_i/b`, so axis `i` accelerates at
//! `v²·Δu_i/b + a·q'_i(s)` and leaves the sharp path by at most
//! `|Δu_i|·b/8` (mm, or degrees for a rotary axis). The blend is as long as
//! the junction tolerance `δ` allows and the neighbouring intervals hold
//! (each gives at most half of itself, so blends never overlap):
//!
//! `b = min(L_before, L_after, 8·δ / max_i |Δu_i|)`.
//!
//! Its speed cap gives the direction change at most [`BLEND_SHARE`] of each
//! axis' acceleration, `v² ≤ BLEND_SHARE·amax_i·b/|Δu_i|`, and its path
//! acceleration limit is what is left of each axis' acceleration at that
//! speed, `(amax_i − v²·|Δu_i|/b) / max(|u_i before|, |u_i after|)`. So the
//! sum of the direction change and the tangential acceleration stays
//! within every axis' limit (conservative: it is not shared out optimally).
//! On a finely sampled smooth curve `b` is the sample spacing and `Δu/b`
//! the curvature of the axis path, so the cap is the curvature limit
//! `v² ≤ BLEND_SHARE·amax_i / |q_i''(s)|` whatever the spacing (FANUC's
//! "feedrate clamp based on acceleration" of AI contour control); at a
//! sharp corner it is the velocity jump an axis can make within the
//! tolerance, `v·|Δu_i| ≤ √(8·BLEND_SHARE·amax_i·δ)` (the per-axis rule of
//! FANUC's automatic corner deceleration, parameter No.1783, with the
//! allowed difference taken from the acceleration and the tolerance).
//! The jerk of the direction change itself is not modelled (only jerk
//! along the path).

use crate::profile::Dynamics;
use crate::{Axis, MAX_AXES};

/// The share of each axis' acceleration a joint's direction change may
/// take; the rest is left for speeding up and slowing down through it.
pub const BLEND_SHARE: f64 = 0.5;

/// Directions closer than this (relative to the larger rate) are one line:
/// no joint, no blend (rounding of samples taken along one line).
const COLLINEAR: f64 = 1e-9;

/// One interval between samples.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Interval {
    /// Axis rates dq/ds (axis unit per mm of path).
    pub u: [f64; MAX_AXES],
    /// Length along the path, mm.
    pub len: f64,
    /// Speed cap from the feed and every axis' velocity, mm/s.
    pub cap: f64,
    pub dynamics: Dynamics,
    /// The speed is zero where the interval starts.
    pub stop_before: bool,
    /// The blend of the joint where the interval starts, if any.
    pub front: Option<Blend>,
}

/// The rounding of one joint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Blend {
    /// Path length of the blend, half on each side of the joint, mm.
    pub len: f64,
    pub cap: f64,
    pub dynamics: Dynamics,
}

/// What happens where one interval meets the next.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Joint {
    /// Same direction: nothing.
    Straight,
    /// The speed goes to zero (exact stop, rapid, zero tolerance).
    Stop,
    Blend(Blend),
}

/// The interval from `dq` over `len` mm with speed cap `feed` (mm/s,
/// infinite for a rapid), the axes at their cutting or rapid rates.
pub(crate) fn interval(axes: &[Axis], dq: &[f64], len: f64, feed: f64, rapid: bool) -> Interval {
    let mut u = [0.0; MAX_AXES];
    let mut cap = feed;
    let mut acc = f64::INFINITY;
    let mut jerk = f64::INFINITY;
    for (i, axis) in axes.iter().enumerate() {
        u[i] = dq[i] / len;
        let rate = u[i].abs();
        if rate > 0.0 {
            let vmax = if rapid { axis.rapid } else { axis.velocity };
            cap = cap.min(vmax / rate);
            acc = acc.min(axis.acceleration / rate);
            jerk = jerk.min(axis.jerk / rate);
        }
    }
    Interval {
        u,
        len,
        cap,
        dynamics: Dynamics { acc, jerk },
        stop_before: false,
        front: None,
    }
}

/// The joint between intervals `p` and `q` with junction tolerance
/// `tolerance`.
pub(crate) fn joint(axes: &[Axis], tolerance: f64, p: &Interval, q: &Interval) -> Joint {
    let n = axes.len();
    let mut jump = 0.0f64;
    let mut rate = 0.0f64;
    for i in 0..n {
        jump = jump.max((q.u[i] - p.u[i]).abs());
        rate = rate.max(p.u[i].abs()).max(q.u[i].abs());
    }
    if jump <= COLLINEAR * rate {
        return Joint::Straight;
    }
    let len = p.len.min(q.len).min(8.0 * tolerance / jump);
    if len <= 0.0 {
        return Joint::Stop;
    }
    // The square root once, of the smallest: it keeps order, so this is
    // the smallest root to the last bit.
    let mut squared = f64::INFINITY;
    for (i, axis) in axes.iter().enumerate() {
        let du = (q.u[i] - p.u[i]).abs();
        if du > 0.0 {
            squared = squared.min(BLEND_SHARE * axis.acceleration * len / du);
        }
    }
    let cap = p.cap.min(q.cap).min(squared.sqrt());
    let mut acc = f64::INFINITY;
    let mut jerk = f64::INFINITY;
    for (i, axis) in axes.iter().enumerate() {
        let w = p.u[i].abs().max(q.u[i].abs());
        if w > 0.0 {
            let du = (q.u[i] - p.u[i]).abs();
            let left = axis.acceleration - cap * cap * du / len;
            acc = acc.min(left.max(0.0) / w);
            jerk = jerk.min(axis.jerk / w);
        }
    }
    if cap <= 0.0 || acc <= 0.0 {
        return Joint::Stop;
    }
    Joint::Blend(Blend {
        len,
        cap,
        dynamics: Dynamics { acc, jerk },
    })
}
