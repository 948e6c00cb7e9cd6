//! Particle–element contact (Long et al. 2016 after Johnson & Stryk 2001; `DESIGN.md` §4.5): positions and normal
//! velocities of slave particles and master nodes are corrected so that no particle stays within the contact
//! thickness of the structure and no contact approaches, conserving linear and angular momentum.

use super::detection::{Detector, Hit, Master, Topology};
use super::geometry::{cross, dot, scale, sub, Vec2};
use super::grid::CellGrid;
use super::rigid::{position_step, velocity_step, HalfPlane};
use super::workspace::ContactWorkspace;
use super::{param, validate, ContactError, Nodes, Particles, Segment};

/// Exact steps per particle and sweep against immovable masters (one is the rule; more only in an
/// over-constrained pocket).
const RIGID_STEPS: usize = 16;

/// Parameters of the particle–element contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactParams {
    /// Contact thickness r_c [m]: particles are kept this far from the segments (`DESIGN.md` §4.5: Δx/2).
    pub thickness: f64,
    /// Far-side limit d_max [m]: a particle more than this far behind a segment is on the other side of the
    /// structure and ignored. Keep it below the thinnest part of the structure (plus r_c), or particles on one face
    /// are caught by the segments of the opposite face.
    pub far_side: f64,
    /// Maximum Gauss–Seidel sweeps of each phase (positions, velocities); the paper uses 2–3. Sweeps stop earlier
    /// once converged.
    pub sweeps: u32,
    /// Relative convergence tolerance: a phase stops when a sweep's largest correction is below
    /// `tolerance · thickness` (positions) or `tolerance ·` the first sweep's largest approach speed (velocities).
    /// Contacts within `tolerance · thickness` of touching after the position phase get the velocity correction
    /// (and those within 1e-12 · thickness plus 16 ulp of the coordinates, whatever the tolerance).
    pub tolerance: f64,
    /// Whether the position phase moves the master nodes too (x_a −= λ N_a/m_a n, `DESIGN.md` §4.5 as written).
    /// When false the masters are held in place for the position phase (the particle alone is projected, exactly,
    /// as against a rigid structure) and take their share of the velocity phase only: momentum is exchanged the
    /// same way, and no FE node is displaced by a share of the penetration that goes with 1/m instead of with the
    /// structure's stiffness.
    pub move_masters: bool,
}

impl Default for ContactParams {
    /// [`ContactParams::for_spacing`] of 0.01 m.
    fn default() -> Self {
        Self::for_spacing(0.01)
    }
}

impl ContactParams {
    /// The defaults for particle spacing `dx`: r_c = Δx/2, d_max = 2Δx, 3 sweeps, tolerance 1e-9, masters moved
    /// by the position phase (the paper's algorithm).
    pub fn for_spacing(dx: f64) -> Self {
        ContactParams {
            thickness: 0.5 * dx,
            far_side: 2.0 * dx,
            sweeps: 3,
            tolerance: 1e-9,
            move_masters: true,
        }
    }

    fn validate(&self) -> Result<(), ContactError> {
        param("thickness", self.thickness, self.thickness > 0.0, "positive and finite")?;
        param("far_side", self.far_side, self.far_side > 0.0, "positive and finite")?;
        param("sweeps", self.sweeps as f64, self.sweeps >= 1, "at least 1")?;
        param(
            "tolerance",
            self.tolerance,
            (0.0..1.0).contains(&self.tolerance),
            "in [0, 1)",
        )
    }
}

