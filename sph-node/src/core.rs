//! The SPH node's message handler: turns step commands into states. No messaging here — the zenoh adapter
//! (`node.rs`, through `cosim_bus::serve`) and the in-process launcher both call it, so the two modes compute the
//! same bits.

use std::time::Instant;

use cosim_proto::messages::{Correction, SphSetup, SphSnapshot, SphState, StepCommand};
use cosim_proto::scene::Scene;

use bincode::Options;
use cosim_proto::scene::{FluidSolver, PpeSourceKind};
use serde::{Deserialize, Serialize};

use crate::error::SphError;
use crate::isph::{IsphSolver, PpeSource};
use crate::particles::{FluidState, WallParticles};
use crate::solver::{SphParams, WcsphSolver};
use crate::stability::EnergyGuard;

/// Tag and format version at the head of a fluid node's checkpoint (`docs/PROTOCOL.md` §9). Version 2: the
/// solvers carry `fluid.cfl`; 3: the WCSPH solver carries its wall boxes and wall-guard count; 4: the neighbour lists
/// keep only the ∇W factor per pair (no r², no W), and the WCSPH scratch has two per-particle buffers (was six); 6: the
/// WCSPH options carry the δ-SPH density diffusion.
const CHECKPOINT_TAG: (&str, u32) = ("cosim-sph-checkpoint", 6);

/// The fluid solver the scene asks for.
#[derive(Serialize, Deserialize)]
pub enum Fluid {
    /// Weakly compressible.
    Wcsph(WcsphSolver),
    /// Incompressible (projection).
    Isph(IsphSolver),
}

impl Fluid {
    /// Build the solver of `fluid.solver`.
    pub fn new(scene: &Scene) -> Result<Self, SphError> {
        let spec = scene.fluid.as_ref().ok_or_else(|| SphError::InvalidScene {
            key: "fluid".into(),
            message: "the scene has no [fluid] section".into(),
        })?;
        Ok(match spec.solver {
            FluidSolver::Wcsph => Fluid::Wcsph(WcsphSolver::new(scene)?),
            FluidSolver::Isph => Fluid::Isph(IsphSolver::with_source(
                scene,
                match spec.ppe_source.unwrap_or(PpeSourceKind::DivergenceFree) {
                    PpeSourceKind::DivergenceFree => PpeSource::DivergenceFree,
                    PpeSourceKind::DensityInvariant => PpeSource::DensityInvariant,
                },
            )?),
        })
    }

    /// Particle state.
    pub fn state(&self) -> &FluidState {
        match self {
            Fluid::Wcsph(s) => s.state(),
            Fluid::Isph(s) => s.state(),
        }
    }

    /// Particle state, for corrections.
    pub fn state_mut(&mut self) -> &mut FluidState {
        match self {
            Fluid::Wcsph(s) => s.state_mut(),
            Fluid::Isph(s) => s.state_mut(),
        }
    }

    /// Wall particles.
    pub fn walls(&self) -> &WallParticles {
        match self {
            Fluid::Wcsph(s) => s.walls(),
            Fluid::Isph(s) => s.walls(),
        }
    }

    /// Resolved parameters.
    pub fn params(&self) -> &SphParams {
        match self {
            Fluid::Wcsph(s) => s.params(),
            Fluid::Isph(s) => s.params(),
        }
    }

    /// Stable step of the current state.
    pub fn stable_dt(&self) -> f64 {
        match self {
            Fluid::Wcsph(s) => s.stable_dt(),
            Fluid::Isph(s) => s.stable_dt(),
        }
    }

    /// Fluid particles the WCSPH wall guard has put back out of a wall over the run
    /// ([`WcsphSolver::wall_pushes`]); `None` for ISPH (its guard's count is per step, in its PPE report).
    pub fn wall_pushes(&self) -> Option<u64> {
        match self {
            Fluid::Wcsph(s) => Some(s.wall_pushes().0),
            Fluid::Isph(_) => None,
        }
    }

