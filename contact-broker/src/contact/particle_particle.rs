//! Particle–particle contact, the paper's baseline (`DESIGN.md` §4.6): structure boundary nodes, plus extra points
//! along each segment at spacing ≤ Δx, act as boundary particles that repel fluid particles with Monaghan's (1994)
//! Lennard-Jones force. Each reaction goes to the structure, spread on the segment's nodes with N1, N2, so linear
//! and angular momentum are conserved.

use super::algorithm::{ContactAlgorithm, PassReport, Stiffness};
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

    /// The potential of the force per unit particle mass [m²/s²] at distance `r` ≤ r0, zero at r0:
    /// φ = D[((r0/r)^p1 − 1)/p1 − ((r0/r)^p2 − 1)/p2], so that a = −∂φ/∂r.
    fn potential(&self, r: f64) -> f64 {
        let q = self.r0 / r;
        self.strength * ((q.powi(self.p1) - 1.0) / f64::from(self.p1) - (q.powi(self.p2) - 1.0) / f64::from(self.p2))
    }

    /// The force's radial stiffness per unit particle mass at distance `r` [1/s²]: −∂|a|/∂r =
    /// D[(p1 + 1)(r0/r)^p1 − (p2 + 1)(r0/r)^p2]/r² (Ω_c² = D(p1 − p2)/r0² at r0).
    fn stiffness(&self, r: f64) -> f64 {
        let q = self.r0 / r;
        self.strength * (f64::from(self.p1 + 1) * q.powi(self.p1) - f64::from(self.p2 + 1) * q.powi(self.p2)) / (r * r)
    }

    /// Where a pair at distance `r` with `energy` [m²/s²] of relative motion towards each other per unit particle
    /// mass (besides its potential) turns: the r_t ≤ r with φ(r_t) = φ(r) + energy (bisection; φ falls
    /// monotonically on (0, r0)).
    fn turning_point(&self, r: f64, energy: f64) -> f64 {
        if energy <= 0.0 {
            return r;
        }
        let e = self.potential(r) + energy;
        let (mut lo, mut hi) = (0.5 * r, r);
        while self.potential(lo) < e && lo > 1e-6 * r {
            (lo, hi) = (0.5 * lo, lo);
        }
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if self.potential(mid) < e {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        hi
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
    /// The force's stiffness over the pairs, as the particles and the free nodes feel it (zero unless asked for).
    pub stiffness: Stiffness,
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
    /// Per node: Σ 2 N_a k_ij over the pairs (for [`Stiffness::nodes`]).
    node_stiffness: Vec<f64>,
}

/// Applies Δt times the repulsive acceleration to the particles' velocities and the reactions to the nodes (free
/// nodes' velocities change by impulse/m; fixed ones only report it). Positions are not changed. Reports the force's
/// [`Stiffness`] too.
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
        true,
    )
}

/// [`particle_particle`] reusing the scratch arrays of `ws`; the [`Stiffness`] (a turning point per pair) only where
/// `stiffness` asks for it.
pub fn particle_particle_with(
    ws: &mut ParticleParticleWorkspace,
    particles: Particles<'_>,
    nodes: Nodes<'_>,
    segments: &[Segment],
    params: &ParticleParticleParams,
    dt: f64,
    stiffness: bool,
) -> Result<ParticleParticleReport, ContactError> {
    params.validate()?;
    param("dt", dt, dt >= 0.0, "non-negative and finite")?;
    validate(&particles, &nodes, segments)?;
    let ParticleParticleWorkspace {
        grid,
        points,
        touched,
        node_stiffness,
    } = ws;
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
    node_stiffness.clear();
    node_stiffness.resize(nn, 0.0);
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
        let mut row = 0.0;
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
            // How stiff the pair will be where it turns: entered twice, since the particle's row sum of M⁻¹K is
            // Σ k/m (1 + N_a + N_b).
            let k = if stiffness {
                params.stiffness(params.turning_point(dist, closing_energy(&particles, &nodes, s, &p, r, dist)))
            } else {
                0.0
            };
            row += 2.0 * k;
            any = true;
            report.contacts += 1;
            report.max_penetration = report.max_penetration.max(r0 - dist);
            report.min_distance = report.min_distance.min(dist);
            // Reaction −m_i Δt a_i on the structure, spread with N1, N2 (zero moment: it acts at the point, along r).
            for (node, nk) in [(p.a, p.na), (p.b, p.nb)] {
                let imp = &mut report.node_impulse[node];
                *imp = [imp[0] - m_dt * nk * a[0], imp[1] - m_dt * nk * a[1]];
                node_stiffness[node] += 2.0 * particles.m[s] * k * nk;
            }
        }
        report.stiffness.particles = report.stiffness.particles.max(row);
        if any {
            let v = &mut particles.v[s];
            *v = [v[0] + dt * acc[0], v[1] + dt * acc[1]];
            report.particles_corrected += 1;
        }
    }
    for (k, row) in node_stiffness.iter().enumerate() {
        let imp = report.node_impulse[k];
        if !nodes.fixed[k] {
            report.stiffness.nodes = report.stiffness.nodes.max(row / nodes.m[k]);
        }
        if !nodes.fixed[k] && (imp[0] != 0.0 || imp[1] != 0.0) {
            let v = &mut nodes.v[k];
            *v = [v[0] + imp[0] / nodes.m[k], v[1] + imp[1] / nodes.m[k]];
        }
    }
    Ok(report)
}

