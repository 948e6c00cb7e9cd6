//! The wall condition of the projection on the walls' normal: u^{n+1} · n = 0 (walls at rest).
//!
//! The corrector u^{n+1} = u* − Δt ∇p/ρ stops the motion into a wall when ∂p/∂n = ρ u* · n / Δt there (Cummins &
//! Rudman 1999, the Neumann condition of the projection; `DESIGN.md` §4.3). With u* = uⁿ + Δt (g + ν∇²uⁿ) this is
//! the Adami et al. 2012 extrapolation, Eq. (27), whose g · r_wf term is the gravity part, plus the part of the
//! fluid's own motion, ρ (ũ_f · n)(r_wf · n)/Δt with ũ_f = u*_f − Δt g, taken from the fluid in contact with the wall
//! only ([`normal_motion_term`]). Both sit in the wall rows of the PPE, so both act on every fluid particle next to
//! a wall, also on one whose own row is Dirichlet (a free-surface particle at a wall) or whose pressure is clipped
//! to 0.
//!
//! The flux through the wall is then imposed once, by the wall rows: in ∇·u* a wall particle carries Δt g plus the
//! normal part of the fluid's motion next to it, (ũ_w · n) n with ũ_w = Σ_f s_wf ũ_f W_wf / Σ_f W_wf (the Shepard
//! average, as Adami et al. 2012, Eq. (22), extrapolate the wall velocity), so that the divergence sees only the
//! motion along the wall, not the normal motion the wall rows stop. Both take the same contact weight s_wf
//! ([`contact_weight`]): with the rows weighted and the divergence not (2026-11-25), the normal motion of fluid
//! near a wall but not touching it was neither stopped by the wall rows nor seen by the fluid rows' divergence;
//! weighting both (2026-11-27) took the Lobovsky ISPH sensor peaks from 12.3 / 12.5 to 5.0 / 10.3 ρgH, the coupled
//! ISPH gate's energy gain from +0.103 to +0.062 of its budget, and ISPH at 8 × its step from running on with 2.0 of
//! its budget to a stop by the energy guard (docs/CORRECTIONS.md, "ISPH pressure").
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

/// The velocity the walls carry in ∇·u*: Δt g + (ũ_w · n) n, with ũ_w the Shepard average of s_wf (u*_f − Δt g)
/// over the fluid neighbours of wall particle w (Δt g alone for a wall particle with no fluid in reach); s_wf is the
/// contact weight of [`contact_weight`], the same as the wall rows' ([`normal_motion_term`]): the normal motion the
/// wall rows stop is the motion the divergence does not see, no more and no less. `view.v` holds u* of the fluid;
/// `touch` is per wall particle as in [`normal_motion_term`]; the result goes to `out` (one per wall particle, in
/// the order of `normals`).
#[allow(clippy::too_many_arguments)]
pub fn divergence_velocities_into(
    view: &ParticleView<'_>,
    list: &NeighborList,
    kernel: &CubicSpline,
    normals: &[[f64; 2]],
    touch: &[f64],
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
            let touch = touch.get(k).copied().unwrap_or(0.0);
            let (mut s, mut sum_w) = (0.0, 0.0);
            for &f in list.of(w) {
                let f = f as usize;
                if f >= nf {
                    continue;
                }
                let (r_wf, r) = separation(view.x[w], view.x[f]);
                let wgt = kernel.w(r);
                let u = [view.v[f][0] - dtg[0], view.v[f][1] - dtg[1]];
                s += contact_weight(r_wf, n, touch) * dot(u, n) * wgt;
                sum_w += wgt;
            }
            // Adami et al. 2012, Eq. (22): ũ_w = Σ_f u_f W_wf / Σ_f W_wf, its normal part only
            let un = if sum_w > 0.0 { s / sum_w } else { 0.0 };
            [dtg[0] + un * n[0], dtg[1] + un * n[1]]
        })
        .collect_into_vec(out);
}

/// The contact weight s_wf = clamp(2 − (−r_wf · n)/touch, 0, 1) of fluid neighbour f of wall particle w (see
/// [`normal_motion_term`]); 0 where `touch` is not positive (a wall particle outside the boxes).
#[inline]
pub fn contact_weight(r_wf: [f64; 2], normal: [f64; 2], touch: f64) -> f64 {
    if touch > 0.0 {
        (2.0 + dot(r_wf, normal) / touch).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// The term ρ_f s_wf (ũ_f · n)(r_wf · n)/Δt of one fluid neighbour f in the wall row of w (before the division by
/// Σ_f W_wf), ũ_f = u*_f − Δt g, r_wf = x_w − x_f: the projection's wall condition on the normal (module docs).
///
/// `touch` is the distance from w to a fluid particle that touches the face: w's depth behind the face plus Δx/2
/// (the first fluid layer of the lattice). The condition is the wall's on the fluid in contact with it, not on the
/// fluid within the kernel's reach: s_wf = 1 for a neighbour within `touch` of w along n, falling linearly to 0 at
/// 2 `touch` (s_wf = clamp(2 − (−r_wf · n)/touch, 0, 1)). With s_wf = 1 for every neighbour within 2h the wall
/// rows stopped the front of the Lobovsky dam break while it was still 1.8 Δx from the wall: the wall particle at
/// sensor 1 carried 48 ρgH at t = 0.4305 s, and the probe read 12.7 ρgH at sensor 1 and 26.9 at sensor 2 against
/// 3.0 and 1.95 recorded; with the ramp 3.9 and 5.9 (docs/CORRECTIONS.md, "ISPH pressure"). A hard cut at contact
/// instead (only the approach that would carry f nearer than `touch` within the step) stops a particle in one step
/// and threw one at 4.7 m/s. Established ISPH codes impose on a wall at rest only ∂p/∂n = ρ g · n (Shao & Lo 2003;
/// Lind et al. 2012, J. Comput. Phys. 231:1499), the fluid's motion into it being left to the fluid rows.
#[inline]
pub fn normal_motion_term(
    rho_f: f64,
    u_star_f: [f64; 2],
    r_wf: [f64; 2],
    normal: [f64; 2],
    touch: f64,
    dt: f64,
    g: [f64; 2],
) -> f64 {
    let u = [u_star_f[0] - dt * g[0], u_star_f[1] - dt * g[1]];
    let contact = contact_weight(r_wf, normal, touch);
    // ∂p/∂n = ρ u*·n/Δt (Cummins & Rudman 1999), less the ρ g·n of Adami et al. 2012, Eq. (27), on the fluid that
    // touches the wall
    rho_f * contact * dot(u, normal) * dot(r_wf, normal) / dt
}
