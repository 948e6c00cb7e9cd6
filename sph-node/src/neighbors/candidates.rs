//! The Verlet candidates of [`CHUNK`] consecutive fluid particles in 2 bytes each instead of 4 (issue 20, memory).
//!
//! A chunk's particles are neighbours in the cell order, so their candidates lie in two short runs of slots: fluid
//! slots of the few cell rows the chunk touches, and wall slots (which follow the fluid's) of the same rows. Each
//! candidate is kept as a `u16` code: codes below `split` are fluid slots counted from the chunk's smallest fluid
//! candidate, codes from `split` on are wall slots counted from its smallest wall candidate. A chunk whose two runs
//! need more than 65,535 codes together keeps its candidates as `u32` slots. Either way a candidate decodes to the
//! slot it was gathered as, in the order it was gathered: the filter sees the same slots as with `u32` lists.

use rayon::prelude::*;

use super::cell_list::{ListChunk, CHUNK};

/// The slots of one chunk's candidates, as stored.
#[derive(Clone, Debug, PartialEq)]
pub enum Slots<'a> {
    /// Codes: `c < split` is fluid slot `fluid_base + c`, else wall slot `wall_base + (c − split)`.
    Narrow {
        /// One code a candidate.
        codes: &'a [u16],
        /// Fluid codes are below it.
        split: u16,
        /// The fluid slot of code 0.
        fluid_base: u32,
        /// The wall slot of code `split`.
        wall_base: u32,
    },
    /// The slots themselves.
    Wide(&'a [u32]),
}

impl Slots<'_> {
    /// Calls `f` with every slot, in the stored order.
    #[inline(always)]
    pub fn for_each(&self, mut f: impl FnMut(u32)) {
        match *self {
            Slots::Narrow {
                codes,
                split,
                fluid_base,
                wall_base,
            } => {
                // The wall base less the split, so that one add decodes either run (wrapping: the sum is a slot),
                // and the base chosen by a mask, not a branch: in a flow, which run a candidate is in follows no
                // pattern a branch predictor learns.
                let wall_shift = wall_base.wrapping_sub(u32::from(split));
                let to_wall = wall_shift.wrapping_sub(fluid_base);
                for &c in codes {
                    let wall = u32::from(c >= split).wrapping_neg();
                    f(fluid_base.wrapping_add(wall & to_wall).wrapping_add(u32::from(c)));
                }
            }
            Slots::Wide(slots) => slots.iter().for_each(|&j| f(j)),
        }
    }

    /// Number of slots.
    pub fn len(&self) -> usize {
        match self {
            Slots::Narrow { codes, .. } => codes.len(),
            Slots::Wide(slots) => slots.len(),
        }
    }

    /// True when there is none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The slots, decoded.
    pub fn to_vec(&self) -> Vec<u32> {
        let mut v = Vec::with_capacity(self.len());
        self.for_each(|j| v.push(j));
        v
    }
}

/// One chunk's candidates.
#[derive(Clone, Debug, Default)]
struct CandidateChunk {
    /// `start[k]..start[k + 1]` indexes the codes (or slots) of the chunk's `k`-th particle.
    start: Vec<u32>,
    /// The candidates are stored in `codes` (else in `wide`).
    narrow: bool,
    /// Fluid codes are below it; it is the fluid run's length.
    split: u16,
    fluid_base: u32,
    wall_base: u32,
    /// The codes, when the chunk's slots fit (else empty).
    codes: Vec<u16>,
    /// The slots, when they do not (else empty).
    wide: Vec<u32>,
}

impl CandidateChunk {
    /// The chunk's lists `built` (a gather's), stored in codes when they fit; slots below `n_fluid` are fluid.
    fn encode(built: &ListChunk, n_fluid: usize) -> Self {
        let slots = &built.idx;
        let n_fluid = n_fluid as u32;
        let (mut f_lo, mut f_hi, mut w_lo, mut w_hi) = (u32::MAX, 0, u32::MAX, 0);
        for &j in slots {
            if j < n_fluid {
                (f_lo, f_hi) = (f_lo.min(j), f_hi.max(j));
            } else {
                (w_lo, w_hi) = (w_lo.min(j), w_hi.max(j));
            }
        }
        // Codes each run needs (0 when it is empty).
        let span = |lo: u32, hi: u32| if lo > hi { 0 } else { u64::from(hi - lo) + 1 };
        let (f_span, w_span) = (span(f_lo, f_hi), span(w_lo, w_hi));
        let start = (0..=built.len())
            .map(|k| if k == 0 { 0 } else { built.range(k - 1).end as u32 })
            .collect();
        // At most 65,535 codes, so that `split` (the fluid's count) is a u16 and every wall code is ≥ it.
        if f_span + w_span < 1 << 16 {
            let (split, fluid_base, wall_base) = (f_span as u16, f_lo, w_lo);
            let codes = slots
                .iter()
                .map(|&j| match j < n_fluid {
                    true => (j - fluid_base) as u16,
                    false => (j - wall_base) as u16 + split,
                })
                .collect();
            Self {
                start,
                narrow: true,
                split,
                fluid_base,
                wall_base,
                codes,
                wide: Vec::new(),
            }
        } else {
            Self {
                start,
                wide: slots.clone(),
                ..Self::default()
            }
        }
    }

