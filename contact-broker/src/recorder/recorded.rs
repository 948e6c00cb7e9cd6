//! A node in this process, recorded (`cosim run --record --in-process`).

use std::collections::BTreeMap;

use cosim_proto::envelope::Envelope;
use cosim_proto::messages::{NodeError, StepCommand};
use cosim_proto::trace::Kind;
use serde::Serialize;

use super::Tap;
use crate::link::{LinkError, NodeLink};

/// A node in this process, recorded (`cosim run --record --in-process`): the messages it would have exchanged as a
/// process, encoded as the broker and `cosim_bus::serve` encode them (the answer's envelope time is the node's, as
/// `serve` computes it), so that its trace replays against the node programs as a processes-mode trace does.
pub struct Recorded<L> {
    inner: L,
    tap: Tap,
    run: String,
    /// The node's time after its last answer, and the last command's step, start time and step length.
    t: f64,
    sent: (u64, f64, f64),
}

impl<L: NodeLink> Recorded<L>
where
    L::Setup: Serialize,
{
    /// Record `inner`'s messages into `tap` from now on, starting with its registration.
    pub fn new(inner: L, tap: Tap, run: &str) -> Self {
        tap.record(Kind::Setup, 0, &Envelope::new(run, 0, 0.0, inner.setup()).encode());
        Self {
            inner,
            tap,
            run: run.into(),
            t: 0.0,
            sent: (0, 0.0, 0.0),
        }
    }
}

impl<L: NodeLink> NodeLink for Recorded<L>
where
    L::State: Serialize,
{
    type Setup = L::Setup;
    type State = L::State;

    fn setup(&self) -> &L::Setup {
        self.inner.setup()
    }

    fn send(&mut self, step: u64, t: f64, cmd: StepCommand) -> Result<(), LinkError> {
        self.tap
            .command(step, t, &Envelope::new(&self.run, step, t, &cmd).encode());
        self.sent = (step, t, cmd.dt);
        self.inner.send(step, t, cmd)
    }

    fn receive(&mut self, step: u64) -> Result<L::State, LinkError> {
        match self.inner.receive(step) {
            Ok(state) => {
                // `cosim_bus::serve`: the node's time after a step, or where it stands when it did not advance.
                let (_, t, dt) = self.sent;
                self.t = if dt > 0.0 { t + dt } else { self.t.max(t) };
                let bytes = Envelope::new(&self.run, step, self.t, &state).encode();
                self.tap.record(Kind::State, step, &bytes);
                Ok(state)
            }
            Err(e) => {
                let message = match &e {
                    LinkError::Unstable { message, .. } | LinkError::Failed { message, .. } => message.clone(),
                };
                let body = NodeError {
                    status: e.status().as_str().into(),
                    message,
                };
                self.tap
                    .record(Kind::Error, step, &Envelope::new(&self.run, 0, 0.0, body).encode());
                Err(e)
            }
        }
    }

    fn concurrent(&self) -> bool {
        self.inner.concurrent()
    }

    fn counts(&mut self) -> Option<BTreeMap<String, u64>> {
        self.inner.counts()
    }

    fn checkpoint(&mut self, step: u64) -> Result<Vec<u8>, LinkError> {
        self.inner.checkpoint(step)
    }
}
