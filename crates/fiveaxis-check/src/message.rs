//! A finding's words as data: pieces of fixed text, letters and numbers,
//! turned into text only where a report is written.
//!
//! The findings a block can raise on every block (chord error, rotary
//! flip, feed limit, singular passage, over-travel) keep their numbers as
//! numbers: a writer that has its own number formatting (the JSON report)
//! writes them with it, and a finding no one writes costs no text. Every
//! number reads as Rust's `{}` writes it (negative zero as `0`, as in the
//! rows), so [`Message`]'s `Display` and such a writer give the same
//! text.

use arrayvec::ArrayVec;
use std::fmt;

/// Most words one message holds (an over-travel's message has 12).
pub const MAX_WORDS: usize = 12;

/// One word of a message.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Word<'a> {
    /// Text as it is.
    Text(&'a str),
    /// A letter (an axis name, a sign).
    Letter(char),
    /// A number, written as Rust's `{}` writes an `f64`, but never `-0`
    /// (as the rows write numbers).
    Number(f64),
}

/// A finding's message.
#[derive(Clone, Debug, PartialEq)]
pub struct Message(Repr);

// The words stay inline: they are the message of every finding a block
// raises, and boxing them would cost the allocation kept words avoid.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
enum Repr {
    /// Text made where the finding was found (rare findings).
    Owned(String),
    /// Words kept apart until written.
    Words(ArrayVec<Word<'static>, MAX_WORDS>),
}

impl Message {
    /// A message of these words (at most [`MAX_WORDS`]; a longer list is
    /// a fault of the caller, which debug builds and the tests stop at,
    /// and a release build cuts short).
    pub fn of(words: &[Word<'static>]) -> Self {
        debug_assert!(words.len() <= MAX_WORDS, "{} words", words.len());
        Self(Repr::Words(words.iter().copied().take(MAX_WORDS).collect()))
    }

    /// The words in order: an owned text is one word.
    pub fn words(&self) -> impl Iterator<Item = Word<'_>> {
        let (owned, words): (Option<&str>, &[Word<'static>]) = match &self.0 {
            Repr::Owned(text) => (Some(text), &[]),
            Repr::Words(words) => (None, words),
        };
        owned
            .map(Word::Text)
            .into_iter()
            .chain(words.iter().copied())
    }
}

impl From<String> for Message {
    fn from(text: String) -> Self {
        Self(Repr::Owned(text))
    }
}

impl fmt::Display for Message {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for word in self.words() {
            match word {
                Word::Text(text) => f.write_str(text)?,
                Word::Letter(c) => fmt::Write::write_char(f, c)?,
                Word::Number(x) => write!(f, "{}", x + 0.0)?,
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_read_as_the_text_they_stand_for() {
        let m = Message::of(&[
            Word::Letter('C'),
            Word::Text(" turns "),
            Word::Number(93.637),
            Word::Text("° in one block (more than "),
            Word::Number(90.0),
            Word::Text("°)"),
        ]);
        assert_eq!(
            m.to_string(),
            "C turns 93.637° in one block (more than 90°)"
        );
        let owned = Message::from("X+ over-travel".to_string());
        assert_eq!(owned.to_string(), "X+ over-travel");
        assert_eq!(owned.words().count(), 1);
        let zero = Message::of(&[Word::Number(-0.0), Word::Text(" mm")]);
        assert_eq!(zero.to_string(), "0 mm");
    }
}
