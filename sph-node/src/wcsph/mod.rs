//! Weakly compressible SPH rates (`DESIGN.md` §4.2; Long et al. 2016, Eqs. (9)–(12)).

pub mod artificial_viscosity;
pub mod continuity;
pub mod laminar_viscosity;
pub mod momentum;

pub use momentum::MomentumParams;
