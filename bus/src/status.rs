//! A process's live status, served as JSON on the queryable `cosim/<run>/<node>/status` (`DESIGN.md` §5,
//! `cosim inspect`). The serving loop updates a [`Status`] after each step; a query reads it at any time without
//! waiting for the step in progress.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use serde::Serialize;
use zenoh::query::Queryable;
use zenoh::{Session, Wait};

/// What a process says about itself.
#[derive(Clone, Debug, Serialize)]
pub struct Status {
    /// Program name (`fem-node`, `sph-node`, `contact-broker`).
    pub node: String,
    /// Run id.
    pub run: String,
    /// Operating-system process id.
    pub pid: u32,
    /// `starting` (joining, building the model), `running`, `finished` or `failed`.
    pub health: String,
    /// Last coupling step done.
    pub step: u64,
    /// Simulated time reached [s].
    pub t: f64,
    /// Last coupling step size [s].
    pub dt: f64,
    /// Wall-clock seconds since the process started serving.
    pub wall_seconds: f64,
    /// Seconds spent computing (handling commands), in total and per step on average.
    pub compute_seconds: f64,
    /// Mean compute seconds per step.
    pub compute_per_step: f64,
    /// Seconds spent waiting for the next command (the partner's compute and the messaging), in total.
    pub waiting_seconds: f64,
    /// Mean waiting seconds per step.
    pub waiting_per_step: f64,
    /// Sizes: particles, nodes, elements, …
    pub counts: BTreeMap<String, u64>,
    /// Anything else the process reports (the broker: contacts, max penetration, energies).
    pub extra: BTreeMap<String, serde_json::Value>,
    /// Why it failed, when it did.
    pub message: String,
}

/// A [`Status`] shared between the serving loop and the queryable.
#[derive(Clone)]
pub struct Board {
    status: Arc<Mutex<Status>>,
    started: Instant,
}

impl Board {
    /// A board for `node` of `run`, health `starting`.
    pub fn new(node: &str, run: &str) -> Self {
        Self {
            status: Arc::new(Mutex::new(Status {
                node: node.into(),
                run: run.into(),
                pid: std::process::id(),
                health: "starting".into(),
                step: 0,
                t: 0.0,
                dt: 0.0,
                wall_seconds: 0.0,
                compute_seconds: 0.0,
                compute_per_step: 0.0,
                waiting_seconds: 0.0,
                waiting_per_step: 0.0,
                counts: BTreeMap::new(),
                extra: BTreeMap::new(),
                message: String::new(),
            })),
            started: Instant::now(),
        }
    }

    /// Change the status (a poisoned lock is taken over: a status is never worth a panic).
    pub fn update(&self, f: impl FnOnce(&mut Status)) {
        let mut s = self.status.lock().unwrap_or_else(|e| e.into_inner());
        f(&mut s);
    }

    /// Account one step: its number, time, size, and the compute and waiting seconds it took.
    pub fn step(&self, step: u64, t: f64, dt: f64, compute: f64, waiting: f64) {
        self.update(|s| {
            s.health = "running".into();
            s.step = step;
            s.t = t;
            s.dt = dt;
            s.compute_seconds += compute;
            s.waiting_seconds += waiting;
            let n = (step + 1) as f64;
            s.compute_per_step = s.compute_seconds / n;
            s.waiting_per_step = s.waiting_seconds / n;
        });
    }

    /// The status as JSON, with the wall time as of now.
    pub fn json(&self) -> String {
        let mut s = self.status.lock().unwrap_or_else(|e| e.into_inner()).clone();
        s.wall_seconds = self.started.elapsed().as_secs_f64();
        serde_json::to_string(&s).unwrap_or_else(|e| format!("{{\"error\":\"{e}\"}}"))
    }
}

/// Answer queries on `key` with the board's JSON for as long as the returned queryable lives.
pub fn serve_status(session: &Session, key: String, board: Board) -> anyhow::Result<Queryable<()>> {
    // Replies carry this process's own key, not the query's: a wildcard query (`*/status`) gets one reply per
    // process, which zenoh would otherwise consolidate into one.
    let own = key.clone();
    session
        .declare_queryable(key)
        .callback(move |query| {
            if let Err(e) = query.reply(own.clone(), board.json()).wait() {
                tracing::warn!("status query: {e}");
            }
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("{e}"))
}

/// Ask every process of `run` for its status (`cosim/<run>/*/status`): (key, JSON text) per answer, sorted by key,
/// within `timeout`.
pub fn query_all(session: &Session, run: &str, timeout: std::time::Duration) -> anyhow::Result<Vec<(String, String)>> {
    let replies = session
        .get(cosim_proto::keys::key(run, cosim_proto::keys::topic::ANY_STATUS))
        .consolidation(zenoh::query::ConsolidationMode::None)
        .timeout(timeout)
        .wait()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut out = Vec::new();
    while let Ok(reply) = replies.recv() {
        if let Ok(sample) = reply.result() {
            let text = String::from_utf8_lossy(&sample.payload().to_bytes()).into_owned();
            out.push((sample.key_expr().as_str().to_string(), text));
        }
    }
    out.sort();
    Ok(out)
}
