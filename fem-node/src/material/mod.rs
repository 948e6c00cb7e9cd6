//! Constitutive laws, all hyperelastic in plane strain (`F₃₃ = 1`, unit thickness).
//!
//! Each law gives the strain energy density `W(F)` per unit reference volume and the in-plane block of the first
//! Piola–Kirchhoff stress `P = ∂W/∂F`; the Cauchy stress follows as `σ = P Fᵀ / J`. The elements evaluate them
//! in a total-Lagrangian way (see [`crate::element`]).

pub mod linear_elastic;
pub mod neo_hookean;
pub mod st_venant_kirchhoff;

use cosim_proto::scene::{MaterialModel, MaterialSpec};
use nalgebra::Matrix2;

pub use linear_elastic::CorotationalLinearElastic;
pub use neo_hookean::NeoHookean;
pub use st_venant_kirchhoff::StVenantKirchhoff;

/// Lamé parameters (the 3D ones; plane strain uses them unchanged).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lame {
    /// First Lamé parameter λ \[Pa\].
    pub lambda: f64,
    /// Shear modulus μ \[Pa\].
    pub mu: f64,
}

impl Lame {
    /// `λ = E ν / ((1 + ν)(1 − 2ν))`, `μ = E / (2 (1 + ν))`.
    pub fn from_young_poisson(youngs_modulus: f64, poisson_ratio: f64) -> Self {
        let (e, nu) = (youngs_modulus, poisson_ratio);
        Self {
            lambda: e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            mu: e / (2.0 * (1.0 + nu)),
        }
    }

    /// P-wave modulus `λ + 2μ`; the dilatational wave speed is `c_d = sqrt((λ + 2μ) / ρ)`.
    pub fn p_wave_modulus(&self) -> f64 {
        self.lambda + 2.0 * self.mu
    }

    /// Plane-strain bending modulus `E / (1 − ν²) = 4μ(λ + μ) / (λ + 2μ)` (uniaxial stress in the plane, zero
    /// strain out of it).
    pub fn plane_strain_modulus(&self) -> f64 {
        4.0 * self.mu * (self.lambda + self.mu) / (self.lambda + 2.0 * self.mu)
    }
}

/// A hyperelastic law in plane strain.
pub trait Hyperelastic {
    /// Strain energy density `W(F)` [J/m³] of the in-plane deformation gradient `F` (with `F₃₃ = 1`).
    fn energy_density(&self, f: &Matrix2<f64>) -> f64;

    /// In-plane first Piola–Kirchhoff stress `P = ∂W/∂F` \[Pa\].
    fn first_piola(&self, f: &Matrix2<f64>) -> Matrix2<f64>;

    /// Cauchy stress `σ = P Fᵀ / J` \[Pa\] (in-plane block).
    fn cauchy(&self, f: &Matrix2<f64>) -> Matrix2<f64> {
        self.first_piola(f) * f.transpose() / f.determinant()
    }
}

/// The material of one solid (enum dispatch keeps the element loop monomorphic and cheap).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// [`CorotationalLinearElastic`].
    LinearElastic(CorotationalLinearElastic),
    /// [`NeoHookean`].
    NeoHookean(NeoHookean),
    /// [`StVenantKirchhoff`].
    StVenantKirchhoff(StVenantKirchhoff),
}

impl Material {
    /// The law a scene asks for, with its Lamé parameters from E and ν.
    pub fn from_spec(spec: &MaterialSpec) -> Self {
        let lame = Lame::from_young_poisson(spec.youngs_modulus, spec.poisson_ratio);
        match spec.model {
            MaterialModel::LinearElastic => Material::LinearElastic(CorotationalLinearElastic { lame }),
            MaterialModel::NeoHookean => Material::NeoHookean(NeoHookean { lame }),
            MaterialModel::StVenantKirchhoff => Material::StVenantKirchhoff(StVenantKirchhoff { lame }),
        }
    }

    /// Lamé parameters (the small-strain moduli of every law here).
    pub fn lame(&self) -> Lame {
        match self {
            Material::LinearElastic(m) => m.lame,
            Material::NeoHookean(m) => m.lame,
            Material::StVenantKirchhoff(m) => m.lame,
        }
    }
}

impl Hyperelastic for Material {
    #[inline]
    fn energy_density(&self, f: &Matrix2<f64>) -> f64 {
        match self {
            Material::LinearElastic(m) => m.energy_density(f),
            Material::NeoHookean(m) => m.energy_density(f),
            Material::StVenantKirchhoff(m) => m.energy_density(f),
        }
    }

