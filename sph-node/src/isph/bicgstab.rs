//! BiCGSTAB (van der Vorst 1992) with a right preconditioner for the PPE (`DESIGN.md` §4.3, step 4).
//!
//! The caller scales every row to a unit diagonal first ([`SparseRows::scale_rows`]: the Jacobi scaling), so the
//! residual the iteration reports and tests, ‖b − A x‖₂ / ‖b‖₂ of the scaled system, is ‖D⁻¹(b − A x)‖₂ /
//! ‖D⁻¹ b‖₂ of the assembled one, in pressure units. The preconditioner M ([`super::multigrid`], or none) is
//! applied on the right, A M⁻¹ y = b with x = M⁻¹ y, so that the residual is the true one whatever M is. Dot
//! products are summed in fixed chunks of [`CHUNK`] entries, each chunk in index order, then the chunk sums in
//! order, so the result is bit-identical for any number of threads.

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
    /// ‖b − A x‖₂ / ‖b‖₂ (absolute when b = 0).
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

/// z = M⁻¹ r.
pub trait Preconditioner {
    /// z = M⁻¹ r (`z` is overwritten).
    fn apply(&mut self, r: &[f64], z: &mut [f64]);
}

/// M = I (on a system scaled to a unit diagonal: Jacobi's preconditioner).
pub struct Identity;

impl Preconditioner for Identity {
    fn apply(&mut self, r: &[f64], z: &mut [f64]) {
        z.copy_from_slice(r);
    }
}

/// Resets the search directions after a breakdown: the current residual becomes the shadow residual.
fn restart(r_hat: &mut [f64], r: &[f64], p: &mut [f64], v: &mut [f64]) -> (f64, f64, f64) {
    r_hat.copy_from_slice(r);
    p.iter_mut().for_each(|p| *p = 0.0);
    v.iter_mut().for_each(|v| *v = 0.0);
    (1.0, 1.0, 1.0)
}

/// Solves A x = b from the initial guess in `x` (warm start), preconditioned by `m` on the right.
/// Converged: `Ok`; not converged within `max_iter` iterations, or broken down: `Err` with the last residual
/// (`x` then holds the last iterate).
pub fn solve<M: Preconditioner>(
    a: &SparseRows,
    b: &[f64],
    x: &mut [f64],
    m: &mut M,
    tol: f64,
    max_iter: usize,
) -> Result<SolveStats, SolveStats> {
    let n = b.len();
    let b_norm = dot(b, b).sqrt();
    let scale = if b_norm > 0.0 { b_norm } else { 1.0 };
    // r = b − A x
    let mut r = vec![0.0; n];
    a.residual_into(b, x, &mut r);
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
    // M⁻¹p and M⁻¹s
    let mut y = vec![0.0; n];
    let mut z = vec![0.0; n];
    let mut s = vec![0.0; n];
    let mut t = vec![0.0; n];
    let fail = |iterations, residual| Err(SolveStats { iterations, residual });
    for it in 1..=max_iter {
        // van der Vorst 1992, Alg. 3.1 (BiCGSTAB), preconditioned on the right
        let mut rho_new = dot(&r_hat, &r);
        if rho_new.abs() <= 1e-30 * dot(&r, &r) || omega == 0.0 {
            // Breakdown: restart with the current residual as the shadow residual (at most MAX_RESTARTS times).
            if restarts == MAX_RESTARTS {
                return fail(it - 1, res);
            }
            restarts += 1;
            (rho, alpha, omega) = restart(&mut r_hat, &r, &mut p, &mut v);
            rho_new = dot(&r_hat, &r);
        }
        if !rho_new.is_finite() {
            return fail(it - 1, res);
        }
        let beta = (rho_new / rho) * (alpha / omega);
        rho = rho_new;
        p.par_iter_mut()
            .zip(r.par_iter().zip(v.par_iter()))
            .for_each(|(p, (r, v))| *p = r + beta * (*p - omega * v));
        m.apply(&p, &mut y);
        a.mul_into(&y, &mut v);
        let rv = dot(&r_hat, &v);
        if rv == 0.0 || !rv.is_finite() {
            if rv == 0.0 && restarts < MAX_RESTARTS {
                // Breakdown: restart on the next iteration.
                restarts += 1;
                (rho, alpha, omega) = restart(&mut r_hat, &r, &mut p, &mut v);
                continue;
            }
            return fail(it - 1, res);
        }
        alpha = rho / rv;
        s.par_iter_mut()
            .zip(r.par_iter().zip(v.par_iter()))
            .for_each(|(s, (r, v))| *s = r - alpha * v);
        let s_res = dot(&s, &s).sqrt() / scale;
        if s_res <= tol {
            x.par_iter_mut().zip(y.par_iter()).for_each(|(x, y)| *x += alpha * y);
            return Ok(SolveStats {
                iterations: it,
                residual: s_res,
            });
        }
        m.apply(&s, &mut z);
        a.mul_into(&z, &mut t);
        let tt = dot(&t, &t);
        omega = if tt > 0.0 { dot(&t, &s) / tt } else { 0.0 };
        x.par_iter_mut()
            .zip(y.par_iter().zip(z.par_iter()))
            .for_each(|(x, (y, z))| *x += alpha * y + omega * z);
        r.par_iter_mut()
            .zip(s.par_iter().zip(t.par_iter()))
            .for_each(|(r, (s, t))| *r = s - omega * t);
        res = dot(&r, &r).sqrt() / scale;
        if !res.is_finite() {
            return fail(it, res);
        }
        if res <= tol {
            return Ok(SolveStats {
                iterations: it,
                residual: res,
            });
        }
    }
    fail(max_iter, res)
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
        let mut x = vec![0.0; n];
        let stats = solve(&a, &b, &mut x, &mut Identity, 1e-10, 500).expect("converges");
        let mut ax = vec![0.0; n];
        a.mul_into(&x, &mut ax);
        let err = ax.iter().zip(&b).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
        assert!(err < 1e-7, "max |Ax − b| = {err}, {stats:?}");
    }
}
