//! Pause, step, resume, break and look inside a live run (issue 19; `docs/PROTOCOL.md` §11): `cosim run --break
//! t>=T` pauses the coarse gate within one step of T with every process alive; `cosim snapshot` writes its frames
//! there; `cosim ctl step 10` takes exactly 10 steps; `cosim inspect --particle/--node` print one particle's and one
//! node's state; `cosim ctl resume` lets it finish, and its probes and frames are byte-identical to a run never
//! paused. `--break unstable` on a run that blows up (through a router, `--connect`) pauses it, processes alive,
//! where `cosim inspect --particle` shows the particle the fluid node named; `stop` ends it `unstable` as before.

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::*;

/// Bound on each wait for a run; the runs themselves take a few seconds.
const LIMIT: Duration = Duration::from_secs(90);
/// The coarse gate: 875 particles at 4 mm, to 0.03 s (300 coupling steps of `coupling.max_dt` = 1e-4 s).
const GATE: [&str; 5] = [
    "scenes/elastic_gate.toml",
    "--set",
    "fluid.spacing=0.004",
    "--set",
    "run.end_time=0.03",
];
/// Where the gate run breaks [s].
const BREAK_AT: f64 = 0.0125;
/// The gate's coupling step cap (`coupling.max_dt`) [s].
const MAX_DT: f64 = 1e-4;

/// `cosim run` of `scene_args` with `extra`, not waited for.
fn start(scene_args: &[&str], out: &Path, id: &str, extra: &[&str]) -> Kill {
    Kill(
        Command::new(cosim())
            .current_dir(root())
            .env("COSIM_BIN_DIR", bin_dir())
            .arg("run")
            .args(scene_args)
            .args(["--quiet", "--run-id", id, "--out"])
            .arg(out)
            .args(extra)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap(),
    )
}

/// `cosim ARGS`: exit code, stdout parsed as JSON (Null if it is not), stdout and stderr as text.
fn cosim_json(args: &[&str]) -> (i32, serde_json::Value, String) {
    let out = cosim_run(args, Duration::from_secs(60));
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let doc = serde_json::from_str(&stdout).unwrap_or(serde_json::Value::Null);
    let text = stdout + &String::from_utf8_lossy(&out.stderr);
    (out.status.code().unwrap_or(-1), doc, text)
}

