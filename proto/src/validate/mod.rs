//! The contents of a well-framed message checked before anything uses them (`docs/PROTOCOL.md` §7, "Contents").
//!
//! The codec guarantees a message has the right layout, version, run and step; it cannot know that a segment names
//! a node the mesh has, that two arrays meant to run side by side have the same length, or that a position is a
//! number. Each incoming message type has one check here, run by its receiver right where it takes the message in,
//! so that no later code indexes wire data unchecked. An error names the message, the field, the index and the
//! value.

use std::fmt;

use crate::messages::{
    Correction, FemMesh, FemSnapshot, FemState, Segment, SphSetup, SphSnapshot, SphState, StepCommand,
};

/// The largest magnitude a number of a message may hold: the largest a scene's physical value may take
/// (`scene::MAGNITUDES`).
pub const LARGEST: f64 = 1e50;

/// Whether `v` is a number a state can hold: finite, and within ±[`LARGEST`]. The nodes' checkpoint checks use it
/// too.
pub fn within_largest(v: f64) -> bool {
    v.is_finite() && v.abs() <= LARGEST
}

/// What makes a message unusable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Ids out of range, lengths that disagree, impossible parameters.
    Inconsistent,
    /// A NaN, an infinity or a number beyond ±[`LARGEST`] where a state holds numbers: the sender blew up.
    NonFinite,
    /// A state no run of the scene can reach, though its numbers are finite: a speed or a position beyond
    /// [`Asked::reach`], a surface segment collapsed to a point. The sender blew up.
    Implausible,
}

/// A message whose contents cannot be used: `fem/mesh cells[12][2] = 999: node id out of range (480 nodes)`.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{message} {field}{} = {value}: {problem}", Index(index))]
pub struct Invalid {
    /// The message (its topic, e.g. `fem/mesh`).
    pub message: &'static str,
    /// The field.
    pub field: &'static str,
    /// The index within the field, outermost first (empty for a scalar or a whole array).
    pub index: Vec<usize>,
    /// The offending value, as text.
    pub value: String,
    /// What is wrong with it.
    pub problem: String,
    /// Inconsistent, or a non-finite number.
    pub kind: Kind,
}

impl Invalid {
    /// The same, as a state no run of the scene reaches ([`Kind::Implausible`]): its sender blew up.
    fn implausible(self) -> Self {
        Self {
            kind: Kind::Implausible,
            ..self
        }
    }

    /// True when the message holds a NaN or an infinity where a state holds numbers: the sender blew up.
    pub fn is_non_finite(&self) -> bool {
        self.kind == Kind::NonFinite
    }

    /// True when the sender blew up: a number no state holds ([`Kind::NonFinite`]) or a state no run of the scene
    /// reaches ([`Kind::Implausible`]). The run ends `unstable`, naming the sender.
    pub fn blew_up(&self) -> bool {
        matches!(self.kind, Kind::NonFinite | Kind::Implausible)
    }
}

struct Index<'a>(&'a [usize]);

impl fmt::Display for Index<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.iter().try_for_each(|i| write!(f, "[{i}]"))
    }
}

/// `Ok` or the first problem found.
pub type Result<T = ()> = std::result::Result<T, Invalid>;

