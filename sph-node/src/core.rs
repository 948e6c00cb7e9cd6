//! The SPH node's message handler: turns step commands into states. No messaging here — the zenoh adapter
//! (`node.rs`, through `cosim_bus::serve`) and the in-process launcher both call it, so the two modes compute the
//! same bits.

use std::time::Instant;

use bincode::Options;
use cosim_bus::interrupt::{Interrupt, REASON};
use cosim_proto::messages::{ContactFace, Correction, SphSetup, SphSnapshot, SphState, StepCommand};
use cosim_proto::scene::{FluidSolver as SceneSolver, Scene};
use serde::{Deserialize, Serialize};

use crate::error::{SphError, MAX_SUBSTEPS};
use crate::fluid_solver::{FluidSolver, SavedSolver};
use crate::isph::IsphSolver;
use crate::sensors::{IntervalSensors, PressureField, SensorLog};
use crate::setup;
use crate::stability::EnergyGuard;
use crate::wcsph::WcsphSolver;

/// Tag and format version at the head of a fluid node's checkpoint (`docs/PROTOCOL.md` §9). Version 2: the
/// solvers carry `fluid.cfl`; 3: the WCSPH solver carries its wall boxes and wall-guard count; 4: the neighbour lists
/// keep only the ∇W factor per pair (no r², no W), and the WCSPH scratch has two per-particle buffers (was six); 6: the
/// WCSPH options carry the δ-SPH density diffusion; 7: state only ([`SphCheckpoint`]: no parameters, neighbour lists
/// or scratch, which the scene and the restore rebuild), with the interval sensors' log.
pub const CHECKPOINT_TAG: (&str, u32) = ("cosim-sph-checkpoint", 7);

/// What a fluid node's checkpoint holds after its tag and version: the solver's state and the energy guard's bound.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SphCheckpoint {
    /// The solver's state ([`FluidSolver::save`]).
    pub solver: SavedSolver,
    /// The energy guard.
    pub guard: EnergyGuard,
    /// The interval pressure sensors' integrals since the last snapshot.
    pub sensors: SensorLog,
}

impl SphCheckpoint {
    /// The state in [`SphCore::checkpoint`]'s bytes, read as it is, without the checks a restore makes (a state
    /// that blew up is read too): for looking at a live run (`cosim snapshot`, `cosim inspect --particle`).
    pub fn decode(data: &[u8]) -> Result<Self, SphError> {
        let options = bincode::DefaultOptions::new().with_fixint_encoding();
        let invalid = |message: String| SphError::InvalidParameter {
            name: "checkpoint",
            message,
        };
        let (tag, version, saved): (String, u32, SphCheckpoint) = options
            .reject_trailing_bytes()
            .deserialize(data)
            .map_err(|e| invalid(format!("not a fluid node's state: {e}")))?;
        if (tag.as_str(), version) != CHECKPOINT_TAG {
            return Err(invalid(format!(
                "holds `{tag}` version {version}, this build reads `{}` version {}",
                CHECKPOINT_TAG.0, CHECKPOINT_TAG.1
            )));
        }
        Ok(saved)
    }
}

/// The solver of `fluid.solver`.
pub fn solver_from_scene(scene: &Scene) -> Result<Box<dyn FluidSolver>, SphError> {
    let spec = setup::fluid_spec_any(scene)?;
    Ok(match spec.solver {
        SceneSolver::Wcsph => Box::new(WcsphSolver::new(scene)?),
        SceneSolver::Isph => Box::new(IsphSolver::new(scene)?),
    })
}

/// A fluid node: the solver plus what it tells the broker.
pub struct SphCore {
    solver: Box<dyn FluidSolver>,
    setup: SphSetup,
    guard: EnergyGuard,
    /// `coupling.max_dt`: no command may ask for a longer step.
    max_dt: f64,
    /// The scene's interval-mean pressure sensors, logged after every step.
    sensors: IntervalSensors,
    /// A signal that gives up a step in progress ([`SphCore::stop_on`]).
    stop: Option<Interrupt>,
}