    #[inline]
    fn first_piola(&self, f: &Matrix2<f64>) -> Matrix2<f64> {
        match self {
            Material::LinearElastic(m) => m.first_piola(f),
            Material::NeoHookean(m) => m.first_piola(f),
            Material::StVenantKirchhoff(m) => m.first_piola(f),
        }
    }
}

#[cfg(test)]
pub(crate) mod test_support {
    use super::*;

    /// Central-difference check of `P = ∂W/∂F`; returns the largest error relative to `scale`.
    pub fn piola_matches_energy_gradient(law: &impl Hyperelastic, f: Matrix2<f64>, scale: f64) -> f64 {
        let p = law.first_piola(&f);
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for i in 0..2 {
            for j in 0..2 {
                let mut fp = f;
                fp[(i, j)] += h;
                let mut fm = f;
                fm[(i, j)] -= h;
                let d = (law.energy_density(&fp) - law.energy_density(&fm)) / (2.0 * h);
                worst = worst.max((d - p[(i, j)]).abs() / scale);
            }
        }
        worst
    }

    /// A rotation by `angle`.
    pub fn rotation(angle: f64) -> Matrix2<f64> {
        let (s, c) = angle.sin_cos();
        Matrix2::new(c, -s, s, c)
    }

    /// The Lamé parameters of the Turek CSM bar (E = 1.4 MPa, ν = 0.4).
    pub fn turek() -> Lame {
        Lame::from_young_poisson(1.4e6, 0.4)
    }

    /// The tests every hyperelastic law passes, written once and expanded in each law's `tests` module (as fenris
    /// applies its test macros to every material): `hyperelastic_law_tests!(law(), rigid_energy_tolerance = 1e-9)`.
    /// `law()` makes the law (with a `lame` field); the tolerance bounds `W` of a rigid rotation relative to μ,
    /// which is exactly zero in exact arithmetic for every law but carries each formula's own round-off.
    ///
    /// - `zero_stress_for_identity_and_rigid_rotation`: `P(I) = 0` exactly, `P(R) ≈ 0` and `W(R) ≈ 0`;
    /// - `matches_hooke_for_small_strain`: `σ` of `F = I + ∇u`, |∇u| ~ 1e-6, is Hooke's within 1e-5;
    /// - `piola_is_the_energy_gradient`: `P = ∂W/∂F` by central differences at stretched and rotated `F`.
    macro_rules! hyperelastic_law_tests {
        ($law:expr, rigid_energy_tolerance = $tolerance:expr) => {
            #[test]
            fn zero_stress_for_identity_and_rigid_rotation() {
                use nalgebra::Matrix2;
                use $crate::material::test_support::rotation;
                use $crate::material::Hyperelastic;
                let m = $law;
                assert_eq!(m.first_piola(&Matrix2::identity()), Matrix2::zeros());
                for angle in [0.3, 1.7, -2.9, std::f64::consts::PI * 0.999] {
                    let p = m.first_piola(&rotation(angle));
                    assert!(p.abs().max() < 1e-9 * m.lame.mu, "angle {angle}: {p}");
                    assert!(m.energy_density(&rotation(angle)).abs() < $tolerance * m.lame.mu);
                }
            }

            #[test]
            fn matches_hooke_for_small_strain() {
                use nalgebra::Matrix2;
                use $crate::material::Hyperelastic;
                let m = $law;
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
                use nalgebra::Matrix2;
                use $crate::material::test_support::{piola_matches_energy_gradient, rotation};
                let m = $law;
                for f in [
                    rotation(0.6) * Matrix2::new(1.1, 0.05, 0.05, 0.93),
                    rotation(-0.4) * Matrix2::new(1.2, 0.1, 0.1, 0.85),
                    rotation(2.0) * Matrix2::new(1.05, -0.1, -0.1, 0.9),
                ] {
                    assert!(piola_matches_energy_gradient(&m, f, m.lame.mu) < 1e-6, "F = {f}");
                }
            }
        };
    }
    pub(crate) use hyperelastic_law_tests;

    #[test]
    fn lame_of_turek_bar() {
        let l = turek();
        assert!((l.lambda - 2.0e6).abs() < 1e-6 && (l.mu - 0.5e6).abs() < 1e-6, "{l:?}");
        assert!((l.plane_strain_modulus() - 1.4e6 / (1.0 - 0.16)).abs() < 1e-6);
    }
}
