//! Weakly compressible SPH rates (`DESIGN.md` §4.2; Long et al. 2016, Eqs. (9)–(12)), and the optional δ-SPH
//! density diffusion (Molteni & Colagrossi 2009, Fourtakas et al. 2019).

pub mod artificial_viscosity;
pub mod continuity;
pub mod density_diffusion;
pub mod laminar_viscosity;
pub mod momentum;

pub use density_diffusion::DensityDiffusion;
pub use momentum::MomentumParams;
