//! Samples per second through the planner: a 5-axis program of short
//! blocks along a helix with the rotary axes turning, 8 samples a block,
//! planned without and with a jerk limit (`planner/trapezoid`,
//! `planner/s_curve`), and a program of long straight G01 lines with
//! rapids between them (`planner/lines`). Run with
//! `cargo bench -p fiveaxis-planner --bench planner`.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use fiveaxis_planner::{AxisLimits, Block, Feed, Options, Planner, Point};

/// Blocks of the helix program.
const BLOCKS: usize = 10_000;
/// Samples per block.
const SAMPLES: usize = 8;

fn limits(jerk: Option<f64>) -> [AxisLimits; 5] {
    let linear = AxisLimits {
        max_velocity: 30_000.0,
        rapid: 48_000.0,
        max_acceleration: 3000.0,
        max_jerk: jerk,
    };
    let rotary = AxisLimits {
        max_velocity: 10_800.0,
        rapid: 18_000.0,
        max_acceleration: 1500.0,
        max_jerk: jerk,
    };
    [linear, linear, linear, rotary, rotary]
}

/// The helix program: each block a list of samples.
fn helix() -> Vec<Vec<Point>> {
    let mut blocks = Vec::with_capacity(BLOCKS);
    let step = 0.02; // rad per sample
    let mut k = 0usize;
    let mut prev = [50.0, 0.0, 0.0, 0.0, 0.0];
    for _ in 0..BLOCKS {
        let mut points = Vec::with_capacity(SAMPLES);
        for _ in 0..SAMPLES {
            k += 1;
            let a = k as f64 * step;
            let q = [
                50.0 * a.cos(),
                50.0 * a.sin(),
                0.01 * k as f64,
                30.0 * (0.1 * a).sin(),
                a.to_degrees(),
            ];
            let len = (0..3).map(|i| (q[i] - prev[i]).powi(2)).sum::<f64>().sqrt();
            points.push(Point::new(&q, len));
            prev = q;
        }
        blocks.push(points);
    }
    blocks
}

fn run(blocks: &[Vec<Point>], jerk: Option<f64>) -> f64 {
    let start = [50.0, 0.0, 0.0, 0.0, 0.0];
    let mut planner =
        Planner::new(&limits(jerk), Options::default(), &start).expect("valid limits");
    for points in blocks {
        let block = Block {
            feed: Feed::PerMinute(5000.0),
            exact_stop: false,
            points,
        };
        planner.push(&block).expect("valid block");
    }
    planner.finish().time
}

fn lines(count: usize) -> f64 {
    let mut planner =
        Planner::new(&limits(None), Options::default(), &[0.0; 5]).expect("valid limits");
    for k in 0..count {
        let x = if k % 2 == 0 { 100.0 } else { 0.0 };
        let y = k as f64 * 0.5;
        let feed = if k % 10 == 9 {
            Feed::Rapid
        } else {
            Feed::PerMinute(3000.0)
        };
        let points = [Point::new(&[x, y, 0.0, 0.0, 0.0], 100.0)];
        planner
            .push(&Block {
                feed,
                exact_stop: false,
                points: &points,
            })
            .expect("valid block");
    }
    planner.finish().time
}

fn bench(c: &mut Criterion) {
    let blocks = helix();
    let mut group = c.benchmark_group("planner");
    group.throughput(Throughput::Elements((BLOCKS * SAMPLES) as u64));
    group.bench_function("trapezoid", |b| b.iter(|| run(black_box(&blocks), None)));
    group.bench_function("s_curve", |b| {
        b.iter(|| run(black_box(&blocks), Some(50_000.0)))
    });
    group.throughput(Throughput::Elements(BLOCKS as u64));
    group.bench_function("lines", |b| b.iter(|| lines(black_box(BLOCKS))));
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
