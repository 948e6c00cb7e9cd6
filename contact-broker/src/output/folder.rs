//! Whose folder a run writes into. A run clears `frames/`, `plots/` and `logs/` of its output folder (`cosim run`)
//! and writes `summary.json`, `probes.csv` and `scene.toml` over what is there, so it takes only a folder that is
//! new, empty, or an earlier run's (found 2026-12-06: `--out /tmp/proj` deleted `proj/logs/notes.txt`, and
//! `--out /` wrote into the root).

use std::path::Path;

/// An output folder that holds someone's own files: bad input (exit 2), said in one line.
#[derive(Debug, thiserror::Error)]
#[error(
    "--out {folder}: the folder holds {holds} and no summary.json of a run; a run clears frames/, plots/ and logs/ \
         of its folder and writes its files over what is there, so it writes only into a new or empty folder, or an \
         earlier run's"
)]
pub struct ForeignFolder {
    /// The folder.
    pub folder: String,
    /// Up to three of its entries.
    pub holds: String,
}

/// Refuse `out` where it holds anything but an earlier run's outputs: it exists, holds entries other than
/// `beside` (what the caller wrote there itself, e.g. a bench case's log), and no run's `summary.json` (every run
/// writes one before anything else). The message names the folder and up to three of its entries.
pub fn refuse_foreign(out: &Path, beside: &[&str]) -> Result<(), ForeignFolder> {
    let Ok(entries) = std::fs::read_dir(out) else {
        return Ok(());
    };
    let mut names: Vec<String> = entries
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| !beside.contains(&n.as_str()))
        .collect();
    names.sort();
    if names.is_empty() || is_run_summary(&out.join("summary.json")) {
        return Ok(());
    }
    let mut shown: Vec<String> = names.iter().take(3).map(|n| format!("`{n}`")).collect();
    if names.len() > 3 {
        shown.push(format!("{} more", names.len() - 3));
    }
    Err(ForeignFolder {
        folder: out.display().to_string(),
        holds: shown.join(", "),
    })
}

/// Whether `path` is a run's `summary.json` (a JSON object with its `run_id` and `status`).
fn is_run_summary(path: &Path) -> bool {
    let Ok(text) = std::fs::read_to_string(path) else {
        return false;
    };
    serde_json::from_str::<serde_json::Value>(&text)
        .is_ok_and(|v| v.get("run_id").is_some_and(|r| r.is_string()) && v.get("status").is_some())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_new_empty_or_earlier_runs_folders_are_taken() {
        let dir = super::super::test_dir("folder-rule");
        let _ = std::fs::remove_dir_all(&dir);
        assert!(refuse_foreign(&dir.join("new"), &[]).is_ok());
        std::fs::create_dir_all(dir.join("mine/logs")).unwrap();
        let err = refuse_foreign(&dir.join("mine"), &[]).unwrap_err().to_string();
        assert!(
            err.contains("mine: the folder holds `logs` and no summary.json of a run"),
            "{err}"
        );
        assert!(refuse_foreign(&dir.join("mine"), &["logs"]).is_ok());
        std::fs::write(dir.join("mine/summary.json"), r#"{"run_id": "r1", "status": "ok"}"#).unwrap();
        assert!(refuse_foreign(&dir.join("mine"), &[]).is_ok());
        std::fs::write(dir.join("mine/summary.json"), "{}").unwrap();
        assert!(refuse_foreign(&dir.join("mine"), &[]).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
