//! Scene validation at the limits (issue 17): names checked in linear time, non-finite numbers refused, the fixed
//! box test without listing the mesh, and the sizing of a scene from its numbers alone.

use cosim_proto::scene::{parse, Scene};
use cosim_proto::sizing::{Part, Sizing, MAX_COUNT};
use proptest::prelude::*;

const PLATE: &str = r#"
version = 1
[run]
name = "s"
end_time = 1.0
output_interval = 0.1
[[solid]]
name = "a"
min = [0.0, 0.0]
max = [1.0, 0.1]
divisions = [10, 1]
material = { model = "linear_elastic", density = 1000.0, youngs_modulus = 1e6, poisson_ratio = 0.3 }
"#;

/// The dam break of `scenes/dam_break.toml` (Δx = 2 mm: 50 × 100 particles).
const DAM: &str = r#"
version = 1
[run]
name = "dam"
end_time = 0.2
output_interval = 0.005
[fluid]
density = 1000.0
spacing = 0.002
[[fluid.block]]
min = [0.0, 0.0]
max = [0.1, 0.2]
[[wall]]
min = [-0.008, -0.008]
max = [0.608, 0.0]
[[wall]]
min = [-0.008, 0.0]
max = [0.0, 0.3]
[[wall]]
min = [0.6, 0.0]
max = [0.608, 0.3]
"#;

fn err(text: &str, sets: &[&str]) -> String {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    parse("f.toml", text, &sets).unwrap_err().to_string()
}

fn ok(text: &str, sets: &[&str]) -> Scene {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    parse("f.toml", text, &sets).unwrap()
}

#[test]
fn duplicate_names_are_found_among_many() {
    let mut text = PLATE.to_string();
    for i in 0..20_000 {
        text.push_str(&format!(
            "[[probe]]\nname = \"p{i}\"\nkind = \"energy\"\npart = \"total\"\n"
        ));
    }
    ok(&text, &[]);
    assert_eq!(
        err(&text, &["probe[19999].name=p17"]),
        "f.toml: probe[19999].name: `p17` is used by another probe"
    );
    let two = format!("{PLATE}[[solid]]\nname = \"a\"\nmin = [0.0, 1.0]\nmax = [1.0, 1.1]\ndivisions = [10, 1]\nmaterial = {{ model = \"linear_elastic\", density = 1000.0, youngs_modulus = 1e6, poisson_ratio = 0.3 }}\n");
    assert_eq!(err(&two, &[]), "f.toml: solid[1].name: `a` is used by another solid");
    assert!(ok(&two, &["solid[1].name=b"]).solids.len() == 2);
}

#[test]
fn every_scene_number_must_be_finite() {
    let probe = format!(
        "{PLATE}[[probe]]\nname = \"tip\"\nkind = \"node_displacement\"\nsolid = \"a\"\npoint = [1.0, 0.05]\n\
         component = \"y\"\nreference = {{ file = \"r.csv\", t = \"t\", value = \"v\" }}\n"
    );
    ok(&probe, &[]);
    for (set, line) in [
        (
            "probe[0].point=[0.5, nan]",
            "f.toml: probe[0].point: must be finite, got [0.5, NaN]",
        ),
        (
            "probe[0].point=[inf, 0.0]",
            "f.toml: probe[0].point: must be finite, got [inf, 0.0]",
        ),
        (
            "probe[0].x_max=-inf",
            "f.toml: probe[0].x_max: must be finite, got -inf",
        ),
        (
            "probe[0].reference.t_scale=nan",
            "f.toml: probe[0].reference.t_scale: must be finite, got NaN",
        ),
        (
            "probe[0].reference.t_offset=inf",
            "f.toml: probe[0].reference.t_offset: must be finite, got inf",
        ),
    ] {
        assert_eq!(err(&probe, &[set]), line, "{set}");
    }
    let fixed = format!("{PLATE}fixed = [{{ min = [-0.1, -0.1], max = [0.01, 0.2] }}]\n");
    ok(&fixed, &[]);
    assert_eq!(
        err(&fixed, &["solid[0].fixed[0].min=[nan, -0.1]"]),
        "f.toml: solid[0].fixed[0]: corners must be finite, got min [NaN, -0.1] max [0.01, 0.2]"
    );
    // An infinite box would hold every node: refused as well, not taken as "clamp everything".
    assert!(err(&fixed, &["solid[0].fixed[0].max=[inf, inf]"]).starts_with("f.toml: solid[0].fixed[0]: corners"));
}

#[test]
fn walls_without_water_and_an_empty_scene_are_refused() {
    let empty = PLATE.split("[[solid]]").next().unwrap();
    assert_eq!(
        err(empty, &[]),
        "f.toml: solid: nothing to run: the scene has no [[solid]] and no [fluid]"
    );
    let walls = format!("{PLATE}[[wall]]\nmin = [0.0, -0.1]\nmax = [1.0, 0.0]\n");
    assert_eq!(
        err(&walls, &[]),
        "f.toml: wall: walls hold water: a scene with [[wall]] needs a [fluid]"
    );
}

