//! The zenoh side of the co-simulation's processes, shared by every node binary and the broker: session
//! settings (`session`), a query asked again while nobody can answer it yet (`ask`), the claim a process makes on its run id (`claim`), the loop a solver node runs to serve a
//! run (`serve`), telling a lost link from a partner gone (`link_loss`), the live status every process answers
//! queries with (`status`), the catching of Ctrl-C (`interrupt`), logging that survives a full disk (`log`) and the
//! machine's available memory a scene is sized against (`memory`), waits given in seconds (`seconds`). Solver libraries never see it.
#![warn(missing_docs)]

pub mod ask;
pub mod claim;
pub mod cli;
pub mod disk;
pub mod interrupt;
pub mod link_loss;
pub mod log;
pub mod memory;
pub mod refusals;
pub mod seconds;
pub mod serve;
pub mod session;
pub mod status;
