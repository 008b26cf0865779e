//! The arguments of a macro call (`G65`, `G66`): argument specification I
//! and II.
//!
//! Sources: the Series 16i/18i operator's manual (B-63684EN, custom macro,
//! "argument specification", p. 278 found with the search tool) for the
//! mixed form (the argument specified later for the same variable wins,
//! example `G65 A1.0 B2.0 I-3.0 I4.0 D5.0 P1000` gives #1 = 1, #2 = 2,
//! #4 = -3, #7 = 5) and the tables as every FANUC manual gives them:
//!
//! * I: A #1, B #2, C #3, I #4, J #5, K #6, D #7, E #8, F #9, H #11, M #13,
//!   Q #17, R #18, S #19, T #20, U #21, V #22, W #23, X #24, Y #25, Z #26;
//! * II: A B C #1 … #3, then up to ten sets of I J K: set n gives
//!   #(3n+1), #(3n+2), #(3n+3).
//!
//! The NC tells I from II by the order of I, J, K: an I, J or K starts a
//! new set when its letter does not come after the last letter of the
//! current set (`I1 J2 I3` is set 1 = I1 J2, set 2 = I3; `I1 K2 J3` is
//! set 1 = I1 K2, set 2 = J3). A lone first set is specification I.
//!
//! Decisions where the manual is silent: the same A … Z letter twice keeps
//! the later value (the mixed-form rule); an eleventh I J K set is PS0129.
//! Values are taken as written: scaling a value written without decimal
//! point by the least input increment (the manual's rule) is left to the
//! caller, who knows the increment system, and can read
//! `Word::decimal_point` before calling.

use fiveaxis_gcode::{Block, Code};

use crate::error::{MacroError, MacroErrorKind};
use crate::variables::LOCAL_COUNT;

/// The local variable (1-based) of each argument specification I address.
fn spec_one(letter: u8) -> Option<usize> {
    Some(match letter {
        b'A' => 1,
        b'B' => 2,
        b'C' => 3,
        b'D' => 7,
        b'E' => 8,
        b'F' => 9,
        b'H' => 11,
        b'M' => 13,
        b'Q' => 17,
        b'R' => 18,
        b'S' => 19,
        b'T' => 20,
        b'U' => 21,
        b'V' => 22,
        b'W' => 23,
        b'X' => 24,
        b'Y' => 25,
        b'Z' => 26,
        _ => return None,
    })
}

/// How many I J K sets argument specification II has.
const IJK_SETS: usize = 10;

/// The macro call codes whose word is skipped: G65, G66, G66.1.
const CALL_CODES: [Code; 3] = [Code::new(65, 0), Code::new(66, 0), Code::new(66, 1)];

/// The local variables `#1` … `#33` a call with the words of `block` starts
/// with (`None`: vacant). The call word (G65, G66, G66.1), `P` (program)
/// and `L` (repetitions) are skipped.
///
/// # Errors
///
/// PS0129 for an address that cannot be an argument (another `G`, `O`,
/// or an eleventh I J K set), at the word.
pub fn arguments(block: &Block) -> Result<[Option<f64>; LOCAL_COUNT], MacroError> {
    let mut locals = [None; LOCAL_COUNT];
    // Current I J K set (1-based; 0 before the first) and the position
    // (0 = I, 1 = J, 2 = K) of its last letter.
    let mut set = 0usize;
    let mut last = None::<usize>;
    for word in &block.words {
        let index = match word.letter {
            b'G' if word.code.is_some_and(|c| CALL_CODES.contains(&c)) => continue,
            b'P' | b'L' => continue,
            letter @ (b'I' | b'J' | b'K') => {
                let position = usize::from(letter - b'I');
                if set == 0 || last.is_some_and(|l| position <= l) {
                    set += 1;
                }
                last = Some(position);
                if set > IJK_SETS {
                    return Err(MacroError::new(
                        MacroErrorKind::IllegalArgumentAddress,
                        word.span,
                        format!(
                            "`{}`: more than {IJK_SETS} I, J, K argument sets",
                            char::from(letter)
                        ),
                    ));
                }
                3 * set + position + 1
            }
            letter => spec_one(letter).ok_or_else(|| {
                MacroError::new(
                    MacroErrorKind::IllegalArgumentAddress,
                    word.span,
                    format!(
                        "address `{}` cannot be a macro argument",
                        char::from(letter)
                    ),
                )
            })?,
        };
        if let Some(slot) = locals.get_mut(index - 1) {
            *slot = Some(word.value);
        }
    }
    Ok(locals)
}
