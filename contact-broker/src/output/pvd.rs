//! ParaView collection files (`.pvd`): a list of `(time, file)` pairs that ParaView opens as one time series.
//!
//! vtkio has no collection type, and the format is five lines of XML, so it is written here.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};

use super::{write_atomic, OutputError, Result};

/// Everything before the entries.
const HEAD: &str = concat!(
    "<?xml version=\"1.0\"?>\n",
    "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n",
    "  <Collection>\n"
);
/// Everything after them.
const FOOT: &str = "  </Collection>\n</VTKFile>\n";

/// A `.pvd` collection, valid on disk after every added entry, so that a run that dies keeps a file listing every
/// frame written so far. A new entry is written in place over the closing tags, with them after it, in one write
/// (a run of n frames writes O(n) bytes of collection, not the O(n²) of rewriting it whole each time); the file is
/// rewritten whole, atomically, when an entry changes or the file is not as this collection left it.
#[derive(Clone, Debug)]
pub struct PvdCollection {
    path: PathBuf,
    entries: Vec<(f64, String)>,
    /// Where each file is in `entries`.
    index: HashMap<String, usize>,
    /// The file's length as this collection last wrote it; `None` before it wrote it.
    written: Option<u64>,
}

impl PvdCollection {
    /// An empty collection that will be written to `path` (nothing is written until [`push`](Self::push)).
    pub fn new(path: impl Into<PathBuf>) -> Self {
        Self {
            path: path.into(),
            entries: Vec::new(),
            index: HashMap::new(),
            written: None,
        }
    }

    /// A collection that starts with `entries` (a run continuing from a checkpoint keeps the frames before it);
    /// written at once when there are any, so the file lists them even before the next frame.
    pub fn with_entries(path: impl Into<PathBuf>, entries: Vec<(f64, String)>) -> Result<Self> {
        let mut c = Self::new(path);
        for (t, file) in entries {
            match c.index.get(&file) {
                Some(&i) => c.entries[i].0 = t,
                None => {
                    c.index.insert(file.clone(), c.entries.len());
                    c.entries.push((t, file));
                }
            }
        }
        if !c.entries.is_empty() {
            c.rewrite()?;
        }
        Ok(c)
    }

    /// Path of the `.pvd` file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Entries so far: time and file name relative to the `.pvd`'s folder.
    pub fn entries(&self) -> &[(f64, String)] {
        &self.entries
    }

    /// Add the data set `file` (relative to the `.pvd`'s folder) at time `t`, then write the collection.
    /// Adding a file already listed replaces its entry (a frame written again).
    pub fn push(&mut self, t: f64, file: &str) -> Result<()> {
        if !t.is_finite() {
            return Err(OutputError::input(
                &self.path,
                format!("time {t} of `{file}` is not finite"),
            ));
        }
        if let Some(&i) = self.index.get(file) {
            self.entries[i].0 = t;
            return self.rewrite();
        }
        self.index.insert(file.to_string(), self.entries.len());
        self.entries.push((t, file.to_string()));
        let line = line(t, file);
        match self.written.map(|len| self.append_in_place(len, &line)) {
            Some(Ok(len)) => {
                self.written = Some(len);
                Ok(())
            }
            // Not written yet, changed by someone else, or the write failed (the file was put back as it was):
            // whole, atomically (which names the path if it fails too).
            _ => self.rewrite(),
        }
    }

