//! A checkpoint is a trust boundary (issue 17): a restart reads back files that anything may have changed since they
//! were written. `checkpoint.json` holds the size and CRC-32 of every other file of the folder, and a restart checks
//! them before it starts anything: a file whose bytes changed, its size kept, is refused with exit code 2 and one
//! line that names the file and says the checksum expected and found (before, such a restart exited 0 with probes
//! that differ from the uninterrupted run's). A manifest of the format before checksums is refused as such, and so is
//! a manifest that leaves a file out. The same checkpoint, untouched, restarts as a run that ends `ok`.
//!
//! What the files hold once their checksums match (a state another tool wrote, consistent checksum and all) is
//! checked by the nodes and the broker themselves: `fem-node/tests/restore.rs`, `sph-node/tests/restore.rs`, the
//! solvers' `restore` unit tests and `contact-broker/src/checkpoint/broker_state.rs`.

mod common;

use contact_broker::checkpoint::FORMAT;

use std::path::{Path, PathBuf};
use std::time::Duration;

use common::*;
use contact_broker::checkpoint::BrokerState;
use cosim_proto::messages::Correction;
use sph_node::core::SphCheckpoint;

/// Bound on every run; no test may hang.
const LIMIT: Duration = Duration::from_secs(120);

/// The coarse elastic gate (a structure, a fluid and the contact) for 0.02 s, as settings after the scene path.
const GATE: [&str; 4] = ["--set", "fluid.spacing=0.006", "--set", "run.end_time=0.02"];

fn gate() -> String {
    root().join("scenes").join("elastic_gate.toml").display().to_string()
}

/// A checkpointed in-process run of the coarse gate (checkpoints at 0.01 and 0.02 s); its first checkpoint.
fn first_checkpoint(dir: &Path) -> PathBuf {
    let out = dir.join("run").display().to_string();
    let g = gate();
    let mut args = vec!["run", &g, "--quiet", "--in-process", "--out", &out];
    args.extend(GATE);
    args.extend(["--checkpoint-interval", "0.01"]);
    let got = cosim_run(&args, LIMIT);
    assert!(got.status.success(), "{}", String::from_utf8_lossy(&got.stderr));
    let root = dir.join("run").join("checkpoints");
    let mut steps: Vec<u64> = std::fs::read_dir(&root)
        .unwrap()
        .flatten()
        .filter_map(|e| e.file_name().to_str()?.parse().ok())
        .collect();
    steps.sort();
    root.join(steps[0].to_string())
}

