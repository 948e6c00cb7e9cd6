//! What a trace holds for one node, in the order it is played back: the scene, the restore reply, the registration,
//! then each command with the answer the node gave to it.

use std::path::{Path, PathBuf};

use anyhow::Context;
use cosim_proto::envelope::Envelope;
use cosim_proto::messages::{FemMesh, FemState, NodeCheckpoint, NodeError, SphSetup, SphState, StepCommand};
use cosim_proto::trace::{self, Kind, Node, RawEnvelope, Torn};
use serde::de::DeserializeOwned;

use crate::cli::ExternalNode;

/// What the node answered to one command in the recorded run.
#[derive(Clone, Debug, PartialEq)]
pub enum Answer {
    /// Its state (`fem/state`, `sph/state`).
    State(Vec<u8>),
    /// Its failure report (`fem/error`, `sph/error`).
    Error(Vec<u8>),
}

/// One command and what came back.
#[derive(Clone, Debug, PartialEq)]
pub struct Exchange {
    /// The envelope's step.
    pub step: u64,
    /// The command as sent.
    pub command: Vec<u8>,
    /// A stop command (nothing comes back).
    pub stop: bool,
    /// The recorded answer; `None` when the trace ends before it.
    pub answer: Option<Answer>,
    /// The command's record in the file (0 = the first).
    pub record: usize,
}

/// One node's part of a trace.
#[derive(Clone, Debug)]
pub struct Script {
    /// The file read.
    pub path: PathBuf,
    /// The scene (TOML) the broker served.
    pub scene: String,
    /// The broker's reply to the node's restore query, as recorded.
    pub restore: Option<Vec<u8>>,
    /// The node's registration as received.
    pub setup: Vec<u8>,
    /// The commands, in the order they were sent, with their answers.
    pub exchanges: Vec<Exchange>,
    /// Where the file stops before its end (a run that was killed), if it does.
    pub torn: Option<Torn>,
    /// The end record (JSON), when the run got to write it.
    pub end: Option<String>,
}

/// `DIR/trace` → `DIR/trace/trace.bin`; a file is taken as it is.
pub fn trace_file(path: &Path) -> PathBuf {
    match path.is_dir() {
        true => path.join(contact_broker::recorder::FILE),
        false => path.to_path_buf(),
    }
}

/// A recorded message, decoded under its own run id: what a replay would fail on later, said before the node starts.
fn decode<B: DeserializeOwned>(payload: &[u8], what: &'static str) -> Result<Envelope<B>, String> {
    let raw = RawEnvelope::split(payload).ok_or("not an envelope")?;
    Envelope::<B>::decode(payload, raw.run, what).map_err(|e| e.to_string())
}

