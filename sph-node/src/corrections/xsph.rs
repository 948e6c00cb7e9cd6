//! XSPH (Monaghan 1989; `DESIGN.md` §4.4): dx_i/dt = v_i − ε Σ_j (m_j/ρ̄_ij) v_ij W_ij over fluid neighbours.

use rayon::prelude::*;

use crate::kernel::CubicSpline;
use crate::neighbors::NeighborList;
use crate::particles::{separation, ParticleView};

/// The XSPH velocity correction −ε Σ_j (m_j/ρ̄_ij) v_ij W_ij of fluid particle i.
#[inline]
pub fn xsph_correction(
    i: usize,
    view: &ParticleView<'_>,
    neighbors: &[u32],
    kernel: &CubicSpline,
    eps: f64,
) -> [f64; 2] {
    let xi = view.x[i];
    let mut s = [0.0, 0.0];
    for &j in neighbors {
        let j = j as usize;
        if j >= view.n_fluid {
            continue;
        }
        let (_, r) = separation(xi, view.x[j]);
        add_term(&mut s, view, i, j, kernel.w(r));
    }
    finish(s, eps)
}

/// s += (m_j/ρ̄_ij) v_ij W_ij, the term of fluid neighbour j (`w` = W_ij) in the XSPH sum of particle i.
#[inline(always)]
pub fn add_term(s: &mut [f64; 2], view: &ParticleView<'_>, i: usize, j: usize, w: f64) {
    let (vi, rho_i) = (view.v[i], view.rho[i]);
    // §4.4 XSPH
    let f = view.m[j] / (0.5 * (rho_i + view.rho[j])) * w;
    s[0] += f * (vi[0] - view.v[j][0]);
    s[1] += f * (vi[1] - view.v[j][1]);
}

/// The correction −ε s from the sum s of [`add_term`].
#[inline(always)]
pub fn finish(s: [f64; 2], eps: f64) -> [f64; 2] {
    [-eps * s[0], -eps * s[1]]
}

/// XSPH corrections of every fluid particle into `out`.
pub fn xsph_into(
    view: &ParticleView<'_>,
    list: &NeighborList,
    kernel: &CubicSpline,
    eps: f64,
    out: &mut Vec<[f64; 2]>,
) {
    out.clear();
    (0..view.n_fluid)
        .into_par_iter()
        .map(|i| xsph_correction(i, view, list.of(i), kernel, eps))
        .collect_into_vec(out);
}
