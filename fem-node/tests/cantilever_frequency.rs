//! First bending frequency of a slender clamped beam against Euler–Bernoulli in plane strain
//! (`data/analytic_checks_COMPUTED.csv`, check 2): f₁ = (1.875104)² / (2π L²) · sqrt(D / (ρ h)),
//! D = E h³ / (12 (1 − ν²)).
//!
//! L = 1, h = 0.05 (L/h = 20, where shear and rotary inertia lower f₁ by ~0.1%), E = 1 MPa, ν = 0.3, ρ = 1000,
//! corotational linear elastic. The beam starts straight with the Euler–Bernoulli mode shape as velocity and a tip
//! amplitude of 1e-3 L; f₁ is read from the zero crossings of the tip deflection over three periods.

mod common;

use std::f64::consts::PI;

use common::*;
use cosim_proto::scene::{ElementKind, MaterialModel};

const BETA_L: f64 = 1.875104068711961;
const L: f64 = 1.0;
const H: f64 = 0.05;
const E: f64 = 1.0e6;
const NU: f64 = 0.3;
const RHO: f64 = 1000.0;

fn euler_bernoulli_frequency() -> f64 {
    let d = E * H.powi(3) / (12.0 * (1.0 - NU * NU));
    BETA_L * BETA_L / (2.0 * PI * L * L) * (d / (RHO * H)).sqrt()
}

/// First cantilever mode shape at `s = x / L` (1.3622 at the tip).
fn mode_shape(s: f64) -> f64 {
    let b = BETA_L;
    let sigma = (b.cosh() + b.cos()) / (b.sinh() + b.sin());
    (b * s).cosh() - (b * s).cos() - sigma * ((b * s).sinh() - (b * s).sin())
}

fn measured_frequency(element: ElementKind, divisions: [u32; 2]) -> f64 {
    let f_eb = euler_bernoulli_frequency();
    let spec = cantilever(
        [0.0, L],
        [-H / 2.0, H / 2.0],
        divisions,
        element,
        material(MaterialModel::LinearElastic, RHO, E, NU),
    );
    let mut s = solver(spec, [0.0, 0.0], 0.9);
    let v_tip = 1e-3 * L * 2.0 * PI * f_eb;
    s.set_velocities(|_, p| [0.0, v_tip * mode_shape(p[0] / L) / mode_shape(1.0)]);
    let tip = s.model().nearest_node(0, [L, 0.0]).unwrap();
    let mut uy = vec![(0.0, 0.0)];
    let sample = 1.0 / (400.0 * f_eb);
    for _ in 0..1200 {
        s.advance(sample).unwrap();
        uy.push((s.state().t, s.displacement(tip)[1]));
    }
    frequency_from_crossings(&uy, 0.0)
}

fn errors(element: ElementKind, meshes: [[u32; 2]; 3]) -> [f64; 3] {
    let f_eb = euler_bernoulli_frequency();
    meshes.map(|m| {
        let f = measured_frequency(element, m);
        let err = rel_err(f, f_eb);
        println!(
            "{element:?} {}x{}: f1 = {f:.6} Hz, Euler-Bernoulli {f_eb:.6} Hz, error {:.3}%",
            m[0],
            m[1],
            100.0 * err
        );
        err
    })
}

#[test]
fn quad4_first_frequency_within_2_percent_and_converging() {
    // One, two and four elements through the thickness (elements 2:1).
    let err = errors(ElementKind::Quad4, [[10, 1], [20, 2], [40, 4]]);
    assert!(err.iter().all(|&e| e < 0.02), "quad4 errors {err:?}");
    assert!(
        err[2] < err[1] && err[1] < err[0],
        "quad4 errors do not fall with refinement: {err:?}"
    );
}

#[test]
fn tri3_first_frequency_converges() {
    // Constant-strain triangles lock in bending: the error is large on coarse meshes and falls with refinement.
    let err = errors(ElementKind::Tri3, [[20, 2], [40, 4], [80, 8]]);
    assert!(
        err[2] < err[1] && err[1] < err[0],
        "tri3 errors do not fall with refinement: {err:?}"
    );
    assert!(err[2] < 0.05, "tri3 error on the finest mesh {:.2}%", 100.0 * err[2]);
}
