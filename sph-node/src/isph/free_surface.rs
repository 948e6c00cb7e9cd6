//! Free-surface detection by the divergence of position (Lo & Shao 2002; Shao & Lo 2003; `DESIGN.md` §4.3,
//! step 3): ∇·r_i = −Σ_j (m_j/ρ_j) r_ij · ∇_i W_ij, which is 2 inside the fluid in 2D and drops towards 1 at a
//! free surface. Wall particles count as matter, so the fluid next to a wall is not a free surface.

use rayon::prelude::*;

use crate::kernel::CubicSpline;
use crate::neighbors::NeighborList;
use crate::particles::{separation, ParticleView};

/// Threshold of ∇·r below which a 2D particle is on the free surface: the middle of the band of [`dirichlet_weight`].
pub const THRESHOLD_2D: f64 = 1.5;

/// ∇·r of fluid particle i over all its neighbours (fluid and wall).
#[inline]
pub fn position_divergence(i: usize, view: &ParticleView<'_>, neighbors: &[u32], kernel: &CubicSpline) -> f64 {
    let xi = view.x[i];
    let mut s = 0.0;
    for &j in neighbors {
        let j = j as usize;
        let (_, r) = separation(xi, view.x[j]);
        // r_ij · ∇_i W_ij = r dW/dr; Shao & Lo 2003, ∇·r = −Σ_j (m_j/ρ_j) r_ij · ∇_i W_ij
        s -= view.m[j] / view.rho[j] * r * kernel.dw_dr(r);
    }
    s
}

/// Half-width of the band of ∇·r around the threshold over which a particle's PPE row passes from Dirichlet (p = 0)
/// to Poisson ([`dirichlet_weight`]): φ = 1 at ∇·r ≤ 1.25, 0 at ∇·r ≥ 1.75 (threshold 1.5). On the lattice (h = 1.3
/// Δx) a flat surface's row reads ∇·r = 1.28 (φ = 0.94), the second row 1.90 and the interior 2.02 (both φ = 0).
pub const BLEND_2D: f64 = 0.25;

/// The Dirichlet weight φ of a particle with ∇·r = `div_r`: 1 at or below `threshold − BLEND_2D` (a free-surface
/// particle, p = 0), falling linearly to 0 at `threshold + BLEND_2D` (an interior particle). The PPE row of a particle
/// in the band is (1 − φ) × its Poisson row + φ × the Dirichlet row diag · p_i = 0 ([`super::ppe::fluid_row`]), so a
/// particle the flow carries across the threshold takes its pressure on, or gives it up, over several steps.
///
/// With a switch at the threshold (Lo & Shao 2002's flag as it stands), the pressure jumped wherever particles
/// crossed it. In the corner of the Lobovsky dam break (ISPH, H/60) two particles of the sheet turned from Dirichlet
/// to Poisson in one step and closed a cluster of seven compressed particles off from the surface: its pressure rose
/// from 3–4 ρgH to 15–19 ρgH for that step, threw the top particle up the wall at 5.6 m/s, and the overshoot left
/// the cluster at p = 0 the steps after; which particles crossed when decided the sensors' peak, 3.95 to 6.41 ρgH for
/// changes in the last bits of the PPE's solution. With the band, 3.03 and 2.82 ρgH for two such changes, and the
/// 10 s still tank's surface, whose particles kept crossing the threshold, holds a third of the kinetic energy it
/// did. A wider band (±0.3) was less sensitive still but let ISPH at 8 × its step run on gaining energy; one on one
/// side of the threshold only moves the still tank's pressure (docs/CORRECTIONS.md, "The switch at the free
/// surface").
#[inline]
pub fn dirichlet_weight(div_r: f64, threshold: f64) -> f64 {
    let (lo, hi) = (threshold - BLEND_2D, threshold + BLEND_2D);
    ((hi - div_r) / (hi - lo)).clamp(0.0, 1.0)
}

/// The Dirichlet weight φ of every fluid particle into `weight` ([`dirichlet_weight`]; φ = 1: on the free surface,
/// its row is Dirichlet p = 0).
pub fn free_surface_into(
    view: &ParticleView<'_>,
    list: &NeighborList,
    kernel: &CubicSpline,
    threshold: f64,
    weight: &mut Vec<f64>,
) {
    (0..view.n_fluid)
        .into_par_iter()
        .map(|i| dirichlet_weight(position_divergence(i, view, list.of(i), kernel), threshold))
        .collect_into_vec(weight);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∇·r of the particle at the origin of a square lattice holding rows y = −5 Δx … `top` Δx.
    fn lattice_div_r(top: i32) -> f64 {
        let lattice = super::super::lattice::Lattice::new(-5..=top);
        position_divergence(0, &lattice.view(), &lattice.neighbors, &lattice.kernel)
    }

    #[test]
    fn the_band_takes_the_surface_row_and_leaves_the_second_row_and_the_interior() {
        // Lattice values of the cubic spline at h = 1.3 Δx (summed by hand over the stencil): surface row 1.2788,
        // second row 1.9005, interior 2.0211.
        let (surface, second, interior) = (lattice_div_r(0), lattice_div_r(1), lattice_div_r(5));
        for (got, want) in [(surface, 1.2788), (second, 1.9005), (interior, 2.0211)] {
            assert!((got - want).abs() < 1e-4, "∇·r {got} against {want}");
        }
        let phi = |d| dirichlet_weight(d, THRESHOLD_2D);
        // (1.75 − 1.2788)/0.5 = 0.9424: the surface row is nearly Dirichlet; the rows below are Poisson rows.
        assert!((phi(surface) - 0.9424).abs() < 1e-3, "surface row φ = {}", phi(surface));
        assert_eq!(phi(second), 0.0);
        assert_eq!(phi(interior), 0.0);
        // Continuous across the band: the ends and the threshold.
        assert_eq!(phi(THRESHOLD_2D - BLEND_2D), 1.0);
        assert_eq!(phi(THRESHOLD_2D + BLEND_2D), 0.0);
        assert!((phi(THRESHOLD_2D) - 0.5).abs() < 1e-12);
    }
}
