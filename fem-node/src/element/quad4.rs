//! 4-node quadrilateral with one-point integration and physical (assumed-strain) hourglass stabilisation.
//!
//! * Mean part: the deformation gradient is the Flanagan–Belytschko uniform gradient of the reference element,
//!   `F = Σ_I x_I ⊗ b_I` with `b_I = (1/A) ∫ ∇_X N_I dA` (Flanagan & Belytschko 1981), and the nodal
//!   forces are `f_I = A P b_I` (the one-point rule of Eq. (4), Long et al. 2016, written total-Lagrangian).
//! * Hourglass part: the FB hourglass base vector `γ_I = ¼ (h_I − (h·X_k) b_kI)`, `h = (1, −1, 1, −1)`
//!   (Flanagan & Belytschko 1981), is orthogonal to every linear field, so the hourglass
//!   displacement `g = Σ_I γ_I x_I` vanishes under any homogeneous deformation. It is measured in the element's
//!   corotational frame, `q = Rᵀ g` with `R` the polar rotation of `F`, and resisted by the energy
//!   `E_hg = ½ qᵀ K q` with the *physical* stiffness of the assumed-strain "quintessential bending" element
//!   (Belytschko & Bindeman 1991, CMAME 88: 311–340): parasitic shear dropped, the other normal
//!   stress relaxed, which for a rectangle of half-sides `a` (along ξ) and `b` (along η) gives
//!   `K = 4/3 E' [(b/a) e_ξ e_ξᵀ + (a/b) e_η e_ηᵀ]`, `E' = E / (1 − ν²)` (plane strain).
//!   That is the exact energy of pure bending, so a beam with a single element through its thickness bends
//!   correctly and there is no shear locking. The forces are the exact gradient of `E_hg` including the
//!   derivative of the rotation, so the element is conservative and keeps linear and angular momentum.
//!
//! The stabilisation uses the small-strain moduli of the material for every law; it only carries the part of the
//! strain that varies linearly across an element, which is small when the mesh resolves the deformation.

use nalgebra::{Matrix2, Vector2};

use super::{ElementFailure, ElementForces};
use crate::kinematics::{cross, polar_rotation, rotation_matrix, vec2};
use crate::material::{Hyperelastic, Lame};

/// ξ of the four corners (counter-clockwise from (−1, −1)).
const XI: [f64; 4] = [-1.0, 1.0, 1.0, -1.0];
/// η of the four corners.
const ETA: [f64; 4] = [-1.0, -1.0, 1.0, 1.0];
/// The hourglass pattern `h = ξη` at the corners.
const H: [f64; 4] = [1.0, -1.0, 1.0, -1.0];

/// A reference quad element, counter-clockwise nodes.
#[derive(Clone, Debug, PartialEq)]
pub struct Quad4 {
    /// Global node ids, counter-clockwise.
    pub nodes: [u32; 4],
    /// Reference area \[m²\].
    pub area: f64,
    /// FB uniform gradient `b_I` of the reference configuration.
    grad: [Vector2<f64>; 4],
    /// FB hourglass base vector `γ_I` of the reference configuration.
    gamma: [f64; 4],
    /// Hourglass stiffness `K` (symmetric, reference frame) \[Pa\].
    k_hg: Matrix2<f64>,
}

/// The hourglass state of a deformed element.
struct Hourglass {
    /// Polar rotation `R`.
    r: Matrix2<f64>,
    /// `q = Rᵀ g`.
    q: Vector2<f64>,
    /// `K q`.
    kq: Vector2<f64>,
}

impl Quad4 {
    /// Builds the element from its reference corner positions and the material's small-strain moduli.
    pub fn new(nodes: [u32; 4], x: [[f64; 2]; 4], lame: Lame) -> Result<Self, ElementFailure> {
        let p = x.map(vec2);
        let area = signed_area(&p);
        if !(area > 0.0 && area.is_finite()) {
            return Err(ElementFailure::Inverted { jacobian: area });
        }
        // Flanagan & Belytschko 1981: uniform gradient of a bilinear quad, exact in closed form.
        let inv = 1.0 / (2.0 * area);
        let grad = [
            Vector2::new(p[1].y - p[3].y, p[3].x - p[1].x) * inv,
            Vector2::new(p[2].y - p[0].y, p[0].x - p[2].x) * inv,
            Vector2::new(p[3].y - p[1].y, p[1].x - p[3].x) * inv,
            Vector2::new(p[0].y - p[2].y, p[2].x - p[0].x) * inv,
        ];
        // Flanagan & Belytschko 1981: hourglass base vector γ = ¼ [h − (h·x_k) b_k].
        let hx: Vector2<f64> = (0..4).map(|i| p[i] * H[i]).sum();
        let gamma = std::array::from_fn(|i| 0.25 * (H[i] - hx.dot(&grad[i])));
        // Half-axes of the element: X = X₀ + ξ j_ξ + η j_η + ξη (…).
        let j_xi: Vector2<f64> = (0..4).map(|i| p[i] * (0.25 * XI[i])).sum();
        let j_eta: Vector2<f64> = (0..4).map(|i| p[i] * (0.25 * ETA[i])).sum();
        let (a, b) = (j_xi.norm(), j_eta.norm());
        let e_xi = j_xi / a;
        let e_eta = Vector2::new(-e_xi.y, e_xi.x);
        // Belytschko & Bindeman 1991 (QBI): exact pure-bending energy ½ (4/3)(b/a) E' q² per mode.
        let e_prime = lame.plane_strain_modulus();
        let k_hg = (e_xi * e_xi.transpose() * (b / a) + e_eta * e_eta.transpose() * (a / b)) * (4.0 / 3.0 * e_prime);
        Ok(Self {
            nodes,
            area,
            grad,
            gamma,
            k_hg,
        })
    }

