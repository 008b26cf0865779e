//! Cutter compensation C (`fiveaxis_control::cutter`): hand-computed
//! paths for every FANUC rule the module implements, and seeded
//! properties.
//!
//! Expected points come from the geometry alone (offset lines, circle
//! equations solved here), never from the module's own helpers.
//!
//! A note on sides: on a counter-clockwise contour the left side (G41) is
//! the inside; the outside of a contour is cut with G41 going clockwise or
//! G42 going counter-clockwise.

mod common;

use std::f64::consts::PI;

use common::check;
use fiveaxis_control::cutter::{
    CompError, Compensated, CutterComp, Element, Move, P2, PieceKind, Side, StartupType,
};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestCaseError};

const EPS: f64 = 1e-9;

fn p(x: f64, y: f64) -> P2 {
    P2::new(x, y)
}

fn line(from: P2, to: P2) -> Option<Element> {
    Some(Element::Line { from, to })
}

fn arc(from: P2, to: P2, center: P2, ccw: bool) -> Option<Element> {
    Some(Element::Arc {
        from,
        to,
        center,
        ccw,
    })
}

const L5: Option<(Side, f64)> = Some((Side::Left, 5.0));
const R5: Option<(Side, f64)> = Some((Side::Right, 5.0));
const OFF: Option<(Side, f64)> = None;

/// One programmed block: its movement in the plane and its mode.
type Blk = (Option<Element>, Option<(Side, f64)>);

/// Pushes the blocks with tags 0, 1, … and finishes.
fn run(ty: StartupType, blocks: &[Blk]) -> Result<Vec<Compensated>, CompError> {
    let mut comp = CutterComp::new(ty);
    let mut out = Vec::new();
    for (tag, (element, mode)) in blocks.iter().enumerate() {
        let m = element.map(|element| Move {
            element,
            rapid: false,
            vector: None,
        });
        comp.push(m, *mode, u32::try_from(tag).unwrap_or(u32::MAX), &mut out)?;
    }
    comp.finish(&mut out)?;
    assert!(!comp.is_active());
    Ok(out)
}

/// Runs and expects success, checking continuity and tag order.
fn ok(ty: StartupType, blocks: &[Blk]) -> Vec<Compensated> {
    let out = match run(ty, blocks) {
        Ok(out) => out,
        Err(e) => panic!("unexpected {e:?}"),
    };
    assert_joined(&out);
    out
}

fn assert_joined(out: &[Compensated]) {
    let mut last: Option<P2> = None;
    let mut last_tag = 0;
    for piece in out {
        assert!(piece.tag >= last_tag, "tags go back: {out:#?}");
        last_tag = piece.tag;
        assert_eq!(piece.element.is_none(), piece.kind == PieceKind::Still);
        if let Some(e) = piece.element {
            if let Some(l) = last {
                assert!(
                    (e.start() - l).norm() <= EPS,
                    "gap before {piece:?} (previous end {l:?})"
                );
            }
            last = Some(e.end());
        }
    }
}

fn assert_pt(actual: P2, expected: P2) {
    assert!(
        (actual - expected).norm() <= 1e-7,
        "{actual:?} != {expected:?}"
    );
}

/// The pieces as (kind, tag, start, end).
fn summary(out: &[Compensated]) -> Vec<(PieceKind, u32, P2, P2)> {
    out.iter()
        .filter_map(|c| c.element.map(|e| (c.kind, c.tag, e.start(), e.end())))
        .collect()
}

/// Asserts the line pieces of `out` one by one: (kind, tag, from, to).
fn assert_lines(out: &[Compensated], expected: &[(PieceKind, u32, P2, P2)]) {
    let got = summary(out);
    assert_eq!(got.len(), expected.len(), "pieces: {got:#?}");
    for (g, e) in got.iter().zip(expected) {
        assert_eq!((g.0, g.1), (e.0, e.1), "piece {g:?}, expected {e:?}");
        assert_pt(g.2, e.2);
        assert_pt(g.3, e.3);
    }
}

/// Signed distance of `q` from the infinite line through `a`, `b`
/// (positive on the left).
fn signed_distance(q: P2, a: P2, b: P2) -> f64 {
    let t = (b - a).normalize();
    let v = q - a;
    t.x * v.y - t.y * v.x
}

/// Intersections of the circles (c1, r1) and (c2, r2).
fn circle_circle(c1: P2, r1: f64, c2: P2, r2: f64) -> [P2; 2] {
    let d = (c2 - c1).norm();
    let a = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);
    let h = (r1 * r1 - a * a).sqrt();
    let e = (c2 - c1) / d;
    let base = c1 + e * a;
    let n = p(-e.y, e.x);
    [base + n * h, base - n * h]
}

fn closest(points: [P2; 2], to: P2) -> P2 {
    if (points[0] - to).norm() <= (points[1] - to).norm() {
        points[0]
    } else {
        points[1]
    }
}

use PieceKind::{Cancel, Corner, Offset, StartUp};

// ----- offset mode: corners -------------------------------------------------

/// The 100 × 100 square from (0, 0), cut outside clockwise with G41 r 5:
/// every corner is α = 90°, which the manual counts as obtuse
/// (90° ≤ α < 180°): the corner is the intersection of the offset lines,
/// with no extra points. Start-up and cancel are on the inner side, so
/// both start-up types give the same path.
#[test]
fn square_outside_g41_right_angles_are_obtuse_intersections() {
    let blocks: Vec<Blk> = vec![
        (line(p(-30.0, 50.0), p(0.0, 50.0)), L5),
        (line(p(0.0, 50.0), p(0.0, 100.0)), L5),
        (line(p(0.0, 100.0), p(100.0, 100.0)), L5),
        (line(p(100.0, 100.0), p(100.0, 0.0)), L5),
        (line(p(100.0, 0.0), p(0.0, 0.0)), L5),
        (line(p(0.0, 0.0), p(0.0, 50.0)), L5),
        (line(p(0.0, 50.0), p(-30.0, 50.0)), OFF),
    ];
    let expected = [
        (StartUp, 0, p(-30.0, 50.0), p(-5.0, 50.0)),
        (Offset, 1, p(-5.0, 50.0), p(-5.0, 105.0)),
        (Offset, 2, p(-5.0, 105.0), p(105.0, 105.0)),
        (Offset, 3, p(105.0, 105.0), p(105.0, -5.0)),
        (Offset, 4, p(105.0, -5.0), p(-5.0, -5.0)),
        (Offset, 5, p(-5.0, -5.0), p(-5.0, 50.0)),
        (Cancel, 6, p(-5.0, 50.0), p(-30.0, 50.0)),
    ];
    for ty in [StartupType::A, StartupType::B] {
        let out = ok(ty, &blocks);
        assert_lines(&out, &expected);
        // Every offset piece lies at exactly r on the left of its side.
        for c in &out {
            if c.kind == Offset
                && let (Some(e), Some((Some(prog), _))) = (c.element, blocks.get(c.tag as usize))
            {
                let (a, b) = (prog.start(), prog.end());
                assert!((signed_distance(e.start(), a, b) - 5.0).abs() < EPS);
                assert!((signed_distance(e.end(), a, b) - 5.0).abs() < EPS);
            }
        }
    }
}

