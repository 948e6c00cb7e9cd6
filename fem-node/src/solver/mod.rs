//! The structure solver: a model, its state and scratch, and the explicit time loop with sub-cycling.

pub mod central_difference;
pub mod internal_forces;
pub mod stable_dt;

use cosim_proto::messages::{Correction, Energies, FemMesh, FemSnapshot};

use crate::error::{FemError, Result};
use crate::model::FemModel;
use crate::state::{FemScratch, FemState};
pub use internal_forces::DEFAULT_PARALLEL_MIN_ELEMENTS;

/// Explicit FEM solver of one [`FemModel`].
#[derive(Clone, Debug)]
pub struct FemSolver {
    model: FemModel,
    state: FemState,
    scratch: FemScratch,
    cfl: f64,
    parallel_min_elements: usize,
    accelerations_stale: bool,
}

impl FemSolver {
    /// A solver with the model at rest in its reference configuration; computes the initial accelerations.
    /// `cfl` is the safety factor on the stable step, in (0, 1].
    pub fn new(model: FemModel, cfl: f64) -> Result<Self> {
        let state = FemState::at_rest(&model);
        let mut solver = Self::with_state(model, state, cfl)?;
        solver.refresh_accelerations()?;
        Ok(solver)
    }

    /// A solver resuming from `state` (e.g. a restart); its accelerations are used as they are.
    pub fn with_state(model: FemModel, state: FemState, cfl: f64) -> Result<Self> {
        if !(cfl > 0.0 && cfl <= 1.0) {
            return Err(FemError::InvalidParameter {
                name: "cfl",
                message: format!("must be in (0, 1], got {cfl}"),
            });
        }
        let n = model.node_count();
        if state.x.len() != n || state.v.len() != n || state.a.len() != n {
            return Err(FemError::InvalidParameter {
                name: "state",
                message: format!("holds {} positions for a model of {n} nodes", state.x.len()),
            });
        }
        let scratch = FemScratch::new(&model);
        Ok(Self {
            model,
            state,
            scratch,
            cfl,
            parallel_min_elements: DEFAULT_PARALLEL_MIN_ELEMENTS,
            accelerations_stale: false,
        })
    }

    /// The model.
    pub fn model(&self) -> &FemModel {
        &self.model
    }

    /// The state.
    pub fn state(&self) -> &FemState {
        &self.state
    }

    /// Mutable state. The accelerations are used as they are at the next step: call
    /// [`refresh_accelerations`](Self::refresh_accelerations) after moving nodes.
    pub fn state_mut(&mut self) -> &mut FemState {
        &mut self.state
    }

    /// Safety factor on the stable step.
    pub fn cfl(&self) -> f64 {
        self.cfl
    }

    /// Element count from which element forces are computed on the rayon pool (default
    /// [`DEFAULT_PARALLEL_MIN_ELEMENTS`]); results do not depend on it.
    pub fn set_parallel_min_elements(&mut self, n: usize) {
        self.parallel_min_elements = n;
    }

    /// Whether the accelerations are recomputed before the next step (after corrections or new velocities); a
    /// checkpoint keeps it with the state, so that a restarted run takes the same steps.
    pub fn accelerations_stale(&self) -> bool {
        self.accelerations_stale
    }

    /// Continue from a saved state (a checkpoint): the state as it was, accelerations included, and whether they
    /// were to be recomputed. The state is checked against the model first ([`FemState::check`]); one that does not
    /// hold together is refused and the solver keeps its own.
    pub fn resume(&mut self, state: FemState, accelerations_stale: bool) -> Result<()> {
        state.check(&self.model).map_err(|message| FemError::InvalidParameter {
            name: cosim_proto::keys::FEM.checkpoint_file,
            message,
        })?;
        self.state = state;
        self.accelerations_stale = accelerations_stale;
        Ok(())
    }

