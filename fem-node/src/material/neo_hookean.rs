//! Compressible neo-Hookean law.

use nalgebra::Matrix2;

use super::{Hyperelastic, Lame};

/// Compressible neo-Hookean solid in plane strain (`F₃₃ = 1`, so `I₁ = tr(FᵀF) + 1`, `J = det F`):
///
/// `W = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)²`, `P = μ (F − F⁻ᵀ) + λ ln J F⁻ᵀ`.
///
/// Its small-strain limit is Hooke's law with the same λ, μ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeoHookean {
    /// Lamé parameters.
    pub lame: Lame,
}

impl Hyperelastic for NeoHookean {
    fn energy_density(&self, f: &Matrix2<f64>) -> f64 {
        let ln_j = f.determinant().ln();
        let i1 = f.component_mul(f).sum() + 1.0;
        0.5 * self.lame.mu * (i1 - 3.0) - self.lame.mu * ln_j + 0.5 * self.lame.lambda * ln_j * ln_j
    }

    fn first_piola(&self, f: &Matrix2<f64>) -> Matrix2<f64> {
        let j = f.determinant();
        // F⁻ᵀ of a 2×2 matrix: cofactor / J.
        let f_inv_t = Matrix2::new(f[(1, 1)], -f[(1, 0)], -f[(0, 1)], f[(0, 0)]) / j;
        (f - f_inv_t) * self.lame.mu + f_inv_t * (self.lame.lambda * j.ln())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::test_support::*;

    fn law() -> NeoHookean {
        NeoHookean { lame: turek() }
    }

    #[test]
    fn zero_stress_for_identity_and_rigid_rotation() {
        let m = law();
        assert_eq!(m.first_piola(&Matrix2::identity()), Matrix2::zeros());
        for angle in [0.3, 1.7, -2.9] {
            let p = m.first_piola(&rotation(angle));
            assert!(p.abs().max() < 1e-9 * m.lame.mu, "angle {angle}: {p}");
            assert!(m.energy_density(&rotation(angle)).abs() < 1e-9 * m.lame.mu);
        }
    }

    #[test]
    fn matches_hooke_for_small_strain() {
        let m = law();
        let grad = Matrix2::new(0.3, -0.7, 0.4, 0.9) * 1e-6;
        let sigma = m.cauchy(&(Matrix2::identity() + grad));
        let eps = 0.5 * (grad + grad.transpose());
        let hooke = Matrix2::identity() * (m.lame.lambda * eps.trace()) + eps * (2.0 * m.lame.mu);
        assert!(
            (sigma - hooke).abs().max() < 1e-5 * hooke.abs().max(),
            "{sigma} vs {hooke}"
        );
    }

    #[test]
    fn piola_is_the_energy_gradient() {
        let m = law();
        let f = rotation(-0.4) * Matrix2::new(1.2, 0.1, 0.1, 0.85);
        assert!(piola_matches_energy_gradient(&m, f, m.lame.mu) < 1e-6);
    }
}