/// The same square clockwise with G42: the tool is inside, every corner
/// is on the inner side (α = 270°): the intersection of the offset lines.
#[test]
fn square_inside_g42_inner_corners_are_intersections() {
    let blocks: Vec<Blk> = vec![
        (line(p(30.0, 50.0), p(0.0, 50.0)), R5),
        (line(p(0.0, 50.0), p(0.0, 100.0)), R5),
        (line(p(0.0, 100.0), p(100.0, 100.0)), R5),
        (line(p(100.0, 100.0), p(100.0, 0.0)), R5),
        (line(p(100.0, 0.0), p(0.0, 0.0)), R5),
        (line(p(0.0, 0.0), p(0.0, 50.0)), R5),
        (line(p(0.0, 50.0), p(30.0, 50.0)), OFF),
    ];
    let out = ok(StartupType::A, &blocks);
    assert_lines(
        &out,
        &[
            (StartUp, 0, p(30.0, 50.0), p(5.0, 50.0)),
            (Offset, 1, p(5.0, 50.0), p(5.0, 95.0)),
            (Offset, 2, p(5.0, 95.0), p(95.0, 95.0)),
            (Offset, 3, p(95.0, 95.0), p(95.0, 5.0)),
            (Offset, 4, p(95.0, 5.0), p(5.0, 5.0)),
            (Offset, 5, p(5.0, 5.0), p(5.0, 50.0)),
            (Cancel, 6, p(5.0, 50.0), p(30.0, 50.0)),
        ],
    );
}

/// Start-up onto (−100, 0), a line to the origin along +x, then a line
/// from the origin in direction `dir`, G41 r 5, cancel along `dir`.
fn corner_program(dir: P2) -> Vec<Blk> {
    let end = dir * 100.0;
    vec![
        (line(p(-100.0, -30.0), p(-100.0, 0.0)), L5),
        (line(p(-100.0, 0.0), p(0.0, 0.0)), L5),
        (line(p(0.0, 0.0), end), L5),
        (line(end, end + dir * 50.0), OFF),
    ]
}

/// G41 along +x, then a right turn of 150°: outer side, α = 30° < 90°.
/// The first offset runs on r past the perpendicular point, a corner line
/// joins the point r before the start of the second offset.
#[test]
fn acute_outer_corner_of_30_degrees_has_two_extra_points() {
    let a = 150f64.to_radians();
    let dir = p(a.cos(), -a.sin()); // −150°
    let out = ok(StartupType::A, &corner_program(dir));
    let n2 = p(-dir.y, dir.x);
    let p1 = p(5.0, 5.0);
    let p2 = n2 * 5.0 - dir * 5.0;
    // Hand values: P2 = (2.5 + 4.330127, −4.330127 + 2.5).
    assert_pt(p2, p(2.5 + 2.5 * 3f64.sqrt(), 2.5 - 2.5 * 3f64.sqrt()));
    let s = summary(&out);
    assert_eq!(s[1].0, Offset);
    assert_pt(s[1].3, p1);
    assert_eq!(
        (s[2].0, s[2].1),
        (Corner, 1),
        "the corner line belongs to the block ending there"
    );
    assert_pt(s[2].2, p1);
    assert_pt(s[2].3, p2);
    assert_eq!((s[3].0, s[3].1), (Offset, 2));
    assert_pt(s[3].2, p2);
    // Both extra points lie on the extended offset lines.
    assert!((signed_distance(p2, p(0.0, 0.0), dir) - 5.0).abs() < EPS);
    assert!((signed_distance(p1, p(-100.0, 0.0), p(0.0, 0.0)) - 5.0).abs() < EPS);
}

/// A right turn of 60° with G41: outer side, α = 120°: the intersection,
/// at r / cos 30° from the corner on its bisector.
#[test]
fn obtuse_outer_corner_is_the_intersection() {
    let a = 60f64.to_radians();
    let dir = p(a.cos(), -a.sin());
    let out = ok(StartupType::A, &corner_program(dir));
    let s = summary(&out);
    let x = p(5.0 * (30f64.to_radians()).tan(), 5.0);
    assert_pt(x, p(2.886_751_345_948_129, 5.0));
    assert_eq!(s.iter().filter(|q| q.0 == Corner).count(), 0);
    assert_pt(s[1].3, x);
    assert_pt(s[2].2, x);
}

/// A left turn of 45° with G41 (inner side): the intersection of the
/// offset lines.
#[test]
fn inner_line_line_corner_is_the_intersection() {
    let a = 45f64.to_radians();
    let dir = p(a.cos(), a.sin());
    let out = ok(StartupType::B, &corner_program(dir));
    let s = summary(&out);
    // y = 5 meets the offset of the 45° line at x = 5·tan(22.5°)... on the
    // inner side: x = −5·tan(22.5°).
    let x = p(-5.0 * (22.5f64.to_radians()).tan(), 5.0);
    assert_pt(s[1].3, x);
    assert_pt(s[2].2, x);
    assert!((signed_distance(x, p(0.0, 0.0), dir) - 5.0).abs() < EPS);
}

/// Line along +x into a counter-clockwise arc about (−10, 10) through the
/// origin: a left turn of 45°.
fn line_arc_program(mode: Option<(Side, f64)>) -> Vec<Blk> {
    let c = p(-10.0, 10.0);
    vec![
        (line(p(-100.0, -40.0), p(-100.0, 0.0)), mode),
        (line(p(-100.0, 0.0), p(0.0, 0.0)), mode),
        (arc(p(0.0, 0.0), p(-20.0, 20.0), c, true), mode),
        (line(p(-20.0, 20.0), p(-20.0, 60.0)), mode),
        (line(p(-20.0, 60.0), p(-60.0, 60.0)), OFF),
    ]
}

/// G41 keeps the tool inside the arc (radius √200 − 5) and on the inner
/// side of the corner: y = 5 meets that circle.
#[test]
fn line_arc_inner_corner_is_line_circle_intersection() {
    let out = ok(StartupType::A, &line_arc_program(L5));
    let rho = 200f64.sqrt() - 5.0;
    // (x + 10)² + (5 − 10)² = ρ²
    let x = -10.0 + (rho * rho - 25.0).sqrt();
    let s = summary(&out);
    let arc_piece = out
        .iter()
        .find(|c| c.tag == 2 && c.kind == Offset)
        .and_then(|c| c.element);
    let Some(Element::Arc {
        from,
        center,
        ccw,
        to,
    }) = arc_piece
    else {
        panic!("no arc: {s:#?}")
    };
    assert!(ccw);
    assert_pt(center, p(-10.0, 10.0));
    assert_pt(from, p(x, 5.0));
    assert!(((to - center).norm() - rho).abs() < 1e-9);
    // Arc → line at (−20, 20) turns right by 135° (α = 45°, acute): the
    // arc ends perpendicular, a tangent line runs on r to P1, a corner
    // line to P2 on the next offset (x = −25).
    assert_pt(to, center + (p(-20.0, 20.0) - center).normalize() * rho);
    let corners: Vec<_> = summary(&out)
        .into_iter()
        .filter(|q| q.0 == Corner && q.1 == 2)
        .collect();
    assert_eq!(corners.len(), 2);
    let t1 = p(-1.0, -1.0).normalize();
    assert_pt(corners[0].3, to + t1 * 5.0);
    assert_pt(corners[1].3, p(-25.0, 20.0) - p(0.0, 5.0));
}

