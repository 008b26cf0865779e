//! Unit tests of the scanner, one group per reading rule.

use super::*;
use SyntaxErrorKind::*;

/// Parses `text` as line 7.
fn parse(text: &str) -> Result<Block, SyntaxError> {
    parse_bytes(text.as_bytes())
}

fn parse_bytes(text: &[u8]) -> Result<Block, SyntaxError> {
    let mut block = Block::default();
    parse_line(text, 7, &mut block).map(|()| block)
}

/// The block of a line that must parse.
#[track_caller]
fn ok(text: &str) -> Block {
    match parse(text) {
        Ok(block) => block,
        Err(error) => panic!("{text:?} failed: {error:?}"),
    }
}

/// The error of a line that must fail, as (kind, start column, end column).
#[track_caller]
fn err(text: &str) -> (SyntaxErrorKind, u32, u32) {
    err_bytes(text.as_bytes())
}

#[track_caller]
fn err_bytes(text: &[u8]) -> (SyntaxErrorKind, u32, u32) {
    match parse_bytes(text) {
        Ok(block) => panic!("{text:?} parsed as {block:?}"),
        Err(error) => (error.kind, error.span.start, error.span.end),
    }
}

/// The words of a line as (letter, value, decimal point).
#[track_caller]
fn words(text: &str) -> Vec<(char, f64, bool)> {
    ok(text)
        .words
        .iter()
        .map(|w| (char::from(w.letter), w.value, w.decimal_point))
        .collect()
}

#[track_caller]
fn single(text: &str) -> Word {
    let block = ok(text);
    assert_eq!(block.words.len(), 1, "{text:?}: {block:?}");
    block.words[0]
}

fn spans(text: &str) -> Vec<(u32, u32)> {
    ok(text)
        .words
        .iter()
        .map(|w| (w.span.start, w.span.end))
        .collect()
}

fn unknown(text: &str) -> SyntaxErrorKind {
    UnknownWord(crate::UnknownWord::new(text.as_bytes()))
}

// --- blocks and lines ---------------------------------------------------

#[test]
fn empty_blank_and_comment_lines_have_no_words() {
    for text in [
        "",
        "   ",
        "\t \t",
        "(only a comment)",
        "  (a) (b)  ",
        ";",
        "\r",
    ] {
        let block = ok(text);
        assert!(block.is_empty(), "{text:?}");
        assert!(!block.tape_mark && !block.block_delete && block.sequence.is_none());
        assert_eq!(block.line, 7);
    }
}

#[test]
fn block_is_cleared_and_its_buffer_reused() {
    let mut block = Block::default();
    parse_line(b"/N5 G1 X1 Y2 Z3", 1, &mut block).expect("valid");
    let capacity = block.words.capacity();
    parse_line(b"G0", 2, &mut block).expect("valid");
    assert_eq!(block.line, 2);
    assert!(!block.block_delete);
    assert_eq!(block.sequence, None);
    assert_eq!(block.words.len(), 1);
    assert_eq!(block.words.capacity(), capacity);
}

#[test]
fn error_leaves_an_empty_block_with_its_line() {
    let mut block = Block::default();
    let error = parse_line(b"N3 G1 X1 Y--2", 12, &mut block).expect_err("bad number");
    assert_eq!(error.kind, BadNumber);
    assert_eq!(block.line, 12);
    assert!(block.is_empty());
    assert_eq!(block.sequence, None);
}

#[test]
fn semicolon_ends_the_block() {
    assert_eq!(words("G1 X1 ; Y2"), [('G', 1.0, false), ('X', 1.0, false)]);
    assert_eq!(words("G1;#@!=( \u{e9}"), [('G', 1.0, false)]);
}

#[test]
fn semicolon_ends_the_block_even_inside_a_comment() {
    assert_eq!(err("G1 (A;B)"), (UnclosedComment, 4, 6));
}

#[test]
fn missing_value_before_semicolon() {
    assert_eq!(err("G1 X;"), (MissingValue('X'), 4, 5));
}

#[test]
fn trailing_carriage_return_is_removed() {
    assert_eq!(words("G1 X1\r"), [('G', 1.0, false), ('X', 1.0, false)]);
    assert_eq!(words("G1 X1\r\n"), [('G', 1.0, false), ('X', 1.0, false)]);
    assert_eq!(words("G1 X1 ;\r"), [('G', 1.0, false), ('X', 1.0, false)]);
    assert_eq!(err("G1\r X1"), (UnexpectedChar('\r'), 3, 4));
}

