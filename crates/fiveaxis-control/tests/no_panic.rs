//! The runner never panics: whatever program it is given, on every built-in
//! machine, it ends (`Ok(None)`) or stops with an alarm, and every row it
//! yields on the way is made of finite numbers.
//!
//! The controller's plain path (`controller/plain.rs`) gives, block for
//! block, the segments and alarms its general path gives.
//!
//! Programs come from a vocabulary of realistic words (the G and M codes the
//! kernel has, with the values they take, axis and centre words with small,
//! huge, zero and negative values, with and without a decimal point), from
//! G-code characters in any order, and from arbitrary bytes.

use std::io;

use fiveaxis_control::{
    Interpolation, MAX_STEPS, Row, RunError, RunOptions, Runner, Segment, SliceSource, Source,
};
use fiveaxis_machine::{Machine, Offsets, ToolOffset, Vec3, builtin, builtin_names};
use proptest::prelude::*;

/// Most segments taken from one run; a program may legitimately repeat
/// forever (`M99` in a loop), so the test stops consuming there.
const MAX_SEGMENTS: usize = 10_000;

/// Most lines the runner may read in one run (subprogram calls and
/// searches included): bounds the work of call trees that never move.
const LINE_BUDGET: u64 = 200_000;

/// Where each segment is sampled, besides the first of its `--step` rows.
const SAMPLES: [f64; 2] = [0.5, 1.0];

/// `--step` and `--step-angle` for the step count of each segment.
const STEP: f64 = 5.0;
const STEP_ANGLE: f64 = 5.0;

/// A source that stops with `TimedOut` once it has read `budget` lines.
struct Budgeted<S> {
    inner: S,
    budget: u64,
}

impl<S: Source> Source for Budgeted<S> {
    fn read_line(&mut self, buf: &mut Vec<u8>) -> io::Result<bool> {
        if self.budget == 0 {
            return Err(io::Error::new(
                io::ErrorKind::TimedOut,
                "line budget of the test used up",
            ));
        }
        self.budget -= 1;
        self.inner.read_line(buf)
    }

    fn position(&self) -> u64 {
        self.inner.position()
    }

    fn seek(&mut self, offset: u64) -> io::Result<()> {
        self.inner.seek(offset)
    }
}

/// Offset memory with tools and work offsets set, so that G43, G54 … have
/// something to apply. H3 is negative.
fn offsets() -> Offsets {
    let tool = |length, length_wear, radius| ToolOffset {
        length,
        length_wear,
        radius,
        ..ToolOffset::default()
    };
    let mut offsets = Offsets::default();
    offsets.tools.extend([
        (1, tool(100.0, 0.0, 5.0)),
        (2, tool(50.0, -0.5, 2.0)),
        (3, tool(-20.0, 0.0, -3.0)),
    ]);
    // Setup error data sets (G54.4), one naming a table axis.
    offsets.setup_error.insert(
        1,
        fiveaxis_machine::SetupErrorSet {
            origin: Vec3::new(1.0, -2.0, 0.5),
            rotation: Vec3::new(0.0, -30.0, 5.0),
            table: vec![],
        },
    );
    offsets.setup_error.insert(
        2,
        fiveaxis_machine::SetupErrorSet {
            rotation: Vec3::new(3.0, 0.0, 0.0),
            table: vec![('C', 90.0)],
            ..Default::default()
        },
    );
    offsets.work[0] = Vec3::new(10.0, 20.0, 30.0);
    offsets.work[1] = Vec3::new(100.0, 0.0, -50.0);
    offsets.extended_work[0] = Vec3::new(-10.0, -20.0, -30.0);
    offsets
}

fn machines() -> Vec<Machine> {
    builtin_names()
        .iter()
        .map(|&name| builtin(name).expect("built-in machine"))
        .collect()
}

fn check_row(row: &Row, machine: &Machine, lines: u32) -> Result<(), TestCaseError> {
    let n = machine.axis_count();
    let finite = row.s.is_finite()
        && row.joints[..n].iter().all(|x| x.is_finite())
        && row.tip.iter().all(|x| x.is_finite())
        && row.dir.iter().all(|x| x.is_finite())
        && row.feed.is_none_or(f64::is_finite);
    prop_assert!(finite, "row with a value that is not finite: {row:?}");
    prop_assert!(
        (row.dir.norm() - 1.0).abs() < 1e-9,
        "tool direction is not a unit vector: {row:?}"
    );
    prop_assert!(
        (1..=lines).contains(&row.line),
        "row of line {} in a {lines}-line program",
        row.line
    );
    Ok(())
}

/// Samples `segment` where the `run` writer would: the first `--step` row,
/// half way and the end.
fn check_segment(segment: &Segment, machine: &Machine, lines: u32) -> Result<(), TestCaseError> {
    let n = segment
        .steps(machine, STEP, STEP_ANGLE)
        .unwrap_or(MAX_STEPS);
    prop_assert!((1..=MAX_STEPS).contains(&n), "{n} steps for {segment:?}");
    for s in std::iter::once(1.0 / f64::from(n)).chain(SAMPLES) {
        check_row(&segment.row(machine, s), machine, lines)?;
    }
    Ok(())
}

