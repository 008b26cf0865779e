use crate::{Block, SyntaxError};

/// Reads one line of a program into `block` (cleared first).
pub fn parse_line(_text: &[u8], line: u32, block: &mut Block) -> Result<(), SyntaxError> {
    block.clear();
    block.line = line;
    Ok(())
}
