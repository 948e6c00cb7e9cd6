//! A square sparse matrix in compressed rows, stored in chunks of [`ROWS`] rows that are filled in parallel and keep
//! their allocations from one assembly to the next.
//!
//! Each row's entries are in the fixed order they were assembled (the PPE puts the diagonal first), so products
//! are bit-identical for any thread count. The chunks are the PPE's largest allocation (a column and a value per
//! neighbour pair): assembled in place, a step holds them once, not again as per-row lists on the way.

use rayon::prelude::*;

/// Rows per chunk.
pub const ROWS: usize = 1024;

/// Rows `first..first + start.len() - 1`: row `first + k` is `col[start[k]..start[k + 1]]` with its values.
#[derive(Clone, Debug, Default)]
struct Chunk {
    start: Vec<u32>,
    col: Vec<u32>,
    val: Vec<f64>,
}

impl Chunk {
    /// Σ_j A_kj x_j over the chunk's row k, in its stored order.
    #[inline]
    fn row_dot(&self, k: usize, x: &[f64]) -> f64 {
        let r = self.start[k] as usize..self.start[k + 1] as usize;
        self.col[r.clone()]
            .iter()
            .zip(&self.val[r])
            .map(|(&c, &v)| v * x[c as usize])
            .sum()
    }
}

/// The entries of one row being assembled: push them in order, then [`RowSink::finish`].
pub struct RowSink<'a> {
    chunk: &'a mut Chunk,
}

impl RowSink<'_> {
    /// Appends entry (column, value) to the row.
    #[inline]
    pub fn push(&mut self, col: u32, val: f64) {
        self.chunk.col.push(col);
        self.chunk.val.push(val);
    }

    /// The values pushed to the row so far, in order (to rescale or fill in an entry).
    #[inline]
    pub fn values_mut(&mut self) -> &mut [f64] {
        let from = *self.chunk.start.last().expect("a chunk starts with 0") as usize;
        &mut self.chunk.val[from..]
    }

    /// Drops every entry of the row pushed so far.
    #[inline]
    pub fn clear(&mut self) {
        let from = *self.chunk.start.last().expect("a chunk starts with 0") as usize;
        self.chunk.col.truncate(from);
        self.chunk.val.truncate(from);
    }
}

/// The matrix: `n` rows in chunks of [`ROWS`].
#[derive(Clone, Debug, Default)]
pub struct SparseRows {
    n: usize,
    chunks: Vec<Chunk>,
}

impl SparseRows {
    /// Rows from per-row (column, value) lists, in order.
    pub fn from_rows(rows: &[Vec<(u32, f64)>]) -> Self {
        let mut m = Self::default();
        m.assemble(
            rows.len(),
            &mut Vec::new(),
            |i| rows[i].len(),
            |i, row| {
                for &(c, v) in &rows[i] {
                    row.push(c, v);
                }
                0.0
            },
        );
        m
    }

    /// Rebuilds the matrix with `n` rows, reusing the allocations: `row(i, sink)` pushes the entries of row i in
    /// order and returns its right-hand side, written to `b[i]` (`b` is resized to `n`). `bound(i)` is at least
    /// the number of entries row i will have: each chunk reserves their sum before it is filled, so that its
    /// arrays do not grow by doubling. Chunks are filled in parallel; the result does not depend on the thread
    /// count.
    pub fn assemble<B, F>(&mut self, n: usize, b: &mut Vec<f64>, bound: B, row: F)
    where
        B: Fn(usize) -> usize + Sync,
        F: Fn(usize, &mut RowSink<'_>) -> f64 + Sync,
    {
        self.n = n;
        let n_chunks = n.div_ceil(ROWS);
        self.chunks.truncate(n_chunks);
        self.chunks.resize_with(n_chunks, Chunk::default);
        b.clear();
        b.resize(n, 0.0);
        self.chunks
            .par_iter_mut()
            .zip(b.par_chunks_mut(ROWS))
            .enumerate()
            .for_each(|(c, (chunk, b))| {
                chunk.start.clear();
                chunk.col.clear();
                chunk.val.clear();
                let first = c * ROWS;
                let entries: usize = (first..first + b.len()).map(&bound).sum();
                chunk.start.reserve_exact(b.len() + 1);
                chunk.col.reserve_exact(entries);
                chunk.val.reserve_exact(entries);
                chunk.start.push(0);
                for (k, bi) in b.iter_mut().enumerate() {
                    let mut sink = RowSink { chunk };
                    *bi = row(c * ROWS + k, &mut sink);
                    let end = u32::try_from(chunk.col.len()).expect("under 2³² entries in a chunk of rows");
                    chunk.start.push(end);
                }
            });
    }

    /// Number of rows.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Stored entries.
    pub fn nnz(&self) -> usize {
        self.chunks.iter().map(|c| c.val.len()).sum()
    }

    /// Bytes held (capacities).
    pub fn heap_bytes(&self) -> usize {
        self.chunks
            .iter()
            .map(|c| c.start.capacity() * 4 + c.col.capacity() * 4 + c.val.capacity() * 8)
            .sum::<usize>()
            + self.chunks.capacity() * std::mem::size_of::<Chunk>()
    }

    /// (columns, values) of row i.
    #[inline]
    pub fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let c = &self.chunks[i / ROWS];
        let k = i % ROWS;
        let r = c.start[k] as usize..c.start[k + 1] as usize;
        (&c.col[r.clone()], &c.val[r])
    }

