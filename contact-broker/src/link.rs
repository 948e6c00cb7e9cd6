//! The coordinator's view of a solver node: send a step command, get the node's state back.
//!
//! The same coordinator drives a node in this process (a direct call) or in another process (zenoh), so the
//! physics and the outputs cannot differ between the two modes.

use cosim_proto::messages::{FemMesh, FemState, StepCommand};

/// Why a node could not answer.
#[derive(Debug, thiserror::Error)]
pub enum LinkError {
    /// The node reported a numerical blow-up.
    #[error("{node}: {message}")]
    Unstable {
        /// Node name.
        node: String,
        /// What it said.
        message: String,
    },
    /// The node failed, died, timed out or sent something unusable.
    #[error("{node}: {message}")]
    Failed {
        /// Node name.
        node: String,
        /// What went wrong.
        message: String,
    },
}

impl LinkError {
    /// `unstable` or `failed`, for `summary.json`.
    pub fn status(&self) -> &'static str {
        match self {
            LinkError::Unstable { .. } => "unstable",
            LinkError::Failed { .. } => "failed",
        }
    }
}

/// A structure node as the coordinator sees it.
pub trait FemLink {
    /// The reference mesh the node registered.
    fn mesh(&self) -> &FemMesh;

    /// Send `cmd` for coupling step `step` starting at time `t`; the node's answer, or `None` for a stop command.
    fn exchange(&mut self, step: u64, t: f64, cmd: StepCommand) -> Result<Option<FemState>, LinkError>;
}
