//! Artificial particle displacement, APD (`DESIGN.md` §4.4), in the kernel-gradient ("Fickian") form of the
//! δ+-SPH particle shifting (Sun, Colagrossi, Marrone & Zhang 2017, Comput. Methods Appl. Mech. Eng. 315:25,
//! Eq. (7); the Fickian shift of Lind, Xu, Stansby & Rogers 2012, J. Comput. Phys. 231:1499):
//!
//! δr_i = −K β h v_max Δt Σ_j [1 + R (W_ij / W(Δx_i))⁴] V_j ∇_i W_ij,   K = [`K_SUN`], R = [`R_PAIRING`],
//!
//! with V_j = m_j/ρ_j, v_max the largest fluid speed, Δt the step and Δx_i = sqrt(V_i) the local spacing. The sum
//! runs over every neighbour within 2h, wall particles included (they hold the fluid off the walls as the
//! ghost particles of Sun et al. do). β keeps the meaning of Xu, Stansby & Laurence 2009 (J. Comput. Phys.
//! 228:6703, Eq. (35), δr_i = β r̄_i² v_max Δt Σ_j r_ij/|r_ij|³, the form this module had before): the shift per
//! step is β times a velocity-times-step scale, and β = 0.04 gives K β = 2, half of Sun et al.'s CFL·Ma·(2h)²/h
//! = 4 v_max Δt. The kernel-gradient form goes to zero smoothly at 2h and stays finite for close pairs (Xu's sum
//! grows as 1/|r_ij|² and stops abruptly at 2h); the anti-pairing term R (W_ij/W(Δx))⁴ (Sun et al., after
//! Monaghan 2000) pushes close pairs apart. |δr_i| is capped at [`SHIFT_CAP`]·h.
//!
//! Free surface (`DESIGN.md` §4.4; the free-surface treatment of the shift in Sun et al. 2017 and Lind et al.
//! 2012): a particle with ∇·r_i = −Σ_j V_j r_ij·∇_i W_ij < [`FREE_SURFACE_DIV_R`] (2D; about 2 inside the fluid,
//! about 1 on a flat surface) is a free-surface particle and is not shifted; a particle with ∇·r_i <
//! [`NEAR_SURFACE_DIV_R`] keeps only the part of its shift tangential to the surface, whose normal is
//! −Σ_{j fluid} V_j ∇_i W_ij normalised (fluid neighbours only, so that a dry wall above the water does not tilt
//! it).
//!
//! Hydrodynamic quantities: no Taylor correction of v or ρ; the density is changed as the continuity equation
//! would change it for the displacement δr ([`shift_density_change`]), keeping ρ consistent with the particle
//! number density (the Taylor form δr·∇ρ and the ALE form of Sun et al. 2019 were tried; see
//! `docs/CORRECTIONS.md`).
//!
//! Still water (why R is 0.02 and not Sun et al.'s 0.2; numbers in `docs/CORRECTIONS.md`): the WCSPH square lattice
//! pairs up under hydrostatic load with or without APD (cubic spline, h = 1.3Δx, α = 0.01), and the paired
//! lattice is the stable equilibrium of the SPH forces. A shift that pushes the pairs apart works against those
//! forces every step (with the continuity-form ρ update the shift changes the potential energy by
//! −Σ m_i a_i·δr_i), and the energy it puts in grows: with R = 0.2 and β = 0.04 the still tank ends 10 s outside
//! its bounds; R = 0.05–0.1 passes 10 s but not the 2 s tank (+3.8–3.9 % at mid-depth); R = 0.02 passes both
//! (+1.9 % at 2 s, −1.0 / −0.4 / −0.8 % over 10 s) and still halves the dam break's disorder (× 0.43). With the
//! WCSPH wall repulsion (`boundary::repulsion`) this makes β = 0.04 the WCSPH default, as the paper has it. (Those
//! numbers are from the shift applied after the drift; applied with it, at xⁿ, as now: +1.9 % at 2 s,
//! −0.8 / −0.8 / −1.6 % over 10 s, disorder × 0.41.)

use rayon::prelude::*;

use crate::kernel::CubicSpline;
use crate::neighbors::NeighborList;
use crate::particles::{dot, separation, ParticleView};

/// ∇·r below which a particle is a free-surface particle (2D).
pub const FREE_SURFACE_DIV_R: f64 = 1.5;

/// ∇·r below which a particle is near the free surface and keeps only the tangential part of its shift (2D).
pub const NEAR_SURFACE_DIV_R: f64 = 1.8;

/// K of the shift: β = 0.04 gives K β = 2 (see the module documentation).
pub const K_SUN: f64 = 50.0;

/// R of the anti-pairing term (Sun et al. 2017, below Eq. (9), exponent n = 4; their R = 0.2 pumps energy into
/// still water, see the module notes: 0.02 here).
pub const R_PAIRING: f64 = 0.02;

