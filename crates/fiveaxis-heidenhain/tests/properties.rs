//! The reader and the interpreter never panic, whatever the text: random
//! programs made of pieces of Klartext, run with a small block budget on
//! a fixed seed.

mod common;

use common::{FakeSystem, StrictText};
use fiveaxis_heidenhain::{Block, Executed, Interpreter, MemoryStore, Options, Step, parse_block};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// Pieces of Klartext, glued into lines at random.
fn piece() -> impl Strategy<Value = &'static str> {
    prop::sample::select(vec![
        "10 ",
        "/",
        "~",
        ";",
        " ; c~",
        "*",
        "L ",
        "LN ",
        "C ",
        "CC ",
        "CR ",
        "CP ",
        "LP ",
        "CTP ",
        "X",
        "IX",
        "Y+",
        "Z-",
        "+",
        "-",
        "5",
        ".5",
        "0",
        "Q",
        "Q1",
        "QL2",
        "QR3",
        "QS4",
        "Q2000",
        "F",
        "FMAX",
        "F MAX",
        "F AUTO",
        "FQ1",
        "R0",
        "RL",
        "DR+",
        "DR-",
        "R+20",
        "M3",
        "M30",
        "M",
        "PA+",
        "IPA",
        "=",
        "(",
        ")",
        "*",
        "/",
        "%",
        "^",
        " SIN ",
        " SQRT ",
        " SQ ",
        " LN ",
        " PI ",
        "||",
        "\"",
        "\"A\"",
        "SRC_",
        "TONUMB (",
        "SUBSTR ( SRC_QS4 BEG",
        " LEN",
        "FN ",
        "FN 4: Q1 = +1 DIV +",
        "FN 9: IF +Q1 EQU +",
        " GOTO LBL ",
        "LBL ",
        "LBL 0",
        "LBL 1",
        "LBL \"N\"",
        "CALL LBL 1",
        " REP ",
        "CALL PGM ",
        "SUB1",
        "TOOL CALL ",
        "TOOL DEF ",
        "\"T1\"",
        " Z ",
        "S1000",
        "DL+",
        "DR2+",
        "BLK FORM 0.1 Z",
        "CYCL DEF ",
        "7.0",
        "7.1",
        "200 DRILLING",
        "Q200=",
        "CYCL CALL",
        "PATTERN DEF ",
        "POS1 (",
        "PLANE ",
        "SPATIAL",
        "SPA+",
        "STAY",
        "SEQ-",
        "TABLE ROT",
        "MB MAX",
        "FUNCTION TCPM F TCP",
        "FUNCTION RESET",
        "P1X",
        "HSC-MODE:",
        "APPR LT",
        "DEP ",
        "LEN",
        "CHF ",
        "RND R",
        "END PGM",
        "BEGIN PGM ",
        "STOP",
        "DECLARE STRING ",
        "FN 14: ERROR = ",
        "FN 18: SYSREAD Q1 = ID",
        " NR",
        " IDX",
        "FN 13: Q1 = +0 ANG +",
        "TOCHAR ( DAT+",
        " DECIMALS",
        "ü",
        "\t",
    ])
}

/// Whole lines, mostly valid.
fn statement() -> impl Strategy<Value = &'static str> {
    prop::sample::select(vec![
        "L X+10 Y-5 R0 FMAX M3",
        "L X+Q1 IY-Q2 FQ3",
        "Q1 = Q1 + 1",
        "Q2 = SIN Q1 * 2 + SQRT ABS Q3",
        "QL1 = QL1 + 1",
        "QS1 = \"A\" || QS1",
        "Q5 = STRLEN ( SRC_QS1 )",
        "FN 0: Q3 = +5",
        "FN 4: Q4 = +Q1 DIV +2",
        "FN 9: IF +Q1 EQU +3 GOTO LBL 1",
        "FN 12: IF +Q1 LT +5 GOTO LBL 1",
        "FN 11: IF +Q1 GT +2 GOTO LBL \"END\"",
        "LBL 1",
        "LBL 0",
        "LBL \"END\"",
        "CALL LBL 1",
        "CALL LBL 1 REP 2",
        "CALL PGM SUB1",
        "END PGM X MM",
        "BEGIN PGM X MM",
        "CYCL DEF 200 DRILLING~",
        "   Q200=2 ;SET-UP CLEARANCE~",
        "   Q201=-Q1 ;DEPTH",
        "PLANE SPATIAL SPA+Q1 SPB+0 SPC+0 STAY SEQ- TABLE ROT",
        "FN 15: PRINT Q1",
        "FN 18: SYSREAD Q1 = ID210 NR1",
        "TOOL CALL 5 Z S3000 DL+0.1",
        "* - heading",
        "; comment",
        "/ L Z+1",
    ])
}

