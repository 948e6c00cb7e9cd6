//! [`IsphSolver`]: the projection method of `DESIGN.md` §4.3 (Cummins & Rudman 1999; Shao & Lo 2003) with
//! walls as PPE unknowns (Adami et al. 2012, Eq. (27) rows; §4.7) and optional XSPH (§4.4).
//!
//! One step of size Δt:
//! 0. in a coupled run, the contact's corrections since the last step tell which particles lean on a structure
//!    ([`super::contact`]), and a particle found inside a wall is put back on its face ([`crate::boundary::wall_guard`]);
//! 1. predictor u* = uⁿ + Δt (g + ν∇²uⁿ), x* = xⁿ + Δt u*;
//! 2. neighbours at x*; free surface (∇·r ≤ 1.25 → p = 0, Poisson rows from 1.75, blended between); PPE source (∇·u*/Δt or (ρ0 − ρ*)/(ρ0 Δt²));
//! 3. PPE solved by Jacobi-BiCGSTAB warm-started from the last pressures (fluid and walls);
//! 4. corrector u^{n+1} = u* − Δt (∇p/ρ)_i at x*; x^{n+1} = xⁿ + Δt (uⁿ + u^{n+1})/2 (+ Δt XSPH of u^{n+1});
//! 5. APD shift of x^{n+1} (`fluid.apd` > 0, §4.4).
//!
//! The fluid is incompressible: ρ = ρ0 for fluid and walls throughout.

use cosim_proto::scene::{ContactAlgorithm, FluidSolver as SceneSolver, PpeSourceKind, Scene};
use rayon::prelude::*;

use super::contact::{ContactLayer, ContactRow};
use super::{ppe, projection, wall_normal, IsphOptions, PpeSource};
use crate::boundary::repulsion::RANGE;
use crate::boundary::wall_guard::WallBoxes;
use crate::corrections::{apd, xsph};
use crate::eos::Tait;
use crate::error::{Result, SphError};
use crate::kernel::CubicSpline;
use crate::neighbors::{CellList, NeighborList};
use crate::params::SphParams;
use crate::particles::{max_norm, FluidState, ParticleView, WallParticles};
use crate::setup::{self, FluidSetup};

mod diagnostics;
pub use diagnostics::PpeReport;
mod fluid_solver;
mod pressure;
mod restore;
mod source;

use source::Source;

/// Scratch rebuilt every step: nothing here is state.
#[derive(Clone, Debug, Default)]
struct Scratch {
    x: Vec<[f64; 2]>,
    v: Vec<[f64; 2]>,
    rho: Vec<f64>,
    p: Vec<f64>,
    m: Vec<f64>,
    cells: CellList,
    list: NeighborList,
    free: Vec<bool>,
    weight: Vec<f64>,
    contact: Vec<Option<ContactRow>>,
    in_contact: Vec<bool>,
    source: Vec<f64>,
    xsph: Vec<[f64; 2]>,
    wall_v: Vec<[f64; 2]>,
    /// The PPE's matrix and right-hand side, assembled anew each step into the allocations of the last.
    ppe: ppe::SparseRows,
    rhs: Vec<f64>,
}

/// Incompressible SPH solver (projection method).
#[derive(Clone, Debug)]
pub struct IsphSolver {
    params: SphParams,
    options: IsphOptions,
    kernel: CubicSpline,
    state: FluidState,
    walls: WallParticles,
    /// sqrt(2 |g| H), H the fluid's depth: the speed scale of Δt while the fluid is slower (§4.2: v_max ≈
    /// sqrt(2gH)).
    v_ref: f64,
    /// Largest |u^{n+1} − uⁿ|/Δt of the last step (|g| before the first).
    a_max: f64,
    /// ρ0 Σ_lattice W Δx²: the summation density of a full lattice, the reference of the density-invariant
    /// source (the cubic spline sum of a lattice is not exactly 1).
    rho_ref: f64,
    last_ppe: PpeReport,
    /// The particles the contact corrected lately and the faces they revealed (coupled runs; see
    /// [`super::contact`]).
    contact: ContactLayer,
    /// The wall boxes, to put back a particle found inside a wall (see [`crate::boundary::wall_guard`]).
    wall_boxes: WallBoxes,
    /// The unit normal of each wall particle ([`super::wall_normal`]).
    wall_normals: Vec<[f64; 2]>,
    /// Where a fluid particle touches each wall particle's face: its depth behind the face plus Δx/2
    /// ([`super::wall_normal::contact_weight`]; walls do not move).
    wall_touch: Vec<f64>,
    /// Factor on the step of §4.3 (`fluid.cfl`, in (0, 1]; 1 unless the scene says otherwise).
    cfl: f64,
    /// APD β (`fluid.apd`, §4.4; 0 disables): the particle shift applied after each step, as for WCSPH.
    apd: f64,
    /// c0 of the scene (`fluid.sound_speed`, else its WCSPH default) when it couples a structure with the
    /// `particle_particle` contact, else 0: the broker applies that contact's repulsive force once per coupling
    /// step, explicitly, and the step is bounded by the acoustic step the force is integrated at with WCSPH (see
    /// [`IsphSolver::stable_dt`]).
    force_c0: f64,
    scratch: Scratch,
}

