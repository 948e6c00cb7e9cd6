//! Exact correction of one particle against immovable masters (all nodes fixed: 1/m = 0).
//!
//! With an immovable master the Gauss–Seidel update of `DESIGN.md` §4.5 moves only the particle, by −g along n:
//! it is the projection on that master's constraint. Sweeping several such constraints (a concave corner) converges
//! to the nearest admissible point only geometrically (per sweep by the cosine of the wedge angle), so instead the
//! limit is computed directly: in 2D the nearest admissible point lies on one constraint boundary or at the
//! intersection of two, so the candidates are the single projections and the pairwise intersections, and the
//! nearest one that violates no constraint wins (ties: the first in master order). The same holds for velocities,
//! where each contact is a half-plane (v − u)·n ≥ 0. When no candidate is admissible (an over-constrained pocket)
//! one plain Gauss–Seidel step on the deepest violation is returned instead and the caller repeats.

use super::detection::{Detector, Master, Shape};
use crate::contact::geometry::{add, cross, dot, normalize, scale, sub, Vec2};

/// Constraints entering the candidate set (those violated at the start, and those violated after one single
/// projection); beyond this many the rest is left to the caller's repeat.
const MAX_SET: usize = 8;

/// Result of one exact position step: the new position and the (one or two) masters whose boundaries define it,
/// as indices into the master list.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PositionStep {
    pub x: Vec2,
    pub by: [Option<usize>; 2],
    /// [`Gaps::x0`] now holds the gaps at `x` (the step landed on an admissible candidate, whose gaps were all
    /// computed to admit it); otherwise it is stale.
    pub gaps_at_x: bool,
}

/// Per-master gaps (`f64::INFINITY` where a master finds no contact) that one exact step computes anyway, kept so
/// that no detection is repeated at the same point with the same master: the gaps at the particle's position, at
/// each single projection, at the candidate being admitted and at the best one so far. Scratch only.
#[derive(Clone, Debug, Default)]
pub(crate) struct Gaps {
    /// At the position the step starts from (filled by the caller), then at the step's result (`gaps_at_x`).
    pub x0: Vec<f64>,
    proj: Vec<f64>,
    cand: Vec<f64>,
    best: Vec<f64>,
}

impl Gaps {
    /// Fills [`Gaps::x0`] with the gaps of `masters` at `x`.
    pub fn fill_x0(&mut self, det: &Detector, masters: &[Master], x: Vec2) {
        self.x0.clear();
        self.x0.extend(masters.iter().map(|&m| gap(det, m, x)));
    }
}

/// The gap of master `m` at `x`, or infinity where it finds no contact.
#[inline]
fn gap(det: &Detector, m: Master, x: Vec2) -> f64 {
    det.detect(m, x).map_or(f64::INFINITY, |h| h.g)
}

/// Whether no gap in `gaps` is below −`tol` (NaN is not admissible).
#[inline]
fn admits(gaps: &[f64], tol: f64) -> bool {
    gaps.iter().all(|&g| g >= -tol)
}

/// Fills `out` with the gaps of `masters` at `x` while they admit `x` (no gap below −`tol`); whether all do. The
/// same answer as `masters.iter().all(|&m| gap(m, x) >= -tol)`, which stops at the first that does not.
fn admit_into(det: &Detector, masters: &[Master], x: Vec2, tol: f64, out: &mut Vec<f64>) -> bool {
    out.clear();
    for &m in masters {
        let g = gap(det, m, x);
        if g < -tol || g.is_nan() {
            return false;
        }
        out.push(g);
    }
    true
}

