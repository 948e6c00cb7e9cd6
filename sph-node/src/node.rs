//! The SPH node's adapter to the shared serving loop (`cosim_bus::serve`).

use cosim_bus::serve::{Failure, NodeCore};
use cosim_proto::messages::{SphSetup, SphState, StepCommand};

use crate::core::SphCore;
use crate::error::SphError;

impl From<SphError> for Failure {
    fn from(e: SphError) -> Self {
        Failure {
            unstable: e.is_unstable(),
            message: e.to_string(),
        }
    }
}

impl NodeCore for SphCore {
    type Setup = SphSetup;
    type State = SphState;

    fn setup(&self) -> &SphSetup {
        SphCore::setup(self)
    }

    fn handle(&mut self, cmd: &StepCommand) -> Result<Option<SphState>, Failure> {
        SphCore::handle(self, cmd).map_err(Failure::from)
    }

    fn counts(&self) -> Vec<(&'static str, u64)> {
        let s = SphCore::setup(self);
        let mut counts = vec![
            ("particles", u64::from(s.particles)),
            ("wall_particles", s.walls.len() as u64),
        ];
        // The WCSPH wall guard's interventions so far (refreshed with the energies).
        counts.extend(self.solver().wall_pushes().map(|n| ("wall_pushes", n)));
        counts
    }

    fn energy(&self) -> Vec<(&'static str, f64)> {
        let state = self.solver().state();
        vec![
            ("kinetic", state.kinetic_energy()),
            ("potential", state.potential_energy(self.solver().params().gravity)),
        ]
    }

    fn checkpoint(&self) -> Option<Vec<u8>> {
        Some(SphCore::checkpoint(self))
    }

    fn time(&self) -> Option<f64> {
        Some(self.solver().state().t)
    }

    fn restore(&mut self, data: &[u8]) -> Result<(), Failure> {
        SphCore::restore(self, data).map_err(Failure::from)
    }
}
