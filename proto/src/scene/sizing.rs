//! Sizing a scene before anything is built: the fluid and wall particles, the cells of the fluid's neighbour grid,
//! the FE nodes and elements and the probe samples a run of it makes, and about how many bytes each of its
//! processes holds — from the scene's numbers alone, allocating nothing that grows with them.
//!
//! Validation refuses a scene whose counts do not fit the `u32` ids of the wire and the solvers ([`MAX_COUNT`]);
//! `cosim check`/`run` and each node refuse one whose estimate is above the machine's available memory
//! ([`Sizing::refuse_above`]). Either way the error names the key that makes the scene big.
//!
//! The bytes are measured, not counted from the code's arrays: peak resident memory of each process of
//! `cosim run` (processes mode, the default, which holds more than `--in-process`) at ~10⁵ fluid particles and
//! 10⁶ FE elements, less the fixed part (docs/PERFORMANCE.md, "Memory per particle" and "Scene sizing"). They are
//! good to some tens of per cent: enough to tell a run that fits from one that cannot.

use super::schema::{BoxSpec, ElementKind, FluidSolver, Scene, SolidSpec};
use crate::Num;

/// Most particles (fluid and walls together), FE nodes, FE elements or neighbour-grid cells a run may have: their
/// ids are `u32` on the wire (`docs/PROTOCOL.md`) and in the solvers' lists.
pub const MAX_COUNT: f64 = u32::MAX as f64;

/// Bytes of one process before any particle or node: the program, its libraries, zenoh, the thread pool.
const PROCESS_BYTES: f64 = 20.0 * MIB;
/// sph-node, per fluid particle: WCSPH (lists, id-ordered and sorted state, scratch, the state messages). Was 800 B
/// with 4 B a Verlet candidate; remeasured 2026-12-05 with the candidates' 2 B (docs/PERFORMANCE.md, "Scene sizing").
const WCSPH_PARTICLE_BYTES: f64 = 850.0;
/// sph-node, per fluid particle: ISPH (the Poisson matrix, its Krylov vectors and the multigrid preconditioner's
/// levels besides). Was 950 B, measured 2026-11-25, before the multigrid preconditioner landed; remeasured 2026-12-05.
const ISPH_PARTICLE_BYTES: f64 = 1250.0;
/// sph-node, per WCSPH fluid particle with Verlet candidate lists (`fluid.verlet_skin` > 0), per candidate: its
/// code (u16; a chunk spanning more than 65,535 slots keeps u32 slots instead, `sph-node/src/neighbors/candidates.rs`);
/// the candidates are those within 2h + skin, π (2h + skin)² / Δx² of them in the bulk.
const VERLET_CANDIDATE_BYTES: f64 = 2.0;
/// sph-node, per WCSPH fluid particle with Verlet candidate lists: the position they were gathered at.
const VERLET_REFERENCE_BYTES: f64 = 16.0;
/// sph-node, per wall particle: WCSPH.
const WCSPH_WALL_BYTES: f64 = 250.0;
/// sph-node, per wall particle: ISPH (walls have rows of the Poisson matrix).
const ISPH_WALL_BYTES: f64 = 300.0;
/// sph-node, per cell of the neighbour grid: the fluid and wall starts and the insertion cursor (3 × u32), the
/// plain cell list's two.
const CELL_BYTES: f64 = 20.0;
/// contact-broker, per fluid particle: the snapshot for frames and probes, its decoding, the frame writer.
const BROKER_PARTICLE_BYTES: f64 = 250.0;
/// contact-broker, per wall particle: the positions of the registration, written in every frame.
const BROKER_WALL_BYTES: f64 = 80.0;
/// fem-node, per FE node: reference, state, masses, forces.
const FEM_NODE_BYTES: f64 = 150.0;
/// fem-node, per quad4 element: its reference gradients and hourglass data, forces, stress.
const FEM_QUAD4_BYTES: f64 = 400.0;
/// fem-node, per tri3 element.
const FEM_TRI3_BYTES: f64 = 340.0;
/// contact-broker, per FE node: the mesh of the registration, snapshots, frames.
const BROKER_NODE_BYTES: f64 = 200.0;
/// contact-broker, per quad4 element: the connectivity (one `Vec` a cell), stress of the snapshots, frames.
const BROKER_QUAD4_BYTES: f64 = 450.0;
/// contact-broker, per tri3 element.
const BROKER_TRI3_BYTES: f64 = 370.0;
/// Per probe, in every process: its part of the scene text and of the parsed scene.
const PROBE_BYTES: f64 = 1024.0;
/// contact-broker, per probe sample kept for the plots: (t, value), in a `Vec` that grows by doubling.
const SAMPLE_BYTES: f64 = 32.0;

