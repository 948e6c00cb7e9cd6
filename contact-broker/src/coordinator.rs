//! The step coordinator (`DESIGN.md` §3): fixes each coupling step, holds the step barrier, samples probes and
//! writes the outputs. It talks to the solvers only through [`crate::link::NodeLink`], so it runs the same in-process and
//! distributed.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context;

use cosim_proto::messages::{FemMesh, FemState, SphSnapshot, SphState, StepCommand};
use cosim_proto::scene::LoadedScene;
use cosim_proto::validate::{Asked, Invalid};

use crate::checkpoint::{self, BrokerState};
use crate::interface::{Corrections, Interface, PassStats};
use crate::link::{FemLink, LinkError, Reply, SphLink};
use crate::output::{plot_probe, FrameQueue, FrameWriter, Part, PointField, ProbeCsv};
use crate::probes::Probes;
use crate::summary::{ContactStats, Summary};

/// Progress of a run, reported after each coupling step.
#[derive(Clone, Copy, Debug, Default)]
pub struct Progress {
    /// Coupling steps taken.
    pub step: u64,
    /// Simulated time [s].
    pub t: f64,
    /// End time [s].
    pub end_time: f64,
    /// Contacts the last contact pass resolved.
    pub contacts: u64,
    /// Deepest penetration of the contact thickness so far [m].
    pub max_penetration: f64,
    /// Fluid particles exchanged in the last step (the region of interest).
    pub exchanged: u64,
}

/// How the run is launched, for the summary.
#[derive(Clone, Debug)]
pub struct RunInfo {
    /// Run id.
    pub run_id: String,
    /// `processes` | `in-process`.
    pub mode: String,
    /// Output folder.
    pub out: PathBuf,
}

/// A finished run: its summary (also written to `summary.json`) and the error that ended it, if any.
pub struct Outcome {
    /// The summary.
    pub summary: Summary,
    /// Set when the run did not finish.
    pub error: Option<anyhow::Error>,
}

/// Steps closer than this fraction of `max_dt` to an output time land on it.
const LANDING: f64 = 1e-9;

/// The nodes of a run; a scene without fluid has no fluid node and vice versa.
pub struct Nodes<'a> {
    /// The structure node.
    pub fem: Option<&'a mut FemLink>,
    /// The fluid node.
    pub sph: Option<&'a mut SphLink>,
}

/// Checkpoints to write, and the one to continue from.
#[derive(Debug, Default)]
pub struct Checkpoints {
    /// Write `DIR/checkpoints/<step>/` at the first step at or after every multiple of this simulated time [s].
    pub interval: Option<f64>,
    /// Continue from this checkpoint's coordinator state (the nodes were given theirs when they started).
    pub restart: Option<BrokerState>,
}

/// What the run's progress callback answers after each step: go on, or stop the run now for the reason given (the
/// run then ends `failed` with that reason, its outputs so far written, like any other failure).
pub type Control = std::ops::ControlFlow<String>;

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
    mut nodes: Nodes<'_>,
    info: &RunInfo,
    plan: &Checkpoints,
    progress: &mut dyn FnMut(Progress) -> Control,
) -> Outcome {
    let started = Instant::now();
    let s = &scene.scene;
    let (fem_nodes, fem_elements) = nodes
        .fem
        .as_ref()
        .map_or((0, 0), |f| (f.setup().nodes.len() as u64, f.setup().cells.len() as u64));
    // Every counter starts at zero, as in the summary of a run that failed before it computed anything.
    let mut summary = Summary {
        status: "ok".into(),
        message: String::new(),
        scene: s.run.name.clone(),
        particles: nodes.sph.as_ref().map_or(0, |n| u64::from(n.setup().particles)),
        fem_nodes,
        fem_elements,
        solver: s
            .fluid
            .as_ref()
            .map_or("none".into(), |f| format!("{:?}", f.solver).to_lowercase()),
        contact: if s.fluid.is_some() && !s.solids.is_empty() {
            s.contact.algorithm.name().into()
        } else {
            "none".into()
        },
        ..Summary::failed(&info.run_id, &info.mode, String::new())
    };
    let mut series = Vec::new();
    let error = drive(scene, &mut nodes, info, plan, progress, &mut summary, &mut series).err();
    if error.is_some() {
        // What the nodes still alive counted up to the failure (a finished run asked them before its stop).
        collect_counts(&mut nodes, &mut summary);
    }
    // Whatever happened, the probes computed so far are plotted and the summary is written.
    let t_plot = Instant::now();
    if let Err(e) = plot_all(scene, &info.out, &series) {
        tracing::warn!("plots: {e:#}");
    }
    summary.timings.broker += t_plot.elapsed().as_secs_f64();
    if let Some(e) = &error {
        summary.status = match e.downcast_ref::<LinkError>() {
            Some(l) => l.status().into(),
            None => "failed".into(),
        };
        summary.message = format!("{e:#}").replace('\n', " ");
    } else {
        summary.message = format!("reached t = {} s in {} steps", summary.sim_time, summary.steps);
    }
    summary.wall_seconds = started.elapsed().as_secs_f64();
    if let Err(e) = write_summary(&info.out, &summary) {
        tracing::error!("{e:#}");
    }
    Outcome { summary, error }
}

