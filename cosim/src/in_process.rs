//! Every node in this process: the coordinator calls the nodes' handlers directly.

use contact_broker::link::{InProcess, LinkError};
use cosim_proto::messages::{FemMesh, FemState, SphSetup, SphState};
use fem_node::core::FemCore;
use sph_node::core::SphCore;

/// The structure node, in this process.
pub fn fem(core: FemCore) -> InProcess<FemMesh, FemState> {
    let setup = core.mesh().clone();
    let mut core = core;
    InProcess::new(setup, move |cmd| {
        core.handle(cmd).map_err(|e| {
            let (node, message) = ("fem-node".to_string(), e.to_string());
            if e.is_unstable() {
                LinkError::Unstable { node, message }
            } else {
                LinkError::Failed { node, message }
            }
        })
    })
}

/// The fluid node, in this process.
pub fn sph(core: SphCore) -> InProcess<SphSetup, SphState> {
    let setup = core.setup().clone();
    let mut core = core;
    InProcess::new(setup, move |cmd| {
        core.handle(cmd).map_err(|e| {
            let (node, message) = ("sph-node".to_string(), e.to_string());
            if e.is_unstable() {
                LinkError::Unstable { node, message }
            } else {
                LinkError::Failed { node, message }
            }
        })
    })
}
