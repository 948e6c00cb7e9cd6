//! The run's energy balance (`summary.json` `energy_growth`): how much mechanical energy the fluid and the
//! structure together hold over what they held at t = 0, sampled at every output time, against the potential
//! energy the water can release.
//!
//! Nothing in a scene drives the water or the structure (no moving wall, no inflow, no applied load besides
//! gravity), so the fluid's kinetic, gravitational and (WCSPH) elastic energy plus the structure's kinetic, strain
//! and gravitational energy can only fall: the viscosities and the contact's inelastic velocity correction (Long et
//! al. 2016, Eq. (12)) take energy out of it. A gain is energy the numerical scheme
//! made: the symptom of an unstable coupling, or of a step too long for it, often long before anything blows up
//! (the coupled ISPH gate at `coupling.max_dt = 1e-2` ends `ok` having gained its whole budget, docs/CORRECTIONS.md
//! "The structure's own face velocity, sent by the broker"). A run whose gain passes [`WARN_GROWTH`] of the budget
//! says so once in its log while it runs; every run with a fluid under gravity reports its largest gain.

use cosim_proto::scene::{FluidSolver, Scene};
use serde::{Deserialize, Serialize};
use sph_node::eos::Tait;

/// A gain beyond this fraction of the budget is a warning (once a run). As shipped the scenes gain at most 0.0003
/// with WCSPH, 0.032 with ISPH and 0.079 with ISPH + `particle_particle` (the gate; docs/VALIDATION.md, 2026-11-29
/// twelfth); the stress tests bound the fluid's own gain by 0.05.
pub const WARN_GROWTH: f64 = 0.1;

/// Whether a largest gain of `largest` (a fraction of the budget) is energy the scheme made: past [`WARN_GROWTH`].
pub fn made_energy(largest: f64) -> bool {
    largest > WARN_GROWTH
}

/// A run's mean coupling step and the one to try after it made energy ([`shorter_step`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepHint {
    /// The run's mean coupling step [s].
    pub mean: f64,
    /// Half of it, rounded down to one significant digit [s].
    pub try_dt: f64,
}

/// The coupling step to try after a run of `steps` coupling steps to `sim_time` made energy: half its mean step,
/// rounded down to one significant digit (`None` without a step). On the gate a shorter coupling step took the energy
/// made back within the bound: WCSPH at Δx = 4.5 mm 0.113 of its budget → 0 at the step this suggests (3e-5; its own
/// steps averaged 6.7e-5 s), ISPH at `coupling.max_dt` 1e-2 1.057 → 0.057 (7e-5). Not ISPH + `particle_particle` at
/// Δx = 4 mm: 2.66 → 2.31 at 2e-5 (docs/VALIDATION.md, 2026-11-29 thirteenth).
pub fn shorter_step(sim_time: f64, steps: u64) -> Option<StepHint> {
    if steps == 0 || sim_time.is_nan() || sim_time <= 0.0 {
        return None;
    }
    let mean = sim_time / steps as f64;
    let half = 0.5 * mean;
    let unit = 10f64.powf(half.log10().floor());
    // A digit from 1 to 9 (the guard: a power of ten whose logarithm rounds below it)
    let digit = (half / unit * (1.0 + 1e-12)).floor().clamp(1.0, 9.0);
    Some(StepHint {
        mean,
        try_dt: digit * unit,
    })
}

/// The largest energy gain of a run so far (`summary.json` `energy_growth`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EnergyGrowth {
    /// The largest gain E(t) − E(0) over the output times so far, as a fraction of [`EnergyGrowth::budget`] (0 at
    /// the start: t = 0 counts).
    pub largest: f64,
    /// The output time of the largest gain [s].
    pub at: f64,
    /// The potential energy the water can release [J/m]: Σ m |g| (h − h_min) over the fluid at t = 0, h the height
    /// against gravity (ρ g W H²/2 less half a spacing's worth for a block W × H on a floor).
    pub budget: f64,
    /// E(0) [J/m]: the fluid's kinetic energy, its gravitational energy relative to its first positions and, for
    /// WCSPH, its elastic energy Σ m e(ρ) (`sph_node::eos::Tait::specific_energy`), plus the structure's kinetic,
    /// strain and gravitational energy (the `energy` probes count all of these but the elastic energy).
    pub initial: f64,
    /// How far rounding could move the energy of an output time, at most, as a fraction of
    /// [`EnergyGrowth::budget`] ([`crate::probes::Probes::energy_rounding`]): a gain within the rounding of the two
    /// energies it compares is not counted. Some 1e-12 on the shipped scenes; where a structure's own energies are
    /// 1e15 times the water's (a solid of ρ = 1e20 falling under its weight), past 1, and the balance cannot see a
    /// gain of the budget's size.
    #[serde(default)]
    pub rounding: f64,
}

