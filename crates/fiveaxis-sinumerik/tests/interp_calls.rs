//! Subprograms, parameters, passes, sections, external and modal calls,
//! macros and global data.

mod common;

use common::fake::{FakeStore, FakeSystem, run_store, run_with};
use fiveaxis_sinumerik::{Options, Value};

fn words_of(main: &str, store: FakeStore) -> Vec<String> {
    let r = run_store(main, store);
    let mut w = r.words();
    w.retain(|w| w != "M=30");
    w
}

const SUB1: &str = "PROC SUB1(REAL A, VAR REAL B, INT C)\nB=A*2+C\nX=A\nRET\n";

#[test]
fn proc_with_value_and_var_parameters() {
    let store = FakeStore::with(&[("SUB1", SUB1)]);
    let r = run_store("DEF REAL Q\nSUB1(1.5, Q, 3)\nY=Q\nM30\n", store.clone());
    assert_eq!(r.words(), ["X=1.5", "Y=6", "M=30"]);
    assert_eq!(r.names, ["SUB1", "main", "main"]);
    assert_eq!(r.ok()[0].program, 1);
    assert_eq!(r.ok()[0].line, 3);
    // An omitted argument gets the type's default.
    assert_eq!(
        words_of("DEF REAL Q\nSUB1(1.5, Q)\nY=Q\nM30\n", store.clone()),
        ["X=1.5", "Y=3"]
    );
    assert_eq!(
        words_of("DEF REAL Q\nSUB1(, Q, 1)\nY=Q\nM30\n", store.clone()),
        ["X=0", "Y=1"]
    );
    // VAR by reference to an R parameter and to an array element.
    let store2 = FakeStore::with(&[("INC", "PROC INC(VAR REAL B)\nB=B+1\nM17\n")]);
    assert_eq!(
        words_of("R5=2\nINC(R5)\nINC(R5)\nX=R5\nM30\n", store2.clone()),
        ["X=4"]
    );
    assert_eq!(
        words_of(
            "DEF REAL A[3]\nINC(A[1])\nX=A[1] Y=A[0]\nM30\n",
            store2.clone()
        ),
        ["X=1", "Y=0"]
    );
    // A VAR parameter passed on by reference again.
    let store3 = FakeStore::with(&[
        ("INC", "PROC INC(VAR REAL B)\nB=B+1\nM17\n"),
        ("TWICE", "PROC TWICE(VAR REAL B)\nINC(B)\nINC(B)\nRET\n"),
    ]);
    assert_eq!(words_of("TWICE(R7)\nX=R7\nM30\n", store3), ["X=2"]);
    // An argument that is not a variable for a VAR parameter.
    let r = run_store("INC(5)\nM30\n", store2);
    assert_eq!(r.err().alarm, Some(12550));
    assert_eq!(r.err().line, 1);
    // Locals of the subprogram are its own.
    let store4 = FakeStore::with(&[("L1", "PROC L1\nDEF INT K=5\nX=K\nRET\n")]);
    let r = run_store("DEF INT K=1\nL1\nY=K\nM30\n", store4);
    assert_eq!(r.words(), ["X=5", "Y=1", "M=30"]);
    // Too many arguments, arguments without PROC.
    let r = run_store("SUB1(1, R1, 2, 3)\n", FakeStore::with(&[("SUB1", SUB1)]));
    assert_eq!(r.err().alarm, Some(12080));
    let r = run_store("NOPROC(1)\n", FakeStore::with(&[("NOPROC", "X1\n")]));
    assert_eq!(r.err().alarm, Some(12080));
}

#[test]
fn passes_returns_and_ends() {
    let store = FakeStore::with(&[
        ("L100", "X=R1\nR1=R1+1\nM17\n"),
        ("RETS", "G1 X5 M17\nX6\n"),
        ("ENDS", "X7\n"),
        ("STOPS", "X8 M30\nX9\n"),
        ("RETWORD", "Y1\nRET\nY2\n"),
    ]);
    assert_eq!(
        words_of("L100 P3\nM30\n", store.clone()),
        ["X=0", "X=1", "X=2"]
    );
    assert_eq!(
        words_of("R2=2\nL100 P=R2\nM30\n", store.clone()),
        ["X=0", "X=1"]
    );
    // M17 in a block with words: the block without M17, then back.
    let r = run_store("RETS\nY1\nM30\n", store.clone());
    assert_eq!(r.words(), ["G=1", "X=5", "Y=1", "M=30"]);
    // The end of a subprogram's text returns.
    assert_eq!(words_of("ENDS\nENDS\nM30\n", store.clone()), ["X=7", "X=7"]);
    // RET returns at once.
    assert_eq!(words_of("RETWORD\nM30\n", store.clone()), ["Y=1"]);
    // M30 in a subprogram ends the whole program after its block.
    let r = run_store("STOPS\nY1\nM30\n", store.clone());
    assert_eq!(r.words(), ["X=8", "M=30"]);
    // M17 and RET at the main level end the program.
    assert_eq!(words_of("X1\nM17\nX2\n", store.clone()), ["X=1"]);
    assert_eq!(words_of("X1\nRET\nX2\n", store.clone()), ["X=1"]);
    // The end of the main program's text ends it.
    assert_eq!(words_of("X1\n", store), ["X=1"]);
}

