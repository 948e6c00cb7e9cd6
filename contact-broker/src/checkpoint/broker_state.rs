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
        let shortest = crate::coordinator::shortest_step(scene.coupling.max_dt);
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
mod tests {
    use super::*;
    use crate::summary::{ContactStats, Timings};

    /// A coupled scene: one 2 × 1 quad solid (6 nodes), a fluid block, one probe.
    fn scene() -> Scene {
        let text = r#"
version = 1
[run]
name = "t"
end_time = 1.0
output_interval = 0.1
gravity = [0.0, -9.81]
[fluid]
density = 1000.0
spacing = 0.1
sound_speed = 20.0
[[fluid.block]]
min = [0.0, 0.0]
max = [0.4, 0.4]
[[wall]]
min = [-0.2, -0.2]
max = [2.0, 0.0]
[[solid]]
name = "s"
min = [1.0, 0.0]
max = [1.2, 0.1]
divisions = [2, 1]
material = { model = "linear_elastic", density = 1000.0, youngs_modulus = 1e6, poisson_ratio = 0.3 }
[[probe]]
name = "front"
kind = "surge_front"
component = "x"
"#;
        cosim_proto::scene::parse("t.toml", text, &[]).unwrap()
    }

    fn state() -> BrokerState {
        BrokerState {
            step: 10,
            t: 0.25,
            next_output: 3,
            next_checkpoint: 2,
            dt_fluid: 1e-3,
            dt_contact: f64::INFINITY,
            dt_structure: f64::INFINITY,
            pending_fem: vec![Correction {
                id: 5,
                dx: [0.0, 1e-4],
                dv: [0.0; 2],
                face: None,
            }],
            pending_sph: vec![Correction {
                id: 15,
                dx: [1e-4, 0.0],
                dv: [0.1, 0.0],
                face: None,
            }],
            roi: Some([0.9, -0.1, 1.3, 0.2]),
            load: Some(vec![[0.0; 2]; 6]),
            load_log: LoadLog::default(),
            owed: Vec::new(),
            exchanged: 40,
            fluid_origin: Some(vec![[0.05, 0.05]; 16]),
            rows: vec![(0.0, vec![0.4]), (0.1, vec![0.45]), (0.2, vec![0.5])],
            summary: Summary {
                status: cosim_proto::run_status::RunStatus::Ok,
                message: String::new(),
                run_id: "r".into(),
                scene: "t".into(),
                steps: 10,
                fem_substeps: 100,
                sph_substeps: 10,
                sim_time: 0.25,
                wall_seconds: 1.0,
                particles: 16,
                fem_nodes: 6,
                fem_elements: 2,
                solver: "wcsph".into(),
                contact: "node_to_segment".into(),
                mode: "in-process".into(),
                frames: 3,
                samples: 3,
                timings: Timings::default(),
                contact_stats: ContactStats::default(),
                counts: Default::default(),
                reaction_relaxation: None,
                contact_step_bound: None,
                energy_growth: None,
                trace: None,
                solid_in_wall: None,
            },
        }
    }

    /// The refusal of `state` after `edit`.
    fn refused(edit: impl FnOnce(&mut BrokerState)) -> String {
        let mut s = state();
        edit(&mut s);
        s.check(&scene()).expect_err("an inconsistent state is refused")
    }

    #[test]
    fn a_consistent_state_passes() {
        assert_eq!(state().check(&scene()), Ok(()));
        assert!(state().check_nodes(6, 16).is_ok());
    }

    #[test]
    fn ids_out_of_range_are_refused_naming_the_field() {
        let e = refused(|s| s.pending_sph[0].id = 16);
        assert_eq!(e, "pending_sph[0].id = 16, but there are 16 fluid particles");
        let e = refused(|s| s.pending_fem[0].id = 6);
        assert_eq!(e, "pending_fem[0].id = 6, but there are 6 structure nodes");
        let e = refused(|s| s.pending_fem[0].dv = [f64::NAN, 0.0]);
        assert!(e.starts_with("pending_fem[0] (id 5)") && e.contains("NaN"), "{e}");
    }

