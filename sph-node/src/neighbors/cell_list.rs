//! Cell-linked list (cell size = kernel support 2h), built in O(N) by a counting sort of the particles by cell
//! index, so that the particles of one cell, and of neighbouring cells along x, lie next to each other in the
//! sorted index array.
//!
//! The gather visits the 3 × 3 block of cells in a fixed order (row by row, bottom to top) and, inside a cell,
//! the particles in increasing index (the counting sort is stable), so every particle's neighbour list has the
//! same order whatever the thread count.

use rayon::prelude::*;

use super::grid::Grid;
use crate::kernel::CubicSpline;

/// Particles binned on a uniform grid.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CellList {
    grid: Grid,
    /// `cell_start[c]..cell_start[c + 1]` indexes `sorted` for cell c.
    cell_start: Vec<u32>,
    /// Particle indices sorted by cell (stable).
    sorted: Vec<u32>,
    /// The positions binned, in the order of `sorted`: a gather reads its candidates from three contiguous runs
    /// instead of one scattered load each (ISPH keeps its particles in id order, which the flow scatters over the
    /// cells as a run goes on).
    binned: Vec<[f64; 2]>,
}

impl CellList {
    /// Bins `positions` on cells of size `cell_size` covering their bounding box.
    ///
    /// Positions must be finite (the solver checks this before building).
    pub fn new(positions: &[[f64; 2]], cell_size: f64) -> Self {
        let mut list = Self::default();
        list.rebuild(positions, cell_size);
        list
    }

