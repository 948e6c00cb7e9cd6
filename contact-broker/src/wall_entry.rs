//! A structure gone into a tank wall (`summary.json` `solid_in_wall`): the net under the walls' contact.
//!
//! The walls (`[[wall]]`) are the fluid's boundary particles; the structure node knows nothing of them. The broker
//! puts the structure's surface nodes back on a wall's surface after each contact pass (`wall_contact.rs`), so a node
//! ends a step inside a wall by at most its displacement over that step. One found deeper has gone past that
//! contact: a node off the surface, or one fast enough to cross half a spacing in a step (before `wall_contact.rs`,
//! every solid that reached a wall went through it: a free block dropped onto the floor drove the water to 1.8
//! times the energy it can release; docs/VALIDATION.md, 2026-12-07 thirty-third). So the broker looks at the
//! structure's nodes at every output time and notes the first one found inside a wall by more than half a fluid
//! spacing that was not within that distance of a wall where the scene put it (a clamped end may start on a wall's
//! face or in it).

use cosim_proto::messages::FemMesh;
use cosim_proto::scene::Scene;
use serde::{Deserialize, Serialize};

use cosim_proto::walls::{deepest, depth, wall_boxes, WallBox};

/// The first structure node found inside a wall.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WallEntry {
    /// The output time it was found at [s].
    pub t: f64,
    /// Its solid's name.
    pub solid: String,
    /// The node (its index in the structure's mesh).
    pub node: u32,
    /// The wall's index in the scene (`wall[k]`).
    pub wall: usize,
    /// How far inside the wall's box it was [m].
    pub depth: f64,
}

/// The walls' boxes and which nodes are watched.
#[derive(Clone, Debug)]
pub struct WallWatch {
    walls: Vec<WallBox>,
    /// Half the fluid spacing: deeper than this is inside.
    margin: f64,
    /// Per node: watched (not within `margin` of a wall where the scene put it).
    watched: Vec<bool>,
}

impl WallWatch {
    /// The watch for the scene's walls over the structure `mesh`; `None` without walls, fluid or nodes.
    pub fn new(scene: &Scene, mesh: &FemMesh) -> Option<Self> {
        let fluid = scene.fluid.as_ref()?;
        if scene.walls.is_empty() || mesh.nodes.is_empty() {
            return None;
        }
        let walls = wall_boxes(scene);
        let margin = 0.5 * fluid.spacing;
        let watched = mesh.nodes.iter().map(|&p| deepest(p, &walls) < -margin).collect();
        Some(Self { walls, margin, watched })
    }

    /// The first watched node at positions `x` (the mesh's order) deeper than the margin inside a wall, at output
    /// time `t`; `None` where there is none.
    pub fn observe(&self, t: f64, x: &[[f64; 2]], mesh: &FemMesh) -> Option<WallEntry> {
        x.iter().zip(&self.watched).enumerate().find_map(|(k, (&p, &watched))| {
            if !watched {
                return None;
            }
            let (wall, d) = self
                .walls
                .iter()
                .enumerate()
                .map(|(w, &b)| (w, depth(p, b)))
                .find(|&(_, d)| d > self.margin)?;
            let solid = mesh
                .node_solid
                .get(k)
                .and_then(|&s| mesh.solid_names.get(s as usize))
                .cloned()
                .unwrap_or_default();
            Some(WallEntry {
                t,
                solid,
                node: k as u32,
                wall,
                depth: d,
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wall_contact::tests::{mesh, scene};

    #[test]
    fn a_node_deeper_than_half_a_spacing_in_a_wall_is_found_once_it_goes_there() {
        // One node on the floor's face (not watched), one above it.
        let m = mesh(vec![[0.5, 0.0], [0.5, 0.05]], Vec::new());
        let watch = WallWatch::new(&scene(), &m).expect("walls and a fluid");
        assert!(watch.observe(0.0, &m.nodes, &m).is_none());
        // The node on the face sinks in: it started on the wall, so it is not watched.
        assert!(watch.observe(0.01, &[[0.5, -0.02], [0.5, 0.05]], &m).is_none());
        // The upper node 4 mm into the floor: within half a spacing (5 mm), not yet.
        assert!(watch.observe(0.02, &[[0.5, 0.0], [0.5, -0.004]], &m).is_none());
        let e = watch.observe(0.03, &[[0.5, 0.0], [0.5, -0.006]], &m).expect("6 mm in");
        assert_eq!((e.t, e.solid.as_str(), e.node, e.wall), (0.03, "block", 1, 0));
        assert!((e.depth - 0.006).abs() < 1e-15, "{}", e.depth);
    }
}
