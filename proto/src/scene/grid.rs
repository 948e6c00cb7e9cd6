//! FEM grid numbering of a `[[solid]]` rectangle: node (i, j) is `j * nx + i`, its reference position, and the
//! node and element counts that follow (fem-node meshes in this order; probes and clamps find nodes by it).

use super::schema::{BoxSpec, ElementKind, Scene, SolidSpec};

impl SolidSpec {
    /// Number of grid nodes along x and y.
    pub fn grid_size(&self) -> [usize; 2] {
        [self.divisions[0] as usize + 1, self.divisions[1] as usize + 1]
    }

    /// Reference position of grid node (i, j); node numbering is `j * nx + i`.
    pub fn grid_node(&self, i: usize, j: usize) -> [f64; 2] {
        let [nx, ny] = self.grid_size();
        let fx = i as f64 / (nx - 1) as f64;
        let fy = j as f64 / (ny - 1) as f64;
        [
            self.min[0] + (self.max[0] - self.min[0]) * fx,
            self.min[1] + (self.max[1] - self.min[1]) * fy,
        ]
    }

    /// All grid nodes in numbering order.
    pub fn grid_nodes(&self) -> Vec<[f64; 2]> {
        let [nx, ny] = self.grid_size();
        (0..ny)
            .flat_map(|j| (0..nx).map(move |i| (i, j)))
            .map(|(i, j)| self.grid_node(i, j))
            .collect()
    }

    /// Whether a grid node lies in `b` (bounds included), found per axis without listing the nodes: the grid is
    /// the product of two rows of coordinates, each increasing with its index (a binary search for the first at or
    /// above the box's lower bound).
    pub fn has_node_in(&self, b: &BoxSpec) -> bool {
        let n = self.grid_size();
        (0..2).all(|k| {
            let at = |i: usize| {
                if k == 0 {
                    self.grid_node(i, 0)[0]
                } else {
                    self.grid_node(0, i)[1]
                }
            };
            let (mut lo, mut hi) = (0, n[k]);
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                (lo, hi) = if at(mid) < b.min[k] { (mid + 1, hi) } else { (lo, mid) };
            }
            lo < n[k] && at(lo) <= b.max[k]
        })
    }

    /// Number of elements the mesh will have.
    pub fn element_count(&self) -> usize {
        let cells = self.divisions[0] as usize * self.divisions[1] as usize;
        match self.element {
            ElementKind::Quad4 => cells,
            ElementKind::Tri3 => 2 * cells,
        }
    }
}

impl Scene {
    /// Total FE nodes and elements.
    pub fn fem_counts(&self) -> (usize, usize) {
        self.solids.iter().fold((0, 0), |(n, e), s| {
            let [nx, ny] = s.grid_size();
            (n + nx * ny, e + s.element_count())
        })
    }
}
