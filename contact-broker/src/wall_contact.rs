//! The walls stop the structure after each contact pass: its surface nodes put back on a wall's face, their
//! velocity into it taken off (the rule and its exclusions: `cosim_proto::walls`).
//!
//! fem-node applies the same rule after every sub-step's drift, so a node its own step took into a wall is back on
//! the face before it answers; what is left for the broker is what the contact pass moved (a correction that
//! pushes a node into a wall) and a structure node that does not stop its nodes itself (an outside solver). Until
//! 2026-12-08 the broker alone stopped the nodes, once a coupling step, and that made energy: within the step's
//! unconstrained sub-steps a node pressed into the wall went deeper while the compression above it grew, and was
//! put back against the force at the step's end (docs/CORRECTIONS.md "The walls inside the structure's
//! sub-steps"). Before the thirty-third session (2026-12-07) a solid that reached a wall passed through it.

use cosim_proto::messages::{Correction, FemMesh, FemState};
use cosim_proto::scene::Scene;
use cosim_proto::walls::Walls;

/// The walls and which interface nodes they stop.
#[derive(Clone, Debug)]
pub struct WallContact {
    walls: Walls,
    /// Per interface node (in the order of the interface's ids): stopped by the walls.
    stopped: Vec<bool>,
    /// Scratch of [`WallContact::correct`]: the pass's corrections summed per interface node, (dx, dv).
    moved_by: Vec<([f64; 2], [f64; 2])>,
}

impl WallContact {
    /// The walls of `scene` against the interface nodes `ids` of `mesh`; `None` without walls or nodes to stop.
    pub fn new(scene: &Scene, mesh: &FemMesh, ids: &[u32]) -> Option<Self> {
        let walls = Walls::new(scene)?;
        let mut fixed = vec![false; mesh.nodes.len()];
        for &f in &mesh.fixed {
            if let Some(slot) = fixed.get_mut(f as usize) {
                *slot = true;
            }
        }
        let all = walls.stopped(&mesh.nodes, &fixed, &mesh.node_solid);
        let stopped: Vec<bool> = ids
            .iter()
            .map(|&id| all.get(id as usize).copied().unwrap_or(false))
            .collect();
        stopped.iter().any(|&s| s).then_some(Self {
            walls,
            stopped,
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
            let Some((dx, dv)) = self.walls.stop(p, u) else {
                continue;
            };
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
