//! Checkpoint and restart (`cosim run --checkpoint-interval T`, `cosim run SCENE --restart DIR/checkpoints/<step>`):
//! a coupled run as three processes that loses a node mid-run continues from its last checkpoint, into the same
//! folder, and ends with outputs byte-identical to the run that was never interrupted — probes.csv, every frame
//! and the ParaView collections. The same checkpoint continued in one process gives the same probes (processes and
//! in-process compute the same bits), and so does an ISPH run, whose solver carries more state between steps. A
//! checkpoint from another scene or another protocol version is refused up front, naming the file and the key.

#[path = "../common/mod.rs"]
mod common;

use cosim_proto::envelope::PROTOCOL_VERSION;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::*;

/// Bound on every wait; no test may hang.
const LIMIT: Duration = Duration::from_secs(240);
/// A shipped scene, by absolute path (the tests run in the crate's folder).
fn scene(name: &str) -> String {
    root().join("scenes").join(name).display().to_string()
}
/// The coarse gate (875 particles) for 0.2 s with a checkpoint every 0.05 s, its coupling step allowed to span the
/// scene's 4 fluid steps (`coupling.fluid_substeps`; 3 of the 4 mm gate's fit under 2.5e-4 s, 1 under the shipped 1e-4):
/// a restart takes the next step from the fluid's stable step the checkpoint saved.
const GATE: [&str; 8] = [
    "--set",
    "fluid.spacing=0.004",
    "--set",
    "run.end_time=0.2",
    "--set",
    "coupling.max_dt=2.5e-4",
    "--checkpoint-interval",
    "0.05",
];

/// The checkpoint folders of a run, by step.
fn checkpoints(out: &Path) -> Vec<(u64, PathBuf)> {
    let mut found: Vec<(u64, PathBuf)> = std::fs::read_dir(out.join("checkpoints"))
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| Some((e.file_name().to_str()?.parse().ok()?, e.path())))
        .collect();
    found.sort();
    found
}

/// Every file of a folder tree (relative path, bytes), checkpoints and logs left out.
fn tree(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let path = e.path();
            let rel = path.strip_prefix(dir).unwrap().display().to_string();
            if ["checkpoints", "logs", "logs.before-restart", "summary.json"]
                .iter()
                .any(|s| rel == *s)
            {
                continue;
            }
            if path.is_dir() {
                stack.push(path);
            } else {
                files.push((rel, std::fs::read(&path).unwrap()));
            }
        }
    }
    files.sort();
    files
}