impl IsphSolver {
    /// Builds particles and walls from the scene (`fluid.solver` must be `isph`), with the scene's PPE source
    /// (`fluid.ppe_source`, default divergence-free) and tolerance (`fluid.ppe_tolerance`).
    pub fn new(scene: &Scene) -> Result<Self> {
        let spec = setup::fluid_spec(scene, SceneSolver::Isph)?;
        Self::with_source(
            scene,
            match spec.ppe_source.unwrap_or(PpeSourceKind::DivergenceFree) {
                PpeSourceKind::DivergenceFree => PpeSource::DivergenceFree,
                PpeSourceKind::DensityInvariant => PpeSource::DensityInvariant,
            },
        )
    }

    /// As [`IsphSolver::new`] with the given PPE source.
    pub fn with_source(scene: &Scene, source: PpeSource) -> Result<Self> {
        let spec = setup::fluid_spec(scene, SceneSolver::Isph)?;
        Self::with_options(
            scene,
            IsphOptions {
                source,
                tolerance: spec.ppe_tolerance(),
                ..IsphOptions::default()
            },
        )
    }

    /// As [`IsphSolver::new`] with all the ISPH options.
    pub fn with_options(scene: &Scene, options: IsphOptions) -> Result<Self> {
        let spec = setup::fluid_spec(scene, SceneSolver::Isph)?;
        if !(options.tolerance > 0.0 && options.max_iterations > 0 && options.courant > 0.0) {
            return Err(SphError::InvalidParameter {
                name: "isph options",
                message: format!("tolerance, max_iterations and courant must be positive: {options:?}"),
            });
        }
        let gravity = scene.run.gravity;
        let (dx, rho0) = (spec.spacing, spec.density);
        // The domain (see `FluidSetup::new`) is padded at least by how far a particle that leaves the walls can
        // travel in the run: the end of a floor it flows off, a jet thrown up by an impact on a structure. ISPH fronts
        // and jets move at the fluid's full speed (the elastic gate's front runs at 2.1 m/s, ≈ 2 sqrt(g H), and falls
        // off the floor's end at x = 0.5 m at t = 0.24 s; the obstacle throws a particle up at 4 m/s), so the padding
        // is 2 sqrt(2 |g| H) T + |g| T²/2 for a run of T = end_time. This box only catches runaway particles; it
        // bounds no search grid.
        let g_abs = gravity[0].hypot(gravity[1]);
        let v_fluid = {
            let (top, bottom) = setup::fluid_extent(spec);
            (2.0 * g_abs * (top - bottom)).sqrt()
        };
        let t_end = scene.run.end_time.max(0.0);
        let reach = 2.0 * v_fluid * t_end + 0.5 * g_abs * t_end * t_end;
        // Hydrostatic initial pressure (the warm start of the first PPE); the Tait law only places densities,
        // which are reset to ρ0.
        let FluidSetup {
            mut state,
            walls,
            wall_boxes,
            params,
        } = FluidSetup::new(scene, spec, &Tait::new(rho0, 1.0), reach);
        state.rho.iter_mut().for_each(|r| *r = rho0);
        let wall_normals = wall_normal::wall_normals(&walls.x, &wall_boxes);
        let wall_touch = walls.x.iter().map(|&x| wall_boxes.depth(x) + 0.5 * dx).collect();
        let nw = walls.len();
        let h = params.h;
        let kernel = CubicSpline::new(h);
        let rho_ref = {
            let reach = (2.0 * h / dx).ceil() as i64 + 1;
            let mut s = 0.0;
            for iy in -reach..=reach {
                for ix in -reach..=reach {
                    s += kernel.w((ix as f64 * dx).hypot(iy as f64 * dx));
                }
            }
            rho0 * s * dx * dx
        };
        let mut solver = Self {
            params,
            options,
            kernel,
            state,
            walls,
            a_max: gravity[0].hypot(gravity[1]),
            v_ref: v_fluid,
            rho_ref,
            last_ppe: PpeReport::default(),
            contact: ContactLayer::default(),
            wall_boxes,
            wall_normals,
            wall_touch,
            cfl: spec.cfl,
            apd: spec.apd(),
            force_c0: if scene.contact.algorithm == ContactAlgorithm::ParticleParticle && !scene.solids.is_empty() {
                setup::sound_speed(spec, gravity)?
            } else {
                0.0
            },
            scratch: Scratch::default(),
        };
        solver.contact.record_end(&solver.state);
        solver.scratch.m = solver.state.m.iter().chain(&solver.walls.m).copied().collect();
        solver.scratch.rho = vec![rho0; solver.state.len() + nw];
        solver.scratch.v = vec![[0.0; 2]; solver.state.len() + nw];
        solver.check(0)?;
        solver.rebuild_neighbors();
        Ok(solver)
    }

