//! The motion laws of a segment as [`Moving`] points: the linear axes of
//! a TCPC block, and the tool tip of a machine-axis block, with bounds on
//! their derivatives in `s` for [`crate::bound::maximize`].

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
            }
        }
        Path::Helix { circle, drift } => {
            let c = Moving::tip_path(circle);
            Moving {
                at0: xyz(&seg.start),
                speed: c.speed + drift.norm(),
                curvature: c.curvature,
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
