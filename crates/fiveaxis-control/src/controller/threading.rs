//! LinuxCNC's spindle-synchronized motion (`control = "linuxcnc"`;
//! g-code.adoc, G33, G33.1, G76): moves whose feed is a distance per
//! spindle revolution.
//!
//! * `G33 X Y Z K`: a straight move at K per revolution along it.
//! * `G33.1 X Y Z K I`: rigid tapping, to the point at K per revolution
//!   and back to the start at I times that (I below 1 counts as 1). The
//!   overshoot while the spindle reverses is a matter of the drive's
//!   dynamics, not of the program: the kernel's path turns at the point.
//! * `G76 P Z I J K R Q H E L`: the threading cycle in the ZX plane, made
//!   of G33 passes. The rules below are the manual's words, with the
//!   figures it leaves open measured on `rs274 -g` (2.9):
//!   - the drive line is the X where the tool stands, the thread from its
//!     Z to the cycle's Z; the thread peak is at X + I (I < 0 external,
//!     I > 0 internal), and each pass cuts deeper than the peak, away from
//!     the drive line's side, by `d_n = J·n^(1/R)` (R 1: constant depth,
//!     R 2: constant area, as the manual describes), while `d_n < K`; then
//!     one pass at the full depth K and H spring passes there;
//!   - a pass at depth d is the final pass shifted along the drive line by
//!     `(K − d)·tan Q` towards the start (Q, the compound slide angle):
//!     it starts `d·tan Q` past the thread's start and ends
//!     `(K − d)·tan Q` short of its end (rs274: Q29.5, the first pass of
//!     J0.008 starts 0.0045 in past the start);
//!   - between passes the tool stands on the line `K − d` outside the
//!     drive line (the final pass returns to the drive line itself); it
//!     reaches a pass's start by a rapid move there, then rapid to the
//!     cutting depth, or with an entry taper (L1, L3) at the taper's feed
//!     to K short of the depth and then along the taper, E long; an exit
//!     taper (L2, L3) climbs K over the last E; the tool leaves the cut
//!     by a rapid move back to its line, and the cycle ends at the end of
//!     the drive line;
//!   - a taper's feed keeps the pitch along Z: `P·√(E² + K²) / E` per
//!     revolution along the taper (rs274: 1.166190 for P1, E1, K0.6).

use fiveaxis_machine::Joints;

use super::Controller;
use super::cycles::MAX_CYCLE_SEGMENTS;
use super::linuxcnc::NgcMotion;
use crate::alarm::{Alarm, Condition};
use crate::fanuc::ThreadData;
use crate::modal::Plane;
use crate::segment::{Motion, Path, Segment};

/// Most passes of one G76 block, below the full depth and again as spring
/// passes (each makes up to six moves).
const MAX_PASSES: u32 = (MAX_CYCLE_SEGMENTS / 8) as u32;

