//! The energy guard of the stability checks: in a tank the water can never hold more kinetic energy than it
//! had in total at the start (kinetic plus potential above its lowest possible level), plus what a solid held
//! nowhere can give it by falling to that level, so kinetic energy beyond twice that budget means the solution is
//! blowing up, and the run stops as `unstable` instead of writing garbage. (NaN and particles leaving the domain
//! are caught inside the solvers.) Before 2026-12-08 the budget was the water's alone, and a heavy solid dropped into
//! the water stopped runs that made no energy: an 8,000 kg/m³ block 97 × 29 mm falling from 12 cm onto the surge,
//! which can give the water about 3 times its own budget, ended `unstable` at t = 0.162 s (`energy_growth` 3.5e-5).

use cosim_proto::scene::Scene;

use crate::error::SphError;
use crate::particles::{FluidState, WallParticles};
use serde::{Deserialize, Serialize};

/// The kinetic energy the guard never takes for a blow-up, as a fraction of the fluid's sound speed: the whole fluid
/// moving at 1e-6 c0. Under a gravity of 1e-30 m/s² the budget was 1e-30 J/m, and the gate was "unstable" at its
/// sixth step on 1e-27 J/m of rounding (found 2026-12-06); on the shipped scenes the budget is 1e9–1e10 times this
/// floor, which never binds there.
const QUIET_SPEED: f64 = 1e-6;

/// Stops a run whose kinetic energy grows without bound.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct EnergyGuard {
    /// Largest kinetic energy allowed [J per unit thickness]; infinite when the scene has no energy source.
    pub bound: f64,
}

impl EnergyGuard {
    /// The budget of the initial state: kinetic energy plus the potential energy above the lowest level any
    /// particle (fluid or wall) occupies, doubled for margin; at least the whole fluid at [`QUIET_SPEED`] × `c0`
    /// (the fluid's sound speed, where it has one). No bound where the fluid starts with no energy at all.
    pub fn new(state: &FluidState, walls: &WallParticles, gravity: [f64; 2], c0: Option<f64>) -> Self {
        Self::with_bodies(state, walls, gravity, c0, &[])
    }

    /// [`EnergyGuard::new`] with the potential energy of free bodies, each (mass [kg per unit thickness], centre of
    /// mass), above the same lowest level added to the budget: what they can give the water by sinking.
    pub fn with_bodies(
        state: &FluidState,
        walls: &WallParticles,
        gravity: [f64; 2],
        c0: Option<f64>,
        bodies: &[(f64, [f64; 2])],
    ) -> Self {
        let height = |x: &[f64; 2]| -(gravity[0] * x[0] + gravity[1] * x[1]);
        let lowest = state.x.iter().chain(&walls.x).map(height).fold(f64::INFINITY, f64::min);
        let potential: f64 = state
            .x
            .iter()
            .zip(&state.m)
            .map(|(x, m)| m * (height(x) - lowest))
            .sum();
        let sinking: f64 = bodies.iter().map(|(m, c)| m * (height(c) - lowest).max(0.0)).sum();
        let budget = state.kinetic_energy() + potential + sinking;
        let mass: f64 = state.m.iter().sum();
        let quiet = c0.map_or(0.0, |c| 0.5 * mass * (QUIET_SPEED * c).powi(2));
        let budget = if budget > 0.0 { budget.max(quiet) } else { budget };
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

/// The scene's solids held nowhere (no `fixed` box), each as (mass [kg per unit thickness], centre of mass): the
/// bodies whose fall the fluid's energy guard counts ([`EnergyGuard::with_bodies`]). A clamped solid gives the
/// water only what its deformation releases, which the guard's factor 2 covers.
pub fn free_solids(scene: &Scene) -> Vec<(f64, [f64; 2])> {
    scene
        .solids
        .iter()
        .filter(|s| s.held_nowhere())
        .map(|s| {
            let area = (s.max[0] - s.min[0]) * (s.max[1] - s.min[1]);
            let centre = [0.5 * (s.min[0] + s.max[0]), 0.5 * (s.min[1] + s.max[1])];
            (s.material.density * area, centre)
        })
        .collect()
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
    fn a_free_body_adds_what_it_can_give_by_sinking() {
        // The water's 20 J/m, and 3 kg/m at y = 2 falling to the lowest particle (y = 0): 60 J/m; a body below that
        // level gives nothing.
        let bodies = [(3.0, [5.0, 2.0]), (7.0, [0.0, -1.0])];
        let guard = EnergyGuard::with_bodies(&state([0.0, 0.0]), &no_walls(), [0.0, -10.0], Some(20.0), &bodies);
        assert_eq!(guard.bound, 160.0);
        // The gate's solid: clamped, none; held nowhere, 2,700 kg/m³ × 5 × 79 mm at the middle of its box.
        let text =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/elastic_gate.toml")).unwrap();
        let gate = |sets: &[&str]| {
            let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
            free_solids(&cosim_proto::scene::parse("elastic_gate.toml", &text, &sets).unwrap())
        };
        assert!(gate(&[]).is_empty());
        let free = gate(&["solid[0].fixed=[]", "solid[0].material.density=2700.0"]);
        assert_eq!(free.len(), 1);
        let (m, c) = free[0];
        assert!((m - 2700.0 * 0.005 * 0.079).abs() < 1e-9, "{m}");
        assert!((c[0] - 0.1025).abs() < 1e-12 && (c[1] - 0.0395).abs() < 1e-12, "{c:?}");
    }

    #[test]
    fn bound_is_twice_the_initial_budget() {
        // Potential above the lowest particle: m g Δy = 2 × 10 × 1 = 20 J/m; no motion.
        let guard = EnergyGuard::new(&state([0.0, 0.0]), &no_walls(), [0.0, -10.0], Some(20.0));
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
        let guard = EnergyGuard::new(&state([0.0, 0.0]), &no_walls(), [0.0, 0.0], Some(20.0));
        assert_eq!(guard.bound, f64::INFINITY);
    }

    /// Under a gravity of 1e-30 m/s² the budget is the quiet floor: two particles of 2 kg/m at 1e-6 × 20 m/s hold
    /// 4e-10 J/m, the bound twice that; rounding-sized motion passes, a blow-up does not.
    #[test]
    fn a_tiny_gravity_leaves_the_quiet_floor() {
        let guard = EnergyGuard::new(&state([0.0, 0.0]), &no_walls(), [0.0, -1e-30], Some(20.0));
        assert!((guard.bound - 2.0 * 0.5 * 4.0 * 4e-10).abs() < 1e-24, "{}", guard.bound);
        assert!(guard.check(&state([1e-13, 0.0])).is_ok());
        assert!(guard.check(&state([1.0, 0.0])).is_err());
        // Without a sound speed (ISPH without gravity's default) the budget is the potential alone, as before.
        let bare = EnergyGuard::new(&state([0.0, 0.0]), &no_walls(), [0.0, -1e-30], None);
        assert!(bare.bound < 1e-28, "{}", bare.bound);
    }
}
