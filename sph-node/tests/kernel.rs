//! Cubic spline kernel properties (`DESIGN.md` §4.2).

use proptest::prelude::*;
use sph_node::kernel::CubicSpline;

/// Lattice points within `reach` lattice steps of the origin-centred particle.
fn lattice(dx: f64, reach: i32) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    for iy in -reach..=reach {
        for ix in -reach..=reach {
            out.push([ix as f64 * dx, iy as f64 * dx]);
        }
    }
    out
}

/// ∫ W dA = 2π ∫_0^{2h} W(r) r dr = 1, by composite Simpson quadrature (W is piecewise cubic: exact per piece).
#[test]
fn normalised_by_quadrature() {
    for h in [0.013, 1.0, 7.5] {
        let k = CubicSpline::new(h);
        let n = 2000; // even, and q = 1 falls on a node
        let step = 2.0 * h / n as f64;
        let f = |r: f64| 2.0 * std::f64::consts::PI * k.w(r) * r;
        let mut s = f(0.0) + f(2.0 * h);
        for i in 1..n {
            s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(i as f64 * step);
        }
        let integral = s * step / 3.0;
        assert!((integral - 1.0).abs() < 1e-12, "h = {h}: ∫W = {integral}");
    }
}

proptest! {
    /// Σ_j (m_j/ρ_j) W_ij = Σ_j Δx² W_ij ≈ 1 within 1 % for an interior lattice particle, h = 1.3 Δx.
    #[test]
    fn partition_of_unity(dx in 1e-3f64..10.0) {
        let k = CubicSpline::new(1.3 * dx);
        let sum: f64 = lattice(dx, 4).iter().map(|p| dx * dx * k.w(p[0].hypot(p[1]))).sum();
        prop_assert!((sum - 1.0).abs() < 0.01, "sum = {sum}");
    }

    /// Σ_j ∇_i W_ij = 0 on a symmetric lattice, to 1e-12 relative to Σ_j |∇_i W_ij|.
    #[test]
    fn zero_gradient_sum(dx in 1e-3f64..10.0, ratio in 1.0f64..2.0) {
        let k = CubicSpline::new(ratio * dx);
        let (mut s, mut scale) = ([0.0f64; 2], 0.0f64);
        for p in lattice(dx, 5) {
            let r_ij = [-p[0], -p[1]];
            let g = k.grad(r_ij, p[0].hypot(p[1]));
            s[0] += g[0];
            s[1] += g[1];
            scale += g[0].hypot(g[1]);
        }
        prop_assert!(s[0].hypot(s[1]) <= 1e-12 * scale, "|Σ∇W| = {:?}, scale {scale}", s);
    }

    /// ∇_i W_ij = −∇_j W_ji (antisymmetric, exactly).
    #[test]
    fn gradient_antisymmetric(x in -3.0f64..3.0, y in -3.0f64..3.0, h in 0.1f64..2.0) {
        let k = CubicSpline::new(h);
        let r = x.hypot(y);
        let gi = k.grad([x, y], r);
        let gj = k.grad([-x, -y], r);
        prop_assert_eq!(gi[0], -gj[0]);
        prop_assert_eq!(gi[1], -gj[1]);
    }

    /// W ≥ 0 everywhere, W = ∇W = 0 for r ≥ 2h, W > 0 inside.
    #[test]
    fn positive_with_compact_support(r in 0.0f64..5.0, h in 0.1f64..2.0) {
        let k = CubicSpline::new(h);
        prop_assert!(k.w(r) >= 0.0);
        if r >= 2.0 * h {
            prop_assert_eq!(k.w(r), 0.0);
            prop_assert_eq!(k.dw_dr(r), 0.0);
        } else {
            prop_assert!(k.w(r) > 0.0);
            prop_assert!(k.dw_dr(r) <= 0.0);
        }
    }
}
