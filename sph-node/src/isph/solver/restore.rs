//! The checks on an [`IsphSolver`] read back from a checkpoint (see [`crate::restore`]).

use crate::neighbors::CellList;
use crate::restore::{check_state, check_walls, finite2, len, same, same_bits, Check};

use super::IsphSolver;

impl IsphSolver {
    /// Check this solver, read back from a checkpoint, against `scene`, the solver the scene builds: everything
    /// that follows from the scene equal to it (but the domain, which grows with `run.end_time`: it must hold every
    /// particle); the state, the walls and the contact layer whole and finite; the copies a step gathers from
    /// (`scratch.x`, `p`, `m`, `rho`) the state's; the cell list and neighbour lists those the positions give (built
    /// again and compared). `Err` is one line naming the field, the index and the value.
    pub(crate) fn check_restored(&self, scene: &Self) -> Check {
        let mut params = self.params.clone();
        params.domain = scene.params.domain.clone();
        same("params", &params, &scene.params)?;
        same("options", &self.options, &scene.options)?;
        same("kernel", &self.kernel, &scene.kernel)?;
        same("wall_boxes", &self.wall_boxes, &scene.wall_boxes)?;
        same_bits("wall_normals", &self.wall_normals, &scene.wall_normals, "the scene")?;
        same("cfl", &self.cfl, &scene.cfl)?;
        same("apd", &self.apd, &scene.apd)?;
        same("v_ref", &self.v_ref, &scene.v_ref)?;
        same("rho_ref", &self.rho_ref, &scene.rho_ref)?;
        if !(self.a_max.is_finite() && self.a_max >= 0.0) {
            return Err(format!("a_max = {} is not an acceleration", self.a_max));
        }
        check_state(&self.state, &scene.state)?;
        check_walls(&self.walls, &scene.walls)?;
        let domain = &self.params.domain;
        if let Some(i) = self.state.x.iter().position(|x| !domain.contains(*x)) {
            return Err(format!(
                "state.x[{i}] = {:?} is outside the fluid's domain",
                self.state.x[i]
            ));
        }
        self.contact.check(&self.state)?;
        let (nf, nw) = (self.state.len(), self.walls.len());
        let s = &self.scratch;
        let joined = |fluid: &[f64], walls: &[f64]| -> Vec<f64> { fluid.iter().chain(walls).copied().collect() };
        let x: Vec<[f64; 2]> = self.state.x.iter().chain(&self.walls.x).copied().collect();
        same_bits("scratch.x", &s.x, &x, "state.x and walls.x")?;
        same_bits(
            "scratch.p",
            &s.p,
            &joined(&self.state.p, &self.walls.p),
            "state.p and walls.p",
        )?;
        same_bits(
            "scratch.m",
            &s.m,
            &joined(&self.state.m, &self.walls.m),
            "state.m and walls.m",
        )?;
        same_bits("scratch.rho", &s.rho, &scene.scratch.rho, "the scene")?;
        len("scratch.v", &s.v, nf + nw, "fluid and wall particles")?;
        finite2("scratch.v", &s.v)?;

        // The caches of the positions, built again: a step's predictor reads them before it rebuilds them.
        let support = self.kernel.support();
        let cells = CellList::new(&s.x, support);
        if s.cells != cells {
            return Err("scratch.cells differs from the cell list of the positions".into());
        }
        let list = cells.neighbor_list(&s.x, s.x.len(), support);
        if let Some(why) = s.list.differs_from(&list) {
            return Err(format!("scratch.list: {why}"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::neighbors::NeighborList;
    use crate::restore::tests::tank;

    /// The tank's solver (with the scene overrides `sets`) after a few steps (one of them after a
    /// correction), and the one its scene builds.
    fn stepped_with(sets: &[&str]) -> (IsphSolver, IsphSolver) {
        let scene = tank("isph", sets);
        let fresh = IsphSolver::new(&scene).unwrap();
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

    fn stepped() -> (IsphSolver, IsphSolver) {
        stepped_with(&[])
    }

    /// The refusal of the stepped solver after `edit`.
    fn refused(edit: impl FnOnce(&mut IsphSolver)) -> String {
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
            &["fluid.apd=0.04", "fluid.xsph=0.5"],
            &["fluid.ppe_source=density_invariant"],
        ] {
            let (solver, fresh) = stepped_with(sets);
            assert_eq!(solver.check_restored(&fresh), Ok(()), "{sets:?}");
            assert_eq!(fresh.check_restored(&fresh), Ok(()), "{sets:?}");
        }
    }

    #[test]
    fn a_longer_run_keeps_its_saved_domain() {
        let (solver, _) = stepped();
        let mut scene = tank("isph", &[]);
        scene.run.end_time = 3.0;
        let longer = IsphSolver::new(&scene).unwrap();
        assert_ne!(
            longer.params.domain, solver.params.domain,
            "the domain grows with the end time"
        );
        assert_eq!(solver.check_restored(&longer), Ok(()));
    }

    #[test]
    fn lengths_that_disagree_are_refused_naming_the_field() {
        let (solver, _) = stepped();
        let (nf, nw) = (solver.state.len(), solver.walls.len());
        let e = refused(|s| {
            s.state.p.pop();
        });
        assert_eq!(
            e,
            format!("state.p holds {} entries, there are {nf} fluid particles", nf - 1)
        );
        let e = refused(|s| s.scratch.v.truncate(nf));
        assert_eq!(
            e,
            format!(
                "scratch.v holds {nf} entries, there are {} fluid and wall particles",
                nf + nw
            )
        );
        let e = refused(|s| s.scratch.m.push(1.0));
        assert!(e.starts_with("scratch.m holds"), "{e}");
    }

    #[test]
    fn broken_caches_and_numbers_are_refused() {
        let e = refused(|s| s.scratch.list = NeighborList::default());
        assert!(e.starts_with("scratch.list: lists of 0 particles in 0 chunks"), "{e}");
        let e = refused(|s| s.scratch.cells = CellList::default());
        assert_eq!(e, "scratch.cells differs from the cell list of the positions");
        let e = refused(|s| s.state.v[3] = [0.0, f64::INFINITY]);
        assert_eq!(e, "state.v[3] = [0.0, inf] is not finite");
        let e = refused(|s| {
            let mut moved = s.state.clone();
            moved.x[5][0] += 1e-3;
            s.contact.record_end(&moved);
        });
        assert!(e.starts_with("contact.x_end[5] = "), "{e}");
        let e = refused(|s| s.a_max = f64::NAN);
        assert_eq!(e, "a_max = NaN is not an acceleration");
    }
}
