//! One test per tunable scene key: its default, the range it takes, and the one-line error (file and key) beyond it.

use super::*;

#[test]
fn fluid_cfl_defaults_to_one_and_is_refused_above_one() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/dam_break.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let s = parse("d.toml", &text, &[]).unwrap();
    assert_eq!(s.fluid.as_ref().unwrap().cfl, 1.0);
    // At the default the resolved scene is written as before (checkpoints compare it line by line).
    assert!(!s.to_toml().lines().any(|l| l.starts_with("cfl")));
    let s = parse("d.toml", &text, &["fluid.cfl=0.9".into()]).unwrap();
    assert_eq!(s.fluid.as_ref().unwrap().cfl, 0.9);
    assert_eq!(parse("resolved", &s.to_toml(), &[]).unwrap(), s);
    for bad in ["1.1", "0", "-0.5", "nan", "1e-300", "9e-7"] {
        let e = err(&text, &[&format!("fluid.cfl={bad}")]);
        assert!(e.starts_with("f.toml: fluid.cfl: must be in [1e-6, 1]"), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}

#[test]
fn fluid_substeps_defaults_to_the_lockstep_in_its_range() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/hydrostatic_plate.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let s = parse("p.toml", &text, &[]).unwrap();
    assert_eq!(s.coupling.fluid_substeps, 1);
    // At the default the resolved scene is written as before (checkpoints compare it line by line).
    assert!(!s.to_toml().lines().any(|l| l.starts_with("fluid_substeps")));
    for ok in 1..=cosim_proto::scene::FLUID_SUBSTEPS_MAX {
        let s = parse("p.toml", &text, &[format!("coupling.fluid_substeps={ok}")]).unwrap();
        assert_eq!(s.coupling.fluid_substeps, ok);
        assert_eq!(parse("resolved", &s.to_toml(), &[]).unwrap(), s);
    }
    for bad in ["0", "9", "100"] {
        let e = err(&text, &[&format!("coupling.fluid_substeps={bad}")]);
        assert_eq!(
            e,
            format!(
                "f.toml: coupling.fluid_substeps: must be a whole number in [1, 8] (1: a contact pass after every fluid \
                 step), got {bad}"
            )
        );
    }
    for bad in ["2.5", "-1", "\"two\""] {
        let e = err(&text, &[&format!("coupling.fluid_substeps={bad}")]);
        assert!(e.starts_with("f.toml: coupling.fluid_substeps"), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}

#[test]
fn structure_courant_defaults_to_its_constant_in_its_range() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/elastic_gate.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let s = parse("g.toml", &text, &[]).unwrap();
    assert_eq!(
        s.coupling.structure_courant,
        cosim_proto::scene::STRUCTURE_COURANT_DEFAULT
    );
    assert_eq!(s.coupling.structure_courant, 0.05);
    // At the default the resolved scene is written as before (checkpoints compare it line by line).
    assert!(!s.to_toml().lines().any(|l| l.starts_with("structure_courant")));
    for ok in ["0", "0.001", "0.02", "1"] {
        let s = parse("g.toml", &text, &[format!("coupling.structure_courant={ok}")]).unwrap();
        assert_eq!(s.coupling.structure_courant, ok.parse::<f64>().unwrap());
        assert_eq!(parse("resolved", &s.to_toml(), &[]).unwrap(), s);
    }
    for bad in ["1.5", "-0.1", "nan", "inf", "1e-300", "0.0009"] {
        let e = err(&text, &[&format!("coupling.structure_courant={bad}")]);
        assert!(
            e.starts_with(
                "f.toml: coupling.structure_courant: must be 0 (no bound from the structure's speed) or in [0.001, 1]"
            ),
            "{e}"
        );
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}

#[test]
fn ppe_tolerance_is_for_isph_in_its_range_and_defaults_to_1e_6() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/dam_break.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let isph = "fluid.solver=\"isph\"";
    let s = parse("d.toml", &text, &[isph.into()]).unwrap();
    assert_eq!(s.fluid.as_ref().unwrap().ppe_tolerance(), 1e-6);
    assert!(!s.to_toml().lines().any(|l| l.starts_with("ppe_tolerance")));
    let s = parse("d.toml", &text, &[isph.into(), "fluid.ppe_tolerance=1e-8".into()]).unwrap();
    assert_eq!(s.fluid.as_ref().unwrap().ppe_tolerance(), 1e-8);
    assert_eq!(parse("resolved", &s.to_toml(), &[]).unwrap(), s);
    for bad in ["1e-2", "1e-13", "0", "-1e-6", "nan"] {
        let e = err(&text, &[isph, &format!("fluid.ppe_tolerance={bad}")]);
        assert!(
            e.starts_with("f.toml: fluid.ppe_tolerance: must be in [1e-12, 1e-3]"),
            "{e}"
        );
        assert_eq!(e.lines().count(), 1, "{e}");
    }
    let e = err(&text, &["fluid.ppe_tolerance=1e-6"]);
    assert_eq!(
        e, "f.toml: fluid.ppe_tolerance: applies to solver = \"isph\" only",
        "{e}"
    );
}

/// `contact.load_spread` (fluid spacings): 0 by default and then not written to the resolved scene; in [0, 4]; a
/// value outside is refused in one line naming the key.
#[test]
fn load_spread_defaults_to_zero_in_its_range() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/elastic_gate.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let s = parse("g.toml", &text, &[]).unwrap();
    assert_eq!(s.contact.load_spread, 0.0);
    assert!(!s.to_toml().contains("load_spread"));
    let s = parse("g.toml", &text, &["contact.load_spread=2".into()]).unwrap();
    assert_eq!(s.contact.load_spread, 2.0);
    assert_eq!(parse("resolved", &s.to_toml(), &[]).unwrap(), s);
    for bad in ["4.5", "-0.5", "nan", "inf"] {
        let e = err(&text, &[&format!("contact.load_spread={bad}")]);
        assert!(
            e.starts_with("f.toml: contact.load_spread: must be in [0, 4] fluid spacings"),
            "{e}"
        );
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}

/// `solid[i].mesh_damping` (the damping ratio of the mesh's highest mode): where the scene gives none, 0 for a
/// clamped solid and `FREE_MESH_DAMPING` (0.02) for one held nowhere, and then not written to the resolved scene; a
/// value given, 0 included, is the one in force; in [0, 1); a bad value is refused with one line naming the key.
#[test]
fn mesh_damping_defaults_by_how_the_solid_is_held_in_its_range() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/elastic_gate.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let s = parse("g.toml", &text, &[]).unwrap();
    assert_eq!((s.solids[0].mesh_damping, s.solids[0].mesh_damping()), (None, 0.0));
    assert!(!s.to_toml().contains("mesh_damping"));
    let free = parse("g.toml", &text, &["solid[0].fixed=[]".into()]).unwrap();
    assert_eq!(free.solids[0].mesh_damping(), cosim_proto::scene::FREE_MESH_DAMPING);
    assert_eq!(cosim_proto::scene::FREE_MESH_DAMPING, 0.02);
    assert!(!free.to_toml().contains("mesh_damping"));
    let undamped = parse(
        "g.toml",
        &text,
        &["solid[0].fixed=[]".into(), "solid[0].mesh_damping=0".into()],
    )
    .unwrap();
    assert_eq!(undamped.solids[0].mesh_damping(), 0.0);
    assert_eq!(parse("resolved", &undamped.to_toml(), &[]).unwrap(), undamped);
    let s = parse("g.toml", &text, &["solid[0].mesh_damping=0.25".into()]).unwrap();
    assert_eq!(s.solids[0].mesh_damping(), 0.25);
    assert_eq!(parse("resolved", &s.to_toml(), &[]).unwrap(), s);
    for bad in ["1", "1.5", "-0.1", "nan", "inf"] {
        let e = err(&text, &[&format!("solid[0].mesh_damping={bad}")]);
        assert!(
            e.starts_with(
                "f.toml: solid[0].mesh_damping: must be in [0, 1) (the damping ratio of the mesh's highest mode)"
            ),
            "{e}"
        );
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}

#[test]
fn frame_interval_is_a_whole_multiple_of_the_output_interval() {
    let s = parse("f.toml", SCENE, &[]).unwrap();
    assert_eq!(
        (s.run.frame_interval, s.run.frame_every(), s.run.frame_count()),
        (None, 1, 11)
    );
    // Absent, the resolved scene is written as before (checkpoints compare it line by line).
    assert!(!s.to_toml().contains("frame_interval"));
    let s = parse("f.toml", SCENE, &["run.frame_interval=0.3".into()]).unwrap();
    // 10 output times after t = 0: frames at 0, 3, 6, 9 and the last, 10.
    assert_eq!((s.run.frame_every(), s.run.frame_count()), (3, 5));
    assert!(s.run.is_frame(9, false) && !s.run.is_frame(10, false) && s.run.is_frame(10, true));
    assert_eq!(parse("resolved", &s.to_toml(), &[]).unwrap(), s);
    let s = parse("f.toml", SCENE, &["run.frame_interval=0.5".into()]).unwrap();
    assert_eq!(s.run.frame_count(), 3);
    for bad in ["0.25", "0.05", "0", "-0.1", "nan"] {
        let e = err(SCENE, &[&format!("run.frame_interval={bad}")]);
        assert!(e.starts_with("f.toml: run.frame_interval: "), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
    assert!(err(SCENE, &["run.frame_interval=0.25"]).contains("not a whole multiple of run.output_interval (0.1 s)"));
}

/// `contact.reaction_relaxation`: in (0, 1], with `particle_particle` only; absent from the resolved scene unless
/// given, so scenes and checkpoints written before it read the same.
#[test]
fn reaction_relaxation_is_a_fraction_for_particle_particle_only() {
    let pp = "contact.algorithm=particle_particle";
    let s = parse(
        "f.toml",
        SCENE,
        &[pp.to_string(), "contact.reaction_relaxation=0.1".into()],
    )
    .unwrap();
    assert_eq!(s.contact.reaction_relaxation, Some(0.1));
    assert!(s.to_toml().contains("reaction_relaxation = 0.1"));
    assert!(!parse("f.toml", SCENE, &[])
        .unwrap()
        .to_toml()
        .contains("reaction_relaxation"));
    for bad in ["0", "1.5", "-0.1", "nan"] {
        let e = err(SCENE, &[pp, &format!("contact.reaction_relaxation={bad}")]);
        assert!(
            e.contains("f.toml") && e.contains("contact.reaction_relaxation") && e.contains("(0, 1]"),
            "{bad}: {e}"
        );
    }
    let e = err(SCENE, &["contact.reaction_relaxation=0.5"]);
    assert!(
        e.contains("contact.reaction_relaxation") && e.contains("\"particle_particle\" only"),
        "{e}"
    );
}

#[test]
fn verlet_skin_is_for_wcsph_in_its_range_and_defaults_to_0_2() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/dam_break.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let s = parse("d.toml", &text, &[]).unwrap();
    assert_eq!(s.fluid.as_ref().unwrap().verlet_skin(), 0.2);
    assert_eq!(cosim_proto::scene::WCSPH_VERLET_SKIN_DEFAULT, 0.2);
    // At the default the resolved scene is written as before (checkpoints compare it line by line).
    assert!(!s.to_toml().lines().any(|l| l.starts_with("verlet_skin")));
    for ok in ["0", "0.5", "1"] {
        let s = parse("d.toml", &text, &[format!("fluid.verlet_skin={ok}")]).unwrap();
        assert_eq!(s.fluid.as_ref().unwrap().verlet_skin(), ok.parse::<f64>().unwrap());
        assert_eq!(parse("resolved", &s.to_toml(), &[]).unwrap(), s);
    }
    for bad in ["1.5", "-0.1", "nan", "inf"] {
        let e = err(&text, &[&format!("fluid.verlet_skin={bad}")]);
        assert!(
            e.starts_with("f.toml: fluid.verlet_skin: must be in [0, 1] (units of h; 0 searches every step)"),
            "{e}"
        );
        assert_eq!(e.lines().count(), 1, "{e}");
    }
    let isph = parse("d.toml", &text, &["fluid.solver=\"isph\"".into()]).unwrap();
    assert_eq!(isph.fluid.as_ref().unwrap().verlet_skin(), 0.0);
    let e = err(&text, &["fluid.solver=\"isph\"", "fluid.verlet_skin=0.2"]);
    assert_eq!(
        e,
        "f.toml: fluid.verlet_skin: applies to solver = \"wcsph\" only (the ISPH search runs every step)"
    );
}
