//! Linear elastic (Hooke) law in a corotational frame.

use nalgebra::Matrix2;

use super::{Hyperelastic, Lame};
use crate::kinematics::{polar_rotation, rotation_matrix};

/// Small-strain Hooke's law applied to the stretch of the polar decomposition `F = R U`, rotated back:
///
/// `ε = U − I`, `T = λ tr(ε) I + 2μ ε`, `P = R T`, `W = μ ε:ε + λ/2 (tr ε)²` (plane strain, `ε₃₃ = 0`).
///
/// Because `T` is a polynomial in `U` (coaxial with it), `P = R T` is exactly `∂W/∂F`: the law is hyperelastic
/// (the "Biot" material), rigid rotations give exactly zero stress, and for small strain it is Hooke's law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CorotationalLinearElastic {
    /// Lamé parameters.
    pub lame: Lame,
}

impl CorotationalLinearElastic {
    /// `(R, ε = U − I)`; a deformation without a polar rotation (only for `det F ≤ 0`) gets `R = I`.
    fn rotation_and_strain(f: &Matrix2<f64>) -> (Matrix2<f64>, Matrix2<f64>) {
        let r = polar_rotation(f).map(rotation_matrix).unwrap_or_else(Matrix2::identity);
        let u = r.transpose() * f;
        // U is symmetric up to round-off; symmetrise so that W and T see a proper strain.
        let off = 0.5 * (u[(0, 1)] + u[(1, 0)]);
        let eps = Matrix2::new(u[(0, 0)] - 1.0, off, off, u[(1, 1)] - 1.0);
        (r, eps)
    }
}

impl Hyperelastic for CorotationalLinearElastic {
    fn energy_density(&self, f: &Matrix2<f64>) -> f64 {
        let (_, eps) = Self::rotation_and_strain(f);
        let tr = eps.trace();
        self.lame.mu * eps.component_mul(&eps).sum() + 0.5 * self.lame.lambda * tr * tr
    }

    fn first_piola(&self, f: &Matrix2<f64>) -> Matrix2<f64> {
        let (r, eps) = Self::rotation_and_strain(f);
        let t = Matrix2::identity() * (self.lame.lambda * eps.trace()) + eps * (2.0 * self.lame.mu);
        r * t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::test_support::*;

    fn law() -> CorotationalLinearElastic {
        CorotationalLinearElastic { lame: turek() }
    }

    hyperelastic_law_tests!(law(), rigid_energy_tolerance = 1e-20);

    #[test]
    fn hooke_stress_is_rotated_with_the_body() {
        let m = law();
        let stretch = Matrix2::new(1.01, 0.002, 0.002, 0.995);
        let q = rotation(0.8);
        let s0 = m.cauchy(&stretch);
        let s1 = m.cauchy(&(q * stretch));
        assert!((s1 - q * s0 * q.transpose()).abs().max() < 1e-9 * s0.abs().max());
    }
}