const MIB: f64 = 1024.0 * 1024.0;

/// Whose memory: the whole run (every process on one machine), or one process's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// `cosim` and every process it starts.
    Run,
    /// `sph-node`.
    Fluid,
    /// `fem-node`.
    Structure,
    /// `contact-broker`.
    Broker,
}

impl Part {
    /// Index into the per-process arrays (the fourth holds cosim's bytes, and the whole run's largest item).
    fn index(self) -> usize {
        match self {
            Part::Fluid => 0,
            Part::Structure => 1,
            Part::Broker => 2,
            Part::Run => 3,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Part::Run => "the run",
            Part::Fluid => "sph-node",
            Part::Structure => "fem-node",
            Part::Broker => "contact-broker",
        }
    }
}

/// One thing of the scene that takes memory, with the key a user changes to make it smaller.
#[derive(Clone, Debug)]
struct Item {
    key: String,
    what: String,
    /// Bytes in sph-node, fem-node, contact-broker, cosim.
    bytes: [f64; 4],
}

impl Item {
    fn bytes(&self, part: Part) -> f64 {
        share(&self.bytes, part)
    }
}

/// `part`'s bytes of an item's bytes in sph-node, fem-node, contact-broker and cosim.
fn share(bytes: &[f64; 4], part: Part) -> f64 {
    match part {
        Part::Run => bytes.iter().sum(),
        _ => bytes[part.index()],
    }
}

/// What a scene makes, estimated from its numbers. Counts are `f64`: a scene may ask for more than `u64` holds.
#[derive(Clone, Debug)]
pub struct Sizing {
    /// Fluid particles (exact: the lattice of sph-node's set-up).
    pub fluid_particles: f64,
    /// Wall particles (exact but for the corners that overlapping walls share, counted once per wall).
    pub wall_particles: f64,
    /// Cells of the fluid's neighbour grid (2h wide) over the fluid blocks and walls at the start.
    pub grid_cells: f64,
    /// FE nodes of every solid.
    pub fem_nodes: f64,
    /// FE elements of every solid.
    pub fem_elements: f64,
    /// Probe samples the broker keeps for the plots: probes × frames.
    pub probe_samples: f64,
    /// Bytes of sph-node, fem-node, contact-broker and cosim (0 for a node the scene does not start), each with its
    /// fixed part.
    process_bytes: [f64; 4],
    /// The item that takes most of sph-node's, fem-node's, contact-broker's and the whole run's memory.
    largest: [Option<Item>; 4],
    /// The largest contributor of particles, of FE nodes and of grid cells (for the id limit).
    particle_key: Option<(String, String)>,
    solid_key: Option<(String, String)>,
    grid_key: (String, String),
}

