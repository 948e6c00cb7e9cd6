//! Momentum equation, Eq. (10) of Long et al. 2016:
//! Dv_i/Dt = −Σ_j m_j (p_i/ρ_i² + p_j/ρ_j² + Π_ij) ∇_i W_ij + g (+ Eq. (12) when ν > 0).

use crate::kernel::CubicSpline;
use crate::neighbors::NeighborList;
use crate::particles::{dot, ParticleView};

/// Constants of the momentum equation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MomentumParams {
    /// Gravity g (m/s²).
    pub gravity: [f64; 2],
    /// α_π of Eq. (11).
    pub alpha: f64,
    /// Speed of sound c0 (c̄_ij = c0: one sound speed for all particles).
    pub c0: f64,
    /// Kinematic viscosity ν (m²/s); 0 skips the Eq. (12) loop.
    pub nu: f64,
}

/// The pairs of one particle with their precomputed ∇W factors (see [`crate::neighbors::ListChunk`]).
#[derive(Clone, Copy, Debug)]
pub struct Pairs<'a> {
    /// Neighbour indices.
    pub idx: &'a [u32],
    /// ∇W factors: ∇_i W_ij = grad · r_ij.
    pub grad: &'a [f64],
}

/// Dv_i/Dt of fluid particle i over its pairs with their ∇W factors (∇_i W_ij = grad · r_ij, see
/// [`crate::neighbors::ListChunk`]); `pr2[j]` = p_j/ρ_j².
///
/// One loop over the pairs for the pressure, the artificial viscosity (Eq. (11), [`pi_ij`]) and the laminar
/// viscosity (Eq. (12), [`morris_factor`]), with one division a pair: both viscous terms share the denominator
/// r_ij² + η², and 1/(ρ̄_ij ρ_j (r_ij² + η²)) serves both (issue 20; before, two loops, two square roots and two
/// divisions a pair: the same terms up to rounding).
///
/// [`pi_ij`]: crate::wcsph::artificial_viscosity::pi_ij
/// [`morris_factor`]: crate::wcsph::laminar_viscosity::morris_factor
#[inline]
pub fn acceleration(
    i: usize,
    view: &ParticleView<'_>,
    pr2: &[f64],
    pairs: Pairs<'_>,
    h: f64,
    params: &MomentumParams,
) -> [f64; 2] {
    let (xi, vi, rho_i) = (view.x[i], view.v[i], view.rho[i]);
    let pi_term = pr2[i];
    // Eq. (11): Π_ij = −α c̄ h (v_ij·r_ij) / (ρ̄_ij (r² + η²)), η = 0.1h, for approaching pairs
    let av = -params.alpha * params.c0 * h;
    // Eq. (12): m_j (ν_i + ν_j) (r_ij·∇_i W_ij) / (ρ_j (r² + η²)) v_ij, ν_i = ν_j = ν
    let nu_sum = 2.0 * params.nu;
    let eta2 = 0.01 * h * h;
    let mut a = [0.0, 0.0];
    for (&j, &g) in pairs.idx.iter().zip(pairs.grad) {
        let j = j as usize;
        let xj = view.x[j];
        let r_ij = [xi[0] - xj[0], xi[1] - xj[1]];
        let grad = [g * r_ij[0], g * r_ij[1]];
        let v_ij = [vi[0] - view.v[j][0], vi[1] - view.v[j][1]];
        let (rho_j, m_j) = (view.rho[j], view.m[j]);
        let rho_bar = 0.5 * (rho_i + rho_j);
        let r2 = dot(r_ij, r_ij);
        // 1/(ρ̄_ij ρ_j (r² + η²)): Π_ij takes it times ρ_j, the Morris factor times ρ̄_ij
        let inv = 1.0 / (rho_bar * rho_j * (r2 + eta2));
        let vr = dot(v_ij, r_ij);
        // Evaluated either way and then selected: approaching and separating pairs alternate unpredictably
        let visc = if vr < 0.0 { av * vr * rho_j * inv } else { 0.0 };
        // Eq. (10), Long et al. 2016
        let f = m_j * (pi_term + pr2[j] + visc);
        // Eq. (12), Long et al. 2016 (zero at ν = 0)
        let lam = m_j * nu_sum * dot(r_ij, grad) * rho_bar * inv;
        a[0] += lam * v_ij[0] - f * grad[0];
        a[1] += lam * v_ij[1] - f * grad[1];
    }
    // Eq. (10), Long et al. 2016: body force
    [a[0] + params.gravity[0], a[1] + params.gravity[1]]
}

/// Dv/Dt of every fluid particle into `out` (a parallel gather) from lists with ∇W factors (as built by
/// [`crate::neighbors::SortedCells::build_fluid_lists`]); `pr2[j]` = p_j/ρ_j².
pub fn accelerations_into(
    view: &ParticleView<'_>,
    pr2: &[f64],
    list: &NeighborList,
    kernel: &CubicSpline,
    params: &MomentumParams,
    out: &mut Vec<[f64; 2]>,
) {
    let h = kernel.h();
    list.map_pairs_into(out, |i, idx, grad| {
        acceleration(i, view, pr2, Pairs { idx, grad }, h, params)
    });
}
