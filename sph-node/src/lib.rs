//! Weakly compressible SPH solver for the fluid of the FEM–SPH co-simulation (`DESIGN.md` §4.2, §4.4, §4.7;
//! Long et al. 2016, Eqs. (7)–(12)), as a pure library: it knows nothing of zenoh, files or the clock.
//!
//! * [`kernel`]: the 2D cubic spline kernel.
//! * [`neighbors`]: cell-linked list and fixed-order neighbour lists (gathers).
//! * [`eos`]: Tait equation of state.
//! * [`wcsph`]: the WCSPH solver and its rates: continuity Eq. (9), momentum Eq. (10), artificial viscosity Eq. (11),
//!   laminar viscosity Eq. (12); optional δ-SPH density diffusion (Molteni & Colagrossi 2009, Fourtakas et al. 2019).
//! * [`boundary`]: wall particles, the Adami et al. 2012 pressure extrapolation, the wall repulsion and guard.
//! * [`corrections`]: Shepard density filter and XSPH (§4.4).
//! * [`time_step`], [`integrator`]: stable step and kick–drift–kick.
//! * [`particles`]: serializable [`FluidState`] and [`WallParticles`], apart from scratch.
//! * [`params`]: [`SphParams`], shared by the solvers; [`setup`]: particles, walls and domain from the scene, one
//!   set-up for both solvers.
//! * [`fluid_solver`]: the [`FluidSolver`] trait the node drives; [`wcsph`]: [`WcsphSolver`]; [`isph`]:
//!   incompressible SPH by projection (§4.3), [`IsphSolver`].
//! * [`core`]: the node's message handler and its checkpoint; [`node`]: its adapter to the serving loop.
//!
//! Every per-particle loop is a gather (each particle sums its own neighbours in a fixed order), so results are
//! bit-identical for any number of rayon threads.
#![warn(missing_docs)]

pub mod boundary;
pub mod core;
pub mod corrections;
pub mod eos;
pub mod error;
pub mod fluid_solver;
pub mod gauge;
pub mod integrator;
pub mod isph;
pub mod kernel;
pub mod neighbors;
pub mod node;
pub mod params;
pub mod particles;
mod restore;
pub mod sensors;
pub mod setup;
pub mod stability;
pub mod time_step;
pub mod wcsph;

pub use error::{Result, SphError};
pub use fluid_solver::FluidSolver;
pub use isph::{IsphSolver, PpeSource};
pub use params::SphParams;
pub use particles::{FluidState, WallParticles};
pub use wcsph::{WcsphParams, WcsphSolver};
