//! The step coordinator (`DESIGN.md` §3): fixes each coupling step, holds the step barrier, runs the contact pass,
//! samples probes and writes the outputs. It talks to the solvers only through [`crate::link::NodeLink`], so it
//! runs the same in-process and distributed.
//!
//! The step loop is `drive`, written as its sequence of named steps; each step is a file here:
//! `step_time.rs` (how long the step is, and the output times it lands on), `exchange.rs` (the commands out and
//! the answers in, checked), `contact_pass.rs` (contact on the states just reported), `sampling.rs` (probes and
//! frames at the output times), `progress.rs` (the report to whoever runs it, who may stop it) and
//! `checkpointing.rs` (checkpoints between two steps, and continuing from one).

use std::path::Path;
use std::time::Instant;

use cosim_proto::run_status::RunStatus;
use cosim_proto::scene::LoadedScene;

use crate::link::LinkError;
use crate::summary::{Summary, SummaryBuilder};

mod checkpointing;
mod contact_pass;
mod exchange;
mod inputs;
pub mod pause;
mod progress;
mod sampling;
mod step_time;

use checkpointing::{RunState, Schedule};
use contact_pass::ContactPass;
use exchange::check_registrations;
pub use inputs::{Checkpoints, Nodes, RunInfo};
use pause::{Debugger, Halt};
pub use progress::{Control, Progress};
use sampling::{Outputs, Series};
pub use step_time::first_step;
use step_time::Clock;

/// A finished run: its summary (also written to `summary.json`) and the error that ended it, if any.
pub struct Outcome {
    /// The summary.
    pub summary: Summary,
    /// Set when the run did not finish.
    pub error: Option<anyhow::Error>,
}

/// Run a scene to its end time (or to the first failure) and write every output.
pub fn run(
    scene: &LoadedScene,
    nodes: Nodes<'_>,
    info: &RunInfo,
    progress: &mut dyn FnMut(Progress) -> Control,
) -> Outcome {
    run_with(scene, nodes, info, &Checkpoints::default(), progress)
}

/// [`run`], writing checkpoints or continuing from one.
pub fn run_with(
    scene: &LoadedScene,
    nodes: Nodes<'_>,
    info: &RunInfo,
    plan: &Checkpoints,
    progress: &mut dyn FnMut(Progress) -> Control,
) -> Outcome {
    run_debug(scene, nodes, info, plan, progress, None)
}

/// [`run_with`], paused and driven by `debugger` between two steps (`cosim run --break`, `cosim ctl`).
pub fn run_debug(
    scene: &LoadedScene,
    mut nodes: Nodes<'_>,
    info: &RunInfo,
    plan: &Checkpoints,
    progress: &mut dyn FnMut(Progress) -> Control,
    debugger: Option<&mut Debugger<'_>>,
) -> Outcome {
    let started = Instant::now();
    let (fem_nodes, fem_elements) = nodes
        .fem
        .as_ref()
        .map_or((0, 0), |f| (f.setup().nodes.len() as u64, f.setup().cells.len() as u64));
    let particles = nodes.sph.as_ref().map_or(0, |n| u64::from(n.setup().particles));
    let mut summary = SummaryBuilder::new(&info.run_id, &info.mode)
        .scene(&scene.scene)
        .sizes(particles, fem_nodes, fem_elements)
        .running();
    let mut series = Vec::new();
    let error = drive(
        scene,
        &mut nodes,
        info,
        plan,
        progress,
        &mut summary,
        &mut series,
        debugger,
    )
    .err();
    if error.is_some() {
        // What the nodes still alive counted up to the failure (a finished run asked them before its stop); then
        // they are told to stop.
        collect_counts(&mut nodes, &mut summary);
        exchange::farewell(&mut nodes);
    }
    // Whatever happened, the probes computed so far are plotted and the summary is written.
    let t_plot = Instant::now();
    if let Err(e) = sampling::plot_all(scene, &info.out, &series) {
        tracing::warn!("plots: {e:#}");
    }
    summary.timings.broker += t_plot.elapsed().as_secs_f64();
    let failure = error.as_ref().map(|e| {
        let status = e
            .downcast_ref::<LinkError>()
            .map_or(RunStatus::Failed, LinkError::status);
        (status, format!("{e:#}").replace('\n', " "))
    });
    summary.end(failure, started.elapsed().as_secs_f64());
    if let Err(e) = write_summary(&info.out, &summary) {
        tracing::error!("{e:#}");
    }
    Outcome { summary, error }
}