/// What one call of [`particle_element`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactReport {
    /// Particle–master pairs found penetrating (g < 0) in the first sweep.
    pub contacts: usize,
    /// Of these, node contacts (convex corners, ends of open chains).
    pub node_contacts: usize,
    /// Pairs touching after the position phase (gap within the touch tolerance, see [`ContactParams::tolerance`]):
    /// the velocity phase's contacts.
    pub touching: usize,
    /// Largest penetration −g found in the first sweep [m] (0 without contact).
    pub max_penetration: f64,
    /// Largest penetration left after the position phase [m] (0 against a rigid structure, up to round-off).
    pub residual_penetration: f64,
    /// Particles whose position or velocity was changed.
    pub particles_corrected: usize,
    /// Position sweeps run.
    pub position_sweeps: u32,
    /// Velocity sweeps run (0 when nothing touched).
    pub velocity_sweeps: u32,
    /// Velocity impulse received by each node [N·s/m]: m Δv for a free node, the reaction passed to the support for
    /// a fixed one. Interface load = impulse / Δt ([`ContactReport::interface_load`]).
    pub node_impulse: Vec<[f64; 2]>,
    /// Mass-weighted position change received by each node [kg·m/m]: m Δx for a free node, the reaction of the
    /// position correction for a fixed one. Together with the particles' m Δx it sums to zero.
    pub node_position_impulse: Vec<[f64; 2]>,
}

impl ContactReport {
    /// Interface load on each node [N/m]: nodal impulse / Δt (`DESIGN.md` §4.5).
    pub fn interface_load(&self, dt: f64) -> Vec<[f64; 2]> {
        self.node_impulse.iter().map(|i| [i[0] / dt, i[1] / dt]).collect()
    }
}

/// A contact of the velocity phase, its geometry frozen at the corrected positions.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Contact {
    s: usize,
    hit: Hit,
    rigid: bool,
}

/// Corrects particles and nodes in place (see the [module docs](super) for the algorithm) with a fresh workspace.
pub fn particle_element(
    particles: Particles<'_>,
    nodes: Nodes<'_>,
    segments: &[Segment],
    params: &ContactParams,
) -> Result<ContactReport, ContactError> {
    particle_element_with(&mut ContactWorkspace::default(), particles, nodes, segments, params)
}

