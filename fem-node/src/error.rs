//! Errors of the structure solver.

/// Everything the FEM library can fail with. Numerical failure is a value, never a panic.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FemError {
    /// A solid of the scene cannot be meshed or has an unusable material.
    #[error("solid `{solid}`: {message}")]
    InvalidSolid {
        /// Solid name.
        solid: String,
        /// What is wrong.
        message: String,
    },
    /// A solver parameter is out of range (CFL number, time step).
    #[error("{name}: {message}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The solution blew up: an inverted element (J ≤ 0) or a non-finite value.
    #[error("unstable at FEM sub-step {step}, element {element}: {reason}")]
    Unstable {
        /// Number of the sub-step being taken when it failed (`FemState::step + 1`, or the current step when
        /// the failure is found outside a step).
        step: u64,
        /// Global element index.
        element: usize,
        /// What went wrong.
        reason: String,
    },
    /// The caller stopped an [`advance`](crate::solver::FemSolver::advance_until) between two sub-steps; the state
    /// is part of the way through the step (the run ends here).
    #[error("stopped after {done} of {of} sub-steps of {dt:e} s: {why}")]
    Stopped {
        /// Sub-steps taken.
        done: u32,
        /// Sub-steps the step needed.
        of: u32,
        /// The step asked for [s].
        dt: f64,
        /// The caller's reason.
        why: &'static str,
    },
}

/// `Result` with [`FemError`] by default.
pub type Result<T, E = FemError> = std::result::Result<T, E>;

impl FemError {
    /// True for a numerical blow-up ([`FemError::Unstable`]), which a run reports as `unstable`.
    pub fn is_unstable(&self) -> bool {
        matches!(self, FemError::Unstable { .. })
    }
}
