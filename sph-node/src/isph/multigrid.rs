//! Aggregation multigrid: the preconditioner of the PPE's BiCGSTAB (issue 20; [`super::bicgstab`]).
//!
//! The PPE is rebuilt every step (the particles move), so the hierarchy must cost a few products of the matrix, not
//! the hundreds of iterations that a Jacobi preconditioner needs at 80,000 particles. Plain (unsmoothed) aggregation
//! does (Vaněk, Mandel & Brezina 1996 without the smoothing of the prolongator; Notay 2010 for aggregation AMG as a
//! Krylov preconditioner, where a W-cycle keeps the two-grid rate that a V-cycle loses with depth):
//!
//! * Aggregates are geometric ([`coarsen`]): the particles (fluid and walls) in one cell of side 2 Δx, then 2×2
//!   blocks of those cells at each coarser level, until at most [`COARSEST`] unknowns are left. Dirichlet rows
//!   (p = 0 at a free surface) belong to no aggregate: the smoother solves them exactly.
//! * P is piecewise constant (1 from an aggregate to each of its members), the coarse operator Galerkin's,
//!   A_c = Pᵀ A P.
//! * One W-cycle: damped Jacobi (ω = [`OMEGA`], 1 on Dirichlet rows), one sweep before and one after the coarse
//!   correction, the coarse level visited twice ([`GAMMA`]); the coarsest level is solved by a dense LU with
//!   partial pivoting ([`dense_lu`]).
//!
//! The cycle is a fixed linear operator (no inner Krylov, no line search), as BiCGSTAB needs. Every sum is in a
//! fixed order (rows in their stored order, aggregates' members in index order), so the result is bit-identical
//! for any number of threads.
//!
//! Measured on the dam break (`cargo bench -p sph-node --bench particle_steps`, `SPH_BENCH_SOLVER=isph`, first
//! steps): 242 → 9 BiCGSTAB iterations at 20,000 particles, 725 → 11 at 80,000 (docs/PERFORMANCE.md).

use rayon::prelude::*;

use super::sparse::SparseRows;

pub mod coarsen;
pub mod dense_lu;

use coarsen::{is_dirichlet, Aggregates, Csr, Rows};
use dense_lu::DenseLu;

/// Most unknowns left to the dense LU of the coarsest level.
pub const COARSEST: usize = 100;
/// Jacobi damping of the smoother.
pub const OMEGA: f64 = 2.0 / 3.0;
/// Visits of the next level per cycle (2: a W-cycle).
pub const GAMMA: usize = 2;

/// One level: its aggregation into the next, the next level's operator and the cycle's work vectors.
#[derive(Clone, Debug)]
struct Level {
    aggregates: Aggregates,
    /// ω/A_ii (1/A_ii on a Dirichlet row: exact there).
    weight: Vec<f64>,
    /// The operator of the next level, Pᵀ A P.
    coarse: Csr,
    /// f − A x on this level.
    res: Vec<f64>,
    /// The next level's right-hand side, solution, residual and correction.
    fc: Vec<f64>,
    xc: Vec<f64>,
    rc: Vec<f64>,
    dc: Vec<f64>,
}

impl Level {
    fn new<A: Rows>(a: &A, aggregates: Aggregates) -> Self {
        let coarse = aggregates.galerkin(a);
        let nc = aggregates.len();
        Self {
            weight: weights(a),
            coarse,
            res: vec![0.0; a.n()],
            fc: vec![0.0; nc],
            xc: vec![0.0; nc],
            rc: vec![0.0; nc],
            dc: vec![0.0; nc],
            aggregates,
        }
    }
}

/// The hierarchy of one PPE.
#[derive(Clone, Debug)]
pub struct Multigrid {
    levels: Vec<Level>,
    coarsest: Option<DenseLu>,
    /// ω/A_ii of the coarsest level, smoothed instead when its LU fails.
    coarsest_weight: Vec<f64>,
}

/// ω/A_ii, or 1/A_ii on a Dirichlet row; 0 where the diagonal is 0 or not finite.
fn weights<A: Rows>(a: &A) -> Vec<f64> {
    (0..a.n())
        .into_par_iter()
        .with_min_len(256)
        .map(|i| {
            let (c, v) = a.row(i);
            let d: f64 = c.iter().zip(v).filter(|(&c, _)| c as usize == i).map(|(_, &v)| v).sum();
            let w = if is_dirichlet(a, i) { 1.0 } else { OMEGA };
            if d != 0.0 && d.is_finite() {
                w / d
            } else {
                0.0
            }
        })
        .collect()
}

/// One damped Jacobi sweep: x += W (f − A x).
fn sweep<A: Rows>(a: &A, weight: &[f64], f: &[f64], x: &mut [f64], res: &mut [f64]) {
    a.residual(f, x, res);
    x.par_iter_mut()
        .zip(res.par_iter().zip(weight.par_iter()))
        .with_min_len(1024)
        .for_each(|(x, (r, w))| *x += w * r);
}

