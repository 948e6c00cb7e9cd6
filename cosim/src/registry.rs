//! Where `cosim inspect ID` finds a run started on this machine: `cosim run` (processes mode) writes
//! `$TMPDIR/cosim-runs/<ID>.json` with the endpoint to join once the broker listens, and removes it when the run
//! ends. A run on another host is inspected with `--connect` instead. `cosim inspect` without an id lists the runs
//! registered here whose `cosim run` is alive.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// How to join a running run.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Entry {
    /// Run id.
    pub run: String,
    /// Endpoint to connect to: the broker's, or the router's.
    pub connect: String,
    /// Join as a zenoh client (the run goes through a router).
    pub client: bool,
    /// The run's zenoh config file (`--zenoh-config`), which the inspector needs too (credentials, certificates).
    #[serde(default)]
    pub zenoh_config: Option<PathBuf>,
    /// Output folder.
    pub out: PathBuf,
    /// Process id of `cosim run`.
    pub pid: u32,
    /// The scene's `run.name` (absent in an entry an older `cosim run` wrote).
    #[serde(default)]
    pub scene: Option<String>,
    /// When the run registered, in seconds since the Unix epoch (absent as `scene`).
    #[serde(default)]
    pub since: Option<u64>,
}

/// Seconds since the Unix epoch now (`Entry::since`); `None` with a clock set before it.
pub fn now() -> Option<u64> {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .ok()
        .map(|d| d.as_secs())
}

/// The folder of the entries.
pub fn dir() -> PathBuf {
    std::env::temp_dir().join("cosim-runs")
}

fn path(run: &str) -> PathBuf {
    dir().join(format!("{run}.json"))
}

/// An entry on disk, removed when dropped.
pub struct Registration(PathBuf);

impl Drop for Registration {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// Write the entry (best effort: a run that cannot register still runs; it is then inspected with `--connect`).
pub fn register(entry: &Entry) -> Option<Registration> {
    let file = path(&entry.run);
    let write = || -> std::io::Result<()> {
        std::fs::create_dir_all(dir())?;
        let tmp = file.with_extension("json.tmp");
        std::fs::write(&tmp, serde_json::to_vec_pretty(entry)?)?;
        std::fs::rename(&tmp, &file)
    };
    match write() {
        Ok(()) => Some(Registration(file)),
        Err(e) => {
            tracing::debug!("cannot register run {} in {}: {e}", entry.run, dir().display());
            None
        }
    }
}

/// The entry of `run`, if one is registered and its `cosim run` is still alive.
pub fn lookup(run: &str) -> Option<Entry> {
    read(&path(run))
}

/// Every run registered here whose `cosim run` is alive, by run id. An entry left by a `cosim run` that was killed
/// (it could not remove it) is not listed.
pub fn live() -> Vec<Entry> {
    let Ok(files) = std::fs::read_dir(dir()) else {
        return Vec::new();
    };
    let mut runs: Vec<Entry> = files
        .flatten()
        .map(|f| f.path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .filter_map(|p| read(&p))
        .collect();
    runs.sort_by(|a, b| a.run.cmp(&b.run));
    runs
}

/// The entry in `file`, if it reads as one and its `cosim run` is still alive.
fn read(file: &Path) -> Option<Entry> {
    let entry: Entry = serde_json::from_slice(&std::fs::read(file).ok()?).ok()?;
    Path::new(&format!("/proc/{}", entry.pid)).exists().then_some(entry)
}
