//! Tilted working plane (FANUC 30i-B "tilted working plane indexing"):
//! `G68.2` defines a feature coordinate system, `G53.1` turns the rotary
//! axes so that the tool stands along its Z axis, `G69` cancels.
//!
//! * `G68.2 X x Y y Z z I α J β K γ` (P0, the default): the feature frame's
//!   origin is (x, y, z) in the workpiece coordinate system, its axes those
//!   of the workpiece turned by the Euler angles α about Z, then β about the
//!   new X, then γ about the newest Z: `R = Rz(α)·Rx(β)·Rz(γ)`.
//!   `G68.2 P1 X Y Z I J K`: roll-pitch-yaw, I about X, J about Y, K about Z
//!   of the workpiece, in that order: `R = Rz(K)·Ry(J)·Rx(I)`. A programmed
//!   point p is the workpiece point `origin + R·p`. Words left out are 0;
//!   X, Y, Z are absolute whatever G90 / G91 (the manual's definition).
//! * `G68.2 P2` three points, one block each: `Q0 X Y Z R` (optional,
//!   first) the origin's shift from the first point in the new frame and
//!   a turn about the new Z; `Q1`, `Q2`, `Q3 X Y Z` the first point, a
//!   point on +X, a point of the X-Y plane on the +Y side.
//!   `G68.2 P3` two vectors: `Q1 X Y Z I J K` the origin and +X, `Q2 I J K`
//!   +Z; square within 5° (the 30i-B's 85°–95°), +X then made normal to +Z.
//!   The blocks of P2 / P3 follow each other with nothing between (PS5457
//!   otherwise). Block order and words as FANUC post processors write
//!   them (NX and open posts for the 30i); the FANUC manual pages
//!   themselves were not at hand.
//! * `G68.2 P4 X Y Z I J K` projection angles: the plane's trace in the
//!   Y-Z plane is +Y turned by I about X, its trace in the Z-X plane is +X
//!   turned by J about Y (that trace is the frame's +X); K turns the frame
//!   about its Z. One angle alone is the rotation about that axis. The
//!   FANUC figure was not at hand: this is the projection-angle definition
//!   of Heidenhain's PLANE PROJECTED and Siemens' CYCLE800, which agree.
//! * `G53.1`: the rotary axes turn (rapid, the linear axes stay) to the
//!   position that points the tool along the feature Z, chosen among the
//!   solutions by the control's rule (`rotary_choice`, as TCPC chooses).
//! * In the mode every programmed point goes through the feature frame,
//!   then the work offset (and a setup error), and the linear axes are
//!   whatever puts the tool tip there with the rotary axes where they
//!   stand and the tool length along the tool (G43: as FANUC applies it in
//!   the tool axis direction in this mode). Lines are straight in the
//!   feature frame (the rotary axes stand, so a joint line is exact); arcs
//!   are circles in the feature plane, carried into the machine frame.
//!   Canned cycles drill along the feature Z; cutter compensation C
//!   offsets in the feature plane (controller/cutter_c.rs maps its pieces
//!   through the frame).
//!
//! Haas: `G268 X Y Z I J K Q` is the same plane with the turns in the
//! order Q names (`feature_by_rotation_order`), `G253` is G53.1, `G269`
//! G69; `G254` (dynamic work offset) is a frame whose origin is the work
//! zero and whose axes are the machine's as the table stands
//! (`Feature::dwo`, `controller/haas.rs`).
//!
//! TCPC inside the plane programs in the feature frame (on WKP = 1 the
//! feature frame is defined on the frame that does not turn; see
//! `tcpc.rs`), and a 3-D tool compensation vector I J K is read in it.
//!
//! Decisions where this kernel is stricter than the control (each alarm
//! FX0150 naming the function): G68.2 is not started while TCPC or 3-D
//! tool compensation is on; the work offset and G54.4 cannot change in
//! the mode (except the work offset in Haas's G254, whose frame takes its
//! zero from the offset in force); `G68.2` in the mode replaces the frame (FANUC nests it with
//! parameter No.11221; here the new frame is always relative to the
//! workpiece).

use fiveaxis_gcode::{Code, Span};
use fiveaxis_machine::{Joints, Vec3};
use nalgebra::{IsometryMatrix3, Rotation3, Translation3, Unit};

use crate::alarm::{Alarm, Condition};
use crate::controller::Controller;
use crate::fanuc::FeatureCode;
use crate::modal::LengthMode;
use crate::segment::{Motion, Segment, TipPath};

