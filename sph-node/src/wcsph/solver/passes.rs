//! The passes of a WCSPH step over the cell-sorted particles: ρ following displaced particles, the density half
//! kick (continuity, Eq. (9)), EOS with wall pressures and accelerations (momentum, Eq. (10)), and the re-sort with
//! the neighbour search.

use rayon::prelude::*;

use super::WcsphSolver;
use crate::boundary::adami;
use crate::boundary::repulsion::Repulsion;
use crate::corrections::apd;
use crate::kernel::CubicSpline;
use crate::neighbors::{NeighborList, SortedCells, VerletCandidates};
use crate::wcsph::sorted::{permute, permute_spending, update_vol};
use crate::wcsph::{continuity, momentum, MomentumParams};

impl WcsphSolver {
    /// ρ follows the positions edited through [`WcsphSolver::state_mut`] (the contact's corrections, `DESIGN.md` §3
    /// step 5) as the continuity equation would follow the same displacement (Eq. (9) with δr for v Δt, as for the
    /// APD shift: [`apd::shift_density_change`]), at the positions and neighbours of the last search.
    ///
    /// Without it a position correction moves a particle without any change of density: the contact, which puts
    /// every particle it finds inside the structure back on the same line r_c in front of its face, stacked particles
    /// up in front of the elastic gate's tip at Δx = 5 mm (some 20 in a few mm², at pressures of a few kPa), until the
    /// stack blew apart and the energy guard stopped the run (`cosim/tests/stress/`,
    /// `coarse_elastic_gate_keeps_its_water_on_the_floor`).
    pub(super) fn density_follows_edits(&mut self) {
        let nf = self.state.len();
        let mut shift = std::mem::take(&mut self.scratch.per2);
        shift.clear();
        let s = &self.sorted;
        shift.extend(
            self.scratch
                .edited_x
                .iter()
                .zip(&s.x[..nf])
                .map(|(e, x)| [e[0] - x[0], e[1] - x[1]]),
        );
        self.density_follows_shift(&shift);
        self.scratch.per2 = shift;
    }

    /// ρ += δρ for the displacement `shift` of each fluid particle, as the continuity equation would change it
    /// ([`apd::shift_density_change`]), at the positions and neighbours of the last search; the volumes follow.
    pub(super) fn density_follows_shift(&mut self, shift: &[[f64; 2]]) {
        let nf = self.state.len();
        let mut drho = std::mem::take(&mut self.scratch.per1);
        apd::shift_density_change_pairs_into(&self.view(), &self.scratch.list, shift, &mut drho);
        let s = &mut self.sorted;
        s.rho[..nf].iter_mut().zip(&drho).for_each(|(r, d)| *r += d);
        update_vol(&mut s.vol[..nf], &s.m[..nf], &s.rho[..nf]);
        self.scratch.per1 = drho;
    }

    /// EOS, wall pressures (Adami) and accelerations for the current positions, densities and velocities.
    pub(super) fn update_pressure_and_acceleration(&mut self) {
        let eos = self.eos;
        let nf = self.state.len();
        let s = &mut self.sorted;
        s.p[..nf]
            .par_iter_mut()
            .zip(s.pr2[..nf].par_iter_mut())
            .zip(s.rho[..nf].par_iter())
            .with_min_len(1024)
            .for_each(|((p, pr2), &r)| {
                *p = eos.pressure(r);
                *pr2 = *p / (r * r);
            });
        let mut wall = std::mem::take(&mut self.scratch.wall);
        adami::wall_pressures_sorted_into(
            &self.view(),
            &self.scratch.cells,
            &self.kernel,
            self.params.gravity,
            &eos,
            &mut wall,
        );
        let s = &mut self.sorted;
        s.p[nf..]
            .par_iter_mut()
            .zip(s.rho[nf..].par_iter_mut())
            .zip(s.vol[nf..].par_iter_mut())
            .zip(s.pr2[nf..].par_iter_mut())
            .zip(s.m[nf..].par_iter())
            .zip(self.walls.p.par_iter_mut().zip(self.walls.rho.par_iter_mut()))
            .zip(wall.par_iter())
            .with_min_len(1024)
            .for_each(|((((((p, rho), vol), pr2), m), (wp, wrho)), &(pw, rw))| {
                (*p, *rho, *wp, *wrho) = (pw, rw, pw, rw);
                *vol = m / rw;
                *pr2 = pw / (rw * rw);
            });
        self.scratch.wall = wall;
        let params = MomentumParams {
            gravity: self.params.gravity,
            alpha: self.wcsph.alpha,
            c0: self.wcsph.c0,
            nu: self.params.nu,
        };
        let mut accel = std::mem::take(&mut self.sorted.accel);
        momentum::accelerations_into(
            &self.view(),
            &self.sorted.pr2,
            &self.scratch.list,
            &self.kernel,
            &params,
            &mut accel,
        );
        let k = self.wcsph.central_force;
        if k != 0.0 {
            // Monaghan & Rafiee 2013: central body force f = −Ω² r
            accel
                .par_iter_mut()
                .zip(self.sorted.x[..nf].par_iter())
                .for_each(|(a, x)| {
                    a[0] -= k * x[0];
                    a[1] -= k * x[1];
                });
        }
        if !self.wall_boxes.boxes().is_empty() {
            // Short-range wall repulsion (boundary/repulsion.rs)
            Repulsion::new(self.params.dx, self.wcsph.c0).add_into(&self.wall_boxes, &self.sorted.x[..nf], &mut accel);
        }
        self.sorted.accel = accel;
    }

