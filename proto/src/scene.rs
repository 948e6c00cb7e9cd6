//! Scene files (TOML, SI units): the types of `DESIGN.md` §5.1, loading with `--set` overrides, and validation.
//!
//! Every user error is a [`SceneError`]: one line naming the file, the dotted key and the problem.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::overlap;
use crate::overrides;
use crate::sizing::Sizing;

/// The scene format version this build reads.
pub const SCENE_VERSION: u32 = 1;

/// A whole scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Format version; must be [`SCENE_VERSION`].
    pub version: u32,
    /// Run-wide settings.
    pub run: RunSpec,
    /// Water (`[fluid]`); absent for a structure-only run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fluid: Option<FluidSpec>,
    /// Rigid walls (`[[wall]]`), filled with fixed boundary particles.
    #[serde(default, rename = "wall", skip_serializing_if = "Vec::is_empty")]
    pub walls: Vec<BoxSpec>,
    /// Elastic structures (`[[solid]]`).
    #[serde(default, rename = "solid", skip_serializing_if = "Vec::is_empty")]
    pub solids: Vec<SolidSpec>,
    /// Contact algorithm settings.
    #[serde(default)]
    pub contact: ContactSpec,
    /// Coupling (step) settings.
    #[serde(default)]
    pub coupling: CouplingSpec,
    /// Probes sampled every `run.output_interval` (`[[probe]]`).
    #[serde(default, rename = "probe", skip_serializing_if = "Vec::is_empty")]
    pub probes: Vec<ProbeSpec>,
}

/// `[run]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    /// Name used in outputs.
    pub name: String,
    /// Simulated end time [s].
    pub end_time: f64,
    /// Gravity [m/s²].
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 2],
    /// Interval between frames and probe samples [s].
    pub output_interval: f64,
}

fn default_gravity() -> [f64; 2] {
    [0.0, -9.81]
}

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
    /// Particle spacing Δx [m].
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
    #[serde(default, skip_serializing_if = "is_zero")]
    pub density_diffusion: f64,
    /// ISPH pressure Poisson source (isph only); default divergence_free.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ppe_source: Option<PpeSourceKind>,
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

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

fn is_default_fluid_cfl(cfl: &f64) -> bool {
    *cfl == default_fluid_cfl()
}

/// APD β of WCSPH when the scene names none: the paper's (Long et al. 2016 after Ozbulut et al. 2013 and Xu et al.
/// 2009).
pub const WCSPH_APD_DEFAULT: f64 = 0.04;

/// APD β of ISPH when the scene names none: the paper's, as for WCSPH.
pub const ISPH_APD_DEFAULT: f64 = 0.04;

impl FluidSpec {
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

/// Finite element type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ElementKind {
    /// 4-node quadrilateral, one-point integration with hourglass control.
    Quad4,
    /// 3-node constant-strain triangle.
    Tri3,
}

/// Constitutive model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MaterialModel {
    /// Small-strain Hooke's law in a corotational frame (large rotations stay exact).
    LinearElastic,
    /// Compressible neo-Hookean.
    NeoHookean,
    /// St. Venant–Kirchhoff (the Turek–Hron benchmarks use it).
    StVenantKirchhoff,
}

/// `material = { ... }` of a solid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Model.
    pub model: MaterialModel,
    /// Density [kg/m³].
    pub density: f64,
    /// Young's modulus [Pa].
    pub youngs_modulus: f64,
    /// Poisson's ratio, in [0, 0.5).
    pub poisson_ratio: f64,
}

/// An axis-aligned box.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec {
    /// Lower corner.
    pub min: [f64; 2],
    /// Upper corner.
    pub max: [f64; 2],
}

impl BoxSpec {
    /// True if `p` lies inside the box (bounds included).
    pub fn contains(&self, p: [f64; 2]) -> bool {
        (0..2).all(|k| p[k] >= self.min[k] && p[k] <= self.max[k])
    }
}

/// `[[solid]]`: a rectangle meshed with `divisions[0] × divisions[1]` cells.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolidSpec {
    /// Unique name, referenced by probes.
    pub name: String,
    /// Lower corner of the rectangle.
    pub min: [f64; 2],
    /// Upper corner of the rectangle.
    pub max: [f64; 2],
    /// Cells along x and y.
    pub divisions: [u32; 2],
    /// Element type; `tri3` splits each cell into two triangles.
    #[serde(default = "default_element")]
    pub element: ElementKind,
    /// Material.
    pub material: MaterialSpec,
    /// Nodes inside any of these boxes are clamped.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fixed: Vec<BoxSpec>,
    /// Mass-proportional damping coefficient [1/s] (force −c·m·v); 0 (default) is undamped.
    #[serde(default)]
    pub damping: f64,
}