/// Runs `program` on `machine` until it ends, alarms, or uses up the
/// test's budget, checking every sampled row and the alarm's line.
fn check_run(machine: &Machine, program: &[u8], options: RunOptions) -> Result<(), TestCaseError> {
    // Lines end at LF, CR LF or a lone CR.
    let breaks = program
        .iter()
        .enumerate()
        .filter(|&(i, &b)| b == b'\n' || (b == b'\r' && program.get(i + 1) != Some(&b'\n')))
        .count();
    let lines = u32::try_from(breaks + 1).unwrap_or(u32::MAX);
    let source = Budgeted {
        inner: SliceSource::new(program),
        budget: LINE_BUDGET,
    };
    let mut runner = Runner::new(machine, offsets(), source, options);
    for _ in 0..MAX_SEGMENTS {
        match runner.next_segment() {
            Ok(Some(segment)) => check_segment(&segment, machine, lines)?,
            Ok(None) => return Ok(()),
            Err(RunError::Alarm { alarm, .. }) => {
                prop_assert!(
                    (1..=lines).contains(&alarm.line),
                    "alarm on line {} of {lines}: {alarm:?}",
                    alarm.line
                );
                prop_assert!(
                    !alarm.message.is_empty(),
                    "alarm without a message: {alarm:?}"
                );
                return Ok(());
            }
            Err(RunError::Io(e)) if e.kind() == io::ErrorKind::TimedOut => return Ok(()),
            Err(e) => {
                return Err(TestCaseError::fail(format!(
                    "a program in memory failed to read: {e}"
                )));
            }
        }
    }
    Ok(())
}

/// Runs the program that `text_for` writes for each built-in machine.
fn check_on_every_machine(
    text_for: impl Fn(&Machine) -> Vec<u8>,
    options: RunOptions,
) -> Result<(), TestCaseError> {
    for machine in machines() {
        check_run(&machine, &text_for(&machine), options)?;
    }
    Ok(())
}

// ----- program generators ----------------------------------------------

/// The address of a generated word: a fixed letter, or the machine's first
/// or second rotary axis (the word is left out on a machine without it), so
/// that one program runs on every machine.
#[derive(Clone, Copy, Debug)]
enum Address {
    Fixed(&'static str),
    Rotary(usize),
}

#[derive(Clone, Debug)]
struct Word {
    address: Address,
    value: String,
}

/// A program as blocks of words, written out for one machine.
#[derive(Clone, Debug)]
struct Program(Vec<Vec<Word>>);

impl Program {
    fn text_for(&self, machine: &Machine) -> String {
        let block = |words: &Vec<Word>| {
            let words: Vec<String> = words
                .iter()
                .filter_map(|word| {
                    let letter = match word.address {
                        Address::Fixed(letter) => letter.to_owned(),
                        Address::Rotary(k) => machine.rotary.get(k)?.name.to_string(),
                    };
                    Some(format!("{letter}{}", word.value))
                })
                .collect();
            words.join(" ")
        };
        self.0.iter().map(block).collect::<Vec<_>>().join("\n") + "\n"
    }
}

fn fixed(letter: &'static str, value: impl Into<String>) -> Word {
    Word {
        address: Address::Fixed(letter),
        value: value.into(),
    }
}

/// A code word: `G43.1` is letter `G`, value `43.1`.
fn code(text: &'static str) -> Word {
    fixed(&text[..1], &text[1..])
}

fn one_of_codes(codes: &'static [&'static str]) -> impl Strategy<Value = Word> + Clone {
    prop::sample::select(codes).prop_map(code)
}

/// A number as a program writes it: mostly in `range`, with no decimal
/// point (least input increments), a bare point or a fraction; sometimes
/// zero, huge, negative or oddly written whatever the range.
fn number(range: std::ops::RangeInclusive<i64>) -> impl Strategy<Value = String> + Clone {
    let plain =
        (range, prop::option::of(prop::option::of(0u32..1000))).prop_map(|(int, fraction)| {
            match fraction {
                None => int.to_string(),
                Some(None) => format!("{int}."),
                Some(Some(fraction)) => format!("{int}.{fraction:03}"),
            }
        });
    let odd = prop::sample::select(
        &[
            "0",
            "-0.",
            "0.0001",
            "-1.5",
            "99999999",
            "-99999999.",
            "999999999999999",
        ][..],
    );
    prop_oneof![12 => plain, 1 => odd.prop_map(str::to_owned)]
}

fn value(
    letter: &'static str,
    range: std::ops::RangeInclusive<i64>,
) -> impl Strategy<Value = Word> + Clone {
    number(range).prop_map(move |v| fixed(letter, v))
}

fn integer(
    letter: &'static str,
    range: std::ops::RangeInclusive<u32>,
) -> impl Strategy<Value = Word> + Clone {
    range.prop_map(move |n| fixed(letter, n.to_string()))
}

/// Any of X, Y, Z, each at most once.
fn linear_axes() -> impl Strategy<Value = Vec<Word>> {
    let linear = |letter| prop::option::of(value(letter, -150..=150));
    (linear("X"), linear("Y"), linear("Z"))
        .prop_map(|(x, y, z)| [x, y, z].into_iter().flatten().collect())
}

/// Axis words: any of X, Y, Z, sometimes the rotary axes, each at most once.
fn axes() -> impl Strategy<Value = Vec<Word>> {
    let rotary = |k: usize| {
        prop::option::weighted(
            0.25,
            number(-180..=180).prop_map(move |v| Word {
                address: Address::Rotary(k),
                value: v,
            }),
        )
    };
    (linear_axes(), rotary(0), rotary(1))
        .prop_map(|(linear, r0, r1)| linear.into_iter().chain(r0).chain(r1).collect())
}

/// Arc words: R, or centre words of any plane.
fn arc_words() -> impl Strategy<Value = Vec<Word>> {
    prop_oneof![
        3 => value("R", -100..=100).prop_map(|r| vec![r]),
        1 => (value("I", -100..=100), value("J", -100..=100)).prop_map(|(i, j)| vec![i, j]),
        1 => (value("I", -100..=100), value("K", -100..=100)).prop_map(|(i, k)| vec![i, k]),
        1 => (value("J", -100..=100), value("K", -100..=100)).prop_map(|(j, k)| vec![j, k]),
    ]
}

