//! ParaView collection files (`.pvd`): a list of `(time, file)` pairs that ParaView opens as one time series.
//!
//! vtkio has no collection type, and the format is five lines of XML, so it is written here.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::{write_atomic, OutputError, Result};

/// A `.pvd` collection, rewritten in full (atomically) after every added entry so that a run that dies keeps
/// a valid file listing every frame written so far.
#[derive(Clone, Debug)]
pub struct PvdCollection {
    path: PathBuf,
    entries: Vec<(f64, String)>,
}

impl PvdCollection {
    /// An empty collection that will be written to `path` (nothing is written until [`push`](Self::push)).
    pub fn new(path: impl Into<PathBuf>) -> Self {
        Self {
            path: path.into(),
            entries: Vec::new(),
        }
    }

    /// A collection that starts with `entries` (a run continuing from a checkpoint keeps the frames before it);
    /// written at once when there are any, so the file lists them even before the next frame.
    pub fn with_entries(path: impl Into<PathBuf>, entries: Vec<(f64, String)>) -> Result<Self> {
        let c = Self {
            path: path.into(),
            entries,
        };
        if !c.entries.is_empty() {
            write_atomic(&c.path, c.render().as_bytes())?;
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

    /// Add the data set `file` (relative to the `.pvd`'s folder) at time `t`, then rewrite the collection.
    /// Adding a file already listed replaces its entry (a frame written again).
    pub fn push(&mut self, t: f64, file: &str) -> Result<()> {
        if !t.is_finite() {
            return Err(OutputError::input(
                &self.path,
                format!("time {t} of `{file}` is not finite"),
            ));
        }
        match self.entries.iter_mut().find(|(_, f)| f == file) {
            Some(entry) => entry.0 = t,
            None => self.entries.push((t, file.to_string())),
        }
        write_atomic(&self.path, self.render().as_bytes())
    }

    /// The XML text of the collection. Times use Rust's shortest round-trip `{}` formatting.
    pub fn render(&self) -> String {
        let mut s = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  \
             <Collection>\n",
        );
        for (t, file) in &self.entries {
            let _ = writeln!(
                s,
                "    <DataSet timestep=\"{t}\" group=\"\" part=\"0\" file=\"{}\"/>",
                escape_attribute(file)
            );
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        s
    }
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

    #[test]
    fn checker_rejects_malformed_xml() {
        assert!(parse_xml_elements("<a><b></a>").is_err());
        assert!(parse_xml_elements("<a x=1/>").is_err());
        assert!(parse_xml_elements("<a/><b/>").is_err());
        assert!(parse_xml_elements("<a>").is_err());
        assert!(parse_xml_elements("<?xml version=\"1.0\"?>\n<a k=\"v\"><b/></a>\n").is_ok());
    }
}