/// One exact position step for a particle at `x0` against the immovable `masters`, or `None` when none is
/// penetrated (g < 0). Candidates are admissible when no master's gap is below −`tol`. `gaps.x0` must hold the
/// masters' gaps at `x0` ([`Gaps::fill_x0`]).
pub(crate) fn position_step(
    det: &Detector,
    masters: &[Master],
    x0: Vec2,
    tol: f64,
    gaps: &mut Gaps,
) -> Option<PositionStep> {
    let n = masters.len();
    debug_assert_eq!(gaps.x0.len(), n);
    // Deepest violation at x0 (first in order on ties).
    let mut deepest: Option<(usize, f64)> = None;
    let mut set = [0usize; MAX_SET];
    let mut len = 0;
    for (i, &g) in gaps.x0.iter().enumerate() {
        if g < 0.0 {
            if deepest.is_none_or(|(_, d)| g < d) {
                deepest = Some((i, g));
            }
            if len < MAX_SET {
                set[len] = i;
                len += 1;
            }
        }
    }
    let (deep, _) = deepest?;

    // Add the constraints that a single projection runs into. Every master's gap at each single projection is
    // kept: the projection is the first candidate below, admitted on those very gaps.
    let violated_at_start = len;
    let mut projected = [false; MAX_SET];
    gaps.proj.clear();
    gaps.proj.resize(violated_at_start * n, f64::INFINITY);
    for k in 0..violated_at_start {
        let Some(p) = det.shape(masters[set[k]]).map(|s| project(s, x0)) else {
            continue;
        };
        projected[k] = true;
        let row = &mut gaps.proj[k * n..(k + 1) * n];
        for (i, &m) in masters.iter().enumerate() {
            let g = gap(det, m, p);
            row[i] = g;
            if len < MAX_SET && !set[..len].contains(&i) && g < 0.0 {
                set[len] = i;
                len += 1;
            }
        }
    }

    // The nearest admissible candidate (the first on ties); its gaps go to `gaps.best`.
    let mut best: Option<(f64, PositionStep)> = None;
    let Gaps {
        proj,
        cand,
        best: best_gaps,
        ..
    } = gaps;
    let mut consider = |x: Vec2, by: [Option<usize>; 2], known: Option<&[f64]>| {
        let d2 = dot(sub(x, x0), sub(x, x0));
        if !best.as_ref().is_none_or(|(b, _)| d2 < *b) {
            return;
        }
        let admitted = match known {
            Some(row) => {
                admits(row, tol) && {
                    best_gaps.clear();
                    best_gaps.extend_from_slice(row);
                    true
                }
            }
            None => {
                admit_into(det, masters, x, tol, cand) && {
                    std::mem::swap(cand, best_gaps);
                    true
                }
            }
        };
        if admitted {
            best = Some((d2, PositionStep { x, by, gaps_at_x: true }));
        }
    };
    for (k, &i) in set[..len].iter().enumerate() {
        if let Some(s) = det.shape(masters[i]) {
            // The first `violated_at_start` are the single projections whose gaps are known.
            let known = (k < violated_at_start && projected[k]).then(|| &proj[k * n..(k + 1) * n]);
            consider(project(s, x0), [Some(i), None], known);
        }
    }
    for (k, &i) in set[..len].iter().enumerate() {
        for &j in &set[k + 1..len] {
            let (Some(si), Some(sj)) = (det.shape(masters[i]), det.shape(masters[j])) else {
                continue;
            };
            for x in intersections(si, sj).into_iter().flatten() {
                consider(x, [Some(i), Some(j)], None);
            }
        }
    }
    match best {
        Some((_, step)) => {
            std::mem::swap(&mut gaps.x0, &mut gaps.best);
            Some(step)
        }
        // No admissible candidate: one Gauss–Seidel step on the deepest violation.
        None => det.shape(masters[deep]).map(|s| PositionStep {
            x: project(s, x0),
            by: [Some(deep), None],
            gaps_at_x: false,
        }),
    }
}

/// Nearest point of a constraint boundary.
fn project(s: Shape, x: Vec2) -> Vec2 {
    match s {
        // x += −g n with g = n·x − c (DESIGN.md §4.5 position update for 1/m_master = 0: λ/m_s = −g).
        Shape::Line { n, c } => add(x, scale(n, c - dot(n, x))),
        Shape::Circle { centre, r, fallback } => add(centre, scale(normalize(sub(x, centre)).unwrap_or(fallback), r)),
    }
}

