//! Shared helpers of the end-to-end tests: run the real binaries with a bounded wait.
#![allow(dead_code)]

use std::io::Read;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The `cosim` binary under test; its siblings (`fem-node`, `contact-broker`) sit in the same folder.
pub fn cosim() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_cosim"))
}

/// Folder of the built programs.
pub fn bin_dir() -> PathBuf {
    cosim().parent().unwrap().to_path_buf()
}

/// A sibling program, which must have been built (`cargo build --release` before `cargo test --release`).
pub fn program(name: &str) -> PathBuf {
    let p = bin_dir().join(name);
    assert!(
        p.is_file(),
        "{} is missing: run `cargo build --release` before the tests",
        p.display()
    );
    p
}

/// The workspace root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

/// A fresh empty folder for one test (`cosim-test-<name>-<pid>` under the temp dir), removed when the test passes
/// and kept for a look when it panics: a suite run would otherwise leave ~1 GB of runs under the temp dir each time.
pub fn scratch(name: &str) -> Scratch {
    let path = std::env::temp_dir().join(format!("cosim-test-{}-{}", name, std::process::id()));
    let _ = std::fs::remove_dir_all(&path);
    std::fs::create_dir_all(&path).unwrap();
    Scratch {
        root: path.clone(),
        path,
    }
}

/// A test's folder (see [`scratch`]); it reads as the `Path` it holds.
pub struct Scratch {
    /// What is removed.
    root: PathBuf,
    /// What it reads as: `root` or a folder in it.
    path: PathBuf,
}

impl Scratch {
    /// The folder `name` in this one (not created), removed with it.
    pub fn child(mut self, name: &str) -> Scratch {
        self.path = self.path.join(name);
        self
    }
}

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.path
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.path
    }
}

impl AsRef<std::ffi::OsStr> for Scratch {
    fn as_ref(&self) -> &std::ffi::OsStr {
        self.path.as_os_str()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.root);
        }
    }
}

/// Run a command, killing it after `limit`; panics on a timeout so no test can hang. The command runs in its own
/// process group, and a timeout kills the whole group: `cosim run` and the nodes it started, none left behind.
/// Its stdout and stderr are read while it runs: a command that writes more than a pipe holds (`cosim inspect`
/// following a slow run prints a table every interval) would otherwise block on the write and never finish.
pub fn run_bounded(cmd: &mut Command, limit: Duration) -> Output {
    let mut child = cmd
        .process_group(0)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let drain = |pipe: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            if let Some(mut pipe) = pipe {
                let _ = pipe.read_to_end(&mut bytes);
            }
            bytes
        })
    };
    let stdout = drain(child.stdout.take().map(|p| Box::new(p) as Box<dyn Read + Send>));
    let stderr = drain(child.stderr.take().map(|p| Box::new(p) as Box<dyn Read + Send>));
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return Output {
                status,
                stdout: stdout.join().unwrap(),
                stderr: stderr.join().unwrap(),
            };
        }
        if start.elapsed() > limit {
            let group = format!("-{}", child.id());
            let _ = Command::new("kill").args(["-KILL", "--", &group]).status();
            let _ = child.kill();
            let _ = child.wait();
            panic!(
                "{cmd:?} did not finish within {limit:?}; stderr: {}",
                String::from_utf8_lossy(&stderr.join().unwrap())
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// `cosim ARGS` with a bounded wait.
pub fn cosim_run(args: &[&str], limit: Duration) -> Output {
    run_bounded(Command::new(cosim()).args(args).env("COSIM_BIN_DIR", bin_dir()), limit)
}

/// Bound on one `cosim` command of [`run_ok`].
pub const RUN_LIMIT: Duration = Duration::from_secs(240);

/// `cosim ARGS` from the workspace root (so scene paths may be relative to it), bounded by [`RUN_LIMIT`]; fails the
/// test, with the command and its output, unless it succeeds.
pub fn run_ok(args: &[&str]) -> Output {
    let mut cmd = Command::new(cosim());
    cmd.current_dir(root()).args(args).env("COSIM_BIN_DIR", bin_dir());
    let out = run_bounded(&mut cmd, RUN_LIMIT);
    assert!(
        out.status.success(),
        "cosim {} failed: {}{}",
        args.join(" "),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A unique run id per test.
pub fn run_id(name: &str) -> String {
    format!("t{}-{}", std::process::id(), name)
}

/// Read a JSON file.
pub fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))).unwrap()
}

