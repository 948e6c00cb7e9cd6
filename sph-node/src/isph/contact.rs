//! The fluid particles against a structure the fluid does not see (coupled runs, `DESIGN.md` §3 step 5, §4.5).
//!
//! In a coupled run the structure has no particles in the SPH node: the broker's particle–element contact moves
//! fluid particles out of the contact thickness r_c = Δx/2 and removes their approach velocity between steps. The
//! particles next to the structure therefore have a truncated kernel support, like a free surface: ∇·r of the first
//! layer of a lattice Δx/2 from a flat face is 1.28 (< 1.5). Left alone they are free-surface particles, p = 0, and
//! the PPE has a Dirichlet boundary p = 0 on the structure: the hydrostatic pressure cannot build up against it (a
//! single p = 0 particle in a Neumann boundary drains the pressure around it; on the hydrostatic plate the column's
//! pressure was 0 in most steps, with spikes of 150 kPa), and the load reaches the structure only as the contact
//! stops a falling fluid, in bursts.
//!
//! The solver recognises these particles by the corrections themselves ([`ContactLayer::detect`]): a particle whose
//! position or velocity changed between the end of one step and the start of the next was corrected by the contact,
//! along the face normal n (both corrections are along n), and now lies r_c in front of the face. It stays against
//! that face while it was corrected within [`STEPS_KEPT`] steps and lies within Δx of it (a loaded particle is
//! pressed into the structure every step by the pressure it carries, the symmetric pressure gradient of a truncated
//! support pointing into the missing side, so it is corrected nearly every step). Every fluid particle within 2h in
//! front of the face of a neighbour that is against one has its support cut by that face ([`contact_rows_into`]):
//! the first layer, including the particles the contact did not correct lately (no p = 0 hole), and the second row.
//!
//! For such a particle ([`ContactRow`]):
//! * ∇·r and the predicted density count the neighbours in front of the face plus the lattice half-space behind it
//!   ([`half_space`]), so a particle that is on a free surface as well (a water line on the structure, a drop
//!   hitting it) still gets p = 0, and the truncated sums do not read as an expansion (24 % in the first layer,
//!   1 % in the second, whose density term would otherwise be a sink as large as the gravity flux);
//! * the PPE row carries the Neumann condition ∂p/∂n = ρ0 g · n of the face (the structure's acceleration is left to
//!   the contact, as the walls' is, Adami et al. 2012 with a_w = 0): the row is written for p − ρ0 g · x, so the
//!   hydrostatic field solves it exactly (see [`super::ppe::fluid_row`]);
//! * in the first layer, the normal velocity the divergence sees is the face's, measured from the positions of the
//!   corrections and filtered by the face's travel ([`Face::velocity`], [`face_normal_velocity`]).

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use cosim_proto::messages::ContactFace;

use crate::kernel::CubicSpline;
use crate::neighbors::NeighborList;
use crate::particles::{separation, FluidState, ParticleView};

/// Steps a particle stays against the face its last correction revealed (while within Δx of it).
pub const STEPS_KEPT: u32 = 10;

/// Face travel, in Δx, over which the face velocity the fluid sees follows the measured one (see
/// [`Face::velocity`]).
pub const FACE_TRAVEL: f64 = 0.05;

/// A structure face seen from one particle: the points x with n · x = `offset`, n the unit normal into the fluid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Face {
    /// Unit normal into the fluid.
    pub normal: [f64; 2],
    /// n · x on the face.
    pub offset: f64,
    /// Normal velocity of the face (into the fluid) that the projection sees. Measured from the displacement of the
    /// face between two corrections of the particle (n · (q − q_old)/Δt, q = x − r_c n), not from the corrected
    /// velocity: that is the velocity of the structure's surface nodes at one instant, and on a stiff structure they
    /// ring after every contact impulse (the plate's top nodes take ~0.1 m/s from each particle pressed into them).
    /// Then filtered by the face's travel: each new measurement enters with the weight min(1, |travel| /
    /// ([`FACE_TRAVEL`] Δx)), so the fluid follows the structure at once when it moves by a resolvable fraction of
    /// the particle spacing (the elastic gate: its added mass) and sees the mean of a vibration far below it (the
    /// hydrostatic plate rings with 7e-5 m = 0.003 Δx). Seen at once, that vibration becomes a velocity condition one
    /// coupling step late on the whole water column, whose pressure (ρ H Δv/Δt) returns to the plate through the
    /// contact as a larger impulse: the explicit coupling's added-mass instability (ρ H / (ρ_s h_s) = 15), which
    /// threw the plate's column up within 20 ms. 0 until the face has been measured.
    pub velocity: f64,
}