/// A copy of the checkpoint folder `ck` at `to`; returns `to`.
fn copy_of(ck: &Path, to: &Path) -> PathBuf {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(ck).unwrap().flatten() {
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
    to.to_path_buf()
}

/// `cosim run` of the gate restarted from `ck` into `out`, in processes (`--in-process` when `in_process`).
fn restart(ck: &Path, out: &Path, in_process: bool) -> std::process::Output {
    let (g, ck, out) = (gate(), ck.display().to_string(), out.display().to_string());
    let id = run_id("integrity");
    let mut args = vec!["run", &g, "--quiet", "--out", &out, "--restart", &ck, "--run-id", &id];
    args.extend(GATE);
    if in_process {
        args.push("--in-process");
    }
    cosim_run(&args, LIMIT)
}

/// The restart from `ck` is refused before anything starts: exit 2, one line holding each of `expect`, nothing
/// written to its output folder.
fn assert_refused(ck: &Path, out: &Path, expect: &[&str]) {
    let got = restart(ck, out, false);
    let stderr = String::from_utf8_lossy(&got.stderr);
    assert_eq!(got.status.code(), Some(2), "bad input: {stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "one line: {stderr}");
    for e in expect {
        assert!(stderr.contains(e), "`{e}` in: {stderr}");
    }
    assert!(!out.join("probes.csv").exists(), "nothing ran: {}", out.display());
    assert!(!out.join("summary.json").exists(), "nothing ran: {}", out.display());
}

/// The CRC-32 the manifest of `ck` records for `file`.
fn recorded_crc(ck: &Path, file: &str) -> String {
    json(&ck.join("checkpoint.json"))["files"][file]["crc32"]
        .as_str()
        .unwrap_or_else(|| panic!("no crc32 for {file}"))
        .to_string()
}

#[test]
fn a_file_changed_in_place_is_refused_naming_it_and_its_checksums() {
    let dir = scratch("ck-integrity");
    let ck = first_checkpoint(&dir);
    let manifest = json(&ck.join("checkpoint.json"));
    assert_eq!(manifest["format"].as_u64(), Some(u64::from(FORMAT)), "{manifest}");

    // Untouched, the checkpoint restarts (the copies below differ from it only by the bytes flipped).
    let intact = copy_of(&ck, &dir.join("intact"));
    let got = restart(&intact, &dir.join("intact-out"), true);
    assert!(got.status.success(), "{}", String::from_utf8_lossy(&got.stderr));
    assert_eq!(json(&dir.join("intact-out").join("summary.json"))["status"], "ok");

    for file in ["sph.bin", "fem.bin", "broker.bin", "scene.toml"] {
        let damaged = copy_of(&ck, &dir.join(format!("flipped-{file}")));
        let path = damaged.join(file);
        let mut bytes = std::fs::read(&path).unwrap();
        let size = bytes.len();
        // Two bytes in the middle, each to another value.
        let mid = size / 2;
        for b in &mut bytes[mid..mid + 2] {
            *b ^= 0x5a;
        }
        std::fs::write(&path, &bytes).unwrap();
        assert_eq!(std::fs::metadata(&path).unwrap().len() as usize, size, "size kept");
        let found = format!("{:08x}", crc32fast::hash(&bytes));
        let expected = recorded_crc(&ck, file);
        assert_ne!(found, expected);
        assert_refused(
            &damaged,
            &dir.join(format!("out-{file}")),
            &[
                &path.display().to_string(),
                &format!("crc32 {found}"),
                &format!("expects {expected}"),
                "damaged",
            ],
        );
    }
}

#[test]
fn an_old_format_or_incomplete_manifest_is_refused() {
    let dir = scratch("ck-integrity-manifest");
    let ck = first_checkpoint(&dir);
    let text = std::fs::read_to_string(ck.join("checkpoint.json")).unwrap();
    let mut manifest: serde_json::Value = serde_json::from_str(&text).unwrap();

    // Format 1, as the builds before checksums wrote it: each file's size alone.
    let old = copy_of(&ck, &dir.join("format1"));
    let mut m = manifest.clone();
    m["format"] = 1.into();
    for (_, entry) in m["files"].as_object_mut().unwrap() {
        *entry = entry["bytes"].clone();
    }
    std::fs::write(old.join("checkpoint.json"), m.to_string()).unwrap();
    assert_refused(
        &old,
        &dir.join("out-format1"),
        &[
            "checkpoint.json",
            "checkpoint format 1",
            &format!("reads format {FORMAT}"),
            "no checksums",
        ],
    );

    // A manifest that leaves sph.bin out: its bytes would be read unchecked.
    let partial = copy_of(&ck, &dir.join("partial"));
    manifest["files"].as_object_mut().unwrap().remove("sph.bin");
    std::fs::write(partial.join("checkpoint.json"), manifest.to_string()).unwrap();
    assert_refused(
        &partial,
        &dir.join("out-partial"),
        &["checkpoint.json", "does not list sph.bin"],
    );
}

/// `file` of the checkpoint `ck` replaced by `bytes`, its size and checksum recorded in the manifest as a tool
/// that writes checkpoints would record them.
fn rewrite(ck: &Path, file: &str, bytes: &[u8]) {
    std::fs::write(ck.join(file), bytes).unwrap();
    let path = ck.join("checkpoint.json");
    let mut manifest = json(&path);
    manifest["files"][file] = serde_json::json!({
        "bytes": bytes.len(),
        "crc32": format!("{:08x}", crc32fast::hash(bytes)),
    });
    std::fs::write(&path, manifest.to_string()).unwrap();
}

#[test]
fn a_state_whose_checksum_matches_but_does_not_hold_together_is_refused_naming_the_field() {
    let dir = scratch("ck-integrity-state");
    let ck = first_checkpoint(&dir);

    // broker.bin naming a fluid particle the run does not have: refused before anything starts.
    let bad = copy_of(&ck, &dir.join("broker-id"));
    type SavedBroker = (String, u32, BrokerState);
    let (tag, format, mut state): SavedBroker =
        bincode::deserialize(&std::fs::read(ck.join("broker.bin")).unwrap()).unwrap();
    let particles = state.summary.particles;
    let k = state.pending_sph.len();
    state.pending_sph.push(Correction {
        id: particles as u32 + 5,
        dx: [0.0; 2],
        dv: [0.0; 2],
        face: None,
    });
    rewrite(&bad, "broker.bin", &bincode::serialize(&(tag, format, state)).unwrap());
    assert_refused(
        &bad,
        &dir.join("out-broker-id"),
        &[
            "broker.bin",
            &format!(
                "pending_sph[{k}].id = {}, but there are {particles} fluid particles",
                particles + 5
            ),
        ],
    );

    // broker.bin with a fluid step no run takes (1e-300 s, under coupling.max_dt / 2^32): it was accepted, and the
    // run took one tiny extra step (found 2026-12-06 by the sweep of crafted checkpoints, D25).
    let bad = copy_of(&ck, &dir.join("broker-dt"));
    let (tag, format, mut state): SavedBroker =
        bincode::deserialize(&std::fs::read(ck.join("broker.bin")).unwrap()).unwrap();
    state.dt_fluid = 1e-300;
    rewrite(&bad, "broker.bin", &bincode::serialize(&(tag, format, state)).unwrap());
    assert_refused(
        &bad,
        &dir.join("out-broker-dt"),
        &["broker.bin: dt_fluid = 1e-300 s is below coupling.max_dt / 2^32 = "],
    );

    // sph.bin with one velocity more than there are particles: the fluid node refuses it when it starts, reports it
    // on its error topic, and the run fails with that reason (exit 1, summary.json `failed`), naming the file (it
    // said "checkpoint: …", found 2026-12-06 by the sweep of crafted checkpoints, D23).
    let bad = copy_of(&ck, &dir.join("sph-length"));
    type SavedFluid = (String, u32, SphCheckpoint);
    let (tag, version, mut fluid): SavedFluid =
        bincode::deserialize(&std::fs::read(ck.join("sph.bin")).unwrap()).unwrap();
    let n = fluid.solver.state.len();
    fluid.solver.state.v.push([0.0; 2]);
    rewrite(&bad, "sph.bin", &bincode::serialize(&(tag, version, &fluid)).unwrap());
    let why = format!(
        "cannot restart from the checkpoint: sph.bin: state.v holds {} entries, there are {n} fluid particles",
        n + 1
    );
    let out = dir.join("out-sph-length");
    let got = restart(&bad, &out, false);
    let stderr = String::from_utf8_lossy(&got.stderr);
    assert_eq!(got.status.code(), Some(1), "the run fails: {stderr}");
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["status"], "failed", "{summary}");
    let message = summary["message"].as_str().unwrap();
    assert!(message.contains("sph-node") && message.contains(&why), "{message}");
    // In one process the same refusal, from the same check.
    let got = restart(&bad, &dir.join("out-sph-length-in-process"), true);
    let stderr = String::from_utf8_lossy(&got.stderr);
    assert_eq!(got.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("sph-node") && stderr.contains(&why), "{stderr}");

    // fem.bin cut short (its checksum rewritten): the structure node names the file too.
    let bad = copy_of(&ck, &dir.join("fem-cut"));
    let fem = std::fs::read(ck.join("fem.bin")).unwrap();
    rewrite(&bad, "fem.bin", &fem[..fem.len() - 9]);
    let out = dir.join("out-fem-cut");
    let got = restart(&bad, &out, false);
    let stderr = String::from_utf8_lossy(&got.stderr);
    assert_eq!(got.status.code(), Some(1), "the run fails: {stderr}");
    let message = json(&out.join("summary.json"))["message"].as_str().unwrap().to_string();
    assert!(
        message.contains("fem-node")
            && message.contains("cannot restart from the checkpoint: fem.bin: not a structure node's state: "),
        "{message}"
    );
}

/// A `broker.bin` and manifest whose time was moved (0.01 → 0.0149 s), the checksum rewritten: the nodes' states are
/// at 0.01 s.
/// Found 2026-12-06 by a sweep of crafted checkpoints: the run continued from the wrong time and ended `ok`, "reached
/// t = 0.02 s", having simulated 0.0049 s less. Now each node compares the time its restored state is at with the
/// checkpoint's, as processes and in one process, and the run fails naming both.
#[test]
fn a_checkpoint_whose_times_disagree_is_refused() {
    let dir = scratch("ck-integrity-time");
    let ck = first_checkpoint(&dir);
    let bad = copy_of(&ck, &dir.join("broker-time"));
    type SavedBroker = (String, u32, BrokerState);
    let (tag, format, mut state): SavedBroker =
        bincode::deserialize(&std::fs::read(ck.join("broker.bin")).unwrap()).unwrap();
    assert!(
        (state.t - 0.01).abs() < 1e-12,
        "the first checkpoint at t = {}",
        state.t
    );
    state.t = 0.0149;
    state.summary.sim_time = 0.0149;
    rewrite(&bad, "broker.bin", &bincode::serialize(&(tag, format, state)).unwrap());
    // The manifest with it (it and broker.bin must agree).
    let path = bad.join("checkpoint.json");
    let mut manifest = json(&path);
    manifest["t"] = serde_json::json!(0.0149);
    std::fs::write(&path, manifest.to_string()).unwrap();
    for in_process in [false, true] {
        let out = dir.join(format!("out-{in_process}"));
        let got = restart(&bad, &out, in_process);
        let stderr = String::from_utf8_lossy(&got.stderr);
        assert_ne!(got.status.code(), Some(0), "in process {in_process}: {stderr}");
        let said = match in_process {
            true => stderr.to_string(),
            false => json(&out.join("summary.json"))["message"]
                .as_str()
                .unwrap_or_default()
                .to_string(),
        };
        assert!(
            said.contains(
                "cannot restart from the checkpoint: its state is at t = 0.01 s, the checkpoint at t = 0.0149 s"
            ),
            "in process {in_process}: {said} / {stderr}"
        );
    }
}

/// A checkpoint file that is not a regular file is refused before a byte of it is read (found 2026-12-06 by a sweep
/// of crafted checkpoints): `sph.bin` linked to /dev/zero was read until 10.9 GB were taken in 8 s, and a FIFO held
/// the restart for ever before anything started.
#[test]
fn a_checkpoint_file_that_is_not_a_file_is_refused_unread() {
    let dir = scratch("ck-integrity-special");
    let ck = first_checkpoint(&dir);
    let zero = copy_of(&ck, &dir.join("zero"));
    std::fs::remove_file(zero.join("sph.bin")).unwrap();
    std::os::unix::fs::symlink("/dev/zero", zero.join("sph.bin")).unwrap();
    assert_refused(
        &zero,
        &dir.join("out-zero"),
        &["sph.bin: not a regular file (a character device)"],
    );
    let fifo = copy_of(&ck, &dir.join("fifo"));
    std::fs::remove_file(fifo.join("sph.bin")).unwrap();
    let made = std::process::Command::new("mkfifo")
        .arg(fifo.join("sph.bin"))
        .status()
        .unwrap();
    assert!(made.success());
    assert_refused(&fifo, &dir.join("out-fifo"), &["sph.bin: not a regular file (a FIFO)"]);
}