/// A free TCP port on loopback (nobody listens on it once this returns).
pub fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

/// A child process that is killed (and reaped) when dropped, so a test that fails leaves nothing running.
pub struct Kill(pub std::process::Child);

impl Drop for Kill {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Wait for `child` to exit, at most until `until`; panics naming `what` otherwise.
pub fn wait_exit(child: &mut std::process::Child, until: Instant, what: &str) -> std::process::ExitStatus {
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s;
        }
        assert!(Instant::now() < until, "{what} did not finish in time");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Data rows of `DIR/probes.csv` written so far.
pub fn samples(out: &Path) -> usize {
    std::fs::read_to_string(out.join("probes.csv")).map_or(0, |t| t.lines().skip(1).count())
}

/// Wait until the run writing to `out` has `n` probe samples; panics if it ends first or takes over `limit`.
pub fn wait_for_samples(run: &mut std::process::Child, out: &Path, n: usize, limit: Duration) {
    let started = Instant::now();
    while samples(out) < n {
        assert!(run.try_wait().unwrap().is_none(), "the run ended early");
        assert!(started.elapsed() < limit, "the run did not get going");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// `cosim router --listen ENDPOINT [--zenoh-config FILE]` as its own process, with its stderr in `log`; returns
/// once it prints that it listens (within 20 s, else panics), with the endpoints it printed. Killed when dropped.
pub fn start_router(endpoint: &str, zenoh_config: Option<&Path>, log: &Path) -> (Kill, Vec<String>) {
    use std::io::BufRead;
    let mut cmd = Command::new(cosim());
    cmd.args(["router", "--listen", endpoint]);
    if let Some(file) = zenoh_config {
        cmd.arg("--zenoh-config").arg(file);
    }
    let mut router = Kill(
        cmd.stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(std::fs::File::create(log).unwrap())
            .spawn()
            .unwrap(),
    );
    let stdout = router.0.stdout.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut line = String::new();
        let _ = std::io::BufReader::new(stdout).read_line(&mut line);
        let _ = tx.send(line);
    });
    let line = rx.recv_timeout(Duration::from_secs(20)).unwrap_or_default();
    let v: serde_json::Value = serde_json::from_str(&line).unwrap_or_else(|_| {
        panic!(
            "cosim router did not say it listens (stdout {line:?}); stderr: {}",
            std::fs::read_to_string(log).unwrap_or_default()
        )
    });
    assert_eq!(v["event"], "listening", "{line}");
    let endpoints = v["endpoints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_str().unwrap().to_string())
        .collect();
    (router, endpoints)
}

/// The pids and program names of `pid`'s children.
pub fn children(pid: u32) -> Vec<(u32, String)> {
    let mut out = Vec::new();
    for task in std::fs::read_dir(format!("/proc/{pid}/task"))
        .into_iter()
        .flatten()
        .flatten()
    {
        let list = std::fs::read_to_string(task.path().join("children")).unwrap_or_default();
        for child in list.split_whitespace().filter_map(|c| c.parse::<u32>().ok()) {
            let name = std::fs::read_to_string(format!("/proc/{child}/comm")).unwrap_or_default();
            out.push((child, name.trim().to_string()));
        }
    }
    out
}

/// Whether `pid` is still a live process (not gone, not a zombie).
pub fn alive(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat"))
        .map(|s| s.rsplit_once(") ").is_some_and(|(_, rest)| !rest.starts_with('Z')))
        .unwrap_or(false)
}

/// A valid structure-only scene (a clamped beam with a tip probe); tests of bad input edit one thing of it.
pub const BEAM_SCENE: &str = r#"
version = 1
[run]
name = "bad"
end_time = 0.01
output_interval = 0.005
[[solid]]
name = "beam"
min = [0.0, 0.0]
max = [0.1, 0.01]
divisions = [10, 2]
material = { model = "linear_elastic", density = 1000.0, youngs_modulus = 1.0e6, poisson_ratio = 0.3 }
fixed = [{ min = [-0.001, -0.001], max = [0.001, 0.011] }]
[[probe]]
name = "tip"
kind = "node_displacement"
solid = "beam"
point = [0.1, 0.005]
component = "y"
"#;

/// Write `text` as `<name>.toml` in a fresh folder `<prefix>-<name>` ([`scratch`]); its path, removed with the
/// folder when the test passes.
pub fn write_scene(prefix: &str, name: &str, text: &str) -> Scratch {
    let path = scratch(&format!("{prefix}-{name}")).child(&format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}
