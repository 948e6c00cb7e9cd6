//! `solid.mesh_damping`: stiffness-proportional (Rayleigh β) damping, β = ζ · min_e L_e / c_d, the internal forces
//! taken at x + β v. Against the analytic modal damping ratio β ω / 2 (Belytschko, Liu & Moran, Nonlinear Finite
//! Elements, §6.2.4), the damped stable step `√(1 + ζ²) − ζ` of the undamped one (their Eq. 6.2.32), and the linear
//! momentum of a free body kept to round-off.

mod common;

use std::f64::consts::PI;

use common::*;
use cosim_proto::scene::{ElementKind, MaterialModel, SolidSpec};
use fem_node::{FemModel, FemSolver};

const BETA_L: f64 = 1.875104068711961;
/// A stubby cantilever, so that its first mode is not too far below the mesh's highest one: L = 0.2 m, h =
/// 0.05 m, 8 × 2 square cells of 25 mm.
const L: f64 = 0.2;
const H: f64 = 0.05;
const CELL: f64 = 0.025;
const E: f64 = 1.0e6;
const NU: f64 = 0.3;
const RHO: f64 = 1000.0;

fn beam(mesh_damping: f64) -> SolidSpec {
    let mut spec = cantilever(
        [0.0, L],
        [-H / 2.0, H / 2.0],
        [8, 2],
        ElementKind::Quad4,
        material(MaterialModel::LinearElastic, RHO, E, NU),
    );
    spec.mesh_damping = Some(mesh_damping);
    spec
}

/// c_d = sqrt((λ + 2μ) / ρ) in plane strain.
fn wave_speed() -> f64 {
    let p_wave = E * (1.0 - NU) / ((1.0 + NU) * (1.0 - 2.0 * NU));
    (p_wave / RHO).sqrt()
}

/// β the scene's ζ asks for: ζ times the square cell's characteristic length (area over its diagonal, a/√2) over c_d.
fn beta(zeta: f64) -> f64 {
    zeta * CELL / 2f64.sqrt() / wave_speed()
}

/// First cantilever mode shape at `s = x / L`.
fn mode_shape(s: f64) -> f64 {
    let b = BETA_L;
    let sigma = (b.cosh() + b.cos()) / (b.sinh() + b.sin());
    (b * s).cosh() - (b * s).cos() - sigma * ((b * s).sinh() - (b * s).sin())
}

/// (ω₁, the damping ratio ζ₁) of the tip's free vibration: ω₁ from the zero crossings, ζ₁ from the least-squares
/// slope of ln(peak) against time over the positive peaks after the first two periods (slope = −ζ₁ ω₁).
fn free_vibration(mesh_damping: f64, periods: f64) -> (f64, f64) {
    let mut s = solver(beam(mesh_damping), [0.0, 0.0], 0.9);
    let tip = s.model().nearest_node(0, [L, 0.0]).unwrap();
    // 1e-4 L at the tip: small enough for the corotational law to stay linear.
    s.set_velocities(|_, p| [0.0, 1e-4 * mode_shape(p[0] / L) / mode_shape(1.0)]);
    // The Euler–Bernoulli period, only to size the sampling: this beam's own (shear-softer) period is longer.
    let d = E * H.powi(3) / (12.0 * (1.0 - NU * NU));
    let period = 2.0 * PI * L * L / (BETA_L * BETA_L) / (d / (RHO * H)).sqrt();
    let sample = period / 200.0;
    let mut uy: Series = vec![(0.0, 0.0)];
    for _ in 0..(periods * 200.0) as usize {
        s.advance(sample).unwrap();
        uy.push((s.state().t, s.displacement(tip)[1]));
    }
    let omega = 2.0 * PI * frequency_from_crossings(&uy, 0.0);
    let peaks: Vec<(f64, f64)> = uy
        .windows(3)
        .filter(|w| w[1].1 > 0.0 && w[1].1 >= w[0].1 && w[1].1 > w[2].1 && w[1].0 > 2.0 * period)
        .map(|w| (w[1].0, w[1].1.ln()))
        .collect();
    assert!(peaks.len() >= 8, "only {} peaks", peaks.len());
    let n = peaks.len() as f64;
    let (mt, my) = peaks.iter().fold((0.0, 0.0), |(a, b), p| (a + p.0 / n, b + p.1 / n));
    let (sxy, sxx) = peaks.iter().fold((0.0, 0.0), |(a, b), p| {
        (a + (p.0 - mt) * (p.1 - my), b + (p.0 - mt).powi(2))
    });
    (omega, -sxy / sxx / omega)
}

