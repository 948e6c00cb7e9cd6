//! Message bodies carried in an [`Envelope`](crate::Envelope), one type per topic (`DESIGN.md` §3).
//!
//! Positions and vectors are `[f64; 2]` (2D). Node ids are indices into the FE node list of [`FemMesh`].

use serde::{Deserialize, Serialize};

/// A boundary segment of the structure, from node `a` to node `b`. The structure lies on the left of a→b
/// (boundaries run counter-clockwise), so the outward unit normal is `(dy, −dx) / L`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Segment {
    /// First node id.
    pub a: u32,
    /// Second node id.
    pub b: u32,
}

/// Topic `fem/mesh` (fem → broker, once): the reference mesh, masses and interface segments.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FemMesh {
    /// Names of the solids, in scene order.
    pub solid_names: Vec<String>,
    /// Reference position of every node.
    pub nodes: Vec<[f64; 2]>,
    /// Lumped mass of every node, per unit thickness [kg/m].
    pub masses: Vec<f64>,
    /// Solid index of every node.
    pub node_solid: Vec<u32>,
    /// Element connectivity (3 or 4 node ids, counter-clockwise).
    pub cells: Vec<Vec<u32>>,
    /// Solid index of every element.
    pub cell_solid: Vec<u32>,
    /// Outer boundary segments of all solids (the contact masters).
    pub interface: Vec<Segment>,
    /// Clamped node ids.
    pub fixed: Vec<u32>,
    /// Stable FEM step of the reference configuration [s].
    pub dt_stable: f64,
}

impl FemMesh {
    /// Ids of the nodes on the interface segments, ascending and unique: the order `fem/state` reports them in.
    pub fn interface_nodes(&self) -> Vec<u32> {
        let mut ids: Vec<u32> = self.interface.iter().flat_map(|s| [s.a, s.b]).collect();
        ids.sort_unstable();
        ids.dedup();
        ids
    }
}

/// A sparse correction to one particle or node: position and velocity increments, and for a fluid particle that a
/// `particle_particle` pass corrected, the structure's face behind it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Correction {
    /// Node or particle id.
    pub id: u32,
    /// Position increment [m].
    pub dx: [f64; 2],
    /// Velocity increment [m/s].
    pub dv: [f64; 2],
    /// The structure's face nearest the corrected particle, where the correction does not show it: sent with the
    /// fluid's corrections of a `particle_particle` pass, which changes velocities only (a `particle_element` pass
    /// puts the particle r_c in front of the face along its normal, so its correction shows the face; ISPH reads it
    /// from there). `None` on the structure's corrections.
    pub face: Option<ContactFace>,
}

/// A face of the structure as seen from one fluid particle: the nearest point of its boundary and the unit normal
/// there, out of the structure (the outward normal of the segment that point lies on; at a convex corner, of the
/// segment the particle lies further in front of).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactFace {
    /// The nearest point of the structure's boundary [m].
    pub point: [f64; 2],
    /// Unit normal out of the structure, towards the particle.
    pub normal: [f64; 2],
}

/// Topics `broker/fem` and `broker/sph` (broker → node, each step): corrections to apply, then the step to take.
///
/// The node applies `corrections`, then advances by `dt` (no advance when `dt == 0`), then answers with its state
/// for the same envelope step. With `stop` set the node answers nothing and exits cleanly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepCommand {
    /// Coupling step to advance by [s].
    pub dt: f64,
    /// Corrections from the previous contact pass.
    pub corrections: Vec<Correction>,
    /// Region of interest `[xmin, ymin, xmax, ymax]`; the fluid node sends only particles inside it.
    pub roi: Option<[f64; 4]>,
    /// Send the interface state in the answer.
    pub want_interface: bool,
    /// Send a full snapshot in the answer (an output time).
    pub want_snapshot: bool,
    /// End of run: exit after applying the corrections.
    pub stop: bool,
}

impl StepCommand {
    /// A stop with nothing to apply: what a node is told when a run ends without the stop of its last step (a
    /// run that failed, a replayed trace cut short).
    pub fn bare_stop() -> Self {
        Self {
            dt: 0.0,
            corrections: Vec::new(),
            roi: None,
            want_interface: false,
            want_snapshot: false,
            stop: true,
        }
    }
}

/// Energies of one solid [J per unit thickness].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Energies {
    /// ½ Σ m v².
    pub kinetic: f64,
    /// Σ_e W(F_e) A_e.
    pub strain: f64,
    /// −Σ m g·(x − X).
    pub potential: f64,
}

