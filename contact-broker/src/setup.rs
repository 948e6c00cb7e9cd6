//! The set-up of a run, the same for `cosim run` (in-process, or launching the processes) and for the
//! `contact-broker` process: the scene loaded with its overrides and sized against this machine, the checkpoint
//! plan checked, the checkpoint to continue from opened and checked against the scene; then the coordinator run
//! with that plan. Everything refused here is bad input (exit 2), said before any output is touched.

use std::path::Path;

use cosim_proto::scene::disk::DiskEstimate;
use cosim_proto::scene::LoadedScene;
use cosim_proto::sizing::Part;

use crate::checkpoint::{self, Restart};
use crate::coordinator::pause::Debugger;
use crate::coordinator::{self, Checkpoints, Control, Nodes, Outcome, Progress, RunInfo};

/// A run ready to start: its scene and its checkpoints.
#[derive(Debug)]
pub struct RunSetup {
    /// The scene, overrides applied.
    pub scene: LoadedScene,
    /// Write a checkpoint every this many seconds of simulated time.
    pub checkpoint_interval: Option<f64>,
    /// The checkpoint the run continues from.
    pub restart: Option<Restart>,
}

impl RunSetup {
    /// Load the scene `file` with the overrides `set` (`key.path=value`), and refuse one too big for the memory
    /// this machine has available for `part` of the run. No checkpoints yet ([`RunSetup::with_checkpoints`]).
    pub fn load(file: &Path, set: &[String], part: Part) -> anyhow::Result<Self> {
        let scene = cosim_proto::scene::load(file, set)?;
        let name = file.display().to_string();
        cosim_bus::memory::refuse_above(&scene.scene, part, &name, cosim_bus::memory::available())?;
        crate::step_budget::refuse_endless(&scene.scene).map_err(|(key, message)| cosim_proto::scene::SceneError {
            file: name.clone(),
            key,
            message,
        })?;
        Ok(Self {
            scene,
            checkpoint_interval: None,
            restart: None,
        })
    }

    /// Write checkpoints every `interval` seconds of simulated time (a positive number), and continue from the
    /// checkpoint folder `restart` (`DIR/checkpoints/<step>`), which must be intact and of this scene.
    pub fn with_checkpoints(mut self, interval: Option<f64>, restart: Option<&Path>) -> anyhow::Result<Self> {
        checkpoint::check_interval(interval)?;
        self.checkpoint_interval = interval;
        self.restart = match restart {
            Some(dir) => Some(checkpoint::open(dir, &self.scene)?),
            None => None,
        };
        Ok(self)
    }

    /// Refuse a run whose outputs (frames, probe table, checkpoints; from the restart's time when it continues one)
    /// cannot fit the free space of `out`'s disk, naming the key that makes them large (`cosim_bus::disk`).
    pub fn refuse_full_disk(&self, out: &Path) -> anyhow::Result<()> {
        let from = self.restart_time();
        cosim_bus::disk::refuse_above(
            &self.scene.scene,
            &self.scene.path.display().to_string(),
            out,
            self.checkpoint_interval,
            from,
            cosim_bus::disk::free(out),
        )?;
        Ok(())
    }

    /// The simulated time the run starts from: 0, or the checkpoint's.
    pub fn restart_time(&self) -> f64 {
        self.restart.as_ref().map_or(0.0, |r| r.broker.t)
    }

    /// The bytes the run writes into its output folder from [`RunSetup::restart_time`] to its end, as estimated
    /// before it starts (`cosim_proto::scene::disk`; the trace of `--record` not counted).
    pub fn outputs_bytes(&self) -> f64 {
        let scene = &self.scene.scene;
        let sizing = cosim_proto::scene::sizing::Sizing::of(scene);
        DiskEstimate::of(scene, &sizing, self.checkpoint_interval, self.restart_time()).total()
    }

    /// The structure node's saved state to restore, when the run continues from a checkpoint.
    pub fn saved_fem(&self) -> Option<&Vec<u8>> {
        self.restart.as_ref().and_then(|r| r.fem.as_ref())
    }

    /// The fluid node's saved state to restore, when the run continues from a checkpoint.
    pub fn saved_sph(&self) -> Option<&Vec<u8>> {
        self.restart.as_ref().and_then(|r| r.sph.as_ref())
    }

    /// Run the scene with `nodes` (which restored their saved states, if any, when they were built) and write
    /// every output, checkpoints included: [`coordinator::run_with`].
    pub fn run(&self, nodes: Nodes<'_>, info: &RunInfo, progress: &mut dyn FnMut(Progress) -> Control) -> Outcome {
        let plan = Checkpoints {
            interval: self.checkpoint_interval,
            restart: self.restart.as_ref().map(|r| r.broker.clone()),
        };
        coordinator::run_with(&self.scene, nodes, info, &plan, progress)
    }

    /// [`RunSetup::run`], paused and driven by `debugger` between two steps (`cosim run --break`, `cosim ctl`):
    /// [`coordinator::run_debug`].
    pub fn run_debug(
        &self,
        nodes: Nodes<'_>,
        info: &RunInfo,
        progress: &mut dyn FnMut(Progress) -> Control,
        debugger: &mut Debugger<'_>,
    ) -> Outcome {
        let plan = Checkpoints {
            interval: self.checkpoint_interval,
            restart: self.restart.as_ref().map(|r| r.broker.clone()),
        };
        coordinator::run_debug(&self.scene, nodes, info, &plan, progress, Some(debugger))
    }
}
