//! The random scenes the contact properties run on: a star-shaped structure with its supports, the particles placed
//! around its segments and corners, the contact each particle should feel by direct geometry (to measure
//! penetration and approach against), and the momentum balances.

use contact_broker::contact::{
    particle_element, particle_particle, ContactParams, ContactReport, Nodes, ParticleParticleParams,
    ParticleParticleReport, Particles, Segment,
};
use proptest::prelude::*;

use super::V;

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Support {
    Rigid,
    Free,
    Mixed,
}

#[derive(Clone, Debug)]
pub(super) struct Scene {
    pub(super) dx: f64,
    pub(super) nx: Vec<V>,
    pub(super) nv: Vec<V>,
    pub(super) nm: Vec<f64>,
    pub(super) fixed: Vec<bool>,
    pub(super) segs: Vec<Segment>,
    pub(super) px: Vec<V>,
    pub(super) pv: Vec<V>,
    pub(super) pm: Vec<f64>,
}

impl Scene {
    pub(super) fn element(&mut self, params: &ContactParams) -> ContactReport {
        let p = Particles {
            x: &mut self.px,
            v: &mut self.pv,
            m: &self.pm,
        };
        let n = Nodes {
            x: &mut self.nx,
            v: &mut self.nv,
            m: &self.nm,
            fixed: &self.fixed,
        };
        particle_element(p, n, &self.segs, params).unwrap()
    }

    pub(super) fn particle(&mut self, params: &ParticleParticleParams, dt: f64) -> ParticleParticleReport {
        let p = Particles {
            x: &mut self.px,
            v: &mut self.pv,
            m: &self.pm,
        };
        let n = Nodes {
            x: &mut self.nx,
            v: &mut self.nv,
            m: &self.nm,
            fixed: &self.fixed,
        };
        particle_particle(p, n, &self.segs, params, dt).unwrap()
    }

    pub(super) fn params(&self) -> ContactParams {
        ContactParams::for_spacing(self.dx)
    }
}

/// A particle placed relative to a segment: which segment, ξ along it (beyond [0, 1] near the corners), offset
/// along the normal as a fraction in [−1, 1] mapped onto [−0.9 d_max, 1.5 r_c], velocity, mass factor.
pub(super) type Placement = (usize, f64, f64, V, f64);

/// A particle placed around a vertex, to exercise the corners: which vertex, direction angle, distance as a
/// fraction of 2 r_c, velocity, mass factor.
pub(super) type CornerPlacement = (usize, f64, f64, V, f64);

#[allow(clippy::type_complexity)]
pub(super) fn scene(support: Support) -> impl Strategy<Value = Scene> {
    (
        (
            prop::collection::vec(0.7f64..1.3, 5..10),
            0.0f64..6.3,
            -3.0f64..3.0,
            -3.0f64..3.0,
            any::<bool>(),
        ),
        0.02f64..0.06,
        prop::collection::vec(
            (
                0usize..1000,
                -0.3f64..1.3,
                -1.0f64..1.0,
                [-2.0f64..2.0, -2.0f64..2.0],
                0.5f64..2.0,
            ),
            8..48,
        ),
        prop::collection::vec(([-1.0f64..1.0, -1.0f64..1.0], 0.2f64..20.0, 0.0f64..1.0), 9),
        prop::collection::vec(
            (
                0usize..1000,
                0.0f64..6.3,
                0.0f64..1.0,
                [-2.0f64..2.0, -2.0f64..2.0],
                0.5f64..2.0,
            ),
            2..16,
        ),
    )
        .prop_map(
            move |((radii, rot, cx, cy, inside), dx, placements, node_props, corners)| {
                build(
                    support,
                    &radii,
                    rot,
                    [cx, cy],
                    inside,
                    dx,
                    &placements,
                    &node_props,
                    &corners,
                )
            },
        )
}

