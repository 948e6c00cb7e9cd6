//! Particle data: the serializable [`FluidState`] and [`WallParticles`], and the read-only [`ParticleView`] the
//! physics functions gather from. Per-step scratch lives in the solver, not here.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::kernel::CubicSpline;

/// The state of the fluid particles at one time level (everything a restart needs besides the scene).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FluidState {
    /// Time (s).
    pub t: f64,
    /// Steps taken.
    pub step: u64,
    /// Positions (m).
    pub x: Vec<[f64; 2]>,
    /// Velocities (m/s).
    pub v: Vec<[f64; 2]>,
    /// Densities (kg/m³).
    pub rho: Vec<f64>,
    /// Pressures (Pa).
    pub p: Vec<f64>,
    /// Masses (kg) (per unit depth).
    pub m: Vec<f64>,
}

impl FluidState {
    /// Number of fluid particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// True when there are no particles.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// ½ m |v|² of particle `i` (per unit depth).
    pub fn kinetic_energy_of(&self, i: usize) -> f64 {
        let v = self.v[i];
        0.5 * self.m[i] * (v[0] * v[0] + v[1] * v[1])
    }

    /// Σ ½ m |v|² (per unit depth).
    pub fn kinetic_energy(&self) -> f64 {
        (0..self.len()).map(|i| self.kinetic_energy_of(i)).sum()
    }

    /// Σ −m g · x (per unit depth; zero at the origin).
    pub fn potential_energy(&self, g: [f64; 2]) -> f64 {
        self.x
            .iter()
            .zip(&self.m)
            .map(|(x, m)| -m * (g[0] * x[0] + g[1] * x[1]))
            .sum()
    }

    /// Shepard-normalised SPH interpolation of the fluid pressure at `point`,
    /// Σ_f p_f (m_f/ρ_f) W / Σ_f (m_f/ρ_f) W; `None` when no fluid particle is within 2h.
    pub fn sample_pressure(&self, kernel: &CubicSpline, point: [f64; 2]) -> Option<f64> {
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..self.len() {
            let x = self.x[i];
            let r = (point[0] - x[0]).hypot(point[1] - x[1]);
            let w = kernel.w(r) * self.m[i] / self.rho[i];
            num += self.p[i] * w;
            den += w;
        }
        (den > 0.0).then(|| num / den)
    }
}

/// Fixed boundary particles of the `[[wall]]` boxes (`DESIGN.md` §4.7). Positions and masses never change;
/// pressure and density are extrapolated from the fluid every step (Adami et al. 2012).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WallParticles {
    /// Positions (m).
    pub x: Vec<[f64; 2]>,
    /// Extrapolated pressures (Pa).
    pub p: Vec<f64>,
    /// Densities from the inverse EOS (kg/m³).
    pub rho: Vec<f64>,
    /// Masses (kg) (ρ0 Δx²).
    pub m: Vec<f64>,
}

impl WallParticles {
    /// Number of wall particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// True when there are no wall particles.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }
}

/// All particles, fluid first (indices `0..n_fluid`), then walls, as the gathers see them.
#[derive(Clone, Copy, Debug)]
pub struct ParticleView<'a> {
    /// Positions.
    pub x: &'a [[f64; 2]],
    /// Velocities (zero for walls).
    pub v: &'a [[f64; 2]],
    /// Densities.
    pub rho: &'a [f64],
    /// Pressures.
    pub p: &'a [f64],
    /// Masses.
    pub m: &'a [f64],
    /// Number of fluid particles.
    pub n_fluid: usize,
}

/// r_ij = x_i − x_j and |r_ij|.
#[inline]
pub fn separation(xi: [f64; 2], xj: [f64; 2]) -> ([f64; 2], f64) {
    let r = [xi[0] - xj[0], xi[1] - xj[1]];
    (r, (r[0] * r[0] + r[1] * r[1]).sqrt())
}

/// a · b.
#[inline]
pub fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// max_k |a_k| with |a| = `a[0].hypot(a[1])`, exactly as the maximum over all k, but evaluating `hypot` only for
/// the vectors whose a[0]² + a[1]² is within 1e-12 (relative; far above its rounding error) of the largest.
pub(crate) fn max_norm(a: &[[f64; 2]]) -> f64 {
    let sq = |a: &[f64; 2]| a[0] * a[0] + a[1] * a[1];
    let largest = a.par_iter().with_min_len(4096).map(sq).reduce(|| 0.0, f64::max);
    let cut = if largest > 0.0 {
        largest * (1.0 - 1e-12)
    } else {
        f64::NEG_INFINITY
    };
    a.par_iter()
        .with_min_len(4096)
        .filter(|a| {
            let s = sq(a);
            s >= cut || s.is_nan()
        })
        .map(|a| a[0].hypot(a[1]))
        .reduce(|| 0.0, f64::max)
}