/// The checks of one message, all naming it.
#[derive(Clone, Copy)]
struct Check(&'static str);

impl Check {
    fn fail(
        self,
        field: &'static str,
        index: &[usize],
        value: impl fmt::Display,
        problem: impl Into<String>,
    ) -> Invalid {
        Invalid {
            message: self.0,
            field,
            index: index.to_vec(),
            value: value.to_string(),
            problem: problem.into(),
            kind: Kind::Inconsistent,
        }
    }

    /// `field` must hold `want` entries, one per `per`.
    fn len(self, field: &'static str, got: usize, want: usize, per: &str) -> Result {
        if got == want {
            Ok(())
        } else {
            Err(self.fail(
                field,
                &[],
                format!("{got} entries"),
                format!("one per {per} expected: {want}"),
            ))
        }
    }

    /// A number a state can hold: finite, and within ±[`LARGEST`] (a node that reports 1e200 m/s has blown up as
    /// surely as one that reports an infinity, and its squares and products would overflow the contact, the
    /// probes and the energy balance: a structure at ±1e308 m held the broker's contact grid in an endless loop).
    fn finite(self, field: &'static str, index: &[usize], v: f64) -> Result {
        if within_largest(v) {
            Ok(())
        } else {
            Err(Invalid {
                kind: Kind::NonFinite,
                ..self.fail(field, index, format!("{v:?}"), "not a finite number within ±1e50")
            })
        }
    }

    fn points<const N: usize>(self, field: &'static str, xs: &[[f64; N]]) -> Result {
        for (i, x) in xs.iter().enumerate() {
            for (k, v) in x.iter().enumerate() {
                self.finite(field, &[i, k], *v)?;
            }
        }
        Ok(())
    }

    fn values(self, field: &'static str, xs: &[f64]) -> Result {
        xs.iter()
            .enumerate()
            .try_for_each(|(i, v)| self.finite(field, &[i], *v))
    }

    /// A number > 0 and at most [`LARGEST`] (masses, densities, lengths).
    fn positive(self, field: &'static str, index: &[usize], v: f64) -> Result {
        if v > 0.0 && v <= LARGEST {
            Ok(())
        } else {
            Err(self.fail(field, index, format!("{v:?}"), "must be a number > 0 and ≤ 1e50"))
        }
    }

    /// A time step: > 0 and not NaN (an infinite stable step means "no limit").
    fn step(self, field: &'static str, v: f64) -> Result {
        if v > 0.0 {
            Ok(())
        } else {
            Err(self.fail(field, &[], format!("{v:?}"), "a stable step must be > 0"))
        }
    }

    /// Seconds of computation: finite and ≥ 0.
    fn seconds(self, field: &'static str, v: f64) -> Result {
        // At most 1e9 s (31 years) a step: the run's totals (summary.json `timings`) stay finite.
        if v.is_finite() && (0.0..=1e9).contains(&v) {
            Ok(())
        } else {
            Err(self.fail(field, &[], format!("{v:?}"), "must be a number of seconds within 0…1e9"))
        }
    }

    fn id(self, field: &'static str, index: &[usize], id: u32, count: usize, what: &str) -> Result {
        if (id as usize) < count {
            Ok(())
        } else {
            Err(self.fail(field, index, id, format!("out of range ({count} {what})")))
        }
    }
}

/// What the broker asked a node for in a step, which its answer must match.
#[derive(Clone, Copy, Debug)]
pub struct Asked<'a> {
    /// The interface state: for the structure, exactly the mesh's interface nodes; for the fluid, the particles
    /// inside the region of interest.
    pub interface: bool,
    /// A full snapshot (an output time).
    pub snapshot: bool,
    /// For the structure: the ids of the mesh's interface nodes ([`FemMesh::interface_nodes`]).
    pub interface_ids: &'a [u32],
    /// How fast and how far a particle or a node of the answer may be ([`Reach`]).
    pub reach: Reach,
}

impl FemState {
    /// Check a structure node's answer (topic `fem/state`) against its mesh and what it was asked for.
    pub fn validate(&self, mesh: &FemMesh, asked: Asked<'_>) -> Result {
        let c = Check("fem/state");
        if asked.interface || !self.ids.is_empty() {
            let want = asked.interface_ids;
            c.len("ids", self.ids.len(), want.len(), "interface node of the mesh")?;
            if let Some(k) = (0..want.len()).find(|&k| self.ids[k] != want[k]) {
                return Err(c.fail(
                    "ids",
                    &[k],
                    self.ids[k],
                    format!("the mesh's interface node {k} is node {}", want[k]),
                ));
            }
        }
        c.len("x", self.x.len(), self.ids.len(), "id")?;
        c.len("v", self.v.len(), self.ids.len(), "id")?;
        c.points("x", &self.x)?;
        c.points("v", &self.v)?;
        c.speeds("v", &self.v, &asked.reach)?;
        c.positions("x", &self.x, &asked.reach)?;
        self.check_segments(c, mesh)?;
        c.step("dt_stable", self.dt_stable)?;
        c.seconds("compute_seconds", self.compute_seconds)?;
        match &self.snapshot {
            Some(s) => s.validate(mesh, &asked.reach),
            None if asked.snapshot => Err(c.fail("snapshot", &[], "none", "asked for at an output time")),
            None => Ok(()),
        }
    }

