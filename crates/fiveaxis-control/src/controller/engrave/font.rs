//! The kernel's single-stroke engraving font for Haas G47.
//!
//! Haas's own font is compiled into the control and not published (the
//! mill operator's manual only says the strokes are G-code in the control,
//! once replaceable as program O9876), so the kernel draws its own: every
//! printable ASCII character, codes 32 to 126 (the characters G47 P0
//! engraves, and the range of G47 P32–P126), as polylines on a grid.
//!
//! The cell, in grid units:
//!
//! * capitals and digits stand on the baseline, y = 0, and are
//!   [`CAP_HEIGHT`] = 6 high (J, the height of the text, is this height);
//! * lower-case letters are 4 high, with ascenders to 6 and descenders to
//!   [`DESCENDER`] = −2 (g j p q y , ; _ |);
//! * every glyph lies within x = 0 … [`GLYPH_WIDTH`] = 4, and characters
//!   follow each other every [`ADVANCE`] = 6 units (a gap of 2);
//!
//! so with `J` the scale is J / 6 per unit: a capital is 2/3 J wide and J
//! high, the next character starts J further on. Curves are drawn as
//! polygons on the grid. A glyph is written as text: strokes separated by
//! `/`, the points of a stroke by blanks, each point `x,y`; a stroke of one
//! point is a dot (plunge and retract in place). The space has no stroke.
//! The design is the kernel's own.

/// Height of capitals and digits, grid units (the text height J).
pub const CAP_HEIGHT: i8 = 6;
/// Lowest point of descenders, grid units (the tests keep every glyph
/// within the cell).
#[allow(dead_code)]
pub const DESCENDER: i8 = -2;
/// Widest glyph, grid units.
#[allow(dead_code)]
pub const GLYPH_WIDTH: i8 = 4;
/// From one character's origin to the next, grid units.
pub const ADVANCE: i8 = 6;

/// First character of the font (the space).
pub const FIRST: u8 = 32;
/// Last character of the font (`~`).
pub const LAST: u8 = 126;