/// Probe values over time, per probe.
type Series = Vec<Vec<(f64, f64)>>;

/// The answers of one coupling step.
struct Round {
    fem: Option<FemState>,
    sph: Option<SphState>,
}

fn drive(
    scene: &LoadedScene,
    nodes: &mut Nodes<'_>,
    info: &RunInfo,
    plan: &Checkpoints,
    progress: &mut dyn FnMut(Progress) -> Control,
    summary: &mut Summary,
    series: &mut Series,
) -> anyhow::Result<()> {
    let s = &scene.scene;
    // docs/PROTOCOL.md §7 "Contents": the registrations are checked before anything indexes them.
    if let Some(link) = &nodes.fem {
        link.setup().validate().map_err(|e| unusable("fem-node", e))?;
    }
    if let Some(link) = &nodes.sph {
        link.setup().validate().map_err(|e| unusable("sph-node", e))?;
    }
    let interface_ids = nodes
        .fem
        .as_ref()
        .map_or_else(Vec::new, |f| f.setup().interface_nodes());
    let probes = Probes::resolve(
        s,
        nodes.fem.as_ref().map(|f| f.setup()),
        nodes.sph.as_ref().map(|n| n.setup()),
    )
    .map_err(anyhow::Error::msg)?;
    *series = vec![Vec::new(); probes.names().len()];
    // Frames are encoded and written on their own thread (output/queue.rs), from the snapshots handed over.
    let writer = match &plan.restart {
        Some(saved) => FrameWriter::resume(&info.out, &saved.rows.iter().map(|r| r.0).collect::<Vec<_>>())?,
        None => FrameWriter::new(&info.out)?,
    };
    let frames = FrameQueue::new(writer)?;
    let mesh = nodes.fem.as_ref().map(|f| Arc::new(f.setup().clone()));
    let walls = nodes.sph.as_ref().map(|n| Arc::new(n.setup().walls.clone()));
    let density = nodes.sph.as_ref().map_or(0.0, |n| n.setup().density);
    let csv = ProbeCsv::create(&info.out.join("probes.csv"), probes.names())?;
    let interval = s.run.output_interval;
    let end = s.run.end_time;
    let mut out = Outputs {
        probes,
        csv,
        frames,
        series,
        mesh,
        walls,
        density,
    };

    // DESIGN.md §3: with both a structure and a fluid the broker runs the contact pass between steps.
    let mut interface = match (&nodes.fem, &nodes.sph) {
        (Some(f), Some(p)) => Some(Interface::new(s, f.setup(), p.setup())?),
        _ => None,
    };
    let mut roi = interface.as_ref().map(|i| {
        let mesh = nodes.fem.as_ref().expect("interface has a structure").setup();
        let x: Vec<[f64; 2]> = i.node_ids().iter().map(|&id| mesh.nodes[id as usize]).collect();
        i.roi(&x)
    });
    let mut pending = Corrections::default();
    let mut load = None;
    let mut exchanged = 0u64;
    let mut last_pass = PassStats::default();

    let mut t = 0.0;
    let mut step = 0u64;
    let coupled = interface.is_some();
    let mut dt_fluid = nodes.sph.as_ref().map_or(f64::INFINITY, |n| n.setup().dt_stable);
    let mut next_output = 1u64;
    let mut next_checkpoint = 1u64;
    match &plan.restart {
        // Continue where the checkpoint left off: the nodes restored their own states when they started.
        Some(saved) => {
            saved.check_nodes(summary.fem_nodes, summary.particles)?;
            (t, step, next_output, dt_fluid) = (saved.t, saved.step, saved.next_output, saved.dt_fluid);
            // From the time, not the saved index: the restart may ask for another interval.
            next_checkpoint = plan
                .interval
                .map_or(saved.next_checkpoint, |i| checkpoint_after(t, i, 0.0));
            pending = Corrections {
                fem: saved.pending_fem.clone(),
                sph: saved.pending_sph.clone(),
            };
            (roi, load, exchanged) = (saved.roi, saved.load.clone(), saved.exchanged);
            out.probes.set_fluid_origin(saved.fluid_origin.clone());
            for (t, values) in &saved.rows {
                out.csv.push(*t, values)?;
                for (line, v) in out.series.iter_mut().zip(values) {
                    line.push((*t, *v));
                }
            }
            let s = &saved.summary;
            summary.steps = s.steps;
            summary.fem_substeps = s.fem_substeps;
            summary.sph_substeps = s.sph_substeps;
            summary.sim_time = s.sim_time;
            summary.frames = s.frames;
            summary.samples = s.samples;
            summary.timings = s.timings.clone();
            summary.contact_stats = s.contact_stats.clone();
        }
        None => {
            let mut round = exchange(
                nodes,
                &interface_ids,
                summary,
                step,
                t,
                commands(0.0, true, coupled, roi, &mut pending),
            )?;
            out.sample(t, &mut round, nodes, load.as_deref(), summary)?;
        }
    }
    while t < end {
        let target = (next_output as f64 * interval).min(end);
        // §3 step 1: the coupling step is the fluid's stable step, capped by the user and the next output time.
        // Without a structure there is nothing to couple: the fluid node sub-cycles at its own stable step.
        let cap = if nodes.fem.is_some() {
            s.coupling.max_dt.min(dt_fluid)
        } else {
            s.coupling.max_dt
        };
        let mut dt = cap.min(target - t);
        let lands = target - (t + dt) <= LANDING * cap;
        if lands {
            dt = target - t;
        }
        step += 1;
        let mut round = exchange(
            nodes,
            &interface_ids,
            summary,
            step,
            t,
            commands(dt, lands, coupled, roi, &mut pending),
        )?;
        if let Some(state) = &round.fem {
            summary.fem_substeps += u64::from(state.substeps);
        }
        if let Some(state) = &round.sph {
            dt_fluid = state.dt_stable;
            summary.sph_substeps += u64::from(state.substeps);
        }
        t = if lands { target } else { t + dt };
        summary.steps = step;
        summary.sim_time = t;
        // §3 step 4: contact on the states just reported; the corrections go out with the next command.
        if let (Some(interface), Some(fem), Some(sph)) = (interface.as_mut(), &round.fem, &round.sph) {
            let started = Instant::now();
            let (corrections, stats) = interface
                .pass(fem, sph, dt)
                .with_context(|| format!("contact pass of coupling step {step} at t = {t} s"))?;
            pending = corrections;
            last_pass = stats.clone();
            roi = Some(interface.roi(&fem.x));
            exchanged += stats.exchanged as u64;
            record(&mut summary.contact_stats, &stats, exchanged, step);
            if lands {
                load = Some(interface.load());
            }
            summary.timings.broker += started.elapsed().as_secs_f64();
        }
        if lands {
            out.sample(t, &mut round, nodes, load.as_deref(), summary)?;
            if target >= next_output as f64 * interval {
                next_output += 1;
            }
        }
        let control = progress(Progress {
            step,
            t,
            end_time: end,
            contacts: last_pass.contacts as u64,
            max_penetration: summary.contact_stats.max_penetration,
            exchanged: last_pass.exchanged as u64,
        });
        if let Control::Break(why) = control {
            anyhow::bail!("stopped after coupling step {step} (t = {t} s): {why}");
        }
        // Between two steps: every node answered `step`, its corrections are still to be sent.
        // The last step too, so that a finished run can be continued further.
        if let Some(interval) = plan.interval {
            if t >= next_checkpoint as f64 * interval - LANDING * cap || t >= end {
                next_checkpoint = checkpoint_after(t, interval, LANDING * cap);
                let state = BrokerState {
                    step,
                    t,
                    next_output,
                    next_checkpoint,
                    dt_fluid,
                    pending_fem: pending.fem.clone(),
                    pending_sph: pending.sph.clone(),
                    roi,
                    load: load.clone(),
                    exchanged,
                    fluid_origin: out.probes.fluid_origin().map(<[_]>::to_vec),
                    rows: out.csv.rows().to_vec(),
                    summary: summary.clone(),
                };
                save_checkpoint(scene, nodes, info, &state)?;
            }
        }
    }
    collect_counts(nodes, summary);
    let stop = command(0.0, false, true);
    if let Some(link) = nodes.fem.as_deref_mut() {
        link.send(step + 1, t, stop.clone())?;
    }
    if let Some(link) = nodes.sph.as_deref_mut() {
        link.send(step + 1, t, stop)?;
    }
    // The frames still being written count as the broker's time.
    let started = Instant::now();
    let written = out.frames.finish();
    summary.timings.broker += started.elapsed().as_secs_f64();
    written?;
    Ok(())
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

/// Index k of the first checkpoint time k · `interval` after `t` (times within `slack` before `t` count as reached).
fn checkpoint_after(t: f64, interval: f64, slack: f64) -> u64 {
    ((t + slack) / interval + 1e-9).floor() as u64 + 1
}

/// The run's outputs: the probes and `probes.csv`, the frames (written on their own thread, `output/queue.rs`),
/// and the probe series for the plots.
struct Outputs<'s> {
    probes: Probes,
    csv: ProbeCsv,
    frames: FrameQueue,
    series: &'s mut Series,
    mesh: Option<Arc<FemMesh>>,
    walls: Option<Arc<Vec<[f64; 2]>>>,
    density: f64,
}