// --- tape mark ------------------------------------------------------------

#[test]
fn tape_mark() {
    for text in [
        "%",
        "  %  ",
        "% (PROGRAM START)",
        "%\r",
        "\t%anything at all #[]=",
    ] {
        let block = ok(text);
        assert!(block.tape_mark, "{text:?}");
        assert!(block.is_empty());
    }
    assert!(!ok("G1").tape_mark);
}

#[test]
fn percent_elsewhere_is_unexpected() {
    assert_eq!(err("G1 %"), (UnexpectedChar('%'), 4, 5));
    assert_eq!(err("/%"), (UnexpectedChar('%'), 2, 3));
}

// --- block delete ---------------------------------------------------------

#[test]
fn block_delete() {
    let block = ok("/G1 X1");
    assert!(block.block_delete);
    assert_eq!(block.words.len(), 2);
    assert!(ok("  / N10 G0").block_delete);
    assert!(!ok("G0").block_delete);
    assert!(ok("/").block_delete);
}

#[test]
fn block_delete_skip_numbers_are_ignored() {
    for level in 1..=9 {
        let block = ok(&format!("/{level} G1"));
        assert!(block.block_delete);
        assert_eq!(block.words.len(), 1);
        assert_eq!(block.words[0].value, 1.0);
    }
    assert_eq!(spans("/ 3 N1 G1"), [(8, 10)]);
    assert_eq!(ok("/ 3 N1 G1").sequence, Some(1));
}

#[test]
fn block_delete_bad_skip_numbers_leave_a_stray_digit() {
    assert_eq!(err("/0 G1"), (UnexpectedChar('0'), 2, 3));
    assert_eq!(err("/12 G1"), (UnexpectedChar('2'), 3, 4));
}

#[test]
fn slash_not_first_is_unexpected() {
    assert_eq!(err("G1 /X1"), (UnexpectedChar('/'), 4, 5));
    assert_eq!(err("//G1"), (UnexpectedChar('/'), 2, 3));
    assert_eq!(err("(c) /G1"), (UnexpectedChar('/'), 5, 6));
}

// --- comments -------------------------------------------------------------

#[test]
fn comments_are_removed() {
    assert_eq!(
        words("G1(A)X1 (B) Y2(C)"),
        [('G', 1.0, false), ('X', 1.0, false), ('Y', 2.0, false)]
    );
    assert_eq!(spans("(HELLO) G1"), [(9, 11)]);
}

#[test]
fn comments_hold_anything() {
    assert_eq!(
        words("G1 (#1=[2] IF GOTO / % \u{e9} , ) X1"),
        [('G', 1.0, false), ('X', 1.0, false)]
    );
}

#[test]
fn nested_open_paren_is_text() {
    assert_eq!(words("G1 (A(B) X1"), [('G', 1.0, false), ('X', 1.0, false)]);
    assert_eq!(err("G1 (A(B)) X1"), (UnexpectedChar(')'), 9, 10));
}

#[test]
fn first_comment_is_kept_with_its_columns() {
    let block = ok("G47 P0 (TEXT TO ENGRAVE) X2. (second)");
    assert_eq!(block.comment, b"TEXT TO ENGRAVE");
    assert_eq!(block.comment_span, Some(Span::new(8, 25)));
    let block = ok("G1 X1");
    assert!(block.comment.is_empty() && block.comment_span.is_none());
    let block = ok("()");
    assert!(block.comment.is_empty());
    assert_eq!(block.comment_span, Some(Span::new(1, 3)));
    // The buffer is emptied for the next line.
    let mut block = ok("(A)");
    parse_line(b"G1 X1", 8, &mut block).expect("a plain line");
    assert!(block.comment.is_empty() && block.comment_span.is_none());
    // Haas's nested reading keeps the inner parentheses as text.
    let mut block = Block::default();
    parse_line_as(Syntax::HAAS, b"G47 P0 (A (B) C)", 1, &mut block).expect("nested comment");
    assert_eq!(block.comment, b"A (B) C");
    // Haas: a `;` inside a comment, nested or not, is text; outside one it
    // ends the block.
    parse_line_as(
        Syntax::HAAS,
        b"G47 P0 (A;B (C;D) E) X1. ; Y2.",
        1,
        &mut block,
    )
    .expect("semicolons in a comment");
    assert_eq!(block.comment, b"A;B (C;D) E");
    assert_eq!(block.words.len(), 3);
    // FANUC: the first `;` ends the block, inside a comment or not.
    assert_eq!(err("G1 (A;B) X1"), (UnclosedComment, 4, 6));
}

