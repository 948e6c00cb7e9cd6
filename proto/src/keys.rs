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
    /// Liveliness token of the broker.
    pub const BROKER_ALIVE: &str = "broker/alive";
    /// Status queryable of the FEM node.
    pub const FEM_STATUS: &str = "fem/status";
    /// Status queryable of the broker.
    pub const BROKER_STATUS: &str = "broker/status";
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
