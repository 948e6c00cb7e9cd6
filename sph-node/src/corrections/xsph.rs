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
    let (xi, vi, rho_i) = (view.x[i], view.v[i], view.rho[i]);
    let mut s = [0.0, 0.0];
    for &j in neighbors {
        let j = j as usize;
        if j >= view.n_fluid {
            continue;
        }
        let (_, r) = separation(xi, view.x[j]);
        // §4.4 XSPH
        let f = view.m[j] / (0.5 * (rho_i + view.rho[j])) * kernel.w(r);
        s[0] += f * (vi[0] - view.v[j][0]);
        s[1] += f * (vi[1] - view.v[j][1]);
    }
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
