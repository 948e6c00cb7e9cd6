//! Scene parsing: `--set` overrides, error keys, round trip of the resolved scene.

use cosim_proto::scene::{parse, ElementKind, MaterialModel};

const SCENE: &str = r#"
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

fn err(text: &str, sets: &[&str]) -> String {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    parse("f.toml", text, &sets).unwrap_err().to_string()
}

#[test]
fn defaults_and_overrides_by_index_name_and_single_item() {
    let s = parse("f.toml", SCENE, &[]).unwrap();
    assert_eq!(s.run.gravity, [0.0, -9.81]);
    assert_eq!(s.solids[0].element, ElementKind::Quad4);
    assert_eq!(s.coupling.max_dt, 1e-3);
    let sets = [
        "run.end_time=0.25",
        "solid[0].material.youngs_modulus=2e6",
        "solid.0.divisions=[20, 2]",
        "solid.material.model=neo_hookean",
        "solid[0].element=tri3",
        "coupling.max_dt=5e-4",
    ]
    .map(String::from);
    let s = parse("f.toml", SCENE, &sets).unwrap();
    assert_eq!(s.run.end_time, 0.25);
    assert_eq!(s.solids[0].material.youngs_modulus, 2e6);
    assert_eq!(s.solids[0].divisions, [20, 2]);
    assert_eq!(s.solids[0].material.model, MaterialModel::NeoHookean);
    assert_eq!(s.solids[0].element, ElementKind::Tri3);
    assert_eq!(s.coupling.max_dt, 5e-4);
}

#[test]
fn errors_name_file_and_key() {
    assert_eq!(err(SCENE, &["run.speed=3"]), "f.toml: run.speed: unknown key");
    // A slip of the keyboard is answered with the key meant (at most a third of its letters wrong); a key far from
    // every known one is not guessed at.
    assert_eq!(
        err(SCENE, &["run.end_tme=3"]),
        "f.toml: run.end_tme: unknown key (did you mean run.end_time?)"
    );
    assert_eq!(
        err(SCENE, &["solid[0].material.youngs_modlus=1e6"]),
        "f.toml: solid[0].material.youngs_modlus: unknown key (did you mean solid[0].material.youngs_modulus?)"
    );
    assert_eq!(
        err(&SCENE.replace("[run]", "[rnu]"), &[]),
        "f.toml: rnu: unknown key (did you mean run?)"
    );
    assert_eq!(
        err(&SCENE.replace("name = \"s\"\n", ""), &[]),
        "f.toml: run.name: missing key"
    );
    assert_eq!(
        err(SCENE, &["solid[0].material.poisson_ratio=0.5"]),
        "f.toml: solid[0].material.poisson_ratio: must be in [0, 0.5), got 0.5"
    );
    assert!(err(SCENE, &["solid[3].name=x"]).starts_with("f.toml: --set solid[3].name: index 3 out of range"));
    assert!(err(SCENE, &["novalue"]).contains("expected key.path=value"));
    assert!(err(&SCENE.replace("version = 1", "version = 2"), &[]).contains("version: this build reads version 1"));
    assert!(err(SCENE, &["solid[0].element=hex8"]).starts_with("f.toml: solid[0].element: unknown variant `hex8`"));
    // toml's "in `solid.divisions`" and line break after a value's error are not repeated after the key.
    assert_eq!(
        err(SCENE, &["solid[0].divisions=[1]"]),
        "f.toml: solid[0].divisions: invalid length 1, expected an array of length 2"
    );
}

