//! Forward kinematics (`machine-model.md` §3), the one source of the tool
//! tip and tool direction that the kernel reports.

use nalgebra::{IsometryMatrix3, Rotation3, Translation3, Unit};

use crate::{Joints, MAX_ROTARY, Machine, Side, Vec3};

/// Where the tool is: tip and direction (tip → spindle, unit) in one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Tool tip, mm.
    pub tip: Vec3,
    /// Unit tool direction, tip towards spindle.
    pub dir: Vec3,
}

/// `p` turned by `degrees` about the line through `center` along unit
/// `axis`, right-hand rule: what [`rotation`] about that line gives,
/// without building the matrix (Rodrigues' formula on the vector).
#[inline]
pub fn turn_about(axis: &Unit<Vec3>, center: &Vec3, degrees: f64, p: &Vec3) -> Vec3 {
    let (sin, cos) = sin_cos_degrees(degrees);
    center + turn(axis, &(p - center), sin, cos)
}

/// Rotation by `degrees` about `axis`, right-hand rule.
pub fn rotation(axis: &Unit<Vec3>, degrees: f64) -> Rotation3<f64> {
    let (sin, cos) = sin_cos_degrees(degrees);
    let k = axis.as_ref();
    // Rodrigues: R = cos·I + sin·[k]× + (1 − cos)·k kᵀ.
    let c1 = 1.0 - cos;
    Rotation3::from_matrix_unchecked(nalgebra::Matrix3::new(
        cos + k.x * k.x * c1,
        k.x * k.y * c1 - k.z * sin,
        k.x * k.z * c1 + k.y * sin,
        k.y * k.x * c1 + k.z * sin,
        cos + k.y * k.y * c1,
        k.y * k.z * c1 - k.x * sin,
        k.z * k.x * c1 - k.y * sin,
        k.z * k.y * c1 + k.x * sin,
        cos + k.z * k.z * c1,
    ))
}

/// Sine and cosine of an angle in degrees, to within an ulp or two.
///
/// The angle is first reduced to `[-45°, 45°]` by a multiple of 90°, which
/// is exact in degrees (`x − 90·n` is representable for every `x` below
/// 2^53 and `n` its nearest quarter turn), so that a rotary axis at
/// 13,783° is as exact as one at 103°: better than reducing in radians
/// after `to_radians`, whose product is rounded at the angle's magnitude.
/// On the reduced angle, in radians (|t| ≤ π/4), the Taylor series of sine
/// to t¹⁵ and of cosine to t¹⁶ leave less than 5·10⁻¹⁷; the quarter turns
/// are then swaps and signs. Several times faster than the library's
/// `sin_cos` on the radian value, which is what forward kinematics spends
/// most of its time on.
#[inline]
pub fn sin_cos_degrees(degrees: f64) -> (f64, f64) {
    if !degrees.is_finite() || degrees.abs() >= EXACT_REDUCTION_LIMIT {
        return degrees.to_radians().sin_cos();
    }
    // The nearest quarter turn by a truncating conversion (one
    // instruction; `round` and `rem_euclid` are library calls on the
    // baseline x86-64 target).
    let half = if degrees < 0.0 { -0.5 } else { 0.5 };
    let quarters = (degrees / 90.0 + half) as i64;
    let t = (degrees - 90.0 * quarters as f64) * (std::f64::consts::PI / 180.0);
    let t2 = t * t;
    // Horner in t²: 1/(2k+1)! and 1/(2k)! with alternating signs.
    let sin = t
        * (1.0
            + t2 * (-1.0 / 6.0
                + t2 * (1.0 / 120.0
                    + t2 * (-1.0 / 5040.0
                        + t2 * (1.0 / 362_880.0
                            + t2 * (-1.0 / 39_916_800.0
                                + t2 * (1.0 / 6_227_020_800.0
                                    + t2 * (-1.0 / 1_307_674_368_000.0))))))));
    let cos = 1.0
        + t2 * (-0.5
            + t2 * (1.0 / 24.0
                + t2 * (-1.0 / 720.0
                    + t2 * (1.0 / 40_320.0
                        + t2 * (-1.0 / 3_628_800.0
                            + t2 * (1.0 / 479_001_600.0
                                + t2 * (-1.0 / 87_178_291_200.0
                                    + t2 * (1.0 / 20_922_789_888_000.0))))))));
    // n mod 4, also for negative n (two's complement).
    match quarters & 3 {
        0 => (sin, cos),
        1 => (cos, -sin),
        2 => (-sin, -cos),
        _ => (-cos, sin),
    }
}

