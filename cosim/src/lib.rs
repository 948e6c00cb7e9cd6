//! The `cosim` command: launches a scene as processes or in one process (`run`), validates it (`check`),
//! overlays a probe of several runs (`compare`), measures run time against error over a suite of scenes (`bench`),
//! shows a running run's status (`inspect`), serves as the zenoh router of a run over several hosts (`router`),
//! runs one node again on a recorded run's messages (`replay`), pauses and steps a live run (`ctl`) and writes its
//! state now (`snapshot`).
#![warn(missing_docs)]

pub mod bench;
pub mod check;
pub mod child_log;
pub mod cli;
pub mod closed_stdout;
pub mod compare;
pub mod ctl;
pub mod estimate;
pub mod in_process;
pub mod inspect;
pub mod join;
pub mod launch;
pub mod look;
pub mod progress;
pub mod registry;
pub mod replay;
pub mod router;
pub mod run;
pub mod snapshot;