#[allow(clippy::too_many_arguments)]
fn build(
    support: Support,
    radii: &[f64],
    rot: f64,
    centre: V,
    inside: bool,
    dx: f64,
    placements: &[Placement],
    node_props: &[(V, f64, f64)],
    corners: &[CornerPlacement],
) -> Scene {
    let nvert = radii.len();
    let mp = 1000.0 * dx * dx; // water particle mass per unit thickness
    let mut nx: Vec<V> = (0..nvert)
        .map(|i| {
            let a = rot + std::f64::consts::TAU * i as f64 / nvert as f64;
            [centre[0] + radii[i] * a.cos(), centre[1] + radii[i] * a.sin()]
        })
        .collect();
    if inside {
        // Clockwise: the structure is outside the polygon, the fluid inside (a container).
        nx.reverse();
    }
    let segs: Vec<Segment> = (0..nvert)
        .map(|i| Segment {
            a: i,
            b: (i + 1) % nvert,
        })
        .collect();
    let nv = (0..nvert).map(|i| node_props[i].0).collect();
    let nm = (0..nvert).map(|i| node_props[i].1 * mp).collect();
    let fixed = (0..nvert)
        .map(|i| match support {
            Support::Rigid => true,
            Support::Free => false,
            Support::Mixed => node_props[i].2 < 0.35,
        })
        .collect();
    let params = ContactParams::for_spacing(dx);
    let (mut px, mut pv, mut pm) = (Vec::new(), Vec::new(), Vec::new());
    for &(j, xi, f, v, mf) in placements {
        let s = segs[j % nvert];
        let (a, b) = (nx[s.a], nx[s.b]);
        let d = [b[0] - a[0], b[1] - a[1]];
        let l = d[0].hypot(d[1]);
        let n = [d[1] / l, -d[0] / l];
        let off = if f < 0.0 {
            -f * -0.9 * params.far_side
        } else {
            f * 1.5 * params.thickness
        };
        px.push([a[0] + xi * d[0] + off * n[0], a[1] + xi * d[1] + off * n[1]]);
        pv.push(v);
        pm.push(mf * mp);
    }
    for &(k, angle, f, v, mf) in corners {
        let (c, rho) = (nx[k % nvert], f * 2.0 * params.thickness);
        px.push([c[0] + rho * angle.cos(), c[1] + rho * angle.sin()]);
        pv.push(v);
        pm.push(mf * mp);
    }
    Scene {
        dx,
        nx,
        nv,
        nm,
        fixed,
        segs,
        px,
        pv,
        pm,
    }
}

// ---- Independent re-statement of the detection of DESIGN.md §4.5, for the checks. ----

/// (n, N1, N2, gap) of particle x against segment j when x is in its detection zone.
fn seg_contact(sc: &Scene, j: usize, x: V, p: &ContactParams) -> Option<(V, f64, f64, f64)> {
    let s = sc.segs[j];
    let (a, b) = (sc.nx[s.a], sc.nx[s.b]);
    let d = [b[0] - a[0], b[1] - a[1]];
    let l = d[0].hypot(d[1]);
    let (t, n) = ([d[0] / l, d[1] / l], [d[1] / l, -d[0] / l]);
    let xi = ((x[0] - a[0]) * t[0] + (x[1] - a[1]) * t[1]) / l;
    let xc = [(1.0 - xi) * a[0] + xi * b[0], (1.0 - xi) * a[1] + xi * b[1]];
    let dn = (x[0] - xc[0]) * n[0] + (x[1] - xc[1]) * n[1];
    ((0.0..=1.0).contains(&xi) && dn > -p.far_side).then_some((n, 1.0 - xi, xi, dn - p.thickness))
}

/// (n, gap) of particle x against node k (between segments k−1 → k and k → k+1 of the closed polygon) when k is a
/// convex corner and x in its wedge.
fn node_contact(sc: &Scene, k: usize, x: V, p: &ContactParams) -> Option<(V, f64)> {
    let nv = sc.nx.len();
    let (xp, xk, xq) = (sc.nx[(k + nv - 1) % nv], sc.nx[k], sc.nx[(k + 1) % nv]);
    let (tp, tq) = ([xk[0] - xp[0], xk[1] - xp[1]], [xq[0] - xk[0], xq[1] - xk[1]]);
    if tp[0] * tq[1] - tp[1] * tq[0] <= 0.0 {
        return None;
    }
    let r = [x[0] - xk[0], x[1] - xk[1]];
    let beyond_p = r[0] * tp[0] + r[1] * tp[1] > 0.0;
    let before_q = r[0] * tq[0] + r[1] * tq[1] < 0.0;
    let dist = r[0].hypot(r[1]);
    (beyond_p && before_q && dist > 0.0).then(|| ([r[0] / dist, r[1] / dist], dist - p.thickness))
}