#[test]
fn unclosed_comment_spans_to_end_of_line() {
    assert_eq!(err("G1 (abc"), (UnclosedComment, 4, 8));
    assert_eq!(err("G1 (abc  "), (UnclosedComment, 4, 10));
    assert_eq!(err("G1 (abc\r"), (UnclosedComment, 4, 8));
    assert_eq!(err("("), (UnclosedComment, 1, 2));
}

#[test]
fn closing_paren_alone_is_unexpected() {
    assert_eq!(err("G1 ) X1"), (UnexpectedChar(')'), 4, 5));
}

#[test]
fn comment_ends_a_word() {
    assert_eq!(err("X1(C)0"), (UnexpectedChar('0'), 6, 7));
    assert_eq!(err("X(C)10"), (MissingValue('X'), 1, 2));
}

// --- letters and blanks ---------------------------------------------------

#[test]
fn letters_are_case_insensitive() {
    let block = ok("g1 x2 y-3 z4.");
    let letters: Vec<u8> = block.words.iter().map(|w| w.letter).collect();
    assert_eq!(letters, b"GXYZ");
}

#[test]
fn every_letter_is_an_address() {
    for letter in b'A'..=b'Z' {
        if letter == b'N' {
            continue;
        }
        for text in [
            format!("{}5", char::from(letter)),
            format!("{}5", char::from(letter.to_ascii_lowercase())),
        ] {
            let word = single(&text);
            assert_eq!(word.letter, letter);
            assert_eq!(word.value, 5.0);
        }
    }
}

#[test]
fn blanks_inside_words() {
    assert_eq!(
        words("G 1 X 1 0 . 5"),
        [('G', 1.0, false), ('X', 10.5, true)]
    );
    assert_eq!(spans("G 1 X 1 0 . 5"), [(1, 4), (5, 14)]);
    assert_eq!(words("X\t-\t2"), [('X', -2.0, false)]);
    assert_eq!(words("G1 .5"), [('G', 1.5, true)]);
}

#[test]
fn words_without_blanks() {
    assert_eq!(
        words("G1X10Y-2.5Z.5F100."),
        [
            ('G', 1.0, false),
            ('X', 10.0, false),
            ('Y', -2.5, true),
            ('Z', 0.5, true),
            ('F', 100.0, true),
        ]
    );
    assert_eq!(spans("G1X10Y-2.5"), [(1, 3), (3, 6), (6, 11)]);
}

#[test]
fn word_span_ends_at_the_last_character_of_its_number() {
    assert_eq!(spans("  X5.   Y6  "), [(3, 6), (9, 11)]);
}

// --- numbers --------------------------------------------------------------

#[test]
fn valid_numbers() {
    assert_eq!(words("X.5"), [('X', 0.5, true)]);
    assert_eq!(words("X5."), [('X', 5.0, true)]);
    assert_eq!(words("X-0.5"), [('X', -0.5, true)]);
    assert_eq!(words("X+3"), [('X', 3.0, false)]);
    assert_eq!(words("X0"), [('X', 0.0, false)]);
    assert_eq!(words("X007"), [('X', 7.0, false)]);
    assert_eq!(words("X-.25"), [('X', -0.25, true)]);
    assert_eq!(words("X+.25"), [('X', 0.25, true)]);
    assert_eq!(words("X0.0"), [('X', 0.0, true)]);
}

#[test]
fn negative_zero_keeps_its_sign() {
    let word = single("X-0");
    assert_eq!(word.value, 0.0);
    assert!(word.value.is_sign_negative());
}

