//! The exact projection of one particle on its immovable masters (all their nodes fixed, or held in place for the
//! position phase), in both phases: `rigid.rs`'s exact steps repeated until no constraint is violated, and the
//! reactions that the particle's change puts on the fixed nodes. Against a rigid structure this leaves no particle
//! inside the contact thickness and no contact approaching, whatever the corner angles.

use super::detection::{Detector, Hit, Master};
use super::pairs::{Out, PairLog};
use super::report::ContactReport;
use super::rigid::{position_step, velocity_step, Gaps, HalfPlane};
use super::setup::Setup;
use crate::contact::bodies::Particles;
use crate::contact::geometry::{axpy, cross, dot, sub, Vec2};

/// Exact steps per particle and sweep against immovable masters (one is the rule; more only in an
/// over-constrained pocket).
const RIGID_STEPS: usize = 16;

/// What the exact position projection of one particle found.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Projected {
    /// Deepest penetration met [m] (0 if none).
    pub worst: f64,
    /// In the first sweep, a master within the touch gap of the particle's position before any step.
    pub near: bool,
    /// A master was penetrated: the particle's position was not admissible.
    pub penetrated: bool,
    /// The particle was moved.
    pub moved: bool,
    /// `gaps.x0` holds the gaps of the masters at the particle's final position.
    pub gaps_valid: bool,
}

/// Projects particle `s` out of its immovable masters `rigid` (node positions `node_x`) in one position sweep,
/// `first` when it is the first; the penetrations found before the first step of the first sweep are counted in
/// `report`. `gaps` is scratch; `known`: `gaps.x0` already holds the masters' gaps at the particle's position.
#[allow(clippy::too_many_arguments)]
pub(super) fn position(
    setup: &Setup,
    particles: &mut Particles,
    s: usize,
    node_x: &[Vec2],
    rigid: &[Master],
    first: bool,
    gaps: &mut Gaps,
    mut known: bool,
    out: Out,
) -> Projected {
    let Out { report, pairs } = out;
    let mut out = Projected::default();
    // `known`: whether `gaps.x0` holds the gaps at the particle's position (the last step computed them to admit it).
    for step in 0..RIGID_STEPS {
        if rigid.is_empty() {
            break;
        }
        let d = setup.detector(node_x);
        let x0 = particles.x[s];
        if !known {
            gaps.fill_x0(&d, rigid, x0);
            known = true;
        }
        let mut penetrated = false;
        // A master that finds no contact has an infinite gap: neither near nor penetrated. A gap within round-off
        // (−`tol_round` ≤ g) is not a penetration: it is what `position_step` admits, so a position it admitted
        // is final. Counted against 0, the position it admitted was often "penetrated" again by round-off and
        // projected again, by ~1e-17 m: 9 exact steps per penetrating particle on the shipped gate, up to
        // `RIGID_STEPS`, and again in the next sweep (docs/PERFORMANCE.md, 2026-11-28 eighth).
        for (&m, &g) in rigid.iter().zip(&gaps.x0) {
            if first && step == 0 && g <= setup.touch {
                out.near = true;
            }
            if g < -setup.tol_round {
                penetrated = true;
                out.worst = out.worst.max(-g);
                if first && step == 0 {
                    report.note_contact(m, g);
                }
            }
        }
        if !penetrated {
            break;
        }
        out.penetrated = true;
        let Some(st) = position_step(&d, rigid, x0, setup.tol_round, gaps) else {
            break;
        };
        known = st.gaps_at_x;
        // The particle's change m_s Δx is balanced by reactions −m_s μ_j N_a n_j on the fixed nodes.
        let delta = sub(st.x, x0);
        let m_s = particles.m[s];
        for (m, h, mu) in split(&d, rigid, st.by, st.x, delta) {
            // λ = m_s μ: the particle moved by μ = λ/m_s along n_j; the gap is the master's at x0.
            let g0 = d.detect(m, x0).map_or(h.g, |h0| h0.g);
            pairs.record(s, m, g0, m_s * mu, 0.0);
            for (k, nk) in [(h.a, h.na), (h.b, h.nb)] {
                report.node_position_impulse[k] = axpy(report.node_position_impulse[k], -m_s * mu * nk, h.n);
            }
        }
        particles.x[s] = st.x;
        out.moved = true;
    }
    out.gaps_valid = known && !rigid.is_empty();
    out
}

