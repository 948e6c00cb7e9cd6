//! The step coordinator (`DESIGN.md` §3): fixes each coupling step, holds the step barrier, samples probes and
//! writes the outputs. It talks to the solvers only through [`FemLink`], so it runs the same in-process and
//! distributed.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;

use cosim_proto::messages::{FemSnapshot, FemState, StepCommand};
use cosim_proto::scene::{LoadedScene, SceneError};

use crate::link::{FemLink, LinkError};
use crate::output::{plot_probe, FrameWriter, ProbeCsv};
use crate::probes::Probes;
use crate::summary::{ContactStats, Summary, Timings};

/// Progress of a run, reported after each coupling step.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Coupling steps taken.
    pub step: u64,
    /// Simulated time [s].
    pub t: f64,
    /// End time [s].
    pub end_time: f64,
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

/// What this build can run: structure-only scenes. The fluid node is not wired into the coordinator yet, so a
/// scene with water or walls is refused up front with the key that asks for it.
pub fn check_supported(scene: &LoadedScene) -> Result<(), SceneError> {
    let file = scene.path.display().to_string();
    let refuse = |key: &str, message: &str| {
        Err(SceneError {
            file: file.clone(),
            key: key.into(),
            message: message.into(),
        })
    };
    if scene.scene.fluid.is_some() {
        return refuse(
            "fluid",
            "this build runs structure-only scenes; the SPH node is not part of the run yet",
        );
    }
    if !scene.scene.walls.is_empty() {
        return refuse(
            "wall",
            "rigid walls belong to the SPH node, which this build does not run yet",
        );
    }
    if scene.scene.solids.is_empty() {
        return refuse("solid", "nothing to run: the scene has no [[solid]]");
    }
    Ok(())
}

/// Steps closer than this fraction of `max_dt` to an output time land on it.
const LANDING: f64 = 1e-9;

/// Run a scene to its end time (or to the first failure) and write every output.
pub fn run(scene: &LoadedScene, fem: &mut dyn FemLink, info: &RunInfo, progress: &mut dyn FnMut(Progress)) -> Outcome {
    let started = Instant::now();
    let s = &scene.scene;
    let (fem_nodes, fem_elements) = (fem.mesh().nodes.len() as u64, fem.mesh().cells.len() as u64);
    let mut summary = Summary {
        status: "ok".into(),
        message: String::new(),
        run_id: info.run_id.clone(),
        scene: s.run.name.clone(),
        steps: 0,
        fem_substeps: 0,
        sim_time: 0.0,
        wall_seconds: 0.0,
        particles: 0,
        fem_nodes,
        fem_elements,
        solver: "none".into(),
        contact: "none".into(),
        mode: info.mode.clone(),
        frames: 0,
        samples: 0,
        timings: Timings::default(),
        contact_stats: ContactStats::default(),
    };
    let mut series = Vec::new();
    let error = drive(scene, fem, info, progress, &mut summary, &mut series).err();
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
        tracing::error!("summary.json: {e:#}");
    }
    Outcome { summary, error }
}

/// Probe values over time, per probe.
type Series = Vec<Vec<(f64, f64)>>;

fn drive(
    scene: &LoadedScene,
    fem: &mut dyn FemLink,
    info: &RunInfo,
    progress: &mut dyn FnMut(Progress),
    summary: &mut Summary,
    series: &mut Series,
) -> anyhow::Result<()> {
    let s = &scene.scene;
    let probes = Probes::resolve(s, fem.mesh()).map_err(anyhow::Error::msg)?;
    *series = vec![Vec::new(); probes.names().len()];
    let mut frames = FrameWriter::new(&info.out)?;
    let mut csv = ProbeCsv::create(&info.out.join("probes.csv"), probes.names())?;
    let interval = s.run.output_interval;
    let end = s.run.end_time;
    let mut sample = |t: f64, snap: &FemSnapshot, summary: &mut Summary, fem: &dyn FemLink| -> anyhow::Result<()> {
        let values = probes.sample(fem.mesh(), snap);
        csv.push(t, &values)?;
        for (line, v) in series.iter_mut().zip(&values) {
            line.push((t, *v));
        }
        frames.write_structure(summary.frames as usize, t, fem.mesh(), snap)?;
        summary.frames += 1;
        summary.samples += 1;
        Ok(())
    };

    let mut t = 0.0;
    let mut step = 0u64;
    let state = exchange(fem, summary, step, t, command(0.0, true, false))?;
    let t0 = Instant::now();
    sample(t, snapshot(&state)?, summary, fem)?;
    summary.timings.broker += t0.elapsed().as_secs_f64();
    let mut next_output = 1u64;
    while t < end {
        let target = (next_output as f64 * interval).min(end);
        let mut dt = s.coupling.max_dt.min(target - t);
        let lands = target - (t + dt) <= LANDING * s.coupling.max_dt;
        if lands {
            dt = target - t;
        }
        step += 1;
        let state = exchange(fem, summary, step, t, command(dt, lands, false))?;
        summary.fem_substeps += u64::from(state.substeps);
        t = if lands { target } else { t + dt };
        summary.steps = step;
        summary.sim_time = t;
        if lands {
            let t0 = Instant::now();
            sample(t, snapshot(&state)?, summary, fem)?;
            summary.timings.broker += t0.elapsed().as_secs_f64();
            if target >= next_output as f64 * interval {
                next_output += 1;
            }
        }
        progress(Progress { step, t, end_time: end });
    }
    exchange(fem, summary, step + 1, t, command(0.0, false, true))?;
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

fn snapshot(state: &FemState) -> anyhow::Result<&FemSnapshot> {
    state
        .snapshot
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("fem-node: answered an output step without a snapshot"))
}

/// One round trip, timed: the node's own compute time counts as `fem`, the rest as `messaging`.
fn exchange(
    fem: &mut dyn FemLink,
    summary: &mut Summary,
    step: u64,
    t: f64,
    cmd: StepCommand,
) -> anyhow::Result<FemState> {
    let stop = cmd.stop;
    let t0 = Instant::now();
    let reply = fem
        .exchange(step, t, cmd)
        .with_context(|| format!("coupling step {step} from t = {t} s"))?;
    let wall = t0.elapsed().as_secs_f64();
    match reply {
        Some(state) => {
            summary.timings.fem += state.compute_seconds;
            summary.timings.messaging += (wall - state.compute_seconds).max(0.0);
            Ok(state)
        }
        None if stop => Ok(FemState {
            ids: Vec::new(),
            x: Vec::new(),
            v: Vec::new(),
            substeps: 0,
            dt_stable: 0.0,
            compute_seconds: 0.0,
            snapshot: None,
        }),
        None => anyhow::bail!("fem-node: no answer to step {step}"),
    }
}

fn plot_all(scene: &LoadedScene, out: &Path, series: &Series) -> anyhow::Result<()> {
    let dir = out.join("plots");
    std::fs::create_dir_all(&dir)?;
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
            tracing::warn!("plot {}: {e:#}", path.display());
        }
    }
    Ok(())
}

/// Write `summary.json` atomically (temporary file, then rename).
pub fn write_summary(out: &Path, summary: &Summary) -> anyhow::Result<()> {
    let tmp = out.join("summary.json.tmp");
    std::fs::write(&tmp, serde_json::to_string_pretty(summary)? + "\n")?;
    std::fs::rename(&tmp, out.join("summary.json"))?;
    Ok(())
}