impl Face {
    /// Signed distance of `x` in front of the face.
    #[inline]
    pub fn distance(&self, x: [f64; 2]) -> f64 {
        self.normal[0] * x[0] + self.normal[1] * x[1] - self.offset
    }
}

/// Lattice sums over the half-space behind a face at distance `d` in front of a particle: the points at
/// (i Δx, −d − (k + ½) Δx) from it, k ≥ 0 (the fluid lattice continued behind the face; for d = Δx/2, the first
/// layer of a lattice against the face, ∇·r 0.743 and Σ W Δx² 0.237 with h = 1.3 Δx). Returns (−Σ Δx² r dW/dr,
/// Σ Δx² W): the parts of ∇·r and of the Shepard sum the structure takes away.
pub fn half_space(kernel: &CubicSpline, dx: f64, d: f64) -> (f64, f64) {
    let reach = (kernel.support() / dx).ceil() as i64 + 1;
    let (mut div_r, mut w_sum) = (0.0, 0.0);
    for k in 0..=reach {
        let y = d + (k as f64 + 0.5) * dx;
        if y >= kernel.support() {
            break;
        }
        for i in -reach..=reach {
            let r = (i as f64 * dx).hypot(y);
            div_r -= dx * dx * r * kernel.dw_dr(r);
            w_sum += dx * dx * kernel.w(r);
        }
    }
    (div_r, w_sum)
}

/// A fluid particle against a structure face, at the predicted positions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactRow {
    /// The face.
    pub face: Face,
    /// Within Δx of the face (the first layer, which the contact holds r_c in front of it), not just within 2h.
    pub against: bool,
    /// ∇·r over the neighbours in front of the face and the half-space behind it.
    pub div_r: f64,
    /// Summation density over the particle, the neighbours in front of the face and the half-space behind it
    /// (ρ0 Δx² per lattice point).
    pub density: f64,
}

/// Which fluid particles the contact corrected lately, and the faces they revealed.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct ContactLayer {
    /// Positions at the end of the last step.
    x_end: Vec<[f64; 2]>,
    /// Velocities at the end of the last step.
    v_end: Vec<[f64; 2]>,
    /// Per particle: the face of its last correction.
    face: Vec<Face>,
    /// Per particle: the point of that face in front of which the particle was put (x − r_c n).
    point: Vec<[f64; 2]>,
    /// Per particle: the time of that correction.
    time: Vec<f64>,
    /// Per particle: the face velocity has been measured (two corrections against the same face).
    measured: Vec<bool>,
    /// Per particle: steps since the last correction (`u32::MAX`: none within [`STEPS_KEPT`]).
    age: Vec<u32>,
    /// Per particle: against its face at the start of the step.
    flags: Vec<bool>,
    /// Particles corrected before this step.
    corrected: usize,
    /// The faces the broker sent with the corrections before this step (`particle_particle`), by particle id,
    /// ascending: taken by the next [`ContactLayer::detect`] in place of the face a correction would reveal.
    /// Never held between two steps, so not in a checkpoint.
    #[serde(skip)]
    given: Vec<(usize, Face)>,
}

impl ContactLayer {
    /// Remembers the state at the end of a step (or at the start of the run).
    pub fn record_end(&mut self, state: &FluidState) {
        self.x_end.clear();
        self.x_end.extend_from_slice(&state.x);
        self.v_end.clear();
        self.v_end.extend_from_slice(&state.v);
    }

