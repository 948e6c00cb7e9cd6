//! Per-particle gathers of the projection step (`DESIGN.md` §4.3): viscous acceleration of the predictor,
//! velocity divergence and predicted density (PPE sources), and the pressure gradient of the corrector.

use crate::kernel::CubicSpline;
use crate::particles::{dot, separation, ParticleView};
use crate::wcsph::laminar_viscosity::morris_factor;

/// ν∇²u_i (Morris et al. 1997, Eq. (12) of Long et al. 2016) over fluid and wall neighbours (walls at rest:
/// no slip). Zero when `nu` is 0.
#[inline]
pub fn viscous_acceleration(
    i: usize,
    view: &ParticleView<'_>,
    neighbors: &[u32],
    kernel: &CubicSpline,
    nu: f64,
) -> [f64; 2] {
    if nu <= 0.0 {
        return [0.0, 0.0];
    }
    let (xi, vi) = (view.x[i], view.v[i]);
    let mut a = [0.0, 0.0];
    for &j in neighbors {
        let j = j as usize;
        let (r_ij, r) = separation(xi, view.x[j]);
        let grad = kernel.grad(r_ij, r);
        let v_ij = [vi[0] - view.v[j][0], vi[1] - view.v[j][1]];
        // Eq. (12), Long et al. 2016, ν_i = ν_j = ν
        let f = morris_factor(view.m[j], 2.0 * nu, dot(r_ij, grad), view.rho[j], r * r, kernel.h());
        a[0] += f * v_ij[0];
        a[1] += f * v_ij[1];
    }
    a
}

/// ∇·u_i = (1/ρ_i) Σ_j m_j (u_j − u_i) · ∇_i W_ij over fluid and wall neighbours (Cummins & Rudman 1999).
///
/// The caller gives the wall particles the velocity Δt g + (ũ_w · n) n in `view.v` (the predictor applied to the
/// walls as well, and the normal part of the fluid's motion next to them; [`super::wall_normal`]): the flux of u*
/// into the wall is then left to the Neumann condition of the wall rows (∂p/∂n = ρ u* · n/Δt), and the divergence
/// sees only the motion along the wall. Without the walls a particle moving into a wall would see an expansion and
/// be sucked in; with walls at rest the flux would be imposed twice.
#[inline]
pub fn velocity_divergence(i: usize, view: &ParticleView<'_>, neighbors: &[u32], kernel: &CubicSpline) -> f64 {
    let (xi, vi) = (view.x[i], view.v[i]);
    let mut s = 0.0;
    for &j in neighbors {
        let j = j as usize;
        let (r_ij, r) = separation(xi, view.x[j]);
        let grad = kernel.grad(r_ij, r);
        // Cummins & Rudman 1999: ∇·u_i = (1/ρ_i) Σ_j m_j (u_j − u_i) · ∇_i W_ij
        s += view.m[j] * ((view.v[j][0] - vi[0]) * grad[0] + (view.v[j][1] - vi[1]) * grad[1]);
    }
    s / view.rho[i]
}

/// Summation density ρ_i = m_i W(0) + Σ_j m_j W_ij over fluid and wall neighbours (Shao & Lo 2003, ρ*).
#[inline]
pub fn summation_density(i: usize, view: &ParticleView<'_>, neighbors: &[u32], kernel: &CubicSpline) -> f64 {
    let xi = view.x[i];
    let mut s = view.m[i] * kernel.w(0.0);
    for &j in neighbors {
        let j = j as usize;
        let (_, r) = separation(xi, view.x[j]);
        s += view.m[j] * kernel.w(r);
    }
    s
}

/// (∇p/ρ)_i = Σ_j m_j (p_i/ρ_i² + p_j/ρ_j²) ∇_i W_ij over fluid and wall neighbours (`DESIGN.md` §4.3, step 5;
/// Shao & Lo 2003, Eq. (12)).
#[inline]
pub fn pressure_gradient(i: usize, view: &ParticleView<'_>, neighbors: &[u32], kernel: &CubicSpline) -> [f64; 2] {
    let (xi, rho_i) = (view.x[i], view.rho[i]);
    let pi_term = view.p[i] / (rho_i * rho_i);
    let mut g = [0.0, 0.0];
    for &j in neighbors {
        let j = j as usize;
        let (r_ij, r) = separation(xi, view.x[j]);
        let grad = kernel.grad(r_ij, r);
        let rho_j = view.rho[j];
        // §4.3 step 5: Σ_j m_j (p_i/ρ_i² + p_j/ρ_j²) ∇_i W_ij
        let f = view.m[j] * (pi_term + view.p[j] / (rho_j * rho_j));
        g[0] += f * grad[0];
        g[1] += f * grad[1];
    }
    g
}
