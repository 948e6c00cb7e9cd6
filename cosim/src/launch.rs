//! Processes mode: start `contact-broker` and `fem-node` as OS processes connected over zenoh on loopback, follow
//! the broker's progress, and make sure no process outlives the run.

use std::io::{BufRead, BufReader};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use anyhow::Context;
use contact_broker::coordinator::{write_summary, Progress, RunInfo};
use contact_broker::summary::{Summary, SummaryBuilder};
use cosim_bus::interrupt::Interrupt;
use cosim_proto::scene::Scene;

use crate::child_log::last_line;
use crate::cli::{ExternalNode, RunArgs};
use crate::progress::Bar;

/// How long the broker may take to open its session.
const LISTEN_TIMEOUT: Duration = Duration::from_secs(20);
/// How long the broker may take to notice a dead node before it is stopped.
const GRACE: Duration = Duration::from_secs(10);

/// Find a sibling program: `$COSIM_BIN_DIR`, the folder of this executable, then `PATH`.
pub fn find_program(name: &str) -> anyhow::Result<PathBuf> {
    let mut places: Vec<PathBuf> = Vec::new();
    if let Some(dir) = std::env::var_os("COSIM_BIN_DIR") {
        places.push(PathBuf::from(dir));
    }
    if let Some(dir) = std::env::current_exe()
        .ok()
        .and_then(|e| e.parent().map(Path::to_path_buf))
    {
        places.push(dir);
    }
    if let Some(path) = std::env::var_os("PATH") {
        places.extend(std::env::split_paths(&path));
    }
    places.iter().map(|d| d.join(name)).find(|p| p.is_file()).ok_or_else(|| {
        anyhow::anyhow!(
            "cannot find the `{name}` program (looked in $COSIM_BIN_DIR, next to cosim and on PATH); build it with `cargo build --release`"
        )
    })
}

/// `contact-broker` refused to start (exit code 2): the run id is live already (`cosim_bus::claim`).
#[derive(Debug, thiserror::Error)]
#[error("contact-broker refused to start: {0}")]
pub struct BrokerRefused(String);

/// Whether the run was refused (by the broker, or by [`ensure_run_id_free`]) rather than failed.
pub fn is_refused(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.is::<BrokerRefused>()) || cosim_bus::claim::is_refusal(e)
}

/// How long [`ensure_run_id_free`] waits to join the router; one slower than that is left to the broker's own check.
const CHECK_CONNECT_MS: u64 = 1000;

/// Refuse run id `run` when its broker is live on the router at `connect` (`cosim_bus::claim`). A router that cannot
/// be joined (within [`CHECK_CONNECT_MS`]) is not this check's to report: the broker, started next, says so.
pub fn ensure_run_id_free(connect: &str, zenoh_config: Option<&Path>, run: &str) -> anyhow::Result<()> {
    let connect = [connect.to_string()];
    let session = match cosim_bus::session::open_client_from(zenoh_config, &connect, CHECK_CONNECT_MS) {
        Ok(session) => session,
        Err(e) => {
            tracing::debug!("run id check skipped: {e:#}");
            return Ok(());
        }
    };
    let free = cosim_bus::claim::ensure_free(&session, run, cosim_proto::keys::topic::BROKER_ALIVE, "contact-broker");
    drop(session);
    free
}

/// Kills a child when dropped, so an early return never leaves a process behind.
struct Guard {
    name: &'static str,
    child: Child,
}

impl Guard {
    fn exited(&mut self) -> Option<std::process::ExitStatus> {
        self.child.try_wait().ok().flatten()
    }