/// Intersection points of two constraint boundaries (none for parallel lines or circles that miss).
fn intersections(a: Shape, b: Shape) -> [Option<Vec2>; 2] {
    match (a, b) {
        (Shape::Line { n: n1, c: c1 }, Shape::Line { n: n2, c: c2 }) => {
            let det = cross(n1, n2);
            if det.abs() < 1e-12 {
                return [None, None];
            }
            [
                Some([(c1 * n2[1] - n1[1] * c2) / det, (n1[0] * c2 - c1 * n2[0]) / det]),
                None,
            ]
        }
        (Shape::Line { n, c }, Shape::Circle { centre, r, .. })
        | (Shape::Circle { centre, r, .. }, Shape::Line { n, c }) => {
            // Points q + s t on the line with |q + s t − centre| = r, q the foot of the centre on the line.
            let t = [-n[1], n[0]];
            let q = add(centre, scale(n, c - dot(n, centre)));
            let h2 = r * r - (c - dot(n, centre)).powi(2);
            if h2 < 0.0 {
                return [None, None];
            }
            let h = h2.sqrt();
            [Some(add(q, scale(t, h))), Some(sub(q, scale(t, h)))]
        }
        (Shape::Circle { centre: c1, r: r1, .. }, Shape::Circle { centre: c2, r: r2, .. }) => {
            let d = sub(c2, c1);
            let l2 = dot(d, d);
            if l2 <= 0.0 {
                return [None, None];
            }
            let l = l2.sqrt();
            let a = (r1 * r1 - r2 * r2 + l2) / (2.0 * l);
            let h2 = r1 * r1 - a * a;
            if h2 < 0.0 {
                return [None, None];
            }
            let e = scale(d, 1.0 / l);
            let m = add(c1, scale(e, a));
            let off = scale([-e[1], e[0]], h2.sqrt());
            [Some(add(m, off)), Some(sub(m, off))]
        }
    }
}

/// A velocity constraint n·v ≥ c of one contact (c = n·u, u the master's velocity at the contact point).
#[derive(Clone, Copy, Debug)]
pub(crate) struct HalfPlane {
    pub n: Vec2,
    pub c: f64,
}

/// Result of one exact velocity step: the new velocity and its change split as Σ μ_j n_j over (one or two)
/// constraints, given as (index into the constraint list, μ).
#[derive(Clone, Copy, Debug)]
pub(crate) struct VelocityStep {
    pub v: Vec2,
    pub by: [Option<(usize, f64)>; 2],
}

/// One exact velocity step for a particle with velocity `v0` against immovable contacts, or `None` when no contact
/// approaches (n·v < c). Candidates are admissible when no constraint is violated by more than `tol`.
pub(crate) fn velocity_step(planes: &[HalfPlane], v0: Vec2, tol: f64) -> Option<VelocityStep> {
    let slack = |p: &HalfPlane, v: Vec2| dot(p.n, v) - p.c;
    let mut deepest: Option<(usize, f64)> = None;
    for (i, p) in planes.iter().enumerate() {
        let s = slack(p, v0);
        if s < 0.0 && deepest.is_none_or(|(_, d)| s < d) {
            deepest = Some((i, s));
        }
    }
    let (deep, s_deep) = deepest?;
    let admissible = |v: Vec2| planes.iter().all(|p| slack(p, v) >= -tol);
    let mut best: Option<(f64, VelocityStep)> = None;
    let mut consider = |v: Vec2, by: [Option<(usize, f64)>; 2]| {
        let d2 = dot(sub(v, v0), sub(v, v0));
        if best.as_ref().is_none_or(|(b, _)| d2 < *b) && admissible(v) {
            best = Some((d2, VelocityStep { v, by }));
        }
    };
    let n = planes.len().min(MAX_SET);
    for (i, p) in planes[..n].iter().enumerate() {
        // Single contact: J/m_s = −v_rel, the DESIGN.md §4.5 velocity update with 1/m_master = 0.
        let mu = -slack(p, v0);
        if mu > 0.0 {
            consider(add(v0, scale(p.n, mu)), [Some((i, mu)), None]);
        }
    }
    for i in 0..n {
        for j in i + 1..n {
            let (a, b) = (planes[i], planes[j]);
            let det = cross(a.n, b.n);
            if det.abs() < 1e-12 {
                continue;
            }
            // Δv = μ_a n_a + μ_b n_b with both constraints met exactly: n_a·Δv = −slack_a, n_b·Δv = −slack_b.
            let (ra, rb) = (-slack(&a, v0), -slack(&b, v0));
            let dv = [(ra * b.n[1] - a.n[1] * rb) / det, (a.n[0] * rb - ra * b.n[0]) / det];
            let (mu_a, mu_b) = (cross(dv, b.n) / det, cross(a.n, dv) / det);
            if mu_a >= 0.0 && mu_b >= 0.0 {
                consider(add(v0, dv), [Some((i, mu_a)), Some((j, mu_b))]);
            }
        }
    }
    Some(match best {
        Some((_, step)) => step,
        None => VelocityStep {
            v: add(v0, scale(planes[deep].n, -s_deep)),
            by: [Some((deep, -s_deep)), None],
        },
    })
}

