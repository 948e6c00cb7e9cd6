//! Wall pressure by extrapolation from the fluid, Adami, Hu & Adams 2012 (J. Comput. Phys. 231:7057), Eq. (27):
//! p_w = [Σ_f p_f W_wf + (g − a_w) · Σ_f ρ_f r_wf W_wf] / Σ_f W_wf, r_wf = x_w − x_f; the wall density follows
//! from the inverse EOS. Walls are fixed, so a_w = 0.

use rayon::prelude::*;

use crate::eos::Tait;
use crate::kernel::CubicSpline;
use crate::neighbors::{NeighborList, SortedCells};
use crate::particles::{separation, ParticleView};

/// Eq. (27) at the wall position `xw` over the fluid particles `fluid` (indices into `view`, each within the
/// kernel support, in gather order). No fluid gives p = 0; negative pressures are clipped to 0 so walls never
/// pull the fluid.
#[inline]
fn extrapolate(
    xw: [f64; 2],
    fluid: impl Iterator<Item = usize>,
    view: &ParticleView<'_>,
    kernel: &CubicSpline,
    gravity: [f64; 2],
    eos: &Tait,
) -> (f64, f64) {
    let (mut sum_pw, mut sum_rho_r, mut sum_w) = (0.0, [0.0, 0.0], 0.0);
    for f in fluid {
        let (r_wf, r) = separation(xw, view.x[f]);
        let wgt = kernel.w(r);
        // Adami et al. 2012, Eq. (27)
        sum_pw += view.p[f] * wgt;
        sum_rho_r[0] += view.rho[f] * r_wf[0] * wgt;
        sum_rho_r[1] += view.rho[f] * r_wf[1] * wgt;
        sum_w += wgt;
    }
    if sum_w <= 0.0 {
        return (0.0, eos.rho0);
    }
    // Adami et al. 2012, Eq. (27), a_w = 0
    let p = ((sum_pw + gravity[0] * sum_rho_r[0] + gravity[1] * sum_rho_r[1]) / sum_w).max(0.0);
    (p, eos.density(p))
}

/// (p_w, ρ_w) of wall particle `w` (an index into `view`, ≥ `n_fluid`). A wall particle with no fluid in reach
/// gets p = 0; negative pressures are clipped to 0 so walls never pull the fluid.
#[inline]
pub fn wall_pressure(
    w: usize,
    view: &ParticleView<'_>,
    neighbors: &[u32],
    kernel: &CubicSpline,
    gravity: [f64; 2],
    eos: &Tait,
) -> (f64, f64) {
    let fluid = neighbors.iter().map(|&f| f as usize).filter(|&f| f < view.n_fluid);
    extrapolate(view.x[w], fluid, view, kernel, gravity, eos)
}

/// Pressure and density of every wall particle (`view` indices `n_fluid..`) into `p` and `rho`.
pub fn wall_pressures_into(
    view: &ParticleView<'_>,
    list: &NeighborList,
    kernel: &CubicSpline,
    gravity: [f64; 2],
    eos: &Tait,
    out: &mut Vec<(f64, f64)>,
) {
    out.clear();
    (view.n_fluid..view.x.len())
        .into_par_iter()
        .map(|w| wall_pressure(w, view, list.of(w), kernel, gravity, eos))
        .collect_into_vec(out);
}

/// As [`wall_pressures_into`] (same sums in the same order), gathering the fluid straight from the cell-sorted
/// fluid of `cells` (`view` holds the fluid in that order, then the walls): no neighbour lists for the walls, and
/// a wall with no fluid in its block of cells costs only the look-up.
pub fn wall_pressures_sorted_into(
    view: &ParticleView<'_>,
    cells: &SortedCells,
    kernel: &CubicSpline,
    gravity: [f64; 2],
    eos: &Tait,
    out: &mut Vec<(f64, f64)>,
) {
    let nf = view.n_fluid;
    let radius = kernel.support();
    let r2max = radius * radius;
    out.clear();
    (nf..view.x.len())
        .into_par_iter()
        .with_min_len(256)
        .map(|w| {
            let rows = cells.fluid_near_wall(w - nf);
            if rows.iter().all(|r| r.is_empty()) {
                return (0.0, eos.rho0);
            }
            let xw = view.x[w];
            let near = rows.into_iter().flatten().filter(|&f| {
                let p = view.x[f];
                let dx = xw[0] - p[0];
                let dy = xw[1] - p[1];
                dx * dx + dy * dy < r2max
            });
            extrapolate(xw, near, view, kernel, gravity, eos)
        })
        .collect_into_vec(out);
}
