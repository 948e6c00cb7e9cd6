//! `[[solid]]`: an elastic rectangle, its element type, material and clamps.

use serde::{Deserialize, Serialize};

use super::BoxSpec;

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
    /// Young's modulus \[Pa\].
    pub youngs_modulus: f64,
    /// Poisson's ratio, in [0, 0.5).
    pub poisson_ratio: f64,
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
    /// Stiffness-proportional (Rayleigh β) damping given as the damping ratio ζ of the mesh's highest mode: the
    /// internal forces are taken at x + β v with β = ζ · min_e L_e / c_d of the reference mesh, so a mode of angular
    /// frequency ω is damped by the ratio β ω / 2 — ζ at the mesh's own scale (ω ≈ 2 c_d / L_e), a thousandth of it
    /// or less for the bending modes a scene looks at (`fem-node/src/solver/central_difference.rs`). In [0, 1); 0
    /// (default) is off for a solid held by a `fixed` box; a solid held nowhere takes [`FREE_MESH_DAMPING`] unless
    /// the scene gives it a value ([`SolidSpec::mesh_damping`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh_damping: Option<f64>,
}

/// The `mesh_damping` of a solid held nowhere that the scene gives none (2026-12-08, thirty-sixth session). Such a
/// body lands on floors and slams onto water, and the contact's and the walls' impulses ring its mesh's highest
/// modes, which an undamped explicit mesh keeps and, under coupling steps of changing length, grows. Measured on
/// free blocks dropped onto the shipped gate's surge (`docs/experiments/slam_sweep.py 1 16` and `5 10`, and the
/// thirty-fourth session's sweep block), the energy the coupled run made, in the water's releasable energy,
/// undamped → 0.02: 8.96 → 0.93, 1.66 → 0.02, 1.28 → 0.92, 0.93 → 0.35, 0.85 → 0.29, 0.21 → 0.002, never higher in
/// a run that ended `ok` (docs/CORRECTIONS.md "A solid held nowhere is damped at its mesh's scale"). A clamped solid
/// keeps 0: the hydrostatic plate's load swings more when its mesh is damped.
pub const FREE_MESH_DAMPING: f64 = 0.02;

impl SolidSpec {
    /// Whether the solid is held nowhere (no `fixed` box): gravity and the water move it as a whole, only the walls
    /// stop it (`crate::scene::unheld`), and what it can give the water by sinking counts in the fluid's energy guard.
    pub fn held_nowhere(&self) -> bool {
        self.fixed.is_empty()
    }

    /// The damping ratio at the mesh's highest mode in force: the scene's `mesh_damping`, or where it gives none
    /// [`FREE_MESH_DAMPING`] for a solid held nowhere and 0 for a clamped one.
    pub fn mesh_damping(&self) -> f64 {
        self.mesh_damping
            .unwrap_or(if self.held_nowhere() { FREE_MESH_DAMPING } else { 0.0 })
    }
}

fn default_element() -> ElementKind {
    ElementKind::Quad4
}
