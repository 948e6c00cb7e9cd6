//! 3-node constant-strain triangle (CST).

use nalgebra::{Matrix2, Vector2};

use super::{ElementFailure, ElementForces};
use crate::kinematics::{cross, vec2};
use crate::material::Hyperelastic;

/// A reference triangle, counter-clockwise nodes. `F = Σ_I x_I ⊗ ∇_X N_I` is constant over the element and the
/// nodal forces `f_I = A P ∇_X N_I` are exact (Eq. (4), Long et al. 2016, written total-Lagrangian).
#[derive(Clone, Debug, PartialEq)]
pub struct Tri3 {
    /// Global node ids, counter-clockwise.
    pub nodes: [u32; 3],
    /// Reference area \[m²\].
    pub area: f64,
    /// Reference shape-function gradients `∇_X N_I`.
    grad: [Vector2<f64>; 3],
}

impl Tri3 {
    /// Builds the element from its reference corner positions.
    pub fn new(nodes: [u32; 3], x: [[f64; 2]; 3]) -> Result<Self, ElementFailure> {
        let p = x.map(vec2);
        let area = 0.5 * cross(p[1] - p[0], p[2] - p[0]);
        if !(area > 0.0 && area.is_finite()) {
            return Err(ElementFailure::Inverted { jacobian: area });
        }
        // ∇N_I = (y_J − y_K, x_K − x_J) / 2A for (I, J, K) cyclic.
        let grad = std::array::from_fn(|i| {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            Vector2::new(p[j].y - p[k].y, p[k].x - p[j].x) / (2.0 * area)
        });
        Ok(Self { nodes, area, grad })
    }

    /// Deformation gradient `F = Σ_I x_I ⊗ ∇_X N_I`.
    pub fn deformation_gradient(&self, x: &[[f64; 2]; 3]) -> Matrix2<f64> {
        (0..3).map(|i| vec2(x[i]) * self.grad[i].transpose()).sum()
    }

    /// Internal nodal forces `f_I = A P ∇_X N_I` into `out[0..3]` (`out[3]` is set to zero).
    pub fn internal_forces(
        &self,
        x: &[[f64; 2]; 3],
        law: &impl Hyperelastic,
        out: &mut ElementForces,
    ) -> Result<(), ElementFailure> {
        let f = self.deformation_gradient(x);
        let j = f.determinant();
        if !j.is_finite() {
            return Err(ElementFailure::NonFinite);
        }
        if j <= 0.0 {
            return Err(ElementFailure::Inverted { jacobian: j });
        }
        let pa = law.first_piola(&f) * self.area;
        for (o, g) in out.iter_mut().zip(&self.grad) {
            let fi = pa * g;
            *o = [fi.x, fi.y];
        }
        out[3] = [0.0; 2];
        if out.iter().flatten().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(ElementFailure::NonFinite)
        }
    }

    /// Stored energy `W(F) A` [J per unit thickness].
    pub fn strain_energy(&self, x: &[[f64; 2]; 3], law: &impl Hyperelastic) -> f64 {
        law.energy_density(&self.deformation_gradient(x)) * self.area
    }

    /// Characteristic length of the current shape: the smallest altitude, `2A / longest edge`.
    pub fn characteristic_length(x: &[[f64; 2]; 3]) -> f64 {
        let p = x.map(vec2);
        let area2 = cross(p[1] - p[0], p[2] - p[0]);
        let longest = (0..3).map(|i| (p[(i + 1) % 3] - p[i]).norm()).fold(0.0, f64::max);
        area2 / longest
    }

    /// Row-sum lumped masses `ρ A / 3` (Eq. (6), Long et al. 2016, row-summed).
    pub fn lumped_masses(x: &[[f64; 2]; 3], density: f64) -> [f64; 3] {
        let p = x.map(vec2);
        [density * 0.5 * cross(p[1] - p[0], p[2] - p[0]) / 3.0; 3]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::test_support::element_tests;
    use crate::material::Lame;

    #[test]
    fn gradients_of_the_unit_triangle() {
        let t = Tri3::new([0, 1, 2], [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]).unwrap();
        assert_eq!(
            t.grad,
            [Vector2::new(-1.0, -1.0), Vector2::new(1.0, 0.0), Vector2::new(0.0, 1.0)]
        );
        assert!(Tri3::new([0, 2, 1], [[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]]).is_err());
    }

    element_tests!(
        element = |_| Tri3::new([0, 1, 2], [[0.0, 0.0], [1.0, 0.2], [0.3, 0.9]]).unwrap(),
        deformed = [[0.1, -0.1], [1.2, 0.4], [0.0, 1.0]],
        lame = Lame::from_young_poisson(1.0e6, 0.45)
    );
}
