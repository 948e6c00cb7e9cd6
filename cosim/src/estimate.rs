//! What a run will cost in time, from the work `cosim check` counts: the CPU seconds on one core of the machine the
//! rates were measured on (this project's 2-core machine; docs/PERFORMANCE.md), so that a user sees before starting
//! whether a scene takes seconds, hours or years. A machine, a scene's flow and the load around it move the real
//! figure by up to about twice either way; the estimate is for telling orders of magnitude apart, not a benchmark.

use cosim_proto::scene::FluidSolver;

/// Structure element-steps per CPU-second (docs/PERFORMANCE.md "Structure solver": 1.3–1.7e7 quad4, 1.7–2.8e7
/// tri3, one thread).
pub const ELEMENT_STEPS_PER_SECOND: f64 = 2.0e7;

/// WCSPH fluid particle-steps per CPU-second (the dam break side by side with DualSPHysics, 1.55–2.12e6 at 20k–80k
/// particles; the Lobovsky case's 1,800 particles about 1e6).
pub const WCSPH_PARTICLE_STEPS_PER_SECOND: f64 = 1.5e6;

/// ISPH fluid particle-steps per CPU-second (the Lobovsky case at 1,800 and 7,200 particles, the pressure solve with
/// its multigrid preconditioner: 1.3–1.5e5).
pub const ISPH_PARTICLE_STEPS_PER_SECOND: f64 = 1.5e5;

/// The broker's contact pass and a coupling step's round trip between three processes [s] (0.2 and 0.3–0.5 ms on
/// the shipped gate; docs/PERFORMANCE.md "Coupled runs").
pub const COUPLING_STEP_SECONDS: f64 = 6e-4;

/// The CPU seconds on one core of a run of `element_steps` structure element-steps, `particle_steps` fluid
/// particle-steps of `solver` and `coupling_steps` steps between processes.
pub fn cpu_seconds(element_steps: f64, particle_steps: f64, solver: Option<FluidSolver>, coupling_steps: u64) -> f64 {
    let fluid_rate = match solver {
        Some(FluidSolver::Isph) => ISPH_PARTICLE_STEPS_PER_SECOND,
        _ => WCSPH_PARTICLE_STEPS_PER_SECOND,
    };
    element_steps / ELEMENT_STEPS_PER_SECOND
        + particle_steps / fluid_rate
        + coupling_steps as f64 * COUPLING_STEP_SECONDS
}

/// `seconds` for a person: one or two significant figures in seconds, minutes, hours, days or years.
pub fn duration_text(seconds: f64) -> String {
    const UNITS: [(f64, &str); 5] = [
        (365.25 * 86_400.0, "years"),
        (86_400.0, "days"),
        (3_600.0, "hours"),
        (60.0, "minutes"),
        (1.0, "s"),
    ];
    if !seconds.is_finite() {
        return "more than can be counted".to_string();
    }
    let (unit, name) = UNITS
        .iter()
        .copied()
        .find(|&(u, _)| seconds >= 2.0 * u)
        .unwrap_or((1.0, "s"));
    let value = seconds / unit;
    if value < 10.0 {
        format!("{value:.1} {name}")
    } else {
        format!("{value:.0} {name}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_estimate_adds_each_solvers_work_at_its_rate() {
        // 2e7 element-steps (1 s), 3e6 WCSPH particle-steps (2 s) and 1,000 coupling steps (0.6 s).
        let t = cpu_seconds(2e7, 3e6, Some(FluidSolver::Wcsph), 1_000);
        assert!((t - 3.6).abs() < 1e-12, "{t}");
        // ISPH's particle-step is ten times dearer.
        let t = cpu_seconds(0.0, 3e6, Some(FluidSolver::Isph), 0);
        assert!((t - 20.0).abs() < 1e-12, "{t}");
        assert_eq!(cpu_seconds(0.0, 0.0, None, 0), 0.0);
    }

    #[test]
    fn durations_read_in_the_unit_that_suits_them() {
        assert_eq!(duration_text(0.4), "0.4 s");
        assert_eq!(duration_text(35.2), "35 s");
        assert_eq!(duration_text(150.0), "2.5 minutes");
        assert_eq!(duration_text(7_200.0), "2.0 hours");
        assert_eq!(duration_text(3.0 * 86_400.0), "3.0 days");
        assert_eq!(duration_text(1e7 * 365.25 * 86_400.0 / 1e6), "10 years");
        assert_eq!(duration_text(f64::INFINITY), "more than can be counted");
    }
}