/// Largest penetration left (−gap of every particle against every segment and convex corner).
pub(super) fn worst_penetration(sc: &Scene, p: &ContactParams) -> f64 {
    let mut worst = 0.0f64;
    for &x in &sc.px {
        for j in 0..sc.segs.len() {
            if let Some((_, _, _, g)) = seg_contact(sc, j, x, p) {
                worst = worst.max(-g);
            }
            if let Some((_, g)) = node_contact(sc, j, x, p) {
                worst = worst.max(-g);
            }
        }
    }
    worst
}

/// Most negative relative normal velocity over the contacts touching (gap ≤ tolerance · thickness).
pub(super) fn worst_approach(sc: &Scene, p: &ContactParams) -> f64 {
    let touch = p.tolerance * p.thickness;
    let mut worst = 0.0f64;
    for (i, &x) in sc.px.iter().enumerate() {
        let v = sc.pv[i];
        for j in 0..sc.segs.len() {
            let s = sc.segs[j];
            if let Some((n, n1, n2, g)) = seg_contact(sc, j, x, p).filter(|c| c.3 <= touch) {
                let (va, vb) = (sc.nv[s.a], sc.nv[s.b]);
                let rel = [v[0] - n1 * va[0] - n2 * vb[0], v[1] - n1 * va[1] - n2 * vb[1]];
                let _ = g;
                worst = worst.min(rel[0] * n[0] + rel[1] * n[1]);
            }
            if let Some((n, _)) = node_contact(sc, j, x, p).filter(|c| c.1 <= touch) {
                let vk = sc.nv[j];
                worst = worst.min((v[0] - vk[0]) * n[0] + (v[1] - vk[1]) * n[1]);
            }
        }
    }
    -worst
}

pub(super) fn v_ref(sc: &Scene) -> f64 {
    sc.pv.iter().chain(&sc.nv).fold(0.0f64, |m, v| m.max(v[0].hypot(v[1])))
}

/// Relative changes of linear momentum, angular momentum (at the corrected positions) and centre of mass, over
/// particles and free nodes, with what fixed nodes received counted as the supports' share.
pub(super) fn balances(
    before: &Scene,
    after: &Scene,
    node_impulse: &[V],
    node_position_impulse: &[V],
) -> (f64, f64, f64) {
    let cross = |x: V, v: V| x[0] * v[1] - x[1] * v[0];
    let (mut p, mut p_scale, mut l, mut l_scale, mut c, mut c_scale) = ([0.0f64; 2], 0.0, 0.0, 0.0, [0.0f64; 2], 0.0);
    let mut body = |m: f64, x0: V, x: V, v0: V, v: V| {
        for k in 0..2 {
            p[k] += m * (v[k] - v0[k]);
            c[k] += m * (x[k] - x0[k]);
        }
        l += m * (cross(x, v) - cross(x, v0));
        let r = x[0].hypot(x[1]);
        p_scale += m * (v[0].hypot(v[1]) + v0[0].hypot(v0[1]));
        l_scale += m * r * (v[0].hypot(v[1]) + v0[0].hypot(v0[1]));
        c_scale += m * (x[0].hypot(x[1]) + x0[0].hypot(x0[1]));
    };
    for i in 0..after.px.len() {
        body(after.pm[i], before.px[i], after.px[i], before.pv[i], after.pv[i]);
    }
    for k in 0..after.nx.len() {
        if !after.fixed[k] {
            body(after.nm[k], before.nx[k], after.nx[k], before.nv[k], after.nv[k]);
        }
    }
    for k in 0..after.nx.len() {
        if after.fixed[k] {
            let (i, pi, x) = (node_impulse[k], node_position_impulse[k], after.nx[k]);
            for d in 0..2 {
                p[d] += i[d];
                c[d] += pi[d];
            }
            l += cross(x, i);
            p_scale += i[0].hypot(i[1]);
            l_scale += x[0].hypot(x[1]) * i[0].hypot(i[1]);
            c_scale += pi[0].hypot(pi[1]);
        }
    }
    let rel = |e: f64, s: f64| if s > 0.0 { e / s } else { e };
    (
        rel(p[0].hypot(p[1]), p_scale),
        rel(l.abs(), l_scale),
        rel(c[0].hypot(c[1]), c_scale),
    )
}

pub(super) fn report(name: &str, value: f64) {
    if std::env::var_os("CONTACT_REPORT").is_some() {
        eprintln!("{name}: {value:.3e}");
    }
}

pub(super) fn bits(v: &[V]) -> Vec<[u64; 2]> {
    v.iter().map(|x| [x[0].to_bits(), x[1].to_bits()]).collect()
}
