//! Probes of `DESIGN.md` §5, evaluated on the nodes' snapshots at output times.

use cosim_proto::messages::{FemMesh, FemSnapshot, SphSetup, SphSnapshot};
use cosim_proto::scene::{Average, EnergyOf, EnergyPart, PressureSensor, ProbeKind, Scene};
use serde::{Deserialize, Serialize};
use sph_node::gauge::water_level;
use sph_node::sensors::{sensor_pressure, PressureField};

/// A probe resolved against the registered mesh and particles.
#[derive(Clone, Debug)]
enum Resolved {
    /// Displacement component of one FE node.
    Node { node: usize, component: usize },
    /// Energy of one solid, all solids, the fluid, or everything.
    Energy {
        part: EnergyPart,
        solid: Option<usize>,
        of: EnergyOf,
    },
    /// Largest fluid coordinate along a component.
    Front { component: usize },
    /// Highest fluid particle with x ≤ x_max.
    Column { x_max: f64 },
    /// Height of the water surface above a gauge's foot.
    Level { foot: [f64; 2] },
    /// Shepard-normalised SPH pressure, the mean over a sensor's face, now.
    Pressure { sensor: PressureSensor },
    /// The same, its time mean over the sampling interval: the fluid node's interval sensor `index`.
    PressureMean { index: usize },
    /// The summed interface load of one solid or all, component `component`, over the sampling interval.
    InterfaceLoad { solid: Option<usize>, component: usize },
}

/// The contact impulse the structure received since the last sample, per solid, and the time it took: what an
/// `interface_load` probe reads (a checkpoint keeps it).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LoadLog {
    /// Σ over the passes since the last sample of each solid's nodes' contact impulses [N s per unit thickness].
    pub impulse: Vec<[f64; 2]>,
    /// Σ Δt over those passes [s].
    pub time: f64,
}

impl LoadLog {
    /// Add one pass's impulses (`impulse[n]` on FE node n, of solid `node_solid[n]`) over a step `dt`.
    pub fn add(&mut self, impulse: &[[f64; 2]], node_solid: &[u32], dt: f64) {
        for (j, &solid) in impulse.iter().zip(node_solid) {
            let solid = solid as usize;
            if self.impulse.len() <= solid {
                self.impulse.resize(solid + 1, [0.0; 2]);
            }
            self.impulse[solid][0] += j[0];
            self.impulse[solid][1] += j[1];
        }
        self.time += dt;
    }

    /// The mean load of `solid` (all where `None`) along `component` since the last sample; NaN before any pass.
    fn mean(&self, solid: Option<usize>, component: usize) -> f64 {
        if self.time <= 0.0 {
            return f64::NAN;
        }
        let total: f64 = match solid {
            Some(s) => self.impulse.get(s).map_or(0.0, |j| j[component]),
            None => self.impulse.iter().map(|j| j[component]).sum(),
        };
        total / self.time
    }
}

/// All probes of a scene, resolved once.
#[derive(Clone, Debug)]
pub struct Probes {
    names: Vec<String>,
    resolved: Vec<Resolved>,
    gravity: [f64; 2],
    /// Fluid positions of the first sample (potential energy is measured from there, as for the structure).
    fluid_x0: Option<Vec<[f64; 2]>>,
}

impl Probes {
    /// Fluid positions of the first sample, once taken (a checkpoint keeps them).
    pub fn fluid_origin(&self) -> Option<&[[f64; 2]]> {
        self.fluid_x0.as_deref()
    }

    /// Continue with the first sample's fluid positions of a checkpoint.
    pub fn set_fluid_origin(&mut self, x0: Option<Vec<[f64; 2]>>) {
        self.fluid_x0 = x0;
    }

