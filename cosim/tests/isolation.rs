//! Two runs at once through one zenoh network never see each other's messages (`docs/PROTOCOL.md` §2: every key is
//! under `cosim/<run>/`). A zenoh router on loopback, started as its own process (`cosim router`, the router `zenohd`
//! runs), is the hub, as `zenohd` would be on a shared machine; two different coupled runs (the coarse gate with the
//! particle–element contact, and with the particle–particle contact, so that their messages differ) run side by side
//! as processes with `--connect` to it. Each must give the probes its own in-process run gives, byte for byte: one
//! foreign message taken in would change them or fail the run.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::*;

const LIMIT: Duration = Duration::from_secs(300);
const SCENE: &str = "scenes/elastic_gate.toml";

/// `cosim run SCENE` with the variant's settings; not waited for.
fn start(out: &Path, id: &str, contact: &str, extra: &[&str]) -> Kill {
    let mut cmd = Command::new(cosim());
    cmd.current_dir(root())
        .env("COSIM_BIN_DIR", bin_dir())
        .args(["run", SCENE, "--quiet", "--out"])
        .arg(out)
        .args(["--run-id", id])
        .args(["--set", "fluid.spacing=0.004", "--set", "run.end_time=0.05"])
        .args(["--set", &format!("contact.algorithm={contact}")])
        .args(extra)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(out.with_extension("stderr")).unwrap());
    Kill(cmd.spawn().unwrap())
}

fn finish(run: &mut Kill, out: &Path) {
    let status = wait_exit(&mut run.0, Instant::now() + LIMIT, &out.display().to_string());
    let stderr = std::fs::read_to_string(out.with_extension("stderr")).unwrap_or_default();
    assert!(status.success(), "{}: {stderr}", out.display());
}

fn probes(out: &Path) -> Vec<u8> {
    let bytes = std::fs::read(out.join("probes.csv")).unwrap();
    assert!(bytes.len() > 100, "{}: no samples", out.display());
    bytes
}

#[test]
fn two_runs_through_one_router_keep_to_themselves() {
    let dir = scratch("isolation");
    let hub_endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let (hub, endpoints) = start_router(&hub_endpoint, None, &dir.join("router.stderr"));
    assert_eq!(endpoints, std::slice::from_ref(&hub_endpoint));

    let out: Vec<PathBuf> = ["pe_hub", "pp_hub", "pe_alone", "pp_alone"]
        .iter()
        .map(|n| dir.join(n))
        .collect();
    let ids = [run_id("iso-pe"), run_id("iso-pp")];
    let mut pe = start(&out[0], &ids[0], "particle_element", &["--connect", &hub_endpoint]);
    let mut pp = start(&out[1], &ids[1], "particle_particle", &["--connect", &hub_endpoint]);
    finish(&mut pe, &out[0]);
    finish(&mut pp, &out[1]);
    drop(hub);
    // References: each run alone, in one process.
    let mut pe_alone = start(&out[2], &run_id("iso-pe-alone"), "particle_element", &["--in-process"]);
    finish(&mut pe_alone, &out[2]);
    let mut pp_alone = start(&out[3], &run_id("iso-pp-alone"), "particle_particle", &["--in-process"]);
    finish(&mut pp_alone, &out[3]);

    for (shared, alone) in [(&out[0], &out[2]), (&out[1], &out[3])] {
        let s = json(&shared.join("summary.json"));
        assert_eq!(s["status"], "ok");
        assert_eq!(s["mode"], "processes");
        assert!(
            probes(shared) == probes(alone),
            "{} differs from its run alone",
            shared.display()
        );
    }
    // The two runs really differ, so a swapped message could not go unnoticed.
    assert!(probes(&out[0]) != probes(&out[1]));
}