/// A full structure snapshot for frames and probes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FemSnapshot {
    /// Current node positions.
    pub x: Vec<[f64; 2]>,
    /// Node velocities.
    pub v: Vec<[f64; 2]>,
    /// Cauchy stress per element `[σxx, σyy, σxy]` [Pa].
    pub stress: Vec<[f64; 3]>,
    /// Energies per solid, in scene order.
    pub energies: Vec<Energies>,
}

/// Topic `fem/state` (fem → broker, each step).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FemState {
    /// Interface node ids (empty unless asked for).
    pub ids: Vec<u32>,
    /// Their positions.
    pub x: Vec<[f64; 2]>,
    /// Their velocities.
    pub v: Vec<[f64; 2]>,
    /// FEM sub-steps taken for this coupling step.
    pub substeps: u32,
    /// Current stable FEM step [s].
    pub dt_stable: f64,
    /// Seconds of computation this step took on the node.
    pub compute_seconds: f64,
    /// Full snapshot when asked for.
    pub snapshot: Option<FemSnapshot>,
}

/// Topic `<node>/error` (node → broker): the node failed and is about to exit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NodeError {
    /// `unstable` for a numerical blow-up, `failed` otherwise.
    pub status: String,
    /// One line saying what went wrong.
    pub message: String,
}

/// Topic `sph/setup` (sph → broker, once): what the fluid node holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SphSetup {
    /// Fluid particles.
    pub particles: u32,
    /// Particle spacing Δx [m].
    pub spacing: f64,
    /// Smoothing length h [m].
    pub h: f64,
    /// Rest density ρ0 [kg/m³].
    pub density: f64,
    /// Fixed wall particle positions (for frames).
    pub walls: Vec<[f64; 2]>,
    /// Stable step of the initial state [s].
    pub dt_stable: f64,
    /// Interval-mean pressure sensors the node computes: the scene's `pressure` probes with `average =
    /// "interval"` (`cosim_proto::scene::PressureSensor::interval`), in scene order; 0 for a node that offers none.
    pub sensors: u32,
}

/// A full fluid snapshot for frames and probes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SphSnapshot {
    /// Fluid particle positions.
    pub x: Vec<[f64; 2]>,
    /// Velocities.
    pub v: Vec<[f64; 2]>,
    /// Densities [kg/m³].
    pub rho: Vec<f64>,
    /// Pressures [Pa].
    pub p: Vec<f64>,
    /// Masses per unit thickness [kg/m].
    pub m: Vec<f64>,
    /// Wall particle pressures [Pa], in the order of [`SphSetup::walls`].
    pub wall_p: Vec<f64>,
    /// Each interval sensor's time mean since the last snapshot [Pa] ([`SphSetup::sensors`] of them): Σ p_k Δt_k /
    /// Σ Δt_k over the SPH steps k since then, p_k the mean over the sensor's face after step k; the value now
    /// where no step was taken since. NaN where no particle is within reach of the face.
    pub sensors: Vec<f64>,
}

/// Topic `sph/state` (sph → broker, each step).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SphState {
    /// Ids of the particles inside the region of interest.
    pub ids: Vec<u32>,
    /// Their positions.
    pub x: Vec<[f64; 2]>,
    /// Their velocities.
    pub v: Vec<[f64; 2]>,
    /// Their masses.
    pub m: Vec<f64>,
    /// SPH steps taken for this coupling step.
    pub substeps: u32,
    /// Stable SPH step for the next step [s].
    pub dt_stable: f64,
    /// Seconds of computation this step took on the node.
    pub compute_seconds: f64,
    /// Full snapshot when asked for.
    pub snapshot: Option<SphSnapshot>,
}

/// Topics `fem/checkpoint`, `sph/checkpoint` (node's reply to the broker's query) and `fem/restore`,
/// `sph/restore` (broker's reply to the node's query): a node's whole state between two coupling steps, in the
/// node's own format (opaque to the protocol; `docs/PROTOCOL.md` §9). The envelope's step and t are those of
/// the last step the node completed. In a restore reply, `data` empty means "start from the scene".
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NodeCheckpoint {
    /// `fem-node` or `sph-node`: a state is never given to the other kind of node.
    pub node: String,
    /// The node's state, in its own format.
    pub data: Vec<u8>,
}
