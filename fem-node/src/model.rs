//! The immutable structure model: reference mesh, elements, materials, masses, clamps, gravity.

use std::ops::Range;

use cosim_proto::messages::Segment;
use cosim_proto::scene::{ElementKind, Scene, SolidSpec};

use crate::element::{Element, Quad4, Tri3};
use crate::error::{FemError, Result};
use crate::material::Material;
use crate::mesh::{structured_mesh, Cell};
use crate::walls::WallStop;

/// One solid of the model.
#[derive(Clone, Debug, PartialEq)]
pub struct SolidModel {
    /// Name from the scene.
    pub name: String,
    /// Constitutive law.
    pub material: Material,
    /// Density [kg/m³].
    pub density: f64,
    /// Mass-proportional damping coefficient [1/s].
    pub damping: f64,
    /// Stiffness-proportional damping time β [s]: the internal forces are taken at x + β v
    /// (`solver::central_difference`); `mesh_damping` × the shortest L_e / c_d of the reference mesh.
    pub stiffness_damping: f64,
    /// Element type.
    pub element: ElementKind,
    /// Its global node ids.
    pub nodes: Range<usize>,
    /// Its global element ids.
    pub elements: Range<usize>,
}

impl SolidModel {
    /// Dilatational wave speed `c_d = sqrt((λ + 2μ) / ρ)` [m/s].
    pub fn wave_speed(&self) -> f64 {
        (self.material.lame().p_wave_modulus() / self.density).sqrt()
    }
}

/// Everything about the structure that does not change during a run.
#[derive(Clone, Debug, PartialEq)]
pub struct FemModel {
    solids: Vec<SolidModel>,
    reference: Vec<[f64; 2]>,
    elements: Vec<Element>,
    element_solid: Vec<u32>,
    node_solid: Vec<u32>,
    masses: Vec<f64>,
    fixed: Vec<bool>,
    boundary: Vec<Segment>,
    gravity: [f64; 2],
    /// The tank's walls, where the scene has a fluid and walls and a node they stop.
    walls: Option<WallStop>,
}

impl FemModel {
    /// The model of a scene's `[[solid]]`s under `run.gravity`.
    pub fn build(scene: &Scene) -> Result<Self> {
        let mut model = Self::from_solids(&scene.solids, scene.run.gravity)?;
        model.walls = WallStop::new(
            scene,
            &model.reference,
            &model.fixed,
            &model.node_solid,
            &model.boundary,
        );
        Ok(model)
    }

    /// The model of some solids under `gravity` [m/s²].
    pub fn from_solids(specs: &[SolidSpec], gravity: [f64; 2]) -> Result<Self> {
        let mut model = FemModel {
            solids: Vec::with_capacity(specs.len()),
            reference: Vec::new(),
            elements: Vec::new(),
            element_solid: Vec::new(),
            node_solid: Vec::new(),
            masses: Vec::new(),
            fixed: Vec::new(),
            boundary: Vec::new(),
            gravity,
            walls: None,
        };
        if !gravity.iter().all(|g| g.is_finite()) {
            return Err(FemError::InvalidParameter {
                name: "gravity",
                message: format!("{gravity:?} is not finite"),
            });
        }
        for (s, spec) in specs.iter().enumerate() {
            model.add_solid(s as u32, spec)?;
        }
        Ok(model)
    }

