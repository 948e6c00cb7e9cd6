//! Particle–particle contact, the paper's baseline (`DESIGN.md` §4.6): structure boundary nodes, plus extra points
//! along each segment at spacing ≤ Δx, act as boundary particles that repel fluid particles with Monaghan's (1994)
//! Lennard-Jones force. Each reaction goes to the structure, spread on the segment's nodes with N1, N2, so linear
//! and angular momentum are conserved.

use super::algorithm::{ContactAlgorithm, PassReport};
use super::bodies::{validate, Nodes, Particles, Segment};
use super::error::{param, ContactError};
use super::geometry::{dot, sub, Vec2};
use super::grid::CellGrid;

/// Parameters of the particle–particle contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParticleParticleParams {
    /// Largest spacing of the boundary points along a segment [m] (Δx).
    pub spacing: f64,
    /// Strength D [m²/s²], ≈ 5 g H (H the water depth).
    pub strength: f64,
    /// Cut-off distance r0 [m] (Δx): no force at r ≥ r0.
    pub r0: f64,
    /// Repulsive exponent p1 (12).
    pub p1: i32,
    /// Attractive exponent p2 (4), below p1 so that the force repels for every r < r0.
    pub p2: i32,
}

impl Default for ParticleParticleParams {
    /// [`ParticleParticleParams::monaghan`] for Δx = 0.01 m, g = 9.81 m/s², H = 1 m.
    fn default() -> Self {
        Self::monaghan(0.01, 9.81, 1.0)
    }
}

impl ParticleParticleParams {
    /// Monaghan's (1994) choice for spacing `dx`, gravity `g` [m/s²] and depth `h` [m]: D = 5gH, r0 = Δx, p1 = 12,
    /// p2 = 4 (`DESIGN.md` §4.6).
    pub fn monaghan(dx: f64, g: f64, h: f64) -> Self {
        ParticleParticleParams {
            spacing: dx,
            strength: 5.0 * g * h,
            r0: dx,
            p1: 12,
            p2: 4,
        }
    }

    fn validate(&self) -> Result<(), ContactError> {
        param("spacing", self.spacing, self.spacing > 0.0, "positive and finite")?;
        param(
            "strength",
            self.strength,
            self.strength >= 0.0,
            "non-negative and finite",
        )?;
        param("r0", self.r0, self.r0 > 0.0, "positive and finite")?;
        param("p2", self.p2 as f64, self.p2 >= 1, "at least 1")?;
        param("p1", self.p1 as f64, self.p1 > self.p2, "greater than p2")
    }
}

/// What one call of [`particle_particle`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParticleParticleReport {
    /// Particle–boundary point pairs closer than r0.
    pub contacts: usize,
    /// Deepest reach into the force range, max(r0 − r) over the pairs [m] (0 without pairs).
    pub max_penetration: f64,
    /// Boundary points used (nodes plus extra points along the segments).
    pub boundary_points: usize,
    /// Particles whose velocity was changed.
    pub particles_corrected: usize,
    /// Smallest particle–boundary point distance among the pairs [m] (r0 without pairs).
    pub min_distance: f64,
    /// Impulse received by each node [N·s/m]: m Δv for a free node, the reaction passed to the support for a fixed
    /// one. Interface load = impulse / Δt.
    pub node_impulse: Vec<[f64; 2]>,
}

/// A boundary particle: the point N_a x_a + N_b x_b of a segment (a node: a = b, N_a = 1, N_b = 0).
#[derive(Clone, Copy, Debug)]
struct BoundaryPoint {
    x: Vec2,
    a: usize,
    b: usize,
    na: f64,
    nb: f64,
}

/// Scratch arrays of [`particle_particle_with`]: keep one per caller and pass it to every call so the arrays are
/// allocated once. Holds no state between calls: results never depend on what it held before. Not serialisable, by
/// design.
#[derive(Clone, Debug, Default)]
pub struct ParticleParticleWorkspace {
    /// The boundary points binned in cells.
    grid: CellGrid,
    /// The boundary points: the nodes used by a segment, then the points along each segment.
    points: Vec<BoundaryPoint>,
    /// Per node: used by a segment.
    touched: Vec<bool>,
}

