//! Looking inside a live run (`cosim snapshot`, `cosim inspect RUN --particle ID | --node ID`): its state between
//! two steps from its broker (`cosim/<run>/broker/state`, `docs/PROTOCOL.md` §11: every node's checkpoint and the
//! last contact pass's corrections), read here with the nodes' own code, and the scene from the broker's `scene`
//! queryable. Reading changes nothing in the run: the nodes answer a checkpoint query from their state as it is.

use std::time::Duration;

use anyhow::Context;
use cosim_proto::control::{ContactRecord, DebugState, StateOf};
use cosim_proto::envelope::Envelope;
use cosim_proto::keys::{key, topic};
use cosim_proto::messages::{Correction, FemMesh, FemSnapshot, StepCommand};
use cosim_proto::scene::Scene;
use fem_node::core::FemCore;
use serde_json::json;
use sph_node::core::SphCheckpoint;
use zenoh::{Session, Wait};

/// The structure as the run holds it now.
pub struct FemView {
    /// Its mesh (reference positions, cells, interface segments, masses).
    pub mesh: FemMesh,
    /// Its state now (positions, velocities, stresses, energies).
    pub snap: FemSnapshot,
}

/// A live run's state between two steps.
pub struct Look {
    /// Last coupling step done.
    pub step: u64,
    /// Simulated time [s].
    pub t: f64,
    /// `paused at step N: REASON`, or empty while running.
    pub paused: String,
    /// The scene as the run runs it.
    pub scene: Scene,
    /// The structure, if the scene has one.
    pub fem: Option<FemView>,
    /// The fluid (and walls), if the scene has one.
    pub sph: Option<SphCheckpoint>,
    /// The broker's part: the last pass's corrections, the deepest penetration so far.
    pub debug: DebugState,
}

/// Ask run `id`'s broker for `what`, with the selector's `parameters` (`""`: none).
fn ask(session: &Session, id: &str, what: &str, parameters: &str, timeout: Duration) -> anyhow::Result<Vec<u8>> {
    let selector = match parameters {
        "" => key(id, what),
        p => format!("{}?{p}", key(id, what)),
    };
    let replies = session
        .get(selector)
        .timeout(timeout)
        .wait()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let reply = replies.recv().map_err(|_| {
        anyhow::anyhow!(
            "the broker of run `{id}` did not answer {what} within {:.0} s",
            timeout.as_secs_f64()
        )
    })?;
    match reply.result() {
        Ok(sample) => Ok(sample.payload().to_bytes().into_owned()),
        Err(e) => {
            let why = e
                .payload()
                .try_to_string()
                .map_or_else(|_| "(no reason)".into(), |s| s.into_owned());
            anyhow::bail!("the broker of run `{id}` refused {what}: {why}")
        }
    }
}

/// Fetch and read run `id`'s state now (a running run answers between two steps): every node's, or the fluid's alone
/// (`of`; the look then has no structure).
pub fn fetch(session: &Session, id: &str, timeout: Duration, of: StateOf) -> anyhow::Result<Look> {
    let text = String::from_utf8(ask(session, id, topic::SCENE, "", timeout)?).context("the run's scene")?;
    let scene = cosim_proto::scene::parse("(scene from the broker)", &text, &[])?;
    let bytes = ask(session, id, topic::BROKER_STATE, of.parameters(), timeout)?;
    let env = Envelope::<DebugState>::decode(&bytes, id, topic::BROKER_STATE)?;
    let fem = match env.body.fem.is_empty() {
        true => None,
        false => {
            let mut core = FemCore::new(&scene).context("fem-node")?;
            core.restore(&env.body.fem)
                .context("cannot read the structure node's state")?;
            // A step of length 0 moves nothing and answers the state as it is, on this copy of the node.
            let look = StepCommand {
                dt: 0.0,
                corrections: Vec::new(),
                roi: None,
                want_interface: false,
                want_snapshot: true,
                stop: false,
            };
            let snap = core
                .handle(&look)
                .context("cannot read the structure node's state")?
                .and_then(|s| s.snapshot)
                .context("the structure node's state gave no snapshot")?;
            Some(FemView {
                mesh: core.mesh().clone(),
                snap,
            })
        }
    };
    let sph = match env.body.sph.is_empty() {
        true => None,
        false => Some(SphCheckpoint::decode(&env.body.sph).context("cannot read the fluid node's state")?),
    };
    Ok(Look {
        step: env.step,
        t: env.t,
        paused: env.body.paused.clone(),
        scene,
        fem,
        sph,
        debug: env.body,
    })
}

