//! Wall pressure by extrapolation from the fluid, Adami, Hu & Adams 2012 (J. Comput. Phys. 231:7057), Eq. (27):
//! p_w = [Σ_f p_f W_wf + (g − a_w) · Σ_f ρ_f r_wf W_wf] / Σ_f W_wf, r_wf = x_w − x_f; the wall density follows
//! from the inverse EOS. Walls are fixed, so a_w = 0.

use rayon::prelude::*;

use crate::eos::Tait;
use crate::kernel::CubicSpline;
use crate::neighbors::NeighborList;
use crate::particles::{separation, ParticleView};

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
    let xw = view.x[w];
    let (mut sum_pw, mut sum_rho_r, mut sum_w) = (0.0, [0.0, 0.0], 0.0);
    for &f in neighbors {
        let f = f as usize;
        if f >= view.n_fluid {
            continue;
        }
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
