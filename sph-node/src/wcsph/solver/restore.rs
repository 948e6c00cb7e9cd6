//! A [`WcsphSolver`]'s state for a checkpoint, and the solver continued from it (see [`crate::restore`] for the
//! checks). Saved: the particles, the walls' pressures and densities, the accelerations of the current time level
//! (the next step's first half kick reads them), the wall guard's count, and, when the state has been edited since
//! the last step, the positions of the last neighbour search (that step's first density rate and XSPH read them).
//! Not saved: the cell order, the cell bins, the neighbour lists and the scratch, which are functions of the positions
//! ([`crate::neighbors::SortedCells::sort`] orders by cell, then id) and are rebuilt as the step rebuilds them.

use serde::{Deserialize, Serialize};

use super::{Scratch, WcsphSolver};
use crate::fluid_solver::{decode, encode, SavedSolver};
use crate::neighbors::SortedCells;
use crate::restore::{check_state, check_walls, finite2, inside, len, Check};
use crate::wcsph::sorted::Sorted;

/// What a WCSPH solver carries from one step to the next besides particles and walls.
#[derive(Serialize, Deserialize)]
struct Own {
    /// Accelerations at the current time level, in id order.
    accel: Vec<[f64; 2]>,
    /// [`WcsphSolver::wall_pushes`].
    wall_pushes: (u64, u64),
    /// Positions of the last neighbour search, in id order, when the state was edited since ([`WcsphSolver::state_mut`]).
    searched: Option<Vec<[f64; 2]>>,
}

impl WcsphSolver {
    /// The state for a checkpoint.
    pub(crate) fn save_state(&self) -> SavedSolver {
        let searched = self.state_edited.then(|| {
            let s = &self.sorted;
            s.slot.iter().map(|&k| s.x[k as usize]).collect()
        });
        let own = Own {
            accel: self.accel.clone(),
            wall_pushes: self.wall_pushes,
            searched,
        };
        SavedSolver {
            solver: "wcsph".into(),
            state: self.state.clone(),
            walls: self.walls.clone(),
            own: encode(&own),
        }
    }

    /// Continue from `saved` (see [`crate::FluidSolver::restore`]).
    pub(crate) fn restore_state(&mut self, saved: SavedSolver) -> Check {
        let own: Own = decode("wcsph state", &saved.own)?;
        check_state(&saved.state, &self.state)?;
        check_walls(&saved.walls, &self.walls)?;
        let nf = self.state.len();
        let domain = &self.params.domain;
        inside("state.x", &saved.state.x, domain)?;
        len("accel", &own.accel, nf, "fluid particles")?;
        finite2("accel", &own.accel)?;
        if let Some(x) = &own.searched {
            len("searched", x, nf, "fluid particles")?;
            finite2("searched", x)?;
            inside("searched", x, domain)?;
        }
        self.state = saved.state;
        self.walls = saved.walls;
        self.accel = own.accel;
        self.wall_pushes = own.wall_pushes;
        // The working copy in id order, then sorted by cell as `rebuild_neighbors` sorts it after a drift.
        let mut sorted = Sorted::new(&self.state, &self.walls);
        if let Some(x) = &own.searched {
            sorted.x[..nf].copy_from_slice(x);
        }
        sorted.accel.copy_from_slice(&self.accel);
        self.sorted = sorted;
        self.scratch = Scratch {
            cells: SortedCells::new(&self.walls.x),
            ..Scratch::default()
        };
        self.rebuild_neighbors();
        let s = &mut self.sorted;
        for ((pr2, p), r) in s.pr2.iter_mut().zip(&s.p).zip(&s.rho) {
            *pr2 = p / (r * r);
        }
        self.state_edited = own.searched.is_some();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::restore::tests::tank;

    /// The tank's solver after a few steps.
    fn stepped() -> WcsphSolver {
        let mut solver = WcsphSolver::new(&tank("wcsph", &[])).unwrap();
        for _ in 0..5 {
            let dt = solver.stable_dt();
            solver.step(dt).unwrap();
        }
        solver
    }

    /// The refusal of the stepped solver's saved state after `edit`; the solver it is restored into is unchanged.
    fn refused(edit: impl FnOnce(&mut Own)) -> String {
        let solver = stepped();
        let mut saved = solver.save_state();
        let mut own: Own = decode("", &saved.own).unwrap();
        edit(&mut own);
        saved.own = encode(&own);
        let mut fresh = WcsphSolver::new(&tank("wcsph", &[])).unwrap();
        let before = encode(&fresh.save_state());
        let e = fresh.restore_state(saved).expect_err("refused");
        assert_eq!(encode(&fresh.save_state()), before, "the refused state is not taken");
        e
    }

    #[test]
    fn accelerations_and_search_positions_that_do_not_hold_together_are_refused() {
        let n = stepped().state.len();
        let e = refused(|o| {
            o.accel.pop();
        });
        assert_eq!(
            e,
            format!("accel holds {} entries, there are {n} fluid particles", n - 1)
        );
        let e = refused(|o| o.accel[4] = [f64::NAN, 0.0]);
        assert_eq!(e, "accel[4] = [NaN, 0.0] is not finite");
        let e = refused(|o| o.searched = Some(vec![[0.0; 2]; 3]));
        assert_eq!(e, format!("searched holds 3 entries, there are {n} fluid particles"));
        let e = refused(|o| o.searched = Some(vec![[1e200, 0.0]; n]));
        assert_eq!(e, "searched[0] = [1e200, 0.0] is outside the fluid's domain");
    }

    /// The cell order, the cell bins and the neighbour lists rebuilt on restore are those the step left.
    #[test]
    fn the_rebuilt_caches_are_the_steps() {
        let solver = stepped();
        let mut fresh = WcsphSolver::new(&tank("wcsph", &[])).unwrap();
        fresh.restore_state(solver.save_state()).unwrap();
        assert_eq!(fresh.sorted.ids, solver.sorted.ids);
        assert_eq!(fresh.scratch.cells.differs_from(&solver.scratch.cells), None);
        assert_eq!(fresh.scratch.list.differs_from(&solver.scratch.list), None);
        let bits = |a: &[f64]| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&fresh.sorted.vol), bits(&solver.sorted.vol));
        assert_eq!(bits(&fresh.sorted.pr2), bits(&solver.sorted.pr2));
    }
}
