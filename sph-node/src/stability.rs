//! The energy guard of the stability checks: in a tank the water can never hold more kinetic energy than it
//! had in total at the start (kinetic plus potential above its lowest possible level), so kinetic energy
//! beyond twice that budget means the solution is blowing up, and the run stops as `unstable` instead of
//! writing garbage. (NaN and particles leaving the domain are caught inside the solvers.)

use crate::error::SphError;
use crate::particles::{FluidState, WallParticles};
use serde::{Deserialize, Serialize};

/// Stops a run whose kinetic energy grows without bound.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct EnergyGuard {
    /// Largest kinetic energy allowed [J per unit thickness]; infinite when the scene has no energy source.
    pub bound: f64,
}

impl EnergyGuard {
    /// The budget of the initial state: kinetic energy plus the potential energy above the lowest level any
    /// particle (fluid or wall) occupies, doubled for margin.
    pub fn new(state: &FluidState, walls: &WallParticles, gravity: [f64; 2]) -> Self {
        let height = |x: &[f64; 2]| -(gravity[0] * x[0] + gravity[1] * x[1]);
        let lowest = state.x.iter().chain(&walls.x).map(height).fold(f64::INFINITY, f64::min);
        let potential: f64 = state
            .x
            .iter()
            .zip(&state.m)
            .map(|(x, m)| m * (height(x) - lowest))
            .sum();
        let budget = state.kinetic_energy() + potential;
        Self {
            bound: if budget > 0.0 { 2.0 * budget } else { f64::INFINITY },
        }
    }

    /// `Unstable` naming the most energetic particle when the kinetic energy exceeds the bound.
    pub fn check(&self, state: &FluidState) -> Result<(), SphError> {
        let total = state.kinetic_energy();
        if total <= self.bound {
            return Ok(());
        }
        let particle = (0..state.len())
            .max_by(|&a, &b| state.kinetic_energy_of(a).total_cmp(&state.kinetic_energy_of(b)))
            .unwrap_or(0);
        Err(SphError::Unstable {
            step: state.step,
            particle,
            reason: format!(
                "kinetic energy {total:.4e} J/m exceeds twice the initial energy budget ({:.4e} J/m)",
                self.bound
            ),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(v: [f64; 2]) -> FluidState {
        FluidState {
            t: 0.0,
            step: 7,
            x: vec![[0.0, 1.0], [0.0, 0.0]],
            v: vec![[0.0, 0.0], v],
            rho: vec![1000.0; 2],
            p: vec![0.0; 2],
            m: vec![2.0, 2.0],
        }
    }

    fn no_walls() -> WallParticles {
        WallParticles {
            x: Vec::new(),
            p: Vec::new(),
            rho: Vec::new(),
            m: Vec::new(),
        }
    }

    #[test]
    fn bound_is_twice_the_initial_budget() {
        // Potential above the lowest particle: m g Δy = 2 × 10 × 1 = 20 J/m; no motion.
        let guard = EnergyGuard::new(&state([0.0, 0.0]), &no_walls(), [0.0, -10.0]);
        assert_eq!(guard.bound, 40.0);
        // ½ 2 v² = 40 at v = 6.3246: 6.32 is allowed, 6.33 refused, naming particle 1 and the step.
        assert!(guard.check(&state([6.32, 0.0])).is_ok());
        match guard.check(&state([6.33, 0.0])) {
            Err(SphError::Unstable {
                step: 7,
                particle: 1,
                reason,
            }) => assert!(reason.contains("kinetic energy")),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn no_energy_source_means_no_bound() {
        let guard = EnergyGuard::new(&state([0.0, 0.0]), &no_walls(), [0.0, 0.0]);
        assert_eq!(guard.bound, f64::INFINITY);
    }
}
