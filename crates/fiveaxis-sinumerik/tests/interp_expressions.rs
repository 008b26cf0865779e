//! Golden values of expressions, functions, types and conversions, read
//! back from the words of single-line programs.

mod common;

use common::fake::{run, value_text};
use fiveaxis_sinumerik::Value;

/// `X=<expression>` and the value the word must carry, written short
/// (`value_text`).
const VALUES: &[(&str, &str)] = &[
    // Arithmetic and precedence (ONE p444).
    ("1+2*3", "7"),
    ("(1+2)*3", "9"),
    ("7/2", "3.5"),
    ("6/2", "3"),
    ("7 DIV 2", "3"),
    ("-7 DIV 2", "-3"),
    ("7.9 DIV 2", "3"),
    ("7 MOD 3", "1"),
    ("7.5 MOD 2", "1.5"),
    ("2*3-4/8", "5.5"),
    ("-(2+3)", "-5"),
    ("1+2==3", "TRUE"),
    ("1+2<>3", "FALSE"),
    ("(2*3>5) AND (1<2)", "TRUE"),
    ("1 OR 0 AND 0", "TRUE"),
    ("1 XOR 1", "FALSE"),
    ("NOT 1", "FALSE"),
    ("NOT (1>2)", "TRUE"),
    ("5 B_AND 3", "1"),
    ("5 B_OR 3", "7"),
    ("5 B_XOR 3", "6"),
    ("B_NOT 0", "-1"),
    ("1 B_OR 2 B_AND 2", "3"),
    ("3 >= 3", "TRUE"),
    ("2.5 <= 2", "FALSE"),
    // REAL comparisons with a relative tolerance of 1e-12.
    ("1==1+1EX-14", "TRUE"),
    ("1==1+1EX-6", "FALSE"),
    ("0.1+0.2==0.3", "TRUE"),
    // String concatenation, numbers written as the control writes them.
    ("\"A\"<<1.5", "\"A1.5\""),
    ("\"N\"<<3.0", "\"N3\""),
    ("\"V=\"<<0.1+0.2", "\"V=0.3\""),
    ("1<<2", "\"12\""),
    ("\"A\"<<\"B\"==\"AB\"", "TRUE"),
    ("\"ABC\"<\"ABD\"", "TRUE"),
    // Functions (ONE p387; 828JP p70, p74), degrees.
    ("SIN(30)", "0.5"),
    ("COS(60)", "0.5"),
    ("TAN(45)", "1"),
    ("ASIN(1)", "90"),
    ("ACOS(0)", "90"),
    ("ATAN2(1,1)", "45"),
    ("ATAN2(1,-1)", "135"),
    ("ATAN2(-1,0)", "-90"),
    ("SQRT(16)", "4"),
    ("SQRT(2)*SQRT(2)", "2"),
    ("ABS(-3)", "3"),
    ("ABS(-2.5)", "2.5"),
    ("POT(3)", "9"),
    ("POT(-1.5)", "2.25"),
    ("TRUNC(2.7)", "2"),
    ("TRUNC(-2.7)", "-2"),
    ("ROUND(2.5)", "3"),
    ("ROUND(-2.5)", "-3"),
    ("ROUND(2.4)", "2"),
    ("ROUNDUP(2.1)", "3"),
    ("ROUNDUP(2)", "2"),
    ("LN(EXP(2))", "2"),
    ("EXP(0)", "1"),
    ("MINVAL(3,2)", "2"),
    ("MAXVAL(3,2.5)", "3"),
    ("BOUND(0,10,12)", "10"),
    ("BOUND(0,10,-1)", "0"),
    ("BOUND(0,10,5.5)", "5.5"),
    ("STRLEN(\"ABC\")", "3"),
    ("STRLEN(\"\")", "0"),
    ("INDEX(\"ABCB\",\"B\")", "1"),
    ("RINDEX(\"ABCB\",\"B\")", "3"),
    ("INDEX(\"ABC\",\"Z\")", "-1"),
    ("SUBSTR(\"ABCDE\",1,3)", "\"BCD\""),
    ("SUBSTR(\"ABCDE\",2)", "\"CDE\""),
    ("SUBSTR(\"ABC\",5,2)", "\"\""),
    ("TOUPPER(\"ab1\")", "\"AB1\""),
    ("TOLOWER(\"AB1\")", "\"ab1\""),
    ("NUMBER(\"1.5\")", "1.5"),
    ("NUMBER(\" -2EX2 \")", "-200"),
    ("ISNUMBER(\"x1\")", "FALSE"),
    ("ISNUMBER(\"-2\")", "TRUE"),
    ("AXNAME(\"y\")", "Y"),
    ("AXSTRING(Y)", "\"Y\""),
    ("AXNAME(\"Z\")==Z", "TRUE"),
    // Names: an axis is a value of type AXIS, R parameters start at 0.
    ("C", "C"),
    ("R1", "0"),
    ("R99+1", "1"),
];