/// G42 puts the tool outside (radius √200 + 5), the corner is outer
/// obtuse (α = 135°): y = −5 meets that circle.
#[test]
fn line_arc_outer_corner_is_line_circle_intersection() {
    let out = ok(StartupType::A, &line_arc_program(R5));
    let rho = 200f64.sqrt() + 5.0;
    let x = -10.0 + (rho * rho - 225.0).sqrt();
    let arc_piece = out
        .iter()
        .find(|c| c.tag == 2 && c.kind == Offset)
        .and_then(|c| c.element);
    let Some(Element::Arc { from, center, .. }) = arc_piece else {
        panic!("no arc: {out:#?}")
    };
    assert_pt(from, p(x, -5.0));
    assert_pt(center, p(-10.0, 10.0));
    assert!(out.iter().all(|c| c.kind != Corner));
}

/// Clockwise arc about (−10, 0) from (−20, 0) to the origin (upper half),
/// then a counter-clockwise arc about (10, 5): a left turn at the origin.
/// G41 is on the inner side: the offset circles (radius 15 about (−10, 0),
/// √125 − 5 about (10, 5)) meet at the corner. G42 is on the outer side
/// (obtuse): circles of radius 5 and √125 + 5.
#[test]
fn arc_arc_corners_are_circle_intersections() {
    let c1 = p(-10.0, 0.0);
    let c2 = p(10.0, 5.0);
    let r2 = 125f64.sqrt();
    let end2 = c2 + p(r2, 0.0);
    for (mode, rho1, rho2) in [(L5, 15.0, r2 - 5.0), (R5, 5.0, r2 + 5.0)] {
        let blocks: Vec<Blk> = vec![
            (line(p(-20.0, -30.0), p(-20.0, 0.0)), mode),
            (arc(p(-20.0, 0.0), p(0.0, 0.0), c1, false), mode),
            (arc(p(0.0, 0.0), end2, c2, true), mode),
            (line(end2, end2 + p(0.0, 30.0)), OFF),
        ];
        let out = ok(StartupType::A, &blocks);
        // Reference for the nearer intersection: the perpendicular points.
        let d = if mode == L5 { 5.0 } else { -5.0 };
        let t1 = p(0.0, -1.0); // clockwise about (−10, 0) at the origin
        let u2 = (p(0.0, 0.0) - c2).normalize();
        let t2 = p(-u2.y, u2.x);
        let qa = p(-t1.y, t1.x) * d;
        let qb = p(-t2.y, t2.x) * d;
        let x = closest(circle_circle(c1, rho1, c2, rho2), (qa + qb) * 0.5);
        let pieces: Vec<_> = out
            .iter()
            .filter(|c| c.kind == Offset && (c.tag == 1 || c.tag == 2))
            .filter_map(|c| c.element)
            .collect();
        let (
            Some(Element::Arc { to, center, .. }),
            Some(Element::Arc {
                from, center: cb, ..
            }),
        ) = (pieces.first().copied(), pieces.get(1).copied())
        else {
            panic!("arcs expected: {out:#?}")
        };
        assert_pt(to, x);
        assert_pt(from, x);
        assert_pt(center, c1);
        assert_pt(cb, c2);
        assert!(out.iter().all(|c| c.kind != Corner));
    }
}

/// A rounded rectangle cut outside: lines and tangent arcs, so every
/// transition is tangent: no extra points, each piece is the offset of its
/// block, arcs concentric with radius R + r.
#[test]
fn tangent_transitions_have_no_extra_points() {
    // Counter-clockwise, outside with G42, corner radius 10.
    let blocks: Vec<Blk> = vec![
        (line(p(50.0, -40.0), p(50.0, 0.0)), R5),
        (line(p(50.0, 0.0), p(90.0, 0.0)), R5),
        (arc(p(90.0, 0.0), p(100.0, 10.0), p(90.0, 10.0), true), R5),
        (line(p(100.0, 10.0), p(100.0, 50.0)), R5),
        (arc(p(100.0, 50.0), p(90.0, 60.0), p(90.0, 50.0), true), R5),
        (line(p(90.0, 60.0), p(10.0, 60.0)), R5),
        (arc(p(10.0, 60.0), p(0.0, 50.0), p(10.0, 50.0), true), R5),
        (line(p(0.0, 50.0), p(0.0, 10.0)), R5),
        (arc(p(0.0, 10.0), p(10.0, 0.0), p(10.0, 10.0), true), R5),
        (line(p(10.0, 0.0), p(50.0, 0.0)), R5),
        (line(p(50.0, 0.0), p(50.0, -40.0)), OFF),
    ];
    let out = ok(StartupType::B, &blocks);
    assert!(out.iter().all(|c| c.kind != Corner), "{out:#?}");
    let arcs: Vec<_> = out
        .iter()
        .filter_map(|c| match c.element {
            Some(Element::Arc {
                from, to, center, ..
            }) => Some((from, to, center)),
            _ => None,
        })
        .collect();
    assert_eq!(arcs.len(), 4);
    for (from, to, center) in arcs {
        assert!(((from - center).norm() - 15.0).abs() < EPS);
        assert!(((to - center).norm() - 15.0).abs() < EPS);
    }
    let s = summary(&out);
    assert_pt(s[1].2, p(50.0, -5.0));
    assert_pt(s[1].3, p(90.0, -5.0));
    assert_pt(s[2].3, p(105.0, 10.0));
}

/// A full circle in offset mode, entered and left tangentially: one turn
/// of radius R + r, emitted as two half circles.
#[test]
fn full_circle_is_split_into_half_circles() {
    let c = p(0.0, 20.0);
    let blocks: Vec<Blk> = vec![
        (line(p(-50.0, -30.0), p(-50.0, 0.0)), R5),
        (line(p(-50.0, 0.0), p(0.0, 0.0)), R5),
        (arc(p(0.0, 0.0), p(0.0, 0.0), c, true), R5),
        (line(p(0.0, 0.0), p(50.0, 0.0)), R5),
        (line(p(50.0, 0.0), p(50.0, -30.0)), OFF),
    ];
    let out = ok(StartupType::A, &blocks);
    let arcs: Vec<_> = out.iter().filter(|c| c.tag == 2).collect();
    assert_eq!(arcs.len(), 2);
    for a in &arcs {
        let Some(Element::Arc {
            from,
            to,
            center,
            ccw,
        }) = a.element
        else {
            panic!("arc expected")
        };
        assert!(ccw);
        assert_pt(center, c);
        assert!(((from - c).norm() - 25.0).abs() < EPS);
        assert!(((to - c).norm() - 25.0).abs() < EPS);
    }
    assert_pt(
        arcs[0].element.map_or(P2::zeros(), |e| e.start()),
        p(0.0, -5.0),
    );
    assert_pt(
        arcs[0].element.map_or(P2::zeros(), |e| e.end()),
        p(0.0, 45.0),
    );
    assert_pt(
        arcs[1].element.map_or(P2::zeros(), |e| e.end()),
        p(0.0, -5.0),
    );
}

// ----- start-up and cancel ----------------------------------------------------

fn startup_program(from: P2) -> Vec<Blk> {
    vec![
        (line(from, p(0.0, 0.0)), L5),
        (line(p(0.0, 0.0), p(100.0, 0.0)), L5),
        (line(p(100.0, 0.0), p(100.0, 50.0)), OFF),
    ]
}

