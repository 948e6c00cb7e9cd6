//! Every node in this process: the coordinator calls the nodes' handlers directly — the same handlers the node
//! binaries serve over zenoh (`cosim_bus::serve::NodeCore`).

use contact_broker::link::{InProcess, LinkError, Reply};
use cosim_bus::serve::NodeCore;

/// A node, in this process; `name` labels its errors.
pub fn link<C>(name: &'static str, core: C) -> InProcess<C::Setup, C::State>
where
    C: NodeCore + 'static,
    C::Setup: Clone,
    C::State: Reply,
{
    let setup = core.setup().clone();
    let mut core = core;
    InProcess::new(setup, move |cmd| {
        core.handle(cmd).map_err(|f| match f.unstable {
            true => LinkError::Unstable {
                node: name.into(),
                message: f.message,
            },
            false => LinkError::Failed {
                node: name.into(),
                message: f.message,
            },
        })
    })
}
