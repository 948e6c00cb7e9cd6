//! `broker.bin`: the coordinator's state between two steps ([`BrokerState`]), and the checks a restart runs on it
//! before it is used. The file's checksum (`checkpoint.json`) catches a damaged copy; these checks catch a state
//! that is intact but does not hold together (written by another tool, or by a build with a bug): every id the
//! pending corrections name is a node or particle of the run, every probe row has a value per probe, the numbers
//! the coordinator steps with are finite. Each refusal is one line naming the field, the index and the value.

use cosim_proto::messages::Correction;
use cosim_proto::scene::Scene;
use cosim_proto::Num;
use serde::{Deserialize, Serialize};

use crate::probes::LoadLog;
use crate::summary::Summary;

/// The coordinator's state between two steps: what, with the nodes' states, makes the continued run the same.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BrokerState {
    /// Coupling steps completed.
    pub step: u64,
    /// Simulated time [s].
    pub t: f64,
    /// Index of the next output time.
    pub next_output: u64,
    /// Index of the next checkpoint time.
    pub next_checkpoint: u64,
    /// The fluid's stable step last reported [s].
    pub dt_fluid: f64,
    /// The longest step the contact allows from now on [s]; infinite where it sets no bound (`contact_step`).
    pub dt_contact: f64,
    /// The longest next step the structure's speed allows [s]; infinite at rest or without the bound
    /// (`coupling.structure_courant`).
    pub dt_structure: f64,
    /// Contact corrections of the last step, still to be sent to the structure node.
    pub pending_fem: Vec<Correction>,
    /// … and to the fluid node.
    pub pending_sph: Vec<Correction>,
    /// Region of interest of the next fluid command.
    pub roi: Option<[f64; 4]>,
    /// Interface load of the last output step.
    pub load: Option<Vec<[f64; 2]>>,
    /// The contact impulse per solid since the last sample (`interface_load` probes).
    pub load_log: LoadLog,
    /// The contact impulse owed to each interface node and not yet given (`contact.reaction_relaxation`); empty
    /// where none is.
    pub owed: Vec<[f64; 2]>,
    /// Fluid particles exchanged over the run.
    pub exchanged: u64,
    /// Fluid positions of the first sample (potential energy probes).
    pub fluid_origin: Option<Vec<[f64; 2]>>,
    /// Every probe row so far: time and values.
    pub rows: Vec<(f64, Vec<f64>)>,
    /// The summary's counters so far.
    pub summary: Summary,
}

/// `Err(message)` unless `ok`.
fn ensure(ok: bool, message: impl FnOnce() -> String) -> Result<(), String> {
    if ok {
        Ok(())
    } else {
        Err(message())
    }
}

/// Whether every component is finite.
fn finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

