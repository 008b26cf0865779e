//! The judge of the post's outputs, by forward kinematics: the output is
//! run by the kernel on its machine (TCPC off, rows every 0.05 mm / 0.05°,
//! soft limits on), and every row's tool tip (part frame) and direction
//! are compared with the source program's, run on its own machine, at the
//! same instant. Instants: a source block lasts its tip length (densely
//! sampled forward tips) over its programmed feed, or 1/F for an inverse
//! time source; an output block lasts 1/F (G93) or, in G94, its composite
//! travel (all axes, degrees as mm: FANUC's reading of a feed with rotary
//! axes) over F, F read from the output's text. Flips (between the
//! output's `(FLIP BEFORE ...)` and `(FLIP END ...)` comments) are judged
//! apart: the tip stays on the tool axis line through the tip where the
//! tool left, reaches the retract, and comes back to that tip with the
//! same direction; their time is not the source's.

#![allow(dead_code)]

use fiveaxis_control::{
    Interpolation, Motion, Path, RunError, RunOptions, Runner, Segment, SliceSource,
};
use fiveaxis_machine::{Machine, Offsets, Vec3};
use fiveaxis_post::{Converter, PostOptions, program};

/// Interpolation of the output run: rows this close (mm, degrees).
pub const ROW_STEP: f64 = 0.05;
/// Samples of a source block for its tip length.
const LENGTH_SAMPLES: u32 = 400;
/// Share of a block's time within which its end must be kept.
pub const TIME_SHARE: f64 = 0.01;
/// Source blocks shorter than this (minutes) have no end to keep in time.
const MIN_MINUTES: f64 = 1e-7;
/// Rounding of the comparison itself, mm / deg.
const SLACK: f64 = 1e-6;

/// Runs `text` and returns its segments, or the run error.
pub fn run(
    machine: &Machine,
    offsets: &Offsets,
    text: &str,
    step: Option<f64>,
    limits: bool,
) -> Result<Vec<Segment>, RunError> {
    let options = RunOptions {
        interpolation: step.map(|s| Interpolation {
            step: s,
            step_angle: s,
        }),
        lift_soft_limits: !limits,
        ..RunOptions::default()
    };
    let mut runner = Runner::new(
        machine,
        offsets.clone(),
        SliceSource::new(text.as_bytes()),
        options,
    );
    let mut out = Vec::new();
    loop {
        let want = out.len() + 1024;
        if !runner.fill(&mut out, want)? {
            break;
        }
    }
    Ok(out)
}

/// The output program of `segments` run on `from`, for `to`.
pub fn post(
    from: &Machine,
    to: &Machine,
    segments: &[Segment],
    options: PostOptions,
) -> (String, fiveaxis_post::Post) {
    let mut converter = Converter::retarget(from, to, options);
    for seg in segments {
        converter.push(seg);
    }
    let post = converter.finish();
    let text = program::write(
        to,
        &post,
        &options,
        &program::Header {
            source: "test",
            ..Default::default()
        },
    );
    (text, post)
}

/// One side of a comparison: a program on a machine.
#[derive(Clone, Copy)]
pub struct Side<'a> {
    pub machine: &'a Machine,
    pub offsets: &'a Offsets,
    pub text: &'a str,
}

/// What the comparison allows.
#[derive(Clone, Copy, Debug)]
pub struct Rules {
    pub tolerance: f64,
    pub angle_tolerance: f64,
    /// Table-frame coordinates of the part zero on the output's machine.
    pub origin: Vec3,
    /// The source's TCPC blocks turn the tool on the great circle between
    /// their end directions.
    pub great_circle: bool,
    /// Where the programmed direction lies within `singular_cone` plus
    /// this margin (degrees) of the output machine's singular line, the
    /// direction may be off by its angle to that line.
    pub singular_margin: Option<f64>,
    /// The tool length of a machine-axis source (its blocks have none).
    pub source_tool_length: Option<f64>,
    /// The output is run with the soft limits on.
    pub output_limits: bool,
}

impl Rules {
    pub fn of(options: &PostOptions) -> Self {
        Self {
            tolerance: options.tolerance,
            angle_tolerance: options.angle_tolerance,
            origin: options.origin,
            great_circle: false,
            singular_margin: None,
            source_tool_length: options.source_tool_length,
            output_limits: true,
        }
    }

