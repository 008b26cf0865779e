//! The singular direction of a two-rotary machine and the smallest angle
//! a block's tool direction makes with it, in closed form.
//!
//! The singular direction is the line of the rotating axis: the outer head
//! axis of a head-head machine, the table axis nearer the part of a
//! table-table machine, the table axis of a mixed one (where the inverse
//! kinematics of `fiveaxis-machine` leaves that axis free). In the table
//! frame that line is fixed, and the tool direction's component along it
//! does not depend on the rotating axis at all: turning about a line keeps
//! the component along it. So along it the direction is a function of the
//! other (tilt) axis alone, and by Rodrigues' formula of the form
//! `A + B·cos φ + C·sin φ`. When the rotary axes move linearly in a block
//! (machine-axis moves, TCPC without tool posture control) φ moves
//! linearly, and the largest `|A + B cos φ + C sin φ|` over the block is
//! at an end or where `φ = atan2(C, B) + k·180°`: the smallest angle is
//! exact. Under tool posture control the direction turns on a great
//! circle, `e0·cos ψ + w·sin ψ`, whose component along the line has the
//! same form in ψ: exact again.

use fiveaxis_control::Posture;
use fiveaxis_machine::{Joints, MAX_AXES, Machine, Side, Vec3, sin_cos_degrees};

/// The singular line of a machine and the law of the tool direction's
/// component along it.
#[derive(Clone, Copy, Debug)]
pub struct Singular {
    /// Unit direction of the rotating axis' line (table frame).
    line: Vec3,
    /// Joint index of the tilt axis (the other rotary axis).
    tilt: usize,
    /// `line · dir = a + b·cos φ + c·sin φ`, φ the tilt angle.
    a: f64,
    b: f64,
    c: f64,
}

impl Singular {
    /// The singular line of a machine with two rotary axes; `None` for
    /// other machines.
    pub fn of(machine: &Machine) -> Option<Self> {
        if machine.rotary.len() != 2 {
            return None;
        }
        let rotating = match (machine.rotary[0].on, machine.rotary[1].on) {
            (Side::Head, Side::Head) | (Side::Table, Side::Head) => 0,
            (Side::Table, Side::Table) | (Side::Head, Side::Table) => 1,
        };
        let line = machine.rotary[rotating].axis.into_inner();
        let tilt = machine.rotary_index(1 - rotating);
        let along = |phi: f64| {
            let mut joints: Joints = [0.0; MAX_AXES];
            joints[tilt] = phi;
            line.dot(&machine.forward(&joints, 0.0).dir)
        };
        let (c0, c90, c180) = (along(0.0), along(90.0), along(180.0));
        let a = 0.5 * (c0 + c180);
        Some(Self {
            line,
            tilt,
            a,
            b: 0.5 * (c0 - c180),
            c: c90 - a,
        })
    }

    /// Angle in degrees between a direction and the singular line.
    pub fn angle(&self, dir: &Vec3) -> f64 {
        let d = dir.normalize();
        self.line
            .cross(&d)
            .norm()
            .atan2(self.line.dot(&d).abs())
            .to_degrees()
    }

    /// Smallest angle to the singular line while the tilt axis moves
    /// linearly from `from` to `to` (degrees): the angle and the tilt
    /// angle where it is reached.
    pub fn smallest_on_tilt(&self, machine: &Machine, joints: &Joints, to: f64) -> (f64, f64) {
        let from = joints[self.tilt];
        let phi = best_angle(from, to, self.b, self.c, |phi| {
            let (s, c) = sin_cos_degrees(phi);
            (self.a + self.b * c + self.c * s).abs()
        });
        let mut at = *joints;
        at[self.tilt] = phi;
        (self.angle(&machine.forward(&at, 0.0).dir), phi)
    }

    /// The joint index of the tilt axis.
    pub fn tilt(&self) -> usize {
        self.tilt
    }

    /// Smallest angle to the singular line along a posture-controlled
    /// block (the tool on the great circle from `ends[0]` to `ends[1]`).
    pub fn smallest_on_posture(&self, posture: &Posture) -> f64 {
        let [e0, e1] = posture.ends.map(|e| e.normalize());
        let across = e1 - e0 * e0.dot(&e1);
        if across.norm() < 1e-12 {
            return self.angle(&e0).min(self.angle(&e1));
        }
        let w = across.normalize();
        let total = e0.cross(&e1).norm().atan2(e0.dot(&e1)).to_degrees();
        let (p, q) = (self.line.dot(&e0), self.line.dot(&w));
        let psi = best_angle(0.0, total, p, q, |psi| {
            let (s, c) = sin_cos_degrees(psi);
            (p * c + q * s).abs()
        });
        let (s, c) = sin_cos_degrees(psi);
        self.angle(&(e0 * c + w * s))
    }
}

/// Of the angles from `from` to `to` (degrees), the one where `size`
/// (`|a + b cos x + c sin x|`) is largest: an end, or a critical point
/// `atan2(c, b) + k·180°` inside the range.
fn best_angle(from: f64, to: f64, b: f64, c: f64, size: impl Fn(f64) -> f64) -> f64 {
    let (lo, hi) = (from.min(to), from.max(to));
    let mut best = (from, size(from));
    let mut consider = |x: f64| {
        let v = size(x);
        if v > best.1 {
            best = (x, v);
        }
    };
    consider(to);
    if b != 0.0 || c != 0.0 {
        let peak = c.atan2(b).to_degrees();
        // The first critical point at or above `lo`; a range of any size
        // holds at most a bounded number worth looking at: past two turns
        // every value repeats.
        let first = peak + ((lo - peak) / 180.0).ceil() * 180.0;
        let mut x = first;
        let mut count = 0;
        while x <= hi && count < 4 {
            consider(x);
            x += 180.0;
            count += 1;
        }
    }
    best.0
}
