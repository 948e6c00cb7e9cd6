//! Reading a scene: TOML text, `--set` overrides applied to it, serde with the full dotted key of any error, then
//! [`Scene::validate`]. Every user error is a [`SceneError`].

use std::path::{Path, PathBuf};

use super::overrides;
use super::schema::Scene;

/// A user error in a scene: one line naming the file, the key and the problem.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}: {key}: {message}")]
pub struct SceneError {
    /// Scene file (or `--set` for an override).
    pub file: String,
    /// Dotted key path, e.g. `solid[0].material.youngs_modulus`.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl SceneError {
    fn new(file: &str, key: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            file: file.to_string(),
            key: key.into(),
            message: message.into(),
        }
    }
}

/// A scene with where it came from.
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// The validated scene.
    pub scene: Scene,
    /// The file it was read from.
    pub path: PathBuf,
}

impl LoadedScene {
    /// Resolve a path written in the scene (relative to the scene file's folder).
    pub fn resolve(&self, relative: &str) -> PathBuf {
        let p = Path::new(relative);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.path.parent().unwrap_or(Path::new(".")).join(p)
        }
    }
}

/// Read, override and validate a scene file. `overrides` are `key.path=value` strings (`--set`).
pub fn load(path: &Path, overrides: &[String]) -> Result<LoadedScene, SceneError> {
    let file = path.display().to_string();
    let text = read_bounded(path).map_err(|message| SceneError::new(&file, "(file)", message))?;
    let scene = parse(&file, &text, overrides)?;
    Ok(LoadedScene {
        scene,
        path: path.to_path_buf(),
    })
}

/// The most bytes a scene file may have: the shipped scenes are a few KiB (a million probes, which `cosim check`
/// takes, about 60 MiB), and a path to something endless
/// (`/dev/zero`, a pipe) would otherwise be read until memory runs out (found 2026-12-06: `cosim check /dev/zero`
/// never returned).
pub const MAX_SCENE_BYTES: u64 = 256 << 20;

/// The file's text, at most [`MAX_SCENE_BYTES`] of it; `Err` says why not.
fn read_bounded(path: &Path) -> Result<String, String> {
    use std::io::Read;
    let file = std::fs::File::open(path).map_err(|e| match nearest_file(path, &e) {
        Some(near) => format!("cannot read: {e} (did you mean {}?)", near.display()),
        None => format!("cannot read: {e}"),
    })?;
    let mut bytes = Vec::new();
    file.take(MAX_SCENE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read: {e}"))?;
    if bytes.len() as u64 > MAX_SCENE_BYTES {
        return Err(format!("more than {} MiB: not a scene file", MAX_SCENE_BYTES >> 20));
    }
    String::from_utf8(bytes).map_err(|e| format!("cannot read: not UTF-8 text ({e})"))
}

/// Where `path` is not there, the file beside it whose name is [`nearest`] to its name.
fn nearest_file(path: &Path, e: &std::io::Error) -> Option<std::path::PathBuf> {
    if e.kind() != std::io::ErrorKind::NotFound {
        return None;
    }
    let name = path.file_name()?.to_str()?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .ok()?
        .flatten()
        .filter(|f| f.file_type().is_ok_and(|t| t.is_file()))
        .filter_map(|f| f.file_name().into_string().ok())
        .collect();
    // In name order: the same suggestion whatever order the directory lists them in.
    names.sort();
    nearest(name, names.iter().map(String::as_str)).map(|near| path.with_file_name(near))
}

/// Of `candidates`, the one nearest to `name` where it is near enough to be a slip of the keyboard: at most a third
/// of its letters (at least one) added, dropped, changed or swapped (Damerau–Levenshtein). The first of equally near
/// ones.
fn nearest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    candidates
        .into_iter()
        .map(|c| (strsim::damerau_levenshtein(name, c), c))
        .filter(|&(d, c)| d <= (c.chars().count() / 3).max(1))
        .min_by_key(|&(d, _)| d)
        .map(|(_, c)| c)
}

/// Parse, override and validate scene text; `file` names it in errors.
pub fn parse(file: &str, text: &str, overrides: &[String]) -> Result<Scene, SceneError> {
    let mut value: toml::Value = toml::from_str(text).map_err(|e| syntax_error(file, text, &e))?;
    for o in overrides {
        overrides::apply(&mut value, o).map_err(|(key, msg)| SceneError::new(file, format!("--set {key}"), msg))?;
    }
    let scene: Scene = serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner().to_string();
        let (key, message) = key_of_serde_error(&path, &inner);
        SceneError::new(file, key, message)
    })?;
    scene.validate().map_err(|(key, msg)| SceneError::new(file, key, msg))?;
    Ok(scene)
}

/// One line for a TOML syntax error: the line number and toml's own message.
fn syntax_error(file: &str, text: &str, e: &toml::de::Error) -> SceneError {
    let key = match e.span() {
        Some(span) => format!("line {}", text[..span.start.min(text.len())].matches('\n').count() + 1),
        None => "(syntax)".to_string(),
    };
    SceneError::new(file, key, e.message().replace('\n', " "))
}

/// The key [`nearest`] to the unknown `field` among those serde's `message` lists after "expected", in the order
/// serde lists them (the struct's).
fn nearest_key(field: &str, message: &str) -> Option<String> {
    let (_, expected) = message.split_once(", expected ")?;
    nearest(field, expected.split('`').skip(1).step_by(2)).map(str::to_string)
}

/// Make the key of a serde error the full dotted path of the offending field.
fn key_of_serde_error(path: &str, message: &str) -> (String, String) {
    let parent = if path == "." { String::new() } else { path.to_string() };
    // serde_path_to_error already ends the path with an unknown field, but not with a missing one.
    let join = |field: &str| {
        if parent.is_empty() {
            field.to_string()
        } else if parent == field || parent.ends_with(&format!(".{field}")) {
            parent.clone()
        } else {
            format!("{parent}.{field}")
        }
    };
    let field_in = |prefix: &str| {
        message
            .strip_prefix(prefix)
            .and_then(|rest| rest.split('`').next())
            .map(str::to_string)
    };
    if let Some(field) = field_in("unknown field `") {
        let key = join(&field);
        let sibling = |near: String| format!("{}{near}", key.strip_suffix(field.as_str()).unwrap_or_default());
        let hint =
            nearest_key(&field, message).map_or(String::new(), |near| format!(" (did you mean {}?)", sibling(near)));
        return (key, format!("unknown key{hint}"));
    }
    if let Some(field) = field_in("missing field `") {
        return (join(&field), "missing key".to_string());
    }
    let key = if parent.is_empty() {
        "(top level)".to_string()
    } else {
        parent
    };
    // toml ends a value's error with the key again, as "in `solid.divisions`" (without the index) and a line break:
    // the line names the key already.
    let message = message.trim_end();
    let message = match message.rfind("in `") {
        Some(at) if message.ends_with('`') && message[..at].ends_with(char::is_whitespace) => message[..at].trim_end(),
        _ => message,
    };
    (key, message.replace('\n', " "))
}
