//! [`WcsphSolver`]: the WCSPH pipeline of `DESIGN.md` §4.2 (Eqs. (9)–(12)) with Adami walls (§4.7), the Shepard
//! or first-order MLS density filter, XSPH and APD (§4.4), the optional δ-SPH density diffusion
//! ([`crate::wcsph::density_diffusion`]), advanced by kick–drift–kick.
//!
//! The solver owns the serializable [`FluidState`] and [`WallParticles`], a working copy of the particles sorted by
//! cell (`wcsph/sorted.rs`), and scratch that is rebuilt every step (cell bins, neighbour lists with the ∇W
//! factor of each pair, rates) and never saved (`solver/restore.rs`). The step is [`WcsphSolver::step`] below; its passes
//! over the sorted particles are in `solver/passes.rs`.
//!
//! Speed (`docs/PERFORMANCE.md`): the fluid is re-sorted by cell at every neighbour search, so that the gathers read
//! neighbouring memory; the neighbour lists are built once per search (fluid particles only: walls get their
//! pressure straight from the cell bins) with the ∇W factor of every pair, and reused by every pass until the next
//! search (r² and W, where a pass needs them, are recomputed from the positions, which the lists were built from:
//! 12 bytes per pair instead of 28). Every sum still runs over the same neighbours in the same order, with the
//! same arithmetic, as plain gathers of [`crate::wcsph::continuity`], [`crate::wcsph::momentum`],
//! [`crate::boundary::adami`] and [`crate::corrections::xsph`] on the id-ordered particles, so the results are
//! bit-identical to theirs (`tests.rs`) and independent of the thread count.
//!
//! One search per step: the APD shift (§4.4) is computed at xⁿ with the lists of the last search and applied with
//! the drift, x^{n+1} = xⁿ + Δt (v^{n+½} + XSPH) + δr (as DualSPHysics applies its shifting with the position
//! update). Shifting x^{n+1} after the drift, as the solver did before, needed a second search and sort per step:
//! a sixth of a step's time on the 20,000-particle dam break (docs/PERFORMANCE.md).
//!
//! Three passes over the pairs per step besides the search (issue 20): at xⁿ the density rate, XSPH and the APD
//! shift together (`drift_pass.rs`); at x^{n+1}, the density rate with the shift's density change, each particle's
//! taken as soon as the search has built its list (`passes.rs`, `rebuild_neighbors_and_density`); then the
//! momentum equation.

use cosim_proto::scene::{FluidSolver as SceneSolver, Scene};
use rayon::prelude::*;

use crate::boundary::wall_guard::WallBoxes;
use crate::corrections::{apd, density_filter, mls};
use crate::eos::Tait;
use crate::error::{Result, SphError};
use crate::integrator;
use crate::kernel::CubicSpline;
use crate::neighbors::{NeighborList, SortedCells, VerletCandidates};
use crate::params::SphParams;
use crate::particles::{max_norm, FluidState, ParticleView, WallParticles};
use crate::setup::{self, FluidSetup};
use crate::time_step;
use crate::wcsph::drift_pass::{self, DriftPass};
use crate::wcsph::params::WcsphParams;
use crate::wcsph::sorted::{update_vol, Sorted};
use crate::wcsph::DensityDiffusion;

mod diagnostics;
mod fluid_solver;
mod passes;
mod restore;
#[cfg(test)]
mod tests;

/// Scratch rebuilt every step: nothing here is state.
#[derive(Clone, Debug, Default)]
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
    /// The APD shift of each fluid particle, from the drift pass until its density change is taken after the search
    /// (`rebuild_neighbors_and_density`, which empties it); empty when the step has none.
    shift: Vec<[f64; 2]>,
    wall: Vec<(f64, f64)>,
    /// Positions (slot order) edited through `state_mut`, for the next drift; empty when none.
    edited_x: Vec<[f64; 2]>,
    /// Verlet candidate lists, when on (`fluid.verlet_skin` > 0).
    verlet: Option<VerletCandidates>,
}

/// Weakly compressible SPH solver.
///
/// Internally the fluid particles are kept sorted by cell (see the module documentation); [`WcsphSolver::state`]
/// is in id order, written back after every step.
#[derive(Clone, Debug)]
pub struct WcsphSolver {
    params: SphParams,
    /// What only WCSPH uses (sound speed, artificial viscosity, density filter, APD, δ-SPH).
    wcsph: WcsphParams,
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
    /// Builds particles and walls from the scene ([`FluidSetup`]) and evaluates the initial rates.
    pub fn new(scene: &Scene) -> Result<Self> {
        let spec = setup::fluid_spec(scene, SceneSolver::Wcsph)?;
        let wcsph = WcsphParams::from_scene(spec, scene.run.gravity)?;
        let eos = Tait::new(spec.density, wcsph.c0);
        let set = FluidSetup::new(scene, spec, &eos, 0.0);
        // The walls' boxes before the first accelerations: they carry the walls' repulsion (none unless a block
        // starts within its range).
        let mut solver = Self::build(set.params, wcsph, set.state, set.walls, set.wall_boxes)?;
        solver.cfl = spec.cfl;
        Ok(solver)
    }

    /// A solver on given particles (tests, e.g. the oscillating drop, whose circle the scene's blocks cannot
    /// describe): the Tait law follows from `params.rho0` and `wcsph.c0`, the kernel from `params.h`. The
    /// state's ρ and v are taken as given (p is recomputed from ρ); wall p and ρ are re-extrapolated.
    pub fn from_particles(
        params: SphParams,
        wcsph: WcsphParams,
        state: FluidState,
        walls: WallParticles,
    ) -> Result<Self> {
        Self::build(params, wcsph, state, walls, WallBoxes::default())
    }

