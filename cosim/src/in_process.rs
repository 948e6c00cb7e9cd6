//! Every node in this process: the coordinator calls the nodes' handlers directly — the same handlers the node
//! binaries serve over zenoh (`cosim_bus::serve::NodeCore`).

use std::cell::RefCell;
use std::rc::Rc;

use contact_broker::link::{InProcess, LinkError, Reply};
use cosim_bus::serve::{counts_of, Failure, NodeCore};

/// A node, in this process; `name` labels its errors.
pub fn link<C>(name: &'static str, core: C) -> InProcess<C::Setup, C::State>
where
    C: NodeCore + 'static,
    C::Setup: Clone,
    C::State: Reply,
{
    let setup = core.setup().clone();
    let error = move |f: Failure| match f.unstable {
        true => LinkError::Unstable {
            node: name.into(),
            message: f.message,
        },
        false => LinkError::Failed {
            node: name.into(),
            message: f.message,
        },
    };
    let core = Rc::new(RefCell::new(core));
    let saving = Rc::clone(&core);
    let counting = Rc::clone(&core);
    InProcess::new(setup, move |cmd| core.borrow_mut().handle(cmd).map_err(error))
        .with_checkpoint(move || {
            saving.borrow().checkpoint().ok_or_else(|| LinkError::Failed {
                node: name.into(),
                message: "cannot save a checkpoint".into(),
            })
        })
        .with_counts(move || counts_of(&*counting.borrow()))
}
