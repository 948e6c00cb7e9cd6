//! Shepard density filter (`DESIGN.md` §4.4): ρ_i = Σ_j m_j W_ij / Σ_j (m_j/ρ_j) W_ij over the fluid particles
//! (self included), applied every N steps.

use rayon::prelude::*;

use crate::kernel::CubicSpline;
use crate::neighbors::NeighborList;
use crate::particles::{separation, ParticleView};

/// Filtered density of fluid particle i.
#[inline]
pub fn shepard_density(i: usize, view: &ParticleView<'_>, neighbors: &[u32], kernel: &CubicSpline) -> f64 {
    let w0 = kernel.w(0.0);
    let mut num = view.m[i] * w0;
    let mut den = view.m[i] / view.rho[i] * w0;
    for &j in neighbors {
        let j = j as usize;
        if j >= view.n_fluid {
            continue;
        }
        let (_, r) = separation(view.x[i], view.x[j]);
        let w = kernel.w(r);
        // §4.4 Shepard filter
        num += view.m[j] * w;
        den += view.m[j] / view.rho[j] * w;
    }
    num / den
}

/// Filtered densities of every fluid particle into `out`.
pub fn shepard_into(view: &ParticleView<'_>, list: &NeighborList, kernel: &CubicSpline, out: &mut Vec<f64>) {
    out.clear();
    (0..view.n_fluid)
        .into_par_iter()
        .map(|i| shepard_density(i, view, list.of(i), kernel))
        .collect_into_vec(out);
}
