//! Key expressions: every topic of a run lives under `cosim/<run>/` so concurrent runs never cross.

/// Topic names under `cosim/<run>/` (`DESIGN.md` §3).
pub mod topic {
    /// Broker queryable answering the validated scene (TOML text).
    pub const SCENE: &str = "scene";
    /// fem → broker, once.
    pub const FEM_MESH: &str = "fem/mesh";
    /// fem → broker, each step.
    pub const FEM_STATE: &str = "fem/state";
    /// fem → broker, when it fails.
    pub const FEM_ERROR: &str = "fem/error";
    /// broker → fem, each step.
    pub const BROKER_FEM: &str = "broker/fem";
    /// Liveliness token of the FEM node.
    pub const FEM_ALIVE: &str = "fem/alive";
    /// sph → broker, once.
    pub const SPH_SETUP: &str = "sph/setup";
    /// sph → broker, each step.
    pub const SPH_STATE: &str = "sph/state";
    /// sph → broker, when it fails.
    pub const SPH_ERROR: &str = "sph/error";
    /// broker → sph, each step.
    pub const BROKER_SPH: &str = "broker/sph";
    /// Liveliness token of the SPH node.
    pub const SPH_ALIVE: &str = "sph/alive";
    /// Liveliness token of the broker.
    pub const BROKER_ALIVE: &str = "broker/alive";
    /// Status queryable of the FEM node.
    pub const FEM_STATUS: &str = "fem/status";
    /// Status queryable of the broker.
    pub const BROKER_STATUS: &str = "broker/status";
    /// Status queryable of the SPH node.
    pub const SPH_STATUS: &str = "sph/status";
    /// Checkpoint queryable of the FEM node: its state between two steps, for `DIR/checkpoints/` (broker asks).
    pub const FEM_CHECKPOINT: &str = "fem/checkpoint";
    /// Checkpoint queryable of the SPH node.
    pub const SPH_CHECKPOINT: &str = "sph/checkpoint";
    /// Broker queryable: the state the FEM node restarts from (node asks, once, after the scene).
    pub const FEM_RESTORE: &str = "fem/restore";
    /// Broker queryable: the state the SPH node restarts from.
    pub const SPH_RESTORE: &str = "sph/restore";
    /// Broker queryable: `cosim ctl` commands (pause, resume, step, stop), JSON (`crate::control`).
    pub const BROKER_CONTROL: &str = "broker/control";
    /// Broker queryable: the run's state between two steps, for `cosim snapshot` and `cosim inspect --particle`.
    pub const BROKER_STATE: &str = "broker/state";
    /// Every status queryable of a run (`cosim/<run>/*/status`).
    pub const ANY_STATUS: &str = "*/status";
}

/// `cosim/<run>/<topic>`.
pub fn key(run: &str, topic: &str) -> String {
    format!("cosim/{run}/{topic}")
}

/// A run id is used inside key expressions: letters, digits, `-` and `_` only.
pub fn valid_run_id(run: &str) -> bool {
    !run.is_empty() && run.len() <= 64 && run.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
}

/// A fresh run id from the clock and the process id.
pub fn fresh_run_id() -> String {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    format!("r{:x}{:x}", nanos & 0xffff_ffff_ffff, std::process::id())
}

/// The topics of one node kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodeTopics {
    /// Name in messages (`fem-node`, `sph-node`).
    pub name: &'static str,
    /// Registration (node → broker, once).
    pub setup: &'static str,
    /// State (node → broker, each step).
    pub state: &'static str,
    /// Failure report (node → broker).
    pub error: &'static str,
    /// Commands (broker → node).
    pub command: &'static str,
    /// Liveliness token.
    pub alive: &'static str,
    /// Live status queryable.
    pub status: &'static str,
    /// Checkpoint queryable (served by the node).
    pub checkpoint: &'static str,
    /// Restart state queryable (served by the broker).
    pub restore: &'static str,
    /// The file of a checkpoint folder that holds the node's state (`docs/PROTOCOL.md` §9): what the node names
    /// when it refuses the state it is given to continue from.
    pub checkpoint_file: &'static str,
}

/// The structure node's topics.
pub const FEM: NodeTopics = NodeTopics {
    name: "fem-node",
    setup: topic::FEM_MESH,
    state: topic::FEM_STATE,
    error: topic::FEM_ERROR,
    command: topic::BROKER_FEM,
    alive: topic::FEM_ALIVE,
    status: topic::FEM_STATUS,
    checkpoint: topic::FEM_CHECKPOINT,
    restore: topic::FEM_RESTORE,
    checkpoint_file: "fem.bin",
};

/// The fluid node's topics.
pub const SPH: NodeTopics = NodeTopics {
    name: "sph-node",
    setup: topic::SPH_SETUP,
    state: topic::SPH_STATE,
    error: topic::SPH_ERROR,
    command: topic::BROKER_SPH,
    alive: topic::SPH_ALIVE,
    status: topic::SPH_STATUS,
    checkpoint: topic::SPH_CHECKPOINT,
    restore: topic::SPH_RESTORE,
    checkpoint_file: "sph.bin",
};
