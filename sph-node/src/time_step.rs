//! Stable time step (`DESIGN.md` §4.2): Δt = min(0.25 h/(c0 + v_max), 0.25 sqrt(h/|a|_max), 0.125 h²/ν).

/// The stable step for smoothing length `h`, sound speed `c0`, largest speed `v_max`, largest acceleration
/// `a_max` and kinematic viscosity `nu` (terms with a zero denominator drop out).
pub fn stable_dt(h: f64, c0: f64, v_max: f64, a_max: f64, nu: f64) -> f64 {
    // §4.2: acoustic (CFL) condition
    let mut dt = 0.25 * h / (c0 + v_max);
    if a_max > 0.0 {
        dt = dt.min(0.25 * (h / a_max).sqrt()); // §4.2: force condition
    }
    if nu > 0.0 {
        dt = dt.min(0.125 * h * h / nu); // §4.2: viscous diffusion condition
    }
    dt
}
