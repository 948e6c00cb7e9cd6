//! The coarsest level of [`super::Multigrid`]: a dense LU with partial pivoting.

use super::coarsen::Rows;

/// A factorised square matrix (row-major, L below the diagonal with a unit diagonal, U on and above it).
#[derive(Clone, Debug)]
pub struct DenseLu {
    n: usize,
    lu: Vec<f64>,
    pivot: Vec<usize>,
}

impl DenseLu {
    /// `None` when a pivot is zero or not finite.
    pub fn factor<A: Rows>(a: &A) -> Option<Self> {
        let n = a.n();
        let mut lu = vec![0.0; n * n];
        for i in 0..n {
            let (c, v) = a.row(i);
            for (&c, &v) in c.iter().zip(v) {
                lu[i * n + c as usize] += v;
            }
        }
        let mut pivot: Vec<usize> = (0..n).collect();
        for k in 0..n {
            // The largest |entry| of column k at or below the diagonal, the first of equals.
            let mut p = k;
            for i in k + 1..n {
                if lu[i * n + k].abs() > lu[p * n + k].abs() {
                    p = i;
                }
            }
            let pv = lu[p * n + k];
            if pv == 0.0 || !pv.is_finite() {
                return None;
            }
            if p != k {
                for c in 0..n {
                    lu.swap(k * n + c, p * n + c);
                }
                pivot.swap(k, p);
            }
            let (upper, lower) = lu.split_at_mut((k + 1) * n);
            let row_k = &upper[k * n..];
            for row_i in lower.chunks_exact_mut(n) {
                let l = row_i[k] / pv;
                row_i[k] = l;
                if l != 0.0 {
                    for (a, b) in row_i[k + 1..].iter_mut().zip(&row_k[k + 1..]) {
                        *a -= l * b;
                    }
                }
            }
        }
        Some(Self { n, lu, pivot })
    }

    /// x = A⁻¹ f.
    pub fn solve(&self, f: &[f64], x: &mut [f64]) {
        let n = self.n;
        for (xi, &p) in x.iter_mut().zip(&self.pivot) {
            *xi = f[p];
        }
        for i in 0..n {
            let row = &self.lu[i * n..i * n + i];
            let s: f64 = row.iter().zip(&x[..i]).map(|(a, b)| a * b).sum();
            x[i] -= s;
        }
        for i in (0..n).rev() {
            let row = &self.lu[i * n + i + 1..(i + 1) * n];
            let s: f64 = row.iter().zip(&x[i + 1..]).map(|(a, b)| a * b).sum();
            x[i] = (x[i] - s) / self.lu[i * n + i];
        }
    }
}