impl SphCore {
    /// Fill the scene's fluid blocks and walls with particles.
    pub fn new(scene: &Scene) -> Result<Self, SphError> {
        let solver = solver_from_scene(scene)?;
        let params = solver.params();
        let setup = SphSetup {
            particles: solver.state().len() as u32,
            spacing: params.dx,
            h: params.h,
            density: scene.fluid.as_ref().map_or(1000.0, |f| f.density),
            walls: solver.walls().x.clone(),
            dt_stable: solver.stable_dt(),
            sensors: 0,
        };
        let sensors = IntervalSensors::new(scene);
        let setup = SphSetup {
            sensors: sensors.len() as u32,
            ..setup
        };
        // The guard's quiet floor needs the fluid's sound speed (WCSPH's c0; ISPH's where the scene gives one).
        let c0 = scene
            .fluid
            .as_ref()
            .and_then(|f| crate::setup::sound_speed(f, scene.run.gravity).ok());
        // The budget counts what a solid held nowhere can give the water by sinking (`stability.rs`).
        let bodies = crate::stability::free_solids(scene);
        let guard = EnergyGuard::with_bodies(solver.state(), solver.walls(), scene.run.gravity, c0, &bodies);
        Ok(Self {
            solver,
            setup,
            guard,
            max_dt: scene.coupling.max_dt,
            sensors,
            stop: None,
        })
    }

    /// Give up a step still in progress [`STOP_WAIT`](cosim_bus::interrupt::STOP_WAIT) after `interrupt` arrived,
    /// between two sub-steps ([`SphError::Stopped`]): in `cosim run --in-process`, a coupling step of many fluid
    /// steps would hold Ctrl-C that long. A step that ends within that time is still taken. (As a process the node
    /// need not: the broker stops waiting for its answer.)
    pub fn stop_on(&mut self, interrupt: Interrupt) {
        self.stop = Some(interrupt);
    }

    /// The `sph/setup` registration message.
    pub fn setup(&self) -> &SphSetup {
        &self.setup
    }

    /// The solver (tests, checkpoints).
    pub fn solver(&self) -> &dyn FluidSolver {
        self.solver.as_ref()
    }

    /// The node's state between two steps, for a checkpoint: the solver's ([`FluidSolver::save`]: particles,
    /// walls and what the method carries from one step to the next) and the energy guard's bound. Parameters come from
    /// the scene; neighbour lists, cell order and scratch are rebuilt on restore.
    pub fn checkpoint(&self) -> Vec<u8> {
        let tag = CHECKPOINT_TAG;
        let saved = SphCheckpoint {
            solver: self.solver.save(),
            guard: self.guard,
            sensors: self.sensors.log().clone(),
        };
        bincode::serialize(&(tag.0, tag.1, &saved)).expect("in-memory bincode encoding of plain data")
    }

    /// Continue from [`SphCore::checkpoint`]'s bytes, on a core built from the same scene. The tag and version are
    /// read first (another version is refused, naming both); what the bytes hold is then checked before it is used
    /// ([`FluidSolver::restore`], `restore.rs`); a state that does not hold together is refused naming the
    /// field, and the core keeps the scene's state.
    pub fn restore(&mut self, data: &[u8]) -> Result<(), SphError> {
        // Named as the checkpoint's file: "checkpoint: not a fluid node's state: io error: …" named none (found
        // 2026-12-06 by the sweep of crafted checkpoints, D23).
        let invalid = |message: String| SphError::InvalidParameter {
            name: cosim_proto::keys::SPH.checkpoint_file,
            message,
        };
        let not_ours = |e: bincode::Error| invalid(format!("not a fluid node's state: {e}"));
        let options = bincode::DefaultOptions::new().with_fixint_encoding();
        let (tag, version): (String, u32) = options.allow_trailing_bytes().deserialize(data).map_err(not_ours)?;
        if (tag.as_str(), version) != CHECKPOINT_TAG {
            return Err(invalid(format!(
                "holds `{tag}` version {version}, this sph-node reads `{}` version {} (restart the run from its start)",
                CHECKPOINT_TAG.0, CHECKPOINT_TAG.1
            )));
        }
        let (_, _, saved): (String, u32, SphCheckpoint) =
            options.reject_trailing_bytes().deserialize(data).map_err(not_ours)?;
        let SphCheckpoint { solver, guard, sensors } = saved;
        if solver.solver != self.solver.name() {
            return Err(invalid(format!(
                "saved with fluid.solver = \"{}\", the scene has \"{}\"",
                solver.solver,
                self.solver.name()
            )));
        }
        let (saved, scene) = (solver.state.len(), self.solver.state().len());
        if saved != scene || solver.walls.len() != self.solver.walls().len() {
            return Err(invalid(format!(
                "holds {saved} fluid particles, the scene makes {scene} (another scene?)"
            )));
        }
        if guard != self.guard {
            return Err(invalid(format!(
                "guard.bound = {} where the scene gives {}",
                guard.bound, self.guard.bound
            )));
        }
        let mut logged = self.sensors.clone();
        logged.restore(sensors).map_err(invalid)?;
        self.solver.restore(solver).map_err(invalid)?;
        self.guard = guard;
        self.sensors = logged;
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
        let faces: Vec<(usize, ContactFace)> = corrections
            .iter()
            .filter_map(|c| Some((c.id as usize, c.face?)))
            .collect();
        if !faces.is_empty() {
            self.solver.contact_faces(&faces);
        }
        Ok(())
    }

