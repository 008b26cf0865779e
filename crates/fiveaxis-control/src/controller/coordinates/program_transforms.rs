//! The two-dimensional program transforms of the FANUC 30i and the local
//! coordinate system: G52, polar coordinates (G16 / G15), programmable
//! mirror image (G51.1 / G50.1), scaling (G51 / G50) and coordinate system
//! rotation (G68 / G69).
//!
//! A programmed point `p` (the axis words read in the program's own
//! coordinates, after the polar conversion of G16) becomes the point the
//! rest of the controller works with (cutter compensation C, arcs, the
//! work offset) as `T(p) = R(S(M(p)))`: the mirror image first, then the
//! scaling, then the rotation (FANUC 30i operator's manual: in scaling
//! mode "the scaling is applied first and then the coordinates are
//! rotated"; the programmable mirror image comes before both). The centre
//! of each stage is stored where that stage acts, that is, already mapped
//! by the stages before it (the manual: the rotation centre is scaled).
//! Because the stages must be nested (G51.1, G51, G68 on; off in the
//! reverse order), a stored centre never has to be mapped again.
//!
//! G52 shifts the program's zero within every work coordinate system: it is
//! added to the programmed point after the transforms, before the setup
//! error and the work offset (`Controller::to_real`).

use fiveaxis_gcode::{Code, Span};
use fiveaxis_machine::{Joints, Vec3};

use crate::alarm::{Alarm, Condition};
use crate::controller::{Controller, Targets};
use crate::cutter::Side;
use crate::fanuc::GCodes;
use crate::fanuc::{OneShot, ScaleFactors};
use crate::modal::{Distance, MotionMode, Plane};

/// Slots of [`GCodes::frames`]: one per modal group.
pub(crate) const POLAR: usize = 0;
/// Group 22: G50.1 / G51.1.
pub(crate) const MIRROR: usize = 1;
/// Group 11: G50 / G51.
pub(crate) const SCALING: usize = 2;
/// Group 16: G68 / G69.
pub(crate) const ROTATION: usize = 3;

/// Scaling: about `center` (where the scaling acts: already mirrored), by
/// a factor per linear axis.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Scaling {
    center: Vec3,
    factor: [f64; 3],
}

/// Coordinate system rotation in `plane` about `center` (already mirrored
/// and scaled) by `angle` degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Rotation {
    plane: Plane,
    center: Vec3,
    angle: f64,
}

/// The transforms in force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(in crate::controller) struct Frames {
    /// G16: the plane's first axis word is a radius, the second an angle.
    pub(in crate::controller) polar: bool,
    /// G52: the local coordinate system's zero in the work coordinate
    /// system.
    pub(in crate::controller) local: Vec3,
    /// G51.1: the mirror position of each linear axis.
    mirror: [Option<f64>; 3],
    scaling: Option<Scaling>,
    rotation: Option<Rotation>,
}

impl Default for Frames {
    fn default() -> Self {
        Self {
            polar: false,
            local: Vec3::zeros(),
            mirror: [None; 3],
            scaling: None,
            rotation: None,
        }
    }
}

impl Frames {
    /// A control-neutral programmable frame's scale factors and mirror
    /// (`crate::command::Frame`): about the program zero, the mirror
    /// before the scaling as here.
    pub(in crate::controller) fn set_scale_mirror(&mut self, factor: [f64; 3], mirror: [bool; 3]) {
        self.mirror = mirror.map(|m| m.then_some(0.0));
        self.scaling = (factor != [1.0; 3]).then_some(Scaling {
            center: Vec3::zeros(),
            factor,
        });
    }

    /// Whether a mirror image, scaling or rotation maps the points.
    pub(in crate::controller) fn maps(&self) -> bool {
        self.mirror.iter().any(Option::is_some) || self.scaling.is_some() || self.rotation.is_some()
    }

    /// Whether the programmed end point is not simply the axis words.
    pub(in crate::controller) fn active(&self) -> bool {
        self.polar || self.maps()
    }

