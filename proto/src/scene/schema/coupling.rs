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
    /// The structure's Courant number: with the `particle_element` contact a coupling step is at most
    /// `structure_courant` · h / |v|_max, h the fluid's smoothing length and |v|_max the fastest interface node at the
    /// end of the last step, so that the structure's surface moves at most that fraction of h between two contact
    /// passes (docs/CORRECTIONS.md "The coupling step
    /// bounded by the structure's speed"). In [0, 1]; 0 switches the bound off; default
    /// [`STRUCTURE_COURANT_DEFAULT`]. Not written to `scene.toml` at its default.
    #[serde(
        default = "default_structure_courant",
        skip_serializing_if = "is_default_structure_courant"
    )]
    pub structure_courant: f64,
}

/// The default of `coupling.structure_courant`: the largest of those measured (0.2, 0.1, 0.05) at which the ISPH
/// gate at its own step keeps its energy (docs/CORRECTIONS.md).
pub const STRUCTURE_COURANT_DEFAULT: f64 = 0.05;

fn default_structure_courant() -> f64 {
    STRUCTURE_COURANT_DEFAULT
}

fn is_default_structure_courant(c: &f64) -> bool {
    *c == STRUCTURE_COURANT_DEFAULT
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
            structure_courant: default_structure_courant(),
        }
    }
}
