//! The fluid–structure interface of a run (`DESIGN.md` §3 steps 1, 4): the region of interest the fluid node
//! reports particles from, and the contact pass that turns one step's interface states into the sparse
//! corrections both nodes apply before the next step. Pure: wire messages in, wire messages out.

use cosim_proto::control::ContactRecord;
use cosim_proto::messages::{ContactFace, Correction, FemMesh, FemState, SphSetup, SphState};
use cosim_proto::scene::{ContactAlgorithm as ContactChoice, Scene};

use crate::contact::{self, ContactAlgorithm};
use crate::contact_step;
use crate::load_spread::LoadSpread;
use crate::relaxation::{self, Relaxation};

/// What one contact pass did, for `summary.json` `contact_stats` and the frames.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PassStats {
    /// Particles in the region of interest (exchanged this step).
    pub exchanged: usize,
    /// Active contacts.
    pub contacts: usize,
    /// Deepest penetration of the contact thickness before the correction [m].
    pub max_penetration: f64,
    /// |Δ Σ m v| / Σ m |Δv|: the change of total linear momentum relative to the momentum moved.
    pub linear_momentum_change: f64,
    /// |Δ Σ m x × v| / Σ m |x × Δv| at the corrected positions.
    pub angular_momentum_change: f64,
    /// The longest next coupling step the contact force allows ([`crate::contact_step`]); `None` for no bound.
    pub stable_dt: Option<f64>,
}

/// The corrections of one pass, per node.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Corrections {
    /// To the structure node (FE node ids).
    pub fem: Vec<Correction>,
    /// To the fluid node (particle ids).
    pub sph: Vec<Correction>,
}

/// The interface between the structure's boundary segments and the fluid particles.
pub struct Interface {
    /// The `[contact] algorithm`, with its parameters and scratch memory.
    algorithm: Box<dyn ContactAlgorithm>,
    /// FE ids of the interface nodes, ascending (the order `fem-node` reports them in).
    node_ids: Vec<u32>,
    /// Segments as indices into `node_ids`.
    segments: Vec<contact::Segment>,
    masses: Vec<f64>,
    fixed: Vec<bool>,
    /// How far outside the structure's bounding box particles are reported.
    margin: f64,
    /// Contact impulse of the last pass per FE node [N·s/m], for the interface load.
    impulse: Vec<[f64; 2]>,
    dt: f64,
    /// The pairs the last pass acted on, in fluid and FE ids (reused from pass to pass); `recorded` false where
    /// the algorithm records none.
    records: Vec<ContactRecord>,
    recorded: bool,
    /// Send the structure's face with each fluid correction (`particle_particle`, whose corrections do not show it).
    faces: bool,
    /// The impulse owed to the structure's nodes and not yet given (`contact.reaction_relaxation`).
    relaxation: Relaxation,
    /// The structure's share spread along its surface (`contact.load_spread`).
    spread: LoadSpread,
}

impl Interface {
    /// The interface of `mesh` (its boundary segments, lumped masses and clamped nodes) against `sph`'s particles.
    ///
    /// `mesh` must have passed [`FemMesh::validate`] (its ids in range, one mass per node); a mesh that did not is
    /// refused here too, never indexed out of range.
    pub fn new(scene: &Scene, mesh: &FemMesh, sph: &SphSetup) -> anyhow::Result<Self> {
        let node_ids = mesh.interface_nodes();
        // Every segment end is in `node_ids`, which is made of them.
        let local = |id: u32| node_ids.binary_search(&id).unwrap_or_default();
        let segments = mesh
            .interface
            .iter()
            .map(|s| contact::Segment {
                a: local(s.a),
                b: local(s.b),
            })
            .collect();
        let masses = node_ids
            .iter()
            .map(|&id| {
                mesh.masses.get(id as usize).copied().ok_or_else(|| {
                    anyhow::anyhow!(
                        "fem/mesh interface node {id} has no mass ({} masses)",
                        mesh.masses.len()
                    )
                })
            })
            .collect::<anyhow::Result<_>>()?;
        let mut clamped = vec![false; mesh.nodes.len()];
        for &id in &mesh.fixed {
            if let Some(c) = clamped.get_mut(id as usize) {
                *c = true;
            }
        }
        let fixed = node_ids
            .iter()
            .map(|&id| clamped.get(id as usize).copied().unwrap_or(false))
            .collect();
        let dx = sph.spacing;
        let thickness = scene.contact.thickness.unwrap_or(0.5 * dx);
        let force = particle_params(scene, dx, thickness);
        let algorithm: Box<dyn ContactAlgorithm> = match scene.contact.algorithm {
            ContactChoice::ParticleElement => {
                Box::new(contact::ParticleElement::new(element_params(scene, dx, thickness)))
            }
            ContactChoice::ParticleParticle => {
                Box::new(contact::ParticleParticle::new(force, contact_step::applies(scene)))
            }
            ContactChoice::None => Box::new(()),
        };
        let relaxation = Relaxation::new(relaxation::choose(scene, &force));
        if let Some(c) = relaxation.choice() {
            tracing::info!("contact reaction relaxation ω = {:.4} ({})", c.omega, c.reason);
        }
        Ok(Self {
            algorithm,
            node_ids,
            segments,
            masses,
            fixed,
            // A particle moves less than h in one step (CFL), so one outside the box inflated by 2h plus the
            // contact range cannot reach a segment before the next pass.
            margin: 2.0 * sph.h + thickness.max(dx) + dx,
            impulse: vec![[0.0; 2]; mesh.nodes.len()],
            dt: 0.0,
            records: Vec::new(),
            recorded: false,
            faces: scene.contact.algorithm == ContactChoice::ParticleParticle,
            relaxation,
            spread: LoadSpread::new(scene.contact.load_spread * dx),
        })
    }