fn default_element() -> ElementKind {
    ElementKind::Quad4
}

impl SolidSpec {
    /// Number of grid nodes along x and y.
    pub fn grid_size(&self) -> [usize; 2] {
        [self.divisions[0] as usize + 1, self.divisions[1] as usize + 1]
    }

    /// Reference position of grid node (i, j); node numbering is `j * nx + i`.
    pub fn grid_node(&self, i: usize, j: usize) -> [f64; 2] {
        let [nx, ny] = self.grid_size();
        let fx = i as f64 / (nx - 1) as f64;
        let fy = j as f64 / (ny - 1) as f64;
        [
            self.min[0] + (self.max[0] - self.min[0]) * fx,
            self.min[1] + (self.max[1] - self.min[1]) * fy,
        ]
    }

    /// All grid nodes in numbering order.
    pub fn grid_nodes(&self) -> Vec<[f64; 2]> {
        let [nx, ny] = self.grid_size();
        (0..ny)
            .flat_map(|j| (0..nx).map(move |i| (i, j)))
            .map(|(i, j)| self.grid_node(i, j))
            .collect()
    }

    /// Whether a grid node lies in `b` (bounds included), found per axis without listing the nodes: the grid is
    /// the product of two rows of coordinates, each increasing with its index (a binary search for the first at or
    /// above the box's lower bound).
    pub fn has_node_in(&self, b: &BoxSpec) -> bool {
        let n = self.grid_size();
        (0..2).all(|k| {
            let at = |i: usize| {
                if k == 0 {
                    self.grid_node(i, 0)[0]
                } else {
                    self.grid_node(0, i)[1]
                }
            };
            let (mut lo, mut hi) = (0, n[k]);
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                (lo, hi) = if at(mid) < b.min[k] { (mid + 1, hi) } else { (lo, mid) };
            }
            lo < n[k] && at(lo) <= b.max[k]
        })
    }

    /// Number of elements the mesh will have.
    pub fn element_count(&self) -> usize {
        let cells = self.divisions[0] as usize * self.divisions[1] as usize;
        match self.element {
            ElementKind::Quad4 => cells,
            ElementKind::Tri3 => 2 * cells,
        }
    }
}

/// Contact algorithm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactAlgorithm {
    /// Long et al. 2016 particle–element contact.
    ParticleElement,
    /// Repulsive-force baseline.
    ParticleParticle,
    /// No contact.
    None,
}

impl ContactAlgorithm {
    /// The scene spelling (`particle_element` | `particle_particle` | `none`).
    pub fn name(self) -> &'static str {
        match self {
            ContactAlgorithm::ParticleElement => "particle_element",
            ContactAlgorithm::ParticleParticle => "particle_particle",
            ContactAlgorithm::None => "none",
        }
    }
}

/// `[contact]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Algorithm.
    #[serde(default = "default_algorithm")]
    pub algorithm: ContactAlgorithm,
    /// Contact thickness r_c [m]; default spacing / 2.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<f64>,
    /// Gauss–Seidel sweeps.
    #[serde(default = "default_sweeps")]
    pub sweeps: u32,
    /// Whether the position correction also moves the structure's nodes (λ N_a / m_a, `DESIGN.md` §4.5 as
    /// written). Off by default: the structure takes its share of the *velocity* correction (the momentum), and
    /// its displacement follows from its own dynamics; moving FE nodes by a share of the penetration that goes
    /// with 1/m rather than with 1/stiffness puts strain energy ½ k δ² into stiff structures that no contact
    /// had (the hydrostatic plate inverts an element within 120 steps with it on).
    #[serde(default)]
    pub move_structure: bool,
}

fn default_algorithm() -> ContactAlgorithm {
    ContactAlgorithm::ParticleElement
}

fn default_sweeps() -> u32 {
    3
}

impl Default for ContactSpec {
    fn default() -> Self {
        Self {
            algorithm: default_algorithm(),
            thickness: None,
            sweeps: default_sweeps(),
            move_structure: false,
        }
    }
}

