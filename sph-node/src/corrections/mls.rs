//! First-order moving-least-squares density filter (`DESIGN.md` §4.4; Colagrossi & Landrini 2003,
//! J. Comput. Phys. 191:448, Eqs. (20)–(22); Dilts 1999, Int. J. Numer. Meth. Eng. 44:1115):
//!
//! ρ_i = Σ_j m_j W^MLS_ij,  W^MLS_ij = [β0 + β1 (x_i − x_j) + β2 (y_i − y_j)] W_ij,  β = A⁻¹ (1, 0, 0)ᵀ,
//! A = Σ_j W_ij Ã_ij (m_j/ρ_j),  Ã_ij = (1, x_ij, y_ij)ᵀ (1, x_ij, y_ij),
//!
//! over the fluid particles (self included), as the Shepard filter. Where A is singular (relative determinant
//! below [`SINGULAR_TOLERANCE`]: isolated particles, lines of particles) the Shepard value is used.

use rayon::prelude::*;

use super::density_filter::shepard_density;
use crate::kernel::CubicSpline;
use crate::neighbors::NeighborList;
use crate::particles::{separation, ParticleView};

/// |det A| / (A00 A11 A22) below which A counts as singular.
pub const SINGULAR_TOLERANCE: f64 = 1e-6;

/// MLS-filtered density of fluid particle i.
#[inline]
pub fn mls_density(i: usize, view: &ParticleView<'_>, neighbors: &[u32], kernel: &CubicSpline) -> f64 {
    let xi = view.x[i];
    let w0 = kernel.w(0.0);
    // Colagrossi & Landrini 2003, Eq. (21): A = Σ_j W_ij Ã_ij V_j (self term: r_ii = 0)
    let mut a = [[0.0; 3]; 3];
    a[0][0] = w0 * view.m[i] / view.rho[i];
    for &j in neighbors {
        let j = j as usize;
        if j >= view.n_fluid {
            continue;
        }
        let (r, d) = separation(xi, view.x[j]);
        let wv = kernel.w(d) * view.m[j] / view.rho[j];
        let e = [1.0, r[0], r[1]];
        for (row, &er) in a.iter_mut().zip(&e) {
            for (acc, &ec) in row.iter_mut().zip(&e) {
                *acc += wv * er * ec;
            }
        }
    }
    // β = A⁻¹ e1: first column of the inverse of the symmetric A, by cofactors.
    let c0 = a[1][1] * a[2][2] - a[1][2] * a[2][1];
    let c1 = a[1][2] * a[2][0] - a[1][0] * a[2][2];
    let c2 = a[1][0] * a[2][1] - a[1][1] * a[2][0];
    let det = a[0][0] * c0 + a[0][1] * c1 + a[0][2] * c2;
    let scale = (a[0][0] * a[1][1] * a[2][2]).abs();
    if !(det.abs() > SINGULAR_TOLERANCE * scale && det.is_finite()) {
        // Singular A: fall back to the Shepard filter (zeroth order).
        return shepard_density(i, view, neighbors, kernel);
    }
    let beta = [c0 / det, c1 / det, c2 / det];
    // Colagrossi & Landrini 2003, Eqs. (20), (22): ρ_i = Σ_j m_j [β0 + β1 x_ij + β2 y_ij] W_ij
    let mut rho = view.m[i] * beta[0] * w0;
    for &j in neighbors {
        let j = j as usize;
        if j >= view.n_fluid {
            continue;
        }
        let (r, d) = separation(xi, view.x[j]);
        rho += view.m[j] * (beta[0] + beta[1] * r[0] + beta[2] * r[1]) * kernel.w(d);
    }
    rho
}

/// MLS-filtered densities of every fluid particle into `out`.
pub fn mls_into(view: &ParticleView<'_>, list: &NeighborList, kernel: &CubicSpline, out: &mut Vec<f64>) {
    out.clear();
    (0..view.n_fluid)
        .into_par_iter()
        .map(|i| mls_density(i, view, list.of(i), kernel))
        .collect_into_vec(out);
}
