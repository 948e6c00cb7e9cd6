//! Continuity equation, Eq. (9) of Long et al. 2016: Dρ_i/Dt = ρ_i Σ_j (m_j/ρ_j) (v_i − v_j) · ∇_i W_ij.

use super::density_diffusion::DensityDiffusion;
use crate::neighbors::NeighborList;
use crate::particles::{dot, ParticleView};

/// Dρ_i/Dt of fluid particle i (wall neighbours included, with their zero velocity) over its neighbours with the
/// ∇W factors of the pairs (`grad[k]`: ∇W factor of pair (i, `neighbors[k]`), see [`crate::neighbors::ListChunk`]);
/// `vol[j]` = m_j/ρ_j. With `diffusion`, the δ-SPH diffusive term D_i of the fluid–fluid pairs ([`DensityDiffusion`])
/// is added, summed in the same pass over the neighbours.
#[inline]
pub fn density_rate(
    i: usize,
    view: &ParticleView<'_>,
    vol: &[f64],
    neighbors: &[u32],
    grad: &[f64],
    diffusion: Option<&DensityDiffusion>,
) -> f64 {
    let (xi, vi, rho_i) = (view.x[i], view.v[i], view.rho[i]);
    let mut sum = 0.0;
    let mut diff = 0.0;
    for (&j, &f) in neighbors.iter().zip(grad) {
        let j = j as usize;
        let (xj, vj) = (view.x[j], view.v[j]);
        let grad = [f * (xi[0] - xj[0]), f * (xi[1] - xj[1])];
        let v_ij = [vi[0] - vj[0], vi[1] - vj[1]];
        // Eq. (9), Long et al. 2016
        sum += vol[j] * dot(v_ij, grad);
        if let Some(d) = diffusion.filter(|_| j < view.n_fluid) {
            // Molteni & Colagrossi 2009 with Fourtakas et al. 2019 (density_diffusion.rs)
            diff += d.pair(xi, xj, rho_i, view.rho[j], f, vol[j]);
        }
    }
    match diffusion {
        Some(d) => rho_i * sum - d.coef * diff, // Eq. (9), Long et al. 2016, + D_i
        None => rho_i * sum,                    // Eq. (9), Long et al. 2016
    }
}

/// Dρ/Dt of every fluid particle into `out` (a parallel gather) from lists with ∇W factors (as built by
/// [`crate::neighbors::SortedCells::build_fluid_lists`]); `vol[j]` = m_j/ρ_j; with the δ-SPH term when `diffusion`
/// is given.
pub fn density_rates_into(
    view: &ParticleView<'_>,
    vol: &[f64],
    list: &NeighborList,
    diffusion: Option<&DensityDiffusion>,
    out: &mut Vec<f64>,
) {
    list.map_pairs_into(out, |i, idx, grad| density_rate(i, view, vol, idx, grad, diffusion));
}
