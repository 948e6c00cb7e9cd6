//! `[coupling]`: the coupling step and how long a node may take to answer it.

use serde::{Deserialize, Serialize};

use super::{ContactAlgorithm, FluidSolver, Scene};

/// `[coupling]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CouplingSpec {
    /// Cap on the coupling step \[s\].
    #[serde(default = "default_max_dt")]
    pub max_dt: f64,
    /// Safety factor on the FEM stable step, Δt_fem = fem_cfl · min_e(L_e / c_d).
    #[serde(default = "default_fem_cfl")]
    pub fem_cfl: f64,
    /// Seconds a node may take to answer one step before the run fails.
    #[serde(default = "default_step_timeout")]
    pub step_timeout: f64,
    /// The structure's Courant number: with the `particle_element` contact a coupling step is at most
    /// `structure_courant` · h / |v|_max, h the fluid's smoothing length and |v|_max the fastest interface node at the
    /// end of the last step, so that the structure's surface moves at most that fraction of h between two contact
    /// passes (docs/CORRECTIONS.md "The coupling step
    /// bounded by the structure's speed"). In [0, 1]; 0 switches the bound off; default
    /// [`STRUCTURE_COURANT_DEFAULT`]. Not written to `scene.toml` at its default.
    #[serde(
        default = "default_structure_courant",
        skip_serializing_if = "is_default_structure_courant"
    )]
    pub structure_courant: f64,
    /// How many of the fluid's own stable steps one coupling step may span, with WCSPH and the `particle_element`
    /// contact (the fluid node sub-cycles through them, as the structure node does through its FE steps): the
    /// coupling step is then at most `fluid_substeps` − 0.05 of the fluid's last stable steps, rounded down to whole
    /// steps where `max_dt` or the structure's Courant bound caps it. 1 is the paper's lockstep, a contact pass after
    /// every fluid step (Long et al. 2016); larger values exchange and run the contact pass less often
    /// (docs/CORRECTIONS.md "The fluid sub-cycled between contact passes"). ISPH and `particle_particle` keep the
    /// lockstep. In [1, [`FLUID_SUBSTEPS_MAX`]]; default 1; not written to `scene.toml` at its default.
    #[serde(
        default = "default_fluid_substeps",
        skip_serializing_if = "is_default_fluid_substeps"
    )]
    pub fluid_substeps: u32,
}

/// The most fluid steps a coupling step may span. A WCSPH step moves a particle 0.25 h v / (c0 + v), at most 0.023 h
/// at the Mach number 0.1 WCSPH is run at (c0 ≥ 10 v_max, DESIGN.md §4.2): eight of them 0.18 h, well inside what the
/// contact catches behind a face (d_max = 2 Δx = 1.5 h). Measured up to 6 a pass, on the 1 mm gate, whose `max_dt`
/// holds no more (docs/CORRECTIONS.md "The fluid sub-cycled between contact passes").
pub const FLUID_SUBSTEPS_MAX: u32 = 8;

fn default_fluid_substeps() -> u32 {
    1
}

fn is_default_fluid_substeps(k: &u32) -> bool {
    *k == 1
}

/// The default of `coupling.structure_courant`: the largest of those measured (0.2, 0.1, 0.05) at which the ISPH
/// gate at its own step keeps its energy (docs/CORRECTIONS.md).
pub const STRUCTURE_COURANT_DEFAULT: f64 = 0.05;

/// The least `coupling.structure_courant` other than 0 (off): below it the bound makes a run crawl (50 times the
/// default's steps at 1e-3; 1e-300 took ~1e9 coupling steps a simulated millisecond), not a setting anyone means.
pub const STRUCTURE_COURANT_MIN: f64 = 1e-3;

fn default_structure_courant() -> f64 {
    STRUCTURE_COURANT_DEFAULT
}

fn is_default_structure_courant(c: &f64) -> bool {
    *c == STRUCTURE_COURANT_DEFAULT
}

fn default_max_dt() -> f64 {
    1.0e-3
}

fn default_fem_cfl() -> f64 {
    0.9
}

fn default_step_timeout() -> f64 {
    60.0
}

impl Default for CouplingSpec {
    fn default() -> Self {
        Self {
            max_dt: default_max_dt(),
            fem_cfl: default_fem_cfl(),
            step_timeout: default_step_timeout(),
            structure_courant: default_structure_courant(),
            fluid_substeps: default_fluid_substeps(),
        }
    }
}

/// How much of a fluid step a coupling step of several leaves out (`contact-broker` `Clock::fluid_span`). The fluid
/// node sub-cycles at its own stable step, full steps and a remainder (WCSPH), and its stable step shrinks a little
/// from one sub-step to the next as the flow speeds up; a coupling step of exactly k last-reported steps then took k
/// full steps and a remainder of a few ulps to a few per cent of one in most coupling steps (the shipped gate at
/// k = 4: 16,035 fluid steps against 13,479 in lockstep). n − 0.05 steps leave the last sub-step to absorb a shrink
/// of up to 1.2 % a step.
pub const SUBSTEP_SLACK: f64 = 0.05;

/// How many whole fluid steps of `dt_fluid` a coupling step within `cap` spans: the most n, up to `most`, whose
/// n − [`SUBSTEP_SLACK`] steps fit in the cap; at least 1. The rule of the broker's clock (`Clock::fluid_span`) and of
/// what `cosim check` and `cosim run` say of it.
pub fn whole_fluid_steps(cap: f64, dt_fluid: f64, most: u32) -> u32 {
    let whole = (cap / dt_fluid + SUBSTEP_SLACK).floor().min(f64::from(most));
    if whole >= 1.0 {
        whole as u32
    } else {
        1
    }
}

/// The shortest coupling step a run takes, `coupling.max_dt` / 2^32 [s]: a shorter one cannot move the run on (the
/// broker's clock refuses it), and a restored bound below it is refused (the broker's checkpoint check).
pub fn shortest_step(max_dt: f64) -> f64 {
    max_dt / 4_294_967_296.0
}

impl Scene {
    /// How many fluid steps of `dt_fluid` a coupling step spans at most: [`Scene::fluid_substeps`], fewer where
    /// `coupling.max_dt` holds fewer whole ones ([`whole_fluid_steps`]).
    pub fn fluid_steps_per_pass(&self, dt_fluid: f64) -> u32 {
        whole_fluid_steps(self.coupling.max_dt, dt_fluid, self.fluid_substeps())
    }

    /// How many of the fluid's last stable steps one coupling step may span: `coupling.fluid_substeps` with WCSPH and
    /// the particle–element contact, 1 (the paper's lockstep) otherwise. The contact corrects at each coupling step's
    /// end whatever the step made penetrate, however many fluid steps it spans (the fluid node sub-cycles through
    /// them), and a WCSPH step is set by the sound speed: its particles move 0.25 h v / (c0 + v), a fortieth of h at
    /// the Mach numbers WCSPH is run at, where the contact needs a pass every few hundredths of h. ISPH's own step
    /// already moves its fastest particle a quarter of h (DESIGN.md §4.3); `particle_particle` acts as a force, once a
    /// coupling step, which a longer step would coarsen.
    pub fn fluid_substeps(&self) -> u32 {
        match (&self.fluid, self.contact.algorithm) {
            (Some(f), ContactAlgorithm::ParticleElement) if f.solver == FluidSolver::Wcsph => {
                self.coupling.fluid_substeps
            }
            _ => 1,
        }
    }
}
