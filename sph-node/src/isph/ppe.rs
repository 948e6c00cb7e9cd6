//! The pressure Poisson equation (`DESIGN.md` §4.3, step 2) as sparse rows built from the neighbour lists.
//!
//! Unknowns: the pressures of all particles, fluid first, then walls (the indices of [`ParticleView`]).
//!
//! * Interior fluid particle i (Shao & Lo 2003, Eq. (15); Cummins & Rudman 1999):
//!   Σ_j 8 m_j/(ρ_i+ρ_j)² (p_i − p_j)(r_ij · ∇_i W_ij)/(r_ij² + η²) = source_i, η = 0.1h, j over fluid and
//!   walls. Stored with the sign flipped (c_ij = −8 m_j/(ρ_i+ρ_j)² r_ij·∇_iW_ij/(r_ij²+η²) ≥ 0) so that the
//!   diagonal Σ_j c_ij is positive: c_i p_i − Σ_j c_ij p_j = −source_i.
//! * Free-surface fluid particle (∇·r < threshold): p_i = 0 (Dirichlet).
//! * Wall particle w (Adami et al. 2012, Eq. (27), a_w = 0): p_w − Σ_f (W_wf/Σ_f W_wf) p_f =
//!   g · Σ_f ρ_f r_wf W_wf / Σ_f W_wf; a wall particle with no fluid in reach gets p_w = 0.

use rayon::prelude::*;

use crate::kernel::CubicSpline;
use crate::neighbors::NeighborList;
use crate::particles::{separation, ParticleView};

/// A square sparse matrix in compressed rows; each row's entries are in the fixed order they were assembled
/// (the diagonal first), so products are bit-identical for any thread count.
#[derive(Clone, Debug, Default)]
pub struct SparseRows {
    start: Vec<usize>,
    col: Vec<u32>,
    val: Vec<f64>,
}

impl SparseRows {
    /// Rows from per-row (column, value) lists, in order.
    pub fn from_rows(rows: &[Vec<(u32, f64)>]) -> Self {
        let mut m = Self::default();
        m.start.reserve(rows.len() + 1);
        m.start.push(0);
        for row in rows {
            for &(c, v) in row {
                m.col.push(c);
                m.val.push(v);
            }
            m.start.push(m.col.len());
        }
        m
    }

    /// Number of rows.
    pub fn n(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    /// Stored entries.
    pub fn nnz(&self) -> usize {
        self.val.len()
    }

    /// (columns, values) of row i.
    #[inline]
    pub fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let r = self.start[i]..self.start[i + 1];
        (&self.col[r.clone()], &self.val[r])
    }

    /// The diagonal (0 where a row has no diagonal entry).
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.n())
            .into_par_iter()
            .map(|i| {
                let (c, v) = self.row(i);
                c.iter().zip(v).filter(|(&c, _)| c as usize == i).map(|(_, &v)| v).sum()
            })
            .collect()
    }

    /// y = A x (a gather per row).
    pub fn mul_into(&self, x: &[f64], y: &mut [f64]) {
        y.par_iter_mut().enumerate().for_each(|(i, yi)| {
            let (c, v) = self.row(i);
            *yi = c.iter().zip(v).map(|(&c, &v)| v * x[c as usize]).sum();
        });
    }
}

/// Coefficient c_ij ≥ 0 of pair ij in an interior row (Shao & Lo 2003, Eq. (15), sign flipped).
#[inline]
pub fn laplacian_coefficient(m_j: f64, rho_i: f64, rho_j: f64, r: f64, kernel: &CubicSpline) -> f64 {
    let h = kernel.h();
    let eta2 = 0.01 * h * h;
    let rs = rho_i + rho_j;
    // Shao & Lo 2003 Eq. (15): 8 m_j/(ρ_i+ρ_j)² · (r_ij·∇_iW_ij)/(r_ij²+η²), r_ij·∇_iW_ij = r dW/dr
    -8.0 * m_j / (rs * rs) * r * kernel.dw_dr(r) / (r * r + eta2)
}

/// Row of fluid particle i and its right-hand side, given `source_i` and the free-surface flag.
pub fn fluid_row(
    i: usize,
    view: &ParticleView<'_>,
    neighbors: &[u32],
    kernel: &CubicSpline,
    free_surface: bool,
    source: f64,
) -> (Vec<(u32, f64)>, f64) {
    if free_surface {
        // §4.3 step 3: Dirichlet p = 0 on the free surface
        return (vec![(i as u32, 1.0)], 0.0);
    }
    let (xi, rho_i) = (view.x[i], view.rho[i]);
    let mut row = Vec::with_capacity(neighbors.len() + 1);
    row.push((i as u32, 0.0));
    let mut diag = 0.0;
    for &j in neighbors {
        let (_, r) = separation(xi, view.x[j as usize]);
        let c = laplacian_coefficient(view.m[j as usize], rho_i, view.rho[j as usize], r, kernel);
        diag += c;
        row.push((j, -c));
    }
    row[0].1 = diag;
    (row, -source)
}

/// Row of wall particle w (a `view` index ≥ `n_fluid`) and its right-hand side: Adami et al. 2012, Eq. (27).
pub fn wall_row(
    w: usize,
    view: &ParticleView<'_>,
    neighbors: &[u32],
    kernel: &CubicSpline,
    gravity: [f64; 2],
) -> (Vec<(u32, f64)>, f64) {
    let xw = view.x[w];
    let mut row = vec![(w as u32, 1.0)];
    let (mut sum_w, mut sum_rho_r) = (0.0, [0.0, 0.0]);
    for &f in neighbors {
        let f = f as usize;
        if f >= view.n_fluid {
            continue;
        }
        let (r_wf, r) = separation(xw, view.x[f]);
        let wgt = kernel.w(r);
        sum_w += wgt;
        sum_rho_r[0] += view.rho[f] * r_wf[0] * wgt;
        sum_rho_r[1] += view.rho[f] * r_wf[1] * wgt;
        row.push((f as u32, wgt));
    }
    if sum_w <= 0.0 {
        return (vec![(w as u32, 1.0)], 0.0);
    }
    for e in &mut row[1..] {
        // Adami et al. 2012, Eq. (27): p_w = Σ_f p_f W_wf / Σ_f W_wf + …
        e.1 = -e.1 / sum_w;
    }
    // Adami et al. 2012, Eq. (27), a_w = 0: … + g · Σ_f ρ_f r_wf W_wf / Σ_f W_wf
    let rhs = (gravity[0] * sum_rho_r[0] + gravity[1] * sum_rho_r[1]) / sum_w;
    (row, rhs)
}

/// Assembles the whole system: `sources` (one per fluid particle) and `free` (free-surface flags) in, the
/// matrix and right-hand side out.
pub fn assemble(
    view: &ParticleView<'_>,
    list: &NeighborList,
    kernel: &CubicSpline,
    gravity: [f64; 2],
    free: &[bool],
    sources: &[f64],
) -> (SparseRows, Vec<f64>) {
    let rows: Vec<(Vec<(u32, f64)>, f64)> = (0..view.x.len())
        .into_par_iter()
        .map(|i| {
            if i < view.n_fluid {
                fluid_row(i, view, list.of(i), kernel, free[i], sources[i])
            } else {
                wall_row(i, view, list.of(i), kernel, gravity)
            }
        })
        .collect();
    let b = rows.iter().map(|r| r.1).collect();
    let rows: Vec<Vec<(u32, f64)>> = rows.into_iter().map(|r| r.0).collect();
    (SparseRows::from_rows(&rows), b)
}
