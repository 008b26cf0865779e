//! The stock as the page shows it: the model's rays merged into a coarse
//! grid of cells, each at its highest material, and how that grid
//! changes along the run, so that the viewer shows the stock of the
//! moment the slider is at.
//!
//! The history is a start grid and, per snapshot, the cells that changed
//! since the one before. Snapshots are taken every `every` blocks, only
//! where the stock was cut since (the model says which rays), and there
//! are at most [`MAX_SNAPSHOTS`] of them: when there would be more,
//! neighbours merge (the later one's block is kept, so that the stock
//! never shows a cut before the tool made it) and `every` doubles. The
//! changes held are bounded by [`MAX_CHANGES`] the same way.

use fiveaxis_stock::Stock;
use fiveaxis_stock::dexel::Dexels;
use serde_json::{Value, json};

/// Snapshots held at most.
pub const MAX_SNAPSHOTS: usize = 256;

/// Changed cells held at most over all snapshots (8 bytes each in the
/// page).
pub const MAX_CHANGES: usize = 2_000_000;

/// The coarse grid: `k` × `k` rays per cell.
#[derive(Clone, Copy, Debug)]
struct Grid {
    k: usize,
    nx: usize,
    ny: usize,
}

impl Grid {
    fn of(d: &Dexels, cells: usize) -> Self {
        let k = d.nx.max(d.ny).div_ceil(cells).max(1);
        Self {
            k,
            nx: d.nx.div_ceil(k),
            ny: d.ny.div_ceil(k),
        }
    }

    /// The highest material of cell (`ci`, `cj`), above the model's
    /// origin; NaN when it holds none.
    fn top(&self, d: &Dexels, ci: usize, cj: usize) -> f32 {
        let mut top = f32::NAN;
        for j in cj * self.k..((cj + 1) * self.k).min(d.ny) {
            for i in ci * self.k..((ci + 1) * self.k).min(d.nx) {
                if let Some(span) = d.spans(j * d.nx + i).last() {
                    top = if top.is_nan() {
                        span[1]
                    } else {
                        top.max(span[1])
                    };
                }
            }
        }
        top
    }
}

/// The stock over a run, for the page.
#[derive(Debug)]
pub struct StockHistory {
    grid: Grid,
    /// The grid's description for the viewer.
    model: Value,
    /// Each cell's top when the history began, in the table frame.
    pub start: Vec<f32>,
    /// Each cell's top now (above the model's origin).
    current: Vec<f32>,
    origin_z: f32,
    /// Changed cells, snapshot after snapshot.
    pub cells: Vec<u32>,
    /// Their new tops, in the table frame (NaN: no material left).
    pub values: Vec<f32>,
    /// Per snapshot: the last block it includes, and the end of its
    /// changes in `cells`.
    snapshots: Vec<(u32, u32)>,
    every: u32,
    since: u32,
    /// Scratch for merging: the snapshot that last saw each cell.
    seen: Vec<u32>,
}

impl StockHistory {
    /// The history of `stock` from now on, on a grid of at most `cells`
    /// cells along its longer side.
    pub fn start(stock: &mut Stock, cells: usize) -> Self {
        stock.take_touched();
        let d = &stock.dexels;
        let grid = Grid::of(d, cells);
        let mut current = vec![f32::NAN; grid.nx * grid.ny];
        let mut base = f32::INFINITY;
        for cj in 0..grid.ny {
            for ci in 0..grid.nx {
                current[cj * grid.nx + ci] = grid.top(d, ci, cj);
            }
        }
        for k in 0..d.nx * d.ny {
            if let Some(first) = d.spans(k).first() {
                base = base.min(first[0]);
            }
        }
        let oz = d.origin.z;
        let base = if base.is_finite() {
            f64::from(base) + oz
        } else {
            oz
        };
        let origin_z = oz as f32;
        let model = json!({
            "origin": [d.origin.x, d.origin.y],
            "cell": d.cell * grid.k as f64,
            "nx": grid.nx,
            "ny": grid.ny,
            "base": base,
        });
        let start = current.iter().map(|t| t + origin_z).collect();
        Self {
            grid,
            model,
            start,
            seen: vec![u32::MAX; current.len()],
            current,
            origin_z,
            cells: Vec::new(),
            values: Vec::new(),
            snapshots: Vec::new(),
            every: 1,
            since: 0,
        }
    }

    /// After a block: whether it is time for a snapshot.
    pub fn due(&mut self) -> bool {
        self.since += 1;
        if self.since >= self.every {
            self.since = 0;
            true
        } else {
            false
        }
    }

    /// The changes since the last snapshot, as the stock stands after
    /// block `block` (its index in the page); at the run's end too.
    pub fn snapshot(&mut self, stock: &mut Stock, block: u32) {
        let Some(touched) = stock.take_touched() else {
            return;
        };
        let (g, d) = (self.grid, &stock.dexels);
        let before = self.cells.len();
        for cj in touched.j.0 / g.k..touched.j.1.div_ceil(g.k).min(g.ny) {
            for ci in touched.i.0 / g.k..touched.i.1.div_ceil(g.k).min(g.nx) {
                let at = cj * g.nx + ci;
                let top = g.top(d, ci, cj);
                if top.to_bits() != self.current[at].to_bits() {
                    self.current[at] = top;
                    self.cells.push(at as u32);
                    self.values.push(top + self.origin_z);
                }
            }
        }
        if self.cells.len() == before {
            return;
        }
        self.snapshots.push((block, self.cells.len() as u32));
        while self.snapshots.len() > MAX_SNAPSHOTS
            || (self.cells.len() > MAX_CHANGES && self.snapshots.len() > 1)
        {
            self.merge_pairs();
        }
    }