impl Outputs<'_> {
    /// Sample the probes and write the frames of an output time, from the snapshots of `round`.
    fn sample(
        &mut self,
        t: f64,
        round: &mut Round,
        nodes: &Nodes<'_>,
        load: Option<&[[f64; 2]]>,
        summary: &mut Summary,
    ) -> anyhow::Result<()> {
        let started = Instant::now();
        let fem = match (&nodes.fem, &round.fem) {
            (Some(link), Some(state)) => Some((link.setup(), snapshot(state.snapshot.as_ref(), "fem-node")?)),
            _ => None,
        };
        let sph = match (&nodes.sph, &round.sph) {
            (Some(link), Some(state)) => Some((link.setup(), snapshot(state.snapshot.as_ref(), "sph-node")?)),
            _ => None,
        };
        let values = self.probes.sample(fem, sph);
        self.csv.push(t, &values)?;
        for (line, v) in self.series.iter_mut().zip(&values) {
            line.push((t, *v));
        }
        let index = summary.frames as usize;
        if let (Some(mesh), Some(snap)) = (&self.mesh, round.fem.as_mut().and_then(|s| s.snapshot.take())) {
            let (mesh, load) = (Arc::clone(mesh), load.map(<[_]>::to_vec));
            self.frames.push(Box::new(move |w| {
                w.write_structure(index, t, &mesh, &snap, load.as_deref()).map(drop)
            }))?;
        }
        if let (Some(walls), Some(snap)) = (&self.walls, round.sph.as_mut().and_then(|s| s.snapshot.take())) {
            let (walls, density) = (Arc::clone(walls), self.density);
            self.frames
                .push(Box::new(move |w| write_particles(w, index, t, &walls, density, &snap)))?;
        }
        summary.frames += 1;
        summary.samples += 1;
        summary.timings.broker += started.elapsed().as_secs_f64();
        Ok(())
    }
}