    /// No interface segment of the reported state (ids already checked against the mesh's interface nodes, which
    /// are ascending) has collapsed to a point: the contact takes its normal from it. An outside node that put half
    /// its interface nodes at one point ran on until the fluid node blew up and took the blame (found 2026-12-06).
    fn check_segments(&self, c: Check, mesh: &FemMesh) -> Result {
        let at = |id: u32| self.ids.binary_search(&id).ok().and_then(|k| self.x.get(k));
        for (i, Segment { a, b }) in mesh.interface.iter().enumerate() {
            if let (Some(pa), Some(pb)) = (at(*a), at(*b)) {
                if pa == pb {
                    return Err(c
                        .fail(
                            "x",
                            &[],
                            format!("{pa:?} for nodes {a} and {b}"),
                            format!("interface segment {i} collapsed to a point"),
                        )
                        .implausible());
                }
            }
        }
        Ok(())
    }
}

impl FemSnapshot {
    /// Check a structure snapshot against the mesh it is of, its nodes within `reach`.
    pub fn validate(&self, mesh: &FemMesh, reach: &Reach) -> Result {
        let c = Check("fem/state snapshot");
        c.len("x", self.x.len(), mesh.nodes.len(), "node")?;
        c.len("v", self.v.len(), mesh.nodes.len(), "node")?;
        c.len("stress", self.stress.len(), mesh.cells.len(), "cell")?;
        c.len("energies", self.energies.len(), mesh.solid_names.len(), "solid")?;
        c.points("x", &self.x)?;
        c.points("v", &self.v)?;
        c.speeds("v", &self.v, reach)?;
        c.positions("x", &self.x, reach)?;
        c.points("stress", &self.stress)?;
        let energies: Vec<[f64; 3]> = self
            .energies
            .iter()
            .map(|e| [e.kinetic, e.strain, e.potential])
            .collect();
        c.points("energies", &energies)
    }
}

impl SphSetup {
    /// Check what a fluid node registered with (topic `sph/setup`).
    pub fn validate(&self) -> Result {
        let c = Check("sph/setup");
        c.positive("spacing", &[], self.spacing)?;
        c.positive("h", &[], self.h)?;
        c.positive("density", &[], self.density)?;
        c.points("walls", &self.walls)?;
        c.step("dt_stable", self.dt_stable)
    }
}

impl SphState {
    /// Check a fluid node's answer (topic `sph/state`) against its registration and what it was asked for.
    pub fn validate(&self, setup: &SphSetup, asked: Asked<'_>) -> Result {
        let c = Check("sph/state");
        let n = setup.particles as usize;
        let mut last = None;
        for (k, &id) in self.ids.iter().enumerate() {
            c.id("ids", &[k], id, n, "particles")?;
            if last.is_some_and(|l| id <= l) {
                return Err(c.fail("ids", &[k], id, "ids must be ascending, each once"));
            }
            last = Some(id);
        }
        c.len("x", self.x.len(), self.ids.len(), "id")?;
        c.len("v", self.v.len(), self.ids.len(), "id")?;
        c.len("m", self.m.len(), self.ids.len(), "id")?;
        c.points("x", &self.x)?;
        c.points("v", &self.v)?;
        c.speeds("v", &self.v, &asked.reach)?;
        c.positions("x", &self.x, &asked.reach)?;
        for (k, m) in self.m.iter().enumerate() {
            c.positive("m", &[k], *m)?;
        }
        c.step("dt_stable", self.dt_stable)?;
        c.seconds("compute_seconds", self.compute_seconds)?;
        match &self.snapshot {
            Some(s) => s.validate(setup, &asked.reach),
            None if asked.snapshot => Err(c.fail("snapshot", &[], "none", "asked for at an output time")),
            None => Ok(()),
        }
    }
}

