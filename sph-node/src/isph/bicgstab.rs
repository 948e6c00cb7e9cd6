//! BiCGSTAB (van der Vorst 1992) with Jacobi preconditioning for the PPE (`DESIGN.md` §4.3, step 4).
//!
//! The preconditioner is applied on the left, so the iteration solves D⁻¹A x = D⁻¹b and the residual it reports
//! and tests is ‖D⁻¹(b − A x)‖₂ / ‖D⁻¹ b‖₂ (in pressure units before the division: every row is scaled to a
//! unit diagonal). Dot products are summed in fixed chunks of [`CHUNK`] entries, each chunk in index order, then
//! the chunk sums in order, so the result is bit-identical for any number of threads.

use rayon::prelude::*;

use super::ppe::SparseRows;

/// Entries per chunk of a reduction.
pub const CHUNK: usize = 1024;

/// Restarts allowed after a breakdown ((r̂, r) ≈ 0, (r̂, v) = 0 or ω = 0).
pub const MAX_RESTARTS: usize = 20;

/// Iterations taken and the final relative residual.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveStats {
    /// BiCGSTAB iterations (0 when the start was already converged).
    pub iterations: usize,
    /// ‖D⁻¹(b − A x)‖₂ / ‖D⁻¹ b‖₂ (absolute when D⁻¹b = 0).
    pub residual: f64,
}

/// a · b in a fixed order (chunked, see the module documentation).
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let partial: Vec<f64> = a
        .par_chunks(CHUNK)
        .zip(b.par_chunks(CHUNK))
        .map(|(x, y)| x.iter().zip(y).map(|(p, q)| p * q).sum::<f64>())
        .collect();
    partial.iter().sum()
}

/// y = D⁻¹ A x.
fn apply(a: &SparseRows, inv_diag: &[f64], x: &[f64], y: &mut [f64]) {
    a.mul_into(x, y);
    y.par_iter_mut().zip(inv_diag.par_iter()).for_each(|(y, d)| *y *= d);
}