/// Gather every node's state and write the checkpoint folder. A node that cannot save its state fails the run:
/// asked for checkpoints, the user must not find out at the restart that there are none.
fn save_checkpoint(
    scene: &LoadedScene,
    nodes: &mut Nodes<'_>,
    info: &RunInfo,
    state: &BrokerState,
) -> anyhow::Result<()> {
    let started = Instant::now();
    let context = || format!("checkpoint at step {} (t = {} s)", state.step, state.t);
    let mut saved = Vec::new();
    if let Some(link) = nodes.fem.as_deref_mut() {
        saved.push(("fem", link.checkpoint(state.step).with_context(context)?));
    }
    if let Some(link) = nodes.sph.as_deref_mut() {
        saved.push(("sph", link.checkpoint(state.step).with_context(context)?));
    }
    let written = checkpoint::write(&info.out, &info.run_id, scene, state, &saved, started).with_context(context)?;
    tracing::info!(
        "checkpoint {}: {} bytes in {:.3} s",
        written.dir.display(),
        written.bytes,
        written.seconds
    );
    Ok(())
}

fn command(dt: f64, want_snapshot: bool, stop: bool) -> StepCommand {
    StepCommand {
        dt,
        corrections: Vec::new(),
        roi: None,
        want_interface: false,
        want_snapshot,
        stop,
    }
}