/// The run from its first command to its last: the step loop (`DESIGN.md` §3).
#[allow(clippy::too_many_arguments)]
fn drive(
    scene: &LoadedScene,
    nodes: &mut Nodes<'_>,
    info: &RunInfo,
    plan: &Checkpoints,
    progress: &mut dyn FnMut(Progress) -> Control,
    summary: &mut Summary,
    series: &mut Series,
    mut debugger: Option<&mut Debugger<'_>>,
) -> anyhow::Result<()> {
    let s = &scene.scene;
    check_registrations(s, nodes)?;
    let expected = exchange::Expected::new(s, nodes);
    let mut outputs = Outputs::open(scene, nodes, &info.out, plan.restart.as_ref(), series)?;
    let mut contact = ContactPass::new(s, nodes)?;
    summary.reaction_relaxation = contact.relaxation().cloned();
    let dt_fluid = nodes.sph.as_ref().map_or(f64::INFINITY, |n| n.setup().dt_stable);
    let mut clock = Clock::new(s, nodes.fem.is_some(), dt_fluid);
    let mut checkpoints = Schedule::new(plan.interval);
    match &plan.restart {
        Some(saved) => checkpointing::resume(saved, &mut checkpoints, &mut clock, &mut contact, &mut outputs, summary)?,
        // The first sample, at t = 0.
        None => {
            let commands = contact.commands(0.0, true);
            let mut round = exchange::exchange(nodes, &expected, summary, 0, 0.0, commands)?;
            outputs.sample(
                0.0,
                false,
                &mut round,
                nodes,
                contact.load.as_deref(),
                &mut contact.since,
                summary,
            )?;
        }
    }
    let mut stepping = || -> anyhow::Result<()> {
        while clock.running() {
            // §3 step 1: how long this step is, and whether it lands on an output time.
            let step = clock.next_step();
            clock.check_step(&step)?;
            // §3 steps 2–3: the commands out (with the last pass's corrections), the states in.
            let commands = contact.commands(step.dt, step.lands);
            let mut round = exchange::exchange(nodes, &expected, summary, clock.step, clock.t, commands)?;
            clock.advance(&step, &round, summary);
            // §3 step 4: contact on the states just reported; the corrections go out with the next command.
            contact.pass(&round, &step, clock.step, clock.t, summary)?;
            clock.contact_bound(contact.last.stable_dt);
            summary.contact_step_bound = clock.dt_contact.is_finite().then_some(clock.dt_contact);
            // §5: probes and frames at an output time.
            if step.lands {
                outputs.sample(
                    clock.t,
                    !clock.running(),
                    &mut round,
                    nodes,
                    contact.load.as_deref(),
                    &mut contact.since,
                    summary,
                )?;
                clock.sampled(&step);
            }
            progress::report(progress, &clock, &contact, summary)?;
            let state = RunState {
                clock: &clock,
                contact: &contact,
                outputs: &outputs,
                summary,
            };
            checkpointing::save_if_due(&mut checkpoints, &step, state, scene, nodes, info)?;
            // Between two steps, every node waiting for its next command: where a run pauses (`pause.rs`).
            if let Some(debugger) = debugger.as_deref_mut() {
                let mut halt = halt_now(&clock, summary, &contact, nodes);
                debugger.after_step(&mut halt).map_err(|why| {
                    anyhow::anyhow!(
                        "stopped after coupling step {} (t = {} s): {why}",
                        clock.step,
                        cosim_proto::Num(cosim_proto::readable::significant(clock.t, 12))
                    )
                })?;
            }
        }
        Ok(())
    };
    if let Err(e) = stepping() {
        // `--break unstable`: a blow-up pauses the run where it happened, every process alive, until it is stopped.
        let unstable = e.downcast_ref::<LinkError>().map(LinkError::status) == Some(RunStatus::Unstable);
        if let (true, Some(debugger)) = (unstable, debugger) {
            let mut halt = halt_now(&clock, summary, &contact, nodes);
            debugger.on_unstable(&mut halt, &format!("{e:#}").replace('\n', " "));
        }
        return Err(e);
    }
    collect_counts(nodes, summary);
    exchange::stop(nodes, clock.step + 1, clock.t)?;
    outputs.finish(summary)
}

/// Each node's counts into the summary (`Summary::counts`), for the nodes that can say.
fn collect_counts(nodes: &mut Nodes<'_>, summary: &mut Summary) {
    if let Some(counts) = nodes.fem.as_deref_mut().and_then(|l| l.counts()) {
        summary.counts.insert("fem-node".into(), counts);
    }
    if let Some(counts) = nodes.sph.as_deref_mut().and_then(|l| l.counts()) {
        summary.counts.insert("sph-node".into(), counts);
    }
}

/// Write `summary.json` in place over the room reserved for it when the run started (`crate::summary`), so that
/// it is written however full the disk got; an error names the file.
pub fn write_summary(out: &Path, summary: &Summary) -> anyhow::Result<()> {
    Ok(crate::summary::write(out, summary)?)
}

/// The run as it stands between two steps, for the debugger (`pause.rs`).
fn halt_now<'a, 'n>(
    clock: &Clock,
    summary: &Summary,
    contact: &'a ContactPass,
    nodes: &'a mut Nodes<'n>,
) -> Halt<'a, 'n> {
    let max_penetration = summary.contact_stats.max_penetration;
    Halt::new(
        clock.step,
        clock.t,
        max_penetration,
        &contact.pending,
        contact.contacts(),
        nodes,
    )
}
