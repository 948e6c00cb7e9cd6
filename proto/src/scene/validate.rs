//! Validation of a parsed scene: every value a solver relies on, checked in file order; the first problem found is
//! returned as its dotted key and one line.

use std::collections::HashSet;

use super::schema::{
    ContactAlgorithm, FluidSolver, ProbeKind, Scene, FLUID_SUBSTEPS_MAX, SCENE_VERSION, STRUCTURE_COURANT_MIN,
};
use super::sizing::Sizing;
use crate::{overlap, Num};

mod fluid;
mod probe_point;
mod solid;

type Invalid = (String, String);

fn check(ok: bool, key: impl FnOnce() -> String, message: impl FnOnce() -> String) -> Result<(), Invalid> {
    if ok {
        Ok(())
    } else {
        Err((key(), message()))
    }
}

fn finite_positive(key: &str, v: f64) -> Result<(), Invalid> {
    check(
        v.is_finite() && v > 0.0,
        || key.to_string(),
        || format!("must be a positive number, got {}", Num(v)),
    )
}

impl Scene {
    /// Checks every value a solver relies on. Returns the dotted key and the problem.
    pub fn validate(&self) -> Result<(), (String, String)> {
        check(
            self.version == SCENE_VERSION,
            || "version".into(),
            || {
                format!(
                    "this build reads version {SCENE_VERSION}, the file says {}",
                    self.version
                )
            },
        )?;
        check(
            !self.run.name.trim().is_empty(),
            || "run.name".into(),
            || "must not be empty".into(),
        )?;
        check(
            self.fluid.is_some() || self.walls.is_empty(),
            || "wall".into(),
            || "walls hold water: a scene with [[wall]] needs a [fluid]".into(),
        )?;
        check(
            self.fluid.is_some() || !self.solids.is_empty(),
            || "solid".into(),
            || "nothing to run: the scene has no [[solid]] and no [fluid]".into(),
        )?;
        finite_positive("run.end_time", self.run.end_time)?;
        finite_positive("run.output_interval", self.run.output_interval)?;
        if let Some(f) = self.run.frame_interval {
            finite_positive("run.frame_interval", f)?;
            let ratio = f / self.run.output_interval;
            check(
                ratio >= 1.0 - 1e-9 && (ratio - ratio.round()).abs() <= 1e-9 * ratio,
                || "run.frame_interval".into(),
                || {
                    format!(
                        "{} s is not a whole multiple of run.output_interval ({} s): frames are written at output \
                         times",
                        Num(f),
                        Num(self.run.output_interval)
                    )
                },
            )?;
        }
        check(
            self.run.gravity.iter().all(|g| g.is_finite()),
            || "run.gravity".into(),
            || "must be finite".into(),
        )?;
        finite_positive("coupling.max_dt", self.coupling.max_dt)?;
        finite_positive("coupling.step_timeout", self.coupling.step_timeout)?;
        check(
            // Above 0.94 elongated tri3 meshes go unstable (their characteristic length is an estimate).
            self.coupling.fem_cfl > 0.0 && self.coupling.fem_cfl <= 0.9,
            || "coupling.fem_cfl".into(),
            || format!("must be in (0, 0.9], got {}", Num(self.coupling.fem_cfl)),
        )?;
        check(
            self.coupling.structure_courant == 0.0
                || (STRUCTURE_COURANT_MIN..=1.0).contains(&self.coupling.structure_courant),
            || "coupling.structure_courant".into(),
            || {
                format!(
                    "must be 0 (no bound from the structure's speed) or in [0.001, 1], got {}",
                    Num(self.coupling.structure_courant)
                )
            },
        )?;
        check(
            (1..=FLUID_SUBSTEPS_MAX).contains(&self.coupling.fluid_substeps),
            || "coupling.fluid_substeps".into(),
            || {
                format!(
                    "must be a whole number in [1, {FLUID_SUBSTEPS_MAX}] (1: a contact pass after every fluid step), got {}",
                    self.coupling.fluid_substeps
                )
            },
        )?;
        if let Some(t) = self.contact.thickness {
            finite_positive("contact.thickness", t)?;
        }
        check(
            self.contact.sweeps >= 1,
            || "contact.sweeps".into(),
            || "must be at least 1".into(),
        )?;
        check(
            self.contact.load_spread.is_finite() && (0.0..=4.0).contains(&self.contact.load_spread),
            || "contact.load_spread".into(),
            || {
                format!(
                    "must be in [0, 4] fluid spacings, got {}",
                    Num(self.contact.load_spread)
                )
            },
        )?;
        if let Some(w) = self.contact.reaction_relaxation {
            check(
                w > 0.0 && w <= 1.0,
                || "contact.reaction_relaxation".into(),
                || format!("must be in (0, 1], got {}", Num(w)),
            )?;
            check(
                self.contact.algorithm == ContactAlgorithm::ParticleParticle,
                || "contact.reaction_relaxation".into(),
                || {
                    format!(
                        "applies to contact.algorithm = \"particle_particle\" only, not \"{}\"",
                        self.contact.algorithm.name()
                    )
                },
            )?;
        }
        if let Some(fluid) = &self.fluid {
            fluid::validate_fluid(fluid, &self.walls, &self.solids)?;
            // c0 defaults to 10 sqrt(2 g H) (`sph_node::setup::sound_speed`): WCSPH always needs it, ISPH for the
            // `particle_particle` force. Without gravity there is no default, and the fluid node failed at start
            // where `cosim check` refused (found 2026-12-06).
            let needs_c0 = fluid.solver == FluidSolver::Wcsph
                || (self.contact.algorithm == ContactAlgorithm::ParticleParticle && !self.solids.is_empty());
            check(
                fluid.sound_speed.is_some() || !needs_c0 || self.run.gravity != [0.0, 0.0],
                || "fluid.sound_speed".into(),
                || "cannot default to 10 sqrt(2 g H) without gravity (run.gravity is [0, 0]); give a value".into(),
            )?;
        }
        for (w, wall) in self.walls.iter().enumerate() {
            check(
                (0..2).all(|k| wall.min[k].is_finite() && wall.max[k].is_finite() && wall.max[k] > wall.min[k]),
                || format!("wall[{w}].max"),
                || {
                    format!(
                        "must be greater than min in every component, got min {:?} max {:?}",
                        wall.min, wall.max
                    )
                },
            )?;
        }
        let mut solids = HashSet::with_capacity(self.solids.len());
        for (s, solid) in self.solids.iter().enumerate() {
            solid::validate_solid(s, solid)?;
            check(
                solids.insert(solid.name.as_str()),
                || format!("solid[{s}].name"),
                || format!("`{}` is used by another solid", solid.name),
            )?;
        }
        let rects: Vec<overlap::Rect> = self.solids.iter().map(|s| (s.min, s.max)).collect();
        if let Some((a, b)) = overlap::first_overlap(&rects) {
            let (first, second) = (&self.solids[a], &self.solids[b]);
            return Err((
                format!("solid[{b}]"),
                format!(
                    "`{}` (min {:?} max {:?}) overlaps solid[{a}] `{}` (min {:?} max {:?}): solids may touch along \
                     an edge but not share area",
                    second.name, second.min, second.max, first.name, first.min, first.max
                ),
            ));
        }
        let mut names = HashSet::with_capacity(self.probes.len());
        for (p, probe) in self.probes.iter().enumerate() {
            let key = |k: &str| format!("probe[{p}].{k}");
            check(
                !probe.name.trim().is_empty() && !probe.name.contains(','),
                || key("name"),
                || "must be non-empty and contain no comma".into(),
            )?;
            check(
                names.insert(probe.name.as_str()),
                || key("name"),
                || format!("`{}` is used by another probe", probe.name),
            )?;
            let finite = |v: &[f64]| v.iter().all(|v| v.is_finite());
            check(
                probe.point.is_none_or(|p| finite(&p)),
                || key("point"),
                || format!("must be finite, got {:?}", probe.point.unwrap_or_default()),
            )?;
            check(
                probe.x_max.is_none_or(f64::is_finite),
                || key("x_max"),
                || format!("must be finite, got {}", Num(probe.x_max.unwrap_or_default())),
            )?;
            if let Some(name) = &probe.solid {
                check(
                    solids.contains(name.as_str()),
                    || key("solid"),
                    || format!("no solid named `{name}` (solids: {})", self.solid_names()),
                )?;
            }
            match probe.kind {
                ProbeKind::NodeDisplacement => {
                    check(
                        probe.solid.is_some(),
                        || key("solid"),
                        || "missing key (node_displacement)".into(),
                    )?;
                    check(
                        probe.point.is_some(),
                        || key("point"),
                        || "missing key (node_displacement)".into(),
                    )?;
                    let on = self.solids.iter().find(|s| Some(&s.name) == probe.solid.as_ref());
                    if let (Some(point), Some(solid)) = (probe.point, on) {
                        probe_point::on_solid(p, point, solid)?;
                    }
                    check(
                        probe.component.is_some(),
                        || key("component"),
                        || "missing key (node_displacement)".into(),
                    )?;
                }
                ProbeKind::Energy => {
                    check(probe.part.is_some(), || key("part"), || "missing key (energy)".into())?;
                }
                ProbeKind::InterfaceLoad => {
                    check(
                        !self.solids.is_empty() && self.fluid.is_some(),
                        || key("kind"),
                        || "needs a [[solid]] and a [fluid] in the scene".into(),
                    )?;
                    check(
                        probe.component.is_some(),
                        || key("component"),
                        || "missing key (interface_load)".into(),
                    )?;
                }
                ProbeKind::SurgeFront | ProbeKind::ColumnHeight | ProbeKind::Pressure | ProbeKind::WaterLevel => {
                    check(
                        self.fluid.is_some(),
                        || key("kind"),
                        || "needs a [fluid] in the scene".into(),
                    )?;
                    let (needed, present) = match probe.kind {
                        ProbeKind::SurgeFront => ("component", probe.component.is_some()),
                        ProbeKind::ColumnHeight => ("x_max", probe.x_max.is_some_and(f64::is_finite)),
                        _ => ("point", probe.point.is_some()),
                    };
                    check(
                        present,
                        || key(needed),
                        || format!("missing key ({:?})", probe.kind).to_lowercase(),
                    )?;
                    if let (ProbeKind::ColumnHeight, Some(x_max), Some(fluid)) = (probe.kind, probe.x_max, &self.fluid)
                    {
                        // The first column of particles of a block is half a spacing inside it (sph-node setup).
                        let first = fluid
                            .blocks
                            .iter()
                            .map(|b| b.min[0] + 0.5 * fluid.spacing)
                            .fold(f64::INFINITY, f64::min);
                        check(
                            x_max >= first,
                            || key("x_max"),
                            || {
                                format!(
                                    "{} is left of every fluid particle (the first are at x = {}): the column \
                                     would be empty from the start",
                                    Num(x_max),
                                    Num(first)
                                )
                            },
                        )?;
                    }
                }
            }
            // A sensor's face and time mean (pressure probes only).
            for (k, present) in [
                ("radius", probe.radius.is_some()),
                ("normal", probe.normal.is_some()),
                ("average", probe.average.is_some()),
            ] {
                check(
                    !present || probe.kind == ProbeKind::Pressure,
                    || key(k),
                    || "only a pressure probe takes this key".into(),
                )?;
            }
            if let Some(r) = probe.radius {
                check(
                    r.is_finite() && r >= 0.0,
                    || key("radius"),
                    || format!("must be a finite length >= 0, got {}", Num(r)),
                )?;
                let n = probe.normal.unwrap_or([0.0, 0.0]);
                check(
                    r == 0.0 || (finite(&n) && n[0].hypot(n[1]) > 0.0),
                    || key("normal"),
                    || match probe.normal {
                        None => "missing key (a face with radius > 0 needs the normal it lies across)".into(),
                        Some(n) => format!("must be a finite non-zero vector, got {n:?}"),
                    },
                )?;
            }
            if let Some(r) = &probe.reference {
                finite_positive(&key("reference.scale"), r.scale.abs())?;
                for (k, v) in [("t_scale", r.t_scale), ("t_offset", r.t_offset)] {
                    check(
                        v.is_finite(),
                        || key(&format!("reference.{k}")),
                        || format!("must be finite, got {}", Num(v)),
                    )?;
                }
            }
        }
        // Last: the counts are meaningful once every number above is known to be finite and positive.
        Sizing::of(self).check_counts()
    }

    fn solid_names(&self) -> String {
        if self.solids.is_empty() {
            return "none".into();
        }
        self.solids
            .iter()
            .map(|s| s.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    }
}