    /// One step.
    pub fn step(&mut self, dt: f64) -> Result<(), SphError> {
        match self {
            Fluid::Wcsph(s) => s.step(dt),
            Fluid::Isph(s) => s.step(dt),
        }
    }
}

/// A fluid node: the solver plus what it tells the broker.
pub struct SphCore {
    solver: Fluid,
    setup: SphSetup,
    guard: EnergyGuard,
    /// `coupling.max_dt`: no command may ask for a longer step.
    max_dt: f64,
}

impl SphCore {
    /// Fill the scene's fluid blocks and walls with particles.
    pub fn new(scene: &Scene) -> Result<Self, SphError> {
        let solver = Fluid::new(scene)?;
        let params = solver.params();
        let setup = SphSetup {
            particles: solver.state().len() as u32,
            spacing: params.dx,
            h: params.h,
            density: scene.fluid.as_ref().map_or(1000.0, |f| f.density),
            walls: solver.walls().x.clone(),
            dt_stable: solver.stable_dt(),
        };
        let guard = EnergyGuard::new(solver.state(), solver.walls(), scene.run.gravity);
        Ok(Self {
            solver,
            setup,
            guard,
            max_dt: scene.coupling.max_dt,
        })
    }

    /// The `sph/setup` registration message.
    pub fn setup(&self) -> &SphSetup {
        &self.setup
    }

    /// The solver (tests, checkpoints).
    pub fn solver(&self) -> &Fluid {
        &self.solver
    }

    /// The node's state between two steps, for a checkpoint: the whole solver — particles, and also their order
    /// in memory, the neighbour lists and every cache a step reads before it rebuilds them, so that a restarted
    /// run computes the same bits — and the energy guard's bound.
    pub fn checkpoint(&self) -> Vec<u8> {
        let tag = CHECKPOINT_TAG;
        bincode::serialize(&(tag.0, tag.1, &self.solver, &self.guard))
            .expect("in-memory bincode encoding of plain data")
    }

    /// Continue from [`SphCore::checkpoint`]'s bytes, on a core built from the same scene. What the bytes hold is
    /// checked before it is used ([`crate::restore`]): against the solver this core built from the scene, and for
    /// consistency with itself; a state that does not hold together is refused naming the field, and the core
    /// keeps the scene's state.
    pub fn restore(&mut self, data: &[u8]) -> Result<(), SphError> {
        let invalid = |message: String| SphError::InvalidParameter {
            name: "checkpoint",
            message,
        };
        let (tag, version, solver, guard): (String, u32, Fluid, EnergyGuard) = bincode::DefaultOptions::new()
            .with_fixint_encoding()
            .reject_trailing_bytes()
            .deserialize(data)
            .map_err(|e| invalid(format!("not a fluid node's state: {e}")))?;
        if (tag.as_str(), version) != CHECKPOINT_TAG {
            return Err(invalid(format!(
                "holds `{tag}` version {version}, this sph-node reads `{}` version {}",
                CHECKPOINT_TAG.0, CHECKPOINT_TAG.1
            )));
        }
        let (saved, scene) = (solver.state().len(), self.solver.state().len());
        if saved != scene || solver.walls().len() != self.solver.walls().len() {
            return Err(invalid(format!(
                "holds {saved} fluid particles, the scene makes {scene} (another scene?)"
            )));
        }
        match (&solver, &self.solver) {
            (Fluid::Wcsph(saved), Fluid::Wcsph(scene)) => saved.check_restored(scene),
            (Fluid::Isph(saved), Fluid::Isph(scene)) => saved.check_restored(scene),
            _ => Err("saved with the other fluid.solver".into()),
        }
        .map_err(invalid)?;
        if guard != self.guard {
            return Err(invalid(format!(
                "guard.bound = {} where the scene gives {}",
                guard.bound, self.guard.bound
            )));
        }
        self.solver = solver;
        self.guard = guard;
        Ok(())
    }

