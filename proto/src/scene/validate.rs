//! Validation of a parsed scene: every value a solver relies on, checked in file order; the first problem found is
//! returned as its dotted key and one line.

use std::collections::HashSet;

use super::schema::{ContactAlgorithm, FluidSolver, Scene, FLUID_SUBSTEPS_MAX, SCENE_VERSION, STRUCTURE_COURANT_MIN};
use super::sizing::Sizing;
use crate::{overlap, Num};

mod fluid;
mod probe_point;
mod probes;
mod solid;

type Invalid = (String, String);

/// The smallest factor on a stable step (`fluid.cfl`, `coupling.fem_cfl`): below it a step so short that 1/Δt²
/// (ISPH's pressure equation) overflows.
const CFL_MIN: f64 = 1e-6;

/// `contact.thickness` = `t` against the fluid spacing `dx`, per algorithm (the gate at Δx = 2 mm to 0.05 s,
/// 2026-12-06): `particle_element` ran from Δx/100 to 0.75 Δx, gained energy at Δx and went unstable at 2 Δx and
/// past 5 Δx pushed particles out of the domain (past 1e10 m it found no contact at all and the water went through
/// the gate); `particle_particle` puts its force's range r0 at the thickness and its boundary points half of it
/// apart, so past Δx/2 the particles start inside the force (unstable at the second step at 0.75 Δx), at Δx/100
/// its stiffness, ∝ 1/r0², went unstable after 7 ms, and at 1e-8 m the points filled the memory.
fn thickness(t: f64, dx: f64, algorithm: ContactAlgorithm) -> Result<(), Invalid> {
    let (lo, hi, why) = match algorithm {
        ContactAlgorithm::ParticleElement => (
            0.01,
            1.0,
            "thicker, the contact reaches particles that are not touching and the coupled run gains energy",
        ),
        ContactAlgorithm::ParticleParticle => (
            0.1,
            0.5,
            "its force's range is the thickness, so thicker, the fluid particles (half a spacing from the \
             structure) start inside it; thinner, its stiffness (∝ 1/thickness²) outruns the step",
        ),
        ContactAlgorithm::None => return Ok(()),
    };
    check(
        (lo * dx..=hi * dx).contains(&t),
        || "contact.thickness".into(),
        || {
            format!(
                "{} m is outside [{lo} × spacing, {hi} × spacing] = [{}, {}] m for contact.algorithm = \"{}\" \
                 (default spacing / 2): {why}",
                Num(t),
                Num(lo * dx),
                Num(hi * dx),
                algorithm.name()
            )
        },
    )
}

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

/// The magnitudes a physical value of a scene may take, [1e-50, 1e50] (or 0 where the key allows it): the solvers
/// square and multiply them (ρ c0², ρ², E / ρ, h⁻³ …), and products of a few of them must stay finite and normal
/// in double precision. Past it a run ended "unstable at step 1" or with a NaN in a message, naming no key (found
/// 2026-12-06 by a sweep of extreme values: fluid.density = 1e300, fluid.sound_speed = 1e-300, run.gravity = 1e300).
pub const MAGNITUDES: [f64; 2] = [1e-50, 1e50];

/// `v` (finite) is zero or within [`MAGNITUDES`] in magnitude.
fn magnitude(key: &str, v: f64, unit: &str) -> Result<(), Invalid> {
    let a = v.abs();
    check(
        a == 0.0 || (MAGNITUDES[0]..=MAGNITUDES[1]).contains(&a),
        || key.to_string(),
        || {
            format!(
                "{} {unit} is outside the magnitudes this build computes with, {:e} to {:e} (their squares and \
                 products must stay finite in double precision)",
                Num(v),
                MAGNITUDES[0],
                MAGNITUDES[1]
            )
        },
    )
}

/// Every coordinate of the box `min`–`max` (finite) is within [`MAGNITUDES`]' largest magnitude.
fn coordinates(key: &str, min: [f64; 2], max: [f64; 2]) -> Result<(), Invalid> {
    check(
        min.iter().chain(&max).all(|v| v.abs() <= MAGNITUDES[1]),
        || key.to_string(),
        || format!("corners min {min:?} max {max:?} lie beyond ±{:e} m", MAGNITUDES[1]),
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
        magnitude("run.end_time", self.run.end_time, "s")?;
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
        for g in self.run.gravity {
            magnitude("run.gravity", g, "m/s²")?;
        }
        finite_positive("coupling.max_dt", self.coupling.max_dt)?;
        finite_positive("coupling.step_timeout", self.coupling.step_timeout)?;
        check(
            // Above 0.94 elongated tri3 meshes go unstable (their characteristic length is an estimate).
            (CFL_MIN..=0.9).contains(&self.coupling.fem_cfl),
            || "coupling.fem_cfl".into(),
            || format!("must be in [{CFL_MIN:e}, 0.9], got {}", Num(self.coupling.fem_cfl)),
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
        // Walls and solids first: the fluid's blocks are checked against them.
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
            coordinates(&format!("wall[{w}]"), wall.min, wall.max)?;
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
            if let (Some(t), false) = (self.contact.thickness, self.solids.is_empty()) {
                thickness(t, fluid.spacing, self.contact.algorithm)?;
            }
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
        probes::validate_probes(self, &solids)?;
        // Last: the counts are meaningful once every number above is known to be finite and positive.
        Sizing::of(self).check_counts()
    }
}