/// Applies Δt times the repulsive acceleration to the particles' velocities and the reactions to the nodes (free
/// nodes' velocities change by impulse/m; fixed ones only report it). Positions are not changed.
pub fn particle_particle(
    particles: Particles<'_>,
    nodes: Nodes<'_>,
    segments: &[Segment],
    params: &ParticleParticleParams,
    dt: f64,
) -> Result<ParticleParticleReport, ContactError> {
    particle_particle_with(
        &mut ParticleParticleWorkspace::default(),
        particles,
        nodes,
        segments,
        params,
        dt,
    )
}

/// [`particle_particle`] reusing the scratch arrays of `ws`.
pub fn particle_particle_with(
    ws: &mut ParticleParticleWorkspace,
    particles: Particles<'_>,
    nodes: Nodes<'_>,
    segments: &[Segment],
    params: &ParticleParticleParams,
    dt: f64,
) -> Result<ParticleParticleReport, ContactError> {
    params.validate()?;
    param("dt", dt, dt >= 0.0, "non-negative and finite")?;
    validate(&particles, &nodes, segments)?;
    let ParticleParticleWorkspace { grid, points, touched } = ws;
    let nn = nodes.x.len();
    let mut report = ParticleParticleReport {
        node_impulse: vec![[0.0; 2]; nn],
        min_distance: params.r0,
        ..ParticleParticleReport::default()
    };

    // Boundary points: every node used by a segment once (index order), then each segment's interior points at
    // ξ = i/k, k = ceil(L/Δx), so their spacing is ≤ Δx (DESIGN.md §4.6).
    points.clear();
    touched.clear();
    touched.resize(nn, false);
    for s in segments {
        touched[s.a] = true;
        touched[s.b] = true;
    }
    for k in (0..nn).filter(|&k| touched[k]) {
        points.push(BoundaryPoint {
            x: nodes.x[k],
            a: k,
            b: k,
            na: 1.0,
            nb: 0.0,
        });
    }
    for s in segments {
        let (xa, xb) = (nodes.x[s.a], nodes.x[s.b]);
        let d = sub(xb, xa);
        let pieces = (d[0].hypot(d[1]) / params.spacing).ceil().max(1.0) as usize;
        for i in 1..pieces {
            let (na, nb) = (1.0 - i as f64 / pieces as f64, i as f64 / pieces as f64);
            let x = [na * xa[0] + nb * xb[0], na * xa[1] + nb * xb[1]];
            points.push(BoundaryPoint {
                x,
                a: s.a,
                b: s.b,
                na,
                nb,
            });
        }
    }
    report.boundary_points = points.len();
    let r0 = params.r0;
    {
        let pts = &*points;
        grid.build(pts.len(), 2.0 * r0, |i| {
            let x = pts[i].x;
            ([x[0] - r0, x[1] - r0], [x[0] + r0, x[1] + r0])
        });
    }

    for s in 0..particles.x.len() {
        let xs = particles.x[s];
        let mut acc = [0.0; 2];
        let mut any = false;
        let m_dt = particles.m[s] * dt;
        for &i in grid.query(xs) {
            let p = points[i as usize];
            let r = sub(xs, p.x);
            let r2 = dot(r, r);
            if !(r2 < r0 * r0 && r2 > 0.0) {
                continue;
            }
            let dist = r2.sqrt();
            let q = r0 / dist;
            // a_i = D[(r0/r)^p1 − (r0/r)^p2] r_ij/r² (Monaghan 1994; DESIGN.md §4.6): along r_ij, away from the
            // boundary point, since (r0/r)^p1 > (r0/r)^p2 for r < r0.
            let f = params.strength * (q.powi(params.p1) - q.powi(params.p2)) / r2;
            let a = [f * r[0], f * r[1]];
            acc = [acc[0] + a[0], acc[1] + a[1]];
            any = true;
            report.contacts += 1;
            report.max_penetration = report.max_penetration.max(r0 - dist);
            report.min_distance = report.min_distance.min(dist);
            // Reaction −m_i Δt a_i on the structure, spread with N1, N2 (zero moment: it acts at the point, along r).
            for (k, nk) in [(p.a, p.na), (p.b, p.nb)] {
                let imp = &mut report.node_impulse[k];
                *imp = [imp[0] - m_dt * nk * a[0], imp[1] - m_dt * nk * a[1]];
            }
        }
        if any {
            let v = &mut particles.v[s];
            *v = [v[0] + dt * acc[0], v[1] + dt * acc[1]];
            report.particles_corrected += 1;
        }
    }
    for k in 0..nn {
        let imp = report.node_impulse[k];
        if !nodes.fixed[k] && (imp[0] != 0.0 || imp[1] != 0.0) {
            let v = &mut nodes.v[k];
            *v = [v[0] + imp[0] / nodes.m[k], v[1] + imp[1] / nodes.m[k]];
        }
    }
    Ok(report)
}

