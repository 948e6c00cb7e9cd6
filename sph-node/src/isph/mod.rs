//! Incompressible SPH by the projection method (`DESIGN.md` §4.3; Cummins & Rudman 1999, J. Comput. Phys.
//! 152:584; Shao & Lo 2003, Adv. Water Resour. 26:787), with Adami et al. 2012 walls (§4.7).
//!
//! * [`free_surface`]: the divergence of position ∇·r that marks free-surface particles (p = 0).
//! * [`projection`]: the per-particle gathers of the predictor, the PPE source and the corrector.
//! * [`ppe`]: the pressure Poisson equation assembled as sparse rows from the neighbour lists.
//! * [`bicgstab`]: BiCGSTAB on the Jacobi-scaled system, right-preconditioned, with fixed-order (thread-count
//!   independent) reductions; [`multigrid`]: its aggregation multigrid preconditioner.
//! * [`contact`]: the particles against a structure the fluid does not see (coupled runs): Neumann rows, not a free
//!   surface.
//! * [`crate::boundary::wall_guard`]: a particle found inside a wall is put back on its face.
//! * [`wall_normal`]: the projection's wall condition u^{n+1} · n = 0 in the wall rows and the walls' velocity in
//!   ∇·u*.
//! * [`solver`]: [`IsphSolver`], with the public API of [`crate::WcsphSolver`].
//!
//! Walls are PPE unknowns: each wall particle has the row of the Adami et al. 2012 extrapolation, Eq. (27),
//! p_w − Σ_f p_f W_wf / Σ_f W_wf = g · Σ_f ρ_f r_wf W_wf / Σ_f W_wf + the fluid's normal motion, a discrete Neumann
//! condition ∂p/∂n = ρ u* · n/Δt ([`wall_normal`]), so the hydrostatic pressure is right at the wall and the
//! corrected velocity does not enter it. In ∇·u* the walls carry Δt g (the predictor applied to them) plus the
//! normal part of the fluid's motion next to them, so the flux into the wall is imposed once, by the Neumann rows.
//! After the solve negative pressures are clipped to 0 (fluid and walls).
//!
//! An interior fluid row whose support the void cuts (no fluid or wall particle there) counts the void as p = 0, as
//! the corrector's symmetric gradient does ([`ppe::fluid_row`]): otherwise the PPE gives such a particle the
//! pressure of a closed box and the gradient throws it into the void, creating energy.

use serde::{Deserialize, Serialize};
pub mod bicgstab;
pub mod contact;
pub mod free_surface;
#[cfg(test)]
mod lattice;
pub mod multigrid;
pub mod ppe;
pub mod projection;
pub mod solver;
pub mod sparse;
pub mod wall_normal;

pub use solver::IsphSolver;

/// Right-hand side of the pressure Poisson equation (`DESIGN.md` §4.3, step 2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum PpeSource {
    /// ∇·u*_i / Δt (Cummins & Rudman 1999): the corrected velocity is divergence-free.
    #[default]
    DivergenceFree,
    /// (ρ0 − ρ*_i)/(ρ0 Δt²) (Shao & Lo 2003): the density of the predicted positions returns to ρ0.
    DensityInvariant,
}

/// Preconditioner of the PPE's BiCGSTAB ([`bicgstab`]); both solve to the same tolerance on the same residual.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Preconditioning {
    /// Jacobi only (the rows scaled to a unit diagonal): iterations grow with the resolution.
    Jacobi,
    /// One V-cycle of aggregation multigrid ([`multigrid`]).
    #[default]
    Multigrid,
}

/// Settings of the ISPH solver that the scene does not carry.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct IsphOptions {
    /// PPE source term.
    pub source: PpeSource,
    /// γ of the stabilised divergence-free source (Asai et al. 2012, J. Appl. Math. 2012:139583, Eq. (25)):
    /// ∇·u*/Δt + γ (ρ0 − ρ*)/(ρ0 Δt²); it pulls the density back to ρ0 against the volume drift of the pure
    /// divergence-free source. Ignored for [`PpeSource::DensityInvariant`]; 0 gives the pure Cummins & Rudman
    /// source. Default 0.01 (Asai et al.'s value): without it the still-water column loses 2 % of its volume in 2 s
    /// and the pressure 0.2 m below the surface is 5 % low; with it, 1 %.
    pub density_relaxation: f64,
    /// Preconditioner of the PPE's BiCGSTAB.
    #[serde(default)]
    pub preconditioner: Preconditioning,
    /// Relative tolerance of the Jacobi-preconditioned residual, ‖D⁻¹(b − A p)‖₂ ≤ tol ‖D⁻¹ b‖₂ (the scene's
    /// `fluid.ppe_tolerance`; default [`cosim_proto::scene::ISPH_PPE_TOLERANCE_DEFAULT`]).
    pub tolerance: f64,
    /// BiCGSTAB iterations before [`crate::SphError::PpeNotConverged`].
    pub max_iterations: usize,
    /// C of Δt = C h / v_max (`DESIGN.md` §4.3, step 6: 0.1–0.25).
    pub courant: f64,
    /// Particles with ∇·r below this are free-surface particles (2D: 1.5, Lo & Shao 2002); the PPE rows pass from
    /// Dirichlet to Poisson over ± [`free_surface::BLEND_2D`] around it ([`free_surface::dirichlet_weight`]).
    pub free_surface_threshold: f64,
}

impl Default for IsphOptions {
    fn default() -> Self {
        Self {
            source: PpeSource::DivergenceFree,
            density_relaxation: 0.01,
            preconditioner: Preconditioning::default(),
            tolerance: cosim_proto::scene::ISPH_PPE_TOLERANCE_DEFAULT,
            max_iterations: 2000,
            courant: 0.2,
            free_surface_threshold: free_surface::THRESHOLD_2D,
        }
    }
}
