//! The block table of `fiveaxis view`, bounded: one entry per run of
//! segments of the same program line, motion and frame (the chords of a
//! spline block, the feeds of a cycle are one entry), with the line, the
//! motion, the frame in force and the time at which it ends. Past
//! [`MAX_BLOCKS`] entries neighbouring entries are merged in pairs, each
//! then standing for the blocks run since the one before it (the later
//! one's line, motion and frame), so that a page holds at most that many
//! whatever the program. Pure: no I/O, no machine.

use std::collections::VecDeque;

/// Most entries the table holds: a million are 21 MB of arrays, and a
/// timeline slider has far fewer positions.
pub const MAX_BLOCKS: usize = 1_000_000;

/// The table of entries, and the frames they name.
#[derive(Debug)]
pub struct BlockTable<F> {
    /// 1-based program line of each entry (its last block's).
    pub lines: Vec<u32>,
    /// Programmed time at which each entry ends, seconds.
    pub ends: Vec<f64>,
    /// Estimated time at which each entry ends, seconds (NaN until known).
    pub estimated: Vec<f64>,
    /// Motion code of each entry.
    pub motions: Vec<u8>,
    /// The frames the entries name.
    pub frames: Vec<F>,
    /// `[first entry, frame index]` for each change of frame.
    pub frame_runs: Vec<[usize; 2]>,
    /// For each segment whose estimated end is still to come, its entry.
    awaiting: VecDeque<usize>,
    /// Segments pushed.
    segments: u64,
    /// Entries merged in pairs at least once.
    merged: bool,
    budget: usize,
}

impl<F: PartialEq> BlockTable<F> {
    /// An empty table holding at most [`MAX_BLOCKS`] entries.
    pub fn new() -> Self {
        Self {
            lines: Vec::new(),
            ends: Vec::new(),
            estimated: Vec::new(),
            motions: Vec::new(),
            frames: Vec::new(),
            frame_runs: Vec::new(),
            awaiting: VecDeque::new(),
            segments: 0,
            merged: false,
            budget: MAX_BLOCKS,
        }
    }

    /// The same table holding at most `budget` entries (at least 2).
    #[cfg(test)]
    #[must_use]
    pub fn with_budget(mut self, budget: usize) -> Self {
        self.budget = budget.max(2);
        self
    }

    /// Entries.
    pub fn len(&self) -> usize {
        self.lines.len()
    }

    /// Segments pushed.
    pub fn segments(&self) -> u64 {
        self.segments
    }

    /// Whether entries were merged to keep within the budget.
    pub fn merged(&self) -> bool {
        self.merged
    }

    /// Adds the next segment, ending at programmed time `end`. Returns
    /// whether it starts a new frame.
    pub fn push(&mut self, line: u32, motion: u8, frame: F, end: f64) -> bool {
        self.segments += 1;
        let new_frame = self.frames.last() != Some(&frame);
        if new_frame {
            self.frames.push(frame);
        }
        let same =
            !new_frame && self.lines.last() == Some(&line) && self.motions.last() == Some(&motion);
        if same {
            if let Some(last) = self.ends.last_mut() {
                *last = end;
            }
        } else {
            if new_frame {
                self.frame_runs
                    .push([self.lines.len(), self.frames.len() - 1]);
            }
            self.lines.push(line);
            self.ends.push(end);
            self.estimated.push(f64::NAN);
            self.motions.push(motion);
        }
        self.awaiting.push_back(self.lines.len() - 1);
        if self.lines.len() > self.budget {
            self.merge_pairs();
        }
        new_frame
    }

    /// The estimated end of the next segment whose end was awaited.
    pub fn estimated_end(&mut self, time: f64) {
        if let Some(entry) = self.awaiting.pop_front() {
            self.estimated[entry] = time;
        }
    }

    /// Whether every segment's estimated end has come.
    pub fn fully_estimated(&self) -> bool {
        self.awaiting.is_empty() && !self.estimated.iter().any(|t| t.is_nan())
    }

