//! `cosim run` of a structure-only scene end to end: the outputs of the run contract, processes against
//! in-process replay, thread-count independence and isolation of concurrent runs.

mod common;

use std::time::Duration;

use common::*;

const LIMIT: Duration = Duration::from_secs(240);

/// The shipped CSM3 scene, shortened.
fn csm3_args<'a>(out: &'a str, run: &'a str, end: &'a str) -> Vec<&'a str> {
    vec![
        "run",
        "scenes/csm3.toml",
        "--out",
        out,
        "--run-id",
        run,
        "--set",
        end,
        "--quiet",
    ]
}

#[test]
fn processes_run_writes_every_output_of_the_contract() {
    let dir = scratch("contract");
    let out = dir.join("out");
    let out_s = out.to_str().unwrap();
    run_ok(&csm3_args(out_s, &run_id("contract"), "run.end_time=0.2"));

    let s = json(&out.join("summary.json"));
    assert_eq!(s["status"], "ok");
    assert_eq!(s["mode"], "processes");
    assert_eq!(s["sim_time"].as_f64().unwrap(), 0.2);
    assert_eq!(s["fem_nodes"].as_u64().unwrap(), 71 * 5);
    assert_eq!(s["fem_elements"].as_u64().unwrap(), 70 * 4);
    assert_eq!(s["particles"].as_u64().unwrap(), 0);
    // max_dt 0.002 and output every 0.01: 100 coupling steps.
    assert_eq!(s["steps"].as_u64().unwrap(), 100);
    for k in ["fem", "sph", "broker", "messaging"] {
        assert!(s["timings"][k].as_f64().unwrap() >= 0.0, "timings.{k}");
    }
    for k in [
        "contacts",
        "max_penetration",
        "linear_momentum_change",
        "angular_momentum_change",
    ] {
        assert!(s["contact_stats"][k].is_number(), "contact_stats.{k}");
    }
    // No fluid, no contact: nothing relaxed, and the key says so.
    assert!(s["reaction_relaxation"].is_null(), "{s}");
    assert!(s["contact_step_bound"].is_null(), "{s}");
    // No fluid: no water whose releasable energy a gain is measured against.
    assert!(s["energy_growth"].is_null(), "{s}");

    let csv = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), "t,tip_ux,tip_uy,energy_total");
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 21, "samples at t = 0, 0.01, ..., 0.2");
    assert_eq!(rows[0][0], 0.0);
    assert_eq!(rows[0][2], 0.0, "starts undeformed");
    assert!((rows[20][0] - 0.2).abs() < 1e-12);
    assert!(
        rows[20][2] < -1e-3,
        "the bar sags under gravity: tip_uy = {}",
        rows[20][2]
    );

    let frames = out.join("frames");
    let vtu = std::fs::read_dir(&frames)
        .unwrap()
        .filter(|e| e.as_ref().unwrap().path().extension().is_some_and(|x| x == "vtu"));
    assert_eq!(vtu.count(), 21);
    let pvd = std::fs::read_to_string(frames.join("structure.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 21);
    for p in ["tip_ux", "tip_uy", "energy_total"] {
        let plot = out.join("plots").join(format!("{p}.svg"));
        assert!(
            std::fs::metadata(&plot).map(|m| m.len() > 500).unwrap_or(false),
            "{} missing",
            plot.display()
        );
    }
    let svg = std::fs::read_to_string(out.join("plots/tip_uy.svg")).unwrap();
    assert!(svg.contains("Turek"), "the reference is drawn and labelled");
}

#[test]
fn in_process_and_processes_give_identical_probes_for_any_thread_count() {
    let dir = scratch("replay");
    let a = dir.join("processes");
    let b = dir.join("in-process");
    let c = dir.join("in-process-1-thread");
    let d = dir.join("processes-2-threads");
    let end = "run.end_time=0.3";
    run_ok(&csm3_args(a.to_str().unwrap(), &run_id("replay-a"), end));
    run_ok(
        &[
            csm3_args(b.to_str().unwrap(), &run_id("replay-b"), end),
            vec!["--in-process"],
        ]
        .concat(),
    );
    run_ok(
        &[
            csm3_args(c.to_str().unwrap(), &run_id("replay-c"), end),
            vec!["--in-process", "--threads", "1"],
        ]
        .concat(),
    );
    run_ok(
        &[
            csm3_args(d.to_str().unwrap(), &run_id("replay-d"), end),
            vec!["--threads", "2"],
        ]
        .concat(),
    );
    let read = |p: &std::path::Path| std::fs::read(p.join("probes.csv")).unwrap();
    let reference = read(&a);
    assert!(reference.len() > 100);
    assert_eq!(read(&b), reference, "in-process differs from processes");
    assert_eq!(read(&c), reference, "1 thread differs");
    assert_eq!(read(&d), reference, "2 threads differ");
    assert_eq!(json(&b.join("summary.json"))["mode"], "in-process");
}

#[test]
fn parallel_element_loop_gives_the_same_bits_on_1_and_2_threads_across_modes() {
    // 5,000 elements: above the size where the element loop runs on the thread pool.
    let dir = scratch("parallel");
    let (a, b) = (dir.join("a"), dir.join("b"));
    let common = [
        "run",
        "scenes/bench_5000.toml",
        "--quiet",
        "--set",
        "run.end_time=0.02",
        "--set",
        "run.output_interval=0.005",
    ];
    run_ok(
        &[
            &common[..],
            &[
                "--out",
                a.to_str().unwrap(),
                "--threads",
                "2",
                "--run-id",
                &run_id("par-a"),
            ],
        ]
        .concat(),
    );
    run_ok(
        &[
            &common[..],
            &["--out", b.to_str().unwrap(), "--threads", "1", "--in-process"],
        ]
        .concat(),
    );
    let (pa, pb) = (
        std::fs::read(a.join("probes.csv")).unwrap(),
        std::fs::read(b.join("probes.csv")).unwrap(),
    );
    assert_eq!(pa.iter().filter(|&&c| c == b'\n').count(), 6);
    assert_eq!(pa, pb);
}

#[test]
fn two_runs_at_once_do_not_collide() {
    let dir = scratch("concurrent");
    let a = dir.join("a");
    let b = dir.join("b");
    let (ia, ib) = (run_id("conc-a"), run_id("conc-b"));
    let args_a = csm3_args(a.to_str().unwrap(), &ia, "run.end_time=0.1");
    let args_b = [
        csm3_args(b.to_str().unwrap(), &ib, "run.end_time=0.1"),
        vec!["--set", "solid[0].material.youngs_modulus=2.8e6"],
    ]
    .concat();
    let (ra, rb) = std::thread::scope(|s| {
        let ta = s.spawn(|| run_ok(&args_a));
        let tb = s.spawn(|| run_ok(&args_b));
        (ta.join().unwrap(), tb.join().unwrap())
    });
    assert!(ra.status.success() && rb.status.success());
    let (pa, pb) = (
        std::fs::read(a.join("probes.csv")).unwrap(),
        std::fs::read(b.join("probes.csv")).unwrap(),
    );
    assert_ne!(
        pa, pb,
        "different stiffness must give different probes: the runs crossed"
    );
    assert_eq!(json(&a.join("summary.json"))["run_id"], ia.as_str());
    assert_eq!(json(&b.join("summary.json"))["run_id"], ib.as_str());
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

/// `cosim check` says how many mesh cells of each solid a fluid particle weighs (ρ Δx² / (ρ_s w h / (nx ny))): the
/// shipped gate's 2 mm particles 3.64 of its 1 mm cells, no warning; 4 mm particles against cells half as wide, 58.2,
/// over the bound of 30, and both `check` and `run` warn, naming the solid (docs/CORRECTIONS.md "The structure's mesh
/// against the fluid's particles": that gate gains 0.106 of its budget with WCSPH).
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

#[test]
fn a_blow_up_ends_the_run_unstable_and_keeps_what_was_computed() {
    // A soft bar under a huge load: its elements invert within a few steps.
    let dir = scratch("unstable");
    let out = dir.join("out");
    let mut cmd = std::process::Command::new(cosim());
    cmd.current_dir(root()).env("COSIM_BIN_DIR", bin_dir()).args([
        "run",
        "scenes/csm3.toml",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--run-id",
        &run_id("unstable"),
        "--set",
        "run.gravity=[0.0, -1.0e5]",
        "--set",
        "run.end_time=1.0",
    ]);
    let res = run_bounded(&mut cmd, LIMIT);
    let err = String::from_utf8_lossy(&res.stderr);
    assert_eq!(res.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("unstable") && err.contains("element"), "{err}");
    let s = json(&out.join("summary.json"));
    assert_eq!(s["status"], "unstable");
    assert!(s["sim_time"].as_f64().unwrap() < 1.0);
    // The samples taken before the blow-up are kept, and they are finite.
    let csv = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    let rows = csv.lines().skip(1).count();
    assert!(
        rows >= 1 && rows as u64 == s["samples"].as_u64().unwrap(),
        "{rows} rows"
    );
    assert!(csv
        .lines()
        .skip(1)
        .all(|l| l.split(',').all(|v| v.parse::<f64>().unwrap().is_finite())));
    assert!(out.join("frames/structure.pvd").is_file());
}

#[test]
fn fluid_only_dam_break_runs_as_processes_and_replays_in_process_bit_for_bit() {
    let dir = scratch("fluid");
    let (a, b) = (dir.join("processes"), dir.join("in-process"));
    let common = [
        "run",
        "scenes/dam_break.toml",
        "--quiet",
        "--set",
        "fluid.spacing=0.01",
        "--set",
        "run.end_time=0.05",
        "--set",
        "run.output_interval=0.01",
    ];
    run_ok(
        &[
            &common[..],
            &[
                "--out",
                a.to_str().unwrap(),
                "--run-id",
                &run_id("fluid-a"),
                "--threads",
                "2",
            ],
        ]
        .concat(),
    );
    run_ok(
        &[
            &common[..],
            &["--out", b.to_str().unwrap(), "--in-process", "--threads", "1"],
        ]
        .concat(),
    );
    let s = json(&a.join("summary.json"));
    assert_eq!(s["status"], "ok");
    assert_eq!(s["solver"], "wcsph");
    assert_eq!(s["particles"].as_u64().unwrap(), 10 * 20, "0.1 x 0.2 m at 1 cm");
    assert_eq!(s["fem_nodes"].as_u64().unwrap(), 0);
    assert!(s["timings"]["sph"].as_f64().unwrap() > 0.0);
    let (pa, pb) = (
        std::fs::read(a.join("probes.csv")).unwrap(),
        std::fs::read(b.join("probes.csv")).unwrap(),
    );
    assert_eq!(pa, pb, "in-process differs from processes");
    let csv = String::from_utf8(pa).unwrap();
    assert_eq!(
        csv.lines().next().unwrap(),
        "t,surge_front,surge_front_mps,column_height,p_floor,energy"
    );
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 6);
    // The front starts at the column's last particle (a - dx/2) and moves downstream.
    assert_eq!(rows[0][1], 0.095);
    assert!(rows[5][1] > rows[0][1] + 0.01, "front moved: {:?}", rows[5]);
    let pvd = std::fs::read_to_string(a.join("frames/particles.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 6);
    assert!(a.join("plots/surge_front.svg").is_file());
}

#[test]
fn isph_dam_break_replays_in_process_bit_for_bit() {
    let dir = scratch("isph");
    let (a, b) = (dir.join("processes"), dir.join("in-process"));
    let common = [
        "run",
        "scenes/dam_break.toml",
        "--quiet",
        "--set",
        "fluid.solver=isph",
        "--set",
        "fluid.spacing=0.01",
        "--set",
        "run.end_time=0.05",
        "--set",
        "run.output_interval=0.01",
    ];
    run_ok(
        &[
            &common[..],
            &[
                "--out",
                a.to_str().unwrap(),
                "--run-id",
                &run_id("isph-a"),
                "--threads",
                "2",
            ],
        ]
        .concat(),
    );
    run_ok(
        &[
            &common[..],
            &["--out", b.to_str().unwrap(), "--in-process", "--threads", "1"],
        ]
        .concat(),
    );
    let s = json(&a.join("summary.json"));
    assert_eq!((s["status"].as_str(), s["solver"].as_str()), (Some("ok"), Some("isph")));
    let (pa, pb) = (
        std::fs::read(a.join("probes.csv")).unwrap(),
        std::fs::read(b.join("probes.csv")).unwrap(),
    );
    assert_eq!(pa, pb, "in-process differs from processes");
    let last: Vec<f64> = String::from_utf8(pa)
        .unwrap()
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(last[1] > 0.1, "the front moved downstream: {last:?}");
}