    /// Holds the structure's `faces` the broker sent with the corrections before this step, by particle id, for the
    /// next [`ContactLayer::detect`]. A `particle_particle` pass changes velocities only, by a force that acts
    /// within r_c of the structure's boundary points: where its correction leaves a particle says nothing of the
    /// face, and the face inferred from it (x − r_c n, with n the velocity change's direction) wandered with the
    /// particle; its travel, read as the face's velocity, drained the hydrostatic plate's pressure (docs/CORRECTIONS.md
    /// "ISPH + `particle_particle`"). A given face stands still in the PPE (velocity 0): the structure's motion
    /// reaches the fluid through the face's position, taken anew at each correction, and its momentum through the
    /// force.
    pub fn give(&mut self, faces: &[(usize, ContactFace)]) {
        self.given.clear();
        self.given.extend(faces.iter().map(|&(i, f)| {
            let offset = f.normal[0] * f.point[0] + f.normal[1] * f.point[1];
            let face = Face {
                normal: f.normal,
                offset,
                velocity: 0.0,
            };
            (i, face)
        }));
        // The broker sends them in id order; a stable sort keeps the first of an id sent twice first.
        self.given.sort_by_key(|&(i, _)| i);
    }

    /// Compares `state` with the end of the last step: a particle whose position or velocity changed in between was
    /// corrected, along the face normal, and lies r_c = Δx/2 in front of the face (`DESIGN.md` §4.5, r_c's default).
    /// It is against that face while it was corrected within [`STEPS_KEPT`] steps and lies within Δx of it.
    pub fn detect(&mut self, state: &FluidState, dx: f64) {
        let n = state.len();
        self.corrected = 0;
        if self.x_end.len() != n {
            return; // first step: nothing to compare with
        }
        if self.age.len() != n {
            // The per-particle records are made at the first correction: a run that is never corrected (no
            // structure) does not hold them. Before it every particle is as they would have recorded it: never
            // corrected, against no face.
            let changed = |i: usize| state.x[i] != self.x_end[i] || state.v[i] != self.v_end[i];
            if !(0..n).any(changed) {
                return;
            }
            self.face = vec![Face::default(); n];
            self.point = vec![[0.0; 2]; n];
            self.time = vec![0.0; n];
            self.measured = vec![false; n];
            self.age = vec![u32::MAX; n];
            self.flags = vec![false; n];
        }
        let r_c = 0.5 * dx;
        let mut corrected = 0;
        let given = std::mem::take(&mut self.given);
        let mut given_at = given.iter().peekable();
        for i in 0..n {
            let (x, v) = (state.x[i], state.v[i]);
            let d_x = [x[0] - self.x_end[i][0], x[1] - self.x_end[i][1]];
            let d_v = [v[0] - self.v_end[i][0], v[1] - self.v_end[i][1]];
            let dir = if d_x != [0.0; 2] { d_x } else { d_v };
            let len = dir[0].hypot(dir[1]);
            while given_at.next_if(|&&(j, _)| j < i).is_some() {}
            let given_face = given_at.next_if(|&&(j, _)| j == i).map(|&(_, f)| f);
            if let (Some(face), true) = (given_face, len > 0.0) {
                // The structure's face, as the broker sent it (see `give`).
                self.face[i] = face;
                let d = face.distance(x);
                self.point[i] = [x[0] - d * face.normal[0], x[1] - d * face.normal[1]];
                self.measured[i] = false;
                self.time[i] = state.t;
                self.age[i] = 0;
                corrected += 1;
            } else if len > 0.0 {
                let normal = [dir[0] / len, dir[1] / len];
                let point = [x[0] - r_c * normal[0], x[1] - r_c * normal[1]];
                // The face moved along n by n · (q − q_old) since the last correction of this particle against the
                // same face (normals within 25°, see `Face::velocity`).
                let old = self.face[i];
                let elapsed = state.t - self.time[i];
                let same = self.age[i] <= STEPS_KEPT
                    && elapsed > 0.0
                    && normal[0] * old.normal[0] + normal[1] * old.normal[1] > 0.9;
                let velocity = if same {
                    let q = self.point[i];
                    let travel = normal[0] * (point[0] - q[0]) + normal[1] * (point[1] - q[1]);
                    let measured = travel / elapsed;
                    if self.measured[i] {
                        let w = (travel.abs() / (FACE_TRAVEL * dx)).min(1.0);
                        old.velocity + w * (measured - old.velocity)
                    } else {
                        measured
                    }
                } else {
                    0.0
                };
                self.measured[i] = same;
                let offset = normal[0] * point[0] + normal[1] * point[1];
                self.face[i] = Face {
                    normal,
                    offset,
                    velocity,
                };
                self.point[i] = point;
                self.time[i] = state.t;
                self.age[i] = 0;
                corrected += 1;
            } else if self.age[i] < STEPS_KEPT {
                self.age[i] += 1;
            } else {
                self.age[i] = u32::MAX;
            }
            self.flags[i] = self.age[i] <= STEPS_KEPT && self.face[i].distance(x) <= dx;
        }
        self.corrected = corrected;
    }

