//! Bad input never panics: every case exits non-zero within seconds with one line naming the file, the key and
//! the problem.

mod common;

use std::process::Command;
use std::time::{Duration, Instant};

use common::*;

const LIMIT: Duration = Duration::from_secs(30);

const GOOD: &str = BEAM_SCENE;

/// `write_scene` with this file's folder prefix.
fn write_scene(name: &str, text: &str) -> Scratch {
    common::write_scene("bad", name, text)
}

/// Runs `cosim run` on the scene and returns (exit code, stderr).
fn run_scene(name: &str, text: &str) -> (i32, String) {
    let path = write_scene(name, text);
    let out_dir = path.parent().unwrap().join("out");
    let out = cosim_run(
        &[
            "run",
            path.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
            "--quiet",
        ],
        LIMIT,
    );
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn assert_refused(name: &str, text: &str, key: &str, words: &str) {
    let (code, err) = run_scene(name, text);
    assert_eq!(code, 2, "{name}: exit code; stderr: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{name}: one line expected, got: {err}");
    let line = lines[0];
    assert!(line.contains(&format!("{name}.toml")), "{name}: file not named: {line}");
    assert!(line.contains(key), "{name}: key `{key}` not named: {line}");
    assert!(line.contains(words), "{name}: `{words}` not said: {line}");
    assert!(!line.contains("panicked"), "{name}: {line}");
}

#[test]
fn unknown_key() {
    assert_refused(
        "unknown",
        &GOOD.replace("divisions = [10, 2]", "divisions = [10, 2]\ncolour = 3"),
        "solid[0].colour",
        "unknown key",
    );
}

#[test]
fn missing_key() {
    assert_refused(
        "missing",
        &GOOD.replace("end_time = 0.01\n", ""),
        "run.end_time",
        "missing key",
    );
}

#[test]
fn youngs_modulus_not_positive() {
    assert_refused(
        "young",
        &GOOD.replace("youngs_modulus = 1.0e6", "youngs_modulus = 0.0"),
        "solid[0].material.youngs_modulus",
        "positive",
    );
    assert_refused(
        "young_neg",
        &GOOD.replace("youngs_modulus = 1.0e6", "youngs_modulus = -5.0"),
        "solid[0].material.youngs_modulus",
        "positive",
    );
}

#[test]
fn poisson_ratio_out_of_range() {
    assert_refused(
        "nu_half",
        &GOOD.replace("poisson_ratio = 0.3", "poisson_ratio = 0.5"),
        "solid[0].material.poisson_ratio",
        "[0, 0.5)",
    );
    assert_refused(
        "nu_neg",
        &GOOD.replace("poisson_ratio = 0.3", "poisson_ratio = -0.1"),
        "solid[0].material.poisson_ratio",
        "[0, 0.5)",
    );
}

#[test]
fn density_not_positive() {
    assert_refused(
        "density",
        &GOOD.replace("density = 1000.0", "density = 0.0"),
        "solid[0].material.density",
        "positive",
    );
}

#[test]
fn zero_divisions() {
    assert_refused(
        "divisions",
        &GOOD.replace("divisions = [10, 2]", "divisions = [10, 0]"),
        "solid[0].divisions",
        "at least 1",
    );
}

#[test]
fn fixed_box_without_nodes() {
    let text = GOOD.replace(
        "max = [0.001, 0.011] }",
        "max = [0.001, 0.011] }, { min = [0.2, 0.2], max = [0.3, 0.3] }",
    );
    assert_refused("fixed", &text, "solid[0].fixed[1]", "holds no node");
}

#[test]
fn probe_names_a_missing_solid() {
    assert_refused(
        "probe",
        &GOOD.replace("solid = \"beam\"", "solid = \"gate\""),
        "probe[0].solid",
        "no solid named `gate`",
    );
}

#[test]
fn end_time_not_positive() {
    assert_refused(
        "end",
        &GOOD.replace("end_time = 0.01", "end_time = 0.0"),
        "run.end_time",
        "positive",
    );
    assert_refused(
        "end_neg",
        &GOOD.replace("end_time = 0.01", "end_time = -1.0"),
        "run.end_time",
        "positive",
    );
}

#[test]
fn wrong_type_and_syntax_error() {
    assert_refused(
        "type",
        &GOOD.replace("end_time = 0.01", "end_time = \"soon\""),
        "run.end_time",
        "invalid type",
    );
    assert_refused("syntax", &GOOD.replace("[run]", "[run"), "line", "");
}

#[test]
fn bad_override_names_the_set_key() {
    let path = write_scene("set", GOOD);
    let out = cosim_run(
        &[
            "check",
            path.to_str().unwrap(),
            "--set",
            "solid[0].material.poisson_ratio=0.7",
        ],
        LIMIT,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("solid[0].material.poisson_ratio") && err.contains("[0, 0.5)"),
        "{err}"
    );
    let out = cosim_run(&["check", path.to_str().unwrap(), "--set", "run.colour=1"], LIMIT);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("run.colour") && err.contains("unknown key"), "{err}");
}

