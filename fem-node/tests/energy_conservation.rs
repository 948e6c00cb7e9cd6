//! Undamped free vibration keeps its total energy (kinetic + strain + potential) within 1% over 100 periods.
//!
//! The Turek bar (L = 0.35, h = 0.02, E = 1.4 MPa, ν = 0.4, ρ = 1000, 35 × 2 cells) starts straight with a velocity
//! field `v_y = V (x/L)²` and a tip speed V = 0.7 m/s (tip swing about ±0.1 m, i.e. large rotations), and is
//! followed for 95 s, at least 100 periods of its first mode.

mod common;

use common::*;
use cosim_proto::scene::{ElementKind, MaterialModel};

fn max_energy_drift(element: ElementKind, model: MaterialModel, gravity: [f64; 2]) -> f64 {
    let spec = cantilever(
        [0.0, 0.35],
        [-0.01, 0.01],
        [35, 2],
        element,
        material(model, 1000.0, 1.4e6, 0.4),
    );
    let mut s = solver(spec, gravity, 0.9);
    s.set_velocities(|_, p| [0.0, 0.7 * (p[0] / 0.35).powi(2)]);
    let e0 = s.total_energy();
    let tip = s.model().nearest_node(0, [0.35, 0.0]).unwrap();
    let mut worst: f64 = 0.0;
    let mut uy = Series::new();
    let t_end = 95.0;
    while s.state().t < t_end {
        s.advance(0.01).unwrap();
        worst = worst.max((s.total_energy() - e0).abs() / e0);
        uy.push((s.state().t, s.displacement(tip)[1]));
    }
    let (mean, amp) = mean_amplitude(&uy, 0.0, t_end);
    let f = frequency_from_crossings(&uy, mean);
    let periods = t_end * f;
    println!(
        "{element:?} {model:?} g={gravity:?}: E0 = {e0:.4e} J/m, tip uy {mean:.4} +- {amp:.4} m, {periods:.1} periods, \
         max |E - E0|/E0 = {worst:.3e}"
    );
    assert!(periods >= 100.0, "only {periods} periods");
    worst
}

#[test]
fn quad4_st_venant_kirchhoff_with_gravity() {
    let drift = max_energy_drift(ElementKind::Quad4, MaterialModel::StVenantKirchhoff, [0.0, -2.0]);
    assert!(drift < 0.01, "energy drift {drift}");
}

#[test]
fn quad4_neo_hookean() {
    let drift = max_energy_drift(ElementKind::Quad4, MaterialModel::NeoHookean, [0.0, 0.0]);
    assert!(drift < 0.01, "energy drift {drift}");
}

#[test]
fn tri3_corotational_linear_elastic() {
    let drift = max_energy_drift(ElementKind::Tri3, MaterialModel::LinearElastic, [0.0, 0.0]);
    assert!(drift < 0.01, "energy drift {drift}");
}