impl Sizing {
    /// Size `scene`. Meaningful for a scene whose numbers are finite and positive where they must be (run it after
    /// the other checks of [`Scene::validate`]).
    pub fn of(scene: &Scene) -> Self {
        let mut s = Sizing {
            fluid_particles: 0.0,
            wall_particles: 0.0,
            grid_cells: 0.0,
            fem_nodes: 0.0,
            fem_elements: 0.0,
            probe_samples: 0.0,
            process_bytes: [0.0, 0.0, PROCESS_BYTES, PROCESS_BYTES],
            largest: [None, None, None, None],
            particle_key: None,
            solid_key: None,
            grid_key: (String::new(), String::new()),
        };
        if let Some(f) = &scene.fluid {
            let dx = f.spacing;
            let h = f.smoothing_ratio * dx;
            let (per_particle, per_wall) = match f.solver {
                FluidSolver::Wcsph => {
                    let reach = (2.0 + f.verlet_skin()) * f.smoothing_ratio;
                    let candidates = std::f64::consts::PI * reach * reach;
                    let verlet = match f.verlet_skin() > 0.0 {
                        true => candidates * VERLET_CANDIDATE_BYTES + VERLET_REFERENCE_BYTES,
                        false => 0.0,
                    };
                    (WCSPH_PARTICLE_BYTES + verlet, WCSPH_WALL_BYTES)
                }
                FluidSolver::Isph => (ISPH_PARTICLE_BYTES, ISPH_WALL_BYTES),
            };
            s.fluid_particles = f.blocks.iter().map(|b| block_particles(b, dx)).sum();
            let n = s.fluid_particles;
            s.add([n * per_particle, 0.0, n * BROKER_PARTICLE_BYTES, 0.0], || {
                let what = format!("{} m fills the fluid blocks with {} particles", Num(dx), count(n));
                ("fluid.spacing".into(), what)
            });
            s.particle_key = Some(("fluid.spacing".into(), format!("{} m", Num(dx))));
            let origin = f.blocks.first().map_or([0.0; 2], |b| b.min);
            let mut largest_wall = 0.0;
            for (w, wall) in scene.walls.iter().enumerate() {
                let n = wall_particles(wall, origin, dx, h);
                s.wall_particles += n;
                s.add([n * per_wall, 0.0, n * BROKER_WALL_BYTES, 0.0], || {
                    let (min, max, n) = (wall.min, wall.max, count(n));
                    let what = format!(
                        "min {min:?} max {max:?} holds {n} wall particles at a spacing of {} m",
                        Num(dx)
                    );
                    (format!("wall[{w}]"), what)
                });
                if n > largest_wall {
                    largest_wall = n;
                    if n > s.fluid_particles {
                        s.particle_key = Some((format!("wall[{w}]"), format!("min {:?} max {:?}", wall.min, wall.max)));
                    }
                }
            }
            let (cells, key, what) = grid(&f.blocks, &scene.walls, dx, h);
            s.grid_cells = cells;
            s.add([cells * CELL_BYTES, 0.0, 0.0, 0.0], || (key.clone(), what.clone()));
            s.grid_key = (key, what);
            s.process_bytes[0] += PROCESS_BYTES;
        }
        let mut largest_solid = 0.0;
        for (i, solid) in scene.solids.iter().enumerate() {
            let (nodes, elements) = solid_counts(solid);
            s.fem_nodes += nodes;
            s.fem_elements += elements;
            let (fem, broker) = match solid.element {
                ElementKind::Quad4 => (FEM_QUAD4_BYTES, BROKER_QUAD4_BYTES),
                ElementKind::Tri3 => (FEM_TRI3_BYTES, BROKER_TRI3_BYTES),
            };
            let key = || format!("solid[{i}].divisions");
            let divisions = || format!("{:?}", solid.divisions);
            let structure = nodes * FEM_NODE_BYTES + elements * fem;
            s.add(
                [0.0, structure, nodes * BROKER_NODE_BYTES + elements * broker, 0.0],
                || {
                    let kind = format!("{:?}", solid.element).to_lowercase();
                    let (nodes, elements) = (count(nodes), count(elements));
                    (
                        key(),
                        format!("{} makes {nodes} nodes and {elements} {kind} elements", divisions()),
                    )
                },
            );
            if elements.max(nodes) > largest_solid {
                largest_solid = elements.max(nodes);
                s.solid_key = Some((key(), divisions()));
            }
        }
        if !scene.solids.is_empty() {
            s.process_bytes[1] += PROCESS_BYTES;
        }
        let probes = scene.probes.len() as f64;
        let frames = (scene.run.end_time / scene.run.output_interval).ceil() + 1.0;
        s.probe_samples = probes * frames;
        let (key, what) = match frames > probes {
            true => (
                "run.output_interval".to_string(),
                format!(
                    "{} s samples {} probe(s) {} times",
                    Num(scene.run.output_interval),
                    count(probes),
                    count(frames)
                ),
            ),
            false => (
                "probe".to_string(),
                format!("{} probes, each sampled {} times", count(probes), count(frames)),
            ),
        };
        let in_node = |present: bool| if present { probes * PROBE_BYTES } else { 0.0 };
        let broker = probes * PROBE_BYTES + s.probe_samples * SAMPLE_BYTES;
        let bytes = [
            in_node(scene.fluid.is_some()),
            in_node(!scene.solids.is_empty()),
            broker,
            probes * PROBE_BYTES,
        ];
        s.add(bytes, || (key, what));
        s
    }