/// The velocity constraints of one particle's immovable contacts, n·v_s ≥ n·u, each with its contact's geometry.
#[derive(Clone, Debug, Default)]
pub(super) struct Planes {
    planes: Vec<HalfPlane>,
    hits: Vec<Hit>,
    masters: Vec<Master>,
}

impl Planes {
    /// Empties the list for the next particle.
    pub fn clear(&mut self) {
        self.planes.clear();
        self.hits.clear();
        self.masters.clear();
    }

    /// Adds the contact `h` with master `m` moving at `u` (its prescribed velocity at the contact point).
    pub fn push(&mut self, h: Hit, m: Master, u: Vec2) {
        self.planes.push(HalfPlane { n: h.n, c: dot(h.n, u) });
        self.hits.push(h);
        self.masters.push(m);
    }
}

/// Projects the velocity of particle `s` (mass `m_s`) on its immovable contacts `planes` in one velocity sweep;
/// returns the fastest approach met [m/s] (0 if none) and whether the velocity was changed.
pub(super) fn velocity(
    particles: &mut Particles,
    s: usize,
    m_s: f64,
    planes: &Planes,
    pairs: &mut PairLog,
    report: &mut ContactReport,
) -> (f64, bool) {
    let (mut worst, mut moved) = (0.0f64, false);
    for _ in 0..if planes.planes.is_empty() { 0 } else { RIGID_STEPS } {
        let v0 = particles.v[s];
        let approach = planes.planes.iter().fold(0.0f64, |a, p| a.max(p.c - dot(p.n, v0)));
        worst = worst.max(approach);
        let big = planes
            .planes
            .iter()
            .fold(v0[0].abs().max(v0[1].abs()), |a, p| a.max(p.c.abs()));
        let Some(st) = velocity_step(&planes.planes, v0, 1e-12 * big) else {
            break;
        };
        for (pi, mu) in st.by.into_iter().flatten() {
            let h = planes.hits[pi];
            // J = m_s μ along n_j.
            pairs.record(s, planes.masters[pi], h.g, 0.0, m_s * mu);
            for (k, nk) in [(h.a, h.na), (h.b, h.nb)] {
                report.node_impulse[k] = axpy(report.node_impulse[k], -m_s * mu * nk, h.n);
            }
        }
        particles.v[s] = st.v;
        moved = true;
    }
    (worst, moved)
}

/// Splits a particle's change `delta` at position `at` along the normals of the (one or two) masters that define
/// it: delta = Σ μ_j n_j, each with its master and contact geometry (N_a at `at`, unclamped, so x_s − x_c ∥ n_j
/// holds).
fn split(
    d: &Detector,
    masters: &[Master],
    by: [Option<usize>; 2],
    at: Vec2,
    delta: Vec2,
) -> impl Iterator<Item = (Master, Hit, f64)> {
    let hits = by.map(|i| i.and_then(|i| d.attach(masters[i], at).map(|(h, _)| (masters[i], h))));
    let mus = match hits {
        [Some((_, h1)), Some((_, h2))] if cross(h1.n, h2.n).abs() > 1e-12 => {
            let det = cross(h1.n, h2.n);
            [cross(delta, h2.n) / det, cross(h1.n, delta) / det]
        }
        [Some((_, h1)), _] => [dot(delta, h1.n), 0.0],
        _ => [0.0, 0.0],
    };
    let keep = [hits[0], if mus[1] != 0.0 { hits[1] } else { None }];
    keep.into_iter()
        .zip(mus)
        .filter_map(|(h, mu)| h.map(|(m, h)| (m, h, mu)))
}
