//! Material removal against closed-form volumes: a slot, a hole, a ball's
//! cap, a trench cut by the side of a horizontal tool, a gouge of known
//! depth; the dexels of a mesh against those of the same box; the
//! surface written out encloses the dexels' volume.

use std::f64::consts::PI;

use fiveaxis_machine::Vec3;
use fiveaxis_machine::geometry::{Cutter, ToolShape};
use fiveaxis_stock::dexel::Dexels;
use fiveaxis_stock::solid::{Posed, ToolPieces};
use fiveaxis_stock::{Part, Stock};

const CELL: f64 = 0.1;

/// A stock box 0..100 × 0..50 × −20..0.
fn block() -> Dexels {
    let (min, max) = (Vec3::new(0.0, 0.0, -20.0), Vec3::new(100.0, 50.0, 0.0));
    let margin = Vec3::repeat(1.0);
    let mut d = Dexels::empty(&(min - margin), &(max + margin), CELL).expect("grid");
    d.fill_box(&min, &max);
    d
}

fn tool(cutter: Cutter, radius: f64) -> ToolPieces {
    let shape = ToolShape {
        cutter,
        flute: 30.0,
        shank: 2.0 * radius,
        holder: Vec::new(),
    };
    ToolPieces::of(&shape, 100.0, radius)
}

/// Cuts along the straight move from `a` to `b` with the axis `axis`, at
/// poses `step` apart; the volume removed.
fn sweep(stock: &mut Stock, pieces: &ToolPieces, a: Vec3, b: Vec3, axis: Vec3) -> f64 {
    let n = ((b - a).norm() / CELL).ceil().max(1.0) as u32;
    let mut removed = 0.0;
    for k in 0..=n {
        let tip = a + (b - a) * (f64::from(k) / f64::from(n));
        let posed = Posed::new(&pieces.cutting, &tip, &axis);
        removed += stock.cut(&posed, 1, false).removed;
    }
    removed
}

fn close(got: f64, want: f64, relative: f64) {
    assert!(
        (got - want).abs() <= relative * want,
        "got {got}, want {want} (±{:.2} %)",
        relative * 100.0
    );
}

#[test]
fn a_slot_through_the_block() {
    let mut stock = Stock::new(block(), None, 0.05);
    let start = stock.dexels.volume();
    close(start, 100.0 * 50.0 * 20.0, 1e-9);
    let up = Vec3::z();
    let removed = sweep(
        &mut stock,
        &tool(Cutter::Flat, 5.0),
        Vec3::new(-10.0, 25.0, -5.0),
        Vec3::new(110.0, 25.0, -5.0),
        up,
    );
    // 10 wide, 5 deep, 100 long.
    close(removed, 5000.0, 0.005);
    close(start - stock.dexels.volume(), removed, 1e-6);
    // The same pass again cuts air.
    let again = sweep(
        &mut stock,
        &tool(Cutter::Flat, 5.0),
        Vec3::new(-10.0, 25.0, -5.0),
        Vec3::new(110.0, 25.0, -5.0),
        up,
    );
    assert!(again < 1e-6, "{again}");
}

#[test]
fn a_hole_and_a_ball_cap() {
    let mut stock = Stock::new(block(), None, 0.05);
    let up = Vec3::z();
    // A flat end mill of radius 4 plunges 10 mm: π r² h.
    let hole = sweep(
        &mut stock,
        &tool(Cutter::Flat, 4.0),
        Vec3::new(20.0, 20.0, 5.0),
        Vec3::new(20.0, 20.0, -10.0),
        up,
    );
    close(hole, PI * 16.0 * 10.0, 0.01);
    // A ball of radius 5 pressed 3 mm in: the cap π h² (3R − h) / 3.
    let posed = Posed::new(
        &tool(Cutter::Ball, 5.0).cutting,
        &Vec3::new(60.0, 25.0, -3.0),
        &up,
    );
    let cap = stock.cut(&posed, 1, false).removed;
    close(cap, PI * 9.0 * (15.0 - 3.0) / 3.0, 0.01);
    // A drill of 118°: the cone's volume π r² h / 3 below the full
    // diameter, then the cylinder.
    let drill = tool(Cutter::Drill { point_angle: 118.0 }, 3.0);
    let point = 3.0 / 59f64.to_radians().tan();
    let posed = Posed::new(&drill.cutting, &Vec3::new(80.0, 25.0, -10.0), &up);
    let removed = stock.cut(&posed, 1, false).removed;
    let want = PI * 9.0 * point / 3.0 + PI * 9.0 * (10.0 - point);
    close(removed, want, 0.01);
}

