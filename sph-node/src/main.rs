//! `sph-node`: the fluid solver as its own process (`sph-node --run ID --connect ENDPOINT`).

use cosim_bus::serve::Failure;
use cosim_proto::sizing::Part;
use sph_node::core::SphCore;

fn main() {
    cosim_bus::cli::node_main(cosim_proto::keys::SPH, |scene| {
        // Sized before anything is built: a scene too big for this machine fails with one line, not an abort.
        cosim_bus::memory::node_fits(scene, Part::Fluid)?;
        SphCore::new(scene).map_err(Failure::from)
    })
}