    /// The FE ids of the interface nodes, in the order the structure node reports them.
    pub fn node_ids(&self) -> &[u32] {
        &self.node_ids
    }

    /// The (particle, master) pairs the last pass acted on, as the algorithm recorded them (gap, λ, J), in fluid
    /// particle ids, interface segment indices and FE node ids; `None` where the algorithm records none.
    pub fn contacts(&self) -> Option<&[ContactRecord]> {
        self.recorded.then_some(&self.records[..])
    }

    /// Whether contact is computed at all (`[contact] algorithm` not `none`).
    pub fn active(&self) -> bool {
        self.algorithm.active()
    }

    /// The region of interest `[x0, y0, x1, y1]`: the bounding box of the interface nodes at `x`, inflated by
    /// 2h + the contact range (§3 step 1).
    pub fn roi(&self, x: &[[f64; 2]]) -> [f64; 4] {
        let mut b = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
        for x in x {
            b = [b[0].min(x[0]), b[1].min(x[1]), b[2].max(x[0]), b[3].max(x[1])];
        }
        [
            b[0] - self.margin,
            b[1] - self.margin,
            b[2] + self.margin,
            b[3] + self.margin,
        ]
    }

    /// The contact impulse of the last pass per FE node [N·s/m].
    pub fn impulses(&self) -> &[[f64; 2]] {
        &self.impulse
    }

    /// The contact impulse of the last pass per FE node divided by its coupling step: the interface load [N/m].
    pub fn load(&self) -> Vec<[f64; 2]> {
        let k = if self.dt > 0.0 { 1.0 / self.dt } else { 0.0 };
        self.impulse.iter().map(|j| [j[0] * k, j[1] * k]).collect()
    }

    /// How the structure's contact impulse is relaxed; `None` where it is given at once.
    pub fn relaxation(&self) -> Option<&relaxation::RelaxationChoice> {
        self.relaxation.choice()
    }

    /// The impulse owed to each interface node and not yet given (empty unless the reaction is relaxed), for a
    /// checkpoint.
    pub fn owed(&self) -> &[[f64; 2]] {
        self.relaxation.owed()
    }

    /// Put back the owed impulse a checkpoint saved ([`Interface::owed`]).
    pub fn restore_owed(&mut self, owed: &[[f64; 2]]) -> anyhow::Result<()> {
        self.relaxation.restore(owed, self.node_ids.len())
    }

