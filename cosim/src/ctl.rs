//! `cosim ctl RUN pause|resume|step [N]|stop|status`: drive a live run through its broker's control queryable
//! (`cosim/<run>/broker/control`, `docs/PROTOCOL.md` §11). The broker takes a command between two steps and
//! answers with where the run is; `step N` waits here until the N steps are taken and the run paused again.

use std::process::ExitCode;
use std::time::{Duration, Instant};

use cosim_proto::control::{ControlCommand, ControlReply};
use cosim_proto::keys::{key, topic};
use zenoh::{Session, Wait};

use crate::cli::{CtlAction, CtlArgs};
use crate::join::join;

/// Send `command` to run `id`'s broker and wait up to `timeout` for its answer (it comes between two steps).
pub fn ask(session: &Session, id: &str, command: ControlCommand, timeout: Duration) -> anyhow::Result<ControlReply> {
    let text = serde_json::to_string(&command)?;
    let replies = session
        .get(key(id, topic::BROKER_CONTROL))
        .payload(text)
        .timeout(timeout)
        .wait()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let reply = replies.recv().map_err(|_| {
        anyhow::anyhow!(
            "the broker of run `{id}` did not answer within {:.0} s",
            timeout.as_secs_f64()
        )
    })?;
    let sample = reply
        .result()
        .map_err(|e| anyhow::anyhow!("the broker of run `{id}` refused: {e:?}"))?;
    Ok(serde_json::from_slice(&sample.payload().to_bytes())?)
}

/// Run `cosim ctl`: exit 0 when the broker took the command, 1 when it refused it or did not answer.
pub fn ctl(args: &CtlArgs) -> anyhow::Result<ExitCode> {
    let command = match args.action {
        CtlAction::Pause => ControlCommand::Pause,
        CtlAction::Resume => ControlCommand::Resume,
        CtlAction::Step => ControlCommand::Step {
            steps: args.steps.unwrap_or(1),
        },
        CtlAction::Stop => ControlCommand::Stop,
        CtlAction::Status => ControlCommand::Status,
    };
    anyhow::ensure!(
        args.steps.is_none() || args.action == CtlAction::Step,
        "a number of steps goes with `step` only"
    );
    if let Some(why) = args.steps.and_then(contact_broker::coordinator::pause::refuse_steps) {
        anyhow::bail!(why);
    }
    let (session, connect) = join(&args.id, &args.join)?;
    let timeout = cosim_bus::seconds::wait(args.join.timeout);
    let reply = match ask(&session, &args.id, command, timeout) {
        Ok(reply) => reply,
        Err(e) => {
            eprintln!("cosim: run `{}` at {connect}: {e:#}", args.id);
            return Ok(ExitCode::from(1));
        }
    };
    let reply = match (&command, reply.ok) {
        // Wait for the steps: the run pauses again once they are taken (or ends first).
        (ControlCommand::Step { .. } | ControlCommand::Pause, true) => wait_paused(&session, &args.id, timeout, reply),
        _ => reply,
    };
    println!("{}", serde_json::to_string(&reply)?);
    Ok(if reply.ok { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

/// Ask where the run is until it says it is paused (or stops answering: it ended); the last answer. Each answer
/// comes between two steps, so a long step only makes this wait longer, up to `timeout` without an answer.
fn wait_paused(session: &Session, id: &str, timeout: Duration, first: ControlReply) -> ControlReply {
    let mut last = first;
    let started = Instant::now();
    let alive = key(id, topic::BROKER_ALIVE);
    while last.paused.is_empty() {
        match ask(session, id, ControlCommand::Status, timeout) {
            Ok(reply) => last = reply,
            Err(e) => {
                // A run that reached its end before the steps asked were taken: its broker's token is gone (`cosim
                // ctl RUN step N` beyond the run's end said only that the broker "did not answer within 10 s"). A
                // broker that has taken its control queryable down but still writes its outputs holds its token a
                // little longer: ask again until the token goes or `timeout` has passed (a fresh clone's suite met
                // that race once in four, 2026-12-07).
                let held = cosim_bus::claim::held(session, &alive, Duration::from_secs(2));
                let waited = started.elapsed();
                if matches!(held, Ok(true)) && waited < timeout {
                    std::thread::sleep(Duration::from_millis(50));
                    continue;
                }
                last.ok = false;
                last.message = match held {
                    Ok(false) => format!(
                        "the run ended before pausing again (its broker is gone; last seen at step {}, t = {} s)",
                        last.step,
                        cosim_proto::Num(cosim_proto::readable::significant(last.t, 12))
                    ),
                    _ => format!("the run did not pause again after {:.1} s: {e:#}", waited.as_secs_f64()),
                };
                break;
            }
        }
        if last.paused.is_empty() {
            std::thread::sleep(Duration::from_millis(20));
        }
    }
    last
}