#[test]
fn the_side_of_a_horizontal_tool_cuts_a_trench() {
    let mut stock = Stock::new(block(), None, 0.05);
    // The axis along +y, the tip at y 10: the cutting part (30 long, radius
    // 4) spans y 10..40 inside the block, its axis at z 0 (the top):
    // moving along x it sweeps everything from the top down to z −4 over
    // those 30 mm, a trench 30 · 4 · 100.
    let removed = sweep(
        &mut stock,
        &tool(Cutter::Flat, 4.0),
        Vec3::new(-10.0, 10.0, 0.0),
        Vec3::new(110.0, 10.0, 0.0),
        Vec3::y(),
    );
    close(removed, 30.0 * 4.0 * 100.0, 0.005);
}

#[test]
fn a_tilted_flat_end_mill_pressed_into_a_plane_cuts_a_wedge_of_its_disc() {
    let mut stock = Stock::new(block(), None, 0.05);
    // Tilted 30° about y, the tip's centre at the surface: the lower half
    // of the end face goes below z 0, at most r·sin 30° deep. The volume
    // below the plane of a cylinder tilted by θ whose end-face centre
    // lies on the plane: 2 r³ tan θ / 3.
    let theta = 30f64.to_radians();
    let axis = Vec3::new(theta.sin(), 0.0, theta.cos());
    let r: f64 = 5.0;
    let posed = Posed::new(
        &tool(Cutter::Flat, r).cutting,
        &Vec3::new(50.0, 25.0, 0.0),
        &axis,
    );
    let removed = stock.cut(&posed, 1, false).removed;
    close(removed, 2.0 * r.powi(3) * theta.tan() / 3.0, 0.02);
}

#[test]
fn a_ball_mill_gouges_a_plane_at_a_known_depth() {
    // The part is the block below z −2; the stock the whole block. A ball
    // mill of radius 5 runs along x with its tip at z −2.3: 0.3 mm into
    // the part.
    let stock_dexels = block();
    let mut design = stock_dexels.like();
    let (pmin, pmax) = (Vec3::new(0.0, 0.0, -20.0), Vec3::new(100.0, 50.0, -2.0));
    design.fill_box(&pmin, &pmax);
    let part = Part {
        dexels: design,
        depth: Box::new(move |p| box_depth(pmin, pmax, p)),
    };
    let mut stock = Stock::new(stock_dexels, Some(part), 0.05);
    let ball = tool(Cutter::Ball, 5.0);
    let mut deepest: f64 = 0.0;
    for k in 0..=200 {
        let tip = Vec3::new(20.0 + 0.1 * f64::from(k), 25.0, -2.3);
        let cut = stock.cut(&Posed::new(&ball.cutting, &tip, &Vec3::z()), 7, false);
        deepest = deepest.max(cut.gouge);
    }
    assert!((deepest - 0.3).abs() < 1e-3, "{deepest}");
    // Material is left over the part where the ball did not pass.
    let left = stock.left_on_part();
    assert!(left.iter().any(|l| l.0 == 0 && (l.1 - 2.0).abs() < 1e-3));
    // A tool that stays 0.02 mm above the part gouges nothing.
    let mut clean = Stock::new(block(), None, 0.05);
    let cut = clean.cut(
        &Posed::new(&ball.cutting, &Vec3::new(50.0, 25.0, -1.98), &Vec3::z()),
        1,
        false,
    );
    assert_eq!(cut.gouge, 0.0);
}

