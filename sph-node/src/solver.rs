//! [`WcsphSolver`]: the WCSPH pipeline of `DESIGN.md` §4.2 (Eqs. (9)–(12)) with Adami walls (§4.7), the Shepard
//! or first-order MLS density filter, XSPH and APD (§4.4), advanced by kick–drift–kick.
//!
//! The solver owns the serializable [`FluidState`] and [`WallParticles`] and scratch that is rebuilt every step
//! (combined particle arrays, cell list, neighbour lists, rates).

use cosim_proto::scene::{BoxSpec, DensityFilter, FluidSolver, Scene};
use rayon::prelude::*;

use crate::boundary::{adami, walls};
use crate::corrections::{apd, density_filter, mls, xsph};
use crate::eos::Tait;
use crate::error::{Result, SphError};
use crate::integrator;
use crate::kernel::CubicSpline;
use crate::neighbors::{CellList, NeighborList};
use crate::particles::{FluidState, ParticleView, WallParticles};
use crate::setup;
use crate::time_step;
use crate::wcsph::{continuity, momentum, MomentumParams};

/// Resolved parameters of the fluid.
#[derive(Clone, Debug, PartialEq)]
pub struct SphParams {
    /// Rest density ρ0.
    pub rho0: f64,
    /// Particle spacing Δx.
    pub dx: f64,
    /// Smoothing length h.
    pub h: f64,
    /// Speed of sound c0.
    pub c0: f64,
    /// Kinematic viscosity ν.
    pub nu: f64,
    /// Gravity.
    pub gravity: [f64; 2],
    /// α_π of Eq. (11).
    pub alpha: f64,
    /// Density filter interval in steps (`None`: off); the filter (Shepard or MLS) is chosen by
    /// [`WcsphOptions::mls`].
    pub shepard_interval: Option<u32>,
    /// XSPH ε (0: off).
    pub xsph: f64,
    /// A fluid particle outside this box is unstable.
    pub domain: BoxSpec,
}

/// WCSPH settings beyond [`SphParams`] (kept apart so that `SphParams` stays shared with other solvers).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WcsphOptions {
    /// The density filter passes (every [`SphParams::shepard_interval`] steps) use the first-order MLS filter
    /// (Colagrossi & Landrini 2003) instead of Shepard's.
    pub mls: bool,
    /// APD β (0: off; §4.4, Xu et al. 2009).
    pub apd: f64,
    /// Central body force a = −k x (k = Ω², Monaghan & Rafiee 2013 oscillating drop); 0 for scenes.
    pub central_force: f64,
}

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
    accel: Vec<[f64; 2]>,
    drho: Vec<f64>,
    filtered: Vec<f64>,
    xsph: Vec<[f64; 2]>,
    shift: Vec<[f64; 2]>,
    wall: Vec<(f64, f64)>,
}

/// Weakly compressible SPH solver.
#[derive(Clone, Debug)]
pub struct WcsphSolver {
    params: SphParams,
    options: WcsphOptions,
    kernel: CubicSpline,
    eos: Tait,
    state: FluidState,
    walls: WallParticles,
    scratch: Scratch,
}