    /// Sets every node's velocity (clamped nodes stay at rest); accelerations are refreshed before the next step.
    pub fn set_velocities(&mut self, v: impl Fn(usize, [f64; 2]) -> [f64; 2]) {
        for k in 0..self.state.v.len() {
            self.state.v[k] = if self.model.fixed()[k] {
                [0.0; 2]
            } else {
                v(k, self.model.reference()[k])
            };
        }
        self.accelerations_stale = true;
    }

    /// Recomputes the accelerations from the current positions and velocities.
    pub fn refresh_accelerations(&mut self) -> Result<()> {
        central_difference::refresh_accelerations(
            &self.model,
            &mut self.state,
            &mut self.scratch,
            self.parallel_min_elements,
        )
        .map_err(|(e, why)| self.unstable(self.state.step, e, why.to_string()))?;
        self.accelerations_stale = false;
        Ok(())
    }

    /// Stable step of the current configuration, `cfl · min_e(L_e / c_d)`; 0 if an element has collapsed.
    pub fn stable_dt(&self) -> f64 {
        stable_dt::stable_dt(&self.model, &self.state.x, self.cfl).unwrap_or(0.0)
    }

    /// Advances by `dt` in `k = ceil(dt / Δt_stable)` equal sub-steps (the stable step is recomputed at the start
    /// of each call) and returns `k`; `dt = 0` does nothing.
    pub fn advance(&mut self, dt: f64) -> Result<u32> {
        self.advance_until(dt, &|| None)
    }

    /// [`FemSolver::advance`], asking `stop` before each sub-step but the first: a reason from it ends the step
    /// there with [`FemError::Stopped`] (a step of many sub-steps that the user interrupts). The same bits as
    /// `advance` while it answers `None`.
    pub fn advance_until(&mut self, dt: f64, stop: &dyn Fn() -> Option<&'static str>) -> Result<u32> {
        if !(dt.is_finite() && dt >= 0.0) {
            return Err(FemError::InvalidParameter {
                name: "dt",
                message: format!("must be finite and >= 0, got {dt}"),
            });
        }
        if dt == 0.0 {
            return Ok(0);
        }
        if self.accelerations_stale {
            self.refresh_accelerations()?;
        }
        let stable = stable_dt::stable_dt(&self.model, &self.state.x, self.cfl).map_err(|(e, l)| {
            self.unstable(
                self.state.step,
                e,
                format!("collapsed element (characteristic length {l:.3e})"),
            )
        })?;
        let mut k = (dt / stable).ceil().max(1.0);
        if dt / k > stable {
            k += 1.0;
        }
        if k > u32::MAX as f64 {
            return Err(FemError::InvalidParameter {
                name: "dt",
                message: format!("{dt} needs more than 2^32 sub-steps of {stable:.3e}"),
            });
        }
        let (k, h, t0) = (k as u32, dt / k, self.state.t);
        for i in 0..k {
            if let Some(why) = (i > 0).then(stop).flatten() {
                return Err(FemError::Stopped {
                    done: i,
                    of: k,
                    dt,
                    why,
                });
            }
            self.substep(h)?;
        }
        self.state.t = t0 + dt;
        Ok(k)
    }

    /// One central-difference step of exactly `dt`, without checking it against the stable step.
    pub fn substep(&mut self, dt: f64) -> Result<()> {
        if self.accelerations_stale {
            self.refresh_accelerations()?;
        }
        let step = self.state.step + 1;
        central_difference::step(
            &self.model,
            &mut self.state,
            &mut self.scratch,
            dt,
            self.parallel_min_elements,
        )
        .map_err(|(e, why)| self.unstable(step, e, why.to_string()))?;
        if let Some(k) = self
            .state
            .a
            .iter()
            .position(|a| !(a[0].is_finite() && a[1].is_finite()))
        {
            return Err(FemError::Unstable {
                step,
                element: self.element_of_node(k),
                reason: format!("non-finite acceleration at node {k}"),
            });
        }
        Ok(())
    }

