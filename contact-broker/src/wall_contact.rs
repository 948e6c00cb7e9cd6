//! The walls stop the structure: its surface nodes put back on a wall's face, their velocity into it taken off.
//!
//! The walls (`[[wall]]`) are the fluid's boundary particles; the structure node knows nothing of them. Without
//! this a solid that reaches a wall passed through it, the water caught between the two squeezed without bound (a
//! free block dropped onto the floor drove the fluid to 1.8 times the energy the water can release and ended the run
//! `unstable`; docs/VALIDATION.md, 2026-12-07 thirty-third). After each contact pass, every interface node that is
//! neither clamped nor inside a wall where the scene put it, and that ends the step inside a wall (its position
//! and velocity with the pass's corrections), is moved to the nearest point of the walls' surface and loses the
//! velocity component into it: a frictionless, perfectly inelastic contact with an immovable body,
//! the one the particle–element contact applies to a particle against a fixed master (`DESIGN.md` §4.5), here with
//! the wall as the master. The walls take the momentum, as fixed nodes do. A node enters a wall by at most its
//! displacement over one coupling step before it is put back.
//!
//! Not stopped: a node inside a wall from the start (a clamped end's neighbours), and a node of a clamped solid
//! within half a fluid spacing of a wall from the start. The shipped gate hangs from its wall with its free end on the
//! floor's face, and dipped up to 3.6 µm into it; stopping that end there (the floor a frictionless prop under the
//! tip) made energy: at Δx = 4 mm to 0.05 s, 0.137 of the water's releasable energy against 0.0004 without, 19 %
//! more fluid steps, the tip_x at 0.05 s 1.5 % further (why was not found). So a clamped structure the scene puts
//! against a wall moves as before; one that comes to a wall, and every free solid (resting on the floor from the
//! start: held within 0.6 µm for 0.1 s, no energy made), is stopped. Every shipped scene computes the same bits with
//! and without it.

use cosim_proto::messages::{Correction, FemMesh, FemState};
use cosim_proto::scene::Scene;

/// The walls' boxes and which interface nodes they stop.
#[derive(Clone, Debug)]
pub struct WallContact {
    walls: Vec<WallBox>,
    /// Per interface node (in the order of the interface's ids): stopped by the walls (not fixed, not inside a wall
    /// in the mesh as the scene made it).
    stopped: Vec<bool>,
    /// How far from a candidate exit point the union's outside is looked for [m].
    hair: f64,
    /// Scratch of [`WallContact::correct`]: the pass's corrections summed per interface node, (dx, dv).
    moved_by: Vec<([f64; 2], [f64; 2])>,
}

/// A wall's box, (lower corner, upper corner).
pub(crate) type WallBox = ([f64; 2], [f64; 2]);

/// The scene's walls as boxes, in its order (`wall[k]`).
pub(crate) fn wall_boxes(scene: &Scene) -> Vec<WallBox> {
    scene.walls.iter().map(|w| (w.min, w.max)).collect()
}

/// How far `p` lies inside the box `lo`–`hi` (0 on its boundary, negative outside).
pub(crate) fn depth(p: [f64; 2], (lo, hi): WallBox) -> f64 {
    (p[0] - lo[0]).min(hi[0] - p[0]).min(p[1] - lo[1]).min(hi[1] - p[1])
}

/// The largest [`depth`] of `p` in any of `walls` (−∞ without walls).
pub(crate) fn deepest(p: [f64; 2], walls: &[WallBox]) -> f64 {
    walls.iter().map(|&w| depth(p, w)).fold(f64::NEG_INFINITY, f64::max)
}

