//! Scenes at the limits (issue 17, the scene side of the trust boundary): a scene too big for the run's ids or for
//! this machine's memory, a million probes, non-finite numbers, overlapping solids and a scene with nothing to run
//! are each refused by `cosim check` and `cosim run` within seconds, exit code 2, with one line naming the key and
//! the value — before anything the size of the scene is allocated. So is a run that needs more steps than any run
//! can take (`contact_broker::step_budget`): found 2026-12-06, a viscosity of 1e300 m²/s held the fluid node in one
//! coupling step that Ctrl-C could not end, and a `coupling.max_dt` of 1e-300 ran ~18,000 steps a second toward
//! 1e301.

mod common;

use std::process::Output;
use std::time::{Duration, Instant};

use common::*;

const LIMIT: Duration = Duration::from_secs(30);

const PLATE: &str = BEAM_SCENE;

/// `write_scene` with this file's folder prefix.
fn write_scene(name: &str, text: &str) -> common::Scratch {
    common::write_scene("limits", name, text)
}

/// `cosim check|run SCENE --set …` in the workspace root (so `scenes/…` resolves), bounded by `limit`; a `sets` item
/// that starts with `--` is passed as it is.
fn cosim(command: &str, scene: &str, sets: &[&str], limit: Duration) -> Output {
    let out_dir = std::env::temp_dir().join(format!("cosim-test-limits-out-{}", std::process::id()));
    let out_dir = out_dir.to_str().unwrap().to_string();
    let mut args = vec![command, scene];
    for s in sets {
        match s.starts_with("--") {
            true => args.push(s),
            false => args.extend(["--set", s]),
        }
    }
    if command == "run" {
        args.extend(["--out", &out_dir, "--quiet"]);
    }
    let mut cmd = std::process::Command::new(common::cosim());
    cmd.current_dir(root()).args(&args).env("COSIM_BIN_DIR", bin_dir());
    run_bounded(&mut cmd, limit)
}

/// Asserts exit code 2 and one line on stderr that says each of `words`; returns the line.
fn refused(out: &Output, what: &str, words: &[&str]) -> String {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{what}: exit code; stderr: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{what}: one line expected, got: {err}");
    let line = lines[0];
    for w in words {
        assert!(line.contains(w), "{what}: `{w}` not said: {line}");
    }
    assert!(!line.contains("panicked"), "{what}: {line}");
    line.to_string()
}

fn both_refuse(scene: &str, sets: &[&str], words: &[&str]) {
    for command in ["check", "run"] {
        let started = Instant::now();
        let out = cosim(command, scene, sets, LIMIT);
        refused(&out, &format!("{command} {scene} {sets:?}"), words);
        assert!(
            started.elapsed() < Duration::from_secs(10),
            "{command}: took {:?}",
            started.elapsed()
        );
    }
}

#[test]
fn spacing_too_fine_for_u32_ids_is_refused_naming_the_spacing() {
    // 2e10 fluid particles: once "memory allocation of 320000000000 bytes failed" and a backtrace.
    both_refuse(
        "scenes/dam_break.toml",
        &["fluid.spacing=1e-6"],
        &["dam_break.toml", "fluid.spacing: 1e-6 m", "u32"],
    );
}

#[test]
fn a_run_that_could_never_end_is_refused_naming_the_key() {
    both_refuse(
        "scenes/csm3.toml",
        &["coupling.max_dt=1e-300"],
        &["coupling.max_dt", "1e-300 s", "1.00e301 coupling steps", "1e12"],
    );
    both_refuse(
        "scenes/dam_break.toml",
        &["fluid.kinematic_viscosity=1e40"],
        &[
            "fluid.kinematic_viscosity",
            "1e40 m²/s",
            "8.450e-47 s",
            "fluid steps",
            "1e12",
        ],
    );
    both_refuse(
        "scenes/elastic_gate.toml",
        &["fluid.sound_speed=1e40"],
        &["fluid.sound_speed", "1e40 m/s", "0.25 h/c0"],
    );
    // The broker started by hand (a run over several hosts) refuses it the same way, as bad input.
    let out_dir = scratch("limits-broker");
    let mut broker = std::process::Command::new(program("contact-broker"));
    broker
        .current_dir(root())
        .args(["--run", &run_id("endless"), "--scene", "scenes/csm3.toml"])
        .args(["--set", "coupling.max_dt=1e-300", "--out"])
        .arg(&*out_dir);
    let out = run_bounded(&mut broker, LIMIT);
    let line = refused(&out, "contact-broker", &["coupling.max_dt", "1e12"]);
    assert!(
        line.starts_with("contact-broker: scenes/csm3.toml: coupling.max_dt: "),
        "{line}"
    );
}