/// Start-up upwards, then +x with G41: a right turn of 90°, outer side,
/// α = 90° (obtuse). Type A: the vector is perpendicular to the next block
/// (0, 5). Type B: the intersection of the start-up line's offset (x = −5)
/// with the next block's (y = 5).
#[test]
fn startup_obtuse_type_a_is_perpendicular_type_b_intersection() {
    let blocks = startup_program(p(0.0, -30.0));
    let a = ok(StartupType::A, &blocks);
    let b = ok(StartupType::B, &blocks);
    assert_lines(
        &a[..2],
        &[
            (StartUp, 0, p(0.0, -30.0), p(0.0, 5.0)),
            (Offset, 1, p(0.0, 5.0), p(100.0, 5.0)),
        ],
    );
    assert_lines(
        &b[..2],
        &[
            (StartUp, 0, p(0.0, -30.0), p(-5.0, 5.0)),
            (Offset, 1, p(-5.0, 5.0), p(100.0, 5.0)),
        ],
    );
}

/// Start-up in direction 150° then +x: a right turn of 150°, α = 30°.
/// Type A: perpendicular to the next block. Type B: the two extra points
/// P1 = r·n₁ + r·t₁ and P2 = (0, 5) − (5, 0).
#[test]
fn startup_acute_type_b_has_two_extra_points() {
    let a = 150f64.to_radians();
    let t1 = p(a.cos(), a.sin());
    let start = -t1 * 40.0;
    let blocks = startup_program(start);
    let out_a = ok(StartupType::A, &blocks);
    assert_lines(
        &out_a[..2],
        &[
            (StartUp, 0, start, p(0.0, 5.0)),
            (Offset, 1, p(0.0, 5.0), p(100.0, 5.0)),
        ],
    );
    let out_b = ok(StartupType::B, &blocks);
    let n1 = p(-t1.y, t1.x);
    let p1 = n1 * 5.0 + t1 * 5.0;
    assert_pt(p1, p(-2.5 - 2.5 * 3f64.sqrt(), 2.5 - 2.5 * 3f64.sqrt()));
    assert_lines(
        &out_b[..3],
        &[
            (StartUp, 0, start, p1),
            (Corner, 0, p1, p(-5.0, 5.0)),
            (Offset, 1, p(-5.0, 5.0), p(100.0, 5.0)),
        ],
    );
}

/// Start-up downwards then +x with G41: a left turn, inner side: both
/// types end the start-up perpendicular to the next block.
#[test]
fn startup_inner_side_is_perpendicular_for_both_types() {
    let blocks = startup_program(p(0.0, 30.0));
    for ty in [StartupType::A, StartupType::B] {
        let out = ok(ty, &blocks);
        assert_lines(
            &out[..2],
            &[
                (StartUp, 0, p(0.0, 30.0), p(0.0, 5.0)),
                (Offset, 1, p(0.0, 5.0), p(100.0, 5.0)),
            ],
        );
    }
}

/// G41 along +x, cancel downwards: a right turn of 90°, outer side
/// (α = 90°). Type A: the last block ends perpendicular to itself
/// (100, 5); type B at the intersection with the cancel line's offset
/// (x = 105). The cancel move ends on the programmed point.
#[test]
fn cancel_type_a_and_b_end_on_the_programmed_point() {
    let blocks: Vec<Blk> = vec![
        (line(p(0.0, -30.0), p(0.0, 0.0)), L5),
        (line(p(0.0, 0.0), p(100.0, 0.0)), L5),
        (line(p(100.0, 0.0), p(100.0, -30.0)), OFF),
    ];
    let a = ok(StartupType::A, &blocks);
    let b = ok(StartupType::B, &blocks);
    assert_lines(
        &a[1..],
        &[
            (Offset, 1, p(0.0, 5.0), p(100.0, 5.0)),
            (Cancel, 2, p(100.0, 5.0), p(100.0, -30.0)),
        ],
    );
    assert_lines(
        &b[1..],
        &[
            (Offset, 1, p(-5.0, 5.0), p(105.0, 5.0)),
            (Cancel, 2, p(105.0, 5.0), p(100.0, -30.0)),
        ],
    );
}

/// Cancel at an acute outer corner with type B: P1, P2, then the cancel
/// move to the programmed point.
#[test]
fn cancel_acute_type_b_has_two_extra_points() {
    let a = 150f64.to_radians();
    let t2 = p(a.cos(), -a.sin()); // right turn of 150° from +x
    let end = t2 * 40.0 + p(100.0, 0.0);
    let blocks: Vec<Blk> = vec![
        (line(p(0.0, -30.0), p(0.0, 0.0)), L5),
        (line(p(0.0, 0.0), p(100.0, 0.0)), L5),
        (line(p(100.0, 0.0), end), OFF),
    ];
    let out = ok(StartupType::B, &blocks);
    let n2 = p(-t2.y, t2.x);
    let p2 = p(100.0, 0.0) + n2 * 5.0 - t2 * 5.0;
    assert_lines(
        &out[1..],
        &[
            (Offset, 1, p(-5.0, 5.0), p(105.0, 5.0)),
            (Corner, 1, p(105.0, 5.0), p2),
            (Cancel, 2, p2, end),
        ],
    );
}

#[test]
fn arc_in_startup_or_cancel_is_ps0034() {
    let c = p(0.0, 10.0);
    let startup = run(
        StartupType::A,
        &[(arc(p(0.0, 0.0), p(0.0, 20.0), c, true), L5)],
    );
    assert_eq!(startup, Err(CompError::ArcInStartOrCancel { tag: 0 }));
    assert_eq!(startup.err().and_then(|e| e.code()), Some(34));
    let cancel = run(
        StartupType::A,
        &[
            (line(p(0.0, -20.0), p(0.0, 0.0)), L5),
            (line(p(0.0, 0.0), p(10.0, 0.0)), L5),
            (arc(p(10.0, 0.0), p(10.0, 20.0), p(10.0, 10.0), true), OFF),
        ],
    );
    assert_eq!(cancel, Err(CompError::ArcInStartOrCancel { tag: 2 }));
}

/// G41 with no movement in the plane does not start up; the next move
/// does, from its programmed start.
#[test]
fn startup_command_without_movement_starts_at_the_next_move() {
    let out = ok(
        StartupType::A,
        &[
            (None, L5),
            (line(p(0.0, -30.0), p(0.0, 0.0)), L5),
            (line(p(0.0, 0.0), p(100.0, 0.0)), L5),
            (line(p(100.0, 0.0), p(100.0, 30.0)), OFF),
        ],
    );
    assert_eq!(out[0].kind, PieceKind::Still);
    assert_eq!(out[0].tag, 0);
    assert_lines(
        &out[1..3],
        &[
            (StartUp, 1, p(0.0, -30.0), p(0.0, 5.0)),
            (Offset, 2, p(0.0, 5.0), p(100.0, 5.0)),
        ],
    );
}

// ----- changes in offset mode -------------------------------------------------

/// G41 along +x, then G42 upwards: the corner is the intersection of the
/// old side's offset (y = 5) with the new side's (x = 105).
#[test]
fn change_of_side_uses_the_intersection() {
    let out = ok(
        StartupType::A,
        &[
            (line(p(0.0, -30.0), p(0.0, 0.0)), L5),
            (line(p(0.0, 0.0), p(100.0, 0.0)), L5),
            (line(p(100.0, 0.0), p(100.0, 100.0)), R5),
            (line(p(100.0, 100.0), p(130.0, 100.0)), OFF),
        ],
    );
    assert_lines(
        &out[1..3],
        &[
            (Offset, 1, p(0.0, 5.0), p(105.0, 5.0)),
            (Offset, 2, p(105.0, 5.0), p(105.0, 100.0)),
        ],
    );
}

