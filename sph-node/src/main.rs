//! `sph-node`: the fluid solver as its own process (`sph-node --run ID --connect ENDPOINT`).

use cosim_bus::serve::Failure;
use sph_node::core::SphCore;

fn main() {
    cosim_bus::cli::node_main(cosim_proto::keys::SPH, |scene| {
        SphCore::new(scene).map_err(Failure::from)
    })
}