/// `[coupling]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CouplingSpec {
    /// Cap on the coupling step [s].
    #[serde(default = "default_max_dt")]
    pub max_dt: f64,
    /// Safety factor on the FEM stable step, Δt_fem = fem_cfl · min_e(L_e / c_d).
    #[serde(default = "default_fem_cfl")]
    pub fem_cfl: f64,
    /// Seconds a node may take to answer one step before the run fails.
    #[serde(default = "default_step_timeout")]
    pub step_timeout: f64,
}

fn default_max_dt() -> f64 {
    1.0e-3
}

fn default_fem_cfl() -> f64 {
    0.9
}

fn default_step_timeout() -> f64 {
    60.0
}

impl Default for CouplingSpec {
    fn default() -> Self {
        Self {
            max_dt: default_max_dt(),
            fem_cfl: default_fem_cfl(),
            step_timeout: default_step_timeout(),
        }
    }
}

/// Probe kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ProbeKind {
    /// Displacement of the FE node nearest `point` (reference configuration), `component` x or y.
    NodeDisplacement,
    /// Energy: `part` = kinetic | strain | potential | total, of `solid` (one solid), or of `of` = structure |
    /// fluid | all (default all).
    Energy,
    /// Extreme fluid particle coordinate along `component` (the front of a dam break).
    SurgeFront,
    /// Highest fluid particle among those with x ≤ `x_max` (the residual column of a dam break).
    ColumnHeight,
    /// SPH-interpolated pressure at `point`.
    Pressure,
}

/// Which bodies an energy probe sums over.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EnergyOf {
    /// Every solid.
    Structure,
    /// The water.
    Fluid,
    /// Both.
    All,
}

/// A vector component.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Component {
    /// x.
    X,
    /// y.
    Y,
}

impl Component {
    /// Index into a 2-vector.
    pub fn index(self) -> usize {
        match self {
            Component::X => 0,
            Component::Y => 1,
        }
    }
}

/// Energy part.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EnergyPart {
    /// ½ m v².
    Kinetic,
    /// Stored elastic energy.
    Strain,
    /// −m g·x relative to the reference configuration.
    Potential,
    /// Sum of the three.
    Total,
}

/// `[[probe]]`. Flat so that a missing or misplaced key gets a precise message.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    /// Column name in `probes.csv`.
    pub name: String,
    /// Kind.
    pub kind: ProbeKind,
    /// Solid name (node_displacement; optional for energy).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub solid: Option<String>,
    /// Point (node_displacement).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<[f64; 2]>,
    /// Component (node_displacement).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub component: Option<Component>,
    /// Energy part (energy).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub part: Option<EnergyPart>,
    /// Bodies an energy probe covers (energy; default all).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub of: Option<EnergyOf>,
    /// Column probes look at particles with x ≤ x_max (column_height).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x_max: Option<f64>,
    /// Reference data drawn in the plot: a CSV file (relative to the scene file) and its columns.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<ReferenceSpec>,
}

/// Reference curve for a probe's plot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    /// CSV file with a header row; relative paths are relative to the scene file.
    pub file: String,
    /// Column holding time.
    pub t: String,
    /// Column holding the value.
    pub value: String,
    /// Label in the legend.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
    /// Multiply the value column by this (e.g. to change units).
    #[serde(default = "one")]
    pub scale: f64,
    /// Multiply the time column by this (e.g. to turn a dimensionless time into seconds).
    #[serde(default = "one")]
    pub t_scale: f64,
    /// Add this to the time column (after scaling).
    #[serde(default)]
    pub t_offset: f64,
}

fn one() -> f64 {
    1.0
}

/// A user error in a scene: one line naming the file, the key and the problem.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}: {key}: {message}")]
pub struct SceneError {
    /// Scene file (or `--set` for an override).
    pub file: String,
    /// Dotted key path, e.g. `solid[0].material.youngs_modulus`.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl SceneError {
    fn new(file: &str, key: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            file: file.to_string(),
            key: key.into(),
            message: message.into(),
        }
    }
}

/// A scene with where it came from.
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// The validated scene.
    pub scene: Scene,
    /// The file it was read from.
    pub path: PathBuf,
}

impl LoadedScene {
    /// Resolve a path written in the scene (relative to the scene file's folder).
    pub fn resolve(&self, relative: &str) -> PathBuf {
        let p = Path::new(relative);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.path.parent().unwrap_or(Path::new(".")).join(p)
        }
    }
}

