//! St. Venant–Kirchhoff law (the Turek–Hron CSM benchmarks use it).

use nalgebra::Matrix2;

use super::{Hyperelastic, Lame};

/// St. Venant–Kirchhoff solid in plane strain (`E₃₃ = 0`):
///
/// `E = ½ (FᵀF − I)`, `S = λ tr(E) I + 2μ E`, `P = F S`, `W = λ/2 (tr E)² + μ E:E`.
///
/// Exact for rigid rotations, Hooke's law for small strain; it softens (and loses stability) in strong
/// compression, which the benchmarks never reach.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StVenantKirchhoff {
    /// Lamé parameters.
    pub lame: Lame,
}

impl StVenantKirchhoff {
    fn green_lagrange(f: &Matrix2<f64>) -> Matrix2<f64> {
        (f.transpose() * f - Matrix2::identity()) * 0.5
    }
}

impl Hyperelastic for StVenantKirchhoff {
    fn energy_density(&self, f: &Matrix2<f64>) -> f64 {
        let e = Self::green_lagrange(f);
        let tr = e.trace();
        0.5 * self.lame.lambda * tr * tr + self.lame.mu * e.component_mul(&e).sum()
    }

    fn first_piola(&self, f: &Matrix2<f64>) -> Matrix2<f64> {
        let e = Self::green_lagrange(f);
        let s = Matrix2::identity() * (self.lame.lambda * e.trace()) + e * (2.0 * self.lame.mu);
        f * s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::test_support::*;

    fn law() -> StVenantKirchhoff {
        StVenantKirchhoff { lame: turek() }
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
        let f = rotation(2.0) * Matrix2::new(1.05, -0.1, -0.1, 0.9);
        assert!(piola_matches_energy_gradient(&m, f, m.lame.mu) < 1e-6);
    }
}