fn feed() -> impl Strategy<Value = Option<Word>> {
    prop::option::weighted(0.5, value("F", 1..=5000))
}

/// G00-G03 with the modal codes that change how they read, axis words,
/// arc words when the block is an arc, and a feed.
fn motion_block() -> impl Strategy<Value = Vec<Word>> {
    let modal = |codes| prop::option::weighted(0.2, one_of_codes(codes));
    let motion = prop::option::weighted(
        0.85,
        one_of_codes(&["G0", "G0", "G0", "G1", "G1", "G1", "G2", "G3"]),
    );
    let setup = (
        modal(&["G90", "G91"]),
        modal(&["G17", "G18", "G19"]),
        modal(&["G20", "G21"]),
    );
    (setup, motion, axes(), arc_words(), feed()).prop_map(
        |((distance, plane, units), motion, axes, arc, feed)| {
            let is_arc = motion
                .as_ref()
                .is_some_and(|m| m.value == "2" || m.value == "3");
            // An arc with centre words and no axis words is a full circle.
            let by_radius = matches!(arc[0].address, Address::Fixed("R"));
            let (axes, arc) = match (is_arc, by_radius) {
                (false, _) => (axes, Vec::new()),
                (true, false) if axes.len() % 2 == 0 => (Vec::new(), arc),
                (true, _) => (axes, arc),
            };
            [distance, plane, units, motion]
                .into_iter()
                .flatten()
                .chain(axes)
                .chain(arc)
                .chain(feed)
                .collect()
        },
    )
}

/// G27, G28, G30, G53, G92 with axis words.
fn reference_block() -> impl Strategy<Value = Vec<Word>> {
    (one_of_codes(&["G27", "G28", "G30", "G53", "G92"]), axes())
        .prop_map(|(code, axes)| std::iter::once(code).chain(axes).collect())
}

/// Tool length compensation on (G43, G44, G43.1 with H) or off (G49).
fn length_block() -> impl Strategy<Value = Vec<Word>> {
    let on = (
        one_of_codes(&["G43", "G44", "G43.1"]),
        integer("H", 0..=3),
        prop::option::of(value("Z", -100..=200)),
    )
        .prop_map(|(code, h, z)| [Some(code), Some(h), z].into_iter().flatten().collect());
    prop_oneof![3 => on, 1 => Just(vec![code("G49")])]
}

/// G54-G59, G54.1 Pn and G54 Pn (P up to 60, past the 48 that exist).
fn work_block() -> impl Strategy<Value = Vec<Word>> {
    prop_oneof![
        one_of_codes(&["G54", "G55", "G56", "G57", "G58", "G59"]).prop_map(|c| vec![c]),
        (one_of_codes(&["G54.1", "G54"]), integer("P", 0..=60)).prop_map(|(c, p)| vec![c, p]),
    ]
}

/// G10: L2 and L20 work offsets, L10-L13 tool offsets, P in and out of range.
fn data_block() -> impl Strategy<Value = Vec<Word>> {
    let work = (
        prop::sample::select(&["2", "20"][..]),
        integer("P", 0..=60),
        linear_axes(),
    )
        .prop_map(|(l, p, axes)| {
            [code("G10"), fixed("L", l), p]
                .into_iter()
                .chain(axes)
                .collect()
        });
    let tool = (10u32..=13, integer("P", 0..=4), value("R", -200..=200))
        .prop_map(|(l, p, r)| vec![code("G10"), fixed("L", l.to_string()), p, r]);
    prop_oneof![work, tool]
}

/// G93, G94, G95, and the spindle that G95 needs.
fn feed_block() -> impl Strategy<Value = Vec<Word>> {
    let mode = (one_of_codes(&["G93", "G94", "G95"]), feed())
        .prop_map(|(c, f)| [Some(c), f].into_iter().flatten().collect());
    let spindle =
        (integer("S", 0..=20_000), one_of_codes(&["M3", "M5"])).prop_map(|(s, m)| vec![s, m]);
    prop_oneof![mode, spindle]
}

/// Program numbers an `M98 P` may name: the two subprograms of the file,
/// one that is missing, and the eight-digit form with repetitions.
const CALLED: &[u32] = &[1, 2, 1, 2, 4242, 20001, 30002, 99_999_999];

/// Sequence numbers some blocks carry and `M99 P` returns to.
const SEQUENCES: &[u32] = &[10, 20, 30];

/// M98 P… L…, M99 P…, M30.
fn flow_block() -> impl Strategy<Value = Vec<Word>> {
    // L is kept small: a call tree of L-fold calls nested ten deep is
    // L^10 runs long.
    let call = (
        prop::sample::select(CALLED),
        prop::option::of(integer("L", 0..=3)),
    )
        .prop_map(|(p, l)| {
            [Some(code("M98")), Some(fixed("P", p.to_string())), l]
                .into_iter()
                .flatten()
                .collect()
        });
    let back =
        prop::sample::select(SEQUENCES).prop_map(|n| vec![code("M99"), fixed("P", n.to_string())]);
    prop_oneof![4 => call, 2 => back, 1 => Just(vec![code("M99")]), 1 => Just(vec![code("M30")])]
}