impl SphSnapshot {
    /// Check a fluid snapshot against the registration it belongs to, its particles within `reach`.
    pub fn validate(&self, setup: &SphSetup, reach: &Reach) -> Result {
        let c = Check("sph/state snapshot");
        let n = setup.particles as usize;
        for (field, len) in [
            ("x", self.x.len()),
            ("v", self.v.len()),
            ("rho", self.rho.len()),
            ("p", self.p.len()),
            ("m", self.m.len()),
        ] {
            c.len(field, len, n, "fluid particle")?;
        }
        c.len("wall_p", self.wall_p.len(), setup.walls.len(), "wall particle")?;
        c.len("sensors", self.sensors.len(), setup.sensors as usize, "interval sensor")?;
        for (k, v) in self.sensors.iter().enumerate() {
            // NaN: no particle near the sensor (a point out of the water and the walls), as an instant probe says.
            if v.is_infinite() {
                return Err(c.fail("sensors", &[k], format!("{v}"), "not a number"));
            }
        }
        c.points("x", &self.x)?;
        c.points("v", &self.v)?;
        c.speeds("v", &self.v, reach)?;
        c.positions("x", &self.x, reach)?;
        c.values("p", &self.p)?;
        c.values("wall_p", &self.wall_p)?;
        for (k, rho) in self.rho.iter().enumerate() {
            c.finite("rho", &[k], *rho)?;
            c.positive("rho", &[k], *rho)?;
        }
        for (k, m) in self.m.iter().enumerate() {
            c.positive("m", &[k], *m)?;
        }
        Ok(())
    }
}

impl StepCommand {
    /// Check a command (topics `broker/fem`, `broker/sph`) before a node applies any of it: a step no longer
    /// than the scene's `coupling.max_dt`, a region of interest of numbers, and corrections to the node's
    /// `count` nodes or particles. `message` names the topic.
    pub fn validate(&self, message: &'static str, count: usize, max_dt: f64) -> Result {
        let c = Check(message);
        // The broker lands on output times within 1e-9 of a step (coordinator LANDING): allow that much.
        if !(self.dt >= 0.0 && self.dt <= max_dt * (1.0 + 1e-6)) {
            return Err(c.fail(
                "dt",
                &[],
                format!("{:?}", self.dt),
                format!("a step is between 0 and coupling.max_dt = {max_dt:?} s"),
            ));
        }
        if let Some(roi) = &self.roi {
            c.points("roi", std::slice::from_ref(roi))?;
        }
        validate_corrections(c, &self.corrections, count, message == crate::keys::topic::BROKER_SPH)
    }
}

/// Corrections to `count` ids; faces only where `faces` (the fluid's corrections), with finite points and unit
/// normals.
fn validate_corrections(c: Check, corrections: &[Correction], count: usize, faces: bool) -> Result {
    for (k, corr) in corrections.iter().enumerate() {
        c.id("corrections.id", &[k], corr.id, count, "ids")?;
        for d in 0..2 {
            c.finite("corrections.dx", &[k, d], corr.dx[d])?;
            c.finite("corrections.dv", &[k, d], corr.dv[d])?;
        }
        let Some(face) = corr.face else { continue };
        if !faces {
            return Err(c.fail(
                "corrections.face",
                &[k],
                "a face",
                "faces come with the fluid's corrections only",
            ));
        }
        for d in 0..2 {
            c.finite("corrections.face.point", &[k, d], face.point[d])?;
        }
        let off = (face.normal[0].hypot(face.normal[1]) - 1.0).abs();
        // A NaN length fails too.
        if off.is_nan() || off > 1e-9 {
            return Err(c.fail(
                "corrections.face.normal",
                &[k],
                format!("{:?}", face.normal),
                "must be a unit vector",
            ));
        }
    }
    Ok(())
}

mod mesh;
mod reach;

pub use reach::{speed_limit, Reach, SPEED_LIMIT_FACTOR};
#[cfg(test)]
mod tests;