    /// Re-sorts the fluid by cell for the current positions and rebuilds the neighbour lists (and the Verlet
    /// candidates, when on).
    pub(super) fn rebuild_neighbors(&mut self) {
        if let Some(v) = &mut self.scratch.verlet {
            v.clear();
        }
        self.resort();
        self.rebuild_lists();
    }

    /// Rebuilds the neighbour lists at the current positions, from the Verlet candidates when on, else from the
    /// cells of the last sort.
    pub(super) fn rebuild_lists(&mut self) {
        let nf = self.state.len();
        let s = &self.sorted;
        let sc = &mut self.scratch;
        let (cells, verlet) = (&sc.cells, sc.verlet.as_ref());
        search_and_map(
            cells,
            verlet,
            &s.x,
            nf,
            &self.kernel,
            &mut sc.list,
            &mut Vec::new(),
            |_, _, _| (),
        );
    }

    /// [`WcsphSolver::rebuild_neighbors`] after the drift, with the density's half kick at the new positions
    /// taken in the same pass, each particle's as soon as its list is built: ρ += ½ Δt Dρ/Dt (Eq. (9), with the
    /// δ-SPH diffusion when on), plus the density change of the drift's APD shift (`Scratch::shift`, when the
    /// step has one; [`continuity::density_increment`]). The volumes follow.
    pub(super) fn rebuild_neighbors_and_density(&mut self, dt: f64) {
        let nf = self.state.len();
        self.resort();
        let diffusion = self.density_diffusion();
        let s = &self.sorted;
        let sc = &mut self.scratch;
        let (view, vol, kernel) = (s.view(nf), &s.vol, &self.kernel);
        let (shift, mut drho) = (&sc.shift, std::mem::take(&mut sc.per1));
        let h = 0.5 * dt;
        // The half kick's density change of each particle: the rate's alone, or with the drift's APD shift.
        let change = |i, idx: &[u32], grad: &[f64]| match shift.is_empty() {
            true => h * continuity::density_rate(i, &view, vol, idx, grad, diffusion.as_ref()),
            false => continuity::density_increment(i, &view, vol, idx, grad, diffusion.as_ref(), shift, dt),
        };
        search_and_map(
            &sc.cells,
            sc.verlet.as_ref(),
            &s.x,
            nf,
            kernel,
            &mut sc.list,
            &mut drho,
            change,
        );
        let s = &mut self.sorted;
        s.rho[..nf].iter_mut().zip(&drho).for_each(|(r, d)| *r += d);
        update_vol(&mut s.vol[..nf], &s.m[..nf], &s.rho[..nf]);
        self.scratch.per1 = drho;
        self.scratch.shift.clear();
    }

    /// Re-sorts the fluid (and the drift's APD shift, when there is one) by cell for the current positions, and
    /// gathers the Verlet candidates when on; with Verlet candidates that still hold, nothing moves.
    pub(super) fn resort(&mut self) {
        let nf = self.state.len();
        let s = &mut self.sorted;
        let sc = &mut self.scratch;
        if sc.verlet.as_ref().is_some_and(|v| v.still_hold(&s.x[..nf])) {
            return;
        }
        let skin = sc.verlet.as_ref().map_or(0.0, |v| v.skin());
        sc.cells.sort(
            &s.x[..nf],
            &self.walls.x,
            self.kernel.support() + skin,
            &mut s.ids,
            &mut s.slot,
            &mut sc.src,
        );
        let src = &sc.src;
        for a in [&mut s.x, &mut s.v, &mut s.accel] {
            permute(a, &mut sc.per2, src);
        }
        for a in [&mut s.rho, &mut s.p, &mut s.m, &mut s.vol] {
            permute(a, &mut sc.per1, src);
        }
        if !sc.shift.is_empty() {
            // The drift's APD shift, for its density change at the new positions: in place, so that no spare of
            // its size is held for it (`src` is spent doing so; nothing reads it before the next sort).
            permute_spending(&mut sc.shift, &mut sc.src);
        }
        if let Some(v) = &mut sc.verlet {
            v.gather(&sc.cells, &s.x, nf, self.kernel.support());
        }
    }
}

/// The fluid's neighbour lists with their ∇W factors and `out[i] = f(i, neighbours, factors)`: from the Verlet
/// candidates when on, else from the cells.
#[allow(clippy::too_many_arguments)]
fn search_and_map<T, F>(
    cells: &SortedCells,
    verlet: Option<&VerletCandidates>,
    x: &[[f64; 2]],
    nf: usize,
    kernel: &CubicSpline,
    list: &mut NeighborList,
    out: &mut Vec<T>,
    f: F,
) where
    T: Copy + Default + Send,
    F: Fn(usize, &[u32], &[f64]) -> T + Sync,
{
    match verlet {
        Some(v) => v.build_lists_and_map(x, kernel, list, out, f),
        None => cells.build_fluid_lists_and_map(x, nf, kernel, list, out, f),
    }
}
