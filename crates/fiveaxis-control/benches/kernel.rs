//! Benchmarks of the kernel alone, without I/O or output formatting:
//!
//! * `front_end/parse_line`: the G-code front end over a 10,000-line
//!   program held in memory, one [`Block`] reused;
//! * `runner/segments` and `runner/rows`: the whole [`Runner`] over the
//!   same program on the `trunnion-ac` machine, consuming every segment,
//!   and (`rows`) also computing its row at s = 1 as `fiveaxis run` does;
//! * `kinematics/forward`: [`Machine::forward`] over 1,024 machine
//!   positions.
//!
//! Throughput is reported in blocks (or calls) per second. Run with
//! `cargo bench -p fiveaxis-control --bench kernel`; the end-to-end
//! comparison with LinuxCNC's `rs274` is `bench/run.sh`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use fiveaxis_control::{RunOptions, Runner, SliceSource};
use fiveaxis_gcode::{Block, parse_line};
use fiveaxis_machine::{Joints, MAX_AXES, Machine, Offsets, builtin};

/// G1 blocks in the benchmark program.
const BLOCKS: usize = 10_000;
/// Machine positions for the forward-kinematics benchmark.
const POSES: usize = 1024;

/// A small deterministic generator (xorshift64*), so that the program is
/// the same on every run without a random-number crate.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        (x >> 11) as f64 / (1u64 << 53) as f64
    }

    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

/// The same kind of program as `bench/gen.py`: a header, `BLOCKS` G1
/// blocks with five axes inside the default machine's limits, `M30`.
fn program() -> Vec<u8> {
    use std::fmt::Write as _;
    let mut rng = Rng(0x5eed_f1e5_a1c5);
    let mut text = String::from("G21 G90 G94 G17\nG0 X0 Y0 Z0\nF1000.\n");
    for _ in 0..BLOCKS {
        let (x, y, z) = (
            rng.uniform(-200.0, 200.0),
            rng.uniform(-200.0, 200.0),
            rng.uniform(-100.0, 100.0),
        );
        let (a, c) = (rng.uniform(-100.0, 0.0), rng.uniform(0.0, 359.999));
        writeln!(text, "G1 X{x:.3} Y{y:.3} Z{z:.3} A{a:.3} C{c:.3}").expect("writing to a String");
    }
    text.push_str("M30\n");
    text.into_bytes()
}

/// The same number of TCPC type 2 blocks (`bench/gen.py --tcpc`): tool
/// vectors within 60° of +Z.
fn tcpc_program() -> Vec<u8> {
    use std::fmt::Write as _;
    let mut rng = Rng(0x7c9c_5eed);
    let mut text = String::from("G21 G90 G94 G17\nG0 X0 Y0 Z0\nF1000.\nG43.5 H0 X0 Y0 Z50.\n");
    for _ in 0..BLOCKS {
        let (x, y, z) = (
            rng.uniform(-150.0, 150.0),
            rng.uniform(-150.0, 150.0),
            rng.uniform(0.0, 100.0),
        );
        let tilt = rng.uniform(0.0, 60.0).to_radians();
        let turn = rng.uniform(0.0, 360.0).to_radians();
        let (i, j, k) = (tilt.sin() * turn.cos(), tilt.sin() * turn.sin(), tilt.cos());
        writeln!(text, "G1 X{x:.3} Y{y:.3} Z{z:.3} I{i:.6} J{j:.6} K{k:.6}")
            .expect("writing to a String");
    }
    text.push_str("M30\n");
    text.into_bytes()
}

fn machine() -> Machine {
    builtin("trunnion-ac").expect("trunnion-ac is a built-in machine")
}

/// Runs the whole program; returns the number of segments and a checksum
/// of what was computed, so that nothing is optimised away.
fn run(machine: &Machine, program: &[u8], rows: bool) -> (usize, f64) {
    let source = SliceSource::new(program);
    let mut runner = Runner::new(machine, Offsets::default(), source, RunOptions::default());
    let mut count = 0;
    let mut sum = 0.0;
    while let Some(seg) = runner
        .next_segment()
        .expect("the benchmark program runs without alarm")
    {
        count += 1;
        if rows {
            let row = seg.row(machine, 1.0);
            sum += row.tip.x + row.dir.z;
        } else {
            sum += seg.end[0];
        }
    }
    (count, sum)
}

fn front_end(c: &mut Criterion) {
    let program = program();
    let lines: Vec<&[u8]> = program
        .split(|&b| b == b'\n')
        .filter(|l| !l.is_empty())
        .collect();
    let mut group = c.benchmark_group("front_end");
    group.throughput(Throughput::Elements(lines.len() as u64));
    group.bench_function("parse_line", |b| {
        let mut block = Block::default();
        b.iter(|| {
            let mut words = 0;
            for (i, line) in lines.iter().enumerate() {
                parse_line(black_box(line), i as u32 + 1, &mut block)
                    .expect("the benchmark program parses");
                words += block.words.len();
            }
            words
        });
    });
    group.finish();
}

fn runner(c: &mut Criterion) {
    let program = program();
    let machine = machine();
    let (segments, _) = run(&machine, &program, true);
    assert_eq!(segments, BLOCKS, "one segment per G1 block");
    let mut group = c.benchmark_group("runner");
    group.throughput(Throughput::Elements(BLOCKS as u64));
    group.bench_function("segments", |b| {
        b.iter(|| run(&machine, black_box(&program), false))
    });
    group.bench_function("rows", |b| {
        b.iter(|| run(&machine, black_box(&program), true))
    });
    let tcpc = tcpc_program();
    let (segments, _) = run(&machine, &tcpc, true);
    assert_eq!(
        segments,
        BLOCKS + 1,
        "one segment per G1 block and the start-up"
    );
    group.bench_function("tcpc_rows", |b| {
        b.iter(|| run(&machine, black_box(&tcpc), true))
    });
    group.finish();
}

fn kinematics(c: &mut Criterion) {
    let machine = machine();
    let mut rng = Rng(0xf0_4a4d);
    let poses: Vec<Joints> = (0..POSES)
        .map(|_| {
            let mut joints = [0.0; MAX_AXES];
            joints[..5].copy_from_slice(&[
                rng.uniform(-200.0, 200.0),
                rng.uniform(-200.0, 200.0),
                rng.uniform(-100.0, 100.0),
                rng.uniform(-100.0, 0.0),
                rng.uniform(0.0, 360.0),
            ]);
            joints
        })
        .collect();
    let mut group = c.benchmark_group("kinematics");
    group.throughput(Throughput::Elements(POSES as u64));
    group.bench_function("forward", |b| {
        b.iter(|| {
            let mut sum = 0.0;
            for joints in &poses {
                let pose = machine.forward(black_box(joints), black_box(100.0));
                sum += pose.tip.x + pose.dir.z;
            }
            sum
        });
    });
    group.finish();
}

fn config() -> Criterion {
    Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
}

criterion_group! {
    name = benches;
    config = config();
    targets = front_end, runner, kinematics
}
criterion_main!(benches);