    /// Count an item's bytes in sph-node, fem-node, contact-broker and cosim, and keep it where it is the largest
    /// so far; `describe` (its key and what it makes) is only called then.
    fn add(&mut self, bytes: [f64; 4], describe: impl FnOnce() -> (String, String)) {
        for (p, b) in bytes.iter().enumerate() {
            self.process_bytes[p] += b;
        }
        let parts = [Part::Fluid, Part::Structure, Part::Broker, Part::Run];
        let wins = parts.map(|part| {
            let p = part.index();
            self.largest[p]
                .as_ref()
                .is_none_or(|l| share(&bytes, part) > l.bytes(part))
        });
        if wins.contains(&true) {
            let (key, what) = describe();
            let item = Item { key, what, bytes };
            for (part, wins) in parts.into_iter().zip(wins) {
                if wins {
                    self.largest[part.index()] = Some(item.clone());
                }
            }
        }
    }

    /// Estimated peak bytes of `part`.
    pub fn bytes(&self, part: Part) -> f64 {
        share(&self.process_bytes, part)
    }

    /// The item of the scene that takes most of `part`'s memory: its key and what it makes.
    fn driver(&self, part: Part) -> Option<&Item> {
        self.largest[part.index()].as_ref()
    }

    /// Refuse counts beyond [`MAX_COUNT`], naming the key that makes them: the dotted key and the problem.
    pub fn check_counts(&self) -> Result<(), (String, String)> {
        let limit = |n: f64, what: &str| {
            format!(
                "{} {what}, more than {MAX_COUNT}, the most a run numbers with its u32 ids (about {} of memory)",
                count(n),
                bytes_text(self.bytes(Part::Run))
            )
        };
        let particles = self.fluid_particles + self.wall_particles;
        if let (true, Some((key, value))) = (particles > MAX_COUNT, &self.particle_key) {
            let what = format!("fluid and wall particles ({} fluid)", count(self.fluid_particles));
            return Err((key.clone(), format!("{value} makes {}", limit(particles, &what))));
        }
        if let (true, Some((key, value))) = (self.fem_nodes.max(self.fem_elements) > MAX_COUNT, &self.solid_key) {
            let what = format!("FE nodes and {} elements over all solids", count(self.fem_elements));
            return Err((key.clone(), format!("{value} makes {}", limit(self.fem_nodes, &what))));
        }
        if self.grid_cells > MAX_COUNT {
            let (key, what) = &self.grid_key;
            return Err((
                key.clone(),
                format!("{what}: more than {MAX_COUNT}, the most a grid numbers (u32)"),
            ));
        }
        Ok(())
    }

    /// Refuse a scene whose `part` would need more than `available` bytes: the dotted key of the item that takes
    /// most of it, what it makes, how much the part needs and how much is available.
    pub fn refuse_above(&self, part: Part, available: u64) -> Result<(), (String, String)> {
        let needed = self.bytes(part);
        if needed <= available as f64 {
            return Ok(());
        }
        let (key, what) = match self.driver(part) {
            Some(item) => (item.key.clone(), item.what.clone()),
            None => ("(scene)".to_string(), "the scene".to_string()),
        };
        Err((
            key,
            format!(
                "{what}: {} needs about {} of memory, this machine has {} available",
                part.name(),
                bytes_text(needed),
                bytes_text(available as f64)
            ),
        ))
    }
}

/// Particles of one fluid block: the lattice of sph-node's set-up, ⌊extent/Δx + 10⁻⁹⌋ per axis.
fn block_particles(b: &BoxSpec, dx: f64) -> f64 {
    (0..2)
        .map(|k| ((b.max[k] - b.min[k]) / dx + 1e-9).floor().max(0.0))
        .product()
}

/// Layers a wall is filled with: at least 3 and ⌈2h/Δx⌉ (sph-node `boundary::walls::layers_needed`).
fn wall_layers(dx: f64, h: f64) -> f64 {
    (2.0 * h / dx - 1e-9).ceil().max(3.0)
}

/// Particles of one wall: its box (grown to [`wall_layers`] where thinner, on one side: the count does not depend
/// on which) on the fluid's lattice origin + (k + ½) Δx (sph-node `boundary::walls::wall_positions`).
fn wall_particles(wall: &BoxSpec, origin: [f64; 2], dx: f64, h: f64) -> f64 {
    let thick = wall_layers(dx, h) * dx;
    (0..2)
        .map(|k| {
            let lo = wall.min[k].min(wall.max[k] - thick);
            let first = ((lo - origin[k]) / dx - 0.5 - 1e-9).ceil();
            let last = ((wall.max[k] - origin[k]) / dx - 0.5 + 1e-9).floor();
            (last - first + 1.0).max(0.0)
        })
        .product()
}