    /// Merges entries `2i` and `2i + 1` into entry `i` (the later one's
    /// line, motion, ends), renumbering frame runs and awaited segments;
    /// frames no entry names any more go.
    fn merge_pairs(&mut self) {
        self.merged = true;
        let n = self.lines.len();
        for i in 0..n.div_ceil(2) {
            let from = (2 * i + 1).min(n - 1);
            self.lines[i] = self.lines[from];
            self.ends[i] = self.ends[from];
            self.estimated[i] = self.estimated[from];
            self.motions[i] = self.motions[from];
        }
        let m = n.div_ceil(2);
        self.lines.truncate(m);
        self.ends.truncate(m);
        self.estimated.truncate(m);
        self.motions.truncate(m);
        for entry in &mut self.awaiting {
            *entry /= 2;
        }
        // Frame runs that now start in the same entry: the later one is
        // in force at its end.
        let mut runs: Vec<[usize; 2]> = Vec::with_capacity(self.frame_runs.len());
        for [first, frame] in self.frame_runs.drain(..) {
            let first = first / 2;
            match runs.last_mut() {
                Some(last) if last[0] == first => last[1] = frame,
                _ => runs.push([first, frame]),
            }
        }
        // Frames no run names: dropped, the rest renumbered in order (the
        // last stays last: the one in force).
        let mut named = vec![false; self.frames.len()];
        for run in &runs {
            named[run[1]] = true;
        }
        if let Some(last) = named.last_mut() {
            *last = true;
        }
        let mut number = Vec::with_capacity(named.len());
        let mut kept = 0;
        for &n in &named {
            number.push(kept);
            kept += usize::from(n);
        }
        let mut k = 0;
        self.frames.retain(|_| {
            k += 1;
            named[k - 1]
        });
        for run in &mut runs {
            run[1] = number[run[1]];
        }
        self.frame_runs = runs;
    }
}

impl<F: PartialEq> Default for BlockTable<F> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_of_one_line_motion_and_frame_are_one_entry() {
        let mut t = BlockTable::new();
        assert!(t.push(5, 1, 'a', 1.0));
        assert!(!t.push(5, 1, 'a', 2.0));
        assert!(!t.push(5, 0, 'a', 3.0)); // another motion
        assert!(!t.push(6, 0, 'a', 4.0)); // another line
        assert!(t.push(6, 0, 'b', 5.0)); // another frame
        assert_eq!(t.lines, [5, 5, 6, 6]);
        assert_eq!(t.ends, [2.0, 3.0, 4.0, 5.0]);
        assert_eq!(t.motions, [1, 0, 0, 0]);
        assert_eq!(t.frames, ['a', 'b']);
        assert_eq!(t.frame_runs, [[0, 0], [3, 1]]);
        assert_eq!(t.segments(), 5);
        // The estimated ends come per segment: the last of an entry wins.
        for e in [1.5, 2.5, 3.5, 4.5] {
            t.estimated_end(e);
        }
        assert!(!t.fully_estimated());
        t.estimated_end(5.5);
        assert!(t.fully_estimated());
        assert_eq!(t.estimated, [2.5, 3.5, 4.5, 5.5]);
    }

    #[test]
    fn past_the_budget_entries_merge_in_pairs_and_stay_within_it() {
        let mut t = BlockTable::new().with_budget(8);
        for k in 0..1000u32 {
            // A new frame every 10 blocks.
            t.push(k + 1, (k % 2) as u8, k / 10, f64::from(k + 1));
            assert!(t.len() <= 8, "{} entries", t.len());
        }
        assert!(t.merged());
        // The last entry ends with the program, on its last line.
        assert_eq!(t.ends.last(), Some(&1000.0));
        assert_eq!(t.lines.last(), Some(&1000));
        assert!(t.ends.windows(2).all(|w| w[0] < w[1]));
        // Frame runs start in increasing entries and name existing
        // frames; the frame in force is the last.
        assert!(t.frame_runs.windows(2).all(|w| w[0][0] < w[1][0]));
        assert!(t.frame_runs.iter().all(|r| r[1] < t.frames.len()));
        assert_eq!(t.frames.last(), Some(&99));
        assert!(t.frames.len() <= t.frame_runs.len() + 1);
        // Estimated ends still land on the entries of their segments.
        for k in 0..1000 {
            t.estimated_end(f64::from(k + 1) * 2.0);
        }
        assert!(t.fully_estimated());
        assert_eq!(t.estimated.last(), Some(&2000.0));
    }
}
