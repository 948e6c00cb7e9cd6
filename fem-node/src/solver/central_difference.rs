//! Explicit central-difference integration with a lumped mass matrix, in kick–drift–kick form so that positions
//! and velocities sit at the same (full) time levels:
//!
//! `v^{n+½} = v^n + Δt/2 a^n`, `x^{n+1} = x^n + Δt v^{n+½}`,
//! `a^{n+1} = M⁻¹ (f_ext − f_int(x^{n+1})) − c v^{n+½}`, `v^{n+1} = v^{n+½} + Δt/2 a^{n+1}`.
//!
//! This is the central difference of Eq. (3), Long et al. 2016 (`v^{n+½} = v^{n−½} + Δt a^n` once the two
//! half kicks are merged). Clamped nodes keep `x = X`, `v = 0`, `a = 0`. A node the drift takes into a tank wall is
//! put back on its surface and `v^{n+½}` loses its component into the wall (`crate::walls`).
//!
//! Stiffness-proportional (Rayleigh β) damping, where a solid has it (`mesh_damping`): `f_int` is taken at
//! `x + β v` (with `v^{n+½}` in a step, as the mass-proportional term), which is `f_int(x) + β K(x) v + O(β²)`, the
//! damping force `β K v` of any element and material without forming `K` (Belytschko, Liu & Moran, Nonlinear Finite
//! Elements, §6.2.4: a mode of angular frequency ω is damped by the ratio `β ω / 2`). Internal forces sum to zero
//! at any positions, so the damping keeps the linear momentum.

use crate::element::ElementFailure;
use crate::model::FemModel;
use crate::solver::internal_forces::internal_forces;
use crate::state::{FemScratch, FemState};

/// `a = g − f_int / m − c v` on free nodes (zero on clamped ones), from the forces in `scratch.internal` and the
/// velocities `v`.
pub fn accelerations(model: &FemModel, v: &[[f64; 2]], scratch: &FemScratch, a: &mut [[f64; 2]]) {
    let g = model.gravity();
    let solids = model.solids();
    let node_solid = model.node_solid();
    for k in 0..a.len() {
        if model.fixed()[k] {
            a[k] = [0.0; 2];
            continue;
        }
        let inv_m = 1.0 / model.masses()[k];
        let c = solids[node_solid[k] as usize].damping;
        let f = scratch.internal[k];
        // Eq. (3) with lumped M, f_ext = m g (Eq. (5)), and mass-proportional damping −c m v.
        a[k] = [g[0] - f[0] * inv_m - c * v[k][0], g[1] - f[1] * inv_m - c * v[k][1]];
    }
}

/// Fills `scratch.internal` with the internal forces of positions `x` and velocities `v`: `f_int(x)`, or
/// `f_int(x + β v)` for the nodes of a solid with stiffness-proportional damping β (module docs).
fn damped_internal_forces(
    model: &FemModel,
    x: &[[f64; 2]],
    v: &[[f64; 2]],
    scratch: &mut FemScratch,
    parallel_min_elements: usize,
) -> Result<(), (usize, ElementFailure)> {
    if !model.stiffness_damped() {
        return internal_forces(model, x, scratch, parallel_min_elements);
    }
    let mut shifted = std::mem::take(&mut scratch.damped_positions);
    shifted.clear();
    let solids = model.solids();
    shifted.extend(x.iter().zip(v).zip(model.node_solid()).map(|((x, v), &s)| {
        let beta = solids[s as usize].stiffness_damping;
        [x[0] + beta * v[0], x[1] + beta * v[1]]
    }));
    let result = internal_forces(model, &shifted, scratch, parallel_min_elements);
    scratch.damped_positions = shifted;
    result
}

/// Recomputes `state.a` from `state.x` and `state.v`.
pub fn refresh_accelerations(
    model: &FemModel,
    state: &mut FemState,
    scratch: &mut FemScratch,
    parallel_min_elements: usize,
) -> Result<(), (usize, ElementFailure)> {
    damped_internal_forces(model, &state.x, &state.v, scratch, parallel_min_elements)?;
    accelerations(model, &state.v, scratch, &mut state.a);
    Ok(())
}

/// One sub-step of length `dt`. Advances `state.t` and `state.step`.
pub fn step(
    model: &FemModel,
    state: &mut FemState,
    scratch: &mut FemScratch,
    dt: f64,
    parallel_min_elements: usize,
) -> Result<(), (usize, ElementFailure)> {
    let half = 0.5 * dt;
    let nodes = state
        .x
        .iter_mut()
        .zip(state.v.iter_mut())
        .zip(&state.a)
        .zip(model.reference().iter().zip(model.fixed()));
    for (((x, v), a), (reference, &fixed)) in nodes {
        if fixed {
            *x = *reference;
            *v = [0.0; 2];
            continue;
        }
        v[0] += half * a[0];
        v[1] += half * a[1];
        x[0] += dt * v[0];
        x[1] += dt * v[1];
    }
    // The walls stop the nodes the drift took into them (`crate::walls`), before the forces at x^{n+1}.
    if let Some(walls) = model.walls() {
        walls.apply(&mut state.x, &mut state.v);
    }
    // The damping forces use v^{n+½}, the latest velocity known before the closing kick.
    damped_internal_forces(model, &state.x, &state.v, scratch, parallel_min_elements)?;
    accelerations(model, &state.v, scratch, &mut state.a);
    for (v, a) in state.v.iter_mut().zip(&state.a) {
        v[0] += half * a[0];
        v[1] += half * a[1];
    }
    state.t += dt;
    state.step += 1;
    Ok(())
}