/// G41 → G42 on a straight continuation: the offsets are parallel, no
/// intersection: the first ends perpendicular, a corner line crosses, the
/// second starts perpendicular.
#[test]
fn change_of_side_without_intersection_crosses_perpendicular() {
    let out = ok(
        StartupType::A,
        &[
            (line(p(0.0, -30.0), p(0.0, 0.0)), L5),
            (line(p(0.0, 0.0), p(100.0, 0.0)), L5),
            (line(p(100.0, 0.0), p(200.0, 0.0)), R5),
            (line(p(200.0, 0.0), p(200.0, -30.0)), OFF),
        ],
    );
    assert_lines(
        &out[1..4],
        &[
            (Offset, 1, p(0.0, 5.0), p(100.0, 5.0)),
            (Corner, 1, p(100.0, 5.0), p(100.0, -5.0)),
            (Offset, 2, p(100.0, -5.0), p(200.0, -5.0)),
        ],
    );
}

/// D changes from 5 to 8 in block 2: its start keeps the old vector, its
/// end has the new one.
#[test]
fn change_of_offset_value_applies_at_the_end_of_the_block() {
    let l8 = Some((Side::Left, 8.0));
    let out = ok(
        StartupType::A,
        &[
            (line(p(0.0, -30.0), p(0.0, 0.0)), L5),
            (line(p(0.0, 0.0), p(100.0, 0.0)), L5),
            (line(p(100.0, 0.0), p(200.0, 0.0)), l8),
            (line(p(200.0, 0.0), p(300.0, 0.0)), l8),
            (line(p(300.0, 0.0), p(300.0, 30.0)), OFF),
        ],
    );
    assert_lines(
        &out[1..4],
        &[
            (Offset, 1, p(0.0, 5.0), p(100.0, 5.0)),
            (Offset, 2, p(100.0, 5.0), p(200.0, 8.0)),
            (Offset, 3, p(200.0, 8.0), p(300.0, 8.0)),
        ],
    );
}

/// D changes from 5 to 8 on a counter-clockwise arc of radius 20 cut
/// outside (G42): the offset arc starts at radius 25 and ends at 28
/// (a spiral about the same centre).
#[test]
fn change_of_offset_value_on_an_arc_gives_a_spiral() {
    let r8 = Some((Side::Right, 8.0));
    let c = p(100.0, 20.0);
    let out = ok(
        StartupType::A,
        &[
            (line(p(0.0, -30.0), p(0.0, 0.0)), R5),
            (line(p(0.0, 0.0), p(100.0, 0.0)), R5),
            (arc(p(100.0, 0.0), p(120.0, 20.0), c, true), r8),
            (line(p(120.0, 20.0), p(120.0, 60.0)), r8),
            (line(p(120.0, 60.0), p(150.0, 60.0)), OFF),
        ],
    );
    let spiral = out.iter().find(|q| q.tag == 2).and_then(|q| q.element);
    let Some(Element::Arc {
        from,
        to,
        center,
        ccw,
    }) = spiral
    else {
        panic!("arc expected: {out:#?}")
    };
    assert!(ccw);
    assert_pt(center, c);
    assert_pt(from, p(100.0, -5.0));
    assert_pt(to, p(128.0, 20.0));
}

/// A negative radius swaps the sides: G41 with −5 is G42 with 5.
#[test]
fn negative_radius_swaps_sides() {
    let prog = |mode| -> Vec<Blk> {
        vec![
            (line(p(0.0, -30.0), p(0.0, 0.0)), mode),
            (line(p(0.0, 0.0), p(100.0, 0.0)), mode),
            (line(p(100.0, 0.0), p(100.0, 30.0)), OFF),
        ]
    };
    let neg = ok(StartupType::B, &prog(Some((Side::Left, -5.0))));
    let right = ok(StartupType::B, &prog(R5));
    assert_eq!(summary(&neg), summary(&right));
}

/// Radius 0: the tool centre follows the program.
#[test]
fn zero_radius_follows_the_program() {
    let blocks: Vec<Blk> = vec![
        (line(p(0.0, -30.0), p(0.0, 0.0)), Some((Side::Left, 0.0))),
        (line(p(0.0, 0.0), p(100.0, 0.0)), Some((Side::Left, 0.0))),
        (
            arc(p(100.0, 0.0), p(120.0, 20.0), p(100.0, 20.0), true),
            Some((Side::Left, 0.0)),
        ),
        (line(p(120.0, 20.0), p(120.0, 50.0)), OFF),
    ];
    let out = ok(StartupType::B, &blocks);
    for c in &out {
        if let Some((Some(prog), _)) = blocks.get(c.tag as usize) {
            assert_eq!(
                c.element.map(|e| (e.start(), e.end())),
                Some((prog.start(), prog.end()))
            );
        }
    }
}

// ----- blocks without movement ---------------------------------------------------

fn with_stills(n: usize) -> Vec<Blk> {
    let mut blocks: Vec<Blk> = vec![
        (line(p(0.0, -30.0), p(0.0, 0.0)), L5),
        (line(p(0.0, 0.0), p(100.0, 0.0)), L5),
    ];
    blocks.extend(std::iter::repeat_n((None, L5), n));
    blocks.push((line(p(100.0, 0.0), p(100.0, 100.0)), L5));
    blocks.push((line(p(100.0, 100.0), p(130.0, 100.0)), OFF));
    blocks
}

/// One block without movement between two moves changes nothing; it runs
/// at the corner (95, 5).
#[test]
fn one_block_without_movement_keeps_the_intersection() {
    let plain = ok(StartupType::A, &with_stills(0));
    let one = ok(StartupType::A, &with_stills(1));
    let moving: Vec<_> = summary(&one)
        .into_iter()
        .map(|(k, t, a, b)| (k, if t > 2 { t - 1 } else { t }, a, b))
        .collect();
    assert_eq!(moving, summary(&plain));
    let i = one.iter().position(|c| c.kind == PieceKind::Still);
    assert_eq!(i.map(|i| one[i].tag), Some(2));
    assert_eq!(
        i.map(|i| one[i - 1].element.map(|e| e.end())),
        Some(Some(p(95.0, 5.0)))
    );
}

/// Two blocks without movement: the block before them ends perpendicular
/// (100, 5), and the next move runs from there to its end vector.
#[test]
fn two_blocks_without_movement_end_perpendicular() {
    let out = ok(StartupType::A, &with_stills(2));
    let kinds: Vec<_> = out.iter().map(|c| (c.kind, c.tag)).collect();
    assert_eq!(
        kinds,
        vec![
            (StartUp, 0),
            (Offset, 1),
            (PieceKind::Still, 2),
            (PieceKind::Still, 3),
            (Offset, 4),
            (Cancel, 5)
        ]
    );
    let s = summary(&out);
    assert_pt(s[1].3, p(100.0, 5.0));
    assert_pt(s[2].2, p(100.0, 5.0));
    assert_pt(s[2].3, p(95.0, 100.0));
}