    /// The rules of a post whose own axes turn the tool on the great
    /// circle (`Axes::Post { great_circle: true }`: CL input), its
    /// direction free by the knot turn near the singular line.
    pub fn great_circle_of(options: &PostOptions) -> Self {
        Self {
            great_circle: true,
            singular_margin: Some(fiveaxis_post::follow::KNOT_TURN),
            ..Self::of(options)
        }
    }
}

/// Worst deviations found.
#[derive(Clone, Copy, Debug, Default)]
pub struct Worst {
    pub tip: f64,
    pub angle: f64,
    pub time: f64,
    pub rows: u64,
    pub flips: u64,
    /// Largest direction error allowed by a singular passage that was used.
    pub singular: f64,
}

impl Worst {
    pub fn max(self, o: Worst) -> Worst {
        Worst {
            tip: self.tip.max(o.tip),
            angle: self.angle.max(o.angle),
            time: self.time.max(o.time),
            rows: self.rows + o.rows,
            flips: self.flips + o.flips,
            singular: self.singular.max(o.singular),
        }
    }
}

/// The F word of a line of a program text.
pub fn line_f(text: &str, line: u32) -> Option<f64> {
    let l = text.lines().nth(line as usize - 1)?;
    let at = l.find('F')?;
    let rest = &l[at + 1..];
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .unwrap_or(rest.len());
    rest[..end].parse().ok()
}

/// Whether a program text runs in inverse time.
pub fn is_inverse_time(text: &str) -> bool {
    text.lines()
        .any(|l| !l.starts_with('(') && l.contains("G93"))
}

