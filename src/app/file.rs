//! Scene files (TOML): one table per scene, the same keys as the scene's flags.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::cli::{HairArgs, PendulumArgs, RopeArgs};
use crate::error::UsageError;

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
    pub fn load(path: &Path) -> Result<Self, UsageError> {
        let text = std::fs::read(path)
            .map_err(|e| UsageError(format!("--config {}: cannot read it: {e}", path.display())))?;
        let text = String::from_utf8(text).map_err(|_| {
            UsageError(format!(
                "--config {}: not a TOML file (not UTF-8 text)",
                path.display()
            ))
        })?;
        if text.trim().is_empty() {
            return Err(UsageError(format!(
                "--config {}: the file is empty; expected tables [pendulum], [rope] and/or [hair]",
                path.display()
            )));
        }
        Self::parse(&text).map_err(|e| UsageError(format!("--config {}: {e}", path.display())))
    }

    pub fn parse(text: &str) -> Result<Self, String> {
        let file: SceneFile =
            toml::from_str(text).map_err(|e| e.to_string().trim_end().replace('\n', "\n  "))?;
        check_keys(text)?;
        Ok(file)
    }

    pub fn to_toml(&self) -> anyhow::Result<String> {
        Ok(toml::to_string(self)?)
    }
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
                &["dt", "log_strands"],
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
