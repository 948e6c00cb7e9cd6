//! `contact-broker`: the step coordinator (and, with fluid, the contact solver) as its own process.
//!
//! Prints JSON lines on stdout for the launcher: `{"event":"listening","endpoints":[...]}` once the session is
//! up, then `{"event":"progress",...}` a few times a second, then `{"event":"done",...}`.

use std::io::Write;
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::Parser;
use contact_broker::coordinator::pause::Debugger;
use contact_broker::coordinator::{Nodes, Progress, RunInfo};
use contact_broker::link::{FemLink, NodeLink, SphLink};
use contact_broker::recorder::{Recorder, Tap};
use contact_broker::remote_control::RemoteControl;
use contact_broker::setup::RunSetup;
use contact_broker::summary::{self, SummaryBuilder};
use contact_broker::transport::{self, ZenohLink};
use cosim_bus::interrupt::Interrupt;
use cosim_bus::status::{serve_status, Board};
use cosim_proto::control::BreakCondition;
use cosim_proto::keys::{key, topic, valid_run_id};
use cosim_proto::messages::{FemMesh, FemState, SphSetup, SphState};
use cosim_proto::sizing::Part;
use cosim_proto::trace;

/// The co-simulation's step coordinator and contact broker.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Args {
    /// Run id; every key expression is under `cosim/<run>/`.
    #[arg(long)]
    run: String,
    /// Scene file (TOML).
    #[arg(long)]
    scene: PathBuf,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Scene overrides, `key.path=value`.
    #[arg(long = "set")]
    set: Vec<String>,
    /// Endpoints to listen on.
    #[arg(long, default_value = "tcp/127.0.0.1:0", value_parser = cosim_bus::session::endpoint)]
    listen: Vec<String>,
    /// Endpoints (a router or peers) to connect to.
    #[arg(long, value_parser = cosim_bus::session::endpoint)]
    connect: Vec<String>,
    /// `--connect` is a zenoh router (`zenohd`): join through it as a client and listen on nothing; the nodes
    /// then join through the same router with `--client`.
    #[arg(long)]
    client: bool,
    /// Seconds to wait for the nodes to register.
    #[arg(long, value_parser = cosim_bus::seconds::positive, default_value_t = 60.0)]
    wait_nodes: f64,
    /// Write a checkpoint (`DIR/checkpoints/<step>/`) every this many seconds of simulated time.
    #[arg(long, value_name = "SECONDS")]
    checkpoint_interval: Option<f64>,
    /// Continue from this checkpoint folder (`DIR/checkpoints/<step>`) instead of from the scene.
    #[arg(long, value_name = "DIR")]
    restart: Option<PathBuf>,
    /// Start even where the outputs are estimated larger than the free space of `--out`'s disk (refused without it).
    #[arg(long)]
    ignore_disk_space: bool,
    /// A zenoh JSON5 config file the session starts from (user and password, TLS certificates, …); the broker's
    /// own settings (mode, endpoints, multicast scouting off, timeouts) are put on top of it.
    #[arg(long, value_name = "FILE")]
    zenoh_config: Option<PathBuf>,
    /// Keep every message of the run in `DIR/trace/trace.bin` (`docs/PROTOCOL.md` §10), for `cosim replay`.
    #[arg(long)]
    record: bool,
    /// Pause the run, every process alive, when CONDITION first holds (`t>=SECONDS`, `step=N`,
    /// `max_penetration>METRES`, `unstable`); `cosim ctl` goes on from there (`docs/PROTOCOL.md` §11).
    #[arg(long = "break", value_name = "CONDITION")]
    break_on: Option<BreakCondition>,
    /// Mode written into summary.json.
    #[arg(long, default_value = "processes")]
    mode: String,
}

