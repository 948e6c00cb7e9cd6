//! The run's clock (`DESIGN.md` §3 step 1): how long each coupling step is, and the output times the steps land
//! on.

use cosim_proto::scene::{shortest_step, whole_fluid_steps, ContactAlgorithm, Scene, SUBSTEP_SLACK};
use cosim_proto::Num;

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
    /// The longest next step the structure's speed allows [s] ([`Clock::structure_bound`]; infinite at rest).
    pub dt_structure: f64,
    /// `coupling.structure_courant` · h: how far the structure's surface may move in one step [m] (0: no bound).
    reach: f64,
    /// How many of the fluid's stable steps a coupling step may span ([`Scene::fluid_substeps`]).
    fluid_substeps: u32,
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

/// How far the structure's surface may move in one coupling step [m]: `coupling.structure_courant` · h with the
/// particle–element contact, which corrects at each step's end what the step made penetrate; 0 (no bound) otherwise.
/// `particle_particle` corrects nothing: its force acts, and its step is bounded by the force's stiffness (WCSPH,
/// [`crate::contact_step`]) or its reaction relaxed (ISPH); the ISPH + `particle_particle` gate bounded by the
/// structure's speed took three times the steps and heated its mesh as much (docs/CORRECTIONS.md).
fn structure_reach(scene: &Scene) -> f64 {
    match (&scene.fluid, scene.contact.algorithm) {
        (Some(f), ContactAlgorithm::ParticleElement) => {
            scene.coupling.structure_courant * f.smoothing_ratio * f.spacing
        }
        _ => 0.0,
    }
}

