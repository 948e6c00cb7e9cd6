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

/// The longest step a scene's fluid can take whatever its motion, and the key of the condition that sets it: the
/// acoustic condition `fluid.cfl` · 0.25 h / c0 (WCSPH) and the viscous one, 0.125 h² / ν (§4.2; WCSPH times
/// `fluid.cfl`). `None` where neither applies (an inviscid ISPH fluid, whose step follows its speed) or c0 has no
/// default. A run needs at least `run.end_time` over this many fluid steps.
pub fn longest(spec: &cosim_proto::scene::FluidSpec, gravity: [f64; 2]) -> Option<(f64, &'static str)> {
    let h = spec.smoothing_ratio * spec.spacing;
    let wcsph = matches!(spec.solver, cosim_proto::scene::FluidSolver::Wcsph);
    let cfl = if wcsph { spec.cfl } else { 1.0 };
    let mut bound: Option<(f64, &'static str)> = None;
    let mut take = |dt: f64, key: &'static str| {
        if bound.is_none_or(|(b, _)| dt < b) {
            bound = Some((dt, key));
        }
    };
    if wcsph {
        take(at_rest(spec, gravity)?, "fluid.sound_speed"); // §4.2: acoustic (CFL) condition
    }
    if spec.kinematic_viscosity > 0.0 {
        take(
            cfl * 0.125 * h * h / spec.kinematic_viscosity,
            "fluid.kinematic_viscosity",
        ); // §4.2: viscous condition
    }
    bound
}