/// G40 in a block without movement: the block before ends perpendicular;
/// the next move removes the vector.
#[test]
fn cancel_without_movement_removes_the_vector_at_the_next_move() {
    let out = ok(
        StartupType::B,
        &[
            (line(p(0.0, -30.0), p(0.0, 0.0)), L5),
            (line(p(0.0, 0.0), p(100.0, 0.0)), L5),
            (None, OFF),
            (line(p(100.0, 0.0), p(100.0, -30.0)), OFF),
        ],
    );
    let s = summary(&out);
    assert_eq!(out[2].kind, PieceKind::Still);
    assert_pt(s[1].3, p(100.0, 5.0));
    assert_eq!((s[2].0, s[2].1), (Cancel, 3));
    assert_pt(s[2].2, p(100.0, 5.0));
    assert_pt(s[2].3, p(100.0, -30.0));
}

// ----- alarms -----------------------------------------------------------------

/// A groove 6 wide and 10 deep, cutter radius 5 (diameter 10): the offset
/// of the groove's bottom runs backwards, from (5, −5) to (1, −5):
/// PS0041 on that block, before any piece of it.
#[test]
fn groove_narrower_than_the_cutter_is_interference() {
    let blocks: Vec<Blk> = vec![
        (line(p(-50.0, -20.0), p(-50.0, 0.0)), L5),
        (line(p(-50.0, 0.0), p(0.0, 0.0)), L5),
        (line(p(0.0, 0.0), p(0.0, -10.0)), L5),
        (line(p(0.0, -10.0), p(6.0, -10.0)), L5),
        (line(p(6.0, -10.0), p(6.0, 0.0)), L5),
        (line(p(6.0, 0.0), p(50.0, 0.0)), L5),
        (line(p(50.0, 0.0), p(50.0, 20.0)), OFF),
    ];
    let mut comp = CutterComp::new(StartupType::A);
    let mut out = Vec::new();
    let mut err = None;
    for (tag, (e, mode)) in blocks.iter().enumerate() {
        let m = e.map(|element| Move {
            element,
            rapid: false,
            vector: None,
        });
        if let Err(e) = comp.push(m, *mode, tag as u32, &mut out) {
            err = Some(e);
            break;
        }
    }
    assert_eq!(err, Some(CompError::Interference { tag: 3 }));
    assert_eq!(err.and_then(|e| e.code()), Some(41));
    assert!(out.iter().all(|c| c.tag < 3), "{out:#?}");
    // The wall before it reached down to the bottom's offset.
    assert_pt(summary(&out)[2].3, p(5.0, -5.0));
    // Wide enough (10 = 2r) is no alarm.
    let mut wide = blocks.clone();
    wide[3].0 = line(p(0.0, -10.0), p(10.0, -10.0));
    wide[4].0 = line(p(10.0, -10.0), p(10.0, 0.0));
    wide[5].0 = line(p(10.0, 0.0), p(50.0, 0.0));
    ok(StartupType::A, &wide);
}

/// A counter-clockwise arc of radius 3 with G41 (tool inside) and r = 5:
/// the cutter does not fit: PS0041 on the arc.
#[test]
fn inner_arc_smaller_than_the_radius_is_interference() {
    let r = run(
        StartupType::A,
        &[
            (line(p(0.0, -30.0), p(0.0, 0.0)), L5),
            (line(p(0.0, 0.0), p(10.0, 0.0)), L5),
            (arc(p(10.0, 0.0), p(13.0, 3.0), p(10.0, 3.0), true), L5),
            (line(p(13.0, 3.0), p(13.0, 30.0)), L5),
            (line(p(13.0, 30.0), p(40.0, 30.0)), OFF),
        ],
    );
    assert_eq!(r, Err(CompError::Interference { tag: 2 }));
    // The same arc with G42 (tool outside) is fine.
    let mut right: Vec<Blk> = vec![
        (line(p(0.0, -30.0), p(0.0, 0.0)), R5),
        (line(p(0.0, 0.0), p(10.0, 0.0)), R5),
        (arc(p(10.0, 0.0), p(13.0, 3.0), p(10.0, 3.0), true), R5),
        (line(p(13.0, 3.0), p(13.0, 30.0)), R5),
    ];
    right.push((line(p(13.0, 30.0), p(40.0, 30.0)), OFF));
    ok(StartupType::A, &right);
}

/// Two counter-clockwise arcs of radius 6 about (0, 0) and (11, 0) meeting
/// at (5.5, √5.75) with a left turn; G41 r 5 keeps the tool inside both:
/// the offset circles (radius 1, 11 apart) never meet: PS0033 on the
/// second arc.
#[test]
fn inner_corner_without_intersection_is_ps0033() {
    let y = 5.75f64.sqrt();
    let r = run(
        StartupType::A,
        &[
            (line(p(-6.0, 30.0), p(-6.0, 0.0)), L5),
            (arc(p(-6.0, 0.0), p(5.5, y), p(0.0, 0.0), true), L5),
            (arc(p(5.5, y), p(17.0, 0.0), p(11.0, 0.0), true), L5),
        ],
    );
    assert_eq!(r, Err(CompError::NoIntersection { tag: 2 }));
    assert_eq!(r.err().and_then(|e| e.code()), Some(33));
}

#[test]
fn arc_centre_on_its_end_point_is_ps0038() {
    let r = run(
        StartupType::A,
        &[
            (line(p(0.0, -30.0), p(0.0, 0.0)), L5),
            (arc(p(0.0, 0.0), p(10.0, 0.0), p(10.0, 0.0), true), L5),
        ],
    );
    assert_eq!(r, Err(CompError::ArcCentreOnEndpoint { tag: 1 }));
    assert_eq!(r.err().and_then(|e| e.code()), Some(38));
}

#[test]
fn non_finite_input_is_refused() {
    let r = run(StartupType::A, &[(line(p(0.0, 0.0), p(f64::NAN, 0.0)), L5)]);
    assert_eq!(r, Err(CompError::NonFinite { tag: 0 }));
    let r = run(
        StartupType::A,
        &[(
            line(p(0.0, 0.0), p(1.0, 0.0)),
            Some((Side::Left, f64::INFINITY)),
        )],
    );
    assert_eq!(r.err().map(|e| e.code()), Some(None));
}

// ----- other behaviour ------------------------------------------------------------

/// A reversal (180° turn) on the outer side goes around the end with the
/// two extra points.
#[test]
fn reversal_goes_around_the_end() {
    let out = ok(
        StartupType::A,
        &[
            (line(p(0.0, -30.0), p(0.0, 0.0)), L5),
            (line(p(0.0, 0.0), p(100.0, 0.0)), L5),
            (line(p(100.0, 0.0), p(50.0, 0.0)), L5),
            (line(p(50.0, 0.0), p(50.0, -30.0)), OFF),
        ],
    );
    assert_lines(
        &out[1..4],
        &[
            (Offset, 1, p(0.0, 5.0), p(105.0, 5.0)),
            (Corner, 1, p(105.0, 5.0), p(105.0, -5.0)),
            (Offset, 2, p(105.0, -5.0), p(50.0, -5.0)),
        ],
    );
}

/// At the end of the program the held block ends perpendicular and the
/// vector stays.
#[test]
fn finish_leaves_the_vector() {
    let out = ok(
        StartupType::A,
        &[
            (line(p(0.0, -30.0), p(0.0, 0.0)), L5),
            (line(p(0.0, 0.0), p(100.0, 0.0)), L5),
        ],
    );
    assert_pt(summary(&out)[1].3, p(100.0, 5.0));
}