#[test]
fn values_match_str_parse() {
    for (text, digits) in [
        ("X0.1", "0.1"),
        ("X-123.456", "-123.456"),
        ("X1.23456789012345", "1.23456789012345"),
        ("X999999999999999", "999999999999999"),
        ("X.000000000000001", "0.000000000000001"),
        ("X+7.7", "7.7"),
        ("X00012.5000", "12.5000"),
    ] {
        let expected: f64 = digits.parse().expect("valid float");
        assert_eq!(single(text).value.to_bits(), expected.to_bits(), "{text}");
    }
}

#[test]
fn bad_numbers() {
    assert_eq!(err("X1.2.3"), (BadNumber, 1, 7));
    assert_eq!(err("X1.2.3 Y1"), (BadNumber, 1, 7));
    assert_eq!(err("G1 X-"), (BadNumber, 4, 6));
    assert_eq!(err("X-."), (BadNumber, 1, 4));
    assert_eq!(err("X--1"), (BadNumber, 1, 5));
    assert_eq!(err("X."), (BadNumber, 1, 3));
    assert_eq!(err("X+-1"), (BadNumber, 1, 5));
    assert_eq!(err("X1-2"), (BadNumber, 1, 5));
    assert_eq!(err("X1+ Y2"), (BadNumber, 1, 4));
    assert_eq!(err("X- Y2"), (BadNumber, 1, 3));
    assert_eq!(err("X1 - 2"), (BadNumber, 1, 7));
    assert_eq!(err("X..5"), (BadNumber, 1, 5));
}

#[test]
fn exponents_are_bad_numbers() {
    assert_eq!(err("G1e5"), (BadNumber, 1, 5));
    assert_eq!(err("X1.5e-3 Y1"), (BadNumber, 1, 8));
    assert_eq!(err("X1.e2"), (BadNumber, 1, 6));
    assert_eq!(err("X1e"), (BadNumber, 1, 4));
}

#[test]
fn upper_case_e_and_spaced_e_are_addresses() {
    assert_eq!(words("G1E5"), [('G', 1.0, false), ('E', 5.0, false)]);
    assert_eq!(words("G1 e5"), [('G', 1.0, false), ('E', 5.0, false)]);
    assert_eq!(words("G1E-5"), [('G', 1.0, false), ('E', -5.0, false)]);
}

#[test]
fn too_many_digits() {
    assert_eq!(single("X123456789012345").value, 123_456_789_012_345.0);
    assert_eq!(err("X1234567890123456"), (TooManyDigits, 1, 18));
    assert_eq!(err("X12345678.90123456"), (TooManyDigits, 1, 19));
    assert_eq!(err("X.1234567890123456"), (TooManyDigits, 1, 19));
    assert_eq!(err("X1.000000000000000"), (TooManyDigits, 1, 19));
}

#[test]
fn leading_integer_zeros_do_not_count_as_digits() {
    let word = single("X00000000000000000001.5");
    assert_eq!(word.value, 1.5);
    assert_eq!(word.code, Some(Code::new(1, 5)));
    assert_eq!(single("X-000000000000000000000").value, 0.0);
}

#[test]
fn fraction_zeros_count_as_digits() {
    assert_eq!(single("X0.000000000000001").value, 1e-15);
    assert_eq!(err("X0.0000000000000001"), (TooManyDigits, 1, 20));
}

#[test]
fn malformed_number_wins_over_too_many_digits() {
    assert_eq!(err("X12345678901234567.8.9"), (BadNumber, 1, 23));
}

// --- codes ----------------------------------------------------------------

#[test]
fn codes() {
    for (text, major, minor) in [
        ("G43.4", 43, 4),
        ("G01", 1, 0),
        ("G1", 1, 0),
        ("G54.1", 54, 1),
        ("M98", 98, 0),
        ("G1.", 1, 0),
        ("G1.0", 1, 0),
        ("G.5", 0, 5),
        ("G0", 0, 0),
        ("G65535", 65535, 0),
        ("T0012", 12, 0),
        ("G 4 3 . 4", 43, 4),
    ] {
        assert_eq!(single(text).code, Some(Code::new(major, minor)), "{text}");
    }
}

#[test]
fn not_codes() {
    for text in [
        "X-1.25", "G1.50", "G+1", "G-1", "G65536", "X0.01", "G100000",
    ] {
        assert_eq!(single(text).code, None, "{text}");
    }
}

// --- sequence and program numbers -----------------------------------------