/// [`particle_element`] reusing the scratch arrays of `ws`.
pub fn particle_element_with(
    ws: &mut ContactWorkspace,
    particles: Particles<'_>,
    nodes: Nodes<'_>,
    segments: &[Segment],
    params: &ContactParams,
) -> Result<ContactReport, ContactError> {
    params.validate()?;
    validate(&particles, &nodes, segments)?;
    let ContactWorkspace {
        grid,
        topo,
        inv_m,
        masters,
        rigid,
        touched,
        contacts,
        planes,
        plane_contacts,
        visits,
        exhaustive,
        ..
    } = ws;
    let (np, nn) = (particles.x.len(), nodes.x.len());
    let fixed = nodes.fixed;
    let mut report = ContactReport {
        node_impulse: vec![[0.0; 2]; nn],
        node_position_impulse: vec![[0.0; 2]; nn],
        ..ContactReport::default()
    };
    if np == 0 || segments.is_empty() {
        return Ok(report);
    }

    topo.build(nn, segments);
    inv_m.clear();
    inv_m.extend((0..nn).map(|k| if fixed[k] { 0.0 } else { 1.0 / nodes.m[k] }));
    touched.clear();
    touched.resize(np, false);
    visits.clear();
    visits.resize(np, Visit::default());

    // Segments are binned with their boxes inflated by twice the detection reach, so that a particle's candidate
    // list also covers the places an exact rigid projection may move it to.
    let (r_c, d_max) = (params.thickness, params.far_side);
    let inflate = 2.0 * r_c.max(d_max);
    let mean_len = segments.iter().map(|s| dist(nodes.x[s.a], nodes.x[s.b])).sum::<f64>() / segments.len() as f64;
    {
        let x = &*nodes.x;
        grid.build(segments.len(), inflate.max(mean_len), |j| {
            let (a, b) = (x[segments[j].a], x[segments[j].b]);
            let lo = [a[0].min(b[0]) - inflate, a[1].min(b[1]) - inflate];
            let hi = [a[0].max(b[0]) + inflate, a[1].max(b[1]) + inflate];
            (lo, hi)
        });
    }
    let coord = nodes.x.iter().fold(0.0f64, |c, x| c.max(x[0].abs()).max(x[1].abs()));
    // Convergence tolerance, and the round-off allowance of the exact rigid projection (16 ulp of the coordinates).
    let tol_x = params.tolerance * r_c;
    let tol_round = 1e-12 * r_c + 16.0 * f64::EPSILON * coord;
    // Contacts within this gap after the position phase get the velocity correction (never below round-off).
    let touch = tol_x.max(tol_round);
    let min_len = 1e-12 * r_c;
    let ctx = Ctx {
        segments,
        topo,
        r_c,
        d_max,
        min_len,
        reach: touch,
    };

    // ---- Position phase: Gauss–Seidel sweeps (DESIGN.md §4.5 "Position"). ----
    // Masters held in place (`move_masters` off) are immovable here: the exact rigid projection below.
    let held;
    let pos_fixed: &[bool] = if params.move_masters {
        fixed
    } else {
        held = vec![true; nn];
        &held
    };
    // Every master immovable in this phase (masters held, or all nodes fixed): the nodes do not move, so a visit
    // depends on nothing but the particle's own position. A particle that a visit left where it was is then
    // skipped by the later sweeps, and one that also touched nothing in the first sweep by the touch test below:
    // they would repeat the same detection on the same inputs and find the same nothing (bit-identical result).
    let nodes_static = !*exhaustive && pos_fixed.iter().all(|&f| f);
    for sweep in 0..params.sweeps {
        let mut worst = 0.0f64;
        #[allow(clippy::needless_range_loop)] // s indexes x, m and touched together
        for s in 0..np {
            if nodes_static && sweep > 0 && visits[s].still {
                continue;
            }
            gather(grid, topo, segments, nodes.x, particles.x[s], inflate, masters);
            visits[s].still = true;
            if sweep == 0 {
                visits[s].clear = true;
            }
            if masters.is_empty() {
                continue;
            }
            rigid.clear();
            let im_s = 1.0 / particles.m[s];
            for &m in masters.iter() {
                if ctx.detector(nodes.x).is_rigid(m, pos_fixed) {
                    rigid.push(m);
                    continue;
                }
                let Some(h) = ctx.detector(nodes.x).detect(m, particles.x[s]) else {
                    continue;
                };
                if h.g >= 0.0 {
                    continue;
                }
                worst = worst.max(-h.g);
                if sweep == 0 {
                    note_contact(&mut report, m, h.g);
                }
                // DESIGN.md §4.5: w = 1/m_s + N1²/m1 + N2²/m2 (a fixed node adds 0), λ = −g/w.
                let w = im_s + h.na * h.na * inv_m[h.a] + h.nb * h.nb * inv_m[h.b];
                let lam = -h.g / w;
                // x_s += (λ/m_s) n; x1 −= (λ N1/m1) n; x2 −= (λ N2/m2) n.
                particles.x[s] = axpy(particles.x[s], lam * im_s, h.n);
                for (k, nk) in [(h.a, h.na), (h.b, h.nb)] {
                    if !pos_fixed[k] && nk != 0.0 {
                        nodes.x[k] = axpy(nodes.x[k], -lam * nk * inv_m[k], h.n);
                    }
                    report.node_position_impulse[k] = axpy(report.node_position_impulse[k], -lam * nk, h.n);
                }
                touched[s] = true;
            }
            // Immovable masters: the exact limit of the sweeps, per particle (rigid.rs).
            for step in 0..RIGID_STEPS {
                if rigid.is_empty() {
                    break;
                }
                let d = ctx.detector(nodes.x);
                let x0 = particles.x[s];
                let mut penetrated = false;
                for &m in rigid.iter() {
                    let Some(h) = d.detect(m, x0) else {
                        continue;
                    };
                    if sweep == 0 && step == 0 && h.g <= touch {
                        visits[s].clear = false;
                    }
                    if h.g < 0.0 {
                        penetrated = true;
                        worst = worst.max(-h.g);
                        if sweep == 0 && step == 0 {
                            note_contact(&mut report, m, h.g);
                        }
                    }
                }
                // position_step would find the same (no penetration at x0) and return None.
                if !penetrated {
                    break;
                }
                visits[s].still = false;
                let Some(st) = position_step(&d, rigid, x0, tol_round) else {
                    break;
                };
                // The particle's change m_s Δx is balanced by reactions −m_s μ_j N_a n_j on the fixed nodes.
                let delta = sub(st.x, x0);
                let m_s = particles.m[s];
                for (h, mu) in split(&d, rigid, st.by, st.x, delta) {
                    for (k, nk) in [(h.a, h.na), (h.b, h.nb)] {
                        report.node_position_impulse[k] = axpy(report.node_position_impulse[k], -m_s * mu * nk, h.n);
                    }
                }
                particles.x[s] = st.x;
                touched[s] = true;
            }
        }
        report.position_sweeps += 1;
        if worst <= tol_x {
            break;
        }
    }

    // ---- Contacts after the position phase, geometry frozen at the corrected positions. ----
    contacts.clear();
    for s in 0..np {
        // Never moved, and the first sweep's detection at this very position found no gap within `touch`.
        if nodes_static && !touched[s] && visits[s].clear {
            continue;
        }
        gather(grid, topo, segments, nodes.x, particles.x[s], inflate, masters);
        let d = ctx.detector(nodes.x);
        for &m in masters.iter() {
            if let Some(hit) = d.detect(m, particles.x[s]).filter(|h| h.g <= touch) {
                report.residual_penetration = report.residual_penetration.max(-hit.g);
                contacts.push(Contact {
                    s,
                    hit,
                    rigid: d.is_rigid(m, fixed),
                });
            }
        }
    }
    report.touching = contacts.len();

    // ---- Velocity phase: Gauss–Seidel sweeps (DESIGN.md §4.5 "Normal velocity"). ----
    let mut v_scale = 0.0;
    for sweep in 0..if contacts.is_empty() { 0 } else { params.sweeps } {
        let mut worst = 0.0f64;
        let mut i = 0;
        while i < contacts.len() {
            let s = contacts[i].s;
            let end = i + contacts[i..].iter().take_while(|c| c.s == s).count();
            let (m_s, im_s) = (particles.m[s], 1.0 / particles.m[s]);
            planes.clear();
            plane_contacts.clear();
            for (ci, c) in contacts[i..end].iter().enumerate() {
                let h = c.hit;
                if c.rigid {
                    // n·v_s ≥ n·u with u = N1 v1 + N2 v2 the (prescribed) master velocity.
                    let u = axpy(scale(nodes.v[h.a], h.na), h.nb, nodes.v[h.b]);
                    planes.push(HalfPlane { n: h.n, c: dot(h.n, u) });
                    plane_contacts.push(i + ci);
                    continue;
                }
                // v_rel = (v_s − N1 v1 − N2 v2)·n; only approaching contacts are corrected.
                let u = axpy(scale(nodes.v[h.a], h.na), h.nb, nodes.v[h.b]);
                let v_rel = dot(sub(particles.v[s], u), h.n);
                if v_rel >= 0.0 {
                    continue;
                }
                worst = worst.max(-v_rel);
                // J = −v_rel/w; v_s += (J/m_s) n; v1 −= (J N1/m1) n; v2 −= (J N2/m2) n.
                let w = im_s + h.na * h.na * inv_m[h.a] + h.nb * h.nb * inv_m[h.b];
                let j = -v_rel / w;
                particles.v[s] = axpy(particles.v[s], j * im_s, h.n);
                for (k, nk) in [(h.a, h.na), (h.b, h.nb)] {
                    if !fixed[k] && nk != 0.0 {
                        nodes.v[k] = axpy(nodes.v[k], -j * nk * inv_m[k], h.n);
                    }
                    report.node_impulse[k] = axpy(report.node_impulse[k], -j * nk, h.n);
                }
                touched[s] = true;
            }
            // Immovable masters: exact per particle (rigid.rs).
            for _ in 0..if planes.is_empty() { 0 } else { RIGID_STEPS } {
                let v0 = particles.v[s];
                let approach = planes.iter().fold(0.0f64, |a, p| a.max(p.c - dot(p.n, v0)));
                worst = worst.max(approach);
                let big = planes
                    .iter()
                    .fold(v0[0].abs().max(v0[1].abs()), |a, p| a.max(p.c.abs()));
                let Some(st) = velocity_step(planes, v0, 1e-12 * big) else {
                    break;
                };
                for (pi, mu) in st.by.into_iter().flatten() {
                    let h = contacts[plane_contacts[pi]].hit;
                    for (k, nk) in [(h.a, h.na), (h.b, h.nb)] {
                        report.node_impulse[k] = axpy(report.node_impulse[k], -m_s * mu * nk, h.n);
                    }
                }
                particles.v[s] = st.v;
                touched[s] = true;
            }
            i = end;
        }
        if sweep == 0 {
            v_scale = worst;
        }
        report.velocity_sweeps += 1;
        if worst <= params.tolerance * v_scale {
            break;
        }
    }

    report.particles_corrected = touched.iter().filter(|&&t| t).count();
    Ok(report)
}