/// One contact of the last pass: a (particle, master) pair the particle–element pass recorded (`recorded`), or,
/// for an algorithm that records none (`particle_particle`), a particle it corrected against the interface segment
/// nearest it now, λ and J reconstructed from the correction (`reconstructed`).
#[derive(Clone, Debug, serde::Serialize)]
pub struct ContactRow {
    /// `recorded` (by the pass) or `reconstructed` (after it, from the correction).
    pub source: &'static str,
    /// Fluid particle id.
    pub particle: u32,
    /// Its position now (before the correction, which goes out with the next command) [m].
    pub x: [f64; 2],
    /// The interface segment (index into `fem/mesh` `interface`; reconstructed: the nearest), −1 for a node
    /// contact.
    pub segment: i64,
    /// Its nodes a, b (a node contact: the node twice).
    pub nodes: [u32; 2],
    /// Recorded: the gap when the pass first acted on the pair; reconstructed: g = (x_s − x_c)·n − r_c to the
    /// nearest segment now [m] (DESIGN.md §4.5; negative: penetrating).
    pub gap: f64,
    /// The position multiplier λ applied to the pair, all sweeps [kg m] (reconstructed: m_s Δx·n).
    pub lambda: f64,
    /// The velocity impulse J applied to the pair, all sweeps [kg m/s] (reconstructed: m_s Δv·n).
    pub impulse: f64,
    /// The particle's whole correction (all its pairs).
    pub dx: [f64; 2],
    /// Its velocity part.
    pub dv: [f64; 2],
}

/// The contacts the last pass recorded (`DebugState::contacts`), with the particle's position and correction.
fn recorded(look: &Look, fem: &FemView, sph: &SphCheckpoint, records: &[ContactRecord]) -> Vec<ContactRow> {
    let state = &sph.solver.state;
    let mut rows = Vec::with_capacity(records.len());
    for r in records {
        let Some(&x) = state.x.get(r.particle as usize) else {
            continue;
        };
        let (segment, nodes) = match (r.segment, r.node) {
            (Some(k), _) => match fem.mesh.interface.get(k as usize) {
                Some(s) => (i64::from(k), [s.a, s.b]),
                None => continue,
            },
            (None, Some(n)) => (-1, [n, n]),
            (None, None) => continue,
        };
        let c = look.debug.sph_corrections.iter().find(|c| c.id == r.particle);
        rows.push(ContactRow {
            source: "recorded",
            particle: r.particle,
            x,
            segment,
            nodes,
            gap: r.gap,
            lambda: r.lambda,
            impulse: r.impulse,
            dx: c.map_or([0.0; 2], |c| c.dx),
            dv: c.map_or([0.0; 2], |c| c.dv),
        });
    }
    rows
}

/// The contacts of the last pass: the pairs the pass recorded (particle–element), else (`particle_particle`, or
/// no pass since a restart) every particle it corrected, with the segment nearest it, its gap, λ and J
/// reconstructed from the correction (DESIGN.md §4.5: λ = m Δx·n, J = m Δv·n).
pub fn contacts(look: &Look) -> Vec<ContactRow> {
    let (Some(fem), Some(sph)) = (&look.fem, &look.sph) else {
        return Vec::new();
    };
    if let Some(records) = &look.debug.contacts {
        return recorded(look, fem, sph, records);
    }
    let state = &sph.solver.state;
    let spacing = look.scene.fluid.as_ref().map_or(0.0, |f| f.spacing);
    let r_c = look.scene.contact.thickness.unwrap_or(0.5 * spacing);
    let mut rows = Vec::new();
    for c in &look.debug.sph_corrections {
        let i = c.id as usize;
        let (Some(&x), Some(&m)) = (state.x.get(i), state.m.get(i)) else {
            continue;
        };
        let Some((segment, nodes, x_c, n)) = nearest_segment(&fem.mesh, &fem.snap.x, x) else {
            continue;
        };
        let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
        rows.push(ContactRow {
            source: "reconstructed",
            particle: c.id,
            x,
            segment: segment as i64,
            nodes,
            gap: dot([x[0] - x_c[0], x[1] - x_c[1]], n) - r_c,
            lambda: m * dot(c.dx, n),
            impulse: m * dot(c.dv, n),
            dx: c.dx,
            dv: c.dv,
        });
    }
    rows
}

/// An interface segment as a point sees it: its index, its nodes, the point's closest point on it and its outward
/// unit normal.
type Nearest = (usize, [u32; 2], [f64; 2], [f64; 2]);

/// The interface segment nearest `p` (positions `x` of the mesh's nodes): its index, nodes, the closest point on
/// it and its outward unit normal (dy, −dx)/L (`fem/mesh` runs boundaries counter-clockwise).
fn nearest_segment(mesh: &FemMesh, x: &[[f64; 2]], p: [f64; 2]) -> Option<Nearest> {
    let mut best: Option<(f64, Nearest)> = None;
    for (k, s) in mesh.interface.iter().enumerate() {
        let (Some(&a), Some(&b)) = (x.get(s.a as usize), x.get(s.b as usize)) else {
            continue;
        };
        let d = [b[0] - a[0], b[1] - a[1]];
        let len = d[0].hypot(d[1]);
        if len == 0.0 {
            continue;
        }
        let xi = (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / (len * len)).clamp(0.0, 1.0);
        let c = [a[0] + xi * d[0], a[1] + xi * d[1]];
        let dist = (p[0] - c[0]).hypot(p[1] - c[1]);
        if best.as_ref().is_none_or(|(bd, _)| dist < *bd) {
            best = Some((dist, (k, [s.a, s.b], c, [d[1] / len, -d[0] / len])));
        }
    }
    best.map(|(_, found)| found)
}

