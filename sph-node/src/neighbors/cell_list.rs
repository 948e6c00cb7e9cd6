//! Cell-linked list (cell size = kernel support 2h), built in O(N) by a counting sort of the particles by cell
//! index, so that the particles of one cell, and of neighbouring cells along x, lie next to each other in the
//! sorted index array.
//!
//! The gather visits the 3 × 3 block of cells in a fixed order (row by row, bottom to top) and, inside a cell,
//! the particles in increasing index (the counting sort is stable), so every particle's neighbour list has the
//! same order whatever the thread count.

use rayon::prelude::*;

/// Particles binned on a uniform grid.
#[derive(Clone, Debug, Default)]
pub struct CellList {
    origin: [f64; 2],
    cell_size: f64,
    dims: [usize; 2],
    /// `cell_start[c]..cell_start[c + 1]` indexes `sorted` for cell c.
    cell_start: Vec<u32>,
    /// Particle indices sorted by cell (stable).
    sorted: Vec<u32>,
}

impl CellList {
    /// Bins `positions` on cells of size `cell_size` covering their bounding box.
    ///
    /// Positions must be finite (the solver checks this before building).
    pub fn new(positions: &[[f64; 2]], cell_size: f64) -> Self {
        let mut list = Self::default();
        list.rebuild(positions, cell_size);
        list
    }

    /// Re-bins `positions`, reusing the allocations.
    pub fn rebuild(&mut self, positions: &[[f64; 2]], cell_size: f64) {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in positions {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if positions.is_empty() {
            lo = [0.0; 2];
            hi = [0.0; 2];
        }
        self.origin = lo;
        self.cell_size = cell_size;
        self.dims = [0, 1].map(|k| ((hi[k] - lo[k]) / cell_size).floor() as usize + 1);
        let n_cells = self.dims[0] * self.dims[1];
        // Counting sort by cell index: O(N + cells), stable.
        self.cell_start.clear();
        self.cell_start.resize(n_cells + 1, 0);
        let cells: Vec<u32> = positions.par_iter().map(|&p| self.cell_of(p) as u32).collect();
        for &c in &cells {
            self.cell_start[c as usize + 1] += 1;
        }
        for c in 0..n_cells {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        let mut next: Vec<u32> = self.cell_start[..n_cells].to_vec();
        self.sorted.clear();
        self.sorted.resize(positions.len(), 0);
        for (i, &c) in cells.iter().enumerate() {
            let slot = &mut next[c as usize];
            self.sorted[*slot as usize] = i as u32;
            *slot += 1;
        }
    }

    fn coords(&self, p: [f64; 2]) -> [usize; 2] {
        [0, 1].map(|k| {
            let c = ((p[k] - self.origin[k]) / self.cell_size).floor();
            (c.max(0.0) as usize).min(self.dims[k] - 1)
        })
    }

    fn cell_of(&self, p: [f64; 2]) -> usize {
        let [cx, cy] = self.coords(p);
        cy * self.dims[0] + cx
    }

    /// Particle indices in cell order (the memory order of the gathers).
    pub fn sorted(&self) -> &[u32] {
        &self.sorted
    }

    /// Appends to `out` every particle j ≠ `exclude` with |x_j − `query`| < `radius` (`radius` ≤ cell size),
    /// in the fixed order described in the module documentation.
    pub fn gather_into(
        &self,
        positions: &[[f64; 2]],
        query: [f64; 2],
        exclude: Option<usize>,
        radius: f64,
        out: &mut Vec<u32>,
    ) {
        if self.sorted.is_empty() {
            return;
        }
        let r2 = radius * radius;
        let [cx, cy] = self.coords(query);
        let y0 = cy.saturating_sub(1);
        let y1 = (cy + 1).min(self.dims[1] - 1);
        let x0 = cx.saturating_sub(1);
        let x1 = (cx + 1).min(self.dims[0] - 1);
        for y in y0..=y1 {
            // Cells x0..=x1 of one row are contiguous in `sorted`.
            let a = self.cell_start[y * self.dims[0] + x0] as usize;
            let b = self.cell_start[y * self.dims[0] + x1 + 1] as usize;
            for &j in &self.sorted[a..b] {
                if Some(j as usize) == exclude {
                    continue;
                }
                let p = positions[j as usize];
                let dx = query[0] - p[0];
                let dy = query[1] - p[1];
                if dx * dx + dy * dy < r2 {
                    out.push(j);
                }
            }
        }
    }

    /// Neighbour lists (self excluded) of the first `n_query` particles of `positions`, built in parallel.
    pub fn neighbor_list(&self, positions: &[[f64; 2]], n_query: usize, radius: f64) -> NeighborList {
        let lists: Vec<Vec<u32>> = (0..n_query)
            .into_par_iter()
            .map(|i| {
                let mut out = Vec::with_capacity(32);
                self.gather_into(positions, positions[i], Some(i), radius, &mut out);
                out
            })
            .collect();
        let mut start = Vec::with_capacity(n_query + 1);
        start.push(0);
        let mut idx = Vec::with_capacity(lists.iter().map(Vec::len).sum());
        for l in &lists {
            idx.extend_from_slice(l);
            start.push(idx.len());
        }
        NeighborList { start, idx }
    }
}

/// Compressed per-particle neighbour lists (self excluded), each in the fixed gather order.
#[derive(Clone, Debug, Default)]
pub struct NeighborList {
    start: Vec<usize>,
    idx: Vec<u32>,
}

impl NeighborList {
    /// Neighbours of particle i.
    #[inline]
    pub fn of(&self, i: usize) -> &[u32] {
        &self.idx[self.start[i]..self.start[i + 1]]
    }

    /// Number of particles with a list.
    pub fn len(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    /// True when no particle has a list.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Total number of (ordered) pairs.
    pub fn pair_count(&self) -> usize {
        self.idx.len()
    }
}
