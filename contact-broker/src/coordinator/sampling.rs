//! Sampling at the output times (`DESIGN.md` §5): the probes into `probes.csv` and the plots' series, and the
//! frames, encoded and written on their own thread (`output/queue.rs`) from the snapshots handed over.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context;

use cosim_proto::messages::{FemMesh, FemSnapshot, SphSetup, SphSnapshot};
use cosim_proto::scene::LoadedScene;
use cosim_proto::Num;
use sph_node::eos::Tait;

use super::exchange::Round;
use super::inputs::Nodes;
use crate::checkpoint::BrokerState;
use crate::energy_balance::{elastic_energy, elastic_eos, elastic_size, releasable, shorter_step, EnergyGrowth};
use crate::output::{plot_probe, FrameQueue, FrameWriter, Part, PointField, ProbeCsv};
use crate::probes::{LoadLog, Probes};
use crate::summary::Summary;
use crate::wall_entry::WallWatch;

/// Probe values over time, per probe.
pub(super) type Series = Vec<Vec<(f64, f64)>>;

/// The run's outputs: the probes and `probes.csv`, the frames (written on their own thread, `output/queue.rs`),
/// and the probe series for the plots.
pub(super) struct Outputs<'s> {
    pub probes: Probes,
    pub csv: ProbeCsv,
    frames: FrameQueue,
    /// `[run]`: which output times get frames.
    run: cosim_proto::scene::RunSpec,
    series: &'s mut Series,
    mesh: Option<Arc<FemMesh>>,
    walls: Option<Arc<Vec<[f64; 2]>>>,
    density: f64,
    /// The WCSPH fluid's equation of state, for its elastic energy in the energy balance (`None`: ISPH, no fluid).
    eos: Option<Tait>,
    /// The structure's nodes watched against the walls (`None` without walls, fluid or structure).
    wall_watch: Option<WallWatch>,
}

impl<'s> Outputs<'s> {
    /// Resolve the probes of `scene` against the registered nodes and open the outputs in `out`: `probes.csv`, and
    /// the frames folder, continued where `restart` left it.
    pub fn open(
        scene: &LoadedScene,
        nodes: &Nodes<'_>,
        out: &Path,
        restart: Option<&BrokerState>,
        series: &'s mut Series,
    ) -> anyhow::Result<Self> {
        let probes = Probes::resolve(
            &scene.scene,
            nodes.fem.as_ref().map(|f| f.setup()),
            nodes.sph.as_ref().map(|n| n.setup()),
        )
        .map_err(anyhow::Error::msg)?;
        *series = vec![Vec::new(); probes.names().len()];
        let writer = match restart {
            Some(saved) => FrameWriter::resume(out, &saved.rows.iter().map(|r| r.0).collect::<Vec<_>>())?,
            None => FrameWriter::new(out)?,
        };
        let frames = FrameQueue::new(writer)?;
        let mesh = nodes.fem.as_ref().map(|f| Arc::new(f.setup().clone()));
        let walls = nodes.sph.as_ref().map(|n| Arc::new(n.setup().walls.clone()));
        let density = nodes.sph.as_ref().map_or(0.0, |n| n.setup().density);
        let csv = ProbeCsv::create(&out.join("probes.csv"), probes.names())?;
        let eos = elastic_eos(&scene.scene);
        let wall_watch = mesh.as_deref().and_then(|m| WallWatch::new(&scene.scene, m));
        Ok(Self {
            probes,
            csv,
            frames,
            run: scene.scene.run.clone(),
            series,
            mesh,
            walls,
            density,
            eos,
            wall_watch,
        })
    }

    /// Put back the probe rows of a checkpoint (`probes.csv` and the series) and the fluid's first positions.
    pub fn resume(&mut self, saved: &BrokerState) -> anyhow::Result<()> {
        self.probes.set_fluid_origin(saved.fluid_origin.clone());
        for (t, values) in &saved.rows {
            self.csv.push(*t, values)?;
            self.push_series(*t, values);
        }
        Ok(())
    }

