//! The FEM node's adapter to the shared serving loop (`cosim_bus::serve`).

use cosim_bus::serve::{Failure, NodeCore};
use cosim_proto::messages::{FemMesh, FemState, StepCommand};

use crate::core::FemCore;
use crate::error::FemError;

impl From<FemError> for Failure {
    fn from(e: FemError) -> Self {
        Failure {
            unstable: e.is_unstable(),
            message: e.to_string(),
        }
    }
}

impl NodeCore for FemCore {
    type Setup = FemMesh;
    type State = FemState;

    fn setup(&self) -> &FemMesh {
        self.mesh()
    }

    fn handle(&mut self, cmd: &StepCommand) -> Result<Option<FemState>, Failure> {
        FemCore::handle(self, cmd).map_err(Failure::from)
    }

    fn counts(&self) -> Vec<(&'static str, u64)> {
        let m = self.mesh();
        vec![
            ("nodes", m.nodes.len() as u64),
            ("elements", m.cells.len() as u64),
            ("interface_segments", m.interface.len() as u64),
        ]
    }

    fn energy(&self) -> Vec<(&'static str, f64)> {
        let e = self.solver().energies();
        let sum = |f: fn(&cosim_proto::messages::Energies) -> f64| e.iter().map(f).sum::<f64>();
        vec![
            ("kinetic", sum(|e| e.kinetic)),
            ("strain", sum(|e| e.strain)),
            ("potential", sum(|e| e.potential)),
        ]
    }

    fn checkpoint(&self) -> Option<Vec<u8>> {
        Some(FemCore::checkpoint(self))
    }

    fn time(&self) -> Option<f64> {
        Some(self.solver().state().t)
    }

    fn restore(&mut self, data: &[u8]) -> Result<(), Failure> {
        FemCore::restore(self, data).map_err(Failure::from)
    }
}