    /// Advances the fluid by `dt` in sub-steps of its own stable step; how many.
    fn subcycle(&mut self, dt: f64) -> Result<u32, SphError> {
        let mut substeps = 0u32;
        // Sub-cycle at the solver's own adaptive stable step (one step when the broker already capped dt by it).
        let mut done = 0.0;
        while done < dt {
            if substeps > 0 && self.stop.as_ref().is_some_and(Interrupt::overdue) {
                return Err(SphError::Stopped {
                    done: substeps,
                    dt,
                    why: REASON,
                });
            }
            let (stable, left) = (self.solver.stable_dt(), dt - done);
            let mut h = stable.min(left);
            if self.solver.equal_substeps() && left > stable {
                // ISPH: equal sub-steps, not full steps and a remainder. Its pressure carries 1/Δt (the PPE source
                // ∇·u*/Δt and the walls' Neumann rows ρ u*·n/Δt: the impulse Δt ∇p/ρ is what the projection
                // fixes), so a remainder step multiplies it by Δt_own/Δt: the Lobovsky dam break at H/30 took
                // remainders down to 7.4e-7 s (own step 1e-3 s; 411 ρgH in a fluid particle, −1585 before the
                // clip), and its probes, sampled after the last sub-step, read only remainders (docs/CORRECTIONS.md,
                // "ISPH pressure"). WCSPH keeps full steps and a remainder (its pressure is the state's).
                h = left / (left / stable).ceil();
            }
            if dt - done - h <= 1e-9 * h {
                h = dt - done;
            }
            // A stable step that would take more than 2^32 sub-steps, or that no longer moves `done` (below its
            // last bit), is a blow-up in the making: an error now, not a coupling step that never ends (which no
            // Ctrl-C, answered between coupling steps, could stop).
            let count = left / stable;
            if count.is_nan() || count > MAX_SUBSTEPS || done + h <= done {
                return Err(SphError::StepCollapsed {
                    step: self.solver.state().step + 1,
                    stable,
                    left,
                });
            }
            self.solver.step(h)?;
            if !self.sensors.is_empty() {
                self.sensors
                    .after_step(&pressure_field(self.solver.as_ref(), &self.setup), h);
            }
            substeps = substeps.saturating_add(1);
            done += h;
        }
        Ok(substeps)
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
        // The whole sub-cycle runs on a worker of the rayon pool: every pass of a step is a parallel loop, and one
        // started from a thread outside the pool hands its work to a worker and sleeps until it is done, two
        // context switches a pass (about 70 a WCSPH step at `--threads 1`, issue 20). Started from a worker, the
        // loops run where they are, split as before: the same bits.
        let substeps = rayon::scope(|_| self.subcycle(cmd.dt))?;
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
            sensors: self
                .sensors
                .take_means(&pressure_field(self.solver.as_ref(), &self.setup)),
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

/// What the pressure sensors read: the solver's particles and walls.
fn pressure_field<'a>(solver: &'a dyn FluidSolver, setup: &SphSetup) -> PressureField<'a> {
    let (state, walls) = (solver.state(), solver.walls());
    PressureField {
        x: &state.x,
        m: &state.m,
        rho: &state.rho,
        p: &state.p,
        wall_x: &walls.x,
        h: setup.h,
        spacing: setup.spacing,
    }
}
