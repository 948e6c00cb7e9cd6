//! Initial particles from the scene's `[fluid]` (`DESIGN.md` §5.1): `[[fluid.block]]` boxes filled on a lattice
//! of spacing Δx with cell-centred particles (first particle at min + Δx/2), mass ρ0 Δx², at rest with the
//! hydrostatic pressure p = ρ0 |g| (H_top − y) and the matching density from the inverse Tait law.

use cosim_proto::scene::{BoxSpec, FluidSpec};

use crate::eos::Tait;
use crate::error::{Result, SphError};
use crate::particles::FluidState;

/// Highest block top H_top and lowest block bottom.
pub fn fluid_extent(spec: &FluidSpec) -> (f64, f64) {
    let top = spec.blocks.iter().map(|b| b.max[1]).fold(f64::NEG_INFINITY, f64::max);
    let bottom = spec.blocks.iter().map(|b| b.min[1]).fold(f64::INFINITY, f64::min);
    (top, bottom)
}

/// c0: the scene's value, else 10 sqrt(2 |g| H) with H the depth from the lowest block bottom to the highest
/// block top (`DESIGN.md` §4.2, c0 ≥ 10 v_max).
pub fn sound_speed(spec: &FluidSpec, gravity: [f64; 2]) -> Result<f64> {
    if let Some(c) = spec.sound_speed {
        return Ok(c);
    }
    let (top, bottom) = fluid_extent(spec);
    let g = gravity[0].hypot(gravity[1]);
    let c0 = 10.0 * (2.0 * g * (top - bottom)).sqrt();
    if c0.is_finite() && c0 > 0.0 {
        Ok(c0)
    } else {
        Err(SphError::InvalidScene {
            key: "fluid.sound_speed".into(),
            message: "cannot default to 10 sqrt(2 g H) without gravity; give a value".into(),
        })
    }
}

/// Lattice points x = min + (k + ½) Δx inside `block`.
pub fn block_positions(block: &BoxSpec, dx: f64) -> Vec<[f64; 2]> {
    let n = [0, 1].map(|k| ((block.max[k] - block.min[k]) / dx + 1e-9).floor() as usize);
    let mut out = Vec::with_capacity(n[0] * n[1]);
    for iy in 0..n[1] {
        for ix in 0..n[0] {
            out.push([
                block.min[0] + (ix as f64 + 0.5) * dx,
                block.min[1] + (iy as f64 + 0.5) * dx,
            ]);
        }
    }
    out
}

/// The initial fluid state: particles at rest in hydrostatic equilibrium (gravity along −y assumed for the
/// pressure; a zero or sideways gravity gives p = 0).
pub fn initial_state(spec: &FluidSpec, gravity: [f64; 2], eos: &Tait) -> FluidState {
    let (top, _) = fluid_extent(spec);
    let dx = spec.spacing;
    let x: Vec<[f64; 2]> = spec.blocks.iter().flat_map(|b| block_positions(b, dx)).collect();
    let g_down = (-gravity[1]).max(0.0);
    // DESIGN.md §4.2 / case 7.1: hydrostatic p = ρ0 g (H − y), ρ from the inverse Tait law
    let p: Vec<f64> = x.iter().map(|q| spec.density * g_down * (top - q[1])).collect();
    let rho: Vec<f64> = p.iter().map(|&p| eos.density(p)).collect();
    let n = x.len();
    FluidState {
        t: 0.0,
        step: 0,
        v: vec![[0.0; 2]; n],
        m: vec![spec.density * dx * dx; n],
        x,
        rho,
        p,
    }
}