/// The triangles of a box's surface, outward.
fn box_mesh(min: Vec3, max: Vec3) -> Vec<[Vec3; 3]> {
    let p = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { min.x } else { max.x },
            if i & 2 == 0 { min.y } else { max.y },
            if i & 4 == 0 { min.z } else { max.z },
        )
    };
    let faces = [
        [0, 2, 3, 1], // bottom (−z)
        [4, 5, 7, 6], // top (+z)
        [0, 1, 5, 4], // −y
        [2, 6, 7, 3], // +y
        [0, 4, 6, 2], // −x
        [1, 3, 7, 5], // +x
    ];
    let mut out = Vec::new();
    for f in faces {
        out.push([p(f[0]), p(f[1]), p(f[2])]);
        out.push([p(f[0]), p(f[2]), p(f[3])]);
    }
    out
}

#[test]
fn a_mesh_fills_the_same_dexels_as_its_box() {
    let (min, max) = (Vec3::new(3.05, 4.05, -7.0), Vec3::new(40.05, 20.05, 2.5));
    let margin = Vec3::repeat(1.0);
    let mut from_box = Dexels::empty(&(min - margin), &(max + margin), 0.5).expect("grid");
    let mut from_mesh = from_box.like();
    from_box.fill_box(&min, &max);
    from_mesh.fill_mesh(&box_mesh(min, max));
    close(from_mesh.volume(), from_box.volume(), 1e-6);
    // Reversed triangles fill the same (nonzero winding).
    let mut reversed = from_box.like();
    let flipped: Vec<_> = box_mesh(min, max)
        .into_iter()
        .map(|[a, b, c]| [a, c, b])
        .collect();
    reversed.fill_mesh(&flipped);
    close(reversed.volume(), from_box.volume(), 1e-6);
}

#[test]
fn the_surface_of_a_cut_stock_is_closed() {
    let mut stock = Stock::new(block(), None, 0.05);
    sweep(
        &mut stock,
        &tool(Cutter::Ball, 3.0),
        Vec3::new(-5.0, 10.0, -2.0),
        Vec3::new(40.0, 30.0, -4.0),
        Vec3::z(),
    );
    // A coarse copy keeps the count of edges small.
    let mut coarse = Dexels::empty(
        &Vec3::new(-1.0, -1.0, -21.0),
        &Vec3::new(11.0, 7.0, 1.0),
        1.0,
    )
    .expect("grid");
    coarse.fill_box(&Vec3::new(0.0, 0.0, -20.0), &Vec3::new(10.0, 6.0, 0.0));
    let mut c = Stock::new(coarse, None, 0.05);
    c.cut(
        &Posed::new(
            &tool(Cutter::Flat, 2.0).cutting,
            &Vec3::new(5.0, 3.0, -3.0),
            &Vec3::z(),
        ),
        1,
        false,
    );
    let mut count = 0;
    c.dexels.triangles(|_| count += 1);
    assert!(count > 12);
    // The volume the surface encloses (divergence theorem) is the
    // dexels': no face is missing or turned inwards.
    let mut enclosed = 0.0;
    c.dexels.triangles(|t| {
        enclosed += t[0].dot(&t[1].cross(&t[2])) / 6.0;
    });
    close(enclosed, c.dexels.volume(), 1e-9);
}

mod properties {
    use super::*;
    use fiveaxis_stock::solid::Piece;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

        /// Where a vertical ray meets a sphere or a frustum of any size,
        /// axis and placement (found in closed form) is where points are
        /// inside it by the membership test (depth ≥ 0), sampled along
        /// the ray every 0.01 mm.
        #[test]
        fn ray_spans_are_the_inside_of_each_piece(
            sphere in any::<bool>(),
            dims in (0.0..8.0f64, 0.5..8.0f64, 0.5..30.0f64),
            axis in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
            at in (-5.0..5.0f64, -5.0..5.0f64),
        ) {
            let axis = Vec3::new(axis.0, axis.1, axis.2);
            prop_assume!(axis.norm() > 0.1);
            let axis = axis.normalize();
            let piece = if sphere {
                Piece::Sphere { at: dims.2 / 3.0, radius: dims.1 }
            } else {
                Piece::Frustum { a0: 0.0, a1: dims.2, r0: dims.0, r1: dims.1 }
            };
            let posed = Posed::new(&[piece], &Vec3::zeros(), &axis);
            let (x, y) = at;
            let span = posed.ray(x, y);
            let (lo, hi) = (posed.min.z - 1.0, posed.max.z + 1.0);
            let n = ((hi - lo) / 0.01) as usize;
            for k in 0..=n {
                let z = lo + 0.01 * k as f64;
                let inside = posed.depth(&Vec3::new(x, y, z)) >= 0.0;
                let claimed = span.is_some_and(|(a, b)| z >= a && z <= b);
                let near_end = span.is_some_and(|(a, b)| (z - a).abs() < 1e-6 || (z - b).abs() < 1e-6);
                prop_assert!(inside == claimed || near_end, "z {z}: inside {inside}, span {span:?}");
            }
        }
    }
}

