//! The ISPH solver as the node drives it: [`crate::FluidSolver`].

use cosim_proto::messages::ContactFace;

use super::IsphSolver;
use crate::error::Result;
use crate::fluid_solver::{FluidSolver, SavedSolver};
use crate::params::SphParams;
use crate::particles::{FluidState, WallParticles};

impl FluidSolver for IsphSolver {
    fn name(&self) -> &'static str {
        "isph"
    }

    /// Its pressure carries 1/Δt (the PPE source ∇·u*/Δt, the walls' Neumann rows): a remainder step multiplies
    /// it (`core.rs`, docs/CORRECTIONS.md "ISPH pressure").
    fn equal_substeps(&self) -> bool {
        true
    }

    fn params(&self) -> &SphParams {
        IsphSolver::params(self)
    }

    fn state(&self) -> &FluidState {
        IsphSolver::state(self)
    }

    fn state_mut(&mut self) -> &mut FluidState {
        IsphSolver::state_mut(self)
    }

    fn walls(&self) -> &WallParticles {
        IsphSolver::walls(self)
    }

    fn stable_dt(&self) -> f64 {
        IsphSolver::stable_dt(self)
    }

    /// Held for the next step's [`crate::isph::contact::ContactLayer::detect`].
    fn contact_faces(&mut self, faces: &[(usize, ContactFace)]) {
        self.contact.give(faces);
    }

    fn step(&mut self, dt: f64) -> Result<()> {
        IsphSolver::step(self, dt)
    }

    fn ppe_iterations(&self) -> Option<usize> {
        Some(self.last_ppe().iterations)
    }

    fn save(&self) -> SavedSolver {
        self.save_state()
    }

    fn restore(&mut self, saved: SavedSolver) -> std::result::Result<(), String> {
        self.restore_state(saved)
    }
}
