//! Uniform cell list over axis-aligned boxes, so contact detection costs O(particles + masters) rather than
//! their product. Built in two passes into one CSR array: no per-cell allocation, and each cell lists its items in
//! ascending index order, so every query — and everything built on it — is deterministic.

use super::geometry::Vec2;

/// Cells at most this many times the number of items (plus a floor), so a huge, sparse domain cannot allocate a
/// huge grid: the cell size grows instead.
const CELLS_PER_ITEM: usize = 16;
const MIN_CELL_BUDGET: usize = 4096;

/// Items binned by the cells their boxes overlap.
#[derive(Clone, Debug, Default)]
pub(crate) struct CellGrid {
    origin: Vec2,
    cell: f64,
    nx: usize,
    ny: usize,
    /// `start[c]..start[c + 1]` indexes `items` for cell `c`.
    start: Vec<u32>,
    items: Vec<u32>,
    /// Fill cursor of the second pass (kept to reuse its allocation).
    fill: Vec<u32>,
    /// Each item's box, evaluated once a build (kept to reuse its allocation).
    boxes: Vec<(Vec2, Vec2)>,
}

impl CellGrid {
    /// Bins `count` items whose boxes are `bounds(i) = (min, max)`, with cells at least `min_cell` wide.
    /// Boxes must be finite (callers validate their inputs).
    pub fn build(&mut self, count: usize, min_cell: f64, bounds: impl Fn(usize) -> (Vec2, Vec2)) {
        self.start.clear();
        self.items.clear();
        self.nx = 0;
        self.ny = 0;
        if count == 0 {
            return;
        }
        // Each box once: the bounding box and both passes below read them.
        let mut boxes = std::mem::take(&mut self.boxes);
        boxes.clear();
        boxes.extend((0..count).map(bounds));
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for &(a, b) in &boxes {
            for k in 0..2 {
                lo[k] = lo[k].min(a[k]);
                hi[k] = hi[k].max(b[k]);
            }
        }
        let ext = [hi[0] - lo[0], hi[1] - lo[1]];
        let budget = (CELLS_PER_ITEM * count).max(MIN_CELL_BUDGET) as f64;
        let mut cell = min_cell.max(f64::MIN_POSITIVE);
        // Grow the cell until the grid fits the budget (the +1 accounts for partial cells on each axis).
        let fits = |c: f64| ((ext[0] / c).floor() + 1.0) * ((ext[1] / c).floor() + 1.0) <= budget;
        if !fits(cell) {
            cell = cell
                .max((ext[0] * ext[1] / budget).sqrt())
                .max(ext[0].max(ext[1]) / budget);
            while !fits(cell) {
                cell *= 1.5;
            }
        }
        self.origin = lo;
        self.cell = cell;
        self.nx = (ext[0] / cell).floor() as usize + 1;
        self.ny = (ext[1] / cell).floor() as usize + 1;
        let ncell = self.nx * self.ny;

        // Pass 1: count items per cell; pass 2: fill (items visited in ascending order, so cells stay sorted).
        self.start.resize(ncell + 1, 0);
        for &bx in &boxes {
            let (x0, x1, y0, y1) = self.range(bx);
            for iy in y0..=y1 {
                for ix in x0..=x1 {
                    self.start[iy * self.nx + ix + 1] += 1;
                }
            }
        }
        for c in 0..ncell {
            self.start[c + 1] += self.start[c];
        }
        self.items.resize(self.start[ncell] as usize, 0);
        self.fill.clear();
        self.fill.extend_from_slice(&self.start[..ncell]);
        for (i, &bx) in boxes.iter().enumerate() {
            let (x0, x1, y0, y1) = self.range(bx);
            for iy in y0..=y1 {
                for ix in x0..=x1 {
                    let c = iy * self.nx + ix;
                    self.items[self.fill[c] as usize] = i as u32;
                    self.fill[c] += 1;
                }
            }
        }
        self.boxes = boxes;
    }

    /// Cell index ranges covered by a box (clamped to the grid). `max(0.0)` then the truncating cast is
    /// `floor().max(0.0)` then the cast for every input (NaN included), without a call to `floor`.
    fn range(&self, (a, b): (Vec2, Vec2)) -> (usize, usize, usize, usize) {
        let cx = |v: f64| (((v - self.origin[0]) / self.cell).max(0.0) as usize).min(self.nx - 1);
        let cy = |v: f64| (((v - self.origin[1]) / self.cell).max(0.0) as usize).min(self.ny - 1);
        (cx(a[0]), cx(b[0]), cy(a[1]), cy(b[1]))
    }

    /// The items whose boxes overlap the cell holding `p` (empty outside the grid or for a non-finite `p`).
    #[inline]
    pub fn query(&self, p: Vec2) -> &[u32] {
        &self.items[self.query_range(p)]
    }

    /// Where [`CellGrid::query`]'s items lie in [`CellGrid::items`], so that a table in the same order (one entry
    /// an item of a cell) can be read alongside.
    #[inline]
    pub fn query_range(&self, p: Vec2) -> std::ops::Range<usize> {
        if self.nx == 0 {
            return 0..0;
        }
        let fx = (p[0] - self.origin[0]) / self.cell;
        let fy = (p[1] - self.origin[1]) / self.cell;
        // Written so that NaN fails the test.
        if !(fx >= 0.0 && fy >= 0.0 && fx < self.nx as f64 && fy < self.ny as f64) {
            return 0..0;
        }
        let c = fy as usize * self.nx + fx as usize;
        self.start[c] as usize..self.start[c + 1] as usize
    }

    /// Every cell's items, cell after cell (what [`CellGrid::query_range`] indexes).
    pub fn items(&self) -> &[u32] {
        &self.items
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn query_returns_overlapping_boxes_in_index_order() {
        let boxes = [
            ([0.0, 0.0], [1.0, 1.0]),
            ([5.0, 5.0], [6.0, 6.0]),
            ([0.5, 0.5], [5.5, 5.5]),
        ];
        let mut g = CellGrid::default();
        g.build(boxes.len(), 1.0, |i| boxes[i]);
        assert_eq!(g.query([0.6, 0.6]), &[0, 2]);
        assert_eq!(g.query([5.5, 5.2]), &[1, 2]);
        assert_eq!(g.query([3.0, 3.0]), &[2]);
        assert!(g.query([-1.0, 0.0]).is_empty());
        assert!(g.query([100.0, 0.0]).is_empty());
        assert!(g.query([f64::NAN, 0.0]).is_empty());
    }

    #[test]
    fn sparse_domain_grows_the_cell_instead_of_the_grid() {
        let boxes = [([0.0, 0.0], [0.1, 0.1]), ([1.0e6, 1.0e6], [1.0e6 + 0.1, 1.0e6 + 0.1])];
        let mut g = CellGrid::default();
        g.build(boxes.len(), 0.1, |i| boxes[i]);
        assert!(g.nx * g.ny <= MIN_CELL_BUDGET);
        assert_eq!(g.query([0.05, 0.05]), &[0]);
        assert_eq!(g.query([1.0e6 + 0.05, 1.0e6 + 0.05]), &[1]);
    }
}
