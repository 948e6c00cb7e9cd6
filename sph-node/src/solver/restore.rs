//! The checks on a [`WcsphSolver`] read back from a checkpoint (see [`crate::restore`]).

use crate::neighbors::{NeighborList, SortedCells};
use crate::restore::{check_state, check_walls, finite, finite2, len, permutation, same, same_bits, Check};

use super::WcsphSolver;

impl WcsphSolver {
    /// Check this solver, read back from a checkpoint, against `scene`, the solver the scene builds: everything
    /// that follows from the scene equal to it; the state and the walls whole and finite; the working copy in cell
    /// order (`sorted`) the state's particles in a permutation, with their volumes and p/ρ² as a step leaves them;
    /// the cell bins and neighbour lists those its positions give (built again and compared). `Err` is one line
    /// naming the field, the index and the value.
    pub(crate) fn check_restored(&self, scene: &Self) -> Check {
        same("params", &self.params, &scene.params)?;
        same("options", &self.options, &scene.options)?;
        same("kernel", &self.kernel, &scene.kernel)?;
        same("eos", &self.eos, &scene.eos)?;
        same("cfl", &self.cfl, &scene.cfl)?;
        same("wall_boxes", &self.wall_boxes, &scene.wall_boxes)?;
        check_state(&self.state, &scene.state)?;
        check_walls(&self.walls, &scene.walls)?;
        let (nf, nw) = (self.state.len(), self.walls.len());
        len("accel", &self.accel, nf, "fluid particles")?;
        finite2("accel", &self.accel)?;
        let domain = &self.params.domain;
        if let Some(i) = self.state.x.iter().position(|x| !domain.contains(*x)) {
            return Err(format!(
                "state.x[{i}] = {:?} is outside the fluid's domain",
                self.state.x[i]
            ));
        }
        let s = &self.sorted;
        permutation("sorted.ids", &s.ids, "sorted.slot", &s.slot, nf)?;
        let all = "fluid and wall particles";
        for (field, n) in [("sorted.x", s.x.len()), ("sorted.v", s.v.len())] {
            if n != nf + nw {
                return Err(format!("{field} holds {n} entries, there are {} {all}", nf + nw));
            }
        }
        for (field, values) in [("sorted.rho", &s.rho), ("sorted.p", &s.p), ("sorted.m", &s.m)] {
            len(field, values, nf + nw, all)?;
        }
        // Slot k holds particle ids[k] (in range: `ids` is a permutation of 0..nf), then the walls in their order.
        let by_slot = |fluid: &[[f64; 2]], walls: &[[f64; 2]]| -> Vec<[f64; 2]> {
            let fluid = s
                .ids
                .iter()
                .map(|&id| fluid.get(id as usize).copied().unwrap_or([f64::NAN; 2]));
            fluid.chain(walls.iter().copied()).collect()
        };
        let by_slot1 = |fluid: &[f64], walls: &[f64]| -> Vec<f64> {
            let fluid = s
                .ids
                .iter()
                .map(|&id| fluid.get(id as usize).copied().unwrap_or(f64::NAN));
            fluid.chain(walls.iter().copied()).collect()
        };
        if self.state_edited {
            // The state was handed out for edits that the next step takes over: only the walls must agree.
            finite2("sorted.x", &s.x)?;
            if let Some(k) = s.x[..nf].iter().position(|x| !domain.contains(*x)) {
                return Err(format!("sorted.x[{k}] = {:?} is outside the fluid's domain", s.x[k]));
            }
            finite2("sorted.v", &s.v)?;
            finite("sorted.p", &s.p)?;
            same_bits("sorted.x (walls)", &s.x[nf..], &self.walls.x, "walls.x")?;
        } else {
            same_bits(
                "sorted.x",
                &s.x,
                &by_slot(&self.state.x, &self.walls.x),
                "the state in slot order",
            )?;
            same_bits(
                "sorted.v",
                &s.v,
                &by_slot(&self.state.v, &vec![[0.0; 2]; nw]),
                "the state in slot order",
            )?;
            same_bits(
                "sorted.rho",
                &s.rho,
                &by_slot1(&self.state.rho, &self.walls.rho),
                "the state in slot order",
            )?;
            same_bits(
                "sorted.p",
                &s.p,
                &by_slot1(&self.state.p, &self.walls.p),
                "the state in slot order",
            )?;
        }
        same_bits(
            "sorted.m",
            &s.m,
            &by_slot1(&self.state.m, &self.walls.m),
            "the state in slot order",
        )?;
        same_bits(
            "sorted.accel",
            &s.accel,
            &by_slot(&self.accel, &[]),
            "accel in slot order",
        )?;
        if !s.rho.iter().all(|r| r.is_finite() && *r > 0.0) {
            return Err("sorted.rho holds a density that is not positive".into());
        }
        let vol: Vec<f64> = s.m.iter().zip(&s.rho).map(|(m, r)| m / r).collect();
        same_bits("sorted.vol", &s.vol, &vol, "m/ρ")?;
        let pr2: Vec<f64> = s.p.iter().zip(&s.rho).map(|(p, r)| p / (r * r)).collect();
        same_bits("sorted.pr2", &s.pr2, &pr2, "p/ρ²")?;

        // The caches of the positions, built again: a step reads them before it rebuilds them.
        let x = &s.x[..nf];
        let mut cells = SortedCells::new(&self.walls.x);
        let (mut ids, mut slot, mut src) = (s.ids.clone(), s.slot.clone(), Vec::new());
        cells.sort(x, &self.walls.x, self.kernel.support(), &mut ids, &mut slot, &mut src);
        if let Some(k) = (0..nf).find(|&k| ids.get(k) != s.ids.get(k)) {
            return Err(format!(
                "sorted.ids[{k}] = {:?}: the cell order of the positions puts particle {:?} in that slot",
                s.ids.get(k),
                ids.get(k)
            ));
        }
        if let Some(field) = self.scratch.cells.differs_from(&cells) {
            return Err(format!(
                "scratch.cells.{field} differs from the cell bins of the positions"
            ));
        }
        let mut list = NeighborList::default();
        cells.build_fluid_lists(&s.x, nf, &self.kernel, &mut list);
        if let Some(why) = self.scratch.list.differs_from(&list) {
            return Err(format!("scratch.list: {why}"));
        }
        if !self.scratch.edited_x.is_empty() {
            return Err(format!(
                "scratch.edited_x holds {} positions, none are pending between two steps",
                self.scratch.edited_x.len()
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::restore::tests::tank;

    /// The tank's solver (with the scene overrides `sets`) after a few steps (one of them after a
    /// correction), and the one its scene builds.
    fn stepped_with(sets: &[&str]) -> (WcsphSolver, WcsphSolver) {
        let scene = tank("wcsph", sets);
        let fresh = WcsphSolver::new(&scene).unwrap();
        let mut solver = fresh.clone();
        for k in 0..5 {
            if k == 3 {
                // A contact correction, as the broker sends them between two steps.
                let state = solver.state_mut();
                state.x[0][0] += 1e-5;
                state.v[0][0] -= 1e-3;
            }
            let dt = solver.stable_dt();
            solver.step(dt).unwrap();
        }
        (solver, fresh)
    }

    fn stepped() -> (WcsphSolver, WcsphSolver) {
        stepped_with(&[])
    }

    /// The refusal of the stepped solver after `edit`.
    fn refused(edit: impl FnOnce(&mut WcsphSolver)) -> String {
        let (mut solver, fresh) = stepped();
        edit(&mut solver);
        solver
            .check_restored(&fresh)
            .expect_err("an inconsistent solver is refused")
    }

    #[test]
    fn a_solver_as_a_step_leaves_it_passes() {
        for sets in [
            &[][..],
            &["fluid.density_filter=mls", "fluid.density_filter_interval=2"],
            &[
                "fluid.density_filter=shepard",
                "fluid.density_filter_interval=2",
                "fluid.apd=0.04",
                "fluid.xsph=0.5",
            ],
        ] {
            let (solver, fresh) = stepped_with(sets);
            assert_eq!(solver.check_restored(&fresh), Ok(()), "{sets:?}");
            assert_eq!(fresh.check_restored(&fresh), Ok(()), "{sets:?}");
        }
    }

    #[test]
    fn edits_not_yet_taken_pass_but_the_working_copy_stays_in_the_domain() {
        let (mut solver, fresh) = stepped();
        solver.state_mut().x[0][0] += 1e-5;
        assert_eq!(solver.check_restored(&fresh), Ok(()));
        // Far out but finite: the cell grid of the check (and of the next step) would not fit in memory.
        let k = solver.sorted.slot[1] as usize;
        solver.sorted.x[k] = [1e200, 0.0];
        assert_eq!(
            solver.check_restored(&fresh),
            Err(format!("sorted.x[{k}] = [1e200, 0.0] is outside the fluid's domain"))
        );
    }

    #[test]
    fn lengths_that_disagree_are_refused_naming_the_field() {
        let n = stepped().0.state.len();
        let e = refused(|s| s.state.v.push([0.0; 2]));
        assert_eq!(
            e,
            format!("state.v holds {} entries, there are {n} fluid particles", n + 1)
        );
        let e = refused(|s| {
            s.accel.pop();
        });
        assert_eq!(
            e,
            format!("accel holds {} entries, there are {n} fluid particles", n - 1)
        );
        let e = refused(|s| {
            s.sorted.pr2.pop();
        });
        assert!(e.starts_with("sorted.pr2 holds"), "{e}");
        let e = refused(|s| s.walls.p.push(0.0));
        assert!(e.starts_with("walls.p holds"), "{e}");
    }

    #[test]
    fn ids_out_of_range_and_broken_caches_are_refused() {
        let n = stepped().0.state.len();
        let e = refused(|s| s.sorted.slot[3] = 1_000_000);
        assert_eq!(
            e,
            format!("sorted.slot[3] = 1000000 is not a slot ({n} fluid particles)")
        );
        let e = refused(|s| s.sorted.ids.swap(0, 1));
        assert!(e.starts_with("sorted.slot["), "{e}");
        let e = refused(|s| {
            s.sorted.ids.swap(0, 1);
            let (a, b) = (s.sorted.ids[0] as usize, s.sorted.ids[1] as usize);
            s.sorted.slot.swap(a, b);
        });
        assert!(e.starts_with("sorted.x[0]"), "{e}");
        let e = refused(|s| s.scratch.list = NeighborList::default());
        assert!(
            e.starts_with("scratch.list: lists of 0 particles in 0 chunks where the positions give"),
            "{e}"
        );
        // The lists of other positions: particle 0 moved by 2h.
        let e = refused(|s| {
            let mut x = s.sorted.x.clone();
            let k = s.sorted.slot[0] as usize;
            x[k][0] += s.kernel.support();
            let nf = s.state.len();
            s.scratch
                .cells
                .build_fluid_lists(&x, nf, &s.kernel, &mut s.scratch.list);
        });
        assert!(e.starts_with("scratch.list: the neighbours of particle"), "{e}");
        let e = refused(|s| s.scratch.edited_x.push([0.0; 2]));
        assert!(e.starts_with("scratch.edited_x holds 1"), "{e}");
    }

    #[test]
    fn numbers_that_are_not_finite_or_not_the_scenes_are_refused() {
        let e = refused(|s| s.state.x[7] = [f64::NAN, 0.0]);
        assert_eq!(e, "state.x[7] = [NaN, 0.0] is not finite");
        let e = refused(|s| s.state.m[2] *= 2.0);
        assert!(
            e.starts_with("state.m[2] = ") && e.contains("where the scene has"),
            "{e}"
        );
        let e = refused(|s| s.params.h *= 2.0);
        assert!(e.starts_with("params = SphParams"), "{e}");
        let e = refused(|s| s.state.x[0] = [1e6, 0.0]);
        assert_eq!(e, "state.x[0] = [1000000.0, 0.0] is outside the fluid's domain");
        let e = refused(|s| s.sorted.vol[4] = 0.5);
        assert!(e.starts_with("sorted.vol[4] = 0.5 where m/ρ has"), "{e}");
    }
}
