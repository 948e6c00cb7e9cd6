//! A run spread over hosts, on loopback: a zenoh router as its own process (`cosim router`, the router `zenohd`
//! runs) is the hub, and every process of the run joins it as a client (`--connect ENDPOINT --client`).
//!
//! - The three processes of a run started by hand (`contact-broker`, `fem-node`, `sph-node`) through the router
//!   give the probes `cosim run --in-process` gives, byte for byte.
//! - A router that wants a user and password (`transport/auth/usrpwd` in its `--zenoh-config` file) lets in a run
//!   whose processes have the right ones in theirs; with a wrong password the run fails cleanly: exit 1, one line on
//!   stderr, in bounded time, no process left.
//! - The same over TLS (`tls/127.0.0.1:PORT`), with the test certificates of `tests/data/tls/`.
//!
//! Multicast scouting is off everywhere (the project's settings go on top of every config file); every test has
//! its own run ids and port.

mod common;

use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use common::*;

/// Longest a run may take.
const LIMIT: Duration = Duration::from_secs(300);
/// Longest a run that cannot join may take to fail (the connect timeout is 5 s).
const FAIL_LIMIT: Duration = Duration::from_secs(60);
const SCENE: &str = "scenes/elastic_gate.toml";
/// The coarse gate, briefly: fluid, structure and contact, so all three processes work.
const SETTINGS: [&str; 4] = ["--set", "fluid.spacing=0.004", "--set", "run.end_time=0.05"];

fn scene() -> PathBuf {
    root().join(SCENE)
}

/// `cosim run SCENE` with the test's settings and `extra`, waited for at most `limit`.
fn cosim_run_scene(out: &Path, id: &str, extra: &[&str], limit: Duration) -> Output {
    let mut cmd = Command::new(cosim());
    cmd.current_dir(root())
        .env("COSIM_BIN_DIR", bin_dir())
        .arg("run")
        .arg(scene())
        .args(["--quiet", "--run-id", id, "--out"])
        .arg(out)
        .args(SETTINGS)
        .args(extra);
    run_bounded(&mut cmd, limit)
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn probes(out: &Path) -> Vec<u8> {
    let bytes = std::fs::read(out.join("probes.csv")).unwrap();
    assert!(bytes.len() > 100, "{}: no samples", out.display());
    bytes
}

/// Command lines of the processes still running that mention `word` (a run id).
fn processes_with(word: &str) -> Vec<String> {
    let me = std::process::id().to_string();
    std::fs::read_dir("/proc")
        .unwrap()
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().chars().all(|c| c.is_ascii_digit()))
        .filter(|e| e.file_name().to_string_lossy() != me.as_str())
        .filter_map(|e| std::fs::read(e.path().join("cmdline")).ok())
        .map(|c| String::from_utf8_lossy(&c).replace('\0', " "))
        .filter(|c| c.contains(word))
        .collect()
}

/// The in-process twin of a run: its probes.
fn reference_probes(dir: &Path, name: &str) -> Vec<u8> {
    let out = dir.join(format!("{name}_alone"));
    let output = cosim_run_scene(&out, &run_id(&format!("{name}-alone")), &["--in-process"], LIMIT);
    assert!(output.status.success(), "in-process reference: {}", stderr(&output));
    probes(&out)
}

/// Write a zenoh JSON5 config file.
fn config_file(path: &Path, json5: &str) -> PathBuf {
    std::fs::write(path, json5).unwrap();
    path.to_path_buf()
}

