//! The WCSPH solver as the node drives it: [`crate::FluidSolver`].

use super::WcsphSolver;
use crate::error::Result;
use crate::fluid_solver::{FluidSolver, SavedSolver};
use crate::params::SphParams;
use crate::particles::{FluidState, WallParticles};

impl FluidSolver for WcsphSolver {
    fn name(&self) -> &'static str {
        "wcsph"
    }

    fn params(&self) -> &SphParams {
        WcsphSolver::params(self)
    }

    fn state(&self) -> &FluidState {
        WcsphSolver::state(self)
    }

    fn state_mut(&mut self) -> &mut FluidState {
        WcsphSolver::state_mut(self)
    }

    fn walls(&self) -> &WallParticles {
        WcsphSolver::walls(self)
    }

    fn stable_dt(&self) -> f64 {
        WcsphSolver::stable_dt(self)
    }

    fn step(&mut self, dt: f64) -> Result<()> {
        WcsphSolver::step(self, dt)
    }

    fn wall_pushes(&self) -> Option<u64> {
        Some(self.wall_pushes.0)
    }

    fn save(&self) -> SavedSolver {
        self.save_state()
    }

    fn restore(&mut self, saved: SavedSolver) -> std::result::Result<(), String> {
        self.restore_state(saved)
    }
}