    /// Resolved parameters (`c0` and `alpha` are 0: ISPH has neither).
    pub fn params(&self) -> &SphParams {
        &self.params
    }

    /// The ISPH options.
    pub fn options(&self) -> &IsphOptions {
        &self.options
    }

    /// The kernel.
    pub fn kernel(&self) -> &CubicSpline {
        &self.kernel
    }

    /// The fluid state.
    pub fn state(&self) -> &FluidState {
        &self.state
    }

    /// The particle state, for corrections applied from outside (contact, `DESIGN.md` §3 step 5). Positions and
    /// velocities may change; the particle count and order may not.
    pub fn state_mut(&mut self) -> &mut FluidState {
        &mut self.state
    }

    /// The wall particles, with the pressures of the last PPE solution.
    pub fn walls(&self) -> &WallParticles {
        &self.walls
    }

    /// Advances the fluid by `dt` (predictor, PPE, corrector; see the module documentation).
    ///
    /// Errors: [`SphError::PpeNotConverged`] when BiCGSTAB does not reach the tolerance, [`SphError::Unstable`]
    /// for non-finite values or a particle leaving the domain. After an error the state is part-way through the
    /// step and should not be advanced further.
    pub fn step(&mut self, dt: f64) -> Result<()> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(SphError::InvalidParameter {
                name: "dt",
                message: format!("must be a positive number, got {dt}"),
            });
        }
        let step_no = self.state.step + 1;
        let nf = self.state.len();
        let g = self.params.gravity;
        // The solver's own step for this state: the density terms of the source relax over it (see below).
        let dt_own = self.stable_dt();
        // 0. Contact corrections applied since the last step (coupled runs): which particles lean on a structure,
        //    and particles put inside a wall sent back to its face.
        self.contact.detect(&self.state, self.params.dx);
        let mut wall_pushes = 0;
        for (x, v) in self.state.x.iter_mut().zip(self.state.v.iter_mut()) {
            wall_pushes += usize::from(self.wall_boxes.push_out(x, v));
        }
        let x_n = self.state.x.clone();
        let v_n = self.state.v.clone();

        // 1. Predictor (Cummins & Rudman 1999, Eq. (13)): u* = uⁿ + Δt (g + ν∇²uⁿ), neighbours of xⁿ.
        self.scratch.v[..nf].copy_from_slice(&self.state.v);
        let visc: Vec<[f64; 2]> = {
            let view = self.view();
            let (list, kernel, nu) = (&self.scratch.list, &self.kernel, self.params.nu);
            (0..nf)
                .into_par_iter()
                .map(|i| projection::viscous_acceleration(i, &view, list.of(i), kernel, nu))
                .collect()
        };
        // u* in place of uⁿ (kept in `v_n`).
        for (v, a) in self.state.v.iter_mut().zip(&visc) {
            v[0] += dt * (g[0] + a[0]);
            v[1] += dt * (g[1] + a[1]);
        }
        drop(visc);
        // x* = xⁿ + Δt u*
        for (x, v) in self.state.x.iter_mut().zip(&self.state.v) {
            x[0] += dt * v[0];
            x[1] += dt * v[1];
        }
        self.check(step_no)?;
        self.rebuild_neighbors();
        self.scratch.v[..nf].copy_from_slice(&self.state.v);

        let Source {
            mut free,
            weight,
            rows,
            in_contact,
            n_contact,
            source,
        } = self.free_surface_and_source(dt, dt_own);

        for v in &mut self.scratch.v[nf..] {
            *v = [0.0, 0.0];
        }
        // 3. PPE (Shao & Lo 2003, Eq. (15); walls: Adami et al. 2012, Eq. (27)), warm-started.
        let (mut a, mut b) = (
            std::mem::take(&mut self.scratch.ppe),
            std::mem::take(&mut self.scratch.rhs),
        );
        ppe::assemble(
            &self.view(),
            &self.scratch.list,
            &self.kernel,
            g,
            self.params.rho0,
            &weight,
            &in_contact,
            &source,
            &self.wall_normals,
            &self.wall_touch,
            dt,
            // The void that cuts a support counts as p = 0 beyond `ppe::VOID_TOLERANCE` of a full support
            // (`ppe::fluid_row`). Computed here, not stored: the checkpoint format stays as it is.
            ppe::full_support_coefficient(&self.kernel, self.params.dx, self.params.rho0),
            &mut a,
            &mut b,
        );
        let pinned = ppe::anchor_floating_groups(&mut a, &mut b, &mut free, &weight, &self.scratch.x, nf, g);
        let mut p: Vec<f64> = self.state.p.iter().chain(&self.walls.p).copied().collect();
        for (pi, &f) in p.iter_mut().zip(&free) {
            if f {
                *pi = 0.0;
            }
        }
        let result = self.solve_pressure(&mut a, &mut b, &mut p);
        // On the free surface by Lo & Shao's flag (∇·r below the threshold: φ > 1/2), Dirichlet rows or not
        let n_free = free.iter().zip(&weight).filter(|&(&f, &w)| f || w > 0.5).count();
        self.scratch.free = free;
        self.scratch.weight = weight;
        self.scratch.source = source;
        self.scratch.contact = rows;
        self.scratch.in_contact = in_contact;
        (self.scratch.ppe, self.scratch.rhs) = (a, b);
        let stats = match result {
            Ok(s) => s,
            Err(s) => {
                return Err(SphError::PpeNotConverged {
                    step: step_no,
                    iterations: s.iterations,
                    residual: s.residual,
                })
            }
        };
        self.last_ppe = PpeReport {
            iterations: stats.iterations,
            residual: stats.residual,
            free_surface: n_free,
            contact: n_contact,
            anchored: pinned.len(),
            wall_pushes,
        };
        if let Some(i) = p.iter().position(|p| !p.is_finite()) {
            return Err(self.unstable(step_no, i.min(nf.saturating_sub(1)), "non-finite PPE pressure".into()));
        }
        // Negative pressures are clipped to 0 after the linear solve: walls never pull the fluid (Adami et al.
        // 2012, as `boundary::adami`; wall particles above the free surface extrapolate below 0), and negative
        // fluid pressures (tensile instability of the symmetric gradient) are set to 0 as is usual in free-surface
        // ISPH (Shao & Lo 2003 treat the surface as p = 0). Without this the still-water tank blows up in 0.6 s.
        for pi in &mut p {
            *pi = pi.max(0.0);
        }
        self.state.p.copy_from_slice(&p[..nf]);
        self.walls.p.copy_from_slice(&p[nf..]);
        self.scratch.p.clear();
        self.scratch.p.extend_from_slice(&p);

        // 4. Corrector (Cummins & Rudman 1999, Eq. (16)): u^{n+1} = u* − Δt (∇p/ρ)_i at x*.
        let grad: Vec<[f64; 2]> = {
            let view = self.view();
            let (list, kernel) = (&self.scratch.list, &self.kernel);
            (0..nf)
                .into_par_iter()
                .map(|i| projection::pressure_gradient(i, &view, list.of(i), kernel))
                .collect()
        };
        for (v, gp) in self.state.v.iter_mut().zip(&grad) {
            v[0] -= dt * gp[0];
            v[1] -= dt * gp[1];
        }
        // XSPH (§4.4) of u^{n+1}, gathered at x*.
        let mut corr = std::mem::take(&mut self.scratch.xsph);
        corr.clear();
        if self.params.xsph > 0.0 {
            self.scratch.v[..nf].copy_from_slice(&self.state.v);
            xsph::xsph_into(
                &self.view(),
                &self.scratch.list,
                &self.kernel,
                self.params.xsph,
                &mut corr,
            );
        }
        // §4.3 step 5: x^{n+1} = xⁿ + Δt (uⁿ + u^{n+1})/2
        let mut a_max: f64 = 0.0;
        for i in 0..nf {
            let (v0, v1) = (v_n[i], self.state.v[i]);
            let c = corr.get(i).copied().unwrap_or([0.0; 2]);
            self.state.x[i] = [
                x_n[i][0] + dt * (0.5 * (v0[0] + v1[0]) + c[0]),
                x_n[i][1] + dt * (0.5 * (v0[1] + v1[1]) + c[1]),
            ];
            a_max = a_max.max((v1[0] - v0[0]).hypot(v1[1] - v0[1]) / dt);
        }
        self.scratch.xsph = corr;
        self.a_max = a_max.max(g[0].hypot(g[1]));
        self.check(step_no)?;
        self.rebuild_neighbors();
        // 5. APD (§4.4): the shifting of Lind, Xu, Stansby & Rogers (2012), which was made for ISPH, in the same
        //    δ+-SPH kernel-gradient form and free-surface treatment as WCSPH's (`corrections::apd`), at x^{n+1}.
        //    The fluid is incompressible (ρ = ρ0): no density to carry along; velocities stay with their particles.
        if self.apd > 0.0 {
            let v_max = max_norm(&self.state.v);
            if v_max > 0.0 {
                let params = apd::ApdParams {
                    beta: self.apd,
                    v_max,
                    dt,
                };
                let mut shift = Vec::new();
                apd::apd_into(&self.view(), &self.scratch.list, &self.kernel, &params, &mut shift);
                // The shift does not take a particle nearer to a wall face than the range of the WCSPH wall
                // repulsion, Δx/4 (`boundary::repulsion::RANGE`). Near the line where the surface meets a wall the
                // tangential part that the surface treatment keeps can point into the wall, and with the ISPH
                // surface never at rest it carried particles through it (10 s still tank: 90 put back by the wall
                // guard, the deepest 0.015 Δx inside; with the hold-off none, closest 0.18 Δx). A hold-off of Δx/2
                // kept the tank out of the walls too, but in the tall dam break's impact on the far wall at
                // `fluid.cfl` = 0.9 a corner particle was shot up at 7.6 m/s (in 1 of 5 runs at `fluid.cfl`
                // 0.8–1; in none of them at Δx/4 or without a hold-off; cause not found).
                let gap = RANGE * self.params.dx;
                for (x, d) in self.state.x.iter_mut().zip(&shift) {
                    let d = self.wall_boxes.hold_off(*x, *d, gap);
                    x[0] += d[0];
                    x[1] += d[1];
                }
                self.check(step_no)?;
                self.rebuild_neighbors();
            }
        }
        self.state.t += dt;
        self.state.step = step_no;
        self.contact.record_end(&self.state);
        Ok(())
    }

    fn rebuild_neighbors(&mut self) {
        let s = &mut self.scratch;
        s.x.clear();
        s.x.extend_from_slice(&self.state.x);
        s.x.extend_from_slice(&self.walls.x);
        s.cells.rebuild(&s.x, self.kernel.support());
        s.cells
            .neighbor_list_into(&s.x, s.x.len(), self.kernel.support(), &mut s.list);
        s.p.clear();
        s.p.extend_from_slice(&self.state.p);
        s.p.extend_from_slice(&self.walls.p);
    }

    fn view(&self) -> ParticleView<'_> {
        let s = &self.scratch;
        ParticleView {
            x: &s.x,
            v: &s.v,
            rho: &s.rho,
            p: &s.p,
            m: &s.m,
            n_fluid: self.state.len(),
        }
    }

    /// Non-finite or out-of-domain positions and velocities.
    fn check(&self, step: u64) -> Result<()> {
        let d = &self.params.domain;
        for (i, (x, v)) in self.state.x.iter().zip(&self.state.v).enumerate() {
            if !(x[0].is_finite() && x[1].is_finite() && v[0].is_finite() && v[1].is_finite()) {
                return Err(self.unstable(step, i, "non-finite position or velocity".into()));
            }
            if !d.contains(*x) {
                return Err(self.unstable(step, i, format!("left the domain at {x:?}")));
            }
        }
        Ok(())
    }

    fn unstable(&self, step: u64, particle: usize, reason: String) -> SphError {
        SphError::Unstable { step, particle, reason }
    }
}