    /// Mean deformation gradient `F = Σ_I x_I ⊗ b_I`.
    pub fn deformation_gradient(&self, x: &[[f64; 2]; 4]) -> Matrix2<f64> {
        (0..4).map(|i| vec2(x[i]) * self.grad[i].transpose()).sum()
    }

    /// Checks the corners and the mean Jacobian; returns `F`.
    fn checked_gradient(&self, x: &[[f64; 2]; 4]) -> Result<Matrix2<f64>, ElementFailure> {
        let f = self.deformation_gradient(x);
        let j = f.determinant();
        if !j.is_finite() {
            return Err(ElementFailure::NonFinite);
        }
        if j <= 0.0 {
            return Err(ElementFailure::Inverted { jacobian: j });
        }
        // A quad can fold at a corner while its mean J stays positive (hourglassing): check every corner.
        let p = x.map(vec2);
        for i in 0..4 {
            let corner = cross(p[(i + 1) % 4] - p[i], p[(i + 3) % 4] - p[i]);
            if corner <= 0.0 {
                return Err(ElementFailure::Inverted {
                    jacobian: corner / self.area,
                });
            }
        }
        Ok(f)
    }

    fn hourglass(&self, f: &Matrix2<f64>, x: &[[f64; 2]; 4]) -> Option<Hourglass> {
        let r = rotation_matrix(polar_rotation(f)?);
        let g: Vector2<f64> = (0..4).map(|i| vec2(x[i]) * self.gamma[i]).sum();
        let q = r.transpose() * g;
        Some(Hourglass {
            r,
            q,
            kq: self.k_hg * q,
        })
    }

    /// Internal nodal forces `f_I = ∂E/∂x_I` (mean part plus hourglass part) into `out[0..4]`.
    pub fn internal_forces(
        &self,
        x: &[[f64; 2]; 4],
        law: &impl Hyperelastic,
        out: &mut ElementForces,
    ) -> Result<(), ElementFailure> {
        let f = self.checked_gradient(x)?;
        let p = law.first_piola(&f);
        let hg = self.hourglass(&f, x).ok_or(ElementFailure::Inverted {
            jacobian: f.determinant(),
        })?;
        // ∂E_hg/∂θ: q = R(θ)ᵀ g gives dq/dθ = (q_y, −q_x).
        let de_dtheta = hg.kq.x * hg.q.y - hg.kq.y * hg.q.x;
        // θ = atan2(F₂₁ − F₁₂, F₁₁ + F₂₂): ∂θ/∂F = [[−s, −c], [c, −s]] / r².
        let (c, s) = (f[(0, 0)] + f[(1, 1)], f[(1, 0)] - f[(0, 1)]);
        let dtheta_df = Matrix2::new(-s, -c, c, -s) / (c * c + s * s);
        // One-point rule for the mean stress plus the rotation term of the hourglass energy, both acting on b_I.
        let mean = p * self.area + dtheta_df * de_dtheta;
        let rkq = hg.r * hg.kq;
        for (o, (b, gamma)) in out.iter_mut().zip(self.grad.iter().zip(self.gamma)) {
            let fi = mean * b + rkq * gamma;
            *o = [fi.x, fi.y];
        }
        if out.iter().flatten().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(ElementFailure::NonFinite)
        }
    }

    /// Stored energy `W(F) A + ½ qᵀ K q` [J per unit thickness].
    pub fn strain_energy(&self, x: &[[f64; 2]; 4], law: &impl Hyperelastic) -> f64 {
        let f = self.deformation_gradient(x);
        let hourglass = self.hourglass(&f, x).map_or(0.0, |hg| 0.5 * hg.q.dot(&hg.kq));
        law.energy_density(&f) * self.area + hourglass
    }

    /// Characteristic length of the current shape: area over the longest diagonal (the critical length of a
    /// one-point quad with lumped mass: `Δt_crit = L_e / c_d` exactly for a square).
    pub fn characteristic_length(x: &[[f64; 2]; 4]) -> f64 {
        let p = x.map(vec2);
        let d1 = (p[2] - p[0]).norm();
        let d2 = (p[3] - p[1]).norm();
        signed_area(&p) / d1.max(d2)
    }

    /// Row-sum lumped masses `m_I = Σ_J M_IJ = ρ ∫ N_I dA` (Eq. (6), Long et al. 2016, row-summed; 2×2 Gauss, exact
    /// for a bilinear quad).
    pub fn lumped_masses(x: &[[f64; 2]; 4], density: f64) -> [f64; 4] {
        let p = x.map(vec2);
        let g = 1.0 / 3f64.sqrt();
        let mut m = [0.0; 4];
        for (xi, eta) in [(-g, -g), (g, -g), (g, g), (-g, g)] {
            let n: [f64; 4] = std::array::from_fn(|i| 0.25 * (1.0 + XI[i] * xi) * (1.0 + ETA[i] * eta));
            let dx_dxi: Vector2<f64> = (0..4).map(|i| p[i] * (0.25 * XI[i] * (1.0 + ETA[i] * eta))).sum();
            let dx_deta: Vector2<f64> = (0..4).map(|i| p[i] * (0.25 * ETA[i] * (1.0 + XI[i] * xi))).sum();
            let det = cross(dx_dxi, dx_deta);
            for i in 0..4 {
                m[i] += density * n[i] * det;
            }
        }
        m
    }
}