    fn slots(&self, k: usize) -> Slots<'_> {
        let r = self.start[k] as usize..self.start[k + 1] as usize;
        match self.narrow {
            true => Slots::Narrow {
                codes: &self.codes[r],
                split: self.split,
                fluid_base: self.fluid_base,
                wall_base: self.wall_base,
            },
            false => Slots::Wide(&self.wide[r]),
        }
    }

    fn heap_bytes(&self) -> usize {
        4 * (self.start.capacity() + self.wide.capacity()) + 2 * self.codes.capacity()
    }
}

/// Candidate lists of every fluid particle, chunk by chunk in 2-byte codes where they fit.
#[derive(Clone, Debug, Default)]
pub struct CandidateLists {
    n: usize,
    chunks: Vec<CandidateChunk>,
}

impl CandidateLists {
    /// Rebuilds the lists of particles `0..n` (fluid slots `0..n_fluid`, wall slots from `n_fluid` on):
    /// `gather(i, chunk)` appends the candidates of particle i to `chunk.idx`, as for
    /// [`super::NeighborList::build`]. Each chunk is gathered into a list of its own, encoded, and the list
    /// dropped, so that no more than one chunk a thread is held in 4-byte slots at a time.
    pub fn build<G>(&mut self, n: usize, n_fluid: usize, gather: G)
    where
        G: Fn(usize, &mut ListChunk) + Sync,
    {
        self.n = n;
        let n_chunks = n.div_ceil(CHUNK);
        self.chunks.truncate(n_chunks);
        self.chunks.resize_with(n_chunks, CandidateChunk::default);
        self.chunks.par_iter_mut().enumerate().for_each(|(c, chunk)| {
            let first = c * CHUNK;
            let last = (first + CHUNK).min(n);
            let mut built = ListChunk::default();
            built.clear(first, last - first);
            for i in first..last {
                gather(i, &mut built);
                built.close_particle();
            }
            *chunk = CandidateChunk::encode(&built, n_fluid);
        });
    }

    /// The candidates of particle i, as stored.
    #[inline]
    pub fn of(&self, i: usize) -> Slots<'_> {
        self.chunks[i / CHUNK].slots(i % CHUNK)
    }

    /// Number of particles with candidates.
    pub fn len(&self) -> usize {
        self.n
    }

    /// True when no particle has candidates.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// Chunks stored in 4-byte slots (their runs did not fit in 2-byte codes), and all chunks.
    pub fn wide_chunks(&self) -> (usize, usize) {
        (self.chunks.iter().filter(|c| !c.narrow).count(), self.chunks.len())
    }

    /// The first particle whose candidates differ from `other`'s, in one line; `None` when they are the same.
    pub fn differs_from(&self, other: &CandidateLists) -> Option<String> {
        if self.n != other.n {
            return Some(format!("candidates of {} particles against {}", self.n, other.n));
        }
        (0..self.n)
            .find(|&i| self.of(i).to_vec() != other.of(i).to_vec())
            .map(|i| format!("the candidates of particle {i} differ"))
    }

    /// Bytes held (capacities).
    pub fn heap_bytes(&self) -> usize {
        self.chunks.iter().map(CandidateChunk::heap_bytes).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lists of `lists.len()` particles from explicit slots, through the gather interface.
    fn built(lists: &[Vec<u32>], n_fluid: usize) -> CandidateLists {
        let mut c = CandidateLists::default();
        c.build(lists.len(), n_fluid, |i, chunk| chunk.idx.extend_from_slice(&lists[i]));
        c
    }

    fn decoded(c: &CandidateLists) -> Vec<Vec<u32>> {
        (0..c.len()).map(|i| c.of(i).to_vec()).collect()
    }

    #[test]
    fn slots_come_back_in_their_order_narrow_or_wide() {
        let n_fluid = 200_000;
        // Chunk 0: fluid and wall runs that fit; chunk 1: a fluid run of 70,000 slots (wide); chunk 2: wall only,
        // and particles with no candidate.
        let mut lists: Vec<Vec<u32>> = (0..CHUNK as u32)
            .map(|k| vec![1_000 + k, 1_000 - k, 200_005 + k % 7, 999, 200_004])
            .collect();
        lists.extend((0..CHUNK as u32).map(|k| vec![10 + k, 70_010 - k]));
        lists.extend((0..100u32).map(|k| if k % 3 == 0 { vec![] } else { vec![300_000 + k, 299_990] }));
        let c = built(&lists, n_fluid);
        assert_eq!(decoded(&c), lists);
        assert_eq!(c.wide_chunks(), (1, 3));
        assert!(c.differs_from(&built(&lists, n_fluid)).is_none());
        let mut other = lists.clone();
        other[300].swap(0, 1);
        assert_eq!(
            c.differs_from(&built(&other, n_fluid)).as_deref(),
            Some("the candidates of particle 300 differ")
        );
    }

    #[test]
    fn runs_that_fill_the_codes_fit_and_one_more_does_not() {
        // Fluid span 40,000 + wall span 25,535 = 65,535 codes: narrow. One wall slot further: wide.
        let fit = vec![vec![5, 40_004, 100_000, 125_534]];
        let c = built(&fit, 50_000);
        assert_eq!((c.wide_chunks(), decoded(&c)), ((0, 1), fit));
        let over = vec![vec![5, 40_004, 100_000, 125_535]];
        let c = built(&over, 50_000);
        assert_eq!((c.wide_chunks(), decoded(&c)), ((1, 1), over));
        // One run alone, at the largest span that fits.
        for one in [vec![vec![0, 65_534]], vec![vec![100_000, 165_534]]] {
            let c = built(&one, 100_000);
            assert_eq!((c.wide_chunks(), decoded(&c)), ((0, 1), one));
        }
    }
}
