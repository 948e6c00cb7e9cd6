//! [`SphParams`]: the fluid's parameters that every solver shares (what the scene's `[fluid]` and the set-up give).
//! Each solver keeps what only it uses apart ([`crate::wcsph::WcsphParams`], [`crate::isph::IsphOptions`]).

use cosim_proto::scene::BoxSpec;
use serde::{Deserialize, Serialize};

/// Resolved parameters of the fluid, common to the solvers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SphParams {
    /// Rest density ρ0.
    pub rho0: f64,
    /// Particle spacing Δx.
    pub dx: f64,
    /// Smoothing length h.
    pub h: f64,
    /// Kinematic viscosity ν.
    pub nu: f64,
    /// Gravity.
    pub gravity: [f64; 2],
    /// XSPH ε (0: off).
    pub xsph: f64,
    /// A fluid particle outside this box is unstable.
    pub domain: BoxSpec,
}