/// The particle–particle algorithm with its parameters and its scratch memory.
#[derive(Clone, Debug, Default)]
pub struct ParticleParticle {
    /// The parameters of every pass.
    pub params: ParticleParticleParams,
    workspace: ParticleParticleWorkspace,
}

impl ParticleParticle {
    /// The algorithm with `params` and an empty workspace.
    pub fn new(params: ParticleParticleParams) -> Self {
        ParticleParticle {
            params,
            workspace: ParticleParticleWorkspace::default(),
        }
    }
}

impl ContactAlgorithm for ParticleParticle {
    /// [`particle_particle_with`] over the coupling step `dt`.
    fn correct(
        &mut self,
        particles: Particles<'_>,
        nodes: Nodes<'_>,
        segments: &[Segment],
        dt: f64,
    ) -> Result<PassReport, ContactError> {
        let report = particle_particle_with(&mut self.workspace, particles, nodes, segments, &self.params, dt)?;
        Ok(PassReport {
            contacts: report.contacts,
            max_penetration: report.max_penetration,
            node_impulse: report.node_impulse,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn single_point_force_matches_monaghan() {
        // One node (a segment's end far away): particle at distance 0.5 r0 straight above node 0.
        let mut px = [[0.0, 0.05]];
        let mut pv = [[0.0, 0.0]];
        let mut nx = [[0.0, 0.0], [10.0, 0.0]];
        let mut nv = [[0.0; 2]; 2];
        let params = ParticleParticleParams {
            spacing: 20.0,
            strength: 2.0,
            r0: 0.1,
            p1: 12,
            p2: 4,
        };
        let p = Particles {
            x: &mut px,
            v: &mut pv,
            m: &[3.0],
        };
        let n = Nodes {
            x: &mut nx,
            v: &mut nv,
            m: &[5.0, 5.0],
            fixed: &[false, true],
        };
        let r = particle_particle(p, n, &[Segment { a: 0, b: 1 }], &params, 0.01).unwrap();
        let a = 2.0 * (2f64.powi(12) - 2f64.powi(4)) / 0.05;
        assert_eq!(r.contacts, 1);
        assert!((r.max_penetration - 0.05).abs() < 1e-15);
        assert!((pv[0][1] - 0.01 * a).abs() < 1e-12 * a && pv[0][0] == 0.0);
        assert!((nv[0][1] + 3.0 * 0.01 * a / 5.0).abs() < 1e-12 * a);
        assert_eq!(nv[1], [0.0, 0.0]);
    }

    #[test]
    fn boundary_points_are_at_most_dx_apart() {
        let mut nx = [[0.0, 0.0], [1.0, 0.0]];
        let mut nv = [[0.0; 2]; 2];
        let p = Particles {
            x: &mut [],
            v: &mut [],
            m: &[],
        };
        let n = Nodes {
            x: &mut nx,
            v: &mut nv,
            m: &[1.0, 1.0],
            fixed: &[true, true],
        };
        let params = ParticleParticleParams::monaghan(0.3, 9.81, 1.0);
        let r = particle_particle(p, n, &[Segment { a: 0, b: 1 }], &params, 0.01).unwrap();
        // ceil(1/0.3) = 4 pieces: 2 nodes + 3 interior points, 0.25 apart.
        assert_eq!(r.boundary_points, 5);
    }
}