    /// A programmed point as the controller works with it.
    pub(in crate::controller) fn apply(&self, p: &Vec3) -> Vec3 {
        let mut x = *p;
        for (i, m) in self.mirror.iter().enumerate() {
            if let Some(c) = m {
                x[i] = 2.0 * c - x[i];
            }
        }
        if let Some(s) = &self.scaling {
            for i in 0..3 {
                x[i] = s.center[i] + s.factor[i] * (x[i] - s.center[i]);
            }
        }
        if let Some(r) = &self.rotation {
            x = rotate(r.plane, &r.center, r.angle, &x);
        }
        x
    }

    /// The inverse of [`Frames::apply`].
    pub(in crate::controller) fn invert(&self, x: &Vec3) -> Vec3 {
        let mut p = *x;
        if let Some(r) = &self.rotation {
            p = rotate(r.plane, &r.center, -r.angle, &p);
        }
        if let Some(s) = &self.scaling {
            for i in 0..3 {
                p[i] = s.center[i] + (p[i] - s.center[i]) / s.factor[i];
            }
        }
        for (i, m) in self.mirror.iter().enumerate() {
            if let Some(c) = m {
                p[i] = 2.0 * c - p[i];
            }
        }
        p
    }

    /// The G code of transform group `#4011` (11), `#4016` (16), `#4017`
    /// (17) or `#4022` (22).
    pub(in crate::controller) fn modal_g(&self, variable: u32) -> f64 {
        match variable {
            4011 if self.scaling.is_some() => 51.0,
            4011 => 50.0,
            4016 if self.rotation.is_some() => 68.0,
            4016 => 69.0,
            4017 if self.polar => 16.0,
            4017 => 15.0,
            _ if self.mirror.iter().any(Option::is_some) => 51.1,
            _ => 50.1,
        }
    }

    /// The linear part of [`Frames::apply`]: how a programmed direction or
    /// increment turns.
    pub(in crate::controller) fn vector(&self, v: &Vec3) -> Vec3 {
        self.apply(v) - self.apply(&Vec3::zeros())
    }

    /// Whether the transform reverses the sense of rotation in the plane
    /// with axes `p`, `q` (an odd number of mirrored axes, negative
    /// scaling factors included): G02 and G03 swap, so do G41 and G42.
    pub(in crate::controller) fn flips(&self, p: usize, q: usize) -> bool {
        let mut sign = 1.0;
        for i in [p, q] {
            if self.mirror[i].is_some() {
                sign = -sign;
            }
            if let Some(s) = &self.scaling {
                sign *= s.factor[i].signum();
            }
        }
        sign < 0.0
    }
}

/// `x` turned by `angle` degrees about `center` in `plane` (counter-
/// clockwise seen from the plane's normal).
fn rotate(plane: Plane, center: &Vec3, angle: f64, x: &Vec3) -> Vec3 {
    let [p, q, _] = plane.axes();
    let (sin, cos) = angle.to_radians().sin_cos();
    let (dp, dq) = (x[p] - center[p], x[q] - center[q]);
    let mut y = *x;
    y[p] = center[p] + cos * dp - sin * dq;
    y[q] = center[q] + sin * dp + cos * dq;
    y
}

