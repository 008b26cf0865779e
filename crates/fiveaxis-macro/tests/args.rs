//! Argument specification I and II of G65/G66.

use fiveaxis_gcode::{Block, Span, parse_line};
use fiveaxis_macro::{LOCAL_COUNT, MacroErrorKind as K, arguments};

fn args(text: &str) -> Result<[Option<f64>; LOCAL_COUNT], fiveaxis_macro::MacroError> {
    let mut block = Block::default();
    parse_line(text.as_bytes(), 1, &mut block).expect("plain block");
    arguments(&block)
}

fn set(pairs: &[(usize, f64)]) -> [Option<f64>; LOCAL_COUNT] {
    let mut locals = [None; LOCAL_COUNT];
    for &(n, v) in pairs {
        locals[n - 1] = Some(v);
    }
    locals
}

#[test]
fn specification_one() {
    let got = args("G65 P9010 L2 A1. B2. C3. I4. J5. K6. D7. E8. F9. H11. M13. Q17. R18. S19. T20. U21. V22. W23. X24. Y25. Z26.").expect("ok");
    let want: Vec<(usize, f64)> = [
        1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 13, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26,
    ]
    .iter()
    .map(|&n| (n, n as f64))
    .collect();
    assert_eq!(got, set(&want));
    assert_eq!(args("G65 P1 X5").expect("ok"), set(&[(24, 5.0)]));
}

#[test]
fn specification_two() {
    let got = args("G65 P1 A1 B2 C3 I4 J5 K6 I7 J8 K9 I10 K12 J14").expect("ok");
    assert_eq!(
        got,
        set(&[
            (1, 1.0),
            (2, 2.0),
            (3, 3.0),
            (4, 4.0),
            (5, 5.0),
            (6, 6.0),
            (7, 7.0),
            (8, 8.0),
            (9, 9.0),
            (10, 10.0),
            (12, 12.0),
            (14, 14.0)
        ])
    );
    let ten = (1..=10)
        .map(|i| format!("I{i} J{i} K{i}"))
        .collect::<Vec<_>>()
        .join(" ");
    let got = args(&format!("G65 P1 {ten}")).expect("ok");
    assert_eq!(got[30..33], [Some(10.0); 3]);
    assert_eq!(got[3], Some(1.0));
    let e = args(&format!("G65 P1 {ten} I11")).expect_err("eleventh set");
    assert_eq!(e.kind, K::IllegalArgumentAddress);
}

#[test]
fn the_manuals_mixed_example() {
    // G65 A1.0 B2.0 I-3.0 I4.0 D5.0 P1000: D5.0 comes later than I4.0 (#7).
    let got = args("G65 A1.0 B2.0 I-3.0 I4.0 D5.0 P1000").expect("ok");
    assert_eq!(got, set(&[(1, 1.0), (2, 2.0), (4, -3.0), (7, 5.0)]));
    let got = args("G65 P1 D5.0 I-3.0 I4.0").expect("ok");
    assert_eq!(got, set(&[(4, -3.0), (7, 4.0)]));
}

#[test]
fn addresses_that_are_not_arguments() {
    let e = args("G65 P1 G01 A1").expect_err("G");
    assert_eq!(e.kind, K::IllegalArgumentAddress);
    assert_eq!(e.fanuc_number(), 129);
    assert_eq!(e.span, Span::new(8, 11));
    assert_eq!(
        args("G65 P1 O100").map_err(|e| e.kind),
        Err(K::IllegalArgumentAddress)
    );
    assert_eq!(args("G66 P1 A1").expect("ok"), set(&[(1, 1.0)]));
    assert_eq!(args("G66.1 P1 A1").expect("ok"), set(&[(1, 1.0)]));
    assert_eq!(args("N5 G65 P1 L3").expect("ok"), [None; LOCAL_COUNT]);
}
