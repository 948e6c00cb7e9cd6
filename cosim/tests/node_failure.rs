//! Clean failure (`DESIGN.md` §3, `docs/PROTOCOL.md` §8): a coupled run as three processes loses one of them
//! mid-run — `fem-node`, `sph-node` or `contact-broker` killed with SIGKILL, or `sph-node` frozen with SIGSTOP so
//! that it stops answering. Each time `cosim run` must exit 1 within seconds with one line on stderr naming the
//! process and what happened, `summary.json` must say `failed`, the probe samples and frames written before must
//! still be there, and no process of the run may be left behind. And `cosim run` itself interrupted (Ctrl-C) or
//! killed with SIGKILL: the run stops between two steps and says why in summary.json, and its processes go with it.

mod common;

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::*;

/// Bound on every wait; no test may hang.
const LIMIT: Duration = Duration::from_secs(120);
/// The coarse gate (875 particles), long enough never to finish before the failure.
const SCENE: &str = "scenes/elastic_gate.toml";
const SETS: [&str; 4] = [
    "fluid.spacing=0.004",
    "run.end_time=10",
    // A frozen node is declared dead after this long without an answer.
    "coupling.step_timeout=2",
    "run.output_interval=0.005",
];

/// A run of the scene as processes, under way: its `cosim run`, output folder, stderr file and the three children.
struct Started {
    run: Kill,
    out: std::path::PathBuf,
    stderr_path: std::path::PathBuf,
    kids: Vec<(u32, String)>,
    /// Holds the folder of `out` and `stderr_path` until the test ends.
    _dir: Scratch,
}

/// Starts the scene and waits until its three processes run and a few probe samples are written.
fn start(name: &str) -> Started {
    start_with(name, false)
}

/// [`start`], or in one process (`--in-process`: no children; it waits for the samples only).
fn start_with(name: &str, in_process: bool) -> Started {
    start_run(name, SCENE, &SETS, in_process, if in_process { 0 } else { 3 }, 3)
}

/// Starts `scene` with `sets` and waits until `processes` children run and `at_least` probe samples are written.
fn start_run(name: &str, scene: &str, sets: &[&str], in_process: bool, processes: usize, at_least: usize) -> Started {
    let dir = scratch(&format!("failure-{name}"));
    let out = dir.join("out");
    let stderr_path = dir.join("stderr.txt");
    let mut cmd = Command::new(cosim());
    cmd.current_dir(root())
        .env("COSIM_BIN_DIR", bin_dir())
        .args(["run", scene, "--quiet", "--out"])
        .arg(&out)
        .args(["--run-id", &run_id(name)]);
    for s in sets {
        cmd.args(["--set", s]);
    }
    if in_process {
        cmd.arg("--in-process");
    }
    let mut run = Kill(
        cmd.stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(&stderr_path).unwrap())
            .spawn()
            .unwrap(),
    );
    let started = Instant::now();
    let kids = loop {
        let kids = children(run.0.id());
        if kids.len() == processes && samples(&out) >= at_least {
            break kids;
        }
        assert!(run.0.try_wait().unwrap().is_none(), "the run ended early");
        assert!(started.elapsed() < LIMIT, "the run did not get going: {kids:?}");
        std::thread::sleep(Duration::from_millis(50));
    };
    Started {
        run,
        out,
        stderr_path,
        kids,
        _dir: dir,
    }
}

/// Waits (at most 10 s) for every process in `kids` to be gone, kills what is left, and fails the test if any was.
fn assert_all_gone(kids: &[(u32, String)]) {
    // Nothing is left running (a stopped process counts).
    let until = Instant::now() + Duration::from_secs(10);
    while kids.iter().any(|(p, _)| alive(*p)) && Instant::now() < until {
        std::thread::sleep(Duration::from_millis(50));
    }
    let left: Vec<_> = kids.iter().filter(|(p, _)| alive(*p)).collect();
    for (p, _) in &left {
        let _ = Command::new("kill").args(["-9", &p.to_string()]).status();
    }
    assert!(left.is_empty(), "left running: {left:?}");
}

/// Sends `signal` to process `pid`, waits for `cosim run` to exit, and asserts exit 1 with one line on stderr that
/// says each of `words`; returns the time it took and the line.
fn signal_and_expect(
    run: &mut Kill,
    pid: u32,
    signal: &str,
    stderr_path: &std::path::Path,
    words: &[&str],
) -> (Duration, String) {
    signal_n_and_expect(run, pid, signal, 1, stderr_path, words)
}