/// Tool radius compensation (G40, G41/G42 with D, with or without I J K),
/// TCPC (G43.4/G43.5 with H, P, Q, I J K) and setup error correction
/// (G54.4 P0–P8, alone or not).
fn compensation_block() -> impl Strategy<Value = Vec<Word>> {
    let radius = (
        one_of_codes(&["G40", "G41", "G42", "G41", "G42"]),
        integer("D", 0..=3),
        prop::option::weighted(
            0.5,
            (
                value("I", -10..=10),
                value("J", -10..=10),
                value("K", -10..=10),
            ),
        ),
        linear_axes(),
    )
        .prop_map(|(code, d, ijk, axes)| {
            let ijk = ijk.map(|(i, j, k)| vec![i, j, k]).unwrap_or_default();
            [code, d].into_iter().chain(ijk).chain(axes).collect()
        });
    let tcpc = (
        one_of_codes(&["G43.4", "G43.5"]),
        integer("H", 0..=3),
        prop::option::of(integer("P", 0..=1)),
        prop::option::weighted(0.3, value("Q", -30..=30)),
        prop::option::weighted(
            0.5,
            (
                value("I", -10..=10),
                value("J", -10..=10),
                value("K", -10..=10),
            ),
        ),
        axes(),
    )
        .prop_map(|(code, h, p, q, ijk, axes)| {
            let ijk = ijk.map(|(i, j, k)| vec![i, j, k]).unwrap_or_default();
            [Some(code), Some(h), p, q]
                .into_iter()
                .flatten()
                .chain(ijk)
                .chain(axes)
                .collect()
        });
    let vector = (
        value("I", -10..=10),
        value("J", -10..=10),
        value("K", -10..=10),
        linear_axes(),
    )
        .prop_map(|(i, j, k, axes)| [i, j, k].into_iter().chain(axes).collect());
    let setup = (
        integer("P", 0..=8),
        prop::option::weighted(0.2, value("X", -10..=10)),
    )
        .prop_map(|(p, x)| {
            [Some(code("G54.4")), Some(p), x]
                .into_iter()
                .flatten()
                .collect()
        });
    prop_oneof![3 => radius, 2 => tcpc, 2 => vector, 1 => setup]
}

/// Canned cycles: a cycle code (or G80, G98, G99) with plane positions,
/// the drilling data and repeats; or just positions in the cycle mode.
fn cycle_block() -> impl Strategy<Value = Vec<Word>> {
    let code = prop::option::weighted(
        0.7,
        one_of_codes(&[
            "G73", "G74", "G76", "G80", "G81", "G82", "G83", "G84", "G85", "G86", "G87", "G88",
            "G89",
        ]),
    );
    let back = prop::option::weighted(0.3, one_of_codes(&["G98", "G99"]));
    let opt = |letter, lo, hi| prop::option::weighted(0.5, value(letter, lo..=hi));
    (
        (back, code, axes()),
        (opt("Z", -300, 100), opt("R", -100, 100), opt("Q", -20, 20)),
        (
            prop::option::weighted(0.5, integer("P", 0..=2000)),
            prop::option::weighted(0.5, integer("K", 0..=5)),
            feed(),
        ),
    )
        .prop_map(|((back, code, axes), (z, r, q), (p, k, f))| {
            [back, code]
                .into_iter()
                .flatten()
                .chain(axes)
                .chain([z, r, q, p, k, f].into_iter().flatten())
                .collect()
        })
}

/// Program transforms: G52, G16/G15, G51.1/G50.1, G51/G50, G68/G69 with
/// centres, angles and factors (zero and negative ones included).
fn frames_block() -> impl Strategy<Value = Vec<Word>> {
    let code = one_of_codes(&[
        "G52", "G16", "G15", "G51.1", "G50.1", "G51", "G50", "G68", "G69", "G68", "G51",
    ]);
    let opt = |letter, lo, hi| prop::option::weighted(0.4, value(letter, lo..=hi));
    (
        code,
        axes(),
        (opt("R", -400, 400), opt("P", -3000, 3000), opt("I", -3, 3)),
    )
        .prop_map(|(code, axes, (r, p, i))| {
            std::iter::once(code)
                .chain(axes)
                .chain([r, p, i].into_iter().flatten())
                .collect()
        })
}

/// Words of the vocabulary in any mix: mostly blocks a control refuses.
fn noise_block() -> impl Strategy<Value = Vec<Word>> {
    let codes = one_of_codes(&[
        "G0", "G2", "G17", "G20", "G27", "G28", "G53", "G91", "G92", "G93", "G43", "G43.1", "G49",
        "G54", "G10", "M3", "M98", "M99", "M30",
    ]);
    let letters =
        prop::sample::select(&["X", "Y", "Z", "I", "J", "K", "R", "F", "S", "P", "L", "H"][..]);
    let values = (letters, number(-99_999..=99_999)).prop_map(|(letter, v)| fixed(letter, v));
    prop::collection::vec(prop_oneof![codes, values], 1..5)
}

/// One block of any kind, sometimes with a sequence number, sometimes
/// marked for block delete.
fn block() -> impl Strategy<Value = Vec<Word>> {
    let body = prop_oneof![
        12 => motion_block(),
        2 => reference_block(),
        2 => length_block(),
        2 => work_block(),
        1 => data_block(),
        2 => feed_block(),
        2 => flow_block(),
        1 => noise_block(),
        3 => compensation_block(),
        2 => cycle_block(),
        2 => frames_block(),
    ];
    let deleted = prop::option::weighted(0.1, Just(fixed("/", "")));
    let sequence = prop::option::weighted(0.2, prop::sample::select(SEQUENCES));
    (deleted, sequence, body).prop_map(|(deleted, n, body)| {
        let n = n.map(|n| fixed("N", n.to_string()));
        deleted.into_iter().chain(n).chain(body).collect()
    })
}