impl EnergyGrowth {
    /// The balance of a run whose first output time holds `energy`, up to `rounding` [J/m], with `budget`
    /// ([`releasable`]); `None` where there is no budget to measure a gain against (no fluid, no gravity).
    pub fn start(t: f64, energy: f64, rounding: f64, budget: f64) -> Option<Self> {
        (budget > 0.0 && budget.is_finite() && energy.is_finite() && rounding.is_finite()).then_some(Self {
            largest: 0.0,
            at: t,
            budget,
            initial: energy,
            rounding: rounding / budget,
        })
    }

    /// Take the energy of output time `t`, up to `rounding` [J/m]; true at the first output time whose gain passes
    /// [`WARN_GROWTH`]. A non-finite energy (a state blowing up, which the nodes refuse) is skipped, and so is a
    /// gain within the rounding of the two energies it compares (the start's is within
    /// [`EnergyGrowth::rounding`]).
    pub fn observe(&mut self, t: f64, energy: f64, rounding: f64) -> bool {
        if !(energy.is_finite() && rounding.is_finite()) {
            return false;
        }
        let floor = rounding / self.budget + self.rounding;
        self.rounding = self.rounding.max(rounding / self.budget);
        let gain = (energy - self.initial) / self.budget;
        if !(gain > self.largest && gain > floor) {
            return false;
        }
        let crossed = !made_energy(self.largest) && made_energy(gain);
        self.largest = gain;
        self.at = t;
        crossed
    }
}

/// The equation of state of the scene's fluid where it stores elastic energy (WCSPH: the Tait law with the scene's
/// c0, as the fluid node takes it); `None` for ISPH and without a fluid.
pub fn elastic_eos(scene: &Scene) -> Option<Tait> {
    let fluid = scene.fluid.as_ref().filter(|f| f.solver == FluidSolver::Wcsph)?;
    let c0 = sph_node::setup::sound_speed(fluid, scene.run.gravity).ok()?;
    Some(Tait::new(fluid.density, c0))
}

/// The elastic energy of particles of masses `m` and densities `rho` [J/m]: Σ m e(ρ) (`Tait::specific_energy`).
/// Counted, or the balance would read each acoustic swing between kinetic and elastic energy as a gain, and the
/// release of the hydrostatic compression a WCSPH column starts with as one.
pub fn elastic_energy(eos: &Tait, m: &[f64], rho: &[f64]) -> f64 {
    m.iter().zip(rho).map(|(m, rho)| m * eos.specific_energy(*rho)).sum()
}

/// The size the elastic energy's terms are computed at [J/m]: e(ρ) is a difference of terms of order B/ρ0 (1/ρ
/// and (ρ/ρ0)⁶/6, against 1 + 1/6), so each m e(ρ) is off by a few u m B/ρ0, not u m e(ρ): Σ 3 m B/ρ0.
pub fn elastic_size(eos: &Tait, m: &[f64]) -> f64 {
    3.0 * eos.b() / eos.rho0 * m.iter().map(|m| m.abs()).sum::<f64>()
}

