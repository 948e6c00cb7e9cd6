//! `--set key.path=value` overrides of a scene, applied to its TOML before it is read into [`crate::scene::Scene`].

use serde::Deserialize;

/// Apply one `key.path=value` override. Paths take `name`, `name[3]` or `name.3` segments; an array of tables
/// with a single element may be addressed without an index.
pub(crate) fn apply(root: &mut toml::Value, assignment: &str) -> Result<(), (String, String)> {
    let (path, raw) = assignment
        .split_once('=')
        .ok_or_else(|| (assignment.to_string(), "expected key.path=value".to_string()))?;
    let path = path.trim();
    let fail = |msg: String| (path.to_string(), msg);
    let value = parse_value(raw.trim());
    let mut segments = Vec::new();
    for part in path.split('.') {
        if part.is_empty() {
            return Err(fail("empty segment in key path".into()));
        }
        match part.split_once('[') {
            Some((name, rest)) => {
                let index = rest
                    .strip_suffix(']')
                    .and_then(|i| i.parse::<usize>().ok())
                    .ok_or_else(|| fail(format!("bad index in `{part}`")))?;
                if !name.is_empty() {
                    segments.push(Segment::Key(name.to_string()));
                }
                segments.push(Segment::Index(index));
            }
            None => match part.parse::<usize>() {
                Ok(i) => segments.push(Segment::Index(i)),
                Err(_) => segments.push(Segment::Key(part.to_string())),
            },
        }
    }
    let mut node = root;
    let n = segments.len();
    for (k, seg) in segments.into_iter().enumerate() {
        let last = k + 1 == n;
        // An array addressed by name alone: step into its only element.
        let array_len = node.as_array().map(Vec::len);
        if let (Segment::Key(_), Some(len)) = (&seg, array_len) {
            if len != 1 {
                return Err(fail(format!("is an array of {len} items; give an index")));
            }
            node = node.as_array_mut().and_then(|a| a.first_mut()).expect("one item");
        }
        node = match seg {
            Segment::Key(name) => {
                let table = node
                    .as_table_mut()
                    .ok_or_else(|| fail(format!("`{name}` is not inside a table")))?;
                if last {
                    table.insert(name, value);
                    return Ok(());
                }
                table
                    .entry(name)
                    .or_insert_with(|| toml::Value::Table(toml::map::Map::new()))
            }
            Segment::Index(i) => {
                let items = node
                    .as_array_mut()
                    .ok_or_else(|| fail(format!("[{i}] applied to a non-array")))?;
                let len = items.len();
                let item = items
                    .get_mut(i)
                    .ok_or_else(|| fail(format!("index {i} out of range ({len} items)")))?;
                if last {
                    *item = value;
                    return Ok(());
                }
                item
            }
        };
    }
    Err(fail("empty key path".into()))
}

enum Segment {
    Key(String),
    Index(usize),
}

/// A TOML value if the text parses as one, else a bare string (so `--set fluid.solver=isph` works unquoted).
fn parse_value(raw: &str) -> toml::Value {
    #[derive(Deserialize)]
    struct Holder {
        v: toml::Value,
    }
    toml::from_str::<Holder>(&format!("v = {raw}"))
        .map(|h| h.v)
        .unwrap_or_else(|_| toml::Value::String(raw.to_string()))
}