#[test]
fn sequence_number() {
    let block = ok("N10 G1 X1");
    assert_eq!(block.sequence, Some(10));
    assert_eq!(block.words.len(), 2);
    assert!(block.word(b'N').is_none());
    assert_eq!(ok("n0").sequence, Some(0));
    assert_eq!(ok("N0010").sequence, Some(10));
    assert_eq!(ok("N4294967295").sequence, Some(u32::MAX));
    assert_eq!(ok("G1 N5").sequence, Some(5));
    assert_eq!(ok("N 1 2").sequence, Some(12));
}

#[test]
fn bad_sequence_numbers() {
    assert_eq!(err("N4294967296"), (BadNumber, 1, 12));
    assert_eq!(err("N1.5 G1"), (BadNumber, 1, 5));
    assert_eq!(err("N1."), (BadNumber, 1, 4));
    assert_eq!(err("N-1"), (BadNumber, 1, 4));
    assert_eq!(err("N+1"), (BadNumber, 1, 4));
    assert_eq!(err("N"), (MissingValue('N'), 1, 2));
    assert_eq!(err("N1234567890123456"), (TooManyDigits, 1, 18));
}

#[test]
fn second_sequence_number_is_an_error() {
    assert_eq!(err("N1 G1 N2"), (DuplicateSequence, 7, 9));
}

#[test]
fn program_numbers_are_words() {
    let word = single("O1234");
    assert_eq!(word.letter, b'O');
    assert_eq!(word.value, 1234.0);
    assert_eq!(word.code, Some(Code::new(1234, 0)));
    assert_eq!(single("o0001 (MAIN)").value, 1.0);
}

// --- words of several letters ---------------------------------------------

#[test]
fn unknown_words() {
    assert_eq!(err("TRAORI"), (unknown("TRAORI"), 1, 7));
    assert_eq!(err("G1 traori"), (unknown("TRAORI"), 4, 10));
    assert_eq!(err("CYCLE800(1,2)"), (unknown("CYCLE800"), 1, 9));
    assert_eq!(err("o100 sub"), (unknown("SUB"), 6, 9));
    assert_eq!(err("G1 MY_WORD2 X1"), (unknown("MY_WORD2"), 4, 12));
    assert_eq!(err("G1 X Y1"), (unknown("XY1"), 4, 8));
    assert_eq!(err("X Y"), (unknown("XY"), 1, 4));
    assert_eq!(err("G1 TRAORI X1"), (unknown("TRAORI"), 4, 10));
    assert_eq!(err("G1 X TRAORI"), (unknown("XTRAORI"), 4, 12));
    assert_eq!(err("G1 X Y Z"), (unknown("XYZ"), 4, 9));
    assert_eq!(err("o100 s u b 1"), (unknown("SUB"), 6, 11));
    assert_eq!(
        err("ABCDEFGHIJKLMNOPQRSTUVWXYZ"),
        (unknown("ABCDEFGHIJKL"), 1, 27)
    );
}

/// The message of a line's error.
#[track_caller]
fn message(text: &str) -> String {
    err(text).0.to_string()
}

#[test]
fn a_letter_o_typed_for_a_zero_is_named_in_the_message() {
    assert_eq!(
        message("G1O X10."),
        "unknown word `OX10`: `O` after `G1` is the letter O; did you mean the digit 0 (`G10`)?"
    );
    assert_eq!(
        message("X5 m3o x1"),
        "unknown word `OX1`: `O` after `M3` is the letter O; did you mean the digit 0 (`M30`)?"
    );
    assert_eq!(
        message("GO1 X1"),
        "unknown word `GO1`: `O` in `GO1` is the letter O; did you mean the digit 0 (`G01`)?"
    );
    assert_eq!(
        message("G1 XO.5"),
        "unknown word `XO`: `O` in `XO` is the letter O; did you mean the digit 0 (`X0`)?"
    );
    // The span stays the word's.
    assert_eq!(err("G1O X10.").1..err("G1O X10.").2, 3..8);
}

#[test]
fn other_unknown_words_get_no_hint() {
    for (text, word) in [
        ("TRAORI", "TRAORI"),
        ("G1 OX10", "OX10"),
        ("o100 sub", "SUB"),
        ("G1 XO1A", "XO1A"),
        ("CYCLE800", "CYCLE800"),
        ("G1 X1 O X2", "OX2"),
    ] {
        assert_eq!(message(text), format!("unknown word `{word}`"), "{text}");
    }
}