    #[test]
    fn lengths_that_disagree_are_refused_naming_the_field() {
        let e = refused(|s| s.rows[1].1.push(0.0));
        assert_eq!(e, "rows[1] holds 2 values, the scene has 1 probes");
        let e = refused(|s| {
            s.load.as_mut().unwrap().pop();
        });
        assert_eq!(e, "load holds 5 nodes, the structure has 6");
        let e = refused(|s| s.fluid_origin = Some(vec![[0.0; 2]; 17]));
        assert_eq!(e, "fluid_origin holds 17 positions, the fluid has 16 particles");
        let e = refused(|s| s.summary.fem_nodes = 9);
        assert_eq!(e, "summary.fem_nodes = 9 where the scene's solids have 6 nodes");
        let e = refused(|s| s.rows.push((0.25, vec![0.5])));
        assert_eq!(e, "summary.samples = 3 and summary.frames = 3 where rows holds 4");
        let entry = |t: f64, node: u32, wall: usize, depth: f64| crate::wall_entry::WallEntry {
            t,
            solid: "gate".into(),
            node,
            wall,
            depth,
        };
        let mut fine = state();
        fine.summary.solid_in_wall = Some(entry(0.25, 5, 0, 1e-3));
        fine.check(&scene()).unwrap();
        for bad in [
            entry(0.3, 5, 0, 1e-3),
            entry(0.25, 6, 0, 1e-3),
            entry(0.25, 5, 1, 1e-3),
            entry(0.25, 5, 0, 0.0),
            entry(f64::NAN, 5, 0, 1e-3),
        ] {
            let e = refused(|s| s.summary.solid_in_wall = Some(bad.clone()));
            assert!(
                e.starts_with("summary.solid_in_wall = ") && e.ends_with("node below 6, wall below 1)"),
                "{e}"
            );
        }
        let e = state().check_nodes(6, 17).unwrap_err().to_string();
        assert!(e.contains("16 fluid particles") && e.contains("have 6 and 17"), "{e}");
    }

    #[test]
    fn numbers_that_would_stall_or_poison_the_run_are_refused() {
        for dt in [0.0, -1e-3, f64::NAN] {
            let e = refused(|s| s.dt_fluid = dt);
            assert_eq!(e, format!("dt_fluid = {dt} is not a positive step"));
            let e = refused(|s| s.dt_contact = dt);
            assert_eq!(e, format!("dt_contact = {dt} is not a positive step"));
            let e = refused(|s| s.dt_structure = dt);
            assert_eq!(e, format!("dt_structure = {dt} is not a positive step"));
        }
        // Positive, but below coupling.max_dt / 2^32 (the scene's default max_dt, 1e-4 s).
        let floor = crate::coordinator::shortest_step(scene().coupling.max_dt);
        assert_eq!(
            refused(|s| s.dt_fluid = 1e-300),
            format!(
                "dt_fluid = 1e-300 s is below coupling.max_dt / 2^32 = {} s, the shortest step a run takes",
                Num(floor)
            )
        );
        assert!(refused(|s| s.dt_structure = floor * 0.5).starts_with("dt_structure = "));
        let mut at_floor = state();
        at_floor.dt_contact = floor;
        assert_eq!(at_floor.check(&scene()), Ok(()));
        let e = refused(|s| s.next_output = 2);
        assert!(
            e.starts_with("next_output = 2: output time 0.2 s is not after t = 0.25 s"),
            "{e}"
        );
        let e = refused(|s| s.rows[2].0 = f64::NAN);
        assert!(e.starts_with("rows[2]: t = NaN"), "{e}");
        let e = refused(|s| s.t = f64::INFINITY);
        assert_eq!(e, "t = inf is not a time");
        let e = refused(|s| s.summary.steps = 11);
        assert_eq!(e, "summary.steps = 11 where step = 10");
        let e = refused(|s| s.owed = vec![[0.0, f64::NAN]]);
        assert_eq!(e, "owed[0] = [0.0, NaN] is not finite");
        let e = refused(|s| s.owed = vec![[0.0; 2]; 7]);
        assert_eq!(e, "owed holds 7 nodes, the structure has 6");
    }

    #[test]
    fn an_energy_balance_without_a_budget_is_refused() {
        let growth = |budget: f64, largest: f64, rounding: f64| {
            refused(|s| {
                s.summary.energy_growth = Some(crate::energy_balance::EnergyGrowth {
                    largest,
                    at: 0.1,
                    budget,
                    initial: -1.0,
                    rounding,
                })
            })
        };
        for (budget, largest, rounding) in [
            (0.0, 0.1, 0.0),
            (-2.0, 0.1, 0.0),
            (f64::NAN, 0.1, 0.0),
            (2.0, f64::INFINITY, 0.0),
            (2.0, -0.5, 0.0),
            (2.0, 0.1, -1e-12),
            (2.0, 0.1, f64::NAN),
        ] {
            let e = growth(budget, largest, rounding);
            assert!(e.starts_with("summary.energy_growth = "), "{e}");
            assert!(
                e.ends_with("is not a balance (budget > 0, gain and rounding ≥ 0, all finite)"),
                "{e}"
            );
        }
    }
}