/// Outputs no disk holds (the gate's 1 MiB frames every 1e-7 s: 4e6 of them, 4 TiB) are refused by `cosim run`,
/// processes and in-process, and by the broker started by hand, naming the key, before anything is written;
/// `cosim check` says what they need instead (the output folder is `run`'s to choose).
#[test]
fn outputs_no_disk_holds_are_refused_naming_the_key() {
    let sets = ["run.output_interval=1e-7"];
    let said = ["run.output_interval: 1e-7 s writes 4000002 frames of 1.0 MiB", "free"];
    for mode in [None, Some("--in-process")] {
        let mut args = sets.to_vec();
        args.extend(mode);
        let out = cosim("run", "scenes/elastic_gate.toml", &args, LIMIT);
        refused(&out, &format!("run {mode:?}"), &said);
    }
    let out = cosim("check", "scenes/elastic_gate.toml", &sets, LIMIT);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "check: {}", String::from_utf8_lossy(&out.stderr));
    assert!(
        text.contains("  disk: about 3.9 TiB written to the output folder (4000002 frames of 1.0 MiB"),
        "{text}"
    );
    let out_dir = scratch("limits-disk-broker").child("out");
    let mut broker = std::process::Command::new(program("contact-broker"));
    broker
        .current_dir(root())
        .args(["--run", &run_id("disk"), "--scene", "scenes/elastic_gate.toml"])
        .args(["--set", sets[0], "--out"])
        .arg(&*out_dir);
    let out = run_bounded(&mut broker, LIMIT);
    refused(&out, "contact-broker", &said);
    assert!(!out_dir.exists(), "the refused broker made its output folder");
}

#[test]
fn a_scene_path_to_something_endless_is_refused() {
    // `/dev/zero` was read until memory ran out.
    both_refuse("/dev/zero", &[], &["/dev/zero", "(file)", "more than 256 MiB"]);
}

#[test]
fn spacing_too_fine_for_this_machine_is_refused_with_what_it_needs_and_has() {
    // 2e9 fluid particles and 9e8 wall particles: under the id limit, but terabytes.
    let spacing = 3.2e-6;
    let line = cosim(
        "check",
        "scenes/dam_break.toml",
        &[&format!("fluid.spacing={spacing}")],
        LIMIT,
    );
    let line = refused(&line, "check", &["fluid.spacing: 3.2e-6 m", "TiB", "available"]);
    assert!(!line.contains("u32"), "the id limit is not what stops it: {line}");
    both_refuse(
        "scenes/dam_break.toml",
        &[&format!("fluid.spacing={spacing}")],
        &["fluid.spacing", "available"],
    );
}

#[test]
fn mesh_too_big_for_this_machine_is_refused_before_validation_allocates() {
    // 3.6e9 elements and nodes: validation once listed every node to test the fixed box (58 GB).
    let path = write_scene("mesh", PLATE);
    both_refuse(
        path.to_str().unwrap(),
        &["solid[0].divisions=[60000, 60000]"],
        &["solid[0].divisions", "[60000, 60000]", "available"],
    );
}

#[test]
fn mesh_over_u32_ids_is_refused_naming_the_divisions() {
    let path = write_scene("mesh_ids", PLATE);
    both_refuse(
        path.to_str().unwrap(),
        &["solid[0].divisions=[100000, 100000]"],
        &["solid[0].divisions", "[100000, 100000]", "u32"],
    );
}

#[test]
fn check_prints_the_memory_estimate_and_counts_what_the_nodes_make() {
    let out = cosim("check", "scenes/dam_break.toml", &[], LIMIT);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("memory: about"), "{text}");
    let out = cosim("check", "scenes/elastic_gate.toml", &["--json"], LIMIT);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let est = &doc["estimate"];
    // The estimate counts from the scene alone what the nodes build.
    assert_eq!(est["fluid_particles"], doc["particles"], "{doc}");
    assert_eq!(est["fem_nodes"], doc["fem_nodes"], "{doc}");
    assert_eq!(est["fem_elements"], doc["fem_elements"], "{doc}");
    let (walls, built) = (
        est["wall_particles"].as_f64().unwrap(),
        doc["wall_particles"].as_f64().unwrap(),
    );
    // Walls: shared corners of overlapping boxes are counted once by the node, per box by the estimate.
    assert!(walls >= built && walls <= 1.05 * built, "walls {walls} against {built}");
    let bytes = est["memory_bytes"].as_f64().unwrap();
    assert!(bytes > 20e6 && bytes < 1e9, "{bytes}");
}

