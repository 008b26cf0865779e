//! Motion of group 01: straight lines and circles in programmed
//! coordinates turned into segments (the cutting feed, the circle's
//! centre from I J K or R, its sense and sweep), for the plain,
//! transformed and feature-frame cases alike.

use fiveaxis_gcode::Span;
use fiveaxis_machine::{Joints, SetupError, Vec3};

use super::{ARC_RADIUS_TOLERANCE, Controller, MAX_ARC_RADIUS, POSITION_TOLERANCE};
use crate::alarm::{Alarm, Condition};
use crate::fanuc::ArcCenter;
use crate::modal::{FeedMode, MotionMode};
use crate::segment::{Arc, Motion, Path, Segment, TipPath};

/// LinuxCNC's absolute arc radius tolerance under G21, mm, as `rs274` 2.9
/// applies it (0.02·√2 mm).
const LINUXCNC_ARC_ABSOLUTE_MM: f64 = 0.02 * std::f64::consts::SQRT_2;
/// The same under G20, inches (0.002·√2 in).
const LINUXCNC_ARC_ABSOLUTE_IN: f64 = 0.002 * std::f64::consts::SQRT_2;
/// How far LinuxCNC lets R fall short of half the chord of an R-format
/// arc, mm: 0.00005 in whatever the units (measured with `rs274` 2.9:
/// under G21 a shortfall of 0.00125 mm is taken and 0.00128 mm refused,
/// under G20 0.00005 in taken and 0.0001 in refused).
const LINUXCNC_R_TOLERANCE_MM: f64 = 0.00005 * MM_PER_INCH;
/// LinuxCNC's relative arc radius tolerance (0.1 % of the radius).
const LINUXCNC_ARC_RELATIVE: f64 = 0.001;
/// Millimetres in an inch.
const MM_PER_INCH: f64 = 25.4;

