//! The check of a structure node's registration (topic `fem/mesh`): its arrays agree, its ids are in range, and its
//! geometry is one the contact and the frames can use (`docs/PROTOCOL.md` §7, "Contents").

use super::{Check, Result};
use crate::messages::{FemMesh, Segment};

impl FemMesh {
    /// Check the mesh a structure node registered (topic `fem/mesh`).
    pub fn validate(&self) -> Result {
        let c = Check("fem/mesh");
        let (nodes, solids) = (self.nodes.len(), self.solid_names.len());
        if nodes == 0 {
            return Err(c.fail("nodes", &[], "0 entries", "a structure node needs nodes"));
        }
        if solids == 0 {
            return Err(c.fail("solid_names", &[], "0 entries", "a structure node needs a solid"));
        }
        c.points("nodes", &self.nodes)?;
        c.len("masses", self.masses.len(), nodes, "node")?;
        for (i, m) in self.masses.iter().enumerate() {
            c.positive("masses", &[i], *m)?;
        }
        c.len("node_solid", self.node_solid.len(), nodes, "node")?;
        for (i, s) in self.node_solid.iter().enumerate() {
            c.id("node_solid", &[i], *s, solids, "solids")?;
        }
        c.len("cell_solid", self.cell_solid.len(), self.cells.len(), "cell")?;
        for (e, cell) in self.cells.iter().enumerate() {
            if !(3..=4).contains(&cell.len()) {
                return Err(c.fail(
                    "cells",
                    &[e],
                    format!("{} node ids", cell.len()),
                    "a cell has 3 or 4 nodes",
                ));
            }
            for (k, id) in cell.iter().enumerate() {
                c.id("cells", &[e, k], *id, nodes, "nodes")?;
            }
        }
        self.check_cells(c)?;
        for (e, s) in self.cell_solid.iter().enumerate() {
            c.id("cell_solid", &[e], *s, solids, "solids")?;
        }
        for (i, Segment { a, b }) in self.interface.iter().enumerate() {
            c.id("interface", &[i, 0], *a, nodes, "nodes")?;
            c.id("interface", &[i, 1], *b, nodes, "nodes")?;
            if a == b {
                return Err(c.fail(
                    "interface",
                    &[i],
                    format!("{a}→{b}"),
                    "a segment joins two different nodes",
                ));
            }
        }
        self.check_boundary(c)?;
        self.check_segments_once(c)?;
        let mut listed: Vec<Option<usize>> = vec![None; nodes];
        for (i, id) in self.fixed.iter().enumerate() {
            c.id("fixed", &[i], *id, nodes, "nodes")?;
            // In range: checked on the line above.
            if let Some(first) = listed.get_mut(*id as usize).and_then(|f| f.replace(i)) {
                return Err(c.fail(
                    "fixed",
                    &[i],
                    id,
                    format!("node {id} is listed twice (also fixed[{first}])"),
                ));
            }
        }
        c.positive("dt_stable", &[], self.dt_stable)
    }

    /// Each cell (ids already checked) joins different nodes and goes counter-clockwise round an area > 0 (its
    /// signed area by the shoelace formula), as PROTOCOL §5 says a cell's nodes run. The frames draw the cells, and
    /// a cell listed as `[0, 0, 0, 0]`, or one turned inside out, drew nothing or a solid inside out while the run
    /// ended `ok` (found 2026-12-06 by the sweep of hostile external nodes, D15).
    fn check_cells(&self, c: Check) -> Result {
        for (e, cell) in self.cells.iter().enumerate() {
            if let Some(k) = (1..cell.len()).find(|&k| cell[..k].contains(&cell[k])) {
                return Err(c.fail(
                    "cells",
                    &[e],
                    format!("{cell:?}"),
                    format!("node {} is in it twice: a cell joins different nodes", cell[k]),
                ));
            }
            let area = self.signed_area(cell.iter().copied());
            if area.is_nan() || area <= 0.0 {
                return Err(c.fail(
                    "cells",
                    &[e],
                    format!("{cell:?}"),
                    format!(
                        "its nodes go clockwise or enclose nothing (signed area {area:e} m²): a cell's nodes go \
                         counter-clockwise"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The signed area Σ (x_k × x_k+1)/2 of the polygon through `ids` (in range), > 0 counter-clockwise.
    fn signed_area(&self, ids: impl Iterator<Item = u32> + Clone) -> f64 {
        let at = |id: u32| self.nodes.get(id as usize).copied().unwrap_or([f64::NAN; 2]);
        let next = ids.clone().cycle().skip(1);
        ids.zip(next).map(|(a, b)| shoelace(&at(a), &at(b))).sum()
    }

    /// The contact's geometry (ids already checked): every segment has a length, and each solid's segments go
    /// counter-clockwise round it (its signed area Σ (x_a × x_b)/2 over them is > 0), so that their normals point out
    /// of it. A clockwise boundary from an outside node ran `ok` with the contact pushing the water into the solid and
    /// 0.66 of the water's energy made; segments of zero length, the same (found 2026-12-06 by a sweep of hostile
    /// external nodes).
    fn check_boundary(&self, c: Check) -> Result {
        // Per solid: the signed area its segments enclose, and whether any segment starts on it.
        let mut area = vec![(0.0, false); self.solid_names.len()];
        for (i, Segment { a, b }) in self.interface.iter().enumerate() {
            let (Some(pa), Some(pb)) = (self.nodes.get(*a as usize), self.nodes.get(*b as usize)) else {
                continue;
            };
            if pa == pb {
                return Err(c.fail(
                    "interface",
                    &[i],
                    format!("{a}→{b}"),
                    format!("a segment of zero length (both nodes at {pa:?})"),
                ));
            }
            let solid = self.node_solid.get(*a as usize);
            let Some(slot) = solid.and_then(|&s| area.get_mut(s as usize)) else {
                continue;
            };
            slot.1 = true;
            if self.node_solid.get(*b as usize) == solid {
                slot.0 += shoelace(pa, pb);
            }
        }
        for ((s, &(a, has)), name) in area.iter().enumerate().zip(&self.solid_names) {
            if has && (a.is_nan() || a <= 0.0) {
                return Err(c.fail(
                    "interface",
                    &[],
                    format!("the segments of solid {s} ({name})"),
                    format!(
                        "they go clockwise round it or enclose nothing (signed area {a:e} m²): they must go \
                         counter-clockwise, so that their normals point out of the solid"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// No segment is listed twice, either way round: the contact would test a particle against it twice, and
    /// `particle_particle` lay its points twice (a duplicated boundary ran `ok`; the sweep of hostile external nodes,
    /// D15). Both ways round is a sheet of no thickness, which no solid's boundary is.
    fn check_segments_once(&self, c: Check) -> Result {
        let mut order: Vec<(u32, u32, usize)> = (self.interface.iter().enumerate())
            .map(|(i, s)| (s.a.min(s.b), s.a.max(s.b), i))
            .collect();
        order.sort_unstable();
        for w in order.windows(2) {
            if let [(a, b, first), (a2, b2, i)] = *w {
                if (a, b) == (a2, b2) {
                    let Segment { a, b } = self.interface[i];
                    return Err(c.fail(
                        "interface",
                        &[i],
                        format!("{a}→{b}"),
                        format!("the segment of interface[{first}] again: each boundary segment is listed once"),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// The edge a → b's term of a polygon's signed area, (x_a × x_b)/2.
fn shoelace(a: &[f64; 2], b: &[f64; 2]) -> f64 {
    0.5 * (a[0] * b[1] - a[1] * b[0])
}