/// A scene file that is not there, with a file beside it whose name is one slip away, names that file; a name far
/// from every file there names none.
#[test]
fn a_missing_scene_file_names_the_one_beside_it_meant() {
    let dir = std::env::temp_dir().join(format!("cosim-scene-near-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("elastic_gate.toml"), SCENE).unwrap();
    std::fs::write(dir.join("dam_break.toml"), SCENE).unwrap();
    let load = |name: &str| {
        cosim_proto::scene::load(&dir.join(name), &[])
            .err()
            .map(|e| e.to_string())
    };
    let slip = load("elastic_gat.toml").expect("refused");
    assert!(
        slip.ends_with(&format!("(did you mean {}?)", dir.join("elastic_gate.toml").display())),
        "{slip}"
    );
    let far = load("nothing_like_it.toml").expect("refused");
    assert!(far.contains("cannot read") && !far.contains("did you mean"), "{far}");
    assert!(load("dam_break.toml").is_none());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_column_probe_left_of_the_water_is_refused() {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/dam_break.toml")).unwrap();
    let scene = parse("dam_break.toml", &text, &[]).unwrap();
    let p = scene.probes.iter().position(|p| p.name == "column_height").unwrap();
    let first = scene.fluid.as_ref().unwrap().blocks[0].min[0] + 0.5 * scene.fluid.as_ref().unwrap().spacing;
    assert_eq!(
        err(&text, &[&format!("probe[{p}].x_max=-0.01")]),
        format!(
            "f.toml: probe[{p}].x_max: -0.01 is left of every fluid particle (the first are at x = {first}): \
             the column would be empty from the start"
        )
    );
    // Its first column of particles is inside: accepted.
    assert!(parse("f.toml", &text, &[format!("probe[{p}].x_max={first}")]).is_ok());
}

/// A sensor's face and time mean are pressure-probe keys; a face needs the normal it lies across.
#[test]
fn sensor_keys_are_checked_by_name() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/lobovsky_dam_break.toml"
    ))
    .unwrap();
    let scene = parse("f.toml", &text, &[]).unwrap();
    let p = scene.probes.iter().position(|p| p.name == "p_sensor1").unwrap();
    let front = scene.probes.iter().position(|p| p.name == "surge_front").unwrap();
    assert_eq!(
        err(&text, &[&format!("probe[{front}].average=interval")]),
        format!("f.toml: probe[{front}].average: only a pressure probe takes this key")
    );
    assert_eq!(
        err(&text, &[&format!("probe[{p}].radius=0.002")]),
        format!("f.toml: probe[{p}].normal: missing key (a face with radius > 0 needs the normal it lies across)")
    );
    assert_eq!(
        err(&text, &[&format!("probe[{p}].radius=-0.002")]),
        format!("f.toml: probe[{p}].radius: must be a finite length >= 0, got -0.002")
    );
    assert!(err(&text, &[&format!("probe[{p}].average=sometimes")]).contains("unknown variant `sometimes`"));
    let ok = [
        format!("probe[{p}].radius=0.002"),
        format!("probe[{p}].normal=[-1.0, 0.0]"),
    ];
    assert!(parse("f.toml", &text, &ok).is_ok());
    // An interface load needs a structure (the dam break has none).
    assert_eq!(
        err(&text, &[&format!("probe[{front}].kind=interface_load")]),
        format!("f.toml: probe[{front}].kind: needs a [[solid]] and a [fluid] in the scene")
    );
}

#[test]
fn resolved_scene_round_trips_through_toml() {
    let s = parse("f.toml", SCENE, &["run.end_time=0.5".into()]).unwrap();
    let again = parse("resolved", &s.to_toml(), &[]).unwrap();
    assert_eq!(s, again);
}

#[test]
fn a_fluid_without_gravity_needs_its_sound_speed() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/elastic_gate.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let refused = "f.toml: fluid.sound_speed: cannot default to 10 sqrt(2 g H) without gravity";
    // The gate gives c0 = 20 m/s; without it, gravity sets the default.
    let without = text.replace("sound_speed = 20.0", "");
    assert!(parse("f.toml", &without, &[]).is_ok());
    let e = err(&without, &["run.gravity=[0, 0]"]);
    assert!(e.starts_with(refused), "{e}");
    // ISPH needs c0 only for the `particle_particle` force against a solid.
    assert!(parse(
        "f.toml",
        &without,
        &["run.gravity=[0, 0]".into(), "fluid.solver=\"isph\"".into()]
    )
    .is_ok());
    let pp = [
        "run.gravity=[0, 0]",
        "fluid.solver=\"isph\"",
        "contact.algorithm=\"particle_particle\"",
    ];
    assert!(err(&without, &pp).starts_with(refused));
    assert!(
        parse("f.toml", &text, &["run.gravity=[0, 0]".into()]).is_ok(),
        "a value given"
    );
}

#[test]
fn a_node_probe_must_look_at_its_solid() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/csm3.toml");
    let text = std::fs::read_to_string(path).unwrap();
    // The bar is [0.25, 0.6] x [0.19, 0.21] in 70 x 4 cells: a cell's diagonal is 7.07e-3 m.
    for ok in ["[0.6, 0.2]", "[0.25, 0.19]", "[0.605, 0.2]", "[0.4, 0.215]"] {
        assert!(
            parse("f.toml", &text, &[format!("probe[0].point={ok}")]).is_ok(),
            "{ok}"
        );
    }
    for (bad, off) in [
        ("[0.7, 0.2]", "1.000e-1"),
        ("[0.608, 0.2]", "8.000e-3"),
        ("[1e308, 1e308]", "1.414e308"),
    ] {
        let e = err(&text, &[&format!("probe[0].point={bad}")]);
        assert!(
            e.starts_with(
                &format!(
                    "f.toml: probe[0].point: {} lies {off} m outside solid `bar`",
                    bad.replace(' ', "")
                )
                .replace(",", ", ")
            ),
            "{e}"
        );
    }
}

