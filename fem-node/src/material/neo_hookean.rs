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

    hyperelastic_law_tests!(law(), rigid_energy_tolerance = 1e-9);
}
