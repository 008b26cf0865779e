//! The interpreter never panics, whatever the text: random programs made
//! of pieces of the language, run with a small block budget on a fixed
//! seed.

mod common;

use common::fake::{FakeStore, FakeSystem, StrictText};
use fiveaxis_sinumerik::{Executed, Interpreter, Options, Step};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// Pieces of SINUMERIK text, glued into lines at random.
fn piece() -> impl Strategy<Value = &'static str> {
    prop::sample::select(vec![
        "N10 ",
        "N20 ",
        "/",
        "/1 ",
        "LBL: ",
        "LBL",
        "TOP: ",
        "TOP",
        "G1 ",
        "X",
        "X=",
        "Y-",
        "Z=R1",
        "10",
        "-5.5",
        ".5",
        "0",
        "EX-3",
        "=",
        "==",
        "<>",
        "<",
        ">=",
        "+",
        "-",
        "*",
        "/",
        " DIV ",
        " MOD ",
        " AND ",
        " OR ",
        " NOT ",
        " << ",
        "(",
        ")",
        "[",
        "]",
        ",",
        "R1",
        "R[R2]",
        "R1=",
        "R2=R2+1 ",
        "R99",
        "R100",
        "\"S\"",
        "IF ",
        "IF R1<3 ",
        "ELSE",
        "ENDIF",
        "WHILE ",
        "WHILE R2<5",
        "ENDWHILE",
        "FOR R3=1 TO 3",
        "ENDFOR",
        "REPEAT",
        "UNTIL ",
        "UNTIL R2>4",
        "LOOP",
        "ENDLOOP",
        "CASE(R1) OF 1 GOTOF LBL DEFAULT GOTOF TOP",
        "GOTOF ",
        "GOTOB ",
        "GOTO ",
        "GOTOC ",
        "GOTOS",
        "GOTOF N20",
        "GOTOB TOP",
        "DEF INT I",
        "DEF REAL A[3]=SET(1,2)",
        "DEF STRING[4] S=\"ABCDEF\"",
        "A[2]",
        "I=",
        "S[1]",
        "DEFINE MAC AS G0 X1",
        "MAC",
        "SUB1",
        "SUB1(1,R1)",
        "SUB2",
        "L100 P2",
        "CALL \"SUB1\"",
        "CALL BLOCK LBL TO TOP",
        "EXTCALL(\"SUB2\")",
        "MCALL SUB2",
        "MCALL CYCLE81(1,,2)",
        "MCALL",
        "RET",
        "M17",
        "M30",
        "M2",
        "STOPRE",
        "MSG(\"A\"<<R1)",
        "TRAORI",
        "SIN(",
        "SQRT(-1)",
        "ASIN(2)",
        "1/0",
        "CTRANS(X,1):CROT(Z,45)",
        "$P_UIFR[1]=",
        "$AA_IW[X]",
        "ID=1 WHENEVER R1>1 DO R2=1",
        "PROC SUB9(VAR REAL B)",
        ";",
        " ; c",
        "%_N_X_MPF",
        ":",
        "'H1F'",
        "AC(",
        "T=\"D\"",
    ])
}

/// Whole lines of the language, mostly valid.
fn statement() -> impl Strategy<Value = &'static str> {
    prop::sample::select(vec![
        "N10 G1 X=R1*2 Y5",
        "N20 R1=R1+1",
        "R2=R2+1",
        "LBL: X1",
        "TOP: R1=R1+1",
        "IF R1<3",
        "IF R2==1",
        "ELSE",
        "ENDIF",
        "WHILE R2<5",
        "ENDWHILE",
        "FOR R3=1 TO 3",
        "ENDFOR",
        "REPEAT",
        "UNTIL R2>4",
        "LOOP",
        "ENDLOOP",
        "CASE(R1) OF 1 GOTOF LBL 2 GOTOB TOP DEFAULT GOTOF N20",
        "IF R1>2 GOTOF LBL",
        "IF R2<3 GOTOB TOP",
        "GOTOF N20",
        "GOTOC NONE",
        "GOTO TOP",
        "GOTOS",
        "DEF INT I=2",
        "DEF REAL A[3]=SET(1,2)",
        "DEF STRING[4] S=\"ABCDEF\"",
        "X=A[R1]",
        "Y=S[R2]",
        "DEFINE MAC AS G0 X1",
        "MAC",
        "SUB1(1,R1)",
        "SUB2",
        "L100 P2",
        "CALL \"SUB1\"",
        "CALL BLOCK LBL TO TOP",
        "EXTCALL(\"SUB2\")",
        "MCALL SUB2",
        "MCALL CYCLE81(1,,2)",
        "MCALL",
        "RET",
        "M17",
        "M30",
        "STOPRE",
        "MSG(\"A\"<<R1)",
        "TRAORI",
        "$P_UIFR[1]=CTRANS(X,1):CROT(Z,45):CROT(X,30)",
        "R4=$AA_IW[X]/R2",
        "ID=1 WHENEVER R1>1 DO R2=1",
        "X=SQRT(R1-2) Y=ASIN(R2/3)",
    ])
}

fn line() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => statement().prop_map(str::to_string),
        1 => prop::collection::vec(piece(), 0..6).prop_map(|p| p.concat()),
    ]
}

fn program() -> impl Strategy<Value = String> {
    prop::collection::vec(line(), 0..25).prop_map(|l| l.join("\n"))
}

/// Runs one program; gives the blocks yielded and whether it failed.
fn run_one(text: &str) -> (usize, bool) {
    let store = FakeStore::with(&[
        ("SUB1", "PROC SUB1(REAL A, VAR REAL B)\nB=A+1\nX=B\nRET\n"),
        ("SUB2", "G0 Z=R1\nIF R1>1\nM17\nENDIF\nLBL: X1\n"),
        ("L100", "R1=R1+1\nX=R1\n"),
    ]);
    let options = Options {
        max_blocks: 3000,
        ..Options::default()
    };
    let Ok(mut interp) =
        Interpreter::new(Box::new(StrictText::new(text)), Box::new(store), options)
    else {
        return (0, true);
    };
    let mut yielded = 0;
    let mut failed = false;
    let mut sys = FakeSystem {
        zero_reads: true,
        ..FakeSystem::default()
    };
    let mut out = Executed::default();
    for _ in 0..5000 {
        match interp.next_block(&mut sys, &mut out) {
            Ok(Step::Block) => {
                assert!(!out.actions.is_empty());
                yielded += 1;
                let _ = interp.program_name(out.program);
            }
            Ok(Step::End) => break,
            Err(e) => {
                assert!(!e.message.is_empty());
                assert!(e.span.start >= 1 && e.span.start < e.span.end, "{e:?}");
                let _ = interp.program_name(e.program);
                failed = true;
                break;
            }
        }
    }
    assert!(interp.blocks() <= 3000);
    assert!(interp.notes().len() <= 101);
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
    // The pieces make programs that run as well as programs that fail.
    assert!(n >= 400 && b > n && f > 0 && f < n, "{n} {b} {f}");
}

#[test]
fn never_panics_on_random_bytes() {
    let config = Config {
        cases: 200,
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner =
        TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    runner
        .run(&prop::collection::vec(any::<u8>(), 0..400), |bytes| {
            let _ = run_one(&String::from_utf8_lossy(&bytes));
            Ok(())
        })
        .expect("no panic");
}
