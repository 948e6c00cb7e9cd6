//! Kick–drift–kick leapfrog (`DESIGN.md` §4.2), so that fluid and FEM states sit at the same time levels.
//!
//! One step: v^{n+½} = vⁿ + ½Δt aⁿ; ρ^{n+½} = ρⁿ + ½Δt Dρ/Dt(xⁿ, v^{n+½});
//! x^{n+1} = xⁿ + Δt (v^{n+½} + δv_XSPH); ρ^{n+1} = ρ^{n+½} + ½Δt Dρ/Dt(x^{n+1}, v^{n+½});
//! v^{n+1} = v^{n+½} + ½Δt a(x^{n+1}, ρ^{n+1}, v^{n+½}). Density moves with the positions (both rates use
//! v^{n+½}), which keeps the acoustic modes neutrally stable as in a plain leapfrog.

use rayon::prelude::*;

/// v += ½ Δt a.
pub fn half_kick(v: &mut [[f64; 2]], a: &[[f64; 2]], dt: f64) {
    let h = 0.5 * dt;
    v.par_iter_mut().zip(a.par_iter()).for_each(|(v, a)| {
        v[0] += h * a[0];
        v[1] += h * a[1];
    });
}

/// ρ += ½ Δt Dρ/Dt.
pub fn half_kick_density(rho: &mut [f64], drho: &[f64], dt: f64) {
    let h = 0.5 * dt;
    rho.par_iter_mut().zip(drho.par_iter()).for_each(|(r, d)| *r += h * d);
}

/// x += Δt (v + δv); `correction` (XSPH) may be empty.
pub fn drift(x: &mut [[f64; 2]], v: &[[f64; 2]], correction: &[[f64; 2]], dt: f64) {
    if correction.is_empty() {
        x.par_iter_mut().zip(v.par_iter()).for_each(|(x, v)| {
            x[0] += dt * v[0];
            x[1] += dt * v[1];
        });
    } else {
        x.par_iter_mut()
            .zip(v.par_iter())
            .zip(correction.par_iter())
            .for_each(|((x, v), c)| {
                x[0] += dt * (v[0] + c[0]);
                x[1] += dt * (v[1] + c[1]);
            });
    }
}
