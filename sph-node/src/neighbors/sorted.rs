//! Cell-sorted particle order for the WCSPH solver: the fluid particles are kept sorted by cell (then by id) in
//! memory, so that the particles of one cell, and of the cells of one grid row, are contiguous; wall particles
//! do not move, so they keep their order and are binned by cell once (again only when the grid changes).
//!
//! The grid ([`Grid`]) is the one [`super::CellList`] builds over all particles (fluid and walls): cell size = kernel
//! support, origin at the lower corner of the bounding box. A gather visits the 3 × 3 block of cells row by row
//! (bottom to top), cells left to right, and inside a cell the fluid particles by id, then the wall particles by
//! index, which is exactly the order of [`super::CellList::gather_into`] on the combined fluid-then-wall array:
//! every sum runs over the same neighbours in the same order, so the results do not depend on the memory order
//! (nor on the thread count).

use std::ops::Range;

use rayon::prelude::*;

use super::candidates::CandidateLists;
use super::cell_list::{ListChunk, NeighborList};
use super::grid::Grid;
use crate::kernel::CubicSpline;

/// Lower and upper corners of the bounding box of `x` (`None` when empty).
fn bounds(x: &[[f64; 2]]) -> Option<([f64; 2], [f64; 2])> {
    x.par_iter().with_min_len(4096).map(|p| (*p, *p)).reduce_with(|a, b| {
        (
            [a.0[0].min(b.0[0]), a.0[1].min(b.0[1])],
            [a.1[0].max(b.1[0]), a.1[1].max(b.1[1])],
        )
    })
}

/// Fluid sorted by cell, walls binned by cell, on the grid of the current positions.
#[derive(Clone, Debug, Default)]
pub struct SortedCells {
    grid: Grid,
    /// `fluid_start[c]..fluid_start[c + 1]`: the (sorted) fluid indices in cell c.
    fluid_start: Vec<u32>,
    /// Cell of each fluid particle, in sorted order.
    fluid_cell: Vec<u32>,
    /// Bounding box of the walls (fixed).
    wall_bounds: Option<([f64; 2], [f64; 2])>,
    /// The grid the walls are binned on.
    wall_grid: Option<Grid>,
    /// `wall_start[c]..wall_start[c + 1]` indexes `wall_sorted` for cell c.
    wall_start: Vec<u32>,
    /// Wall numbers sorted by cell, then number.
    wall_sorted: Vec<u32>,
    /// Cell of each wall particle.
    wall_cell: Vec<u32>,
    /// Cells of the fluid in the previous order (scratch).
    old_cell: Vec<u32>,
    /// Fill pointers of the counting sort (scratch).
    next: Vec<u32>,
}

impl SortedCells {
    /// For the fixed wall particles `wall_x`.
    pub fn new(wall_x: &[[f64; 2]]) -> Self {
        Self {
            wall_bounds: bounds(wall_x),
            ..Self::default()
        }
    }

    /// Bytes held (capacities).
    pub fn heap_bytes(&self) -> usize {
        4 * [
            &self.fluid_start,
            &self.fluid_cell,
            &self.wall_start,
            &self.wall_sorted,
            &self.wall_cell,
            &self.old_cell,
            &self.next,
        ]
        .iter()
        .map(|v| v.capacity())
        .sum::<usize>()
    }

