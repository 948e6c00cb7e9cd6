//! An [`IsphSolver`]'s state for a checkpoint, and the solver continued from it (see [`crate::restore`] for the
//! checks). Saved: the particles, the walls' pressures (the warm start of the next PPE), the largest acceleration of
//! the last step (the next stable step), the last PPE report and the contact layer (which particles the contact
//! corrected lately). Not saved: the gather copies, the cell list, the neighbour lists and the scratch, which the step
//! rebuilds from the positions; they are rebuilt as the step's end rebuilds them.

use serde::{Deserialize, Serialize};

use super::{IsphSolver, PpeReport, Scratch};
use crate::fluid_solver::{decode, encode, SavedSolver};
use crate::isph::contact::ContactLayer;
use crate::restore::{check_state, check_walls, inside, Check};

/// What an ISPH solver carries from one step to the next besides particles and walls.
#[derive(Serialize, Deserialize)]
struct Own {
    /// Largest |u^{n+1} − uⁿ|/Δt of the last step.
    a_max: f64,
    /// [`IsphSolver::last_ppe`].
    last_ppe: PpeReport,
    /// The contact layer.
    contact: ContactLayer,
}

impl IsphSolver {
    /// The state for a checkpoint.
    pub(crate) fn save_state(&self) -> SavedSolver {
        let own = Own {
            a_max: self.a_max,
            last_ppe: self.last_ppe,
            contact: self.contact.clone(),
        };
        SavedSolver {
            solver: "isph".into(),
            state: self.state.clone(),
            walls: self.walls.clone(),
            own: encode(&own),
        }
    }

    /// Continue from `saved` (see [`crate::FluidSolver::restore`]). The domain is the scene's (it grows with
    /// `run.end_time`: a run continued further has the larger one); it must hold every particle.
    pub(crate) fn restore_state(&mut self, saved: SavedSolver) -> Check {
        let own: Own = decode("isph state", &saved.own)?;
        check_state(&saved.state, &self.state)?;
        check_walls(&saved.walls, &self.walls)?;
        inside("state.x", &saved.state.x, &self.params.domain)?;
        if !(own.a_max.is_finite() && own.a_max >= 0.0) {
            return Err(format!("a_max = {} is not an acceleration", own.a_max));
        }
        own.contact.check(&saved.state)?;
        self.state = saved.state;
        self.walls = saved.walls;
        self.a_max = own.a_max;
        self.last_ppe = own.last_ppe;
        self.contact = own.contact;
        // The gather copies as `with_options` makes them (ρ0 throughout, walls at rest), then the positions' caches.
        let (nf, nw) = (self.state.len(), self.walls.len());
        self.scratch = Scratch {
            m: self.state.m.iter().chain(&self.walls.m).copied().collect(),
            rho: vec![self.params.rho0; nf + nw],
            v: vec![[0.0; 2]; nf + nw],
            ..Scratch::default()
        };
        self.rebuild_neighbors();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::restore::tests::tank;

    /// The tank's solver after a few steps.
    fn stepped() -> IsphSolver {
        let mut solver = IsphSolver::new(&tank("isph", &[])).unwrap();
        for _ in 0..5 {
            let dt = solver.stable_dt();
            solver.step(dt).unwrap();
        }
        solver
    }

    /// The refusal of the stepped solver's saved state after `edit`; the solver it is restored into is unchanged.
    fn refused(edit: impl FnOnce(&mut Own, &mut SavedSolver)) -> String {
        let mut saved = stepped().save_state();
        let mut own: Own = decode("", &saved.own).unwrap();
        edit(&mut own, &mut saved);
        saved.own = encode(&own);
        let mut fresh = IsphSolver::new(&tank("isph", &[])).unwrap();
        let before = encode(&fresh.save_state());
        let e = fresh.restore_state(saved).expect_err("refused");
        assert_eq!(encode(&fresh.save_state()), before, "the refused state is not taken");
        e
    }

    #[test]
    fn an_acceleration_or_contact_layer_that_does_not_hold_together_is_refused() {
        let e = refused(|o, _| o.a_max = f64::NAN);
        assert_eq!(e, "a_max = NaN is not an acceleration");
        let e = refused(|o, s| {
            let mut moved = s.state.clone();
            moved.x[5][0] += 1e-3;
            o.contact.record_end(&moved);
        });
        assert!(e.starts_with("contact.x_end[5] = "), "{e}");
    }

    #[test]
    fn a_longer_run_takes_the_saved_state_in_its_own_domain() {
        let saved = stepped().save_state();
        let mut scene = tank("isph", &[]);
        scene.run.end_time = 3.0;
        let mut longer = IsphSolver::new(&scene).unwrap();
        assert_ne!(
            longer.params.domain,
            stepped().params.domain,
            "the domain grows with the end time"
        );
        let domain = longer.params.domain.clone();
        assert_eq!(longer.restore_state(saved), Ok(()));
        assert_eq!(longer.params.domain, domain);
    }

    /// The cell list and neighbour lists rebuilt on restore are those the step left.
    #[test]
    fn the_rebuilt_caches_are_the_steps() {
        let solver = stepped();
        let mut fresh = IsphSolver::new(&tank("isph", &[])).unwrap();
        fresh.restore_state(solver.save_state()).unwrap();
        assert!(fresh.scratch.cells == solver.scratch.cells);
        assert_eq!(fresh.scratch.list.differs_from(&solver.scratch.list), None);
        assert_eq!(fresh.scratch.x, solver.scratch.x);
        assert_eq!(fresh.scratch.p, solver.scratch.p);
    }
}