impl Multigrid {
    /// The hierarchy of `a` (the PPE, any row scaling), its unknowns at `x` (fluid and walls, as `a`'s rows),
    /// aggregated on cells of side `cell` (2 Δx) and then 2×2 blocks of them.
    pub fn build(a: &SparseRows, x: &[[f64; 2]], cell: f64) -> Self {
        let n = a.n();
        assert_eq!(x.len(), n, "one position per unknown");
        let lo = x
            .iter()
            .fold([f64::INFINITY; 2], |lo, p| [lo[0].min(p[0]), lo[1].min(p[1])]);
        let keys: Vec<[i64; 2]> = x
            .par_iter()
            .map(|p| [0, 1].map(|k| ((p[k] - lo[k]) / cell).floor() as i64))
            .collect();
        let skip: Vec<bool> = (0..n).into_par_iter().map(|i| is_dirichlet(a, i)).collect();
        let mut levels = vec![Level::new(a, Aggregates::by_cell(&keys, &skip))];
        loop {
            let last = levels.last().expect("one level");
            let size = last.coarse.n();
            if size <= COARSEST {
                break;
            }
            let keys: Vec<[i64; 2]> = last.aggregates.keys.iter().map(|k| [k[0] >> 1, k[1] >> 1]).collect();
            let aggregates = Aggregates::by_cell(&keys, &vec![false; size]);
            if aggregates.len() == size {
                break; // 2×2 blocks no longer merge anything
            }
            let level = Level::new(&last.coarse, aggregates);
            levels.push(level);
        }
        let last = &levels.last().expect("one level").coarse;
        let coarsest = if last.n() <= 4 * COARSEST {
            DenseLu::factor(last)
        } else {
            None
        };
        let coarsest_weight = weights(last);
        Self {
            levels,
            coarsest,
            coarsest_weight,
        }
    }

    /// Levels below the finest (the coarsest included).
    pub fn depth(&self) -> usize {
        self.levels.len()
    }

    /// z = M⁻¹ r: one W-cycle on `a` (the matrix the hierarchy was built from) from z = 0.
    pub fn apply(&mut self, a: &SparseRows, r: &[f64], z: &mut [f64]) {
        cycle(&mut self.levels, &self.coarsest, &self.coarsest_weight, a, r, z);
    }
}

/// The cycle from `levels[0]` down, on `a` (the operator of `levels[0]`), from x = 0.
fn cycle<A: Rows>(
    levels: &mut [Level],
    coarsest: &Option<DenseLu>,
    coarsest_weight: &[f64],
    a: &A,
    f: &[f64],
    x: &mut [f64],
) {
    let (level, below) = levels.split_first_mut().expect("a level");
    // Pre-smoothing from x = 0: the sweep is x = W f.
    x.par_iter_mut()
        .zip(f.par_iter().zip(level.weight.par_iter()))
        .with_min_len(1024)
        .for_each(|(x, (f, w))| *x = w * f);
    // Coarse correction: f_c = Pᵀ (f − A x), x += P A_c⁻¹ f_c.
    a.residual(f, x, &mut level.res);
    level.aggregates.restrict(&level.res, &mut level.fc);
    if below.is_empty() {
        match coarsest {
            Some(lu) => lu.solve(&level.fc, &mut level.xc),
            None => {
                // No LU (a zero pivot): smooth the coarsest level instead.
                level.xc.iter_mut().for_each(|x| *x = 0.0);
                for _ in 0..20 {
                    sweep(&level.coarse, coarsest_weight, &level.fc, &mut level.xc, &mut level.rc);
                }
            }
        }
    } else {
        cycle(
            below,
            coarsest,
            coarsest_weight,
            &level.coarse,
            &level.fc,
            &mut level.xc,
        );
        for _ in 1..GAMMA {
            // W-cycle: the next level again, on what the first visit left
            level.coarse.residual(&level.fc, &level.xc, &mut level.rc);
            cycle(
                below,
                coarsest,
                coarsest_weight,
                &level.coarse,
                &level.rc,
                &mut level.dc,
            );
            level.xc.iter_mut().zip(&level.dc).for_each(|(x, d)| *x += d);
        }
    }
    level.aggregates.prolong_add(&level.xc, x);
    // Post-smoothing
    sweep(a, &level.weight, f, x, &mut level.res);
}

/// The cycle of a hierarchy on the matrix it was built from, as BiCGSTAB's preconditioner.
pub struct Cycle<'a> {
    /// The hierarchy.
    pub multigrid: &'a mut Multigrid,
    /// The matrix it was built from.
    pub a: &'a SparseRows,
}

impl super::bicgstab::Preconditioner for Cycle<'_> {
    fn apply(&mut self, r: &[f64], z: &mut [f64]) {
        self.multigrid.apply(self.a, r, z);
    }
}

#[cfg(test)]
mod tests {
    use super::coarsen::NONE;
    use super::*;
    use crate::isph::bicgstab;

