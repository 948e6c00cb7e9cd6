//! The PPE's linear solve (`DESIGN.md` §4.3, step 4): Jacobi scaling, then BiCGSTAB with the preconditioner the
//! options name.

use super::IsphSolver;
use crate::isph::bicgstab::{self, SolveStats};
use crate::isph::multigrid::{Cycle, Multigrid};
use crate::isph::ppe::SparseRows;
use crate::isph::Preconditioning;

impl IsphSolver {
    /// Solves A p = b from the warm start in `p`. Every row of `a` and `b` is scaled to a unit diagonal first (the
    /// residual [`bicgstab::solve`] tests is then ‖D⁻¹(b − A p)‖ / ‖D⁻¹b‖, in pressure units); `a` and `b` are left
    /// scaled.
    pub(super) fn solve_pressure(
        &self,
        a: &mut SparseRows,
        b: &mut [f64],
        p: &mut [f64],
    ) -> Result<SolveStats, SolveStats> {
        let inv_diag: Vec<f64> = a
            .diagonal()
            .iter()
            .map(|&d| if d != 0.0 { 1.0 / d } else { 1.0 })
            .collect();
        a.scale_rows(&inv_diag, b);
        drop(inv_diag);
        let (tol, max_iter) = (self.options.tolerance, self.options.max_iterations);
        match self.options.preconditioner {
            Preconditioning::Jacobi => bicgstab::solve(a, b, p, &mut bicgstab::Identity, tol, max_iter),
            Preconditioning::Multigrid => {
                // Aggregates: the particles in cells of 2 Δx, fluid and walls (`multigrid`)
                let mut multigrid = Multigrid::build(a, &self.scratch.x, 2.0 * self.params.dx);
                let mut m = Cycle {
                    multigrid: &mut multigrid,
                    a,
                };
                bicgstab::solve(a, b, p, &mut m, tol, max_iter)
            }
        }
    }
}