#[test]
fn letter_digit_letter_is_two_words() {
    assert_eq!(words("G1X10"), [('G', 1.0, false), ('X', 10.0, false)]);
}

#[test]
fn missing_values() {
    assert_eq!(err("G1 X"), (MissingValue('X'), 4, 5));
    assert_eq!(err("G1 x  "), (MissingValue('X'), 4, 5));
    assert_eq!(err("G1 X (C)"), (MissingValue('X'), 4, 5));
    assert_eq!(err("G1 X(C)"), (MissingValue('X'), 4, 5));
    assert_eq!(err("G1X10Y"), (MissingValue('Y'), 6, 7));
}

#[test]
fn letter_followed_by_an_unexpected_byte_reports_that_byte() {
    assert_eq!(err("X=1"), (UnexpectedChar('='), 2, 3));
    assert_eq!(err("X ,1"), (UnexpectedChar(','), 3, 4));
    assert_eq!(err("X/1"), (UnexpectedChar('/'), 2, 3));
}

// --- custom macro syntax --------------------------------------------------

#[test]
fn macro_keywords() {
    assert_eq!(err("IF[#1EQ1]GOTO5"), (Macro, 1, 3));
    assert_eq!(err("GOTO10"), (Macro, 1, 5));
    assert_eq!(err("goto 10"), (Macro, 1, 5));
    assert_eq!(err("G O T O 1"), (Macro, 1, 8));
    assert_eq!(err("G O TO 1"), (Macro, 1, 7));
    assert_eq!(err("GOTO X1"), (Macro, 1, 5));
    assert_eq!(err("END1"), (Macro, 1, 4));
    assert_eq!(err("WHILE [#1 LT 5] DO1"), (Macro, 1, 6));
    assert_eq!(err("N10 DO 1"), (Macro, 5, 7));
    assert_eq!(err("G1 X1 POPEN"), (Macro, 7, 12));
    for keyword in MACRO_KEYWORDS {
        let text = std::str::from_utf8(keyword).expect("ASCII");
        let len = u32::try_from(keyword.len()).expect("short");
        assert_eq!(err(&format!("G0 {text} 1")), (Macro, 4, 4 + len), "{text}");
    }
}

#[test]
fn macro_characters() {
    assert_eq!(err("#1=2"), (Macro, 1, 2));
    assert_eq!(err("G1 X#1"), (Macro, 5, 6));
    assert_eq!(err("G1 X #1"), (Macro, 6, 7));
    assert_eq!(err("X[1+2]"), (Macro, 2, 3));
    assert_eq!(err("G1 ]"), (Macro, 4, 5));
    assert_eq!(err("/#1=2"), (Macro, 2, 3));
}

#[test]
fn any_error_in_a_macro_line_is_macro() {
    assert_eq!(err("G1 X-#1"), (Macro, 6, 7));
    assert_eq!(err("X1.2.3 #1"), (Macro, 8, 9));
    assert_eq!(err("ABC[1]"), (Macro, 4, 5));
    assert_eq!(err("X=#1"), (Macro, 3, 4));
    assert_eq!(err("X=1 (#1) [2]"), (Macro, 10, 11));
    assert_eq!(
        err("GOTO #1"),
        (Macro, 1, 5),
        "a keyword met first keeps its span"
    );
}

#[test]
fn macro_characters_in_comments_do_not_count() {
    assert_eq!(err("X=1 (#1)"), (UnexpectedChar('='), 2, 3));
    assert_eq!(err("X=1 (#1"), (UnexpectedChar('='), 2, 3));
    assert_eq!(err("(#1 X=1"), (UnclosedComment, 1, 8));
}

#[test]
fn equals_sign_outside_macros() {
    assert_eq!(err("G1 = 2"), (UnexpectedChar('='), 4, 5));
}

// --- unexpected bytes -----------------------------------------------------

