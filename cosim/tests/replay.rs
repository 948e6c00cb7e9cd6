//! Record and replay (issue 19, `docs/PROTOCOL.md` §10): a coupled gate recorded with `cosim run --record` replays
//! byte for byte against `fem-node` and `sph-node`; a node that answers one value one ulp off at step k is named
//! with its step, message, field and index; a trace cut short (a broker killed mid-run, or a file cut mid-record)
//! replays up to its last complete step. Everything on loopback with fresh run ids; each test takes seconds.

mod common;

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use common::*;

/// The coarse gate: 314 coupling steps, under a second on 2 cores.
const GATE: [&str; 5] = [
    "scenes/elastic_gate.toml",
    "--set",
    "run.end_time=0.02",
    "--set",
    "fluid.spacing=0.004",
];

/// Record the coarse gate into a fresh folder; the folder.
fn record(name: &str, extra: &[&str]) -> Scratch {
    let out = scratch(name);
    let out_s = out.display().to_string();
    let id = run_id(name);
    let mut args = vec!["run", "--quiet", "--run-id", &id, "--out", &out_s];
    args.extend(GATE);
    args.extend(extra);
    run_ok(&args);
    out
}

/// `cosim replay ARGS`, bounded.
fn replay(args: &[&str]) -> Output {
    let mut cmd = Command::new(cosim());
    cmd.current_dir(root())
        .arg("replay")
        .args(args)
        .env("COSIM_BIN_DIR", bin_dir());
    run_bounded(&mut cmd, Duration::from_secs(60))
}

