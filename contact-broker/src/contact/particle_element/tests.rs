//! Unit tests of the particle–element pass: the formulas on one contact, bad input, and the static-node skips.

use super::segment_grid::dist;
use super::*;
use crate::contact::geometry::{axpy, cross, sub, Vec2};

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
            let mut ws = ParticleElementWorkspace { exhaustive, ..ParticleElementWorkspace::default() };
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

/// One particle 0.03 under a horizontal segment (thickness 0.05, so g = −0.02), from below at v = (0.4, 2.0):
/// the case of `single_contact_matches_the_formulas`, with the nodes free or fixed; the pass's record of the pair.
fn one_pair(fixed: [bool; 2]) -> (ParticleElementWorkspace, Vec2, Vec2) {
    let mut px = [[0.25, -0.03]];
    let mut pv = [[0.4, 2.0]];
    let pm = [1.0];
    let mut nx = [[0.0, 0.0], [1.0, 0.0]];
    let mut nv = [[0.0, 0.0], [0.0, -1.0]];
    if fixed[0] {
        nv = [[0.0; 2]; 2];
    }
    let nm = [2.0, 4.0];
    let params = ContactParams {
        thickness: 0.05,
        far_side: 0.2,
        sweeps: 1,
        tolerance: 0.0,
        move_masters: true,
    };
    let mut ws = ParticleElementWorkspace::default();
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
    particle_element_with(&mut ws, p, n, &[Segment { a: 0, b: 1 }], &params).unwrap();
    (ws, px[0], pv[0])
}

#[test]
fn the_pass_records_its_pair_with_gap_lambda_and_impulse() {
    // Free nodes: λ = −g/w, w = 1/m_s + N1²/m1 + N2²/m2 (DESIGN.md §4.5, Long et al. 2016 after Johnson & Stryk
    // 2001); J = −v_rel/w' at the corrected geometry, which the particle's Δv·n' shows (Δv ∥ n').
    let (ws, x, v) = one_pair([false, false]);
    let pairs = ws.pairs();
    assert_eq!(pairs.len(), 1, "{pairs:?}");
    let p = pairs[0];
    assert_eq!((p.particle, p.master), (0, PairMaster::Segment(0)));
    assert!((p.gap - (-0.02)).abs() < 1e-15, "gap {}", p.gap);
    let w = 1.0 + 0.5625 / 2.0 + 0.0625 / 4.0;
    assert!((p.lambda - 0.02 / w).abs() < 1e-15, "λ {}", p.lambda);
    // m_s = 1: the particle moved by λ along n = (0, −1), and its velocity changed by J along n' ≈ n.
    assert!((x[1] - (-0.03 - p.lambda)).abs() < 1e-15);
    let dv = [v[0] - 0.4, v[1] - 2.0];
    assert!(
        (dv[0].hypot(dv[1]) - p.impulse).abs() < 1e-14,
        "J {} vs |Δv| {:?}",
        p.impulse,
        dv
    );
    assert!(
        (p.impulse - 2.25 / w).abs() < 2e-3 * p.impulse,
        "close to the undeformed value"
    );

    // Fixed nodes: the exact projection (projection.rs): μ = −g along n, λ = m_s μ = 0.02; J = m_s·(−v_rel) = 2.
    let (ws, x, v) = one_pair([true, true]);
    let pairs = ws.pairs();
    assert_eq!(pairs.len(), 1, "{pairs:?}");
    let p = pairs[0];
    assert_eq!((p.particle, p.master), (0, PairMaster::Segment(0)));
    assert!((p.gap - (-0.02)).abs() < 1e-15, "gap {}", p.gap);
    assert!((p.lambda - 0.02).abs() < 1e-15, "λ {}", p.lambda);
    assert!((p.impulse - 2.0).abs() < 1e-14, "J {}", p.impulse);
    assert!((x[1] - (-0.05)).abs() < 1e-15 && v[1].abs() < 1e-14 && v[0] == 0.4);

    // Nothing touched: no pairs, and the previous pass's are gone.
    let mut ws = ws;
    let (mut px, mut pv, pm) = ([[0.25, -0.5]], [[0.0, 0.0]], [1.0]);
    let (mut nx, mut nv) = ([[0.0, 0.0], [1.0, 0.0]], [[0.0; 2]; 2]);
    let p = Particles {
        x: &mut px,
        v: &mut pv,
        m: &pm,
    };
    let n = Nodes {
        x: &mut nx,
        v: &mut nv,
        m: &[2.0, 4.0],
        fixed: &[false, false],
    };
    particle_element_with(&mut ws, p, n, &[Segment { a: 0, b: 1 }], &ContactParams::default()).unwrap();
    assert!(ws.pairs().is_empty());
}