/// A feature coordinate system: a programmed point `p` is the workpiece
/// point `origin + rotation·p`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(in crate::controller) struct Feature {
    origin: Vec3,
    rotation: Rotation3<f64>,
    /// 0: a tilted working plane (G68.2 and its kin); 1 or 2: a
    /// three-dimensional coordinate conversion (G68 with I, J, K) and how
    /// many are nested.
    conversions: u8,
    /// Haas G254 dynamic work offset: origin the work zero, axes those of
    /// the machine as the table stands (`Feature::dwo`).
    dwo: bool,
}

impl Feature {
    /// Haas G254 with the table turned by `turn` (the rotation of the
    /// table's map at the standing rotary axes): the work zero follows the
    /// table, the axes stay those of the machine, so a programmed point p
    /// is the workpiece point `turn⁻¹·p` from the work zero (the machine
    /// sees p from the turned work zero, the tool along its Z).
    pub(in crate::controller) fn dwo(turn: Rotation3<f64>) -> Self {
        Self {
            origin: Vec3::zeros(),
            rotation: turn.inverse(),
            conversions: 0,
            dwo: true,
        }
    }

    /// Whether this is Haas's dynamic work offset (G254).
    pub(in crate::controller) fn is_dwo(&self) -> bool {
        self.dwo
    }

    /// A feature frame of the tilted working plane (not a conversion).
    pub(in crate::controller) fn plane(origin: Vec3, rotation: Rotation3<f64>) -> Self {
        Self {
            origin,
            rotation,
            conversions: 0,
            dwo: false,
        }
    }

    /// The rotation: the frame's axes as columns, in workpiece axes.
    pub(in crate::controller) fn rotation(&self) -> Rotation3<f64> {
        self.rotation
    }

    pub(super) fn work_point(&self, p: &Vec3) -> Vec3 {
        self.origin + self.rotation * p
    }

    pub(super) fn feature_point(&self, x: &Vec3) -> Vec3 {
        self.rotation.inverse() * (x - self.origin)
    }

    /// G68.4: the plane `inner`, defined in this frame, in workpiece
    /// coordinates.
    pub(super) fn within(&self, inner: &Feature) -> Feature {
        Feature::plane(
            self.work_point(&inner.origin),
            self.rotation * inner.rotation,
        )
    }
}

/// A definition given block by block (G68.2 P2 three points, P3 two
/// vectors) while its blocks come: nothing else may come between them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(in crate::controller) struct Pending {
    /// G68.2 or G68.4.
    pub(in crate::controller) code: Code,
    /// 2 or 3.
    pub(in crate::controller) form: u32,
    /// Whether a block of it has been read.
    pub(super) started: bool,
    /// The Q of the last block read.
    pub(in crate::controller) last_q: u32,
    /// P2 Q0: the origin's shift from the first point, in the new frame.
    pub(super) shift: Vec3,
    /// P2 Q0: the turn about the new Z, degrees.
    pub(super) turn: f64,
    /// P2: the three points; P3: origin, +X direction, +Z direction.
    pub(super) points: [Vec3; 3],
}

impl Pending {
    /// A definition of form `form` (2 or 3) by `code` before its first block.
    pub(super) fn new(code: Code, form: u32) -> Self {
        Self {
            code,
            form,
            started: false,
            last_q: 0,
            shift: Vec3::zeros(),
            turn: 0.0,
            points: [Vec3::zeros(); 3],
        }
    }
}

/// Below this, points coincide, lie on one line, or a vector is zero
/// (a definition the control refuses), mm or unit vectors.
pub(super) const DEFINITION_TOLERANCE: f64 = 1e-9;

/// How far from square the two vectors of G68.2 P3 may be, degrees (the
/// 30i-B's 85 to 95 degrees, as read in the FANUC tilted working plane
/// documentation).
const SQUARE_TOLERANCE: f64 = 5.0;

/// The rotation whose +Z is along `z` and whose +X is `x` made normal to
/// it (`x` not along `z`).
pub(super) fn frame_of(x: Vec3, z: Vec3) -> Rotation3<f64> {
    let z = z.normalize();
    let x = (x - z * x.dot(&z)).normalize();
    let y = z.cross(&x);
    Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_columns(&[x, y, z]))
}

/// How many three-dimensional coordinate conversions nest (FANUC: two).
const MAX_CONVERSIONS: u8 = 2;

/// Below this, the tool axis is taken as the vertical axis (G68.3).
const VERTICAL_TOLERANCE: f64 = 1e-9;