impl WcsphSolver {
    /// Builds particles and walls from the scene and evaluates the initial rates.
    pub fn new(scene: &Scene) -> Result<Self> {
        let spec = scene.fluid.as_ref().ok_or_else(|| SphError::InvalidScene {
            key: "fluid".into(),
            message: "the scene has no [fluid] section".into(),
        })?;
        if spec.solver != FluidSolver::Wcsph {
            return Err(SphError::InvalidScene {
                key: "fluid.solver".into(),
                message: "only wcsph is implemented by this solver".into(),
            });
        }
        let shepard_interval = match spec.density_filter() {
            DensityFilter::None => None,
            DensityFilter::Shepard | DensityFilter::Mls if spec.density_filter_interval == 0 => {
                return Err(SphError::InvalidScene {
                    key: "fluid.density_filter_interval".into(),
                    message: "must be at least 1 step".into(),
                })
            }
            DensityFilter::Shepard | DensityFilter::Mls => Some(spec.density_filter_interval),
        };
        let gravity = scene.run.gravity;
        let dx = spec.spacing;
        let h = spec.smoothing_ratio * dx;
        let c0 = setup::sound_speed(spec, gravity)?;
        let eos = Tait::new(spec.density, c0);
        let state = setup::initial_state(spec, gravity, &eos);

        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for b in spec.blocks.iter().chain(&scene.walls) {
            for k in 0..2 {
                lo[k] = lo[k].min(b.min[k]);
                hi[k] = hi[k].max(b.max[k]);
            }
        }
        let fluid_centre = {
            let n = state.len().max(1) as f64;
            let s = state.x.iter().fold([0.0; 2], |s, p| [s[0] + p[0], s[1] + p[1]]);
            [s[0] / n, s[1] / n]
        };
        let wall_x = walls::wall_positions(&scene.walls, spec.blocks[0].min, dx, h, fluid_centre);
        let nw = wall_x.len();
        let walls = WallParticles {
            x: wall_x,
            p: vec![0.0; nw],
            rho: vec![spec.density; nw],
            m: vec![spec.density * dx * dx; nw],
        };
        // Domain: the box around blocks and walls, padded by half its largest extent.
        let pad = 0.5 * (hi[0] - lo[0]).max(hi[1] - lo[1]) + 4.0 * h;
        let domain = BoxSpec {
            min: [lo[0] - pad, lo[1] - pad],
            max: [hi[0] + pad, hi[1] + pad],
        };
        let params = SphParams {
            rho0: spec.density,
            dx,
            h,
            c0,
            nu: spec.kinematic_viscosity,
            gravity,
            alpha: spec.artificial_viscosity,
            shepard_interval,
            xsph: spec.xsph,
            domain,
        };
        let options = WcsphOptions {
            mls: spec.density_filter() == DensityFilter::Mls,
            // The scene's default is 0 for now: with β = 0.04 still water develops an interior pressure error
            // (particles pair up at Δx/2 mid-depth; 11 % at mid-depth after 2 s).
            apd: spec.apd,
            central_force: 0.0,
        };
        Self::from_particles(params, options, state, walls)
    }

    /// A solver on given particles (tests, e.g. the oscillating drop, whose circle the scene's blocks cannot
    /// describe): the Tait law follows from `params.rho0` and `params.c0`, the kernel from `params.h`. The
    /// state's ρ and v are taken as given (p is recomputed from ρ); wall p and ρ are re-extrapolated.
    pub fn from_particles(
        params: SphParams,
        options: WcsphOptions,
        state: FluidState,
        walls: WallParticles,
    ) -> Result<Self> {
        let n = state.len();
        if state.v.len() != n || state.rho.len() != n || state.m.len() != n || state.p.len() != n {
            return Err(SphError::InvalidParameter {
                name: "state",
                message: "x, v, rho, p and m must have the same length".into(),
            });
        }
        let nw = walls.len();
        if walls.p.len() != nw || walls.rho.len() != nw || walls.m.len() != nw {
            return Err(SphError::InvalidParameter {
                name: "walls",
                message: "x, p, rho and m must have the same length".into(),
            });
        }
        let eos = Tait::new(params.rho0, params.c0);
        let kernel = CubicSpline::new(params.h);
        let mut solver = Self {
            params,
            options,
            kernel,
            eos,
            state,
            walls,
            scratch: Scratch::default(),
        };
        solver.scratch.m = solver.state.m.iter().chain(&solver.walls.m).copied().collect();
        solver.scratch.v = vec![[0.0; 2]; solver.state.len() + solver.walls.len()];
        solver.check(0)?;
        solver.rebuild_neighbors();
        solver.update_pressure_and_acceleration();
        Ok(solver)
    }

    /// Resolved parameters.
    pub fn params(&self) -> &SphParams {
        &self.params
    }

    /// WCSPH options (density filter kind, APD β, central force).
    pub fn options(&self) -> &WcsphOptions {
        &self.options
    }

    /// Sets the APD β (§4.4; 0 disables) for the following steps.
    pub fn set_apd(&mut self, beta: f64) {
        self.options.apd = beta;
    }

    /// The kernel.
    pub fn kernel(&self) -> &CubicSpline {
        &self.kernel
    }