impl Controller<'_> {
    pub(super) fn segment(
        &self,
        motion: Motion,
        start: Joints,
        end: Joints,
        path: Path,
    ) -> Segment {
        // Tool posture control turns the axes on the great circle the
        // control works out.
        let posture = matches!(&path, Path::Tcpc(t) if t.posture.is_some());
        Segment {
            line: self.fanuc.line,
            motion,
            feed: None,
            start,
            end,
            path,
            tool_length: self.tool_length(),
            tool: self.physical_tool(),
            work: self.work(),
            setup: self.state.setup,
            exact_stop: self.block_exact_stop
                || self.state.modal.cutting == crate::modal::CuttingMode::ExactStop,
            inverse_time: self.state.modal.feed_mode == FeedMode::InverseTime,
            rotary_chosen: self.block_chose_rotary.get() || posture,
            rows: 1,
        }
    }

    /// The tool in the spindle; for a program that never changes tools,
    /// the tool of the last length offset it called (tool and offset
    /// numbers alike, the usual setup).
    pub(super) fn physical_tool(&self) -> u32 {
        if self.state.spindle_tool != 0 {
            self.state.spindle_tool
        } else {
            self.state.length_tool
        }
    }

    /// Keeps the H number just set as the tool of a program without tool
    /// changes ([`Controller::physical_tool`]).
    pub(super) fn note_length_tool(&mut self) {
        if self.state.h != 0 {
            self.state.length_tool = self.state.h;
        }
    }

    /// The feed at the tool tip for a cutting move, mm/min; `length` gives
    /// how far the tip travels (needed for inverse time feed only).
    pub(super) fn cutting_feed(&self, length: impl FnOnce() -> f64) -> Result<f64, Alarm> {
        let f = self.state.feed;
        if f <= 0.0 {
            let span = self.op_feed_span();
            return Err(self.alarm(
                Condition::FeedZero,
                span,
                "cutting feed is zero: program F".into(),
            ));
        }
        match self.state.modal.feed_mode {
            FeedMode::PerMinute => Ok(f),
            FeedMode::PerRevolution => {
                if !self.state.spindle_on || self.state.spindle_speed <= 0.0 {
                    return Err(self.alarm(
                        Condition::NoSpindleForFeedPerRev,
                        None,
                        "feed per revolution (G95) with the spindle stopped".into(),
                    ));
                }
                Ok(f * self.state.spindle_speed)
            }
            FeedMode::InverseTime => {
                if self.op_feed_span().is_none() {
                    return Err(self.alarm(
                        Condition::FeedZero,
                        None,
                        "inverse time feed (G93) needs F in every cutting block".into(),
                    ));
                }
                Ok(f * length())
            }
        }
    }

    /// Motion in the current mode: the block's axis words, or only a
    /// change of the length offset (axes not named move by the change of
    /// the offset vector alone).
    pub(super) fn motion(
        &mut self,
        from: &Joints,
        length_changed: bool,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        if self.cutter.routing() {
            return self.cutter_c_motion(from, length_changed, out);
        }
        if let Some(kind) = self.tcpc_type() {
            return self.tcpc_motion(kind, from, length_changed, out);
        }
        let targets = self.axis_words();
        let has_axes = targets.iter().any(Option::is_some);
        let mode = self.state.modal.motion;
        let is_arc = matches!(mode, MotionMode::Cw | MotionMode::Ccw);
        let arc_words = is_arc && self.arc_words_present();
        if !has_axes && !arc_words && !length_changed {
            return Ok(());
        }
        let (end_p, travel) = self.end_point(from, &targets);
        let end = self.machine_position(&end_p);
        let start = self.rollover_start(&end, &travel);
        if is_arc && (has_axes || arc_words) {
            return self.arc(mode, start, from, &end_p, end, out);
        }
        let motion = if mode == MotionMode::Rapid {
            Motion::Rapid
        } else {
            Motion::Linear
        };
        self.push_line(motion, start, end, out)
    }

    /// A straight move in joint space (rapid or linear at the modal feed).
    pub(super) fn push_line(
        &self,
        motion: Motion,
        start: Joints,
        end: Joints,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        // A joint move moves when its ends differ (`Segment::moves`).
        if start == end {
            return Ok(());
        }
        let feed = if motion == Motion::Linear {
            let machine = self.machine;
            let length = || {
                let seg = self.segment(motion, start, end, Path::Joint);
                (seg.row(machine, 1.0).tip - seg.row(machine, 0.0).tip).norm()
            };
            Some(self.cutting_feed(length)?)
        } else {
            None
        };
        // Built in place: a segment is a few hundred bytes.
        out.push(Segment {
            feed,
            ..self.segment(motion, start, end, Path::Joint)
        });
        Ok(())
    }

    /// Whether the block gives a circle's radius or a centre word of the
    /// selected plane.
    pub(super) fn arc_words_present(&self) -> bool {
        let [p, q, _] = self.state.modal.plane.axes();
        self.op_has_arc(p, q)
    }

    /// G02 / G03: circle in the selected plane, helical on the normal axis,
    /// other axes linear.
    pub(super) fn arc(
        &mut self,
        mode: MotionMode,
        start: Joints,
        from: &Joints,
        end_p: &Joints,
        end: Joints,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let Some(geo) = self.arc_geometry(mode, from, end_p)? else {
            // R with the end point on the start point: no arc.
            return self.push_line(Motion::Linear, start, end, out);
        };
        let [p, q] = geo.axes;
        if self.feature().is_some() {
            // The circle of the feature plane, carried into the machine
            // frame with the rotary axes where they stand.
            let circle = self.feature_circle(&start, &programmed_circle(&geo, from, end_p));
            let path = Path::Helix {
                circle,
                drift: Vec3::zeros(),
            };
            let mut seg = self.segment(geo.motion, start, end, path);
            seg.feed = Some(self.cutting_feed(|| circle.length())?);
            out.push(seg);
            return Ok(());
        }
        if self.state.setup.rotation != SetupError::IDENTITY.rotation {
            // The real workpiece is turned: the circle is no longer in a
            // plane of the machine axes.
            let circle = self.real_circle(&geo, from, end_p);
            let drift = self.length_vector(&end) - self.length_vector(&start);
            let offset = self.length_vector(&start);
            let circle = circle.shifted(&offset);
            let mut seg = self.segment(geo.motion, start, end, Path::Helix { circle, drift });
            seg.feed = Some(self.cutting_feed(|| circle.length())?);
            out.push(seg);
            return Ok(());
        }
        // The centre in machine coordinates, and its drift when the offset
        // vector changes over the block.
        let offset0 = self.length_vector(&start) + self.to_real(&Vec3::zeros());
        let offset1 = self.length_vector(&end) + self.to_real(&Vec3::zeros());
        let arc = Arc {
            axes: [p, q],
            center: [geo.center[0] + offset0[p], geo.center[1] + offset0[q]],
            r0: geo.r0,
            r1: geo.r1,
            theta0: geo.theta0,
            sweep: geo.sweep,
            drift: [offset1[p] - offset0[p], offset1[q] - offset0[q]],
        };
        let mut seg = self.segment(geo.motion, start, end, Path::Arc(arc));
        let helix = end_p[geo.normal] - from[geo.normal];
        seg.feed = Some(self.cutting_feed(|| arc.length().hypot(helix))?);
        out.push(seg);
        Ok(())
    }

    /// The circle of an arc block on the real workpiece, work offset
    /// included (before the length offset).
    pub(super) fn real_circle(&self, geo: &ArcGeometry, from: &Joints, end_p: &Joints) -> TipPath {
        programmed_circle(geo, from, end_p)
            .mapped(|p| self.to_real(p), |v| self.state.setup.vector(v))
    }

    /// The circle of a G02 / G03 block in programmed coordinates, from
    /// `from` to `end_p` in the selected plane; `None` for an R arc whose
    /// end point is its start point (no arc).
    pub(super) fn arc_geometry(
        &mut self,
        mode: MotionMode,
        from: &Joints,
        end_p: &Joints,
    ) -> Result<Option<ArcGeometry>, Alarm> {
        let [p, q, normal] = self.state.modal.plane.axes();
        let ccw = self.framed_ccw(mode);
        let (sp, sq) = (from[p], from[q]);
        let (ep, eq) = (end_p[p], end_p[q]);
        let absolute = self.state.modal.ijk_absolute;
        let center = match self.op_arc_center(p, q)? {
            ArcCenter::Radius(r, span) => {
                let r = self.framed_radius(r, span)?;
                match self.center_from_radius((sp, sq), (ep, eq), r, ccw, span)? {
                    Some(c) => c,
                    None => return Ok(None),
                }
            }
            ArcCenter::Center { i, j, span } => {
                let (i, j) = if absolute { (i - sp, j - sq) } else { (i, j) };
                if i == 0.0 && j == 0.0 {
                    return Err(self.alarm(
                        Condition::ArcCenterMissing,
                        span,
                        "the arc's centre is its start point: the radius is 0".into(),
                    ));
                }
                let (i, j) = self.framed_center(i, j, span)?;
                (sp + i, sq + j)
            }
        };
        let r0 = (sp - center.0).hypot(sq - center.1);
        let r1 = (ep - center.0).hypot(eq - center.1);
        if r0.max(r1) > MAX_ARC_RADIUS {
            // A centre kilometres away: no machine makes that arc, and its
            // points would drown in rounding (program it as a line).
            let span = self.op_radius_span();
            return Err(self.alarm(
                Condition::ValueOutOfRange,
                span,
                format!(
                    "arc radius {} mm is beyond {MAX_ARC_RADIUS:e} mm: program a straight line",
                    r0.max(r1)
                ),
            ));
        }
        if self.dialect.rs274ngc {
            self.linuxcnc_arc_check(r0, r1)?;
        } else if (r1 - r0).abs() > ARC_RADIUS_TOLERANCE {
            return Err(self.alarm(
                Condition::ArcRadiusTolerance,
                None,
                format!("end point is not on the arc: start radius {r0}, end radius {r1}"),
            ));
        }
        let theta0 = (sq - center.1).atan2(sp - center.0);
        let theta1 = (eq - center.1).atan2(ep - center.0);
        let mut sweep = arc_sweep(theta0, theta1, ccw, r0);
        if self.dialect.rs274ngc
            && let Some(turns) = self.fanuc.arc_turns()?
        {
            // LinuxCNC: P − 1 whole turns before the arc to the end point.
            sweep += sweep.signum() * std::f64::consts::TAU * f64::from(turns - 1);
        }
        if let Some(turns) = self.block_turns {
            // A command's whole turns beyond the part turn (SINUMERIK
            // `TURN=`).
            sweep += sweep.signum() * std::f64::consts::TAU * f64::from(turns);
        }
        Ok(Some(ArcGeometry {
            axes: [p, q],
            normal,
            center: [center.0, center.1],
            r0,
            r1,
            theta0,
            sweep,
            motion: if ccw { Motion::Ccw } else { Motion::Cw },
        }))
    }

    /// LinuxCNC's check of a centre-format arc: the radii to the start
    /// and to the end may differ by up to the larger of an absolute
    /// tolerance and 0.1 % of the radius. g-code.adoc gives 0.005 mm
    /// (0.0005 in) and 0.1 %, or at most 0.5 mm (0.05 in); `rs274 -g`
    /// (2.9) was measured instead, on radii of 2 to 2000 mm and 0.2 in:
    /// it accepts up to 0.02·√2 mm (0.002·√2 in) or 0.1 % of the radius,
    /// whichever is larger, with no upper cap (2000 mm accepts 1.3 mm).
    /// The kernel follows the binary.
    fn linuxcnc_arc_check(&self, r0: f64, r1: f64) -> Result<(), Alarm> {
        let absolute = if self.state.modal.units == crate::modal::Units::Inch {
            LINUXCNC_ARC_ABSOLUTE_IN * MM_PER_INCH
        } else {
            LINUXCNC_ARC_ABSOLUTE_MM
        };
        let diff = (r1 - r0).abs();
        if diff > absolute && diff > LINUXCNC_ARC_RELATIVE * r0 {
            return Err(self.alarm(
                Condition::ArcRadiusTolerance,
                None,
                format!(
                    "radius to end of arc differs from radius to start: start radius {r0}, \
                     end radius {r1} (LinuxCNC accepts {:.4} mm or 0.1 %)",
                    absolute.max(LINUXCNC_ARC_RELATIVE * r0)
                ),
            ));
        }
        Ok(())
    }

    /// The centre of an R arc: of the two circles through both points, the
    /// one whose arc is at most 180° for R > 0, more for R < 0.
    pub(super) fn center_from_radius(
        &self,
        (sp, sq): (f64, f64),
        (ep, eq): (f64, f64),
        r: f64,
        ccw: bool,
        span: Span,
    ) -> Result<Option<(f64, f64)>, Alarm> {
        let (dp, dq) = (ep - sp, eq - sq);
        let chord = dp.hypot(dq);
        if chord <= POSITION_TOLERANCE {
            return Ok(None);
        }
        let half = chord / 2.0;
        let tolerance = if self.dialect.rs274ngc {
            LINUXCNC_R_TOLERANCE_MM
        } else {
            ARC_RADIUS_TOLERANCE
        };
        if r.abs() < half - tolerance {
            return Err(self.alarm(
                Condition::ArcRadiusTolerance,
                Some(span),
                if self.dialect.rs274ngc {
                    format!(
                        "arc radius too small to reach end point: R{} is shorter than half the \
                         chord {half}",
                        r.abs()
                    )
                } else {
                    format!("radius {} is shorter than half the chord {half}", r.abs())
                },
            ));
        }
        let h = (r * r - half * half).max(0.0).sqrt();
        // Unit normal to the left of the chord.
        let (np, nq) = (-dq / chord, dp / chord);
        let side = if ccw == (r > 0.0) { 1.0 } else { -1.0 };
        Ok(Some((
            sp + dp / 2.0 + side * h * np,
            sq + dq / 2.0 + side * h * nq,
        )))
    }
}

