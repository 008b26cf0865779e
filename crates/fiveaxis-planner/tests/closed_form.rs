//! A single line against the closed-form times: the trapezoid (constant
//! acceleration) and the double-S (jerk-limited) point-to-point move with
//! all its reduced cases, as L. Biagiotti and C. Melchiorri derive them
//! (*Trajectory Planning for Automatic Machines and Robots*, Springer 2008,
//! §3.2.2 and §3.4); rapids as FANUC's linear interpolation type
//! positioning; inverse time; exact stop; a corner against a straight
//! continuation.

use fiveaxis_planner::{AxisLimits, Block, Feed, Options, Piece, Planner, Point};

/// Relative agreement with a closed form.
const REL: f64 = 1e-6;

fn axis(vmax: f64, acc: f64, jerk: Option<f64>) -> AxisLimits {
    AxisLimits {
        max_velocity: vmax,
        rapid: vmax,
        max_acceleration: acc,
        max_jerk: jerk,
    }
}

/// Rest-to-rest time of a trapezoid over `h` with speed `v`, acceleration
/// `a` (Biagiotti §3.2.2: the cruise speed is reached when h ≥ v²/a).
fn trapezoid(h: f64, v: f64, a: f64) -> f64 {
    if h >= v * v / a {
        h / v + v / a
    } else {
        2.0 * (h / a).sqrt()
    }
}

/// Rest-to-rest time of the double-S over `h` with limits `v`, `a`, `j`
/// (Biagiotti §3.4.1, v0 = v1 = 0; returns the case as well).
fn double_s(h: f64, v: f64, a: f64, j: f64) -> (f64, &'static str) {
    // Case 1: the speed limit is reached.
    let ta = if v * j < a * a {
        2.0 * (v / j).sqrt()
    } else {
        a / j + v / a
    };
    let tv = h / v - ta;
    if tv >= 0.0 {
        let case = if v * j < a * a {
            "v reached, a not"
        } else {
            "v and a reached"
        };
        return (2.0 * ta + tv, case);
    }
    // Case 2: not reached; first assume a is.
    let tj = a / j;
    let delta = a.powi(4) / (j * j) + 4.0 * a * h;
    let ta = (a * a / j + delta.sqrt()) / (2.0 * a);
    if ta >= 2.0 * tj {
        return (2.0 * ta, "a reached, v not");
    }
    // Neither: four jerk phases of (h / 2j)^(1/3).
    (4.0 * (h / (2.0 * j)).cbrt(), "neither reached")
}

fn line_time(axes: &[AxisLimits], end: &[f64], samples: usize, feed: Feed) -> f64 {
    let start = vec![0.0; end.len()];
    let mut planner = Planner::new(axes, Options::default(), &start).expect("valid limits");
    let len = end.iter().map(|x| x * x).sum::<f64>().sqrt();
    let points: Vec<Point> = (1..=samples)
        .map(|k| {
            let f = k as f64 / samples as f64;
            let q: Vec<f64> = end.iter().map(|x| x * f).collect();
            Point::new(&q, len / samples as f64)
        })
        .collect();
    planner
        .push(&Block {
            feed,
            exact_stop: false,
            points: &points,
        })
        .expect("valid block");
    planner.finish().time
}

fn assert_close(got: f64, want: f64, what: &str) {
    assert!(
        (got - want).abs() <= REL * want,
        "{what}: planned {got} s, closed form {want} s"
    );
}

#[test]
fn trapezoid_reaches_the_feed() {
    let axes = [axis(30_000.0, 3000.0, None); 3];
    for samples in [1, 7, 1000] {
        let t = line_time(&axes, &[100.0, 0.0, 0.0], samples, Feed::PerMinute(6000.0));
        assert_close(t, trapezoid(100.0, 100.0, 3000.0), "reached");
    }
}

#[test]
fn trapezoid_short_of_the_feed() {
    let axes = [axis(30_000.0, 3000.0, None); 3];
    for samples in [1, 13] {
        let t = line_time(&axes, &[1.0, 0.0, 0.0], samples, Feed::PerMinute(6000.0));
        assert_close(t, trapezoid(1.0, 100.0, 3000.0), "not reached");
    }
}