/// The trace's records for `node`. Bad input (a file that is not a trace, a node the run did not have, a message
/// that does not decode, records out of order) is an error naming the file and the record (its index in the file),
/// said before the node starts (found 2026-12-06 by the sweep of damaged traces, D22: two command records swapped
/// were replayed, and the node blamed, "no answer from fem-node within 10 s").
pub fn read(path: &Path, node: ExternalNode) -> anyhow::Result<Script> {
    let path = trace_file(path);
    // A regular file, before it is read whole: /dev/zero was read until 6.5 GB were taken (2026-12-06).
    let meta = std::fs::metadata(&path).with_context(|| format!("cannot read {}", path.display()))?;
    anyhow::ensure!(meta.is_file(), "{}: not a regular file, so not a trace", path.display());
    let bytes = std::fs::read(&path).with_context(|| format!("cannot read {}", path.display()))?;
    let who = match node {
        ExternalNode::Fem => Node::Fem,
        ExternalNode::Sph => Node::Sph,
    };
    // Only the broker's records and this node's are kept: a replay holds little more than its part of the trace.
    let trace =
        trace::parse_with(&bytes, |_, n| n == who || n == Node::Broker).with_context(|| path.display().to_string())?;
    drop(bytes);
    anyhow::ensure!(
        trace.protocol_version == cosim_proto::PROTOCOL_VERSION,
        "{}: recorded with protocol version {}, this build speaks {}",
        path.display(),
        trace.protocol_version,
        cosim_proto::PROTOCOL_VERSION
    );
    let mut scene = None;
    let mut restore = None;
    let mut setup = None;
    let mut end = None;
    let mut exchanges: Vec<Exchange> = Vec::new();
    for r in trace.records {
        // The file's record index (not the index among this node's records), found 2026-12-06 by the sweep, D22.
        let i = r.index;
        let bad = |why: &str| {
            anyhow::anyhow!(
                "{}: record {i} ({} of step {}): {why}",
                path.display(),
                r.kind.name(),
                r.step
            )
        };
        match (r.kind, r.node) {
            (Kind::Scene, _) => scene = Some(String::from_utf8(r.payload.clone()).map_err(|_| bad("not UTF-8"))?),
            (Kind::End, _) => end = Some(String::from_utf8_lossy(&r.payload).into_owned()),
            (_, n) if n != who => {}
            (Kind::Restore, _) => {
                decode::<NodeCheckpoint>(&r.payload, "restore").map_err(|e| bad(&e))?;
                restore = Some(r.payload)
            }
            (Kind::Setup, _) => {
                match node {
                    ExternalNode::Fem => decode::<FemMesh>(&r.payload, "setup").map(|_| ()),
                    ExternalNode::Sph => decode::<SphSetup>(&r.payload, "setup").map(|_| ()),
                }
                .map_err(|e| bad(&e))?;
                setup = Some(r.payload)
            }
            (Kind::Command, _) => {
                let env = decode::<StepCommand>(&r.payload, "command").map_err(|e| bad(&e))?;
                if env.step != r.step {
                    return Err(bad(&format!("its envelope is for step {}", env.step)));
                }
                // The broker records each command once, the next step's after the last's answer.
                if let Some(last) = exchanges.last().filter(|x| x.step + 1 != env.step) {
                    return Err(bad(&format!(
                        "comes after the command of step {} (record {}): the commands are out of order (a record lost, \
                         moved or changed)",
                        last.step, last.record
                    )));
                }
                exchanges.push(Exchange {
                    step: env.step,
                    command: r.payload,
                    stop: env.body.stop,
                    answer: None,
                    record: i,
                });
            }
            (Kind::State | Kind::Error, _) => {
                let answer = match r.kind {
                    Kind::State => {
                        let step = match node {
                            ExternalNode::Fem => decode::<FemState>(&r.payload, "state").map(|e| e.step),
                            ExternalNode::Sph => decode::<SphState>(&r.payload, "state").map(|e| e.step),
                        }
                        .map_err(|e| bad(&e))?;
                        if step != r.step {
                            return Err(bad(&format!("its envelope is for step {step}")));
                        }
                        Answer::State(r.payload)
                    }
                    // A node reports its failure with step 0 in its envelope: the record holds the step.
                    _ => {
                        decode::<NodeError>(&r.payload, "error").map_err(|e| bad(&e))?;
                        Answer::Error(r.payload)
                    }
                };
                // The answer to the last command, recorded once, before the next command: an answer anywhere else
                // was replayed against the wrong command, and the node blamed for the silence that followed (D22).
                let error = r.kind == Kind::Error;
                match exchanges.last_mut() {
                    Some(x) if x.step == r.step && !x.stop && x.answer.is_none() => x.answer = Some(answer),
                    // A failure report after the answer or the stop, or before any command (at the restore): the
                    // broker records it under the last command's step; there is nothing to replay it against.
                    Some(x) if error && x.step == r.step => {}
                    None if error => {}
                    Some(x) => {
                        let why = match (x.step == r.step, x.stop) {
                            (_, true) => "a stop command, which has no answer",
                            (true, false) => "already answered",
                            (false, false) => "of another step",
                        };
                        return Err(bad(&format!(
                            "the last command before it is record {} (step {}), {why}: the trace is damaged (a record \
                             lost, moved or changed)",
                            x.record, x.step
                        )));
                    }
                    None => return Err(bad("no command comes before it: the trace is damaged")),
                }
            }
        }
    }
    // A command without an answer ends a trace cut short (the run killed while the node computed); one with later
    // steps after it is a record lost or changed inside the trace, which would otherwise replay as "matched" up to
    // there (found 2026-12-06: a state record removed, or a command's step changed, replayed "matched 2 steps"
    // of 51, exit 0).
    if let Some(k) = exchanges.iter().position(|x| !x.stop && x.answer.is_none()) {
        let x = &exchanges[k];
        if let Some(later) = exchanges[k + 1..].iter().find(|y| y.step != x.step) {
            anyhow::bail!(
                "{}: record {}: the command of step {} has no answer, yet step {} follows it: the trace is damaged (a \
                 record lost or changed)",
                path.display(),
                x.record,
                x.step,
                later.step
            );
        }
    }
    let what = node.program();
    let scene = scene.ok_or_else(|| anyhow::anyhow!("{}: no scene record (not a whole trace)", path.display()))?;
    let setup = setup.ok_or_else(|| {
        anyhow::anyhow!(
            "{}: {what} never registered in the recorded run (the run has no such node, or it died first)",
            path.display()
        )
    })?;
    Ok(Script {
        path,
        scene,
        restore,
        setup,
        exchanges,
        torn: trace.torn,
        end,
    })
}
