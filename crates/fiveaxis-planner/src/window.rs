//! The look-ahead window: a bounded queue of stretches of path, planned by
//! the classic two passes (backward: every speed low enough to brake to a
//! stop at the window's end; forward: every speed reachable from the
//! committed speed at the window's start), its front half committed when
//! it is full.
//!
//! Committing is safe because the window's end is assumed to be a stop: a
//! speed the backward pass allowed can always be braked from, so later
//! blocks (which can only give the backward pass more room) never make a
//! committed speed infeasible. A window shorter than the braking distance
//! plans slower than a longer one would, as a control with a short block
//! buffer does.

use std::collections::VecDeque;

use crate::profile::{self, Dynamics, Piece};

/// How far before a stretch's end, relative to the path length so far, a
/// mark is at its end: the rounding of lengths summed in another order.
const MARK_ROUNDING: f64 = 1e-9;

/// A stretch of path with one speed cap and one set of dynamics: the
/// planner's unit. Consecutive pieces of path whose limits are alike are
/// merged into one stretch (with the smallest of their limits).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stretch {
    /// Length along the path, mm.
    pub len: f64,
    /// Speed cap, mm/s.
    pub cap: f64,
    pub dynamics: Dynamics,
    /// The speed must be zero where the stretch starts.
    pub stop_before: bool,
    /// The largest limits merged into the stretch (for the merge rule).
    cap_max: f64,
    acc_max: f64,
    jerk_max: f64,
    /// The backward pass's limit on the entry speed.
    entry_limit: f64,
}

impl Stretch {
    pub(crate) fn new(len: f64, cap: f64, dynamics: Dynamics, stop_before: bool) -> Self {
        Self {
            len,
            cap,
            dynamics,
            stop_before,
            cap_max: cap,
            acc_max: dynamics.acc,
            jerk_max: dynamics.jerk,
            entry_limit: 0.0,
        }
    }
}

/// How alike two limits are: the smaller over the larger (1 when both are
/// infinite, 0 when one is).
fn alike(min: f64, max: f64) -> f64 {
    if min == max {
        1.0
    } else if max.is_infinite() {
        0.0
    } else {
        min / max
    }
}

#[derive(Debug)]
pub(crate) struct Window {
    queue: VecDeque<Stretch>,
    capacity: usize,
    /// Limits within this ratio of each other are merged.
    merge_ratio: f64,
    /// Speed, path parameter and time where the window starts (the end of
    /// what has been committed).
    v: f64,
    s: f64,
    t: f64,
    /// Path parameters whose time is asked for (block ends), in order,
    /// not yet committed past.
    marks: VecDeque<f64>,
    /// The times of the marks committed past, in order, not yet taken.
    mark_times: Vec<f64>,
}

impl Window {
    pub(crate) fn new(capacity: usize, merge_ratio: f64) -> Self {
        Self {
            queue: VecDeque::with_capacity(capacity),
            capacity,
            merge_ratio,
            v: 0.0,
            s: 0.0,
            t: 0.0,
            marks: VecDeque::new(),
            mark_times: Vec::new(),
        }
    }

    /// Asks for the time at which the path parameter reaches `s` (at least
    /// every earlier mark's).
    pub(crate) fn mark(&mut self, s: f64) {
        self.marks.push_back(s);
    }

    /// Hands over the times of the marks committed past, in order.
    pub(crate) fn take_mark_times(&mut self, mut take: impl FnMut(f64)) {
        for t in self.mark_times.drain(..) {
            take(t);
        }
    }

    /// Time committed so far, s.
    pub(crate) fn time(&self) -> f64 {
        self.t
    }

    /// Path parameter committed so far, mm.
    pub(crate) fn length(&self) -> f64 {
        self.s
    }