impl Controller<'_> {
    /// The transform codes of the block (after the modal groups, length
    /// compensation and cutter compensation are applied): the centres are
    /// read from the block's X, Y, Z, which then do not move the tool.
    /// `from` is where the program stands (after the transforms in force).
    /// Returns whether the block's axis words were taken for a transform
    /// (G68, G51, G51.1, G50.1): such a block does not move.
    pub(in crate::controller) fn apply_frames(
        &mut self,
        codes: &GCodes,
        from: &Joints,
    ) -> Result<bool, Alarm> {
        let here = Vec3::new(from[0], from[1], from[2]);
        let mut starts = [MIRROR, SCALING, ROTATION]
            .into_iter()
            .filter_map(|slot| codes.frames[slot].filter(|&(on, _, _)| on));
        let first = starts.next();
        if let (Some((_, _, first)), Some((_, span, code))) = (first, starts.next()) {
            return Err(self.alarm(
                Condition::GCodeConflict,
                Some(span),
                format!("G{code} and G{first} both take X, Y, Z: give them in separate blocks"),
            ));
        }
        // Cancels first, innermost first; then the start.
        if let Some((false, _, _)) = codes.frames[ROTATION] {
            self.state.frames.rotation = None;
        }
        if let Some((false, span, code)) = codes.frames[SCALING] {
            self.nesting(self.state.frames.rotation.is_some(), code, span, "G69")?;
            self.state.frames.scaling = None;
        }
        if let Some((false, span, code)) = codes.frames[MIRROR] {
            let f = self.state.frames;
            self.nesting(
                f.rotation.is_some() || f.scaling.is_some(),
                code,
                span,
                "G69 and G50",
            )?;
            self.mirror_cancel();
        }
        if let Some((on, _, _)) = codes.frames[POLAR] {
            self.state.frames.polar = on;
        }
        if let Some((true, span, code)) = codes.frames[MIRROR] {
            let f = self.state.frames;
            self.nesting(
                f.rotation.is_some() || f.scaling.is_some(),
                code,
                span,
                "G69 and G50",
            )?;
            self.mirror_start(code, span)?;
        }
        if let Some((true, span, code)) = codes.frames[SCALING] {
            self.nesting(self.state.frames.rotation.is_some(), code, span, "G69")?;
            self.scaling_start(code, span, &here)?;
        }
        if let Some((true, span, _)) = codes.frames[ROTATION] {
            if self.conversion_requested() {
                // G68 with I, J, K: three-dimensional coordinate conversion
                // (feature_frame.rs).
                self.conversion_start(span, &here)?;
            } else {
                self.rotation_start(&here);
            }
        }
        self.frames_restrictions(codes)?;
        let mirror = codes.frames[MIRROR].is_some();
        Ok(first.is_some() || mirror)
    }

    fn nesting(&self, inner: bool, code: Code, span: Span, first: &str) -> Result<(), Alarm> {
        if inner {
            return Err(self.alarm(
                Condition::FrameNesting,
                Some(span),
                format!(
                    "G{code} inside an inner transform: give {first} first (the transforms nest: G51.1, G51, G68 on, G69, G50, G50.1 off)"
                ),
            ));
        }
        Ok(())
    }

    /// The alarms of a block once its transforms are in force.
    fn frames_restrictions(&self, codes: &GCodes) -> Result<(), Alarm> {
        let f = &self.state.frames;
        let any_code = codes.frames.iter().flatten().next().map(|&(_, s, _)| s);
        let local_code = codes
            .one_shot
            .filter(|&(what, _, _)| what == OneShot::LocalShift)
            .map(|(_, s, _)| s);
        if (self.tcpc_type().is_some() || self.state.comp3d.active)
            && (f.active() || f.local != Vec3::zeros())
        {
            let span = any_code
                .or(local_code)
                .or(codes.length.map(|(_, s, _)| s))
                .or(codes.cutter.map(|(_, s)| s));
            return Err(self.alarm(
                Condition::FrameNotAllowed,
                span,
                "polar coordinates, coordinate rotation, scaling, mirror image and G52 cannot be used with TCPC or 3-D tool compensation: cancel one first".into(),
            ));
        }
        if let Some(r) = &f.rotation
            && r.plane != self.state.modal.plane
        {
            return Err(self.alarm(
                Condition::FramePlaneChange,
                None,
                "the plane cannot change in coordinate system rotation (G68): cancel it with G69 first".into(),
            ));
        }
        if f.maps() {
            let forbidden = codes
                .one_shot
                .filter(|&(what, _, _)| {
                    matches!(
                        what,
                        OneShot::ReferenceCheck
                            | OneShot::ReferenceReturn { .. }
                            | OneShot::LocalShift
                            | OneShot::SetPosition
                            | OneShot::ShiftReset(_)
                    )
                })
                .map(|(_, span, code)| (code, span))
                .or(codes.work.map(|(_, span, code)| (code, span)));
            if let Some((code, span)) = forbidden {
                return Err(self.alarm(
                    Condition::FrameCommandForbidden,
                    Some(span),
                    format!(
                        "G{code} cannot be given in coordinate rotation, scaling or mirror image: cancel them first"
                    ),
                ));
            }
        }
        Ok(())
    }

    fn mirror_cancel(&mut self) {
        let rules = self.rules();
        let named = self.fanuc.linear_values(&rules);
        for (i, value) in named.iter().enumerate() {
            if value.is_some() {
                self.state.frames.mirror[i] = None;
            }
        }
        if named.iter().all(Option::is_none) {
            self.state.frames.mirror = [None; 3];
        }
    }

    fn mirror_start(&mut self, code: Code, span: Span) -> Result<(), Alarm> {
        let rules = self.rules();
        let named = self.fanuc.linear_values(&rules);
        if named.iter().all(Option::is_none) {
            return Err(self.alarm(
                Condition::NoDataAfterAddress,
                Some(span),
                format!("G{code} needs the axis words of the mirror positions (X, Y, Z)"),
            ));
        }
        for (i, value) in named.into_iter().enumerate() {
            if value.is_some() {
                self.state.frames.mirror[i] = value;
            }
        }
        Ok(())
    }

    fn scaling_start(&mut self, code: Code, span: Span, here: &Vec3) -> Result<(), Alarm> {
        let mut center = self.state.frames.invert(here);
        let rules = self.rules();
        for (i, value) in self.fanuc.linear_values(&rules).into_iter().enumerate() {
            if let Some(value) = value {
                center[i] = value;
            }
        }
        let factor = match self.fanuc.scale_factors(code, span)? {
            ScaleFactors::Uniform(p) => [p; 3],
            ScaleFactors::PerAxis(k) => k,
            ScaleFactors::None => [1.0; 3],
        };
        // The centre is where the scaling acts: mirrored first.
        let center = self.state.frames.apply(&center);
        self.state.frames.scaling = Some(Scaling { center, factor });
        Ok(())
    }

    fn rotation_start(&mut self, here: &Vec3) {
        let plane = self.state.modal.plane;
        let [p, q, _] = plane.axes();
        let rules = self.rules();
        let given = [p, q].map(|axis| self.fanuc.linear_value(axis, &rules));
        let center = if given.iter().any(Option::is_some) {
            // The centre in program coordinates, mirrored and scaled.
            let before = Frames {
                rotation: None,
                ..self.state.frames
            };
            let mut c = before.invert(here);
            for (axis, value) in [p, q].into_iter().zip(given) {
                if let Some(value) = value {
                    c[axis] = value;
                }
            }
            before.apply(&c)
        } else {
            // Omitted: the tool position when G68 is given.
            *here
        };
        let previous = self.state.frames.rotation.map_or(0.0, |r| r.angle);
        let angle = match self.fanuc.rotation_angle(&rules) {
            Some(angle) if self.state.modal.distance == Distance::Incremental => previous + angle,
            Some(angle) => angle,
            // FANUC No.5410: the angle of a G68 without R; taken as 0.
            None => 0.0,
        };
        self.state.frames.rotation = Some(Rotation {
            plane,
            center,
            angle,
        });
    }

    /// G52: the local coordinate system (absolute values in the work
    /// coordinate system; axes not named keep theirs; `G52 X0 Y0 Z0`
    /// cancels).
    ///
    /// LinuxCNC keeps G52 in G92's registers (coordinates.adoc, "G52 and
    /// G92 share the same offset registers. Therefore, setting G52 will
    /// override any earlier G92 setting"; rs274: `G92 X0` at X5, then
    /// `G52 X1`, prints the G92 offset 1): there, each named axis's G92
    /// shift becomes the value.
    pub(in crate::controller) fn local_coordinate_system(&mut self) -> Result<(), Alarm> {
        let rules = self.rules();
        for (i, value) in self.fanuc.linear_values(&rules).into_iter().enumerate() {
            if let Some(value) = value {
                if self.dialect.rs274ngc {
                    self.state.shift[i] = value;
                    self.state.frames.local[i] = 0.0;
                    // The parameters #5211… too: G92.3 brings it back.
                    self.state.g92_kept.0[i] = value;
                } else {
                    self.state.frames.local[i] = value;
                }
            }
        }
        Ok(())
    }

    /// [`Controller::end_point`] under polar coordinates or a transform:
    /// the end point in program coordinates, then mapped.
    pub(in crate::controller) fn framed_end_point(
        &self,
        from: &Joints,
        targets: &Targets,
    ) -> (Joints, Joints) {
        let f = &self.state.frames;
        let here = Vec3::new(from[0], from[1], from[2]);
        let program = f.invert(&here);
        let mut prog_from = *from;
        prog_from[..3].copy_from_slice(program.as_slice());
        let [p, q, _] = self.state.modal.plane.axes();
        let polar = f.polar && (targets[p].is_some() || targets[q].is_some());
        let mut plain = *targets;
        if polar {
            plain[p] = None;
            plain[q] = None;
        }
        let (mut end, mut travel) = self.plain_end_point(&prog_from, &plain);
        if polar {
            let (x, y) = (program[p], program[q]);
            let radius = x.hypot(y);
            let current = y.atan2(x).to_degrees();
            let (pole, r, a) = if self.state.modal.distance == Distance::Incremental {
                let a = current + targets[q].unwrap_or(0.0);
                match targets[p] {
                    // An incremental radius: the pole is the current position.
                    Some(r) => ((x, y), r, a),
                    None => ((0.0, 0.0), radius, a),
                }
            } else {
                (
                    (0.0, 0.0),
                    targets[p].unwrap_or(radius),
                    targets[q].unwrap_or(current),
                )
            };
            let (sin, cos) = a.to_radians().sin_cos();
            end[p] = pole.0 + r * cos;
            end[q] = pole.1 + r * sin;
        }
        // An axis the block leaves, which no other axis turns into, stays
        // exactly where it is (no rounding from the round trip).
        let target = Vec3::new(end[0], end[1], end[2]);
        let mapped = f.apply(&target);
        for i in 0..3 {
            let separate = (0..3).all(|j| j == i || f.vector(&unit(j))[i] == 0.0);
            end[i] = if target[i] == program[i] && separate {
                from[i]
            } else {
                mapped[i]
            };
            travel[i] = end[i] - from[i];
        }
        (end, travel)
    }

    /// The sense of an arc after the transforms (G02 ↔ G03 under an odd
    /// mirror image).
    pub(in crate::controller) fn framed_ccw(&self, mode: MotionMode) -> bool {
        let [p, q, _] = self.state.modal.plane.axes();
        (mode == MotionMode::Ccw) != self.state.frames.flips(p, q)
    }

    /// An arc's R after scaling; unequal factors on the plane's axes are
    /// refused.
    pub(in crate::controller) fn framed_radius(&self, r: f64, span: Span) -> Result<f64, Alarm> {
        let [p, q, _] = self.state.modal.plane.axes();
        let Some(s) = &self.state.frames.scaling else {
            return Ok(r);
        };
        let (kp, kq) = (s.factor[p].abs(), s.factor[q].abs());
        if (kp - kq).abs() > 1e-12 {
            return Err(self.alarm(
                Condition::FrameArcScaling,
                Some(span),
                format!(
                    "an arc under scaling by {kp} and {kq} on its plane's axes would be an ellipse"
                ),
            ));
        }
        Ok(r * kp)
    }

    /// The centre increments I, J of an arc (plane axes `p`, `q`) after the
    /// transforms.
    pub(in crate::controller) fn framed_center(
        &self,
        i: f64,
        j: f64,
        span: Option<Span>,
    ) -> Result<(f64, f64), Alarm> {
        let [p, q, _] = self.state.modal.plane.axes();
        if let Some(span) = span {
            self.framed_radius(1.0, span)?;
        }
        let mut v = Vec3::zeros();
        v[p] = i;
        v[q] = j;
        let w = self.state.frames.vector(&v);
        Ok((w[p], w[q]))
    }

    /// The direction of an I, J type vector (cutter compensation C) after
    /// the transforms.
    pub(in crate::controller) fn framed_direction(
        &self,
        v: crate::cutter::P2,
        plane: [usize; 3],
    ) -> crate::cutter::P2 {
        let mut w = Vec3::zeros();
        w[plane[0]] = v.x;
        w[plane[1]] = v.y;
        let w = self.state.frames.vector(&w);
        crate::cutter::P2::new(w[plane[0]], w[plane[1]])
    }

    /// The side of cutter compensation C after a mirror image.
    pub(in crate::controller) fn framed_side(&self, side: Side, plane: [usize; 3]) -> Side {
        if self.state.frames.flips(plane[0], plane[1]) {
            match side {
                Side::Left => Side::Right,
                Side::Right => Side::Left,
            }
        } else {
            side
        }
    }
}

fn unit(i: usize) -> Vec3 {
    let mut v = Vec3::zeros();
    v[i] = 1.0;
    v
}
