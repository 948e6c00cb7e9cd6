//! What a run is given: its nodes, how it was launched, and its checkpoint plan.

use std::path::PathBuf;

use crate::checkpoint::BrokerState;
use crate::link::{FemLink, SphLink};

/// How the run is launched, for the summary.
#[derive(Clone, Debug)]
pub struct RunInfo {
    /// Run id.
    pub run_id: String,
    /// `processes` | `in-process`.
    pub mode: String,
    /// Output folder.
    pub out: PathBuf,
}

/// The nodes of a run; a scene without fluid has no fluid node and vice versa.
pub struct Nodes<'a> {
    /// The structure node.
    pub fem: Option<&'a mut FemLink>,
    /// The fluid node.
    pub sph: Option<&'a mut SphLink>,
}

/// Checkpoints to write, and the one to continue from.
#[derive(Debug, Default)]
pub struct Checkpoints {
    /// Write `DIR/checkpoints/<step>/` at the first step at or after every multiple of this simulated time [s].
    pub interval: Option<f64>,
    /// Continue from this checkpoint's coordinator state (the nodes were given theirs when they started).
    pub restart: Option<BrokerState>,
}
