//! [`FluidSolver`]: what the fluid node asks of a solver, whichever method it uses (WCSPH, [`crate::wcsph`]; ISPH,
//! [`crate::isph`]), as salva's `PressureSolver`. A third method is a folder with its step and its data and an
//! implementation of this trait; [`crate::core::solver_from_scene`] picks it by `fluid.solver`.
//!
//! A solver's state for a checkpoint is [`SavedSolver`]: the particles ([`FluidState`]), the walls, and what else
//! the method carries from one step to the next, in its own encoding. Nothing that a step rebuilds (neighbour
//! lists, cell order, scratch) is saved: [`FluidSolver::restore`] rebuilds it as a step would.

use cosim_proto::messages::ContactFace;
use serde::{de::DeserializeOwned, Deserialize, Serialize};

use crate::error::Result;
use crate::params::SphParams;
use crate::particles::{FluidState, WallParticles};

/// A fluid solver: particles, walls, and the step that advances them.
pub trait FluidSolver: Send + Sync {
    /// The method's name, as `fluid.solver` spells it.
    fn name(&self) -> &'static str;

    /// Resolved parameters shared by the methods.
    fn params(&self) -> &SphParams;

    /// Particle state (id order).
    fn state(&self) -> &FluidState;

    /// The particle state, for corrections applied from outside (contact, `DESIGN.md` §3 step 5). Positions and
    /// velocities may change; the particle count and order may not.
    fn state_mut(&mut self) -> &mut FluidState;

    /// Wall particles.
    fn walls(&self) -> &WallParticles;

    /// Stable step of the current state.
    fn stable_dt(&self) -> f64;

    /// Whether a coupling step longer than the stable step is cut into equal sub-steps rather than full steps and
    /// a remainder: a method whose pressure carries 1/Δt (ISPH) must not take a short remainder step.
    fn equal_substeps(&self) -> bool {
        false
    }
    /// The structure's faces the broker sent with the corrections just applied (`Correction::face`: a
    /// `particle_particle` pass, which changes velocities only), by particle id, for the step that follows them. A
    /// method that does not use them (WCSPH: the structure acts on it through the contact alone) ignores them.
    fn contact_faces(&mut self, _faces: &[(usize, ContactFace)]) {}

    /// Advances the fluid by `dt`. After an error the state is part-way through the step and should not be
    /// advanced further.
    fn step(&mut self, dt: f64) -> Result<()>;

    /// Fluid particles the wall guard has put back out of a wall over the run, where the method counts them over
    /// the run (WCSPH); `None` otherwise (ISPH counts per step, in its PPE report).
    fn wall_pushes(&self) -> Option<u64> {
        None
    }

    /// Iterations of the last step's pressure solve, where the method solves one (ISPH); `None` otherwise.
    fn ppe_iterations(&self) -> Option<usize> {
        None
    }

    /// The solver's state between two steps, for a checkpoint.
    fn save(&self) -> SavedSolver;

    /// Continue from `saved`, on a solver built from the same scene: what it holds is checked first (against this
    /// solver's scene, and for consistency with itself); `Err`, one line naming the field, the index and the value,
    /// leaves this solver as it was. What a step rebuilds is rebuilt from the state as the step would, so the run
    /// continues bit for bit.
    fn restore(&mut self, saved: SavedSolver) -> std::result::Result<(), String>;
}

/// A solver's state for a checkpoint (`docs/PROTOCOL.md` §9).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SavedSolver {
    /// [`FluidSolver::name`] of the solver that saved it.
    pub solver: String,
    /// The particles.
    pub state: FluidState,
    /// The walls (their pressures and densities are state for the next step).
    pub walls: WallParticles,
    /// What else the method carries from one step to the next, encoded by it ([`encode`]).
    pub own: Vec<u8>,
}

/// A method's own part of [`SavedSolver`], in the checkpoint's encoding (bincode, fixed-width integers).
pub fn encode<T: Serialize>(own: &T) -> Vec<u8> {
    bincode::serialize(own).expect("in-memory bincode encoding of plain data")
}

/// [`encode`]'s bytes read back; `Err` says why, naming `what`.
pub(crate) fn decode<T: DeserializeOwned>(what: &str, bytes: &[u8]) -> std::result::Result<T, String> {
    use bincode::Options;
    bincode::DefaultOptions::new()
        .with_fixint_encoding()
        .reject_trailing_bytes()
        .deserialize(bytes)
        .map_err(|e| format!("{what}: {e}"))
}
