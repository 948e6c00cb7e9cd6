//! Explicit 2D (plane strain) finite element solver for the structures of the FEM–SPH co-simulation
//! (`DESIGN.md` §4.1; Long et al. 2016, Eqs. (1)–(6)), as a pure library: it knows nothing of zenoh, files or
//! the clock.
//!
//! * [`mesh`]: structured meshes of the scene's rectangles; [`model::FemModel`]: the immutable model.
//! * [`element`]: one-point quads with physical hourglass stabilisation, constant-strain triangles.
//! * [`material`]: corotational linear elastic, neo-Hookean, St. Venant–Kirchhoff.
//! * [`solver`]: stable step, central difference (kick–drift–kick), [`FemSolver`] with sub-cycling.
//! * [`state::FemState`]: the serializable state, kept apart from per-step scratch.
//! * [`walls`]: the tank's walls, which stop the structure's nodes inside every sub-step.
#![warn(missing_docs)]

pub mod core;
pub mod element;
pub mod error;
pub mod kinematics;
pub mod material;
pub mod mesh;
pub mod model;
pub mod node;
pub mod solver;
pub mod state;
pub mod walls;

pub use error::{FemError, Result};
pub use model::FemModel;
pub use solver::FemSolver;
pub use state::{FemScratch, FemState};
