//! `[fluid]`: the solver, its corrections and the blocks of water.

use serde::{Deserialize, Serialize};

use super::BoxSpec;

/// Fluid solver.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FluidSolver {
    /// Weakly compressible SPH (`DESIGN.md` §4.2).
    Wcsph,
    /// Incompressible SPH, projection method (§4.3).
    Isph,
}

/// Density filter (§4.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DensityFilter {
    /// None.
    None,
    /// Shepard filter.
    Shepard,
    /// First-order moving least squares.
    Mls,
}

/// Source term of the ISPH pressure Poisson equation (`DESIGN.md` §4.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PpeSourceKind {
    /// ∇·u*/Δt (Cummins & Rudman 1999), with a small density-invariant relaxation.
    DivergenceFree,
    /// (ρ0 − ρ*)/(ρ0 Δt²) (Shao & Lo 2003).
    DensityInvariant,
}

/// `[fluid]` (`DESIGN.md` §5.1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidSpec {
    /// Solver.
    #[serde(default = "default_fluid_solver")]
    pub solver: FluidSolver,
    /// Rest density ρ0 [kg/m³].
    pub density: f64,
    /// Kinematic viscosity ν [m²/s]; 0 disables the viscous term.
    #[serde(default)]
    pub kinematic_viscosity: f64,
    /// Particle spacing Δx \[m\].
    pub spacing: f64,
    /// h = smoothing_ratio · spacing.
    #[serde(default = "default_smoothing_ratio")]
    pub smoothing_ratio: f64,
    /// Speed of sound c0 [m/s] (WCSPH); default 10·sqrt(2 g H) with H the highest fluid block top.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sound_speed: Option<f64>,
    /// α of the Monaghan artificial viscosity, Eq. (11).
    #[serde(default = "default_artificial_viscosity")]
    pub artificial_viscosity: f64,
    /// Density filter; default Shepard for WCSPH, none for ISPH.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density_filter: Option<DensityFilter>,
    /// Steps between density filter passes.
    #[serde(default = "default_filter_interval")]
    pub density_filter_interval: u32,
    /// XSPH ε; 0 disables.
    #[serde(default = "default_xsph")]
    pub xsph: f64,
    /// APD β (§4.4; 0 disables). Default per solver ([`FluidSpec::apd`]): the paper's 0.04 for WCSPH; 0 for ISPH,
    /// where the shift is available but not yet the default (docs/CORRECTIONS.md).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub apd: Option<f64>,
    /// δ of the δ-SPH density diffusion in the continuity equation (Molteni & Colagrossi 2009, with the hydrostatic
    /// correction of Fourtakas et al. 2019; WCSPH only), in [0, 1]; 0, the default, disables it (0.1 is the usual
    /// value). Not written to `scene.toml` when 0.
    #[serde(default, skip_serializing_if = "super::is_zero")]
    pub density_diffusion: f64,
    /// Skin of the WCSPH neighbour search's Verlet candidate lists, in units of h (WCSPH only), in [0, 1]: the
    /// candidates within the kernel support plus the skin are gathered from the cells and kept until a particle
    /// has moved half the skin, and each step's lists are filtered from them. Default [`WCSPH_VERLET_SKIN_DEFAULT`];
    /// 0 searches the cells every step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verlet_skin: Option<f64>,
    /// ISPH pressure Poisson source (isph only); default divergence_free.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ppe_source: Option<PpeSourceKind>,
    /// Relative tolerance of the ISPH pressure solve (isph only): BiCGSTAB stops when the Jacobi-scaled residual
    /// ‖D⁻¹(b − A p)‖ is at most this times ‖D⁻¹ b‖. In [1e-12, 1e-3]; default [`ISPH_PPE_TOLERANCE_DEFAULT`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ppe_tolerance: Option<f64>,
    /// Safety factor on the fluid's stable step: the node steps at `cfl` times the step of `DESIGN.md` §4.2
    /// (WCSPH: min of the acoustic, force and viscous limits) or §4.3 (ISPH: C h / v_max with the same force and
    /// viscous limits). In (0, 1], default 1 (the limit itself); a value above 1 is refused, since the limit is
    /// already the largest step the schemes are stable at. Not written to `scene.toml` when 1.
    #[serde(default = "default_fluid_cfl", skip_serializing_if = "is_default_fluid_cfl")]
    pub cfl: f64,
    /// Regions filled with particles at rest (`[[fluid.block]]`).
    #[serde(rename = "block")]
    pub blocks: Vec<BoxSpec>,
}

