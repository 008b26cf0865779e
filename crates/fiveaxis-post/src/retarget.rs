//! Retargeting: a program written for machine A (its machine axes, or
//! TCPC) becomes the same tool path on machine B.
//!
//! The source is run on A (with A's offsets); each of its blocks gives the
//! tool tip and direction in the part frame by forward kinematics on A
//! (`Segment::row`: the work offset and the setup error taken out). On B
//! the part zero sits at the output's origin (B's G54 plus its external
//! offset), so the tip in B's table frame is the part-frame tip plus that
//! origin, the direction unchanged. B's axes are the post's own
//! ([`crate::follow`]: continuous, singular passages, flips), linearised
//! to the tolerances as for any source; the time of each block is A's
//! (tip length over programmed feed). The tool is the same tool: B's
//! output is for the tool length A's block ran with.

use fiveaxis_control::Segment;
use fiveaxis_machine::Machine;

use crate::{Converter, Post, PostOptions};

/// Converts the segments of a run on `from` into a program for `to`.
pub fn retarget<'s>(
    from: &Machine,
    to: &Machine,
    segments: impl IntoIterator<Item = &'s Segment>,
    options: PostOptions,
) -> Post {
    let mut converter = Converter::retarget(from, to, options);
    for seg in segments {
        converter.push(seg);
    }
    converter.finish()
}