/// The frame whose +Z is the unit tool axis `z` (G68.3): +X normal to
/// the plane of +Z and the vertical axis (the machine's +Z), `Xc = V ×
/// Zc`, `Yc = Zc × Xc`; +X of the workpiece when the tool is vertical.
pub(super) fn tool_axis_frame(z: Vec3) -> Rotation3<f64> {
    let vertical = Vec3::z();
    let mut x = vertical.cross(&z);
    if x.norm() < VERTICAL_TOLERANCE {
        x = Vec3::x();
    }
    let x = x.normalize();
    let y = z.cross(&x);
    Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_columns(&[x, y, z]))
}

/// The Q of the last block of a definition given block by block: P2's
/// three points end at Q3, P3's two vectors at Q2.
fn definition_last(form: u32) -> u32 {
    if form == 2 { 3 } else { 2 }
}

pub(super) fn about(axis: Vec3, degrees: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Unit::new_unchecked(axis), degrees.to_radians())
}

impl Controller<'_> {
    /// The feature frame in force, if any.
    pub(in crate::controller) fn feature(&self) -> Option<&Feature> {
        self.state.feature.as_ref()
    }

    /// The feature frame as a map of TCPC programming coordinates: a point
    /// `y = p + w` of the workpiece frame (w: work offset and what is
    /// added to it) goes to `R^T (y - w - origin) + w`, so that a TCPC
    /// programmed point p is read in the feature frame.
    pub(in crate::controller) fn feature_isometry(&self, w: Vec3) -> Option<IsometryMatrix3<f64>> {
        let f = self.feature()?;
        let back = f.rotation.inverse();
        let shift = w - back * (w + f.origin);
        Some(IsometryMatrix3::from_parts(Translation3::from(shift), back))
    }

    /// A programmed point in workpiece coordinates (through the feature
    /// frame in the mode).
    pub(in crate::controller) fn feature_to_work(&self, p: &Vec3) -> Vec3 {
        self.feature().map_or(*p, |f| f.work_point(p))
    }

    /// A programmed vector in workpiece coordinates (turned by the feature
    /// frame in the mode).
    pub(in crate::controller) fn feature_vector(&self, v: &Vec3) -> Vec3 {
        self.feature().map_or(*v, |f| f.rotation * v)
    }

    /// The inverse of [`Controller::feature_to_work`].
    pub(in crate::controller) fn work_to_feature(&self, x: &Vec3) -> Vec3 {
        self.feature().map_or(*x, |f| f.feature_point(x))
    }

    /// The tool length along the tool in the mode: the H value with the
    /// sign of G43 / G44, 0 without length compensation.
    pub(in crate::controller) fn feature_tool_length(&self) -> f64 {
        match self.state.modal.length {
            LengthMode::Plus | LengthMode::ToolAxis => self.tool_length(),
            LengthMode::Minus => -self.tool_length(),
            _ => 0.0,
        }
    }

    /// G68.2 (define the frame) or G68.4 (define it relative to the frame
    /// in force). G69 cancels it before the block's move (in `execute`).
    pub(in crate::controller) fn feature_command(
        &mut self,
        what: FeatureCode,
        code: Code,
        span: Span,
    ) -> Result<(), Alarm> {
        let name = format!("G{code}");
        self.feature_allowed(span, &name)?;
        if what == FeatureCode::ToolAxis {
            return self.feature_from_tool_axis(span);
        }
        if what == FeatureCode::HaasPlane {
            let feature = self.feature_by_rotation_order(span)?;
            self.state.feature = Some(feature);
            return Ok(());
        }
        let form = self.definition_form(code, span)?;
        let defined = match form {
            0 | 1 | 4 => Some(self.feature_by_angles(form, &name, span)?),
            2 => self.feature_by_points(code, &name, span)?,
            3 => self.feature_by_vectors(code, &name, span)?,
            _ => {
                return Err(self.alarm(
                    Condition::FeatureDefinition,
                    Some(span),
                    format!(
                        "{name} P{form}: the forms are P0 (Euler angles), P1 (roll-pitch-yaw), P2 (three points), P3 (two vectors) and P4 (projection angles)"
                    ),
                ));
            }
        };
        // A multi-block definition not yet complete defines nothing yet.
        let Some(defined) = defined else {
            return Ok(());
        };
        // G68.4: the new frame is given in the frame in force.
        let feature = match self.state.feature {
            Some(outer) if what == FeatureCode::Relative => outer.within(&defined),
            _ => defined,
        };
        self.state.feature = Some(feature);
        Ok(())
    }

    /// The origin X, Y, Z of a definition block (absolute, 0 when left
    /// out).
    pub(super) fn definition_point(&mut self) -> Vec3 {
        let rules = self.rules();
        Vec3::from(self.fanuc.linear_values(&rules).map(|v| v.unwrap_or(0.0)))
    }

    /// I, J, K of a definition block as angles (P0, P1, P4) or vector
    /// components (P3): the decimal-point rule, no unit change; 0 when
    /// left out.
    pub(super) fn definition_ijk(&mut self) -> Vec3 {
        let rules = self.rules();
        Vec3::from(self.fanuc.angle_vector(&rules).map(|v| v.unwrap_or(0.0)))
    }

    /// Alarms on a definition value that is not a finite number.
    pub(super) fn definition_finite(
        &self,
        values: &[f64],
        name: &str,
        span: Span,
    ) -> Result<(), Alarm> {
        if values.iter().all(|v| v.is_finite()) {
            return Ok(());
        }
        Err(self.alarm(
            Condition::ValueOutOfRange,
            Some(span),
            format!("{name} with a value that is not a finite number"),
        ))
    }

    /// The one-block forms: P0 Euler angles, P1 roll-pitch-yaw, P4
    /// projection angles (see the module documentation).
    fn feature_by_angles(&mut self, form: u32, name: &str, span: Span) -> Result<Feature, Alarm> {
        let origin = self.definition_point();
        let angles = self.definition_ijk();
        let (i, j, k) = (angles.x, angles.y, angles.z);
        self.definition_finite(&[origin.x, origin.y, origin.z, i, j, k], name, span)?;
        let rotation = match form {
            0 => about(Vec3::z(), i) * about(Vec3::x(), j) * about(Vec3::z(), k),
            1 => about(Vec3::z(), k) * about(Vec3::y(), j) * about(Vec3::x(), i),
            _ => {
                // The plane's trace in the Y-Z plane is +Y turned by I about
                // X; its trace in the Z-X plane is +X turned by J about Y.
                let x = about(Vec3::y(), j) * Vec3::x();
                let trace_yz = about(Vec3::x(), i) * Vec3::y();
                let z = x.cross(&trace_yz);
                if z.norm() < DEFINITION_TOLERANCE {
                    return Err(self.alarm(
                        Condition::FeatureDefinition,
                        Some(span),
                        format!("{name} P4 I{i} J{j}: both traces run along Z, which leaves the plane undefined"),
                    ));
                }
                frame_of(x, z) * about(Vec3::z(), k)
            }
        };
        Ok(Feature {
            origin,
            rotation,
            conversions: 0,
            dwo: false,
        })
    }

    /// Haas `G268 X Y Z I J K Q`: the feature frame's origin X, Y, Z in the
    /// workpiece coordinate system (absolute, 0 when left out), its axes
    /// those of the workpiece turned by I about X, J about Y and K about
    /// Z, in the order Q names (three digits, 1 = X / I, 2 = Y / J, 3 =
    /// Z / K; each a turn about the workpiece's fixed axes): `Q123` is I,
    /// then J, then K, `R = Rz(K)·Ry(J)·Rx(I)` (FANUC G68.2 P1). Q left
    /// out is 123.
    fn feature_by_rotation_order(&mut self, span: Span) -> Result<Feature, Alarm> {
        let origin = self.definition_point();
        let angles = self.definition_ijk();
        let order = self.fanuc.rotation_order()?;
        self.definition_finite(
            &[origin.x, origin.y, origin.z, angles.x, angles.y, angles.z],
            "G268",
            span,
        )?;
        let axes = [Vec3::x(), Vec3::y(), Vec3::z()];
        let mut rotation = Rotation3::identity();
        for k in order {
            // Each turn about the fixed axes: applied after those before.
            rotation = about(axes[k], angles[k]) * rotation;
        }
        Ok(Feature {
            origin,
            rotation,
            conversions: 0,
            dwo: false,
        })
    }

    /// P2, three points, one block each: `Q0 X Y Z R` (optional, first):
    /// the origin's shift from the first point in the new frame, and a
    /// turn about the new Z; `Q1`, `Q2`, `Q3 X Y Z`: the first point
    /// (origin), the second (on +X), the third (in the X-Y plane on the +Y
    /// side). The frame is defined at the Q3 block.
    fn feature_by_points(
        &mut self,
        code: Code,
        name: &str,
        span: Span,
    ) -> Result<Option<Feature>, Alarm> {
        let (mut pending, q) = self.definition_block(code, 2, name, span)?;
        let point = self.definition_point();
        let turn = if q == 0 {
            let rules = self.rules();
            self.fanuc.rotation_angle(&rules).unwrap_or(0.0)
        } else {
            0.0
        };
        self.definition_finite(&[point.x, point.y, point.z, turn], name, span)?;
        if q == 0 {
            pending.shift = point;
            pending.turn = turn;
        } else {
            pending.points[q as usize - 1] = point;
        }
        let Some(pending) = self.definition_hold(pending, q) else {
            return Ok(None);
        };
        let [p1, p2, p3] = pending.points;
        let x = p2 - p1;
        let z = x.cross(&(p3 - p1));
        if x.norm() < DEFINITION_TOLERANCE || z.norm() < DEFINITION_TOLERANCE * x.norm() {
            return Err(self.alarm(
                Condition::FeatureDefinition,
                Some(span),
                format!("{name} P2: the three points lie on one line (or two are the same point)"),
            ));
        }
        let frame = frame_of(x, z);
        Ok(Some(Feature {
            origin: p1 + frame * pending.shift,
            rotation: frame * about(Vec3::z(), pending.turn),
            conversions: 0,
            dwo: false,
        }))
    }

    /// P3, two vectors: `Q1 X Y Z I J K`: the origin and the direction of
    /// +X; `Q2 I J K`: the direction of +Z. The two must be square within
    /// [`SQUARE_TOLERANCE`]; +X is then made exactly normal to +Z.
    fn feature_by_vectors(
        &mut self,
        code: Code,
        name: &str,
        span: Span,
    ) -> Result<Option<Feature>, Alarm> {
        let (mut pending, q) = self.definition_block(code, 3, name, span)?;
        if q == 1 {
            pending.points[0] = self.definition_point();
        }
        let vector = self.definition_ijk();
        pending.points[q as usize] = vector;
        let [origin, x, z] = pending.points;
        self.definition_finite(
            &[origin.x, origin.y, origin.z, vector.x, vector.y, vector.z],
            name,
            span,
        )?;
        if vector.norm() < DEFINITION_TOLERANCE {
            return Err(self.alarm(
                Condition::FeatureDefinition,
                Some(span),
                format!("{name} P3 Q{q}: the direction is a zero vector"),
            ));
        }
        if self.definition_hold(pending, q).is_none() {
            return Ok(None);
        }
        let angle = x.angle(&z).to_degrees();
        if (angle - 90.0).abs() > SQUARE_TOLERANCE {
            return Err(self.alarm(
                Condition::FeatureDefinition,
                Some(span),
                format!(
                    "{name} P3: the +X and +Z directions are {angle:.3} degrees apart; they must be square within {SQUARE_TOLERANCE} degrees"
                ),
            ));
        }
        Ok(Some(Feature {
            origin,
            rotation: frame_of(x, z),
            conversions: 0,
            dwo: false,
        }))
    }

    /// The form P of a definition block (0 when left out); while a
    /// definition given block by block is pending, only its next block may
    /// come.
    pub(super) fn definition_form(&mut self, code: Code, span: Span) -> Result<u32, Alarm> {
        let form = self.fanuc.definition_form()?;
        if let Some(pending) = self.state.feature_pending
            && (pending.code != code || pending.form != form)
        {
            return Err(self.alarm(
                Condition::FeatureDefinition,
                Some(span),
                format!(
                    "G{} P{} is being defined block by block: its next block must be G{} P{} Q{}",
                    pending.code,
                    pending.form,
                    pending.code,
                    pending.form,
                    pending.last_q + 1
                ),
            ));
        }
        Ok(form)
    }

    /// A block of a definition given block by block (P2: Q0–Q3, P3:
    /// Q1–Q2): the definition so far (a new one before its first block)
    /// and the block's Q, checked to come in order.
    pub(super) fn definition_block(
        &mut self,
        code: Code,
        form: u32,
        name: &str,
        span: Span,
    ) -> Result<(Pending, u32), Alarm> {
        let q = self.definition_step(name, span, definition_last(form))?;
        let pending = self
            .state
            .feature_pending
            .take()
            .unwrap_or_else(|| Pending::new(code, form));
        self.definition_order(&pending, q, name, span)?;
        Ok((pending, q))
    }

    /// After block `q` of a definition given block by block: kept pending
    /// (`None`) until its last block, then the whole definition.
    pub(super) fn definition_hold(&mut self, mut pending: Pending, q: u32) -> Option<Pending> {
        pending.last_q = q;
        pending.started = true;
        if q < definition_last(pending.form) {
            self.state.feature_pending = Some(pending);
            return None;
        }
        Some(pending)
    }

    /// The Q of a multi-block definition block: required, 0 to `last`.
    pub(super) fn definition_step(
        &mut self,
        name: &str,
        span: Span,
        last: u32,
    ) -> Result<u32, Alarm> {
        self.fanuc.definition_step(name, span, last)
    }

    /// Alarms on a definition block out of its order.
    /// Alarms on a definition block out of its order: P2 starts with Q0
    /// or Q1, P3 with Q1, and each block has the next Q.
    pub(super) fn definition_order(
        &self,
        pending: &Pending,
        q: u32,
        name: &str,
        span: Span,
    ) -> Result<(), Alarm> {
        let expected = if pending.started {
            pending.last_q + 1
        } else {
            1
        };
        let first_p2 = !pending.started && pending.form == 2 && q == 0;
        if q == expected || first_p2 {
            return Ok(());
        }
        Err(self.alarm(
            Condition::FeatureDefinition,
            Some(span),
            format!(
                "{name} P{} Q{q} out of order: Q{expected} comes next",
                pending.form
            ),
        ))
    }

    /// In the mode: a block may not start what the tilted plane is not
    /// combined with, nor change the work offset or the setup error.
    pub(in crate::controller) fn feature_restrictions(
        &self,
        codes: &crate::controller::GCodes,
    ) -> Result<(), Alarm> {
        if let Some(pending) = self.state.feature_pending
            && codes.feature.is_none_or(|(_, _, c)| c != pending.code)
        {
            return Err(self.alarm(
                Condition::FeatureDefinition,
                None,
                format!(
                    "G{} P{} is defined block by block: the block after Q{} must be its Q{}",
                    pending.code,
                    pending.form,
                    pending.last_q,
                    pending.last_q + 1
                ),
            ));
        }
        if self.feature().is_none() {
            return Ok(());
        }
        let refused = [
            codes
                .feature
                .filter(|&(what, _, _)| what == FeatureCode::Cancel && self.tcpc_type().is_some())
                .map(|(_, s, c)| {
                    (
                        c,
                        s,
                        "the end of the tilted plane under TCPC: cancel TCPC first",
                    )
                }),
            // Haas's DWO takes its work zero from the offset in force, so
            // the offset may be selected again in it (the NX UMC post
            // writes `G254` then `G54 G90 G00 X… Y…`).
            codes
                .work
                .filter(|_| !self.feature().is_some_and(|f| f.dwo))
                .map(|(_, s, c)| (c, s, "a change of the work offset")),
            codes
                .setup
                .map(|s| (Code::new(54, 4), s, "workpiece setup error correction")),
            codes
                .frames
                .iter()
                .enumerate()
                .filter_map(|(slot, f)| f.map(|f| (slot, f)))
                .find(|&(slot, (on, _, _))| {
                    let nested_conversion = slot == crate::controller::ROTATION
                        && self.conversion_requested()
                        && self.feature().is_some_and(|f| f.conversions > 0);
                    !nested_conversion && on
                })
                .map(|(_, (_, s, c))| (c, s, "a program transform")),
        ];
        match refused.into_iter().flatten().next() {
            Some((code, span, what)) => Err(self.alarm(
                Condition::FeatureNotAllowed,
                Some(span),
                format!("G{code} ({what}) cannot be given in the tilted working plane (G68.2) in this kernel: cancel it with G69 first"),
            )),
            None => Ok(()),
        }
    }

    /// G68.3 X Y Z R: the feature frame whose +Z is the tool axis as the
    /// rotary axes stand (FANUC 30i "tilted working plane based on the
    /// tool axis direction", B-79976E): +X is normal to the plane of +Z and
    /// the vertical axis direction (the machine's +Z, parameter No.12321),
    /// `Xc = V × Zc`, `Yc = Zc × Xc` (+X of the workpiece when the tool
    /// is vertical); R turns the frame about +Z. The origin is X, Y, Z
    /// (absolute whatever G90 / G91), or the current position when all
    /// three are left out; one or two left out is PS5457.
    fn feature_from_tool_axis(&mut self, span: Span) -> Result<(), Alarm> {
        let rules = self.rules();
        let given = self.fanuc.linear_values(&rules);
        let origin = match given.iter().filter(|w| w.is_some()).count() {
            0 => {
                // Where the program stands, in workpiece coordinates.
                self.state.feature = None;
                let p = self.programmed(&self.state.joints);
                Vec3::new(p[0], p[1], p[2])
            }
            3 => Vec3::from(given.map(|v| v.unwrap_or(0.0))),
            _ => {
                return Err(self.alarm(
                    Condition::FeatureOriginIncomplete,
                    Some(span),
                    "G68.3 gives the origin with all of X, Y, Z or none of them".into(),
                ));
            }
        };
        let turn = self.fanuc.rotation_angle(&rules).unwrap_or(0.0);
        let dir = self.machine.forward(&self.state.joints, 0.0).dir;
        let z = self.state.setup.inverse_vector(&dir).normalize();
        let rotation = tool_axis_frame(z) * about(Vec3::z(), turn);
        self.state.feature = Some(Feature {
            origin,
            rotation,
            conversions: 0,
            dwo: false,
        });
        Ok(())
    }

    /// Whether a G68 block asks for a three-dimensional coordinate
    /// conversion: one of I, J, K is given.
    pub(in crate::controller) fn conversion_requested(&self) -> bool {
        self.fanuc.has_vector()
    }

    /// G68 X Y Z I J K R: three-dimensional coordinate conversion (FANUC
    /// 16i/18i/30i): the program's coordinates turn by R degrees about the
    /// axis (I, J, K) through the centre (X, Y, Z), right-handed about
    /// the vector. Centre words left out are where the program stands; R
    /// left out is 0 (No.5410). A second G68 nests inside the first (its
    /// centre and axis in the converted coordinates); a third is PS0049.
    /// In force, the conversion is a feature frame: points, arcs, cycles,
    /// cutter compensation C and the tool length work in it as in the
    /// tilted plane (tool length along the tool). G69 cancels every level.
    pub(in crate::controller) fn conversion_start(
        &mut self,
        span: Span,
        here: &Vec3,
    ) -> Result<(), Alarm> {
        let outer = self.state.feature;
        let depth = match outer {
            Some(f) if f.conversions == 0 => {
                return Err(self.alarm(
                    Condition::FeatureNotAllowed,
                    Some(span),
                    "G68 with I, J, K (three-dimensional coordinate conversion) cannot be given in the tilted working plane (G68.2): cancel it with G69 first".into(),
                ));
            }
            Some(f) if f.conversions >= MAX_CONVERSIONS => {
                return Err(self.alarm(
                    Condition::ConversionCommand,
                    Some(span),
                    format!("G68 three-dimensional coordinate conversion nests at most {MAX_CONVERSIONS} deep: give G69 first"),
                ));
            }
            Some(f) => f.conversions + 1,
            None => {
                self.feature_allowed(span, "G68 with I, J, K")?;
                1
            }
        };
        let mut center = *here;
        let rules = self.rules();
        for (i, value) in self.fanuc.linear_values(&rules).into_iter().enumerate() {
            if let Some(value) = value {
                center[i] = value;
            }
        }
        let axis = self.definition_ijk();
        let angle = self.fanuc.rotation_angle(&rules).unwrap_or(0.0);
        self.definition_finite(
            &[center.x, center.y, center.z, axis.x, axis.y, axis.z, angle],
            "G68",
            span,
        )?;
        if axis.norm() < DEFINITION_TOLERANCE {
            return Err(self.alarm(
                Condition::ConversionCommand,
                Some(span),
                "G68 with I, J, K all 0: the rotation axis has no direction".into(),
            ));
        }
        let rotation = Rotation3::from_axis_angle(&Unit::new_normalize(axis), angle.to_radians());
        let defined = Feature {
            origin: center - rotation * center,
            rotation,
            conversions: depth,
            dwo: false,
        };
        self.state.feature = Some(match outer {
            Some(outer) => Feature {
                origin: outer.work_point(&defined.origin),
                rotation: outer.rotation * defined.rotation,
                conversions: depth,
                dwo: false,
            },
            None => defined,
        });
        Ok(())
    }

    /// The functions the tilted plane is not combined with (yet).
    pub(in crate::controller) fn feature_allowed(
        &self,
        span: Span,
        what: &str,
    ) -> Result<(), Alarm> {
        let conflict = if self.feature().is_some_and(|f| f.conversions > 0) {
            Some("three-dimensional coordinate conversion (G68 with I, J, K)")
        } else if self.feature().is_some_and(|f| f.dwo) {
            Some("the dynamic work offset (G254): give G255 first")
        } else if self.tcpc_type().is_some() {
            Some("tool centre point control (G43.4/G43.5): give G68.2 first")
        } else if self.state.frames.active() {
            Some("a program transform (G68, G51, G51.1, G16)")
        } else if self.state.comp3d.active {
            Some("3-D tool compensation")
        } else {
            None
        };
        match conflict {
            Some(mode) => Err(self.alarm(
                Condition::FeatureNotAllowed,
                Some(span),
                format!("{what} cannot be used with {mode} in this kernel: cancel it first"),
            )),
            None => Ok(()),
        }
    }

    /// G53.1: the rotary axes turn so that the tool stands along the
    /// feature Z; the linear axes stay. G53.6 (`keep_tip`): the same turn
    /// with the tool tip held where it is (the linear axes follow, as in
    /// TCPC).
    pub(in crate::controller) fn tool_axis_control(
        &mut self,
        span: Span,
        keep_tip: bool,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        self.tool_axis_control_by(span, keep_tip, None, out)
    }

    /// The rotary positions (machine order, unwrapped near where the axes
    /// stand) that put the tool along the Z axis of the tilted working
    /// plane in force, chosen by `choice` (or the control's rule): what
    /// G53.1 moves to, and what HEIDENHAIN `PLANE … STAY` computes without
    /// moving. `name` names the function in alarms.
    pub(in crate::controller) fn plane_rotaries(
        &self,
        name: &str,
        span: Span,
        choice: Option<crate::controller::tcpc::Choice>,
    ) -> Result<[f64; 2], Alarm> {
        let Some(feature) = self.state.feature.filter(|f| f.conversions == 0 && !f.dwo) else {
            return Err(self.alarm(
                Condition::FeatureNotAllowed,
                Some(span),
                format!("{name} needs a tilted working plane in force"),
            ));
        };
        if self.machine.rotary.len() != 2 {
            return Err(self.alarm(
                Condition::TcpcWithoutRotaryAxis,
                Some(span),
                format!("{name} needs a machine with two rotary axes"),
            ));
        }
        let z = feature.rotation * Vec3::z();
        let dir = self.state.setup.vector(&z);
        let (i0, i1) = (self.machine.rotary_index(0), self.machine.rotary_index(1));
        let current = self.state.joints;
        match choice {
            Some(choice) => self.choose_rotaries_by(&dir, [current[i0], current[i1]], choice),
            None => self.choose_rotaries(&dir, [current[i0], current[i1]]),
        }
    }

    /// [`Controller::tool_axis_control`] with the rotary solution chosen
    /// by `choice` instead of the control's rule.
    pub(in crate::controller) fn tool_axis_control_by(
        &mut self,
        span: Span,
        keep_tip: bool,
        choice: Option<crate::controller::tcpc::Choice>,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        let name = if keep_tip { "G53.6" } else { "G53.1" };
        let chosen = self.plane_rotaries(name, span, choice)?;
        let (i0, i1) = (self.machine.rotary_index(0), self.machine.rotary_index(1));
        let current = self.state.joints;
        let mut end = current;
        let mut start = current;
        for (k, i) in [i0, i1].into_iter().enumerate() {
            if self.is_rollover(i) {
                end[i] = crate::controller::normalize_360(chosen[k]);
                start[i] = end[i] - (chosen[k] - current[i]);
            } else {
                end[i] = chosen[k];
            }
        }
        if !keep_tip {
            return self.push_line(Motion::Rapid, start, end, out);
        }
        // The tip stays: a TCPC law with a standing tip.
        let tip = self
            .machine
            .programmed_pose(&current, self.feature_tool_length())
            .tip;
        let gauge = self
            .machine
            .gauge_for_programmed_tip(&end, &tip, self.feature_tool_length());
        end[..3].copy_from_slice(gauge.as_slice());
        let path = crate::segment::Path::Tcpc(crate::segment::TcpcPath {
            tip: TipPath::Line([tip, tip]),
            turning: false,
            posture: None,
        });
        let mut seg = self.segment(Motion::Rapid, start, end, path);
        seg.tool_length = self.feature_tool_length();
        if seg.moves() {
            out.push(seg);
        }
        Ok(())
    }

    /// Linear axes that put the tip on programmed point `p` (feature
    /// frame) with the rotary axes at `joints`.
    pub(in crate::controller) fn feature_gauge(&self, joints: &Joints, p: &Vec3) -> Vec3 {
        let tip = self.to_real(p);
        self.machine
            .gauge_for_programmed_tip(joints, &tip, self.feature_tool_length())
    }

    /// The programmed point (feature frame) of the tip at `joints`.
    pub(in crate::controller) fn feature_programmed(&self, joints: &Joints) -> Vec3 {
        let tip = self
            .machine
            .programmed_pose(joints, self.feature_tool_length())
            .tip;
        self.programmed_of_real(&tip)
    }

    /// A path of the feature frame carried into machine X, Y, Z with the
    /// rotary axes at `joints`: the map is a rigid motion, so a circle
    /// stays a circle.
    pub(in crate::controller) fn feature_circle(
        &self,
        joints: &Joints,
        circle: &TipPath,
    ) -> TipPath {
        let origin = self.feature_gauge(joints, &Vec3::zeros());
        circle.mapped(
            |p| self.feature_gauge(joints, p),
            |v| self.feature_gauge(joints, v) - origin,
        )
    }
}