#[test]
fn diagonal_line_is_limited_by_its_slowest_axis() {
    // X slow and weak, Y fast: along (3, 4)/5 the path speed is
    // min(F, vx/0.6, vy/0.8), the acceleration min(ax/0.6, ay/0.8).
    let axes = [axis(3000.0, 600.0, None), axis(30_000.0, 5000.0, None)];
    let t = line_time(&axes, &[60.0, 80.0], 50, Feed::PerMinute(10_000.0));
    let v = (10_000.0f64 / 60.0).min(50.0 / 0.6).min(500.0 / 0.8);
    let a = (600.0f64 / 0.6).min(5000.0 / 0.8);
    assert_close(t, trapezoid(100.0, v, a), "diagonal");
}

#[test]
fn double_s_in_every_case() {
    let (a, j) = (3000.0, 50_000.0);
    let cases = [
        (1000.0, 500.0, "v and a reached"),
        (100.0, 100.0, "v reached, a not"),
        (40.0, 500.0, "a reached, v not"),
        (5.0, 500.0, "neither reached"),
    ];
    for (h, v, name) in cases {
        let (want, case) = double_s(h, v, a, j);
        assert_eq!(case, name, "the test's case for h = {h}, v = {v}");
        let axes = [axis(60_000.0, a, Some(j)); 3];
        for samples in [1, 9, 500] {
            let t = line_time(&axes, &[0.0, h, 0.0], samples, Feed::PerMinute(v * 60.0));
            assert_close(t, want, name);
        }
    }
}

#[test]
fn rapid_is_linear_interpolation_type_positioning() {
    // X 100 at 24 m/min, Y 50 at 12 m/min: both need 0.25 s at rate, the
    // move is a straight line at the speed of the slower.
    let axes = [
        AxisLimits {
            max_velocity: 6000.0,
            rapid: 24_000.0,
            max_acceleration: 2000.0,
            max_jerk: None,
        },
        AxisLimits {
            max_velocity: 6000.0,
            rapid: 12_000.0,
            max_acceleration: 500.0,
            max_jerk: None,
        },
    ];
    let t = line_time(&axes, &[100.0, 50.0], 1, Feed::Rapid);
    let len = 125.0f64.sqrt() * 10.0;
    let (ux, uy) = (100.0 / len, 50.0 / len);
    let v = (400.0 / ux).min(200.0 / uy);
    let a = (2000.0 / ux).min(500.0 / uy);
    assert_close(t, trapezoid(len, v, a), "rapid");
    // Rapid time is independent of the length the caller measures.
    let mut planner = Planner::new(&axes, Options::default(), &[0.0, 0.0]).expect("limits");
    let points = [Point::new(&[100.0, 50.0], 1.0)];
    planner
        .push(&Block {
            feed: Feed::Rapid,
            exact_stop: false,
            points: &points,
        })
        .expect("block");
    assert_close(
        planner.finish().time,
        trapezoid(len, v, a),
        "rapid, other length",
    );
}

#[test]
fn inverse_time_takes_one_over_f_minutes() {
    let axes = [axis(30_000.0, 1e6, None); 3];
    // 50 mm in 1/2 min is 100 mm/min; with a huge acceleration, 30 s.
    let t = line_time(&axes, &[30.0, 40.0, 0.0], 5, Feed::InverseTime(2.0));
    assert_close(t, trapezoid(50.0, 50.0 / 30.0, 1e6), "G93");
    assert!(t >= 30.0);
    // The same block as G94 at the equivalent feed takes the same time.
    let axes = [axis(30_000.0, 20.0, None); 3];
    let g93 = line_time(&axes, &[30.0, 40.0, 0.0], 5, Feed::InverseTime(2.0));
    let g94 = line_time(&axes, &[30.0, 40.0, 0.0], 5, Feed::PerMinute(100.0));
    assert_close(g93, g94, "G93 against G94");
    assert!(g93 > 30.0);
}

/// Two blocks: X 50, then 50 more either straight on or turning 90°.
fn two_blocks(turn: bool, exact_stop: bool) -> (f64, Vec<Piece>) {
    let axes = [axis(30_000.0, 3000.0, None); 3];
    let mut planner = Planner::new(&axes, Options::default(), &[0.0; 3]).expect("limits");
    let mut trace = Vec::new();
    let first = [Point::new(&[50.0, 0.0, 0.0], 50.0)];
    let second = if turn {
        [Point::new(&[50.0, 50.0, 0.0], 50.0)]
    } else {
        [Point::new(&[100.0, 0.0, 0.0], 50.0)]
    };
    for (points, stop) in [(&first, exact_stop), (&second, false)] {
        planner
            .push_traced(
                &Block {
                    feed: Feed::PerMinute(12_000.0),
                    exact_stop: stop,
                    points,
                },
                &mut trace,
            )
            .expect("block");
    }
    (planner.finish_traced(&mut trace).time, trace)
}