    /// Writes `line` and the closing tags over the closing tags of the file of length `len`, when its length and
    /// closing tags are those this collection wrote; the new length. A failed write is undone.
    fn append_in_place(&self, len: u64, line: &str) -> std::io::Result<u64> {
        let unlike = || std::io::Error::other("not as this collection wrote it");
        let file = std::fs::OpenOptions::new().read(true).write(true).open(&self.path)?;
        let at = len.checked_sub(FOOT.len() as u64).ok_or_else(unlike)?;
        let mut tail = [0u8; FOOT.len()];
        if file.metadata()?.len() != len {
            return Err(unlike());
        }
        file.read_exact_at(&mut tail, at)?;
        if tail != FOOT.as_bytes() {
            return Err(unlike());
        }
        let bytes = format!("{line}{FOOT}");
        if let Err(e) = file.write_all_at(bytes.as_bytes(), at) {
            // The closing tags again, over the bytes they had (no new space needed), and the old length.
            let _ = file.write_all_at(FOOT.as_bytes(), at).and_then(|()| file.set_len(len));
            return Err(e);
        }
        Ok(at + bytes.len() as u64)
    }

    /// The whole file, atomically.
    fn rewrite(&mut self) -> Result<()> {
        let text = self.render();
        self.written = None;
        write_atomic(&self.path, text.as_bytes())?;
        self.written = Some(text.len() as u64);
        Ok(())
    }

    /// The XML text of the collection. Times use Rust's shortest round-trip `{}` formatting.
    pub fn render(&self) -> String {
        let mut s = String::from(HEAD);
        for (t, file) in &self.entries {
            s.push_str(&line(*t, file));
        }
        s.push_str(FOOT);
        s
    }
}

/// One entry's line.
fn line(t: f64, file: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "    <DataSet timestep=\"{t}\" group=\"\" part=\"0\" file=\"{}\"/>",
        escape_attribute(file)
    );
    s
}