/// The first coupling step of `scene` as the broker fixes it (`cosim check`'s estimate): `structure` says whether a
/// structure node takes part, `dt_fluid` is the fluid's first stable step (infinite without a fluid).
pub fn first_step(scene: &Scene, structure: bool, dt_fluid: f64) -> f64 {
    Clock::new(scene, structure, dt_fluid).next_step().dt
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
            dt_structure: f64::INFINITY,
            reach: structure_reach(scene),
            fluid_substeps: scene.fluid_substeps(),
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

    /// Fix the next coupling step: the fluid's stable step (or several, [`Clock::fluid_span`]), the contact's and the
    /// structure's, capped by the user and the next output time. Without a structure there is nothing to couple: the
    /// fluid node sub-cycles at its own stable step.
    pub fn next_step(&mut self) -> Step {
        let target = (self.next_output as f64 * self.interval).min(self.end);
        let cap = if self.structure {
            self.fluid_span(self.max_dt.min(self.dt_contact).min(self.dt_structure))
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

    /// The coupling step within `cap` (the user's, the contact's and the structure's bounds) that spans whole
    /// fluid steps: lockstep, min(cap, Δt_fluid), where the scene's fluid sub-steps in force
    /// ([`Scene::fluid_substeps`]) are 1 or the cap holds fewer than two fluid steps; otherwise n − [`SUBSTEP_SLACK`]
    /// fluid steps, n the most of them, up to k, that fit in the cap (a cap of 3.3 steps gives 2.95, which the fluid
    /// takes in 3 sub-steps, where 3.3 would take 4).
    fn fluid_span(&self, cap: f64) -> f64 {
        let whole = whole_fluid_steps(cap, self.dt_fluid, self.fluid_substeps);
        if whole >= 2 {
            (f64::from(whole) - SUBSTEP_SLACK) * self.dt_fluid
        } else {
            cap.min(self.dt_fluid)
        }
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

    /// The next step from the interface nodes' velocities `v` at the end of the last one: at most
    /// `coupling.structure_courant` · h / |v|_max, so that the surface moves at most that fraction of the fluid's
    /// smoothing length between two contact passes. The contact corrects what the surface's motion over a step made
    /// penetrate, in one pass at the step's end; a surface that moves a large part of h in a step (an ISPH step on
    /// the elastic gate spans ~115 of its FE steps, and the gate's surface rings at the mesh's own frequencies) makes
    /// corrections of that size, and the coupled energy grows (docs/CORRECTIONS.md "The coupling step bounded by the
    /// structure's speed"). Not kept from step to step: the bound follows the structure.
    fn structure_bound(&mut self, v: &[[f64; 2]]) {
        if self.reach <= 0.0 {
            return;
        }
        let speed = v.iter().map(|v| v[0].hypot(v[1])).fold(0.0, f64::max);
        self.dt_structure = if speed > 0.0 { self.reach / speed } else { f64::INFINITY };
    }

    /// The nodes answered `step`: count their sub-steps, take the fluid's new stable step, and move on to the end
    /// of the step.
    pub fn advance(&mut self, step: &Step, round: &Round, summary: &mut Summary) {
        if let Some(state) = &round.fem {
            summary.fem_substeps += u64::from(state.substeps);
            self.structure_bound(&state.v);
        }
        if let Some(state) = &round.sph {
            self.dt_fluid = state.dt_stable;
            summary.sph_substeps += u64::from(state.substeps);
        }
        self.t = if step.lands { step.target } else { self.t + step.dt };
        summary.steps = self.step;
        summary.sim_time = self.t;
    }

    /// A step that cannot move the run on: one shorter than `coupling.max_dt` / 2^32, or too short to advance `t` in
    /// double precision. A node's stable step or speed collapsed (or a restored bound did), and the run would take
    /// steps for ever at a frozen time; it ends `unstable`, naming the node and the value that set the step (the
    /// fluid node ends its own run the same way where one coupling step would take it 2^32 of its steps).
    pub fn check_step(&self, step: &Step) -> Result<(), crate::link::LinkError> {
        let floor = shortest_step(self.max_dt);
        if step.lands || (step.dt >= floor && self.t + step.dt > self.t) {
            return Ok(());
        }
        let (node, what, value) = [
            ("sph-node", "sph/state dt_stable", self.dt_fluid),
            ("contact-broker", "the contact's bound on the step", self.dt_contact),
            (
                "fem-node",
                "the bound its fem/state v sets on the step",
                self.dt_structure,
            ),
        ]
        .into_iter()
        .min_by(|a, b| a.2.total_cmp(&b.2))
        .expect("three bounds");
        Err(crate::link::LinkError::Unstable {
            node: node.into(),
            message: format!(
                "the coupling step collapsed to {} s at t = {} s, under coupling.max_dt / 2^32 = {} s or too short to \
                 advance the time: {what} = {} s",
                Num(step.dt),
                Num(self.t),
                Num(floor),
                Num(value)
            ),
        })
    }

    /// The output step `step` was sampled: the next output time is the one after its target.
    pub fn sampled(&mut self, step: &Step) {
        if step.target >= self.next_output as f64 * self.interval {
            self.next_output += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use cosim_proto::messages::FemState;
    use cosim_proto::scene::parse;

    use super::*;

    fn gate(sets: &[&str]) -> Scene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/elastic_gate.toml");
        let text = std::fs::read_to_string(path).unwrap();
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        parse("gate.toml", &text, &sets).unwrap()
    }

    /// The next step after the structure answered with interface velocities `v`, on a clock whose fluid and user
    /// allow 1 s.
    fn step_after(scene: &Scene, v: Vec<[f64; 2]>) -> f64 {
        let mut clock = Clock::new(scene, true, 1.0);
        (clock.max_dt, clock.end, clock.interval) = (1.0, 100.0, 1000.0);
        let first = clock.next_step();
        let fem = FemState {
            ids: Vec::new(),
            x: vec![[0.0; 2]; v.len()],
            v,
            substeps: 1,
            dt_stable: 1.0,
            compute_seconds: 0.0,
            snapshot: None,
        };
        let round = Round {
            fem: Some(fem),
            sph: None,
        };
        clock.advance(&first, &round, &mut Summary::failed("r", "in-process", String::new()));
        clock.next_step().dt
    }

    #[test]
    fn the_structures_speed_bounds_the_next_step_with_the_particle_element_contact() {
        // h = 1.3 × 2 mm; the fastest node (3, 4) m/s moves 0.05 h in 0.05 h / 5 s.
        let scene = gate(&[]);
        let v = vec![[0.1, 0.0], [3.0, -4.0], [-1.0, 2.0]];
        assert_eq!(step_after(&scene, v.clone()), 0.05 * (1.3 * 0.002) / 5.0);
        let half = gate(&["coupling.structure_courant=0.025"]);
        assert_eq!(step_after(&half, v.clone()), 0.025 * (1.3 * 0.002) / 5.0);
        // At rest, switched off, or with a contact that corrects nothing: no bound.
        assert_eq!(step_after(&scene, vec![[0.0; 2]; 3]), 1.0);
        assert_eq!(step_after(&gate(&["coupling.structure_courant=0"]), v.clone()), 1.0);
        assert_eq!(
            step_after(&gate(&["contact.algorithm=particle_particle"]), v.clone()),
            1.0
        );
        assert_eq!(step_after(&gate(&["contact.algorithm=none"]), v), 1.0);
    }

    #[test]
    fn a_coupling_step_spans_the_fluid_substeps_with_wcsph_and_particle_element_only() {
        // The fluid's stable step 1e-5 s; the user's cap and the output times far away.
        let first = |sets: &[&str]| {
            let mut clock = Clock::new(&gate(sets), true, 1e-5);
            (clock.max_dt, clock.end, clock.interval) = (1.0, 100.0, 1000.0);
            clock.next_step().dt
        };
        assert_eq!(first(&["coupling.fluid_substeps=1"]), 1e-5);
        // The shipped gate takes 8.
        assert_eq!(first(&[]), (8.0 - SUBSTEP_SLACK) * 1e-5);
        assert_eq!(first(&["coupling.fluid_substeps=3"]), (3.0 - SUBSTEP_SLACK) * 1e-5);
        assert_eq!(first(&["coupling.fluid_substeps=4"]), (4.0 - SUBSTEP_SLACK) * 1e-5);
        // particle_particle acts as a force once a coupling step, ISPH's own step is long: the paper's lockstep
        // whatever the key says.
        assert_eq!(
            first(&["coupling.fluid_substeps=4", "contact.algorithm=particle_particle"]),
            1e-5
        );
        assert_eq!(first(&["coupling.fluid_substeps=4", "fluid.solver=\"isph\""]), 1e-5);
        // A cap between whole fluid steps is rounded down to them: coupling.max_dt = 3.3 fluid steps gives 2.95 (three
        // sub-steps, where 3.3 would take four), 1.5 gives one (lockstep).
        let capped = |max_dt: f64, v: Option<[f64; 2]>| {
            let mut clock = Clock::new(&gate(&["coupling.fluid_substeps=4"]), true, 1e-5);
            (clock.max_dt, clock.end, clock.interval) = (max_dt, 100.0, 1000.0);
            if let Some(v) = v {
                clock.structure_bound(&[v]);
            }
            clock.next_step().dt
        };
        assert_eq!(capped(3.3e-5, None), (3.0 - SUBSTEP_SLACK) * 1e-5);
        assert_eq!(capped(1.5e-5, None), 1e-5);
        assert_eq!(capped(0.5e-5, None), 0.5e-5);
        // The structure's Courant bound caps it as well: 0.05 h / 5 m/s = 2.6e-5 s, 2.6 fluid steps: 1.95 of them.
        assert_eq!(capped(1.0, Some([3.0, -4.0])), (2.0 - SUBSTEP_SLACK) * 1e-5);
        // Without a fluid (an infinite stable step) the cap is the step.
        let mut clock = Clock::new(&gate(&["coupling.fluid_substeps=4"]), true, f64::INFINITY);
        (clock.max_dt, clock.end, clock.interval) = (2e-5, 100.0, 1000.0);
        assert_eq!(clock.next_step().dt, 2e-5);
    }
}
