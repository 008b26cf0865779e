//! LinuxCNC's splines in the XY plane (`control = "linuxcnc"`;
//! g-code.adoc, G5 and G5.1):
//!
//! * `G5 X Y I J P Q`: the cubic from the start to X Y whose control
//!   points are the start + (I, J) and the end + (P, Q) (a Bézier curve:
//!   the manual's "cubic B-spline" with these two control points); a G5
//!   without I, J continues the last one smoothly, as if I, J were its
//!   −P, −Q;
//! * `G5.1 X Y I J`: the quadratic whose control point is the start +
//!   (I, J).
//!
//! The kernel's paths are lines and circles, so a spline is followed by
//! chords whose distance from the curve stays within
//! [`SPLINE_TOLERANCE`]: for a polynomial curve `B(t)` cut into `n`
//! equal steps of t, a chord is within `max|B''|/(8 n²)` of its arc
//! (the interpolation error of a straight line), which fixes `n`.

use fiveaxis_machine::Joints;

use super::Controller;
use crate::alarm::{Alarm, Condition};
use crate::fanuc::SplineData;
use crate::modal::{Distance, Plane};
use crate::segment::{Motion, Segment};

/// Largest distance, mm, between a spline and the chords that follow it.
pub const SPLINE_TOLERANCE: f64 = 0.001;
/// Most chords one spline block makes.
const MAX_SPLINE_CHORDS: usize = 1 << 14;

impl Controller<'_> {
    /// A G5 (`cubic`) or G5.1 block.
    pub(super) fn spline(
        &mut self,
        cubic: bool,
        from: &Joints,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let name = if cubic { "G5" } else { "G5.1" };
        if self.state.modal.plane != Plane::Xy {
            return Err(self.alarm(
                Condition::WordNotUsed,
                None,
                format!("{name} draws in the XY plane: select G17"),
            ));
        }
        let rules = self.rules();
        let SplineData {
            i,
            j,
            end: control_end,
        } = self.fanuc.spline(name, cubic, &rules)?;
        let start = [from[0], from[1]];
        let targets = self.axis_words();
        let end = [
            end_coordinate(self.state.modal.distance, from[0], targets[0]),
            end_coordinate(self.state.modal.distance, from[1], targets[1]),
        ];
        let (points, len) = if cubic {
            let [p, q] = control_end.unwrap_or_default();
            let first = match (i, j, self.state.spline_tangent) {
                (Some(i), Some(j), _) => [i, j],
                (None, None, Some([p0, q0])) => [-p0, -q0],
                (None, None, None) => {
                    return Err(self.alarm(
                        Condition::CycleDataMissing,
                        None,
                        "the first G5 of a series needs I and J".into(),
                    ));
                }
                _ => {
                    return Err(self.alarm(
                        Condition::CycleDataMissing,
                        None,
                        "G5 takes both I and J or neither".into(),
                    ));
                }
            };
            self.state.spline_tangent = Some([p, q]);
            (
                [
                    start,
                    [start[0] + first[0], start[1] + first[1]],
                    [end[0] + p, end[1] + q],
                    end,
                ],
                4,
            )
        } else {
            let offset = [i.unwrap_or(0.0), j.unwrap_or(0.0)];
            if offset == [0.0, 0.0] {
                return Err(self.alarm(
                    Condition::CycleDataMissing,
                    None,
                    "G5.1 needs I or J, the control point's offset".into(),
                ));
            }
            (
                [
                    start,
                    [start[0] + offset[0], start[1] + offset[1]],
                    end,
                    end,
                ],
                3,
            )
        };
        let control = &points[..len];
        // max |B''| over t: the largest second difference, times
        // degree·(degree − 1).
        let degree = control.len() - 1;
        let second = control
            .windows(3)
            .map(|w| (w[0][0] - 2.0 * w[1][0] + w[2][0]).hypot(w[0][1] - 2.0 * w[1][1] + w[2][1]))
            .fold(0.0, f64::max)
            * (degree * (degree - 1)) as f64;
        let needed = (second / (8.0 * SPLINE_TOLERANCE)).sqrt().ceil();
        if needed.is_nan() || needed > MAX_SPLINE_CHORDS as f64 {
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                None,
                format!(
                    "{name}: the curve bends too sharply to follow within {SPLINE_TOLERANCE} mm in \
                     {MAX_SPLINE_CHORDS} chords (control points too far out)"
                ),
            ));
        }
        let chords = (needed as usize).max(1);
        let mut cur = self.state.joints;
        for k in 1..=chords {
            let t = k as f64 / chords as f64;
            let [x, y] = if k == chords { end } else { bezier(control, t) };
            let mut p = *from;
            p[0] = x;
            p[1] = y;
            let next = self.machine_position(&p);
            self.push_line(Motion::Linear, cur, next, out)?;
            cur = next;
        }
        Ok(())
    }
}

/// An end coordinate of the block: the word (absolute or incremental), or
/// where the program stands.
fn end_coordinate(distance: Distance, from: f64, word: Option<f64>) -> f64 {
    match (word, distance) {
        (Some(v), Distance::Absolute) => v,
        (Some(v), Distance::Incremental) => from + v,
        (None, _) => from,
    }
}

/// The Bézier curve of `control` at `t` (de Casteljau).
fn bezier(control: &[[f64; 2]], t: f64) -> [f64; 2] {
    let mut points = [[0.0; 2]; 4];
    let n = control.len();
    points[..n].copy_from_slice(control);
    for level in 1..n {
        for k in 0..n - level {
            let next = points[k + 1];
            for (v, w) in points[k].iter_mut().zip(next) {
                *v += t * (w - *v);
            }
        }
    }
    points[0]
}
