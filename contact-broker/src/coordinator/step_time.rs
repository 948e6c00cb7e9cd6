//! The run's clock (`DESIGN.md` §3 step 1): how long each coupling step is, and the output times the steps land
//! on.

use cosim_proto::scene::Scene;

use super::exchange::Round;
use crate::summary::Summary;

/// Steps closer than this fraction of `max_dt` to an output time land on it.
pub(super) const LANDING: f64 = 1e-9;

/// Where the run is in time, and the fluid's stable step that bounds the next coupling step.
pub(super) struct Clock {
    /// Simulated time [s].
    pub t: f64,
    /// Coupling steps taken.
    pub step: u64,
    /// Index k of the next output time k · `run.output_interval`.
    pub next_output: u64,
    /// The fluid's stable step last reported [s] (infinite without a fluid).
    pub dt_fluid: f64,
    /// The longest step the contact passes so far allow [s] (infinite where none set a bound:
    /// [`crate::contact_step`]).
    pub dt_contact: f64,
    interval: f64,
    end: f64,
    max_dt: f64,
    structure: bool,
}

/// One coupling step, as fixed before it is taken.
pub(super) struct Step {
    /// Its length [s].
    pub dt: f64,
    /// Whether it ends on the output time `target` (then it is an output step).
    pub lands: bool,
    /// The next output time [s].
    pub target: f64,
    /// The most a step may take now [s]; times within [`LANDING`] of it count as reached.
    pub cap: f64,
}

impl Clock {
    /// The clock at t = 0 of `scene`; `structure` says whether a structure node takes part, `dt_fluid` is the
    /// fluid's first stable step (infinite without a fluid).
    pub fn new(scene: &Scene, structure: bool, dt_fluid: f64) -> Self {
        Self {
            t: 0.0,
            step: 0,
            next_output: 1,
            dt_fluid,
            dt_contact: f64::INFINITY,
            interval: scene.run.output_interval,
            end: scene.run.end_time,
            max_dt: scene.coupling.max_dt,
            structure,
        }
    }

    /// The end time [s].
    pub fn end(&self) -> f64 {
        self.end
    }

    /// Whether the end time is still ahead.
    pub fn running(&self) -> bool {
        self.t < self.end
    }

    /// Fix the next coupling step: the fluid's stable step and the contact's, capped by the user and the next
    /// output time. Without a structure there is nothing to couple: the fluid node sub-cycles at its own stable
    /// step.
    pub fn next_step(&mut self) -> Step {
        let target = (self.next_output as f64 * self.interval).min(self.end);
        let cap = if self.structure {
            self.max_dt.min(self.dt_fluid).min(self.dt_contact)
        } else {
            self.max_dt
        };
        let mut dt = cap.min(target - self.t);
        let lands = target - (self.t + dt) <= LANDING * cap;
        if lands {
            dt = target - self.t;
        }
        self.step += 1;
        Step { dt, lands, target, cap }
    }

    /// A contact pass allows the next step to be at most `dt` long (`None`: no bound); the bound holds for the rest
    /// of the run.
    pub fn contact_bound(&mut self, dt: Option<f64>) {
        // Never longer again: a step that follows the contact's stiffness up and down pumps energy into it
        // (contact_step.rs).
        if let Some(dt) = dt {
            if self.dt_contact.is_infinite() {
                tracing::info!(
                    "the contact force's stiffness bounds the coupling step from t = {:.6} s: {dt:.3e} s (and shorter where \
                     it asks; summary.json contact_step_bound)",
                    self.t
                );
            }
            // Once, where it makes the run ten times longer than the fluid alone would: say so while it runs.
            let slow = 0.1 * self.dt_fluid.min(self.max_dt);
            if dt < slow && self.dt_contact >= slow {
                tracing::warn!(
                    "the contact force's stiffness shortens the coupling step to {dt:.3e} s at t = {:.6} s, under a tenth \
                     of the {:.3e} s the fluid and coupling.max_dt allow: the rest of the run takes over ten times the steps \
                     (particle_particle with WCSPH; particle_element sets no such bound)",
                    self.t,
                    self.dt_fluid.min(self.max_dt)
                );
            }
            self.dt_contact = self.dt_contact.min(dt);
        }
    }

    /// The nodes answered `step`: count their sub-steps, take the fluid's new stable step, and move on to the end
    /// of the step.
    pub fn advance(&mut self, step: &Step, round: &Round, summary: &mut Summary) {
        if let Some(state) = &round.fem {
            summary.fem_substeps += u64::from(state.substeps);
        }
        if let Some(state) = &round.sph {
            self.dt_fluid = state.dt_stable;
            summary.sph_substeps += u64::from(state.substeps);
        }
        self.t = if step.lands { step.target } else { self.t + step.dt };
        summary.steps = self.step;
        summary.sim_time = self.t;
    }

    /// The output step `step` was sampled: the next output time is the one after its target.
    pub fn sampled(&mut self, step: &Step) {
        if step.target >= self.next_output as f64 * self.interval {
            self.next_output += 1;
        }
    }
}