    /// Resolve every probe (nearest node in the reference configuration, solid indices).
    pub fn resolve(scene: &Scene, mesh: Option<&FemMesh>, fluid: Option<&SphSetup>) -> Result<Self, String> {
        let mut resolved = Vec::with_capacity(scene.probes.len());
        let solid_index = |p: usize, name: &str| -> Result<usize, String> {
            let mesh = mesh.ok_or_else(|| format!("probe[{p}].solid: the run has no structure node"))?;
            mesh.solid_names
                .iter()
                .position(|s| s == name)
                .ok_or_else(|| format!("probe[{p}].solid: the structure node has no solid `{name}`"))
        };
        let need_fluid = |p: usize| {
            fluid
                .map(|_| ())
                .ok_or_else(|| format!("probe[{p}].kind: the run has no fluid node"))
        };
        // The fluid node computes the interval means, in scene order (`PressureSensor::interval`); an outside node
        // may offer none, and then cannot run a scene that asks for them.
        let intervals = PressureSensor::interval(scene).len();
        if let Some(setup) = fluid.filter(|s| s.sensors as usize != intervals) {
            return Err(format!(
                "probe: the scene has {intervals} pressure probes with average = \"interval\", the fluid node computes {} \
                 interval sensors",
                setup.sensors
            ));
        }
        let mut interval = 0;
        for (p, spec) in scene.probes.iter().enumerate() {
            let missing = |k: &str| format!("probe[{p}].{k}: missing");
            resolved.push(match spec.kind {
                ProbeKind::NodeDisplacement => {
                    let solid = solid_index(p, spec.solid.as_deref().ok_or_else(|| missing("solid"))?)?;
                    let point = spec.point.ok_or_else(|| missing("point"))?;
                    let component = spec.component.ok_or_else(|| missing("component"))?.index();
                    let node = nearest_node(mesh.expect("checked by solid_index"), solid, point)
                        .ok_or_else(|| format!("probe[{p}].solid: the solid has no node"))?;
                    Resolved::Node { node, component }
                }
                ProbeKind::Energy => Resolved::Energy {
                    part: spec.part.ok_or_else(|| missing("part"))?,
                    solid: spec.solid.as_deref().map(|n| solid_index(p, n)).transpose()?,
                    of: spec.of.unwrap_or(EnergyOf::All),
                },
                ProbeKind::SurgeFront => {
                    need_fluid(p)?;
                    Resolved::Front {
                        component: spec.component.ok_or_else(|| missing("component"))?.index(),
                    }
                }
                ProbeKind::ColumnHeight => {
                    need_fluid(p)?;
                    Resolved::Column {
                        x_max: spec.x_max.ok_or_else(|| missing("x_max"))?,
                    }
                }
                ProbeKind::WaterLevel => {
                    need_fluid(p)?;
                    Resolved::Level {
                        foot: spec.point.ok_or_else(|| missing("point"))?,
                    }
                }
                ProbeKind::Pressure => {
                    let setup = fluid.ok_or_else(|| format!("probe[{p}].kind: the run has no fluid node"))?;
                    let sensor = PressureSensor::of(scene, p, setup.spacing).ok_or_else(|| missing("point"))?;
                    if spec.average == Some(Average::Interval) {
                        interval += 1;
                        Resolved::PressureMean { index: interval - 1 }
                    } else {
                        Resolved::Pressure { sensor }
                    }
                }
                ProbeKind::InterfaceLoad => Resolved::InterfaceLoad {
                    solid: spec.solid.as_deref().map(|n| solid_index(p, n)).transpose()?,
                    component: spec.component.ok_or_else(|| missing("component"))?.index(),
                },
            });
        }
        Ok(Self {
            names: scene.probes.iter().map(|p| p.name.clone()).collect(),
            resolved,
            gravity: scene.run.gravity,
            fluid_x0: None,
        })
    }