/// Area of a quad from its diagonals, `½ (x₃ − x₁) × (x₄ − x₂)`; positive when counter-clockwise.
fn signed_area(p: &[Vector2<f64>; 4]) -> f64 {
    0.5 * cross(p[2] - p[0], p[3] - p[1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::test_support::element_tests;
    use crate::material::{Hyperelastic, Lame, StVenantKirchhoff};

    fn lame() -> Lame {
        Lame::from_young_poisson(1.0e6, 0.3)
    }

    fn rect(w: f64, h: f64) -> [[f64; 2]; 4] {
        [[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]]
    }

    #[test]
    fn gradient_and_gamma_of_a_square() {
        let q = Quad4::new([0, 1, 2, 3], rect(2.0, 2.0), lame()).unwrap();
        assert_eq!(q.area, 4.0);
        assert_eq!(q.grad[0], Vector2::new(-0.25, -0.25));
        assert_eq!(q.gamma, [0.25, -0.25, 0.25, -0.25]);
        assert_eq!(Quad4::lumped_masses(&rect(2.0, 2.0), 3.0), [3.0; 4]);
    }

    element_tests!(
        element = |lame| Quad4::new([0, 1, 2, 3], [[0.1, 0.0], [1.3, 0.1], [1.2, 0.8], [0.0, 0.7]], lame).unwrap(),
        deformed = [[0.15, -0.05], [1.25, 0.3], [1.0, 1.0], [-0.15, 0.65]],
        lame = lame()
    );

    #[test]
    fn pure_bending_energy_is_exact() {
        // u_x = κ x y on a 2a × 2b rectangle centred at the origin; exact plane-strain energy
        // ½ E' κ² ∫ y² dA (σ_yy = 0 through the relaxed transverse strain).
        let lame = lame();
        let (a, b, kappa) = (0.3, 0.1, 1e-4);
        let x0 = [[-a, -b], [a, -b], [a, b], [-a, b]];
        let q = Quad4::new([0, 1, 2, 3], x0, lame).unwrap();
        let law = StVenantKirchhoff { lame };
        let x = x0.map(|p| [p[0] + kappa * p[0] * p[1], p[1]]);
        let exact = 0.5 * lame.plane_strain_modulus() * kappa * kappa * (2.0 * a) * (2.0 * b).powi(3) / 12.0;
        let e = q.strain_energy(&x, &law);
        assert!((e - exact).abs() < 1e-6 * exact, "{e} vs {exact}");
    }

    #[test]
    fn inverted_corner_is_reported() {
        let law = StVenantKirchhoff { lame: lame() };
        let q = Quad4::new([0, 1, 2, 3], rect(1.0, 1.0), lame()).unwrap();
        // Node 2 pulled inside past the diagonal: mean J > 0 but the corner at node 2 folds.
        let x = [[0.0, 0.0], [1.0, 0.0], [0.3, 0.3], [0.0, 1.0]];
        let mut f = [[0.0; 2]; 4];
        assert!(matches!(
            q.internal_forces(&x, &law, &mut f),
            Err(ElementFailure::Inverted { .. })
        ));
        assert!(law.energy_density(&q.deformation_gradient(&x)).is_finite());
    }
}