#[test]
fn three_processes_started_by_hand_through_a_router_process() {
    let dir = scratch("by-hand");
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let (_router, endpoints) = start_router(&endpoint, None, &dir.join("router.stderr"));
    assert_eq!(endpoints, std::slice::from_ref(&endpoint));
    let id = run_id("by-hand");
    let out = dir.join("by_hand");
    let log = |name: &str| std::fs::File::create(dir.join(format!("{name}.stderr"))).unwrap();
    let read_log = |name: &str| std::fs::read_to_string(dir.join(format!("{name}.stderr"))).unwrap_or_default();

    // The broker first, as on its host: `contact-broker --run ID --scene … --out … --connect ROUTER --client`.
    let broker_stdout = dir.join("contact-broker.stdout");
    let mut broker = Kill(
        Command::new(program("contact-broker"))
            .args(["--run", &id, "--scene"])
            .arg(scene())
            .arg("--out")
            .arg(&out)
            .args(SETTINGS)
            .args(["--connect", &endpoint, "--client"])
            .stdin(Stdio::null())
            .stdout(std::fs::File::create(&broker_stdout).unwrap())
            .stderr(log("contact-broker"))
            .spawn()
            .unwrap(),
    );
    let until = Instant::now() + Duration::from_secs(20);
    while !std::fs::read_to_string(&broker_stdout)
        .unwrap_or_default()
        .contains("\"listening\"")
    {
        assert!(
            broker.0.try_wait().unwrap().is_none(),
            "contact-broker exited: {}",
            read_log("contact-broker")
        );
        assert!(Instant::now() < until, "contact-broker did not join the router");
        std::thread::sleep(Duration::from_millis(20));
    }
    // Then the two solver nodes, as on theirs: `fem-node --run ID --connect ROUTER --client`.
    let mut nodes: Vec<(&str, Kill)> = ["fem-node", "sph-node"]
        .into_iter()
        .map(|name| {
            let child = Command::new(program(name))
                .args(["--run", &id, "--connect", &endpoint, "--client"])
                .stdin(Stdio::null())
                .stdout(Stdio::null())
                .stderr(log(name))
                .spawn()
                .unwrap();
            (name, Kill(child))
        })
        .collect();

    let status = wait_exit(&mut broker.0, Instant::now() + LIMIT, "contact-broker");
    assert!(status.success(), "contact-broker: {}", read_log("contact-broker"));
    for (name, node) in &mut nodes {
        let status = wait_exit(&mut node.0, Instant::now() + Duration::from_secs(30), name);
        assert!(status.success(), "{name}: {}", read_log(name));
    }
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["status"], "ok", "{summary}");
    assert_eq!(summary["mode"], "processes");
    assert!(
        probes(&out) == reference_probes(&dir, "by-hand"),
        "the run started by hand differs from its in-process twin"
    );
}

/// The router of a run killed mid-run and started again on its endpoint: every process loses its link, and every
/// partner's liveliness token with it, for about a second (a zenoh client retries its router at once, then after a
/// second). The run goes on (`cosim_bus::link_loss`): no process calls the others gone, the broker sends its last
/// commands again, and the probes are those of the in-process twin, byte for byte.
#[test]
fn a_run_outlives_its_router_restarting() {
    let dir = scratch("router-restart");
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let (router, _) = start_router(&endpoint, None, &dir.join("router.stderr"));
    // Twice the others' end time, so that the restart falls well inside the run (the later `--set` wins).
    let settings = ["--set", "fluid.spacing=0.004", "--set", "run.end_time=0.1"];
    let out = dir.join("restarted");
    let mut run = Kill(
        Command::new(cosim())
            .current_dir(root())
            .env("COSIM_BIN_DIR", bin_dir())
            .arg("run")
            .arg(scene())
            .args(["--quiet", "--run-id", &run_id("router-restart"), "--out"])
            .arg(&out)
            .args(settings)
            .args(["--connect", &endpoint])
            .process_group(0)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(dir.join("cosim.stderr")).unwrap())
            .spawn()
            .unwrap(),
    );
    // The router goes once the run has written its first probe samples after t = 0 (one every 5 ms of 100).
    let until = Instant::now() + LIMIT;
    while std::fs::read_to_string(out.join("probes.csv")).map_or(0, |t| t.lines().count()) < 3 {
        assert!(
            run.0.try_wait().unwrap().is_none(),
            "the run ended before its router was stopped"
        );
        assert!(Instant::now() < until, "the run wrote no samples");
        std::thread::sleep(Duration::from_millis(10));
    }
    drop(router);
    assert!(
        run.0.try_wait().unwrap().is_none(),
        "the run ended before its router was stopped"
    );
    std::thread::sleep(Duration::from_millis(300));
    let (_router, _) = start_router(&endpoint, None, &dir.join("router2.stderr"));

    let status = wait_exit(&mut run.0, Instant::now() + LIMIT, "cosim run");
    let said = std::fs::read_to_string(dir.join("cosim.stderr")).unwrap_or_default();
    assert!(status.success(), "after the router restarted: {said}");
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["status"], "ok", "{summary}");
    // Each process saw its partners' tokens go and come back.
    for name in ["contact-broker", "fem-node", "sph-node"] {
        let log = std::fs::read_to_string(out.join(format!("logs/{name}.log"))).unwrap_or_default();
        assert!(
            log.contains("a link lost and restored"),
            "{name} did not see the link go: {log}"
        );
    }
    let alone = dir.join("alone");
    let output = cosim_run_scene(
        &alone,
        &run_id("router-restart-alone"),
        &["--in-process", settings[2], settings[3]],
        LIMIT,
    );
    assert!(output.status.success(), "in-process reference: {}", stderr(&output));
    assert!(
        probes(&out) == probes(&alone),
        "the run whose router restarted differs from its in-process twin"
    );
}