    /// Column names, in scene order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Evaluate every probe on the snapshots of this output time and the load since the last one.
    pub fn sample(
        &mut self,
        fem: Option<(&FemMesh, &FemSnapshot)>,
        sph: Option<(&SphSetup, &SphSnapshot)>,
        load: &LoadLog,
    ) -> Vec<f64> {
        if let (None, Some((_, snap))) = (&self.fluid_x0, sph) {
            self.fluid_x0 = Some(snap.x.clone());
        }
        self.resolved
            .iter()
            .map(|r| match *r {
                Resolved::Node { node, component } => fem.map_or(f64::NAN, |(mesh, snap)| {
                    snap.x[node][component] - mesh.nodes[node][component]
                }),
                Resolved::Energy { part, solid, of } => {
                    let structure = match (of, fem) {
                        (EnergyOf::Structure | EnergyOf::All, Some((_, snap))) => structure_energy(snap, part, solid),
                        _ => 0.0,
                    };
                    let fluid = match (of, sph, solid) {
                        (EnergyOf::Fluid | EnergyOf::All, Some((_, snap)), None) => self.fluid_energy(snap, part),
                        _ => 0.0,
                    };
                    structure + fluid
                }
                Resolved::Front { component } => sph.map_or(f64::NAN, |(_, s)| {
                    s.x.iter().map(|x| x[component]).fold(f64::NEG_INFINITY, f64::max)
                }),
                // A column the water has left holds no height: NaN ("no value", as CSV readers parse it), not the
                // −inf of an empty maximum. The scene check refuses an x_max left of the water at the start.
                Resolved::Column { x_max } => sph.map_or(f64::NAN, |(_, s)| {
                    s.x.iter()
                        .filter(|x| x[0] <= x_max)
                        .map(|x| x[1])
                        .reduce(f64::max)
                        .unwrap_or(f64::NAN)
                }),
                Resolved::Level { foot } => sph.map_or(f64::NAN, |(setup, s)| water_level(&field(setup, s), foot)),
                Resolved::Pressure { ref sensor } => {
                    sph.map_or(f64::NAN, |(setup, s)| sensor_pressure(&field(setup, s), sensor))
                }
                Resolved::PressureMean { index } => {
                    sph.map_or(f64::NAN, |(_, s)| s.sensors.get(index).copied().unwrap_or(f64::NAN))
                }
                Resolved::InterfaceLoad { solid, component } => load.mean(solid, component),
            })
            .collect()
    }

    /// The mechanical energy of the snapshots, as an `energy` probe of the whole run counts it (`part = "total"`,
    /// `of = "all"`): the fluid's kinetic energy and its gravitational energy relative to its first positions, plus
    /// the structure's kinetic, strain and gravitational energy [J/m]. Call after [`Probes::sample`] of the same
    /// output time (which takes the fluid's first positions).
    pub fn mechanical_energy(
        &self,
        fem: Option<(&FemMesh, &FemSnapshot)>,
        sph: Option<(&SphSetup, &SphSnapshot)>,
    ) -> f64 {
        let structure = fem.map_or(0.0, |(_, snap)| structure_energy(snap, EnergyPart::Total, None));
        let fluid = sph.map_or(0.0, |(_, snap)| self.fluid_energy(snap, EnergyPart::Total));
        structure + fluid
    }

    /// How far rounding can move [`Probes::mechanical_energy`] plus the fluid's elastic energy [J/m], to first
    /// order and at worst; `elastic` is the size the elastic terms are computed at
    /// ([`crate::energy_balance::elastic_size`]), `steps` the (structure, fluid) steps taken so far. Two parts, the
    /// unit roundoff u times:
    /// - the sums: a recursive sum of n terms is off by at most (n − 1) u Σ|x_i| (Higham 2002, Eq. (4.4)). fem-node
    ///   sends each solid's sums, not their terms: there the sums' magnitudes stand for the terms' (a structure's
    ///   kinetic and strain terms are ≥ 0, and its nodes' gravitational terms share their sign as it sags or falls);
    /// - the states: each step's x += Δt v rounds x by up to u|x|, and v by up to u|v|, so after N steps the
    ///   gravitational energy is off by up to N u Σ m |g·x| (the heights from the origin, not from the start: a
    ///   body far from the origin has coarser positions) and the kinetic energy by up to 2 N u Σ m v²/2.
    pub fn energy_rounding(
        &self,
        fem: Option<(&FemMesh, &FemSnapshot)>,
        sph: Option<(&SphSetup, &SphSnapshot)>,
        elastic: f64,
        steps: (u64, u64),
    ) -> f64 {
        let u = 0.5 * f64::EPSILON;
        let g = self.gravity;
        let heights = |m: &[f64], x: &[[f64; 2]]| -> f64 {
            m.iter()
                .zip(x)
                .map(|(m, x)| (m * (g[0] * x[0] + g[1] * x[1])).abs())
                .sum()
        };
        let structure = fem.map_or(0.0, |(mesh, snap)| {
            let terms = (mesh.nodes.len() + mesh.cell_solid.len()) as f64;
            let (mut kinetic, mut sums) = (0.0, 0.0);
            for e in &snap.energies {
                kinetic += e.kinetic.abs();
                sums += e.kinetic.abs() + e.strain.abs() + e.potential.abs();
            }
            let states = (steps.0 + 1) as f64 * (heights(&mesh.masses, &snap.x) + 2.0 * kinetic);
            terms * sums + states
        });
        let fluid = sph.map_or(0.0, |(_, snap)| {
            let potential = self.fluid_x0.as_ref().map_or(0.0, |x0| {
                snap.m
                    .iter()
                    .zip(snap.x.iter().zip(x0))
                    .map(|(m, (x, x0))| (m * (g[0] * (x[0] - x0[0]) + g[1] * (x[1] - x0[1]))).abs())
                    .sum::<f64>()
            });
            let kinetic = self.fluid_energy(snap, EnergyPart::Kinetic);
            let states = (steps.1 + 1) as f64 * (heights(&snap.m, &snap.x) + 2.0 * kinetic);
            snap.m.len() as f64 * (kinetic + potential + elastic) + states
        });
        u * (structure + fluid)
    }