/// Largest shift, as a fraction of h (`DESIGN.md` §4.4).
pub const SHIFT_CAP: f64 = 0.05;

/// Parameters of one APD pass.
#[derive(Clone, Copy, Debug)]
pub struct ApdParams {
    /// β (Xu et al. 2009 use 0.01–0.1; 0.04 is the paper's).
    pub beta: f64,
    /// Largest fluid speed v_max.
    pub v_max: f64,
    /// Time step Δt.
    pub dt: f64,
}

/// ∇·r_i = −Σ_j (m_j/ρ_j) r_ij·∇_i W_ij over all neighbours (fluid and wall).
#[inline]
pub fn position_divergence(i: usize, view: &ParticleView<'_>, neighbors: &[u32], kernel: &CubicSpline) -> f64 {
    let xi = view.x[i];
    let mut div = 0.0;
    for &j in neighbors {
        let j = j as usize;
        let (r_ij, r) = separation(xi, view.x[j]);
        // Lind et al. 2012, Eq. (15): ∇·r = Σ_j V_j (r_j − r_i)·∇_i W_ij
        div -= view.m[j] / view.rho[j] * dot(r_ij, kernel.grad(r_ij, r));
    }
    div
}

/// The APD shift δr_i of fluid particle i (zero for a free-surface particle).
#[inline]
pub fn apd_shift(
    i: usize,
    view: &ParticleView<'_>,
    neighbors: &[u32],
    kernel: &CubicSpline,
    p: &ApdParams,
) -> [f64; 2] {
    let vol = |j: usize| view.m[j] / view.rho[j];
    apd_shift_with(
        i,
        view,
        neighbors,
        kernel,
        p,
        vol,
        |_, r_ij, r| kernel.grad(r_ij, r),
        |_, _, _, _| (),
    )
}

/// The shift of [`apd_shift`], with V_j from `vol_of(j)` and ∇_i W_ij of the k-th neighbour from
/// `grad_of(k, r_ij, r)`; `pair(k, j, W_ij, ∇_i W_ij)` is called for every neighbour j = `neighbors[k]`, in order
/// (a pass that shares the loop: `crate::wcsph::drift_pass`).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn apd_shift_with(
    i: usize,
    view: &ParticleView<'_>,
    neighbors: &[u32],
    kernel: &CubicSpline,
    p: &ApdParams,
    vol_of: impl Fn(usize) -> f64,
    grad_of: impl Fn(usize, [f64; 2], f64) -> [f64; 2],
    mut pair: impl FnMut(usize, usize, f64, [f64; 2]),
) -> [f64; 2] {
    let xi = view.x[i];
    // Sun et al. 2017, Eq. (7): W(Δx), here at the local spacing Δx_i = sqrt(m_i/ρ_i)
    // 1/W(Δx_i), once a particle: a multiplication a pair where W_ij/W(Δx_i) was a division (issue 20)
    let inv_w_dx = 1.0 / kernel.w((view.m[i] / view.rho[i]).sqrt());
    let (mut div_r, mut s) = (0.0, [0.0, 0.0]);
    for (k, &j) in neighbors.iter().enumerate() {
        let j = j as usize;
        let (r_ij, r) = separation(xi, view.x[j]);
        let g = grad_of(k, r_ij, r);
        let w = kernel.w(r);
        pair(k, j, w, g);
        let v_j = vol_of(j);
        // Lind et al. 2012, Eq. (15): ∇·r = Σ_j V_j (r_j − r_i)·∇_i W_ij (as `position_divergence`)
        div_r -= v_j * dot(r_ij, g);
        if r <= 0.0 {
            continue;
        }
        // Sun et al. 2017, Eq. (7): [1 + R (W_ij/W(Δx))^n] V_j ∇_i W_ij, n = 4 (R: `R_PAIRING`)
        let q = w * inv_w_dx;
        let f = v_j * (1.0 + R_PAIRING * q * q * q * q);
        s[0] += f * g[0];
        s[1] += f * g[1];
    }
    if div_r < FREE_SURFACE_DIV_R {
        // DESIGN.md §4.4: free-surface particles are not shifted
        return [0.0, 0.0];
    }
    // Sun et al. 2017, Eq. (7): δr = −CFL·Ma·(2h)² Σ…, CFL·Ma = v_max Δt/h; here −K β h v_max Δt Σ…
    let f = -K_SUN * p.beta * kernel.h() * p.v_max * p.dt;
    let mut d = [f * s[0], f * s[1]];
    if div_r < NEAR_SURFACE_DIV_R {
        // Sun et al. 2017 / Lind et al. 2012 (free-surface treatment): near the surface only the part tangential
        // to it, normal n = −∇C/|∇C| from the fluid neighbours
        // Σ_j∈fluid V_j ∇_i W_ij, in a loop of its own for the few particles near the surface: in the loop above
        // its accumulators and branch made the shift's spill to the stack (issue 20; the same sums in the same
        // order, so the same bits)
        let mut fluid = [0.0, 0.0];
        for (k, &j) in neighbors.iter().enumerate() {
            let j = j as usize;
            let (r_ij, r) = separation(xi, view.x[j]);
            if r > 0.0 && j < view.n_fluid {
                let (g, v_j) = (grad_of(k, r_ij, r), vol_of(j));
                fluid[0] += v_j * g[0];
                fluid[1] += v_j * g[1];
            }
        }
        let len = fluid[0].hypot(fluid[1]);
        if len > 0.0 {
            let n = [-fluid[0] / len, -fluid[1] / len];
            let dn = dot(d, n);
            d = [d[0] - dn * n[0], d[1] - dn * n[1]];
        }
    }
    // DESIGN.md §4.4: |δr| ≤ 0.05 h (compared squared: no square root for a shift within the cap)
    let cap = SHIFT_CAP * kernel.h();
    if dot(d, d) > cap * cap {
        let len = d[0].hypot(d[1]);
        [d[0] * cap / len, d[1] * cap / len]
    } else {
        d
    }
}