/// Removes the box `min`..`max` from `d` (rays whose centre is inside).
fn cut_box(d: &mut Dexels, min: Vec3, max: Vec3) {
    let (lo, hi) = ((min.z - d.origin.z) as f32, (max.z - d.origin.z) as f32);
    for j in d.rows(min.y, max.y) {
        for i in d.columns(min.x, max.x) {
            let k = j * d.nx + i;
            d.subtract(k, lo, hi, |_| {});
        }
    }
}

/// How deep `p` is inside the box `min`..`max` (negative outside, the
/// distance then where one axis is out).
fn box_depth(min: Vec3, max: Vec3, p: &Vec3) -> f64 {
    let inside = [
        p.x - min.x,
        max.x - p.x,
        p.y - min.y,
        max.y - p.y,
        p.z - min.z,
        max.z - p.z,
    ];
    let least = inside.into_iter().fold(f64::INFINITY, f64::min);
    if least >= 0.0 {
        return least;
    }
    let out = Vec3::new(
        (min.x - p.x).max(p.x - max.x).max(0.0),
        (min.y - p.y).max(p.y - max.y).max(0.0),
        (min.z - p.z).max(p.z - max.z).max(0.0),
    );
    -out.norm()
}

#[test]
fn material_left_on_a_wall_is_measured_across_it() {
    // The part: a boss 20..80 × 10..40, the block's full height. The
    // stock left: the boss with 0.7 mm more on its +x wall, nothing
    // elsewhere. Material beside the wall, where the part has no rays.
    let (pmin, pmax) = (Vec3::new(20.0, 10.0, -20.0), Vec3::new(80.0, 40.0, 0.0));
    let empty = block().like();
    let mut design = empty.clone();
    design.fill_box(&pmin, &pmax);
    let mut left = empty;
    left.fill_box(&pmin, &Vec3::new(80.7, 40.0, 0.0));
    let part = Part {
        dexels: design,
        depth: Box::new(move |p| box_depth(pmin, pmax, p)),
    };
    let stock = Stock::new(left, Some(part), 0.05);
    let found = stock.left_on_part();
    assert_eq!(found.len(), 1, "{found:?}");
    let (line, most, at, volume) = found[0];
    assert_eq!(line, 0, "never cut");
    // The farthest ray centre is 80.65: 0.65 mm from the wall.
    assert!((most - 0.65).abs() < 1e-4, "{most}");
    assert!((at.x - 80.65).abs() < 1e-4, "{at:?}");
    // 0.7 × 30 × 20 mm³, to the rays' width.
    assert!((volume - 420.0).abs() < 0.1 * 30.0 * 20.0, "{volume}");
}

#[test]
fn a_pocket_wall_left_thick_is_its_thickness_not_the_pocket_depth() {
    // The part: the block with a pocket 30..70 × 15..35, 5 deep. The
    // stock left: the pocket 0.5 mm narrower on every wall, its floor
    // exact.
    let (bmin, bmax) = (Vec3::new(0.0, 0.0, -20.0), Vec3::new(100.0, 50.0, 0.0));
    let (qmin, qmax) = (Vec3::new(30.0, 15.0, -5.0), Vec3::new(70.0, 35.0, 10.0));
    let mut design = block();
    cut_box(&mut design, qmin, qmax);
    let mut left = block();
    cut_box(
        &mut left,
        qmin + Vec3::new(0.5, 0.5, 0.0),
        qmax - Vec3::new(0.5, 0.5, 0.0),
    );
    let depth = move |p: &Vec3| box_depth(bmin, bmax, p).min(-box_depth(qmin, qmax, p));
    let part = Part {
        dexels: design,
        depth: Box::new(depth),
    };
    let stock = Stock::new(left, Some(part), 0.05);
    let found = stock.left_on_part();
    assert_eq!(found.len(), 1, "{found:?}");
    let (_, most, at, _) = found[0];
    // Rays 0.05..0.45 mm in from the walls: the farthest 0.45 mm.
    assert!((most - 0.45).abs() < 1e-4, "{most} at {at:?}");
    assert!(at.z > -5.0 && at.z <= 0.0, "{at:?}");
    // A tolerance above the thickness: nothing left to report.
    let mut exact = Stock::new(block(), None, 0.5);
    exact.part = Some(Part {
        dexels: {
            let mut d = block();
            cut_box(&mut d, qmin, qmax);
            d
        },
        depth: Box::new(depth),
    });
    cut_box(
        &mut exact.dexels,
        qmin + Vec3::new(0.5, 0.5, 0.0),
        qmax - Vec3::new(0.5, 0.5, 0.0),
    );
    assert!(exact.left_on_part().is_empty());
}

