//! Checkpoints of a run (`cosim run --checkpoint-interval T`) and restarts from them (`cosim run SCENE --restart
//! DIR/checkpoints/<step>`).
//!
//! A checkpoint is taken between two coupling steps, when every node has answered step `step` and the contact
//! corrections of that step are computed but not yet sent. It is a folder `DIR/checkpoints/<step>/`:
//!
//! - `checkpoint.json`: the manifest ([`Manifest`]): format and protocol version, run id, step, t, and the size and
//!   CRC-32 of every other file;
//! - `scene.toml`: the resolved scene the run was started with;
//! - `broker.bin`: the coordinator's state ([`BrokerState`]): time, step, the pending corrections, the probe rows
//!   so far, the summary's counters;
//! - `fem.bin`, `sph.bin`: each node's own state, as the node saved it (opaque here, `docs/PROTOCOL.md` §9).
//!
//! The folder is written under a temporary name (`.<step>.<pid>.partial`, so that two runs writing into one
//! folder by mistake do not write into each other's), each file and the folder are flushed to the disk
//! (`fsync`), and only then is it renamed: a run, or a machine, that dies while it writes never leaves a half
//! checkpoint that looks whole. [`open`] reads every file once and checks its size and checksum against the
//! manifest before it looks inside any, so a checkpoint damaged afterwards (a copy cut short, a full disk, a changed
//! byte) is refused naming the file; what it then decodes from `broker.bin` is checked as well
//! ([`BrokerState::check`]). Pure: files only, no messaging.

mod broker_state;
pub mod restore_reply;

use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use cosim_proto::envelope::PROTOCOL_VERSION;
use cosim_proto::scene::LoadedScene;
use serde::{Deserialize, Serialize};

pub use broker_state::BrokerState;

/// Version of the checkpoint folder's layout and of `broker.bin`. 2: the manifest holds each file's CRC-32; 3: the
/// interface_load probes' impulse since the last sample (`BrokerState::load_log`); 4: the contact impulse owed to the
/// structure (`BrokerState::owed`); 5: the contact's bound on the coupling step (`BrokerState::dt_contact`); 6: the
/// run's energy balance (`Summary::energy_growth`); 7: the structure's bound on the coupling step
/// (`BrokerState::dt_structure`); 8: the positions a WCSPH fluid's Verlet candidates were gathered at (in `sph.bin`);
/// 9: the energy balance's rounding (`EnergyGrowth::rounding`); 10: the first structure node found inside a wall
/// (`Summary::solid_in_wall`).
pub const FORMAT: u32 = 10;
/// The manifest's file name.
pub const MANIFEST: &str = "checkpoint.json";
const TAG: &str = "cosim-broker-checkpoint";
/// The files a checkpoint folder may hold besides the manifest.
const FILES: [&str; 4] = ["scene.toml", "broker.bin", "fem.bin", "sph.bin"];

/// `checkpoint.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// [`FORMAT`] of the writer.
    pub format: u32,
    /// Wire protocol version of the writer (`cosim_proto::envelope::PROTOCOL_VERSION`).
    pub protocol_version: u32,
    /// Run that wrote it.
    pub run_id: String,
    /// Scene name (`run.name`).
    pub scene: String,
    /// Coupling steps completed.
    pub step: u64,
    /// Simulated time reached [s].
    pub t: f64,
    /// Every other file of the folder, by name.
    pub files: BTreeMap<String, FileEntry>,
    /// Seconds it took to gather the nodes' states and write the folder.
    pub write_seconds: f64,
}

/// One file of a checkpoint as the manifest records it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FileEntry {
    /// Size [bytes].
    pub bytes: u64,
    /// CRC-32 (IEEE, as zlib and `crc32fast` compute it) of the whole file: 8 lowercase hex digits.
    pub crc32: String,
}

impl FileEntry {
    /// The entry of `bytes`.
    pub fn of(bytes: &[u8]) -> Self {
        Self {
            bytes: bytes.len() as u64,
            crc32: crc32_hex(bytes),
        }
    }
}

/// CRC-32 of `bytes` as 8 lowercase hex digits.
fn crc32_hex(bytes: &[u8]) -> String {
    format!("{:08x}", crc32fast::hash(bytes))
}