impl Controller<'_> {
    /// A block in G33, G33.1 or G76 mode.
    pub(super) fn sync_motion(
        &mut self,
        mode: NgcMotion,
        from: &Joints,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        if mode == NgcMotion::ThreadingCycle {
            return self.threading_cycle(from, out);
        }
        let name = if mode == NgcMotion::Thread {
            "G33"
        } else {
            "G33.1"
        };
        let targets = self.axis_words();
        let rules = self.rules();
        let pitch = self.fanuc.sync_pitch(name, &rules)?;
        let multiplier = if mode == NgcMotion::RigidTap {
            self.fanuc.retract_multiplier()
        } else {
            1.0
        };
        let rate = self.sync_rate(pitch, name)?;
        let (end_p, _) = self.end_point(from, &targets);
        let start = self.state.joints;
        let end = self.machine_position(&end_p);
        self.push_sync(start, end, rate, out);
        if mode == NgcMotion::RigidTap {
            self.push_sync(end, start, rate * multiplier, out);
        }
        Ok(())
    }

    /// The feed, mm/min, of `pitch` per revolution of the spindle; the
    /// spindle must turn (g-code.adoc, G33: an error if "the selected
    /// spindle is not commanded to turn").
    fn sync_rate(&self, pitch: f64, name: &str) -> Result<f64, Alarm> {
        if !self.state.spindle_on || self.state.spindle_speed <= 0.0 {
            return Err(self.alarm(
                Condition::NoSpindleForFeedPerRev,
                None,
                format!("{name} with the spindle stopped: its feed is per revolution (M3 or M4)"),
            ));
        }
        Ok(pitch * self.state.spindle_speed)
    }

    /// A synchronized straight move at `rate` mm/min.
    fn push_sync(&self, start: Joints, end: Joints, rate: f64, out: &mut Vec<Segment>) {
        let mut seg = self.segment(Motion::Linear, start, end, Path::Joint);
        if seg.moves() {
            seg.feed = Some(rate);
            out.push(seg);
        }
    }

    /// G76: the threading passes, from where the tool stands.
    fn threading_cycle(&mut self, from: &Joints, out: &mut Vec<Segment>) -> Result<(), Alarm> {
        if self.state.modal.plane != Plane::Zx {
            return Err(self.alarm(
                Condition::CycleNotAllowed,
                None,
                "G76 threads in the ZX plane: select G18".into(),
            ));
        }
        let rules = self.rules();
        let data = self
            .fanuc
            .thread_data(&rules, self.state.modal.diameter_mode, MAX_PASSES)?;
        let ThreadData {
            pitch,
            peak_offset,
            first,
            full,
            degression,
            compound,
            spring,
            taper,
            ends,
            ..
        } = data;
        let z_end = if self.state.modal.distance == crate::modal::Distance::Incremental {
            from[2] + data.z
        } else {
            data.z
        };
        let drive = from[0];
        let z_start = from[2];
        let length = (z_end - z_start).abs();
        let taper = match taper {
            Some((e, span)) if e < 0.0 || e > length / 2.0 => {
                return Err(self.alarm(
                    Condition::ValueOutOfRange,
                    Some(span),
                    format!("G76: E{e} is beyond half the drive line's length {length}"),
                ));
            }
            Some((e, _)) => e,
            None => 0.0,
        };
        let rate = self.sync_rate(pitch, "G76")?;
        // Passes: depths J·n^(1/R) below K, then K, then H more at K.
        let depth = |n: u32| first * f64::from(n).powf(1.0 / degression);
        let mut below = 0u32;
        while depth(below + 1) < full {
            below += 1;
            if below > MAX_PASSES {
                return Err(self.alarm(
                    Condition::ValueOutOfRange,
                    Some(data.first_span),
                    format!(
                        "G76: a first cut of {first} mm to a full depth of {full} mm with R{degression} makes more than {MAX_PASSES} passes",
                    ),
                ));
            }
        }
        // Depth grows away from the drive line on the peak's side.
        let into = if peak_offset > 0.0 { 1.0 } else { -1.0 };
        let along = if z_end >= z_start { 1.0 } else { -1.0 };
        let tan_q = compound.to_radians().tan();
        let (entry, exit) = (ends & 1 != 0 && taper > 0.0, ends & 2 != 0 && taper > 0.0);
        let taper_rate = if taper > 0.0 {
            rate * taper.hypot(full) / taper
        } else {
            rate
        };
        let mut cur = self.state.joints;
        let at = |c: &Self, x: f64, z: f64| {
            let mut p = *from;
            p[0] = x;
            p[2] = z;
            c.machine_position(&p)
        };
        for pass in 1..=below + 1 + spring {
            let d = if pass <= below { depth(pass) } else { full };
            let cut_x = drive + peak_offset + into * d;
            let line_x = drive - into * (full - d);
            let zs = z_start + along * d * tan_q;
            let ze = z_end - along * (full - d) * tan_q;
            let next = at(self, line_x, zs);
            self.push_line(Motion::Rapid, cur, next, out)?;
            cur = next;
            if entry {
                let next = at(self, cut_x - into * full, zs);
                self.push_sync(cur, next, taper_rate, out);
                cur = next;
                let next = at(self, cut_x, zs + along * taper);
                self.push_sync(cur, next, taper_rate, out);
                cur = next;
            } else {
                let next = at(self, cut_x, zs);
                self.push_line(Motion::Rapid, cur, next, out)?;
                cur = next;
            }
            if exit {
                let next = at(self, cut_x, ze - along * taper);
                self.push_sync(cur, next, rate, out);
                cur = next;
                let next = at(self, cut_x - into * full, ze);
                self.push_sync(cur, next, taper_rate, out);
                cur = next;
            } else {
                let next = at(self, cut_x, ze);
                self.push_sync(cur, next, rate, out);
                cur = next;
            }
            let next = at(self, line_x, ze);
            self.push_line(Motion::Rapid, cur, next, out)?;
            cur = next;
        }
        let next = at(self, drive, z_end);
        self.push_line(Motion::Rapid, cur, next, out)?;
        Ok(())
    }
}