/// The circle of an arc block in programmed coordinates: centre in the
/// plane at the start's normal coordinate, rising to the end's.
pub(super) fn programmed_circle(geo: &ArcGeometry, from: &Joints, end_p: &Joints) -> TipPath {
    let [p, q] = geo.axes;
    let mut center = Vec3::new(from[0], from[1], from[2]);
    center[p] = geo.center[0];
    center[q] = geo.center[1];
    TipPath::plane_arc(
        [p, q, geo.normal],
        center,
        [geo.r0, geo.r1],
        geo.theta0,
        geo.sweep,
        end_p[geo.normal] - from[geo.normal],
    )
}

/// Signed sweep from `theta0` to `theta1` in the arc's direction; a full
/// circle when the two meet.
pub(super) fn arc_sweep(theta0: f64, theta1: f64, ccw: bool, radius: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let mut d = (theta1 - theta0).rem_euclid(tau);
    if !ccw {
        d = (theta0 - theta1).rem_euclid(tau);
    }
    // End point on the start point (within the position tolerance along
    // the circle): a full circle.
    if d * radius <= POSITION_TOLERANCE || (tau - d) * radius <= POSITION_TOLERANCE {
        d = tau;
    }
    if ccw { d } else { -d }
}

/// A G02 / G03 circle in programmed coordinates.
#[derive(Clone, Copy, Debug)]
pub(super) struct ArcGeometry {
    /// Indices of the plane's first and second axis.
    pub(super) axes: [usize; 2],
    /// Index of the plane's normal axis.
    pub(super) normal: usize,
    pub(super) center: [f64; 2],
    pub(super) r0: f64,
    pub(super) r1: f64,
    pub(super) theta0: f64,
    pub(super) sweep: f64,
    pub(super) motion: Motion,
}