/// What the position phase learnt about one particle, for the skips that hold while the nodes are static.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Visit {
    /// Its last visit left it where it was (no master penetrated at its position).
    still: bool,
    /// Its first-sweep visit found no master within the touch gap at its position.
    clear: bool,
}

/// What a [`Detector`] needs besides the node positions, which change during the position phase.
struct Ctx<'a> {
    segments: &'a [Segment],
    topo: &'a Topology,
    r_c: f64,
    d_max: f64,
    min_len: f64,
    /// The touch gap: no caller of `detect` here acts on a larger gap.
    reach: f64,
}

impl Ctx<'_> {
    fn detector<'b>(&'b self, x: &'b [Vec2]) -> Detector<'b> {
        Detector {
            x,
            segments: self.segments,
            topo: self.topo,
            thickness: self.r_c,
            far_side: self.d_max,
            min_len: self.min_len,
            reach: self.reach,
        }
    }
}

/// The masters near `xs`, in a fixed order: those of the segments in its grid cell whose box, inflated by
/// `inflate`, holds `xs` (a node master lies within its owning segment's box).
fn gather(
    grid: &CellGrid,
    topo: &Topology,
    segments: &[Segment],
    x: &[Vec2],
    xs: Vec2,
    inflate: f64,
    out: &mut Vec<Master>,
) {
    out.clear();
    for &j in grid.query(xs) {
        let s = segments[j as usize];
        let (a, b) = (x[s.a], x[s.b]);
        let outside = |k: usize| xs[k] < a[k].min(b[k]) - inflate || xs[k] > a[k].max(b[k]) + inflate;
        if !(outside(0) || outside(1)) {
            topo.masters_near(j as usize, s, out);
        }
    }
}

