//! Scene files (TOML): one table per scene, the same keys as the scene's flags.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::cli::{HairArgs, PendulumArgs, RopeArgs};
use crate::error::Error;

/// A scene file: a table per scene, each optional.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pendulum: Option<PendulumArgs>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rope: Option<RopeArgs>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hair: Option<HairArgs>,
}

impl SceneFile {
    /// Reads and parses `path`. Errors name the file, and the line and key at fault.
    pub fn load(path: &Path) -> Result<Self, Error> {
        let text = read_capped(path)?;
        let text = String::from_utf8(text).map_err(|_| {
            Error::Usage(format!(
                "--config {}: not a TOML file (not UTF-8 text)",
                path.display()
            ))
        })?;
        if text.trim().is_empty() {
            return Err(Error::Usage(format!(
                "--config {}: the file is empty; expected tables [pendulum], [rope] and/or [hair]",
                path.display()
            )));
        }
        Self::parse(&text).map_err(|e| Error::Usage(format!("--config {}: {e}", path.display())))
    }

    pub fn parse(text: &str) -> Result<Self, String> {
        let file: SceneFile = toml::from_str(text).map_err(|e| {
            // serde loses the place of a key of a flattened flag group (the error then points
            // at its table's header) and reads a date as a map: see `refused_value`.
            let placed = e
                .span()
                .map(|span| text[..span.start].matches('\n').count() + 1);
            match refused_value(text) {
                Some(refused) if refused.date || refused.line != placed => refused.message,
                _ => e.to_string().trim_end().replace('\n', "\n  "),
            }
        })?;
        check_keys(text)?;
        check_method_lists(text)?;
        Ok(file)
    }

    pub fn to_toml(&self) -> anyhow::Result<String> {
        Ok(toml::to_string(self)?)
    }
}

/// A scene file is a few tables of numbers: a larger file is not one (and a path to an endless
/// stream must not fill the memory).
pub const MAX_SCENE_FILE_BYTES: u64 = 1 << 20;

/// The bytes of a regular file of at most [`MAX_SCENE_FILE_BYTES`]. It is opened without
/// blocking and its type read from the open file, so that a FIFO with no writer or a device is
/// refused at once rather than waited on or read forever.
fn read_capped(path: &Path) -> Result<Vec<u8>, Error> {
    use std::io::Read as _;
    use std::os::unix::fs::{FileTypeExt as _, OpenOptionsExt as _};
    let fail = |what: String| Error::Usage(format!("--config {}: {what}", path.display()));
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
        .map_err(|e| fail(format!("cannot read it: {e}")))?;
    let kind = file
        .metadata()
        .map_err(|e| fail(format!("cannot read it: {e}")))?
        .file_type();
    let special = if kind.is_fifo() {
        Some("a FIFO (named pipe)")
    } else if kind.is_char_device() {
        Some("a character device")
    } else if kind.is_block_device() {
        Some("a block device")
    } else if kind.is_socket() {
        Some("a socket")
    } else {
        None
    };
    if let Some(special) = special {
        return Err(fail(format!(
            "is {special}, not a regular file; give a TOML scene file"
        )));
    }
    let mut bytes = Vec::new();
    file.take(MAX_SCENE_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| fail(format!("cannot read it: {e}")))?;
    if bytes.len() as u64 > MAX_SCENE_FILE_BYTES {
        return Err(fail(format!(
            "larger than {} MiB: not a scene file (a scene file is a few tables of numbers)",
            MAX_SCENE_FILE_BYTES >> 20
        )));
    }
    Ok(bytes)
}

