//! Free-surface detection by the divergence of position (Lo & Shao 2002; Shao & Lo 2003; `DESIGN.md` §4.3,
//! step 3): ∇·r_i = −Σ_j (m_j/ρ_j) r_ij · ∇_i W_ij, which is 2 inside the fluid in 2D and drops towards 1 at a
//! free surface. Wall particles count as matter, so the fluid next to a wall is not a free surface.

use rayon::prelude::*;

use crate::kernel::CubicSpline;
use crate::neighbors::NeighborList;
use crate::particles::{separation, ParticleView};

/// Threshold of ∇·r below which a 2D particle is on the free surface.
pub const THRESHOLD_2D: f64 = 1.5;

/// ∇·r of fluid particle i over all its neighbours (fluid and wall).
#[inline]
pub fn position_divergence(i: usize, view: &ParticleView<'_>, neighbors: &[u32], kernel: &CubicSpline) -> f64 {
    let xi = view.x[i];
    let mut s = 0.0;
    for &j in neighbors {
        let j = j as usize;
        let (_, r) = separation(xi, view.x[j]);
        // r_ij · ∇_i W_ij = r dW/dr; Shao & Lo 2003, ∇·r = −Σ_j (m_j/ρ_j) r_ij · ∇_i W_ij
        s -= view.m[j] / view.rho[j] * r * kernel.dw_dr(r);
    }
    s
}

/// Free-surface flags of every fluid particle into `out` (true: Dirichlet p = 0).
pub fn free_surface_into(
    view: &ParticleView<'_>,
    list: &NeighborList,
    kernel: &CubicSpline,
    threshold: f64,
    out: &mut Vec<bool>,
) {
    out.clear();
    (0..view.n_fluid)
        .into_par_iter()
        .map(|i| position_divergence(i, view, list.of(i), kernel) < threshold)
        .collect_into_vec(out);
}