#[test]
fn missing_scene_file() {
    let out = cosim_run(&["run", "/nonexistent/scene.toml", "--quiet"], LIMIT);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("/nonexistent/scene.toml") && err.contains("cannot read"),
        "{err}"
    );
}

#[test]
fn missing_fem_node_program_is_reported_within_seconds() {
    // A folder holding cosim and the broker but no fem-node, and a PATH without it.
    let dir = scratch("nofem");
    for p in ["cosim", "contact-broker"] {
        std::fs::copy(program(p), dir.join(p)).unwrap();
    }
    let scene = write_scene("nofem_scene", GOOD);
    let start = Instant::now();
    let out = run_bounded(
        Command::new(dir.join("cosim"))
            .args([
                "run",
                scene.to_str().unwrap(),
                "--out",
                dir.join("out").to_str().unwrap(),
                "--quiet",
            ])
            .env("PATH", "/usr/bin:/bin")
            .env_remove("COSIM_BIN_DIR"),
        LIMIT,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_ne!(out.status.code(), Some(0));
    assert!(err.contains("cannot find the `fem-node` program"), "{err}");
    assert!(start.elapsed() < Duration::from_secs(10), "took {:?}", start.elapsed());
}

#[test]
fn node_that_cannot_connect_fails_within_seconds() {
    let port = free_port();
    let start = Instant::now();
    let out = run_bounded(
        Command::new(program("fem-node")).args([
            "--run",
            &run_id("noconnect"),
            "--connect",
            &format!("tcp/127.0.0.1:{port}"),
            "--timeout",
            "2",
        ]),
        LIMIT,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_ne!(out.status.code(), Some(0), "{err}");
    assert!(err.contains("cannot connect to tcp/127.0.0.1:"), "{err}");
    assert!(start.elapsed() < Duration::from_secs(10), "took {:?}", start.elapsed());
}

#[test]
fn node_with_no_broker_on_its_run_fails_within_seconds() {
    // A broker of another run listens; the node asks for a run nobody serves.
    let dir = scratch("wrongrun");
    let scene = write_scene("wrongrun_scene", GOOD);
    let mut broker = Command::new(program("contact-broker"))
        .args([
            "--run",
            &run_id("served"),
            "--scene",
            scene.to_str().unwrap(),
            "--out",
            dir.to_str().unwrap(),
            "--wait-nodes",
            "20",
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut line = String::new();
    std::io::BufRead::read_line(&mut std::io::BufReader::new(broker.stdout.as_mut().unwrap()), &mut line).unwrap();
    let v: serde_json::Value = serde_json::from_str(&line).unwrap();
    let endpoint = v["endpoints"]
        .as_array()
        .unwrap()
        .iter()
        .find_map(|e| e.as_str().filter(|e| e.starts_with("tcp/")))
        .unwrap()
        .to_string();
    let start = Instant::now();
    let out = run_bounded(
        Command::new(program("fem-node")).args([
            "--run",
            &run_id("unserved"),
            "--connect",
            &endpoint,
            "--timeout",
            "2",
        ]),
        LIMIT,
    );
    let _ = broker.kill();
    let _ = broker.wait();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_ne!(out.status.code(), Some(0), "{err}");
    assert!(err.contains("no broker of run"), "{err}");
    assert!(start.elapsed() < Duration::from_secs(10), "took {:?}", start.elapsed());
}

#[test]
fn fluid_block_overlapping_a_solid_is_refused_naming_the_key() {
    let text = GOOD.replace(
        "[[solid]]",
        "[fluid]\ndensity = 1000.0\nspacing = 0.005\n[[fluid.block]]\nmin = [0.0, -0.02]\nmax = [0.1, 0.1]\n\n[[solid]]",
    );
    assert_refused("fluid", &text, "fluid.block[0]", "overlaps solid `beam`");
}

#[test]
fn spacing_and_smoothing_ratio_out_of_range() {
    let fluid = |extra: &str| {
        format!(
            "version = 1\n[run]\nname = \"f\"\nend_time = 0.01\noutput_interval = 0.005\n[fluid]\ndensity = 1000.0\n{extra}\n[[fluid.block]]\nmin = [0.0, 0.0]\nmax = [0.1, 0.1]\n"
        )
    };
    assert_refused("spacing", &fluid("spacing = 0.0"), "fluid.spacing", "positive");
    assert_refused(
        "ratio",
        &fluid("spacing = 0.01\nsmoothing_ratio = 3.0"),
        "fluid.smoothing_ratio",
        "[1, 2]",
    );
    let overlap = fluid("spacing = 0.01") + "[[wall]]\nmin = [-0.05, -0.05]\nmax = [0.05, 0.05]\n";
    assert_refused("overlap", &overlap, "fluid.block[0]", "overlaps wall[0]");
}

#[test]
fn fluid_block_smaller_than_the_spacing() {
    let text = GOOD.replace(
        "[[solid]]",
        "[fluid]\ndensity = 1000.0\nspacing = 0.01\n[[fluid.block]]\nmin = [0.0, 0.02]\nmax = [0.005, 0.1]\n\n[[solid]]",
    );
    assert_refused("fluid_block", &text, "fluid.block[0]", "holds no particle");
}

#[test]
fn external_node_refused_where_it_cannot_join_and_a_missing_one_fails_within_seconds() {
    let path = write_scene("external", GOOD);
    let out_dir = path.parent().unwrap().join("out");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "run",
            path.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
            "--quiet",
        ];
        args.extend_from_slice(extra);
        let out = cosim_run(&args, LIMIT);
        (
            out.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    // A structure-only scene has no fluid node to replace.
    let (code, err) = run(&["--external", "sph"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--external sph") && err.contains("[fluid]"), "{err}");
    // An outside program joins over zenoh: not in one process.
    let (code, err) = run(&["--external", "fem", "--in-process"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--in-process"), "{err}");
    // Nobody joins: the run fails once the wait is over, saying who did not come, and leaves a summary.
    let started = Instant::now();
    let (code, err) = run(&["--external", "fem", "--wait-external", "2"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("waiting up to 2 s for an external fem node"), "{err}");
    assert!(err.contains("did not register within 2 s"), "{err}");
    assert!(started.elapsed() < Duration::from_secs(20), "{:?}", started.elapsed());
    assert_eq!(json(&out_dir.join("summary.json"))["status"], "failed");
}

/// An output folder that holds the user's own files is never cleared: a run clears `frames/`, `plots/` and `logs/`
/// of its folder, so `--out` at a project folder is refused (exit 2, one line naming the folder and what it holds),
/// by `cosim run` and by the broker started by hand, and everything in it stays. An earlier run's folder (it has the run's `summary.json`) and an empty one are taken.
/// Found 2026-12-06: `--out /tmp/proj` deleted `proj/logs/notes.txt`, and `--out /` wrote into the root.
#[test]
fn a_folder_of_the_users_is_never_cleared() {
    let dir = scratch("bad-out-folder");
    let project = dir.join("project");
    std::fs::create_dir_all(project.join("logs")).unwrap();
    std::fs::create_dir_all(project.join("plots")).unwrap();
    std::fs::write(project.join("logs/notes.txt"), "mine").unwrap();
    std::fs::write(project.join("plots/figure.svg"), "<svg/>").unwrap();
    let run = |out: &std::path::Path| {
        let mut cmd = Command::new(cosim());
        cmd.current_dir(root())
            .env("COSIM_BIN_DIR", bin_dir())
            .args([
                "run",
                "scenes/csm3.toml",
                "--quiet",
                "--set",
                "run.end_time=0.01",
                "--out",
            ])
            .arg(out);
        run_bounded(&mut cmd, LIMIT)
    };
    let out = run(&project);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains(&format!(
            "--out {}: the folder holds `logs`, `plots` and no summary.json",
            project.display()
        )),
        "{stderr}"
    );
    // The broker started by hand (a run over several hosts) refuses it the same way.
    let mut broker = Command::new(program("contact-broker"));
    broker
        .current_dir(root())
        .args(["--run", &run_id("foreign-out"), "--scene", "scenes/csm3.toml", "--out"])
        .arg(&project);
    let out = run_bounded(&mut broker, LIMIT);
    let said = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{said}");
    assert!(
        said.contains("the folder holds `logs`, `plots` and no summary.json"),
        "{said}"
    );
    assert_eq!(std::fs::read_to_string(project.join("logs/notes.txt")).unwrap(), "mine");
    assert_eq!(
        std::fs::read_to_string(project.join("plots/figure.svg")).unwrap(),
        "<svg/>"
    );
    assert!(!project.join("summary.json").exists());
    // A new folder, then the same folder again (an earlier run's, its frames replaced).
    let fresh = dir.join("fresh");
    for _ in 0..2 {
        let out = run(&fresh);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(json(&fresh.join("summary.json"))["status"], "ok");
    }
}
