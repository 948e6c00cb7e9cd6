//! The step barrier (`DESIGN.md` §3 steps 2–3): the commands of a coupling step go out to every node, and every
//! node's answer comes back and is checked before anything reads it.

use std::time::Instant;

use anyhow::Context;

use cosim_proto::messages::{FemState, SphState, StepCommand};
use cosim_proto::readable::significant;
use cosim_proto::scene::Scene;
use cosim_proto::validate::{speed_limit, Asked, Invalid, Reach};
use cosim_proto::Num;

use super::inputs::Nodes;
use crate::interface::Corrections;
use crate::link::LinkError;
use crate::summary::Summary;

/// The answers of one coupling step.
pub(super) struct Round {
    pub fem: Option<FemState>,
    pub sph: Option<SphState>,
}

/// docs/PROTOCOL.md §7 "Contents": the registrations are checked before anything indexes them, and against what
/// the scene fixes: a coupled structure must have a surface (none made an infinite region of interest, which the
/// fluid node refused as the broker's fault), and the fluid's spacing, smoothing length and density are the scene's
/// (the contact's thickness, reach and region of interest are made from them: a fluid node registering 1e-300 m
/// made `particle_particle` build 1e300 points a segment, and one at twice the spacing ran `ok` with no contact).
pub(super) fn check_registrations(scene: &Scene, nodes: &Nodes<'_>) -> anyhow::Result<()> {
    if let Some(link) = &nodes.fem {
        link.setup().validate().map_err(|e| unusable("fem-node", e))?;
        check_solids(scene, link.setup())?;
        if nodes.sph.is_some() && link.setup().interface.is_empty() {
            return Err(unusable_because(
                "fem-node",
                "fem/mesh interface = 0 entries: a structure coupled to a fluid needs its boundary segments".into(),
            ));
        }
        if nodes.sph.is_some() {
            check_surface(scene, link.setup())?;
        }
    }
    if let Some(link) = &nodes.sph {
        let setup = link.setup();
        setup.validate().map_err(|e| unusable("sph-node", e))?;
        let Some(f) = &scene.fluid else {
            return Ok(());
        };
        for (field, got, want) in [
            ("spacing", setup.spacing, f.spacing),
            ("h", setup.h, f.smoothing_ratio * f.spacing),
            ("density", setup.density, f.density),
        ] {
            if (got - want).abs() > 1e-9 * want.abs() {
                return Err(unusable_because(
                    "sph-node",
                    format!("sph/setup {field} = {}: the scene gives {}", Num(got), Num(want)),
                ));
            }
        }
    }
    Ok(())
}

/// What every answer of the run is checked against besides its node's registration.
pub(super) struct Expected {
    /// The ids of the structure's interface nodes, which its answers report ([`cosim_proto::messages::FemMesh::interface_nodes`]).
    interface_ids: Vec<u32>,
    /// How fast and how far a node may report a particle or a node ([`Reach`]).
    reach: Reach,
}

impl Expected {
    /// From the scene and the registrations (checked).
    pub fn new(scene: &Scene, nodes: &Nodes<'_>) -> Self {
        let c0 = scene
            .fluid
            .as_ref()
            .and_then(|f| sph_node::setup::sound_speed(f, scene.run.gravity).ok());
        // A solid's bar wave speed √(E/ρ).
        let solids = scene
            .solids
            .iter()
            .map(|s| (s.material.youngs_modulus / s.material.density).sqrt());
        let mesh = nodes.fem.as_ref().map(|f| f.setup());
        let walls = nodes.sph.as_ref().map_or(&[][..], |s| &s.setup().walls);
        let start = start(scene, mesh.map_or(&[][..], |m| &m.nodes), walls);
        Self {
            interface_ids: mesh.map_or_else(Vec::new, |m| m.interface_nodes()),
            reach: Reach::new(speed_limit(c0, solids), start, scene.run.end_time),
        }
    }
}

