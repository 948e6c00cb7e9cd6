//! The particles as the WCSPH gathers see them: the fluid sorted by cell, then the walls (`Sorted`), with the
//! re-sort's permutation of the arrays (`permute`) and the write-back to id order (`Sorted::write_back`).
//!
//! The order is a function of the positions alone ([`crate::neighbors::SortedCells::sort`]: by cell, then id), so a
//! solver rebuilds it from the id-ordered state (a checkpoint does not hold it).

use rayon::prelude::*;

use crate::particles::{FluidState, ParticleView, WallParticles};

/// The particles as the gathers see them: the fluid sorted by cell (slot k holds particle `ids[k]`), then the
/// walls in their own order (they never move). The solver's working copy; [`FluidState`] keeps the id order.
#[derive(Clone, Debug, Default)]
pub(super) struct Sorted {
    pub(super) x: Vec<[f64; 2]>,
    /// Velocities (zero for walls).
    pub(super) v: Vec<[f64; 2]>,
    pub(super) rho: Vec<f64>,
    pub(super) p: Vec<f64>,
    pub(super) m: Vec<f64>,
    /// m/ρ, for the continuity equation.
    pub(super) vol: Vec<f64>,
    /// p/ρ², for the momentum equation.
    pub(super) pr2: Vec<f64>,
    /// Particle id of each fluid slot.
    pub(super) ids: Vec<u32>,
    /// Slot of each fluid particle id.
    pub(super) slot: Vec<u32>,
    /// Accelerations of the fluid slots.
    pub(super) accel: Vec<[f64; 2]>,
}

impl Sorted {
    /// The fluid of `state` in id order (slot k = particle k), then the walls; m/ρ of every particle; p/ρ² zero;
    /// zero accelerations.
    pub(super) fn new(state: &FluidState, walls: &WallParticles) -> Self {
        let (n, nw) = (state.len(), walls.len());
        let cat = |f: &[f64], w: &[f64]| -> Vec<f64> { f.iter().chain(w).copied().collect() };
        let m = cat(&state.m, &walls.m);
        let rho = cat(&state.rho, &walls.rho);
        Sorted {
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
        }
    }

    /// The gathers' view: the first `n_fluid` slots are fluid.
    pub(super) fn view(&self, n_fluid: usize) -> ParticleView<'_> {
        ParticleView {
            x: &self.x,
            v: &self.v,
            rho: &self.rho,
            p: &self.p,
            m: &self.m,
            n_fluid,
        }
    }

    /// Writes the fluid's x, v, ρ, p and accelerations back in id order (into `state` and `accel`).
    pub(super) fn write_back(&self, state: &mut FluidState, accel: &mut [[f64; 2]]) {
        let s = self;
        let st = state;
        st.x.par_iter_mut()
            .zip(st.v.par_iter_mut())
            .zip(st.rho.par_iter_mut())
            .zip(st.p.par_iter_mut())
            .zip(accel.par_iter_mut())
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
}

/// vol = m/ρ.
pub(super) fn update_vol(vol: &mut [f64], m: &[f64], rho: &[f64]) {
    vol.par_iter_mut()
        .zip(m.par_iter())
        .zip(rho.par_iter())
        .with_min_len(4096)
        .for_each(|((v, m), r)| *v = m / r);
}

/// Moves the fluid slots of `a` (its first `src.len()` entries) to their new slots: a_new[n] = a[src[n]]; the
/// walls behind them stay.
pub(super) fn permute<T: Copy + Default + Send + Sync>(a: &mut Vec<T>, spare: &mut Vec<T>, src: &[u32]) {
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

/// `a[k] = a_old[src[k]]` for every k of `a` in place, following the cycles of the permutation; `src` is spent: its
/// entries are marked `u32::MAX` as they are done. Serial, with no spare of `a`'s size (the permutation of a
/// buffer that is read once after it).
pub(super) fn permute_spending<T: Copy>(a: &mut [T], src: &mut [u32]) {
    const DONE: u32 = u32::MAX;
    for start in 0..a.len() {
        if src[start] == DONE {
            continue;
        }
        let first = a[start];
        let mut k = start;
        loop {
            let from = src[k] as usize;
            src[k] = DONE;
            if from == start {
                a[k] = first;
                break;
            }
            a[k] = a[from];
            k = from;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The in-place permutation gives what the one with a spare gives, on a permutation with several cycles and
    /// fixed points.
    #[test]
    fn permuting_in_place_equals_permuting_with_a_spare() {
        let src: Vec<u32> = vec![3, 0, 2, 5, 1, 4, 7, 6, 8];
        let a: Vec<[f64; 2]> = (0..src.len()).map(|k| [k as f64, -(k as f64)]).collect();
        let (mut with_spare, mut spare) = (a.clone(), Vec::new());
        permute(&mut with_spare, &mut spare, &src);
        let (mut in_place, mut spent) = (a, src.clone());
        permute_spending(&mut in_place, &mut spent);
        assert_eq!(in_place, with_spare);
        assert_eq!(with_spare[0], [3.0, -3.0]);
        assert!(spent.iter().all(|&s| s == u32::MAX));
    }
}
