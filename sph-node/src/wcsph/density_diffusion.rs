//! Density diffusion, δ-SPH (`fluid.density_diffusion`, off by default): the diffusive term of Molteni &
//! Colagrossi 2009 (Comput. Phys. Commun. 180:861) added to the continuity equation, Eq. (9) of Long et al. 2016,
//! with the hydrostatic correction of Fourtakas et al. 2019 (Comput. Fluids 190:346; DualSPHysics' density
//! diffusion term "DDT type 2"):
//!
//! D_i = 2 δ h c0 Σ_j ψ_ij (r_ji · ∇_i W_ij) / |r_ij|² V_j,   ψ_ij = (ρ_j − ρ_i) − ρ^H_ij,
//!
//! with V_j = m_j/ρ_j, r_ji = x_j − x_i and ρ^H_ij the density difference of the hydrostatic state between the two
//! particles. (r_ji · ∇_i W_ij)/|r_ij|² is −F_ij for ∇_i W_ij = F_ij r_ij, so no regularising η² is needed: F is
//! finite at r → 0 for the cubic spline.
//!
//! ρ^H_ij: Fourtakas et al. take ρ0 [(1 + ρ0 g z_ji/B)^{1/γ} − 1] from the inverse Tait law; here it is that law
//! linearised in ρ0 g z/B, ρ^H_ij = (ρ0/c0²) g · r_ji (g the gravity vector, any direction). The two differ by
//! O((ρ0 g |r_ij|/B)²) — about 10⁻³ of ρ^H_ij at the spacings of the scenes — far below what the correction leaves
//! on the Tait hydrostatic state anyway (the curvature of ρ(depth), second order in the depth); the linear form is
//! antisymmetric, ρ^H_ji = −ρ^H_ij, so every pair term is, and Σ_i V_i D_i = 0 to round-off (the term moves mass
//! between particles and creates none), and it costs no power per pair.
//!
//! Without the correction (plain Molteni & Colagrossi, [`DensityDiffusion::uncorrected`], for tests and
//! comparisons) the term acts on the hydrostatic density gradient wherever the kernel is truncated: at the free
//! surface and along the walls (fluid–fluid pairs only, see below) it is first order in the gradient and pushes the
//! still tank off its hydrostatic state (`sph-node/tests/density_diffusion.rs`).
//!
//! Pairs: fluid–fluid only. Wall particles carry the extrapolated Adami density (§4.7), which does not evolve by
//! this equation; a fluid–wall pair would not be antisymmetric. (DualSPHysics' DDT type 2 likewise leaves
//! fluid–boundary pairs out.)

use crate::kernel::CubicSpline;
use crate::particles::{separation, ParticleView};

/// The constants of the term for one fluid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DensityDiffusion {
    /// 2 δ h c0.
    pub coef: f64,
    /// (ρ0/c0²) g: ρ^H_ij = `rho_h` · r_ji (zero without the hydrostatic correction).
    pub rho_h: [f64; 2],
}

impl DensityDiffusion {
    /// δ-SPH with the hydrostatic correction: δ (0.1 is the usual value), smoothing length h, sound speed c0,
    /// rest density ρ0 and gravity g.
    pub fn new(delta: f64, h: f64, c0: f64, rho0: f64, gravity: [f64; 2]) -> Self {
        let k = rho0 / (c0 * c0);
        Self {
            // Molteni & Colagrossi 2009: D_i = 2 δ h c0 Σ_j ψ_ij (r_ji·∇_iW_ij)/|r_ij|² V_j
            coef: 2.0 * delta * h * c0,
            // Fourtakas et al. 2019: ρ^H_ij from p^H_j − p^H_i = ρ0 g·r_ji, linearised Tait law (module notes)
            rho_h: [k * gravity[0], k * gravity[1]],
        }
    }

    /// The plain Molteni & Colagrossi term, without the hydrostatic correction (ρ^H_ij = 0).
    pub fn uncorrected(delta: f64, h: f64, c0: f64) -> Self {
        Self {
            coef: 2.0 * delta * h * c0,
            rho_h: [0.0; 2],
        }
    }

    /// ψ_ij F_ij V_j of one fluid–fluid pair (F_ij: the ∇W factor, ∇_i W_ij = F_ij r_ij); D_i is −`coef` times
    /// the sum of these over j.
    #[inline]
    pub fn pair(&self, xi: [f64; 2], xj: [f64; 2], rho_i: f64, rho_j: f64, f: f64, vol_j: f64) -> f64 {
        // Fourtakas et al. 2019: ρ^H_ij, linearised (module notes)
        let rho_h = self.rho_h[0] * (xj[0] - xi[0]) + self.rho_h[1] * (xj[1] - xi[1]);
        // Fourtakas et al. 2019: ψ_ij = (ρ_j − ρ_i) − ρ^H_ij; (r_ji·∇_iW_ij)/|r_ij|² = −F_ij
        (rho_j - rho_i - rho_h) * f * vol_j
    }

    /// D_i of fluid particle i (a gather over `neighbors`, walls skipped).
    pub fn rate(&self, i: usize, view: &ParticleView<'_>, neighbors: &[u32], kernel: &CubicSpline) -> f64 {
        let (xi, rho_i) = (view.x[i], view.rho[i]);
        let mut sum = 0.0;
        for &j in neighbors {
            let j = j as usize;
            if j >= view.n_fluid {
                continue;
            }
            let (_, r) = separation(xi, view.x[j]);
            let f = kernel.w_and_grad_factor(r).1;
            sum += self.pair(xi, view.x[j], rho_i, view.rho[j], f, view.m[j] / view.rho[j]);
        }
        // Molteni & Colagrossi 2009
        -self.coef * sum
    }
}