/// A main program and two subprograms, O1 and O2, in one file. Most main
/// programs set a feed first, as real ones do.
fn program() -> impl Strategy<Value = Program> {
    let blocks = |range| prop::collection::vec(block(), range);
    let preamble = prop::option::weighted(0.7, value("F", 1..=5000));
    (
        preamble,
        blocks(1..25),
        any::<bool>(),
        blocks(0..6),
        blocks(0..6),
    )
        .prop_map(|(feed, main, end, o1, o2)| {
            let mut all: Vec<Vec<Word>> = feed
                .map(|f| vec![code("G94"), f])
                .into_iter()
                .chain(main)
                .collect();
            if end {
                all.push(vec![code("M30")]);
            }
            for (number, body) in [("1", o1), ("2", o2)] {
                all.push(vec![fixed("O", number)]);
                all.extend(body);
                all.push(vec![code("M99")]);
            }
            all.push(vec![fixed("%", "")]);
            Program(all)
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn programs_of_realistic_words_end_or_alarm_with_finite_rows(program in program(), block_delete in any::<bool>()) {
        check_on_every_machine(|machine| program.text_for(machine).into_bytes(), RunOptions { block_delete, ..RunOptions::default() })?;
    }

    #[test]
    fn text_of_g_code_characters_never_panics(program in "[GMXYZABCIJKRFSPLHNO0-9.+\\- ()/%;#\n]{0,300}") {
        check_on_every_machine(|_| program.clone().into_bytes(), RunOptions::default())?;
    }

    #[test]
    fn arbitrary_bytes_never_panic(program in prop::collection::vec(any::<u8>(), 0..400)) {
        check_on_every_machine(|_| program.clone(), RunOptions::default())?;
    }
}

// ----- plain path against general path ------------------------------------

/// Runs `program` on `machine` twice, plain blocks through the plain path
/// and every block through the general path, and checks that both give the
/// same segments, the same alarm at the same block and end in the same
/// state.
fn check_plain_path(machine: &Machine, program: &[u8]) -> Result<(), TestCaseError> {
    let runner = |plain| {
        let source = Budgeted {
            inner: SliceSource::new(program),
            budget: LINE_BUDGET,
        };
        let mut runner = Runner::new(machine, offsets(), source, RunOptions::default());
        runner.set_plain_path(plain);
        runner
    };
    let (mut plain, mut general) = (runner(true), runner(false));
    for _ in 0..MAX_SEGMENTS {
        let (a, b) = (plain.next_segment(), general.next_segment());
        prop_assert_eq!(plain.blocks(), general.blocks());
        match (a, b) {
            (Ok(Some(a)), Ok(Some(b))) => prop_assert_eq!(a, b),
            (Ok(None), Ok(None)) => break,
            (Err(RunError::Alarm { alarm: a, .. }), Err(RunError::Alarm { alarm: b, .. })) => {
                prop_assert_eq!(a, b);
                break;
            }
            (Err(RunError::Io(a)), Err(RunError::Io(b))) if a.kind() == b.kind() => break,
            (a, b) => {
                return Err(TestCaseError::fail(format!(
                    "plain path {a:?}, general path {b:?}"
                )));
            }
        }
    }
    let (a, b) = (plain.controller(), general.controller());
    prop_assert_eq!(a.joints(), b.joints());
    prop_assert_eq!(a.modal(), b.modal());
    prop_assert_eq!(a.feed().to_bits(), b.feed().to_bits());
    prop_assert_eq!(a.programmed_position(), b.programmed_position());
    Ok(())
}

/// A block that puts the control in a state a plain block then runs in
/// (or refuses): modes, offsets, compensations, TCPC, cycles, frames,
/// setup error correction, spindle and feed modes, all well formed.
fn state_block() -> impl Strategy<Value = Vec<Word>> {
    const STATES: &[&str] = &[
        "G90",
        "G91",
        "G20",
        "G21",
        "G17",
        "G18",
        "G19",
        "G43 H1",
        "G43 H2",
        "G44 H3",
        "G49",
        "G41 D1",
        "G42 D2",
        "G40",
        "G41 D1 I0 J0 K1",
        "G43.4 H1",
        "G43.5 H2",
        "G81 Z-10. R5.",
        "G83 Z-20. R2. Q3.",
        "G80",
        "G68 X1. Y2. R30.",
        "G69",
        "G51 X0 Y0 P2000",
        "G50",
        "G51.1 X5.",
        "G50.1 X0",
        "G52 X10. Y5.",
        "G52 X0 Y0",
        "G16",
        "G15",
        "G93",
        "G94",
        "G95 S1000 M3",
        "M5",
        "M8",
        "M9",
        "G54",
        "G55",
        "G54.1 P1",
        "G54.4 P1",
        "G54.4 P0",
        "G10 L2 P1 X5. Y-3.",
        "G92 X0 Y0",
        "G28 X0",
        "G2 X10. Y10. R20.",
        "G3 X-5. R40.",
        "G09 G1 X1.",
        "G61",
        "G64",
        "G4 P100",
        "M1",
        "S2000",
        "T2 M6",
        "G68.2 X0 Y0 Z0 I0 J30. K0",
        "G53.1",
        "G69",
        "G254",
        "G255",
        "G43.4 H1 G68.2 X0 Y0 Z0 I0 J0 K0",
    ];
    prop::sample::select(STATES).prop_map(|text| {
        text.split(' ')
            .map(|word| fixed(&word[..1], &word[1..]))
            .collect()
    })
}

/// A plain block or one that just misses being plain: G00 / G01 or no
/// code, axis words, a tool direction (plain under TCPC type 2), a feed.
fn plain_block() -> impl Strategy<Value = Vec<Word>> {
    let motion = prop::option::weighted(0.6, one_of_codes(&["G0", "G1", "G1", "G00", "G01"]));
    let vector = prop::option::weighted(
        0.3,
        (
            value("I", -10..=10),
            value("J", -10..=10),
            value("K", -10..=10),
        ),
    );
    (motion, axes(), vector, feed()).prop_map(|(motion, axes, vector, feed)| {
        let vector = vector.map(|(i, j, k)| vec![i, j, k]).unwrap_or_default();
        motion
            .into_iter()
            .chain(axes)
            .chain(vector)
            .chain(feed)
            .collect()
    })
}

/// Programs of plain blocks in every state of [`state_block`].
fn plain_program() -> impl Strategy<Value = Program> {
    let block = prop_oneof![4 => plain_block(), 1 => state_block()];
    prop::collection::vec(block, 1..40).prop_map(|blocks| {
        let start = vec![code("G94"), fixed("F", "1000.")];
        Program(std::iter::once(start).chain(blocks).collect())
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1024, ..ProptestConfig::default() })]

    #[test]
    fn plain_path_gives_what_the_general_path_gives(program in prop_oneof![program(), plain_program()]) {
        // LinuxCNC's reading too, on two of the machines.
        let linuxcnc = ["trunnion-ac", "head-table-bc"].map(|name| Machine {
            control: fiveaxis_machine::Control::LinuxCnc,
            ..builtin(name).expect("built-in machine")
        });
        for machine in machines().into_iter().chain(linuxcnc) {
            check_plain_path(&machine, program.text_for(&machine).as_bytes())?;
        }
    }
}

// ----- interpolation continuity ----------------------------------------

/// Checks the `--step` contract on every pair of rows of a run: each block
/// starts where the previous one ended (machine position, rollover axes
/// modulo 360), and consecutive rows inside a block, from its start, are at
/// most `step` apart at the tool tip and `step_angle` on every rotary axis.
/// A block that cannot keep the bound must stop with an alarm instead.
fn check_continuity(
    machine: &Machine,
    program: &[u8],
    step: f64,
    step_angle: f64,
) -> Result<(), TestCaseError> {
    let options = RunOptions {
        interpolation: Some(Interpolation { step, step_angle }),
        ..RunOptions::default()
    };
    let source = Budgeted {
        inner: SliceSource::new(program),
        budget: LINE_BUDGET,
    };
    let mut runner = Runner::new(machine, offsets(), source, options);
    let rotary = machine.linear.len()..machine.axis_count();
    let slack = 1.0 + 1e-6;
    let mut previous_end: Option<fiveaxis_machine::Joints> = None;
    for _ in 0..MAX_SEGMENTS / 10 {
        let segment = match runner.next_segment() {
            Ok(Some(segment)) => segment,
            Ok(None) | Err(RunError::Alarm { .. }) => return Ok(()),
            Err(RunError::Io(e)) if e.kind() == io::ErrorKind::TimedOut => return Ok(()),
            Err(e) => return Err(TestCaseError::fail(format!("read error: {e}"))),
        };
        let first = segment.eval(machine, 0.0);
        if let Some(end) = previous_end {
            for i in 0..machine.axis_count() {
                let mut gap = (first[i] - end[i]).abs();
                if machine
                    .rotary
                    .iter()
                    .enumerate()
                    .any(|(k, a)| a.rollover && machine.rotary_index(k) == i)
                {
                    gap = fiveaxis_machine::principal(first[i] - end[i]).abs();
                }
                prop_assert!(
                    gap <= 1e-6 * (1.0 + end[i].abs()),
                    "line {} starts {gap} away from the previous block's end on axis {i}: {first:?} vs {end:?}",
                    segment.line
                );
            }
        }
        let n = segment.rows;
        prop_assert!((1..=MAX_STEPS).contains(&n));
        let mut last = (first, machine.forward(&first, segment.tool_length).tip);
        for i in 1..=n {
            let s = f64::from(i) / f64::from(n);
            let joints = segment.eval(machine, s);
            let tip = machine.forward(&joints, segment.tool_length).tip;
            let moved = (tip - last.1).norm();
            prop_assert!(
                moved <= step * slack + 1e-9,
                "line {}: rows at s = {s} are {moved} mm apart (step {step})",
                segment.line
            );
            for k in rotary.clone() {
                let turn = (joints[k] - last.0[k]).abs();
                prop_assert!(
                    turn <= step_angle * slack + 1e-9,
                    "line {}: axis {k} turns {turn} degrees between rows at s = {s} (step angle {step_angle})",
                    segment.line
                );
            }
            last = (joints, tip);
        }
        previous_end = Some(segment.end);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 256,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x5EED_0008),
        ..ProptestConfig::default()
    })]

    #[test]
    fn interpolated_rows_are_continuous_and_within_the_step(
        program in program(),
        step in prop::sample::select(&[2.0, 10.0, 50.0][..]),
        step_angle in prop::sample::select(&[1.0, 10.0][..]),
    ) {
        for machine in machines() {
            check_continuity(&machine, program.text_for(&machine).as_bytes(), step, step_angle)?;
        }
    }
}

