//! A text buffer for formatted rows: bytes are written at a cursor into
//! storage that always has room for one more row, so that small pieces are
//! copied as fixed-size chunks instead of through `memcpy` calls.

/// Bytes gathered before the buffer asks to be written out.
pub const CHUNK: usize = 1 << 16;
/// Room kept free past the cursor when a row starts: more than the longest
/// row (16 columns of the longest number, 330 bytes, plus JSON keys).
pub const ROW_ROOM: usize = 1 << 13;

/// The digits of 00 to 99, two bytes each.
const PAIRS: &[u8; 200] = b"0001020304050607080910111213141516171819\
2021222324252627282930313233343536373839\
4041424344454647484950515253545556575859\
6061626364656667686970717273747576777879\
8081828384858687888990919293949596979899";

/// Output text with a cursor.
#[derive(Debug)]
pub struct Text {
    bytes: Vec<u8>,
    len: usize,
}

impl Default for Text {
    fn default() -> Self {
        Self {
            bytes: vec![0; CHUNK + ROW_ROOM],
            len: 0,
        }
    }
}

impl Text {
    /// Whether a chunk's worth has gathered.
    pub fn is_full(&self) -> bool {
        self.len >= CHUNK
    }

    /// Makes sure a whole row fits past the cursor.
    pub fn make_room(&mut self) {
        if self.bytes.len() - self.len < ROW_ROOM {
            self.bytes.resize(self.len + ROW_ROOM, 0);
        }
    }

    /// The text written so far.
    pub fn as_bytes(&self) -> &[u8] {
        &self.bytes[..self.len]
    }

    /// Forgets the text (after it was written out).
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// Appends one byte.
    #[inline]
    pub fn push(&mut self, byte: u8) {
        self.bytes[self.len] = byte;
        self.len += 1;
    }

    /// Appends the last `count` decimal digits of `n`, zero-padded, written
    /// straight into place (no staging buffer to read back).
    #[inline]
    pub fn put_digits(&mut self, mut n: u64, count: usize) {
        let place = &mut self.bytes[self.len..self.len + count];
        for byte in place.iter_mut().rev() {
            *byte = b'0' + (n % 10) as u8;
            n /= 10;
        }
        self.len += count;
    }

    /// Appends the decimal digits of `n` (no leading zeros; `0` for 0),
    /// two at a time from a table.
    #[inline]
    pub fn put_decimal(&mut self, n: u64) {
        if n < 10 {
            self.push(b'0' + n as u8);
        } else if n < 100 {
            self.put_pair(n as usize);
        } else if n < 1000 {
            self.push(b'0' + (n / 100) as u8);
            self.put_pair((n % 100) as usize);
        } else {
            let mut digits = [0u8; 20];
            let mut at = digits.len();
            let mut rest = n;
            while rest >= 100 {
                at -= 2;
                let pair = (rest % 100) as usize * 2;
                digits[at..at + 2].copy_from_slice(&PAIRS[pair..pair + 2]);
                rest /= 100;
            }
            if rest >= 10 {
                at -= 2;
                let pair = rest as usize * 2;
                digits[at..at + 2].copy_from_slice(&PAIRS[pair..pair + 2]);
            } else {
                at -= 1;
                digits[at] = b'0' + rest as u8;
            }
            self.put_slice(&digits[at..]);
        }
    }

    /// Appends the two digits of `pair` (below 100), zero-padded.
    #[inline]
    pub fn put_pair(&mut self, pair: usize) {
        let k = pair * 2;
        self.bytes[self.len..self.len + 2].copy_from_slice(&PAIRS[k..k + 2]);
        self.len += 2;
    }

    /// Appends a slice. Pieces of 4 to 32 bytes (numbers, names) go as two
    /// overlapping copies of a fixed size, without a call to `memcpy`.
    #[inline]
    pub fn put_slice(&mut self, piece: &[u8]) {
        let n = piece.len();
        let place = &mut self.bytes[self.len..self.len + n];
        match n {
            4..=8 => {
                place[..4].copy_from_slice(&piece[..4]);
                place[n - 4..].copy_from_slice(&piece[n - 4..]);
            }
            9..=16 => {
                place[..8].copy_from_slice(&piece[..8]);
                place[n - 8..].copy_from_slice(&piece[n - 8..]);
            }
            17..=32 => {
                place[..16].copy_from_slice(&piece[..16]);
                place[n - 16..].copy_from_slice(&piece[n - 16..]);
            }
            _ => place.copy_from_slice(piece),
        }
        self.len += n;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_numbers_are_written_as_rust_writes_them() {
        let mut numbers: Vec<u64> = (0..2_000).collect();
        numbers.extend((0..64).map(|k| 1u64 << k));
        numbers.extend([99_999, 100_000, 999_999_999, u64::MAX - 1, u64::MAX]);
        for n in numbers {
            let mut out = Text::default();
            out.put_decimal(n);
            assert_eq!(out.as_bytes(), n.to_string().as_bytes());
        }
    }

    #[test]
    fn slices_of_every_length_are_appended_whole() {
        let source: Vec<u8> = (0..70u8).map(|b| b'!' + b).collect();
        let mut out = Text::default();
        let mut expected = Vec::new();
        for n in 0..source.len() {
            out.make_room();
            out.put_slice(&source[..n]);
            out.push(b'|');
            expected.extend_from_slice(&source[..n]);
            expected.push(b'|');
        }
        assert_eq!(out.as_bytes(), expected.as_slice());
    }
}
