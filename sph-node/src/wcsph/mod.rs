//! The weakly compressible SPH solver (`DESIGN.md` §4.2; Long et al. 2016, Eqs. (9)–(12)): [`WcsphSolver`] and its
//! step ([`solver`]), its parameters ([`params`]), its cell-sorted working copy of the particles (`sorted.rs`), and its
//! rate equations, one file each, with the optional δ-SPH density diffusion (Molteni & Colagrossi 2009, Fourtakas et
//! al. 2019).

pub mod artificial_viscosity;
pub mod continuity;
pub mod density_diffusion;
pub mod drift_pass;
pub mod laminar_viscosity;
pub mod momentum;
pub mod params;
pub mod solver;
mod sorted;

pub use density_diffusion::DensityDiffusion;
pub use momentum::MomentumParams;
pub use params::WcsphParams;
pub use solver::WcsphSolver;