fn text(out: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// The N of "matched N steps".
fn matched(out: &Output) -> u64 {
    assert!(out.status.success(), "replay failed: {}", text(out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    stdout
        .split_whitespace()
        .nth(1)
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no `matched N steps` in {stdout:?}"))
}

/// `full` (a trace whose records are `records`) with its records in `order` (indices into `records`).
fn reordered(full: &[u8], records: &[cosim_proto::trace::Record], order: &[usize]) -> Vec<u8> {
    let mut spans = Vec::with_capacity(records.len());
    let mut at = cosim_proto::trace::HEADER_BYTES;
    for r in records {
        let len = 8 + 10 + r.payload.len();
        spans.push(at..at + len);
        at += len;
    }
    let mut out = full[..cosim_proto::trace::HEADER_BYTES].to_vec();
    for &k in order {
        out.extend_from_slice(&full[spans[k].clone()]);
    }
    out
}

fn trace_of(out: &Path) -> String {
    out.join("trace").display().to_string()
}

#[test]
fn recorded_gate_replays_byte_for_byte_against_both_nodes() {
    let out = record("replay_gate", &["--record"]);
    let steps = json(&out.join("summary.json"))["steps"].as_u64().unwrap();
    assert_eq!(steps, 314);
    // Step 0 (the first sample) and every coupling step: each node answered 315 commands.
    let trace = trace_of(&out);
    assert_eq!(matched(&replay(&[&trace, "--node", "fem"])), steps + 1);
    assert_eq!(matched(&replay(&[&trace, "--node", "sph"])), steps + 1);
    // A run in one process records the messages its nodes would have exchanged: they replay the same.
    let inside = record("replay_gate_in_process", &["--record", "--in-process"]);
    let trace = trace_of(&inside);
    assert_eq!(matched(&replay(&[&trace, "--node", "fem"])), steps + 1);
    assert_eq!(matched(&replay(&[&trace, "--node", "sph"])), steps + 1);
    // Recording changes nothing the run writes.
    let plain = record("replay_gate_plain", &[]);
    for file in ["probes.csv", "frames/structure_00002.vtu", "frames/particles_00002.vtu"] {
        let (a, b) = (
            std::fs::read(out.join(file)).unwrap(),
            std::fs::read(plain.join(file)).unwrap(),
        );
        assert!(a == b, "{file} differs with --record");
    }
    // The end record says how the run ended and what the recording cost.
    let bytes = std::fs::read(out.join("trace/trace.bin")).unwrap();
    let t = cosim_proto::trace::parse(&bytes).unwrap();
    let end = t.records.last().unwrap();
    assert_eq!(end.kind, cosim_proto::trace::Kind::End);
    let end: serde_json::Value = serde_json::from_slice(&end.payload).unwrap();
    assert_eq!(
        (end["status"].as_str(), end["steps"].as_u64()),
        (Some("ok"), Some(steps))
    );
    assert_eq!(
        end["bytes"].as_u64().unwrap() as usize + 8 + 10 + t.records.last().unwrap().payload.len(),
        bytes.len()
    );
    // The summary says what the trace holds, end record included, and that it holds the whole run.
    let note = &json(&out.join("summary.json"))["trace"];
    assert_eq!(note["records"].as_u64(), Some(t.records.len() as u64), "{note}");
    assert_eq!(note["bytes"].as_u64(), Some(bytes.len() as u64), "{note}");
    assert!(note["stopped"].is_null(), "{note}");
    assert!(json(&plain.join("summary.json"))["trace"].is_null());
}

#[test]
fn a_wrong_node_is_named_at_its_step_field_and_index() {
    let out = record("replay_wrong", &["--record"]);
    let trace = trace_of(&out);
    let fem = program("fem-node").display().to_string();
    let wrong = format!("env COSIM_TEST_PERTURB_STEP=7 {fem}");
    let got = replay(&[&trace, "--node", "fem", "--exec", &wrong]);
    let said = text(&got);
    assert_eq!(got.status.code(), Some(1), "{said}");
    assert!(
        said.contains("divergence at step 7, message fem/state, field x index [0][0]: recorded "),
        "{said}"
    );
    // One ulp is within any tolerance worth the name: the per-field comparison lets it through.
    let lenient = replay(&[&trace, "--node", "fem", "--exec", &wrong, "--rtol", "1e-12"]);
    assert_eq!(matched(&lenient), 315);
    // A compound line runs as the shell runs it, the arguments going to the node at its end: it was `exec cd … &&
    // ./fem-node "$@"`, and the node never started (found 2026-12-06 by the sweep of hostile external nodes, D25).
    let compound = format!("cd '{}' && ./fem-node", bin_dir().display());
    assert_eq!(matched(&replay(&[&trace, "--node", "fem", "--exec", &compound])), 315);
}

#[test]
fn a_trace_cut_mid_record_replays_its_complete_steps() {
    let out = record("replay_cut", &["--record"]);
    let full = std::fs::read(out.join("trace/trace.bin")).unwrap();
    let records = cosim_proto::trace::parse(&full).unwrap().records;
    // Cut in the middle of the 400th record (a state or command of step ~100).
    let mut at = cosim_proto::trace::HEADER_BYTES;
    for r in &records[..400] {
        at += 8 + 10 + r.payload.len();
    }
    let cut = at + 8 + 10 + records[400].payload.len() / 2;
    let dir = scratch("replay_cut_trace");
    std::fs::write(dir.join("trace.bin"), &full[..cut]).unwrap();
    let complete = records[..400]
        .iter()
        .filter(|r| r.kind == cosim_proto::trace::Kind::State && r.node == cosim_proto::trace::Node::Sph)
        .count() as u64;
    let dir_s = dir.display().to_string();
    let got = replay(&[&dir_s, "--node", "sph"]);
    assert_eq!(matched(&got), complete);
    assert!(complete > 50 && complete < 315, "{complete}");
    let said = String::from_utf8_lossy(&got.stderr);
    assert!(
        said.contains("stops before its end") && said.contains("cut short"),
        "{said}"
    );
    // Bad input: not a trace, and a node the run did not have (exit 2, one line).
    let scene = root().join("scenes/elastic_gate.toml").display().to_string();
    let not = replay(&[&scene, "--node", "fem"]);
    assert_eq!(not.status.code(), Some(2), "{}", text(&not));
    assert!(text(&not).contains("not a cosim trace"), "{}", text(&not));
}

/// The broker SIGKILLed in the middle of a run: its trace replays up to the last step it recorded whole.
#[test]
fn killing_the_broker_mid_run_leaves_a_trace_that_replays() {
    let out = scratch("replay_killed");
    let id = run_id("replay_killed");
    let mut run = Kill(
        Command::new(cosim())
            .current_dir(root())
            .args(["run", "--quiet", "--record", "--run-id", &id, "--out"])
            .arg(&out)
            .args([
                "scenes/elastic_gate.toml",
                "--set",
                "run.end_time=0.5",
                "--set",
                "fluid.spacing=0.004",
            ])
            .env("COSIM_BIN_DIR", bin_dir())
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    );
    let file = out.join("trace/trace.bin");
    let started = Instant::now();
    while std::fs::metadata(&file).map_or(0, |m| m.len()) < 2_000_000 {
        assert!(
            run.0.try_wait().unwrap().is_none(),
            "the run ended before it was killed"
        );
        assert!(started.elapsed() < Duration::from_secs(60), "the run did not get going");
        std::thread::sleep(Duration::from_millis(5));
    }
    let broker = children(run.0.id())
        .into_iter()
        .find(|(_, name)| name == "contact-broker")
        .expect("the broker is a child of cosim run");
    Command::new("kill")
        .args(["-KILL", &broker.0.to_string()])
        .status()
        .unwrap();
    let status = wait_exit(&mut run.0, Instant::now() + Duration::from_secs(30), "cosim run");
    assert!(!status.success());
    let bytes = std::fs::read(&file).unwrap();
    let t = cosim_proto::trace::parse(&bytes).unwrap();
    assert!(
        t.records.iter().all(|r| r.kind != cosim_proto::trace::Kind::End),
        "no end record after a SIGKILL"
    );
    let states = |node| {
        t.records
            .iter()
            .filter(|r| r.kind == cosim_proto::trace::Kind::State && r.node == node)
            .count() as u64
    };
    let trace = trace_of(&out);
    let fem = matched(&replay(&[&trace, "--node", "fem"]));
    assert_eq!(fem, states(cosim_proto::trace::Node::Fem));
    assert!(fem > 50, "{fem}");
    assert_eq!(
        matched(&replay(&[&trace, "--node", "sph"])),
        states(cosim_proto::trace::Node::Sph)
    );
}

/// A run continued from a checkpoint records the state the broker hands each node (the restore reply): its trace
/// replays from there, the node restored from the recorded state.
#[test]
fn a_restarted_run_replays_from_its_checkpoint() {
    let first = record("replay_ckpt", &["--checkpoint-interval", "0.01"]);
    let at = first.join("checkpoints/156");
    assert!(at.is_dir(), "no checkpoint at step 156");
    let at = at.display().to_string();
    let out = record("replay_restarted", &["--restart", &at, "--record"]);
    let trace = trace_of(&out);
    // Steps 157 to 314 (158 commands answered).
    assert_eq!(matched(&replay(&[&trace, "--node", "fem"])), 158);
    assert_eq!(matched(&replay(&[&trace, "--node", "sph"])), 158);
    // The recorded run had no structure node: nothing to replay (exit 2, one line).
    let fluid = scratch("replay_fluid_only");
    let fluid_s = fluid.display().to_string();
    let id = run_id("replay_fluid_only");
    run_ok(&[
        "run",
        "scenes/dam_break.toml",
        "--quiet",
        "--record",
        "--run-id",
        &id,
        "--out",
        &fluid_s,
        "--set",
        "run.end_time=0.01",
        "--set",
        "fluid.spacing=0.01",
    ]);
    let none = replay(&[&trace_of(&fluid), "--node", "fem"]);
    assert_eq!(none.status.code(), Some(2), "{}", text(&none));
    assert!(text(&none).contains("fem-node never registered"), "{}", text(&none));
}

/// A run that blew up: the node's failure report is recorded under the step it failed at, and the replayed node
/// fails at that step with the same report (compared like an answer).
#[test]
fn an_unstable_runs_trace_replays_its_failure() {
    let out = scratch("replay_unstable");
    let out_s = out.display().to_string();
    let id = run_id("replay_unstable");
    let mut cmd = Command::new(cosim());
    cmd.current_dir(root())
        .args([
            "run",
            "cosim/tests/data/fluid_unstable.toml",
            "--quiet",
            "--record",
            "--run-id",
            &id,
            "--out",
            &out_s,
        ])
        .env("COSIM_BIN_DIR", bin_dir());
    let run = run_bounded(&mut cmd, RUN_LIMIT);
    assert_eq!(run.status.code(), Some(1), "{}", text(&run));
    let bytes = std::fs::read(out.join("trace/trace.bin")).unwrap();
    let t = cosim_proto::trace::parse(&bytes).unwrap();
    let error = t
        .records
        .iter()
        .find(|r| r.kind == cosim_proto::trace::Kind::Error)
        .expect("an error record");
    let states = t
        .records
        .iter()
        .filter(|r| r.kind == cosim_proto::trace::Kind::State)
        .count() as u64;
    assert_eq!(
        error.step, states,
        "the failure is recorded under the step after the last answer"
    );
    // Every answer and the failure itself.
    assert_eq!(matched(&replay(&[&trace_of(&out), "--node", "sph"])), states + 1);
}

/// A replay "matches" only what it checked (found 2026-12-06 by a sweep of damaged traces): a trace with a state
/// record removed from its middle replayed "matched 2 steps" of 315 and exit 0, and a node answering compute_seconds
/// = NaN (the one field the comparison masks, which a live run refuses) matched every step. Now the first is a damaged
/// trace (exit 2, one line) and the second a failure at its step (exit 1).
#[test]
fn a_damaged_trace_or_an_unusable_answer_is_not_a_match() {
    let out = record("replay_damaged", &["--record"]);
    let full = std::fs::read(out.join("trace/trace.bin")).unwrap();
    let records = cosim_proto::trace::parse(&full).unwrap().records;
    let (mut at, mut cut) = (cosim_proto::trace::HEADER_BYTES, None);
    for r in &records {
        let len = 8 + 10 + r.payload.len();
        if r.kind == cosim_proto::trace::Kind::State && r.node == cosim_proto::trace::Node::Fem && r.step == 100 {
            cut = Some((at, at + len));
        }
        at += len;
    }
    let (from, to) = cut.expect("fem-node's answer to step 100 in the trace");
    let dir = scratch("replay_damaged_trace");
    std::fs::write(dir.join("trace.bin"), [&full[..from], &full[to..]].concat()).unwrap();
    let dir_s = dir.display().to_string();
    let got = replay(&[&dir_s, "--node", "fem"]);
    let said = text(&got);
    assert_eq!(got.status.code(), Some(2), "{said}");
    assert!(
        said.contains("the command of step 100 has no answer, yet step 101 follows it: the trace is damaged"),
        "{said}"
    );
    // The other node's part of the same file is whole.
    assert_eq!(matched(&replay(&[&dir_s, "--node", "sph"])), 315);

    // Two of fem-node's commands swapped, or one removed: said before the node starts, naming the file's record
    // (found 2026-12-06 by the sweep of damaged traces, D22: the node was blamed, "no answer from fem-node within
    // 10 s", and the record numbered among the node's own).
    let fem_command = |step| {
        records
            .iter()
            .position(|r| {
                r.kind == cosim_proto::trace::Kind::Command && r.node == cosim_proto::trace::Node::Fem && r.step == step
            })
            .unwrap()
    };
    let (c9, c10, c11) = (fem_command(9), fem_command(10), fem_command(11));
    let mut order: Vec<usize> = (0..records.len()).collect();
    order.swap(c10, c11);
    let file = dir.join("trace.bin");
    std::fs::write(&file, reordered(&full, &records, &order)).unwrap();
    let got = replay(&[&dir_s, "--node", "fem"]);
    let said = text(&got);
    assert_eq!(got.status.code(), Some(2), "{said}");
    assert_eq!(
        said.trim(),
        format!(
            "cosim: {}: record {c10} (command of step 11): comes after the command of step 9 (record {c9}): the \
             commands are out of order (a record lost, moved or changed)",
            file.display()
        )
    );
    let state10 = records
        .iter()
        .position(|r| {
            r.kind == cosim_proto::trace::Kind::State && r.node == cosim_proto::trace::Node::Fem && r.step == 10
        })
        .unwrap();
    let order: Vec<usize> = (0..records.len()).filter(|&k| k != c10).collect();
    std::fs::write(&file, reordered(&full, &records, &order)).unwrap();
    let got = replay(&[&dir_s, "--node", "fem"]);
    let said = text(&got);
    assert_eq!(got.status.code(), Some(2), "{said}");
    assert!(
        said.contains(&format!(
            "record {} (state of step 10): the last command before it is record {c9} (step 9), of another step: the \
             trace is damaged",
            state10 - 1
        )),
        "{said}"
    );
    // A device is not a trace, and is not read (/dev/zero was read until 6.5 GB were taken).
    let zero = replay(&["/dev/zero", "--node", "fem"]);
    assert_eq!(zero.status.code(), Some(2), "{}", text(&zero));
    assert!(
        text(&zero).contains("/dev/zero: not a regular file, so not a trace"),
        "{}",
        text(&zero)
    );

    let trace = trace_of(&out);
    let fem = program("fem-node").display().to_string();
    let nan = format!("env COSIM_TEST_NAN_SECONDS_STEP=7 {fem}");
    let got = replay(&[&trace, "--node", "fem", "--exec", &nan]);
    let said = text(&got);
    assert_eq!(got.status.code(), Some(1), "{said}");
    assert!(
        said.contains("step 7: fem-node answered fem/state compute_seconds = NaN: must be a number of seconds"),
        "{said}"
    );

    // What an --exec wrapper starts beside the node ends with the replay (a wrapper's child outlived it).
    let wrapper = dir.join("wrapper.sh");
    let pid_file = dir.join("sleep.pid");
    std::fs::write(
        &wrapper,
        format!(
            "#!/bin/sh\nsleep 321 &\necho $! > {}\nexec {fem} \"$@\"\n",
            pid_file.display()
        ),
    )
    .unwrap();
    std::fs::set_permissions(&wrapper, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    let wrapper_s = wrapper.display().to_string();
    assert_eq!(matched(&replay(&[&trace, "--node", "fem", "--exec", &wrapper_s])), 315);
    let pid = std::fs::read_to_string(&pid_file).unwrap().trim().to_string();
    // Alive: in /proc and not a zombie (killed, it waits there for init to reap it).
    let running = || {
        std::fs::read_to_string(format!("/proc/{pid}/stat"))
            .ok()
            .and_then(|s| s.rsplit(')').next().map(|rest| !rest.trim_start().starts_with('Z')))
            .unwrap_or(false)
    };
    let since = Instant::now();
    while running() && since.elapsed() < Duration::from_secs(2) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let alive = running();
    if alive {
        let _ = Command::new("kill").arg(&pid).status();
    }
    assert!(!alive, "the wrapper's child {pid} outlived the replay");
}