/// A checkpoint read back and checked against the scene of the run that continues from it.
#[derive(Debug)]
pub struct Restart {
    /// The folder.
    pub dir: PathBuf,
    /// Its manifest.
    pub manifest: Manifest,
    /// The coordinator's state.
    pub broker: BrokerState,
    /// The structure node's state, when the scene has one.
    pub fem: Option<Vec<u8>>,
    /// The fluid node's state, when the scene has one.
    pub sph: Option<Vec<u8>>,
}

/// What [`write`] did.
#[derive(Clone, Debug)]
pub struct Written {
    /// The checkpoint folder.
    pub dir: PathBuf,
    /// Bytes written.
    pub bytes: u64,
    /// Seconds it took to write (the nodes' states included, when `started` was taken before gathering them).
    pub seconds: f64,
}

/// Refuse a `--checkpoint-interval` that is not a positive number of seconds.
pub fn check_interval(interval: Option<f64>) -> anyhow::Result<()> {
    if let Some(i) = interval {
        anyhow::ensure!(
            i.is_finite() && i > 0.0,
            "--checkpoint-interval must be a positive number of seconds, got {}",
            cosim_proto::Num(i)
        );
    }
    Ok(())
}

/// Write `out/checkpoints/<step>/`. `nodes` are `("fem", bytes)` and/or `("sph", bytes)`; `started` is when the
/// checkpoint began (before the nodes were asked), for the manifest's `write_seconds`.
pub fn write(
    out: &Path,
    run_id: &str,
    scene: &LoadedScene,
    state: &BrokerState,
    nodes: &[(&str, Vec<u8>)],
    started: Instant,
) -> anyhow::Result<Written> {
    let root = out.join("checkpoints");
    let dir = root.join(state.step.to_string());
    let tmp = root.join(format!(".{}.{}.partial", state.step, std::process::id()));
    if tmp.exists() {
        std::fs::remove_dir_all(&tmp).with_context(|| format!("cannot clear {}", tmp.display()))?;
    }
    std::fs::create_dir_all(&tmp).with_context(|| format!("cannot create {}", tmp.display()))?;
    let mut files = BTreeMap::new();
    let mut put = |name: &str, bytes: &[u8]| -> anyhow::Result<()> {
        let path = tmp.join(name);
        write_synced(&path, bytes).with_context(|| format!("cannot write {}", path.display()))?;
        files.insert(name.to_string(), FileEntry::of(bytes));
        Ok(())
    };
    put("scene.toml", scene.scene.to_toml().as_bytes())?;
    let broker = bincode::serialize(&(TAG, FORMAT, state)).expect("in-memory bincode encoding of plain data");
    put("broker.bin", &broker)?;
    for (node, bytes) in nodes {
        put(&format!("{node}.bin"), bytes)?;
    }
    let mut manifest = Manifest {
        format: FORMAT,
        protocol_version: PROTOCOL_VERSION,
        run_id: run_id.to_string(),
        scene: scene.scene.run.name.clone(),
        step: state.step,
        t: state.t,
        files,
        write_seconds: 0.0,
    };
    manifest.write_seconds = started.elapsed().as_secs_f64();
    let text = serde_json::to_string_pretty(&manifest)? + "\n";
    let path = tmp.join(MANIFEST);
    write_synced(&path, text.as_bytes()).with_context(|| format!("cannot write {}", path.display()))?;
    sync_dir(&tmp)?;
    if dir.exists() {
        std::fs::remove_dir_all(&dir).with_context(|| format!("cannot replace {}", dir.display()))?;
    }
    std::fs::rename(&tmp, &dir).with_context(|| format!("cannot rename {} to {}", tmp.display(), dir.display()))?;
    sync_dir(&root)?;
    Ok(Written {
        bytes: manifest.files.values().map(|f| f.bytes).sum::<u64>() + text.len() as u64,
        dir,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// Write `bytes` to `path` and flush them to the disk before returning.
fn write_synced(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut file = std::fs::File::create(path)?;
    file.write_all(bytes)?;
    file.sync_all()
}

/// Flush a folder's entries (the names of the files in it, a rename) to the disk.
fn sync_dir(dir: &Path) -> anyhow::Result<()> {
    std::fs::File::open(dir)
        .and_then(|d| d.sync_all())
        .with_context(|| format!("cannot flush {} to the disk", dir.display()))
}

/// Read the checkpoint `dir` and check that `scene` may continue from it: same format and protocol version, every
/// file whole (size and CRC-32 of the manifest), the same scene but for `run.end_time` (a restart may run longer or
/// shorter), and a coordinator state that holds together ([`BrokerState::check`]). Every refusal is one line naming
/// the file.
pub fn open(dir: &Path, scene: &LoadedScene) -> anyhow::Result<Restart> {
    let manifest_path = dir.join(MANIFEST);
    let text = std::fs::read_to_string(&manifest_path).with_context(|| {
        format!(
            "{}: not a checkpoint (give a folder DIR/checkpoints/<step> that a run with --checkpoint-interval wrote)",
            manifest_path.display()
        )
    })?;
    let not_manifest =
        |e: serde_json::Error| anyhow::anyhow!("{}: not a checkpoint manifest: {e}", manifest_path.display());
    // The versions first, from the bare JSON: a manifest of another format need not have this one's fields.
    let value: serde_json::Value = serde_json::from_str(&text).map_err(not_manifest)?;
    let version = |key: &str| value.get(key).and_then(serde_json::Value::as_u64);
    let protocol_version = version("protocol_version");
    anyhow::ensure!(
        protocol_version == Some(u64::from(PROTOCOL_VERSION)),
        "{}: written by protocol version {}, this build speaks {PROTOCOL_VERSION}; restart with the build that wrote it",
        manifest_path.display(),
        protocol_version.map_or("(none)".into(), |v| v.to_string())
    );
    let format = version("format");
    anyhow::ensure!(
        format == Some(u64::from(FORMAT)),
        "{}: checkpoint format {}, this build reads format {FORMAT} (format 1 has no checksums); restart with the \
         build that wrote it",
        manifest_path.display(),
        format.map_or("(none)".into(), |v| v.to_string())
    );
    let manifest: Manifest = serde_json::from_value(value).map_err(not_manifest)?;
    anyhow::ensure!(
        scene.scene.run.end_time > manifest.t,
        "{}: the checkpoint is at t = {} s and run.end_time = {} s: nothing to run (set a later run.end_time)",
        manifest_path.display(),
        manifest.t,
        scene.scene.run.end_time
    );
    let files = read_files(dir, &manifest, &manifest_path, scene)?;
    let file = |name: &str| files.get(name).map(Vec::as_slice).unwrap_or_default();

    let scene_path = dir.join("scene.toml");
    let saved_text =
        std::str::from_utf8(file("scene.toml")).with_context(|| format!("{}: not UTF-8 text", scene_path.display()))?;
    let mut saved = cosim_proto::scene::parse(&scene_path.display().to_string(), saved_text, &[])?;
    saved.run.end_time = scene.scene.run.end_time;
    if let Some((ours, theirs)) = first_difference(&scene.scene.to_toml(), &saved.to_toml()) {
        anyhow::bail!(
            "{}: the checkpoint is from another scene: {} has `{ours}` where the checkpoint has `{theirs}` \
             (only run.end_time may differ)",
            scene_path.display(),
            scene.path.display()
        );
    }
    let broker_path = dir.join("broker.bin");
    let (tag, format, broker): (String, u32, BrokerState) = bincode::deserialize(file("broker.bin"))
        .with_context(|| format!("{}: not a broker state", broker_path.display()))?;
    anyhow::ensure!(
        tag == TAG && format == FORMAT,
        "{}: holds `{tag}` format {format}, this build reads `{TAG}` format {FORMAT}",
        broker_path.display()
    );
    anyhow::ensure!(
        broker.step == manifest.step && broker.t.to_bits() == manifest.t.to_bits(),
        "{}: step {} at t = {} does not match {} (step {}, t = {})",
        broker_path.display(),
        broker.step,
        broker.t,
        manifest_path.display(),
        manifest.step,
        manifest.t
    );
    broker
        .check(&scene.scene)
        .map_err(|e| anyhow::anyhow!("{}: {e}", broker_path.display()))?;
    let mut files = files;
    let (fem, sph) = (files.remove("fem.bin"), files.remove("sph.bin"));
    Ok(Restart {
        dir: dir.to_path_buf(),
        fem: fem.filter(|_| !scene.scene.solids.is_empty()),
        sph: sph.filter(|_| scene.scene.fluid.is_some()),
        manifest,
        broker,
    })
}

/// Read every file the manifest lists, once, and check its size and CRC-32 before anything looks inside: the
/// manifest must list exactly the files a checkpoint of `scene` holds (`scene.toml`, `broker.bin`, and `fem.bin` /
/// `sph.bin` when the scene has a structure / a fluid), so that nothing is read unchecked.
fn read_files(
    dir: &Path,
    manifest: &Manifest,
    manifest_path: &Path,
    scene: &LoadedScene,
) -> anyhow::Result<BTreeMap<String, Vec<u8>>> {
    let s = &scene.scene;
    let needed = FILES.iter().filter(|&&name| match name {
        "fem.bin" => !s.solids.is_empty(),
        "sph.bin" => s.fluid.is_some(),
        _ => true,
    });
    for name in needed {
        anyhow::ensure!(
            manifest.files.contains_key(*name),
            "{}: does not list {name}, which a checkpoint of this scene holds",
            manifest_path.display()
        );
    }
    let mut files = BTreeMap::new();
    for (name, entry) in &manifest.files {
        anyhow::ensure!(
            FILES.contains(&name.as_str()),
            "{}: lists `{name}`, which is not a checkpoint file (expected {})",
            manifest_path.display(),
            FILES.join(", ")
        );
        let path = dir.join(name);
        let unreadable = || {
            format!(
                "{}: missing or unreadable, {} lists it",
                path.display(),
                manifest_path.display()
            )
        };
        // A regular file of the size the manifest says, before a byte is read: a link to /dev/zero was read until
        // the memory ran out, and a FIFO held the restart for ever (found 2026-12-06 by a sweep of crafted
        // checkpoints).
        let meta = std::fs::metadata(&path).with_context(unreadable)?;
        anyhow::ensure!(
            meta.is_file(),
            "{}: not a regular file ({}), {} lists it as one",
            path.display(),
            kind_of(&meta.file_type()),
            manifest_path.display()
        );
        anyhow::ensure!(
            meta.len() == entry.bytes,
            "{}: {} bytes where {} says {}: the checkpoint is damaged (cut short or changed)",
            path.display(),
            meta.len(),
            manifest_path.display(),
            entry.bytes
        );
        // At most that size, however the file changes from here on (what it holds is then the checksum's to judge).
        let mut bytes = Vec::new();
        std::fs::File::open(&path)
            .and_then(|f| f.take(entry.bytes).read_to_end(&mut bytes))
            .with_context(unreadable)?;
        let found = crc32_hex(&bytes);
        anyhow::ensure!(
            found == entry.crc32,
            "{}: checksum crc32 {found} where {} expects {}: the checkpoint is damaged (changed after it was written)",
            path.display(),
            manifest_path.display(),
            entry.crc32
        );
        files.insert(name.clone(), bytes);
    }
    Ok(files)
}

/// The first line that differs between two texts, `(ours, theirs)`; `None` when they are equal.
fn first_difference(ours: &str, theirs: &str) -> Option<(String, String)> {
    let (mut a, mut b) = (ours.lines(), theirs.lines());
    // The section a line is in, so that `spacing = …` reads as `[fluid] spacing = …`.
    let mut section = String::new();
    loop {
        match (a.next(), b.next()) {
            (None, None) => return None,
            (x, y) if x == y => {
                let line = x.unwrap_or_default().trim();
                if line.starts_with('[') {
                    section = format!("{line} ");
                }
            }
            (x, y) => {
                let show = |l: Option<&str>| match l.map(str::trim) {
                    None => "(end of scene)".to_string(),
                    Some(l) if l.starts_with('[') => l.to_string(),
                    Some(l) => format!("{section}{l}"),
                };
                return Some((show(x), show(y)));
            }
        }
    }
}

/// What a path that is not a regular file is, in a message.
fn kind_of(t: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    match () {
        _ if t.is_dir() => "a folder",
        _ if t.is_fifo() => "a FIFO",
        _ if t.is_char_device() => "a character device",
        _ if t.is_block_device() => "a block device",
        _ if t.is_socket() => "a socket",
        _ => "not a file",
    }
}

#[cfg(test)]
mod tests {
    use super::first_difference;

    #[test]
    fn first_difference_names_the_line() {
        assert_eq!(first_difference("a = 1\nb = 2\n", "a = 1\nb = 2\n"), None);
        assert_eq!(
            first_difference("[run]\na = 1\nb = 2\n", "[run]\na = 1\nb = 3\n"),
            Some(("[run] b = 2".into(), "[run] b = 3".into()))
        );
        assert_eq!(
            first_difference("a = 1\n", "a = 1\nc = 0\n"),
            Some(("(end of scene)".into(), "c = 0".into()))
        );
    }
}
