//! The tank's walls as a boundary condition of the structure: a node that a sub-step's drift takes into a wall is
//! put back on the nearest point of the walls' surface and loses its velocity into it (frictionless, perfectly
//! inelastic; the rule and which nodes it applies to: `cosim_proto::walls`).
//!
//! Applied inside the sub-steps so that a node enters a wall by at most one sub-step's drift. Applied once a coupling
//! step instead (the broker did, 2026-12-07 to 12-08), a node pressed into the wall went on in for the step's several
//! sub-steps while the compression above it grew, and was put back against that force at the step's end: work done
//! on the solid each step. An elastic block dropped onto the floor at 0.93 m/s left it ringing with 13 times the
//! kinetic energy it fell with (docs/CORRECTIONS.md "The walls inside the structure's sub-steps").

use cosim_proto::messages::Segment;
use cosim_proto::scene::Scene;
use cosim_proto::walls::Walls;

/// The walls and the nodes they stop.
#[derive(Clone, Debug, PartialEq)]
pub struct WallStop {
    walls: Walls,
    /// The stopped nodes (on the outer boundary), ascending.
    nodes: Vec<usize>,
}

impl WallStop {
    /// The walls of `scene` against the nodes at `reference` (clamped where `fixed`, of solid `node_solid`) that lie on
    /// the solids' outer `boundary` (an inner node reaches a wall only after the surface in front of it, which the
    /// walls stop); `None` without walls (or a fluid, whose boundary they are) or without a node to stop.
    pub fn new(
        scene: &Scene,
        reference: &[[f64; 2]],
        fixed: &[bool],
        node_solid: &[u32],
        boundary: &[Segment],
    ) -> Option<Self> {
        let walls = Walls::new(scene)?;
        let stopped = walls.stopped(reference, fixed, node_solid);
        let mut nodes: Vec<usize> = boundary
            .iter()
            .flat_map(|s| [s.a as usize, s.b as usize])
            .filter(|&k| stopped.get(k).copied().unwrap_or(false))
            .collect();
        nodes.sort_unstable();
        nodes.dedup();
        (!nodes.is_empty()).then_some(Self { walls, nodes })
    }

    /// Puts every stopped node of `x` that lies inside a wall back on its surface, taking off the component of its
    /// velocity `v` into the wall.
    pub fn apply(&self, x: &mut [[f64; 2]], v: &mut [[f64; 2]]) {
        for &k in &self.nodes {
            let (Some(p), Some(u)) = (x.get_mut(k), v.get_mut(k)) else {
                continue;
            };
            if let Some((dx, dv)) = self.walls.stop(*p, *u) {
                *p = [p[0] + dx[0], p[1] + dx[1]];
                *u = [u[0] + dv[0], u[1] + dv[1]];
            }
        }
    }
}
