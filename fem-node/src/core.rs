//! The FEM node's message handler: turns step commands into states. No messaging here — the zenoh adapter
//! (`node.rs`) and the in-process launcher both call it, so the two modes compute the same bits.

use std::time::Instant;

use bincode::Options;

use cosim_bus::interrupt::{Interrupt, REASON};
use cosim_proto::messages::{FemMesh, FemState, StepCommand};
use cosim_proto::scene::Scene;

use crate::error::FemError;
use crate::model::FemModel;
use crate::solver::FemSolver;
use crate::state::FemState as SolverState;

/// Tag and format version at the head of a structure node's checkpoint (`docs/PROTOCOL.md` §9).
const CHECKPOINT_TAG: (&str, u32) = ("cosim-fem-checkpoint", 1);

/// A structure node: the solver plus what it tells the broker.
pub struct FemCore {
    solver: FemSolver,
    mesh: FemMesh,
    interface_nodes: Vec<u32>,
    /// `coupling.max_dt`: no command may ask for a longer step.
    max_dt: f64,
    /// A signal that gives up a step in progress ([`FemCore::stop_on`]).
    stop: Option<Interrupt>,
}

impl FemCore {
    /// Build the model of every solid of the scene.
    pub fn new(scene: &Scene) -> Result<Self, FemError> {
        let model = FemModel::build(scene)?;
        let solver = FemSolver::new(model, scene.coupling.fem_cfl)?;
        let mesh = solver.mesh_message();
        let interface_nodes = mesh.interface_nodes();
        Ok(Self {
            solver,
            mesh,
            interface_nodes,
            max_dt: scene.coupling.max_dt,
            stop: None,
        })
    }

    /// Give up a step still in progress [`STOP_WAIT`](cosim_bus::interrupt::STOP_WAIT) after `interrupt` arrived,
    /// between two sub-steps ([`FemError::Stopped`]): in `cosim run --in-process`, a coupling step of minutes (a fine
    /// mesh) would hold Ctrl-C that long. A step that ends within that time is still taken. (As a process the node
    /// need not: the broker stops waiting for its answer.)
    pub fn stop_on(&mut self, interrupt: Interrupt) {
        self.stop = Some(interrupt);
    }

    /// The `fem/mesh` registration message.
    pub fn mesh(&self) -> &FemMesh {
        &self.mesh
    }

    /// The solver (tests, checkpoints).
    pub fn solver(&self) -> &FemSolver {
        &self.solver
    }

    /// The node's state between two steps, for a checkpoint: the solver state (positions, velocities,
    /// accelerations, time, sub-step count) and whether its accelerations are stale. The model is not saved:
    /// it follows from the scene, which the checkpoint keeps.
    pub fn checkpoint(&self) -> Vec<u8> {
        let tag = CHECKPOINT_TAG;
        let saved = (tag.0, tag.1, self.solver.state(), self.solver.accelerations_stale());
        bincode::serialize(&saved).expect("in-memory bincode encoding of plain data")
    }

    /// Continue from [`FemCore::checkpoint`]'s bytes, on a core built from the same scene. The state is checked
    /// before it is used ([`SolverState::check`]): one entry per node of the model, finite, clamped nodes at rest
    /// where they are clamped; a state that does not hold together is refused naming the field, and the core keeps
    /// the scene's state.
    pub fn restore(&mut self, data: &[u8]) -> Result<(), FemError> {
        // Named as the checkpoint's file: "checkpoint: not a structure node's state: io error: …" named none (found
        // 2026-12-06 by the sweep of crafted checkpoints, D23).
        let invalid = |message: String| FemError::InvalidParameter {
            name: cosim_proto::keys::FEM.checkpoint_file,
            message,
        };
        let (tag, version, state, stale): (String, u32, SolverState, bool) = bincode::DefaultOptions::new()
            .with_fixint_encoding()
            .reject_trailing_bytes()
            .deserialize(data)
            .map_err(|e| invalid(format!("not a structure node's state: {e}")))?;
        if (tag.as_str(), version) != CHECKPOINT_TAG {
            return Err(invalid(format!(
                "holds `{tag}` version {version}, this fem-node reads `{}` version {}",
                CHECKPOINT_TAG.0, CHECKPOINT_TAG.1
            )));
        }
        self.solver.resume(state, stale)
    }

    /// Apply the corrections, advance by `dt`, and answer. `None` for a stop command.
    pub fn handle(&mut self, cmd: &StepCommand) -> Result<Option<FemState>, FemError> {
        let started = Instant::now();
        // docs/PROTOCOL.md §7 "Contents": nothing of a command is applied before all of it is checked.
        cmd.validate("broker/fem", self.mesh.nodes.len(), self.max_dt)
            .map_err(|e| FemError::InvalidParameter {
                name: "command",
                message: e.to_string(),
            })?;
        self.solver.apply_corrections(&cmd.corrections)?;
        if cmd.stop {
            return Ok(None);
        }
        // On a worker of the rayon pool (as sph-node's sub-cycle): the element loop is parallel above
        // `DEFAULT_PARALLEL_MIN_ELEMENTS`, and a parallel loop started from outside the pool hands its work to a
        // worker and sleeps, two context switches a sub-step; the same bits either way.
        let substeps = if cmd.dt > 0.0 {
            let (solver, stop) = (&mut self.solver, &self.stop);
            let overdue = || stop.as_ref().is_some_and(Interrupt::overdue).then_some(REASON);
            rayon::scope(|_| solver.advance_until(cmd.dt, &overdue))?
        } else {
            0
        };
        let state = self.solver.state();
        let (ids, x, v) = if cmd.want_interface {
            let ids = self.interface_nodes.clone();
            let x = ids.iter().map(|&n| state.x[n as usize]).collect();
            let v = ids.iter().map(|&n| state.v[n as usize]).collect();
            (ids, x, v)
        } else {
            (Vec::new(), Vec::new(), Vec::new())
        };
        let snapshot = cmd.want_snapshot.then(|| self.solver.snapshot());
        Ok(Some(FemState {
            ids,
            x,
            v,
            substeps,
            dt_stable: self.solver.stable_dt(),
            compute_seconds: started.elapsed().as_secs_f64(),
            snapshot,
        }))
    }
}