#[test]
fn nesting_is_bounded() {
    let store = FakeStore::with(&[("REC", "X1\nREC\n")]);
    let r = run_store("REC\n", store);
    let e = r.err();
    assert_eq!(e.alarm, None);
    assert!(e.message.contains("16"), "{}", e.message);
    assert_eq!(r.blocks.len(), 15);
}

#[test]
fn call_block_runs_a_section() {
    let main = "GOTOF START\nS1: X1\nX2\nS2: X3\nSTART: CALL BLOCK S1 TO S2\nX4\nCALL BLOCK S2\nCALL BLOCK N50 TO N60\nM30\nN50 Y1\nN60 Y2\nY3\n";
    assert_eq!(
        words_of(main, FakeStore::default()),
        ["X=1", "X=2", "X=3", "X=4", "X=3", "Y=1", "Y=2"]
    );
    let r = run_store("X1\nCALL BLOCK NONE TO S2\nX2\nX3\n", FakeStore::default());
    assert_eq!((r.err().alarm, r.err().line), (Some(14080), 2));
    assert_eq!((r.err().span.start, r.err().span.end), (12, 16));
}

#[test]
fn external_and_indirect_calls() {
    let store = FakeStore::with(&[("4444411", "X11\n"), ("SUB3", "X3\nM17\n")]);
    assert_eq!(
        words_of(
            "EXTCALL(\"4444411\")\nDEF STRING[20] P=\"SUB3\"\nCALL P\nCALL \"sub3\"\nM30\n",
            store.clone()
        ),
        ["X=11", "X=3", "X=3"]
    );
    let r = run_store("EXTCALL(\"MISSING\")\n", store.clone());
    assert_eq!((r.err().alarm, r.err().line), (Some(14011), 1));
    let r = run_store("X1\nUNKNOWN\n", store.clone());
    assert_eq!((r.err().alarm, r.err().line), (Some(14011), 2));
    assert_eq!((r.err().span.start, r.err().span.end), (1, 8));
    let r = run_store("CALL \"NOTHERE\"\n", store);
    assert_eq!(r.err().alarm, Some(14011));
}

#[test]
fn builtins_and_instructions_reach_the_control() {
    let w = words_of(
        "TRAORI\nCYCLE81(5,,3)\nMSG(\"R=\"<<R1)\nSTOPRE\nFGROUP(X,Y,Z)\nTRANS X10\nSETAL(61000)\nCYCLE800()\nM30\n",
        FakeStore::default(),
    );
    assert_eq!(
        w,
        [
            "TRAORI",
            "CYCLE81(5,,3)",
            "MSG(\"R=0\")",
            "FGROUP(X,Y,Z)",
            "TRANS",
            "X=10",
            "SETAL(61000)",
            "CYCLE800()"
        ]
    );
    // A store program wins over a builtin of the same name.
    assert_eq!(
        words_of(
            "CYCLE81(1)\nM30\n",
            FakeStore::with(&[("CYCLE81", "PROC CYCLE81(REAL D)\nZ=D\n")])
        ),
        ["Z=1"]
    );
}

#[test]
fn modal_calls() {
    // A subprogram of the store: called after every block that moves an axis.
    let store = FakeStore::with(&[("DRILL", "PROC DRILL(REAL D)\nZ=D\nRET\n")]);
    assert_eq!(
        words_of("MCALL DRILL(-5)\nX10\nY20\nG4 F1\nMCALL\nX30\nM30\n", store),
        ["X=10", "Z=-5", "Y=20", "Z=-5", "G=4", "F=1", "X=30"]
    );
    // A cycle the control carries out: a modal call action.
    assert_eq!(
        words_of(
            "MCALL CYCLE81(10,0,2,-5)\nX1\nMCALL\nM30\n",
            FakeStore::default()
        ),
        ["MCALL CYCLE81(10,0,2,-5)", "X=1", "MCALL"]
    );
}