    /// Applies contact corrections: `x += dx`, `v += dv` on free nodes; clamped nodes are skipped, and a
    /// correction for a node the mesh does not have is an error (as in the fluid node), applied to nothing.
    /// Accelerations are refreshed before the next step when a position moved.
    pub fn apply_corrections(&mut self, corrections: &[Correction]) -> Result<()> {
        let n = self.state.x.len();
        if let Some(c) = corrections.iter().find(|c| c.id as usize >= n) {
            return Err(FemError::InvalidParameter {
                name: "corrections",
                message: format!("correction for node {}, but the mesh has {n} nodes", c.id),
            });
        }
        for c in corrections {
            let k = c.id as usize;
            if self.model.fixed()[k] {
                continue;
            }
            for d in 0..2 {
                self.state.x[k][d] += c.dx[d];
                self.state.v[k][d] += c.dv[d];
            }
            // Damping makes a depend on v too.
            let damped = self.model.solids()[self.model.node_solid()[k] as usize].damping > 0.0;
            if c.dx != [0.0; 2] || (damped && c.dv != [0.0; 2]) {
                self.accelerations_stale = true;
            }
        }
        Ok(())
    }

    /// Kinetic `½ Σ m v²`, strain `Σ_e (W(F) A + hourglass energy)` and potential `−Σ m g·(x − X)` energy of
    /// every solid [J per unit thickness].
    pub fn energies(&self) -> Vec<Energies> {
        let (m, x, v, g) = (self.model.masses(), &self.state.x, &self.state.v, self.model.gravity());
        let reference = self.model.reference();
        self.model
            .solids()
            .iter()
            .map(|solid| {
                let mut out = Energies::default();
                for k in solid.nodes.clone() {
                    out.kinetic += 0.5 * m[k] * (v[k][0] * v[k][0] + v[k][1] * v[k][1]);
                    out.potential -= m[k] * (g[0] * (x[k][0] - reference[k][0]) + g[1] * (x[k][1] - reference[k][1]));
                }
                for e in solid.elements.clone() {
                    out.strain += self.model.elements()[e].strain_energy(x, &solid.material);
                }
                out
            })
            .collect()
    }

    /// Sum of all energies of all solids.
    pub fn total_energy(&self) -> f64 {
        self.energies().iter().map(|e| e.kinetic + e.strain + e.potential).sum()
    }

    /// Cauchy stress `[σxx, σyy, σxy]` of every element (the mean stress of a quad) \[Pa\].
    pub fn cell_stress(&self) -> Vec<[f64; 3]> {
        (0..self.model.elements().len())
            .map(|e| self.model.elements()[e].cauchy_stress(&self.state.x, self.model.element_material(e)))
            .collect()
    }

    /// Displacement `x − X` of node `k`.
    pub fn displacement(&self, k: usize) -> [f64; 2] {
        self.state.displacement(&self.model, k)
    }

    /// The `fem/mesh` message of this model.
    pub fn mesh_message(&self) -> FemMesh {
        FemMesh {
            solid_names: self.model.solids().iter().map(|s| s.name.clone()).collect(),
            nodes: self.model.reference().to_vec(),
            masses: self.model.masses().to_vec(),
            node_solid: self.model.node_solid().to_vec(),
            cells: self.model.cells(),
            cell_solid: self.model.element_solid().to_vec(),
            interface: self.model.boundary().to_vec(),
            fixed: (0..self.model.node_count())
                .filter(|&k| self.model.fixed()[k])
                .map(|k| k as u32)
                .collect(),
            dt_stable: self.stable_dt(),
        }
    }

    /// Positions, velocities, stresses and energies for frames and probes.
    pub fn snapshot(&self) -> FemSnapshot {
        FemSnapshot {
            x: self.state.x.clone(),
            v: self.state.v.clone(),
            stress: self.cell_stress(),
            energies: self.energies(),
        }
    }

    fn unstable(&self, step: u64, element: usize, reason: String) -> FemError {
        FemError::Unstable { step, element, reason }
    }

    /// The first element that holds node `k` (for error messages).
    fn element_of_node(&self, k: usize) -> usize {
        self.model
            .elements()
            .iter()
            .position(|e| e.nodes().contains(&(k as u32)))
            .unwrap_or(0)
    }
}
