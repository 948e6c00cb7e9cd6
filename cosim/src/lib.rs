//! The `cosim` command: launches a scene as processes or in one process (`run`), validates it (`check`).
#![warn(missing_docs)]

pub mod check;
pub mod cli;
pub mod in_process;
pub mod launch;
pub mod progress;
pub mod run;
