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
    /// (default) is off.
    #[serde(default, skip_serializing_if = "super::is_zero")]
    pub mesh_damping: f64,
}

fn default_element() -> ElementKind {
    ElementKind::Quad4
}