/// Angles at or beyond this many degrees go to the library's `sin_cos`
/// (the quarter-turn count stays far inside exact integers below it).
const EXACT_REDUCTION_LIMIT: f64 = 1e12;

/// The rigid map of a rotation by `degrees` about the line through `center`
/// along `axis`: `p ↦ center + R·(p − center)`.
pub(crate) fn rotation_about(
    axis: &Unit<Vec3>,
    center: &Vec3,
    degrees: f64,
) -> IsometryMatrix3<f64> {
    let r = rotation(axis, degrees);
    let t = center - r * center;
    IsometryMatrix3::from_parts(Translation3::from(t), r)
}

impl Machine {
    /// The map of the outermost body of one side's chain, bed outwards
    /// `[k1, k2]` giving `M1 ∘ M2`. Head maps act on coordinates relative to
    /// the spindle gauge point; table maps on machine coordinates.
    pub fn chain(&self, side: Side, joints: &Joints) -> IsometryMatrix3<f64> {
        let mut map = IsometryMatrix3::identity();
        for (k, axis) in self.rotary.iter().enumerate() {
            if axis.on == side {
                let angle = joints[self.rotary_index(k)];
                map *= rotation_about(&axis.axis, &axis.center, angle);
            }
        }
        map
    }

    /// Forward kinematics: the tool tip and direction in the table frame
    /// for these machine positions and tool length `tool_length` (the
    /// active H value, 0 without length compensation).
    ///
    /// The same maps as [`Machine::chain`], applied to the two vectors
    /// directly (Rodrigues' formula) rather than composed as matrices: the
    /// head axes turn the tool from the innermost outwards, then the table
    /// axes are undone from the bed outwards. A quill ([`crate::Along::Tool`])
    /// at W puts the tip at `(X, Y, Z) + H((W − L)·t0)`, the contract's
    /// formula with `W − L` for `−L` (`machine-model.md` §3 extended as
    /// its §4 foresees, "more linear axes, e.g. W, allowed later").
    pub fn forward(&self, joints: &Joints, tool_length: f64) -> Pose {
        let (tip, dir) = self.turn_tool::<true>(joints, tool_length);
        Pose { tip, dir }
    }

    /// The tip of [`Machine::forward`] alone, the same to the last bit,
    /// without turning the direction: for the checks that sample where
    /// the tip goes.
    #[inline]
    pub fn forward_tip(&self, joints: &Joints, tool_length: f64) -> Vec3 {
        self.turn_tool::<false>(joints, tool_length).0
    }

    /// The tip, and with `DIRECTION` the tool direction (else `t0`), as
    /// [`Machine::forward`] describes.
    #[inline]
    fn turn_tool<const DIRECTION: bool>(&self, joints: &Joints, tool_length: f64) -> (Vec3, Vec3) {
        let t0 = self.tool_direction.into_inner();
        // A quill along the tool moves the tip before the head turns it.
        let mut tip = (self.quill(joints) - tool_length) * t0;
        let mut dir = t0;
        let first = self.linear.len();
        for (k, axis) in self.rotary.iter().enumerate().rev() {
            if axis.on == Side::Head {
                let (sin, cos) = sin_cos_degrees(joints[first + k]);
                tip = axis.center + turn(&axis.axis, &(tip - axis.center), sin, cos);
                if DIRECTION {
                    dir = turn(&axis.axis, &dir, sin, cos);
                }
            }
        }
        tip += Vec3::new(joints[0], joints[1], joints[2]);
        for (k, axis) in self.rotary.iter().enumerate() {
            if axis.on == Side::Table {
                let (sin, cos) = sin_cos_degrees(joints[first + k]);
                tip = axis.center + turn(&axis.axis, &(tip - axis.center), -sin, cos);
                if DIRECTION {
                    dir = turn(&axis.axis, &dir, -sin, cos);
                }
            }
        }
        (tip, dir)
    }
}