/// FE nodes and elements of one solid.
pub(super) fn solid_counts(solid: &SolidSpec) -> (f64, f64) {
    let [dx, dy] = solid.divisions.map(f64::from);
    let cells = dx * dy;
    let elements = match solid.element {
        ElementKind::Quad4 => cells,
        ElementKind::Tri3 => 2.0 * cells,
    };
    ((dx + 1.0) * (dy + 1.0), elements)
}

/// Cells of the neighbour grid (2h wide) over the fluid blocks and the walls (grown by their layers on both
/// sides, an upper bound), and the key that makes it large: the block or wall whose removal shrinks it most when
/// that is more than half of it (a box far from the others), else `fluid.spacing`.
fn grid(blocks: &[BoxSpec], walls: &[BoxSpec], dx: f64, h: f64) -> (f64, String, String) {
    let cell = 2.0 * h;
    let grow = wall_layers(dx, h) * dx;
    let boxes = || {
        let blocks = blocks.iter().map(|b| (b.min, b.max));
        blocks.chain(walls.iter().map(|w| (w.min.map(|v| v - grow), w.max.map(|v| v + grow))))
    };
    // Per axis the two lowest lower bounds and the two highest upper bounds, with the box of the extreme one.
    let mut lo = [(f64::INFINITY, f64::INFINITY, usize::MAX); 2];
    let mut hi = [(f64::NEG_INFINITY, f64::NEG_INFINITY, usize::MAX); 2];
    for (i, (min, max)) in boxes().enumerate() {
        for k in 0..2 {
            if min[k] < lo[k].0 {
                lo[k] = (min[k], lo[k].0, i);
            } else if min[k] < lo[k].1 {
                lo[k].1 = min[k];
            }
            if max[k] > hi[k].0 {
                hi[k] = (max[k], hi[k].0, i);
            } else if max[k] > hi[k].1 {
                hi[k].1 = max[k];
            }
        }
    }
    let cells = |without: usize| -> f64 {
        (0..2)
            .map(|k| {
                let a = if lo[k].2 == without { lo[k].1 } else { lo[k].0 };
                let b = if hi[k].2 == without { hi[k].1 } else { hi[k].0 };
                if b >= a {
                    ((b - a) / cell).floor() + 1.0
                } else {
                    0.0
                }
            })
            .product()
    };
    let all = cells(usize::MAX);
    let what = format!(
        "the fluid's neighbour grid over x {} to {} m, y {} to {} m has {} cells of 2h = {} m",
        Num(lo[0].0),
        Num(hi[0].0),
        Num(lo[1].0),
        Num(hi[1].0),
        count(all),
        Num(cell)
    );
    let (shrink, far) = [lo[0].2, lo[1].2, hi[0].2, hi[1].2]
        .into_iter()
        .filter(|&i| i != usize::MAX)
        .map(|i| (all - cells(i), i))
        .fold((0.0, usize::MAX), |best, c| if c.0 > best.0 { c } else { best });
    let key = match far {
        i if shrink > 0.5 * all && i < blocks.len() => format!("fluid.block[{i}]"),
        i if shrink > 0.5 * all => format!("wall[{}]", i - blocks.len()),
        _ => "fluid.spacing".to_string(),
    };
    (all, key, what)
}

/// A count as an integer up to 10⁷, in scientific notation above.
pub fn count(n: f64) -> String {
    if !n.is_finite() {
        "more than 1e308".to_string()
    } else if n < 1e7 {
        format!("{n:.0}")
    } else {
        format!("{n:.2e}")
    }
}

/// Bytes in binary units (KiB, MiB, GiB, TiB, …).
pub fn bytes_text(bytes: f64) -> String {
    const UNITS: [&str; 7] = ["B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    if !bytes.is_finite() {
        return "more than 1e308 B".to_string();
    }
    let (mut v, mut u) = (bytes, 0);
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    match u {
        0 => format!("{v:.0} B"),
        _ => format!("{:.1} {}", Num(v), UNITS[u]),
    }
}
