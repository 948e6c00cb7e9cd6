//! Verlet candidate lists for the WCSPH search: every fluid particle's neighbours within the kernel support plus a
//! skin, kept over several steps. While no fluid particle has moved more than half the skin since the candidates
//! were gathered, every pair closer than the support is among them (two particles close by at most twice the
//! largest displacement; the walls do not move), so a step's lists are the candidates filtered by distance, with no
//! scan of the 3 × 3 block of cells and no re-sort of the particles (Verlet 1967; Allen & Tildesley, Computer
//! Simulation of Liquids, §5.3.1).
//!
//! The filtered lists keep the candidates' order, the gather order of the last rebuild: a neighbour that has
//! since changed cell keeps its old place, so the sums run in an order that depends on when the candidates were
//! gathered, not only on the positions (it does not depend on the thread count).

use rayon::prelude::*;

use super::candidates::CandidateLists;
use super::cell_list::{ListChunk, NeighborList};
use super::sorted::SortedCells;
use crate::kernel::CubicSpline;

/// Candidate lists with their skin and the positions they were gathered at.
#[derive(Clone, Debug, Default)]
pub struct VerletCandidates {
    /// Skin (a length) beyond the kernel support.
    skin: f64,
    /// The candidates of each fluid particle (slots of the sort they were gathered after, in 2-byte codes where a
    /// chunk's slots fit: [`CandidateLists`]; no ∇W factors).
    candidates: CandidateLists,
    /// Fluid positions (slot order) when the candidates were gathered; empty before the first gather.
    x_ref: Vec<[f64; 2]>,
    /// Gathers since the candidates were made (diagnostics).
    gathers: u64,
}

impl VerletCandidates {
    /// Candidate lists with a skin of `skin` (a length, > 0) beyond the kernel support.
    pub fn new(skin: f64) -> Self {
        Self {
            skin,
            ..Self::default()
        }
    }

    /// The skin, a length.
    pub fn skin(&self) -> f64 {
        self.skin
    }

    /// Forgets the candidates: the next [`VerletCandidates::still_hold`] is false.
    pub fn clear(&mut self) {
        self.x_ref.clear();
    }

    /// Whether the candidates still hold every pair of the fluid at positions `x` (slot order of the last gather)
    /// closer than the kernel support: twice the largest displacement since the gather is less than the skin.
    pub fn still_hold(&self, x: &[[f64; 2]]) -> bool {
        !self.x_ref.is_empty() && self.within_half_skin(x, &self.x_ref)
    }

    /// Whether every position of `x` is closer than half the skin to the same entry of `x_ref` (of the same
    /// length): candidates gathered at `x_ref` hold the pairs of `x`.
    pub fn within_half_skin(&self, x: &[[f64; 2]], x_ref: &[[f64; 2]]) -> bool {
        if x_ref.len() != x.len() {
            return false;
        }
        let max_d2 = x
            .par_iter()
            .zip(x_ref.par_iter())
            .with_min_len(4096)
            .map(|(p, q)| {
                let dx = p[0] - q[0];
                let dy = p[1] - q[1];
                dx * dx + dy * dy
            })
            .reduce(|| 0.0, f64::max);
        4.0 * max_d2 < self.skin * self.skin
    }

    /// The fluid positions (slot order) the candidates were gathered at; empty before the first gather.
    pub fn reference(&self) -> &[[f64; 2]] {
        &self.x_ref
    }

    /// Gathers the candidates of the fluid particles `0..n_fluid` of `x` (sorted fluid, then the walls) from the
    /// cells just sorted (cell size at least `support` + skin).
    pub fn gather(&mut self, cells: &SortedCells, x: &[[f64; 2]], n_fluid: usize, support: f64) {
        cells.build_candidate_lists(x, n_fluid, support + self.skin, &mut self.candidates);
        self.x_ref.clear();
        self.x_ref.extend_from_slice(&x[..n_fluid]);
        self.gathers += 1;
    }

    /// How many times the candidates were gathered from the cells.
    pub fn gathers(&self) -> u64 {
        self.gathers
    }

    /// The neighbour lists, with ∇W factors, of the fluid particles at positions `x` (their candidates filtered
    /// by the kernel support), and `out[i] = f(i, neighbours of i, their ∇W factors)` as each is built
    /// ([`NeighborList::build_and_map`]).
    pub fn build_lists_and_map<T, F>(
        &self,
        x: &[[f64; 2]],
        kernel: &CubicSpline,
        list: &mut NeighborList,
        out: &mut Vec<T>,
        f: F,
    ) where
        T: Copy + Default + Send,
        F: Fn(usize, &[u32], &[f64]) -> T + Sync,
    {
        let r2max = kernel.support() * kernel.support();
        list.build_and_map(
            self.x_ref.len(),
            |i, chunk| self.filter(x, kernel, r2max, i, chunk),
            out,
            f,
        );
    }

    /// Appends the candidates of fluid slot i closer than the support, with their ∇W factors, to `chunk`.
    #[inline]
    fn filter(&self, x: &[[f64; 2]], kernel: &CubicSpline, r2max: f64, i: usize, chunk: &mut ListChunk) {
        let cand = self.candidates.of(i);
        let total = cand.len();
        if chunk.cand_idx.len() < total {
            chunk.cand_idx.resize(total, 0);
            chunk.cand_d2.resize(total, 0.0);
        }
        let xi = x[i];
        let mut n = 0;
        let (cand_idx, cand_d2) = (&mut chunk.cand_idx[..total], &mut chunk.cand_d2[..total]);
        // Branch-free compaction, as the cells' scan.
        cand.for_each(|j| {
            let p = x[j as usize];
            let dx = xi[0] - p[0];
            let dy = xi[1] - p[1];
            let d2 = dx * dx + dy * dy;
            cand_idx[n] = j;
            cand_d2[n] = d2;
            n += usize::from(d2 < r2max);
        });
        chunk.push_candidates(n, kernel);
    }

    /// The first part in which these candidates (rebuilt on restore) differ from `other`; `None` when the same.
    pub fn differs_from(&self, other: &VerletCandidates) -> Option<String> {
        let bits = |x: &[[f64; 2]]| x.iter().map(|p| p.map(f64::to_bits)).collect::<Vec<_>>();
        if self.skin.to_bits() != other.skin.to_bits() {
            return Some(format!("skin {} against {}", self.skin, other.skin));
        }
        if bits(&self.x_ref) != bits(&other.x_ref) {
            return Some("the positions the candidates were gathered at".into());
        }
        self.candidates.differs_from(&other.candidates)
    }

    /// Bytes held (capacities).
    pub fn heap_bytes(&self) -> usize {
        self.candidates.heap_bytes() + 16 * self.x_ref.capacity()
    }
}
