//! `--record`: the broker writes every message of the run to `DIR/trace/trace.bin` as it sends or receives it
//! (format: `cosim_proto::trace`, `docs/PROTOCOL.md` §10).
//!
//! Each record goes to the file with one `write` call as soon as the message is sent or accepted, with no buffer in
//! this process: a broker killed at any point (SIGKILL included) leaves every record it wrote readable, and at worst
//! one record cut short at the end, which readers skip. It is not flushed to the disk (no fsync): a machine that
//! loses power may lose the tail. A write that fails (a full disk) stops the recording with one error in the log;
//! the run goes on. The recording also stops, with one error in the log, before it would take the room the run's
//! frames, probe table and checkpoints still need on that disk, and says once beforehand when its pace will not fit
//! to the end (`room.rs`).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use anyhow::Context;
use cosim_proto::trace::{self, Kind, Node};

use crate::setup::RunSetup;
use crate::summary::{Summary, TraceNote};

mod recorded;
mod room;

pub use recorded::Recorded;
use room::{Room, Verdict};

/// The trace's file name inside `DIR/trace/`.
pub const FILE: &str = "trace.bin";

/// What a recording cost, for its end record and the log.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Cost {
    /// Records written.
    pub records: u64,
    /// Bytes written, header included.
    pub bytes: u64,
    /// Seconds spent encoding and writing them.
    pub seconds: f64,
}

struct Inner {
    file: Option<std::fs::File>,
    path: PathBuf,
    cost: Cost,
    /// The outputs' room on the trace's disk (none with `--ignore-disk-space`).
    room: Option<Room>,
    /// Why the recording stopped before the run's end.
    stopped: Option<String>,
}

/// The open trace, shared by everything that records into it (the two node links and the broker itself).
#[derive(Clone)]
pub struct Recorder(Arc<Mutex<Inner>>);

impl Recorder {
    /// Create `out/trace/trace.bin` afresh (a trace of an earlier run in that folder is replaced) and write its
    /// header. The recording stops before it takes `room` (when given) from the run's outputs.
    fn create(out: &Path, room: Option<Room>) -> anyhow::Result<Self> {
        let dir = out.join("trace");
        std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let path = dir.join(FILE);
        let mut file = std::fs::File::create(&path).with_context(|| format!("cannot create {}", path.display()))?;
        let header = trace::header(cosim_proto::PROTOCOL_VERSION);
        file.write_all(&header)
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(Self(Arc::new(Mutex::new(Inner {
            file: Some(file),
            path,
            cost: Cost {
                bytes: header.len() as u64,
                ..Cost::default()
            },
            room,
            stopped: None,
        }))))
    }

    /// Append one record. Never fails the run: a write error stops the recording and is logged once.
    pub fn record(&self, kind: Kind, node: Node, step: u64, payload: &[u8]) {
        self.write(kind, node, step, payload, None);
    }

    /// Append a step command of the step from simulated time `t` (the room's clock, [`Room::at`]).
    pub fn record_command(&self, node: Node, step: u64, t: f64, payload: &[u8]) {
        self.write(Kind::Command, node, step, payload, Some(t));
    }

    /// One record, after moving the room's clock to `t` (a command's).
    fn write(&self, kind: Kind, node: Node, step: u64, payload: &[u8], t: Option<f64>) {
        let started = Instant::now();
        let Ok(mut inner) = self.0.lock() else { return };
        let inner = &mut *inner;
        if let (Some(room), Some(t)) = (inner.room.as_mut(), t) {
            room.at(t, inner.cost.bytes);
        }
        let Some(file) = inner.file.as_mut() else { return };
        let written = match trace::encode(kind, node, step, payload) {
            Some(bytes) => file.write_all(&bytes).map(|()| bytes.len() as u64),
            None => Err(std::io::Error::other("a message over 4 GiB")),
        };
        match written {
            Ok(n) => {
                inner.cost.records += 1;
                inner.cost.bytes += n;
                match inner.room.as_mut().map(|room| room.after_write(n, inner.cost.bytes)) {
                    Some(Verdict::Warn(why)) => tracing::warn!("{}: {why}", inner.path.display()),
                    Some(Verdict::Stop(why)) => {
                        tracing::error!("{}: {why}", inner.path.display());
                        inner.file = None;
                        inner.stopped = Some(format!("at step {step}: {why}"));
                    }
                    Some(Verdict::Go) | None => {}
                }
            }
            Err(e) => {
                tracing::error!(
                    "{}: {e}; the recording stops here (what was written stays readable)",
                    inner.path.display()
                );
                inner.file = None;
                inner.stopped = Some(format!("at step {step}: {e}"));
            }
        }
        inner.cost.seconds += started.elapsed().as_secs_f64();
    }

