//! The coordinator's view of a solver node: send a step command, later receive the node's state.
//!
//! The same coordinator drives a node in this process (a direct call) or in another process (zenoh), so the
//! physics and the outputs cannot differ between the two modes. Sending and receiving are separate so that the
//! structure and fluid nodes compute a step at the same time when they run as processes.

use std::collections::BTreeMap;

use cosim_proto::messages::{FemMesh, FemState, SphSetup, SphState, StepCommand};
use cosim_proto::run_status::RunStatus;

/// Why a node could not answer.
#[derive(Debug, thiserror::Error)]
pub enum LinkError {
    /// The node reported a numerical blow-up.
    #[error("{node}: {message}")]
    Unstable {
        /// Node name.
        node: String,
        /// What it said.
        message: String,
    },
    /// The node failed, died, timed out or sent something unusable.
    #[error("{node}: {message}")]
    Failed {
        /// Node name.
        node: String,
        /// What went wrong.
        message: String,
    },
}

impl LinkError {
    /// How the run ends: `unstable` or `failed`.
    pub fn status(&self) -> RunStatus {
        match self {
            LinkError::Unstable { .. } => RunStatus::Unstable,
            LinkError::Failed { .. } => RunStatus::Failed,
        }
    }
}

/// What the coordinator reads from every node's answer.
pub trait Reply {
    /// Seconds the node computed for this step.
    fn compute_seconds(&self) -> f64;
}

impl Reply for FemState {
    fn compute_seconds(&self) -> f64 {
        self.compute_seconds
    }
}

impl Reply for SphState {
    fn compute_seconds(&self) -> f64 {
        self.compute_seconds
    }
}

/// A solver node as the coordinator sees it.
pub trait NodeLink {
    /// What the node registered with (mesh, particle setup).
    type Setup;
    /// Its answer to a step.
    type State: Reply;

    /// The registration message.
    fn setup(&self) -> &Self::Setup;

    /// Send `cmd` for coupling step `step` starting at time `t`. After a stop command nothing is received.
    fn send(&mut self, step: u64, t: f64, cmd: StepCommand) -> Result<(), LinkError>;

    /// The node's answer to the command of step `step`.
    fn receive(&mut self, step: u64) -> Result<Self::State, LinkError>;

    /// Whether the node computes on its own while the coordinator waits (another process), rather than inside
    /// [`NodeLink::receive`], one node after the other (this process). Decides how a round's time is split
    /// between the nodes and messaging.
    fn concurrent(&self) -> bool {
        true
    }

    /// What the node counts (its sizes, and for the fluid the wall guard's interventions, `wall_pushes`) as it
    /// reports them on its live status after its last answer; `None` when it cannot say (no status, gone).
    fn counts(&mut self) -> Option<BTreeMap<String, u64>> {
        None
    }

    /// The node's whole state after the last step it answered, in its own format, for a checkpoint
    /// (`docs/PROTOCOL.md` §9). Asked for only between two steps.
    fn checkpoint(&mut self, step: u64) -> Result<Vec<u8>, LinkError>;

    /// The run ended before its end time (a failure, an interrupt): tell the node to stop, as far as it can still
    /// be told, so that it exits now instead of [`cosim_bus::link_loss::GRACE`] later, when it finds the broker
    /// gone. Best effort: the run's outcome is already decided.
    fn farewell(&mut self) {}
}

/// The structure node.
pub type FemLink = dyn NodeLink<Setup = FemMesh, State = FemState>;
/// The fluid node.
pub type SphLink = dyn NodeLink<Setup = SphSetup, State = SphState>;

/// A node's step handler: the answer to a command, `None` for a stop.
type Handler<T> = Box<dyn FnMut(&StepCommand) -> Result<Option<T>, LinkError>>;
/// A node's checkpoint: its state between two steps.
type Saver = Box<dyn FnMut() -> Result<Vec<u8>, LinkError>>;
/// A node's counts (see [`NodeLink::counts`]).
type Counter = Box<dyn FnMut() -> BTreeMap<String, u64>>;

/// A node in this process: a handler called when its answer is asked for.
pub struct InProcess<S, T> {
    setup: S,
    handler: Handler<T>,
    saver: Option<Saver>,
    counter: Option<Counter>,
    pending: Option<StepCommand>,
}

impl<S, T> InProcess<S, T> {
    /// A node from its registration message and its step handler.
    pub fn new(setup: S, handler: impl FnMut(&StepCommand) -> Result<Option<T>, LinkError> + 'static) -> Self {
        Self {
            setup,
            handler: Box::new(handler),
            saver: None,
            counter: None,
            pending: None,
        }
    }

    /// The node reports its counts with `counter`.
    pub fn with_counts(mut self, counter: impl FnMut() -> BTreeMap<String, u64> + 'static) -> Self {
        self.counter = Some(Box::new(counter));
        self
    }

    /// The node can save its state for a checkpoint with `saver`.
    pub fn with_checkpoint(mut self, saver: impl FnMut() -> Result<Vec<u8>, LinkError> + 'static) -> Self {
        self.saver = Some(Box::new(saver));
        self
    }
}

impl<S, T: Reply> NodeLink for InProcess<S, T> {
    type Setup = S;
    type State = T;

    fn setup(&self) -> &S {
        &self.setup
    }

    fn send(&mut self, _step: u64, _t: f64, cmd: StepCommand) -> Result<(), LinkError> {
        if cmd.stop {
            (self.handler)(&cmd)?;
        } else {
            self.pending = Some(cmd);
        }
        Ok(())
    }

    fn receive(&mut self, step: u64) -> Result<T, LinkError> {
        let cmd = self.pending.take().ok_or_else(|| LinkError::Failed {
            node: "in-process node".into(),
            message: format!("asked for step {step} without a command"),
        })?;
        (self.handler)(&cmd)?.ok_or_else(|| LinkError::Failed {
            node: "in-process node".into(),
            message: format!("no answer to step {step}"),
        })
    }

    fn concurrent(&self) -> bool {
        false
    }

    fn counts(&mut self) -> Option<BTreeMap<String, u64>> {
        self.counter.as_mut().map(|count| count())
    }

    fn checkpoint(&mut self, _step: u64) -> Result<Vec<u8>, LinkError> {
        match &mut self.saver {
            Some(save) => save(),
            None => Err(LinkError::Failed {
                node: "in-process node".into(),
                message: "cannot save a checkpoint".into(),
            }),
        }
    }
}
