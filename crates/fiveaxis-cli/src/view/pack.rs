//! The data of `fiveaxis view`, packed for the browser: rows become typed
//! arrays (machine positions as `Float32Array`, times as `Float64Array`,
//! lines as `Uint32Array`, motions as `Uint8Array`), written into the page
//! as base64 text. Pure: no I/O, no machine, no HTML.
//!
//! Two tables come out:
//!
//! * **vertices**: the path as the viewer draws and plays it, one machine
//!   position (every axis) and one time per vertex. The tool tip is not
//!   stored: the viewer computes it by forward kinematics, as the kernel
//!   does for its rows.
//! * **blocks**: one entry per segment (moving block), with its line, its
//!   motion and the time at which it ends.
//!
//! Between two vertices every axis moves linearly in time. A row is left
//! out (simplification) only where that holds to within the tolerance
//! anyway: its tool tip lies within the tolerance of the straight line
//! between the kept vertices around it, every axis within the tolerance
//! (mm or degrees) of its linear interpolation in time, and the motion and
//! the frame do not change there. So points closer than the tolerance on a
//! straight stretch go; a corner, an arc, a change of speed or of colour
//! always stays.

use fiveaxis_machine::{Joints, Vec3};

/// Default simplification tolerance, mm (and degrees): a micrometre, far
/// below a pixel at any zoom that shows a whole part, so nothing visible
/// is ever lost.
pub const DEFAULT_TOLERANCE: f64 = 0.001;

/// Most rows one kept vertex may stand for: bounds the work of each
/// simplification test (every test looks at the rows since the last kept
/// vertex).
pub const MAX_DROPPED_RUN: usize = 256;

/// A sampled point of the path: machine position, tool tip (any fixed
/// frame: it is only compared with its neighbours) and time from the start
/// of the program, seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Every machine axis (the first `axes` entries are used).
    pub joints: Joints,
    /// Tool tip, mm.
    pub tip: Vec3,
    /// Seconds from the program start.
    pub time: f64,
}

/// The path, simplified as it is fed, point by point.
#[derive(Debug)]
pub struct PathPacker {
    axes: usize,
    tolerance: f64,
    /// Kept vertices: `axes` positions each.
    joints: Vec<f32>,
    /// Kept vertices: time, seconds.
    times: Vec<f64>,
    /// The last kept vertex.
    anchor: Option<Point>,
    /// Points after the anchor that may still be left out; the last is the
    /// current end of the straight stretch.
    pending: Vec<Point>,
}

impl PathPacker {
    /// A packer for machines with `axes` axes (at most
    /// [`fiveaxis_machine::MAX_AXES`]) and the given tolerance (mm, deg).
    pub fn new(axes: usize, tolerance: f64) -> Self {
        Self {
            axes,
            tolerance,
            joints: Vec::new(),
            times: Vec::new(),
            anchor: None,
            pending: Vec::with_capacity(MAX_DROPPED_RUN),
        }
    }

    /// Adds the next point. `corner`: the point starts something new (a
    /// block of another motion or frame), so the one before it must stay.
    pub fn push(&mut self, point: Point, corner: bool) {
        let Some(anchor) = self.anchor else {
            self.keep(point);
            return;
        };
        let bent = || !self.pending.iter().all(|p| self.within(&anchor, &point, p));
        if corner || self.pending.len() >= MAX_DROPPED_RUN || bent() {
            self.keep_pending_end();
        }
        self.pending.push(point);
    }

    /// Adds the next point and keeps it whatever its neighbours (the one
    /// before it stays too).
    pub fn push_kept(&mut self, point: Point) {
        self.keep_pending_end();
        self.keep(point);
    }

    /// Keeps the last point (call once after the last [`PathPacker::push`]).
    pub fn finish(&mut self) {
        self.keep_pending_end();
    }

    /// Kept vertices so far.
    pub fn vertex_count(&self) -> usize {
        self.times.len()
    }

    /// Machine positions of the kept vertices, `axes` per vertex.
    pub fn joints(&self) -> &[f32] {
        &self.joints
    }

