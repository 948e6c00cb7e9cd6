//! Weakly compressible SPH solver for the fluid of the FEM–SPH co-simulation (`DESIGN.md` §4.2, §4.4, §4.7;
//! Long et al. 2016, Eqs. (7)–(12)), as a pure library: it knows nothing of zenoh, files or the clock.
//!
//! * [`kernel`]: the 2D cubic spline kernel.
//! * [`neighbors`]: cell-linked list and fixed-order neighbour lists (gathers).
//! * [`eos`]: Tait equation of state.
//! * [`wcsph`]: continuity Eq. (9), momentum Eq. (10), artificial viscosity Eq. (11), laminar viscosity Eq. (12);
//!   optional δ-SPH density diffusion (Molteni & Colagrossi 2009, Fourtakas et al. 2019).
//! * [`boundary`]: wall particles and the Adami et al. 2012 pressure extrapolation.
//! * [`corrections`]: Shepard density filter and XSPH (§4.4).
//! * [`time_step`], [`integrator`]: stable step and kick–drift–kick.
//! * [`particles`]: serializable [`FluidState`] and [`WallParticles`], apart from scratch.
//! * [`setup`]: particles from the scene; [`solver`]: [`WcsphSolver`].
//! * [`isph`]: incompressible SPH by projection (§4.3), [`IsphSolver`].
//!
//! Every per-particle loop is a gather (each particle sums its own neighbours in a fixed order), so results are
//! bit-identical for any number of rayon threads.
#![warn(missing_docs)]

pub mod boundary;
pub mod core;
pub mod corrections;
pub mod eos;
pub mod error;
pub mod integrator;
pub mod isph;
pub mod kernel;
pub mod neighbors;
pub mod node;
pub mod particles;
mod restore;
pub mod setup;
pub mod solver;
pub mod stability;
pub mod time_step;
pub mod wcsph;

pub use error::{Result, SphError};
pub use isph::{IsphSolver, PpeSource};
pub use particles::{FluidState, WallParticles};
pub use solver::WcsphSolver;