    /// Add the broker's position and velocity increments to the particles they name.
    fn apply_corrections(&mut self, corrections: &[Correction]) -> Result<(), SphError> {
        let state = self.solver.state_mut();
        let n = state.len();
        for c in corrections {
            let i = c.id as usize;
            if i >= n {
                return Err(SphError::InvalidParameter {
                    name: "corrections",
                    message: format!("correction for particle {i}, but there are {n} particles"),
                });
            }
            for k in 0..2 {
                state.x[i][k] += c.dx[k];
                state.v[i][k] += c.dv[k];
            }
        }
        Ok(())
    }

    /// Apply the corrections, advance by `dt` (in as many stable steps as it takes) and answer. `None` for a stop.
    pub fn handle(&mut self, cmd: &StepCommand) -> Result<Option<SphState>, SphError> {
        let started = Instant::now();
        // docs/PROTOCOL.md §7 "Contents": nothing of a command is applied before all of it is checked.
        cmd.validate("broker/sph", self.setup.particles as usize, self.max_dt)
            .map_err(|e| SphError::InvalidParameter {
                name: "command",
                message: e.to_string(),
            })?;
        // DESIGN.md §3 step 5: the contact corrections of the last step, applied before this one.
        self.apply_corrections(&cmd.corrections)?;
        if cmd.stop {
            return Ok(None);
        }
        let mut substeps = 0u32;
        // Sub-cycle at the solver's own adaptive stable step (one step when the broker already capped dt by it).
        let mut done = 0.0;
        while done < cmd.dt {
            let (stable, left) = (self.solver.stable_dt(), cmd.dt - done);
            let mut h = stable.min(left);
            if matches!(self.solver, Fluid::Isph(_)) && left > stable {
                // ISPH: equal sub-steps, not full steps and a remainder. Its pressure carries 1/Δt (the PPE source
                // ∇·u*/Δt and the walls' Neumann rows ρ u*·n/Δt: the impulse Δt ∇p/ρ is what the projection
                // fixes), so a remainder step multiplies it by Δt_own/Δt: the Lobovsky dam break at H/30 took
                // remainders down to 7.4e-7 s (own step 1e-3 s; 411 ρgH in a fluid particle, −1585 before the
                // clip), and its probes, sampled after the last sub-step, read only remainders (docs/CORRECTIONS.md,
                // "ISPH pressure"). WCSPH keeps full steps and a remainder (its pressure is the state's).
                h = left / (left / stable).ceil();
            }
            if cmd.dt - done - h <= 1e-9 * h {
                h = cmd.dt - done;
            }
            self.solver.step(h)?;
            substeps += 1;
            done += h;
        }
        if substeps > 0 {
            self.guard.check(self.solver.state())?;
        }
        let state = self.solver.state();
        let (mut ids, mut x, mut v, mut m) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        if let Some([x0, y0, x1, y1]) = cmd.roi {
            for (i, p) in state.x.iter().enumerate() {
                if p[0] >= x0 && p[0] <= x1 && p[1] >= y0 && p[1] <= y1 {
                    ids.push(i as u32);
                    x.push(*p);
                    v.push(state.v[i]);
                    m.push(state.m[i]);
                }
            }
        }
        let snapshot = cmd.want_snapshot.then(|| SphSnapshot {
            x: state.x.clone(),
            v: state.v.clone(),
            rho: state.rho.clone(),
            p: state.p.clone(),
            m: state.m.clone(),
            wall_p: self.solver.walls().p.clone(),
        });
        Ok(Some(SphState {
            ids,
            x,
            v,
            m,
            substeps,
            dt_stable: self.solver.stable_dt(),
            compute_seconds: started.elapsed().as_secs_f64(),
            snapshot,
        }))
    }
}
