//! [`WcsphSolver`]: the WCSPH pipeline of `DESIGN.md` §4.2 (Eqs. (9)–(12)) with Adami walls (§4.7), the Shepard
//! or first-order MLS density filter, XSPH and APD (§4.4), the optional δ-SPH density diffusion
//! ([`crate::wcsph::density_diffusion`]), advanced by kick–drift–kick.
//!
//! The solver owns the serializable [`FluidState`] and [`WallParticles`], a working copy of the particles sorted by
//! cell, and scratch that is rebuilt every step (cell bins, neighbour lists with the ∇W factor of each pair,
//! rates).
//!
//! Speed (`docs/PERFORMANCE.md`): the fluid is re-sorted by cell at every neighbour search, so that the gathers read
//! neighbouring memory; the neighbour lists are built once per search (fluid particles only: walls get their
//! pressure straight from the cell bins) with the ∇W factor of every pair, and reused by every pass until the next
//! search (r² and W, where a pass needs them, are recomputed from the positions, which the lists were built from:
//! 12 bytes per pair instead of 28). Every sum still runs over the same neighbours in the same order, with the
//! same arithmetic, as the plain gathers of [`continuity`], [`momentum`], [`adami`] and
//! [`crate::corrections::xsph`] on the id-ordered particles, so the results are bit-identical to theirs (tests
//! below) and independent of the thread count.
//!
//! One search per step: the APD shift (§4.4) is computed at xⁿ with the lists of the last search and applied with
//! the drift, x^{n+1} = xⁿ + Δt (v^{n+½} + XSPH) + δr (as DualSPHysics applies its shifting with the position
//! update). Shifting x^{n+1} after the drift, as the solver did before, needed a second search and sort per step:
//! a sixth of a step's time on the 20,000-particle dam break (docs/PERFORMANCE.md).

use cosim_proto::scene::{BoxSpec, DensityFilter, FluidSolver, Scene};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::boundary::repulsion::Repulsion;
use crate::boundary::{adami, walls};
use crate::corrections::{apd, density_filter, mls, xsph};
use crate::eos::Tait;
use crate::error::{Result, SphError};
use crate::integrator;
use crate::isph::wall_guard::WallBoxes;
use crate::kernel::CubicSpline;
use crate::neighbors::{NeighborList, SortedCells};
use crate::particles::{max_norm, FluidState, ParticleView, WallParticles};
use crate::setup;
use crate::time_step;
use crate::wcsph::{continuity, momentum, DensityDiffusion, MomentumParams};

mod restore;

/// Resolved parameters of the fluid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WcsphOptions {
    /// The density filter passes (every [`SphParams::shepard_interval`] steps) use the first-order MLS filter
    /// (Colagrossi & Landrini 2003) instead of Shepard's.
    pub mls: bool,
    /// APD β (0: off; §4.4, Xu et al. 2009).
    pub apd: f64,
    /// Central body force a = −k x (k = Ω², Monaghan & Rafiee 2013 oscillating drop); 0 for scenes.
    pub central_force: f64,
    /// δ of the δ-SPH density diffusion in the continuity equation (0: off; `fluid.density_diffusion`,
    /// [`crate::wcsph::density_diffusion`]).
    pub density_diffusion: f64,
    /// The density diffusion leaves out the hydrostatic correction of Fourtakas et al. 2019 (plain Molteni &
    /// Colagrossi 2009; tests and comparisons only, no scene key).
    pub density_diffusion_uncorrected: bool,
}

/// The particles as the gathers see them: the fluid sorted by cell (slot k holds particle `ids[k]`), then the
/// walls in their own order (they never move). The solver's working copy; [`FluidState`] keeps the id order.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct Sorted {
    x: Vec<[f64; 2]>,
    /// Velocities (zero for walls).
    v: Vec<[f64; 2]>,
    rho: Vec<f64>,
    p: Vec<f64>,
    m: Vec<f64>,
    /// m/ρ, for the continuity equation.
    vol: Vec<f64>,
    /// p/ρ², for the momentum equation.
    pr2: Vec<f64>,
    /// Particle id of each fluid slot.
    ids: Vec<u32>,
    /// Slot of each fluid particle id.
    slot: Vec<u32>,
    /// Accelerations of the fluid slots.
    accel: Vec<[f64; 2]>,
}

/// Scratch rebuilt every step: nothing here is state.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct Scratch {
    /// Cell bins (held inline: the solver is then about as large as the ISPH one, which `core::Fluid` may hold
    /// instead).
    cells: SortedCells,
    /// Fluid neighbour lists (slots) with ∇W factors.
    list: NeighborList,
    /// Old slot of each new slot (re-sorting).
    src: Vec<u32>,
    /// One value per particle, for whichever pass needs it at the time (never two at once): the density rate,
    /// the APD density change, the filtered density, the spare of the re-sort.
    per1: Vec<f64>,
    /// A vector per particle, likewise: the XSPH correction, the spare of the re-sort.
    per2: Vec<[f64; 2]>,
    /// The APD shift of each fluid particle (in use with the XSPH correction, for the same drift); empty when the
    /// step has none. Not kept in a checkpoint: it is computed and used within one step.
    #[serde(skip)]
    shift: Vec<[f64; 2]>,
    wall: Vec<(f64, f64)>,
    /// Positions (slot order) edited through `state_mut`, for the next drift; empty when none.
    edited_x: Vec<[f64; 2]>,
}

