//! Errors of the SPH solver.

/// Everything the SPH library can fail with. Numerical failure is a value, never a panic.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SphError {
    /// The scene cannot be turned into a fluid (no `[fluid]`, unsupported solver, no sound speed).
    #[error("{key}: {message}")]
    InvalidScene {
        /// Dotted scene key.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// A solver parameter is out of range (time step).
    #[error("{name}: {message}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The solution blew up: a non-finite value or a particle that left the domain.
    #[error("unstable at SPH step {step}, particle {particle}: {reason}")]
    Unstable {
        /// Number of the step being taken when it failed (`FluidState::step + 1`).
        step: u64,
        /// Fluid particle index.
        particle: usize,
        /// What went wrong.
        reason: String,
    },
    /// The ISPH pressure Poisson equation did not converge (`DESIGN.md` §4.3).
    #[error("PPE not converged at SPH step {step}: relative residual {residual:e} after {iterations} iterations")]
    PpeNotConverged {
        /// Number of the step being taken when it failed (`FluidState::step + 1`).
        step: u64,
        /// BiCGSTAB iterations done.
        iterations: usize,
        /// Relative (Jacobi-preconditioned) residual reached.
        residual: f64,
    },
}

impl SphError {
    /// True for a numerical blow-up ([`SphError::Unstable`]).
    pub fn is_unstable(&self) -> bool {
        matches!(self, SphError::Unstable { .. })
    }
}

/// `Result` with [`SphError`] by default.
pub type Result<T, E = SphError> = std::result::Result<T, E>;