fn main() {
    // Its stderr is a log file in the output folder: a disk that fills up loses log lines, never the broker.
    cosim_bus::log::init();
    let result = run(Args::parse());
    // Every session of the run is closed and dropped by now.
    cosim_bus::session::stop_runtime();
    if let Err(e) = result {
        cosim_bus::log::say(&format!("contact-broker: {}", format!("{e:#}").replace('\n', " ")));
        // A run id that is live already, a scene refused and an output folder of someone's own files are bad input
        // (exit 2, as `cosim run` gives for them).
        let bad_input = cosim_bus::claim::is_refusal(&e)
            || e.chain().any(|c| {
                c.is::<cosim_proto::scene::SceneError>() || c.is::<contact_broker::output::folder::ForeignFolder>()
            });
        std::process::exit(if bad_input { 2 } else { 1 });
    }
}

/// One event line on stdout. An error means nobody reads it any more: a launcher that died (even by SIGKILL, which
/// runs no clean-up of its own) closes its end of the pipe.
fn emit(value: serde_json::Value) -> std::io::Result<()> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "{value}")?;
    out.flush()
}

fn run(args: Args) -> anyhow::Result<()> {
    let started = Instant::now();
    anyhow::ensure!(
        valid_run_id(&args.run),
        "--run `{}`: use letters, digits, - and _ only",
        args.run
    );
    let setup = RunSetup::load(&args.scene, &args.set, Part::Broker)?
        .with_checkpoints(args.checkpoint_interval, args.restart.as_deref())?;
    if !args.ignore_disk_space {
        setup.refuse_full_disk(&args.out)?;
    }
    // Not a folder of the user's own files (`cosim run` made it, or an earlier run did).
    contact_broker::output::folder::refuse_foreign(&args.out, &[])?;
    // From here on a signal stops the run between two steps instead of killing the broker mid-step.
    let interrupt = Interrupt::install().context("cannot catch SIGINT and SIGTERM")?;
    let base = args.zenoh_config.as_deref();
    // A bad config file is its own error, not "cannot open a session".
    cosim_bus::session::base_config(base)?;
    let (session, endpoints) = match args.client {
        true => transport::open_client_from(base, &args.connect, 5000)
            .map(|s| (s, Vec::new()))
            .with_context(|| format!("cannot join the router {:?}", args.connect))?,
        false => transport::open_listening_from(base, &args.listen, &args.connect, 5000).with_context(|| {
            format!(
                "cannot open a zenoh session (listen {:?}, connect {:?})",
                args.listen, args.connect
            )
        })?,
    };
    // A run id claims its key space (`cosim_bus::claim`): on a live run id this broker stops here, before it
    // declares anything there or writes into the output folder (which may be the live run's).
    cosim_bus::claim::ensure_free(&session, &args.run, topic::BROKER_ALIVE, "contact-broker")?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    // The room for summary.json, taken before anything else is written: a disk that fills up during the run
    // still gets the summary that says so (`contact_broker::summary`).
    summary::reserve(&args.out, &args.run, &args.mode)?;
    // The body keeps a handle of the session (a shared one: cloning it opens nothing).
    let recorder = match args.record {
        true => Some(Recorder::begin(&args.out, &args.run, &setup, !args.ignore_disk_space)?),
        false => None,
    };
    let result = serve(&args, &setup, session.clone(), endpoints, &interrupt, recorder.as_ref());
    cosim_bus::session::close(&session);
    // A run that failed before the coordinator wrote its summary (a node that never registered): say why there.
    if let Err(e) = &result {
        let written = std::fs::read_to_string(args.out.join(summary::FILE))
            .ok()
            .and_then(|t| serde_json::from_str::<summary::Summary>(&t).ok())
            .is_some_and(|s| !s.is_placeholder());
        if !written {
            let failed = SummaryBuilder::new(&args.run, &args.mode)
                .wall_seconds(started.elapsed().as_secs_f64())
                .failed(format!("{e:#}").replace('\n', " "));
            if let Err(e) = summary::write(&args.out, &failed) {
                cosim_bus::log::say(&format!("contact-broker: {e}"));
            }
        }
    }
    result
}

