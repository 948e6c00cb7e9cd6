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