#[cfg(test)]
mod tests {
    use super::super::detection::Topology;
    use super::*;
    use crate::contact::bodies::Segment;

    /// A 60° tank bottom (V-shaped notch, fluid above): both walls concave at node 1.
    fn notch() -> (Vec<Vec2>, Vec<Segment>) {
        let s = 3f64.sqrt();
        // Clockwise around the fluid: structure on the left of each segment.
        let x = vec![[-1.0, s], [0.0, 0.0], [1.0, s]];
        (x, vec![Segment { a: 2, b: 1 }, Segment { a: 1, b: 0 }])
    }

    fn step_at(det: &Detector, masters: &[Master], x: Vec2) -> Option<PositionStep> {
        let mut gaps = Gaps::default();
        gaps.fill_x0(det, masters, x);
        position_step(det, masters, x, 1e-14, &mut gaps)
    }

    #[test]
    fn acute_concave_corner_is_solved_exactly_in_one_step() {
        let (x, segs) = notch();
        let mut topo = Topology::default();
        topo.build(3, &segs);
        let det = Detector {
            x: &x,
            segments: &segs,
            topo: &topo,
            thickness: 0.1,
            far_side: 0.3,
            min_len: 0.0,
            reach: f64::INFINITY,
            frames: None,
        };
        let masters = [Master::Segment(0), Master::Segment(1), Master::Node(1)];
        let step = step_at(&det, &masters, [0.0, 0.05]).unwrap();
        // The apex of the two offset lines lies on the axis at r_c / sin(30°) = 0.2 above the corner.
        assert!(
            step.x[0].abs() < 1e-15 && (step.x[1] - 0.2).abs() < 1e-15,
            "{:?}",
            step.x
        );
        assert_eq!(step.by, [Some(0), Some(1)]);
        assert!(step_at(&det, &masters, step.x).is_none_or(|s| (s.x[1] - 0.2).abs() < 1e-15));
    }

    #[test]
    fn velocity_into_a_wedge_is_stopped() {
        let planes = [
            HalfPlane { n: [0.6, 0.8], c: 0.0 },
            HalfPlane { n: [-0.6, 0.8], c: 0.0 },
        ];
        let step = velocity_step(&planes, [0.1, -1.0], 1e-14).unwrap();
        assert!(step.v[0].abs() < 1e-15 && step.v[1].abs() < 1e-15, "{:?}", step.v);
        // Sliding along one wall while leaving the other is a single projection.
        let step = velocity_step(&planes, [1.0, -0.5], 1e-14).unwrap();
        assert!(step.by[1].is_none() && dot(planes[1].n, step.v).abs() < 1e-15);
        assert!(velocity_step(&planes, [0.0, 1.0], 1e-14).is_none());
    }

    #[test]
    fn intersections_of_circles_and_lines() {
        let c = Shape::Circle {
            centre: [0.0, 0.0],
            r: 1.0,
            fallback: [1.0, 0.0],
        };
        let l = Shape::Line { n: [0.0, 1.0], c: 0.5 };
        for p in intersections(l, c).into_iter().flatten() {
            assert!((dot(p, p) - 1.0).abs() < 1e-15 && (p[1] - 0.5).abs() < 1e-15);
        }
        let c2 = Shape::Circle {
            centre: [1.0, 0.0],
            r: 1.0,
            fallback: [1.0, 0.0],
        };
        let [Some(p), Some(q)] = intersections(c, c2) else {
            panic!()
        };
        assert!((p[0] - 0.5).abs() < 1e-15 && (q[0] - 0.5).abs() < 1e-15 && (p[1] + q[1]).abs() < 1e-15);
    }
}