    /// One contact pass (§3 step 4) on the states both nodes answered after a step of length `dt`.
    pub fn pass(&mut self, fem: &FemState, sph: &SphState, dt: f64) -> anyhow::Result<(Corrections, PassStats)> {
        // The coordinator checked both states (FemState::validate, SphState::validate); a pass called without that
        // check is refused here rather than indexing past an array.
        anyhow::ensure!(
            fem.ids == self.node_ids && fem.x.len() == fem.ids.len() && fem.v.len() == fem.ids.len(),
            "fem/state does not report the mesh's {} interface nodes (ids {}, x {}, v {})",
            self.node_ids.len(),
            fem.ids.len(),
            fem.x.len(),
            fem.v.len()
        );
        anyhow::ensure!(
            sph.x.len() == sph.ids.len() && sph.v.len() == sph.ids.len() && sph.m.len() == sph.ids.len(),
            "sph/state arrays disagree (ids {}, x {}, v {}, m {})",
            sph.ids.len(),
            sph.x.len(),
            sph.v.len(),
            sph.m.len()
        );
        for j in &mut self.impulse {
            *j = [0.0; 2];
        }
        self.dt = dt;
        let mut stats = PassStats {
            exchanged: sph.ids.len(),
            ..PassStats::default()
        };
        self.records.clear();
        self.recorded = self.algorithm.pairs().is_some();
        // Without particles nothing changes, unless the structure is still owed an impulse.
        let owed = self.relaxation.owed().iter().any(|o| *o != [0.0; 2]);
        if !self.active() || (sph.ids.is_empty() && !owed) {
            return Ok((Corrections::default(), stats));
        }
        let (mut px, mut pv) = (sph.x.clone(), sph.v.clone());
        let (mut nx, mut nv) = (fem.x.clone(), fem.v.clone());
        let node_impulse = {
            let particles = contact::Particles {
                x: &mut px,
                v: &mut pv,
                m: &sph.m,
            };
            let nodes = contact::Nodes {
                x: &mut nx,
                v: &mut nv,
                m: &self.masses,
                fixed: &self.fixed,
            };
            let report = self.algorithm.correct(particles, nodes, &self.segments, dt)?;
            stats.contacts = report.contacts;
            stats.max_penetration = report.max_penetration;
            // Zero, so no bound, unless the algorithm measured it (contact_step::applies).
            stats.stable_dt = contact_step::stable_step(report.stiffness, self.relaxation.omega(dt));
            report.node_impulse
        };
        // Of the pass: the balance of the momentum it moved, before the structure's share is relaxed.
        let (lin, ang) = momentum_change((&sph.m, &sph.v, &px, &pv), &nx, &node_impulse);
        stats.linear_momentum_change = lin;
        stats.angular_momentum_change = ang;
        let mut node_impulse = node_impulse;
        let mut change = self.relaxation.give(&mut node_impulse, &self.fixed, dt);
        // What the structure receives now, spread along its surface where the scene asks (load_spread.rs).
        if self.spread.active() {
            let spread = self.spread.apply(&self.segments, &nx, &self.fixed, &mut node_impulse);
            for (c, s) in change.iter_mut().zip(&spread) {
                *c = [c[0] + s[0], c[1] + s[1]];
            }
        }
        for ((v, c), m) in nv.iter_mut().zip(&change).zip(&self.masses) {
            if *c != [0.0; 2] {
                *v = [v[0] + c[0] / m, v[1] + c[1] / m];
            }
        }
        if let Some(pairs) = self.algorithm.pairs() {
            for p in pairs {
                let Some(&particle) = sph.ids.get(p.particle) else {
                    continue;
                };
                let (segment, node) = match p.master {
                    contact::PairMaster::Segment(k) => (Some(k), None),
                    contact::PairMaster::Node(k) => (None, self.node_ids.get(k as usize).copied()),
                };
                self.records.push(ContactRecord {
                    particle,
                    segment,
                    node,
                    gap: p.gap,
                    lambda: p.lambda,
                    impulse: p.impulse,
                });
            }
        }
        tracing::debug!(
            contacts = stats.contacts,
            penetration = stats.max_penetration,
            load_y = node_impulse.iter().map(|j| j[1]).sum::<f64>() / dt,
            "contact pass"
        );
        for (&id, j) in self.node_ids.iter().zip(&node_impulse) {
            if let Some(slot) = self.impulse.get_mut(id as usize) {
                *slot = *j;
            }
        }
        // The face behind a corrected particle, at the corrected positions, where the correction does not show it.
        let face = |k: usize| {
            if !self.faces {
                return None;
            }
            let (point, normal) = contact::nearest_face(&self.segments, &nx, *px.get(k)?)?;
            Some(ContactFace { point, normal })
        };
        let corrections = Corrections {
            fem: diff(&self.node_ids, (&fem.x, &fem.v), (&nx, &nv), |_| None),
            sph: diff(&sph.ids, (&sph.x, &sph.v), (&px, &pv), face),
        };
        Ok((corrections, stats))
    }
}