fn note_contact(report: &mut ContactReport, m: Master, g: f64) {
    report.contacts += 1;
    if matches!(m, Master::Node(_)) {
        report.node_contacts += 1;
    }
    report.max_penetration = report.max_penetration.max(-g);
}

/// Splits a particle's change `delta` at position `at` along the normals of the (one or two) masters that define
/// it: delta = Σ μ_j n_j, each with its contact geometry (N_a at `at`, unclamped, so x_s − x_c ∥ n_j holds).
fn split(
    d: &Detector,
    masters: &[Master],
    by: [Option<usize>; 2],
    at: Vec2,
    delta: Vec2,
) -> impl Iterator<Item = (Hit, f64)> {
    let hits = by.map(|i| i.and_then(|i| d.attach(masters[i], at)).map(|(h, _)| h));
    let mus = match hits {
        [Some(h1), Some(h2)] if cross(h1.n, h2.n).abs() > 1e-12 => {
            let det = cross(h1.n, h2.n);
            [cross(delta, h2.n) / det, cross(h1.n, delta) / det]
        }
        [Some(h1), _] => [dot(delta, h1.n), 0.0],
        _ => [0.0, 0.0],
    };
    let keep = [hits[0], if mus[1] != 0.0 { hits[1] } else { None }];
    keep.into_iter().zip(mus).filter_map(|(h, mu)| h.map(|h| (h, mu)))
}