    fn add_solid(&mut self, index: u32, spec: &SolidSpec) -> Result<()> {
        let invalid = |message: String| FemError::InvalidSolid {
            solid: spec.name.clone(),
            message,
        };
        let m = &spec.material;
        if !(m.density.is_finite() && m.density > 0.0) {
            return Err(invalid(format!("density must be positive, got {}", m.density)));
        }
        if !(m.youngs_modulus.is_finite() && m.youngs_modulus > 0.0) {
            return Err(invalid(format!(
                "youngs_modulus must be positive, got {}",
                m.youngs_modulus
            )));
        }
        if !(0.0..0.5).contains(&m.poisson_ratio) {
            return Err(invalid(format!(
                "poisson_ratio must be in [0, 0.5), got {}",
                m.poisson_ratio
            )));
        }
        if !(spec.damping.is_finite() && spec.damping >= 0.0) {
            return Err(invalid(format!(
                "damping must be zero or positive, got {}",
                spec.damping
            )));
        }
        let mesh_damping = spec.mesh_damping();
        if !(mesh_damping.is_finite() && (0.0..1.0).contains(&mesh_damping)) {
            return Err(invalid(format!("mesh_damping must be in [0, 1), got {mesh_damping}")));
        }
        if spec.divisions.contains(&0) {
            return Err(invalid(format!(
                "divisions must be at least 1, got {:?}",
                spec.divisions
            )));
        }
        let material = Material::from_spec(m);
        let first = self.reference.len();
        let first_element = self.elements.len();
        let mesh = structured_mesh(spec, first as u32);
        self.reference.extend_from_slice(&mesh.nodes);
        self.fixed.extend_from_slice(&mesh.fixed);
        self.node_solid.resize(self.reference.len(), index);
        self.masses.resize(self.reference.len(), 0.0);
        let lame = material.lame();
        for cell in &mesh.cells {
            let at = |n: &u32| self.reference[*n as usize];
            let element = match cell {
                Cell::Quad(n) => {
                    let x = n.map(|k| at(&k));
                    for (k, mass) in n.iter().zip(Quad4::lumped_masses(&x, m.density)) {
                        self.masses[*k as usize] += mass;
                    }
                    Quad4::new(*n, x, lame).map(Element::Quad4)
                }
                Cell::Tri(n) => {
                    let x = n.map(|k| at(&k));
                    for (k, mass) in n.iter().zip(Tri3::lumped_masses(&x, m.density)) {
                        self.masses[*k as usize] += mass;
                    }
                    Tri3::new(*n, x).map(Element::Tri3)
                }
            };
            let element = element.map_err(|e| invalid(format!("degenerate element {cell:?}: {e}")))?;
            self.elements.push(element);
            self.element_solid.push(index);
        }
        self.boundary.extend_from_slice(&mesh.boundary);
        let mut solid = SolidModel {
            name: spec.name.clone(),
            material,
            density: m.density,
            damping: spec.damping,
            stiffness_damping: 0.0,
            element: spec.element,
            nodes: first..self.reference.len(),
            elements: first_element..self.elements.len(),
        };
        if mesh_damping > 0.0 {
            // ζ at the mesh's highest mode, ω_max ≈ 2 c_d / L_e of its shortest element: β = 2ζ / ω_max.
            let shortest = self.elements[solid.elements.clone()]
                .iter()
                .map(|e| e.characteristic_length(&self.reference))
                .fold(f64::INFINITY, f64::min);
            solid.stiffness_damping = mesh_damping * shortest / solid.wave_speed();
        }
        self.solids.push(solid);
        Ok(())
    }

    /// Solids in scene order.
    pub fn solids(&self) -> &[SolidModel] {
        &self.solids
    }

    /// Whether any solid has stiffness-proportional damping (`mesh_damping`).
    pub fn stiffness_damped(&self) -> bool {
        self.solids.iter().any(|s| s.stiffness_damping > 0.0)
    }

    /// Reference node positions `X`.
    pub fn reference(&self) -> &[[f64; 2]] {
        &self.reference
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.reference.len()
    }

    /// Elements.
    pub fn elements(&self) -> &[Element] {
        &self.elements
    }

    /// Solid index of every element.
    pub fn element_solid(&self) -> &[u32] {
        &self.element_solid
    }

    /// Solid index of every node.
    pub fn node_solid(&self) -> &[u32] {
        &self.node_solid
    }

    /// Material of element `e`.
    #[inline]
    pub fn element_material(&self, e: usize) -> &Material {
        &self.solids[self.element_solid[e] as usize].material
    }

    /// Row-sum lumped nodal masses [kg per unit thickness].
    pub fn masses(&self) -> &[f64] {
        &self.masses
    }

    /// Whether each node is clamped.
    pub fn fixed(&self) -> &[bool] {
        &self.fixed
    }

    /// Outer boundary segments of all solids, each counter-clockwise.
    pub fn boundary(&self) -> &[Segment] {
        &self.boundary
    }

    /// Gravity [m/s²].
    pub fn gravity(&self) -> [f64; 2] {
        self.gravity
    }

    /// The tank's walls, where they stop a node.
    pub fn walls(&self) -> Option<&WallStop> {
        self.walls.as_ref()
    }

    /// Element connectivity as id lists (the `fem/mesh` message layout).
    pub fn cells(&self) -> Vec<Vec<u32>> {
        self.elements.iter().map(|e| e.nodes().to_vec()).collect()
    }

    /// The node of solid `solid` nearest to `point` in the reference configuration.
    pub fn nearest_node(&self, solid: usize, point: [f64; 2]) -> Option<usize> {
        let range = self.solids.get(solid)?.nodes.clone();
        range.min_by(|&a, &b| {
            let d = |k: usize| (self.reference[k][0] - point[0]).hypot(self.reference[k][1] - point[1]);
            d(a).total_cmp(&d(b))
        })
    }
}