    /// Check a layer read back from a checkpoint (see [`crate::restore`]) against the state it was saved with,
    /// between two steps: the end of the last step is that state, and the per-particle records are either not made
    /// yet or one per particle, with finite faces, points and times.
    pub(crate) fn check(&self, state: &FluidState) -> crate::restore::Check {
        use crate::restore::{finite, finite2, same_bits};
        same_bits("contact.x_end", &self.x_end, &state.x, "state.x")?;
        same_bits("contact.v_end", &self.v_end, &state.v, "state.v")?;
        let n = state.len();
        let records = [
            ("face", self.face.len()),
            ("point", self.point.len()),
            ("time", self.time.len()),
            ("measured", self.measured.len()),
            ("age", self.age.len()),
            ("flags", self.flags.len()),
        ];
        let m = self.age.len();
        if let Some((field, len)) = records.iter().find(|(_, len)| *len != m || !(m == 0 || m == n)) {
            return Err(format!(
                "contact.{field} holds {len} records (contact.age {m}), there are {n} fluid particles"
            ));
        }
        let faces: Vec<[f64; 2]> = self.face.iter().map(|f| f.normal).collect();
        finite2("contact.face.normal", &faces)?;
        let offsets: Vec<f64> = self.face.iter().map(|f| f.offset).collect();
        finite("contact.face.offset", &offsets)?;
        let velocities: Vec<f64> = self.face.iter().map(|f| f.velocity).collect();
        finite("contact.face.velocity", &velocities)?;
        finite2("contact.point", &self.point)?;
        finite("contact.time", &self.time)?;
        if self.corrected > n {
            return Err(format!(
                "contact.corrected = {}, there are {n} fluid particles",
                self.corrected
            ));
        }
        Ok(())
    }

    /// The face particle `i` was against at the start of the step.
    #[inline]
    pub fn face(&self, i: usize) -> Option<Face> {
        self.flags.get(i).copied().unwrap_or(false).then(|| self.face[i])
    }

    /// The face a particle at `x`, against none of its own, takes from its fluid `neighbors` (indices below `nf`):
    /// of those that are against a face that `cut` accepts, the one whose contact point (where it was put r_c in
    /// front of the face) is nearest to `x`, and only if the foot of `x` on that face lies within Δx of the point.
    /// A face stands for the structure near where it was measured: the plate's first layer takes the plane its
    /// neighbours are held against, but a particle of the jet passing the gate's tip does not take the plane of a
    /// neighbour corrected at the tip's corner, whose normal there is the corner's (taking the first neighbour's
    /// face, as before, the coupled ISPH gate gained 18.6 % of its energy budget, docs/CORRECTIONS.md "The coupled
    /// ISPH gate creates energy").
    fn inherited_face(
        &self,
        x: [f64; 2],
        neighbors: &[u32],
        nf: usize,
        dx: f64,
        cut: impl Fn(&Face) -> bool,
    ) -> Option<Face> {
        let mut nearest: Option<(f64, Face)> = None;
        for j in neighbors.iter().map(|&j| j as usize).filter(|&j| j < nf) {
            let Some(face) = self.face(j).filter(&cut) else {
                continue;
            };
            let q = self.point[j];
            let d2 = (x[0] - q[0]).powi(2) + (x[1] - q[1]).powi(2);
            if nearest.is_none_or(|(best, _)| d2 < best) {
                nearest = Some((d2, face));
            }
        }
        let (d2, face) = nearest?;
        let normal = face.distance(x);
        // The squared distance along the face from the foot of x to the point.
        (d2 - normal * normal <= dx * dx).then_some(face)
    }