    /// Appends a stretch (merged into the last one when they are alike),
    /// committing the front half of the window when it is full.
    pub(crate) fn push(&mut self, stretch: Stretch, trace: Option<&mut Vec<Piece>>) {
        if stretch.len <= 0.0 {
            return;
        }
        if !stretch.stop_before
            && let Some(last) = self.queue.back_mut()
        {
            let cap = last.cap.min(stretch.cap);
            let cap_max = last.cap_max.max(stretch.cap_max);
            let acc = last.dynamics.acc.min(stretch.dynamics.acc);
            let acc_max = last.acc_max.max(stretch.acc_max);
            let jerk = last.dynamics.jerk.min(stretch.dynamics.jerk);
            let jerk_max = last.jerk_max.max(stretch.jerk_max);
            if alike(cap, cap_max) >= self.merge_ratio
                && alike(acc, acc_max) >= self.merge_ratio
                && alike(jerk, jerk_max) >= self.merge_ratio
            {
                last.len += stretch.len;
                last.cap = cap;
                last.cap_max = cap_max;
                last.dynamics = Dynamics { acc, jerk };
                last.acc_max = acc_max;
                last.jerk_max = jerk_max;
                return;
            }
        }
        if self.queue.len() == self.capacity {
            self.commit(self.capacity / 2, trace);
        }
        self.queue.push_back(stretch);
    }

    /// Plans what is left with a stop at its end and commits all of it.
    pub(crate) fn flush(&mut self, trace: Option<&mut Vec<Piece>>) {
        self.commit(self.queue.len(), trace);
        // Marks past the end (rounding of the lengths): the end.
        let end = self.t;
        self.mark_times.extend(self.marks.drain(..).map(|_| end));
    }

    /// The two passes over the whole window, then the first `count`
    /// stretches committed: their time added, their pieces traced.
    fn commit(&mut self, count: usize, mut trace: Option<&mut Vec<Piece>>) {
        let n = self.queue.len();
        let mut exit = 0.0;
        for k in (0..n).rev() {
            let node = if k == 0 {
                f64::INFINITY
            } else if self.queue[k].stop_before {
                0.0
            } else {
                self.queue[k].cap.min(self.queue[k - 1].cap)
            };
            let st = &mut self.queue[k];
            st.entry_limit = node.min(profile::reach(exit, st.len, st.dynamics));
            exit = st.entry_limit;
        }
        for k in 0..count.min(n) {
            let st = self.queue[k];
            let exit_limit = if k + 1 < n {
                self.queue[k + 1].entry_limit
            } else {
                0.0
            };
            let v0 = self.v;
            let v1 = profile::reach(v0, st.len, st.dynamics)
                .min(exit_limit)
                .min(st.cap);
            let shape = profile::stretch(v0, v1, st.len, st.cap, st.dynamics);
            let end = self.s + st.len;
            while let Some(&m) = self.marks.front()
                && m <= end
            {
                self.marks.pop_front();
                // A mark at the stretch's end to the rounding of the summed
                // lengths is its end: near a stop the time at a length is
                // sensitive to the last digits of the length.
                let within = if end - m <= MARK_ROUNDING * end {
                    shape.time
                } else {
                    profile::time_at(v0, v1, shape, st.dynamics, m - self.s)
                };
                self.mark_times.push(self.t + within);
            }
            if let Some(out) = trace.as_deref_mut() {
                trace_stretch(v0, v1, self.t, self.s, &st, shape, out);
            }
            self.t += shape.time;
            self.s += st.len;
            self.v = v1;
        }
        self.queue.drain(..count.min(n));
    }
}

/// Appends the pieces of one committed stretch.
fn trace_stretch(
    v0: f64,
    v1: f64,
    t: f64,
    s: f64,
    st: &Stretch,
    shape: profile::Shape,
    out: &mut Vec<Piece>,
) {
    let (t, s) = profile::change_pieces(v0, shape.peak, st.dynamics, t, s, out);
    let (t, s) = if shape.cruise > 0.0 {
        let duration = shape.cruise / shape.peak;
        out.push(Piece {
            t,
            duration,
            s,
            v: shape.peak,
            a: 0.0,
            j: 0.0,
        });
        (t + duration, s + shape.cruise)
    } else {
        (t, s)
    };
    profile::change_pieces(shape.peak, v1, st.dynamics, t, s, out);
}
