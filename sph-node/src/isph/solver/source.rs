//! Step 2 of the ISPH step (see [`super`]): the free surface, the contact rows and the PPE source at the predicted
//! positions x*.

use rayon::prelude::*;

use super::IsphSolver;
use crate::isph::contact::{self, ContactRow};
use crate::isph::{free_surface, projection, wall_normal, PpeSource};

/// What step 2 gives the PPE.
pub(super) struct Source {
    /// Free-surface particles (p = 0).
    pub(super) free: Vec<bool>,
    /// The Dirichlet weight of every fluid particle's PPE row ([`free_surface::dirichlet_weight`]).
    pub(super) weight: Vec<f64>,
    /// The contact row of each fluid particle against a structure (empty when none is).
    pub(super) rows: Vec<Option<ContactRow>>,
    /// Which fluid particles have a contact row.
    pub(super) in_contact: Vec<bool>,
    /// How many.
    pub(super) n_contact: usize,
    /// The PPE's source per fluid particle.
    pub(super) source: Vec<f64>,
}

impl IsphSolver {
    /// Free surface, contact rows and PPE source at x* for a step of `dt` (`dt_own`: the solver's own step for the
    /// state at the start of the step). The wall rows of `scratch.v` receive the walls' divergence velocities.
    pub(super) fn free_surface_and_source(&mut self, dt: f64, dt_own: f64) -> Source {
        let nf = self.state.len();
        let g = self.params.gravity;
        // 2. Free surface and PPE source at x*.
        let mut free = std::mem::take(&mut self.scratch.free);
        let mut weight = std::mem::take(&mut self.scratch.weight);
        free_surface::free_surface_into(
            &self.view(),
            &self.scratch.list,
            &self.kernel,
            self.options.free_surface_threshold,
            &mut weight,
        );
        // Particles against a structure (see `super::contact`): their support, ∇·r and ρ* count the structure's
        // half-space; their rows carry the face's Neumann condition.
        let mut rows = std::mem::take(&mut self.scratch.contact);
        contact::contact_rows_into(
            &self.view(),
            &self.scratch.list,
            &self.kernel,
            &self.contact,
            self.params.dx,
            self.params.rho0,
            self.options.free_surface_threshold,
            &mut weight,
            &mut rows,
        );
        // Free surface: the particles whose row is Dirichlet (φ = 1).
        free.clear();
        free.extend(weight.iter().map(|&w| w >= 1.0));
        let mut in_contact = std::mem::take(&mut self.scratch.in_contact);
        in_contact.clear();
        in_contact.extend(rows.iter().map(Option::is_some));
        let n_contact = in_contact.iter().filter(|&&c| c).count();
        let mut source = std::mem::take(&mut self.scratch.source);
        source.clear();
        // Walls carry Δt g and the normal part of the fluid's motion next to them for the divergence only (see
        // `projection::velocity_divergence` and `wall_normal`), and so does the normal velocity of the first layer
        // against a structure, with the face's (see `contact::face_normal_velocity`).
        let mut wall_v = std::mem::take(&mut self.scratch.wall_v);
        wall_normal::divergence_velocities_into(
            &self.view(),
            &self.scratch.list,
            &self.kernel,
            &self.wall_normals,
            &self.wall_touch,
            dt,
            g,
            &mut wall_v,
        );
        self.scratch.v[nf..].copy_from_slice(&wall_v);
        self.scratch.wall_v = wall_v;
        for (v, row) in self.scratch.v[..nf].iter_mut().zip(&rows) {
            if let Some(row) = row.filter(|r| r.against) {
                *v = contact::face_normal_velocity(*v, &row.face, dt, g);
            }
        }
        {
            let view = self.view();
            let (list, kernel) = (&self.scratch.list, &self.kernel);
            let (rho0, rho_ref) = (self.params.rho0, self.rho_ref);
            // Δt² of the density terms: Δt · max(Δt, Δt_own). They move a particle by a fixed fraction of its density
            // error per step (Δx ∝ Δt² · source), so a step shorter than the solver's own (a coupled run steps at
            // the coupling's max_dt, 1e-4 s where ISPH would take 1e-3 s) would relax the density that many times
            // faster in time, and the ~1 % deficit the summation reads next to any truncated support (the second
            // row under a free surface or over a structure) would become a sink of −γ 0.01 ρ0 Δx²/(4 Δt²) ≈ −3 kPa
            // at 2e-4 s: a suction that, clipped, takes the hydrostatic pressure off the structure. At Δt = Δt_own
            // (every uncoupled run) this is Δt², bit for bit.
            let dt2 = dt * dt.max(dt_own);
            // ρ* of a particle against a structure counts the structure's half-space as fluid.
            let rows = &rows;
            let rho_star = |i: usize| {
                let s = match rows.get(i).copied().flatten() {
                    Some(row) => row.density,
                    None => projection::summation_density(i, &view, list.of(i), kernel),
                };
                s * rho0 / rho_ref
            };
            match self.options.source {
                // Cummins & Rudman 1999, Eq. (15): ∇·(∇p/ρ) = ∇·u*/Δt
                // + Asai et al. 2012, Eq. (25): γ (ρ0 − ρ*)/(ρ0 Δt²) when density_relaxation γ > 0
                PpeSource::DivergenceFree => {
                    let gamma = self.options.density_relaxation;
                    (0..nf)
                        .into_par_iter()
                        .map(|i| {
                            let div = projection::velocity_divergence(i, &view, list.of(i), kernel) / dt;
                            if gamma > 0.0 {
                                div + gamma * (rho0 - rho_star(i)) / (rho0 * dt2)
                            } else {
                                div
                            }
                        })
                        .collect_into_vec(&mut source)
                }
                // Shao & Lo 2003, Eq. (14): ∇·(∇p/ρ) = (ρ0 − ρ*)/(ρ0 Δt²), ρ* by summation at x* relative to the
                // full-lattice sum (ρ* = ρ0 on the initial lattice)
                PpeSource::DensityInvariant => (0..nf)
                    .into_par_iter()
                    .map(|i| (rho0 - rho_star(i)) / (rho0 * dt2))
                    .collect_into_vec(&mut source),
            }
        }
        Source {
            free,
            weight,
            rows,
            in_contact,
            n_contact,
            source,
        }
    }
}
