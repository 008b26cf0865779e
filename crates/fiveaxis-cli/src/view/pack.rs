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

use std::borrow::Cow;
use std::io::{self, Write};

use fiveaxis_machine::{Joints, Vec3};
use flate2::Compression;

/// Default simplification tolerance, mm (and degrees): a micrometre, far
/// below a pixel at any zoom that shows a whole part, so nothing visible
/// is ever lost.
pub const DEFAULT_TOLERANCE: f64 = 0.001;

/// Most rows one kept vertex may stand for: bounds the work of each
/// simplification test (every test looks at the rows since the last kept
/// vertex).
pub const MAX_DROPPED_RUN: usize = 256;

/// Most vertices a page holds. Past them the path is simplified again
/// with twice the tolerance, as often as it takes: a screen shows far
/// fewer distinct points (a million vertices are 28 MB of arrays for five
/// axes, about what a browser reads in a second or two).
pub const MAX_VERTICES: usize = 1_000_000;

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
    /// Kept vertices: tool tip (for simplifying them again).
    tips: Vec<[f32; 3]>,
    /// Kept vertices that stay whatever the tolerance (a corner, the
    /// first and the last).
    stays: Vec<bool>,
    /// Most vertices kept ([`MAX_VERTICES`]).
    budget: usize,
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
            tips: Vec::new(),
            stays: Vec::new(),
            budget: MAX_VERTICES,
            anchor: None,
            pending: Vec::with_capacity(MAX_DROPPED_RUN),
        }
    }

    /// The same packer holding at most `budget` vertices (at least 16).
    #[cfg(test)]
    #[must_use]
    pub fn with_budget(mut self, budget: usize) -> Self {
        self.budget = budget.max(16);
        self
    }

    /// The tolerance the kept vertices are simplified to: the one given,
    /// or a multiple of it when the budget made the path coarser.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// Adds the next point. `corner`: the point starts something new (a
    /// block of another motion or frame), so the one before it must stay.
    pub fn push(&mut self, point: Point, corner: bool) {
        let Some(anchor) = self.anchor else {
            self.keep(point, true);
            return;
        };
        let bent = || !self.pending.iter().all(|p| self.within(&anchor, &point, p));
        if corner {
            self.keep_pending_end(true);
        } else if self.pending.len() >= MAX_DROPPED_RUN || bent() {
            self.keep_pending_end(false);
        }
        self.pending.push(point);
    }

    /// Adds the next point and keeps it whatever its neighbours (the one
    /// before it stays too).
    pub fn push_kept(&mut self, point: Point) {
        self.keep_pending_end(true);
        self.keep(point, true);
    }

    /// Keeps the last point (call once after the last [`PathPacker::push`]).
    pub fn finish(&mut self) {
        self.keep_pending_end(true);
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

    /// Times of the kept vertices, to be moved to another timeline
    /// ([`retime`]).
    pub fn times_mut(&mut self) -> &mut [f64] {
        &mut self.times
    }

    fn keep_pending_end(&mut self, stays: bool) {
        if let Some(end) = self.pending.pop() {
            self.pending.clear();
            self.keep(end, stays);
        } else if stays && let Some(last) = self.stays.last_mut() {
            *last = true;
        }
    }

    fn keep(&mut self, point: Point, stays: bool) {
        self.joints
            .extend(point.joints[..self.axes].iter().map(|&x| x as f32));
        self.times.push(point.time);
        self.tips
            .push([point.tip.x as f32, point.tip.y as f32, point.tip.z as f32]);
        self.stays.push(stays);
        self.anchor = Some(point);
        if self.times.len() > self.budget {
            self.thin();
        }
    }

    /// Simplifies the kept vertices again with twice the tolerance (eight
    /// times, after a pass that left nine in ten) until at most half the
    /// budget stay. Once the tolerance is past any
    /// machine's size the corners go too (only the first and last vertex
    /// stay), so that every pass leaves at most one in
    /// [`MAX_DROPPED_RUN`] of a run and the budget is always met.
    fn thin(&mut self) {
        let mut factor = 2.0;
        while self.times.len() > self.budget / 2 {
            let before = self.times.len();
            self.tolerance *= factor;
            if self.tolerance > LOOSEST {
                let n = self.stays.len();
                for (i, stays) in self.stays.iter_mut().enumerate() {
                    *stays = i == 0 || i + 1 == n;
                }
            }
            self.simplify_kept();
            // A pass that left nearly all (a path of sharp turns, far
            // apart): the next one jumps further.
            if self.times.len() * 10 > before * 9 {
                factor = 8.0;
            }
        }
    }

    /// The kept vertex `i` as a point (the joints and tip to `f32`).
    fn vertex(&self, i: usize) -> Point {
        let mut joints = [0.0; fiveaxis_machine::MAX_AXES];
        for (k, x) in self.joints[i * self.axes..(i + 1) * self.axes]
            .iter()
            .enumerate()
        {
            joints[k] = f64::from(*x);
        }
        let [x, y, z] = self.tips[i];
        Point {
            joints,
            tip: Vec3::new(f64::from(x), f64::from(y), f64::from(z)),
            time: self.times[i],
        }
    }

    /// Moves kept vertex `from` to place `to` (`to <= from`).
    fn move_vertex(&mut self, from: usize, to: usize) {
        let a = self.axes;
        self.joints.copy_within(from * a..(from + 1) * a, to * a);
        self.times[to] = self.times[from];
        self.tips[to] = self.tips[from];
        self.stays[to] = self.stays[from];
    }

    /// One pass of the simplification over the kept vertices, in place,
    /// at the current tolerance; the last vertex (the anchor of what is
    /// still pending) stays.
    fn simplify_kept(&mut self) {
        let n = self.times.len();
        if n < 3 {
            return;
        }
        self.stays[n - 1] = true;
        // Vertices before `out` are the new path; those after `i` are not
        // yet read, and the pending run lies between (never overwritten:
        // `out` is at most the anchor's old place plus one).
        let mut out = 1;
        let mut run: Vec<usize> = Vec::with_capacity(MAX_DROPPED_RUN);
        for i in 1..n {
            if let Some(&last) = run.last() {
                let anchor = self.vertex(out - 1);
                let point = self.vertex(i);
                let bent = || {
                    !run.iter()
                        .all(|&q| self.within(&anchor, &point, &self.vertex(q)))
                };
                if self.stays[last] || run.len() >= MAX_DROPPED_RUN || bent() {
                    self.move_vertex(last, out);
                    out += 1;
                    run.clear();
                }
            }
            run.push(i);
        }
        if let Some(&last) = run.last() {
            self.move_vertex(last, out);
            out += 1;
        }
        self.joints.truncate(out * self.axes);
        self.times.truncate(out);
        self.tips.truncate(out);
        self.stays.truncate(out);
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

/// The tolerance past which the budget drops corners too, mm (and
/// degrees): a kilometre, beyond the travel of any machine.
const LOOSEST: f64 = 1e6;

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

/// Moves times from one timeline of blocks to another: a time inside
/// block k of `from` goes to the same fraction of block k of `to`. `from`
/// and `to` hold the blocks' end times (seconds from the start, never
/// decreasing, as many of each); `times` must never decrease either. A
/// time at the end of a block goes to its end in `to` (a vertex between
/// two blocks, at the first whose end it is); a block that takes no time
/// in `from` holds no time inside it. Times past the last end go to the
/// last end of `to`.
pub fn retime(times: &mut [f64], from: &[f64], to: &[f64]) {
    let n = from.len().min(to.len());
    let mut k = 0;
    for t in times {
        while k < n && from[k] < *t {
            k += 1;
        }
        if k == n {
            *t = to.get(n.wrapping_sub(1)).copied().unwrap_or(0.0);
            continue;
        }
        let (from0, to0) = if k == 0 {
            (0.0, 0.0)
        } else {
            (from[k - 1], to[k - 1])
        };
        let span = from[k] - from0;
        let f = if span > 0.0 {
            ((*t - from0) / span).clamp(0.0, 1.0)
        } else {
            1.0
        };
        // A block's end is its end exactly (the last vertex is the total).
        *t = if f < 1.0 {
            to0 + (to[k] - to0) * f
        } else {
            to[k]
        };
    }
}

/// A typed array for the page: its values, as the browser's typed arrays
/// read them (little-endian).
#[derive(Clone, Copy, Debug)]
pub enum Column<'a> {
    /// `Uint8Array`.
    U8(&'a [u8]),
    /// `Uint32Array`.
    U32(&'a [u32]),
    /// `Float32Array`.
    F32(&'a [f32]),
    /// `Float64Array`.
    F64(&'a [f64]),
}

impl<'a> Column<'a> {
    /// Bytes per element.
    pub fn width(self) -> usize {
        match self {
            Column::U8(_) => 1,
            Column::U32(_) | Column::F32(_) => 4,
            Column::F64(_) => 8,
        }
    }

    /// The little-endian bytes of the values regrouped by byte position:
    /// every element's first byte, then every second byte, and so on.
    /// Neighbouring values of a path share their high bytes, so grouped
    /// they compress far better (the viewer regroups them back,
    /// `viewer/src/data.js`).
    pub fn shuffled(self) -> Cow<'a, [u8]> {
        match self {
            Column::U8(v) => Cow::Borrowed(v),
            Column::U32(v) => Cow::Owned(regroup(v, |x| x.to_le_bytes())),
            Column::F32(v) => Cow::Owned(regroup(v, |x| x.to_le_bytes())),
            Column::F64(v) => Cow::Owned(regroup(v, |x| x.to_le_bytes())),
        }
    }
}

fn regroup<const W: usize, T: Copy>(values: &[T], le: impl Fn(T) -> [u8; W]) -> Vec<u8> {
    let n = values.len();
    let mut out = vec![0; n * W];
    for (i, v) in values.iter().enumerate() {
        for (b, byte) in le(*v).into_iter().enumerate() {
            out[b * n + i] = byte;
        }
    }
    out
}

/// Compressed size, as a share of the raw size, above which an array is
/// written raw: the browser inflates about as slowly per byte as it parses
/// the page, so compressing pays where it leaves a small part of the
/// bytes (line numbers, motions, finding kinds: a hundredth), not for
/// times or positions (half or more).
pub const DEFLATE_WORTH: f64 = 0.25;

/// How a packed array is encoded in the page.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// Base64 of the regrouped bytes.
    Raw,
    /// Base64 of the regrouped bytes compressed in the zlib format.
    Deflate,
}

impl Encoding {
    /// As the page names it (`data-encoding`).
    pub fn name(self) -> &'static str {
        match self {
            Encoding::Raw => "raw",
            Encoding::Deflate => "deflate",
        }
    }
}

/// Writes `column` packed for the page: its regrouped bytes
/// ([`Column::shuffled`]), compressed in the zlib format (RFC 1950, which
/// the browser's `DecompressionStream("deflate")` reads) at the fast level
/// where that leaves at most [`DEFLATE_WORTH`] of them, in base64. Returns
/// the encoding chosen; `head` is called with it before the data.
pub fn write_packed(
    out: &mut dyn Write,
    column: Column<'_>,
    head: impl FnOnce(&mut dyn Write, Encoding) -> io::Result<()>,
) -> io::Result<Encoding> {
    let bytes = column.shuffled();
    let mut zlib =
        flate2::write::ZlibEncoder::new(Vec::with_capacity(bytes.len() / 4), Compression::fast());
    zlib.write_all(&bytes)?;
    let packed = zlib.finish()?;
    #[allow(clippy::cast_precision_loss)] // a ratio
    let (encoding, data) = if (packed.len() as f64) <= DEFLATE_WORTH * bytes.len() as f64 {
        (Encoding::Deflate, &packed[..])
    } else {
        (Encoding::Raw, &bytes[..])
    };
    head(out, encoding)?;
    let mut base64 = Base64Writer::new(out);
    base64.write_all(data)?;
    base64.finish()?;
    Ok(encoding)
}

const BASE64_ALPHABET: &[u8; 64] =
    b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Bytes encoded at a time.
const BASE64_CHUNK: usize = 3 * 1024;

/// A writer that writes standard base64 with padding (RFC 4648 §4) of
/// everything written to it; [`Base64Writer::finish`] writes the end.
#[derive(Debug)]
pub struct Base64Writer<W: Write> {
    out: W,
    /// Bytes not yet encoded (fewer than three at rest).
    pending: Vec<u8>,
    text: Vec<u8>,
}

impl<W: Write> Base64Writer<W> {
    /// Writes to `out`.
    pub fn new(out: W) -> Self {
        Self {
            out,
            pending: Vec::with_capacity(BASE64_CHUNK),
            text: Vec::with_capacity(BASE64_CHUNK / 3 * 4),
        }
    }

    fn encode_whole_groups(&mut self) -> io::Result<()> {
        let whole = self.pending.len() / 3 * 3;
        self.text.clear();
        for c in self.pending[..whole].chunks_exact(3) {
            let v = (u32::from(c[0]) << 16) | (u32::from(c[1]) << 8) | u32::from(c[2]);
            self.text
                .extend([sym(v, 18), sym(v, 12), sym(v, 6), sym(v, 0)]);
        }
        self.pending.drain(..whole);
        self.out.write_all(&self.text)
    }

    /// Encodes what is left, with its padding.
    pub fn finish(mut self) -> io::Result<()> {
        self.encode_whole_groups()?;
        let end = match *self.pending {
            [a] => {
                let v = u32::from(a) << 16;
                [sym(v, 18), sym(v, 12), b'=', b'=']
            }
            [a, b] => {
                let v = (u32::from(a) << 16) | (u32::from(b) << 8);
                [sym(v, 18), sym(v, 12), sym(v, 6), b'=']
            }
            _ => return self.out.flush(),
        };
        self.out.write_all(&end)?;
        self.out.flush()
    }
}

fn sym(v: u32, shift: u32) -> u8 {
    BASE64_ALPHABET[((v >> shift) & 63) as usize]
}

impl<W: Write> Write for Base64Writer<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let room = BASE64_CHUNK - self.pending.len();
        let n = buf.len().min(room);
        self.pending.extend_from_slice(&buf[..n]);
        if self.pending.len() == BASE64_CHUNK {
            self.encode_whole_groups()?;
        }
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

/// Standard base64 of `bytes`.
#[cfg(test)]
pub fn base64(bytes: &[u8]) -> String {
    let mut out = Vec::new();
    let mut w = Base64Writer::new(&mut out);
    w.write_all(bytes).expect("a Vec takes it");
    w.finish().expect("a Vec takes it");
    String::from_utf8(out).expect("ASCII")
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
    fn base64_written_in_any_pieces_is_the_same() {
        let bytes: Vec<u8> = (0..10_000u32).map(|i| (i * 7919 % 251) as u8).collect();
        let whole = base64(&bytes);
        for piece in [1, 2, 5, 1000, 3071, 3072, 3073] {
            let mut out = Vec::new();
            let mut w = Base64Writer::new(&mut out);
            for chunk in bytes.chunks(piece) {
                w.write_all(chunk).expect("a Vec takes it");
            }
            w.finish().expect("a Vec takes it");
            assert_eq!(
                String::from_utf8(out).expect("ASCII"),
                whole,
                "pieces of {piece}"
            );
        }
    }

    #[test]
    fn what_compresses_is_deflated_what_does_not_is_written_raw() {
        let encoding = |column: Column<'_>| {
            let mut out = Vec::new();
            write_packed(&mut out, column, |_, _| Ok(())).expect("a Vec takes it")
        };
        let lines: Vec<u32> = (1..=10_000).collect();
        assert_eq!(encoding(Column::U32(&lines)), Encoding::Deflate);
        // Values of no pattern (xorshift).
        let mut x = 0x2545_f491_u32;
        let noise: Vec<u8> = (0..10_000)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                x.to_le_bytes()[1]
            })
            .collect();
        assert_eq!(encoding(Column::U8(&noise)), Encoding::Raw);
    }

    #[test]
    fn typed_array_bytes_are_little_endian_regrouped_by_byte() {
        assert_eq!(*Column::F32(&[1.0]).shuffled(), [0x00, 0x00, 0x80, 0x3f]);
        assert_eq!(*Column::U32(&[0x0102_0304]).shuffled(), [4, 3, 2, 1]);
        assert_eq!(
            *Column::F64(&[-2.0]).shuffled(),
            [0, 0, 0, 0, 0, 0, 0, 0xc0]
        );
        assert_eq!(
            *Column::U32(&[0x0102_0304, 0x0506_0708]).shuffled(),
            [4, 8, 3, 7, 2, 6, 1, 5]
        );
        assert_eq!(*Column::U8(&[9, 8]).shuffled(), [9, 8]);
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
    fn the_budget_bounds_the_vertices_and_coarsens_the_tolerance() {
        // 20,000 points on a wavy line: a vertex each at 1 µm.
        let mut p = PathPacker::new(2, DEFAULT_TOLERANCE).with_budget(200);
        let mut all = Vec::new();
        for i in 0..20_000 {
            let x = f64::from(i) * 0.1;
            let pt = point(x, (x * 0.05).sin() * 20.0, f64::from(i));
            all.push(pt);
            p.push(pt, false);
        }
        p.finish();
        assert!(p.vertex_count() <= 200, "{} kept", p.vertex_count());
        assert!(p.tolerance() > DEFAULT_TOLERANCE);
        assert_eq!(p.times().first(), Some(&0.0));
        assert_eq!(p.times().last(), Some(&19_999.0));
        // Every point lies within twice the final tolerance of the kept
        // path (each pass within its own tolerance, which doubles), to
        // the rounding of f32.
        let kept: Vec<(f64, Vec3)> = p
            .times()
            .iter()
            .zip(p.joints().chunks(2))
            .map(|(&t, j)| (t, Vec3::new(f64::from(j[0]), f64::from(j[1]), 0.0)))
            .collect();
        for pt in &all {
            let k = kept.partition_point(|k| k.0 < pt.time).max(1);
            let d = distance_to_segment(&pt.tip, &kept[k - 1].1, &kept[k.min(kept.len() - 1)].1);
            assert!(d <= 2.0 * p.tolerance() + 1e-3, "{d} at {}", pt.time);
        }
    }

    #[test]
    fn the_budget_holds_when_every_point_is_a_corner() {
        let mut p = PathPacker::new(2, DEFAULT_TOLERANCE).with_budget(100);
        for i in 0..50_000 {
            let x = f64::from(i % 7);
            p.push(point(x, f64::from(i % 3), f64::from(i)), true);
        }
        p.finish();
        assert!(p.vertex_count() <= 100, "{} kept", p.vertex_count());
        assert_eq!(p.times().last(), Some(&49_999.0));
    }

    #[test]
    fn retime_moves_each_time_to_the_same_fraction_of_its_block() {
        // Blocks of 10, 0 and 20 s become 5, 3 and 40 s.
        let from = [10.0, 10.0, 30.0];
        let to = [5.0, 8.0, 48.0];
        let mut times = [0.0, 2.0, 10.0, 10.0, 20.0, 30.0, 31.0];
        retime(&mut times, &from, &to);
        // 2 s of 10 is a fifth of the first block (1 s of 5); the end of
        // block 0 is its end in `to`; 20 s is half of block 2 (8 + 20);
        // past the end, the end.
        assert_eq!(times, [0.0, 1.0, 5.0, 5.0, 28.0, 48.0, 48.0]);
        // Nothing to map by: the start.
        let mut times = [0.0, 1.0];
        retime(&mut times, &[], &[]);
        assert_eq!(times, [0.0, 0.0]);
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