/// Read, override and validate a scene file. `overrides` are `key.path=value` strings (`--set`).
pub fn load(path: &Path, overrides: &[String]) -> Result<LoadedScene, SceneError> {
    let file = path.display().to_string();
    let text =
        std::fs::read_to_string(path).map_err(|e| SceneError::new(&file, "(file)", format!("cannot read: {e}")))?;
    let scene = parse(&file, &text, overrides)?;
    Ok(LoadedScene {
        scene,
        path: path.to_path_buf(),
    })
}

/// Parse, override and validate scene text; `file` names it in errors.
pub fn parse(file: &str, text: &str, overrides: &[String]) -> Result<Scene, SceneError> {
    let mut value: toml::Value = toml::from_str(text).map_err(|e| syntax_error(file, text, &e))?;
    for o in overrides {
        overrides::apply(&mut value, o).map_err(|(key, msg)| SceneError::new(file, format!("--set {key}"), msg))?;
    }
    let scene: Scene = serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner().to_string();
        let (key, message) = key_of_serde_error(&path, &inner);
        SceneError::new(file, key, message)
    })?;
    scene.validate().map_err(|(key, msg)| SceneError::new(file, key, msg))?;
    Ok(scene)
}

/// One line for a TOML syntax error: the line number and toml's own message.
fn syntax_error(file: &str, text: &str, e: &toml::de::Error) -> SceneError {
    let key = match e.span() {
        Some(span) => format!("line {}", text[..span.start.min(text.len())].matches('\n').count() + 1),
        None => "(syntax)".to_string(),
    };
    SceneError::new(file, key, e.message().replace('\n', " "))
}

/// Make the key of a serde error the full dotted path of the offending field.
fn key_of_serde_error(path: &str, message: &str) -> (String, String) {
    let parent = if path == "." { String::new() } else { path.to_string() };
    // serde_path_to_error already ends the path with an unknown field, but not with a missing one.
    let join = |field: &str| {
        if parent.is_empty() {
            field.to_string()
        } else if parent == field || parent.ends_with(&format!(".{field}")) {
            parent.clone()
        } else {
            format!("{parent}.{field}")
        }
    };
    let field_in = |prefix: &str| {
        message
            .strip_prefix(prefix)
            .and_then(|rest| rest.split('`').next())
            .map(str::to_string)
    };
    if let Some(field) = field_in("unknown field `") {
        return (join(&field), "unknown key".to_string());
    }
    if let Some(field) = field_in("missing field `") {
        return (join(&field), "missing key".to_string());
    }
    let key = if parent.is_empty() {
        "(top level)".to_string()
    } else {
        parent
    };
    (key, message.replace('\n', " "))
}

type Invalid = (String, String);

fn check(ok: bool, key: impl FnOnce() -> String, message: impl FnOnce() -> String) -> Result<(), Invalid> {
    if ok {
        Ok(())
    } else {
        Err((key(), message()))
    }
}

fn finite_positive(key: &str, v: f64) -> Result<(), Invalid> {
    check(
        v.is_finite() && v > 0.0,
        || key.to_string(),
        || format!("must be a positive number, got {v}"),
    )
}