/// The commands of one step, (fem, sph): the pending corrections go to their node; the fluid node is asked for
/// the particles inside `roi`, the structure node for its interface nodes, when the run is coupled.
fn commands(
    dt: f64,
    want_snapshot: bool,
    coupled: bool,
    roi: Option<[f64; 4]>,
    pending: &mut Corrections,
) -> (StepCommand, StepCommand) {
    let fem = StepCommand {
        corrections: std::mem::take(&mut pending.fem),
        want_interface: coupled,
        ..command(dt, want_snapshot, false)
    };
    let sph = StepCommand {
        corrections: std::mem::take(&mut pending.sph),
        roi,
        want_interface: coupled,
        ..command(dt, want_snapshot, false)
    };
    (fem, sph)
}

/// Fold one pass into the run's contact statistics.
fn record(total: &mut ContactStats, pass: &PassStats, exchanged: u64, steps: u64) {
    total.contacts += pass.contacts as u64;
    total.max_penetration = total.max_penetration.max(pass.max_penetration);
    total.linear_momentum_change = total.linear_momentum_change.max(pass.linear_momentum_change);
    total.angular_momentum_change = total.angular_momentum_change.max(pass.angular_momentum_change);
    total.exchanged_per_step = exchanged as f64 / steps.max(1) as f64;
    total.exchanged_max = total.exchanged_max.max(pass.exchanged as u64);
}

fn snapshot<'s, T>(snap: Option<&'s T>, node: &str) -> anyhow::Result<&'s T> {
    snap.ok_or_else(|| anyhow::anyhow!("{node}: answered an output step without a snapshot"))
}

/// Fluid and wall particles (walls at `wall_x`, of density `density`) in one frame, told apart by `wall` (0 fluid,
/// 1 wall).
fn write_particles(
    frames: &mut FrameWriter,
    index: usize,
    t: f64,
    wall_x: &[[f64; 2]],
    density: f64,
    snap: &SphSnapshot,
) -> crate::output::Result<()> {
    // The frame is streamed from the snapshot and the walls as they are: no concatenated copy.
    let (fluid, walls) = (snap.x.len(), wall_x.len());
    frames.write_particle_parts(
        index,
        t,
        &[Part::Slice(&snap.x), Part::Slice(wall_x)],
        &[
            PointField::VectorParts("velocity", &[Part::Slice(&snap.v), Part::Repeat([0.0; 2], walls)]),
            PointField::ScalarParts("pressure", &[Part::Slice(&snap.p), Part::Slice(&snap.wall_p)]),
            PointField::ScalarParts("density", &[Part::Slice(&snap.rho), Part::Repeat(density, walls)]),
            PointField::ScalarParts("wall", &[Part::Repeat(0.0, fluid), Part::Repeat(1.0, walls)]),
        ],
    )?;
    Ok(())
}

