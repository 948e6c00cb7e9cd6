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

/// The WCSPH stable step of a scene's fluid at rest, from the scene alone: `fluid.cfl` · 0.25 h / c0, the acoustic
/// condition (at rest the force and viscous conditions allow more on every shipped scene; the solver's own first step
/// is at most this). What `cosim run` sizes its warnings with before anything is built; `None` where c0 has no default
/// (no gravity and no `fluid.sound_speed`).
pub fn at_rest(spec: &cosim_proto::scene::FluidSpec, gravity: [f64; 2]) -> Option<f64> {
    let c0 = crate::setup::sound_speed(spec, gravity).ok()?;
    Some(spec.cfl * stable_dt(spec.smoothing_ratio * spec.spacing, c0, 0.0, 0.0, 0.0))
}