/// The fluid section: positive sizes, a sensible smoothing ratio, blocks that hold particles and stay out of walls.
fn validate_fluid(f: &FluidSpec, walls: &[BoxSpec], solids: &[SolidSpec]) -> Result<(), Invalid> {
    finite_positive("fluid.density", f.density)?;
    finite_positive("fluid.spacing", f.spacing)?;
    check(
        f.kinematic_viscosity.is_finite() && f.kinematic_viscosity >= 0.0,
        || "fluid.kinematic_viscosity".into(),
        || format!("must be zero or positive, got {}", f.kinematic_viscosity),
    )?;
    check(
        (1.0..=2.0).contains(&f.smoothing_ratio),
        || "fluid.smoothing_ratio".into(),
        || format!("must be in [1, 2] (h = ratio x spacing), got {}", f.smoothing_ratio),
    )?;
    if let Some(c) = f.sound_speed {
        finite_positive("fluid.sound_speed", c)?;
    }
    check(
        f.cfl.is_finite() && f.cfl > 0.0 && f.cfl <= 1.0,
        || "fluid.cfl".into(),
        || {
            format!(
                "must be in (0, 1] (a factor on the stable step of DESIGN.md §4.2/§4.3; above 1 the fluid is \
                 stepped past its stability limit), got {}",
                f.cfl
            )
        },
    )?;
    check(
        f.artificial_viscosity.is_finite() && f.artificial_viscosity >= 0.0,
        || "fluid.artificial_viscosity".into(),
        || format!("must be zero or positive, got {}", f.artificial_viscosity),
    )?;
    check(
        f.density_filter_interval >= 1,
        || "fluid.density_filter_interval".into(),
        || "must be at least 1".into(),
    )?;
    check(
        f.xsph.is_finite() && (0.0..=1.0).contains(&f.xsph),
        || "fluid.xsph".into(),
        || format!("must be in [0, 1], got {}", f.xsph),
    )?;
    check(
        f.apd().is_finite() && (0.0..=1.0).contains(&f.apd()),
        || "fluid.apd".into(),
        || format!("must be in [0, 1], got {}", f.apd()),
    )?;
    check(
        f.density_diffusion.is_finite() && (0.0..=1.0).contains(&f.density_diffusion),
        || "fluid.density_diffusion".into(),
        || {
            format!(
                "must be in [0, 1] (δ of δ-SPH; 0.1 is usual), got {}",
                f.density_diffusion
            )
        },
    )?;
    check(
        f.density_diffusion == 0.0 || f.solver == FluidSolver::Wcsph,
        || "fluid.density_diffusion".into(),
        || "applies to solver = \"wcsph\" only (ISPH takes its pressure from the Poisson equation)".into(),
    )?;
    if f.solver == FluidSolver::Isph {
        check(
            f.density_filter() == DensityFilter::None,
            || "fluid.density_filter".into(),
            || "ISPH takes no density filter (its pressure comes from the Poisson equation); set \"none\"".into(),
        )?;
    } else {
        check(
            f.ppe_source.is_none(),
            || "fluid.ppe_source".into(),
            || "applies to solver = \"isph\" only".into(),
        )?;
    }
    check(
        !f.blocks.is_empty(),
        || "fluid.block".into(),
        || "at least one [[fluid.block]] is needed".into(),
    )?;
    for (b, block) in f.blocks.iter().enumerate() {
        let key = || format!("fluid.block[{b}]");
        check(
            (0..2).all(|k| block.min[k].is_finite() && block.max[k].is_finite()),
            key,
            || "corners must be finite".into(),
        )?;
        check((0..2).all(|k| block.max[k] - block.min[k] >= f.spacing), key, || {
            format!(
                "holds no particle: min {:?} max {:?} is narrower than the spacing {}",
                block.min, block.max, f.spacing
            )
        })?;
        for (w, wall) in walls.iter().enumerate() {
            // Overlap of more than half a spacing in both directions: particles would sit inside the wall.
            let overlap =
                (0..2).all(|k| block.max[k].min(wall.max[k]) - block.min[k].max(wall.min[k]) > 0.5 * f.spacing);
            check(!overlap, key, || {
                format!("overlaps wall[{w}] (min {:?} max {:?})", wall.min, wall.max)
            })?;
        }
        for solid in solids {
            // The same rule against a solid's rectangle: particles inside a structure would be pushed out by
            // the contact in the first step, with an impulse no physics asked for.
            let overlap =
                (0..2).all(|k| block.max[k].min(solid.max[k]) - block.min[k].max(solid.min[k]) > 0.5 * f.spacing);
            check(!overlap, key, || {
                format!(
                    "overlaps solid `{}` (min {:?} max {:?})",
                    solid.name, solid.min, solid.max
                )
            })?;
        }
    }
    Ok(())
}