    /// [`WcsphSolver::from_particles`] with the `[[wall]]` boxes of the scene (guard and repulsion).
    fn build(
        params: SphParams,
        wcsph: WcsphParams,
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
        let eos = Tait::new(params.rho0, wcsph.c0);
        let kernel = CubicSpline::new(params.h);
        let sorted = Sorted::new(&state, &walls);
        let scratch = Scratch {
            cells: SortedCells::new(&walls.x),
            verlet: verlet_candidates(&wcsph, &params),
            ..Scratch::default()
        };
        let mut solver = Self {
            params,
            wcsph,
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
        solver.sorted.write_back(&mut solver.state, &mut solver.accel);
        Ok(solver)
    }

    /// Resolved parameters shared with the other solvers.
    pub fn params(&self) -> &SphParams {
        &self.params
    }

    /// What only WCSPH uses (sound speed, artificial viscosity, density filter kind, APD β, central force, δ-SPH).
    pub fn wcsph_params(&self) -> &WcsphParams {
        &self.wcsph
    }

    /// Sets the APD β (§4.4; 0 disables) for the following steps.
    pub fn set_apd(&mut self, beta: f64) {
        self.wcsph.apd = beta;
    }

    /// Sets the δ of the density diffusion (0 disables it) and whether it keeps the hydrostatic correction, for the
    /// following steps (see [`WcsphParams::density_diffusion`]).
    pub fn set_density_diffusion(&mut self, delta: f64, hydrostatic_correction: bool) {
        self.wcsph.density_diffusion = delta;
        self.wcsph.density_diffusion_uncorrected = !hydrostatic_correction;
    }

    /// The δ-SPH density diffusion in force, `None` when off.
    pub fn density_diffusion(&self) -> Option<DensityDiffusion> {
        let o = &self.wcsph;
        let p = &self.params;
        (o.density_diffusion > 0.0).then(|| {
            if o.density_diffusion_uncorrected {
                DensityDiffusion::uncorrected(o.density_diffusion, p.h, o.c0)
            } else {
                DensityDiffusion::new(o.density_diffusion, p.h, o.c0, p.rho0, p.gravity)
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
    /// Stable step of §4.2 for the current state, times the scene's `fluid.cfl` (1 by default, and for a
    /// solver built by [`WcsphSolver::from_particles`]).
    pub fn stable_dt(&self) -> f64 {
        // From the id-ordered copies, which also hold any edit made through `state_mut`.
        let v_max = max_norm(&self.state.v);
        let a_max = max_norm(&self.accel);
        self.cfl * time_step::stable_dt(self.params.h, self.wcsph.c0, v_max, a_max, self.params.nu)
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
        self.sorted.write_back(&mut self.state, &mut self.accel);
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
        // One pass over the pairs at xⁿ with v^{n+½} (drift_pass.rs): the density rate (its half kick below; the
        // rate uses v^{n+½} at both ends of the step, a trapezoid in x: a rate kept from the previous step,
        // v^{n−½}, would make the acoustic modes grow), XSPH for the drift, and APD (§4.4; Sun et al. 2017) with the
        // neighbours of the last search. The shift joins the drift, so that the positions are searched once a step
        // (DualSPHysics applies its shifting with the position update in the same way); its density change is
        // taken with the rate at the new positions.
        let mut rate = std::mem::take(&mut self.scratch.per1);
        let mut corr = std::mem::take(&mut self.scratch.per2);
        let mut shift = std::mem::take(&mut self.scratch.shift);
        let v_max = if self.wcsph.apd > 0.0 {
            max_norm(&self.sorted.v[..nf])
        } else {
            0.0
        };
        let apd_params = (v_max > 0.0).then_some(apd::ApdParams {
            beta: self.wcsph.apd,
            v_max,
            dt,
        });
        let diffusion = self.density_diffusion();
        let view = self.view();
        let pass = DriftPass {
            view: &view,
            vol: &self.sorted.vol,
            kernel: &self.kernel,
            diffusion: diffusion.as_ref(),
            apd: apd_params.as_ref(),
            xsph: self.params.xsph,
        };
        drift_pass::drift_pass_into(&pass, &self.scratch.list, &mut rate, &mut shift, &mut corr);
        let s = &mut self.sorted;
        integrator::half_kick_density(&mut s.rho[..nf], &rate, dt);
        update_vol(&mut s.vol[..nf], &s.m[..nf], &s.rho[..nf]);
        self.scratch.per1 = rate;
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
        // The search at the new positions, and with it the density's half kick there (its rate at the new
        // positions with v^{n+½}), with the density change of the shift (`apd::shift_density_change`).
        self.rebuild_neighbors_and_density(dt);
        if let Some(n) = self.wcsph.shepard_interval {
            if step_no % u64::from(n.max(1)) == 0 {
                let mut filtered = std::mem::take(&mut self.scratch.per1);
                if self.wcsph.mls {
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

    fn view(&self) -> ParticleView<'_> {
        self.sorted.view(self.state.len())
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

/// The Verlet candidate lists of `wcsph.verlet_skin` (units of `params.h`), `None` when it is 0.
fn verlet_candidates(wcsph: &WcsphParams, params: &SphParams) -> Option<VerletCandidates> {
    (wcsph.verlet_skin > 0.0).then(|| VerletCandidates::new(wcsph.verlet_skin * params.h))
}
