//! `cosim run`: validate the scene, prepare the output folder, run it (processes or in-process), report.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use contact_broker::coordinator::{Nodes, RunInfo};
use contact_broker::energy_balance::{made_energy, shorter_step};
use contact_broker::link::NodeLink;
use contact_broker::recorder::{Recorded, Recorder, Tap};
use contact_broker::setup::RunSetup;
use contact_broker::summary::{self, Summary};
use cosim_bus::interrupt::Interrupt;
use cosim_bus::serve::{check_restored_time, NodeCore};
use cosim_proto::keys::{fresh_run_id, valid_run_id};
use cosim_proto::scene::{LoadedScene, STRUCTURE_COURANT_DEFAULT, STRUCTURE_COURANT_MIN};
use cosim_proto::sizing::Part;
use cosim_proto::trace::Node;
use fem_node::core::FemCore;
use sph_node::core::SphCore;

use crate::cli::{ExternalNode, RunArgs};
use crate::in_process;
use crate::launch;
use crate::progress::Bar;

/// Run a scene; `Err` only for bad input (exit 2), a failed run is exit 1 with one line on stderr.
pub fn run(args: &RunArgs) -> anyhow::Result<ExitCode> {
    // Before anything is built or started: a scene too big for this machine is bad input, said with its key.
    let setup = RunSetup::load(&args.scene, &args.set, Part::Run)?;
    let scene = &setup.scene;
    let run_id = match &args.run_id {
        Some(id) if valid_run_id(id) => id.clone(),
        Some(id) => anyhow::bail!("--run-id `{id}`: use 1–64 letters, digits, - and _"),
        None => fresh_run_id(),
    };
    // A zenoh config file that cannot be read or parsed is bad input, said once here rather than by each process.
    let args = &match &args.zenoh_config {
        Some(file) => {
            cosim_bus::session::base_config(Some(file))?;
            let absolute = std::path::absolute(file).with_context(|| format!("zenoh config {}", file.display()))?;
            RunArgs {
                zenoh_config: Some(absolute),
                ..args.clone()
            }
        }
        None => args.clone(),
    };
    if let Some(node) = args.external {
        anyhow::ensure!(
            !args.in_process,
            "--external {}: an outside program joins over zenoh, so it needs processes mode (drop --in-process)",
            node.name()
        );
        let present = match node {
            ExternalNode::Fem => !scene.scene.solids.is_empty(),
            ExternalNode::Sph => scene.scene.fluid.is_some(),
        };
        anyhow::ensure!(
            present,
            "--external {}: {} has no {} for it to solve",
            node.name(),
            args.scene.display(),
            match node {
                ExternalNode::Fem => "[[solid]]",
                ExternalNode::Sph => "[fluid]",
            }
        );
        anyhow::ensure!(
            args.wait_external.is_finite() && args.wait_external > 0.0,
            "--wait-external must be a positive number of seconds, got {}",
            cosim_proto::Num(args.wait_external)
        );
    }
    if let (Some(condition), true) = (&args.break_on, args.in_process) {
        anyhow::bail!(
            "--break {condition}: a paused run is driven from another process (`cosim ctl`), so it needs processes \
             mode (drop --in-process)"
        );
    }
    if let (Some(node), true) = (
        args.external,
        args.checkpoint_interval.is_some() || args.restart.is_some(),
    ) {
        anyhow::bail!(
            "--external {}: checkpoints and restarts need every node's state, which an outside program does not \
             save (drop --checkpoint-interval and --restart)",
            node.name()
        );
    }
    // Checked here, before anything is cleared or started: the wrong checkpoint is bad input (exit 2).
    let setup = setup.with_checkpoints(args.checkpoint_interval, args.restart.as_deref())?;
    let scene = &setup.scene;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(&scene.scene.run.name));
    // Outputs that cannot fit the folder's disk are bad input too, said before the folder is touched.
    if !args.ignore_disk_space {
        setup.refuse_full_disk(&out)?;
    }
    // A restart into the folder of the run it continues keeps that run's frames; anywhere else they are cleared.
    let own_folder = setup.restart.as_ref().is_some_and(|r| {
        let parent = r
            .dir
            .canonicalize()
            .ok()
            .and_then(|d| d.parent().map(Path::to_path_buf));
        parent.is_some() && parent == out.join("checkpoints").canonicalize().ok()
    });
    let info = RunInfo {
        run_id,
        mode: if args.in_process { "in-process" } else { "processes" }.into(),
        out: out.clone(),
    };
    // Through a router the run id may be live already (another `cosim run` on it): refused here, before the
    // output folder (maybe that run's) is touched. The broker checks it again (`cosim_bus::claim`).
    if let (Some(connect), false) = (&args.connect, args.in_process) {
        launch::ensure_run_id_free(connect, args.zenoh_config.as_deref(), &info.run_id)?;
    }
    prepare_out(&out, scene, &info, own_folder, &args.beside)?;
    // Not refused: a mesh that fine for this fluid runs, but its energy is not to be trusted (mass_ratio.rs).
    // The fluid's first stable step estimated from the scene (WCSPH at rest): how many of them a contact pass spans.
    let s = &scene.scene;
    let dt_fluid = s
        .fluid
        .as_ref()
        .and_then(|f| sph_node::time_step::at_rest(f, s.run.gravity));
    for w in s.warnings(dt_fluid.unwrap_or(f64::INFINITY)) {
        eprintln!("cosim: warning: {w}");
    }
    let bar = Bar::new(args.quiet);
    let result = if args.in_process {
        run_in_process(args, &setup, &info, &bar)
    } else {
        launch::run_processes(args, &scene.scene, &info, &bar)
    };
    bar.finish();
    // Whatever ended the run before its summary, the summary says it (in place of the one reserved).
    let summary = match result {
        Ok(summary) => summary,
        Err(e) => {
            let message = format!("{e:#}").replace('\n', " ");
            let summary = Summary::failed(&info.run_id, &info.mode, message);
            if let Err(w) = summary::write(&out, &summary) {
                eprintln!("cosim: {w}");
            }
            // The broker refused the run id (`cosim_bus::claim`): refused input, exit code 2.
            if launch::is_refused(&e) {
                eprintln!("cosim: {} (summary in {})", summary.message, out.display());
                return Ok(ExitCode::from(2));
            }
            eprintln!("cosim: {} (outputs so far in {})", summary.message, out.display());
            return Ok(ExitCode::from(1));
        }
    };
    if summary.status.is_ok() {
        println!(
            "ok: {} steps to t = {} s in {:.2} s ({}) -> {}",
            summary.steps,
            cosim_proto::Num(summary.sim_time),
            summary.wall_seconds,
            summary.mode,
            out.display()
        );
        // `--record` that could not keep the whole run (`contact_broker::recorder`): the outputs are whole.
        if let Some(why) = summary.trace.as_ref().and_then(|t| t.stopped.as_ref()) {
            eprintln!("cosim: warning: the trace holds the run only in part: the recording stopped {why}");
        }
        // A structure node past the walls' contact (`contact_broker::wall_entry`).
        if let Some(e) = summary.solid_in_wall.as_ref() {
            eprintln!(
                "cosim: warning: at t = {} s node {} of solid `{}` was {:.3e} m inside wall[{}]: deeper than the \
                 walls' contact leaves a surface node, so it went past it, and what followed is not the tank's \
                 physics (summary.json solid_in_wall)",
                cosim_proto::Num(e.t),
                e.node,
                e.solid,
                e.depth,
                e.wall
            );
        }
        // A balance that cannot see a gain of the warning's size: the energies it sums are too large beside the
        // water's (`EnergyGrowth::rounding`).
        if let Some(g) = summary.energy_growth.as_ref().filter(|g| made_energy(g.rounding)) {
            eprintln!(
                "cosim: note: the energy balance cannot see a gain under {:.1} % of the {:.4} J/m the water can \
                 release: the energies it sums are so large beside it that rounding alone can move their balance that \
                 much (summary.json energy_growth.rounding)",
                cosim_proto::Num(200.0 * g.rounding),
                cosim_proto::Num(g.budget)
            );
        }
        // Ok, but not to be trusted without a look: energy the scheme made (`contact_broker::energy_balance`).
        if let Some(g) = summary.energy_growth.as_ref().filter(|g| made_energy(g.largest)) {
            eprintln!(
                "cosim: warning: the fluid and the structure gained {:.1} % of the {:.4} J/m the water can release \
                 (the most at t = {} s), which nothing in the scene supplies: the numerical scheme made it; see \
                 summary.json energy_growth",
                cosim_proto::Num(100.0 * g.largest),
                cosim_proto::Num(g.budget),
                cosim_proto::Num(g.at)
            );
            if let Some(h) = shorter_step(summary.sim_time, summary.steps) {
                eprintln!(
                    "cosim: a shorter coupling step is the first thing to try: this run's averaged {:.2e} s, e.g. \
                     --set coupling.max_dt={:.0e}",
                    h.mean, h.try_dt
                );
            }
            // A structure whose surface moves a large part of h between two contact passes (docs/CORRECTIONS.md
            // "The coupling step bounded by the structure's speed").
            let c = scene.scene.coupling.structure_courant;
            // (Halved down to the key's least value; at that value there is nothing shorter to suggest.)
            if !scene.scene.solids.is_empty() && scene.scene.fluid.is_some() && (c == 0.0 || c > STRUCTURE_COURANT_MIN)
            {
                let try_c = if c > 0.0 {
                    (0.5 * c).max(STRUCTURE_COURANT_MIN)
                } else {
                    STRUCTURE_COURANT_DEFAULT
                };
                eprintln!(
                    "cosim: so is a step bounded by the structure's speed, --set coupling.structure_courant={try_c} \
                     (now {c})"
                );
            }
            // A structure whose mesh rings under the contact's impulses: a tenth of the damping first measured holds
            // it as well (docs/CORRECTIONS.md "The structure's sub-steps of changing length").
            if let Some(i) = scene.scene.solids.iter().position(|s| s.mesh_damping() == 0.0) {
                eprintln!(
                    "cosim: so is damping the structure's mesh-scale ringing, --set solid[{i}].mesh_damping=0.02 \
                     (docs/CORRECTIONS.md)"
                );
            }
        }
        Ok(ExitCode::SUCCESS)
    } else {
        eprintln!(
            "cosim: run {}: {} (outputs so far in {})",
            summary.status,
            summary.message,
            out.display()
        );
        Ok(ExitCode::from(1))
    }
}

