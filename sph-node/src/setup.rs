//! Initial particles from the scene's `[fluid]` (`DESIGN.md` §5.1): `[[fluid.block]]` boxes filled on a lattice
//! of spacing Δx with cell-centred particles (first particle at min + Δx/2), mass ρ0 Δx², at rest with the
//! hydrostatic pressure p = ρ0 |g| (H_top − y) and the matching density from the inverse Tait law; the wall particles
//! and boxes of the scene's `[[wall]]`s and the domain around them ([`FluidSetup`], shared by the solvers).

use cosim_proto::scene::{BoxSpec, FluidSolver, FluidSpec, Scene};

use crate::boundary::wall_guard::WallBoxes;
use crate::boundary::walls;
use crate::eos::Tait;
use crate::error::{Result, SphError};
use crate::params::SphParams;
use crate::particles::{FluidState, WallParticles};

/// What every fluid solver builds from the scene: the particles, the walls, and the parameters they share.
#[derive(Clone, Debug)]
pub struct FluidSetup {
    /// Fluid particles at rest, hydrostatic (see [`initial_state`]).
    pub state: FluidState,
    /// Wall particles of the `[[wall]]` boxes (pressure 0, density ρ0, mass ρ0 Δx²).
    pub walls: WallParticles,
    /// The `[[wall]]` boxes as filled by the wall particles (guard and repulsion).
    pub wall_boxes: WallBoxes,
    /// Shared parameters; the domain is the box around blocks and walls, padded (see [`FluidSetup::new`]).
    pub params: SphParams,
}

/// The scene's `[fluid]`; `Err` names the key.
pub fn fluid_spec_any(scene: &Scene) -> Result<&FluidSpec> {
    scene.fluid.as_ref().ok_or_else(|| SphError::InvalidScene {
        key: "fluid".into(),
        message: "the scene has no [fluid] section".into(),
    })
}

/// The scene's `[fluid]`, which must ask for `solver`; `Err` names the key.
pub fn fluid_spec(scene: &Scene, solver: FluidSolver) -> Result<&FluidSpec> {
    let spec = fluid_spec_any(scene)?;
    if spec.solver != solver {
        return Err(SphError::InvalidScene {
            key: "fluid.solver".into(),
            message: format!("this solver needs fluid.solver = \"{}\"", solver_name(solver)),
        });
    }
    Ok(spec)
}

/// The scene's name of `solver` (`fluid.solver`).
pub fn solver_name(solver: FluidSolver) -> &'static str {
    match solver {
        FluidSolver::Wcsph => "wcsph",
        FluidSolver::Isph => "isph",
    }
}

impl FluidSetup {
    /// Fill the blocks of `spec` (the scene's `[fluid]`) with particles whose densities follow from their
    /// hydrostatic pressures by `eos`, and the scene's walls with wall particles. The domain is the box around blocks
    /// and walls padded by half its largest extent plus 4h, or by `reach` where that is more (a solver whose particles
    /// can travel further in the run).
    pub fn new(scene: &Scene, spec: &FluidSpec, eos: &Tait, reach: f64) -> Self {
        let gravity = scene.run.gravity;
        let dx = spec.spacing;
        let h = spec.smoothing_ratio * dx;
        let state = initial_state(spec, gravity, eos);
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for b in spec.blocks.iter().chain(&scene.walls) {
            for k in 0..2 {
                lo[k] = lo[k].min(b.min[k]);
                hi[k] = hi[k].max(b.max[k]);
            }
        }
        let fluid_centre = {
            let n = state.len().max(1) as f64;
            let s = state.x.iter().fold([0.0; 2], |s, p| [s[0] + p[0], s[1] + p[1]]);
            [s[0] / n, s[1] / n]
        };
        let wall_x = walls::wall_positions(&scene.walls, spec.blocks[0].min, dx, h, fluid_centre);
        let nw = wall_x.len();
        let walls = WallParticles {
            x: wall_x,
            p: vec![0.0; nw],
            rho: vec![spec.density; nw],
            m: vec![spec.density * dx * dx; nw],
        };
        let wall_boxes = WallBoxes::new(&scene.walls, dx, h, fluid_centre);
        // Domain: the box around blocks and walls, padded by half its largest extent.
        let pad = (0.5 * (hi[0] - lo[0]).max(hi[1] - lo[1]) + 4.0 * h).max(reach);
        let domain = BoxSpec {
            min: [lo[0] - pad, lo[1] - pad],
            max: [hi[0] + pad, hi[1] + pad],
        };
        let params = SphParams {
            rho0: spec.density,
            dx,
            h,
            nu: spec.kinematic_viscosity,
            gravity,
            xsph: spec.xsph,
            domain,
        };
        Self {
            state,
            walls,
            wall_boxes,
            params,
        }
    }
}

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