    /// The first field in which these bins (read back from a checkpoint) differ from `built`, the bins sorted again
    /// from the same positions; `None` when they are the same. The counting sort's scratch (`old_cell`, `next`) is
    /// left out: it is written before it is read.
    pub fn differs_from(&self, built: &SortedCells) -> Option<&'static str> {
        let (a, b) = (self, built);
        [
            ("grid", a.grid == b.grid),
            ("fluid_start", a.fluid_start == b.fluid_start),
            ("fluid_cell", a.fluid_cell == b.fluid_cell),
            ("wall_bounds", a.wall_bounds == b.wall_bounds),
            ("wall_grid", a.wall_grid == b.wall_grid),
            ("wall_start", a.wall_start == b.wall_start),
            ("wall_sorted", a.wall_sorted == b.wall_sorted),
            ("wall_cell", a.wall_cell == b.wall_cell),
        ]
        .into_iter()
        .find_map(|(field, same)| (!same).then_some(field))
    }

    /// The grid of the last [`SortedCells::sort`].
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// Re-sorts the fluid for its positions `x` (in the current memory order) on the grid of cell size
    /// `cell_size` over fluid and walls. `ids` maps memory slots to particle ids and `slot` ids to slots; both are
    /// updated to the new order, which is by cell, then id. `src[n]` receives the old slot of the particle that
    /// goes to slot n (the caller moves its arrays accordingly).
    pub fn sort(
        &mut self,
        x: &[[f64; 2]],
        wall_x: &[[f64; 2]],
        cell_size: f64,
        ids: &mut [u32],
        slot: &mut [u32],
        src: &mut Vec<u32>,
    ) {
        let nf = x.len();
        let (lo, hi) = match (bounds(x), self.wall_bounds) {
            (Some(f), Some(w)) => (
                [f.0[0].min(w.0[0]), f.0[1].min(w.0[1])],
                [f.1[0].max(w.1[0]), f.1[1].max(w.1[1])],
            ),
            (Some(b), None) | (None, Some(b)) => b,
            (None, None) => ([0.0; 2], [0.0; 2]),
        };
        self.grid = Grid::covering(lo, hi, cell_size);
        let grid = self.grid;
        let n_cells = grid.n_cells();
        if self.wall_grid != Some(grid) {
            self.bin_walls(wall_x);
        }
        // Counting sort by cell, visiting the particles by id: stable in id.
        self.old_cell.clear();
        x.par_iter()
            .with_min_len(4096)
            .map(|&p| grid.cell_of(p) as u32)
            .collect_into_vec(&mut self.old_cell);
        self.fluid_start.clear();
        self.fluid_start.resize(n_cells + 1, 0);
        for &c in &self.old_cell {
            self.fluid_start[c as usize + 1] += 1;
        }
        for c in 0..n_cells {
            self.fluid_start[c + 1] += self.fluid_start[c];
        }
        self.next.clear();
        self.next.extend_from_slice(&self.fluid_start[..n_cells]);
        // Every entry of these is overwritten below.
        src.resize(nf, 0);
        self.fluid_cell.resize(nf, 0);
        for (id, s) in slot.iter_mut().enumerate() {
            let old = *s as usize;
            let c = self.old_cell[old];
            let n = self.next[c as usize];
            self.next[c as usize] += 1;
            src[n as usize] = old as u32;
            ids[n as usize] = id as u32;
            self.fluid_cell[n as usize] = c;
            *s = n;
        }
    }

    fn bin_walls(&mut self, wall_x: &[[f64; 2]]) {
        let grid = self.grid;
        let n_cells = grid.n_cells();
        self.wall_cell.clear();
        self.wall_cell.extend(wall_x.iter().map(|&p| grid.cell_of(p) as u32));
        self.wall_start.clear();
        self.wall_start.resize(n_cells + 1, 0);
        for &c in &self.wall_cell {
            self.wall_start[c as usize + 1] += 1;
        }
        for c in 0..n_cells {
            self.wall_start[c + 1] += self.wall_start[c];
        }
        self.next.clear();
        self.next.extend_from_slice(&self.wall_start[..n_cells]);
        self.wall_sorted.clear();
        self.wall_sorted.resize(wall_x.len(), 0);
        for (w, &c) in self.wall_cell.iter().enumerate() {
            let n = &mut self.next[c as usize];
            self.wall_sorted[*n as usize] = w as u32;
            *n += 1;
        }
        self.wall_grid = Some(grid);
    }

    /// Neighbour lists (self excluded) of the fluid particles `0..n_fluid` of `x` (sorted fluid first, then the
    /// walls), each with the ∇W factors of its pairs ([`ListChunk::grad`]);
    /// neighbours are the particles closer than `kernel.support()`, in the order of the module documentation.
    pub fn build_fluid_lists(&self, x: &[[f64; 2]], n_fluid: usize, kernel: &CubicSpline, list: &mut NeighborList) {
        // Values of `()`: no memory, nothing computed.
        self.build_fluid_lists_and_map(x, n_fluid, kernel, list, &mut Vec::new(), |_, _, _| ());
    }

    /// [`SortedCells::build_fluid_lists`], and `out[i] = f(i, neighbours of i, their ∇W factors)` for each fluid
    /// particle as soon as its list is built ([`NeighborList::build_and_map`]).
    pub fn build_fluid_lists_and_map<T, F>(
        &self,
        x: &[[f64; 2]],
        n_fluid: usize,
        kernel: &CubicSpline,
        list: &mut NeighborList,
        out: &mut Vec<T>,
        f: F,
    ) where
        T: Copy + Default + Send,
        F: Fn(usize, &[u32], &[f64]) -> T + Sync,
    {
        list.build_and_map(
            n_fluid,
            |i, chunk| self.gather_fluid(x, n_fluid, kernel, i, chunk),
            out,
            f,
        );
    }

    /// Appends the neighbours of fluid slot i, with their ∇W factors, to `chunk`.
    #[inline]
    fn gather_fluid(&self, x: &[[f64; 2]], n_fluid: usize, kernel: &CubicSpline, i: usize, chunk: &mut ListChunk) {
        let radius = kernel.support();
        let n = self.scan_block(x, n_fluid, radius * radius, i, chunk);
        chunk.push_candidates(n, kernel);
    }

    /// Lists (no ∇W factors) of the particles closer to each fluid particle `0..n_fluid` of `x` than `radius` (at
    /// most the cell size of the last sort), in the order of the module documentation: the candidates of a
    /// [`super::VerletCandidates`] list.
    pub fn build_candidate_lists(&self, x: &[[f64; 2]], n_fluid: usize, radius: f64, list: &mut CandidateLists) {
        list.build(n_fluid, n_fluid, |i, chunk| {
            let n = self.scan_block(x, n_fluid, radius * radius, i, chunk);
            chunk.reserve_pairs(n, false);
            chunk.idx.extend_from_slice(&chunk.cand_idx[..n]);
        });
    }

    /// Scans the 3 × 3 block of cells around fluid slot i, in gather order, into the chunk's candidate buffers;
    /// the first of them (their count returned) are the particles j ≠ i with |x_i − x_j|² < `r2max`.
    #[inline]
    fn scan_block(&self, x: &[[f64; 2]], n_fluid: usize, r2max: f64, i: usize, chunk: &mut ListChunk) -> usize {
        let d0 = self.grid.dims()[0];
        let xi = x[i];
        let ([y0, y1], [x0, x1]) = self.grid.block(self.fluid_cell[i] as usize);
        // Candidates of the block, in gather order.
        let mut total = 0;
        for y in y0..=y1 {
            let row = y * d0;
            total += (self.fluid_start[row + x1 + 1] - self.fluid_start[row + x0]) as usize;
            total += (self.wall_start[row + x1 + 1] - self.wall_start[row + x0]) as usize;
        }
        if chunk.cand_idx.len() < total {
            chunk.cand_idx.resize(total, 0);
            chunk.cand_d2.resize(total, 0.0);
        }
        // Branch-free compaction: every candidate is written, the count advances only for a neighbour. The
        // candidate buffers are taken as slices of the block's size, and a row's fluid as a slice of `x`, so that
        // the loop keeps their addresses in registers and checks no index of `x` (issue 20).
        let mut n = 0;
        let (cand_idx, cand_d2) = (&mut chunk.cand_idx[..total], &mut chunk.cand_d2[..total]);
        let mut visit = |j: usize, p: [f64; 2]| {
            let dx = xi[0] - p[0];
            let dy = xi[1] - p[1];
            let d2 = dx * dx + dy * dy;
            cand_idx[n] = j as u32;
            cand_d2[n] = d2;
            n += usize::from((d2 < r2max) & (j != i));
        };
        macro_rules! visit_fluid {
            ($a:expr, $b:expr) => {{
                let (a, b) = ($a as usize, $b as usize);
                for (j, &p) in (a..b).zip(&x[a..b]) {
                    visit(j, p);
                }
            }};
        }
        for y in y0..=y1 {
            let row = y * d0;
            if self.wall_start[row + x0] == self.wall_start[row + x1 + 1] {
                // No walls in this row of the block: its fluid is one contiguous range.
                visit_fluid!(self.fluid_start[row + x0], self.fluid_start[row + x1 + 1]);
                continue;
            }
            for c in row + x0..=row + x1 {
                visit_fluid!(self.fluid_start[c], self.fluid_start[c + 1]);
                for &w in &self.wall_sorted[self.wall_start[c] as usize..self.wall_start[c + 1] as usize] {
                    let j = n_fluid + w as usize;
                    visit(j, x[j]);
                }
            }
        }
        n
    }

    /// The sorted fluid slots in the 3 × 3 block of cells around wall particle `w`, one range per row (empty
    /// ranges where the block is clipped), in gather order.
    #[inline]
    pub fn fluid_near_wall(&self, w: usize) -> [Range<usize>; 3] {
        let d0 = self.grid.dims()[0];
        let ([y0, y1], [x0, x1]) = self.grid.block(self.wall_cell[w] as usize);
        let row = |y: usize| {
            if y > y1 {
                return 0..0;
            }
            self.fluid_start[y * d0 + x0] as usize..self.fluid_start[y * d0 + x1 + 1] as usize
        };
        [row(y0), row(y0 + 1), row(y0 + 2)]
    }
}