/// Values that passed `check` and then broke a run without naming their key (a sweep of extreme values over the
/// shipped scenes, 2026-12-06): now each is refused at once, naming it. The shipped values pass.
#[test]
fn extreme_values_are_refused_naming_their_key() {
    let shipped = |name: &str| {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenes")
            .join(name);
        std::fs::read_to_string(path).unwrap()
    };
    let (gate, lobovsky) = (shipped("elastic_gate.toml"), shipped("lobovsky_dam_break.toml"));
    assert!(parse("g.toml", &gate, &[]).is_ok());
    let refused = [
        // Magnitudes whose squares and products overflow or underflow (ρ², ρ c0², E / ρ).
        (
            &gate,
            "fluid.density=1e300",
            "fluid.density: 1e300 kg/m³ is outside the magnitudes",
        ),
        (
            &gate,
            "fluid.density=4.9e-324",
            "fluid.density: 5e-324 kg/m³ is outside the magnitudes",
        ),
        (
            &gate,
            "fluid.sound_speed=1e-300",
            "fluid.sound_speed: 1e-300 m/s is outside",
        ),
        (
            &gate,
            "fluid.kinematic_viscosity=1e-300",
            "fluid.kinematic_viscosity: 1e-300 m²/s is outside",
        ),
        (
            &gate,
            "run.gravity=[0.0, 1e-300]",
            "run.gravity: 1e-300 m/s² is outside",
        ),
        (
            &gate,
            "solid[0].material.youngs_modulus=1e300",
            "solid[0].material.youngs_modulus: 1e300 Pa",
        ),
        (
            &gate,
            "solid[0].material.density=1e-300",
            "solid[0].material.density: 1e-300 kg/m³",
        ),
        (
            &gate,
            "solid[0].damping=1e300",
            "solid[0].damping: 1e300 1/s is outside",
        ),
        (
            &gate,
            "solid[0].max=[1e300, 0.079]",
            "solid[0].max: corners min [0.1, 0.0] max [1e300, 0.079]",
        ),
        (&gate, "wall[1].min=[-1e300, 0.0]", "wall[1]: corners min [-1e300, 0.0]"),
        // A wall that is not a box is said as the wall's, not as a block overlapping it.
        (&gate, "wall[0].min=[nan, 0.0]", "wall[0].max: must be greater than min"),
        (
            &gate,
            "fluid.artificial_viscosity=5",
            "fluid.artificial_viscosity: must be in [0, 4]",
        ),
        (
            &gate,
            "coupling.fem_cfl=1e-300",
            "coupling.fem_cfl: must be in [1e-6, 0.9]",
        ),
        // The contact layer against the fluid's spacing (2 mm), per algorithm.
        (
            &gate,
            "contact.thickness=1e-300",
            "contact.thickness: 1e-300 m is outside [0.01 × spacing, 1 × spacing]",
        ),
        (
            &gate,
            "contact.thickness=0.0021",
            "contact.thickness: 0.0021 m is outside [0.01 × spacing",
        ),
        (
            &gate,
            "contact.thickness=1e300",
            "contact.thickness: 1e300 m is outside",
        ),
        // A pressure sensor's face sampled every quarter spacing: at most 100 spacings wide (1 m at 1 cm).
        (
            &lobovsky,
            "probe[0].radius=1.01",
            "probe[0].radius: 1.01 m is more than 100 fluid spacings (1 m)",
        ),
        // A gauge where no water can be.
        (
            &lobovsky,
            "probe[4].point=[0.3, -1e300]",
            "probe[4].point: [0.3, -1e300] lies outside the scene",
        ),
    ];
    for (text, set, start) in refused {
        let e = err(text, &[set]);
        assert!(e.starts_with(&format!("f.toml: {start}")), "{set}: {e}");
    }
    let pp = "contact.algorithm=\"particle_particle\"";
    let e = err(&gate, &[pp, "contact.thickness=0.0011"]);
    assert!(
        e.starts_with("f.toml: contact.thickness: 0.0011 m is outside [0.1 × spacing, 0.5 × spacing]"),
        "{e}"
    );
    for fine in [
        vec!["contact.thickness=0.002"],
        vec!["contact.thickness=0.00002"],
        vec![pp, "contact.thickness=0.001"],
        vec![pp, "contact.thickness=0.0002"],
        vec!["run.gravity=[0.0, 0.0]", "fluid.sound_speed=1e-50"],
    ] {
        let sets: Vec<String> = fine.iter().map(|s| s.to_string()).collect();
        assert!(parse("g.toml", &gate, &sets).is_ok(), "{fine:?}");
    }
    let sets = [
        "probe[0].radius=1.0".to_string(),
        "probe[0].normal=[1.0, 0.0]".to_string(),
    ];
    assert!(parse("l.toml", &lobovsky, &sets).is_ok());
}

mod key_ranges;