#[test]
fn the_first_bending_mode_decays_at_beta_omega_over_two() {
    let zeta = 0.5;
    let (omega, measured) = free_vibration(zeta, 16.0);
    let expected = beta(zeta) * omega / 2.0;
    println!(
        "mesh_damping {zeta}: ω₁ = {omega:.3} rad/s, ζ₁ = {measured:.5e}, β ω₁ / 2 = {expected:.5e} (β = {:.4e} s)",
        beta(zeta)
    );
    assert!(
        rel_err(measured, expected) < 0.05,
        "ζ₁ {measured:e} against β ω₁ / 2 = {expected:e}"
    );
    // Undamped, the same beam keeps its amplitude: the decay above is the damping's.
    let (omega0, undamped) = free_vibration(0.0, 16.0);
    println!("undamped: ω₁ = {omega0:.3} rad/s, ζ₁ = {undamped:.2e}");
    assert!(undamped.abs() < 0.02 * expected, "undamped ζ₁ {undamped:e}");
    // Stiffness-proportional damping leaves the frequency of a lightly damped mode: ω_d = ω √(1 − ζ₁²).
    assert!(rel_err(omega, omega0) < 1e-3, "ω₁ {omega} damped against {omega0}");
}

#[test]
fn the_stable_step_shrinks_by_the_damped_factor() {
    let undamped = FemSolver::new(FemModel::from_solids(&[beam(0.0)], [0.0; 2]).unwrap(), 0.9).unwrap();
    for zeta in [0.1, 0.25, 0.5, 0.9] {
        let model = FemModel::from_solids(&[beam(zeta)], [0.0; 2]).unwrap();
        assert!(rel_err(model.solids()[0].stiffness_damping, beta(zeta)) < 1e-12);
        let damped = FemSolver::new(model, 0.9).unwrap();
        let ratio = damped.stable_dt() / undamped.stable_dt();
        let expected = (1.0 + zeta * zeta).sqrt() - zeta;
        assert!(
            (ratio - expected).abs() < 1e-12,
            "ζ = {zeta}: ratio {ratio}, expected {expected}"
        );
    }
}

#[test]
fn a_free_body_keeps_its_momentum_and_loses_its_mesh_scale_energy() {
    let free = |zeta: f64| {
        let mut spec = beam(zeta);
        spec.fixed.clear();
        let mut s = solver(spec, [0.0, 0.0], 0.9);
        // A deterministic rough velocity field: most of its energy in the mesh's short modes.
        let mut seed = 12345u64;
        let mut rand = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let v: Vec<[f64; 2]> = (0..s.model().node_count()).map(|_| [rand(), rand()]).collect();
        s.set_velocities(|k, _| [1e-3 * v[k][0], 1e-3 * v[k][1]]);
        s
    };
    let momentum = |s: &FemSolver| {
        let m = s.model().masses();
        let v = &s.state().v;
        (0..m.len()).fold([0.0, 0.0, 0.0], |p, k| {
            [
                p[0] + m[k] * v[k][0],
                p[1] + m[k] * v[k][1],
                p[2] + m[k] * v[k][0].hypot(v[k][1]),
            ]
        })
    };
    let (mut damped, mut undamped) = (free(0.5), free(0.0));
    let p0 = momentum(&damped);
    let (e0, e0_undamped) = (damped.total_energy(), undamped.total_energy());
    damped.advance(0.05).unwrap();
    undamped.advance(0.05).unwrap();
    let p = momentum(&damped);
    for d in 0..2 {
        assert!(
            (p[d] - p0[d]).abs() <= 1e-12 * p0[2],
            "momentum {d}: {} → {} (scale {})",
            p0[d],
            p[d],
            p0[2]
        );
    }
    let (e, e_undamped) = (damped.total_energy() / e0, undamped.total_energy() / e0_undamped);
    println!(
        "after 0.05 s (sound crosses {:.0} cells): energy {e:.4} of its start damped, {e_undamped:.4} undamped",
        0.05 * wave_speed() / CELL
    );
    // Undamped, the central difference's energy at whole steps (kinetic energy of v^n) swings by a few per cent for
    // a field this rough, and does not fall.
    assert!((e_undamped - 1.0).abs() < 0.1, "undamped energy {e_undamped}");
    assert!(e < 0.2, "damped energy {e} of its start");
}
