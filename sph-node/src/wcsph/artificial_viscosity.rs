//! Monaghan (1994) artificial viscosity, Eq. (11) of Long et al. 2016:
//! Π_ij = −α c̄_ij h (v_ij · r_ij) / (ρ̄_ij (r_ij² + η²)) when v_ij · r_ij < 0, else 0, η = 0.1h.

/// Π_ij for approaching particles (0 when they separate).
#[inline]
pub fn pi_ij(alpha: f64, c_bar: f64, h: f64, vr: f64, rho_bar: f64, r2: f64) -> f64 {
    let eta2 = 0.01 * h * h;
    // Eq. (11), Long et al. 2016 (η² = (0.1h)² keeps the denominator away from zero)
    let pi = -alpha * c_bar * h * vr / (rho_bar * (r2 + eta2));
    // Evaluated either way and then selected: approaching and separating pairs alternate unpredictably, and a
    // mispredicted branch costs more than the division.
    if vr >= 0.0 {
        0.0
    } else {
        pi
    }
}
