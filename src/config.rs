//! Scene files (TOML): one table per scene, the same keys as the scene's flags. Values are
//! layered: flags over the file over presets over defaults.

use std::fmt;
use std::path::Path;
use std::str::FromStr;

use glam::DVec3;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::app::UsageError;
use crate::cli::{HairArgs, PendulumArgs, RopeArgs};

/// A 3-vector given as "x,y" or "x,y,z" on the command line (z = 0 when omitted) and as
/// [x, y, z] in a scene file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vector(pub DVec3);

impl FromStr for Vector {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, String> {
        let bad =
            || format!("expected x,y or x,y,z with finite numbers, e.g. 0,-9.81,0 (got '{text}')");
        let parts: Vec<f64> = text
            .split(',')
            .map(|p| p.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad())?;
        Vector::from_components(&parts).ok_or_else(bad)
    }
}

impl Vector {
    fn from_components(c: &[f64]) -> Option<Self> {
        if !c.iter().all(|x| x.is_finite()) {
            return None;
        }
        match *c {
            [x, y] => Some(Vector(DVec3::new(x, y, 0.0))),
            [x, y, z] => Some(Vector(DVec3::new(x, y, z))),
            _ => None,
        }
    }
}

impl fmt::Display for Vector {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{}", self.0.x, self.0.y, self.0.z)
    }
}

impl Serialize for Vector {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.to_array().serialize(s)
    }
}

impl<'de> Deserialize<'de> for Vector {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let c = Vec::<f64>::deserialize(d)?;
        Vector::from_components(&c).ok_or_else(|| {
            serde::de::Error::custom("expected [x, y] or [x, y, z] with finite numbers")
        })
    }
}

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

    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("scene parameters serialise to TOML")
    }
}

/// Layers values: each later layer's given fields override the earlier ones'.
pub fn layered<T: Serialize + DeserializeOwned>(layers: &[&T]) -> T {
    let mut table = toml::Table::new();
    for layer in layers {
        if let toml::Value::Table(t) = toml::Value::try_from(layer).expect("parameters serialise") {
            table.extend(t);
        }
    }
    toml::Value::Table(table)
        .try_into()
        .expect("layered parameters deserialise")
}