    /// Sample the probes and write the frames of an output time, from the snapshots of `round`: frames at every
    /// `run.frame_interval` (and at `last`, the run's last output time), named by the output time's number.
    #[allow(clippy::too_many_arguments)]
    pub fn sample(
        &mut self,
        t: f64,
        last: bool,
        round: &mut Round,
        nodes: &Nodes<'_>,
        load: Option<&[[f64; 2]]>,
        since: &mut LoadLog,
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
        let values = self.probes.sample(fem, sph, since);
        // The interface_load probes' interval starts again.
        *since = LoadLog::default();
        self.csv.push(t, &values)?;
        self.push_series(t, &values);
        let index = summary.samples as usize;
        energy_balance(&self.probes, self.eos.as_ref(), t, index, fem, sph, summary);
        if let (Some(watch), Some((mesh, snap)), None) = (&self.wall_watch, fem, &summary.solid_in_wall) {
            summary.solid_in_wall = watch.observe(t, &snap.x, mesh).inspect(|e| {
                tracing::warn!(
                    "at t = {} s node {} of solid `{}` is {:.3e} m inside wall[{}]: deeper than the walls' contact leaves \
                     a surface node (wall_contact.rs), so it went past it, and what follows is not the tank's physics \
                     (summary.json solid_in_wall)",
                    Num(e.t),
                    e.node,
                    e.solid,
                    e.depth,
                    e.wall
                )
            });
        }
        summary.samples += 1;
        if self.run.is_frame(index as u64, last) {
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
        }
        summary.timings.broker += started.elapsed().as_secs_f64();
        Ok(())
    }

    /// Wait for the frames still being written; they count as the broker's time.
    pub fn finish(self, summary: &mut Summary) -> anyhow::Result<()> {
        let started = Instant::now();
        let written = self.frames.finish();
        summary.timings.broker += started.elapsed().as_secs_f64();
        Ok(written?)
    }

    fn push_series(&mut self, t: f64, values: &[f64]) {
        for (line, v) in self.series.iter_mut().zip(values) {
            line.push((t, *v));
        }
    }
}

/// The run's energy balance at output time `t`, the `index`-th (`energy_balance.rs`): started at the first, taken
/// at the others; the first output time whose gain passes [`crate::energy_balance::WARN_GROWTH`] of the budget is
/// logged.
fn energy_balance(
    probes: &Probes,
    eos: Option<&Tait>,
    t: f64,
    index: usize,
    fem: Option<(&FemMesh, &FemSnapshot)>,
    sph: Option<(&SphSetup, &SphSnapshot)>,
    summary: &mut Summary,
) {
    let (elastic, elastic_size) = match (eos, sph) {
        (Some(eos), Some((_, s))) => (elastic_energy(eos, &s.m, &s.rho), elastic_size(eos, &s.m)),
        _ => (0.0, 0.0),
    };
    let energy = probes.mechanical_energy(fem, sph) + elastic;
    let steps = (summary.fem_substeps, summary.sph_substeps);
    let rounding = probes.energy_rounding(fem, sph, elastic_size, steps);
    if index == 0 {
        let budget = sph.map_or(0.0, |(_, s)| releasable(&s.m, &s.x, probes.gravity()));
        summary.energy_growth = EnergyGrowth::start(t, energy, rounding, budget);
    } else if let Some(growth) = summary.energy_growth.as_mut() {
        if growth.observe(t, energy, rounding) {
            // The step to try, from the steps so far (`cosim run` names it again after the run, from all of them).
            let hint = shorter_step(summary.sim_time, summary.steps).map_or(String::new(), |h| {
                format!(
                    "; a shorter coupling step is the first thing to try (the steps so far averaged {:.2e} s: \
                     coupling.max_dt = {:.0e})",
                    h.mean, h.try_dt
                )
            });
            tracing::warn!(
                "by t = {} s the fluid and the structure together have gained {:.4} J/m, {:.1} % of the {:.4} J/m \
                 the water can release: nothing in the scene supplies it, so the scheme made it (an unstable \
                 coupling, or a step too long for it); what follows may be unphysical (summary.json \
                 energy_growth){hint}",
                Num(t),
                Num(growth.largest * growth.budget),
                Num(100.0 * growth.largest),
                Num(growth.budget)
            );
        }
    }
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

/// One SVG per probe in `out/plots/`, of `series`, with the scene's reference data where it names some. A plot
/// that cannot be drawn is logged, not an error.
pub(super) fn plot_all(scene: &LoadedScene, out: &Path, series: &Series) -> anyhow::Result<()> {
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