    /// The equation of state.
    pub fn eos(&self) -> &Tait {
        &self.eos
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

    /// The wall particles.
    pub fn walls(&self) -> &WallParticles {
        &self.walls
    }

    /// Acceleration of every fluid particle at the current time level.
    pub fn accelerations(&self) -> &[[f64; 2]] {
        &self.scratch.accel
    }

    /// Stable step of §4.2 for the current state.
    pub fn stable_dt(&self) -> f64 {
        let v_max = self
            .state
            .v
            .par_iter()
            .map(|v| v[0].hypot(v[1]))
            .reduce(|| 0.0, f64::max);
        let a_max = self
            .scratch
            .accel
            .par_iter()
            .map(|a| a[0].hypot(a[1]))
            .reduce(|| 0.0, f64::max);
        time_step::stable_dt(self.params.h, self.params.c0, v_max, a_max, self.params.nu)
    }

    /// Σ ½ m |v|² (per unit depth).
    pub fn kinetic_energy(&self) -> f64 {
        self.state.kinetic_energy()
    }

    /// Σ −m g · x (per unit depth; zero at the origin).
    pub fn potential_energy(&self) -> f64 {
        self.state.potential_energy(self.params.gravity)
    }

    /// Shepard-normalised SPH interpolation of the fluid pressure at `point`; `None` when no fluid particle is
    /// within 2h.
    pub fn sample_pressure(&self, point: [f64; 2]) -> Option<f64> {
        self.state.sample_pressure(&self.kernel, point)
    }

    /// Advances the fluid by `dt` (kick–drift–kick, see [`integrator`]).
    ///
    /// After an [`SphError::Unstable`] the state is part-way through the step and should not be advanced further.
    pub fn step(&mut self, dt: f64) -> Result<()> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(SphError::InvalidParameter {
                name: "dt",
                message: format!("must be a positive number, got {dt}"),
            });
        }
        let step_no = self.state.step + 1;
        // Kick.
        integrator::half_kick(&mut self.state.v, &self.scratch.accel, dt);
        // Density drifts with the positions: its rate uses v^{n+½} at both ends of the step (trapezoid in x).
        // A rate kept from the previous step (v^{n−½}) would make the acoustic modes grow.
        self.sync_fluid();
        let mut drho = std::mem::take(&mut self.scratch.drho);
        continuity::density_rates_into(&self.view(), &self.scratch.list, &self.kernel, &mut drho);
        self.scratch.drho = drho;
        integrator::half_kick_density(&mut self.state.rho, &self.scratch.drho, dt);
        // Drift (XSPH at the old positions with the half-step velocities).
        let mut corr = std::mem::take(&mut self.scratch.xsph);
        corr.clear();
        if self.params.xsph > 0.0 {
            self.sync_fluid();
            xsph::xsph_into(
                &self.view(),
                &self.scratch.list,
                &self.kernel,
                self.params.xsph,
                &mut corr,
            );
        }
        integrator::drift(&mut self.state.x, &self.state.v, &corr, dt);
        self.scratch.xsph = corr;
        self.check(step_no)?;
        self.rebuild_neighbors();
        // APD after the drift (§4.4; Xu et al. 2009, Eq. (35)), then the neighbours of the shifted positions.
        if self.options.apd > 0.0 {
            let v_max = self
                .state
                .v
                .par_iter()
                .map(|v| v[0].hypot(v[1]))
                .reduce(|| 0.0, f64::max);
            if v_max > 0.0 {
                self.sync_fluid();
                let apd_params = apd::ApdParams {
                    beta: self.options.apd,
                    v_max,
                    dt,
                };
                let mut shift = std::mem::take(&mut self.scratch.shift);
                apd::apd_into(&self.view(), &self.scratch.list, &self.kernel, &apd_params, &mut shift);
                // ρ follows the shift as the continuity equation would (see `apd::shift_density_change`).
                let mut drho = std::mem::take(&mut self.scratch.filtered);
                apd::shift_density_change_into(&self.view(), &self.scratch.list, &self.kernel, &shift, &mut drho);
                self.state.rho.iter_mut().zip(&drho).for_each(|(r, d)| *r += d);
                self.scratch.filtered = drho;
                integrator::drift(&mut self.state.x, &shift, &[], 1.0);
                self.scratch.shift = shift;
                self.check(step_no)?;
                self.rebuild_neighbors();
            }
        }
        // Rates at the new positions.
        self.sync_fluid();
        let mut drho = std::mem::take(&mut self.scratch.drho);
        continuity::density_rates_into(&self.view(), &self.scratch.list, &self.kernel, &mut drho);
        self.scratch.drho = drho;
        integrator::half_kick_density(&mut self.state.rho, &self.scratch.drho, dt);
        if let Some(n) = self.params.shepard_interval {
            if step_no % u64::from(n.max(1)) == 0 {
                self.sync_fluid();
                let mut filtered = std::mem::take(&mut self.scratch.filtered);
                if self.options.mls {
                    // §4.4 first-order MLS filter (Colagrossi & Landrini 2003, Eqs. (20)–(22))
                    mls::mls_into(&self.view(), &self.scratch.list, &self.kernel, &mut filtered);
                } else {
                    // §4.4 Shepard filter
                    density_filter::shepard_into(&self.view(), &self.scratch.list, &self.kernel, &mut filtered);
                }
                self.state.rho.copy_from_slice(&filtered);
                self.scratch.filtered = filtered;
            }
        }
        if let Some(i) = self.state.rho.iter().position(|r| !(r.is_finite() && *r > 0.0)) {
            return Err(self.unstable(step_no, i, format!("density {}", self.state.rho[i])));
        }
        self.update_pressure_and_acceleration();
        // Kick.
        integrator::half_kick(&mut self.state.v, &self.scratch.accel, dt);
        if let Some(i) = self
            .state
            .v
            .iter()
            .position(|v| !(v[0].is_finite() && v[1].is_finite()))
        {
            return Err(self.unstable(step_no, i, "non-finite velocity".into()));
        }
        self.state.t += dt;
        self.state.step = step_no;
        Ok(())
    }

    /// EOS, wall pressures (Adami) and accelerations for the current positions, densities and velocities.
    fn update_pressure_and_acceleration(&mut self) {
        let eos = self.eos;
        self.state
            .p
            .par_iter_mut()
            .zip(self.state.rho.par_iter())
            .for_each(|(p, &r)| *p = eos.pressure(r));
        self.sync_fluid();
        let mut wall = std::mem::take(&mut self.scratch.wall);
        adami::wall_pressures_into(
            &self.view(),
            &self.scratch.list,
            &self.kernel,
            self.params.gravity,
            &eos,
            &mut wall,
        );
        let nf = self.state.len();
        for (w, &(p, rho)) in wall.iter().enumerate() {
            self.walls.p[w] = p;
            self.walls.rho[w] = rho;
            self.scratch.p[nf + w] = p;
            self.scratch.rho[nf + w] = rho;
        }
        self.scratch.wall = wall;
        let params = MomentumParams {
            gravity: self.params.gravity,
            alpha: self.params.alpha,
            c0: self.params.c0,
            nu: self.params.nu,
        };
        let mut accel = std::mem::take(&mut self.scratch.accel);
        momentum::accelerations_into(&self.view(), &self.scratch.list, &self.kernel, &params, &mut accel);
        let k = self.options.central_force;
        if k != 0.0 {
            // Monaghan & Rafiee 2013: central body force f = −Ω² r
            accel.par_iter_mut().zip(self.state.x.par_iter()).for_each(|(a, x)| {
                a[0] -= k * x[0];
                a[1] -= k * x[1];
            });
        }
        self.scratch.accel = accel;
    }

    fn rebuild_neighbors(&mut self) {
        let s = &mut self.scratch;
        s.x.clear();
        s.x.extend_from_slice(&self.state.x);
        s.x.extend_from_slice(&self.walls.x);
        s.cells.rebuild(&s.x, self.kernel.support());
        s.list = s.cells.neighbor_list(&s.x, s.x.len(), self.kernel.support());
    }

    /// Copies the fluid's v, ρ, p into the combined arrays (x is copied by `rebuild_neighbors`).
    fn sync_fluid(&mut self) {
        let nf = self.state.len();
        let s = &mut self.scratch;
        s.v[..nf].copy_from_slice(&self.state.v);
        s.rho.clear();
        s.rho.extend_from_slice(&self.state.rho);
        s.rho.extend_from_slice(&self.walls.rho);
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
