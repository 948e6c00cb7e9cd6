//! The broker's side of `cosim ctl` and `cosim snapshot` (`docs/PROTOCOL.md` §11): the queryables
//! `cosim/<run>/broker/control` (JSON commands: pause, resume, step, stop, status) and `cosim/<run>/broker/state`
//! (the run's state between two steps), answered on the coordinator's thread between two steps
//! ([`Controller`]), so that a command never lands in the middle of a step.

use std::time::{Duration, Instant};

use cosim_proto::control::{ControlCommand, ControlReply, StateOf};
use cosim_proto::envelope::Envelope;
use cosim_proto::keys::{key, topic};
use zenoh::handlers::FifoChannelHandler;
use zenoh::query::{Query, Queryable};
use zenoh::{Session, Wait};

use crate::coordinator::pause::{Controller, Halt};

/// Why a paused run must stop now, if it must (a signal, a launcher gone); asked while the run is paused.
pub type StopCheck = Box<dyn FnMut() -> Option<String>>;
/// Shows the pause on the broker's live status (`paused at step N: REASON`, or empty).
pub type Show = Box<dyn FnMut(&str)>;

/// The queryables of a live run's controls.
pub struct RemoteControl {
    run: String,
    control: Queryable<FifoChannelHandler<Query>>,
    state: Queryable<FifoChannelHandler<Query>>,
    asking: Option<Query>,
    must_stop: StopCheck,
    show: Show,
}

impl RemoteControl {
    /// Declare the control queryables of `run`.
    pub fn declare(session: &Session, run: &str, must_stop: StopCheck, show: Show) -> anyhow::Result<Self> {
        let declare = |topic: &str| {
            session
                .declare_queryable(key(run, topic))
                .wait()
                .map_err(|e| anyhow::anyhow!("{e}"))
        };
        Ok(Self {
            run: run.into(),
            control: declare(topic::BROKER_CONTROL)?,
            state: declare(topic::BROKER_STATE)?,
            asking: None,
            must_stop,
            show,
        })
    }

    /// Answer a state query from `halt`: an envelope of `DebugState`, or an error naming what failed.
    fn answer_state(&self, query: Query, halt: &mut Halt<'_, '_>) {
        let of = StateOf::parse(query.parameters().get(StateOf::PARAMETER));
        let encoded = of
            .and_then(|of| halt.state(of).map_err(|e| e.to_string()))
            .and_then(|s| {
                Envelope::new(&self.run, halt.step, halt.t, s)
                    .encode_checked(topic::BROKER_STATE)
                    .map_err(|e| e.to_string())
            });
        let sent = match encoded {
            Ok(bytes) => query.reply(query.key_expr().clone(), bytes).wait(),
            Err(why) => query.reply_err(why).wait(),
        };
        if let Err(e) = sent {
            tracing::warn!("state query: {e}");
        }
    }
}

/// A command as its JSON text says, or why not.
fn parse(query: &Query) -> Result<ControlCommand, String> {
    let bytes = query.payload().map(|p| p.to_bytes().into_owned()).unwrap_or_default();
    serde_json::from_slice(&bytes)
        .map_err(|e| format!("not a control command ({e}): {}", String::from_utf8_lossy(&bytes)))
}

fn reply_json(query: &Query, reply: &ControlReply) {
    let text = serde_json::to_string(reply).unwrap_or_default();
    if let Err(e) = query.reply(query.key_expr().clone(), text).wait() {
        tracing::warn!("control query: {e}");
    }
}

impl Controller for RemoteControl {
    fn next(&mut self, halt: &mut Halt<'_, '_>, wait: Option<Duration>) -> Option<ControlCommand> {
        let until = wait.map(|w| Instant::now() + w);
        loop {
            while let Ok(Some(query)) = self.state.try_recv() {
                self.answer_state(query, halt);
            }
            while let Ok(Some(query)) = self.control.try_recv() {
                match parse(&query) {
                    Ok(command) => {
                        self.asking = Some(query);
                        return Some(command);
                    }
                    Err(why) => reply_json(&query, &halt.reply(false, why)),
                }
            }
            match until {
                Some(until) if Instant::now() < until => std::thread::sleep(Duration::from_millis(5)),
                _ => return None,
            }
        }
    }

    fn answer(&mut self, reply: ControlReply) {
        if let Some(query) = self.asking.take() {
            reply_json(&query, &reply);
        }
    }

    fn show(&mut self, line: &str) {
        (self.show)(line);
    }

    fn must_stop(&mut self) -> Option<String> {
        (self.must_stop)()
    }
}
