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

    #[test]
    fn lame_of_turek_bar() {
        let l = turek();
        assert!((l.lambda - 2.0e6).abs() < 1e-6 && (l.mu - 0.5e6).abs() < 1e-6, "{l:?}");
        assert!((l.plane_strain_modulus() - 1.4e6 / (1.0 - 0.16)).abs() < 1e-6);
    }
}
