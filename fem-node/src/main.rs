//! `fem-node`: the structure solver as its own process (`fem-node --run ID --connect ENDPOINT`).

use cosim_bus::serve::Failure;
use cosim_proto::sizing::Part;
use fem_node::core::FemCore;

fn main() {
    cosim_bus::cli::node_main(cosim_proto::keys::FEM, |scene| {
        // Sized before anything is built: a scene too big for this machine fails with one line, not an abort.
        cosim_bus::memory::node_fits(scene, Part::Structure)?;
        FemCore::new(scene).map_err(Failure::from)
    })
}
