//! Run outputs, the files of the run contract (`DESIGN.md` §5):
//!
//! - `DIR/probes.csv`: [`ProbeCsv`], one row per probe sample, flushed row by row;
//! - `DIR/frames/`: [`FrameWriter`], VTK XML unstructured grids (`.vtu`) with a ParaView collection (`.pvd`)
//!   per data set, rewritten after every frame;
//! - `DIR/plots/`: [`plot_probe`], one SVG per probe, with reference data ([`read_reference`]) where the scene
//!   names it.
//!
//! Every error names the file it is about, so the caller can log it in one line and go on.

mod compare;
mod csv;
mod fields;
pub mod folder;
mod frames;
mod plot;
mod pvd;
mod queue;
mod vtk;
mod vtu;

use std::path::{Path, PathBuf};

pub use compare::plot_compare;
pub use csv::ProbeCsv;
pub use fields::{Part, PointField};
pub use frames::FrameWriter;
pub use plot::{plot_probe, read_reference};
pub use pvd::PvdCollection;
pub use queue::{FrameJob, FrameQueue};
pub use vtk::von_mises_2d;

/// An output file could not be written, or an input to it was unusable. Each variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// Reading or writing the file failed.
    #[error("{}: {error}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The OS error. In the message, not a `source`: an error chain printed whole (`{:#}`) says it once.
        error: std::io::Error,
    },
    /// The VTK library could not encode a frame.
    #[error("{}: VTK: {message}", path.display())]
    Vtk {
        /// The frame file.
        path: PathBuf,
        /// vtkio's message.
        message: String,
    },
    /// The plotting library could not draw a plot.
    #[error("{}: plot: {message}", path.display())]
    Plot {
        /// The plot file.
        path: PathBuf,
        /// plotters' message.
        message: String,
    },
    /// A reference data file is malformed (missing column, unparsable number).
    #[error("{}: reference data: {message}", path.display())]
    Reference {
        /// The reference CSV file.
        path: PathBuf,
        /// What is wrong, with the line where there is one.
        message: String,
    },
    /// The data handed in for a file is inconsistent (array lengths, element sizes, column names).
    #[error("{}: {message}", path.display())]
    Input {
        /// The file that was to be written.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// Result of the output functions.
pub type Result<T, E = OutputError> = std::result::Result<T, E>;

impl OutputError {
    pub(crate) fn io(path: &Path, error: std::io::Error) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            error,
        }
    }

    pub(crate) fn input(path: &Path, message: impl Into<String>) -> Self {
        Self::Input {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}

/// Write `bytes` to `path` through a temporary sibling and a rename, so that a reader (or a run that dies
/// mid-write) sees either the old file or the new one, never a torn one. A write that fails (a full disk) removes
/// the temporary file and names `path`.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    with_temporary(path, |tmp| std::fs::write(tmp, bytes))
}

/// `path` with `.tmp` appended: where [`write_atomic`] and the frame writer put a file before renaming it.
pub(crate) fn temporary(path: &Path) -> PathBuf {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    PathBuf::from(tmp)
}

/// Write `path` by `write`-ing its [`temporary`] sibling, then renaming it. When either fails, the temporary file
/// is removed (a full disk leaves no stray `.tmp` behind) and the error names `path`.
pub(crate) fn with_temporary(path: &Path, write: impl FnOnce(&Path) -> std::io::Result<()>) -> Result<()> {
    let tmp = temporary(path);
    write(&tmp).and_then(|()| std::fs::rename(&tmp, path)).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        OutputError::io(path, e)
    })
}

/// Write `bytes` to `path` in one go (a plot: nothing reads it during the run); a write that fails (a full disk)
/// removes the torn file and names `path`.
pub(crate) fn write_whole(path: &Path, bytes: &[u8]) -> Result<()> {
    std::fs::write(path, bytes).map_err(|e| {
        let _ = std::fs::remove_file(path);
        OutputError::io(path, e)
    })
}

/// A fresh, empty folder under the system temp dir for one test.
#[cfg(test)]
pub(crate) fn test_dir(name: &str) -> PathBuf {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("cosim-output-{}-{name}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