// ----- SINUMERIK programs ------------------------------------------------

/// Blocks of the Siemens language, with holes for numbers, that a random
/// program strings together: motion, frames, TRAORI with vectors, cycles,
/// the language's flow, and some that must alarm.
const SINUMERIK_BLOCKS: &[&str] = &[
    "G0 X{} Y{} Z{}",
    "G1 X{} Y{} F{}",
    "G2 X{} Y{} I{} J{}",
    "G3 X{} Y{} CR={}",
    "G2 X{} Y{} I=AC({}) J=AC({}) TURN={}",
    "G91 G1 Z{} F{}",
    "G90",
    "G70",
    "G71",
    "G700",
    "G17",
    "G18",
    "G19",
    "G54",
    "G500",
    "G505",
    "G53 G0 Z{}",
    "SUPA G0 X{} Y{}",
    "T1 D1",
    "T=\"FRA\" D1",
    "D0",
    "TRANS X{} Y{} Z{}",
    "ATRANS X{}",
    "ROT Z{}",
    "AROT X{} Y{}",
    "ROT RPL={}",
    "TRANS",
    "TRAORI",
    "TRAFOOF",
    "G1 X{} Y{} Z{} A3={} B3={} C3={} F{}",
    "G1 X{} Y{} Z{} A2={} B2={} C2={} F{}",
    "G1 X{} B={} C=DC({}) F{}",
    "CYCLE800({},\"TC1\",{},57,{},{},{},{},{},{},{},{},{},{})",
    "CYCLE800()",
    "MCALL CYCLE81({},{},{},{})",
    "MCALL CYCLE83({},{},{},{},,{},,{},,,1,{})",
    "MCALL",
    "HOLES2({},{},{},{},{},{})",
    "CYCLE84({},{},{},{},,,3,{},,,{})",
    "CYCLE60(\"AB\",{},{},{},{})",
    "R1={} R2=R1*{}",
    "DEF REAL V={}",
    "X=R1+{} Y=SIN({})*R2",
    "IF R1>{} GOTOF SKIP",
    "SKIP:",
    "WHILE R1<{}",
    "R1=R1+1",
    "ENDWHILE",
    "FOR R3=1 TO {}",
    "ENDFOR",
    "G4 F{}",
    "M3 S{}",
    "M30",
    "MSG(\"a\" << {})",
    "SETAL(65000)",
    "GOTOB SKIP",
];