/// Ask `cosim ctl ID status` until the run says it is paused; its answer.
fn wait_paused(run: &mut Kill, id: &str, join: &[&str]) -> serde_json::Value {
    let started = Instant::now();
    loop {
        assert!(run.0.try_wait().unwrap().is_none(), "the run ended instead of pausing");
        assert!(started.elapsed() < LIMIT, "the run did not pause");
        let mut args = vec!["ctl", id, "status"];
        args.extend_from_slice(join);
        let (code, doc, _) = cosim_json(&args);
        if code == 0 && doc["paused"].as_str().is_some_and(|p| !p.is_empty()) {
            return doc;
        }
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// Every file of `a/frames` and `a/probes.csv` has the same bytes in `b`.
fn assert_same_outputs(a: &Path, b: &Path) {
    let read = |p: &Path| std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    assert!(
        read(&a.join("probes.csv")) == read(&b.join("probes.csv")),
        "probes.csv differs"
    );
    let mut names: Vec<_> = std::fs::read_dir(a.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    names.sort();
    assert!(names.len() > 4, "{names:?}");
    for name in &names {
        let (fa, fb) = (a.join("frames").join(name), b.join("frames").join(name));
        assert!(read(&fa) == read(&fb), "{} differs", name.to_string_lossy());
    }
    let count = std::fs::read_dir(b.join("frames")).unwrap().count();
    assert_eq!(count, names.len(), "frames in {} and {}", a.display(), b.display());
}

#[test]
fn break_snapshot_step_and_resume_leave_the_run_bit_identical() {
    let dir = scratch("ctl-break");
    // A bad condition is refused before anything starts, naming it.
    let bad = cosim_run(&["run", "x.toml", "--break", "t>0.1"], Duration::from_secs(20));
    let err = String::from_utf8_lossy(&bad.stderr);
    assert_eq!(bad.status.code(), Some(2), "{err}");
    assert!(err.contains("`t>0.1`") && err.contains("unstable"), "{err}");
    let scene = root().join("cosim/tests/data/fluid_unstable.toml");
    let in_process = cosim_run(
        &["run", scene.to_str().unwrap(), "--in-process", "--break", "unstable"],
        Duration::from_secs(20),
    );
    let err = String::from_utf8_lossy(&in_process.stderr);
    assert_eq!(in_process.status.code(), Some(2), "{err}");
    assert!(err.contains("--in-process"), "{err}");

    // The run never paused.
    let reference = dir.join("reference");
    let mut args: Vec<&str> = vec!["run"];
    args.extend_from_slice(&GATE);
    args.extend(["--quiet", "--out", reference.to_str().unwrap()]);
    run_ok(&args);

    let out = dir.join("paused");
    let id = run_id("ctl-break");
    let condition = format!("t>={BREAK_AT}");
    let mut run = start(&GATE, &out, &id, &["--break", &condition]);
    let paused = wait_paused(&mut run, &id, &[]);
    let (step, t) = (paused["step"].as_u64().unwrap(), paused["t"].as_f64().unwrap());
    assert_eq!(
        paused["paused"],
        format!("paused at step {step}: {condition}"),
        "{paused}"
    );
    assert!(
        (BREAK_AT..BREAK_AT + MAX_DT * (1.0 + 1e-9)).contains(&t),
        "paused at t = {t}"
    );
    // Every process alive, the broker's status saying why it waits.
    let names: Vec<String> = children(run.0.id()).into_iter().map(|c| c.1).collect();
    for name in ["contact-broker", "fem-node", "sph-node"] {
        assert!(names.iter().any(|n| n == name), "{name} not alive: {names:?}");
    }
    let (code, doc, text) = cosim_json(&["inspect", &id, "--once"]);
    assert_eq!(code, 0, "{text}");
    assert_eq!(
        doc["nodes"]["contact-broker"]["extra"]["paused"], paused["paused"],
        "{doc:#}"
    );
    assert_eq!(doc["nodes"]["sph-node"]["step"], step, "{doc:#}");
    // The energy balance, live: the WCSPH gate gains at most 0.0011 of its budget as shipped (docs/VALIDATION.md).
    let made = doc["nodes"]["contact-broker"]["extra"]["energy_made"].as_f64();
    assert!(made.is_some_and(|g| (0.0..0.01).contains(&g)), "{doc:#}");

    // Not into the run's own folder, whose first frames it would replace (2026-12-06): exit 2, the frame kept.
    let first = std::fs::read(out.join("frames/structure_00000.vtu")).unwrap();
    let (code, _, text) = cosim_json(&["snapshot", &id, "--out", out.to_str().unwrap()]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("holds a run's outputs (summary.json)"), "{text}");
    assert!(std::fs::read(out.join("frames/structure_00000.vtu")).unwrap() == first);
    // A snapshot while paused: the mesh, the particles, the last pass's contacts.
    let snap = dir.join("snapshot");
    let (code, _, text) = cosim_json(&["snapshot", &id, "--out", snap.to_str().unwrap()]);
    assert_eq!(code, 0, "{text}");
    for frame in [
        "structure_00000.vtu",
        "particles_00000.vtu",
        "contacts.vtu",
        "structure.pvd",
        "particles.pvd",
    ] {
        let file = snap.join("frames").join(frame);
        let body = std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        assert!(body.trim_end().ends_with("</VTKFile>"), "{frame} is not complete");
    }
    let s = json(&snap.join("snapshot.json"));
    assert_eq!(s["step"], step);
    assert_eq!(s["particles"], 875);
    assert_eq!(s["fem_nodes"], 480);
    // The contacts as the particle–element pass recorded them (not reconstructed): each pair with a segment (or a
    // node), its gap at detection (penetrating or within touch), λ = −g/w ≥ 0 and J = −v_rel/w ≥ 0 (DESIGN.md §4.5).
    assert_eq!(s["contacts_source"], "recorded", "{s:#}");
    let contacts = s["contacts"].as_array().unwrap();
    assert!(!contacts.is_empty(), "the gate touches the fluid by t = {BREAK_AT} s");
    for c in contacts {
        assert_eq!(c["source"], "recorded", "{c}");
        let segment = c["segment"].as_i64().unwrap();
        assert!(segment >= -1, "{c}");
        let (gap, lambda, impulse) = (
            c["gap"].as_f64().unwrap(),
            c["lambda"].as_f64().unwrap(),
            c["impulse"].as_f64().unwrap(),
        );
        assert!(gap.is_finite() && gap < 1e-3, "{c}");
        assert!(lambda >= 0.0 && impulse >= 0.0 && lambda + impulse > 0.0, "{c}");
        if lambda > 0.0 {
            assert!(gap < 0.0, "a position correction only on a penetrating pair: {c}");
        }
    }
    let vtu = std::fs::read_to_string(snap.join("frames/contacts.vtu")).unwrap();
    assert!(
        vtu.contains(&format!("NumberOfPoints=\"{}\"", contacts.len())),
        "{vtu:.300}"
    );
    for field in [
        "particle", "segment", "node", "gap", "lambda", "impulse", "dx", "dv", "recorded",
    ] {
        assert!(
            vtu.contains(&format!("Name=\"{field}\"")),
            "{field} missing from contacts.vtu"
        );
    }
    let particles = std::fs::read_to_string(snap.join("frames/particles_00000.vtu")).unwrap();
    assert!(particles.contains("NumberOfPoints=\""), "{particles:.200}");

    // One particle and one node, as the run holds them now.
    let (code, p, text) = cosim_json(&["inspect", &id, "--particle", "0"]);
    assert_eq!(code, 0, "{text}");
    assert_eq!(p["step"], step);
    assert_eq!(p["particle"]["id"], 0);
    assert!(p["particle"]["rho"].as_f64().unwrap() > 900.0, "{p:#}");
    assert!(
        !p["particle"]["neighbours"]["fluid"].as_array().unwrap().is_empty(),
        "{p:#}"
    );
    let (code, n, text) = cosim_json(&["inspect", &id, "--node", "0"]);
    assert_eq!(code, 0, "{text}");
    assert_eq!(n["node"]["id"], 0);
    assert_eq!(n["node"]["x"].as_array().unwrap().len(), 2, "{n:#}");

    // Exactly 10 steps, then paused again.
    let (code, stepped, text) = cosim_json(&["ctl", &id, "step", "10"]);
    assert_eq!(code, 0, "{text}");
    assert_eq!(stepped["step"], step + 10, "{stepped}");
    assert_eq!(
        stepped["paused"],
        format!("paused at step {}: `step 10` done", step + 10)
    );

    // Stepped past its end, it finishes as the run never paused did, to the bit, and `step` says that the run ended
    // before the steps were taken (it waited for an answer and said only that none came, before 2026-12-07).
    let (code, ended, text) = cosim_json(&["ctl", &id, "step", "1000000"]);
    assert_eq!(code, 1, "{text}");
    let message = ended["message"].as_str().unwrap_or_default();
    assert!(
        message.starts_with("the run ended before pausing again (its broker is gone; last seen at step "),
        "{text}"
    );
    let status = wait_exit(&mut run.0, Instant::now() + LIMIT, "the resumed run");
    assert!(status.success());
    assert_same_outputs(&reference, &out);
    assert_eq!(
        json(&out.join("summary.json"))["steps"],
        json(&reference.join("summary.json"))["steps"]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_blow_up_pauses_with_the_processes_alive_through_a_router() {
    let dir = scratch("ctl-unstable");
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let (_router, _) = start_router(&endpoint, None, &dir.join("router.log"));
    let out = dir.join("out");
    let id = run_id("ctl-unstable");
    let scene = ["cosim/tests/data/fluid_unstable.toml"];
    let mut run = start(&scene, &out, &id, &["--break", "unstable", "--connect", &endpoint]);
    let join = ["--connect", endpoint.as_str(), "--client"];
    let paused = wait_paused(&mut run, &id, &join);
    let line = paused["paused"].as_str().unwrap().to_string();
    assert!(
        line.contains(": unstable: ") && line.contains("unstable at SPH step "),
        "{line}"
    );
    // The particle the fluid node named.
    let particle: u32 = line
        .split_once(", particle ")
        .and_then(|(_, r)| r.split(':').next())
        .and_then(|k| k.parse().ok())
        .unwrap_or_else(|| panic!("no particle in {line}"));
    let names: Vec<(u32, String)> = children(run.0.id());
    for name in ["contact-broker", "sph-node"] {
        let pid = names
            .iter()
            .find(|n| n.1 == name)
            .unwrap_or_else(|| panic!("{name}: {names:?}"))
            .0;
        assert!(alive(pid), "{name} is gone");
    }
    let mut args = vec!["inspect", &id, "--particle"];
    let k = particle.to_string();
    args.push(&k);
    args.extend_from_slice(&join);
    let (code, doc, text) = cosim_json(&args);
    assert_eq!(code, 0, "{text}");
    assert_eq!(doc["particle"]["id"], particle, "{doc:#}");
    assert_eq!(doc["paused"], line.as_str());
    let x = doc["particle"]["x"].as_array().unwrap();
    assert_eq!(x.len(), 2, "{doc:#}");
    // "left the domain at [x, y]": the state shown is the one the node blew up in.
    if let Some(at) = line.split_once("left the domain at [").map(|(_, r)| r) {
        let said: Vec<f64> = at
            .split(']')
            .next()
            .unwrap()
            .split(',')
            .map(|v| v.trim().parse().unwrap())
            .collect();
        let shown: Vec<f64> = x.iter().map(|v| v.as_f64().unwrap()).collect();
        for (a, b) in said.iter().zip(&shown) {
            assert!(
                (a - b).abs() <= 1e-6 * a.abs().max(1.0),
                "said {said:?}, shown {shown:?}"
            );
        }
    }
    // It cannot go on; stopped, it ends unstable as a run without --break does.
    let mut args = vec!["ctl", &id, "resume"];
    args.extend_from_slice(&join);
    let (code, doc, text) = cosim_json(&args);
    assert_eq!(code, 1, "{text}");
    assert_eq!(doc["ok"], false);
    let mut args = vec!["ctl", &id, "stop"];
    args.extend_from_slice(&join);
    let (code, _, text) = cosim_json(&args);
    assert_eq!(code, 0, "{text}");
    let status = wait_exit(&mut run.0, Instant::now() + LIMIT, "the stopped run");
    assert_eq!(status.code(), Some(1));
    let s = json(&out.join("summary.json"));
    assert_eq!(s["status"], "unstable", "{s:#}");
    assert!(
        s["message"]
            .as_str()
            .unwrap()
            .contains(&format!("particle {particle}:")),
        "{s:#}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--connect` to a port nothing listens on: said at once, exit 2, for `ctl`, `inspect` and `snapshot`. Before,
/// zenoh tried the refused endpoint again until `--timeout` (here 50 s: the runs would have outlasted
/// `cosim_run`'s 60 s only just, and said "within 50 s" instead of why).
#[test]
fn a_closed_endpoint_is_said_at_once() {
    let closed = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let endpoint = format!("tcp/127.0.0.1:{closed}");
    for args in [
        vec!["ctl", "nowhere", "status"],
        vec!["inspect", "nowhere", "--once"],
        vec!["snapshot", "nowhere", "--out", "/tmp/cosim-closed-endpoint-snapshot"],
    ] {
        let mut args = args;
        args.extend(["--connect", &endpoint, "--timeout", "50"]);
        let (code, _, text) = cosim_json(&args);
        assert_eq!(code, 2, "{args:?}: {text}");
        assert!(
            text.contains(&format!("at {endpoint}: nothing listens there")),
            "{args:?}: {text}"
        );
    }
}

/// A run id no run can have is said as such, exit 2, before any look-up (found 2026-12-06 by the sweep of debug
/// tools, D25: `cosim ctl 'bad/id' status` said "not running on this machine").
#[test]
fn an_invalid_run_id_is_said_as_such() {
    for args in [
        vec!["ctl", "bad/id", "status"],
        vec!["inspect", "bad/id", "--once"],
        vec!["snapshot", "bad/id", "--out", "/tmp/cosim-invalid-id-snapshot"],
    ] {
        let (code, _, text) = cosim_json(&args);
        assert_eq!(code, 2, "{args:?}: {text}");
        assert_eq!(
            text.trim(),
            "cosim: `bad/id` is not a valid run id: a run id is 1–64 letters, digits, - and _",
            "{args:?}"
        );
    }
}

/// A step count no run reaches is refused before anything is asked, exit 2 (found 2026-12-06 by the sweep of debug
/// tools, D25: `step 18446744073709551615` resumed the run, then said it "did not pause again").
#[test]
fn a_step_count_no_run_reaches_is_refused() {
    let (code, _, text) = cosim_json(&["ctl", "nowhere", "step", "18446744073709551615"]);
    assert_eq!(code, 2, "{text}");
    assert_eq!(
        text.trim(),
        "cosim: step 18446744073709551615: more than the 1e12 steps a run may take"
    );
}
