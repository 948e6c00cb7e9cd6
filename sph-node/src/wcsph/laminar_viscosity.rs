//! Morris et al. (1997) laminar viscosity, Eq. (12) of Long et al. 2016:
//! (ν ∇²v)_i = Σ_j m_j (ν_i + ν_j) (r_ij · ∇_i W_ij) / (ρ_j (r_ij² + η²)) v_ij, η = 0.1h.

/// The scalar factor of pair ij; multiply by v_ij.
#[inline]
pub fn morris_factor(m_j: f64, nu_sum: f64, r_dot_grad: f64, rho_j: f64, r2: f64, h: f64) -> f64 {
    let eta2 = 0.01 * h * h;
    // Eq. (12), Long et al. 2016
    m_j * nu_sum * r_dot_grad / (rho_j * (r2 + eta2))
}