fn sinumerik_program() -> impl Strategy<Value = String> {
    let block = (
        prop::sample::select(SINUMERIK_BLOCKS),
        prop::collection::vec(-300i32..300, 14),
    )
        .prop_map(|(template, numbers)| {
            let mut text = String::new();
            let mut n = numbers.iter();
            let mut parts = template.split("{}").peekable();
            while let Some(part) = parts.next() {
                text.push_str(part);
                if parts.peek().is_some() {
                    let v = n.next().copied().unwrap_or(1);
                    text.push_str(&format!("{}", f64::from(v) / 4.0));
                }
            }
            text
        });
    prop::collection::vec(block, 0..40).prop_map(|blocks| blocks.join("\n"))
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 256,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x5EED_0025),
        ..ProptestConfig::default()
    })]

    #[test]
    fn sinumerik_programs_end_or_alarm_with_finite_rows(program in sinumerik_program()) {
        let machine = builtin("sinumerik-dmu-bc").expect("built-in machine");
        check_run(&machine, program.as_bytes(), RunOptions::default())?;
    }

    #[test]
    fn sinumerik_text_never_panics(program in "[A-Z0-9=()\\[\\],.:;\"'$_<>+\\-*/ \n]{0,300}") {
        let machine = builtin("sinumerik-dmu-bc").expect("built-in machine");
        check_run(&machine, program.as_bytes(), RunOptions::default())?;
    }
}

// ----- HEIDENHAIN Klartext ---------------------------------------------

/// Klartext blocks with `{}` where a number goes: paths, the tool call,
/// transformations, PLANE in every form, TCPM, cycles and patterns, Q
/// parameters and program flow.
const HEIDENHAIN_BLOCKS: &[&str] = &[
    "TOOL CALL 1 Z S{} F{} DL{} DR{}",
    "TOOL CALL 2 Y S{}",
    "TOOL CALL \"MILL\" X S{}",
    "TOOL CALL {} Z",
    "L X{} Y{} Z{} R0 FMAX",
    "L IX{} IY{} RL F{}",
    "L X{} Y{} RR F AUTO",
    "L Z{} R0 FMAX M91",
    "L X{} Y{} M92",
    "L A{} C{} R0 FMAX M126",
    "L B{} R0 FMAX",
    "L X{} Y{} Z{} A{} C{} F{} M99",
    "LN X{} Y{} Z{} TX{} TY{} TZ{} F{}",
    "LN X{} Y{} Z{} NX{} NY{} NZ{}",
    "CC X{} Y{}",
    "CC IX{}",
    "C X{} Y{} DR+",
    "C X{} Y{} DR-",
    "CR X{} Y{} R{} DR+",
    "CT X{} Y{}",
    "LP PR{} PA{} R0 F{}",
    "LP IPR{} IPA{}",
    "CP PA{} DR+",
    "CP IPA{} IZ{} DR- F{}",
    "CTP PR{} PA{}",
    "RND R{}",
    "CHF {}",
    "CYCL DEF 7.0 DATUM SHIFT",
    "CYCL DEF 7.1 X{}",
    "CYCL DEF 7.2 IY{}",
    "CYCL DEF 8.0 MIRROR IMAGE",
    "CYCL DEF 8.1 X Y",
    "CYCL DEF 10.0 ROTATION",
    "CYCL DEF 10.1 ROT{}",
    "CYCL DEF 11.0 SCALING",
    "CYCL DEF 11.1 SCL {}",
    "CYCL DEF 26.1 X{} Y{}",
    "CYCL DEF 19.0 WORKING PLANE",
    "CYCL DEF 19.1 A{} C{}",
    "CYCL DEF 32.1 T{}",
    "CYCL DEF 247 DATUM SETTING ~\n  Q339={}",
    "CYCL DEF 200 DRILLING ~\n Q200={} ~\n Q201={} ~\n Q206={} ~\n Q202={} ~\n Q203={} ~\n Q204={}",
    "CYCL DEF 207 RIGID TAPPING NEW ~\n Q200={} ~\n Q201={} ~\n Q239={} ~\n Q203={} ~\n Q204={}",
    "CYCL DEF 208 BORE MILLING ~\n Q200={} ~\n Q201={} ~\n Q206={} ~\n Q334={} ~\n Q203={} ~\n Q204={} ~\n Q335={}",
    "CYCL DEF {}",
    "CYCL CALL",
    "CYCL CALL PAT FMAX",
    "PATTERN DEF ~\n POS1 (X{} Y{} Z{}) ~\n ROW1 (X{} Y{} D{} NUM{} ROT{} Z+0)",
    "PATTERN DEF ~\n CIRC1 (X{} Y{} D{} START{} NUM{} Z+0)",
    "PLANE SPATIAL SPA{} SPB{} SPC{} TURN FMAX",
    "PLANE SPATIAL SPA{} SPB{} SPC{} STAY SEQ-",
    "PLANE SPATIAL SPA{} SPB{} SPC{} MOVE MB{} F{} TABLE ROT",
    "PLANE PROJECTED PROPR{} PROMIN{} ROT{} TURN",
    "PLANE EULER EULPR{} EULNU{} EULROT{} MOVE DIST{} F{}",
    "PLANE VECTOR BX{} BY{} BZ{} NX{} NY{} NZ{} TURN MB MAX FMAX",
    "PLANE POINTS P1X{} P1Y{} P1Z{} P2X{} P2Y{} P2Z{} P3X{} P3Y{} P3Z{} STAY",
    "PLANE RELATIV SPB{} TURN SEQ+",
    "PLANE AXIAL A{} C{} TURN",
    "PLANE RESET TURN FMAX",
    "PLANE RESET STAY",
    "L A+Q120 C+Q122 R0 FMAX",
    "M128 F{}",
    "M129",
    "FUNCTION TCPM F TCP AXIS POS PATHCTRL VECTOR",
    "FUNCTION RESET TCPM",
    "BLK FORM 0.1 Z X{} Y{} Z{}",
    "BLK FORM 0.2 X{} Y{} Z{}",
    "Q1 = {}",
    "Q2 = Q1 * {} + SIN {}",
    "L X+Q1 Y-Q2 F{}",
    "FN 9: IF +Q1 EQU +{} GOTO LBL 1",
    "LBL 1",
    "LBL 0",
    "CALL LBL 1 REP{}",
    "STOP",
    "M89",
    "M30",
    "M3",
];

