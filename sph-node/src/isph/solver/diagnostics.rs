//! What an ISPH solver tells about itself besides its state: the stable step, energies, a pressure probe, the last
//! PPE solve and the neighbour pairs.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::IsphSolver;

/// What the last PPE solve did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PpeReport {
    /// BiCGSTAB iterations.
    pub iterations: usize,
    /// Final relative residual (see [`crate::isph::bicgstab`]).
    pub residual: f64,
    /// Fluid particles on the free surface: ∇·r below the threshold (Dirichlet weight above 1/2,
    /// [`crate::isph::free_surface::dirichlet_weight`]) or anchored at p = 0.
    pub free_surface: usize,
    /// Fluid particles whose support a structure face cuts (the first layer against it and the second row; see
    /// [`crate::isph::contact`]).
    pub contact: usize,
    /// Fluid particles given p = 0 because their group of PPE rows reached no Dirichlet row
    /// ([`crate::isph::ppe::anchor_floating_groups`]).
    pub anchored: usize,
    /// Fluid particles found inside a wall at the start of the step and put back on its face.
    pub wall_pushes: usize,
}

impl IsphSolver {
    /// Neighbour pairs of the current lists (ordered: each pair counts once for each of its particles), the wall
    /// particles' lists included (their PPE rows need them).
    pub fn pair_count(&self) -> usize {
        self.scratch.list.pair_count()
    }

    /// Iterations, residual and free-surface count of the last PPE solve.
    pub fn last_ppe(&self) -> PpeReport {
        self.last_ppe
    }

    /// Δt = min(C h / max(v_max, sqrt(2 |g| H)), 0.25 sqrt(h/a_max), 0.125 h²/ν) (`DESIGN.md` §4.3, step 6, with
    /// the force and viscous limits of §4.2; H is the initial fluid depth, a_max the largest acceleration of the
    /// last step, at least |g|), times the scene's `fluid.cfl` (1 by default).
    pub fn stable_dt(&self) -> f64 {
        let h = self.params.h;
        let v_max = self
            .state
            .v
            .par_iter()
            .map(|v| v[0].hypot(v[1]))
            .reduce(|| 0.0, f64::max);
        let v = v_max.max(self.v_ref);
        let mut dt = f64::INFINITY;
        if v > 0.0 {
            dt = self.options.courant * h / v; // §4.3 step 6
        }
        if self.a_max > 0.0 {
            dt = dt.min(0.25 * (h / self.a_max).sqrt()); // §4.2 force condition
        }
        if self.params.nu > 0.0 {
            dt = dt.min(0.125 * h * h / self.params.nu); // §4.2 viscous condition
        }
        if self.force_c0 > 0.0 {
            // The `particle_particle` contact's force, a ∝ (r0/r)^12 (Monaghan 1994, `DESIGN.md` §4.6), is applied
            // by the broker once per coupling step, explicitly. Its D = 5 g H is made for the WCSPH step, and the
            // ISPH step (about 3 × longer on the elastic gate) does not resolve it: a particle gets deep into the
            // force's range and is thrown back at up to 29 m/s, and the structure's nodes take the reaction
            // (`docs/CORRECTIONS.md`, "ISPH + particle_particle"). The step is bounded by the WCSPH one,
            // `time_step::stable_dt`'s acoustic condition.
            dt = dt.min(0.25 * h / (self.force_c0 + v_max));
        }
        self.cfl
            * if dt.is_finite() {
                dt
            } else {
                0.25 * h // no motion, no force: any step; keep it finite
            }
    }

    /// Σ ½ m |v|² (per unit depth).
    pub fn kinetic_energy(&self) -> f64 {
        self.state.kinetic_energy()
    }

    /// Σ −m g · x (per unit depth; zero at the origin).
    pub fn potential_energy(&self) -> f64 {
        self.state.potential_energy(self.params.gravity)
    }

    /// Shepard-normalised SPH interpolation of the fluid pressure at `point`; `None` when no fluid particle is
    /// within 2h.
    pub fn sample_pressure(&self, point: [f64; 2]) -> Option<f64> {
        self.state.sample_pressure(&self.kernel, point)
    }
}