/// Cancel mode passes blocks through at once; offset mode holds one.
#[test]
fn look_ahead_holds_one_block_and_keeps_rapid() {
    let mut comp = CutterComp::default();
    let mut out = Vec::new();
    let mv = |a, b, rapid| {
        Some(Move {
            element: Element::Line { from: a, to: b },
            rapid,
            vector: None,
        })
    };
    assert!(
        comp.push(mv(p(0.0, 0.0), p(0.0, -30.0), true), OFF, 7, &mut out)
            .is_ok()
    );
    assert_eq!(out.len(), 1);
    assert_eq!(out[0].kind, PieceKind::Programmed);
    assert!(
        comp.push(mv(p(0.0, -30.0), p(0.0, 0.0), true), L5, 8, &mut out)
            .is_ok()
    );
    assert_eq!(out.len(), 1);
    assert!(comp.is_active());
    assert_eq!(comp.held_tag(), Some(8));
    assert!(
        comp.push(mv(p(0.0, 0.0), p(50.0, 0.0), false), L5, 9, &mut out)
            .is_ok()
    );
    assert_eq!(out.len(), 2);
    assert!(out[1].rapid && out[1].kind == StartUp && out[1].tag == 8);
    comp.reset();
    assert!(!comp.is_active());
}

// ----- properties ---------------------------------------------------------------

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x0C0C_0041),
        failure_persistence: None,
        ..Config::default()
    }
}

/// A convex polygon: vertices on a circle of radius `size` at sorted
/// angles with gaps of at least 10°, counter-clockwise.
fn convex_polygon() -> impl Strategy<Value = Vec<P2>> {
    (3usize..9, 20.0..200.0f64, any::<u64>()).prop_map(|(n, size, seed)| {
        // Deterministic gaps from the seed: weights 1..=8.
        let mut s = seed;
        let mut weights = Vec::with_capacity(n);
        for _ in 0..n {
            s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            weights.push(1.0 + ((s >> 33) % 8) as f64);
        }
        let total: f64 = weights.iter().sum();
        let free = 2.0 * PI - n as f64 * 10f64.to_radians();
        let mut angle = (seed % 360) as f64 * PI / 180.0;
        let mut pts = Vec::with_capacity(n);
        for w in weights {
            pts.push(p(angle.cos(), angle.sin()) * size);
            angle += 10f64.to_radians() + free * w / total;
        }
        pts
    })
}

/// How each side of the polygon is made: a line, or an arc bulging
/// outwards with half-angle β (radians).
#[derive(Clone, Copy, Debug)]
enum Edge {
    Line,
    Arc(f64),
}

/// The program around a convex polygon: start-up from outside onto the
/// middle of side 0, the sides, back to that middle, cancel outwards.
/// `ccw` chooses the direction; `edges[i]` the shape of side i (side 0 is
/// always a line). Returns the blocks and the expected signed offset of
/// each tag's element.
fn polygon_program(pts: &[P2], edges: &[Edge], ccw: bool, mode: (Side, f64)) -> Vec<Blk> {
    let mut v: Vec<P2> = pts.to_vec();
    if !ccw {
        v.reverse();
    }
    let n = v.len();
    let mid = (v[0] + v[1]) * 0.5;
    let t = (v[1] - v[0]).normalize();
    // Outward normal: right of a counter-clockwise side, left of a
    // clockwise one.
    let out_n = if ccw { p(t.y, -t.x) } else { p(-t.y, t.x) };
    let far = mid + out_n * (3.0 * mode.1 + 10.0);
    let mut blocks = vec![(line(far, mid), Some(mode))];
    let make_side = |a: P2, b: P2, edge: Edge| match edge {
        Edge::Line => line(a, b),
        Edge::Arc(beta) => {
            let half = (b - a).norm() / 2.0;
            let radius = half / beta.sin();
            let dir = (b - a).normalize();
            // The centre lies inwards: left of a counter-clockwise side.
            let inward = if ccw {
                p(-dir.y, dir.x)
            } else {
                p(dir.y, -dir.x)
            };
            let center = (a + b) * 0.5 + inward * (radius * beta.cos());
            arc(a, b, center, ccw)
        }
    };
    blocks.push((make_side(mid, v[1], Edge::Line), Some(mode)));
    for i in 1..n {
        let e = edges.get(i).copied().unwrap_or(Edge::Line);
        blocks.push((make_side(v[i], v[(i + 1) % n], e), Some(mode)));
    }
    blocks.push((make_side(v[0], mid, Edge::Line), Some(mode)));
    blocks.push((line(mid, far), None));
    blocks
}

/// Every offset line of a programmed line lies at the signed offset `d`
/// from that line; every offset arc of a programmed arc is concentric with
/// radius R − d (counter-clockwise) or R + d (clockwise).
fn check_offsets(blocks: &[Blk], out: &[Compensated], d: f64) -> Result<(), TestCaseError> {
    for c in out.iter().filter(|c| c.kind == Offset) {
        let Some((Some(prog), _)) = blocks.get(c.tag as usize) else {
            continue;
        };
        let Some(e) = c.element else { continue };
        let scale = 1e-9 * (1.0 + prog.start().norm() + d.abs());
        match (*prog, e) {
            (Element::Line { from, to }, Element::Line { from: a, to: b }) => {
                for q in [a, b] {
                    let s = signed_distance(q, from, to);
                    prop_assert!((s - d).abs() < 1e3 * scale, "{c:?} at {s} from {prog:?}");
                }
            }
            (
                Element::Arc {
                    center, from, ccw, ..
                },
                Element::Arc {
                    from: a,
                    to: b,
                    center: cc,
                    ccw: occw,
                },
            ) => {
                prop_assert_eq!(cc, center);
                prop_assert_eq!(ccw, occw);
                let rho = (from - center).norm() - if ccw { d } else { -d };
                for q in [a, b] {
                    prop_assert!(((q - center).norm() - rho).abs() < 1e3 * scale);
                }
            }
            _ => prop_assert!(false, "offset piece of another kind: {c:?} for {prog:?}"),
        }
    }
    Ok(())
}

fn run_blocks(ty: StartupType, blocks: &[Blk]) -> Result<Vec<Compensated>, CompError> {
    run(ty, blocks)
}

/// Outside a convex polygon (clockwise with G41 or counter-clockwise with
/// G42) there is no interference: the program is accepted, the path joins,
/// starts at the start-up point, ends on the cancel point, and every
/// offset line is at exactly r on the tool side.
#[test]
fn property_convex_polygon_outside_offsets_are_at_r() {
    let strategy = (
        convex_polygon(),
        0.05..30.0f64,
        any::<bool>(),
        any::<bool>(),
    );
    check(config(256), strategy, |(pts, r, ccw, type_b)| {
        let side = if ccw { Side::Right } else { Side::Left };
        let blocks = polygon_program(&pts, &[], ccw, (side, r));
        let ty = if type_b {
            StartupType::B
        } else {
            StartupType::A
        };
        let out = run_blocks(ty, &blocks).map_err(|e| TestCaseError::fail(format!("{e:?}")))?;
        assert_joined(&out);
        let first = out.first().and_then(|c| c.element).map(|e| e.start());
        let last = out.last().and_then(|c| c.element).map(|e| e.end());
        prop_assert_eq!(first, blocks.first().and_then(|b| b.0).map(|e| e.start()));
        prop_assert_eq!(last, blocks.last().and_then(|b| b.0).map(|e| e.end()));
        let d = if ccw { -r } else { r };
        check_offsets(&blocks, &out, d)
    });
}