/// Weakly compressible SPH solver.
///
/// Internally the fluid particles are kept sorted by cell (see the module documentation); [`WcsphSolver::state`]
/// is in id order, written back after every step.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct WcsphSolver {
    params: SphParams,
    options: WcsphOptions,
    kernel: CubicSpline,
    eos: Tait,
    state: FluidState,
    walls: WallParticles,
    /// Accelerations in id order.
    accel: Vec<[f64; 2]>,
    sorted: Sorted,
    /// `state` was handed out mutably ([`WcsphSolver::state_mut`]): the next step re-reads it.
    state_edited: bool,
    /// Factor on the stable step of §4.2 (`fluid.cfl`, in (0, 1]; 1 unless the scene says otherwise).
    cfl: f64,
    /// The scene's wall boxes (none for a solver built by [`WcsphSolver::from_particles`]): the last line of
    /// defence against a fluid particle inside a wall (see [`WcsphSolver::wall_pushes`]).
    wall_boxes: WallBoxes,
    /// Fluid particles put back out of a wall, over the whole run and in the last step.
    wall_pushes: (u64, u64),
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
            // The scene's default is 0 for now: with β = 0.04 the 10 s still tank ends 8–11 % off the hydrostatic
            // pressure (the δ+-SPH shift fights the cubic spline's pairing mode; docs/CORRECTIONS.md).
            apd: spec.apd(),
            central_force: 0.0,
            density_diffusion: spec.density_diffusion,
            density_diffusion_uncorrected: false,
        };
        // The walls' boxes before the first accelerations: they carry the walls' repulsion (none unless a block
        // starts within its range).
        let boxes = WallBoxes::new(&scene.walls, dx, h, fluid_centre);
        let mut solver = Self::build(params, options, state, walls, boxes)?;
        solver.cfl = spec.cfl;
        Ok(solver)
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
        Self::build(params, options, state, walls, WallBoxes::default())
    }

    /// [`WcsphSolver::from_particles`] with the `[[wall]]` boxes of the scene (guard and repulsion).
    fn build(
        params: SphParams,
        options: WcsphOptions,
        state: FluidState,
        walls: WallParticles,
        wall_boxes: WallBoxes,
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
        let cat = |f: &[f64], w: &[f64]| -> Vec<f64> { f.iter().chain(w).copied().collect() };
        let m = cat(&state.m, &walls.m);
        let rho = cat(&state.rho, &walls.rho);
        let sorted = Sorted {
            x: state.x.iter().chain(&walls.x).copied().collect(),
            v: state
                .v
                .iter()
                .copied()
                .chain(std::iter::repeat_n([0.0; 2], nw))
                .collect(),
            p: cat(&state.p, &walls.p),
            vol: m.iter().zip(&rho).map(|(m, r)| m / r).collect(),
            pr2: vec![0.0; n + nw],
            rho,
            m,
            ids: (0..n as u32).collect(),
            slot: (0..n as u32).collect(),
            accel: vec![[0.0; 2]; n],
        };
        let scratch = Scratch {
            cells: SortedCells::new(&walls.x),
            ..Scratch::default()
        };
        let mut solver = Self {
            params,
            options,
            kernel,
            eos,
            state,
            walls,
            accel: vec![[0.0; 2]; n],
            sorted,
            state_edited: false,
            cfl: 1.0,
            wall_boxes,
            wall_pushes: (0, 0),
            scratch,
        };
        solver.check(0)?;
        solver.rebuild_neighbors();
        solver.update_pressure_and_acceleration();
        solver.write_back();
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

    /// Sets the δ of the density diffusion (0 disables it) and whether it keeps the hydrostatic correction, for the
    /// following steps (see [`WcsphOptions::density_diffusion`]).
    pub fn set_density_diffusion(&mut self, delta: f64, hydrostatic_correction: bool) {
        self.options.density_diffusion = delta;
        self.options.density_diffusion_uncorrected = !hydrostatic_correction;
    }

    /// The δ-SPH density diffusion in force, `None` when off.
    pub fn density_diffusion(&self) -> Option<DensityDiffusion> {
        let o = &self.options;
        let p = &self.params;
        (o.density_diffusion > 0.0).then(|| {
            if o.density_diffusion_uncorrected {
                DensityDiffusion::uncorrected(o.density_diffusion, p.h, p.c0)
            } else {
                DensityDiffusion::new(o.density_diffusion, p.h, p.c0, p.rho0, p.gravity)
            }
        })
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
    ///
    /// The next [`WcsphSolver::step`] takes v, ρ and p as they then are, changes ρ for the edited positions as
    /// the continuity equation would (see `density_follows_edits`), and drifts from the edited positions; as it
    /// always has, that step's first density rate and XSPH still use the positions and neighbours of the last
    /// neighbour search, and its first kick the accelerations of the last step. (m is not re-read.)
    pub fn state_mut(&mut self) -> &mut FluidState {
        self.state_edited = true;
        &mut self.state
    }

    /// The wall particles.
    pub fn walls(&self) -> &WallParticles {
        &self.walls
    }

    /// Fluid particles found strictly inside a `[[wall]]` box after a drift (or an APD shift) and put back just
    /// outside its nearest face, with the part of their velocity into the wall removed
    /// ([`WallBoxes::push_out`], the guard ISPH uses): (over the whole run, in the last step). Each particle
    /// counts once per drift that put it in a wall.
    ///
    /// A last line of defence, not the wall model: the Adami walls (§4.7) act only through the pressure, which
    /// mirrors the fluid's, so a layer pressed against a wall settles wherever its neighbourhood balances, on the
    /// face itself; the short-range repulsion of [`crate::boundary::repulsion`] keeps the water out. Before it, the
    /// guard put particles back 144,955 times in the tall dam break of `sph-node/tests/wall_guard.rs` and about
    /// 1,450 times in the hydrostatic plate scene; with it, none in either. Unguarded and without the repulsion,
    /// water seeped into the walls from t ≈ 0.19 s and a particle came out of the tank's back corner at 1.88 s.
    /// Runs in which no particle enters a wall are unchanged by the guard, bit for bit.
    pub fn wall_pushes(&self) -> (u64, u64) {
        self.wall_pushes
    }

    /// Acceleration of every fluid particle at the current time level.
    pub fn accelerations(&self) -> &[[f64; 2]] {
        &self.accel
    }

    /// Stable step of §4.2 for the current state, times the scene's `fluid.cfl` (1 by default, and for a
    /// solver built by [`WcsphSolver::from_particles`]).
    pub fn stable_dt(&self) -> f64 {
        // From the id-ordered copies, which also hold any edit made through `state_mut`.
        let v_max = max_norm(&self.state.v);
        let a_max = max_norm(&self.accel);
        self.cfl * time_step::stable_dt(self.params.h, self.params.c0, v_max, a_max, self.params.nu)
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

    /// Fluid–fluid and fluid–wall neighbour pairs (ordered: each pair counts for both fluid particles) of the
    /// current neighbour lists.
    pub fn pair_count(&self) -> usize {
        self.scratch.list.pair_count()
    }

    /// Bytes held by the solver's particle arrays, neighbour lists and scratch (capacities; the serializable
    /// state and walls included).
    pub fn heap_bytes(&self) -> usize {
        fn b<T>(v: &Vec<T>) -> usize {
            v.capacity() * std::mem::size_of::<T>()
        }
        let st = &self.state;
        let w = &self.walls;
        let so = &self.sorted;
        let sc = &self.scratch;
        b(&st.x)
            + b(&st.v)
            + b(&st.rho)
            + b(&st.p)
            + b(&st.m)
            + b(&w.x)
            + b(&w.p)
            + b(&w.rho)
            + b(&w.m)
            + b(&self.accel)
            + b(&so.x)
            + b(&so.v)
            + b(&so.rho)
            + b(&so.p)
            + b(&so.m)
            + b(&so.vol)
            + b(&so.pr2)
            + b(&so.ids)
            + b(&so.slot)
            + b(&so.accel)
            + sc.cells.heap_bytes()
            + sc.list.heap_bytes()
            + b(&sc.src)
            + b(&sc.per1)
            + b(&sc.per2)
            + b(&sc.shift)
            + b(&sc.wall)
            + b(&sc.edited_x)
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
        if std::mem::take(&mut self.state_edited) {
            self.read_state()?;
        }
        let result = self.advance(dt);
        self.write_back();
        result
    }

    /// Takes v, ρ and p from the id-ordered state into the sorted arrays after an edit through
    /// [`WcsphSolver::state_mut`], and keeps edited positions for the drift (`Scratch::edited_x`).
    fn read_state(&mut self) -> Result<()> {
        let st = &self.state;
        let nf = self.sorted.ids.len();
        if [st.x.len(), st.v.len(), st.rho.len(), st.p.len(), st.m.len()] != [nf; 5] {
            return Err(SphError::InvalidParameter {
                name: "state",
                message: format!("the solver has {nf} fluid particles; x, v, rho, p and m must keep that length"),
            });
        }
        let s = &mut self.sorted;
        let mut moved = false;
        for (id, &k) in s.slot.iter().enumerate() {
            let k = k as usize;
            moved |= s.x[k] != st.x[id];
            s.v[k] = st.v[id];
            s.rho[k] = st.rho[id];
            s.p[k] = st.p[id];
        }
        update_vol(&mut s.vol[..nf], &s.m[..nf], &s.rho[..nf]);
        let edited = &mut self.scratch.edited_x;
        edited.clear();
        if moved {
            edited.extend(s.ids.iter().map(|&id| st.x[id as usize]));
        }
        Ok(())
    }

    fn advance(&mut self, dt: f64) -> Result<()> {
        let step_no = self.state.step + 1;
        let nf = self.state.len();
        if !self.scratch.edited_x.is_empty() {
            self.density_follows_edits();
        }
        // Kick.
        integrator::half_kick(&mut self.sorted.v[..nf], &self.sorted.accel, dt);
        // Density drifts with the positions: its rate uses v^{n+½} at both ends of the step (trapezoid in x).
        // A rate kept from the previous step (v^{n−½}) would make the acoustic modes grow.
        self.density_half_kick(dt);
        // Drift (XSPH at the old positions with the half-step velocities).
        let mut corr = std::mem::take(&mut self.scratch.per2);
        corr.clear();
        if self.params.xsph > 0.0 {
            xsph::xsph_into(
                &self.view(),
                &self.scratch.list,
                &self.kernel,
                self.params.xsph,
                &mut corr,
            );
        }
        // APD (§4.4; Xu et al. 2009, Eq. (35)) at x^n, with the neighbours of the last search; the shift joins the
        // drift below, so that the positions are searched once a step (DualSPHysics applies its shifting with the
        // position update in the same way).
        let mut shift = std::mem::take(&mut self.scratch.shift);
        shift.clear();
        if self.options.apd > 0.0 {
            let v_max = max_norm(&self.sorted.v[..nf]);
            if v_max > 0.0 {
                let apd_params = apd::ApdParams {
                    beta: self.options.apd,
                    v_max,
                    dt,
                };
                apd::apd_pairs_into(
                    &self.view(),
                    &self.sorted.vol,
                    &self.scratch.list,
                    &self.kernel,
                    &apd_params,
                    &mut shift,
                );
                // ρ follows the shift as the continuity equation would (see `apd::shift_density_change`).
                self.density_follows_shift(&shift);
            }
        }
        let s = &mut self.sorted;
        if !self.scratch.edited_x.is_empty() {
            // Positions edited through `state_mut` since the last step: the drift starts from them.
            s.x[..nf].copy_from_slice(&self.scratch.edited_x);
            self.scratch.edited_x.clear();
        }
        integrator::drift(&mut s.x[..nf], &s.v[..nf], &corr, dt);
        if !shift.is_empty() {
            integrator::drift(&mut s.x[..nf], &shift, &[], 1.0);
        }
        self.scratch.per2 = corr;
        self.scratch.shift = shift;
        let pushes = self.push_out_of_walls();
        self.check(step_no)?;
        self.rebuild_neighbors();
        // Rates at the new positions.
        self.density_half_kick(dt);
        if let Some(n) = self.params.shepard_interval {
            if step_no % u64::from(n.max(1)) == 0 {
                let mut filtered = std::mem::take(&mut self.scratch.per1);
                if self.options.mls {
                    // §4.4 first-order MLS filter (Colagrossi & Landrini 2003, Eqs. (20)–(22))
                    mls::mls_into(&self.view(), &self.scratch.list, &self.kernel, &mut filtered);
                } else {
                    // §4.4 Shepard filter
                    density_filter::shepard_into(&self.view(), &self.scratch.list, &self.kernel, &mut filtered);
                }
                let s = &mut self.sorted;
                s.rho[..nf].copy_from_slice(&filtered);
                update_vol(&mut s.vol[..nf], &s.m[..nf], &s.rho[..nf]);
                self.scratch.per1 = filtered;
            }
        }
        if let Some(id) = self.first_bad(|s, k| !(s.rho[k].is_finite() && s.rho[k] > 0.0)) {
            let rho = self.sorted.rho[self.sorted.slot[id] as usize];
            return Err(self.unstable(step_no, id, format!("density {rho}")));
        }
        self.update_pressure_and_acceleration();
        // Kick.
        integrator::half_kick(&mut self.sorted.v[..nf], &self.sorted.accel, dt);
        if let Some(id) = self.first_bad(|s, k| !(s.v[k][0].is_finite() && s.v[k][1].is_finite())) {
            return Err(self.unstable(step_no, id, "non-finite velocity".into()));
        }
        self.state.t += dt;
        self.state.step = step_no;
        self.wall_pushes = (self.wall_pushes.0 + pushes, pushes);
        Ok(())
    }

    /// Puts every fluid particle found inside a wall box back out of it (see [`WcsphSolver::wall_pushes`]); how
    /// many. Particles outside the walls are not touched.
    fn push_out_of_walls(&mut self) -> u64 {
        let nf = self.state.len();
        let boxes = &self.wall_boxes;
        let s = &mut self.sorted;
        s.x[..nf]
            .par_iter_mut()
            .zip(s.v[..nf].par_iter_mut())
            .with_min_len(4096)
            .map(|(x, v)| u64::from(boxes.push_out(x, v)))
            .sum()
    }

    /// ρ follows the positions edited through [`WcsphSolver::state_mut`] (the contact's corrections, `DESIGN.md` §3
    /// step 5) as the continuity equation would follow the same displacement (Eq. (9) with δr for v Δt, as for the
    /// APD shift: [`apd::shift_density_change`]), at the positions and neighbours of the last search.
    ///
    /// Without it a position correction moves a particle without any change of density: the contact, which puts
    /// every particle it finds inside the structure back on the same line r_c in front of its face, stacked particles
    /// up in front of the elastic gate's tip at Δx = 5 mm (some 20 in a few mm², at pressures of a few kPa), until the
    /// stack blew apart and the energy guard stopped the run (`cosim/tests/stress.rs`,
    /// `coarse_elastic_gate_keeps_its_water_on_the_floor`).
    fn density_follows_edits(&mut self) {
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
    fn density_follows_shift(&mut self, shift: &[[f64; 2]]) {
        let nf = self.state.len();
        let mut drho = std::mem::take(&mut self.scratch.per1);
        apd::shift_density_change_pairs_into(&self.view(), &self.scratch.list, shift, &mut drho);
        let s = &mut self.sorted;
        s.rho[..nf].iter_mut().zip(&drho).for_each(|(r, d)| *r += d);
        update_vol(&mut s.vol[..nf], &s.m[..nf], &s.rho[..nf]);
        self.scratch.per1 = drho;
    }

    /// ρ += ½ Δt Dρ/Dt at the current positions and velocities (Eq. (9), with the δ-SPH diffusion when on).
    fn density_half_kick(&mut self, dt: f64) {
        let nf = self.state.len();
        let mut drho = std::mem::take(&mut self.scratch.per1);
        let diffusion = self.density_diffusion();
        let (view, vol, list) = (self.view(), &self.sorted.vol, &self.scratch.list);
        continuity::density_rates_pairs_into(&view, vol, list, diffusion.as_ref(), &mut drho);
        let s = &mut self.sorted;
        integrator::half_kick_density(&mut s.rho[..nf], &drho, dt);
        update_vol(&mut s.vol[..nf], &s.m[..nf], &s.rho[..nf]);
        self.scratch.per1 = drho;
    }

    /// EOS, wall pressures (Adami) and accelerations for the current positions, densities and velocities.
    fn update_pressure_and_acceleration(&mut self) {
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
            alpha: self.params.alpha,
            c0: self.params.c0,
            nu: self.params.nu,
        };
        let mut accel = std::mem::take(&mut self.sorted.accel);
        momentum::accelerations_pairs_into(
            &self.view(),
            &self.sorted.pr2,
            &self.scratch.list,
            &self.kernel,
            &params,
            &mut accel,
        );
        let k = self.options.central_force;
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
            Repulsion::new(self.params.dx, self.params.c0).add_into(&self.wall_boxes, &self.sorted.x[..nf], &mut accel);
        }
        self.sorted.accel = accel;
    }

    /// Re-sorts the fluid by cell for the current positions and rebuilds the neighbour lists.
    fn rebuild_neighbors(&mut self) {
        let nf = self.state.len();
        let s = &mut self.sorted;
        let sc = &mut self.scratch;
        sc.cells.sort(
            &s.x[..nf],
            &self.walls.x,
            self.kernel.support(),
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
        sc.cells.build_fluid_lists(&s.x, nf, &self.kernel, &mut sc.list);
    }

    /// Writes the fluid's x, v, ρ, p and accelerations back in id order.
    fn write_back(&mut self) {
        let s = &self.sorted;
        let st = &mut self.state;
        st.x.par_iter_mut()
            .zip(st.v.par_iter_mut())
            .zip(st.rho.par_iter_mut())
            .zip(st.p.par_iter_mut())
            .zip(self.accel.par_iter_mut())
            .zip(s.slot.par_iter())
            .with_min_len(1024)
            .for_each(|(((((x, v), rho), p), a), &k)| {
                let k = k as usize;
                *x = s.x[k];
                *v = s.v[k];
                *rho = s.rho[k];
                *p = s.p[k];
                *a = s.accel[k];
            });
    }

    fn view(&self) -> ParticleView<'_> {
        let s = &self.sorted;
        ParticleView {
            x: &s.x,
            v: &s.v,
            rho: &s.rho,
            p: &s.p,
            m: &s.m,
            n_fluid: self.state.len(),
        }
    }

    /// The lowest id of a fluid particle whose slot k satisfies `bad(sorted, k)`.
    fn first_bad(&self, bad: impl Fn(&Sorted, usize) -> bool + Sync) -> Option<usize> {
        let s = &self.sorted;
        (0..self.state.len())
            .into_par_iter()
            .with_min_len(4096)
            .filter(|&k| bad(s, k))
            .map(|k| s.ids[k] as usize)
            .min()
    }

    /// Non-finite or out-of-domain positions and velocities.
    fn check(&self, step: u64) -> Result<()> {
        let d = &self.params.domain;
        let finite =
            |x: [f64; 2], v: [f64; 2]| x[0].is_finite() && x[1].is_finite() && v[0].is_finite() && v[1].is_finite();
        let Some(id) = self.first_bad(|s, k| !(finite(s.x[k], s.v[k]) && d.contains(s.x[k]))) else {
            return Ok(());
        };
        let k = self.sorted.slot[id] as usize;
        let (x, v) = (self.sorted.x[k], self.sorted.v[k]);
        if !finite(x, v) {
            return Err(self.unstable(step, id, "non-finite position or velocity".into()));
        }
        Err(self.unstable(step, id, format!("left the domain at {x:?}")))
    }

    fn unstable(&self, step: u64, particle: usize, reason: String) -> SphError {
        SphError::Unstable { step, particle, reason }
    }
}

/// vol = m/ρ.
fn update_vol(vol: &mut [f64], m: &[f64], rho: &[f64]) {
    vol.par_iter_mut()
        .zip(m.par_iter())
        .zip(rho.par_iter())
        .with_min_len(4096)
        .for_each(|((v, m), r)| *v = m / r);
}

/// Moves the fluid slots of `a` (its first `src.len()` entries) to their new slots: a_new[n] = a[src[n]]; the
/// walls behind them stay.
fn permute<T: Copy + Default + Send + Sync>(a: &mut Vec<T>, spare: &mut Vec<T>, src: &[u32]) {
    let nf = src.len();
    spare.resize(a.len(), T::default()); // every entry is overwritten
    spare[..nf]
        .par_iter_mut()
        .zip(src.par_iter())
        .with_min_len(4096)
        .for_each(|(d, &k)| *d = a[k as usize]);
    spare[nf..].copy_from_slice(&a[nf..]);
    std::mem::swap(a, spare);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::adami::wall_pressure;
    use crate::corrections::xsph::xsph_correction;
    use crate::neighbors::CellList;
    use crate::particles::separation;
    use crate::wcsph::continuity::density_rate;
    use crate::wcsph::momentum::acceleration;

    fn dam_break(spacing: f64) -> WcsphSolver {
        dam_break_with(spacing, &[])
    }

    /// [`dam_break`] with more scene overrides.
    fn dam_break_with(spacing: f64, sets: &[&str]) -> WcsphSolver {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/dam_break.toml")).unwrap();
        let mut sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        sets.push(format!("fluid.spacing={spacing}"));
        let scene = cosim_proto::scene::parse("dam_break.toml", &text, &sets).unwrap();
        let mut solver = WcsphSolver::new(&scene).unwrap();
        for _ in 0..60 {
            let dt = solver.stable_dt();
            solver.step(dt).unwrap();
        }
        solver
    }

    fn bits(a: &[[f64; 2]]) -> Vec<[u64; 2]> {
        a.iter().map(|a| a.map(f64::to_bits)).collect()
    }

    /// The sorted lists with precomputed ∇W factors give, bit for bit, what the reference gathers give on the
    /// lists of a plain cell list over the same (sorted) particles: same neighbours in the same order, same
    /// continuity, momentum, wall pressure and XSPH.
    #[test]
    fn fast_passes_equal_the_reference_gathers() {
        let solver = dam_break(0.005);
        let view = solver.view();
        let kernel = solver.kernel;
        let nf = view.n_fluid;
        assert!(
            view.v[..nf].iter().any(|v| v[0].abs() > 1e-3),
            "the column must be moving"
        );
        let cells = CellList::new(view.x, kernel.support());
        let reference = cells.neighbor_list(view.x, view.x.len(), kernel.support());
        let list = &solver.scratch.list;
        for i in 0..nf {
            assert_eq!(list.of(i), reference.of(i), "neighbours of slot {i}");
        }
        let mut drho = Vec::new();
        continuity::density_rates_pairs_into(&view, &solver.sorted.vol, list, None, &mut drho);
        for (i, d) in drho.iter().enumerate() {
            assert_eq!(d.to_bits(), density_rate(i, &view, reference.of(i), &kernel).to_bits());
        }
        let params = MomentumParams {
            gravity: solver.params.gravity,
            alpha: solver.params.alpha,
            c0: solver.params.c0,
            nu: solver.params.nu,
        };
        assert!(params.nu > 0.0 && params.alpha > 0.0);
        let mut accel = Vec::new();
        momentum::accelerations_pairs_into(&view, &solver.sorted.pr2, list, &kernel, &params, &mut accel);
        let expected: Vec<_> = (0..nf)
            .map(|i| acceleration(i, &view, reference.of(i), &kernel, &params))
            .collect();
        assert_eq!(bits(&accel), bits(&expected));
        let mut xsph = Vec::new();
        xsph::xsph_into(&view, list, &kernel, 0.5, &mut xsph);
        let expected: Vec<_> = (0..nf)
            .map(|i| xsph_correction(i, &view, reference.of(i), &kernel, 0.5))
            .collect();
        assert_eq!(bits(&xsph), bits(&expected));
        let mut wall = Vec::new();
        let g = solver.params.gravity;
        adami::wall_pressures_sorted_into(&view, &solver.scratch.cells, &kernel, g, &solver.eos, &mut wall);
        assert!(wall.iter().any(|w| w.0 > 0.0));
        for (w, &(p, rho)) in wall.iter().enumerate() {
            let (ep, erho) = wall_pressure(nf + w, &view, reference.of(nf + w), &kernel, g, &solver.eos);
            assert_eq!((p.to_bits(), rho.to_bits()), (ep.to_bits(), erho.to_bits()), "wall {w}");
        }
    }

    /// Edits through `state_mut` reach the sorted working copy: handing the state out without changing it leaves
    /// the run bit-identical, and the drift starts from an edited position.
    #[test]
    fn state_edits_are_taken() {
        // Without APD: its shift of particle 0 depends on where its neighbours are, which the edit moves too.
        let mut a = dam_break_with(0.01, &["fluid.apd=0"]);
        let mut b = a.clone();
        let _ = b.state_mut();
        for _ in 0..20 {
            let dt = a.stable_dt();
            a.step(dt).unwrap();
            b.step(dt).unwrap();
        }
        assert_eq!(a.state(), b.state());
        // Move particle 0: the step's first density rate and XSPH use the last search's positions, as they
        // always have, and the drift starts from the edited one; the densities of particle 0 and its neighbours
        // follow the move (`density_follows_edits`), and the step's first density rate carries that 2h further,
        // which changes the XSPH of the particles within 2h of those (2.4e-10 m for particle 0 here): particle 0
        // lands 1e-4 m further, and every particle beyond 6h lands where it did.
        let x0 = a.state().x[0];
        a.state_mut().x[0] = [x0[0] + 1e-4, x0[1]];
        let dt = a.stable_dt();
        a.step(dt).unwrap();
        b.step(dt).unwrap();
        let (xa, xb) = (&a.state().x, &b.state().x);
        assert!((xa[0][0] - xb[0][0] - 1e-4).abs() < 1e-8 && (xa[0][1] - xb[0][1]).abs() < 1e-8);
        let far = 3.0 * a.kernel.support();
        let beyond: Vec<usize> = (1..xa.len()).filter(|&i| separation(xb[i], x0).1 > far).collect();
        assert!(beyond.len() > xa.len() / 2);
        assert!(beyond.iter().all(|&i| xa[i] == xb[i]));
        assert_ne!(a.state().v, b.state().v);
        // The neighbour lists are those of the new positions.
        let list = &a.scratch.list;
        let view = a.view();
        let cells = CellList::new(view.x, a.kernel.support());
        let reference = cells.neighbor_list(view.x, view.x.len(), a.kernel.support());
        assert!((0..view.n_fluid).all(|i| list.of(i) == reference.of(i)));
    }

    /// A position edit raises the density of a particle moved towards its neighbours as the continuity equation
    /// would (`density_follows_edits`): the top particle of the column, whose neighbours all lie below it, moved
    /// down by Δx/100 gains δρ = Σ_j m_j δr·∇W_ij, within 2 % (the rest of the difference is the step's own
    /// continuity at the two positions).
    #[test]
    fn a_position_edit_moves_the_density() {
        let mut a = dam_break(0.01);
        let mut b = a.clone();
        let top = (0..a.state().len())
            .max_by(|&i, &j| a.state().x[i][1].total_cmp(&a.state().x[j][1]))
            .unwrap();
        let dy = -1e-4;
        let expected = {
            let view = a.view();
            let k = a.sorted.slot[top] as usize;
            let mut shift = vec![[0.0; 2]; view.n_fluid];
            shift[k] = [0.0, dy];
            apd::shift_density_change(k, &view, a.scratch.list.of(k), &a.kernel, &shift)
        };
        assert!(expected > 1.0, "the top particle is compressed: {expected}");
        let x = a.state().x[top];
        a.state_mut().x[top] = [x[0], x[1] + dy];
        let dt = 1e-6;
        a.step(dt).unwrap();
        b.step(dt).unwrap();
        let gained = a.state().rho[top] - b.state().rho[top];
        assert!(
            (gained - expected).abs() < 0.02 * expected,
            "gained {gained}, expected {expected}"
        );
    }

    /// The solver as it was before the cell-sorted pipeline (id order, plain gathers over a cell list of all
    /// particles, every kernel value computed where it is used), reduced to what a comparison needs.
    struct Reference {
        params: SphParams,
        options: WcsphOptions,
        kernel: CubicSpline,
        eos: Tait,
        state: FluidState,
        walls: WallParticles,
        x: Vec<[f64; 2]>,
        v: Vec<[f64; 2]>,
        rho: Vec<f64>,
        p: Vec<f64>,
        m: Vec<f64>,
        list: NeighborList,
        accel: Vec<[f64; 2]>,
        boxes: WallBoxes,
    }

    impl Reference {
        fn new(
            params: SphParams,
            options: WcsphOptions,
            state: FluidState,
            walls: WallParticles,
            boxes: WallBoxes,
        ) -> Self {
            let n = state.len() + walls.len();
            let mut r = Self {
                kernel: CubicSpline::new(params.h),
                eos: Tait::new(params.rho0, params.c0),
                params,
                options,
                m: state.m.iter().chain(&walls.m).copied().collect(),
                v: vec![[0.0; 2]; n],
                state,
                walls,
                x: Vec::new(),
                rho: Vec::new(),
                p: Vec::new(),
                list: NeighborList::default(),
                accel: Vec::new(),
                boxes,
            };
            r.rebuild();
            r.update();
            r
        }

        fn view(&self) -> ParticleView<'_> {
            ParticleView {
                x: &self.x,
                v: &self.v,
                rho: &self.rho,
                p: &self.p,
                m: &self.m,
                n_fluid: self.state.len(),
            }
        }

        fn sync(&mut self) {
            let nf = self.state.len();
            self.v[..nf].copy_from_slice(&self.state.v);
            self.rho = self.state.rho.iter().chain(&self.walls.rho).copied().collect();
            self.p = self.state.p.iter().chain(&self.walls.p).copied().collect();
        }

        fn rebuild(&mut self) {
            self.x = self.state.x.iter().chain(&self.walls.x).copied().collect();
            let cells = CellList::new(&self.x, self.kernel.support());
            self.list = cells.neighbor_list(&self.x, self.x.len(), self.kernel.support());
        }

        fn continuity(&mut self, dt: f64) {
            self.sync();
            let view = self.view();
            let drho: Vec<f64> = (0..view.n_fluid)
                .map(|i| density_rate(i, &view, self.list.of(i), &self.kernel))
                .collect();
            integrator::half_kick_density(&mut self.state.rho, &drho, dt);
        }

        fn update(&mut self) {
            let eos = self.eos;
            self.state.p = self.state.rho.iter().map(|&r| eos.pressure(r)).collect();
            self.sync();
            let nf = self.state.len();
            let view = self.view();
            let g = self.params.gravity;
            let wall: Vec<_> = (nf..view.x.len())
                .map(|w| wall_pressure(w, &view, self.list.of(w), &self.kernel, g, &eos))
                .collect();
            for (w, &(p, rho)) in wall.iter().enumerate() {
                (self.walls.p[w], self.walls.rho[w]) = (p, rho);
                (self.p[nf + w], self.rho[nf + w]) = (p, rho);
            }
            let params = MomentumParams {
                gravity: g,
                alpha: self.params.alpha,
                c0: self.params.c0,
                nu: self.params.nu,
            };
            let view = self.view();
            self.accel = (0..nf)
                .map(|i| acceleration(i, &view, self.list.of(i), &self.kernel, &params))
                .collect();
            let k = self.options.central_force;
            let repulsion = Repulsion::new(self.params.dx, self.params.c0);
            for (a, x) in self.accel.iter_mut().zip(&self.state.x) {
                if k != 0.0 {
                    a[0] -= k * x[0];
                    a[1] -= k * x[1];
                }
                let r = repulsion.acceleration(&self.boxes, *x);
                a[0] += r[0];
                a[1] += r[1];
            }
        }

        fn step(&mut self, dt: f64) {
            let step_no = self.state.step + 1;
            let nf = self.state.len();
            if self.state.x[..] != self.x[..nf] {
                // Edited positions: ρ follows them as the continuity equation would.
                let shift: Vec<[f64; 2]> = (0..nf)
                    .map(|i| [self.state.x[i][0] - self.x[i][0], self.state.x[i][1] - self.x[i][1]])
                    .collect();
                self.sync();
                let view = self.view();
                let drho: Vec<f64> = (0..nf)
                    .map(|i| apd::shift_density_change(i, &view, self.list.of(i), &self.kernel, &shift))
                    .collect();
                self.state.rho.iter_mut().zip(&drho).for_each(|(r, d)| *r += d);
            }
            integrator::half_kick(&mut self.state.v, &self.accel, dt);
            self.continuity(dt);
            let mut corr = Vec::new();
            if self.params.xsph > 0.0 {
                self.sync();
                let view = self.view();
                corr = (0..view.n_fluid)
                    .map(|i| xsph_correction(i, &view, self.list.of(i), &self.kernel, self.params.xsph))
                    .collect();
            }
            let mut shift = Vec::new();
            if self.options.apd > 0.0 {
                let v_max = self.state.v.iter().map(|v| v[0].hypot(v[1])).fold(0.0, f64::max);
                if v_max > 0.0 {
                    self.sync();
                    let ap = apd::ApdParams {
                        beta: self.options.apd,
                        v_max,
                        dt,
                    };
                    let mut drho = Vec::new();
                    apd::apd_into(&self.view(), &self.list, &self.kernel, &ap, &mut shift);
                    apd::shift_density_change_into(&self.view(), &self.list, &self.kernel, &shift, &mut drho);
                    self.state.rho.iter_mut().zip(&drho).for_each(|(r, d)| *r += d);
                }
            }
            integrator::drift(&mut self.state.x, &self.state.v, &corr, dt);
            if !shift.is_empty() {
                integrator::drift(&mut self.state.x, &shift, &[], 1.0);
            }
            self.rebuild();
            self.continuity(dt);
            if let Some(n) = self.params.shepard_interval {
                if step_no % u64::from(n.max(1)) == 0 {
                    self.sync();
                    let mut filtered = Vec::new();
                    if self.options.mls {
                        mls::mls_into(&self.view(), &self.list, &self.kernel, &mut filtered);
                    } else {
                        density_filter::shepard_into(&self.view(), &self.list, &self.kernel, &mut filtered);
                    }
                    self.state.rho = filtered;
                }
            }
            self.update();
            integrator::half_kick(&mut self.state.v, &self.accel, dt);
            self.state.t += dt;
            self.state.step = step_no;
        }
    }

    /// Over a run with MLS, APD, viscosity, XSPH and edits through `state_mut` (positions and velocities of some
    /// particles, as the contact corrections make), the solver stays bit-identical to the reference: state, wall
    /// pressures and accelerations after every step, with 1 and 2 threads.
    #[test]
    fn equals_the_reference_solver_bit_for_bit() {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/dam_break.toml")).unwrap();
        let overrides = [
            "fluid.spacing=0.005".to_string(),
            "fluid.density_filter=\"mls\"".to_string(),
            "fluid.density_filter_interval=7".to_string(),
        ];
        let scene = cosim_proto::scene::parse("dam_break.toml", &text, &overrides).unwrap();
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut solver = WcsphSolver::new(&scene).unwrap();
                solver.set_apd(0.05);
                let mut reference = Reference::new(
                    solver.params.clone(),
                    solver.options.clone(),
                    solver.state.clone(),
                    solver.walls.clone(),
                    solver.wall_boxes.clone(),
                );
                for step in 0..150 {
                    if step % 25 == 10 {
                        for i in (0..solver.state.len()).step_by(97) {
                            let kick = [1e-3 * (i % 7) as f64, -2e-3];
                            let shift = [1e-5 * (i % 3) as f64, 1e-5];
                            for st in [solver.state_mut(), &mut reference.state] {
                                st.v[i] = [st.v[i][0] + kick[0], st.v[i][1] + kick[1]];
                                st.x[i] = [st.x[i][0] + shift[0], st.x[i][1] + shift[1]];
                            }
                        }
                    }
                    let dt = solver.stable_dt();
                    solver.step(dt).unwrap();
                    reference.step(dt);
                    assert!(
                        solver.state == reference.state,
                        "state after step {step}, {threads} threads"
                    );
                    assert_eq!(solver.walls, reference.walls, "walls after step {step}");
                    assert_eq!(
                        bits(&solver.accel),
                        bits(&reference.accel),
                        "accelerations after step {step}"
                    );
                }
                assert!(
                    solver.state.v.iter().any(|v| v[0].abs() > 1e-2),
                    "the column must be moving"
                );
            });
        }
    }
}