/// [`signal_and_expect`] with `signal` sent `times` times back to back (one `kill` call, microseconds apart: as
/// `timeout` sends SIGTERM to a process and again to its group).
fn signal_n_and_expect(
    run: &mut Kill,
    pid: u32,
    signal: &str,
    times: usize,
    stderr_path: &std::path::Path,
    words: &[&str],
) -> (Duration, String) {
    let hit = Instant::now();
    let pids = vec![pid.to_string(); times];
    let sent = Command::new("kill").arg(signal).args(&pids).status().unwrap();
    assert!(sent.success());
    let status = wait_exit(&mut run.0, hit + LIMIT, &format!("cosim after {signal} to {pid}"));
    let took = hit.elapsed();
    let stderr = std::fs::read_to_string(stderr_path).unwrap();
    eprintln!("cosim exited {took:.2?} after {signal} to {pid}: {}", stderr.trim());
    assert_eq!(status.code(), Some(1), "{stderr}");
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "one line on stderr: {stderr}");
    for word in words {
        assert!(lines[0].contains(word), "{word:?} not in {stderr}");
    }
    (took, lines[0].to_string())
}

/// SIGINT to `cosim run`: it exits within 30 s, saying `words` and the signal, and its summary says `failed`,
/// "interrupted"; the summary.
fn interrupt_and_expect(
    run: &mut Kill,
    stderr_path: &std::path::Path,
    out: &std::path::Path,
    words: &[&str],
) -> serde_json::Value {
    interrupt_n_and_expect(run, 1, stderr_path, out, words)
}

/// [`interrupt_and_expect`] with SIGINT sent `times` times back to back: signals that close are one request to
/// stop, not a second one that ends the process at once (before: exit 130, no summary, found 2026-12-06).
fn interrupt_n_and_expect(
    run: &mut Kill,
    times: usize,
    stderr_path: &std::path::Path,
    out: &std::path::Path,
    words: &[&str],
) -> serde_json::Value {
    let pid = run.0.id();
    let words: Vec<&str> = words
        .iter()
        .copied()
        .chain(["interrupted (SIGINT or SIGTERM)"])
        .collect();
    let (took, _) = signal_n_and_expect(run, pid, "-INT", times, stderr_path, &words);
    assert!(took < Duration::from_secs(30), "{took:?}");
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["status"], "failed", "{summary}");
    assert!(
        summary["message"].as_str().unwrap().contains("interrupted"),
        "{summary}"
    );
    summary
}

/// Runs the scene, waits for a few probe samples, sends `signal` to `victim`, and checks the clean failure.
fn lose(name: &str, victim: &str, signal: &str, expect: &[&str]) {
    let Started {
        mut run,
        out,
        stderr_path,
        kids,
        _dir,
    } = start(name);
    let (pid, _) = kids
        .iter()
        .find(|(_, n)| n == victim)
        .unwrap_or_else(|| panic!("{victim} not in {kids:?}"));
    let kept = samples(&out);
    eprintln!("{name}: {signal} to {victim}");
    let (took, _) = signal_and_expect(&mut run, *pid, signal, &stderr_path, expect);
    // The broker's step timeout is 2 s and its liveliness check is immediate: seconds, not minutes.
    assert!(took < Duration::from_secs(30), "{took:?}");
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["status"], "failed", "{summary}");
    assert!(samples(&out) >= kept, "samples lost: {} < {kept}", samples(&out));
    assert!(summary["samples"].as_u64().unwrap() >= kept as u64, "{summary}");
    assert!(out.join("frames").read_dir().unwrap().count() >= 3);
    assert_all_gone(&kids);
}

/// Ctrl-C (SIGINT to `cosim run`), as processes and in-process: the run stops between two steps within a second or
/// two and keeps what it computed: summary.json `failed` saying it was interrupted, the probe samples, the plots
/// and the frames so far; exit 1 with one line; no process left. (Before, the broker died mid-run by the same
/// signal and left no summary and no plots.)
#[test]
fn interrupted() {
    for mode in ["processes", "in-process"] {
        let name = format!("interrupted_{}", mode.replace('-', "_"));
        let Started {
            mut run,
            out,
            stderr_path,
            kids,
            _dir,
        } = start_with(&name, mode == "in-process");
        let kept = samples(&out);
        eprintln!("{name}: SIGINT");
        let summary = interrupt_and_expect(&mut run, &stderr_path, &out, &[]);
        assert_eq!(summary["mode"], mode, "{summary}");
        assert!(samples(&out) >= kept, "samples lost: {} < {kept}", samples(&out));
        assert!(summary["samples"].as_u64().unwrap() >= kept as u64, "{summary}");
        assert!(out.join("plots/tip_x.svg").is_file(), "no plot written");
        assert!(out.join("frames").read_dir().unwrap().count() >= 3);
        assert_all_gone(&kids);
    }
}

