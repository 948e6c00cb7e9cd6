//! Continuity equation, Eq. (9) of Long et al. 2016: Dρ_i/Dt = ρ_i Σ_j (m_j/ρ_j) (v_i − v_j) · ∇_i W_ij.

use super::density_diffusion::DensityDiffusion;
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
    rate_and_shift::<false>(i, view, vol, neighbors, grad, diffusion, &[]).0
}

/// ½ Δt Dρ_i/Dt ([`density_rate`]) plus the density change of the APD shifts `shift` (every fluid particle's;
/// walls do not move) as the continuity equation gives it for a displacement, δρ_i = Σ_j m_j (δr_i − δr_j)·∇_i W_ij
/// ([`crate::corrections::apd::shift_density_change`]), in one loop over the pairs: the shift of the drift just
/// made, taken at the positions after it, in the pass that follows the search anyway (issue 20).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn density_increment(
    i: usize,
    view: &ParticleView<'_>,
    vol: &[f64],
    neighbors: &[u32],
    grad: &[f64],
    diffusion: Option<&DensityDiffusion>,
    shift: &[[f64; 2]],
    dt: f64,
) -> f64 {
    let (rate, moved) = rate_and_shift::<true>(i, view, vol, neighbors, grad, diffusion, shift);
    0.5 * dt * rate + moved
}

/// (Dρ_i/Dt, and with `SHIFT` the density change Σ_j m_j (δr_i − δr_j)·∇_i W_ij of the displacements `shift`).
#[inline(always)]
fn rate_and_shift<const SHIFT: bool>(
    i: usize,
    view: &ParticleView<'_>,
    vol: &[f64],
    neighbors: &[u32],
    grad: &[f64],
    diffusion: Option<&DensityDiffusion>,
    shift: &[[f64; 2]],
) -> (f64, f64) {
    let (xi, vi, rho_i) = (view.x[i], view.v[i], view.rho[i]);
    let di = if SHIFT { shift[i] } else { [0.0, 0.0] };
    let mut sum = 0.0;
    let mut diff = 0.0;
    let mut moved = 0.0;
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
        if SHIFT {
            let dj = if j < view.n_fluid { shift[j] } else { [0.0, 0.0] };
            // Eq. (9) with the displacement δr in place of v Δt (apd::shift_density_change)
            moved += view.m[j] * dot([di[0] - dj[0], di[1] - dj[1]], grad);
        }
    }
    let rate = match diffusion {
        Some(d) => rho_i * sum - d.coef * diff, // Eq. (9), Long et al. 2016, + D_i
        None => rho_i * sum,                    // Eq. (9), Long et al. 2016
    };
    (rate, moved)
}
