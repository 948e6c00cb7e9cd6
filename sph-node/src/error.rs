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
    /// The fluid's own stable step fell so far below what is left of the step asked of it that the sub-cycle would
    /// take more than [`MAX_SUBSTEPS`] sub-steps, or no longer advance the time at all: a blow-up in the making (a
    /// speed or an acceleration without bound), or numbers in the scene that allow no usable step, which `cosim
    /// check` and `cosim run` name before a run starts.
    #[error(
        "unstable at SPH step {step}: the fluid's stable step fell to {stable:.3e} s, and the {left:.3e} s left of \
         the coupling step would take more than 2^32 sub-steps of it"
    )]
    StepCollapsed {
        /// Number of the step that was to be taken (`FluidState::step + 1`).
        step: u64,
        /// The solver's stable step at that point [s].
        stable: f64,
        /// What was left of the coupling step [s].
        left: f64,
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
    /// The caller stopped the sub-cycle of a coupling step between two of its steps; the state is part of the way
    /// through the coupling step (the run ends here).
    #[error("stopped after {done} fluid steps of the coupling step of {dt:e} s: {why}")]
    Stopped {
        /// Fluid steps taken.
        done: u32,
        /// The coupling step asked for [s].
        dt: f64,
        /// The caller's reason.
        why: &'static str,
    },
}

impl SphError {
    /// True for a numerical blow-up ([`SphError::Unstable`], [`SphError::StepCollapsed`]).
    pub fn is_unstable(&self) -> bool {
        matches!(self, SphError::Unstable { .. } | SphError::StepCollapsed { .. })
    }
}

/// The most sub-steps one coupling step may take in the fluid node (2^32, as fem-node's sub-cycle).
pub const MAX_SUBSTEPS: f64 = 4_294_967_296.0;

/// `Result` with [`SphError`] by default.
pub type Result<T, E = SphError> = std::result::Result<T, E>;