    /// [`Recorder::create`], then the records a run starts with: the scene as the broker serves it, and the
    /// broker's restore reply to each node the scene has (`docs/PROTOCOL.md` §10). With `keep_room` the recording
    /// stops before it takes the room the run's outputs need on the disk (`--ignore-disk-space` turns both off).
    pub fn begin(out: &Path, run: &str, setup: &RunSetup, keep_room: bool) -> anyhow::Result<Self> {
        let room = keep_room.then(|| {
            let (from, end) = (setup.restart_time(), setup.scene.scene.run.end_time);
            Room::new(&out.join("trace"), setup.outputs_bytes(), from, end)
        });
        let r = Self::create(out, room)?;
        let scene = &setup.scene.scene;
        r.record(Kind::Scene, Node::Broker, 0, scene.to_toml().as_bytes());
        let saved = |data: Option<&Vec<u8>>| {
            let at = setup.restart.as_ref()?;
            Some((at.broker.step, at.broker.t, data?.clone()))
        };
        let nodes = [
            (
                !scene.solids.is_empty(),
                cosim_proto::keys::FEM,
                Node::Fem,
                saved(setup.saved_fem()),
            ),
            (
                scene.fluid.is_some(),
                cosim_proto::keys::SPH,
                Node::Sph,
                saved(setup.saved_sph()),
            ),
        ];
        for (_, topics, node, saved) in nodes.into_iter().filter(|n| n.0) {
            let reply = crate::checkpoint::restore_reply::restore_reply(run, topics, saved)?;
            r.record(Kind::Restore, node, 0, &reply);
        }
        Ok(r)
    }

    /// What the recording cost so far.
    pub fn cost(&self) -> Cost {
        self.0.lock().map(|i| i.cost).unwrap_or_default()
    }

    /// The end record: how the run ended and what the recording cost (this record's own bytes not counted).
    pub fn finish(&self, status: &str, message: &str, steps: u64) {
        let cost = self.cost();
        let end = serde_json::json!({
            "status": status,
            "message": message,
            "steps": steps,
            "records": cost.records,
            "bytes": cost.bytes,
            "record_seconds": cost.seconds,
        });
        self.record(Kind::End, Node::Broker, steps, end.to_string().as_bytes());
    }

    /// [`Recorder::finish`] the trace of the run `summary` describes, then say in `out/summary.json` what the trace
    /// holds and whether it stopped early (`trace`), and in the log.
    pub fn close(&self, summary: &mut Summary, out: &Path) {
        self.finish(summary.status.as_str(), &summary.message, summary.steps);
        let (cost, stopped) = match self.0.lock() {
            Ok(inner) => (inner.cost, inner.stopped.clone()),
            Err(_) => return,
        };
        tracing::info!(
            "trace: {} records, {} bytes, {:.3} s spent recording",
            cost.records,
            cost.bytes,
            cost.seconds
        );
        summary.trace = Some(TraceNote {
            records: cost.records,
            bytes: cost.bytes,
            stopped,
        });
        if let Err(e) = crate::summary::write(out, summary) {
            tracing::error!("{e:#}");
        }
    }
}

/// A recorder bound to one node's messages.
#[derive(Clone)]
pub struct Tap {
    /// The trace.
    pub recorder: Recorder,
    /// Whose messages.
    pub node: Node,
}

impl Tap {
    /// Append one of this node's messages.
    pub fn record(&self, kind: Kind, step: u64, payload: &[u8]) {
        self.recorder.record(kind, self.node, step, payload);
    }

    /// Append a step command to this node, of the step from simulated time `t`.
    pub fn command(&self, step: u64, t: f64, payload: &[u8]) {
        self.recorder.record_command(self.node, step, t, payload);
    }
}