fn line() -> impl Strategy<Value = String> {
    prop_oneof![
        12 => statement().prop_map(str::to_string),
        1 => prop::collection::vec(piece(), 0..7).prop_map(|p| p.concat()),
    ]
}

fn program() -> impl Strategy<Value = String> {
    prop::collection::vec(line(), 0..15).prop_map(|l| l.join("\n"))
}

/// Runs one program; gives the blocks yielded and whether it failed.
fn run_one(text: &str) -> (usize, bool) {
    let store = MemoryStore::new()
        .with(
            "SUB1",
            "QL1 = QL1 + 1\nL X+QL1\nCALL LBL 3\nLBL 3\nEND PGM SUB1 MM\n",
        )
        .with("SUB2", "CALL PGM SUB2\n");
    let options = Options {
        block_skip: true,
        max_blocks: 3000,
    };
    let Ok(mut interp) =
        Interpreter::new(Box::new(StrictText::new(text)), Box::new(store), options)
    else {
        return (0, true);
    };
    let mut yielded = 0;
    let mut failed = false;
    let mut sys = FakeSystem::default();
    sys.data.insert((210, 1, None), 1.0);
    let mut out = Executed::default();
    for _ in 0..5000 {
        match interp.next_block(&mut sys, &mut out) {
            Ok(Step::Block) => {
                yielded += 1;
                let _ = interp.program_name(out.program);
            }
            Ok(Step::End) => break,
            Err(e) => {
                assert!(!e.message.is_empty());
                assert!(e.span.start >= 1 && e.span.start < e.span.end, "{e:?}");
                let _ = interp.program_name(e.program);
                if std::env::var("HH_DEBUG").is_ok() {
                    println!("{:?} {}", e.kind, e.message);
                }
                failed = true;
                break;
            }
        }
    }
    assert!(interp.blocks() <= 3001);
    assert!(interp.notes().len() <= 100);
    (yielded, failed)
}

#[test]
fn never_panics_on_random_programs() {
    let config = Config {
        cases: 400,
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner =
        TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    let stats = std::cell::Cell::new((0usize, 0usize, 0usize));
    runner
        .run(&program(), |text| {
            let (blocks, failed) = run_one(&text);
            let (n, b, f) = stats.get();
            stats.set((n + 1, b + blocks, f + usize::from(failed)));
            Ok(())
        })
        .expect("no panic");
    let (n, b, f) = stats.get();
    println!("{n} programs, {b} blocks, {f} stopped by an error");
    assert!(
        n >= 400 && b > n / 2 && f > 0 && f < n * 3 / 4,
        "{n} {b} {f}"
    );
}

#[test]
fn never_panics_on_random_bytes() {
    let config = Config {
        cases: 300,
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner =
        TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    runner
        .run(&prop::collection::vec(any::<u8>(), 0..400), |bytes| {
            let _ = run_one(&String::from_utf8_lossy(&bytes));
            let mut b = Block::default();
            if let Err(e) = parse_block(&bytes, &mut b) {
                assert!(e.span.start >= 1 && e.span.start < e.span.end);
            }
            Ok(())
        })
        .expect("no panic");
}

#[test]
fn reader_never_panics_on_pieces() {
    let config = Config {
        cases: 2000,
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner =
        TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    runner
        .run(&prop::collection::vec(piece(), 0..12), |p| {
            let text = p.concat();
            let mut b = Block::default();
            if let Err(e) = parse_block(text.as_bytes(), &mut b) {
                assert!(
                    e.span.start >= 1 && e.span.start < e.span.end,
                    "{text}: {e:?}"
                );
                assert!(!e.message.is_empty());
            }
            Ok(())
        })
        .expect("no panic");
}