/// The nearest point to `p` on the boundary of the union of the `walls` when `p` lies in one of them (their closed
/// boxes), `None` outside them or on that boundary. Walls may touch or overlap (a floor and a side wall meet in a
/// corner), so a box's face may lie inside the union: the candidates are `p` projected on every face of every box
/// and every box's corners, and one counts only where a point a hair away from it, along an axis or a diagonal,
/// lies outside every wall. Ties go to the first candidate (boxes in the scene's order, faces −x, +x, −y, +y, then
/// the corners).
fn exit_point(p: [f64; 2], walls: &[WallBox], hair: f64) -> Option<[f64; 2]> {
    if walls.iter().all(|&w| depth(p, w) < 0.0) {
        return None;
    }
    let outside = |q: [f64; 2]| walls.iter().all(|&w| depth(q, w) < 0.0);
    let on_boundary = |c: [f64; 2]| {
        [
            [1.0, 0.0],
            [-1.0, 0.0],
            [0.0, 1.0],
            [0.0, -1.0],
            [1.0, 1.0],
            [1.0, -1.0],
            [-1.0, 1.0],
            [-1.0, -1.0],
        ]
        .iter()
        .any(|d: &[f64; 2]| outside([c[0] + hair * d[0], c[1] + hair * d[1]]))
    };
    let mut best: Option<([f64; 2], f64)> = None;
    for &(lo, hi) in walls {
        let (cx, cy) = (p[0].clamp(lo[0], hi[0]), p[1].clamp(lo[1], hi[1]));
        let candidates = [
            [lo[0], cy],
            [hi[0], cy],
            [cx, lo[1]],
            [cx, hi[1]],
            lo,
            [hi[0], lo[1]],
            [lo[0], hi[1]],
            hi,
        ];
        for c in candidates {
            let d2 = (c[0] - p[0]).powi(2) + (c[1] - p[1]).powi(2);
            if best.is_none_or(|(_, b)| d2 < b) && on_boundary(c) {
                best = Some((c, d2));
            }
        }
    }
    best.filter(|&(_, d2)| d2 > 0.0).map(|(c, _)| c)
}

impl WallContact {
    /// The walls of `scene` against the interface nodes `ids` of `mesh`; `None` without walls or nodes to stop.
    pub fn new(scene: &Scene, mesh: &FemMesh, ids: &[u32]) -> Option<Self> {
        let spacing = scene.fluid.as_ref()?.spacing;
        if scene.walls.is_empty() {
            return None;
        }
        let walls = wall_boxes(scene);
        // The solids with a clamp.
        let held: Vec<bool> = (0..mesh.solid_names.len())
            .map(|k| {
                mesh.fixed
                    .iter()
                    .any(|&f| mesh.node_solid.get(f as usize) == Some(&(k as u32)))
            })
            .collect();
        let stopped: Vec<bool> = ids
            .iter()
            .map(|&id| {
                let Some(&p) = mesh.nodes.get(id as usize) else {
                    return false;
                };
                let fixed = mesh.fixed.contains(&id);
                let solid_held = mesh
                    .node_solid
                    .get(id as usize)
                    .is_some_and(|&k| held.get(k as usize) == Some(&true));
                let deepest = deepest(p, &walls);
                // Inside a wall from the start (a clamped end's neighbours): left as the scene put it. A clamped
                // solid's node within half a spacing of a wall from the start (the gate's free end on the floor's
                // face) too: stopping it there made energy (the module docs).
                !fixed && deepest <= 0.0 && !(solid_held && deepest >= -0.5 * spacing)
            })
            .collect();
        // A hair: far below any wall's size, far above the coordinates' round-off.
        let scale = walls.iter().fold(1.0f64, |m, (lo, hi)| {
            m.max(lo[0].abs()).max(lo[1].abs()).max(hi[0].abs()).max(hi[1].abs())
        });
        let hair = 1e-9 * scale;
        stopped.iter().any(|&s| s).then_some(Self {
            walls,
            stopped,
            hair,
            moved_by: Vec::new(),
        })
    }