/// Refuses keys a scene's table does not know (the tables flatten shared flag groups, which
/// serde cannot combine with `deny_unknown_fields`), naming the line, the key and the known ones.
fn check_keys(text: &str) -> Result<(), String> {
    let Ok(file) = toml::from_str::<toml::Table>(text) else {
        return Ok(()); // already refused by the typed parse
    };
    let known = |defaults: Result<toml::Value, toml::ser::Error>, extra: &[&str]| -> Vec<String> {
        let mut keys: Vec<String> = match defaults {
            Ok(toml::Value::Table(t)) => t.keys().cloned().collect(),
            _ => Vec::new(),
        };
        keys.extend(extra.iter().map(|k| k.to_string()));
        keys
    };
    let scenes = [
        (
            "pendulum",
            known(toml::Value::try_from(PendulumArgs::defaults()), &[]),
        ),
        (
            "rope",
            known(toml::Value::try_from(RopeArgs::defaults()), &["preset"]),
        ),
        (
            "hair",
            known(
                toml::Value::try_from(HairArgs::defaults()),
                &["dt", "log_strands", "stiffness"],
            ),
        ),
    ];
    for (scene, keys) in &scenes {
        let Some(toml::Value::Table(table)) = file.get(*scene) else {
            continue;
        };
        if let Some(unknown) = table.keys().find(|k| !keys.contains(k)) {
            let line =
                line_of_key(text, scene, unknown).map_or(String::new(), |l| format!("line {l}: "));
            return Err(format!(
                "{line}unknown key `{unknown}` in [{scene}]; expected one of {}",
                keys.join(", ")
            ));
        }
    }
    Ok(())
}

/// A value its key does not take.
struct Refused {
    /// Names the line, the table, the key and the value, and why.
    message: String,
    line: Option<usize>,
    date: bool,
}

/// The first value of a well-formed file that its key does not take, found by reading each key
/// alone, so that the error is placed at the key's own line.
fn refused_value(text: &str) -> Option<Refused> {
    let file: toml::Table = toml::from_str(text).ok()?;
    let alone = |scene: &str, key: &str, value: toml::Value| {
        let table = toml::Table::from_iter([(key.to_string(), value)]);
        let file = toml::Table::from_iter([(scene.to_string(), toml::Value::Table(table))]);
        toml::Value::Table(file).try_into::<SceneFile>().err()
    };
    for (scene, table) in &file {
        let toml::Value::Table(table) = table else {
            continue;
        };
        for (key, value) in table {
            let Some(error) = alone(scene, key, value.clone()) else {
                continue;
            };
            let line = line_of_key(text, scene, key);
            let at = line.map_or(String::new(), |l| format!("line {l}: "));
            // A date reads as a map to serde; as text its error names the type the key takes.
            let why = match value {
                toml::Value::Datetime(date) => {
                    let as_text = alone(scene, key, toml::Value::String(date.to_string()))
                        .map_or(String::new(), |e| {
                            format!(" (read as text: {})", e.message())
                        });
                    format!("a TOML date-time is not a value of {key}{as_text}")
                }
                _ => error.message().to_string(),
            };
            return Some(Refused {
                message: format!("{at}[{scene}] {key} = {value}: {why}"),
                line,
                date: matches!(value, toml::Value::Datetime(_)),
            });
        }
    }
    None
}

/// Refuses an empty `methods` list in any table, as `--methods ""` is refused: a run of no
/// method is a slip, not a request for the defaults.
fn check_method_lists(text: &str) -> Result<(), String> {
    let Ok(file) = toml::from_str::<toml::Table>(text) else {
        return Ok(()); // already refused by the typed parse
    };
    for (scene, table) in &file {
        if let Some(toml::Value::Array(list)) = table.get("methods")
            && list.is_empty()
        {
            let line = line_of_key(text, scene, "methods")
                .map_or(String::new(), |l| format!("line {l}: "));
            return Err(format!(
                "{line}[{scene}] methods = []: lists no method; name at least one, or leave the key \
                 out for the defaults (`physlab methods` lists them)"
            ));
        }
    }
    Ok(())
}

/// The 1-based line where `key` is set inside `[scene]`, if it can be found.
fn line_of_key(text: &str, scene: &str, key: &str) -> Option<usize> {
    let mut in_table = false;
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.starts_with('[') {
            in_table = line.trim_matches(|c| c == '[' || c == ']').trim() == scene;
        } else if in_table
            && line
                .strip_prefix(key)
                .is_some_and(|rest| rest.trim_start().starts_with('='))
        {
            return Some(i + 1);
        }
    }
    None
}