    /// The diagonal (0 where a row has no diagonal entry).
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.n())
            .into_par_iter()
            .map(|i| {
                let (c, v) = self.row(i);
                c.iter().zip(v).filter(|(&c, _)| c as usize == i).map(|(_, &v)| v).sum()
            })
            .collect()
    }

    /// Replaces row i by the Dirichlet row p_i = 0 in place (the diagonal becomes 1, the other entries 0; the
    /// caller sets the right-hand side to 0).
    pub fn set_dirichlet(&mut self, i: usize) {
        let c = &mut self.chunks[i / ROWS];
        let k = i % ROWS;
        for e in c.start[k] as usize..c.start[k + 1] as usize {
            c.val[e] = if c.col[e] as usize == i { 1.0 } else { 0.0 };
        }
    }

    /// Multiplies row i and `b[i]` by `s[i]` (the Jacobi scaling s = 1/A_ii of [`super::bicgstab`]).
    pub fn scale_rows(&mut self, s: &[f64], b: &mut [f64]) {
        self.chunks
            .par_iter_mut()
            .zip(s.par_chunks(ROWS).zip(b.par_chunks_mut(ROWS)))
            .for_each(|(c, (s, b))| {
                for (k, (s, b)) in s.iter().zip(b.iter_mut()).enumerate() {
                    *b *= s;
                    for v in &mut c.val[c.start[k] as usize..c.start[k + 1] as usize] {
                        *v *= s;
                    }
                }
            });
    }

    /// r = f − A x (a gather per row, each in its stored order).
    pub fn residual_into(&self, f: &[f64], x: &[f64], r: &mut [f64]) {
        r.par_chunks_mut(ROWS)
            .zip(f.par_chunks(ROWS))
            .zip(&self.chunks)
            .for_each(|((r, f), c)| {
                for (k, (ri, fi)) in r.iter_mut().zip(f).enumerate() {
                    *ri = fi - c.row_dot(k, x);
                }
            });
    }

    /// y = A x (a gather per row).
    pub fn mul_into(&self, x: &[f64], y: &mut [f64]) {
        y.par_chunks_mut(ROWS).zip(&self.chunks).for_each(|(y, c)| {
            for (k, yi) in y.iter_mut().enumerate() {
                *yi = c.row_dot(k, x);
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_across_chunks_multiply_as_their_lists_say() {
        // Rows of 0–3 entries over three chunks, the last one partial.
        let n = 2 * ROWS + 17;
        let rows: Vec<Vec<(u32, f64)>> = (0..n)
            .map(|i| {
                (0..i % 4)
                    .map(|k| (((i * 7 + k * 13) % n) as u32, 1.0 + (i + k) as f64 * 0.5))
                    .collect()
            })
            .collect();
        let a = SparseRows::from_rows(&rows);
        assert_eq!(a.n(), n);
        assert_eq!(a.nnz(), rows.iter().map(Vec::len).sum::<usize>());
        let x: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let mut y = vec![f64::NAN; n];
        a.mul_into(&x, &mut y);
        for (i, row) in rows.iter().enumerate() {
            let (c, v) = a.row(i);
            assert_eq!(c, row.iter().map(|e| e.0).collect::<Vec<_>>());
            assert_eq!(v, row.iter().map(|e| e.1).collect::<Vec<_>>());
            // Same order of the sum as the list: bit-identical.
            let want: f64 = row.iter().map(|&(c, v)| v * x[c as usize]).sum();
            assert_eq!(y[i].to_bits(), want.to_bits(), "row {i}");
        }
    }

    #[test]
    fn a_reassembled_matrix_reuses_its_chunks_and_forgets_its_old_rows() {
        let mut a = SparseRows::default();
        let mut b = Vec::new();
        a.assemble(
            3 * ROWS,
            &mut b,
            |_| 2,
            |i, row| {
                row.push(i as u32, 2.0);
                row.push(((i + 1) % (3 * ROWS)) as u32, -1.0);
                i as f64
            },
        );
        let held = a.heap_bytes();
        // Fewer rows, each cleared and rescaled after its pushes.
        a.assemble(
            ROWS + 5,
            &mut b,
            |_| 3,
            |i, row| {
                row.push(0, 9.0);
                row.clear();
                row.push(i as u32, 4.0);
                row.push(0, 2.0);
                for v in &mut row.values_mut()[1..] {
                    *v *= 0.5;
                }
                1.0
            },
        );
        assert!(a.heap_bytes() <= held, "{} > {held}", a.heap_bytes());
        assert_eq!((a.n(), a.nnz(), b.len()), (ROWS + 5, 2 * (ROWS + 5), ROWS + 5));
        assert_eq!(a.row(ROWS + 4), (&[(ROWS + 4) as u32, 0][..], &[4.0, 1.0][..]));
        assert_eq!(a.diagonal()[ROWS], 4.0);
        a.set_dirichlet(ROWS);
        assert_eq!(a.row(ROWS).1, &[1.0, 0.0]);
    }
}