#[test]
fn a_router_with_passwords_lets_in_the_right_password_only() {
    let dir = scratch("usrpwd");
    let dictionary = dir.join("passwords.txt");
    std::fs::write(&dictionary, "alice:right-secret\nbob:other-secret\n").unwrap();
    let router_config = config_file(
        &dir.join("router.json5"),
        &format!("{{ transport: {{ auth: {{ usrpwd: {{ dictionary_file: {dictionary:?} }} }} }} }}"),
    );
    let user = |password: &str| {
        format!("{{ transport: {{ auth: {{ usrpwd: {{ user: \"alice\", password: \"{password}\" }} }} }} }}")
    };
    let right = config_file(&dir.join("right.json5"), &user("right-secret"));
    let wrong = config_file(&dir.join("wrong.json5"), &user("wrong-secret"));
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let (_router, _) = start_router(&endpoint, Some(&router_config), &dir.join("router.stderr"));

    let out = dir.join("right");
    let output = cosim_run_scene(
        &out,
        &run_id("usrpwd-right"),
        &["--connect", &endpoint, "--zenoh-config", right.to_str().unwrap()],
        LIMIT,
    );
    assert!(output.status.success(), "right password: {}", stderr(&output));
    assert_eq!(json(&out.join("summary.json"))["status"], "ok");

    let id = run_id("usrpwd-wrong");
    let started = Instant::now();
    let output = cosim_run_scene(
        &dir.join("wrong"),
        &id,
        &["--connect", &endpoint, "--zenoh-config", wrong.to_str().unwrap()],
        FAIL_LIMIT,
    );
    let message = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "wrong password: {message}");
    assert_eq!(message.trim().lines().count(), 1, "one line: {message}");
    assert!(message.contains("router"), "says it cannot join the router: {message}");
    assert!(
        message.contains("wrong.json5"),
        "names the config file to check: {message}"
    );
    assert!(started.elapsed() < FAIL_LIMIT);
    assert_eq!(
        processes_with(&id),
        Vec::<String>::new(),
        "a process of the failed run is left"
    );
}

#[test]
fn a_run_through_a_tls_router() {
    let dir = scratch("tls");
    let tls = root().join("cosim/tests/data/tls");
    let router_config = config_file(
        &dir.join("router.json5"),
        &format!(
            "{{ transport: {{ link: {{ tls: {{ listen_certificate: {:?}, listen_private_key: {:?} }} }} }} }}",
            tls.join("server.pem"),
            tls.join("server.key")
        ),
    );
    let client_config = config_file(
        &dir.join("client.json5"),
        &format!(
            "{{ transport: {{ link: {{ tls: {{ root_ca_certificate: {:?} }} }} }} }}",
            tls.join("ca.pem")
        ),
    );
    let endpoint = format!("tls/127.0.0.1:{}", free_port());
    let (_router, endpoints) = start_router(&endpoint, Some(&router_config), &dir.join("router.stderr"));
    assert_eq!(endpoints, std::slice::from_ref(&endpoint));

    let out = dir.join("tls");
    let output = cosim_run_scene(
        &out,
        &run_id("tls"),
        &[
            "--connect",
            &endpoint,
            "--zenoh-config",
            client_config.to_str().unwrap(),
        ],
        LIMIT,
    );
    assert!(output.status.success(), "over TLS: {}", stderr(&output));
    assert_eq!(json(&out.join("summary.json"))["status"], "ok");

    // Without the CA the router's certificate is not trusted: the run cannot join.
    let output = cosim_run_scene(
        &dir.join("untrusted"),
        &run_id("tls-untrusted"),
        &["--connect", &endpoint],
        FAIL_LIMIT,
    );
    assert_eq!(output.status.code(), Some(1), "without the CA: {}", stderr(&output));
}

#[test]
fn a_config_file_that_cannot_be_read_is_one_clear_error() {
    let dir = scratch("bad-config");
    let missing = dir.join("missing.json5");
    let broken = config_file(&dir.join("broken.json5"), "{ transport: { auth: ");
    for file in [&missing, &broken] {
        let output = cosim_run_scene(
            &dir.join("out"),
            &run_id("bad-config"),
            &["--zenoh-config", file.to_str().unwrap()],
            Duration::from_secs(30),
        );
        let message = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "{}: {message}", file.display());
        assert_eq!(message.trim().lines().count(), 1, "one line: {message}");
        assert!(message.contains(file.to_str().unwrap()), "names the file: {message}");
        // The router says the same.
        let output = run_bounded(
            Command::new(cosim())
                .args(["router", "--listen", "tcp/127.0.0.1:0", "--zenoh-config"])
                .arg(file),
            Duration::from_secs(30),
        );
        let message = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "router, {}: {message}", file.display());
        assert!(
            message.contains(file.to_str().unwrap()),
            "router names the file: {message}"
        );
    }
}