/// Inside a convex polygon corners are inner: either an interference
/// alarm (the cutter does not fit a side) or every offset line at r.
#[test]
fn property_convex_polygon_inside_offsets_are_at_r_or_interference() {
    let strategy = (convex_polygon(), 0.05..60.0f64, any::<bool>());
    check(config(256), strategy, |(pts, r, ccw)| {
        let side = if ccw { Side::Left } else { Side::Right };
        let blocks = polygon_program(&pts, &[], ccw, (side, r));
        match run_blocks(StartupType::B, &blocks) {
            Ok(out) => {
                assert_joined(&out);
                check_offsets(&blocks, &out, if ccw { r } else { -r })
            }
            Err(CompError::Interference { .. } | CompError::NoIntersection { .. }) => Ok(()),
            Err(e) => Err(TestCaseError::fail(format!("{e:?}"))),
        }
    });
}

/// Convex chains of lines and outward-bulging arcs, cut outside with a
/// radius small against the geometry: accepted, joined, offset lines at r
/// and offset arcs concentric with radius R + r.
#[test]
fn property_convex_arc_chains_outside_are_concentric() {
    let edges = proptest::collection::vec(
        prop_oneof![Just(Edge::Line), (0.05..1.4f64).prop_map(Edge::Arc)],
        9,
    );
    let strategy = (
        convex_polygon(),
        edges,
        0.01..1.0f64,
        any::<bool>(),
        any::<bool>(),
    );
    check(config(256), strategy, |(pts, edges, rf, ccw, type_b)| {
        let n = pts.len();
        let shortest = (0..n)
            .map(|i| (pts[(i + 1) % n] - pts[i]).norm())
            .fold(f64::INFINITY, f64::min);
        let r = rf * 0.1 * shortest;
        let side = if ccw { Side::Right } else { Side::Left };
        let blocks = polygon_program(&pts, &edges, ccw, (side, r));
        let ty = if type_b {
            StartupType::B
        } else {
            StartupType::A
        };
        let out = run_blocks(ty, &blocks).map_err(|e| TestCaseError::fail(format!("{e:?}")))?;
        assert_joined(&out);
        let d = if ccw { -r } else { r };
        check_offsets(&blocks, &out, d)?;
        // Every programmed arc has its offset arc.
        for (tag, (e, _)) in blocks.iter().enumerate() {
            if matches!(e, Some(Element::Arc { .. })) {
                let has_arc = out.iter().any(|c| {
                    c.tag as usize == tag && matches!(c.element, Some(Element::Arc { .. }))
                });
                prop_assert!(has_arc, "no offset arc for block {}", tag);
            }
        }
        Ok(())
    });
}

fn coordinate() -> impl Strategy<Value = f64> {
    prop_oneof![
        6 => -100.0..100.0f64,
        1 => Just(0.0),
        1 => -1e-9..1e-9f64,
        1 => prop_oneof![Just(1e12), Just(-1e12), Just(1e300)],
    ]
}

fn radius() -> impl Strategy<Value = Option<(Side, f64)>> {
    let r = prop_oneof![
        6 => 0.0..20.0f64,
        1 => Just(0.0),
        1 => -20.0..0.0f64,
        1 => prop_oneof![Just(1e-12), Just(1e9), Just(1e300), Just(f64::NAN)],
    ];
    prop_oneof![
        1 => Just(None),
        3 => (prop_oneof![Just(Side::Left), Just(Side::Right)], r).prop_map(Some),
    ]
}

#[derive(Clone, Copy, Debug)]
enum Step {
    Still,
    Line(f64, f64),
    Back,
    Arc(f64, f64, f64, f64, bool),
    FullCircle(f64, f64, bool),
}

fn step() -> impl Strategy<Value = Step> {
    prop_oneof![
        2 => Just(Step::Still),
        6 => (coordinate(), coordinate()).prop_map(|(x, y)| Step::Line(x, y)),
        1 => Just(Step::Back),
        3 => (coordinate(), coordinate(), coordinate(), coordinate(), any::<bool>())
            .prop_map(|(a, b, c, d, ccw)| Step::Arc(a, b, c, d, ccw)),
        1 => (coordinate(), coordinate(), any::<bool>()).prop_map(|(a, b, ccw)| Step::FullCircle(a, b, ccw)),
    ]
}

/// Random continuous chains with random modes, degenerate elements (zero
/// length, reversals, centres on end points, full circles, huge values)
/// never panic; what is accepted is finite, joined and in tag order.
#[test]
fn property_random_programs_never_panic() {
    let strategy = (
        proptest::collection::vec((step(), radius()), 1..14),
        any::<bool>(),
    );
    check(config(2048), strategy, |(steps, type_b)| {
        let ty = if type_b {
            StartupType::B
        } else {
            StartupType::A
        };
        let mut comp = CutterComp::new(ty);
        let mut out = Vec::new();
        let mut at = p(0.0, 0.0);
        let mut prev = at;
        let mut failed = false;
        for (tag, (s, mode)) in steps.iter().enumerate() {
            let element = match *s {
                Step::Still => None,
                Step::Line(x, y) => Some(Element::Line {
                    from: at,
                    to: p(x, y),
                }),
                Step::Back => Some(Element::Line { from: at, to: prev }),
                Step::Arc(x, y, cx, cy, ccw) => Some(Element::Arc {
                    from: at,
                    to: p(x, y),
                    center: p(cx, cy),
                    ccw,
                }),
                Step::FullCircle(cx, cy, ccw) => Some(Element::Arc {
                    from: at,
                    to: at,
                    center: p(cx, cy),
                    ccw,
                }),
            };
            if let Some(e) = element {
                prev = at;
                at = e.end();
            }
            let m = element.map(|element| Move {
                element,
                rapid: tag % 3 == 0,
                vector: None,
            });
            if comp.push(m, *mode, tag as u32, &mut out).is_err() {
                failed = true;
                break;
            }
        }
        if !failed {
            let _ = comp.finish(&mut out);
        }
        let mut last: Option<P2> = None;
        let mut last_tag = 0;
        for c in &out {
            prop_assert!(c.tag >= last_tag);
            last_tag = c.tag;
            if let Some(e) = c.element {
                let pts = match e {
                    Element::Line { from, to } => [from, to, from],
                    Element::Arc {
                        from, to, center, ..
                    } => [from, to, center],
                };
                prop_assert!(
                    pts.iter().all(|q| q.x.is_finite() && q.y.is_finite()),
                    "{c:?}"
                );
                if let Some(l) = last {
                    // Exact joins; a start-up starts at its programmed start
                    // point, which a move below the length tolerance before
                    // it (no movement for compensation) may miss by that.
                    let gap = (e.start() - l).norm();
                    let allowed = if c.kind == StartUp { 1e-7 } else { 0.0 };
                    prop_assert!(gap <= allowed, "gap {} before {:?}", gap, c);
                }
                last = Some(e.end());
            }
        }
        Ok(())
    });
}