impl Scene {
    /// Checks every value a solver relies on. Returns the dotted key and the problem.
    pub fn validate(&self) -> Result<(), (String, String)> {
        check(
            self.version == SCENE_VERSION,
            || "version".into(),
            || {
                format!(
                    "this build reads version {SCENE_VERSION}, the file says {}",
                    self.version
                )
            },
        )?;
        check(
            !self.run.name.trim().is_empty(),
            || "run.name".into(),
            || "must not be empty".into(),
        )?;
        check(
            self.fluid.is_some() || self.walls.is_empty(),
            || "wall".into(),
            || "walls hold water: a scene with [[wall]] needs a [fluid]".into(),
        )?;
        check(
            self.fluid.is_some() || !self.solids.is_empty(),
            || "solid".into(),
            || "nothing to run: the scene has no [[solid]] and no [fluid]".into(),
        )?;
        finite_positive("run.end_time", self.run.end_time)?;
        finite_positive("run.output_interval", self.run.output_interval)?;
        check(
            self.run.gravity.iter().all(|g| g.is_finite()),
            || "run.gravity".into(),
            || "must be finite".into(),
        )?;
        finite_positive("coupling.max_dt", self.coupling.max_dt)?;
        finite_positive("coupling.step_timeout", self.coupling.step_timeout)?;
        check(
            // Above 0.94 elongated tri3 meshes go unstable (their characteristic length is an estimate).
            self.coupling.fem_cfl > 0.0 && self.coupling.fem_cfl <= 0.9,
            || "coupling.fem_cfl".into(),
            || format!("must be in (0, 0.9], got {}", self.coupling.fem_cfl),
        )?;
        if let Some(t) = self.contact.thickness {
            finite_positive("contact.thickness", t)?;
        }
        check(
            self.contact.sweeps >= 1,
            || "contact.sweeps".into(),
            || "must be at least 1".into(),
        )?;
        if let Some(fluid) = &self.fluid {
            validate_fluid(fluid, &self.walls, &self.solids)?;
        }
        for (w, wall) in self.walls.iter().enumerate() {
            check(
                (0..2).all(|k| wall.min[k].is_finite() && wall.max[k].is_finite() && wall.max[k] > wall.min[k]),
                || format!("wall[{w}].max"),
                || {
                    format!(
                        "must be greater than min in every component, got min {:?} max {:?}",
                        wall.min, wall.max
                    )
                },
            )?;
        }
        let mut solids = HashSet::with_capacity(self.solids.len());
        for (s, solid) in self.solids.iter().enumerate() {
            Self::validate_solid(s, solid)?;
            check(
                solids.insert(solid.name.as_str()),
                || format!("solid[{s}].name"),
                || format!("`{}` is used by another solid", solid.name),
            )?;
        }
        let rects: Vec<overlap::Rect> = self.solids.iter().map(|s| (s.min, s.max)).collect();
        if let Some((a, b)) = overlap::first_overlap(&rects) {
            let (first, second) = (&self.solids[a], &self.solids[b]);
            return Err((
                format!("solid[{b}]"),
                format!(
                    "`{}` (min {:?} max {:?}) overlaps solid[{a}] `{}` (min {:?} max {:?}): solids may touch along \
                     an edge but not share area",
                    second.name, second.min, second.max, first.name, first.min, first.max
                ),
            ));
        }
        let mut names = HashSet::with_capacity(self.probes.len());
        for (p, probe) in self.probes.iter().enumerate() {
            let key = |k: &str| format!("probe[{p}].{k}");
            check(
                !probe.name.trim().is_empty() && !probe.name.contains(','),
                || key("name"),
                || "must be non-empty and contain no comma".into(),
            )?;
            check(
                names.insert(probe.name.as_str()),
                || key("name"),
                || format!("`{}` is used by another probe", probe.name),
            )?;
            let finite = |v: &[f64]| v.iter().all(|v| v.is_finite());
            check(
                probe.point.is_none_or(|p| finite(&p)),
                || key("point"),
                || format!("must be finite, got {:?}", probe.point.unwrap_or_default()),
            )?;
            check(
                probe.x_max.is_none_or(f64::is_finite),
                || key("x_max"),
                || format!("must be finite, got {}", probe.x_max.unwrap_or_default()),
            )?;
            if let Some(name) = &probe.solid {
                check(
                    solids.contains(name.as_str()),
                    || key("solid"),
                    || format!("no solid named `{name}` (solids: {})", self.solid_names()),
                )?;
            }
            match probe.kind {
                ProbeKind::NodeDisplacement => {
                    check(
                        probe.solid.is_some(),
                        || key("solid"),
                        || "missing key (node_displacement)".into(),
                    )?;
                    check(
                        probe.point.is_some(),
                        || key("point"),
                        || "missing key (node_displacement)".into(),
                    )?;
                    check(
                        probe.component.is_some(),
                        || key("component"),
                        || "missing key (node_displacement)".into(),
                    )?;
                }
                ProbeKind::Energy => {
                    check(probe.part.is_some(), || key("part"), || "missing key (energy)".into())?;
                }
                ProbeKind::SurgeFront | ProbeKind::ColumnHeight | ProbeKind::Pressure => {
                    check(
                        self.fluid.is_some(),
                        || key("kind"),
                        || "needs a [fluid] in the scene".into(),
                    )?;
                    let (needed, present) = match probe.kind {
                        ProbeKind::SurgeFront => ("component", probe.component.is_some()),
                        ProbeKind::ColumnHeight => ("x_max", probe.x_max.is_some_and(f64::is_finite)),
                        _ => ("point", probe.point.is_some()),
                    };
                    check(
                        present,
                        || key(needed),
                        || format!("missing key ({:?})", probe.kind).to_lowercase(),
                    )?;
                    if let (ProbeKind::ColumnHeight, Some(x_max), Some(fluid)) = (probe.kind, probe.x_max, &self.fluid)
                    {
                        // The first column of particles of a block is half a spacing inside it (sph-node setup).
                        let first = fluid
                            .blocks
                            .iter()
                            .map(|b| b.min[0] + 0.5 * fluid.spacing)
                            .fold(f64::INFINITY, f64::min);
                        check(
                            x_max >= first,
                            || key("x_max"),
                            || {
                                format!(
                                    "{x_max} is left of every fluid particle (the first are at x = {first}): the \
                                     column would be empty from the start"
                                )
                            },
                        )?;
                    }
                }
            }
            if let Some(r) = &probe.reference {
                finite_positive(&key("reference.scale"), r.scale.abs())?;
                for (k, v) in [("t_scale", r.t_scale), ("t_offset", r.t_offset)] {
                    check(
                        v.is_finite(),
                        || key(&format!("reference.{k}")),
                        || format!("must be finite, got {v}"),
                    )?;
                }
            }
        }
        // Last: the counts are meaningful once every number above is known to be finite and positive.
        Sizing::of(self).check_counts()
    }

