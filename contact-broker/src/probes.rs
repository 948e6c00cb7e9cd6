//! Probes of `DESIGN.md` §5 evaluated on structure snapshots.

use cosim_proto::messages::{FemMesh, FemSnapshot};
use cosim_proto::scene::{EnergyPart, ProbeKind, ProbeSpec, Scene};

/// A probe resolved against the mesh.
#[derive(Clone, Debug)]
enum Resolved {
    /// Displacement component of one node.
    Node { node: usize, component: usize },
    /// Energy of one solid or all of them.
    Energy { part: EnergyPart, solid: Option<usize> },
}

/// All probes of a scene, resolved once against the registered mesh.
#[derive(Clone, Debug)]
pub struct Probes {
    names: Vec<String>,
    resolved: Vec<Resolved>,
}

impl Probes {
    /// Resolve every probe (nearest node in the reference configuration, solid indices).
    pub fn resolve(scene: &Scene, mesh: &FemMesh) -> Result<Self, String> {
        let solid_index = |name: &str| mesh.solid_names.iter().position(|s| s == name);
        let mut resolved = Vec::with_capacity(scene.probes.len());
        for (p, spec) in scene.probes.iter().enumerate() {
            resolved.push(match spec.kind {
                ProbeKind::NodeDisplacement => {
                    let (solid, point, component) = node_probe_keys(spec)
                        .ok_or_else(|| format!("probe[{p}]: node_displacement needs solid, point and component"))?;
                    let s = solid_index(solid)
                        .ok_or_else(|| format!("probe[{p}].solid: the FEM node has no solid `{solid}`"))?;
                    let node = nearest_node(mesh, s, point)
                        .ok_or_else(|| format!("probe[{p}].solid: solid `{solid}` has no node"))?;
                    Resolved::Node {
                        node,
                        component: component.index(),
                    }
                }
                ProbeKind::Energy => {
                    let solid = match &spec.solid {
                        Some(name) => Some(
                            solid_index(name)
                                .ok_or_else(|| format!("probe[{p}].solid: the FEM node has no solid `{name}`"))?,
                        ),
                        None => None,
                    };
                    let part = spec.part.ok_or_else(|| format!("probe[{p}].part: missing"))?;
                    Resolved::Energy { part, solid }
                }
            });
        }
        Ok(Self {
            names: scene.probes.iter().map(|p| p.name.clone()).collect(),
            resolved,
        })
    }

    /// Column names, in scene order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Evaluate every probe on a snapshot.
    pub fn sample(&self, mesh: &FemMesh, snap: &FemSnapshot) -> Vec<f64> {
        self.resolved
            .iter()
            .map(|r| match *r {
                Resolved::Node { node, component } => snap.x[node][component] - mesh.nodes[node][component],
                Resolved::Energy { part, solid } => snap
                    .energies
                    .iter()
                    .enumerate()
                    .filter(|(s, _)| solid.is_none_or(|want| want == *s))
                    .map(|(_, e)| match part {
                        EnergyPart::Kinetic => e.kinetic,
                        EnergyPart::Strain => e.strain,
                        EnergyPart::Potential => e.potential,
                        EnergyPart::Total => e.kinetic + e.strain + e.potential,
                    })
                    .sum(),
            })
            .collect()
    }
}

fn node_probe_keys(spec: &ProbeSpec) -> Option<(&str, [f64; 2], cosim_proto::scene::Component)> {
    Some((spec.solid.as_deref()?, spec.point?, spec.component?))
}

/// The node of solid `solid` nearest `point` in the reference configuration; ties go to the lowest id.
fn nearest_node(mesh: &FemMesh, solid: usize, point: [f64; 2]) -> Option<usize> {
    let d2 = |p: [f64; 2]| (p[0] - point[0]).powi(2) + (p[1] - point[1]).powi(2);
    mesh.nodes
        .iter()
        .enumerate()
        .filter(|(n, _)| mesh.node_solid[*n] as usize == solid)
        .fold(None, |best: Option<(usize, f64)>, (n, &p)| match best {
            Some((_, d)) if d <= d2(p) => best,
            _ => Some((n, d2(p))),
        })
        .map(|(n, _)| n)
}
