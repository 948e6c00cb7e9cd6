//! `DIR/probes.csv`: header `t,<probe names…>`, one row per probe sample.
//!
//! Each row is written with one `write_all` on an unbuffered file as soon as it is pushed, so a run that dies
//! keeps every sample taken. A row that cannot be written whole (a full disk) is cut off again, so the file never
//! ends in a torn row. Numbers use Rust's shortest round-trip formatting of `f64` (`{}`, or `{:e}` below
//! 1e-4 and from 1e15): parsing a field back gives the same bits, and the same run gives the same bytes.

use std::fs::File;
use std::io::{Seek as _, SeekFrom, Write as _};
use std::path::{Path, PathBuf};

use super::{OutputError, Result};

/// The probe table of a run, on disk and in memory (for the plots at the end).
#[derive(Debug)]
pub struct ProbeCsv {
    path: PathBuf,
    file: File,
    /// Bytes of whole rows (and the header) written.
    len: u64,
    names: Vec<String>,
    rows: Vec<(f64, Vec<f64>)>,
}

impl ProbeCsv {
    /// Create (or truncate) `path`, its folder if needed, and write the header `t,<names…>`.
    ///
    /// Names must be non-empty, distinct, not `t`, and free of `,`, `"` and line breaks (no quoting is done).
    pub fn create(path: &Path, names: &[String]) -> Result<Self> {
        for (i, name) in names.iter().enumerate() {
            if name.is_empty() || name.contains([',', '"', '\n', '\r']) {
                return Err(OutputError::input(
                    path,
                    format!("probe name {name:?} cannot be a CSV column name"),
                ));
            }
            if name == "t" || names[..i].contains(name) {
                return Err(OutputError::input(path, format!("column `{name}` appears twice")));
            }
        }
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| OutputError::io(dir, e))?;
        }
        let mut file = File::create(path).map_err(|e| OutputError::io(path, e))?;
        let mut header = String::from("t");
        for name in names {
            header.push(',');
            header.push_str(name);
        }
        header.push('\n');
        file.write_all(header.as_bytes())
            .map_err(|e| OutputError::io(path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
            len: header.len() as u64,
            names: names.to_vec(),
            rows: Vec::new(),
        })
    }

    /// Append the sample at time `t`: one value per probe, in the order of the names.
    pub fn push(&mut self, t: f64, values: &[f64]) -> Result<()> {
        if values.len() != self.names.len() {
            return Err(OutputError::input(
                &self.path,
                format!("{} values for {} probes at t = {t}", values.len(), self.names.len()),
            ));
        }
        let row = format_row(t, values);
        if let Err(e) = self.file.write_all(row.as_bytes()) {
            // Back to the last whole row; the error is the one to report, whatever this does.
            let _ = self.file.set_len(self.len);
            let _ = self.file.seek(SeekFrom::Start(self.len));
            return Err(OutputError::io(&self.path, e));
        }
        self.len += row.len() as u64;
        self.rows.push((t, values.to_vec()));
        Ok(())
    }

    /// Every row pushed so far: time and the probe values.
    pub fn rows(&self) -> &[(f64, Vec<f64>)] {
        &self.rows
    }

    /// Probe names (the columns after `t`).
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The CSV file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// One probe's samples `(t, value)`, for its plot; `None` for an unknown name.
    pub fn series(&self, name: &str) -> Option<Vec<(f64, f64)>> {
        let k = self.names.iter().position(|n| n == name)?;
        Some(self.rows.iter().map(|(t, v)| (*t, v[k])).collect())
    }
}

fn format_row(t: f64, values: &[f64]) -> String {
    let mut line = String::with_capacity(24 * (values.len() + 1));
    write_number(&mut line, t);
    for &v in values {
        line.push(',');
        write_number(&mut line, v);
    }
    line.push('\n');
    line
}

/// Shortest round-trip digits; plain decimals for ordinary magnitudes, exponent form for tiny or huge ones (so
/// 6e-26 is not written as 26 zeros).
fn write_number(line: &mut String, v: f64) {
    use std::fmt::Write as _;
    let plain = v == 0.0 || !v.is_finite() || (1e-4..1e15).contains(&v.abs());
    let _ = if plain {
        write!(line, "{v}")
    } else {
        write!(line, "{v:e}")
    };
}

#[cfg(test)]
mod tests {
    use super::super::test_dir;
    use super::*;

    #[test]
    fn values_round_trip_bit_for_bit() {
        let dir = test_dir("csv");
        let path = dir.join("probes.csv");
        let names = vec!["tip_x".to_string(), "front".to_string()];
        let mut csv = ProbeCsv::create(&path, &names).unwrap();
        let samples = [
            (0.0, [0.0, -0.0]),
            (0.1 + 0.2, [1.0 / 3.0, -2.5e-13]),
            (1e-5, [f64::MAX, f64::MIN_POSITIVE]),
            (0.015, [123456.789e10, std::f64::consts::PI]),
        ];
        for (t, v) in samples {
            csv.push(t, &v).unwrap();
        }
        // Written row by row: the file is complete before the writer is dropped.
        let text = std::fs::read_to_string(&path).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("t,tip_x,front"));
        for (line, (t, v)) in lines.zip(samples) {
            let fields: Vec<f64> = line.split(',').map(|f| f.parse().unwrap()).collect();
            assert_eq!(fields.len(), 3);
            assert_eq!(fields[0].to_bits(), t.to_bits());
            assert_eq!(fields[1].to_bits(), v[0].to_bits());
            assert_eq!(fields[2].to_bits(), v[1].to_bits());
        }
        assert_eq!(text.lines().count(), 5);
        assert_eq!(csv.rows().len(), 4);
        assert_eq!(csv.series("front").unwrap()[1], (0.1 + 0.2, -2.5e-13));
        drop(csv);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn same_samples_give_the_same_bytes() {
        let dir = test_dir("csv-repro");
        let names = vec!["a".to_string()];
        let write = |p: &Path| {
            let mut c = ProbeCsv::create(p, &names).unwrap();
            for i in 0..50 {
                let t = i as f64 * 0.005;
                c.push(t, &[(t * 7.0).sin()]).unwrap();
            }
        };
        write(&dir.join("1.csv"));
        write(&dir.join("2.csv"));
        assert_eq!(
            std::fs::read(dir.join("1.csv")).unwrap(),
            std::fs::read(dir.join("2.csv")).unwrap()
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_names_and_row_lengths_are_errors_naming_the_file() {
        let dir = test_dir("csv-bad");
        let path = dir.join("probes.csv");
        for names in [
            vec!["a,b".to_string()],
            vec!["t".to_string()],
            vec!["a".into(), "a".into()],
        ] {
            assert!(ProbeCsv::create(&path, &names)
                .unwrap_err()
                .to_string()
                .contains("probes.csv"));
        }
        let mut c = ProbeCsv::create(&path, &["a".to_string()]).unwrap();
        let e = c.push(0.0, &[1.0, 2.0]).unwrap_err().to_string();
        assert!(e.contains("probes.csv") && e.contains("2 values"), "{e}");
        assert!(c.rows().is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
