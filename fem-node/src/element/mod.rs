//! Finite elements: reference data built once, evaluated total-Lagrangian each step.
//!
//! The design (`DESIGN.md` §4.1) states the updated-Lagrangian form of Eq. (1)–(4) of Long et al. 2016. For the
//! hyperelastic and corotational laws used here the total-Lagrangian evaluation, `F` from reference shape-function
//! gradients and `f_I = ∫ P ∇_X N_I dA`, is the same weak form pulled back to the reference configuration
//! (`σ_ji ∂N_I/∂x_j dΩ = P_ij ∂N_I/∂X_j dΩ₀`), so it gives the same forces without tracking stress rates.

pub mod quad4;
pub mod tri3;

use std::fmt;

use nalgebra::Matrix2;

use crate::material::{Hyperelastic, Material};
pub use quad4::Quad4;
pub use tri3::Tri3;

/// Nodal forces of one element (`[3]` unused by triangles).
pub type ElementForces = [[f64; 2]; 4];

/// Why an element cannot be evaluated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ElementFailure {
    /// `J ≤ 0` (mean or at a corner), relative to the reference configuration.
    Inverted {
        /// The offending Jacobian ratio.
        jacobian: f64,
    },
    /// A position, stress or force is NaN or infinite.
    NonFinite,
}

impl fmt::Display for ElementFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ElementFailure::Inverted { jacobian } => write!(f, "inverted element (J = {jacobian:.3e} <= 0)"),
            ElementFailure::NonFinite => write!(f, "non-finite position, stress or force"),
        }
    }
}

/// An element of any kind.
#[derive(Clone, Debug, PartialEq)]
pub enum Element {
    /// 4-node quad.
    Quad4(Quad4),
    /// 3-node triangle.
    Tri3(Tri3),
}

impl Element {
    /// Global node ids, counter-clockwise.
    pub fn nodes(&self) -> &[u32] {
        match self {
            Element::Quad4(e) => &e.nodes,
            Element::Tri3(e) => &e.nodes,
        }
    }

    /// Reference area \[m²\].
    pub fn reference_area(&self) -> f64 {
        match self {
            Element::Quad4(e) => e.area,
            Element::Tri3(e) => e.area,
        }
    }

    /// Internal nodal forces from the global positions `x`.
    #[inline]
    pub fn internal_forces(
        &self,
        x: &[[f64; 2]],
        law: &Material,
        out: &mut ElementForces,
    ) -> Result<(), ElementFailure> {
        match self {
            Element::Quad4(e) => e.internal_forces(&gather(x, &e.nodes), law, out),
            Element::Tri3(e) => e.internal_forces(&gather(x, &e.nodes), law, out),
        }
    }

    /// Stored energy [J per unit thickness].
    pub fn strain_energy(&self, x: &[[f64; 2]], law: &Material) -> f64 {
        match self {
            Element::Quad4(e) => e.strain_energy(&gather(x, &e.nodes), law),
            Element::Tri3(e) => e.strain_energy(&gather(x, &e.nodes), law),
        }
    }

    /// Deformation gradient (the mean one for a quad).
    pub fn deformation_gradient(&self, x: &[[f64; 2]]) -> Matrix2<f64> {
        match self {
            Element::Quad4(e) => e.deformation_gradient(&gather(x, &e.nodes)),
            Element::Tri3(e) => e.deformation_gradient(&gather(x, &e.nodes)),
        }
    }

    /// Cauchy stress `[σxx, σyy, σxy]` (of the mean deformation gradient for a quad).
    pub fn cauchy_stress(&self, x: &[[f64; 2]], law: &Material) -> [f64; 3] {
        let s = law.cauchy(&self.deformation_gradient(x));
        [s[(0, 0)], s[(1, 1)], 0.5 * (s[(0, 1)] + s[(1, 0)])]
    }

    /// Characteristic length of the current shape for the stable step.
    pub fn characteristic_length(&self, x: &[[f64; 2]]) -> f64 {
        match self {
            Element::Quad4(e) => Quad4::characteristic_length(&gather(x, &e.nodes)),
            Element::Tri3(e) => Tri3::characteristic_length(&gather(x, &e.nodes)),
        }
    }
}

/// Positions of an element's nodes.
#[inline]
fn gather<const N: usize>(x: &[[f64; 2]], nodes: &[u32; N]) -> [[f64; 2]; N] {
    nodes.map(|n| x[n as usize])
}

#[cfg(test)]
pub(crate) mod test_support {
    /// The tests every element passes, written once and expanded in each element's `tests` module (as fenris
    /// applies its test macros to every element), under every material law:
    /// `element_tests!(element = |lame| Quad4::new(..), deformed = [..], lame = Lame::from_young_poisson(..))`.
    ///
    /// - `forces_are_the_energy_gradient`: the internal nodal forces at the deformed positions are `∂E/∂x` of the
    ///   element's strain energy, by central differences (h = 1e-7, error below 1e-5 · 1e6), for each of the
    ///   linear elastic, neo-Hookean and St. Venant–Kirchhoff laws with the given Lamé parameters.
    macro_rules! element_tests {
        (element = $element:expr, deformed = $x:expr, lame = $lame:expr) => {
            #[test]
            fn forces_are_the_energy_gradient() {
                use $crate::material::{CorotationalLinearElastic, Material, NeoHookean, StVenantKirchhoff};
                let lame = $lame;
                let element = ($element)(lame);
                let x = $x;
                for law in [
                    Material::LinearElastic(CorotationalLinearElastic { lame }),
                    Material::NeoHookean(NeoHookean { lame }),
                    Material::StVenantKirchhoff(StVenantKirchhoff { lame }),
                ] {
                    let mut f = [[0.0; 2]; 4];
                    element.internal_forces(&x, &law, &mut f).unwrap();
                    let h = 1e-7;
                    for i in 0..x.len() {
                        for k in 0..2 {
                            let (mut xp, mut xm) = (x, x);
                            xp[i][k] += h;
                            xm[i][k] -= h;
                            let d = (element.strain_energy(&xp, &law) - element.strain_energy(&xm, &law)) / (2.0 * h);
                            assert!(
                                (d - f[i][k]).abs() < 1e-5 * 1e6,
                                "{law:?} node {i} comp {k}: {d} vs {}",
                                f[i][k]
                            );
                        }
                    }
                }
            }
        };
    }
    pub(crate) use element_tests;
}