#[test]
fn stray_characters() {
    assert_eq!(err("5 G1"), (UnexpectedChar('5'), 1, 2));
    assert_eq!(err("(C).5"), (UnexpectedChar('.'), 4, 5));
    assert_eq!(err("-1"), (UnexpectedChar('-'), 1, 2));
    assert_eq!(err("G1 ,C2."), (UnexpectedChar(','), 4, 5));
    assert_eq!(err("G1 @"), (UnexpectedChar('@'), 4, 5));
    assert_eq!(err("G1\x0bX1"), (UnexpectedChar('\x0b'), 3, 4));
    assert_eq!(err_bytes(b"G1\0"), (UnexpectedChar('\0'), 3, 4));
}

#[test]
fn non_ascii_characters_are_decoded() {
    assert_eq!(err("G1 \u{e9}"), (UnexpectedChar('\u{e9}'), 4, 6));
    assert_eq!(err("\u{20ac}5"), (UnexpectedChar('\u{20ac}'), 1, 4));
    assert_eq!(err("X1 \u{1f600}"), (UnexpectedChar('\u{1f600}'), 4, 8));
}

#[test]
fn invalid_utf8_is_reported_as_the_byte() {
    assert_eq!(err_bytes(b"G1 \xff X1"), (InvalidByte(0xff), 4, 5));
    assert_eq!(err_bytes(b"G1 \xe2\x82"), (InvalidByte(0xe2), 4, 5));
    // A real replacement character in UTF-8 text is a character.
    assert_eq!(
        err_bytes("G1 \u{fffd}".as_bytes()),
        (UnexpectedChar(char::REPLACEMENT_CHARACTER), 4, 7)
    );
    assert!(parse_bytes(b"G1 (\xff\xfe) X1").is_ok());
}

#[test]
fn first_error_is_reported() {
    assert_eq!(err("X1.2.3 Y--1"), (BadNumber, 1, 7));
    assert_eq!(err("G1 Q Y1.2.3"), (unknown("QY1"), 4, 8));
    assert_eq!(err("Y1 = (oops"), (UnexpectedChar('='), 4, 5));
    assert_eq!(err("Y1 TRAORI X1.2.3"), (unknown("TRAORI"), 4, 10));
}

// --- helpers --------------------------------------------------------------

#[test]
fn columns_saturate() {
    assert_eq!(column(0), 1);
    assert_eq!(column(usize::MAX), u32::MAX);
}

#[test]
fn decode_char_at_the_end_of_the_text() {
    assert_eq!(decode_char(b"", 0), (char::REPLACEMENT_CHARACTER, 1));
    assert_eq!(decode_char(b"a", 5), (char::REPLACEMENT_CHARACTER, 1));
    assert_eq!(decode_char(b"a\xc3\xa9", 1), ('\u{e9}', 2));
}

#[test]
fn linuxcnc_semicolon_inside_a_comment_is_text() {
    let mut block = Block::default();
    parse_line_as(Syntax::LINUXCNC, b"G1 (a;b) X2 ; rest (", 1, &mut block).expect("reads");
    assert_eq!(block.words.len(), 2);
    assert_eq!(block.words[1].letter, b'X');
    // FANUC: the first `;` ends the block, leaving `(a` unclosed.
    assert!(parse_line_as(Syntax::FANUC, b"G1 (a;b) X2", 1, &mut block).is_err());
}

/// LinuxCNC reads `m66e0l0` as `M66 E0 L0` (words are case-insensitive
/// and numbers have no exponent; rs274 runs the bridge mill demo's line);
/// FANUC tape format keeps refusing `G1e5` as a malformed number.
#[test]
fn a_lower_case_e_after_digits_is_a_word_in_linuxcnc_only() {
    let mut block = Block::default();
    crate::parse_line_as(crate::Syntax::LINUXCNC, b"m66e0l0", 1, &mut block).expect("reads");
    let words: Vec<(u8, f64)> = block.words.iter().map(|w| (w.letter, w.value)).collect();
    assert_eq!(words, vec![(b'M', 66.0), (b'E', 0.0), (b'L', 0.0)]);
    crate::parse_line_as(crate::Syntax::LINUXCNC, b"g1 x1.5e2", 1, &mut block).expect("reads");
    let words: Vec<(u8, f64)> = block.words.iter().map(|w| (w.letter, w.value)).collect();
    assert_eq!(words, vec![(b'G', 1.0), (b'X', 1.5), (b'E', 2.0)]);
    assert!(crate::parse_line(b"G1e5", 1, &mut block).is_err());
}