    /// Times of the kept vertices, seconds.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    fn keep_pending_end(&mut self) {
        if let Some(end) = self.pending.pop() {
            self.pending.clear();
            self.keep(end);
        }
    }

    fn keep(&mut self, point: Point) {
        self.joints
            .extend(point.joints[..self.axes].iter().map(|&x| x as f32));
        self.times.push(point.time);
        self.anchor = Some(point);
    }

    /// Whether `p`, between `a` and `b`, is on their straight stretch: its
    /// tip within the tolerance of the segment a–b, its axes within the
    /// tolerance of their linear interpolation at its time.
    fn within(&self, a: &Point, b: &Point, p: &Point) -> bool {
        let span = b.time - a.time;
        let f = if span > 0.0 {
            ((p.time - a.time) / span).clamp(0.0, 1.0)
        } else {
            // No time passes: the point must be on the segment anyway;
            // nothing to interpolate in time.
            0.0
        };
        if span > 0.0 {
            for i in 0..self.axes {
                let lerp = a.joints[i] + (b.joints[i] - a.joints[i]) * f;
                if (p.joints[i] - lerp).abs() > self.tolerance {
                    return false;
                }
            }
        } else if (0..self.axes).any(|i| (p.joints[i] - a.joints[i]).abs() > self.tolerance) {
            return false;
        }
        distance_to_segment(&p.tip, &a.tip, &b.tip) <= self.tolerance
    }
}

/// Distance of `p` from the segment `a`–`b`.
pub fn distance_to_segment(p: &Vec3, a: &Vec3, b: &Vec3) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t - p).norm()
}

/// Rapid traverse rate used for the timeline, mm/min (deg/min for rotary
/// axes), until the machine model gives each axis its own (`rapid` in the
/// machine file, `machine-model.md` "Axis dynamics").
pub const TIMELINE_RAPID: f64 = 10_000.0;

/// Programmed time of one block, seconds: a cutting move takes its tool-tip
/// path length at the programmed feed, or, when the tip does not move (a
/// rotary axis alone), its largest rotary turn at the feed read as deg/min
/// (FANUC); a rapid move takes its largest axis travel at
/// [`TIMELINE_RAPID`]. `travel` holds each axis' travel (absolute), linear
/// axes first; `first_rotary` is where the rotary axes start.
pub fn block_seconds(
    feed: Option<f64>,
    tip_length: f64,
    travel: &[f64],
    first_rotary: usize,
) -> f64 {
    let longest = |t: &[f64]| t.iter().copied().fold(0.0, f64::max);
    match feed {
        Some(f) if f > 0.0 => {
            let length = if tip_length > TIP_AT_REST {
                tip_length
            } else {
                longest(&travel[first_rotary.min(travel.len())..])
            };
            length / f * 60.0
        }
        _ => longest(travel) / TIMELINE_RAPID * 60.0,
    }
}

/// Tip travel below which a cutting block is a rotary move alone, mm.
pub const TIP_AT_REST: f64 = 1e-9;