/// The kinetic energy per unit mass of particle `s` moving towards the boundary point `p` at separation `r`
/// (distance `dist`) that the pair's relative motion can turn into potential: ½ (μ/m_s) c², c the closing speed
/// along r and μ the reduced mass of the particle and the point (1/m_point = N_a²/m_a + N_b²/m_b over free nodes);
/// 0 when they separate.
fn closing_energy(
    particles: &Particles<'_>,
    nodes: &Nodes<'_>,
    s: usize,
    p: &BoundaryPoint,
    r: Vec2,
    dist: f64,
) -> f64 {
    let vp = particles.v[s];
    let (va, vb) = (nodes.v[p.a], nodes.v[p.b]);
    let vb = [p.na * va[0] + p.nb * vb[0], p.na * va[1] + p.nb * vb[1]];
    let closing = -dot(sub(vp, vb), r) / dist;
    if closing <= 0.0 {
        return 0.0;
    }
    let inverse = |k: usize, n: f64| if nodes.fixed[k] { 0.0 } else { n * n / nodes.m[k] };
    let point = if p.a == p.b {
        inverse(p.a, 1.0)
    } else {
        inverse(p.a, p.na) + inverse(p.b, p.nb)
    };
    0.5 * closing * closing / (1.0 + particles.m[s] * point)
}

/// The particle–particle algorithm with its parameters and its scratch memory.
#[derive(Clone, Debug, Default)]
pub struct ParticleParticle {
    /// The parameters of every pass.
    pub params: ParticleParticleParams,
    /// Whether each pass reports the force's [`Stiffness`] (for a coupling step bounded by it).
    stiffness: bool,
    workspace: ParticleParticleWorkspace,
}

impl ParticleParticle {
    /// The algorithm with `params` and an empty workspace; its passes report the [`Stiffness`] where `stiffness`.
    pub fn new(params: ParticleParticleParams, stiffness: bool) -> Self {
        ParticleParticle {
            params,
            stiffness,
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
        let ws = &mut self.workspace;
        let report = particle_particle_with(ws, particles, nodes, segments, &self.params, dt, self.stiffness)?;
        Ok(PassReport {
            contacts: report.contacts,
            max_penetration: report.max_penetration,
            node_impulse: report.node_impulse,
            stiffness: report.stiffness,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// D = 2, r0 = 0.1, p1 = 12, p2 = 4, and no points along a segment shorter than 20.
    fn one_pair() -> ParticleParticleParams {
        ParticleParticleParams {
            spacing: 20.0,
            strength: 2.0,
            r0: 0.1,
            p1: 12,
            p2: 4,
        }
    }

    #[test]
    fn single_point_force_matches_monaghan() {
        // One node (a segment's end far away): particle at distance 0.5 r0 straight above node 0.
        let mut px = [[0.0, 0.05]];
        let mut pv = [[0.0, 0.0]];
        let mut nx = [[0.0, 0.0], [10.0, 0.0]];
        let mut nv = [[0.0; 2]; 2];
        let params = one_pair();
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

    /// The stiffness is the force's derivative (central differences), the potential its integral, and the turning
    /// point where the potential has taken the closing energy; a single pair's [`Stiffness`] is 2k for the particle
    /// and 2 m_p k / m_a for a free node, k at the turning point.
    #[test]
    fn stiffness_potential_and_turning_point_agree_with_the_force() {
        let params = one_pair();
        let accel = |r: f64| {
            let q = 0.1 / r;
            2.0 * (q.powi(12) - q.powi(4)) / r
        };
        for r in [0.05, 0.08, 0.099] {
            let h = 1e-7;
            let k = -(accel(r + h) - accel(r - h)) / (2.0 * h);
            assert!(
                (params.stiffness(r) / k - 1.0).abs() < 1e-6,
                "r {r}: {} vs {k}",
                params.stiffness(r)
            );
            let a = -(params.potential(r + h) - params.potential(r - h)) / (2.0 * h);
            assert!((a / accel(r) - 1.0).abs() < 1e-6, "r {r}: {a} vs {}", accel(r));
            let t = params.turning_point(r, 3.0);
            assert!(
                t < r && (params.potential(t) - params.potential(r) - 3.0).abs() < 1e-9,
                "{t}"
            );
            assert_eq!(params.turning_point(r, 0.0), r);
        }
        assert_eq!(params.potential(0.1), 0.0);
        // A particle of 3 kg/m at 0.05 from a free node of 5 kg/m (the segment's far end fixed), closing at 2 m/s.
        let (mut px, mut pv) = ([[0.0, 0.05]], [[0.0, -2.0]]);
        let (mut nx, mut nv) = ([[0.0, 0.0], [10.0, 0.0]], [[0.0; 2]; 2]);
        let r = particle_particle(
            Particles {
                x: &mut px,
                v: &mut pv,
                m: &[3.0],
            },
            Nodes {
                x: &mut nx,
                v: &mut nv,
                m: &[5.0, 5.0],
                fixed: &[false, true],
            },
            &[Segment { a: 0, b: 1 }],
            &params,
            1e-6,
        )
        .unwrap();
        // ½ μ/m_p c² with μ/m_p = 1/(1 + 3/5).
        let k = params.stiffness(params.turning_point(0.05, 0.5 * 4.0 / 1.6));
        assert!(
            (r.stiffness.particles / (2.0 * k) - 1.0).abs() < 1e-12,
            "{:?}",
            r.stiffness
        );
        assert!(
            (r.stiffness.nodes / (2.0 * 3.0 * k / 5.0) - 1.0).abs() < 1e-12,
            "{:?}",
            r.stiffness
        );
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
