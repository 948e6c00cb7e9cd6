//! The zenoh side of the co-simulation's processes, shared by every node binary and the broker: session
//! settings (`session`), the loop a solver node runs to serve a run (`serve`) and the live status every process
//! answers queries with (`status`). Solver libraries never see it.
#![warn(missing_docs)]

pub mod cli;
pub mod serve;
pub mod session;
pub mod status;