/// The run, from the declarations on its keys to its end.
fn serve(
    args: &Args,
    setup: &RunSetup,
    session: zenoh::Session,
    endpoints: Vec<String>,
    interrupt: &Interrupt,
    recorder: Option<&Recorder>,
) -> anyhow::Result<()> {
    let scene = &setup.scene;
    // Subscriptions first, then the scene queryable: a node that got the scene can already be heard.
    let fem_subs = match scene.scene.solids.is_empty() {
        false => Some(transport::subscribe(&session, &args.run, cosim_proto::keys::FEM)?),
        true => None,
    };
    let sph_subs = match scene.scene.fluid {
        Some(_) => Some(transport::subscribe(&session, &args.run, cosim_proto::keys::SPH)?),
        None => None,
    };
    let _scene_queryable = transport::serve_scene(&session, &args.run, scene.scene.to_toml())?;
    // Each node asks, once it has the scene, whether it continues from a saved state.
    let saved = |data: Option<&Vec<u8>>| {
        let r = setup.restart.as_ref()?;
        Some((r.broker.step, r.broker.t, data?.clone()))
    };
    let _restore = (
        transport::serve_restore(&session, &args.run, cosim_proto::keys::FEM, saved(setup.saved_fem()))?,
        transport::serve_restore(&session, &args.run, cosim_proto::keys::SPH, saved(setup.saved_sph()))?,
    );
    let _alive = session
        .liveliness()
        .declare_token(key(&args.run, topic::BROKER_ALIVE))
        .wait_ok()?;
    // Live status (`cosim inspect`): the run's progress, what registered, how it ended.
    let board = Board::new("contact-broker", &args.run);
    let _status = serve_status(&session, key(&args.run, topic::BROKER_STATUS), board.clone())?;
    board.update(|s| {
        s.extra.insert("end_time".into(), scene.scene.run.end_time.into());
        s.extra.insert("endpoints".into(), endpoints.clone().into());
    });
    emit(serde_json::json!({"event": "listening", "endpoints": endpoints, "run": args.run}))
        .context("cannot write the listening event on stdout")?;

    let wait = cosim_bus::seconds::wait(args.wait_nodes);
    let step_timeout = cosim_bus::seconds::wait(scene.scene.coupling.step_timeout);
    let mut fem: Option<ZenohLink<FemMesh, FemState>> = fem_subs
        .map(|subs| ZenohLink::register(&session, &args.run, subs, wait, interrupt, step_timeout))
        .transpose()?;
    let mut sph: Option<ZenohLink<SphSetup, SphState>> = sph_subs
        .map(|subs| ZenohLink::register(&session, &args.run, subs, wait, interrupt, step_timeout))
        .transpose()?;
    // Ctrl-C during a long step: the wait for the nodes' answers is given up, the outputs so far written.
    if let Some(link) = fem.as_mut() {
        link.stop_on(interrupt.clone());
    }
    if let Some(link) = sph.as_mut() {
        link.stop_on(interrupt.clone());
    }
    if let Some(r) = recorder {
        let tap = |node| Tap {
            recorder: r.clone(),
            node,
        };
        if let Some(link) = fem.as_mut() {
            link.record_to(tap(trace::Node::Fem));
        }
        if let Some(link) = sph.as_mut() {
            link.record_to(tap(trace::Node::Sph));
        }
    }
    board.update(|s| {
        if let Some(f) = &fem {
            s.counts.insert("fem_nodes".into(), f.setup().nodes.len() as u64);
            s.counts.insert("fem_elements".into(), f.setup().cells.len() as u64);
        }
        if let Some(p) = &sph {
            s.counts.insert("particles".into(), u64::from(p.setup().particles));
        }
        s.health = "running".into();
    });
    let fem_and_fluid = fem.is_some() && sph.is_some();
    let nodes = Nodes {
        fem: fem.as_mut().map(|l| l as &mut FemLink),
        sph: sph.as_mut().map(|l| l as &mut SphLink),
    };
    let info = RunInfo {
        run_id: args.run.clone(),
        mode: args.mode.clone(),
        out: args.out.clone(),
    };
    let mut last = Instant::now();
    let (mut last_t, mut last_step, mut last_wall) = (0.0, 0u64, Instant::now());
    let mut report = |p: Progress| {
        // Ctrl-C or SIGTERM (`cosim run` passes a Ctrl-C on as SIGTERM): stop here, outputs written.
        interrupt.control()?;
        // The broker's own time is not split from its wait for the nodes here: the summary has that split.
        if p.step > last_step {
            let dt = (p.t - last_t) / (p.step - last_step) as f64;
            let wall = last_wall.elapsed().as_secs_f64() / (p.step - last_step) as f64;
            board.update(|s| {
                s.step = p.step;
                s.t = p.t;
                s.dt = dt;
                s.extra.insert("wall_per_step".into(), wall.into());
                s.extra.insert("progress".into(), (p.t / p.end_time).into());
                if fem_and_fluid {
                    s.extra.insert("contacts".into(), p.contacts.into());
                    s.extra.insert("max_penetration".into(), p.max_penetration.into());
                    s.extra.insert("exchanged".into(), p.exchanged.into());
                }
                if let Some(g) = p.energy_made {
                    s.extra.insert("energy_made".into(), g.into());
                }
            });
            (last_t, last_step, last_wall) = (p.t, p.step, Instant::now());
        }
        if last.elapsed() >= Duration::from_millis(200) || p.t >= p.end_time {
            last = Instant::now();
            let event = serde_json::json!({"event": "progress", "step": p.step, "t": p.t, "end_time": p.end_time});
            // The launcher (`cosim run`) is gone: nobody will collect this run, so it stops rather than compute
            // on unwatched (the summary says why; the nodes follow when this broker's liveliness token goes).
            if let Err(e) = emit(event) {
                return ControlFlow::Break(format!("the launcher stopped reading this broker's progress ({e})"));
            }
        }
        ControlFlow::Continue(())
    };
    // `cosim ctl` and `cosim snapshot` (`docs/PROTOCOL.md` §11), answered between two steps.
    let mut heartbeat = Instant::now();
    let stopping = interrupt.clone();
    let must_stop = move || -> Option<String> {
        if stopping.arrived() {
            return Some(cosim_bus::interrupt::REASON.to_string());
        }
        // While paused the launcher still hears from the broker, so a launcher gone stops a paused run too.
        if heartbeat.elapsed() >= Duration::from_millis(200) {
            heartbeat = Instant::now();
            if let Err(e) = emit(serde_json::json!({"event": "paused"})) {
                return Some(format!("the launcher stopped reading this broker's progress ({e})"));
            }
        }
        None
    };
    let showing = board.clone();
    let show = move |line: &str| {
        showing.update(|s| match line.is_empty() {
            true => drop(s.extra.remove("paused")),
            false => drop(s.extra.insert("paused".into(), line.into())),
        });
        if !line.is_empty() {
            tracing::info!("{line}");
        }
    };
    let mut control = RemoteControl::declare(&session, &args.run, Box::new(must_stop), Box::new(show))?;
    let mut debugger = Debugger::new(args.break_on, &mut control);
    let mut outcome = setup.run_debug(nodes, &info, &mut report, &mut debugger);
    if let Some(r) = recorder {
        r.close(&mut outcome.summary, &args.out);
    }
    board.update(|s| {
        s.health = if outcome.summary.status.is_ok() {
            "finished"
        } else {
            "failed"
        }
        .into();
        s.message = outcome.summary.message.clone();
        s.extra.insert(
            "contact_stats".into(),
            serde_json::to_value(&outcome.summary.contact_stats).unwrap_or_default(),
        );
        s.extra.insert(
            "timings".into(),
            serde_json::to_value(&outcome.summary.timings).unwrap_or_default(),
        );
    });
    // Nobody may be reading any more (the launcher gone): the summary on disk says the same.
    let _ = emit(
        serde_json::json!({"event": "done", "status": outcome.summary.status, "message": outcome.summary.message}),
    );
    match outcome.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// `wait()` with the error turned into anyhow.
trait WaitOk<T> {
    fn wait_ok(self) -> anyhow::Result<T>;
}

impl<R: zenoh::Wait + zenoh::Resolvable<To = zenoh::Result<T>>, T> WaitOk<T> for R {
    fn wait_ok(self) -> anyhow::Result<T> {
        self.wait().map_err(|e| anyhow::anyhow!("{e}"))
    }
}