#[test]
fn expressions_and_functions() {
    let mut failures = Vec::new();
    for (expr, want) in VALUES {
        let r = run(&format!("X={expr}\nM30\n"));
        if let Some(e) = &r.error {
            failures.push(format!("{expr}: error {e:?}"));
            continue;
        }
        let got = r.values("X").first().map(value_text).unwrap_or_default();
        if got != *want {
            failures.push(format!("{expr}: got {got}, want {want}"));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// Programs that must stop with an alarm, and where.
const ALARMS: &[(&str, u32, (u32, u32))] = &[
    ("X=1/0", 14051, (3, 6)),
    ("X=1 DIV 0", 14051, (3, 10)),
    ("X=5 MOD 0", 14051, (3, 10)),
    ("X=SQRT(-1)", 14051, (3, 11)),
    ("X=ASIN(2)", 14051, (3, 10)),
    ("X=LN(0)", 14051, (3, 8)),
    ("X=UNDEF+1", 12550, (3, 8)),
    ("E_ZDARZ=1", 12550, (1, 8)),
    ("X=FOO(1)", 12550, (3, 9)),
    ("X=\"A\"+1", 14096, (3, 8)),
    ("R1=\"A\"", 14096, (1, 3)),
    ("X=R100", 17020, (3, 7)),
    ("X=R[100]", 17020, (3, 9)),
    ("R[-1]=2", 17020, (3, 5)),
    ("X=NUMBER(\"1A\")", 14096, (3, 15)),
    ("X=SIN()", 12080, (3, 8)),
];

#[test]
fn alarms_of_expressions() {
    let mut failures = Vec::new();
    for (text, alarm, (start, end)) in ALARMS {
        let r = run(&format!("{text}\nM30\n"));
        match &r.error {
            Some(e) => {
                if e.alarm != Some(*alarm)
                    || (e.span.start, e.span.end) != (*start, *end)
                    || e.line != 1
                {
                    failures.push(format!(
                        "{text}: alarm {:?} at {}..{} line {}, want {alarm} at {start}..{end}: {}",
                        e.alarm, e.span.start, e.span.end, e.line, e.message
                    ));
                }
                if e.message.is_empty() {
                    failures.push(format!("{text}: empty message"));
                }
            }
            None => failures.push(format!("{text}: no error")),
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// Programs and the words they give, in order.
const PROGRAMS: &[(&str, &[&str])] = &[
    // Conversions on assignment (840Di p62–63).
    ("DEF INT I=2.6\nX=I", &["X=3"]),
    ("DEF INT I=-2.5\nX=I", &["X=-3"]),
    ("DEF REAL A=5\nX=A", &["X=5"]),
    ("DEF BOOL B=2\nX=B", &["X=TRUE"]),
    ("DEF STRING[3] S=\"ABCDE\"\nX=S", &["X=\"ABC\""]),
    ("DEF STRING[10] S=12.50\nX=S<<\"|\"", &["X=\"12.5|\""]),
    ("DEF CHAR C=\"A\"\nX=C", &["X='A'"]),
    ("DEF CHAR C=66\nX=C", &["X='B'"]),
    ("DEF AXIS AX1=(Z)\nX=AX1", &["X=Z"]),
    ("DEF STRING[10] S=\"ABC\"\nX=S[1]", &["X='B'"]),
    ("DEF INT I, J=4\nX=I+J", &["X=4"]),
    ("R1=7\nDEF INT I=R1/2\nX=I", &["X=4"]),
    // Arrays with SET and REP (840Di p62–63).
    ("DEF REAL A[3]=SET(1,2,3)\nX=A[0]+A[1]*A[2]", &["X=7"]),
    (
        "DEF INT M[2,3]=REP(4)\nM[1,2]=9\nX=M[1,2]+M[0,0]",
        &["X=13"],
    ),
    (
        "DEF INT N[2,2]=SET(1,2,3)\nX=N[1,0] Y=N[1,1]",
        &["X=3", "Y=0"],
    ),
    ("DEF REAL A[4]\nR1=2\nA[R1+1]=1.5\nX=A[3]", &["X=1.5"]),
    // R parameters: R01 is R1, indexed R[…].
    ("R01=5\nX=R1", &["X=5"]),
    ("R1=5\nR[R1-3]=7\nX=R2", &["X=7"]),
    ("R1=2.5\nX=R1*2", &["X=5"]),
    // Assignments in a block are carried out in order while evaluating.
    ("R1=1 X=R1 R1=2 Y=R1", &["X=1", "Y=2"]),
    // Words: every value evaluated, T with a string.
    ("G1 X=R1*2+5 F=100*2", &["G=1", "X=5", "F=200"]),
    ("T=\"DRILL\" M6", &["T=\"DRILL\"", "M=6"]),
    ("X=AC(10) A3=IC(5)", &["X=10", "A3=5"]),
    ("POS[A]=90 FA[A]=1000", &["POS[A]=90", "FA[A]=1000"]),
];

#[test]
fn types_arrays_and_words() {
    let mut failures = Vec::new();
    for (text, want) in PROGRAMS {
        let r = run(&format!("{text}\nM30\n"));
        if let Some(e) = &r.error {
            failures.push(format!("{text:?}: error {e:?}"));
            continue;
        }
        let mut got = r.words();
        got.retain(|w| w != "M=30");
        if got != *want {
            failures.push(format!("{text:?}: got {got:?}, want {want:?}"));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// Programs that must stop with an alarm on a given line.
const PROGRAM_ALARMS: &[(&str, u32, u32)] = &[
    ("DEF INT I\nI=\"A\"", 14096, 2),
    ("DEF REAL A[3]\nX=A[3]", 17020, 2),
    ("DEF REAL A[2,3]\nX=A[0,3]", 17030, 2),
    ("DEF REAL A[2]=SET(1,2,3)", 17020, 1),
    ("DEF FRAME F=5", 14096, 1),
    ("DEF AXIS AX1=\"X\"", 14096, 1),
    ("DEF CHAR C=300", 14051, 1),
    ("DEF INT K=2147483647\nK=K+1", 14051, 2),
];

#[test]
fn alarms_of_programs() {
    let mut failures = Vec::new();
    for (text, alarm, line) in PROGRAM_ALARMS {
        let r = run(&format!("{text}\nM30\n"));
        match &r.error {
            Some(e) if e.alarm == Some(*alarm) && e.line == *line => {}
            other => failures.push(format!("{text:?}: {other:?}, want {alarm} on line {line}")),
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn frames_compose_and_reach_system_variables() {
    let mut sys = common::fake::FakeSystem::default();
    let r = common::fake::run_with(
        "DEF FRAME F\nF=CTRANS(X,10,Y,5):CROT(Z,90)\n$P_UIFR[1]=F\n$P_UIFR[2]=CROT(Z,90):CTRANS(X,10)\n$P_UIFR[3]=CSCALE(X,2):CTRANS(X,3):CMIRROR(Y)\nM30\n",
        common::fake::FakeStore::default(),
        &mut sys,
        fiveaxis_sinumerik::Options::default(),
    );
    r.ok();
    let frame = |k: &str| match sys.vars.get(k) {
        Some(Value::Frame(f)) => f.clone(),
        other => panic!("{k}: {other:?}"),
    };
    let comp = |f: &fiveaxis_sinumerik::FrameValue, axis: &str| {
        f.axes
            .iter()
            .find(|a| a.axis == axis)
            .map(|a| (a.tr, a.rt, a.sc, a.mi))
            .unwrap_or((0.0, 0.0, 1.0, false))
    };
    let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
    let f1 = frame("$P_UIFR[1]");
    assert!(close(comp(&f1, "X").0, 10.0) && close(comp(&f1, "Y").0, 5.0));
    assert!(close(comp(&f1, "Z").1, 90.0));
    let f2 = frame("$P_UIFR[2]");
    assert!(close(comp(&f2, "X").0, 0.0), "{f2:?}");
    assert!(close(comp(&f2, "Y").0, 10.0), "{f2:?}");
    let f3 = frame("$P_UIFR[3]");
    assert!(close(comp(&f3, "X").0, 6.0), "{f3:?}");
    assert!(close(comp(&f3, "X").2, 2.0) && comp(&f3, "Y").3, "{f3:?}");
}

#[test]
fn system_variables_are_read_with_axis_indices() {
    let mut sys = common::fake::FakeSystem::default();
    sys.vars.insert("$AA_IW[X]".into(), Value::Real(12.5));
    sys.vars.insert("$TC_DP3[1,2]".into(), Value::Real(100.0));
    let r = common::fake::run_with(
        "R1=$AA_IW[X]+$TC_DP3[1,R2+2]\nX=R1\n$P_TOOLNO=5\nM30\n",
        common::fake::FakeStore::default(),
        &mut sys,
        fiveaxis_sinumerik::Options::default(),
    );
    assert_eq!(r.words(), ["X=112.5", "M=30"]);
    assert_eq!(sys.vars.get("$P_TOOLNO"), Some(&Value::Int(5)));
    let r = run("X=$NOPE[Y]\n");
    assert_eq!(r.err().alarm, Some(12550));
    assert_eq!((r.err().span.start, r.err().span.end), (3, 11));
}

#[test]
fn words_keep_address_mode_and_span() {
    use fiveaxis_sinumerik::{Action, PositionMode};
    let r = run("N5 G1 X=AC(R1+10) A3=IC(-5) CYCLE81(2,,R1)\n");
    let b = &r.ok()[0];
    assert_eq!(b.number, Some(5));
    match &b.actions[1] {
        Action::Word {
            address,
            value,
            mode,
            span,
        } => {
            assert_eq!(address, "X");
            assert_eq!(value, &Value::Real(10.0));
            assert_eq!(*mode, Some(PositionMode::Ac));
            assert_eq!((span.start, span.end), (7, 18));
        }
        other => panic!("{other:?}"),
    }
    match &b.actions[3] {
        Action::Instruction { name, args, .. } => {
            assert_eq!(name, "CYCLE81");
            assert_eq!(
                args.as_deref(),
                Some(&[Some(Value::Int(2)), None, Some(Value::Real(0.0))][..])
            );
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn definitions_anywhere_and_again() {
    // DEF after executed blocks is accepted (the control wants it at the
    // top); a DEF run again by a jump back defines the variable afresh.
    let r = run("X1\nAGAIN: DEF INT K=5\nK=K+1\nY=K\nR1=R1+1\nIF R1<2 GOTOB AGAIN\nM30\n");
    assert_eq!(r.words(), ["X=1", "Y=6", "Y=6", "M=30"]);
}

#[test]
fn reals_are_written_short() {
    use fiveaxis_sinumerik::format_real;
    for (x, want) in [
        (1.5, "1.5"),
        (3.0, "3"),
        (-0.25, "-0.25"),
        (0.1 + 0.2, "0.3"),
        (1e-12, "0"),
        (-1e-12, "0"),
        (123456.789, "123456.789"),
        (f64::NAN, "0"),
    ] {
        assert_eq!(format_real(x), want, "{x}");
    }
}