/// APD shifts of every fluid particle into `out`.
pub fn apd_into(
    view: &ParticleView<'_>,
    list: &NeighborList,
    kernel: &CubicSpline,
    params: &ApdParams,
    out: &mut Vec<[f64; 2]>,
) {
    out.clear();
    (0..view.n_fluid)
        .into_par_iter()
        .map(|i| apd_shift(i, view, list.of(i), kernel, params))
        .collect_into_vec(out);
}

/// Density change of fluid particle i for the shifts `shift` (all fluid particles; walls do not move), at the
/// unshifted positions: the continuity equation, Eq. (9), with the shift as the displacement,
/// δρ_i = Σ_j m_j (δr_i − δr_j)·∇_i W_ij, so that ρ follows the particle number density as it does for the drift
/// (a first-order Taylor step δρ_i = δr_i·∇ρ_i, Xu et al. 2009 §3.4, was tried and did not stop the still-tank
/// drift described in the solver).
pub fn shift_density_change(
    i: usize,
    view: &ParticleView<'_>,
    neighbors: &[u32],
    kernel: &CubicSpline,
    shift: &[[f64; 2]],
) -> f64 {
    let xi = view.x[i];
    shift_density_change_with(i, view, neighbors, shift, |_, xj| {
        let (r_ij, r) = separation(xi, xj);
        kernel.grad(r_ij, r)
    })
}

/// [`shift_density_change`] with the ∇W factors of the pairs precomputed (`grad[k]`: ∇W factor of pair (i, `neighbors[k]`), see [`crate::neighbors::ListChunk::grad`]):
/// the same sum, bit for bit, without a square root or dW/dr per pair.
#[inline]
pub fn shift_density_change_pairs(
    i: usize,
    view: &ParticleView<'_>,
    neighbors: &[u32],
    grad: &[f64],
    shift: &[[f64; 2]],
) -> f64 {
    let xi = view.x[i];
    shift_density_change_with(i, view, neighbors, shift, |k, xj| {
        [grad[k] * (xi[0] - xj[0]), grad[k] * (xi[1] - xj[1])]
    })
}

/// The sum of [`shift_density_change`], with ∇_i W_ij of the k-th neighbour from `grad_of(k, x_j)`.
#[inline(always)]
fn shift_density_change_with(
    i: usize,
    view: &ParticleView<'_>,
    neighbors: &[u32],
    shift: &[[f64; 2]],
    grad_of: impl Fn(usize, [f64; 2]) -> [f64; 2],
) -> f64 {
    let d = shift[i];
    let mut drho = 0.0;
    for (k, &j) in neighbors.iter().enumerate() {
        let j = j as usize;
        let dj = if j < view.n_fluid { shift[j] } else { [0.0, 0.0] };
        // Eq. (9) (continuity) with the displacement δr in place of v Δt
        drho += view.m[j] * dot([d[0] - dj[0], d[1] - dj[1]], grad_of(k, view.x[j]));
    }
    drho
}

/// [`shift_density_change`] of every fluid particle into `out`.
pub fn shift_density_change_into(
    view: &ParticleView<'_>,
    list: &NeighborList,
    kernel: &CubicSpline,
    shift: &[[f64; 2]],
    out: &mut Vec<f64>,
) {
    out.clear();
    (0..view.n_fluid)
        .into_par_iter()
        .map(|i| shift_density_change(i, view, list.of(i), kernel, shift))
        .collect_into_vec(out);
}

/// [`shift_density_change_into`] from lists with ∇W factors (as built by [`crate::neighbors::SortedCells::build_fluid_lists`]): the same changes, bit for bit.
pub fn shift_density_change_pairs_into(
    view: &ParticleView<'_>,
    list: &NeighborList,
    shift: &[[f64; 2]],
    out: &mut Vec<f64>,
) {
    list.map_pairs_into(out, |i, idx, grad| {
        shift_density_change_pairs(i, view, idx, grad, shift)
    });
}