#[test]
fn a_killed_run_continues_from_its_last_checkpoint_byte_for_byte() {
    let dir = scratch("checkpoint");
    let (reference, crashed, in_process) = (dir.join("reference"), dir.join("crashed"), dir.join("in_process"));
    let s = |p: &Path| p.display().to_string();

    // The run nobody interrupts.
    let gate = scene("elastic_gate.toml");
    let mut args = vec!["run", &gate, "--quiet"];
    args.extend(GATE);
    let reference_s = s(&reference);
    run_ok(&[&args[..], &["--out", &reference_s, "--run-id", &run_id("ck-ref")]].concat());
    let written = checkpoints(&reference);
    assert_eq!(written.len(), 4, "checkpoints at 0.05, 0.1, 0.15, 0.2 s: {written:?}");
    // The broker's log says where each went (its `info` lines are kept without RUST_LOG: bus::log::DEFAULT_FILTER).
    let log = std::fs::read_to_string(reference.join("logs/contact-broker.log")).unwrap();
    for (_, dir) in &written {
        assert!(
            log.contains(&format!("checkpoint {}: ", dir.display())),
            "{} not in the broker's log:\n{log}",
            dir.display()
        );
    }
    let manifest = json(&written[0].1.join("checkpoint.json"));
    assert_eq!(manifest["t"].as_f64(), Some(0.05));
    assert_eq!(manifest["protocol_version"].as_u64(), Some(u64::from(PROTOCOL_VERSION)));
    for file in ["scene.toml", "broker.bin", "fem.bin", "sph.bin"] {
        assert!(
            manifest["files"][file]["bytes"].as_u64().unwrap() > 0,
            "{file} in {manifest}"
        );
    }

    // The same run, its fluid node killed once the first checkpoint is on disk.
    let mut cmd = Command::new(cosim());
    cmd.current_dir(root())
        .env("COSIM_BIN_DIR", bin_dir())
        .args(&args)
        .arg("--out")
        .arg(&crashed)
        .args(["--run-id", &run_id("ck-crash")])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    let mut run = Kill(cmd.spawn().unwrap());
    let started = Instant::now();
    while checkpoints(&crashed).is_empty() {
        assert!(
            run.0.try_wait().unwrap().is_none(),
            "the run ended before its first checkpoint"
        );
        assert!(started.elapsed() < LIMIT, "no checkpoint within {LIMIT:?}");
        std::thread::sleep(Duration::from_millis(20));
    }
    let killed = Command::new("pkill")
        .args(["-KILL", "-P", &run.0.id().to_string(), "sph-node"])
        .status()
        .unwrap();
    assert!(killed.success(), "pkill sph-node");
    let status = wait_exit(
        &mut run.0,
        Instant::now() + LIMIT,
        "cosim after its sph-node was killed",
    );
    assert_eq!(status.code(), Some(1), "the killed run fails");
    let last = checkpoints(&crashed).pop().unwrap();
    assert!(last.0 < written[3].0, "killed before the end: {last:?}");

    // Continued into its own folder: everything it writes equals the uninterrupted run's.
    let (crashed_s, last_s) = (s(&crashed), s(&last.1));
    run_ok(
        &[
            &args[..],
            &[
                "--out",
                &crashed_s,
                "--restart",
                &last_s,
                "--run-id",
                &run_id("ck-restart"),
            ],
        ]
        .concat(),
    );
    let (want, got) = (tree(&reference), tree(&crashed));
    assert_eq!(
        want.iter().map(|f| &f.0).collect::<Vec<_>>(),
        got.iter().map(|f| &f.0).collect::<Vec<_>>(),
        "the same files"
    );
    for ((name, a), (_, b)) in want.iter().zip(&got) {
        assert!(a == b, "{name} differs after the restart");
    }
    let summary = json(&crashed.join("summary.json"));
    assert_eq!(summary["status"], "ok");
    assert_eq!(summary["steps"].as_u64(), Some(written[3].0));
    // The energy balance goes on from the checkpoint's: the same as the uninterrupted run's, to the bit.
    let whole = json(&reference.join("summary.json"));
    assert!(whole["energy_growth"]["budget"].as_f64() > Some(0.0), "{whole}");
    assert_eq!(summary["energy_growth"], whole["energy_growth"]);
    assert_eq!(
        checkpoints(&crashed).len(),
        4,
        "the restarted run goes on writing checkpoints"
    );
    assert!(
        crashed.join("logs.before-restart").join("contact-broker.log").is_file(),
        "the logs of the run that stopped are kept"
    );

    // The same checkpoint continued in one process.
    let in_process_s = s(&in_process);
    let restart = [
        "run",
        &gate,
        "--quiet",
        "--in-process",
        "--set",
        "fluid.spacing=0.004",
        "--set",
        "run.end_time=0.2",
        "--set",
        "coupling.max_dt=2.5e-4",
    ];
    run_ok(&[&restart[..], &["--out", &in_process_s, "--restart", &last_s]].concat());
    let probes = |d: &Path| std::fs::read(d.join("probes.csv")).unwrap();
    assert!(
        probes(&in_process) == probes(&reference),
        "in-process restart: probes.csv differs"
    );
}

#[test]
fn isph_restart_is_byte_identical() {
    gate_restart("checkpoint-isph", "isph", &[]);
}

/// ISPH at its own step (`coupling.max_dt = 1e-2`), where the structure's speed bounds the coupling step (525 steps
/// to 0.1 s, 218 without the bound; `BrokerState::dt_structure`): the bound in force at the checkpoint holds on after
/// the restart.
#[test]
fn isph_restart_with_the_structures_bound_on_the_step_is_byte_identical() {
    gate_restart("checkpoint-isph-own-step", "isph", &["--set", "coupling.max_dt=1e-2"]);
}

/// ISPH with `particle_particle`: the contact impulse still owed to the gate's nodes at the checkpoint
/// (`contact.reaction_relaxation`, `BrokerState::owed`) is saved and given on after the restart.
#[test]
fn isph_particle_particle_restart_is_byte_identical() {
    gate_restart(
        "checkpoint-isph-pp",
        "isph",
        &["--set", "contact.algorithm=particle_particle"],
    );
}

/// WCSPH with `particle_particle`: the bound the contact's stiffness has set on the coupling step
/// (`BrokerState::dt_contact`) holds on after the restart.
#[test]
fn wcsph_particle_particle_restart_is_byte_identical() {
    gate_restart(
        "checkpoint-wcsph-pp",
        "wcsph",
        &["--set", "contact.algorithm=particle_particle"],
    );
}