/// A scene of `n` energy probes (an inline array before the first table, to keep the text short).
fn many_probes(n: usize) -> String {
    let mut text = String::from("version = 1\nprobe = [\n");
    for i in 0..n {
        text.push_str(&format!(
            "{{ name = \"p{i}\", kind = \"energy\", part = \"total\" }},\n"
        ));
    }
    text.push_str("]\n");
    let rest = PLATE.split("[[probe]]").next().unwrap();
    text.push_str(rest.trim_start().strip_prefix("version = 1").unwrap());
    text
}

#[test]
fn a_million_probes_are_checked_in_seconds() {
    // Once a quadratic test of the names: 30,000 probes took 2.7 s, so 1e6 would take most of an hour. Now most of
    // the time is the TOML parser's (about 5 s a million probes here).
    let path = write_scene("probes", &many_probes(1_000_000));
    let listing = path.with_extension("out");
    // stdout (a line a probe) to a file: a pipe nobody reads while the program runs would fill up and stop it.
    let command = format!(
        "'{}' check '{}' > '{}'",
        common::cosim().display(),
        path.display(),
        listing.display()
    );
    let started = Instant::now();
    let out = run_bounded(
        std::process::Command::new("sh").args(["-c", &command]),
        Duration::from_secs(90),
    );
    let took = started.elapsed();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let listed = std::fs::read_to_string(&listing).unwrap();
    assert!(listed.contains("probe p999999: Energy"), "the last probe is listed");
    eprintln!("1e6 probes checked in {took:?}");
}

#[test]
fn non_finite_scene_numbers_are_refused_naming_the_key() {
    let path = write_scene("nan", PLATE);
    let scene = path.to_str().unwrap();
    both_refuse(scene, &["probe[0].point=[nan, 0.005]"], &["probe[0].point", "NaN"]);
    for (set, key, value) in [
        ("solid[0].fixed[0].max=[inf, 0.011]", "solid[0].fixed[0]", "inf"),
        ("probe[0].x_max=nan", "probe[0].x_max", "NaN"),
    ] {
        let out = cosim("check", scene, &[set], LIMIT);
        refused(&out, set, &[key, value]);
    }
}

/// A value of 1e300 reads `1e300` in the refusal, not as its 301 digits (found 2026-12-06: a Young's modulus of
/// −1e300 was refused with a 300-digit number, a run of 1e300 s "needed about" a 283-digit number of EiB).
#[test]
fn extreme_values_are_said_in_scientific_notation() {
    for (set, said) in [
        ("solid[0].material.youngs_modulus=-1e300", "got -1e300"),
        ("fluid.cfl=1e300", "got 1e300"),
        ("run.end_time=1e40", "1.1e26 EiB of memory"),
        ("run.end_time=1e300", "run.end_time: 1e300 s is outside the magnitudes"),
        ("fluid.spacing=1e-300", "fluid.spacing: 1e-300 m makes"),
    ] {
        let out = cosim("check", "scenes/elastic_gate.toml", &[set], LIMIT);
        let line = refused(&out, set, &[said]);
        assert!(line.len() < 400, "{set}: {} characters: {line}", line.len());
    }
}

#[test]
fn overlapping_solids_are_refused_naming_both_and_touching_ones_pass() {
    let second = |min: &str, max: &str| {
        format!(
            "{PLATE}\n[[solid]]\nname = \"b\"\nmin = {min}\nmax = {max}\ndivisions = [2, 2]\nmaterial = {{ model = \
             \"linear_elastic\", density = 1000.0, youngs_modulus = 1.0e6, poisson_ratio = 0.3 }}\n"
        )
    };
    let path = write_scene("overlap", &second("[0.05, 0.005]", "[0.2, 0.05]"));
    both_refuse(path.to_str().unwrap(), &[], &["solid[0]", "solid[1]", "overlap"]);
    // Along an edge: legal.
    let path = write_scene("touch", &second("[0.1, 0.0]", "[0.2, 0.05]"));
    let out = cosim("check", path.to_str().unwrap(), &[], LIMIT);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn scene_with_nothing_to_run_is_refused_by_check_as_by_run() {
    let text = PLATE.split("[[solid]]").next().unwrap();
    let path = write_scene("empty", text);
    both_refuse(path.to_str().unwrap(), &[], &["empty.toml", "solid", "nothing to run"]);
}
