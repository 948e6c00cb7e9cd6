//! The WCSPH solver as it was before the cell-sorted pipeline, for `equals_the_reference_solver_bit_for_bit`.

use super::*;

/// The solver as it was before the cell-sorted pipeline (id order, plain gathers over a cell list of all
/// particles, every kernel value computed where it is used), reduced to what a comparison needs.
pub(super) struct Reference {
    params: SphParams,
    wcsph: WcsphParams,
    kernel: CubicSpline,
    eos: Tait,
    pub(super) state: FluidState,
    pub(super) walls: WallParticles,
    x: Vec<[f64; 2]>,
    v: Vec<[f64; 2]>,
    rho: Vec<f64>,
    p: Vec<f64>,
    m: Vec<f64>,
    list: NeighborList,
    pub(super) accel: Vec<[f64; 2]>,
    boxes: WallBoxes,
}

impl Reference {
    pub(super) fn new(
        params: SphParams,
        wcsph: WcsphParams,
        state: FluidState,
        walls: WallParticles,
        boxes: WallBoxes,
    ) -> Self {
        let n = state.len() + walls.len();
        let mut r = Self {
            kernel: CubicSpline::new(params.h),
            eos: Tait::new(params.rho0, wcsph.c0),
            params,
            wcsph,
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
        let vol = volumes(&view);
        let drho: Vec<f64> = (0..view.n_fluid)
            .map(|i| density_rate(i, &view, &vol, self.list.of(i), &self.kernel))
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
            alpha: self.wcsph.alpha,
            c0: self.wcsph.c0,
            nu: self.params.nu,
        };
        let view = self.view();
        let pr2 = pr2_of(&view);
        self.accel = (0..nf)
            .map(|i| acceleration(i, &view, &pr2, self.list.of(i), &self.kernel, &params))
            .collect();
        let k = self.wcsph.central_force;
        let repulsion = Repulsion::new(self.params.dx, self.wcsph.c0);
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

    pub(super) fn step(&mut self, dt: f64) {
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
        // XSPH and APD at xⁿ with ρⁿ, before the density's half kick (drift_pass.rs).
        self.sync();
        let mut corr = Vec::new();
        if self.params.xsph > 0.0 {
            let view = self.view();
            corr = (0..view.n_fluid)
                .map(|i| xsph_correction(i, &view, self.list.of(i), &self.kernel, self.params.xsph))
                .collect();
        }
        let mut shift = Vec::new();
        if self.wcsph.apd > 0.0 {
            let v_max = self.state.v.iter().map(|v| v[0].hypot(v[1])).fold(0.0, f64::max);
            if v_max > 0.0 {
                let ap = apd::ApdParams {
                    beta: self.wcsph.apd,
                    v_max,
                    dt,
                };
                apd::apd_into(&self.view(), &self.list, &self.kernel, &ap, &mut shift);
            }
        }
        self.continuity(dt);
        integrator::drift(&mut self.state.x, &self.state.v, &corr, dt);
        if !shift.is_empty() {
            integrator::drift(&mut self.state.x, &shift, &[], 1.0);
        }
        self.rebuild();
        if shift.is_empty() {
            self.continuity(dt);
        } else {
            // The rate at the new positions with the shift's density change, added together.
            self.sync();
            let view = self.view();
            let vol = volumes(&view);
            let inc: Vec<f64> = (0..view.n_fluid)
                .map(|i| {
                    let rate = density_rate(i, &view, &vol, self.list.of(i), &self.kernel);
                    0.5 * dt * rate + apd::shift_density_change(i, &view, self.list.of(i), &self.kernel, &shift)
                })
                .collect();
            self.state.rho.iter_mut().zip(&inc).for_each(|(r, d)| *r += d);
        }
        if let Some(n) = self.wcsph.shepard_interval {
            if step_no % u64::from(n.max(1)) == 0 {
                self.sync();
                let mut filtered = Vec::new();
                if self.wcsph.mls {
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