/// The glyphs of characters 32 … 126, in order.
const GLYPHS: [&str; (LAST - FIRST + 1) as usize] = [
    // 32 space
    "",
    // 33 !
    "2,6 2,2/2,0",
    // 34 "
    "1,6 1,4/3,6 3,4",
    // 35 #
    "1,0 1,6/3,0 3,6/0,2 4,2/0,4 4,4",
    // 36 $
    "4,5 3,6 1,6 0,5 0,4 1,3 3,3 4,2 4,1 3,0 1,0 0,1/2,6 2,0",
    // 37 %
    "0,0 4,6/0,6 1,6 1,5 0,5 0,6/3,1 4,1 4,0 3,0 3,1",
    // 38 &
    "4,0 1,4 1,5 2,6 3,5 3,4 0,2 0,1 1,0 2,0 4,2",
    // 39 '
    "2,6 2,4",
    // 40 (
    "3,6 1,4 1,2 3,0",
    // 41 )
    "1,6 3,4 3,2 1,0",
    // 42 *
    "2,5 2,1/0,4 4,2/0,2 4,4",
    // 43 +
    "2,5 2,1/0,3 4,3",
    // 44 ,
    "2,1 2,0 1,-1",
    // 45 -
    "0,3 4,3",
    // 46 .
    "2,0",
    // 47 /
    "0,0 4,6",
    // 48 0 (slashed, unlike O)
    "1,0 0,1 0,5 1,6 3,6 4,5 4,1 3,0 1,0/0,1 4,5",
    // 49 1
    "1,5 2,6 2,0/1,0 3,0",
    // 50 2
    "0,5 1,6 3,6 4,5 4,4 0,0 4,0",
    // 51 3
    "0,5 1,6 3,6 4,5 4,4 3,3 1,3/3,3 4,2 4,1 3,0 1,0 0,1",
    // 52 4
    "3,0 3,6 0,2 4,2",
    // 53 5
    "4,6 0,6 0,3 3,3 4,2 4,1 3,0 1,0 0,1",
    // 54 6
    "4,5 3,6 1,6 0,5 0,1 1,0 3,0 4,1 4,2 3,3 0,3",
    // 55 7
    "0,6 4,6 1,0",
    // 56 8
    "1,3 0,4 0,5 1,6 3,6 4,5 4,4 3,3 1,3 0,2 0,1 1,0 3,0 4,1 4,2 3,3",
    // 57 9
    "4,3 1,3 0,4 0,5 1,6 3,6 4,5 4,1 3,0 1,0 0,1",
    // 58 :
    "2,4/2,1",
    // 59 ;
    "2,4/2,1 2,0 1,-1",
    // 60 <
    "4,6 0,3 4,0",
    // 61 =
    "0,4 4,4/0,2 4,2",
    // 62 >
    "0,6 4,3 0,0",
    // 63 ?
    "0,5 1,6 3,6 4,5 4,4 2,3 2,2/2,0",
    // 64 @
    "3,2 3,4 1,4 1,2 3,2 4,3 4,5 3,6 1,6 0,5 0,1 1,0 4,0",
    // 65 A
    "0,0 0,4 2,6 4,4 4,0/0,3 4,3",
    // 66 B
    "0,0 0,6 3,6 4,5 4,4 3,3 0,3/3,3 4,2 4,1 3,0 0,0",
    // 67 C
    "4,5 3,6 1,6 0,5 0,1 1,0 3,0 4,1",
    // 68 D
    "0,0 0,6 2,6 4,4 4,2 2,0 0,0",
    // 69 E
    "4,6 0,6 0,0 4,0/0,3 3,3",
    // 70 F
    "4,6 0,6 0,0/0,3 3,3",
    // 71 G
    "4,5 3,6 1,6 0,5 0,1 1,0 3,0 4,1 4,3 2,3",
    // 72 H
    "0,0 0,6/4,0 4,6/0,3 4,3",
    // 73 I
    "1,6 3,6/2,6 2,0/1,0 3,0",
    // 74 J
    "4,6 4,1 3,0 1,0 0,1",
    // 75 K
    "0,0 0,6/4,6 0,2/1,3 4,0",
    // 76 L
    "0,6 0,0 4,0",
    // 77 M
    "0,0 0,6 2,3 4,6 4,0",
    // 78 N
    "0,0 0,6 4,0 4,6",
    // 79 O
    "1,0 0,1 0,5 1,6 3,6 4,5 4,1 3,0 1,0",
    // 80 P
    "0,0 0,6 3,6 4,5 4,4 3,3 0,3",
    // 81 Q
    "1,0 0,1 0,5 1,6 3,6 4,5 4,1 3,0 1,0/2,2 4,0",
    // 82 R
    "0,0 0,6 3,6 4,5 4,4 3,3 0,3/2,3 4,0",
    // 83 S
    "4,5 3,6 1,6 0,5 0,4 1,3 3,3 4,2 4,1 3,0 1,0 0,1",
    // 84 T
    "0,6 4,6/2,6 2,0",
    // 85 U
    "0,6 0,1 1,0 3,0 4,1 4,6",
    // 86 V
    "0,6 2,0 4,6",
    // 87 W
    "0,6 1,0 2,4 3,0 4,6",
    // 88 X
    "0,0 4,6/0,6 4,0",
    // 89 Y
    "0,6 2,3 4,6/2,3 2,0",
    // 90 Z
    "0,6 4,6 0,0 4,0",
    // 91 [
    "3,6 1,6 1,0 3,0",
    // 92 backslash
    "0,6 4,0",
    // 93 ]
    "1,6 3,6 3,0 1,0",
    // 94 ^
    "0,4 2,6 4,4",
    // 95 _
    "0,-1 4,-1",
    // 96 `
    "1,6 3,4",
    // 97 a
    "0,4 3,4 4,3 4,0 1,0 0,1 0,2 1,2 4,2",
    // 98 b
    "0,6 0,0 3,0 4,1 4,3 3,4 0,4",
    // 99 c
    "4,4 1,4 0,3 0,1 1,0 4,0",
    // 100 d
    "4,6 4,0 1,0 0,1 0,3 1,4 4,4",
    // 101 e
    "0,2 4,2 4,3 3,4 1,4 0,3 0,1 1,0 4,0",
    // 102 f
    "4,6 2,6 1,5 1,0/0,4 3,4",
    // 103 g
    "4,0 1,0 0,1 0,3 1,4 4,4 4,-1 3,-2 0,-2",
    // 104 h
    "0,6 0,0/0,4 3,4 4,3 4,0",
    // 105 i
    "2,4 2,0/2,6",
    // 106 j
    "3,4 3,-1 2,-2 0,-2/3,6",
    // 107 k
    "0,6 0,0/4,4 0,1/1,2 4,0",
    // 108 l
    "1,6 2,6 2,1 3,0",
    // 109 m
    "0,0 0,4/0,3 1,4 2,3 2,0/2,3 3,4 4,3 4,0",
    // 110 n
    "0,0 0,4/0,3 1,4 3,4 4,3 4,0",
    // 111 o
    "1,0 0,1 0,3 1,4 3,4 4,3 4,1 3,0 1,0",
    // 112 p
    "0,-2 0,4 3,4 4,3 4,1 3,0 0,0",
    // 113 q
    "4,-2 4,4 1,4 0,3 0,1 1,0 4,0",
    // 114 r
    "0,0 0,4/0,2 2,4 4,4",
    // 115 s
    "4,4 1,4 0,3 1,2 3,2 4,1 3,0 0,0",
    // 116 t
    "1,6 1,1 2,0 3,0/0,4 3,4",
    // 117 u
    "0,4 0,1 1,0 3,0 4,1/4,4 4,0",
    // 118 v
    "0,4 2,0 4,4",
    // 119 w
    "0,4 1,0 2,3 3,0 4,4",
    // 120 x
    "0,0 4,4/0,4 4,0",
    // 121 y
    "0,4 2,0/4,4 1,-2",
    // 122 z
    "0,4 4,4 0,0 4,0",
    // 123 {
    "3,6 2,5 2,4 1,3 2,2 2,1 3,0",
    // 124 |
    "2,6 2,-2",
    // 125 }
    "1,6 2,5 2,4 3,3 2,2 2,1 1,0",
    // 126 ~
    "0,3 1,4 3,2 4,3",
];

