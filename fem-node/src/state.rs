//! The solver state that defines a run (serializable, for restarts and snapshots), kept apart from the per-step
//! scratch memory (which is only workspace and is not serialized).

use cosim_proto::validate::within_largest;
use serde::{Deserialize, Serialize};

use crate::element::ElementForces;
use crate::model::FemModel;

/// Positions, velocities and accelerations of all nodes at time `t`, after `step` sub-steps.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FemState {
    /// Simulated time \[s\].
    pub t: f64,
    /// Sub-steps taken so far.
    pub step: u64,
    /// Current positions `x` \[m\].
    pub x: Vec<[f64; 2]>,
    /// Full-step velocities `v` [m/s].
    pub v: Vec<[f64; 2]>,
    /// Accelerations `a` [m/s²] of the current positions.
    pub a: Vec<[f64; 2]>,
}

impl FemState {
    /// The model at rest in its reference configuration (accelerations still to be computed).
    pub fn at_rest(model: &FemModel) -> Self {
        let n = model.node_count();
        Self {
            t: 0.0,
            step: 0,
            x: model.reference().to_vec(),
            v: vec![[0.0; 2]; n],
            a: vec![[0.0; 2]; n],
        }
    }

    /// Check a state read back from outside (a checkpoint) before a solver of `model` continues from it: one
    /// position, velocity and acceleration per node of the model, every value finite, the time finite and not
    /// negative, and every clamped node where the solver keeps it (`x = X`, `v = a = 0`). `Err` is one line naming
    /// the field, the node and the value.
    pub fn check(&self, model: &FemModel) -> Result<(), String> {
        let n = model.node_count();
        if !(self.t.is_finite() && self.t >= 0.0) {
            return Err(format!("state.t = {} is not a time", self.t));
        }
        for (field, values) in [("x", &self.x), ("v", &self.v), ("a", &self.a)] {
            if values.len() != n {
                return Err(format!("state.{field} holds {} nodes, the model has {n}", values.len()));
            }
            // Within ±1e50, as every number of a message (`cosim_proto::validate::LARGEST`): a node at 1e300 m
            // passed, and the run failed at its first step as a collapsed element, naming no checkpoint.
            let held = |p: &[f64; 2]| within_largest(p[0]) && within_largest(p[1]);
            if let Some(k) = values.iter().position(|p| !held(p)) {
                return Err(format!(
                    "state.{field}[{k}] = {:?} is not finite within ±1e50",
                    values[k]
                ));
            }
        }
        let clamped = model
            .fixed()
            .iter()
            .zip(model.reference())
            .enumerate()
            .filter(|(_, (f, _))| **f);
        for (k, (_, reference)) in clamped {
            // Indexing is in bounds: every field holds `n` nodes, checked above.
            let (x, v, a) = (self.x[k], self.v[k], self.a[k]);
            if x != *reference || v != [0.0; 2] || a != [0.0; 2] {
                return Err(format!(
                    "state: node {k} is clamped at {reference:?} but has x {x:?}, v {v:?}, a {a:?}"
                ));
            }
        }
        Ok(())
    }

    /// Displacement `x − X` of node `k`.
    pub fn displacement(&self, model: &FemModel, k: usize) -> [f64; 2] {
        let r = model.reference()[k];
        [self.x[k][0] - r[0], self.x[k][1] - r[1]]
    }
}

/// Per-step workspace: element force buffers and the assembled internal forces. This contains only workspace
/// data, so there is no point in making it serializable.
#[derive(Clone, Debug, Default)]
pub struct FemScratch {
    /// Nodal forces of every element, written in parallel.
    pub element_forces: Vec<ElementForces>,
    /// Assembled internal forces per node.
    pub internal: Vec<[f64; 2]>,
    /// The positions `x + β v` the internal forces of a stiffness-damped solid are taken at (empty without one).
    pub damped_positions: Vec<[f64; 2]>,
}

impl FemScratch {
    /// Buffers sized for `model`.
    pub fn new(model: &FemModel) -> Self {
        Self {
            element_forces: vec![[[0.0; 2]; 4]; model.elements().len()],
            internal: vec![[0.0; 2]; model.node_count()],
            damped_positions: Vec::new(),
        }
    }
}