/// The particle–element parameters of `scene` for particle spacing `dx` and contact thickness r_c = `thickness`.
fn element_params(scene: &Scene, dx: f64, thickness: f64) -> contact::ContactParams {
    // Far-side limit r_c + Δx, but never more than r_c + half the thinnest solid: a particle resting r_c in front of
    // one face lies T + r_c behind the opposite face of a solid T thick, so d_max must stay below that or the
    // opposite face's segments take it for a particle through them and throw it across (the 5 mm gate at Δx ≥ 5 mm
    // did, at its first steps).
    let thinnest = scene
        .solids
        .iter()
        .map(|s| (s.max[0] - s.min[0]).min(s.max[1] - s.min[1]))
        .fold(f64::INFINITY, f64::min);
    contact::ContactParams {
        thickness,
        far_side: thickness + dx.min(0.5 * thinnest),
        sweeps: scene.contact.sweeps,
        move_masters: scene.contact.move_structure,
        ..contact::ContactParams::for_spacing(dx)
    }
}

/// The particle–particle parameters of `scene` for particle spacing `dx` and contact thickness r_c = `thickness`.
fn particle_params(scene: &Scene, dx: f64, thickness: f64) -> contact::ParticleParticleParams {
    // Monaghan (1994): D ≈ 5 g H with H the deepest water, r0 = Δx (DESIGN.md §4.6).
    let depth = scene.fluid.as_ref().map_or(0.0, |f| {
        f.blocks.iter().map(|b| b.max[1] - b.min[1]).fold(0.0, f64::max)
    });
    let g = scene.run.gravity[0].hypot(scene.run.gravity[1]);
    // Monaghan (1994) with r0 = r_c rather than Δx: the fluid's particles start Δx/2 from the structure's surface,
    // so with r0 = Δx every one of them would start deep inside the force range (a ∝ (r0/r)^12). Boundary points at
    // r0/2 so that no particle slips between two of them.
    contact::ParticleParticleParams {
        r0: thickness,
        spacing: 0.5 * thickness,
        ..contact::ParticleParticleParams::monaghan(dx, g, depth)
    }
}

/// Sparse (id, Δx, Δv) for every entry that changed, with `face(k)` of the k-th entry.
fn diff(
    ids: &[u32],
    before: (&[[f64; 2]], &[[f64; 2]]),
    after: (&[[f64; 2]], &[[f64; 2]]),
    face: impl Fn(usize) -> Option<ContactFace>,
) -> Vec<Correction> {
    let mut out = Vec::new();
    for (k, &id) in ids.iter().enumerate() {
        let dx = [after.0[k][0] - before.0[k][0], after.0[k][1] - before.0[k][1]];
        let dv = [after.1[k][0] - before.1[k][0], after.1[k][1] - before.1[k][1]];
        if dx != [0.0; 2] || dv != [0.0; 2] {
            out.push(Correction {
                id,
                dx,
                dv,
                face: face(k),
            });
        }
    }
    out
}

type Side<'a> = (&'a [f64], &'a [[f64; 2]], &'a [[f64; 2]], &'a [[f64; 2]]);

/// Change of total linear and angular momentum made by one pass, relative to the momentum it moved
/// (`DESIGN.md` §5 `contact_stats`): the particles' m Δv plus the impulse every node received (m Δv for a free
/// node, the support's reaction for a clamped one), moments taken at the corrected positions.
fn momentum_change(fluid: Side<'_>, node_x: &[[f64; 2]], node_impulse: &[[f64; 2]]) -> (f64, f64) {
    let (mut dp, mut dl, mut moved, mut moved_l) = ([0.0f64; 2], 0.0f64, 0.0f64, 0.0f64);
    let mut add = |x: [f64; 2], j: [f64; 2]| {
        dp[0] += j[0];
        dp[1] += j[1];
        let torque = x[0] * j[1] - x[1] * j[0];
        dl += torque;
        moved += j[0].hypot(j[1]);
        moved_l += torque.abs();
    };
    let (m, v0, x1, v1) = fluid;
    for i in 0..m.len() {
        add(x1[i], [m[i] * (v1[i][0] - v0[i][0]), m[i] * (v1[i][1] - v0[i][1])]);
    }
    for (x, j) in node_x.iter().zip(node_impulse) {
        add(*x, *j);
    }
    let rel = |d: f64, scale: f64| if scale > 0.0 { d / scale } else { 0.0 };
    (rel(dp[0].hypot(dp[1]), moved), rel(dl.abs(), moved_l))
}
