//! Dam break, column a × 2a (Martin & Moyce 1952, n² = 2): surge front Z = z/a against T = t sqrt(2g/a),
//! compared with tests/data/mm1952_n2eq2_a2.25in_pysph.csv (see tests/data/SOURCE.txt).

mod common;

use sph_node::WcsphSolver;

const A: f64 = 0.1;
const G: f64 = 9.81;

fn reference() -> Vec<(f64, f64)> {
    include_str!("data/mm1952_n2eq2_a2.25in_pysph.csv")
        .lines()
        .skip(1)
        .filter_map(|l| {
            let mut it = l.split(',').map(|v| v.trim().parse::<f64>());
            Some((it.next()?.ok()?, it.next()?.ok()?))
        })
        .collect()
}

/// Surge front: the rightmost fluid particle near the floor, plus half a spacing (so Z(0) = 1).
fn front(solver: &WcsphSolver, dx: f64) -> f64 {
    let s = solver.state();
    s.x.iter()
        .filter(|x| x[1] < 0.25 * A)
        .map(|x| x[0])
        .fold(f64::NEG_INFINITY, f64::max)
        + 0.5 * dx
}

/// Runs to T = `t_end` and returns (T, Z) every step.
fn surge(dx: f64, t_end: f64) -> Vec<(f64, f64)> {
    let scene = common::dam_break(A, 5.0 * A, dx, "");
    let mut solver = WcsphSolver::new(&scene).expect("solver");
    let scale = (2.0 * G / A).sqrt();
    let mut out = vec![(0.0, front(&solver, dx) / A)];
    while solver.state().t * scale < t_end {
        let dt = solver.stable_dt();
        solver.step(dt).expect("stable");
        out.push((solver.state().t * scale, front(&solver, dx) / A));
    }
    out
}

fn interpolate(curve: &[(f64, f64)], t: f64) -> f64 {
    let k = curve.partition_point(|p| p.0 < t).clamp(1, curve.len() - 1);
    let (a, b) = (curve[k - 1], curve[k]);
    a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0)
}

#[test]
fn surge_front_against_martin_moyce() {
    let dx = A / 40.0;
    let sim = surge(dx, 2.6);
    let mut worst: f64 = 0.0;
    for (t, z) in reference().into_iter().filter(|p| p.0 <= 2.6) {
        let zs = interpolate(&sim, t);
        let err = (zs - z) / z;
        eprintln!(
            "T = {t:.3}: Z_sph = {zs:.3}, Z_exp = {z:.3}, error {:+.1} %",
            100.0 * err
        );
        worst = worst.max(err.abs());
    }
    eprintln!("worst relative error for T <= 2.6: {:.1} %", 100.0 * worst);
    // Measured (Δx = a/40): +13.1 %, +17.1 %, +13.4 %, +11.1 % at T = 0.83, 1.22, 2.00, 2.55 — the SPH front leads
    // the experiment (no gate-opening time, no wall friction), so this is NOT a 5 % validation; it is a 20 %
    // regression guard on the measured behaviour.
    assert!(worst < 0.20, "worst error {worst}");
}
