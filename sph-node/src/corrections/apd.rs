//! Artificial particle displacement, APD (`DESIGN.md` §4.4; Xu, Stansby & Laurence 2009, J. Comput. Phys.
//! 228:6703, Eq. (35); Shadloo, Zainali, Yildiz & Suleman 2012, Int. J. Numer. Meth. Eng. 89:939, Eq. (37)):
//!
//! δr_i = β r̄_i² v_max Δt Σ_j r_ij / |r_ij|³,
//!
//! with r̄_i the mean distance to the neighbours of i, v_max the largest fluid speed and Δt the step. The sum runs
//! over every neighbour within the support 2h, wall particles included (so the shift also pushes fluid away from
//! the walls). |δr_i| is capped at [`SHIFT_CAP`]·h.
//!
//! Free surface: a particle with ∇·r_i = −Σ_j (m_j/ρ_j) r_ij·∇_i W_ij < [`FREE_SURFACE_DIV_R`] (2D; about 2 inside
//! the fluid, about 1 on a flat surface; Lee et al. 2008 / Lind et al. 2012 criterion) is taken as a free-surface
//! particle and is not shifted (`DESIGN.md` §4.4: "no shift").
//!
//! Hydrodynamic quantities: no Taylor correction of v or ρ; instead the density is changed as the continuity
//! equation would change it for the displacement δr ([`shift_density_change`]), keeping ρ consistent with the
//! particle number density.
//!
//! Still water (why the scene default of β is 0; numbers in `docs/CORRECTIONS.md`): the WCSPH square lattice
//! pairs up under hydrostatic load with or without APD (cubic spline, h = 1.3Δx, α = 0.01). With the v_max Δt
//! scale the shift is about 100 times weaker in still water (v_max of a few cm/s) than in a dam break and does
//! not stop the pairing; once pairs exist it pushes the partners apart every step while the pressure holds them
//! together, and that exchange feeds the noise (β = 0.04: 8 % r.m.s. particle pressure noise mid-depth, six
//! times the kinetic energy of β = 0, unstable before t = 9 s). A shift strong enough to keep the lattice
//! ordered (a velocity scale of sqrt(g H)) does stop the pairing, but the shift moves particles without
//! changing their velocity, so wherever its fixed point and the pressure balance differ (walls, corners) the
//! particles keep a velocity equal to the shift rate, which grows until the run blows up (≈ 5 s).

use rayon::prelude::*;

use crate::kernel::CubicSpline;
use crate::neighbors::NeighborList;
use crate::particles::{dot, separation, ParticleView};

/// ∇·r below which a particle is a free-surface particle (2D).
pub const FREE_SURFACE_DIV_R: f64 = 1.5;

/// Largest shift, as a fraction of h (`DESIGN.md` §4.4).
pub const SHIFT_CAP: f64 = 0.05;

/// Parameters of one APD pass.
#[derive(Clone, Copy, Debug)]
pub struct ApdParams {
    /// β (Xu et al. 2009 use 0.01–0.1).
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
    if position_divergence(i, view, neighbors, kernel) < FREE_SURFACE_DIV_R {
        // DESIGN.md §4.4: free-surface particles are not shifted
        return [0.0, 0.0];
    }
    let xi = view.x[i];
    let support = kernel.support();
    let (mut s, mut r_sum, mut n) = ([0.0, 0.0], 0.0, 0usize);
    for &j in neighbors {
        let (r_ij, r) = separation(xi, view.x[j as usize]);
        if !(r > 0.0 && r < support) {
            continue;
        }
        // Xu et al. 2009, Eq. (35) / Shadloo et al. 2012, Eq. (37): Σ_j r_ij / |r_ij|³
        let r3 = r * r * r;
        s[0] += r_ij[0] / r3;
        s[1] += r_ij[1] / r3;
        // Xu et al. 2009: r̄_i = (1/N_i) Σ_j |r_ij|
        r_sum += r;
        n += 1;
    }
    if n == 0 {
        return [0.0, 0.0];
    }
    let r_bar = r_sum / n as f64;
    // Xu et al. 2009, Eq. (35): δr_i = C α r̄_i² Σ_j r_ij/|r_ij|³ with α = v_max Δt (C = β)
    let f = p.beta * r_bar * r_bar * p.v_max * p.dt;
    let d = [f * s[0], f * s[1]];
    // DESIGN.md §4.4: |δr| ≤ 0.05 h
    let len = d[0].hypot(d[1]);
    let cap = SHIFT_CAP * kernel.h();
    if len > cap {
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
    let d = shift[i];
    let xi = view.x[i];
    let mut drho = 0.0;
    for &j in neighbors {
        let j = j as usize;
        let dj = if j < view.n_fluid { shift[j] } else { [0.0, 0.0] };
        let (r_ij, r) = separation(xi, view.x[j]);
        // Eq. (9) (continuity) with the displacement δr in place of v Δt
        drho += view.m[j] * dot([d[0] - dj[0], d[1] - dj[1]], kernel.grad(r_ij, r));
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