fn escape_attribute(value: &str) -> String {
    let mut out = String::with_capacity(value.len());
    for c in value.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// An XML element as seen by [`parse_xml_elements`]: name and attributes in order.
#[cfg(test)]
pub(crate) type XmlElement = (String, Vec<(String, String)>);

/// Minimal XML well-formedness check for tests: balanced tags, quoted attributes; returns the elements in
/// document order.
#[cfg(test)]
pub(crate) fn parse_xml_elements(text: &str) -> Result<Vec<XmlElement>, String> {
    let mut elements = Vec::new();
    let mut stack: Vec<String> = Vec::new();
    let mut rest = text.trim_start();
    if let Some(r) = rest.strip_prefix("<?xml") {
        let end = r.find("?>").ok_or("unterminated XML declaration")?;
        rest = &r[end + 2..];
    }
    loop {
        let Some(open) = rest.find('<') else {
            if !rest.trim().is_empty() {
                return Err(format!("text outside the root element: {rest:?}"));
            }
            break;
        };
        if stack.is_empty() && !rest[..open].trim().is_empty() {
            return Err(format!("text outside the root element: {:?}", &rest[..open]));
        }
        let close = rest[open..].find('>').ok_or("unterminated tag")? + open;
        let tag = &rest[open + 1..close];
        rest = &rest[close + 1..];
        if let Some(name) = tag.strip_prefix('/') {
            match stack.pop() {
                Some(top) if top == name.trim() => {}
                other => return Err(format!("</{name}> closes {other:?}")),
            }
            if stack.is_empty() && !rest.trim().is_empty() {
                return Err("content after the root element".into());
            }
            continue;
        }
        if stack.is_empty() && !elements.is_empty() {
            return Err("more than one root element".into());
        }
        let (body, self_closing) = match tag.strip_suffix('/') {
            Some(b) => (b, true),
            None => (tag, false),
        };
        let mut parts = body.trim();
        let name_end = parts.find(char::is_whitespace).unwrap_or(parts.len());
        let name = parts[..name_end].to_string();
        if name.is_empty() {
            return Err("empty tag name".into());
        }
        parts = parts[name_end..].trim_start();
        let mut attributes = Vec::new();
        while !parts.is_empty() {
            let eq = parts
                .find('=')
                .ok_or_else(|| format!("attribute without value in <{name}>"))?;
            let key = parts[..eq].trim().to_string();
            let after = parts[eq + 1..].trim_start();
            let quote = after.chars().next().filter(|c| *c == '"' || *c == '\'');
            let quote = quote.ok_or_else(|| format!("unquoted attribute `{key}` in <{name}>"))?;
            let end = after[1..].find(quote).ok_or("unterminated attribute value")? + 1;
            if attributes.iter().any(|(k, _)| *k == key) {
                return Err(format!("duplicate attribute `{key}` in <{name}>"));
            }
            attributes.push((key, after[1..end].to_string()));
            parts = after[end + 1..].trim_start();
        }
        if !self_closing {
            stack.push(name.clone());
        }
        elements.push((name, attributes));
        if self_closing && stack.is_empty() && !rest.trim().is_empty() {
            return Err("content after the root element".into());
        }
    }
    if !stack.is_empty() {
        return Err(format!("unclosed elements {stack:?}"));
    }
    if elements.is_empty() {
        return Err("no root element".into());
    }
    Ok(elements)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collection_lists_every_entry_and_stays_well_formed() {
        let dir = super::super::test_dir("pvd");
        let path = dir.join("a.pvd");
        let mut c = PvdCollection::new(&path);
        c.push(0.0, "a_00000.vtu").unwrap();
        c.push(0.005, "a_00001.vtu").unwrap();
        c.push(0.0051, "a_00001.vtu").unwrap(); // rewritten frame replaces its entry
        let text = std::fs::read_to_string(&path).unwrap();
        let elements = parse_xml_elements(&text).unwrap();
        let data_sets: Vec<_> = elements.iter().filter(|(n, _)| n == "DataSet").collect();
        assert_eq!(data_sets.len(), 2);
        let attr = |i: usize, k: &str| data_sets[i].1.iter().find(|(a, _)| a == k).unwrap().1.clone();
        assert_eq!(attr(0, "timestep"), "0");
        assert_eq!(attr(1, "timestep"), "0.0051");
        assert_eq!(attr(1, "file"), "a_00001.vtu");
        assert!(!dir.join("a.pvd.tmp").exists());
        assert!(c.push(f64::NAN, "x.vtu").unwrap_err().to_string().contains("a.pvd"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// New entries go in place (the same file, not a renamed copy: O(1) bytes an entry), and the file is always
    /// the whole collection; a file changed by someone else, or a replaced entry, is rewritten whole.
    #[test]
    fn new_entries_are_written_in_place_and_the_file_stays_whole() {
        use std::os::unix::fs::MetadataExt;
        let dir = super::super::test_dir("pvd-append");
        let path = dir.join("b.pvd");
        let inode = || std::fs::metadata(&path).unwrap().ino();
        let mut c = PvdCollection::new(&path);
        c.push(0.0, "b_00000.vtu").unwrap();
        let first = inode();
        for k in 1..200 {
            c.push(k as f64 * 1e-3, &format!("b_{k:05}.vtu")).unwrap();
            assert_eq!(std::fs::read_to_string(&path).unwrap(), c.render(), "after {k}");
        }
        assert_eq!(inode(), first, "appended in place");
        assert_eq!(parse_xml_elements(&c.render()).unwrap().len(), 202);
        // Cut short by someone: rewritten whole at the next entry.
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::write(&path, &text[..text.len() - 5]).unwrap();
        c.push(0.5, "b_00500.vtu").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), c.render());
        // A replaced entry: whole, atomically.
        c.push(0.25, "b_00001.vtu").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), c.render());
        assert!(c
            .render()
            .contains("timestep=\"0.25\" group=\"\" part=\"0\" file=\"b_00001.vtu\""));
        assert_eq!(c.entries().len(), 201);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn checker_rejects_malformed_xml() {
        assert!(parse_xml_elements("<a><b></a>").is_err());
        assert!(parse_xml_elements("<a x=1/>").is_err());
        assert!(parse_xml_elements("<a/><b/>").is_err());
        assert!(parse_xml_elements("<a>").is_err());
        assert!(parse_xml_elements("<?xml version=\"1.0\"?>\n<a k=\"v\"><b/></a>\n").is_ok());
    }
}
