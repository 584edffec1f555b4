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
        toml::from_str(text).map_err(|e| e.to_string().trim_end().replace('\n', "\n  "))
    }

    pub fn to_toml(&self) -> anyhow::Result<String> {
        Ok(toml::to_string(self)?)
    }
}