/// The coarse gate with fluid solver `solver` and `extra` arguments to 0.1 s, whole and continued from its 0.04 s
/// checkpoint: the same probes byte for byte.
fn gate_restart(name: &str, solver: &str, extra: &[&str]) {
    let solver = format!("fluid.solver={solver}");
    let dir = scratch(name);
    let (whole, continued) = (dir.join("whole"), dir.join("continued"));
    let gate = scene("elastic_gate.toml");
    let base = [
        &[
            "run",
            &gate,
            "--quiet",
            "--in-process",
            "--set",
            &solver,
            "--set",
            "fluid.spacing=0.006",
            "--set",
            "run.end_time=0.1",
        ][..],
        extra,
    ]
    .concat();
    let whole_s = whole.display().to_string();
    run_ok(&[&base[..], &["--out", &whole_s, "--checkpoint-interval", "0.04"]].concat());
    // At 0.04 and 0.08 s, and at the end (0.1 s), so that a finished run can be continued.
    let t = |dir: &Path| json(&dir.join("checkpoint.json"))["t"].as_f64().unwrap();
    let times = |out: &Path| checkpoints(out).iter().map(|(_, d)| t(d)).collect::<Vec<_>>();
    assert_eq!(times(&whole), [0.04, 0.08, 0.1]);
    let first = checkpoints(&whole).remove(0).1.display().to_string();
    let continued_s = continued.display().to_string();
    // Continued with another interval: the next checkpoints follow it from the restart's time on.
    run_ok(
        &[
            &base[..],
            &[
                "--out",
                &continued_s,
                "--restart",
                &first,
                "--checkpoint-interval",
                "0.03",
            ],
        ]
        .concat(),
    );
    assert_eq!(times(&continued), [0.06, 0.09, 0.1]);
    let probes = |d: &Path| std::fs::read(d.join("probes.csv")).unwrap();
    assert!(probes(&whole).len() > 200, "samples written");
    assert!(
        probes(&whole) == probes(&continued),
        "{solver} restart: probes.csv differs"
    );
}

/// `run.frame_interval`: frames at every third output time of the coarse gate (0.015 s; probes every 0.005 s) and at
/// the last one, named by their output time's number, listed in the `.pvd`s; a restart from the 0.04 s checkpoint (not
/// on a frame time) into a fresh folder writes the frames from there on, probes.csv and the plots byte for byte.
#[test]
fn frames_at_their_own_interval_and_across_a_restart() {
    let dir = scratch("checkpoint-frames");
    let (whole, continued) = (dir.join("whole"), dir.join("continued"));
    let gate = scene("elastic_gate.toml");
    let base = [
        "run",
        &gate,
        "--quiet",
        "--in-process",
        "--set",
        "fluid.spacing=0.006",
        "--set",
        "run.end_time=0.1",
        "--set",
        "run.frame_interval=0.015",
    ];
    let whole_s = whole.display().to_string();
    run_ok(&[&base[..], &["--out", &whole_s, "--checkpoint-interval", "0.04"]].concat());
    let summary = json(&whole.join("summary.json"));
    // 21 output times, k = 0 … 20: frames at k = 0, 3, …, 18 and at the last, 20.
    assert_eq!(summary["samples"].as_u64(), Some(21));
    assert_eq!(summary["frames"].as_u64(), Some(8));
    let names = |d: &Path, prefix: &str| -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d.join("frames"))
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with(prefix) && n.ends_with(".vtu"))
            .collect();
        v.sort();
        v
    };
    let want: Vec<String> = [0, 3, 6, 9, 12, 15, 18, 20]
        .iter()
        .map(|k| format!("particles_{k:05}.vtu"))
        .collect();
    assert_eq!(names(&whole, "particles_"), want);
    assert_eq!(names(&whole, "structure_").len(), 8);
    let pvd = std::fs::read_to_string(whole.join("frames/particles.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 8);
    assert!(
        pvd.contains("particles_00020.vtu") && !pvd.contains("particles_00001.vtu"),
        "{pvd}"
    );
    let rows = std::fs::read_to_string(whole.join("probes.csv"))
        .unwrap()
        .lines()
        .count();
    assert_eq!(rows, 22, "a header and 21 probe rows");

    let first = checkpoints(&whole).remove(0).1;
    assert_eq!(json(&first.join("checkpoint.json"))["t"].as_f64(), Some(0.04));
    let (first_s, continued_s) = (first.display().to_string(), continued.display().to_string());
    run_ok(&[&base[..], &["--out", &continued_s, "--restart", &first_s]].concat());
    // A fresh folder: the frames from the checkpoint's time on (k = 8 was sampled before it), each the same bytes;
    // probes.csv and the plots whole (the checkpoint carries the rows before).
    assert_eq!(names(&continued, "particles_"), &want[3..]);
    let a = tree(&whole);
    let b = tree(&continued);
    assert!(b.iter().any(|f| f.0 == "probes.csv"));
    for (name, y) in &b {
        if name.ends_with(".pvd") {
            continue;
        }
        let x = a.iter().find(|f| &f.0 == name).map(|f| &f.1);
        assert!(x == Some(y), "{name} differs after the restart");
    }
}

mod refused;