fn default_fluid_solver() -> FluidSolver {
    FluidSolver::Wcsph
}

fn default_smoothing_ratio() -> f64 {
    1.3
}

fn default_artificial_viscosity() -> f64 {
    0.01
}

fn default_filter_interval() -> u32 {
    20
}

fn default_xsph() -> f64 {
    0.5
}

fn default_fluid_cfl() -> f64 {
    1.0
}

fn is_default_fluid_cfl(cfl: &f64) -> bool {
    *cfl == default_fluid_cfl()
}

/// APD β of WCSPH when the scene names none: the paper's (Long et al. 2016 after Ozbulut et al. 2013 and Xu et al.
/// 2009).
pub const WCSPH_APD_DEFAULT: f64 = 0.04;

/// Skin of the WCSPH Verlet candidate lists (units of h) when the scene names none (`fluid.verlet_skin`).
pub const WCSPH_VERLET_SKIN_DEFAULT: f64 = 0.2;

/// APD β of ISPH when the scene names none: the paper's, as for WCSPH.
pub const ISPH_APD_DEFAULT: f64 = 0.04;

/// Tolerance of the ISPH pressure solve when the scene names none (`fluid.ppe_tolerance`). 1e-6: at 1e-8 the solve
/// took 40 % more iterations for impact pressures, levels and coupled results that moved within their bounds and
/// their run-to-run scatter (docs/VALIDATION.md, 2026-11-29 fourteenth).
pub const ISPH_PPE_TOLERANCE_DEFAULT: f64 = 1e-6;

/// The range `fluid.ppe_tolerance` may take.
pub const ISPH_PPE_TOLERANCE_RANGE: std::ops::RangeInclusive<f64> = 1e-12..=1e-3;

impl FluidSpec {
    /// The ISPH pressure solve's relative tolerance: the scene's, or [`ISPH_PPE_TOLERANCE_DEFAULT`].
    pub fn ppe_tolerance(&self) -> f64 {
        self.ppe_tolerance.unwrap_or(ISPH_PPE_TOLERANCE_DEFAULT)
    }

    /// The WCSPH search's Verlet skin in units of h: the scene's, or [`WCSPH_VERLET_SKIN_DEFAULT`] (0 for ISPH,
    /// which does not use it).
    pub fn verlet_skin(&self) -> f64 {
        self.verlet_skin.unwrap_or(match self.solver {
            FluidSolver::Wcsph => WCSPH_VERLET_SKIN_DEFAULT,
            FluidSolver::Isph => 0.0,
        })
    }

    /// APD β in force: the scene's, or the per-solver default (WCSPH [`WCSPH_APD_DEFAULT`], ISPH
    /// [`ISPH_APD_DEFAULT`]).
    pub fn apd(&self) -> f64 {
        self.apd.unwrap_or(match self.solver {
            FluidSolver::Wcsph => WCSPH_APD_DEFAULT,
            FluidSolver::Isph => ISPH_APD_DEFAULT,
        })
    }

    /// The density filter in force (the per-solver default of §4.4 when the scene names none).
    pub fn density_filter(&self) -> DensityFilter {
        self.density_filter.unwrap_or(match self.solver {
            FluidSolver::Wcsph => DensityFilter::Shepard,
            FluidSolver::Isph => DensityFilter::None,
        })
    }
}