/// Solves A x = b from the initial guess in `x` (warm start). `inv_diag` is the Jacobi preconditioner 1/A_ii.
/// Converged: `Ok`; not converged within `max_iter` iterations, or broken down: `Err` with the last residual
/// (`x` then holds the last iterate).
pub fn solve(
    a: &SparseRows,
    b: &[f64],
    x: &mut [f64],
    inv_diag: &[f64],
    tol: f64,
    max_iter: usize,
) -> Result<SolveStats, SolveStats> {
    let n = b.len();
    // ‖D⁻¹b‖ in the order of `dot`, without holding D⁻¹b (one vector less at the PPE's peak of memory).
    let bt = |(b, d): (&f64, &f64)| b * d;
    let partial: Vec<f64> = b
        .par_chunks(CHUNK)
        .zip(inv_diag.par_chunks(CHUNK))
        .map(|(b, d)| b.iter().zip(d).map(bt).map(|t| t * t).sum::<f64>())
        .collect();
    let b_norm = partial.iter().sum::<f64>().sqrt();
    let scale = if b_norm > 0.0 { b_norm } else { 1.0 };
    // r = D⁻¹b − D⁻¹A x
    let mut r = vec![0.0; n];
    apply(a, inv_diag, x, &mut r);
    r.par_iter_mut()
        .zip(b.par_iter().zip(inv_diag.par_iter()))
        .for_each(|(r, bd)| *r = bt(bd) - *r);
    let mut res = dot(&r, &r).sqrt() / scale;
    if res <= tol {
        return Ok(SolveStats {
            iterations: 0,
            residual: res,
        });
    }
    let mut r_hat = r.clone();
    let (mut rho, mut alpha, mut omega) = (1.0, 1.0, 1.0);
    let mut restarts = 0;
    let mut v = vec![0.0; n];
    let mut p = vec![0.0; n];
    let mut s = vec![0.0; n];
    let mut t = vec![0.0; n];
    for it in 1..=max_iter {
        // van der Vorst 1992, Alg. BiCGSTAB (on the left-preconditioned system)
        let mut rho_new = dot(&r_hat, &r);
        if rho_new.abs() <= 1e-30 * dot(&r, &r) || omega == 0.0 {
            // Breakdown: restart with the current residual as the shadow residual (at most MAX_RESTARTS times).
            if restarts == MAX_RESTARTS {
                return Err(SolveStats {
                    iterations: it - 1,
                    residual: res,
                });
            }
            restarts += 1;
            r_hat.copy_from_slice(&r);
            (rho, alpha, omega) = (1.0, 1.0, 1.0);
            p.iter_mut().for_each(|p| *p = 0.0);
            v.iter_mut().for_each(|v| *v = 0.0);
            rho_new = dot(&r_hat, &r);
        }
        if !rho_new.is_finite() {
            return Err(SolveStats {
                iterations: it - 1,
                residual: res,
            });
        }
        let beta = (rho_new / rho) * (alpha / omega);
        rho = rho_new;
        p.par_iter_mut()
            .zip(r.par_iter().zip(v.par_iter()))
            .for_each(|(p, (r, v))| *p = r + beta * (*p - omega * v));
        apply(a, inv_diag, &p, &mut v);
        let rv = dot(&r_hat, &v);
        if rv == 0.0 || !rv.is_finite() {
            if rv == 0.0 && restarts < MAX_RESTARTS {
                // Breakdown: restart on the next iteration.
                restarts += 1;
                r_hat.copy_from_slice(&r);
                (rho, alpha, omega) = (1.0, 1.0, 1.0);
                p.iter_mut().for_each(|p| *p = 0.0);
                v.iter_mut().for_each(|v| *v = 0.0);
                continue;
            }
            return Err(SolveStats {
                iterations: it - 1,
                residual: res,
            });
        }
        alpha = rho / rv;
        s.par_iter_mut()
            .zip(r.par_iter().zip(v.par_iter()))
            .for_each(|(s, (r, v))| *s = r - alpha * v);
        let s_res = dot(&s, &s).sqrt() / scale;
        if s_res <= tol {
            x.par_iter_mut().zip(p.par_iter()).for_each(|(x, p)| *x += alpha * p);
            return Ok(SolveStats {
                iterations: it,
                residual: s_res,
            });
        }
        apply(a, inv_diag, &s, &mut t);
        let tt = dot(&t, &t);
        omega = if tt > 0.0 { dot(&t, &s) / tt } else { 0.0 };
        x.par_iter_mut()
            .zip(p.par_iter().zip(s.par_iter()))
            .for_each(|(x, (p, s))| *x += alpha * p + omega * s);
        r.par_iter_mut()
            .zip(s.par_iter().zip(t.par_iter()))
            .for_each(|(r, (s, t))| *r = s - omega * t);
        res = dot(&r, &r).sqrt() / scale;
        if !res.is_finite() {
            return Err(SolveStats {
                iterations: it,
                residual: res,
            });
        }
        if res <= tol {
            return Ok(SolveStats {
                iterations: it,
                residual: res,
            });
        }
    }
    Err(SolveStats {
        iterations: max_iter,
        residual: res,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_small_nonsymmetric_system() {
        // 1D Laplacian with an asymmetric last row (like a wall row).
        let n = 50;
        let rows: Vec<Vec<(u32, f64)>> = (0..n)
            .map(|i| {
                if i == 0 {
                    vec![(0, 1.0)]
                } else if i == n - 1 {
                    vec![(i as u32, 1.0), (i as u32 - 1, -1.0)]
                } else {
                    vec![(i as u32, 2.0), (i as u32 - 1, -1.0), (i as u32 + 1, -1.0)]
                }
            })
            .collect();
        let a = SparseRows::from_rows(&rows);
        let b: Vec<f64> = (0..n).map(|i| if i == n - 1 { 0.5 } else { 0.1 }).collect();
        let inv: Vec<f64> = a.diagonal().iter().map(|d| 1.0 / d).collect();
        let mut x = vec![0.0; n];
        let stats = solve(&a, &b, &mut x, &inv, 1e-10, 500).expect("converges");
        let mut ax = vec![0.0; n];
        a.mul_into(&x, &mut ax);
        let err = ax.iter().zip(&b).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
        assert!(err < 1e-7, "max |Ax − b| = {err}, {stats:?}");
    }
}
