//! Every node in this process: the coordinator calls the FEM node's handler directly.

use contact_broker::link::{FemLink, LinkError};
use cosim_proto::messages::{FemMesh, FemState, StepCommand};
use fem_node::core::FemCore;

/// The FEM node, in this process.
pub struct InProcessFem {
    core: FemCore,
}

impl InProcessFem {
    /// Wrap a built node.
    pub fn new(core: FemCore) -> Self {
        Self { core }
    }
}

impl FemLink for InProcessFem {
    fn mesh(&self) -> &FemMesh {
        self.core.mesh()
    }

    fn exchange(&mut self, _step: u64, _t: f64, cmd: StepCommand) -> Result<Option<FemState>, LinkError> {
        self.core.handle(&cmd).map_err(|e| {
            let (node, message) = ("fem-node".to_string(), e.to_string());
            if e.is_unstable() {
                LinkError::Unstable { node, message }
            } else {
                LinkError::Failed { node, message }
            }
        })
    }
}
