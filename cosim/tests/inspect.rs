//! Live inspection (`DESIGN.md` §5): while a coupled run goes on as three processes, `cosim inspect ID --once`
//! from another process prints one JSON document with the status of the broker and both nodes (found through
//! the local run registry, or with `--connect` to the run's endpoint as from another host); the refreshing table
//! follows the run and ends when the run does; a run that is not going is refused; without an id, the runs going on
//! this machine are listed.

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

use common::*;

/// Bound on each wait (the 0.25 s run takes 10–40 s alone; on a loaded machine the table has taken over 120 s to end,
/// and with a 0.15 s run, which can end before the table starts, over 240 s: see the closing note of 2026-11-27).
const LIMIT: Duration = Duration::from_secs(240);

/// The coarse gate as processes, not waited for.
fn start(out: &Path, id: &str, end_time: &str) -> Kill {
    Kill(
        Command::new(cosim())
            .current_dir(root())
            .env("COSIM_BIN_DIR", bin_dir())
            .args(["run", "scenes/elastic_gate.toml", "--quiet", "--run-id", id, "--out"])
            .arg(out)
            .args([
                "--set",
                "fluid.spacing=0.004",
                "--set",
                &format!("run.end_time={end_time}"),
            ])
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    )
}

fn inspect(args: &[&str]) -> (i32, serde_json::Value, String) {
    let mut all = vec!["inspect"];
    all.extend_from_slice(args);
    let out = cosim_run(&all, Duration::from_secs(30));
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let doc = serde_json::from_str(&stdout).unwrap_or(serde_json::Value::Null);
    (
        out.status.code().unwrap_or(-1),
        doc,
        String::from_utf8_lossy(&out.stderr).into_owned() + &stdout,
    )
}

fn check_document(doc: &serde_json::Value, id: &str) {
    assert_eq!(doc["run"], id);
    let nodes = doc["nodes"].as_object().unwrap_or_else(|| panic!("{doc:#}"));
    assert_eq!(nodes.len(), 3, "broker and both nodes answer: {doc:#}");
    for name in ["contact-broker", "fem-node", "sph-node"] {
        let s = &nodes[name];
        assert_eq!(s["health"], "running", "{name}: {s}");
        assert_eq!(s["run"], id);
        assert!(s["step"].as_u64().unwrap() > 0, "{name}: {s}");
        assert!(s["t"].as_f64().unwrap() > 0.0, "{name}: {s}");
        assert!(s["dt"].as_f64().unwrap() > 0.0, "{name}: {s}");
        assert!(s["wall_seconds"].as_f64().unwrap() > 0.0, "{name}: {s}");
        assert!(s["pid"].as_u64().unwrap() > 0, "{name}: {s}");
    }
    // Sizes as the scene makes them: 875 particles at 4 mm, the gate's 5 × 79 quad4 mesh.
    assert_eq!(nodes["sph-node"]["counts"]["particles"], 875);
    assert_eq!(nodes["fem-node"]["counts"]["nodes"], 480);
    assert_eq!(nodes["fem-node"]["counts"]["elements"], 395);
    assert_eq!(nodes["contact-broker"]["counts"]["particles"], 875);
    // The nodes split their wall time into compute and waiting, and report their energies.
    for name in ["fem-node", "sph-node"] {
        assert!(nodes[name]["compute_per_step"].as_f64().unwrap() > 0.0);
        assert!(nodes[name]["waiting_per_step"].as_f64().unwrap() >= 0.0);
        let energy = &nodes[name]["extra"]["energy"];
        assert!(energy["kinetic"].as_f64().unwrap() >= 0.0, "{name}: {energy}");
        assert!(energy["potential"].as_f64().unwrap().is_finite(), "{name}: {energy}");
    }
    // The water column stands on the floor: its potential energy, Σ m g y, is positive; the gate is strained.
    assert!(nodes["sph-node"]["extra"]["energy"]["potential"].as_f64().unwrap() > 0.0);
    assert!(nodes["fem-node"]["extra"]["energy"]["strain"].as_f64().unwrap() >= 0.0);
    // The broker: the last pass's contacts, the deepest penetration so far, the particles exchanged.
    let extra = &nodes["contact-broker"]["extra"];
    assert!(extra["contacts"].as_u64().is_some(), "{extra}");
    assert!(extra["max_penetration"].as_f64().unwrap() >= 0.0, "{extra}");
    assert!(extra["exchanged"].as_u64().unwrap() > 0, "{extra}");
}

#[test]
fn inspect_a_running_coupled_run() {
    let dir = scratch("inspect");
    let out = dir.join("out");
    let id = run_id("inspect");
    let mut run = start(&out, &id, "10");
    wait_for_samples(&mut run.0, &out, 3, LIMIT);
    // Found on this machine by its id.
    let (code, doc, text) = inspect(&[&id, "--once"]);
    assert_eq!(code, 0, "{text}");
    check_document(&doc, &id);
    // As from another host: given the endpoint.
    let entry = json(&std::env::temp_dir().join("cosim-runs").join(format!("{id}.json")));
    let endpoint = entry["connect"].as_str().unwrap().to_string();
    let (code, doc, text) = inspect(&[&id, "--once", "--connect", &endpoint]);
    assert_eq!(code, 0, "{text}");
    check_document(&doc, &id);
    // Without an id: the runs on this machine (other tests' runs may be among them), this one with its endpoint,
    // folder and the pid of its `cosim run`.
    let (code, list, text) = inspect(&["--once"]);
    assert_eq!(code, 0, "{text}");
    let mine: Vec<&serde_json::Value> = list
        .as_array()
        .unwrap_or_else(|| panic!("{text}"))
        .iter()
        .filter(|e| e["run"] == id.as_str())
        .collect();
    assert_eq!(mine.len(), 1, "{text}");
    assert_eq!(mine[0]["connect"], endpoint.as_str());
    assert_eq!(mine[0]["out"], out.display().to_string());
    assert_eq!(mine[0]["pid"].as_u64(), Some(u64::from(run.0.id())));
    assert_eq!(mine[0]["scene"], "elastic_gate");
    assert!(mine[0]["since"].as_u64().is_some_and(|t| t > 1_700_000_000), "{text}");
    let (code, _, text) = inspect(&[]);
    assert_eq!(code, 0, "{text}");
    assert!(text.lines().any(|l| l.starts_with(&format!("{id} "))), "{text}");
    // A mistyped id is refused, saying what runs here.
    let (code, _, text) = inspect(&[&format!("{id}x"), "--once"]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("running here: "), "{text}");
    drop(run);
    // Gone: refused, naming the run.
    let (code, _, text) = inspect(&["no-such-run", "--once"]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("no-such-run"), "{text}");
}

#[test]
fn the_table_follows_a_run_to_its_end() {
    let dir = scratch("inspect-live");
    let out = dir.join("out");
    let id = run_id("inspect-live");
    let mut run = start(&out, &id, "0.25");
    wait_for_samples(&mut run.0, &out, 2, LIMIT);
    let table = cosim_run(&["inspect", &id, "--interval", "0.2"], LIMIT);
    let text = String::from_utf8_lossy(&table.stdout);
    assert!(
        table.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&table.stderr)
    );
    for name in ["contact-broker", "fem-node", "sph-node"] {
        assert!(text.contains(name), "{name} not in the table: {text}");
    }
    // It stopped because the run did: the run is over by now.
    let status = run.0.wait().unwrap();
    assert!(status.success());
}