    fn wait_for(&mut self, limit: Duration) -> Option<std::process::ExitStatus> {
        let until = Instant::now() + limit;
        while Instant::now() < until {
            if let Some(s) = self.exited() {
                return Some(s);
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        None
    }
}

impl Drop for Guard {
    fn drop(&mut self) {
        if self.exited().is_none() {
            // The run's outcome is already decided and reported; this only makes sure nothing outlives it.
            tracing::debug!("stopping {}", self.name);
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

fn spawn(name: &'static str, program: &Path, args: &[String], log: &Path, stdout: Stdio) -> anyhow::Result<Guard> {
    let log_file = std::fs::File::create(log).with_context(|| format!("cannot create {}", log.display()))?;
    let child = Command::new(program)
        // Its own process group: a Ctrl-C in the terminal reaches `cosim run` alone, which stops the run through
        // the broker (SIGTERM, outputs written); the nodes would otherwise die mid-step and the run would read as
        // a node failure.
        .process_group(0)
        .args(args)
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(log_file)
        .spawn()
        .with_context(|| format!("cannot start {}", program.display()))?;
    Ok(Guard { name, child })
}

/// Events the broker prints on stdout.
enum Event {
    Listening(Vec<String>),
    Progress(Progress),
}

fn parse_event(line: &str) -> Option<Event> {
    let v: serde_json::Value = serde_json::from_str(line).ok()?;
    match v.get("event")?.as_str()? {
        "listening" => Some(Event::Listening(
            v.get("endpoints")?
                .as_array()?
                .iter()
                .filter_map(|e| e.as_str().map(str::to_string))
                .collect(),
        )),
        "progress" => Some(Event::Progress(Progress {
            step: v.get("step")?.as_u64()?,
            t: v.get("t")?.as_f64()?,
            end_time: v.get("end_time")?.as_f64()?,
            ..Progress::default()
        })),
        _ => None,
    }
}

/// Run the scene as processes and return the broker's summary.
pub fn run_processes(args: &RunArgs, scene: &Scene, info: &RunInfo, bar: &Bar) -> anyhow::Result<Summary> {
    let broker_bin = find_program("contact-broker")?;
    // The solver nodes this scene needs.
    let mut wanted: Vec<&'static str> = Vec::new();
    if !scene.solids.is_empty() {
        wanted.push("fem-node");
    }
    if scene.fluid.is_some() {
        wanted.push("sph-node");
    }
    // An outside program takes that node's place (`--external`): it is not started here.
    let external = args.external.map(ExternalNode::program);
    wanted.retain(|n| Some(*n) != external);
    let programs = wanted
        .iter()
        .map(|n| Ok((*n, find_program(n)?)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let logs = info.out.join("logs");
    std::fs::create_dir_all(&logs)?;
    let broker_log = logs.join("contact-broker.log");
    let started = Instant::now();
    // Ctrl-C (or SIGTERM) is passed on to the broker as SIGTERM: it stops the run between two steps and writes
    // the outputs; the nodes follow it. A second Ctrl-C ends `cosim run` at once (the broker then stops as its
    // progress pipe closes).
    let interrupt = Interrupt::install().context("cannot catch SIGINT and SIGTERM")?;

    let mut broker_args = vec![
        "--run".into(),
        info.run_id.clone(),
        "--scene".into(),
        args.scene.display().to_string(),
        "--out".into(),
        info.out.display().to_string(),
        "--mode".into(),
        info.mode.clone(),
    ];
    for s in &args.set {
        broker_args.extend(["--set".into(), s.clone()]);
    }
    // Through a router every process is a zenoh client (see `cosim_bus::session`, client settings).
    if let Some(c) = &args.connect {
        broker_args.extend(["--connect".into(), c.clone(), "--client".into()]);
    }
    if args.external.is_some() {
        broker_args.extend(["--wait-nodes".into(), args.wait_external.to_string()]);
    }
    if let Some(i) = args.checkpoint_interval {
        broker_args.extend(["--checkpoint-interval".into(), i.to_string()]);
    }
    if let Some(dir) = &args.restart {
        broker_args.extend(["--restart".into(), dir.display().to_string()]);
    }
    if args.record {
        broker_args.push("--record".into());
    }
    if args.ignore_disk_space {
        broker_args.push("--ignore-disk-space".into());
    }
    if let Some(condition) = &args.break_on {
        broker_args.extend(["--break".into(), condition.to_string()]);
    }
    // The zenoh config file (credentials, certificates) goes to every process started.
    let zenoh_config: Vec<String> = match &args.zenoh_config {
        Some(f) => vec!["--zenoh-config".into(), f.display().to_string()],
        None => Vec::new(),
    };
    broker_args.extend(zenoh_config.iter().cloned());
    let mut broker = spawn("contact-broker", &broker_bin, &broker_args, &broker_log, Stdio::piped())?;
    let (tx, rx) = mpsc::channel();
    let stdout = broker.child.stdout.take().expect("piped stdout");
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if let Some(ev) = parse_event(&line) {
                if tx.send(ev).is_err() {
                    break;
                }
            }
        }
    });

    // The broker listens on a port the OS picks, so runs side by side never collide.
    let endpoints = loop {
        match rx.recv_timeout(Duration::from_millis(50)) {
            Ok(Event::Listening(e)) => break e,
            Ok(Event::Progress(_)) => {}
            Err(mpsc::RecvTimeoutError::Timeout) | Err(mpsc::RecvTimeoutError::Disconnected) => {}
        }
        if let Some(status) = broker.exited() {
            let said = last_line(&broker_log);
            if status.code() == Some(2) {
                let said = said.strip_prefix("contact-broker: ").unwrap_or(&said);
                return Err(BrokerRefused(said.to_string()).into());
            }
            anyhow::bail!("contact-broker failed to start: {said}");
        }
        anyhow::ensure!(
            !interrupt.arrived(),
            "{} before the run started",
            cosim_bus::interrupt::REASON
        );
        if started.elapsed() > LISTEN_TIMEOUT {
            anyhow::bail!(
                "contact-broker did not open its session within {} s",
                LISTEN_TIMEOUT.as_secs()
            );
        }
    };
    let connect = match &args.connect {
        Some(c) => c.clone(),
        None => endpoints
            .iter()
            .find(|e| e.starts_with("tcp/"))
            .cloned()
            .ok_or_else(|| anyhow::anyhow!("contact-broker listens on no TCP endpoint ({endpoints:?})"))?,
    };
    // `cosim inspect ID` on this machine finds the run here while it lasts.
    let _registered = crate::registry::register(&crate::registry::Entry {
        run: info.run_id.clone(),
        connect: connect.clone(),
        client: args.connect.is_some(),
        zenoh_config: args.zenoh_config.clone(),
        out: info.out.clone(),
        pid: std::process::id(),
        scene: Some(scene.run.name.clone()),
        since: crate::registry::now(),
    });
    if let Some(node) = args.external {
        let mode = if args.connect.is_some() { "client" } else { "peer" };
        announce_external(node, &info.run_id, &connect, mode, args.wait_external, &info.out)?;
    }
    // The nodes wait for the broker's scene as long as the broker had to open its session (their own default is 5 s):
    // this broker is listening and watched, and on a loaded machine a node's first query through a TLS router took
    // longer than 5 s (`cosim/tests/access.rs`, `a_run_through_a_tls_router`, beside the rest of the suite).
    let mut node_args = vec![
        "--run".into(),
        info.run_id.clone(),
        "--connect".into(),
        connect,
        "--timeout".into(),
        LISTEN_TIMEOUT.as_secs().to_string(),
    ];
    if args.connect.is_some() {
        node_args.push("--client".into());
    }
    node_args.extend(zenoh_config);
    if let Some(n) = args.threads {
        node_args.extend(["--threads".into(), n.to_string()]);
    }
    let mut nodes = programs
        .iter()
        .map(|(name, program)| {
            spawn(
                name,
                program,
                &node_args,
                &logs.join(format!("{name}.log")),
                Stdio::null(),
            )
        })
        .collect::<anyhow::Result<Vec<Guard>>>()?;

    // A node that fails makes the broker fail the run within a step (liveliness); if it does not, stop it.
    let mut node_failed_at: Option<Instant> = None;
    let mut interrupted_at: Option<Instant> = None;
    let broker_status = loop {
        if let Ok(Event::Progress(p)) = rx.recv_timeout(Duration::from_millis(50)) {
            bar.update(p);
        }
        if let Some(status) = broker.exited() {
            break status;
        }
        match interrupted_at {
            None if interrupt.arrived() => {
                interrupted_at = Some(Instant::now());
                let pid = nix::unistd::Pid::from_raw(broker.child.id() as i32);
                if let Err(e) = nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGTERM) {
                    tracing::warn!("cannot pass the interrupt on to contact-broker: {e}");
                }
            }
            // A broker that does not stop within a few steps' time (stuck waiting for a node) is stopped.
            Some(at) if at.elapsed() > GRACE => {
                let _ = broker.child.kill();
                break broker.child.wait()?;
            }
            _ => {}
        }
        let failed = nodes.iter_mut().any(|n| n.exited().is_some_and(|s| !s.success()));
        match node_failed_at {
            None if failed => node_failed_at = Some(Instant::now()),
            Some(at) if at.elapsed() > GRACE => {
                let _ = broker.child.kill();
                break broker.child.wait()?;
            }
            _ => {}
        }
    };
    // After a run that ended well the broker told the nodes to stop; after a failure a live node sees the broker's
    // token go within a fraction of a second, and one that does not (frozen, or the one that failed) is stopped
    // here. Give them a moment to exit, then make sure.
    let grace = if broker_status.success() { 5 } else { 2 };
    let until = Instant::now() + Duration::from_secs(grace);
    for node in &mut nodes {
        node.wait_for(until.saturating_duration_since(Instant::now()));
    }
    drop(nodes);

    let summary_path = info.out.join("summary.json");
    // The placeholder reserved at the start (`contact_broker::summary`) means the broker wrote none.
    match std::fs::read_to_string(&summary_path)
        .ok()
        .and_then(|s| serde_json::from_str::<Summary>(&s).ok())
        .filter(|s| !s.is_placeholder())
    {
        Some(summary) => Ok(summary),
        None => {
            // The broker died before it could write one: write what we know.
            // The broker's last line already carries a node's report when one came in; else the nodes' logs.
            let broker_said = last_line(&broker_log);
            let message = if broker_status.success() {
                "contact-broker exited without a summary".to_string()
            } else if let Some(reason) = broker_said.strip_prefix("contact-broker: ") {
                reason.to_string()
            } else {
                // It died without a word (killed, crashed): say how, then what the nodes saw.
                let how = match std::os::unix::process::ExitStatusExt::signal(&broker_status) {
                    Some(signal) => format!("contact-broker died (signal {signal})"),
                    None => format!("contact-broker died ({broker_status})"),
                };
                let nodes: Vec<String> = wanted
                    .iter()
                    .map(|n| last_line(&logs.join(format!("{n}.log"))))
                    .collect();
                match nodes.is_empty() {
                    true => how,
                    false => format!("{how}; {}", nodes.join("; ")),
                }
            };
            let (samples, sim_time, frames) = kept_outputs(&info.out);
            let summary = SummaryBuilder::new(&info.run_id, &info.mode)
                .wall_seconds(started.elapsed().as_secs_f64())
                .kept(samples, sim_time, frames)
                .failed(message);
            write_summary(&info.out, &summary)?;
            Ok(summary)
        }
    }
}

/// Tell the user (stderr) and a script (`DIR/external.json`) how to join the run in place of `node`.
/// `mode` is the zenoh mode to join in: `peer` (connecting to the broker) or `client` (through a router).
fn announce_external(
    node: ExternalNode,
    run: &str,
    connect: &str,
    mode: &str,
    wait: f64,
    out: &Path,
) -> anyhow::Result<()> {
    let path = out.join("external.json");
    let doc =
        serde_json::json!({"node": node.name(), "run": run, "connect": connect, "mode": mode, "wait_seconds": wait});
    // Written whole, then renamed into place: a script that waits for the file to appear (as
    // `cosim/tests/run_identity.rs` does) must never read it empty or half written.
    contact_broker::output::write_atomic(&path, format!("{doc:#}\n").as_bytes())?;
    let flag = if mode == "client" { " --client" } else { "" };
    eprintln!(
        "cosim: waiting up to {wait} s for an external {} node to join run {run} at {connect} (as `{} --run {run} \
         --connect {connect}{flag}` would; details in {})",
        node.name(),
        node.program(),
        path.display()
    );
    Ok(())
}

/// What a broker that died left on disk, so that the summary says what was kept: the probe samples (rows of
/// `probes.csv`), the last one's time, and the frames.
fn kept_outputs(out: &Path) -> (u64, f64, u64) {
    let (mut samples, mut sim_time) = (0, 0.0);
    if let Ok(text) = std::fs::read_to_string(out.join("probes.csv")) {
        let rows: Vec<&str> = text.lines().skip(1).filter(|l| !l.trim().is_empty()).collect();
        samples = rows.len() as u64;
        if let Some(t) = rows
            .last()
            .and_then(|l| l.split(',').next())
            .and_then(|t| t.parse().ok())
        {
            sim_time = t;
        }
    }
    // One frame is one time: count the structure's files, or the particles' in a fluid-only run.
    let count = |prefix: &str| {
        std::fs::read_dir(out.join("frames")).map_or(0, |dir| {
            dir.filter_map(Result::ok)
                .filter(|e| {
                    let name = e.file_name();
                    let name = name.to_string_lossy();
                    name.starts_with(prefix) && name.ends_with(".vtu")
                })
                .count() as u64
        })
    };
    (samples, sim_time, count("structure_").max(count("particles_")))
}