/// One coupling step with every node: send to all, then collect all, so processes compute side by side. The
/// nodes' own compute time counts as `fem`/`sph`; the rest of the round as `messaging`: beyond the slower node where
/// the nodes compute side by side (other processes), beyond their sum where they compute one after the other inside
/// `receive` (in this process).
fn exchange(
    nodes: &mut Nodes<'_>,
    interface_ids: &[u32],
    summary: &mut Summary,
    step: u64,
    t: f64,
    (fem_cmd, sph_cmd): (StepCommand, StepCommand),
) -> anyhow::Result<Round> {
    let context = || format!("coupling step {step} from t = {t} s");
    let asked = |cmd: &StepCommand| Asked {
        interface: cmd.want_interface,
        snapshot: cmd.want_snapshot,
        interface_ids,
    };
    let (fem_asked, sph_asked) = (asked(&fem_cmd), asked(&sph_cmd));
    let started = Instant::now();
    if let Some(link) = nodes.sph.as_deref_mut() {
        link.send(step, t, sph_cmd).with_context(context)?;
    }
    if let Some(link) = nodes.fem.as_deref_mut() {
        link.send(step, t, fem_cmd).with_context(context)?;
    }
    // docs/PROTOCOL.md §7 "Contents": each answer is checked against the node's registration and the command
    // before anything reads it.
    let sph = match nodes.sph.as_deref_mut() {
        Some(link) => {
            let state = link.receive(step).with_context(context)?;
            state
                .validate(link.setup(), sph_asked)
                .map_err(|e| unusable("sph-node", e))
                .with_context(context)?;
            Some(state)
        }
        None => None,
    };
    let fem = match nodes.fem.as_deref_mut() {
        Some(link) => {
            let state = link.receive(step).with_context(context)?;
            state
                .validate(link.setup(), fem_asked)
                .map_err(|e| unusable("fem-node", e))
                .with_context(context)?;
            Some(state)
        }
        None => None,
    };
    let wall = started.elapsed().as_secs_f64();
    let c_fem = fem.as_ref().map_or(0.0, |s| s.compute_seconds());
    let c_sph = sph.as_ref().map_or(0.0, |s| s.compute_seconds());
    summary.timings.fem += c_fem;
    summary.timings.sph += c_sph;
    let (mut side_by_side, mut in_turn) = (0.0f64, 0.0);
    for (concurrent, c) in [
        (nodes.fem.as_ref().is_none_or(|l| l.concurrent()), c_fem),
        (nodes.sph.as_ref().is_none_or(|l| l.concurrent()), c_sph),
    ] {
        if concurrent {
            side_by_side = side_by_side.max(c);
        } else {
            in_turn += c;
        }
    }
    summary.timings.messaging += (wall - side_by_side - in_turn).max(0.0);
    Ok(Round { fem, sph })
}

/// A message from `node` whose contents cannot be used: the run fails (or, for a NaN or an infinity in a state,
/// ends `unstable`: the node blew up without noticing), naming the message, the field, the index and the value.
fn unusable(node: &str, e: Invalid) -> LinkError {
    let (node, message) = (node.to_string(), format!("sent an unusable message: {e}"));
    if e.is_non_finite() {
        LinkError::Unstable { node, message }
    } else {
        LinkError::Failed { node, message }
    }
}

fn plot_all(scene: &LoadedScene, out: &Path, series: &Series) -> anyhow::Result<()> {
    let dir = out.join("plots");
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    for (spec, line) in scene.scene.probes.iter().zip(series) {
        let reference = spec.reference.as_ref().map(|r| (r, scene.resolve(&r.file)));
        let path = dir.join(format!("{}.svg", spec.name));
        let result = plot_probe(
            &path,
            &spec.name,
            line,
            reference.as_ref().map(|(r, p)| (*r, p.as_path())),
        );
        if let Err(e) = result {
            tracing::warn!("{e:#}");
        }
    }
    Ok(())
}

/// Write `summary.json` in place over the room reserved for it when the run started (`crate::summary`), so that
/// it is written however full the disk got; an error names the file.
pub fn write_summary(out: &Path, summary: &Summary) -> anyhow::Result<()> {
    Ok(crate::summary::write(out, summary)?)
}