impl BrokerState {
    /// Check the state against itself and against `scene` (the scene the restart runs, which the checkpoint's
    /// `scene.toml` was already found equal to): what can be known before any node is started. The sizes of the
    /// nodes are those the saved summary recorded (`fem_nodes`, `particles`); the structure's is the scene's own,
    /// the fluid's is compared with the fluid node's registration by [`BrokerState::check_nodes`].
    /// `Err` is one line naming the field, the index and the value.
    pub fn check(&self, scene: &Scene) -> Result<(), String> {
        let s = &self.summary;
        ensure(self.t.is_finite() && self.t >= 0.0, || {
            format!("t = {} is not a time", self.t)
        })?;
        ensure(s.steps == self.step, || {
            format!("summary.steps = {} where step = {}", s.steps, self.step)
        })?;
        ensure(s.sim_time.to_bits() == self.t.to_bits(), || {
            format!("summary.sim_time = {} where t = {}", s.sim_time, self.t)
        })?;
        // A step of 0 or less (or NaN, which `min` passes over) would never reach the end: the run would hang. One
        // below the shortest a run takes would end it `unstable` at once, or take a step no run takes (dt_fluid =
        // 1e-300 was accepted, found 2026-12-06 by the sweep of crafted checkpoints, D25).
        let shortest = cosim_proto::scene::shortest_step(scene.coupling.max_dt);
        for (field, dt) in [
            ("dt_fluid", self.dt_fluid),
            ("dt_contact", self.dt_contact),
            ("dt_structure", self.dt_structure),
        ] {
            ensure(dt > 0.0, || format!("{field} = {dt} is not a positive step"))?;
            ensure(dt >= shortest, || {
                format!(
                    "{field} = {} s is below coupling.max_dt / 2^32 = {} s, the shortest step a run takes",
                    Num(dt),
                    Num(shortest)
                )
            })?;
        }
        if let Some(g) = &s.energy_growth {
            // A budget that is not positive would divide every later gain by zero or turn its sign.
            ensure(
                g.budget > 0.0
                    && g.budget.is_finite()
                    && finite(&[g.initial, g.largest, g.at, g.rounding])
                    && g.largest >= 0.0
                    && g.rounding >= 0.0,
                || {
                    format!(
                        "summary.energy_growth = {g:?} is not a balance (budget > 0, gain and rounding ≥ 0, all finite)"
                    )
                },
            )?;
        }
        let interval = scene.run.output_interval;
        // Every output time up to `t` is sampled, so the next one lies after it.
        ensure(
            self.next_output >= 1 && self.next_output as f64 * interval > self.t,
            || {
                format!(
                    "next_output = {}: output time {} s is not after t = {} s",
                    self.next_output,
                    self.next_output as f64 * interval,
                    self.t
                )
            },
        )?;
        let fem_nodes: u64 = scene
            .solids
            .iter()
            .map(|solid| solid.grid_size().iter().map(|&n| n as u64).product::<u64>())
            .sum();
        ensure(s.fem_nodes == fem_nodes, || {
            format!(
                "summary.fem_nodes = {} where the scene's solids have {fem_nodes} nodes",
                s.fem_nodes
            )
        })?;
        if let Some(e) = &s.solid_in_wall {
            // Only ever read back into the summary and the run's last message, but checked as every other field.
            ensure(
                e.t.is_finite()
                    && (0.0..=self.t).contains(&e.t)
                    && e.depth.is_finite()
                    && e.depth > 0.0
                    && u64::from(e.node) < fem_nodes
                    && e.wall < scene.walls.len(),
                || {
                    format!(
                        "summary.solid_in_wall = {e:?} is not a node inside a wall (t within 0..{}, depth > 0, node \
                         below {fem_nodes}, wall below {})",
                        self.t,
                        scene.walls.len()
                    )
                },
            )?;
        }
        let particles = match scene.fluid {
            Some(_) => s.particles,
            None => 0,
        };
        ensure(s.particles == particles, || {
            format!("summary.particles = {} but the scene has no fluid", s.particles)
        })?;
        check_corrections("pending_fem", &self.pending_fem, fem_nodes, "structure nodes")?;
        check_corrections("pending_sph", &self.pending_sph, particles, "fluid particles")?;
        if let Some(roi) = self.roi {
            ensure(finite(&roi), || format!("roi = {roi:?} is not finite"))?;
        }
        if let Some(load) = &self.load {
            ensure(load.len() as u64 == fem_nodes, || {
                format!("load holds {} nodes, the structure has {fem_nodes}", load.len())
            })?;
            if let Some(k) = load.iter().position(|l| !finite(l)) {
                return Err(format!("load[{k}] = {:?} is not finite", load[k]));
            }
        }
        ensure(self.load_log.time >= 0.0 && self.load_log.time.is_finite(), || {
            format!("load_log.time = {} is not a time", self.load_log.time)
        })?;
        if let Some(k) = self.load_log.impulse.iter().position(|j| !finite(j)) {
            return Err(format!(
                "load_log.impulse[{k}] = {:?} is not finite",
                self.load_log.impulse[k]
            ));
        }
        if let Some(k) = self.owed.iter().position(|j| !finite(j)) {
            return Err(format!("owed[{k}] = {:?} is not finite", self.owed[k]));
        }
        ensure(self.owed.len() as u64 <= fem_nodes, || {
            format!("owed holds {} nodes, the structure has {fem_nodes}", self.owed.len())
        })?;
        if let Some(x0) = &self.fluid_origin {
            ensure(x0.len() as u64 == particles, || {
                format!(
                    "fluid_origin holds {} positions, the fluid has {particles} particles",
                    x0.len()
                )
            })?;
            if let Some(k) = x0.iter().position(|x| !finite(x)) {
                return Err(format!("fluid_origin[{k}] = {:?} is not finite", x0[k]));
            }
        }
        let probes = scene.probes.len();
        let mut last = f64::NEG_INFINITY;
        for (k, (t, values)) in self.rows.iter().enumerate() {
            ensure(t.is_finite() && *t >= last && *t <= self.t, || {
                format!(
                    "rows[{k}]: t = {t} is not after the row before ({last}) and at most t = {}",
                    self.t
                )
            })?;
            ensure(values.len() == probes, || {
                format!("rows[{k}] holds {} values, the scene has {probes} probes", values.len())
            })?;
            last = *t;
        }
        // One probe row per output time, and a frame set at every `run.frame_interval` of them (one more where the
        // last was the run's end): the frames written next are numbered from here.
        let rows = self.rows.len() as u64;
        let regular = rows.div_ceil(scene.run.frame_every());
        ensure(
            s.samples == rows && (s.frames == regular || s.frames == regular + 1),
            || {
                format!(
                    "summary.samples = {} and summary.frames = {} where rows holds {rows}",
                    s.samples, s.frames
                )
            },
        )?;
        Ok(())
    }

    /// Check the sizes the saved summary recorded against the nodes of the continued run, once they registered
    /// (`fem_nodes`, `particles` as the run's summary counts them): the ids of the pending corrections and the
    /// fluid origin were checked against the saved sizes by [`BrokerState::check`].
    pub fn check_nodes(&self, fem_nodes: u64, particles: u64) -> anyhow::Result<()> {
        let s = &self.summary;
        anyhow::ensure!(
            s.fem_nodes == fem_nodes && s.particles == particles,
            "the checkpoint's broker.bin was saved with {} structure nodes and {} fluid particles, the nodes of this \
             run have {fem_nodes} and {particles}",
            s.fem_nodes,
            s.particles
        );
        Ok(())
    }
}

/// Every correction names one of `count` ids (`what`) and moves it by finite amounts.
fn check_corrections(field: &str, corrections: &[Correction], count: u64, what: &str) -> Result<(), String> {
    for (k, c) in corrections.iter().enumerate() {
        ensure(u64::from(c.id) < count, || {
            format!("{field}[{k}].id = {}, but there are {count} {what}", c.id)
        })?;
        ensure(finite(&c.dx) && finite(&c.dv), || {
            format!(
                "{field}[{k}] (id {}): dx {:?}, dv {:?} are not finite",
                c.id, c.dx, c.dv
            )
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests;