    /// Gravity, as the scene gives it.
    pub fn gravity(&self) -> [f64; 2] {
        self.gravity
    }

    fn fluid_energy(&self, snap: &SphSnapshot, part: EnergyPart) -> f64 {
        let kinetic = || {
            snap.m
                .iter()
                .zip(&snap.v)
                .map(|(m, v)| 0.5 * m * (v[0] * v[0] + v[1] * v[1]))
                .sum::<f64>()
        };
        let potential = || match &self.fluid_x0 {
            Some(x0) => snap
                .m
                .iter()
                .zip(snap.x.iter().zip(x0))
                .map(|(m, (x, x0))| -m * (self.gravity[0] * (x[0] - x0[0]) + self.gravity[1] * (x[1] - x0[1])))
                .sum::<f64>(),
            None => 0.0,
        };
        match part {
            EnergyPart::Kinetic => kinetic(),
            EnergyPart::Potential => potential(),
            EnergyPart::Strain => 0.0,
            EnergyPart::Total => kinetic() + potential(),
        }
    }
}

fn structure_energy(snap: &FemSnapshot, part: EnergyPart, solid: Option<usize>) -> f64 {
    snap.energies
        .iter()
        .enumerate()
        .filter(|(s, _)| solid.is_none_or(|want| want == *s))
        .map(|(_, e)| match part {
            EnergyPart::Kinetic => e.kinetic,
            EnergyPart::Strain => e.strain,
            EnergyPart::Potential => e.potential,
            EnergyPart::Total => e.kinetic + e.strain + e.potential,
        })
        .sum()
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

/// The fluid and wall particles of a snapshot, as the pressure and level probes read them.
fn field<'a>(setup: &'a SphSetup, s: &'a SphSnapshot) -> PressureField<'a> {
    PressureField {
        x: &s.x,
        m: &s.m,
        rho: &s.rho,
        p: &s.p,
        wall_x: &setup.walls,
        h: setup.h,
        spacing: setup.spacing,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shipped dam break's column probe (x ≤ 0.01 m) on two snapshots: one with water in the column, one whose
    /// water has all moved beyond it.
    #[test]
    fn an_emptied_column_reads_nan_not_minus_infinity() {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/dam_break.toml")).unwrap();
        let scene = cosim_proto::scene::parse("dam_break.toml", &text, &[]).unwrap();
        let column = scene
            .probes
            .iter()
            .position(|p| p.kind == ProbeKind::ColumnHeight)
            .unwrap();
        let setup = SphSetup {
            particles: 2,
            spacing: 0.005,
            h: 0.0065,
            density: 1000.0,
            walls: Vec::new(),
            dt_stable: 1e-4,
            sensors: 0,
        };
        let snap = |x: Vec<[f64; 2]>| SphSnapshot {
            v: vec![[0.0; 2]; x.len()],
            rho: vec![1000.0; x.len()],
            p: vec![0.0; x.len()],
            m: vec![0.025; x.len()],
            wall_p: Vec::new(),
            sensors: Vec::new(),
            x,
        };
        let mut probes = Probes::resolve(&scene, None, Some(&setup)).unwrap();
        let full = probes.sample(
            None,
            Some((&setup, &snap(vec![[0.0025, 0.0975], [0.2, 0.01]]))),
            &LoadLog::default(),
        );
        assert_eq!(full[column], 0.0975);
        let empty = probes.sample(
            None,
            Some((&setup, &snap(vec![[0.3, 0.01], [0.2, 0.01]]))),
            &LoadLog::default(),
        );
        assert!(empty[column].is_nan(), "{}", empty[column]);
    }
}
