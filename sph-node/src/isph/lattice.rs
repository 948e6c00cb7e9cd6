//! Test fixture: a particle at the origin of a square lattice (Δx = 1 cm, ρ0 = 1000 kg/m³, h = 1.3 Δx) and its
//! neighbours, for the rows and flags that the PPE builds from a particle's support.

use crate::kernel::CubicSpline;
use crate::particles::{separation, ParticleView};

/// The lattice's particles (the one at the origin first) and the origin's neighbours.
pub(crate) struct Lattice {
    pub(crate) dx: f64,
    pub(crate) rho0: f64,
    pub(crate) kernel: CubicSpline,
    x: Vec<[f64; 2]>,
    v: Vec<[f64; 2]>,
    rho: Vec<f64>,
    p: Vec<f64>,
    m: Vec<f64>,
    /// The neighbours of the particle at the origin (index 0).
    pub(crate) neighbors: Vec<u32>,
}

impl Lattice {
    /// Rows y = iy Δx for iy in `rows`, columns x = −5 Δx … 5 Δx, at rest.
    pub(crate) fn new(rows: std::ops::RangeInclusive<i32>) -> Self {
        let (dx, rho0) = (0.01, 1000.0);
        let kernel = CubicSpline::new(1.3 * dx);
        let mut x = vec![[0.0, 0.0]];
        for iy in rows {
            for ix in -5..=5 {
                if (ix, iy) != (0, 0) {
                    x.push([ix as f64 * dx, iy as f64 * dx]);
                }
            }
        }
        let n = x.len();
        let neighbors = (1..n as u32)
            .filter(|&j| separation(x[0], x[j as usize]).1 < kernel.support())
            .collect();
        Self {
            dx,
            rho0,
            kernel,
            v: vec![[0.0; 2]; n],
            rho: vec![rho0; n],
            p: vec![0.0; n],
            m: vec![rho0 * dx * dx; n],
            x,
            neighbors,
        }
    }

    /// All of it as fluid.
    pub(crate) fn view(&self) -> ParticleView<'_> {
        ParticleView {
            x: &self.x,
            v: &self.v,
            rho: &self.rho,
            p: &self.p,
            m: &self.m,
            n_fluid: self.x.len(),
        }
    }
}