proptest! {
    /// The fixed-box test by binary search per axis agrees with testing every node of the mesh.
    #[test]
    fn fixed_box_search_agrees_with_the_listing(
        nx in 1u32..40, ny in 1u32..40,
        x0 in -2.0f64..2.0, y0 in -2.0f64..2.0, w in 0.01f64..3.0, h in 0.01f64..3.0,
        bx in -3.0f64..3.0, by in -3.0f64..3.0, bw in 0.0f64..2.0, bh in 0.0f64..2.0,
        on_node in proptest::bool::ANY,
    ) {
        let mut scene = ok(PLATE, &[]);
        let solid = &mut scene.solids[0];
        (solid.min, solid.max, solid.divisions) = ([x0, y0], [x0 + w, y0 + h], [nx, ny]);
        // Half the boxes start exactly on a node, where rounding decides.
        let start = if on_node { solid.grid_node(nx as usize / 2, ny as usize / 3) } else { [bx, by] };
        let b = cosim_proto::scene::BoxSpec { min: start, max: [start[0] + bw, start[1] + bh] };
        let listed = solid.grid_nodes().iter().any(|&p| b.contains(p));
        prop_assert_eq!(solid.has_node_in(&b), listed);
    }
}

#[test]
fn sizing_counts_what_the_nodes_make() {
    let dam = Sizing::of(&ok(DAM, &[]));
    assert_eq!(dam.fluid_particles, 5000.0);
    // As sph-node: 308 × 4 in the floor, 4 × 150 in each side wall.
    assert_eq!(dam.wall_particles, 2432.0);
    assert_eq!(dam.fem_nodes, 0.0);
    assert_eq!(dam.probe_samples, 0.0);
    // 0.628 m × 0.320 m of walls (grown by 3 layers each side) and water, over cells of 2h = 5.2 mm.
    assert_eq!(dam.grid_cells, 121.0 * 62.0);
    let tri = Sizing::of(&ok(PLATE, &["solid[0].element=tri3", "solid[0].divisions=[30, 4]"]));
    assert_eq!((tri.fem_nodes, tri.fem_elements), (31.0 * 5.0, 240.0));
    // Each node's share is part of the run's; the run holds more than its largest process.
    let run = dam.bytes(Part::Run);
    assert!(dam.bytes(Part::Fluid) > dam.bytes(Part::Broker) && run > dam.bytes(Part::Fluid) + dam.bytes(Part::Broker));
    assert_eq!(dam.bytes(Part::Structure), 0.0);
}

#[test]
fn ids_beyond_u32_are_refused_naming_the_key() {
    assert_eq!(MAX_COUNT, 4294967295.0);
    let line = err(DAM, &["fluid.spacing=1e-6"]);
    assert!(
        line.starts_with("f.toml: fluid.spacing: 1e-6 m makes 2.97e10 fluid and wall particles (2.00e10 fluid)"),
        "{line}"
    );
    assert!(
        line.contains("more than 4294967295") && line.contains("TiB of memory"),
        "{line}"
    );
    let line = err(PLATE, &["solid[0].divisions=[100000, 100000]"]);
    assert!(
        line.starts_with("f.toml: solid[0].divisions: [100000, 100000] makes 1.00e10 FE nodes"),
        "{line}"
    );
    // Just under the limit in elements, over it in nodes.
    let line = err(PLATE, &["solid[0].divisions=[65535, 65537]"]);
    assert!(line.contains("solid[0].divisions: [65535, 65537]"), "{line}");
    // A wall far from the water: few particles, but a neighbour grid of 1e10 cells over the gap.
    let far = format!("{DAM}[[wall]]\nmin = [500.0, 500.0]\nmax = [500.1, 500.1]\n");
    let line = err(&far, &[]);
    assert!(
        line.starts_with("f.toml: wall[3]: the fluid's neighbour grid"),
        "{line}"
    );
    assert!(line.contains("the most a grid numbers"), "{line}");
}

#[test]
fn memory_refusal_names_the_key_that_takes_most() {
    let gib = 1u64 << 30;
    let big = ok(DAM, &["fluid.spacing=2e-5"]);
    let (key, message) = Sizing::of(&big).refuse_above(Part::Run, gib).unwrap_err();
    assert_eq!(key, "fluid.spacing");
    assert!(
        message.starts_with("2e-5 m fills the fluid blocks with 5.00e7 particles: the run needs about"),
        "{message}"
    );
    assert!(message.ends_with("this machine has 1.0 GiB available"), "{message}");
    assert!(Sizing::of(&big).refuse_above(Part::Run, 1 << 40).is_ok());
    let (key, message) = Sizing::of(&ok(PLATE, &["solid[0].divisions=[20000, 20000]"]))
        .refuse_above(Part::Structure, gib)
        .unwrap_err();
    assert_eq!(key, "solid[0].divisions");
    assert!(
        message.starts_with("[20000, 20000] makes 4.00e8 nodes and 4.00e8 quad4 elements: fem-node needs"),
        "{message}"
    );
    // Probes sampled very often: the broker's series, keyed by the interval.
    let mut text = PLATE.to_string();
    text.push_str("[[probe]]\nname = \"e\"\nkind = \"energy\"\npart = \"total\"\n");
    let (key, message) = Sizing::of(&ok(&text, &["run.output_interval=1e-9"]))
        .refuse_above(Part::Broker, gib)
        .unwrap_err();
    assert_eq!(key, "run.output_interval");
    assert!(
        message.starts_with("1e-9 s samples 1 probe(s) 1.00e9 times"),
        "{message}"
    );
}
