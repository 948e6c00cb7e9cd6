//! The wall condition of the projection on the walls' normal: u^{n+1} · n = 0 (walls at rest).
//!
//! The corrector u^{n+1} = u* − Δt ∇p/ρ stops the motion into a wall when ∂p/∂n = ρ u* · n / Δt there (Cummins &
//! Rudman 1999, the Neumann condition of the projection; `DESIGN.md` §4.3). With u* = uⁿ + Δt (g + ν∇²uⁿ) this is
//! the Adami et al. 2012 extrapolation, Eq. (27), whose g · r_wf term is the gravity part, plus the part of the
//! fluid's own motion, ρ (ũ_f · n)(r_wf · n)/Δt with ũ_f = u*_f − Δt g. Both sit in the wall rows of the PPE, so both
//! act on every fluid particle next to a wall, also on one whose own row is Dirichlet (a free-surface particle at a
//! wall) or whose pressure is clipped to 0.
//!
//! The flux through the wall is then imposed once, by the wall rows: in ∇·u* a wall particle carries Δt g plus the
//! normal part of the fluid's motion next to it, (ũ_w · n) n with ũ_w = Σ_f ũ_f W_wf / Σ_f W_wf (the Shepard
//! average, as Adami et al. 2012, Eq. (22), extrapolate the wall velocity), so that the divergence sees only the
//! motion along the wall, not the normal motion the wall rows stop.
//!
//! Without the normal part (the walls' Neumann rows carrying g only, the normal motion left to the divergence of the
//! fluid rows), nothing stops a free-surface particle that moves into a wall: in the still-water tank the particles
//! where the surface meets a side wall cross the face within 0.3 s.
//!
//! The normal n of a wall particle is the direction to the nearest point outside every wall box
//! ([`crate::boundary::wall_guard::WallBoxes::exit_direction`]): the face normal, or the diagonal in a corner where two boxes
//! meet. Its sign does not matter: both terms are products of two projections on n.

use rayon::prelude::*;

use crate::boundary::wall_guard::WallBoxes;
use crate::kernel::CubicSpline;
use crate::neighbors::NeighborList;
use crate::particles::{separation, ParticleView};

/// The unit normal of each wall particle (zero for one outside the boxes, which gets no normal term).
pub fn wall_normals(walls_x: &[[f64; 2]], boxes: &WallBoxes) -> Vec<[f64; 2]> {
    walls_x
        .iter()
        .map(|&x| boxes.exit_direction(x).unwrap_or([0.0; 2]))
        .collect()
}

#[inline]
fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// The velocity the walls carry in ∇·u*: Δt g + (ũ_w · n) n, with ũ_w the Shepard average of u*_f − Δt g over the
/// fluid neighbours of wall particle w (Δt g alone for a wall particle with no fluid in reach). `view.v` holds u* of
/// the fluid; the result goes to `out` (one per wall particle, in the order of `normals`).
pub fn divergence_velocities_into(
    view: &ParticleView<'_>,
    list: &NeighborList,
    kernel: &CubicSpline,
    normals: &[[f64; 2]],
    dt: f64,
    g: [f64; 2],
    out: &mut Vec<[f64; 2]>,
) {
    let nf = view.n_fluid;
    let dtg = [dt * g[0], dt * g[1]];
    out.clear();
    (0..normals.len())
        .into_par_iter()
        .map(|k| {
            let w = nf + k;
            let n = normals[k];
            let (mut s, mut sum_w) = (0.0, 0.0);
            for &f in list.of(w) {
                let f = f as usize;
                if f >= nf {
                    continue;
                }
                let (_, r) = separation(view.x[w], view.x[f]);
                let wgt = kernel.w(r);
                let u = [view.v[f][0] - dtg[0], view.v[f][1] - dtg[1]];
                s += dot(u, n) * wgt;
                sum_w += wgt;
            }
            // Adami et al. 2012, Eq. (22): ũ_w = Σ_f u_f W_wf / Σ_f W_wf, its normal part only
            let un = if sum_w > 0.0 { s / sum_w } else { 0.0 };
            [dtg[0] + un * n[0], dtg[1] + un * n[1]]
        })
        .collect_into_vec(out);
}

/// The term ρ_f (ũ_f · n)(r_wf · n)/Δt of one fluid neighbour f in the wall row of w (before the division by
/// Σ_f W_wf), ũ_f = u*_f − Δt g, r_wf = x_w − x_f: the projection's wall condition on the normal (module docs).
#[inline]
pub fn normal_motion_term(
    rho_f: f64,
    u_star_f: [f64; 2],
    r_wf: [f64; 2],
    normal: [f64; 2],
    dt: f64,
    g: [f64; 2],
) -> f64 {
    let u = [u_star_f[0] - dt * g[0], u_star_f[1] - dt * g[1]];
    // ∂p/∂n = ρ u*·n/Δt (Cummins & Rudman 1999), less the ρ g·n of Adami et al. 2012, Eq. (27)
    rho_f * dot(u, normal) * dot(r_wf, normal) / dt
}