    /// Whether any particle is against a face.
    pub fn any(&self) -> bool {
        self.flags.iter().any(|&f| f)
    }

    /// Number of particles corrected before this step.
    pub fn corrected(&self) -> usize {
        self.corrected
    }
}

/// The contact rows of the step at the predicted positions `view.x`, and the Dirichlet weights of their particles.
/// A particle's support is cut by a face when [`ContactLayer::face`] says it is against that face and it is still
/// within Δx of it, or when it lies within 2h in front of the face of a neighbour that is (the neighbour whose
/// contact point is nearest, if the particle's foot on its face is within Δx of that point,
/// [`ContactLayer::inherited_face`]; this includes the particles next to the structure that the contact did not
/// correct lately, and the second row, whose support the face still cuts: without it the hydrostatic field misses the second row's
/// truncated stencil, 12 % of the gravity flux, and the summation reads a 1 % expansion there). Its Dirichlet weight
/// (free surface or not) follows ∇·r in front of the face plus the half-space
/// ([`super::free_surface::dirichlet_weight`]). Distances below −Δx/4 (a particle the
/// predictor took into the structure) count as −Δx/4. `out` is left empty when no particle is against a face.
#[allow(clippy::too_many_arguments)]
pub fn contact_rows_into(
    view: &ParticleView<'_>,
    list: &NeighborList,
    kernel: &CubicSpline,
    layer: &ContactLayer,
    dx: f64,
    rho0: f64,
    threshold: f64,
    weight: &mut [f64],
    out: &mut Vec<Option<ContactRow>>,
) {
    out.clear();
    let nf = view.n_fluid;
    if !layer.any() {
        // Nothing in contact: no row at all (an uncoupled run does not hold a row per particle).
        return;
    }
    (0..nf)
        .into_par_iter()
        .map(|i| {
            let x = view.x[i];
            let own = |f: &Face| f.distance(x) <= dx;
            let cut = |f: &Face| (-0.25 * dx..kernel.support()).contains(&f.distance(x));
            let face = layer
                .face(i)
                .filter(own)
                .or_else(|| layer.inherited_face(x, list.of(i), nf, dx, cut))?;
            let d = face.distance(x).max(-0.25 * dx);
            let (mut div_r, mut w_sum) = half_space(kernel, dx, d);
            w_sum *= rho0;
            let mut density = view.m[i] * kernel.w(0.0) + w_sum;
            for &j in list.of(i) {
                let j = j as usize;
                if face.distance(view.x[j]) < 0.0 {
                    continue; // behind the face: the half-space stands for it
                }
                let (_, r) = separation(x, view.x[j]);
                div_r -= view.m[j] / view.rho[j] * r * kernel.dw_dr(r);
                density += view.m[j] * kernel.w(r);
            }
            Some(ContactRow {
                face,
                against: face.distance(x) <= dx,
                div_r,
                density,
            })
        })
        .collect_into_vec(out);
    for (w, row) in weight.iter_mut().zip(out.iter()) {
        if let Some(row) = row {
            *w = super::free_surface::dirichlet_weight(row.div_r, threshold);
        }
    }
}

/// The velocity the divergence of the PPE source sees for a particle against a face: its normal part is the face's
/// ([`Face::velocity`], plus Δt g, as walls carry it, see [`super::projection::velocity_divergence`]), its
/// tangential part the particle's own: u − ((u − Δt g) · n − v_face) n.
#[inline]
pub fn face_normal_velocity(u: [f64; 2], face: &Face, dt: f64, gravity: [f64; 2]) -> [f64; 2] {
    let n = face.normal;
    let un = (u[0] - dt * gravity[0]) * n[0] + (u[1] - dt * gravity[1]) * n[1] - face.velocity;
    [u[0] - un * n[0], u[1] - un * n[1]]
}

#[cfg(test)]
mod tests;
