//! What a WCSPH solver tells about itself besides its state: energies, a pressure probe, neighbour pairs and the
//! memory it holds.

use super::WcsphSolver;

impl WcsphSolver {
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
            + sc.verlet.as_ref().map_or(0, |v| v.heap_bytes())
            + b(&sc.src)
            + b(&sc.per1)
            + b(&sc.per2)
            + b(&sc.shift)
            + b(&sc.wall)
            + b(&sc.edited_x)
    }
}