impl Machine {
    /// [`Machine::forward`] with the quill ([`crate::Along::Tool`]) at 0:
    /// the point TCPC and the tilted working plane program (the inverse
    /// of [`Machine::gauge_for_programmed_tip`]). Without a quill it is
    /// `forward`.
    pub fn programmed_pose(&self, joints: &Joints, tool_length: f64) -> Pose {
        match self.quill_index() {
            Some(i) if joints[i] != 0.0 => {
                let mut j = *joints;
                j[i] = 0.0;
                self.forward(&j, tool_length)
            }
            _ => self.forward(joints, tool_length),
        }
    }
}

/// The forward kinematics of one machine laid out for many evaluations:
/// the rotary axes of each side as plain arrays in the order
/// [`Machine::forward`] applies them, the quill's index found once. Its
/// tips are [`Machine::forward_tip`]'s to the last bit (the same
/// operations in the same order); the checks that sample a block many
/// times make one per block.
#[derive(Clone, Copy, Debug)]
pub struct TipChain {
    t0: Vec3,
    quill: Option<usize>,
    /// Head axes, innermost first: axis, centre, joint index.
    head: [(Vec3, Vec3, usize); MAX_ROTARY],
    heads: usize,
    /// Table axes, bed outwards.
    table: [(Vec3, Vec3, usize); MAX_ROTARY],
    tables: usize,
}

impl TipChain {
    /// The chain of `machine`.
    pub fn new(machine: &Machine) -> Self {
        let none = (Vec3::zeros(), Vec3::zeros(), 0);
        let mut chain = Self {
            t0: machine.tool_direction.into_inner(),
            quill: machine.quill_index(),
            head: [none; MAX_ROTARY],
            heads: 0,
            table: [none; MAX_ROTARY],
            tables: 0,
        };
        let first = machine.linear.len();
        for (k, axis) in machine.rotary.iter().enumerate().rev() {
            if axis.on == Side::Head && chain.heads < MAX_ROTARY {
                chain.head[chain.heads] = (axis.axis.into_inner(), axis.center, first + k);
                chain.heads += 1;
            }
        }
        for (k, axis) in machine.rotary.iter().enumerate() {
            if axis.on == Side::Table && chain.tables < MAX_ROTARY {
                chain.table[chain.tables] = (axis.axis.into_inner(), axis.center, first + k);
                chain.tables += 1;
            }
        }
        chain
    }

    /// The tool tip for these machine positions and tool length.
    #[inline]
    pub fn tip(&self, joints: &Joints, tool_length: f64) -> Vec3 {
        let along = self.quill.map_or(0.0, |i| joints[i]);
        let mut tip = (along - tool_length) * self.t0;
        for (axis, center, j) in &self.head[..self.heads] {
            let (sin, cos) = sin_cos_degrees(joints[*j]);
            tip = center + turn_vec(axis, &(tip - center), sin, cos);
        }
        tip += Vec3::new(joints[0], joints[1], joints[2]);
        for (axis, center, j) in &self.table[..self.tables] {
            let (sin, cos) = sin_cos_degrees(joints[*j]);
            tip = center + turn_vec(axis, &(tip - center), -sin, cos);
        }
        tip
    }
}

