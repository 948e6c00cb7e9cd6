//! `cosim check`: what it prints of a scene before anything runs — sizes, the coupling step it estimates, the
//! corrections in force — and the warnings it (and `cosim run`) gives of a coupling that will gain energy.

mod common;

use std::time::Duration;

use common::*;

/// A reader that closes the output early (`cosim check … | head -1`) ends the command without a panic's report
/// (`cosim::closed_stdout`); it printed "failed printing to stdout: Broken pipe" and a backtrace before.
#[test]
fn a_closed_output_ends_the_command_quietly() {
    use std::process::{Command, Stdio};

    let mut child = Command::new(cosim())
        .args(["check", root().join("scenes/csm3.toml").to_str().unwrap()])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The reading end closed before anything is written.
    drop(child.stdout.take());
    let until = std::time::Instant::now() + Duration::from_secs(30);
    let status = wait_exit(&mut child, until, "cosim check");
    let mut stderr = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut stderr).unwrap();
    assert!(!status.success(), "it cannot have printed what it checked");
    assert_eq!(stderr, "", "nothing said on stderr for a closed pipe");
}

#[test]
fn check_prints_what_would_run() {
    let out = cosim_run(
        &["check", root().join("scenes/csm3.toml").to_str().unwrap(), "--json"],
        Duration::from_secs(30),
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["fem_nodes"].as_u64().unwrap(), 355);
    assert_eq!(doc["fem_elements"].as_u64().unwrap(), 280);
    assert_eq!(doc["coupling_steps"].as_u64().unwrap(), 5000);
    assert!(doc["fem_dt_stable"].as_f64().unwrap() > 0.0);
}

