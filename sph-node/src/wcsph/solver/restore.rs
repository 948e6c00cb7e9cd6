//! A [`WcsphSolver`]'s state for a checkpoint, and the solver continued from it (see [`crate::restore`] for the
//! checks). Saved: the particles, the walls' pressures and densities, the accelerations of the current time level
//! (the next step's first half kick reads them), the wall guard's count, and, when the state has been edited since
//! the last step, the positions of the last neighbour search (that step's first density rate and XSPH read them),
//! and, with Verlet candidate lists, the positions they were gathered at.
//! Not saved: the cell order, the cell bins, the candidates, the neighbour lists and the scratch, which are functions
//! of those positions ([`crate::neighbors::SortedCells::sort`] orders by cell, then id; the candidates are gathered
//! from those cells and the lists filtered from them) and are rebuilt as the step rebuilt them.

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
    /// Positions the Verlet candidates were gathered at, in id order, when the solver has them
    /// ([`crate::neighbors::VerletCandidates::reference`]).
    candidates_at: Option<Vec<[f64; 2]>>,
}

impl WcsphSolver {
    /// The state for a checkpoint.
    pub(crate) fn save_state(&self) -> SavedSolver {
        let searched = self.state_edited.then(|| {
            let s = &self.sorted;
            s.slot.iter().map(|&k| s.x[k as usize]).collect()
        });
        let candidates_at = self.scratch.verlet.as_ref().map(|v| {
            let r = v.reference();
            self.sorted.slot.iter().map(|&k| r[k as usize]).collect()
        });
        let own = Own {
            accel: self.accel.clone(),
            wall_pushes: self.wall_pushes,
            searched,
            candidates_at,
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
        let verlet = super::verlet_candidates(&self.wcsph, &self.params);
        match (&verlet, &own.candidates_at) {
            (Some(v), Some(at)) => {
                len("candidates_at", at, nf, "fluid particles")?;
                finite2("candidates_at", at)?;
                inside("candidates_at", at, domain)?;
                let searched = own.searched.as_ref().unwrap_or(&saved.state.x);
                if !v.within_half_skin(searched, at) {
                    return Err(format!(
                        "candidates_at: a particle is half the Verlet skin ({} m) or more from its searched position: \
                         the candidates would miss neighbours",
                        0.5 * v.skin()
                    ));
                }
            }
            (None, Some(_)) => return Err("candidates_at is saved, but the scene's fluid.verlet_skin is 0".into()),
            (Some(_), None) => {
                return Err("candidates_at is missing: the scene's fluid.verlet_skin is not 0".into());
            }
            (None, None) => {}
        }
        self.state = saved.state;
        self.walls = saved.walls;
        self.accel = own.accel;
        self.wall_pushes = own.wall_pushes;
        // The working copy in id order, then sorted by cell as `rebuild_neighbors` sorted it: at the positions the
        // candidates were gathered at, when there are candidates, else at those of the last search.
        let edited = own.searched.is_some();
        let searched = own.searched.unwrap_or_else(|| self.state.x.clone());
        let mut sorted = Sorted::new(&self.state, &self.walls);
        sorted.x[..nf].copy_from_slice(own.candidates_at.as_ref().unwrap_or(&searched));
        sorted.accel.copy_from_slice(&self.accel);
        self.sorted = sorted;
        self.scratch = Scratch {
            cells: SortedCells::new(&self.walls.x),
            verlet,
            ..Scratch::default()
        };
        // The fresh scratch has no candidates: the sort runs (and gathers them, when on).
        self.resort();
        if own.candidates_at.is_some() {
            // The lists of the last search are filtered from the candidates at its positions.
            let s = &mut self.sorted;
            for (x, &id) in s.x[..nf].iter_mut().zip(&s.ids) {
                *x = searched[id as usize];
            }
        }
        self.rebuild_lists();
        let s = &mut self.sorted;
        for ((pr2, p), r) in s.pr2.iter_mut().zip(&s.p).zip(&s.rho) {
            *pr2 = p / (r * r);
        }
        self.state_edited = edited;
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
        assert_eq!(e, "accel[4] = [NaN, 0.0] is not finite within ±1e50");
        let e = refused(|o| o.searched = Some(vec![[0.0; 2]; 3]));
        assert_eq!(e, format!("searched holds 3 entries, there are {n} fluid particles"));
        let e = refused(|o| o.searched = Some(vec![[1e20, 0.0]; n]));
        assert_eq!(e, "searched[0] = [1e20, 0.0] is outside the fluid's domain");
        let e = refused(|o| o.candidates_at = None);
        assert_eq!(e, "candidates_at is missing: the scene's fluid.verlet_skin is not 0");
        let e = refused(|o| {
            o.candidates_at.as_mut().unwrap().pop();
        });
        assert_eq!(
            e,
            format!("candidates_at holds {} entries, there are {n} fluid particles", n - 1)
        );
        let skin = stepped().scratch.verlet.as_ref().map(|v| v.skin()).unwrap();
        let e = refused(|o| o.candidates_at.as_mut().unwrap()[7][0] += 0.6 * skin);
        assert!(
            e.starts_with("candidates_at: a particle is half the Verlet skin"),
            "{e}"
        );
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
        let (a, b) = (fresh.scratch.verlet.as_ref(), solver.scratch.verlet.as_ref());
        assert!(b.is_some(), "the scene's default searches with Verlet candidates");
        assert_eq!(a.zip(b).and_then(|(a, b)| a.differs_from(b)), None);
        let bits = |a: &[f64]| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&fresh.sorted.vol), bits(&solver.sorted.vol));
        assert_eq!(bits(&fresh.sorted.pr2), bits(&solver.sorted.pr2));
    }
}
