//! Oscillating elliptical drop in a central force field (case 7.4 of /work/shared/data/07_sph_analytic; Monaghan &
//! Rafiee 2013, Int. J. Numer. Meth. Fluids 71:537, Eq. (A.19)): a circular drop of radius R = 1, no walls, no
//! gravity, body force f = −Ω² r, initial velocity u = σ0 x, v = −σ0 y and pressure p = Q (1 − r²/R²),
//! Q = ρ (σ0² + Ω²) R² / 2. With σ0 = 0.5, Ω = 1 the semi-axis A(t) oscillates with period T = 4.56737
//! (README.txt there; the exact A(t) is tests/data/oscillating_drop_exact_sigma0.5_Omega1_R1_COMPUTED.csv).
//!
//! The drop is built programmatically ([`WcsphSolver::from_particles`]) because scenes fill rectangles only.

use cosim_proto::scene::BoxSpec;
use sph_node::{FluidState, WallParticles, WcsphSolver};
use sph_node::{SphParams, WcsphParams};

const R: f64 = 1.0;
const SIGMA0: f64 = 0.5;
const OMEGA: f64 = 1.0;
const RHO0: f64 = 1000.0;
/// Period of the semi-axis oscillation from the ODE of Monaghan & Rafiee 2013, Eq. (A.19) (README.txt, case 4).
const T_EXACT: f64 = 4.56737;

fn exact() -> Vec<(f64, f64)> {
    include_str!("data/oscillating_drop_exact_sigma0.5_Omega1_R1_COMPUTED.csv")
        .lines()
        .skip(1)
        .filter_map(|l| {
            let v: Vec<f64> = l.split(',').filter_map(|x| x.trim().parse().ok()).collect();
            (v.len() == 4).then(|| (v[0], v[2]))
        })
        .collect()
}

fn drop_solver(n_radius: usize, c0: f64, options: WcsphParams, shepard: Option<u32>, xsph: f64) -> WcsphSolver {
    let dx = R / n_radius as f64;
    let n = n_radius as i64;
    let mut x = Vec::new();
    for iy in -n..n {
        for ix in -n..n {
            let p = [(ix as f64 + 0.5) * dx, (iy as f64 + 0.5) * dx];
            if p[0].hypot(p[1]) < R {
                x.push(p);
            }
        }
    }
    let params = SphParams {
        rho0: RHO0,
        dx,
        h: 1.3 * dx,
        nu: 0.0,
        gravity: [0.0, 0.0],
        xsph,
        domain: BoxSpec {
            min: [-4.0 * R, -4.0 * R],
            max: [4.0 * R, 4.0 * R],
        },
    };
    let eos = sph_node::eos::Tait::new(RHO0, c0);
    let q = RHO0 * (SIGMA0 * SIGMA0 + OMEGA * OMEGA) * R * R / 2.0;
    // README case 4: p = Q (1 − r²/R²), u = σ0 x, v = −σ0 y
    let p: Vec<f64> = x
        .iter()
        .map(|r| q * (1.0 - (r[0] * r[0] + r[1] * r[1]) / (R * R)))
        .collect();
    let state = FluidState {
        t: 0.0,
        step: 0,
        v: x.iter().map(|r| [SIGMA0 * r[0], -SIGMA0 * r[1]]).collect(),
        rho: p.iter().map(|&p| eos.density(p)).collect(),
        m: vec![RHO0 * dx * dx; x.len()],
        p,
        x,
    };
    let options = WcsphParams {
        c0,
        alpha: 0.01,
        shepard_interval: shepard,
        central_force: OMEGA * OMEGA,
        ..options
    };
    WcsphSolver::from_particles(params, options, state, WallParticles::default()).expect("solver")
}

/// Semi-axis along x from the second moment, A = R sqrt(<x²>(t) / <x²>(0)) (uniform ellipse: <x²> = A²/4).
fn second_moment(s: &FluidState) -> f64 {
    let m: f64 = s.m.iter().sum();
    s.x.iter().zip(&s.m).map(|(x, m)| m * x[0] * x[0]).sum::<f64>() / m
}

/// Runs the drop and returns (period, A_max, t(A_max), worst |A − A_exact| on the 0.1 grid up to 4.6).
fn run(n_radius: usize, c0: f64, options: WcsphParams, shepard: Option<u32>, xsph: f64) -> (f64, f64, f64, f64) {
    let mut solver = drop_solver(n_radius, c0, options, shepard, xsph);
    let m0 = second_moment(solver.state());
    let a_of = |s: &WcsphSolver| R * (second_moment(s.state()) / m0).sqrt();
    let mut curve = vec![(0.0, R)];
    let mut period = f64::NAN;
    while solver.state().t < 5.5 {
        let dt = solver.stable_dt();
        solver.step(dt).expect("stable");
        let (t, a) = (solver.state().t, a_of(&solver));
        let (t0, a0) = *curve.last().expect("non-empty");
        // Upward crossing of A = R after the minimum (t > 3): one full period.
        if t0 > 3.0 && a0 < R && a >= R {
            period = t0 + (R - a0) * (t - t0) / (a - a0);
            curve.push((t, a));
            break;
        }
        curve.push((t, a));
    }
    let (t_max, a_max) = curve
        .iter()
        .copied()
        .fold((0.0, 0.0), |b, p| if p.1 > b.1 { p } else { b });
    let mut worst: f64 = 0.0;
    for (t, a) in exact() {
        let k = curve.partition_point(|p| p.0 < t);
        if k == 0 || k >= curve.len() {
            continue;
        }
        let (p, q) = (curve[k - 1], curve[k]);
        let a_sph = p.1 + (q.1 - p.1) * (t - p.0) / (q.0 - p.0);
        worst = worst.max((a_sph - a).abs());
    }
    eprintln!(
        "drop R/dx = {n_radius}, c0 = {c0}, {} particles, {} steps: period {period:.4} (exact {T_EXACT}, error {:+.2} %), \
         A_max {a_max:.4} at t = {t_max:.3} (exact 1.41421), worst |A − A_exact| {worst:.4}",
        solver.state().len(),
        solver.state().step,
        100.0 * (period / T_EXACT - 1.0)
    );
    (period, a_max, t_max, worst)
}

#[test]
fn oscillating_drop_period() {
    let options = WcsphParams {
        mls: false,
        apd: 0.04,
        central_force: 0.0,
        ..Default::default()
    };
    let (period, a_max, _, worst) = run(20, 20.0, options, Some(20), 0.5);
    assert!((period / T_EXACT - 1.0).abs() < 0.03, "period {period}");
    // README case 4: A_max = 1.41421 R = √2 R.
    assert!((a_max - std::f64::consts::SQRT_2 * R).abs() < 0.03, "A_max {a_max}");
    assert!(worst < 0.05, "worst semi-axis error {worst}");
}