#[inline]
fn axpy(y: Vec2, a: f64, x: Vec2) -> Vec2 {
    [y[0] + a * x[0], y[1] + a * x[1]]
}

#[inline]
fn dist(a: Vec2, b: Vec2) -> f64 {
    let d = sub(a, b);
    d[0].hypot(d[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One particle under the middle of a free horizontal segment (structure above, fluid below).
    #[test]
    fn single_contact_matches_the_formulas() {
        let mut px = [[0.25, -0.03]];
        let mut pv = [[0.4, 2.0]];
        let pm = [1.0];
        let mut nx = [[0.0, 0.0], [1.0, 0.0]];
        let mut nv = [[0.0, 0.0], [0.0, -1.0]];
        let (nm, fixed) = ([2.0, 4.0], [false, false]);
        let segs = [Segment { a: 0, b: 1 }];
        let params = ContactParams {
            thickness: 0.05,
            far_side: 0.2,
            sweeps: 1,
            tolerance: 0.0,
            move_masters: true,
        };
        let p = Particles {
            x: &mut px,
            v: &mut pv,
            m: &pm,
        };
        let n = Nodes {
            x: &mut nx,
            v: &mut nv,
            m: &nm,
            fixed: &fixed,
        };
        let r = particle_element(p, n, &segs, &params).unwrap();
        // ξ = 0.25, n = (0, −1), g = 0.03 − 0.05 = −0.02, w = 1 + 0.75²/2 + 0.25²/4 = 1.296875, λ = 0.02/w.
        let w = 1.0 + 0.5625 / 2.0 + 0.0625 / 4.0;
        let lam = 0.02 / w;
        assert_eq!(r.contacts, 1);
        assert!((r.max_penetration - 0.02).abs() < 1e-15);
        assert!((px[0][1] - (-0.03 - lam)).abs() < 1e-15);
        assert!((nx[0][1] - lam * 0.75 / 2.0).abs() < 1e-15 && (nx[1][1] - lam * 0.25 / 4.0).abs() < 1e-15);
        // Velocity phase at the corrected positions: the nodes moved by different amounts, so the segment turned
        // slightly (n' ≈ (0, −1)). v_rel = (2 − 0.25·(−1))·(−1) = −2.25 < 0: J ≈ 2.25/w.
        let d = [nx[1][0] - nx[0][0], nx[1][1] - nx[0][1]];
        let l = d[0].hypot(d[1]);
        let n1 = [d[1] / l, -d[0] / l];
        let xi = ((px[0][0] - nx[0][0]) * d[0] + (px[0][1] - nx[0][1]) * d[1]) / (l * l);
        let dv = [pv[0][0] - 0.4, pv[0][1] - 2.0];
        let j = dv[0] * n1[0] + dv[1] * n1[1];
        // J = −v_rel/w evaluated at the corrected geometry (ξ', n') with the velocities before.
        let w1 = 1.0 + (1.0 - xi) * (1.0 - xi) / 2.0 + xi * xi / 4.0;
        // u = N1 v1 + N2 v2 = (0, −ξ) with v1 = 0, v2 = (0, −1).
        let v_rel0 = 0.4 * n1[0] + (2.0 + xi) * n1[1];
        assert!((j - (-v_rel0 / w1)).abs() < 1e-14, "J = {j}, expected {}", -v_rel0 / w1);
        assert!((j - 2.25 / w).abs() < 2e-3 * j, "close to the undeformed value");
        assert!(cross(dv, n1).abs() < 1e-15, "tangential velocity untouched: Δv ∥ n'");
        let u = [
            (1.0 - xi) * nv[0][0] + xi * nv[1][0],
            (1.0 - xi) * nv[0][1] + xi * nv[1][1],
        ];
        let v_rel = (pv[0][0] - u[0]) * n1[0] + (pv[0][1] - u[1]) * n1[1];
        assert!(v_rel.abs() < 1e-14, "contact no longer approaches: {v_rel:e}");
        // Momentum: the particle's change is the nodes' impulse, reversed; free nodes: impulse = m Δv.
        for k in 0..2 {
            let nodes_dp = r.node_impulse[0][k] + r.node_impulse[1][k];
            assert!((pm[0] * dv[k] + nodes_dp).abs() < 1e-15);
            assert!((r.node_impulse[0][k] - nm[0] * (nv[0][k] - [0.0, 0.0][k])).abs() < 1e-15);
            assert!((r.node_impulse[1][k] - nm[1] * (nv[1][k] - [0.0, -1.0][k])).abs() < 1e-15);
        }
        let load = r.interface_load(0.5);
        assert!((load[1][1] - 2.0 * r.node_impulse[1][1]).abs() < 1e-15);
    }

    #[test]
    fn separating_contact_keeps_its_velocity() {
        let mut px = [[0.5, -0.01]];
        let mut pv = [[0.0, -3.0]];
        let mut nx = [[0.0, 0.0], [1.0, 0.0]];
        let mut nv = [[0.0; 2]; 2];
        let segs = [Segment { a: 0, b: 1 }];
        let p = Particles {
            x: &mut px,
            v: &mut pv,
            m: &[1.0],
        };
        let n = Nodes {
            x: &mut nx,
            v: &mut nv,
            m: &[1.0, 1.0],
            fixed: &[true, true],
        };
        let r = particle_element(p, n, &segs, &ContactParams::for_spacing(0.1)).unwrap();
        assert_eq!(pv[0], [0.0, -3.0]);
        assert!((px[0][1] + 0.05).abs() < 1e-15);
        assert_eq!(r.node_impulse, vec![[0.0; 2]; 2]);
        assert_eq!(nx, [[0.0, 0.0], [1.0, 0.0]]);
    }

    #[test]
    fn bad_input_is_an_error_and_nothing_moves() {
        let mut px = [[0.5, -0.01]];
        let mut pv = [[0.0, 1.0]];
        let mut nx = [[0.0, 0.0], [1.0, 0.0]];
        let mut nv = [[0.0; 2]; 2];
        let mut run = |segs: &[Segment], params: &ContactParams| {
            let p = Particles {
                x: &mut px,
                v: &mut pv,
                m: &[1.0],
            };
            let n = Nodes {
                x: &mut nx,
                v: &mut nv,
                m: &[0.0, 1.0],
                fixed: &[false, false],
            };
            particle_element(p, n, segs, params).unwrap_err()
        };
        let params = ContactParams::for_spacing(0.1);
        let e = run(&[Segment { a: 0, b: 1 }], &params);
        assert_eq!(e.to_string(), "node 0: m is 0, it must be finite and positive");
        let e = run(&[Segment { a: 0, b: 2 }], &params);
        assert!(matches!(e, ContactError::Segment { segment: 0, .. }));
        let e = run(&[], &ContactParams { sweeps: 0, ..params });
        assert_eq!(e.to_string(), "contact parameter `sweeps` is 0: it must be at least 1");
        assert_eq!((px, pv), ([[0.5, -0.01]], [[0.0, 1.0]]));
    }

    /// A closed polygon through `corners` with its edges cut into pieces of about `dx`: nodes and segments.
    fn polygon(corners: &[Vec2], dx: f64) -> (Vec<Vec2>, Vec<Segment>) {
        let mut x = Vec::new();
        for (i, &a) in corners.iter().enumerate() {
            let b = corners[(i + 1) % corners.len()];
            let n = ((dist(a, b) / dx).round() as usize).max(1);
            x.extend((0..n).map(|k| axpy(a, k as f64 / n as f64, sub(b, a))));
        }
        let s = (0..x.len())
            .map(|i| Segment {
                a: i,
                b: (i + 1) % x.len(),
            })
            .collect();
        (x, s)
    }

    fn bits(v: &[Vec2]) -> Vec<[u64; 2]> {
        v.iter().map(|p| [p[0].to_bits(), p[1].to_bits()]).collect()
    }

    proptest::proptest! {
        /// The skips taken while the nodes are static (masters held, or all fixed) change no bit of the result.
        #[test]
        fn static_node_skips_are_exact(
            shape in 0usize..3,
            held in proptest::bool::ANY,
            sweeps in 1u32..4,
            offsets in proptest::collection::vec(([0.0f64..1.0, -2.5f64..2.5], [-1.0f64..1.0, -1.0f64..1.0]), 20..400),
        ) {
            let dx = 0.01;
            let corners: Vec<Vec2> = match shape {
                // A plate (convex, fluid outside), an L (one concave corner), a tank (clockwise: fluid inside).
                0 => vec![[0.0, 0.0], [0.05, 0.0], [0.05, 0.3], [0.0, 0.3]],
                1 => vec![[0.0, 0.0], [0.2, 0.0], [0.2, 0.05], [0.05, 0.05], [0.05, 0.2], [0.0, 0.2]],
                _ => vec![[0.0, 0.0], [0.0, 0.2], [0.3, 0.2], [0.3, 0.0]],
            };
            let (nx, segs) = polygon(&corners, dx);
            let nn = nx.len();
            // Particles around the boundary: a point along it, then an offset along the normal in [−2.5, 2.5] Δx.
            let (mut px, mut pv) = (Vec::new(), Vec::new());
            for &([along, off], v) in &offsets {
                let j = ((along * segs.len() as f64) as usize).min(segs.len() - 1);
                let (a, b) = (nx[segs[j].a], nx[segs[j].b]);
                let f = crate::contact::geometry::Frame::new(a, b, 0.0).unwrap();
                let t = along * segs.len() as f64 - j as f64;
                px.push(axpy(f.point(1.0 - t, t), off * dx, f.n));
                pv.push(v);
            }
            let pm = vec![0.1; px.len()];
            let nm: Vec<f64> = (0..nn).map(|k| 0.5 + (k % 3) as f64).collect();
            let fixed: Vec<bool> = (0..nn).map(|k| !held || k % 4 != 0).collect();
            let fixed = if held { fixed } else { vec![true; nn] };
            let nv: Vec<Vec2> = (0..nn).map(|k| [0.01 * (k % 5) as f64, -0.02]).collect();
            let params = ContactParams {
                sweeps,
                move_masters: !held,
                ..ContactParams::for_spacing(dx)
            };
            let run = |exhaustive: bool| {
                let (mut px, mut pv, mut nx, mut nv) = (px.clone(), pv.clone(), nx.clone(), nv.clone());
                let mut ws = ContactWorkspace { exhaustive, ..ContactWorkspace::default() };
                let p = Particles { x: &mut px, v: &mut pv, m: &pm };
                let n = Nodes { x: &mut nx, v: &mut nv, m: &nm, fixed: &fixed };
                let r = particle_element_with(&mut ws, p, n, &segs, &params).unwrap();
                (bits(&px), bits(&pv), bits(&nx), bits(&nv), bits(&r.node_impulse), bits(&r.node_position_impulse), r)
            };
            let (fast, full) = (run(false), run(true));
            proptest::prop_assume!(full.6.contacts > 0, "no particle penetrates");
            proptest::prop_assert_eq!(&fast.0, &full.0);
            proptest::prop_assert_eq!(&fast.1, &full.1);
            proptest::prop_assert_eq!(&fast.2, &full.2);
            proptest::prop_assert_eq!(&fast.3, &full.3);
            proptest::prop_assert_eq!(&fast.4, &full.4);
            proptest::prop_assert_eq!(&fast.5, &full.5);
            let strip = |r: &ContactReport| (r.contacts, r.node_contacts, r.touching, r.particles_corrected,
                r.position_sweeps, r.velocity_sweeps, r.max_penetration.to_bits(), r.residual_penetration.to_bits());
            proptest::prop_assert_eq!(strip(&fast.6), strip(&full.6));
        }
    }
}