#[test]
fn macros_and_global_data() {
    assert_eq!(
        words_of(
            "DEFINE LIFT AS G0 Z100\nLIFT\nX1 ; LIFT\nMSG(\"LIFT\")\nM30\n",
            FakeStore::default()
        ),
        ["G=0", "Z=100", "X=1", "MSG(\"LIFT\")"]
    );
    let store = FakeStore::with(&[("SUB4", "Y=E_ZDARZ\nZ=GTOL\nGTOL=1\n")])
        .define(
            "GUD",
            "%_N_GUD_DEF\nDEF NCK INT E_ZDARZ\nDEF CHAN REAL GTOL=0.5\nM30\n",
        )
        .define("MMAC", "DEFINE HOME AS G53 Z0\n");
    let r = run_store("E_ZDARZ=1.6\nX=GTOL\nSUB4\nHOME\nX=GTOL\nM30\n", store);
    assert_eq!(
        r.words(),
        ["X=0.5", "Y=2", "Z=0.5", "G=53", "Z=0", "X=1", "M=30"]
    );
    // An error in a definition file names it.
    let store = FakeStore::default().define("BAD", "DEF NCK INT\n");
    let r = run_store("X1\n", store);
    assert!(r.err().message.contains("BAD"), "{}", r.err().message);
    // A GUD is written through a VAR parameter too.
    let store = FakeStore::with(&[("INC", "PROC INC(VAR INT B)\nB=B+1\n")])
        .define("GUD", "DEF NCK INT COUNT\n");
    assert_eq!(
        words_of("INC(COUNT)\nINC(COUNT)\nX=COUNT\nM30\n", store),
        ["X=2"]
    );
}

#[test]
fn system_variables_by_reference() {
    let store = FakeStore::with(&[("SETV", "PROC SETV(VAR REAL B)\nB=42\n")]);
    let mut sys = FakeSystem::default();
    let r = run_with(
        "SETV($AC_MARKER[3])\nM30\n",
        store,
        &mut sys,
        Options::default(),
    );
    r.ok();
    assert_eq!(sys.vars.get("$AC_MARKER[3]"), Some(&Value::Int(42)));
}

#[test]
fn jumps_inside_a_subprogram_search_its_own_text() {
    let store = FakeStore::with(&[(
        "LOOPS",
        "PROC LOOPS(INT N)\nDEF INT K\nAGAIN: K=K+1\nX=K\nIF K<N GOTOB AGAIN\nRET\n",
    )]);
    assert_eq!(
        words_of("LOOPS(2)\nAGAIN: LOOPS(3)\nM30\n", store),
        ["X=1", "X=2", "X=1", "X=2", "X=3"]
    );
}

#[test]
fn locals_of_the_caller_are_not_visible() {
    let store = FakeStore::with(&[("PEEK", "X=K\n")]);
    let r = run_store("DEF INT K=1\nPEEK\n", store);
    let e = r.err();
    assert_eq!((e.alarm, e.program, e.line), (Some(12550), 1, 1));
    assert_eq!((e.span.start, e.span.end), (3, 4));
}

#[test]
fn passes_are_bounded_and_counted() {
    let store = FakeStore::with(&[("EMPTY", ""), ("L1", "X1\n")]);
    let r = run_store("EMPTY P10000\n", store.clone());
    assert_eq!(r.err().alarm, Some(12080));
    let r = run_store("EMPTY P0\n", store.clone());
    assert_eq!(r.err().alarm, Some(12080));
    // An empty program run 9999 times uses the budget up all the same.
    let options = Options {
        max_blocks: 500,
        ..Options::default()
    };
    let r = run_with(
        "EMPTY P9999\nM30\n",
        store.clone(),
        &mut FakeSystem::default(),
        options,
    );
    assert!(r.err().message.contains("budget"), "{:?}", r.err());
    let r = run_store("EMPTY P9999\nL1 P3\nM30\n", store);
    assert_eq!(r.words(), ["X=1", "X=1", "X=1", "M=30"]);
}

#[test]
fn each_opening_of_a_program_keeps_to_its_own_positions() {
    // The second call jumps forward to a label that only the first
    // opening has read: the text is searched again, not sought blindly.
    let store = FakeStore::with(&[("SUBJ", "IF R1==1 GOTOF SKIP\nX1\nSKIP: X2\n")]);
    assert_eq!(
        words_of("SUBJ\nR1=1\nSUBJ\nM30\n", store),
        ["X=1", "X=2", "X=2"]
    );
}