/// The bytes of `values` as the browser's typed arrays read them
/// (little-endian).
pub fn f32_bytes(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// See [`f32_bytes`].
pub fn f64_bytes(values: &[f64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// See [`f32_bytes`].
pub fn u32_bytes(values: &[u32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// The bytes of `n`-byte elements regrouped by byte position: every
/// element's first byte, then every second byte, and so on. Neighbouring
/// values of a path share their high bytes, so grouped they compress far
/// better (the viewer regroups them, `viewer/src/data.js`).
pub fn shuffle(bytes: &[u8], width: usize) -> Vec<u8> {
    if width <= 1 || !bytes.len().is_multiple_of(width) {
        return bytes.to_vec();
    }
    let n = bytes.len() / width;
    let mut out = vec![0; bytes.len()];
    for (i, element) in bytes.chunks_exact(width).enumerate() {
        for (b, byte) in element.iter().enumerate() {
            out[b * n + i] = *byte;
        }
    }
    out
}

/// `bytes` compressed in the zlib format (RFC 1950), which the browser's
/// `DecompressionStream("deflate")` reads. The fast level: a large page is
/// written in a fraction of the time the run takes, and most of the gain
/// is there already.
pub fn deflate(bytes: &[u8]) -> Vec<u8> {
    use std::io::Write as _;
    let mut encoder = flate2::write::ZlibEncoder::new(
        Vec::with_capacity(bytes.len() / 2),
        flate2::Compression::fast(),
    );
    // Writing into a Vec cannot fail.
    let _ = encoder.write_all(bytes);
    encoder.finish().unwrap_or_default()
}

const BASE64_ALPHABET: &[u8; 64] =
    b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Standard base64 with padding (RFC 4648 §4), appended to `out`.
pub fn base64_into(bytes: &[u8], out: &mut String) {
    out.reserve(bytes.len().div_ceil(3) * 4);
    let sym = |v: u32, shift: u32| BASE64_ALPHABET[((v >> shift) & 63) as usize] as char;
    let mut chunks = bytes.chunks_exact(3);
    for c in &mut chunks {
        let v = (u32::from(c[0]) << 16) | (u32::from(c[1]) << 8) | u32::from(c[2]);
        out.extend([sym(v, 18), sym(v, 12), sym(v, 6), sym(v, 0)]);
    }
    match *chunks.remainder() {
        [a] => {
            let v = u32::from(a) << 16;
            out.extend([sym(v, 18), sym(v, 12), '=', '=']);
        }
        [a, b] => {
            let v = (u32::from(a) << 16) | (u32::from(b) << 8);
            out.extend([sym(v, 18), sym(v, 12), sym(v, 6), '=']);
        }
        _ => {}
    }
}

/// Standard base64 of `bytes`.
#[cfg(test)]
pub fn base64(bytes: &[u8]) -> String {
    let mut out = String::new();
    base64_into(bytes, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use fiveaxis_machine::MAX_AXES;
    use proptest::prelude::*;

    fn point(x: f64, y: f64, time: f64) -> Point {
        let mut joints = [0.0; MAX_AXES];
        joints[0] = x;
        joints[1] = y;
        Point {
            joints,
            tip: Vec3::new(x, y, 0.0),
            time,
        }
    }

    fn kept_x(p: &PathPacker) -> Vec<f32> {
        p.joints().chunks(2).map(|c| c[0]).collect()
    }

    #[test]
    fn base64_rfc4648_vectors() {
        // RFC 4648 §10 test vectors.
        let cases = [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ];
        for (plain, encoded) in cases {
            assert_eq!(base64(plain.as_bytes()), encoded);
        }
        assert_eq!(base64(&[0xff, 0xfe, 0xfd]), "//79");
    }

    #[test]
    fn typed_array_bytes_are_little_endian() {
        assert_eq!(f32_bytes(&[1.0]), vec![0x00, 0x00, 0x80, 0x3f]);
        assert_eq!(u32_bytes(&[0x0102_0304]), vec![4, 3, 2, 1]);
        assert_eq!(f64_bytes(&[-2.0]), vec![0, 0, 0, 0, 0, 0, 0, 0xc0]);
    }

    #[test]
    fn straight_evenly_timed_points_collapse_to_their_ends() {
        let mut p = PathPacker::new(2, DEFAULT_TOLERANCE);
        for i in 0..=10 {
            p.push(point(f64::from(i), 0.0, f64::from(i)), false);
        }
        p.finish();
        assert_eq!(kept_x(&p), vec![0.0, 10.0]);
        assert_eq!(p.times(), &[0.0, 10.0]);
    }

    #[test]
    fn a_corner_stays() {
        let mut p = PathPacker::new(2, DEFAULT_TOLERANCE);
        let pts = [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (2.0, 1.0), (2.0, 2.0)];
        for (t, (x, y)) in pts.iter().enumerate() {
            p.push(point(*x, *y, t as f64), false);
        }
        p.finish();
        assert_eq!(kept_x(&p), vec![0.0, 2.0, 2.0]);
        assert_eq!(p.times(), &[0.0, 2.0, 4.0]);
    }

    #[test]
    fn a_change_of_speed_stays() {
        // Straight, but the second half twice as slow: the axes are not
        // linear in time across the middle point.
        let mut p = PathPacker::new(2, DEFAULT_TOLERANCE);
        for (x, t) in [(0.0, 0.0), (1.0, 1.0), (2.0, 2.0), (3.0, 4.0), (4.0, 6.0)] {
            p.push(point(x, 0.0, t), false);
        }
        p.finish();
        assert_eq!(kept_x(&p), vec![0.0, 2.0, 4.0]);
    }

    #[test]
    fn a_point_pushed_kept_stays() {
        let mut p = PathPacker::new(2, DEFAULT_TOLERANCE);
        for i in 0..5 {
            let pt = point(f64::from(i), 0.0, f64::from(i));
            if i == 2 {
                p.push_kept(pt)
            } else {
                p.push(pt, false)
            }
        }
        p.finish();
        // The one before stays too.
        assert_eq!(kept_x(&p), vec![0.0, 1.0, 2.0, 4.0]);
    }

    #[test]
    fn a_corner_flag_keeps_the_point_before() {
        let mut p = PathPacker::new(2, DEFAULT_TOLERANCE);
        p.push(point(0.0, 0.0, 0.0), false);
        p.push(point(1.0, 0.0, 1.0), false);
        p.push(point(2.0, 0.0, 2.0), true);
        p.push(point(3.0, 0.0, 3.0), false);
        p.finish();
        assert_eq!(kept_x(&p), vec![0.0, 1.0, 3.0]);
    }

    #[test]
    fn a_bump_below_the_tolerance_goes_one_above_stays() {
        for (bump, kept) in [(0.0005, 2), (0.002, 3)] {
            let mut p = PathPacker::new(2, DEFAULT_TOLERANCE);
            p.push(point(0.0, 0.0, 0.0), false);
            p.push(point(1.0, bump, 1.0), false);
            p.push(point(2.0, 0.0, 2.0), false);
            p.finish();
            assert_eq!(p.vertex_count(), kept, "bump {bump}");
        }
    }

    #[test]
    fn long_straight_runs_are_cut_at_the_bound() {
        let mut p = PathPacker::new(2, DEFAULT_TOLERANCE);
        let n = 3 * MAX_DROPPED_RUN;
        for i in 0..=n {
            p.push(point(i as f64, 0.0, i as f64), false);
        }
        p.finish();
        assert!(
            p.vertex_count() <= n / MAX_DROPPED_RUN + 2,
            "{} kept",
            p.vertex_count()
        );
        assert!(p.vertex_count() >= 2);
        assert_eq!(p.times().last(), Some(&(n as f64)));
    }

    #[test]
    fn block_seconds_by_hand() {
        // 100 mm at F600: 10 s.
        assert_eq!(
            block_seconds(Some(600.0), 100.0, &[60.0, 80.0, 0.0], 3),
            10.0
        );
        // A turn of 90 degrees alone at F900 (deg/min): 6 s.
        assert_eq!(
            block_seconds(Some(900.0), 0.0, &[0.0, 0.0, 0.0, 90.0, 30.0], 3),
            6.0
        );
        // Rapid: the longest axis, 500 mm at the timeline rate.
        let rapid = block_seconds(None, 0.0, &[500.0, 20.0, 0.0], 3);
        assert_eq!(rapid, 500.0 / TIMELINE_RAPID * 60.0);
    }

    proptest! {
        #![proptest_config(ProptestConfig { rng_seed: proptest::test_runner::RngSeed::Fixed(12), ..ProptestConfig::default() })]

        /// Every row left out lies within the tolerance of the straight
        /// line between the kept vertices around it, in tip and in every
        /// axis interpolated in time; the first and last rows are kept.
        #[test]
        fn dropped_rows_are_within_the_tolerance(
            steps in proptest::collection::vec((-1.0f64..1.0, -1.0f64..1.0, 0u8..4, 0.5f64..2.0), 2..200),
        ) {
            let tol = 0.01;
            let mut p = PathPacker::new(2, tol);
            let mut all = Vec::new();
            let (mut x, mut y, mut t) = (0.0, 0.0, 0.0);
            for (dx, dy, kind, dt) in steps {
                // Many straight evenly timed stretches, some noise, some turns.
                let (dx, dy) = match kind {
                    0 => (1.0, 0.0),
                    1 => (1.0, 0.0005 * dy),
                    _ => (dx, dy),
                };
                x += dx;
                y += dy;
                t += if kind < 2 { 1.0 } else { dt };
                let pt = point(x, y, t);
                all.push(pt);
                p.push(pt, false);
            }
            p.finish();
            let kept: Vec<(f64, f64)> = p.times().iter().zip(p.joints().chunks(2)).map(|(&t, j)| (t, f64::from(j[0]))).collect();
            prop_assert_eq!(kept[0].0, all[0].time);
            prop_assert_eq!(kept.last().map(|k| k.0), all.last().map(|a| a.time));
            for pt in &all {
                let k = kept.partition_point(|k| k.0 < pt.time);
                if kept.get(k).is_some_and(|k| k.0 == pt.time) {
                    continue;
                }
                let (a, b) = (&all.iter().find(|q| q.time == kept[k - 1].0).copied(), &all.iter().find(|q| q.time == kept[k].0).copied());
                let (a, b) = (a.unwrap_or(*pt), b.unwrap_or(*pt));
                prop_assert!(distance_to_segment(&pt.tip, &a.tip, &b.tip) <= tol + 1e-12);
                let f = (pt.time - a.time) / (b.time - a.time);
                for i in 0..2 {
                    let lerp = a.joints[i] + (b.joints[i] - a.joints[i]) * f;
                    prop_assert!((pt.joints[i] - lerp).abs() <= tol + 1e-12);
                }
            }
        }
    }
}