/// The potential energy particles of masses `m` at `x` release under `gravity` falling to the height of the lowest
/// of them: Σ m |g| (h − h_min), h = −g·x/|g| [J/m]. Zero without gravity or particles.
pub fn releasable(m: &[f64], x: &[[f64; 2]], gravity: [f64; 2]) -> f64 {
    let g = gravity[0].hypot(gravity[1]);
    let down = g.is_finite() && g > 0.0;
    if !down || x.is_empty() {
        return 0.0;
    }
    let height = |x: &[f64; 2]| -(gravity[0] * x[0] + gravity[1] * x[1]) / g;
    let lowest = x.iter().map(height).fold(f64::INFINITY, f64::min);
    m.iter().zip(x).map(|(m, x)| m * g * (height(x) - lowest)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_step_to_try_is_half_the_mean_step_to_one_digit() {
        // 0.4 s in 6,012 steps: 6.65e-5 s a step, half of it 3.33e-5 → 3e-5.
        let dt = shorter_step(0.4, 6012).unwrap().try_dt;
        assert!((dt - 3e-5).abs() < 1e-18, "{dt}");
        // 0.2 s in 1,000 steps: 2e-4 a step, 1e-4 exactly (no rounding below it).
        let dt = shorter_step(0.2, 1000).unwrap().try_dt;
        assert!((dt - 1e-4).abs() < 1e-18, "{dt}");
        assert_eq!(shorter_step(0.0, 10), None);
        assert_eq!(shorter_step(0.1, 0), None);
    }

    #[test]
    fn the_budget_of_a_column_is_its_weight_times_its_height_over_two() {
        // A column of 10 particles of 1 kg, 0.1 m apart, the lowest at y = 0.05: Σ m g (y − 0.05) = g · 0.1 · 45.
        let x: Vec<[f64; 2]> = (0..10).map(|k| [0.3, 0.05 + 0.1 * k as f64]).collect();
        let m = vec![1.0; 10];
        let b = releasable(&m, &x, [0.0, -9.81]);
        assert!((b - 9.81 * 0.1 * 45.0).abs() < 1e-12, "{b}");
        // Gravity along −x: the heights are the x coordinates, all equal.
        assert_eq!(releasable(&m, &x, [-9.81, 0.0]), 0.0);
        assert_eq!(releasable(&m, &x, [0.0, 0.0]), 0.0);
        assert_eq!(releasable(&[], &[], [0.0, -9.81]), 0.0);
    }

    #[test]
    fn no_budget_no_balance() {
        assert_eq!(EnergyGrowth::start(0.0, 1.0, 0.0, 0.0), None);
        assert_eq!(EnergyGrowth::start(0.0, f64::NAN, 0.0, 2.0), None);
        assert_eq!(EnergyGrowth::start(0.0, 1.0, f64::INFINITY, 2.0), None);
        assert!(EnergyGrowth::start(0.0, -3.0, 0.0, 2.0).is_some());
    }

    #[test]
    fn the_largest_gain_is_kept_and_the_warning_given_once() {
        // Numbers exact in binary: a budget of 16 J/m from −4 J/m.
        let mut g = EnergyGrowth::start(0.0, -4.0, 0.0, 16.0).unwrap();
        // Losses leave the largest gain at the start's 0.
        assert!(!g.observe(0.1, -5.0, 0.0));
        assert_eq!((g.largest, g.at), (0.0, 0.0));
        // A gain of 1/16 of the budget is under the line.
        assert!(!g.observe(0.2, -3.0, 0.0));
        assert_eq!((g.largest, g.at), (0.0625, 0.2));
        // Past it: warned once, at the first output time past it.
        assert!(g.observe(0.3, -2.0, 0.0));
        assert_eq!((g.largest, g.at), (0.125, 0.3));
        assert!(!g.observe(0.4, 0.0, 0.0));
        assert_eq!((g.largest, g.at), (0.25, 0.4));
        // Smaller gains, and non-finite energies, leave it.
        assert!(!g.observe(0.5, -1.0, 0.0));
        assert!(!g.observe(0.6, f64::NAN, 0.0));
        assert!(!g.observe(0.7, f64::INFINITY, 0.0));
        assert_eq!((g.largest, g.at), (0.25, 0.4));
    }

    #[test]
    fn a_gain_within_the_energies_rounding_is_not_counted() {
        // A budget of 16 J/m from 0, the start's energy good to 0.5 J/m.
        let mut g = EnergyGrowth::start(0.0, 0.0, 0.5, 16.0).unwrap();
        assert_eq!(g.rounding, 0.5 / 16.0);
        // 4 J/m (0.25 of the budget) where the two energies compared are good to 3.5 and 0.5 J/m: rounding.
        assert!(!g.observe(0.1, 4.0, 3.5));
        assert_eq!((g.largest, g.at), (0.0, 0.0));
        // The largest rounding of an output time so far is kept, and stands for the start's from then on.
        assert_eq!(g.rounding, 3.5 / 16.0);
        assert!(!g.observe(0.2, 4.5, 1.0));
        assert_eq!((g.largest, g.rounding), (0.0, 3.5 / 16.0));
        // Past both: counted, and warned.
        assert!(g.observe(0.3, 8.0, 1.0));
        assert_eq!((g.largest, g.at), (0.5, 0.3));
        // A non-finite rounding (a state blowing up) is skipped with its energy.
        assert!(!g.observe(0.4, 12.0, f64::NAN));
        assert_eq!((g.largest, g.rounding), (0.5, 3.5 / 16.0));
    }
}
