//! Dam break, column a × 2a (Martin & Moyce 1952, n² = 2), WCSPH and ISPH: surge front Z = z/a against
//! T = t sqrt(2g/a) (files in scenes/data/ and tests/data/, sources in scenes/data/README.md and tests/data/SOURCE.txt).
//!
//! Two references, two checks:
//! * Koshizuka & Oka's (1996) MPS computation of the same case: an independent particle method with an
//!   instantaneous release, like ours. Z within 5 % for T ≤ 2.5.
//! * The Martin & Moyce experiment (all three digitisations of the n² = 2 series). Every computation with an
//!   instantaneous release leads it: the column in the experiment was released by removing a diaphragm, so its
//!   time origin is not the start of free collapse. We compare with the experiment's time axis shifted by ΔT₀,
//!   the offset that aligns the MPS computation with the experiment (least squares over the experimental points,
//!   computed here from the two data files: it is a property of the references, not fitted to our result). Once
//!   the front has moved 0.2 a (Z ≥ 1.2, T ≳ 0.8) Z is within 5 % for T ≤ 2.5 after the shift. Before that the
//!   one early experimental point (T = 0.41, Z = 1.11) agrees *unshifted* (the diaphragm does not delay the first
//!   creep of the front, only the bulk acceleration), and is checked unshifted. The unshifted lead over the
//!   whole range (10–20 %) is printed and guarded below 20 %.

mod common;

use sph_node::core::solver_from_scene;
use sph_node::FluidSolver;

const A: f64 = 0.1;
const G: f64 = 9.81;
const T_MAX: f64 = 2.5;

fn curve(text: &str) -> Vec<(f64, f64)> {
    text.lines()
        .skip(1)
        .filter_map(|l| {
            let mut it = l.split(',').map(|v| v.trim().parse::<f64>());
            Some((it.next()?.ok()?, it.next()?.ok()?))
        })
        .collect()
}

/// The Martin & Moyce n² = 2 points with 0 < T ≤ 2.5, from the three digitisations.
fn experiment() -> Vec<(f64, f64)> {
    [
        include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../scenes/data/mm1952_n2eq2_a2.25in_pysph.csv"
        )),
        include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../scenes/data/mm1952_n2eq2_a1.125in_pysph.csv"
        )),
        include_str!("data/mm1952_n2eq2_lethe.csv"),
    ]
    .into_iter()
    .flat_map(curve)
    .filter(|p| p.0 > 0.0 && p.0 <= T_MAX)
    .collect()
}

fn mps() -> Vec<(f64, f64)> {
    curve(include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/data/koshizuka_oka1996_MPS_front_pysph.csv"
    )))
}

/// Linear interpolation of y(x) on a curve sorted by x.
fn interpolate(curve: &[(f64, f64)], x: f64) -> f64 {
    let k = curve.partition_point(|p| p.0 < x).clamp(1, curve.len() - 1);
    let (a, b) = (curve[k - 1], curve[k]);
    a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0)
}

/// Z from which the experiment is compared on the shifted time axis (the front has moved 0.2 a).
const Z_RELEASED: f64 = 1.2;

/// ΔT₀: the mean over the experimental points with Z ≥ [`Z_RELEASED`] of
/// T_exp − T_mps(Z_exp), with T_mps(Z) from inverting the monotone MPS curve.
fn release_offset() -> f64 {
    let inverse: Vec<(f64, f64)> = mps().into_iter().map(|(t, z)| (z, t)).collect();
    let shifts: Vec<f64> = experiment()
        .into_iter()
        .filter(|p| p.1 >= Z_RELEASED)
        .map(|(t, z)| t - interpolate(&inverse, z))
        .collect();
    shifts.iter().sum::<f64>() / shifts.len() as f64
}

/// Surge front: the rightmost fluid particle near the floor, plus half a spacing (so Z(0) = 1).
fn front(fluid: &dyn FluidSolver, dx: f64) -> f64 {
    let s = fluid.state();
    s.x.iter()
        .filter(|x| x[1] < 0.25 * A)
        .map(|x| x[0])
        .fold(f64::NEG_INFINITY, f64::max)
        + 0.5 * dx
}

/// Runs to T = 2.6 at Δx = a/40 and returns (T, Z) every step.
fn surge(extra: &str) -> Vec<(f64, f64)> {
    let dx = A / 40.0;
    let mut fluid = solver_from_scene(&common::dam_break(A, 5.0 * A, dx, extra)).expect("solver");
    let scale = (2.0 * G / A).sqrt();
    let mut out = vec![(0.0, front(fluid.as_ref(), dx) / A)];
    while fluid.state().t * scale < T_MAX + 0.1 {
        let dt = fluid.stable_dt();
        fluid.step(dt).expect("stable");
        out.push((fluid.state().t * scale, front(fluid.as_ref(), dx) / A));
    }
    out
}

/// Worst |Z_sim(T − shift) − Z_ref(T)| / Z_ref(T) over `reference`, printing each point.
fn worst_error(name: &str, sim: &[(f64, f64)], reference: &[(f64, f64)], shift: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for &(t, z) in reference.iter().filter(|p| p.0 <= T_MAX) {
        let zs = interpolate(sim, t - shift);
        let err = (zs - z) / z;
        eprintln!(
            "{name}: T = {t:.3}: Z_sph = {zs:.3}, Z_ref = {z:.3}, error {:+.1} %",
            100.0 * err
        );
        worst = worst.max(err.abs());
    }
    eprintln!("{name}: worst relative error for T <= {T_MAX}: {:.1} %", 100.0 * worst);
    worst
}

fn check(solver: &str, extra: &str) {
    let sim = surge(extra);
    let shift = release_offset();
    eprintln!("release offset from MPS vs experiment: ΔT0 = {shift:.3}");
    let vs_mps = worst_error(&format!("{solver} vs MPS"), &sim, &mps(), 0.0);
    let (released, early): (Vec<_>, Vec<_>) = experiment().into_iter().partition(|p| p.1 >= Z_RELEASED);
    let vs_exp = worst_error(&format!("{solver} vs experiment, shifted"), &sim, &released, shift);
    let vs_early = worst_error(&format!("{solver} vs experiment, early"), &sim, &early, 0.0);
    let unshifted = worst_error(&format!("{solver} vs experiment, unshifted"), &sim, &experiment(), 0.0);
    assert!(vs_mps < 0.05, "{solver}: worst error against the MPS front {vs_mps}");
    assert!(
        vs_exp < 0.05,
        "{solver}: worst error against the experiment (ΔT0 = {shift}) {vs_exp}"
    );
    assert!(
        vs_early < 0.05,
        "{solver}: worst error against the early experiment {vs_early}"
    );
    assert!(
        unshifted < 0.20,
        "{solver}: worst error against the unshifted experiment {unshifted}"
    );
}

#[test]
fn wcsph_surge_front() {
    check("WCSPH", "");
}

#[test]
fn isph_surge_front() {
    check("ISPH", "solver = \"isph\"");
}