    fn solid_names(&self) -> String {
        if self.solids.is_empty() {
            return "none".into();
        }
        self.solids
            .iter()
            .map(|s| s.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    }

    fn validate_solid(s: usize, solid: &SolidSpec) -> Result<(), Invalid> {
        let key = |k: &str| format!("solid[{s}].{k}");
        check(
            !solid.name.trim().is_empty(),
            || key("name"),
            || "must not be empty".into(),
        )?;
        for k in 0..2 {
            check(
                solid.min[k].is_finite() && solid.max[k].is_finite() && solid.max[k] > solid.min[k],
                || key("max"),
                || {
                    format!(
                        "must be greater than min in every component, got min {:?} max {:?}",
                        solid.min, solid.max
                    )
                },
            )?;
            check(
                solid.divisions[k] > 0,
                || key("divisions"),
                || format!("must be at least 1 in every component, got {:?}", solid.divisions),
            )?;
        }
        let m = &solid.material;
        finite_positive(&key("material.density"), m.density)?;
        finite_positive(&key("material.youngs_modulus"), m.youngs_modulus)?;
        check(
            m.poisson_ratio.is_finite() && (0.0..0.5).contains(&m.poisson_ratio),
            || key("material.poisson_ratio"),
            || format!("must be in [0, 0.5), got {}", m.poisson_ratio),
        )?;
        check(
            solid.damping.is_finite() && solid.damping >= 0.0,
            || key("damping"),
            || format!("must be zero or positive, got {}", solid.damping),
        )?;
        for (f, b) in solid.fixed.iter().enumerate() {
            check(
                b.min.iter().chain(&b.max).all(|v| v.is_finite()),
                || key(&format!("fixed[{f}]")),
                || format!("corners must be finite, got min {:?} max {:?}", b.min, b.max),
            )?;
            check(
                solid.has_node_in(b),
                || key(&format!("fixed[{f}]")),
                || format!("box min {:?} max {:?} holds no node of the mesh", b.min, b.max),
            )?;
        }
        Ok(())
    }

    /// Total FE nodes and elements.
    pub fn fem_counts(&self) -> (usize, usize) {
        self.solids.iter().fold((0, 0), |(n, e), s| {
            let [nx, ny] = s.grid_size();
            (n + nx * ny, e + s.element_count())
        })
    }

    /// The scene as TOML text (used to hand the resolved scene to the nodes).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a validated scene serialises")
    }
}