/// Ctrl-C during a coupling step of minutes (csm3 with a 1 × 30,000 mesh: 182,575 FE steps of 30,000 elements a
/// coupling step): the broker gives up its wait for the structure's answer 2 s after the signal and ends the run
/// with its outputs so far (the sample and frame at t = 0, the plots), naming the step and the signal; the node
/// still computing goes with it. Before, `cosim run` killed the broker 10 s after the Ctrl-C: "contact-broker died
/// (signal 9); (no message)", no plots.
#[test]
fn interrupted_during_a_long_step() {
    interrupt_a_long_step(false, "fem-node: still computing coupling step 1");
}

/// The same in one process (`--in-process`): the structure's sub-cycle is left between two sub-steps 2 s after the
/// Ctrl-C (`cosim_bus::interrupt::STOP_WAIT`), and the run ends `failed` with its outputs so far. Before, the run
/// waited for the coupling step (4.5 minutes here) or died at a second Ctrl-C with none.
#[test]
fn interrupted_in_process_during_a_long_step() {
    interrupt_a_long_step(true, "coupling step 1 from t = 0 s: fem-node: stopped after");
}

/// csm3 at 1 × 30,000 (`in_process` or as processes), SIGINT a second into its first coupling step (of ~4.5 min):
/// the run ends within 30 s, `failed`, saying `said` and the signal, with the sample, frame and plot at t = 0;
/// nothing left running.
fn interrupt_a_long_step(in_process: bool, said: &str) {
    let sets = ["solid[0].divisions=[1,30000]"];
    let (name, processes) = match in_process {
        true => ("interrupted_long_step_ip", 0),
        false => ("interrupted_long_step", 2),
    };
    let Started {
        mut run,
        out,
        stderr_path,
        kids,
        _dir,
    } = start_run(name, "scenes/csm3.toml", &sets, in_process, processes, 1);
    // Well into coupling step 1.
    std::thread::sleep(Duration::from_secs(1));
    // In one process, the signal twice at once: still one request.
    let times = if in_process { 2 } else { 1 };
    let summary = interrupt_n_and_expect(&mut run, times, &stderr_path, &out, &[said]);
    assert_eq!(summary["samples"], 1, "{summary}");
    assert_eq!(samples(&out), 1);
    assert!(out.join("plots/tip_ux.svg").is_file(), "no plot written");
    assert!(out.join("frames/structure_00000.vtu").is_file(), "no frame written");
    assert_all_gone(&kids);
}

/// `cosim run` itself killed with SIGKILL (it runs no clean-up): the broker finds its progress pipe closed, stops
/// the run within a progress interval and writes why in summary.json; the nodes follow it. Nothing may go on
/// computing a run nobody collects (before, the broker ran on to the scene's end time).
#[test]
fn launcher_killed() {
    let Started {
        mut run,
        out,
        kids,
        _dir,
        ..
    } = start("launcher_killed");
    let kept = samples(&out);
    let hit = Instant::now();
    run.0.kill().unwrap();
    run.0.wait().unwrap();
    assert_all_gone(&kids);
    eprintln!(
        "launcher_killed: its three processes gone {:.2?} after the SIGKILL",
        hit.elapsed()
    );
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["status"], "failed", "{summary}");
    let message = summary["message"].as_str().unwrap();
    assert!(message.contains("the launcher stopped reading"), "{message}");
    // The end time is 10 s of physics: the run was stopped, not finished.
    assert!(summary["sim_time"].as_f64().unwrap() < 5.0, "{summary}");
    assert!(samples(&out) >= kept, "samples lost: {} < {kept}", samples(&out));
}

#[test]
fn fem_node_killed() {
    lose("fem_killed", "fem-node", "-KILL", &["fem-node", "died"]);
}

#[test]
fn sph_node_killed() {
    lose("sph_killed", "sph-node", "-KILL", &["sph-node", "died"]);
}

#[test]
fn broker_killed() {
    lose(
        "broker_killed",
        "contact-broker",
        "-KILL",
        &["contact-broker died (signal 9)"],
    );
}

#[test]
fn sph_node_frozen() {
    lose(
        "sph_frozen",
        "sph-node",
        "-STOP",
        &["sph-node", "no answer", "coupling.step_timeout"],
    );
}