    /// Merges snapshots two by two (the later one's block), keeping of
    /// each cell its last change within a pair.
    fn merge_pairs(&mut self) {
        let mut cells = Vec::with_capacity(self.cells.len());
        let mut values = Vec::with_capacity(self.values.len());
        let mut snapshots = Vec::with_capacity(self.snapshots.len().div_ceil(2));
        let mut start = 0usize;
        for (p, pair) in self.snapshots.chunks(2).enumerate() {
            let (block, end) = pair[pair.len() - 1];
            let end = end as usize;
            let first = cells.len();
            // Backwards: the first change met of a cell is its last.
            for e in (start..end).rev() {
                let cell = self.cells[e] as usize;
                if self.seen[cell] != p as u32 {
                    self.seen[cell] = p as u32;
                    cells.push(self.cells[e]);
                    values.push(self.values[e]);
                }
            }
            cells[first..].reverse();
            values[first..].reverse();
            snapshots.push((block, cells.len() as u32));
            start = end;
        }
        self.seen.fill(u32::MAX);
        self.cells = cells;
        self.values = values;
        self.snapshots = snapshots;
        self.every = self.every.saturating_mul(2);
    }

    /// The grid and the snapshots for the page's `stock_model`.
    pub fn model(&self) -> Value {
        let mut model = self.model.clone();
        model["snapshots"] = json!(self.snapshots);
        model
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fiveaxis_machine::Vec3;

    /// A 10 × 10 × 10 block at 0.5 mm.
    fn block() -> Stock {
        let (min, max) = (Vec3::zeros(), Vec3::new(10.0, 10.0, 10.0));
        let mut d = Dexels::empty(&min, &max, 0.5).expect("a grid");
        d.fill_box(&min, &max);
        Stock::new(d, None, 0.05)
    }

    /// Drills a 0.6 mm hole at (`x`, `y`) down to `z`, as a cut does.
    fn dig(stock: &mut Stock, x: f64, y: f64, z: f64) {
        use fiveaxis_stock::solid::{Piece, Posed};
        let drill = [Piece::Frustum {
            a0: 0.0,
            a1: 20.0,
            r0: 0.3,
            r1: 0.3,
        }];
        let posed = Posed::new(&drill, &Vec3::new(x, y, z), &Vec3::z());
        stock.cut(&posed, 1, false);
    }

    /// A block done: a snapshot when one is due.
    fn after_block(h: &mut StockHistory, stock: &mut Stock, block: u32) {
        if h.due() {
            h.snapshot(stock, block);
        }
    }

    /// The tops replayed from the history: the start and every change.
    fn replay(h: &StockHistory) -> Vec<f32> {
        let mut tops = h.start.clone();
        for (cell, value) in h.cells.iter().zip(&h.values) {
            tops[*cell as usize] = *value;
        }
        tops
    }

    /// The tops of the stock computed directly.
    fn direct(stock: &Stock, cells: usize) -> Vec<f32> {
        let d = &stock.dexels;
        let g = Grid::of(d, cells);
        let mut tops = Vec::new();
        for cj in 0..g.ny {
            for ci in 0..g.nx {
                tops.push(g.top(d, ci, cj) + d.origin.z as f32);
            }
        }
        tops
    }

    fn same(a: &[f32], b: &[f32]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
    }

    #[test]
    fn the_replayed_history_is_the_stock_left() {
        let mut stock = block();
        // A cell per ray: nearly every hole changes the grid.
        let mut h = StockHistory::start(&mut stock, 20);
        // And a twin stock cut the same, 3 × 3 rays a cell.
        let mut coarse = block();
        let mut h3 = StockHistory::start(&mut coarse, 7);
        let mut seed = 7u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for block in 0..2000u32 {
            let (x, y, z) = (10.0 * next(), 10.0 * next(), 10.0 * next());
            dig(&mut stock, x, y, z);
            after_block(&mut h, &mut stock, block);
            dig(&mut coarse, x, y, z);
            after_block(&mut h3, &mut coarse, block);
        }
        h.snapshot(&mut stock, 2000);
        h3.snapshot(&mut coarse, 2000);
        assert_eq!(h3.grid.k, 3);
        assert!(same(&replay(&h3), &direct(&coarse, 7)));
        assert!(same(&replay(&h), &direct(&stock, 20)));
        // Merged down to the bound, blocks in order, changes in range.
        assert!(h.snapshots.len() <= MAX_SNAPSHOTS && h.snapshots.len() > 1);
        assert!(
            h.snapshots
                .windows(2)
                .all(|w| w[0].0 < w[1].0 && w[0].1 <= w[1].1)
        );
        assert_eq!(
            h.snapshots.last().map(|s| s.1 as usize),
            Some(h.cells.len())
        );
        assert!(h.every > 1);
    }

    #[test]
    fn a_snapshot_shows_the_stock_at_its_block() {
        let mut stock = block();
        let mut h = StockHistory::start(&mut stock, 20);
        let untouched = replay(&h);
        dig(&mut stock, 2.25, 2.25, 5.0);
        after_block(&mut h, &mut stock, 0);
        let first = direct(&stock, 20);
        dig(&mut stock, 7.75, 7.75, 3.0);
        after_block(&mut h, &mut stock, 1);
        // A block that cuts nothing takes no snapshot.
        after_block(&mut h, &mut stock, 2);
        assert_eq!(h.snapshots.len(), 2);
        let end = h.snapshots[0].1 as usize;
        let mut tops = h.start.clone();
        for e in 0..end {
            tops[h.cells[e] as usize] = h.values[e];
        }
        assert!(same(&tops, &first));
        assert!(!same(&tops, &untouched));
        assert!(same(&replay(&h), &direct(&stock, 20)));
    }
}