/// The strokes of character `c`, or `None` when the font has no such
/// character. Each stroke is an iterator over its points (grid units).
pub fn glyph(c: u8) -> Option<impl Iterator<Item = Stroke>> {
    let text = GLYPHS.get(usize::from(c.checked_sub(FIRST)?))?;
    Some(text.split('/').filter(|s| !s.is_empty()).map(Stroke))
}

/// One stroke of a glyph: a polyline drawn without lifting the tool.
#[derive(Clone, Copy, Debug)]
pub struct Stroke(&'static str);

impl Stroke {
    /// The points of the stroke in order, grid units.
    pub fn points(self) -> impl Iterator<Item = (i8, i8)> {
        self.0.split(' ').map(point)
    }
}

/// One `x,y` point of the glyph table (checked by the font's tests).
fn point(text: &str) -> (i8, i8) {
    let (x, y) = text.split_once(',').unwrap_or((text, "0"));
    (x.parse().unwrap_or(0), y.parse().unwrap_or(0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every point of every glyph is well written and inside the cell.
    #[test]
    fn every_glyph_is_well_formed_and_inside_the_cell() {
        for (i, text) in GLYPHS.iter().enumerate() {
            let c = char::from(FIRST + i as u8);
            for stroke in text.split('/').filter(|s| !s.is_empty()) {
                for p in stroke.split(' ') {
                    let (x, y) = p.split_once(',').unwrap_or_else(|| panic!("{c:?}: {p:?}"));
                    let (x, y): (i8, i8) = (
                        x.parse().unwrap_or_else(|_| panic!("{c:?}: {p:?}")),
                        y.parse().unwrap_or_else(|_| panic!("{c:?}: {p:?}")),
                    );
                    assert!((0..=GLYPH_WIDTH).contains(&x), "{c:?}: x {x}");
                    assert!((DESCENDER..=CAP_HEIGHT).contains(&y), "{c:?}: y {y}");
                }
            }
            // Only the space is blank.
            assert_eq!(text.is_empty(), c == ' ', "{c:?}");
        }
    }

    /// No two characters share a glyph (O and 0, l and 1, I and |, … stay
    /// apart).
    #[test]
    fn glyphs_are_distinct() {
        for (i, a) in GLYPHS.iter().enumerate() {
            for (j, b) in GLYPHS.iter().enumerate().skip(i + 1) {
                assert_ne!(a, b, "{:?} and {:?}", FIRST + i as u8, FIRST + j as u8);
            }
        }
    }

    #[test]
    fn characters_outside_the_font_have_no_glyph() {
        assert!(glyph(31).is_none());
        assert!(glyph(127).is_none());
        assert!(glyph(b'A').is_some());
        assert_eq!(glyph(b' ').map(Iterator::count), Some(0));
        let a: Vec<Vec<(i8, i8)>> = glyph(b'A')
            .expect("A is in the font")
            .map(|s| s.points().collect())
            .collect();
        assert_eq!(
            a,
            [
                vec![(0, 0), (0, 4), (2, 6), (4, 4), (4, 0)],
                vec![(0, 3), (4, 3)]
            ]
        );
    }
}
