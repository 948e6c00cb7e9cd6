//! Contact algorithms and the step coordinator of the FEM–SPH co-simulation.
//!
//! `coordinator`, `interface`, `relaxation`, `probes`, `energy_balance`, `summary` and `output` are pure (files, no
//! messaging); `setup` is the set-up of a run that `cosim run` and the `contact-broker` binary share; `transport` is
//! the zenoh adapter used by the binary.
#![warn(missing_docs)]

pub mod checkpoint;
pub mod contact;
pub mod contact_step;
pub mod coordinator;
pub mod energy_balance;
pub mod interface;
pub mod link;
pub mod load_spread;
pub mod output;
pub mod probes;
pub mod recorder;
pub mod relaxation;
pub mod remote_control;
pub mod served;
pub mod setup;
pub mod step_budget;
pub mod summary;
pub mod transport;
pub mod wall_contact;
pub mod wall_entry;