/// FANUC's composite travel of a G94 block: every axis, degrees as mm.
pub fn composite(machine: &Machine, seg: &Segment) -> f64 {
    (0..machine.axis_count())
        .map(|i| (seg.end[i] - seg.start[i]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Tip path length of a segment by forward kinematics, mm.
fn tip_length(machine: &Machine, seg: &Segment) -> f64 {
    // At least one sample per 0.02° of rotary turn: long turns far from
    // the axis need them for a length good to 1e-6.
    let turn = (machine.linear.len()..machine.axis_count())
        .map(|i| (seg.end[i] - seg.start[i]).abs())
        .fold(0.0, f64::max);
    let n = LENGTH_SAMPLES.max((turn / 0.02).ceil() as u32);
    let mut last = seg.row(machine, 0.0).tip;
    let mut sum = 0.0;
    for k in 1..=n {
        let tip = seg.row(machine, f64::from(k) / f64::from(n)).tip;
        sum += (tip - last).norm();
        last = tip;
    }
    sum
}

/// Duration of a block of `side`, minutes.
fn block_time(side: &Side<'_>, seg: &Segment, inverse_time: bool) -> f64 {
    if inverse_time {
        return 1.0 / line_f(side.text, seg.line).expect("an F in every G93 block");
    }
    let f = seg.feed.expect("a cutting feed");
    match line_f(side.text, seg.line) {
        // A machine-axis G94 block (the post's output): composite travel.
        Some(word) if is_post_output(side.text) => composite(side.machine, seg) / word,
        _ => {
            let length = tip_length(side.machine, seg);
            if length > 1e-9 {
                length / f
            } else {
                // The tool turns about a standing tip: F in degrees per
                // minute of the largest rotary travel (FANUC).
                let m = side.machine;
                (m.linear.len()..m.axis_count())
                    .map(|i| (seg.end[i] - seg.start[i]).abs())
                    .fold(0.0, f64::max)
                    / f
            }
        }
    }
}

fn is_post_output(text: &str) -> bool {
    text.contains("(FIVEAXIS POST")
}

/// Source lines of the flips of an output text (inclusive ranges).
pub fn flip_ranges(text: &str) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    let mut open = None;
    for (i, l) in text.lines().enumerate() {
        let n = i as u32 + 1;
        if l.starts_with("(FLIP BEFORE") {
            open = Some(n);
        } else if l.starts_with("(FLIP END") {
            out.push((open.take().expect("a flip start"), n));
        }
    }
    out
}

/// The tool length of a source segment's tip.
fn length_of(seg: &Segment, rules: &Rules) -> f64 {
    match rules.source_tool_length {
        Some(l) if seg.tool_length == 0.0 => l,
        _ => seg.tool_length,
    }
}

/// The programmed pose of a source segment at `s` (part frame).
fn source_pose(machine: &Machine, seg: &Segment, s: f64, rules: &Rules) -> (Vec3, Vec3) {
    let length = length_of(seg, rules);
    let row = |s: f64| {
        let p = machine.forward(&seg.eval(machine, s), length);
        (
            seg.setup.inverse_point(&(p.tip - seg.work)),
            seg.setup.inverse_vector(&p.dir),
        )
    };
    let (tip, dir) = row(s);
    if rules.great_circle && matches!(seg.path, Path::Tcpc(_)) {
        (tip, fiveaxis_control::slerp(&row(0.0).1, &row(1.0).1, s))
    } else {
        (tip, dir)
    }
}

pub fn angle(u: &Vec3, v: &Vec3) -> f64 {
    u.cross(v).norm().atan2(u.dot(v)).to_degrees()
}

/// The line of the rotating axis (table frame): the axis whose angle is
/// free when the tool lies on it (restated from the machine model).
pub fn singular_line(machine: &Machine) -> Vec3 {
    use fiveaxis_machine::Side as S;
    let k = match (machine.rotary[0].on, machine.rotary[1].on) {
        (S::Head, S::Head) | (S::Table, S::Head) => 0,
        _ => 1,
    };
    machine.rotary[k].axis.into_inner()
}

/// Judges `out` (the post's output) against `src` under `rules`.
pub fn judge(src: Side<'_>, out: Side<'_>, rules: &Rules) -> Result<Worst, String> {
    let text = out.text;
    let original =
        run(src.machine, src.offsets, src.text, None, false).map_err(|e| format!("source: {e}"))?;
    let output = run(
        out.machine,
        out.offsets,
        text,
        Some(ROW_STEP),
        rules.output_limits,
    )
    .map_err(|e| format!("output: {e}\n{text}"))?;
    let flips = flip_ranges(text);
    let in_flip = |line: u32| flips.iter().position(|(a, b)| line > *a && line < *b);
    let src_g93 = is_inverse_time(src.text);
    let mut worst = Worst {
        flips: flips.len() as u64,
        ..Worst::default()
    };
    // Cutting stretches (between rapids), flips apart.
    let stretches = |segs: &[Segment], side: &Side<'_>, g93: bool, skip_flips: bool| {
        let mut all: Vec<Vec<(Segment, f64)>> = Vec::new();
        let mut current = Vec::new();
        let mut rapids = Vec::new();
        for seg in segs.iter().filter(|s| s.moves()) {
            if skip_flips && in_flip(seg.line).is_some() {
                continue;
            }
            if seg.motion == Motion::Rapid {
                if !current.is_empty() {
                    all.push(std::mem::take(&mut current));
                }
                rapids.push(seg.clone());
            } else {
                current.push((seg.clone(), block_time(side, seg, g93)));
            }
        }
        if !current.is_empty() {
            all.push(current);
        }
        (all, rapids)
    };
    let (s_str, s_rapids) = stretches(&original, &src, src_g93, false);
    let (o_str, o_rapids) = stretches(&output, &out, is_inverse_time(text), true);
    if s_str.len() != o_str.len() {
        return Err(format!(
            "{} cutting stretches in, {} out\n{text}",
            s_str.len(),
            o_str.len()
        ));
    }
    // Rapids end where the source's do (tip of the source's tool).
    for r in &s_rapids {
        let tip = source_pose(src.machine, r, 1.0, rules).0;
        let found = o_rapids.iter().any(|o| {
            let t = out.machine.forward(&o.end, length_of(r, rules)).tip - rules.origin;
            (t - tip).norm() <= rules.tolerance
        });
        if !found {
            return Err(format!(
                "rapid end {tip:?} (line {}) missing\n{text}",
                r.line
            ));
        }
    }
    let cone = out.machine.params.singular_cone;
    let line = (out.machine.rotary.len() == 2).then(|| singular_line(out.machine));
    for (s, o) in s_str.iter().zip(&o_str) {
        let mut ends = Vec::new();
        let mut t = 0.0;
        for (_, d) in s {
            t += d;
            ends.push((t, *d));
        }
        let mut out_ends = Vec::new();
        let mut t = 0.0;
        for (_, d) in o {
            t += d;
            out_ends.push(t);
        }
        for (end, d) in ends.iter().filter(|(_, d)| *d > MIN_MINUTES) {
            let nearest = out_ends
                .iter()
                .map(|e| (e - end).abs())
                .fold(f64::INFINITY, f64::min);
            let share = nearest / d;
            worst.time = worst.time.max(share);
            if share > TIME_SHARE {
                return Err(format!(
                    "source block end at {end} min kept only within {share}\n{text}"
                ));
            }
        }
        // Each source block's end matched to the nearest output block end
        // (kept within 1 % above): a row is compared at the same share of
        // its block's time between matched ends, so that the rounding of
        // many F words (6 digits) does not add up along a stretch.
        let matched: Vec<f64> = ends
            .iter()
            .map(|(end, _)| {
                out_ends
                    .iter()
                    .copied()
                    .min_by(|a, b| (a - end).abs().total_cmp(&(b - end).abs()))
                    .unwrap_or(*end)
            })
            .collect();
        let mut t0 = 0.0;
        for (seg, d) in o {
            for k in 0..=seg.rows {
                let u = f64::from(k) / f64::from(seg.rows);
                let time = t0 + u * d;
                let at = matched
                    .partition_point(|e| *e < time - 1e-12)
                    .min(ends.len() - 1);
                let src_seg = &s[at].0;
                let from = if at == 0 { 0.0 } else { matched[at - 1] };
                let span = matched[at] - from;
                let sv = if span > 0.0 {
                    ((time - from) / span).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                let (tip_p, dir_p) = source_pose(src.machine, src_seg, sv, rules);
                let got = out
                    .machine
                    .forward(&seg.eval(out.machine, u), length_of(src_seg, rules));
                let tip = (got.tip - rules.origin - tip_p).norm();
                let a = angle(&got.dir, &dir_p);
                let mut allowed = rules.angle_tolerance;
                if let (Some(margin), Some(line)) = (rules.singular_margin, line) {
                    let phi = angle(&line, &dir_p).min(angle(&-line, &dir_p));
                    if phi < cone + margin {
                        allowed += phi;
                        if a > rules.angle_tolerance {
                            worst.singular = worst.singular.max(a);
                        }
                    }
                }
                worst.tip = worst.tip.max(tip);
                if a <= rules.angle_tolerance + SLACK {
                    worst.angle = worst.angle.max(a);
                }
                worst.rows += 1;
                if tip > rules.tolerance + SLACK || a > allowed + SLACK {
                    return Err(format!(
                        "row at {time} min (source line {}, s {sv}; output line {}, u {u}): tip off by {tip} mm, direction by {a} deg (allowed {allowed})\n{text}",
                        src_seg.line, seg.line
                    ));
                }
            }
            t0 += d;
        }
    }
    judge_flips(out, &output, &flips, rules)?;
    Ok(worst)
}

/// Every flip: the rows stay on the tool axis line through the tip where
/// the tool left (within the tolerance), go out to the retract, come back
/// to that tip with the same direction, and the rotary axes end elsewhere.
fn judge_flips(
    out: Side<'_>,
    output: &[Segment],
    flips: &[(u32, u32)],
    rules: &Rules,
) -> Result<(), String> {
    let retract = retract_of(out.text);
    for (a, b) in flips {
        let Some(first) = output.iter().position(|s| s.line > *a && s.line < *b) else {
            return Err(format!("flip at line {a} has no motion"));
        };
        let last = output
            .iter()
            .rposition(|s| s.line > *a && s.line < *b)
            .expect("a last");
        // The tool length: the next cutting block's source tool, as the
        // output was made; the tip is judged with the length the header
        // names (one tool in these tests).
        let length = tool_length_of(out.text);
        let before = output[first].start;
        let p = out.machine.forward(&before, length);
        let mut reach: f64 = 0.0;
        for seg in &output[first..=last] {
            for k in 0..=seg.rows {
                let u = f64::from(k) / f64::from(seg.rows);
                let tip = out.machine.forward(&seg.eval(out.machine, u), length).tip;
                let along = (tip - p.tip).dot(&p.dir);
                let off = ((tip - p.tip) - p.dir * along).norm();
                reach = reach.max(along);
                if off > rules.tolerance + SLACK || along < -rules.tolerance - SLACK {
                    return Err(format!(
                        "flip at line {a}: tip {off} mm off the tool axis (at {along} along it)\n{}",
                        out.text
                    ));
                }
            }
        }
        if (reach - retract).abs() > rules.tolerance {
            return Err(format!("flip at line {a}: retract {reach}, not {retract}"));
        }
        // The first move is along the tool axis: the rotary axes stand.
        let r0 = out.machine.linear.len();
        if (r0..out.machine.axis_count()).any(|i| output[first].end[i] != before[i]) {
            return Err(format!(
                "flip at line {a}: the rotaries turn while retracting"
            ));
        }
        let end = out.machine.forward(&output[last].end, length);
        if (end.tip - p.tip).norm() > rules.tolerance
            || angle(&end.dir, &p.dir) > rules.angle_tolerance
        {
            return Err(format!(
                "flip at line {a}: re-engaged {} mm and {} deg away",
                (end.tip - p.tip).norm(),
                angle(&end.dir, &p.dir)
            ));
        }
        let turned = (r0..out.machine.axis_count())
            .map(|i| (output[last].end[i] - before[i]).abs())
            .fold(0.0, f64::max);
        if turned < 10.0 {
            return Err(format!(
                "flip at line {a}: the rotary axes turn only {turned} deg"
            ));
        }
    }
    Ok(())
}

fn retract_of(text: &str) -> f64 {
    let l = text
        .lines()
        .find(|l| l.starts_with("(FLIP BEFORE"))
        .unwrap_or("");
    let at = l.find("RETRACT ").map_or(0, |i| i + 8);
    l[at..]
        .split_whitespace()
        .next()
        .and_then(|w| w.parse().ok())
        .unwrap_or(f64::NAN)
}

fn tool_length_of(text: &str) -> f64 {
    let l = text
        .lines()
        .find(|l| l.starts_with("(FOR TOOL LENGTH "))
        .expect("the header names the tool length");
    l["(FOR TOOL LENGTH ".len()..]
        .split([' ', ','])
        .next()
        .and_then(|w| w.parse().ok())
        .expect("a length")
}

/// Offsets with tool 1 of `length` and G54 at `work`.
pub fn offsets(length: f64, work: Vec3) -> Offsets {
    let mut o = Offsets::default();
    o.tools.insert(
        1,
        fiveaxis_machine::ToolOffset {
            length,
            ..Default::default()
        },
    );
    o.work[0] = work;
    o
}

/// A G43.5 program through `points` (tip, tilt from +Z and azimuth in
/// degrees, part frame), at `feed`.
pub fn vector_program(points: &[(Vec3, f64, f64)], feed: f64) -> String {
    let mut p = String::from("G21 G17 G90 G94 G54\nG0 X0 Y0 Z150.\n");
    let first = points[0].0;
    p.push_str(&format!(
        "G43.5 H1 X{:.4} Y{:.4} Z{:.4}\n",
        first.x,
        first.y,
        first.z + 20.0
    ));
    for (k, (tip, tilt, az)) in points.iter().enumerate() {
        let (t, a) = (tilt.to_radians(), az.to_radians());
        let d = Vec3::new(t.sin() * a.cos(), t.sin() * a.sin(), t.cos());
        p.push_str(&format!(
            "G1 X{:.4} Y{:.4} Z{:.4} I{:.6} J{:.6} K{:.6}{}\n",
            tip.x,
            tip.y,
            tip.z,
            d.x,
            d.y,
            d.z,
            if k == 0 {
                format!(" F{feed:.1}")
            } else {
                String::new()
            }
        ));
    }
    p.push_str("G0 Z150.\nG49\nM30\n");
    p
}

/// Random points for [`vector_program`]: tips within ±40 mm, tilts 10° to
/// 40°, azimuths a walk of steps within ±60°.
pub fn points() -> impl proptest::strategy::Strategy<Value = Vec<(Vec3, f64, f64)>> {
    use proptest::prelude::*;
    prop::collection::vec(
        (
            -40.0..40.0f64,
            -40.0..40.0f64,
            -10.0..10.0f64,
            10.0..40.0f64,
            -60.0..60.0f64,
        ),
        2..6,
    )
    .prop_map(|v| {
        let mut az = 0.0;
        v.into_iter()
            .map(|(x, y, z, tilt, step)| {
                az += step;
                (Vec3::new(x, y, z), tilt, az)
            })
            .collect()
    })
}

/// The fixed-seed proptest configuration of these tests.
pub fn config(cases: u32) -> proptest::test_runner::Config {
    proptest::test_runner::Config {
        cases,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x9057_0013),
        failure_persistence: None,
        max_shrink_iters: 64,
        ..Default::default()
    }
}
