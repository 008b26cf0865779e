//! A text buffer for formatted rows: bytes are written at a cursor into
//! storage that always has room for one more row, so that small pieces are
//! copied as fixed-size chunks instead of through `memcpy` calls.

/// Bytes gathered before the buffer asks to be written out.
pub const CHUNK: usize = 1 << 16;
/// Room kept free past the cursor when a row starts: more than the longest
/// row (16 columns of the longest number, 330 bytes, plus JSON keys).
pub const ROW_ROOM: usize = 1 << 13;

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

    /// Appends a slice.
    #[inline]
    pub fn put_slice(&mut self, piece: &[u8]) {
        self.bytes[self.len..self.len + piece.len()].copy_from_slice(piece);
        self.len += piece.len();
    }
}
