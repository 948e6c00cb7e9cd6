//! Structured meshes of the rectangular solids of a scene.
//!
//! Grid node `(i, j)` of a solid is `first + j·nx + i` ([`SolidSpec::grid_nodes`] order), solids numbered
//! consecutively in scene order.
//! * `quad4`: cell `(i, j)` is `[n(i,j), n(i+1,j), n(i+1,j+1), n(i,j+1)]`, counter-clockwise.
//! * `tri3`: each cell is split along one diagonal, alternating in a checkerboard: cells with `i + j` even use the
//!   diagonal `n(i,j)–n(i+1,j+1)`, odd ones `n(i+1,j)–n(i,j+1)`. The alternation keeps the mesh symmetric under
//!   reflection, so its bending stiffness has no preferred direction (a fixed diagonal stiffens one sense of
//!   shear more than the other).

use cosim_proto::messages::Segment;
use cosim_proto::scene::{ElementKind, SolidSpec};

/// Connectivity of one cell, global node ids, counter-clockwise.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cell {
    /// A quadrilateral.
    Quad([u32; 4]),
    /// A triangle.
    Tri([u32; 3]),
}

impl Cell {
    /// Node ids.
    pub fn nodes(&self) -> &[u32] {
        match self {
            Cell::Quad(n) => n,
            Cell::Tri(n) => n,
        }
    }
}

/// The mesh of one solid.
#[derive(Clone, Debug, PartialEq)]
pub struct SolidMesh {
    /// Reference node positions (local order; global id = `first + index`).
    pub nodes: Vec<[f64; 2]>,
    /// Cells with global node ids.
    pub cells: Vec<Cell>,
    /// Outer boundary, counter-clockwise: the solid lies on the left of each a→b, outward normal `(dy, −dx)/L`.
    pub boundary: Vec<Segment>,
    /// Whether each node lies inside one of the solid's `fixed` boxes.
    pub fixed: Vec<bool>,
}

/// Meshes one solid; its first node gets global id `first`.
pub fn structured_mesh(spec: &SolidSpec, first: u32) -> SolidMesh {
    let nodes = spec.grid_nodes();
    let [nx, ny] = spec.grid_size();
    let n = |i: usize, j: usize| first + (j * nx + i) as u32;
    let mut cells = Vec::with_capacity(spec.element_count());
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let (a, b, c, d) = (n(i, j), n(i + 1, j), n(i + 1, j + 1), n(i, j + 1));
            match spec.element {
                ElementKind::Quad4 => cells.push(Cell::Quad([a, b, c, d])),
                ElementKind::Tri3 if (i + j) % 2 == 0 => {
                    cells.push(Cell::Tri([a, b, c]));
                    cells.push(Cell::Tri([a, c, d]));
                }
                ElementKind::Tri3 => {
                    cells.push(Cell::Tri([a, b, d]));
                    cells.push(Cell::Tri([b, c, d]));
                }
            }
        }
    }
    let mut boundary = Vec::with_capacity(2 * (nx + ny - 2));
    let mut push = |a: u32, b: u32| boundary.push(Segment { a, b });
    for i in 0..nx - 1 {
        push(n(i, 0), n(i + 1, 0));
    }
    for j in 0..ny - 1 {
        push(n(nx - 1, j), n(nx - 1, j + 1));
    }
    for i in (0..nx - 1).rev() {
        push(n(i + 1, ny - 1), n(i, ny - 1));
    }
    for j in (0..ny - 1).rev() {
        push(n(0, j + 1), n(0, j));
    }
    let fixed = nodes
        .iter()
        .map(|&p| spec.fixed.iter().any(|b| b.contains(p)))
        .collect();
    SolidMesh {
        nodes,
        cells,
        boundary,
        fixed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cosim_proto::scene::{BoxSpec, MaterialModel, MaterialSpec};

    fn spec(element: ElementKind) -> SolidSpec {
        SolidSpec {
            name: "bar".into(),
            min: [0.0, 0.0],
            max: [3.0, 1.0],
            divisions: [3, 2],
            element,
            material: MaterialSpec {
                model: MaterialModel::LinearElastic,
                density: 1000.0,
                youngs_modulus: 1e6,
                poisson_ratio: 0.3,
            },
            fixed: vec![BoxSpec {
                min: [-0.1, -0.1],
                max: [0.1, 1.1],
            }],
            damping: 0.0,
            mesh_damping: None,
        }
    }

    fn signed_area(nodes: &[[f64; 2]], cell: &[u32], first: u32) -> f64 {
        let p: Vec<[f64; 2]> = cell.iter().map(|&k| nodes[(k - first) as usize]).collect();
        (0..p.len())
            .map(|i| {
                let (a, b) = (p[i], p[(i + 1) % p.len()]);
                0.5 * (a[0] * b[1] - a[1] * b[0])
            })
            .sum()
    }

    #[test]
    fn counts_orientation_and_fixed_nodes() {
        for (kind, cells) in [(ElementKind::Quad4, 6), (ElementKind::Tri3, 12)] {
            let s = spec(kind);
            let m = structured_mesh(&s, 10);
            assert_eq!(m.nodes.len(), 12);
            assert_eq!(m.cells.len(), cells);
            assert_eq!(m.cells.len(), s.element_count());
            let total: f64 = m.cells.iter().map(|c| signed_area(&m.nodes, c.nodes(), 10)).sum();
            assert!((total - 3.0).abs() < 1e-12);
            for c in &m.cells {
                assert!(
                    signed_area(&m.nodes, c.nodes(), 10) > 0.0,
                    "{c:?} is not counter-clockwise"
                );
            }
            assert_eq!(m.fixed.iter().filter(|&&f| f).count(), 3);
            assert!(m.fixed[0] && m.fixed[4] && m.fixed[8] && !m.fixed[1]);
        }
    }

    #[test]
    fn boundary_is_closed_counter_clockwise_with_outward_normals() {
        let s = spec(ElementKind::Quad4);
        let m = structured_mesh(&s, 10);
        assert_eq!(m.boundary.len(), 2 * (3 + 2));
        let pos = |k: u32| m.nodes[(k - 10) as usize];
        let mut area = 0.0;
        for (k, seg) in m.boundary.iter().enumerate() {
            assert_eq!(seg.b, m.boundary[(k + 1) % m.boundary.len()].a, "chain broken at {k}");
            let (a, b) = (pos(seg.a), pos(seg.b));
            area += 0.5 * (a[0] * b[1] - a[1] * b[0]);
            // Outward normal (dy, −dx) points away from the centre (1.5, 0.5).
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let mid = [0.5 * (a[0] + b[0]) - 1.5, 0.5 * (a[1] + b[1]) - 0.5];
            assert!(dy * mid[0] - dx * mid[1] > 0.0, "segment {k} normal points inward");
        }
        assert!((area - 3.0).abs() < 1e-12, "boundary encloses {area}");
    }
}