    /// Re-bins `positions`, reusing the allocations.
    pub fn rebuild(&mut self, positions: &[[f64; 2]], cell_size: f64) {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in positions {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if positions.is_empty() {
            lo = [0.0; 2];
            hi = [0.0; 2];
        }
        self.grid = Grid::covering(lo, hi, cell_size);
        let grid = self.grid;
        let n_cells = grid.n_cells();
        // Counting sort by cell index: O(N + cells), stable.
        self.cell_start.clear();
        self.cell_start.resize(n_cells + 1, 0);
        let cells: Vec<u32> = positions.par_iter().map(|&p| grid.cell_of(p) as u32).collect();
        for &c in &cells {
            self.cell_start[c as usize + 1] += 1;
        }
        for c in 0..n_cells {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        let mut next: Vec<u32> = self.cell_start[..n_cells].to_vec();
        self.sorted.clear();
        self.sorted.resize(positions.len(), 0);
        for (i, &c) in cells.iter().enumerate() {
            let slot = &mut next[c as usize];
            self.sorted[*slot as usize] = i as u32;
            *slot += 1;
        }
        self.binned.clear();
        self.binned.extend(self.sorted.iter().map(|&i| positions[i as usize]));
    }

    /// Particle indices in cell order (the memory order of the gathers).
    pub fn sorted(&self) -> &[u32] {
        &self.sorted
    }

    /// Appends to `out` every binned particle j ≠ `exclude` with |x_j − `query`| < `radius` (`radius` ≤ cell
    /// size), x_j as the last [`CellList::rebuild`] binned it, in the fixed order described in the module
    /// documentation.
    pub fn gather_into(&self, query: [f64; 2], exclude: Option<usize>, radius: f64, out: &mut Vec<u32>) {
        if self.sorted.is_empty() {
            return;
        }
        let r2 = radius * radius;
        let d0 = self.grid.dims()[0];
        let ([y0, y1], [x0, x1]) = self.grid.block(self.grid.cell_of(query));
        for y in y0..=y1 {
            // Cells x0..=x1 of one row are contiguous in `sorted` and `binned`.
            let a = self.cell_start[y * d0 + x0] as usize;
            let b = self.cell_start[y * d0 + x1 + 1] as usize;
            for (&j, p) in self.sorted[a..b].iter().zip(&self.binned[a..b]) {
                if Some(j as usize) == exclude {
                    continue;
                }
                let dx = query[0] - p[0];
                let dy = query[1] - p[1];
                if dx * dx + dy * dy < r2 {
                    out.push(j);
                }
            }
        }
    }

    /// Neighbour lists (self excluded) of the first `n_query` particles of `positions`, built in parallel;
    /// `positions` are those the list was last built or rebuilt from.
    pub fn neighbor_list(&self, positions: &[[f64; 2]], n_query: usize, radius: f64) -> NeighborList {
        let mut list = NeighborList::default();
        self.neighbor_list_into(positions, n_query, radius, &mut list);
        list
    }

    /// [`CellList::neighbor_list`] into `list`, reusing its allocations (the same lists). Each particle is gathered
    /// into the chunk's candidate scratch first and then copied, so that the pair array grows by
    /// [`ListChunk::reserve_pairs`]' estimate and not by doubling (which left it 1.6× the pairs on average).
    pub fn neighbor_list_into(&self, positions: &[[f64; 2]], n_query: usize, radius: f64, list: &mut NeighborList) {
        assert_eq!(
            positions.len(),
            self.binned.len(),
            "the positions the cells were built from"
        );
        list.build(n_query, |i, chunk| {
            let mut found = std::mem::take(&mut chunk.cand_idx);
            found.clear();
            self.gather_into(positions[i], Some(i), radius, &mut found);
            chunk.reserve_pairs(found.len(), false);
            chunk.idx.extend_from_slice(&found);
            chunk.cand_idx = found;
        });
    }
}

/// Particles per chunk of a [`NeighborList`] (a power of two): the unit of parallel work and of storage.
pub const CHUNK: usize = 256;

/// The neighbour lists of [`CHUNK`] consecutive particles, stored together, with an optional ∇W factor per pair.
///
/// Only what cannot be recomputed cheaply is kept per pair (4 + 8 bytes): r² and W follow from the positions,
/// which do not move between a search and the passes that use its lists, with the builder's own arithmetic
/// (see [`ListChunk::grad`]). The pair arrays grow to an estimate of what the chunk needs (not by doubling) and
/// keep their capacity from list to list.
#[derive(Clone, Debug, Default)]
pub struct ListChunk {
    /// First particle of the chunk.
    first: usize,
    /// Number of particles the chunk is being filled with (for the capacity estimate).
    particles: usize,
    /// `start[k]..start[k + 1]` indexes the pair arrays for particle `first + k`.
    start: Vec<u32>,
    /// Neighbour indices.
    pub idx: Vec<u32>,
    /// ∇W factor per pair (see [`ListChunk::grad`]); longer than `idx` when it held more pairs before.
    grad: Vec<f64>,
    /// The builder evaluated the kernel ([`ListChunk::kernel_values`]) since the chunk was cleared.
    kernel_written: bool,
    /// Candidate indices of the particle being gathered (builder scratch).
    pub(super) cand_idx: Vec<u32>,
    /// Candidate squared distances (builder scratch).
    pub(super) cand_d2: Vec<f64>,
}

impl ListChunk {
    /// First particle of the chunk.
    #[inline]
    pub fn first(&self) -> usize {
        self.first
    }

    /// Number of particles in the chunk.
    #[inline]
    pub fn len(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    /// True when the chunk holds no particle.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Pair index range of the chunk's `k`-th particle.
    #[inline]
    pub fn range(&self, k: usize) -> std::ops::Range<usize> {
        self.start[k] as usize..self.start[k + 1] as usize
    }

    /// Neighbours of the chunk's `k`-th particle.
    #[inline]
    pub fn of(&self, k: usize) -> &[u32] {
        &self.idx[self.range(k)]
    }

    /// Empties the chunk for `particles` particles from `first` (also for a builder outside [`NeighborList`]).
    pub(super) fn clear(&mut self, first: usize, particles: usize) {
        self.first = first;
        self.particles = particles;
        self.kernel_written = false;
        self.start.clear();
        self.start.push(0);
        self.idx.clear();
        // The ∇W factors keep their length, to be overwritten in place ([`ListChunk::kernel_values`]) and read up
        // to the pair count.
    }

    /// The ∇W factor of every pair, dW/dr(r)/r (∇_i W_ij = factor · r_ij), when the builder evaluated the kernel
    /// (else empty); indexed as `idx`. The builder takes r = √d², d² = dx · dx + dy · dy with (dx, dy) = x_i − x_j
    /// (as [`crate::particles::separation`]); a pass that needs r² or W recomputes them from the same positions with
    /// that arithmetic, bit for bit what the builder saw.
    #[inline]
    pub fn grad(&self) -> &[f64] {
        &self.grad[..self.kernel_len()]
    }

    fn kernel_len(&self) -> usize {
        if self.kernel_written {
            self.idx.len()
        } else {
            0
        }
    }

    /// Capacity for `n` more pairs in `idx` (and in the ∇W factors when `kernel`), grown to an estimate of the
    /// whole chunk: the pairs so far, plus as many per remaining particle as the particles so far had on average,
    /// plus 1/32. Exact reservations, so that the pair arrays are not up to twice what the chunk needs, as
    /// doubling growth leaves them.
    #[inline]
    pub fn reserve_pairs(&mut self, n: usize, kernel: bool) {
        let end = self.idx.len() + n;
        let fits = |cap: usize| cap >= end;
        if fits(self.idx.capacity()) && (!kernel || fits(self.grad.len())) {
            return;
        }
        let done = self.start.len(); // particles closed, plus the one being gathered
        let remaining = self.particles.saturating_sub(done);
        let estimate = end + end.div_ceil(done) * remaining;
        let want = estimate + estimate / 32;
        if !fits(self.idx.capacity()) {
            self.idx.reserve_exact(want - self.idx.len());
        }
        if kernel && !fits(self.grad.len()) {
            self.grad.reserve_exact(want - self.grad.len());
            // Every entry is overwritten before it is read.
            self.grad.resize(want, 0.0);
        }
    }

    /// The ∇W factors for the pairs `start..start + n`, for a builder that evaluates the kernel to fill (the
    /// storage is reused from list to list without being zeroed first; [`ListChunk::reserve_pairs`] grows it).
    #[inline]
    pub fn kernel_values(&mut self, start: usize, n: usize) -> &mut [f64] {
        let end = start + n;
        self.kernel_written = true;
        if self.grad.len() < end {
            self.grad.resize(end, 0.0);
        }
        &mut self.grad[start..end]
    }

    /// Appends the first `n` candidates of the builder's scratch (`cand_idx`, with their squared distances in
    /// `cand_d2`) as pairs of the particle being gathered, with their ∇W factors: r as `separation` computes it, the
    /// factor as `CubicSpline::grad`.
    #[inline]
    pub(super) fn push_candidates(&mut self, n: usize, kernel: &CubicSpline) {
        let start = self.idx.len();
        self.reserve_pairs(n, true);
        self.idx.extend_from_slice(&self.cand_idx[..n]);
        let d2 = std::mem::take(&mut self.cand_d2);
        kernel.grad_factors(&d2[..n], self.kernel_values(start, n));
        self.cand_d2 = d2;
    }

    /// The neighbours of the chunk's `k`-th particle and the bits of their ∇W factors (none when the builder did not
    /// evaluate the kernel), read with `get`: the bounds of lists read back from a checkpoint may point anywhere.
    fn saved_pairs(&self, k: usize) -> Option<(&[u32], Vec<u64>)> {
        let r = *self.start.get(k)? as usize..*self.start.get(k + 1)? as usize;
        let grad = match self.kernel_written {
            true => self.grad.get(r.clone())?.iter().map(|g| g.to_bits()).collect(),
            false => Vec::new(),
        };
        Some((self.idx.get(r)?, grad))
    }

    pub(super) fn close_particle(&mut self) {
        self.start.push(self.idx.len() as u32);
    }
}

/// Per-particle neighbour lists (self excluded), each in the fixed gather order, stored in chunks of [`CHUNK`]
/// particles that are built in parallel and never concatenated.
#[derive(Clone, Debug, Default)]
pub struct NeighborList {
    n: usize,
    chunks: Vec<ListChunk>,
}

impl NeighborList {
    /// Rebuilds the lists of particles `0..n`, reusing the allocations: `gather(i, chunk)` appends the neighbours
    /// of particle i to `chunk.idx` (and, if it evaluates the kernel, fills their ∇W factors through
    /// [`ListChunk::kernel_values`], for every particle of the chunk). Chunks are filled in parallel; the lists do
    /// not depend on the thread count.
    pub fn build<F>(&mut self, n: usize, gather: F)
    where
        F: Fn(usize, &mut ListChunk) + Sync,
    {
        // Values of `()`: no memory, nothing computed.
        self.build_and_map(n, gather, &mut Vec::new(), |_, _, _| ());
    }

    /// [`NeighborList::build`], and `out[i] = f(i, neighbours of i, their ∇W factors)` for each particle as soon as
    /// its list is built (while its pairs are in the cache): the lists and the values of a build followed by
    /// [`NeighborList::map_pairs_into`], in one pass.
    pub fn build_and_map<T, G, F>(&mut self, n: usize, gather: G, out: &mut Vec<T>, f: F)
    where
        T: Copy + Default + Send,
        G: Fn(usize, &mut ListChunk) + Sync,
        F: Fn(usize, &[u32], &[f64]) -> T + Sync,
    {
        self.n = n;
        let n_chunks = n.div_ceil(CHUNK);
        self.chunks.truncate(n_chunks);
        self.chunks.resize_with(n_chunks, ListChunk::default);
        out.resize(n, T::default()); // every entry is overwritten
        self.chunks
            .par_iter_mut()
            .zip(out.par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(c, (chunk, out))| {
                let first = c * CHUNK;
                let last = (first + CHUNK).min(n);
                chunk.clear(first, last - first);
                for (i, o) in (first..last).zip(out.iter_mut()) {
                    gather(i, chunk);
                    chunk.close_particle();
                    let r = chunk.range(i - first);
                    let g = if chunk.kernel_written {
                        &chunk.grad[r.clone()]
                    } else {
                        &[][..]
                    };
                    *o = f(i, &chunk.idx[r], g);
                }
            });
    }

    /// `out[i] = f(i, neighbours of i, their ∇W factors)` for every particle with a list, in parallel over the
    /// chunks (each value depends on its own particle only, so the result does not depend on the thread count).
    /// The factors are empty when the builder did not evaluate the kernel.
    pub fn map_pairs_into<T, F>(&self, out: &mut Vec<T>, f: F)
    where
        T: Copy + Default + Send,
        F: Fn(usize, &[u32], &[f64]) -> T + Sync,
    {
        out.resize(self.n, T::default()); // every entry is overwritten
        out.par_chunks_mut(CHUNK)
            .zip(self.chunks.par_iter())
            .for_each(|(out, chunk)| {
                let grad = chunk.grad();
                for (k, o) in out.iter_mut().enumerate() {
                    let r = chunk.range(k);
                    let g = if grad.is_empty() { &[][..] } else { &grad[r.clone()] };
                    *o = f(chunk.first() + k, &chunk.idx[r], g);
                }
            });
    }

    /// [`NeighborList::map_pairs_into`] for a pass with three results per particle: `(a[i], b[i], c[i]) = f(i, …)`.
    pub fn map_pairs_into3<A, B, C, F>(&self, a: &mut Vec<A>, b: &mut Vec<B>, c: &mut Vec<C>, f: F)
    where
        A: Copy + Default + Send,
        B: Copy + Default + Send,
        C: Copy + Default + Send,
        F: Fn(usize, &[u32], &[f64]) -> (A, B, C) + Sync,
    {
        a.resize(self.n, A::default()); // every entry is overwritten
        b.resize(self.n, B::default());
        c.resize(self.n, C::default());
        a.par_chunks_mut(CHUNK)
            .zip(b.par_chunks_mut(CHUNK))
            .zip(c.par_chunks_mut(CHUNK))
            .zip(self.chunks.par_iter())
            .for_each(|(((a, b), c), chunk)| {
                let grad = chunk.grad();
                for (k, ((a, b), c)) in a.iter_mut().zip(b.iter_mut()).zip(c.iter_mut()).enumerate() {
                    let r = chunk.range(k);
                    let g = if grad.is_empty() { &[][..] } else { &grad[r.clone()] };
                    (*a, *b, *c) = f(chunk.first() + k, &chunk.idx[r], g);
                }
            });
    }

    /// Neighbours of particle i.
    #[inline]
    pub fn of(&self, i: usize) -> &[u32] {
        self.chunks[i / CHUNK].of(i % CHUNK)
    }

    /// The chunks, in particle order.
    pub fn chunks(&self) -> &[ListChunk] {
        &self.chunks
    }

    /// Number of particles with a list.
    pub fn len(&self) -> usize {
        self.n
    }

    /// True when no particle has a list.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Total number of (ordered) pairs.
    pub fn pair_count(&self) -> usize {
        self.chunks.iter().map(|c| c.idx.len()).sum()
    }

    /// Where these lists (read back from a checkpoint) differ from `built`, the lists built again from the same
    /// positions, in one line; `None` when they are the same: the same particles in the same chunks, the same
    /// neighbours in the same order, the same ∇W factors bit for bit. Checked before anything is indexed, so lists
    /// that do not hold together are refused rather than read out of bounds. Capacities and the builders' scratch
    /// contents are left out (never read before they are written), but not the lengths that a later build indexes.
    pub fn differs_from(&self, built: &NeighborList) -> Option<String> {
        if self.n != built.n || self.chunks.len() != built.chunks.len() {
            return Some(format!(
                "lists of {} particles in {} chunks where the positions give {} in {}",
                self.n,
                self.chunks.len(),
                built.n,
                built.chunks.len()
            ));
        }
        for (c, (a, b)) in self.chunks.iter().zip(&built.chunks).enumerate() {
            if (a.first, a.particles, a.kernel_written) != (b.first, b.particles, b.kernel_written) {
                return Some(format!(
                    "chunk {c} holds {} particles from {} where the positions give {} from {}",
                    a.particles, a.first, b.particles, b.first
                ));
            }
            if a.kernel_written && (a.grad.len() < a.idx.len() || a.cand_d2.len() < a.cand_idx.len()) {
                return Some(format!(
                    "chunk {c}: {} ∇W factors for {} pairs, {} candidate distances for {} candidates",
                    a.grad.len(),
                    a.idx.len(),
                    a.cand_d2.len(),
                    a.cand_idx.len()
                ));
            }
            let same = |k: usize| a.saved_pairs(k).is_some() && a.saved_pairs(k) == b.saved_pairs(k);
            if a.start.len() != b.start.len() || a.idx.len() != b.idx.len() || !(0..b.len()).all(same) {
                let k = (0..b.len()).find(|&k| !same(k)).unwrap_or(b.len());
                return Some(format!(
                    "the neighbours of particle {} differ from those the positions give",
                    b.first + k
                ));
            }
        }
        None
    }

    /// Bytes held by the lists (capacity).
    pub fn heap_bytes(&self) -> usize {
        self.chunks
            .iter()
            .map(|c| {
                4 * (c.start.capacity() + c.idx.capacity() + c.cand_idx.capacity())
                    + 8 * (c.grad.capacity() + c.cand_d2.capacity())
            })
            .sum()
    }
}