/// The box the run starts in: the scene's walls, fluid blocks and solids, and the points the nodes registered (the
/// structure's nodes `mesh`, the wall particles `walls`); the whole plane where there are none.
fn start(scene: &Scene, mesh: &[[f64; 2]], walls: &[[f64; 2]]) -> ([f64; 2], [f64; 2]) {
    let (mut lo, mut hi) = scene.bounds();
    for p in mesh.iter().chain(walls) {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if lo[0] <= hi[0] {
        (lo, hi)
    } else {
        ([f64::NEG_INFINITY; 2], [f64::INFINITY; 2])
    }
}

/// How many times the scene's solids' perimeter a coupled structure's registered surface may be long.
const SURFACE_FACTOR: f64 = 10.0;

/// A coupled structure's surface is the scene's, give or take: its segments at most [`SURFACE_FACTOR`] times as long
/// as the perimeters of the scene's solids together. An outside node may mesh the solids its own way, but not make
/// them another size: `particle_particle` lays a point every fluid spacing along the surface, and a plate registered
/// 1e6 m long took 7.7 GB and 3 s a coupling step (found 2026-12-06 by the sweep of hostile external nodes, D3).
fn check_surface(scene: &Scene, mesh: &cosim_proto::messages::FemMesh) -> anyhow::Result<()> {
    let perimeter: f64 = scene
        .solids
        .iter()
        .map(|s| 2.0 * ((s.max[0] - s.min[0]) + (s.max[1] - s.min[1])))
        .sum();
    // Ids were checked with the mesh.
    let length: f64 = mesh
        .interface
        .iter()
        .filter_map(|s| Some((mesh.nodes.get(s.a as usize)?, mesh.nodes.get(s.b as usize)?)))
        .map(|(a, b)| (b[0] - a[0]).hypot(b[1] - a[1]))
        .sum();
    if length > SURFACE_FACTOR * perimeter {
        return Err(unusable_because(
            "fem-node",
            format!(
                "fem/mesh interface = {} segments {} m long together: the scene's solids have {} m of surface (at \
                 most {SURFACE_FACTOR} times that)",
                mesh.interface.len(),
                Num(significant(length, 6)),
                Num(significant(perimeter, 6))
            ),
        ));
    }
    Ok(())
}

/// A structure node's solids are the scene's, by name and in scene order (PROTOCOL §5, `solid_names`): the probes
/// find a solid by its name, and the surface's size is checked against the scene's solids. An outside node that
/// registered a second solid the scene does not have ran `ok` (the sweep of hostile external nodes, D15). A scene
/// without solids leaves the node's to it.
fn check_solids(scene: &Scene, mesh: &cosim_proto::messages::FemMesh) -> anyhow::Result<()> {
    let want: Vec<&str> = scene.solids.iter().map(|s| s.name.as_str()).collect();
    if want.is_empty() || mesh.solid_names.iter().map(String::as_str).eq(want.iter().copied()) {
        return Ok(());
    }
    Err(unusable_because(
        "fem-node",
        format!(
            "fem/mesh solid_names = {:?}: the scene's solids are {want:?} (the same names in the same order)",
            mesh.solid_names
        ),
    ))
}

/// A step command with nothing to correct and no region of interest.
fn command(dt: f64, want_snapshot: bool) -> StepCommand {
    StepCommand {
        dt,
        corrections: Vec::new(),
        roi: None,
        want_interface: false,
        want_snapshot,
        stop: false,
    }
}

/// The commands of one step, (fem, sph): the pending corrections go to their node; the fluid node is asked for
/// the particles inside `roi`, the structure node for its interface nodes, when the run is coupled.
pub(super) fn commands(
    dt: f64,
    want_snapshot: bool,
    coupled: bool,
    roi: Option<[f64; 4]>,
    pending: &mut Corrections,
) -> (StepCommand, StepCommand) {
    let fem = StepCommand {
        corrections: std::mem::take(&mut pending.fem),
        want_interface: coupled,
        ..command(dt, want_snapshot)
    };
    let sph = StepCommand {
        corrections: std::mem::take(&mut pending.sph),
        roi,
        want_interface: coupled,
        ..command(dt, want_snapshot)
    };
    (fem, sph)
}

/// One coupling step with every node: send to all, then collect all, so processes compute side by side. The
/// nodes' own compute time counts as `fem`/`sph`; the rest of the round as `messaging`: beyond the slower node where
/// the nodes compute side by side (other processes), beyond their sum where they compute one after the other inside
/// `receive` (in this process).
pub(super) fn exchange(
    nodes: &mut Nodes<'_>,
    expected: &Expected,
    summary: &mut Summary,
    step: u64,
    t: f64,
    (fem_cmd, sph_cmd): (StepCommand, StepCommand),
) -> anyhow::Result<Round> {
    let context = || format!("coupling step {step} from t = {} s", cosim_proto::Num(t));
    let asked = |cmd: &StepCommand| Asked {
        interface: cmd.want_interface,
        snapshot: cmd.want_snapshot,
        interface_ids: &expected.interface_ids,
        reach: expected.reach,
    };
    let (fem_asked, sph_asked) = (asked(&fem_cmd), asked(&sph_cmd));
    let started = Instant::now();
    if let Some(link) = nodes.sph.as_deref_mut() {
        link.send(step, t, sph_cmd).with_context(context)?;
    }
    if let Some(link) = nodes.fem.as_deref_mut() {
        link.send(step, t, fem_cmd).with_context(context)?;
    }
    // docs/PROTOCOL.md §7 "Contents": each answer is checked against the node's registration and the command
    // before anything reads it.
    let sph = match nodes.sph.as_deref_mut() {
        Some(link) => {
            let state = link.receive(step).with_context(context)?;
            state
                .validate(link.setup(), sph_asked)
                .map_err(|e| unusable("sph-node", e))
                .with_context(context)?;
            Some(state)
        }
        None => None,
    };
    let fem = match nodes.fem.as_deref_mut() {
        Some(link) => {
            let state = link.receive(step).with_context(context)?;
            state
                .validate(link.setup(), fem_asked)
                .map_err(|e| unusable("fem-node", e))
                .with_context(context)?;
            Some(state)
        }
        None => None,
    };
    let wall = started.elapsed().as_secs_f64();
    let c_fem = fem.as_ref().map_or(0.0, |s| s.compute_seconds);
    let c_sph = sph.as_ref().map_or(0.0, |s| s.compute_seconds);
    summary.timings.fem += c_fem;
    summary.timings.sph += c_sph;
    let (mut side_by_side, mut in_turn) = (0.0f64, 0.0);
    for (concurrent, c) in [
        (nodes.fem.as_ref().is_none_or(|l| l.concurrent()), c_fem),
        (nodes.sph.as_ref().is_none_or(|l| l.concurrent()), c_sph),
    ] {
        if concurrent {
            side_by_side = side_by_side.max(c);
        } else {
            in_turn += c;
        }
    }
    summary.timings.messaging += (wall - side_by_side - in_turn).max(0.0);
    Ok(Round { fem, sph })
}

/// The last message of a run that reached its end: every node is told to stop.
pub(super) fn stop(nodes: &mut Nodes<'_>, step: u64, t: f64) -> anyhow::Result<()> {
    let stop = StepCommand::bare_stop();
    if let Some(link) = nodes.fem.as_deref_mut() {
        link.send(step, t, stop.clone())?;
    }
    if let Some(link) = nodes.sph.as_deref_mut() {
        link.send(step, t, stop)?;
    }
    Ok(())
}

/// A run that ended early: every node still there is told to stop (`NodeLink::farewell`).
pub(super) fn farewell(nodes: &mut Nodes<'_>) {
    if let Some(link) = nodes.fem.as_deref_mut() {
        link.farewell();
    }
    if let Some(link) = nodes.sph.as_deref_mut() {
        link.farewell();
    }
}

/// A registration from `node` that disagrees with the scene: the run fails.
fn unusable_because(node: &str, why: String) -> anyhow::Error {
    LinkError::Failed {
        node: node.into(),
        message: format!("sent an unusable message: {why}"),
    }
    .into()
}

/// A message from `node` whose contents cannot be used: the run fails (or, for a NaN or an infinity in a state, or a
/// state no run of the scene reaches, ends `unstable`: the node blew up without noticing), naming the message, the
/// field, the index and the value.
fn unusable(node: &str, e: Invalid) -> LinkError {
    let (node, message) = (node.to_string(), format!("sent an unusable message: {e}"));
    if e.blew_up() {
        LinkError::Unstable { node, message }
    } else {
        LinkError::Failed { node, message }
    }
}