#[test]
fn cutting_on_several_lanes_leaves_what_one_leaves() {
    use fiveaxis_stock::{Outcome, Pose};
    // A bull nose with a shank and a holder, leaning and plunging along a
    // seeded random walk over a block with a part inside it; the same
    // poses cut on 1, 2 and 3 lanes.
    let shape = ToolShape {
        cutter: Cutter::BullNose { corner: 1.5 },
        flute: 12.0,
        shank: 8.0,
        holder: vec![fiveaxis_machine::geometry::HolderStep {
            length: 30.0,
            diameter: 30.0,
            tip_diameter: 24.0,
        }],
    };
    let tools = [ToolPieces::of(&shape, 60.0, 4.0)];
    let (pmin, pmax) = (Vec3::new(10.0, 10.0, -20.0), Vec3::new(90.0, 40.0, -6.0));
    let part = || {
        let mut d = block().like();
        d.fill_box(&pmin, &pmax);
        Part {
            dexels: d,
            depth: Box::new(move |p: &Vec3| box_depth(pmin, pmax, p)),
        }
    };
    let mut seed = 11u64;
    let mut next = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut poses = Vec::new();
    let mut tip = Vec3::new(50.0, 25.0, 5.0);
    for k in 0..1200u32 {
        tip += Vec3::new(next() - 0.5, next() - 0.5, 0.6 * (next() - 0.55));
        tip.x = tip.x.clamp(-5.0, 105.0);
        tip.y = tip.y.clamp(-5.0, 55.0);
        tip.z = tip.z.clamp(-12.0, 5.0);
        let lean = Vec3::new(0.4 * (next() - 0.5), 0.4 * (next() - 0.5), 1.0).normalize();
        poses.push(Pose {
            tool: 0,
            tip,
            axis: lean,
            line: k + 1,
            measure_depth: k % 7 == 0,
        });
    }
    let mut results: Vec<(Stock, Vec<Outcome>)> = Vec::new();
    for lanes in [1, 2, 3] {
        let mut stock = Stock::new(block(), Some(part()), 0.05);
        let mut all = Vec::new();
        let mut out = Vec::new();
        // In batches, as the check feeds them.
        for batch in poses.chunks(100) {
            stock.run(&tools, batch, &mut out, lanes);
            all.extend_from_slice(&out);
        }
        results.push((stock, all));
    }
    let (one, outcomes) = &results[0];
    assert!(
        outcomes.iter().any(|o| o.cut.gouge > 0.0),
        "the walk gouges the part"
    );
    assert!(
        outcomes.iter().any(|o| o.shank > 0.0 || o.holder > 0.0),
        "and runs the shank or holder in"
    );
    for (other, theirs) in &results[1..] {
        assert_eq!(
            one.dexels.rays(),
            other.dexels.rays(),
            "the same stock left"
        );
        assert_eq!(
            one.left_on_part(),
            other.left_on_part(),
            "the same lines left material"
        );
        for (a, b) in outcomes.iter().zip(theirs) {
            assert!((a.cut.removed - b.cut.removed).abs() <= 1e-9 * a.cut.removed.max(1.0));
            assert_eq!(a.cut.gouge, b.cut.gouge);
            assert_eq!(a.cut.depth, b.cut.depth);
            assert_eq!((a.shank, a.holder), (b.shank, b.holder));
        }
    }
}
