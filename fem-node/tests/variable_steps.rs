//! The structure's sub-step changes from one coupling step to the next (it is the coupling step, set by the fluid,
//! over a whole number of sub-steps), and the central difference at a step that changes so is unstable in the mesh's
//! highest modes, each step stable on its own: a product of symplectic maps of different steps grows (for one
//! oscillator at ω Δt = 1.8, steps varying by 10 % between calls: ×1e41 in 20,000 calls,
//! `docs/experiments/varying_steps_oscillator.py`). `solid.mesh_damping =
//! 0.02` (a damping ratio of 0.02 at the mesh's highest mode, what `cosim run` suggests after a run that made
//! energy) holds them (docs/CORRECTIONS.md "The structure's sub-steps of changing length").
//!
//! The case: the free 2,700 kg/m³ block of the coupled-scene sweep (87 × 39 mm, 40 × 20 cells, E = 12 MPa, ν = 0.4,
//! neo-Hookean) ringing, 3 m/s along its length and ±1 m/s node to node, as after its slam onto the water,
//! advanced to 0.2 s at the default `fem_cfl` 0.9 in coupling steps drawn from [1e-5, 6e-5] s (a WCSPH fluid's
//! steps after an impact were 2.1–5.5e-5 s), about 6,500 of them, against the same at a steady 3.5e-5 s. Measured
//! (2026-12-07):
//! undamped, a steady step keeps the energy (largest 1.023 / 1.009 of the start, tri3 / quad4) and changing steps
//! make it grow until an element inverts (tri3) or 17.6-fold (quad4); with ζ = 0.02 the energy ends at 0.615 of its
//! start at either (the damping takes the rough part of the field and some of the smooth one) and never passes it.

mod common;

use common::*;
use cosim_proto::scene::{ElementKind, MaterialModel};

/// The damping ratio at the mesh's highest mode that `cosim run` suggests.
const SUGGESTED: f64 = 0.02;

/// A pseudo-random number in [0, 1) from `i` (Weyl sequence and a multiply-shift: the same draws on every machine).
fn draw(i: u64, salt: u64) -> f64 {
    let x = (i.wrapping_add(salt)).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ salt.wrapping_mul(0xD1B5_4A32_D192_ED03);
    (x.wrapping_mul(0xBF58_476D_1CE4_E5B9) >> 11) as f64 / (1u64 << 53) as f64
}

/// (largest, last) total energy over its start for the ringing block advanced in coupling steps of changing length
/// (`changing`) or of 3.5e-5 s each; infinite where an element inverted.
fn ringing_block(element: ElementKind, mesh_damping: f64, changing: bool) -> (f64, f64) {
    let mut spec = cantilever(
        [0.0, 0.0867],
        [0.0, 0.0392],
        [40, 20],
        element,
        material(MaterialModel::NeoHookean, 2700.0, 12.0e6, 0.4),
    );
    spec.fixed.clear();
    spec.mesh_damping = Some(mesh_damping);
    let mut s = solver(spec, [0.0, 0.0], 0.9);
    // A smooth field (the block's first modes, 3 m/s) and a rough one (±1 m/s node to node: 13 % of the energy).
    s.set_velocities(|i, p| {
        let smooth = 3.0 * (2.0 * std::f64::consts::PI * p[0] / 0.0867).cos();
        [
            2.0 * (draw(i as u64, 1) - 0.5),
            smooth + 2.0 * (draw(i as u64, 2) - 0.5),
        ]
    });
    let e0 = s.total_energy();
    let (mut largest, mut call) = (1.0f64, 0u64);
    while s.state().t < 0.2 {
        call += 1;
        let dt = if changing { 1e-5 + 5e-5 * draw(call, 3) } else { 3.5e-5 };
        if s.advance(dt).is_err() {
            // An element inverted: the energy grew without bound.
            return (f64::INFINITY, f64::INFINITY);
        }
        largest = largest.max(s.total_energy() / e0);
    }
    (largest, s.total_energy() / e0)
}

#[test]
fn mesh_damping_holds_the_highest_modes_under_changing_steps() {
    for element in [ElementKind::Tri3, ElementKind::Quad4] {
        let (steady_max, _) = ringing_block(element, 0.0, false);
        let (changing_max, _) = ringing_block(element, 0.0, true);
        let (_, damped_steady_end) = ringing_block(element, SUGGESTED, false);
        let (damped_max, damped_end) = ringing_block(element, SUGGESTED, true);
        println!(
            "{element:?}: undamped largest E/E0 {steady_max:.3} at a steady step, {changing_max:.3} at changing steps; \
             ζ = {SUGGESTED}: energy at the end {damped_steady_end:.4} at a steady step, {damped_end:.4} at changing \
             steps (largest {damped_max:.4})"
        );
        // Undamped, the steady step keeps the energy and the changing steps make it grow many times over.
        assert!(
            steady_max < 1.03,
            "{element:?}: undamped at a steady step, the energy reached {steady_max:.3}"
        );
        assert!(
            changing_max > 5.0,
            "{element:?}: undamped at changing steps, the energy grew only {changing_max:.3}-fold"
        );
        // Damped, the changing steps make nothing: the energy never passes its start and ends where the steady
        // step's does (the damping takes the same share of the rough field either way).
        assert!(
            damped_max < 1.01,
            "{element:?}: damped, the energy reached {damped_max:.4} of its start"
        );
        assert!(
            (damped_end / damped_steady_end - 1.0).abs() < 0.01,
            "{element:?}: damped, {damped_end:.4} at changing steps against {damped_steady_end:.4} at a steady one"
        );
    }
}
