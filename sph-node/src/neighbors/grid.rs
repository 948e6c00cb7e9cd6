//! A uniform grid of square cells over a bounding box: the cells of [`super::CellList`] and of
//! [`super::SortedCells`] (cell size = kernel support 2h, cells numbered row-major, x fastest).

/// A uniform grid over a bounding box.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Grid {
    origin: [f64; 2],
    cell_size: f64,
    dims: [usize; 2],
}

impl Grid {
    /// Cells of size `cell_size` covering the box `lo`–`hi`, origin at `lo`.
    pub fn covering(lo: [f64; 2], hi: [f64; 2], cell_size: f64) -> Self {
        Self {
            origin: lo,
            cell_size,
            dims: [0, 1].map(|k| ((hi[k] - lo[k]) / cell_size).floor() as usize + 1),
        }
    }

    /// Cells along x and y.
    #[inline]
    pub fn dims(&self) -> [usize; 2] {
        self.dims
    }

    /// Number of cells.
    pub fn n_cells(&self) -> usize {
        self.dims[0] * self.dims[1]
    }

    /// Cell coordinates of `p` (clamped to the grid).
    #[inline]
    pub fn coords(&self, p: [f64; 2]) -> [usize; 2] {
        [0, 1].map(|k| {
            // `as usize` truncates, which is the floor for c ≥ 0, and c < 0 (or NaN) clamps to 0 either way: no
            // `floor`, a library call on baseline x86-64, for every particle at every sort (issue 20)
            let c = (p[k] - self.origin[k]) / self.cell_size;
            (c.max(0.0) as usize).min(self.dims[k] - 1)
        })
    }

    /// Cell index of `p` (row-major, x fastest).
    #[inline]
    pub fn cell_of(&self, p: [f64; 2]) -> usize {
        let [cx, cy] = self.coords(p);
        cy * self.dims[0] + cx
    }

    /// The 3 × 3 block around cell `c`: rows `y0..=y1`, columns `x0..=x1` (clipped at the grid's edges).
    #[inline]
    pub fn block(&self, c: usize) -> ([usize; 2], [usize; 2]) {
        let (cx, cy) = (c % self.dims[0], c / self.dims[0]);
        (
            [cy.saturating_sub(1), (cy + 1).min(self.dims[1] - 1)],
            [cx.saturating_sub(1), (cx + 1).min(self.dims[0] - 1)],
        )
    }
}