/// The planned speed where the path parameter reaches `s`.
fn speed_at(trace: &[Piece], s: f64) -> f64 {
    for p in trace {
        let tau = p.duration;
        let end = p.s + p.v * tau + p.a * tau * tau / 2.0 + p.j * tau.powi(3) / 6.0;
        if end >= s {
            // Bisect the piece's time for s.
            let (mut lo, mut hi) = (0.0, tau);
            for _ in 0..100 {
                let m = 0.5 * (lo + hi);
                let sm = p.s + p.v * m + p.a * m * m / 2.0 + p.j * m.powi(3) / 6.0;
                if sm < s { lo = m } else { hi = m }
            }
            return p.v + p.a * lo + p.j * lo * lo / 2.0;
        }
    }
    0.0
}

#[test]
fn a_corner_is_slower_than_going_straight() {
    let (straight, _) = two_blocks(false, false);
    let (corner, trace) = two_blocks(true, false);
    assert_close(straight, trapezoid(100.0, 200.0, 3000.0), "straight on");
    assert!(
        corner > straight,
        "corner {corner} s, straight {straight} s"
    );
    // The corner is taken at a speed above zero (rounded, not stopped) and
    // below the feed.
    let v = speed_at(&trace, 50.0);
    assert!(v > 1.0 && v < 200.0, "corner speed {v}");
    // Each axis' velocity jump there is within what it can do inside the
    // tolerance at half its acceleration: v·|Δu| ≤ √(8·0.5·a·δ).
    assert!(v <= (4.0f64 * 3000.0 * 0.01).sqrt() * (1.0 + REL));
}

#[test]
fn exact_stop_stops_at_the_block_end() {
    let (stopped, trace) = two_blocks(false, true);
    // Locating s = 50 to 1e-10 mm near a stop at 3000 mm/s² leaves a speed
    // of up to √(2·3000·1e-10).
    let v = speed_at(&trace, 50.0);
    assert!(
        v.abs() <= (2.0f64 * 3000.0 * 1e-10).sqrt(),
        "speed at the G09 block end: {v}"
    );
    // Two separate trapezoids.
    assert_close(stopped, 2.0 * trapezoid(50.0, 200.0, 3000.0), "G09");
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    use fiveaxis_planner::PlanError;
    let good = axis(6000.0, 1000.0, None);
    let bad = AxisLimits {
        max_acceleration: 0.0,
        ..good
    };
    assert!(matches!(
        Planner::new(&[good, bad], Options::default(), &[0.0, 0.0]),
        Err(PlanError::AxisLimit { axis: 1, .. })
    ));
    assert!(matches!(
        Planner::new(&[], Options::default(), &[]),
        Err(PlanError::AxisCount { count: 0 })
    ));
    assert!(matches!(
        Planner::new(&[good], Options::default(), &[0.0, 1.0]),
        Err(PlanError::Start { .. })
    ));
    let nan_tol = Options {
        junction_tolerance: f64::NAN,
        ..Options::default()
    };
    assert!(Planner::new(&[good], nan_tol, &[0.0]).is_err());
    let mut planner = Planner::new(&[good], Options::default(), &[0.0]).expect("limits");
    let nan = [Point::new(&[f64::NAN], 1.0)];
    let block = |feed, points| Block {
        feed,
        exact_stop: false,
        points,
    };
    assert!(matches!(
        planner.push(&block(Feed::PerMinute(100.0), &nan)),
        Err(PlanError::Point { index: 0, .. })
    ));
    let fine = [Point::new(&[10.0], 10.0)];
    assert!(matches!(
        planner.push(&block(Feed::PerMinute(-1.0), &fine)),
        Err(PlanError::Feed { .. })
    ));
    assert!(
        planner
            .push(&block(Feed::InverseTime(f64::INFINITY), &fine))
            .is_err()
    );
    // The failed blocks left nothing behind: 10 mm at 100 mm/min.
    planner
        .push(&block(Feed::PerMinute(100.0), &fine))
        .expect("block");
    assert_close(
        planner.finish().time,
        trapezoid(10.0, 100.0 / 60.0, 1000.0),
        "after errors",
    );
}