/// `cosim check` estimates what the run writes into its output folder (`proto::scene::disk`; held to what runs
/// write by `output_size.rs`), with the checkpoints of `--checkpoint-interval` when given: csm3's 1,001 frames of
/// 66.6 KiB, and one checkpoint every 2.5 s of its 10 s (4), or one a coupling step for an interval below it.
#[test]
fn check_estimates_the_outputs_with_their_checkpoints() {
    let csm3 = root().join("scenes/csm3.toml");
    let check = |extra: &[&str]| {
        let mut args = vec!["check", csm3.to_str().unwrap()];
        args.extend_from_slice(extra);
        let out = cosim_run(&args, Duration::from_secs(30));
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let text = check(&[]);
    assert!(
        text.contains("  disk: about 65.2 MiB written to the output folder (1001 frames of 66.6 KiB"),
        "{text}"
    );
    let doc: serde_json::Value = serde_json::from_str(&check(&["--json", "--checkpoint-interval", "2.5"])).unwrap();
    assert_eq!(doc["estimate"]["checkpoints"], 4, "{doc}");
    let every_step = check(&["--checkpoint-interval=1e-300"]);
    assert!(every_step.contains("; 5000 checkpoints of "), "{every_step}");
}

/// `cosim check SCENE --json --set …` from the workspace root, its document (fails the test unless it succeeds).
fn check_json(scene: &str, sets: &[&str]) -> serde_json::Value {
    let path = root().join(scene);
    let mut args = vec!["check", path.to_str().unwrap(), "--json"];
    for set in sets {
        args.extend_from_slice(&["--set", set]);
    }
    let out = cosim_run(&args, Duration::from_secs(30));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// `cosim check` says where the coupling step will be shorter than its estimate: WCSPH with `particle_particle`,
/// whose stiff force bounds it as the run goes (contact-broker/src/contact_step.rs), not `particle_element` nor ISPH.
#[test]
fn check_says_when_the_contact_bounds_the_step() {
    let bounded =
        |extra: &[&str]| check_json("scenes/elastic_gate.toml", extra)["coupling_dt_bounded_by_contact"].clone();
    assert_eq!(bounded(&[]), false);
    assert_eq!(bounded(&["contact.algorithm=particle_particle"]), true);
    assert_eq!(
        bounded(&["contact.algorithm=particle_particle", "fluid.solver=isph"]),
        false
    );
}

/// `cosim check` estimates the coupling step as the broker fixes it: the fluid's stable step in lockstep (the
/// default), `coupling.fluid_substeps` − 0.05 of them with WCSPH and `particle_element`, rounded down to whole fluid
/// steps under `coupling.max_dt`; the lockstep again with `particle_particle` or ISPH.
#[test]
fn check_estimates_the_coupling_step_over_the_fluid_substeps() {
    let step = |extra: &[&str]| {
        let doc = check_json("scenes/elastic_gate.toml", extra);
        let (dt, fluid) = (
            doc["coupling_dt"].as_f64().unwrap(),
            doc["sph_dt_stable"].as_f64().unwrap(),
        );
        (dt / fluid, doc["coupling_fluid_steps_per_pass"].clone())
    };
    let lockstep = step(&["coupling.fluid_substeps=1"]);
    assert_eq!(lockstep, (1.0, serde_json::json!(1)));
    // The gate's fluid step is ~3e-5 s: 4 of them fit under a max_dt of 2e-4 s, 3 under 1e-4 s (3.3 steps).
    let (span, k) = step(&["coupling.fluid_substeps=4", "coupling.max_dt=2e-4"]);
    assert!((span - 3.95).abs() < 1e-12 && k == 4, "{span} {k}");
    let (span, k) = step(&["coupling.fluid_substeps=4", "coupling.max_dt=1e-4"]);
    assert!((span - 2.95).abs() < 1e-12 && k == 3, "{span} {k}");
    let pp = step(&[
        "coupling.fluid_substeps=4",
        "coupling.max_dt=2e-4",
        "contact.algorithm=particle_particle",
    ]);
    assert_eq!(pp, (1.0, serde_json::json!(1)));
}

/// `cosim check` says how many mesh cells of each solid a fluid particle weighs (ρ Δx² / (ρ_s w h / (nx ny))): the
/// shipped gate's 2 mm particles 3.64 of its 1 mm cells, no warning; 4 mm particles against cells half as wide, 58.2,
/// over the bound of 30, and both `check` and `run` warn, naming the solid (docs/CORRECTIONS.md "The structure's mesh
/// against the fluid's particles": that gate gains 0.106 of its budget with WCSPH); and, with the fluid sub-cycled
/// between contact passes (the scene's `coupling.fluid_substeps`), that a pass every few fluid steps rings it.
#[test]
fn check_and_run_warn_of_a_mesh_much_finer_than_the_fluid() {
    let check = |extra: &[&str]| check_json("scenes/elastic_gate.toml", extra);
    let shipped = check(&[]);
    let ratio = shipped["particle_to_cell_mass"]["gate"].as_f64().unwrap();
    assert!((ratio - 4.0 / 1.1).abs() < 1e-9, "{shipped}");
    assert_eq!(shipped["warnings"], serde_json::json!([]));
    let fine = ["fluid.spacing=0.004", "solid[0].divisions=[10,158]"];
    let doc = check(&fine);
    let ratio = doc["particle_to_cell_mass"]["gate"].as_f64().unwrap();
    assert!((ratio - 64.0 / 1.1).abs() < 1e-9, "{doc}");
    let warnings = doc["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{doc}");
    assert!(
        warnings[0].as_str().unwrap().contains("58 cells of solid `gate`"),
        "{doc}"
    );
    // With a max_dt that holds 3 of its fluid steps the scene's coupling.fluid_substeps = 8 sub-cycles the fluid: a
    // contact pass every 3 fluid steps against that mesh is warned of too; not in lockstep.
    let long = check(&[fine[0], fine[1], "coupling.max_dt=2.5e-4"]);
    let warnings = long["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 2, "{long}");
    assert!(
        warnings[1].as_str().unwrap().starts_with(
            "coupling.fluid_substeps = 8 against solid `gate`, whose cells a fluid particle outweighs 58.2 times \
             (above 4): a contact pass every 3 fluid steps"
        ),
        "{long}"
    );
    let lockstep = check(&[fine[0], fine[1], "coupling.max_dt=2.5e-4", "coupling.fluid_substeps=1"]);
    assert_eq!(lockstep["warnings"].as_array().unwrap().len(), 1, "{lockstep}");
    let dir = scratch("heavy-particle");
    let out = dir.join("out");
    let mut args = vec![
        "run",
        "scenes/elastic_gate.toml",
        "--in-process",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ];
    for set in fine
        .iter()
        .chain(&["run.end_time=0.0005", "run.output_interval=0.0005"])
    {
        args.extend_from_slice(&["--set", set]);
    }
    let run = run_ok(&args);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("cosim: warning: a fluid particle weighs 58 cells of solid `gate`"),
        "{stderr}"
    );
}

/// `cosim check` warns where, with ISPH, a coupling step spans many of the structure's FE steps against a mesh that a
/// particle outweighs and the structure's speed does not bound the step: the shipped gate left at the default
/// `coupling.max_dt` (1e-3: ISPH's own step, 76 FE steps) with `coupling.structure_courant = 0`, not at its own 1e-4
/// (25), nor with the bound (the default), nor the hydrostatic plate (78 FE steps, a particle of 1.5 cells), nor WCSPH.
#[test]
fn check_warns_of_an_isph_coupling_step_spanning_many_fe_steps() {
    let warnings = |scene: &str, extra: &[&str]| check_json(scene, extra)["warnings"].as_array().unwrap().clone();
    let isph = "fluid.solver=isph";
    let unbounded = "coupling.structure_courant=0";
    assert!(warnings("scenes/elastic_gate.toml", &[isph, "coupling.max_dt=1e-3"]).is_empty());
    let w = warnings("scenes/elastic_gate.toml", &[isph, "coupling.max_dt=1e-3", unbounded]);
    assert_eq!(w.len(), 1, "{w:?}");
    let w = w[0].as_str().unwrap();
    assert!(
        w.contains("spans 76 FE steps") && w.contains("try coupling.max_dt = 1e-4"),
        "{w}"
    );
    assert!(warnings("scenes/elastic_gate.toml", &[isph]).is_empty());
    assert!(warnings("scenes/elastic_gate.toml", &["coupling.max_dt=1e-3"]).is_empty());
    assert!(warnings("scenes/hydrostatic_plate.toml", &[isph]).is_empty());
}

/// `cosim check` and `cosim run` warn where WCSPH's pressure probes sit on a wall's vertical face (what a wall impact
/// reads there, docs/CORRECTIONS.md "WCSPH at the wall impact"): the Lobovsky scene's four sensor probes as
/// shipped, none with the δ-SPH it recommends or with ISPH, and no other shipped scene (the dam break's floor probe
/// is not on a side wall).
#[test]
fn check_and_run_warn_of_wcsph_pressure_probes_on_a_wall() {
    let warnings = |scene: &str, extra: &[&str]| check_json(scene, extra)["warnings"].as_array().unwrap().clone();
    let w = warnings("scenes/lobovsky_dam_break.toml", &[]);
    assert_eq!(w.len(), 1, "{w:?}");
    let w = w[0].as_str().unwrap();
    assert!(
        w.starts_with("pressure probes p_sensor1, p_sensor2, p_sensor1_raw, p_sensor2_raw on a wall")
            && w.contains("fluid.density_diffusion = 0.5"),
        "{w}"
    );
    assert!(warnings("scenes/lobovsky_dam_break.toml", &["fluid.density_diffusion=0.5"]).is_empty());
    assert!(warnings("scenes/lobovsky_dam_break.toml", &["fluid.solver=isph"]).is_empty());
    assert!(warnings("scenes/dam_break.toml", &[]).is_empty());
    // `cosim run` says it too, before it starts (a run of one millisecond).
    let dir = scratch("check-impact-warning");
    let out = cosim_run(
        &[
            "run",
            &root().join("scenes/lobovsky_dam_break.toml").display().to_string(),
            "--in-process",
            "--quiet",
            "--set",
            "run.end_time=0.001",
            "--out",
            &dir.join("out").display().to_string(),
        ],
        Duration::from_secs(60),
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("cosim: warning: pressure probes p_sensor1"), "{stderr}");
}

/// A solid with no `fixed` box is warned of (the walls act on the fluid only: gravity takes it through the floor;
/// `proto/src/scene/unheld.rs`); every shipped solid is held.
#[test]
fn check_warns_of_a_solid_held_nowhere() {
    let warnings = |scene: &str, extra: &[&str]| check_json(scene, extra)["warnings"].as_array().unwrap().clone();
    for scene in [
        "scenes/elastic_gate.toml",
        "scenes/elastic_obstacle.toml",
        "scenes/hydrostatic_plate.toml",
    ] {
        assert!(warnings(scene, &[]).is_empty(), "{scene}");
    }
    let w = warnings(
        "scenes/elastic_gate.toml",
        &["solid[0].fixed=[]", "solid[0].material.density=2700.0"],
    );
    assert_eq!(w.len(), 1, "{w:?}");
    let w = w[0].as_str().unwrap();
    assert!(
        w.starts_with("solid `gate` is held nowhere (no `fixed` box)") && w.ends_with("it sinks"),
        "{w}"
    );
    // Run, the walls stop it (`fem_node::walls` inside the structure's sub-steps): a block dropped 5 mm above the
    // floor, clear of the water, lands at t = 0.032 s (g t²/2 = 5 mm, 0.31 m/s) and bounces as an elastic body
    // does, to about a fifth of the drop and again (measured 0.87 mm with its mesh damped at its own scale, the
    // default of a solid held nowhere since 2026-12-08; 0.97 mm undamped; it rested within 0.6 µm of the face while
    // the broker stopped it once a coupling step, which made energy at faster landings: docs/CORRECTIONS.md "The
    // walls inside the structure's sub-steps"). Sampled every millisecond to t = 0.1 s, where a free fall would have
    // taken it 44 mm into the floor, its lowest node is never below the floor's face, comes within 0.5 mm of it
    // (a millisecond's fall at 0.31 m/s), never rises above 2 mm after landing (the bounce makes no energy), and no
    // node is found inside a wall (`solid_in_wall`).
    let dir = scratch("check-solid-on-floor");
    let out_dir = dir.join("out");
    let out = cosim_run(
        &[
            "run",
            &root().join("scenes/elastic_gate.toml").display().to_string(),
            "--in-process",
            "--quiet",
            "--set",
            "fluid.spacing=0.006",
            "--set",
            "run.end_time=0.1",
            "--set",
            "solid[0].min=[0.3,0.005]",
            "--set",
            "solid[0].max=[0.35,0.03]",
            "--set",
            "solid[0].divisions=[5,3]",
            "--set",
            "solid[0].fixed=[]",
            "--set",
            "probe[0].point=[0.325,0.005]",
            "--set",
            "probe[1].point=[0.325,0.005]",
            "--set",
            "run.output_interval=0.001",
            "--set",
            "run.frame_interval=0.1",
            "--out",
            &out_dir.display().to_string(),
        ],
        Duration::from_secs(60),
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("inside wall"), "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap()).unwrap();
    assert!(summary["solid_in_wall"].is_null(), "{}", summary["solid_in_wall"]);
    let probes = std::fs::read_to_string(out_dir.join("probes.csv")).unwrap();
    let last = probes.lines().last().unwrap();
    assert!(last.starts_with("0.1,"), "{last}");
    // (t, height of the lowest node above the floor's face).
    let heights: Vec<(f64, f64)> = probes
        .lines()
        .skip(1)
        .map(|l| {
            let mut c = l.split(',');
            let t: f64 = c.next().unwrap().parse().unwrap();
            let tip_y: f64 = c.nth(1).unwrap().parse().unwrap();
            (t, 0.005 + tip_y)
        })
        .collect();
    let lowest = heights.iter().map(|h| h.1).fold(f64::INFINITY, f64::min);
    assert!(
        lowest >= -1e-12,
        "the block's lowest node {lowest} m below the floor's face"
    );
    assert!(
        lowest < 5e-4,
        "the block never came within 0.5 mm of the floor: {lowest} m"
    );
    let bounce = heights
        .iter()
        .filter(|h| h.0 > 0.035)
        .map(|h| h.1)
        .fold(0.0f64, f64::max);
    assert!(bounce < 2e-3, "the block bounced {bounce} m high after a 5 mm drop");
    let gain = summary["energy_growth"]["largest"].as_f64().unwrap();
    assert!(gain < 0.01, "energy made: {gain} of the water's releasable energy");
}

/// `cosim check` says which corrections a fluid runs with (§4.4), the per-solver defaults filled in: WCSPH the
/// paper's Shepard filter, XSPH and APD β = 0.04; ISPH XSPH and APD β = 0.04, no density filter.
#[test]
fn check_names_the_corrections_in_force() {
    let dam = root().join("scenes/dam_break.toml");
    let check = |extra: &[&str]| {
        let mut args = vec!["check", dam.to_str().unwrap(), "--json"];
        args.extend_from_slice(extra);
        let out = cosim_run(&args, Duration::from_secs(30));
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()["corrections"].clone()
    };
    let wcsph = check(&[]);
    assert_eq!(wcsph["density_filter"], "shepard", "{wcsph}");
    assert_eq!(wcsph["density_filter_interval"], 20, "{wcsph}");
    assert_eq!(wcsph["xsph"], 0.5, "{wcsph}");
    assert_eq!(wcsph["apd"], 0.04, "{wcsph}");
    let isph = check(&["--set", "fluid.solver=isph"]);
    assert_eq!(isph["density_filter"], "none", "{isph}");
    assert_eq!(isph["apd"], 0.04, "{isph}");
    assert_eq!(check(&["--set", "fluid.apd=0"])["apd"], 0.0);
    let csm3 = cosim_run(
        &["check", root().join("scenes/csm3.toml").to_str().unwrap(), "--json"],
        Duration::from_secs(30),
    );
    let doc: serde_json::Value = serde_json::from_slice(&csm3.stdout).unwrap();
    assert!(doc["corrections"].is_null(), "a scene without fluid: {doc}");
}

/// `cosim check` estimates the run's work, element-steps and fluid particle-steps, from the first stable steps: on
/// the 4 mm gate to 0.05 s 4.87e6 and 6.74e5 against the run's 4.99e6 and 6.96e5 (its flow speeds up, its steps
/// shorten), and on csm3, a structure alone at a fixed step, exactly.
#[test]
fn check_estimates_the_work_a_run_does() {
    for (scene, sets, within) in [
        (
            "scenes/elastic_gate.toml",
            &["fluid.spacing=0.004", "run.end_time=0.05"][..],
            0.1,
        ),
        ("scenes/csm3.toml", &["run.end_time=0.5"][..], 1e-12),
    ] {
        let estimate = check_json(scene, sets)["work"].clone();
        let out = scratch("check-work").child(scene.trim_start_matches("scenes/"));
        let mut args = vec!["run", scene, "--in-process", "--quiet", "--out", out.to_str().unwrap()];
        for set in sets {
            args.extend_from_slice(&["--set", set]);
        }
        let mut run = std::process::Command::new(cosim());
        run.current_dir(root()).args(&args);
        let done = run_bounded(&mut run, Duration::from_secs(60));
        assert!(done.status.success(), "{}", String::from_utf8_lossy(&done.stderr));
        let s = json(&out.join("summary.json"));
        let count = |a: &str, b: &str| s[a].as_f64().unwrap() * s[b].as_f64().unwrap();
        for (key, done) in [
            ("element_steps", count("fem_substeps", "fem_elements")),
            ("particle_steps", count("sph_substeps", "particles")),
        ] {
            let guess = estimate[key].as_f64().unwrap();
            assert!(
                (guess - done).abs() <= within * done,
                "{scene}: {key} estimated {guess:e}, the run did {done:e}"
            );
        }
    }
}

/// `cosim check` says what a run's work costs in CPU seconds on one core (`work.cpu_seconds`, `estimate.rs`): for
/// telling seconds from hours, so it must come within twice the CPU time the shipped scenes take as `cosim run`
/// (three processes, one thread each, `--threads 1`; user + sys of the whole command, `/usr/bin/time`, this
/// project's 2-core machine, 2026-12-08; the estimates 33.2, 17.4, 10.5, 5.45, 20.4 and 14.8 s).
#[test]
fn check_estimates_the_cpu_time_of_the_shipped_scenes() {
    for (scene, sets, measured) in [
        ("scenes/elastic_gate.toml", &[][..], 37.2),
        ("scenes/elastic_obstacle.toml", &[][..], 15.6),
        ("scenes/hydrostatic_plate.toml", &[][..], 13.9),
        ("scenes/csm3.toml", &[][..], 4.9),
        ("scenes/dam_break.toml", &[][..], 18.4),
        ("scenes/lobovsky_dam_break.toml", &["fluid.solver=\"isph\""][..], 15.5),
    ] {
        let estimate = check_json(scene, sets)["work"]["cpu_seconds"].as_f64().unwrap();
        assert!(
            estimate > 0.5 * measured && estimate < 2.0 * measured,
            "{scene} {sets:?}: estimated {estimate:.1} CPU-s, measured {measured} CPU-s"
        );
    }
}
