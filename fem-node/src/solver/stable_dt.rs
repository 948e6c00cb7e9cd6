//! Stable explicit time step, `Δt = cfl · min_e (L_e / c_d)`, `c_d = sqrt((λ + 2μ) / ρ)` (`DESIGN.md` §4.1),
//! with `L_e` taken from the current configuration: area over the longest diagonal for quads, the smallest altitude
//! (2·area / longest edge) for triangles.
//!
//! Both are the standard lengths of explicit codes. The quad length is the exact critical length of a square
//! one-point element with lumped mass. Measured on the structured meshes (random initial velocities, 4000 steps,
//! ν = 0–0.49), the largest stable `cfl` is 1.00–1.41 for quads (1.00 for very elongated cells) and 0.943–1.2 for
//! the checkerboard triangles (0.943 for cells of aspect 5:1 and more): the default `cfl = 0.9` is stable for both,
//! while `cfl` above 0.94 can blow up elongated triangles (reported as [`crate::FemError::Unstable`]).
//!
//! With stiffness-proportional damping β an element's step is shortened by `√(1 + ζ²) − ζ`, ζ = β c_d / L_e its
//! damping ratio at ω = 2 c_d / L_e (Belytschko, Liu & Moran, Nonlinear Finite Elements, Eq. 6.2.32).
//!
//! Mass-proportional damping c (`solid[i].damping`, the force −c m v taken at v^{n+½}) multiplies a free velocity by
//! 1 − c Δt a step (`central_difference.rs`): past c Δt = 2 it grows, past 1 it flips sign every step. So the step
//! is also at most `cfl / c`. It binds only for a structure damped far beyond critical at its own step (c = 10/s
//! against Δt ~ 1e-5 s on the CSM bar: c Δt = 1e-4); before, c = 1e300 blew the structure up at its second step.

use crate::model::FemModel;

/// The stable step of the configuration `x`. Fails with the element whose length is not positive and finite (a
/// collapsed or inverted element); a model without elements has an infinite stable step.
pub fn stable_dt(model: &FemModel, x: &[[f64; 2]], cfl: f64) -> Result<f64, (usize, f64)> {
    let mut dt = f64::INFINITY;
    for solid in model.solids() {
        if solid.damping > 0.0 {
            dt = dt.min(cfl / solid.damping);
        }
        let c = solid.wave_speed();
        for e in solid.elements.clone() {
            let l = model.elements()[e].characteristic_length(x);
            if !(l > 0.0 && l.is_finite()) {
                return Err((e, l));
            }
            let undamped = cfl * l / c;
            let beta = solid.stiffness_damping;
            dt = dt.min(if beta > 0.0 {
                let zeta = beta * c / l;
                undamped * ((1.0 + zeta * zeta).sqrt() - zeta)
            } else {
                undamped
            });
        }
    }
    Ok(dt)
}