fn correction_of(list: &[Correction], id: u32) -> serde_json::Value {
    list.iter()
        .find(|c| c.id == id)
        .map_or(serde_json::Value::Null, |c| match c.face {
            // particle_particle: the structure's face the broker sent with the correction (protocol 3).
            Some(f) => json!({"dx": c.dx, "dv": c.dv, "face": {"point": f.point, "normal": f.normal}}),
            None => json!({"dx": c.dx, "dv": c.dv}),
        })
}

fn head(look: &Look) -> serde_json::Value {
    json!({"step": look.step, "t": look.t, "paused": look.paused})
}

/// One fluid particle: its state, its neighbours within the kernel's support 2h (fluid ids nearest first, and how
/// many wall particles), the last pass's correction and contact.
pub fn particle(look: &Look, id: u32) -> anyhow::Result<serde_json::Value> {
    let sph = look.sph.as_ref().context("the run has no fluid")?;
    let s = &sph.solver.state;
    let i = id as usize;
    anyhow::ensure!(
        i < s.x.len(),
        "--particle {id}: the fluid has particles 0 to {}",
        s.x.len().saturating_sub(1)
    );
    let (field, at) = (|v: &[f64]| v.get(i).copied().unwrap_or(f64::NAN), s.x[i]);
    let support = 2.0 * look.scene.fluid.as_ref().map_or(0.0, |f| f.smoothing_ratio * f.spacing);
    let within = |p: &[f64; 2]| {
        let r = (p[0] - at[0]).hypot(p[1] - at[1]);
        (r < support).then_some(r)
    };
    let mut fluid: Vec<(f64, usize)> =
        s.x.iter()
            .enumerate()
            .filter(|&(j, _)| j != i)
            .filter_map(|(j, p)| within(p).map(|r| (r, j)))
            .collect();
    fluid.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let walls = sph.solver.walls.x.iter().filter(|p| within(p).is_some()).count();
    let contact = contacts(look).into_iter().find(|c| c.particle == id);
    let mut doc = head(look);
    doc["particle"] = json!({
        "id": id,
        "x": at,
        "v": s.v.get(i),
        "rho": field(&s.rho),
        "p": field(&s.p),
        "m": field(&s.m),
        "neighbours": {"support": support, "fluid": fluid.iter().map(|n| n.1).collect::<Vec<_>>(), "walls": walls},
        "correction": correction_of(&look.debug.sph_corrections, id),
        "contact": contact,
    });
    Ok(doc)
}

/// One FE node: its state, reference position and displacement, the interface segments it ends, whether it is
/// clamped, and the last pass's correction.
pub fn node(look: &Look, id: u32) -> anyhow::Result<serde_json::Value> {
    let fem = look.fem.as_ref().context("the run has no structure")?;
    let i = id as usize;
    let n = fem.mesh.nodes.len();
    anyhow::ensure!(
        i < n && i < fem.snap.x.len(),
        "--node {id}: the structure has nodes 0 to {}",
        n.saturating_sub(1)
    );
    let (x, x0) = (fem.snap.x[i], fem.mesh.nodes[i]);
    let segments: Vec<serde_json::Value> = fem
        .mesh
        .interface
        .iter()
        .enumerate()
        .filter(|(_, s)| s.a == id || s.b == id)
        .map(|(k, s)| json!({"segment": k, "nodes": [s.a, s.b]}))
        .collect();
    let mut doc = head(look);
    doc["node"] = json!({
        "id": id,
        "x": x,
        "v": fem.snap.v.get(i),
        "reference": x0,
        "displacement": [x[0] - x0[0], x[1] - x0[1]],
        "mass": fem.mesh.masses.get(i),
        "solid": fem.mesh.node_solid.get(i).and_then(|&s| fem.mesh.solid_names.get(s as usize)),
        "fixed": fem.mesh.fixed.contains(&id),
        "segments": segments,
        "correction": correction_of(&look.debug.fem_corrections, id),
    });
    Ok(doc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use cosim_proto::messages::ContactFace;

    /// A particle's last correction as `inspect --particle` shows it: with the face a `particle_particle` pass sent.
    #[test]
    fn a_correction_shows_its_face() {
        let plain = Correction {
            id: 3,
            dx: [1e-4, 0.0],
            dv: [0.0; 2],
            face: None,
        };
        let with_face = Correction {
            id: 5,
            dx: [0.0; 2],
            dv: [0.0, 0.5],
            face: Some(ContactFace {
                point: [0.1, 0.0],
                normal: [0.0, 1.0],
            }),
        };
        let list = [plain, with_face];
        assert_eq!(correction_of(&list, 3), json!({"dx": [1e-4, 0.0], "dv": [0.0, 0.0]}));
        assert_eq!(
            correction_of(&list, 5),
            json!({"dx": [0.0, 0.0], "dv": [0.0, 0.5], "face": {"point": [0.1, 0.0], "normal": [0.0, 1.0]}})
        );
        assert_eq!(correction_of(&list, 4), serde_json::Value::Null);
    }
}