/// Create the folder, clear the outputs of an earlier run there, reserve `summary.json` (`contact_broker::summary`)
/// and keep the resolved scene beside them. A restart into the folder of the run it continues (`keep_frames`) keeps
/// the frames: those before the checkpoint stay (and stay listed in the `.pvd` collections); the later ones are
/// written again. The logs of the run that stopped, which explain why, move to `logs.before-restart`.
fn prepare_out(
    out: &Path,
    scene: &LoadedScene,
    info: &RunInfo,
    keep_frames: bool,
    beside: &[String],
) -> anyhow::Result<()> {
    let beside: Vec<&str> = beside.iter().map(String::as_str).collect();
    contact_broker::output::folder::refuse_foreign(out, &beside)?;
    std::fs::create_dir_all(out).with_context(|| format!("cannot create the output folder {}", out.display()))?;
    if keep_frames {
        let (logs, kept) = (out.join("logs"), out.join("logs.before-restart"));
        if logs.exists() {
            let _ = std::fs::remove_dir_all(&kept);
            std::fs::rename(&logs, &kept).with_context(|| format!("cannot keep {}", logs.display()))?;
        }
    }
    let stale_dirs: &[&str] = if keep_frames {
        &["plots"]
    } else {
        &["frames", "plots", "logs"]
    };
    for stale in stale_dirs {
        let dir = out.join(stale);
        if dir.exists() {
            std::fs::remove_dir_all(&dir).with_context(|| format!("cannot clear {}", dir.display()))?;
        }
    }
    for stale in ["summary.json", "probes.csv"] {
        let _ = std::fs::remove_file(out.join(stale));
    }
    // First, so that a disk that fills up later still has the room for it.
    summary::reserve(out, &info.run_id, &info.mode)?;
    std::fs::write(out.join("scene.toml"), scene.scene.to_toml())
        .with_context(|| format!("cannot write {}", out.join("scene.toml").display()))?;
    Ok(())
}

