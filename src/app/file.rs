//! Scene files (TOML): one table per scene, whose keys are the scene configuration's own.

use std::path::{Path, PathBuf};

use crate::error::Error;

/// A scene file: a table per scene, each optional, in the order they were read or set.
#[derive(Clone, Debug, Default)]
pub struct SceneFile {
    /// Where it was read from, and its text (for the lines errors name).
    source: Option<(PathBuf, String)>,
    tables: Vec<(String, toml::Table)>,
}

impl SceneFile {
    pub fn load(path: &Path, scenes: &[&str]) -> Result<Self, Error> {
        let text = read_capped(path)?;
        let text = String::from_utf8(text).map_err(|_| {
            Error::Usage(format!(
                "--config {}: not a TOML file (not UTF-8 text)",
                path.display()
            ))
        })?;
        if text.trim().is_empty() {
            return Err(Error::Usage(format!(
                "--config {}: the file is empty; expected tables {}",
                path.display(),
                listed(scenes)
            )));
        }
        let mut file = Self::parse(&text, scenes)
            .map_err(|e| Error::Usage(format!("--config {}: {e}", path.display())))?;
        file.source = Some((path.to_path_buf(), text));
        Ok(file)
    }

    pub fn parse(text: &str, scenes: &[&str]) -> Result<Self, String> {
        let file: toml::Table =
            toml::from_str(text).map_err(|e| e.to_string().trim_end().replace('\n', "\n  "))?;
        let mut tables = Vec::new();
        for (name, value) in file {
            match value {
                toml::Value::Table(table) if scenes.contains(&name.as_str()) => {
                    tables.push((name, table))
                }
                _ => {
                    let line = at_line(line_at(text, &[&name]));
                    return Err(format!(
                        "{line}`{name}` is not a scene table; expected {}",
                        listed(scenes)
                    ));
                }
            }
        }
        check_method_lists(text, &tables)?;
        Ok(SceneFile {
            source: None,
            tables,
        })
    }

    pub fn table(&self, scene: &str) -> Option<&toml::Table> {
        self.tables.iter().find(|t| t.0 == scene).map(|t| &t.1)
    }

    /// Sets `scene`'s table (after those already set).
    pub fn set(&mut self, scene: &str, table: toml::Table) {
        self.tables.retain(|t| t.0 != scene);
        self.tables.push((scene.to_string(), table));
    }

    /// Refuses a file read (`--config`) without a table for `scene`, for a command that runs
    /// that scene alone: nothing in it would apply.
    pub fn require(&self, scene: &str) -> Result<(), Error> {
        match self.path() {
            Some(path) if self.table(scene).is_none() => Err(Error::Usage(format!(
                "--config {}: has no [{scene}] table, so nothing in it applies to this command",
                path.display()
            ))),
            _ => Ok(()),
        }
    }

    pub fn path(&self) -> Option<&Path> {
        self.source.as_ref().map(|s| s.0.as_path())
    }

    pub fn line_of(&self, scene: &str, key: &str) -> Option<usize> {
        line_at(&self.source.as_ref()?.1, &[scene, key])
    }

    pub fn to_toml(&self) -> anyhow::Result<String> {
        let mut text = String::new();
        for (name, table) in &self.tables {
            if !text.is_empty() {
                text.push('\n');
            }
            let one = toml::Table::from_iter([(name.clone(), toml::Value::Table(table.clone()))]);
            text.push_str(&toml::to_string(&one)?);
        }
        Ok(text)
    }
}

/// `[pendulum], [rope] or [hair]`.
fn listed(scenes: &[&str]) -> String {
    let named: Vec<String> = scenes.iter().map(|s| format!("[{s}]")).collect();
    listing(&named, "or")
}

/// `a, b {last} c`.
pub(super) fn listing<S: std::borrow::Borrow<str>>(items: &[S], last: &str) -> String {
    match items.split_last() {
        Some((end, rest)) if !rest.is_empty() => {
            format!("{} {last} {}", rest.join(", "), end.borrow())
        }
        _ => items.join(""),
    }
}

/// A scene file is a few tables of numbers: a larger file is not one (and a path to an endless
/// stream must not fill the memory).
pub const MAX_SCENE_FILE_BYTES: u64 = 1 << 20;

/// The bytes of a regular file of at most [`MAX_SCENE_FILE_BYTES`], opened without blocking so
/// that a FIFO with no writer or a device is refused at once rather than waited on.
fn read_capped(path: &Path) -> Result<Vec<u8>, Error> {
    use std::io::Read as _;
    use std::os::unix::fs::{FileTypeExt as _, OpenOptionsExt as _};
    let fail = |what: String| Error::Usage(format!("--config {}: {what}", path.display()));
    let unreadable = |e: std::io::Error| fail(format!("cannot read it: {e}"));
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
        .map_err(unreadable)?;
    let kind = file.metadata().map_err(unreadable)?.file_type();
    let special = [
        (kind.is_fifo(), "a FIFO (named pipe)"),
        (kind.is_char_device(), "a character device"),
        (kind.is_block_device(), "a block device"),
        (kind.is_socket(), "a socket"),
    ];
    if let Some((_, special)) = special.into_iter().find(|s| s.0) {
        return Err(fail(format!(
            "is {special}, not a regular file; give a TOML scene file"
        )));
    }
    let mut bytes = Vec::new();
    file.take(MAX_SCENE_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(unreadable)?;
    if bytes.len() as u64 > MAX_SCENE_FILE_BYTES {
        return Err(fail(format!(
            "larger than {} MiB: not a scene file (a scene file is a few tables of numbers)",
            MAX_SCENE_FILE_BYTES >> 20
        )));
    }
    Ok(bytes)
}

/// Refuses an empty `methods` list in any table, as `--methods ""` is refused: a run of no
/// method is a slip, not a request for the defaults.
fn check_method_lists(text: &str, tables: &[(String, toml::Table)]) -> Result<(), String> {
    for (scene, table) in tables {
        if let Some(toml::Value::Array(list)) = table.get("methods")
            && list.is_empty()
        {
            let line = at_line(line_at(text, &[scene, "methods"]));
            return Err(format!(
                "{line}[{scene}] methods = []: lists no method; name at least one, or leave the key \
                 out for the defaults (`physlab methods` lists them)"
            ));
        }
    }
    Ok(())
}

/// `line N: `, that a message starts with when it knows the line.
pub(super) fn at_line(line: Option<usize>) -> String {
    line.map_or(String::new(), |l| format!("line {l}: "))
}

/// The 1-based line of the key at `path` (a table's name, then a key inside it).
fn line_at(text: &str, path: &[&str]) -> Option<usize> {
    let file = toml::de::DeTable::parse(text).ok()?;
    let (mut table, mut start) = (Some(file.get_ref()), 0);
    for name in path {
        let (key, value) = table?.iter().find(|(k, _)| k.get_ref() == name)?;
        start = key.span().start;
        table = match value.get_ref() {
            toml::de::DeValue::Table(inner) => Some(inner),
            _ => None,
        };
    }
    Some(text[..start].matches('\n').count() + 1)
}
