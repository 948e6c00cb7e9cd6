//! `fem-node`: the structure solver as its own process (`fem-node --run ID --connect ENDPOINT`).

use cosim_bus::serve::Failure;
use fem_node::core::FemCore;

fn main() {
    cosim_bus::cli::node_main(cosim_proto::keys::FEM, |scene| {
        FemCore::new(scene).map_err(Failure::from)
    })
}