/// The built-in A/C table, and the same without travel limits (so that
/// more programs run past their first moves).
fn heidenhain_machines() -> [Machine; 2] {
    let machine = builtin("heidenhain-dmu-ac").expect("built-in machine");
    let mut free = machine.clone();
    for axis in &mut free.linear {
        axis.min = -1e6;
        axis.max = 1e6;
    }
    for axis in &mut free.rotary {
        axis.limits = None;
    }
    [machine, free]
}

/// A Klartext program of [`HEIDENHAIN_BLOCKS`], each block with signed
/// numbers and, one time in four, one character deleted, doubled or
/// inserted; between `BEGIN PGM` and `END PGM` after a tool call, or
/// bare.
fn heidenhain_program() -> impl Strategy<Value = String> {
    let block = (
        prop::sample::select(HEIDENHAIN_BLOCKS),
        prop::collection::vec(-400i32..400, 12),
        prop::option::weighted(0.25, (any::<prop::sample::Index>(), 0u8..3, any::<char>())),
    )
        .prop_map(|(template, numbers, mutation)| {
            let mut text = String::new();
            let mut n = numbers.iter();
            let mut parts = template.split("{}").peekable();
            while let Some(part) = parts.next() {
                text.push_str(part);
                if parts.peek().is_some() {
                    let v = n.next().copied().unwrap_or(1);
                    text.push_str(&format!("{:+}", f64::from(v) / 4.0));
                }
            }
            if let Some((at, kind, c)) = mutation {
                let chars: Vec<char> = text.chars().collect();
                let i = at.index(chars.len().max(1));
                let mut out: Vec<char> = chars.clone();
                match kind {
                    0 if !out.is_empty() => {
                        out.remove(i.min(out.len() - 1));
                    }
                    1 if !out.is_empty() => out.insert(i, chars[i.min(chars.len() - 1)]),
                    _ => out.insert(i.min(out.len()), c),
                }
                text = out.into_iter().collect();
            }
            text
        });
    (prop::collection::vec(block, 0..40), any::<bool>()).prop_map(|(blocks, framed)| {
        let body = blocks.join("\n");
        if framed {
            // A tool in the spindle and a feed first, so that more of the
            // blocks after it get past their first check.
            format!(
                "BEGIN PGM F MM\nTOOL CALL 1 Z S1000 F500\nCC X+0 Y+0\nL X+0 Y+0 Z-200 R0 F500\n{body}\nEND PGM F MM\n"
            )
        } else {
            body
        }
    })
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 256,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x4EED_0640),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn heidenhain_programs_end_or_alarm_with_finite_rows(program in heidenhain_program()) {
        for machine in heidenhain_machines() {
            check_run(&machine, program.as_bytes(), RunOptions::default())?;
        }
    }

    #[test]
    fn heidenhain_text_never_panics(program in "[A-Z0-9=()+\\-*/.:;~\" \n]{0,300}") {
        let machine = builtin("heidenhain-dmu-ac").expect("built-in machine");
        check_run(&machine, program.as_bytes(), RunOptions::default())?;
    }

    #[test]
    fn heidenhain_bytes_never_panic(program in prop::collection::vec(any::<u8>(), 0..400)) {
        let machine = builtin("heidenhain-dmu-ac").expect("built-in machine");
        check_run(&machine, &program, RunOptions::default())?;
    }
}