/// The run in this process: the solver cores (restored from the checkpoint, if any) driven by the coordinator.
fn run_in_process(args: &RunArgs, setup: &RunSetup, info: &RunInfo, bar: &Bar) -> anyhow::Result<Summary> {
    if let Some(n) = args.threads {
        rayon_threads(n)?;
    }
    let scene = &setup.scene;
    // `--record`: the messages the nodes would exchange as processes (`docs/PROTOCOL.md` §10).
    let recorder = match args.record {
        true => Some(Recorder::begin(
            &info.out,
            &info.run_id,
            setup,
            !args.ignore_disk_space,
        )?),
        false => None,
    };
    let fem_core = match scene.scene.solids.is_empty() {
        false => {
            let mut core = FemCore::new(&scene.scene).context("fem-node")?;
            if let Some(data) = setup.saved_fem() {
                core.restore(data)
                    .context("fem-node: cannot restart from the checkpoint")?;
                let t = NodeCore::time(&core);
                check_restored_time(t, setup.restart_time(), scene.scene.coupling.max_dt).context("fem-node")?;
            }
            Some(core)
        }
        true => None,
    };
    let sph_core = match scene.scene.fluid {
        Some(_) => {
            let mut core = SphCore::new(&scene.scene).context("sph-node")?;
            if let Some(data) = setup.saved_sph() {
                core.restore(data)
                    .context("sph-node: cannot restart from the checkpoint")?;
                let t = NodeCore::time(&core);
                check_restored_time(t, setup.restart_time(), scene.scene.coupling.max_dt).context("sph-node")?;
            }
            Some(core)
        }
        None => None,
    };
    // Ctrl-C stops the run between two steps with its outputs written (a second one ends it at once); a step still
    // in progress 2 s after it is given up between two of its sub-steps. (Caught from here: during the set-up above
    // Ctrl-C ends the process at once, as there is nothing to keep yet.)
    let interrupt = Interrupt::install().context("cannot catch SIGINT and SIGTERM")?;
    let mut fem = fem_core.map(|mut core| {
        core.stop_on(interrupt.clone());
        recorded(in_process::link("fem-node", core), &recorder, Node::Fem, info)
    });
    let mut sph = sph_core.map(|mut core| {
        core.stop_on(interrupt.clone());
        recorded(in_process::link("sph-node", core), &recorder, Node::Sph, info)
    });
    let nodes = Nodes {
        fem: fem.as_deref_mut(),
        sph: sph.as_deref_mut(),
    };
    let outcome = setup.run(nodes, info, &mut |p| {
        bar.update(p);
        interrupt.control()
    });
    let mut summary = outcome.summary;
    if let Some(r) = &recorder {
        r.close(&mut summary, &info.out);
    }
    Ok(summary)
}

/// `link`, its messages recorded when `recorder` is set.
fn recorded<L>(
    link: L,
    recorder: &Option<Recorder>,
    node: Node,
    info: &RunInfo,
) -> Box<dyn NodeLink<Setup = L::Setup, State = L::State>>
where
    L: NodeLink + 'static,
    L::Setup: serde::Serialize,
    L::State: serde::Serialize,
{
    match recorder {
        Some(r) => {
            let tap = Tap {
                recorder: r.clone(),
                node,
            };
            Box::new(Recorded::new(link, tap, &info.run_id))
        }
        None => Box::new(link),
    }
}

fn rayon_threads(n: usize) -> anyhow::Result<()> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build_global()
        .map_err(|e| anyhow::anyhow!("--threads {n}: {e}"))
}
