//! `[coupling]`: the coupling step and how long a node may take to answer it.

use serde::{Deserialize, Serialize};

/// `[coupling]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CouplingSpec {
    /// Cap on the coupling step \[s\].
    #[serde(default = "default_max_dt")]
    pub max_dt: f64,
    /// Safety factor on the FEM stable step, Δt_fem = fem_cfl · min_e(L_e / c_d).
    #[serde(default = "default_fem_cfl")]
    pub fem_cfl: f64,
    /// Seconds a node may take to answer one step before the run fails.
    #[serde(default = "default_step_timeout")]
    pub step_timeout: f64,
}

fn default_max_dt() -> f64 {
    1.0e-3
}

fn default_fem_cfl() -> f64 {
    0.9
}

fn default_step_timeout() -> f64 {
    60.0
}

impl Default for CouplingSpec {
    fn default() -> Self {
        Self {
            max_dt: default_max_dt(),
            fem_cfl: default_fem_cfl(),
            step_timeout: default_step_timeout(),
        }
    }
}
