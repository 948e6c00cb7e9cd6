//! The coarse levels of [`super::Multigrid`]: geometric aggregates and the Galerkin operator Pᵀ A P of a piecewise
//! constant P.

use rayon::prelude::*;

use crate::isph::sparse::SparseRows;

/// No aggregate (a Dirichlet row).
pub const NONE: u32 = u32::MAX;

/// Rows that a level can multiply and read: the PPE's own chunked rows, or a coarse level's.
pub trait Rows: Sync {
    /// Number of rows.
    fn n(&self) -> usize;
    /// (columns, values) of row i.
    fn row(&self, i: usize) -> (&[u32], &[f64]);
    /// r = f − A x, each row summed in its stored order.
    fn residual(&self, f: &[f64], x: &[f64], r: &mut [f64]) {
        r.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, ri)| {
            let (c, v) = self.row(i);
            *ri = f[i] - c.iter().zip(v).map(|(&c, &v)| v * x[c as usize]).sum::<f64>();
        });
    }
}

impl Rows for SparseRows {
    fn n(&self) -> usize {
        SparseRows::n(self)
    }
    fn row(&self, i: usize) -> (&[u32], &[f64]) {
        SparseRows::row(self, i)
    }
    fn residual(&self, f: &[f64], x: &[f64], r: &mut [f64]) {
        self.residual_into(f, x, r);
    }
}

/// A coarse operator in compressed rows.
#[derive(Clone, Debug, Default)]
pub struct Csr {
    start: Vec<u32>,
    col: Vec<u32>,
    val: Vec<f64>,
}

impl Rows for Csr {
    fn n(&self) -> usize {
        self.start.len() - 1
    }
    fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let r = self.start[i] as usize..self.start[i + 1] as usize;
        (&self.col[r.clone()], &self.val[r])
    }
}

/// Whether row i has no off-diagonal entry (a Dirichlet row, p_i = b_i / A_ii).
pub fn is_dirichlet<A: Rows>(a: &A, i: usize) -> bool {
    let (c, v) = a.row(i);
    c.iter().zip(v).all(|(&c, &v)| c as usize == i || v == 0.0)
}

/// Nodes grouped into aggregates: `agg[i]` is i's aggregate ([`NONE`] for none), aggregate I's members are
/// `members[start[I]..start[I + 1]]` in index order, `keys[I]` its cell.
#[derive(Clone, Debug, Default)]
pub struct Aggregates {
    /// Node → aggregate.
    pub agg: Vec<u32>,
    /// Where each aggregate's members start in `members` (one more entry than aggregates).
    pub start: Vec<u32>,
    /// The members, aggregate by aggregate.
    pub members: Vec<u32>,
    /// Each aggregate's cell.
    pub keys: Vec<[i64; 2]>,
}

impl Aggregates {
    /// Number of aggregates.
    pub fn len(&self) -> usize {
        self.keys.len()
    }

    /// Whether there is none (every row a Dirichlet row).
    pub fn is_empty(&self) -> bool {
        self.keys.is_empty()
    }

    /// The nodes not `skip`ped grouped by `keys` (their cells): aggregates numbered in the order of their keys
    /// (row by row), members in index order.
    pub fn by_cell(keys: &[[i64; 2]], skip: &[bool]) -> Self {
        let mut order: Vec<u32> = (0..keys.len() as u32).filter(|&i| !skip[i as usize]).collect();
        order.par_sort_unstable_by_key(|&i| {
            let k = keys[i as usize];
            (k[1], k[0], i)
        });
        let mut agg = vec![NONE; keys.len()];
        let mut start = Vec::new();
        let mut cells: Vec<[i64; 2]> = Vec::new();
        for (k, &i) in order.iter().enumerate() {
            let key = keys[i as usize];
            if cells.last() != Some(&key) {
                start.push(k as u32);
                cells.push(key);
            }
            agg[i as usize] = (cells.len() - 1) as u32;
        }
        start.push(order.len() as u32);
        Self {
            agg,
            start,
            members: order,
            keys: cells,
        }
    }

    /// The members of aggregate I.
    #[inline]
    pub fn of(&self, c: usize) -> &[u32] {
        &self.members[self.start[c] as usize..self.start[c + 1] as usize]
    }

    /// f_c = Pᵀ r: each aggregate's sum over its members, in index order.
    pub fn restrict(&self, r: &[f64], fc: &mut [f64]) {
        fc.par_iter_mut()
            .enumerate()
            .with_min_len(256)
            .for_each(|(c, fc)| *fc = self.of(c).iter().map(|&i| r[i as usize]).sum());
    }

    /// x += P x_c.
    pub fn prolong_add(&self, xc: &[f64], x: &mut [f64]) {
        x.par_iter_mut()
            .zip(self.agg.par_iter())
            .with_min_len(1024)
            .for_each(|(x, &c)| {
                if c != NONE {
                    *x += xc[c as usize];
                }
            });
    }

    /// Pᵀ A P: row I sums its members' rows with the columns mapped to aggregates (columns of no aggregate
    /// dropped), entries in the order their columns first appear.
    pub fn galerkin<A: Rows>(&self, a: &A) -> Csr {
        let nc = self.len();
        let rows: Vec<(Vec<u32>, Vec<f64>)> = (0..nc)
            .into_par_iter()
            .with_min_len(512)
            .map_init(
                || vec![NONE; nc],
                |at, c| {
                    let (mut cols, mut vals): (Vec<u32>, Vec<f64>) = (Vec::new(), Vec::new());
                    for &i in self.of(c) {
                        let (cj, vj) = a.row(i as usize);
                        for (&j, &v) in cj.iter().zip(vj) {
                            let jc = self.agg[j as usize];
                            if jc == NONE || v == 0.0 {
                                continue;
                            }
                            match at[jc as usize] {
                                NONE => {
                                    at[jc as usize] = cols.len() as u32;
                                    cols.push(jc);
                                    vals.push(v);
                                }
                                k => vals[k as usize] += v,
                            }
                        }
                    }
                    for &jc in &cols {
                        at[jc as usize] = NONE;
                    }
                    (cols, vals)
                },
            )
            .collect();
        let nnz = rows.iter().map(|r| r.0.len()).sum();
        let mut m = Csr {
            start: Vec::with_capacity(nc + 1),
            col: Vec::with_capacity(nnz),
            val: Vec::with_capacity(nnz),
        };
        m.start.push(0);
        for (c, v) in rows {
            m.col.extend_from_slice(&c);
            m.val.extend_from_slice(&v);
            m.start
                .push(u32::try_from(m.col.len()).expect("under 2³² coarse entries"));
        }
        m
    }
}
