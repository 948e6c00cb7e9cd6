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

    hyperelastic_law_tests!(law(), rigid_energy_tolerance = 1e-9);
}