/// `v` turned about unit `axis` by the angle whose sine and cosine are
/// given (Rodrigues: v·cos + (k × v)·sin + k·(k·v)·(1 − cos)).
#[inline]
fn turn(axis: &Unit<Vec3>, v: &Vec3, sin: f64, cos: f64) -> Vec3 {
    turn_vec(axis.as_ref(), v, sin, cos)
}

/// [`turn`] about a unit vector given as a plain one.
#[inline]
fn turn_vec(k: &Vec3, v: &Vec3, sin: f64, cos: f64) -> Vec3 {
    v * cos + k.cross(v) * sin + k * (k.dot(v) * (1.0 - cos))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The library's sine and cosine of the radian value, within an ulp or
    /// two where that value is exact enough to compare (|x| ≤ 720°, where
    /// `to_radians` rounds at most 1e-16·12.6 rad).
    #[test]
    fn sin_cos_degrees_agrees_with_the_library() {
        let mut x = -720.0_f64;
        let mut worst = 0.0_f64;
        while x <= 720.0 {
            let (s, c) = sin_cos_degrees(x);
            let (rs, rc) = x.to_radians().sin_cos();
            worst = worst.max((s - rs).abs()).max((c - rc).abs());
            assert!((s * s + c * c - 1.0).abs() < 5e-16, "{x}");
            x += 0.013_7;
        }
        assert!(worst < 3e-15, "{worst}");
    }

    #[test]
    fn sin_cos_degrees_is_exact_on_quarter_turns_and_known_angles() {
        for n in -8_i32..=8 {
            let (s, c) = sin_cos_degrees(90.0 * f64::from(n));
            let expect =
                [(0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0)][n.rem_euclid(4) as usize];
            // -0.0 == 0.0: the values, not the signs of zero.
            assert!(s == expect.0 && c == expect.1, "{n}: {s} {c}");
        }
        let (s, c) = sin_cos_degrees(30.0);
        assert!((s - 0.5).abs() <= f64::EPSILON && (c - 0.75_f64.sqrt()).abs() <= f64::EPSILON);
        // A rollover axis far out: 13,783.15° is 103.15° after 38 turns,
        // reduced exactly in degrees.
        let (s, c) = sin_cos_degrees(13_783.15);
        let (rs, rc) = (13_783.15_f64 - 38.0 * 360.0).to_radians().sin_cos();
        assert!((s - rs).abs() < 3e-16 && (c - rc).abs() < 3e-16);
        let (s, c) = sin_cos_degrees(f64::NAN);
        assert!(s.is_nan() && c.is_nan());
    }

    #[test]
    fn tip_chain_is_forward_tip_to_the_last_bit() {
        for name in crate::builtin_names() {
            let machine = crate::builtin(name).expect("built in");
            let chain = TipChain::new(&machine);
            let mut joints = [0.0; crate::MAX_AXES];
            for step in 0..50 {
                let t = f64::from(step);
                for (i, j) in joints.iter_mut().enumerate().take(machine.axis_count()) {
                    *j = (t * 37.3 + i as f64 * 11.1).sin() * 170.0;
                }
                let pose = machine.forward(&joints, 12.5);
                assert_eq!(chain.tip(&joints, 12.5), pose.tip, "{name}");
                assert_eq!(machine.forward_tip(&joints, 12.5), pose.tip, "{name}");
            }
        }
    }

    #[test]
    fn rotation_is_the_axis_angle_rotation() {
        let axis = Unit::new_normalize(Vec3::new(0.3, -0.5, 0.8));
        for degrees in [-400.0, -90.0, -12.5, 0.0, 33.0, 179.0, 271.0] {
            let ours = rotation(&axis, degrees);
            let theirs = Rotation3::from_axis_angle(&axis, f64::to_radians(degrees));
            assert!(
                (ours.matrix() - theirs.matrix()).amax() < 1e-15,
                "{degrees}"
            );
        }
    }
}