    /// The corrections that put the interface nodes of `state` (positions and velocities at the end of the step,
    /// plus the contact pass's `corrections` to them) back out of the walls, appended to `corrections`; how many
    /// nodes it moved.
    pub fn correct(&mut self, state: &FemState, corrections: &mut Vec<Correction>) -> usize {
        // The pass's corrections per node in one walk over them (`state.ids` ascending, as the interface reports
        // them), not one walk per node: this runs after every contact pass.
        self.moved_by.clear();
        self.moved_by.resize(state.ids.len(), ([0.0; 2], [0.0; 2]));
        for c in corrections.iter() {
            if let Ok(k) = state.ids.binary_search(&c.id) {
                let (dx, dv) = &mut self.moved_by[k];
                *dx = [dx[0] + c.dx[0], dx[1] + c.dx[1]];
                *dv = [dv[0] + c.dv[0], dv[1] + c.dv[1]];
            }
        }
        let mut moved = 0;
        for (k, &id) in state.ids.iter().enumerate() {
            if !self.stopped.get(k).copied().unwrap_or(false) {
                continue;
            }
            // The node as the next step will start it: the pass's corrections to it added.
            let (dx, dv) = self.moved_by[k];
            let (p, u) = (state.x[k], state.v[k]);
            let (p, u) = ([p[0] + dx[0], p[1] + dx[1]], [u[0] + dv[0], u[1] + dv[1]]);
            let Some(c) = exit_point(p, &self.walls, self.hair) else {
                continue;
            };
            // Out along the shortest way, the velocity into the wall (against that way) taken off.
            let dx = [c[0] - p[0], c[1] - p[1]];
            let len = dx[0].hypot(dx[1]);
            let n = [dx[0] / len, dx[1] / len];
            let into = (u[0] * n[0] + u[1] * n[1]).min(0.0);
            let dv = [-into * n[0], -into * n[1]];
            if dx != [0.0; 2] || dv != [0.0; 2] {
                corrections.push(Correction { id, dx, dv, face: None });
                moved += 1;
            }
        }
        moved
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// One solid, `block`, of unit masses at `nodes`, clamped at `fixed`.
    pub(crate) fn mesh(nodes: Vec<[f64; 2]>, fixed: Vec<u32>) -> FemMesh {
        let n = nodes.len();
        FemMesh {
            solid_names: vec!["block".into()],
            nodes,
            masses: vec![1.0; n],
            node_solid: vec![0; n],
            cells: Vec::new(),
            cell_solid: Vec::new(),
            interface: Vec::new(),
            fixed,
            dt_stable: 1e-6,
        }
    }

    fn state(x: Vec<[f64; 2]>, v: Vec<[f64; 2]>) -> FemState {
        FemState {
            ids: (0..x.len() as u32).collect(),
            x,
            v,
            substeps: 1,
            dt_stable: 1e-6,
            compute_seconds: 0.0,
            snapshot: None,
        }
    }

    /// A floor (to x = 1 m) and a side wall beyond it, a fluid of spacing 0.01 m, the solid `block`.
    pub(crate) fn scene() -> Scene {
        let text = r#"
version = 1
[run]
name = "t"
end_time = 0.1
output_interval = 0.01
[fluid]
density = 1000.0
spacing = 0.01
[[fluid.block]]
min = [0.0, 0.0]
max = [0.1, 0.1]
[[wall]]
min = [-0.03, -0.03]
max = [1.0, 0.0]
[[wall]]
min = [1.0, -0.03]
max = [1.03, 0.6]
[[solid]]
name = "block"
min = [0.5, 0.0]
max = [0.6, 0.05]
divisions = [2, 1]
element = "quad4"
material = { model = "linear_elastic", density = 1000.0, youngs_modulus = 1e6, poisson_ratio = 0.3 }
"#;
        cosim_proto::scene::parse("t.toml", text, &[]).unwrap()
    }

    #[test]
    fn a_node_in_a_wall_is_put_on_its_face_and_stops_going_in() {
        // Node 0 on the floor's face, 1 above it, 2 fixed, 3 inside the floor from the start. Clamped by node 2, the
        // solid's node 0 on the face is left alone too (the gate's free end on the floor); free, it is stopped.
        let nodes = vec![[0.5, 0.0], [0.5, 0.05], [0.6, 0.0], [0.7, -0.01]];
        let held = WallContact::new(&scene(), &mesh(nodes.clone(), vec![2]), &[0, 1, 2, 3]).expect("node 1 to stop");
        assert_eq!(held.stopped, [false, true, false, false]);
        let m = mesh(nodes, Vec::new());
        let mut walls = WallContact::new(&scene(), &m, &[0, 1, 2, 3]).expect("three nodes to stop");
        assert_eq!(walls.stopped, [true, true, true, false]);
        // Node 0 2 mm into the floor, going down and right; the pass moved it 1 mm further down already.
        let mut c = vec![Correction {
            id: 0,
            dx: [0.0, -0.001],
            dv: [0.0, -0.1],
            face: None,
        }];
        let s = state(
            vec![[0.5, -0.002], [0.5, 0.05], [0.6, 0.01], [0.7, -0.02]],
            vec![[0.3, -1.0], [0.0, -1.0], [0.0, -1.0], [0.0, -1.0]],
        );
        assert_eq!(walls.correct(&s, &mut c), 1);
        assert_eq!(c.len(), 2);
        // Back on the face (y = 0 after both corrections), no velocity into the floor, the tangential kept.
        assert_eq!(c[1].id, 0);
        assert!((c[1].dx[1] - 0.003).abs() < 1e-15 && c[1].dx[0] == 0.0, "{:?}", c[1]);
        assert!((c[1].dv[1] - 1.1).abs() < 1e-15 && c[1].dv[0] == 0.0, "{:?}", c[1]);
        // A node leaving the wall keeps its velocity: only the position is put back.
        let mut c = Vec::new();
        let s = state(
            vec![[0.5, -0.002], [0.5, 0.05], [0.6, 0.0], [0.7, -0.01]],
            vec![[0.0, 0.5]; 4],
        );
        assert_eq!(walls.correct(&s, &mut c), 1);
        assert_eq!((c[0].dx, c[0].dv), ([0.0, 0.002], [0.0, 0.0]));
        // In the corner of the floor and the side wall, inside the side wall: out to the corner they make (the side
        // wall's face there lies against the floor), the velocity into the corner taken off.
        let mut c = Vec::new();
        let s = state(
            vec![[1.002, -0.001], [0.5, 0.05], [0.6, 0.01], [0.7, -0.01]],
            vec![[1.0, -1.0]; 4],
        );
        walls.correct(&s, &mut c);
        let end = [1.002 + c[0].dx[0], -0.001 + c[0].dx[1]];
        assert!((end[0] - 1.0).abs() < 1e-15 && end[1].abs() < 1e-15, "{end:?}");
        let speed = [1.0 + c[0].dv[0], -1.0 + c[0].dv[1]];
        // n = (−2, 1)/√5 from the node to the corner; (1, −1)·n = −3/√5 taken off along n.
        assert!(
            (speed[0] - (1.0 - 6.0 / 5.0)).abs() < 1e-12 && (speed[1] - (-1.0 + 3.0 / 5.0)).abs() < 1e-12,
            "{speed:?}"
        );
        // On the shared face of the two walls, below the floor's top: inside their union, put out too.
        let mut c = Vec::new();
        let s = state(
            vec![[1.0, -0.001], [0.5, 0.05], [0.6, 0.01], [0.7, -0.01]],
            vec![[0.0, -1.0]; 4],
        );
        walls.correct(&s, &mut c);
        assert_eq!(c[0].dx, [0.0, 0.001]);
        assert_eq!(c[0].dv, [0.0, 1.0]);
    }
}