    /// The 5-point Laplacian on an n × n grid of spacing 1 with p = 0 on its top row (Dirichlet), the other sides
    /// closed (Neumann), and the grid's positions.
    fn laplacian(n: usize) -> (SparseRows, Vec<[f64; 2]>) {
        let id = |ix: usize, iy: usize| (iy * n + ix) as u32;
        let mut rows = Vec::new();
        let mut x = Vec::new();
        for iy in 0..n {
            for ix in 0..n {
                x.push([ix as f64, iy as f64]);
                if iy == n - 1 {
                    rows.push(vec![(id(ix, iy), 1.0)]);
                    continue;
                }
                let mut nb = Vec::new();
                if ix > 0 {
                    nb.push(id(ix - 1, iy));
                }
                if ix + 1 < n {
                    nb.push(id(ix + 1, iy));
                }
                if iy > 0 {
                    nb.push(id(ix, iy - 1));
                }
                nb.push(id(ix, iy + 1));
                let mut row = vec![(id(ix, iy), nb.len() as f64)];
                row.extend(nb.into_iter().map(|j| (j, -1.0)));
                rows.push(row);
            }
        }
        (SparseRows::from_rows(&rows), x)
    }

    /// BiCGSTAB iterations to 1e-8 on the Jacobi-scaled `laplacian(n)`, with the cycle or without, and the largest
    /// error against the solution the right-hand side was made from.
    fn iterations(n: usize, multigrid: bool) -> (usize, f64) {
        let (mut a, x) = laplacian(n);
        let exact: Vec<f64> = (0..n * n)
            .map(|i| {
                if i / n == n - 1 {
                    0.0
                } else {
                    ((i % n) as f64 * 0.3).sin() + (i / n) as f64 * 0.1
                }
            })
            .collect();
        let mut b = vec![0.0; n * n];
        a.mul_into(&exact, &mut b);
        let scale: Vec<f64> = a.diagonal().iter().map(|d| 1.0 / d).collect();
        a.scale_rows(&scale, &mut b);
        let mut p = vec![0.0; n * n];
        let stats = if multigrid {
            let mut mg = Multigrid::build(&a, &x, 2.0);
            let mut m = Cycle {
                multigrid: &mut mg,
                a: &a,
            };
            bicgstab::solve(&a, &b, &mut p, &mut m, 1e-8, 5000)
        } else {
            bicgstab::solve(&a, &b, &mut p, &mut bicgstab::Identity, 1e-8, 5000)
        }
        .expect("converges");
        let err = p.iter().zip(&exact).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        (stats.iterations, err)
    }

    #[test]
    fn the_cycle_keeps_the_iterations_of_a_poisson_problem_flat_in_its_size() {
        // 64² and 256² unknowns (3 and 5 levels): Jacobi's iterations grow with n, the cycle's stay within a few.
        let (mg64, e64) = iterations(64, true);
        let (mg256, e256) = iterations(256, true);
        let (jac256, _) = iterations(256, false);
        eprintln!(
            "iterations: cycle {mg64} (64²), {mg256} (256²); Jacobi {jac256} (256²); errors {e64:.1e}, {e256:.1e}"
        );
        assert!(
            mg256 <= mg64 + mg64 / 2 + 2 && mg256 <= 30,
            "cycle: {mg64} → {mg256} iterations"
        );
        assert!(jac256 > 5 * mg256, "Jacobi {jac256} against the cycle's {mg256}");
        assert!(e64 < 1e-5 && e256 < 1e-4, "errors {e64}, {e256}");
    }

    #[test]
    fn the_coarse_operator_sums_its_members_rows() {
        let (a, x) = laplacian(8);
        let mg = Multigrid::build(&a, &x, 2.0);
        let l = &mg.levels[0];
        // The Dirichlet top row is in no aggregate; 7 rows × 8 columns in 2×2 cells: 4 × 4 aggregates.
        assert_eq!(l.aggregates.len(), 16);
        assert!((56..64).all(|i| l.aggregates.agg[i] == NONE));
        // A_c 1 = Pᵀ A 1: the row sums of the members, less the Dirichlet columns.
        let ones = vec![1.0; 16];
        let mut y = vec![0.0; 16];
        l.coarse.residual(&[0.0; 16], &ones, &mut y);
        let want: Vec<f64> = (0..16)
            .map(|c| {
                l.aggregates
                    .of(c)
                    .iter()
                    .map(|&i| {
                        let (cols, vals) = a.row(i as usize);
                        cols.iter()
                            .zip(vals)
                            .filter(|(&j, _)| l.aggregates.agg[j as usize] != NONE)
                            .map(|(_, v)| v)
                            .sum::<f64>()
                    })
                    .sum()
            })
            .collect();
        for (y, w) in y.iter().zip(&want) {
            assert!((-y - w).abs() < 1e-12, "{y} vs {w}");
        }
    }
}
